//! IPOPT itself (`--features ipopt`, the system's libipopt) against the interior-point solver
//! on the bench problems: the same `Nlp` (the same transcription, the same exact derivatives),
//! the same start, the same tolerance.
//!
//! `cargo test -p cellplan-ocp --release --features ipopt --test it -- --ignored --nocapture ipopt_vs_ipm`
use crate::bench::{CASES, Problem, solve_ours};
use cellplan_ocp::nlp::ipopt::{self, IpoptOptions};
use cellplan_ocp::nlp::{Nlp, Status};
use std::time::Instant;

#[test]
fn ipopt_reaches_the_casadi_optimum_on_ur10_a() {
    let p = Problem::load("ur10_a", "casadi");
    let s = ipopt::solve(&p.mv, &p.start("casadi"), &IpoptOptions::default());
    assert_eq!(s.status, Status::Solved, "IPOPT code {}", s.code);
    let (rel, _) = p.nearest_optimum("ur10_a", s.objective);
    assert!(rel < 1e-6, "J {} vs CasADi {}", s.objective, p.casadi_j);
    let worst = p.mv.eq(&s.x).iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(worst < 1e-8, "dynamics residual {worst:e}");
}

#[test]
#[ignore = "heavier: cargo test -p cellplan-ocp --release --features ipopt --test it -- --ignored --nocapture ipopt_vs_ipm"]
fn ipopt_vs_ipm() {
    let mut rows = Vec::new();
    for (name, reference) in CASES {
        let p = Problem::load(name, reference);
        let x0 = p.start(reference);
        let t = Instant::now();
        let ours = solve_ours(&p, &x0);
        let ours_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let theirs = ipopt::solve(&p.mv, &x0, &IpoptOptions::default());
        let theirs_s = t.elapsed().as_secs_f64();
        let (ours_rel, _) = p.nearest_optimum(name, ours.objective);
        let (theirs_rel, _) = p.nearest_optimum(name, theirs.objective);
        rows.push(format!(
            "| {name} ({reference}) | {:?} {:.9} ({:.0e}) | {} | {ours_s:.3} | {:?} {:.9} ({:.0e}) | {} | {theirs_s:.3} | {:.1e} | {:.2} |",
            ours.status,
            ours.objective,
            ours_rel,
            ours.iterations,
            theirs.status,
            theirs.objective,
            theirs_rel,
            theirs.iterations,
            (ours.objective - theirs.objective).abs() / theirs.objective.abs(),
            ours_s / theirs_s,
        ));
        // Both solve the problems IPOPT solves, to a known optimum.
        if theirs.status == Status::Solved {
            assert!(
                theirs_rel < 1e-4,
                "{name}: IPOPT's J {} is no known optimum",
                theirs.objective
            );
        }
    }
    eprintln!(
        "| problem | ours: status J (rel. to nearest known optimum) | iterations | s | IPOPT (libipopt): status J (rel.) | iterations | s | |ΔJ|/J | time ratio ours/IPOPT |\n|---|---|---|---|---|---|---|---|---|\n{}",
        rows.join("\n")
    );
}

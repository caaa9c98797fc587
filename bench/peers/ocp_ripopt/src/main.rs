//! ripopt 0.8 on the DMOC bench problems (`bench/ocp`), beside cellplan's own interior-point
//! solver, on the same `Nlp` and start: J, iterations, time, and the distance to the nearest
//! known optimum (the CasADi + IPOPT references).
//!
//! `cargo run --release --manifest-path bench/peers/ocp_ripopt/Cargo.toml`
#[path = "../../../../crates/cellplan-ocp/tests/it/bench.rs"]
#[allow(dead_code)]
mod bench;

use cellplan_ocp::nlp::Nlp;
use cellplan_ocp::nlp::structure::{Structure, stacked_bounds, stacked_constraints, stacked_jacobian};
use ripopt::{NlpProblem, SolverOptions};
use std::time::Instant;

/// A cellplan `Nlp` as ripopt sees it: `g = [c; d]`, structures fixed once.
struct Adapter<'a> {
    nlp: &'a dyn Nlp,
    x0: Vec<f64>,
    jac: Structure,
    hess: Structure,
    outside: std::cell::Cell<bool>,
}

impl NlpProblem for Adapter<'_> {
    fn num_variables(&self) -> usize {
        self.nlp.num_vars()
    }
    fn num_constraints(&self) -> usize {
        self.nlp.num_eq() + self.nlp.num_ineq()
    }
    fn bounds(&self, x_l: &mut [f64], x_u: &mut [f64]) {
        let (l, u) = self.nlp.bounds();
        x_l.copy_from_slice(&l);
        x_u.copy_from_slice(&u);
    }
    fn constraint_bounds(&self, g_l: &mut [f64], g_u: &mut [f64]) {
        let (l, u) = stacked_bounds(self.nlp);
        g_l.copy_from_slice(&l);
        g_u.copy_from_slice(&u);
    }
    fn initial_point(&self, x0: &mut [f64]) {
        x0.copy_from_slice(&self.x0);
    }
    fn objective(&self, x: &[f64], _new_x: bool, obj: &mut f64) -> bool {
        *obj = self.nlp.objective(x);
        obj.is_finite()
    }
    fn gradient(&self, x: &[f64], _new_x: bool, grad: &mut [f64]) -> bool {
        grad.copy_from_slice(&self.nlp.gradient(x));
        grad.iter().all(|v| v.is_finite())
    }
    fn constraints(&self, x: &[f64], _new_x: bool, g: &mut [f64]) -> bool {
        g.copy_from_slice(&stacked_constraints(self.nlp, x));
        g.iter().all(|v| v.is_finite())
    }
    fn jacobian_structure(&self) -> (Vec<usize>, Vec<usize>) {
        (self.jac.rows.clone(), self.jac.cols.clone())
    }
    fn jacobian_values(&self, x: &[f64], _new_x: bool, vals: &mut [f64]) -> bool {
        let ok = self
            .jac
            .scatter(&stacked_jacobian(self.nlp, x, self.nlp.num_eq()), vals);
        self.outside.set(self.outside.get() || !ok);
        ok
    }
    fn hessian_structure(&self) -> (Vec<usize>, Vec<usize>) {
        (self.hess.rows.clone(), self.hess.cols.clone())
    }
    fn hessian_values(
        &self,
        x: &[f64],
        _new_x: bool,
        obj_factor: f64,
        lambda: &[f64],
        vals: &mut [f64],
    ) -> bool {
        let (eq, ineq) = lambda.split_at(self.nlp.num_eq());
        let ok = self
            .hess
            .scatter(&self.nlp.hessian(x, obj_factor, eq, ineq), vals);
        self.outside.set(self.outside.get() || !ok);
        ok
    }
}

fn main() {
    println!(
        "| problem | ours: status J (rel. to nearest known optimum) | iterations | s | ripopt: status J (rel.) | iterations | s | time ratio ours/ripopt |\n|---|---|---|---|---|---|---|---|"
    );
    for (name, reference) in bench::CASES {
        let p = bench::Problem::load(name, reference);
        let x0 = p.start(reference);
        let t = Instant::now();
        let ours = bench::solve_ours(&p, &x0);
        let ours_s = t.elapsed().as_secs_f64();
        let (jac, hess) = Structure::of(&p.mv, &x0);
        let a = Adapter {
            nlp: &p.mv,
            x0: x0.clone(),
            jac,
            hess,
            outside: std::cell::Cell::new(false),
        };
        let opt = SolverOptions {
            tol: 1e-10,
            max_iter: 3000,
            bound_relax_factor: 0.0,
            print_level: 0,
            ..SolverOptions::default()
        };
        let t = Instant::now();
        let r = ripopt::solve(&a, &opt);
        let theirs_s = t.elapsed().as_secs_f64();
        let (ours_rel, _) = p.nearest_optimum(name, ours.objective);
        let (theirs_rel, _) = p.nearest_optimum(name, r.objective);
        let worst = p.mv.eq(&r.x).iter().fold(0.0f64, |m, v| m.max(v.abs()));
        println!(
            "| {name} ({reference}) | {:?} {:.9} ({:.0e}) | {} | {ours_s:.3} | {:?}{} {:.9} ({:.0e}, residual {:.0e}) | {} | {theirs_s:.3} | {:.2} |",
            ours.status,
            ours.objective,
            ours_rel,
            ours.iterations,
            r.status,
            if a.outside.get() {
                " (entry outside the structure)"
            } else {
                ""
            },
            r.objective,
            theirs_rel,
            worst,
            r.iterations,
            ours_s / theirs_s,
        );
    }
}

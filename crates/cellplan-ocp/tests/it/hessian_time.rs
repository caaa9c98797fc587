//! The time of one exact Hessian (and Jacobian) evaluation on the UR10, N = 40 (`ur10_b`).
//! Prints the figures; asserts nothing about time. Run with
//! `cargo test -p cellplan-ocp --release --test it -- --ignored --nocapture hessian_time`.
use crate::bench::Problem;
use std::time::Instant;

#[test]
#[ignore = "timing: cargo test -p cellplan-ocp --release --test it -- --ignored --nocapture hessian_time"]
fn hessian_time() {
    let p = Problem::load("ur10_b", "casadi");
    let m = &p.mv;
    let l = m.layout();
    let mut x = m.initial_guess();
    for (k, v) in x.iter_mut().enumerate() {
        *v += 0.01 * ((k as f64) * 0.37).cos();
    }
    let lambda: Vec<f64> = (0..l.equalities()).map(|r| ((r as f64) * 1.3).sin()).collect();
    let reps = 20;
    let started = Instant::now();
    let mut entries = 0;
    for _ in 0..reps {
        entries = m.hessian(&x, &lambda, 0.7).len();
    }
    let hess_ms = started.elapsed().as_secs_f64() * 1e3 / reps as f64;
    let started = Instant::now();
    for _ in 0..reps {
        std::hint::black_box(m.jacobian(&x));
    }
    let jac_ms = started.elapsed().as_secs_f64() * 1e3 / reps as f64;
    let started = Instant::now();
    for _ in 0..reps {
        std::hint::black_box(m.constraints(&x));
    }
    let c_ms = started.elapsed().as_secs_f64() * 1e3 / reps as f64;
    eprintln!(
        "ur10_b (N = {}, {} variables): Hessian {hess_ms:.2} ms ({entries} triplets), Jacobian {jac_ms:.2} ms, constraints {c_ms:.3} ms",
        l.steps,
        l.vars()
    );
}

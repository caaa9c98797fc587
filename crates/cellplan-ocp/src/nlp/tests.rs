//! Textbook problems with known solutions.
use super::*;

/// Hock–Schittkowski 71: `min x1 x4 (x1 + x2 + x3) + x3` s.t. `x1 x2 x3 x4 ≥ 25`,
/// `Σ xᵢ² = 40`, `1 ≤ x ≤ 5`, from (1, 5, 5, 1); f* = 17.0140173.
struct Hs071;

impl Nlp for Hs071 {
    fn num_vars(&self) -> usize {
        4
    }
    fn num_eq(&self) -> usize {
        1
    }
    fn num_ineq(&self) -> usize {
        1
    }
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![1.0; 4], vec![5.0; 4])
    }
    fn ineq_bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![25.0], vec![f64::INFINITY])
    }
    fn initial_point(&self) -> Vec<f64> {
        vec![1.0, 5.0, 5.0, 1.0]
    }
    fn objective(&self, x: &[f64]) -> f64 {
        x[0] * x[3] * (x[0] + x[1] + x[2]) + x[2]
    }
    fn gradient(&self, x: &[f64]) -> Vec<f64> {
        vec![
            x[3] * (2.0 * x[0] + x[1] + x[2]),
            x[0] * x[3],
            x[0] * x[3] + 1.0,
            x[0] * (x[0] + x[1] + x[2]),
        ]
    }
    fn eq(&self, x: &[f64]) -> Vec<f64> {
        vec![x.iter().map(|v| v * v).sum::<f64>() - 40.0]
    }
    fn eq_jacobian(&self, x: &[f64]) -> Triplets {
        (0..4).map(|j| (0, j, 2.0 * x[j])).collect()
    }
    fn ineq(&self, x: &[f64]) -> Vec<f64> {
        vec![x.iter().product()]
    }
    fn ineq_jacobian(&self, x: &[f64]) -> Triplets {
        (0..4)
            .map(|j| (0, j, (0..4).filter(|&k| k != j).map(|k| x[k]).product()))
            .collect()
    }
    fn hessian(&self, x: &[f64], sigma: f64, lambda: &[f64], mu: &[f64]) -> Triplets {
        let (s, l, m) = (sigma, lambda[0], mu[0]);
        vec![
            (0, 0, s * 2.0 * x[3] + 2.0 * l),
            (1, 0, s * x[3] + m * x[2] * x[3]),
            (1, 1, 2.0 * l),
            (2, 0, s * x[3] + m * x[1] * x[3]),
            (2, 1, m * x[0] * x[3]),
            (2, 2, 2.0 * l),
            (3, 0, s * (2.0 * x[0] + x[1] + x[2]) + m * x[1] * x[2]),
            (3, 1, s * x[0] + m * x[0] * x[2]),
            (3, 2, s * x[0] + m * x[0] * x[1]),
            (3, 3, 2.0 * l),
        ]
    }
}

/// Rosenbrock's function with `x ≤ 0.5` (and `y ≥ -2`): the optimum moves to the bound,
/// (0.5, 0.25), f* = 0.25.
struct BoundedRosenbrock;

impl Nlp for BoundedRosenbrock {
    fn num_vars(&self) -> usize {
        2
    }
    fn num_eq(&self) -> usize {
        0
    }
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![f64::NEG_INFINITY, -2.0], vec![0.5, f64::INFINITY])
    }
    fn initial_point(&self) -> Vec<f64> {
        vec![-1.2, 1.0]
    }
    fn objective(&self, x: &[f64]) -> f64 {
        (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2)
    }
    fn gradient(&self, x: &[f64]) -> Vec<f64> {
        let r = x[1] - x[0] * x[0];
        vec![-2.0 * (1.0 - x[0]) - 400.0 * x[0] * r, 200.0 * r]
    }
    fn eq(&self, _x: &[f64]) -> Vec<f64> {
        Vec::new()
    }
    fn eq_jacobian(&self, _x: &[f64]) -> Triplets {
        Vec::new()
    }
    fn hessian(&self, x: &[f64], sigma: f64, _lambda: &[f64], _mu: &[f64]) -> Triplets {
        vec![
            (
                0,
                0,
                sigma * (2.0 - 400.0 * (x[1] - x[0] * x[0]) + 800.0 * x[0] * x[0]),
            ),
            (1, 0, sigma * -400.0 * x[0]),
            (1, 1, sigma * 200.0),
        ]
    }
}

/// `min x + y` on the unit circle with `x ≥ 2`: no feasible point; the least violation is at
/// (2, 0).
struct Infeasible;

impl Nlp for Infeasible {
    fn num_vars(&self) -> usize {
        2
    }
    fn num_eq(&self) -> usize {
        1
    }
    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (vec![2.0, f64::NEG_INFINITY], vec![10.0, f64::INFINITY])
    }
    fn initial_point(&self) -> Vec<f64> {
        vec![3.0, 1.0]
    }
    fn objective(&self, x: &[f64]) -> f64 {
        x[0] + x[1]
    }
    fn gradient(&self, _x: &[f64]) -> Vec<f64> {
        vec![1.0, 1.0]
    }
    fn eq(&self, x: &[f64]) -> Vec<f64> {
        vec![x[0] * x[0] + x[1] * x[1] - 1.0]
    }
    fn eq_jacobian(&self, x: &[f64]) -> Triplets {
        vec![(0, 0, 2.0 * x[0]), (0, 1, 2.0 * x[1])]
    }
    fn hessian(&self, _x: &[f64], _sigma: f64, lambda: &[f64], _mu: &[f64]) -> Triplets {
        vec![(0, 0, 2.0 * lambda[0]), (1, 1, 2.0 * lambda[0])]
    }
}

fn tight() -> Options {
    Options {
        tol: 1e-10,
        max_iter: 200,
        ..Options::default()
    }
}

#[test]
fn hs071_reaches_the_known_optimum() {
    let s = solve(&Hs071, &tight());
    assert_eq!(s.status, Status::Solved, "{s:?}");
    assert!((s.objective - 17.014017289).abs() < 1e-7, "{}", s.objective);
    let want = [1.0, 4.742999637, 3.821149984, 1.379408293];
    for (a, b) in s.x.iter().zip(want) {
        assert!((a - b).abs() < 1e-6, "{:?}", s.x);
    }
    assert!(s.constraint_violation < 1e-9);
    // x1 sits on its lower bound with a positive multiplier; the product constraint is active.
    assert!(s.z_lower[0] > 0.1 && s.lambda_ineq[0] < -0.1, "{s:?}");
    assert!(s.iterations < 30, "{} iterations", s.iterations);
}

#[test]
fn bounded_rosenbrock_stops_on_its_bound() {
    let s = solve(&BoundedRosenbrock, &tight());
    assert_eq!(s.status, Status::Solved, "{s:?}");
    assert!(
        (s.x[0] - 0.5).abs() < 1e-8 && (s.x[1] - 0.25).abs() < 1e-7,
        "{:?}",
        s.x
    );
    assert!((s.objective - 0.25).abs() < 1e-8);
    // ∂f/∂x = −1 at the bound: the upper multiplier carries it.
    assert!((s.z_upper[0] - 1.0).abs() < 1e-6, "{:?}", s.z_upper);
}

#[test]
fn an_infeasible_problem_is_reported_infeasible() {
    let s = solve(&Infeasible, &tight());
    assert_eq!(s.status, Status::LocallyInfeasible, "{s:?}");
    // It ends near the point of least violation.
    assert!((s.x[0] - 2.0).abs() < 1e-3 && s.x[1].abs() < 1e-3, "{:?}", s.x);
}

#[test]
fn crossed_bounds_are_an_invalid_problem() {
    struct Crossed;
    impl Nlp for Crossed {
        fn num_vars(&self) -> usize {
            1
        }
        fn num_eq(&self) -> usize {
            0
        }
        fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
            (vec![1.0], vec![0.0])
        }
        fn initial_point(&self) -> Vec<f64> {
            vec![0.5]
        }
        fn objective(&self, x: &[f64]) -> f64 {
            x[0]
        }
        fn gradient(&self, _x: &[f64]) -> Vec<f64> {
            vec![1.0]
        }
        fn eq(&self, _x: &[f64]) -> Vec<f64> {
            Vec::new()
        }
        fn eq_jacobian(&self, _x: &[f64]) -> Triplets {
            Vec::new()
        }
        fn hessian(&self, _x: &[f64], _s: f64, _l: &[f64], _m: &[f64]) -> Triplets {
            Vec::new()
        }
    }
    assert_eq!(
        solve(&Crossed, &Options::default()).status,
        Status::InvalidProblem
    );
}

#[test]
fn the_iteration_limit_is_reported() {
    let s = solve(
        &Hs071,
        &Options {
            max_iter: 3,
            ..Options::default()
        },
    );
    assert_eq!(s.status, Status::MaxIterations);
    assert_eq!(s.iterations, 3);
}

//! One move as a nonlinear program (paper 002 §2.3): the DMOC transcription of [`crate::dmoc`]
//! between two configurations at rest, with free final time, in the standard form
//!
//! `min f(x)  s.t.  c(x) = 0,  A x ≤ 0,  x_L ≤ x ≤ x_U`
//!
//! - variables `x = [q_0 … q_N, u_½ … u_{N−½}, h, q̇_0, q̇_N]` ([`Layout`]);
//! - `f = Σ h (c_t + c_e |u_{i+½}|² + c_v |(q_{i+1} − q_i)/h|²)` (the paper's §3 cost);
//! - `c`: the start condition, the N−1 forced discrete Euler–Lagrange equations, the end
//!   condition (n rows each);
//! - `A x ≤ 0`: the velocity bounds as differences, `±(q_{i+1} − q_i) − h v̇_max ≤ 0`, linear;
//! - bounds: joint limits, torque limits, the step's range, the fixed ends (`q_0`, `q_N`,
//!   `q̇_0 = q̇_N = 0` as equal bounds).
//!
//! The Jacobian of `c` and the Hessian of the Lagrangian are exact and sparse (row block k
//! touches `q_{k−1}, q_k, q_{k+1}`, `h` and two torques), computed step by step in `exact`
//! by second-order forward differentiation over each midpoint ([`crate::taylor`]).
use crate::dmoc::{del_residual, end_residual, start_residual};
use cellplan_kin::dynamics::Dynamics;

mod as_nlp;
mod exact;

/// The cost weights (paper 002 §3: c_t = 1, c_e = 1e-6, c_v = 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    /// Per second.
    pub time: f64,
    /// Per (N·m)²·s of torque.
    pub effort: f64,
    /// Per (rad/s)²·s of joint velocity.
    pub velocity: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            time: 1.0,
            effort: 1e-6,
            velocity: 1.0,
        }
    }
}

/// Where each variable lives in `x`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Joints.
    pub n: usize,
    /// Steps.
    pub steps: usize,
}

impl Layout {
    /// Index of `q_i[j]`.
    pub fn q(&self, i: usize, j: usize) -> usize {
        i * self.n + j
    }
    /// Index of `u_{i+½}[j]`.
    pub fn u(&self, i: usize, j: usize) -> usize {
        (self.steps + 1) * self.n + i * self.n + j
    }
    /// Index of `h`.
    pub fn h(&self) -> usize {
        (2 * self.steps + 1) * self.n
    }
    /// Index of `q̇_0[j]`.
    pub fn qd0(&self, j: usize) -> usize {
        self.h() + 1 + j
    }
    /// Index of `q̇_N[j]`.
    pub fn qdn(&self, j: usize) -> usize {
        self.h() + 1 + self.n + j
    }
    /// Number of variables.
    pub fn vars(&self) -> usize {
        self.h() + 1 + 2 * self.n
    }
    /// Number of equality constraints.
    pub fn equalities(&self) -> usize {
        (self.steps + 1) * self.n
    }
}

/// One move between two configurations at rest.
#[derive(Clone, Debug)]
pub struct Move<'a> {
    /// The robot.
    pub dynamics: &'a Dynamics,
    /// Where it starts and ends.
    pub start: Vec<f64>,
    /// Where it ends.
    pub goal: Vec<f64>,
    /// Steps N.
    pub steps: usize,
    /// Joint limits.
    pub q_bounds: Vec<[f64; 2]>,
    /// Joint speed limits (rad/s).
    pub v_max: Vec<f64>,
    /// Torque limits (N·m).
    pub u_max: Vec<f64>,
    /// The step's range (s).
    pub h_bounds: [f64; 2],
    /// The cost.
    pub weights: Weights,
}

pub use crate::nlp::Triplets;

impl Move<'_> {
    /// The layout.
    pub fn layout(&self) -> Layout {
        Layout {
            n: self.start.len(),
            steps: self.steps,
        }
    }

    /// The variable bounds `(x_L, x_U)`.
    pub fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let l = self.layout();
        let mut lo = vec![0.0; l.vars()];
        let mut hi = vec![0.0; l.vars()];
        for i in 0..=l.steps {
            for j in 0..l.n {
                let k = l.q(i, j);
                (lo[k], hi[k]) = if i == 0 {
                    (self.start[j], self.start[j])
                } else if i == l.steps {
                    (self.goal[j], self.goal[j])
                } else {
                    (self.q_bounds[j][0], self.q_bounds[j][1])
                };
            }
        }
        for i in 0..l.steps {
            for j in 0..l.n {
                let k = l.u(i, j);
                (lo[k], hi[k]) = (-self.u_max[j], self.u_max[j]);
            }
        }
        (lo[l.h()], hi[l.h()]) = (self.h_bounds[0], self.h_bounds[1]);
        // q̇_0 and q̇_N: at rest (already 0).
        (lo, hi)
    }

    /// The cost.
    pub fn objective(&self, x: &[f64]) -> f64 {
        let l = self.layout();
        let w = self.weights;
        let h = x[l.h()];
        let mut f = 0.0;
        for i in 0..l.steps {
            let mut uu = 0.0;
            let mut dq = 0.0;
            for j in 0..l.n {
                uu += x[l.u(i, j)].powi(2);
                dq += (x[l.q(i + 1, j)] - x[l.q(i, j)]).powi(2);
            }
            f += h * (w.time + w.effort * uu) + w.velocity * dq / h;
        }
        f
    }

    /// The cost's gradient.
    pub fn gradient(&self, x: &[f64]) -> Vec<f64> {
        let l = self.layout();
        let w = self.weights;
        let h = x[l.h()];
        let mut g = vec![0.0; l.vars()];
        for i in 0..l.steps {
            let mut uu = 0.0;
            let mut dq = 0.0;
            for j in 0..l.n {
                let u = x[l.u(i, j)];
                uu += u * u;
                g[l.u(i, j)] += 2.0 * h * w.effort * u;
                let d = x[l.q(i + 1, j)] - x[l.q(i, j)];
                dq += d * d;
                g[l.q(i + 1, j)] += 2.0 * w.velocity * d / h;
                g[l.q(i, j)] -= 2.0 * w.velocity * d / h;
            }
            g[l.h()] += w.time + w.effort * uu - w.velocity * dq / (h * h);
        }
        g
    }

    /// The equality constraints `c(x)`: start, interior, end, n rows each.
    pub fn constraints(&self, x: &[f64]) -> Vec<f64> {
        let l = self.layout();
        let n = l.n;
        let q = |i: usize| -> Vec<f64> { (0..n).map(|j| x[l.q(i, j)]).collect() };
        let u = |i: usize| -> Vec<f64> { (0..n).map(|j| x[l.u(i, j)]).collect() };
        let h = x[l.h()];
        let qd0: Vec<f64> = (0..n).map(|j| x[l.qd0(j)]).collect();
        let qdn: Vec<f64> = (0..n).map(|j| x[l.qdn(j)]).collect();
        let d = self.dynamics;
        let s = l.steps;
        let mut c = Vec::with_capacity(l.equalities());
        c.extend(start_residual(d, &q(0), &qd0, &q(1), h, &u(0)));
        for k in 1..s {
            c.extend(del_residual(d, &q(k - 1), &q(k), &q(k + 1), h, &u(k - 1), &u(k)));
        }
        c.extend(end_residual(d, &q(s - 1), &q(s), &qdn, h, &u(s - 1)));
        c
    }

    /// The linear inequalities `A x ≤ 0` (velocity bounds) as triplets, `2 n N` rows.
    pub fn inequalities(&self) -> Triplets {
        let l = self.layout();
        let mut t = Vec::with_capacity(6 * l.n * l.steps);
        let mut row = 0;
        for i in 0..l.steps {
            for j in 0..l.n {
                for sign in [1.0, -1.0] {
                    t.push((row, l.q(i + 1, j), sign));
                    t.push((row, l.q(i, j), -sign));
                    t.push((row, l.h(), -self.v_max[j]));
                    row += 1;
                }
            }
        }
        t
    }

    /// A starting point: q linear from start to goal, the torques that hold each midpoint
    /// against gravity, and a step giving the slowest joint 1.5× its least time.
    pub fn initial_guess(&self) -> Vec<f64> {
        let l = self.layout();
        let mut x = vec![0.0; l.vars()];
        let least = (0..l.n)
            .map(|j| (self.goal[j] - self.start[j]).abs() / self.v_max[j])
            .fold(0.0, f64::max);
        let h = (1.5 * least / l.steps as f64).clamp(self.h_bounds[0], self.h_bounds[1]);
        for i in 0..=l.steps {
            let s = i as f64 / l.steps as f64;
            for j in 0..l.n {
                x[l.q(i, j)] = self.start[j] + s * (self.goal[j] - self.start[j]);
            }
        }
        self.hold_against_gravity(&mut x);
        x[l.h()] = h;
        x
    }

    /// Sets the torques of `x` to those that hold each midpoint of its grid against gravity
    /// (within the torque limits).
    pub fn hold_against_gravity(&self, x: &mut [f64]) {
        let l = self.layout();
        for i in 0..l.steps {
            let mid: Vec<f64> = (0..l.n)
                .map(|j| 0.5 * (x[l.q(i, j)] + x[l.q(i + 1, j)]))
                .collect();
            let g = self.dynamics.gravity_torques(&mid);
            for j in 0..l.n {
                x[l.u(i, j)] = g[j].clamp(-self.u_max[j], self.u_max[j]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellplan_kin::load_urdf;
    use std::collections::BTreeMap;
    use std::path::Path;

    fn ur10() -> Dynamics {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/ur10");
        let packages = BTreeMap::from([("ur_description".to_string(), root.join("ur_description"))]);
        let model = load_urdf(&root.join("urdf/ur10.urdf"), &packages, None).unwrap();
        Dynamics::new(&model.chain, &model.inertia)
    }

    fn a_move(d: &Dynamics) -> Move<'_> {
        Move {
            dynamics: d,
            start: vec![0.0, -1.2, 1.0, -1.4, -1.5, 0.3],
            goal: vec![1.2, -0.8, 0.6, -1.0, -1.2, -0.4],
            steps: 8,
            q_bounds: vec![[-std::f64::consts::TAU, std::f64::consts::TAU]; 6],
            v_max: vec![2.0, 2.0, 3.0, 3.0, 3.0, 3.0],
            u_max: vec![330.0, 330.0, 150.0, 54.0, 54.0, 54.0],
            h_bounds: [1e-3, 1.0],
            weights: Weights::default(),
        }
    }

    #[test]
    fn the_jacobian_and_gradient_match_central_differences() {
        let d = ur10();
        let m = a_move(&d);
        let l = m.layout();
        let mut x = m.initial_guess();
        // Off the straight line and with velocities at the ends, so every term is exercised.
        for (k, v) in x.iter_mut().enumerate() {
            *v += 0.01 * ((k as f64) * 0.7).sin();
        }
        x[l.h()] = 0.1;
        let jac = m.jacobian(&x);
        let mut dense = vec![vec![0.0; l.vars()]; l.equalities()];
        for &(r, c, v) in &jac {
            dense[r][c] += v;
        }
        let eps = 1e-6;
        let g = m.gradient(&x);
        for c in 0..l.vars() {
            let mut up = x.clone();
            let mut down = x.clone();
            up[c] += eps;
            down[c] -= eps;
            let (cu, cd) = (m.constraints(&up), m.constraints(&down));
            for r in 0..l.equalities() {
                let fd = (cu[r] - cd[r]) / (2.0 * eps);
                assert!(
                    (fd - dense[r][c]).abs() < 1e-5 * fd.abs().max(1.0),
                    "∂c{r}/∂x{c}: {} vs {fd}",
                    dense[r][c]
                );
            }
            let fd = (m.objective(&up) - m.objective(&down)) / (2.0 * eps);
            assert!(
                (fd - g[c]).abs() < 1e-6 * fd.abs().max(1.0),
                "∂f/∂x{c}: {} vs {fd}",
                g[c]
            );
        }
    }

    #[test]
    fn the_hessian_matches_differences_of_the_exact_gradients() {
        let d = ur10();
        let m = Move {
            steps: 4,
            ..a_move(&d)
        };
        let l = m.layout();
        let mut x = m.initial_guess();
        for (k, v) in x.iter_mut().enumerate() {
            *v += 0.01 * ((k as f64) * 0.37).cos();
        }
        x[l.h()] = 0.12;
        let lambda: Vec<f64> = (0..l.equalities()).map(|r| ((r as f64) * 1.3).sin()).collect();
        let sigma = 0.7;
        let started = std::time::Instant::now();
        let hess = m.hessian(&x, &lambda, sigma);
        eprintln!(
            "hessian of {} steps in {:.1} ms",
            l.steps,
            started.elapsed().as_secs_f64() * 1e3
        );
        let nv = l.vars();
        let mut dense = vec![vec![0.0; nv]; nv];
        for &(r, c, v) in &hess {
            assert!(r >= c, "lower triangle only");
            dense[r][c] += v;
            if r != c {
                dense[c][r] += v;
            }
        }
        // ∇_x (σ f + λᵀ c) by the exact gradient and Jacobian, differenced.
        let grad_lag = |x: &[f64]| -> Vec<f64> {
            let mut g: Vec<f64> = m.gradient(x).into_iter().map(|v| sigma * v).collect();
            for (r, c, v) in m.jacobian(x) {
                g[c] += lambda[r] * v;
            }
            g
        };
        let eps = 1e-6;
        for c in 0..nv {
            let mut up = x.clone();
            let mut down = x.clone();
            up[c] += eps;
            down[c] -= eps;
            let (gu, gd) = (grad_lag(&up), grad_lag(&down));
            for r in 0..nv {
                let fd = (gu[r] - gd[r]) / (2.0 * eps);
                assert!(
                    (fd - dense[r][c]).abs() < 1e-5 * fd.abs().max(1.0),
                    "H[{r}][{c}]: {} vs {fd}",
                    dense[r][c]
                );
            }
        }
    }

    #[test]
    fn a_trajectory_of_the_integrator_satisfies_the_equalities() {
        // Integrate from rest under constant torques: the positions, torques and step then make
        // the interior and start rows vanish; the end row vanishes with the velocity the end
        // condition implies.
        let d = ur10();
        let n = 6;
        let steps = 8;
        let h = 0.02;
        let u: Vec<Vec<f64>> = (0..steps)
            .map(|i| (0..n).map(|j| 10.0 + i as f64 + j as f64).collect())
            .collect();
        let q0 = vec![0.0, -1.2, 1.0, -1.4, -1.5, 0.3];
        let qs = crate::dmoc::integrate(&d, &q0, &[0.0; 6], h, &u).unwrap();
        let m = Move {
            goal: qs[steps].clone(),
            ..a_move(&d)
        };
        let l = m.layout();
        let mut x = vec![0.0; l.vars()];
        for (i, q) in qs.iter().enumerate() {
            for j in 0..n {
                x[l.q(i, j)] = q[j];
            }
        }
        for (i, ui) in u.iter().enumerate() {
            for j in 0..n {
                x[l.u(i, j)] = ui[j];
            }
        }
        x[l.h()] = h;
        let c = m.constraints(&x);
        assert!(
            c[..steps * n].iter().all(|v| v.abs() < 1e-9),
            "{:?}",
            &c[..steps * n]
        );
        // The end row is affine in q̇_N with slope −M(q_N): one Newton step zeroes it.
        let r: Vec<f64> = c[steps * n..].to_vec();
        let mm = d.mass_matrix(&qs[steps]);
        let vn = crate::dmoc::solve_dense(mm, r).unwrap();
        for j in 0..n {
            x[l.qdn(j)] = vn[j];
        }
        let c = m.constraints(&x);
        assert!(c.iter().all(|v| v.abs() < 1e-9));
    }
}

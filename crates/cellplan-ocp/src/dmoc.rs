//! Discrete Mechanics and Optimal Control (paper 002 §2.3; Ober-Blöbaum, Junge, Marsden): the
//! robot's motion on N equal steps of length h, joint positions on the grid points, torques on
//! the midpoints, and the dynamics as the forced discrete Euler–Lagrange equations of the
//! midpoint discrete Lagrangian
//!
//! `L_d(q_k, q_{k+1}) = h · L((q_k + q_{k+1}) / 2, (q_{k+1} − q_k) / h)`, `L = ½ q̇ᵀ M(q) q̇ − V(q)`,
//!
//! with the discrete forces `f_d^± = h/2 · u_{k+½}`:
//!
//! - interior, k = 1 … N−1: `D2 L_d(q_{k−1}, q_k) + D1 L_d(q_k, q_{k+1}) + h/2 (u_{k−½} + u_{k+½}) = 0`;
//! - start (discrete Legendre transform): `∂L/∂q̇(q_0, q̇_0) + D1 L_d(q_0, q_1) + h/2 u_½ = 0`;
//! - end: `−∂L/∂q̇(q_N, q̇_N) + D2 L_d(q_{N−1}, q_N) + h/2 u_{N−½} = 0`.
//!
//! The slot derivatives at the midpoint m = (a + b)/2, velocity v = (b − a)/h:
//! `D1 L_d(a, b) = h/2 ∂L/∂q(m, v) − ∂L/∂q̇(m, v)`, `D2 L_d(a, b) = h/2 ∂L/∂q(m, v) + ∂L/∂q̇(m, v)`.
//! ∂L/∂q̇ = M(q) q̇ is one Newton–Euler recursion; ∂L/∂q is the momentum's derivative along q̇
//! less the Newton–Euler torques at zero acceleration (the Christoffel identity). Every
//! function is generic over the scalar, so the NLP's exact Jacobians and
//! Hessians are the same code run on (nested) dual numbers.
use cellplan_kin::dynamics::{Dual, Dynamics, Real};

/// Most joints a chain may have here (the width of the inner dual numbers).
pub const MAX_DOF: usize = 8;

/// ∂L/∂q at (q, v), exactly: `½ ∂(vᵀM(q)v)/∂q − g(q) = Ṁv − (C(q, v)v + g(q))`, where `Ṁv` is
/// the derivative of the momentum `M(q)v` along `v` (one dual direction) and `Cv + g` the
/// Newton–Euler torques at zero acceleration — the Christoffel identity
/// `(Cv)_i = (Ṁv)_i − ½ ∂(vᵀMv)/∂q_i`.
pub fn lagrangian_dq<T: Real>(d: &Dynamics, q: &[T], v: &[T]) -> Vec<T> {
    let qd: Vec<Dual<1, T>> = q.iter().zip(v).map(|(&x, &dx)| Dual { v: x, d: [dx] }).collect();
    let vd: Vec<Dual<1, T>> = v.iter().map(|&x| Dual::constant(x)).collect();
    let mdot_v = d.momentum(&qd, &vd);
    let bias = d.rnea_with(q, v, &[], 1.0);
    mdot_v.iter().zip(bias).map(|(m, b)| m.d[0] - b).collect()
}

/// ∂L/∂q̇ at (q, v) = M(q) v.
pub fn lagrangian_dv<T: Real>(d: &Dynamics, q: &[T], v: &[T]) -> Vec<T> {
    d.momentum(q, v)
}

/// `(D1 L_d(a, b), D2 L_d(a, b))` for step `h`.
pub fn slot_derivatives<T: Real>(d: &Dynamics, a: &[T], b: &[T], h: T) -> (Vec<T>, Vec<T>) {
    let half = T::from_f64(0.5);
    let mid: Vec<T> = a.iter().zip(b).map(|(&x, &y)| (x + y) * half).collect();
    let vel: Vec<T> = a.iter().zip(b).map(|(&x, &y)| (y - x) / h).collect();
    let lq = lagrangian_dq(d, &mid, &vel);
    let lv = lagrangian_dv(d, &mid, &vel);
    let hh = h * half;
    let d1 = lq.iter().zip(&lv).map(|(&x, &p)| hh * x - p).collect();
    let d2 = lq.iter().zip(&lv).map(|(&x, &p)| hh * x + p).collect();
    (d1, d2)
}

/// The forced discrete Euler–Lagrange residual at an interior grid point.
pub fn del_residual<T: Real>(
    d: &Dynamics,
    prev: &[T],
    here: &[T],
    next: &[T],
    h: T,
    u_before: &[T],
    u_after: &[T],
) -> Vec<T> {
    let (_, d2) = slot_derivatives(d, prev, here, h);
    let (d1, _) = slot_derivatives(d, here, next, h);
    let hh = h * T::from_f64(0.5);
    (0..here.len())
        .map(|j| d2[j] + d1[j] + hh * (u_before[j] + u_after[j]))
        .collect()
}

/// The start condition: `∂L/∂q̇(q_0, q̇_0) + D1 L_d(q_0, q_1) + h/2 u_½`.
pub fn start_residual<T: Real>(d: &Dynamics, q0: &[T], qd0: &[T], q1: &[T], h: T, u: &[T]) -> Vec<T> {
    let p = lagrangian_dv(d, q0, qd0);
    let (d1, _) = slot_derivatives(d, q0, q1, h);
    let hh = h * T::from_f64(0.5);
    (0..q0.len()).map(|j| p[j] + d1[j] + hh * u[j]).collect()
}

/// The end condition: `−∂L/∂q̇(q_N, q̇_N) + D2 L_d(q_{N−1}, q_N) + h/2 u_{N−½}`.
pub fn end_residual<T: Real>(d: &Dynamics, q_before: &[T], qn: &[T], qdn: &[T], h: T, u: &[T]) -> Vec<T> {
    let p = lagrangian_dv(d, qn, qdn);
    let (_, d2) = slot_derivatives(d, q_before, qn, h);
    let hh = h * T::from_f64(0.5);
    (0..qn.len()).map(|j| d2[j] - p[j] + hh * u[j]).collect()
}

/// Solves `A x = b` (dense, partial pivoting); `None` when singular.
pub fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-300 {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        let (top, rest) = a.split_at_mut(c + 1);
        let pivot = &top[c];
        for (r, row) in rest.iter_mut().enumerate() {
            let f = row[c] / pivot[c];
            if f != 0.0 {
                for (x, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                    *x -= f * p;
                }
                b[c + 1 + r] -= f * b[c];
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// Newton's method on `residual(x) = 0` from `x0`, the Jacobian by dual numbers.
fn newton(residual: impl Fn(&[Dual<MAX_DOF>]) -> Vec<Dual<MAX_DOF>>, x0: &[f64]) -> Option<Vec<f64>> {
    let n = x0.len();
    let mut x = x0.to_vec();
    for _ in 0..50 {
        let xd: Vec<Dual<MAX_DOF>> = x.iter().enumerate().map(|(j, &v)| Dual::variable(v, j)).collect();
        let r = residual(&xd);
        let norm = r.iter().map(|e| e.v.abs()).fold(0.0, f64::max);
        if norm < 1e-12 {
            return Some(x);
        }
        let jac: Vec<Vec<f64>> = r.iter().map(|e| e.d[..n].to_vec()).collect();
        let step = solve_dense(jac, r.iter().map(|e| -e.v).collect())?;
        for (xi, s) in x.iter_mut().zip(&step) {
            *xi += s;
        }
        if step.iter().map(|s| s.abs()).fold(0.0, f64::max) < 1e-14 {
            return Some(x);
        }
    }
    None
}

/// The variational integrator these equations define: from `q_0`, `q̇_0` and the midpoint
/// torques `u` (one per step), the grid positions `q_0 … q_N`, each found by Newton's method on
/// the start condition and then the interior equations. `None` when a step does not converge.
pub fn integrate(d: &Dynamics, q0: &[f64], qd0: &[f64], h: f64, u: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = q0.len();
    if n > MAX_DOF {
        return None;
    }
    let c = |v: &[f64]| -> Vec<Dual<MAX_DOF>> { v.iter().map(|&x| Dual::constant(x)).collect() };
    let hd = Dual::constant(h);
    let guess: Vec<f64> = q0.iter().zip(qd0).map(|(q, v)| q + h * v).collect();
    let u0 = u.first()?;
    let q1 = newton(|x| start_residual(d, &c(q0), &c(qd0), x, hd, &c(u0)), &guess)?;
    let mut qs = vec![q0.to_vec(), q1];
    for k in 1..u.len() {
        let (a, b) = (&qs[k - 1], &qs[k]);
        let guess: Vec<f64> = a.iter().zip(b.iter()).map(|(x, y)| 2.0 * y - x).collect();
        let next = newton(
            |x| del_residual(d, &c(a), &c(b), x, hd, &c(&u[k - 1]), &c(&u[k])),
            &guess,
        )?;
        qs.push(next);
    }
    Some(qs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellplan_kin::load_urdf_str;
    use std::collections::BTreeMap;
    use std::path::Path;

    /// A three-joint arm with offsets and full inertias (a shoulder turning about z, two
    /// pitching links).
    fn arm() -> Dynamics {
        let urdf = r#"<robot name="arm">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0 0 0.2"/><mass value="8"/><inertia ixx="0.2" ixy="0.01" ixz="0" iyy="0.25" iyz="0" izz="0.1"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.3 0 0.02" rpy="0.1 0 0.2"/><mass value="5"/><inertia ixx="0.03" ixy="0" ixz="0.002" iyy="0.2" iyz="0" izz="0.21"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.25 0.01 0"/><mass value="3"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.08" iyz="0.001" izz="0.08"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0.05 0.4"/><axis xyz="0 -1 0"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
  <joint name="j3" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0.6 0 0"/><axis xyz="0 -1 0"/><limit lower="-3" upper="3" effort="100" velocity="3"/></joint>
</robot>"#;
        let model = load_urdf_str(urdf, Path::new("arm.urdf"), &BTreeMap::new(), None).unwrap();
        Dynamics::new(&model.chain, &model.inertia)
    }

    /// q̈ from the continuous dynamics: M q̈ = τ − (C q̇ + g).
    fn accel(d: &Dynamics, q: &[f64], v: &[f64], u: &[f64]) -> Vec<f64> {
        let bias = d.inverse_dynamics(q, v, &[0.0; 3]);
        let rhs: Vec<f64> = u.iter().zip(&bias).map(|(a, b)| a - b).collect();
        solve_dense(d.mass_matrix(q), rhs).unwrap()
    }

    /// Classical Runge–Kutta on the continuous dynamics, `steps` steps of `h`.
    fn rk4(d: &Dynamics, q: &[f64], v: &[f64], u: &[f64], h: f64, steps: usize) -> Vec<f64> {
        let (mut q, mut v) = (q.to_vec(), v.to_vec());
        let add =
            |x: &[f64], y: &[f64], s: f64| -> Vec<f64> { x.iter().zip(y).map(|(a, b)| a + s * b).collect() };
        for _ in 0..steps {
            let k1v = accel(d, &q, &v, u);
            let k1q = v.clone();
            let (q2, v2) = (add(&q, &k1q, h / 2.0), add(&v, &k1v, h / 2.0));
            let k2v = accel(d, &q2, &v2, u);
            let k2q = v2.clone();
            let (q3, v3) = (add(&q, &k2q, h / 2.0), add(&v, &k2v, h / 2.0));
            let k3v = accel(d, &q3, &v3, u);
            let k3q = v3.clone();
            let (q4, v4) = (add(&q, &k3q, h), add(&v, &k3v, h));
            let k4v = accel(d, &q4, &v4, u);
            let k4q = v4;
            for j in 0..q.len() {
                q[j] += h / 6.0 * (k1q[j] + 2.0 * k2q[j] + 2.0 * k3q[j] + k4q[j]);
                v[j] += h / 6.0 * (k1v[j] + 2.0 * k2v[j] + 2.0 * k3v[j] + k4v[j]);
            }
        }
        q
    }

    #[test]
    fn the_discrete_equations_converge_to_the_continuous_dynamics_at_second_order() {
        let d = arm();
        let (q0, v0) = ([0.3, 0.5, -0.8], [0.4, -0.2, 0.9]);
        let u = [5.0, 20.0, -3.0];
        let t = 0.5;
        let exact = rk4(&d, &q0, &v0, &u, 1e-4, 5000);
        let mut errors = Vec::new();
        for steps in [50usize, 100, 200] {
            let h = t / steps as f64;
            let qs = integrate(&d, &q0, &v0, h, &vec![u.to_vec(); steps]).unwrap();
            let end = qs.last().unwrap();
            let e = end
                .iter()
                .zip(&exact)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            errors.push(e);
        }
        // Halving h quarters the error (second order), and the finest is close.
        assert!(
            errors[0] / errors[1] > 3.5 && errors[1] / errors[2] > 3.5,
            "{errors:?}"
        );
        assert!(errors[2] < 1e-3, "{errors:?}");
    }

    #[test]
    fn without_torques_the_energy_stays_in_a_band_that_shrinks_with_the_step() {
        // A variational integrator keeps the energy within an O(h²) band over long times
        // (here 10 s of a free-swinging three-link arm), with no secular drift.
        let d = arm();
        let (q0, v0) = ([0.0, 0.4, -0.3], [1.0, 0.0, 0.5]);
        let band = |h: f64| {
            let steps = (10.0 / h) as usize;
            let qs = integrate(&d, &q0, &v0, h, &vec![vec![0.0; 3]; steps]).unwrap();
            let energy = |a: &[f64], b: &[f64]| {
                let m: Vec<f64> = a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect();
                let v: Vec<f64> = a.iter().zip(b).map(|(x, y)| (y - x) / h).collect();
                d.kinetic(&m, &v) + d.potential(&m)
            };
            let e0 = energy(&qs[0], &qs[1]);
            let band = qs
                .windows(2)
                .map(|w| (energy(&w[0], &w[1]) - e0).abs())
                .fold(0.0, f64::max);
            (band, e0)
        };
        let (coarse, e0) = band(0.01);
        let (fine, _) = band(0.005);
        assert!(coarse < 0.02 * e0.abs().max(1.0), "band {coarse}, energy {e0}");
        assert!(coarse / fine > 3.0, "band {coarse} at h = 0.01, {fine} at 0.005");
    }

    #[test]
    fn the_boundary_conditions_hold_on_the_integrator_s_own_trajectory() {
        // Integrate, then read the end velocity from the end condition: it must match the
        // continuous velocity to second order, and the start condition holds by construction.
        let d = arm();
        let (q0, v0) = ([0.1, 0.2, 0.3], [0.3, 0.1, -0.2]);
        let u = vec![vec![1.0, 10.0, 2.0]; 100];
        let h = 0.005;
        let qs = integrate(&d, &q0, &v0, h, &u).unwrap();
        let r = start_residual(&d, &q0, &v0, &qs[1], h, &u[0]);
        assert!(r.iter().all(|x| x.abs() < 1e-10), "{r:?}");
        // The end momentum p_N = D2 L_d(q_{N−1}, q_N) + h/2 u: solve M(q_N) q̇_N = p_N.
        let n = qs.len() - 1;
        let (_, d2) = slot_derivatives(&d, &qs[n - 1], &qs[n], h);
        let p: Vec<f64> = d2.iter().zip(&u[n - 1]).map(|(a, b)| a + 0.5 * h * b).collect();
        let vn = solve_dense(d.mass_matrix(&qs[n]), p).unwrap();
        let r = end_residual(&d, &qs[n - 1], &qs[n], &vn, h, &u[n - 1]);
        assert!(r.iter().all(|x| x.abs() < 1e-10), "{r:?}");
        // Against the continuous velocity after the same time.
        let t_steps = 5000;
        let exact_v = {
            let (mut q, mut v) = (q0.to_vec(), v0.to_vec());
            let hh = h * n as f64 / t_steps as f64;
            for _ in 0..t_steps {
                let a = accel(&d, &q, &v, &u[0]);
                for j in 0..3 {
                    q[j] += hh * v[j] + 0.5 * hh * hh * a[j];
                    v[j] += hh * a[j];
                }
            }
            v
        };
        let err = vn
            .iter()
            .zip(&exact_v)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 5e-3, "end velocity {vn:?} vs {exact_v:?}");
    }
}

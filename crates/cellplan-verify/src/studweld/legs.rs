//! The moves of a stud-weld plan: continuity, the discrete Euler–Lagrange equations of DMOC
//! (paper 002 §2.3) re-evaluated with `cellplan_kin::dynamics`, limits, clearance along the
//! whole motion, J and duration.
//!
//! With `L(q, v) = ½ vᵀM(q)v − V(q)` and the midpoint rule `L_d(a, b) = h L((a+b)/2, (b−a)/h)`:
//! `D₁L_d(a, b) = (h/2) ∂L/∂q − M v` and `D₂L_d(a, b) = (h/2) ∂L/∂q + M v` at the midpoint, and
//! at rest the boundary conditions of the discrete Legendre transform reduce to
//! `D₁L_d(q₀, q₁) + (h/2) u_½ = 0` and `D₂L_d(q_{N−1}, q_N) + (h/2) u_{N−½} = 0`.
use super::{Ctx, WeldViolationKind, close};
use crate::paths::{Prover, gaps};
use cellplan_kin::dynamics::{Dual, Real};
use cellplan_model::robot::Scratch;
use cellplan_studweld::document::WeldPlan;
use cellplan_studweld::leg::Motion;

/// Tolerance of the discrete Euler–Lagrange residuals, relative to the size of their terms.
pub const DEL_TOL: f64 = 1e-6;
/// Samples per phase of each piece of a timed path for J and the torques.
const SAMPLES: usize = 256;
/// Relative tolerance of a timed path's J (a finer quadrature than the planner's).
const QUAD_TOL: f64 = 1e-3;

/// `(∂L/∂q, M v)` at the midpoint of `a → b` over `h`.
fn parts(c: &Ctx, a: &[f64], b: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
    let n = a.len();
    let m: Vec<f64> = a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect();
    let v: Vec<f64> = a.iter().zip(b).map(|(x, y)| (y - x) / h).collect();
    let qd: Vec<Dual<8>> = (0..n).map(|j| Dual::variable(m[j], j)).collect();
    let vd: Vec<Dual<8>> = v.iter().map(|&x| Dual::constant(x)).collect();
    let l = c.dynamics.kinetic(&qd, &vd) - c.dynamics.potential(&qd);
    let dl = (0..n).map(|j| l.d[j]).collect();
    let mm = c.dynamics.mass_matrix(&m);
    let p = (0..n).map(|i| (0..n).map(|j| mm[i][j] * v[j]).sum()).collect();
    (dl, p)
}

/// Checks every move.
pub(super) fn check(c: &mut Ctx, plan: &WeldPlan) {
    let home = c.robot.home.clone();
    let ends: Vec<Vec<f64>> = std::iter::once(home.clone())
        .chain(plan.visits.iter().map(|v| v.q.clone()))
        .chain(std::iter::once(home))
        .collect();
    if plan.legs.len() != ends.len() - 1 {
        c.fail(
            WeldViolationKind::Continuity,
            format!("{} moves for {} welds", plan.legs.len(), plan.visits.len()),
        );
        return;
    }
    // The verifier's own proof of clearance (as for inspection legs), not the planner's check.
    let gaps = gaps(c.cell, c.robot);
    let mut prover = Prover::new(
        c.cell,
        c.robot,
        &gaps,
        crate::VerifySettings::default().joint_step,
    );
    let mut scratch = Scratch::default();
    let wt = c.process.weights;
    for (i, leg) in plan.legs.iter().enumerate() {
        let name = format!("move {i} ({} → {})", leg.from, leg.to);
        let pieces: Vec<Vec<f64>> = match &leg.motion {
            Motion::Ocp(d) => d.q.clone(),
            Motion::TimedPath { waypoints, .. } => waypoints.clone(),
        };
        let (Some(first), Some(last)) = (pieces.first(), pieces.last()) else {
            c.fail(WeldViolationKind::Format, format!("{name}: no positions"));
            continue;
        };
        let off = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        if first.len() != c.robot.dof() || off(first, &ends[i]) > 1e-9 || off(last, &ends[i + 1]) > 1e-9 {
            c.fail(
                WeldViolationKind::Continuity,
                format!("{name} does not join its ends"),
            );
            continue;
        }
        for q in &pieces {
            if !c.robot.within_limits(q) {
                c.fail(
                    WeldViolationKind::JointLimit,
                    format!("{name}: outside the joint limits"),
                );
                break;
            }
        }
        for (k, s) in pieces.windows(2).enumerate() {
            c.segments += 1;
            if let Err((kind, detail)) = prover.segment(&s[0], &s[1], &mut scratch) {
                let kind = if kind == crate::ViolationKind::JointLimit {
                    WeldViolationKind::JointLimit
                } else {
                    WeldViolationKind::Collision
                };
                c.fail(kind, format!("{name}: piece {k}: {detail}"));
                break;
            }
        }
        let (cost, duration) = match &leg.motion {
            Motion::Ocp(d) => dmoc(c, &name, d),
            Motion::TimedPath {
                waypoints,
                acceleration_scale,
            } => timed(c, &name, waypoints, *acceleration_scale, wt),
        };
        if !close(duration, leg.duration_s) {
            c.fail(
                WeldViolationKind::Total,
                format!("{name}: {} s stated, {duration} s re-derived", leg.duration_s),
            );
        }
        let tol = if matches!(leg.motion, Motion::Ocp(_)) {
            1e-9
        } else {
            QUAD_TOL
        };
        if (cost - leg.cost).abs() > tol * cost.abs().max(1.0) {
            c.fail(
                WeldViolationKind::Total,
                format!("{name}: J {} stated, {cost} re-derived", leg.cost),
            );
        }
    }
}

/// The DMOC checks of one move; returns (J, duration).
fn dmoc(c: &mut Ctx, name: &str, d: &cellplan_studweld::leg::Dmoc) -> (f64, f64) {
    let n = c.robot.dof();
    let steps = d.u.len();
    let wt = c.process.weights;
    if d.q.len() != steps + 1 || steps == 0 || d.h.is_nan() || d.h <= 0.0 || d.u.iter().any(|u| u.len() != n)
    {
        c.fail(WeldViolationKind::Format, format!("{name}: malformed trajectory"));
        return (f64::NAN, f64::NAN);
    }
    let h = d.h;
    let mut cost = 0.0;
    for i in 0..steps {
        let (a, b, u) = (&d.q[i], &d.q[i + 1], &d.u[i]);
        for j in 0..n {
            if (b[j] - a[j]).abs() > h * c.robot.max_velocity[j] * (1.0 + 1e-9) + 1e-12 {
                c.fail(
                    WeldViolationKind::Velocity,
                    format!("{name}: joint {} too fast on step {i}", j + 1),
                );
            }
            if u[j].abs() > c.process.max_torque[j] * (1.0 + 1e-9) {
                c.fail(
                    WeldViolationKind::Torque,
                    format!("{name}: joint {} torque {:.1} N·m on step {i}", j + 1, u[j]),
                );
            }
        }
        let uu: f64 = u.iter().map(|x| x * x).sum();
        let vv: f64 = a.iter().zip(b).map(|(x, y)| ((y - x) / h).powi(2)).sum();
        cost += h * (wt.time + wt.effort * uu + wt.velocity * vv);
    }
    // Row k: D₂L_d(q_{k−1}, q_k) + D₁L_d(q_k, q_{k+1}) + h/2 (u_{k−½} + u_{k+½}); rows 0 and N
    // keep only their one side (rest at both ends).
    let pieces: Vec<(Vec<f64>, Vec<f64>)> = (0..steps).map(|i| parts(c, &d.q[i], &d.q[i + 1], h)).collect();
    for k in 0..=steps {
        let mut res = vec![0.0; n];
        let mut size = vec![0.0f64; n];
        if k > 0 {
            let (dl, p) = &pieces[k - 1];
            for j in 0..n {
                let t = [0.5 * h * dl[j], p[j], 0.5 * h * d.u[k - 1][j]];
                res[j] += t.iter().sum::<f64>();
                size[j] = t.iter().fold(size[j], |s, x| s.max(x.abs()));
            }
        }
        if k < steps {
            let (dl, p) = &pieces[k];
            for j in 0..n {
                let t = [0.5 * h * dl[j], -p[j], 0.5 * h * d.u[k][j]];
                res[j] += t.iter().sum::<f64>();
                size[j] = t.iter().fold(size[j], |s, x| s.max(x.abs()));
            }
        }
        for j in 0..n {
            let rel = res[j].abs() / size[j].max(1e-3);
            c.max_residual = c.max_residual.max(rel);
            if rel > DEL_TOL {
                c.fail(
                    WeldViolationKind::Dynamics,
                    format!("{name}: discrete Euler–Lagrange row {k}, joint {}: residual {:.2e} N·m·s ({rel:.1e} of its terms)", j + 1, res[j]),
                );
                return (cost, steps as f64 * h);
            }
        }
    }
    (cost, steps as f64 * h)
}

/// A timed path: each piece straight, the path parameter on the fastest trapezoid within the
/// speed and (scaled) acceleration limits, rest at each waypoint; J by the midpoint rule on
/// [`SAMPLES`] per piece with the torques of inverse dynamics; the torque limits at every sample.
fn timed(
    c: &mut Ctx,
    name: &str,
    waypoints: &[Vec<f64>],
    scale: f64,
    wt: cellplan_studweld::process::Weights,
) -> (f64, f64) {
    let (mut cost, mut duration) = (0.0, 0.0);
    if !(scale > 0.0 && scale <= 1.0) {
        c.fail(
            WeldViolationKind::Format,
            format!("{name}: acceleration scale {scale}"),
        );
        return (f64::NAN, f64::NAN);
    }
    let mut torque_ok = true;
    for s in waypoints.windows(2) {
        let (a, b) = (&s[0], &s[1]);
        let (mut vs, mut acc) = (f64::INFINITY, f64::INFINITY);
        for j in 0..a.len() {
            let d = (b[j] - a[j]).abs();
            if d > 0.0 {
                vs = vs.min(c.robot.max_velocity[j] / d);
                acc = acc.min(scale * c.robot.max_acceleration[j] / d);
            }
        }
        if !vs.is_finite() {
            continue;
        }
        // Triangle when the peak speed is not reached, else trapezoid.
        let (ta, total) = if vs * vs / acc >= 1.0 {
            let ta = (1.0 / acc).sqrt();
            (ta, 2.0 * ta)
        } else {
            (vs / acc, 1.0 / vs + vs / acc)
        };
        // Each phase (accelerate, cruise, decelerate) on its own samples: the torques jump
        // between phases.
        let phases = [[0.0, ta], [ta, total - ta], [total - ta, total]];
        for k in (0..3 * SAMPLES).filter(|k| phases[k / SAMPLES][1] > phases[k / SAMPLES][0]) {
            let [t0, t1] = phases[k / SAMPLES];
            let dt = (t1 - t0) / SAMPLES as f64;
            let t = t0 + ((k % SAMPLES) as f64 + 0.5) * dt;
            let (sv, sd, sdd) = if t < ta {
                (0.5 * acc * t * t, acc * t, acc)
            } else if t <= total - ta {
                (0.5 * acc * ta * ta + acc * ta * (t - ta), acc * ta, 0.0)
            } else {
                let r = total - t;
                (1.0 - 0.5 * acc * r * r, acc * r, -acc)
            };
            let q: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + sv * (y - x)).collect();
            let qd: Vec<f64> = a.iter().zip(b).map(|(x, y)| sd * (y - x)).collect();
            let qdd: Vec<f64> = a.iter().zip(b).map(|(x, y)| sdd * (y - x)).collect();
            let u = c.dynamics.rnea_with(&q, &qd, &qdd, 1.0);
            if torque_ok
                && let Some(j) = (0..u.len()).find(|&j| u[j].abs() > c.process.max_torque[j] * (1.0 + 1e-6))
            {
                torque_ok = false;
                c.fail(
                    WeldViolationKind::Torque,
                    format!("{name}: joint {} torque {:.1} N·m", j + 1, u[j].value()),
                );
            }
            let uu: f64 = u.iter().map(|x| x * x).sum();
            let vv: f64 = qd.iter().map(|x| x * x).sum();
            cost += dt * (wt.time + wt.effort * uu + wt.velocity * vv);
        }
        duration += total;
    }
    (cost, duration)
}

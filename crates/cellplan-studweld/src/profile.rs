//! What a move does over time, for the report's plots: joint velocities and torques, each as a
//! fraction of its limit.
//!
//! - A DMOC trajectory is drawn as the transcription states it: on each step the velocity is the
//!   difference quotient `(q_{k+1} − q_k) / h` and the torque the midpoint torque `u_k`, both
//!   constant over the step (two samples per step, at its ends).
//! - A timed path is sampled [`crate::leg::PATH_SAMPLES`] times per segment along its trapezoid,
//!   the torque by inverse dynamics, as [`crate::leg::timed_path_cost`] integrates J.
use crate::cell::WeldCell;
use crate::leg::{Motion, PATH_SAMPLES, segment_profile};

/// A move sampled over time (from the move's start).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Profile {
    /// Sample times (s), non-decreasing.
    pub t: Vec<f64>,
    /// Joint velocities / the joints' speed limits, per sample.
    pub velocity: Vec<Vec<f64>>,
    /// Joint torques / the joints' torque limits, per sample.
    pub torque: Vec<Vec<f64>>,
}

impl Profile {
    /// The largest |value| of each series (velocity, torque): 1 is the limit.
    pub fn peaks(&self) -> (f64, f64) {
        let peak = |s: &[Vec<f64>]| s.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        (peak(&self.velocity), peak(&self.torque))
    }
}

/// The profile of `motion` in cell `w`.
pub fn profile(w: &WeldCell, motion: &Motion) -> Profile {
    let ratio = |v: Vec<f64>, lim: &[f64]| -> Vec<f64> {
        v.iter()
            .zip(lim)
            .map(|(x, l)| if *l > 0.0 { x / l } else { 0.0 })
            .collect()
    };
    let mut p = Profile::default();
    match motion {
        Motion::Ocp(d) => {
            for (k, u) in d.u.iter().enumerate() {
                let (a, b) = (&d.q[k], &d.q[k + 1]);
                let qd: Vec<f64> = a.iter().zip(b).map(|(x, y)| (y - x) / d.h).collect();
                let v = ratio(qd, &w.v_max);
                let u = ratio(u.clone(), &w.process.max_torque);
                for t in [k as f64 * d.h, (k + 1) as f64 * d.h] {
                    p.t.push(t);
                    p.velocity.push(v.clone());
                    p.torque.push(u.clone());
                }
            }
        }
        Motion::TimedPath {
            waypoints,
            acceleration_scale,
        } => {
            let mut t0 = 0.0;
            for s in waypoints.windows(2) {
                let (a, b) = (&s[0], &s[1]);
                let (dur, _, f) =
                    segment_profile(a, b, &w.v_max, &w.robot.max_acceleration, *acceleration_scale);
                for i in 0..=PATH_SAMPLES {
                    let t = dur * i as f64 / PATH_SAMPLES as f64;
                    let [sv, sd, sdd] = f(t);
                    let q: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + sv * (y - x)).collect();
                    let qd: Vec<f64> = a.iter().zip(b).map(|(x, y)| sd * (y - x)).collect();
                    let qdd: Vec<f64> = a.iter().zip(b).map(|(x, y)| sdd * (y - x)).collect();
                    let u = w.dynamics.inverse_dynamics(&q, &qd, &qdd);
                    p.t.push(t0 + t);
                    p.velocity.push(ratio(qd, &w.v_max));
                    p.torque.push(ratio(u, &w.process.max_torque));
                }
                t0 += dur;
            }
        }
    }
    p
}

/// The torques of holding `q` (gravity) / the limits: what a weld does over its weld time.
pub fn holding(w: &WeldCell, q: &[f64]) -> Vec<f64> {
    w.dynamics
        .gravity_torques(q)
        .iter()
        .zip(&w.process.max_torque)
        .map(|(g, l)| if *l > 0.0 { g / l } else { 0.0 })
        .collect()
}

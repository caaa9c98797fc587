//! The alternatives of each stud (paper 002 §2.1, Table 1): every inverse-kinematics branch of
//! every gun rotation about the stud axis whose reached pose welds within the pose tolerance
//! ([`crate::process::WELD_POSE_TOLERANCE`], the process's `pose_check`), is collision-free
//! (the leg planner's own validity test at the cell's clearance) and whose holding torques are
//! within the limits; each with its node cost, holding the pose for the weld time under gravity.
use crate::cell::WeldCell;
use cellplan_core::candidates::{reach, wrap};
use cellplan_core::motion::robot_validity;
use cellplan_model::Rejection;
use rayon::prelude::*;

/// One way to weld a stud.
#[derive(Clone, Debug, PartialEq)]
pub struct Alternative {
    /// The stud (index into the cell's tasks).
    pub stud: usize,
    /// The gun's rotation about the stud axis (rad).
    pub rotation: f64,
    /// The joint configuration.
    pub q: Vec<f64>,
    /// Cost of holding it for the weld time: `weld_time · (c_t + c_e |g(q)|²)`.
    pub weld_cost: f64,
}

/// Why a stud has no alternative.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoAlternative {
    /// The furthest stage any gun pose reached (out of reach, joint limits, collision).
    Rejected(Rejection),
    /// Poses were reached without collision but holding them needs more than the torque
    /// limits.
    Torque,
}

impl NoAlternative {
    /// Stable short name (as in JSON).
    pub fn code(self) -> &'static str {
        match self {
            NoAlternative::Rejected(r) => r.code(),
            NoAlternative::Torque => "torque",
        }
    }

    /// For people.
    pub fn text(self) -> &'static str {
        match self {
            NoAlternative::Rejected(r) => r.text(),
            NoAlternative::Torque => "every reachable pose needs more than the torque limits to hold",
        }
    }
}

/// The alternatives of every stud, and the studs that have none.
#[derive(Clone, Debug, Default)]
pub struct Alternatives {
    /// Per stud (task order), its alternatives (empty when unweldable).
    pub per_stud: Vec<Vec<Alternative>>,
    /// Studs without an alternative and why.
    pub unweldable: Vec<(usize, NoAlternative)>,
}

/// The holding cost of `q` for `time` seconds: `time · (c_t + c_e |g(q)|²)` (velocity 0).
pub fn hold_cost(w: &WeldCell, q: &[f64], time: f64) -> f64 {
    let g = w.dynamics.gravity_torques(q);
    let gg: f64 = g.iter().map(|v| v * v).sum();
    time * (w.process.weights.time + w.process.weights.effort * gg)
}

/// Whether the gravity torques at `q` are within the limits.
pub fn holds(w: &WeldCell, q: &[f64]) -> bool {
    let g = w.dynamics.gravity_torques(q);
    g.iter().zip(&w.process.max_torque).all(|(g, m)| g.abs() <= *m)
}

/// Weighted distance to `home` (time-like: |Δq_j| / v_max_j summed).
fn to_home(w: &WeldCell, q: &[f64]) -> f64 {
    q.iter()
        .zip(&w.robot.home)
        .zip(&w.v_max)
        .map(|((a, b), v)| (a - b).abs() / v)
        .sum()
}

/// The alternatives of every stud: rotations in steps of the process's `gun_rotation_step`,
/// every IK branch within the joint limits, collision-free at the cell's clearance. Of the
/// configurations that differ only by full turns of a joint (the same geometry), the one
/// nearest home is kept. Parallel over studs; the result does not depend on the thread count.
pub fn alternatives(w: &WeldCell) -> Alternatives {
    let cell = w.cell;
    let validity = robot_validity(cell, w.robot, cell.planning.clearance);
    let process = cell.process.as_ref();
    let rotations = w.process.rotations();
    let found: Vec<(Vec<Alternative>, Option<NoAlternative>)> = cell
        .tasks
        .par_iter()
        .enumerate()
        .map(|(stud, task)| {
            let mut out: Vec<Alternative> = Vec::new();
            let mut furthest: Option<Rejection> = None;
            let mut too_heavy = false;
            for k in 0..rotations {
                let rotation = k as f64 * w.process.rotation_step;
                let pose = crate::process::gun_pose(task.position, task.normal, rotation);
                let r = reach(cell, process, w.robot, task, &[pose], &validity);
                if let Some(why) = r.reason() {
                    furthest = furthest.max(Some(why));
                }
                let mut kept: Vec<Vec<f64>> = Vec::new();
                for c in r.candidates {
                    if !holds(w, &c.q) {
                        too_heavy = true;
                        continue;
                    }
                    match kept
                        .iter_mut()
                        .find(|p| p.iter().zip(&c.q).all(|(a, b)| wrap(a - b).abs() < 1e-9))
                    {
                        Some(p) => {
                            if to_home(w, &c.q) < to_home(w, p) {
                                *p = c.q;
                            }
                        }
                        None => kept.push(c.q),
                    }
                }
                out.extend(kept.into_iter().map(|q| Alternative {
                    stud,
                    rotation,
                    weld_cost: hold_cost(w, &q, w.process.weld_time),
                    q,
                }));
            }
            let why = out.is_empty().then(|| {
                if too_heavy {
                    NoAlternative::Torque
                } else {
                    NoAlternative::Rejected(furthest.unwrap_or(Rejection::NoIk))
                }
            });
            (out, why)
        })
        .collect();
    let mut all = Alternatives::default();
    for (stud, (alts, why)) in found.into_iter().enumerate() {
        if let Some(why) = why {
            all.unweldable.push((stud, why));
        }
        all.per_stud.push(alts);
    }
    all
}

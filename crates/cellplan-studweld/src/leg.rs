//! One move between two configurations at rest (paper 002 §2.2–2.4): a collision-free path of
//! the motion planner; the DMOC optimal-control problem ([`cellplan_ocp::problem::Move`],
//! solved by [`cellplan_ocp::nlp`]) started along that path — zero torques first, then the
//! gravity torques (the KR 210 has several local optima, and from some starts the solver ends
//! `RestorationFailed`); the solved trajectory is checked densely for collisions (every
//! segment between grid points by the motion core's conservative segment check); when the
//! optimum collides, the §2.4 trust regions ([`crate::trust`]) from a path with room
//! ([`roomy_path`]); when they give no collision-free trajectory, or one dearer than the
//! planner's path timed (a synchronised trapezoid in the path parameter on each segment, rest
//! at each waypoint, J integrated along it), the leg is that timed path, and it says why.
use crate::cell::WeldCell;
use crate::trust::{self, TrustSettings};
use cellplan_core::motion::{joint_space, plan_leg, robot_validity};
use cellplan_motion::plan::{PlanSettings, check_segment};
use cellplan_motion::timing::joint_min_time;
use cellplan_ocp::nlp::{self, Status};
use cellplan_ocp::problem::Move;
use std::time::Duration;

/// Samples per path segment of a timed-path leg for J's quadrature and the torque check.
pub const PATH_SAMPLES: usize = 64;

/// A trajectory in DMOC form: `q_0 … q_N` on a grid of step `h`, torques at the midpoints.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
pub struct Dmoc {
    /// Step (s).
    pub h: f64,
    /// Joint positions on the grid (N + 1).
    pub q: Vec<Vec<f64>>,
    /// Torques at the midpoints (N).
    pub u: Vec<Vec<f64>>,
}

/// How a leg moves.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Motion {
    /// The optimal-control solution.
    Ocp(Dmoc),
    /// The planner's path, each segment timed rest to rest (the fallback).
    TimedPath {
        /// Waypoints.
        waypoints: Vec<Vec<f64>>,
        /// Acceleration scale used (≤ 1: lowered until the torques held).
        acceleration_scale: f64,
    },
}

/// One solved move.
#[derive(Clone, Debug, PartialEq)]
pub struct Leg {
    /// The motion.
    pub motion: Motion,
    /// J of the move.
    pub cost: f64,
    /// Its duration (s).
    pub duration: f64,
    /// Solver iterations spent (all attempts).
    pub iterations: usize,
    /// Optimal-control problems solved for it.
    pub solves: usize,
    /// Accepted trust-region iterations (0: the unconstrained optimum was clear).
    pub trust_iterations: usize,
    /// Why it is a timed path, when it is.
    pub fallback: Option<String>,
}

/// Settings of the legs.
#[derive(Clone, Debug)]
pub struct LegSettings {
    /// Seed of the motion planner.
    pub seed: u64,
    /// Most samples of the motion planner.
    pub max_samples: usize,
    /// Most interior-point iterations per solve.
    pub max_iter: usize,
}

impl Default for LegSettings {
    fn default() -> Self {
        LegSettings {
            seed: 0,
            max_samples: 20_000,
            max_iter: 400,
        }
    }
}

/// The least time (s) of the straight segment `a → b` at the speed limits.
fn segment_time(a: &[f64], b: &[f64], v: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .zip(v)
        .map(|((x, y), v)| (y - x).abs() / v)
        .fold(0.0, f64::max)
}

/// The quintic rest-to-rest profile `10τ³ − 15τ⁴ + 6τ⁵` (zero speed and acceleration at both
/// ends).
fn quintic(t: f64) -> f64 {
    t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
}

/// `steps + 1` points along the polyline, at the fractions `profile(τ)` of its least time for
/// τ spread over [0, 1], with every waypoint among them (so that the straight pieces between
/// grid points are pieces of the path, which the planner proved clear): segment k spans
/// `τ ∈ [τ_k, τ_{k+1}]` (`profile(τ_k)` its start's fraction); it gets at least one step and the
/// rest in proportion to its span (largest remainders), its points at evenly spaced τ.
/// `profile` must increase from 0 to 1; `steps` must be at least the number of segments.
fn resample(path: &[Vec<f64>], v: &[f64], steps: usize, profile: fn(f64) -> f64) -> Vec<Vec<f64>> {
    let lengths: Vec<f64> = path.windows(2).map(|s| segment_time(&s[0], &s[1], v)).collect();
    let total: f64 = lengths.iter().sum();
    let segments = lengths.len();
    // τ at each waypoint, by bisection of the profile.
    let mut cum = 0.0;
    let mut tau = vec![0.0];
    for l in &lengths {
        cum += l;
        let target = if total > 0.0 { cum / total } else { 1.0 };
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if profile(mid) < target { lo = mid } else { hi = mid }
        }
        tau.push(hi);
    }
    if let Some(last) = tau.last_mut() {
        *last = 1.0;
    }
    let spare = steps.saturating_sub(segments);
    let share: Vec<f64> = (0..segments)
        .map(|k| spare as f64 * (tau[k + 1] - tau[k]))
        .collect();
    let mut count: Vec<usize> = share.iter().map(|x| 1 + x.floor() as usize).collect();
    let mut order: Vec<usize> = (0..segments).collect();
    order.sort_by(|&a, &b| {
        (share[b] - share[b].floor())
            .total_cmp(&(share[a] - share[a].floor()))
            .then(a.cmp(&b))
    });
    let mut left = steps.saturating_sub(count.iter().sum::<usize>());
    for &k in order.iter().cycle().take(4 * segments.max(1)) {
        if left == 0 {
            break;
        }
        count[k] += 1;
        left -= 1;
    }
    let mut grid = vec![path[0].clone()];
    for (k, c) in count.iter().enumerate() {
        let start: f64 = lengths[..k].iter().sum();
        for i in 1..=*c {
            if i == *c {
                grid.push(path[k + 1].clone());
                continue;
            }
            let t = tau[k] + (tau[k + 1] - tau[k]) * i as f64 / *c as f64;
            let s = if lengths[k] > 0.0 {
                ((profile(t) * total - start) / lengths[k]).clamp(0.0, 1.0)
            } else {
                1.0
            };
            grid.push(
                path[k]
                    .iter()
                    .zip(&path[k + 1])
                    .map(|(a, b)| a + s * (b - a))
                    .collect(),
            );
        }
    }
    grid
}

/// The grid along `path` (`profile` of time, every waypoint on the grid, the ends exactly the
/// move's), zero torques, and the step at `slack` × the path's least time at the joints'
/// speeds.
fn along(m: &Move, path: &[Vec<f64>], profile: fn(f64) -> f64, slack: f64) -> Vec<f64> {
    let l = m.layout();
    let least: f64 = path
        .windows(2)
        .map(|s| segment_time(&s[0], &s[1], &m.v_max))
        .sum();
    let grid = resample(path, &m.v_max, l.steps, profile);
    let mut x = vec![0.0; l.vars()];
    for (i, q) in grid.iter().enumerate() {
        for j in 0..l.n {
            x[l.q(i, j)] = if i == 0 {
                m.start[j]
            } else if i == l.steps {
                m.goal[j]
            } else {
                q[j].clamp(m.q_bounds[j][0], m.q_bounds[j][1])
            };
        }
    }
    x[l.h()] = (slack * least / l.steps as f64).clamp(m.h_bounds[0], m.h_bounds[1]);
    x
}

/// The target of the trust regions' first iterate: the grid at rest-to-rest positions along
/// the path (`quintic` in time, waypoints on the grid), so that a trajectory of the dynamics
/// lies near it; the step giving a mean speed of half the slowest joint's limit
/// (the quintic peaks at 1.875× the mean); zero torques.
pub fn rest_to_rest_guess(m: &Move, path: &[Vec<f64>]) -> Vec<f64> {
    along(m, path, quintic, 2.0)
}

/// DMOC steps for a move along `path`: the process's, or one per path segment when more.
pub fn steps_for(w: &WeldCell, path: &[Vec<f64>]) -> usize {
    w.process.steps.max(path.len().saturating_sub(1))
}

/// The OCP of the move `a → b` in the cell.
pub fn ocp<'a>(w: &'a WeldCell, a: &[f64], b: &[f64]) -> Move<'a> {
    Move {
        dynamics: &w.dynamics,
        start: a.to_vec(),
        goal: b.to_vec(),
        steps: w.process.steps,
        q_bounds: w.q_bounds.clone(),
        v_max: w.v_max.clone(),
        u_max: w.process.max_torque.clone(),
        h_bounds: [1e-3, 1.0],
        weights: w.process.weights,
    }
}

/// The starting point along `path`: positions resampled, the step giving the slowest joint
/// 1.5× its least time, torques zero or the gravity torques at the midpoints.
fn guess(m: &Move, path: &[Vec<f64>], gravity: bool) -> Vec<f64> {
    let mut x = along(m, path, |t| t, 1.5);
    if gravity {
        m.hold_against_gravity(&mut x);
    }
    x
}

/// The DMOC trajectory in `x`.
pub fn unpack(m: &Move, x: &[f64]) -> Dmoc {
    let l = m.layout();
    Dmoc {
        h: x[l.h()],
        q: (0..=l.steps)
            .map(|i| (0..l.n).map(|j| x[l.q(i, j)]).collect())
            .collect(),
        u: (0..l.steps)
            .map(|i| (0..l.n).map(|j| x[l.u(i, j)]).collect())
            .collect(),
    }
}

/// Whether the grid's straight segments are all collision-free at the cell's clearance.
pub fn clear(w: &WeldCell, q: &[Vec<f64>]) -> bool {
    let space = joint_space(w.cell, w.robot);
    let validity = robot_validity(w.cell, w.robot, w.cell.planning.clearance);
    let min = PlanSettings::default().min_clearance;
    q.windows(2)
        .all(|s| check_segment(&space, &validity, &s[0], &s[1], min).valid)
}

/// The collision-free path `a → b` of the motion planner (deterministic: a work budget, the
/// wall clock only as a far safety net).
pub fn path(w: &WeldCell, a: &[f64], b: &[f64], s: &LegSettings) -> Option<Vec<Vec<f64>>> {
    let settings = PlanSettings {
        seed: s.seed,
        max_samples: s.max_samples,
        time_limit: Duration::from_secs(600),
        ..PlanSettings::default()
    };
    plan_leg(w.cell, w.robot, a, b, &settings)
        .ok()
        .map(|p| p.waypoints)
}

/// How far (m) the start of a trust-region iteration backs the gun out along its axis at
/// either end before its middle is planned with [`ROOM`] more clearance.
pub const RETRACT: f64 = 0.1;

/// Clearance (m) beyond the cell's that the middle of a trust-region start keeps, tried in
/// turn: the boxes of §2.4 are as wide as the grid's clearance allows.
pub const ROOM: [f64; 2] = [0.05, 0.02];

/// A path `a → b` with room for the trust regions: out along the gun's axis by [`RETRACT`],
/// the middle planned with the cell's clearance plus [`ROOM`], in along the axis; each retract
/// one straight joint segment to the end of the gun's line, checked with the cell's clearance. `None` when no such path is found.
pub fn roomy_path(w: &WeldCell, a: &[f64], b: &[f64], s: &LegSettings) -> Option<Vec<Vec<f64>>> {
    let chain = &w.robot.model.chain;
    // The retracts' ends, reached by one straight joint segment each (a grid point per
    // retract: the DMOC's steps are equal in time).
    let out_of = |q: &[f64]| -> Option<Vec<Vec<f64>>> {
        let line = cellplan_motion::arm::tool_retract(chain, &w.robot.tool.tcp, q, RETRACT, 0.01)?;
        let seg = vec![q.to_vec(), line.last()?.clone()];
        clear(w, &seg).then_some(seg)
    };
    let exit = out_of(a)?;
    let mut entry = out_of(b)?;
    entry.reverse();
    let space = joint_space(w.cell, w.robot);
    let settings = PlanSettings {
        seed: s.seed,
        max_samples: s.max_samples,
        time_limit: Duration::from_secs(600),
        ..PlanSettings::default()
    };
    let (from, to) = (exit.last()?, entry.first()?);
    ROOM.iter().find_map(|extra| {
        let validity = robot_validity(w.cell, w.robot, w.cell.planning.clearance + extra);
        let middle = cellplan_motion::plan::plan_leg(&space, &validity, from, to, &settings).ok()?;
        let mut path = exit.clone();
        path.extend(middle.waypoints.into_iter().skip(1));
        path.extend(entry.iter().skip(1).cloned());
        Some(path)
    })
}

/// The move `a → b`: `None` when the planner finds no collision-free path.
pub fn solve(w: &WeldCell, a: &[f64], b: &[f64], s: &LegSettings) -> Option<Leg> {
    let path = path(w, a, b, s)?;
    let m = Move {
        steps: steps_for(w, &path),
        ..ocp(w, a, b)
    };
    let opt = nlp::Options {
        tol: 1e-8,
        max_iter: s.max_iter,
        ..nlp::Options::default()
    };
    let mut iterations = 0;
    let mut solves = 0;
    let mut why = Vec::new();
    // The unconstrained optimum, from zero torques, then (only when that solve fails) from the
    // gravity torques: used as it is when it keeps the clearance.
    for gravity in [false, true] {
        let x0 = guess(&m, &path, gravity);
        let sol = nlp::ipm::solve_from(&m, &x0, &opt);
        iterations += sol.iterations;
        solves += 1;
        let start = if gravity {
            "gravity torques"
        } else {
            "zero torques"
        };
        if !matches!(sol.status, Status::Solved | Status::SolvedToAcceptableLevel) {
            why.push(format!("from {start}: {:?}", sol.status));
            continue;
        }
        let traj = unpack(&m, &sol.x);
        if clear(w, &traj.q) {
            return Some(Leg {
                cost: sol.objective,
                duration: traj.h * m.steps as f64,
                motion: Motion::Ocp(traj),
                iterations,
                solves,
                trust_iterations: 0,
                fallback: None,
            });
        }
        why.push(format!("from {start}: the optimum collides"));
        break;
    }
    // Collision trust regions (§2.4) from a path with room, else from the planner's path.
    let start = roomy_path(w, a, b, s).unwrap_or_else(|| path.clone());
    let tm = Move {
        steps: steps_for(w, &start),
        ..ocp(w, a, b)
    };
    let t = trust::iterate(
        w,
        &tm,
        &rest_to_rest_guess(&tm, &start),
        &opt,
        &TrustSettings::default(),
    );
    iterations += t.iterations;
    solves += t.solves;
    let (timed_cost, timed_duration, scale) = timed_path(w, &path);
    match t.best {
        Some((_, cost)) if cost > timed_cost => why.push(format!(
            "trust regions: J {cost:.2} above the timed path's {timed_cost:.2}"
        )),
        Some((traj, cost)) => {
            return Some(Leg {
                cost,
                duration: traj.h * tm.steps as f64,
                motion: Motion::Ocp(traj),
                iterations,
                solves,
                trust_iterations: t.accepted,
                fallback: None,
            });
        }
        None => why.push("trust regions: no iterate kept the clearance".into()),
    }
    Some(Leg {
        motion: Motion::TimedPath {
            waypoints: path,
            acceleration_scale: scale,
        },
        cost: timed_cost,
        duration: timed_duration,
        iterations,
        solves,
        trust_iterations: 0,
        fallback: Some(why.join("; ")),
    })
}

/// One segment `a → b` timed rest to rest along the straight line: the path parameter follows
/// the fastest trapezoid within every joint's speed and acceleration (× `scale`). Returns the
/// duration, the phases' time intervals (accelerate, cruise, decelerate; empty ones left out)
/// and `s(t), ṡ(t), s̈(t)`.
pub fn segment_profile(
    a: &[f64],
    b: &[f64],
    v: &[f64],
    acc: &[f64],
    scale: f64,
) -> (f64, Vec<[f64; 2]>, impl Fn(f64) -> [f64; 3]) {
    let mut vs = f64::INFINITY;
    let mut as_ = f64::INFINITY;
    for j in 0..a.len() {
        let d = (b[j] - a[j]).abs();
        if d > 0.0 {
            vs = vs.min(v[j] / d);
            as_ = as_.min(scale * acc[j] / d);
        }
    }
    if !vs.is_finite() {
        return (0.0, Vec::new(), profile(0.0, 1.0, 1.0));
    }
    let t = joint_min_time(1.0, vs, as_);
    let ta = (vs / as_).min(0.5 * t);
    let phases = [[0.0, ta], [ta, t - ta], [t - ta, t]]
        .into_iter()
        .filter(|p| p[1] > p[0])
        .collect();
    (t, phases, profile(t, vs, as_))
}

fn profile(total: f64, v: f64, a: f64) -> impl Fn(f64) -> [f64; 3] {
    // Accelerate for ta, cruise, decelerate for ta; peak speed a·ta.
    let ta = (v / a).min(0.5 * total);
    let peak = a * ta;
    move |t: f64| {
        let t = t.clamp(0.0, total);
        if total <= 0.0 {
            [1.0, 0.0, 0.0]
        } else if t < ta {
            [0.5 * a * t * t, a * t, a]
        } else if t <= total - ta {
            [0.5 * a * ta * ta + peak * (t - ta), peak, 0.0]
        } else {
            let r = total - t;
            [1.0 - 0.5 * a * r * r, a * r, -a]
        }
    }
}

/// J of a path timed segment by segment (each phase of each segment by 4-point Gauss–Legendre
/// on [`PATH_SAMPLES`]` / 8` pieces, torques by inverse dynamics), its duration, and the
/// acceleration scale: halved from 1 until the torques hold at every quadrature point (at most
/// 8 times).
pub fn timed_path(w: &WeldCell, path: &[Vec<f64>]) -> (f64, f64, f64) {
    let mut scale = 1.0;
    for _ in 0..8 {
        let (cost, duration, peak) = timed_path_cost(w, path, scale);
        if peak <= 1.0 {
            return (cost, duration, scale);
        }
        scale *= 0.5;
    }
    let (cost, duration, _) = timed_path_cost(w, path, scale);
    (cost, duration, scale)
}

/// J, duration and the largest |u_j| / u_max_j of the path timed with acceleration `scale`.
pub fn timed_path_cost(w: &WeldCell, path: &[Vec<f64>], scale: f64) -> (f64, f64, f64) {
    const NODES: [f64; 4] = [
        -0.861_136_311_594_053,
        -0.339_981_043_584_856,
        0.339_981_043_584_856,
        0.861_136_311_594_053,
    ];
    const WEIGHTS: [f64; 4] = [
        0.347_854_845_137_454,
        0.652_145_154_862_546,
        0.652_145_154_862_546,
        0.347_854_845_137_454,
    ];
    let wt = w.process.weights;
    let acc = &w.robot.max_acceleration;
    let pieces = PATH_SAMPLES / 8;
    let (mut cost, mut duration, mut peak) = (0.0, 0.0, 0.0f64);
    for s in path.windows(2) {
        let (a, b) = (&s[0], &s[1]);
        let (t, phases, p) = segment_profile(a, b, &w.v_max, acc, scale);
        for [t0, t1] in phases {
            let dt = (t1 - t0) / pieces as f64;
            for k in 0..pieces {
                let mid = t0 + (k as f64 + 0.5) * dt;
                for (x, wq) in NODES.iter().zip(WEIGHTS) {
                    let [sv, sd, sdd] = p(mid + 0.5 * dt * x);
                    let q: Vec<f64> = a.iter().zip(b).map(|(x, y)| x + sv * (y - x)).collect();
                    let qd: Vec<f64> = a.iter().zip(b).map(|(x, y)| sd * (y - x)).collect();
                    let qdd: Vec<f64> = a.iter().zip(b).map(|(x, y)| sdd * (y - x)).collect();
                    let u = w.dynamics.inverse_dynamics(&q, &qd, &qdd);
                    let uu: f64 = u.iter().map(|v| v * v).sum();
                    let vv: f64 = qd.iter().map(|v| v * v).sum();
                    for (x, m) in u.iter().zip(&w.process.max_torque) {
                        peak = peak.max(x.abs() / m);
                    }
                    cost += 0.5 * dt * wq * (wt.time + wt.effort * uu + wt.velocity * vv);
                }
            }
        }
        duration += t;
    }
    (cost, duration, peak)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampled_grids_keep_every_waypoint_and_follow_the_profile() {
        let path = vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![1.0, 0.1], vec![3.0, 0.1]];
        let v = [1.0, 1.0];
        for profile in [(|t| t) as fn(f64) -> f64, quintic] {
            for steps in [3, 7, 12] {
                let g = resample(&path, &v, steps, profile);
                assert_eq!(g.len(), steps + 1);
                for w in &path {
                    assert!(
                        g.iter().any(|q| q == w),
                        "waypoint {w:?} not on the grid of {steps}"
                    );
                }
                // Every grid point lies on the path, in order along it.
                let mut last = 0.0;
                for q in &g {
                    let at = if q[1] == 0.0 {
                        q[0]
                    } else if q[0] == 1.0 {
                        1.0 + q[1]
                    } else {
                        1.1 + q[0] - 1.0
                    };
                    assert!(at >= last - 1e-12, "{q:?} goes back");
                    last = at;
                }
            }
        }
        // The quintic starts slower than the uniform grid.
        let u = resample(&path, &v, 12, |t| t);
        let q = resample(&path, &v, 12, quintic);
        assert!(q[1][0] < u[1][0]);
    }
}

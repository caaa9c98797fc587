//! `cellplan verify`: an independent check of a plan against its cell. It shares only the
//! geometry and kinematics primitives with the planner (forward kinematics, the collision
//! world, the probe's measurement model) and reads nothing but the plan document: every MP
//! measured exactly once by a robot at a pose meeting the probe constraints; the joint paths of
//! the legs re-sampled at the verifier's own resolution against the static scene and the
//! robot itself; the trajectory walked forward along those joint paths (so the motion is the
//! one checked); joint position, velocity and acceleration limits from the trajectory samples;
//! robot–robot clearance over the whole timeline at the verifier's time step; the reported
//! cycle time and Δt recomputed.
use crate::document::{FORMAT, Plan, RobotPlan};
use cellplan_geom::{BodyContact, DVec3};
use cellplan_model::Cell;
use cellplan_model::robot::{Robot, Scratch};
use serde::Serialize;
use std::collections::BTreeMap;

/// The verifier's resolution.
#[derive(Clone, Copy, Debug)]
pub struct VerifySettings {
    /// Largest joint step when re-sampling a leg's segments (rad or m).
    pub joint_step: f64,
    /// Time step of the robot–robot check over the common timeline (s).
    pub time_step: f64,
    /// Relative tolerance on velocity and acceleration limits.
    pub limit_tolerance: f64,
    /// Whether robot–robot clearance is checked (off for single-robot checks of motion plans
    /// that are not coordinated yet).
    pub robot_robot: bool,
}

impl Default for VerifySettings {
    fn default() -> Self {
        VerifySettings {
            joint_step: 1e-3,
            time_step: 0.01,
            limit_tolerance: 1e-6,
            robot_robot: true,
        }
    }
}

/// What is wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ViolationKind {
    /// The document is not a plan of this version, or does not match the cell.
    Format,
    /// An MP of the cell measured by nobody (and not listed as unmeasurable by the cell).
    MissingTask,
    /// An MP measured more than once.
    DuplicateTask,
    /// An MP id the cell does not have.
    UnknownTask,
    /// A measuring pose that does not measure its MP (stripe, depth of field, view angle,
    /// beams), or whose recorded probe pose disagrees with the joints.
    ProbeConstraint,
    /// A configuration outside the joint limits.
    JointLimit,
    /// A joint faster than its limit.
    Velocity,
    /// A joint accelerating harder than its limit.
    Acceleration,
    /// Closer than the clearance to the part or a fixture.
    StaticClearance,
    /// Two bodies of one robot touching.
    SelfCollision,
    /// Two robots closer than the clearance.
    RobotRobot,
    /// A trajectory that leaves its legs' joint paths (so the motion is not the one checked
    /// against the scene), goes back along them, or covers more path between two samples than
    /// the joint velocity limits allow.
    OffPath,
    /// Legs, visits and trajectory that do not fit together (a gap, a jump, a robot not at its
    /// MP while measuring).
    Continuity,
    /// A reported figure that does not match the recomputed one.
    Totals,
}

/// One violation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Violation {
    /// What.
    pub kind: ViolationKind,
    /// The robot (first robot for robot–robot).
    pub robot: Option<String>,
    /// The other robot (robot–robot only).
    pub other: Option<String>,
    /// When (s), where it applies.
    pub time_s: Option<f64>,
    /// The MP, where it applies.
    pub task: Option<String>,
    /// A sentence.
    pub detail: String,
}

/// The verifier's verdict.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// True when there is no violation.
    pub ok: bool,
    /// Every violation (robot–robot ones merged per robot pair and time interval).
    pub violations: Vec<Violation>,
    /// Recomputed cycle time (s).
    pub cycle_time_s: f64,
    /// Recomputed Δt (s).
    pub delta_t_s: f64,
    /// Configurations checked against the scene.
    pub configurations_checked: usize,
}

fn violation(
    kind: ViolationKind,
    robot: &str,
    time_s: Option<f64>,
    task: Option<&str>,
    detail: String,
) -> Violation {
    Violation {
        kind,
        robot: Some(robot.to_string()),
        other: None,
        time_s,
        task: task.map(String::from),
        detail,
    }
}

/// Verify `plan` against `cell`.
pub fn verify(cell: &Cell, plan: &Plan, settings: &VerifySettings) -> Report {
    let mut out = Vec::new();
    let mut checked = 0usize;
    if plan.format != FORMAT || plan.version != crate::document::VERSION {
        out.push(Violation {
            kind: ViolationKind::Format,
            robot: None,
            other: None,
            time_s: None,
            task: None,
            detail: format!(
                "not a {FORMAT} version {} document ({} version {})",
                crate::document::VERSION,
                plan.format,
                plan.version
            ),
        });
        return finish(out, 0.0, 0.0, 0);
    }
    let process = cell.process.as_ref();
    let words = process.words();
    let clearance = cell.planning.clearance;
    let cap = cell.planning.task_cap;
    // Robots by name, in cell order.
    let mut robots: Vec<(&Robot, &RobotPlan)> = Vec::new();
    for robot in &cell.robots {
        match plan.robots.iter().find(|r| r.name == robot.name) {
            Some(rp) => robots.push((robot, rp)),
            None => out.push(violation(
                ViolationKind::Format,
                &robot.name,
                None,
                None,
                "the plan has no entry for this robot".into(),
            )),
        }
    }
    for rp in &plan.robots {
        if !cell.robots.iter().any(|r| r.name == rp.name) {
            out.push(violation(
                ViolationKind::Format,
                &rp.name,
                None,
                None,
                "the cell has no such robot".into(),
            ));
        }
    }
    // Tasks exactly once.
    let by_name: BTreeMap<&str, usize> = cell.tasks.iter().map(|t| (t.name.as_str(), t.id.0)).collect();
    let mut count = vec![0usize; cell.tasks.len()];
    let unmeasured: Vec<&str> = plan.unmeasured.iter().map(|u| u.task.as_str()).collect();
    let mut scratch = Scratch::default();
    for (robot, rp) in &robots {
        if rp.tasks.len() > cap {
            out.push(violation(
                ViolationKind::Totals,
                &rp.name,
                None,
                None,
                format!("{} {}, over the task cap {cap}", rp.tasks.len(), words.tasks),
            ));
        }
        for v in &rp.tasks {
            let Some(&t) = by_name.get(v.task.as_str()) else {
                out.push(violation(
                    ViolationKind::UnknownTask,
                    &rp.name,
                    Some(v.arrive_s),
                    Some(&v.task),
                    format!("no {} of the cell has this id", words.task),
                ));
                continue;
            };
            count[t] += 1;
            let task = &cell.tasks[t];
            if v.q.len() != robot.dof() || !robot.within_limits(&v.q) {
                out.push(violation(
                    ViolationKind::JointLimit,
                    &rp.name,
                    Some(v.arrive_s),
                    Some(&v.task),
                    "the configuration at the task is outside the joint limits".into(),
                ));
                continue;
            }
            let tcp = robot.tcp_pose(&v.q);
            if (tcp.translation - DVec3::from(v.tcp.xyz)).length() > 1e-6 {
                out.push(violation(
                    ViolationKind::ProbeConstraint,
                    &rp.name,
                    Some(v.arrive_s),
                    Some(&v.task),
                    format!("the recorded {} position disagrees with the joints", words.tool),
                ));
            }
            robot.body_poses(&v.q, &mut scratch);
            let accepted = process
                .pose_check(task, &tcp)
                .and_then(|()| process.reached_check(&cell.world, task, &tcp))
                .and_then(|()| process.arm_check(&cell.world, robot, &scratch.bodies, task, &tcp));
            if let Err(r) = accepted {
                out.push(violation(
                    ViolationKind::ProbeConstraint,
                    &rp.name,
                    Some(v.arrive_s),
                    Some(&v.task),
                    format!(
                        "the process refuses this pose for the {}: {} ({})",
                        words.task, r.text, r.code
                    ),
                ));
            }
            let figures = process.visit_figures(task, &tcp);
            let stated: Vec<&str> = v.figures.keys().map(String::as_str).collect();
            let mut expected: Vec<&str> = figures.iter().map(|f| f.key).collect();
            expected.sort_unstable();
            if stated != expected {
                out.push(violation(
                    ViolationKind::Totals,
                    &rp.name,
                    Some(v.arrive_s),
                    Some(&v.task),
                    format!("states the figures {stated:?}; the process gives {expected:?}"),
                ));
            }
            for f in &figures {
                if let Some(&x) = v.figures.get(f.key)
                    && ((x - f.value).abs() > 1e-6 || x.is_nan())
                {
                    out.push(violation(
                        ViolationKind::Totals,
                        &rp.name,
                        Some(v.arrive_s),
                        Some(&v.task),
                        format!("states {} = {x}, but the pose gives {}", f.key, f.value),
                    ));
                }
            }
            let dwell = process.work(task).duration();
            if v.depart_s - v.arrive_s < dwell - 1e-9 {
                out.push(violation(
                    ViolationKind::Continuity,
                    &rp.name,
                    Some(v.arrive_s),
                    Some(&v.task),
                    format!(
                        "{} for {:.3} s, less than {dwell} s",
                        words.working,
                        v.depart_s - v.arrive_s
                    ),
                ));
            }
        }
    }
    for (t, &n) in count.iter().enumerate() {
        let name = &cell.tasks[t].name;
        if n > 1 {
            out.push(Violation {
                kind: ViolationKind::DuplicateTask,
                robot: None,
                other: None,
                time_s: None,
                task: Some(name.clone()),
                detail: format!("measured {n} times"),
            });
        } else if n == 0 && !unmeasured.contains(&name.as_str()) {
            out.push(Violation {
                kind: ViolationKind::MissingTask,
                robot: None,
                other: None,
                time_s: None,
                task: Some(name.clone()),
                detail: "measured by no robot and not listed as unmeasurable".into(),
            });
        }
    }
    // Legs: chained home → MPs → home, re-sampled against the scene.
    for (robot, rp) in &robots {
        let mut at: &[f64] = &rp.home;
        if rp.legs.len() != rp.tasks.len() + 1 {
            out.push(violation(
                ViolationKind::Continuity,
                &rp.name,
                None,
                None,
                format!(
                    "{} legs for {} MPs (want one more)",
                    rp.legs.len(),
                    rp.tasks.len()
                ),
            ));
            continue;
        }
        for (i, leg) in rp.legs.iter().enumerate() {
            let to: &[f64] = rp.tasks.get(i).map_or(&rp.home, |v| &v.q);
            let (Some(first), Some(last)) = (leg.waypoints.first(), leg.waypoints.last()) else {
                out.push(violation(
                    ViolationKind::Continuity,
                    &rp.name,
                    Some(leg.start_s),
                    None,
                    "a leg without waypoints".into(),
                ));
                continue;
            };
            if dist(first, at) > 1e-9 || dist(last, to) > 1e-9 {
                out.push(violation(
                    ViolationKind::Continuity,
                    &rp.name,
                    Some(leg.start_s),
                    None,
                    format!("leg {} → {} does not join its neighbours", leg.from, leg.to),
                ));
            }
            let mut reported = false;
            for w in leg.waypoints.windows(2) {
                let steps = (max_abs_diff(&w[0], &w[1]) / settings.joint_step).ceil().max(1.0) as usize;
                for s in 0..=steps {
                    let f = s as f64 / steps as f64;
                    let q: Vec<f64> = w[0].iter().zip(&w[1]).map(|(a, b)| a + f * (b - a)).collect();
                    checked += 1;
                    if !reported && let Some(v) = config_violation(cell, robot, &q, clearance, &mut scratch) {
                        out.push(violation(
                            v.0,
                            &rp.name,
                            Some(leg.start_s),
                            None,
                            format!("on leg {} → {}: {}", leg.from, leg.to, v.1),
                        ));
                        reported = true;
                    }
                }
            }
            at = to;
        }
    }
    // Trajectory samples: limits, endpoints, dwells.
    let mut times = Vec::new();
    for (robot, rp) in &robots {
        let tr = &rp.trajectory;
        if tr.is_empty() {
            out.push(violation(
                ViolationKind::Continuity,
                &rp.name,
                None,
                None,
                "no trajectory samples".into(),
            ));
            times.push(0.0);
            continue;
        }
        let end = tr[tr.len() - 1].t;
        times.push(end - tr[0].t);
        if dist(&tr[0].q, &rp.home) > 1e-6 || dist(&tr[tr.len() - 1].q, &rp.home) > 1e-6 {
            out.push(violation(
                ViolationKind::Continuity,
                &rp.name,
                None,
                None,
                "the trajectory does not start and end at home".into(),
            ));
        }
        if (rp.total_s - (end - tr[0].t)).abs() > 1e-6 {
            out.push(violation(
                ViolationKind::Totals,
                &rp.name,
                None,
                None,
                format!(
                    "total {:.3} s, but the trajectory lasts {:.3} s",
                    rp.total_s,
                    end - tr[0].t
                ),
            ));
        }
        let tol = 1.0 + settings.limit_tolerance;
        let mut first = [false; 3];
        for s in tr {
            if !robot.within_limits(&s.q) && !first[0] {
                out.push(violation(
                    ViolationKind::JointLimit,
                    &rp.name,
                    Some(s.t),
                    None,
                    "outside the joint limits".into(),
                ));
                first[0] = true;
            }
        }
        for w in tr.windows(3) {
            let (h1, h2) = (w[1].t - w[0].t, w[2].t - w[1].t);
            if h1 <= 0.0 || h2 <= 0.0 {
                out.push(violation(
                    ViolationKind::Continuity,
                    &rp.name,
                    Some(w[1].t),
                    None,
                    "time does not increase".into(),
                ));
                break;
            }
            for j in 0..robot.dof().min(w[0].q.len()) {
                let v = (w[1].q[j] - w[0].q[j]) / h1;
                if v.abs() > robot.max_velocity[j] * tol && !first[1] {
                    out.push(violation(
                        ViolationKind::Velocity,
                        &rp.name,
                        Some(w[0].t),
                        None,
                        format!(
                            "joint {} at {:.3} (limit {:.3})",
                            j + 1,
                            v.abs(),
                            robot.max_velocity[j]
                        ),
                    ));
                    first[1] = true;
                }
                // Second differences over equal steps average the acceleration.
                if (h1 - h2).abs() < 1e-9 {
                    let a = (w[2].q[j] - 2.0 * w[1].q[j] + w[0].q[j]) / (h1 * h1);
                    if a.abs() > robot.max_acceleration[j] * tol && !first[2] {
                        out.push(violation(
                            ViolationKind::Acceleration,
                            &rp.name,
                            Some(w[1].t),
                            None,
                            format!(
                                "joint {} at {:.3} (limit {:.3})",
                                j + 1,
                                a.abs(),
                                robot.max_acceleration[j]
                            ),
                        ));
                        first[2] = true;
                    }
                }
            }
        }
        if rp.legs.len() == rp.tasks.len() + 1
            && let Some((t, detail)) = follow_legs(robot, rp, settings.limit_tolerance)
        {
            out.push(violation(ViolationKind::OffPath, &rp.name, Some(t), None, detail));
        }
        // Every sample inside a measurement is at the measuring configuration.
        for v in &rp.tasks {
            let inside = tr
                .iter()
                .filter(|s| s.t > v.arrive_s + 1e-9 && s.t < v.depart_s - 1e-9);
            let mid = 0.5 * (v.arrive_s + v.depart_s);
            let off = std::iter::once((mid, position(tr, mid)))
                .chain(inside.map(|s| (s.t, s.q.clone())))
                .find(|(_, q)| dist(q, &v.q) > 1e-6);
            if let Some((t, _)) = off {
                out.push(violation(
                    ViolationKind::Continuity,
                    &rp.name,
                    Some(t),
                    Some(&v.task),
                    "the robot is not at its measuring configuration while measuring".into(),
                ));
            }
        }
    }
    // Robot–robot clearance over the common timeline.
    if settings.robot_robot && robots.len() > 1 {
        let horizon = times.iter().copied().fold(0.0, f64::max);
        let steps = (horizon / settings.time_step).ceil() as usize;
        let mut scratches: Vec<Scratch> = vec![Scratch::default(); robots.len()];
        // (pair) → (first time, last time) of the current contact interval.
        let mut open: BTreeMap<(usize, usize), (f64, f64)> = BTreeMap::new();
        let mut intervals: Vec<((usize, usize), f64, f64)> = Vec::new();
        for k in 0..=steps {
            let t = (k as f64 * settings.time_step).min(horizon);
            for (i, (robot, rp)) in robots.iter().enumerate() {
                let q = if rp.trajectory.is_empty() {
                    rp.home.clone()
                } else {
                    position(&rp.trajectory, t)
                };
                robot.body_poses(&q, &mut scratches[i]);
            }
            for a in 0..robots.len() {
                for b in a + 1..robots.len() {
                    let hit = cell
                        .world
                        .group_vs_group(
                            robots[a].0.group,
                            &scratches[a].bodies,
                            robots[b].0.group,
                            &scratches[b].bodies,
                            clearance,
                        )
                        .is_some();
                    match (hit, open.get_mut(&(a, b))) {
                        (true, Some(iv)) => iv.1 = t,
                        (true, None) => {
                            open.insert((a, b), (t, t));
                        }
                        (false, Some(_)) => {
                            let (s, e) = open.remove(&(a, b)).unwrap_or((t, t));
                            intervals.push(((a, b), s, e));
                        }
                        (false, None) => {}
                    }
                }
            }
        }
        intervals.extend(open.into_iter().map(|(p, (s, e))| (p, s, e)));
        intervals.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
        for ((a, b), s, e) in intervals {
            out.push(Violation {
                kind: ViolationKind::RobotRobot,
                robot: Some(robots[a].1.name.clone()),
                other: Some(robots[b].1.name.clone()),
                time_s: Some(s),
                task: None,
                detail: format!("closer than {:.0} mm from {s:.2} s to {e:.2} s", clearance * 1e3),
            });
        }
    }
    let cycle = times.iter().copied().fold(0.0, f64::max);
    let delta = cycle - times.iter().copied().fold(f64::INFINITY, f64::min).min(cycle);
    if (plan.cycle_time_s - cycle).abs() > 1e-6 || (plan.delta_t_s - delta).abs() > 1e-6 {
        out.push(Violation {
            kind: ViolationKind::Totals,
            robot: None,
            other: None,
            time_s: None,
            task: None,
            detail: format!(
                "reported cycle time {:.3} s and Δt {:.3} s; recomputed {cycle:.3} s and {delta:.3} s",
                plan.cycle_time_s, plan.delta_t_s
            ),
        });
    }
    finish(out, cycle, delta, checked)
}

fn finish(violations: Vec<Violation>, cycle: f64, delta: f64, checked: usize) -> Report {
    Report {
        ok: violations.is_empty(),
        violations,
        cycle_time_s: cycle,
        delta_t_s: delta,
        configurations_checked: checked,
    }
}

/// The first problem of one configuration: joint limits, the scene, the robot itself.
fn config_violation(
    cell: &Cell,
    robot: &Robot,
    q: &[f64],
    clearance: f64,
    scratch: &mut Scratch,
) -> Option<(ViolationKind, String)> {
    if !robot.within_limits(q) {
        return Some((ViolationKind::JointLimit, "outside the joint limits".into()));
    }
    robot.body_poses(q, scratch);
    match robot.contact_at(&cell.world, scratch, clearance) {
        None => None,
        Some(BodyContact::Static { body, object }) => Some((
            ViolationKind::StaticClearance,
            format!(
                "{} within {:.0} mm of {}",
                cell.world.body_name(robot.group, body),
                clearance * 1e3,
                cell.world.static_name(object)
            ),
        )),
        Some(BodyContact::SelfPair(i, j) | BodyContact::Pair(i, j)) => Some((
            ViolationKind::SelfCollision,
            format!(
                "{} touches {}",
                cell.world.body_name(robot.group, i),
                cell.world.body_name(robot.group, j)
            ),
        )),
    }
}

/// Walks the trajectory forward along the legs' joint paths (home → MPs → home, straight
/// joint segments between waypoints): each sample must lie on the path (within 1e-6 in every
/// joint) at or after the previous sample's place, and the path covered between two samples
/// must not exceed, joint by joint, what the velocity limit allows in their time. The first
/// failure: its time and a sentence.
fn follow_legs(robot: &Robot, rp: &RobotPlan, vtol: f64) -> Option<(f64, String)> {
    const TOL: f64 = 1e-6;
    // (start, end, leg) of every straight joint segment, in order.
    let segments: Vec<(&[f64], &[f64], usize)> = rp
        .legs
        .iter()
        .enumerate()
        .flat_map(|(k, leg)| {
            leg.waypoints
                .windows(2)
                .map(move |w| (w[0].as_slice(), w[1].as_slice(), k))
        })
        .collect();
    let leg_name = |s: usize| {
        let leg = &rp.legs[segments[s].2];
        format!("{} → {}", leg.from, leg.to)
    };
    let dof = robot.dof();
    // Waypoints or samples of another length are reported by the other checks (joint limits,
    // continuity); the walk needs every joint.
    let sized = rp.legs.iter().flat_map(|l| &l.waypoints).all(|w| w.len() == dof)
        && rp.trajectory.iter().all(|s| s.q.len() == dof);
    if segments.is_empty() || !sized {
        return None;
    }
    // Place on a segment: the nearest point's parameter and its max-abs distance.
    let place = |s: usize, q: &[f64]| -> (f64, f64) {
        let (a, b, _) = &segments[s];
        let (mut num, mut den) = (0.0, 0.0);
        for j in 0..dof {
            num += (q[j] - a[j]) * (b[j] - a[j]);
            den += (b[j] - a[j]).powi(2);
        }
        let f = if den > 0.0 {
            (num / den).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let off = (0..dof)
            .map(|j| (q[j] - (a[j] + f * (b[j] - a[j]))).abs())
            .fold(0.0, f64::max);
        (f, off)
    };
    let (mut seg, mut frac) = (0usize, 0.0f64);
    let mut prev_t = rp.trajectory.first()?.t;
    for sample in &rp.trajectory {
        // The first segment at or after the current place that holds the sample.
        let found = (seg..segments.len()).find_map(|s| {
            let (f, off) = place(s, &sample.q);
            (off <= TOL && (s > seg || f >= frac - 1e-9)).then_some((s, f))
        });
        let Some((s, f)) = found else {
            let behind = (0..seg).any(|s| place(s, &sample.q).1 <= TOL);
            return Some((
                sample.t,
                if behind {
                    format!("the trajectory goes back along its path on leg {}", leg_name(seg))
                } else {
                    format!(
                        "the trajectory leaves the joint path of leg {} (the motion checked against the scene)",
                        leg_name(seg)
                    )
                },
            ));
        };
        // Path covered per joint from (seg, frac) to (s, f).
        let h = sample.t - prev_t;
        for j in 0..dof {
            let len = |k: usize| (segments[k].1[j] - segments[k].0[j]).abs();
            let covered = if s == seg {
                (f - frac) * len(s)
            } else {
                (1.0 - frac) * len(seg) + (seg + 1..s).map(len).sum::<f64>() + f * len(s)
            };
            if covered > robot.max_velocity[j] * h * (1.0 + vtol) + TOL {
                return Some((
                    prev_t,
                    format!(
                        "joint {} covers {:.4} along the path in {:.3} s, more than its velocity limit allows ({:.4})",
                        j + 1,
                        covered,
                        h,
                        robot.max_velocity[j] * h
                    ),
                ));
            }
        }
        (seg, frac, prev_t) = (s, f, sample.t);
    }
    None
}

/// Position at `t` by linear interpolation of the samples (held before and after).
fn position(tr: &[crate::document::Sample], t: f64) -> Vec<f64> {
    let i = tr.partition_point(|s| s.t <= t);
    if i == 0 {
        return tr[0].q.clone();
    }
    if i >= tr.len() {
        return tr[tr.len() - 1].q.clone();
    }
    let (a, b) = (&tr[i - 1], &tr[i]);
    let f = if b.t > a.t { (t - a.t) / (b.t - a.t) } else { 0.0 };
    a.q.iter().zip(&b.q).map(|(x, y)| x + f * (y - x)).collect()
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

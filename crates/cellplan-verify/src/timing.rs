//! The clock: trajectory samples at the stated step, home to home, within the joint limits;
//! the program re-derived from legs, waits and visits (each leg starts when the robot leaves
//! its stop and any wait there ends; the next visit starts when the leg's motion and its waits
//! are over); each wait a standstill at its waypoint and each visit one at its configuration;
//! the robot's totals recomputed from all that.
use super::paths::{dist, name};
use super::{VerifySettings, Violation, ViolationKind};
use cellplan_core::document::{Plan, RobotPlan, Sample};
use cellplan_model::robot::Robot;

/// Times are compared to this (s).
const TIME_TOL: f64 = 1e-6;

/// The timing checks; returns each robot's recomputed time (trajectory duration).
pub(super) fn check(
    plan: &Plan,
    robots: &[(&Robot, &RobotPlan)],
    settings: &VerifySettings,
    out: &mut Vec<Violation>,
) -> Vec<f64> {
    let mut times = Vec::with_capacity(robots.len());
    for (robot, rp) in robots {
        let mut push = |kind, t: Option<f64>, detail: String| {
            out.push(Violation::robot(kind, &rp.name, t, None, detail));
        };
        let tr = &rp.trajectory;
        let (Some(first), Some(last)) = (tr.first(), tr.last()) else {
            push(ViolationKind::Continuity, None, "no trajectory samples".into());
            times.push(0.0);
            continue;
        };
        times.push(last.t - first.t);
        if dist(&first.q, &rp.home) > 1e-6 || dist(&last.q, &rp.home) > 1e-6 {
            push(
                ViolationKind::Continuity,
                None,
                "the trajectory does not start and end at home".into(),
            );
        }
        if let Some((t, detail)) = sample_steps(tr, plan.settings.sample_dt_s) {
            push(ViolationKind::Continuity, Some(t), detail);
        }
        limits(robot, tr, settings.limit_tolerance, &mut push);
        totals(rp, &mut push);
        if rp.legs.len() == rp.tasks.len() + 1 {
            clock(rp, &mut push);
        }
        standstills(rp, &mut push);
    }
    times
}

/// The samples are at `k · dt` from the start, and the last at the end, no more than `dt`
/// after the one before: a deleted or moved sample shows.
fn sample_steps(tr: &[Sample], dt: f64) -> Option<(f64, String)> {
    let t0 = tr[0].t;
    let n = tr.len();
    for (k, s) in tr.iter().enumerate().skip(1) {
        let expected = t0 + k as f64 * dt;
        let ok = if k + 1 < n {
            (s.t - expected).abs() <= 1e-9 * (1.0 + expected)
        } else {
            s.t > tr[k - 1].t && s.t - tr[k - 1].t <= dt * (1.0 + 1e-9)
        };
        if !ok {
            return Some((
                tr[k - 1].t,
                format!(
                    "sample {k} is at {:.6} s; samples are every {dt} s from the start (one is missing or moved)",
                    s.t
                ),
            ));
        }
    }
    None
}

/// Joint position, velocity and acceleration limits over the samples (the first violation
/// of each kind).
fn limits(
    robot: &Robot,
    tr: &[Sample],
    tolerance: f64,
    push: &mut dyn FnMut(ViolationKind, Option<f64>, String),
) {
    if let Some(s) = tr.iter().find(|s| !robot.within_limits(&s.q)) {
        push(
            ViolationKind::JointLimit,
            Some(s.t),
            "outside the joint limits".into(),
        );
    }
    let tol = 1.0 + tolerance;
    let (mut velocity, mut acceleration) = (false, false);
    for w in tr.windows(3) {
        let (h1, h2) = (w[1].t - w[0].t, w[2].t - w[1].t);
        for j in 0..robot.dof() {
            let v = (w[1].q[j] - w[0].q[j]) / h1;
            if v.abs() > robot.max_velocity[j] * tol && !velocity {
                push(
                    ViolationKind::Velocity,
                    Some(w[0].t),
                    format!(
                        "joint {} at {:.3} (limit {:.3})",
                        j + 1,
                        v.abs(),
                        robot.max_velocity[j]
                    ),
                );
                velocity = true;
            }
            // Second differences over equal steps average the acceleration.
            if (h1 - h2).abs() < 1e-9 {
                let a = (w[2].q[j] - 2.0 * w[1].q[j] + w[0].q[j]) / (h1 * h1);
                if a.abs() > robot.max_acceleration[j] * tol && !acceleration {
                    push(
                        ViolationKind::Acceleration,
                        Some(w[1].t),
                        format!(
                            "joint {} at {:.3} (limit {:.3})",
                            j + 1,
                            a.abs(),
                            robot.max_acceleration[j]
                        ),
                    );
                    acceleration = true;
                }
            }
        }
    }
}

/// The robot's stated totals against their parts: motion = the legs, working = the visits,
/// waiting = the waits, and start, end and total against the trajectory and each other.
fn totals(rp: &RobotPlan, push: &mut dyn FnMut(ViolationKind, Option<f64>, String)) {
    let tr = &rp.trajectory;
    let (t0, t1) = (tr[0].t, tr[tr.len() - 1].t);
    let motion: f64 = rp.legs.iter().map(|l| l.duration_s).sum();
    let working: f64 = rp.tasks.iter().map(|v| v.depart_s - v.arrive_s).sum();
    let waiting: f64 = rp.waits.iter().map(|w| w.duration_s).sum();
    for (key, stated, derived, from) in [
        ("start_s", rp.start_s, t0, "the first trajectory sample"),
        ("start_s", rp.start_s, 0.0, "the common clock's start"),
        ("end_s", rp.end_s, t1, "the last trajectory sample"),
        ("total_s", rp.total_s, t1 - t0, "the trajectory's duration"),
        ("motion_s", rp.motion_s, motion, "the legs' durations"),
        ("measuring_s", rp.measuring_s, working, "the visits' durations"),
        ("waiting_s", rp.waiting_s, waiting, "the waits' durations"),
        (
            "total_s",
            rp.total_s,
            motion + working + waiting,
            "motion, work and waiting together",
        ),
    ] {
        if (stated - derived).abs() > TIME_TOL {
            push(
                ViolationKind::Totals,
                None,
                format!(
                    "`{key}` is {stated:.6} s; recomputed from {from}: {:.6} s",
                    derived + 0.0
                ),
            );
        }
    }
}

/// The program's clock re-derived from its parts: leg `k` starts when the robot leaves stop
/// `k` plus the wait at its first waypoint; the visit (or home) is reached after the leg's
/// motion and the waits on its other waypoints; a wait at a leg's start ends when the leg
/// starts, one on the way lies within the leg.
fn clock(rp: &RobotPlan, push: &mut dyn FnMut(ViolationKind, Option<f64>, String)) {
    let mut leave = rp.start_s;
    for (k, leg) in rp.legs.iter().enumerate() {
        let waits = rp.waits.iter().filter(|w| w.leg == k);
        let at_start: f64 = waits
            .clone()
            .filter(|w| w.waypoint == 0)
            .map(|w| w.duration_s)
            .sum();
        let on_the_way: f64 = waits
            .clone()
            .filter(|w| w.waypoint > 0)
            .map(|w| w.duration_s)
            .sum();
        if (leg.start_s - (leave + at_start)).abs() > TIME_TOL {
            push(
                ViolationKind::Continuity,
                Some(leg.start_s),
                format!(
                    "leg {} starts at {:.6} s, but the robot leaves at {leave:.6} s and waits {at_start:.6} s there",
                    name(leg),
                    leg.start_s
                ),
            );
        }
        let arrive = leg.start_s + leg.duration_s + on_the_way;
        let (stated, what) = match rp.tasks.get(k) {
            Some(v) => (v.arrive_s, format!("{} arrives", v.task)),
            None => (rp.end_s, "the program ends".to_string()),
        };
        if (stated - arrive).abs() > TIME_TOL {
            push(
                ViolationKind::Continuity,
                Some(stated),
                format!(
                    "{what} at {stated:.6} s, but leg {} ends at {arrive:.6} s (motion {:.6} s, waits on the way {on_the_way:.6} s)",
                    name(leg),
                    leg.duration_s
                ),
            );
        }
        for w in waits {
            let inside = if w.waypoint == 0 {
                (w.start_s + w.duration_s - leg.start_s).abs() <= TIME_TOL
            } else {
                w.start_s >= leg.start_s - TIME_TOL && w.start_s + w.duration_s <= arrive + TIME_TOL
            };
            if !inside {
                push(
                    ViolationKind::Continuity,
                    Some(w.start_s),
                    format!(
                        "the wait at {} does not fit in leg {}'s time",
                        rp.wait_place(w),
                        name(leg)
                    ),
                );
            }
        }
        leave = rp.tasks.get(k).map_or(leave, |v| v.depart_s);
    }
}

/// Each wait is a standstill at its waypoint, each visit one at its configuration: the
/// position in the middle and every sample inside.
fn standstills(rp: &RobotPlan, push: &mut dyn FnMut(ViolationKind, Option<f64>, String)) {
    let tr = &rp.trajectory;
    let still = |q: &[f64], start: f64, end: f64| {
        // The middle and every sample inside (at the ends, the samples' linear interpolation
        // cuts the corner from the motion before or after).
        std::iter::once(0.5 * (start + end))
            .map(|t| (t, position(tr, t)))
            .chain(
                tr.iter()
                    .filter(|s| s.t > start + 1e-9 && s.t < end - 1e-9)
                    .map(|s| (s.t, s.q.clone())),
            )
            .find(|(_, p)| dist(p, q) > 1e-6)
            .map(|(t, _)| t)
    };
    for v in &rp.tasks {
        if let Some(t) = still(&v.q, v.arrive_s, v.depart_s) {
            push(
                ViolationKind::Continuity,
                Some(t),
                format!(
                    "the robot is not at its configuration for {} while working there",
                    v.task
                ),
            );
        }
    }
    for w in &rp.waits {
        let Some(q) = rp.legs.get(w.leg).and_then(|l| l.waypoints.get(w.waypoint)) else {
            continue;
        };
        if let Some(t) = still(q, w.start_s, w.start_s + w.duration_s) {
            push(
                ViolationKind::Continuity,
                Some(t),
                format!("the robot moves during its wait at {}", rp.wait_place(w)),
            );
        }
    }
}

/// Position at `t` by linear interpolation of the samples (held before and after).
pub(super) fn position(tr: &[Sample], t: f64) -> Vec<f64> {
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

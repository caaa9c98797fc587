//! The legs: chained home → tasks → home, naming their ends, re-sampled at the verifier's
//! joint step against the static scene and the robot itself; and the trajectory walked
//! forward along them, so that the motion checked is the motion timed.
use super::{VerifySettings, Violation, ViolationKind};
use cellplan_core::document::{LegOut, RobotPlan};
use cellplan_core::plan::Stop;
use cellplan_geom::BodyContact;
use cellplan_model::Cell;
use cellplan_model::robot::{Robot, Scratch};

/// The leg checks; returns the configurations checked.
pub(super) fn check(
    cell: &Cell,
    robots: &[(&Robot, &RobotPlan)],
    settings: &VerifySettings,
    out: &mut Vec<Violation>,
) -> usize {
    let mut checked = 0;
    let mut scratch = Scratch::default();
    for (robot, rp) in robots {
        if rp.legs.len() != rp.tasks.len() + 1 {
            out.push(Violation::robot(
                ViolationKind::Continuity,
                &rp.name,
                None,
                None,
                format!(
                    "{} legs for {} tasks (want one more)",
                    rp.legs.len(),
                    rp.tasks.len()
                ),
            ));
            continue;
        }
        let mut at: &[f64] = &rp.home;
        for (i, leg) in rp.legs.iter().enumerate() {
            let to: &[f64] = rp.tasks.get(i).map_or(&rp.home, |v| &v.q);
            check_ends(rp, i, leg, at, to, out);
            checked += resample(cell, robot, rp, leg, settings, &mut scratch, out);
            at = to;
        }
        if let Some((t, detail)) = follow_legs(robot, rp, settings.limit_tolerance) {
            out.push(Violation::robot(
                ViolationKind::OffPath,
                &rp.name,
                Some(t),
                None,
                detail,
            ));
        }
    }
    checked
}

/// A leg starts where the one before ended, ends at its task (or home), names those stops,
/// and is one segment when it says it is straight.
fn check_ends(rp: &RobotPlan, i: usize, leg: &LegOut, at: &[f64], to: &[f64], out: &mut Vec<Violation>) {
    let stop = |k: usize| {
        if k == 0 || k > rp.tasks.len() {
            Stop::Home
        } else {
            Stop::Task(rp.tasks[k - 1].task.clone())
        }
    };
    let mut push = |detail: String| {
        out.push(Violation::robot(
            ViolationKind::Continuity,
            &rp.name,
            Some(leg.start_s),
            None,
            detail,
        ));
    };
    let (first, last) = (&leg.waypoints[0], &leg.waypoints[leg.waypoints.len() - 1]);
    if dist(first, at) > 1e-9 || dist(last, to) > 1e-9 {
        push(format!("leg {} does not join its neighbours", name(leg)));
    }
    if leg.from != stop(i) || leg.to != stop(i + 1) {
        push(format!(
            "leg {i} says {}, but the visits make it {} → {}",
            name(leg),
            stop(i).label(),
            stop(i + 1).label()
        ));
    }
    if leg.straight && leg.waypoints.len() != 2 {
        push(format!(
            "leg {} says it is straight but has {} waypoints",
            name(leg),
            leg.waypoints.len()
        ));
    }
}

/// A leg for people: "M3 → M7".
pub(super) fn name(leg: &LegOut) -> String {
    format!("{} → {}", leg.from.label(), leg.to.label())
}

/// Re-samples a leg's segments at the joint step; reports its first bad configuration and
/// returns the configurations checked.
fn resample(
    cell: &Cell,
    robot: &Robot,
    rp: &RobotPlan,
    leg: &LegOut,
    settings: &VerifySettings,
    scratch: &mut Scratch,
    out: &mut Vec<Violation>,
) -> usize {
    let clearance = cell.planning.clearance;
    let mut checked = 0;
    let mut reported = false;
    for w in leg.waypoints.windows(2) {
        let steps = (max_abs_diff(&w[0], &w[1]) / settings.joint_step).ceil().max(1.0) as usize;
        for s in 0..=steps {
            let f = s as f64 / steps as f64;
            let q: Vec<f64> = w[0].iter().zip(&w[1]).map(|(a, b)| a + f * (b - a)).collect();
            checked += 1;
            if !reported && let Some(v) = config_violation(cell, robot, &q, clearance, scratch) {
                out.push(Violation::robot(
                    v.0,
                    &rp.name,
                    Some(leg.start_s),
                    None,
                    format!("on leg {}: {}", name(leg), v.1),
                ));
                reported = true;
            }
        }
    }
    checked
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
    let leg_name = |s: usize| name(&rp.legs[segments[s].2]);
    // Every waypoint and sample has the robot's joint count: the document was validated and
    // the robot's joints matched.
    let dof = robot.dof();
    if segments.is_empty() {
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

/// Euclidean distance of two configurations (infinite when their lengths differ).
pub(super) fn dist(a: &[f64], b: &[f64]) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
}

/// Largest joint difference.
pub(super) fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

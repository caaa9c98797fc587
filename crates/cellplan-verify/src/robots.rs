//! Robot–robot clearance over the common timeline, at the verifier's time step, each contact
//! reported once per robot pair and time interval.
use super::timing::position;
use super::{VerifySettings, Violation, ViolationKind};
use cellplan_core::document::RobotPlan;
use cellplan_model::Cell;
use cellplan_model::robot::{Robot, Scratch};
use std::collections::BTreeMap;

/// The robot–robot check; `times` are the robots' recomputed times.
pub(super) fn check(
    cell: &Cell,
    robots: &[(&Robot, &RobotPlan)],
    times: &[f64],
    settings: &VerifySettings,
    out: &mut Vec<Violation>,
) {
    if robots.len() < 2 {
        return;
    }
    let clearance = cell.planning.clearance;
    for ((a, b), s, e) in contacts(cell, robots, times, settings.time_step) {
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

/// (pair, first time, last time) of every interval in which a pair is closer than the
/// clearance, by start time.
fn contacts(
    cell: &Cell,
    robots: &[(&Robot, &RobotPlan)],
    times: &[f64],
    time_step: f64,
) -> Vec<((usize, usize), f64, f64)> {
    let clearance = cell.planning.clearance;
    let horizon = times.iter().copied().fold(0.0, f64::max);
    let steps = (horizon / time_step).ceil() as usize;
    let mut scratches: Vec<Scratch> = vec![Scratch::default(); robots.len()];
    // (pair) → (first time, last time) of the current contact interval.
    let mut open: BTreeMap<(usize, usize), (f64, f64)> = BTreeMap::new();
    let mut intervals: Vec<((usize, usize), f64, f64)> = Vec::new();
    for k in 0..=steps {
        let t = (k as f64 * time_step).min(horizon);
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
    intervals
}

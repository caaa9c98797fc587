//! Robot–robot clearance over the common timeline, at the verifier's time step, each contact
//! reported once per robot pair and time interval.
use super::timing::position;
use super::{VerifySettings, Violation, ViolationKind};
use cellplan_core::document::RobotPlan;
use cellplan_model::Cell;
use cellplan_model::robot::{Robot, Scratch};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Steps of the timeline checked side by side before their contacts are read off.
const TIME_CHUNK: usize = 1024;

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
    let at = |k: usize| (k as f64 * time_step).min(horizon);
    // The pairs closer than the clearance at a step, at the robots' poses in `scratches`.
    let hits_at = |scratches: &mut [Scratch], k: usize| {
        let t = at(k);
        for (i, (robot, rp)) in robots.iter().enumerate() {
            let q = if rp.trajectory.is_empty() {
                rp.home.clone()
            } else {
                position(&rp.trajectory, t)
            };
            robot.body_poses(&q, &mut scratches[i]);
        }
        let mut hit = Vec::new();
        for a in 0..robots.len() {
            for b in a + 1..robots.len() {
                let near = cell.world.group_vs_group(
                    robots[a].0.group,
                    &scratches[a].bodies,
                    robots[b].0.group,
                    &scratches[b].bodies,
                    clearance,
                );
                if near.is_some() {
                    hit.push((a, b));
                }
            }
        }
        hit
    };
    // (pair) → (first time, last time) of the current contact interval.
    let mut open: BTreeMap<(usize, usize), (f64, f64)> = BTreeMap::new();
    let mut intervals: Vec<((usize, usize), f64, f64)> = Vec::new();
    // The steps of a chunk side by side (each thread with its own scratch), then read off in
    // step order; chunks bound the memory whatever the timeline's length.
    for first in (0..=steps).step_by(TIME_CHUNK) {
        let hits: Vec<Vec<(usize, usize)>> = (first..=steps.min(first + TIME_CHUNK - 1))
            .into_par_iter()
            .map_init(|| vec![Scratch::default(); robots.len()], |s, k| hits_at(s, k))
            .collect();
        for (k, hit) in (first..).zip(&hits) {
            let t = at(k);
            // The pairs not hit at this step close their interval at its last hit.
            open.retain(|p, &mut (s, e)| {
                let still = hit.contains(p);
                if !still {
                    intervals.push((*p, s, e));
                }
                still
            });
            for &p in hit {
                open.entry(p).and_modify(|iv| iv.1 = t).or_insert((t, t));
            }
        }
    }
    intervals.extend(open.into_iter().map(|(p, (s, e))| (p, s, e)));
    intervals.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
    intervals
}

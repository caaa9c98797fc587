//! The plan's record: the settings the cell fixes, the cycle time, Δt, the lower bound and its
//! ratio (recomputed from the candidates the settings name), the candidate count, and the
//! coordination record (strategy, wait and pose counts, priority, the tracks before
//! coordination and the conflicts met on them).
use super::{Violation, ViolationKind};
use cellplan_core::candidates::CandidateTable;
use cellplan_core::document::{self, ActivityOut, ConflictOut, Plan, ProbeTrack, RobotPlan, RouteBoundOut};
use cellplan_core::plan::allocate;
use cellplan_core::plan::graph::RobotGraph;
use cellplan_geom::DVec3;
use cellplan_model::Cell;
use cellplan_model::robot::Robot;
use cellplan_model::tasks::TaskId;
use rayon::prelude::*;

/// How far a conflict's stated tool position may lie from the track before coordination
/// (m), beyond how far the track's two samples around it lie apart: the tracks are sampled
/// every 0.1 s and interpolated, and a tool that moves fast (a metre in a sample step, on a
/// robot's first move out of home) can be anywhere near that chord.
const TRACK_TOL: f64 = 0.05;

/// The record checks; returns the recomputed cycle time and Δt.
pub(super) fn check(
    cell: &Cell,
    table: &CandidateTable,
    plan: &Plan,
    robots: &[(&Robot, &RobotPlan)],
    times: &[f64],
    out: &mut Vec<Violation>,
) -> (f64, f64) {
    let mut totals = |detail: String| out.push(Violation::plan(ViolationKind::Totals, detail));
    settings(cell, plan, &mut totals);
    let cycle = times.iter().copied().fold(0.0, f64::max);
    // Δt over the robots that can do some task: the others stay at home, and the plan names
    // them with the reason `check` gives.
    let idle: Vec<bool> = cell
        .robots
        .iter()
        .map(|r| {
            cell.tasks
                .iter()
                .all(|t| table.get(t.id, r.id).candidates.is_empty())
        })
        .collect();
    idle_robots(cell, table, plan, &idle, &mut totals);
    // `times` goes with `robots` (the plan's robots paired with the cell's by name).
    let working = times
        .iter()
        .zip(robots)
        .filter(|(_, (r, _))| !idle.get(r.id.0).copied().unwrap_or(false))
        .map(|(t, _)| *t);
    let shortest = working.clone().fold(f64::INFINITY, f64::min);
    let longest = working.fold(f64::NEG_INFINITY, f64::max);
    let delta = if shortest.is_finite() {
        (longest - shortest).max(0.0)
    } else {
        0.0
    };
    if (plan.cycle_time_s - cycle).abs() > 1e-6 || (plan.delta_t_s - delta).abs() > 1e-6 {
        totals(format!(
            "states cycle time {:.6} s and Δt {:.6} s; recomputed {cycle:.6} s and {delta:.6} s",
            plan.cycle_time_s, plan.delta_t_s
        ));
    }
    lower_bound(cell, table, plan, &mut totals);
    if plan.stats.candidates != table.total() {
        totals(format!(
            "states {} candidates; the cell has {}",
            plan.stats.candidates,
            table.total()
        ));
    }
    coordination(plan, robots, out);
    (cycle, delta)
}

/// The robots the plan says can do no task: exactly those whose every task has no candidate
/// (`idle`, cell order), each with the reason `check` gives. (A task given to one of them has
/// no candidate, which `tasks` reports.)
fn idle_robots(
    cell: &Cell,
    table: &CandidateTable,
    plan: &Plan,
    idle: &[bool],
    totals: &mut dyn FnMut(String),
) {
    let derived: Vec<(String, String)> = cell
        .robots
        .iter()
        .zip(idle)
        .filter(|(_, idle)| **idle)
        .map(|(r, _)| {
            (
                r.name.clone(),
                cellplan_core::check::idle_reason(cell, table, r.id),
            )
        })
        .collect();
    let stated: Vec<(String, String)> = plan
        .idle_robots
        .iter()
        .map(|i| (i.robot.clone(), i.reason.clone()))
        .collect();
    if stated != derived {
        let names = |v: &[(String, String)]| {
            let n: Vec<&str> = v.iter().map(|(r, _)| r.as_str()).collect();
            if n.is_empty() {
                "none".to_string()
            } else {
                n.join(", ")
            }
        };
        totals(format!(
            "states the robots that can do no task as {} ({:?}); the cell's are {} ({:?})",
            names(&stated),
            stated.iter().map(|(_, w)| w).collect::<Vec<_>>(),
            names(&derived),
            derived.iter().map(|(_, w)| w).collect::<Vec<_>>(),
        ));
    }
}

/// The settings the cell fixes: clearance, task cap, balance limit, the process.
fn settings(cell: &Cell, plan: &Plan, totals: &mut dyn FnMut(String)) {
    let s = &plan.settings;
    let p = &cell.planning;
    if s.clearance_m != p.clearance || s.task_cap != p.task_cap || s.balance_limit_s != p.balance_limit {
        totals(format!(
            "states clearance {} m, task cap {}, balance limit {:?} s; the cell has {} m, {}, {:?} s",
            s.clearance_m, s.task_cap, s.balance_limit_s, p.clearance, p.task_cap, p.balance_limit
        ));
    }
    let process = document::process_settings(cell.process.as_ref());
    if s.process != process {
        totals(format!(
            "states the process {}; the cell's is {}",
            s.process, process
        ));
    }
}

/// The lower bound, recomputed on the graphs the settings name, and its ratio.
fn lower_bound(cell: &Cell, table: &CandidateTable, plan: &Plan, totals: &mut dyn FnMut(String)) {
    let s = &plan.settings;
    // One graph per robot, built side by side (each on its own; `collect` keeps the order).
    let graphs: Vec<RobotGraph> = cell
        .robots
        .par_iter()
        .map(|r| RobotGraph::new(cell, r, table, s.move_model, s.alternatives, s.roomy_m))
        .collect();
    // The tasks the plan does not measure are left out of the bound.
    let measured: std::collections::BTreeSet<&str> = plan
        .robots
        .iter()
        .flat_map(|r| r.tasks.iter().map(|v| v.task.as_str()))
        .collect();
    let left_out: Vec<TaskId> = cell
        .tasks
        .iter()
        .filter(|t| !measured.contains(t.name.as_str()))
        .map(|t| t.id)
        .collect();
    match allocate::lower_bound(cell, table, &graphs, &left_out) {
        Ok(legs) => {
            // The route bound, where stated, derived again from its certificate.
            let lb = match &plan.route_bound {
                None => legs,
                Some(stated) => legs.max(route_bound(cell, table, &graphs, &left_out, stated, legs, totals)),
            };
            if (plan.lower_bound_s - lb).abs() > 1e-6 * (1.0 + lb) {
                totals(format!(
                    "states the lower bound {:.6} s; recomputed {lb:.6} s",
                    plan.lower_bound_s
                ));
            }
        }
        Err(e) => totals(format!("the lower bound cannot be recomputed: {e}")),
    }
    let ratio = document::ratio(plan.cycle_time_s, plan.lower_bound_s);
    if (plan.ratio_to_lower_bound - ratio).abs() > 1e-9 * (1.0 + ratio) {
        totals(format!(
            "states the ratio {:.6} to the lower bound; its cycle time and bound give {ratio:.6}",
            plan.ratio_to_lower_bound
        ));
    }
}

/// The route bound `stated`, checked from its certificate: its leg bound is `legs`, and its
/// duals, named by MP and robot, prove `bound_s` again with one pricing per robot. Returns the
/// bound proved (`legs` when there is no certificate or it proves nothing).
fn route_bound(
    cell: &Cell,
    table: &CandidateTable,
    graphs: &[RobotGraph],
    left_out: &[TaskId],
    stated: &RouteBoundOut,
    legs: f64,
    totals: &mut dyn FnMut(String),
) -> f64 {
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * (1.0 + b.abs());
    if !close(stated.legs_s, legs) {
        totals(format!(
            "states the route bound's leg bound {:.6} s; recomputed {legs:.6} s",
            stated.legs_s
        ));
    }
    let Some(duals) = &stated.duals else {
        if !close(stated.bound_s, legs) {
            totals(format!(
                "states the route bound {:.6} s without its duals; without them it is the leg bound {legs:.6} s",
                stated.bound_s
            ));
        }
        return legs;
    };
    let mut pi = vec![0.0; cell.tasks.len()];
    let mut mu = vec![0.0; cell.robots.len()];
    let mut named = true;
    // By name, once: a document may name as many MPs as it likes.
    let tasks: std::collections::HashMap<&str, usize> = cell
        .tasks
        .iter()
        .enumerate()
        .map(|(t, task)| (task.name.as_str(), t))
        .collect();
    for (name, &v) in &duals.mps {
        match tasks.get(name.as_str()).copied() {
            Some(t) if !left_out.contains(&TaskId(t)) => pi[t] = v,
            Some(_) => {
                totals(format!(
                    "the route bound's duals price MP {name}, which the plan does not measure"
                ));
                named = false;
            }
            None => {
                totals(format!(
                    "the route bound's duals name MP {name}, which the cell does not have"
                ));
                named = false;
            }
        }
    }
    for (name, &v) in &duals.robots {
        match cell.robots.iter().position(|r| &r.name == name) {
            Some(r) => mu[r] = v,
            None => {
                totals(format!(
                    "the route bound's duals name robot {name}, which the cell does not have"
                ));
                named = false;
            }
        }
    }
    if !named {
        return legs;
    }
    match allocate::route_bound_at(cell, table, graphs, left_out, &pi, &mu) {
        Ok(Some(proved)) => {
            if !close(stated.bound_s, proved) {
                totals(format!(
                    "states the route bound {:.6} s; its duals prove {proved:.6} s",
                    stated.bound_s
                ));
            }
            proved
        }
        Ok(None) => {
            totals(format!(
                "states the route bound {:.6} s with duals that prove nothing (each must be at least 0, the robots' sum at most 1 and the value finite, and the problem within the pricing's size limits)",
                stated.bound_s
            ));
            legs
        }
        Err(e) => {
            totals(format!("the route bound cannot be derived again: {e}"));
            legs
        }
    }
}

/// The coordination record against the programs and the tracks before coordination.
fn coordination(plan: &Plan, robots: &[(&Robot, &RobotPlan)], out: &mut Vec<Violation>) {
    let c = &plan.coordination;
    let mut totals = |detail: String| out.push(Violation::plan(ViolationKind::Totals, detail));
    if c.strategy != plan.settings.coordination {
        totals(format!(
            "coordination says `{:?}`, the settings `{:?}`",
            c.strategy, plan.settings.coordination
        ));
    }
    let waits: usize = plan.robots.iter().map(|r| r.waits.len()).sum();
    let changed = plan
        .robots
        .iter()
        .flat_map(|r| &r.tasks)
        .filter(|v| v.perturbation_rad.is_some())
        .count();
    if c.waits != waits || c.poses_changed != changed {
        totals(format!(
            "coordination states {} waits and {} poses changed; the programs have {waits} and {changed}",
            c.waits, c.poses_changed
        ));
    }
    let names: Vec<&str> = plan.robots.iter().map(|r| r.name.as_str()).collect();
    let mut priority = c.priority.clone();
    priority.sort();
    priority.dedup();
    if priority.len() != c.priority.len() || c.priority.iter().any(|p| !names.contains(&p.as_str())) {
        totals(format!(
            "the priority order {:?} is not an order of the plan's robots",
            c.priority
        ));
    }
    for rp in &plan.robots {
        for w in &rp.waits {
            if let Some(o) = &w.for_robot
                && (o == &rp.name || !names.contains(&o.as_str()))
            {
                totals(format!(
                    "{} waits for `{o}`, not another robot of the plan",
                    rp.name
                ));
            }
        }
    }
    if c.strategy != cellplan_core::coord::Coordination::None && !c.conflicts_after.is_empty() {
        totals(format!(
            "{} conflicts left, but the strategy resolves conflicts",
            c.conflicts_after.len()
        ));
    }
    tracks(plan, robots, &mut totals);
    for x in c.conflicts_before.iter().chain(&c.conflicts_after) {
        if let Some(why) = conflict_problem(plan, x) {
            totals(format!(
                "the conflict of {} and {} at {:.2} s: {why}",
                x.robots[0], x.robots[1], x.start_s
            ));
        }
    }
}

/// The tracks before coordination: one per robot in plan order, from home to home, and the
/// uncoordinated cycle time the longest of them.
fn tracks(plan: &Plan, robots: &[(&Robot, &RobotPlan)], totals: &mut dyn FnMut(String)) {
    let c = &plan.coordination;
    let order: Vec<&str> = c.uncoordinated_probe.iter().map(|t| t.robot.as_str()).collect();
    let names: Vec<&str> = plan.robots.iter().map(|r| r.name.as_str()).collect();
    if order != names {
        totals(format!(
            "tracks before coordination for {order:?}; the plan's robots are {names:?}"
        ));
        return;
    }
    for (robot, rp) in robots {
        let Some(track) = c.uncoordinated_probe.iter().find(|t| t.robot == rp.name) else {
            continue;
        };
        let home = robot.tcp_pose(&rp.home).translation;
        let off = |p: Option<&[f64; 3]>| p.is_some_and(|p| (DVec3::from(*p) - home).length() > 1e-3);
        if off(track.xyz.first()) || off(track.xyz.last()) {
            totals(format!(
                "{}'s track before coordination does not start and end at home",
                rp.name
            ));
        }
    }
    let u = c.uncoordinated_cycle_time_s;
    let span = |t: &ProbeTrack, less: usize| t.xyz.len().saturating_sub(less) as f64 * t.dt_s;
    let upper = c
        .uncoordinated_probe
        .iter()
        .map(|t| span(t, 1))
        .fold(0.0, f64::max);
    let lower = c
        .uncoordinated_probe
        .iter()
        .map(|t| span(t, 2))
        .fold(0.0, f64::max);
    if c.uncoordinated_probe.iter().all(|t| !t.xyz.is_empty()) && !(u <= upper + 1e-9 && u > lower - 1e-9) {
        totals(format!(
            "the uncoordinated cycle time {u:.6} s does not fit its tracks ({lower:.1}–{upper:.1} s)"
        ));
    }
}

/// What is wrong with a conflict: its robots, its activities (legs and stops as the final
/// programs name them; coordination keeps every robot's order of visits), its scenario, its
/// times, its tool positions against the tracks.
fn conflict_problem(plan: &Plan, x: &ConflictOut) -> Option<String> {
    if x.robots[0] == x.robots[1] {
        return Some("a robot in conflict with itself".into());
    }
    if x.end_s < x.start_s
        || x.start_s
            > plan
                .coordination
                .uncoordinated_cycle_time_s
                .max(plan.cycle_time_s)
                + 1e-6
    {
        return Some(format!(
            "the interval {:.6}–{:.6} s is out of place",
            x.start_s, x.end_s
        ));
    }
    let both_working = x
        .activity
        .iter()
        .all(|a| matches!(a, ActivityOut::Working { .. }));
    if x.scenario != if both_working { 1 } else { 2 } {
        return Some(format!("scenario {} does not match the activities", x.scenario));
    }
    for side in 0..2 {
        let rp = plan.robots.iter().find(|r| r.name == x.robots[side])?;
        let fits = match &x.activity[side] {
            ActivityOut::Moving { leg, from, to } | ActivityOut::Waiting { leg, from, to, .. } => {
                rp.legs.get(*leg).is_some_and(|l| &l.from == from && &l.to == to)
            }
            ActivityOut::Working { task } => rp.tasks.iter().any(|v| &v.task == task),
        };
        if !fits {
            return Some(format!("{}'s activity is not one of its program", rp.name));
        }
        if let Some(track) = plan
            .coordination
            .uncoordinated_probe
            .iter()
            .find(|t| t.robot == rp.name)
            && let Some((p, span)) = track_at(track, x.start_s)
            && (p - DVec3::from(x.probe_xyz[side])).length() > TRACK_TOL + span
        {
            return Some(format!(
                "{}'s tool position {:?} is not where its track puts it then",
                rp.name, x.probe_xyz[side]
            ));
        }
    }
    None
}

/// The track's position at `t`, linearly interpolated (held after its end).
/// The track's position at `t` (linear between its samples) and the distance between the two
/// samples around `t`.
fn track_at(track: &ProbeTrack, t: f64) -> Option<(DVec3, f64)> {
    let n = track.xyz.len();
    if n == 0 {
        return None;
    }
    let f = (t / track.dt_s).max(0.0);
    let i = (f.floor() as usize).min(n - 1);
    let j = (i + 1).min(n - 1);
    let w = (f - i as f64).clamp(0.0, 1.0);
    let (a, b) = (DVec3::from(track.xyz[i]), DVec3::from(track.xyz[j]));
    Some((a + (b - a) * w, (b - a).length()))
}

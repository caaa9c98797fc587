//! The document from a run: per robot its visits, legs, waits and trajectory; the totals; the
//! coordination record; the unmeasured tasks; the search's counts and times.
use super::{
    ActivityOut, BlendOut, ComputeTimes, ConflictOut, CoordinationOut, FORMAT, LegOut, PROBE_TRACK_DT, Plan,
    PoseOut, ProbeTrack, RobotPlan, RouteBoundOut, RouteBoundRun, Sample, SettingsOut, Stats, UnmeasuredTask,
    VERSION, Visit, WaitOut,
};
use crate::candidates::CandidateTable;
use crate::coord::{Activity, Conflict, Coordinated, Program, Timed};
use crate::plan::{self, Outcome, PlanSettings, Stage};
use cellplan_model::Process;
use cellplan_model::robot::Robot;
use cellplan_model::tasks::TaskId;
use cellplan_model::{Cell, RobotId};

/// Build the document from a run and its coordination.
pub fn build(
    cell: &Cell,
    table: &CandidateTable,
    outcome: &Outcome,
    coordinated: &Coordinated,
    settings: &PlanSettings,
    load_s: f64,
    candidates_s: f64,
) -> Plan {
    let robots: Vec<RobotPlan> = cell
        .robots
        .iter()
        .enumerate()
        .map(|(r, robot)| {
            robot_plan(
                cell,
                robot,
                &coordinated.programs[r],
                &coordinated.timed[r],
                settings.sample_dt,
            )
        })
        .collect();
    let idle = crate::check::idle_robots(cell, table);
    let (cycle, delta) = cycle_and_delta(&robots, &idle);
    // The bound holds for the tasks the plan does: the ones given up are left out of it.
    let left_out: Vec<TaskId> = outcome.unreached.iter().map(|(t, _)| *t).collect();
    let lb = if left_out.is_empty() {
        outcome.allocated.lower_bound
    } else {
        crate::plan::allocate::lower_bound(cell, table, &outcome.graphs, &left_out)
            .unwrap_or(outcome.allocated.lower_bound)
    };
    let began = std::time::Instant::now();
    // The run's wall-clock limit bounds it too (none by default).
    let route_bound = settings.route_bound_work.and_then(|max_work| {
        let limits = (max_work, settings.deadline);
        let (rb, tasks) =
            crate::plan::allocate::route_bound(cell, table, &outcome.graphs, &left_out, limits).ok()?;
        let tasks: Vec<&str> = tasks.iter().map(|&t| cell.tasks[t.0].name.as_str()).collect();
        let robots: Vec<&str> = cell.robots.iter().map(|r| r.name.as_str()).collect();
        Some((
            RouteBoundOut::new(&rb, &tasks, &robots),
            RouteBoundRun::new(&rb, max_work),
        ))
    });
    let (route_bound, route_run) = route_bound.unzip();
    let lb = route_bound.as_ref().map_or(lb, |r| lb.max(r.bound_s));
    // The clock stopped the route bound: the plan says so.
    let clock_cut = route_run.as_ref().is_some_and(|r| r.cut_by_clock);
    let route_bound_s = if route_bound.is_some() {
        began.elapsed().as_secs_f64()
    } else {
        0.0
    };
    Plan {
        format: FORMAT.to_string(),
        version: VERSION,
        cell: cell.name.clone(),
        cell_file: cell.path.display().to_string(),
        settings: settings_out(cell, settings, coordinated),
        cycle_time_s: cycle,
        delta_t_s: delta,
        lower_bound_s: lb,
        ratio_to_lower_bound: ratio(cycle, lb),
        route_bound,
        verified: false,
        coordination: coordination_out(cell, outcome, coordinated),
        robots,
        unmeasured: unmeasured(cell, table, &outcome.unreached),
        idle_robots: crate::check::idle_robots_out(cell, table),
        stats: Stats {
            time_limit_hit: outcome.time_limit_hit || clock_cut,
            route_bound: route_run,
            ..stats(table, outcome, coordinated)
        },
        compute_s: compute_times(outcome, coordinated, load_s, candidates_s, route_bound_s),
    }
}

/// `cycle / lower_bound`, 1 when the bound is 0.
pub fn ratio(cycle: f64, lower_bound: f64) -> f64 {
    if lower_bound > 0.0 {
        cycle / lower_bound
    } else {
        1.0
    }
}

/// The cycle time (longest robot time) and Δt (longest minus shortest).
fn cycle_and_delta(robots: &[RobotPlan], idle: &[RobotId]) -> (f64, f64) {
    let cycle = robots.iter().map(|r| r.total_s).fold(0.0, f64::max);
    let working = robots
        .iter()
        .enumerate()
        .filter(|(r, _)| !idle.contains(&RobotId(*r)))
        .map(|(_, p)| p.total_s);
    (cycle, crate::check::balance_spread(working))
}

/// One robot's visits, legs, waits, totals and sampled trajectory.
fn robot_plan(cell: &Cell, robot: &Robot, prog: &Program, timed: &Timed, sample_dt: f64) -> RobotPlan {
    let process = cell.process.as_ref();
    let tasks = prog
        .visits
        .iter()
        .zip(&timed.visits)
        .map(|(v, &(arrive, depart))| Visit {
            task: cell.tasks[v.task.0].name.clone(),
            candidate: v.candidate,
            q: v.q.clone(),
            tcp: pose_out(&v.tcp),
            figures: process
                .visit_figures(&cell.tasks[v.task.0], &v.tcp)
                .into_iter()
                .map(|f| (f.key.to_string(), f.value))
                .collect(),
            perturbation_rad: v.perturbation,
            arrive_s: arrive,
            depart_s: depart,
        })
        .collect();
    let legs = prog
        .legs
        .iter()
        .enumerate()
        .map(|(k, leg)| LegOut {
            from: prog.stop(cell, k),
            to: prog.stop(cell, k + 1),
            start_s: timed.arrivals[k][0] + prog.wait_at(k, 0).map_or(0.0, |w| w.duration),
            duration_s: leg.duration(),
            straight: leg.straight,
            waypoints: leg.waypoints.clone(),
            blends: leg.blend.as_ref().map_or_else(Vec::new, |b| {
                b.corners
                    .iter()
                    .map(|&(waypoint, radius)| BlendOut { waypoint, radius })
                    .collect()
            }),
        })
        .collect();
    let waits = prog
        .waits
        .iter()
        .zip(&timed.wait_starts)
        .map(|(w, &start)| WaitOut {
            leg: w.leg,
            waypoint: w.waypoint,
            start_s: start,
            duration_s: w.duration,
            reason: w.reason,
            for_robot: w.for_robot.map(|o| cell.robots[o].name.clone()),
        })
        .collect();
    let total = timed.end();
    RobotPlan {
        name: robot.name.clone(),
        joints: robot.joint_names().into_iter().map(String::from).collect(),
        home: robot.home.clone(),
        tasks,
        start_s: 0.0,
        end_s: total,
        motion_s: prog.motion(),
        measuring_s: prog.working(),
        waiting_s: prog.waiting(),
        total_s: total,
        waits,
        legs,
        trajectory: timed
            .trajectory
            .sample(sample_dt)
            .into_iter()
            .map(|(t, q)| Sample { t, q })
            .collect(),
    }
}

/// The `settings` entry.
fn settings_out(cell: &Cell, settings: &PlanSettings, coordinated: &Coordinated) -> SettingsOut {
    SettingsOut {
        allocation: settings.allocation,
        cover: settings.cover,
        move_model: settings.move_model,
        seed: settings.seed,
        time_limit_s: (settings.time_limit < PlanSettings::NO_TIME_LIMIT)
            .then_some(settings.time_limit.as_secs_f64()),
        local_set_radius_m: settings.local_set_radius,
        alternatives: settings.alternatives,
        roomy_m: settings.roomy,
        sample_dt_s: settings.sample_dt,
        clearance_m: cell.planning.clearance,
        task_cap: cell.planning.task_cap,
        balance_limit_s: cell.planning.balance_limit,
        process: process_settings(cell.process.as_ref()),
        coordination: coordinated.strategy,
    }
}

/// The `settings.process` entry: `kind` first, then the process's parameters.
pub fn process_settings(process: &dyn Process) -> serde_json::Value {
    let mut map = serde_json::Map::new();
    map.insert("kind".into(), process.kind().into());
    if let serde_json::Value::Object(params) = process.parameters() {
        map.extend(params);
    }
    serde_json::Value::Object(map)
}

/// The `coordination` record.
fn coordination_out(cell: &Cell, outcome: &Outcome, coordinated: &Coordinated) -> CoordinationOut {
    let conflicts = |list: &[Conflict]| -> Vec<ConflictOut> {
        list.iter().map(|c| conflict_out(cell, coordinated, c)).collect()
    };
    CoordinationOut {
        strategy: coordinated.strategy,
        uncoordinated_cycle_time_s: coordinated.uncoordinated_cycle,
        conflicts_before: conflicts(&coordinated.before),
        conflicts_after: conflicts(&coordinated.after),
        // What the programs hold (a wait added where one stood already lengthens it).
        waits: coordinated.programs.iter().map(|p| p.waits.len()).sum(),
        poses_changed: coordinated
            .programs
            .iter()
            .flat_map(|p| &p.visits)
            .filter(|v| v.perturbation.is_some())
            .count(),
        priority: coordinated
            .priority
            .iter()
            .map(|&r| cell.robots[r].name.clone())
            .collect(),
        uncoordinated_probe: uncoordinated_probe(cell, outcome, &coordinated.reversed),
    }
}

/// The tasks no robot can do, each with the furthest check any pose passed, and those no
/// robot was given a path to (`no-path`, with the planner's words), in task order.
fn unmeasured(cell: &Cell, table: &CandidateTable, unreached: &[(TaskId, String)]) -> Vec<UnmeasuredTask> {
    (0..cell.tasks.len())
        .filter_map(|t| {
            if table.robots_for(TaskId(t)).is_empty() {
                Some((unmeasured_reason(table, t).to_string(), None))
            } else {
                unreached
                    .iter()
                    .find(|u| u.0 == TaskId(t))
                    .map(|u| (super::NO_PATH.to_string(), Some(u.1.clone())))
            }
            .map(|(reason, detail)| UnmeasuredTask {
                task: cell.tasks[t].name.clone(),
                reason,
                detail,
            })
        })
        .collect()
}

/// The code of the furthest rejection of task `t` over the robots.
pub fn unmeasured_reason(table: &CandidateTable, t: usize) -> &'static str {
    table.table[t]
        .iter()
        .filter_map(|reach| reach.reason())
        .max()
        .map_or("none", |r| r.code())
}

/// The search's counts.
fn stats(table: &CandidateTable, outcome: &Outcome, coordinated: &Coordinated) -> Stats {
    let seqs = outcome.robots.iter().map(|r| &r.sequence);
    Stats {
        candidates: table.total(),
        legs_planned: seqs.clone().map(|s| s.legs_planned).sum(),
        legs_sampled: seqs.clone().map(|s| s.legs_sampled).sum(),
        legs_failed: seqs.clone().map(|s| s.legs_failed).sum(),
        sequencing_rounds: seqs.map(|s| s.rounds).max().unwrap_or(0),
        local_sets_built: outcome.allocated.local_sets.0,
        local_sets_chosen: outcome.allocated.local_sets.1,
        conflicts_resolved: coordinated.resolved,
        passage_search: coordinated.search,
        time_limit_hit: outcome.time_limit_hit,
        route_bound: None,
        ours: coordinated.ours.map(|o| o.0),
    }
}

/// Wall seconds per stage (the verification and the total are completed by the caller).
fn compute_times(
    outcome: &Outcome,
    coordinated: &Coordinated,
    load_s: f64,
    candidates_s: f64,
    route_bound_s: f64,
) -> ComputeTimes {
    let mut compute = ComputeTimes {
        load: load_s,
        candidates: candidates_s,
        coordination: coordinated.compute_s,
        route_bound: route_bound_s,
        ours: coordinated.ours.map(|o| o.1),
        ..ComputeTimes::default()
    };
    for &(stage, s) in &outcome.compute {
        match stage {
            Stage::Costs => compute.costs = s,
            Stage::Allocation => compute.allocation = s,
            Stage::Sequencing => compute.sequencing_motion = s,
            Stage::Timing => compute.timing = s,
        }
    }
    compute.total = load_s
        + candidates_s
        + outcome.compute.iter().map(|x| x.1).sum::<f64>()
        + coordinated.compute_s
        + route_bound_s;
    compute
}

/// The probe tracks of the programs before coordination (see [`ProbeTrack`]), each tour in
/// the direction coordination chose (`reversed`, per robot; empty: as planned).
fn uncoordinated_probe(cell: &Cell, outcome: &Outcome, reversed: &[bool]) -> Vec<ProbeTrack> {
    let round = |v: f64| (v * 1e4).round() / 1e4;
    cell.robots
        .iter()
        .zip(&outcome.robots)
        .enumerate()
        .map(|(r, (robot, res))| {
            let limits = plan::graph::limits_of(robot);
            let program = if reversed.get(r).copied().unwrap_or(false) {
                res.program.reversed(&limits)
            } else {
                Ok(res.program.clone())
            };
            let xyz = match program.and_then(|p| p.timed(&limits)) {
                Ok(timed) => {
                    let end = timed.trajectory.duration();
                    let steps = (end / PROBE_TRACK_DT).ceil() as usize;
                    (0..=steps)
                        .map(|k| {
                            let t = (k as f64 * PROBE_TRACK_DT).min(end);
                            let p = robot.tcp_pose(&timed.trajectory.position(t)).translation;
                            [round(p.x), round(p.y), round(p.z)]
                        })
                        .collect()
                }
                Err(_) => Vec::new(),
            };
            ProbeTrack {
                robot: robot.name.clone(),
                dt_s: PROBE_TRACK_DT,
                xyz,
            }
        })
        .collect()
}

/// A conflict for the document. Coordination keeps every robot's order of visits, so the
/// final programs name the legs and tasks of the conflicts met before coordination too.
fn conflict_out(cell: &Cell, coordinated: &Coordinated, c: &Conflict) -> ConflictOut {
    let robots = [c.robots.0, c.robots.1];
    let activity = |k: usize| {
        let prog = &coordinated.programs[robots[k]];
        let stop = |i: usize| prog.stop(cell, i);
        match c.activity[k] {
            Activity::Move { leg, .. } => ActivityOut::Moving {
                leg,
                from: stop(leg),
                to: stop(leg + 1),
            },
            Activity::Measure { visit } => ActivityOut::Working {
                task: stop(visit + 1).label().to_string(),
            },
            Activity::Wait { leg, waypoint } => ActivityOut::Waiting {
                leg,
                waypoint,
                from: stop(leg),
                to: stop(leg + 1),
            },
        }
    };
    ConflictOut {
        robots: robots.map(|r| cell.robots[r].name.clone()),
        start_s: c.start,
        end_s: c.end,
        scenario: c.scenario.number(),
        activity: [activity(0), activity(1)],
        probe_xyz: [c.tcp[0].to_array(), c.tcp[1].to_array()],
    }
}

fn pose_out(p: &cellplan_geom::Pose) -> PoseOut {
    let t = p.translation;
    let q = p.rotation;
    PoseOut {
        xyz: [t.x, t.y, t.z],
        quat: [q.x, q.y, q.z, q.w],
    }
}

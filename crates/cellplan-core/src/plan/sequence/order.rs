//! The best order of a robot's tasks: a GTSP over their candidates under the current costs,
//! optionally sweeping the tasks along a line.
use super::{NO_PATH, Planned};
use crate::plan::graph::RobotGraph;
use cellplan_model::tasks::TaskId;
use cellplan_solve::{CostMatrix, Gtsp, GtspParams};
use std::time::Duration;

/// Kicks of the GTSP heuristic per sequencing round (fixed, for determinism).
const GTSP_ITERATIONS: usize = 400;
/// ... and stop after this many kicks in a row that did not shorten the best order.
const GTSP_STALL: usize = 100;

/// The best order (GTSP over the tasks' candidates) under the current costs: planned legs at
/// their real time, the others at their lower bound; with `sweep` keys per task (see
/// [`crate::plan::PlanSettings::sweep`], [`crate::plan::sweep_keys`]), the order that sweeps
/// the tasks in [`SWEEP_GROUPS`] groups of rising key wherever that is possible.
pub fn best_order(
    graph: &RobotGraph,
    tasks: &[TaskId],
    planned: &Planned,
    seed: u64,
    sweep: &[f64],
) -> Vec<usize> {
    best_order_with(graph, tasks, planned, seed, GTSP_ITERATIONS, sweep)
}

/// Groups of a sweep: a robot's tasks in this many groups of equal size by their sweep keys.
pub const SWEEP_GROUPS: usize = 3;

/// Added to the cost of a move from a task back to a task of an earlier sweep group, in the
/// GTSP only (the order's time is its real time): longer than any leg, so that an order sweeps
/// its groups one after the other whenever some order can.
const SWEEP_PENALTY: f64 = 100.0;

/// Each task's sweep group (`usize::MAX` for none), indexed by task: `tasks` sorted by their
/// `sweep` keys (then by id) and cut into [`SWEEP_GROUPS`] groups of equal size.
fn sweep_groups(tasks: &[TaskId], sweep: &[f64]) -> Vec<usize> {
    let mut group = vec![usize::MAX; sweep.len()];
    let mut sorted: Vec<TaskId> = tasks.iter().copied().filter(|t| t.0 < sweep.len()).collect();
    sorted.sort_by(|a, b| sweep[a.0].total_cmp(&sweep[b.0]).then(a.0.cmp(&b.0)));
    for (rank, t) in sorted.iter().enumerate() {
        group[t.0] = rank * SWEEP_GROUPS / sorted.len();
    }
    group
}

/// [`best_order`] with `iterations` kicks of the GTSP heuristic.
pub fn best_order_with(
    graph: &RobotGraph,
    tasks: &[TaskId],
    planned: &Planned,
    seed: u64,
    iterations: usize,
    sweep: &[f64],
) -> Vec<usize> {
    if tasks.is_empty() {
        return Vec::new();
    }
    let groups = sweep_groups(tasks, sweep);
    let mut local = vec![0usize];
    let mut group_of = vec![usize::MAX];
    let mut clusters = Vec::with_capacity(tasks.len());
    for t in tasks {
        let mut cl = Vec::new();
        for &n in &graph.alternatives[t.0] {
            cl.push(local.len());
            local.push(n);
            group_of.push(groups.get(t.0).copied().unwrap_or(usize::MAX));
        }
        clusters.push(cl);
    }
    let back = |i: usize, j: usize| {
        let (gi, gj) = (group_of[i], group_of[j]);
        if gi != usize::MAX && gj != usize::MAX && gj < gi {
            SWEEP_PENALTY
        } else {
            0.0
        }
    };
    // The lower bounds, then the planned legs over them (a leg is planned both ways at once):
    // a walk over the planned legs instead of a lookup per pair.
    let n = local.len();
    let mut data = vec![0.0; n * n];
    for (i, row) in data.chunks_exact_mut(n).enumerate() {
        for (j, c) in row.iter_mut().enumerate() {
            if i != j {
                *c = graph.costs.get(local[i], local[j]) + back(i, j);
            }
        }
    }
    let mut at = vec![usize::MAX; graph.len()];
    for (i, &node) in local.iter().enumerate() {
        at[node] = i;
    }
    for (&(a, b), leg) in planned {
        let (i, j) = (at[a], at[b]);
        if i == usize::MAX || j == usize::MAX || i == j {
            continue;
        }
        let time = match leg {
            Ok(leg) => leg.duration,
            Err(_) => NO_PATH,
        };
        data[i * n + j] = time + back(i, j);
        data[j * n + i] = time + back(j, i);
    }
    let costs = CostMatrix::new(n, data).expect("leg times and their bounds are finite and non-negative");
    let service = (0..local.len()).map(|i| graph.dwell[local[i]]).collect();
    let g = Gtsp::new(costs, clusters)
        .and_then(|g| g.with_depots(Some(0), None))
        .and_then(|g| g.with_service(service))
        .expect("every allocated task has candidates");
    let sol = cellplan_solve::solve_gtsp(
        &g,
        &GtspParams {
            time_limit: Duration::from_secs(600),
            seed,
            max_iterations: Some(iterations),
            max_stall: Some(GTSP_STALL),
            ..GtspParams::default()
        },
    );
    sol.tour.nodes.iter().map(|&i| local[i]).collect()
}

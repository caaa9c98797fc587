//! The best order of a robot's tasks: a GTSP over their candidates under the current costs,
//! optionally sweeping the tasks along a line and leaving some of them to the end.
use super::{NO_PATH, Planned};
use crate::plan::graph::RobotGraph;
use cellplan_model::tasks::TaskId;
use cellplan_solve::{CostMatrix, Gtsp, GtspParams};
use std::time::Duration;

/// Kicks of the GTSP heuristic per sequencing round (fixed, for determinism).
const GTSP_ITERATIONS: usize = 400;
/// ... and stop after this many kicks in a row that did not shorten the best order.
const GTSP_STALL: usize = 100;

/// What a robot's order must respect, wherever some order can (see
/// [`crate::plan::order_rule`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OrderRule {
    /// Each task's place along the sweep, indexed by task (empty: no sweep; see
    /// [`crate::plan::PlanSettings::sweep`]).
    pub sweep: Vec<f64>,
    /// Tasks visited after every other task of their robot (see
    /// [`crate::plan::PlanSettings::late`]).
    pub late: Vec<TaskId>,
}

/// The best order (GTSP over the tasks' candidates) under the current costs: planned legs at
/// their real time, the others at their lower bound; with `rule`'s sweep keys, the order that
/// sweeps the tasks in [`SWEEP_GROUPS`] groups of rising key, and with its late tasks, the
/// order that visits them after the others, wherever that is possible.
pub fn best_order(
    graph: &RobotGraph,
    tasks: &[TaskId],
    planned: &Planned,
    seed: u64,
    rule: &OrderRule,
) -> Vec<usize> {
    best_order_with(graph, tasks, planned, seed, GTSP_ITERATIONS, rule)
}

/// Groups of a sweep: a robot's tasks in this many groups of equal size by their sweep keys.
pub const SWEEP_GROUPS: usize = 3;

/// Added to the cost of a move from a task back to a task of an earlier group (of a sweep, or
/// the late tasks' after the others), in the GTSP only (the order's time is its real time):
/// longer than any leg, so that an order visits its groups one after the other whenever some
/// order can.
const SWEEP_PENALTY: f64 = 100.0;

/// Each task's group (`usize::MAX` for none), indexed by task: the tasks that are not late
/// sorted by their sweep keys (then by id) and cut into [`SWEEP_GROUPS`] groups of equal size
/// (without a sweep, one group when some task is late, else none), the late ones after them.
fn order_groups(tasks: &[TaskId], rule: &OrderRule) -> Vec<usize> {
    let late = |t: &TaskId| rule.late.contains(t);
    let any_late = tasks.iter().any(late);
    let mut group = vec![usize::MAX; tasks.iter().map(|t| t.0 + 1).max().unwrap_or(0)];
    let sweep = &rule.sweep;
    let mut sorted: Vec<TaskId> = tasks
        .iter()
        .copied()
        .filter(|t| t.0 < sweep.len() && !late(t))
        .collect();
    sorted.sort_by(|a, b| sweep[a.0].total_cmp(&sweep[b.0]).then(a.0.cmp(&b.0)));
    for (rank, t) in sorted.iter().enumerate() {
        group[t.0] = rank * SWEEP_GROUPS / sorted.len();
    }
    if any_late {
        for t in tasks {
            if late(t) {
                group[t.0] = SWEEP_GROUPS;
            } else if group[t.0] == usize::MAX {
                group[t.0] = 0;
            }
        }
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
    rule: &OrderRule,
) -> Vec<usize> {
    if tasks.is_empty() {
        return Vec::new();
    }
    let groups = order_groups(tasks, rule);
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn late_tasks_form_the_last_group() {
        let t = |i: usize| TaskId(i);
        let tasks = [t(0), t(1), t(2), t(5)];
        // No rule: no groups.
        assert!(
            order_groups(&tasks, &OrderRule::default())
                .iter()
                .all(|&g| g == usize::MAX)
        );
        // Late tasks after one group of the others; tasks of other robots have none.
        let late = OrderRule {
            late: vec![t(2), t(4)],
            ..OrderRule::default()
        };
        let g = order_groups(&tasks, &late);
        assert_eq!((g[0], g[1], g[2], g[5]), (0, 0, SWEEP_GROUPS, 0));
        assert_eq!((g[3], g[4]), (usize::MAX, usize::MAX));
        // With a sweep: the others in its groups by key, the late ones after them all.
        let keys = vec![3.0, 2.0, 0.0, 0.0, 0.0, 1.0];
        let both = OrderRule {
            sweep: keys.clone(),
            late: vec![t(2)],
        };
        let g = order_groups(&tasks, &both);
        assert_eq!((g[5], g[1], g[0], g[2]), (0, 1, 2, SWEEP_GROUPS));
        let sweep = OrderRule {
            sweep: keys,
            late: Vec::new(),
        };
        let g = order_groups(&tasks, &sweep);
        assert_eq!((g[2], g[5], g[1], g[0]), (0, 0, 1, 2));
    }
}

//! One vehicle's route: cheapest insertion, removal deltas and re-optimisation by the GTSP
//! solver (clusters = the route's tasks' alternatives, depot start = end, task service).
use std::time::Duration;

use super::MinMaxProblem;
use crate::gtsp::{self, GtspParams};
use crate::problem::Gtsp;

/// A visit: (task, node).
pub(crate) type Visit = (usize, usize);

/// The cheapest way to insert task `t` into vehicle `v`'s `tour`: (time added, position, node).
/// Ties go to the earliest position and the first node.
pub(crate) fn best_insertion(p: &MinMaxProblem, v: usize, tour: &[Visit], t: usize) -> (f64, usize, usize) {
    let veh = &p.vehicles[v];
    let c = |a: usize, b: usize| veh.costs.get(a, b);
    let mut best = (f64::INFINITY, 0, usize::MAX);
    for pos in 0..=tour.len() {
        let prev = if pos == 0 { veh.depot } else { tour[pos - 1].1 };
        let next = if pos == tour.len() { veh.depot } else { tour[pos].1 };
        let base = c(prev, next);
        for &a in &veh.alternatives[t] {
            let d = c(prev, a) + c(a, next) - base;
            if d < best.0 {
                best = (d, pos, a);
            }
        }
    }
    (best.0 + p.service[t], best.1, best.2)
}

/// Time change (negative or zero for metric costs) of removing position `i` from `tour`.
pub(crate) fn removal_delta(p: &MinMaxProblem, v: usize, tour: &[Visit], i: usize) -> f64 {
    let veh = &p.vehicles[v];
    let c = |a: usize, b: usize| veh.costs.get(a, b);
    let prev = if i == 0 { veh.depot } else { tour[i - 1].1 };
    let next = if i + 1 == tour.len() {
        veh.depot
    } else {
        tour[i + 1].1
    };
    let (t, x) = tour[i];
    c(prev, next) - c(prev, x) - c(x, next) - p.service[t]
}

/// A route over `tasks` by cheapest insertion in the given order.
pub(crate) fn insertion_route(p: &MinMaxProblem, v: usize, tasks: &[usize]) -> Vec<Visit> {
    let mut tour = Vec::with_capacity(tasks.len());
    for &t in tasks {
        let (_, pos, node) = best_insertion(p, v, &tour, t);
        tour.insert(pos, (t, node));
    }
    tour
}

/// `tour` re-optimised by the GTSP solver (`iters` kicks, `seed`); the input is returned when
/// the solver does not improve on it.
pub(crate) fn optimise(p: &MinMaxProblem, v: usize, tour: &[Visit], seed: u64, iters: usize) -> Vec<Visit> {
    if tour.is_empty() {
        return Vec::new();
    }
    let veh = &p.vehicles[v];
    let mut nodes = vec![veh.depot];
    let mut task_of = vec![usize::MAX];
    let mut clusters = Vec::with_capacity(tour.len());
    for &(t, _) in tour {
        let mut cl = Vec::with_capacity(veh.alternatives[t].len());
        for &a in &veh.alternatives[t] {
            cl.push(nodes.len());
            nodes.push(a);
            task_of.push(t);
        }
        clusters.push(cl);
    }
    let costs = veh.costs.sub(&nodes);
    let service = task_of
        .iter()
        .map(|&t| if t == usize::MAX { 0.0 } else { p.service[t] })
        .collect();
    let g = Gtsp::new(costs, clusters)
        .and_then(|g| g.with_depots(Some(0), None))
        .and_then(|g| g.with_service(service))
        .expect("a valid vehicle gives a valid GTSP");
    let sol = gtsp::solve(
        &g,
        &GtspParams {
            time_limit: Duration::from_secs(3600),
            seed,
            max_iterations: Some(iters),
            max_stall: None,
            method: gtsp::GtspMethod::Ils,
        },
    );
    let cand: Vec<Visit> = sol.tour.nodes.iter().map(|&i| (task_of[i], nodes[i])).collect();
    if p.route_time(v, &cand) < p.route_time(v, tour) - 1e-9 {
        cand
    } else {
        tour.to_vec()
    }
}

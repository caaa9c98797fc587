//! The two constructions: the proximity baseline and Algorithm 1 of paper 000 generalised to
//! m vehicles; and the augmenting-path repair that keeps caps feasible.
use std::collections::VecDeque;

use super::MinMaxProblem;
use super::route::{Visit, best_insertion, insertion_route, optimise};

/// GTSP kicks for the final optimisation of each constructed route.
pub(crate) const FINAL_ITERS: usize = 30;

/// A task moved between vehicles: (task, from, to).
pub(crate) type TaskMove = (usize, usize, usize);

/// A way to give task `t` a place when the vehicles that can do it may be full: `(v0, moves)`,
/// where `t` goes to `v0` after applying `moves` in order, each `(task, from, to)` moving a
/// task currently held by `from` to `to` (the last `to` ... first `from` chain ends at a
/// vehicle with room). `None` when no assignment of the tasks in `sets` plus `t` fits the caps.
pub(crate) fn augment(p: &MinMaxProblem, sets: &[Vec<usize>], t: usize) -> Option<(usize, Vec<TaskMove>)> {
    let caps: Vec<usize> = p.vehicles.iter().map(|v| v.cap).collect();
    augment_by(&caps, &|v, u| p.can_do(v, u), sets, t)
}

/// [`augment`] on plain data: vehicle `v` takes at most `caps[v]` tasks and can do task `u`
/// when `can_do(v, u)`.
pub(crate) fn augment_by(
    caps: &[usize],
    can_do: &dyn Fn(usize, usize) -> bool,
    sets: &[Vec<usize>],
    t: usize,
) -> Option<(usize, Vec<TaskMove>)> {
    let m = caps.len();
    // parent[w] = Some((v, task)) when w was reached by moving `task` from v to w.
    let mut parent: Vec<Option<(usize, usize)>> = vec![None; m];
    let mut seen = vec![false; m];
    let mut queue = VecDeque::new();
    for v in (0..m).filter(|&v| can_do(v, t)) {
        seen[v] = true;
        queue.push_back(v);
    }
    while let Some(v) = queue.pop_front() {
        if sets[v].len() < caps[v] {
            let mut moves = Vec::new();
            let mut w = v;
            while let Some((from, task)) = parent[w] {
                moves.push((task, from, w));
                w = from;
            }
            return Some((w, moves));
        }
        for &u in &sets[v] {
            for w in 0..m {
                if !seen[w] && can_do(w, u) {
                    seen[w] = true;
                    parent[w] = Some((v, u));
                    queue.push_back(w);
                }
            }
        }
    }
    None
}

/// Insert task `t` into `tours` when every vehicle able to do it is full, moving tasks along an
/// augmenting path (each moved task at its cheapest insertion).
pub(crate) fn place_by_augment(p: &MinMaxProblem, tours: &mut [Vec<Visit>], t: usize) {
    let sets: Vec<Vec<usize>> = tours.iter().map(|r| r.iter().map(|x| x.0).collect()).collect();
    let (v0, moves) = augment(p, &sets, t).expect("a validated problem always has room");
    for &(u, from, to) in &moves {
        tours[from].retain(|x| x.0 != u);
        let (_, pos, node) = best_insertion(p, to, &tours[to], u);
        tours[to].insert(pos, (u, node));
    }
    let (_, pos, node) = best_insertion(p, v0, &tours[v0], t);
    tours[v0].insert(pos, (t, node));
}

/// Cheapest depot-to-node cost of vehicle `v` for task `t`.
fn reach(p: &MinMaxProblem, v: usize, t: usize) -> f64 {
    let veh = &p.vehicles[v];
    veh.alternatives[t]
        .iter()
        .map(|&a| veh.costs.get(veh.depot, a))
        .fold(f64::INFINITY, f64::min)
}

/// Final GTSP optimisation of every route.
fn optimise_all(p: &MinMaxProblem, tours: Vec<Vec<Visit>>, seed: u64) -> Vec<Vec<Visit>> {
    tours
        .iter()
        .enumerate()
        .map(|(v, r)| optimise(p, v, r, seed ^ (v as u64) << 32, FINAL_ITERS))
        .collect()
}

/// The proximity baseline: tasks in index order, each to the vehicle (with room) whose depot
/// is cheapest to reach one of its nodes; then each route by the GTSP solver.
pub(crate) fn proximity(p: &MinMaxProblem, seed: u64) -> Vec<Vec<Visit>> {
    let m = p.vehicles.len();
    let mut sets: Vec<Vec<usize>> = vec![Vec::new(); m];
    let mut overflow = Vec::new();
    for t in 0..p.tasks {
        let best = p
            .capable(t)
            .into_iter()
            .filter(|&v| sets[v].len() < p.vehicles[v].cap)
            .min_by(|&a, &b| reach(p, a, t).total_cmp(&reach(p, b, t)).then(a.cmp(&b)));
        match best {
            Some(v) => sets[v].push(t),
            None => overflow.push(t),
        }
    }
    let mut tours: Vec<Vec<Visit>> = sets
        .iter()
        .enumerate()
        .map(|(v, s)| insertion_route(p, v, s))
        .collect();
    for t in overflow {
        place_by_augment(p, &mut tours, t);
    }
    optimise_all(p, tours, seed)
}

/// Algorithm 1 (paper 000) for m vehicles: the tasks only one vehicle can do go to it; the
/// shared ones, grouped by the set of vehicles able to do them (groups in lexicographic order
/// of that set) and nearest-first within a group, each go to the vehicle with room whose tour
/// cost *after* adding the task is least (line 15 compares `Cost_i` and `Cost_l`, the costs of
/// `u_j ∪ U_i` and `u_j ∪ U_l`; estimated by cheapest insertion); finally every route is
/// optimised by the GTSP solver (eq. 8–9).
pub(crate) fn algorithm1(p: &MinMaxProblem, seed: u64) -> Vec<Vec<Visit>> {
    let m = p.vehicles.len();
    let capable: Vec<Vec<usize>> = (0..p.tasks).map(|t| p.capable(t)).collect();
    let near = |t: usize| {
        capable[t]
            .iter()
            .map(|&v| reach(p, v, t))
            .fold(f64::INFINITY, f64::min)
    };
    let mut exclusive: Vec<Vec<usize>> = vec![Vec::new(); m];
    let mut shared = Vec::new();
    for t in 0..p.tasks {
        if capable[t].len() == 1 {
            exclusive[capable[t][0]].push(t);
        } else {
            shared.push(t);
        }
    }
    let mut tours: Vec<Vec<Visit>> = exclusive
        .iter_mut()
        .enumerate()
        .map(|(v, s)| {
            s.sort_by(|&a, &b| reach(p, v, a).total_cmp(&reach(p, v, b)).then(a.cmp(&b)));
            insertion_route(p, v, s)
        })
        .collect();
    let mut overflow = Vec::new();
    // Exclusive tasks over a cap (possible only when caps are tight) are placed by augmenting.
    for (v, tour) in tours.iter_mut().enumerate() {
        while tour.len() > p.vehicles[v].cap {
            overflow.push(tour.pop().expect("over cap, so not empty").0);
        }
    }
    shared.sort_by(|&a, &b| {
        capable[a]
            .cmp(&capable[b])
            .then(near(a).total_cmp(&near(b)))
            .then(a.cmp(&b))
    });
    let mut times: Vec<f64> = tours
        .iter()
        .enumerate()
        .map(|(v, r)| p.route_time(v, r))
        .collect();
    for t in shared {
        let mut best: Option<(f64, usize, usize, usize)> = None;
        for &v in &capable[t] {
            if tours[v].len() >= p.vehicles[v].cap {
                continue;
            }
            let (d, pos, node) = best_insertion(p, v, &tours[v], t);
            let cost = times[v] + d;
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, v, pos, node));
            }
        }
        match best {
            Some((cost, v, pos, node)) => {
                tours[v].insert(pos, (t, node));
                times[v] = cost;
            }
            None => overflow.push(t),
        }
    }
    for t in overflow {
        place_by_augment(p, &mut tours, t);
    }
    optimise_all(p, tours, seed)
}

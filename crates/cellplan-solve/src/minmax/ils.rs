//! Iterated local search between routes aimed at the makespan: relocate a task from the
//! longest route to another vehicle (best insertion position and node), swap a task of the
//! longest route with one of another route, re-optimise both changed routes with the GTSP
//! solver; random relocations as kicks and restarts from the best. Moves are compared by the
//! balance-limit violation first, then the route times sorted longest first (so ties at the
//! makespan are broken by the next longest), then the total.
use std::cmp::Ordering;
use std::time::Instant;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::construct::{self, FINAL_ITERS};
use super::route::{Visit, best_insertion, optimise, removal_delta};
use super::{MinMaxParams, MinMaxProblem, violation};

/// GTSP kicks when re-optimising a route after a move.
const MOVE_ITERS: usize = 5;
/// Non-improving kicks before restarting from the best.
const RESTART_AFTER: usize = 40;
const EPS: f64 = 1e-9;

/// Compare two vectors of route times (smaller is better).
fn cmp_times(p: &MinMaxProblem, a: &[f64], b: &[f64]) -> Ordering {
    let (va, vb) = (violation(p, a), violation(p, b));
    if (va - vb).abs() > EPS {
        return va.total_cmp(&vb);
    }
    let sorted = |x: &[f64]| {
        let mut s = x.to_vec();
        s.sort_by(|a, b| b.total_cmp(a));
        s
    };
    let (sa, sb) = (sorted(a), sorted(b));
    for (x, y) in sa.iter().zip(&sb) {
        if (x - y).abs() > EPS {
            return x.total_cmp(y);
        }
    }
    let (ta, tb): (f64, f64) = (a.iter().sum(), b.iter().sum());
    if (ta - tb).abs() > EPS {
        return ta.total_cmp(&tb);
    }
    Ordering::Equal
}

/// The reported objective: violation, makespan, total.
fn cmp_report(p: &MinMaxProblem, a: &[f64], b: &[f64]) -> Ordering {
    let key = |x: &[f64]| {
        (
            violation(p, x),
            x.iter().copied().fold(0.0, f64::max),
            x.iter().sum::<f64>(),
        )
    };
    let (ka, kb) = (key(a), key(b));
    for (x, y) in [(ka.0, kb.0), (ka.1, kb.1), (ka.2, kb.2)] {
        if (x - y).abs() > EPS {
            return x.total_cmp(&y);
        }
    }
    Ordering::Equal
}

#[derive(Clone)]
struct St {
    tours: Vec<Vec<Visit>>,
    times: Vec<f64>,
}

impl St {
    fn new(p: &MinMaxProblem, tours: Vec<Vec<Visit>>) -> Self {
        let times = tours
            .iter()
            .enumerate()
            .map(|(v, r)| p.route_time(v, r))
            .collect();
        St { tours, times }
    }

    fn reopt(&mut self, p: &MinMaxProblem, v: usize, seed: u64) {
        self.tours[v] = optimise(p, v, &self.tours[v], seed, MOVE_ITERS);
        self.times[v] = p.route_time(v, &self.tours[v]);
    }
}

enum Move {
    /// Task at position `i` of route `f` to vehicle `w` at (`pos`, `node`).
    Relocate {
        f: usize,
        i: usize,
        w: usize,
        pos: usize,
        node: usize,
    },
    /// Task at `i` of the longest route with the task at `j` of route `w`.
    Swap { i: usize, w: usize, j: usize },
}

/// Best-improvement descent until no move improves or `stop()` says so.
fn descend(p: &MinMaxProblem, st: &mut St, seed: &mut u64, stop: &dyn Fn() -> bool) {
    let m = p.vehicles.len();
    loop {
        if stop() {
            return;
        }
        let l = (0..m)
            .max_by(|&a, &b| st.times[a].total_cmp(&st.times[b]).then(b.cmp(&a)))
            .expect("at least one vehicle");
        let mut best_times = st.times.clone();
        let mut best_move = None;
        let mut trial = st.times.clone();
        // Relocations from any route (shortening a non-longest route can open the way for
        // the longest one under the sorted-times order).
        for f in 0..m {
            let tf = &st.tours[f];
            for i in 0..tf.len() {
                let task = tf[i].0;
                let rem = removal_delta(p, f, tf, i);
                for w in 0..m {
                    if w == f || !p.can_do(w, task) || st.tours[w].len() >= p.vehicles[w].cap {
                        continue;
                    }
                    let (ins, pos, node) = best_insertion(p, w, &st.tours[w], task);
                    trial.copy_from_slice(&st.times);
                    trial[f] += rem;
                    trial[w] += ins;
                    if cmp_times(p, &trial, &best_times) == Ordering::Less {
                        best_times.copy_from_slice(&trial);
                        best_move = Some(Move::Relocate { f, i, w, pos, node });
                    }
                }
            }
        }
        let tl = &st.tours[l];
        for i in 0..tl.len() {
            let task = tl[i].0;
            let rem = removal_delta(p, l, tl, i);
            // Swaps.
            let mut l_minus: Vec<Visit> = tl.clone();
            l_minus.remove(i);
            let l_minus_time = st.times[l] + rem;
            for w in 0..m {
                if w == l || !p.can_do(w, task) {
                    continue;
                }
                let tw = &st.tours[w];
                for j in 0..tw.len() {
                    let other = tw[j].0;
                    if !p.can_do(l, other) {
                        continue;
                    }
                    let (ins_l, _, _) = best_insertion(p, l, &l_minus, other);
                    let new_l = l_minus_time + ins_l;
                    if new_l >= best_times.iter().copied().fold(0.0, f64::max) + EPS
                        && violation(p, &best_times) <= EPS
                    {
                        continue;
                    }
                    let rem_w = removal_delta(p, w, tw, j);
                    let mut w_minus = tw.clone();
                    w_minus.remove(j);
                    let (ins_w, _, _) = best_insertion(p, w, &w_minus, task);
                    trial.copy_from_slice(&st.times);
                    trial[l] = new_l;
                    trial[w] += rem_w + ins_w;
                    if cmp_times(p, &trial, &best_times) == Ordering::Less {
                        best_times.copy_from_slice(&trial);
                        best_move = Some(Move::Swap { i, w, j });
                    }
                }
            }
        }
        let Some(mv) = best_move else { return };
        let (l, w) = match mv {
            Move::Relocate { f, i, w, pos, node } => {
                let (task, _) = st.tours[f].remove(i);
                st.tours[w].insert(pos, (task, node));
                (f, w)
            }
            Move::Swap { i, w, j } => {
                let (a, _) = st.tours[l].remove(i);
                let (b, _) = st.tours[w].remove(j);
                let (_, pos, node) = best_insertion(p, l, &st.tours[l], b);
                st.tours[l].insert(pos, (b, node));
                let (_, pos, node) = best_insertion(p, w, &st.tours[w], a);
                st.tours[w].insert(pos, (a, node));
                (l, w)
            }
        };
        for v in [l, w] {
            st.times[v] = p.route_time(v, &st.tours[v]);
            *seed = seed.wrapping_add(1);
            st.reopt(p, v, *seed);
        }
    }
}

/// `k` random relocations (a random task to a random other vehicle able to take it).
fn kick(p: &MinMaxProblem, st: &mut St, rng: &mut ChaCha8Rng, k: usize) {
    let m = p.vehicles.len();
    for _ in 0..k {
        let nonempty: Vec<usize> = (0..m).filter(|&v| !st.tours[v].is_empty()).collect();
        if nonempty.is_empty() {
            return;
        }
        let v = nonempty[rng.random_range(0..nonempty.len())];
        let i = rng.random_range(0..st.tours[v].len());
        let task = st.tours[v][i].0;
        let targets: Vec<usize> = (0..m)
            .filter(|&w| w != v && p.can_do(w, task) && st.tours[w].len() < p.vehicles[w].cap)
            .collect();
        if targets.is_empty() {
            continue;
        }
        let w = targets[rng.random_range(0..targets.len())];
        st.tours[v].remove(i);
        let (_, pos, node) = best_insertion(p, w, &st.tours[w], task);
        st.tours[w].insert(pos, (task, node));
        st.times[v] = p.route_time(v, &st.tours[v]);
        st.times[w] = p.route_time(w, &st.tours[w]);
    }
}

/// Independent search chains. Each runs its share of the kicks from the same start with its
/// own seed, on its own thread when there is one; the best chain wins (ties to the first), so
/// the result does not depend on the thread count.
const CHAINS: usize = 2;

/// The ILS; returns the best tours found.
pub(crate) fn run(p: &MinMaxProblem, params: &MinMaxParams) -> Vec<Vec<Visit>> {
    use rayon::prelude::*;
    let start = Instant::now();
    let a = St::new(p, construct::proximity(p, params.seed));
    let b = St::new(p, construct::algorithm1(p, params.seed));
    let first = if cmp_report(p, &b.times, &a.times) == Ordering::Less {
        b
    } else {
        a
    };
    let per_chain = params.max_iterations.map(|n| n.div_ceil(CHAINS));
    let chains: Vec<(St, u64)> = (0..CHAINS)
        .into_par_iter()
        .map(|c| {
            let seed = params
                .seed
                .wrapping_add((c as u64).wrapping_mul(0xA076_1D64_78BD_642F));
            chain(p, params, start, first.clone(), seed, per_chain)
        })
        .collect();
    let (best, seed) = chains
        .into_iter()
        .reduce(|x, y| {
            if cmp_report(p, &y.0.times, &x.0.times) == Ordering::Less {
                y
            } else {
                x
            }
        })
        .expect("at least one chain");
    let mut polished = best.clone();
    for v in 0..polished.tours.len() {
        polished.tours[v] = optimise(p, v, &polished.tours[v], seed.wrapping_add(v as u64), FINAL_ITERS);
        polished.times[v] = p.route_time(v, &polished.tours[v]);
    }
    if cmp_report(p, &polished.times, &best.times) == Ordering::Greater {
        polished = best;
    }
    polished.tours
}

/// One chain: descents and kicks from `cur` for at most `max_iter` kicks (and the time
/// limit); the best state and the last GTSP seed.
fn chain(
    p: &MinMaxProblem,
    params: &MinMaxParams,
    start: Instant,
    mut cur: St,
    seed: u64,
    max_iter: Option<usize>,
) -> (St, u64) {
    let mut best = cur.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut seed = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    let max_iter = max_iter.unwrap_or(usize::MAX);
    let mut stale = 0;
    let mut iter = 0;
    loop {
        descend(p, &mut cur, &mut seed, &|| start.elapsed() >= params.time_limit);
        if cmp_report(p, &cur.times, &best.times) == Ordering::Less {
            best = cur.clone();
            stale = 0;
        } else {
            stale += 1;
        }
        if iter >= max_iter || start.elapsed() >= params.time_limit {
            break;
        }
        iter += 1;
        if stale >= RESTART_AFTER {
            cur = best.clone();
            stale = 0;
            let k = 3 + rng.random_range(0..4);
            kick(p, &mut cur, &mut rng, k);
        } else {
            let k = 1 + rng.random_range(0..2);
            kick(p, &mut cur, &mut rng, k);
        }
    }
    (best, seed)
}

//! Iterated local search: construct, improve, then repeatedly kick the accepted tour with a
//! local double bridge (swap two adjacent segments of random lengths), improve, and accept the
//! result if it is no worse than the current tour by more than a random threshold (see
//! [`ACCEPT`]); the best tour seen is kept.
use std::time::Instant;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::search::{Queue, local_search};
use super::{GtspParams, Inst, State, layer};

/// Kicked segments are up to a quarter of the tour long, but at least this many items may be
/// moved (when the tour has them)...
const MIN_SEGMENT: usize = 30;
/// ... and never more than this.
const MAX_SEGMENT: usize = 200;

/// Acceptance: a kicked and improved tour replaces the current one when it is worse by at most
/// `ACCEPT · u` mean arcs (u uniform in [0, 1)), a random walk near the best tour that escapes
/// the deep local optima plain "better or equal" acceptance sticks in (on kroB100, ch150,
/// rat195 it turns 0.2–0.4 % gaps at 2 s into the optimum); the best tour seen is returned.
const ACCEPT: f64 = 1.0;

/// The best state found and the number of kicks.
pub(super) fn run(inst: &Inst, params: &GtspParams, deadline: Instant) -> (State, usize) {
    let mut cur = State::new(inst, inst.first_order.clone());
    let mut queue = Queue::default();
    let mut memo = layer::LayerMemo::default();
    for &x in &cur.t.clone() {
        queue.push(x);
    }
    local_search(inst, &mut cur, &mut queue, &mut memo);
    let mut cur_cost = inst.cost(&cur);
    let m = cur.t.len();
    let lo = usize::from(inst.depot);
    let movable = m - lo.min(m);
    if movable < 3 {
        return (cur, 0);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mut trial = cur.clone();
    let mut best = cur.clone();
    let mut best_cost = cur_cost;
    let accept = ACCEPT;
    let mut iterations = 0;
    let mut stall = 0;
    loop {
        if params.max_iterations.is_some_and(|n| iterations >= n) {
            break;
        }
        if params.max_stall.is_some_and(|n| stall >= n) {
            break;
        }
        stall += 1;
        if Instant::now() >= deadline {
            break;
        }
        iterations += 1;
        trial.clone_from(&cur);
        // Double bridge: swap segments [p, p+l1) and [p+l1, p+l1+l2).
        let cap = (movable / 4).clamp(MIN_SEGMENT, MAX_SEGMENT).min(movable - 1);
        let l1 = rng.random_range(1..=cap);
        let l2 = rng.random_range(1..=cap.min(movable - l1));
        let p = rng.random_range(lo..=m - l1 - l2);
        let ends = [
            trial.t[trial.prev(p)],
            trial.t[p],
            trial.t[p + l1 - 1],
            trial.t[p + l1],
            trial.t[p + l1 + l2 - 1],
            trial.t[trial.next(p + l1 + l2 - 1)],
        ];
        trial.t[p..p + l1 + l2].rotate_left(l1);
        trial.reindex(inst, p, p + l1 + l2 - 1);
        for e in ends {
            queue.push(e);
        }
        // Let the nodes follow the new order before improving it.
        for x in layer::layer_pass(inst, &mut trial, &mut memo) {
            queue.push(x);
        }
        local_search(inst, &mut trial, &mut queue, &mut memo);
        let cost = inst.cost(&trial);
        let threshold = accept * best_cost / movable as f64 * rng.random::<f64>();
        if cost <= cur_cost + threshold {
            std::mem::swap(&mut cur, &mut trial);
            cur_cost = cost;
            if cost < best_cost - super::EPS {
                best.clone_from(&cur);
                best_cost = cost;
                stall = 0;
            }
        }
    }
    (best, iterations)
}

//! Our optimiser: a good start built from the board's geometry, then an iterated local search on
//! the true cycle-time model (order moves, bin swaps — the quadratic assignment of types to
//! bins —, robot re-assignment, the fixed devices' positions), every candidate scored with our
//! rendezvous rule ([`crate::rendezvous::Greedy`]) and the exact safety delay; finally the
//! rendezvous themselves are polished one meeting at a time on the whole schedule.
//!
//! Two chains with their own seeds run side by side and the better is kept, so the result does
//! not depend on the number of threads. The budget is counted in simulations.
use crate::cell::PcbCell;
use crate::rendezvous::Greedy;
use crate::sim::{Decision, DelayRule, Given, simulate, slot_lookup};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod polish;
mod start;
use polish::tune_fixed;
pub use polish::{polish, settle_order};
use start::mirrored;
pub use start::{default_slots, fix_devices, initial, nearer_feeder, robot_can};

/// Search settings.
#[derive(Clone, Copy, Debug)]
pub struct SearchSettings {
    /// Simulations in all (both chains).
    pub evaluations: usize,
    /// Seed.
    pub seed: u64,
    /// Wall-clock safety net.
    pub deadline: Option<std::time::Instant>,
}

impl Default for SearchSettings {
    fn default() -> Self {
        SearchSettings {
            evaluations: 200_000,
            seed: 0,
            deadline: None,
        }
    }
}

/// The delay rule of our optimiser.
pub fn rule(cell: &PcbCell) -> DelayRule {
    if cell.robots.len() == 2 && cell.collision_avoidance {
        DelayRule::Exact
    } else {
        DelayRule::Off
    }
}

/// Scores a decision with our rendezvous rule (fixed devices where the decision puts them).
pub fn evaluate(cell: &PcbCell, d: &Decision) -> f64 {
    simulate(cell, d, &mut Greedy, rule(cell)).makespan
}

/// Writes the rendezvous our rule chooses into the decision (so it stands alone).
pub fn record_rendezvous(cell: &PcbCell, d: &mut Decision) {
    let s = simulate(cell, d, &mut Greedy, rule(cell));
    for cy in &s.cycles {
        d.carriage[cy.component] = cy.carriage;
        d.table[cy.component] = cy.table;
    }
}

/// The progress of a run: (simulations, best assembly time).
pub type Trace = Vec<(usize, f64)>;

/// Runs our optimiser from `start` (or our own start); returns the best decision (with its
/// rendezvous recorded), its assembly time under [`Given`] rendezvous, and the trace.
pub fn run(
    cell: &PcbCell,
    settings: &SearchSettings,
    start: Option<&Decision>,
) -> (Decision, f64, Trace, bool) {
    let start = start.cloned().unwrap_or_else(|| initial(cell));
    let half = settings.evaluations / 2;
    let seed = |k: u64| settings.seed.wrapping_mul(4).wrapping_add(k);
    let ((d0, v0, t0, h0), (d1, v1, t1, h1)) = rayon::join(
        || staged_chain(cell, &start, half, 0, seed(1), settings.deadline),
        || {
            staged_chain(
                cell,
                &start,
                settings.evaluations - half,
                1,
                seed(2),
                settings.deadline,
            )
        },
    );
    let hit = h0 || h1;
    // Merge the traces by simulations spent (both chains run at once).
    let mut trace: Trace = Vec::new();
    let mut all: Vec<(usize, f64)> = t0
        .iter()
        .map(|&(e, v)| (e * 2, v))
        .chain(t1.iter().map(|&(e, v)| (e * 2, v)))
        .collect();
    all.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    for (e, v) in all {
        if trace.last().is_none_or(|l: &(usize, f64)| v < l.1 - 1e-12) {
            trace.push((e, v));
        }
    }
    if v1 < v0 - 1e-12 {
        (d1, v1, trace, hit)
    } else {
        (d0, v0, trace, hit)
    }
}

/// One of the two chains. Chain 1 starts from the mirrored start where there is one (the
/// feeders' contents exchanged), so that the two explore the two sides a fixed table can take.
/// With moving feeders the chain goes through stages, each a cell with fewer devices moving
/// (cheaper to simulate — no carriage to choose — and a fixed device is one of a moving one's
/// options), each stage starting from the last one's result: chain 0 of an all-moving cell
/// runs moving-table then all-moving, chain 1 all-fixed, moving-feeders, all-moving; a
/// moving-feeders cell runs all-fixed then moving-feeders. At the end, the previous stage's
/// plan as it stands (the devices it fixed moving once from home to their spot), polished, is
/// a candidate too.
fn staged_chain(
    cell: &PcbCell,
    start: &Decision,
    budget: usize,
    k: usize,
    seed: u64,
    deadline: Option<std::time::Instant>,
) -> (Decision, f64, Trace, bool) {
    use crate::cell::Configuration::*;
    let start = if k == 1 {
        mirrored(cell, start).unwrap_or_else(|| start.clone())
    } else {
        start.clone()
    };
    let stages: &[(crate::cell::Configuration, usize)] = match (cell.configuration, k) {
        (AllMoving, 0) => &[(MovingTable, 60), (AllMoving, 40)],
        (AllMoving, _) => &[(AllFixed, 40), (MovingCds, 30), (AllMoving, 30)],
        (MovingCds, _) => &[(AllFixed, 60), (MovingCds, 40)],
        _ => &[],
    };
    if stages.is_empty() || budget < 1000 {
        return chain(cell, &start, budget, seed, deadline);
    }
    let mut d = start;
    let mut spent = 0;
    let mut trace: Trace = Vec::new();
    let mut last = (0.0, false);
    for (i, &(conf, share)) in stages.iter().enumerate() {
        let mut stage = cell.clone();
        stage.configuration = conf;
        let real = i + 1 == stages.len();
        let mut part = if real {
            budget - spent
        } else {
            budget * share / 100
        };
        let polish_share = if real { part / 5 } else { 0 };
        part -= polish_share;
        let (d2, v2, t2, hit) = chain(&stage, &d, part, seed.wrapping_add(1000 * i as u64), deadline);
        if real {
            // The relaxed stages' times are not this cell's: only this stage's trace is kept.
            trace = t2.into_iter().map(|(e, v)| (e + spent, v)).collect();
        }
        spent += part;
        if hit {
            let mut d2 = d2;
            if !real {
                record_rendezvous(cell, &mut d2);
            }
            let v = evaluate(cell, &d2);
            return (d2, v, vec![(spent, v)], true);
        }
        let prev = std::mem::replace(&mut d, d2);
        last = (v2, false);
        if real {
            let as_is = simulate(cell, &prev, &mut Given(&prev), rule(cell)).makespan;
            if as_is < v2 * 1.05 {
                let (d3, v3, _) = polish(cell, prev, polish_share);
                if v3 < v2 - 1e-12 {
                    trace.push((budget, v3));
                    return (d3, v3, trace, false);
                }
            }
        }
    }
    (d, last.0, trace, last.1)
}

/// Moves of the local search.
fn neighbour(cell: &PcbCell, d: &Decision, rng: &mut ChaCha8Rng, step: &mut [f64; 2]) -> Option<Decision> {
    let n = d.order.len();
    let mut x = d.clone();
    let can_bins = cell.given_bins.is_empty();
    let two = cell.robots.len() == 2;
    let fixed = !cell.configuration.feeders_move() || !cell.configuration.table_moves();
    let roll: f64 = rng.random();
    let near = |rng: &mut ChaCha8Rng, i: usize| -> usize {
        if rng.random::<f64>() < 0.7 {
            let lo = i.saturating_sub(12);
            let hi = (i + 12).min(n - 1);
            rng.random_range(lo..=hi)
        } else {
            rng.random_range(0..n)
        }
    };
    if n == 0 || (n < 2 && !two) {
        return None;
    }
    // One component of two robots: only a change of robot is a move.
    let roll = if n < 2 { 0.86 } else { roll };
    if roll < 0.35 {
        let i = rng.random_range(0..n);
        let j = near(rng, i);
        let c = x.order.remove(i);
        x.order.insert(j.min(n - 1), c);
    } else if roll < 0.5 {
        let i = rng.random_range(0..n);
        let j = near(rng, i);
        x.order.swap(i, j);
    } else if roll < 0.65 {
        let i = rng.random_range(0..n);
        let j = near(rng, i);
        x.order[i.min(j)..=i.max(j)].reverse();
    } else if roll < 0.8 && can_bins {
        // Swap two bins: within a feeder, or (one robot) across the two.
        let f = rng.random_range(0..2);
        let g = if two { f } else { rng.random_range(0..2) };
        let a = rng.random_range(0..x.slots[f].len());
        let b = rng.random_range(0..x.slots[g].len());
        if f == g {
            x.slots[f].swap(a, b);
        } else {
            let (lo, hi) = x.slots.split_at_mut(1);
            let (s0, s1) = if f == 0 {
                (&mut lo[0][a], &mut hi[0][b])
            } else {
                (&mut hi[0][a], &mut lo[0][b])
            };
            std::mem::swap(s0, s1);
        }
        let lookup = slot_lookup(cell, &x);
        for c in 0..n {
            let t = cell.type_of[c];
            if two {
                lookup[x.robot[c]][t]?;
            } else {
                x.feeder[c] = if lookup[0][t].is_some() {
                    0
                } else if lookup[1][t].is_some() {
                    1
                } else {
                    return None;
                };
            }
        }
        if !two {
            // Which bin of each type: every bin must still be within the robot's reach.
            for c in 0..n {
                let slot = lookup[x.feeder[c]][cell.type_of[c]]?;
                cell.pick_range(0, x.feeder[c], slot)?;
            }
        }
    } else if roll < 0.9 && two && !(fixed && roll >= 0.85 && n >= 2) {
        let c = rng.random_range(0..n);
        let lookup = slot_lookup(cell, &x);
        let r = 1 - x.robot[c];
        if !robot_can(cell, &lookup, r, c) {
            return None;
        }
        x.robot[c] = r;
        x.feeder[c] = r;
    } else if roll < 0.9 && !two && !(fixed && roll >= 0.85) {
        // One robot: a component whose type both feeders hold picks from the other one.
        let c = rng.random_range(0..n);
        let lookup = slot_lookup(cell, &x);
        let f = 1 - x.feeder[c];
        let slot = lookup[f][cell.type_of[c]]?;
        cell.pick_range(0, f, slot)?;
        x.feeder[c] = f;
    } else if fixed {
        // Move a fixed device: a small step, or anywhere in its travel (the time is far from
        // unimodal in a fixed position while order and bins follow the old one).
        let which = rng.random_range(0..3);
        let jump = rng.random::<bool>();
        let g = gauss(rng);
        let h = gauss(rng);
        let (u, w): (f64, f64) = (rng.random(), rng.random());
        if which < 2 && !cell.configuration.feeders_move() {
            let f = which;
            let travel = cell.feeders[f].travel;
            for c in 0..n {
                if x.feeder[c] == f {
                    x.carriage[c] = if jump {
                        travel[0] + u * (travel[1] - travel[0])
                    } else {
                        x.carriage[c] + g * step[0]
                    };
                }
            }
        } else if !cell.configuration.table_moves() {
            let (tx, ty) = (cell.table.x, cell.table.y);
            for t in x.table.iter_mut() {
                if jump {
                    *t = [tx[0] + u * (tx[1] - tx[0]), ty[0] + w * (ty[1] - ty[0])];
                } else {
                    t[0] += g * step[1];
                    t[1] += h * step[1];
                }
            }
        } else {
            return None;
        }
    } else {
        return None;
    }
    if fixed {
        fix_devices(cell, &mut x, None)?;
    }
    Some(x)
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u: f64 = rng.random::<f64>().max(1e-12);
    let v: f64 = rng.random();
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// The first position of the order from which `b` may simulate differently from `a` (0 when
/// a fixed device stands elsewhere, since that is part of the start).
fn first_change(cell: &PcbCell, a: &Decision, b: &Decision) -> usize {
    let n = a.order.len();
    if (!cell.configuration.feeders_move() && a.carriage != b.carriage)
        || (!cell.configuration.table_moves() && a.table != b.table)
    {
        return 0;
    }
    let (la, lb) = (slot_lookup(cell, a), slot_lookup(cell, b));
    for k in 0..n {
        let (ca, cb) = (a.order[k], b.order[k]);
        if ca != cb || a.feeder[ca] != b.feeder[cb] || a.robot[ca] != b.robot[cb] {
            return k;
        }
        let t = cell.type_of[ca];
        if la[a.feeder[ca]][t] != lb[b.feeder[cb]][t] {
            return k;
        }
    }
    n
}

fn chain(
    cell: &PcbCell,
    start: &Decision,
    budget: usize,
    seed: u64,
    deadline: Option<std::time::Instant>,
) -> (Decision, f64, Trace, bool) {
    let mut hit = false;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut cur, mut cur_v, mut evals) = tune_fixed(cell, start.clone(), 2);

    let mut best = cur.clone();
    let mut best_v = cur_v;
    let mut trace: Trace = vec![(evals, best_v)];
    let mut step = [0.01, 0.01];
    // Keep a fifth of the budget for the rendezvous polish.
    let search_budget = budget - budget / 5;
    // Simulated annealing: the start temperature accepts a typical worsening move of the
    // first sample with probability 0.3; geometric cooling by a factor 10⁴ over the budget.
    let mut sample = Vec::new();
    for _ in 0..50 {
        if let Some(x) = neighbour(cell, &cur, &mut rng, &mut step) {
            let v = evaluate(cell, &x);
            evals += 1;
            if v > cur_v {
                sample.push(v - cur_v);
            }
        }
    }
    let typical = if sample.is_empty() {
        1e-3 * cur_v.max(1e-9)
    } else {
        sample.iter().sum::<f64>() / sample.len() as f64
    };
    let t0 = typical / -(0.3f64.ln());
    let start_evals = evals;
    let span = (search_budget.saturating_sub(start_evals)).max(1) as f64;
    let mut since_best = 0usize;
    let n = cell.len().max(1);
    // One robot: each candidate is simulated only from the first cycle it changes, from the
    // state the current decision had there, and only as long as it can still be accepted.
    let one = cell.robots.len() == 1;
    let least = if one {
        crate::sim::least_cycles(cell)
    } else {
        Vec::new()
    };
    let mut cur_states = vec![crate::sim::blank_state(); cell.len() + 1];
    let mut scratch = cur_states.clone();
    if one {
        let slot_of = slot_lookup(cell, &cur);
        cur_v = crate::sim::one_robot_from(
            cell,
            &cur,
            &slot_of,
            &mut Greedy,
            &mut cur_states,
            0,
            f64::INFINITY,
            &least,
        )
        .unwrap_or(cur_v);
    }
    while evals < search_budget {
        if evals % 64 == 0 && deadline.is_some_and(|d| std::time::Instant::now() > d) {
            hit = true;
            break;
        }
        let Some(x) = neighbour(cell, &cur, &mut rng, &mut step) else {
            evals += 1;
            continue;
        };
        let progress = (evals - start_evals) as f64 / span;
        let temp = t0 * (1e-4f64).powf(progress);
        let u: f64 = rng.random::<f64>().max(1e-300);
        // Accepted when v ≤ cur_v, or with probability exp(−(v − cur_v)/T).
        let threshold = (cur_v - temp * u.ln()).max(cur_v + 1e-12);
        evals += 1;
        let value = if one {
            let from = first_change(cell, &cur, &x);
            scratch[..=from].copy_from_slice(&cur_states[..=from]);
            let slot_of = slot_lookup(cell, &x);
            crate::sim::one_robot_from(
                cell,
                &x,
                &slot_of,
                &mut Greedy,
                &mut scratch,
                from,
                threshold,
                &least,
            )
        } else {
            Some(evaluate(cell, &x)).filter(|&v| v <= threshold)
        };
        since_best += 1;
        if let Some(v) = value {
            cur = x;
            cur_v = v;
            if one {
                std::mem::swap(&mut cur_states, &mut scratch);
            }
            if v < best_v - 1e-12 {
                best = cur.clone();
                best_v = v;
                since_best = 0;
                trace.push((evals, best_v));
            }
        }
        if since_best > 200 * n {
            // Long without a new best: back to it, with the fixed devices re-tuned.
            let (d, v, spent) = tune_fixed(cell, best.clone(), 1);
            evals += spent;
            cur = d;
            cur_v = v;
            since_best = 0;
            if one {
                let slot_of = slot_lookup(cell, &cur);
                cur_v = crate::sim::one_robot_from(
                    cell,
                    &cur,
                    &slot_of,
                    &mut Greedy,
                    &mut cur_states,
                    0,
                    f64::INFINITY,
                    &least,
                )
                .unwrap_or(cur_v);
            }
            if cur_v < best_v - 1e-12 {
                best = cur.clone();
                best_v = cur_v;
                trace.push((evals, best_v));
            }
        }
    }
    record_rendezvous(cell, &mut best);
    let polish_budget = if hit { 0 } else { budget.saturating_sub(evals) };
    let (best, best_v, spent) = polish(cell, best, polish_budget);
    if let Some(last) = trace.last()
        && best_v < last.1 - 1e-12
    {
        trace.push((evals + spent, best_v));
    }
    (best, best_v, trace, hit)
}

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

/// Whether robot `r` can place component `c` (two robots: its own feeder stocks the type).
pub fn robot_can(cell: &PcbCell, lookup: &[Vec<Option<usize>>; 2], r: usize, c: usize) -> bool {
    if cell.place_box(r, c).is_none() {
        return false;
    }
    if cell.robots.len() == 1 {
        return true;
    }
    lookup[r][cell.type_of[c]].is_some_and(|slot| cell.pick_range(r, r, slot).is_some())
}

/// Bins ordered from the middle of the feeder outward.
fn center_out(bins: usize) -> Vec<usize> {
    let mid = (bins as f64 - 1.0) / 2.0;
    let mut v: Vec<usize> = (0..bins).collect();
    v.sort_by(|&a, &b| {
        (a as f64 - mid)
            .abs()
            .total_cmp(&(b as f64 - mid).abs())
            .then(a.cmp(&b))
    });
    v
}

/// The bins the cell gives; else, with one robot, each type in the feeder on its components'
/// side of the board, most used types in the middle bins; with two robots every type in both
/// feeders where they hold all types, else split the same way.
pub fn default_slots(cell: &PcbCell) -> [Vec<Option<usize>>; 2] {
    let mut slots = [vec![None; cell.feeders[0].bins], vec![None; cell.feeders[1].bins]];
    if !cell.given_bins.is_empty() {
        for b in &cell.given_bins {
            slots[b.feeder][b.slot] = Some(b.kind);
        }
        return slots;
    }
    let nt = cell.types.len();
    let mut count = vec![0usize; nt];
    let mut mean_x = vec![0.0f64; nt];
    for (c, &t) in cell.type_of.iter().enumerate() {
        count[t] += 1;
        mean_x[t] += cell.components[c].position[0];
    }
    for t in 0..nt {
        mean_x[t] /= count[t].max(1) as f64;
    }
    let mut by_use: Vec<usize> = (0..nt).collect();
    by_use.sort_by(|&a, &b| count[b].cmp(&count[a]).then(a.cmp(&b)));
    let order = [center_out(cell.feeders[0].bins), center_out(cell.feeders[1].bins)];
    if cell.robots.len() == 2 && cell.feeders.iter().all(|f| f.bins >= nt) {
        for f in 0..2 {
            for (k, &t) in by_use.iter().enumerate() {
                slots[f][order[f][k]] = Some(t);
            }
        }
        return slots;
    }
    let mid = cell.board.size[0] / 2.0;
    let mut used = [0usize; 2];
    for &t in &by_use {
        let prefer = if mean_x[t] < mid { 0 } else { 1 };
        let f = if used[prefer] < cell.feeders[prefer].bins {
            prefer
        } else {
            1 - prefer
        };
        slots[f][order[f][used[f]]] = Some(t);
        used[f] += 1;
    }
    slots
}

/// Puts every meeting of a fixed device at one position: the given fractions of the common
/// feasible range, or else the current position of its first use, clipped. `None` if the
/// device has no position that serves all its meetings.
pub fn fix_devices(cell: &PcbCell, d: &mut Decision, fractions: Option<[f64; 4]>) -> Option<()> {
    let lookup = slot_lookup(cell, d);
    let n = cell.len();
    if !cell.configuration.feeders_move() {
        for f in 0..2 {
            let mut range = cell.feeders[f].travel;
            let mut first = None;
            for &c in &d.order {
                if d.feeder[c] != f {
                    continue;
                }
                first.get_or_insert(c);
                let slot = lookup[f][cell.type_of[c]]?;
                let r = cell.pick_range(d.robot[c], f, slot)?;
                range = [range[0].max(r[0]), range[1].min(r[1])];
            }
            if range[0] > range[1] {
                return None;
            }
            let Some(first) = first else { continue };
            let pos = match fractions {
                Some(fr) => range[0] + fr[f] * (range[1] - range[0]),
                None => d.carriage[first].clamp(range[0], range[1]),
            };
            for c in 0..n {
                if d.feeder[c] == f {
                    d.carriage[c] = pos;
                }
            }
        }
    }
    if !cell.configuration.table_moves() && n > 0 {
        let mut bx = [cell.table.x, cell.table.y];
        for c in 0..n {
            let b = cell.place_box(d.robot[c], c)?;
            for a in 0..2 {
                bx[a] = [bx[a][0].max(b[a][0]), bx[a][1].min(b[a][1])];
            }
        }
        if bx[0][0] > bx[0][1] || bx[1][0] > bx[1][1] {
            return None;
        }
        let first = d.order[0];
        let pos = match fractions {
            Some(fr) => [
                bx[0][0] + fr[2] * (bx[0][1] - bx[0][0]),
                bx[1][0] + fr[3] * (bx[1][1] - bx[1][0]),
            ],
            None => [
                d.table[first][0].clamp(bx[0][0], bx[0][1]),
                d.table[first][1].clamp(bx[1][0], bx[1][1]),
            ],
        };
        for t in d.table.iter_mut() {
            *t = pos;
        }
    }
    Some(())
}

/// Nearest-neighbour tour over board points, then 2-opt (Euclidean, open path).
fn board_tour(cell: &PcbCell, members: &[usize]) -> Vec<usize> {
    if members.len() < 3 {
        return members.to_vec();
    }
    let p = |c: usize| cell.components[c].position;
    let d = |a: usize, b: usize| crate::sim::dist(p(a), p(b));
    let mut left: Vec<usize> = members.to_vec();
    // Start at the lowest-left point.
    left.sort_by(|&a, &b| {
        (p(a)[0] + p(a)[1])
            .total_cmp(&(p(b)[0] + p(b)[1]))
            .then(a.cmp(&b))
    });
    let mut tour = vec![left.remove(0)];
    while !left.is_empty() {
        let last = *tour.last().unwrap_or(&0);
        let (k, _) = left
            .iter()
            .enumerate()
            .min_by(|x, y| d(last, *x.1).total_cmp(&d(last, *y.1)))
            .unwrap_or((0, &0));
        tour.push(left.remove(k));
    }
    let n = tour.len();
    let mut improved = true;
    let mut rounds = 0;
    while improved && rounds < 50 {
        improved = false;
        rounds += 1;
        for i in 0..n - 2 {
            for j in i + 2..n {
                let a = d(tour[i], tour[i + 1]);
                let b = if j + 1 < n { d(tour[j], tour[j + 1]) } else { 0.0 };
                let a2 = d(tour[i], tour[j]);
                let b2 = if j + 1 < n {
                    d(tour[i + 1], tour[j + 1])
                } else {
                    0.0
                };
                if a2 + b2 < a + b - 1e-12 {
                    tour[i + 1..=j].reverse();
                    improved = true;
                }
            }
        }
    }
    tour
}

/// One robot: the feeder to pick component `c` from — the one holding its type, or of the two
/// that both do, the one whose pick line is nearer to where it can be placed.
pub fn nearer_feeder(cell: &PcbCell, lookup: &[Vec<Option<usize>>; 2], c: usize) -> usize {
    let t = cell.type_of[c];
    match (lookup[0][t].is_some(), lookup[1][t].is_some()) {
        (true, true) => nearer_feeder_of_two(cell, c),
        (false, true) => 1,
        _ => 0,
    }
}

/// The feeder whose pick line is nearer to the middle of where component `c` can be placed.
fn nearer_feeder_of_two(cell: &PcbCell, c: usize) -> usize {
    let b = cell.components[c].position[0];
    let x = 0.5 * (cell.table.x[0] + cell.table.x[1]) + b;
    if (cell.feeders[0].x - x).abs() <= (cell.feeders[1].x - x).abs() {
        0
    } else {
        1
    }
}

/// Our starting decision.
pub fn initial(cell: &PcbCell) -> Decision {
    let n = cell.len();
    let slots = default_slots(cell);
    let mut d = Decision {
        order: Vec::new(),
        robot: vec![0; n],
        feeder: vec![0; n],
        slots,
        carriage: cell_home_carriages(cell),
        table: vec![cell.table.home; n],
    };
    let lookup = slot_lookup(cell, &d);
    if cell.robots.len() == 1 {
        for c in 0..n {
            d.feeder[c] = nearer_feeder(cell, &lookup, c);
        }
        d.order = board_tour(cell, &(0..n).collect::<Vec<_>>());
    } else {
        // Left half of the board to the left robot, where it can.
        let mut by_x: Vec<usize> = (0..n).collect();
        by_x.sort_by(|&a, &b| {
            cell.components[a].position[0]
                .total_cmp(&cell.components[b].position[0])
                .then(a.cmp(&b))
        });
        for (k, &c) in by_x.iter().enumerate() {
            // (One component: the robot whose feeder is nearer.)
            let want = if n == 1 {
                nearer_feeder_of_two(cell, c)
            } else if k < n / 2 {
                0
            } else {
                1
            };
            let r = if robot_can(cell, &lookup, want, c) {
                want
            } else {
                1 - want
            };
            d.robot[c] = r;
            d.feeder[c] = r;
        }
        let tours: Vec<Vec<usize>> = (0..2)
            .map(|r| board_tour(cell, &(0..n).filter(|&c| d.robot[c] == r).collect::<Vec<_>>()))
            .collect();
        let (mut a, mut b) = (tours[0].iter(), tours[1].iter());
        loop {
            match (a.next(), b.next()) {
                (None, None) => break,
                (x, y) => {
                    d.order.extend(x);
                    d.order.extend(y);
                }
            }
        }
    }
    for c in 0..n {
        let slot = lookup[d.feeder[c]][cell.type_of[c]].unwrap_or(0);
        if let Some(r) = cell.pick_range(d.robot[c], d.feeder[c], slot) {
            d.carriage[c] = 0.5 * (r[0] + r[1]);
        }
        if let Some(bx) = cell.place_box(d.robot[c], c) {
            d.table[c] = [0.5 * (bx[0][0] + bx[0][1]), 0.5 * (bx[1][0] + bx[1][1])];
        }
    }
    let _ = fix_devices(cell, &mut d, Some([0.5; 4]));
    record_rendezvous(cell, &mut d);
    d
}

fn cell_home_carriages(cell: &PcbCell) -> Vec<f64> {
    vec![cell.feeders[0].home; cell.len()]
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

/// The decision with the contents of the two feeders exchanged bin for bin (one robot, bins
/// free, equal bin counts, every bin still reachable).
fn mirrored(cell: &PcbCell, d: &Decision) -> Option<Decision> {
    if cell.robots.len() != 1 || !cell.given_bins.is_empty() || cell.feeders[0].bins != cell.feeders[1].bins {
        return None;
    }
    let mut x = d.clone();
    x.slots.swap(0, 1);
    for c in 0..cell.len() {
        x.feeder[c] = 1 - x.feeder[c];
    }
    let lookup = slot_lookup(cell, &x);
    for c in 0..cell.len() {
        let slot = lookup[x.feeder[c]][cell.type_of[c]]?;
        let r = cell.pick_range(0, x.feeder[c], slot)?;
        x.carriage[c] = 0.5 * (r[0] + r[1]);
    }
    fix_devices(cell, &mut x, Some([0.5; 4]))?;
    Some(x)
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

/// Golden-section line searches on each coordinate of the fixed devices' positions (feeder
/// carriages, table x and y) over the range that serves all their meetings; returns the
/// decision, its time and the simulations spent.
fn tune_fixed(cell: &PcbCell, mut d: Decision, rounds: usize) -> (Decision, f64, usize) {
    let mut spent = 0;
    let mut best = evaluate(cell, &d);
    spent += 1;
    if cell.configuration.feeders_move() && cell.configuration.table_moves() {
        return (d, best, spent);
    }
    let lookup = slot_lookup(cell, &d);
    for _ in 0..rounds {
        for axis in 0..4 {
            let range = if axis < 2 {
                if cell.configuration.feeders_move() {
                    continue;
                }
                let f = axis;
                let mut r = cell.feeders[f].travel;
                let mut any = false;
                for c in 0..d.order.len() {
                    if d.feeder[c] != f {
                        continue;
                    }
                    any = true;
                    let Some(slot) = lookup[f][cell.type_of[c]] else {
                        continue;
                    };
                    let Some(pr) = cell.pick_range(d.robot[c], f, slot) else {
                        continue;
                    };
                    r = [r[0].max(pr[0]), r[1].min(pr[1])];
                }
                if !any || r[0] > r[1] {
                    continue;
                }
                r
            } else {
                if cell.configuration.table_moves() {
                    continue;
                }
                let a = axis - 2;
                let mut r = if a == 0 { cell.table.x } else { cell.table.y };
                for c in 0..d.order.len() {
                    let Some(bx) = cell.place_box(d.robot[c], c) else {
                        continue;
                    };
                    r = [r[0].max(bx[a][0]), r[1].min(bx[a][1])];
                }
                if r[0] > r[1] {
                    continue;
                }
                r
            };
            let set = |d: &mut Decision, v: f64| {
                if axis < 2 {
                    for c in 0..d.order.len() {
                        if d.feeder[c] == axis {
                            d.carriage[c] = v;
                        }
                    }
                } else {
                    for t in d.table.iter_mut() {
                        t[axis - 2] = v;
                    }
                }
            };
            let mut trial = d.clone();
            // A coarse scan first (the time is not unimodal in a fixed position once bins and
            // order are fixed), then golden-section search around the best point of the scan.
            let steps = 16;
            let at = |k: usize| range[0] + (range[1] - range[0]) * k as f64 / steps as f64;
            let mut scan_best = (f64::INFINITY, 0);
            for k in 0..=steps {
                set(&mut trial, at(k));
                spent += 1;
                let v = evaluate(cell, &trial);
                if v < scan_best.0 {
                    scan_best = (v, k);
                }
            }
            let k = scan_best.1;
            let (lo, hi) = (at(k.saturating_sub(1)), at((k + 1).min(steps)));
            let x = crate::rendezvous::golden(lo, hi, 20, |v| {
                set(&mut trial, v);
                spent += 1;
                evaluate(cell, &trial)
            });
            set(&mut trial, x);
            let v = evaluate(cell, &trial);
            spent += 1;
            if v < best - 1e-12 {
                best = v;
                d = trial;
            }
        }
    }
    (d, best, spent)
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

/// Coordinate descent on the recorded rendezvous of moving devices, on the whole schedule
/// (which sees what the greedy rule cannot: a meeting placed for the next cycles' sake). Under
/// the constant-speed model without safety delays the assembly time is a convex function of
/// all meeting positions (sums and maxima of distances), so each coordinate's golden-section
/// search is exact along that coordinate.
pub fn polish(cell: &PcbCell, mut d: Decision, budget: usize) -> (Decision, f64, usize) {
    let eval = |d: &Decision| simulate(cell, d, &mut Given(d), rule(cell)).makespan;
    let mut best = eval(&d);
    let mut spent = 1;
    let lookup = slot_lookup(cell, &d);
    let moving_feeders = cell.configuration.feeders_move();
    let moving_table = cell.configuration.table_moves();
    let mut round_gain = f64::INFINITY;
    while spent < budget && round_gain > 1e-9 {
        let before = best;
        for k in 0..d.order.len() {
            let c = d.order[k];
            let (r, f) = (d.robot[c], d.feeder[c]);
            for axis in 0..3 {
                if spent >= budget {
                    break;
                }
                let range = match axis {
                    0 if moving_feeders => {
                        let Some(slot) = lookup[f][cell.type_of[c]] else {
                            continue;
                        };
                        let Some(rg) = cell.pick_range(r, f, slot) else {
                            continue;
                        };
                        rg
                    }
                    1 | 2 if moving_table => {
                        let Some(bx) = cell.place_box(r, c) else { continue };
                        bx[axis - 1]
                    }
                    _ => continue,
                };
                let mut x = d.clone();
                let set = |x: &mut Decision, v: f64| {
                    if axis == 0 {
                        x.carriage[c] = v;
                    } else {
                        x.table[c][axis - 1] = v;
                    }
                };
                let v = crate::rendezvous::golden(range[0], range[1], 25, |v| {
                    set(&mut x, v);
                    spent += 1;
                    eval(&x)
                });
                set(&mut x, v);
                let value = eval(&x);
                spent += 1;
                if value < best - 1e-12 {
                    best = value;
                    d = x;
                }
            }
        }
        round_gain = before - best;
    }
    (d, best, spent)
}

/// A decision with the order given and everything else ours (bins, robots by board side, fixed
/// positions tuned, meetings by our rule then polished within `budget` simulations): what
/// `cellplan plan --order` evaluates, e.g. a placement order from another tool.
pub fn settle_order(cell: &PcbCell, order: &[usize], budget: usize) -> (Decision, f64) {
    let mut d = initial(cell);
    d.order = order.to_vec();
    let _ = fix_devices(cell, &mut d, None);
    let (mut d, _, spent) = tune_fixed(cell, d, 2);
    record_rendezvous(cell, &mut d);
    let (d, v, _) = polish(cell, d, budget.saturating_sub(spent));
    (d, v)
}

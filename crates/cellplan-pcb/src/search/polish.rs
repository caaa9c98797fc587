//! The continuous part of our search: line searches of the fixed devices' positions, the
//! coordinate-wise polish of every meeting, and a given order settled with both.
use super::{evaluate, fix_devices, initial, record_rendezvous, rule};
use crate::cell::PcbCell;
use crate::sim::{Decision, Given, simulate, slot_lookup};

/// Golden-section line searches on each coordinate of the fixed devices' positions (feeder
/// carriages, table x and y) over the range that serves all their meetings; returns the
/// decision, its time and the simulations spent.
pub(super) fn tune_fixed(cell: &PcbCell, mut d: Decision, rounds: usize) -> (Decision, f64, usize) {
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

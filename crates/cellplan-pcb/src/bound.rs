//! A lower bound on the assembly time, valid for every order, bin assignment, robot assignment
//! and rendezvous of the cell in its configuration (so the gap of a plan to it is a true gap).
//!
//! Each cycle costs at least the pick and the place, and a robot's loop from its last place
//! point through a pick point to the next place point is at least the X distance from each place
//! point to the nearest pick line it can use (`m` of a component: over the table positions and
//! robots that can place it). For one robot (moving at most `v`) this gives
//! `N·(pick + place) + (h + 2·Σm − max m)/v` with `h` the distance from home to a pick line.
//! With one robot, a second bound couples robot and table: between two placements the table
//! moves at least `|Δb| − ℓ` (board points `b`, robot loop `ℓ`), so a cycle lasts at least
//! `min over ℓ ≥ m_j + m_k of max(pick + ℓ/v, (|Δb| − ℓ)/v_table)` plus the place; summed over
//! each component's cheapest predecessor. With two robots, the robots' busy times share the
//! work: the bound is half the sum of both, or the serial placements on the one table, whichever
//! is larger.
use crate::cell::PcbCell;

/// The robot's travel with the types in the feeders: the leg from a pick to its placement is at
/// least the X distance from the feeder line it picks at to the place point (`a`), the leg from a
/// placement to the next pick at least the distance to the nearer line (`m`). With the bins the
/// cell gives, each type's feeders are known; otherwise the types go to the feeders by the
/// cheapest assignment the bin counts allow (exact for two feeders: the types that gain most
/// from feeder 2 go there), less what spare bins could save by holding a type in both feeders. With a fixed table, the table position is one
/// for all placements: the bound is the least over its X (scanned at 0.1 mm, less the most the
/// travel can fall between two scanned points).
fn assigned_travel(cell: &PcbCell, h: f64) -> f64 {
    let n = cell.len();
    let nt = cell.types.len();
    let xf = [cell.feeders[0].x, cell.feeders[1].x];
    let dist_to = |lo: f64, hi: f64, x: f64| {
        if x < lo {
            lo - x
        } else if x > hi {
            x - hi
        } else {
            0.0
        }
    };
    // For table X positions within [lo, hi] (per component), the travel bound.
    let travel = |ranges: &dyn Fn(usize) -> Option<[f64; 2]>| -> Option<f64> {
        let mut m_sum = 0.0;
        let mut m_max = 0.0f64;
        let mut cost = vec![[0.0f64; 2]; nt];
        // A type in both feeders lets each of its components use the nearer one.
        let mut both = vec![0.0f64; nt];
        for c in 0..n {
            let r = ranges(c)?;
            let a = [dist_to(r[0], r[1], xf[0]), dist_to(r[0], r[1], xf[1])];
            let m = a[0].min(a[1]);
            m_sum += m;
            m_max = m_max.max(m);
            let t = cell.type_of[c];
            cost[t][0] += a[0];
            cost[t][1] += a[1];
            both[t] += m;
        }
        let best = if !cell.given_bins.is_empty() {
            // The cell fixes the bins: each type's feeders are known.
            let mut in_feeder = vec![[false; 2]; nt];
            for b in &cell.given_bins {
                in_feeder[b.kind][b.feeder] = true;
            }
            (0..nt)
                .map(|t| match in_feeder[t] {
                    [true, true] => both[t],
                    [true, false] => cost[t][0],
                    [false, true] => cost[t][1],
                    [false, false] => 0.0,
                })
                .sum()
        } else {
            // Capacitated assignment of the types to the two feeders, one bin each.
            let (cap0, cap1) = (cell.feeders[0].bins, cell.feeders[1].bins);
            let mut gain: Vec<f64> = cost.iter().map(|c| c[1] - c[0]).collect();
            gain.sort_by(f64::total_cmp);
            let base: f64 = cost.iter().map(|c| c[0]).sum();
            let least_in_1 = nt.saturating_sub(cap0);
            let most_in_1 = cap1.min(nt);
            let mut single = f64::INFINITY;
            let mut acc = 0.0;
            for k in 0..=most_in_1 {
                if k > 0 {
                    acc += gain[k - 1];
                }
                if k >= least_in_1 {
                    single = single.min(base + acc);
                }
            }
            // Spare bins may hold a type twice, once in each feeder: a plan with doubled types
            // D becomes one with single types by keeping each doubled type in its cheaper feeder
            // (no feeder gets fuller), at an extra cost of that type's gain from doubling. So
            // no plan beats the single assignment by more than the `spare` largest gains.
            let spare = (cap0 + cap1).saturating_sub(nt);
            let mut gains: Vec<f64> = (0..nt)
                .map(|t| (cost[t][0].min(cost[t][1]) - both[t]).max(0.0))
                .collect();
            gains.sort_by(|a, b| b.total_cmp(a));
            let saved: f64 = gains.iter().take(spare).sum();
            (single - saved).max(0.0)
        };
        Some(h + m_sum - m_max + best)
    };
    let robot = &cell.robots[0];
    if cell.configuration.table_moves() {
        travel(&|c| {
            let bx = cell.place_box(0, c)?;
            let b = cell.components[c].position[0];
            Some([bx[0][0] + b, bx[0][1] + b])
        })
        .unwrap_or(0.0)
    } else {
        // One table X for all: scan it.
        let mut lo = cell.table.x[0];
        let mut hi = cell.table.x[1];
        for c in 0..n {
            let b = cell.components[c].position[0];
            lo = lo.max(robot.x[0] - b);
            hi = hi.min(robot.x[1] - b);
        }
        if lo > hi {
            return 0.0;
        }
        // 0.1 mm steps, but no more than about 2·10⁷ component visits in all.
        let step = 1e-4;
        let k = ((hi - lo) / step).ceil().max(1.0) as usize;
        let k = k.min(20_000_000 / n.max(1)).clamp(1, 200_000);
        let step = (hi - lo) / k as f64;
        let mut best = f64::INFINITY;
        for i in 0..=k {
            let tx = lo + step * i as f64;
            if let Some(t) = travel(&|c| {
                let x = tx + cell.components[c].position[0];
                Some([x, x])
            }) {
                best = best.min(t);
            }
        }
        // Each component's two legs change by at most the table's shift: 2·n·step/2.
        (best - n as f64 * step).max(0.0)
    }
}

/// Components above which the quadratic coupling bound is skipped.
const COUPLING_LIMIT: usize = 3000;

/// The bound (s).
pub fn lower_bound(cell: &PcbCell) -> f64 {
    let n = cell.len();
    if n == 0 {
        return 0.0;
    }
    let robots = cell.robots.len();
    let v = cell.robots.iter().map(|r| r.drive.speed).fold(0.0, f64::max);
    let (pk, pl) = (cell.pick_time, cell.place_time);
    let fixed_table = !cell.configuration.table_moves();
    // m: per component, the least X distance from a reachable place point to a usable pick line.
    let m: Vec<f64> = (0..n)
        .map(|c| {
            let b = cell.components[c].position;
            (0..robots)
                .filter_map(|r| cell.place_box(r, c).map(|bx| (r, bx)))
                .flat_map(|(r, bx)| {
                    let lo = bx[0][0] + b[0];
                    let hi = bx[0][1] + b[0];
                    cell.feeders_of(r).map(move |f| (lo, hi, f))
                })
                .map(|(lo, hi, f)| {
                    let x = cell.feeders[f].x;
                    if x < lo {
                        lo - x
                    } else if x > hi {
                        x - hi
                    } else {
                        0.0
                    }
                })
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    let h: f64 = (0..robots)
        .map(|r| {
            cell.feeders_of(r)
                .map(|f| (cell.robots[r].home[0] - cell.feeders[f].x).abs())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(f64::INFINITY, f64::min);
    let sum_m: f64 = m.iter().sum();
    let max_m = m.iter().copied().fold(0.0, f64::max);
    let work = n as f64 * (pk + pl);
    if robots == 1 {
        let travel = h + 2.0 * sum_m - max_m;
        let lb1 = work + travel / v;
        let lb1 = lb1.max(work + assigned_travel(cell, h) / v);
        if !(2..=COUPLING_LIMIT).contains(&n) {
            return lb1;
        }
        let vt = cell.table.drive.speed;
        let cost = |j: usize, k: usize| -> f64 {
            let bj = cell.components[j].position;
            let bk = cell.components[k].position;
            let db = ((bj[0] - bk[0]).powi(2) + (bj[1] - bk[1]).powi(2)).sqrt();
            let lmin = m[j] + m[k];
            let loop_len = if fixed_table {
                lmin.max(db)
            } else {
                // max(pk + ℓ/v, (db − ℓ)/vt) is least where the two meet, if that ℓ ≥ lmin.
                let meet = (db / vt - pk) / (1.0 / v + 1.0 / vt);
                lmin.max(meet)
            };
            let robot = pk + loop_len / v;
            let table = if fixed_table {
                0.0
            } else {
                (db - loop_len).max(0.0) / vt
            };
            pl + robot.max(table)
        };
        let cheapest: Vec<f64> = (0..n)
            .map(|k| {
                (0..n)
                    .filter(|&j| j != k)
                    .map(|j| cost(j, k))
                    .fold(f64::INFINITY, f64::min)
            })
            .collect();
        let first = pk + pl + (h + m.iter().copied().fold(f64::INFINITY, f64::min)) / v;
        let lb2 = first + cheapest.iter().sum::<f64>() - cheapest.iter().copied().fold(0.0, f64::max);
        lb1.max(lb2)
    } else {
        let busy = (work + (2.0 * sum_m - 2.0 * max_m + h).max(0.0) / v) / 2.0;
        let first = pk + pl + (h + m.iter().copied().fold(f64::INFINITY, f64::min)) / v;
        let serial = first + (n as f64 - 1.0) * pl;
        busy.max(serial).max(two_robot_split(cell))
    }
}

/// Two robots: the longer robot's busy time under the best fractional split of the components.
/// Robot `r` spends at least `pick + place + 2·a_jr/v_r` on component `j` (both its legs run
/// between its own feeder's line and the place point, at least `a_jr` apart in X), less its
/// longest such leg once (its last placement needs no return); the LP relaxation of "assign
/// each component to one robot, minimise the larger busy time" is a fractional knapsack,
/// solved exactly by taking components in order of `c_j0 / c_j1`.
fn two_robot_split(cell: &PcbCell) -> f64 {
    let n = cell.len();
    let (pk, pl) = (cell.pick_time, cell.place_time);
    let cost = |r: usize, c: usize| -> Option<(f64, f64)> {
        let bx = cell.place_box(r, c)?;
        let b = cell.components[c].position[0];
        let (lo, hi) = (bx[0][0] + b, bx[0][1] + b);
        let x = cell.feeders[r].x;
        let a = if x < lo {
            lo - x
        } else if x > hi {
            x - hi
        } else {
            0.0
        };
        let v = cell.robots[r].drive.speed;
        Some((pk + pl + 2.0 * a / v, a / v))
    };
    let mut items: Vec<(f64, f64)> = Vec::with_capacity(n);
    let (mut fixed0, mut fixed1) = (0.0, 0.0);
    let mut longest = [0.0f64; 2];
    for c in 0..n {
        match (cost(0, c), cost(1, c)) {
            (Some(a), Some(b)) => {
                items.push((a.0, b.0));
                longest[0] = longest[0].max(a.1);
                longest[1] = longest[1].max(b.1);
            }
            (Some(a), None) => {
                fixed0 += a.0;
                longest[0] = longest[0].max(a.1);
            }
            (None, Some(b)) => {
                fixed1 += b.0;
                longest[1] = longest[1].max(b.1);
            }
            (None, None) => {}
        }
    }
    items.sort_by(|x, y| (x.0 / x.1).total_cmp(&(y.0 / y.1)));
    // Robot 0 takes a prefix (the last item in part); find where the two busy times meet.
    let total1: f64 = items.iter().map(|i| i.1).sum();
    let (m0, m1) = (longest[0], longest[1]);
    let mut a = fixed0 - m0;
    let mut b = fixed1 + total1 - m1;
    if a >= b {
        return a.max(0.0);
    }
    for &(c0, c1) in &items {
        if a + c0 >= b - c1 {
            // Split this item: a + f·c0 = b − f·c1.
            let f = (b - a) / (c0 + c1);
            return (a + f * c0).max(0.0);
        }
        a += c0;
        b -= c1;
    }
    a.max(b).max(0.0)
}

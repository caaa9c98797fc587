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
        if n > COUPLING_LIMIT || n < 2 {
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
        busy.max(serial)
    }
}

//! Our starting decision: bins by use and side, robots by board half, orders as tours over the
//! board, fixed devices in the middle of their common range; and the mirrored start.
use super::record_rendezvous;
use crate::cell::PcbCell;
use crate::sim::{Decision, slot_lookup};

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
        carriage: vec![cell.feeders[0].home; n],
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

/// The decision with the contents of the two feeders exchanged bin for bin (one robot, bins
/// free, equal bin counts, every bin still reachable).
pub(super) fn mirrored(cell: &PcbCell, d: &Decision) -> Option<Decision> {
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

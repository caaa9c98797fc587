//! Item distances (the cheapest arc either way between two clusters), neighbour lists and the
//! nearest-neighbour cluster order.
use super::Inst;

/// For item `x`, the distance to every item: the cheapest arc between a node of `x` and a node
/// of the other, in either direction (`INFINITY` to itself).
fn row(inst: &Inst, x: usize, out: &mut Vec<f64>) {
    out.clear();
    out.resize(inst.items(), f64::INFINITY);
    for (y, cy) in inst.clusters.iter().enumerate() {
        if y == x {
            continue;
        }
        let mut best = f64::INFINITY;
        for &a in &inst.clusters[x] {
            for &b in cy {
                best = best.min(inst.w(a, b)).min(inst.w(b, a));
            }
        }
        out[y] = best;
    }
}

/// The `k` nearest items of every item, nearest first (ties by index).
pub(super) fn neighbours(inst: &Inst, k: usize) -> Vec<Vec<usize>> {
    let items = inst.items();
    let k = k.min(items.saturating_sub(1));
    let mut d = Vec::new();
    (0..items)
        .map(|x| {
            row(inst, x, &mut d);
            let mut ids: Vec<usize> = (0..items).filter(|&y| y != x).collect();
            let key = |&a: &usize, &b: &usize| d[a].total_cmp(&d[b]).then(a.cmp(&b));
            if k < ids.len() {
                ids.select_nth_unstable_by(k, key);
                ids.truncate(k);
            }
            ids.sort_by(key);
            ids
        })
        .collect()
}

/// Nearest-neighbour order of the items, from the depot item (position 0) or from cluster 0.
pub(super) fn nearest_neighbour(inst: &Inst) -> Vec<usize> {
    let items = inst.items();
    if items == 0 {
        return Vec::new();
    }
    let first = if inst.depot { inst.k } else { 0 };
    let mut used = vec![false; items];
    let mut order = Vec::with_capacity(items);
    let mut d = Vec::new();
    let mut x = first;
    loop {
        used[x] = true;
        order.push(x);
        if order.len() == items {
            break;
        }
        row(inst, x, &mut d);
        let mut best = (f64::INFINITY, usize::MAX);
        for (y, &dy) in d.iter().enumerate() {
            if !used[y] && (dy < best.0 || best.1 == usize::MAX) {
                best = (dy, y);
            }
        }
        x = best.1;
    }
    order
}

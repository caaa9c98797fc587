//! Item distances (the cheapest arc either way between two clusters), neighbour lists and the
//! nearest-neighbour cluster order.
use super::Inst;

/// Item distances for instances of at most this many items are computed once, as a table
/// (8 MB at most); larger instances compute each item's row when they need it.
const TABLE_MAX_ITEMS: usize = 1024;

/// The distance between two items: the cheapest arc between a node of one and a node of the
/// other, in either direction.
fn item_distance(inst: &Inst, x: usize, y: usize) -> f64 {
    let mut best = f64::INFINITY;
    for &a in &inst.clusters[x] {
        for &b in &inst.clusters[y] {
            best = best.min(inst.w(a, b)).min(inst.w(b, a));
        }
    }
    best
}

/// Every item's distance to every item ([`item_distance`], `INFINITY` to itself), row-major;
/// `None` for instances of more than [`TABLE_MAX_ITEMS`] items. Each pair is computed once:
/// the distance is symmetric, and a minimum does not depend on the order it is taken in, so
/// the table holds exactly what [`row`] computes.
fn item_table(inst: &Inst) -> Option<Vec<f64>> {
    let items = inst.items();
    if items > TABLE_MAX_ITEMS {
        return None;
    }
    let mut d = vec![f64::INFINITY; items * items];
    for x in 0..items {
        for y in x + 1..items {
            let v = item_distance(inst, x, y);
            d[x * items + y] = v;
            d[y * items + x] = v;
        }
    }
    Some(d)
}

/// For item `x`, the distance to every item (`INFINITY` to itself): from `table` when there
/// is one.
fn row(inst: &Inst, table: Option<&[f64]>, x: usize, out: &mut Vec<f64>) {
    let items = inst.items();
    out.clear();
    if let Some(t) = table {
        out.extend_from_slice(&t[x * items..(x + 1) * items]);
        return;
    }
    out.resize(items, f64::INFINITY);
    for (y, o) in out.iter_mut().enumerate() {
        if y != x {
            *o = item_distance(inst, x, y);
        }
    }
}

/// The `k` nearest items of every item, nearest first (ties by index), and the nearest-
/// neighbour order of the items, from the depot item (position 0) or from cluster 0.
pub(super) fn neighbours_and_order(inst: &Inst, k: usize) -> (Vec<Vec<usize>>, Vec<usize>) {
    let table = item_table(inst);
    let table = table.as_deref();
    (neighbours(inst, table, k), nearest_neighbour(inst, table))
}

/// The `k` nearest items of every item, nearest first (ties by index).
fn neighbours(inst: &Inst, table: Option<&[f64]>, k: usize) -> Vec<Vec<usize>> {
    let items = inst.items();
    let k = k.min(items.saturating_sub(1));
    let mut d = Vec::new();
    (0..items)
        .map(|x| {
            row(inst, table, x, &mut d);
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
fn nearest_neighbour(inst: &Inst, table: Option<&[f64]>) -> Vec<usize> {
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
        row(inst, table, x, &mut d);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CostMatrix;
    use crate::problem::Gtsp;

    /// The table holds, bit for bit, what each item's row computes without it.
    #[test]
    fn the_item_table_is_the_rows() {
        let n = 23;
        let data: Vec<f64> = (0..n * n)
            .map(|k| {
                if k / n == k % n {
                    0.0
                } else {
                    ((k * 7919) % 1013) as f64 / 7.0
                }
            })
            .collect();
        let clusters: Vec<Vec<usize>> = (0..n - 1)
            .collect::<Vec<_>>()
            .chunks(3)
            .map(<[usize]>::to_vec)
            .collect();
        let g = Gtsp::new(CostMatrix::new(n, data).unwrap(), clusters)
            .unwrap()
            .with_depots(Some(n - 1), None)
            .unwrap();
        let inst = Inst::new(&g);
        let table = item_table(&inst).expect("a small instance");
        let (mut with, mut without) = (Vec::new(), Vec::new());
        for x in 0..inst.items() {
            row(&inst, Some(&table), x, &mut with);
            row(&inst, None, x, &mut without);
            let bits = |v: &[f64]| v.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&with), bits(&without));
            assert!(
                with[x].is_infinite() && with.iter().filter(|d| d.is_finite()).count() == inst.items() - 1
            );
        }
        assert_eq!(neighbours(&inst, Some(&table), 4), neighbours(&inst, None, 4));
        assert_eq!(
            nearest_neighbour(&inst, Some(&table)),
            nearest_neighbour(&inst, None)
        );
    }
}

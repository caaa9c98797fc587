//! The layer pass: for the current cluster order, the best node of every cluster, by a
//! shortest path through the layers (one per cluster). On a cycle the layer of the smallest
//! cluster is fixed first and each of its nodes tried; with depots the depot item is that layer.
use super::{EPS, Inst, State};

/// The position of the first layer (the depot item, or the smallest cluster) and the clusters
/// in tour order from it.
pub(super) fn layers<'a>(inst: &'a Inst, st: &State) -> (usize, Vec<&'a [usize]>) {
    let m = st.t.len();
    let first = (0..m)
        .min_by_key(|&i| (inst.clusters[st.t[i]].len(), i))
        .unwrap_or(0);
    let first = if inst.depot { st.pos[inst.k] } else { first };
    let layers = (0..m)
        .map(|i| inst.clusters[st.t[(first + i) % m]].as_slice())
        .collect();
    (first, layers)
}

/// What the last layer pass of a search with depots computed: its layers' items in order and
/// their shortest-path table. A layer's values depend only on the layers before it, so the
/// next pass recomputes only from the first layer whose item differs (a kick or a local move
/// changes part of the order): the same arithmetic on the same numbers, the same choice.
#[derive(Clone, Debug, Default)]
pub(super) struct LayerMemo {
    items: Vec<usize>,
    value: Vec<f64>,
    parent: Vec<usize>,
    /// Layers taken from the last pass, over every pass (for the tests).
    #[cfg(test)]
    pub(super) reused: usize,
}

/// Re-choose every cluster's node optimally for the current order. Returns the items whose node
/// changed (empty when the tour did not improve). `memo` carries the table from one pass to the
/// next on instances with depots (a cycle's first layer is the smallest cluster, each of whose
/// nodes starts a pass of its own: nothing is kept there).
pub(super) fn layer_pass(inst: &Inst, st: &mut State, memo: &mut LayerMemo) -> Vec<usize> {
    let m = st.t.len();
    if m == 0 || inst.clusters.iter().all(|c| c.len() == 1) {
        return Vec::new();
    }
    let (first, layers) = layers(inst, st);
    let mut offset = Vec::with_capacity(m + 1);
    offset.push(0);
    for l in &layers {
        offset.push(offset.last().copied().unwrap_or(0) + l.len());
    }
    let total = offset[m];
    // Layers `..keep` are those of the last pass (with depots only).
    let keep = if inst.depot && memo.items.len() == m {
        (0..m)
            .take_while(|&i| memo.items[i] == st.t[(first + i) % m])
            .count()
    } else {
        0
    };
    #[cfg(test)]
    {
        memo.reused += keep;
    }
    memo.items.clear();
    if inst.depot {
        memo.items.extend((0..m).map(|i| st.t[(first + i) % m]));
    }
    let LayerMemo { value, parent, .. } = memo;
    value.resize(total, 0.0);
    parent.resize(total, 0);
    let mut best = (f64::INFINITY, 0usize, 0usize); // (cost, start index, last index)
    // With one start (the depot item), the table's parents at the end are the best start's;
    // with several, each start's are kept when it leads.
    let single = layers[0].len() == 1;
    let mut best_parent = Vec::new();
    let mut columns = Vec::new();
    for (si, &s) in layers[0].iter().enumerate() {
        if keep == 0 {
            value[..layers[0].len()].fill(f64::INFINITY);
            value[si] = inst.s(s);
        }
        for l in keep.max(1)..m {
            let (prev, cur) = (layers[l - 1], layers[l]);
            // Row by row of the cost table (each `u` of the layer before, in order, so every
            // `v` keeps the first cheapest `u` as before).
            let (before, here) = value.split_at_mut(offset[l]);
            let (before, here) = (&before[offset[l - 1]..], &mut here[..cur.len()]);
            let parents = &mut parent[offset[l]..offset[l] + cur.len()];
            here.fill(f64::INFINITY);
            columns.clear();
            columns.extend(cur.iter().map(|&v| inst.column(v)));
            // A cluster whose nodes are numbered one after the other (as the planner's
            // instances number them) reads each row as one slice: the same values in the same
            // order, without a lookup per node.
            let first = columns.first().copied().unwrap_or(0);
            let run = columns.iter().enumerate().all(|(j, &c)| c == first + j);
            for (i, (&u, &vu)) in prev.iter().zip(before.iter()).enumerate() {
                let row = inst.row(u);
                if run {
                    relax(
                        here,
                        parents,
                        row[first..first + columns.len()].iter().copied(),
                        vu,
                        i,
                    );
                } else {
                    relax(here, parents, columns.iter().map(|&c| row[c]), vu, i);
                }
            }
            // (Costs are finite: every node of `cur` got a parent from `prev`.)
            for (h, &v) in here.iter_mut().zip(cur.iter()) {
                *h += inst.s(v);
            }
        }
        let last = layers[m - 1];
        for (j, &v) in last.iter().enumerate() {
            let x = value[offset[m - 1] + j] + inst.w(v, s);
            if x < best.0 {
                best = (x, si, j);
                if !single {
                    best_parent.clone_from(parent);
                }
            }
        }
    }
    let now = inst.cost(st) - inst.fixed;
    if best.0 >= now - EPS {
        return Vec::new();
    }
    let parents: &[usize] = if single { parent } else { &best_parent };
    let mut changed = Vec::new();
    let mut j = best.2;
    for l in (0..m).rev() {
        let node = if l == 0 { layers[0][best.1] } else { layers[l][j] };
        let item = st.t[(first + l) % m];
        if st.choice[item] != node {
            st.choice[item] = node;
            changed.push(item);
        }
        if l > 0 {
            j = parents[offset[l] + j];
        }
    }
    st.refresh(inst);
    changed
}

/// One row of a layer's table: every node `v` of the layer takes `vu + cost(u, v)` and `u`'s
/// index `i` as its parent where that is strictly cheaper (so each keeps the first cheapest
/// `u`), `costs` giving `cost(u, v)` in the layer's order.
#[inline]
fn relax(here: &mut [f64], parents: &mut [usize], costs: impl Iterator<Item = f64>, vu: f64, i: usize) {
    for ((h, p), c) in here.iter_mut().zip(parents.iter_mut()).zip(costs) {
        let x = vu + c;
        if x < *h {
            *h = x;
            *p = i;
        }
    }
}

//! Exact Held–Karp dynamic programming over clusters (paper 002 §2.1): the optimal GTSP tour for
//! small instances. State: (set of clusters visited, last node); each set's values are stored
//! only for the nodes of its clusters, so memory is 2^(K−1)·N values for K clusters and N nodes
//! (12 clusters × 20 nodes: 49 k values; 20 clusters, 301 nodes: 158 M values, 1.3 GB).
use crate::problem::{Gtsp, Tour};
use rayon::prelude::*;

/// Why the exact solver declined.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HeldKarpError {
    /// The state table would exceed the memory limit.
    #[error("exact DP needs {entries} states ({} MB), more than the limit of {limit} states; use the heuristic solver", entries * 8 / 1_000_000)]
    TooLarge {
        /// States the instance needs.
        entries: u128,
        /// The limit.
        limit: u128,
    },
    /// No clusters to visit.
    #[error("the instance has no clusters")]
    Empty,
}

/// Limits of the exact solver.
#[derive(Clone, Copy, Debug)]
pub struct HeldKarpLimits {
    /// Most DP states (8 bytes each) allowed.
    pub max_states: u128,
}

impl Default for HeldKarpLimits {
    fn default() -> Self {
        // 2^(20-1) * 301 states (paper 002's instance) fit; about 3.2 GB at most.
        HeldKarpLimits {
            max_states: 400_000_000,
        }
    }
}

/// An optimal tour and its cost (as [`Gtsp::tour_cost`] counts it).
#[derive(Clone, Debug, PartialEq)]
pub struct Exact {
    /// The tour.
    pub tour: Tour,
    /// Its cost.
    pub cost: f64,
}

/// The number of DP states `solve` needs for `p` (for deciding between exact and heuristic).
pub fn states_needed(p: &Gtsp) -> u128 {
    let (clusters, nodes) = dp_shape(p);
    if clusters == 0 {
        return 0;
    }
    (1u128 << (clusters - 1)) * nodes as u128
}

/// Clusters and nodes in the DP: in cycle mode the smallest cluster is the fixed start.
fn dp_shape(p: &Gtsp) -> (usize, usize) {
    let total: usize = p.clusters.iter().map(Vec::len).sum();
    if p.start.is_some() || p.clusters.is_empty() {
        (p.clusters.len(), total)
    } else {
        let smallest = p.clusters.iter().map(Vec::len).min().unwrap_or(0);
        (p.clusters.len() - 1, total - smallest)
    }
}

/// The optimal tour of `p`: with depots, from `start` through one node of every cluster to
/// `end` (or back to `start` when `end` is `None`); without, the best closed cycle. Service
/// times count once per visited node.
pub fn solve(p: &Gtsp, limits: HeldKarpLimits) -> Result<Exact, HeldKarpError> {
    if p.clusters.is_empty() {
        return Err(HeldKarpError::Empty);
    }
    let needed = states_needed(p);
    if needed > limits.max_states {
        return Err(HeldKarpError::TooLarge {
            entries: needed,
            limit: limits.max_states,
        });
    }
    solve_bounded(p, upper_bound(p, needed))
}

/// [`solve`] with pruning against `upper`, the cost of some tour (or infinity).
fn solve_bounded(p: &Gtsp, mut upper: f64) -> Result<Exact, HeldKarpError> {
    let c = |u: usize, v: usize| p.costs.get(u, v) + p.service[v];
    match p.start {
        Some(s) => {
            let end = p.end.unwrap_or(s);
            let extra = p.service[s] + if end != s { p.service[end] } else { 0.0 };
            let found = run(
                &p.clusters,
                &c,
                &|v| c(s, v),
                &|v| p.costs.get(v, end),
                upper - extra,
            );
            // The bound is a tour's cost, so some path meets it; without one, search unbounded.
            let (cost, path) = found
                .or_else(|| {
                    run(
                        &p.clusters,
                        &c,
                        &|v| c(s, v),
                        &|v| p.costs.get(v, end),
                        f64::INFINITY,
                    )
                })
                .ok_or(HeldKarpError::Empty)?;
            Ok(Exact {
                tour: Tour { nodes: path },
                cost: cost + extra,
            })
        }
        None => {
            // Fix the smallest cluster as the start and try each of its nodes.
            let first = (0..p.clusters.len())
                .min_by_key(|&k| (p.clusters[k].len(), k))
                .unwrap_or(0);
            let rest: Vec<Vec<usize>> = p
                .clusters
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != first)
                .map(|(_, v)| v.clone())
                .collect();
            let mut best: Option<Exact> = None;
            for &s in &p.clusters[first] {
                let found = if rest.is_empty() {
                    Some((p.costs.get(s, s), Vec::new()))
                } else {
                    run(
                        &rest,
                        &c,
                        &|v| c(s, v),
                        &|v| p.costs.get(v, s),
                        upper - p.service[s],
                    )
                };
                let Some((cost, path)) = found else { continue };
                let cost = cost + p.service[s];
                if best.as_ref().is_none_or(|b| cost < b.cost) {
                    let mut nodes = vec![s];
                    nodes.extend(path);
                    upper = upper.min(cost);
                    best = Some(Exact {
                        tour: Tour { nodes },
                        cost,
                    });
                }
            }
            match best {
                Some(b) => Ok(b),
                // Only when the bound was wrong (it never is: it is a tour's cost); stay exact.
                None if upper.is_finite() => solve_bounded(p, f64::INFINITY),
                None => Err(HeldKarpError::Empty),
            }
        }
    }
}

/// The cost of a good tour, to prune with: the heuristic's for large instances (a few hundred
/// kicks; any tour's cost is a valid bound), none for small ones.
fn upper_bound(p: &Gtsp, states: u128) -> f64 {
    if states < 2_000_000 {
        return f64::INFINITY;
    }
    let params = crate::gtsp::GtspParams {
        time_limit: std::time::Duration::from_secs(2),
        seed: 0,
        max_iterations: Some(500),
        ..Default::default()
    };
    crate::gtsp::solve(p, &params).cost
}

/// The DP over `clusters`: cheapest path entering with `from(v)`, visiting one node per
/// cluster, leaving with `to(v)`. Returns the cost and the node path, or `None` when no path
/// costs at most `upper_bound` (states whose value plus a lower bound of the rest exceeds it are
/// pruned; states on an optimal path never are, so the result does not depend on the bound).
///
/// Subsets are processed by size, each size in parallel (a subset only reads smaller ones), and
/// the values of a subset are contiguous, cluster after cluster, so the inner minimum runs over
/// two contiguous slices (values of the predecessor cluster, and the transposed cost column).
fn run(
    clusters: &[Vec<usize>],
    c: &dyn Fn(usize, usize) -> f64,
    from: &dyn Fn(usize) -> f64,
    to: &dyn Fn(usize) -> f64,
    upper_bound: f64,
) -> Option<(f64, Vec<usize>)> {
    let k = clusters.len();
    let full = (1usize << k) - 1;
    // Local node numbering, cluster after cluster.
    let nodes: Vec<usize> = clusters.iter().flatten().copied().collect();
    let n = nodes.len();
    let mut first = vec![0usize; k + 1];
    for (q, cl) in clusters.iter().enumerate() {
        first[q + 1] = first[q] + cl.len();
    }
    // Transposed costs: `w[v * n + u]` is the cost of u → v (with v's service).
    let mut w = vec![0.0; n * n];
    for v in 0..n {
        for u in 0..n {
            w[v * n + u] = c(nodes[u], nodes[v]);
        }
    }
    let enter: Vec<f64> = nodes.iter().map(|&v| from(v)).collect();
    let leave: Vec<f64> = nodes.iter().map(|&v| to(v)).collect();
    // Lower bound of what is left after a subset: every unvisited cluster is entered once (by
    // its cheapest arc from outside it, or from the start), then the path leaves.
    let in_min: Vec<f64> = (0..k)
        .map(|q| {
            let mut m = f64::INFINITY;
            for v in first[q]..first[q + 1] {
                m = m.min(enter[v]);
                for u in (0..first[q]).chain(first[q + 1]..n) {
                    m = m.min(w[v * n + u]);
                }
            }
            m
        })
        .collect();
    let leave_min = leave.iter().copied().fold(f64::INFINITY, f64::min);
    let bound = upper_bound * (1.0 + 1e-12) + 1e-9;

    // Nodes in each subset; subsets ordered by size, each subset's values contiguous.
    let mut count = vec![0usize; full + 1];
    for s in 1..=full {
        let low = s.trailing_zeros() as usize;
        count[s] = count[s & (s - 1)] + clusters[low].len();
    }
    let mut order: Vec<usize> = (1..=full).collect();
    order.sort_by_key(|&s| (s.count_ones(), s));
    let mut offset = vec![0usize; full + 1];
    let mut at = 0;
    for &s in &order {
        offset[s] = at;
        at += count[s];
    }
    let mut value = vec![f64::INFINITY; at];
    // Bit r of `alive[s]`: some value of cluster r in subset s is finite.
    let mut alive = vec![0u32; full + 1];
    let rest_bound: Vec<f64> = (0..=full)
        .map(|s| {
            (0..k)
                .filter(|&q| s & (1 << q) == 0)
                .map(|q| in_min[q])
                .sum::<f64>()
                + leave_min
        })
        .collect();
    let pos = |s: usize, q: usize, j: usize| offset[s] + count[s & ((1 << q) - 1)] + j;

    let mut layer_begin = 0;
    while layer_begin < order.len() {
        let size = order[layer_begin].count_ones();
        let layer_end = order[layer_begin..]
            .iter()
            .position(|s| s.count_ones() != size)
            .map_or(order.len(), |i| layer_begin + i);
        let layer = &order[layer_begin..layer_end];
        let start = offset[layer[0]];
        let (done, rest) = value.split_at_mut(start);
        let done: &[f64] = done;
        let mut slices = Vec::with_capacity(layer.len());
        let mut rest = rest;
        for &s in layer {
            let (mine, tail) = rest.split_at_mut(count[s]);
            slices.push((s, mine));
            rest = tail;
        }
        let (alive_ref, count_ref, offset_ref) = (&alive, &count, &offset);
        let (w, enter, first, rest_bound) = (&w, &enter, &first, &rest_bound);
        let bits: Vec<u32> = slices
            .into_par_iter()
            .map(|(s, out)| {
                let mut bits = 0u32;
                let mut o = 0;
                for q in 0..k {
                    if s & (1 << q) == 0 {
                        continue;
                    }
                    let t = s ^ (1 << q);
                    for v in first[q]..first[q + 1] {
                        let best = if t == 0 {
                            enter[v]
                        } else {
                            let col = &w[v * n..(v + 1) * n];
                            let mut best = f64::INFINITY;
                            let live = alive_ref[t];
                            let mut base = offset_ref[t];
                            for r in 0..k {
                                if t & (1 << r) == 0 {
                                    continue;
                                }
                                let len = first[r + 1] - first[r];
                                if live & (1 << r) != 0 {
                                    best = best
                                        .min(min_plus(&done[base..base + len], &col[first[r]..first[r + 1]]));
                                }
                                base += len;
                            }
                            debug_assert_eq!(base, offset_ref[t] + count_ref[t]);
                            best
                        };
                        let best = if best + rest_bound[s] > bound {
                            f64::INFINITY
                        } else {
                            bits |= 1 << q;
                            best
                        };
                        out[o] = best;
                        o += 1;
                    }
                }
                bits
            })
            .collect();
        for (&s, b) in layer.iter().zip(bits) {
            alive[s] = b;
        }
        layer_begin = layer_end;
    }

    // Close and walk back.
    let mut best = (f64::INFINITY, 0usize, 0usize);
    for q in 0..k {
        for j in 0..clusters[q].len() {
            let x = value[pos(full, q, j)] + leave[first[q] + j];
            if x < best.0 {
                best = (x, q, j);
            }
        }
    }
    if !best.0.is_finite() {
        return None;
    }
    let mut path = Vec::with_capacity(k);
    let (mut s, mut q, mut j) = (full, best.1, best.2);
    loop {
        let v = first[q] + j;
        path.push(nodes[v]);
        let t = s ^ (1 << q);
        if t == 0 {
            break;
        }
        let here = value[pos(s, q, j)];
        let mut prev = None;
        'search: for r in 0..k {
            if t & (1 << r) == 0 {
                continue;
            }
            for i in 0..clusters[r].len() {
                if value[pos(t, r, i)] + w[v * n + first[r] + i] == here {
                    prev = Some((r, i));
                    break 'search;
                }
            }
        }
        // The value came from one of these predecessors, so the search always succeeds.
        let Some((r, i)) = prev else { break };
        (s, q, j) = (t, r, i);
    }
    path.reverse();
    Some((best.0, path))
}

/// `min_i a[i] + b[i]`, in four independent lanes so that it vectorises.
fn min_plus(a: &[f64], b: &[f64]) -> f64 {
    let mut lanes = [f64::INFINITY; 4];
    let mut ca = a.chunks_exact(4);
    let mut cb = b.chunks_exact(4);
    for (x, y) in (&mut ca).zip(&mut cb) {
        for l in 0..4 {
            let s = x[l] + y[l];
            if s < lanes[l] {
                lanes[l] = s;
            }
        }
    }
    for (x, y) in ca.remainder().iter().zip(cb.remainder()) {
        let s = x + y;
        if s < lanes[0] {
            lanes[0] = s;
        }
    }
    lanes[0].min(lanes[1]).min(lanes[2].min(lanes[3]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::CostMatrix;
    use proptest::prelude::*;

    /// Every tour by brute force: cluster orders × node choices.
    fn brute_force(p: &Gtsp) -> f64 {
        fn permutations(items: Vec<usize>) -> Vec<Vec<usize>> {
            if items.len() <= 1 {
                return vec![items];
            }
            let mut out = Vec::new();
            for i in 0..items.len() {
                let mut rest = items.clone();
                let x = rest.remove(i);
                for mut p in permutations(rest) {
                    p.insert(0, x);
                    out.push(p);
                }
            }
            out
        }
        let mut best = f64::INFINITY;
        for order in permutations((0..p.clusters.len()).collect()) {
            // Every node choice, as a mixed-radix counter over the clusters in this order.
            let mut choice = vec![0usize; order.len()];
            'choices: loop {
                let nodes = order
                    .iter()
                    .zip(&choice)
                    .map(|(&k, &j)| p.clusters[k][j])
                    .collect();
                best = best.min(p.tour_cost(&Tour { nodes }));
                for (i, &k) in order.iter().enumerate() {
                    choice[i] += 1;
                    if choice[i] < p.clusters[k].len() {
                        continue 'choices;
                    }
                    choice[i] = 0;
                }
                break;
            }
        }
        best
    }

    fn instance(n_clusters: usize, per: usize, seed: u64, depots: bool) -> Gtsp {
        // Random points, Euclidean (asymmetric perturbation to test direction handling).
        let mut x = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut rnd = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = n_clusters * per + if depots { 2 } else { 0 };
        let pts: Vec<(f64, f64)> = (0..n).map(|_| (rnd() * 100.0, rnd() * 100.0)).collect();
        let skew: Vec<f64> = (0..n * n).map(|_| rnd() * 5.0).collect();
        let costs = CostMatrix::from_fn(n, |i, j| {
            if i == j {
                0.0
            } else {
                ((pts[i].0 - pts[j].0).powi(2) + (pts[i].1 - pts[j].1).powi(2)).sqrt() + skew[i * n + j]
            }
        });
        let clusters: Vec<Vec<usize>> = (0..n_clusters)
            .map(|k| (k * per..(k + 1) * per).collect())
            .collect();
        let mut g = Gtsp::new(costs, clusters).unwrap();
        if depots {
            g = g.with_depots(Some(n - 2), Some(n - 1)).unwrap();
        }
        g
    }

    #[test]
    fn matches_brute_force_on_small_instances() {
        for seed in 0..12 {
            for depots in [false, true] {
                let p = instance(2 + (seed as usize % 4), 1 + (seed as usize % 3), seed, depots);
                let exact = solve(&p, HeldKarpLimits::default()).unwrap();
                p.check(&exact.tour).unwrap();
                let recomputed = p.tour_cost(&exact.tour);
                assert!(
                    (recomputed - exact.cost).abs() < 1e-9,
                    "{recomputed} vs {}",
                    exact.cost
                );
                let brute = brute_force(&p);
                assert!(
                    (exact.cost - brute).abs() < 1e-9,
                    "seed {seed} depots {depots}: {} vs {brute}",
                    exact.cost
                );
            }
        }
    }

    #[test]
    fn refuses_instances_beyond_the_memory_limit() {
        let p = instance(6, 3, 1, false);
        let err = solve(&p, HeldKarpLimits { max_states: 10 }).unwrap_err();
        assert!(matches!(err, HeldKarpError::TooLarge { .. }));
        assert_eq!(states_needed(&p), (1 << 4) * 15);
    }

    #[test]
    fn pruning_with_any_valid_bound_keeps_the_optimum() {
        for seed in 0..6 {
            for depots in [false, true] {
                let p = instance(7, 4, seed, depots);
                let free = solve_bounded(&p, f64::INFINITY).unwrap();
                // The tightest valid bound (the optimum itself) and a loose one.
                for upper in [free.cost, free.cost * 1.05] {
                    let pruned = solve_bounded(&p, upper).unwrap();
                    assert!(
                        (pruned.cost - free.cost).abs() < 1e-9,
                        "seed {seed}: {} vs {}",
                        pruned.cost,
                        free.cost
                    );
                    assert_eq!(
                        pruned.tour, free.tour,
                        "seed {seed}: same tour whatever the bound"
                    );
                    p.check(&pruned.tour).unwrap();
                }
            }
        }
    }

    proptest! {
        #[test]
        fn no_random_tour_beats_the_optimum(seed in 0u64..1000, swaps in proptest::collection::vec((0usize..5, 0usize..5, 0usize..3), 0..8)) {
            let p = instance(5, 3, seed, seed % 2 == 0);
            let exact = solve(&p, HeldKarpLimits::default()).unwrap();
            let mut order: Vec<usize> = (0..5).collect();
            let mut pick = [0usize; 5];
            for (a, b, j) in swaps {
                order.swap(a, b);
                pick[a] = j;
            }
            let tour = Tour { nodes: order.iter().map(|&k| p.clusters[k][pick[k]]).collect() };
            prop_assert!(exact.cost <= p.tour_cost(&tour) + 1e-9);
        }
    }
}

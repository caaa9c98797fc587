//! Exact Held–Karp dynamic programming over clusters (paper 002 §2.1): the optimal GTSP tour for
//! small instances. State: (set of clusters visited, last node); each set's values are stored
//! only for the nodes of its clusters, so memory is 2^(K−1)·N values for K clusters and N nodes
//! (12 clusters × 20 nodes: 49 k values; 20 clusters, 301 nodes: 158 M values, 1.3 GB).
use crate::problem::{Gtsp, Tour};

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
    let c = |u: usize, v: usize| p.costs.get(u, v) + p.service[v];
    match p.start {
        Some(s) => {
            let end = p.end.unwrap_or(s);
            let (cost, path) = run(&p.clusters, &c, &|v| c(s, v), &|v| p.costs.get(v, end));
            let cost = cost + p.service[s] + if end != s { p.service[end] } else { 0.0 };
            Ok(Exact {
                tour: Tour { nodes: path },
                cost,
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
                let (cost, path) = if rest.is_empty() {
                    (p.costs.get(s, s), Vec::new())
                } else {
                    run(&rest, &c, &|v| c(s, v), &|v| p.costs.get(v, s))
                };
                let cost = cost + p.service[s];
                if best.as_ref().is_none_or(|b| cost < b.cost) {
                    let mut nodes = vec![s];
                    nodes.extend(path);
                    best = Some(Exact {
                        tour: Tour { nodes },
                        cost,
                    });
                }
            }
            best.ok_or(HeldKarpError::Empty)
        }
    }
}

/// The DP over `clusters`: cheapest path entering with `from(v)`, visiting one node per
/// cluster, leaving with `to(v)`. Returns the cost and the node path.
fn run(
    clusters: &[Vec<usize>],
    c: &dyn Fn(usize, usize) -> f64,
    from: &dyn Fn(usize) -> f64,
    to: &dyn Fn(usize) -> f64,
) -> (f64, Vec<usize>) {
    let k = clusters.len();
    let full = (1usize << k) - 1;
    // Nodes in each subset, and each subset's offset in the value table.
    let mut count = vec![0usize; full + 1];
    for s in 1..=full {
        let low = s.trailing_zeros() as usize;
        count[s] = count[s & (s - 1)] + clusters[low].len();
    }
    let mut offset = vec![0usize; full + 2];
    for s in 0..=full {
        offset[s + 1] = offset[s] + count[s];
    }
    let mut value = vec![f64::INFINITY; offset[full + 1]];
    // Position of node j of cluster q inside subset s: the nodes of s's lower clusters first.
    let pos = |s: usize, q: usize, j: usize| offset[s] + count[s & ((1 << q) - 1)] + j;
    for s in 1..=full {
        for q in 0..k {
            if s & (1 << q) == 0 {
                continue;
            }
            let t = s ^ (1 << q);
            for (j, &v) in clusters[q].iter().enumerate() {
                let best = if t == 0 {
                    from(v)
                } else {
                    let mut best = f64::INFINITY;
                    let mut at = offset[t];
                    for (r, cluster) in clusters.iter().enumerate() {
                        if t & (1 << r) == 0 {
                            continue;
                        }
                        for &u in cluster {
                            let x = value[at] + c(u, v);
                            if x < best {
                                best = x;
                            }
                            at += 1;
                        }
                    }
                    best
                };
                value[pos(s, q, j)] = best;
            }
        }
    }
    // Close and walk back.
    let mut best = (f64::INFINITY, 0usize, 0usize);
    for (q, cluster) in clusters.iter().enumerate() {
        for (j, &v) in cluster.iter().enumerate() {
            let x = value[pos(full, q, j)] + to(v);
            if x < best.0 {
                best = (x, q, j);
            }
        }
    }
    let mut path = Vec::with_capacity(k);
    let (mut s, mut q, mut j) = (full, best.1, best.2);
    loop {
        let v = clusters[q][j];
        path.push(v);
        let t = s ^ (1 << q);
        if t == 0 {
            break;
        }
        let here = value[pos(s, q, j)];
        let mut prev = None;
        'search: for (r, cluster) in clusters.iter().enumerate() {
            if t & (1 << r) == 0 {
                continue;
            }
            for (i, &u) in cluster.iter().enumerate() {
                if value[pos(t, r, i)] + c(u, v) == here {
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
    (best.0, path)
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

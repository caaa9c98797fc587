//! Anytime heuristic for the GTSP (and the TSP, as singleton clusters): nearest-neighbour
//! construction over clusters, the layer pass (the best node per cluster for a fixed cluster
//! order, by DP), 2-opt and Or-opt on neighbour lists with node re-choice, and iterated local
//! search with local double-bridge kicks. Deterministic for a seed and `max_iterations`; the time
//! limit only cuts the search short. [`GtspMethod::Ga`] selects paper 003's enhanced genetic
//! algorithm instead (module `ga`).
//!
//! Internally a tour is an array of *items*: the clusters in visiting order and, when the problem
//! has depots, a fixed pseudo-cluster at position 0 standing for "start … end" (arcs into it go
//! to `end`, arcs out of it leave `start`). Either way the array is read as a cycle.
use std::time::{Duration, Instant};

use crate::problem::{Gtsp, Tour};

mod construct;
mod ga;
mod ils;
mod layer;
mod or_opt;
mod search;
mod two_opt;

/// Which GTSP heuristic [`solve`] runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GtspMethod {
    /// The default: iterated local search (nearest-neighbour construction, layer pass, 2-opt,
    /// Or-opt, double-bridge kicks); `iterations` counts kicks.
    #[default]
    Ils,
    /// Paper 003's enhanced genetic algorithm (§3.3, Algorithm 5): random-key-like integer
    /// encoding by sub-segments, elite/non-elite two-point crossover, heuristic mutation and the
    /// paper's max/min gene exchange ("2-opt"); population 100, 10 elite, `P_c` = 0.9,
    /// `P_m` = 1.0, 3 mutated genes. `iterations` counts generations (`max_iterations` = `T_iter`).
    Ga,
}

/// Parameters of [`solve`].
#[derive(Clone, Debug, PartialEq)]
pub struct GtspParams {
    /// Stop after this much wall-clock time (checked between iterations).
    pub time_limit: Duration,
    /// Seed of the random kicks (ILS) or of the GA.
    pub seed: u64,
    /// Stop after this many kicks (ILS) or generations (GA); the result then depends only on the
    /// instance and the seed.
    pub max_iterations: Option<usize>,
    /// ILS: stop after this many kicks in a row that did not improve the best tour (the result
    /// still depends only on the instance and the seed).
    pub max_stall: Option<usize>,
    /// The heuristic (default [`GtspMethod::Ils`]).
    pub method: GtspMethod,
}

impl Default for GtspParams {
    fn default() -> Self {
        GtspParams {
            time_limit: Duration::from_secs(1),
            seed: 0,
            max_iterations: None,
            max_stall: None,
            method: GtspMethod::Ils,
        }
    }
}

/// The best tour found, its cost (as [`Gtsp::tour_cost`] counts it) and the kicks made.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// The tour (depots excluded).
    pub tour: Tour,
    /// Its cost.
    pub cost: f64,
    /// Iterated-local-search kicks made (ILS) or generations run (GA).
    pub iterations: usize,
}

/// Improvements smaller than this are ignored (guards against cycling on rounding).
pub(crate) const EPS: f64 = 1e-7;

/// The best GTSP tour found for `p` within `params`. With depots the tour runs start → clusters
/// → end (back to start when `end` is `None`); without, it is a closed cycle.
pub fn solve(p: &Gtsp, params: &GtspParams) -> Solution {
    let deadline = Instant::now() + params.time_limit;
    if params.method == GtspMethod::Ga {
        let (tour, iterations) = ga::run(p, params, deadline);
        let cost = p.tour_cost(&tour);
        return Solution {
            tour,
            cost,
            iterations,
        };
    }
    let inst = Inst::new(p);
    let (st, iterations) = ils::run(&inst, params, deadline);
    let tour = inst.tour_of(&st);
    let cost = p.tour_cost(&tour);
    Solution {
        tour,
        cost,
        iterations,
    }
}

/// The instance as the search sees it.
pub(crate) struct Inst<'a> {
    /// Row-major costs.
    data: &'a [f64],
    service: &'a [f64],
    /// Real nodes; node `n` is the depot item.
    n: usize,
    /// Clusters; pseudo-cluster `k` is the depot item (when `depot`).
    k: usize,
    clusters: Vec<Vec<usize>>,
    depot: bool,
    start: usize,
    end: usize,
    /// Whether arc costs are symmetric (2-opt then needs no prefix sums).
    sym: bool,
    /// Nearest items of every item (clusters and the depot item).
    neigh: Vec<Vec<usize>>,
    /// The nearest-neighbour order of the items (the search's first tour).
    first_order: Vec<usize>,
    /// Service of the depots, constant.
    fixed: f64,
    /// Per cluster, the cheapest arcs into and out of it (see [`ClusterBounds`]); `None` when
    /// every cluster has one node or the table would be too large.
    bounds: Option<ClusterBounds>,
}

/// Lower bounds for the scans over a cluster's nodes (a node re-chosen between two others):
/// for cluster `c` and node `u` (the depot item included), the cheapest arc from `u` into `c`
/// and out of `c` into `u`, and the cheapest service in `c`. A scan whose bound cannot beat
/// what it must beat is skipped; the bound is a sum of the same terms in the same order as
/// every scanned value, each no larger, so (rounding being monotone) no skipped value could
/// have won and the search takes the same moves.
pub(crate) struct ClusterBounds {
    /// `into[c * (n + 1) + u]`: min over `z` in `c` of `w(u, z)`.
    into: Vec<f64>,
    /// `out[c * (n + 1) + v]`: min over `z` in `c` of `w(z, v)`.
    out: Vec<f64>,
    /// Min over `z` in `c` of `s(z)`.
    service: Vec<f64>,
}

/// Largest `into` / `out` table built (entries each; 16 MB apiece): larger instances scan
/// their clusters whole.
const BOUNDS_MAX_ENTRIES: usize = 2_000_000;

impl<'a> Inst<'a> {
    fn new(p: &'a Gtsp) -> Self {
        let n = p.costs.n();
        let k = p.clusters.len();
        let (depot, start, end, fixed) = match p.start {
            Some(s) => {
                let e = p.end.unwrap_or(s);
                let f = p.service[s] + if e != s { p.service[e] } else { 0.0 };
                (true, s, e, f)
            }
            None => (false, 0, 0, 0.0),
        };
        let mut clusters = p.clusters.clone();
        if depot {
            clusters.push(vec![n]);
        }
        let mut inst = Inst {
            data: p.costs.data(),
            service: &p.service,
            n,
            k,
            clusters,
            depot,
            start,
            end,
            sym: p.costs.is_symmetric(0.0),
            neigh: Vec::new(),
            first_order: Vec::new(),
            fixed,
            bounds: None,
        };
        (inst.neigh, inst.first_order) = construct::neighbours_and_order(&inst, 12);
        inst.bounds = inst.cluster_bounds();
        inst
    }

    /// The [`ClusterBounds`] of the instance, when some cluster has several nodes and the
    /// tables stay within [`BOUNDS_MAX_ENTRIES`].
    fn cluster_bounds(&self) -> Option<ClusterBounds> {
        let nn = self.n + 1;
        let k = self.clusters.len();
        if self.clusters.iter().all(|c| c.len() < 2) || k.saturating_mul(nn) > BOUNDS_MAX_ENTRIES {
            return None;
        }
        let mut into = vec![f64::INFINITY; k * nn];
        let mut out = vec![f64::INFINITY; k * nn];
        let mut service = vec![f64::INFINITY; k];
        for (c, cluster) in self.clusters.iter().enumerate() {
            let (into, out) = (&mut into[c * nn..(c + 1) * nn], &mut out[c * nn..(c + 1) * nn]);
            for &z in cluster {
                service[c] = service[c].min(self.s(z));
                for u in 0..nn {
                    into[u] = into[u].min(self.w(u, z));
                    out[u] = out[u].min(self.w(z, u));
                }
            }
        }
        Some(ClusterBounds { into, out, service })
    }

    /// A lower bound on `w(u, z) + s(z) + w(z, v)` (summed in that order) over the nodes `z`
    /// of cluster `c`; minus infinity without [`ClusterBounds`].
    #[inline]
    pub(crate) fn through_bound(&self, u: usize, c: usize, v: usize) -> f64 {
        match &self.bounds {
            Some(b) => {
                let nn = self.n + 1;
                b.into[c * nn + u] + b.service[c] + b.out[c * nn + v]
            }
            None => f64::NEG_INFINITY,
        }
    }

    /// The row of arc costs out of node `u` (the depot item standing for start), to be indexed
    /// by [`Inst::column`].
    #[inline]
    pub(crate) fn row(&self, u: usize) -> &[f64] {
        let from = self.row_start(u);
        &self.data[from..from + self.n]
    }

    /// Where the row of node `u` starts in the table (the depot item standing for start).
    #[inline]
    fn row_start(&self, u: usize) -> usize {
        (if u == self.n { self.start } else { u }) * self.n
    }

    /// The index of node `v` in a [`Inst::row`] (the depot item standing for end):
    /// `w(u, v) == row(u)[column(v)]`.
    #[inline]
    pub(crate) fn column(&self, v: usize) -> usize {
        if v == self.n { self.end } else { v }
    }

    /// Number of items (clusters plus the depot item).
    #[inline]
    pub(crate) fn items(&self) -> usize {
        self.clusters.len()
    }

    /// Arc cost between two nodes, the depot item `n` standing for start (out) and end (in).
    #[inline]
    pub(crate) fn w(&self, u: usize, v: usize) -> f64 {
        self.data[self.row_start(u) + self.column(v)]
    }

    /// Service of a node (0 for the depot item, whose service is in `fixed`).
    #[inline]
    pub(crate) fn s(&self, v: usize) -> f64 {
        if v == self.n { 0.0 } else { self.service[v] }
    }

    /// The cost of a state, as `Gtsp::tour_cost` counts it.
    pub(crate) fn cost(&self, st: &State) -> f64 {
        let m = st.t.len();
        let mut total = self.fixed;
        for i in 0..m {
            let u = st.node(i);
            let v = st.node(if i + 1 == m { 0 } else { i + 1 });
            total += self.w(u, v) + self.s(u);
        }
        total
    }

    fn tour_of(&self, st: &State) -> Tour {
        let nodes = if self.depot {
            st.t[1..].iter().map(|&c| st.choice[c]).collect()
        } else {
            st.t.iter().map(|&c| st.choice[c]).collect()
        };
        Tour { nodes }
    }
}

/// A tour: items in order, their positions, the chosen node of every item, and (for asymmetric
/// costs) prefix sums of the forward and backward arc costs along the array.
#[derive(Clone, Debug, Default)]
pub(crate) struct State {
    pub t: Vec<usize>,
    pub pos: Vec<usize>,
    pub choice: Vec<usize>,
    pub fwd: Vec<f64>,
    pub bwd: Vec<f64>,
}

impl State {
    pub(crate) fn new(inst: &Inst, order: Vec<usize>) -> Self {
        let mut pos = vec![0; inst.items()];
        for (i, &c) in order.iter().enumerate() {
            pos[c] = i;
        }
        let mut st = State {
            t: order,
            pos,
            choice: inst.clusters.iter().map(|c| c[0]).collect(),
            fwd: Vec::new(),
            bwd: Vec::new(),
        };
        st.refresh(inst);
        st
    }

    /// The node at position `i`.
    #[inline]
    pub(crate) fn node(&self, i: usize) -> usize {
        self.choice[self.t[i]]
    }

    /// The position after `i`, cyclically.
    #[inline]
    pub(crate) fn next(&self, i: usize) -> usize {
        if i + 1 == self.t.len() { 0 } else { i + 1 }
    }

    /// The position before `i`, cyclically.
    #[inline]
    pub(crate) fn prev(&self, i: usize) -> usize {
        if i == 0 { self.t.len() - 1 } else { i - 1 }
    }

    /// Recompute positions of `lo..=hi` and, for asymmetric costs, the prefix sums.
    pub(crate) fn reindex(&mut self, inst: &Inst, lo: usize, hi: usize) {
        for i in lo..=hi {
            self.pos[self.t[i]] = i;
        }
        if !inst.sym {
            self.refresh(inst);
        }
    }

    /// Recompute the prefix sums (asymmetric costs only).
    pub(crate) fn refresh(&mut self, inst: &Inst) {
        if inst.sym {
            return;
        }
        let m = self.t.len();
        self.fwd.clear();
        self.bwd.clear();
        let (mut f, mut b) = (0.0, 0.0);
        self.fwd.push(0.0);
        self.bwd.push(0.0);
        for i in 0..m.saturating_sub(1) {
            let (u, v) = (self.node(i), self.node(i + 1));
            f += inst.w(u, v);
            b += inst.w(v, u);
            self.fwd.push(f);
            self.bwd.push(b);
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::held_karp::{self, HeldKarpLimits};
    use crate::problem::CostMatrix;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// `k` clusters of `per` random points in the unit square ×100, plus `depots` extra nodes;
    /// asymmetric when `asym`.
    pub(crate) fn random_gtsp(seed: u64, k: usize, per: usize, depots: usize, asym: bool) -> Gtsp {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let n = k * per + depots;
        let pts: Vec<(f64, f64)> = (0..n)
            .map(|_| (rng.random::<f64>() * 100.0, rng.random::<f64>() * 100.0))
            .collect();
        let extra: Vec<f64> = (0..n * n).map(|_| rng.random::<f64>() * 20.0).collect();
        let costs = CostMatrix::from_fn(n, |i, j| {
            let d = ((pts[i].0 - pts[j].0).powi(2) + (pts[i].1 - pts[j].1).powi(2)).sqrt();
            if asym { d + extra[i * n + j] } else { d }
        });
        let clusters = (0..k).map(|c| (c * per..(c + 1) * per).collect()).collect();
        Gtsp::new(costs, clusters).unwrap()
    }

    fn check(p: &Gtsp, iters: usize, seed: u64) -> Solution {
        let params = GtspParams {
            time_limit: Duration::from_secs(3600),
            seed,
            max_iterations: Some(iters),
            max_stall: None,
            method: GtspMethod::Ils,
        };
        let sol = solve(p, &params);
        p.check(&sol.tour).unwrap();
        assert_eq!(sol.cost, p.tour_cost(&sol.tour));
        sol
    }

    fn assert_optimal(p: &Gtsp, seed: u64) {
        let exact = held_karp::solve(p, HeldKarpLimits::default()).unwrap();
        let sol = check(p, 300, seed);
        assert!(
            (sol.cost - exact.cost).abs() < 1e-6,
            "heuristic {} vs optimum {}",
            sol.cost,
            exact.cost
        );
    }

    #[test]
    fn gtsp_matches_held_karp_closed() {
        for seed in 0..6 {
            assert_optimal(&random_gtsp(seed, 8, 3, 0, false), seed);
        }
    }

    #[test]
    fn gtsp_matches_held_karp_with_depots() {
        for seed in 0..6 {
            let g = random_gtsp(100 + seed, 8, 3, 2, false);
            let n = g.costs.n();
            let ret = g.clone().with_depots(Some(n - 2), None).unwrap();
            assert_optimal(&ret, seed);
            let path = g.with_depots(Some(n - 2), Some(n - 1)).unwrap();
            assert_optimal(&path, seed);
        }
    }

    #[test]
    fn gtsp_matches_held_karp_asymmetric_with_service() {
        for seed in 0..6 {
            let g = random_gtsp(200 + seed, 8, 3, 1, true);
            let n = g.costs.n();
            let service = (0..n).map(|v| (v % 5) as f64).collect();
            let g = g.with_service(service).unwrap();
            assert_optimal(&g, seed);
            assert_optimal(&g.with_depots(Some(n - 1), None).unwrap(), seed);
        }
    }

    /// The layer pass as first written (for each node of a layer, every node of the layer
    /// before through `w`), to compare with the row-by-row one.
    fn layer_pass_plain(inst: &Inst, st: &mut State) -> Vec<usize> {
        let m = st.t.len();
        let (first, layers) = layer::layers(inst, st);
        let mut best = (f64::INFINITY, Vec::new());
        for &s in layers[0] {
            let mut value = vec![(inst.s(s), vec![s])];
            for layer in &layers[1..] {
                value = layer
                    .iter()
                    .map(|&v| {
                        let mut b = (f64::INFINITY, 0);
                        for (i, (x, path)) in value.iter().enumerate() {
                            let x = x + inst.w(*path.last().unwrap(), v);
                            if x < b.0 {
                                b = (x, i);
                            }
                        }
                        let mut path = value[b.1].1.clone();
                        path.push(v);
                        (b.0 + inst.s(v), path)
                    })
                    .collect();
            }
            for (x, path) in value {
                let x = x + inst.w(*path.last().unwrap(), s);
                if x < best.0 {
                    best = (x, path);
                }
            }
        }
        if best.0 >= inst.cost(st) - inst.fixed - EPS {
            return Vec::new();
        }
        let mut changed = Vec::new();
        for (l, &node) in best.1.iter().enumerate().rev() {
            let item = st.t[(first + l) % m];
            if st.choice[item] != node {
                st.choice[item] = node;
                changed.push(item);
            }
        }
        st.refresh(inst);
        changed
    }

    /// The items `0..m` in a random order.
    fn shuffled(m: usize, rng: &mut ChaCha8Rng) -> Vec<usize> {
        let mut order: Vec<usize> = (0..m).collect();
        for i in (1..order.len()).rev() {
            order.swap(i, rng.random_range(0..=i));
        }
        order
    }

    /// A state of `order` with a random node chosen in every cluster.
    fn random_state(inst: &Inst, order: Vec<usize>, rng: &mut ChaCha8Rng) -> State {
        let mut st = State::new(inst, order);
        for (x, c) in inst.clusters.iter().enumerate() {
            st.choice[x] = c[rng.random_range(0..c.len())];
        }
        st.refresh(inst);
        st
    }

    /// Random instances of every shape the sequencer and the benchmarks use: closed or with a
    /// start depot, symmetric or not, with service times, clusters of 1–6 nodes, consecutive
    /// or interleaved.
    fn shaped_instances() -> Vec<Gtsp> {
        let mut out = Vec::new();
        for seed in 0..8u64 {
            let (k, per) = (5 + seed as usize * 3, 1 + seed as usize % 6);
            let g = random_gtsp(300 + seed, k, per, 1, seed % 2 == 1);
            let n = g.costs.n();
            let service = (0..n)
                .map(|v| ((v * 7 + seed as usize) % 4) as f64 * 0.5)
                .collect();
            let g = g.with_service(service).unwrap();
            out.push(g.clone());
            // The same nodes in interleaved clusters (no cluster of consecutive nodes).
            let interleaved = (0..k).map(|c| (0..per).map(|x| x * k + c).collect()).collect();
            let spread = Gtsp::new(g.costs.clone(), interleaved).unwrap();
            out.push(spread.with_depots(Some(n - 1), None).unwrap());
            out.push(g.with_depots(Some(n - 1), None).unwrap());
        }
        out
    }

    #[test]
    fn the_row_by_row_layer_pass_chooses_as_the_plain_one() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for g in shaped_instances() {
            let inst = Inst::new(&g);
            for _ in 0..5 {
                let order = shuffled(inst.items(), &mut rng);
                let mut st = random_state(&inst, order, &mut rng);
                let mut plain = st.clone();
                let changed = layer::layer_pass(&inst, &mut st, &mut layer::LayerMemo::default());
                let expected = layer_pass_plain(&inst, &mut plain);
                assert_eq!(changed, expected);
                assert_eq!(st.choice, plain.choice);
            }
        }
    }

    /// A layer pass that reuses the last pass's table (the orders here share prefixes, as a
    /// kick's or a local move's do) chooses as one computed afresh.
    #[test]
    fn the_layer_memo_changes_no_choice() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut reused = 0;
        for g in shaped_instances() {
            let inst = Inst::new(&g);
            let m = inst.items();
            // The depot item (the last) first: the layers are read from it.
            let mut order: Vec<usize> = (0..m).collect();
            order.rotate_right(usize::from(inst.depot));
            let mut memo = layer::LayerMemo::default();
            for _ in 0..20 {
                // Swap two adjacent segments after a random point (the first item stays).
                let p = rng.random_range(1..m - 1);
                let l = rng.random_range(1..m - p);
                order[p..].rotate_left(l);
                let mut st = random_state(&inst, order.clone(), &mut rng);
                let mut fresh = st.clone();
                let changed = layer::layer_pass(&inst, &mut st, &mut memo);
                let expected = layer::layer_pass(&inst, &mut fresh, &mut layer::LayerMemo::default());
                assert_eq!(changed, expected);
                assert_eq!(st.choice, fresh.choice);
                assert_eq!(inst.cost(&st).to_bits(), inst.cost(&fresh).to_bits());
            }
            reused += memo.reused;
        }
        assert!(reused > 0, "no pass reused a layer");
    }

    /// Every Or-opt move's stated change (segment's shared sums made once, each place then
    /// costed) is the tour's change once the move is applied.
    #[test]
    fn or_opt_changes_are_the_tour_changes() {
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        let mut moves = 0;
        for g in shaped_instances() {
            let inst = Inst::new(&g);
            let m = inst.items();
            if m < 5 {
                continue;
            }
            for _ in 0..30 {
                let order = shuffled(m, &mut rng);
                let st = random_state(&inst, order, &mut rng);
                let l = rng.random_range(0..m);
                let r = (l + rng.random_range(0..3)).min(m - 1);
                let Some(seg) = or_opt::segment(&inst, &st, l, r) else {
                    continue;
                };
                let before = inst.cost(&st);
                for q in 0..m {
                    let Some((d, mv)) = or_opt::best_at(&inst, &st, &seg, q, f64::INFINITY) else {
                        continue;
                    };
                    let mut after = st.clone();
                    or_opt::apply(&inst, &mut after, mv);
                    after.refresh(&inst);
                    let got = inst.cost(&after) - before;
                    assert!(
                        (got - d).abs() <= 1e-9 * (1.0 + before.abs()),
                        "{mv:?}: {d} vs {got}"
                    );
                    moves += 1;
                }
            }
        }
        assert!(moves > 1000, "{moves} moves");
    }

    #[test]
    fn the_cluster_bounds_change_no_move() {
        let mut pruned_some = false;
        for g in shaped_instances() {
            let with = Inst::new(&g);
            let mut without = Inst::new(&g);
            pruned_some |= with.bounds.is_some();
            without.bounds = None;
            let params = GtspParams {
                time_limit: Duration::from_secs(3600),
                seed: 3,
                max_iterations: Some(60),
                max_stall: None,
                method: GtspMethod::Ils,
            };
            let far = Instant::now() + params.time_limit;
            let (a, ia) = ils::run(&with, &params, far);
            let (b, ib) = ils::run(&without, &params, far);
            assert_eq!((a.t, a.choice, ia), (b.t, b.choice, ib));
        }
        assert!(pruned_some);
    }

    #[test]
    fn gtsp_tiny_and_empty() {
        let g = random_gtsp(7, 0, 1, 2, false);
        let sol = check(&g, 10, 0);
        assert!(sol.tour.nodes.is_empty());
        let d = g.with_depots(Some(0), Some(1)).unwrap();
        let sol = check(&d, 10, 0);
        assert_eq!(sol.cost, d.costs.get(0, 1));
        for k in 1..=4 {
            assert_optimal(&random_gtsp(k as u64, k, 3, 0, true), 0);
            let g = random_gtsp(k as u64, k, 2, 1, false);
            let n = g.costs.n();
            assert_optimal(&g.with_depots(Some(n - 1), None).unwrap(), 0);
        }
    }

    #[test]
    fn gtsp_same_seed_same_tour() {
        let g = random_gtsp(5, 40, 4, 0, false);
        let a = check(&g, 200, 9);
        let b = check(&g, 200, 9);
        assert_eq!(a, b);
    }

    #[test]
    fn gtsp_tsp_singletons() {
        let g = random_gtsp(11, 60, 1, 0, false);
        let g = Gtsp::tsp(g.costs);
        let zero = check(&g, 0, 0);
        let more = check(&g, 500, 0);
        assert!(more.cost <= zero.cost);
    }
}

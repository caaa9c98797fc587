//! Weighted set cover: choose columns of least total cost so that every row is covered.
//!
//! - [`greedy`]: Chvátal's ratio rule (cost per newly covered row), then redundant columns are
//!   dropped, most expensive first.
//! - [`exact`]: depth-first branch and bound on a column (include, then exclude) with Lagrangian
//!   lower bounds from subgradient optimisation of the row multipliers (Beasley 1990 style),
//!   forced columns (a row left with one usable column forces it), Lagrangian reduced-cost
//!   fixing and a Lagrangian heuristic for upper bounds. It stops at [`ExactLimits`] and then
//!   returns the best cover found with `proven_optimal: false`.
//! - [`penalty_method`]: the penalty / auxiliary-function search of paper 000 (§3.2, eq. 6–7):
//!   minimise `f(β) = Σ c_j β_j + μ·(uncovered rows)` by flip moves, and escape the current
//!   local minimiser `x0` by descending `T(x, k) = f(x) + k‖x − x0‖₁` when `f(x) ≥ f(x1*)`
//!   (and `f(x)` otherwise) from perturbations of `x0`.
//!
//! All three assume non-negative costs and panic if some row is covered by no column (the
//! instance is then infeasible) or a row names a column out of range. Every returned
//! [`Cover`] covers all rows, lists its columns sorted, and its `cost` is
//! [`SetCover::cover_cost`] of those columns.
use std::time::{Duration, Instant};

use crate::problem::SetCover;

/// A set-cover solution.
#[derive(Clone, Debug, PartialEq)]
pub struct Cover {
    /// The chosen columns, sorted ascending, without repeats.
    pub columns: Vec<usize>,
    /// Their total cost.
    pub cost: f64,
    /// Whether the solver proved that no cheaper cover exists.
    pub proven_optimal: bool,
}

/// When [`exact`] gives up proving and returns its best cover.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExactLimits {
    /// Wall-clock budget (`None`: unlimited). Results cut by time depend on machine speed.
    pub time_limit: Option<Duration>,
    /// Branch-and-bound nodes to process at most (`None`: unlimited). Deterministic.
    pub max_nodes: Option<u64>,
}

impl Default for ExactLimits {
    /// 60 s and no node limit.
    fn default() -> Self {
        ExactLimits {
            time_limit: Some(Duration::from_secs(60)),
            max_nodes: None,
        }
    }
}

/// Parameters of [`penalty_method`].
#[derive(Clone, Debug, PartialEq)]
pub struct PenaltyParams {
    /// Penalty `μ` per uncovered row; `None`: the largest column cost plus one, which makes
    /// every local minimiser of `f` under flip moves a cover.
    pub mu: Option<f64>,
    /// Weight `k` of the distance term of the auxiliary function `T`; `None`: the mean column
    /// cost.
    pub k: Option<f64>,
    /// Rounds of escapes from the current local minimiser.
    pub rounds: usize,
    /// Perturbed starting points tried per round before moving on.
    pub tries: usize,
    /// Columns flipped in a perturbation of `x0`.
    pub strength: usize,
    /// Seed of the perturbations; equal seeds give equal results.
    pub seed: u64,
}

impl Default for PenaltyParams {
    fn default() -> Self {
        PenaltyParams {
            mu: None,
            k: None,
            rounds: 300,
            tries: 8,
            strength: 6,
            seed: 1,
        }
    }
}

/// The instance with its transpose, validated.
struct Inst<'a> {
    sc: &'a SetCover,
    colrows: Vec<Vec<usize>>,
}

impl<'a> Inst<'a> {
    fn new(sc: &'a SetCover) -> Self {
        assert_eq!(
            sc.covers.len(),
            sc.rows,
            "the set cover lists {} rows' covers but claims {} rows",
            sc.covers.len(),
            sc.rows
        );
        assert_eq!(
            sc.costs.len(),
            sc.columns,
            "the set cover lists {} costs for {} columns",
            sc.costs.len(),
            sc.columns
        );
        for (r, cols) in sc.covers.iter().enumerate() {
            assert!(
                !cols.is_empty(),
                "row {r} is covered by no column; the instance is infeasible"
            );
            if let Some(&c) = cols.iter().find(|&&c| c >= sc.columns) {
                panic!(
                    "row {r} names column {c}, out of range (the instance has {} columns)",
                    sc.columns
                );
            }
        }
        Inst {
            sc,
            colrows: sc.column_rows(),
        }
    }

    fn m(&self) -> usize {
        self.sc.rows
    }

    fn n(&self) -> usize {
        self.sc.columns
    }

    fn cost(&self, j: usize) -> f64 {
        self.sc.costs[j]
    }

    fn finish(&self, mut columns: Vec<usize>, proven_optimal: bool) -> Cover {
        columns.sort_unstable();
        columns.dedup();
        let cost = self
            .sc
            .cover_cost(&columns)
            .expect("internal error: a set-cover solver returned a non-cover");
        Cover {
            columns,
            cost,
            proven_optimal,
        }
    }

    fn add(&self, j: usize, chosen: &mut Vec<usize>, cnt: &mut [u32]) {
        chosen.push(j);
        for &r in &self.colrows[j] {
            cnt[r] += 1;
        }
    }

    /// Extends `chosen` (whose row counts are `cnt`) to a cover with usable columns by the
    /// ratio rule. False if some row cannot be covered.
    fn complete(&self, usable: &dyn Fn(usize) -> bool, chosen: &mut Vec<usize>, cnt: &mut [u32]) -> bool {
        let mut unc: Vec<usize> = (0..self.m()).filter(|&i| cnt[i] == 0).collect();
        let mut seen = vec![false; self.n()];
        let mut cand = Vec::new();
        while !unc.is_empty() {
            cand.clear();
            for &i in &unc {
                for &j in &self.sc.covers[i] {
                    if !seen[j] && usable(j) {
                        seen[j] = true;
                        cand.push(j);
                    }
                }
            }
            let mut best: Option<(f64, usize, usize)> = None;
            for &j in &cand {
                seen[j] = false;
                let k = self.colrows[j].iter().filter(|&&r| cnt[r] == 0).count();
                let ratio = self.cost(j) / k as f64;
                let better = match best {
                    None => true,
                    Some((br, bk, bj)) => ratio < br || (ratio == br && (k > bk || (k == bk && j < bj))),
                };
                if better {
                    best = Some((ratio, k, j));
                }
            }
            let Some((_, _, j)) = best else {
                return false;
            };
            self.add(j, chosen, cnt);
            unc.retain(|&i| cnt[i] == 0);
        }
        true
    }

    /// Drops columns all of whose rows are covered twice, most expensive first.
    fn remove_redundant(&self, chosen: &mut Vec<usize>, cnt: &mut [u32]) {
        let mut order = chosen.clone();
        order.sort_by(|&a, &b| self.cost(b).total_cmp(&self.cost(a)).then(b.cmp(&a)));
        for j in order {
            if self.colrows[j].iter().all(|&r| cnt[r] >= 2) {
                for &r in &self.colrows[j] {
                    cnt[r] -= 1;
                }
                chosen.retain(|&c| c != j);
            }
        }
    }

    fn greedy_cover(&self) -> Vec<usize> {
        let mut cnt = vec![0u32; self.m()];
        let mut chosen = Vec::new();
        let ok = self.complete(&|_| true, &mut chosen, &mut cnt);
        debug_assert!(ok);
        self.remove_redundant(&mut chosen, &mut cnt);
        chosen
    }
}

/// Chvátal's greedy: repeatedly take the column of least cost per newly covered row (ties: more
/// rows, then the lower index), then drop redundant columns, most expensive first.
/// `proven_optimal` is true only for an instance without rows.
///
/// # Panics
/// If a row is covered by no column or names a column out of range.
pub fn greedy(sc: &SetCover) -> Cover {
    let inst = Inst::new(sc);
    let chosen = inst.greedy_cover();
    inst.finish(chosen, sc.rows == 0)
}

const FREE: u8 = 0;
const IN: u8 = 1;
const OUT: u8 = 2;

struct Bb<'a> {
    inst: &'a Inst<'a>,
    int_costs: bool,
    ub: f64,
    best: Vec<usize>,
}

/// Subgradient iterations, initial step factor and how often to run the heuristic.
#[derive(Clone, Copy)]
struct Schedule {
    iters: usize,
    lambda0: f64,
    heur_every: usize,
}

/// What processing a node left to do.
enum Outcome {
    Pruned,
    Branch {
        column: usize,
        status: Vec<u8>,
        u: Vec<f64>,
    },
}

impl Bb<'_> {
    /// Whether a lower bound shows that the subtree cannot beat the incumbent.
    fn prunes(&self, bound: f64) -> bool {
        if self.int_costs {
            bound > self.ub - 1.0 + 1e-6
        } else {
            bound >= self.ub - 1e-9 * self.ub.abs().max(1.0)
        }
    }

    /// Offers a cover (after dropping redundant columns) as the incumbent.
    fn offer(&mut self, mut chosen: Vec<usize>, cnt: &mut [u32]) {
        self.inst.remove_redundant(&mut chosen, cnt);
        let cost: f64 = chosen.iter().map(|&j| self.inst.cost(j)).sum();
        if cost < self.ub - 1e-9 {
            self.ub = cost;
            self.best = chosen;
        }
    }

    /// The Lagrangian heuristic: the columns fixed in plus those of negative reduced cost,
    /// completed greedily with columns not fixed out.
    fn heuristic(&mut self, status: &[u8], reduced: &[f64]) {
        let inst = self.inst;
        let mut cnt = vec![0u32; inst.m()];
        let mut chosen = Vec::new();
        for j in 0..inst.n() {
            if status[j] == IN || (status[j] == FREE && reduced[j] < 0.0) {
                inst.add(j, &mut chosen, &mut cnt);
            }
        }
        if inst.complete(&|j| status[j] != OUT, &mut chosen, &mut cnt) {
            self.offer(chosen, &mut cnt);
        }
    }

    /// Forced columns to a fixpoint; `None` if some row has no usable column left. Returns the
    /// per-row count of columns fixed in.
    fn reduce(&self, status: &mut [u8]) -> Option<Vec<u32>> {
        let inst = self.inst;
        let mut cnt = vec![0u32; inst.m()];
        for (j, _) in status.iter().enumerate().filter(|(_, s)| **s == IN) {
            for &r in &inst.colrows[j] {
                cnt[r] += 1;
            }
        }
        loop {
            let mut changed = false;
            for i in 0..inst.m() {
                if cnt[i] > 0 {
                    continue;
                }
                let mut free = inst.sc.covers[i].iter().filter(|&&j| status[j] == FREE);
                let &j = free.next()?;
                if free.next().is_none() {
                    status[j] = IN;
                    for &r in &inst.colrows[j] {
                        cnt[r] += 1;
                    }
                    changed = true;
                }
            }
            if !changed {
                return Some(cnt);
            }
        }
    }

    /// Reduced costs of the free columns over the uncovered rows (0 elsewhere).
    fn reduced_costs(&self, status: &[u8], open: &[bool], u: &[f64], out: &mut [f64]) {
        let inst = self.inst;
        for j in 0..inst.n() {
            out[j] = if status[j] == FREE {
                inst.cost(j)
                    - inst.colrows[j]
                        .iter()
                        .filter(|&&r| open[r])
                        .map(|&r| u[r])
                        .sum::<f64>()
            } else {
                0.0
            };
        }
    }

    /// Subgradient optimisation of the multipliers `u` of the open rows. Returns the best
    /// Lagrangian bound; `u` ends as the multipliers that gave it.
    fn subgradient(
        &mut self,
        status: &[u8],
        open: &[bool],
        fixed_cost: f64,
        u: &mut [f64],
        schedule: Schedule,
    ) -> f64 {
        let Schedule {
            iters,
            lambda0,
            heur_every,
        } = schedule;
        let inst = self.inst;
        let (m, n) = (inst.m(), inst.n());
        let mut reduced = vec![0.0; n];
        let mut g = vec![0.0f64; m];
        let mut best_l = f64::NEG_INFINITY;
        let mut best_u = u.to_vec();
        let mut lambda = lambda0;
        let mut since = 0;
        for it in 0..iters {
            self.reduced_costs(status, open, u, &mut reduced);
            let mut l = fixed_cost;
            for i in 0..m {
                if open[i] {
                    l += u[i];
                    g[i] = 1.0;
                } else {
                    g[i] = 0.0;
                }
            }
            for j in 0..n {
                if status[j] == FREE && reduced[j] < 0.0 {
                    l += reduced[j];
                    for &r in &inst.colrows[j] {
                        g[r] -= 1.0;
                    }
                }
            }
            if l > best_l + 1e-9 {
                best_l = l;
                best_u.copy_from_slice(u);
                since = 0;
            } else {
                since += 1;
            }
            if heur_every > 0 && (it % heur_every == 0 || it + 1 == iters) {
                self.heuristic(status, &reduced);
            }
            if self.prunes(best_l) {
                break;
            }
            let mut norm = 0.0;
            for i in 0..m {
                if open[i] {
                    if u[i] <= 0.0 && g[i] < 0.0 {
                        g[i] = 0.0;
                    }
                    norm += g[i] * g[i];
                }
            }
            if norm == 0.0 {
                // The relaxed solution covers every open row exactly once (where u > 0): it is
                // optimal for this node's relaxation; offer it and stop.
                self.heuristic(status, &reduced);
                break;
            }
            if since >= 20 {
                lambda /= 2.0;
                since = 0;
                if lambda < 0.005 {
                    break;
                }
            }
            let gap = (self.ub - l).max(1e-3 * self.ub.abs().max(1.0));
            let t = lambda * gap / norm;
            for i in 0..m {
                if open[i] {
                    u[i] = (u[i] + t * g[i]).max(0.0);
                }
            }
        }
        u.copy_from_slice(&best_u);
        best_l
    }

    fn process(&mut self, mut status: Vec<u8>, mut u: Vec<f64>, root: bool) -> Outcome {
        let inst = self.inst;
        let (m, n) = (inst.m(), inst.n());
        let mut reduced = vec![0.0; n];
        for pass in 0.. {
            let Some(cnt) = self.reduce(&mut status) else {
                return Outcome::Pruned;
            };
            let fixed: Vec<usize> = (0..n).filter(|&j| status[j] == IN).collect();
            let fixed_cost: f64 = fixed.iter().map(|&j| inst.cost(j)).sum();
            if cnt.iter().all(|&c| c > 0) {
                let mut cnt = cnt;
                self.offer(fixed, &mut cnt);
                return Outcome::Pruned;
            }
            if self.prunes(fixed_cost) {
                return Outcome::Pruned;
            }
            let open: Vec<bool> = cnt.iter().map(|&c| c == 0).collect();
            if root && pass == 0 {
                // Start from the cheapest cost per row of each row's columns.
                for (ui, cols) in u.iter_mut().zip(&inst.sc.covers) {
                    *ui = cols
                        .iter()
                        .map(|&j| inst.cost(j) / inst.colrows[j].len() as f64)
                        .fold(f64::INFINITY, f64::min);
                }
            }
            let schedule = if root && pass == 0 {
                Schedule {
                    iters: 3000,
                    lambda0: 2.0,
                    heur_every: 10,
                }
            } else {
                Schedule {
                    iters: 200,
                    lambda0: 0.5,
                    heur_every: 50,
                }
            };
            let bound = self.subgradient(&status, &open, fixed_cost, &mut u, schedule);
            if self.prunes(bound) {
                return Outcome::Pruned;
            }
            // Reduced-cost fixing.
            self.reduced_costs(&status, &open, &u, &mut reduced);
            let mut fixed_any = false;
            for j in 0..n {
                if status[j] != FREE {
                    continue;
                }
                if reduced[j] >= 0.0 {
                    if self.prunes(bound + reduced[j]) {
                        status[j] = OUT;
                        fixed_any = true;
                    }
                } else if self.prunes(bound - reduced[j]) {
                    status[j] = IN;
                    fixed_any = true;
                }
            }
            if fixed_any && pass < 4 {
                continue;
            }
            let Some(cnt) = self.reduce(&mut status) else {
                return Outcome::Pruned;
            };
            if cnt.iter().all(|&c| c > 0) {
                let fixed: Vec<usize> = (0..n).filter(|&j| status[j] == IN).collect();
                let mut cnt = cnt;
                self.offer(fixed, &mut cnt);
                return Outcome::Pruned;
            }
            // Branch on the free column of least reduced cost in the open row with the fewest
            // free columns.
            let open: Vec<bool> = cnt.iter().map(|&c| c == 0).collect();
            self.reduced_costs(&status, &open, &u, &mut reduced);
            let row = (0..m)
                .filter(|&i| open[i])
                .min_by_key(|&i| {
                    let k = inst.sc.covers[i].iter().filter(|&&j| status[j] == FREE).count();
                    (k, i)
                })
                .expect("an open row exists");
            let column = inst.sc.covers[row]
                .iter()
                .copied()
                .filter(|&j| status[j] == FREE)
                .min_by(|&a, &b| reduced[a].total_cmp(&reduced[b]).then(a.cmp(&b)))
                .expect("reduce left every open row two free columns");
            return Outcome::Branch { column, status, u };
        }
        unreachable!()
    }
}

/// Branch and bound for the optimal cover; see the [module](self) documentation. Depth-first,
/// branching on one column (fixed in first, then out). With `max_nodes` as the binding limit
/// the result is deterministic. When a limit stops the search the best cover found is returned
/// with `proven_optimal: false`.
///
/// # Panics
/// If a row is covered by no column or names a column out of range.
pub fn exact(sc: &SetCover, limits: &ExactLimits) -> Cover {
    let start = Instant::now();
    let inst = Inst::new(sc);
    if sc.rows == 0 {
        return inst.finish(Vec::new(), true);
    }
    let best = inst.greedy_cover();
    let mut bb = Bb {
        inst: &inst,
        int_costs: sc.costs.iter().all(|c| c.fract() == 0.0),
        ub: best.iter().map(|&j| sc.costs[j]).sum(),
        best,
    };
    let mut stack: Vec<(Vec<u8>, Vec<f64>, bool)> = vec![(vec![FREE; sc.columns], vec![0.0; sc.rows], true)];
    let mut nodes = 0u64;
    let mut stopped = false;
    while let Some((status, u, root)) = stack.pop() {
        if limits.max_nodes.is_some_and(|k| nodes >= k)
            || limits.time_limit.is_some_and(|t| start.elapsed() >= t)
        {
            stopped = true;
            break;
        }
        nodes += 1;
        if let Outcome::Branch { column, status, u } = bb.process(status, u, root) {
            let mut out = status.clone();
            out[column] = OUT;
            stack.push((out, u.clone(), false));
            let mut inn = status;
            inn[column] = IN;
            stack.push((inn, u, false));
        }
    }
    let best = std::mem::take(&mut bb.best);
    inst.finish(best, !stopped)
}

/// xorshift64* seeded through splitmix64.
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        Rng((z ^ (z >> 31)) | 1)
    }

    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        ((self.next() >> 11) as f64 / (1u64 << 53) as f64 * n as f64) as usize % n.max(1)
    }
}

/// A binary vector β with its row counts, cost and uncovered rows.
#[derive(Clone)]
struct Point {
    x: Vec<bool>,
    cnt: Vec<u32>,
    cost: f64,
    uncovered: usize,
}

impl Point {
    fn f(&self, mu: f64) -> f64 {
        self.cost + mu * self.uncovered as f64
    }

    fn flip(&mut self, inst: &Inst, j: usize) {
        if self.x[j] {
            self.x[j] = false;
            self.cost -= inst.cost(j);
            for &r in &inst.colrows[j] {
                self.cnt[r] -= 1;
                if self.cnt[r] == 0 {
                    self.uncovered += 1;
                }
            }
        } else {
            self.x[j] = true;
            self.cost += inst.cost(j);
            for &r in &inst.colrows[j] {
                if self.cnt[r] == 0 {
                    self.uncovered -= 1;
                }
                self.cnt[r] += 1;
            }
        }
    }

    /// The change of `f` if column `j` were flipped.
    fn delta(&self, inst: &Inst, mu: f64, j: usize) -> f64 {
        if self.x[j] {
            let lost = inst.colrows[j].iter().filter(|&&r| self.cnt[r] == 1).count();
            -inst.cost(j) + mu * lost as f64
        } else {
            let won = inst.colrows[j].iter().filter(|&&r| self.cnt[r] == 0).count();
            inst.cost(j) - mu * won as f64
        }
    }
}

/// Best-improvement descent by flip moves on `T(x, k)` of eq. 7, with `x0`, `f(x1*) = fstar`;
/// `k = 0` (or `x0 = None`) is plain descent on `f`.
fn descend(inst: &Inst, p: &mut Point, mu: f64, x0: Option<&[bool]>, fstar: f64, k: f64) {
    let mut dist = x0.map_or(0, |x0| p.x.iter().zip(x0).filter(|(a, b)| a != b).count());
    let t = |f: f64, d: usize| {
        if x0.is_some() && f >= fstar {
            f + k * d as f64
        } else {
            f
        }
    };
    loop {
        let f = p.f(mu);
        let cur = t(f, dist);
        let mut best: Option<(f64, usize, usize)> = None;
        for j in 0..inst.n() {
            let nd = match x0 {
                Some(x0) if p.x[j] == x0[j] => dist + 1,
                Some(_) => dist - 1,
                None => 0,
            };
            let v = t(f + p.delta(inst, mu, j), nd);
            if v < cur - 1e-9 && best.is_none_or(|(bv, _, _)| v < bv) {
                best = Some((v, j, nd));
            }
        }
        let Some((_, j, nd)) = best else {
            return;
        };
        p.flip(inst, j);
        dist = nd;
    }
}

/// The penalty-function method of paper 000 (§3.2, eq. 6–7); see the [module](self)
/// documentation. Starts from the [`greedy`] cover, descends `f` by flips to a local minimiser
/// `x0 = x1*`, then for every round tries `tries` perturbations of `x0` (`strength` random
/// flips, half of them dropping a chosen column), each descended on the auxiliary function `T`.
/// A point better than `x1*` becomes the new `x0 = x1*` after descending `f`; if no try finds
/// one, the `f`-local minimiser reached from the last try becomes `x0` (worse, but `x1*` is
/// kept). The best cover is repaired (greedy completion, redundant columns dropped) if `μ` was
/// too small to force feasibility. Deterministic for a given seed.
///
/// # Panics
/// If a row is covered by no column or names a column out of range.
pub fn penalty_method(sc: &SetCover, params: &PenaltyParams) -> Cover {
    let inst = Inst::new(sc);
    if sc.rows == 0 || sc.columns == 0 {
        return inst.finish(Vec::new(), sc.rows == 0);
    }
    let maxc = sc.costs.iter().copied().fold(0.0, f64::max);
    let mu = params.mu.unwrap_or(maxc + 1.0);
    let k = params
        .k
        .unwrap_or(sc.costs.iter().sum::<f64>() / sc.columns as f64);
    let mut rng = Rng::new(params.seed);
    let mut p = Point {
        x: vec![false; sc.columns],
        cnt: vec![0; sc.rows],
        cost: 0.0,
        uncovered: sc.rows,
    };
    for j in inst.greedy_cover() {
        p.flip(&inst, j);
    }
    descend(&inst, &mut p, mu, None, 0.0, 0.0);
    let mut best = p.clone();
    let mut x0 = p;
    for _ in 0..params.rounds {
        let fstar = best.f(mu);
        let mut last = None;
        let mut improved = false;
        for _ in 0..params.tries.max(1) {
            let mut y = x0.clone();
            let chosen: Vec<usize> = (0..sc.columns).filter(|&j| y.x[j]).collect();
            for s in 0..params.strength {
                let j = if s % 2 == 0 && !chosen.is_empty() {
                    chosen[rng.below(chosen.len())]
                } else {
                    rng.below(sc.columns)
                };
                y.flip(&inst, j);
            }
            descend(&inst, &mut y, mu, Some(&x0.x), fstar, k);
            if y.f(mu) < fstar - 1e-9 {
                descend(&inst, &mut y, mu, None, 0.0, 0.0);
                best = y.clone();
                x0 = y;
                improved = true;
                break;
            }
            last = Some(y);
        }
        if let (false, Some(mut y)) = (improved, last) {
            descend(&inst, &mut y, mu, None, 0.0, 0.0);
            x0 = y;
        }
    }
    let mut chosen: Vec<usize> = (0..sc.columns).filter(|&j| best.x[j]).collect();
    let mut cnt = best.cnt;
    if best.uncovered > 0 {
        inst.complete(&|_| true, &mut chosen, &mut cnt);
    }
    inst.remove_redundant(&mut chosen, &mut cnt);
    inst.finish(chosen, false)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_instance(rng: &mut Rng, rows: usize, columns: usize, integer: bool) -> SetCover {
        let mut covers = Vec::new();
        for _ in 0..rows {
            let mut cols: Vec<usize> = (0..columns).filter(|_| rng.below(100) < 30).collect();
            if cols.is_empty() {
                cols.push(rng.below(columns));
            }
            covers.push(cols);
        }
        let costs = (0..columns)
            .map(|_| {
                if integer {
                    1.0 + rng.below(10) as f64
                } else {
                    0.5 + rng.below(1000) as f64 / 97.0
                }
            })
            .collect();
        SetCover {
            rows,
            columns,
            costs,
            covers,
        }
    }

    fn brute_force(sc: &SetCover) -> f64 {
        let mut best = f64::INFINITY;
        for mask in 0u32..(1 << sc.columns) {
            let chosen: Vec<usize> = (0..sc.columns).filter(|&j| mask >> j & 1 == 1).collect();
            if let Ok(c) = sc.cover_cost(&chosen) {
                best = best.min(c);
            }
        }
        best
    }

    fn check(sc: &SetCover, c: &Cover) {
        assert!(c.columns.windows(2).all(|w| w[0] < w[1]), "{c:?}");
        assert_eq!(sc.cover_cost(&c.columns), Ok(c.cost), "{c:?}");
    }

    #[test]
    fn setcover_tiny_against_brute_force() {
        let mut rng = Rng::new(7);
        for case in 0..300 {
            let rows = 1 + rng.below(10);
            let columns = 1 + rng.below(12);
            let sc = random_instance(&mut rng, rows, columns, case % 2 == 0);
            let opt = brute_force(&sc);
            let e = exact(&sc, &ExactLimits::default());
            let g = greedy(&sc);
            let p = penalty_method(
                &sc,
                &PenaltyParams {
                    rounds: 20,
                    seed: case,
                    ..PenaltyParams::default()
                },
            );
            for c in [&e, &g, &p] {
                check(&sc, c);
            }
            assert!(e.proven_optimal, "case {case}");
            assert!((e.cost - opt).abs() < 1e-9, "case {case}: {} vs {opt}", e.cost);
            assert!(g.cost >= e.cost - 1e-9 && p.cost >= e.cost - 1e-9);
        }
    }

    #[test]
    fn setcover_forced_and_degenerate() {
        let sc = SetCover {
            rows: 0,
            columns: 2,
            costs: vec![1.0, 1.0],
            covers: vec![],
        };
        for c in [
            exact(&sc, &ExactLimits::default()),
            greedy(&sc),
            penalty_method(&sc, &PenaltyParams::default()),
        ] {
            assert!(c.columns.is_empty() && c.cost == 0.0);
        }
        // Row 0 only by column 2 (expensive) forces it; it also covers row 1.
        let sc = SetCover {
            rows: 3,
            columns: 3,
            costs: vec![1.0, 1.0, 5.0],
            covers: vec![vec![2], vec![0, 2], vec![1]],
        };
        let e = exact(&sc, &ExactLimits::default());
        assert_eq!(
            (e.columns.clone(), e.cost, e.proven_optimal),
            (vec![1, 2], 6.0, true)
        );
        assert_eq!(greedy(&sc).cost, 6.0);
        assert_eq!(penalty_method(&sc, &PenaltyParams::default()).cost, 6.0);
    }

    #[test]
    #[should_panic(expected = "covered by no column")]
    fn setcover_infeasible_panics() {
        let sc = SetCover {
            rows: 1,
            columns: 1,
            costs: vec![1.0],
            covers: vec![vec![]],
        };
        greedy(&sc);
    }

    fn orlib(name: &str) -> SetCover {
        let path = format!(
            "{}/../../data/benchmarks/orlib-setcover/{name}.txt",
            env!("CARGO_MANIFEST_DIR")
        );
        crate::io::read_orlib_setcover(path).unwrap()
    }

    #[test]
    fn setcover_node_limit_is_deterministic() {
        let sc = orlib("scp41");
        let limits = ExactLimits {
            time_limit: None,
            max_nodes: Some(3),
        };
        let a = exact(&sc, &limits);
        let b = exact(&sc, &limits);
        assert_eq!(a, b);
        check(&sc, &a);
        let g = greedy(&sc);
        check(&sc, &g);
        assert!(g.cost >= 429.0 && a.cost >= 429.0 && a.cost <= g.cost);
        let p = penalty_method(
            &sc,
            &PenaltyParams {
                rounds: 20,
                ..PenaltyParams::default()
            },
        );
        check(&sc, &p);
        assert!(p.cost >= 429.0 && p.cost <= g.cost);
    }

    #[test]
    fn setcover_exact_proves_scp41() {
        let sc = orlib("scp41");
        let e = exact(
            &sc,
            &ExactLimits {
                time_limit: None,
                max_nodes: None,
            },
        );
        check(&sc, &e);
        assert_eq!((e.cost, e.proven_optimal), (429.0, true));
    }
}

//! The two sequencers of paper 002's Table 2 on one GTSP graph (home and every alternative):
//!
//! - [`Sequencer::TravelTime`] ("old", the paper's "approximate travel time minimization"): the
//!   order and alternatives that minimise the straight moves' times at the joints' speed and
//!   acceleration limits, then each leg of that tour optimised by the OCP (an edge without a
//!   collision-free path barred and the tour re-sequenced);
//! - [`Sequencer::OptimalControl`] ("new", §2.1): node cost = holding the alternative for the
//!   weld time, edge cost = J of the leg's OCP; lazy — first the legs of the tour on
//!   travel-time bounds with the node costs (a complete cycle, solved), then from the paper's
//!   estimates (the best J of a straight move whose effort is the static one at its ends,
//!   scaled by the solved legs' median J/estimate), solve the OCPs of the edges the tour uses,
//!   re-sequence until every edge of the tour is solved, or the OCP budget ends (then the
//!   current tour's remaining edges are solved and the outcome says so); the result is the
//!   cheapest fully solved tour met on the way (round 0's included).
//!
//! Legs are symmetric (the dynamics have no friction and the midpoint rule is symmetric, so a
//! DMOC trajectory run backwards with its torques reversed in order solves the reverse move
//! with the same J): one solve serves both directions.
use crate::alternatives::Alternatives;
use crate::cell::WeldCell;
use crate::leg::{self, Leg, LegSettings, Motion};
use cellplan_solve::{CostMatrix, Gtsp, GtspParams, held_karp};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Which sequencer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Sequencer {
    /// Paper 002's "old" sequence: travel time, then each leg optimised.
    TravelTime,
    /// Paper 002's "new" sequence: optimal-control costs in the GTSP.
    OptimalControl,
}

impl Sequencer {
    /// Stable name.
    pub fn name(self) -> &'static str {
        match self {
            Sequencer::TravelTime => "travel-time",
            Sequencer::OptimalControl => "optimal-control",
        }
    }
}

/// The GTSP graph: node 0 is home, then every alternative.
pub struct Graph {
    /// Configurations of the nodes.
    pub q: Vec<Vec<f64>>,
    /// `(stud, index among its alternatives)` of each node (`None` for home).
    pub of: Vec<Option<(usize, usize)>>,
    /// Node (weld) cost.
    pub weld_cost: Vec<f64>,
    /// The clusters: nodes of each weldable stud.
    pub clusters: Vec<Vec<usize>>,
}

impl Graph {
    /// Home and the alternatives.
    pub fn new(w: &WeldCell, alts: &Alternatives) -> Self {
        let mut g = Graph {
            q: vec![w.robot.home.clone()],
            of: vec![None],
            weld_cost: vec![0.0],
            clusters: Vec::new(),
        };
        for (stud, list) in alts.per_stud.iter().enumerate() {
            if list.is_empty() {
                continue;
            }
            let mut cluster = Vec::new();
            for (k, a) in list.iter().enumerate() {
                cluster.push(g.q.len());
                g.q.push(a.q.clone());
                g.of.push(Some((stud, k)));
                g.weld_cost.push(a.weld_cost);
            }
            g.clusters.push(cluster);
        }
        g
    }
}

/// Solved legs and planned paths shared between sequencers, by unordered node pair.
#[derive(Default)]
pub struct Cache {
    /// OCP legs (`None`: no collision-free path).
    pub legs: BTreeMap<(usize, usize), Option<Leg>>,
    /// OCPs solved.
    pub solves: usize,
}

fn key(a: usize, b: usize) -> (usize, usize) {
    (a.min(b), a.max(b))
}

/// The leg `a → b` from a leg solved for `key(a, b)`: reversed when `a > b`.
pub fn oriented(leg: &Leg, reverse: bool) -> Leg {
    let mut l = leg.clone();
    if reverse {
        match &mut l.motion {
            Motion::Ocp(d) => {
                d.q.reverse();
                d.u.reverse();
            }
            Motion::TimedPath { waypoints, .. } => waypoints.reverse(),
        }
    }
    l
}

/// A sequence: the tour's nodes (home excluded) and how it was found.
#[derive(Clone, Debug)]
pub struct Sequence {
    /// Visited nodes in order.
    pub nodes: Vec<usize>,
    /// Sequencing rounds.
    pub rounds: usize,
    /// Whether the lazy loop ended with every edge of the tour solved before the budget ran
    /// out.
    pub converged: bool,
    /// Whether the GTSP was solved exactly (Held–Karp) in every round.
    pub exact: bool,
    /// Optimal control: J / estimate over the solved legs (least, median, largest) at the
    /// end; the median scales the estimates of the unsolved edges.
    pub estimate_ratio: Option<[f64; 3]>,
}

/// Most DP states for the exact solver; beyond, the iterated local search.
pub const EXACT_STATES: u128 = 4_000_000;

/// Kicks of the iterated local search per GTSP (beyond [`EXACT_STATES`]).
pub const ILS_KICKS: usize = 100;

/// Whether to print the lazy rounds and the trust-region steps to stderr
/// (`CELLPLAN_STUDWELD_VERBOSE`).
pub(crate) fn verbose() -> bool {
    std::env::var_os("CELLPLAN_STUDWELD_VERBOSE").is_some()
}

/// Solves the GTSP on `costs` with `service` (start and end at home).
fn tour(g: &Graph, costs: &[Vec<f64>], service: &[f64], seed: u64) -> (Vec<usize>, bool) {
    let started = std::time::Instant::now();
    let out = tour_inner(g, costs, service, seed);
    if verbose() {
        eprintln!(
            "  gtsp: {:.2} s (exact: {})",
            started.elapsed().as_secs_f64(),
            out.1
        );
    }
    out
}

fn tour_inner(g: &Graph, costs: &[Vec<f64>], service: &[f64], seed: u64) -> (Vec<usize>, bool) {
    let n = g.q.len();
    let m = CostMatrix::from_fn(n, |i, j| costs[i][j]);
    let p = Gtsp::new(m, g.clusters.clone())
        .and_then(|p| p.with_depots(Some(0), None))
        .and_then(|p| p.with_service(service.to_vec()))
        .expect("the graph's clusters are disjoint and non-empty, service finite");
    if held_karp::states_needed(&p) <= EXACT_STATES
        && let Ok(e) = held_karp::solve(&p, held_karp::HeldKarpLimits::default())
    {
        return (e.tour.nodes, true);
    }
    let params = GtspParams {
        seed,
        max_iterations: Some(ILS_KICKS),
        time_limit: std::time::Duration::from_secs(600),
        ..GtspParams::default()
    };
    (cellplan_solve::gtsp::solve(&p, &params).tour.nodes, false)
}

/// The tour's edges, home to home.
pub fn edges(nodes: &[usize]) -> Vec<(usize, usize)> {
    let mut all = vec![0];
    all.extend_from_slice(nodes);
    all.push(0);
    all.windows(2).map(|w| (w[0], w[1])).collect()
}

/// The paper's estimate of an edge's J: the least `c_t T + c_v |Δq|²/T + c_e T ḡ` over
/// `T ≥ T_min` (the straight move at constant speed, its effort the mean of the squared gravity
/// torques at the ends, `T_min` the slowest joint's least time). Not a strict bound.
pub fn estimate(w: &WeldCell, a: &[f64], b: &[f64]) -> f64 {
    let wt = w.process.weights;
    let g2 = |q: &[f64]| w.dynamics.gravity_torques(q).iter().map(|v| v * v).sum::<f64>();
    let gbar = 0.5 * (g2(a) + g2(b));
    let d2: f64 = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum();
    let tmin = a
        .iter()
        .zip(b)
        .zip(&w.v_max)
        .map(|((x, y), v)| (x - y).abs() / v)
        .fold(0.0, f64::max);
    let rate = wt.time + wt.effort * gbar;
    let t = (wt.velocity * d2 / rate).sqrt().max(tmin);
    if t <= 0.0 {
        0.0
    } else {
        rate * t + wt.velocity * d2 / t
    }
}

/// The travel-time lower bound of an edge: the straight move at the joints' speed and
/// acceleration limits, each joint its own trapezoid.
fn travel_bound(w: &WeldCell, a: &[f64], b: &[f64]) -> f64 {
    let limits = cellplan_motion::timing::Limits {
        velocity: w.v_max.clone(),
        acceleration: w.robot.max_acceleration.clone(),
    };
    cellplan_motion::timing::move_time(a, b, &limits)
}

/// `f` of every ordered pair of the graph's configurations (rows in parallel).
fn pairwise(g: &Graph, f: impl Fn(&[f64], &[f64]) -> f64 + Sync) -> Vec<Vec<f64>> {
    g.q.par_iter()
        .map(|a| g.q.iter().map(|b| f(a, b)).collect())
        .collect()
}

/// Solves the legs of `pairs` (not yet in the cache) in parallel, into the cache.
pub fn solve_legs(w: &WeldCell, g: &Graph, pairs: &[(usize, usize)], s: &LegSettings, cache: &mut Cache) {
    let mut todo: Vec<(usize, usize)> = pairs
        .iter()
        .map(|&(a, b)| key(a, b))
        .filter(|k| !cache.legs.contains_key(k))
        .collect();
    todo.sort();
    todo.dedup();
    let solved: Vec<((usize, usize), Option<Leg>)> = todo
        .par_iter()
        .map(|&(a, b)| ((a, b), leg::solve(w, &g.q[a], &g.q[b], s)))
        .collect();
    for (k, l) in solved {
        cache.solves += l.as_ref().map_or(0, |l| l.solves);
        cache.legs.insert(k, l);
    }
}

/// The leg `a → b` from the cache.
pub fn cached_leg(cache: &Cache, a: usize, b: usize) -> Option<Leg> {
    let l = cache.legs.get(&key(a, b))?.as_ref()?;
    Some(oriented(l, a > b))
}

/// The calibration of the estimates by the solved legs: the median of J / estimate (1 before
/// any leg is solved), and (least, median, largest). The paper's estimates (static effort at
/// the ends) leave out the effort of accelerating the arm; scaling them by what the solved legs
/// show keeps them estimates, not bounds, and lets the lazy loop close in far fewer rounds.
pub fn calibration(cache: &Cache, est: &[Vec<f64>]) -> (f64, [f64; 3]) {
    let mut r: Vec<f64> = cache
        .legs
        .iter()
        .filter_map(|(&(a, b), l)| {
            let l = l.as_ref()?;
            (est[a][b] > 0.0).then(|| l.cost / est[a][b])
        })
        .collect();
    if r.is_empty() {
        return (1.0, [1.0; 3]);
    }
    r.sort_by(f64::total_cmp);
    let med = r[r.len() / 2];
    (med.max(1.0), [r[0], med, r[r.len() - 1]])
}

/// J of the tour `nodes` when every edge of it is solved: Σ legs + Σ node costs.
fn solved_cost(g: &Graph, cache: &Cache, nodes: &[usize]) -> Option<f64> {
    let travel: Option<f64> = edges(nodes)
        .iter()
        .map(|&(a, b)| cache.legs.get(&key(a, b))?.as_ref().map(|l| l.cost))
        .sum();
    Some(travel? + nodes.iter().map(|&v| g.weld_cost[v]).sum::<f64>())
}

/// The better of the lazy loop's last tour and the best fully solved tour it met before (the
/// estimates are not bounds, so a later round can end dearer than an earlier one).
fn best_of(g: &Graph, cache: &Cache, nodes: Vec<usize>, best: &Option<(f64, Vec<usize>)>) -> Vec<usize> {
    match (solved_cost(g, cache, &nodes), best) {
        (Some(c), Some((b, bn))) if *b < c => bn.clone(),
        (None, Some((_, bn))) => bn.clone(),
        _ => nodes,
    }
}

/// Sequences on optimal-control costs (lazy), solving the legs it needs into `cache`.
pub fn optimal_control(w: &WeldCell, g: &Graph, s: &LegSettings, cache: &mut Cache) -> Sequence {
    let n = g.q.len();
    let est = pairwise(g, |a, b| estimate(w, a, b));
    // Round 0: the tour on travel-time bounds (straight moves at the joints' limits) with the
    // node costs — its legs, solved, are a complete cycle whose J the loop can only improve on,
    // and the first calibration of the estimates.
    let bound = pairwise(g, |a, b| travel_bound(w, a, b));
    let (first, ex) = tour(g, &bound, &g.weld_cost, s.seed);
    let mut exact = ex;
    solve_legs(w, g, &edges(&first), s, cache);
    let mut best = solved_cost(g, cache, &first).map(|c| (c, first));
    let mut rounds = 0;
    loop {
        rounds += 1;
        let ratio = calibration(cache, &est);
        let costs: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| match cache.legs.get(&key(i, j)) {
                        Some(Some(l)) => l.cost,
                        Some(None) => 1e12,
                        None => ratio.0 * est[i][j],
                    })
                    .collect()
            })
            .collect();
        let (nodes, ex) = tour(g, &costs, &g.weld_cost, s.seed);
        exact &= ex;
        let open: Vec<(usize, usize)> = edges(&nodes)
            .into_iter()
            .filter(|&(a, b)| !cache.legs.contains_key(&key(a, b)))
            .collect();
        if open.is_empty() {
            return Sequence {
                nodes: best_of(g, cache, nodes, &best),
                rounds,
                converged: true,
                exact,
                estimate_ratio: Some(ratio.1),
            };
        }
        let over = cache.solves >= w.process.ocp_budget;
        let started = std::time::Instant::now();
        solve_legs(w, g, &open, s, cache);
        if verbose() {
            eprintln!(
                "optimal-control round {rounds}: {} legs solved in {:.1} s ({} OCPs so far, estimate × {:.2})",
                open.len(),
                started.elapsed().as_secs_f64(),
                cache.solves,
                ratio.0
            );
        }
        if let Some(c) = solved_cost(g, cache, &nodes)
            && best.as_ref().is_none_or(|(b, _)| c < *b)
        {
            best = Some((c, nodes.clone()));
        }
        if over {
            return Sequence {
                nodes: best_of(g, cache, nodes, &best),
                rounds,
                converged: false,
                exact,
                estimate_ratio: Some(calibration(cache, &est).1),
            };
        }
    }
}

/// Sequences on approximate travel time (the paper's old sequencer): the straight move at the
/// joints' speed and acceleration limits per edge, the weld time per node; then solves the
/// tour's legs (planner path, OCP). An edge whose move has no collision-free path is barred and
/// the tour re-sequenced.
pub fn travel_time(w: &WeldCell, g: &Graph, s: &LegSettings, cache: &mut Cache) -> Sequence {
    let n = g.q.len();
    let bound = pairwise(g, |a, b| travel_bound(w, a, b));
    let service: Vec<f64> = (0..n)
        .map(|i| if i == 0 { 0.0 } else { w.process.weld_time })
        .collect();
    let mut rounds = 0;
    let mut exact = true;
    loop {
        rounds += 1;
        let costs: Vec<Vec<f64>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| match cache.legs.get(&key(i, j)) {
                        Some(None) => 1e12,
                        _ => bound[i][j],
                    })
                    .collect()
            })
            .collect();
        let (nodes, ex) = tour(g, &costs, &service, s.seed);
        exact &= ex;
        let tour_edges = edges(&nodes);
        solve_legs(w, g, &tour_edges, s, cache);
        let barred = tour_edges
            .iter()
            .any(|&(a, b)| matches!(cache.legs.get(&key(a, b)), Some(None)));
        if !barred || rounds >= n {
            return Sequence {
                nodes,
                rounds,
                converged: !barred,
                exact,
                estimate_ratio: None,
            };
        }
    }
}

//! Collision-free joint-space path planning, arranged as OMPL arranges it: a state space
//! ([`JointSpace`]), a validity checker ([`StateValidity`]), a motion validator
//! ([`check_segment`]) and planners behind one interface ([`Planner`]: [`Straight`],
//! [`RrtConnect`]), plus path post-processing ([`shortcut`]) and the usual recipe for one leg
//! ([`plan_leg`]: the straight segment if clear, else RRT-Connect, shortcut and smoothed).
//!
//! # Why no contact is missed between samples
//!
//! A [`StateValidity`] returns a *clearance* `c(q)`: a lower bound on how far every point of
//! every moving body may move (in Cartesian space) before the state can become invalid (for a
//! robot: distance to obstacles minus the margin, self distances halved because both bodies
//! move). A [`JointSpace`] carries per-joint radii such that along a straight joint-space
//! segment from `a` to `b` no point moves more than `Σ_j radii[j]·|a_j − b_j|`. So around a
//! sample at parameter `s` of a segment whose whole bound is `L`, every parameter `s'` with
//! `|s' − s|·L < c(q(s))` is valid: [`check_segment`] covers the segment with such intervals,
//! placing each new sample where its interval should about touch the covered part, until no
//! gap is left. Samples therefore crowd near obstacles and spread in free space; a clearance below
//! [`PlanSettings::min_clearance`] counts as a contact (so the check always ends). A checker
//! may split its clearance by the joints that can reduce each part
//! ([`StateValidity::clearances`]): the step is then the smallest `c_k / L_k`, `L_k` summing
//! only over the joints of part `k`.
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::ops::Range;
use std::time::{Duration, Instant};
use thiserror::Error;

/// Steps are shortened by this factor so that a step never reaches the clearance exactly.
const STEP_SAFETY: f64 = 0.999;

/// A box of joint values with what the motion check and the metric need.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpace {
    /// Lower joint limits (rad or m).
    pub lower: Vec<f64>,
    /// Upper joint limits (rad or m).
    pub upper: Vec<f64>,
    /// Cartesian displacement bound per joint: along the straight segment from `a` to `b`
    /// every point of every moving body moves at most `Σ_j radii[j]·|a_j − b_j|` (m). For a
    /// revolute joint, at least the largest distance from its axis of any point it carries;
    /// 1 for a prismatic joint.
    pub radii: Vec<f64>,
    /// Metric weights for nearest neighbours, steering and path length: the distance is
    /// `sqrt(Σ_j (weights[j]·(a_j − b_j))²)`. `1/v_max` makes it time-like.
    pub weights: Vec<f64>,
}

impl JointSpace {
    /// A space with unit metric weights.
    pub fn new(lower: Vec<f64>, upper: Vec<f64>, radii: Vec<f64>) -> Self {
        let weights = vec![1.0; lower.len()];
        JointSpace {
            lower,
            upper,
            radii,
            weights,
        }
    }

    /// The same space with other metric weights (one per joint).
    pub fn with_weights(mut self, weights: Vec<f64>) -> Self {
        self.weights = weights;
        self
    }

    /// Number of joints.
    pub fn dim(&self) -> usize {
        self.lower.len()
    }

    /// Whether `q` has one finite value per joint, each within its limits (tolerance 1e-9).
    pub fn contains(&self, q: &[f64]) -> bool {
        q.len() == self.dim()
            && q.iter()
                .zip(self.lower.iter().zip(&self.upper))
                .all(|(&v, (&lo, &hi))| v.is_finite() && v >= lo - 1e-9 && v <= hi + 1e-9)
    }

    /// Bound on the Cartesian displacement of any body point along the segment `a → b`:
    /// `Σ_j radii[j]·|a_j − b_j|`.
    pub fn cartesian_bound(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.radii)
            .map(|((x, y), r)| r * (x - y).abs())
            .sum()
    }

    /// Weighted Euclidean distance `sqrt(Σ_j (weights[j]·(a_j − b_j))²)`.
    pub fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.weights)
            .map(|((x, y), w)| {
                let d = w * (x - y);
                d * d
            })
            .sum::<f64>()
            .sqrt()
    }

    /// `a + t·(b − a)` into `out`.
    pub fn interpolate(&self, a: &[f64], b: &[f64], t: f64, out: &mut Vec<f64>) {
        out.clear();
        out.extend(a.iter().zip(b).map(|(x, y)| x + t * (y - x)));
    }

    /// The distance between opposite corners of the box.
    pub fn extent(&self) -> f64 {
        self.distance(&self.lower, &self.upper)
    }

    fn sample(&self, rng: &mut ChaCha8Rng, out: &mut Vec<f64>) {
        out.clear();
        out.extend(
            self.lower.iter().zip(&self.upper).map(
                |(&lo, &hi)| {
                    if hi > lo { rng.random_range(lo..hi) } else { lo }
                },
            ),
        );
    }
}

/// One clearance with the joints whose motion can reduce it (see
/// [`StateValidity::clearances`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Clearance {
    /// How far (m) the points involved may move relative to each other; `<= 0`: invalid.
    pub distance: f64,
    /// The joints (indices, clipped to the space) whose motion can reduce it: along a segment
    /// the points involved move relative to each other by at most
    /// `Σ_{j in joints} radii[j]·|Δq_j|`.
    pub joints: Range<usize>,
}

/// Whether a configuration is valid, as a clearance.
pub trait StateValidity: Sync {
    /// A lower bound on how far (m) every point of every moving body may move from its place
    /// at `q` before the state can become invalid: the distance to every obstacle (static
    /// scene and checked self pairs) minus the required margin. `<= 0` (or NaN) means invalid.
    /// Implementations may cap the value (return `min(d, cap)`) for speed: a smaller value is
    /// always safe.
    fn clearance(&self, q: &[f64]) -> f64;

    /// The same, finer: several clearances into `out` (cleared first), each with the range of
    /// joints that can reduce it — on a serial chain, a body on link `k` is moved only by
    /// joints up to `k`, and two bodies of the chain move relative to each other only by the
    /// joints between them. The segment check steps by the smallest `distance / bound over
    /// joints`, which allows long steps when the only tight clearance is one that few joints
    /// change (a tool near the wrist it hangs on). The smallest distance must not exceed
    /// [`StateValidity::clearance`]. Default: that one clearance, over every joint.
    fn clearances(&self, q: &[f64], out: &mut Vec<Clearance>) {
        out.clear();
        out.push(Clearance {
            distance: self.clearance(q),
            joints: 0..usize::MAX,
        });
    }

    /// The radius, in segment parameter, of the piece of a segment around `q` proven valid:
    /// `min_k distance_k / bound(joints_k)` over [`StateValidity::clearances`], at most
    /// `limit`; `None` when some distance is below `floor` (or NaN). `bound(joints)` is the
    /// Cartesian displacement bound of those joints over the whole segment (0 when they do not
    /// move). The segment check calls this; an implementation may override it to skip work
    /// the answer does not need — a distance query capped at `step · bound` (the step found so
    /// far) answers as well as an exact one. The result must not exceed the default's.
    fn segment_step(
        &self,
        q: &[f64],
        bound: &dyn Fn(&Range<usize>) -> f64,
        floor: f64,
        limit: f64,
    ) -> Option<f64> {
        // One buffer per thread, taken out while in use (so a nested call gets its own).
        thread_local! {
            static BUF: std::cell::Cell<Vec<Clearance>> = const { std::cell::Cell::new(Vec::new()) };
        }
        let mut buf = BUF.take();
        self.clearances(q, &mut buf);
        let step = buf.iter().try_fold(limit, |step, c| {
            narrow_step(step, c.distance, bound(&c.joints), floor)
        });
        BUF.set(buf);
        step
    }
}

/// One part's say in [`StateValidity::segment_step`]: `None` when its clearance `distance` is
/// below `floor` (or NaN), else `step` shortened to `distance / bound` if that is shorter
/// (a part whose joints do not move, `bound` 0, only has to be valid).
pub fn narrow_step(step: f64, distance: f64, bound: f64, floor: f64) -> Option<f64> {
    // NaN fails the comparison and so counts as a contact.
    if distance.is_nan() || distance < floor {
        return None;
    }
    Some(if bound > 0.0 {
        step.min(distance / bound)
    } else {
        step
    })
}

/// A plain function or closure of `q` is a validity checker (its value is the clearance).
impl<F: Fn(&[f64]) -> f64 + Sync> StateValidity for F {
    fn clearance(&self, q: &[f64]) -> f64 {
        self(q)
    }
}

/// The outcome of [`check_segment`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SegmentCheck {
    /// Whether the whole straight segment is valid.
    pub valid: bool,
    /// Calls of [`StateValidity::clearance`] made.
    pub calls: usize,
}

/// Conservative check of the straight joint-space segment `a → b`: valid only when every
/// configuration on it is proven valid (see the module documentation). A clearance below
/// `min_clearance` (clamped to at least 1e-9) counts as invalid.
pub fn check_segment(
    space: &JointSpace,
    validity: &dyn StateValidity,
    a: &[f64],
    b: &[f64],
    min_clearance: f64,
) -> SegmentCheck {
    let mut calls = 0;
    let valid = segment_valid(space, validity, a, b, min_clearance, &mut calls);
    SegmentCheck { valid, calls }
}

/// The check of [`check_segment`]; counts the clearance calls into `calls`.
///
/// The segment is covered by parameter intervals proven valid, one around each sample (its
/// radius from [`StateValidity::segment_step`]). Gaps between covered pieces are kept in a
/// first-in first-out list; a gap wider than two of its ends' radii is entered one radius
/// past its left end (where, the radius being 1-Lipschitz in the parameter, the new ball
/// about touches the covered piece: each sample covers about twice its radius, where a walk
/// would cover one), a narrower gap is sampled in its middle. The check ends at the first
/// contact or when no gap is left.
fn segment_valid(
    space: &JointSpace,
    validity: &dyn StateValidity,
    a: &[f64],
    b: &[f64],
    min_clearance: f64,
    calls: &mut usize,
) -> bool {
    let floor = min_clearance.max(1e-9);
    let n = space.dim().min(a.len()).min(b.len());
    // Bound of each joint over the whole segment, and prefix sums for the ranges.
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for j in 0..n {
        let r = space.radii.get(j).copied().unwrap_or(f64::INFINITY);
        let d = (a[j] - b[j]).abs();
        let term = if d == 0.0 { 0.0 } else { r * d };
        prefix.push(prefix[j] + term);
    }
    if !prefix[n].is_finite() {
        return false;
    }
    let bound = |joints: &Range<usize>| {
        let (lo, hi) = (joints.start.min(n), joints.end.min(n));
        if hi > lo { prefix[hi] - prefix[lo] } else { 0.0 }
    };
    let mut measure = |q: &[f64], limit: f64| -> Option<f64> {
        *calls += 1;
        validity
            .segment_step(q, &bound, floor, limit)
            .map(|r| r * STEP_SAFETY)
    };
    let Some(ra) = measure(a, 1.0) else {
        return false;
    };
    let Some(rb) = measure(b, 1.0) else {
        return false;
    };
    // Gaps (left end, its radius, right end, its radius).
    let mut gaps = std::collections::VecDeque::from([(0.0, ra, 1.0, rb)]);
    let mut q = Vec::with_capacity(n);
    while let Some((s0, r0, s1, r1)) = gaps.pop_front() {
        let (lo, hi) = (s0 + r0, s1 - r1);
        if lo >= hi {
            continue;
        }
        let guess = r0.min(r1);
        let s = if hi - lo <= 2.0 * guess {
            0.5 * (lo + hi)
        } else {
            lo + guess
        };
        space.interpolate(a, b, s, &mut q);
        // A radius beyond the farther end of the gap is of no use.
        let Some(r) = measure(&q, (s - s0).max(s1 - s)) else {
            return false;
        };
        gaps.push_back((s0, r0, s, r));
        gaps.push_back((s, r, s1, r1));
    }
    true
}

/// Limits and knobs of a planning query.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanSettings {
    /// Seed of the planner's random numbers (same seed, same path, unless the time limit
    /// stops the search first).
    pub seed: u64,
    /// Wall-clock limit of the search.
    pub time_limit: Duration,
    /// Most random samples a sampling planner draws.
    pub max_samples: usize,
    /// Longest tree edge, in the space's metric; 0 or less: a fifth of the space's
    /// [`JointSpace::extent`] (OMPL's default).
    pub range: f64,
    /// Clearances below this (m) count as contact, so that checks end.
    pub min_clearance: f64,
    /// Random shortcut attempts after a sampling planner.
    pub shortcut_iterations: usize,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            seed: 0,
            time_limit: Duration::from_secs(5),
            max_samples: 20_000,
            range: 0.0,
            min_clearance: 1e-4,
            shortcut_iterations: 100,
        }
    }
}

/// A collision-free joint-space path: straight segments between waypoints.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedPath {
    /// From the start to the goal, inclusive.
    pub waypoints: Vec<Vec<f64>>,
    /// Whether it is the direct segment (two waypoints, no search).
    pub straight: bool,
    /// Random samples drawn.
    pub samples: usize,
    /// Calls of [`StateValidity::clearance`] made (checks, search and post-processing).
    pub validity_calls: usize,
}

impl PlannedPath {
    /// Length in the space's metric.
    pub fn length(&self, space: &JointSpace) -> f64 {
        path_length(space, &self.waypoints)
    }
}

/// Why no path.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum PlanError {
    /// The start is outside the space or invalid.
    #[error("the start configuration is invalid (clearance {clearance} m)")]
    StartInvalid {
        /// Its clearance (negative infinity outside the joint limits).
        clearance: f64,
    },
    /// The goal is outside the space or invalid.
    #[error("the goal configuration is invalid (clearance {clearance} m)")]
    GoalInvalid {
        /// Its clearance (negative infinity outside the joint limits).
        clearance: f64,
    },
    /// The planner gave up.
    #[error("no path found within the limits ({samples} samples, {validity_calls} validity calls)")]
    NoPath {
        /// Random samples drawn.
        samples: usize,
        /// Validity calls made.
        validity_calls: usize,
    },
}

/// A path planner between two configurations (OMPL's `Planner`): implementations are
/// interchangeable behind this trait, for benchmarks.
pub trait Planner {
    /// Short name, for reports.
    fn name(&self) -> &str;
    /// A path from `start` to `goal` whose every segment passes [`check_segment`].
    fn plan(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        settings: &PlanSettings,
    ) -> Result<PlannedPath, PlanError>;
}

/// Checks both ends (two clearance calls).
fn check_ends(
    space: &JointSpace,
    validity: &dyn StateValidity,
    start: &[f64],
    goal: &[f64],
    settings: &PlanSettings,
) -> Result<(), PlanError> {
    let floor = settings.min_clearance.max(1e-9);
    let measure = |q: &[f64]| {
        if space.contains(q) {
            validity.clearance(q)
        } else {
            f64::NEG_INFINITY
        }
    };
    let cs = measure(start);
    if cs.is_nan() || cs < floor {
        return Err(PlanError::StartInvalid { clearance: cs });
    }
    let cg = measure(goal);
    if cg.is_nan() || cg < floor {
        return Err(PlanError::GoalInvalid { clearance: cg });
    }
    Ok(())
}

/// Only the direct segment.
#[derive(Clone, Copy, Debug, Default)]
pub struct Straight;

impl Planner for Straight {
    fn name(&self) -> &str {
        "straight"
    }

    fn plan(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        settings: &PlanSettings,
    ) -> Result<PlannedPath, PlanError> {
        check_ends(space, validity, start, goal, settings)?;
        let mut calls = 2;
        let ok = segment_valid(space, validity, start, goal, settings.min_clearance, &mut calls);
        if ok {
            Ok(PlannedPath {
                waypoints: vec![start.to_vec(), goal.to_vec()],
                straight: true,
                samples: 0,
                validity_calls: calls,
            })
        } else {
            Err(PlanError::NoPath {
                samples: 0,
                validity_calls: calls,
            })
        }
    }
}

/// RRT-Connect (Kuffner & LaValle 2000): two trees, rooted at the start and the goal, grown in
/// turn towards random samples; after each extension the other tree greedily connects to the
/// new node. Every edge passes [`check_segment`]. Deterministic for a seed (ChaCha8).
#[derive(Clone, Copy, Debug, Default)]
pub struct RrtConnect;

struct Tree {
    nodes: Vec<Vec<f64>>,
    parent: Vec<usize>,
}

impl Tree {
    fn new(root: &[f64]) -> Self {
        Tree {
            nodes: vec![root.to_vec()],
            parent: vec![usize::MAX],
        }
    }

    fn nearest(&self, space: &JointSpace, q: &[f64]) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = space.distance(n, q);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// Root-to-node path.
    fn path_to(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        while i != usize::MAX {
            out.push(self.nodes[i].clone());
            i = self.parent[i];
        }
        out.reverse();
        out
    }
}

enum Extend {
    Trapped,
    Advanced(usize),
    Reached(usize),
}

struct Search<'a> {
    space: &'a JointSpace,
    validity: &'a dyn StateValidity,
    range: f64,
    min_clearance: f64,
    calls: usize,
}

impl Search<'_> {
    /// One RRT extension of `tree` from node `from` towards `target`.
    fn extend_from(&mut self, tree: &mut Tree, from: usize, target: &[f64]) -> Extend {
        let near = &tree.nodes[from];
        let d = self.space.distance(near, target);
        let (q_new, reached) = if d <= self.range {
            (target.to_vec(), true)
        } else {
            let mut q = Vec::new();
            self.space.interpolate(near, target, self.range / d, &mut q);
            (q, false)
        };
        if !segment_valid(
            self.space,
            self.validity,
            near,
            &q_new,
            self.min_clearance,
            &mut self.calls,
        ) {
            return Extend::Trapped;
        }
        tree.nodes.push(q_new);
        tree.parent.push(from);
        let i = tree.nodes.len() - 1;
        if reached {
            Extend::Reached(i)
        } else {
            Extend::Advanced(i)
        }
    }

    fn extend(&mut self, tree: &mut Tree, target: &[f64]) -> Extend {
        let from = tree.nearest(self.space, target);
        self.extend_from(tree, from, target)
    }

    /// Extends `tree` towards `target` until it is reached or the tree is trapped.
    fn connect(&mut self, tree: &mut Tree, target: &[f64]) -> Option<usize> {
        let mut from = tree.nearest(self.space, target);
        loop {
            match self.extend_from(tree, from, target) {
                Extend::Trapped => return None,
                Extend::Reached(i) => return Some(i),
                Extend::Advanced(i) => from = i,
            }
        }
    }
}

impl Planner for RrtConnect {
    fn name(&self) -> &str {
        "rrt-connect"
    }

    fn plan(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        settings: &PlanSettings,
    ) -> Result<PlannedPath, PlanError> {
        let began = Instant::now();
        check_ends(space, validity, start, goal, settings)?;
        let range = if settings.range > 0.0 {
            settings.range
        } else {
            (0.2 * space.extent()).max(1e-6)
        };
        let mut search = Search {
            space,
            validity,
            range,
            min_clearance: settings.min_clearance,
            calls: 2,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        // trees[0] grows from the start, trees[1] from the goal; `a` is the one extended.
        let mut trees = [Tree::new(start), Tree::new(goal)];
        let mut a = 0;
        let mut samples = 0;
        let mut q_rand = Vec::with_capacity(space.dim());
        while samples < settings.max_samples && began.elapsed() < settings.time_limit {
            space.sample(&mut rng, &mut q_rand);
            samples += 1;
            let (ta, tb) = if a == 0 {
                let (x, y) = trees.split_at_mut(1);
                (&mut x[0], &mut y[0])
            } else {
                let (x, y) = trees.split_at_mut(1);
                (&mut y[0], &mut x[0])
            };
            let new = match search.extend(ta, &q_rand) {
                Extend::Trapped => None,
                Extend::Advanced(i) | Extend::Reached(i) => Some(i),
            };
            if let Some(i) = new {
                let target = ta.nodes[i].clone();
                if let Some(j) = search.connect(tb, &target) {
                    let (si, gi) = if a == 0 { (i, j) } else { (j, i) };
                    let mut waypoints = trees[0].path_to(si);
                    let mut back = trees[1].path_to(gi);
                    back.reverse();
                    // The meeting node is in both halves.
                    back.remove(0);
                    waypoints.extend(back);
                    return Ok(PlannedPath {
                        waypoints,
                        straight: false,
                        samples,
                        validity_calls: search.calls,
                    });
                }
            }
            a = 1 - a;
        }
        Err(PlanError::NoPath {
            samples,
            validity_calls: search.calls,
        })
    }
}

/// Length of a polyline in the space's metric.
pub fn path_length(space: &JointSpace, waypoints: &[Vec<f64>]) -> f64 {
    waypoints.windows(2).map(|w| space.distance(&w[0], &w[1])).sum()
}

/// Shortens a valid path in place and returns the validity calls made: removes repeated
/// waypoints, then `settings.shortcut_iterations` random shortcuts between two points on
/// different segments (partial shortcuts, deterministic for `settings.seed`), then removes
/// redundant waypoints (each waypoint whose neighbours see each other). A change is kept only
/// when the new segment passes [`check_segment`] and the path gets shorter, so the path never
/// lengthens (the metric is a norm) and stays valid.
pub fn shortcut(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    settings: &PlanSettings,
) -> usize {
    let mut calls = 0;
    waypoints.dedup_by(|b, a| space.distance(a, b) == 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(settings.seed ^ 0x5348_4f52_5443_5554);
    let (mut p1, mut p2) = (Vec::new(), Vec::new());
    for _ in 0..settings.shortcut_iterations {
        let segments = waypoints.len().saturating_sub(1);
        if segments < 2 {
            break;
        }
        let i = rng.random_range(0..segments);
        let j = rng.random_range(0..segments);
        let (i, j) = (i.min(j), i.max(j));
        if i == j {
            continue;
        }
        let (t1, t2): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        space.interpolate(&waypoints[i], &waypoints[i + 1], t1, &mut p1);
        space.interpolate(&waypoints[j], &waypoints[j + 1], t2, &mut p2);
        let old = space.distance(&p1, &waypoints[i + 1])
            + path_length(space, &waypoints[i + 1..=j])
            + space.distance(&waypoints[j], &p2);
        if space.distance(&p1, &p2) >= old - 1e-9 {
            continue;
        }
        let check = check_segment(space, validity, &p1, &p2, settings.min_clearance);
        calls += check.calls;
        if check.valid {
            // waypoints[..=i], p1, p2, waypoints[j+1..]
            let tail = waypoints.split_off(j + 1);
            waypoints.truncate(i + 1);
            waypoints.push(p1.clone());
            waypoints.push(p2.clone());
            waypoints.extend(tail);
            waypoints.dedup_by(|b, a| space.distance(a, b) <= 1e-12);
        }
    }
    calls += remove_redundant(space, validity, waypoints, settings.min_clearance);
    calls
}

/// Drops every waypoint whose neighbours see each other directly; returns the calls made.
fn remove_redundant(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    min_clearance: f64,
) -> usize {
    let mut calls = 0;
    let mut i = 0;
    while i + 2 < waypoints.len() {
        let check = check_segment(space, validity, &waypoints[i], &waypoints[i + 2], min_clearance);
        calls += check.calls;
        if check.valid {
            waypoints.remove(i + 1);
        } else {
            i += 1;
        }
    }
    calls
}

/// One leg: the straight segment if it is clear, else [`RrtConnect`] followed by
/// [`shortcut`]. The counts in the result add up every stage.
pub fn plan_leg(
    space: &JointSpace,
    validity: &dyn StateValidity,
    start: &[f64],
    goal: &[f64],
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    let straight_calls = match Straight.plan(space, validity, start, goal, settings) {
        Ok(path) => return Ok(path),
        Err(PlanError::NoPath { validity_calls, .. }) => validity_calls,
        Err(e) => return Err(e),
    };
    let mut path = match RrtConnect.plan(space, validity, start, goal, settings) {
        Ok(p) => p,
        Err(PlanError::NoPath {
            samples,
            validity_calls,
        }) => {
            return Err(PlanError::NoPath {
                samples,
                validity_calls: validity_calls + straight_calls,
            });
        }
        Err(e) => return Err(e),
    };
    path.validity_calls += straight_calls;
    path.validity_calls += shortcut(space, validity, &mut path.waypoints, settings);
    Ok(path)
}

#[cfg(test)]
mod tests;

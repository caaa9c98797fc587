//! A serial arm in a collision world: its joint space and its validity checker, the bridge
//! between geometry ([`cellplan_geom::CollisionWorld`]), kinematics ([`cellplan_kin::Chain`])
//! and the generic planners of [`crate::plan`].
//!
//! - [`Arm`]: the chain, where its root stands, its body group in the world and the chain link
//!   each body hangs on, and the self pairs to check.
//! - [`joint_radii`] and [`joint_space`]: limits, metric weights `1/v_max` (a time-like
//!   metric) and per-joint Cartesian radii that bound how far any body point moves.
//! - [`ArmValidity`]: the clearance of a configuration — joint limits, distance of the moving
//!   bodies to the static scene and to parked groups (minus the margin), distance of the
//!   checked self pairs — split by the joints that can reduce each part, with the sphere-cover
//!   broad phase of the world in front of every exact distance.
//!
//! # The broad phase
//!
//! A segment check asks each part only whether its clearance reaches `step · bound` (see
//! [`StateValidity::segment_step`]). The arm's [`BroadPhase`] gives a lower bound on every
//! distance from the bodies' sphere covers, object by object and pair by pair; where the bound
//! already reaches what is asked, that answer is proven and the exact (GJK) distance is
//! skipped. Only the objects and pairs whose bound falls short pay for the exact query, which
//! then decides. Bounds never exceed exact distances, so the guarantee of the segment check is
//! unchanged.
//!
//! # Each part's own motion bound
//!
//! The space's radii bound how far *any* point of the arm moves; a part's clearance only has
//! to outlast the motion of the points it involves. A body's clearance to the scene is reduced
//! by its own motion ([`Chain::body_radii`]: the forearm is not carried as far by the base
//! joint as the gripper is), and a self pair's by the motion of its distal body relative to
//! the proximal one, over the joints between them only. The segment check steps by these
//! tighter bounds ([`SegmentMotion::bound_with`]). On the MBM UR5, the upper arm's points lie
//! within 0.64 m and 0.50 m of the first two axes, where the whole arm's radii are 1.45 m and
//! 1.31 m. Two joints are bounded tighter still (`body_radii`, `pair_radii`): a body's
//! own joint, the last before its link, by its reach from that joint's axis, and a self pair's
//! first joint by the nearer body's reach from its axis — the base reaches 0.11 m from the
//! first axis, so the base/upper-arm pair, which cuts most steps short, allows longer ones
//! (`bench/motion/README.md`). Pairs proven apart everywhere are not checked at all
//! ([`apart_everywhere`]).
//!
//! # Bounds taken where the arm stands
//!
//! Those radii hold in every configuration, so they count every link stretched out. At a
//! sample the arm is posed: each joint's axis and each body's outer sphere are known, and the
//! body's points lie within the sphere's reach from the axis. A step of parameter length `t`
//! moves them by at most `t·(Σ_j ρ_j·|Δq_j| + t·E)`, `ρ_j` that reach and `E` how far the later
//! joints can carry the body away from the earlier axes over the whole segment (a constant of
//! the segment and the part; [`SegmentMotion::bound_at`], [`SegmentMotion::drift_with`]). A
//! segment step takes the smaller of the two bounds for each part it queries, after the query's
//! clusters and tables, so only parts that pay for a distance query pay for this bound too
//! (Schwarzer, Saha and Latombe's adaptive segment checking bounds motion the same way). On
//! the MBM UR5 it takes 11 % of the validity checks and 8.7 % of the planning instructions off
//! the same paths (`bench/motion/README.md`, twenty-fourth session).
use crate::plan::{Clearance, JointSpace, SegmentMotion, StateValidity};
use cellplan_geom::spheres::Sphere;
use cellplan_geom::{BroadPhase, CollisionWorld, DVec3, GroupId, PlacedCovers, Pose, Precision};
use cellplan_kin::Chain;
use std::cell::{Cell, RefCell};
use std::ops::Range;

mod apart;
mod clusters;
mod pose;
mod radii;
mod step;
#[cfg(test)]
mod tests;
mod turned;

pub use apart::{APART_BUDGET, apart_everywhere, pairs_that_may_touch};
use clusters::{Clusters, Settled};
pub use pose::tool_retract;
use radii::{PosedAxes, body_radii, moved_by, pair_radii};
pub use radii::{joint_radii, point_speed_weights};
pub use turned::{CLOSE, PROBES, PairTable, PairTables, pair_table};

/// Clearances are capped at this (m) by default: larger values only lengthen the steps of a
/// segment check a little, and the cap lets the distance queries skip everything further.
pub const DEFAULT_CLEARANCE_CAP: f64 = 0.25;

/// Taken off every measured distance (m), for rounding (the world's distances are certified
/// lower bounds: the gap of the supports along GJK's witness direction).
const DISTANCE_SLACK: f64 = 1e-6;

/// The part of a measured distance `d` that is trusted: `d` less the slack.
#[inline]
fn trusted(d: f64) -> f64 {
    d - DISTANCE_SLACK
}

/// How far past a threshold [`ArmValidity::clear_by`] caps its queries (m).
const CAP_PAST: f64 = 1e-9;

/// A segment step takes a part at its cover bound, without the exact query, when that bound
/// reaches this share of the clearance the step asks of the part (see
/// [`ArmValidity::capped_step`]): the step may come out shorter than the exact distance would
/// allow, and a query saved costs more than the samples added (box, first 30 MBM problems:
/// planning instructions −11 % at 0.4–0.6, the same paths; 0 asks the exact query only below
/// the floor and makes 20 % more samples).
const ENOUGH_SHARE: f64 = 0.5;

/// A segment step's exact queries may fall short of the distance by this share of its excess
/// over what the step needs (a [`Precision`] whose `above` is the part's floor, so that every
/// answer is the exact one's: [`ArmValidity::capped_step`]): GJK stops once its lower bound is
/// within it of its upper one, where it would run on to the last bits. The step comes out at
/// most that much shorter. MBM UR5 planning instructions on two sets of problems, the same
/// paths: −7.5 % / −3.4 % against exact queries (0.01: about −6.7 % / −3.1 %; 0.25: −8.2 % /
/// −3.7 %, with more samples); the README cell's legs −3.0 %, the same plan.
const STEP_SHARE: f64 = 0.1;

/// What a part is asked when its distance must be exact up to `cap` (no bound taken for it, no
/// precision short of it): the `(cap, enough, precision)` of [`ArmValidity::scene_part`].
#[inline]
fn exact(cap: f64) -> (f64, f64, Precision) {
    (cap, cap, Precision::EXACT)
}

/// The measured distance whose trusted part is `t` (the inverse of [`trusted`]).
#[inline]
fn measured_for(t: f64) -> f64 {
    t + DISTANCE_SLACK
}

/// A serial arm placed in a collision world.
#[derive(Clone, Copy)]
pub struct Arm<'a> {
    /// The world holding the arm's body group and the static scene.
    pub world: &'a CollisionWorld,
    /// The kinematic chain (root to tip).
    pub chain: &'a Chain,
    /// Pose of the chain's root link in the world.
    pub base: Pose,
    /// The arm's body group in `world`.
    pub group: GroupId,
    /// For each body of the group, the chain link it hangs on (index into `chain.links`).
    pub body_links: &'a [usize],
    /// Body pairs `(i, j)` checked for self-collision.
    pub self_pairs: &'a [(usize, usize)],
    /// Tables bounding the close self pairs over one joint, shared by the arm's checkers
    /// ([`PairTables::build`]); `None`: none are used.
    pub pair_tables: Option<&'a PairTables>,
}

impl std::fmt::Debug for Arm<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Arm")
            .field("group", &self.group)
            .field("bodies", &self.body_links.len())
            .field("self_pairs", &self.self_pairs.len())
            .finish_non_exhaustive()
    }
}

thread_local! {
    static LINKS: RefCell<(Vec<Pose>, Vec<Pose>)> = const { RefCell::new((Vec::new(), Vec::new())) };
    static CLEARANCES: RefCell<Vec<Clearance>> = const { RefCell::new(Vec::new()) };
    static COVERS: RefCell<PlacedCovers> = RefCell::new(PlacedCovers::default());
    static AXES: RefCell<PosedAxes> = RefCell::new(PosedAxes::default());
}

/// The arm's joint space: the chain's limits, [`joint_radii`], metric weights `1/v` from
/// `max_velocity` (1 where a velocity is missing, zero or not finite), and its rotational
/// joints marked as turning ([`JointSpace::turns`]).
pub fn joint_space(arm: &Arm, max_velocity: &[f64]) -> JointSpace {
    let chain = arm.chain;
    let lower = chain.joints.iter().map(|j| j.lower).collect();
    let upper = chain.joints.iter().map(|j| j.upper).collect();
    let weights = (0..chain.dof())
        .map(|j| match max_velocity.get(j) {
            Some(&v) if v.is_finite() && v > 0.0 => 1.0 / v,
            _ => 1.0,
        })
        .collect();
    let turns = chain.joints.iter().map(|j| j.is_rotational()).collect();
    JointSpace::new(lower, upper, joint_radii(arm))
        .with_weights(weights)
        .with_turns(turns)
}

/// A part index shared by the threads that use one checker (relaxed: a hint, never a result).
#[derive(Debug, Default)]
struct PartHint(std::sync::atomic::AtomicUsize);

impl PartHint {
    fn get(&self) -> usize {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
    fn set(&self, k: usize) {
        self.0.store(k, std::sync::atomic::Ordering::Relaxed);
    }
}

impl Clone for PartHint {
    fn clone(&self) -> Self {
        PartHint(std::sync::atomic::AtomicUsize::new(self.get()))
    }
}

/// [`ArmValidity::order`] for `moving` bodies and checked self pairs `pairs` (parts `moving..`):
/// the pairs [`PairTables::likely_contacts`] lists, in its order, then the moving bodies, then
/// the other pairs.
fn part_order(arm: &Arm, moving: usize, pairs: &[(usize, usize)]) -> Vec<usize> {
    let likely: Vec<usize> = arm.pair_tables.map_or(Vec::new(), |t| {
        t.likely_contacts()
            .iter()
            .filter_map(|p| pairs.iter().position(|q| q == p))
            .collect()
    });
    let rest = (0..pairs.len()).filter(|k| !likely.contains(k));
    likely
        .iter()
        .map(|k| moving + k)
        .chain(0..moving)
        .chain(rest.map(|k| moving + k))
        .collect()
}

/// A checked self pair `(i, j)` with the joints between its bodies and the radii that bound
/// their relative motion ([`pair_radii`]).
type CheckedPair = (usize, usize, Range<usize>, Vec<f64>);

/// The clearance of an arm's configurations (see the module documentation).
///
/// [`StateValidity::clearances`] splits it by the joints that can reduce each part: the
/// distance of a body on link `k` to the scene (minus the margin) by joints `0..=k`, the
/// distance of a self pair by the joints between its two links. Every distance is capped at
/// [`ArmValidity::cap`].
#[derive(Clone, Debug)]
pub struct ArmValidity<'a> {
    /// The arm.
    pub arm: Arm<'a>,
    /// Required distance (m) from the static scene and the parked groups.
    pub margin: f64,
    /// Clearances are capped at this (m).
    pub cap: f64,
    /// Whether the sphere-cover bounds are asked before exact distances (on by default; off
    /// only to measure what the broad phase saves).
    pub broad_phase: bool,
    /// Whether a segment check bounds each part's motion by the radii of the body concerned
    /// (the distal one of a self pair; [`Chain::body_radii`]) rather than the space's (on by
    /// default; off only to compare with the plain bound).
    pub own_radii: bool,
    /// Whether a segment step also bounds each part's motion at the sample itself (on by
    /// default; off only to compare): see `posed_bound`.
    pub posed_radii: bool,
    /// Bodies checked against the scene (those moved by some joint), with their joints.
    moving: Vec<(usize, Range<usize>)>,
    /// Checked self pairs with the joints between them and the radii that bound their
    /// relative motion ([`pair_radii`]).
    pairs: Vec<CheckedPair>,
    /// Each body's radii ([`body_radii`]).
    body_radii: Vec<Vec<f64>>,
    /// Each body's outer sphere in its own frame (none for a body without shapes).
    outer: Vec<Option<Sphere>>,
    /// Per pair: its distal body, the one whose motion [`Self::posed_bound`] bounds.
    pair_far: Vec<usize>,
    /// Per joint: the chain link it moves and its axis in that link's frame (none for a
    /// sliding joint).
    axes: Vec<Option<(usize, DVec3)>>,
    /// The part that last proved a configuration invalid (asked first next time).
    last_failed: PartHint,
    /// The order in which [`Self::is_valid`] asks the other parts ([`part_order`]): a part
    /// likely to fail before the many that rarely do. Only the work depends on it, never the
    /// answer.
    order: Vec<usize>,
    /// Per part (the moving bodies, then the pairs): the chain links it needs posed, `0..end`
    /// (its bodies', which hold its clusters' too).
    part_links: Vec<usize>,
    /// Other groups standing still (obstacles like the scene), with their body poses.
    parked: Vec<(GroupId, Vec<Pose>)>,
    /// Distance (m) kept from the parked groups beyond the margin.
    parked_extra: f64,
    /// The arm's covers against the scene and the parked groups.
    broad: BroadPhase,
    /// Bodies grouped by link ([`Clusters`]), to settle several parts with one test.
    clusters: Clusters,
}

impl<'a> ArmValidity<'a> {
    /// With the default cap [`DEFAULT_CLEARANCE_CAP`], keeping `margin` from the scene and from
    /// the `parked` groups. Bodies on links before the first joint never move and are not
    /// checked against the scene (a robot's base stands on its floor).
    pub fn new(arm: Arm<'a>, margin: f64, parked: Vec<(GroupId, Vec<Pose>)>) -> Self {
        let moving: Vec<(usize, Range<usize>)> = (0..arm.body_links.len())
            .map(|i| (i, 0..moved_by(&arm, i)))
            .filter(|(_, r)| !r.is_empty())
            .collect();
        // Pairs that no joint moves relative to each other keep one distance: measured once
        // (at the middle of the limits) and dropped when apart; kept when touching, which
        // makes every configuration invalid, as it is.
        let mut links = Vec::new();
        let mut poses = Vec::new();
        arm.body_poses(&arm.chain.mid_configuration(), &mut links, &mut poses);
        let body_radii: Vec<Vec<f64>> = (0..arm.body_links.len()).map(|i| body_radii(&arm, i)).collect();
        // Each pair with its distal body (the one whose radii bound the pair's motion).
        let (pairs, pair_far): (Vec<CheckedPair>, Vec<usize>) = arm
            .self_pairs
            .iter()
            .map(|&(i, j)| {
                let (a, b) = (moved_by(&arm, i), moved_by(&arm, j));
                let (near, far) = if b >= a { (i, j) } else { (j, i) };
                let radii = pair_radii(&arm, near, a.min(b), &body_radii[far]);
                ((i, j, a.min(b)..a.max(b), radii), far)
            })
            .filter(|((i, j, r, _), _)| {
                !r.is_empty() || arm.world.pair_distance(arm.group, *i, *j, &poses, 1.0) <= DISTANCE_SLACK
            })
            .unzip();
        let broad = BroadPhase::new(arm.world, arm.group, &parked);
        let outer = (0..arm.body_links.len()).map(|i| broad.outer_of(&[i])).collect();
        let axes = (0..arm.chain.dof())
            .map(|j| {
                let joint = arm.chain.joints.get(j).filter(|joint| joint.is_rotational())?;
                Some((arm.chain.joint_link(j)?, joint.axis.normalize_or_zero()))
            })
            .collect();
        let pair_bodies: Vec<(usize, usize)> = pairs.iter().map(|&(i, j, _, _)| (i, j)).collect();
        let order = part_order(&arm, moving.len(), &pair_bodies);
        let clusters = Clusters::new(&arm, &broad, &moving, &pair_bodies);
        let end = |i: usize| arm.body_links.get(i).map_or(usize::MAX, |&l| l.saturating_add(1));
        let part_links = moving
            .iter()
            .map(|&(i, _)| end(i))
            .chain(pairs.iter().map(|&(i, j, _, _)| end(i).max(end(j))))
            .collect();
        ArmValidity {
            part_links,
            broad,
            clusters,
            arm,
            margin,
            cap: DEFAULT_CLEARANCE_CAP,
            broad_phase: true,
            own_radii: true,
            posed_radii: true,
            outer,
            pair_far,
            axes,
            last_failed: PartHint::default(),
            order,
            moving,
            body_radii,
            pairs,
            parked,
            parked_extra: 0.0,
        }
    }

    /// The same checker keeping `extra` (m, ≥ 0) more than the margin from the parked groups
    /// (robots that will move later keep the slack their coordination needs).
    pub fn with_parked_extra(mut self, extra: f64) -> Self {
        let extra = if extra.is_finite() { extra.max(0.0) } else { 0.0 };
        self.broad = BroadPhase::with_parked_extra(self.arm.world, self.arm.group, &self.parked, extra);
        self.parked_extra = extra;
        self
    }

    /// The cluster of moving part `k` ([`Clusters`]; none with the broad phase off).
    #[inline]
    fn scene_cluster(&self, k: usize) -> Option<usize> {
        self.clusters
            .scene
            .get(k)
            .copied()
            .flatten()
            .filter(|_| self.broad_phase)
    }

    /// The groups of pair `k` ([`Clusters`]; none with the broad phase off).
    #[inline]
    fn pair_groups(&self, k: usize) -> impl Iterator<Item = &usize> {
        self.clusters
            .pair
            .get(k)
            .filter(|_| self.broad_phase)
            .into_iter()
            .flatten()
            .flatten()
    }

    /// Distance of body `i` (posed in `bodies`) to the scene and the parked groups, capped.
    fn body_scene_distance(&self, i: usize, bodies: &[Pose], cap: f64) -> f64 {
        let world = self.arm.world;
        let g = self.arm.group;
        let mut d = world.body_static_distance(g, i, bodies, cap);
        let extra = self.parked_extra;
        for (other, poses) in &self.parked {
            if d <= 0.0 {
                break;
            }
            d = (world.body_group_distance(g, i, bodies, *other, poses, d + extra) - extra).max(0.0);
        }
        d
    }

    /// Runs `f` with the arm's body poses at `q` (and, with the broad phase on, its covers
    /// placed there), in this thread's scratch.
    fn posed<T>(&self, q: &[f64], f: impl FnOnce(&[Pose], &PlacedCovers) -> T) -> T {
        LINKS.with_borrow_mut(|(links, bodies)| {
            self.arm.body_poses(q, links, bodies);
            self.covered(bodies, f)
        })
    }

    /// Runs `f` with the body poses `bodies` and, with the broad phase on, the arm's covers
    /// placed there, in this thread's scratch.
    fn covered<T>(&self, bodies: &[Pose], f: impl FnOnce(&[Pose], &PlacedCovers) -> T) -> T {
        COVERS.with_borrow_mut(|placed| {
            if self.broad_phase {
                self.broad.place(bodies, placed);
            }
            f(bodies, placed)
        })
    }

    /// Distance of moving body `i` to the scene and the parked groups, of `(cap, enough,
    /// precision)` capped at `cap`: through the broad phase when it is on — where a cover bound
    /// reaching `enough` answers without the exact query, and that query may fall short as the
    /// [`Precision`] allows ([`BroadPhase::scene_distance_enough`]) — else exact for every
    /// object.
    fn scene_part(
        &self,
        i: usize,
        bodies: &[Pose],
        placed: &PlacedCovers,
        ask: (f64, f64, Precision),
    ) -> f64 {
        let cap = ask.0;
        if self.broad_phase {
            self.broad
                .scene_distance_enough(self.arm.world, i, bodies, placed, ask)
        } else {
            self.body_scene_distance(i, bodies, cap)
        }
    }

    /// Distance between bodies `i` and `j` at `q` (posed in `bodies`), capped at `cap` (as
    /// [`Self::scene_part`]); with the broad phase, the pair's table over one joint
    /// ([`PairTables`]) comes after the outer spheres and before the exact query: after the
    /// covers, or before them when `enough >= cap` ([`BroadPhase::pair_distance_or`]).
    fn pair_part(
        &self,
        i: usize,
        j: usize,
        q: &[f64],
        bodies: &[Pose],
        placed: &PlacedCovers,
        ask: (f64, f64, Precision),
    ) -> f64 {
        let cap = ask.0;
        if self.broad_phase {
            let table = || {
                self.arm
                    .pair_tables
                    .and_then(|t| t.get(i, j))
                    .and_then(|t| Some(t.least_within(*q.get(t.joint())?, 0.0)))
                    .unwrap_or(0.0)
            };
            self.broad
                .pair_distance_or(self.arm.world, i, j, bodies, placed, ask, table)
        } else {
            self.arm.world.pair_distance(self.arm.group, i, j, bodies, cap)
        }
    }

    /// Whether a self pair's table proves it in contact at `q` (with the broad phase only:
    /// [`PairTables::prove_contact`]), before anything is posed: on the MBM UR5, 36 % of
    /// random configurations have the base and the upper arm in contact, and the table proves
    /// 84 % of those.
    #[inline]
    fn proven_contact(&self, q: &[f64]) -> bool {
        self.broad_phase && self.arm.pair_tables.is_some_and(|t| t.prove_contact(q))
    }

    /// Whether `q` is valid: within the joint limits, every moving body farther than the
    /// margin from the scene and the parked groups, every checked self pair apart. Broad phase
    /// first, the exact test only for the parts it does not clear.
    pub fn is_valid(&self, q: &[f64]) -> bool {
        if !self.arm.chain.within_limits(q, 1e-9) || self.proven_contact(q) {
            return false;
        }
        // The part that failed last is asked first (see [`Self::valid_posed`]) with the arm
        // posed up to the links it needs: a configuration it proves invalid is not posed further.
        let first = self.last_failed.get();
        let end = self.part_links.get(first).copied().unwrap_or(usize::MAX);
        LINKS.with_borrow_mut(|(links, bodies)| {
            let partial = self.arm.body_poses_before(q, links, bodies, end);
            COVERS.with_borrow_mut(|placed| {
                if self.broad_phase {
                    self.broad.place(bodies, placed);
                }
                let sets = Settled::untested();
                if !self.part_clear(first, q, bodies, placed, &sets) {
                    return false;
                }
                if partial {
                    self.arm.body_poses_from(q, links, bodies, end);
                    if self.broad_phase {
                        self.broad.repose(bodies, placed);
                    }
                }
                self.other_parts_clear(first, q, bodies, placed, &sets)
            })
        })
    }

    /// [`Self::is_valid`] for a caller that has posed the arm at `q` already: `bodies` are its
    /// body poses there, as [`Arm::body_poses`] gives them (the same answer, without posing
    /// the arm again; with poses of another length, `q` is posed here).
    pub fn is_valid_posed(&self, q: &[f64], bodies: &[Pose]) -> bool {
        if !self.arm.chain.within_limits(q, 1e-9) || self.proven_contact(q) {
            return false;
        }
        if bodies.len() != self.arm.body_links.len() {
            return self.is_valid(q);
        }
        self.covered(bodies, |bodies, placed| self.valid_posed(q, bodies, placed))
    }

    /// The parts of [`Self::is_valid`] at `q`, posed at body poses `bodies` (covers placed in
    /// `placed`). The part that failed last is asked first: samples near each other usually
    /// fail on the same part. Only the work depends on it, never the answer.
    fn valid_posed(&self, q: &[f64], bodies: &[Pose], placed: &PlacedCovers) -> bool {
        let first = self.last_failed.get();
        let sets = Settled::untested();
        self.part_clear(first, q, bodies, placed, &sets)
            && self.other_parts_clear(first, q, bodies, placed, &sets)
    }

    /// Whether every part of [`Self::is_valid`] but `first` is clear; the first that is not
    /// becomes the part asked first next time.
    fn other_parts_clear(
        &self,
        first: usize,
        q: &[f64],
        bodies: &[Pose],
        placed: &PlacedCovers,
        sets: &[Cell<Settled>; 2],
    ) -> bool {
        match self
            .order
            .iter()
            .copied()
            .find(|&k| k != first && !self.part_clear(k, q, bodies, placed, sets))
        {
            Some(k) => {
                self.last_failed.set(k);
                false
            }
            None => true,
        }
    }

    /// Whether part `k` of [`Self::is_valid`] at `q` is clear (posed at `bodies`, covers
    /// placed in `placed`): a moving body against the scene (`k` below the number of moving
    /// bodies), else a self pair; a body of a cluster clear of the scene, or a pair of two
    /// clusters apart, is clear without its own query (see [`Clusters`]; `sets`: the clusters
    /// and the groups tested within this check). Parts beyond the last are clear.
    #[inline]
    fn part_clear(
        &self,
        k: usize,
        q: &[f64],
        bodies: &[Pose],
        placed: &PlacedCovers,
        sets: &[Cell<Settled>; 2],
    ) -> bool {
        // Strictly farther than the margin, as the clearance (> 0) requires.
        let need = measured_for(self.margin.max(0.0));
        let apart = measured_for(0.0);
        let tiny = 1e-9;
        let m = self.moving.len();
        let settled = |sets: &Cell<Settled>, c: usize, test: &dyn Fn() -> bool| {
            let mut s = sets.get();
            let clear = s.clear(c, test);
            sets.set(s);
            clear
        };
        if let Some((i, _)) = self.moving.get(k) {
            if let Some(c) = self.scene_cluster(k)
                && settled(&sets[0], c, &|| {
                    self.broad
                        .sphere_clears_scene(self.clusters.placed(c, bodies), need + tiny)
                })
            {
                return true;
            }
            self.scene_part(*i, bodies, placed, exact(need + tiny)) > need
        } else if let Some(&(i, j, _, _)) = self.pairs.get(k - m) {
            if self.pair_groups(k - m).any(|&g| {
                settled(&sets[1], g, &|| {
                    self.clusters.group_apart(g, bodies, apart + tiny)
                })
            }) {
                return true;
            }
            self.pair_part(i, j, q, bodies, placed, exact(apart + tiny)) > apart
        } else {
            true
        }
    }

    /// The clearance of `q` from the scene (minus the margin) and the smallest distance between
    /// its checked self pairs, each capped at [`Self::cap`] (the parts of
    /// [`StateValidity::clearances`], split); both negative infinity outside the joint limits.
    pub fn scene_and_self_clearance(&self, q: &[f64]) -> (f64, f64) {
        if !self.arm.chain.within_limits(q, 1e-9) {
            return (f64::NEG_INFINITY, f64::NEG_INFINITY);
        }
        CLEARANCES.with_borrow_mut(|out| {
            self.clearances(q, out);
            // `clearances` lists the moving bodies first, then the pairs.
            let (scene, pairs) = out.split_at(self.moving.len().min(out.len()));
            let min = |parts: &[Clearance]| parts.iter().map(|c| c.distance).fold(self.cap, f64::min);
            (min(scene), min(pairs))
        })
    }

    /// Whether `scene_and_self_clearance(q)` is at least `(scene, own)`, both parts — the same
    /// answer, cheaper: every part is asked only as far as the comparison needs (its query
    /// capped just past the threshold, so the broad phase skips the exact query of whatever its
    /// covers show to be farther), and the first part short of its threshold ends the check.
    pub fn clear_by(&self, q: &[f64], scene: f64, own: f64) -> bool {
        if !self.arm.chain.within_limits(q, 1e-9) {
            return f64::NEG_INFINITY >= scene && f64::NEG_INFINITY >= own;
        }
        // Both parts are capped at `cap` (and a part's trusted distance at less).
        if !(scene <= self.cap && own <= self.cap) {
            return false;
        }
        let margin = self.margin.max(0.0);
        // A query capped at `cap` answers at most `cap`: the caps sit a nanometre past the
        // measured distance whose trusted part is the threshold, so that a part answering its
        // cap passes (the trusted part of `measured_for(x)` may round below `x`).
        let past = |x: f64| measured_for(x) + CAP_PAST;
        self.posed(q, |bodies, placed| {
            let cap = past(scene).min(self.cap) + margin;
            let scene_clear = self
                .moving
                .iter()
                .all(|(i, _)| trusted(self.scene_part(*i, bodies, placed, exact(cap))) - margin >= scene);
            let cap = past(own).min(self.cap);
            scene_clear
                && self
                    .pairs
                    .iter()
                    .all(|(i, j, _, _)| trusted(self.pair_part(*i, *j, q, bodies, placed, exact(cap))) >= own)
        })
    }
}

impl StateValidity for ArmValidity<'_> {
    fn is_valid(&self, q: &[f64]) -> bool {
        ArmValidity::is_valid(self, q)
    }

    /// [`ArmValidity::clear_by`] with the floor for both parts (each part asked only as far as
    /// the floor), after the pair tables' proofs of contact, as [`ArmValidity::is_valid`] asks
    /// them: a contact is below any positive floor.
    fn clear_of(&self, q: &[f64], floor: f64) -> bool {
        // NaN fails, as the comparison of the default does.
        if floor.is_nan() || (floor > 0.0 && self.arm.chain.within_limits(q, 1e-9) && self.proven_contact(q))
        {
            return false;
        }
        self.clear_by(q, floor, floor)
    }

    fn clearance(&self, q: &[f64]) -> f64 {
        CLEARANCES.with_borrow_mut(|out| {
            self.clearances(q, out);
            out.iter().map(|c| c.distance).fold(f64::INFINITY, f64::min)
        })
    }

    fn clearances(&self, q: &[f64], out: &mut Vec<Clearance>) {
        out.clear();
        if !self.arm.chain.within_limits(q, 1e-9) {
            out.push(Clearance {
                distance: f64::NEG_INFINITY,
                joints: 0..usize::MAX,
            });
            return;
        }
        let margin = self.margin.max(0.0);
        self.posed(q, |bodies, placed| {
            for (i, joints) in &self.moving {
                let d = self.scene_part(*i, bodies, placed, exact(self.cap + margin));
                out.push(Clearance {
                    distance: trusted(d) - margin,
                    joints: joints.clone(),
                });
            }
            for (i, j, joints, _) in &self.pairs {
                let d = self.pair_part(*i, *j, q, bodies, placed, exact(self.cap));
                out.push(Clearance {
                    distance: trusted(d),
                    joints: joints.clone(),
                });
            }
        });
    }

    /// As the default, with every part asked only as far as it matters (see `capped_step`):
    /// bodies from the tip inwards (the tool is the usual tightest part, and its step then caps
    /// the others' queries), then the self pairs; each queried part's motion bounded where the
    /// arm stands (`posed_bound`) when that is tighter.
    fn segment_step(&self, q: &[f64], motion: &SegmentMotion, floor: f64, limit: f64) -> Option<f64> {
        if !self.arm.chain.within_limits(q, 1e-9) {
            return None;
        }
        // Each part's bound depends on the segment alone: made at its first sample (moving
        // bodies, then pairs, in `self`'s order) and kept for the others.
        let bounds = motion.memo(self as *const Self as usize, || self.part_bounds(motion));
        LINKS.with_borrow_mut(|(links, bodies)| {
            self.arm.body_poses(q, links, bodies);
            AXES.with_borrow_mut(|axes| {
                axes.place(self, links);
                self.covered(bodies, |bodies, placed| {
                    self.step_posed(q, motion, floor, limit, &bounds, bodies, placed, axes)
                })
            })
        })
    }
}

//! The broad phase of one body group against everything that stands still, precomputed:
//! [`BroadPhase`] (the whole group placed at once, then each body against each object).
//!
//! A motion planner asks the same group thousands of times per query, so [`BroadPhase`] does
//! the lookups of shapes, covers and poses once:
//!
//! - each body's cover (see [`crate::spheres`]) is kept in one flat array;
//!   [`BroadPhase::place`] keeps the poses; a body's outer sphere is put in the world (one
//!   rotation matrix per body) when a query first needs it, and its cover likewise;
//! - each object — a static object, or a body of another group parked at a fixed pose — gets
//!   its world box and, for boxes, cylinders and balls, its inverse pose, so that a sphere's
//!   distance to it is a few lines of arithmetic (meshes and other shapes fall back to a point
//!   projection);
//! - [`BroadPhase::scene_distance`] then goes object by object: the body's outer sphere against
//!   the object's box, the cover against the object, and the exact (GJK) distance **for that
//!   object only** when the cover's bound falls short of what is asked. The answer is the
//!   exact capped distance, as [`CollisionWorld::body_static_distance`] and
//!   [`CollisionWorld::body_group_distance`] would give it together, at a fraction of the work
//!   when most objects are far.
//!
//! Bounds never exceed exact distances (the covers contain the bodies), so skipping an exact
//! query whose bound already reaches the cap changes no answer.
use super::distance::outers_apart;
use super::{CollisionWorld, GroupId, Precision, sanitize_margin};
use crate::spheres::{Sphere, reaches};
use crate::{DMat3, DVec3, Pose};
use std::cell::Cell;
use std::ops::Range;

/// From a box to `p`, per axis (0 inside): its length is the distance.
#[inline]
fn box_gap(p: DVec3, mins: DVec3, maxs: DVec3) -> DVec3 {
    (mins - p).max(p - maxs).max(DVec3::ZERO)
}

/// Whether a sphere about `p` of radius `r` is at least `gap` from a box: `|box_gap| − r ≥
/// gap`, compared squared ([`reaches`]). A NaN centre counts as inside the box (apart only for
/// a reach of zero or less).
#[inline]
fn sphere_box_apart(p: DVec3, r: f64, mins: DVec3, maxs: DVec3, gap: f64) -> bool {
    reaches(box_gap(p, mins, maxs).length_squared(), r + gap)
}

/// What an object is, for a sphere's distance to it.
#[derive(Clone, Debug)]
enum Kind {
    /// A solid box: world-to-local rotation, centre, half extents.
    Cuboid {
        to_local: DMat3,
        centre: DVec3,
        half: DVec3,
    },
    /// A solid cylinder along its local y axis (parry's): world-to-local rotation, centre,
    /// radius, half height.
    Cylinder {
        to_local: DMat3,
        centre: DVec3,
        radius: f64,
        half_height: f64,
    },
    /// A solid ball.
    Ball { centre: DVec3, radius: f64 },
    /// Any other static object, measured by the world's point projection (meshes: surfaces;
    /// other convex shapes: solids).
    Other,
    /// Body `body` of group `group`, standing at `pose`; its cover in the world is
    /// `parked[spheres]` (grown by `extra`); distances to it count `extra` less.
    Body {
        group: GroupId,
        body: usize,
        pose: Pose,
        spheres: Range<usize>,
        extra: f64,
    },
}

/// One object that stands still.
#[derive(Clone, Debug)]
struct Object {
    /// World box (for a parked body: the box of its outer sphere).
    mins: DVec3,
    maxs: DVec3,
    /// The world's index of a static object (unused for a parked body).
    index: usize,
    kind: Kind,
}

/// The world covers of a group's bodies at one set of poses (see [`BroadPhase::place`]).
/// Nothing is placed at once: a body's frame and outer sphere when a query first needs them,
/// its cover when a query first needs that (most queries settle most bodies by their outer
/// spheres, and an invalid configuration stops at its first failing part).
#[derive(Clone, Debug, Default)]
pub struct PlacedCovers {
    /// The poses placed, one per body of the group.
    poses: Vec<Pose>,
    /// Per body: nothing placed (0), or [`FRAMED`] with [`COVERED`], [`SHAPED`] and
    /// [`FINITE`] as they hold.
    state: Vec<Cell<u8>>,
    /// Every body's cover in the world; body `i`'s spheres are `spheres[ranges[i]]`.
    spheres: Vec<Cell<Sphere>>,
    /// Each body's rotation and translation, to place its cover.
    frames: Vec<Cell<(DMat3, DVec3)>>,
    /// Each body's outer sphere in the world (when [`SHAPED`]).
    outer: Vec<Cell<Sphere>>,
}

/// A body of [`PlacedCovers`] whose frame and outer sphere are placed.
const FRAMED: u8 = 1;
/// A body of [`PlacedCovers`] whose cover is placed too.
const COVERED: u8 = 2;
/// A body of [`PlacedCovers`] with a shape (and an outer sphere).
const SHAPED: u8 = 4;
/// A body of [`PlacedCovers`] at a finite pose.
const FINITE: u8 = 8;

/// The broad phase of one group against the static scene and parked groups (see the module
/// documentation). Built for a world and its current objects: rebuild it when they change.
#[derive(Clone, Debug)]
pub struct BroadPhase {
    group: GroupId,
    /// Every body's cover in its body frame; body `i`'s are `local[ranges[i]]`.
    local: Vec<Sphere>,
    ranges: Vec<Range<usize>>,
    outer: Vec<Option<Sphere>>,
    objects: Vec<Object>,
    /// The objects in runs (the static objects, then each parked group's bodies), each with
    /// the box around its objects' boxes: a body farther from a run's box than what is asked
    /// skips the whole run.
    runs: Vec<(DVec3, DVec3, Range<usize>)>,
    /// The covers of the parked bodies, in the world.
    parked: Vec<Sphere>,
}

impl BroadPhase {
    /// The broad phase of group `g` against `world`'s static objects and the `parked` groups
    /// (each with the poses of its bodies, standing still).
    pub fn new(world: &CollisionWorld, g: GroupId, parked: &[(GroupId, Vec<Pose>)]) -> BroadPhase {
        BroadPhase::with_parked_extra(world, g, parked, 0.0)
    }

    /// As [`BroadPhase::new`], with distances to the parked bodies counted `extra` (m, ≥ 0)
    /// less than they are: those bodies are kept `extra` farther away than the scene.
    pub fn with_parked_extra(
        world: &CollisionWorld,
        g: GroupId,
        parked: &[(GroupId, Vec<Pose>)],
        extra: f64,
    ) -> BroadPhase {
        let extra = if extra.is_finite() { extra.max(0.0) } else { 0.0 };
        let mut local = Vec::new();
        let mut ranges = Vec::new();
        let mut outer = Vec::new();
        for i in 0..world.body_count(g) {
            let start = local.len();
            local.extend_from_slice(world.body_cover(g, i));
            ranges.push(start..local.len());
            outer.push(
                world.group(g).bodies[i]
                    .convex
                    .as_ref()
                    .and_then(|c| c.cover.outer),
            );
        }
        let mut objects = Vec::new();
        for (index, s) in world.statics.iter().enumerate() {
            let Some(shape) = s.shape.as_deref() else {
                continue;
            };
            let to_local = DMat3::from_quat(s.pose.rotation.inverse());
            let centre = s.pose.translation;
            let kind = if let Some(c) = shape.as_cuboid() {
                Kind::Cuboid {
                    to_local,
                    centre,
                    half: c.half_extents,
                }
            } else if let Some(c) = shape.as_cylinder() {
                Kind::Cylinder {
                    to_local,
                    centre,
                    radius: c.radius,
                    half_height: c.half_height,
                }
            } else if let Some(b) = shape.as_ball() {
                Kind::Ball {
                    centre,
                    radius: b.radius,
                }
            } else {
                Kind::Other
            };
            objects.push(Object {
                mins: s.aabb.mins,
                maxs: s.aabb.maxs,
                index,
                kind,
            });
        }
        let mut runs = Vec::new();
        let mut run_start = 0;
        let mut close_run = |objects: &[Object], runs: &mut Vec<(DVec3, DVec3, Range<usize>)>| {
            if objects.len() > run_start {
                let run = &objects[run_start..];
                let mins = run.iter().fold(DVec3::splat(f64::INFINITY), |m, o| m.min(o.mins));
                let maxs = run
                    .iter()
                    .fold(DVec3::splat(f64::NEG_INFINITY), |m, o| m.max(o.maxs));
                runs.push((mins, maxs, run_start..objects.len()));
            }
            run_start = objects.len();
        };
        close_run(&objects, &mut runs);
        let mut parked_spheres = Vec::new();
        for (other, poses) in parked {
            for (j, pose) in poses.iter().enumerate().take(world.body_count(*other)) {
                let Some(o) = world.group(*other).bodies[j]
                    .convex
                    .as_ref()
                    .and_then(|c| c.cover.outer)
                else {
                    continue;
                };
                let start = parked_spheres.len();
                let (mins, maxs) = if pose.is_finite() {
                    parked_spheres.extend(world.body_cover(*other, j).iter().map(|s| Sphere {
                        centre: pose.transform_point(s.centre),
                        radius: s.radius + extra,
                    }));
                    let c = pose.transform_point(o.centre);
                    let r = o.radius + extra;
                    (c - DVec3::splat(r), c + DVec3::splat(r))
                } else {
                    // Never dismissed by its box: the exact query says 0.
                    (DVec3::splat(f64::NEG_INFINITY), DVec3::splat(f64::INFINITY))
                };
                objects.push(Object {
                    mins,
                    maxs,
                    index: usize::MAX,
                    kind: Kind::Body {
                        group: *other,
                        body: j,
                        pose: *pose,
                        spheres: start..parked_spheres.len(),
                        extra,
                    },
                });
            }
            close_run(&objects, &mut runs);
        }
        BroadPhase {
            group: g,
            local,
            ranges,
            outer,
            objects,
            runs,
            parked: parked_spheres,
        }
    }

    /// Number of objects (static objects with geometry, and parked bodies with shapes).
    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Places the group at `poses` (world frame, one per body of the group; a missing pose is
    /// the identity) into `out`: each body's frame and outer sphere when a query first asks for
    /// them, its cover when a query first asks for that.
    pub fn place(&self, poses: &[Pose], out: &mut PlacedCovers) {
        let n = self.ranges.len();
        out.poses.clear();
        out.poses.extend_from_slice(&poses[..n.min(poses.len())]);
        out.poses.resize(n, Pose::IDENTITY);
        out.state.clear();
        out.state.resize(n, Cell::new(0));
        let zero = Sphere {
            centre: DVec3::ZERO,
            radius: 0.0,
        };
        if out.spheres.len() != self.local.len() {
            out.spheres.resize(self.local.len(), Cell::new(zero));
        }
        if out.frames.len() != n {
            out.frames.resize(n, Cell::new((DMat3::IDENTITY, DVec3::ZERO)));
            out.outer.resize(n, Cell::new(zero));
        }
    }

    /// The placement in `out` with the poses `poses` in place of those it was made with, for
    /// the bodies no query has asked for yet: a caller that placed some bodies' poses before it
    /// knew the others' ([`BroadPhase::place`] with placeholders) gives them here. The bodies
    /// a query has asked for must keep their poses.
    pub fn repose(&self, poses: &[Pose], out: &mut PlacedCovers) {
        let n = out.poses.len().min(poses.len());
        debug_assert!(
            (0..n).all(|i| out.state[i].get() == 0 || out.poses[i] == poses[i]),
            "a body placed already keeps its pose"
        );
        out.poses[..n].copy_from_slice(&poses[..n]);
    }

    /// Body `i`'s outer sphere in the world (`None`: no shape, or no such body) and whether its
    /// pose is finite; placed now with its frame if no query has needed them yet.
    #[inline(always)]
    fn outer_placed(&self, placed: &PlacedCovers, i: usize) -> (Option<Sphere>, bool) {
        let Some(state) = placed.state.get(i) else {
            return (None, true);
        };
        let mut s = state.get();
        if s & FRAMED == 0 {
            s = self.frame(placed, i);
        }
        let outer = (s & SHAPED != 0).then(|| placed.outer[i].get());
        (outer, s & FINITE != 0)
    }

    /// Places body `i`'s frame and outer sphere; its new state.
    #[inline(never)]
    fn frame(&self, placed: &PlacedCovers, i: usize) -> u8 {
        let pose = placed.poses[i];
        let rot = DMat3::from_quat(pose.rotation);
        let t = pose.translation;
        placed.frames[i].set((rot, t));
        let mut s = FRAMED;
        if let Some(o) = self.outer[i] {
            placed.outer[i].set(Sphere {
                centre: rot * o.centre + t,
                radius: o.radius,
            });
            s |= SHAPED;
        }
        if pose.is_finite() {
            s |= FINITE;
        }
        placed.state[i].set(s);
        s
    }

    /// Body `i`'s cover in the world, placed now if no query has needed it yet.
    fn cover<'p>(&self, placed: &'p PlacedCovers, i: usize) -> &'p [Cell<Sphere>] {
        let range = self.ranges[i].clone();
        let out = &placed.spheres[range.clone()];
        let mut s = placed.state[i].get();
        if s & COVERED == 0 {
            if s & FRAMED == 0 {
                s = self.frame(placed, i);
            }
            let (rot, t) = placed.frames[i].get();
            for (o, l) in out.iter().zip(&self.local[range]) {
                o.set(Sphere {
                    centre: rot * l.centre + t,
                    radius: l.radius,
                });
            }
            placed.state[i].set(s | COVERED);
        }
        out
    }

    /// Distance from body `i` (placed in `placed`, at `poses`) to every object, capped at
    /// `cap`: `min(true distance, cap)`, 0 when touching or at a non-finite pose (when there is
    /// an object), the cap for a body without shapes. Equal to the smaller of
    /// [`CollisionWorld::body_static_distance`] and [`CollisionWorld::body_group_distance`]
    /// over the parked groups (less the parked bodies' extra, see
    /// [`BroadPhase::with_parked_extra`]); the exact query runs only for objects whose bound
    /// falls short.
    pub fn scene_distance(
        &self,
        world: &CollisionWorld,
        i: usize,
        poses: &[Pose],
        placed: &PlacedCovers,
        cap: f64,
    ) -> f64 {
        self.scene_distance_enough(world, i, poses, placed, (cap, cap, Precision::EXACT))
    }

    /// [`BroadPhase::scene_distance`] capped at `cap`, settling for less: an object whose cover
    /// bound reaches `enough` is taken at that bound (a lower bound of its distance) without the
    /// exact query, and the exact query may fall short of the distance as `precision` allows
    /// ([`Precision`]). With `enough >= cap` and [`Precision::EXACT`], the same answer as
    /// `scene_distance`.
    pub fn scene_distance_enough(
        &self,
        world: &CollisionWorld,
        i: usize,
        poses: &[Pose],
        placed: &PlacedCovers,
        (cap, enough, precision): (f64, f64, Precision),
    ) -> f64 {
        let mut best = sanitize_margin(cap);
        let outer = match self.placed_body(i, placed, best) {
            Ok(outer) => outer,
            Err(answer) => return answer,
        };
        for (mins, maxs, run) in &self.runs {
            // The whole run is farther than what is asked.
            if sphere_box_apart(outer.centre, outer.radius, *mins, *maxs, best) {
                continue;
            }
            for object in &self.objects[run.clone()] {
                if sphere_box_apart(outer.centre, outer.radius, object.mins, object.maxs, best) {
                    continue;
                }
                let (bound, towards) = self.object_bound(world, object, self.cover(placed, i), outer, best);
                if bound >= best {
                    continue;
                }
                if bound >= enough {
                    best = bound;
                    continue;
                }
                let d = match &object.kind {
                    Kind::Body {
                        group,
                        body,
                        pose,
                        extra,
                        ..
                    } => (world.body_body_distance(self.group, i, poses, *group, *body, pose, best + extra)
                        - extra)
                        .max(0.0),
                    _ => world.body_object_distance_hinted(
                        self.group,
                        i,
                        poses,
                        object.index,
                        (best, precision),
                        towards,
                    ),
                };
                best = best.min(d);
                if best <= 0.0 {
                    return 0.0;
                }
            }
        }
        best
    }

    /// Body `i`'s outer sphere as placed, or the answer of a distance query capped at `best`
    /// when there is nothing to measure: `best` for a body without shapes, 0 at a non-finite
    /// pose (when there is an object).
    fn placed_body(&self, i: usize, placed: &PlacedCovers, best: f64) -> Result<Sphere, f64> {
        let (Some(outer), finite) = self.outer_placed(placed, i) else {
            return Err(best);
        };
        if !finite {
            return Err(if self.objects.is_empty() { best } else { 0.0 });
        }
        Ok(outer)
    }

    /// A sphere holding the outer spheres of `bodies` (bodies that share one frame, as the
    /// bodies of one link do: the sphere is in that frame); `None` when none of them has a
    /// shape. Where such a sphere, placed, is at least `best` from the scene
    /// ([`BroadPhase::sphere_clears_scene`]) or from another one, every query of its bodies
    /// capped at `best` or less answers its cap: their outer spheres settle it.
    pub fn outer_of(&self, bodies: &[usize]) -> Option<Sphere> {
        let spheres: Vec<Sphere> = bodies
            .iter()
            .filter_map(|&i| self.outer.get(i).copied().flatten())
            .collect();
        let first = spheres.first()?;
        let (lo, hi) = spheres.iter().fold((first.centre, first.centre), |(lo, hi), s| {
            (lo.min(s.centre - s.radius), hi.max(s.centre + s.radius))
        });
        let centre = 0.5 * (lo + hi);
        let radius = spheres
            .iter()
            .map(|s| (s.centre - centre).length() + s.radius)
            .fold(0.0, f64::max);
        // Rounding: the sphere must hold every one of them.
        Some(Sphere {
            centre,
            radius: radius * (1.0 + 1e-12) + 1e-12,
        })
    }

    /// Whether `sphere` (in the world) is at least `best` from the box of every run of objects:
    /// then a body whose outer sphere it holds answers [`BroadPhase::scene_distance`] capped at
    /// `best` or less with its cap (the same test, on a larger sphere). False for a sphere that
    /// is not finite.
    pub fn sphere_clears_scene(&self, sphere: Sphere, best: f64) -> bool {
        let best = sanitize_margin(best);
        self.runs
            .iter()
            .all(|(mins, maxs, _)| sphere_box_apart(sphere.centre, sphere.radius, *mins, *maxs, best))
    }

    /// A lower bound on the distance from body `i` to every object, capped at `cap` (the cover
    /// only, never an exact query).
    pub fn scene_bound(&self, world: &CollisionWorld, i: usize, placed: &PlacedCovers, cap: f64) -> f64 {
        let mut best = sanitize_margin(cap);
        let outer = match self.placed_body(i, placed, best) {
            Ok(outer) => outer,
            Err(answer) => return answer,
        };
        for (mins, maxs, run) in &self.runs {
            if sphere_box_apart(outer.centre, outer.radius, *mins, *maxs, best) {
                continue;
            }
            for object in &self.objects[run.clone()] {
                if sphere_box_apart(outer.centre, outer.radius, object.mins, object.maxs, best) {
                    continue;
                }
                best = best.min(
                    self.object_bound(world, object, self.cover(placed, i), outer, best)
                        .0,
                );
                if best <= 0.0 {
                    return 0.0;
                }
            }
        }
        best
    }

    /// Distance between bodies `i` and `j` of the group (placed in `placed`, at `poses`),
    /// capped at `cap`, as [`CollisionWorld::pair_distance`] gives it: the outer spheres, the
    /// covers, then the exact query only when the covers fall short.
    pub fn pair_distance(
        &self,
        world: &CollisionWorld,
        i: usize,
        j: usize,
        poses: &[Pose],
        placed: &PlacedCovers,
        cap: f64,
    ) -> f64 {
        self.pair_distance_or(world, i, j, poses, placed, (cap, cap, Precision::EXACT), || 0.0)
    }

    /// [`BroadPhase::pair_distance`] with another lower bound on the pair's distance, `other`,
    /// asked only when the outer spheres fall short — after the covers, or before them when
    /// `enough >= cap` —: where it reaches the cap, the exact query is skipped too (the same
    /// answer, when `other` never exceeds the distance). Of `(cap,
    /// enough, precision)`, a bound reaching `enough` is answered without the exact query (a
    /// lower bound of the distance), and the exact query may fall short of the distance as
    /// `precision` allows ([`Precision`]); with `enough >= cap` and [`Precision::EXACT`], the
    /// same answer as [`BroadPhase::pair_distance`].
    #[allow(clippy::too_many_arguments)]
    pub fn pair_distance_or(
        &self,
        world: &CollisionWorld,
        i: usize,
        j: usize,
        poses: &[Pose],
        placed: &PlacedCovers,
        (cap, enough, precision): (f64, f64, Precision),
        other: impl FnOnce() -> f64,
    ) -> f64 {
        let best = sanitize_margin(cap);
        let (bound, towards) = match self.outer_pair(i, j, placed, best) {
            Some(settled) => settled,
            None if enough >= best => {
                // Only whether a bound reaches `best` matters now (one that falls short is never
                // the answer): `other` first, a few lines where it is there, while the covers
                // of two close bodies compare every sphere with every sphere.
                let other = other();
                if other >= best {
                    return best;
                }
                let (bound, towards) =
                    spheres_bound(self.cover(placed, i), None, self.cover(placed, j), best);
                if bound.max(other) >= best {
                    return best;
                }
                return world.pair_distance_hinted(self.group, i, j, poses, (best, precision), towards);
            }
            None => spheres_bound(self.cover(placed, i), None, self.cover(placed, j), best),
        };
        if bound >= best {
            return best;
        }
        let bound = bound.max(other());
        if bound >= best {
            return best;
        }
        if bound >= enough {
            return bound;
        }
        world.pair_distance_hinted(self.group, i, j, poses, (best, precision), towards)
    }

    /// A lower bound on the distance between bodies `i` and `j`, capped at `cap` (covers only).
    pub fn pair_bound(&self, i: usize, j: usize, placed: &PlacedCovers, cap: f64) -> f64 {
        self.pair_bound_towards(i, j, placed, cap).0
    }

    /// [`BroadPhase::pair_bound`] with the direction from `i` towards `j` that gives it.
    fn pair_bound_towards(&self, i: usize, j: usize, placed: &PlacedCovers, cap: f64) -> (f64, DVec3) {
        let best = sanitize_margin(cap);
        self.outer_pair(i, j, placed, best)
            .unwrap_or_else(|| spheres_bound(self.cover(placed, i), None, self.cover(placed, j), best))
    }

    /// [`BroadPhase::pair_bound_towards`] capped at `best` (sanitized) where the covers are not
    /// needed: a body without shapes, the same body twice or two outer spheres `best` apart
    /// (`best`), a pose not finite (0); `None` where the covers are.
    #[inline]
    fn outer_pair(&self, i: usize, j: usize, placed: &PlacedCovers, best: f64) -> Option<(f64, DVec3)> {
        let ((Some(oa), finite_a), (Some(ob), finite_b)) =
            (self.outer_placed(placed, i), self.outer_placed(placed, j))
        else {
            return Some((best, DVec3::ZERO));
        };
        if i == j {
            return Some((best, DVec3::ZERO));
        }
        if !finite_a || !finite_b {
            return Some((0.0, DVec3::ZERO));
        }
        if oa.apart_by(&ob, best) {
            return Some((best, DVec3::ZERO));
        }
        None
    }

    /// Lower bound on the distance from `spheres` (held by the sphere `outer`) to `object`,
    /// capped at `best`, with the direction (world) from the sphere that gives it towards the
    /// object (zero when none does, or when it is inside): a guess of the separating direction
    /// for the exact query.
    fn object_bound(
        &self,
        world: &CollisionWorld,
        object: &Object,
        spheres: &[Cell<Sphere>],
        outer: Sphere,
        best: f64,
    ) -> (f64, DVec3) {
        let mut b = best;
        let mut arg = usize::MAX;
        let mut towards = DVec3::ZERO;
        match &object.kind {
            Kind::Cuboid {
                to_local,
                centre,
                half,
            } => {
                for (k, s) in spheres.iter().map(Cell::get).enumerate() {
                    let p = *to_local * (s.centre - *centre);
                    let gap = (p.abs() - *half).max(DVec3::ZERO);
                    // Only a sphere that comes closer than `b` needs its square root (most of a
                    // cover's are farther than the bound so far).
                    if reaches(gap.length_squared(), b + s.radius) {
                        continue;
                    }
                    let d = gap.length() - s.radius;
                    if d < b {
                        (b, arg) = (d, k);
                    }
                }
                if let Some(s) = spheres.get(arg).map(Cell::get) {
                    let p = *to_local * (s.centre - *centre);
                    towards = to_local.transpose() * (p.clamp(-*half, *half) - p);
                }
            }
            Kind::Cylinder {
                to_local,
                centre,
                radius,
                half_height,
            } => {
                for (k, s) in spheres.iter().map(Cell::get).enumerate() {
                    let p = *to_local * (s.centre - *centre);
                    let radial = (p.x * p.x + p.z * p.z).sqrt() - radius;
                    let axial = p.y.abs() - half_height;
                    let d = radial.max(0.0).hypot(axial.max(0.0)) - s.radius;
                    if d < b {
                        (b, arg) = (d, k);
                    }
                }
                if let Some(s) = spheres.get(arg).map(Cell::get) {
                    let p = *to_local * (s.centre - *centre);
                    let r = (p.x * p.x + p.z * p.z).sqrt();
                    let shrink = if r > *radius { radius / r } else { 1.0 };
                    let q = DVec3::new(p.x * shrink, p.y.clamp(-half_height, *half_height), p.z * shrink);
                    towards = to_local.transpose() * (q - p);
                }
            }
            Kind::Ball { centre, radius } => {
                for (k, s) in spheres.iter().map(Cell::get).enumerate() {
                    let v = s.centre - *centre;
                    if reaches(v.length_squared(), b + radius + s.radius) {
                        continue;
                    }
                    let d = v.length() - radius - s.radius;
                    if d < b {
                        (b, arg) = (d, k);
                    }
                }
                if let Some(s) = spheres.get(arg).map(Cell::get) {
                    towards = *centre - s.centre;
                }
            }
            Kind::Other => {
                let st = &world.statics[object.index];
                let Some(shape) = st.shape.as_deref() else {
                    return (best, DVec3::ZERO);
                };
                let solid = shape.as_trimesh().is_none();
                for s in spheres.iter().map(Cell::get) {
                    if sphere_box_apart(s.centre, s.radius, object.mins, object.maxs, b) {
                        continue;
                    }
                    let reach = b + s.radius;
                    if let Some(proj) = shape.project_point_with_max_dist(&st.pose, s.centre, solid, reach) {
                        let d = if solid && proj.is_inside {
                            0.0
                        } else {
                            (proj.point - s.centre).length()
                        };
                        if d - s.radius < b {
                            b = d - s.radius;
                            towards = proj.point - s.centre;
                        }
                    }
                    if b <= 0.0 {
                        return (0.0, towards);
                    }
                }
            }
            Kind::Body { spheres: range, .. } => {
                return spheres_bound(spheres, Some(outer), &self.parked[range.clone()], b);
            }
        }
        (b.max(0.0), towards)
    }
}

/// Lower bound on the distance between two sphere sets, capped at `best`, with the direction
/// from the sphere of `a` towards the sphere of `b` that give it (zero when no pair does).
/// `holder`, a sphere holding every sphere of `a` (its outer sphere), lets a sphere of `b`
/// that is farther from it than the bound so far be passed over ([`outers_apart`], with its
/// nanometre of slack against rounding): no sphere of `a` comes closer, so the answer is that
/// of every pair.
#[inline(always)]
fn spheres_bound<B: SphereRead>(
    a: &[Cell<Sphere>],
    holder: Option<Sphere>,
    b: &[B],
    best: f64,
) -> (f64, DVec3) {
    let mut least = best;
    let mut arg = (usize::MAX, usize::MAX);
    for (kb, sb) in b.iter().map(SphereRead::read).enumerate() {
        if outers_apart(holder, Some(sb), least) {
            continue;
        }
        for (ka, sa) in a.iter().map(Cell::get).enumerate() {
            let v = sb.centre - sa.centre;
            // Only a pair that comes closer than `least` needs its square root.
            if reaches(v.length_squared(), least + sa.radius + sb.radius) {
                continue;
            }
            let d = v.length() - sa.radius - sb.radius;
            if d < least {
                (least, arg) = (d, (ka, kb));
            }
        }
    }
    let towards = match (a.get(arg.0), b.get(arg.1)) {
        (Some(sa), Some(sb)) => sb.read().centre - sa.get().centre,
        _ => DVec3::ZERO,
    };
    (least.max(0.0), towards)
}

/// A sphere as stored: placed lazily (in a [`Cell`]) or fixed.
trait SphereRead {
    fn read(&self) -> Sphere;
}

impl SphereRead for Sphere {
    #[inline]
    fn read(&self) -> Sphere {
        *self
    }
}

impl SphereRead for Cell<Sphere> {
    #[inline]
    fn read(&self) -> Sphere {
        self.get()
    }
}

#[cfg(test)]
mod tests;

//! The exact narrow phase of the world: GJK decisions and distances between convex shapes, and
//! between a triangle mesh and a convex shape (a BVH walk with cached separating axes).
use super::{Placed, StaticObject, aabb_distance, box_overlap, loosened, overlap};
use crate::{DVec3, Pose};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::partitioning::TraversalAction;
use parry3d_f64::query;
use parry3d_f64::query::gjk::{self, CsoPoint, GJKResult, VoronoiSimplex};
use parry3d_f64::shape::{Shape, SupportMap, TriMesh, Triangle};
use std::cell::{Cell, RefCell};

/// The AABB, in the frame where it stands at `pose`, of a convex shape (six support queries).
pub(super) fn support_aabb(support: &dyn SupportMap, pose: &Pose) -> Aabb {
    let mut mins = DVec3::ZERO;
    let mut maxs = DVec3::ZERO;
    for (i, axis) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
        maxs[i] = support.support_point(pose, axis)[i];
        mins[i] = support.support_point(pose, -axis)[i];
    }
    Aabb::new(mins, maxs)
}

/// Whether a static object and a placed body are closer than `margin` (`margin ≥ 0`).
///
/// Convex pairs run GJK without exact distance: it stops as soon as it proves the distance
/// above or below the margin. A triangle mesh is handled by [`mesh_within`].
pub(super) fn static_within(s: &StaticObject, shape: &dyn Shape, b: &Placed, margin: f64) -> bool {
    let pos12 = s.pose.inv_mul(&b.pose);
    if let Some(c) = shape.as_support_map() {
        convex_within(&pos12, c, b.support, margin)
    } else if let Some(mesh) = shape.as_trimesh() {
        mesh_within(&pos12, mesh, b.support, margin)
    } else {
        // Never built by this crate; kept for safety. An unsupported pair counts as touching.
        !matches!(
            query::closest_points(&s.pose, shape, &b.pose, b.shape, margin),
            Ok(query::ClosestPoints::Disjoint)
        )
    }
}

/// GJK decision "distance ≤ margin" for two convex shapes; `pos12` places `g2` in `g1`'s frame.
#[inline]
pub(super) fn convex_within<G1, G2>(pos12: &Pose, g1: &G1, g2: &G2, margin: f64) -> bool
where
    G1: ?Sized + SupportMap,
    G2: ?Sized + SupportMap,
{
    !matches!(
        convex_gjk(pos12, g1, g2, margin, false, None),
        GJKResult::NoIntersection(_)
    )
}

/// A GJK run; `init` seeds the search direction, pointing from `g1` towards `g2`.
#[inline]
pub(super) fn convex_gjk<G1, G2>(
    pos12: &Pose,
    g1: &G1,
    g2: &G2,
    max_dist: f64,
    exact: bool,
    init: Option<DVec3>,
) -> GJKResult
where
    G1: ?Sized + SupportMap,
    G2: ?Sized + SupportMap,
{
    // GJK's CSO is g1 − g2, so its first direction points from g2 towards g1.
    let dir = init
        .map(|d| -d)
        .or_else(|| (-pos12.translation).try_normalize())
        .unwrap_or(DVec3::X);
    let mut simplex = VoronoiSimplex::new();
    simplex.reset(CsoPoint::from_shapes(pos12, g1, g2, dir));
    gjk::closest_points(pos12, g1, g2, max_dist, exact, &mut simplex)
}

/// Whether a triangle mesh (frame 1) and a convex shape (at `pos12` in the mesh's frame) are
/// closer than `margin`.
///
/// Walks the mesh's BVH, pruning nodes and triangles that lie outside the convex shape's box
/// (loosened by the margin) or beyond an axis that already separated a triangle, then tries
/// the triangle's plane as a separating axis, and runs GJK on the rest, stopping at the first
/// triangle within the margin. Each separating axis found (plane or GJK) is cached: along a
/// panel, one axis usually disposes of the neighbouring triangles and whole BVH nodes.
pub(super) fn mesh_within(pos12: &Pose, mesh: &TriMesh, convex: &dyn SupportMap, margin: f64) -> bool {
    let query = loosened(&support_aabb(convex, pos12), margin);
    if !overlap(&query, &mesh.local_aabb()) {
        return false;
    }
    let mut cache = AxisCache::default();
    let centre = query.center();
    let mut hit = false;
    mesh.bvh().traverse(|node| {
        let (lo, hi) = (node.mins(), node.maxs());
        if !box_overlap(&query, lo, hi) || cache.separates_box(lo, hi) {
            return TraversalAction::Prune;
        }
        let Some(i) = node.leaf_data() else {
            return TraversalAction::Continue;
        };
        let t = mesh.triangle(i);
        if cache.separates(&t) {
            return TraversalAction::Continue;
        }
        // The triangle's plane often separates (a link above a panel), for one support query.
        if let Some(n) = (t.b - t.a).cross(t.c - t.a).try_normalize() {
            let n = if n.dot(centre - t.a) < 0.0 { -n } else { n };
            let lowest = n.dot(convex.support_point(pos12, -n));
            if lowest - margin > n.dot(t.a) {
                cache.push(n, lowest - margin);
                return TraversalAction::Continue;
            }
        }
        match convex_gjk(pos12, &t, convex, margin, false, cache.last_dir()) {
            GJKResult::NoIntersection(dir) => {
                // The convex shape lies beyond the triangle along `dir`: remember by how much.
                let lowest = dir.dot(convex.support_point(pos12, -dir));
                cache.push(dir, lowest - margin);
                TraversalAction::Continue
            }
            _ => {
                hit = true;
                TraversalAction::EarlyExit
            }
        }
    });
    hit
}

/// The last few axes that separated a triangle from the convex shape, each with the shape's
/// lowest projection on it minus the margin. Neighbouring triangles (and whole BVH nodes) are
/// usually separated by the same axis: testing it costs a dot product or three instead of a
/// GJK run.
#[derive(Default)]
pub(super) struct AxisCache {
    axes: [(DVec3, f64); 4],
    len: usize,
    next: usize,
}

/// The highest projection of a triangle on `d`.
#[inline]
pub(super) fn triangle_top(d: DVec3, t: &Triangle) -> f64 {
    d.dot(t.a).max(d.dot(t.b)).max(d.dot(t.c))
}

/// The highest projection on `d` of the box with centre `c` and half extents `e`.
#[inline]
pub(super) fn box_top(d: DVec3, c: DVec3, e: DVec3) -> f64 {
    d.dot(c) + d.abs().dot(e)
}

impl AxisCache {
    #[inline]
    fn separates(&self, t: &Triangle) -> bool {
        self.axes[..self.len]
            .iter()
            .any(|&(d, limit)| triangle_top(d, t) < limit)
    }

    #[inline]
    fn separates_box(&self, mins: DVec3, maxs: DVec3) -> bool {
        let (c, e) = ((mins + maxs) * 0.5, (maxs - mins) * 0.5);
        self.axes[..self.len]
            .iter()
            .any(|&(d, limit)| box_top(d, c, e) < limit)
    }

    /// The largest gap `limit − max(axis · vertex)` over the cached axes (−∞ when empty): with
    /// limits that are the convex shape's lowest projections, a lower bound on the distance
    /// from the triangle to the shape.
    #[inline]
    pub(super) fn triangle_gap(&self, t: &Triangle) -> f64 {
        self.axes[..self.len]
            .iter()
            .map(|&(d, limit)| limit - triangle_top(d, t))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// [`AxisCache::triangle_gap`] for everything inside the box `mins..maxs`.
    #[inline]
    pub(super) fn box_gap(&self, mins: DVec3, maxs: DVec3) -> f64 {
        let (c, e) = ((mins + maxs) * 0.5, (maxs - mins) * 0.5);
        self.axes[..self.len]
            .iter()
            .map(|&(d, limit)| limit - box_top(d, c, e))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    pub(super) fn push(&mut self, dir: DVec3, limit: f64) {
        self.axes[self.next] = (dir, limit);
        self.next = (self.next + 1) % self.axes.len();
        self.len = (self.len + 1).min(self.axes.len());
    }

    fn last_dir(&self) -> Option<DVec3> {
        (self.len > 0).then(|| self.axes[(self.next + self.axes.len() - 1) % self.axes.len()].0)
    }
}

/// Exact distance between a static object and a placed body (0 when they overlap), if it is
/// below `best`; `None` otherwise.
pub(super) fn static_distance(s: &StaticObject, shape: &dyn Shape, b: &Placed, best: f64) -> Option<f64> {
    static_distance_hinted(s, shape, b, best, DVec3::ZERO, Precision::EXACT)
}

/// [`static_distance`] with a guess of the separating direction for convex objects:
/// `towards`, in the world, from the body towards the object (zero for none; see
/// [`hinted_distance`]), to `precision` (see there).
pub(super) fn static_distance_hinted(
    s: &StaticObject,
    shape: &dyn Shape,
    b: &Placed,
    best: f64,
    towards: DVec3,
    precision: Precision,
) -> Option<f64> {
    let pos12 = s.pose.inv_mul(&b.pose);
    if let Some(c) = shape.as_support_map() {
        // From the object (shape 1) towards the body, in the object's frame.
        let seed = s.pose.rotation.inverse() * -towards;
        Some(hinted_distance(&pos12, c, b.support, (best, precision), seed)).filter(|&d| d < best)
    } else if let Some(mesh) = shape.as_trimesh() {
        mesh_distance(&pos12, mesh, b.support, (best, precision))
    } else {
        let d = query::distance(&s.pose, shape, &b.pose, b.shape).map_or(0.0, |d| d.distance);
        (d < best).then_some(d.max(0.0))
    }
}

/// Exact distance between a triangle mesh (frame 1) and a convex shape (at `pos12` in the
/// mesh's frame), 0 when they touch, if below `best`; `None` otherwise. With a [`Precision`]
/// whose share is positive each triangle's GJK stops as [`distance_within`] does, seeded with
/// the axis cached last (a neighbour's), and the answer may fall short of the distance as that
/// allows.
///
/// The BVH is searched nearest box first. Every axis that separated a triangle from the
/// convex shape (the GJK witness direction, or the direction that proved a triangle beyond
/// `best`) is cached with the shape's lowest projection on it: the gap along such an axis is
/// a lower bound on the distance of any other triangle or BVH node, usually a tight one for
/// the neighbours of the nearest triangle, so most of them are dismissed without GJK.
pub(super) fn mesh_distance(
    pos12: &Pose,
    mesh: &TriMesh,
    convex: &dyn SupportMap,
    (best, precision): (f64, Precision),
) -> Option<f64> {
    let query = support_aabb(convex, pos12);
    let cache = RefCell::new(AxisCache::default());
    let convex = Recording {
        inner: convex,
        last: Cell::new((DVec3::ZERO, DVec3::ZERO)),
    };
    // Caches `dir` (pointing from the triangle towards the shape) with the shape's lowest
    // projection on it; GJK's last support query was usually that very one.
    let remember = |dir: DVec3| {
        let (asked, point) = convex.last.get();
        let point = if asked == -dir {
            point
        } else {
            convex.support_point(pos12, -dir)
        };
        cache.borrow_mut().push(dir, dir.dot(point));
    };
    mesh.bvh()
        .find_best(
            best,
            |node, _| {
                let (lo, hi) = (node.mins(), node.maxs());
                aabb_distance(&query, &Aabb::new(lo, hi)).max(cache.borrow().box_gap(lo, hi))
            },
            |i, best| {
                let t = mesh.triangle(i);
                if cache.borrow().triangle_gap(&t) >= best {
                    return None;
                }
                if precision.share > 0.0 {
                    // The direction of the bound found separates the triangle by it.
                    let seed = cache.borrow().last_dir().unwrap_or(DVec3::ZERO);
                    let (d, dir) = distance_within(pos12, &t, &convex, (best, precision), seed);
                    if dir != DVec3::ZERO {
                        remember(dir);
                    }
                    return (d < best).then_some(d);
                }
                match convex_gjk(pos12, &t, &convex, best, true, None) {
                    GJKResult::ClosestPoints(p1, p2, _) => {
                        let d = (p2 - p1).length();
                        if d <= 0.0 {
                            return Some(0.0);
                        }
                        let n = (p2 - p1) / d;
                        // Certified from below, as in `hinted_distance`.
                        let gap = n.dot(convex.support_point(pos12, -n)) - n.dot(t.local_support_point(n));
                        remember(n);
                        let d = gap.clamp(0.0, d);
                        (d < best).then_some(d)
                    }
                    GJKResult::Intersection => Some(0.0),
                    GJKResult::NoIntersection(dir) => {
                        remember(dir);
                        None
                    }
                    GJKResult::Proximity(_) => None,
                }
            },
        )
        .map(|(_, d)| d)
}

/// A support map that remembers its last world-frame query `(direction, support point)`.
struct Recording<'a> {
    inner: &'a dyn SupportMap,
    last: Cell<(DVec3, DVec3)>,
}

impl SupportMap for Recording<'_> {
    #[inline]
    fn local_support_point(&self, dir: DVec3) -> DVec3 {
        self.inner.local_support_point(dir)
    }

    #[inline]
    fn support_point(&self, transform: &Pose, dir: DVec3) -> DVec3 {
        let p = self.inner.support_point(transform, dir);
        self.last.set((dir, p));
        p
    }
}

/// Distance between two convex shapes capped at `best` (0 when they overlap), certified
/// from below (never above the true distance; see the witness gap below), with a guess of the
/// separating direction: `seed` (in `g1`'s frame, from `g1` towards `g2`; zero for none) is
/// tried first — the gap between the two shapes' supports along any direction is a lower
/// bound on their distance, so a gap that reaches `best` answers without GJK — then seeds GJK.
/// With [`Precision::EXACT`] the answer is the exact distance (GJK run to convergence, less its
/// tolerance); else it may fall short of it as `precision` allows ([`distance_within`]). The
/// answer is a function of the shapes, their placement, `best`, `precision` and `seed` alone.
pub(super) fn hinted_distance<G1, G2>(
    pos12: &Pose,
    g1: &G1,
    g2: &G2,
    (best, precision): (f64, Precision),
    seed: DVec3,
) -> f64
where
    G1: ?Sized + SupportMap,
    G2: ?Sized + SupportMap,
{
    let seed = seed.try_normalize().unwrap_or(DVec3::ZERO);
    if precision.share > 0.0 {
        return distance_within(pos12, g1, g2, (best, precision), seed).0;
    }
    if seed != DVec3::ZERO {
        let gap = seed.dot(g2.support_point(pos12, -seed)) - seed.dot(g1.local_support_point(seed));
        if gap >= best {
            return best;
        }
    }
    match convex_gjk(pos12, g1, g2, best, true, (seed != DVec3::ZERO).then_some(seed)) {
        GJKResult::ClosestPoints(p1, p2, _) => {
            let v = p2 - p1;
            let d = v.length();
            if d <= 0.0 {
                return 0.0;
            }
            let n = v / d;
            // GJK's distance is that of two witness points: at or above the true distance,
            // by its tolerance (or more, where it stalls). The gap of the supports along the
            // witness direction is below it: the certified answer.
            let gap = n.dot(g2.support_point(pos12, -n)) - n.dot(g1.local_support_point(n));
            gap.clamp(0.0, d).min(best)
        }
        GJKResult::Intersection => 0.0,
        GJKResult::NoIntersection(_) | GJKResult::Proximity(_) => best,
    }
}

/// How close to the exact distance a capped query must come. Its answer is never above the
/// distance; with `share` 0 ([`Precision::EXACT`]) it is the distance (less GJK's tolerance),
/// else it may fall short by `share` of the distance's excess over `above`: at least
/// `above + (1 − share)·(distance − above)` where the distance reaches `above`, below `above`
/// where it does not — a caller comparing the answer with `above` decides as the exact
/// distance would, and a segment step whose floor is `above` takes the same steps to within
/// the share ([`crate::BroadPhase::scene_distance_enough`]). GJK converges fast at first and
/// slowly at the end: the last bits of a distance far above `above` cost the most.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Precision {
    /// The share of the excess over `above` the answer may lose (0 to 1; 0: exact).
    pub share: f64,
    /// The distance (m) the answer must be exact about: below it or not.
    pub above: f64,
}

impl Precision {
    /// The exact distance.
    pub const EXACT: Precision = Precision {
        share: 0.0,
        above: 0.0,
    };
}

/// Most GJK iterations of [`distance_within`] (a run that has not converged by then answers
/// with the lower bound it has).
const WITHIN_ITERATIONS: usize = 64;

/// [`hinted_distance`] to a [`Precision`] whose share is positive (the seed normalised or
/// zero): GJK on the shapes' difference, where each support query gives a lower bound on the
/// distance (the gap of the two supports along the query direction, the largest one so far
/// kept) and the simplex's nearest point an upper bound (the simplex lies in the difference).
/// It stops as soon as the lower bound reaches `best` (answer `best`), the upper one falls
/// below `above`, or the two come within `share` of the upper one's excess over `above`, and
/// answers the lower bound: never above the distance, below `above` where the distance is, and
/// else at least `above + (1 − share)·(min(distance, best) − above)`. The origin reached
/// answers 0, a contact; a run that stalls or reaches [`WITHIN_ITERATIONS`] answers the lower
/// bound it has (0 if none is positive: on the safe side). With the answer, the unit direction
/// (from `g1` towards `g2`) whose gap gave it (zero where the answer is 0 without one).
fn distance_within<G1, G2>(
    pos12: &Pose,
    g1: &G1,
    g2: &G2,
    (best, precision): (f64, Precision),
    seed: DVec3,
) -> (f64, DVec3)
where
    G1: ?Sized + SupportMap,
    G2: ?Sized + SupportMap,
{
    // From g1 towards g2: the difference g1 − g2 lies the other way from the origin, and its
    // support along this direction is its point nearest the origin along it.
    let first = if seed != DVec3::ZERO {
        seed
    } else {
        pos12.translation.try_normalize().unwrap_or(DVec3::X)
    };
    let point = CsoPoint::from_shapes(pos12, g1, g2, first);
    let (mut lower, mut along) = (-first.dot(point.point), first);
    if lower >= best {
        return (best, along);
    }
    let mut simplex = VoronoiSimplex::new();
    simplex.reset(point);
    for _ in 0..WITHIN_ITERATIONS {
        let nearest = simplex.project_origin_and_reduce();
        let upper = nearest.length();
        if upper.is_nan() || upper <= 0.0 {
            return (0.0, DVec3::ZERO);
        }
        let dir = -nearest / upper;
        let point = CsoPoint::from_shapes(pos12, g1, g2, dir);
        let gap = -dir.dot(point.point);
        if gap > lower {
            (lower, along) = (gap, dir);
        }
        if lower >= best {
            return (best, along);
        }
        // Below `above` for certain, or within the share of the excess over it.
        if upper < precision.above
            || upper - lower <= precision.share * (upper - precision.above)
            || !simplex.add_point(point)
        {
            break;
        }
    }
    (lower.clamp(0.0, best), along)
}

//! Distance queries of the collision world: capped, exact (certified from below) distances
//! between bodies and the static scene, between bodies of one group and of two groups.
use super::narrow::{Precision, hinted_distance, static_distance, static_distance_hinted};
use super::{CollisionWorld, GroupId, Placed, Placement, aabb_distance, place, place_with, sanitize_margin};
use crate::{DVec3, Pose, Sphere};
use parry3d_f64::shape::SupportMap;

impl CollisionWorld {
    /// Distance from body `i` of `g` (at `poses[i]`) to every body of group `other` (at
    /// `other_poses`), capped at `cap`: `min(true distance, cap)`, 0 when touching or at a
    /// non-finite pose. A NaN or negative cap counts as 0; a missing pose or a body without
    /// shapes gives the cap.
    pub fn body_group_distance(
        &self,
        g: GroupId,
        i: usize,
        poses: &[Pose],
        other: GroupId,
        other_poses: &[Pose],
        cap: f64,
    ) -> f64 {
        let mut best = sanitize_margin(cap);
        let (Some(body), Some(pose)) = (self.group(g).bodies.get(i), poses.get(i)) else {
            return best;
        };
        let pa = match place(body, pose) {
            Placement::Empty => return best,
            Placement::Invalid => return 0.0,
            Placement::At(p) => p,
        };
        for (b, p) in self.group(other).bodies.iter().zip(other_poses) {
            match place(b, p) {
                Placement::Empty => {}
                Placement::Invalid => return 0.0,
                Placement::At(pb) => best = placed_distance(&pa, &pb, best),
            }
            if best <= 0.0 {
                return 0.0;
            }
        }
        best
    }

    /// Smallest distance between any body of `a` (at `poses_a`) and any body of another group
    /// `b` (at `poses_b`), capped at `cap`: `min(true distance, cap)`, 0 when two bodies touch
    /// or a pose is not finite (as [`CollisionWorld::body_group_distance`] body by body would
    /// give it, each capped at the best so far, so a small cap is fast: every body is placed
    /// once, and the exact query runs only for the body pairs whose sphere covers come closer
    /// than the best so far). A NaN or negative cap counts as 0.
    pub fn group_group_distance(
        &self,
        a: GroupId,
        poses_a: &[Pose],
        b: GroupId,
        poses_b: &[Pose],
        cap: f64,
    ) -> f64 {
        self.group_group_distance_from(a, poses_a, b, poses_b, cap, &mut None)
    }

    /// [`CollisionWorld::group_group_distance`], asking the body pair `closest` (body of `a`,
    /// body of `b`) first and leaving there the pair found closest (unchanged when none came
    /// within `cap`). The answer is the same whatever `closest` says; when it names the pair
    /// that is closest now — as it mostly does for the next sample of a motion — the best so
    /// far is small from the start and most other pairs are settled by their sphere covers.
    pub fn group_group_distance_from(
        &self,
        a: GroupId,
        poses_a: &[Pose],
        b: GroupId,
        poses_b: &[Pose],
        cap: f64,
        closest: &mut Option<(usize, usize)>,
    ) -> f64 {
        let mut best = sanitize_margin(cap);
        // Each body's outer sphere placed first; its placement and sphere cover in the world
        // only when a pair's outer spheres come within `best` (most do not), once. A body
        // pair whose covers are already at least `best` apart needs no exact query (the
        // covers hold the bodies), nor one whose outer spheres are `best` apart.
        let (Some(pa), Some(pb)) = (LazyBody::of(self, a, poses_a), LazyBody::of(self, b, poses_b)) else {
            return 0.0;
        };
        let mut found = None;
        let mut ask = |i: usize, j: usize, best: &mut f64| {
            let (x, y) = (&pa[i], &pb[j]);
            if outers_apart(x.outer, y.outer, *best) {
                return;
            }
            if let ((Placement::At(px), cover_x), (Placement::At(py), cover_y)) = (x.placed(), y.placed())
                && covers_within(cover_x, x.outer, cover_y, *best)
            {
                let d = placed_distance(px, py, *best);
                if d < *best {
                    *best = d;
                    found = Some((i, j));
                }
            }
        };
        let first = closest.filter(|&(i, j)| i < pa.len() && j < pb.len());
        if let Some((i, j)) = first {
            ask(i, j, &mut best);
        }
        'pairs: for i in 0..pa.len() {
            for j in 0..pb.len() {
                if best <= 0.0 {
                    break 'pairs;
                }
                if first != Some((i, j)) {
                    ask(i, j, &mut best);
                }
            }
        }
        if found.is_some() {
            *closest = found;
        }
        best.max(0.0)
    }

    /// Smallest distance from any body of `g` to the static scene (0 when touching).
    ///
    /// Exact (up to the convex hulls of the bodies), so slower than
    /// [`CollisionWorld::group_vs_static`]. `f64::INFINITY` when the group has no body with
    /// shapes or the scene has no object.
    pub fn min_distance_to_static(&self, g: GroupId, poses: &[Pose]) -> f64 {
        let group = self.group(g);
        debug_assert_eq!(poses.len(), group.bodies.len(), "one pose per body");
        let mut best = f64::INFINITY;
        for i in 0..group.bodies.len().min(poses.len()) {
            best = self.body_static_distance(g, i, poses, best);
            if best <= 0.0 {
                return 0.0;
            }
        }
        best
    }

    /// Smallest distance from the bodies of `g` that are **not** exempt (see
    /// [`CollisionWorld::set_static_exempt`]) to the static scene, capped at `cap`: the result
    /// is `min(true distance, cap)` (0 when touching), for distance-based motion checks.
    ///
    /// The cap prunes the search (objects, BVH nodes and triangles whose box is at least `cap`
    /// away are skipped), so a small cap is much faster than
    /// [`CollisionWorld::min_distance_to_static`], which also measures exempt bodies. A
    /// non-finite pose of a non-exempt body gives 0 (when the scene has an object); a NaN or
    /// negative cap counts as 0.
    pub fn group_static_distance(&self, g: GroupId, poses: &[Pose], cap: f64) -> f64 {
        let group = self.group(g);
        debug_assert_eq!(poses.len(), group.bodies.len(), "one pose per body");
        let mut best = sanitize_margin(cap);
        for i in 0..group.bodies.len().min(poses.len()) {
            if !group.exempt[i] {
                best = self.body_static_distance(g, i, poses, best);
                if best <= 0.0 {
                    return 0.0;
                }
            }
        }
        best
    }

    /// Distance from body `i` of `g` (at `poses[i]`) to the static scene, capped at `cap`:
    /// `min(true distance, cap)`, 0 when touching or at a non-finite pose (when the scene has
    /// an object). Exemption is not consulted. A NaN or negative cap counts as 0; a missing
    /// pose or a body without shapes gives the cap.
    pub fn body_static_distance(&self, g: GroupId, i: usize, poses: &[Pose], cap: f64) -> f64 {
        let mut best = sanitize_margin(cap);
        let (Some(body), Some(pose)) = (self.group(g).bodies.get(i), poses.get(i)) else {
            return best;
        };
        let placed = match place(body, pose) {
            Placement::Empty => return best,
            Placement::Invalid => {
                return if self.first_solid_static().is_some() {
                    0.0
                } else {
                    best
                };
            }
            Placement::At(p) => p,
        };
        for s in &self.statics {
            let Some(shape) = s.shape.as_deref() else {
                continue;
            };
            if aabb_distance(&placed.aabb, &s.aabb) >= best {
                continue;
            }
            if let Some(d) = static_distance(s, shape, &placed, best) {
                best = d;
                if best <= 0.0 {
                    return 0.0;
                }
            }
        }
        best
    }

    /// Distance from body `i` of `g` (at `poses[i]`) to static object `object` alone, capped at
    /// `cap` (as [`CollisionWorld::body_static_distance`] measures each object). The cap for an
    /// object without geometry, a missing pose or a body without shapes; 0 at a non-finite pose.
    pub fn body_object_distance(&self, g: GroupId, i: usize, poses: &[Pose], object: usize, cap: f64) -> f64 {
        self.body_object_distance_hinted(g, i, poses, object, (cap, Precision::EXACT), DVec3::ZERO)
    }

    /// [`CollisionWorld::body_object_distance`] with a guess of the separating direction:
    /// `towards`, in the world, from the body towards the object (zero for none). Any
    /// direction gives a lower bound (the gap between the supports), which answers when it
    /// reaches the cap; else it seeds GJK. Meshes keep their own axis cache and ignore it. Of
    /// `(cap, precision)`, the answer may fall short of `min(distance, cap)` as the
    /// [`Precision`] allows, and GJK stops sooner.
    pub fn body_object_distance_hinted(
        &self,
        g: GroupId,
        i: usize,
        poses: &[Pose],
        object: usize,
        (cap, precision): (f64, Precision),
        towards: DVec3,
    ) -> f64 {
        let best = sanitize_margin(cap);
        let (Some(body), Some(pose), Some(s)) = (
            self.group(g).bodies.get(i),
            poses.get(i),
            self.statics.get(object),
        ) else {
            return best;
        };
        let Some(shape) = s.shape.as_deref() else {
            return best;
        };
        let boxed = towards == DVec3::ZERO;
        match place_with(body, pose, boxed) {
            Placement::Empty => best,
            Placement::Invalid => 0.0,
            Placement::At(p) => {
                if boxed && aabb_distance(&p.aabb, &s.aabb) >= best {
                    return best;
                }
                static_distance_hinted(s, shape, &p, best, towards, precision).map_or(best, |d| d.min(best))
            }
        }
    }

    /// Distance from body `i` of `g` (at `poses[i]`) to body `j` of group `other` standing at
    /// `pose`, capped at `cap` (as [`CollisionWorld::body_group_distance`] measures each body).
    #[allow(clippy::too_many_arguments)]
    pub fn body_body_distance(
        &self,
        g: GroupId,
        i: usize,
        poses: &[Pose],
        other: GroupId,
        j: usize,
        pose: &Pose,
        cap: f64,
    ) -> f64 {
        let best = sanitize_margin(cap);
        let (Some(a), Some(pa), Some(b)) = (
            self.group(g).bodies.get(i),
            poses.get(i),
            self.group(other).bodies.get(j),
        ) else {
            return best;
        };
        match (place(a, pa), place(b, pose)) {
            (Placement::Empty, _) | (_, Placement::Empty) => best,
            (Placement::Invalid, _) | (_, Placement::Invalid) => 0.0,
            (Placement::At(a), Placement::At(b)) => placed_distance(&a, &b, best),
        }
    }

    /// Smallest distance between the checked self pairs of `g` (see
    /// [`CollisionWorld::set_self_pairs`]), capped at `cap`: `min(true distance, cap)`, 0 when
    /// a pair touches or a pose is not finite. `cap` (at least 0) when no pair is checked.
    pub fn group_self_distance(&self, g: GroupId, poses: &[Pose], cap: f64) -> f64 {
        let group = self.group(g);
        debug_assert_eq!(poses.len(), group.bodies.len(), "one pose per body");
        let mut best = sanitize_margin(cap);
        for &(i, j) in &group.self_pairs {
            best = self.pair_distance(g, i, j, poses, best);
            if best <= 0.0 {
                return 0.0;
            }
        }
        best
    }

    /// Distance between bodies `i` and `j` of `g` (whether or not the pair is checked), capped
    /// at `cap`: `min(true distance, cap)`, 0 when they touch or a pose is not finite. The cap
    /// (at least 0) when `i == j`, a body has no shapes or a pose is missing.
    pub fn pair_distance(&self, g: GroupId, i: usize, j: usize, poses: &[Pose], cap: f64) -> f64 {
        self.pair_distance_hinted(g, i, j, poses, (cap, Precision::EXACT), DVec3::ZERO)
    }

    /// [`CollisionWorld::pair_distance`] with a guess of the separating direction: `towards`,
    /// in the world, from body `i` towards body `j` (zero for none; see
    /// [`CollisionWorld::body_object_distance_hinted`], which says what `precision` allows).
    pub fn pair_distance_hinted(
        &self,
        g: GroupId,
        i: usize,
        j: usize,
        poses: &[Pose],
        (cap, precision): (f64, Precision),
        towards: DVec3,
    ) -> f64 {
        let group = self.group(g);
        let best = sanitize_margin(cap);
        let (Some(ba), Some(bb), Some(pa), Some(pb)) = (
            group.bodies.get(i),
            group.bodies.get(j),
            poses.get(i),
            poses.get(j),
        ) else {
            return best;
        };
        if i == j {
            return best;
        }
        // A caller with a direction has run a broad phase: no box test.
        let boxed = towards == DVec3::ZERO;
        match (place_with(ba, pa, boxed), place_with(bb, pb, boxed)) {
            (Placement::Empty, _) | (_, Placement::Empty) => best,
            (Placement::Invalid, _) | (_, Placement::Invalid) => 0.0,
            (Placement::At(a), Placement::At(b)) => {
                if boxed && aabb_distance(&a.aabb, &b.aabb) >= best {
                    return best;
                }
                let seed = a.pose.rotation.inverse() * towards;
                hinted_distance(
                    &a.pose.inv_mul(&b.pose),
                    a.support,
                    b.support,
                    (best, precision),
                    seed,
                )
            }
        }
    }
}

/// A body of [`CollisionWorld::group_group_distance_from`]: the sphere around its cover in
/// the world (`None` without a shape or with an empty cover: `Cover::outer`), its placement
/// and cover placed on first use.
struct LazyBody<'a> {
    body: &'a super::Body,
    pose: &'a Pose,
    outer: Option<Sphere>,
    placed: std::cell::OnceCell<(Placement<'a>, Vec<Sphere>)>,
}

impl<'a> LazyBody<'a> {
    /// The bodies of group `g` at `poses`, their outer spheres placed; `None` when a body
    /// with a shape is at a pose that is not finite (touching).
    fn of(world: &'a CollisionWorld, g: GroupId, poses: &'a [Pose]) -> Option<Vec<LazyBody<'a>>> {
        let mut out = Vec::new();
        for (body, pose) in world.group(g).bodies.iter().zip(poses) {
            let outer = match body.convex.as_ref() {
                Some(_) if !pose.is_finite() => return None,
                Some(c) => c.cover.outer.map(|s| Sphere {
                    centre: pose.transform_point(s.centre),
                    radius: s.radius,
                }),
                None => None,
            };
            out.push(LazyBody {
                body,
                pose,
                outer,
                placed: std::cell::OnceCell::new(),
            });
        }
        Some(out)
    }

    /// The body placed with its sphere cover in the world (empty without a shape).
    fn placed(&self) -> &(Placement<'a>, Vec<Sphere>) {
        self.placed.get_or_init(|| {
            let p = place(self.body, self.pose);
            let cover = match (&p, self.body.convex.as_ref()) {
                (Placement::At(_), Some(c)) => c
                    .cover
                    .spheres
                    .iter()
                    .map(|s| Sphere {
                        centre: self.pose.transform_point(s.centre),
                        radius: s.radius,
                    })
                    .collect(),
                _ => Vec::new(),
            };
            (p, cover)
        })
    }
}

/// Whether the spheres around two covers show that no sphere of one comes within `d` of a
/// sphere of the other (so [`covers_within`] would say no); a nanometre of slack for the
/// rounding of the placed centres. False when either cover is empty (has no outer sphere).
/// A single sphere of a cover is the sphere around itself, so this also says that no sphere
/// held by `oa` comes within `d` of the sphere `ob`.
pub(super) fn outers_apart(oa: Option<Sphere>, ob: Option<Sphere>, d: f64) -> bool {
    match (oa, ob) {
        (Some(oa), Some(ob)) => oa.apart_by(&ob, d + OUTER_SLACK),
        _ => false,
    }
}

/// See [`outers_apart`] (m).
const OUTER_SLACK: f64 = 1e-9;

/// Whether two sphere covers may come closer than `d`: false when every sphere pair is at
/// least `d` apart (empty covers: true, nothing is known). `outer_a`, a sphere holding every
/// sphere of `a`, passes over the spheres of `b` at least `d` (and [`OUTER_SLACK`]) from it:
/// no sphere of `a` comes closer to them, so the answer is that of every pair.
fn covers_within(a: &[Sphere], outer_a: Option<Sphere>, b: &[Sphere], d: f64) -> bool {
    if a.is_empty() || b.is_empty() {
        return true;
    }
    b.iter().any(|q| {
        !outers_apart(outer_a, Some(*q), d)
            && a.iter()
                .any(|p| (p.centre - q.centre).length() - p.radius - q.radius < d)
    })
}

/// `min(distance between two placed bodies, best)` (0 when they touch); the AABB test first.
fn placed_distance(a: &Placed, b: &Placed, best: f64) -> f64 {
    if aabb_distance(&a.aabb, &b.aabb) >= best {
        return best;
    }
    hinted_distance(
        &a.pose.inv_mul(&b.pose),
        a.support,
        b.support,
        (best, Precision::EXACT),
        DVec3::ZERO,
    )
}

/// Distance between two convex support maps at poses `pa` and `pb` (world), capped at `cap`
/// and certified from below (never above the true distance; 0 when they overlap): for sets a
/// body's shape does not describe, such as a body turned about an axis
/// ([`crate::revolved::Revolved`]).
pub fn convex_distance(pa: &Pose, a: &dyn SupportMap, pb: &Pose, b: &dyn SupportMap, cap: f64) -> f64 {
    if !(pa.is_finite() && pb.is_finite()) {
        return 0.0;
    }
    hinted_distance(
        &pa.inv_mul(pb),
        a,
        b,
        (sanitize_margin(cap), Precision::EXACT),
        DVec3::ZERO,
    )
}

/// Whether two convex support maps at poses `pa` and `pb` (world) overlap, as GJK finds the
/// origin inside their difference. GJK declares an overlap within its tolerance of a touch
/// (far below a micrometre at these scales): a caller that needs a proof of contact asks it of
/// one shape shrunk by more than that.
pub fn convex_overlap(pa: &Pose, a: &dyn SupportMap, pb: &Pose, b: &dyn SupportMap) -> bool {
    if !(pa.is_finite() && pb.is_finite()) {
        return false;
    }
    matches!(
        super::narrow::convex_gjk(&pa.inv_mul(pb), a, b, 1e-9, false, None),
        parry3d_f64::query::gjk::GJKResult::Intersection
    )
}

#[cfg(test)]
mod tests {
    use super::{Sphere, covers_within};
    use crate::DVec3;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A sphere holding the first cover changes no answer of `covers_within`, and passes over
    /// spheres of the second: random covers, with distances at which a pair is just within or
    /// just beyond.
    #[test]
    fn a_holding_sphere_changes_no_answer_of_covers_within() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let cover = |rng: &mut ChaCha8Rng, at: DVec3| -> Vec<Sphere> {
            (0..rng.random_range(1..9))
                .map(|_| Sphere {
                    centre: at
                        + DVec3::new(
                            rng.random_range(-0.4..0.4),
                            rng.random_range(-0.4..0.4),
                            rng.random_range(-0.4..0.4),
                        ),
                    radius: rng.random_range(0.01..0.2),
                })
                .collect()
        };
        let (mut yes, mut no) = (0, 0);
        for _ in 0..500 {
            let a = cover(&mut rng, DVec3::ZERO);
            let at = DVec3::new(rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5), 0.0);
            let b = cover(&mut rng, at);
            let outer = crate::spheres::enclosing(&a);
            let mut ds = vec![0.0, 0.2, 1.0];
            for p in a.iter().take(2) {
                for q in b.iter().take(2) {
                    let d = (p.centre - q.centre).length() - p.radius - q.radius;
                    ds.extend([d, d.next_up(), d.next_down()]);
                }
            }
            for d in ds {
                let want = a.iter().any(|p| {
                    b.iter()
                        .any(|q| (p.centre - q.centre).length() - p.radius - q.radius < d)
                });
                assert_eq!(covers_within(&a, outer, &b, d), want, "d {d}");
                assert_eq!(covers_within(&a, None, &b, d), want, "d {d}");
                if want {
                    yes += 1;
                } else {
                    no += 1;
                }
            }
        }
        assert!(yes > 500 && no > 500, "{yes} within, {no} apart");
    }

    /// Two boxes overlap by GJK's account exactly when they do: 1 mm apart, 1 mm into each
    /// other, and at non-finite poses (no answer, so no overlap).
    #[test]
    fn convex_overlap_tells_overlap_from_a_gap() {
        use crate::Pose;
        use parry3d_f64::shape::Cuboid;
        let b = Cuboid::new(DVec3::splat(0.1));
        let at = |x: f64| Pose::from_parts(DVec3::new(x, 0.0, 0.0), Default::default());
        assert!(super::convex_overlap(&at(0.0), &b, &at(0.199), &b));
        assert!(!super::convex_overlap(&at(0.0), &b, &at(0.201), &b));
        assert!(!super::convex_overlap(&at(0.0), &b, &at(f64::NAN), &b));
    }
}

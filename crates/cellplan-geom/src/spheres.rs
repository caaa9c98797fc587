//! Sphere covers of convex bodies: the broad phase of the collision world.
//!
//! A body's cover is a few spheres whose union **contains the whole convex solid** (not only
//! its vertices), so for any object `O` and any point `p` of the body, lying in some sphere
//! `(c, r)` of the cover, `dist(p, O) ≥ dist(c, O) − r`. The smallest `dist(c, O) − r` over the
//! cover is therefore a lower bound on the body's distance to `O`: cheap (a point query per
//! sphere), and exact enough to dismiss everything not near the body.
//!
//! How the cover is built: the body is cut into slabs along the longest axis of its bounding
//! box (as many as its length holds its width, at most [`MAX_SLABS`]). The part of a convex
//! polyhedron inside a slab is the convex hull of its vertices inside the slab and of the
//! points where its edges cross the slab's two planes; a sphere holding those points holds that
//! part (a sphere is convex). Boxes and cylinders are cut the same way in closed form; a ball is
//! its own cover.
use crate::{DVec3, Pose};
use parry3d_f64::shape::{Shape, TypedShape};

/// Most slabs a body is cut into.
pub const MAX_SLABS: usize = 8;

/// Relative and absolute slack added to every radius, for rounding.
const RADIUS_SLACK: (f64, f64) = (1e-9, 1e-9);

/// A sphere (body frame or world frame, as the context says).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre (m).
    pub centre: DVec3,
    /// Radius (m).
    pub radius: f64,
}

impl Sphere {
    /// The smallest sphere about `centre` holding `points` (a little larger, for rounding).
    fn around(centre: DVec3, points: &[DVec3]) -> Sphere {
        let r = points.iter().map(|p| (*p - centre).length()).fold(0.0, f64::max);
        Sphere {
            centre,
            radius: r * (1.0 + RADIUS_SLACK.0) + RADIUS_SLACK.1,
        }
    }

    /// The sphere about the centre of the bounding box of `points` holding them.
    fn bounding(points: &[DVec3]) -> Option<Sphere> {
        let first = *points.first()?;
        let (lo, hi) = points
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        Some(Sphere::around((lo + hi) * 0.5, points))
    }
}

/// A body's cover with a sphere holding the whole cover (for a first test).
#[derive(Clone, Debug, Default)]
pub struct Cover {
    /// Spheres whose union contains the body (body frame).
    pub spheres: Vec<Sphere>,
    /// A sphere containing every sphere of the cover.
    pub outer: Option<Sphere>,
}

impl Cover {
    /// The cover of `shape` placed at `local` in the body frame; empty for a shape it cannot
    /// cover (no support map and no triangles).
    pub fn of(shape: &dyn Shape, local: &Pose) -> Cover {
        let spheres: Vec<Sphere> = local_cover(shape)
            .into_iter()
            .map(|s| Sphere {
                centre: local.transform_point(s.centre),
                radius: s.radius,
            })
            .collect();
        let outer = enclosing(&spheres);
        Cover { spheres, outer }
    }
}

/// A sphere containing every sphere of `spheres`.
fn enclosing(spheres: &[Sphere]) -> Option<Sphere> {
    let first = spheres.first()?;
    let (lo, hi) = spheres.iter().fold(
        (first.centre - first.radius, first.centre + first.radius),
        |(lo, hi), s| (lo.min(s.centre - s.radius), hi.max(s.centre + s.radius)),
    );
    let c = (lo + hi) * 0.5;
    let r = spheres
        .iter()
        .map(|s| (s.centre - c).length() + s.radius)
        .fold(0.0, f64::max);
    Some(Sphere {
        centre: c,
        radius: r * (1.0 + RADIUS_SLACK.0) + RADIUS_SLACK.1,
    })
}

/// Number of slabs for a body `length` long and `width` wide.
fn slab_count(length: f64, width: f64) -> usize {
    if length.is_nan() || length <= 0.0 || !length.is_finite() {
        return 1;
    }
    if width.is_nan() || width <= 0.0 {
        return MAX_SLABS;
    }
    ((length / width).ceil() as usize).clamp(1, MAX_SLABS)
}

/// The cover in the shape's own frame.
fn local_cover(shape: &dyn Shape) -> Vec<Sphere> {
    match shape.as_typed_shape() {
        TypedShape::Ball(b) => vec![Sphere {
            centre: DVec3::ZERO,
            radius: b.radius,
        }],
        TypedShape::Cuboid(c) => box_cover(c.half_extents),
        TypedShape::Cylinder(c) => cylinder_cover(c.half_height, c.radius),
        TypedShape::ConvexPolyhedron(c) => {
            let edges: Vec<[usize; 2]> = c
                .edges()
                .iter()
                .map(|e| [e.vertices[0] as usize, e.vertices[1] as usize])
                .collect();
            polytope_cover(c.points(), &edges)
        }
        TypedShape::TriMesh(m) => {
            let edges: Vec<[usize; 2]> = m
                .indices()
                .iter()
                .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
                .map(|[a, b]| [a as usize, b as usize])
                .collect();
            polytope_cover(m.vertices(), &edges)
        }
        _ => {
            // Any other shape: the sphere about its bounding box.
            let aabb = shape.compute_local_aabb();
            let c = aabb.center();
            let r = aabb.half_extents().length();
            if r.is_finite() {
                vec![Sphere { centre: c, radius: r }]
            } else {
                Vec::new()
            }
        }
    }
}

/// A box cut along its longest axis: each slab is a box, held by the sphere of its half
/// diagonal.
fn box_cover(half: DVec3) -> Vec<Sphere> {
    let k = half.max_position();
    let width = 2.0 * (0..3).filter(|&i| i != k).map(|i| half[i]).fold(0.0, f64::max);
    let n = slab_count(2.0 * half[k], width);
    let mut slab = half;
    slab[k] = half[k] / n as f64;
    let radius = slab.length() * (1.0 + RADIUS_SLACK.0) + RADIUS_SLACK.1;
    (0..n)
        .map(|i| {
            let mut centre = DVec3::ZERO;
            centre[k] = -half[k] + slab[k] * (2 * i + 1) as f64;
            Sphere { centre, radius }
        })
        .collect()
}

/// A cylinder (axis y, as parry's) cut across its axis into slabs when it is longer than
/// wide: each slab is a shorter cylinder, held by the sphere through its rims.
fn cylinder_cover(half_height: f64, radius: f64) -> Vec<Sphere> {
    let n = slab_count(2.0 * half_height, 2.0 * radius);
    let h = half_height / n as f64;
    let r = (radius * radius + h * h).sqrt() * (1.0 + RADIUS_SLACK.0) + RADIUS_SLACK.1;
    (0..n)
        .map(|i| Sphere {
            centre: DVec3::new(0.0, -half_height + h * (2 * i + 1) as f64, 0.0),
            radius: r,
        })
        .collect()
}

/// A convex polytope (its vertices and edges) cut into slabs along the longest axis of its
/// bounding box; each slab's part is held by the sphere about the points that span it (the
/// vertices inside the slab and the edges' crossings of its planes).
fn polytope_cover(points: &[DVec3], edges: &[[usize; 2]]) -> Vec<Sphere> {
    let points: Vec<DVec3> = points.iter().copied().filter(|p| p.is_finite()).collect();
    let Some(&first) = points.first() else {
        return Vec::new();
    };
    let (lo, hi) = points
        .iter()
        .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let extent = hi - lo;
    let k = extent.max_position();
    let width = (0..3).filter(|&i| i != k).map(|i| extent[i]).fold(0.0, f64::max);
    let n = slab_count(extent[k], width);
    if n == 1 {
        return Sphere::bounding(&points).into_iter().collect();
    }
    let cut = |i: usize| {
        if i == n {
            hi[k]
        } else {
            lo[k] + extent[k] * i as f64 / n as f64
        }
    };
    let mut out = Vec::with_capacity(n);
    let mut held = Vec::new();
    for i in 0..n {
        let (t0, t1) = (cut(i), cut(i + 1));
        held.clear();
        held.extend(points.iter().copied().filter(|p| p[k] >= t0 && p[k] <= t1));
        for &[a, b] in edges {
            let (Some(&pa), Some(&pb)) = (points.get(a), points.get(b)) else {
                continue;
            };
            for t in [t0, t1] {
                let (da, db) = (pa[k] - t, pb[k] - t);
                if (da < 0.0) != (db < 0.0) && da != db {
                    let s = da / (da - db);
                    let mut p = pa + (pb - pa) * s;
                    p[k] = t;
                    held.push(p);
                }
            }
        }
        if let Some(s) = Sphere::bounding(&held) {
            out.push(s);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::shape::{Ball, ConvexPolyhedron, Cuboid, Cylinder, SharedShape};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random points of the solid shape (rejection sampling in its bounding box) all lie in
    /// some sphere of the cover, and the cover is not much larger than the shape.
    fn assert_covers(shape: &dyn Shape, local: Pose) {
        let cover = Cover::of(shape, &local);
        assert!(!cover.spheres.is_empty());
        let outer = cover.outer.unwrap();
        let aabb = shape.compute_local_aabb();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut inside = 0;
        for _ in 0..20_000 {
            let p = DVec3::new(
                rng.random_range(aabb.mins.x..=aabb.maxs.x),
                rng.random_range(aabb.mins.y..=aabb.maxs.y),
                rng.random_range(aabb.mins.z..=aabb.maxs.z),
            );
            // Points on the surface matter most: push some to the boundary.
            let p = if inside % 2 == 0 {
                shape.project_local_point(p, false).point
            } else {
                p
            };
            if !shape.contains_local_point(p) && shape.distance_to_local_point(p, true) > 1e-12 {
                continue;
            }
            inside += 1;
            let w = local.transform_point(p);
            assert!(
                cover.spheres.iter().any(|s| (w - s.centre).length() <= s.radius),
                "{w:?} outside the cover {:?}",
                cover.spheres
            );
            assert!((w - outer.centre).length() <= outer.radius);
        }
        assert!(inside > 1000);
        // Not too loose: the cover's spheres stay within the shape's bounding sphere.
        let bound = aabb.half_extents().length();
        for s in &cover.spheres {
            assert!(s.radius <= bound + 1e-9, "{s:?} larger than {bound}");
        }
    }

    #[test]
    fn covers_contain_their_shapes() {
        let local = Pose::from_parts(
            DVec3::new(0.1, -0.2, 0.3),
            crate::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.5, 1.1),
        );
        assert_covers(&Ball::new(0.2), local);
        assert_covers(&Cuboid::new(DVec3::new(0.5, 0.05, 0.1)), local);
        assert_covers(&Cylinder::new(0.4, 0.05), local);
        assert_covers(&Cylinder::new(0.02, 0.3), local);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let pts: Vec<DVec3> = (0..60)
            .map(|_| {
                DVec3::new(
                    rng.random_range(-0.4..0.4),
                    rng.random_range(-0.06..0.06),
                    rng.random_range(-0.05..0.05),
                )
            })
            .collect();
        let hull = ConvexPolyhedron::from_convex_hull(&pts).unwrap();
        assert_covers(&hull, local);
        let shared = SharedShape::new(hull);
        assert!(
            Cover::of(&*shared, &local).spheres.len() > 2,
            "a long hull is cut into slabs"
        );
    }

    #[test]
    fn slab_count_is_bounded() {
        assert_eq!(slab_count(1.0, 1.0), 1);
        assert_eq!(slab_count(1.0, 0.3), 4);
        assert_eq!(slab_count(1.0, 0.0), MAX_SLABS);
        assert_eq!(slab_count(f64::NAN, 1.0), 1);
        assert_eq!(slab_count(100.0, 1.0), MAX_SLABS);
    }
}

//! Sphere covers of convex bodies: the broad phase of the collision world.
//!
//! A body's cover is a few spheres whose union **contains the whole convex solid** (not only
//! its vertices), so for any object `O` and any point `p` of the body, lying in some sphere
//! `(c, r)` of the cover, `dist(p, O) ≥ dist(c, O) − r`. The smallest `dist(c, O) − r` over the
//! cover is therefore a lower bound on the body's distance to `O`: cheap (a point query per
//! sphere), and exact enough to dismiss everything not near the body.
//!
//! How the cover is built ([`fit`]): every shape but a ball (its own cover) is taken as a
//! convex polytope — a body's hull as it is, a box by its corners, a cylinder by the prism
//! circumscribing it, a mesh by its hull — and cut by a grid of planes into cells; each cell's
//! part is held by one sphere about points whose convex hull provably contains that part (the
//! proof is in [`fit`]). Of a few grids (along the body's axes and its principal axes, cells
//! about as long as wide, at most [`MAX_SPHERES`]), the one whose cover sticks out of the body
//! least on average, counting [`SPHERE_COST`] per sphere, is kept, its centres moved to stick
//! out less.
use crate::{DVec3, Pose};
use fit::Polytope;
use parry3d_f64::shape::{ConvexPolyhedron, Shape, TypedShape};

pub mod fit;

pub use fit::{MAX_SPHERES, SPHERE_COST};

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
    /// Whether the two spheres are at least `gap` apart (surface to surface): `|c₁ − c₂| ≥
    /// r₁ + r₂ + gap`, compared squared (`reaches`; no square root, the hot test of the broad
    /// phase); false for a NaN centre.
    #[inline]
    pub fn apart_by(&self, other: &Sphere, gap: f64) -> bool {
        reaches(
            (self.centre - other.centre).length_squared(),
            self.radius + other.radius + gap,
        )
    }
}

/// Whether a distance whose square is `d2` is at least `reach` (`√d2 ≥ reach`), without the
/// square root: any distance reaches a reach of zero or less; a NaN `d2` reaches nothing.
#[inline(always)]
pub(crate) fn reaches(d2: f64, reach: f64) -> bool {
    if reach <= 0.0 {
        d2 >= 0.0
    } else {
        d2 >= reach * reach
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
pub(crate) fn enclosing(spheres: &[Sphere]) -> Option<Sphere> {
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

/// The cover in the shape's own frame.
fn local_cover(shape: &dyn Shape) -> Vec<Sphere> {
    let polytope = match shape.as_typed_shape() {
        TypedShape::Ball(b) => {
            return vec![Sphere {
                centre: DVec3::ZERO,
                radius: b.radius,
            }];
        }
        TypedShape::Cuboid(c) => box_polytope(c.half_extents),
        TypedShape::Cylinder(c) => cylinder_polytope(c.half_height, c.radius),
        TypedShape::ConvexPolyhedron(c) => convex_polytope(c),
        TypedShape::TriMesh(m) => match ConvexPolyhedron::from_convex_hull(m.vertices()) {
            Some(hull) => convex_polytope(&hull),
            // A flat mesh: its own edges, bounded by the grid's box alone.
            None => Polytope::new(
                m.vertices(),
                m.indices()
                    .iter()
                    .flat_map(|t| [[t[0], t[1]], [t[1], t[2]], [t[2], t[0]]])
                    .map(|[a, b]| [a as usize, b as usize]),
                [],
            ),
        },
        _ => None,
    };
    if let Some(p) = polytope {
        return fit::fitted_cover(&p);
    }
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

/// A convex polyhedron: its points, every edge of its triangulated surface (parry keeps the
/// edges inside merged coplanar faces too) and its faces' normals.
fn convex_polytope(c: &ConvexPolyhedron) -> Option<Polytope> {
    Polytope::new(
        c.points(),
        c.edges()
            .iter()
            .map(|e| [e.vertices[0] as usize, e.vertices[1] as usize]),
        c.faces().iter().map(|f| f.normal),
    )
}

/// A box of half extents `half` as a polytope.
fn box_polytope(half: DVec3) -> Option<Polytope> {
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            let s = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
            half * DVec3::new(s(1), s(2), s(4))
        })
        .collect();
    // Corners differing in one bit share an edge.
    let edges = (0..8usize).flat_map(|a| {
        [1, 2, 4]
            .into_iter()
            .filter(move |b| a & b == 0)
            .map(move |b| [a, a | b])
    });
    let normals = [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    Polytope::new(&corners, edges, normals)
}

/// Sides of the prism circumscribing a cylinder for its cover.
const CYLINDER_SIDES: usize = 32;

/// A cylinder (axis y, as parry's) as the prism circumscribing it (its sides touch it).
fn cylinder_polytope(half_height: f64, radius: f64) -> Option<Polytope> {
    let n = CYLINDER_SIDES;
    // The polygon's apothem is the radius: its vertices lie at r / cos(π/n).
    let r = radius / (std::f64::consts::PI / n as f64).cos();
    let angle = |k: usize| std::f64::consts::TAU * k as f64 / n as f64;
    let points: Vec<DVec3> = (0..n)
        .flat_map(|k| {
            let (s, c) = angle(k).sin_cos();
            [
                DVec3::new(r * c, -half_height, r * s),
                DVec3::new(r * c, half_height, r * s),
            ]
        })
        .collect();
    // Point 2k is at the bottom, 2k + 1 at the top of corner k.
    let edges = (0..n).flat_map(|k| {
        let m = (k + 1) % n;
        [[2 * k, 2 * m], [2 * k + 1, 2 * m + 1], [2 * k, 2 * k + 1]]
    });
    let normals = (0..n)
        .map(|k| {
            let (s, c) = (angle(k) + std::f64::consts::PI / n as f64).sin_cos();
            DVec3::new(c, 0.0, s)
        })
        .chain([DVec3::Y, DVec3::NEG_Y]);
    Polytope::new(&points, edges, normals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::shape::{Ball, ConvexPolyhedron, Cuboid, Cylinder, SharedShape, TriMesh};
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
        for k in 0..20_000 {
            let p = DVec3::new(
                rng.random_range(aabb.mins.x..=aabb.maxs.x),
                rng.random_range(aabb.mins.y..=aabb.maxs.y),
                rng.random_range(aabb.mins.z..=aabb.maxs.z),
            );
            // Points on the surface matter most: push some to the boundary.
            let p = if k % 2 == 0 {
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
        assert!(inside > 1000, "{inside} samples inside");
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
        // Fat shapes, cut in two or three directions.
        assert_covers(&Cuboid::new(DVec3::new(0.2, 0.2, 0.2)), local);
        assert_covers(&Cuboid::new(DVec3::new(0.3, 0.25, 0.01)), local);
        assert_covers(&Cylinder::new(0.1, 0.3), local);
        // A mesh: covered by its hull; a flat one by its own triangles.
        let mesh = |vertices: Vec<DVec3>| {
            TriMesh::new(vertices, vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]).unwrap()
        };
        let tetra = mesh(vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.4, 0.0, 0.0),
            DVec3::new(0.0, 0.3, 0.0),
            DVec3::new(0.1, 0.1, 0.2),
        ]);
        assert_covers(&tetra, local);
        let flat = mesh(vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.4, 0.0, 0.0),
            DVec3::new(0.0, 0.3, 0.0),
            DVec3::new(0.3, 0.2, 0.0),
        ]);
        let cover = Cover::of(&flat, &Pose::IDENTITY);
        for (a, b) in [
            (0.0, 0.0),
            (1.0, 0.0),
            (0.0, 1.0),
            (0.5, 0.5),
            (0.2, 0.7),
            (0.9, 0.05),
        ] {
            for t in flat.triangles() {
                let p = t.a + (t.b - t.a) * a * (1.0 - b) + (t.c - t.a) * b * (1.0 - a);
                assert!(cover.spheres.iter().any(|s| (p - s.centre).length() <= s.radius));
            }
        }
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
}

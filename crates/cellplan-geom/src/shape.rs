//! Shapes as a cell file states them, and their conversion to parry shapes.
use crate::{DQuat, DVec3, Mesh, Pose};
use parry3d_f64::shape::{Ball, ConvexPolyhedron, Cuboid, Cylinder, Shape, SharedShape, TriMesh};
use std::sync::Arc;

/// A shape in its own frame (metres).
#[derive(Clone, Debug)]
pub enum ShapeSpec {
    /// A box centred on the origin.
    Box {
        /// Half extents along x, y, z.
        half_extents: crate::DVec3,
    },
    /// A cylinder centred on the origin with its axis along **z** (URDF convention).
    Cylinder {
        /// Radius.
        radius: f64,
        /// Half of the length along z.
        half_height: f64,
    },
    /// A sphere centred on the origin.
    Sphere {
        /// Radius.
        radius: f64,
    },
    /// A triangle mesh.
    Mesh(Arc<Mesh>),
}

/// Sides of the polygon that circumscribes a cylinder's circle in a conservative hull.
pub const CYLINDER_HULL_SIDES: usize = 16;

impl ShapeSpec {
    /// Triangles of the shape in its own frame: a mesh as it is, primitives tessellated (a box
    /// exactly, cylinders with 24 sides, spheres with 12 rings of 24) — for drawing and sampling.
    pub fn to_mesh(&self) -> Mesh {
        match self {
            ShapeSpec::Mesh(m) => (**m).clone(),
            ShapeSpec::Box { half_extents: h } => {
                let v: Vec<DVec3> = (0..8)
                    .map(|i| {
                        DVec3::new(
                            if i & 1 == 0 { -h.x } else { h.x },
                            if i & 2 == 0 { -h.y } else { h.y },
                            if i & 4 == 0 { -h.z } else { h.z },
                        )
                    })
                    .collect();
                let faces = [
                    [0, 2, 3, 1],
                    [4, 5, 7, 6],
                    [0, 1, 5, 4],
                    [2, 6, 7, 3],
                    [0, 4, 6, 2],
                    [1, 3, 7, 5],
                ];
                let triangles = faces
                    .iter()
                    .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
                    .collect();
                Mesh {
                    vertices: v,
                    triangles,
                }
            }
            ShapeSpec::Cylinder { radius, half_height } => {
                let n = 24u32;
                let mut vertices = Vec::new();
                for k in 0..n {
                    let a = std::f64::consts::TAU * f64::from(k) / f64::from(n);
                    let (x, y) = (radius * a.cos(), radius * a.sin());
                    vertices.push(DVec3::new(x, y, -half_height));
                    vertices.push(DVec3::new(x, y, *half_height));
                }
                vertices.push(DVec3::new(0.0, 0.0, -half_height));
                vertices.push(DVec3::new(0.0, 0.0, *half_height));
                let (bottom, top) = (2 * n, 2 * n + 1);
                let mut triangles = Vec::new();
                for k in 0..n {
                    let (a0, a1) = (2 * k, 2 * k + 1);
                    let (b0, b1) = (2 * ((k + 1) % n), 2 * ((k + 1) % n) + 1);
                    triangles.extend([[a0, b0, b1], [a0, b1, a1], [bottom, b0, a0], [top, a1, b1]]);
                }
                Mesh { vertices, triangles }
            }
            ShapeSpec::Sphere { radius } => {
                let (rings, segs) = (12u32, 24u32);
                let mut vertices = Vec::new();
                for i in 0..=rings {
                    let th = std::f64::consts::PI * f64::from(i) / f64::from(rings);
                    for j in 0..segs {
                        let ph = std::f64::consts::TAU * f64::from(j) / f64::from(segs);
                        vertices
                            .push(DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()) * *radius);
                    }
                }
                let mut triangles = Vec::new();
                for i in 0..rings {
                    for j in 0..segs {
                        let a = i * segs + j;
                        let b = i * segs + (j + 1) % segs;
                        triangles.extend([[a, a + segs, b + segs], [a, b + segs, b]]);
                    }
                }
                Mesh { vertices, triangles }
            }
        }
    }

    /// Points whose convex hull contains the shape (in the shape's frame): the corners of a
    /// box, a prism circumscribing a cylinder ([`CYLINDER_HULL_SIDES`] sides), a polyhedron
    /// (a subdivided icosahedron) circumscribing a sphere, the vertices of a mesh. Non-finite
    /// values give no points.
    pub fn hull_points(&self) -> Vec<DVec3> {
        let mut out = Vec::new();
        self.push_hull_points(&Pose::IDENTITY, &mut out);
        out
    }

    /// The farthest any point of the shape lies from its own origin (m): a box's half
    /// diagonal, a cylinder's rim, a sphere's radius, a mesh's farthest vertex.
    pub fn reach(&self) -> f64 {
        match self {
            ShapeSpec::Box { half_extents } => half_extents.length(),
            ShapeSpec::Cylinder { radius, half_height } => {
                (radius * radius + half_height * half_height).sqrt()
            }
            ShapeSpec::Sphere { radius } => radius.abs(),
            ShapeSpec::Mesh(m) => m.vertices.iter().map(|v| v.length()).fold(0.0, f64::max),
        }
    }

    /// Whether the shape has a finite, non-empty geometry (finite parameters; a mesh with at
    /// least one triangle). Shapes that are not valid never collide.
    pub fn is_valid(&self) -> bool {
        match self {
            ShapeSpec::Box { half_extents } => half_extents.is_finite(),
            ShapeSpec::Cylinder { radius, half_height } => radius.is_finite() && half_height.is_finite(),
            ShapeSpec::Sphere { radius } => radius.is_finite(),
            ShapeSpec::Mesh(m) => !m.triangles.is_empty(),
        }
    }

    fn push_hull_points(&self, pose: &Pose, out: &mut Vec<DVec3>) {
        match self {
            ShapeSpec::Box { half_extents } => {
                if !half_extents.is_finite() {
                    return;
                }
                let h = half_extents.abs();
                for i in 0..8 {
                    let s = DVec3::new(
                        if i & 1 == 0 { -1.0 } else { 1.0 },
                        if i & 2 == 0 { -1.0 } else { 1.0 },
                        if i & 4 == 0 { -1.0 } else { 1.0 },
                    );
                    out.push(pose.transform_point(h * s));
                }
            }
            ShapeSpec::Cylinder { radius, half_height } => {
                if !(radius.is_finite() && half_height.is_finite()) {
                    return;
                }
                let n = CYLINDER_HULL_SIDES;
                // The polygon's apothem is the radius: its vertices lie at r / cos(π/n).
                let r = radius.abs() / (std::f64::consts::PI / n as f64).cos();
                let h = half_height.abs();
                for k in 0..n {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    for z in [-h, h] {
                        out.push(pose.transform_point(DVec3::new(r * a.cos(), r * a.sin(), z)));
                    }
                }
            }
            ShapeSpec::Sphere { radius } => {
                if !radius.is_finite() {
                    return;
                }
                let (dirs, inradius) = unit_sphere_polytope();
                let scale = radius.abs() / inradius;
                out.extend(dirs.iter().map(|&d| pose.transform_point(d * scale)));
            }
            ShapeSpec::Mesh(m) => {
                out.extend(
                    m.vertices
                        .iter()
                        .filter(|v| v.is_finite())
                        .map(|&v| pose.transform_point(v)),
                );
            }
        }
    }
}

/// The vertices of a once-subdivided icosahedron on the unit sphere, and the distance from
/// the centre to the nearest plane of its faces (so that scaling by `r / inradius` gives a
/// polytope containing the sphere of radius `r`).
fn unit_sphere_polytope() -> (Vec<DVec3>, f64) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut verts: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|&a| DVec3::from_array(a).normalize())
    .collect();
    let faces: [[usize; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut mid = std::collections::HashMap::new();
    let mut midpoint = |a: usize, b: usize, verts: &mut Vec<DVec3>| -> usize {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            verts.push((verts[a] + verts[b]).normalize());
            verts.len() - 1
        })
    };
    let mut inradius = f64::INFINITY;
    for [a, b, c] in faces {
        let ab = midpoint(a, b, &mut verts);
        let bc = midpoint(b, c, &mut verts);
        let ca = midpoint(c, a, &mut verts);
        for [p, q, r] in [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]] {
            let n = (verts[q] - verts[p]).cross(verts[r] - verts[p]).normalize();
            inradius = inradius.min(n.dot(verts[p]).abs());
        }
    }
    (verts, inradius)
}

/// The rotation taking parry's cylinder axis (y) to ours (z).
fn y_to_z() -> DQuat {
    DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2)
}

/// Converts one primitive (box, cylinder, sphere) to an exact parry shape and the pose of that
/// shape in the spec's frame. `None` for meshes and invalid shapes.
fn primitive(spec: &ShapeSpec) -> Option<(SharedShape, Pose)> {
    if !spec.is_valid() {
        return None;
    }
    match spec {
        ShapeSpec::Box { half_extents } => {
            Some((SharedShape::new(Cuboid::new(half_extents.abs())), Pose::IDENTITY))
        }
        ShapeSpec::Cylinder { radius, half_height } => Some((
            SharedShape::new(Cylinder::new(half_height.abs(), radius.abs())),
            Pose::from_rotation(y_to_z()),
        )),
        ShapeSpec::Sphere { radius } => Some((SharedShape::new(Ball::new(radius.abs())), Pose::IDENTITY)),
        ShapeSpec::Mesh(_) => None,
    }
}

/// A static object's shape: primitives exactly, meshes as a triangle-mesh surface (with its
/// BVH). Triangles with out-of-range indices or non-finite corners are left out. `None` when
/// nothing is left.
pub(crate) fn static_shape(spec: &ShapeSpec) -> Option<(SharedShape, Pose)> {
    match spec {
        ShapeSpec::Mesh(m) => {
            let ok = |i: u32| m.vertices.get(i as usize).is_some_and(|v| v.is_finite());
            let tris: Vec<[u32; 3]> = m
                .triangles
                .iter()
                .copied()
                .filter(|t| t.iter().all(|&i| ok(i)))
                .collect();
            let mesh = TriMesh::new(m.vertices.clone(), tris).ok()?;
            Some((SharedShape::new(mesh), Pose::IDENTITY))
        }
        _ => primitive(spec),
    }
}

/// A group body's single convex shape and its pose in the body frame: the primitive itself
/// when the body has exactly one (valid) primitive, otherwise the convex hull of every shape's
/// conservative points (see [`ShapeSpec::hull_points`]). A flat set of points gives a flat
/// hull; points parry cannot hull (collinear ones) fall back to their bounding box, thickened
/// to 1 µm. `None` for a body without geometry.
pub(crate) fn body_shape(shapes: &[(ShapeSpec, Pose)]) -> Option<(SharedShape, Pose)> {
    let shapes: Vec<&(ShapeSpec, Pose)> = shapes
        .iter()
        .filter(|(s, p)| s.is_valid() && p.is_finite())
        .collect();
    if let [(spec, pose)] = shapes.as_slice()
        && let Some((shape, local)) = primitive(spec)
    {
        return Some((shape, *pose * local));
    }
    let mut points = Vec::new();
    for (spec, pose) in shapes {
        spec.push_hull_points(pose, &mut points);
    }
    if points.is_empty() {
        return None;
    }
    if let Some(hull) = ConvexPolyhedron::from_convex_hull(&points) {
        return Some((SharedShape::new(hull), Pose::IDENTITY));
    }
    let (lo, hi) = points
        .iter()
        .fold((points[0], points[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let half = ((hi - lo) / 2.0).max(DVec3::splat(1e-6));
    Some((
        SharedShape::new(Cuboid::new(half)),
        Pose::from_translation((lo + hi) / 2.0),
    ))
}

/// The convex shape of a body as a mesh (for drawing), in the body frame.
pub(crate) fn shape_as_mesh(shape: &dyn Shape, local: &Pose) -> Option<Mesh> {
    use parry3d_f64::shape::TypedShape;
    let (vertices, triangles) = match shape.as_typed_shape() {
        TypedShape::ConvexPolyhedron(c) => c.to_trimesh(),
        TypedShape::Cuboid(c) => c.to_trimesh(),
        TypedShape::Ball(b) => b.to_trimesh(12, 24),
        TypedShape::Cylinder(c) => c.to_trimesh(CYLINDER_HULL_SIDES as u32 * 2),
        TypedShape::TriMesh(m) => (m.vertices().to_vec(), m.indices().to_vec()),
        _ => return None,
    };
    Some(Mesh { vertices, triangles }.transformed(local))
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::query::PointQuery;

    #[test]
    fn reach_is_the_farthest_point_from_the_origin() {
        let b = ShapeSpec::Box {
            half_extents: DVec3::new(1.0, 2.0, -2.0),
        };
        assert_eq!(b.reach(), 3.0);
        let c = ShapeSpec::Cylinder {
            radius: 3.0,
            half_height: 4.0,
        };
        assert_eq!(c.reach(), 5.0);
        assert_eq!(ShapeSpec::Sphere { radius: 0.5 }.reach(), 0.5);
        // A mesh: its farthest vertex, not its box's corner.
        let m = ShapeSpec::Box {
            half_extents: DVec3::splat(1.0),
        }
        .to_mesh();
        let far = m.vertices.iter().map(|v| v.length()).fold(0.0, f64::max);
        assert_eq!(ShapeSpec::Mesh(std::sync::Arc::new(m)).reach(), far);
        assert!((far - 3f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn tessellated_primitives_are_closed_and_sized() {
        let b = ShapeSpec::Box {
            half_extents: DVec3::new(1.0, 2.0, 3.0),
        }
        .to_mesh();
        assert_eq!(b.triangles.len(), 12);
        let (lo, hi) = b.aabb().unwrap();
        assert!((hi - lo - DVec3::new(2.0, 4.0, 6.0)).length() < 1e-12);
        let c = ShapeSpec::Cylinder {
            radius: 0.5,
            half_height: 1.0,
        }
        .to_mesh();
        let (lo, hi) = c.aabb().unwrap();
        assert!((hi.z - lo.z - 2.0).abs() < 1e-12 && (hi.x - 0.5).abs() < 1e-12);
        let s = ShapeSpec::Sphere { radius: 2.0 }.to_mesh();
        assert!(s.vertices.iter().all(|v| (v.length() - 2.0).abs() < 1e-9));
    }

    #[test]
    fn sphere_polytope_contains_sphere() {
        let (dirs, inradius) = unit_sphere_polytope();
        assert_eq!(dirs.len(), 42);
        assert!(inradius > 0.9 && inradius < 1.0, "{inradius}");
        let pts = ShapeSpec::Sphere { radius: 2.0 }.hull_points();
        let hull = ConvexPolyhedron::from_convex_hull(&pts).unwrap();
        // Every point of the sphere is inside the hull.
        for k in 0..500 {
            let a = k as f64 * 2.399963;
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / 500.0;
            let r = (1.0 - z * z).sqrt();
            let p = DVec3::new(r * a.cos(), r * a.sin(), z) * 2.0;
            assert!(hull.contains_local_point(p * 0.999_999), "{p}");
        }
        // ... and the hull is not much larger than it.
        let far = pts.iter().map(|p| p.length()).fold(0.0, f64::max);
        assert!(far < 2.0 * 1.25, "{far}");
    }

    #[test]
    fn cylinder_prism_contains_cylinder() {
        let pts = ShapeSpec::Cylinder {
            radius: 1.0,
            half_height: 0.5,
        }
        .hull_points();
        let hull = ConvexPolyhedron::from_convex_hull(&pts).unwrap();
        for k in 0..64 {
            let a = std::f64::consts::TAU * (k as f64 + 0.37) / 64.0;
            let p = DVec3::new(a.cos(), a.sin(), 0.4999) * 0.999_999;
            assert!(hull.contains_local_point(p), "{p}");
        }
        assert!(!hull.contains_local_point(DVec3::new(0.0, 0.0, 0.51)));
        assert!(!hull.contains_local_point(DVec3::new(1.1, 0.0, 0.0)));
    }

    #[test]
    fn single_primitive_body_is_exact_and_cylinder_axis_is_z() {
        let (shape, local) = body_shape(&[(
            ShapeSpec::Cylinder {
                radius: 0.1,
                half_height: 1.0,
            },
            Pose::IDENTITY,
        )])
        .unwrap();
        assert!(shape.as_cylinder().is_some());
        let aabb = shape.compute_aabb(&local);
        assert!((aabb.maxs.z - 1.0).abs() < 1e-12, "{aabb:?}");
        assert!((aabb.maxs.x - 0.1).abs() < 1e-12, "{aabb:?}");
        assert!((aabb.maxs.y - 0.1).abs() < 1e-12, "{aabb:?}");
    }

    #[test]
    fn several_shapes_become_one_hull() {
        let b = ShapeSpec::Box {
            half_extents: DVec3::splat(0.5),
        };
        let (shape, local) = body_shape(&[
            (b.clone(), Pose::IDENTITY),
            (b, Pose::from_translation(DVec3::new(2.0, 0.0, 0.0))),
        ])
        .unwrap();
        let c = shape.as_convex_polyhedron().unwrap();
        assert_eq!(c.points().len(), 8);
        let aabb = shape.compute_aabb(&local);
        assert!((aabb.mins.x + 0.5).abs() < 1e-12 && (aabb.maxs.x - 2.5).abs() < 1e-12);
    }

    #[test]
    fn flat_mesh_body_falls_back_to_thin_box_and_empty_body_has_no_shape() {
        let m = Mesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)],
            triangles: vec![[0, 1, 2], [1, 3, 2]],
        };
        let (shape, local) = body_shape(&[(ShapeSpec::Mesh(Arc::new(m)), Pose::IDENTITY)]).unwrap();
        let aabb = shape.compute_aabb(&local);
        assert!(aabb.maxs.z - aabb.mins.z < 1e-5, "{aabb:?}");
        assert!((aabb.maxs.x - 1.0).abs() < 1e-9);
        // Collinear points: no hull, a thin box.
        let m = Mesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0],
            triangles: vec![[0, 1, 2]],
        };
        let (shape, local) = body_shape(&[(ShapeSpec::Mesh(Arc::new(m)), Pose::IDENTITY)]).unwrap();
        let aabb = shape.compute_aabb(&local);
        assert!(
            (aabb.maxs.x - 2.0).abs() < 1e-9 && aabb.mins.x.abs() < 1e-9,
            "{aabb:?}"
        );
        assert!(aabb.maxs.y > 0.0 && aabb.maxs.y < 1e-5, "{aabb:?}");
        assert!(body_shape(&[]).is_none());
        assert!(body_shape(&[(ShapeSpec::Sphere { radius: f64::NAN }, Pose::IDENTITY)]).is_none());
    }

    #[test]
    fn static_mesh_drops_bad_triangles() {
        let m = Mesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::splat(f64::NAN)],
            triangles: vec![[0, 1, 2], [0, 1, 3], [0, 1, 9]],
        };
        let (shape, _) = static_shape(&ShapeSpec::Mesh(Arc::new(m))).unwrap();
        assert_eq!(shape.as_trimesh().unwrap().num_triangles(), 1);
        assert!(static_shape(&ShapeSpec::Mesh(Arc::new(Mesh::default()))).is_none());
    }
}

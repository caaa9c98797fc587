//! The test part of paper 003's kind: a machined block like an inline-four cylinder block, built
//! as a triangle mesh by this code, with its measuring points (MPs).
//!
//! Dimensions ([`BlockSpec::default`], mm; the block's corner at the origin, on a fixture plate
//! whose top is z = 0):
//! - the block: 400 (X) × 240 (Y) × 300 (Z), the two top long edges chamfered 30 mm at 45°;
//! - the deck face (z = 300) with four cylinder bores Ø80 at x = 65, 155, 245, 335, y = 120,
//!   150 deep;
//! - the side y = 0 with three holes Ø20, 40 deep, at x = 100, 200, 300, z = 150;
//! - the side y = 240 with two bosses Ø40 standing 15 out, at x = 130, 270, z = 120;
//! - the end x = 0 with a hole Ø30, 50 deep, at y = 120, z = 80; the end x = 400 with a boss Ø50
//!   standing 20 out at the same place.
//!
//! The 39 MPs: eleven on the deck, one on each bore wall (12 mm below the deck, on the bore's
//! +X side, facing its axis), two on each chamfer, on the side y = 0 the rim of each hole and
//! four plane points, six plane points on the side y = 240 around its bosses, on the end x = 0
//! two points on the hole's rim and two plane points, on the end x = 400 the boss's face and two
//! plane points. Each has a cone half-angle θ: 20° for plane points, 30° for rims, the boss
//! face and the chamfers, 80° for bore walls (the probe reaches them tilted, from above). Faces are numbered for
//! the classification ([`block_adjacent`]); the four bore walls count as one face — a liberty
//! with eq. 3's "at most two planes" (the walls are four cylinders, all adjacent to the deck and
//! reached from above along one probe direction), which lets the deck and the bores form one
//! group as a real cylinder block's deck program does. The mesh is a set of faces meeting with
//! T-junctions along shared cell edges: exact for distances, not for inside/outside tests.
use crate::builder::{Builder, Circle, Frame};
use cellplan_geom::Mesh;
use glam::DVec3;

/// The block's dimensions (mm) and the circle resolution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockSpec {
    /// Length along X.
    pub length: f64,
    /// Width along Y.
    pub width: f64,
    /// Height along Z.
    pub height: f64,
    /// The chamfer of the top long edges (45°).
    pub chamfer: f64,
    /// Bore diameter, depth, and the X of each bore.
    pub bore: (f64, f64, [f64; 4]),
    /// Segments of a full circle.
    pub segments: usize,
}

impl Default for BlockSpec {
    fn default() -> Self {
        BlockSpec {
            length: 400.0,
            width: 240.0,
            height: 300.0,
            chamfer: 30.0,
            bore: (80.0, 150.0, [65.0, 155.0, 245.0, 335.0]),
            segments: 48,
        }
    }
}

/// What a measuring point measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MpFeature {
    /// A point of a plane.
    Plane,
    /// A point of a bore wall.
    BoreWall,
    /// A point on a hole's rim.
    HoleEdge,
    /// A point on a boss's face.
    Boss,
}

impl MpFeature {
    /// The name in the task file's `feature` column.
    pub fn column(self) -> &'static str {
        match self {
            MpFeature::Plane => "surface",
            MpFeature::BoreWall => "hole",
            MpFeature::HoleEdge => "edge",
            MpFeature::Boss => "stud",
        }
    }
}

/// A measuring point (mm).
#[derive(Clone, Debug, PartialEq)]
pub struct Mp {
    /// Name (`D1`, `B3`, …).
    pub name: String,
    /// Position.
    pub position: DVec3,
    /// Outward unit normal of the surface.
    pub normal: DVec3,
    /// What it measures.
    pub feature: MpFeature,
    /// Cone half-angle θ (deg).
    pub theta_deg: f64,
    /// Index of the face it lies on (points on the same plane share it; a bore wall counts as
    /// its own face).
    pub face: usize,
}

/// The block's mesh and its MPs (mm).
pub fn cylinder_block(spec: &BlockSpec) -> (Mesh, Vec<Mp>) {
    let (l, w, h, c) = (spec.length, spec.width, spec.height, spec.chamfer);
    let seg = spec.segments.max(8);
    let mut b = Builder::default();
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    let r2 = std::f64::consts::SQRT_2;
    // Faces and their frames.
    let bottom = Frame {
        origin: DVec3::ZERO,
        u: y,
        v: x,
    };
    let deck = Frame {
        origin: DVec3::ZERO + h * z,
        u: x,
        v: y,
    };
    let side0 = Frame {
        origin: DVec3::ZERO,
        u: x,
        v: z,
    };
    let side1 = Frame {
        origin: DVec3::new(0.0, w, 0.0),
        u: z,
        v: x,
    };
    let chamfer0 = Frame {
        origin: DVec3::new(0.0, 0.0, h - c),
        u: x,
        v: (y + z) / r2,
    };
    let chamfer1 = Frame {
        origin: DVec3::new(l, w, h - c),
        u: -x,
        v: (z - y) / r2,
    };
    let end0 = Frame {
        origin: DVec3::ZERO,
        u: z,
        v: y,
    };
    let end1 = Frame {
        origin: DVec3::new(l, 0.0, 0.0),
        u: y,
        v: z,
    };
    let (bore_d, bore_depth, bore_x) = spec.bore;
    let bores: Vec<Circle> = bore_x
        .iter()
        .map(|&bx| Circle {
            s: bx,
            t: w / 2.0,
            r: bore_d / 2.0,
            depth: -bore_depth,
        })
        .collect();
    let side_holes: Vec<Circle> = [100.0, 200.0, 300.0]
        .iter()
        .map(|&hx| Circle {
            s: hx,
            t: 150.0,
            r: 10.0,
            depth: -40.0,
        })
        .collect();
    let side_bosses: Vec<Circle> = [130.0, 270.0]
        .iter()
        .map(|&bx| Circle {
            s: 120.0,
            t: bx,
            r: 20.0,
            depth: 15.0,
        })
        .collect();
    let end_hole = Circle {
        s: 80.0,
        t: w / 2.0,
        r: 15.0,
        depth: -50.0,
    };
    let end_boss = Circle {
        s: w / 2.0,
        t: 80.0,
        r: 25.0,
        depth: 20.0,
    };

    b.rect_face(&bottom, [0.0, w], [0.0, l], &[], seg);
    b.rect_face(&deck, [0.0, l], [c, w - c], &bores, seg);
    b.rect_face(&side0, [0.0, l], [0.0, h - c], &side_holes, seg);
    b.rect_face(&side1, [0.0, h - c], [0.0, l], &[], seg);
    for sb in &side_bosses {
        b.boss(&side1, sb, seg);
    }
    b.rect_face(&chamfer0, [0.0, l], [0.0, c * r2], &[], seg);
    b.rect_face(&chamfer1, [0.0, l], [0.0, c * r2], &[], seg);
    // The ends: the rectangle below the chamfers (with the hole or the boss), and the trapezoid.
    b.rect_face(&end0, [0.0, h - c], [0.0, w], &[end_hole], seg);
    b.rect_face(&end1, [0.0, w], [0.0, h - c], &[], seg);
    b.boss(&end1, &end_boss, seg);
    for (xe, normal) in [(0.0, -x), (l, x)] {
        let q = [
            DVec3::new(xe, 0.0, h - c),
            DVec3::new(xe, w, h - c),
            DVec3::new(xe, w - c, h),
            DVec3::new(xe, c, h),
        ]
        .map(|p| b.vertex(p));
        b.tri(q[0], q[1], q[2], normal);
        b.tri(q[0], q[2], q[3], normal);
    }

    // The MPs.
    let mut mps = Vec::new();
    let mut add = |name: String, p: DVec3, n: DVec3, feature: MpFeature, theta: f64, face: usize| {
        mps.push(Mp {
            name,
            position: p,
            normal: n.normalize(),
            feature,
            theta_deg: theta,
            face,
        });
    };
    // Deck: between and beside the bores.
    let deck_pts = [
        (20.0, 60.0),
        (110.0, 60.0),
        (200.0, 60.0),
        (290.0, 60.0),
        (380.0, 60.0),
        (20.0, 180.0),
        (110.0, 180.0),
        (200.0, 180.0),
        (290.0, 180.0),
        (380.0, 180.0),
        (200.0, 120.0),
    ];
    for (k, &(px, py)) in deck_pts.iter().enumerate() {
        add(
            format!("D{}", k + 1),
            DVec3::new(px, py, h),
            z,
            MpFeature::Plane,
            20.0,
            0,
        );
    }
    // Bore walls, 12 mm below the deck on each bore's +X side (a ring vertex, so on the mesh),
    // facing the axis; reached with the probe tilted from above.
    for (k, bore) in bores.iter().enumerate() {
        let p = DVec3::new(bore.s + bore.r, bore.t, h - 12.0);
        add(format!("B{}", k + 1), p, -x, MpFeature::BoreWall, 80.0, 1);
    }
    // Chamfers.
    for (k, &px) in [120.0, 280.0].iter().enumerate() {
        add(
            format!("C{}", k + 1),
            chamfer0.at(px, c * r2 / 2.0),
            chamfer0.normal(),
            MpFeature::Plane,
            30.0,
            5,
        );
        add(
            format!("C{}", k + 3),
            chamfer1.at(l - px, c * r2 / 2.0),
            chamfer1.normal(),
            MpFeature::Plane,
            30.0,
            6,
        );
    }
    // Side y = 0: the rim of each hole (2 mm outside it, on the face) and plane points.
    for (k, hole) in side_holes.iter().enumerate() {
        add(
            format!("S{}", k + 1),
            side0.at(hole.s, hole.t + hole.r + 2.0),
            -y,
            MpFeature::HoleEdge,
            30.0,
            7,
        );
    }
    for (k, &(px, pz)) in [(40.0, 60.0), (160.0, 60.0), (240.0, 60.0), (360.0, 60.0)]
        .iter()
        .enumerate()
    {
        add(
            format!("S{}", k + 4),
            DVec3::new(px, 0.0, pz),
            -y,
            MpFeature::Plane,
            20.0,
            7,
        );
    }
    // Side y = 240: plane points around the bosses.
    for (k, &(px, pz)) in [
        (60.0, 200.0),
        (200.0, 200.0),
        (340.0, 200.0),
        (60.0, 60.0),
        (200.0, 60.0),
        (340.0, 60.0),
    ]
    .iter()
    .enumerate()
    {
        add(
            format!("T{}", k + 1),
            DVec3::new(px, w, pz),
            y,
            MpFeature::Plane,
            20.0,
            10,
        );
    }
    // End x = 0: two rim points of the hole and two plane points.
    for (k, dy) in [-1.0, 1.0].iter().enumerate() {
        add(
            format!("E{}", k + 1),
            DVec3::new(0.0, w / 2.0 + dy * (end_hole.r + 2.0), end_hole.s),
            -x,
            MpFeature::HoleEdge,
            30.0,
            11,
        );
    }
    for (k, &(py, pz)) in [(40.0, 200.0), (200.0, 200.0)].iter().enumerate() {
        add(
            format!("E{}", k + 3),
            DVec3::new(0.0, py, pz),
            -x,
            MpFeature::Plane,
            20.0,
            11,
        );
    }
    // End x = 400: the boss's face and two plane points.
    add(
        "F1".into(),
        DVec3::new(l + end_boss.depth, w / 2.0, end_boss.t),
        x,
        MpFeature::Boss,
        30.0,
        12,
    );
    for (k, &(py, pz)) in [(40.0, 200.0), (200.0, 200.0)].iter().enumerate() {
        add(
            format!("F{}", k + 2),
            DVec3::new(l, py, pz),
            x,
            MpFeature::Plane,
            20.0,
            13,
        );
    }
    (b.mesh, mps)
}

/// Whether two faces of [`cylinder_block`]'s MPs share an edge: 0 deck, 1 the bore walls, 5 and
/// 6 the chamfers at y = 0 and y = 240, 7 the side y = 0, 8 and 9 the bosses on the side y = 240
/// (10), 11 the end x = 0, 12 the boss on the end x = 400 (13).
pub fn block_adjacent(f: usize, g: usize) -> bool {
    const PAIRS: [(usize, usize); 20] = [
        (0, 1),
        (0, 2),
        (0, 3),
        (0, 4),
        (0, 5),
        (0, 6),
        (0, 11),
        (0, 13),
        (5, 7),
        (5, 11),
        (5, 13),
        (6, 10),
        (6, 11),
        (6, 13),
        (7, 11),
        (7, 13),
        (8, 10),
        (9, 10),
        (10, 11),
        (10, 13),
    ];
    f != g && PAIRS.iter().any(|&(a, b)| (a, b) == (f, g) || (b, a) == (f, g))
        || (f, g) == (12, 13)
        || (f, g) == (13, 12)
}

/// Names of [`cylinder_block`]'s faces, by index (the task file's `face` column).
pub const BLOCK_FACES: [&str; 14] = [
    "deck",
    "bores",
    "unused-2",
    "unused-3",
    "unused-4",
    "chamfer-y0",
    "chamfer-y240",
    "side-y0",
    "boss-y240-1",
    "boss-y240-2",
    "side-y240",
    "end-x0",
    "boss-x400",
    "end-x400",
];

/// The mesh as Wavefront OBJ text.
pub fn to_obj(mesh: &Mesh, comment: &str) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    for line in comment.lines() {
        let _ = writeln!(s, "# {line}");
    }
    for v in &mesh.vertices {
        let _ = writeln!(s, "v {:.6} {:.6} {:.6}", v.x, v.y, v.z);
    }
    for t in &mesh.triangles {
        let _ = writeln!(s, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

/// The MPs as a task CSV (`id,x,y,z,nx,ny,nz,feature,theta,face`; mm and degrees), the faces
/// named by `faces`.
pub fn to_csv(mps: &[Mp], faces: &[&str]) -> String {
    use std::fmt::Write;
    let mut s = String::from("id,x,y,z,nx,ny,nz,feature,theta,face\n");
    for m in mps {
        let _ = writeln!(
            s,
            "{},{:.4},{:.4},{:.4},{:.6},{:.6},{:.6},{},{},{}",
            m.name,
            m.position.x,
            m.position.y,
            m.position.z,
            m.normal.x,
            m.normal.y,
            m.normal.z,
            m.feature.column(),
            m.theta_deg,
            faces.get(m.face).copied().unwrap_or("?")
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::closest;

    #[test]
    fn the_block_has_39_mps_on_its_surface_facing_out() {
        let spec = BlockSpec::default();
        let (mesh, mps) = cylinder_block(&spec);
        assert_eq!(mps.len(), 39);
        let names: std::collections::HashSet<&str> = mps.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names.len(), 39, "names are unique");
        let half_step = std::f64::consts::PI / spec.segments as f64;
        for m in &mps {
            let (d, n) = closest(&mesh, m.position);
            assert!(d < 1e-6, "{} is {d} mm off the surface", m.name);
            assert!(
                n.dot(m.normal) > half_step.cos() - 1e-9,
                "{}: mesh normal {n} against {}",
                m.name,
                m.normal
            );
        }
        // Every triangle has area; the outward normals of a closed block sum to zero, here plus
        // the caps of the three bosses (their bases lie on the faces they stand on).
        let mut sum = DVec3::ZERO;
        for i in 0..mesh.triangles.len() {
            assert!(mesh.triangle_area(i) > 1e-9, "triangle {i} is degenerate");
            sum += mesh.triangle_area(i) * mesh.triangle_normal(i);
        }
        let ring_area = |r: f64| {
            0.5 * spec.segments as f64 * r * r * (std::f64::consts::TAU / spec.segments as f64).sin()
        };
        let expected = 2.0 * ring_area(20.0) * DVec3::Y + ring_area(25.0) * DVec3::X;
        assert!(
            (sum - expected).length() < 1e-6 * expected.length().max(1.0),
            "{sum} vs {expected}"
        );
        let (lo, hi) = mesh.aabb().unwrap();
        assert!((lo - DVec3::ZERO).length() < 1e-9);
        assert!((hi - DVec3::new(420.0, 255.0, 300.0)).length() < 1e-9, "{hi}");
    }

    #[test]
    fn files_are_written_in_the_usual_formats() {
        let (mesh, mps) = cylinder_block(&BlockSpec::default());
        let obj = to_obj(&mesh, "test");
        let back = cellplan_geom::mesh::parse_obj(obj.as_bytes(), std::path::Path::new("block.obj")).unwrap();
        assert_eq!(back.triangles.len(), mesh.triangles.len());
        let csv = to_csv(&mps, &BLOCK_FACES);
        assert_eq!(csv.lines().count(), 40);
        assert!(csv.starts_with("id,x,y,z,nx,ny,nz,feature,theta,face"));
        assert!(!csv.contains("unused") && !csv.contains('?'));
    }
}

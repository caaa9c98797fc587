//! The second test part: a gearbox or pump housing, built as a triangle mesh by this code, with
//! its measuring points (MPs). Where [`crate::part`]'s block is a tall prism measured mostly on
//! its deck and long sides, the housing is a body on a wider base flange, so that MPs lie on the
//! flange around the body and on its edges near the fixture plate, on a face inclined 30° that
//! needs a tilted probe, around a bore from the top (120° apart, so no one tilt reaches them
//! all) and in a bore in a boss on a side, reached nearly horizontally.
//!
//! Dimensions ([`HousingSpec::default`], mm; the flange's corner at the origin, on a fixture
//! plate whose top is z = 0):
//! - the base flange: 340 (X) × 240 (Y) × 25 (Z), with four through-holes Ø16 whose centres lie
//!   20 mm from the two nearest edges;
//! - the body on it, centred: 240 × 160 × 150 (x 50…290, y 40…200, z 25…175);
//! - the slope: between the top and the end x = 290, inclined 30° to the horizontal, 50 mm
//!   high (its top edge at x = 290 − 50/tan 30° ≈ 203.40, z = 175; its bottom edge at x = 290,
//!   z = 125; 100 mm along the incline), with a hole Ø16, 25 deep, normal to it at its centre;
//! - the top (z = 175): a bore Ø90, 60 deep, at x = 110, y = 120; two threaded-hole stand-ins
//!   Ø12, 20 deep, 20 mm from the slope's top edge, at y = 80 and 160;
//! - the side y = 40 (the front): two holes Ø20, 30 deep, at x = 100 and 180, z = 100;
//! - the side y = 200 (the back): a boss Ø70 standing 20 out at x = 120, z = 100, with a bore
//!   Ø40 in it, 50 deep from the boss's face (through the boss and 30 into the wall);
//! - the ends x = 50 (left) and x = 290 (right, below the slope): plain.
//!
//! The 40 MPs ([`HOUSING_FACES`] names their faces): on the top four plane points around the
//! bore, one between the threaded holes and each threaded hole's rim (`T1`–`T7`); three points
//! on the bore's wall 15 mm below the top, 120° apart, and one on its floor (`B1`–`B4`); on the
//! slope three plane points and the hole's rim (`S1`–`S4`); on the front the rims of its holes
//! and three plane points (`F1`–`F5`); on the back three plane points around the boss (`K1`–
//! `K3`), two on the boss's face and one on its bore's wall, at the bottom, 10 mm in (`P1`–`P3`);
//! two plane points on each end (`L1`, `L2`, `R1`, `R2`); on the flange's top six plane points
//! around the body and the rims of two corner holes (`G1`–`G8`); one plane point on each of the
//! flange's sides x = 0 and y = 0 (`E1`, `E2`). θ as on the block: 20° for plane points, 30° for
//! rims and the boss's face, 80° for bore walls (reached tilted). A rim point lies 2 mm outside
//! its hole; a bore-wall point lies on a vertex of the bore's ring, so exactly on the mesh
//! whatever the segments. The points on the flange keep clear of the boss's shadow, so that the
//! probe reaches them straight down.
//!
//! The mesh is closed (every opening has its wall and bottom, the through-holes come out of the
//! flange's bottom, the boss stands in a cut of its wall, the body stands on a cut of the
//! flange's top), up to T-junctions along shared cell edges: its area-weighted normals sum to
//! zero. The feature and MP positions are laid out for the default dimensions (and kept
//! relative to the body's edges): other dimensions work as long as every feature still fits
//! its face.
use crate::builder::{Builder, Circle, Frame, Opening};
use crate::part::{Mp, MpFeature};
use cellplan_geom::Mesh;
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// The housing's dimensions (mm, degrees) and the circle resolution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HousingSpec {
    /// The base flange: length (X), width (Y), thickness (Z).
    pub flange: (f64, f64, f64),
    /// The flange's four corner through-holes: diameter, and the distance of their centres from
    /// the flange's two nearest edges.
    pub flange_holes: (f64, f64),
    /// The body, centred on the flange: length (X), width (Y), height above the flange (Z).
    pub body: (f64, f64, f64),
    /// The slope from the top down to the end +X: its angle to the horizontal (deg, strictly
    /// between 0 and 90) and its height.
    pub slope: (f64, f64),
    /// The top's bore: diameter, depth.
    pub bore: (f64, f64),
    /// The top's two threaded-hole stand-ins: diameter, depth.
    pub tapped: (f64, f64),
    /// The boss on the back (the side +Y): diameter, how far it stands out.
    pub boss: (f64, f64),
    /// The bore in the boss: diameter, depth below the boss's face.
    pub boss_bore: (f64, f64),
    /// The front's (the side −Y's) two holes: diameter, depth.
    pub side_holes: (f64, f64),
    /// The hole normal to the slope: diameter, depth.
    pub slope_hole: (f64, f64),
    /// Segments of a full circle.
    pub segments: usize,
}

impl Default for HousingSpec {
    /// The dimensions of the module's documentation.
    fn default() -> Self {
        HousingSpec {
            flange: (340.0, 240.0, 25.0),
            flange_holes: (16.0, 20.0),
            body: (240.0, 160.0, 150.0),
            slope: (30.0, 50.0),
            bore: (90.0, 60.0),
            tapped: (12.0, 20.0),
            boss: (70.0, 20.0),
            boss_bore: (40.0, 50.0),
            side_holes: (20.0, 30.0),
            slope_hole: (16.0, 25.0),
            segments: 48,
        }
    }
}

/// Names of [`housing`]'s faces that carry MPs, by index (the task file's `face` column):
/// the top, the bore's wall and floor, the slope, the sides y = 40 (front) and y = 200 (back),
/// the boss's face and its bore's wall, the ends x = 50 (left) and x = 290 (right), the flange's
/// top and its sides x = 0 and y = 0.
pub const HOUSING_FACES: [&str; 13] = [
    "top",
    "bore",
    "bore-floor",
    "slope",
    "side-front",
    "side-back",
    "boss",
    "boss-bore",
    "end-left",
    "end-right",
    "flange-top",
    "flange-left",
    "flange-front",
];

/// Whether two faces of [`housing`]'s MPs ([`HOUSING_FACES`]) share an edge. As on the block,
/// the boss's face counts as adjacent to the side it stands on (the boss's cylinder, which
/// carries no MP, joins them).
pub fn housing_adjacent(f: usize, g: usize) -> bool {
    const PAIRS: [(usize, usize); 22] = [
        (0, 1),
        (0, 3),
        (0, 4),
        (0, 5),
        (0, 8),
        (1, 2),
        (3, 4),
        (3, 5),
        (3, 9),
        (4, 8),
        (4, 9),
        (4, 10),
        (5, 6),
        (5, 8),
        (5, 9),
        (5, 10),
        (6, 7),
        (8, 10),
        (9, 10),
        (10, 11),
        (10, 12),
        (11, 12),
    ];
    PAIRS.iter().any(|&(a, b)| (a, b) == (f, g) || (b, a) == (f, g))
}

/// The housing's mesh and its MPs (mm).
pub fn housing(spec: &HousingSpec) -> (Mesh, Vec<Mp>) {
    use MpFeature::{BoreWall, Boss, HoleEdge, Plane};
    let seg = spec.segments.max(8);
    let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
    let (fl, fw, ft) = spec.flange;
    let (bl, bw, bh) = spec.body;
    let (x0, y0, z0) = ((fl - bl) / 2.0, (fw - bw) / 2.0, ft);
    let (x1, y1, z1) = (x0 + bl, y0 + bw, z0 + bh);
    let yc = (y0 + y1) / 2.0;
    let alpha = spec.slope.0.to_radians();
    let drop = spec.slope.1;
    // The slope's top edge and its length along the incline.
    let xs = x1 - drop / alpha.tan();
    let incline = drop / alpha.sin();
    let mut b = Builder::default();

    // The flange: its top around the body (the corner cells with the through-holes, a strip
    // along each side of the body), its bottom (the same cells and the one under the body), its
    // four sides.
    let (hole_r, hole_e) = (spec.flange_holes.0 / 2.0, spec.flange_holes.1);
    let corners = [
        ([0.0, x0], [0.0, y0], (hole_e, hole_e)),
        ([x1, fl], [0.0, y0], (fl - hole_e, hole_e)),
        ([0.0, x0], [y1, fw], (hole_e, fw - hole_e)),
        ([x1, fl], [y1, fw], (fl - hole_e, fw - hole_e)),
    ];
    let strips = [
        ([x0, x1], [0.0, y0]),
        ([x0, x1], [y1, fw]),
        ([0.0, x0], [y0, y1]),
        ([x1, fl], [y0, y1]),
    ];
    let flange_top = Frame {
        origin: ft * z,
        u: x,
        v: y,
    };
    // The bottom, seen from below: (s, t) = (x, fw − y), so that a hole's ring there meets its
    // wall's vertex for vertex.
    let bottom = Frame {
        origin: fw * y,
        u: x,
        v: -y,
    };
    let flip = |ys: [f64; 2]| [fw - ys[1], fw - ys[0]];
    for &(xs_, ys_, (hx, hy)) in &corners {
        let top_hole = Circle {
            s: hx,
            t: hy,
            r: hole_r,
            depth: -ft,
        };
        b.face(&flange_top, xs_, ys_, &[(top_hole, Opening::Through)], seg);
        let bottom_hole = Circle {
            t: fw - hy,
            ..top_hole
        };
        b.face(&bottom, xs_, flip(ys_), &[(bottom_hole, Opening::Bare)], seg);
    }
    for &(xs_, ys_) in &strips {
        b.face(&flange_top, xs_, ys_, &[], seg);
        b.face(&bottom, xs_, flip(ys_), &[], seg);
    }
    b.face(&bottom, [x0, x1], flip([y0, y1]), &[], seg);
    let flange_left = Frame {
        origin: DVec3::ZERO,
        u: z,
        v: y,
    };
    let flange_front = Frame {
        origin: DVec3::ZERO,
        u: x,
        v: z,
    };
    b.face(&flange_left, [0.0, ft], [0.0, fw], &[], seg);
    b.face(
        &Frame {
            origin: fl * x,
            u: y,
            v: z,
        },
        [0.0, fw],
        [0.0, ft],
        &[],
        seg,
    );
    b.face(&flange_front, [0.0, fl], [0.0, ft], &[], seg);
    b.face(
        &Frame {
            origin: fw * y,
            u: z,
            v: x,
        },
        [0.0, ft],
        [0.0, fl],
        &[],
        seg,
    );

    // The top: the cell with the bore, and beside it, along the slope's top edge, one cell per
    // threaded hole.
    let top = Frame {
        origin: z1 * z,
        u: x,
        v: y,
    };
    let bore = Circle {
        s: x0 + 60.0,
        t: yc,
        r: spec.bore.0 / 2.0,
        depth: -spec.bore.1,
    };
    let tapped: Vec<Circle> = [yc - bw / 4.0, yc + bw / 4.0]
        .iter()
        .map(|&ty| Circle {
            s: xs - 20.0,
            t: ty,
            r: spec.tapped.0 / 2.0,
            depth: -spec.tapped.1,
        })
        .collect();
    let xm = xs - 40.0;
    b.face(&top, [x0, xm], [y0, y1], &[(bore, Opening::Closed)], seg);
    b.face(&top, [xm, xs], [y0, yc], &[(tapped[0], Opening::Closed)], seg);
    b.face(&top, [xm, xs], [yc, y1], &[(tapped[1], Opening::Closed)], seg);

    // The slope: t up the incline from its bottom edge, s along Y.
    let slope = Frame {
        origin: DVec3::new(x1, y0, z1 - drop),
        u: y,
        v: DVec3::new(-alpha.cos(), 0.0, alpha.sin()),
    };
    let slope_hole = Circle {
        s: bw / 2.0,
        t: incline / 2.0,
        r: spec.slope_hole.0 / 2.0,
        depth: -spec.slope_hole.1,
    };
    b.face(
        &slope,
        [0.0, bw],
        [0.0, incline],
        &[(slope_hole, Opening::Closed)],
        seg,
    );

    // The front and the back: the part as high as the top (with the holes, or the boss), the
    // part below the slope, and the triangle beside the slope.
    let front = Frame {
        origin: y0 * y,
        u: x,
        v: z,
    };
    let side_holes: Vec<(Circle, Opening)> = [x0 + 50.0, x0 + 130.0]
        .iter()
        .map(|&hx| {
            let hole = Circle {
                s: hx,
                t: z0 + 75.0,
                r: spec.side_holes.0 / 2.0,
                depth: -spec.side_holes.1,
            };
            (hole, Opening::Closed)
        })
        .collect();
    b.face(&front, [x0, xs], [z0, z1], &side_holes, seg);
    b.face(&front, [xs, x1], [z0, z1 - drop], &[], seg);
    let back = Frame {
        origin: y1 * y,
        u: z,
        v: x,
    };
    let boss = Circle {
        s: z0 + 75.0,
        t: x0 + 70.0,
        r: spec.boss.0 / 2.0,
        depth: spec.boss.1,
    };
    let bored = Opening::BoredBoss {
        r: spec.boss_bore.0 / 2.0,
        depth: spec.boss_bore.1,
    };
    b.face(&back, [z0, z1], [x0, xs], &[(boss, bored)], seg);
    b.face(&back, [z0, z1 - drop], [xs, x1], &[], seg);
    for (side, facing) in [(y0, -y), (y1, y)] {
        let q = [
            DVec3::new(xs, side, z1 - drop),
            DVec3::new(x1, side, z1 - drop),
            DVec3::new(xs, side, z1),
        ]
        .map(|p| b.vertex(p));
        b.tri(q[0], q[1], q[2], facing);
    }

    // The ends.
    let left = Frame {
        origin: x0 * x,
        u: z,
        v: y,
    };
    let right = Frame {
        origin: x1 * x,
        u: y,
        v: z,
    };
    b.face(&left, [z0, z1], [y0, y1], &[], seg);
    b.face(&right, [y0, y1], [z0, z1 - drop], &[], seg);

    // The MPs.
    let mut mps = Vec::new();
    let mut add = |name: &str, p: DVec3, n: DVec3, feature: MpFeature, face: usize| {
        let theta = match feature {
            MpFeature::Plane => 20.0,
            MpFeature::HoleEdge | MpFeature::Boss => 30.0,
            MpFeature::BoreWall => 80.0,
        };
        mps.push(Mp {
            name: name.to_string(),
            position: p,
            // + 0 turns the −0 of a negated axis into 0 (the task file shows no "-0.000000").
            normal: n.normalize() + DVec3::ZERO,
            feature,
            theta_deg: theta,
            face,
        });
    };
    // The rim of a hole cut into face `f`: 2 mm outside the circle at angle `phi`.
    let rim =
        |f: &Frame, h: &Circle, phi: f64| f.at(h.s + (h.r + 2.0) * phi.cos(), h.t + (h.r + 2.0) * phi.sin());
    // The top.
    for (name, (px, py)) in [
        ("T1", (x0 + 15.0, y0 + 15.0)),
        ("T2", (x0 + 15.0, y1 - 15.0)),
        ("T3", (xs - 55.0, y0 + 15.0)),
        ("T4", (xs - 55.0, y1 - 15.0)),
        ("T5", (xs - 20.0, yc)),
    ] {
        add(name, top.at(px, py), z, Plane, 0);
    }
    add("T6", rim(&top, &tapped[0], PI), z, HoleEdge, 0);
    add("T7", rim(&top, &tapped[1], PI), z, HoleEdge, 0);
    // The bore: three points on its wall 15 mm down, 120° apart; one on its floor.
    for (k, name) in ["B1", "B2", "B3"].iter().enumerate() {
        let (p, n) = bore.wall_point(&top, TAU * k as f64 / 3.0, 15.0, seg);
        add(name, p, n, BoreWall, 1);
    }
    add(
        "B4",
        top.at(bore.s + bore.r / 2.0, bore.t) + bore.depth * z,
        z,
        Plane,
        2,
    );
    // The slope.
    let up_slope = slope.normal();
    for (name, (s, t)) in [
        ("S1", (25.0, incline / 2.0)),
        ("S2", (bw - 25.0, incline / 2.0)),
        ("S3", (bw / 2.0 + 40.0, 20.0)),
    ] {
        add(name, slope.at(s, t), up_slope, Plane, 3);
    }
    add("S4", rim(&slope, &slope_hole, PI / 2.0), up_slope, HoleEdge, 3);
    // The front: the holes' rims (above them) and plane points.
    add("F1", rim(&front, &side_holes[0].0, PI / 2.0), -y, HoleEdge, 4);
    add("F2", rim(&front, &side_holes[1].0, PI / 2.0), -y, HoleEdge, 4);
    for (name, (px, pz)) in [
        ("F3", (x0 + 20.0, z0 + 25.0)),
        ("F4", (x0 + 90.0, z1 - 20.0)),
        ("F5", (x1 - 30.0, z0 + 50.0)),
    ] {
        add(name, front.at(px, pz), -y, Plane, 4);
    }
    // The back around the boss; the boss's face on either side of its bore; the bore's wall at
    // its bottom (facing up), 10 mm in.
    for (name, (px, pz)) in [
        ("K1", (x0 + 15.0, z1 - 20.0)),
        ("K2", (x0 + 130.0, z0 + 20.0)),
        ("K3", (x1 - 30.0, z0 + 50.0)),
    ] {
        add(name, back.at(pz, px), y, Plane, 5);
    }
    let boss_face = back.offset(boss.depth);
    let mid = 0.5 * (spec.boss.0 + spec.boss_bore.0) / 2.0;
    add("P1", boss_face.at(boss.s, boss.t + mid), y, Boss, 6);
    add("P2", boss_face.at(boss.s, boss.t - mid), y, Boss, 6);
    let boss_bore = Circle {
        r: spec.boss_bore.0 / 2.0,
        depth: -spec.boss_bore.1,
        ..boss
    };
    // Angle π from the back's u (= Z): the bore's lowest line.
    let (p, n) = boss_bore.wall_point(&boss_face, PI, 10.0, seg);
    add("P3", p, n, BoreWall, 7);
    // The ends.
    add("L1", left.at(z1 - 30.0, y0 + 40.0), -x, Plane, 8);
    add("L2", left.at(z0 + 30.0, y1 - 40.0), -x, Plane, 8);
    add("R1", right.at(y0 + 40.0, z0 + 50.0), x, Plane, 9);
    add("R2", right.at(y1 - 40.0, z0 + 50.0), x, Plane, 9);
    // The flange's top around the body, clear of the boss (x0 + 35 … x0 + 105 on the back),
    // and the rims of two corner holes, on the side toward the flange's centre line x.
    for (name, (px, py)) in [
        ("G1", (x0 + 70.0, y0 / 2.0)),
        ("G2", (x1 - 40.0, y0 / 2.0)),
        ("G3", (x1 - 40.0, fw - y0 / 2.0)),
        ("G4", (x0 + 10.0, fw - y0 / 2.0)),
        ("G5", (x0 / 2.0, yc)),
        ("G6", (fl - x0 / 2.0, yc)),
    ] {
        add(name, flange_top.at(px, py), z, Plane, 10);
    }
    for (name, k, phi) in [("G7", 0, 0.0), ("G8", 3, PI)] {
        let (_, _, (hx, hy)) = corners[k];
        let hole = Circle {
            s: hx,
            t: hy,
            r: hole_r,
            depth: -ft,
        };
        add(name, rim(&flange_top, &hole, phi), z, HoleEdge, 10);
    }
    // The flange's sides x = 0 and y = 0, halfway up.
    add("E1", flange_left.at(ft / 2.0, yc), -x, Plane, 11);
    add("E2", flange_front.at(fl / 2.0, ft / 2.0), -y, Plane, 12);
    (b.mesh, mps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::classify::{Method, classify};
    use crate::part::to_csv;
    use crate::scene::closest;

    #[test]
    fn the_housing_has_40_mps_on_its_surface_facing_out() {
        for segments in [48, 30, 13] {
            let spec = HousingSpec {
                segments,
                ..HousingSpec::default()
            };
            let (mesh, mps) = housing(&spec);
            assert_eq!(mps.len(), 40);
            let names: std::collections::HashSet<&str> = mps.iter().map(|m| m.name.as_str()).collect();
            assert_eq!(names.len(), 40, "names are unique");
            let half_step = PI / segments as f64;
            for m in &mps {
                let (d, n) = closest(&mesh, m.position);
                assert!(
                    d < 1e-6,
                    "{segments} segments: {} is {d} mm off the surface",
                    m.name
                );
                assert!(
                    n.dot(m.normal) > half_step.cos() - 1e-9,
                    "{segments} segments: {}: mesh normal {n} against {}",
                    m.name,
                    m.normal
                );
                assert!((m.normal.length() - 1.0).abs() < 1e-12);
            }
            // Every triangle has area; the mesh is closed, so the outward normals weighted by
            // area sum to zero.
            let (mut sum, mut area) = (DVec3::ZERO, 0.0);
            for i in 0..mesh.triangles.len() {
                assert!(mesh.triangle_area(i) > 1e-9, "triangle {i} is degenerate");
                sum += mesh.triangle_area(i) * mesh.triangle_normal(i);
                area += mesh.triangle_area(i);
            }
            assert!(
                sum.length() < 1e-9 * area,
                "{segments} segments: {sum} over {area} mm²"
            );
            let (lo, hi) = mesh.aabb().unwrap();
            assert!((lo - DVec3::ZERO).length() < 1e-9, "{lo}");
            assert!((hi - DVec3::new(340.0, 240.0, 175.0)).length() < 1e-9, "{hi}");
        }
    }

    #[test]
    fn the_housings_faces_are_named_and_adjacent_both_ways() {
        let (_, mps) = housing(&HousingSpec::default());
        for (f, name) in HOUSING_FACES.iter().enumerate() {
            assert!(mps.iter().any(|m| m.face == f), "no MP on {name}");
            assert!(!housing_adjacent(f, f));
            for g in 0..HOUSING_FACES.len() {
                assert_eq!(housing_adjacent(f, g), housing_adjacent(g, f));
            }
        }
        assert!(housing_adjacent(0, 3) && housing_adjacent(10, 4) && !housing_adjacent(0, 10));
    }

    #[test]
    fn the_housings_task_file_reads_back_as_written() {
        let (mesh, mps) = housing(&HousingSpec::default());
        let obj = crate::part::to_obj(&mesh, "test");
        let back =
            cellplan_geom::mesh::parse_obj(obj.as_bytes(), std::path::Path::new("housing.obj")).unwrap();
        assert_eq!(back.triangles.len(), mesh.triangles.len());
        let csv = to_csv(&mps, &HOUSING_FACES);
        assert_eq!(csv.lines().count(), 41);
        assert!(!csv.contains('?'));
        let path = std::env::temp_dir().join(format!("cellplan-housing-{}.csv", std::process::id()));
        std::fs::write(&path, &csv).unwrap();
        let read = crate::cell::read_mps(&path, 1e-3);
        std::fs::remove_file(&path).unwrap();
        let (read, _, faces) = read.unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(read.len(), mps.len());
        for (r, m) in read.iter().zip(&mps) {
            assert_eq!(r.name, m.name);
            assert!((r.position * 1e3 - m.position).length() < 1e-4, "{}", m.name);
            assert!((r.normal - m.normal).length() < 1e-5, "{}", m.name);
            assert_eq!((r.feature, r.theta_deg), (m.feature, m.theta_deg));
            assert_eq!(faces[r.face], HOUSING_FACES[m.face]);
        }
    }

    #[test]
    fn every_mp_of_the_housing_is_grouped_within_its_cone_on_adjacent_faces() {
        let (mps, probe) = crate::scene::housing();
        let both = crate::scene::classify_both(&mps, &probe, &housing_adjacent);
        for (method, c) in ["greedy", "exact"].iter().zip(&both) {
            eprintln!("housing, {method}: {} groups", c.groups.len());
            for g in &c.groups {
                let faces: Vec<&str> = g.faces.iter().map(|&f| HOUSING_FACES[f]).collect();
                let members: Vec<&str> = g.members.iter().map(|&i| mps[i].name.as_str()).collect();
                eprintln!(
                    "  A {:5.1}° B {:6.1}°  {faces:?}: {members:?}",
                    g.angles.0.to_degrees(),
                    g.angles.1.to_degrees()
                );
            }
        }
        let counts = both.map(|c| c.groups.len());
        // Eleven: the top with the slope (tilted 15°), the flange's top (straight down), the
        // front, the back with the boss's face, the bore's wall in two tilts (one with its
        // floor), the boss's bore, each end, and each of the flange's sides alone (eq. 3 does
        // not pair it with the end above it, across the flange's top).
        assert_eq!(counts[1], 11);
    }

    #[test]
    fn the_boss_shadows_the_flange_below_it_but_not_the_flange_points() {
        let (mps, probe) = crate::scene::housing();
        let spec = HousingSpec::default();
        // Straight down onto the flange under the boss (x 85…155, y 200…220): the stylus runs
        // into the boss. The flange's MPs are clear straight down.
        let under = 1e-3 * DVec3::new(120.0, 210.0, spec.flange.2);
        assert!(!probe.touch_clear(under, DVec3::Z, -DVec3::Z, 0.001));
        for m in mps.iter().filter(|m| m.face == 10) {
            assert!(
                probe.touch_clear(m.position, m.normal, -DVec3::Z, 0.001),
                "{}",
                m.name
            );
        }
    }

    #[test]
    fn the_housing_is_planned_whole() {
        use crate::job::{JobSettings, plan_job};
        use crate::motion::{CmmValidity, space};
        let (mps, probe) = crate::scene::housing();
        let groups = classify(
            &mps,
            &housing_adjacent,
            &probe,
            &crate::scene::grid(),
            0.001,
            Method::Exact,
        )
        .groups;
        let space = space(&probe, &crate::scene::TRAVEL);
        let validity = CmmValidity {
            probe: &probe,
            margin: 0.002,
        };
        let home = vec![0.17, 0.12, 0.9, 0.0, 0.0];
        let job = plan_job(
            &probe,
            &validity,
            &space,
            &mps,
            &groups,
            &home,
            &JobSettings::default(),
        )
        .unwrap_or_else(|e| panic!("{e:?}"));
        crate::scene::assert_job_whole(&job, &space, &validity, mps.len(), &home);
        eprintln!(
            "housing: {} groups planned, movement {:.1} s, rotation {:.1} s, inspection {:.1} s, motion {:.1} s, computed in {:.2} s",
            job.groups.len(),
            job.movement_s,
            job.rotation_s,
            job.inspection_s,
            job.motion_s(),
            job.compute_s
        );
        for &g in &job.group_order {
            let g = &job.groups[g];
            let names: Vec<&str> = g.order.iter().map(|&k| mps[g.members[k]].name.as_str()).collect();
            eprintln!(
                "  A {:5.1}° B {:6.1}°: {names:?}",
                g.paths.angles.0.to_degrees(),
                g.paths.angles.1.to_degrees()
            );
        }
    }
}

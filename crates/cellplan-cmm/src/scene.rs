//! The test scenes every module's tests share: a test part ([`crate::part`]'s block or
//! [`crate::housing`]'s housing) in metres on a fixture plate, paper 003's probe, a 7.5° grid of
//! head orientations, and a travel around them; and the closest point of a mesh, to check that
//! MPs lie on their part.
use crate::classify::{Probe, ProbeBodies};
use crate::housing::{HousingSpec, housing as housing_part};
use crate::motion::Travel;
use crate::part::{BlockSpec, Mp, cylinder_block};
use cellplan_geom::{DQuat, DVec3, Mesh, Pose, ShapeSpec};
use cellplan_kin::cmm::CmmHead;
use std::sync::Arc;

/// The block's MPs (m) and the probe in the block's scene.
pub(crate) fn block() -> (Vec<Mp>, Probe) {
    let (mesh, mps) = cylinder_block(&BlockSpec::default());
    on_plate("block", &mesh, mps, DVec3::new(0.2, 0.12, -0.011))
}

/// The housing's MPs (m) and the probe in the housing's scene: the same plate, under the
/// housing's centre.
pub(crate) fn housing() -> (Vec<Mp>, Probe) {
    let spec = HousingSpec::default();
    let (mesh, mps) = housing_part(&spec);
    let centre = 0.5e-3 * DVec3::new(spec.flange.0, spec.flange.1, 0.0);
    on_plate("housing", &mesh, mps, centre + DVec3::new(0.0, 0.0, -0.011))
}

/// A part (mm) named `name` at the origin in metres, on a 700 × 500 × 20 mm plate centred at
/// `plate` (m), with paper 003's probe.
fn on_plate(name: &str, mesh: &Mesh, mps: Vec<Mp>, plate: DVec3) -> (Vec<Mp>, Probe) {
    let mps: Vec<Mp> = mps
        .into_iter()
        .map(|m| Mp {
            position: m.position * 1e-3,
            ..m
        })
        .collect();
    let statics = vec![
        (
            name.to_string(),
            ShapeSpec::Mesh(Arc::new(mesh.scaled(1e-3))),
            Pose::IDENTITY,
        ),
        (
            "plate".to_string(),
            ShapeSpec::Box {
                half_extents: DVec3::new(0.35, 0.25, 0.01),
            },
            Pose::from_parts(plate, DQuat::IDENTITY),
        ),
    ];
    (mps, Probe::new(statics, CmmHead::paper(), ProbeBodies::paper()))
}

/// Every head orientation on a 7.5° grid within paper 003's ranges.
pub(crate) fn grid() -> Vec<(f64, f64)> {
    CmmHead {
        index_step: Some(7.5f64.to_radians()),
        ..CmmHead::paper()
    }
    .indexed_orientations()
}

/// A travel around the part with room for the probe on every side.
pub(crate) const TRAVEL: Travel = Travel {
    x: [-0.4, 0.8],
    y: [-0.5, 0.7],
    z: [0.0, 1.0],
};

/// The distance from `p` to the mesh, and the normal of the triangle that is closest (of
/// those at the same distance, the first with area).
pub(crate) fn closest(mesh: &Mesh, p: DVec3) -> (f64, DVec3) {
    let mut best = (f64::INFINITY, DVec3::ZERO);
    for (i, _) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = mesh.corners(i);
        let q = closest_on_triangle(p, a, b, c);
        let d = (q - p).length();
        if d < best.0 - 1e-9 || (d < best.0 + 1e-9 && mesh.triangle_area(i) > 0.0 && best.1 == DVec3::ZERO) {
            best = (d, mesh.triangle_normal(i));
        }
    }
    best
}

/// Closest point on a triangle (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Asserts what §3.1 promises of a classification of `mps`: every MP measurable and in exactly
/// one group, each group on one face or two adjacent ones, each member on the group's faces,
/// within its cone and touched clear by `clearance`.
pub(crate) fn assert_grouped(
    mps: &[Mp],
    c: &crate::classify::Classification,
    adjacent: &dyn Fn(usize, usize) -> bool,
    probe: &Probe,
    clearance: f64,
) {
    let names: Vec<&str> = c.unmeasurable.iter().map(|&i| mps[i].name.as_str()).collect();
    assert!(names.is_empty(), "unmeasurable {names:?}");
    let mut seen = vec![0; mps.len()];
    for g in &c.groups {
        assert!(g.faces.len() <= 2);
        if g.faces.len() == 2 {
            assert!(adjacent(g.faces[0], g.faces[1]));
        }
        let d = CmmHead::direction(g.angles.0, g.angles.1);
        for &i in &g.members {
            seen[i] += 1;
            assert!(g.faces.contains(&mps[i].face));
            let angle = (-d).dot(mps[i].normal).acos().to_degrees();
            assert!(angle <= mps[i].theta_deg + 1e-9, "{}: {angle}°", mps[i].name);
            assert!(probe.touch_clear(mps[i].position, mps[i].normal, d, clearance));
        }
    }
    assert!(seen.iter().all(|&k| k == 1), "each MP in one group");
}

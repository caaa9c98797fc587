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
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::Triangle;
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
        let q = Triangle::new(a, b, c).project_local_point(p, true).point;
        let d = (q - p).length();
        if d < best.0 - 1e-9 || (d < best.0 + 1e-9 && mesh.triangle_area(i) > 0.0 && best.1 == DVec3::ZERO) {
            best = (d, mesh.triangle_normal(i));
        }
    }
    best
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

/// A whole job holds up: nothing unmeasured, every segment of its path clear (the conservative
/// check), every one of the `mps` MPs touched exactly once at its group's approach
/// configuration, and the path from `home` back to `home`.
pub(crate) fn assert_job_whole(
    job: &crate::job::Job,
    space: &cellplan_motion::plan::JointSpace,
    validity: &crate::motion::CmmValidity,
    mps: usize,
    home: &[f64],
) {
    assert!(job.unmeasured.is_empty(), "unmeasured: {:?}", job.unmeasured);
    for w in job.path.windows(2) {
        assert!(cellplan_motion::plan::check_segment(space, validity, &w[0], &w[1], 1e-4).valid);
    }
    let mut touched: Vec<usize> = job.touches.iter().map(|t| t.1).collect();
    touched.sort_unstable();
    assert_eq!(touched, (0..mps).collect::<Vec<_>>());
    for &(at, mp) in &job.touches {
        let g = job.groups.iter().find(|g| g.members.contains(&mp)).unwrap();
        let k = g.members.iter().position(|&x| x == mp).unwrap();
        assert_eq!(job.path[at], g.paths.approaches[k]);
    }
    assert_eq!(job.path.first().map(Vec::as_slice), Some(home));
    assert_eq!(job.path.last().map(Vec::as_slice), Some(home));
}

/// The classification of `mps` by both methods over [`grid`], each checked by
/// [`assert_grouped`]; the exact one never has more groups than the greedy one. Returns both.
pub(crate) fn classify_both(
    mps: &[Mp],
    probe: &Probe,
    adjacent: &dyn Fn(usize, usize) -> bool,
) -> [crate::classify::Classification; 2] {
    use crate::classify::{Method, classify};
    let orientations = grid();
    let [greedy, exact] = [Method::Greedy, Method::Exact].map(|method| {
        let c = classify(mps, adjacent, probe, &orientations, 0.001, method);
        assert_grouped(mps, &c, adjacent, probe, 0.001);
        c
    });
    assert!(
        exact.groups.len() <= greedy.groups.len(),
        "exact {} vs greedy {}",
        exact.groups.len(),
        greedy.groups.len()
    );
    [greedy, exact]
}

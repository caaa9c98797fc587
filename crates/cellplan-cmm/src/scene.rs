//! The test scene every module's tests share: the block of [`crate::part`] in metres on a
//! fixture plate, paper 003's probe, a 7.5° grid of head orientations, and a travel around them.
use crate::classify::{Probe, ProbeBodies};
use crate::motion::Travel;
use crate::part::{BlockSpec, Mp, cylinder_block};
use cellplan_geom::{DQuat, DVec3, Pose, ShapeSpec};
use cellplan_kin::cmm::CmmHead;
use std::sync::Arc;

/// The block's MPs (m) and the probe in the block's scene.
pub(crate) fn block() -> (Vec<Mp>, Probe) {
    let (mesh, mps) = cylinder_block(&BlockSpec::default());
    let mps: Vec<Mp> = mps
        .into_iter()
        .map(|m| Mp {
            position: m.position * 1e-3,
            ..m
        })
        .collect();
    let statics = vec![
        (
            "block".to_string(),
            ShapeSpec::Mesh(Arc::new(mesh.scaled(1e-3))),
            Pose::IDENTITY,
        ),
        (
            "plate".to_string(),
            ShapeSpec::Box {
                half_extents: DVec3::new(0.35, 0.25, 0.01),
            },
            Pose::from_parts(DVec3::new(0.2, 0.12, -0.011), DQuat::IDENTITY),
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

/// A travel around the block with room for the probe on every side.
pub(crate) const TRAVEL: Travel = Travel {
    x: [-0.4, 0.8],
    y: [-0.5, 0.7],
    z: [0.0, 1.0],
};

//! The direct segment only.
use super::{
    JointSpace, PlanError, PlanSettings, PlannedPath, Planner, StateValidity, check_ends, segment_valid,
};

/// Only the direct segment.
#[derive(Clone, Copy, Debug, Default)]
pub struct Straight;

impl Planner for Straight {
    fn name(&self) -> &str {
        "straight"
    }

    fn plan(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        settings: &PlanSettings,
    ) -> Result<PlannedPath, PlanError> {
        check_ends(space, validity, start, goal, settings)?;
        let mut calls = 2;
        let ok = segment_valid(space, validity, start, goal, settings.min_clearance, &mut calls);
        if ok {
            Ok(PlannedPath {
                waypoints: vec![start.to_vec(), goal.to_vec()],
                straight: true,
                samples: 0,
                validity_calls: calls,
            })
        } else {
            Err(PlanError::NoPath {
                samples: 0,
                validity_calls: calls,
            })
        }
    }
}

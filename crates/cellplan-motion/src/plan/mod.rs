//! Collision-free joint-space path planning, arranged as OMPL arranges it: a state space
//! ([`JointSpace`]), a validity checker ([`StateValidity`]), a motion validator
//! ([`check_segment`]) and planners behind one interface ([`Planner`]: [`Straight`],
//! [`RrtConnect`]), plus path post-processing ([`shortcut`]) and the usual recipe for one leg
//! ([`plan_leg`]: the straight segment if clear, else RRT-Connect, shortcut and smoothed).
//!
//! # Why no contact is missed between samples
//!
//! A [`StateValidity`] returns a *clearance* `c(q)`: a lower bound on how far every point of
//! every moving body may move (in Cartesian space) before the state can become invalid (for a
//! robot: distance to obstacles minus the margin, self distances halved because both bodies
//! move). A [`JointSpace`] carries per-joint radii such that along a straight joint-space
//! segment from `a` to `b` no point moves more than `Σ_j radii[j]·|a_j − b_j|`. So around a
//! sample at parameter `s` of a segment whose whole bound is `L`, every parameter `s'` with
//! `|s' − s|·L < c(q(s))` is valid: [`check_segment`] covers the segment with such intervals,
//! placing each new sample where its interval should about touch the covered part, until no
//! gap is left. Samples therefore crowd near obstacles and spread in free space; a clearance below
//! [`PlanSettings::min_clearance`] counts as a contact (so the check always ends). A checker
//! may split its clearance by the joints that can reduce each part
//! ([`StateValidity::clearances`]): the step is then the smallest `c_k / L_k`, `L_k` summing
//! only over the joints of part `k`.
use std::time::Duration;
use thiserror::Error;

mod rrt_connect;
mod simplify;
mod space;
mod straight;
mod validity;

pub use rrt_connect::RrtConnect;
pub use simplify::{path_length, shortcut};
pub use space::JointSpace;
pub use straight::Straight;
use validity::segment_valid;
pub use validity::{Clearance, SegmentCheck, StateValidity, check_segment, narrow_step};

/// Limits and knobs of a planning query.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanSettings {
    /// Seed of the planner's random numbers (same seed, same path, unless the time limit
    /// stops the search first).
    pub seed: u64,
    /// Wall-clock limit of the search.
    pub time_limit: Duration,
    /// Most random samples a sampling planner draws.
    pub max_samples: usize,
    /// Longest tree edge, in the space's metric; 0 or less: a fifth of the space's
    /// [`JointSpace::extent`] (OMPL's default).
    pub range: f64,
    /// Clearances below this (m) count as contact, so that checks end.
    pub min_clearance: f64,
    /// Random shortcut attempts after a sampling planner.
    pub shortcut_iterations: usize,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            seed: 0,
            time_limit: Duration::from_secs(5),
            max_samples: 20_000,
            range: 0.0,
            min_clearance: 1e-4,
            shortcut_iterations: 100,
        }
    }
}

/// A collision-free joint-space path: straight segments between waypoints.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedPath {
    /// From the start to the goal, inclusive.
    pub waypoints: Vec<Vec<f64>>,
    /// Whether it is the direct segment (two waypoints, no search).
    pub straight: bool,
    /// Random samples drawn.
    pub samples: usize,
    /// Calls of [`StateValidity::clearance`] made (checks, search and post-processing).
    pub validity_calls: usize,
}

impl PlannedPath {
    /// Length in the space's metric.
    pub fn length(&self, space: &JointSpace) -> f64 {
        path_length(space, &self.waypoints)
    }
}

/// Why no path.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum PlanError {
    /// The start is outside the space or invalid.
    #[error("the start configuration is invalid (clearance {clearance} m)")]
    StartInvalid {
        /// Its clearance (negative infinity outside the joint limits).
        clearance: f64,
    },
    /// The goal is outside the space or invalid.
    #[error("the goal configuration is invalid (clearance {clearance} m)")]
    GoalInvalid {
        /// Its clearance (negative infinity outside the joint limits).
        clearance: f64,
    },
    /// The planner gave up.
    #[error("no path found within the limits ({samples} samples, {validity_calls} validity calls)")]
    NoPath {
        /// Random samples drawn.
        samples: usize,
        /// Validity calls made.
        validity_calls: usize,
    },
}

/// A path planner between two configurations (OMPL's `Planner`): implementations are
/// interchangeable behind this trait, for benchmarks.
pub trait Planner {
    /// Short name, for reports.
    fn name(&self) -> &str;
    /// A path from `start` to `goal` whose every segment passes [`check_segment`].
    fn plan(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        settings: &PlanSettings,
    ) -> Result<PlannedPath, PlanError>;
}

/// Checks both ends (two clearance calls).
fn check_ends(
    space: &JointSpace,
    validity: &dyn StateValidity,
    start: &[f64],
    goal: &[f64],
    settings: &PlanSettings,
) -> Result<(), PlanError> {
    let floor = settings.min_clearance.max(1e-9);
    let measure = |q: &[f64]| {
        if space.contains(q) {
            validity.clearance(q)
        } else {
            f64::NEG_INFINITY
        }
    };
    let cs = measure(start);
    if cs.is_nan() || cs < floor {
        return Err(PlanError::StartInvalid { clearance: cs });
    }
    let cg = measure(goal);
    if cg.is_nan() || cg < floor {
        return Err(PlanError::GoalInvalid { clearance: cg });
    }
    Ok(())
}

/// One leg: the straight segment if it is clear, else [`RrtConnect`] followed by
/// [`shortcut`]. The counts in the result add up every stage.
pub fn plan_leg(
    space: &JointSpace,
    validity: &dyn StateValidity,
    start: &[f64],
    goal: &[f64],
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    let straight_calls = match Straight.plan(space, validity, start, goal, settings) {
        Ok(path) => return Ok(path),
        Err(PlanError::NoPath { validity_calls, .. }) => validity_calls,
        Err(e) => return Err(e),
    };
    let mut path = match RrtConnect.plan(space, validity, start, goal, settings) {
        Ok(p) => p,
        Err(PlanError::NoPath {
            samples,
            validity_calls,
        }) => {
            return Err(PlanError::NoPath {
                samples,
                validity_calls: validity_calls + straight_calls,
            });
        }
        Err(e) => return Err(e),
    };
    path.validity_calls += straight_calls;
    path.validity_calls += shortcut(space, validity, &mut path.waypoints, settings);
    Ok(path)
}

#[cfg(test)]
mod tests;

//! Collision-free joint-space path planning, arranged as OMPL arranges it: a state space
//! ([`JointSpace`]), a validity checker ([`StateValidity`]), a motion validator
//! ([`check_segment`]), a query ([`Problem`]: one start, one or more goals), a stop condition
//! ([`Termination`]: a work budget and an optional wall clock), and planners behind one
//! interface ([`MotionPlanner`]) that answer with a [`PlanResult`] (a [`Status`], the path,
//! the goal reached, the [`Work`] spent), plus path post-processing ([`shortcut`]).
//!
//! # Choosing a planner
//!
//! Planners are built by name from a static registry ([`planners`], [`planner`]) with one
//! parameter struct ([`PlannerParams`]):
//!
//! | name          | planner          | what it does |
//! |---------------|------------------|--------------|
//! | `straight`    | [`Straight`]     | the direct segment only; [`Status::Infeasible`] when blocked |
//! | `rrt-connect` | [`RrtConnect`]   | bidirectional trees, the goal tree rooted at every valid goal |
//! | `rrt-star`    | [`RrtStar`]      | anytime: spends the budget shortening the best path |
//! | `prm`         | [`Prm`]          | lazy PRM over a [`Roadmap`] reused across queries in one scene |
//! | `leg`         | [`Leg`]          | the direct segment if clear, else RRT-Connect, then post-processing |
//!
//! ```
//! use cellplan_motion::plan::{JointSpace, PlannerParams, Problem, Status, Termination, planner};
//! let space = JointSpace::new(vec![0.0; 2], vec![10.0; 2], vec![1.0; 2]);
//! // A disc of radius 2 at (5, 5): clearance is the distance to its surface.
//! let validity = |q: &[f64]| ((q[0] - 5.0).powi(2) + (q[1] - 5.0).powi(2)).sqrt() - 2.0;
//! let goals = [vec![9.0, 5.0], vec![9.0, 9.0]];
//! let problem = Problem::new(&space, &validity, &[1.0, 5.0], &goals);
//! let mut leg = (planner("leg").unwrap().build)(&PlannerParams { seed: 7, ..Default::default() });
//! let result = leg.solve(&problem, &Termination::samples(5_000));
//! assert_eq!(result.status, Status::Solved);
//! assert!(result.goal.is_some());
//! ```
//!
//! Runs are reproducible: the same seed and work budget give the same path on any machine;
//! the wall clock is a safety net whose binding the result reports ([`Work::clock_bound`]).
//! The older two-configuration interface ([`Planner`], [`plan_leg`], [`PlanSettings`],
//! [`PlanError`]) is kept for existing callers and runs on the same planners.
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

mod prm;
mod problem;
mod registry;
mod rrt_connect;
mod rrt_star;
mod shared_roadmap;
mod simplify;
mod space;
mod straight;
mod validity;

pub use prm::{Key, Prm, Roadmap};
use problem::solve_with;
pub use problem::{PlanResult, Problem, Status, Termination, Work};
pub use registry::{Entry, Leg, MotionPlanner, PlannerParams, UnknownPlanner, planner, planners};
pub use rrt_connect::RrtConnect;
pub use rrt_star::RrtStar;
pub use shared_roadmap::{RoadmapPath, SharedRoadmap, SharedRoadmapSettings};
use simplify::shortcut_with;
pub use simplify::{path_length, shortcut, shortcut_timed, straighten_joints_timed};
pub use space::JointSpace;
pub use straight::Straight;
use validity::segment_valid;
pub use validity::{Clearance, SegmentCheck, SegmentMotion, StateValidity, check_segment, narrow_step};

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

/// The older two-configuration interface, with [`PlanSettings`] and [`PlanError`]: kept for
/// existing callers ([`Straight`], [`RrtConnect`]); new code uses [`MotionPlanner`] from the
/// registry ([`planner`]), which takes goal sets and reports a [`Status`].
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

/// The path from a tree's root to node `i`: `parent[k]` is `usize::MAX` at the root.
pub(crate) fn path_to_root(nodes: &[Vec<f64>], parent: &[usize], mut i: usize) -> Vec<Vec<f64>> {
    let mut out = Vec::new();
    while i != usize::MAX {
        out.push(nodes[i].clone());
        i = parent[i];
    }
    out.reverse();
    out
}

/// One leg: the straight segment if it is clear, else [`RrtConnect`] followed by
/// [`shortcut`] (the [`Leg`] planner with the parameters and limits of `settings`). The counts
/// in the result add up every stage.
pub fn plan_leg(
    space: &JointSpace,
    validity: &dyn StateValidity,
    start: &[f64],
    goal: &[f64],
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    settings.with_problem(space, validity, start, goal, |problem| {
        let mut leg = Leg {
            params: settings.params(),
        };
        leg.solve(problem, &settings.termination()).into_planned()
    })
}

/// A leg that leaves its start along `exit` and arrives along `entry` — fixed polylines such as
/// a retract of the tool along its axis and the matching approach (see
/// [`crate::arm::tool_retract`]) — with [`plan_leg`] between the end of `exit` and the start
/// of `entry`. `exit` starts at the leg's start, `entry` ends at its goal; each of their
/// segments must pass [`check_segment`] or the leg fails ([`PlanError::NoPath`]). The whole
/// path is then shortened by [`shortcut`] (which keeps it valid), so a retract that is not
/// needed in full is cut back. Counts add up every stage.
pub fn plan_leg_via(
    space: &JointSpace,
    validity: &dyn StateValidity,
    exit: &[Vec<f64>],
    entry: &[Vec<f64>],
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    plan_leg_via_with(space, validity, exit, entry, settings, &|from, to| {
        plan_leg(space, validity, from, to, settings)
    })
}

/// A planner of one leg between two valid configurations (the sampler, a roadmap…).
pub type LegPlanner<'a> = dyn Fn(&[f64], &[f64]) -> Result<PlannedPath, PlanError> + 'a;

/// [`plan_leg_via`] with another planner between the inner ends of `exit` and `entry`
/// (`middle(from, to)`, whose path must pass [`check_segment`] segment by segment).
pub fn plan_leg_via_with(
    space: &JointSpace,
    validity: &dyn StateValidity,
    exit: &[Vec<f64>],
    entry: &[Vec<f64>],
    settings: &PlanSettings,
    middle: &LegPlanner,
) -> Result<PlannedPath, PlanError> {
    let (Some(from), Some(to)) = (exit.last(), entry.first()) else {
        return Err(PlanError::NoPath {
            samples: 0,
            validity_calls: 0,
        });
    };
    let mut calls = 0;
    for w in exit.windows(2).chain(entry.windows(2)) {
        let check = check_segment(space, validity, &w[0], &w[1], settings.min_clearance);
        calls += check.calls;
        if !check.valid {
            return Err(PlanError::NoPath {
                samples: 0,
                validity_calls: calls,
            });
        }
    }
    let middle = middle(from, to).map_err(|e| match e {
        PlanError::NoPath {
            samples,
            validity_calls,
        } => PlanError::NoPath {
            samples,
            validity_calls: validity_calls + calls,
        },
        other => other,
    })?;
    let mut waypoints = exit[..exit.len() - 1].to_vec();
    waypoints.extend(middle.waypoints);
    waypoints.extend(entry[1..].iter().cloned());
    calls += middle.validity_calls;
    calls += shortcut(space, validity, &mut waypoints, settings);
    Ok(PlannedPath {
        waypoints,
        straight: false,
        samples: middle.samples,
        validity_calls: calls,
    })
}

/// One leg through a [`SharedRoadmap`] built in the same scene, space and validity: its
/// shortest valid path from `start` to `goal` (both valid), shortened by [`shortcut`] with
/// `settings`; [`PlanError::NoPath`] (no samples) when the roadmap has none within its budget.
pub fn roadmap_leg(
    space: &JointSpace,
    validity: &dyn StateValidity,
    roadmap: &SharedRoadmap,
    start: &[f64],
    goal: &[f64],
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    let found = roadmap.query(space, validity, start, goal);
    let Some(mut waypoints) = found.waypoints else {
        return Err(PlanError::NoPath {
            samples: 0,
            validity_calls: found.validity_calls,
        });
    };
    let calls = found.validity_calls + shortcut(space, validity, &mut waypoints, settings);
    Ok(PlannedPath {
        straight: waypoints.len() == 2,
        waypoints,
        samples: 0,
        validity_calls: calls,
    })
}

impl PlanSettings {
    /// The one-goal query `start → goal` with these settings' minimum clearance, handed to `f`
    /// (the older [`Planner`] interface on the planners of the registry).
    pub(crate) fn with_problem<T>(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        f: impl FnOnce(&Problem) -> T,
    ) -> T {
        let goals = [goal.to_vec()];
        f(&Problem::new(space, validity, start, &goals).with_min_clearance(self.min_clearance))
    }

    /// The planner parameters of these settings (seed, range, shortcut iterations;
    /// post-processing on, checking every shortening shortcut). RRT-Connect searches as
    /// OMPL's does — a range of a fifth of the extent (when `range` is 0), no dynamic
    /// domains, trees in turn — not with the standalone planner's VAMP tuning: a cell's legs
    /// have a small sample budget and reach through openings, where that tuning failed legs
    /// the OMPL-like search planned (`crowded-6r-home-out`: 0 → 12 failed leg queries, cycle
    /// 30.60 → 32.46 s). Small shortcuts are checked as before: the cells' plans move with
    /// every leg's shape (README cell seeds 0–3: 24.35 / 26.68 / 26.78 / 26.70 s as now,
    /// 26.78 / 24.01 / 25.88 / 26.70 s with them unchecked), which wants the hard cells over
    /// seeds before a change (bench/motion/README.md).
    pub fn params(&self) -> PlannerParams {
        PlannerParams {
            seed: self.seed,
            range: self.range,
            range_share: 0.2,
            dynamic_domain: false,
            balance: false,
            skip_small_shortcuts: false,
            simplify: true,
            shortcut_iterations: self.shortcut_iterations,
            ..PlannerParams::default()
        }
    }

    /// The stop condition of these settings: `max_samples`, no limit on validity calls, the
    /// time limit.
    pub fn termination(&self) -> Termination {
        Termination {
            max_samples: self.max_samples,
            max_validity_calls: usize::MAX,
            time_limit: Some(self.time_limit),
        }
    }
}

impl PlanResult {
    /// The result in the older form: a [`PlannedPath`] when solved, else the [`PlanError`]
    /// (an approximate path counts as no path; for several goals all invalid, the largest
    /// goal clearance).
    pub fn into_planned(self) -> Result<PlannedPath, PlanError> {
        match self.status {
            Status::Solved => Ok(PlannedPath {
                waypoints: self.waypoints,
                straight: self.straight,
                samples: self.work.samples,
                validity_calls: self.work.validity_calls,
            }),
            Status::InvalidStart => Err(PlanError::StartInvalid {
                clearance: self.start_clearance,
            }),
            Status::InvalidGoal => Err(PlanError::GoalInvalid {
                clearance: self
                    .goal_clearances
                    .iter()
                    .copied()
                    .fold(f64::NEG_INFINITY, |a, b| if b > a { b } else { a }),
            }),
            Status::Approximate | Status::Timeout | Status::BudgetExhausted | Status::Infeasible => {
                Err(PlanError::NoPath {
                    samples: self.work.samples,
                    validity_calls: self.work.validity_calls,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests;

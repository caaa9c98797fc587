//! The knobs of coordination.
use super::Coordination;

/// Knobs of coordination.
#[derive(Clone, Debug)]
pub struct CoordSettings {
    /// Strategy.
    pub strategy: Coordination,
    /// Delay increment of delay-startup (s).
    pub delay_step: f64,
    /// Orientation increment of pose-perturbation (rad); the grid is ±2 increments about each
    /// of w, p, r.
    pub perturb_step: f64,
    /// Perturbed (or alternative) pose combinations whose legs are planned per conflict.
    pub perturb_evaluations: usize,
    /// Seed of the local path planner.
    pub seed: u64,
    /// A cycle time to beat (s), from another plan of the same cell: `best` stops resolving a
    /// priority order with waits as soon as its programs end after it (waits only lengthen a
    /// program) and ranks it by that end; the two best orders are still tried with other
    /// poses. `None`: every order is resolved to the end.
    pub bar: Option<f64>,
    /// Nodes of `best`'s search over passage orders (work, not time: the result does not
    /// depend on the machine).
    pub schedule_nodes: usize,
    /// The shortest wait `best` adds (s): at least two trajectory sample steps, so that every
    /// wait shows in the sampled trajectory of the plan.
    pub min_wait: f64,
    /// Exact robot–robot distances the coordination diagrams of ours' plans may ask in all
    /// ([`crate::pipeline::coordinate`]; default
    /// [`crate::pipeline::OURS_COORDINATION_DISTANCES`]): beyond the first plan, a try or a
    /// hand-over is coordinated only while what was asked so far, plus as much again as the
    /// costliest coordination, stays within it (work, not time).
    pub ours_distances: usize,
    /// Beyond this many MPs × robots ours plans all its tries before coordinating any, and
    /// coordinates them most promising first (default [`crate::pipeline::PLAN_FIRST_PAIRS`]).
    pub plan_first_pairs: usize,
    /// After coordination, the legs without a wait on the way are timed through their corners
    /// without stopping, each corner's blend within this much (rad, per joint) of the corner
    /// and checked against the scene (see [`super::blend`]); 0: every leg stops at every waypoint.
    pub blend_deviation: f64,
    /// Polishing a coordinated plan: `best`'s searches over passage orders, where they end
    /// unproven, spend one more budget putting each robot back through the others (what ours
    /// does to its winner before blending, see [`crate::pipeline::coordinate`]).
    pub polish: bool,
    /// The run's wall-clock limit, for a coordination that may be given up: past it, the
    /// coordination stops between robot pairs' diagrams and between tour directions with
    /// [`crate::plan::PlanError::TimeLimit`] (ours' tries after the first and its hand-overs;
    /// `None`, the default: a coordination always finishes).
    pub deadline: Option<std::time::Instant>,
}

/// The default of [`CoordSettings::blend_deviation`] (rad).
pub const BLEND_DEVIATION: f64 = 0.1;

impl Default for CoordSettings {
    fn default() -> Self {
        CoordSettings {
            strategy: Coordination::Best,
            delay_step: 0.1,
            perturb_step: 4f64.to_radians(),
            perturb_evaluations: 12,
            seed: 0,
            bar: None,
            schedule_nodes: 20_000,
            min_wait: 0.05,
            ours_distances: crate::pipeline::OURS_COORDINATION_DISTANCES,
            plan_first_pairs: crate::pipeline::PLAN_FIRST_PAIRS,
            blend_deviation: BLEND_DEVIATION,
            polish: false,
            deadline: None,
        }
    }
}

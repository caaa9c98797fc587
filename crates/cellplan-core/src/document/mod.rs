//! The Plan document (`docs/plan-format.md`, schema `docs/plan.schema.json`, generated from
//! these types): versioned JSON, SI units (m, rad, s), written atomically. Its key names are
//! stable. Every number it states about the plan is recomputed by the `cellplan-verify` crate; `stats`
//! and `compute_s` describe the search that found it and are not claims about the plan.
//!
//! A document read from a file is checked by [`validate`] (sizes, magnitudes, orders) before
//! anything walks it; [`read`] does both.
mod build;
mod validate;

pub use build::{build, process_settings};
pub use build::{ratio, unmeasured_reason};
pub use validate::{DocumentError, MAX_PLAN_BYTES, matches_cell, read, validate};

use crate::coord::{Coordination, WaitReason};
use crate::plan::{self, Stop};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Value of the `format` key.
pub const FORMAT: &str = "cellplan-plan";
/// Value of the `version` key; raised when a key changes meaning or disappears.
pub const VERSION: u32 = 4;

/// A plan for a cell.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Plan {
    /// Always `cellplan-plan`.
    pub format: String,
    /// The layout's version (3).
    pub version: u32,
    /// Cell name.
    pub cell: String,
    /// Cell file, as given.
    pub cell_file: String,
    /// How the plan was made.
    pub settings: SettingsOut,
    /// The longest robot time (s).
    pub cycle_time_s: f64,
    /// Δt: the largest difference between the times of the robots that can do some task (s;
    /// the robots of `idle_robots` are left out).
    pub delta_t_s: f64,
    /// A lower bound of the cycle time over the candidates the planner considered (s): the
    /// min-max bound of paper 000's allocation problem on lower-bound move times, over the
    /// tasks the plan measures — its leg bound, or the route bound where `route_bound` is
    /// given and larger.
    pub lower_bound_s: f64,
    /// `cycle_time_s / lower_bound_s` (1 when the bound is 0).
    pub ratio_to_lower_bound: f64,
    /// The route bound of the same problem (`plan --route-bound`; absent without it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub route_bound: Option<RouteBoundOut>,
    /// Whether `cellplan verify` accepted the plan before it was written (false only when
    /// written with `--no-verify`).
    pub verified: bool,
    /// What coordination did.
    pub coordination: CoordinationOut,
    /// One entry per robot, in cell order.
    pub robots: Vec<RobotPlan>,
    /// Tasks no robot can do, with the reason.
    pub unmeasured: Vec<UnmeasuredTask>,
    /// Robots that can do none of the tasks, with the reason: they stay at home, and Δt leaves
    /// them out (absent when every robot can do some task).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub idle_robots: Vec<IdleRobotOut>,
    /// Counts of the search (not claims about the plan; `candidates` is checked).
    pub stats: Stats,
    /// Wall-clock seconds per stage.
    pub compute_s: ComputeTimes,
}

/// The route bound: column generation over whole routes of the allocation problem
/// (`cellplan_solve::minmax::route_bound`), stated with its certificate: the duals of the round
/// that set it, from which the verifier derives the bound again with one pricing per robot
/// (`cellplan_solve::minmax::lagrangian_bound`). How the run went (budget, work, rounds,
/// whether it was solved) is in `stats.route_bound`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RouteBoundOut {
    /// The bound (s); `lower_bound_s` is the larger of it and the leg bound.
    pub bound_s: f64,
    /// The leg bound it started from (s).
    pub legs_s: f64,
    /// The certificate: absent when no round beat the leg bound (`bound_s` is then `legs_s`).
    pub duals: Option<RouteDuals>,
}

/// Duals of the route bound's linear relaxation: any `π, μ ≥ 0` with `Σμ ≤ 1` prove the bound
/// `Σπ + Σ_robots min(0, least μ·time(r) − π(r) over the robot's programs r)`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RouteDuals {
    /// `π` per MP the bound covers (an MP left out has `π = 0`), seconds.
    pub mps: BTreeMap<String, f64>,
    /// `μ` per robot (a robot left out has `μ = 0`), summing to at most one.
    pub robots: BTreeMap<String, f64>,
}

impl RouteBoundOut {
    /// The record of `rb`; `tasks` names its problem's tasks in order, `robots` its vehicles.
    pub fn new(rb: &cellplan_solve::minmax::RouteBound, tasks: &[&str], robots: &[&str]) -> Self {
        let named = |names: &[&str], values: &[f64]| -> BTreeMap<String, f64> {
            names
                .iter()
                .zip(values)
                .map(|(n, &v)| (n.to_string(), v))
                .collect()
        };
        RouteBoundOut {
            bound_s: rb.bound,
            legs_s: rb.legs,
            duals: rb.duals.as_ref().map(|(pi, mu)| RouteDuals {
                mps: named(tasks, pi),
                robots: named(robots, mu),
            }),
        }
    }
}

/// How ours (`best` on the zones allocation) went through its coordination stage: the search,
/// not a claim about the plan (not checked); its seconds are in [`ComputeTimes::ours`].
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OursRun {
    /// Plans coordinated while choosing among ours' tries (the run's first plan, the strips,
    /// the nearest robots, the zones again, the balanced allocation where it runs).
    pub tries_coordinated: usize,
    /// Hand-over plans (single hand-overs, reliefs, groups) coordinated and judged after them.
    pub handovers_judged: usize,
    /// Whether a hand-over beat the best try (the plan is then one).
    pub handover_taken: bool,
    /// Whether the winner's coordination, polished (searched again, each robot then put back
    /// through the others where a search over passage orders ended unproven), ended sooner and
    /// was kept.
    #[serde(default)]
    pub polished: bool,
    /// Whether every coordination was polished as it was made (on cells beyond
    /// [`crate::coord::CoordSettings::plan_first_pairs`], where the work budget affords few);
    /// the winner is then not polished again.
    #[serde(default)]
    pub polished_throughout: bool,
    /// Plans blended and compared at the end (the winner and the runners-up within reach).
    pub blended: usize,
}

/// Wall seconds of ours' parts of its coordination stage, one after the other (they add up to
/// about [`ComputeTimes::coordination`]).
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, Default, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct OursTimes {
    /// Until the best try was known: the first plan's coordination, every other try's
    /// planning and coordination.
    pub tries: f64,
    /// The hand-overs: their planning and coordinations.
    pub handovers: f64,
    /// Polishing the winner's coordination.
    #[serde(default)]
    pub polish: f64,
    /// Blending the winner and the runners-up and choosing among them.
    pub blend: f64,
}

/// How a route bound's column generation went: the search, not a claim about the plan (not
/// checked; the bound is checked from its certificate).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RouteBoundRun {
    /// The budget: no round starts once its pricings have looked at this many arcs (a round
    /// may pass it).
    pub max_work: u64,
    /// Arcs its pricings looked at.
    pub work: u64,
    /// Rounds of column generation (0: the problem passes the size limits, and the bound is
    /// the leg bound).
    pub rounds: usize,
    /// Whether the relaxation was solved (else the bound is the best round's; see
    /// [`RouteBoundRun::ending`]).
    pub converged: bool,
    /// Whether the run's wall-clock limit (`--time-limit`) stopped it before its budget.
    pub cut_by_clock: bool,
}

impl RouteBoundRun {
    /// The run of `rb`, made under `max_work`.
    pub fn new(rb: &cellplan_solve::minmax::RouteBound, max_work: u64) -> Self {
        RouteBoundRun {
            max_work,
            work: rb.work,
            rounds: rb.rounds,
            converged: rb.converged,
            cut_by_clock: rb.clock_cut,
        }
    }

    /// How the run ended, in words.
    pub fn ending(&self) -> String {
        if self.converged {
            "the relaxation solved".to_string()
        } else if self.cut_by_clock {
            format!("cut by the time limit after {} rounds", self.rounds)
        } else if self.rounds == 0 {
            "not run: the problem passes its size limits (1,000 MPs, 60 M arcs), so the leg bound stands"
                .to_string()
        } else if self.work >= self.max_work {
            format!("cut by its budget of {:.2} G arcs", self.max_work as f64 * 1e-9)
        } else {
            "stopped before the relaxation was solved (its round limit or the linear solver)".to_string()
        }
    }
}

/// The settings of the run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SettingsOut {
    /// Allocation strategy.
    pub allocation: plan::Allocation,
    /// Set-cover method (local-robust only).
    pub cover: plan::CoverMethod,
    /// Move-time model of the lower-bound costs.
    pub move_model: plan::MoveModel,
    /// Seed.
    pub seed: u64,
    /// Wall-clock limit of the run (s); absent when none was given (the searches stopped at
    /// their work budgets).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_limit_s: Option<f64>,
    /// ε of the local robust sets (m).
    pub local_set_radius_m: f64,
    /// Candidates kept per task and robot for allocation and sequencing.
    pub alternatives: usize,
    /// Candidates this much roomier (m) than the clearance are kept first.
    pub roomy_m: f64,
    /// Trajectory sample step (s).
    pub sample_dt_s: f64,
    /// Clearance kept from the static scene (m).
    pub clearance_m: f64,
    /// The process: its `kind` and parameters (SI, keys with units).
    pub process: serde_json::Value,
    /// φ.
    pub task_cap: usize,
    /// γ (s), if any.
    pub balance_limit_s: Option<f64>,
    /// Coordination strategy.
    pub coordination: Coordination,
}

/// What coordination did.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CoordinationOut {
    /// The strategy.
    pub strategy: Coordination,
    /// Cycle time of the programs before coordination (s): what the plan would take if the
    /// robots could pass through each other.
    pub uncoordinated_cycle_time_s: f64,
    /// Conflicts of the programs before coordination.
    pub conflicts_before: Vec<ConflictOut>,
    /// Conflicts left (only with strategy `none`).
    pub conflicts_after: Vec<ConflictOut>,
    /// Waits in the programs.
    pub waits: usize,
    /// Working poses changed (perturbed).
    pub poses_changed: usize,
    /// Priority order (highest first), where the strategy uses one.
    pub priority: Vec<String>,
    /// Each robot's tool (TCP) position over time as planned before coordination, for the
    /// time–position chart of paper 000 Fig. 7 (the plan's own trajectories give Fig. 8).
    pub uncoordinated_probe: Vec<ProbeTrack>,
}

/// A robot's tool position sampled at a fixed step from time 0 to the end of its program.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProbeTrack {
    /// Robot name.
    pub robot: String,
    /// Sampling step (s); the last sample is the end of the program.
    pub dt_s: f64,
    /// Positions (m), rounded to 0.1 mm.
    pub xyz: Vec<[f64; 3]>,
}

/// Step of [`ProbeTrack`]s in plans.
pub const PROBE_TRACK_DT: f64 = 0.1;

/// A robot–robot conflict.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ConflictOut {
    /// The two robots.
    pub robots: [String; 2],
    /// First time found closer than the clearance (s).
    pub start_s: f64,
    /// First time found clear again (s).
    pub end_s: f64,
    /// Paper 000's scenario: 1 both working, 2 at least one moving or waiting.
    pub scenario: u8,
    /// What each robot was doing.
    pub activity: [ActivityOut; 2],
    /// Tool positions at `start_s` (m).
    pub probe_xyz: [[f64; 3]; 2],
}

/// What a robot is doing at a moment.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ActivityOut {
    /// Moving along leg `leg`, from one stop to the next.
    Moving {
        /// Index of the leg in the robot's `legs`.
        leg: usize,
        /// Where the leg starts.
        from: Stop,
        /// Where it ends.
        to: Stop,
    },
    /// Doing the work at a task.
    Working {
        /// The task id.
        task: String,
    },
    /// Standing at waypoint `waypoint` of leg `leg`.
    Waiting {
        /// Index of the leg.
        leg: usize,
        /// Index of the waypoint (0: the leg's start).
        waypoint: usize,
        /// Where the leg starts.
        from: Stop,
        /// Where it ends.
        to: Stop,
    },
}

impl ActivityOut {
    /// A phrase for people ("moving M3 → M7", "measuring M7", "waiting at M3"); `working` is
    /// the process's word for its work ([`Words::working`](cellplan_model::process::Words)).
    pub fn text(&self, working: &str) -> String {
        match self {
            ActivityOut::Moving { from, to, .. } => format!("moving {} → {}", from.label(), to.label()),
            ActivityOut::Working { task } => format!("{working} {task}"),
            ActivityOut::Waiting {
                waypoint: 0, from, ..
            } => format!("waiting at {}", from.label()),
            ActivityOut::Waiting { from, to, .. } => {
                format!("waiting on the way {} → {}", from.label(), to.label())
            }
        }
    }

    /// The tasks involved: the task ends of a leg, or the task worked at.
    pub fn tasks(&self) -> Vec<&str> {
        match self {
            ActivityOut::Moving { from, to, .. } => [from, to].into_iter().filter_map(Stop::task).collect(),
            ActivityOut::Working { task } => vec![task.as_str()],
            ActivityOut::Waiting {
                waypoint: 0, from, ..
            } => from.task().into_iter().collect(),
            ActivityOut::Waiting { .. } => Vec::new(),
        }
    }
}

/// One robot's part of the plan.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RobotPlan {
    /// Robot name.
    pub name: String,
    /// Joint names, the order of every `q`.
    pub joints: Vec<String>,
    /// Home configuration (rad or m per joint).
    pub home: Vec<f64>,
    /// The tasks in visiting order.
    pub tasks: Vec<Visit>,
    /// Start of the robot's program (s).
    pub start_s: f64,
    /// End, back at home (s).
    pub end_s: f64,
    /// Time moving: the legs' durations (s).
    pub motion_s: f64,
    /// Time working at the tasks (s).
    pub measuring_s: f64,
    /// Time standing still to let other robots pass: the waits' durations (s).
    pub waiting_s: f64,
    /// `end_s − start_s` (s).
    pub total_s: f64,
    /// Where and how long the robot waits, in program order.
    pub waits: Vec<WaitOut>,
    /// The legs: home → first task, …, last task → home.
    pub legs: Vec<LegOut>,
    /// The timed trajectory, sampled every `sample_dt_s` (and at its end), home to home.
    pub trajectory: Vec<Sample>,
}

impl RobotPlan {
    /// Where a wait stands, for people ("home", "M3", "on the way M3 → M7").
    pub fn wait_place(&self, w: &WaitOut) -> String {
        match self.legs.get(w.leg) {
            Some(leg) if w.waypoint == 0 => leg.from.label().to_string(),
            Some(leg) => format!("on the way {} → {}", leg.from.label(), leg.to.label()),
            None => format!("leg {}", w.leg),
        }
    }
}

/// One visit of a task.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
pub struct Visit {
    /// Task id (the task file's `id`).
    pub task: String,
    /// Index of the candidate among the robot's candidates for this task.
    pub candidate: usize,
    /// Joint configuration.
    pub q: Vec<f64>,
    /// Tool (TCP) pose in the world.
    pub tcp: PoseOut,
    /// The figures the process states about the visit (the optical probe's `view_angle_rad`),
    /// recomputed by the verifier.
    #[serde(flatten)]
    pub figures: BTreeMap<String, f64>,
    /// (Δw, Δp, Δr) (rad) when coordination perturbed the tool orientation of the candidate
    /// (paper 000 §4.2); null otherwise.
    pub perturbation_rad: Option<[f64; 3]>,
    /// Arrival (start of the work) (s).
    pub arrive_s: f64,
    /// Departure (end of the work) (s).
    pub depart_s: f64,
}

/// A wait.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct WaitOut {
    /// Index of the leg.
    pub leg: usize,
    /// Index of the waypoint of the leg where the robot stands (0: the leg's start).
    pub waypoint: usize,
    /// Start (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Why.
    pub reason: WaitReason,
    /// The robot it lets pass, if any.
    pub for_robot: Option<String>,
}

/// A pose: position (m) and unit quaternion (x, y, z, w).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PoseOut {
    /// Position (m).
    pub xyz: [f64; 3],
    /// Orientation (x, y, z, w).
    pub quat: [f64; 4],
}

/// One leg's path.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LegOut {
    /// Where it starts.
    pub from: Stop,
    /// Where it ends.
    pub to: Stop,
    /// Start of the motion (after any wait at its first waypoint) (s).
    pub start_s: f64,
    /// Moving time, waits excluded (s).
    pub duration_s: f64,
    /// Whether it is the direct joint segment (else found by the sampling planner).
    pub straight: bool,
    /// The collision-free joint path: straight segments between these waypoints.
    pub waypoints: Vec<Vec<f64>>,
    /// Corners crossed without stopping, in order (none: the leg stops at every waypoint).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub blends: Vec<BlendOut>,
}

/// A corner of a leg crossed without stopping: the joints leave the segment into waypoint
/// `waypoint` at distance `radius` before it and join the segment out of it at `radius` after
/// it (Euclidean joint-space distances), along the quadratic Bézier curve with control points
/// `p − radius·u_in`, `p`, `p + radius·u_out` (`u_in`, `u_out`: the unit directions of the two
/// segments) — the curve of a constant joint acceleration.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlendOut {
    /// The corner: an interior waypoint of the leg.
    pub waypoint: usize,
    /// Distance (joint space) from the corner at which the blend leaves and joins the path;
    /// at most half of either segment.
    pub radius: f64,
}

/// A trajectory sample.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Joint positions.
    pub q: Vec<f64>,
}

/// A task no robot can do.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct UnmeasuredTask {
    /// Task id.
    pub task: String,
    /// The furthest check any robot's pose passed: the process's rejection code (`view-angle`,
    /// `stripe`, … for the optical probe) or `no-ik`, `joint-limits`, `collision`; or
    /// [`NO_PATH`] when robots have poses for it but the motion planner found no path to any
    /// of them within its budget (see `detail`).
    pub reason: String,
    /// The planner's words for `no-path` (which leg, why); absent otherwise.
    #[serde(default)]
    pub detail: Option<String>,
}

/// A robot that can do none of the tasks.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct IdleRobotOut {
    /// Robot name.
    pub robot: String,
    /// Why, for people: its rejections counted, the nearest task and its reach.
    pub reason: String,
}

/// The reason of a task robots can reach but were given no path to.
pub const NO_PATH: &str = "no-path";

/// Counts of the search.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Stats {
    /// Candidates in the table (checked by the verifier).
    pub candidates: usize,
    /// Legs planned by the motion planner (straight or sampled).
    pub legs_planned: usize,
    /// Of those, legs the sampling planner had to solve.
    pub legs_sampled: usize,
    /// Legs for which no path was found (and that the sequence then avoided).
    pub legs_failed: usize,
    /// Sequencing rounds of the lazy loop, the most over the robots.
    pub sequencing_rounds: usize,
    /// Local robust sets built and chosen by the set cover (local-robust only).
    pub local_sets_built: usize,
    /// See `local_sets_built`.
    pub local_sets_chosen: usize,
    /// Conflicts coordination met and resolved (a resolution may meet new ones later on).
    pub conflicts_resolved: usize,
    /// `best`'s search over passage orders, when it ran.
    #[serde(default)]
    pub passage_search: Option<PassageSearch>,
    /// Whether the wall-clock limit (`--time-limit`) stopped a search before its work budget:
    /// then, and only then, the plan depends on the machine's speed.
    #[serde(default)]
    pub time_limit_hit: bool,
    /// How the route bound's search went (`plan --route-bound`; absent without it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub route_bound: Option<RouteBoundRun>,
    /// How ours spent its coordination stage (ours only: `best` on the zones allocation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ours: Option<OursRun>,
}

/// `best`'s search over the orders in which robots pass their conflict boxes.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PassageSearch {
    /// Conflict boxes of the coordination diagrams (every robot pair).
    pub boxes: usize,
    /// Exact robot–robot distances the diagrams asked.
    pub distances: usize,
    /// Nodes of the branch and bound, over every combination of tour directions tried (the
    /// searches of each robot pair alone, which bound it from below, included).
    pub nodes: usize,
    /// Whether the search for the tour directions chosen ended within its node budget or
    /// reached the bound of the robot pairs scheduled alone (the schedule is then the shortest
    /// the boxes allow for them; else the best found).
    pub proven: bool,
    /// Robots whose tours the search runs the other way round (the direction of each tour
    /// is chosen with the passage orders).
    #[serde(default)]
    pub reversed: usize,
}

/// Wall-clock seconds per stage.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ComputeTimes {
    /// Loading the cell.
    pub load: f64,
    /// Candidate generation.
    pub candidates: f64,
    /// Lower-bound move times.
    pub costs: f64,
    /// Allocation (of the run's first plan: ours' other plans count under `coordination`).
    pub allocation: f64,
    /// Sequencing with lazy motion planning (of the run's first plan, as `allocation`).
    pub sequencing_motion: f64,
    /// Timing and assembly.
    pub timing: f64,
    /// Coordination; for ours (`best` on the zones allocation), also the planning and
    /// coordinating of its other plans and hand-overs (see `pipeline::coordinate`).
    pub coordination: f64,
    /// The verifier.
    pub verification: f64,
    /// The route bound (`plan --route-bound`; 0 without it).
    #[serde(default)]
    pub route_bound: f64,
    /// Ours' parts of `coordination` (ours only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ours: Option<OursTimes>,
    /// Everything, including writing.
    pub total: f64,
}

/// The JSON Schema of the document, as `docs/plan.schema.json` holds it.
pub fn schema() -> String {
    cellplan_model::document::schema_text(&schemars::schema_for!(Plan))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// `docs/plan.schema.json` is the schema of these types (regenerate it with
    /// `CELLPLAN_UPDATE_SCHEMA=1 cargo test -p cellplan-core schema`).
    #[test]
    fn the_schema_in_docs_is_generated_from_the_types() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/plan.schema.json");
        let schema =
            cellplan_model::document::schema_file_matches(&path, &super::schema()).unwrap_or_else(|e| {
                panic!("{e}; regenerate it with CELLPLAN_UPDATE_SCHEMA=1 cargo test -p cellplan-core schema")
            });
        let required = schema["required"].as_array().unwrap();
        assert!(required.iter().any(|k| k == "coordination"), "{required:?}");
    }
}

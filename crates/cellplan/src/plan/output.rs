//! The Plan document (`docs/plan-format.md`, schema `docs/plan.schema.json`): versioned JSON, SI
//! units (m, rad, s), written atomically. Its key names are stable.
use super::{Outcome, PlanSettings, Stage};
use crate::Cell;
use crate::candidates::CandidateTable;
use crate::model::tasks::TaskId;
use serde::{Deserialize, Serialize};

/// Value of the `format` key.
pub const FORMAT: &str = "cellplan-plan";
/// Value of the `version` key; raised when a key changes meaning or disappears.
pub const VERSION: u32 = 1;

/// A plan for a cell.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Plan {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`] for this layout.
    pub version: u32,
    /// Cell name.
    pub cell: String,
    /// Cell file, as given.
    pub cell_file: String,
    /// How the plan was made.
    pub settings: SettingsOut,
    /// The longest robot time (s).
    pub cycle_time_s: f64,
    /// Largest difference between robot times (s).
    pub delta_t_s: f64,
    /// A lower bound of the cycle time of any plan of these MPs with these candidates (s).
    pub lower_bound_s: f64,
    /// `cycle_time_s / lower_bound_s`.
    pub ratio_to_lower_bound: f64,
    /// One entry per robot, in cell order.
    pub robots: Vec<RobotPlan>,
    /// MPs no robot can measure, with the reason.
    pub unmeasured: Vec<UnmeasuredTask>,
    /// Counts of the search.
    pub stats: Stats,
    /// Wall-clock seconds per stage.
    pub compute_s: ComputeTimes,
}

/// The settings of the run.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SettingsOut {
    /// `proximity`, `local-robust` or `balanced`.
    pub allocation: super::Allocation,
    /// `penalty` or `exact` (local-robust only).
    pub cover: super::CoverMethod,
    /// `trapezoid` or `instant`.
    pub move_model: super::MoveModel,
    /// Seed.
    pub seed: u64,
    /// Search budget (s).
    pub time_limit_s: f64,
    /// ε of the local robust sets (m).
    pub local_set_radius_m: f64,
    /// Trajectory sample step (s).
    pub sample_dt_s: f64,
    /// Clearance kept from the static scene (m).
    pub clearance_m: f64,
    /// Measuring time per MP (s).
    pub measure_time_s: f64,
    /// φ.
    pub task_cap: usize,
    /// γ (s), if any.
    pub balance_limit_s: Option<f64>,
}

/// One robot's part of the plan.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RobotPlan {
    /// Robot name.
    pub name: String,
    /// Joint names, the order of every `q`.
    pub joints: Vec<String>,
    /// Home configuration (rad or m per joint).
    pub home: Vec<f64>,
    /// The MPs in visiting order.
    pub tasks: Vec<Visit>,
    /// Start of the robot's program (s).
    pub start_s: f64,
    /// End, back at home (s).
    pub end_s: f64,
    /// Time moving (s).
    pub motion_s: f64,
    /// Time measuring (s).
    pub measuring_s: f64,
    /// `end_s − start_s` (s).
    pub total_s: f64,
    /// The legs: home → first MP, …, last MP → home.
    pub legs: Vec<LegOut>,
    /// The timed trajectory, sampled every `sample_dt_s` (and at its end), home to home.
    pub trajectory: Vec<Sample>,
}

/// One measurement.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Visit {
    /// MP id (the task file's `id`).
    pub task: String,
    /// Index of the candidate among the robot's candidates for this MP.
    pub candidate: usize,
    /// Joint configuration.
    pub q: Vec<f64>,
    /// Probe (TCP) pose in the world.
    pub tcp: PoseOut,
    /// Angle between the beam and the MP normal (rad).
    pub view_angle_rad: f64,
    /// Arrival (start of the measurement) (s).
    pub arrive_s: f64,
    /// Departure (end of the measurement) (s).
    pub depart_s: f64,
}

/// A pose: position (m) and unit quaternion (x, y, z, w).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PoseOut {
    /// Position (m).
    pub xyz: [f64; 3],
    /// Orientation (x, y, z, w).
    pub quat: [f64; 4],
}

/// One leg's path.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct LegOut {
    /// "home" or an MP id.
    pub from: String,
    /// "home" or an MP id.
    pub to: String,
    /// Start time (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Whether it is the direct joint segment (else found by the sampling planner).
    pub straight: bool,
    /// The collision-free joint path: straight segments between these waypoints.
    pub waypoints: Vec<Vec<f64>>,
}

/// A trajectory sample.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Sample {
    /// Time (s).
    pub t: f64,
    /// Joint positions.
    pub q: Vec<f64>,
}

/// An MP no robot can measure.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct UnmeasuredTask {
    /// MP id.
    pub task: String,
    /// The furthest stage any robot's pose reached (`no-ik`, `collision`, ...).
    pub reason: String,
}

/// Counts of the search.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Stats {
    /// Candidates in the table.
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
}

/// Wall-clock seconds per stage.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
pub struct ComputeTimes {
    /// Loading the cell.
    pub load: f64,
    /// Candidate generation.
    pub candidates: f64,
    /// Lower-bound move times.
    pub costs: f64,
    /// Allocation.
    pub allocation: f64,
    /// Sequencing with lazy motion planning.
    pub sequencing_motion: f64,
    /// Timing and assembly.
    pub timing: f64,
    /// Everything, including writing.
    pub total: f64,
}

/// Build the document from a run.
pub fn build(
    cell: &Cell,
    table: &CandidateTable,
    outcome: &Outcome,
    settings: &PlanSettings,
    load_s: f64,
    candidates_s: f64,
) -> Plan {
    let process = cell.optical();
    let mut robots = Vec::with_capacity(cell.robots.len());
    for (r, robot) in cell.robots.iter().enumerate() {
        let res = &outcome.robots[r];
        let graph = &outcome.graphs[r];
        let name_of = |node: usize| match graph.node_task[node] {
            None => "home".to_string(),
            Some((t, _)) => cell.tasks[t.0].name.clone(),
        };
        let tasks = res
            .sequence
            .nodes
            .iter()
            .zip(&res.visits)
            .map(|(&node, &(arrive, depart))| {
                let (t, c) = graph.node_task[node].expect("visited nodes are candidates");
                let cand = &table.get(t, robot.id).candidates[c];
                Visit {
                    task: cell.tasks[t.0].name.clone(),
                    candidate: c,
                    q: cand.q.clone(),
                    tcp: pose_out(&cand.tcp),
                    view_angle_rad: cand.view_angle,
                    arrive_s: arrive,
                    depart_s: depart,
                }
            })
            .collect();
        let mut legs = Vec::with_capacity(res.sequence.legs.len());
        let mut prev = 0usize;
        let mut clock = 0.0;
        for (i, leg) in res.sequence.legs.iter().enumerate() {
            let to = res.sequence.nodes.get(i).copied().unwrap_or(0);
            legs.push(LegOut {
                from: name_of(prev),
                to: name_of(to),
                start_s: clock,
                duration_s: leg.duration,
                straight: leg.straight,
                waypoints: leg.waypoints.clone(),
            });
            clock += leg.duration;
            if let Some(&(_, depart)) = res.visits.get(i) {
                clock = depart;
            }
            prev = to;
        }
        let total = res.trajectory.duration();
        robots.push(RobotPlan {
            name: robot.name.clone(),
            joints: robot.joint_names().into_iter().map(String::from).collect(),
            home: robot.home.clone(),
            tasks,
            start_s: 0.0,
            end_s: total,
            motion_s: res.motion,
            measuring_s: res.measuring,
            total_s: total,
            legs,
            trajectory: res
                .trajectory
                .sample(settings.sample_dt)
                .into_iter()
                .map(|(t, q)| Sample { t, q })
                .collect(),
        });
    }
    let times: Vec<f64> = robots.iter().map(|r| r.total_s).collect();
    let cycle = times.iter().copied().fold(0.0, f64::max);
    let delta = cycle - times.iter().copied().fold(f64::INFINITY, f64::min).min(cycle);
    let lb = outcome.allocated.lower_bound;
    let unmeasured = (0..cell.tasks.len())
        .filter(|&t| table.robots_for(TaskId(t)).is_empty())
        .map(|t| UnmeasuredTask {
            task: cell.tasks[t].name.clone(),
            reason: table.table[t]
                .iter()
                .filter_map(|reach| reach.reason())
                .max()
                .map_or("none", |r| r.name())
                .to_string(),
        })
        .collect();
    let mut compute = ComputeTimes {
        load: load_s,
        candidates: candidates_s,
        ..ComputeTimes::default()
    };
    for &(stage, s) in &outcome.compute {
        match stage {
            Stage::Costs => compute.costs = s,
            Stage::Allocation => compute.allocation = s,
            Stage::Sequencing => compute.sequencing_motion = s,
            Stage::Timing => compute.timing = s,
        }
    }
    compute.total = load_s + candidates_s + outcome.compute.iter().map(|x| x.1).sum::<f64>();
    let seqs = outcome.robots.iter().map(|r| &r.sequence);
    Plan {
        format: FORMAT.to_string(),
        version: VERSION,
        cell: cell.name.clone(),
        cell_file: cell.path.display().to_string(),
        settings: SettingsOut {
            allocation: settings.allocation,
            cover: settings.cover,
            move_model: settings.move_model,
            seed: settings.seed,
            time_limit_s: settings.time_limit.as_secs_f64(),
            local_set_radius_m: settings.local_set_radius,
            sample_dt_s: settings.sample_dt,
            clearance_m: process.clearance,
            measure_time_s: process.measure_time,
            task_cap: process.task_cap,
            balance_limit_s: process.balance_limit,
        },
        cycle_time_s: cycle,
        delta_t_s: delta,
        lower_bound_s: lb,
        ratio_to_lower_bound: if lb > 0.0 { cycle / lb } else { 1.0 },
        robots,
        unmeasured,
        stats: Stats {
            candidates: table.total(),
            legs_planned: seqs.clone().map(|s| s.legs_planned).sum(),
            legs_sampled: seqs.clone().map(|s| s.legs_sampled).sum(),
            legs_failed: seqs.clone().map(|s| s.legs_failed).sum(),
            sequencing_rounds: seqs.map(|s| s.rounds).max().unwrap_or(0),
            local_sets_built: outcome.allocated.local_sets.0,
            local_sets_chosen: outcome.allocated.local_sets.1,
        },
        compute_s: compute,
    }
}

fn pose_out(p: &cellplan_geom::Pose) -> PoseOut {
    let t = p.translation;
    let q = p.rotation;
    PoseOut {
        xyz: [t.x, t.y, t.z],
        quat: [q.x, q.y, q.z, q.w],
    }
}

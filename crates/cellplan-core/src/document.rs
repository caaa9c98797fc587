//! The Plan document (`docs/plan-format.md`, schema `docs/plan.schema.json`): versioned JSON, SI
//! units (m, rad, s), written atomically. Its key names are stable.
use crate::candidates::CandidateTable;
use crate::coord::{Activity, Conflict, Coordinated, Coordination, WaitReason};
use crate::plan::{self, Outcome, PlanSettings, Stage};
use cellplan_model::Cell;
use cellplan_model::Process;
use cellplan_model::tasks::TaskId;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Value of the `format` key.
pub const FORMAT: &str = "cellplan-plan";
/// Value of the `version` key; raised when a key changes meaning or disappears.
pub const VERSION: u32 = 2;

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
    /// Whether `cellplan verify` accepted the plan before it was written (false only when
    /// written with `--no-verify`).
    #[serde(default)]
    pub verified: bool,
    /// What coordination did.
    #[serde(default)]
    pub coordination: CoordinationOut,
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
    pub allocation: plan::Allocation,
    /// `penalty` or `exact` (local-robust only).
    pub cover: plan::CoverMethod,
    /// `trapezoid` or `instant`.
    pub move_model: plan::MoveModel,
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
    /// The process: its `kind` and parameters (SI, keys with units).
    pub process: serde_json::Value,
    /// φ.
    pub task_cap: usize,
    /// γ (s), if any.
    pub balance_limit_s: Option<f64>,
    /// `none`, `delay-startup`, `fixed-priority`, `pose-perturbation` or `best`.
    #[serde(default = "no_coordination")]
    pub coordination: Coordination,
}

fn no_coordination() -> Coordination {
    Coordination::None
}

/// What coordination did.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CoordinationOut {
    /// The strategy.
    pub strategy: Coordination,
    /// Cycle time of the programs before coordination (s): what the plan would take if the
    /// robots could pass through each other.
    pub uncoordinated_cycle_time_s: f64,
    /// Conflicts of the programs before coordination.
    pub conflicts_before: Vec<ConflictOut>,
    /// Conflicts met and resolved (a resolution may meet new ones later on).
    pub conflicts_resolved: usize,
    /// Conflicts left (only with strategy `none`).
    pub conflicts_after: Vec<ConflictOut>,
    /// Waits added.
    pub waits: usize,
    /// Measuring poses changed.
    pub poses_changed: usize,
    /// Priority order (highest first), where the strategy uses one.
    pub priority: Vec<String>,
    /// Wall seconds.
    pub compute_s: f64,
    /// Each robot's probe (TCP) position over time as planned before coordination, for the
    /// time–position chart of paper 000 Fig. 7 (the plan's own trajectories give Fig. 8).
    #[serde(default)]
    pub uncoordinated_probe: Vec<ProbeTrack>,
}

/// A robot's probe position sampled at a fixed step from time 0 to the end of its program.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
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

impl Default for CoordinationOut {
    fn default() -> Self {
        CoordinationOut {
            strategy: Coordination::None,
            uncoordinated_cycle_time_s: 0.0,
            conflicts_before: Vec::new(),
            conflicts_resolved: 0,
            conflicts_after: Vec::new(),
            waits: 0,
            poses_changed: 0,
            priority: Vec::new(),
            compute_s: 0.0,
            uncoordinated_probe: Vec::new(),
        }
    }
}

/// A robot–robot conflict.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ConflictOut {
    /// The two robots.
    pub robots: [String; 2],
    /// First time found closer than the clearance (s).
    pub start_s: f64,
    /// First time found clear again (s).
    pub end_s: f64,
    /// Paper 000's scenario: 1 both measuring, 2 moving between points.
    pub scenario: u8,
    /// What each robot was doing ("moving M3 → M7", "measuring M7", "waiting at M3").
    pub activity: [String; 2],
    /// The legs, as "from → to" ("" when measuring or waiting).
    pub legs: [String; 2],
    /// The MPs involved (the ends of each robot's leg, or the MP measured).
    pub tasks: [Vec<String>; 2],
    /// Probe positions at `start_s` (m).
    pub probe_xyz: [[f64; 3]; 2],
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
    /// Time standing still to let other robots pass (s).
    #[serde(default)]
    pub waiting_s: f64,
    /// `end_s − start_s` (s).
    pub total_s: f64,
    /// Where and how long the robot waits.
    #[serde(default)]
    pub waits: Vec<WaitOut>,
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
    /// The figures the process states about the visit (the optical probe's `view_angle_rad`),
    /// recomputed by the verifier.
    #[serde(flatten)]
    pub figures: BTreeMap<String, f64>,
    /// (Δw, Δp, Δr) (rad) when coordination perturbed the probe orientation of the candidate
    /// (paper 000 §4.2); null otherwise.
    #[serde(default)]
    pub perturbation_rad: Option<[f64; 3]>,
    /// Arrival (start of the measurement) (s).
    pub arrive_s: f64,
    /// Departure (end of the measurement) (s).
    pub depart_s: f64,
}

/// A wait.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct WaitOut {
    /// Index of the leg.
    pub leg: usize,
    /// Index of the waypoint of the leg where the robot stands (0: the leg's start).
    pub waypoint: usize,
    /// Where, for people ("home", "M3", "on the way M3 → M7").
    pub at: String,
    /// Start (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// `startup`, `give-way` or `fallback`.
    pub reason: String,
    /// The robot it lets pass, if any.
    pub for_robot: Option<String>,
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
    /// Coordination.
    #[serde(default)]
    pub coordination: f64,
    /// The verifier.
    #[serde(default)]
    pub verification: f64,
    /// Everything, including writing.
    pub total: f64,
}

/// The probe tracks of the programs before coordination (see [`ProbeTrack`]).
fn uncoordinated_probe(cell: &Cell, outcome: &Outcome) -> Vec<ProbeTrack> {
    let round = |v: f64| (v * 1e4).round() / 1e4;
    cell.robots
        .iter()
        .zip(&outcome.robots)
        .map(|(robot, res)| {
            let xyz = match res.program.timed(&plan::graph::limits_of(robot)) {
                Ok(timed) => {
                    let end = timed.trajectory.duration();
                    let steps = (end / PROBE_TRACK_DT).ceil() as usize;
                    (0..=steps)
                        .map(|k| {
                            let t = (k as f64 * PROBE_TRACK_DT).min(end);
                            let p = robot.tcp_pose(&timed.trajectory.position(t)).translation;
                            [round(p.x), round(p.y), round(p.z)]
                        })
                        .collect()
                }
                Err(_) => Vec::new(),
            };
            ProbeTrack {
                robot: robot.name.clone(),
                dt_s: PROBE_TRACK_DT,
                xyz,
            }
        })
        .collect()
}

/// The `settings.process` entry: `kind` first, then the process's parameters.
pub fn process_settings(process: &dyn Process) -> serde_json::Value {
    let mut map = serde_json::Map::new();
    map.insert("kind".into(), process.kind().into());
    if let serde_json::Value::Object(params) = process.parameters() {
        map.extend(params);
    }
    serde_json::Value::Object(map)
}

/// Build the document from a run and its coordination.
pub fn build(
    cell: &Cell,
    table: &CandidateTable,
    outcome: &Outcome,
    coordinated: &Coordinated,
    settings: &PlanSettings,
    load_s: f64,
    candidates_s: f64,
) -> Plan {
    let process = cell.process.as_ref();
    let mut robots = Vec::with_capacity(cell.robots.len());
    for (r, robot) in cell.robots.iter().enumerate() {
        let prog = &coordinated.programs[r];
        let timed = &coordinated.timed[r];
        let name_of = |k: usize| prog.stop_name(cell, k);
        let tasks = prog
            .visits
            .iter()
            .zip(&timed.visits)
            .map(|(v, &(arrive, depart))| Visit {
                task: cell.tasks[v.task.0].name.clone(),
                candidate: v.candidate,
                q: v.q.clone(),
                tcp: pose_out(&v.tcp),
                figures: process
                    .visit_figures(&cell.tasks[v.task.0], &v.tcp)
                    .into_iter()
                    .map(|f| (f.key.to_string(), f.value))
                    .collect(),
                perturbation_rad: v.perturbation,
                arrive_s: arrive,
                depart_s: depart,
            })
            .collect();
        let legs = prog
            .legs
            .iter()
            .enumerate()
            .map(|(k, leg)| LegOut {
                from: name_of(k),
                to: name_of(k + 1),
                start_s: timed.arrivals[k][0] + prog.wait_at(k, 0).map_or(0.0, |w| w.duration),
                duration_s: leg.duration(),
                straight: leg.straight,
                waypoints: leg.waypoints.clone(),
            })
            .collect();
        let waits = prog
            .waits
            .iter()
            .zip(&timed.wait_starts)
            .map(|(w, &start)| WaitOut {
                leg: w.leg,
                waypoint: w.waypoint,
                at: if w.waypoint == 0 {
                    name_of(w.leg)
                } else {
                    format!("on the way {} → {}", name_of(w.leg), name_of(w.leg + 1))
                },
                start_s: start,
                duration_s: w.duration,
                reason: match w.reason {
                    WaitReason::Startup => "startup",
                    WaitReason::GiveWay => "give-way",
                    WaitReason::Fallback => "fallback",
                }
                .into(),
                for_robot: w.for_robot.map(|o| cell.robots[o].name.clone()),
            })
            .collect();
        let total = timed.end();
        robots.push(RobotPlan {
            name: robot.name.clone(),
            joints: robot.joint_names().into_iter().map(String::from).collect(),
            home: robot.home.clone(),
            tasks,
            start_s: 0.0,
            end_s: total,
            motion_s: prog.motion(),
            measuring_s: prog.working(),
            waiting_s: prog.waiting(),
            total_s: total,
            waits,
            legs,
            trajectory: timed
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
                .map_or("none", |r| r.code())
                .to_string(),
        })
        .collect();
    let mut compute = ComputeTimes {
        load: load_s,
        candidates: candidates_s,
        coordination: coordinated.compute_s,
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
    compute.total =
        load_s + candidates_s + outcome.compute.iter().map(|x| x.1).sum::<f64>() + coordinated.compute_s;
    let seqs = outcome.robots.iter().map(|r| &r.sequence);
    let conflicts = |list: &[Conflict]| -> Vec<ConflictOut> {
        list.iter().map(|c| conflict_out(cell, coordinated, c)).collect()
    };
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
            clearance_m: cell.planning.clearance,
            task_cap: cell.planning.task_cap,
            balance_limit_s: cell.planning.balance_limit,
            process: process_settings(process),
            coordination: coordinated.strategy,
        },
        cycle_time_s: cycle,
        delta_t_s: delta,
        lower_bound_s: lb,
        ratio_to_lower_bound: if lb > 0.0 { cycle / lb } else { 1.0 },
        verified: false,
        coordination: CoordinationOut {
            strategy: coordinated.strategy,
            uncoordinated_cycle_time_s: coordinated.uncoordinated_cycle,
            conflicts_before: conflicts(&coordinated.before),
            conflicts_resolved: coordinated.resolved,
            conflicts_after: conflicts(&coordinated.after),
            waits: coordinated.waits,
            poses_changed: coordinated.poses_changed,
            priority: coordinated
                .priority
                .iter()
                .map(|&r| cell.robots[r].name.clone())
                .collect(),
            compute_s: coordinated.compute_s,
            uncoordinated_probe: uncoordinated_probe(cell, outcome),
        },
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

/// A conflict for the document.
fn conflict_out(cell: &Cell, coordinated: &Coordinated, c: &Conflict) -> ConflictOut {
    let robots = [c.robots.0, c.robots.1];
    // Coordination keeps every robot's order of visits, so the final programs name them.
    let progs = &coordinated.programs;
    let one = |k: usize| {
        let prog = &progs[robots[k]];
        let name = |i: usize| prog.stop_name(cell, i);
        let (leg, tasks) = match c.activity[k] {
            Activity::Move { leg, .. } => (
                format!("{} → {}", name(leg), name(leg + 1)),
                [name(leg), name(leg + 1)]
                    .into_iter()
                    .filter(|n| n != "home")
                    .collect(),
            ),
            Activity::Measure { visit } => (String::new(), vec![name(visit + 1)]),
            Activity::Wait { leg, .. } => (
                String::new(),
                vec![name(leg)].into_iter().filter(|n| n != "home").collect(),
            ),
        };
        (
            crate::coord::timeline::activity_text(cell, prog, c.activity[k]),
            leg,
            tasks,
        )
    };
    let (a0, l0, t0) = one(0);
    let (a1, l1, t1) = one(1);
    ConflictOut {
        robots: [
            cell.robots[robots[0]].name.clone(),
            cell.robots[robots[1]].name.clone(),
        ],
        start_s: c.start,
        end_s: c.end,
        scenario: c.scenario.number(),
        activity: [a0, a1],
        legs: [l0, l1],
        tasks: [t0, t1],
        probe_xyz: [c.tcp[0].to_array(), c.tcp[1].to_array()],
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

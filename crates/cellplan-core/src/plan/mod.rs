//! `cellplan plan`: allocation, sequencing, collision-free motion and timing (paper 000 §3–§4.1,
//! with paper 002's lazy path costs). Stages, each a function of plain data:
//!
//! 1. [`graph`]: per robot, home and candidates with lower-bound move times between them;
//! 2. [`allocate`]: which robot measures which MP (proximity, local-robust, balanced);
//! 3. [`sequence`]: per robot, the order and candidates as a GTSP, legs planned lazily;
//! 4. timing: every leg timed under the joint limits, a dwell for each measurement;
//! 5. [`crate::document`]: the Plan document.
pub mod allocate;
mod cache;
pub mod graph;
pub mod rebalance;
mod rows;
pub mod sequence;

pub use allocate::{Allocation, CoverMethod};
pub use cache::PlanCache;
pub use graph::MoveModel;
pub use rows::{order_rule, robot_rows, sweep_keys};

use crate::candidates::CandidateTable;
use crate::coord::Program;
use cellplan_model::Cell;
use cellplan_model::tasks::TaskId;
use cellplan_motion::plan::PlanSettings as MotionSettings;
use cellplan_solve::CostMatrix;
use graph::RobotGraph;
use rayon::prelude::*;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Knobs of a planning run.
#[derive(Clone, Debug)]
pub struct PlanSettings {
    /// Allocation strategy.
    pub allocation: Allocation,
    /// Set-cover method of the local-robust strategy.
    pub cover: CoverMethod,
    /// Move-time model of the lower-bound costs.
    pub move_model: MoveModel,
    /// Seed of every random choice.
    pub seed: u64,
    /// Wall-clock limit of the whole run (every stage); the searches stop at their work
    /// budgets, so the plan depends on this only when it cuts (then `time_limit_hit`).
    /// Default: [`PlanSettings::NO_TIME_LIMIT`].
    pub time_limit: Duration,
    /// ε of eq. 4 (m): MPs closer than this may form a local robust set.
    pub local_set_radius: f64,
    /// Kicks of the balanced strategy's min-max search.
    pub balanced_iterations: usize,
    /// Re-allocations of the balanced strategy on the costs learnt while sequencing.
    pub reallocation_rounds: usize,
    /// Most sequencing rounds of the lazy loop per robot (twice that while its best order
    /// still needs a leg the quick planner gave up on).
    pub lazy_rounds: usize,
    /// The lazy loop stops when no order can beat the best fully planned one by more than
    /// this fraction (its optimistic cost, with unplanned legs at their bound, is not lower).
    pub lazy_tolerance: f64,
    /// Candidates kept per task and robot for sequencing (see [`graph::select`]).
    pub alternatives: usize,
    /// Candidates with at least this much more clearance (m) than the process asks are kept
    /// first (see [`graph::select`]); 0 keeps them regardless.
    pub roomy: f64,
    /// Settings of every leg's path planner (its seed is derived per leg); its shortcut
    /// iterations apply while the lazy loop ranks orders.
    pub motion: MotionSettings,
    /// Shortcut iterations for the sampled legs of the final orders.
    pub final_shortcut_iterations: usize,
    /// Sample budget for legs of the final orders that the lazy rounds' budget
    /// (`motion.max_samples`) did not solve.
    pub final_max_samples: usize,
    /// Whether a leg the sampler cannot solve goes through the robot's shared roadmap
    /// ([`graph::RobotGraph::roadmap`]); on by default.
    pub roadmap: bool,
    /// Time step of the trajectory samples written to the plan (s).
    pub sample_dt: f64,
    /// When the whole run must end (set by the pipeline from `time_limit` at its start, so
    /// that one limit bounds every stage); `None`: `time_limit` from the start of [`plan`].
    pub deadline: Option<Instant>,
    /// Extra seconds the zones allocation counts for a robot doing a task, `[task][robot]`
    /// (empty: none): what its measurement there cost the other robots in an earlier
    /// coordination (see [`crate::coord::Coordinated::blocking`]).
    pub task_penalty: Vec<Vec<f64>>,
    /// A direction in the floor plane (unit `[x, y]`) along which the robots stand (`None`:
    /// none). With it, the zones allocation draws strips across it instead (see
    /// [`allocate`]), and each robot's order visits its tasks in [`sequence::SWEEP_GROUPS`]
    /// groups of rising place along it, one group after the other, wherever some order can
    /// (see [`sequence::best_order`]): every robot sweeping the same way, neighbours stay
    /// about a strip apart.
    pub sweep: Option<[f64; 2]>,
    /// A fixed allocation, per robot its tasks (`None`: the allocation strategy decides). The
    /// caller keeps it within the caps and to robots able to do each task; see
    /// [`rebalance::rebalance`].
    pub tasks: Option<Vec<Vec<TaskId>>>,
    /// Tasks each robot visits after all its others, wherever some order can (none by
    /// default): where a robot waits for a neighbour on its way to a task, the same tour with
    /// that task at its end may pass when the neighbour has gone (see
    /// [`rebalance::rebalance`]'s reorders).
    pub late: Vec<TaskId>,
    /// Also prove the route bound ([`allocate::route_bound`]) with this work budget, in arcs
    /// its pricings look at (`None`: the leg bound alone, as by default). The plan states the
    /// larger bound, and the verifier derives the route bound again under the same budget.
    pub route_bound_work: Option<u64>,
    /// Give the plan up ([`PlanError::TimeLimit`]) once `deadline` has passed, between
    /// sequencing rounds and between the phases of full-budget retries, instead of finishing
    /// it: for a plan the run can do without (ours' tries after the first, its hand-overs).
    /// Off by default: past the deadline a plan stops searching but finishes its legs.
    pub give_up_at_deadline: bool,
}

impl PlanSettings {
    /// The `time_limit` meaning none (a year): the searches stop at their work budgets.
    pub const NO_TIME_LIMIT: Duration = Duration::from_secs(365 * 24 * 3600);

    /// When a run started at `start` must end under `time_limit`.
    pub fn deadline_from(&self, start: Instant) -> Instant {
        start
            .checked_add(self.time_limit)
            .or_else(|| start.checked_add(Self::NO_TIME_LIMIT))
            .unwrap_or(start)
    }
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            allocation: Allocation::Zones,
            cover: CoverMethod::Penalty,
            move_model: MoveModel::Trapezoid,
            seed: 0,
            time_limit: PlanSettings::NO_TIME_LIMIT,
            local_set_radius: 0.3,
            balanced_iterations: 200,
            alternatives: 24,
            roomy: 0.02,
            lazy_rounds: 4,
            reallocation_rounds: 0,
            lazy_tolerance: 0.01,
            motion: MotionSettings {
                time_limit: Duration::from_secs(30),
                shortcut_iterations: 10,
                max_samples: 60,
                ..MotionSettings::default()
            },
            final_shortcut_iterations: 40,
            final_max_samples: 20_000,
            roadmap: true,
            sample_dt: 0.02,
            task_penalty: Vec::new(),
            sweep: None,
            tasks: None,
            late: Vec::new(),
            route_bound_work: None,
            deadline: None,
            give_up_at_deadline: false,
        }
    }
}

/// Why a leg could not be had.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LegError {
    /// The path planner found no collision-free path.
    #[error(transparent)]
    Motion(#[from] cellplan_motion::plan::PlanError),
    /// The path could not be timed.
    #[error(transparent)]
    Timing(#[from] cellplan_motion::timing::TimingError),
    /// Not searched: a full search from a pose the robot reaches from home found no path to
    /// one of the leg's ends, so no leg to that end can be part of a tour.
    #[error("{0}")]
    Unreached(Box<Unreached>),
}

/// See [`LegError::Unreached`].
#[derive(Clone, Debug, PartialEq)]
pub struct Unreached {
    /// The pose the search started from (a label: `home` or the task).
    pub from: String,
    /// The end it did not reach.
    pub to: String,
    /// The samples that search drew.
    pub samples: usize,
}

impl std::fmt::Display for Unreached {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "not searched again: the full search from {}", self.from)?;
        if self.from != Stop::Home.to_string() {
            write!(f, ", which the robot reaches from home,")?;
        }
        write!(f, " found no path to {} ({} samples)", self.to, self.samples)
    }
}

/// Where a robot stands between legs: at home or at a task. In the Plan document: `"home"` or
/// `{"task": "M3"}` (so a task may be named `home`).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Stop {
    /// The robot's home configuration.
    Home,
    /// A task, by its name.
    Task(String),
}

impl Stop {
    /// The task's name, or `home`: a label for people, not an identifier.
    pub fn label(&self) -> &str {
        match self {
            Stop::Home => "home",
            Stop::Task(t) => t,
        }
    }

    /// The task's name, if it is a task.
    pub fn task(&self) -> Option<&str> {
        match self {
            Stop::Home => None,
            Stop::Task(t) => Some(t),
        }
    }
}

impl std::fmt::Display for Stop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stop::Home => f.write_str("home"),
            Stop::Task(t) => write!(f, "task `{t}`"),
        }
    }
}

/// Why no plan.
#[derive(Debug, Clone, thiserror::Error)]
pub enum PlanError {
    /// A task only robots already at their task cap can do.
    #[error(
        "task `{task}` cannot be allocated: every robot able to do it already has task_cap = {cap} tasks"
    )]
    TaskCap {
        /// The task.
        task: String,
        /// φ.
        cap: usize,
    },
    /// The robots' caps cannot hold every task some robot can do.
    #[error("the robots' task caps cannot hold every task they can do: {reason}")]
    CapsTooSmall {
        /// The solver's finding.
        reason: cellplan_solve::minmax::MinMaxError,
    },
    /// A strategy the process does not support.
    #[error("{what} needs something the `{process}` process does not define")]
    Unsupported {
        /// The strategy.
        what: &'static str,
        /// The process kind.
        process: &'static str,
    },
    /// A leg of the final order has no path.
    #[error("robot `{robot}`: no collision-free path from {from} to {to}: {source}")]
    NoPath {
        /// The robot.
        robot: String,
        /// Where the leg starts.
        from: Stop,
        /// Where it ends.
        to: Stop,
        /// Why.
        source: LegError,
    },
    /// Two robots still meet after coordination.
    #[error("coordination: robots `{}` and `{}` still meet at {at:.2} s", robots[0], robots[1])]
    StillMeet {
        /// The robots.
        robots: [String; 2],
        /// When (s).
        at: f64,
    },
    /// Neither robot of a conflict can give way.
    #[error("coordination: robots `{}` and `{}` meet at {at:.2} s and neither can wait (or, where allowed, take another pose) to let the other pass", robots[0], robots[1])]
    Deadlock {
        /// The robots.
        robots: [String; 2],
        /// When (s).
        at: f64,
    },
    /// Resolutions keep producing conflicts.
    #[error("coordination: {0} conflicts resolved and more keep coming; giving up")]
    TooManyConflicts(usize),
    /// No priority order resolves every conflict.
    #[error(
        "coordination: no priority order resolves every conflict (a robot stands in another's path at home)"
    )]
    NoPriorityOrder,
    /// The run's wall-clock limit passed during a coordination that may be given up.
    #[error("coordination: the time limit passed before it finished")]
    TimeLimit,
    /// Timing failed (should not happen on a planner's path).
    #[error("timing: {0}")]
    Timing(#[from] cellplan_motion::timing::TimingError),
}

impl PlanError {
    /// Whether the cell's own limits (caps, the process) rule the plan out, rather than the
    /// search failing.
    pub fn is_input(&self) -> bool {
        matches!(
            self,
            PlanError::TaskCap { .. } | PlanError::CapsTooSmall { .. } | PlanError::Unsupported { .. }
        )
    }
}

/// The stages, for progress reports; serialized (and displayed) by their key in `compute_s`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Lower-bound move times between candidates.
    Costs,
    /// Allocation.
    Allocation,
    /// Sequencing with lazy motion planning.
    #[serde(rename = "sequencing_motion")]
    Sequencing,
    /// Time parameterisation and assembly.
    Timing,
}

/// Name in reports and in `compute_s` (the serde name).
impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(cellplan_model::names::serde_name(self))
    }
}

/// One robot's result, before coordination.
#[derive(Clone, Debug)]
pub struct RobotResult {
    /// The sequence with its legs.
    pub sequence: sequence::Sequence,
    /// The sequence as a program: its measuring poses and its legs, timed (no waits yet).
    pub program: Program,
}

/// Everything a run produced.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Per robot graphs (shared with the other plans of the cell made through one
    /// [`PlanCache`]: they depend on the settings of the costs only).
    pub graphs: Arc<Vec<RobotGraph>>,
    /// The allocation.
    pub allocated: allocate::Allocated,
    /// Per robot results.
    pub robots: Vec<RobotResult>,
    /// Seconds per stage, in stage order.
    pub compute: Vec<(Stage, f64)>,
    /// Whether the wall-clock limit stopped a search before its work budget (the plan then
    /// depends on the machine's speed).
    pub time_limit_hit: bool,
    /// Tasks some robot has candidates for but no robot could be given a path to (each given
    /// up by its robot, then tried on every other robot that can do it): why.
    pub unreached: Vec<(TaskId, String)>,
}

/// Plan `cell` from its candidate table. `progress` is told when each stage starts.
pub fn plan(
    cell: &Cell,
    table: &CandidateTable,
    settings: &PlanSettings,
    progress: &(dyn Fn(Stage) + Sync),
) -> Result<Outcome, PlanError> {
    plan_cached(cell, table, settings, progress, &mut PlanCache::default())
}

/// The min-max problem the allocations of `cell` work on with `settings` (its move model,
/// alternatives and room): per robot its graph's lower-bound move times between home and its
/// candidates, per measurable task the robots' candidates for it and its measuring time, the
/// task cap and γ; with the cell task of each of its tasks. Its lower bound is the plan's
/// ([`allocate::Allocated::lower_bound`]). `cellplan check --minmax-out` writes it in the min-max format
/// (docs/minmax-format.md), so that the allocation can be studied with `cellplan bench minmax`
/// and the peers.
pub fn allocation_problem(
    cell: &Cell,
    table: &CandidateTable,
    settings: &PlanSettings,
) -> Result<(cellplan_solve::minmax::MinMaxProblem, Vec<usize>), PlanError> {
    let graphs = robot_graphs(cell, table, settings);
    let capable: Vec<Vec<usize>> = (0..cell.tasks.len())
        .map(|t| table.robots_for(TaskId(t)).into_iter().map(|r| r.0).collect())
        .collect();
    allocate::min_max_problem(cell, &graphs, &capable)
}

/// Each robot's move-time graph with `settings`' move model, alternatives and room (in
/// parallel; each graph depends on its robot only).
fn robot_graphs(cell: &Cell, table: &CandidateTable, settings: &PlanSettings) -> Vec<RobotGraph> {
    cell.robots
        .par_iter()
        .map(|r| {
            RobotGraph::new(
                cell,
                r,
                table,
                settings.move_model,
                settings.alternatives,
                settings.roomy,
            )
        })
        .collect()
}

/// [`plan`], sharing graphs and planned legs with earlier runs through `cache`.
pub fn plan_cached(
    cell: &Cell,
    table: &CandidateTable,
    settings: &PlanSettings,
    progress: &(dyn Fn(Stage) + Sync),
    cache: &mut PlanCache,
) -> Result<Outcome, PlanError> {
    plan_keeping(cell, table, settings, progress, cache, None)
}

/// [`plan_cached`], where every robot whose tasks are those it has in `prior` (a plan of the
/// same cell and settings but the allocation) keeps its sequence and program from `prior`
/// unless sequencing it again (with the legs planned since) gives a shorter program: a
/// robot's program depends on its tasks only (its legs keep clear of the others parked at
/// home). Robots that keep their programs keep their paths, and coordination reuses their
/// pairs' diagrams (see [`crate::coord::DiagramCache`]).
pub fn plan_keeping(
    cell: &Cell,
    table: &CandidateTable,
    settings: &PlanSettings,
    progress: &(dyn Fn(Stage) + Sync),
    cache: &mut PlanCache,
    prior: Option<&Outcome>,
) -> Result<Outcome, PlanError> {
    let started = Instant::now();
    let deadline = settings.deadline.unwrap_or(settings.deadline_from(started));
    let mut compute = Vec::new();
    let mut lap = Instant::now();
    let mut tick = |stage: Stage, compute: &mut Vec<(Stage, f64)>| {
        compute.push((stage, lap.elapsed().as_secs_f64()));
        lap = Instant::now();
    };

    progress(Stage::Costs);
    let key = (
        settings.move_model,
        settings.alternatives,
        settings.roomy.to_bits(),
    );
    let (graphs, bound) = cache.graphs_for(key, cell.robots.len(), || robot_graphs(cell, table, settings));
    tick(Stage::Costs, &mut compute);

    progress(Stage::Allocation);
    let mut allocated = allocate::allocate_bounded(cell, table, &graphs, settings, None, &bound)?;
    // The allocation searches stop at their iteration counts; past the deadline, the clock
    // stopped them.
    let mut clock_cut = Instant::now() >= deadline;
    tick(Stage::Allocation, &mut compute);

    progress(Stage::Sequencing);
    let mut planned: Vec<sequence::Planned> = std::mem::take(&mut cache.planned);
    planned.resize_with(cell.robots.len(), Default::default);
    let mut counts = vec![(0usize, 0usize, 0usize); cell.robots.len()];
    let mut sequences = sequence_all(
        cell,
        &graphs,
        &allocated.tasks,
        settings,
        deadline,
        f64::INFINITY,
        &mut planned,
        &mut counts,
    )?
    // Without a bar, only the deadline beats a sequence (`give_up_at_deadline`).
    .ok_or(PlanError::TimeLimit)?;
    if settings.allocation == Allocation::Balanced {
        // Re-allocate on what is known now: planned legs at their real time (paper 002's lazy
        // costs, one level up); keep the better plan. An alternative is sequenced only as long
        // as its robots' optimistic times stay below the best real makespan (the lazy bar), so
        // one that cannot win costs a sequencing round, not its legs.
        let makespan = |seqs: &[sequence::Sequence], planned: &[sequence::Planned]| {
            seqs.iter()
                .enumerate()
                .map(|(r, s)| sequence::order_cost(&graphs[r], &planned[r], &s.nodes))
                .fold(0.0, f64::max)
        };
        // The nearest-robot allocation is tried too, so that ours is never worse than the
        // baseline on the real times.
        let proximity = allocate::allocate_bounded(
            cell,
            table,
            &graphs,
            &PlanSettings {
                allocation: Allocation::Proximity,
                ..settings.clone()
            },
            None,
            &bound,
        )?;
        let mut tried = vec![allocated.tasks.clone()];
        for round in 0..=settings.reallocation_rounds {
            if Instant::now() >= deadline {
                clock_cut = true;
                break;
            }
            let next = if round == 0 {
                proximity.tasks.clone()
            } else {
                let mixed: Vec<CostMatrix> = graphs
                    .iter()
                    .zip(&planned)
                    .map(|(g, p)| mixed_costs(g, p))
                    .collect();
                allocate::allocate_bounded(cell, table, &graphs, settings, Some(&mixed), &bound)?.tasks
            };
            if tried.contains(&next) {
                continue;
            }
            tried.push(next.clone());
            let bar = makespan(&sequences, &planned) - 1e-9;
            let Some(seqs) = sequence_all(
                cell,
                &graphs,
                &next,
                settings,
                deadline,
                bar,
                &mut planned,
                &mut counts,
            )?
            else {
                continue;
            };
            if makespan(&seqs, &planned) < makespan(&sequences, &planned) - 1e-9 {
                sequences = seqs;
                allocated.tasks = next;
            }
        }
    }
    let unreached = reassign_dropped(
        cell,
        table,
        &graphs,
        settings,
        deadline,
        &mut sequences,
        &mut allocated,
        &mut planned,
        &mut counts,
    )?;
    for (s, c) in sequences.iter_mut().zip(&counts) {
        (s.legs_planned, s.legs_sampled, s.legs_failed) = *c;
    }
    let sequences_cut = sequences.iter().any(|s| s.clock_cut);
    cache.planned = planned;
    sequences
        .par_iter_mut()
        .zip(&cell.robots)
        .zip(&graphs[..])
        .for_each(|((seq, robot), graph)| sequence::polish(cell, robot, graph, seq, settings));
    tick(Stage::Sequencing, &mut compute);

    progress(Stage::Timing);
    let mut robots = Vec::with_capacity(sequences.len());
    for (r, ((sequence, graph), robot)) in sequences
        .into_iter()
        .zip(graphs.iter())
        .zip(&cell.robots)
        .enumerate()
    {
        let new = RobotResult {
            program: Program::from_sequence(cell, table, robot, graph, &sequence)?,
            sequence,
        };
        // What the robot had in `prior`, if its tasks are the same (on the final allocation:
        // the balanced one may have changed it, dropped tasks moved) and its order leaves the
        // late ones to the end.
        let kept = prior
            .filter(|p| p.allocated.tasks.get(r) == allocated.tasks.get(r))
            .and_then(|p| p.robots.get(r))
            .filter(|k| late_last(graph, &k.sequence.nodes, &settings.late));
        let result = match kept {
            Some(k) if k.program.duration() <= new.program.duration() + 1e-9 => k.clone(),
            _ => new,
        };
        robots.push(result);
    }
    tick(Stage::Timing, &mut compute);
    Ok(Outcome {
        graphs,
        allocated,
        robots,
        compute,
        unreached,
        time_limit_hit: clock_cut || sequences_cut,
    })
}

/// Whether an order (`nodes` of `graph`) visits no task of `late` before one that is not.
fn late_last(graph: &RobotGraph, nodes: &[usize], late: &[TaskId]) -> bool {
    let is_late = |n: &usize| graph.node_task[*n].is_some_and(|(t, _)| late.contains(&t));
    nodes.iter().skip_while(|n| !is_late(n)).all(is_late)
}

/// The tasks the robots gave up (no path), each tried on the other robots that have
/// candidates for it and room under the task cap, the least busy first: the first whose sequence then includes it, giving
/// up nothing else, takes it. Returns the tasks nobody could take, with the first robot's
/// reason.
#[allow(clippy::too_many_arguments)]
fn reassign_dropped(
    cell: &Cell,
    table: &CandidateTable,
    graphs: &[RobotGraph],
    settings: &PlanSettings,
    deadline: Instant,
    sequences: &mut [sequence::Sequence],
    allocated: &mut allocate::Allocated,
    planned: &mut [sequence::Planned],
    counts: &mut [(usize, usize, usize)],
) -> Result<Vec<(TaskId, String)>, PlanError> {
    let dropped: Vec<(usize, TaskId, String)> = sequences
        .iter_mut()
        .enumerate()
        .flat_map(|(r, s)| {
            std::mem::take(&mut s.dropped)
                .into_iter()
                .map(move |(t, why)| (r, t, why))
        })
        .collect();
    let mut unreached = Vec::new();
    for (r, t, why) in dropped {
        allocated.tasks[r].retain(|&x| x != t);
        let mut others: Vec<usize> = table
            .robots_for(t)
            .into_iter()
            .map(|id| id.0)
            .filter(|&s| s != r && allocated.tasks[s].len() < cell.planning.task_cap)
            .collect();
        let time = |s: usize| sequence::order_cost(&graphs[s], &planned[s], &sequences[s].nodes);
        let times: Vec<f64> = (0..sequences.len()).map(time).collect();
        others.sort_by(|&a, &b| times[a].total_cmp(&times[b]).then(a.cmp(&b)));
        let mut taken = false;
        for s in others {
            let mut tasks = allocated.tasks[s].clone();
            tasks.push(t);
            let seq = sequence::sequence(
                cell,
                &cell.robots[s],
                &graphs[s],
                &tasks,
                settings,
                deadline,
                f64::INFINITY,
                None,
                &mut planned[s],
            )?;
            if seq.beaten {
                return Err(PlanError::TimeLimit);
            }
            counts[s].0 += seq.legs_planned;
            counts[s].1 += seq.legs_sampled;
            counts[s].2 += seq.legs_failed;
            if seq.dropped.is_empty() {
                sequences[s] = seq;
                allocated.tasks[s] = tasks;
                taken = true;
                break;
            }
        }
        if !taken {
            unreached.push((t, why));
        }
    }
    unreached.sort_by_key(|u| u.0);
    Ok(unreached)
}

/// The time `cell`'s process spends at `task` (s).
pub fn dwell(cell: &Cell, task: TaskId) -> f64 {
    cell.process.work(&cell.tasks[task.0]).duration()
}

/// Sequence every robot's tasks (in parallel), reusing and extending each robot's planned legs;
/// `counts` accumulates (planned, sampled, failed) legs per robot. `None` when some robot's
/// time cannot get below `bar` (see [`sequence::sequence`]): every robot first finds its best
/// order on the current costs, and only when all of them are below the bar are legs planned.
#[allow(clippy::too_many_arguments)]
fn sequence_all(
    cell: &Cell,
    graphs: &[RobotGraph],
    tasks: &[Vec<TaskId>],
    settings: &PlanSettings,
    deadline: Instant,
    bar: f64,
    planned: &mut [sequence::Planned],
    counts: &mut [(usize, usize, usize)],
) -> Result<Option<Vec<sequence::Sequence>>, PlanError> {
    // Every robot's first order, looked at before any robot plans a leg when there is a bar.
    let firsts: Vec<Option<Vec<usize>>> = if bar.is_finite() {
        let orders: Vec<(Vec<usize>, f64)> = cell
            .robots
            .par_iter()
            .zip(graphs)
            .zip(tasks)
            .zip(planned.par_iter())
            .map(|(((robot, graph), tasks), planned)| {
                let order = sequence::best_order(
                    graph,
                    tasks,
                    planned,
                    sequence::order_seed(settings, robot),
                    &order_rule(cell, settings),
                );
                let time = sequence::order_cost(graph, planned, &order);
                (order, time)
            })
            .collect();
        if orders.iter().any(|(_, time)| *time >= bar) {
            return Ok(None);
        }
        orders.into_iter().map(|(order, _)| Some(order)).collect()
    } else {
        vec![None; graphs.len()]
    };
    let seqs: Vec<sequence::Sequence> = cell
        .robots
        .par_iter()
        .zip(graphs)
        .zip(tasks)
        .zip(firsts)
        .zip(planned.par_iter_mut())
        .map(|((((robot, graph), tasks), first), planned)| {
            sequence::sequence(cell, robot, graph, tasks, settings, deadline, bar, first, planned)
        })
        .collect::<Result<_, _>>()?;
    for (s, c) in seqs.iter().zip(counts.iter_mut()) {
        c.0 += s.legs_planned;
        c.1 += s.legs_sampled;
        c.2 += s.legs_failed;
    }
    Ok((!seqs.iter().any(|s| s.beaten)).then_some(seqs))
}

/// A robot's costs with its planned legs at their real time (failed ones prohibitive).
fn mixed_costs(graph: &RobotGraph, planned: &sequence::Planned) -> CostMatrix {
    let n = graph.len();
    let mut data = graph.costs.data().to_vec();
    for (&(a, b), leg) in planned {
        let c = match leg {
            Ok(l) => l.duration,
            Err(_) => sequence::NO_PATH,
        };
        data[a * n + b] = c;
        data[b * n + a] = c;
    }
    CostMatrix::new(n, data).expect("same size as the graph")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For every stage: the serde name and `Display` agree, and name a key of `compute_s`.
    #[test]
    fn stage_names_are_the_compute_keys() {
        let all = [Stage::Costs, Stage::Allocation, Stage::Sequencing, Stage::Timing];
        // A new stage must be added to `all` (and to `compute_s`).
        for s in all {
            match s {
                Stage::Costs | Stage::Allocation | Stage::Sequencing | Stage::Timing => {}
            }
        }
        let compute = serde_json::to_value(crate::document::ComputeTimes::default()).unwrap();
        for s in all {
            let name = s.to_string();
            assert_eq!(serde_json::to_value(s).unwrap().as_str(), Some(name.as_str()));
            assert!(compute.get(&name).is_some(), "`{name}` is not a key of compute_s");
        }
        assert_eq!(
            all.map(|s| s.to_string()),
            ["costs", "allocation", "sequencing_motion", "timing"]
        );
    }
}

//! Allocation strategies: which robot measures which MP (paper 000 §3.2).
//!
//! - [`Allocation::Proximity`]: the paper's benchmark — every MP goes to the nearest robot
//!   (base to MP) that can measure it and has room under its cap φ.
//! - [`Allocation::LocalRobust`]: the paper's method — MPs only one robot can measure go to it
//!   (δ_i); the shared ones, per group of robots able to measure them (Q_il), are grouped into
//!   local robust MP sets (eq. 4: closer than ε, admissible probe-orientation cones that
//!   overlap), a set cover picks the sets (eq. 5, solved by the penalty/auxiliary-function
//!   method of eq. 6–7 or exactly), and Algorithm 1 gives each set to the robot whose tour
//!   (eq. 8–9: Euclidean, from its base through its MPs) is shortest, within φ.
//! - [`Allocation::Balanced`]: ours — allocation, order and candidate chosen together as a
//!   min-max multi-robot routing with alternatives over the candidates' lower-bound move times
//!   and the measuring time, within φ and γ.
//! - [`Allocation::Zones`]: ours, for robots that share space — each robot keeps a compact
//!   zone of its own (as Åblad et al. separate the robots' workspaces): the nearest-robot
//!   allocation, then, while the busiest robot can give a task away and finish sooner, the
//!   task at the edge of its zone nearest to a neighbour that can do it moves there.
use super::graph::RobotGraph;
use super::{PlanError, PlanSettings};
use crate::candidates::CandidateTable;
use cellplan_model::Cell;
use cellplan_model::names::serde_name;
use cellplan_model::tasks::TaskId;
use cellplan_solve::minmax::{self, MinMaxMethod, MinMaxParams, MinMaxProblem, Vehicle};
use cellplan_solve::setcover::{self, ExactLimits, PenaltyParams};
use cellplan_solve::{CostMatrix, Gtsp, GtspParams, SetCover};
use glam::DVec3;
use std::collections::BTreeMap;
use std::sync::OnceLock;
use std::time::Duration;

mod strips;

/// Allocation strategy.
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum Allocation {
    /// Nearest robot (paper 000's benchmark).
    Proximity,
    /// Local robust MP sets, set cover, Algorithm 1 (paper 000's method).
    LocalRobust,
    /// Min-max routing with alternatives (ours).
    Balanced,
    /// Nearest robot, then balanced by moving edge tasks to neighbours (ours).
    Zones,
}

/// Name as on the command line and in the plan document (the serde name).
impl std::fmt::Display for Allocation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(serde_name(self))
    }
}

/// How the local-robust strategy solves its set cover.
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum CoverMethod {
    /// Paper 000's penalty and auxiliary function (eq. 6–7).
    Penalty,
    /// Branch and bound with Lagrangian bounds.
    Exact,
}

/// The allocation, and for `balanced` the routes it found.
#[derive(Clone, Debug, Default)]
pub struct Allocated {
    /// Tasks per robot.
    pub tasks: Vec<Vec<TaskId>>,
    /// Local robust sets built and chosen by the set cover (local-robust only).
    pub local_sets: (usize, usize),
    /// Lower bound of the min-max problem on the lower-bound costs (valid for any allocation).
    pub lower_bound: f64,
}

/// Allocate the measurable tasks of `cell` to its robots. `costs`, when given, replaces each
/// robot's lower-bound matrix in the balanced strategy's routing (the lower bound reported
/// stays the one of the lower-bound costs).
pub fn allocate(
    cell: &Cell,
    table: &CandidateTable,
    graphs: &[RobotGraph],
    settings: &PlanSettings,
    costs: Option<&[CostMatrix]>,
) -> Result<Allocated, PlanError> {
    allocate_bounded(cell, table, graphs, settings, costs, &OnceLock::new())
}

/// [`allocate`], with the lower bound of `graphs` taken from `bound` where an earlier call
/// with the same graphs (of the same cell and candidate table) has set it, and set there
/// otherwise: it does not depend on the allocation, and costs a search of its own.
pub fn allocate_bounded(
    cell: &Cell,
    table: &CandidateTable,
    graphs: &[RobotGraph],
    settings: &PlanSettings,
    costs: Option<&[CostMatrix]>,
    bound: &OnceLock<f64>,
) -> Result<Allocated, PlanError> {
    let m = cell.robots.len();
    let capable: Vec<Vec<usize>> = (0..cell.tasks.len())
        .map(|t| table.robots_for(TaskId(t)).into_iter().map(|r| r.0).collect())
        .collect();
    let problem = min_max_problem(cell, graphs, &capable)?;
    let lower_bound = *bound.get_or_init(|| minmax::lower_bound(&problem.0));
    if let Some(fixed) = &settings.tasks {
        return Ok(Allocated {
            tasks: fixed.clone(),
            local_sets: (0, 0),
            lower_bound,
        });
    }
    let cap = cell.planning.task_cap;
    let mut tasks: Vec<Vec<TaskId>> = vec![Vec::new(); m];
    let mut local_sets = (0, 0);
    match settings.allocation {
        Allocation::Zones if settings.sweep.is_some() => {
            strips::strips(cell, graphs, &capable, settings, &mut tasks)?;
        }
        Allocation::Proximity | Allocation::Zones => {
            // Exclusive tasks first (they have no choice), then the shared ones.
            let mut order: Vec<usize> = (0..cell.tasks.len())
                .filter(|&t| !capable[t].is_empty())
                .collect();
            order.sort_by_key(|&t| (capable[t].len() > 1, t));
            for t in order {
                let p = cell.tasks[t].position;
                let mut who = capable[t].clone();
                who.sort_by(|&a, &b| {
                    let da = (cell.robots[a].base.translation - p).length();
                    let db = (cell.robots[b].base.translation - p).length();
                    da.total_cmp(&db).then(a.cmp(&b))
                });
                let r = who
                    .into_iter()
                    .find(|&r| tasks[r].len() < cap)
                    .ok_or_else(|| cap_error(cell, t, cap))?;
                tasks[r].push(TaskId(t));
            }
            if settings.allocation == Allocation::Zones {
                zones(cell, graphs, &capable, settings, &mut tasks);
            }
        }
        Allocation::LocalRobust => {
            local_sets = local_robust(cell, &capable, settings, &mut tasks)?;
        }
        Allocation::Balanced => {
            let problem = match costs {
                Some(c) => {
                    let mut p = problem.0.clone();
                    for (v, m) in p.vehicles.iter_mut().zip(c) {
                        v.costs = std::sync::Arc::new(m.clone());
                    }
                    (p, problem.1)
                }
                None => problem,
            };
            let sol = minmax::solve(
                &problem.0,
                &MinMaxParams {
                    time_limit: settings.time_limit,
                    seed: settings.seed,
                    max_iterations: Some(settings.balanced_iterations),
                    method: MinMaxMethod::Ils,
                },
            );
            for (r, tour) in sol.routes.tours.iter().enumerate() {
                tasks[r] = tour.iter().map(|&(t, _)| TaskId(problem.1[t])).collect();
            }
        }
    }
    for list in &mut tasks {
        list.sort();
    }
    Ok(Allocated {
        tasks,
        local_sets,
        lower_bound,
    })
}

/// Kicks of the GTSP heuristic for a robot's tour while zones are drawn (the sequencer
/// optimises the final tours again).
const ZONE_TOUR_ITERATIONS: usize = 400;
/// Kicks × tasks of one zones tour re-optimisation, at most (fewer kicks for long tours).
const ZONE_TOUR_WORK: usize = 20_000;
/// Insertion and removal evaluations (node visits) the zones search may spend: the bound
/// that keeps large cells fast; it stops there, deterministically.
const ZONE_SEARCH_WORK: usize = 300_000_000;

/// A robot's tour under the lower-bound costs: nodes from home back home, and its time.
struct Tour {
    nodes: Vec<usize>,
    time: f64,
}

impl Tour {
    fn new(graph: &RobotGraph, tasks: &[TaskId], seed: u64) -> Tour {
        // Long tours get fewer kicks: the work per kick grows with the tour.
        let kicks = (ZONE_TOUR_WORK / (tasks.len() + 1)).clamp(20, ZONE_TOUR_ITERATIONS);
        let nodes = super::sequence::best_order_with(
            graph,
            tasks,
            &Default::default(),
            seed,
            kicks,
            &Default::default(),
        );
        let time = super::sequence::order_cost(graph, &Default::default(), &nodes);
        Tour { nodes, time }
    }

    /// The tour's time without task `t`'s node (bypassed), and where it was.
    fn without_at(&self, graph: &RobotGraph, t: TaskId) -> (f64, Option<usize>) {
        let Some(i) = self
            .nodes
            .iter()
            .position(|&n| graph.node_task[n].is_some_and(|(x, _)| x == t))
        else {
            return (self.time, None);
        };
        let prev = if i == 0 { 0 } else { self.nodes[i - 1] };
        let next = self.nodes.get(i + 1).copied().unwrap_or(0);
        let n = self.nodes[i];
        let c = |a: usize, b: usize| graph.costs.get(a, b);
        (
            self.time - c(prev, n) - c(n, next) + c(prev, next) - graph.dwell[n],
            Some(i),
        )
    }

    /// The tour's time without task `t`'s node (bypassed).
    fn without(&self, graph: &RobotGraph, t: TaskId) -> f64 {
        self.without_at(graph, t).0
    }

    /// The tour's time with task `t` inserted at its cheapest place and candidate, and that
    /// place (index in `nodes`) and node.
    fn with_at(&self, graph: &RobotGraph, t: TaskId) -> (f64, usize, usize) {
        let c = |a: usize, b: usize| graph.costs.get(a, b);
        let mut best = (f64::INFINITY, 0, 0);
        for &n in &graph.alternatives[t.0] {
            for i in 0..=self.nodes.len() {
                let a = if i == 0 { 0 } else { self.nodes[i - 1] };
                let b = self.nodes.get(i).copied().unwrap_or(0);
                let d = c(a, n) + c(n, b) - c(a, b) + graph.dwell[n];
                if d < best.0 {
                    best = (d, i, n);
                }
            }
        }
        (self.time + best.0, best.1, best.2)
    }

    /// The tour's time with task `t` inserted at its cheapest place and candidate.
    fn with(&self, graph: &RobotGraph, t: TaskId) -> f64 {
        self.with_at(graph, t).0
    }

    /// Takes task `t` out (bypassed).
    fn remove(&mut self, graph: &RobotGraph, t: TaskId) {
        if let (time, Some(i)) = self.without_at(graph, t) {
            self.nodes.remove(i);
            self.time = time;
        }
    }

    /// Puts task `t` in at its cheapest place and candidate.
    fn insert(&mut self, graph: &RobotGraph, t: TaskId) {
        let (time, i, n) = self.with_at(graph, t);
        self.nodes.insert(i, n);
        self.time = time;
    }
}

/// Moves between re-optimisations of every zones tour (a move edits the two tours it
/// touches by cheapest removal and insertion).
const ZONE_REOPTIMISE_EVERY: usize = 8;

/// [`Allocation::Zones`]: from the nearest-robot allocation in `tasks`, tasks move one at a
/// time from a robot to another that can do them and has room, as long as that lowers the
/// robots' lower-bound times sorted from the longest (leximax: the busiest robot first, then
/// the next — so a robot may pass work on to make room for a busier neighbour's). Robots are
/// looked at busiest first; of the moves that help, the task nearest to the receiving
/// robot's own tasks (its base when it has none) moves — the edge of a zone, so zones stay
/// compact. The two tours a move touches are edited (cheapest removal and insertion) and
/// re-optimised every few moves, and all of them when no move helps. A robot's time counts
/// [`PlanSettings::task_penalty`] for each of its tasks.
fn zones(
    cell: &Cell,
    graphs: &[RobotGraph],
    capable: &[Vec<usize>],
    settings: &PlanSettings,
    tasks: &mut [Vec<TaskId>],
) {
    let m = graphs.len();
    let cap = cell.planning.task_cap;
    let seed = settings.seed;
    let pen = |t: TaskId, r: usize| penalty(settings, t, r);
    let load = |r: usize, tasks: &[TaskId]| load(settings, r, tasks);
    let mut tours: Vec<Tour> = (0..m).map(|r| Tour::new(&graphs[r], &tasks[r], seed)).collect();
    let sorted = |times: &[f64]| {
        let mut v = times.to_vec();
        v.sort_by(|a, b| b.total_cmp(a));
        v
    };
    // Strictly below, by more than rounding, in the first place that differs.
    let lower = |a: &[f64], b: &[f64]| {
        for (x, y) in a.iter().zip(b) {
            if *x < *y - 1e-6 {
                return true;
            }
            if *x > *y + 1e-6 {
                return false;
            }
        }
        false
    };
    // Moves since the last re-optimisation of a tour; whether any tour is edited since all
    // were re-optimised.
    let (mut since, mut edited) = (0, false);
    let mut work = 0usize;
    for _ in 0..4 * cell.tasks.len() {
        if work > ZONE_SEARCH_WORK {
            break;
        }
        let times: Vec<f64> = (0..m).map(|r| tours[r].time + load(r, &tasks[r])).collect();
        let now = sorted(&times);
        let mut order: Vec<usize> = (0..m).collect();
        order.sort_by(|&a, &b| times[b].total_cmp(&times[a]).then(a.cmp(&b)));
        let mut pick: Option<(f64, usize, usize, usize)> = None;
        for &from in &order {
            for &t in &tasks[from] {
                work += tours[from].nodes.len();
                let gone = tours[from].without(&graphs[from], t) + load(from, &tasks[from]) - pen(t, from);
                for &to in &capable[t.0] {
                    if to == from || tasks[to].len() >= cap {
                        continue;
                    }
                    work += (tours[to].nodes.len() + 1) * graphs[to].alternatives[t.0].len();
                    let mut next = times.clone();
                    next[from] = gone;
                    next[to] = tours[to].with(&graphs[to], t) + load(to, &tasks[to]) + pen(t, to);
                    if !lower(&sorted(&next), &now) {
                        continue;
                    }
                    let p = cell.tasks[t.0].position;
                    let near = tasks[to]
                        .iter()
                        .map(|x| (cell.tasks[x.0].position - p).length())
                        .fold((cell.robots[to].base.translation - p).length(), f64::min);
                    if pick.is_none_or(|(d, ..)| near < d) {
                        pick = Some((near, from, t.0, to));
                    }
                }
            }
            if pick.is_some() {
                break;
            }
        }
        let Some((_, from, t, to)) = pick else {
            // No move helps on the edited tours: re-optimised ones may still offer one.
            if !edited {
                break;
            }
            (since, edited) = (0, false);
            for r in 0..m {
                tours[r] = Tour::new(&graphs[r], &tasks[r], seed);
            }
            continue;
        };
        hand_over(graphs, tasks, &mut tours, (from, to, TaskId(t)), &mut since, seed);
        edited = true;
    }
}

/// Moves task `t` from robot `from` to robot `to`: the two tours edited (cheapest removal and
/// insertion), and both re-optimised every [`ZONE_REOPTIMISE_EVERY`] moves (`since` counts
/// them).
fn hand_over(
    graphs: &[RobotGraph],
    tasks: &mut [Vec<TaskId>],
    tours: &mut [Tour],
    (from, to, t): (usize, usize, TaskId),
    since: &mut usize,
    seed: u64,
) {
    tasks[from].retain(|&x| x != t);
    tasks[to].push(t);
    tasks[to].sort();
    tours[from].remove(&graphs[from], t);
    tours[to].insert(&graphs[to], t);
    *since += 1;
    if *since >= ZONE_REOPTIMISE_EVERY {
        *since = 0;
        tours[from] = Tour::new(&graphs[from], &tasks[from], seed);
        tours[to] = Tour::new(&graphs[to], &tasks[to], seed);
    }
}

/// [`PlanSettings::task_penalty`] of robot `r` doing task `t` (0 when not given).
fn penalty(settings: &PlanSettings, t: TaskId, r: usize) -> f64 {
    settings
        .task_penalty
        .get(t.0)
        .and_then(|p| p.get(r))
        .copied()
        .unwrap_or(0.0)
}

/// The task penalties of robot `r` doing `tasks`.
fn load(settings: &PlanSettings, r: usize, tasks: &[TaskId]) -> f64 {
    tasks.iter().map(|&t| penalty(settings, t, r)).sum()
}

fn cap_error(cell: &Cell, t: usize, cap: usize) -> PlanError {
    PlanError::TaskCap {
        task: cell.tasks[t].name.clone(),
        cap,
    }
}

/// The lower bound of the min-max problem on the graphs' lower-bound costs over the measurable
/// tasks except `left_out` (the tasks a plan gives up: a bound of a plan holds for the tasks it
/// does): [`Allocated::lower_bound`] when nothing is left out. The plan document states it
/// for the tasks the plan measures, and the verifier recomputes it so.
pub fn lower_bound(
    cell: &Cell,
    table: &CandidateTable,
    graphs: &[RobotGraph],
    left_out: &[TaskId],
) -> Result<f64, PlanError> {
    let capable = capable_except(cell, table, left_out);
    Ok(minmax::lower_bound(&min_max_problem(cell, graphs, &capable)?.0))
}

/// The route bound ([`minmax::route_bound`]) of the problem [`lower_bound`] bounds: column
/// generation over whole routes, started from the routes of Algorithm 1 (seed 0, a
/// construction) and stopped once its pricings have looked at `max_work` arcs, or once
/// `deadline` has passed, where given. Every round's value is a proof, so a cut run still
/// bounds every plan that measures these tasks; it is never below the leg bound, and the duals
/// of the round that set it prove it again ([`route_bound_at`]). Returns it with the cell task
/// of each of its problem's tasks, in the order of its duals.
pub fn route_bound(
    cell: &Cell,
    table: &CandidateTable,
    graphs: &[RobotGraph],
    left_out: &[TaskId],
    (max_work, deadline): (u64, Option<std::time::Instant>),
) -> Result<(minmax::RouteBound, Vec<TaskId>), PlanError> {
    let capable = capable_except(cell, table, left_out);
    let (p, tasks) = min_max_problem(cell, graphs, &capable)?;
    let params = MinMaxParams {
        method: MinMaxMethod::Algorithm1,
        seed: 0,
        max_iterations: Some(0),
        time_limit: Duration::from_secs(3600),
    };
    let start = minmax::solve(&p, &params).routes;
    let defaults = minmax::RouteBoundSettings::default();
    let settings = minmax::RouteBoundSettings {
        max_work,
        deadline,
        ..defaults
    };
    let rb = minmax::route_bound(&p, &start, &settings);
    Ok((rb, tasks.into_iter().map(TaskId).collect()))
}

/// The route bound's problem (the one [`route_bound`] solves) bounded from duals: `pi` per
/// cell task, `mu` per robot, checked with one exact pricing per robot
/// ([`minmax::lagrangian_bound`]). `Ok(None)` when the duals prove nothing: negative or not
/// finite, `Σμ` above one, a task the problem leaves out given a `π`, or the problem past the
/// pricing's size limits.
pub fn route_bound_at(
    cell: &Cell,
    table: &CandidateTable,
    graphs: &[RobotGraph],
    left_out: &[TaskId],
    pi: &[f64],
    mu: &[f64],
) -> Result<Option<f64>, PlanError> {
    let capable = capable_except(cell, table, left_out);
    if pi.len() != cell.tasks.len()
        || pi
            .iter()
            .zip(&capable)
            .any(|(&v, who)| who.is_empty() && v != 0.0)
    {
        return Ok(None);
    }
    let (p, tasks) = min_max_problem(cell, graphs, &capable)?;
    let pi: Vec<f64> = tasks.iter().map(|&t| pi[t]).collect();
    Ok(minmax::lagrangian_bound(
        &p,
        &pi,
        mu,
        &minmax::RouteBoundSettings::default(),
    ))
}

/// Per task the robots able to do it, none for the tasks `left_out`.
fn capable_except(cell: &Cell, table: &CandidateTable, left_out: &[TaskId]) -> Vec<Vec<usize>> {
    (0..cell.tasks.len())
        .map(|t| {
            if left_out.contains(&TaskId(t)) {
                Vec::new()
            } else {
                table.robots_for(TaskId(t)).into_iter().map(|r| r.0).collect()
            }
        })
        .collect()
}

/// The min-max problem over the measurable tasks, and the cell task of each of its tasks.
pub(crate) fn min_max_problem(
    cell: &Cell,
    graphs: &[RobotGraph],
    capable: &[Vec<usize>],
) -> Result<(MinMaxProblem, Vec<usize>), PlanError> {
    let measurable: Vec<usize> = (0..cell.tasks.len())
        .filter(|&t| !capable[t].is_empty())
        .collect();
    let vehicles = graphs
        .iter()
        .map(|g| Vehicle {
            costs: g.costs.clone(),
            depot: 0,
            cap: cell.planning.task_cap,
            alternatives: measurable.iter().map(|&t| g.alternatives[t].clone()).collect(),
        })
        .collect();
    let p = MinMaxProblem::new(
        vehicles,
        measurable.len(),
        measurable
            .iter()
            .map(|&t| super::dwell(cell, TaskId(t)))
            .collect(),
        cell.planning.balance_limit,
    )
    .map_err(|reason| PlanError::CapsTooSmall { reason })?;
    Ok((p, measurable))
}

/// Paper 000 §3.2 steps 1–6 and Algorithm 1, generalised from pairs to any group of robots
/// sharing MPs. Returns (local sets built, sets chosen).
fn local_robust(
    cell: &Cell,
    capable: &[Vec<usize>],
    settings: &PlanSettings,
    tasks: &mut [Vec<TaskId>],
) -> Result<(usize, usize), PlanError> {
    let cap = cell.planning.task_cap;
    // U_i ← δ_i.
    let mut groups: BTreeMap<Vec<usize>, Vec<usize>> = BTreeMap::new();
    for (t, who) in capable.iter().enumerate() {
        match who.len() {
            0 => {}
            1 => {
                if tasks[who[0]].len() >= cap {
                    return Err(cap_error(cell, t, cap));
                }
                tasks[who[0]].push(TaskId(t));
            }
            _ => groups.entry(who.clone()).or_default().push(t),
        }
    }
    let eps = settings.local_set_radius;
    let (mut built, mut chosen_total) = (0, 0);
    for (who, members) in groups {
        // Step 2: the local robust set of every MP of the group (eq. 4), as the process
        // defines it.
        let ids: Vec<TaskId> = members.iter().map(|&t| TaskId(t)).collect();
        let sets: Vec<Vec<usize>> = cell
            .process
            .local_sets(&cell.tasks, &ids, eps)
            .ok_or(PlanError::Unsupported {
                what: "the local-robust allocation",
                process: cell.process.kind(),
            })?
            .into_iter()
            .map(|set| set.into_iter().map(|t| t.0).collect())
            .collect();
        built += sets.len();
        // Step 3: the cover model (eq. 5). The paper asks for the fewest sets and weighs a set
        // by its running time once sorted (its measuring time and shortest open path at the
        // nominal TCP speed); c_j = 1 + time_j / (1 + Σ time) keeps the count first and the
        // time as the tie-break (with c_j = time alone, singletons would always win).
        let row_of: BTreeMap<usize, usize> = members.iter().enumerate().map(|(r, &t)| (t, r)).collect();
        let mut covers = vec![Vec::new(); members.len()];
        for (c, set) in sets.iter().enumerate() {
            for t in set {
                covers[row_of[t]].push(c);
            }
        }
        for row in &mut covers {
            row.sort_unstable();
        }
        let times: Vec<f64> = sets
            .iter()
            .map(|s| {
                let pts: Vec<DVec3> = s.iter().map(|&t| cell.tasks[t].position).collect();
                s.iter().map(|&t| super::dwell(cell, TaskId(t))).sum::<f64>()
                    + open_path(&pts, settings.seed) / NOMINAL_TCP_SPEED
            })
            .collect();
        let sum: f64 = times.iter().sum();
        let costs: Vec<f64> = times.iter().map(|t| 1.0 + t / (1.0 + sum)).collect();
        let sc = SetCover {
            rows: members.len(),
            columns: sets.len(),
            costs,
            covers,
        };
        // Step 4.
        let cover = match settings.cover {
            CoverMethod::Penalty => setcover::penalty_method(
                &sc,
                &PenaltyParams {
                    seed: settings.seed,
                    ..PenaltyParams::default()
                },
            ),
            CoverMethod::Exact => setcover::exact(
                &sc,
                &ExactLimits {
                    time_limit: None,
                    max_nodes: Some(200_000),
                },
            ),
        };
        chosen_total += cover.columns.len();
        // Each MP belongs to the first chosen set holding it (a_uk = 0 for the others).
        let mut taken = vec![false; members.len()];
        let mut parts: Vec<Vec<usize>> = Vec::new();
        for &c in &cover.columns {
            let part: Vec<usize> = sets[c]
                .iter()
                .copied()
                .filter(|t| !std::mem::replace(&mut taken[row_of[t]], true))
                .collect();
            if !part.is_empty() {
                parts.push(part);
            }
        }
        // Steps 5–6, Algorithm 1: each set to the robot with the cheaper tour (eq. 8–9).
        for part in parts {
            let mut best: Option<(f64, usize)> = None;
            for &r in &who {
                if tasks[r].len() + part.len() > cap {
                    continue;
                }
                let mut pts: Vec<DVec3> = tasks[r].iter().map(|t| cell.tasks[t.0].position).collect();
                pts.extend(part.iter().map(|&t| cell.tasks[t].position));
                let cost = closed_tour(cell.robots[r].base.translation, &pts, settings.seed);
                if best.is_none_or(|(c, _)| cost < c) {
                    best = Some((cost, r));
                }
            }
            match best {
                Some((_, r)) => tasks[r].extend(part.iter().map(|&t| TaskId(t))),
                // No robot has room for the whole set: place its MPs one by one.
                None => {
                    for &t in &part {
                        let r = who
                            .iter()
                            .copied()
                            .filter(|&r| tasks[r].len() < cap)
                            .min_by(|&a, &b| {
                                let p = cell.tasks[t].position;
                                let da = (cell.robots[a].base.translation - p).length();
                                let db = (cell.robots[b].base.translation - p).length();
                                da.total_cmp(&db)
                            })
                            .ok_or_else(|| cap_error(cell, t, cap))?;
                        tasks[r].push(TaskId(t));
                    }
                }
            }
        }
    }
    Ok((built, chosen_total))
}

/// TCP speed (m/s) that turns path lengths into the running time of a set cover column.
const NOMINAL_TCP_SPEED: f64 = 1.0;
/// Kicks of the tour heuristic inside the allocation (deterministic).
const TOUR_ITERATIONS: usize = 200;

fn euclid(points: &[DVec3]) -> CostMatrix {
    CostMatrix::from_fn(points.len(), |i, j| (points[i] - points[j]).length())
}

/// Eq. 8: the shortest closed tour from `base` through `points` (Euclidean).
fn closed_tour(base: DVec3, points: &[DVec3], seed: u64) -> f64 {
    if points.is_empty() {
        return 0.0;
    }
    let mut all = vec![base];
    all.extend_from_slice(points);
    let n = all.len();
    let g = Gtsp::new(euclid(&all), (1..n).map(|i| vec![i]).collect())
        .and_then(|g| g.with_depots(Some(0), None))
        .expect("a Euclidean tour instance is valid");
    tour_cost(&g, seed)
}

/// The shortest open path through `points` (any end points).
fn open_path(points: &[DVec3], seed: u64) -> f64 {
    if points.len() < 2 {
        return 0.0;
    }
    // A dummy node at zero distance from every point turns the path into a tour.
    let n = points.len();
    let costs = CostMatrix::from_fn(n + 1, |i, j| {
        if i == n || j == n {
            0.0
        } else {
            (points[i] - points[j]).length()
        }
    });
    let g = Gtsp::new(costs, (0..n).map(|i| vec![i]).collect())
        .and_then(|g| g.with_depots(Some(n), None))
        .expect("a Euclidean path instance is valid");
    tour_cost(&g, seed)
}

fn tour_cost(g: &Gtsp, seed: u64) -> f64 {
    cellplan_solve::solve_gtsp(
        g,
        &GtspParams {
            time_limit: Duration::from_secs(60),
            seed,
            max_iterations: Some(TOUR_ITERATIONS),
            ..GtspParams::default()
        },
    )
    .cost
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For every allocation strategy: the serde name, `Display` and (with feature `clap`) the
    /// command-line value agree.
    #[test]
    fn allocation_names_agree() {
        let all = [
            Allocation::Proximity,
            Allocation::LocalRobust,
            Allocation::Balanced,
            Allocation::Zones,
        ];
        // A new strategy must be added to `all`.
        for a in all {
            match a {
                Allocation::Proximity
                | Allocation::LocalRobust
                | Allocation::Balanced
                | Allocation::Zones => {}
            }
        }
        for a in all {
            let name = a.to_string();
            let json = serde_json::to_value(a).unwrap();
            assert_eq!(json.as_str(), Some(name.as_str()));
            assert_eq!(serde_json::from_value::<Allocation>(json).unwrap(), a);
            #[cfg(feature = "clap")]
            assert_eq!(clap::ValueEnum::to_possible_value(&a).unwrap().get_name(), name);
        }
        #[cfg(feature = "clap")]
        assert_eq!(<Allocation as clap::ValueEnum>::value_variants(), all);
        assert_eq!(
            all.map(|a| a.to_string()),
            ["proximity", "local-robust", "balanced", "zones"]
        );
    }
}

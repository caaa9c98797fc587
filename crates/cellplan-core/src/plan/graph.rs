//! Per-robot graphs: the robot's home and every candidate of every task it can do, with the
//! lower-bound move times between them (paper 000 eq. 3 with the move model of the settings).
use crate::candidates::CandidateTable;
use cellplan_model::Cell;
use cellplan_model::robot::Robot;
use cellplan_model::tasks::TaskId;
use cellplan_motion::plan::SharedRoadmap;
use cellplan_motion::timing::{Limits, move_time, move_time_instant};
use cellplan_solve::CostMatrix;
use std::sync::{Arc, OnceLock};

/// How the time of a move between two configurations is estimated before it is planned.
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "kebab-case")]
pub enum MoveModel {
    /// Synchronised trapezoidal/triangular profiles under the velocity and acceleration
    /// limits: a lower bound of any real move.
    Trapezoid,
    /// Paper 000's assumption 2: maximum velocity reached at once (max_j |Δq_j| / v_j).
    Instant,
}

/// One robot's nodes: node 0 is home, the others are candidates.
#[derive(Clone, Debug)]
pub struct RobotGraph {
    /// Configurations, node 0 the home.
    pub q: Vec<Vec<f64>>,
    /// For nodes ≥ 1: the task and the index of the candidate in the table.
    pub node_task: Vec<Option<(TaskId, usize)>>,
    /// For every task of the cell, this robot's nodes for it (empty when it cannot do it).
    pub alternatives: Vec<Vec<usize>>,
    /// Time spent at each node's task (s; 0 at home).
    pub dwell: Vec<f64>,
    /// Lower-bound move times between nodes (s).
    pub costs: Arc<CostMatrix>,
    /// The joint limits used for timing.
    pub limits: Limits,
    /// The robot's roadmap in the cell (see [`RobotGraph::roadmap`]), built on first need and
    /// shared by the legs planned on any thread.
    pub roadmap: Arc<OnceLock<SharedRoadmap>>,
    /// Every leg the motion planner was asked for between two of its nodes (see
    /// [`super::sequence::LegMemo`]), shared by every plan that shares the graph.
    pub legs: Arc<super::sequence::LegMemo>,
}

/// At most this many of a graph's configurations become roadmap nodes (evenly spread over the
/// graph's nodes, home first).
const MAX_ROADMAP_SEEDS: usize = 1500;

/// The joint limits of a robot.
pub fn limits_of(robot: &Robot) -> Limits {
    Limits::new(robot.max_velocity.clone(), robot.max_acceleration.clone())
        .expect("the loader checks velocity and acceleration limits")
}

/// At most `k` of the configurations `qs` (their indices, ascending): the half nearest to
/// `home` in move time (the natural arm postures, which short tours use), then the rest by
/// farthest-point sampling in move time (different postures, for detours and for
/// coordination). A task × robot pair has hundreds of candidates (poses × IK branches × ±2π
/// turns), far more than sequencing needs; the kept ones span them.
///
/// `roomy(i)` says whether configuration `i` keeps a comfortable distance from the scene; it
/// is asked only of configurations about to be chosen, and one that is not roomy is passed
/// over while roomy ones remain (then the others fill up to `k`). A pose with a millimetre to
/// spare is valid, but every leg out of it starts in a crevice — slow to plan, and fragile
/// against the cell's real tolerances.
pub fn select(
    qs: &[&[f64]],
    home: &[f64],
    k: usize,
    limits: &Limits,
    roomy: &dyn Fn(usize) -> bool,
) -> Vec<usize> {
    if qs.len() <= k {
        return (0..qs.len()).collect();
    }
    let mut order: Vec<(f64, usize)> = qs
        .iter()
        .enumerate()
        .map(|(i, q)| (move_time(home, q, limits), i))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    // Roominess, asked lazily.
    let mut known: Vec<Option<bool>> = vec![None; qs.len()];
    let ask = |known: &mut Vec<Option<bool>>, i: usize| *known[i].get_or_insert_with(|| roomy(i));
    let near = k.div_ceil(2);
    let mut chosen: Vec<usize> = Vec::with_capacity(k);
    for &(_, i) in &order {
        if chosen.len() == near {
            break;
        }
        if ask(&mut known, i) {
            chosen.push(i);
        }
    }
    // Farthest-point sampling over the roomy ones; then, if short, over the rest.
    let mut dist: Vec<f64> = qs
        .iter()
        .map(|q| {
            chosen
                .iter()
                .map(|&c| move_time(qs[c], q, limits))
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    // Chosen, or passed over in this round.
    let mut passed = vec![false; qs.len()];
    for strict in [true, false] {
        passed.fill(false);
        for &c in &chosen {
            passed[c] = true;
        }
        while chosen.len() < k {
            let (far, d) = dist.iter().enumerate().filter(|&(i, _)| !passed[i]).fold(
                (usize::MAX, f64::NEG_INFINITY),
                |best, (i, &d)| {
                    if d > best.1 { (i, d) } else { best }
                },
            );
            if far == usize::MAX || d <= 0.0 {
                break;
            }
            passed[far] = true;
            if strict && !ask(&mut known, far) {
                continue;
            }
            chosen.push(far);
            for (i, q) in qs.iter().enumerate() {
                dist[i] = dist[i].min(move_time(qs[far], q, limits));
            }
        }
    }
    chosen.sort_unstable();
    chosen
}

/// Most nodes of one robot's graph: its move-time matrix is dense (nodes² times, 128 MiB at
/// this size), so a robot that can do many tasks keeps fewer candidates per task (at least
/// one), and a robot that can do more tasks than this is refused before planning (see
/// [`crate::check::graph_size_error`]).
pub const MAX_GRAPH_NODES: usize = 4096;

/// Candidates kept per task for a robot that can do `doable` tasks, asked for `per_task`:
/// as many as fit in [`MAX_GRAPH_NODES`] (at least one).
pub fn per_task_within(per_task: usize, doable: usize) -> usize {
    per_task.min((MAX_GRAPH_NODES.saturating_sub(1) / doable.max(1)).max(1))
}

impl RobotGraph {
    /// The robot's shared roadmap ([`crate::motion::robot_roadmap`]): the graph's
    /// configurations (home and the candidates kept, at most `MAX_ROADMAP_SEEDS` of them)
    /// and samples seeded by `seed` (half uniform, half near those configurations). Built the first time it is asked for; the same
    /// for every caller.
    pub fn roadmap(&self, cell: &Cell, robot: &Robot, seed: u64) -> &SharedRoadmap {
        self.roadmap.get_or_init(|| {
            let stride = self.q.len().div_ceil(MAX_ROADMAP_SEEDS).max(1);
            let seeds: Vec<Vec<f64>> = self.q.iter().step_by(stride).cloned().collect();
            crate::motion::robot_roadmap(cell, robot, &seeds, seed)
        })
    }

    /// The graph of `robot` over the candidates of `table`, at most `per_task` per task (see
    /// [`select`]; fewer when the robot can do so many tasks that they would not fit in
    /// [`MAX_GRAPH_NODES`], see [`per_task_within`]), preferring candidates at least `roomy` (m) farther from the static scene
    /// than the process clearance asks, whose self pairs are that far apart too (or as far
    /// as at home, if less).
    pub fn new(
        cell: &Cell,
        robot: &Robot,
        table: &CandidateTable,
        model: MoveModel,
        per_task: usize,
        roomy: f64,
    ) -> Self {
        let validity = crate::motion::robot_validity(cell, robot, cell.planning.clearance);
        // Some self pairs are close by construction (a tool beside its wrist): what is roomy
        // for them is what they have at home, if less.
        let self_roomy = roomy.min(validity.scene_and_self_clearance(&robot.home).1);
        let limits = limits_of(robot);
        let time = match model {
            MoveModel::Trapezoid => move_time,
            MoveModel::Instant => move_time_instant,
        };
        let doable = table
            .table
            .iter()
            .filter(|row| !row[robot.id.0].candidates.is_empty())
            .count();
        let per_task = per_task_within(per_task, doable);
        let mut q = vec![robot.home.clone()];
        let mut node_task = vec![None];
        let mut alternatives = vec![Vec::new(); table.table.len()];
        for (t, row) in table.table.iter().enumerate() {
            let cands = &row[robot.id.0].candidates;
            let all: Vec<&[f64]> = cands.iter().map(|c| c.q.as_slice()).collect();
            let roomy = |i: usize| roomy <= 0.0 || validity.clear_by(all[i], roomy, self_roomy);
            for c in select(&all, &robot.home, per_task, &limits, &roomy) {
                alternatives[t].push(q.len());
                q.push(cands[c].q.clone());
                node_task.push(Some((TaskId(t), c)));
            }
        }
        let costs = CostMatrix::from_fn(
            q.len(),
            |i, j| if i == j { 0.0 } else { time(&q[i], &q[j], &limits) },
        );
        let dwell = node_task
            .iter()
            .map(|n| n.map_or(0.0, |(t, _)| super::dwell(cell, t)))
            .collect();
        RobotGraph {
            q,
            dwell,
            node_task,
            alternatives,
            costs: Arc::new(costs),
            limits,
            roadmap: Arc::default(),
            legs: Arc::default(),
        }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// Whether there is only the home.
    pub fn is_empty(&self) -> bool {
        self.q.len() <= 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The kept candidates per task shrink so that a robot's graph stays within its node
    /// budget, never below one; small cells keep what they ask for.
    #[test]
    fn graphs_keep_within_their_node_budget() {
        assert_eq!(per_task_within(24, 45), 24);
        assert_eq!(per_task_within(24, 0), 24);
        for doable in [100, 500, 700, 2000, MAX_GRAPH_NODES - 1] {
            let k = per_task_within(24, doable);
            assert!(k >= 1 && k * doable < MAX_GRAPH_NODES, "{doable}: {k}");
            // One more per task would not fit (or the ask is met).
            assert!(k == 24 || 1 + (k + 1) * doable > MAX_GRAPH_NODES, "{doable}: {k}");
        }
        assert_eq!(per_task_within(24, 10 * MAX_GRAPH_NODES), 1);
    }
}

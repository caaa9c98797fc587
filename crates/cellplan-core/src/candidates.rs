//! Candidates: for every task and robot, the feasible ways to do the task — a joint
//! configuration, the tool pose and its quality — and, where there are none, why.
use cellplan_geom::{GroupId, Pose};
use cellplan_model::robot::{Robot, RobotId, Scratch};
use cellplan_model::tasks::{Task, TaskId};
use cellplan_model::{Cell, Process, Rejection};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;

/// One feasible way for a robot to do a task.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// Joint configuration (within limits, collision-free, accepted by the process).
    pub q: Vec<f64>,
    /// TCP pose in the world.
    pub tcp: Pose,
}

/// The candidates of one robot for one task, and the fate of the poses that did not make it.
#[derive(Clone, Debug, Default)]
pub struct Reach {
    /// Feasible configurations.
    pub candidates: Vec<Candidate>,
    /// Sampled poses that yielded no candidate, by the furthest stage they reached.
    pub rejected: BTreeMap<Rejection, usize>,
}

impl Reach {
    /// Why this robot cannot do the task: the furthest stage any pose reached (`None` when it
    /// can).
    pub fn reason(&self) -> Option<Rejection> {
        if self.candidates.is_empty() {
            self.rejected.keys().next_back().copied()
        } else {
            None
        }
    }
}

/// Candidates for every task × robot: `table[task][robot]`.
#[derive(Clone, Debug)]
pub struct CandidateTable {
    /// Indexed by task then robot.
    pub table: Vec<Vec<Reach>>,
}

impl CandidateTable {
    /// The entry of one task and robot.
    pub fn get(&self, task: TaskId, robot: RobotId) -> &Reach {
        &self.table[task.0][robot.0]
    }

    /// Robots with at least one candidate for `task`.
    pub fn robots_for(&self, task: TaskId) -> Vec<RobotId> {
        self.table[task.0]
            .iter()
            .enumerate()
            .filter(|(_, r)| !r.candidates.is_empty())
            .map(|(i, _)| RobotId(i))
            .collect()
    }

    /// Total number of candidates.
    pub fn total(&self) -> usize {
        self.table.iter().flatten().map(|r| r.candidates.len()).sum()
    }
}

/// Generates the candidates of every task for every robot. Parallel over tasks and robots;
/// the result does not depend on the thread count.
pub fn generate(cell: &Cell) -> CandidateTable {
    let process = cell.process.as_ref();
    let validity: Vec<_> = cell
        .robots
        .iter()
        .map(|r| crate::motion::robot_validity(cell, r, cell.planning.clearance))
        .collect();
    let table = cell
        .tasks
        .par_iter()
        .map(|task| {
            let poses = process.tool_poses(task);
            cell.robots
                .par_iter()
                .zip(&validity)
                .map(|(robot, validity)| reach(cell, process, robot, task, &poses, validity))
                .collect()
        })
        .collect();
    CandidateTable { table }
}

/// Wraps a joint value into (-π, π] so configurations differing by full turns compare equal
/// (same geometry).
pub fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let w = a.rem_euclid(t);
    if w > std::f64::consts::PI { w - t } else { w }
}

fn same_geometry(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).all(|(x, y)| (wrap(x - y)).abs() < 1e-9)
}

/// The other robots of the cell parked at home: (their body group, their body poses). A
/// measuring pose that comes within the clearance of a parked robot is no candidate: every
/// robot parks at home before and after its program, and a pose it cannot take while a
/// neighbour is parked could only be timed around that neighbour's whole program.
pub fn parked_others(cell: &cellplan_model::Cell, robot: &Robot) -> Vec<(GroupId, Vec<Pose>)> {
    let mut scratch = Scratch::default();
    cell.robots
        .iter()
        .filter(|r| r.id != robot.id)
        .map(|r| {
            r.body_poses(&r.home, &mut scratch);
            (r.group, scratch.bodies.clone())
        })
        .collect()
}

/// The candidates of one robot for one task among the tool `poses`: the process's pose
/// check, IK within the joint limits, the process's checks of the reached pose and of each
/// configuration, then collision — decided by `validity`, the robot's checker as the leg
/// planner uses it ([`crate::motion::robot_validity`] at the cell's clearance, with the other
/// robots parked at home, see [`parked_others`]): a configuration the planner would refuse to
/// leave or reach is no candidate.
pub fn reach(
    cell: &Cell,
    process: &dyn Process,
    robot: &Robot,
    task: &Task,
    poses: &[Pose],
    validity: &crate::motion::RobotValidity,
) -> Reach {
    let world = &cell.world;
    let mut reach = Reach::default();
    let mut scratch = Scratch::default();
    let mut solutions = Vec::new();
    // Verdicts of configurations already checked at this pose: (q, feasible or why not).
    let mut verdicts: Vec<(Vec<f64>, Result<(), Rejection>)> = Vec::new();
    // Quick reach test: beyond the reach bound plus the tool's own reach, no pose can work.
    let distance = (task.position - robot.base.translation).length();
    if distance > robot.reach + process.tool_reach() + 0.05 {
        reach.rejected.insert(Rejection::NoIk, poses.len());
        return reach;
    }
    for tcp in poses {
        if let Err(r) = process.pose_check(task, tcp) {
            *reach.rejected.entry(Rejection::Pose(r)).or_default() += 1;
            continue;
        }
        solutions.clear();
        let raw = robot.ik(tcp, &mut solutions);
        if solutions.is_empty() {
            let r = if raw == 0 {
                Rejection::NoIk
            } else {
                Rejection::JointLimits
            };
            *reach.rejected.entry(r).or_default() += 1;
            continue;
        }
        // The process's checks against the scene depend on the pose only: once, after reach
        // is known.
        if let Err(r) = process.reached_check(world, task, tcp) {
            *reach.rejected.entry(Rejection::Reached(r)).or_default() += 1;
            continue;
        }
        verdicts.clear();
        let mut furthest: Option<Rejection> = None;
        let mut any = false;
        for q in &solutions {
            // The pose the joints reach, which the verifier checks: a numeric IK solution
            // misses the asked pose by its tolerance, and a pose on the edge of what the
            // process accepts may fall outside. (The links posed here serve the
            // configuration's checks below too.)
            robot.link_poses(q, &mut scratch);
            let reached = robot.tcp_from_links(&scratch);
            let verdict = match verdicts.iter().find(|(p, _)| same_geometry(p, q)) {
                Some((_, v)) => *v,
                None => {
                    let v = check_reached(cell, process, task, tcp, &reached).and_then(|()| {
                        check_configuration(cell, process, robot, task, &reached, q, validity, &mut scratch)
                    });
                    verdicts.push((q.clone(), v));
                    v
                }
            };
            match verdict {
                Ok(()) => {
                    any = true;
                    reach.candidates.push(Candidate {
                        q: q.clone(),
                        tcp: reached,
                    });
                }
                Err(r) => furthest = furthest.max(Some(r)),
            }
        }
        if !any && let Some(r) = furthest {
            *reach.rejected.entry(r).or_default() += 1;
        }
    }
    reach
}

/// The process's checks of the pose the joints reach, when it is not the pose asked for (the
/// asked pose passed them already).
fn check_reached(
    cell: &Cell,
    process: &dyn Process,
    task: &Task,
    asked: &Pose,
    reached: &Pose,
) -> Result<(), Rejection> {
    let same = (reached.translation - asked.translation).length() <= 1e-12
        && reached.rotation.dot(asked.rotation).abs() >= 1.0 - 1e-15;
    if same {
        return Ok(());
    }
    process.pose_check(task, reached).map_err(Rejection::Pose)?;
    process
        .reached_check(&cell.world, task, reached)
        .map_err(Rejection::Reached)
}

/// The process's checks of one configuration (the cheap ones first), then collision with the
/// scene, the robot itself and the parked robots, by the planner's own test. `scratch.links`
/// holds the links posed at `q` ([`Robot::link_poses`]).
#[allow(clippy::too_many_arguments)]
fn check_configuration(
    cell: &Cell,
    process: &dyn Process,
    robot: &Robot,
    task: &Task,
    tcp: &Pose,
    q: &[f64],
    validity: &crate::motion::RobotValidity,
    scratch: &mut Scratch,
) -> Result<(), Rejection> {
    robot.bodies_from_links(scratch);
    process
        .arm_check(&cell.world, robot, &scratch.bodies, task, tcp)
        .map_err(Rejection::Reached)?;
    // The bodies were posed at `q` just above, as the checker poses them.
    if !validity.is_valid_posed(q, &scratch.bodies) {
        return Err(Rejection::Collision);
    }
    Ok(())
}

/// Reachability classes of paper 000 §3.2.
#[derive(Clone, Debug, Serialize)]
pub struct Classes {
    /// δ_i: tasks only robot i can do, per robot.
    pub exclusive: Vec<Vec<TaskId>>,
    /// Q_il: tasks both robots i and l can do (others may too), for each pair i < l that
    /// shares any.
    pub shared_pairs: Vec<((RobotId, RobotId), Vec<TaskId>)>,
    /// Tasks no robot can do.
    pub unmeasurable: Vec<TaskId>,
}

/// Splits the tasks into the δ and Q classes.
pub fn classes(table: &CandidateTable, robots: usize) -> Classes {
    let mut exclusive = vec![Vec::new(); robots];
    let mut pairs: BTreeMap<(usize, usize), Vec<TaskId>> = BTreeMap::new();
    let mut unmeasurable = Vec::new();
    for t in 0..table.table.len() {
        let who = table.robots_for(TaskId(t));
        match who.len() {
            0 => unmeasurable.push(TaskId(t)),
            1 => exclusive[who[0].0].push(TaskId(t)),
            _ => {
                for (a, i) in who.iter().enumerate() {
                    for l in &who[a + 1..] {
                        pairs.entry((i.0, l.0)).or_default().push(TaskId(t));
                    }
                }
            }
        }
    }
    Classes {
        exclusive,
        shared_pairs: pairs
            .into_iter()
            .map(|((i, l), t)| ((RobotId(i), RobotId(l)), t))
            .collect(),
        unmeasurable,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellplan_model::ProcessReason;

    #[test]
    fn classes_split_by_who_can() {
        let reach = |n: usize| Reach {
            candidates: vec![
                Candidate {
                    q: vec![0.0],
                    tcp: Pose::IDENTITY,
                };
                n
            ],
            rejected: BTreeMap::new(),
        };
        let table = CandidateTable {
            table: vec![
                vec![reach(2), reach(0), reach(0)],
                vec![reach(1), reach(3), reach(0)],
                vec![reach(0), reach(0), reach(0)],
                vec![reach(1), reach(1), reach(1)],
            ],
        };
        let c = classes(&table, 3);
        assert_eq!(c.exclusive, vec![vec![TaskId(0)], vec![], vec![]]);
        assert_eq!(c.unmeasurable, vec![TaskId(2)]);
        let pair = |a, b| {
            c.shared_pairs
                .iter()
                .find(|((x, y), _)| *x == RobotId(a) && *y == RobotId(b))
                .map(|p| p.1.clone())
        };
        assert_eq!(pair(0, 1), Some(vec![TaskId(1), TaskId(3)]));
        assert_eq!(pair(1, 2), Some(vec![TaskId(3)]));
        let mut reasons = Reach::default();
        let early = ProcessReason {
            rank: 9,
            code: "early",
            text: "refused before IK",
        };
        reasons.rejected.insert(Rejection::Pose(early), 7);
        reasons.rejected.insert(Rejection::NoIk, 5);
        assert_eq!(reasons.reason(), Some(Rejection::NoIk));
        reasons.rejected.insert(Rejection::Collision, 2);
        assert_eq!(reasons.reason(), Some(Rejection::Collision));
    }
}

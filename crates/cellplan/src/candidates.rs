//! Candidates: for every task and robot, the feasible ways to do the task — a joint
//! configuration, the tool pose and its quality — and, where there are none, why.
use crate::model::robot::{BodyFrame, Robot, RobotId, Scratch};
use crate::model::tasks::{Task, TaskId};
use crate::process::optical::{OpticalProcess, ProbePose, Rejection};
use crate::{Cell, Process};
use cellplan_geom::{CollisionWorld, GroupId, Pose};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;

/// One feasible way for a robot to do a task.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// Joint configuration (within limits, collision-free, beams clear).
    pub q: Vec<f64>,
    /// TCP pose in the world.
    pub tcp: Pose,
    /// Angle between beam and MP normal (rad).
    pub view_angle: f64,
    /// Rotation of the probe about its beam (rad), as sampled.
    pub spin: f64,
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
    let Process::Optical(process) = &cell.process;
    let parked: Vec<_> = cell.robots.iter().map(|r| parked_others(cell, r)).collect();
    let table = cell
        .tasks
        .par_iter()
        .map(|task| {
            let poses = process.sample_poses(task);
            cell.robots
                .par_iter()
                .zip(&parked)
                .map(|(robot, parked)| optical_reach(process, &cell.world, robot, task, &poses, parked))
                .collect()
        })
        .collect();
    CandidateTable { table }
}

/// Wraps a joint value into (-π, π] so configurations differing by full turns compare equal
/// (same geometry).
pub(crate) fn wrap(a: f64) -> f64 {
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
pub fn parked_others(cell: &crate::Cell, robot: &Robot) -> Vec<(GroupId, Vec<Pose>)> {
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

/// The candidates of one robot for one MP under the optical process, clear of the `parked`
/// robots (see [`parked_others`]).
pub fn optical_reach(
    process: &OpticalProcess,
    world: &CollisionWorld,
    robot: &Robot,
    task: &Task,
    poses: &[ProbePose],
    parked: &[(GroupId, Vec<Pose>)],
) -> Reach {
    let mut reach = Reach::default();
    let mut scratch = Scratch::default();
    let mut solutions = Vec::new();
    // Verdicts of configurations already checked at this pose: (q, feasible or why not).
    let mut verdicts: Vec<(Vec<f64>, Result<(), Rejection>)> = Vec::new();
    // Quick reach test: beyond the reach bound plus the standoff, no pose can work.
    let distance = (task.position - robot.base.translation).length();
    if distance > robot.reach + process.standoff + 0.05 {
        reach.rejected.insert(Rejection::NoIk, poses.len());
        return reach;
    }
    for pose in poses {
        let view_angle = match process.measurement(task, &pose.tcp) {
            Ok(a) => a,
            Err(r) => {
                *reach.rejected.entry(r).or_default() += 1;
                continue;
            }
        };
        solutions.clear();
        let raw = robot.ik(&pose.tcp, &mut solutions);
        if solutions.is_empty() {
            let r = if raw == 0 {
                Rejection::NoIk
            } else {
                Rejection::JointLimits
            };
            *reach.rejected.entry(r).or_default() += 1;
            continue;
        }
        // The static beams depend on the pose only: check once, after reach is known.
        if !process.beams_clear_of_statics(world, task, &pose.tcp) {
            *reach.rejected.entry(Rejection::BeamOccluded).or_default() += 1;
            continue;
        }
        verdicts.clear();
        let mut furthest: Option<Rejection> = None;
        let mut any = false;
        for q in &solutions {
            let verdict = match verdicts.iter().find(|(p, _)| same_geometry(p, q)) {
                Some((_, v)) => *v,
                None => {
                    let v =
                        check_configuration(process, world, robot, task, &pose.tcp, q, parked, &mut scratch);
                    verdicts.push((q.clone(), v));
                    v
                }
            };
            match verdict {
                Ok(()) => {
                    any = true;
                    reach.candidates.push(Candidate {
                        q: q.clone(),
                        tcp: pose.tcp,
                        view_angle,
                        spin: pose.spin,
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

/// Own-arm beam and collision checks of one configuration (the cheap rays first), then the
/// parked robots.
#[allow(clippy::too_many_arguments)]
fn check_configuration(
    process: &OpticalProcess,
    world: &CollisionWorld,
    robot: &Robot,
    task: &Task,
    tcp: &Pose,
    q: &[f64],
    parked: &[(GroupId, Vec<Pose>)],
    scratch: &mut Scratch,
) -> Result<(), Rejection> {
    robot.body_poses(q, scratch);
    // The beams start on the probe, so the probe itself is left out: only the arm can block them.
    let tool = robot.bodies.iter().position(|b| *b == BodyFrame::Tool);
    for (from, dir, len) in process.beams(task, tcp) {
        if world
            .cast_ray_group_except(robot.group, &scratch.bodies, from, dir, len, tool)
            .is_some()
        {
            return Err(Rejection::BeamOccluded);
        }
    }
    if robot.contact_at(world, scratch, process.clearance).is_some() {
        return Err(Rejection::Collision);
    }
    for (group, poses) in parked {
        if world
            .group_vs_group(robot.group, &scratch.bodies, *group, poses, process.clearance)
            .is_some()
        {
            return Err(Rejection::Collision);
        }
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
    use crate::model::load::{LoadOptions, load};
    use std::path::Path;

    #[test]
    fn every_candidate_rechecks_clean() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/autobody-2r/cell.toml");
        let cell = load(&path, &LoadOptions::default()).unwrap();
        let table = generate(&cell);
        let process = cell.optical();
        let mut scratch = Scratch::default();
        let mut checked = 0;
        for task in &cell.tasks {
            for robot in &cell.robots {
                // Every 7th candidate: enough to catch frame mistakes, cheap in a debug build.
                for c in table.get(task.id, robot.id).candidates.iter().step_by(7) {
                    assert!(robot.within_limits(&c.q));
                    let tcp = robot.tcp_pose(&c.q);
                    assert!(
                        (tcp.translation - c.tcp.translation).length() < 1e-6,
                        "FK disagrees with the pose"
                    );
                    assert!(tcp.rotation.dot(c.tcp.rotation).abs() > 1.0 - 1e-9);
                    let angle = process
                        .measurement(task, &tcp)
                        .expect("candidate measures its MP");
                    assert!((angle - c.view_angle).abs() < 1e-6);
                    assert!(process.beams_clear_of_statics(&cell.world, task, &tcp));
                    robot.body_poses(&c.q, &mut scratch);
                    assert!(
                        robot
                            .contact_at(&cell.world, &scratch, process.clearance)
                            .is_none()
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 1000, "only {checked} candidates checked");
        assert!(classes(&table, cell.robots.len()).unmeasurable.is_empty());
    }

    #[test]
    fn classes_split_by_who_can() {
        let reach = |n: usize| Reach {
            candidates: vec![
                Candidate {
                    q: vec![0.0],
                    tcp: Pose::IDENTITY,
                    view_angle: 0.0,
                    spin: 0.0
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
        reasons.rejected.insert(Rejection::NoIk, 5);
        reasons.rejected.insert(Rejection::Collision, 2);
        assert_eq!(reasons.reason(), Some(Rejection::Collision));
    }
}

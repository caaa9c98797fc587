//! A robot's program — its legs (collision-free joint polylines), its measurements and its
//! waits — and the program timed on the cell's common clock.
//!
//! Every leg is timed segment by segment, each segment a synchronised trapezoid from rest to
//! rest (as [`time_path_exact`] does for a whole polyline: it stops at every waypoint), so a
//! wait at any waypoint changes nothing but the clock: the robot is at rest there anyway.
//! After coordination a leg without a wait on the way may be *blended* ([`LegBlend`], made
//! by `coord::blend`): timed through its corners without stopping, each corner cut by a
//! parabolic blend whose curve was checked against the scene; a wait put on the way of such
//! a leg takes the blend away (the robot must stop there).
use crate::candidates::{Candidate, CandidateTable};
use crate::plan::graph::RobotGraph;
use crate::plan::sequence::Sequence;
use crate::plan::{PlanError, Stop};
use cellplan_geom::Pose;
use cellplan_model::Cell;
use cellplan_model::robot::Robot;
use cellplan_model::tasks::TaskId;
use cellplan_motion::timing::{Limits, Trajectory, time_path_exact};

/// One measurement of a program.
#[derive(Clone, Debug, PartialEq)]
pub struct VisitPose {
    /// The MP.
    pub task: TaskId,
    /// The table candidate this pose is (or was perturbed from).
    pub candidate: usize,
    /// Joint configuration.
    pub q: Vec<f64>,
    /// Tool (TCP) pose in the world.
    pub tcp: Pose,
    /// Time spent at the task (s): the process's work.
    pub dwell: f64,
    /// The (Δw, Δp, Δr) increments (rad) of paper 000 §4.2 when the orientation was perturbed.
    pub perturbation: Option<[f64; 3]>,
}

impl VisitPose {
    /// Candidate `index` of the table, as it is, with the task's `dwell`.
    pub fn from_candidate(task: TaskId, index: usize, c: &Candidate, dwell: f64) -> Self {
        VisitPose {
            task,
            candidate: index,
            q: c.q.clone(),
            tcp: c.tcp,
            dwell,
            perturbation: None,
        }
    }
}

/// One leg: a collision-free joint polyline.
#[derive(Clone, Debug, PartialEq)]
pub struct ProgramLeg {
    /// From the previous stop to the next, inclusive.
    pub waypoints: Vec<Vec<f64>>,
    /// Whether it is the direct segment.
    pub straight: bool,
    /// Duration of each segment (rest to rest).
    pub segments: Vec<f64>,
    /// The leg timed through its corners without stopping, when it is (see [`LegBlend`]);
    /// `None`: rest to rest at every waypoint, as `segments` say.
    pub blend: Option<LegBlend>,
}

/// A leg crossed without stopping at some of its corners: at corner `w` (an interior waypoint
/// of the leg) with radius `r` the joints leave the incoming segment at distance `r`
/// (Euclidean, joint space) before the corner and join the outgoing one `r` after it, along
/// the quadratic Bézier curve with control points `p_w − r·u_in`, `p_w`, `p_w + r·u_out` — the
/// curve a constant joint acceleration draws (see
/// [`cellplan_motion::timing::time_path_blended`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LegBlend {
    /// The leg's motion, from rest at its first waypoint to rest at its last.
    pub trajectory: Trajectory,
    /// `(waypoint, radius)` of each corner crossed without stopping, in order.
    pub corners: Vec<(usize, f64)>,
    /// Time from the leg's start at which the trajectory passes each waypoint (at a blended
    /// corner: the middle of its blend).
    pub waypoint_times: Vec<f64>,
}

impl ProgramLeg {
    /// A leg from its waypoints, each segment timed under `limits`.
    pub fn new(waypoints: Vec<Vec<f64>>, straight: bool, limits: &Limits) -> Result<Self, PlanError> {
        let segments = waypoints
            .windows(2)
            .map(|w| segment_trajectory(&w[0], &w[1], limits).map(|t| t.duration()))
            .collect::<Result<_, _>>()?;
        Ok(ProgramLeg {
            waypoints,
            straight,
            segments,
            blend: None,
        })
    }

    /// Moving time (s).
    pub fn duration(&self) -> f64 {
        match &self.blend {
            Some(b) => b.trajectory.duration(),
            None => self.segments.iter().sum(),
        }
    }
}

/// Why a robot waits.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    PartialOrd,
    Ord,
    serde::Serialize,
    serde::Deserialize,
    schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum WaitReason {
    /// Delayed start (delay-startup).
    Startup,
    /// Gives way to a robot of higher priority.
    GiveWay,
    /// No perturbed pose cleared the conflict (pose-perturbation's fallback).
    Fallback,
}

impl std::fmt::Display for WaitReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(cellplan_model::names::serde_name(self))
    }
}

/// A stop: the robot stands at `legs[leg].waypoints[waypoint]` for `duration` before going on.
#[derive(Clone, Debug, PartialEq)]
pub struct Wait {
    /// The leg.
    pub leg: usize,
    /// The waypoint of the leg (0: its start, after the previous measurement or at home).
    pub waypoint: usize,
    /// Seconds.
    pub duration: f64,
    /// Why.
    pub reason: WaitReason,
    /// The robot it waits for, if any.
    pub for_robot: Option<usize>,
}

/// A robot's program: home → visits → home.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// Index of the robot in the cell.
    pub robot: usize,
    /// Home configuration.
    pub home: Vec<f64>,
    /// `visits.len() + 1` legs.
    pub legs: Vec<ProgramLeg>,
    /// The measurements in order.
    pub visits: Vec<VisitPose>,
    /// Stops, at most one per waypoint, sorted by (leg, waypoint).
    pub waits: Vec<Wait>,
}

/// What a robot does during a span of its timeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Activity {
    /// Moving along segment `segment` of leg `leg`.
    Move {
        /// Leg.
        leg: usize,
        /// Segment of the leg.
        segment: usize,
    },
    /// Measuring visit `visit`.
    Measure {
        /// Index into the visits.
        visit: usize,
    },
    /// Standing at a waypoint.
    Wait {
        /// Leg.
        leg: usize,
        /// Waypoint.
        waypoint: usize,
    },
}

impl Activity {
    /// Whether the robot stands still.
    pub fn holds(self) -> bool {
        !matches!(self, Activity::Move { .. })
    }
}

/// A span of a robot's timeline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    /// Start (s).
    pub start: f64,
    /// End (s).
    pub end: f64,
    /// What.
    pub what: Activity,
}

/// A program on the clock.
#[derive(Clone, Debug)]
pub struct Timed {
    /// Home to home, waits and measurements included; afterwards the robot stands at home.
    pub trajectory: Trajectory,
    /// The spans, in order, covering `[0, trajectory.duration()]`.
    pub spans: Vec<Span>,
    /// (arrive, depart) per visit.
    pub visits: Vec<(f64, f64)>,
    /// Start (s) of each wait, in the order of [`Program::waits`].
    pub wait_starts: Vec<f64>,
    /// Arrival time (s) at each waypoint of each leg (before any wait there).
    pub arrivals: Vec<Vec<f64>>,
    /// Whether the robot can do none of the cell's tasks ([`crate::check::idle_robots`]; set
    /// by the coordination's context): its end is left out of Δt ([`super::cycle_and_delta`]).
    pub idle: bool,
}

impl Timed {
    /// End of the program (s).
    pub fn end(&self) -> f64 {
        self.trajectory.duration()
    }

    /// Index of the span at `t` (the last one for `t` past the end).
    pub fn span_at(&self, t: f64) -> usize {
        let i = self.spans.partition_point(|s| s.end <= t);
        i.min(self.spans.len() - 1)
    }

    /// Until when the robot is certain to stand still from `t` on (`t` itself when moving;
    /// infinity after its end: it stays home).
    pub fn hold_until(&self, t: f64) -> f64 {
        if t >= self.end() {
            return f64::INFINITY;
        }
        let mut i = self.span_at(t);
        if !self.spans[i].what.holds() {
            return t;
        }
        // Consecutive holds (a wait then a measurement) add up.
        while i + 1 < self.spans.len() && self.spans[i + 1].what.holds() {
            i += 1;
        }
        if i + 1 == self.spans.len() {
            f64::INFINITY
        } else {
            self.spans[i].end
        }
    }
}

/// One straight segment timed from rest to rest.
pub fn segment_trajectory(a: &[f64], b: &[f64], limits: &Limits) -> Result<Trajectory, PlanError> {
    time_path_exact(&[a.to_vec(), b.to_vec()], limits)
        .map(|t| t.trajectory)
        .map_err(PlanError::Timing)
}

impl Program {
    /// The same program without its waits.
    pub fn without_waits(&self) -> Program {
        Program {
            waits: Vec::new(),
            ..self.clone()
        }
    }

    /// A robot's program from its final sequence, without waits: the sequence's candidates
    /// as visits, every leg timed segment by segment.
    pub fn from_sequence(
        cell: &Cell,
        table: &CandidateTable,
        robot: &Robot,
        graph: &RobotGraph,
        seq: &Sequence,
    ) -> Result<Program, PlanError> {
        let visits = seq
            .nodes
            .iter()
            .map(|&node| {
                let (t, c) = graph.node_task[node].expect("visited nodes are candidates");
                VisitPose::from_candidate(
                    t,
                    c,
                    &table.get(t, robot.id).candidates[c],
                    crate::plan::dwell(cell, t),
                )
            })
            .collect();
        let legs = seq
            .legs
            .iter()
            .map(|l| ProgramLeg::new(l.waypoints.clone(), l.straight, &graph.limits))
            .collect::<Result<_, _>>()?;
        Ok(Program {
            robot: robot.id.0,
            home: robot.home.clone(),
            legs,
            visits,
            waits: Vec::new(),
        })
    }

    /// Stop `k` of the program: 0 and `visits.len() + 1` are home, else the task of visit
    /// `k − 1` (leg `k` runs from stop `k` to stop `k + 1`).
    pub fn stop(&self, cell: &Cell, k: usize) -> Stop {
        if k == 0 || k > self.visits.len() {
            Stop::Home
        } else {
            Stop::Task(cell.tasks[self.visits[k - 1].task.0].name.clone())
        }
    }

    /// Adds a stop where the program (timed as `timed`, without waits) is at time `at`, if it
    /// is moving along a segment there: the segment is split at that configuration — the same
    /// joint path, one more rest — and its leg timed again under `limits`. Returns whether a
    /// stop was added. Waits keep their places only before it (they are cleared by callers
    /// that add stops: the program is scheduled again).
    pub fn stop_at(&mut self, timed: &Timed, at: f64, limits: &Limits) -> Result<bool, PlanError> {
        let span = &timed.spans[timed.span_at(at)];
        let Activity::Move { leg, segment } = span.what else {
            return Ok(false);
        };
        if at <= span.start || at >= span.end {
            return Ok(false);
        }
        let q = timed.trajectory.position(at);
        let mut waypoints = self.legs[leg].waypoints.clone();
        waypoints.insert(segment + 1, q);
        self.legs[leg] = ProgramLeg::new(waypoints, false, limits)?;
        Ok(true)
    }

    /// The same tour the other way round: the visits in reverse order, each leg's joint path
    /// reversed, no waits. Every segment is timed from rest to rest, which takes as long
    /// either way, so the program's duration does not change.
    pub fn reversed(&self, limits: &Limits) -> Result<Program, PlanError> {
        let legs = self
            .legs
            .iter()
            .rev()
            .map(|l| {
                let mut w = l.waypoints.clone();
                w.reverse();
                ProgramLeg::new(w, l.straight, limits)
            })
            .collect::<Result<_, _>>()?;
        Ok(Program {
            robot: self.robot,
            home: self.home.clone(),
            legs,
            visits: self.visits.iter().rev().cloned().collect(),
            waits: Vec::new(),
        })
    }

    /// The wait at a waypoint, if any.
    pub fn wait_at(&self, leg: usize, waypoint: usize) -> Option<&Wait> {
        self.waits.iter().find(|w| w.leg == leg && w.waypoint == waypoint)
    }

    /// Sets (replaces) the wait at a waypoint; a duration of 0 removes it. A wait on the way
    /// of a blended leg takes its blend away: the robot stops at every waypoint again.
    pub fn set_wait(&mut self, wait: Wait) {
        if wait.waypoint > 0
            && wait.duration > 0.0
            && let Some(leg) = self.legs.get_mut(wait.leg)
        {
            leg.blend = None;
        }
        self.waits
            .retain(|w| !(w.leg == wait.leg && w.waypoint == wait.waypoint));
        if wait.duration > 0.0 {
            self.waits.push(wait);
            self.waits.sort_by_key(|w| (w.leg, w.waypoint));
        }
    }

    /// Total waiting (s).
    pub fn waiting(&self) -> f64 {
        self.waits.iter().map(|w| w.duration).fold(0.0, |a, b| a + b)
    }

    /// Time at the tasks, doing the work (s).
    pub fn working(&self) -> f64 {
        // `+ 0.0`: an empty sum is −0, which a table prints as "-0.00".
        self.visits.iter().map(|v| v.dwell).sum::<f64>() + 0.0
    }

    /// Moving time (s).
    pub fn motion(&self) -> f64 {
        self.legs.iter().map(ProgramLeg::duration).sum::<f64>() + 0.0
    }

    /// The program's length without building its trajectory (s).
    pub fn duration(&self) -> f64 {
        self.motion() + self.working() + self.waiting()
    }

    /// The program on the clock.
    pub fn timed(&self, limits: &Limits) -> Result<Timed, PlanError> {
        let mut parts: Vec<Trajectory> = Vec::new();
        let mut spans = Vec::new();
        let mut visits = Vec::with_capacity(self.visits.len());
        let mut wait_starts = vec![0.0; self.waits.len()];
        let mut arrivals = Vec::with_capacity(self.legs.len());
        let mut t = 0.0;
        for (k, leg) in self.legs.iter().enumerate() {
            let mut at = Vec::with_capacity(leg.waypoints.len());
            // A blended leg moves on from its first waypoint in one piece: the others are
            // passed, not stood at (`set_wait` takes the blend away from a leg given a wait on
            // the way).
            let mut moving_from = t;
            for w in 0..leg.waypoints.len() {
                if let Some(blend) = &leg.blend
                    && w > 0
                {
                    at.push(moving_from + blend.waypoint_times[w]);
                    continue;
                }
                at.push(t);
                if let Some(i) = self.waits.iter().position(|x| x.leg == k && x.waypoint == w) {
                    let d = self.waits[i].duration;
                    wait_starts[i] = t;
                    parts.push(Trajectory::dwell(&leg.waypoints[w], d));
                    spans.push(Span {
                        start: t,
                        end: t + d,
                        what: Activity::Wait { leg: k, waypoint: w },
                    });
                    t += d;
                }
                if let Some(blend) = &leg.blend {
                    let times = &blend.waypoint_times;
                    for segment in 0..leg.waypoints.len().saturating_sub(1) {
                        spans.push(Span {
                            start: t + times[segment],
                            end: t + times[segment + 1],
                            what: Activity::Move { leg: k, segment },
                        });
                    }
                    parts.push(blend.trajectory.clone());
                    moving_from = t;
                    t += blend.trajectory.duration();
                } else if w + 1 < leg.waypoints.len() {
                    let seg = segment_trajectory(&leg.waypoints[w], &leg.waypoints[w + 1], limits)?;
                    let d = seg.duration();
                    parts.push(seg);
                    spans.push(Span {
                        start: t,
                        end: t + d,
                        what: Activity::Move { leg: k, segment: w },
                    });
                    t += d;
                }
            }
            arrivals.push(at);
            if k < self.visits.len() {
                let dwell = self.visits[k].dwell;
                parts.push(Trajectory::dwell(&self.visits[k].q, dwell));
                spans.push(Span {
                    start: t,
                    end: t + dwell,
                    what: Activity::Measure { visit: k },
                });
                visits.push((t, t + dwell));
                t += dwell;
            }
        }
        if parts.is_empty() {
            parts.push(Trajectory::dwell(&self.home, 0.0));
            spans.push(Span {
                start: 0.0,
                end: 0.0,
                what: Activity::Wait { leg: 0, waypoint: 0 },
            });
        }
        let trajectory = Trajectory::concat(&parts)?;
        Ok(Timed {
            trajectory,
            spans,
            visits,
            wait_starts,
            arrivals,
            idle: false,
        })
    }
}

impl super::Coordinated {
    /// Its waits for [`crate::plan::rebalance`]: per robot pair the seconds in all
    /// ([`super::Coordinated::waits_for`]) and each wait that names the robot it waits for,
    /// with the task the waiting robot is on its way to and where the other robot is (or is
    /// going) when the wait ends.
    pub fn waits(&self) -> crate::plan::rebalance::Waits {
        let task_of = |r: usize, leg: usize| self.programs.get(r)?.visits.get(leg).map(|v| v.task);
        let mut stalls = Vec::new();
        for (r, (p, t)) in self.programs.iter().zip(&self.timed).enumerate() {
            for (wait, &start) in p.waits.iter().zip(&t.wait_starts) {
                let Some(s) = wait.for_robot.filter(|&s| s < self.timed.len()) else {
                    continue;
                };
                let other = &self.timed[s];
                let blocker = match other
                    .spans
                    .get(other.span_at(start + wait.duration))
                    .map(|x| x.what)
                {
                    Some(Activity::Measure { visit }) => task_of(s, visit),
                    Some(Activity::Move { leg, .. } | Activity::Wait { leg, .. }) => task_of(s, leg),
                    None => None,
                };
                stalls.push(crate::plan::rebalance::Stall {
                    robot: r,
                    heading: task_of(r, wait.leg),
                    seconds: wait.duration,
                    for_robot: s,
                    blocker,
                });
            }
        }
        crate::plan::rebalance::Waits {
            totals: self.waits_for(),
            stalls,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_idle_robot_works_and_moves_zero_not_minus_zero() {
        let idle = Program {
            robot: 0,
            home: vec![0.0; 6],
            legs: Vec::new(),
            visits: Vec::new(),
            waits: Vec::new(),
        };
        assert!(idle.working() == 0.0 && idle.working().is_sign_positive());
        assert!(idle.motion() == 0.0 && idle.motion().is_sign_positive());
        assert_eq!(format!("{:.2}", idle.working()), "0.00");
    }

    /// Δt leaves out a robot that can do no task (its `Timed` says so), not one that could
    /// work but has nothing to do.
    #[test]
    fn delta_t_leaves_out_only_robots_that_can_do_no_task() {
        let stand = |seconds: f64, idle: bool| Timed {
            trajectory: Trajectory::dwell(&[0.0], seconds),
            spans: Vec::new(),
            visits: Vec::new(),
            wait_starts: Vec::new(),
            arrivals: Vec::new(),
            idle,
        };
        let mut timed = vec![stand(10.0, false), stand(8.5, false), stand(0.0, true)];
        assert_eq!(super::super::cycle_and_delta(&timed), (10.0, 1.5));
        timed[2].idle = false;
        assert_eq!(super::super::cycle_and_delta(&timed), (10.0, 10.0));
    }
}

//! Robot–robot clearance over the common timeline, proven between the instants measured: each
//! contact reported once per robot pair and time interval.
//!
//! Each pair of robots is walked through time by conservative advancement. At an instant the
//! pair's distance `d` is measured (exact, capped). Between two trajectory samples every joint
//! moves linearly in time, so over `[t, t']` the points of a robot's bodies move at most its
//! *travel* `Σ_j R_j·∫|q̇_j|`, with `R_j` a bound on any body point's distance from joint `j`'s
//! axis ([`cellplan_kin::Chain::joint_radii`], each body's reach taken from its shape as the
//! cell gives it: this module's own bound, not the planner's). The next instant is the latest
//! `t'` at which the two robots' travels since `t` add up to no more than `d − clearance +`
//! [`PROOF_TOLERANCE`]: no pair comes closer than the clearance at an instant measured, nor
//! closer than the clearance less the tolerance between them. Inside a contact the walk steps
//! by the verifier's time step, which sets how finely a contact's interval is reported.
use super::timing::position;
use super::{VerifySettings, Violation, ViolationKind};
use cellplan_core::document::{RobotPlan, Sample};
use cellplan_model::Cell;
use cellplan_model::robot::{Robot, Scratch};
use rayon::prelude::*;

/// How far (m) below the clearance a pair may come between the instants measured (the bound
/// proves every pair at least the clearance less this apart at every time). The planner keeps
/// 3 mm more than the clearance between robots (`cellplan_core::coord::REPLAY_SLACK`), so its
/// plans pass the instants with room; the tolerance keeps the steps from shrinking towards
/// nothing where a plan grazes the clearance.
pub const PROOF_TOLERANCE: f64 = 1e-3;

/// Longest step (s) of the walk: the distance query is capped at what the robots can travel in
/// it, which keeps the query cheap where they are far apart.
const MAX_STEP: f64 = 0.5;

/// Shortest step (s): where a robot's trajectory jumps (two samples at one time, which the
/// timing check reports), no motion bound holds across the jump and the walk moves on by this.
const MIN_STEP: f64 = 1e-7;

/// Instants one pair may be measured at, per step of the verifier's time step over the
/// timeline (and [`MIN_BUDGET`] more): a pair that stays within the tolerance of the clearance
/// while moving would otherwise be walked in ever shorter steps. Past it the rest of the pair's
/// timeline is reported unproven. Plans of the planner take far fewer: on dense-8r-250
/// (8 robots, 79.7 s, 7,972 steps of 10 ms) 186–992 instants per pair.
const BUDGET_PER_STEP: usize = 2;
const MIN_BUDGET: usize = 10_000;

/// The robot–robot check; `times` are the robots' recomputed times. Returns the instants
/// measured, over all pairs.
pub(super) fn check(
    cell: &Cell,
    robots: &[(&Robot, &RobotPlan)],
    times: &[f64],
    settings: &VerifySettings,
    out: &mut Vec<Violation>,
) -> usize {
    if robots.len() < 2 {
        return 0;
    }
    let clearance = cell.planning.clearance;
    let (findings, instants) = contacts(cell, robots, times, settings.time_step);
    for found in findings {
        let ((a, b), s) = (found.pair, found.start);
        let detail = match found.kind {
            Found::Contact { end } => {
                format!(
                    "closer than {:.0} mm from {s:.2} s to {end:.2} s",
                    clearance * 1e3
                )
            }
            Found::Unproven { checks } => format!(
                "clearance of {:.0} mm not proven from {s:.2} s on: the pair stays within {:.1} mm \
                 of it while moving, and the check stopped after {checks} instants",
                clearance * 1e3,
                PROOF_TOLERANCE * 1e3
            ),
        };
        out.push(Violation {
            kind: ViolationKind::RobotRobot,
            robot: Some(robots[a].1.name.clone()),
            other: Some(robots[b].1.name.clone()),
            time_s: Some(s),
            task: None,
            detail,
        });
    }
    instants
}

/// What the walk of one pair found.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Found {
    /// Closer than the clearance at every instant measured from the start to `end`.
    Contact { end: f64 },
    /// The budget ran out at the start, after `checks` instants.
    Unproven { checks: usize },
}

/// One finding of a pair (robot indices, `a < b`).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Finding {
    pair: (usize, usize),
    start: f64,
    kind: Found,
}

/// A robot's travel along its trajectory: at each sample, the bound on how far its bodies'
/// points have moved since the first (see the module documentation).
struct Travel<'a> {
    samples: &'a [Sample],
    /// Cumulative travel (m) at each sample.
    at: Vec<f64>,
}

impl<'a> Travel<'a> {
    fn new(radii: &[f64], samples: &'a [Sample]) -> Travel<'a> {
        let mut at = Vec::with_capacity(samples.len());
        let mut sum = 0.0;
        for (k, s) in samples.iter().enumerate() {
            if k > 0 {
                let prev = &samples[k - 1].q;
                sum +=
                    s.q.iter()
                        .zip(prev)
                        .zip(radii)
                        .map(|((x, y), r)| r * (x - y).abs())
                        .sum::<f64>();
            }
            at.push(sum);
        }
        Travel { samples, at }
    }

    /// The travel at time `t`, interpolated as [`position`] interpolates the joints (so the
    /// travel between two times bounds the motion between the positions there).
    fn at_time(&self, t: f64) -> f64 {
        let tr = self.samples;
        let i = tr.partition_point(|s| s.t <= t);
        if i == 0 {
            return self.at.first().copied().unwrap_or(0.0);
        }
        if i >= tr.len() {
            return self.at.last().copied().unwrap_or(0.0);
        }
        let (a, b) = (&tr[i - 1], &tr[i]);
        let f = if b.t > a.t { (t - a.t) / (b.t - a.t) } else { 0.0 };
        self.at[i - 1] + f * (self.at[i] - self.at[i - 1])
    }
}

/// The contacts and unproven stretches of every pair, by start time (then pair), and the
/// instants measured.
fn contacts(
    cell: &Cell,
    robots: &[(&Robot, &RobotPlan)],
    times: &[f64],
    time_step: f64,
) -> (Vec<Finding>, usize) {
    let horizon = times.iter().copied().fold(0.0, f64::max);
    let travels: Vec<Travel> = robots
        .iter()
        .map(|(robot, rp)| Travel::new(&super::body_radii(robot), &rp.trajectory))
        .collect();
    let pairs: Vec<(usize, usize)> = (0..robots.len())
        .flat_map(|a| (a + 1..robots.len()).map(move |b| (a, b)))
        .collect();
    let budget = ((horizon / time_step).ceil() as usize)
        .saturating_mul(BUDGET_PER_STEP)
        .saturating_add(MIN_BUDGET);
    let walk = Walk {
        cell,
        robots,
        travels: &travels,
        horizon,
        time_step,
        budget,
    };
    let walked: Vec<(Vec<Finding>, usize)> = pairs.par_iter().map(|&pair| walk.pair(pair)).collect();
    let instants = walked.iter().map(|w| w.1).sum();
    let mut found: Vec<Finding> = walked.into_iter().flat_map(|w| w.0).collect();
    found.sort_by(|x, y| x.start.total_cmp(&y.start).then(x.pair.cmp(&y.pair)));
    (found, instants)
}

/// What every pair's walk shares.
struct Walk<'a> {
    cell: &'a Cell,
    robots: &'a [(&'a Robot, &'a RobotPlan)],
    travels: &'a [Travel<'a>],
    horizon: f64,
    time_step: f64,
    /// Most instants measured per pair.
    budget: usize,
}

impl Walk<'_> {
    /// The configuration of robot `r` at `t`.
    fn q(&self, r: usize, t: f64) -> Vec<f64> {
        let rp = self.robots[r].1;
        if rp.trajectory.is_empty() {
            rp.home.clone()
        } else {
            position(&rp.trajectory, t)
        }
    }

    /// The two robots' travel added up, at `t`.
    fn travel(&self, (a, b): (usize, usize), t: f64) -> f64 {
        self.travels[a].at_time(t) + self.travels[b].at_time(t)
    }

    /// The latest time in `[t, until]` at which the pair has travelled at most `room` since
    /// `t` (the travel only grows with time: bisection).
    fn reach(&self, pair: (usize, usize), t: f64, until: f64, room: f64) -> f64 {
        let limit = self.travel(pair, t) + room;
        super::farthest(t, until, |x| self.travel(pair, x) <= limit)
    }

    /// The walk of one pair through the timeline: what it found and the instants measured.
    fn pair(&self, pair: (usize, usize)) -> (Vec<Finding>, usize) {
        let (a, b) = pair;
        let (ra, rb) = (self.robots[a].0, self.robots[b].0);
        let world = &self.cell.world;
        let clearance = self.cell.planning.clearance;
        let (mut sa, mut sb) = (Scratch::default(), Scratch::default());
        let mut found = Vec::new();
        // The contact going on: (first instant, last instant) closer than the clearance.
        let mut open: Option<(f64, f64)> = None;
        let close = |open: &mut Option<(f64, f64)>, found: &mut Vec<Finding>| {
            found.extend(open.take().map(|(s, end)| Finding {
                pair,
                start: s,
                kind: Found::Contact { end },
            }));
        };
        let mut t = 0.0;
        let mut checks = 0;
        loop {
            if checks == self.budget {
                close(&mut open, &mut found);
                found.push(Finding {
                    pair,
                    start: t,
                    kind: Found::Unproven { checks },
                });
                return (found, checks);
            }
            checks += 1;
            ra.body_poses(&self.q(a, t), &mut sa);
            rb.body_poses(&self.q(b, t), &mut sb);
            let until = (t + MAX_STEP).min(self.horizon);
            // Beyond this distance the pair cannot close in to the clearance before `until`.
            let cap = clearance + PROOF_TOLERANCE + (self.travel(pair, until) - self.travel(pair, t));
            let d = world.group_group_distance(ra.group, &sa.bodies, rb.group, &sb.bodies, cap);
            let next = if d < clearance {
                open = Some(open.map_or((t, t), |(s, _)| (s, t)));
                t + self.time_step
            } else {
                close(&mut open, &mut found);
                self.reach(pair, t, until, d - clearance + PROOF_TOLERANCE)
                    .max(t + MIN_STEP)
            };
            if t >= self.horizon {
                break;
            }
            t = next.min(self.horizon);
        }
        close(&mut open, &mut found);
        (found, checks)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn samples(points: &[(f64, f64)]) -> Vec<Sample> {
        points.iter().map(|&(t, q)| Sample { t, q: vec![q] }).collect()
    }

    #[test]
    fn travel_interpolates_as_the_positions_do() {
        let s = samples(&[(0.0, 0.0), (1.0, 2.0), (2.0, 1.0), (2.0, 5.0), (3.0, 5.0)]);
        let tr = Travel::new(&[0.5], &s);
        assert_eq!(tr.at_time(-1.0), 0.0);
        assert!((tr.at_time(0.5) - 0.5).abs() < 1e-12);
        // Going back counts as travel too.
        assert!((tr.at_time(1.5) - 1.25).abs() < 1e-12);
        // At a jump the later sample holds, as in `position`.
        assert!((tr.at_time(2.0) - 3.5).abs() < 1e-12);
        assert_eq!(position(&s, 2.0), vec![5.0]);
        assert!((tr.at_time(9.0) - 3.5).abs() < 1e-12);
    }
}

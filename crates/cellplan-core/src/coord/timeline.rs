//! Robot–robot contact on the common clock, found by distance-bounded stepping so that no
//! contact is missed between samples.
//!
//! At time `t` the distance `d` between two robots' bodies is measured. Over `[t, t + Δ]` a point
//! of a robot moves at most `Σ_j r_j·|Δq_j|` (the per-joint Cartesian radii of
//! [`crate::motion::joint_radii`]), and each joint moves at most
//! `min(V_j·Δ, |q̇_j(t)|·Δ + ½·A_j·Δ²)` under its velocity and acceleration limits (nothing
//! while the robot stands: measuring, waiting, or home after its program). The next sample is
//! the largest `Δ` at which the two robots together cannot have closed `d − margin`, so the
//! distance stays above the margin in between.
use super::program::{Activity, Timed};
use cellplan_geom::DVec3;
use cellplan_model::Cell;
use cellplan_model::robot::{Robot, Scratch};
use cellplan_motion::timing::Limits;

/// Distances are measured up to this (m): further apart only means longer steps.
const DISTANCE_CAP: f64 = 1.0;
/// Step while in contact, to find where a contact ends (s).
const CONTACT_STEP: f64 = 0.01;
/// Below this step (s) the pair counts as in contact (a grazing pass would take forever to
/// step over, and being this close is a conflict for any practical purpose).
const MIN_STEP: f64 = 1e-4;
/// Limits are taken this much larger, for the rounding of the timing.
const LIMIT_SLACK: f64 = 1.0 + 1e-6;

/// A robot on the clock: what the contact search needs.
pub struct Mover<'a> {
    /// The robot.
    pub robot: &'a Robot,
    /// Its timed program.
    pub timed: &'a Timed,
    /// Per-joint Cartesian radii.
    pub radii: &'a [f64],
    /// Its limits.
    pub limits: &'a Limits,
}

impl Mover<'_> {
    /// Bound on how far any point of the robot moves over `[t, t + dt]` (m), given that it
    /// stands still until `hold`.
    fn reach(&self, t: f64, hold: f64, v: &[f64], dt: f64) -> f64 {
        let moving = dt - (hold - t).max(0.0);
        if moving <= 0.0 {
            return 0.0;
        }
        // After a hold the robot starts from rest.
        let from_rest = hold > t;
        let mut s = 0.0;
        for (j, r) in self.radii.iter().enumerate() {
            let vmax = self.limits.velocity[j] * LIMIT_SLACK;
            let amax = self.limits.acceleration[j] * LIMIT_SLACK;
            let v0 = if from_rest { 0.0 } else { v[j].abs() };
            s += r * (vmax * moving).min(v0 * moving + 0.5 * amax * moving * moving);
        }
        s
    }
}

/// Whether, and when first, two robots come closer than `margin` in `[from, until]`.
pub struct PairProbe<'a> {
    cell: &'a Cell,
    a: &'a Mover<'a>,
    b: &'a Mover<'a>,
    sa: Scratch,
    sb: Scratch,
    /// The body pair found closest at the last sample (asked first at the next).
    closest: Option<(usize, usize)>,
}

impl<'a> PairProbe<'a> {
    /// A probe for one pair.
    pub fn new(cell: &'a Cell, a: &'a Mover<'a>, b: &'a Mover<'a>) -> Self {
        PairProbe {
            cell,
            a,
            b,
            sa: Scratch::default(),
            sb: Scratch::default(),
            closest: None,
        }
    }

    /// Distance between the robots at `t` (capped).
    pub fn distance(&mut self, t: f64) -> f64 {
        let qa = self.a.timed.trajectory.position(t);
        let qb = self.b.timed.trajectory.position(t);
        self.a.robot.body_poses(&qa, &mut self.sa);
        self.b.robot.body_poses(&qb, &mut self.sb);
        self.cell.world.group_group_distance_from(
            self.a.robot.group,
            &self.sa.bodies,
            self.b.robot.group,
            &self.sb.bodies,
            DISTANCE_CAP,
            &mut self.closest,
        )
    }

    /// First time in `[from, until]` at which the robots are within `margin` (m), or `None`
    /// when they keep at least `margin` apart throughout.
    pub fn first_contact(&mut self, from: f64, until: f64, margin: f64) -> Option<f64> {
        let mut t = from;
        let end = until.min(self.a.timed.end().max(self.b.timed.end()));
        loop {
            let d = self.distance(t);
            if d <= margin {
                return Some(t);
            }
            if t >= end {
                return None;
            }
            let budget = d - margin;
            let (ha, hb) = (self.a.timed.hold_until(t), self.b.timed.hold_until(t));
            if ha.is_infinite() && hb.is_infinite() {
                return None;
            }
            let va = self.a.timed.trajectory.velocity(t);
            let vb = self.b.timed.trajectory.velocity(t);
            let f = |dt: f64| self.a.reach(t, ha, &va, dt) + self.b.reach(t, hb, &vb, dt);
            let step = largest_step(&f, budget, end - t);
            if step < MIN_STEP {
                return Some(t);
            }
            t = (t + step).min(end);
        }
    }

    /// [`Self::first_contact`], searched only in the windows of `[from, until]` in which
    /// `cover` says robots `a` and `b` (this probe's two) may meet — all of it without a
    /// cover, or where the cover does not hold for them.
    pub fn first_contact_covered(
        &mut self,
        (a, b): (usize, usize),
        cover: Option<&super::Cover>,
        from: f64,
        until: f64,
        margin: f64,
    ) -> Option<f64> {
        let windows = cover
            .and_then(|c| c.windows(a, self.a.timed, b, self.b.timed, from, until))
            .unwrap_or_else(|| vec![(from, until)]);
        windows
            .into_iter()
            .find_map(|(lo, hi)| self.first_contact(lo, hi, margin))
    }

    /// Every interval of `[0, horizon]` in which the robots are within `margin`.
    pub fn contacts(&mut self, horizon: f64, margin: f64) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        let mut t = 0.0;
        while t <= horizon {
            let Some(start) = self.first_contact(t, horizon, margin) else {
                break;
            };
            let mut end = start;
            loop {
                let next = end + CONTACT_STEP;
                if next > horizon {
                    end = horizon;
                    break;
                }
                end = next;
                if self.distance(end) > margin {
                    break;
                }
            }
            out.push((start, end));
            if end >= horizon {
                break;
            }
            t = end;
        }
        out
    }
}

/// The largest `Δ ≤ max` with `f(Δ) ≤ budget` for a non-decreasing `f` with `f(0) = 0`
/// (to within 1 %, always on the safe side).
fn largest_step(f: &dyn Fn(f64) -> f64, budget: f64, max: f64) -> f64 {
    if max <= 0.0 {
        return 0.0;
    }
    if f(max) <= budget {
        return max;
    }
    let (mut lo, mut hi) = (0.0, max.min(1e-3));
    while f(hi) <= budget {
        lo = hi;
        hi *= 2.0;
        if hi >= max {
            hi = max;
            break;
        }
    }
    for _ in 0..40 {
        if hi - lo <= 0.01 * hi {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if f(mid) <= budget {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Paper 000's two conflict scenarios.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Scenario {
    /// Both probes are measuring (scenario 1).
    Measuring,
    /// At least one robot is moving between points (scenario 2).
    Moving,
}

impl Scenario {
    /// 1 or 2, as in the paper.
    pub fn number(self) -> u8 {
        match self {
            Scenario::Measuring => 1,
            Scenario::Moving => 2,
        }
    }
}

/// Two robots closer than the clearance.
#[derive(Clone, Debug, PartialEq)]
pub struct Conflict {
    /// The robots (cell indices, first < second).
    pub robots: (usize, usize),
    /// First time found in contact (s).
    pub start: f64,
    /// First time found clear again (s).
    pub end: f64,
    /// What each robot was doing at `start`.
    pub activity: [Activity; 2],
    /// Probe (TCP) positions at `start`.
    pub tcp: [DVec3; 2],
    /// Scenario.
    pub scenario: Scenario,
}

/// The timeline of every robot and the search for conflicts.
pub struct Timeline<'a> {
    cell: &'a Cell,
    /// One mover per robot.
    pub movers: Vec<Mover<'a>>,
    /// Clearance kept between robots (m).
    pub margin: f64,
}

impl<'a> Timeline<'a> {
    /// A timeline of robots on the clock, one mover per robot in cell order.
    pub fn new(cell: &'a Cell, movers: Vec<Mover<'a>>, margin: f64) -> Self {
        Timeline { cell, movers, margin }
    }

    /// The latest end of any program.
    pub fn horizon(&self) -> f64 {
        self.movers.iter().map(|m| m.timed.end()).fold(0.0, f64::max)
    }

    /// Every conflict between every pair, by start time.
    pub fn conflicts(&self) -> Vec<Conflict> {
        let horizon = self.horizon();
        let mut out = Vec::new();
        for a in 0..self.movers.len() {
            for b in a + 1..self.movers.len() {
                let mut probe = PairProbe::new(self.cell, &self.movers[a], &self.movers[b]);
                for (start, end) in probe.contacts(horizon, self.margin) {
                    out.push(self.describe(a, b, start, end));
                }
            }
        }
        out.sort_by(|x, y| x.start.total_cmp(&y.start).then(x.robots.cmp(&y.robots)));
        out
    }

    /// The earliest contact of any pair at or after `from`: (time, robot, robot). With a
    /// `cover` (see [`super::Cover`]), a pair it holds for is searched only in the windows where
    /// the two may meet.
    pub fn first_conflict(&self, from: f64, cover: Option<&super::Cover>) -> Option<(f64, usize, usize)> {
        let mut best: Option<(f64, usize, usize)> = None;
        for a in 0..self.movers.len() {
            for b in a + 1..self.movers.len() {
                let limit = best.map_or(f64::INFINITY, |x| x.0);
                let mut probe = PairProbe::new(self.cell, &self.movers[a], &self.movers[b]);
                if let Some(t) = probe.first_contact_covered((a, b), cover, from, limit, self.margin)
                    && best.is_none_or(|x| t < x.0)
                {
                    best = Some((t, a, b));
                }
            }
        }
        best
    }

    /// The conflict record of a contact interval.
    pub fn describe(&self, a: usize, b: usize, start: f64, end: f64) -> Conflict {
        // Past its end a robot is home: `span_at` gives its last span, the leg home.
        let act = |r: usize| {
            let m = &self.movers[r];
            m.timed.spans[m.timed.span_at(start)].what
        };
        let tcp = |r: usize| {
            let m = &self.movers[r];
            m.robot.tcp_pose(&m.timed.trajectory.position(start)).translation
        };
        let activity = [act(a), act(b)];
        let scenario = if activity.iter().all(|x| matches!(x, Activity::Measure { .. })) {
            Scenario::Measuring
        } else {
            Scenario::Moving
        };
        Conflict {
            robots: (a, b),
            start,
            end,
            activity,
            tcp: [tcp(a), tcp(b)],
            scenario,
        }
    }
}

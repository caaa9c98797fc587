//! Coordination (paper 000 §4.2): put every robot's program on one clock, find every
//! robot–robot conflict, and resolve them.
//!
//! - [`timeline`]: contact search by distance-bounded stepping (cannot miss a contact between
//!   samples), [`Conflict`] records with paper 000's scenarios;
//! - strategies ([`Coordination`]):
//!   - `delay-startup` (baseline): the lower-priority robot's start is delayed by increments
//!     `t0` until it has no conflict with the robots before it (priority: cell order);
//!   - `fixed-priority` (baseline): robots in cell order; a robot that meets one before it waits
//!     at the last waypoint before the shared zone, as long as needed (the shortest wait found
//!     to 10 ms);
//!   - `pose-perturbation` (paper 000 §4.2, steps 1–5): conflicts in time order; priority to
//!     the robot with the shorter total time, whose probe orientation (w, p, r) at the MPs
//!     before and after the conflict (p_a, p_b) is perturbed within the probe's tolerance
//!     (valid poses are reachable, measure the MP, clear of the scene), the local paths
//!     re-planned, and the conflict-free combination with the shortest time kept; the robots
//!     do not stop, except where no perturbation clears a conflict (a reported fallback wait);
//!   - `best` (ours): coordination as scheduling. For every robot pair the coordination
//!     diagram (`diagram`: boxes of positions along the two paths that cover every contact,
//!     found by distance-bounded subdivision) and the order in which the two pass each box,
//!     chosen by branch and bound for the shortest makespan (`schedule`; waits at any rest
//!     before a box, a node budget, exact within it); then each wait cut as far as the exact
//!     search on the clock allows. Where no order exists (a robot's home in another's way)
//!     it falls back on prioritised resolution: every priority order (all up to 4 robots,
//!     else a few), at each conflict the shortest wait or another measuring pose.
mod diagram;
mod perturb;
pub mod program;
mod schedule;
pub mod timeline;

pub use diagram::ConflictBox;
pub use program::{Activity, Program, Timed, VisitPose, Wait, WaitReason};
pub use timeline::{Conflict, Scenario, Timeline};

use crate::candidates::CandidateTable;
use crate::plan::PlanError;
use crate::plan::graph::limits_of;
use cellplan_model::Cell;
use cellplan_motion::timing::Limits;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Extra distance (m) kept between robots beyond the process clearance, so that a plan read
/// back from its trajectory samples (linear interpolation, as the verifier replays it) keeps
/// the clearance too.
pub const REPLAY_SLACK: f64 = 0.003;

/// Coordination strategy.
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, PartialOrd, Ord, schemars::JsonSchema,
)]
#[serde(rename_all = "kebab-case")]
pub enum Coordination {
    /// No coordination: robots may meet (for studies; `verify` rejects such plans when they do).
    None,
    /// Baseline: delayed start-up of the lower-priority robot.
    DelayStartup,
    /// Baseline: fixed priority, the lower-priority robot waits.
    FixedPriority,
    /// Paper 000 §4.2.
    PosePerturbation,
    /// Ours.
    Best,
}

/// Name as on the command line and in the plan document (the serde name).
impl std::fmt::Display for Coordination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(cellplan_model::names::serde_name(self))
    }
}

impl Coordination {
    /// Every strategy that resolves conflicts.
    pub const RESOLVING: [Coordination; 4] = [
        Coordination::DelayStartup,
        Coordination::FixedPriority,
        Coordination::PosePerturbation,
        Coordination::Best,
    ];
}

/// Knobs of coordination.
#[derive(Clone, Debug)]
pub struct CoordSettings {
    /// Strategy.
    pub strategy: Coordination,
    /// Delay increment of delay-startup (s).
    pub delay_step: f64,
    /// Orientation increment of pose-perturbation (rad); the grid is ±2 increments about each
    /// of w, p, r.
    pub perturb_step: f64,
    /// Perturbed (or alternative) pose combinations whose legs are planned per conflict.
    pub perturb_evaluations: usize,
    /// Seed of the local path planner.
    pub seed: u64,
    /// A cycle time to beat (s), from another plan of the same cell: `best` stops resolving a
    /// priority order with waits as soon as its programs end after it (waits only lengthen a
    /// program) and ranks it by that end; the two best orders are still tried with other
    /// poses. `None`: every order is resolved to the end.
    pub bar: Option<f64>,
    /// Nodes of `best`'s search over passage orders (work, not time: the result does not
    /// depend on the machine).
    pub schedule_nodes: usize,
    /// The shortest wait `best` adds (s): at least two trajectory sample steps, so that every
    /// wait shows in the sampled trajectory of the plan.
    pub min_wait: f64,
}

impl Default for CoordSettings {
    fn default() -> Self {
        CoordSettings {
            strategy: Coordination::Best,
            delay_step: 0.1,
            perturb_step: 4f64.to_radians(),
            perturb_evaluations: 12,
            seed: 0,
            bar: None,
            schedule_nodes: 20_000,
            min_wait: 0.05,
        }
    }
}

/// What coordination did.
#[derive(Clone, Debug)]
pub struct Coordinated {
    /// The strategy.
    pub strategy: Coordination,
    /// The final programs, one per robot.
    pub programs: Vec<Program>,
    /// Them on the clock.
    pub timed: Vec<Timed>,
    /// Conflicts of the uncoordinated programs.
    pub before: Vec<Conflict>,
    /// Conflicts met and resolved along the way (a resolution may meet new ones).
    pub resolved: usize,
    /// Waits added.
    pub waits: usize,
    /// Measuring poses changed.
    pub poses_changed: usize,
    /// Priority order used (highest first), where the strategy has one.
    pub priority: Vec<usize>,
    /// Conflicts left (only with [`Coordination::None`]).
    pub after: Vec<Conflict>,
    /// Cycle time without coordination (s).
    pub uncoordinated_cycle: f64,
    /// `best`'s search over passage orders, when it ran.
    pub search: Option<crate::document::PassageSearch>,
    /// Per robot, per visit (`best` only; else empty): seconds of the other robots' paths that
    /// conflict with the robot measuring there (see `diagram::blocking`).
    pub blocking: Vec<Vec<f64>>,
    /// Wall seconds.
    pub compute_s: f64,
}

/// Shared state of a coordination run.
pub(crate) struct Ctx<'a> {
    pub cell: &'a Cell,
    pub table: &'a CandidateTable,
    pub radii: Vec<Vec<f64>>,
    pub limits: Vec<Limits>,
    pub margin: f64,
    pub settings: &'a CoordSettings,
    /// Per robot, its validity checker at the cell's clearance (the others parked at home),
    /// as candidates are checked.
    pub validity: Vec<crate::motion::RobotValidity<'a>>,
}

impl<'a> Ctx<'a> {
    pub fn new(cell: &'a Cell, table: &'a CandidateTable, settings: &'a CoordSettings) -> Self {
        Ctx {
            cell,
            table,
            radii: cell
                .robots
                .iter()
                .map(|r| crate::motion::joint_radii(cell, r))
                .collect(),
            limits: cell.robots.iter().map(limits_of).collect(),
            margin: cell.planning.clearance + REPLAY_SLACK,
            settings,
            validity: cell
                .robots
                .iter()
                .map(|r| crate::motion::robot_validity(cell, r, cell.planning.clearance))
                .collect(),
        }
    }

    pub fn timed(&self, p: &Program) -> Result<Timed, PlanError> {
        p.timed(&self.limits[p.robot])
    }

    /// Robot `r` on the clock as `timed`.
    pub fn mover<'b>(&'b self, r: usize, timed: &'b Timed) -> timeline::Mover<'b> {
        timeline::Mover {
            robot: &self.cell.robots[r],
            timed,
            radii: &self.radii[r],
            limits: &self.limits[r],
        }
    }

    pub fn timeline<'b>(&'b self, timed: &'b [Timed]) -> Timeline<'b> {
        let movers = timed.iter().enumerate().map(|(r, t)| self.mover(r, t)).collect();
        Timeline::new(self.cell, movers, self.margin)
    }

    /// Whether robot `x` (timed as `tx`) keeps clear of `others` in `[from, until]`.
    pub fn clear(
        &self,
        x: usize,
        tx: &Timed,
        timed: &[Timed],
        others: &[usize],
        from: f64,
        until: f64,
    ) -> bool {
        let mx = self.mover(x, tx);
        others.iter().filter(|&&o| o != x).all(|&o| {
            let mo = self.mover(o, &timed[o]);
            timeline::PairProbe::new(self.cell, &mx, &mo)
                .first_contact(from, until, self.margin)
                .is_none()
        })
    }
}

/// Cycle time and Δt of timed programs.
pub fn cycle_and_delta(timed: &[Timed]) -> (f64, f64) {
    let ends: Vec<f64> = timed.iter().map(Timed::end).collect();
    let cycle = ends.iter().copied().fold(0.0, f64::max);
    let low = ends.iter().copied().fold(f64::INFINITY, f64::min);
    (cycle, if low.is_finite() { cycle - low } else { 0.0 })
}

/// Coordinate `programs` (one per robot, cell order, without waits) with `settings.strategy`.
pub fn coordinate(
    cell: &Cell,
    table: &CandidateTable,
    programs: Vec<Program>,
    settings: &CoordSettings,
) -> Result<Coordinated, PlanError> {
    let started = Instant::now();
    let ctx = Ctx::new(cell, table, settings);
    let timed: Vec<Timed> = programs.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
    let before = ctx.timeline(&timed).conflicts();
    let uncoordinated_cycle = cycle_and_delta(&timed).0;
    let cell_order: Vec<usize> = (0..programs.len()).collect();
    let (programs, res, priority) = match settings.strategy {
        Coordination::None => (programs, Resolution::default(), Vec::new()),
        _ if before.is_empty() => (programs, Resolution::default(), cell_order),
        Coordination::DelayStartup | Coordination::FixedPriority | Coordination::PosePerturbation => {
            let mode = match settings.strategy {
                Coordination::DelayStartup => Mode::DelayStartup,
                Coordination::FixedPriority => Mode::GiveWay,
                _ => Mode::Perturb,
            };
            let mut progs = programs;
            let res = resolve(&ctx, &mut progs, &rank_of(&cell_order), mode, None)?;
            let priority = if mode == Mode::Perturb {
                Vec::new()
            } else {
                cell_order
            };
            (progs, res, priority)
        }
        Coordination::Best => {
            let first = match scheduled(&ctx, &programs)? {
                Some(done) => done,
                None => best(&ctx, programs.clone())?,
            };
            baselines_if_shorter(&ctx, &programs, first, &cell_order)?
        }
    };
    let timed: Vec<Timed> = programs.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
    // Whatever the strategy claims, the result is searched once more.
    let after = if settings.strategy == Coordination::None {
        before.clone()
    } else if res.resolved == 0 {
        Vec::new()
    } else {
        ctx.timeline(&timed).conflicts()
    };
    if settings.strategy != Coordination::None
        && let Some(c) = after.first()
    {
        return Err(PlanError::StillMeet {
            robots: [
                ctx.cell.robots[c.robots.0].name.clone(),
                ctx.cell.robots[c.robots.1].name.clone(),
            ],
            at: c.start,
        });
    }
    Ok(Coordinated {
        strategy: settings.strategy,
        programs,
        timed,
        before: if settings.strategy == Coordination::None {
            Vec::new()
        } else {
            before
        },
        resolved: res.resolved,
        waits: res.waits,
        poses_changed: res.poses_changed,
        priority,
        after,
        uncoordinated_cycle,
        search: res.search,
        blocking: res.blocking,
        compute_s: started.elapsed().as_secs_f64(),
    })
}

/// Coordinate the programs of a planning run (see [`coordinate`]).
pub fn coordinate_outcome(
    cell: &Cell,
    table: &CandidateTable,
    outcome: &crate::plan::Outcome,
    settings: &CoordSettings,
) -> Result<Coordinated, PlanError> {
    let programs = outcome.robots.iter().map(|r| r.program.clone()).collect();
    coordinate(cell, table, programs, settings)
}

/// Counts of a resolution.
#[derive(Clone, Debug, Default)]
pub(crate) struct Resolution {
    pub resolved: usize,
    pub waits: usize,
    pub poses_changed: usize,
    /// Set when the run stopped early because its programs already ended after the bar: the
    /// end so far (a lower bound of where waits alone would end).
    pub outrun: Option<f64>,
    /// The search over passage orders (`best`).
    pub search: Option<crate::document::PassageSearch>,
    /// See [`Coordinated::blocking`].
    pub blocking: Vec<Vec<f64>>,
}

/// Most conflicts one strategy resolves before giving up (each resolution moves a conflict
/// later or removes it; this only guards against cycling).
const MAX_RESOLUTIONS: usize = 400;

/// How a conflict is resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mode {
    /// The lower-priority robot's start is delayed by increments of `delay_step` (if no delay
    /// of it works, the other robot's).
    DelayStartup,
    /// The lower-priority robot waits the shortest time, at the latest waypoint before the
    /// conflict from which waiting clears it (if none, the other robot does).
    GiveWay,
    /// As `GiveWay`, or the lower-priority robot takes other measuring poses around the
    /// conflict (perturbed or other candidates), whichever ends sooner.
    GiveWayOrRepose,
    /// Paper 000 §4.2: the robot with the shorter program takes perturbed poses; a wait only
    /// where no perturbation clears the conflict.
    Perturb,
}

/// Where and how a wait is searched.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum WaitSearch {
    /// Any waypoint before the conflict (latest first), the shortest wait to 10 ms.
    Shortest,
    /// Only the start, in increments of this (s).
    Startup(f64),
}

/// Resolve every conflict, earliest first, by `mode`; `rank[r]` is robot `r`'s priority (lower
/// is higher priority).
///
/// Each resolution changes one robot from some time `s` before the conflict on, and keeps it
/// clear of every other robot from `s` to the end of what it was doing at the conflict; before
/// `s` nothing changes. So the earliest conflict never moves earlier and the search resumes
/// from it.
pub(crate) fn resolve(
    ctx: &Ctx,
    programs: &mut [Program],
    rank: &[usize],
    mode: Mode,
    bar: Option<f64>,
) -> Result<Resolution, PlanError> {
    let mut timed: Vec<Timed> = programs.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
    let m = programs.len();
    let mut res = Resolution::default();
    let mut from = 0.0;
    let (search, reason) = match mode {
        Mode::DelayStartup => (WaitSearch::Startup(ctx.settings.delay_step), WaitReason::Startup),
        Mode::Perturb => (WaitSearch::Shortest, WaitReason::Fallback),
        _ => (WaitSearch::Shortest, WaitReason::GiveWay),
    };
    // Waits only lengthen programs: with waits alone, programs that already end after the
    // bar cannot beat it; the run stops there and says where it ended.
    debug_assert!(bar.is_none() || matches!(mode, Mode::GiveWay | Mode::DelayStartup));
    while let Some((t, a, b)) = ctx.timeline(&timed).first_conflict(from) {
        let end = timed.iter().map(Timed::end).fold(0.0, f64::max);
        if bar.is_some_and(|bar| end > bar) {
            res.outrun = Some(end);
            return Ok(res);
        }
        from = t;
        res.resolved += 1;
        if res.resolved > MAX_RESOLUTIONS {
            return Err(PlanError::TooManyConflicts(MAX_RESOLUTIONS));
        }
        // (first to change, second to change)
        let (lo, hi) = if mode == Mode::Perturb {
            // Step 1: priority to the shorter time; the prioritised robot is modified.
            if timed[a].end() <= timed[b].end() {
                (a, b)
            } else {
                (b, a)
            }
        } else if rank[a] > rank[b] {
            (a, b)
        } else {
            (b, a)
        };
        let mut done = false;
        for (x, other) in [(lo, hi), (hi, lo)] {
            let others: Vec<usize> = (0..m).filter(|&r| r != x).collect();
            let reposed = match mode {
                Mode::Perturb if x == lo => perturb::repose(ctx, &programs[x], &timed, x, &others, t, false)?,
                Mode::GiveWayOrRepose => perturb::repose(ctx, &programs[x], &timed, x, &others, t, true)?,
                _ => None,
            };
            // The paper's robots do not stop: a perturbation wins whenever there is one, and
            // only without one is a wait looked for.
            let waited = if mode == Mode::Perturb && reposed.is_some() {
                None
            } else {
                let mut p = programs[x].clone();
                if add_wait(ctx, &mut p, &timed, x, &others, t, other, reason, search)? {
                    let tp = ctx.timed(&p)?;
                    Some((p, tp))
                } else {
                    None
                }
            };
            let take_repose = match (&reposed, &waited) {
                (Some(r), Some(w)) => r.1.end() < w.1.end() - 1e-9,
                (Some(_), None) => true,
                _ => false,
            };
            let (change, counter) = if take_repose {
                (reposed, &mut res.poses_changed)
            } else {
                (waited, &mut res.waits)
            };
            if let Some((p, tp)) = change {
                programs[x] = p;
                timed[x] = tp;
                *counter += 1;
                done = true;
                break;
            }
        }
        if !done {
            return Err(PlanError::Deadlock {
                robots: [ctx.cell.robots[a].name.clone(), ctx.cell.robots[b].name.clone()],
                at: t,
            });
        }
    }
    Ok(res)
}

/// Adds to `program` (robot `x`, currently timed as `timed[x]`) a wait that keeps `x` clear
/// of `others` from the waypoint where it waits to the end of what `x` was doing at `t`: with
/// [`WaitSearch::Shortest`], the shortest such wait (to 10 ms) at the latest waypoint reached
/// before `t` where one exists; with [`WaitSearch::Startup`], the first multiple of the step at
/// the start. False when there is none (e.g. the other robot's path crosses where `x` stands).
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_wait(
    ctx: &Ctx,
    program: &mut Program,
    timed: &[Timed],
    x: usize,
    others: &[usize],
    t: f64,
    other: usize,
    reason: WaitReason,
    search: WaitSearch,
) -> Result<bool, PlanError> {
    let tx = &timed[x];
    // Home already at `t`: it can stay out longer instead (wait before going home), until the
    // other robot has left; the window then runs to its new return home.
    let home = t >= tx.end();
    let act_end = if home {
        tx.end() + 0.5
    } else {
        tx.spans[tx.span_at(t)].end
    };
    // Waypoints reached before t, latest first.
    let mut points: Vec<(f64, usize, usize)> = Vec::new();
    match search {
        WaitSearch::Startup(_) => points.push((0.0, 0, 0)),
        WaitSearch::Shortest => {
            for (k, at) in tx.arrivals.iter().enumerate() {
                for (w, &a) in at.iter().enumerate() {
                    if a < t - 1e-9 && w + 1 < program.legs[k].waypoints.len() {
                        points.push((a, k, w));
                    }
                }
            }
            points.sort_by(|p, q| q.0.total_cmp(&p.0).then((q.1, q.2).cmp(&(p.1, p.2))));
            // The latest few, and the start: waiting at home until the other robot is done
            // always works unless that robot's own home stands in the way.
            if points.len() > 12 {
                points.truncate(11);
                points.push((0.0, 0, 0));
            }
        }
    }
    let horizon = others.iter().map(|&o| timed[o].end()).fold(0.0, f64::max);
    for &(arrive, k, w) in &points {
        let base = program.wait_at(k, w).map_or(0.0, |x| x.duration);
        // Past this, every other robot is home for good: waiting longer changes nothing.
        let limit = (horizon - arrive).max(0.0) + (act_end - arrive) + 0.5;
        let check = |delta: f64| -> Result<bool, PlanError> {
            let mut p = program.clone();
            p.set_wait(Wait {
                leg: k,
                waypoint: w,
                duration: base + delta,
                reason,
                for_robot: Some(other),
            });
            let tp = ctx.timed(&p)?;
            Ok(ctx.clear(x, &tp, timed, others, arrive, act_end + delta))
        };
        let found = match search {
            WaitSearch::Startup(step) => {
                let mut delta = step;
                loop {
                    if check(delta)? {
                        break Some(delta);
                    }
                    delta += step;
                    if delta > limit {
                        break None;
                    }
                }
            }
            WaitSearch::Shortest => {
                // Never a wait shorter than the shortest allowed (it would not show between
                // two trajectory samples): the search starts there.
                let floor = (ctx.settings.min_wait - base).max(0.0);
                let mut lo = floor;
                let mut hi = floor + 0.05;
                let ok = loop {
                    if check(hi)? {
                        break true;
                    }
                    lo = hi;
                    hi = floor + (hi - floor) * 1.5;
                    if hi > limit {
                        break false;
                    }
                };
                if ok && floor > 0.0 && check(floor)? {
                    Some(floor)
                } else if ok {
                    // Shrink to 10 ms (good delays need not form an interval; `hi` stays good).
                    while hi - lo > 0.01 {
                        let mid = 0.5 * (lo + hi);
                        if check(mid)? {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    Some(hi)
                } else {
                    None
                }
            }
        };
        if let Some(delta) = found {
            program.set_wait(Wait {
                leg: k,
                waypoint: w,
                duration: base + delta,
                reason,
                for_robot: Some(other),
            });
            return Ok(true);
        }
    }
    Ok(false)
}

/// `found` (by `best`), or the paper's fixed-priority baseline (cell order, shortest waits on
/// the exact timeline, run only until it ends after `found`) where it ends sooner (then Δt):
/// the diagram's boxes are conservative, and on a small cell waits placed on the exact
/// timeline can give a shorter cycle. (Delay-startup, the other baseline, only delays starts:
/// it costs twice as much and was never the shorter of the two on the example cells.)
fn baselines_if_shorter(
    ctx: &Ctx,
    programs: &[Program],
    found: Resolved,
    cell_order: &[usize],
) -> Result<Resolved, PlanError> {
    let score = |progs: &[Program]| -> Result<(f64, f64), PlanError> {
        let timed: Vec<Timed> = progs.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
        Ok(cycle_and_delta(&timed))
    };
    let mut kept = (score(&found.0)?, found);
    for mode in [Mode::GiveWay] {
        let mut progs = programs.to_vec();
        let bar = Some(kept.0.0 + 1e-9);
        let Ok(res) = resolve(ctx, &mut progs, &rank_of(cell_order), mode, bar) else {
            continue;
        };
        if res.outrun.is_some() {
            continue;
        }
        let s = score(&progs)?;
        // Shorter by more than a millisecond (a tie keeps the schedule).
        if s.0 < kept.0.0 - 1e-3 || (s.0 <= kept.0.0 + 1e-3 && s.1 < kept.0.1 - 1e-3) {
            kept = (s, (progs, res, cell_order.to_vec()));
        }
    }
    Ok(kept.1)
}

/// Programs resolved by a strategy, its counts, and the priority order it used (if any).
type Resolved = (Vec<Program>, Resolution, Vec<usize>);

/// A resolved schedule: cycle time, Δt, programs, counts.
type Scheduled = (f64, f64, Vec<Program>, Resolution);

/// Our strategy: every priority order resolved by the shortest waits; the two best orders
/// again with other poses allowed; the shortest cycle time (then Δt) kept.
///
/// With a bar (`CoordSettings::bar`, the cycle of another plan of the cell), a waits-only run
/// stops as soon as its programs end after the bar, and ranks by that end (a lower bound of
/// its own finish). The two best orders by that ranking are still run with other poses allowed,
/// without the bar, since another pose can end sooner than a wait.
fn best(ctx: &Ctx, programs: Vec<Program>) -> Result<Resolved, PlanError> {
    let orders = priority_orders(&programs);
    let run = |order: &Vec<usize>, mode: Mode, bar: Option<f64>| -> Option<Scheduled> {
        let mut p = programs.clone();
        let res = resolve(ctx, &mut p, &rank_of(order), mode, bar).ok()?;
        if let Some(end) = res.outrun {
            return Some((end, f64::INFINITY, Vec::new(), res));
        }
        let timed: Vec<Timed> = p.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>().ok()?;
        let (c, d) = cycle_and_delta(&timed);
        Some((c, d, p, res))
    };
    let waits: Vec<Option<Scheduled>> = orders
        .par_iter()
        .map(|o| run(o, Mode::GiveWay, ctx.settings.bar))
        .collect();
    let mut ranked: Vec<(f64, f64, usize)> = waits
        .iter()
        .enumerate()
        .filter_map(|(i, r)| r.as_ref().map(|r| (r.0, r.1, i)))
        .collect();
    ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
    let top: Vec<usize> = ranked.iter().take(2).map(|r| r.2).collect();
    let reposed: Vec<Option<Scheduled>> = top
        .par_iter()
        .map(|&i| run(&orders[i], Mode::GiveWayOrRepose, None))
        .collect();
    // Each of the top orders with other poses, then with waits only (where that run finished).
    let mut waits = waits;
    let mut results: Vec<(Scheduled, usize)> = Vec::new();
    for (&i, r) in top.iter().zip(reposed) {
        results.extend(r.map(|r| (r, i)));
    }
    for &i in &top {
        results.extend(waits[i].take().filter(|r| r.3.outrun.is_none()).map(|r| (r, i)));
    }
    let Some(((_, _, progs, res), i)) = results.into_iter().min_by(|a, b| {
        a.0.0
            .total_cmp(&b.0.0)
            .then(a.0.1.total_cmp(&b.0.1))
            .then(a.1.cmp(&b.1))
    }) else {
        return Err(PlanError::NoPriorityOrder);
    };
    Ok((progs, res, orders[i].clone()))
}

/// Ours: the coordination diagram of every robot pair, and the passage orders through its
/// conflict boxes with the shortest makespan (`schedule`); every wait at a rest. `None` when
/// no order exists (then `best` falls back on prioritised resolution).
///
/// Waits are at rests only; when no order exists because a robot has no rest where it could let
/// another pass (it must leave one box before the other robot has passed and reach the next
/// before it has), the robots of an infeasible core of boxes get a stop in the middle of each
/// stretch of path between two of the core's boxes that has none (the segment is split: the
/// same joint path, one more stop), and the diagram is built again, up to [`STOP_ROUNDS`]
/// times.
fn scheduled(ctx: &Ctx, programs: &[Program]) -> Result<Option<Resolved>, PlanError> {
    let mut programs = programs.to_vec();
    let mut round = 0;
    let mut parts = Vec::new();
    let mut distances = 0;
    let (paths, boxes, s) = loop {
        let paths: Vec<diagram::RobotPath> = programs
            .iter()
            .map(|p| diagram::RobotPath::new(ctx, p))
            .collect::<Result<_, _>>()?;
        let (boxes, work) = diagram::diagrams_reusing(ctx, &paths, &mut parts);
        distances += work.distances;
        let tracks: Vec<schedule::Track> = paths.iter().map(|p| p.track()).collect();
        let (nodes, min_wait) = (ctx.settings.schedule_nodes, ctx.settings.min_wait);
        if let Some(s) = schedule::schedule(&tracks, &boxes, nodes, min_wait) {
            break (paths, boxes, s);
        }
        if round == STOP_ROUNDS {
            return Ok(None);
        }
        round += 1;
        let core = schedule::infeasible_core(&tracks, &boxes, nodes, min_wait);
        let core: Vec<&ConflictBox> = core.iter().map(|&i| &boxes[i]).collect();
        let changed = add_stops(ctx, &mut programs, &paths, &core)?;
        if changed.iter().all(|&c| !c) {
            return Ok(None);
        }
        // The pairs of robots whose paths changed are built again.
        let m = programs.len();
        let mut i = 0;
        for a in 0..m {
            for b in a + 1..m {
                if changed[a] || changed[b] {
                    parts[i] = None;
                }
                i += 1;
            }
        }
    };
    let mut out = programs;
    let mut res = Resolution::default();
    for ((prog, path), waits) in out.iter_mut().zip(&paths).zip(&s.waits) {
        prog.waits.clear();
        for (rest, &(d, by)) in path.rests.iter().zip(waits) {
            if d > 0.0 {
                prog.set_wait(Wait {
                    leg: rest.leg,
                    waypoint: rest.waypoint,
                    duration: d,
                    reason: WaitReason::GiveWay,
                    for_robot: by,
                });
                res.waits += 1;
            }
        }
    }
    res.resolved = s.decisions;
    res.blocking = diagram::blocking(&paths, &boxes);
    res.search = Some(crate::document::PassageSearch {
        boxes: boxes.len(),
        distances,
        nodes: s.nodes,
        proven: s.proven,
    });
    debug_assert!({
        let timed: Vec<Timed> = out.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
        (cycle_and_delta(&timed).0 - s.makespan).abs() < 1e-6
    });
    shrink_waits(ctx, &mut out)?;
    res.waits = out.iter().map(|p| p.waits.len()).sum();
    Ok(Some((out, res, Vec::new())))
}

/// How many times `scheduled` adds stops before it gives up on passage orders.
const STOP_ROUNDS: usize = 12;

/// The shortest stretch of path (s of position) a stop is added in.
const MIN_STOP_GAP: f64 = 0.05;

/// Adds a stop in each stretch of moving path between two successive boxes of `core` (on the
/// same robot's positions) that has no rest in it; returns, per program, whether it changed.
fn add_stops(
    ctx: &Ctx,
    programs: &mut [Program],
    paths: &[diagram::RobotPath],
    core: &[&ConflictBox],
) -> Result<Vec<bool>, PlanError> {
    let mut changed = vec![false; programs.len()];
    for (i, (prog, path)) in programs.iter_mut().zip(paths).enumerate() {
        let r = prog.robot;
        let mut spans: Vec<(f64, f64)> = core
            .iter()
            .filter_map(|b| {
                if b.robots.0 == r {
                    Some(b.a)
                } else if b.robots.1 == r {
                    Some(b.b)
                } else {
                    None
                }
            })
            .collect();
        spans.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.total_cmp(&y.1)));
        // Merged, then the gaps between them.
        let mut merged: Vec<(f64, f64)> = Vec::new();
        for (a, b) in spans {
            match merged.last_mut() {
                Some(m) if a <= m.1 => m.1 = m.1.max(b),
                _ => merged.push((a, b)),
            }
        }
        let timed = &path.timed;
        // (leg, segment, position) of each new stop.
        let mut stops: Vec<(usize, usize, f64)> = Vec::new();
        for g in merged.windows(2) {
            let (g0, g1) = (g[0].1, g[1].0);
            if path.rests.iter().any(|x| x.at > g0 + 1e-6 && x.at < g1 - 1e-6) {
                continue;
            }
            // The longest moving stretch inside the gap.
            let pick = timed
                .spans
                .iter()
                .filter_map(|sp| match sp.what {
                    Activity::Move { leg, segment } => {
                        let (lo, hi) = (sp.start.max(g0), sp.end.min(g1));
                        (hi - lo >= MIN_STOP_GAP).then_some((hi - lo, leg, segment, 0.5 * (lo + hi)))
                    }
                    _ => None,
                })
                .max_by(|x, y| x.0.total_cmp(&y.0));
            if let Some((_, leg, segment, at)) = pick {
                stops.push((leg, segment, at));
            }
        }
        // Latest first, so earlier indices stay valid; one per segment.
        stops.sort_by(|x, y| (y.0, y.1).cmp(&(x.0, x.1)).then(y.2.total_cmp(&x.2)));
        stops.dedup_by(|x, y| (x.0, x.1) == (y.0, y.1));
        for (_, _, at) in stops {
            changed[i] |= prog.stop_at(timed, at, &ctx.limits[r])?;
        }
    }
    Ok(changed)
}

/// The coordination diagrams of `programs` (their waits ignored): for every robot pair, boxes
/// of positions (program time without waits) that cover every pair of positions at which the
/// two come closer than the clearance (plus [`REPLAY_SLACK`]); see `diagram`.
pub fn conflict_boxes(
    cell: &Cell,
    table: &CandidateTable,
    programs: &[Program],
    settings: &CoordSettings,
) -> Result<Vec<ConflictBox>, PlanError> {
    let ctx = Ctx::new(cell, table, settings);
    let paths: Vec<diagram::RobotPath> = programs
        .iter()
        .map(|p| diagram::RobotPath::new(&ctx, p))
        .collect::<Result<_, _>>()?;
    Ok(diagram::diagrams(&ctx, &paths).0)
}

/// The boxes of the diagram are larger than the contacts they cover, so the schedule's waits
/// are longer than needed: each wait, earliest first, is cut as far as the exact contact
/// search on the clock allows (to 10 ms; to nothing, or at least [`CoordSettings::min_wait`]).
fn shrink_waits(ctx: &Ctx, programs: &mut [Program]) -> Result<(), PlanError> {
    let mut timed: Vec<Timed> = programs.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
    let mut order: Vec<(f64, usize, usize)> = timed
        .iter()
        .enumerate()
        .flat_map(|(r, t)| t.wait_starts.iter().enumerate().map(move |(i, &s)| (s, r, i)))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    let keys: Vec<(usize, usize, usize)> = order
        .iter()
        .map(|&(_, r, i)| (r, programs[r].waits[i].leg, programs[r].waits[i].waypoint))
        .collect();
    let m = programs.len();
    for (r, leg, waypoint) in keys {
        let Some(w) = programs[r].wait_at(leg, waypoint).cloned() else {
            continue;
        };
        let others: Vec<usize> = (0..m).filter(|&o| o != r).collect();
        let start = timed[r].arrivals[leg][waypoint];
        let try_with = |d: f64| -> Result<Option<(Program, Timed)>, PlanError> {
            let mut p = programs[r].clone();
            p.set_wait(Wait {
                duration: d,
                ..w.clone()
            });
            let tp = ctx.timed(&p)?;
            let ok = ctx.clear(r, &tp, &timed, &others, start, f64::INFINITY);
            Ok(ok.then_some((p, tp)))
        };
        let min = ctx.settings.min_wait;
        let found = if let Some(x) = try_with(0.0)? {
            Some(x)
        } else if w.duration <= min + 0.01 {
            None
        } else {
            // The shortest good duration to 10 ms (good ones need not form an interval; `hi`
            // stays good).
            let (mut lo, mut hi) = (min, w.duration);
            let mut best = None;
            if let Some(x) = try_with(min)? {
                best = Some(x);
                hi = min;
            }
            while hi - lo > 0.01 {
                let mid = 0.5 * (lo + hi);
                if let Some(x) = try_with(mid)? {
                    best = Some(x);
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            best
        };
        if let Some((p, tp)) = found {
            programs[r] = p;
            timed[r] = tp;
        }
    }
    Ok(())
}

/// `rank[r]`: the position of robot `r` in `order`.
fn rank_of(order: &[usize]) -> Vec<usize> {
    let mut rank = vec![0; order.len()];
    for (i, &r) in order.iter().enumerate() {
        rank[r] = i;
    }
    rank
}

/// Priority orders tried by `best`: all permutations up to 4 robots; beyond, shortest program
/// first, cell order, and longest first.
fn priority_orders(programs: &[Program]) -> Vec<Vec<usize>> {
    let m = programs.len();
    if m <= 4 {
        let mut out = Vec::new();
        permutations(&mut (0..m).collect(), 0, &mut out);
        return out;
    }
    let mut by_time: Vec<usize> = (0..m).collect();
    by_time.sort_by(|&a, &b| {
        programs[a]
            .duration()
            .total_cmp(&programs[b].duration())
            .then(a.cmp(&b))
    });
    let mut rev = by_time.clone();
    rev.reverse();
    vec![by_time, (0..m).collect(), rev]
}

fn permutations(v: &mut Vec<usize>, k: usize, out: &mut Vec<Vec<usize>>) {
    if k == v.len() {
        out.push(v.clone());
        return;
    }
    for i in k..v.len() {
        v.swap(k, i);
        permutations(v, k + 1, out);
        v.swap(k, i);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For every coordination strategy: the serde name, `Display` and (with feature `clap`)
    /// the command-line value agree.
    #[test]
    fn coordination_names_agree() {
        let all = [
            Coordination::None,
            Coordination::DelayStartup,
            Coordination::FixedPriority,
            Coordination::PosePerturbation,
            Coordination::Best,
        ];
        // A new strategy must be added to `all`.
        for c in all {
            match c {
                Coordination::None
                | Coordination::DelayStartup
                | Coordination::FixedPriority
                | Coordination::PosePerturbation
                | Coordination::Best => {}
            }
        }
        for c in all {
            let name = c.to_string();
            let json = serde_json::to_value(c).unwrap();
            assert_eq!(json.as_str(), Some(name.as_str()));
            assert_eq!(serde_json::from_value::<Coordination>(json).unwrap(), c);
            #[cfg(feature = "clap")]
            assert_eq!(clap::ValueEnum::to_possible_value(&c).unwrap().get_name(), name);
        }
        #[cfg(feature = "clap")]
        assert_eq!(<Coordination as clap::ValueEnum>::value_variants(), all);
        assert_eq!(
            all.map(|c| c.to_string()),
            [
                "none",
                "delay-startup",
                "fixed-priority",
                "pose-perturbation",
                "best"
            ]
        );
    }
}

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
//!     before a box, a node budget, exact within it), together with the direction each robot
//!     runs its tour in (a tour is a cycle from home: either way it takes as long, but it
//!     meets its neighbours at other times); then each wait cut as far as the exact
//!     search on the clock allows. Where no order exists (a robot's home in another's way)
//!     it falls back on prioritised resolution: every priority order (all up to 4 robots,
//!     else a few), at each conflict the shortest wait or another measuring pose.
pub mod blend;
mod cover;
mod diagram;
mod flips;
mod ours;
mod perturb;
pub mod program;
mod resolve;
mod schedule;
mod settings;
pub mod timeline;

pub use blend::blend_coordinated;
pub use cover::Cover;
pub use diagram::{ConflictBox, DiagramCache};
pub use ours::conflict_boxes;
use ours::{against_canonical, baselines_if_shorter, best, rank_of, scheduled};
pub use program::{Activity, Program, Timed, VisitPose, Wait, WaitReason};
pub(crate) use resolve::{Mode, Resolution, resolve};
pub use settings::{BLEND_DEVIATION, CoordSettings};
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
    /// `best`'s search over passage orders, when its schedule was kept.
    pub search: Option<crate::document::PassageSearch>,
    /// Exact robot–robot distances `best`'s coordination diagrams asked, whichever resolution
    /// was kept (each pair counted as if built afresh; 0 for the other strategies): the work
    /// ours budgets ([`CoordSettings::ours_distances`]).
    pub diagram_distances: usize,
    /// Per robot, per visit (`best` only; else empty): seconds of the other robots' paths that
    /// conflict with the robot measuring there (see `diagram::blocking`).
    pub blocking: Vec<Vec<f64>>,
    /// Per robot, whether coordination runs its tour the other way round (`best`; else
    /// empty). The programs, `before` and the uncoordinated cycle are those of the tours in
    /// the directions chosen.
    pub reversed: Vec<bool>,
    /// Corners the final programs cross without stopping (blends; see [`blend`]).
    pub blended_corners: usize,
    /// Wall seconds.
    pub compute_s: f64,
    /// How ours went, and its parts' seconds, when this is ours' winner
    /// ([`crate::pipeline::coordinate`]).
    pub ours: Option<(crate::document::OursRun, crate::document::OursTimes)>,
}

impl Coordinated {
    /// `w[r][s]`: the seconds robot `r` waits for robot `s` in all (its waits that name the
    /// robot they wait for), one row and column per program.
    pub fn waits_for(&self) -> Vec<Vec<f64>> {
        let n = self.programs.len();
        let mut w = vec![vec![0.0; n]; n];
        for (r, p) in self.programs.iter().enumerate() {
            for wait in &p.waits {
                if let Some(s) = wait.for_robot.filter(|&s| s < n) {
                    w[r][s] += wait.duration;
                }
            }
        }
        w
    }
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
    /// Pair diagrams built by earlier coordinations of the cell, if kept.
    pub diagrams: Option<&'a DiagramCache>,
    /// Per robot, whether it can do none of the tasks ([`crate::check::idle_robots`]).
    pub idle: Vec<bool>,
}

impl<'a> Ctx<'a> {
    /// Whether the coordination's deadline ([`CoordSettings::deadline`]) has passed.
    pub fn past_deadline(&self) -> bool {
        self.settings.deadline.is_some_and(|d| Instant::now() >= d)
    }

    pub fn new(
        cell: &'a Cell,
        table: &'a CandidateTable,
        settings: &'a CoordSettings,
        diagrams: Option<&'a DiagramCache>,
    ) -> Self {
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
            diagrams,
            idle: cell
                .robots
                .iter()
                .map(|r| crate::check::can_do_nothing(cell, table, r.id))
                .collect(),
        }
    }

    pub fn timed(&self, p: &Program) -> Result<Timed, PlanError> {
        let mut t = p.timed(&self.limits[p.robot])?;
        t.idle = self.idle.get(p.robot).copied().unwrap_or(false);
        Ok(t)
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

    /// Whether robot `x` (timed as `tx`) keeps clear of `others` in `[from, until]`: the exact
    /// search on the clock, only in the windows where `cover` (when it holds for the pair)
    /// says the two may meet.
    #[allow(clippy::too_many_arguments)]
    pub fn clear(
        &self,
        x: usize,
        tx: &Timed,
        timed: &[Timed],
        others: &[usize],
        from: f64,
        until: f64,
        cover: Option<&Cover>,
    ) -> bool {
        let mx = self.mover(x, tx);
        others.iter().filter(|&&o| o != x).all(|&o| {
            let mo = self.mover(o, &timed[o]);
            timeline::PairProbe::new(self.cell, &mx, &mo)
                .first_contact_covered((x, o), cover, from, until, self.margin)
                .is_none()
        })
    }
}

/// Cycle time and Δt of timed programs (Δt over the robots that can do some task).
pub fn cycle_and_delta(timed: &[Timed]) -> (f64, f64) {
    let cycle = timed.iter().map(Timed::end).fold(0.0, f64::max);
    let working = timed.iter().filter(|t| !t.idle).map(Timed::end);
    (cycle, crate::check::balance_spread(working))
}

/// Coordinate `programs` (one per robot, cell order, without waits) with `settings.strategy`.
pub fn coordinate(
    cell: &Cell,
    table: &CandidateTable,
    programs: Vec<Program>,
    settings: &CoordSettings,
) -> Result<Coordinated, PlanError> {
    coordinate_with(cell, table, programs, settings, None, None)
}

/// As [`coordinate`], `best` taking the pair diagrams `diagrams` holds from earlier
/// coordinations of the cell and keeping those it builds there (the result is the same).
fn coordinate_with(
    cell: &Cell,
    table: &CandidateTable,
    programs: Vec<Program>,
    settings: &CoordSettings,
    diagrams: Option<&DiagramCache>,
    turned: Option<&[bool]>,
) -> Result<Coordinated, PlanError> {
    let started = Instant::now();
    let ctx = Ctx::new(cell, table, settings, diagrams);
    let timed: Vec<Timed> = programs.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
    let before = ctx.timeline(&timed).conflicts();
    let uncoordinated_cycle = cycle_and_delta(&timed).0;
    let cell_order: Vec<usize> = (0..programs.len()).collect();
    let mut distances = 0;
    let given = programs.clone();
    // With `best`, the kept programs blended as its choice scored them (not done again below).
    let (programs, res, priority, pre_blended) = match settings.strategy {
        Coordination::None => (programs, Resolution::default(), Vec::new(), None),
        _ if before.is_empty() => (programs, Resolution::default(), cell_order, None),
        Coordination::DelayStartup | Coordination::FixedPriority | Coordination::PosePerturbation => {
            let mode = match settings.strategy {
                Coordination::DelayStartup => Mode::DelayStartup,
                Coordination::FixedPriority => Mode::GiveWay,
                _ => Mode::Perturb,
            };
            let mut progs = programs;
            let res = resolve(&ctx, &mut progs, &rank_of(&cell_order), mode, None, None)?;
            let priority = if mode == Mode::Perturb {
                Vec::new()
            } else {
                cell_order
            };
            (progs, res, priority, None)
        }
        Coordination::Best => {
            // Tours in their canonical directions; `reversed` then says which run against the
            // planned ones.
            let against = against_canonical(&programs);
            let programs: Vec<Program> = programs
                .iter()
                .zip(&against)
                .map(|(p, &a)| {
                    if a {
                        p.reversed(&ctx.limits[p.robot])
                    } else {
                        Ok(p.clone())
                    }
                })
                .collect::<Result<_, _>>()?;
            // The diagram of the tours as they are certifies where they cannot meet, for the
            // resolutions below (the exact search then looks only where they may).
            let (found, cover, asked) = scheduled(&ctx, &programs, turned)?;
            if ctx.past_deadline() {
                return Err(PlanError::TimeLimit);
            }
            distances = asked;
            let first = match found {
                Some(done) => done,
                None => best(&ctx, programs.clone(), cover.as_ref())?,
            };
            let ((progs, mut res, priority), blended) = baselines_if_shorter(
                &ctx,
                &programs,
                first,
                &cell_order,
                cover.as_ref(),
                (&given, &against),
            )?;
            res.reversed = (0..programs.len())
                .map(|i| against[i] != res.reversed.get(i).copied().unwrap_or(false))
                .collect();
            if let Some(s) = &mut res.search {
                s.reversed = res.reversed.iter().filter(|&&r| r).count();
            }
            (progs, res, priority, blended)
        }
    };
    // Tours `best` runs the other way round: what the programs as given (no pose changed) meet
    // uncoordinated, each turned as run — as the plan's tracks before coordination are made.
    let before = if res.reversed.iter().any(|&r| r) {
        let bare: Vec<Timed> = given
            .iter()
            .zip(&timed)
            .zip(&res.reversed)
            .map(|((p, t), &turned)| match turned {
                true => ctx.timed(&p.reversed(&ctx.limits[p.robot])?),
                false => Ok(t.clone()),
            })
            .collect::<Result<_, _>>()?;
        ctx.timeline(&bare).conflicts()
    } else {
        before
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
    // Legs without a stop on the way run through their corners, where the exact search on
    // the clock lets them.
    let (programs, timed, blended_corners) = match pre_blended {
        Some(blended) => blended,
        None if settings.strategy == Coordination::None => (programs, timed, 0),
        None => blend::blend_all(&ctx, programs, timed, settings, true)?,
    };
    Ok(Coordinated {
        strategy: settings.strategy,
        programs,
        timed,
        blended_corners,
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
        diagram_distances: distances,
        blocking: res.blocking,
        reversed: res.reversed,
        compute_s: started.elapsed().as_secs_f64(),
        ours: None,
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

/// As [`coordinate_outcome`], with the pair diagrams of earlier coordinations of the cell
/// (see [`DiagramCache`]; the result is the same as without).
pub fn coordinate_outcome_cached(
    cell: &Cell,
    table: &CandidateTable,
    outcome: &crate::plan::Outcome,
    settings: &CoordSettings,
    diagrams: &DiagramCache,
) -> Result<Coordinated, PlanError> {
    let programs = outcome.robots.iter().map(|r| r.program.clone()).collect();
    coordinate_with(cell, table, programs, settings, Some(diagrams), None)
}

/// As [`coordinate_outcome_cached`], the search over tour directions (`best`, beyond five
/// robots, where it flips one robot at a time) starting from
/// `turned` (per robot, whether its tour runs against its canonical direction: see
/// [`canonical_turns`]) instead of every tour in its canonical direction. A plan made from
/// another (a hand-over) starts where the other's coordination ended.
pub fn coordinate_outcome_turned(
    cell: &Cell,
    table: &CandidateTable,
    outcome: &crate::plan::Outcome,
    settings: &CoordSettings,
    diagrams: &DiagramCache,
    turned: &[bool],
) -> Result<Coordinated, PlanError> {
    let programs = outcome.robots.iter().map(|r| r.program.clone()).collect();
    coordinate_with(cell, table, programs, settings, Some(diagrams), Some(turned))
}

/// Per robot, whether `coordinated` (of `outcome`'s programs) runs its tour against the tour's
/// canonical direction, with the first robot's direction taken as canonical (turning every
/// tour is the same schedule run backwards): what [`coordinate_outcome_turned`] starts from.
pub fn canonical_turns(outcome: &crate::plan::Outcome, coordinated: &Coordinated) -> Vec<bool> {
    let against = against_canonical(outcome.robots.iter().map(|r| &r.program));
    let turns: Vec<bool> = against
        .iter()
        .enumerate()
        .map(|(i, &a)| a != coordinated.reversed.get(i).copied().unwrap_or(false))
        .collect();
    let first = turns.first().copied().unwrap_or(false);
    turns.into_iter().map(|t| t != first).collect()
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

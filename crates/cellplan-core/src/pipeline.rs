//! The pipeline as `cellplan plan` runs it — candidates, allocation, sequencing with lazily
//! planned legs, timing, coordination, the document and its verification — and the one place
//! that decides what "ours" is: `best` coordination on the zones allocation and on the other
//! plans of [`coordinate`] (strips per row of robots, swept, twice; the nearest-robot
//! allocation; the zones again knowing what their measurements blocked; the balanced
//! allocation on small cells); the shortest coordinated cycle kept, then balanced on its real
//! times ([`plan::rebalance`]).
//! `cellplan compare` takes its "ours" row from here as well.
use crate::candidates::{self, CandidateTable};
use crate::check::{cap_error, graph_size_error, idle_robot_error};
use crate::coord::{
    CoordSettings, Coordinated, Coordination, DiagramCache, coordinate_outcome, coordinate_outcome_cached,
    cycle_and_delta,
};
use crate::document::{self, Plan};
use crate::plan::rebalance::makespan;
use crate::plan::{self, Allocation, Outcome, PlanError, PlanSettings, Stage};
use cellplan_model::{Cell, InputError};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

mod runners_up;
use runners_up::{AsideRun, RUNNER_UP_REACH, RUNNERS_UP, RunnersUp, Tried};

/// The steps of a run, for progress reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Candidate generation.
    Candidates,
    /// A planning stage.
    Plan(Stage),
    /// Coordination (with `zones_too` when ours plans and coordinates the other plans of
    /// [`coordinate`] too).
    Coordination {
        /// Whether ours' other plans are made and coordinated too.
        zones_too: bool,
    },
    /// The verifier.
    Verification,
}

/// Why a run made no plan.
#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    /// The cell is unusable as given (a robot that can do nothing, caps that cannot hold the
    /// tasks).
    #[error(transparent)]
    Input(Box<InputError>),
    /// Planning failed.
    #[error(transparent)]
    Plan(#[from] PlanError),
}

/// What a run made.
#[derive(Debug)]
pub struct Run<R> {
    /// The candidate table.
    pub table: CandidateTable,
    /// The plan document (`verified` set from the verifier's verdict).
    pub plan: Plan,
    /// The verifier's report on it.
    pub report: R,
}

/// The independent check a run ends with (`cellplan_verify` provides it; the core does not
/// depend on its verifier): the verdict and the report.
pub type Verifier<'a, R> = &'a dyn Fn(&Cell, &CandidateTable, &Plan) -> (bool, R);

/// Runs the whole pipeline on a loaded cell: `load_s` is what loading took (for the
/// document's compute times); `verify` checks the document at the end.
pub fn run<R>(
    cell: &Cell,
    settings: &PlanSettings,
    coord: &CoordSettings,
    load_s: f64,
    progress: &(dyn Fn(Step) + Sync),
    verify: Verifier<'_, R>,
) -> Result<Run<R>, PipelineError> {
    if !cell.process.relations().is_empty() {
        // Precedence and pairing are part of the interface for the processes to come; no
        // allocation or sequencing honours them yet, so a plan that ignored them would be wrong.
        return Err(PlanError::Unsupported {
            what: "planning with relations between tasks (precedence, pairing)",
            process: cell.process.kind(),
        }
        .into());
    }
    let run_started = Instant::now();
    progress(Step::Candidates);
    let lap = Instant::now();
    let table = candidates::generate(cell);
    let candidates_s = lap.elapsed().as_secs_f64();
    if let Some(e) = idle_robot_error(cell, &table)
        .or_else(|| cap_error(cell, &table))
        .or_else(|| graph_size_error(cell, &table))
    {
        return Err(PipelineError::Input(Box::new(e)));
    }
    // One limit for the whole run, every stage.
    let settings = &PlanSettings {
        deadline: Some(settings.deadline.unwrap_or(settings.deadline_from(run_started))),
        ..settings.clone()
    };
    let mut cache = plan::PlanCache::default();
    let outcome = plan::plan_cached(cell, &table, settings, &|s| progress(Step::Plan(s)), &mut cache)?;
    progress(Step::Coordination {
        zones_too: ours_tries_zones(settings, coord),
    });
    // The run's stages are its first plan's: ours' other plans (its tries and hand-overs, the
    // winner among them) are planned inside the coordination stage, whose time counts them.
    let first_stages = outcome.compute.clone();
    let (mut outcome, settings, coordinated) =
        coordinate(cell, &table, outcome, settings.clone(), coord, &mut cache)?;
    outcome.compute = first_stages;
    let mut plan = document::build(
        cell,
        &table,
        &outcome,
        &coordinated,
        &settings,
        load_s,
        candidates_s,
    );
    progress(Step::Verification);
    let lap = Instant::now();
    let (ok, report) = verify(cell, &table, &plan);
    plan.compute_s.verification = lap.elapsed().as_secs_f64();
    plan.verified = ok;
    Ok(Run { table, plan, report })
}

/// Whether ours runs: `best` on the zones allocation, which then plans and coordinates the
/// other plans of [`coordinate`].
pub fn ours_tries_zones(settings: &PlanSettings, coord: &CoordSettings) -> bool {
    is_ours(settings.allocation, coord.strategy)
}

/// Whether an allocation and a coordination strategy are ours' (`best` on the zones
/// allocation), as a plan document states them too.
pub fn is_ours(allocation: Allocation, strategy: Coordination) -> bool {
    strategy == Coordination::Best && allocation == Allocation::Zones
}

/// Weight of the blocking seconds (see [`crate::coord::Coordinated::blocking`]) in the zones
/// allocation's second round.
const BLOCKING_WEIGHT: f64 = 0.5;

/// Where coordination lengthened the first plan by more than this share, the zones are tried
/// a third time with the blocking weighed [`HEAVY_BLOCKING_WEIGHT`]: robots that meet much
/// gain from leaving each other the shared space, at the cost of balance.
const CROWDED: f64 = 0.10;

/// See [`CROWDED`].
const HEAVY_BLOCKING_WEIGHT: f64 = 4.0;

/// Per task and robot, the seconds `coordinated` says the robot's measurement there blocked
/// the others (0 for pairs it did not see).
fn blocking_penalty(cell: &Cell, coordinated: &Coordinated) -> Vec<Vec<f64>> {
    let mut pen = vec![vec![0.0; cell.robots.len()]; cell.tasks.len()];
    // The coordinated programs: their visits are those the blocking counts, in the order
    // (the direction) coordination ran them.
    for (r, program) in coordinated.programs.iter().enumerate() {
        let Some(block) = coordinated.blocking.get(r) else {
            continue;
        };
        for (v, visit) in program.visits.iter().enumerate() {
            pen[visit.task.0][r] = block.get(v).copied().unwrap_or(0.0);
        }
    }
    pen
}

/// One of ours' extra plans.
enum Try {
    /// Planned with these settings.
    Plan(Box<PlanSettings>),
    /// The zones allocation again, each task × robot penalised by what the first plan's
    /// measurement there blocked the other robots (known once the first plan is coordinated),
    /// times this weight ([`BLOCKING_WEIGHT`]; [`HEAVY_BLOCKING_WEIGHT`] on crowded cells).
    ZonesBlocking(f64),
}

/// One of ours' tries planned, `None` when it fails (it only loses its try). The balanced
/// allocation is planned afresh, as it is on its own (legs the other plans timed would steer its
/// lazy sequencing elsewhere): ours is then never longer than it with `best`. It shares the
/// graphs, so the legs the motion planner already gave are not planned again
/// ([`plan::sequence::LegMemo`]; the same legs, so the same plan); the others share `cache`.
fn plan_try(
    cell: &Cell,
    table: &CandidateTable,
    more: &PlanSettings,
    cache: &mut plan::PlanCache,
) -> Result<Outcome, PlanError> {
    // A try the run can do without: given up at the deadline.
    let more = &PlanSettings {
        give_up_at_deadline: true,
        ..more.clone()
    };
    if more.allocation == Allocation::Balanced {
        plan::plan_cached(cell, table, more, &|_| {}, &mut cache.graphs_only())
    } else {
        plan::plan_cached(cell, table, more, &|_| {}, cache)
    }
}

/// `r`, with `clock` set when it is a plan or coordination given up at the deadline
/// ([`PlanError::TimeLimit`]): the run's plan then says the clock cut its search.
fn noting_clock<T>(clock: &AtomicBool, r: Result<T, PlanError>) -> Result<T, PlanError> {
    if matches!(r, Err(PlanError::TimeLimit)) {
        clock.store(true, Ordering::Relaxed);
    }
    r
}

/// After the strips planned with `more` (as `o`), the strips once more, each robot's estimates
/// raised by what its legs took beyond their lower bounds in `o`; `None` after any other try.
fn strips_again(cell: &Cell, more: &PlanSettings, o: &Outcome) -> Option<Try> {
    (more.sweep.is_some() && more.task_penalty.is_empty()).then(|| {
        Try::Plan(Box::new(PlanSettings {
            task_penalty: slowness_penalty(cell, o),
            ..more.clone()
        }))
    })
}

/// Ours plans the balanced (min-max) allocation too on cells of at most this many MPs × robots
/// (the README cell's 45 × 4 included: there it costs ~3 s and does not win; on 20 random MP
/// sets of that cell it wins or ties 2 that ours lost without it, see `bench/cells/README.md`).
pub const BALANCED_MAX_PAIRS: usize = 200;

/// Beyond this many MPs × robots, by default ([`CoordSettings::plan_first_pairs`]), ours plans
/// all its tries before coordinating any, and coordinates them most promising first (see
/// [`coordinate`]).
pub const PLAN_FIRST_PAIRS: usize = 2_000;

/// Exact robot–robot distances the coordination diagrams of ours' plans may ask in all, by
/// default ([`CoordSettings::ours_distances`]; each coordination counted as if its diagrams were
/// built afresh). The first plan is always coordinated; another try or hand-over only while
/// what the coordinations so far asked, plus as much again as the costliest of them, stays
/// within this, and only while the costliest asked at most a quarter of it (choosing among
/// plans pays when several fit; when not even four do, the first plan is kept). Work, not
/// time: the plan depends on the cell and the seed only. A coordination asks 25–30 thousand on
/// the README cell, 0.7–1.8 million on the crowded 6- and 8-robot cells (which use up to ten),
/// 4.3–6.7 million on 4 robots × 2,000 MPs, where ten coordinations took 24 minutes.
pub const OURS_COORDINATION_DISTANCES: usize = 16_000_000;

/// The reliefs of [`plan::rebalance`] (a task of a robot the last one waits for handed to a
/// third robot, tried once the hand-overs are spent), and its group hand-overs after them, may
/// go beyond the coordination budget by
/// its share `1 / RELIEF_EXTRA_DISTANCES`: on the crowded cells the budget is spent by the time
/// they come (crowded-6r seed 1: 1.637 with none beyond it, 1.534 with half of it). The bar on
/// the costliest coordination (a quarter of the budget) is the same, so the cells whose
/// coordinations are costly (2,000 MPs) do not judge more.
pub const RELIEF_EXTRA_DISTANCES: usize = 2;

/// The line of the robots along which ours draws strips: see [`plan::robot_rows`].
pub fn robot_line(cell: &Cell) -> Option<[f64; 2]> {
    plan::robot_rows(cell).map(|(line, _)| line)
}

/// Per task and robot, the seconds per task the robot's program in `o` took beyond its
/// lower-bound time (its legs' real times over their lower bounds), spread over its tasks.
fn slowness_penalty(cell: &Cell, o: &plan::Outcome) -> Vec<Vec<f64>> {
    let per_task: Vec<f64> = o
        .robots
        .iter()
        .zip(o.graphs.iter())
        .map(|(r, g)| {
            let bound = plan::sequence::order_cost(g, &Default::default(), &r.sequence.nodes);
            (r.program.duration() - bound).max(0.0) / r.program.visits.len().max(1) as f64
        })
        .collect();
    vec![per_task; cell.tasks.len()]
}

/// What `cellplan plan` runs: `outcome` (planned with `settings`) coordinated with `coord`.
/// With `best` and the zones allocation (ours), more plans are made and coordinated: the
/// zones as strips across the line of the robots, each robot sweeping its strip
/// ([`PlanSettings::sweep`]; where the robots have a line), and the strips once more with each
/// robot's estimates raised by how much slower than their lower bounds its legs were
/// ([`PlanSettings::task_penalty`]); the nearest-robot allocation; the zones allocation
/// again with what the first plan's measurements blocked the other robots (weighed
/// `BLOCKING_WEIGHT`, and where coordination lengthened the first plan by more than
/// `CROWDED` a third time weighed `HEAVY_BLOCKING_WEIGHT`); and, on cells of at
/// most [`BALANCED_MAX_PAIRS`] MPs × robots, the balanced allocation (which shares no planned
/// legs with the others: it is planned and coordinated aside while they are, and judged at
/// its turn, the last; on cells of more than `plan_first_pairs` it is a try like the others).
/// A plan whose robots
/// end no sooner than the best cycle so far even uncoordinated is not coordinated. The shortest
/// coordinated cycle (then Δt, then the earlier) wins; then [`plan::rebalance::rebalance`]
/// hands tasks from the robot that ends last to others, one at a time, each hand-over kept
/// when its plan, coordinated, ends sooner still, then the reliefs (a task of a robot the
/// last one waits for handed to a third) and the groups (several tasks of the last robot to a
/// robot it waits for), which may go beyond the work budget by the share
/// [`RELIEF_EXTRA_DISTANCES`] sets. When no hand-over from the winner helps, they start again
/// from the shortest plan that lost (a runner-up, see below), within as much work again as the
/// first start took, and the shorter of the two stands. The winner is then polished
/// ([`CoordSettings::polish`]) and kept so where that ends sooner; on cells beyond
/// `plan_first_pairs` every coordination is polished as it is made instead. Plans are compared with
/// every leg stopping at every
/// waypoint; the winner and the `RUNNERS_UP` shortest plans that lost (within
/// `RUNNER_UP_REACH` of it, on cells of at most `plan_first_pairs` MPs × robots) are then
/// blended ([`crate::coord::blend`]) and the shortest blended cycle is the plan. The
/// coordination compute of all is counted.
/// Returns the winning run, its settings and its coordination. `cache` holds what earlier runs
/// on the cell planned (see [`plan::PlanCache`]).
pub fn coordinate(
    cell: &Cell,
    table: &CandidateTable,
    outcome: Outcome,
    settings: PlanSettings,
    coord: &CoordSettings,
    cache: &mut plan::PlanCache,
) -> Result<(Outcome, PlanSettings, Coordinated), PlanError> {
    if !ours_tries_zones(&settings, coord) {
        let c = coordinate_outcome(cell, table, &outcome, coord)?;
        return Ok((outcome, settings, c));
    }
    // Ours compares its plans as coordinated, legs stopping at every waypoint (the bars on
    // uncoordinated ends are in the same terms); the winner is then blended.
    let blend = coord.blend_deviation;
    let unblended = CoordSettings {
        blend_deviation: 0.0,
        ..coord.clone()
    };
    let coord = &unblended;
    let lap = Instant::now();
    let plan_first = cell.tasks.len() * cell.robots.len() > coord.plan_first_pairs;
    // Pair diagrams shared by the coordinations below (many robots keep their paths), and
    // where many coordinations are affordable, the pairs of pieces (most legs recur).
    let diagrams = if plan_first {
        DiagramCache::default()
    } else {
        DiagramCache::with_pieces()
    };
    // The nearest-robot allocation the zones start from, planned and coordinated as it is:
    // where neighbours share much space, uneven but separate work can end sooner than
    // balanced work that meets.
    let nearest = PlanSettings {
        allocation: plan::Allocation::Proximity,
        task_penalty: Vec::new(),
        ..settings.clone()
    };
    // Strips across the line of the robots, every robot sweeping its strip along the line
    // (Åblad et al. separate the robots' workspaces; sweeping the same way keeps neighbours a
    // strip apart, and coordination still chooses each tour's direction).
    let sweep = robot_line(cell).map(|line| PlanSettings {
        sweep: Some(line),
        task_penalty: Vec::new(),
        ..settings.clone()
    });
    // On small cells the min-max allocation too: its search is cheap there, and with few
    // robots meeting little, balanced work often ends first.
    let balanced = (cell.tasks.len() * cell.robots.len() <= BALANCED_MAX_PAIRS).then(|| PlanSettings {
        allocation: plan::Allocation::Balanced,
        task_penalty: Vec::new(),
        ..settings.clone()
    });
    // Where the plans are planned first, the work budget affords few coordinations (one on
    // 8 robots × 1,000 MPs), and no runner-up is kept: each is polished as it is made. On the
    // smaller cells a better coordination changes which plan wins and where the hand-overs
    // lead, and there it did not pay on average (see the polish below).
    let polishing = CoordSettings {
        polish: true,
        ..coord.clone()
    };
    let coord = if plan_first { &polishing } else { coord };
    // Past the run's deadline every coordination but the first plan's is given up (the run
    // needs one plan; the others only compete with it), and the plan says the clock cut it.
    let cuttable = CoordSettings {
        deadline: settings.deadline,
        ..coord.clone()
    };
    let clock_stopped = AtomicBool::new(false);
    // The balanced plan shares with the others only the robot graphs (and their memo of legs)
    // and the diagrams, neither of which changes an answer: where the plans are coordinated as
    // they come, it is planned and coordinated beside them, on what would be an idle core, and
    // judged at its turn (the last try) as if it had been made then.
    let (balanced, aside) = if plan_first {
        (balanced, None)
    } else {
        (None, balanced)
    };
    // The strips first: where they pay, the others are then often beaten before coordination.
    let mut tries: Vec<Try> = [
        sweep.map(|s| Try::Plan(Box::new(s))),
        Some(Try::Plan(Box::new(nearest))),
        Some(Try::ZonesBlocking(BLOCKING_WEIGHT)),
        balanced.map(|s| Try::Plan(Box::new(s))),
    ]
    .into_iter()
    .flatten()
    .collect();
    // Only the best run so far is kept (the shortest cycle, then Δt, then the earlier): the
    // others' plans and coordinations are dropped as soon as they lose. Each plan is
    // coordinated while the next is planned (the plans share `cache`, the coordinations
    // nothing but the diagrams: the result is that of one after the other).
    let mut best: Option<Tried> = None;
    let mut pending = Some((outcome, settings.clone()));
    // On large cells every try is planned first and the plans are coordinated in the order of
    // their robots' latest end without coordination (the most promising first: the work budget
    // may allow only one coordination there); the zones with the blocking penalties are left
    // out (they need a coordination to start from).
    let mut ready: Vec<(Outcome, PlanSettings)> = Vec::new();
    if plan_first {
        ready.extend(pending.take());
        let mut k = 0;
        while let Some(t) = tries.get(k) {
            k += 1;
            let Try::Plan(more) = t else {
                continue;
            };
            let more = PlanSettings::clone(more);
            let Ok(o) = noting_clock(&clock_stopped, plan_try(cell, table, &more, cache)) else {
                continue;
            };
            if let Some(again) = strips_again(cell, &more, &o) {
                tries.insert(k, again);
            }
            ready.push((o, more));
        }
        tries.clear();
        // Soonest end first (ties: the earlier try), popped from the back.
        ready.sort_by(|a, b| makespan(&a.0).total_cmp(&makespan(&b.0)));
        ready.reverse();
        pending = ready.pop();
    }
    // What the first plan's measurements blocked the other robots (set once it is coordinated,
    // before [`Try::ZonesBlocking`] comes up: the first try is planned while it is).
    let mut blocking: Vec<Vec<f64>> = Vec::new();
    let mut next = 0;
    let mut cut = false;
    // Diagram work of the coordinations so far, and of the costliest.
    let spent = std::cell::Cell::new(0usize);
    let costliest = std::cell::Cell::new(0usize);
    let coordinations = std::cell::Cell::new(0usize);
    let count = |c: &Coordinated| {
        coordinations.set(coordinations.get() + 1);
        spent.set(spent.get() + c.diagram_distances);
        costliest.set(costliest.get().max(c.diagram_distances));
    };
    // `extra`: work allowed beyond the budget (the reliefs' and the groups', see
    // [`RELIEF_EXTRA_DISTANCES`]).
    // No coordination may ask more than a quarter of the budget.
    let not_too_costly = || costliest.get().saturating_mul(4) <= coord.ours_distances;
    let affordable_beyond = |extra: usize| {
        spent.get() + costliest.get() <= coord.ours_distances.saturating_add(extra) && not_too_costly()
    };
    let affordable = || affordable_beyond(0);
    // The coordinated plans that lost, the shortest few (on small cells): blending can reorder
    // plans whose cycles are close, so the winner and these are blended and compared at the end.
    let mut runners_up = RunnersUp {
        kept: Vec::new(),
        room: if plan_first { 0 } else { RUNNERS_UP },
    };
    let cycle_of = |b: &Option<Tried>| {
        b.as_ref()
            .map_or(f64::INFINITY, |b| cycle_and_delta(&b.2.timed).0)
    };
    // The best cycle so far, for the plan made aside: a plan that ends no sooner even
    // uncoordinated is not coordinated at its turn (the bar only falls), so it need not be now.
    let bar_now = std::sync::atomic::AtomicU64::new(f64::INFINITY.to_bits());
    let mut aside_cache = cache.graphs_only();
    let mut aside_run: AsideRun = None;
    rayon::in_place_scope(|scope| -> Result<(), PlanError> {
        if let Some(more) = aside {
            let (out, aside_cache, diagrams, bar_now, cuttable, clock) = (
                &mut aside_run,
                &mut aside_cache,
                &diagrams,
                &bar_now,
                &cuttable,
                &clock_stopped,
            );
            scope.spawn(move |_| {
                *out = noting_clock(clock, plan_try(cell, table, &more, aside_cache))
                    .ok()
                    .map(|o| {
                        let bar = f64::from_bits(bar_now.load(Ordering::Relaxed));
                        let judged = (makespan(&o) < bar).then(|| {
                            noting_clock(
                                clock,
                                coordinate_outcome_cached(cell, table, &o, cuttable, diagrams),
                            )
                        });
                        (o, more, judged)
                    });
            });
        }
        loop {
            // Past the deadline the other tries are skipped, and the plan says the clock cut it.
            if next < tries.len() && settings.deadline.is_some_and(|d| Instant::now() >= d) {
                cut = true;
            }
            // Past the work budget (one more coordination would pass it) no try is planned.
            let more = match tries.get(next) {
                _ if cut || !affordable() => None,
                Some(Try::Plan(t)) => Some(PlanSettings::clone(t)),
                Some(&Try::ZonesBlocking(weight)) => Some(PlanSettings {
                    task_penalty: blocking
                        .iter()
                        .map(|row| row.iter().map(|p| weight * p).collect())
                        .collect(),
                    ..settings.clone()
                }),
                None => None,
            };
            if pending.is_none() && affordable() {
                pending = ready.pop();
            }
            if pending.is_none() && more.is_none() {
                break;
            }
            // Coordination only adds waits: a plan whose robots end no sooner than the best cycle
            // so far even without them cannot win, and is not coordinated.
            let bar = cycle_of(&best);
            let first = best.is_none();
            let may = first || affordable();
            let (judged, planned) = rayon::join(
                || {
                    let (o, _) = pending.as_ref()?;
                    let with = if first { coord } else { &cuttable };
                    (makespan(o) < bar && may).then(|| {
                        noting_clock(
                            &clock_stopped,
                            coordinate_outcome_cached(cell, table, o, with, &diagrams),
                        )
                    })
                },
                || noting_clock(&clock_stopped, plan_try(cell, table, more.as_ref()?, cache)).ok(),
            );
            if let Some(Ok(c)) = &judged {
                count(c);
            }
            if let Some((o, s)) = pending.take() {
                match judged {
                    // The first plan's coordination is the run's: its failure is the run's.
                    Some(Err(e)) if first => return Err(e),
                    Some(Ok(c)) if first => {
                        blocking = blocking_penalty(cell, &c);
                        let lengthened = cycle_and_delta(&c.timed).0 / makespan(&o);
                        if lengthened > 1.0 + CROWDED
                            && let Some(at) = tries.iter().position(|t| matches!(t, Try::ZonesBlocking(_)))
                        {
                            tries.insert(at + 1, Try::ZonesBlocking(HEAVY_BLOCKING_WEIGHT));
                        }
                        best = Some((o, s, c));
                    }
                    Some(Ok(c)) => runners_up.offer(&mut best, (o, s, c)),
                    _ => {}
                }
            }
            if let Some(more) = more {
                next += 1;
                if let Some(o) = planned {
                    if let Some(again) = strips_again(cell, &more, &o) {
                        tries.insert(next, again);
                    }
                    pending = Some((o, more));
                }
            }
            bar_now.store(cycle_of(&best).to_bits(), Ordering::Relaxed);
        }
        Ok(())
    })?;
    // The plan made aside at its turn, after every other try: planned unless the clock or the
    // work budget had stopped the tries, coordinated unless it ends no sooner than the best
    // cycle even uncoordinated or one more coordination would pass the budget.
    if let Some((o, s, judged)) = aside_run {
        if settings.deadline.is_some_and(|d| Instant::now() >= d) {
            cut = true;
        } else if !cut
            && affordable()
            && makespan(&o) < cycle_of(&best)
            && let Some(Ok(c)) = judged
        {
            count(&c);
            runners_up.offer(&mut best, (o, s, c));
        }
    }
    // (Never `None`: the first plan is coordinated, or the run has failed with its error.)
    let mut best = best.ok_or(PlanError::NoPriorityOrder)?;
    if cut {
        best.0.time_limit_hit = true;
    }
    let (tries_s, tries_coordinated) = (lap.elapsed().as_secs_f64(), coordinations.get());
    // The best plan balanced on its real times (tasks handed from the robot that ends last, one
    // at a time, then reliefs and groups: see [`plan::rebalance`]), each hand-over judged by its
    // coordinated cycle.
    let ends = |c: &Coordinated| c.timed.iter().map(|t| t.end()).collect::<Vec<f64>>();
    let diagrams = &diagrams;
    // The hand-overs from one start: each hand-over's tours start their search over directions
    // where the coordination of the plan it was made from ended (the start's, for the first).
    let handovers = |start: &Tried,
                     cache: &mut plan::PlanCache,
                     may_judge: &dyn Fn(plan::rebalance::Ask) -> bool|
     -> Result<(Option<Tried>, bool), PlanError> {
        let (score, base_ends) = (cycle_and_delta(&start.2.timed).0, ends(&start.2));
        let base_turns = crate::coord::canonical_turns(&start.0, &start.2);
        let mut judge = |o: &Outcome, from: Option<(&Outcome, &Coordinated)>| {
            let turns = from.map(|(f, c)| crate::coord::canonical_turns(f, c));
            let turns = turns.as_deref().unwrap_or(&base_turns);
            let c = crate::coord::coordinate_outcome_turned(cell, table, o, &cuttable, diagrams, turns);
            let c = noting_clock(&clock_stopped, c).ok()?;
            count(&c);
            Some((cycle_and_delta(&c.timed).0, ends(&c), c))
        };
        let base_waits = start.2.waits();
        let base = (&start.0, score, base_ends.as_slice(), &base_waits);
        let waits_of = |c: &Coordinated| c.waits();
        plan::rebalance::rebalance(
            cell,
            table,
            base,
            &start.1,
            cache,
            may_judge,
            (&mut judge, &waits_of),
        )
    };
    let mut handover_taken = false;
    let before_handovers = spent.get();
    let first = handovers(&best, cache, &|ask: plan::rebalance::Ask| match ask {
        plan::rebalance::Ask::Within => affordable(),
        plan::rebalance::Ask::Beyond => affordable_beyond(coord.ours_distances / RELIEF_EXTRA_DISTANCES),
        // Bounded by the reorders' own budget; refused only where a coordination is too
        // costly, as every other plan is.
        plan::rebalance::Ask::Reorder => not_too_costly(),
    });
    let mut second_start = false;
    if let Ok((found, clock_cut)) = first {
        match found {
            Some(found) => {
                handover_taken = true;
                runners_up.keep(Some(std::mem::replace(&mut best, found)));
            }
            // No hand-over from the best try helped: the best try is not always the best
            // start (a plan whose coordination happened to go well may have no hand-over
            // left that pays), so the hand-overs start again from the shortest try that lost,
            // within as much work again as the first start's took (none on cells beyond
            // `plan_first_pairs`: no runner-up is kept there).
            None if !clock_cut => second_start = true,
            None => {}
        }
        // The clock stopped the hand-overs: the plan says so.
        best.0.time_limit_hit |= clock_cut;
    }
    if second_start && let Some(start) = runners_up.kept.first() {
        let allowed = spent.get() - before_handovers;
        let from = spent.get();
        let may_judge =
            |_: plan::rebalance::Ask| spent.get() - from + costliest.get() <= allowed && not_too_costly();
        if let Ok((found, clock_cut)) = handovers(start, cache, &may_judge) {
            if let Some(found) = found {
                handover_taken |= runners_up.offer_to(&mut best, found);
            }
            best.0.time_limit_hit |= clock_cut;
        }
    }
    let handovers_s = lap.elapsed().as_secs_f64() - tries_s;
    let handovers_judged = coordinations.get() - tries_coordinated;
    // The winner polished: coordinated again (its tour directions searched from those it runs
    // in), and where a search over passage orders ends unproven, each robot put back through
    // the others (see `coord::schedule`); kept when it ends sooner. Only the winner: done to
    // every try and hand-over, a better coordination changes which plan wins and where the
    // hand-overs lead, and on the hard cells that did not pay on average
    // (`bench/cells/README.md`).
    let mut polished = false;
    if plan_first {
        // Polished as it was coordinated (see `polishing` above).
    } else if settings.deadline.is_some_and(|d| Instant::now() >= d) {
        best.0.time_limit_hit = true;
    } else {
        let polish = CoordSettings {
            polish: true,
            ..cuttable.clone()
        };
        let turns = crate::coord::canonical_turns(&best.0, &best.2);
        let c = crate::coord::coordinate_outcome_turned(cell, table, &best.0, &polish, diagrams, &turns);
        if let Ok(c) = noting_clock(&clock_stopped, c)
            && cycle_and_delta(&c.timed) < cycle_and_delta(&best.2.timed)
        {
            best.2 = c;
            polished = true;
        }
    }
    // A coordination the clock gave up: the plan says the clock cut the search.
    if clock_stopped.load(Ordering::Relaxed) {
        best.0.time_limit_hit = true;
    }
    let polish_s = lap.elapsed().as_secs_f64() - tries_s - handovers_s;
    // The winner and the runners-up within reach of it, blended; the shortest blended cycle
    // (then Δt, then the winner first) is the plan.
    let blending = CoordSettings {
        blend_deviation: blend,
        ..coord.clone()
    };
    // Whether the clock cut anything in the run: said by the plan chosen, whichever it is.
    let clock_hit = best.0.time_limit_hit;
    let reach = cycle_and_delta(&best.2.timed).0 * (1.0 + RUNNER_UP_REACH);
    let mut chosen: Option<Tried> = None;
    let candidates = std::iter::once(best).chain(
        runners_up
            .kept
            .into_iter()
            .filter(|r| cycle_and_delta(&r.2.timed).0 <= reach),
    );
    // One context for all of them: the robots' checkers are built once.
    let ctx = crate::coord::Ctx::new(cell, table, &blending, None);
    let mut blended = 0;
    for (o, s, c) in candidates {
        blended += 1;
        let c = crate::coord::blend::blend_with(&ctx, c)?;
        if chosen
            .as_ref()
            .is_none_or(|b| cycle_and_delta(&c.timed) < cycle_and_delta(&b.2.timed))
        {
            chosen = Some((o, s, c));
        }
    }
    let (mut o, s, c) = chosen.expect("the winner is a candidate");
    o.time_limit_hit |= clock_hit;
    let spent = lap.elapsed().as_secs_f64();
    let ours = (
        crate::document::OursRun {
            tries_coordinated,
            handovers_judged,
            handover_taken,
            polished,
            polished_throughout: plan_first,
            blended,
        },
        crate::document::OursTimes {
            tries: tries_s,
            handovers: handovers_s,
            polish: polish_s,
            blend: spent - tries_s - handovers_s - polish_s,
        },
    );
    Ok((
        o,
        s,
        Coordinated {
            compute_s: spent,
            ours: Some(ours),
            ..c
        },
    ))
}

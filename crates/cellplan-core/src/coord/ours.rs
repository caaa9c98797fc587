//! Our coordination strategy, `best`: the passage orders scheduled on the coordination
//! diagrams with stops where they help ([`scheduled`]), every priority order resolved by the
//! shortest waits when no schedule is found ([`best`]), the paper's fixed-priority baseline
//! kept where it ends sooner ([`baselines_if_shorter`]), and the schedule's waits cut to what
//! the exact timeline needs ([`shrink_waits`]).
use super::flips::flip_one_at_a_time;
use super::program::{Program, Timed, Wait};
use super::*;

/// `found` (by `best`), or the paper's fixed-priority baseline (cell order, shortest waits on
/// the exact timeline, run only until it ends after `found`) where it ends sooner (then Δt):
/// the diagram's boxes are conservative, and on a small cell waits placed on the exact
/// timeline can give a shorter cycle. Delay-startup, the other baseline, only delays starts:
/// without blends it costs twice as much and was never the shorter of the two on the example
/// cells; with blends (each candidate is scored with its legs blended, see [`super::blend`])
/// it is run too, and both baselines also on the tours as planned (`as_planned`: the
/// programs and, per robot, whether `best`'s tour runs against it). (Then `best`'s result may
/// depend on the directions the tours were given; without blends it does not.)
pub(super) fn baselines_if_shorter(
    ctx: &Ctx,
    programs: &[Program],
    found: Resolved,
    cell_order: &[usize],
    cover: Option<&Cover>,
    as_planned: (&[Program], &[bool]),
) -> Result<(Resolved, Option<Blended>), PlanError> {
    let blending = ctx.settings.blend_deviation > 0.0;
    // Scored as they will run: with blends, with the legs blended that coordination leaves
    // without a stop on the way (the kept one's blending is returned, not done again).
    let score = |progs: &[Program]| -> Result<((f64, f64), Option<Blended>), PlanError> {
        let timed: Vec<Timed> = progs.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
        if !blending {
            return Ok((cycle_and_delta(&timed), None));
        }
        let blended = super::blend::blend_all(ctx, progs.to_vec(), timed, ctx.settings, true)?;
        Ok((cycle_and_delta(&blended.1), Some(blended)))
    };
    let (s, b) = score(&found.0)?;
    // A baseline only adds waits: where the schedule ends with the robots' latest end without
    // any, none ends sooner (a tie could win on Δt; none did on the benchmark cells).
    let floor = |m: f64, p: &Program| ctx.timed(&p.without_waits()).map(|t| m.max(t.end()));
    if !blending && s.0 <= programs.iter().try_fold(0.0, floor)? + 1e-3 {
        return Ok((found, b));
    }
    let mut kept = (s, found, b);
    // (mode, on the tours as planned): fixed priority on the tours as `best` turned them; with
    // blends, both baselines on the tours as planned too, as the strategies themselves run
    // them: blending gains most where no wait is on the way (delay-startup's waits are all at
    // home), so a baseline can end sooner blended than `best`'s schedule does.
    let runs: &[(Mode, bool)] = if blending {
        &[
            (Mode::GiveWay, false),
            (Mode::GiveWay, true),
            (Mode::DelayStartup, true),
        ]
    } else {
        &[(Mode::GiveWay, false)]
    };
    for &(mode, planned) in runs {
        let mut progs = if planned {
            as_planned.0.to_vec()
        } else {
            programs.to_vec()
        };
        // The bar is on ends before blending: with blends, a run that ends after the kept
        // cycle may still end sooner once blended.
        let bar = (!blending).then_some(kept.0.0 + 1e-9);
        let cover = if planned { None } else { cover.cloned() };
        let Ok(mut res) = resolve(ctx, &mut progs, &rank_of(cell_order), mode, bar, cover) else {
            continue;
        };
        if res.outrun.is_some() {
            continue;
        }
        if planned {
            // Against the canonical directions, as `best`'s results are stated.
            res.reversed = as_planned.1.to_vec();
        }
        let (s, b) = score(&progs)?;
        // Shorter by more than a millisecond (a tie keeps the schedule).
        if s.0 < kept.0.0 - 1e-3 || (s.0 <= kept.0.0 + 1e-3 && s.1 < kept.0.1 - 1e-3) {
            kept = (s, (progs, res, cell_order.to_vec()), b);
        }
    }
    Ok((kept.1, kept.2))
}

/// Programs blended, their timing and the corners blended (see [`super::blend::blend_all`]).
pub(super) type Blended = (Vec<Program>, Vec<Timed>, usize);

/// Programs resolved by a strategy, its counts, and the priority order it used (if any).
pub(super) type Resolved = (Vec<Program>, Resolution, Vec<usize>);

/// A resolved schedule: cycle time, Δt, programs, counts.
type Scheduled = (f64, f64, Vec<Program>, Resolution);

/// Our strategy: every priority order resolved by the shortest waits; the two best orders
/// again with other poses allowed; the shortest cycle time (then Δt) kept.
///
/// With a bar (`CoordSettings::bar`, the cycle of another plan of the cell), a waits-only run
/// stops as soon as its programs end after the bar, and ranks by that end (a lower bound of
/// its own finish). The two best orders by that ranking are still run with other poses allowed,
/// without the bar, since another pose can end sooner than a wait.
pub(super) fn best(ctx: &Ctx, programs: Vec<Program>, cover: Option<&Cover>) -> Result<Resolved, PlanError> {
    let orders = priority_orders(&programs);
    let run = |order: &Vec<usize>, mode: Mode, bar: Option<f64>| -> Option<Scheduled> {
        let mut p = programs.clone();
        let res = resolve(ctx, &mut p, &rank_of(order), mode, bar, cover.cloned()).ok()?;
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
/// conflict boxes with the shortest makespan (`schedule`); every wait at a rest; each robot's
/// tour in the direction that goes with them ([`directions`]). `None` when no order exists
/// (then `best` falls back on prioritised resolution).
///
/// Waits are at rests only; when no order exists because a robot has no rest where it could let
/// another pass (it must leave one box before the other robot has passed and reach the next
/// before it has), the robots of an infeasible core of boxes get a stop in the middle of each
/// stretch of path between two of the core's boxes that has none (the segment is split: the
/// same joint path, one more stop), and the diagram is built again, up to [`STOP_ROUNDS`]
/// times (the tours keep their planned directions then).
pub(super) fn scheduled(
    ctx: &Ctx,
    programs: &[Program],
    turned: Option<&[bool]>,
) -> Result<(Option<Resolved>, Option<Cover>, usize), PlanError> {
    let mut programs = programs.to_vec();
    let mut round = 0;
    let mut parts = Vec::new();
    let mut distances = 0;
    let mut searched = 0;
    let m = programs.len();
    // The diagram of the programs as given (round 0), for the resolutions that follow.
    let mut cover = None;
    loop {
        let paths: Vec<diagram::RobotPath> = programs
            .iter()
            .map(|p| diagram::RobotPath::new(ctx, p))
            .collect::<Result<_, _>>()?;
        let (boxes, work) = diagram::diagrams_reusing(ctx, &paths, &mut parts)?;
        if round == 0 {
            cover = Some(Cover::new(m, &boxes));
        }
        distances += work.distances;
        let tracks: Vec<schedule::Track> = paths.iter().map(|p| p.track()).collect();
        let (nodes, min_wait) = (ctx.settings.schedule_nodes, ctx.settings.min_wait);
        // The reversed programs and their paths `directions` made (none after round 0).
        let (found, back) = if round == 0 {
            let (found, back, spent) = directions(ctx, &programs, &paths, &boxes, turned)?;
            searched += spent;
            (found, back)
        } else {
            let s = schedule::schedule_with(&tracks, &boxes, nodes, min_wait, ctx.settings.polish);
            searched += s.as_ref().map_or(nodes, |s| s.nodes);
            let found = s.map(|s| vec![(vec![false; m], s, boxes.clone())]);
            (found.unwrap_or_default(), Vec::new())
        };
        // Each combination of directions found, finished (waits cut on the exact clock; in
        // parallel, each on its own); the shortest cycle (then Δt) wins, ties to the earlier.
        let finished: Vec<((f64, f64), Resolved)> = found
            .into_par_iter()
            .map(|(flip, s, boxes)| -> Result<((f64, f64), Resolved), PlanError> {
                let mut progs = Vec::with_capacity(m);
                let mut ps = Vec::with_capacity(m);
                for (i, (p, path)) in programs.iter().zip(&paths).enumerate() {
                    match back.get(i) {
                        Some(Some((r, rpath))) if flip[i] => {
                            progs.push(r.clone());
                            ps.push(rpath.clone());
                        }
                        _ => {
                            progs.push(p.clone());
                            ps.push(path.clone());
                        }
                    }
                }
                let search = crate::document::PassageSearch {
                    boxes: boxes.len(),
                    distances,
                    nodes: searched,
                    proven: s.proven,
                    reversed: flip.iter().filter(|&&r| r).count(),
                };
                let done = finish(ctx, progs, &ps, &boxes, &s, search, flip)?;
                let timed: Vec<Timed> = done.0.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
                Ok((cycle_and_delta(&timed), done))
            })
            .collect::<Result<_, _>>()?;
        let mut kept: Option<((f64, f64), Resolved)> = None;
        for (key, done) in finished {
            let shorter = kept
                .as_ref()
                .is_none_or(|(k, _)| key.0 < k.0 - 1e-3 || (key.0 <= k.0 + 1e-3 && key.1 < k.1 - 1e-3));
            if shorter {
                kept = Some((key, done));
            }
        }
        if let Some((_, done)) = kept {
            return Ok((Some(done), cover, distances));
        }
        if round == STOP_ROUNDS {
            return Ok((None, cover, distances));
        }
        round += 1;
        let core = schedule::infeasible_core(&tracks, &boxes, nodes, min_wait);
        let core: Vec<&ConflictBox> = core.iter().map(|&i| &boxes[i]).collect();
        let changed = add_stops(ctx, &mut programs, &paths, &core)?;
        if changed.iter().all(|&c| !c) {
            return Ok((None, cover, distances));
        }
        // The pairs of robots whose paths changed are built again.
        let mut i = 0;
        for a in 0..m {
            for b in a + 1..m {
                if changed[a] || changed[b] {
                    parts[i] = None;
                }
                i += 1;
            }
        }
    }
}

/// The programs of `s` (a schedule of `paths` through `boxes`) with its waits, each cut as far
/// as the exact search on the clock allows, and the counts.
fn finish(
    ctx: &Ctx,
    mut out: Vec<Program>,
    paths: &[diagram::RobotPath],
    boxes: &[ConflictBox],
    s: &schedule::Schedule,
    search: crate::document::PassageSearch,
    reversed: Vec<bool>,
) -> Result<Resolved, PlanError> {
    let mut res = Resolution::default();
    for ((prog, path), waits) in out.iter_mut().zip(paths).zip(&s.waits) {
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
            }
        }
    }
    res.resolved = s.decisions;
    res.blocking = diagram::blocking(paths, boxes);
    res.search = Some(search);
    res.reversed = reversed;
    debug_assert!({
        let timed: Vec<Timed> = out.iter().map(|p| ctx.timed(p)).collect::<Result<_, _>>()?;
        (cycle_and_delta(&timed).0 - s.makespan).abs() < 1e-6
    });
    let cover = Cover::new(out.len(), boxes);
    shrink_waits(ctx, &mut out, &cover)?;
    res.waits = out.iter().map(|p| p.waits.len()).sum();
    Ok((out, res, Vec::new()))
}

/// Up to this many robots, [`directions`] tries every combination of tour directions;
/// beyond, it flips one robot at a time.
const ALL_DIRECTIONS_UP_TO: usize = 5;

/// Rounds of single flips [`directions`] makes beyond [`ALL_DIRECTIONS_UP_TO`] robots.
const FLIP_ROUNDS: usize = 2;

/// How many of the best combinations of directions are finished (waits cut on the exact
/// clock) and compared by the cycle they then give: the boxes are conservative, and the
/// shortest schedule through them need not be the shortest once cut.
const DIRECTIONS_FINISHED: usize = 2;

/// A combination of tour directions (per robot, whether its tour runs the other way round),
/// the schedule of passage orders found for it, and its (mirrored) boxes.
type Directed = (Vec<bool>, schedule::Schedule, Vec<ConflictBox>);

/// The directions each robot may run its tour in, chosen with the passage orders.
///
/// A robot's tour is a cycle from home to home: run the other way round it measures the same
/// MPs on the same legs in the same time, but it is in the space it shares with a neighbour at
/// other times. The diagram of a pair with one tour reversed is the pair's diagram mirrored
/// along that robot's positions (`s ↦ len − s`: every segment is timed from rest to rest and
/// takes as long either way), so the boxes are built once and each combination costs one
/// search over passage orders. Reversing every robot is the same schedule run backwards in
/// time, so the first robot keeps its direction. (`best` hands the tours over in their
/// canonical directions, see [`against_canonical`].) Combinations are tried all (up
/// to [`ALL_DIRECTIONS_UP_TO`] robots) or one flip at a time (a flip kept when it shortens the
/// schedule, [`FLIP_ROUNDS`] rounds, from `turned` when given — per robot, whether its tour
/// starts turned); ties go to fewer flips, then to the earlier combination. Each combination's
/// search depends on the combination alone, so they run in parallel (all at once; or two
/// neighbouring flips side by side, the second kept only if the first was not) and are taken
/// in the order above: the result is that of one search after the other.
///
/// Returns the [`DIRECTIONS_FINISHED`] best combinations by makespan (flips relative to
/// `programs`; empty when no combination has a schedule), per robot its reversed program and
/// path (made for every robot but the first, and for the first when the flips start from
/// `turned` turning it), and the nodes searched (of the searches taken).
#[allow(clippy::type_complexity)]
fn directions(
    ctx: &Ctx,
    programs: &[Program],
    paths: &[diagram::RobotPath],
    boxes: &[ConflictBox],
    turned: Option<&[bool]>,
) -> Result<(Vec<Directed>, Vec<Option<(Program, diagram::RobotPath)>>, usize), PlanError> {
    let m = programs.len();
    let (nodes, min_wait) = (ctx.settings.schedule_nodes, ctx.settings.min_wait);
    let index: Vec<usize> = {
        let mut v = vec![usize::MAX; paths.iter().map(|p| p.robot + 1).max().unwrap_or(0)];
        for (i, p) in paths.iter().enumerate() {
            v[p.robot] = i;
        }
        v
    };
    let start = match turned {
        Some(t) if t.len() == m => t.to_vec(),
        _ => vec![false; m],
    };
    let all = m <= ALL_DIRECTIONS_UP_TO;
    // Every robot but the first is flipped by some combination below (the first only by the
    // flips, where `turned` turns it): each reversed program and its path made once, in
    // parallel.
    let back: Vec<Option<(Program, diagram::RobotPath)>> = (0..m)
        .into_par_iter()
        .map(|i| -> Result<_, PlanError> {
            if i == 0 && (all || !start[0]) {
                return Ok(None);
            }
            let p = programs[i].reversed(&ctx.limits[programs[i].robot])?;
            let path = diagram::RobotPath::new(ctx, &p)?;
            Ok(Some((p, path)))
        })
        .collect::<Result<_, _>>()?;
    // One combination's search (a function of the combination alone), and the nodes it took.
    let try_turn = |flip: &[bool]| -> (Option<Directed>, usize) {
        // Past the deadline no search starts (the coordination is then given up, below).
        if ctx.past_deadline() {
            return (None, 0);
        }
        let flip = flip.to_vec();
        let mirrored: Vec<ConflictBox> = boxes
            .iter()
            .map(|b| {
                let (ia, ib) = (index[b.robots.0], index[b.robots.1]);
                let mut mb = b.clone();
                if flip[ia] {
                    mb.a = (paths[ia].len - b.a.1, paths[ia].len - b.a.0);
                    mb.open.swap(0, 1);
                }
                if flip[ib] {
                    mb.b = (paths[ib].len - b.b.1, paths[ib].len - b.b.0);
                    mb.open.swap(2, 3);
                }
                mb
            })
            .collect();
        let tracks: Vec<schedule::Track> = (0..m)
            .map(|i| match (&back[i], flip[i]) {
                (Some((_, p)), true) => p.track(),
                _ => paths[i].track(),
            })
            .collect();
        let s = schedule::schedule_with(&tracks, &mirrored, nodes, min_wait, ctx.settings.polish);
        let spent = s.as_ref().map_or(nodes, |s| s.nodes);
        (s.map(|s| (flip, s, mirrored)), spent)
    };
    let mut spent = 0;
    let mut found: Vec<Directed> = Vec::new();
    // Kept sorted by makespan (stable: ties stay in the order tried).
    let keep = |d: Directed, found: &mut Vec<Directed>| {
        let at = found.partition_point(|x| x.1.makespan <= d.1.makespan + 1e-3);
        found.insert(at, d);
        found.truncate(DIRECTIONS_FINISHED);
    };
    if all {
        // By number of turns, then mask; searched in parallel, taken in that order.
        let mut masks: Vec<usize> = (0..1usize << m.saturating_sub(1)).collect();
        masks.sort_by_key(|&k| (k.count_ones(), k));
        let searched: Vec<(Option<Directed>, usize)> = masks
            .par_iter()
            .map(|&k| {
                let turn: Vec<bool> = (0..m).map(|i| i > 0 && (k >> (i - 1)) & 1 == 1).collect();
                try_turn(&turn)
            })
            .collect();
        for (d, n) in searched {
            spent += n;
            if let Some(d) = d {
                keep(d, &mut found);
            }
        }
    } else {
        // From the directions given (those of the plan this one was made from), else from
        // every tour in its canonical direction.
        let (taken, n) = flip_one_at_a_time(start, FLIP_ROUNDS, &try_turn, &|d: &Directed| d.1.makespan);
        spent += n;
        for d in taken {
            keep(d, &mut found);
        }
    }
    if ctx.past_deadline() {
        return Err(PlanError::TimeLimit);
    }
    Ok((found, back, spent))
}

/// Per program, whether it runs against its tour's canonical direction (the first MP after
/// the last in the cell's order): `best` turns such tours round before it starts, so that what
/// it finds does not depend on which way the sequencer happened to write a tour.
pub(super) fn against_canonical<'p>(programs: impl IntoIterator<Item = &'p Program>) -> Vec<bool> {
    programs
        .into_iter()
        .map(|p| match (p.visits.first(), p.visits.last()) {
            (Some(a), Some(b)) => a.task.0 > b.task.0,
            _ => false,
        })
        .collect()
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
    let ctx = Ctx::new(cell, table, settings, None);
    let paths: Vec<diagram::RobotPath> = programs
        .iter()
        .map(|p| diagram::RobotPath::new(&ctx, p))
        .collect::<Result<_, _>>()?;
    Ok(diagram::diagrams(&ctx, &paths)?.0)
}

/// The boxes of the diagram are larger than the contacts they cover, so the schedule's waits
/// are longer than needed: each wait, earliest first, is cut as far as the exact contact
/// search on the clock allows (to 10 ms; to nothing, or at least [`CoordSettings::min_wait`]).
fn shrink_waits(ctx: &Ctx, programs: &mut [Program], cover: &Cover) -> Result<(), PlanError> {
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
            let ok = ctx.clear(r, &tp, &timed, &others, start, f64::INFINITY, Some(cover));
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
pub(super) fn rank_of(order: &[usize]) -> Vec<usize> {
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

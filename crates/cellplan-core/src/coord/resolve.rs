//! Prioritised resolution of conflicts, earliest first: the baselines (delay startup, fixed
//! priority), paper 000's pose perturbation, and `best`'s fallback when no passage order
//! exists; and the wait a robot takes to let another pass.
use super::*;

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
    /// See [`Coordinated::reversed`] (empty: none).
    pub reversed: Vec<bool>,
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
    mut cover: Option<Cover>,
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
    while let Some((t, a, b)) = ctx.timeline(&timed).first_conflict(from, cover.as_ref()) {
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
                if add_wait(
                    ctx,
                    &mut p,
                    &timed,
                    x,
                    &others,
                    t,
                    other,
                    reason,
                    search,
                    cover.as_ref(),
                )? {
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
                // Other poses: the robot's path is no longer the one the cover was built on.
                if take_repose && let Some(c) = &mut cover {
                    c.invalidate(x);
                }
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
    cover: Option<&Cover>,
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
            Ok(ctx.clear(x, &tp, timed, others, arrive, act_end + delta, cover))
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

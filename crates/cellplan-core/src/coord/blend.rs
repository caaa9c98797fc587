//! Blends: after coordination, the legs a robot crosses without stopping on the way are timed
//! through their corners without stopping (issue 15 item 4).
//!
//! Coordination times every segment from rest to rest, so that a wait may go on any waypoint.
//! Once the waits are placed, a leg with no wait on the way needs none of those stops: each
//! of its corners is cut by a parabolic blend ([`time_path_blended_scaled`]), within
//! [`CoordSettings::blend_deviation`] of the corner in every joint. The blend's curve leaves the
//! path the planner checked, so it is checked itself ([`curve_clear`]: distance-bounded
//! stepping along the curve, as the planner steps along segments); a corner whose blend fails
//! gets a quarter of the bound, then a sixteenth, then none. Before it is blended, a leg that is
//! not the direct segment loses its joints' needless detours (a wrist the sampler swung round
//! and back): partial shortcuts of one joint at a time
//! ([`cellplan_motion::plan::straighten_joints_timed`]), each changed segment checked against
//! the cell. A robot's program straightened and blended is tried first where it ends sooner,
//! then the program only blended. A robot's blended program is kept only if the exact
//! search on the clock finds it clear of every other robot: first with its waits as long as
//! they were (the robot runs ahead of its old timeline), else with each wait lengthened to end
//! when it ended before (the timeline after every wait is the old one).
use super::program::{LegBlend, Program, ProgramLeg, Timed};
use super::{CoordSettings, Coordinated, Coordination, Ctx};
use crate::candidates::CandidateTable;
use crate::plan::PlanError;
use cellplan_model::Cell;
use cellplan_motion::plan::StateValidity;
use cellplan_motion::timing::{Limits, time_path_blended_scaled};

/// Clearance (m) below which a blend's curve is not certified: stepping would take steps too
/// short to be worth it, and the robot passes that close to something only on its own path.
const MIN_CLEARANCE: f64 = 1e-4;
/// Most clearance queries spent on one blend's curve.
const MAX_CURVE_STEPS: usize = 2_000;
/// The deviation bound of a corner whose blend failed its check, as a share of the one before
/// (after the last, the corner is not blended).
const SHRINK: [f64; 3] = [1.0, 0.25, 0.0625];

/// Whether the quadratic Bézier curve with control points `a`, `p`, `c` (joint space) keeps
/// `validity`'s clearance throughout. At a point `q(σ)` of the curve with clearance `d` (its
/// least distance over the scene parts, less the margin, and the self pairs), any point of the
/// robot moves at most `Σ_j R_j·|Δq_j|` while the joints move by `Δq` (`radii`: `R_j` bounds
/// the distance of every point joint `j` moves from its axis), and over `[σ, σ + Δ]` joint `j`
/// moves at most `|q'_j(σ)|·Δ + |D_j|·Δ²` (`q'' = 2D`, `D = a − 2p + c`). The next point is the
/// largest `Δ` at which that stays within `d/2`: a body keeps off the scene, and two bodies
/// (both moving) off each other, in between. Joint limits hold on the whole curve when they
/// hold at the three control points (the curve lies in their convex hull).
pub fn curve_clear(validity: &dyn StateValidity, radii: &[f64], a: &[f64], p: &[f64], c: &[f64]) -> bool {
    let n = a.len();
    let d: Vec<f64> = (0..n).map(|j| a[j] - 2.0 * p[j] + c[j]).collect();
    let quad: f64 = (0..n).map(|j| radii[j] * d[j].abs()).sum();
    let at = |s: f64| -> Vec<f64> {
        (0..n)
            .map(|j| a[j] + 2.0 * s * (p[j] - a[j]) + s * s * d[j])
            .collect()
    };
    let mut s = 0.0f64;
    for _ in 0..MAX_CURVE_STEPS {
        let clearance = validity.clearance(&at(s));
        if clearance.is_nan() || clearance <= MIN_CLEARANCE {
            return false;
        }
        if s >= 1.0 {
            return true;
        }
        let budget = 0.5 * clearance;
        let lin: f64 = (0..n)
            .map(|j| radii[j] * (2.0 * (p[j] - a[j]) + 2.0 * s * d[j]).abs())
            .sum();
        let step = if quad > 0.0 {
            // quad·Δ² + lin·Δ = budget, the positive root (written to stay accurate for small quad).
            2.0 * budget / (lin + (lin * lin + 4.0 * quad * budget).sqrt())
        } else if lin > 0.0 {
            budget / lin
        } else {
            1.0
        };
        if step.is_nan() || step <= 1e-9 {
            return false;
        }
        s = (s + step).min(1.0);
    }
    false
}

/// The leg's waypoints without repeated points and without interior points on a straight
/// line through their neighbours: the same joint path, every interior waypoint a corner.
fn corners_only(waypoints: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let dist = |x: &[f64], y: &[f64]| {
        x.iter()
            .zip(y)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt()
    };
    let mut out: Vec<Vec<f64>> = Vec::with_capacity(waypoints.len());
    for (i, w) in waypoints.iter().enumerate() {
        let last = i + 1 == waypoints.len();
        if let Some(prev) = out.last()
            && dist(prev, w) <= 1e-12
        {
            if last {
                // Keep the leg's end exactly.
                *out.last_mut().expect("non-empty") = w.clone();
            }
            continue;
        }
        if out.len() >= 2 {
            let (a, b) = (&out[out.len() - 2], &out[out.len() - 1]);
            let (lab, lbw) = (dist(a, b), dist(b, w));
            let straight = a
                .iter()
                .zip(b)
                .zip(w)
                .all(|((x, y), z)| ((y - x) / lab - (z - y) / lbw).abs() <= 1e-9);
            if straight {
                out.pop();
            }
        }
        out.push(w.clone());
    }
    out
}

/// The unit direction from `x` to `y`.
fn unit(x: &[f64], y: &[f64]) -> Vec<f64> {
    let d: Vec<f64> = x.iter().zip(y).map(|(a, b)| b - a).collect();
    let len = d.iter().map(|v| v * v).sum::<f64>().sqrt();
    d.iter().map(|v| v / len).collect()
}

/// The control points of the blend at corner `w` of `waypoints` with radius `r`.
pub fn blend_controls(waypoints: &[Vec<f64>], w: usize, r: f64) -> (Vec<f64>, Vec<f64>) {
    let p = &waypoints[w];
    let (u_in, u_out) = (unit(&waypoints[w - 1], p), unit(p, &waypoints[w + 1]));
    let a = p.iter().zip(&u_in).map(|(x, u)| x - r * u).collect();
    let c = p.iter().zip(&u_out).map(|(x, u)| x + r * u).collect();
    (a, c)
}

/// The leg timed through its corners, each blend's curve checked: `None` when no corner can
/// be blended.
fn blend_leg(
    validity: &dyn StateValidity,
    radii: &[f64],
    limits: &Limits,
    leg: &ProgramLeg,
    deviation: f64,
) -> Result<Option<ProgramLeg>, PlanError> {
    let waypoints = corners_only(&leg.waypoints);
    if waypoints.len() < 3 {
        return Ok(None);
    }
    let mut scale = vec![1.0; waypoints.len()];
    // Each round that fails lowers some corner's scale a step: at most this many rounds.
    for _ in 0..=SHRINK.len() * waypoints.len() {
        let path =
            time_path_blended_scaled(&waypoints, limits, &[deviation], &scale).map_err(PlanError::Timing)?;
        if path.blends.is_empty() {
            return Ok(None);
        }
        let mut failed = false;
        for b in &path.blends {
            let (a, c) = blend_controls(&waypoints, b.waypoint, b.radius);
            if !curve_clear(validity, radii, &a, &waypoints[b.waypoint], &c) {
                let next = SHRINK.iter().position(|&x| x < scale[b.waypoint]);
                scale[b.waypoint] = next.map_or(0.0, |i| SHRINK[i]);
                failed = true;
            }
        }
        if !failed {
            let corners = path.blends.iter().map(|b| (b.waypoint, b.radius)).collect();
            let mut blended = ProgramLeg::new(waypoints, leg.straight, limits)?;
            blended.blend = Some(LegBlend {
                trajectory: path.trajectory,
                corners,
                waypoint_times: path.waypoint_times,
            });
            return Ok(Some(blended));
        }
    }
    Ok(None)
}

/// Partial shortcuts of one joint at a time tried on each leg before it is blended
/// ([`cellplan_motion::plan::straighten_joints_timed`]).
const STRAIGHTEN_ATTEMPTS: usize = 40;

/// `prog` with every leg that has no wait on the way blended where its blends check out;
/// `None` when no leg changes. With `plain` — `prog` blended without straightening (this
/// function's answer without `plain`, or `prog` itself when that was `None`) — each such leg
/// that is not the direct segment first has its joints' needless detours removed (partial
/// shortcuts of one joint at a time, every changed segment checked against the cell as the
/// planner checks legs), and a leg that straightening leaves as it was takes its blend from
/// `plain` instead of being blended again (the same leg, the same blend); a leg with a wait on
/// the way is left as it is, its waypoints being where the wait is. Returns the corners blended
/// and the legs straightened too.
fn blended_program(
    ctx: &Ctx,
    prog: &Program,
    deviation: f64,
    plain: Option<&Program>,
) -> Result<Option<(Program, usize, usize)>, PlanError> {
    let r = prog.robot;
    let mut out = prog.clone();
    let (mut corners, mut straightened) = (0, 0);
    let robot = &ctx.cell.robots[r];
    let space = plain.map(|_| crate::motion::joint_space(ctx.cell, robot));
    for (k, leg) in prog.legs.iter().enumerate() {
        if leg.blend.is_some() || prog.waits.iter().any(|w| w.leg == k && w.waypoint > 0) {
            continue;
        }
        let mut leg = std::borrow::Cow::Borrowed(leg);
        if let Some(space) = &space
            && !leg.straight
            && leg.waypoints.len() >= 3
        {
            let mut waypoints = leg.waypoints.clone();
            let seed = ctx.settings.seed ^ ((r as u64) << 32) ^ k as u64;
            cellplan_motion::plan::straighten_joints_timed(
                space,
                &ctx.validity[r],
                &mut waypoints,
                (seed, STRAIGHTEN_ATTEMPTS),
                MIN_CLEARANCE,
                &ctx.limits[r],
            );
            if waypoints != leg.waypoints {
                straightened += 1;
                leg = std::borrow::Cow::Owned(ProgramLeg::new(waypoints, false, &ctx.limits[r])?);
            }
        }
        if let (std::borrow::Cow::Borrowed(_), Some(plain)) = (&leg, plain) {
            let blended = &plain.legs[k];
            corners += blended.blend.as_ref().map_or(0, |x| x.corners.len());
            out.legs[k] = blended.clone();
            continue;
        }
        match blend_leg(&ctx.validity[r], &ctx.radii[r], &ctx.limits[r], &leg, deviation)? {
            Some(b) => {
                corners += b.blend.as_ref().map_or(0, |x| x.corners.len());
                out.legs[k] = b;
            }
            None => {
                if let std::borrow::Cow::Owned(l) = leg {
                    out.legs[k] = l;
                }
            }
        }
    }
    Ok((corners + straightened > 0).then_some((out, corners, straightened)))
}

/// `blended` with each wait lengthened to end when it ended in `before` (the program as timed
/// before blending): the timeline after every wait is the old one.
fn keep_wait_ends(ctx: &Ctx, mut blended: Program, before: &Timed) -> Result<Program, PlanError> {
    for i in 0..blended.waits.len() {
        let timed = ctx.timed(&blended)?;
        let end = before.wait_starts[i] + blended.waits[i].duration;
        let start = timed.wait_starts[i];
        let mut w = blended.waits[i].clone();
        w.duration = (end - start).max(w.duration);
        blended.set_wait(w);
    }
    Ok(blended)
}

/// Blends the coordinated `programs` (timed as `timed`) robot by robot, the robot that ends
/// last first, keeping each robot's blended program only where the exact search on the clock
/// finds it clear of every other robot (with `check`; without, as for uncoordinated programs,
/// always). Returns the programs, their timing and the corners blended.
pub(crate) fn blend_all(
    ctx: &Ctx,
    mut programs: Vec<Program>,
    mut timed: Vec<Timed>,
    settings: &CoordSettings,
    check: bool,
) -> Result<(Vec<Program>, Vec<Timed>, usize), PlanError> {
    let deviation = settings.blend_deviation;
    if deviation.is_nan() || deviation <= 0.0 {
        return Ok((programs, timed, 0));
    }
    let mut order: Vec<usize> = (0..programs.len()).collect();
    order.sort_by(|&x, &y| timed[y].end().total_cmp(&timed[x].end()).then(x.cmp(&y)));
    let all: Vec<usize> = (0..programs.len()).collect();
    let mut blended_corners = 0;
    for r in order {
        // The legs straightened and blended, then blended only (when straightening changed
        // a leg); each with its waits as long as they were, then ending when they ended.
        // (The plain blend first, so that the straightened program takes the legs
        // straightening leaves alone from it.)
        let plain = blended_program(ctx, &programs[r], deviation, None)?;
        let straight = blended_program(
            ctx,
            &programs[r],
            deviation,
            Some(plain.as_ref().map_or(&programs[r], |p| &p.0)),
        )?;
        let mut variants = Vec::new();
        if let Some((p, corners, straightened)) = straight
            && straightened > 0
        {
            variants.push((p, corners));
        }
        if let Some((p, corners, _)) = plain {
            variants.push((p, corners));
        }
        let mut keeping = Vec::new();
        for (blended, corners) in variants {
            if !blended.waits.is_empty() {
                let kept = keep_wait_ends(ctx, blended.clone(), &timed[r])?;
                keeping.push((blended, corners));
                keeping.push((kept, corners));
            } else {
                keeping.push((blended, corners));
            }
        }
        let mut keeping = keeping
            .into_iter()
            .map(|(p, c)| Ok((ctx.timed(&p)?, p, c)))
            .collect::<Result<Vec<_>, PlanError>>()?;
        // The soonest end first (a stable sort: of equal ends, the order above).
        keeping.sort_by(|a, b| a.0.end().total_cmp(&b.0.end()));
        for (t, candidate, corners) in keeping {
            if !check || ctx.clear(r, &t, &timed, &all, 0.0, f64::INFINITY, None) {
                programs[r] = candidate;
                timed[r] = t;
                blended_corners += corners;
                break;
            }
        }
    }
    Ok((programs, timed, blended_corners))
}

/// `coordinated` (not yet blended) with its legs blended as `settings` asks (see the module),
/// where the exact search on the clock keeps the robots clear (the coordination strategy
/// `none` is left as it is).
pub fn blend_coordinated(
    cell: &Cell,
    table: &CandidateTable,
    coordinated: Coordinated,
    settings: &CoordSettings,
) -> Result<Coordinated, PlanError> {
    blend_with(&Ctx::new(cell, table, settings, None), coordinated)
}

/// [`blend_coordinated`] in a coordination context made once for several plans of a cell
/// (with `ctx.settings` the blending asked for).
pub(crate) fn blend_with(ctx: &Ctx, coordinated: Coordinated) -> Result<Coordinated, PlanError> {
    if coordinated.strategy == Coordination::None {
        return Ok(coordinated);
    }
    let (programs, timed, corners) =
        blend_all(ctx, coordinated.programs, coordinated.timed, ctx.settings, true)?;
    Ok(Coordinated {
        programs,
        timed,
        blended_corners: coordinated.blended_corners + corners,
        ..coordinated
    })
}

//! Paper 000 §4.2: conflicts resolved by perturbing the probe orientation at the MPs around
//! them, and the same move with any other candidate pose (used by `best`).
use super::Ctx;
use super::program::{Activity, Program, ProgramLeg, Timed, VisitPose};
use crate::candidates::{reach, wrap};
use crate::plan::PlanError;
use cellplan_geom::DQuat;
use cellplan_motion::plan::PlanSettings as MotionSettings;
use cellplan_motion::timing::move_time;
use glam::EulerRot;
use rayon::prelude::*;
use std::time::Duration;

/// Perturbed orientations kept per MP (nearest to the original configuration first).
const PERTURBED_PER_VISIT: usize = 24;
/// Other candidates of the MP kept per MP (`best` only).
const CANDIDATES_PER_VISIT: usize = 24;

/// The visits around robot `x`'s conflict at `t` (p_a and p_b of paper 000 §4.2 step 2): the
/// MPs before and after the leg it is on, or the MP it measures.
fn around(program: &Program, timed: &Timed, t: f64) -> Vec<usize> {
    let n = program.visits.len();
    match timed.spans[timed.span_at(t)].what {
        Activity::Move { leg, .. } | Activity::Wait { leg, .. } => {
            let mut v = Vec::new();
            if leg >= 1 && leg <= n {
                v.push(leg - 1);
            }
            if leg < n {
                v.push(leg);
            }
            v
        }
        Activity::Measure { visit } => vec![visit],
    }
}

/// Orientation of a probe pose as FANUC (w, p, r): rotation Rz(r)·Ry(p)·Rx(w).
fn wpr(q: DQuat) -> [f64; 3] {
    let (r, p, w) = q.to_euler(EulerRot::ZYX);
    [w, p, r]
}

/// Other measuring poses of visit `v`: the orientation perturbed on the ±2-increment grid about
/// w, p, r (position fixed), kept when the probe still measures the MP, IK reaches it within
/// limits, the beams are clear and the robot is clear of the scene and itself; with
/// `candidates`, also the MP's other candidates from the table.
fn alternatives(ctx: &Ctx, program: &Program, v: usize, candidates: bool) -> Vec<VisitPose> {
    let cell = ctx.cell;
    let robot = &cell.robots[program.robot];
    let orig = &program.visits[v];
    let task = &cell.tasks[orig.task.0];
    let step = ctx.settings.perturb_step;
    let poses = cell.process.nearby_poses(task, &orig.tcp, step);
    let limits = &ctx.limits[program.robot];
    let reach = reach(
        cell,
        cell.process.as_ref(),
        robot,
        task,
        &poses,
        &ctx.validity[program.robot],
    );
    let base = wpr(orig.tcp.rotation);
    let base_pert = orig.perturbation.unwrap_or([0.0; 3]);
    let mut perturbed: Vec<(f64, VisitPose)> = reach
        .candidates
        .into_iter()
        .map(|c| {
            let e = wpr(c.tcp.rotation);
            let d = [
                base_pert[0] + wrap(e[0] - base[0]),
                base_pert[1] + wrap(e[1] - base[1]),
                base_pert[2] + wrap(e[2] - base[2]),
            ];
            let pose = VisitPose {
                perturbation: Some(d),
                ..VisitPose::from_candidate(orig.task, orig.candidate, &c, orig.dwell)
            };
            (move_time(&orig.q, &c.q, limits), pose)
        })
        .collect();
    perturbed.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<VisitPose> = perturbed
        .into_iter()
        .take(PERTURBED_PER_VISIT)
        .map(|x| x.1)
        .collect();
    if candidates {
        let mut others: Vec<(f64, VisitPose)> = ctx
            .table
            .get(orig.task, robot.id)
            .candidates
            .iter()
            .enumerate()
            .filter(|(c, _)| *c != orig.candidate || orig.perturbation.is_some())
            .map(|(c, cand)| {
                (
                    move_time(&orig.q, &cand.q, limits),
                    VisitPose::from_candidate(orig.task, c, cand, orig.dwell),
                )
            })
            .collect();
        others.sort_by(|a, b| a.0.total_cmp(&b.0));
        out.extend(others.into_iter().take(CANDIDATES_PER_VISIT).map(|x| x.1));
    }
    out
}

/// Robot `x`'s program with other measuring poses around its conflict at `t`, the local legs
/// re-planned, clear of `others` from the start of the first changed leg to the end of the
/// measurement after the last one; the one that ends soonest, or `None`.
pub(crate) fn repose(
    ctx: &Ctx,
    program: &Program,
    timed: &[Timed],
    x: usize,
    others: &[usize],
    t: f64,
    candidates: bool,
) -> Result<Option<(Program, Timed)>, PlanError> {
    let tx = &timed[x];
    if t >= tx.end() {
        // Home is not a measuring pose.
        return Ok(None);
    }
    let vis = around(program, tx, t);
    if vis.is_empty() {
        return Ok(None);
    }
    let alts: Vec<Vec<VisitPose>> = vis
        .iter()
        .map(|&v| {
            let mut a = vec![program.visits[v].clone()];
            a.extend(alternatives(ctx, program, v, candidates));
            a
        })
        .collect();
    let first = vis[0];
    let last = *vis.last().expect("not empty");
    let limits = &ctx.limits[x];
    let prev_q = program.legs[first].waypoints[0].clone();
    let next_q = program.legs[last + 1]
        .waypoints
        .last()
        .expect("legs have waypoints")
        .clone();
    // Combinations (one pose per visit), not all original, ranked by their lower-bound time.
    let mut combos: Vec<(f64, Vec<usize>)> = Vec::new();
    let mut push = |c: Vec<usize>| {
        let mut lb = 0.0;
        let mut at = &prev_q;
        for (k, &i) in c.iter().enumerate() {
            lb += move_time(at, &alts[k][i].q, limits);
            at = &alts[k][i].q;
        }
        lb += move_time(at, &next_q, limits);
        combos.push((lb, c));
    };
    if alts.len() == 1 {
        for i in 1..alts[0].len() {
            push(vec![i]);
        }
    } else {
        for i in 0..alts[0].len() {
            for j in 0..alts[1].len() {
                if (i, j) != (0, 0) {
                    push(vec![i, j]);
                }
            }
        }
    }
    combos.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    combos.truncate(ctx.settings.perturb_evaluations);
    let from = tx.arrivals[first][0];
    let robot = &ctx.cell.robots[x];
    let evaluated: Vec<Option<(f64, usize, Program, Timed)>> = combos
        .par_iter()
        .enumerate()
        .map(|(ci, (_, c))| -> Result<_, PlanError> {
            let mut p = program.clone();
            // The chain prev → poses → next, its legs planned anew where an end changed.
            let mut chain: Vec<&[f64]> = vec![&prev_q];
            chain.extend(c.iter().enumerate().map(|(k, &i)| alts[k][i].q.as_slice()));
            chain.push(&next_q);
            let mut legs = Vec::new();
            for (k, w) in chain.windows(2).enumerate() {
                let old = &program.legs[first + k];
                if old.waypoints[0] == w[0] && old.waypoints.last().map(Vec::as_slice) == Some(w[1]) {
                    legs.push(old.clone());
                    continue;
                }
                let settings = MotionSettings {
                    seed: ctx.settings.seed ^ (x as u64) << 40 ^ (first as u64) << 20 ^ ci as u64,
                    max_samples: 400,
                    shortcut_iterations: 20,
                    time_limit: Duration::from_secs(10),
                    ..MotionSettings::default()
                };
                let Ok(path) = crate::motion::plan_leg(ctx.cell, robot, w[0], w[1], &settings) else {
                    return Ok(None);
                };
                legs.push(ProgramLeg::new(path.waypoints, path.straight, limits)?);
            }
            for (k, &i) in c.iter().enumerate() {
                let v = vis[k];
                p.visits[v] = alts[k][i].clone();
            }
            for (k, leg) in legs.into_iter().enumerate() {
                p.legs[first + k] = leg;
            }
            // Waits inside re-planned legs lose their place.
            p.waits
                .retain(|w| w.leg < first || w.leg > last + 1 || w.waypoint == 0);
            let tp = ctx.timed(&p)?;
            let until = tp.visits.get(last + 1).map_or(tp.end(), |v| v.1);
            Ok(ctx
                .clear(x, &tp, timed, others, from, until, None)
                .then(|| (tp.end(), ci, p, tp)))
        })
        .collect::<Result<_, _>>()?;
    Ok(evaluated
        .into_iter()
        .flatten()
        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        .map(|(_, _, p, tp)| (p, tp)))
}

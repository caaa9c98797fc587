//! Sequencing with lazy path costs (paper 002 §2.1): each robot's tasks as a GTSP over its
//! candidates, home → tasks → home, first on the lower-bound move times; the legs the sequence
//! uses are planned (collision-free path, timed under the limits) and their real times replace
//! the bounds; re-sequence until the sequence uses only planned legs, or the budget ends.
use super::graph::RobotGraph;
use super::{LegError, PlanError, PlanSettings};
use cellplan_model::Cell;
use cellplan_model::robot::Robot;
use cellplan_model::tasks::TaskId;
use cellplan_motion::plan::PlanSettings as MotionSettings;
use cellplan_motion::timing::time_path_exact;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::time::Instant;

mod order;
mod reach;
pub use order::{OrderRule, SWEEP_GROUPS, best_order, best_order_with};
pub use reach::Reach;

/// A planned leg between two nodes of a robot graph.
#[derive(Clone, Debug)]
pub struct Leg {
    /// The collision-free joint path (waypoints, straight segments between them).
    pub waypoints: Vec<Vec<f64>>,
    /// Time to drive it from rest to rest under the limits (s).
    pub duration: f64,
    /// Whether it is the direct segment.
    pub straight: bool,
    /// Random samples a sampling planner drew for it.
    pub samples: usize,
    /// Validity (clearance) calls spent on it.
    pub validity_calls: usize,
    /// Seconds spent planning it (one thread).
    pub compute_s: f64,
}

/// One robot's sequence.
#[derive(Clone, Debug, Default)]
pub struct Sequence {
    /// Nodes visited in order (home excluded).
    pub nodes: Vec<usize>,
    /// Legs: home → first, …, last → home (one leg home → home when there are no tasks).
    pub legs: Vec<Leg>,
    /// Sequencing rounds.
    pub rounds: usize,
    /// Legs planned (each pair once).
    pub legs_planned: usize,
    /// Of those, legs that needed the sampling planner.
    pub legs_sampled: usize,
    /// Legs for which no path was found (their nodes were avoided).
    pub legs_failed: usize,
    /// The search stopped because no order could finish below the bar it was given: `nodes`
    /// and `legs` are empty (the counts still say what was planned).
    pub beaten: bool,
    /// Tasks given up (not in `nodes`): every order found needed a leg to or from them that
    /// the planner could not solve with its full budget; with why.
    pub dropped: Vec<(TaskId, String)>,
    /// Whether the deadline, not the round budget, ended the lazy loop.
    pub clock_cut: bool,
}

/// The lazy loop may run this many times its rounds while its best order needs a failed leg.
const STUCK_ROUNDS_FACTOR: usize = 2;
/// Cost of a leg no path was found for: large enough never to be chosen when another exists.
pub const NO_PATH: f64 = 1e6;

/// Legs planned so far for one robot, by unordered node pair (a < b), or why none was found.
pub type Planned = BTreeMap<(usize, usize), Result<Leg, LegError>>;

/// Sequence `tasks` for `robot` with lazily planned legs.
///
/// `bar` (s) is the time to beat: as soon as the best order the sequencer finds under the
/// current costs (planned legs real, the others at their lower bound) takes at least `bar`,
/// the search stops and returns a sequence marked [`Sequence::beaten`]. The legs planned until
/// then stay in `planned`. Pass `f64::INFINITY` to always finish. `first`, when given, is the
/// first round's order, as [`best_order`] gives it for the same `planned` (already computed by
/// a caller that looked before it leapt).
///
/// A task that every order still reaches through a leg without a path (after the full-budget
/// retry) is given up: listed in [`Sequence::dropped`] with the planner's reason, and the rest
/// sequenced without it. One hard task never loses the robot's sequence.
#[allow(clippy::too_many_arguments)]
pub fn sequence(
    cell: &Cell,
    robot: &Robot,
    graph: &RobotGraph,
    tasks: &[TaskId],
    settings: &PlanSettings,
    deadline: Instant,
    bar: f64,
    mut first: Option<Vec<usize>>,
    planned: &mut Planned,
) -> Result<Sequence, PlanError> {
    let mut tasks = tasks.to_vec();
    let mut dropped = Vec::new();
    let (mut legs_planned, mut legs_sampled, mut legs_failed, mut rounds) = (0, 0, 0, 0);
    let mut clock_cut = false;
    loop {
        let (mut seq, failed) = attempt(
            cell,
            robot,
            graph,
            &tasks,
            settings,
            deadline,
            bar,
            first.take(),
            planned,
        );
        legs_planned += seq.legs_planned;
        legs_sampled += seq.legs_sampled;
        legs_failed += seq.legs_failed;
        rounds += seq.rounds;
        clock_cut |= seq.clock_cut;
        match failed {
            None => {
                seq.legs_planned = legs_planned;
                seq.legs_sampled = legs_sampled;
                seq.legs_failed = legs_failed;
                seq.rounds = rounds;
                seq.clock_cut |= clock_cut;
                seq.dropped = dropped;
                return Ok(seq);
            }
            Some((a, b, e)) => {
                let t = hardest_task(graph, planned, a, b);
                tasks.retain(|&x| x != t);
                dropped.push((
                    t,
                    format!(
                        "no collision-free path from {} to {}: {e}",
                        stop_of(cell, graph, a),
                        stop_of(cell, graph, b)
                    ),
                ));
            }
        }
    }
}

/// Of the two ends of a leg without a path, the task to give up: the one whose candidates'
/// planned legs failed the most often (home is never given up).
fn hardest_task(graph: &RobotGraph, planned: &Planned, a: usize, b: usize) -> TaskId {
    let share = |n: usize| -> Option<(f64, TaskId)> {
        let (task, _) = graph.node_task[n]?;
        let nodes: Vec<usize> = (0..graph.len())
            .filter(|&m| graph.node_task[m].is_some_and(|(t, _)| t == task))
            .collect();
        let (mut failed, mut all) = (0usize, 0usize);
        for (&(x, y), leg) in planned {
            if nodes.contains(&x) || nodes.contains(&y) {
                all += 1;
                failed += usize::from(leg.is_err());
            }
        }
        Some((failed as f64 / all.max(1) as f64, task))
    };
    match (share(a), share(b)) {
        (Some(x), Some(y)) => {
            if x.0 > y.0 {
                x.1
            } else {
                y.1
            }
        }
        (Some(x), None) | (None, Some(x)) => x.1,
        (None, None) => unreachable!("a leg from home to home always has a path (it stands still)"),
    }
}

/// One run of the lazy loop on `tasks`; with the leg of the final order that still has no
/// path, if any (then the sequence's nodes and legs are empty).
#[allow(clippy::too_many_arguments)]
fn attempt(
    cell: &Cell,
    robot: &Robot,
    graph: &RobotGraph,
    tasks: &[TaskId],
    settings: &PlanSettings,
    deadline: Instant,
    bar: f64,
    mut first: Option<Vec<usize>>,
    planned: &mut Planned,
) -> (Sequence, Option<(usize, usize, LegError)>) {
    let mut out = Sequence::default();
    // The best order whose every leg is planned, with its real time.
    let mut best: Option<(f64, Vec<usize>)> = None;
    let mut nodes: Vec<usize>;
    // A plan the run can do without is given up at the deadline (see
    // [`PlanSettings::give_up_at_deadline`]): reported as beaten.
    let give_up = || settings.give_up_at_deadline && Instant::now() >= deadline;
    loop {
        if give_up() {
            out.beaten = true;
            return (out, None);
        }
        out.rounds += 1;
        nodes = match first.take() {
            Some(order) => order,
            None => best_order(
                graph,
                tasks,
                planned,
                order_seed(settings, robot),
                &super::order_rule(cell, settings),
            ),
        };
        let optimistic = order_cost(graph, planned, &nodes);
        if optimistic >= bar {
            out.beaten = true;
            return (out, None);
        }
        // No order can beat the best real one by more than the tolerance: stop.
        if let Some((b, order)) = &best
            && optimistic >= b * (1.0 - settings.lazy_tolerance)
        {
            nodes = order.clone();
            break;
        }
        let new: Vec<(usize, usize)> = legs_of(&nodes)
            .into_iter()
            .map(|(a, b)| key(a, b))
            .filter(|k| !planned.contains_key(k))
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        if new.is_empty() {
            // Its cost is real already, and the sequencer found nothing cheaper.
            if best.as_ref().is_none_or(|(b, _)| optimistic < *b) {
                best = Some((optimistic, nodes.clone()));
            }
            nodes = best.as_ref().map(|b| b.1.clone()).unwrap_or_default();
            break;
        }
        let reach = Reach::of(graph, planned, settings.final_max_samples);
        let results: Vec<((usize, usize), Result<Leg, LegError>)> = new
            .par_iter()
            .map(|&(a, b)| {
                (
                    (a, b),
                    reach.leg(cell, robot, graph, planned, a, b, settings, false),
                )
            })
            .collect();
        for (k, r) in results {
            match &r {
                Ok(leg) => {
                    out.legs_planned += 1;
                    out.legs_sampled += usize::from(!leg.straight);
                }
                Err(_) => out.legs_failed += 1,
            }
            planned.insert(k, r);
        }
        let real = order_cost(graph, planned, &nodes);
        if best.as_ref().is_none_or(|(b, _)| real < *b) {
            best = Some((real, nodes.clone()));
        }
        // While the best planned order still needs a leg the quick planner gave up on, more
        // rounds (each a GTSP and a few legs) are cheaper than the full-budget retry below.
        let stuck = best.as_ref().is_some_and(|(b, _)| *b >= NO_PATH);
        let rounds = if stuck {
            STUCK_ROUNDS_FACTOR * settings.lazy_rounds
        } else {
            settings.lazy_rounds
        };
        if out.rounds >= rounds || Instant::now() >= deadline {
            out.clock_cut = out.rounds < rounds;
            nodes = best.as_ref().map(|b| b.1.clone()).unwrap_or_default();
            break;
        }
    }
    // Legs of the final order the quick planner gave up on get the full search budget — once:
    // a leg that failed with it (in this run or an earlier one sharing `planned`) would fail
    // the same way again (the sampler's seed is the leg's), and invalid ends stay invalid.
    //
    // They go in phases, each made after the last one's results are in: a phase takes, for
    // each end outside home's component, one leg that joins it to that component, so that an
    // end one search did not reach is cut off (see [`Reach`]) before more searches are spent
    // on it; legs between two such ends wait until no other leg is left.
    let mut retry: std::collections::BTreeSet<(usize, usize)> = legs_of(&nodes)
        .into_iter()
        .map(|(a, b)| key(a, b))
        .filter(|k| worth_full_budget(planned.get(k), settings.final_max_samples))
        .collect();
    let full = PlanSettings {
        motion: MotionSettings {
            max_samples: settings.final_max_samples,
            ..settings.motion.clone()
        },
        ..settings.clone()
    };
    while !retry.is_empty() {
        if give_up() {
            out.beaten = true;
            return (out, None);
        }
        let reach = Reach::of(graph, planned, settings.final_max_samples);
        let mut taken = std::collections::BTreeSet::new();
        let mut phase: Vec<(usize, usize)> = Vec::new();
        for &(a, b) in &retry {
            let outside: Vec<usize> = [a, b].into_iter().filter(|&n| !reach.joined(n, 0)).collect();
            let ready = reach.is_cut_off(a)
                || reach.is_cut_off(b)
                || match outside[..] {
                    [] => true,
                    [n] => taken.insert(n),
                    _ => false,
                };
            if ready {
                phase.push((a, b));
            }
        }
        if phase.is_empty() {
            phase = retry.iter().copied().collect();
        }
        let retried: Vec<((usize, usize), Result<Leg, LegError>)> = phase
            .par_iter()
            .map(|&(a, b)| ((a, b), reach.leg(cell, robot, graph, planned, a, b, &full, true)))
            .collect();
        for (k, r) in retried {
            if r.is_ok() {
                out.legs_failed -= 1;
                out.legs_planned += 1;
                out.legs_sampled += 1;
            }
            retry.remove(&k);
            planned.insert(k, r);
        }
    }
    let mut legs = Vec::new();
    for (a, b) in legs_of(&nodes) {
        let leg = match planned.get(&key(a, b)) {
            Some(Ok(leg)) => leg.clone(),
            Some(Err(e)) => return (out, Some((a, b, e.clone()))),
            None => unreachable!("every leg of the final order is planned"),
        };
        legs.push(if (a, b) == key(a, b) { leg } else { reversed(leg) });
    }
    out.nodes = nodes;
    out.legs = legs;
    (out, None)
}

/// Whether a leg planned as `planned` says is worth the full sample budget `full`: the sampler
/// gave up on it with fewer samples than that (not an invalid end, not a full-budget failure).
fn worth_full_budget(planned: Option<&Result<Leg, LegError>>, full: usize) -> bool {
    matches!(
        planned,
        Some(Err(LegError::Motion(cellplan_motion::plan::PlanError::NoPath { samples, .. })))
            if *samples < full
    )
}

/// Give the sampled legs of a final sequence the full shortcutting (the lazy rounds used a few
/// iterations per leg, enough to rank orders); a leg is replaced only when it gets faster.
pub fn polish(cell: &Cell, robot: &Robot, graph: &RobotGraph, seq: &mut Sequence, settings: &PlanSettings) {
    let mut prev = 0usize;
    let ends: Vec<(usize, usize)> = seq
        .nodes
        .iter()
        .chain(std::iter::once(&0))
        .map(|&n| {
            let e = (prev, n);
            prev = n;
            e
        })
        .collect();
    let polished: Vec<Option<Leg>> = seq
        .legs
        .par_iter()
        .zip(&ends)
        .map(|(leg, &(a, b))| {
            (!leg.straight).then(|| polish_leg(cell, robot, graph, &key(a, b), leg.clone(), settings))
        })
        .collect();
    for (leg, p) in seq.legs.iter_mut().zip(polished) {
        if let Some(p) = p {
            *leg = p;
        }
    }
}

/// The unordered key of a leg between nodes `a` and `b`.
pub fn key(a: usize, b: usize) -> (usize, usize) {
    (a.min(b), a.max(b))
}

fn reversed(mut leg: Leg) -> Leg {
    leg.waypoints.reverse();
    leg
}

fn legs_of(nodes: &[usize]) -> Vec<(usize, usize)> {
    let mut out = Vec::with_capacity(nodes.len() + 1);
    let mut prev = 0;
    for &n in nodes {
        out.push((prev, n));
        prev = n;
    }
    out.push((prev, 0));
    out
}

/// Where `node` stands: home, or its task.
pub fn stop_of(cell: &Cell, graph: &RobotGraph, node: usize) -> super::Stop {
    match graph.node_task[node] {
        None => super::Stop::Home,
        Some((t, _)) => super::Stop::Task(cell.tasks[t.0].name.clone()),
    }
}

/// Time of an order under the current costs (planned legs real, the others their bound).
pub fn order_cost(graph: &RobotGraph, planned: &Planned, nodes: &[usize]) -> f64 {
    legs_of(nodes)
        .into_iter()
        .map(|(a, b)| match planned.get(&key(a, b)) {
            Some(Ok(leg)) => leg.duration,
            Some(Err(_)) => NO_PATH,
            None => graph.costs.get(a, b),
        })
        .sum::<f64>()
        + nodes.iter().map(|&n| graph.dwell[n]).sum::<f64>()
}

/// The seed of `robot`'s sequencing GTSPs.
pub fn order_seed(settings: &PlanSettings, robot: &Robot) -> u64 {
    settings.seed ^ robot.id.0 as u64
}

/// Shortcut a sampled leg with the full iteration count; keep it if it is faster.
fn polish_leg(
    cell: &Cell,
    robot: &Robot,
    graph: &RobotGraph,
    k: &(usize, usize),
    mut leg: Leg,
    settings: &PlanSettings,
) -> Leg {
    let seed = leg_seed(settings.seed, robot.id.0, k.0, k.1) ^ 1;
    if let Ok((waypoints, duration)) =
        shortcut_and_time(cell, robot, graph, leg.waypoints.clone(), seed, settings)
        && duration < leg.duration
    {
        leg.duration = duration;
        leg.waypoints = waypoints;
    }
    leg
}

/// `waypoints` shortcut with the full iteration count (seeded by `seed`, every change checked
/// at the process clearance, each change kept only when it shortens the time stopping at every
/// waypoint) and timed under the robot's limits: the path and its time.
fn shortcut_and_time(
    cell: &Cell,
    robot: &Robot,
    graph: &RobotGraph,
    mut waypoints: Vec<Vec<f64>>,
    seed: u64,
    settings: &PlanSettings,
) -> Result<(Vec<Vec<f64>>, f64), LegError> {
    let space = crate::motion::joint_space(cell, robot);
    let validity = crate::motion::robot_validity(cell, robot, cell.planning.clearance);
    let motion = MotionSettings {
        seed,
        shortcut_iterations: settings.final_shortcut_iterations,
        ..settings.motion.clone()
    };
    cellplan_motion::plan::shortcut_timed(&space, &validity, &mut waypoints, &motion, &graph.limits);
    let duration = time_path_exact(&waypoints, &graph.limits)?.trajectory.duration();
    Ok((waypoints, duration))
}

/// The leg from node `a` to node `b` as the motion planner gives it (the robot's roadmap and
/// retracts included, see [`crate::motion::plan_leg_with_margin`]), timed; from the graph's
/// [`LegMemo`] when it was asked before with the same settings.
fn plan_leg(
    cell: &Cell,
    robot: &Robot,
    graph: &RobotGraph,
    a: usize,
    b: usize,
    settings: &PlanSettings,
) -> Result<Leg, LegError> {
    let asked = (settings.seed, settings.roadmap, settings.motion.clone());
    if let Some(found) = graph.legs.get(a, b, &asked) {
        return found;
    }
    let afresh = || -> Result<Leg, LegError> {
        let started = Instant::now();
        let motion = MotionSettings {
            seed: leg_seed(settings.seed, robot.id.0, a, b),
            ..settings.motion.clone()
        };
        let roadmap_seed = leg_seed(settings.seed, robot.id.0, usize::MAX, usize::MAX);
        let roadmap = || graph.roadmap(cell, robot, roadmap_seed);
        let path = crate::motion::plan_leg_with_margin(
            cell,
            robot,
            &graph.q[a],
            &graph.q[b],
            cell.planning.clearance,
            &motion,
            settings.roadmap.then_some(&roadmap as &dyn Fn() -> _),
        )?;
        let timed = time_path_exact(&path.waypoints, &graph.limits)?;
        Ok(Leg {
            waypoints: path.waypoints,
            duration: timed.trajectory.duration(),
            straight: path.straight,
            samples: path.samples,
            validity_calls: path.validity_calls,
            compute_s: started.elapsed().as_secs_f64(),
        })
    };
    let leg = afresh();
    graph.legs.put(a, b, asked, leg.clone());
    leg
}

/// The legs the motion planner gave between two nodes of one robot's graph, by the settings
/// it was asked with: a leg is a function of its robot, its two nodes (in that order) and
/// those settings alone, so a plan that asks again gets the same answer without planning it
/// — also a plan that does not share the other plan's [`Planned`] legs (the balanced
/// allocation of ours, planned as on its own: which legs a plan knows steers its lazy
/// sequencing, so each plan keeps its own `Planned`, and this memo below them).
#[derive(Debug, Default)]
pub struct LegMemo {
    legs: std::sync::Mutex<BTreeMap<(usize, usize), Vec<MemoLeg>>>,
    /// Legs given from the memo instead of planned.
    served: std::sync::atomic::AtomicUsize,
}

/// What a leg depends on beyond its robot and nodes: the plan's seed, whether the roadmap
/// is used, the motion settings.
type LegAsked = (u64, bool, MotionSettings);

/// A leg of the memo with what it was asked with.
type MemoLeg = (LegAsked, Result<Leg, LegError>);

impl LegMemo {
    fn get(&self, a: usize, b: usize, asked: &LegAsked) -> Option<Result<Leg, LegError>> {
        let legs = self
            .legs
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let leg = legs.get(&(a, b))?.iter().find(|(k, _)| k == asked)?.1.clone();
        self.served.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Some(leg)
    }

    /// How many legs the memo has given instead of their planning.
    pub fn served(&self) -> usize {
        self.served.load(std::sync::atomic::Ordering::Relaxed)
    }

    fn put(&self, a: usize, b: usize, asked: LegAsked, leg: Result<Leg, LegError>) {
        let mut legs = self
            .legs
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let known = legs.entry((a, b)).or_default();
        if !known.iter().any(|(k, _)| *k == asked) {
            known.push((asked, leg));
        }
    }
}

/// A seed per leg, so that a leg's path does not depend on which thread plans it or when.
fn leg_seed(seed: u64, robot: usize, a: usize, b: usize) -> u64 {
    let mut h = cellplan_model::hash::Fnv::default();
    for x in [seed, robot as u64, a as u64, b as u64] {
        std::hash::Hasher::write(&mut h, &x.to_le_bytes());
    }
    std::hash::Hasher::finish(&h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellplan_motion::plan::PlanError as Motion;

    /// A leg is retried with the full budget only after a quick failure: not after a failure
    /// with the full budget (it would fail the same way: the seed is the leg's), not when an
    /// end is invalid, not when it has a path or was never planned.
    #[test]
    fn only_quick_failures_get_the_full_budget() {
        let no_path = |samples| {
            Err(LegError::Motion(Motion::NoPath {
                samples,
                validity_calls: 10 * samples,
            }))
        };
        assert!(worth_full_budget(Some(&no_path(180)), 20_000));
        assert!(!worth_full_budget(Some(&no_path(20_000)), 20_000));
        assert!(!worth_full_budget(Some(&no_path(60_180)), 20_000));
        let invalid = Err(LegError::Motion(Motion::GoalInvalid { clearance: -0.01 }));
        assert!(!worth_full_budget(Some(&invalid), 20_000));
        assert!(!worth_full_budget(None, 20_000));
    }
}

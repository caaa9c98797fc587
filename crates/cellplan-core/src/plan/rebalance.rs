//! Balancing a plan on its real times: the allocations draw their lines on lower-bound move
//! times, but a robot's legs can be much slower than their bounds (detours around the part,
//! stops at every corner), so the robot that ends last is often not the one the allocation
//! expected. [`rebalance`] hands one task at a time from the robot that ends last to the robot
//! that can take it at the least cost, plans the robots again with that allocation (the legs
//! already planned are reused: see [`super::PlanCache`]; a robot whose tasks did not change
//! keeps its program unless the new one is shorter — and when that plan does not end sooner,
//! every robot is sequenced anew: other paths, which may meet less) and keeps the change when
//! the robots end sooner. Spensieri et al. (2016) iterate routing and scheduling the same way, one level
//! down. Where those hand-overs do not help and the last robot waits for another, a task of the
//! robot it waits for goes to a third one (a relief): the shared space is then held for less
//! time. Where neither helps, a group of the last robot's tasks goes to the robot it waits for
//! (`groups`): on a crowded cell one MP moved at a time changes the coordinated cycle
//! erratically, while a share of the space both reach, moved at once, can end the waiting.
//! Last come the reorders (`reorders`): the allocation kept, the task a robot waits on the way
//! to, or the one the robot it waits for is at, left to the end of its robot's tour
//! ([`PlanSettings::late`]): coordination delays a robot or runs its tour backwards, but cannot
//! move one visit of it past a neighbour's.
use super::{Outcome, PlanCache, PlanError, PlanSettings, dwell, plan_keeping};
use crate::candidates::CandidateTable;
use cellplan_model::Cell;
use cellplan_model::tasks::TaskId;
use std::time::Instant;

/// Plans [`rebalance`] makes at most (work, not time: the result does not depend on the
/// machine).
pub const REBALANCE_PLANS: usize = 10;

/// A hand-over whose plan, the other robots' programs kept, coordinates to a cycle longer
/// than the one to beat by more than this share is not planned again with every robot
/// sequenced anew: the judge and the plan go to the next hand-over instead. Where coordination
/// adds that much, other paths of the same allocation did not win in the traces (hulls-6r:
/// 103.3 then 97.9 s against 71.5; door-opening-4r: 62.3 then 63.6 s against 43.3), and each
/// judge on the crowded cells costs seconds. Ten cells × seeds 0–2: mean ratio 1.395 → 1.392
/// (5 shorter, 4 longer, 21 the same); dense-8r-250 seed 0 106.9 → 100.2 s wall side by side
/// (`bench/cells/README.md`, forty-fifth session).
pub const FAR_WORSE: f64 = 0.05;

/// Plans [`rebalance`] hands its judge at most (a coordination each: the costly part).
pub const REBALANCE_JUDGED: usize = 5;

/// Plans [`rebalance`] makes at most for more direct hand-overs, once the reliefs and groups
/// have not helped either, on cells of at most [`MORE_HANDOVERS_MAX_PAIRS`] tasks × robots (a
/// budget of its own, after the others: the search up to there is the one without it, so its
/// plan is never longer before blending). On door-opening-4r the hand-over that balances the
/// two robots at the door is ranked beyond the fifth. Ten hard cells × seeds 0–2
/// (`bench/cells/README.md`, fiftieth session): mean ratio 1.392 → 1.371; door-opening-4r
/// 1.609 / 1.865 / 1.954 → 1.494 / 1.860 / 1.737. (Made before the reliefs and groups instead,
/// they lost those that had won: crowded-6r seed 2 1.495 → 1.641.)
pub const MORE_PLANS: usize = 20;

/// Of those, plans it hands its judge at most.
pub const MORE_JUDGED: usize = 10;

/// The cells (tasks × robots) on which [`rebalance`] makes the hand-overs of [`MORE_PLANS`]:
/// each judge is a coordination, seconds on the crowded 8-robot cells (dense-8r-250, 2,000:
/// 5.4 s each; ten more, made before the reliefs and groups, gained its seeds 0.00–0.06 in
/// ratio, its runs taking 181–227 s beside other work); dense-8r-120 (960) and the smaller ones make them.
pub const MORE_HANDOVERS_MAX_PAIRS: usize = 1_000;

/// Plans [`rebalance`] makes at most for hand-overs that lighten a robot the last one waits
/// for, once the direct hand-overs are spent (a budget of its own: see [`rebalance`]).
pub const RELIEF_PLANS: usize = 8;

/// Of those, plans it hands its judge at most.
pub const RELIEF_JUDGED: usize = 4;

/// A robot the last one waits for at least this long (s) in all is one a relief may lighten,
/// and one a group may go to.
const RELIEF_MIN_WAIT: f64 = 0.5;

/// Plans [`rebalance`] makes at most for group hand-overs (several tasks of the robot that
/// ends last to a robot it waits for, see `groups`), once the other two kinds are spent.
pub const GROUP_PLANS: usize = 4;

/// Of those, plans it hands its judge at most.
pub const GROUP_JUDGED: usize = 2;

/// Most tasks one group hand-over moves.
const GROUP_MAX: usize = 8;

/// Plans [`rebalance`] makes at most for reorders (a task a robot waits on the way to, or the
/// task the robot it waits for is at, left to the end of its robot's tour; see `reorders`),
/// once the other kinds are spent, on a budget of their own. Ten hard cells × seeds 0–2
/// (`bench/cells/README.md`, fifty-first session): mean ratio 1.371 → 1.359, 9 runs shorter,
/// none longer; crowded-6r seed 1 1.618 → 1.518.
pub const REORDER_PLANS: usize = 6;

/// Of those, plans it hands its judge at most.
pub const REORDER_JUDGED: usize = 4;

/// One hand-over: the tasks (one, or a group), from which robot, to which, and the ends it is
/// expected to give the two (s). A reorder's is from its robot to itself: the tasks left to the
/// end of its tour ([`PlanSettings::late`]).
#[derive(Clone, Debug, PartialEq)]
struct Move {
    tasks: Vec<TaskId>,
    from: usize,
    to: usize,
    expected: f64,
}

/// What a judge says of a plan: its score (s; a cycle, never below the robots' latest end
/// without coordination), each robot's end under it (s), and what it made.
pub type Judged<J> = (f64, Vec<f64>, J);

/// What [`rebalance`] asks of its judge: a plan, and the hand-over plan it was made from with
/// what the judge made of that (`None`: made from the base).
pub type Judge<'a, J> = dyn FnMut(&Outcome, Option<(&Outcome, &J)>) -> Option<Judged<J>> + 'a;

/// What [`rebalance`] asks its caller's budget of work before a plan (`may_judge`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ask {
    /// A direct hand-over's plan: within the budget. Refused, only the reorders are left.
    Within,
    /// A relief's or a group's plan, or a reorder's on a cell larger than
    /// [`MORE_HANDOVERS_MAX_PAIRS`] tasks × robots: the budget may allow it beyond itself.
    /// Refused, the search ends.
    Beyond,
    /// A reorder's plan on a smaller cell: its own budget ([`REORDER_JUDGED`]) bounds it, and
    /// the caller may still refuse (where even one coordination is too costly). Refused, the
    /// search ends.
    Reorder,
}

/// A robot's stop in a judged plan: robot `robot` waits `seconds` on its way to `heading`
/// (`None`: home) for robot `for_robot`, which is at `blocker` when the wait ends or on its
/// way there (`None`: home).
#[derive(Clone, Debug, PartialEq)]
pub struct Stall {
    /// The robot that waits.
    pub robot: usize,
    /// The task it is on its way to.
    pub heading: Option<TaskId>,
    /// How long (s).
    pub seconds: f64,
    /// The robot it waits for.
    pub for_robot: usize,
    /// Where that robot is (or is going) when the wait ends.
    pub blocker: Option<TaskId>,
}

/// The waits of a judged plan: `totals[r][s]`, the seconds robot `r` waits for robot `s` in
/// all, and each wait that names the robot it waits for.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Waits {
    /// `totals[r][s]`: seconds robot `r` waits for robot `s`.
    pub totals: Vec<Vec<f64>>,
    /// The waits one by one.
    pub stalls: Vec<Stall>,
}

/// What [`rebalance`] reads off what its judge made of a plan (see `coord::Coordinated::waits`).
pub type WaitsOf<'a, J> = dyn Fn(&J) -> Waits + 'a;

/// A rebalanced plan: the plan, the settings it was made with (its fixed allocation) and what
/// the judge made of it.
pub type Rebalanced<J> = (Outcome, PlanSettings, J);

/// When each robot of `o` ends without coordination (s).
pub fn ends(o: &Outcome) -> Vec<f64> {
    o.robots.iter().map(|r| r.program.duration()).collect()
}

/// Whether every robot of `a` and `b` has the same program (the same poses, paths and times).
fn same_programs(a: &Outcome, b: &Outcome) -> bool {
    a.robots.len() == b.robots.len()
        && a.robots
            .iter()
            .zip(&b.robots)
            .all(|(x, y)| x.program == y.program)
}

/// The latest of [`ends`].
pub fn makespan(o: &Outcome) -> f64 {
    ends(o).into_iter().fold(0.0, f64::max)
}

/// The robot that ends last by `end` (the higher index on a tie: as the moves have always
/// taken it).
fn last(end: &[f64]) -> Option<usize> {
    (0..end.len()).max_by(|&a, &b| end[a].total_cmp(&end[b]).then(b.cmp(&a)))
}

/// A task handed from robot `from` to any robot but `from` and `skip`: expected to end at
/// `floor` or at the receiving robot's end plus the task's addition, whichever is later, and
/// offered when that is below `bar`.
struct Hand {
    task: TaskId,
    from: usize,
    skip: Option<usize>,
    floor: f64,
    bar: f64,
}

/// What hand-overs are ranked on: each robot's tour as graph nodes (home at both ends) and its
/// slowness (its legs' time over their bounds, at least 1).
struct Tours {
    nodes: Vec<Vec<usize>>,
    slowness: Vec<f64>,
}

impl Tours {
    fn new(o: &Outcome) -> Tours {
        let nodes: Vec<Vec<usize>> = o
            .robots
            .iter()
            .map(|r| {
                let mut t = vec![0];
                t.extend(&r.sequence.nodes);
                t.push(0);
                t
            })
            .collect();
        let slowness = (0..o.robots.len())
            .map(|r| {
                let g = &o.graphs[r];
                let bound: f64 = nodes[r].windows(2).map(|w| g.costs.get(w[0], w[1])).sum();
                let real = o.robots[r].program.motion();
                if bound > 1e-9 {
                    (real / bound).max(1.0)
                } else {
                    1.0
                }
            })
            .collect();
        Tours { nodes, slowness }
    }

    /// Each task of robot `from` with the time its removal is expected to save: its two legs
    /// and dwell, less the bound of the leg that replaces them times the robot's slowness.
    fn removals(&self, cell: &Cell, o: &Outcome, from: usize) -> Vec<(TaskId, f64)> {
        let g = &o.graphs[from];
        let legs = &o.robots[from].sequence.legs;
        self.nodes[from]
            .windows(3)
            .enumerate()
            .filter_map(|(i, w)| {
                let (task, _) = g.node_task[w[1]]?;
                let saved = legs[i].duration + legs[i + 1].duration + dwell(cell, task)
                    - self.slowness[from] * g.costs.get(w[0], w[2]);
                Some((task, saved))
            })
            .collect()
    }

    /// What robot `to` is expected to take longer with `task` added: the dwell plus its
    /// cheapest insertion (on bounds) times the robot's slowness; `None` when it cannot do the
    /// task or has no room under the cap.
    fn addition(&self, cell: &Cell, o: &Outcome, to: usize, task: TaskId) -> Option<f64> {
        let h = &o.graphs[to];
        let nodes = &h.alternatives[task.0];
        if nodes.is_empty() || o.robots[to].sequence.nodes.len() >= cell.planning.task_cap {
            return None;
        }
        let insertion = self.nodes[to]
            .windows(2)
            .flat_map(|p| {
                nodes
                    .iter()
                    .map(move |&n| h.costs.get(p[0], n) + h.costs.get(n, p[1]) - h.costs.get(p[0], p[1]))
            })
            .fold(f64::INFINITY, f64::min);
        Some(dwell(cell, task) + self.slowness[to] * insertion)
    }

    /// Each robot that can take `hand`'s task (its end in `ends`), as a [`Move`] into `out`
    /// when it is expected to end below the bar.
    fn offer(&self, cell: &Cell, o: &Outcome, hand: Hand, ends: &[f64], out: &mut Vec<Move>) {
        for (to, &to_end) in ends.iter().enumerate() {
            if to == hand.from || Some(to) == hand.skip {
                continue;
            }
            let Some(added) = self.addition(cell, o, to, hand.task) else {
                continue;
            };
            let expected = hand.floor.max(to_end + added);
            if expected < hand.bar {
                out.push(Move {
                    tasks: vec![hand.task],
                    from: hand.from,
                    to,
                    expected,
                });
            }
        }
    }
}

/// Best expected first, then by task and receiving robot.
fn ranked(mut out: Vec<Move>) -> Vec<Move> {
    out.sort_by(|a, b| {
        a.expected
            .total_cmp(&b.expected)
            .then(a.tasks.cmp(&b.tasks))
            .then(a.to.cmp(&b.to))
    });
    out
}

/// The hand-overs from the robot of `o` that ends last by `end` (each robot's end as judged:
/// coordinated, waits included), best expected first: each of its tasks
/// to each other robot able to do it with room under the cap. A robot's real legs are slower
/// than their bounds by its own factor (its legs' time over their bounds), so the task's
/// removal saves its two legs and dwell, less the bound of the leg that replaces them times the
/// factor, and its cheapest insertion (on bounds) into the other robot's tour costs the dwell
/// plus the insertion times that robot's factor. Only hand-overs expected to end both robots
/// sooner than the last one ends now are returned.
fn moves(cell: &Cell, o: &Outcome, end: &[f64]) -> Vec<Move> {
    let free = ends(o);
    let Some(from) = last(end) else {
        return Vec::new();
    };
    let tours = Tours::new(o);
    let mut out = Vec::new();
    for (task, saved) in tours.removals(cell, o, from) {
        let hand = Hand {
            task,
            from,
            skip: None,
            floor: free[from] - saved,
            bar: end[from] - 1e-6,
        };
        tours.offer(cell, o, hand, &free, &mut out);
    }
    ranked(out)
}

/// The robot that ends last by `end` and the seconds it waits for each robot (`waits[r][s]`:
/// robot `r` for robot `s`, as judged).
fn waiting<'a>(end: &[f64], waits: &'a [Vec<f64>]) -> Option<(usize, &'a [f64])> {
    let stuck = last(end)?;
    Some((stuck, waits.get(stuck)?))
}

/// The reliefs of `o` (Spensieri et al.'s loop one step further): where the robot that ends
/// last by `end` waits, in all, at least [`RELIEF_MIN_WAIT`] for another (`waits[r][s]`: the
/// seconds robot `r` waits for robot `s`, as judged), a task of the robot it waits for handed to
/// a third robot. The waited-for robot's path then holds the shared space for less time: the
/// last robot is expected to end sooner by what the task saved its holder, up to what it
/// waited for it, and the third robot to end (as judged) later by the task's addition. Ranked
/// as [`moves`]; only reliefs expected to end sooner than the last robot ends now.
fn reliefs(cell: &Cell, o: &Outcome, end: &[f64], waits: &[Vec<f64>]) -> Vec<Move> {
    let Some((stuck, waited)) = waiting(end, waits) else {
        return Vec::new();
    };
    let tours = Tours::new(o);
    let mut out = Vec::new();
    for (from, &wait) in waited.iter().enumerate() {
        if from == stuck || from >= end.len() || wait < RELIEF_MIN_WAIT {
            continue;
        }
        for (task, saved) in tours.removals(cell, o, from) {
            let hand = Hand {
                task,
                from,
                skip: Some(stuck),
                floor: end[stuck] - saved.clamp(0.0, wait),
                bar: end[stuck] - 1e-6,
            };
            tours.offer(cell, o, hand, end, &mut out);
        }
    }
    ranked(out)
}

/// The group hand-overs of `o` (where single tasks do not help, a robot that waits for a
/// neighbour often needs a whole share of the space they both reach moved, not one MP of it):
/// for each robot that the robot ending last by `end` waits for at least [`RELIEF_MIN_WAIT`]
/// in all (`waits` as in [`reliefs`]), the last robot's tasks that robot can take, those that
/// add least to the receiver first (dwell and cheapest insertion, as in [`moves`]: the tasks nearest
/// the receiver's tour, in the space the two share), handed over as the first 2, 3, …
/// [`GROUP_MAX`] of them (within the receiver's room under the cap). Ranking them by what
/// they add less what they save the giver, instead, picks the giver's cheap tasks wherever
/// they are (door-opening-4r, seed 0: 41.88 s with those, 34.90 s with these). The last robot
/// is expected to end sooner by what the tasks save it and by its wait, the receiver later (as
/// judged) by what they add; ranked as [`moves`], only groups expected to end sooner than the
/// last robot ends now.
fn groups(cell: &Cell, o: &Outcome, end: &[f64], waits: &[Vec<f64>]) -> Vec<Move> {
    let Some((stuck, waited)) = waiting(end, waits) else {
        return Vec::new();
    };
    let tours = Tours::new(o);
    let removals = tours.removals(cell, o, stuck);
    let mut out = Vec::new();
    for (to, &wait) in waited.iter().enumerate() {
        if to == stuck || to >= end.len() || wait < RELIEF_MIN_WAIT {
            continue;
        }
        let mut movable: Vec<(f64, TaskId, f64)> = removals
            .iter()
            .filter_map(|&(task, saved)| Some((tours.addition(cell, o, to, task)?, task, saved)))
            .collect();
        movable.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let room = cell
            .planning
            .task_cap
            .saturating_sub(o.robots[to].sequence.nodes.len());
        let (mut saved, mut added) = (0.0, 0.0);
        let mut tasks = Vec::new();
        for &(a, task, s) in movable.iter().take(room.min(GROUP_MAX)) {
            tasks.push(task);
            saved += s;
            added += a;
            if tasks.len() < 2 {
                continue;
            }
            let expected = (end[stuck] - saved.max(0.0) - wait).max(end[to] + added);
            if expected < end[stuck] - 1e-6 {
                out.push(Move {
                    tasks: tasks.clone(),
                    from: stuck,
                    to,
                    expected,
                });
            }
        }
    }
    ranked(out)
}

/// The reorders of `o`: where a robot waits at least [`RELIEF_MIN_WAIT`] for another
/// (`stalls`, as judged), the task it waits on the way to left to the end of its tour (the
/// other robot has gone by then), and the task the other robot is at left to the end of that
/// robot's (the waiting robot passes first); coordination can only delay a robot or run its
/// tour the other way, not move one visit of it. Ranked by how far below the latest end (by
/// `end`) the waiting robot would end without the wait (for the robot that ends last, the wait
/// itself): on crowded-6r, seed 1, a 14 s wait of a robot ending 0.6 s before the last one
/// comes before the last one's 5 s; the longest wait alone would put a robot that ends early
/// first. A task already late (in `late`) is not moved again. (Coordination may still run
/// the new tour backwards: the task then comes first, which the judge weighs the same way.)
fn reorders(o: &Outcome, end: &[f64], stalls: &[Stall], late: &[TaskId]) -> Vec<Move> {
    let latest = end.iter().copied().fold(0.0, f64::max);
    let gain = |s: &Stall| s.seconds - (latest - end.get(s.robot).copied().unwrap_or(0.0));
    let mut waits: Vec<&Stall> = stalls
        .iter()
        .filter(|s| s.for_robot != s.robot && s.robot < end.len() && s.seconds >= RELIEF_MIN_WAIT)
        .collect();
    waits.sort_by(|a, b| gain(b).total_cmp(&gain(a)).then(a.robot.cmp(&b.robot)));
    let mut out: Vec<Move> = Vec::new();
    for s in waits {
        for (robot, task) in [(s.robot, s.heading), (s.for_robot, s.blocker)] {
            let Some(task) = task else { continue };
            let holds = o.allocated.tasks.get(robot).is_some_and(|t| t.contains(&task));
            let again = out.iter().any(|m| m.from == robot && m.tasks == [task]);
            if holds && !late.contains(&task) && !again {
                out.push(Move {
                    tasks: vec![task],
                    from: robot,
                    to: robot,
                    expected: latest - gain(s).max(0.0),
                });
            }
        }
    }
    out
}

/// `base` (planned with `settings`; `judge` said `base_score` and `base_ends` of it) balanced
/// on its real times. Up to [`REBALANCE_PLANS`] times, the best expected hand-over not tried
/// yet (one task of the robot that ends last as judged to another robot, ranked by the ends it
/// is expected to give the two) is planned with the allocation fixed ([`PlanSettings::tasks`]),
/// first with the other robots keeping their programs ([`plan_keeping`]), then, when the judge
/// does not take that plan, with every robot sequenced anew (each counts as a plan; a plan the
/// same as the one before is not judged again).
/// A plan whose robots end, without coordination, sooner than the best score (the judge's
/// score is never below that end) goes to `judge`, with the hand-over plan it was made from
/// and what the judge made of that (`None`: made from `base`) — at most [`REBALANCE_JUDGED`]
/// plans — while `may_judge` says yes before each plan (the caller's budget of work, asked
/// with an [`Ask`]: [`Ask::Within`] before a hand-over's plans, [`Ask::Beyond`] before a
/// relief's or a group's, which it may allow beyond; `Within` refused leaves only the
/// reorders, another refused ends the search);
/// the first it scores below the best is kept and the next hand-overs start from it and its ends.
/// When a round's hand-overs are spent (or their budget is) without help, its reliefs are
/// tried the same way on a budget of their own ([`RELIEF_PLANS`], [`RELIEF_JUDGED`]): they need
/// the judged waits, `base_waits` for `base` and `waits_of` for what the judge made of a plan
/// ([`Waits`]; none given, no relief). After them the round's group hand-overs (`groups`), on
/// a budget of their own too ([`GROUP_PLANS`], [`GROUP_JUDGED`]; asked as a relief). Then, on
/// cells of at most [`MORE_HANDOVERS_MAX_PAIRS`] tasks × robots, more direct hand-overs on a
/// budget of their own ([`MORE_PLANS`], [`MORE_JUDGED`]; asked `Within`). Last the reorders
/// (`reorders`, from the judged [`Waits::stalls`]: the allocation kept, a task left to the end
/// of its robot's tour, the other robots keeping their programs) on a budget of their own
/// ([`REORDER_PLANS`], [`REORDER_JUDGED`]), asked [`Ask::Reorder`] on cells of at most
/// [`MORE_HANDOVERS_MAX_PAIRS`] tasks × robots and `Beyond` on larger ones. A relief, a group,
/// one of the more hand-overs or a reorder taken starts a new round, its hand-overs first
/// while their budget lasts; the late tasks of the plan kept stay late in the plans made from
/// it, but for a task handed to another robot.
/// Returns the best plan found with its settings and what the judge made of it, or `None` when
/// no hand-over beat `base_score`, and whether the deadline stopped the search with hand-overs
/// left to try (the plan then depends on the machine's speed). Plans that fail only lose their
/// try. The tasks `base` gave up (its [`Outcome::unreached`]) are in no robot's allocation, so
/// no hand-over gives them to one: they stay given up, with their reasons, in every plan made
/// here; a plan that gives up more is not judged.
pub fn rebalance<J>(
    cell: &Cell,
    table: &CandidateTable,
    (base, base_score, base_ends, base_waits): (&Outcome, f64, &[f64], &Waits),
    settings: &PlanSettings,
    cache: &mut PlanCache,
    may_judge: &dyn Fn(Ask) -> bool,
    (judge, waits_of): (&mut Judge<'_, J>, &WaitsOf<'_, J>),
) -> Result<(Option<Rebalanced<J>>, bool), PlanError> {
    if cell.robots.len() < 2 {
        return Ok((None, false));
    }
    let mut best: Option<Rebalanced<J>> = None;
    let (mut score, mut judged_ends) = (base_score, base_ends.to_vec());
    let mut waits = base_waits.clone();
    let mut tried: Vec<(Vec<Vec<TaskId>>, Vec<TaskId>)> =
        vec![(base.allocated.tasks.clone(), settings.late.clone())];
    // The direct hand-overs' budget, then the reliefs', then the groups', then more direct
    // hand-overs' on cells small enough (each its own).
    let small = cell.tasks.len() * cell.robots.len() <= MORE_HANDOVERS_MAX_PAIRS;
    let more = if small {
        Budget::new(MORE_PLANS, MORE_JUDGED)
    } else {
        Budget::new(0, 0)
    };
    let mut budgets = [
        (Kind::Direct, Budget::new(REBALANCE_PLANS, REBALANCE_JUDGED)),
        (Kind::Relief, Budget::new(RELIEF_PLANS, RELIEF_JUDGED)),
        (Kind::Group, Budget::new(GROUP_PLANS, GROUP_JUDGED)),
        (Kind::More, more),
        (Kind::Reorder, Budget::new(REORDER_PLANS, REORDER_JUDGED)),
    ];
    let mut refused = false;
    'rounds: loop {
        let current = best.as_ref().map_or(base, |b| &b.0);
        let from_tasks = current.allocated.tasks.clone();
        let from_late = best.as_ref().map_or(&settings.late, |b| &b.1.late).clone();
        'phases: for (kind, budget) in budgets.iter_mut() {
            let (kind, reorder) = (*kind, *kind == Kind::Reorder);
            // Once the caller's budget has refused a hand-over, only the reorders are left.
            if budget.spent() || (refused && !reorder) {
                continue;
            }
            let list = match kind {
                Kind::Relief => reliefs(cell, current, &judged_ends, &waits.totals),
                Kind::Group => groups(cell, current, &judged_ends, &waits.totals),
                Kind::Reorder => reorders(current, &judged_ends, &waits.stalls, &from_late),
                Kind::Direct | Kind::More => moves(cell, current, &judged_ends),
            };
            // A relief, a group or a reorder may go beyond the caller's budget (see [`Ask`]);
            // a direct hand-over, first or more, may not.
            let ask = match kind {
                Kind::Relief | Kind::Group => Ask::Beyond,
                Kind::Reorder if small => Ask::Reorder,
                Kind::Reorder => Ask::Beyond,
                Kind::Direct | Kind::More => Ask::Within,
            };
            for mv in list {
                if budget.spent() {
                    break;
                }
                if settings.deadline.is_some_and(|d| Instant::now() >= d) {
                    return Ok((best, true));
                }
                let mut tasks = from_tasks.clone();
                let mut late = from_late.clone();
                if reorder {
                    late.extend(&mv.tasks);
                } else {
                    tasks[mv.from].retain(|t| !mv.tasks.contains(t));
                    tasks[mv.to].extend(&mv.tasks);
                    late.retain(|t| !mv.tasks.contains(t));
                }
                let key = (tasks, late);
                if tried.contains(&key) {
                    continue;
                }
                tried.push(key.clone());
                let (tasks, late) = key;
                // A hand-over the run can do without: given up at the deadline.
                let next = PlanSettings {
                    tasks: Some(tasks),
                    late,
                    give_up_at_deadline: true,
                    ..settings.clone()
                };
                // First the robots whose tasks did not change keep their programs unless the
                // new ones are shorter (and so, mostly, the diagrams of their pairs); when that
                // does not help, every robot is sequenced again: other paths, which may meet
                // less. A reorder is made the first way only: it is one robot's new order.
                let mut kept: Option<Outcome> = None;
                for keep in [true, false] {
                    if reorder && !keep {
                        break;
                    }
                    if !may_judge(ask) {
                        if ask != Ask::Within {
                            break 'rounds;
                        }
                        refused = true;
                        continue 'phases;
                    }
                    if budget.spent() {
                        break;
                    }
                    budget.plans += 1;
                    let prior = if keep { Some(current) } else { None };
                    let mut o = match plan_keeping(cell, table, &next, &|_| {}, cache, prior) {
                        Ok(o) => o,
                        // Given up at the deadline: the clock ends the hand-overs.
                        Err(PlanError::TimeLimit) => return Ok((best, true)),
                        Err(_) => continue,
                    };
                    // The judge's score is never below the robots' latest end without
                    // coordination; a plan the same as the one just judged is not judged again.
                    let same = kept.as_ref().is_some_and(|k| same_programs(k, &o));
                    if same || !o.unreached.is_empty() || makespan(&o) >= score - 1e-6 {
                        continue;
                    }
                    o.unreached.clone_from(&base.unreached);
                    budget.judged += 1;
                    let judged = judge(&o, best.as_ref().map(|b| (&b.0, &b.2)));
                    // Far worse with the programs kept: not sequenced anew (see FAR_WORSE).
                    let far_worse = keep
                        && judged
                            .as_ref()
                            .is_some_and(|(sc, _, _)| *sc > score * (1.0 + FAR_WORSE));
                    if let Some((sc, e, j)) = judged
                        && sc < score - 1e-6
                    {
                        (score, judged_ends, waits) = (sc, e, waits_of(&j));
                        // The winner's settings are those it would be planned with again.
                        best = Some((
                            o,
                            PlanSettings {
                                give_up_at_deadline: false,
                                ..next
                            },
                            j,
                        ));
                        continue 'rounds;
                    }
                    if far_worse {
                        break;
                    }
                    kept = Some(o);
                }
            }
        }
        // No hand-over of the robot ending last, no relief of one it waits for, and no group
        // to one, helped.
        break;
    }
    Ok((best, false))
}

/// The kinds of change [`rebalance`] tries, in this order, each on a budget of its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Tasks of the robot that ends last handed over one at a time (`moves`).
    Direct,
    /// A task of a robot the last one waits for to a third robot (`reliefs`).
    Relief,
    /// Several of the last robot's tasks to a robot it waits for (`groups`).
    Group,
    /// More direct hand-overs, on small cells ([`MORE_PLANS`]).
    More,
    /// A task left to the end of its robot's tour (`reorders`).
    Reorder,
}

/// Plans made and judged against their caps.
struct Budget {
    plans: usize,
    judged: usize,
    max_plans: usize,
    max_judged: usize,
}

impl Budget {
    fn new(max_plans: usize, max_judged: usize) -> Budget {
        Budget {
            plans: 0,
            judged: 0,
            max_plans,
            max_judged,
        }
    }

    fn spent(&self) -> bool {
        self.plans >= self.max_plans || self.judged >= self.max_judged
    }
}

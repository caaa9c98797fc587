//! Coordination as scheduling: the order in which two robots pass each of their conflict boxes
//! (see [`super::diagram`]), chosen so that the last robot home is home as early as possible.
//!
//! A robot follows its path unchanged and may stand still at its rests (waypoints, and home
//! before it starts). Let `X(r, k)` be when robot `r` leaves rest `k` (at position `p_k`): it
//! is at position `s ∈ [p_k, p_{k+1}]` at `X(r, k) + s − p_k`. Leaving rest `k + 1` no earlier
//! than arriving there is `X(r, k+1) ≥ X(r, k) + p_{k+1} − p_k`. Robot `a` passing box
//! `[a1, a2] × [b1, b2]` first means `a` is past `a2` before `b` reaches `b1`:
//! `X(b, j) + b1 − p_j ≥ X(a, i) + a2 − p_i` with `i` the last rest at or before `a2` and `j`
//! the last rest before `b1` — a difference constraint. For chosen orders the earliest times
//! are longest paths, and the makespan `max_r X(r, last) + len_r − p_last` is their maximum.
//! A robot home for good (`a2` at the end of its path) can never pass first, nor can a robot
//! that conflicts while still at home (`b1 = 0`) pass second — unless the diagram certified
//! that the robot standing still there is clear of the other's whole interval
//! (`ConflictBox::open`); at such an end at a rest, arriving is enough to have passed, and
//! waiting there is allowed before entering.
//!
//! Branch and bound: the earliest times under the orders chosen so far are a lower bound of
//! every completion; a box that neither order satisfies at those times is branched on (the
//! earliest such box; the order with the earlier finish first, so the first dive is the greedy
//! schedule). Depth first until the first schedule, then limited discrepancy search (Harvey &
//! Ginsberg): rounds of dives that leave the greedy order at most 0, 1, 2, … times, pruned by
//! the best schedule so far — on a large diagram the greedy schedule's first orders are the
//! costly ones, and depth first would spend its budget on the last. Exact when a round cuts
//! nothing within the node budget; the best schedule found otherwise. Work is counted in
//! nodes, so the result does not depend on the machine.
//!
//! A box both of whose orders close a positive cycle with the orders chosen above is a dead
//! end. The search then jumps back to the deepest choice on those cycles (conflict-directed
//! backjumping, Prosser 1993), not to the last choice made: on a large diagram the choice to
//! blame is often hundreds of levels up, and backtracking one level at a time spent its whole
//! allowance below it (8 of the 15 searches of the 8 robots × 1,000 MPs cell: 200,000 nodes
//! and no schedule; with the jumps, every one finds one). Cycles through a lengthened wait
//! are not traced, and their dead ends backtrack one level as before. The search keeps a
//! schedule from a fixed priority of the robots too ([`Search::incumbent`]), so it has one
//! even when its own dives find none.
//!
//! When asked ([`schedule_with`], ours' polish of its winner), a search that ends unproven
//! spends one more budget putting each robot back through the others ([`Search::improve`], a
//! large neighbourhood search): the orders among the other robots are kept, the robot's own
//! are searched again, while a round over the robots shortens the schedule.
//!
//! Before it, every pair of robots that shares boxes is scheduled alone through its own boxes
//! ([`floor`]): any schedule of all the robots is one of each pair, so the longest of the
//! pairs' shortest schedules bounds every makespan from below, and a schedule that reaches it
//! is the shortest. Where the bound is the shortest schedule (on dense-8r-120's 2,479 boxes),
//! the search meets it long before its budget: the same schedule, proven, in under a third of
//! the nodes. Where it is not (dense-8r-250, 8 robots × 1,000 MPs) the pairs cost about a sixth
//! more nodes: 6 % of the search's time on dense-8r-250, 1.3 % on 8 × 1,000.
use super::diagram::ConflictBox;

mod improve;
mod incumbent;
mod parts;

use parts::floor;
pub(crate) use parts::infeasible_core;

/// A robot's path as the scheduler sees it.
#[derive(Clone, Debug)]
pub(crate) struct Track {
    /// The robot (cell index).
    pub robot: usize,
    /// Length (s of position).
    pub len: f64,
    /// Positions of its rests, increasing, the first 0 (home).
    pub rests: Vec<f64>,
}

/// Slack (s) in comparisons of times.
const EPS: f64 = 1e-9;

/// A schedule: per robot, the wait at each rest (s) and whom it waits for.
#[derive(Clone, Debug)]
pub(crate) struct Schedule {
    /// Per robot, per rest: (duration, the robot it waits for).
    pub waits: Vec<Vec<(f64, Option<usize>)>>,
    /// When the last robot is home (s).
    pub makespan: f64,
    /// Nodes of the search.
    pub nodes: usize,
    /// Boxes whose order the search had to choose.
    pub decisions: usize,
    /// Whether the search ended within its budget (the schedule is then the shortest).
    pub proven: bool,
}

/// A constraint `X[to] ≥ X[from] + w`.
#[derive(Clone, Copy, Debug)]
struct Edge {
    from: usize,
    to: usize,
    w: f64,
    /// For an order the search chose, its place in [`Search::chosen`]; else [`NO_TAG`].
    tag: u32,
}

/// The tag of an edge that is no choice of the search's.
const NO_TAG: u32 = u32::MAX;

/// A schedule the search holds: makespan, times, the orders chosen, and how many boxes were
/// still open when their order was chosen.
type Best = (f64, Vec<f64>, Vec<Edge>, usize);

/// The two ways of passing a box, as edges (`None`: that order is impossible).
#[derive(Clone, Copy, Debug)]
struct Choice {
    first_a: Option<Edge>,
    first_b: Option<Edge>,
}

struct Search<'a> {
    paths: &'a [Track],
    /// First node of each robot.
    offset: Vec<usize>,
    choices: Vec<Choice>,
    /// Per box, its robots (track indices) and where the first of them enters it.
    entry: Vec<(usize, usize, f64)>,
    /// Per node, the boxes one of whose orders starts there: times only rise, so a box one of
    /// whose orders holds can open again only where the time an order starts from rises.
    incident: Vec<Vec<u32>>,
    /// Per box, the mark of the last refresh that listed it (see [`Search::refresh`]).
    seen: Vec<u32>,
    /// The current refresh's mark.
    mark: u32,
    /// Nodes whose times the last [`Search::add`] or [`Search::lengthen`] raised.
    raised: Vec<usize>,
    /// Per node, how the last propagation raised it: the node it came from, the tag of the
    /// edge, and whether that edge is a lengthened wait (valid for the nodes it raised).
    pred: Vec<(u32, u32, bool)>,
    /// After a propagation that failed: the search's choices on the positive cycle it closed
    /// (tags), or `None` when the cycle runs through a lengthened wait (whose cause is not
    /// kept).
    cycle: Option<Vec<u32>>,
    /// Cross edges by source node (chain edges are implicit).
    out: Vec<Vec<Edge>>,
    /// Per node, the least wait there (0, or the shortest wait allowed once a wait is needed).
    hold: Vec<f64>,
    /// The shortest wait allowed (s).
    min_wait: f64,
    budget: usize,
    nodes: usize,
    /// The best schedule so far.
    best: Option<Best>,
    chosen: Vec<Edge>,
    /// Most discrepancies (second children taken) of a dive; `None`: depth first, all.
    discrepancies: Option<usize>,
    /// Whether a dive left a child out for the discrepancy limit.
    cut: bool,
    /// Stop at the first schedule of the search's own (the depth-first phase that precedes the
    /// discrepancy search).
    stop_at_first: bool,
    /// Whether the search has found a schedule of its own (not only the incumbent).
    found: bool,
    /// Whether the search jumps back over choices not to blame (see [`Search::dive`]).
    backjump: bool,

    /// A lower bound of every schedule's makespan (see [`floor`]): a schedule that reaches it
    /// is the shortest, and the search stops there.
    floor: f64,
}

/// Index of the last rest at or before `s` (`strict`: before).
fn rest_before(path: &Track, s: f64, strict: bool) -> usize {
    let n = if strict {
        path.rests.partition_point(|&r| r < s - EPS)
    } else {
        path.rests.partition_point(|&r| r <= s + EPS)
    };
    n.saturating_sub(1)
}

impl<'a> Search<'a> {
    fn new(paths: &'a [Track], boxes: &[ConflictBox], budget: usize, min_wait: f64) -> Self {
        let mut offset = Vec::with_capacity(paths.len());
        let mut n = 0;
        for p in paths {
            offset.push(n);
            n += p.rests.len();
        }
        let index: Vec<usize> = {
            let mut v = vec![usize::MAX; paths.iter().map(|p| p.robot + 1).max().unwrap_or(0)];
            for (i, p) in paths.iter().enumerate() {
                v[p.robot] = i;
            }
            v
        };
        // `x` passes `[x1, x2]` before `y` reaches `y1`. Where `x` may stand at `x2`
        // (`x_open`), arriving there is enough; where `y` may stand at `y1` (`y_open`), it may
        // wait there.
        let first = |x: usize,
                     (_, x2): (f64, f64),
                     x_open: bool,
                     y: usize,
                     (y1, _): (f64, f64),
                     y_open: bool|
         -> Option<Edge> {
            let (px, py) = (&paths[x], &paths[y]);
            if (x2 >= px.len - EPS && !x_open) || (y1 <= EPS && !y_open) {
                return None;
            }
            let i = rest_before(px, x2, x_open);
            let j = rest_before(py, y1, !y_open);
            Some(Edge {
                from: offset[x] + i,
                to: offset[y] + j,
                w: (x2 - px.rests[i]) - (y1 - py.rests[j]),
                tag: NO_TAG,
            })
        };
        let choices = boxes
            .iter()
            .map(|b| {
                let (a, c) = (index[b.robots.0], index[b.robots.1]);
                Choice {
                    first_a: first(a, b.a, b.open[1], c, b.b, b.open[2]),
                    first_b: first(c, b.b, b.open[3], a, b.a, b.open[0]),
                }
            })
            .collect::<Vec<Choice>>();
        let mut incident = vec![Vec::new(); n];
        for (i, c) in choices.iter().enumerate() {
            for e in [c.first_a, c.first_b].into_iter().flatten() {
                if incident[e.from].last() != Some(&(i as u32)) {
                    incident[e.from].push(i as u32);
                }
            }
        }
        let seen = vec![0; choices.len()];
        let entry = boxes
            .iter()
            .map(|b| (index[b.robots.0], index[b.robots.1], b.a.0.min(b.b.0)))
            .collect();
        Search {
            paths,
            offset,
            choices,
            entry,
            incident,
            seen,
            mark: 0,
            raised: Vec::new(),
            pred: vec![(0, NO_TAG, false); n],
            cycle: None,
            out: vec![Vec::new(); n],
            hold: vec![0.0; n],
            min_wait,
            budget,
            nodes: 0,
            best: None,
            chosen: Vec::new(),
            discrepancies: None,
            cut: false,
            stop_at_first: false,
            found: false,
            backjump: true,
            floor: f64::NEG_INFINITY,
        }
    }

    /// Whether the best schedule so far reaches the floor (no schedule is shorter).
    fn at_floor(&self) -> bool {
        self.best.as_ref().is_some_and(|b| b.0 <= self.floor + EPS)
    }

    fn robot_of(&self, node: usize) -> usize {
        self.offset.partition_point(|&o| o <= node) - 1
    }

    /// Earliest times with only the chain constraints.
    fn initial(&self) -> Vec<f64> {
        let mut x = Vec::new();
        for p in self.paths {
            x.extend(p.rests.iter().copied());
        }
        x
    }

    fn makespan(&self, x: &[f64]) -> f64 {
        self.paths
            .iter()
            .enumerate()
            .map(|(r, p)| {
                let last = self.offset[r] + p.rests.len() - 1;
                x[last] + p.len - p.rests.last().copied().unwrap_or(0.0)
            })
            .fold(0.0, f64::max)
    }

    /// Adds `e` and raises the times it forces; false on a positive cycle (the orders chosen
    /// cannot all hold).
    fn add(&mut self, e: Edge, x: &mut [f64]) -> bool {
        self.out[e.from].push(e);
        self.raised.clear();
        if x[e.to] < x[e.from] + e.w - EPS {
            x[e.to] = x[e.from] + e.w;
            return self.propagate(e.to, x);
        }
        true
    }

    /// When robot `r` arrives at its rest `k` (0 for home).
    fn arrival(&self, r: usize, k: usize, x: &[f64]) -> f64 {
        let o = self.offset[r];
        if k == 0 {
            0.0
        } else {
            x[o + k - 1] + self.paths[r].rests[k] - self.paths[r].rests[k - 1]
        }
    }

    /// A rest with a wait shorter than the shortest allowed.
    fn short_wait(&self, x: &[f64]) -> Option<usize> {
        for (r, p) in self.paths.iter().enumerate() {
            for k in 0..p.rests.len() {
                let v = self.offset[r] + k;
                let d = x[v] - self.arrival(r, k, x);
                if d > 1e-9 && d < self.min_wait - 1e-9 {
                    return Some(v);
                }
            }
        }
        None
    }

    /// Makes the wait at node `v` at least the shortest allowed; false when the chosen orders
    /// then cannot hold.
    fn lengthen(&mut self, v: usize, x: &mut [f64]) -> bool {
        self.hold[v] = self.min_wait;
        self.raised.clear();
        let r = self.robot_of(v);
        let need = self.arrival(r, v - self.offset[r], x) + self.min_wait;
        if x[v] < need - EPS {
            x[v] = need;
            let ok = self.propagate(v, x);
            if !ok {
                self.cycle = None;
            }
            return ok;
        }
        true
    }

    /// Raises every time that the raised `x[start]` forces (each raised node, `start` too,
    /// noted in `raised`); false on a positive cycle (one that comes back to raise `start`
    /// again; `x` and `raised` are then left unfinished).
    fn propagate(&mut self, start: usize, x: &mut [f64]) -> bool {
        let mut raised = std::mem::take(&mut self.raised);
        raised.push(start);
        let mut stack = vec![start];
        while let Some(u) = stack.pop() {
            let r = self.robot_of(u);
            let next = u + 1;
            let chain = (next < self.offset[r] + self.paths[r].rests.len()).then(|| {
                let k = next - self.offset[r];
                Edge {
                    from: u,
                    to: next,
                    w: self.paths[r].rests[k] - self.paths[r].rests[k - 1] + self.hold[next],
                    tag: NO_TAG,
                }
            });
            for (k, f) in chain.iter().chain(&self.out[u]).enumerate() {
                if x[f.to] < x[u] + f.w - EPS {
                    let held = k == 0 && chain.is_some() && self.hold[f.to] > 0.0;
                    if f.to == start {
                        self.cycle = self.cycle_to(start, u, (f.tag, held));
                        return false;
                    }
                    x[f.to] = x[u] + f.w;
                    self.pred[f.to] = (u as u32, f.tag, held);
                    raised.push(f.to);
                    stack.push(f.to);
                }
            }
        }
        self.raised = raised;
        true
    }

    /// The choices on the positive cycle that the edge `last` (its tag, whether it is a
    /// lengthened wait) from `u` back to `start` closes, following how the propagation from
    /// `start` reached `u`; `None` when a lengthened wait is on it.
    fn cycle_to(&self, start: usize, u: usize, last: (u32, bool)) -> Option<Vec<u32>> {
        let mut tags = Vec::new();
        let (mut v, mut edge) = (u, last);
        for _ in 0..=self.pred.len() {
            if edge.1 {
                return None;
            }
            if edge.0 != NO_TAG {
                tags.push(edge.0);
            }
            if v == start {
                return Some(tags);
            }
            let (p, tag, held) = self.pred[v];
            (v, edge) = (p as usize, (tag, held));
        }
        None
    }

    fn holds(e: &Option<Edge>, x: &[f64]) -> bool {
        e.is_some_and(|e| x[e.to] >= x[e.from] + e.w - EPS)
    }

    /// Whether neither order of box `c` holds at `x` (the box is still to be passed).
    fn is_open(c: &Choice, x: &[f64]) -> bool {
        !(Self::holds(&c.first_a, x) || Self::holds(&c.first_b, x))
    }

    /// Every box open at `x` (the root's list).
    fn all_open(&self, x: &[f64]) -> Vec<u32> {
        (0..self.choices.len())
            .filter(|&i| Self::is_open(&self.choices[i], x))
            .map(|i| i as u32)
            .collect()
    }

    /// The boxes open at `x`, given `open`, those open at times that `x` raises only at the
    /// nodes in `raised`: whether a box is passed depends on the times of its orders' nodes
    /// only, and an order that holds keeps holding while the time it starts from stays, so only
    /// the boxes listed and those with an order starting at a raised node are looked at.
    fn refresh(&mut self, open: &[u32], raised: &[usize], x: &[f64]) -> Vec<u32> {
        if self.mark == u32::MAX {
            self.seen.fill(0);
            self.mark = 0;
        }
        self.mark += 1;
        let (mark, choices, seen) = (self.mark, &self.choices, &mut self.seen);
        let mut out = Vec::with_capacity(open.len());
        for &i in open {
            seen[i as usize] = mark;
            if Self::is_open(&choices[i as usize], x) {
                out.push(i);
            }
        }
        for &v in raised {
            for &i in &self.incident[v] {
                if seen[i as usize] != mark {
                    seen[i as usize] = mark;
                    if Self::is_open(&choices[i as usize], x) {
                        out.push(i);
                    }
                }
            }
        }
        out
    }

    /// The box to branch on: of `open` (the boxes that neither order passes at `x`), the
    /// earliest by when its first robot reaches it, ties to the first box.
    fn earliest(&self, open: &[u32], x: &[f64]) -> Option<usize> {
        let mut pick: Option<(f64, usize)> = None;
        for &i in open {
            let (i, c) = (i as usize, &self.choices[i as usize]);
            let when = [c.first_a, c.first_b]
                .iter()
                .flatten()
                .map(|e| x[e.to])
                .fold(f64::INFINITY, f64::min);
            #[allow(clippy::float_cmp)] // the same pick as a scan of the boxes in order
            if pick.is_none_or(|(t, j)| when < t || (when == t && i < j)) {
                pick = Some((when, i));
            }
        }
        pick.map(|p| p.1)
    }

    /// One node of the search at times `x`: `open`, the boxes open at its parent's times, and
    /// `raised`, the nodes whose times rose since (at the root: every box open there, none).
    ///
    /// Returns, when the subtree has no schedule at all because every order of some box closes
    /// a positive cycle with orders chosen above, those choices (places in `chosen`): a conflict
    /// set, as in conflict-directed backjumping (Prosser). A node whose own choice is not in a
    /// child's set does not try its other order: that order would fail the same way, so the
    /// search jumps back to the deepest choice that is to blame. `None` when the subtree found
    /// a schedule, was cut (bound, budget, discrepancies) or failed through a lengthened wait.
    fn dive(&mut self, x: Vec<f64>, open: &[u32], raised: Vec<usize>, used: usize) -> Option<Vec<u32>> {
        if self.at_floor() || (self.stop_at_first && self.found) {
            return None;
        }
        self.nodes += 1;
        let bound = self.makespan(&x);
        if self.best.as_ref().is_some_and(|b| bound >= b.0 - EPS) {
            return None;
        }
        let open = self.refresh(open, &raised, &x);
        debug_assert!({
            let mut o = open.clone();
            o.sort_unstable();
            o == self.all_open(&x)
        });
        let Some(i) = self.earliest(&open, &x) else {
            // Every box passed: a wait too short to show becomes the shortest allowed, and
            // the search goes on from there (it may open boxes again).
            if let Some(v) = self.short_wait(&x) {
                let mut y = x;
                let mut found = None;
                if self.lengthen(v, &mut y) {
                    let raised = std::mem::take(&mut self.raised);
                    found = self.dive(y, &open, raised, used);
                }
                self.hold[v] = 0.0;
                return found;
            }
            self.best = Some((bound, x, self.chosen.clone(), self.chosen.len()));
            self.found = true;
            return None;
        };
        // Each order applied to a copy; the one finishing earlier explored first. An order
        // that closes a cycle adds the choices on it to the conflict set.
        let depth = self.chosen.len() as u32;
        let mut conflict: Option<Vec<u32>> = Some(Vec::new());
        let blame =
            |conflict: &mut Option<Vec<u32>>, found: Option<Vec<u32>>| match (conflict.as_mut(), found) {
                (Some(c), Some(f)) => c.extend(f.into_iter().filter(|&t| t != depth)),
                _ => *conflict = None,
            };
        let c = self.choices[i];
        let mut children = Vec::new();
        for mut e in [c.first_a, c.first_b].into_iter().flatten() {
            e.tag = depth;
            let mut y = x.clone();
            if self.add(e, &mut y) {
                children.push((self.makespan(&y), e, y, std::mem::take(&mut self.raised)));
            } else {
                let cycle = self.cycle.take();
                blame(&mut conflict, cycle);
            }
            self.out[e.from].pop();
        }
        children.sort_by(|p, q| p.0.total_cmp(&q.0));
        for (k, (_, e, y, raised)) in children.into_iter().enumerate() {
            let used = used + k;
            if self.discrepancies.is_some_and(|d| used > d) {
                self.cut = true;
                return None;
            }
            // Without a schedule yet the search may go on a while longer (the first dive
            // usually finds one; a search that does not is proving there is none).
            let cap = if self.found {
                self.budget
            } else {
                self.budget.saturating_mul(NO_SCHEDULE_FACTOR)
            };
            if self.nodes >= cap {
                return None;
            }
            self.out[e.from].push(e);
            self.chosen.push(e);
            let found = self.dive(y, &open, raised, used);
            self.chosen.pop();
            self.out[e.from].pop();
            if let Some(f) = &found
                && !f.contains(&depth)
                && self.backjump
            {
                // This choice is not to blame: the other order fails the same way.
                return found;
            }
            blame(&mut conflict, found);
        }
        if !self.backjump {
            return None;
        }
        conflict.map(|mut c| {
            c.sort_unstable();
            c.dedup();
            c
        })
    }
}

/// How many times its budget the search may spend while it has no schedule at all.
const NO_SCHEDULE_FACTOR: usize = 10;

/// What the search found.
#[derive(Clone, Debug)]
pub(crate) enum Found {
    /// A schedule.
    Schedule(Schedule),
    /// Proof that no order of passing exists (waits only at the rests).
    Infeasible,
    /// Neither, within the budget.
    Unknown,
}

/// The schedule of `paths` (one per robot) passing `boxes` with the shortest makespan found in
/// `budget` nodes; `None` when none was found (no order of passing exists — a robot's home in
/// another's way, or no rest where a robot could let another pass — or none within the budget).
#[cfg(test)]
pub(crate) fn schedule(
    paths: &[Track],
    boxes: &[ConflictBox],
    budget: usize,
    min_wait: f64,
) -> Option<Schedule> {
    schedule_with(paths, boxes, budget, min_wait, false)
}

/// [`schedule`], and with `improve`, when the search ends unproven, one more budget of nodes
/// putting each robot back through the others ([`Search::improve`]).
pub(crate) fn schedule_with(
    paths: &[Track],
    boxes: &[ConflictBox],
    budget: usize,
    min_wait: f64,
    improve: bool,
) -> Option<Schedule> {
    match search_with(paths, boxes, budget, min_wait, true, true, improve).0 {
        Found::Schedule(s) => Some(s),
        Found::Infeasible | Found::Unknown => None,
    }
}

/// The search, and the nodes it took (with `floored`, the pairs' schedules bound it from
/// below first, see [`floor`]).
fn search(
    paths: &[Track],
    boxes: &[ConflictBox],
    budget: usize,
    min_wait: f64,
    floored: bool,
) -> (Found, usize) {
    search_with(paths, boxes, budget, min_wait, floored, true, false)
}

/// [`search`], with or without backjumping, and with or without the neighbourhood search
/// after it ([`Search::improve`]).
fn search_with(
    paths: &[Track],
    boxes: &[ConflictBox],
    budget: usize,
    min_wait: f64,
    floored: bool,
    backjump: bool,
    improve: bool,
) -> (Found, usize) {
    let mut s = Search::new(paths, boxes, budget.max(1), min_wait.max(0.0));
    s.backjump = backjump;
    if s.choices
        .iter()
        .any(|c| c.first_a.is_none() && c.first_b.is_none())
    {
        return (Found::Infeasible, 0);
    }
    // The pairs' schedules bound the makespan from below: a schedule that reaches the bound
    // ends the search, proven the shortest (on a large diagram long before the node budget).
    let mut spent = 0;
    if floored {
        let (floor, nodes) = floor(paths, boxes, budget.max(1), min_wait);
        spent = nodes;
        match floor {
            Some(f) => s.floor = f,
            None => return (Found::Infeasible, spent),
        }
    }
    // A schedule from a complete selection of orders to start from, when one holds; then
    // depth first until the first schedule of the search's own (the first dive is the greedy
    // one; a search that finds none goes on to prove there is none).
    s.best = s.incumbent();
    let x = s.initial();
    let open = s.all_open(&x);
    s.stop_at_first = true;
    s.dive(x.clone(), &open, Vec::new(), 0);
    s.stop_at_first = false;
    // Then limited discrepancy search: dives that leave the greedy order at most `d` times,
    // d = 0, 1, 2, …, pruned by the best schedule so far. A depth-first search spends its
    // budget changing the last orders of the first dive; the first orders, which matter more
    // on a large diagram, are revisited here first. When a round cuts nothing, every order
    // was looked at: the best schedule is the shortest.
    let mut proven = s.at_floor();
    if s.best.is_some() && !proven {
        for d in 0.. {
            s.discrepancies = Some(d);
            s.cut = false;
            s.dive(x.clone(), &open, Vec::new(), 0);
            if (!s.cut && s.nodes < s.budget) || s.at_floor() {
                proven = true;
                break;
            }
            if s.nodes >= s.budget {
                break;
            }
        }
    }
    // Then, unless proven, one more budget of nodes to put each robot back through the
    // others (the main search only: a pair's neighbourhoods are the whole search).
    if improve && !proven && s.best.is_some() && paths.len() > 2 {
        let work = s.budget;
        s.improve(work);
    }
    let nodes = s.nodes + spent;
    let Some((makespan, x, chosen, decisions)) = s.best.take() else {
        let found = if s.nodes >= s.budget.saturating_mul(NO_SCHEDULE_FACTOR) {
            Found::Unknown
        } else {
            Found::Infeasible
        };
        return (found, nodes);
    };
    let mut waits = Vec::with_capacity(paths.len());
    for (r, p) in paths.iter().enumerate() {
        let o = s.offset[r];
        let mut w = Vec::with_capacity(p.rests.len());
        for k in 0..p.rests.len() {
            let arrive = if k == 0 {
                0.0
            } else {
                x[o + k - 1] + p.rests[k] - p.rests[k - 1]
            };
            let d = (x[o + k] - arrive).max(0.0);
            // Whom: the robot of a chosen constraint that holds with equality here.
            let by = chosen
                .iter()
                .find(|e| e.to == o + k && (x[e.from] + e.w - x[o + k]).abs() <= 1e-6)
                .map(|e| paths[s.robot_of(e.from)].robot);
            w.push((if d > 1e-9 { d } else { 0.0 }, by));
        }
        waits.push(w);
    }
    let found = Found::Schedule(Schedule {
        waits,
        makespan,
        nodes,
        decisions,
        proven,
    });
    (found, nodes)
}

#[cfg(test)]
mod tests;

//! What the legs planned so far say about where a robot can go ([`Reach`]), and the legs
//! made of planned legs end to end ([`joined_leg`]).
use super::{Leg, Planned, key, leg_seed, plan_leg, shortcut_and_time, stop_of};
use crate::plan::graph::RobotGraph;
use crate::plan::{LegError, PlanSettings};
use cellplan_model::Cell;
use cellplan_model::robot::Robot;
use cellplan_motion::plan::Key;
use std::collections::BTreeMap;
use std::time::Instant;

/// Candidates of one task cut off (see [`Reach`]) after which all of its candidates are.
const TASK_CUT_OFF: usize = 2;

/// What the legs planned so far say about where a robot can go: which nodes its planned legs
/// join (the same component: a path between them exists, the planned legs end to end), and
/// which nodes a full search from home's component did not reach.
///
/// It is made from `planned` between batches of legs (never while a batch runs), so a leg's
/// result depends on the legs planned before its batch and not on which thread planned what.
pub struct Reach {
    /// Union–find parents over the graph's nodes, through the legs with a path.
    parent: Vec<usize>,
    /// Nodes outside home's component that a full-budget search from a node inside it did not
    /// reach: the node, the search's start and its samples.
    cut_off: BTreeMap<usize, (usize, usize)>,
}

impl Reach {
    /// What `planned` says; `full` is the sample budget of a full search.
    pub fn of(graph: &RobotGraph, planned: &Planned, full: usize) -> Self {
        let mut parent: Vec<usize> = (0..graph.len()).collect();
        fn root(parent: &mut [usize], mut x: usize) -> usize {
            while parent[x] != x {
                parent[x] = parent[parent[x]];
                x = parent[x];
            }
            x
        }
        for (&(a, b), leg) in planned {
            if leg.is_ok() {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                if ra != rb {
                    parent[ra.max(rb)] = ra.min(rb);
                }
            }
        }
        for x in 0..parent.len() {
            parent[x] = root(&mut parent, x);
        }
        let home = parent[0];
        let mut cut_off = BTreeMap::new();
        for (&(a, b), leg) in planned {
            let Err(LegError::Motion(cellplan_motion::plan::PlanError::NoPath { samples, .. })) = leg else {
                continue;
            };
            if *samples < full {
                continue;
            }
            let (inside, outside) = match (parent[a] == home, parent[b] == home) {
                (true, false) => (a, b),
                (false, true) => (b, a),
                _ => continue,
            };
            if let std::collections::btree_map::Entry::Vacant(e) = cut_off.entry(outside) {
                e.insert((inside, *samples));
            }
        }
        // A task with two candidates cut off is given up on this robot: its other candidates
        // outside home's component are cut off too (citing the first search), so that a task
        // in a pocket costs two full searches, not one per candidate.
        let mut per_task: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        for &n in cut_off.keys() {
            if let Some((t, _)) = graph.node_task[n] {
                per_task.entry(t.0).or_default().push(n);
            }
        }
        for (t, nodes) in per_task {
            if nodes.len() < TASK_CUT_OFF {
                continue;
            }
            let first = cut_off[&nodes[0]];
            for &n in &graph.alternatives[t] {
                if parent[n] != home && !cut_off.contains_key(&n) {
                    cut_off.insert(n, first);
                }
            }
        }
        Reach { parent, cut_off }
    }

    /// Whether `n` is cut off.
    pub fn is_cut_off(&self, n: usize) -> bool {
        self.cut_off.contains_key(&n)
    }

    fn unreached(cell: &Cell, graph: &RobotGraph, end: usize, from: usize, samples: usize) -> LegError {
        LegError::Unreached(Box::new(crate::plan::Unreached {
            from: stop_of(cell, graph, from).to_string(),
            to: stop_of(cell, graph, end).to_string(),
            samples,
        }))
    }

    /// Whether planned legs join `a` and `b`.
    pub fn joined(&self, a: usize, b: usize) -> bool {
        self.parent[a] == self.parent[b]
    }

    /// The leg from `a` to `b`: none when an end is cut off; the planned legs joined end to end
    /// and shortcut when `full` (a full-budget search) and they join the two; else the motion
    /// planner, and, when it finds no path and planned legs join the ends, those legs.
    #[allow(clippy::too_many_arguments)]
    pub fn leg(
        &self,
        cell: &Cell,
        robot: &Robot,
        graph: &RobotGraph,
        planned: &Planned,
        a: usize,
        b: usize,
        settings: &PlanSettings,
        full: bool,
    ) -> Result<Leg, LegError> {
        for end in [a, b] {
            if let Some(&(from, samples)) = self.cut_off.get(&end) {
                return Err(Self::unreached(cell, graph, end, from, samples));
            }
        }
        if full && self.joined(a, b) {
            return joined_leg(cell, robot, graph, planned, a, b, settings);
        }
        match plan_leg(cell, robot, graph, a, b, settings) {
            Err(LegError::Motion(cellplan_motion::plan::PlanError::NoPath { .. })) if self.joined(a, b) => {
                joined_leg(cell, robot, graph, planned, a, b, settings)
            }
            r => r,
        }
    }
}

/// The leg from `a` to `b` through planned legs: the quickest chain of them (by their times),
/// end to end, then shortcut (every change checked with the leg's clearance) and timed. Every
/// planned leg keeps the clearance and every joint is a graph node (a checked pose), so the
/// chain does too.
fn joined_leg(
    cell: &Cell,
    robot: &Robot,
    graph: &RobotGraph,
    planned: &Planned,
    a: usize,
    b: usize,
    settings: &PlanSettings,
) -> Result<Leg, LegError> {
    let started = Instant::now();
    // Dijkstra over the planned legs.
    let mut adj: BTreeMap<usize, Vec<(usize, f64)>> = BTreeMap::new();
    for (&(x, y), leg) in planned {
        if let Ok(l) = leg {
            adj.entry(x).or_default().push((y, l.duration));
            adj.entry(y).or_default().push((x, l.duration));
        }
    }
    let mut dist: BTreeMap<usize, (f64, usize)> = BTreeMap::new();
    let mut heap = std::collections::BinaryHeap::new();
    dist.insert(a, (0.0, a));
    heap.push((std::cmp::Reverse(Key(0.0)), a));
    while let Some((std::cmp::Reverse(Key(d)), x)) = heap.pop() {
        if x == b {
            break;
        }
        if dist.get(&x).is_some_and(|&(best, _)| d > best) {
            continue;
        }
        for &(y, w) in adj.get(&x).map(Vec::as_slice).unwrap_or(&[]) {
            let nd = d + w;
            if dist.get(&y).is_none_or(|&(best, _)| nd < best) {
                dist.insert(y, (nd, x));
                heap.push((std::cmp::Reverse(Key(nd)), y));
            }
        }
    }
    let mut chain = vec![b];
    while let Some(&last) = chain.last()
        && last != a
    {
        chain.push(dist[&last].1);
    }
    chain.reverse();
    let mut waypoints: Vec<Vec<f64>> = vec![graph.q[a].clone()];
    for w in chain.windows(2) {
        let (x, y) = (w[0], w[1]);
        let Some(Ok(leg)) = planned.get(&key(x, y)) else {
            unreachable!("the chain follows planned legs")
        };
        let mut points = leg.waypoints.clone();
        if (x, y) != key(x, y) {
            points.reverse();
        }
        waypoints.extend(points.into_iter().skip(1));
    }
    let seed = leg_seed(settings.seed, robot.id.0, a, b) ^ 2;
    let (waypoints, duration) = shortcut_and_time(cell, robot, graph, waypoints, seed, settings)?;
    Ok(Leg {
        waypoints,
        duration,
        straight: false,
        samples: 0,
        validity_calls: 0,
        compute_s: started.elapsed().as_secs_f64(),
    })
}

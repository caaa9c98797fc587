//! Lazy PRM, with a roadmap kept across queries.
use super::problem::{Found, Run};
use super::{JointSpace, MotionPlanner, PlanResult, PlannerParams, Problem, Termination, solve_with};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// Fewest samples added to the roadmap when it cannot connect a query.
const MIN_BATCH: usize = 32;

/// A probabilistic roadmap of one static scene (Kavraki et al. 1996), checked lazily (Bohlin
/// & Kavraki 2000): nodes are valid configurations (checked when added), each linked to its
/// nearest neighbours by edges that are checked only when a shortest path uses them; an
/// invalid edge is removed, a valid one remembered. Keep it between queries in the same
/// scene (same space, validity and `min_clearance`): later queries reuse its nodes and
/// checked edges. Used through [`Prm`].
///
/// The roadmap remembers the space and `min_clearance` it was built for and starts afresh
/// when a query comes with others; it cannot tell a changed validity checker, so a caller
/// whose scene changes must start a new roadmap (or [`Roadmap::clear`] it).
#[derive(Clone, Debug)]
pub struct Roadmap {
    nodes: Vec<Vec<f64>>,
    edges: Vec<Vec<Edge>>,
    rng: ChaCha8Rng,
    scene: Option<(JointSpace, f64)>,
}

#[derive(Clone, Copy, Debug)]
struct Edge {
    to: usize,
    length: f64,
    checked: bool,
}

/// An `f64` ordered by `total_cmp`, for search queues (the roadmaps', and any shortest-path
/// search over costs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key(pub f64);

impl Eq for Key {}

impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Key {
    fn cmp(&self, other: &Self) -> Ordering {
        self.0.total_cmp(&other.0)
    }
}

impl Roadmap {
    /// An empty roadmap whose random samples are seeded with `seed` (ChaCha8).
    pub fn new(seed: u64) -> Self {
        Roadmap {
            nodes: Vec::new(),
            edges: Vec::new(),
            rng: ChaCha8Rng::seed_from_u64(seed),
            scene: None,
        }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether it has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The nodes (valid configurations).
    pub fn nodes(&self) -> &[Vec<f64>] {
        &self.nodes
    }

    /// Number of edges (each counted once).
    pub fn edge_count(&self) -> usize {
        self.edges.iter().map(Vec::len).sum::<usize>() / 2
    }

    /// Number of edges proven valid so far.
    pub fn checked_edge_count(&self) -> usize {
        self.edges
            .iter()
            .map(|e| e.iter().filter(|e| e.checked).count())
            .sum::<usize>()
            / 2
    }

    /// Removes every node and edge (the random sequence goes on).
    pub fn clear(&mut self) {
        self.nodes.clear();
        self.edges.clear();
        self.scene = None;
    }

    /// Starts afresh if the scene is not the one the roadmap was built for.
    fn prepare(&mut self, space: &JointSpace, floor: f64) {
        let same = matches!(&self.scene, Some((s, f)) if s == space && *f == floor);
        if !same {
            self.clear();
            self.scene = Some((space.clone(), floor));
        }
    }

    /// Adds the valid configuration `q` (or finds it) and links it to its nearest nodes.
    fn add_node(&mut self, space: &JointSpace, q: &[f64], neighbours: usize) -> usize {
        if let Some(i) = self.nodes.iter().position(|n| n.as_slice() == q) {
            return i;
        }
        let n = self.nodes.len();
        let k = if neighbours > 0 {
            neighbours
        } else {
            let d = space.dim().max(1) as f64;
            (std::f64::consts::E * (1.0 + 1.0 / d) * ((n + 1) as f64).ln()).ceil() as usize
        }
        .max(1);
        let mut near: Vec<(f64, usize)> = self
            .nodes
            .iter()
            .enumerate()
            .map(|(i, p)| (space.distance(p, q), i))
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        near.truncate(k);
        self.nodes.push(q.to_vec());
        self.edges.push(Vec::with_capacity(near.len()));
        for (length, i) in near {
            let e = |to| Edge {
                to,
                length,
                checked: false,
            };
            self.edges[n].push(e(i));
            self.edges[i].push(e(n));
        }
        n
    }

    fn edge_mut(&mut self, a: usize, b: usize) -> Option<&mut Edge> {
        self.edges[a].iter_mut().find(|e| e.to == b)
    }

    fn is_checked(&self, a: usize, b: usize) -> bool {
        self.edges[a].iter().any(|e| e.to == b && e.checked)
    }

    fn mark_checked(&mut self, a: usize, b: usize) {
        for (x, y) in [(a, b), (b, a)] {
            if let Some(e) = self.edge_mut(x, y) {
                e.checked = true;
            }
        }
    }

    fn remove_edge(&mut self, a: usize, b: usize) {
        self.edges[a].retain(|e| e.to != b);
        self.edges[b].retain(|e| e.to != a);
    }

    /// The shortest path in the roadmap (A*, edges by their length, checked or not) from
    /// `from` to any of `targets`, as node indices.
    fn shortest(&self, space: &JointSpace, from: usize, targets: &[usize]) -> Option<Vec<usize>> {
        let n = self.nodes.len();
        // The distance to the nearest target: consistent, the metric being a norm.
        let h = |i: usize| {
            targets
                .iter()
                .map(|&t| space.distance(&self.nodes[i], &self.nodes[t]))
                .fold(f64::INFINITY, f64::min)
        };
        let mut g = vec![f64::INFINITY; n];
        let mut prev = vec![usize::MAX; n];
        let mut closed = vec![false; n];
        let mut queue = BinaryHeap::new();
        g[from] = 0.0;
        queue.push(Reverse((Key(h(from)), from)));
        while let Some(Reverse((_, i))) = queue.pop() {
            if closed[i] {
                continue;
            }
            closed[i] = true;
            if targets.contains(&i) {
                let mut path = vec![i];
                let mut k = i;
                while prev[k] != usize::MAX {
                    k = prev[k];
                    path.push(k);
                }
                path.reverse();
                return Some(path);
            }
            for e in &self.edges[i] {
                let ng = g[i] + e.length;
                if ng < g[e.to] {
                    g[e.to] = ng;
                    prev[e.to] = i;
                    queue.push(Reverse((Key(ng + h(e.to)), e.to)));
                }
            }
        }
        None
    }
}

/// Lazy PRM over a [`Roadmap`] it keeps: each query adds its start and valid goals to the
/// roadmap, searches the shortest roadmap path to any goal, checks its unchecked edges
/// ([`super::check_segment`]) from the start on, removes an invalid one and searches again;
/// when the roadmap cannot connect the query it grows by a batch of random samples (a
/// quarter of its size, at least 32; invalid samples are dropped). Queries in the same static
/// scene reuse the roadmap, which makes later queries cheaper.
///
/// Deterministic: the roadmap's random numbers are seeded with [`PlannerParams::seed`] when
/// it is made, so the same queries in the same order give the same paths.
#[derive(Clone, Debug)]
pub struct Prm {
    /// Its parameters ([`PlannerParams::neighbours`], the post-processing).
    pub params: PlannerParams,
    roadmap: Roadmap,
}

impl Prm {
    /// A planner with an empty roadmap seeded with `params.seed`.
    pub fn new(params: &PlannerParams) -> Self {
        Prm {
            params: params.clone(),
            roadmap: Roadmap::new(params.seed),
        }
    }

    /// A planner continuing `roadmap` (built in the same scene).
    pub fn with_roadmap(params: &PlannerParams, roadmap: Roadmap) -> Self {
        Prm {
            params: params.clone(),
            roadmap,
        }
    }

    /// Its roadmap.
    pub fn roadmap(&self) -> &Roadmap {
        &self.roadmap
    }

    /// Gives the roadmap back, to keep for later queries.
    pub fn into_roadmap(self) -> Roadmap {
        self.roadmap
    }
}

/// One lazy PRM query on `roadmap`.
fn search(
    run: &mut Run,
    roadmap: &mut Roadmap,
    neighbours: usize,
    start: &[f64],
    goals: &[Vec<f64>],
    valid: &[usize],
) -> Found {
    let space = run.space;
    roadmap.prepare(space, run.floor);
    let from = roadmap.add_node(space, start, neighbours);
    let mut targets = Vec::with_capacity(valid.len());
    let mut goal_of = Vec::with_capacity(valid.len());
    for &g in valid {
        let node = roadmap.add_node(space, &goals[g], neighbours);
        if !targets.contains(&node) {
            targets.push(node);
            goal_of.push(g);
        }
    }
    let mut q = Vec::with_capacity(space.dim());
    loop {
        let Some(path) = roadmap.shortest(space, from, &targets) else {
            // Not connected: grow.
            let batch = (roadmap.len() / 4).max(MIN_BATCH);
            for _ in 0..batch {
                if let Err(why) = run.sample(&mut roadmap.rng, &mut q) {
                    return Found::none(why);
                }
                if run.state_valid(&q) {
                    roadmap.add_node(space, &q, neighbours);
                }
            }
            continue;
        };
        let mut broken = false;
        for w in path.windows(2) {
            if roadmap.is_checked(w[0], w[1]) {
                continue;
            }
            if let Some(why) = run.must_stop() {
                return Found::none(why);
            }
            if run.segment(&roadmap.nodes[w[0]], &roadmap.nodes[w[1]]) {
                roadmap.mark_checked(w[0], w[1]);
            } else {
                roadmap.remove_edge(w[0], w[1]);
                broken = true;
                break;
            }
        }
        if !broken {
            let last = *path.last().expect("a path has a node");
            let goal = goal_of[targets.iter().position(|&t| t == last).expect("a target")];
            let mut waypoints: Vec<Vec<f64>> = path.iter().map(|&i| roadmap.nodes[i].clone()).collect();
            if waypoints.len() == 1 {
                // The start is the goal.
                waypoints.push(goals[goal].clone());
            }
            return Found::path(waypoints, goal);
        }
    }
}

impl MotionPlanner for Prm {
    fn name(&self) -> &'static str {
        "prm"
    }

    fn solve(&mut self, problem: &Problem, stop: &Termination) -> PlanResult {
        let roadmap = &mut self.roadmap;
        let neighbours = self.params.neighbours;
        solve_with(problem, stop, &self.params, |run, valid| {
            search(run, roadmap, neighbours, problem.start, problem.goals, valid)
        })
    }
}

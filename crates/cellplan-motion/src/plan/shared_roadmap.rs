//! A roadmap of one robot in one static scene, shared by every leg query of that robot, from
//! any thread: [`SharedRoadmap`].
//!
//! The inspection planner asks hundreds of legs of each robot in a scene that does not change
//! while it plans them (the other robots stand at home). A sampler starts every leg from
//! nothing; a roadmap keeps what one leg learnt for the next. [`super::Roadmap`] does that for
//! queries asked one after the other; this one is asked by many threads at once, and must
//! give each query the same answer whichever queries ran before it:
//!
//! - **Frozen nodes.** The nodes are fixed when the roadmap is built: the configurations given
//!   (a robot's task candidates: where its legs start and end) and seeded samples — half
//!   uniform over the joint limits, half within [`NEAR`] of a random given configuration on
//!   every joint (paths between the robot's work postures stay near them instead of swinging
//!   through the whole joint space) — each checked valid, every node linked to its `k`
//!   nearest.
//! - **Cached edges.** An edge is checked ([`super::check_segment`]) the first time a query
//!   needs it and its verdict kept (one atomic byte per edge). A verdict depends only on the
//!   edge, so concurrent first checks store the same value.
//! - **Answers that do not depend on the cache's history.** A query links its start and goal
//!   to their nearest nodes and runs lazy PRM (Bohlin & Kavraki 2000): the shortest path under
//!   the edges not known invalid — those it found invalid itself and those the cache already
//!   holds as invalid, whichever query checked them —, its edges checked from the start on
//!   (through the cache, which then holds the first invalid one), search again. Every edge
//!   left out is invalid, so every valid path stays in the graph searched, and the path a
//!   search returns whole valid is the shortest valid path of the roadmap: the same answer
//!   with a cold or a warm cache, in any thread, whichever queries ran before (paths of equal
//!   length compare by their hops: a start or goal that is a node ties exactly with the path
//!   skipping it). There is no budget to bind: each search that fails leaves out one more
//!   edge, so a query ends within the roadmap's edge count of searches, and over all queries
//!   each edge is checked about once (twice when two threads race to it); only the work, not
//!   the answer, depends on what other queries checked first.
use super::prm::Key;
use super::{JointSpace, StateValidity, check_segment};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::cmp::Reverse;
use std::collections::{BTreeSet, BinaryHeap};
use std::sync::atomic::{AtomicU8, Ordering};

/// Half the samples are drawn within this (rad, or joint units) of a seed on every joint.
pub const NEAR: f64 = 0.5;

/// An edge's verdict: not checked yet.
const UNKNOWN: u8 = 0;
/// Checked: valid.
const VALID: u8 = 1;
/// Checked: invalid.
const INVALID: u8 = 2;

/// How a [`SharedRoadmap`] is built and queried.
#[derive(Clone, Debug, PartialEq)]
pub struct SharedRoadmapSettings {
    /// Samples drawn, half uniform, half near the seeds (the invalid ones are dropped).
    pub samples: usize,
    /// Each node is linked to this many nearest nodes.
    pub neighbours: usize,
    /// A query's start and goal are each linked to this many nearest nodes.
    pub connect: usize,
    /// Seed of the samples.
    pub seed: u64,
    /// Clearance (m) below which a configuration counts as invalid (as in
    /// [`super::check_segment`]).
    pub min_clearance: f64,
}

impl Default for SharedRoadmapSettings {
    fn default() -> Self {
        SharedRoadmapSettings {
            samples: 600,
            neighbours: 10,
            connect: 10,
            seed: 0,
            min_clearance: 1e-4,
        }
    }
}

/// A frozen roadmap with a shared cache of edge verdicts (see the module documentation).
#[derive(Debug)]
pub struct SharedRoadmap {
    nodes: Vec<Vec<f64>>,
    /// Per node: (neighbour, edge index), sorted by neighbour.
    adjacent: Vec<Vec<(u32, u32)>>,
    /// Per edge: its two nodes and its length.
    edges: Vec<(u32, u32, f64)>,
    verdicts: Vec<AtomicU8>,
    settings: SharedRoadmapSettings,
}

/// The outcome of a [`SharedRoadmap::query`].
#[derive(Clone, Debug, PartialEq)]
pub struct RoadmapPath {
    /// From the start to the goal, inclusive; `None` when the roadmap has no valid path.
    pub waypoints: Option<Vec<Vec<f64>>>,
    /// Edges examined (fewer when other queries found invalid edges first).
    pub edges_examined: usize,
    /// Validity calls made by this query (fewer when other queries checked its edges first).
    pub validity_calls: usize,
}

/// The `k` nodes of `nodes` nearest to `q` (by the space's metric; ties by index), skipping
/// `skip`, nearest first.
fn nearest(space: &JointSpace, nodes: &[Vec<f64>], q: &[f64], k: usize, skip: usize) -> Vec<(f64, usize)> {
    let mut near: Vec<(f64, usize)> = nodes
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != skip)
        .map(|(i, p)| (space.distance(p, q), i))
        .collect();
    let k = k.min(near.len());
    if k == 0 {
        return Vec::new();
    }
    near.select_nth_unstable_by(k - 1, |a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    near.truncate(k);
    near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    near
}

impl SharedRoadmap {
    /// Builds the roadmap from `seeds` (the valid ones are kept) and `settings.samples` samples
    /// of `space` (seeded by `settings.seed`; every other one uniform, the rest within `NEAR` (0.5 rad)
    /// of a valid seed on every joint; the valid ones are kept), each node
    /// linked to its `settings.neighbours` nearest. Single-threaded and deterministic. Returns
    /// the roadmap and the validity calls made.
    pub fn build(
        space: &JointSpace,
        validity: &dyn StateValidity,
        seeds: &[Vec<f64>],
        settings: &SharedRoadmapSettings,
    ) -> (SharedRoadmap, usize) {
        let floor = settings.min_clearance.max(1e-9);
        let mut calls = 0;
        let mut nodes: Vec<Vec<f64>> = Vec::new();
        let mut seen = BTreeSet::new();
        for q in seeds {
            if q.len() != space.dim() || !space.contains(q) {
                continue;
            }
            let bits: Vec<u64> = q.iter().map(|x| x.to_bits()).collect();
            if !seen.insert(bits) {
                continue;
            }
            calls += 1;
            if validity.clear_of(q, floor) {
                nodes.push(q.clone());
            }
        }
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed ^ 0x524f_4144_4d41_5053);
        let seeded = nodes.len();
        for k in 0..settings.samples {
            use rand::RngExt;
            let near = (seeded > 0 && k % 2 == 0).then(|| rng.random_range(0..seeded));
            let q: Vec<f64> = (0..space.dim())
                .map(|j| {
                    let (lo, hi) = (space.lower[j], space.upper[j]);
                    match near {
                        Some(n) => (nodes[n][j] + rng.random_range(-NEAR..NEAR)).clamp(lo, hi),
                        None => {
                            if lo < hi {
                                rng.random_range(lo..hi)
                            } else {
                                lo
                            }
                        }
                    }
                })
                .collect();
            calls += 1;
            if validity.clear_of(&q, floor) {
                nodes.push(q);
            }
        }
        let mut pairs = BTreeSet::new();
        for (i, q) in nodes.iter().enumerate() {
            for (_, j) in nearest(space, &nodes, q, settings.neighbours, i) {
                pairs.insert((i.min(j) as u32, i.max(j) as u32));
            }
        }
        let mut adjacent = vec![Vec::new(); nodes.len()];
        let mut edges = Vec::with_capacity(pairs.len());
        for (a, b) in pairs {
            let e = edges.len() as u32;
            let length = space.distance(&nodes[a as usize], &nodes[b as usize]);
            edges.push((a, b, length));
            adjacent[a as usize].push((b, e));
            adjacent[b as usize].push((a, e));
        }
        let verdicts = (0..edges.len()).map(|_| AtomicU8::new(UNKNOWN)).collect();
        (
            SharedRoadmap {
                nodes,
                adjacent,
                edges,
                verdicts,
                settings: settings.clone(),
            },
            calls,
        )
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether it has no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Number of edges checked so far (by any query).
    pub fn checked_edges(&self) -> usize {
        self.verdicts
            .iter()
            .filter(|v| v.load(Ordering::Relaxed) != UNKNOWN)
            .count()
    }

    /// The shortest valid path of the roadmap from `start` to `goal` (both valid, the caller
    /// checked them), through their `connect` nearest nodes; see the module documentation.
    /// `validity` and `space` must be those the roadmap was built with.
    pub fn query(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
    ) -> RoadmapPath {
        let floor = self.settings.min_clearance;
        let n = self.nodes.len();
        // Query nodes: n is the start, n + 1 the goal; their edges are the query's own.
        let (s, g) = (n, n + 1);
        let mut extra: Vec<(usize, usize, f64)> = Vec::new();
        for (end, q) in [(s, start), (g, goal)] {
            for (d, i) in nearest(space, &self.nodes, q, self.settings.connect, usize::MAX) {
                extra.push((end, i, d));
            }
        }
        let direct = space.distance(start, goal);
        extra.push((s, g, direct));
        // Verdicts of the query's own edges; an invalid one is set aside.
        let mut extra_verdict = vec![UNKNOWN; extra.len()];
        // Per node, its heuristic once worked out (the A* runs of one query share it). A roadmap
        // edge found invalid is left out through the shared verdicts, stored before the next run.
        let mut to_goal = vec![f64::NAN; n + 2];
        let (mut examined, mut calls) = (0, 0);
        let point = |i: usize| -> &[f64] {
            if i == s {
                start
            } else if i == g {
                goal
            } else {
                &self.nodes[i]
            }
        };
        let waypoints = 'search: loop {
            let Some(path) = self.shortest(space, (start, goal), (&extra, &extra_verdict), &mut to_goal)
            else {
                break 'search None;
            };
            for &(hop, _) in &path {
                examined += 1;
                // The verdict from the query's own cache or the shared one, checked if unknown.
                let mut check = |a: usize, b: usize| {
                    let c = check_segment(space, validity, point(a), point(b), floor);
                    calls += c.calls;
                    if c.valid { VALID } else { INVALID }
                };
                let valid = match hop {
                    Hop::Query(k) => {
                        if extra_verdict[k] == UNKNOWN {
                            extra_verdict[k] = check(extra[k].0, extra[k].1);
                        }
                        extra_verdict[k] == VALID
                    }
                    Hop::Roadmap(e) => {
                        let slot = &self.verdicts[e as usize];
                        let mut v = slot.load(Ordering::Relaxed);
                        if v == UNKNOWN {
                            let (a, b, _) = self.edges[e as usize];
                            v = check(a as usize, b as usize);
                            slot.store(v, Ordering::Relaxed);
                        }
                        v == VALID
                    }
                };
                if !valid {
                    continue 'search;
                }
            }
            let mut waypoints = vec![start.to_vec()];
            waypoints.extend(path.iter().map(|&(_, next)| point(next).to_vec()));
            break 'search Some(waypoints);
        };
        RoadmapPath {
            waypoints,
            edges_examined: examined,
            validity_calls: calls,
        }
    }

    /// A* from the start (node `n`) to the goal (`n + 1`) over the roadmap's edges and the
    /// query's own (`extra`), leaving out the roadmap edges the shared cache holds invalid and
    /// the query edges found invalid; the hops in order, each with the node it reaches.
    /// `to_goal` keeps each node's heuristic (NaN: not worked out yet).
    fn shortest(
        &self,
        space: &JointSpace,
        (start, goal): (&[f64], &[f64]),
        (extra, extra_verdict): (&[(usize, usize, f64)], &[u8]),
        to_goal: &mut [f64],
    ) -> Option<Vec<(Hop, usize)>> {
        let n = self.nodes.len();
        let (s, g) = (n, n + 1);
        let mut h = |i: usize| -> f64 {
            if to_goal[i].is_nan() {
                to_goal[i] = if i == g {
                    0.0
                } else if i == s {
                    space.distance(start, goal)
                } else {
                    space.distance(&self.nodes[i], goal)
                };
            }
            to_goal[i]
        };
        // The query's edges by node.
        let mut query_at: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n + 2];
        for (k, &(a, b, _)) in extra.iter().enumerate() {
            if extra_verdict[k] != INVALID {
                query_at[a].push((b, k));
                query_at[b].push((a, k));
            }
        }
        // Paths compare by length, then by hops: the start or goal often is a node (a task
        // candidate), and a path through it ties exactly with the one that skips it; the fewer
        // hops win, so the answer does not hang on which the search met first.
        let mut dist = vec![(f64::INFINITY, u32::MAX); n + 2];
        let mut prev: Vec<Option<(usize, Hop)>> = vec![None; n + 2];
        let mut closed = vec![false; n + 2];
        let mut queue = BinaryHeap::new();
        dist[s] = (0.0, 0);
        queue.push(Reverse((Key(h(s)), 0, s)));
        while let Some(Reverse((_, _, i))) = queue.pop() {
            if closed[i] {
                continue;
            }
            closed[i] = true;
            if i == g {
                let mut hops = Vec::new();
                let mut k = g;
                while let Some((p, hop)) = prev[k] {
                    hops.push((hop, k));
                    k = p;
                }
                hops.reverse();
                return Some(hops);
            }
            let mut relax =
                |j: usize, length: f64, hop: Hop, queue: &mut BinaryHeap<Reverse<(Key, u32, usize)>>| {
                    let nd = (dist[i].0 + length, dist[i].1 + 1);
                    if nd.0 < dist[j].0 || (nd.0 == dist[j].0 && nd.1 < dist[j].1) {
                        dist[j] = nd;
                        prev[j] = Some((i, hop));
                        queue.push(Reverse((Key(nd.0 + h(j)), nd.1, j)));
                    }
                };
            for &(j, k) in &query_at[i] {
                relax(j, extra[k].2, Hop::Query(k), &mut queue);
            }
            if i < n {
                for &(j, e) in &self.adjacent[i] {
                    if self.verdicts[e as usize].load(Ordering::Relaxed) != INVALID {
                        relax(j as usize, self.edges[e as usize].2, Hop::Roadmap(e), &mut queue);
                    }
                }
            }
        }
        None
    }
}

/// One hop of a query's path.
#[derive(Clone, Copy, Debug)]
enum Hop {
    /// A query edge (index into its list).
    Query(usize),
    /// A roadmap edge.
    Roadmap(u32),
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square with a wall at x = 0.5 from y = 0 to 0.8: paths must go round its top.
    fn wall(q: &[f64]) -> f64 {
        let (x, y) = (q[0], q[1]);
        // Distance to the segment x = 0.5, y in [0, 0.8] (a thin wall).
        let dy = if y > 0.8 { y - 0.8 } else { 0.0 };
        ((x - 0.5).powi(2) + dy * dy).sqrt() - 0.02
    }

    fn space() -> JointSpace {
        JointSpace::new(vec![0.0, 0.0], vec![1.0, 1.0], vec![1.0, 1.0])
    }

    /// The shortest valid path's length from `start` to `goal` by brute force: every edge of
    /// the roadmap and of the query checked, then Dijkstra.
    fn brute_force(roadmap: &SharedRoadmap, space: &JointSpace, start: &[f64], goal: &[f64]) -> Option<f64> {
        let n = roadmap.len();
        let point = |i: usize| -> Vec<f64> {
            match i {
                i if i == n => start.to_vec(),
                i if i == n + 1 => goal.to_vec(),
                i => roadmap.nodes[i].clone(),
            }
        };
        let mut edges: Vec<(usize, usize)> = roadmap
            .edges
            .iter()
            .map(|&(a, b, _)| (a as usize, b as usize))
            .collect();
        for (end, q) in [(n, start), (n + 1, goal)] {
            for (_, i) in nearest(space, &roadmap.nodes, q, roadmap.settings.connect, usize::MAX) {
                edges.push((end, i));
            }
        }
        edges.push((n, n + 1));
        let mut adjacent = vec![Vec::new(); n + 2];
        for (a, b) in edges {
            if check_segment(space, &wall, &point(a), &point(b), 1e-4).valid {
                let d = space.distance(&point(a), &point(b));
                adjacent[a].push((b, d));
                adjacent[b].push((a, d));
            }
        }
        let mut dist = vec![f64::INFINITY; n + 2];
        let mut queue = BinaryHeap::new();
        dist[n] = 0.0;
        queue.push(Reverse((Key(0.0), n)));
        while let Some(Reverse((Key(d), i))) = queue.pop() {
            if d > dist[i] {
                continue;
            }
            for &(j, l) in &adjacent[i] {
                if d + l < dist[j] {
                    dist[j] = d + l;
                    queue.push(Reverse((Key(d + l), j)));
                }
            }
        }
        dist[n + 1].is_finite().then_some(dist[n + 1])
    }

    #[test]
    fn queries_give_the_shortest_valid_path_whatever_other_queries_checked_first() {
        let space = space();
        let settings = SharedRoadmapSettings {
            samples: 200,
            neighbours: 6,
            connect: 6,
            seed: 11,
            min_clearance: 1e-4,
        };
        let queries: Vec<(Vec<f64>, Vec<f64>)> = (0..12)
            .map(|k| {
                let t = k as f64 / 12.0;
                (
                    vec![0.05 + 0.35 * t, 0.05 + 0.7 * t],
                    vec![0.95 - 0.3 * t, 0.1 + 0.6 * (1.0 - t)],
                )
            })
            .collect();
        // Half the queries start or end at a node (as a robot's legs run between its task
        // candidates): their paths tie with those through that node.
        let seeds: Vec<Vec<f64>> = queries
            .iter()
            .enumerate()
            .map(|(k, (a, b))| if k % 2 == 0 { a.clone() } else { b.clone() })
            .collect();
        let build = || SharedRoadmap::build(&space, &wall, &seeds, &settings).0;
        let shared = build();
        let forward: Vec<RoadmapPath> = queries
            .iter()
            .map(|(a, b)| shared.query(&space, &wall, a, b))
            .collect();
        let backward = build();
        let mut reverse: Vec<RoadmapPath> = queries
            .iter()
            .rev()
            .map(|(a, b)| backward.query(&space, &wall, a, b))
            .collect();
        reverse.reverse();
        let (mut warmer, mut found) = (0, 0);
        for (k, (a, b)) in queries.iter().enumerate() {
            // Each query alone, on a cold cache.
            let cold = build().query(&space, &wall, a, b);
            assert_eq!(
                forward[k].waypoints, cold.waypoints,
                "query {k} after the earlier ones"
            );
            assert_eq!(
                reverse[k].waypoints, cold.waypoints,
                "query {k} after the later ones"
            );
            assert!(forward[k].edges_examined <= cold.edges_examined);
            warmer += usize::from(forward[k].edges_examined < cold.edges_examined);
            match (&cold.waypoints, brute_force(&shared, &space, a, b)) {
                (Some(path), Some(best)) => {
                    found += 1;
                    for w in path.windows(2) {
                        assert!(check_segment(&space, &wall, &w[0], &w[1], 1e-4).valid);
                    }
                    assert!(
                        (crate::plan::path_length(&space, path) - best).abs() < 1e-9,
                        "query {k}: {} against {best}",
                        crate::plan::path_length(&space, path)
                    );
                }
                (None, None) => {}
                (got, best) => panic!("query {k}: {got:?} against the brute force's {best:?}"),
            }
        }
        assert!(found >= 10, "most queries have a path ({found})");
        assert!(warmer > 0, "a warm cache saves some query work");
    }

    #[test]
    fn a_query_finds_a_valid_path_round_the_wall_whatever_the_cache_holds() {
        let space = space();
        let settings = SharedRoadmapSettings {
            samples: 300,
            neighbours: 8,
            connect: 8,
            seed: 3,
            min_clearance: 1e-4,
        };
        let (roadmap, _) = SharedRoadmap::build(&space, &wall, &[], &settings);
        assert!(roadmap.len() > 200, "most samples are valid ({})", roadmap.len());
        let (start, goal) = (vec![0.2, 0.2], vec![0.8, 0.2]);
        let cold = roadmap.query(&space, &wall, &start, &goal);
        let path = cold.waypoints.clone().expect("a path round the wall");
        assert_eq!(path.first(), Some(&start));
        assert_eq!(path.last(), Some(&goal));
        for w in path.windows(2) {
            assert!(check_segment(&space, &wall, &w[0], &w[1], 1e-4).valid);
        }
        // It goes over the wall's top.
        assert!(path.iter().any(|q| q[1] > 0.8));
        // Warm: other queries have checked edges since; the answer is the same, the work no more.
        for k in 0..10 {
            let a = vec![0.1 + 0.03 * k as f64, 0.1];
            let b = vec![0.9, 0.1 + 0.05 * k as f64];
            roadmap.query(&space, &wall, &a, &b);
        }
        let warm = roadmap.query(&space, &wall, &start, &goal);
        assert_eq!(warm.waypoints, cold.waypoints);
        assert!(warm.edges_examined <= cold.edges_examined);
        assert!(warm.validity_calls <= cold.validity_calls);
        assert!(roadmap.checked_edges() > 0);
    }

    #[test]
    fn a_roadmap_without_a_way_round_gives_no_path_and_seeds_become_nodes() {
        let space = space();
        let settings = SharedRoadmapSettings {
            samples: 0,
            ..SharedRoadmapSettings::default()
        };
        // Only the seeds, one each side of the wall below its top: no way round.
        let (roadmap, _) = SharedRoadmap::build(&space, &wall, &[vec![0.2, 0.5], vec![0.8, 0.5]], &settings);
        assert_eq!((roadmap.len(), roadmap.edge_count()), (2, 1));
        let found = roadmap.query(&space, &wall, &[0.2, 0.2], &[0.8, 0.2]);
        assert_eq!(found.waypoints, None);
        assert!(found.edges_examined >= 2, "it tried the way through the seeds");
        // One valid each side of the wall above its top, one inside it (dropped), a duplicate.
        let seeds = vec![vec![0.2, 0.9], vec![0.8, 0.9], vec![0.5, 0.5], vec![0.2, 0.9]];
        let (roadmap, _) = SharedRoadmap::build(&space, &wall, &seeds, &settings);
        assert_eq!((roadmap.len(), roadmap.edge_count()), (2, 1));
        let path = roadmap
            .query(&space, &wall, &[0.2, 0.2], &[0.8, 0.2])
            .waypoints
            .expect("over the seeds");
        assert_eq!(path.len(), 4);
    }
}

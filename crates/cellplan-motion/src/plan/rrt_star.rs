//! RRT*.
use super::problem::{Found, Run, range_of};
use super::solve_with;
use super::{JointSpace, MotionPlanner, PlanResult, PlannerParams, Problem, Status, Termination};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// RRT* (Karaman & Frazzoli 2011, Algorithm 6): one tree from the start; each new node
/// (steered at most [`PlannerParams::range`] from its nearest node) takes as parent the node
/// within the radius `min(γ (ln n / n)^(1/d), range)` that gives it the cheapest path, then
/// rewires those near nodes through itself when that shortens their path. Goals enter the
/// tree through goal-biased samples ([`PlannerParams::goal_bias`]); the path ends at the goal
/// node of least cost.
///
/// Anytime: it spends the whole budget ([`Termination`]) improving the best path and then
/// returns it ([`Status::Solved`]); with a fixed seed, a larger budget never gives a costlier
/// path before post-processing (the run with the smaller budget is a prefix of it, and
/// rewiring only lowers costs). `γ` is [`PlannerParams::rewire_factor`] times
/// `2 (1 + 1/d)^(1/d) (μ/ζ_d)^(1/d)`, `μ` the volume of the space's box in the metric (an
/// upper bound of the free volume), `ζ_d` that of the unit ball. Neighbours are found by a
/// linear scan: the cost of `n` samples grows as `n²`.
#[derive(Clone, Debug, Default)]
pub struct RrtStar {
    /// Its parameters.
    pub params: PlannerParams,
}

struct Tree {
    nodes: Vec<Vec<f64>>,
    parent: Vec<usize>,
    cost: Vec<f64>,
    children: Vec<Vec<usize>>,
    /// The goal (index in the query) a node is at.
    goal: Vec<Option<usize>>,
}

impl Tree {
    fn push(&mut self, q: Vec<f64>, parent: usize, cost: f64, goal: Option<usize>) -> usize {
        let i = self.nodes.len();
        self.nodes.push(q);
        self.parent.push(parent);
        self.cost.push(cost);
        self.children.push(Vec::new());
        self.goal.push(goal);
        if parent != usize::MAX {
            self.children[parent].push(i);
        }
        i
    }

    /// Makes `new_parent` the parent of `i`, at cost `cost`, and updates the subtree.
    fn reparent(&mut self, i: usize, new_parent: usize, cost: f64) {
        let old = self.parent[i];
        self.children[old].retain(|&c| c != i);
        self.children[new_parent].push(i);
        self.parent[i] = new_parent;
        let delta = cost - self.cost[i];
        let mut stack = vec![i];
        while let Some(k) = stack.pop() {
            self.cost[k] += delta;
            stack.extend_from_slice(&self.children[k]);
        }
    }

    fn path_to(&self, i: usize) -> Vec<Vec<f64>> {
        super::path_to_root(&self.nodes, &self.parent, i)
    }

    /// The goal node of least cost (the first on ties).
    fn best_goal(&self) -> Option<usize> {
        (0..self.nodes.len())
            .filter(|&i| self.goal[i].is_some())
            .min_by(|&a, &b| self.cost[a].total_cmp(&self.cost[b]).then(a.cmp(&b)))
    }
}

/// The dimension the search moves in: the joints whose range is not a single value (a joint
/// held fixed, as the CMM head's angles within an orientation group, adds no volume and must
/// not slow the shrinking of the rewiring radius).
fn free_dim(space: &JointSpace) -> usize {
    (0..space.dim())
        .filter(|&j| space.upper[j] > space.lower[j])
        .count()
        .max(1)
}

/// `2 (1 + 1/d)^(1/d) (μ/ζ_d)^(1/d)`: the smallest `γ` of the theorem, for the space's box.
fn gamma_min(space: &JointSpace) -> f64 {
    let d = free_dim(space) as f64;
    let volume: f64 = (0..space.dim())
        .map(|j| (space.weights[j] * (space.upper[j] - space.lower[j])).abs())
        .filter(|&w| w > 0.0)
        .product();
    // Volume of the unit ball in d dimensions: π^(d/2) / Γ(d/2 + 1).
    let half = d / 2.0;
    let gamma_fn = |x: f64| {
        // Γ at integers and half integers, enough here.
        let mut g = if x.fract() == 0.0 {
            1.0
        } else {
            std::f64::consts::PI.sqrt()
        };
        let mut y = if x.fract() == 0.0 { 1.0 } else { 0.5 };
        while y < x - 1e-9 {
            g *= y;
            y += 1.0;
        }
        g
    };
    let zeta = std::f64::consts::PI.powf(half) / gamma_fn(half + 1.0);
    2.0 * (1.0 + 1.0 / d).powf(1.0 / d) * (volume / zeta).powf(1.0 / d)
}

pub(crate) fn search(
    run: &mut Run,
    params: &PlannerParams,
    start: &[f64],
    goals: &[Vec<f64>],
    valid: &[usize],
) -> Found {
    let space = run.space;
    let range = range_of(space, params, 0.2);
    let d = free_dim(space) as f64;
    let gamma = params.rewire_factor * gamma_min(space);
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mut tree = Tree {
        nodes: Vec::new(),
        parent: Vec::new(),
        cost: Vec::new(),
        children: Vec::new(),
        goal: Vec::new(),
    };
    tree.push(start.to_vec(), usize::MAX, 0.0, None);
    let mut in_tree = vec![false; valid.len()];
    let mut q_rand = Vec::with_capacity(space.dim());
    let mut near = Vec::new();
    let stopped = loop {
        // The biased draw is made every iteration, so the random sequence does not depend on
        // which goals are in the tree.
        let u: f64 = rng.random_range(0.0..1.0);
        let pending: Vec<usize> = (0..valid.len()).filter(|&k| !in_tree[k]).collect();
        let target_goal = if u < params.goal_bias && !pending.is_empty() {
            let k = pending[rng.random_range(0..pending.len())];
            if let Err(why) = run.count_sample() {
                break why;
            }
            q_rand.clone_from(&goals[valid[k]]);
            Some(k)
        } else {
            if let Err(why) = run.sample(&mut rng, &mut q_rand) {
                break why;
            }
            None
        };
        let nearest = space.nearest(&tree.nodes, &q_rand);
        let dist = space.distance(&tree.nodes[nearest], &q_rand);
        let (q_new, reached) = if dist <= range {
            (q_rand.clone(), true)
        } else {
            let mut q = Vec::new();
            space.interpolate(&tree.nodes[nearest], &q_rand, range / dist, &mut q);
            (q, false)
        };
        if !run.segment(&tree.nodes[nearest], &q_new) {
            continue;
        }
        // Near nodes, by the cost they would give the new node.
        let n = (tree.nodes.len() + 1) as f64;
        let radius = (gamma * (n.ln() / n).powf(1.0 / d)).min(range);
        near.clear();
        for (i, q) in tree.nodes.iter().enumerate() {
            let di = space.distance(q, &q_new);
            if di <= radius || i == nearest {
                near.push((tree.cost[i] + di, di, i));
            }
        }
        near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        // Choose the parent: the cheapest near node whose segment is valid (the nearest's is).
        let mut best = (
            nearest,
            tree.cost[nearest] + space.distance(&tree.nodes[nearest], &q_new),
        );
        for &(c, _, i) in &near {
            if c >= best.1 || i == nearest {
                break;
            }
            if run.must_stop().is_some() {
                break;
            }
            if run.segment(&tree.nodes[i], &q_new) {
                best = (i, c);
                break;
            }
        }
        let goal = target_goal.filter(|_| reached).map(|k| {
            in_tree[k] = true;
            valid[k]
        });
        let new = tree.push(q_new, best.0, best.1, goal);
        // Rewire the near nodes through the new one.
        for &(_, di, i) in &near {
            if i == best.0 || tree.cost[new] + di >= tree.cost[i] - 1e-12 {
                continue;
            }
            if run.must_stop().is_some() {
                break;
            }
            if run.segment(&tree.nodes[new], &tree.nodes[i]) {
                let cost = tree.cost[new] + di;
                tree.reparent(i, new, cost);
            }
        }
    };
    if let Some(g) = tree.best_goal() {
        return Found::path(tree.path_to(g), tree.goal[g].expect("a goal node"));
    }
    if params.approximate {
        // The node nearest any valid goal, and that goal.
        let (node, goal) = (0..tree.nodes.len())
            .flat_map(|i| valid.iter().map(move |&g| (i, g)))
            .min_by(|a, b| {
                let da = space.distance(&tree.nodes[a.0], &goals[a.1]);
                let db = space.distance(&tree.nodes[b.0], &goals[b.1]);
                da.total_cmp(&db)
            })
            .expect("the start is in the tree");
        let mut found = Found::path(tree.path_to(node), goal);
        found.status = Status::Approximate;
        return found;
    }
    Found::none(stopped)
}

impl MotionPlanner for RrtStar {
    fn name(&self) -> &'static str {
        "rrt-star"
    }

    fn solve(&mut self, problem: &Problem, stop: &Termination) -> PlanResult {
        solve_with(problem, stop, &self.params, |run, valid| {
            search(run, &self.params, problem.start, problem.goals, valid)
        })
    }
}

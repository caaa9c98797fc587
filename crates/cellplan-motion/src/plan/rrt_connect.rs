//! RRT-Connect.
use super::problem::{Found, Run, range_of};
use super::{
    JointSpace, MotionPlanner, PlanError, PlanResult, PlanSettings, PlannedPath, Planner, PlannerParams,
    Problem, StateValidity, Termination, solve_with,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// RRT-Connect (Kuffner & LaValle 2000): two trees, one rooted at the start, the other at
/// every valid goal (a forest), grown in turn towards random samples (with
/// [`PlannerParams::balance`], a tree less than half the other's size again); after each
/// extension the other tree greedily connects to the new node. With
/// [`PlannerParams::dynamic_domain`], a node whose extension failed is extended only towards
/// samples within its domain. The path ends at the goal whose root the connection reached.
/// Every edge passes [`super::check_segment`]. Deterministic for a seed (ChaCha8); uses
/// [`PlannerParams::seed`], [`PlannerParams::range`] (or [`PlannerParams::range_share`]),
/// those two and the post-processing settings.
#[derive(Clone, Debug, Default)]
pub struct RrtConnect {
    /// Its parameters (for [`MotionPlanner::solve`]; [`Planner::plan`] takes them from its
    /// settings).
    pub params: PlannerParams,
}

/// The dynamic domain's radius after a node's first failed extension, in ranges (VAMP's UR5
/// settings: 4 against a range of 1.5).
const DOMAIN_RADIUS: f64 = 4.0 / 1.5;

/// The smallest dynamic-domain radius, in ranges (VAMP: 1 against 1.5).
const DOMAIN_MIN: f64 = 1.0 / 1.5;

/// A failed extension shrinks its node's radius by this share, a successful one from a node
/// with a radius grows it by as much (Yershova et al.'s adaptive variant, as VAMP tunes it).
const DOMAIN_ALPHA: f64 = 1e-4;

struct Tree {
    nodes: Vec<Vec<f64>>,
    parent: Vec<usize>,
    /// For each node, the index of its root's query end (0 for the start, else the goal's).
    origin: Vec<usize>,
    /// For each node, its dynamic domain: samples farther from it than this are not extended
    /// from it (infinite until an extension from it fails).
    domain: Vec<f64>,
}

impl Tree {
    fn new(roots: impl IntoIterator<Item = (Vec<f64>, usize)>) -> Self {
        let mut tree = Tree {
            nodes: Vec::new(),
            parent: Vec::new(),
            origin: Vec::new(),
            domain: Vec::new(),
        };
        for (q, origin) in roots {
            tree.push(q, usize::MAX, origin);
        }
        tree
    }

    fn push(&mut self, q: Vec<f64>, parent: usize, origin: usize) -> usize {
        self.nodes.push(q);
        self.parent.push(parent);
        self.origin.push(origin);
        self.domain.push(f64::INFINITY);
        self.nodes.len() - 1
    }

    /// An extension from node `i` failed (`ok` false) or succeeded: its domain shrinks (set
    /// on the first failure) or grows, never below `min`.
    fn learn(&mut self, i: usize, ok: bool, (radius, min): (f64, f64)) {
        let r = &mut self.domain[i];
        *r = match (ok, r.is_finite()) {
            (false, false) => radius,
            (false, true) => (*r * (1.0 - DOMAIN_ALPHA)).max(min),
            (true, true) => *r * (1.0 + DOMAIN_ALPHA),
            (true, false) => return,
        };
    }

    /// Root-to-node path.
    fn path_to(&self, i: usize) -> Vec<Vec<f64>> {
        super::path_to_root(&self.nodes, &self.parent, i)
    }
}

enum Extend {
    Trapped,
    Advanced(usize),
    Reached(usize),
}

/// One RRT extension of `tree` from node `from` towards `target`.
fn extend_from(run: &mut Run, range: f64, tree: &mut Tree, from: usize, target: &[f64]) -> Extend {
    let near = &tree.nodes[from];
    let d = run.space.distance(near, target);
    let (q_new, reached) = if d <= range {
        (target.to_vec(), true)
    } else {
        let mut q = Vec::new();
        run.space.interpolate(near, target, range / d, &mut q);
        (q, false)
    };
    if !run.segment(near, &q_new) {
        return Extend::Trapped;
    }
    let i = tree.push(q_new, from, tree.origin[from]);
    if reached {
        Extend::Reached(i)
    } else {
        Extend::Advanced(i)
    }
}

/// Extends `tree` towards `target` until it is reached, the tree is trapped or the run must
/// stop.
fn connect(run: &mut Run, range: f64, tree: &mut Tree, target: &[f64]) -> Option<usize> {
    let mut from = run.space.nearest(&tree.nodes, target);
    loop {
        match extend_from(run, range, tree, from, target) {
            Extend::Trapped => return None,
            Extend::Reached(i) => return Some(i),
            Extend::Advanced(i) => from = i,
        }
        if run.must_stop().is_some() {
            return None;
        }
    }
}

/// The search of [`RrtConnect`], shared with [`super::Leg`].
pub(crate) fn search(
    run: &mut Run,
    params: &PlannerParams,
    start: &[f64],
    goals: &[Vec<f64>],
    valid: &[usize],
) -> Found {
    let range = range_of(run.space, params, params.range_share);
    let domain = (DOMAIN_RADIUS * range, DOMAIN_MIN * range);
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    // trees[0] grows from the start, trees[1] from the goals; `a` is the one extended.
    let mut trees = [
        Tree::new([(start.to_vec(), 0)]),
        Tree::new(valid.iter().map(|&g| (goals[g].clone(), g))),
    ];
    let mut a = 0;
    let mut q_rand = Vec::with_capacity(run.space.dim());
    loop {
        if let Err(why) = run.sample(&mut rng, &mut q_rand) {
            return Found::none(why);
        }
        let (x, y) = trees.split_at_mut(1);
        let (ta, tb) = if a == 0 {
            (&mut x[0], &mut y[0])
        } else {
            (&mut y[0], &mut x[0])
        };
        let from = run.space.nearest(&ta.nodes, &q_rand);
        // Dynamic domain (Yershova et al. 2005): a node whose extension failed before is
        // extended only towards samples within its radius, so that samples behind the
        // obstacles it met cost no segment check.
        let new = if params.dynamic_domain && run.space.distance(&ta.nodes[from], &q_rand) > ta.domain[from] {
            None
        } else {
            let new = match extend_from(run, range, ta, from, &q_rand) {
                Extend::Trapped => None,
                Extend::Advanced(i) | Extend::Reached(i) => Some(i),
            };
            if params.dynamic_domain {
                ta.learn(from, new.is_some(), domain);
            }
            new
        };
        if let Some(i) = new {
            let target = ta.nodes[i].clone();
            if let Some(j) = connect(run, range, tb, &target) {
                let (si, gi) = if a == 0 { (i, j) } else { (j, i) };
                let mut waypoints = trees[0].path_to(si);
                let mut back = trees[1].path_to(gi);
                back.reverse();
                // The meeting node is in both halves.
                back.remove(0);
                waypoints.extend(back);
                return Found::path(waypoints, trees[1].origin[gi]);
            }
        }
        // Balanced (as VAMP): a tree less than half the other's size is extended again.
        if !params.balance || trees[1 - a].nodes.len() < 2 * trees[a].nodes.len() {
            a = 1 - a;
        }
    }
}

impl MotionPlanner for RrtConnect {
    fn name(&self) -> &'static str {
        "rrt-connect"
    }

    fn solve(&mut self, problem: &Problem, stop: &Termination) -> PlanResult {
        solve_with(problem, stop, &self.params, |run, valid| {
            search(run, &self.params, problem.start, problem.goals, valid)
        })
    }
}

impl Planner for RrtConnect {
    fn name(&self) -> &str {
        "rrt-connect"
    }

    /// The raw RRT-Connect path (no post-processing), with the parameters of `settings`.
    fn plan(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        settings: &PlanSettings,
    ) -> Result<PlannedPath, PlanError> {
        let params = PlannerParams {
            simplify: false,
            ..settings.params()
        };
        settings.with_problem(space, validity, start, goal, |problem| {
            solve_with(problem, &settings.termination(), &params, |run, valid| {
                search(run, &params, start, problem.goals, valid)
            })
            .into_planned()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A node's domain is unbounded until an extension from it fails, then the set radius,
    /// shrinking with each failure down to the smallest, growing with each success.
    #[test]
    fn dynamic_domains_shrink_on_failure_and_grow_on_success() {
        let mut tree = Tree::new([(vec![0.0], 0)]);
        let (radius, min) = (4.0, 1.0);
        tree.learn(0, true, (radius, min));
        assert_eq!(tree.domain[0], f64::INFINITY);
        tree.learn(0, false, (radius, min));
        assert_eq!(tree.domain[0], radius);
        tree.learn(0, false, (radius, min));
        assert_eq!(tree.domain[0], radius * (1.0 - DOMAIN_ALPHA));
        tree.learn(0, true, (radius, min));
        assert_eq!(
            tree.domain[0],
            radius * (1.0 - DOMAIN_ALPHA) * (1.0 + DOMAIN_ALPHA)
        );
        for _ in 0..200_000 {
            tree.learn(0, false, (radius, min));
        }
        assert_eq!(tree.domain[0], min);
        let i = tree.push(vec![1.0], 0, 0);
        assert_eq!(tree.domain[i], f64::INFINITY);
    }
}

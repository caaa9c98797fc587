//! RRT-Connect.
use super::{
    JointSpace, PlanError, PlanSettings, PlannedPath, Planner, StateValidity, check_ends, segment_valid,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// RRT-Connect (Kuffner & LaValle 2000): two trees, rooted at the start and the goal, grown in
/// turn towards random samples; after each extension the other tree greedily connects to the
/// new node. Every edge passes [`check_segment`]. Deterministic for a seed (ChaCha8).
#[derive(Clone, Copy, Debug, Default)]
pub struct RrtConnect;

struct Tree {
    nodes: Vec<Vec<f64>>,
    parent: Vec<usize>,
}

impl Tree {
    fn new(root: &[f64]) -> Self {
        Tree {
            nodes: vec![root.to_vec()],
            parent: vec![usize::MAX],
        }
    }

    fn nearest(&self, space: &JointSpace, q: &[f64]) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = space.distance(n, q);
            if d < best.1 {
                best = (i, d);
            }
        }
        best.0
    }

    /// Root-to-node path.
    fn path_to(&self, mut i: usize) -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        while i != usize::MAX {
            out.push(self.nodes[i].clone());
            i = self.parent[i];
        }
        out.reverse();
        out
    }
}

enum Extend {
    Trapped,
    Advanced(usize),
    Reached(usize),
}

struct Search<'a> {
    space: &'a JointSpace,
    validity: &'a dyn StateValidity,
    range: f64,
    min_clearance: f64,
    calls: usize,
}

impl Search<'_> {
    /// One RRT extension of `tree` from node `from` towards `target`.
    fn extend_from(&mut self, tree: &mut Tree, from: usize, target: &[f64]) -> Extend {
        let near = &tree.nodes[from];
        let d = self.space.distance(near, target);
        let (q_new, reached) = if d <= self.range {
            (target.to_vec(), true)
        } else {
            let mut q = Vec::new();
            self.space.interpolate(near, target, self.range / d, &mut q);
            (q, false)
        };
        if !segment_valid(
            self.space,
            self.validity,
            near,
            &q_new,
            self.min_clearance,
            &mut self.calls,
        ) {
            return Extend::Trapped;
        }
        tree.nodes.push(q_new);
        tree.parent.push(from);
        let i = tree.nodes.len() - 1;
        if reached {
            Extend::Reached(i)
        } else {
            Extend::Advanced(i)
        }
    }

    fn extend(&mut self, tree: &mut Tree, target: &[f64]) -> Extend {
        let from = tree.nearest(self.space, target);
        self.extend_from(tree, from, target)
    }

    /// Extends `tree` towards `target` until it is reached or the tree is trapped.
    fn connect(&mut self, tree: &mut Tree, target: &[f64]) -> Option<usize> {
        let mut from = tree.nearest(self.space, target);
        loop {
            match self.extend_from(tree, from, target) {
                Extend::Trapped => return None,
                Extend::Reached(i) => return Some(i),
                Extend::Advanced(i) => from = i,
            }
        }
    }
}

impl Planner for RrtConnect {
    fn name(&self) -> &str {
        "rrt-connect"
    }

    fn plan(
        &self,
        space: &JointSpace,
        validity: &dyn StateValidity,
        start: &[f64],
        goal: &[f64],
        settings: &PlanSettings,
    ) -> Result<PlannedPath, PlanError> {
        let began = Instant::now();
        check_ends(space, validity, start, goal, settings)?;
        let range = if settings.range > 0.0 {
            settings.range
        } else {
            (0.2 * space.extent()).max(1e-6)
        };
        let mut search = Search {
            space,
            validity,
            range,
            min_clearance: settings.min_clearance,
            calls: 2,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
        // trees[0] grows from the start, trees[1] from the goal; `a` is the one extended.
        let mut trees = [Tree::new(start), Tree::new(goal)];
        let mut a = 0;
        let mut samples = 0;
        let mut q_rand = Vec::with_capacity(space.dim());
        while samples < settings.max_samples && began.elapsed() < settings.time_limit {
            space.sample(&mut rng, &mut q_rand);
            samples += 1;
            let (ta, tb) = if a == 0 {
                let (x, y) = trees.split_at_mut(1);
                (&mut x[0], &mut y[0])
            } else {
                let (x, y) = trees.split_at_mut(1);
                (&mut y[0], &mut x[0])
            };
            let new = match search.extend(ta, &q_rand) {
                Extend::Trapped => None,
                Extend::Advanced(i) | Extend::Reached(i) => Some(i),
            };
            if let Some(i) = new {
                let target = ta.nodes[i].clone();
                if let Some(j) = search.connect(tb, &target) {
                    let (si, gi) = if a == 0 { (i, j) } else { (j, i) };
                    let mut waypoints = trees[0].path_to(si);
                    let mut back = trees[1].path_to(gi);
                    back.reverse();
                    // The meeting node is in both halves.
                    back.remove(0);
                    waypoints.extend(back);
                    return Ok(PlannedPath {
                        waypoints,
                        straight: false,
                        samples,
                        validity_calls: search.calls,
                    });
                }
            }
            a = 1 - a;
        }
        Err(PlanError::NoPath {
            samples,
            validity_calls: search.calls,
        })
    }
}

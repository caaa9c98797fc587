//! The state space: a box of joint values, its metric and its motion bound.
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

/// A box of joint values with what the motion check and the metric need.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpace {
    /// Lower joint limits (rad or m).
    pub lower: Vec<f64>,
    /// Upper joint limits (rad or m).
    pub upper: Vec<f64>,
    /// Cartesian displacement bound per joint: along the straight segment from `a` to `b`
    /// every point of every moving body moves at most `Σ_j radii[j]·|a_j − b_j|` (m). For a
    /// revolute joint, at least the largest distance from its axis of any point it carries;
    /// 1 for a prismatic joint.
    pub radii: Vec<f64>,
    /// Metric weights for nearest neighbours, steering and path length: the distance is
    /// `sqrt(Σ_j (weights[j]·(a_j − b_j))²)`. `1/v_max` makes it time-like.
    pub weights: Vec<f64>,
    /// Per joint, whether values a full turn (2π) apart pose every body the same (a revolute
    /// or continuous joint): a path's interior waypoints may then take such a joint a whole
    /// number of turns from where they have it without changing what stands there (see
    /// [`super::straighten_joints_timed`]). False for joints not listed.
    pub turns: Vec<bool>,
}

impl JointSpace {
    /// A space with unit metric weights.
    pub fn new(lower: Vec<f64>, upper: Vec<f64>, radii: Vec<f64>) -> Self {
        let weights = vec![1.0; lower.len()];
        JointSpace {
            lower,
            upper,
            radii,
            weights,
            turns: Vec::new(),
        }
    }

    /// The same space with the joints whose values a full turn apart pose every body the same
    /// marked (see [`JointSpace::turns`]).
    pub fn with_turns(mut self, turns: Vec<bool>) -> Self {
        self.turns = turns;
        self
    }

    /// Whether joint `j` turns ([`JointSpace::turns`]) over a range wider than a full turn:
    /// only there can a value move by whole turns and stay within the limits.
    pub fn winds(&self, j: usize) -> bool {
        self.turns.get(j).copied().unwrap_or(false)
            && matches!((self.lower.get(j), self.upper.get(j)), (Some(lo), Some(hi)) if hi - lo > std::f64::consts::TAU)
    }

    /// The same space with other metric weights (one per joint).
    pub fn with_weights(mut self, weights: Vec<f64>) -> Self {
        self.weights = weights;
        self
    }

    /// Number of joints.
    pub fn dim(&self) -> usize {
        self.lower.len()
    }

    /// Whether `q` has one finite value per joint, each within its limits (tolerance 1e-9).
    pub fn contains(&self, q: &[f64]) -> bool {
        q.len() == self.dim()
            && q.iter()
                .zip(self.lower.iter().zip(&self.upper))
                .all(|(&v, (&lo, &hi))| v.is_finite() && v >= lo - 1e-9 && v <= hi + 1e-9)
    }

    /// Bound on the Cartesian displacement of any body point along the segment `a → b`:
    /// `Σ_j radii[j]·|a_j − b_j|`.
    pub fn cartesian_bound(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.radii)
            .map(|((x, y), r)| r * (x - y).abs())
            .sum()
    }

    /// Weighted Euclidean distance `sqrt(Σ_j (weights[j]·(a_j − b_j))²)`.
    pub fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .zip(&self.weights)
            .map(|((x, y), w)| {
                let d = w * (x - y);
                d * d
            })
            .sum::<f64>()
            .sqrt()
    }

    /// `a + t·(b − a)` into `out`.
    pub fn interpolate(&self, a: &[f64], b: &[f64], t: f64, out: &mut Vec<f64>) {
        out.clear();
        out.extend(a.iter().zip(b).map(|(x, y)| x + t * (y - x)));
    }

    /// The distance between opposite corners of the box.
    pub fn extent(&self) -> f64 {
        self.distance(&self.lower, &self.upper)
    }

    /// Index of the node of `nodes` nearest to `q` (the first on ties; 0 when empty).
    ///
    /// Compares squared distances (no square root per node; the scan is a large share of a
    /// sampling planner's time, and a branch per joint costs more than it saves).
    pub(crate) fn nearest(&self, nodes: &[Vec<f64>], q: &[f64]) -> usize {
        let mut best = (0, f64::INFINITY);
        for (i, n) in nodes.iter().enumerate() {
            let d2: f64 = n
                .iter()
                .zip(q)
                .zip(&self.weights)
                .map(|((x, y), w)| {
                    let d = w * (x - y);
                    d * d
                })
                .sum();
            if d2 < best.1 {
                best = (i, d2);
            }
        }
        best.0
    }

    pub(crate) fn sample(&self, rng: &mut ChaCha8Rng, out: &mut Vec<f64>) {
        out.clear();
        out.extend(
            self.lower.iter().zip(&self.upper).map(
                |(&lo, &hi)| {
                    if hi > lo { rng.random_range(lo..hi) } else { lo }
                },
            ),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// The scan with squared distances and early exits finds the node a plain scan of the
    /// weighted distances finds (the first of the nearest).
    #[test]
    fn nearest_is_the_first_nearest_node() {
        let space = JointSpace::new(vec![-3.0; 6], vec![3.0; 6], vec![1.0; 6])
            .with_weights(vec![1.0, 0.5, 2.0, 1.0, 0.25, 1.5]);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut q = Vec::new();
        for round in 0..200 {
            let mut nodes: Vec<Vec<f64>> = (0..1 + round % 60)
                .map(|_| {
                    space.sample(&mut rng, &mut q);
                    q.clone()
                })
                .collect();
            // Duplicates: ties go to the first.
            if nodes.len() > 3 {
                nodes[3] = nodes[1].clone();
            }
            space.sample(&mut rng, &mut q);
            let plain = nodes
                .iter()
                .enumerate()
                .fold((0, f64::INFINITY), |b, (i, n)| {
                    let d = space.distance(n, &q);
                    if d < b.1 { (i, d) } else { b }
                })
                .0;
            let found = space.nearest(&nodes, &q);
            assert_eq!(
                space.distance(&nodes[found], &q),
                space.distance(&nodes[plain], &q),
                "round {round}"
            );
            assert!(found <= plain, "round {round}: {found} after {plain}");
        }
    }
}

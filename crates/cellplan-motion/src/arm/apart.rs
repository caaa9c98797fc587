//! Self pairs that can never touch: proven apart over the whole range of the joints between
//! them, so that checking them can only cost time.
//!
//! A pair's distance depends only on the joints between its two bodies, and falls no faster
//! than its radii allow ([`super::pair_radii`]: `|∂d/∂q_k| ≤ L_k`). So over a box of joint
//! values with centre `c` and half-widths `h`, the distance is at least `d(c) − Σ L_k·h_k`;
//! a box where that is positive holds no contact. Boxes that are not proven are halved (across
//! the joint that contributes most) until every box is proven — the pair is apart everywhere
//! — or a centre is found in contact, or the budget of distance queries runs out (then the
//! pair stays checked). A turning joint's range is cut to one turn: its bodies' poses repeat.
//! Boxes are visited lowest bound first, so a pair that does touch is usually found out after
//! a few queries.
use super::{Arm, DISTANCE_SLACK, body_radii, moved_by, pair_radii};
use cellplan_geom::Pose;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Distance queries allowed per pair by [`pairs_that_may_touch`].
pub const APART_BUDGET: usize = 4000;

/// A box of joint values with the lower bound it inherited from its parent.
struct Cell {
    bound: f64,
    centre: Vec<f64>,
    half: Vec<f64>,
}

impl PartialEq for Cell {
    fn eq(&self, other: &Self) -> bool {
        self.bound.total_cmp(&other.bound) == Ordering::Equal
    }
}
impl Eq for Cell {}
impl PartialOrd for Cell {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Cell {
    /// Lowest bound first (the heap is a max-heap).
    fn cmp(&self, other: &Self) -> Ordering {
        other.bound.total_cmp(&self.bound)
    }
}

/// Whether bodies `i` and `j` of `arm` are apart — farther than the slack that counts as
/// contact — in every configuration within the joint limits, proven with at most `budget`
/// distance queries (see the module documentation). False when not proven.
pub fn apart_everywhere(arm: &Arm, i: usize, j: usize, budget: usize) -> bool {
    let (a, b) = (moved_by(arm, i), moved_by(arm, j));
    let (near, far, first, end) = if b >= a { (i, j, a, b) } else { (j, i, b, a) };
    let radii = pair_radii(arm, near, first, &body_radii(arm, far));
    let chain = arm.chain;
    let mut q = chain.mid_configuration();
    let mut centre = Vec::new();
    let mut half = Vec::new();
    for k in first..end {
        let (Some(joint), Some(&l)) = (chain.joints.get(k), radii.get(k)) else {
            return false;
        };
        let (lo, mut hi) = (joint.lower, joint.upper);
        if joint.is_rotational() {
            hi = hi.min(lo + std::f64::consts::TAU);
        }
        if !(lo.is_finite() && hi.is_finite() && l.is_finite() && hi >= lo) {
            return false;
        }
        centre.push(0.5 * (lo + hi));
        half.push(0.5 * (hi - lo));
    }
    let needed = 2.0 * DISTANCE_SLACK;
    let (mut links, mut poses) = (Vec::new(), Vec::<Pose>::new());
    let mut heap = BinaryHeap::from([Cell {
        bound: f64::NEG_INFINITY,
        centre,
        half,
    }]);
    let mut queries = 0;
    while let Some(cell) = heap.pop() {
        if queries >= budget {
            return false;
        }
        queries += 1;
        q[first..end].copy_from_slice(&cell.centre);
        arm.body_poses(&q, &mut links, &mut poses);
        let spread: f64 = cell.half.iter().zip(&radii[first..end]).map(|(h, l)| h * l).sum();
        // Asked only as far as the box needs.
        let d = arm
            .world
            .pair_distance(arm.group, i, j, &poses, spread + 2.0 * needed);
        if d <= needed {
            return false;
        }
        let bound = d - spread;
        if bound > needed {
            continue;
        }
        // Halve across the joint that widens the bound most.
        let Some(k) = (0..cell.half.len())
            .max_by(|&x, &y| (cell.half[x] * radii[first + x]).total_cmp(&(cell.half[y] * radii[first + y])))
        else {
            return false;
        };
        for side in [-1.0, 1.0] {
            let mut centre = cell.centre.clone();
            let mut half = cell.half.clone();
            half[k] *= 0.5;
            centre[k] += side * half[k];
            heap.push(Cell { bound, centre, half });
        }
    }
    true
}

/// The self pairs of `arm` not proven apart everywhere ([`apart_everywhere`], each with
/// [`APART_BUDGET`] queries): the only ones a validity check needs.
pub fn pairs_that_may_touch(arm: &Arm) -> Vec<(usize, usize)> {
    arm.self_pairs
        .iter()
        .copied()
        .filter(|&(i, j)| !apart_everywhere(arm, i, j, APART_BUDGET))
        .collect()
}

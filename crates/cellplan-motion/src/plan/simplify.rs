//! Path post-processing: shortcuts and redundant waypoints.
use super::{JointSpace, PlanSettings, StateValidity, check_segment};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Shortcutting stops after this many attempts in a row that did not shorten the path (by
/// [`MIN_GAIN`] at least).
const MAX_MISSES: usize = 15;

/// A shortcut gaining less than this share of the path's length is a miss.
const MIN_GAIN: f64 = 0.005;

/// Length of a polyline in the space's metric.
pub fn path_length(space: &JointSpace, waypoints: &[Vec<f64>]) -> f64 {
    waypoints.windows(2).map(|w| space.distance(&w[0], &w[1])).sum()
}

/// Shortens a valid path in place and returns the validity calls made: removes repeated
/// waypoints, then `settings.shortcut_iterations` random shortcuts between two points on
/// different segments (partial shortcuts, deterministic for `settings.seed`), then removes
/// redundant waypoints (each waypoint whose neighbours see each other). A change is kept only
/// when the new segment passes [`check_segment`] and the path gets shorter, so the path never
/// lengthens (the metric is a norm) and stays valid. The planners of the registry apply the
/// same post-processing when [`super::PlannerParams::simplify`] is set.
pub fn shortcut(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    settings: &PlanSettings,
) -> usize {
    shortcut_with(
        space,
        validity,
        waypoints,
        settings.seed,
        settings.shortcut_iterations,
        settings.min_clearance,
    )
}

/// [`shortcut`] with its settings spelled out.
pub(crate) fn shortcut_with(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    seed: u64,
    iterations: usize,
    min_clearance: f64,
) -> usize {
    let mut calls = 0;
    waypoints.dedup_by(|b, a| space.distance(a, b) == 0.0);
    calls += remove_redundant(space, validity, waypoints, min_clearance);
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5348_4f52_5443_5554);
    let (mut p1, mut p2) = (Vec::new(), Vec::new());
    let mut misses = 0;
    for _ in 0..iterations {
        if misses >= MAX_MISSES {
            break;
        }
        let segments = waypoints.len().saturating_sub(1);
        if segments < 2 {
            break;
        }
        let i = rng.random_range(0..segments);
        let j = rng.random_range(0..segments);
        let (i, j) = (i.min(j), i.max(j));
        if i == j {
            continue;
        }
        let (t1, t2): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        space.interpolate(&waypoints[i], &waypoints[i + 1], t1, &mut p1);
        space.interpolate(&waypoints[j], &waypoints[j + 1], t2, &mut p2);
        let old = space.distance(&p1, &waypoints[i + 1])
            + path_length(space, &waypoints[i + 1..=j])
            + space.distance(&waypoints[j], &p2);
        if space.distance(&p1, &p2) >= old - 1e-9 {
            misses += 1;
            continue;
        }
        let check = check_segment(space, validity, &p1, &p2, min_clearance);
        calls += check.calls;
        // A shortcut that gains little counts as a miss too: the path is near its local
        // optimum, and every further shortcut costs a whole segment check.
        let gain = old - space.distance(&p1, &p2);
        misses = if check.valid && gain >= MIN_GAIN * path_length(space, waypoints) {
            0
        } else {
            misses + 1
        };
        if check.valid {
            // waypoints[..=i], p1, p2, waypoints[j+1..]
            let tail = waypoints.split_off(j + 1);
            waypoints.truncate(i + 1);
            waypoints.push(p1.clone());
            waypoints.push(p2.clone());
            waypoints.extend(tail);
            waypoints.dedup_by(|b, a| space.distance(a, b) <= 1e-12);
        }
    }
    calls += remove_redundant(space, validity, waypoints, min_clearance);
    calls
}

/// Drops every waypoint whose neighbours see each other directly; returns the calls made.
fn remove_redundant(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    min_clearance: f64,
) -> usize {
    let mut calls = 0;
    let mut i = 0;
    while i + 2 < waypoints.len() {
        let check = check_segment(space, validity, &waypoints[i], &waypoints[i + 2], min_clearance);
        calls += check.calls;
        if check.valid {
            waypoints.remove(i + 1);
        } else {
            i += 1;
        }
    }
    calls
}

//! Path post-processing: shortcuts and redundant waypoints.
use super::{JointSpace, PlanSettings, StateValidity, check_segment};
use crate::timing::{Limits, segment_time, time_path_exact};
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
        (settings.seed, settings.shortcut_iterations),
        settings.min_clearance,
        false,
    )
}

/// [`shortcut`] for a path that is timed stopping at every waypoint: shortens its time under
/// `limits` (each segment from rest to rest, [`segment_time`]) instead of its length. A
/// shortcut that cuts a corner with two new waypoints adds a stop, and is kept only when the
/// time saved on the way pays for it; half of the shortcuts are drawn from a waypoint (the
/// start of a segment) and half to one (the end of a segment), so that corners are also
/// removed, not only cut. Never lengthens the path's time; the path stays valid. Same
/// settings, work and determinism as [`shortcut`].
pub fn shortcut_timed(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    settings: &PlanSettings,
    limits: &Limits,
) -> usize {
    let cost = |a: &[f64], b: &[f64]| segment_time(a, b, limits);
    shortcut_by(
        space,
        validity,
        waypoints,
        (settings.seed, settings.shortcut_iterations, false),
        settings.min_clearance,
        Some(&cost),
    )
}

/// A whole path's cost (its time).
type PathCost<'a> = &'a dyn Fn(&[Vec<f64>]) -> f64;

/// A segment's cost: its time (rest to rest) when shortcutting for time.
type SegmentCost<'a> = &'a dyn Fn(&[f64], &[f64]) -> f64;

/// [`shortcut`] with its settings spelled out; `skip_small`: a shortcut that would gain less
/// than [`MIN_GAIN`] is not checked (see [`super::PlannerParams::skip_small_shortcuts`]).
pub(crate) fn shortcut_with(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    (seed, iterations): (u64, usize),
    min_clearance: f64,
    skip_small: bool,
) -> usize {
    shortcut_by(
        space,
        validity,
        waypoints,
        (seed, iterations, skip_small),
        min_clearance,
        None,
    )
}

/// The shortcut loop: by length in the space's metric, or by `timed` segment costs.
fn shortcut_by(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    (seed, iterations, skip_small): (u64, usize, bool),
    min_clearance: f64,
    timed: Option<SegmentCost<'_>>,
) -> usize {
    let seg = |a: &[f64], b: &[f64]| match timed {
        Some(cost) => cost(a, b),
        None => space.distance(a, b),
    };
    let total = |w: &[Vec<f64>]| w.windows(2).map(|p| seg(&p[0], &p[1])).sum::<f64>();
    let mut calls = 0;
    waypoints.dedup_by(|b, a| space.distance(a, b) == 0.0);
    calls += remove_redundant(space, validity, waypoints, min_clearance, &seg);
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
        let (mut t1, mut t2): (f64, f64) = (rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
        if timed.is_some() {
            // Half from a waypoint and half to one: a shortcut that removes corners adds no
            // stop.
            if rng.random_bool(0.5) {
                t1 = 0.0;
            } else {
                t2 = 1.0;
            }
        }
        space.interpolate(&waypoints[i], &waypoints[i + 1], t1, &mut p1);
        space.interpolate(&waypoints[j], &waypoints[j + 1], t2, &mut p2);
        let (old, new) = match timed {
            // Rest to rest: the pieces before p1 and after p2 are crossed on their own.
            Some(_) => (
                total(&waypoints[i..=j + 1]),
                seg(&waypoints[i], &p1) + seg(&p1, &p2) + seg(&p2, &waypoints[j + 1]),
            ),
            None => (
                seg(&p1, &waypoints[i + 1]) + total(&waypoints[i + 1..=j]) + seg(&waypoints[j], &p2),
                seg(&p1, &p2),
            ),
        };
        if new >= old - 1e-9 {
            misses += 1;
            continue;
        }
        let gain = old - new;
        // A shortcut that gains little counts as a miss even when valid: the path is near its
        // local optimum, and every further shortcut costs a whole segment check. With
        // `skip_small` it is not checked at all.
        let small = gain < MIN_GAIN * total(waypoints);
        if skip_small && small {
            misses += 1;
            continue;
        }
        let check = check_segment(space, validity, &p1, &p2, min_clearance);
        calls += check.calls;
        misses = if check.valid && !small { 0 } else { misses + 1 };
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
    calls += remove_redundant(space, validity, waypoints, min_clearance, &seg);
    calls
}

/// A path's needless joint motion removed, for a path timed stopping at its corners under
/// `limits` (the path's time as [`time_path_exact`] gives it): partial shortcuts of one joint
/// at a time (`straighten_joints`; [`segment_time`] shares a joint's move out over the
/// segments), up to `attempts` of them, deterministic for `seed`; where the turns its turning
/// joints need not make can be taken back (`unwind`), the same shortcuts are also made on the
/// unwound path, which is kept if it ends faster (each can trap the other's shortcuts in a
/// worse local optimum). Never slows the path by that timing, keeps its
/// waypoints' count and its ends, and keeps it valid (every changed segment passes
/// [`check_segment`] at `min_clearance`). Returns the validity calls made.
pub fn straighten_joints_timed(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut [Vec<f64>],
    (seed, attempts): (u64, usize),
    min_clearance: f64,
    limits: &Limits,
) -> usize {
    let seg = |a: &[f64], b: &[f64]| segment_time(a, b, limits);
    let whole =
        |p: &[Vec<f64>]| time_path_exact(p, limits).map_or(f64::INFINITY, |t| t.trajectory.duration());
    let straighten = |waypoints: &mut [Vec<f64>]| {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x4a4f_494e_5453_4855);
        straighten_joints(
            space,
            validity,
            waypoints,
            (&mut rng, attempts),
            min_clearance,
            (&seg, &whole),
        )
    };
    // Unwound first: a path that does not change needs no second straightening.
    let mut unwound = waypoints.to_vec();
    let mut calls = unwind(space, validity, &mut unwound, min_clearance, &whole);
    let changed = unwound != waypoints;
    calls += straighten(waypoints);
    if changed {
        calls += straighten(&mut unwound);
        if whole(&unwound) < whole(waypoints) {
            waypoints.clone_from_slice(&unwound);
        }
    }
    calls
}

/// Partial shortcuts of one joint at a time (Geraerts and Overmars, "Creating high-quality
/// paths for motion planning", 2007): up to `attempts` times (stopping after [`MAX_MISSES`]
/// misses in a row), a joint drawn in proportion to how far it moves beyond what it must (the
/// sum of its moves less its net move) and two waypoints `i < j` at least two apart; between
/// them that joint moves straight from its value at `i` to its value at `j`, shared out over
/// the segments in proportion to what each costs by `seg` without it (so that it rides on the
/// other joints' motion), while the other joints keep their course. The waypoints stay where
/// they are along the path, so no stop is added. Kept only when the path's cost by `whole`
/// falls and every changed segment passes [`check_segment`]. Removes the detours of joints that the
/// obstacles do not ask for (a wrist swung round and back by the sampler, which a shortcut of
/// all joints at once cannot remove where the other joints' detour is needed). Returns the
/// validity calls made.
fn straighten_joints(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut [Vec<f64>],
    (rng, attempts): (&mut ChaCha8Rng, usize),
    min_clearance: f64,
    (seg, whole): (SegmentCost<'_>, PathCost<'_>),
) -> usize {
    let n = waypoints.len();
    if n < 3 {
        return 0;
    }
    let dof = waypoints[0].len();
    let mut calls = 0;
    let mut misses = 0;
    let mut trial: Vec<Vec<f64>> = Vec::with_capacity(n);
    let mut without = Vec::with_capacity(dof);
    // Each joint's motion beyond its net move, and the path's cost: they change only when an
    // attempt is kept.
    let excess_of = |waypoints: &[Vec<f64>]| -> Vec<f64> {
        (0..dof)
            .map(|d| {
                let moved: f64 = waypoints.windows(2).map(|w| (w[1][d] - w[0][d]).abs()).sum();
                (moved - (waypoints[n - 1][d] - waypoints[0][d]).abs()).max(0.0)
            })
            .collect()
    };
    let mut excess = excess_of(waypoints);
    let mut old = whole(waypoints);
    for _ in 0..attempts {
        if misses >= MAX_MISSES {
            break;
        }
        let sum: f64 = excess.iter().sum();
        if sum < 1e-9 {
            break;
        }
        let mut pick = rng.random_range(0.0..sum);
        let d = excess
            .iter()
            .position(|&e| {
                pick -= e;
                pick < 0.0
            })
            .unwrap_or(dof - 1);
        let i = rng.random_range(0..n - 2);
        let j = rng.random_range(i + 2..n);
        // What each segment costs without joint d's move: d's share of the way.
        let shares: Vec<f64> = waypoints[i..=j]
            .windows(2)
            .map(|w| {
                without.clear();
                without.extend_from_slice(&w[1]);
                without[d] = w[0][d];
                seg(&w[0], &without)
            })
            .collect();
        let total: f64 = shares.iter().sum();
        let (from, to) = (waypoints[i][d], waypoints[j][d]);
        trial.clear();
        trial.extend(waypoints.iter().cloned());
        let mut along = 0.0;
        for (k, share) in shares.iter().enumerate().take(j - i - 1) {
            along += if total > 0.0 {
                share / total
            } else {
                1.0 / (j - i) as f64
            };
            trial[i + k + 1][d] = from + (to - from) * along.min(1.0);
        }
        let new = whole(&trial);
        if new >= old - 1e-9 {
            misses += 1;
            continue;
        }
        let mut valid = true;
        for w in trial[i..=j].windows(2) {
            let check = check_segment(space, validity, &w[0], &w[1], min_clearance);
            calls += check.calls;
            if !check.valid {
                valid = false;
                break;
            }
        }
        misses = if valid && old - new >= MIN_GAIN * old {
            0
        } else {
            misses + 1
        };
        if valid {
            waypoints.clone_from_slice(&trial);
            excess = excess_of(waypoints);
            old = new;
        }
    }
    calls
}

/// Unwinds a path's turning joints ([`JointSpace::winds`]): each interior waypoint may take
/// such a joint a whole number of turns from its value (within the limits), which poses every
/// body the same, so the waypoint stays as valid as it was. Per joint, the values that move the
/// joint least along the whole path are chosen (a shortest path over the waypoints' choices,
/// the waypoint's own value first on ties); every segment that changes must pass
/// [`check_segment`], and a waypoint at the end of a segment that does not is held at its own
/// values and the choice made again (at most once per waypoint). The unwound path is kept only
/// when its cost by `total` falls. The sampler draws a joint over its whole range, so a path
/// through samples can swing a wrist joint round by turns it need not make (a leg of
/// dense-8r-120 turned joint 6 by 16.1 rad for a net 2.0 rad), and a shortcut between
/// two such waypoints cannot remove that: it moves the other joints too. Returns the validity
/// calls made.
pub(super) fn unwind(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut [Vec<f64>],
    min_clearance: f64,
    total: PathCost<'_>,
) -> usize {
    let n = waypoints.len();
    let winding: Vec<usize> = (0..space.dim()).filter(|&j| space.winds(j)).collect();
    if n < 3 || winding.is_empty() || waypoints.iter().any(|w| w.len() != space.dim()) {
        return 0;
    }
    let tau = std::f64::consts::TAU;
    // Waypoints held at their own values: the ends always.
    let mut held = vec![false; n];
    held[0] = true;
    held[n - 1] = true;
    let mut calls = 0;
    // Segments found clear in an earlier round: a round after a hold asks most of them again.
    let mut clear: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    loop {
        let mut trial = waypoints.to_vec();
        for &j in &winding {
            // A value moved by turns lands within the limits exactly (no tolerance: the
            // verifier and the timing read the limits as they are).
            let (lo, hi) = (space.lower[j], space.upper[j]);
            // Each waypoint's choices: its own value first, then the others a whole number of
            // turns away within the limits (at most a few: the limits are finite).
            let choices: Vec<Vec<f64>> = waypoints
                .iter()
                .zip(&held)
                .map(|(w, &held)| {
                    let v = w[j];
                    let mut c = vec![v];
                    if !held && v.is_finite() && hi - lo < 64.0 * tau {
                        let (k_lo, k_hi) = (((lo - v) / tau).ceil() as i64, ((hi - v) / tau).floor() as i64);
                        c.extend(
                            (k_lo..=k_hi)
                                .filter(|&k| k != 0)
                                .map(|k| v + k as f64 * tau)
                                .filter(|x| (lo..=hi).contains(x)),
                        );
                    }
                    c
                })
                .collect();
            // The least travel to each choice of each waypoint, and where it came from.
            let mut cost = vec![0.0];
            let mut from: Vec<Vec<usize>> = Vec::with_capacity(n);
            for k in 1..n {
                let (prev, next) = (&choices[k - 1], &choices[k]);
                let mut c = Vec::with_capacity(next.len());
                let mut f = Vec::with_capacity(next.len());
                for &v in next {
                    let (mut best, mut at) = (f64::INFINITY, 0);
                    for (a, &u) in prev.iter().enumerate() {
                        let x = cost[a] + (v - u).abs();
                        if x < best {
                            (best, at) = (x, a);
                        }
                    }
                    c.push(best);
                    f.push(at);
                }
                cost = c;
                from.push(f);
            }
            let mut at = 0;
            for k in (1..n).rev() {
                trial[k][j] = choices[k][at];
                at = from[k - 1][at];
            }
        }
        if trial == waypoints || total(&trial) >= total(waypoints) {
            return calls;
        }
        let mut blocked = false;
        for k in 0..n - 1 {
            let (a, b) = (&trial[k], &trial[k + 1]);
            if (*a == waypoints[k] && *b == waypoints[k + 1]) || clear.iter().any(|(x, y)| x == a && y == b) {
                continue;
            }
            let check = check_segment(space, validity, a, b, min_clearance);
            calls += check.calls;
            if check.valid {
                clear.push((a.clone(), b.clone()));
            } else {
                blocked = true;
                for end in [k, k + 1] {
                    if trial[end] != waypoints[end] {
                        held[end] = true;
                    }
                }
            }
        }
        if !blocked {
            waypoints.clone_from_slice(&trial);
            return calls;
        }
    }
}

/// Drops redundant waypoints: from each kept waypoint in turn, the farthest later waypoint it
/// sees directly (the segment passes [`check_segment`] and costs no more by `seg` than the
/// path it replaces) becomes the next, found by galloping — the waypoints 2, 3, 5, 9, …
/// ahead until one is not seen, then bisection between the last seen and the first not seen —
/// and every waypoint between them is dropped. Returns the calls made.
///
/// A valid segment's check costs about its length in steps and an invalid one's usually a few
/// (its probes find the contact), so galloping checks about twice the final segment's length,
/// where growing the segment one waypoint at a time checks the sum of all its lengths: on
/// the README run's paths of ten or more waypoints (1 cm retract polylines of 20–56 that end
/// as 3 to 6) that was 2.4 times the validity calls (110 k against 46 k). Where visibility is not monotone along the path (a later waypoint seen, an earlier
/// one not), the segment found may reach farther than the first waypoint not seen.
fn remove_redundant(
    space: &JointSpace,
    validity: &dyn StateValidity,
    waypoints: &mut Vec<Vec<f64>>,
    min_clearance: f64,
    seg: &dyn Fn(&[f64], &[f64]) -> f64,
) -> usize {
    let mut calls = 0;
    let mut i = 0;
    while i + 2 < waypoints.len() {
        let last = waypoints.len() - 1;
        // The path's cost from waypoint i to each later one (prefix sums along the path).
        let mut along = vec![0.0; last + 1 - i];
        for k in i + 1..=last {
            along[k - i] = along[k - 1 - i] + seg(&waypoints[k - 1], &waypoints[k]);
        }
        let mut sees = |j: usize| -> bool {
            if seg(&waypoints[i], &waypoints[j]) > along[j - i] + 1e-12 {
                return false;
            }
            let check = check_segment(space, validity, &waypoints[i], &waypoints[j], min_clearance);
            calls += check.calls;
            check.valid
        };
        // `seen`: the farthest waypoint known to be seen; `unseen`: the nearest known not to be.
        let mut seen = i + 1;
        let mut unseen = None;
        let mut ahead = 1;
        while unseen.is_none() && seen < last {
            let j = (i + 1 + ahead).min(last);
            if sees(j) {
                seen = j;
                ahead *= 2;
            } else {
                unseen = Some(j);
            }
        }
        if let Some(mut unseen) = unseen {
            while unseen - seen > 1 {
                let mid = seen + (unseen - seen) / 2;
                if sees(mid) {
                    seen = mid;
                } else {
                    unseen = mid;
                }
            }
        }
        waypoints.drain(i + 1..seen);
        i += 1;
    }
    calls
}

//! Time parameterisation of piecewise-linear joint paths.
//!
//! Both parameterisations share one construction. The path is cleaned (consecutive duplicate
//! waypoints dropped, consecutive segments with the same direction merged into one straight
//! segment) and each segment `k` gets a unit direction `u_k`, a length `L_k` (Euclidean, in
//! joint space) and the largest speed and acceleration along the line that no joint exceeds:
//! `V_k = min_j v_j/|u_kj|`, `A_k = min_j a_j/|u_kj|`. Each corner `k` gets a speed `c_k ≥ 0`
//! (0 at the path's ends). Around a corner with `c_k > 0`, a parabolic blend of duration
//! `b_k = c_k·β_k`, `β_k = max_j |u_kj − u_(k−1)j| / a_j`, takes the joints with constant
//! acceleration `(u_k − u_(k−1)) / β_k` from velocity `c_k·u_(k−1)` to `c_k·u_k`; it leaves
//! segment `k−1` and joins segment `k` at distance `r_k = c_k·b_k/2` from the corner. Between
//! blends each segment is crossed along its line with the time-optimal 1-D profile (accelerate
//! at `A_k`, cruise at `V_k` if reached, decelerate at `A_k`) from speed `c_k` to `c_(k+1)`.
//!
//! Limits hold by construction: along a segment, joint `j` moves at `s'·u_kj` with `s' ≤ V_k`
//! and accelerates at `s''·u_kj` with `|s''| ≤ A_k`; in a blend joint `j` accelerates at
//! `|u_kj − u_(k−1)j| / β_k ≤ a_j` and its velocity moves linearly between `c_k·u_(k−1)j` and
//! `c_k·u_kj`, both within `v_j` since `c_k ≤ min(V_(k−1), V_k)`.

use super::{Limits, Piece, TimingError, Trajectory};

/// Waypoints closer than this (Euclidean, joint units) are the same waypoint.
const SAME_POINT: f64 = 1e-12;
/// Consecutive segments whose unit directions differ by less than this are merged.
const SAME_DIRECTION: f64 = 1e-9;

/// A path timed to follow the polyline exactly: see [`time_path_exact`].
#[derive(Debug, Clone, PartialEq)]
pub struct TimedPath {
    /// The trajectory, starting and ending at rest.
    pub trajectory: Trajectory,
    /// The time in s at which the trajectory passes each input waypoint (same indexing as the
    /// input path; duplicates share a time).
    pub waypoint_times: Vec<f64>,
}

/// One parabolic blend of a [`BlendedPath`].
#[derive(Debug, Clone, PartialEq)]
pub struct Blend {
    /// Index (in the input path) of the corner waypoint the blend replaces.
    pub waypoint: usize,
    /// Start time of the blend, in s.
    pub start_time: f64,
    /// Duration of the blend, in s.
    pub duration: f64,
    /// Speed along the path (joint-space Euclidean, per s) on entering and leaving the blend.
    pub speed: f64,
    /// Distance (Euclidean, joint units) from the corner at which the blend leaves the incoming
    /// segment and joins the outgoing one.
    pub radius: f64,
    /// Per joint, the largest difference between the blended position and the point of the
    /// corner polyline crossed at constant `speed` at the same time (reached at the middle of
    /// the blend, where it equals `|Δv_j|·duration/8`); the distance from the blend to the
    /// polyline is no larger.
    pub deviation: Vec<f64>,
}

/// A path timed with parabolic blends at its corners: see [`time_path_blended`].
#[derive(Debug, Clone, PartialEq)]
pub struct BlendedPath {
    /// The trajectory, starting and ending at rest at the path's end points.
    pub trajectory: Trajectory,
    /// The blends actually used, in time order (corners crossed with a stop have none).
    pub blends: Vec<Blend>,
    /// Per joint, the largest deviation over all blends (0 without blends); at most the
    /// `max_deviation` asked for. Re-check collisions along the trajectory, or inflate the
    /// robot by this much, before trusting the blended path.
    pub deviation: Vec<f64>,
    /// The time in s at which the trajectory passes each input waypoint (same indexing as the
    /// input path): at a blended corner, the middle of its blend (where the blend comes
    /// nearest the corner); elsewhere the time the trajectory is there. Non-decreasing.
    pub waypoint_times: Vec<f64>,
}

/// Times a piecewise-linear joint path (e.g. a collision-free planner's output) so that it is
/// followed exactly: the trajectory stops at every corner and crosses each segment with a
/// synchronised, time-optimal trapezoidal (or triangular) profile along the line; consecutive
/// segments with the same direction are merged and crossed at speed. All joints stay on the
/// polyline, so the planner's collision check of the segments still holds.
///
/// Each segment from rest to rest takes at least [`move_time`](super::move_time) of its end
/// points. Errors: empty path, a waypoint with a joint count other than the limits', a
/// non-finite coordinate. A path of one waypoint (or of duplicates) gives a zero-length dwell.
/// Cost: O(waypoints · dof).
///
/// ```
/// use cellplan_motion::timing::{Limits, check_limits, time_path_exact};
/// let l = Limits::uniform(2, 1.0, 2.0).unwrap();
/// let path = vec![vec![0.0, 0.0], vec![2.0, 0.0], vec![2.0, 2.0]];
/// let timed = time_path_exact(&path, &l).unwrap();
/// assert!((timed.trajectory.duration() - 5.0).abs() < 1e-12); // two 2.5 s trapezoids
/// assert!((timed.waypoint_times[1] - 2.5).abs() < 1e-12);
/// assert!(check_limits(&timed.trajectory, &l, 1e-9).is_ok());
/// ```
pub fn time_path_exact(path: &[Vec<f64>], limits: &Limits) -> Result<TimedPath, TimingError> {
    let clean = Clean::new(path, limits)?;
    let speeds = vec![0.0; clean.segments.len() + 1];
    let built = clean.build(&speeds);
    let waypoint_times = clean
        .waypoint_at
        .iter()
        .map(|&(k, d)| match built.profiles.get(k) {
            Some(prof) => built.segment_starts[k] + time_at_distance(prof, d),
            None => 0.0,
        })
        .collect();
    Ok(TimedPath {
        trajectory: built.trajectory,
        waypoint_times,
    })
}

/// The time of the straight joint segment from `a` to `b`, from rest to rest, as
/// [`time_path_exact`] crosses it: along the line at the largest speed and acceleration no
/// joint exceeds, a trapezoid (or a triangle when the line is too short to cruise). At least
/// [`move_time`](super::move_time) of the two points. Cost: O(dof), no allocation. Panics if
/// `a`, `b` and `limits` differ in length.
///
/// ```
/// use cellplan_motion::timing::{Limits, segment_time, time_path_exact};
/// let l = Limits::new(vec![1.0, 2.0], vec![2.0, 1.0]).unwrap();
/// let (a, b) = (vec![0.0, 0.0], vec![2.0, -1.0]);
/// let exact = time_path_exact(&[a.clone(), b.clone()], &l).unwrap();
/// assert!((segment_time(&a, &b, &l) - exact.trajectory.duration()).abs() < 1e-12);
/// ```
pub fn segment_time(a: &[f64], b: &[f64], limits: &Limits) -> f64 {
    assert!(
        a.len() == b.len() && a.len() == limits.dof(),
        "segment_time: joint counts differ"
    );
    let len = dist(a, b);
    if len <= SAME_POINT {
        return 0.0;
    }
    let (vmax, amax) = line_limits(a.iter().zip(b).map(|(x, y)| (y - x).abs() / len), limits);
    if len * amax >= vmax * vmax {
        len / vmax + vmax / amax
    } else {
        2.0 * (len / amax).sqrt()
    }
}

/// Times a piecewise-linear joint path with parabolic blends at its corners: near
/// time-optimal, never slower than [`time_path_exact`], within `max_deviation` of the polyline.
///
/// `max_deviation` is the per-joint bound (joint units) on the distance between the blended
/// path and the polyline: one value per joint, or a single value for all joints. A bound of 0
/// gives the exact timing. The construction is described in the module source: segments are
/// crossed along their line with time-optimal profiles, each corner `k` is crossed at a speed
/// `c_k` with a constant-acceleration blend of duration `c_k·β_k` (the shortest the acceleration
/// limits allow at that speed, so the blend deviates least). `c_k` is as large as possible
/// under: both segments' velocity limits; the deviation bound (`c_k²·|Δu_j|·β_k/8 ≤ δ_j`);
/// each blend using at most half of each neighbouring segment, so blends never overlap; and a
/// forward/backward pass so that each segment can change speed from `c_k` to `c_(k+1)` within
/// what remains of it. The blend size, and with it the corner speed, is therefore as large as
/// the limits, the deviation bound and the room allow. As a blend can be slower than a stop at
/// very sharp corners (near reversals), the fastest of three speed assignments — all corners
/// blended, sharp corners (`A·β > 1`) stopped, all stopped — is returned.
///
/// Geometry of a blend: it is the quadratic Bézier curve with control points `p_k − r_k·u_(k−1)`,
/// `p_k`, `p_k + r_k·u_k`, so it lies in the triangle they span — within the convex hull of the
/// corner's neighbourhood of the polyline. At each time, every joint is within
/// [`Blend::deviation`] (≤ `max_deviation`) of the point the polyline's own timing (the two
/// segments crossed at constant speed `c_k`) would be at.
///
/// Errors: as [`time_path_exact`], plus a `max_deviation` of the wrong length, negative or not
/// finite. Cost: O(waypoints · dof).
///
/// ```
/// use cellplan_motion::timing::{Limits, check_limits, time_path_blended, time_path_exact};
/// let l = Limits::uniform(2, 1.0, 2.0).unwrap();
/// let path = vec![vec![0.0, 0.0], vec![2.0, 0.0], vec![2.0, 2.0]];
/// let blended = time_path_blended(&path, &l, &[0.05]).unwrap();
/// let exact = time_path_exact(&path, &l).unwrap();
/// assert!(blended.trajectory.duration() < exact.trajectory.duration());
/// assert!(blended.deviation.iter().all(|&d| d <= 0.05 + 1e-12));
/// assert!(check_limits(&blended.trajectory, &l, 1e-9).is_ok());
/// ```
pub fn time_path_blended(
    path: &[Vec<f64>],
    limits: &Limits,
    max_deviation: &[f64],
) -> Result<BlendedPath, TimingError> {
    time_path_blended_scaled(path, limits, max_deviation, &[])
}

/// [`time_path_blended`] with the deviation bound at input waypoint `w` multiplied by
/// `scale[w]` (1 where `scale` is shorter than the path; 0 leaves that corner unblended: the
/// trajectory stops there). A caller that re-checks blends can so shrink or drop the ones that
/// failed and time the path again. Errors: as [`time_path_blended`], plus a scale that is
/// negative or not finite.
pub fn time_path_blended_scaled(
    path: &[Vec<f64>],
    limits: &Limits,
    max_deviation: &[f64],
    scale: &[f64],
) -> Result<BlendedPath, TimingError> {
    if let Some((waypoint, &value)) = scale
        .iter()
        .enumerate()
        .find(|(_, s)| !(s.is_finite() && **s >= 0.0))
    {
        return Err(TimingError::InvalidScale { waypoint, value });
    }
    let dof = limits.dof();
    let delta: Vec<f64> = match max_deviation.len() {
        1 => vec![max_deviation[0]; dof],
        n if n == dof => max_deviation.to_vec(),
        n => {
            return Err(TimingError::DimensionMismatch {
                what: "max_deviation".into(),
                expected: dof,
                found: n,
            });
        }
    };
    if let Some((joint, &value)) = delta
        .iter()
        .enumerate()
        .find(|(_, d)| !(d.is_finite() && **d >= 0.0))
    {
        return Err(TimingError::InvalidDeviation { joint, value });
    }
    let clean = Clean::new(path, limits)?;
    let m = clean.segments.len();
    if m < 2 {
        let built = clean.build(&vec![0.0; m + 1]);
        return Ok(BlendedPath {
            waypoint_times: clean.waypoint_times(&built),
            trajectory: built.trajectory,
            blends: vec![],
            deviation: vec![0.0; dof],
        });
    }

    // Upper bound of each corner speed, squared (x = c²).
    let mut cap = vec![0.0; m + 1];
    for (k, cap_k) in cap.iter_mut().enumerate().take(m).skip(1) {
        let (s0, s1) = (&clean.segments[k - 1], &clean.segments[k]);
        let beta = clean.beta[k];
        let factor = scale.get(clean.corner_waypoint[k]).copied().unwrap_or(1.0);
        if beta <= 0.0 || factor <= 0.0 {
            continue;
        }
        let v = s0.vmax.min(s1.vmax);
        let mut x = v * v;
        x = x.min(s0.len.min(s1.len) / beta);
        for (j, &dj) in delta.iter().enumerate() {
            let du = (s1.dir[j] - s0.dir[j]).abs();
            if du > 0.0 {
                x = x.min(8.0 * dj * factor / (du * beta));
            }
        }
        *cap_k = x;
    }
    let full = clean.feasible_speeds(cap.clone());
    let mut sharp_cap = cap.clone();
    for (k, cap_k) in sharp_cap.iter_mut().enumerate().take(m).skip(1) {
        let (s0, s1) = (&clean.segments[k - 1], &clean.segments[k]);
        if s0.amax * clean.beta[k] > 1.0 || s1.amax * clean.beta[k] > 1.0 {
            *cap_k = 0.0;
        }
    }
    let gentle = clean.feasible_speeds(sharp_cap);
    let mut best: Option<Built> = None;
    for speeds in [full, gentle, vec![0.0; m + 1]] {
        let built = clean.build(&speeds);
        if best
            .as_ref()
            .is_none_or(|b| built.trajectory.duration() < b.trajectory.duration())
        {
            best = Some(built);
        }
    }
    let built = best.expect("three candidates");
    let mut deviation = vec![0.0f64; dof];
    for b in &built.blends {
        for (d, bd) in deviation.iter_mut().zip(&b.deviation) {
            *d = d.max(*bd);
        }
    }
    Ok(BlendedPath {
        waypoint_times: clean.waypoint_times(&built),
        trajectory: built.trajectory,
        blends: built.blends,
        deviation,
    })
}

/// One straight segment of the cleaned path.
struct Segment {
    start: Vec<f64>,
    dir: Vec<f64>,
    len: f64,
    vmax: f64,
    amax: f64,
}

/// The cleaned path: merged segments, corner sharpness, and where each input waypoint lies.
struct Clean {
    first: Vec<f64>,
    segments: Vec<Segment>,
    /// `beta[k] = max_j |u_kj − u_(k−1)j| / a_j` for corners `1..m`; 0 at the ends.
    beta: Vec<f64>,
    /// For each input waypoint: (segment, distance from the segment's start).
    waypoint_at: Vec<(usize, f64)>,
    /// Input waypoint index of each corner vertex `k` (between segments `k − 1` and `k`).
    corner_waypoint: Vec<usize>,
    limits: Limits,
}

/// A constant-acceleration phase of a 1-D profile along a segment.
#[derive(Clone, Copy, Debug)]
struct Phase {
    duration: f64,
    s0: f64,
    v0: f64,
    a: f64,
}

struct Built {
    trajectory: Trajectory,
    /// Start time of each segment's free (non-blend) part.
    segment_starts: Vec<f64>,
    /// 1-D profile of each segment's free part, distances measured from the segment's start.
    profiles: Vec<Vec<Phase>>,
    blends: Vec<Blend>,
}

/// The largest speed and acceleration along a line whose unit direction has the components
/// `|u_j|` (joint order) that no joint exceeds: joint `j` moves at `s'·|u_j|`, so the tightest
/// joint sets them (infinite for a line no joint moves along).
fn line_limits(u: impl Iterator<Item = f64>, limits: &Limits) -> (f64, f64) {
    let (mut v, mut a) = (f64::INFINITY, f64::INFINITY);
    for ((u, &vj), &aj) in u.zip(&limits.velocity).zip(&limits.acceleration) {
        if u > 0.0 {
            v = v.min(vj / u);
            a = a.min(aj / u);
        }
    }
    (v, a)
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (y - x) * (y - x))
        .sum::<f64>()
        .sqrt()
}

impl Clean {
    fn new(path: &[Vec<f64>], limits: &Limits) -> Result<Self, TimingError> {
        let dof = limits.dof();
        let first = path.first().ok_or(TimingError::Empty("path"))?;
        for (i, w) in path.iter().enumerate() {
            if w.len() != dof {
                return Err(TimingError::DimensionMismatch {
                    what: format!("waypoint {i}"),
                    expected: dof,
                    found: w.len(),
                });
            }
            if w.iter().any(|x| !x.is_finite()) {
                return Err(TimingError::NonFinite(format!("waypoint {i}")));
            }
        }
        let mut segments: Vec<Segment> = Vec::new();
        let mut waypoint_at = vec![(0usize, 0.0)];
        // End vertex of the last segment (the path's current end).
        let mut last = first.clone();
        for w in path.iter().skip(1) {
            let d = dist(&last, w);
            if d <= SAME_POINT {
                waypoint_at.push(match segments.last() {
                    Some(s) => (segments.len() - 1, s.len),
                    None => (0, 0.0),
                });
                continue;
            }
            let dir: Vec<f64> = last.iter().zip(w).map(|(a, b)| (b - a) / d).collect();
            let merge = segments
                .last()
                .is_some_and(|s| dist(&s.dir, &dir) <= SAME_DIRECTION);
            if merge {
                let s = segments.last_mut().expect("checked");
                let len = dist(&s.start, w);
                s.dir = s.start.iter().zip(w).map(|(a, b)| (b - a) / len).collect();
                s.len = len;
            } else {
                segments.push(Segment {
                    start: last.clone(),
                    dir,
                    len: d,
                    vmax: 0.0,
                    amax: 0.0,
                });
            }
            waypoint_at.push((segments.len() - 1, segments.last().expect("pushed").len));
            last = w.clone();
        }
        let m = segments.len();
        let mut corner_wp = vec![0usize; m + 1];
        for (k, slot) in corner_wp.iter_mut().enumerate().skip(1) {
            // the last input waypoint mapped to the end of segment k−1 (segments before the
            // last are never extended after the next one starts, so the match is exact)
            *slot = waypoint_at
                .iter()
                .rposition(|&(s, d)| s == k - 1 && (d - segments[k - 1].len).abs() <= SAME_POINT)
                .unwrap_or(path.len() - 1);
        }
        for s in &mut segments {
            (s.vmax, s.amax) = line_limits(s.dir.iter().map(|u| u.abs()), limits);
        }
        let mut beta = vec![0.0; m + 1];
        for (k, b) in beta.iter_mut().enumerate().take(m).skip(1) {
            *b = (0..dof)
                .map(|j| (segments[k].dir[j] - segments[k - 1].dir[j]).abs() / limits.acceleration[j])
                .fold(0.0, f64::max);
        }
        Ok(Self {
            first: first.clone(),
            segments,
            beta,
            waypoint_at,
            corner_waypoint: corner_wp,
            limits: limits.clone(),
        })
    }

    /// When `built` passes each input waypoint: the middle of the blend at a blended corner,
    /// else the time its profile reaches the waypoint's distance (made non-decreasing against
    /// rounding).
    fn waypoint_times(&self, built: &Built) -> Vec<f64> {
        let blend_mid = |w: usize| {
            built
                .blends
                .iter()
                .find(|b| b.waypoint == w)
                .map(|b| b.start_time + 0.5 * b.duration)
        };
        let mut last = 0.0f64;
        self.waypoint_at
            .iter()
            .enumerate()
            .map(|(w, &(k, d))| {
                let t = blend_mid(w).unwrap_or_else(|| match built.profiles.get(k) {
                    Some(prof) => built.segment_starts[k] + time_at_distance(prof, d),
                    None => 0.0,
                });
                last = last.max(t);
                last
            })
            .collect()
    }

    /// Lowers the squared corner speeds `x` (at most their caps) until every segment can go
    /// from `c_k` to `c_(k+1)` within its free length `L − x_k·β_k/2 − x_(k+1)·β_(k+1)/2`.
    fn feasible_speeds(&self, mut x: Vec<f64>) -> Vec<f64> {
        let m = self.segments.len();
        x[0] = 0.0;
        x[m] = 0.0;
        let b = &self.beta;
        for _ in 0..4 * m + 8 {
            let mut changed = false;
            // forward: x_(k+1)·(1 + A·β_(k+1)) ≤ x_k·(1 − A·β_k) + 2·A·L
            for k in 0..m {
                let s = &self.segments[k];
                let bound = (x[k] * (1.0 - s.amax * b[k]) + 2.0 * s.amax * s.len) / (1.0 + s.amax * b[k + 1]);
                if x[k + 1] > bound {
                    x[k + 1] = bound.max(0.0) * (1.0 - 1e-12);
                    changed = true;
                }
            }
            for k in (0..m).rev() {
                let s = &self.segments[k];
                let bound =
                    (x[k + 1] * (1.0 - s.amax * b[k + 1]) + 2.0 * s.amax * s.len) / (1.0 + s.amax * b[k]);
                if x[k] > bound {
                    x[k] = bound.max(0.0) * (1.0 - 1e-12);
                    changed = true;
                }
            }
            if !changed {
                return x.iter().map(|v| v.max(0.0).sqrt()).collect();
            }
        }
        vec![0.0; m + 1]
    }

    /// Builds the trajectory for corner speeds `c` (`c[0] = c[m] = 0`).
    fn build(&self, c: &[f64]) -> Built {
        let dof = self.limits.dof();
        let m = self.segments.len();
        if m == 0 {
            return Built {
                trajectory: Trajectory::dwell(&self.first, 0.0),
                segment_starts: vec![],
                profiles: vec![],
                blends: vec![],
            };
        }
        let mut pieces = Vec::new();
        let mut t = 0.0;
        let mut segment_starts = Vec::with_capacity(m);
        let mut profiles = Vec::with_capacity(m);
        let mut blends = Vec::new();
        let radius = |k: usize| 0.5 * c[k] * c[k] * self.beta[k];
        for k in 0..m {
            let s = &self.segments[k];
            let (r0, r1) = (radius(k), radius(k + 1));
            let free = (s.len - r0 - r1).max(0.0);
            let mut prof = profile(free, c[k], c[k + 1], s.vmax, s.amax);
            for ph in &mut prof {
                ph.s0 += r0;
            }
            segment_starts.push(t);
            for ph in &prof {
                pieces.push(Piece {
                    duration: ph.duration,
                    position: (0..dof).map(|j| s.start[j] + ph.s0 * s.dir[j]).collect(),
                    velocity: s.dir.iter().map(|u| ph.v0 * u).collect(),
                    acceleration: s.dir.iter().map(|u| ph.a * u).collect(),
                });
                t += ph.duration;
            }
            profiles.push(prof);
            if k + 1 < m && c[k + 1] > 0.0 {
                let next = &self.segments[k + 1];
                let (ck, beta) = (c[k + 1], self.beta[k + 1]);
                let duration = ck * beta;
                let corner = &next.start;
                let acceleration: Vec<f64> = (0..dof).map(|j| (next.dir[j] - s.dir[j]) / beta).collect();
                let deviation = (0..dof)
                    .map(|j| ck * (next.dir[j] - s.dir[j]).abs() * duration / 8.0)
                    .collect();
                pieces.push(Piece {
                    duration,
                    position: (0..dof).map(|j| corner[j] - r1 * s.dir[j]).collect(),
                    velocity: s.dir.iter().map(|u| ck * u).collect(),
                    acceleration,
                });
                blends.push(Blend {
                    waypoint: self.corner_waypoint[k + 1],
                    start_time: t,
                    duration,
                    speed: ck,
                    radius: r1,
                    deviation,
                });
                t += duration;
            }
        }
        if pieces.is_empty() {
            pieces.push(Piece {
                duration: 0.0,
                position: self.first.clone(),
                velocity: vec![0.0; dof],
                acceleration: vec![0.0; dof],
            });
        }
        Built {
            trajectory: Trajectory::from_pieces_unchecked(pieces),
            segment_starts,
            profiles,
            blends,
        }
    }
}

/// Time-optimal 1-D profile over `len` from speed `v0` to `v1` under speed `vmax` and
/// acceleration `amax` (assumes `v0, v1 ≤ vmax` and `|v1² − v0²| ≤ 2·amax·len` up to rounding;
/// when rounding breaks the latter, a single phase of the exact needed acceleration is used).
/// Zero-duration phases are dropped.
fn profile(len: f64, v0: f64, v1: f64, vmax: f64, amax: f64) -> Vec<Phase> {
    let mut out = Vec::with_capacity(3);
    let mut push = |duration: f64, s0: f64, v: f64, a: f64| {
        if duration > 0.0 {
            out.push(Phase {
                duration,
                s0,
                v0: v,
                a,
            });
        }
    };
    if len <= 0.0 {
        return out;
    }
    if (v1 * v1 - v0 * v0).abs() >= 2.0 * amax * len {
        // only a ramp fits
        let a = (v1 * v1 - v0 * v0) / (2.0 * len);
        push(2.0 * len / (v0 + v1), 0.0, v0, a);
        return out;
    }
    let peak2 = amax * len + 0.5 * (v0 * v0 + v1 * v1);
    let vp = peak2.sqrt().min(vmax).max(v0).max(v1);
    let d_acc = (vp * vp - v0 * v0) / (2.0 * amax);
    let d_dec = (vp * vp - v1 * v1) / (2.0 * amax);
    let cruise = (len - d_acc - d_dec).max(0.0);
    push((vp - v0) / amax, 0.0, v0, amax);
    push(cruise / vp, d_acc, vp, 0.0);
    push((vp - v1) / amax, d_acc + cruise, vp, -amax);
    out
}

/// The time `τ ≥ 0` at which `v·τ + ½·a·τ² = x`, for `v, a ≥ 0`.
fn root(x: f64, v: f64, a: f64) -> f64 {
    let denom = v + (v * v + 2.0 * a * x).sqrt();
    if denom > 0.0 { 2.0 * x / denom } else { 0.0 }
}

/// The first time the profile reaches distance `d` from the segment's start.
fn time_at_distance(prof: &[Phase], d: f64) -> f64 {
    let mut t = 0.0;
    for ph in prof {
        let s_end = ph.s0 + ph.duration * (ph.v0 + 0.5 * ph.a * ph.duration);
        // Distances within rounding of a phase end snap to it: near a stop, s(t) is flat and
        // one ulp of distance would move the time by ~1e-8 s.
        let snap = 1e-12 * s_end.abs().max(1.0);
        if (d - s_end).abs() <= snap {
            return t + ph.duration;
        }
        if d <= s_end {
            // Solve from the phase's faster end, where the inversion is well conditioned
            // (near a stop, s(t) is flat and the forward root would amplify rounding).
            let tau = if ph.a >= 0.0 {
                root((d - ph.s0).max(0.0), ph.v0, ph.a)
            } else {
                ph.duration - root((s_end - d).max(0.0), ph.v0 + ph.a * ph.duration, -ph.a)
            };
            return t + tau.clamp(0.0, ph.duration);
        }
        t += ph.duration;
    }
    t
}

#[cfg(test)]
mod tests;

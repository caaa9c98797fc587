//! Per-joint limits and point-to-point move times.

use super::{Piece, TimingError, Trajectory};

/// Per-joint velocity (rad/s or m/s) and acceleration (rad/s² or m/s²) limits, each finite
/// and > 0. Build with [`Limits::new`] (validated) or [`Limits::uniform`]; the fields are public
/// for reading, and functions of this module assume they hold valid values.
#[derive(Debug, Clone, PartialEq)]
pub struct Limits {
    /// Maximum absolute velocity of each joint.
    pub velocity: Vec<f64>,
    /// Maximum absolute acceleration of each joint.
    pub acceleration: Vec<f64>,
}

impl Limits {
    /// Validated limits: at least one joint, equal lengths, every value finite and > 0.
    ///
    /// ```
    /// use cellplan_motion::timing::Limits;
    /// let l = Limits::new(vec![2.0, 1.5], vec![5.0, 4.0]).unwrap();
    /// assert_eq!(l.dof(), 2);
    /// assert!(Limits::new(vec![2.0], vec![0.0]).is_err());
    /// ```
    pub fn new(velocity: Vec<f64>, acceleration: Vec<f64>) -> Result<Self, TimingError> {
        if velocity.len() != acceleration.len() {
            return Err(TimingError::LimitLengthMismatch {
                velocity: velocity.len(),
                acceleration: acceleration.len(),
            });
        }
        if velocity.is_empty() {
            return Err(TimingError::EmptyLimits);
        }
        for (quantity, values) in [("velocity", &velocity), ("acceleration", &acceleration)] {
            for (joint, &value) in values.iter().enumerate() {
                if !(value.is_finite() && value > 0.0) {
                    return Err(TimingError::InvalidLimit {
                        joint,
                        quantity,
                        value,
                    });
                }
            }
        }
        Ok(Self {
            velocity,
            acceleration,
        })
    }

    /// The same limits for `dof` joints.
    pub fn uniform(dof: usize, velocity: f64, acceleration: f64) -> Result<Self, TimingError> {
        Self::new(vec![velocity; dof], vec![acceleration; dof])
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.velocity.len()
    }
}

/// Minimum time for one joint to travel `distance` (sign ignored) from rest to rest under
/// velocity limit `v` and acceleration limit `a`: triangular profile `2·sqrt(d/a)` when
/// `d ≤ v²/a`, else trapezoidal `d/v + v/a`.
pub fn joint_min_time(distance: f64, v: f64, a: f64) -> f64 {
    let d = distance.abs();
    if d * a <= v * v {
        2.0 * (d / a).sqrt()
    } else {
        d / v + v / a
    }
}

/// Minimum time of a point-to-point joint move from `a` to `b`, at rest at both ends: the
/// maximum over joints of [`joint_min_time`]. Every joint can then be slowed (its own profile
/// stretched) to finish together — a synchronised move. Since each joint alone needs at least
/// its own minimum time, this is a lower bound of the duration of *any* motion from `a` to `b`
/// that starts and ends at rest (in particular of any collision-free one). The straight line
/// timed by [`time_path_exact`](super::time_path_exact) may take longer, when the velocity and
/// the acceleration bounds bind on different joints.
///
/// Cost: O(dof). Panics if `a`, `b` and `limits` differ in length.
///
/// ```
/// use cellplan_motion::timing::{Limits, move_time, move_time_instant};
/// let l = Limits::uniform(2, 1.0, 2.0).unwrap();
/// // joint 0: 2 rad, trapezoid 2/1 + 1/2 = 2.5 s; joint 1: 0.1 rad, triangle.
/// let t = move_time(&[0.0, 0.0], &[2.0, 0.1], &l);
/// assert!((t - 2.5).abs() < 1e-12);
/// assert!(move_time_instant(&[0.0, 0.0], &[2.0, 0.1], &l) <= t);
/// ```
pub fn move_time(a: &[f64], b: &[f64], limits: &Limits) -> f64 {
    check_dims(a, b, limits);
    a.iter()
        .zip(b)
        .zip(limits.velocity.iter().zip(&limits.acceleration))
        .map(|((x, y), (&v, &acc))| joint_min_time(y - x, v, acc))
        .fold(0.0, f64::max)
}

/// Paper 000's assumption 2 — every joint reaches its maximum velocity at once — gives the move
/// time `max_j |b_j − a_j| / v_j`. Optimistic: never more than [`move_time`] (by `max_j
/// v_j/a_j` at most). Panics if `a`, `b` and `limits` differ in length.
pub fn move_time_instant(a: &[f64], b: &[f64], limits: &Limits) -> f64 {
    check_dims(a, b, limits);
    a.iter()
        .zip(b)
        .zip(&limits.velocity)
        .map(|((x, y), &v)| (y - x).abs() / v)
        .fold(0.0, f64::max)
}

/// A trajectory realising [`move_time`]: every joint follows its own trapezoidal (or, for the
/// slowest, possibly triangular) profile at full acceleration, with its cruise velocity lowered
/// so that all joints start and stop together after exactly `move_time(a, b, limits)`. The
/// joints are synchronised in time but the path is in general *not* the straight line from
/// `a` to `b` (use [`time_path_exact`](super::time_path_exact) for that); it stays within the
/// box spanned by `a` and `b`, since each joint moves monotonically. Panics if `a`, `b` and
/// `limits` differ in length.
///
/// ```
/// use cellplan_motion::timing::{Limits, check_limits, move_time, move_trajectory};
/// let l = Limits::new(vec![1.0, 2.0], vec![2.0, 1.0]).unwrap();
/// let (a, b) = ([0.0, 0.0], [2.0, -1.0]);
/// let t = move_trajectory(&a, &b, &l);
/// assert_eq!(t.duration(), move_time(&a, &b, &l));
/// assert!(check_limits(&t, &l, 1e-9).is_ok());
/// ```
pub fn move_trajectory(a: &[f64], b: &[f64], limits: &Limits) -> Trajectory {
    let total = move_time(a, b, limits);
    if total <= 0.0 {
        return Trajectory::dwell(a, 0.0);
    }
    // Per joint: signed distance, acceleration, cruise velocity and acceleration time.
    let joints: Vec<(f64, f64, f64, f64)> = (0..a.len())
        .map(|j| {
            let d = b[j] - a[j];
            let acc = limits.acceleration[j];
            if d == 0.0 {
                return (0.0, 0.0, 0.0, 0.0);
            }
            // v²/acc − v·T + |d| = 0, smaller root (numerically stable form).
            let disc = (acc * acc * total * total - 4.0 * acc * d.abs()).max(0.0).sqrt();
            let v = (2.0 * acc * d.abs() / (acc * total + disc)).min(limits.velocity[j]);
            (d, acc, v, (v / acc).min(0.5 * total))
        })
        .collect();
    let eval = |j: usize, t: f64| -> (f64, f64) {
        let (d, acc, v, ta) = joints[j];
        let sgn = d.signum();
        let (s, sd) = if d == 0.0 {
            (0.0, 0.0)
        } else if t <= ta {
            (0.5 * acc * t * t, acc * t)
        } else if t <= total - ta {
            (0.5 * acc * ta * ta + v * (t - ta), v)
        } else {
            let r = total - t;
            (d.abs() - 0.5 * acc * r * r, acc * r)
        };
        (a[j] + sgn * s, sgn * sd)
    };
    let mut times = vec![0.0, total];
    for &(d, _, _, ta) in &joints {
        if d != 0.0 {
            times.extend([ta, total - ta]);
        }
    }
    times.sort_by(f64::total_cmp);
    times.dedup_by(|x, y| (*x - *y).abs() <= 1e-12 * total);
    let mut pieces = Vec::with_capacity(times.len());
    for w in times.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        let mid = 0.5 * (t0 + t1);
        let (position, velocity) = (0..a.len()).map(|j| eval(j, t0)).unzip();
        let acceleration = joints
            .iter()
            .map(|&(d, acc, _, ta)| {
                if d == 0.0 || (mid > ta && mid < total - ta) {
                    0.0
                } else if mid <= ta {
                    d.signum() * acc
                } else {
                    -d.signum() * acc
                }
            })
            .collect();
        pieces.push(Piece {
            duration: t1 - t0,
            position,
            velocity,
            acceleration,
        });
    }
    Trajectory::from_pieces_unchecked(pieces)
}

fn check_dims(a: &[f64], b: &[f64], limits: &Limits) {
    assert!(
        a.len() == limits.dof() && b.len() == limits.dof(),
        "move_time: configurations have {} and {} joints, limits {}",
        a.len(),
        b.len(),
        limits.dof()
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        assert_eq!(Limits::new(vec![], vec![]), Err(TimingError::EmptyLimits));
        assert!(matches!(
            Limits::new(vec![1.0], vec![1.0, 2.0]),
            Err(TimingError::LimitLengthMismatch { .. })
        ));
        assert!(matches!(
            Limits::new(vec![1.0, f64::NAN], vec![1.0, 2.0]),
            Err(TimingError::InvalidLimit {
                joint: 1,
                quantity: "velocity",
                ..
            })
        ));
        assert!(matches!(
            Limits::new(vec![1.0], vec![-1.0]),
            Err(TimingError::InvalidLimit {
                joint: 0,
                quantity: "acceleration",
                ..
            })
        ));
    }

    #[test]
    fn trapezoid_and_triangle_by_hand() {
        // v = 1, a = 2: the switch distance is v²/a = 0.5.
        // d = 2: accelerate 0.5 s over 0.25, cruise 1.5 at 1 m/s = 1.5 s, decelerate 0.5 s.
        assert!((joint_min_time(2.0, 1.0, 2.0) - 2.5).abs() < 1e-12);
        // d = 0.5 exactly at the switch: 2·sqrt(0.25) = 1 = 0.5/1 + 1/2.
        assert!((joint_min_time(0.5, 1.0, 2.0) - 1.0).abs() < 1e-12);
        assert!((joint_min_time(-0.5, 1.0, 2.0) - 1.0).abs() < 1e-12);
        // d = 0.125: triangle, peak at 0.0625 after t = sqrt(0.0625) = 0.25, total 0.5.
        assert!((joint_min_time(0.125, 1.0, 2.0) - 0.5).abs() < 1e-12);
        assert_eq!(joint_min_time(0.0, 1.0, 2.0), 0.0);

        let l = Limits::new(vec![1.0, 3.0, 0.5], vec![2.0, 1.0, 10.0]).unwrap();
        let a = [0.0, 1.0, -1.0];
        let b = [2.0, 1.5, -1.0];
        // joint 0: 2.5 s; joint 1: 0.5 rad, triangle 2·sqrt(0.5) ≈ 1.414; joint 2: 0.
        assert!((move_time(&a, &b, &l) - 2.5).abs() < 1e-12);
        assert!((move_time_instant(&a, &b, &l) - 2.0).abs() < 1e-12);
        assert_eq!(move_time(&a, &a, &l), 0.0);
        // joint 1 alone longer: 4 rad at v=3, a=1: 4 > 9? no → triangle 2·sqrt(4) = 4 s.
        let b2 = [0.1, 5.0, -1.0];
        assert!((move_time(&a, &b2, &l) - 4.0).abs() < 1e-12);
        // symmetric
        assert_eq!(move_time(&a, &b2, &l), move_time(&b2, &a, &l));
    }

    #[test]
    fn move_trajectory_realises_move_time() {
        let l = Limits::new(vec![1.0, 3.0, 0.5, 2.0], vec![2.0, 1.0, 10.0, 4.0]).unwrap();
        let a = [0.0, 1.0, -1.0, 0.3];
        for b in [
            [2.0, 1.5, -1.0, 0.2],
            [0.1, 5.0, -2.0, -3.0],
            [0.0, 1.0, -1.0, 0.3],
        ] {
            let t = move_trajectory(&a, &b, &l);
            assert!((t.duration() - move_time(&a, &b, &l)).abs() < 1e-12);
            assert!(super::super::check_limits(&t, &l, 1e-9).is_ok());
            assert!(t.end_position().iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-9));
            assert!(t.velocity(t.duration()).iter().all(|v| v.abs() < 1e-9));
            // monotone per joint: within the box of a and b
            for (_, q) in t.sample(0.01) {
                for j in 0..4 {
                    assert!(q[j] >= a[j].min(b[j]) - 1e-12 && q[j] <= a[j].max(b[j]) + 1e-12);
                }
            }
        }
    }

    #[test]
    #[should_panic]
    fn dimension_mismatch_panics() {
        let l = Limits::uniform(2, 1.0, 1.0).unwrap();
        move_time(&[0.0], &[1.0, 2.0], &l);
    }
}

//! Per-joint limits and point-to-point move times.

use super::TimingError;

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
    #[should_panic]
    fn dimension_mismatch_panics() {
        let l = Limits::uniform(2, 1.0, 1.0).unwrap();
        move_time(&[0.0], &[1.0, 2.0], &l);
    }
}

//! Exact limit checks on trajectories.

use super::{Limits, Trajectory};

/// The first limit a trajectory breaks, with the joint, the time (s) and the values.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitViolation {
    /// The trajectory and the limits differ in joint count.
    #[error("trajectory has {found} joints, limits {expected}")]
    Dimension {
        /// Joints in the limits.
        expected: usize,
        /// Joints in the trajectory.
        found: usize,
    },
    /// `|velocity| > limit + tol`.
    #[error("joint {joint}: velocity {value} exceeds {limit} at t = {time} s")]
    Velocity {
        /// Joint index.
        joint: usize,
        /// Time in s.
        time: f64,
        /// Velocity there.
        value: f64,
        /// The limit.
        limit: f64,
    },
    /// `|acceleration| > limit + tol`.
    #[error("joint {joint}: acceleration {value} exceeds {limit} at t = {time} s")]
    Acceleration {
        /// Joint index.
        joint: usize,
        /// Start time of the piece, in s.
        time: f64,
        /// Acceleration over the piece.
        value: f64,
        /// The limit.
        limit: f64,
    },
    /// Position outside `[lower − tol, upper + tol]`.
    #[error("joint {joint}: position {value} outside [{lower}, {upper}] at t = {time} s")]
    Position {
        /// Joint index.
        joint: usize,
        /// Time in s.
        time: f64,
        /// Position there.
        value: f64,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// Position or velocity differ by more than `tol` across a piece boundary.
    #[error("joint {joint}: {quantity} jumps from {before} to {after} at t = {time} s")]
    Jump {
        /// Joint index.
        joint: usize,
        /// `"position"` or `"velocity"`.
        quantity: &'static str,
        /// Time of the boundary, in s.
        time: f64,
        /// Value at the end of the earlier piece.
        before: f64,
        /// Value at the start of the later piece.
        after: f64,
    },
}

/// Checks a trajectory exactly against velocity and acceleration limits, and checks that
/// position and velocity are continuous across piece boundaries; `tol` is an absolute slack in
/// the units of each quantity. Velocity is linear within a piece, so its extremes are at the
/// piece ends, and acceleration is constant: the check is exact, O(pieces · dof).
pub fn check_limits(traj: &Trajectory, limits: &Limits, tol: f64) -> Result<(), LimitViolation> {
    if traj.dof() != limits.dof() {
        return Err(LimitViolation::Dimension {
            expected: limits.dof(),
            found: traj.dof(),
        });
    }
    let starts = traj.piece_starts();
    let mut prev: Option<(Vec<f64>, Vec<f64>)> = None;
    for (p, &t0) in traj.pieces().iter().zip(starts) {
        if let Some((q_end, v_end)) = &prev {
            for j in 0..traj.dof() {
                for (quantity, before, after) in [
                    ("position", q_end[j], p.position[j]),
                    ("velocity", v_end[j], p.velocity[j]),
                ] {
                    if (before - after).abs() > tol {
                        return Err(LimitViolation::Jump {
                            joint: j,
                            quantity,
                            time: t0,
                            before,
                            after,
                        });
                    }
                }
            }
        }
        let v_end = p.end_velocity();
        for (j, &v_end_j) in v_end.iter().enumerate() {
            let (vmax, amax) = (limits.velocity[j], limits.acceleration[j]);
            if p.acceleration[j].abs() > amax + tol {
                return Err(LimitViolation::Acceleration {
                    joint: j,
                    time: t0,
                    value: p.acceleration[j],
                    limit: amax,
                });
            }
            for (time, value) in [(t0, p.velocity[j]), (t0 + p.duration, v_end_j)] {
                if value.abs() > vmax + tol {
                    return Err(LimitViolation::Velocity {
                        joint: j,
                        time,
                        value,
                        limit: vmax,
                    });
                }
            }
        }
        prev = Some((p.end_position(), v_end));
    }
    Ok(())
}

/// Checks exactly that every joint stays within `[lower − tol, upper + tol]`: within a piece a
/// joint is quadratic in time, so its extremes are at the piece ends or where its velocity
/// vanishes. Panics if the bounds' lengths differ from the trajectory's joint count.
pub fn check_position_limits(
    traj: &Trajectory,
    lower: &[f64],
    upper: &[f64],
    tol: f64,
) -> Result<(), LimitViolation> {
    assert!(
        lower.len() == traj.dof() && upper.len() == traj.dof(),
        "check_position_limits: bounds for {} and {} joints, trajectory has {}",
        lower.len(),
        upper.len(),
        traj.dof()
    );
    for (p, &t0) in traj.pieces().iter().zip(traj.piece_starts()) {
        for j in 0..traj.dof() {
            let (q, v, a) = (p.position[j], p.velocity[j], p.acceleration[j]);
            let mut taus = vec![0.0, p.duration];
            if a != 0.0 {
                let tau = -v / a;
                if tau > 0.0 && tau < p.duration {
                    taus.push(tau);
                }
            }
            for tau in taus {
                let value = q + tau * (v + 0.5 * tau * a);
                if value < lower[j] - tol || value > upper[j] + tol {
                    return Err(LimitViolation::Position {
                        joint: j,
                        time: t0 + tau,
                        value,
                        lower: lower[j],
                        upper: upper[j],
                    });
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::Piece;
    use super::*;

    fn piece(q: f64, v: f64, a: f64, d: f64) -> Piece {
        Piece {
            duration: d,
            position: vec![q],
            velocity: vec![v],
            acceleration: vec![a],
        }
    }

    #[test]
    fn detects_each_violation() {
        let l = Limits::uniform(1, 1.0, 2.0).unwrap();
        let ok = Trajectory::new(vec![piece(0.0, 0.0, 2.0, 0.5), piece(0.25, 1.0, -2.0, 0.5)]).unwrap();
        assert_eq!(check_limits(&ok, &l, 1e-9), Ok(()));
        let fast = Trajectory::new(vec![piece(0.0, 0.0, 2.0, 1.0)]).unwrap();
        assert!(matches!(
            check_limits(&fast, &l, 1e-9),
            Err(LimitViolation::Velocity { time: 1.0, .. })
        ));
        let hard = Trajectory::new(vec![piece(0.0, 0.0, 3.0, 0.1)]).unwrap();
        assert!(matches!(
            check_limits(&hard, &l, 1e-9),
            Err(LimitViolation::Acceleration { .. })
        ));
        let jump = Trajectory::new(vec![piece(0.0, 0.0, 0.0, 1.0), piece(0.0, 0.5, 0.0, 1.0)]).unwrap();
        assert!(matches!(
            check_limits(&jump, &l, 1e-9),
            Err(LimitViolation::Jump {
                quantity: "velocity",
                ..
            })
        ));
        let l2 = Limits::uniform(2, 1.0, 2.0).unwrap();
        assert!(matches!(
            check_limits(&ok, &l2, 0.0),
            Err(LimitViolation::Dimension { .. })
        ));
    }

    #[test]
    fn position_extremum_inside_piece() {
        // goes up to 0.25 at τ = 0.5 and back to 0
        let t = Trajectory::new(vec![piece(0.0, 1.0, -2.0, 1.0)]).unwrap();
        assert_eq!(check_position_limits(&t, &[-0.1], &[0.25], 1e-12), Ok(()));
        match check_position_limits(&t, &[-0.1], &[0.2], 1e-12) {
            Err(LimitViolation::Position { time, value, .. }) => {
                assert!((time - 0.5).abs() < 1e-12 && (value - 0.25).abs() < 1e-12)
            }
            other => panic!("{other:?}"),
        }
    }
}

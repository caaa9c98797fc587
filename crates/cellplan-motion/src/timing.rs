//! Move-time bounds and time parameterisation of joint paths under per-joint velocity and
//! acceleration limits. Units: joint positions in rad (or m for prismatic joints), time in s.
//!
//! The pieces fit together as follows:
//!
//! - [`Limits`] holds the validated per-joint velocity and acceleration limits.
//! - [`move_time`] is the minimum time of a point-to-point move at rest at both ends (each joint
//!   its own trapezoidal or triangular profile, the slowest joint sets the time). It is a lower
//!   bound of the time of *any* motion between the two configurations, collision-free or not,
//!   and is what tour costs (paper 000, eq. 8–9) should be measured in.
//!   [`move_trajectory`] realises it (joints synchronised in time, not on a straight line).
//!   [`move_time_instant`] is paper 000's assumption 2 (every joint reaches its maximum
//!   velocity at once): `max_j |Δq_j| / v_j`, never more than [`move_time`].
//! - [`Trajectory`] is a sequence of [`Piece`]s of constant joint acceleration, so position,
//!   velocity and acceleration are exact at every time.
//! - [`time_path_exact`] times a piecewise-linear joint path (a planner's output) so that it is
//!   followed exactly, stopping at every corner ([`segment_time`] is one segment of it);
//!   [`time_path_blended`] replaces the corners by
//!   parabolic blends within a per-joint deviation bound and is never slower.
//! - [`check_limits`] and [`check_position_limits`] verify a trajectory exactly, piece by piece.

mod check;
mod error;
mod limits;
mod path;
mod trajectory;

pub use check::{LimitViolation, check_limits, check_position_limits};
pub use error::TimingError;
pub use limits::{Limits, joint_min_time, move_time, move_time_instant, move_trajectory};
pub use path::{
    Blend, BlendedPath, TimedPath, segment_time, time_path_blended, time_path_blended_scaled, time_path_exact,
};
pub use trajectory::{Piece, Trajectory};

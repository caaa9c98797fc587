//! Errors of the timing module.

/// Invalid input to a timing function or constructor.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TimingError {
    /// Limits were given for zero joints.
    #[error("limits must cover at least one joint")]
    EmptyLimits,
    /// The velocity and acceleration vectors have different lengths.
    #[error("{velocity} velocity limits but {acceleration} acceleration limits")]
    LimitLengthMismatch {
        /// Number of velocity limits.
        velocity: usize,
        /// Number of acceleration limits.
        acceleration: usize,
    },
    /// A limit is not finite and strictly positive.
    #[error("joint {joint}: {quantity} limit {value} must be finite and > 0")]
    InvalidLimit {
        /// Joint index.
        joint: usize,
        /// `"velocity"` or `"acceleration"`.
        quantity: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A vector has the wrong number of joints.
    #[error("{what}: expected {expected} joints, found {found}")]
    DimensionMismatch {
        /// What was being checked (e.g. `"waypoint 3"`).
        what: String,
        /// Number of joints expected (from the limits or the first element).
        expected: usize,
        /// Number found.
        found: usize,
    },
    /// The path has no waypoints, or a trajectory no pieces.
    #[error("{0} is empty")]
    Empty(&'static str),
    /// A value that must be finite is not (waypoint coordinate, piece duration, ...).
    #[error("{0} is not finite")]
    NonFinite(String),
    /// A piece has a negative duration.
    #[error("piece {index} has negative duration {duration}")]
    NegativeDuration {
        /// Piece index.
        index: usize,
        /// The offending duration in s.
        duration: f64,
    },
    /// A deviation bound is negative or not finite.
    #[error("joint {joint}: deviation bound {value} must be finite and >= 0")]
    InvalidDeviation {
        /// Joint index.
        joint: usize,
        /// The offending value.
        value: f64,
    },
    /// A waypoint's scale of the deviation bound is negative or not finite.
    #[error("waypoint {waypoint}: deviation scale {value} must be finite and >= 0")]
    InvalidScale {
        /// Waypoint index.
        waypoint: usize,
        /// The offending value.
        value: f64,
    },
}

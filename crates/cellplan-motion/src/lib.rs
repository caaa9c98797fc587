//! Joint-space motion with no robot or geometry types in its API: the time a move needs under
//! per-joint velocity and acceleration limits, collision-free path planning behind one
//! interface (a state space, a validity checker, a planner — as OMPL arranges them), and time
//! parameterisation of a path under the limits.
#![warn(missing_docs)]

pub mod plan;
pub mod timing;

//! Joint-space motion: the time a move needs under per-joint velocity and acceleration limits,
//! collision-free path planning behind one interface (a state space, a validity checker, a
//! planner — as OMPL arranges them; [`plan`] knows no robot and no geometry), the arm in a
//! collision world as the validity checker of those planners ([`arm`]), and time
//! parameterisation of a path under the limits.
#![warn(missing_docs)]

pub mod arm;
pub mod plan;
pub mod timing;

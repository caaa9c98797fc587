//! Joint-space motion: the time a move needs under per-joint velocity and acceleration limits,
//! collision-free path planning behind one interface (a state space, a validity checker, a
//! planner — as OMPL arranges them; [`plan`] knows no robot and no geometry), the arm in a
//! collision world as the validity checker of those planners ([`arm`]), planning problems
//! without a cell ([`problem`]: robot, obstacles, start, goals), and time
//! parameterisation of a path under the limits.
#![warn(missing_docs)]

pub mod arm;
pub mod plan;
pub mod problem;
pub mod timing;

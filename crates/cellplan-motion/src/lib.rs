//! Joint-space motion:
//!
//! - [`timing`]: the time a move needs under per-joint velocity and acceleration limits, and
//!   time parameterisation of a path under those limits.
//! - [`plan`] (no robot and no geometry types): collision-free path planning as OMPL arranges
//!   it — a state space ([`plan::JointSpace`]), a validity checker giving a clearance
//!   ([`plan::StateValidity`]), a conservative segment check that misses no contact
//!   ([`plan::check_segment`]), and planners behind one interface ([`plan::MotionPlanner`])
//!   chosen by name from a registry ([`plan::planner`]: `straight`, `rrt-connect`, `rrt-star`,
//!   `prm`, `leg`), each answering a query with one start and one or more goals
//!   ([`plan::Problem`]) within a work budget ([`plan::Termination`]) with a
//!   [`plan::Status`], the path and the work spent.
//! - [`arm`]: a serial arm in a collision world as the validity checker of those planners, with
//!   the sphere-cover broad phase in front of the exact distances.
//! - [`problem`]: planning problems without a cell (robot from URDF + SRDF, obstacles, start,
//!   goals, margin), the format of `docs/motion-problems.md`.
#![warn(missing_docs)]

pub mod arm;
pub mod plan;
pub mod problem;
pub mod timing;

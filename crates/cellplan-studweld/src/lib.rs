//! Paper 002 (Björkenstam et al. 2014, *Efficient sequencing of industrial robots through
//! optimal control*) as a cellplan process: one robot welds studs on a car body; each stud can
//! be welded in several joint configurations (IK branches × gun rotations about the stud
//! axis), and the order and the configurations are chosen as a GTSP whose costs come from an
//! optimal-control problem with the robot's dynamics.
//!
//! - [`process`]: the `stud-weld` process (`[process]` table, gun poses, the weld as a dwell);
//! - [`cell`]: the cell as the planner sees it (robot, dynamics with the gun, limits);
//! - [`alternatives`]: the alternatives of each stud and their node (holding) costs;
//! - [`leg`]: one move between two configurations — a collision-free path of the motion
//!   planner, then the DMOC optimal-control problem started along it, checked densely for
//!   collisions, with a timed-path fallback;
//! - [`sequence`]: the two sequencers of Table 2 (travel time, optimal control — lazy);
//! - [`plan`] and [`document`]: one run and the plan document (`cellplan-studweld-plan` v1);
//! - [`profile`]: a move's velocities and torques over time (the report's plots).
#![warn(missing_docs)]
#![allow(clippy::result_large_err)]
// Index loops over several arrays at once read as the formulas do.
#![allow(clippy::needless_range_loop)]

pub mod alternatives;
pub mod cell;
pub mod document;
pub mod leg;
pub mod plan;
pub mod process;
pub mod profile;
pub mod sequence;
pub mod trust;

use cellplan_model::{InputError, ProcessEntry};
pub use process::{KIND, StudWeld};

/// The registry entry of the `stud-weld` process.
pub const ENTRY: ProcessEntry = ProcessEntry {
    kind: KIND,
    summary: "stud welding by one robot, sequenced on optimal-control costs (paper 002)",
    task_columns: &[],
    build: process::build,
};

/// A registry with this process alone (for tests and embedding).
pub fn registry() -> cellplan_model::Registry {
    cellplan_model::Registry::new().with(ENTRY)
}

/// Loads a cell with [`registry`].
#[allow(clippy::result_large_err)]
pub fn load(
    path: &std::path::Path,
    opts: &cellplan_model::LoadOptions,
) -> Result<cellplan_model::Cell, InputError> {
    cellplan_model::load(path, &registry(), opts)
}

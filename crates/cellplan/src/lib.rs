//! cellplan: plans the work of a multi-robot manufacturing cell.
//!
//! Data flows one way (see `docs/architecture.md`): a cell file is [loaded](model::load) into a
//! [`Cell`]; [`candidates::generate`] finds, for every task and robot, the feasible ways to do
//! the task (or why there are none); [`report::check`] summarises them. Later stages —
//! allocation, sequencing, motion, timing, coordination — consume those candidates.
#![warn(missing_docs)]
// `InputError` carries the source text and span for its snippet; it is built once, on the cold
// path of refusing input, so its size does not matter.
#![allow(clippy::result_large_err)]

pub mod candidates;
pub mod coord;
pub mod error;
pub mod export;
pub mod io;
pub mod model;
pub mod motion;
pub mod plan;
pub mod process;
pub mod report;
pub mod taskgen;
pub mod verify;

pub use candidates::{Candidate, CandidateTable};
pub use error::InputError;
pub use model::robot::{Robot, RobotId};
pub use model::tasks::{Task, TaskId};
pub use model::{Cell, LoadOptions, Process};

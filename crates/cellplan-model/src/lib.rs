//! The cellplan cell model: the cell file as written ([`spec`]) and as loaded ([`Cell`]: robots
//! with their kinematics and collision bodies, static objects, tasks, the collision world, the
//! shared `[planning]` limits), the [`Process`] interface every process implements and the
//! [`Registry`] that finds one by `[process] kind`, and [`InputError`] for input that cellplan
//! cannot use (file, line, what is wrong, what to do).
#![warn(missing_docs)]
// `InputError` carries the source text and span for its snippet; it is built once, on the cold
// path of refusing input, so its size does not matter.
#![allow(clippy::result_large_err)]

pub mod cell;
pub mod document;
pub mod error;
pub mod hash;
pub mod io;
pub mod load;
pub mod names;
pub mod pose;
pub mod process;
pub mod robot;
pub mod self_pairs;
pub mod spec;
pub mod taskgen;
pub mod tasks;
#[cfg(test)]
pub(crate) mod testing;

pub use cell::{Cell, Object, Planning};
pub use error::{InputError, other_separator, shown};
pub use load::{LoadOptions, load, process_kind};
pub use process::{
    ColumnUnit, Figure, Process, ProcessEntry, ProcessInput, ProcessReason, Registry, Rejection, Relation,
    TaskColumn, Words, Work,
};
pub use robot::{Robot, RobotId};
pub use tasks::{Task, TaskId};

//! Paper 004 (Bonert, Shu, Benhabib: motion planning for multi-robot assembly systems) as a
//! cellplan process: PCB assembly as an augmented travelling-salesperson problem (TSP+), where
//! the placement robots, the component feeders and the board table all move, and the plan
//! chooses the placement order, the bins of each component type, where each pick and each
//! placement meet, and with two robots which robot places what.
//!
//! - [`board`]: KiCad 6–9 boards and position files (with [`sexpr`], the S-expression reader);
//! - [`cell`]: the machine (`[process] kind = "pcb-assembly"`);
//! - [`sim`]: the cycle-time model of §3.1 and §4.1–4.2 with the safety delays of the walls
//!   model;
//! - [`rendezvous`]: our rendezvous rule for a given order;
//! - [`ga`]: the paper's genetic algorithm with its compound genome;
//! - [`search`]: our optimiser;
//! - [`bound`]: a lower bound on the assembly time;
//! - [`document`]: the plan document.
// Input errors carry the file's text for their snippet; they are built once, on the cold path
// of refusing input.
#![allow(clippy::result_large_err)]

pub mod board;
pub mod bound;
pub mod cell;
pub mod document;
pub mod ga;
pub mod plan;
pub mod rendezvous;
pub mod search;
pub mod sexpr;
pub mod sim;
pub mod testing;

pub use cell::{Configuration, MotionModel, PcbCell, load};

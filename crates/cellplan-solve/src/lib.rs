//! Combinatorial optimisation with no robotics in it: the problems every cellplan planner ends
//! in — which machine takes which task, in which order, visiting which of several alternative
//! nodes — on plain cost matrices and clusters, so they can be measured on the field's standard
//! instances (TSPLIB, GTSPLIB, OR-Library).
//!
//! - [`problem`]: [`CostMatrix`] and [`Gtsp`] (clusters of alternative nodes, fixed start and
//!   end, service times).
//! - [`io`]: readers for TSPLIB, GTSPLIB and OR-Library set-cover files.
//! - [`held_karp`]: the exact dynamic programme over clusters for small instances.
#![warn(missing_docs)]

pub mod error;
pub mod held_karp;
pub mod io;
pub mod problem;

pub use error::{CostMatrixError, CoverError, Depot, GtspError, ReadError, TourError};
pub use problem::{CostMatrix, Gtsp, SetCover, Tour};
pub mod gtsp;
pub use gtsp::{GtspMethod, GtspParams, Solution, solve as solve_gtsp};

pub mod setcover;
pub use setcover::Cover;
pub mod minmax;

//! The generic cellplan pipeline. A [`Cell`](cellplan_model::Cell) with its process becomes
//! [`candidates`] (every task × robot: the feasible configurations, or why there are none);
//! [`plan`] allocates, sequences, plans collision-free legs ([`motion`]) and times them;
//! [`coord`] puts every robot on one clock and resolves robot–robot conflicts; [`document`] is
//! the Plan document (its independent check is the `cellplan-verify` crate); [`pipeline`] runs the stages as
//! `cellplan plan` does and owns the choice of "ours" once. No process is named here: what
//! differs between processes comes through [`cellplan_model::Process`].
#![warn(missing_docs)]

pub mod candidates;
pub mod check;
pub mod coord;
pub mod document;
pub mod motion;
pub mod pipeline;
pub mod plan;

pub use candidates::{Candidate, CandidateTable};
pub use document::Plan;

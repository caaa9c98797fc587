//! Reports for people and machines.
pub mod check;
pub mod svg;

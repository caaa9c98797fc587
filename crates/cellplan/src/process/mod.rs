//! Processes: what a cell does at a task, and the physical constraints of doing it.
pub mod optical;

//! Paper 003 (Zhao, Wang, Liu: path planning for 5-axis CMM inspection considering path reuse)
//! as a cellplan process (`[process] kind = "cmm-inspection"`):
//!
//! - [`cell`]: the cell file — machine, head, probe, the part posed, fixtures, the MPs.
//! - [`plan`]: plan a cell (or a subset), reuse a plan for a subset; [`document`]: the plan
//!   document (`cellplan-cmm-plan` v1), checked by `cellplan-verify::cmm`.
//! - [`part`]: the cylinder-block-like test part, generated as a mesh with its 39 measuring
//!   points (the paper's case has 39 MPs on a cylinder block; its geometry is not published).
//! - [`housing`]: a second test part, a gearbox or pump housing on a base flange, with 40
//!   measuring points (a bore from the top, a bored boss on a side, a face inclined 30°, the
//!   flange around the body).
//! - [`classify`]: §3.1, the MPs grouped by probe orientation (eq. 3) as a set cover, greedy
//!   (the paper's) or exact.
//! - [`motion`]: the CMM's configuration space and the probe's clearance for the shared motion
//!   planners.
//! - [`job`]: a whole job — groups, their paths, the orders (the paper's enhanced GA or ours) and
//!   Table 3's times.
//! - [`mrnc`]: §3.2, RRT-MRNC (Algorithms 1–4) for one orientation group, and reuse of its
//!   stored paths for any subset of the group's MPs.
//!
//! The machine's kinematics and motion model are `cellplan_kin::cmm`.
#![warn(missing_docs)]
// Input errors are built once, on the cold path of refusing a file.
#![allow(clippy::result_large_err)]

mod builder;
pub mod cell;
pub mod classify;
pub mod document;
pub mod housing;
pub mod job;
pub mod motion;
pub mod mrnc;
pub mod part;
pub mod plan;
#[cfg(test)]
mod scene;

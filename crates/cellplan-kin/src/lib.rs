//! Robot kinematics for cellplan: URDF serial chains, forward kinematics of every link,
//! analytic inverse kinematics for ortho-parallel industrial arms (OPW) and a numeric
//! damped-least-squares solver for the rest.
//!
//! - [`urdf`]: [`load_urdf`] reads a URDF (resolving `package://` URIs) into a [`RobotModel`].
//! - [`srdf`]: the `disable_collisions` rules of an SRDF.
//! - [`chain`]: the serial [`Chain`], its [`Joint`]s and forward kinematics.
//! - [`opw`]: [`OpwParameters`] and the closed-form solution with all eight branches.
//! - [`parallel`]: [`ParallelIk`], the closed form of arms with three parallel axes and an
//!   offset wrist (Universal Robots), read off the chain.
//! - [`track`]: [`TrackIk`], an OPW arm on a linear track: track positions sampled around the
//!   target, the arm's closed form at each.
//! - [`cmm`]: a five-axis CMM head and probe (paper 003): closed-form inverse from ball centre and
//!   probe direction, the move-or-rotate motion model.
//! - [`ik`]: the [`IkSolver`] trait, [`OpwIk`] (OPW on a URDF chain), [`DlsIk`] (numeric),
//!   and joint-limit filtering with ±2π variants.
//!
//! Units: metres and radians. Poses are `cellplan_geom::Pose`.
#![warn(missing_docs)]

mod axes;
pub mod chain;
pub mod cmm;
pub mod dynamics;
pub mod error;
pub mod ik;
pub mod opw;
pub mod parallel;
pub mod srdf;
pub mod track;
pub mod urdf;

pub use chain::{Chain, ChainLink, Joint, JointKind, pose_error};
pub use error::KinError;
pub use ik::{DlsIk, DlsParams, IkSolver, LIMIT_TOLERANCE, OpwIk, limit_variants};
pub use opw::{OpwParameters, wrap_angle};
pub use parallel::ParallelIk;
pub use track::TrackIk;
pub use urdf::{RobotModel, load_urdf, load_urdf_str};

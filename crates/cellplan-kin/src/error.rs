//! Errors of the kinematics crate.
use std::path::PathBuf;

/// A robot model could not be built.
#[derive(Debug, thiserror::Error)]
pub enum KinError {
    /// A file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The URDF is malformed or unusable.
    #[error("{path}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Urdf {
        /// The URDF file.
        path: PathBuf,
        /// 1-based line where known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
        /// What to do about it.
        hint: String,
    },
    /// A mesh named by the URDF could not be loaded.
    #[error("mesh of link '{link}' in {}{}: {source}", urdf.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Mesh {
        /// The URDF file.
        urdf: PathBuf,
        /// 1-based line of the `<mesh>` element, where known.
        line: Option<usize>,
        /// The link.
        link: String,
        /// The cause.
        source: Box<cellplan_geom::MeshError>,
    },
    /// OPW parameters are malformed, or do not match the chain they are used with.
    #[error("{path}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Opw {
        /// The file (or the URDF when parameters do not match it).
        path: PathBuf,
        /// 1-based line where known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
}

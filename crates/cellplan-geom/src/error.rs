//! Errors of the geometry crate.
use std::path::PathBuf;

/// A mesh file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file could not be opened or read.
    #[error("cannot read mesh file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a valid mesh of its format.
    #[error("{path}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line, for text formats.
        line: Option<usize>,
        /// What is wrong, and what to do about it.
        message: String,
    },
    /// The extension names no format we read.
    #[error("{path}: unsupported mesh format (expected .stl or .obj)")]
    Unsupported {
        /// The file.
        path: PathBuf,
    },
}

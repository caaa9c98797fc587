//! Errors of the instance readers in [`crate::io`].
use std::path::{Path, PathBuf};

/// Why an instance file could not be read. Every variant except [`ReadError::Io`] names the file,
/// the line (1-based) when one is to blame, and says what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("cannot read `{}`: {source}; check that the path exists and is readable", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The text does not follow the format (a missing keyword, a non-number, a short section).
    #[error("{}: {message}", location(.path, .line))]
    Syntax {
        /// The file (`<text>` when parsing a string).
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is wrong and what was expected.
        message: String,
    },
    /// Well-formed, but a feature this reader does not handle (another problem TYPE, an
    /// unsupported EDGE_WEIGHT_TYPE or EDGE_WEIGHT_FORMAT).
    #[error("{}: {message}", location(.path, .line))]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is not supported and what is.
        message: String,
    },
    /// Parsed, but the numbers are inconsistent (an index out of range, a node in two sets, a
    /// negative cost).
    #[error("{}: {message}", location(.path, .line))]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is inconsistent and what would be valid.
        message: String,
    },
}

impl ReadError {
    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            ReadError::Io { path, .. }
            | ReadError::Syntax { path, .. }
            | ReadError::Unsupported { path, .. }
            | ReadError::Invalid { path, .. } => path,
        }
    }

    /// The 1-based line at fault, when one is.
    pub fn line(&self) -> Option<usize> {
        match self {
            ReadError::Io { .. } => None,
            ReadError::Syntax { line, .. }
            | ReadError::Unsupported { line, .. }
            | ReadError::Invalid { line, .. } => *line,
        }
    }
}

impl ReadError {
    /// What is wrong, without the file and line (for callers that show those themselves).
    pub fn detail(&self) -> String {
        match self {
            ReadError::Io { source, .. } => format!("cannot read the file: {source}"),
            ReadError::Syntax { message, .. }
            | ReadError::Unsupported { message, .. }
            | ReadError::Invalid { message, .. } => message.clone(),
        }
    }
}

fn location(path: &Path, line: &Option<usize>) -> String {
    match line {
        Some(l) => format!("{}:{l}", path.display()),
        None => path.display().to_string(),
    }
}

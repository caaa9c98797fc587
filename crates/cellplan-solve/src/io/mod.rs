//! Readers for the standard benchmark formats: TSPLIB ([`read_tsplib`]), GTSPLIB
//! ([`read_gtsplib`]), OR-Library set cover ([`read_orlib_setcover`]) and cellplan's own
//! min-max format ([`read_minmax`], written by [`write_minmax`]). Each has a `parse_*` twin that
//! reads from a string. Errors name the file and line and say what was expected.
use std::path::{Path, PathBuf};

use crate::error::ReadError;

mod gtsplib;
mod minmax;
mod orlib;
mod tsplib;

pub use gtsplib::{GtspInstance, parse_gtsplib, read_gtsplib};
pub use minmax::{MinMaxInstance, parse_minmax, read_minmax, read_minmax_instance, write_minmax};
pub use orlib::{parse_orlib_setcover, read_orlib_setcover};
pub use tsplib::{TsplibInstance, parse_optima, parse_tsplib, read_optima, read_tsplib};

/// The path reported for errors in text parsed from a string.
pub(crate) const TEXT: &str = "<text>";

pub(crate) fn read_text(path: &Path) -> Result<String, ReadError> {
    std::fs::read_to_string(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Error constructors bound to one file.
#[derive(Clone, Copy)]
pub(crate) struct Ctx<'a> {
    pub path: &'a Path,
}

impl Ctx<'_> {
    pub fn syntax(&self, line: Option<usize>, message: impl Into<String>) -> ReadError {
        ReadError::Syntax {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
        }
    }
    pub fn unsupported(&self, line: Option<usize>, message: impl Into<String>) -> ReadError {
        ReadError::Unsupported {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
        }
    }
    pub fn invalid(&self, line: Option<usize>, message: impl Into<String>) -> ReadError {
        ReadError::Invalid {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    /// Parse `tok` (on 1-based `line`) as a number, saying what it should have been.
    pub fn number(&self, line: usize, tok: &str, what: &str) -> Result<f64, ReadError> {
        match tok.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.syntax(Some(line), format!("expected {what} (a number), found `{tok}`"))),
        }
    }

    /// Parse `tok` as a non-negative integer.
    pub fn integer(&self, line: usize, tok: &str, what: &str) -> Result<usize, ReadError> {
        tok.parse::<usize>().map_err(|_| {
            self.syntax(
                Some(line),
                format!("expected {what} (a non-negative integer), found `{tok}`"),
            )
        })
    }
}

pub(crate) fn text_path() -> PathBuf {
    PathBuf::from(TEXT)
}

/// Whitespace-separated tokens with their 1-based line numbers.
pub(crate) fn tokens(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .flat_map(|(i, l)| l.split_whitespace().map(move |t| (i + 1, t)))
}

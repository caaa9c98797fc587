//! Readers for the standard benchmark formats: TSPLIB ([`read_tsplib`]), GTSPLIB
//! ([`read_gtsplib`]), OR-Library set cover ([`read_orlib_setcover`]) and cellplan's own
//! min-max format ([`read_minmax`], written by [`write_minmax`]). Each has a `parse_*` twin that
//! reads from a string. Errors name the file and line and say what was expected.
//!
//! Bad input is refused, never a panic or an unbounded allocation: files are read up to
//! [`MAX_FILE_BYTES`] and must be UTF-8, and every stated count is bounded before anything is
//! allocated for it (nodes of a dense matrix [`MAX_DENSE_NODES`], min-max [`MAX_VEHICLES`] and
//! [`MAX_TASKS`]) and must agree with the data that follows.
use std::path::{Path, PathBuf};

use crate::error::ReadError;

mod gtsplib;
mod minmax;
mod orlib;
mod tsplib;

pub use gtsplib::{GtspInstance, parse_gtsplib, read_gtsplib};
pub use minmax::{
    MAX_TASKS, MAX_VEHICLES, MinMaxInstance, parse_minmax, read_minmax, read_minmax_instance, write_minmax,
};
pub use orlib::{parse_orlib_setcover, read_orlib_setcover};
pub use tsplib::{TsplibInstance, parse_optima, parse_tsplib, read_optima, read_tsplib};

/// The path reported for errors in text parsed from a string.
pub(crate) const TEXT: &str = "<text>";

/// Largest instance file read, in bytes (512 MiB): the biggest published TSPLIB, GTSPLIB and
/// OR-Library files are a few tens of MiB, so anything larger is not a benchmark file.
pub const MAX_FILE_BYTES: u64 = 512 << 20;

/// Largest node count of a format stored as a dense `n × n` matrix of `f64` (TSPLIB DIMENSION,
/// GTSPLIB DIMENSION, GLNS `N`, min-max `NODES`): 15,000² × 8 bytes = 1.8 GB.
pub const MAX_DENSE_NODES: usize = 15_000;

/// The most a stated count may be, and why (shown after the number).
#[derive(Clone, Copy)]
pub(crate) struct Limit {
    pub max: usize,
    pub why: &'static str,
}

/// Nodes of a dense matrix.
pub(crate) const DENSE_NODES: Limit = Limit {
    max: MAX_DENSE_NODES,
    why: " (it stores a dense n × n matrix: 15000 nodes take 1.8 GB)",
};

/// Disjoint non-empty sets of the nodes of a dense matrix.
pub(crate) const SETS: Limit = Limit {
    max: MAX_DENSE_NODES,
    why: " (sets are disjoint and non-empty, so at most one per node, and nodes are at most 15000)",
};

pub(crate) fn read_text(path: &Path) -> Result<String, ReadError> {
    read_text_limited(path, MAX_FILE_BYTES)
}

/// `limit` as people read it: whole MiB when it is some, else bytes.
fn show_bytes(limit: u64) -> String {
    if limit >= 1 << 20 && limit.is_multiple_of(1 << 20) {
        format!("{} MiB", limit >> 20)
    } else {
        format!("{limit} bytes")
    }
}

/// Reads at most `limit` bytes of `path` as UTF-8 text. A regular file larger than `limit` is
/// refused before reading; anything else (a pipe, `/dev/zero`) is read up to `limit + 1` bytes
/// and refused if it has more. Never allocates more than `limit + 1` bytes.
pub(crate) fn read_text_limited(path: &Path, limit: u64) -> Result<String, ReadError> {
    use std::io::Read as _;
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let ctx = Ctx { path };
    let too_large = |size: String| {
        ctx.invalid(
            None,
            format!(
                "the file is {size}, larger than the {} this reader takes for an instance file; \
                 check that the path names a benchmark instance",
                show_bytes(limit)
            ),
        )
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let stated = file.metadata().ok().filter(|m| m.is_file()).map(|m| m.len());
    if let Some(len) = stated
        && len > limit
    {
        return Err(too_large(format!("{len} bytes")));
    }
    // `stated <= limit` here, so the reservation is bounded.
    let mut bytes = Vec::with_capacity(stated.map_or(0, |l| l as usize + 1));
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(format!("more than {limit} bytes")));
    }
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        ctx.syntax(
            Some(line),
            format!(
                "byte {at} (0x{:02x}) is not UTF-8 text; instance files are plain text: check that \
                 the path names a benchmark instance, or convert the file to UTF-8",
                bytes[at]
            ),
        )
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

    /// Parse `tok` as the count stated by header field `field` (of nodes, sets, tasks, ...),
    /// refusing more than `limit` before anything is allocated for it. `what` says what the
    /// count is, for a token that is no integer at all.
    pub fn count(
        &self,
        line: usize,
        tok: &str,
        field: &str,
        what: &str,
        limit: Limit,
    ) -> Result<usize, ReadError> {
        let Limit { max, why } = limit;
        let too_many = |shown: &str| {
            self.invalid(
                Some(line),
                format!(
                    "{field} is {shown}, more than the {max} this reader takes{why}; check the \
                     count, or split the instance"
                ),
            )
        };
        match tok.parse::<usize>() {
            Ok(n) if n > max => Err(too_many(&n.to_string())),
            Ok(n) => Ok(n),
            // All digits but too big even for usize.
            Err(_) if !tok.is_empty() && tok.bytes().all(|b| b.is_ascii_digit()) => Err(too_many(tok)),
            Err(_) => Err(self.syntax(
                Some(line),
                format!("expected {what} (a non-negative integer), found `{tok}`"),
            )),
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[cfg(target_os = "linux")]
    #[test]
    fn endless_input_stops_at_the_limit() {
        let e = read_text_limited(Path::new("/dev/zero"), 4096).unwrap_err();
        assert!(matches!(e, ReadError::Invalid { line: None, .. }), "{e:?}");
        assert_eq!(
            e.to_string(),
            "/dev/zero: the file is more than 4096 bytes, larger than the 4096 bytes this reader \
             takes for an instance file; check that the path names a benchmark instance"
        );
    }

    #[test]
    fn counts_name_field_count_and_limit() {
        let p = text_path();
        let ctx = Ctx { path: &p };
        let limit = Limit { max: 12, why: "" };
        assert_eq!(ctx.count(7, "12", "N", "nodes", limit).unwrap(), 12);
        let e = ctx.count(7, "13", "N", "nodes", limit).unwrap_err();
        assert_eq!(
            e.to_string(),
            "<text>:7: N is 13, more than the 12 this reader takes; check the count, or split the instance"
        );
        let e = ctx.count(7, "-1", "N", "the number of nodes", limit).unwrap_err();
        assert!(matches!(e, ReadError::Syntax { line: Some(7), .. }), "{e}");
    }
}

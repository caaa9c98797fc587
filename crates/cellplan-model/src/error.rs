//! Errors of the cellplan core: bad input that names its file, line and a fix.
use miette::{NamedSource, SourceSpan};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Input that cellplan cannot use: a malformed or inconsistent cell file, task list, URDF or
/// mesh, or a cell in which a robot can do nothing. It names the file, the line where there is
/// one, what is wrong and what to do about it.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
#[diagnostic(code(cellplan::input))]
pub struct InputError {
    /// The file at fault.
    pub path: PathBuf,
    /// 1-based line, where the fault has one.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
    /// What to do about it.
    #[help]
    pub hint: Option<String>,
    #[source_code]
    source_code: Option<NamedSource<String>>,
    #[label("here")]
    label: Option<SourceSpan>,
}

impl InputError {
    /// An error about a whole file (no line).
    pub fn new(path: &Path, message: impl Into<String>) -> Self {
        InputError {
            path: path.to_path_buf(),
            line: None,
            message: message.into(),
            hint: None,
            source_code: None,
            label: None,
        }
    }

    /// An error at a 1-based line of a file whose text we do not hold.
    pub fn at_line(path: &Path, line: Option<usize>, message: impl Into<String>) -> Self {
        InputError {
            line,
            ..InputError::new(path, message)
        }
    }

    /// An error at a byte range of a text we hold (the line is derived, the snippet shown).
    pub fn at_span(path: &Path, text: &str, span: Range<usize>, message: impl Into<String>) -> Self {
        let start = span.start.min(text.len());
        let end = span.end.clamp(start, text.len());
        InputError {
            path: path.to_path_buf(),
            line: Some(line_of(text, start)),
            message: message.into(),
            hint: None,
            source_code: Some(NamedSource::new(path.display().to_string(), text.to_string())),
            label: Some((start, end - start).into()),
        }
    }

    /// Adds the hint.
    pub fn hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(hint.into());
        self
    }
}

/// 1-based line of byte offset `offset` in `text`.
pub fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// A number from the input as an error message shows it: as written (`1.5`, `-1`, `NaN`) while
/// it is of a size people write, in scientific notation beyond (`1e300`, `2.5e-9`). Rust's
/// own `{}` spells 1e300 out in 301 digits.
pub fn shown(v: f64) -> String {
    let a = v.abs();
    if v.is_finite() && a != 0.0 && !(1e-4..1e9).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Where a comma-separated file's first line (`text`'s, read from `path`) has no comma but
/// another separator a spreadsheet writes (`;`, a tab, `|`), the error to give at that line:
/// its columns cannot be found. `None` where it has a comma or none of those.
pub fn other_separator(path: &Path, text: &str) -> Option<InputError> {
    let first = text
        .lines()
        .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))?;
    if first.contains(',') {
        return None;
    }
    let (_, name) = [(';', "`;`"), ('\t', "tabs"), ('|', "`|`")]
        .into_iter()
        .find(|(c, _)| first.contains(*c))?;
    Some(
        InputError::at_line(
            path,
            Some(1),
            format!("the header's columns are separated by {name}, not by commas"),
        )
        .hint(
            "save the file as comma-separated values with `.` as the decimal mark (a spreadsheet set to a \
             language that writes `;` and `,` needs that chosen in its CSV export)",
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn other_separators_are_named() {
        let p = Path::new("t.csv");
        let e = other_separator(p, "id;x;y;z;nx;ny;nz\nM1;0,5;0;0;0;0;1\n").unwrap();
        assert!(e.message.contains("`;`") && e.line == Some(1), "{e}");
        let e = other_separator(p, "# made by hand\nid\tx\ty\n").unwrap();
        assert!(e.message.contains("tabs"), "{e}");
        assert!(other_separator(p, "id,x;y\n").is_none());
        assert!(other_separator(p, "id x y\n").is_none());
        assert!(other_separator(p, "").is_none());
    }

    #[test]
    fn span_errors_carry_the_line() {
        let text = "a = 1\nb = 2\nc = oops\n";
        let at = text.find("oops").unwrap();
        let e = InputError::at_span(Path::new("cell.toml"), text, at..at + 4, "bad value");
        assert_eq!(e.line, Some(3));
        assert_eq!(e.to_string(), "cell.toml:3: bad value");
    }

    #[test]
    fn numbers_are_shown_short() {
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(-2.5e-9), "-2.5e-9");
        assert_eq!(shown(6e9), "6e9");
        assert_eq!(shown(1.5), "1.5");
        assert_eq!(shown(-1.0), "-1");
        assert_eq!(shown(0.0), "0");
        assert_eq!(shown(123_456_789.0), "123456789");
        assert_eq!(shown(f64::NAN), "NaN");
        assert_eq!(shown(f64::INFINITY), "inf");
    }

    #[test]
    fn line_of_counts_newlines_before_offset() {
        assert_eq!(line_of("x\ny\nz", 0), 1);
        assert_eq!(line_of("x\ny\nz", 2), 2);
        assert_eq!(line_of("x\ny\nz", 100), 3);
    }
}

//! OR-Library set-cover files (Beasley): `m n`, the `n` column costs, then for every row the
//! number of columns covering it followed by those columns (1-based). Numbers wrap across lines
//! freely.
use std::path::Path;

use super::{Ctx, Limit, read_text, text_path, tokens};
use crate::error::ReadError;
use crate::problem::SetCover;

/// Read an OR-Library set-cover file (`scp*.txt`). Column indices become 0-based; each row's list
/// is sorted and repeats are dropped.
pub fn read_orlib_setcover(path: impl AsRef<Path>) -> Result<SetCover, ReadError> {
    let path = path.as_ref();
    parse_at(&read_text(path)?, path)
}

/// [`read_orlib_setcover`] on text.
pub fn parse_orlib_setcover(text: &str) -> Result<SetCover, ReadError> {
    parse_at(text, &text_path())
}

fn parse_at(text: &str, path: &Path) -> Result<SetCover, ReadError> {
    let ctx = Ctx { path };
    let mut toks = tokens(text);
    let mut last_line = 1;
    let mut next = |what: &str| -> Result<(usize, &str), ReadError> {
        match toks.next() {
            Some((l, t)) => {
                last_line = l;
                Ok((l, t))
            }
            None => Err(ctx.syntax(Some(last_line), format!("the file ends early; expected {what}"))),
        }
    };
    // The largest OR-Library instances have about a million columns.
    const LIMIT: Limit = Limit {
        max: 100_000_000,
        why: "",
    };
    let (l, t) = next("the number of rows m")?;
    let rows = ctx.count(l, t, "the number of rows m", "the number of rows m", LIMIT)?;
    let (l, t) = next("the number of columns n")?;
    let columns = ctx.count(l, t, "the number of columns n", "the number of columns n", LIMIT)?;
    let mut costs = Vec::with_capacity(columns.min(1 << 20));
    for j in 0..columns {
        let what = format!("the cost of column {} of {columns}", j + 1);
        let (l, t) = next(&what)?;
        let c = ctx.number(l, t, &what)?;
        if c < 0.0 {
            return Err(ctx.invalid(Some(l), format!("column {} costs {c}; costs must be >= 0", j + 1)));
        }
        costs.push(c);
    }
    let mut covers = Vec::with_capacity(rows.min(1 << 20));
    for i in 0..rows {
        let what = format!("the number of columns covering row {} of {rows}", i + 1);
        let (l, t) = next(&what)?;
        let k = ctx.integer(l, t, &what)?;
        if k == 0 {
            return Err(ctx.invalid(
                Some(l),
                format!(
                    "row {} is covered by no column; the instance would be infeasible",
                    i + 1
                ),
            ));
        }
        if k > columns {
            return Err(ctx.invalid(
                Some(l),
                format!(
                    "row {} lists {k} covering columns but there are only {columns}",
                    i + 1
                ),
            ));
        }
        // `k <= columns` but may still be far more than the file holds: reserve little.
        let mut cols = Vec::with_capacity(k.min(1 << 10));
        for _ in 0..k {
            let what = format!("a column (1..={columns}) covering row {}", i + 1);
            let (l, t) = next(&what)?;
            let c = ctx.integer(l, t, &what)?;
            if c == 0 || c > columns {
                return Err(ctx.invalid(
                    Some(l),
                    format!(
                        "row {} is covered by column {c}, out of range; columns run 1..={columns}",
                        i + 1
                    ),
                ));
            }
            cols.push(c - 1);
        }
        cols.sort_unstable();
        cols.dedup();
        covers.push(cols);
    }
    if let Some((l, t)) = toks.next() {
        return Err(ctx.syntax(
            Some(l),
            format!("unexpected `{t}` after the last of the {rows} rows; expected the end of the file"),
        ));
    }
    Ok(SetCover {
        rows,
        columns,
        costs,
        covers,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_wrapped_numbers() {
        let sc = parse_orlib_setcover(" 2 3\n 1 2\n 3\n 2 1\n 3 3 1 3 2\n").unwrap();
        assert_eq!(sc.costs, vec![1.0, 2.0, 3.0]);
        assert_eq!(sc.covers, vec![vec![0, 2], vec![0, 1, 2]]);
    }

    #[test]
    fn column_out_of_range() {
        let e = parse_orlib_setcover("2 3\n1 2 3\n2 1 3\n1\n4\n").unwrap_err();
        assert!(matches!(e, ReadError::Invalid { line: Some(5), .. }), "{e}");
        assert!(
            e.to_string().contains("column 4") && e.to_string().contains("1..=3"),
            "{e}"
        );
    }

    #[test]
    fn truncated_and_garbage() {
        assert!(matches!(
            parse_orlib_setcover("2 3\n1 2 3\n2 1"),
            Err(ReadError::Syntax { .. })
        ));
        assert!(matches!(
            parse_orlib_setcover("2 3\n1 x 3\n"),
            Err(ReadError::Syntax { line: Some(2), .. })
        ));
        assert!(parse_orlib_setcover("1 1\n1\n1 1\n9\n").is_err());
        assert!(parse_orlib_setcover("").is_err());
    }
}

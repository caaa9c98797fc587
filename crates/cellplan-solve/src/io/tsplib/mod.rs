//! TSPLIB95 symmetric TSP files (Reinelt 1991) and the core parser shared with GTSPLIB.
use std::collections::BTreeMap;
use std::path::Path;

use super::{Ctx, DENSE_NODES, MAX_DENSE_NODES, SETS, read_text, text_path};
use crate::error::ReadError;
use crate::problem::CostMatrix;

mod metric;
use metric::{Format, WeightType, coord_matrix, explicit_matrix};

/// A TSPLIB instance: its name, size and full cost matrix (the TSPLIB distance rules applied).
#[derive(Clone, Debug, PartialEq)]
pub struct TsplibInstance {
    /// The NAME field (empty if absent).
    pub name: String,
    /// The DIMENSION field: number of nodes.
    pub dimension: usize,
    /// The `dimension × dimension` costs; the diagonal is 0 for coordinate types and as given
    /// for EXPLICIT matrices.
    pub costs: CostMatrix,
}

/// Read a TSPLIB `.tsp` file of TYPE TSP. Supports EDGE_WEIGHT_TYPE EUC_2D, CEIL_2D, ATT, GEO
/// and EXPLICIT (formats FULL_MATRIX, UPPER_ROW, LOWER_ROW, UPPER_DIAG_ROW, LOWER_DIAG_ROW and
/// their *_COL equivalents). DISPLAY_DATA_SECTION and FIXED_EDGES_SECTION are skipped.
pub fn read_tsplib(path: impl AsRef<Path>) -> Result<TsplibInstance, ReadError> {
    let path = path.as_ref();
    parse_tsplib_at(&read_text(path)?, path)
}

/// [`read_tsplib`] on text; errors name the path `<text>`.
pub fn parse_tsplib(text: &str) -> Result<TsplibInstance, ReadError> {
    parse_tsplib_at(text, &text_path())
}

fn parse_tsplib_at(text: &str, path: &Path) -> Result<TsplibInstance, ReadError> {
    let doc = parse_document(text, Ctx { path }, Kind::Tsp)?;
    Ok(TsplibInstance {
        name: doc.name,
        dimension: doc.dimension,
        costs: doc.costs,
    })
}

/// Read the `solutions` file of the TSPLIB benchmark folder: lines `name : value`, optionally
/// followed by a note such as `(CEIL_2D)`. Blank lines are skipped.
pub fn read_optima(path: impl AsRef<Path>) -> Result<BTreeMap<String, f64>, ReadError> {
    let path = path.as_ref();
    parse_optima_at(&read_text(path)?, path)
}

/// [`read_optima`] on text.
pub fn parse_optima(text: &str) -> Result<BTreeMap<String, f64>, ReadError> {
    parse_optima_at(text, &text_path())
}

fn parse_optima_at(text: &str, path: &Path) -> Result<BTreeMap<String, f64>, ReadError> {
    let ctx = Ctx { path };
    let mut out = BTreeMap::new();
    for (i, line) in text.lines().enumerate() {
        let ln = i + 1;
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        let Some((name, rest)) = line.split_once(':') else {
            return Err(ctx.syntax(Some(ln), format!("expected `name : optimum`, found `{line}`")));
        };
        let name = name.trim();
        let Some(tok) = rest.split_whitespace().next() else {
            return Err(ctx.syntax(Some(ln), format!("expected a value after `{name} :`")));
        };
        if name.is_empty() {
            return Err(ctx.syntax(Some(ln), "expected an instance name before `:`"));
        }
        let v = ctx.number(ln, tok, "the optimal tour length")?;
        out.insert(name.to_string(), v);
    }
    Ok(out)
}

/// Which TYPE values the caller accepts.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Tsp,
    Gtsp,
}

/// One set of GTSP_SET_SECTION: the line it starts on, its id and its 1-based nodes.
pub(crate) struct RawSet {
    pub line: usize,
    pub id: usize,
    pub nodes: Vec<(usize, i64)>,
}

pub(crate) struct Document {
    pub name: String,
    pub dimension: usize,
    pub costs: CostMatrix,
    /// GTSP_SETS with its line, if given.
    pub gtsp_sets: Option<(usize, usize)>,
    /// GTSP_SET_SECTION's sets, with the line of the section keyword.
    pub sets: Option<(usize, Vec<RawSet>)>,
}

const WEIGHT_TYPES: &str = "EUC_2D, CEIL_2D, ATT, GEO or EXPLICIT";
const FORMATS: &str =
    "FULL_MATRIX, UPPER_ROW, LOWER_ROW, UPPER_DIAG_ROW, LOWER_DIAG_ROW (or the *_COL equivalents)";
const KEYWORDS: &str = "NAME, TYPE, COMMENT, DIMENSION, EDGE_WEIGHT_TYPE, EDGE_WEIGHT_FORMAT, \
    NODE_COORD_TYPE, DISPLAY_DATA_TYPE, GTSP_SETS, NODE_COORD_SECTION, EDGE_WEIGHT_SECTION, \
    DISPLAY_DATA_SECTION, FIXED_EDGES_SECTION, GTSP_SET_SECTION, EOF";

fn is_keyword_line(l: &str) -> bool {
    l.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
}

/// The non-blank lines of a document, trimmed, with their 1-based numbers; read one at a time
/// (nothing is collected, so memory stays proportional to what the sections hold).
struct Cursor<'t> {
    lines: std::iter::Peekable<Box<dyn Iterator<Item = (usize, &'t str)> + 't>>,
}

impl<'t> Cursor<'t> {
    fn new(text: &'t str) -> Self {
        let it: Box<dyn Iterator<Item = (usize, &'t str)> + 't> = Box::new(
            text.lines()
                .enumerate()
                .map(|(i, l)| (i + 1, l.trim()))
                .filter(|(_, l)| !l.is_empty()),
        );
        Cursor { lines: it.peekable() }
    }

    /// The next line, whatever it holds.
    fn next(&mut self) -> Option<(usize, &'t str)> {
        self.lines.next()
    }

    /// The next line if it is data (not a keyword), consumed.
    fn data(&mut self) -> Option<(usize, &'t str)> {
        self.lines.next_if(|(_, l)| !is_keyword_line(l))
    }

    /// The next line if it is data, not consumed.
    fn peek_data(&mut self) -> Option<(usize, &'t str)> {
        self.lines.peek().copied().filter(|(_, l)| !is_keyword_line(l))
    }

    /// The number of the next line, if any.
    fn next_line(&mut self) -> Option<usize> {
        self.lines.peek().map(|x| x.0)
    }

    /// Skips the data lines of a section this reader does not use.
    fn skip_data(&mut self) {
        while self.data().is_some() {}
    }
}

/// The header fields read so far, with the lines they are on.
#[derive(Default)]
struct Header {
    name: String,
    dimension: Option<(usize, usize)>,
    weight_type: Option<(usize, WeightType)>,
    format: Option<(usize, Format)>,
    gtsp_sets: Option<(usize, usize)>,
}

/// The sections read so far. Weights keep the format they were read with.
#[derive(Default)]
struct Sections {
    coords: Option<Vec<(f64, f64)>>,
    weights: Option<(Format, Vec<f64>)>,
    sets: Option<(usize, Vec<RawSet>)>,
}

/// Parse a TSPLIB-style document (header, sections, EOF) into a cost matrix and optional sets.
pub(crate) fn parse_document(text: &str, ctx: Ctx<'_>, kind: Kind) -> Result<Document, ReadError> {
    let mut cur = Cursor::new(text);
    let mut header = Header::default();
    let mut sections = Sections::default();
    while let Some((ln, l)) = cur.next() {
        let (key, value) = split_keyword(ctx, ln, l)?;
        match key.as_str() {
            "NODE_COORD_SECTION" => {
                let n = header.need_dim(ctx, ln, "NODE_COORD_SECTION")?;
                sections.coords = Some(read_node_coords(&mut cur, ctx, ln, n)?);
            }
            "EDGE_WEIGHT_SECTION" => {
                let n = header.need_dim(ctx, ln, "EDGE_WEIGHT_SECTION")?;
                let Some((_, f)) = header.format else {
                    return Err(ctx.syntax(
                        Some(ln),
                        format!("EDGE_WEIGHT_SECTION without EDGE_WEIGHT_FORMAT; add `EDGE_WEIGHT_FORMAT : <{FORMATS}>` to the header"),
                    ));
                };
                sections.weights = Some((f, read_edge_weights(&mut cur, ctx, ln, n, f)?));
            }
            "DISPLAY_DATA_SECTION" | "FIXED_EDGES_SECTION" => cur.skip_data(),
            "GTSP_SET_SECTION" if kind == Kind::Gtsp => {
                let Some((gl, m)) = header.gtsp_sets else {
                    return Err(ctx.syntax(
                        Some(ln),
                        "GTSP_SET_SECTION before GTSP_SETS; add `GTSP_SETS : <number of sets>` to the header",
                    ));
                };
                if let Some((_, n)) = header.dimension
                    && m > n
                {
                    return Err(too_many_sets(ctx, gl, m, n));
                }
                sections.sets = Some((ln, read_gtsp_sets(&mut cur, ctx, ln, m)?));
            }
            "EOF" => break,
            _ => header.field(ctx, kind, ln, &key, value)?,
        }
    }
    assemble(ctx, header, sections)
}

/// The error for GTSP_SETS (on line `gl`) above DIMENSION.
pub(crate) fn too_many_sets(ctx: Ctx<'_>, gl: usize, m: usize, n: usize) -> ReadError {
    ctx.invalid(
        Some(gl),
        format!("GTSP_SETS is {m} but DIMENSION is {n}; sets are disjoint and non-empty, so at most {n}"),
    )
}

/// A keyword line as (upper-case keyword, value): `KEY : value` or `KEY value`.
fn split_keyword<'l>(ctx: Ctx<'_>, ln: usize, l: &'l str) -> Result<(String, &'l str), ReadError> {
    if !is_keyword_line(l) {
        return Err(ctx.syntax(
            Some(ln),
            format!("expected a keyword ({KEYWORDS}), found `{l}`; numbers belong in a section"),
        ));
    }
    Ok(match l.split_once(':') {
        Some((k, v)) => (k.trim().to_ascii_uppercase(), v.trim()),
        None => {
            let mut it = l.splitn(2, char::is_whitespace);
            let k = it.next().unwrap_or("").to_ascii_uppercase();
            (k, it.next().unwrap_or("").trim())
        }
    })
}

impl Header {
    /// DIMENSION, or an error for a `section` that comes before it.
    fn need_dim(&self, ctx: Ctx<'_>, ln: usize, section: &str) -> Result<usize, ReadError> {
        self.dimension.map(|(_, n)| n).ok_or_else(|| {
            ctx.syntax(
                Some(ln),
                format!(
                    "{section} before DIMENSION; add `DIMENSION : <number of nodes>` to the header above it"
                ),
            )
        })
    }

    /// One header line `key : value` (any keyword that is not a section).
    fn field(
        &mut self,
        ctx: Ctx<'_>,
        kind: Kind,
        ln: usize,
        key: &str,
        value: &str,
    ) -> Result<(), ReadError> {
        match key {
            "NAME" => self.name = value.to_string(),
            "COMMENT" | "DISPLAY_DATA_TYPE" => {}
            "NODE_COORD_TYPE" => {
                let v = value.to_ascii_uppercase();
                if v != "TWOD_COORDS" && v != "NO_COORDS" {
                    return Err(ctx.unsupported(
                        Some(ln),
                        format!("NODE_COORD_TYPE `{value}` is not supported; use TWOD_COORDS or NO_COORDS"),
                    ));
                }
            }
            "TYPE" => check_type(ctx, ln, value, kind)?,
            "DIMENSION" => {
                once(ctx, ln, "DIMENSION", self.dimension)?;
                let n = ctx.count(
                    ln,
                    value,
                    "DIMENSION",
                    "the number of nodes after DIMENSION :",
                    DENSE_NODES,
                )?;
                if n == 0 {
                    return Err(ctx.invalid(
                        Some(ln),
                        format!("DIMENSION is 0; this reader builds a dense matrix and takes 1..={MAX_DENSE_NODES} nodes"),
                    ));
                }
                self.dimension = Some((ln, n));
            }
            "GTSP_SETS" => {
                once(ctx, ln, "GTSP_SETS", self.gtsp_sets)?;
                // Sets are disjoint and non-empty, so there are at most as many as nodes.
                let m = ctx.count(
                    ln,
                    value,
                    "GTSP_SETS",
                    "the number of sets after GTSP_SETS :",
                    SETS,
                )?;
                self.gtsp_sets = Some((ln, m));
            }
            "EDGE_WEIGHT_TYPE" => self.weight_type = Some((ln, weight_type(ctx, ln, value)?)),
            "EDGE_WEIGHT_FORMAT" => self.format = weight_format(ctx, ln, value)?.map(|f| (ln, f)),
            _ => {
                return Err(ctx.syntax(
                    Some(ln),
                    format!("unknown keyword `{key}`; expected one of {KEYWORDS}"),
                ));
            }
        }
        Ok(())
    }
}

/// The value of EDGE_WEIGHT_TYPE (on line `ln`).
fn weight_type(ctx: Ctx<'_>, ln: usize, value: &str) -> Result<WeightType, ReadError> {
    Ok(match value.to_ascii_uppercase().as_str() {
        "EUC_2D" => WeightType::Euc2d,
        "CEIL_2D" => WeightType::Ceil2d,
        "ATT" => WeightType::Att,
        "GEO" => WeightType::Geo,
        "EXPLICIT" => WeightType::Explicit,
        _ => {
            return Err(ctx.unsupported(
                Some(ln),
                format!("unknown or unsupported EDGE_WEIGHT_TYPE `{value}`; expected {WEIGHT_TYPES}"),
            ));
        }
    })
}

/// The value of EDGE_WEIGHT_FORMAT (on line `ln`); `None` for FUNCTION.
fn weight_format(ctx: Ctx<'_>, ln: usize, value: &str) -> Result<Option<Format>, ReadError> {
    Ok(match value.to_ascii_uppercase().as_str() {
        "FUNCTION" => None,
        "FULL_MATRIX" => Some(Format::Full),
        "UPPER_ROW" | "LOWER_COL" => Some(Format::UpperRow),
        "LOWER_ROW" | "UPPER_COL" => Some(Format::LowerRow),
        "UPPER_DIAG_ROW" | "LOWER_DIAG_COL" => Some(Format::UpperDiagRow),
        "LOWER_DIAG_ROW" | "UPPER_DIAG_COL" => Some(Format::LowerDiagRow),
        _ => {
            return Err(ctx.unsupported(
                Some(ln),
                format!("unknown or unsupported EDGE_WEIGHT_FORMAT `{value}`; expected {FORMATS}"),
            ));
        }
    })
}

/// Refuses a count field given a second time (the sections read so far were sized by the first).
fn once(ctx: Ctx<'_>, ln: usize, key: &str, earlier: Option<(usize, usize)>) -> Result<(), ReadError> {
    match earlier {
        Some((first, n)) => Err(ctx.syntax(
            Some(ln),
            format!("{key} is given twice (first on line {first}, as {n}); give it once"),
        )),
        None => Ok(()),
    }
}

/// NODE_COORD_SECTION (keyword on line `ln`): exactly `n` lines `id x y`, each id once.
fn read_node_coords(
    cur: &mut Cursor<'_>,
    ctx: Ctx<'_>,
    ln: usize,
    n: usize,
) -> Result<Vec<(f64, f64)>, ReadError> {
    let mut c: Vec<Option<(f64, f64)>> = vec![None; n];
    for k in 0..n {
        let Some((cl, line)) = cur.data() else {
            return Err(ctx.syntax(
                cur.next_line(),
                format!(
                    "NODE_COORD_SECTION (line {ln}) ends after {k} of {n} nodes; \
                     expected one `id x y` line per node (DIMENSION = {n})"
                ),
            ));
        };
        let toks: Vec<&str> = line.split_whitespace().collect();
        if toks.len() != 3 {
            return Err(ctx.syntax(
                Some(cl),
                format!(
                    "expected a node line `id x y` (3 numbers), found {} fields: `{line}`",
                    toks.len()
                ),
            ));
        }
        let id = ctx.integer(cl, toks[0], "the node id")?;
        let x = ctx.number(cl, toks[1], "the x coordinate")?;
        let y = ctx.number(cl, toks[2], "the y coordinate")?;
        if id == 0 || id > n {
            return Err(ctx.invalid(Some(cl), format!("node id {id} is out of range; ids run 1..={n}")));
        }
        if c[id - 1].is_some() {
            return Err(ctx.invalid(Some(cl), format!("node {id} is given twice; each id once")));
        }
        c[id - 1] = Some((x, y));
    }
    if let Some((cl, line)) = cur.peek_data() {
        return Err(ctx.syntax(
            Some(cl),
            format!(
                "NODE_COORD_SECTION (line {ln}) has more than the {n} node lines DIMENSION states; \
                 found `{line}` after them: fix DIMENSION or remove the extra lines"
            ),
        ));
    }
    Ok(c.into_iter().map(|p| p.unwrap_or((0.0, 0.0))).collect())
}

/// EDGE_WEIGHT_SECTION (keyword on line `ln`): exactly the number of weights format `f` with
/// `n` nodes needs, each non-negative. Grows with the data read, not with the count stated.
fn read_edge_weights(
    cur: &mut Cursor<'_>,
    ctx: Ctx<'_>,
    ln: usize,
    n: usize,
    f: Format,
) -> Result<Vec<f64>, ReadError> {
    let count = match f {
        Format::Full => n * n,
        Format::UpperRow | Format::LowerRow => n * (n - 1) / 2,
        Format::UpperDiagRow | Format::LowerDiagRow => n * (n + 1) / 2,
    };
    let mut vals = Vec::new();
    while vals.len() < count {
        let Some((cl, line)) = cur.data() else {
            return Err(ctx.syntax(
                cur.next_line(),
                format!(
                    "EDGE_WEIGHT_SECTION (line {ln}) ends after {} of {count} weights; \
                     format {f:?} with DIMENSION {n} needs {count}",
                    vals.len()
                ),
            ));
        };
        for tok in line.split_whitespace() {
            if vals.len() == count {
                return Err(ctx.syntax(
                    Some(cl),
                    format!("more than the {count} weights format {f:?} needs; found `{tok}` after them"),
                ));
            }
            let v = ctx.number(cl, tok, "an edge weight")?;
            if v < 0.0 {
                return Err(ctx.invalid(
                    Some(cl),
                    format!("edge weight {v} is negative; weights must be >= 0"),
                ));
            }
            vals.push(v);
        }
    }
    if let Some((cl, line)) = cur.peek_data() {
        return Err(ctx.syntax(
            Some(cl),
            format!("more than the {count} weights format {f:?} needs; expected a keyword, found `{line}`"),
        ));
    }
    Ok(vals)
}

/// The tokens of a section's data lines with their line numbers, read lazily.
struct SectionTokens<'c, 't> {
    cur: &'c mut Cursor<'t>,
    line: Option<(usize, std::str::SplitWhitespace<'t>)>,
}

impl<'t> SectionTokens<'_, 't> {
    fn next(&mut self) -> Option<(usize, &'t str)> {
        loop {
            if let Some((l, toks)) = self.line.as_mut()
                && let Some(t) = toks.next()
            {
                return Some((*l, t));
            }
            let (l, text) = self.cur.data()?;
            self.line = Some((l, text.split_whitespace()));
        }
    }
}

/// GTSP_SET_SECTION (keyword on line `ln`): exactly `m` sets `set-id node ... -1`, the numbers
/// wrapping freely across lines.
fn read_gtsp_sets(cur: &mut Cursor<'_>, ctx: Ctx<'_>, ln: usize, m: usize) -> Result<Vec<RawSet>, ReadError> {
    let mut toks = SectionTokens { cur, line: None };
    let mut raw = Vec::with_capacity(m);
    for k in 0..m {
        let Some((sl, tok)) = toks.next() else {
            return Err(ctx.syntax(
                toks.cur.next_line(),
                format!("GTSP_SET_SECTION (line {ln}) ends after {k} of {m} sets; expected `set-id node ... -1` for each"),
            ));
        };
        let id = ctx.integer(sl, tok, "a set id")?;
        let mut nodes = Vec::new();
        loop {
            let Some((nl, tok)) = toks.next() else {
                return Err(ctx.syntax(
                    Some(sl),
                    format!("set {id} is not terminated; expected its nodes followed by -1"),
                ));
            };
            let v: i64 = tok.parse().map_err(|_| {
                ctx.syntax(
                    Some(nl),
                    format!("expected a node id or -1 in set {id}, found `{tok}`"),
                )
            })?;
            if v == -1 {
                break;
            }
            nodes.push((nl, v));
        }
        raw.push(RawSet { line: sl, id, nodes });
    }
    if let Some((xl, tok)) = toks.next() {
        return Err(ctx.syntax(
            Some(xl),
            format!("more sets than GTSP_SETS = {m}; found `{tok}` after the last one"),
        ));
    }
    Ok(raw)
}

/// The cost matrix from the header and sections read: checks that what the weight type needs
/// is there.
fn assemble(ctx: Ctx<'_>, header: Header, sections: Sections) -> Result<Document, ReadError> {
    let Some((_, n)) = header.dimension else {
        return Err(ctx.syntax(
            None,
            "DIMENSION missing; add `DIMENSION : <number of nodes>` to the header",
        ));
    };
    let Some((wl, wt)) = header.weight_type else {
        return Err(ctx.syntax(
            None,
            format!("EDGE_WEIGHT_TYPE missing; add `EDGE_WEIGHT_TYPE : <{WEIGHT_TYPES}>`"),
        ));
    };
    let costs = if wt == WeightType::Explicit {
        let Some((f, vals)) = sections.weights else {
            return Err(ctx.syntax(
                Some(wl),
                "EDGE_WEIGHT_TYPE is EXPLICIT but there is no EDGE_WEIGHT_SECTION",
            ));
        };
        explicit_matrix(n, f, &vals)
    } else {
        let Some(c) = sections.coords else {
            return Err(ctx.syntax(
                Some(wl),
                format!("EDGE_WEIGHT_TYPE {wt:?} needs a NODE_COORD_SECTION with one `id x y` line per node"),
            ));
        };
        coord_matrix(wt, &c)
    }
    .map_err(|e| ctx.invalid(None, e.to_string()))?;
    Ok(Document {
        name: header.name,
        dimension: n,
        costs,
        gtsp_sets: header.gtsp_sets,
        sets: sections.sets,
    })
}

fn check_type(ctx: Ctx<'_>, ln: usize, value: &str, kind: Kind) -> Result<(), ReadError> {
    let t = value.split_whitespace().next().unwrap_or("").to_ascii_uppercase();
    let ok = match kind {
        Kind::Tsp => t == "TSP",
        Kind::Gtsp => t == "GTSP" || t == "AGTSP",
    };
    if ok {
        return Ok(());
    }
    let hint = match (kind, t.as_str()) {
        (Kind::Tsp, "GTSP" | "AGTSP") => "; read it with read_gtsplib",
        (Kind::Gtsp, "TSP") => "; read it with read_tsplib",
        _ => "",
    };
    let want = if kind == Kind::Tsp { "TSP" } else { "GTSP or AGTSP" };
    Err(ctx.unsupported(
        Some(ln),
        format!("TYPE `{value}` is not supported here; this reader takes {want}{hint}"),
    ))
}

#[cfg(test)]
mod tests;

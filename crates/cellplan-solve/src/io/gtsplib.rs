//! GTSPLIB files (Fischetti, Salazar-González, Toth 1997): a TSPLIB header with `GTSP_SETS` and a
//! `GTSP_SET_SECTION` of lines `set-id node ... -1`. Also the small GLNS format (`N:`, `M:`, one
//! line per set `set-id node ...`, then the full `N × N` matrix).
use std::path::Path;

use super::tsplib::{Kind, parse_document, too_many_sets};
use super::{Ctx, DENSE_NODES, MAX_DENSE_NODES, SETS, read_text, text_path};
use crate::error::ReadError;
use crate::problem::{CostMatrix, Gtsp};

/// A GTSPLIB instance: its name and the problem (no depots, zero service times; clusters in set-id
/// order, nodes 0-based).
#[derive(Clone, Debug, PartialEq)]
pub struct GtspInstance {
    /// The NAME field (the file stem for the GLNS format, empty when parsing text).
    pub name: String,
    /// The problem.
    pub gtsp: Gtsp,
}

/// Read a `.gtsp` file: GTSPLIB (TYPE GTSP or AGTSP; edge weights as in TSPLIB) or the GLNS
/// `N:`/`M:` format.
pub fn read_gtsplib(path: impl AsRef<Path>) -> Result<GtspInstance, ReadError> {
    let path = path.as_ref();
    let mut inst = parse_gtsplib_at(&read_text(path)?, path)?;
    if inst.name.is_empty() {
        inst.name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
    }
    Ok(inst)
}

/// [`read_gtsplib`] on text.
pub fn parse_gtsplib(text: &str) -> Result<GtspInstance, ReadError> {
    parse_gtsplib_at(text, &text_path())
}

fn parse_gtsplib_at(text: &str, path: &Path) -> Result<GtspInstance, ReadError> {
    let ctx = Ctx { path };
    let first = text.lines().map(str::trim).find(|l| !l.is_empty()).unwrap_or("");
    if first.to_ascii_uppercase().starts_with("N:") {
        return parse_glns(text, ctx);
    }
    let doc = parse_document(text, ctx, Kind::Gtsp)?;
    let Some((gl, m)) = doc.gtsp_sets else {
        return Err(ctx.syntax(
            None,
            "GTSP_SETS missing; add `GTSP_SETS : <number of sets>` to the header",
        ));
    };
    let Some((sl, raw)) = doc.sets else {
        return Err(ctx.syntax(
            Some(gl),
            "GTSP_SET_SECTION missing; add it after the weights, one `set-id node ... -1` per set",
        ));
    };
    let n = doc.dimension;
    if m > n {
        return Err(too_many_sets(ctx, gl, m, n));
    }
    let mut clusters: Vec<Option<Vec<usize>>> = vec![None; m];
    for set in raw {
        if set.id == 0 || set.id > m {
            return Err(ctx.invalid(
                Some(set.line),
                format!("set id {} is out of range; ids run 1..={m}", set.id),
            ));
        }
        if clusters[set.id - 1].is_some() {
            return Err(ctx.invalid(Some(set.line), format!("set {} is given twice", set.id)));
        }
        let mut nodes = Vec::with_capacity(set.nodes.len());
        for (nl, v) in set.nodes {
            if v < 1 || v as u64 > n as u64 {
                return Err(ctx.invalid(
                    Some(nl),
                    format!(
                        "set {} names node {v}, out of range; nodes run 1..={n} (DIMENSION)",
                        set.id
                    ),
                ));
            }
            nodes.push(v as usize - 1);
        }
        clusters[set.id - 1] = Some(nodes);
    }
    let clusters: Vec<Vec<usize>> = clusters.into_iter().map(Option::unwrap_or_default).collect();
    let gtsp = Gtsp::new(doc.costs, clusters).map_err(|e| ctx.invalid(Some(sl), e.to_string()))?;
    if let Some(v) = node_in_no_set(&gtsp) {
        return Err(ctx.invalid(
            Some(sl),
            format!(
                "node {} is in no set; every node 1..={n} (DIMENSION) must be in exactly one of \
                 the {m} sets of GTSP_SET_SECTION: add it to a set, or renumber and lower DIMENSION",
                v + 1
            ),
        ));
    }
    Ok(GtspInstance { name: doc.name, gtsp })
}

/// The first node (0-based) that no cluster holds.
fn node_in_no_set(g: &Gtsp) -> Option<usize> {
    g.node_clusters().iter().position(Option::is_none)
}

/// The GLNS format: `N: n`, `M: m`, optional `Symmetric:`/`Triangle:` lines, then `m` set lines
/// (`set-id node ...`, 1-based, an optional trailing -1), then `n × n` weights.
fn parse_glns(text: &str, ctx: Ctx<'_>) -> Result<GtspInstance, ReadError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty())
        .peekable();
    let mut n = None;
    let mut m = None;
    let mut last = 0;
    while let Some(&(ln, l)) = lines.peek() {
        let Some((k, v)) = l.split_once(':') else { break };
        lines.next();
        last = ln;
        match k.trim().to_ascii_uppercase().as_str() {
            "N" => {
                let count = ctx.count(ln, v.trim(), "N", "the number of nodes after N:", DENSE_NODES)?;
                n = Some((ln, count));
            }
            "M" => {
                let count = ctx.count(ln, v.trim(), "M", "the number of sets after M:", SETS)?;
                m = Some((ln, count));
            }
            "SYMMETRIC" | "TRIANGLE" => {}
            other => {
                return Err(ctx.syntax(
                    Some(ln),
                    format!("unknown header `{other}:`; expected N:, M:, Symmetric: or Triangle:"),
                ));
            }
        }
    }
    let (Some((nl, n)), Some((ml, m))) = (n, m) else {
        return Err(ctx.syntax(
            Some(last),
            "the GLNS header needs both `N: <nodes>` and `M: <sets>`",
        ));
    };
    if n == 0 {
        return Err(ctx.invalid(
            Some(nl),
            format!("N is 0; this reader takes 1..={MAX_DENSE_NODES} nodes"),
        ));
    }
    if m > n {
        return Err(ctx.invalid(
            Some(ml),
            format!("M is {m} but there are only {n} nodes; sets are disjoint and non-empty"),
        ));
    }
    let mut clusters = vec![None; m];
    for k in 0..m {
        let Some((sl, l)) = lines.next() else {
            return Err(ctx.syntax(
                None,
                format!("the file ends after {k} of {m} set lines; expected `set-id node ...` per set"),
            ));
        };
        let mut toks = l.split_whitespace();
        let id = ctx.integer(sl, toks.next().unwrap_or(""), "a set id")?;
        if id == 0 || id > m {
            return Err(ctx.invalid(Some(sl), format!("set id {id} is out of range; ids run 1..={m}")));
        }
        let mut nodes = Vec::new();
        while let Some(t) = toks.next() {
            if t == "-1" {
                if let Some(extra) = toks.next() {
                    return Err(ctx.syntax(
                        Some(sl),
                        format!("`{extra}` after the -1 that ends set {id}; one set per line, -1 last"),
                    ));
                }
                break;
            }
            let v = ctx.integer(sl, t, "a node id")?;
            if v == 0 || v > n {
                return Err(ctx.invalid(
                    Some(sl),
                    format!("set {id} names node {v}, out of range; nodes run 1..={n}"),
                ));
            }
            nodes.push(v - 1);
        }
        if nodes.is_empty() {
            return Err(ctx.invalid(
                Some(sl),
                format!("set {id} has no nodes; every set needs at least one (M: {m} set lines)"),
            ));
        }
        if clusters[id - 1].replace(nodes).is_some() {
            return Err(ctx.invalid(Some(sl), format!("set {id} is given twice")));
        }
    }
    let costs = read_glns_matrix(lines, ctx, n)?;
    let clusters = clusters.into_iter().map(Option::unwrap_or_default).collect();
    let gtsp = Gtsp::new(costs, clusters).map_err(|e| ctx.invalid(None, e.to_string()))?;
    if let Some(v) = node_in_no_set(&gtsp) {
        return Err(ctx.invalid(
            Some(ml),
            format!(
                "node {} is in no set; every node 1..={n} (N) must be in exactly one of the \
                 M = {m} sets: add it to a set, or renumber and lower N",
                v + 1
            ),
        ));
    }
    Ok(GtspInstance {
        name: String::new(),
        gtsp,
    })
}

/// The `n × n` weights after the GLNS set lines, wrapping freely across lines. Grows with the
/// weights read, not with the count stated.
fn read_glns_matrix<'t>(
    lines: impl Iterator<Item = (usize, &'t str)>,
    ctx: Ctx<'_>,
    n: usize,
) -> Result<CostMatrix, ReadError> {
    let want = n * n;
    let mut data = Vec::new();
    let mut last = None;
    for (ln, l) in lines {
        last = Some(ln);
        for t in l.split_whitespace() {
            let k = data.len();
            if k == want {
                return Err(ctx.syntax(
                    Some(ln),
                    format!("more than the {want} weights of an {n} × {n} matrix (extra `{t}`)"),
                ));
            }
            let v = t
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| {
                    ctx.syntax(
                        Some(ln),
                        format!(
                            "weight {} (row {}, column {}) is `{t}`; expected a non-negative number",
                            k + 1,
                            k / n + 1,
                            k % n + 1
                        ),
                    )
                })?;
            data.push(v);
        }
    }
    if data.len() != want {
        return Err(ctx.syntax(
            last,
            format!("the matrix has {} weights; N = {n} needs {want}", data.len()),
        ));
    }
    CostMatrix::new(n, data).map_err(|e| ctx.invalid(None, e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_gtsplib() {
        let text = "NAME: t\nTYPE: GTSP\nDIMENSION: 3\nGTSP_SETS: 2\nEDGE_WEIGHT_TYPE: EXPLICIT\n\
            EDGE_WEIGHT_FORMAT: FULL_MATRIX\nEDGE_WEIGHT_SECTION\n0 1 2\n1 0 3\n2 3 0\n\
            GTSP_SET_SECTION:\n2 3 -1\n1 1 2\n -1\nEOF\n";
        let g = parse_gtsplib(text).unwrap();
        assert_eq!(g.gtsp.clusters, vec![vec![0, 1], vec![2]]);
        let e = parse_gtsplib(&text.replace("2 3 -1", "2 4 -1")).unwrap_err();
        assert!(matches!(e, ReadError::Invalid { line: Some(12), .. }), "{e}");
        let e = parse_gtsplib(&text.replace("2 3 -1", "2 1 -1")).unwrap_err();
        assert!(e.to_string().contains("disjoint"), "{e}");
        let e = parse_gtsplib(&text.replace("TYPE: GTSP", "TYPE: TSP")).unwrap_err();
        assert!(matches!(e, ReadError::Unsupported { line: Some(2), .. }), "{e}");
    }

    #[test]
    fn glns_format() {
        let g = parse_gtsplib("N: 3\nM: 2\n1 1\n2 2 3\n0 1 2\n1 0 3\n2 3 0\n").unwrap();
        assert_eq!(g.gtsp.clusters, vec![vec![0], vec![1, 2]]);
        assert!(parse_gtsplib("N: 3\nM: 2\n1 1\n2 2 3\n0 1 2\n1 0 3\n2 3\n").is_err());
        assert!(parse_gtsplib("N: 3\nM: 2\n1 1\n").is_err());
    }
}

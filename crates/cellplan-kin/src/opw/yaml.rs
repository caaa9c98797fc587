//! A reader for the restricted YAML of ROS-Industrial `opw_parameters_*.yaml` files.
use super::OpwParameters;

const GEOMETRIC: &str = "opw_kinematics_geometric_parameters";
const OFFSETS: &str = "opw_kinematics_joint_offsets";
const SIGNS: &str = "opw_kinematics_joint_sign_corrections";
const NAMES: [&str; 7] = ["a1", "a2", "b", "c1", "c2", "c3", "c4"];

type Error = (Option<usize>, String);

/// One top-level entry: its key, the line of the key, the inline value and the indented
/// lines below it (1-based line, text without comment).
struct Entry<'a> {
    key: &'a str,
    line: usize,
    inline: &'a str,
    body: Vec<(usize, &'a str)>,
}

fn strip_comment(line: &str) -> &str {
    let bytes = line.as_bytes();
    for (i, &ch) in bytes.iter().enumerate() {
        if ch == b'#' && (i == 0 || bytes[i - 1].is_ascii_whitespace()) {
            return &line[..i];
        }
    }
    line
}

fn split_entries(text: &str) -> Result<Vec<Entry<'_>>, Error> {
    let mut entries: Vec<Entry<'_>> = Vec::new();
    for (idx, raw) in text.lines().enumerate() {
        let line_no = idx + 1;
        let line = strip_comment(raw).trim_end();
        if line.trim().is_empty() || line.trim() == "---" {
            continue;
        }
        let indented = line.starts_with([' ', '\t']);
        if indented {
            match entries.last_mut() {
                Some(e) => e.body.push((line_no, line.trim())),
                None => {
                    return Err((
                        Some(line_no),
                        "indented line before any key; expected `key: value`".into(),
                    ));
                }
            }
            continue;
        }
        let Some((key, value)) = line.split_once(':') else {
            // The continuation of a multi-line flow list may start at column 0.
            if let Some(e) = entries.last_mut().filter(|e| e.inline.starts_with('[')) {
                e.body.push((line_no, line.trim()));
                continue;
            }
            return Err((
                Some(line_no),
                format!("expected `key: value`, found `{}`", line.trim()),
            ));
        };
        let key = key.trim();
        if entries.iter().any(|e| e.key == key) {
            return Err((Some(line_no), format!("key `{key}` appears twice")));
        }
        entries.push(Entry {
            key,
            line: line_no,
            inline: value.trim(),
            body: Vec::new(),
        });
    }
    Ok(entries)
}

/// A number, `deg(x)` or `rad(x)`, optionally quoted.
fn parse_value(text: &str, line: usize) -> Result<f64, Error> {
    let t = text.trim().trim_matches(|c| c == '"' || c == '\'').trim();
    let (inner, factor) = if let Some(rest) = t.strip_prefix("deg(") {
        (rest.strip_suffix(')'), std::f64::consts::PI / 180.0)
    } else if let Some(rest) = t.strip_prefix("rad(") {
        (rest.strip_suffix(')'), 1.0)
    } else {
        (Some(t), 1.0)
    };
    let bad = || {
        (
            Some(line),
            format!("`{t}` is not a number (expected e.g. 0.5 or deg(-90))"),
        )
    };
    let v: f64 = inner.ok_or_else(bad)?.trim().parse().map_err(|_| bad())?;
    if !v.is_finite() {
        return Err(bad());
    }
    Ok(v * factor)
}

/// Six values from a flow list (possibly over several lines) or a block list.
fn parse_list(entry: &Entry<'_>) -> Result<[f64; 6], Error> {
    let mut items: Vec<(usize, String)> = Vec::new();
    if entry.inline.starts_with('[') {
        let mut text = String::new();
        let mut last_line = entry.line;
        text.push_str(entry.inline);
        for &(l, body) in &entry.body {
            text.push(' ');
            text.push_str(body);
            last_line = l;
        }
        let t = text.trim();
        let Some(inner) = t.strip_prefix('[').and_then(|r| r.strip_suffix(']')) else {
            return Err((
                Some(last_line),
                format!("`{}`: unterminated list, expected `]`", entry.key),
            ));
        };
        for part in inner.split(',') {
            if part.trim().is_empty() {
                continue;
            }
            items.push((entry.line, part.to_string()));
        }
    } else if entry.inline.is_empty() {
        for &(l, body) in &entry.body {
            let Some(item) = body.strip_prefix('-') else {
                return Err((
                    Some(l),
                    format!("`{}`: expected a list item `- value`", entry.key),
                ));
            };
            items.push((l, item.to_string()));
        }
    } else {
        return Err((
            Some(entry.line),
            format!(
                "`{}` must be a list of six values, e.g. [0, 0, deg(-90), 0, 0, 0]",
                entry.key
            ),
        ));
    }
    if items.len() != 6 {
        return Err((
            Some(entry.line),
            format!(
                "`{}` has {} values, expected 6 (one per joint)",
                entry.key,
                items.len()
            ),
        ));
    }
    let mut out = [0.0; 6];
    for (slot, (l, item)) in out.iter_mut().zip(&items) {
        *slot = parse_value(item, *l)?;
    }
    Ok(out)
}

fn parse_geometric(entry: &Entry<'_>) -> Result<[f64; 7], Error> {
    let mut pairs: Vec<(usize, &str)> = Vec::new();
    if let Some(inner) = entry.inline.strip_prefix('{').and_then(|r| r.strip_suffix('}')) {
        pairs.extend(
            inner
                .split(',')
                .filter(|p| !p.trim().is_empty())
                .map(|p| (entry.line, p)),
        );
    } else if entry.inline.is_empty() {
        pairs.extend(entry.body.iter().copied());
    } else {
        return Err((
            Some(entry.line),
            format!("`{GEOMETRIC}` must be a mapping of a1, a2, b, c1, c2, c3, c4"),
        ));
    }
    let mut values: [Option<f64>; 7] = [None; 7];
    for (l, pair) in pairs {
        let Some((k, v)) = pair.split_once(':') else {
            return Err((
                Some(l),
                format!("expected `name: value`, found `{}`", pair.trim()),
            ));
        };
        let k = k.trim();
        let Some(i) = NAMES.iter().position(|n| *n == k) else {
            return Err((
                Some(l),
                format!("unknown geometric parameter `{k}` (expected a1, a2, b, c1, c2, c3, c4)"),
            ));
        };
        if values[i].is_some() {
            return Err((Some(l), format!("parameter `{k}` appears twice")));
        }
        values[i] = Some(parse_value(v, l)?);
    }
    let mut out = [0.0; 7];
    for (i, v) in values.iter().enumerate() {
        out[i] = v.ok_or_else(|| {
            (
                Some(entry.line),
                format!("`{GEOMETRIC}` lacks parameter `{}`", NAMES[i]),
            )
        })?;
    }
    Ok(out)
}

pub(super) fn parse(text: &str) -> Result<OpwParameters, Error> {
    let entries = split_entries(text)?;
    let find = |key: &str| {
        entries.iter().find(|e| e.key == key).ok_or_else(|| {
            (
                None,
                format!("missing key `{key}` (a ROS-Industrial opw_parameters file needs it)"),
            )
        })
    };
    let g = parse_geometric(find(GEOMETRIC)?)?;
    let offsets = parse_list(find(OFFSETS)?)?;
    let signs_entry = find(SIGNS)?;
    let sign_corrections = parse_list(signs_entry)?;
    if let Some(bad) = sign_corrections.iter().find(|s| **s != 1.0 && **s != -1.0) {
        return Err((
            Some(signs_entry.line),
            format!("sign corrections must be 1 or -1, found {bad}"),
        ));
    }
    Ok(OpwParameters {
        a1: g[0],
        a2: g[1],
        b: g[2],
        c1: g[3],
        c2: g[4],
        c3: g[5],
        c4: g[6],
        offsets,
        sign_corrections,
    })
}

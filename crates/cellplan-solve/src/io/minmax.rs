//! The cellplan min-max instance format: a [`MinMaxProblem`] as text (see also
//! `docs/minmax-format.md`). Line-oriented so that a few lines of Python read it: blank lines
//! are ignored, every other line is one of the following, in this order.
//!
//! ```text
//! NAME: inspect-4x45-s1          header, keys in any order, each at most once
//! TYPE: MINMAX                   optional; if given, MINMAX
//! COMMENT: any text              optional, may repeat
//! VEHICLES: 4                    required: number of vehicles m
//! TASKS: 45                      required: number of tasks n
//! BALANCE_LIMIT: 1.5             optional: γ, the largest allowed spread of the route times
//! BEST_KNOWN: 12.25              optional: best known makespan
//! SERVICE_SECTION
//! 0.31                           n lines: service time of task 0, 1, ..., n-1
//! ...
//! VEHICLE: 0                     m blocks, vehicles 0, 1, ..., m-1 in order
//! DEPOT: 0                       the depot node (0-based), keys in any order
//! CAP: 15                        most tasks the vehicle may take
//! NODES: 575                     k, the number of this vehicle's nodes (depot included)
//! FULL_MATRIX
//! 0 0.4142 ...                   k lines of k numbers: row i is the travel time from node i
//! ...
//! ALTERNATIVES
//! 0: 1 2 3                       n lines `t: nodes...` for t = 0..n-1 (0-based node indices;
//! 1:                             nothing after the colon when the vehicle cannot do task t)
//! ...
//! EOF                            optional
//! ```
//!
//! Counts are bounded before anything is allocated for them: `VEHICLES` at most
//! [`MAX_VEHICLES`], `TASKS` at most [`MAX_TASKS`], `NODES` at most
//! [`MAX_DENSE_NODES`](super::MAX_DENSE_NODES) (the matrix is dense).
//!
//! Nodes are 0-based and local to their vehicle. Numbers are decimal (`f64` as Rust or Python
//! print them); costs and service times finite and non-negative. [`write_minmax`] prints every
//! number in its shortest exact form, so reading a written problem gives it back bit for bit.
use std::io::Write;
use std::path::Path;

use super::{Ctx, DENSE_NODES, Limit, read_text, text_path};
use crate::error::ReadError;
use crate::minmax::{MinMaxProblem, Vehicle};
use crate::problem::CostMatrix;

/// Largest `VEHICLES` read.
pub const MAX_VEHICLES: usize = 10_000;
/// Largest `TASKS` read.
pub const MAX_TASKS: usize = 1_000_000;

const VEHICLES_LIMIT: Limit = Limit {
    max: MAX_VEHICLES,
    why: "",
};
const TASKS_LIMIT: Limit = Limit {
    max: MAX_TASKS,
    why: "",
};

/// A min-max instance as read: the problem with its name and best known makespan.
#[derive(Clone, Debug, PartialEq)]
pub struct MinMaxInstance {
    /// The `NAME` (empty when absent).
    pub name: String,
    /// `BEST_KNOWN`, when given.
    pub best_known: Option<f64>,
    /// The problem, validated.
    pub problem: MinMaxProblem,
}

/// Read a min-max instance file into its problem.
pub fn read_minmax(path: impl AsRef<Path>) -> Result<MinMaxProblem, ReadError> {
    read_minmax_instance(path).map(|i| i.problem)
}

/// Read a min-max instance file with its name and best known makespan.
pub fn read_minmax_instance(path: impl AsRef<Path>) -> Result<MinMaxInstance, ReadError> {
    let path = path.as_ref();
    parse(&read_text(path)?, Ctx { path })
}

/// Parse min-max instance text (errors name the file `<text>`).
pub fn parse_minmax(text: &str) -> Result<MinMaxInstance, ReadError> {
    let p = text_path();
    parse(text, Ctx { path: &p })
}

/// Write `p` in the min-max format under `name`. Every number in its shortest exact form.
pub fn write_minmax(p: &MinMaxProblem, name: &str, mut w: impl Write) -> std::io::Result<()> {
    let name = name.replace(['\n', '\r'], " ");
    writeln!(w, "NAME: {name}")?;
    writeln!(w, "TYPE: MINMAX")?;
    writeln!(w, "VEHICLES: {}", p.vehicles.len())?;
    writeln!(w, "TASKS: {}", p.tasks)?;
    if let Some(g) = p.balance_limit {
        writeln!(w, "BALANCE_LIMIT: {g}")?;
    }
    writeln!(w, "SERVICE_SECTION")?;
    for s in &p.service {
        writeln!(w, "{s}")?;
    }
    let mut line = String::new();
    for (i, v) in p.vehicles.iter().enumerate() {
        writeln!(w, "VEHICLE: {i}")?;
        writeln!(w, "DEPOT: {}", v.depot)?;
        writeln!(w, "CAP: {}", v.cap)?;
        let n = v.costs.n();
        writeln!(w, "NODES: {n}")?;
        writeln!(w, "FULL_MATRIX")?;
        for row in v.costs.data().chunks(n.max(1)).take(n) {
            line.clear();
            for (j, c) in row.iter().enumerate() {
                if j > 0 {
                    line.push(' ');
                }
                use std::fmt::Write as _;
                let _ = write!(line, "{c}");
            }
            writeln!(w, "{line}")?;
        }
        writeln!(w, "ALTERNATIVES")?;
        for (t, alts) in v.alternatives.iter().enumerate() {
            line.clear();
            use std::fmt::Write as _;
            let _ = write!(line, "{t}:");
            for a in alts {
                let _ = write!(line, " {a}");
            }
            writeln!(w, "{line}")?;
        }
    }
    writeln!(w, "EOF")?;
    Ok(())
}

/// Non-blank lines, trimmed, with 1-based numbers.
struct Lines<'a> {
    lines: std::iter::Peekable<Box<dyn Iterator<Item = (usize, &'a str)> + 'a>>,
    last: usize,
    ctx: Ctx<'a>,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str, ctx: Ctx<'a>) -> Self {
        let it: Box<dyn Iterator<Item = (usize, &'a str)> + 'a> = Box::new(
            text.lines()
                .enumerate()
                .map(|(i, l)| (i + 1, l.trim()))
                .filter(|(_, l)| !l.is_empty()),
        );
        Lines {
            lines: it.peekable(),
            last: 0,
            ctx,
        }
    }

    /// The next line, or an error saying the file ended where `what` was expected.
    fn next(&mut self, what: &str) -> Result<(usize, &'a str), ReadError> {
        match self.lines.next() {
            Some((n, l)) => {
                self.last = n;
                Ok((n, l))
            }
            None => Err(self.ctx.syntax(
                Some(self.last.max(1)),
                format!("the file ends where {what} was expected"),
            )),
        }
    }

    fn peek(&mut self) -> Option<(usize, &'a str)> {
        self.lines.peek().copied()
    }
}

/// `KEY: value` → (KEY, value); `None` for a line without a colon.
fn key_value(line: &str) -> Option<(&str, &str)> {
    line.split_once(':').map(|(k, v)| (k.trim(), v.trim()))
}

fn parse(text: &str, ctx: Ctx<'_>) -> Result<MinMaxInstance, ReadError> {
    let mut lines = Lines::new(text, ctx);
    let mut name: Option<String> = None;
    let mut m: Option<usize> = None;
    let mut n: Option<usize> = None;
    let mut balance: Option<f64> = None;
    let mut best: Option<f64> = None;
    let mut seen: Vec<&str> = Vec::new();

    // Header.
    let section_line = loop {
        let (ln, l) = lines.next("SERVICE_SECTION")?;
        if l == "SERVICE_SECTION" {
            break ln;
        }
        let Some((key, value)) = key_value(l) else {
            return Err(ctx.syntax(
                Some(ln),
                format!("expected a header line `KEY: value` or SERVICE_SECTION, found `{l}`"),
            ));
        };
        if key != "COMMENT" {
            if seen.contains(&key) {
                return Err(ctx.syntax(Some(ln), format!("{key} is given twice")));
            }
            seen.push(key);
        }
        match key {
            "NAME" => name = Some(value.to_string()),
            "COMMENT" => {}
            "TYPE" => {
                if value != "MINMAX" {
                    return Err(ctx.unsupported(
                        Some(ln),
                        format!("TYPE `{value}` is not a min-max instance; expected MINMAX"),
                    ));
                }
            }
            "VEHICLES" => m = Some(ctx.count(ln, value, "VEHICLES", "VEHICLES", VEHICLES_LIMIT)?),
            "TASKS" => n = Some(ctx.count(ln, value, "TASKS", "TASKS", TASKS_LIMIT)?),
            "BALANCE_LIMIT" => balance = Some(non_negative(ctx, ln, value, "BALANCE_LIMIT")?),
            "BEST_KNOWN" => best = Some(non_negative(ctx, ln, value, "BEST_KNOWN")?),
            other => {
                return Err(ctx.syntax(
                    Some(ln),
                    format!(
                        "unknown header keyword `{other}`; expected NAME, TYPE, COMMENT, VEHICLES, \
                         TASKS, BALANCE_LIMIT, BEST_KNOWN or SERVICE_SECTION"
                    ),
                ));
            }
        }
    };
    let m = m.ok_or_else(|| ctx.syntax(Some(section_line), "VEHICLES is missing before SERVICE_SECTION"))?;
    let n = n.ok_or_else(|| ctx.syntax(Some(section_line), "TASKS is missing before SERVICE_SECTION"))?;
    if m == 0 {
        return Err(ctx.invalid(
            Some(section_line),
            "VEHICLES is 0; at least one vehicle is needed",
        ));
    }

    // Service times.
    let mut service = Vec::with_capacity(n);
    for t in 0..n {
        let what = format!("the service time of task {t}");
        let (ln, l) = lines.next(&what)?;
        if l.split_whitespace().count() != 1 {
            return Err(ctx.syntax(
                Some(ln),
                format!("expected one number, {what}, found `{l}` ({n} service lines for TASKS: {n})"),
            ));
        }
        service.push(non_negative(ctx, ln, l, &what)?);
    }

    // Vehicles.
    let mut vehicles = Vec::with_capacity(m);
    for i in 0..m {
        let (ln, l) = lines.next(&format!("`VEHICLE: {i}`"))?;
        match key_value(l) {
            Some(("VEHICLE", v)) if ctx.integer(ln, v, "the vehicle index")? == i => {}
            _ => {
                return Err(ctx.syntax(
                    Some(ln),
                    format!(
                        "expected `VEHICLE: {i}` (VEHICLES: {m}, vehicles in order), found `{l}`{}",
                        too_many_lines_hint(l, i, n)
                    ),
                ));
            }
        }
        vehicles.push(parse_vehicle(&mut lines, ctx, i, n, ln)?);
    }
    if let Some((ln, l)) = lines.peek()
        && l != "EOF"
    {
        return Err(ctx.syntax(
            Some(ln),
            format!("expected EOF or the end of the file after {m} vehicles (VEHICLES: {m}), found `{l}`"),
        ));
    }
    let _ = lines.next("EOF");
    if let Some((ln, l)) = lines.peek() {
        return Err(ctx.syntax(Some(ln), format!("nothing may follow EOF, found `{l}`")));
    }

    let problem = MinMaxProblem {
        vehicles,
        tasks: n,
        service,
        balance_limit: balance,
    };
    problem
        .validate()
        .map_err(|e| ctx.invalid(None, format!("not a valid min-max problem: {e}")))?;
    Ok(MinMaxInstance {
        name: name.unwrap_or_default(),
        best_known: best,
        problem,
    })
}

/// Why a line stands where `VEHICLE: i` should: the block before it has more lines than
/// TASKS says.
fn too_many_lines_hint(l: &str, i: usize, tasks: usize) -> String {
    if i == 0 && l.parse::<f64>().is_ok() {
        format!("; there are more service times than TASKS: {tasks}")
    } else if i > 0 && key_value(l).is_some_and(|(k, _)| k.parse::<usize>().is_ok()) {
        format!(
            "; vehicle {} has more alternative lines than TASKS: {tasks}",
            i - 1
        )
    } else {
        String::new()
    }
}

fn non_negative(ctx: Ctx<'_>, ln: usize, tok: &str, what: &str) -> Result<f64, ReadError> {
    let v = ctx.number(ln, tok, what)?;
    if v < 0.0 {
        return Err(ctx.invalid(Some(ln), format!("{what} is {v}; it must be non-negative")));
    }
    Ok(v)
}

fn parse_vehicle(
    lines: &mut Lines<'_>,
    ctx: Ctx<'_>,
    i: usize,
    tasks: usize,
    vehicle_line: usize,
) -> Result<Vehicle, ReadError> {
    let (mut depot, mut cap, mut nodes) = (None, None, None);
    let matrix_line = loop {
        let (ln, l) = lines.next(&format!("FULL_MATRIX of vehicle {i}"))?;
        if l == "FULL_MATRIX" {
            break ln;
        }
        let slot = match key_value(l) {
            Some(("DEPOT", v)) => (&mut depot, ln, v, "DEPOT"),
            Some(("CAP", v)) => (&mut cap, ln, v, "CAP"),
            Some(("NODES", v)) => (&mut nodes, ln, v, "NODES"),
            _ => {
                return Err(ctx.syntax(
                    Some(ln),
                    format!("expected DEPOT, CAP, NODES or FULL_MATRIX in vehicle {i}, found `{l}`"),
                ));
            }
        };
        let (field, ln, v, key) = slot;
        if field.is_some() {
            return Err(ctx.syntax(Some(ln), format!("{key} of vehicle {i} is given twice")));
        }
        let value = if key == "NODES" {
            ctx.count(ln, v, "NODES", "NODES", DENSE_NODES)?
        } else {
            ctx.integer(ln, v, key)?
        };
        *field = Some((value, ln));
    };
    let missing = |key: &str| {
        ctx.syntax(
            Some(matrix_line),
            format!("vehicle {i} (line {vehicle_line}) has no {key} before FULL_MATRIX"),
        )
    };
    let (depot, depot_line) = depot.ok_or_else(|| missing("DEPOT"))?;
    let (cap, _) = cap.ok_or_else(|| missing("CAP"))?;
    let (k, _) = nodes.ok_or_else(|| missing("NODES"))?;
    if depot >= k {
        return Err(ctx.invalid(
            Some(depot_line),
            format!("DEPOT {depot} of vehicle {i} is out of range: NODES is {k}, nodes are 0..{k}"),
        ));
    }

    // Grows with the rows read, not with the count stated.
    let mut data = Vec::new();
    for r in 0..k {
        let (ln, l) = lines.next(&format!("row {r} of vehicle {i}'s matrix"))?;
        let count = l.split_whitespace().count();
        if count != k {
            return Err(ctx.syntax(
                Some(ln),
                format!(
                    "row {r} of vehicle {i}'s matrix has {count} numbers; NODES is {k}, so {k} are expected"
                ),
            ));
        }
        for tok in l.split_whitespace() {
            data.push(non_negative(ctx, ln, tok, &format!("a cost of vehicle {i}"))?);
        }
    }
    let costs = CostMatrix::new(k, data).map_err(|e| ctx.invalid(Some(matrix_line), e.to_string()))?;

    let (ln, l) = lines.next(&format!("ALTERNATIVES of vehicle {i}"))?;
    if l != "ALTERNATIVES" {
        return Err(ctx.syntax(
            Some(ln),
            format!("expected ALTERNATIVES after vehicle {i}'s {k} matrix rows (NODES: {k}), found `{l}`"),
        ));
    }
    let mut owner: Vec<Option<usize>> = vec![None; k];
    let mut alternatives = Vec::with_capacity(tasks);
    for t in 0..tasks {
        let (ln, l) = lines.next(&format!("the alternatives of task {t} for vehicle {i}"))?;
        let Some((head, rest)) = l.split_once(':') else {
            return Err(ctx.syntax(
                Some(ln),
                format!("expected `{t}: nodes...` (task {t} of {tasks}, vehicle {i}), found `{l}`"),
            ));
        };
        if head.trim().parse::<usize>().ok() != Some(t) {
            return Err(ctx.syntax(
                Some(ln),
                format!(
                    "expected task {t} (tasks in order, {tasks} lines for TASKS: {tasks}), found `{}`",
                    head.trim()
                ),
            ));
        }
        let mut alts = Vec::new();
        for tok in rest.split_whitespace() {
            let a = ctx.integer(ln, tok, "a node index")?;
            if a >= k {
                return Err(ctx.invalid(
                    Some(ln),
                    format!(
                        "task {t} of vehicle {i} names node {a}, out of range: NODES is {k}, nodes are 0..{k}"
                    ),
                ));
            }
            if a == depot {
                return Err(ctx.invalid(
                    Some(ln),
                    format!("task {t} of vehicle {i} names the depot {a} as an alternative"),
                ));
            }
            if let Some(o) = owner[a] {
                return Err(ctx.invalid(
                    Some(ln),
                    format!(
                        "node {a} of vehicle {i} serves task {o} and again task {t}; a node serves one task"
                    ),
                ));
            }
            owner[a] = Some(t);
            alts.push(a);
        }
        alternatives.push(alts);
    }
    Ok(Vehicle {
        costs: costs.into(),
        depot,
        cap,
        alternatives,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::minmax::generate;

    fn written(p: &MinMaxProblem) -> String {
        let mut buf = Vec::new();
        write_minmax(p, "t", &mut buf).unwrap();
        String::from_utf8(buf).unwrap()
    }

    #[test]
    fn round_trip_is_exact() {
        for (m, n, seed) in [(1, 5, 1), (3, 12, 2), (4, 20, 3)] {
            let mut p = generate(m, n, (1, 4), seed);
            if seed == 2 {
                p.balance_limit = Some(0.75);
            }
            let text = written(&p);
            let back = parse_minmax(&text).unwrap();
            assert_eq!(back.problem, p);
            assert_eq!(back.name, "t");
            assert_eq!(back.best_known, None);
            assert_eq!(written(&back.problem), text);
        }
    }

    /// Tiny valid file: 2 vehicles, 2 tasks.
    const SMALL: &str = "NAME: small
TYPE: MINMAX
VEHICLES: 2
TASKS: 2
BEST_KNOWN: 2.5
SERVICE_SECTION
0.5
0.25
VEHICLE: 0
DEPOT: 0
CAP: 2
NODES: 3
FULL_MATRIX
0 1 2
1 0 1
2 1 0
ALTERNATIVES
0: 1
1: 2
VEHICLE: 1
NODES: 2
DEPOT: 0
CAP: 1

FULL_MATRIX
0 1
1 0
ALTERNATIVES
0:
1: 1
EOF
";

    #[test]
    fn reads_a_small_file() {
        let i = parse_minmax(SMALL).unwrap();
        assert_eq!(i.name, "small");
        assert_eq!(i.best_known, Some(2.5));
        assert_eq!(i.problem.tasks, 2);
        assert_eq!(i.problem.vehicles[1].alternatives, vec![vec![], vec![1]]);
        assert_eq!(i.problem.vehicles[0].costs.get(0, 2), 2.0);
    }

    fn error_line(text: &str) -> (Option<usize>, String) {
        let e = parse_minmax(text).unwrap_err();
        (e.line(), e.to_string())
    }

    #[test]
    fn malformed_files_name_the_line() {
        let cases: &[(&str, &str, usize, &str)] = &[
            ("VEHICLES: 2", "VEHICLES: two", 3, "VEHICLES"),
            ("TYPE: MINMAX", "TYPE: TSP", 2, "MINMAX"),
            ("BEST_KNOWN: 2.5", "SIZE: 3", 5, "unknown header"),
            ("0.25\nVEHICLE: 0", "x\nVEHICLE: 0", 8, "service time of task 1"),
            ("0.25\nVEHICLE: 0", "-1\nVEHICLE: 0", 8, "non-negative"),
            ("0.5\n0.25", "0.5 0.25\n", 7, "one number"),
            ("1 0 1\n2 1 0", "1 0 1\n2 1", 16, "has 2 numbers"),
            ("1 0 1\n2 1 0", "1 0 q\n2 1 0", 15, "cost of vehicle 0"),
            ("0: 1\n1: 2", "0: 1\n1: 3", 19, "out of range"),
            ("0: 1\n1: 2", "0: 1\n1: 1", 19, "serves task 0"),
            ("0: 1\n1: 2", "0: 1\n1: 0", 19, "depot"),
            ("0: 1\n1: 2", "0: 1\n2: 2", 19, "expected task 1"),
            ("DEPOT: 0\nCAP: 2", "DEPOT: 5\nCAP: 2", 10, "DEPOT 5"),
            ("CAP: 1\n", "CAP: 1\nCAP: 1\n", 24, "twice"),
            ("VEHICLE: 1", "VEHICLE: 3", 20, "VEHICLE: 1"),
            ("1: 1\nEOF", "1: 1\n2: 1\nEOF", 31, "expected EOF"),
        ];
        for &(from, to, line, says) in cases {
            let text = SMALL.replacen(from, to, 1);
            assert_ne!(text, SMALL, "{from}");
            let (l, msg) = error_line(&text);
            assert_eq!(l, Some(line), "{to}: {msg}");
            assert!(msg.contains(says), "{to}: {msg}");
            assert!(msg.starts_with(&format!("<text>:{line}:")), "{msg}");
        }
    }

    #[test]
    fn a_truncated_file_names_its_last_line() {
        let text: String = SMALL.lines().take(14).collect::<Vec<_>>().join("\n");
        let (l, msg) = error_line(&text);
        assert_eq!(l, Some(14), "{msg}");
        assert!(msg.contains("row 1 of vehicle 0"), "{msg}");
    }

    #[test]
    fn validation_failures_name_the_file() {
        // Task 0 can be done only by vehicle 0 and task 1 only by vehicle 0 too, but its cap is 1.
        let text = SMALL
            .replacen("CAP: 2", "CAP: 1", 1)
            .replacen("0:\n1: 1", "0:\n1:", 1);
        let e = parse_minmax(&text).unwrap_err();
        assert!(matches!(e, ReadError::Invalid { .. }), "{e}");
        assert!(
            e.to_string().starts_with("<text>: not a valid min-max problem"),
            "{e}"
        );
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("bad.minmax");
        std::fs::write(&f, &text).unwrap();
        let e = read_minmax(&f).unwrap_err();
        assert_eq!(e.path(), f.as_path());
        assert!(e.to_string().contains("bad.minmax"), "{e}");
    }
}

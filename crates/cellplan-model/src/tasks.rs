//! The task list: a CSV of point tasks (measurement points, studs, …) with the columns every
//! process shares and those its process adds ([`TaskColumn`]).
use crate::InputError;
use crate::io::read_bounded;
use crate::names::serde_name;
use crate::process::{ColumnUnit, TaskColumn};
use cellplan_geom::DVec3;
use serde::Serialize;
use std::collections::HashMap;
use std::fmt;
use std::path::Path;

/// Largest task file read (bytes).
pub const MAX_TASK_FILE: u64 = 256 << 20;

/// Largest coordinate of a task (m): a cell is a room, not a continent.
pub const MAX_COORDINATE: f64 = 1e4;

/// Index of a task in [`crate::Cell::tasks`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct TaskId(pub usize);

/// What kind of feature a task measures (reported; the optical process treats them alike).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Feature {
    /// A point on a surface.
    #[default]
    Surface,
    /// A hole.
    Hole,
    /// A slot.
    Slot,
    /// An edge.
    Edge,
    /// A thread.
    Thread,
    /// A stud.
    Stud,
}

impl Feature {
    /// Every feature type.
    const ALL: [Feature; 6] = [
        Feature::Surface,
        Feature::Hole,
        Feature::Slot,
        Feature::Edge,
        Feature::Thread,
        Feature::Stud,
    ];

    /// The feature named `s` (as in the task file, any case).
    fn parse(s: &str) -> Option<Feature> {
        Self::ALL
            .into_iter()
            .find(|f| serde_name(f).eq_ignore_ascii_case(s))
    }
}

/// The name as in the task file (the serde name).
impl fmt::Display for Feature {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(serde_name(self))
    }
}

/// One task: a point with its surface normal, in the world frame (SI).
#[derive(Clone, Debug, Serialize)]
pub struct Task {
    /// Index in the cell.
    pub id: TaskId,
    /// The `id` column.
    pub name: String,
    /// Position (m).
    pub position: DVec3,
    /// Outward unit surface normal.
    pub normal: DVec3,
    /// The values of the process's own columns (SI), in the order the process declares them
    /// ([`crate::ProcessEntry::task_columns`]); `None` where the field is empty.
    pub values: Vec<Option<f64>>,
    /// Feature type.
    pub feature: Feature,
    /// Line in the CSV, for messages.
    pub line: usize,
}

const REQUIRED: [&str; 7] = ["id", "x", "y", "z", "nx", "ny", "nz"];

/// Reads a task CSV with a header naming at least `id,x,y,z,nx,ny,nz` (any order; optional
/// `feature` and the process's `columns`). Lengths are scaled by `to_m`, angles by `to_rad`.
pub fn read_tasks(
    path: &Path,
    to_m: f64,
    to_rad: f64,
    columns: &[TaskColumn],
) -> Result<Vec<Task>, InputError> {
    let text = read_bounded(path, MAX_TASK_FILE).map_err(|e| {
        InputError::new(path, format!("cannot read the task list: {e}"))
            .hint("check `[tasks] file` in the cell file; it is relative to the cell file")
    })?;
    parse_tasks(path, &text, to_m, to_rad, columns)
}

/// [`read_tasks`] on text already read.
pub fn parse_tasks(
    path: &Path,
    text: &str,
    to_m: f64,
    to_rad: f64,
    columns: &[TaskColumn],
) -> Result<Vec<Task>, InputError> {
    if text
        .lines()
        .all(|l| l.trim().is_empty() || l.trim_start().starts_with('#'))
    {
        return Err(InputError::at_line(path, Some(1), "the task list is empty")
            .hint("the first line names the columns (id,x,y,z,nx,ny,nz), one task per line below it"));
    }
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .flexible(true)
        .from_reader(text.as_bytes());
    let optional: Vec<&str> = std::iter::once("feature")
        .chain(columns.iter().map(|c| c.name))
        .collect();
    let header_error = |msg: String| {
        InputError::at_line(path, Some(1), msg).hint(format!(
            "the first line names the columns: id,x,y,z,nx,ny,nz and optionally {}",
            optional.join(", ")
        ))
    };
    let headers = reader
        .headers()
        .map_err(|e| header_error(format!("cannot read the header: {e}")))?
        .clone();
    let column = |name: &str| headers.iter().position(|h| h.eq_ignore_ascii_case(name));
    let mut index = [0usize; 7];
    for (slot, name) in index.iter_mut().zip(REQUIRED) {
        *slot = column(name).ok_or_else(|| {
            crate::other_separator(path, text)
                .unwrap_or_else(|| header_error(format!("no column `{name}` in the header")))
        })?;
    }
    let feature_col = column("feature");
    let value_cols: Vec<Option<usize>> = columns.iter().map(|c| column(c.name)).collect();
    for (i, h) in headers.iter().enumerate() {
        let known = REQUIRED
            .iter()
            .chain(&optional)
            .any(|r| r.eq_ignore_ascii_case(h));
        if !known {
            return Err(header_error(format!("unknown column `{h}`")));
        }
        if headers.iter().take(i).any(|g| g.eq_ignore_ascii_case(h)) {
            return Err(header_error(format!("column `{h}` is named twice")));
        }
    }

    let mut tasks = Vec::new();
    let mut seen: HashMap<String, usize> = HashMap::new();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map(|p| p.line() as usize);
            InputError::at_line(path, line, format!("unreadable row: {e}"))
                .hint("save the task list as plain UTF-8 CSV with one task per line")
        })?;
        let line = record.position().map(|p| p.line() as usize).unwrap_or(0);
        if record.iter().all(|f| f.is_empty()) {
            continue;
        }
        let err = |msg: String| InputError::at_line(path, Some(line), msg);
        if record.len() > headers.len() {
            return Err(err(format!(
                "the row has {} fields but the header names {}",
                record.len(),
                headers.len()
            ))
            .hint("remove the extra fields, or name the column in the header"));
        }
        let field = |i: usize, name: &str| -> Result<&str, InputError> {
            match record.get(i) {
                Some(v) if !v.is_empty() => Ok(v),
                _ => {
                    Err(err(format!("missing value for `{name}`")).hint("every row needs id,x,y,z,nx,ny,nz"))
                }
            }
        };
        let number = |i: usize, name: &str| -> Result<f64, InputError> {
            let v = field(i, name)?;
            match v.parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(err(format!("`{name}` is not a number: `{v}`"))
                    .hint("write numbers with a decimal point and no units, e.g. 1250.5")),
            }
        };
        let name = field(index[0], "id")?.to_string();
        if let Some(first) = seen.insert(name.clone(), line) {
            return Err(
                err(format!("task id `{name}` is used again (first on line {first})"))
                    .hint("task ids must be unique"),
            );
        }
        let p = DVec3::new(
            number(index[1], "x")?,
            number(index[2], "y")?,
            number(index[3], "z")?,
        );
        let n = DVec3::new(
            number(index[4], "nx")?,
            number(index[5], "ny")?,
            number(index[6], "nz")?,
        );
        if p.abs().max_element() * to_m > MAX_COORDINATE {
            return Err(err(format!(
                "task `{name}` lies {:.3e} m from the origin, beyond {MAX_COORDINATE} m",
                p.abs().max_element() * to_m
            ))
            .hint("check the cell's length unit (`units.length`) and the task coordinates"));
        }
        let len = n.length();
        if len < 1e-9 {
            return Err(err(format!("task `{name}` has a zero normal"))
                .hint("nx,ny,nz is the outward surface normal, a unit vector"));
        }
        if (len - 1.0).abs() > 1e-3 {
            return Err(err(format!(
                "task `{name}` has a normal of length {len:.4}, not a unit vector"
            ))
            .hint("normalise nx,ny,nz (divide by their length)"));
        }
        let mut values = Vec::with_capacity(columns.len());
        for (c, col) in columns.iter().zip(&value_cols) {
            let value = match col.and_then(|i| record.get(i)).filter(|s| !s.is_empty()) {
                None => None,
                Some(_) => {
                    let x = number(col.unwrap_or_default(), c.name)?;
                    Some(match c.unit {
                        ColumnUnit::Length => x * to_m,
                        ColumnUnit::Angle => x * to_rad,
                        ColumnUnit::Number => x,
                    })
                }
            };
            values.push(value);
        }
        let feature = match feature_col.and_then(|i| record.get(i)).filter(|s| !s.is_empty()) {
            None => Feature::default(),
            Some(v) => Feature::parse(v).ok_or_else(|| {
                err(format!("unknown feature `{v}`")).hint(format!(
                    "use one of {}",
                    Feature::ALL.map(|f| serde_name(&f)).join(", ")
                ))
            })?,
        };
        tasks.push(Task {
            id: TaskId(tasks.len()),
            name,
            position: p * to_m,
            normal: n / len,
            values,
            feature,
            line,
        });
    }
    if tasks.is_empty() {
        return Err(InputError::new(path, "the task list has no tasks")
            .hint("add rows id,x,y,z,nx,ny,nz below the header"));
    }
    Ok(tasks)
}

/// Writes tasks as CSV in the given units (inverse of [`parse_tasks`]): every column, the
/// feature and the process's `columns` included.
pub fn tasks_to_csv(tasks: &[Task], to_m: f64, to_rad: f64, columns: &[TaskColumn]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<&str> = REQUIRED.to_vec();
    header.push("feature");
    header.extend(columns.iter().map(|c| c.name));
    // Writing to a Vec cannot fail.
    let _ = w.write_record(&header);
    for t in tasks {
        let p = t.position / to_m;
        let n = t.normal;
        let mut row = vec![
            t.name.clone(),
            format!("{:.3}", p.x),
            format!("{:.3}", p.y),
            format!("{:.3}", p.z),
            format!("{:.6}", n.x),
            format!("{:.6}", n.y),
            format!("{:.6}", n.z),
            t.feature.to_string(),
        ];
        for (c, v) in columns.iter().zip(&t.values) {
            row.push(v.map_or(String::new(), |x| match c.unit {
                ColumnUnit::Length => format!("{:.3}", x / to_m),
                ColumnUnit::Angle => format!("{:.6}", x / to_rad),
                ColumnUnit::Number => format!("{x}"),
            }));
        }
        let _ = w.write_record(&row);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOL: [TaskColumn; 1] = [TaskColumn {
        name: "tolerance",
        unit: ColumnUnit::Angle,
    }];

    /// For every feature type: the serde name, `Display` and the name the task file reads agree.
    #[test]
    fn feature_names_are_the_serde_names() {
        for f in Feature::ALL {
            let json = serde_json::to_value(f).unwrap();
            assert_eq!(json.as_str(), Some(f.to_string().as_str()));
            assert_eq!(Feature::parse(&f.to_string()), Some(f));
            assert_eq!(Feature::parse(&f.to_string().to_uppercase()), Some(f));
        }
        assert_eq!(
            Feature::ALL.map(|f| f.to_string()).join(", "),
            "surface, hole, slot, edge, thread, stud"
        );
    }

    fn parse(text: &str) -> Result<Vec<Task>, InputError> {
        parse_tasks(
            Path::new("tasks.csv"),
            text,
            1e-3,
            std::f64::consts::PI / 180.0,
            &TOL,
        )
    }

    #[test]
    fn reads_rows_in_any_column_order_with_units() {
        let t = parse("x,y,z,id,nx,ny,nz,feature,tolerance\n1000,0,0,M1,0,0,1,hole,10\n").unwrap();
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].name, "M1");
        assert!((t[0].position - DVec3::X).length() < 1e-12);
        assert_eq!(t[0].feature, Feature::Hole);
        assert!((t[0].values[0].unwrap() - 10f64.to_radians()).abs() < 1e-12);
        assert_eq!(t[0].line, 2);
    }

    #[test]
    fn non_numeric_field_names_its_line() {
        let e = parse("id,x,y,z,nx,ny,nz\nM1,0,0,0,0,0,1\nM2,0,abc,0,0,0,1\n").unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(e.message.contains("`y` is not a number"), "{e}");
    }

    #[test]
    fn missing_field_names_its_line() {
        let e = parse("id,x,y,z,nx,ny,nz\nM1,0,0,0,0,0\n").unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.message.contains("missing value for `nz`"), "{e}");
    }

    #[test]
    fn empty_lists_and_other_separators_are_named() {
        for text in ["", "\n\n", "# tasks\n"] {
            let e = parse(text).unwrap_err();
            assert!(e.message.contains("the task list is empty"), "{e}");
            assert_eq!(e.line, Some(1));
        }
        let e = parse("id;x;y;z;nx;ny;nz\nM1;0,5;0;0;0;0;1\n").unwrap_err();
        assert!(e.message.contains("separated by `;`"), "{e}");
        assert_eq!(e.line, Some(1));
        // A header with commas and a missing column says which.
        let e = parse("id,x,y,z,nx,ny\n").unwrap_err();
        assert!(e.message.contains("no column `nz`"), "{e}");
    }

    #[test]
    fn zero_and_non_unit_normals_are_refused() {
        let e = parse("id,x,y,z,nx,ny,nz\nM1,0,0,0,0,0,0\n").unwrap_err();
        assert!(e.message.contains("zero normal"));
        let e = parse("id,x,y,z,nx,ny,nz\nM1,0,0,0,0,0,2\n").unwrap_err();
        assert!(e.message.contains("not a unit vector"));
        assert_eq!(e.line, Some(2));
    }

    #[test]
    fn duplicate_ids_and_unknown_columns_are_refused() {
        let e = parse("id,x,y,z,nx,ny,nz\nM1,0,0,0,0,0,1\nM1,1,0,0,0,0,1\n").unwrap_err();
        assert!(e.message.contains("used again"));
        let e = parse("id,x,y,z,nx,ny,nz,colour\nM1,0,0,0,0,0,1,red\n").unwrap_err();
        assert!(e.message.contains("unknown column"));
        let e = parse("id,x,y,z,nx,ny\n").unwrap_err();
        assert!(e.message.contains("no column `nz`"));
    }

    #[test]
    fn extra_fields_and_bad_tolerances_are_refused() {
        let e = parse("id,x,y,z,nx,ny,nz\nM1,0,0,0,0,0,1,7\n").unwrap_err();
        assert!(e.message.contains("8 fields"), "{e}");
        let e = parse("id,x,y,z,nx,ny,nz,tolerance\nM1,0,0,0,0,0,1,abc\n").unwrap_err();
        assert!(e.message.contains("`tolerance` is not a number"), "{e}");
        assert!(e.hint.is_some());
        let e = parse("id,x,y,z,nx,ny,nz,x\nM1,0,0,0,0,0,1,1\n").unwrap_err();
        assert!(e.message.contains("column `x` is named twice"), "{e}");
        assert_eq!(e.line, Some(1));
        let e = parse("id,x,y,z,nx,ny,nz\nM1,1e30,0,0,0,0,1\n").unwrap_err();
        assert!(e.message.contains("from the origin"), "{e}");
    }

    #[test]
    fn csv_round_trip() {
        let t = parse("id,x,y,z,nx,ny,nz,feature,tolerance\nA,1,2,3,0,0.6,0.8,hole,12\nB,1,2,3,0,0,1,,\n")
            .unwrap();
        let back = parse(&tasks_to_csv(&t, 1e-3, std::f64::consts::PI / 180.0, &TOL)).unwrap();
        assert_eq!(back[0].feature, Feature::Hole);
        assert!((back[0].values[0].unwrap() - 12f64.to_radians()).abs() < 1e-9);
        assert_eq!(back[1].values[0], None);
        assert_eq!(back[0].name, "A");
        assert!((back[0].position - t[0].position).length() < 1e-9);
        assert!((back[0].normal - t[0].normal).length() < 1e-9);
    }
}

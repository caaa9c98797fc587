//! The `cellplan` binary on the example cells and on broken inputs, one module per command
//! family; the helpers here are shared.
mod bench;
mod check;
mod cmm;
mod gen_tasks;
mod pcb;
mod plan;
mod refusals;
mod studweld;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub(crate) fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

pub(crate) fn cellplan(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cellplan"))
        .args(args)
        .env("CELLPLAN_CACHE_DIR", cache)
        .env("NO_COLOR", "1")
        .current_dir(root())
        .output()
        .expect("run cellplan")
}

/// Runs `cellplan args` and asserts exit 0 (showing stderr otherwise).
pub(crate) fn run_ok(args: &[&str], cache: &Path) -> Output {
    let out = cellplan(args, cache);
    assert_eq!(
        out.status.code(),
        Some(0),
        "cellplan {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs `cellplan args`, asserts exit 0 (showing stderr otherwise) and parses stdout as JSON.
pub(crate) fn json_ok(args: &[&str], cache: &Path) -> Value {
    serde_json::from_slice(&run_ok(args, cache).stdout).expect("stdout is JSON")
}

/// A fresh scratch folder per test, removed when the test ends (kept, for a look at what a
/// test wrote, with `CELLPLAN_KEEP_SCRATCH` set).
pub(crate) fn scratch(name: &str) -> Scratch {
    let dir = tempfile::Builder::new()
        .prefix(&format!("cellplan-cli-{name}-"))
        .disable_cleanup(std::env::var_os("CELLPLAN_KEEP_SCRATCH").is_some())
        .tempdir()
        .unwrap();
    Scratch(dir)
}

/// A test's scratch folder (see [`scratch`]), read as its path.
pub(crate) struct Scratch(tempfile::TempDir);

impl std::ops::Deref for Scratch {
    type Target = Path;

    fn deref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        self.0.path()
    }
}

pub(crate) const FANUC: &str = "data/robots/fanuc_r2000ic";

/// A one-robot cell with a box part and three tasks, all paths absolute.
pub(crate) fn small_cell(dir: &Path) -> (String, String) {
    let r = root();
    let cell = format!(
        r#"name = "small"
units = {{ length = "mm", angle = "deg" }}

[process]
kind = "optical-inspection"
standoff = 250
stripe_length = 60
baseline = 100

[tools.probe]
tcp = {{ xyz = [0, 0, 300] }}

[[tools.probe.shape]]
box = [180, 120, 220]
pose = {{ xyz = [45, 0, 190] }}

[[robots]]
name = "R1"
urdf = "{r}/{FANUC}/urdf/r2000ic125l.urdf"
packages = {{ fanuc_r2000ic_support = "{r}/{FANUC}/fanuc_r2000ic_support" }}
opw = "{r}/{FANUC}/fanuc_r2000ic_support/config/opw_parameters_r2000ic125l.yaml"
base = {{ xyz = [0, 0, 0] }}
home = [0, -30, 0, 0, -60, 0]
tool = "probe"

[[objects]]
name = "part"
box = [600, 600, 600]
pose = {{ xyz = [1900, 0, 300] }}

[tasks]
file = "tasks.csv"
"#,
        r = r.display()
    );
    let tasks =
        "id,x,y,z,nx,ny,nz\nA,1900,0,600,0,0,1\nB,1900,200,600,0,0,1\nC,1600,0,300,-1,0,0\n".to_string();
    std::fs::write(dir.join("cell.toml"), &cell).unwrap();
    std::fs::write(dir.join("tasks.csv"), &tasks).unwrap();
    (cell, tasks)
}

/// Runs `check --json --svg` on a cell expected to be refused: exit 2, the message names the
/// file (and the line), and the SVG is not written.
pub(crate) fn refused(
    dir: &Path,
    cache: &Path,
    file_in_message: &str,
    line: Option<usize>,
    words: &str,
) -> String {
    let svg = dir.join("out.svg");
    let cell = dir.join("cell.toml");
    let out = cellplan(
        &["check", cell.to_str().unwrap(), "--svg", svg.to_str().unwrap()],
        cache,
    );
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(2), "stderr: {stderr}");
    let expected = match line {
        Some(l) => format!("{file_in_message}:{l}"),
        None => file_in_message.to_string(),
    };
    assert!(stderr.contains(&expected), "expected `{expected}` in: {stderr}");
    assert!(stderr.contains(words), "expected `{words}` in: {stderr}");
    assert!(
        stderr.contains("help:"),
        "every refusal says what to do: {stderr}"
    );
    assert!(!svg.exists(), "nothing may be written on bad input");
    let cached = std::fs::read_dir(cache).map_or(0, |d| {
        d.filter_map(Result::ok)
            .filter(|e| e.file_name().to_string_lossy().starts_with("self-pairs"))
            .count()
    });
    assert_eq!(cached, 0, "not even the cache is written on bad input");
    assert!(out.stdout.is_empty(), "no report on bad input");
    stderr
}

/// Plans the small cell in a fresh scratch folder `name` with `--json`: the folder, the cell
/// file, the output folder and the printed summary.
pub(crate) fn plan_small_cell(name: &str) -> (Scratch, PathBuf, PathBuf, Value) {
    let dir = scratch(name);
    small_cell(&dir);
    let cell = dir.join("cell.toml");
    let out_dir = dir.join("out");
    let out = cellplan(
        &[
            "plan",
            cell.to_str().unwrap(),
            "-o",
            out_dir.to_str().unwrap(),
            "--json",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let summary: Value = serde_json::from_slice(&out.stdout).unwrap();
    (dir, cell, out_dir, summary)
}

//! Test support (feature `testing`), shared by this crate's tests and the report's: the
//! crossing cell — the bundled two-robot example with the second robot moved to 1 m from the
//! first, and its first 8 MPs, so that the robots' paths cross — planned once per test binary,
//! and its plan coordinated by any strategy.
use crate::load;
use cellplan_core::candidates::{CandidateTable, generate};
use cellplan_core::coord::{self, CoordSettings, Coordination};
use cellplan_core::document::Plan;
use cellplan_core::plan::{self, Outcome, PlanSettings};
use cellplan_model::{Cell, LoadOptions};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The repository's root folder.
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// `f` run on a pool of `threads` worker threads (for tests that a result does not depend on
/// the thread count).
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

/// The bundled two-robot example with only its first `tasks` MPs, named `name` and its
/// `cell.toml` text edited by `edit`, written to a folder of the system's temporary folder;
/// returns the path of its `cell.toml`. The folder is named by `folder` and a hash of what it
/// holds, and its files are written whole (each to a temporary file, then renamed): test
/// processes that want the same copy share one folder, running or not, and no run leaves
/// another folder behind.
pub fn example_copy(folder: &str, name: &str, tasks: usize, edit: impl FnOnce(String) -> String) -> PathBuf {
    let root = repo_root();
    let example = root.join("examples/autobody-2r");
    let text = std::fs::read_to_string(example.join("cell.toml"))
        .unwrap()
        .replace("../../data", &root.join("data").display().to_string())
        .replace("name = \"autobody-2r\"", &format!("name = \"{name}\""));
    let text = edit(text);
    let csv = std::fs::read_to_string(example.join("tasks.csv")).unwrap();
    let keep: Vec<&str> = csv
        .lines()
        .filter(|l| !l.starts_with('#'))
        .take(tasks + 1)
        .collect();
    let csv = keep.join("\n") + "\n";
    let mut hash = cellplan_model::hash::Fnv::default();
    for part in [&text, &csv] {
        std::hash::Hasher::write(&mut hash, part.as_bytes());
        std::hash::Hasher::write_u8(&mut hash, 0);
    }
    let hash = std::hash::Hasher::finish(&hash);
    let dir = std::env::temp_dir().join(format!("cellplan-{folder}-{hash:016x}"));
    std::fs::create_dir_all(&dir).unwrap();
    for (file, contents) in [("cell.toml", &text), ("tasks.csv", &csv)] {
        let mut part = tempfile::NamedTempFile::new_in(&dir).unwrap();
        std::io::Write::write_all(&mut part, contents.as_bytes()).unwrap();
        part.persist(dir.join(file)).unwrap();
    }
    dir.join("cell.toml")
}

/// Writes the crossing cell to a temporary folder of this process and returns the path of its
/// `cell.toml`.
pub fn crossing_cell() -> PathBuf {
    example_copy("coord-test", "crossing-2r", 12, |text| {
        let text = text.replace("xyz = [3100, 1100, 0]", "xyz = [3100, -200, 0]");
        assert!(text.contains("[3100, -200, 0]"), "the second robot is moved");
        text
    })
}

/// The crossing cell, its candidates and its uncoordinated plan.
pub struct Fixture {
    /// The crossing cell.
    pub cell: Cell,
    /// Its candidate table.
    pub table: CandidateTable,
    /// The settings it was planned with.
    pub settings: PlanSettings,
    /// Its plan before coordination.
    pub outcome: Outcome,
}

/// The crossing cell, loaded and planned on first use.
pub fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let cell = load(&crossing_cell(), &LoadOptions::default()).expect("the crossing cell loads");
        let table = generate(&cell);
        let settings = PlanSettings {
            alternatives: 8,
            balanced_iterations: 60,
            time_limit: std::time::Duration::from_secs(3600),
            ..PlanSettings::default()
        };
        let outcome = plan::plan(&cell, &table, &settings, &|_| {}).expect("the crossing cell plans");
        Fixture {
            cell,
            table,
            settings,
            outcome,
        }
    })
}

/// The crossing cell's plan coordinated with `strategy`: its Plan document and the
/// coordination it records.
pub fn document(strategy: Coordination) -> (Plan, coord::Coordinated) {
    let f = fixture();
    let c = coord::coordinate_outcome(
        &f.cell,
        &f.table,
        &f.outcome,
        &CoordSettings {
            strategy,
            ..CoordSettings::default()
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", strategy));
    (
        cellplan_core::document::build(&f.cell, &f.table, &f.outcome, &c, &f.settings, 0.0, 0.0),
        c,
    )
}

//! The `cellplan` binary on the example cells and on broken inputs.
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

fn cellplan(args: &[&str], cache: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cellplan"))
        .args(args)
        .env("CELLPLAN_CACHE_DIR", cache)
        .env("NO_COLOR", "1")
        .current_dir(root())
        .output()
        .expect("run cellplan")
}

/// A fresh scratch folder per test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("cellplan-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const FANUC: &str = "data/robots/fanuc_r2000ic";

/// A one-robot cell with a box part and three tasks, all paths absolute.
fn small_cell(dir: &Path) -> (String, String) {
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
fn refused(dir: &Path, cache: &Path, file_in_message: &str, line: Option<usize>, words: &str) -> String {
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

#[test]
fn small_cell_checks_and_classifies() {
    let dir = scratch("small");
    small_cell(&dir);
    let cell = dir.join("cell.toml");
    let out = cellplan(&["check", cell.to_str().unwrap(), "--json"], &dir);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["tasks"], 3);
    assert_eq!(v["robots"], serde_json::json!(["R1"]));
    for t in v["candidates"].as_array().unwrap() {
        assert!(t["robots"]["R1"].as_u64().unwrap() > 0, "{t}");
    }
    assert_eq!(v["unmeasurable"].as_array().unwrap().len(), 0);
    assert_eq!(v["shared"].as_array().unwrap().len(), 0);
}

#[test]
fn malformed_toml_names_the_line() {
    let dir = scratch("toml");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace("standoff = 250", "standoff = = 250"),
    )
    .unwrap();
    refused(&dir, &dir, "cell.toml", Some(6), "invalid cell file");
}

#[test]
fn wrong_type_in_toml_names_the_line() {
    let dir = scratch("toml-type");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace("baseline = 100", "baseline = \"long\""),
    )
    .unwrap();
    refused(&dir, &dir, "cell.toml", Some(8), "expected f64");
}

#[test]
fn csv_missing_field_names_the_line() {
    let dir = scratch("csv-missing");
    small_cell(&dir);
    std::fs::write(
        dir.join("tasks.csv"),
        "id,x,y,z,nx,ny,nz\nA,1900,0,600,0,0,1\nB,1900,200,600,0,0\n",
    )
    .unwrap();
    refused(&dir, &dir, "tasks.csv", Some(3), "missing value for `nz`");
}

#[test]
fn csv_non_numeric_field_names_the_line() {
    let dir = scratch("csv-text");
    small_cell(&dir);
    std::fs::write(
        dir.join("tasks.csv"),
        "id,x,y,z,nx,ny,nz\nA,1900,zero,600,0,0,1\n",
    )
    .unwrap();
    refused(&dir, &dir, "tasks.csv", Some(2), "`y` is not a number");
}

#[test]
fn zero_and_non_unit_normals_are_refused() {
    let dir = scratch("normal");
    small_cell(&dir);
    std::fs::write(dir.join("tasks.csv"), "id,x,y,z,nx,ny,nz\nA,1900,0,600,0,0,0\n").unwrap();
    refused(&dir, &dir, "tasks.csv", Some(2), "zero normal");
    std::fs::write(dir.join("tasks.csv"), "id,x,y,z,nx,ny,nz\nA,1900,0,600,0,1,1\n").unwrap();
    refused(&dir, &dir, "tasks.csv", Some(2), "not a unit vector");
}

#[test]
fn urdf_that_is_not_xml_is_refused() {
    let dir = scratch("urdf-xml");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("bad.urdf"),
        "<robot name=\"x\">\n  <link name=\"a\">\n</robot\n",
    )
    .unwrap();
    let urdf_line = cell.lines().find(|l| l.starts_with("urdf =")).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace(urdf_line, "urdf = \"bad.urdf\""),
    )
    .unwrap();
    refused(&dir, &dir, "bad.urdf", Some(4), "not well-formed XML");
}

#[test]
fn urdf_naming_a_missing_mesh_is_refused() {
    let dir = scratch("urdf-mesh");
    let (cell, _) = small_cell(&dir);
    let r = root();
    let urdf = std::fs::read_to_string(r.join(FANUC).join("urdf/r2000ic125l.urdf"))
        .unwrap()
        .replace("collision/link_3.stl", "collision/link_3_missing.stl");
    std::fs::write(dir.join("robot.urdf"), urdf).unwrap();
    let urdf_line = cell.lines().find(|l| l.starts_with("urdf =")).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace(urdf_line, "urdf = \"robot.urdf\""),
    )
    .unwrap();
    // The second mention is the <collision> mesh, the one cellplan reads.
    let text = std::fs::read_to_string(dir.join("robot.urdf")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let line = lines.iter().rposition(|l| l.contains("link_3_missing")).unwrap() + 1;
    refused(&dir, &dir, "robot.urdf", Some(line), "link_3_missing.stl");
}

#[test]
fn truncated_stl_is_refused() {
    let dir = scratch("stl");
    let (cell, _) = small_cell(&dir);
    let stl = std::fs::read(
        root()
            .join(FANUC)
            .join("fanuc_r2000ic_support/meshes/r2000ic125l/collision/link_1.stl"),
    )
    .unwrap();
    std::fs::write(dir.join("part.stl"), &stl[..stl.len() / 2]).unwrap();
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace("box = [600, 600, 600]", "mesh = \"part.stl\"\nmesh_units = \"m\""),
    )
    .unwrap();
    refused(&dir, &dir, "part.stl", None, "");
}

#[test]
fn missing_mesh_file_names_the_cell_line() {
    let dir = scratch("nomesh");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace("box = [600, 600, 600]", "mesh = \"nowhere.obj\""),
    )
    .unwrap();
    refused(&dir, &dir, "cell.toml", Some(28), "nowhere.obj");
}

#[test]
fn robot_that_reaches_nothing_is_refused_at_its_base() {
    let dir = scratch("far");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace("base = { xyz = [0, 0, 0] }", "base = { xyz = [-20000, 0, 0] }"),
    )
    .unwrap();
    refused(&dir, &dir, "cell.toml", Some(22), "can do none of the 3 tasks");
}

#[test]
fn non_orthonormal_tool_frame_is_refused() {
    let dir = scratch("tcp");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace(
            "tcp = { xyz = [0, 0, 300] }",
            "tcp = { xyz = [0, 0, 300], matrix = [[1, 0.2, 0], [0, 1, 0], [0, 0, 1]] }",
        ),
    )
    .unwrap();
    refused(&dir, &dir, "cell.toml", Some(11), "orthonormal");
}

#[test]
fn missing_cell_file_is_refused() {
    let dir = scratch("nofile");
    let out = cellplan(&["check", dir.join("nope.toml").to_str().unwrap()], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nope.toml"));
}

#[test]
fn unmeasurable_task_gives_exit_3_and_reasons() {
    let dir = scratch("unmeasurable");
    small_cell(&dir);
    // D lies inside the part, facing down: no probe pose around it is usable. E is far away.
    std::fs::write(
        dir.join("tasks.csv"),
        "id,x,y,z,nx,ny,nz\nA,1900,0,600,0,0,1\nD,1900,0,500,0,0,-1\nE,9000,0,600,0,0,1\n",
    )
    .unwrap();
    let cell = dir.join("cell.toml");
    let out = cellplan(&["check", cell.to_str().unwrap(), "--json"], &dir);
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let un = v["unmeasurable"].as_array().unwrap();
    let reason = |task: &str| {
        un.iter()
            .find(|u| u["task"] == task)
            .map(|u| u["reasons"][0]["reason"].as_str().unwrap().to_string())
    };
    assert_eq!(reason("E").as_deref(), Some("no-ik"));
    let d = reason("D").expect("D is unmeasurable");
    assert!(
        ["joint-limits", "collision", "beam-occluded"].contains(&d.as_str()),
        "D: {d}"
    );
    assert!(reason("A").is_none());
}

#[test]
fn gen_tasks_is_deterministic_and_valid() {
    let dir = scratch("gen");
    let out_a = dir.join("a.csv");
    let out_b = dir.join("b.csv");
    for out in [&out_a, &out_b] {
        let o = cellplan(
            &[
                "gen",
                "tasks",
                "--mesh",
                "data/parts/body-in-white/car5.obj",
                "--count",
                "12",
                "--seed",
                "5",
                "--region",
                "x=0..",
                "--facing",
                "+x",
                "--out",
                out.to_str().unwrap(),
            ],
            &dir,
        );
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let a = std::fs::read_to_string(&out_a).unwrap();
    assert_eq!(a, std::fs::read_to_string(&out_b).unwrap());
    let tasks = cellplan_model::tasks::parse_tasks(&out_a, &a, 1.0, 1.0, &[]).unwrap();
    assert_eq!(tasks.len(), 12);
    for t in &tasks {
        assert!(t.position.x >= 0.0);
        assert!(t.normal.x >= 0.5 - 1e-6, "{t:?}");
    }
}

#[test]
fn example_cells_check_clean() {
    let cache = scratch("examples");
    for (cell, robots, tasks) in [
        ("examples/autobody-4r/cell.toml", 4, 45),
        ("examples/autobody-2r/cell.toml", 2, 20),
    ] {
        let out = cellplan(&["check", cell, "--json"], &cache);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{cell}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["tasks"], tasks);
        assert_eq!(v["robots"].as_array().unwrap().len(), robots);
        assert!(
            v["unmeasurable"].as_array().unwrap().is_empty(),
            "{cell}: every MP measurable"
        );
        // Neighbouring robots share some MPs; every robot has some only it can do.
        let pairs = v["classes"]["pairs"].as_array().unwrap();
        for k in 0..robots - 1 {
            let (a, b) = (format!("R{}", k + 1), format!("R{}", k + 2));
            assert!(
                pairs
                    .iter()
                    .any(|p| p["robots"][0] == a.as_str() && p["robots"][1] == b.as_str()),
                "{cell}: {a} and {b} share no MP"
            );
        }
        for (name, only) in v["classes"]["exclusive"].as_object().unwrap() {
            assert!(
                !only.as_array().unwrap().is_empty(),
                "{cell}: {name} has no MP of its own"
            );
        }
    }
}

#[test]
fn json_is_the_same_whatever_the_thread_count() {
    let cache = scratch("threads");
    let run = |threads: &str| {
        let out = cellplan(
            &[
                "--threads",
                threads,
                "check",
                "examples/autobody-2r/cell.toml",
                "--json",
            ],
            &cache,
        );
        assert_eq!(out.status.code(), Some(0));
        out.stdout
    };
    assert_eq!(run("1"), run("2"));
}

#[test]
fn docs_show_the_example_cell_verbatim() {
    let r = root();
    let docs = std::fs::read_to_string(r.join("docs/cell-format.md")).unwrap();
    let cell = std::fs::read_to_string(r.join("examples/autobody-4r/cell.toml")).unwrap();
    assert!(
        docs.contains(cell.trim()),
        "docs/cell-format.md must carry examples/autobody-4r/cell.toml as it is"
    );
}

#[test]
fn ur5_cell_uses_the_numeric_ik() {
    let dir = scratch("ur5");
    let r = root();
    let cell = format!(
        r#"units = {{ length = "mm", angle = "deg" }}

[process]
kind = "optical-inspection"
standoff = 100
stripe_length = 30
baseline = 40
view_angle = 20

[process.sampling]
tilt_steps = 1
azimuth_steps = 4
spin_steps = 4

[tools.probe]
tcp = {{ xyz = [0, 0, 120] }}

[[tools.probe.shape]]
box = [60, 40, 110]
pose = {{ xyz = [10, 0, 60] }}

[[robots]]
name = "ur5"
urdf = "{r}/data/robots/ur5/urdf/ur5.urdf"
packages = {{ ur_description = "{r}/data/robots/ur5/ur_description" }}
base = {{ xyz = [0, 0, 0] }}
home = [0, -90, 90, -90, -90, 0]
tool = "probe"

[[objects]]
name = "part"
box = [200, 200, 200]
pose = {{ xyz = [450, 0, 100] }}

[tasks]
file = "tasks.csv"
"#,
        r = r.display()
    );
    std::fs::write(dir.join("cell.toml"), cell).unwrap();
    std::fs::write(
        dir.join("tasks.csv"),
        "id,x,y,z,nx,ny,nz\nT1,450,0,200,0,0,1\nT2,450,100,150,0,1,0\n",
    )
    .unwrap();
    let out = cellplan(
        &["check", dir.join("cell.toml").to_str().unwrap(), "--json"],
        &dir,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    for t in v["candidates"].as_array().unwrap() {
        assert!(t["robots"]["ur5"].as_u64().unwrap() > 0, "{t}");
    }
}

#[test]
fn home_in_collision_is_refused() {
    let dir = scratch("home-static");
    let (cell, _) = small_cell(&dir);
    // A block where the upper arm stands at home.
    let block =
        "[[objects]]\nname = \"block\"\nbox = [300, 300, 300]\npose = { xyz = [40, 0, 1150] }\n\n[tasks]";
    std::fs::write(dir.join("cell.toml"), cell.replace("[tasks]", block)).unwrap();
    refused(
        &dir,
        &dir,
        "cell.toml",
        Some(23),
        "collides at its home configuration",
    );
}

#[test]
fn robots_colliding_at_home_are_refused() {
    let dir = scratch("home-pair");
    let (cell, _) = small_cell(&dir);
    let start = cell.find("[[robots]]").unwrap();
    let end = cell.find("[[objects]]").unwrap();
    let second = cell[start..end]
        .replace("name = \"R1\"", "name = \"R2\"")
        .replace("xyz = [0, 0, 0]", "xyz = [0, 300, 0]");
    std::fs::write(
        dir.join("cell.toml"),
        format!("{}{second}{}", &cell[..end], &cell[end..]),
    )
    .unwrap();
    refused(
        &dir,
        &dir,
        "cell.toml",
        Some(31),
        "robots `R2` and `R1` collide at home",
    );
}

#[test]
fn beam_blocked_by_a_fixture_is_the_reason() {
    let dir = scratch("beam");
    let (cell, _) = small_cell(&dir);
    // A small plate 100 mm above A: the probe (250 mm up) clears it, the beams do not.
    let plate =
        "[[objects]]\nname = \"plate\"\nbox = [100, 100, 4]\npose = { xyz = [1900, 0, 700] }\n\n[tasks]";
    std::fs::write(dir.join("cell.toml"), cell.replace("[tasks]", plate)).unwrap();
    let out = cellplan(
        &["check", dir.join("cell.toml").to_str().unwrap(), "--json"],
        &dir,
    );
    assert_eq!(
        out.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let un = v["unmeasurable"].as_array().unwrap();
    assert_eq!(un.len(), 1, "{un:?}");
    assert_eq!(un[0]["task"], "A");
    assert_eq!(un[0]["reasons"][0]["reason"], "beam-occluded");
}

#[test]
fn task_tolerance_widens_the_poses() {
    let dir = scratch("tolerance");
    small_cell(&dir);
    let count = |csv: &str| {
        std::fs::write(dir.join("tasks.csv"), csv).unwrap();
        let out = cellplan(
            &["check", dir.join("cell.toml").to_str().unwrap(), "--json"],
            &dir,
        );
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        v["candidates"][0]["robots"]["R1"].as_u64().unwrap()
    };
    let default = count("id,x,y,z,nx,ny,nz\nA,1900,0,600,0,0,1\n");
    let narrow = count("id,x,y,z,nx,ny,nz,tolerance\nA,1900,0,600,0,0,1,1\n");
    let wide = count("id,x,y,z,nx,ny,nz,tolerance\nA,1900,0,600,0,0,1,40\n");
    // The same number of poses is sampled, spread over a wider or narrower cone.
    assert!(narrow > 0 && default > 0 && wide > 0);
    assert_ne!(narrow, wide, "the tolerance must change the poses tried");
}

#[test]
fn svg_draws_every_task() {
    let dir = scratch("svg");
    small_cell(&dir);
    let svg = dir.join("cell.svg");
    let out = cellplan(
        &[
            "check",
            dir.join("cell.toml").to_str().unwrap(),
            "--svg",
            svg.to_str().unwrap(),
        ],
        &dir,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.trim_end().ends_with("</svg>"));
    for t in ["A", "B", "C"] {
        // Once per view.
        assert_eq!(
            text.matches(&format!("<title>{t}</title>")).count(),
            2,
            "task {t}"
        );
    }
    assert!(text.contains("<title>R1</title>") && text.contains("<title>part</title>"));
}

#[test]
fn robot_without_joints_is_refused() {
    let dir = scratch("nojoints");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("stick.urdf"),
        "<robot name=\"stick\"><link name=\"base_link\"><collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision></link></robot>\n",
    )
    .unwrap();
    let urdf_line = cell.lines().find(|l| l.starts_with("urdf =")).unwrap();
    let opw_line = cell.lines().find(|l| l.starts_with("opw =")).unwrap();
    let home_line = cell.lines().find(|l| l.starts_with("home =")).unwrap();
    let cell = cell
        .replace(urdf_line, "urdf = \"stick.urdf\"")
        .replace(opw_line, "")
        .replace(home_line, "");
    std::fs::write(dir.join("cell.toml"), cell).unwrap();
    refused(&dir, &dir, "cell.toml", Some(19), "has no movable joint");
}

#[test]
fn example_task_lists_are_what_their_cell_files_say() {
    let dir = scratch("regen");
    for (name, count) in [("autobody-4r", "45"), ("autobody-2r", "20")] {
        let out = dir.join(format!("{name}.csv"));
        let o = cellplan(
            &[
                "gen",
                "tasks",
                "--mesh",
                "data/parts/body-in-white/car5.obj",
                "--count",
                count,
                "--seed",
                "2",
                "--region",
                "x=0..",
                "--facing",
                "+x",
                "--max-angle",
                "80",
                "--translate",
                "0,-2212,400",
                "-o",
                out.to_str().unwrap(),
            ],
            &dir,
        );
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let committed = std::fs::read_to_string(root().join(format!("examples/{name}/tasks.csv"))).unwrap();
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            committed,
            "{name}: regenerate with the command in its cell.toml"
        );
    }
}

#[test]
fn bench_reports_costs_against_known_optima() {
    let dir = scratch("bench");
    let out = cellplan(
        &[
            "bench",
            "setcover",
            "data/benchmarks/orlib-setcover/scp41.txt",
            "--json",
        ],
        &dir,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let row = &v[0];
    assert_eq!(row["instance"], "scp41");
    assert_eq!(row["cost"], 429.0);
    assert_eq!(row["optimum"], 429.0);
    assert_eq!(row["gap_percent"], 0.0);
    assert_eq!(row["proven_optimal"], true);
    for key in ["mean_cost", "time_s"] {
        assert!(row[key].is_number(), "{key}");
    }
    let out = cellplan(
        &[
            "bench",
            "tsp",
            "data/benchmarks/tsplib/burma14.tsp",
            "--method",
            "exact",
            "--json",
        ],
        &dir,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v[0]["cost"], 3323.0, "Held-Karp proves burma14");
}

#[test]
fn bench_refuses_a_malformed_instance() {
    let dir = scratch("bench-bad");
    let bad = dir.join("bad.tsp");
    std::fs::write(&bad, "NAME: bad\nTYPE: TSP\nDIMENSION: 3\nEDGE_WEIGHT_TYPE: EUC_2D\nNODE_COORD_SECTION\n1 0 0\n2 x 1\n3 1 1\nEOF\n").unwrap();
    let out = cellplan(&["bench", "tsp", bad.to_str().unwrap()], &dir);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.tsp:7"), "{stderr}");
    assert!(stderr.contains("help:"), "{stderr}");
}

#[test]
fn bench_minmax_generates_then_benchmarks() {
    let dir = scratch("bench-minmax");
    let file = dir.join("mm.txt");
    let out = cellplan(
        &[
            "bench",
            "minmax",
            "--generate",
            "--vehicles",
            "3",
            "--tasks",
            "12",
            "--alternatives",
            "2..3",
            "--seed",
            "5",
            "-o",
            file.to_str().unwrap(),
        ],
        &dir,
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(
        text.starts_with("NAME: mm\nTYPE: MINMAX\nVEHICLES: 3\nTASKS: 12\n"),
        "{text}"
    );
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "no temporary file is left behind: {left:?}");

    let bench = |file: &Path, extra: &[&str]| {
        let mut args = vec![
            "bench",
            "minmax",
            file.to_str().unwrap(),
            "--json",
            "--time-limit",
            "0.2",
        ];
        args.extend_from_slice(extra);
        let out = cellplan(&args, &dir);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: Value = serde_json::from_slice(&out.stdout).unwrap();
        v[0].clone()
    };
    let row = bench(&file, &["--runs", "2"]);
    assert_eq!(row["instance"], "mm");
    assert_eq!(row["method"], "ils");
    assert_eq!(row["vehicles"], 3);
    assert_eq!(row["tasks"], 12);
    assert_eq!(row["runs"], 2);
    assert!(row["optimum"].is_null() && row["gap_percent"].is_null(), "{row}");
    let cost = row["cost"].as_f64().unwrap();
    assert!(cost > 0.0 && row["total"].as_f64().unwrap() >= cost, "{row}");
    assert!(row["mean_cost"].as_f64().unwrap() >= cost, "{row}");
    assert!(row["time_s"].is_number());
    for m in ["algorithm1", "proximity"] {
        let r = bench(&file, &["--method", m]);
        assert_eq!(r["method"], m);
        assert!(r["cost"].as_f64().unwrap() >= cost - 1e-9, "{m} beats ils: {r}");
    }

    // A BEST_KNOWN line becomes the optimum and the gap.
    let known = dir.join("known.txt");
    std::fs::write(
        &known,
        text.replacen(
            "TASKS: 12\n",
            &format!("TASKS: 12\nBEST_KNOWN: {}\n", cost / 2.0),
            1,
        ),
    )
    .unwrap();
    let row = bench(&known, &[]);
    assert_eq!(row["optimum"].as_f64(), Some(cost / 2.0));
    assert!(row["gap_percent"].as_f64().unwrap() > 0.0, "{row}");

    // Methods of the other kinds are refused.
    let out = cellplan(
        &["bench", "minmax", file.to_str().unwrap(), "--method", "exact"],
        &dir,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not for minmax"));
}

#[test]
fn bench_minmax_refuses_a_malformed_instance() {
    let dir = scratch("bench-minmax-bad");
    let bad = dir.join("bad.txt");
    let text = "NAME: bad\nVEHICLES: 1\nTASKS: 1\nSERVICE_SECTION\n0.5\nVEHICLE: 0\nDEPOT: 0\nCAP: 1\nNODES: 2\nFULL_MATRIX\n0 1\n1\nALTERNATIVES\n0: 1\n";
    std::fs::write(&bad, text).unwrap();
    let out = cellplan(&["bench", "minmax", bad.to_str().unwrap()], &dir);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.txt:12"), "{stderr}");
    assert!(stderr.contains("help:"), "{stderr}");
    // The same file with the row fixed but the task out of its vehicle's range.
    std::fs::write(
        &bad,
        text.replace("\n1\nALT", "\n1 0\nALT").replace("0: 1", "0: 2"),
    )
    .unwrap();
    let out = cellplan(&["bench", "minmax", bad.to_str().unwrap()], &dir);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.txt:14"), "{stderr}");
    assert!(stderr.contains("out of range"), "{stderr}");
}

/// Plans the small cell in a fresh scratch folder `name` with `--json`: the folder, the cell
/// file, the output folder and the printed summary.
fn plan_small_cell(name: &str) -> (PathBuf, PathBuf, PathBuf, Value) {
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

#[test]
fn plan_writes_a_plan_and_a_stable_summary() {
    let (dir, cell, out_dir, summary) = plan_small_cell("plan");
    for key in [
        "cycle_time_s",
        "delta_t_s",
        "lower_bound_s",
        "robots",
        "unmeasured",
        "compute_s",
    ] {
        assert!(summary.get(key).is_some(), "summary lacks {key}");
    }
    let robots = summary["robots"].as_array().unwrap();
    assert_eq!(robots.len(), 1);
    assert_eq!(robots[0]["name"], "R1");
    assert_eq!(robots[0]["tasks"], 3);
    let cycle = summary["cycle_time_s"].as_f64().unwrap();
    assert!(cycle >= summary["lower_bound_s"].as_f64().unwrap() - 1e-9);
    assert!((robots[0]["total_s"].as_f64().unwrap() - cycle).abs() < 1e-9);
    // Three measurements at the default 1.5 s, plus motion.
    assert!(cycle > 4.5);
    let plan: Value = serde_json::from_slice(&std::fs::read(out_dir.join("plan.json")).unwrap()).unwrap();
    assert_eq!(plan["format"], "cellplan-plan");
    assert_eq!(plan["version"], 2);
    assert_eq!(plan["robots"][0]["tasks"].as_array().unwrap().len(), 3);
    assert_eq!(plan["robots"][0]["legs"].as_array().unwrap().len(), 4);
    // The same seed gives the same plan, whatever the thread count.
    let again = dir.join("again");
    let out = cellplan(
        &[
            "--threads",
            "1",
            "plan",
            cell.to_str().unwrap(),
            "-o",
            again.to_str().unwrap(),
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success());
    let second: Value = serde_json::from_slice(&std::fs::read(again.join("plan.json")).unwrap()).unwrap();
    assert_eq!(plan["robots"], second["robots"]);
    // The verifier accepts it (one robot: nothing to coordinate) ...
    let plan_file = out_dir.join("plan.json");
    let out = cellplan(
        &[
            "verify",
            plan_file.to_str().unwrap(),
            cell.to_str().unwrap(),
            "--json",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stdout));
    let verdict: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(verdict["ok"], true);
    assert!(verdict["violations"].as_array().unwrap().is_empty());
    // ... and rejects it with an MP removed and the cycle time fudged (exit 4, both named).
    let mut broken = plan.clone();
    broken["robots"][0]["tasks"].as_array_mut().unwrap().remove(0);
    broken["cycle_time_s"] = Value::from(1.0);
    let bad = dir.join("broken.json");
    std::fs::write(&bad, serde_json::to_string(&broken).unwrap()).unwrap();
    let out = cellplan(
        &["verify", bad.to_str().unwrap(), cell.to_str().unwrap(), "--json"],
        &dir,
    );
    assert_eq!(out.status.code(), Some(4));
    let verdict: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(verdict["ok"], false);
    let kinds: Vec<&str> = verdict["violations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["kind"].as_str().unwrap())
        .collect();
    assert!(
        kinds.contains(&"missing-task") && kinds.contains(&"totals"),
        "{kinds:?}"
    );
    // Not a plan: exit 2 naming the file and line.
    std::fs::write(&bad, "{\n  \"format\": 3\n").unwrap();
    let out = cellplan(&["verify", bad.to_str().unwrap(), cell.to_str().unwrap()], &dir);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("broken.json") && err.contains("help:"), "{err}");
}

#[test]
fn plan_refuses_caps_that_cannot_hold_the_tasks() {
    let dir = scratch("plan-cap");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace("baseline = 100", "baseline = 100\ntask_cap = 2"),
    )
    .unwrap();
    let out_dir = dir.join("out");
    let out = cellplan(
        &[
            "plan",
            dir.join("cell.toml").to_str().unwrap(),
            "-o",
            out_dir.to_str().unwrap(),
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cell.toml") && err.contains("task_cap"), "{err}");
    assert!(!out_dir.join("plan.json").exists());
}

#[test]
fn plan_writes_a_report_and_export_writes_gltf_and_csv() {
    let (dir, cell, out_dir, summary) = plan_small_cell("report");
    let report = out_dir.join("report.html");
    assert_eq!(summary["report_file"], report.display().to_string());
    let page = std::fs::read_to_string(&report).unwrap();
    assert!(page.starts_with("<!DOCTYPE html>") && page.ends_with("</html>"));
    for id in ["gantt", "timepos-after", "view", "cellplan-data"] {
        assert!(page.contains(&format!("id=\"{id}\"")), "no #{id}");
    }
    // Self-contained: nothing fetched from elsewhere.
    assert!(!page.contains("src=\"http") && !page.contains("href=\"http"));
    let plan = out_dir.join("plan.json");

    // `report` again, elsewhere, with the cell named.
    let other = dir.join("again/page.html");
    let out = cellplan(
        &[
            "report",
            plan.to_str().unwrap(),
            cell.to_str().unwrap(),
            "-o",
            other.to_str().unwrap(),
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("report written to"));
    assert!(std::fs::read_to_string(&other).unwrap().contains("id=\"gantt\""));

    // Exports.
    let glb = dir.join("cell.glb");
    let csv_dir = dir.join("csv");
    let out = cellplan(
        &[
            "export",
            plan.to_str().unwrap(),
            cell.to_str().unwrap(),
            "--gltf",
            glb.to_str().unwrap(),
            "--csv",
            csv_dir.to_str().unwrap(),
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&glb).unwrap();
    assert_eq!(&bytes[..4], b"glTF");
    let traj = std::fs::read_to_string(csv_dir.join("R1-trajectory.csv")).unwrap();
    assert!(traj.starts_with("t_s,joint_1,"), "{}", &traj[..60]);
    let prog = std::fs::read_to_string(csv_dir.join("R1-program.csv")).unwrap();
    assert_eq!(prog.lines().filter(|l| l.contains(",measure,")).count(), 3);

    // Nothing asked: refused.
    let out = cellplan(&["export", plan.to_str().unwrap(), cell.to_str().unwrap()], &dir);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--gltf"));
    // Not a plan: exit 2 naming the file and line; nothing written.
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\n  \"format\": [\n").unwrap();
    let target = dir.join("bad.html");
    let out = cellplan(
        &[
            "report",
            bad.to_str().unwrap(),
            cell.to_str().unwrap(),
            "-o",
            target.to_str().unwrap(),
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.json") && err.contains("help:"), "{err}");
    assert!(!target.exists());
    // A plan for other robots: exit 2 naming the robot.
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&plan).unwrap()).unwrap();
    doc["robots"][0]["name"] = Value::from("R7");
    std::fs::write(&bad, serde_json::to_string(&doc).unwrap()).unwrap();
    let out = cellplan(
        &[
            "report",
            bad.to_str().unwrap(),
            cell.to_str().unwrap(),
            "-o",
            target.to_str().unwrap(),
            "--no-verify",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("R7"));
    assert!(!target.exists());
}

#[test]
fn compare_writes_its_table_and_bar_chart_as_html() {
    let dir = scratch("compare");
    small_cell(&dir);
    let cell = dir.join("cell.toml");
    let out_dir = dir.join("cmp");
    let out = cellplan(
        &[
            "compare",
            cell.to_str().unwrap(),
            "-o",
            out_dir.to_str().unwrap(),
            "--json",
            "-q",
        ],
        &dir,
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = report["strategies"].as_array().unwrap();
    let solved = rows.iter().filter(|r| r["error"].is_null()).count();
    assert!(solved > 0);
    let page = std::fs::read_to_string(out_dir.join("compare.html")).unwrap();
    assert!(page.contains("id=\"strategy-bars\"") && page.contains("id=\"strategies\""));
    // A bar per robot of every solved strategy (one robot here), a table row per strategy.
    assert_eq!(page.matches("class=\"bar\"").count(), solved);
    assert_eq!(page.matches("<tr><td").count(), rows.len());
    assert!(page.contains("<b>balanced+proximity + best</b>"));
}

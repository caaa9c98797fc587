//! Bad input of every kind, table-driven: each case builds its input in a scratch folder, runs
//! one command, and expects exit 2, words naming what is wrong, and nothing written.
use super::*;
use std::path::Path;

struct Case {
    name: &'static str,
    /// Writes the inputs into the folder; returns the command's arguments.
    setup: fn(&Path) -> Vec<String>,
    /// Words the error must contain.
    says: &'static [&'static str],
}

/// The small cell with `edit` applied to its text, written as `cell.toml` with its tasks.
fn cell_with(dir: &Path, edit: impl Fn(String) -> String) -> String {
    let (cell, tasks) = small_cell(dir);
    std::fs::write(dir.join("cell.toml"), edit(cell)).unwrap();
    std::fs::write(dir.join("tasks.csv"), tasks).unwrap();
    dir.join("cell.toml").display().to_string()
}

/// The small cell's text with `line` added to its robot (after its `home`).
fn with_robot_line(cell: String, line: &str) -> String {
    let home = "home = [0, -30, 0, 0, -60, 0]";
    cell.replace(home, &format!("{home}\n{line}"))
}

fn check_args(cell: String) -> Vec<String> {
    vec!["check".into(), cell]
}

fn plan_args(cell: String, dir: &Path) -> Vec<String> {
    vec![
        "plan".into(),
        cell,
        "-o".into(),
        dir.join("out").display().to_string(),
        "--quiet".into(),
    ]
}

/// The six-component PCB example with `edit` applied to its cell text (and the board CSV as
/// `board(...)` gives it), written into `dir`.
fn pcb_with(dir: &Path, edit: impl Fn(String) -> String, board: impl Fn(String) -> String) -> String {
    let ex = root().join("examples/pcb-paper-6");
    let cell = std::fs::read_to_string(ex.join("cell.toml")).unwrap();
    let csv = std::fs::read_to_string(ex.join("board.csv")).unwrap();
    std::fs::write(dir.join("cell.toml"), edit(cell)).unwrap();
    std::fs::write(dir.join("board.csv"), board(csv)).unwrap();
    dir.join("cell.toml").display().to_string()
}

/// The single-robot version of the PCB example (its second robot's entry cut).
fn one_robot(c: String) -> String {
    let at = c.find("[[robots]]\nname = \"R2\"").unwrap();
    let end = c[at..].find("[[feeders]]").unwrap() + at;
    format!("{}{}", &c[..at], &c[end..])
}

/// The CMM example's cell with `edit` applied, and its task file as `tasks(...)` gives it,
/// written into `dir` (the part and the tasks read from the repository's data).
fn cmm_with(dir: &Path, edit: impl Fn(String) -> String, tasks: impl Fn(String) -> String) -> String {
    let ex = root().join("examples/cmm-block/cell.toml");
    let data = root().join("data/parts/cmm-block");
    let cell = std::fs::read_to_string(ex)
        .unwrap()
        .replace("../../data/parts/cmm-block/tasks.csv", "tasks.csv")
        .replace(
            "../../data/parts/cmm-block/block.obj",
            &data.join("block.obj").display().to_string(),
        );
    let csv = std::fs::read_to_string(data.join("tasks.csv")).unwrap();
    std::fs::write(dir.join("cell.toml"), edit(cell)).unwrap();
    std::fs::write(dir.join("tasks.csv"), tasks(csv)).unwrap();
    dir.join("cell.toml").display().to_string()
}

/// The stud-weld example's cell with `edit` applied, written into `dir` (its robot and studs
/// read from the repository).
fn studweld_with(dir: &Path, edit: impl Fn(String) -> String) -> String {
    let r = root().display().to_string();
    let cell = std::fs::read_to_string(root().join("examples/studweld-kr210/cell.toml"))
        .unwrap()
        .replace("../../", &format!("{r}/"))
        .replace(
            "\"studs.csv\"",
            &format!("\"{r}/examples/studweld-kr210/studs.csv\""),
        );
    std::fs::write(dir.join("cell.toml"), edit(cell)).unwrap();
    dir.join("cell.toml").display().to_string()
}

/// A CMM plan of the example written into `dir/out`, for the reuse cases.
fn cmm_plan(dir: &Path) -> String {
    let out = dir.join("planned");
    let o = out.display().to_string();
    run_ok(
        &["plan", "examples/cmm-block/cell.toml", "-o", &o, "--quiet"],
        &dir.join("cache"),
    );
    out.join("plan.json").display().to_string()
}

const CASES: &[Case] = &[
    Case {
        name: "cmm: a cone half-angle of 0",
        setup: |d| {
            plan_args(
                cmm_with(d, |c| c, |t| t.replacen(",surface,20,deck", ",surface,0,deck", 1)),
                d,
            )
        },
        says: &["tasks.csv:2", "θ = 0° must lie strictly between 0° and 90°"],
    },
    Case {
        name: "cmm: a cone half-angle of 90°",
        setup: |d| {
            plan_args(
                cmm_with(d, |c| c, |t| t.replacen(",hole,80,bores", ",hole,90,bores", 1)),
                d,
            )
        },
        says: &["tasks.csv:", "θ = 90°"],
    },
    Case {
        name: "cmm: an MP outside the machine's range",
        setup: |d| {
            plan_args(
                cmm_with(
                    d,
                    |c| c,
                    |t| t.replacen("D1,20.0000,60.0000", "D1,2000.0000,60.0000", 1),
                ),
                d,
            )
        },
        says: &["tasks.csv:2", "MP D1", "outside the machine's range"],
    },
    Case {
        name: "cmm: a stylus longer than the Z travel",
        setup: |d| plan_args(cmm_with(d, |c| c.replace("l2 = 150", "l2 = 900"), |t| t), d),
        says: &["cell.toml:", "Z travel", "shorter stylus"],
    },
    Case {
        name: "cmm: a head range beyond ±180°",
        setup: |d| {
            plan_args(
                cmm_with(d, |c| c.replace("a = [0, 105]", "a = [0, 1050]"), |t| t),
                d,
            )
        },
        says: &["cell.toml:", "`a` = [0, 1050]"],
    },
    Case {
        name: "cmm: an adjacency naming an unknown face",
        setup: |d| {
            plan_args(
                cmm_with(
                    d,
                    |c| c.replace("[\"deck\", \"bores\"]", "[\"deck\", \"roof\"]"),
                    |t| t,
                ),
                d,
            )
        },
        says: &["cell.toml:", "face `roof`"],
    },
    Case {
        name: "cmm: a reuse naming an unknown MP",
        setup: |d| {
            let plan = cmm_plan(d);
            std::fs::write(d.join("subset.txt"), "D1\nS2\nQ9\n").unwrap();
            vec![
                "reuse".into(),
                plan,
                "--tasks".into(),
                format!("@{}", d.join("subset.txt").display()),
                "-o".into(),
                d.join("out").display().to_string(),
            ]
        },
        says: &["subset.txt:3", "`Q9` is not an MP of the cell"],
    },
    Case {
        name: "cmm: a reuse naming an MP the plan never measured",
        setup: |d| {
            let plan = cmm_plan(d);
            // The plan, its group of D1 cut down so that D1 is reported unmeasured.
            let text = std::fs::read_to_string(&plan).unwrap();
            let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
            for g in doc["groups"].as_array_mut().unwrap() {
                let mps = g["mps"].as_array().unwrap().clone();
                if let Some(k) = mps.iter().position(|m| m == "D1") {
                    for key in ["mps", "roots", "local"] {
                        g[key].as_array_mut().unwrap().remove(k);
                    }
                }
            }
            doc["unmeasured"] = serde_json::json!([{"id": "D1", "reason": "cut by the test"}]);
            std::fs::write(&plan, doc.to_string()).unwrap();
            vec![
                "reuse".into(),
                plan,
                "--tasks".into(),
                "S2,D1".into(),
                "-o".into(),
                d.join("out").display().to_string(),
            ]
        },
        says: &["--tasks", "never measured MP `D1`", "cut by the test"],
    },
    Case {
        name: "pcb: a board file that is not KiCad",
        setup: |d| plan_args(pcb_with(d, |c| c, |_| "hello, world\n".into()), d),
        says: &["board.csv:1", "not a KiCad board"],
    },
    Case {
        name: "pcb: a footprint without position",
        setup: |d| {
            let cell = pcb_with(d, |c| c.replace("board.csv", "board.kicad_pcb"), |b| b);
            std::fs::write(
                d.join("board.kicad_pcb"),
                "(kicad_pcb (version 20240108)\n  (footprint \"R_0805\" (layer \"F.Cu\")\n    (property \"Reference\" \"R1\") (attr smd)))\n",
            )
            .unwrap();
            plan_args(cell, d)
        },
        says: &["board.kicad_pcb:2", "no position"],
    },
    Case {
        name: "pcb: a component type with no bin",
        setup: |d| {
            plan_args(
                pcb_with(
                    d,
                    |c| {
                        c + "\n[[process.bins]]\nfeeder = \"CDS1\"\nbin = 0\nfootprint = \"R_0805\"\nvalue = \"10k\"\n"
                    },
                    |b| b,
                ),
                d,
            )
        },
        says: &["board.csv:", "has no bin", "[[process.bins]]"],
    },
    Case {
        name: "pcb: a board larger than the table's reach",
        setup: |d| {
            plan_args(
                pcb_with(
                    d,
                    |c| {
                        c.replace(
                            "x = [-20, 60]           # the board",
                            "x = [300, 320]           # the board",
                        )
                        .replace("home = [20, 0]", "home = [310, 0]")
                    },
                    |b| b,
                ),
                d,
            )
        },
        says: &["cell.toml:", "larger than the table's reach"],
    },
    Case {
        name: "pcb: a robot speed of zero",
        setup: |d| {
            plan_args(
                pcb_with(
                    d,
                    |c| c.replace("name = \"R1\"", "name = \"R1\"\nspeed = 0"),
                    |b| b,
                ),
                d,
            )
        },
        says: &["cell.toml:", "speed 0 must be above 0"],
    },
    Case {
        name: "pcb: one robot and a two-robot option",
        setup: |d| plan_args(pcb_with(d, one_robot, |b| b), d),
        says: &["cell.toml:", "`safety_gap` is a two-robot option"],
    },
    Case {
        name: "absurd pose sampling",
        setup: |d| {
            check_args(cell_with(d, |c| {
                c + "\n[process.sampling]\nspin_steps = 100000000\n"
            }))
        },
        says: &["cell.toml:", "spin_steps", "probe poses per MP"],
    },
    Case {
        name: "a shared limit left in [process]",
        setup: |d| {
            check_args(cell_with(d, |c| {
                c.replace("baseline = 100", "baseline = 100\ntask_cap = 2")
            }))
        },
        says: &["cell.toml:", "task_cap", "[planning]"],
    },
    Case {
        name: "a plan and its cell given the other way round",
        setup: |d| {
            let cell = cell_with(d, |c| c);
            std::fs::write(d.join("plan.json"), "{\n  \"format\": \"cellplan-plan\"\n}\n").unwrap();
            vec!["verify".into(), cell, d.join("plan.json").display().to_string()]
        },
        says: &[
            "plan.json:1",
            "invalid cell file",
            "is it a plan?",
            "the plan first",
        ],
    },
    Case {
        name: "task cap of zero",
        setup: |d| check_args(cell_with(d, |c| c + "\n[planning]\ntask_cap = 0\n")),
        says: &["cell.toml:", "`task_cap` must be between 1"],
    },
    Case {
        name: "a balance limit beyond a day, refused at its line (it once went through planning to a plan its own check refused)",
        setup: |d| plan_args(cell_with(d, |c| c + "\n[planning]\nbalance_limit = 1e300\n"), d),
        says: &[
            "cell.toml:",
            "`balance_limit` of 1e300 s is beyond 86400 s",
            "leave `balance_limit` out",
        ],
    },
    Case {
        name: "a base far beyond any cell, with its size in short",
        setup: |d| {
            check_args(cell_with(d, |c| {
                c.replace("base = { xyz = [0, 0, 0] }", "base = { xyz = [1e300, 0, 0] }")
            }))
        },
        says: &[
            "cell.toml:",
            "lies 1e297 m from its frame's origin, beyond 10000 m",
        ],
    },
    Case {
        name: "a base turned beyond 100 turns",
        setup: |d| {
            check_args(cell_with(d, |c| {
                c.replace(
                    "base = { xyz = [0, 0, 0] }",
                    "base = { xyz = [0, 0, 0], rpy = [0, 0, 1e300] }",
                )
            }))
        },
        says: &["cell.toml:", "`rpy` angle 1e300 is beyond 100 turns"],
    },
    Case {
        name: "an object larger than any cell",
        setup: |d| {
            check_args(cell_with(d, |c| {
                c.replace("box = [600, 600, 600]", "box = [600, 6e9, 600]")
            }))
        },
        says: &["cell.toml:", "`box` of 6000000 m is beyond 10000 m"],
    },
    Case {
        name: "a joint speed beyond any robot's, given in the cell",
        setup: |d| {
            check_args(cell_with(d, |c| {
                with_robot_line(c, "max_velocity = [100, 100, 100, 100, 100, 1e9]")
            }))
        },
        says: &[
            "cell.toml:",
            "`max_velocity` of joint `joint_6`, 1e9, is 1.745e7 rad/s: beyond 100 rad/s",
        ],
    },
    Case {
        name: "a joint acceleration beyond any robot's, given in the cell",
        setup: |d| {
            check_args(cell_with(d, |c| {
                with_robot_line(c, "max_acceleration = [1e7, 100, 100, 100, 100, 100]")
            }))
        },
        says: &[
            "cell.toml:",
            "`max_acceleration` of joint `joint_1`, 10000000, is 1.745e5 rad/s²: beyond 10000 rad/s²",
        ],
    },
    Case {
        name: "a URDF velocity limit beyond any robot's (the timeline's samples would mean nothing)",
        setup: |d| {
            let urdf = root().join("data/robots/fanuc_r2000ic/urdf/r2000ic125l.urdf");
            let text = std::fs::read_to_string(urdf).unwrap();
            let at = text.find("velocity=\"").unwrap() + "velocity=\"".len();
            let end = text[at..].find('"').unwrap() + at;
            std::fs::write(
                d.join("fast.urdf"),
                format!("{}1e300{}", &text[..at], &text[end..]),
            )
            .unwrap();
            let fast = d.join("fast.urdf").display().to_string();
            check_args(cell_with(d, |c| {
                let from = c.find("urdf = \"").unwrap();
                let to = c[from..].find('\n').unwrap() + from;
                format!("{}urdf = \"{fast}\"{}", &c[..from], &c[to..])
            }))
        },
        says: &[
            "cell.toml:",
            "joint `joint_1` has a velocity limit of 1e300 rad/s in the URDF, beyond 100 rad/s",
            "<limit velocity>",
        ],
    },
    Case {
        name: "a stud-weld time beyond an hour (1e300 s ran without end)",
        setup: |d| {
            check_args(studweld_with(d, |c| {
                c.replace("weld_time = 2.0 ", "weld_time = 1e300 ")
            }))
        },
        says: &["cell.toml:9", "`weld_time` of 1e300 s is beyond 3600 s"],
    },
    Case {
        name: "a torque limit per joint short of the robot's joints, at its line",
        setup: |d| {
            plan_args(
                studweld_with(d, |c| c.replace("max_torque = [20000, ", "max_torque = [")),
                d,
            )
        },
        says: &[
            "cell.toml:14",
            "`max_torque` gives 5 values, robot `KR210` has 6 joints",
        ],
    },
    Case {
        name: "a pool of a hundred thousand threads (it took minutes to start)",
        setup: |d| {
            let cell = cell_with(d, |c| c);
            vec!["--threads".into(), "100000".into(), "check".into(), cell]
        },
        says: &["--threads", "100000 is not in 1..=1024"],
    },
    Case {
        name: "a report written onto a folder, refused before any work (it exited 1 after it)",
        setup: |d| {
            let plan = d.join("plan.json").display().to_string();
            vec!["report".into(), plan, "-o".into(), d.display().to_string()]
        },
        says: &["is a folder; give a file path with -o"],
    },
    Case {
        name: "an export whose CSV folder is a file: the glTF is not written either",
        setup: |d| {
            std::fs::write(d.join("taken"), "x").unwrap();
            vec![
                "export".into(),
                d.join("plan.json").display().to_string(),
                "--gltf".into(),
                d.join("plan.glb").display().to_string(),
                "--csv".into(),
                d.join("taken").display().to_string(),
            ]
        },
        says: &["taken is a file, not a folder; give a writable folder with --csv"],
    },
    Case {
        name: "generated tasks moved beyond any cell (they were written, for the cell to refuse)",
        setup: |d| {
            let mesh = root()
                .join("data/parts/body-in-white/car5.obj")
                .display()
                .to_string();
            let out = d.join("tasks.csv").display().to_string();
            [
                "gen",
                "tasks",
                "--mesh",
                &mesh,
                "--count",
                "3",
                "--translate",
                "1e300,0,0",
                "-o",
                &out,
            ]
            .map(String::from)
            .to_vec()
        },
        says: &["--translate 1e300,0,0 is beyond 10000000"],
    },
    Case {
        name: "an empty region for generated tasks, named as such",
        setup: |d| {
            let mesh = root()
                .join("data/parts/body-in-white/car5.obj")
                .display()
                .to_string();
            let out = d.join("tasks.csv").display().to_string();
            [
                "gen", "tasks", "--mesh", &mesh, "--count", "3", "--region", "x=5..1", "-o", &out,
            ]
            .map(String::from)
            .to_vec()
        },
        says: &["the range `5..1` is empty"],
    },
    Case {
        name: "an export of a missing plan makes no CSV folder",
        setup: |d| {
            vec![
                "export".into(),
                d.join("missing.json").display().to_string(),
                "--csv".into(),
                d.join("new/csv").display().to_string(),
            ]
        },
        says: &["missing.json"],
    },
    Case {
        name: "an absurd clearance, with its size in short",
        setup: |d| check_args(cell_with(d, |c| c + "\n[planning]\nclearance = 1e300\n")),
        says: &["cell.toml:", "`clearance` of 1e297 m is beyond 1 m"],
    },
    Case {
        name: "caps that cannot hold the tasks, in check as in plan",
        setup: |d| check_args(cell_with(d, |c| c + "\n[planning]\ntask_cap = 1\n")),
        says: &["cell.toml", "task_cap = 1", "no robot with room"],
    },
    Case {
        name: "endless task file",
        setup: |d| {
            check_args(cell_with(d, |c| {
                c.replace("file = \"tasks.csv\"", "file = \"/dev/zero\"")
            }))
        },
        says: &["/dev/zero", "larger than 256 MiB"],
    },
    Case {
        name: "a task column named twice",
        setup: |d| {
            let cell = cell_with(d, |c| c);
            std::fs::write(d.join("tasks.csv"), "id,x,y,z,nx,ny,nz,y\nA,1900,0,600,0,0,1,0\n").unwrap();
            check_args(cell)
        },
        says: &["tasks.csv:1", "column `y` is named twice"],
    },
    Case {
        name: "a cell name that leads outside the output folder",
        setup: |d| {
            let cell = cell_with(d, |c| c.replace("name = \"small\"", "name = \"../../../x\""));
            vec!["plan".into(), cell, "--quiet".into()]
        },
        says: &["`../../../x` is not a plain folder name", "-o"],
    },
    Case {
        name: "an output folder that cannot be written",
        setup: |d| {
            let cell = cell_with(d, |c| c);
            std::fs::write(d.join("out"), "a file where the folder should be").unwrap();
            plan_args(cell, d)
        },
        says: &["cannot write into the output folder", "-o"],
    },
    Case {
        name: "a time limit out of range",
        setup: |d| {
            let mut a = plan_args(cell_with(d, |c| c), d);
            a.extend(["--time-limit".into(), "0".into()]);
            a
        },
        says: &["--time-limit"],
    },
    Case {
        name: "a verify time step that would run for hours",
        setup: |d| {
            let cell = cell_with(d, |c| c);
            vec![
                "verify".into(),
                d.join("plan.json").display().to_string(),
                cell,
                "--time-step".into(),
                "1e-9".into(),
            ]
        },
        says: &["--time-step must be between"],
    },
    Case {
        name: "gen tasks count out of range",
        setup: |d| {
            vec![
                "gen".into(),
                "tasks".into(),
                "--mesh".into(),
                root()
                    .join("data/parts/body-in-white/car5.obj")
                    .display()
                    .to_string(),
                "--count".into(),
                "0".into(),
                "-o".into(),
                d.join("out").display().to_string(),
            ]
        },
        says: &["--count must be between 1 and"],
    },
];

#[test]
fn bad_input_is_refused_with_exit_2_and_nothing_written() {
    for case in CASES {
        let dir = scratch("refusal");
        let args = (case.setup)(&dir);
        let before: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = cellplan(&argv, &dir.join("cache"));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{}: {stderr}", case.name);
        for words in case.says {
            assert!(
                stderr.contains(words),
                "{}: expected `{words}` in: {stderr}",
                case.name
            );
        }
        let after: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        assert_eq!(before, after, "{}: something was written", case.name);
    }
}

#[test]
fn negative_directions_are_values_not_flags() {
    let dir = scratch("facing");
    let out_file = dir.join("tasks.csv");
    let mesh = root().join("data/parts/body-in-white/car5.obj");
    let args = [
        "gen",
        "tasks",
        "--mesh",
        mesh.to_str().unwrap(),
        "--count",
        "3",
        "--facing",
        "-y",
        "--translate",
        "-1,0,0",
        "-o",
        out_file.to_str().unwrap(),
    ];
    let out = cellplan(&args, &dir);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&out_file).unwrap();
    // Every normal faces -y within the default 60°.
    for row in text.lines().skip(1) {
        let ny: f64 = row.split(',').nth(5).unwrap().parse().unwrap();
        assert!(ny < -0.49, "{row}");
    }
}

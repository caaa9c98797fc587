//! `cellplan check` on the example cells and on broken cells, task lists, URDFs and meshes.
use super::*;
use serde_json::Value;

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

/// A FANUC given without its OPW parameter file gets the parameters read off its URDF: the same
/// candidates as with the file (the numeric solver, which the loader used before, finds fewer
/// branches near the joint limits and takes far longer).
#[test]
fn an_arm_without_its_opw_file_checks_as_with_it() {
    let dir = scratch("opw-derived");
    let (cell, _) = small_cell(&dir);
    let counts = |v: &Value| -> Vec<u64> {
        v["candidates"]
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t["robots"]["R1"].as_u64().unwrap())
            .collect()
    };
    let path = dir.join("cell.toml");
    let with = json_ok(&["check", path.to_str().unwrap(), "--json"], &dir);
    let opw_line = cell.lines().find(|l| l.starts_with("opw =")).unwrap();
    std::fs::write(&path, cell.replace(opw_line, "")).unwrap();
    let without = json_ok(&["check", path.to_str().unwrap(), "--json"], &dir);
    assert!(counts(&with).iter().all(|&n| n > 0), "{with}");
    assert_eq!(counts(&with), counts(&without));
    assert_eq!(with["total_candidates"], without["total_candidates"]);
    assert_eq!(with["ik"], serde_json::json!(["opw"]));
    assert_eq!(without["ik"], serde_json::json!(["opw-derived"]));
    // The text says which solver each robot got.
    let out = run_ok(&["check", path.to_str().unwrap()], &dir);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("inverse kinematics closed form (OPW, read off the URDF): R1"),
        "{text}"
    );
}

/// The same arm on a floor track (a prismatic first joint) gets sampled track positions and
/// the arm's closed form, and reaches the small cell's tasks.
#[test]
fn an_arm_on_a_track_gets_the_track_solver() {
    let dir = scratch("track");
    let (cell, _) = small_cell(&dir);
    let urdf_line = cell.lines().find(|l| l.starts_with("urdf =")).unwrap();
    let home_line = cell.lines().find(|l| l.starts_with("home =")).unwrap();
    let opw_line = cell.lines().find(|l| l.starts_with("opw =")).unwrap();
    let track = root().join(FANUC).join("urdf/r2000ic125l_on_track.urdf");
    let text = cell
        .replace(urdf_line, &format!("urdf = \"{}\"", track.display()))
        .replace(home_line, "home = [0, 0, -30, 0, 0, -60, 0]")
        .replace(opw_line, "");
    let path = dir.join("cell.toml");
    std::fs::write(&path, text).unwrap();
    let v = json_ok(&["check", path.to_str().unwrap(), "--json"], &dir);
    assert_eq!(v["ik"], serde_json::json!(["track"]));
    for t in v["candidates"].as_array().unwrap() {
        assert!(t["robots"]["R1"].as_u64().unwrap() > 0, "{t}");
    }
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

/// A cell none of whose robots can do a task is refused at the first robot's base.
#[test]
fn cell_whose_robots_reach_nothing_is_refused_at_a_base() {
    let dir = scratch("far");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace("base = { xyz = [0, 0, 0] }", "base = { xyz = [-20000, 0, 0] }"),
    )
    .unwrap();
    let err = refused(
        &dir,
        &dir,
        "cell.toml",
        Some(22),
        "no robot can do any of the 3 tasks",
    );
    assert!(err.contains("robot `R1` can do none from this base"), "{err}");
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

/// `check --minmax-out` writes the cell's allocation problem in the min-max format: it reads
/// back, has the cell's robots and MPs, its lower bound is the one `plan` states (every MP is
/// measured here), and `bench minmax` solves it no shorter than that bound. On a PCB cell the
/// option is refused (exit 2).
#[test]
fn check_writes_the_allocation_problem() {
    let (dir, cell, _, summary) = plan_small_cell("check-minmax");
    let file = dir.join("allocation.txt");
    let (cell, file_arg) = (cell.to_str().unwrap(), file.to_str().unwrap());
    run_ok(&["check", cell, "--minmax-out", file_arg, "--json"], &dir);
    let p = cellplan_solve::io::read_minmax(&file).expect("the file reads back");
    assert_eq!((p.vehicles.len(), p.tasks), (1, 3));
    assert!(p.service.iter().all(|&s| s == 1.5), "{:?}", p.service);
    assert_eq!(summary["unmeasured"].as_array().map(Vec::len), Some(0));
    let stated = summary["lower_bound_s"].as_f64().unwrap();
    let bound = cellplan_solve::minmax::lower_bound(&p);
    assert!(
        (bound - stated).abs() <= 1e-9 * stated,
        "{bound} against {stated}"
    );
    let rows = json_ok(&["bench", "minmax", file_arg, "--json"], &dir);
    let row = &rows[0];
    let cost = row["cost"].as_f64().unwrap();
    assert!(cost >= bound - 1e-9, "{rows}");
    // Both bounds are reported: the leg bound the plan states, and the route bound above it.
    // One robot, three MPs: the routes' relaxation is the shortest tour itself.
    assert_eq!(row["lower_bound"].as_f64(), Some(bound), "{rows}");
    let routes = row["route_bound"].as_f64().unwrap();
    assert_eq!(row["route_bound_converged"].as_bool(), Some(true), "{rows}");
    assert!(routes >= bound && (routes - cost).abs() <= 1e-6 * cost, "{rows}");
    let pcb = root().join("examples/pcb-paper-6/cell.toml");
    let out = cellplan(&["check", pcb.to_str().unwrap(), "--minmax-out", file_arg], &dir);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

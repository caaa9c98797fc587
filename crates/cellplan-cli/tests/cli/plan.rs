//! `cellplan plan`, `report`, `export` and `compare`.
use super::*;
use serde_json::Value;

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
    assert_eq!(plan["version"], 4);
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
    // The default budget is work, not the clock: the limit did not bind, and the summary
    // says so; a limit that binds is said, and the plan it gives still verifies.
    assert_eq!(summary["time_limit_hit"], false);
    assert_eq!(plan["stats"]["time_limit_hit"], false);
    let cut = dir.join("cut");
    let cut_summary = json_ok(
        &[
            "plan",
            cell.to_str().unwrap(),
            "-o",
            cut.to_str().unwrap(),
            "--json",
            "--time-limit",
            "0.000001",
        ],
        &dir,
    );
    assert_eq!(cut_summary["time_limit_hit"], true);
    assert_eq!(cut_summary["verified"], true);
    // In words: the limit bound, and the run went past it by what a plan needs.
    let text = run_ok(
        &[
            "plan",
            cell.to_str().unwrap(),
            "-o",
            dir.join("cut-text").to_str().unwrap(),
            "--no-report",
            "--time-limit",
            "0.000001",
        ],
        &dir,
    );
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("time limit reached"), "{text}");
    assert!(text.contains("against the 0.0 s limit"), "{text}");
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

/// A robot that can do none of the tasks (a task file holding only some of the part's MPs,
/// or a base placed far off) is planned idle at home, not refused: `check` and `plan` name it
/// with the reason, Δt leaves it out, and the verifier derives both again.
#[test]
fn a_robot_that_reaches_no_task_stays_home_and_is_left_out_of_delta_t() {
    let dir = scratch("idle-robot");
    let (cell, _) = small_cell(&dir);
    let far = cell
        .split("[[objects]]")
        .next()
        .unwrap()
        .split("[[robots]]")
        .nth(1)
        .unwrap()
        .replace("\"R1\"", "\"R2\"")
        .replace("base = { xyz = [0, 0, 0] }", "base = { xyz = [-20000, 0, 0] }");
    let two = cell.replace("[[objects]]", &format!("[[robots]]{far}[[objects]]"));
    std::fs::write(dir.join("cell.toml"), &two).unwrap();
    let cell = dir.join("cell.toml");
    let check = json_ok(&["check", cell.to_str().unwrap(), "--json"], &dir);
    assert_eq!(check["idle"][0]["robot"], "R2", "{check}");
    assert!(
        check["idle"][0]["reason"]
            .as_str()
            .unwrap()
            .contains("the nearest task is"),
        "{check}"
    );
    assert_eq!(check["idle"].as_array().unwrap().len(), 1);
    let out_dir = dir.join("out");
    let out = cellplan(
        &["plan", cell.to_str().unwrap(), "-o", out_dir.to_str().unwrap()],
        &dir,
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("idle (can do none of the tasks") && text.contains("  R2: "),
        "{text}"
    );
    let file = out_dir.join("plan.json");
    let plan: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    assert_eq!(plan["verified"], true);
    assert_eq!(plan["idle_robots"][0]["robot"], "R2");
    assert_eq!(plan["robots"][1]["tasks"].as_array().unwrap().len(), 0);
    assert_eq!(plan["robots"][0]["tasks"].as_array().unwrap().len(), 3);
    // One robot works: nothing to spread (counted, the idle robot would make Δt the cycle).
    assert!(plan["cycle_time_s"].as_f64().unwrap() > 1.0);
    assert_eq!(plan["delta_t_s"], 0.0);
    let verdict = |file: &std::path::Path| -> Value {
        let out = cellplan(
            &["verify", file.to_str().unwrap(), cell.to_str().unwrap(), "--json"],
            &dir,
        );
        serde_json::from_slice(&out.stdout).unwrap()
    };
    assert_eq!(verdict(&file)["ok"], true);
    // Without its idle robot, or with Δt counting it, the plan is refused.
    for (key, value) in [
        ("idle_robots", Value::Array(Vec::new())),
        ("delta_t_s", plan["cycle_time_s"].clone()),
    ] {
        let mut broken = plan.clone();
        broken[key] = value;
        let bad = dir.join("broken.json");
        std::fs::write(&bad, serde_json::to_string(&broken).unwrap()).unwrap();
        let v = verdict(&bad);
        assert_eq!(v["ok"], false, "{key}: {v}");
        assert_eq!(v["violations"][0]["kind"], "totals", "{key}: {v}");
    }
}

#[test]
fn plan_refuses_caps_that_cannot_hold_the_tasks() {
    let dir = scratch("plan-cap");
    let (cell, _) = small_cell(&dir);
    std::fs::write(
        dir.join("cell.toml"),
        cell.replace("[tools.probe]", "[planning]\ntask_cap = 1\n\n[tools.probe]"),
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

    // The cell with its robot moved: the plan does not hold there, and is not exported (exit
    // 4, nothing written) unless asked to be.
    let moved = dir.join("moved.toml");
    let text = std::fs::read_to_string(&cell).unwrap();
    assert!(text.contains("base = { xyz = [0, 0, 0] }"));
    std::fs::write(
        &moved,
        text.replace("base = { xyz = [0, 0, 0] }", "base = { xyz = [0, 300, 0] }"),
    )
    .unwrap();
    let moved_csv = dir.join("moved-csv");
    let args = [
        "export",
        plan.to_str().unwrap(),
        moved.to_str().unwrap(),
        "--csv",
        moved_csv.to_str().unwrap(),
    ];
    let out = cellplan(&args, &dir);
    assert_eq!(
        out.status.code(),
        Some(4),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("nothing exported"));
    assert!(!moved_csv.exists());
    let out = cellplan(&[&args[..], &["--no-verify"]].concat(), &dir);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(moved_csv.join("R1-program.csv").exists());

    // Nothing asked: refused.
    let out = cellplan(&["export", plan.to_str().unwrap(), cell.to_str().unwrap()], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--gltf"));
    // Not a plan: exit 2 naming the file and line; nothing written.
    let bad = dir.join("bad.json");
    std::fs::write(&bad, "{\n  \"format\": [\n").unwrap();
    let target = dir.join("bad.html");
    let glb_bad = dir.join("bad.glb");
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
    // Edited plans that would make `verify`, `report` or `export` panic or run for hours:
    // refused when read (exit 2, naming the place), nothing written.
    let good: Value = serde_json::from_str(&std::fs::read_to_string(&plan).unwrap()).unwrap();
    type Edit = fn(&mut Value);
    let edits: [(&str, Edit, &str); 4] = [
        (
            "a waypoint of 1e9",
            |d| d["robots"][0]["legs"][0]["waypoints"][0][0] = Value::from(1e9),
            "legs[0]",
        ),
        (
            "a shorter sample",
            |d| {
                d["robots"][0]["trajectory"][3]["q"].as_array_mut().unwrap().pop();
            },
            "trajectory[3]",
        ),
        (
            "time going back",
            |d| d["robots"][0]["trajectory"][3]["t"] = Value::from(0.0),
            "trajectory[3]",
        ),
        ("version 2", |d| d["version"] = Value::from(2), "version 2"),
    ];
    for (what, edit, place) in edits {
        let mut doc = good.clone();
        edit(&mut doc);
        std::fs::write(&bad, serde_json::to_string(&doc).unwrap()).unwrap();
        for args in [
            vec!["verify", bad.to_str().unwrap(), cell.to_str().unwrap()],
            vec![
                "report",
                bad.to_str().unwrap(),
                cell.to_str().unwrap(),
                "-o",
                target.to_str().unwrap(),
            ],
            vec![
                "export",
                bad.to_str().unwrap(),
                cell.to_str().unwrap(),
                "--gltf",
                glb_bad.to_str().unwrap(),
            ],
        ] {
            let out = cellplan(&args, &dir);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{what}, {}: {err}", args[0]);
            assert!(
                err.contains(place) && err.contains("bad.json"),
                "{what}, {}: {err}",
                args[0]
            );
        }
        assert!(!target.exists() && !glb_bad.exists(), "{what}");
    }
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
    assert!(page.contains("<b>ours + best</b>"));
}

#[test]
fn plan_refuses_an_absurd_blend_deviation() {
    let dir = scratch("plan-blend");
    let (cell, _) = small_cell(&dir);
    std::fs::write(dir.join("cell.toml"), cell).unwrap();
    for bad in ["-0.1", "NaN", "7"] {
        let out = cellplan(
            &[
                "plan",
                dir.join("cell.toml").to_str().unwrap(),
                &format!("--blend-deviation={bad}"),
                "-o",
                dir.join("out").to_str().unwrap(),
            ],
            &dir,
        );
        assert_eq!(out.status.code(), Some(2), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--blend-deviation"), "{bad}: {err}");
        assert!(!dir.join("out").join("plan.json").exists());
    }
}

#[test]
fn plan_states_the_route_bound_and_verify_checks_its_duals() {
    let dir = scratch("route-bound");
    small_cell(&dir);
    let cell = dir.join("cell.toml");
    let out_dir = dir.join("out");
    let summary = json_ok(
        &[
            "plan",
            cell.to_str().unwrap(),
            "-o",
            out_dir.to_str().unwrap(),
            "--json",
            "--route-bound",
            "0.01",
        ],
        &dir,
    );
    assert_eq!(summary["verified"], true);
    let rb = &summary["route_bound"];
    let (bound, legs) = (rb["bound_s"].as_f64().unwrap(), rb["legs_s"].as_f64().unwrap());
    let lb = summary["lower_bound_s"].as_f64().unwrap();
    assert!(bound >= legs - 1e-9 && legs > 0.0, "{rb}");
    assert_eq!(
        lb.to_bits(),
        bound.max(legs).to_bits(),
        "the larger bound is stated"
    );
    assert!(summary["cycle_time_s"].as_f64().unwrap() >= lb - 1e-9);
    // One robot, three MPs, each remembered: the relaxation is its shortest program, solved.
    assert_eq!(rb["converged"], true, "{rb}");
    assert_eq!(rb["max_work"], 10_000_000u64);
    assert!(
        rb["rounds"].as_u64().unwrap() >= 1 && rb["work"].as_u64().unwrap() > 0,
        "{rb}"
    );
    let plan_file = out_dir.join("plan.json");
    let plan: Value = serde_json::from_slice(&std::fs::read(&plan_file).unwrap()).unwrap();
    // The plan states the bound with its certificate; how the search went is in its stats.
    let stated = &plan["route_bound"];
    assert_eq!(
        (&stated["bound_s"], &stated["legs_s"]),
        (&rb["bound_s"], &rb["legs_s"])
    );
    let run = &plan["stats"]["route_bound"];
    for key in ["max_work", "work", "rounds", "converged", "cut_by_clock"] {
        assert_eq!(run[key], rb[key], "{key}");
    }
    // The report says which bound it shows.
    let report = std::fs::read_to_string(out_dir.join("report.html")).unwrap();
    let from_routes = report.contains("lower bound from whole programs (legs alone:");
    assert_eq!(from_routes, bound > legs, "{rb}");
    let verify = |doc: &Value| {
        let file = dir.join("tampered.json");
        std::fs::write(&file, serde_json::to_string(doc).unwrap()).unwrap();
        let out = cellplan(
            &["verify", file.to_str().unwrap(), cell.to_str().unwrap(), "--json"],
            &dir,
        );
        serde_json::from_slice::<Value>(&out.stdout).unwrap()
    };
    let details = |verdict: &Value| -> Vec<String> {
        verdict["violations"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v["detail"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(verify(&plan)["ok"], true);
    // The search's record is not a claim: changed, the plan still verifies.
    let mut search = plan.clone();
    search["stats"]["route_bound"]["rounds"] = Value::from(run["rounds"].as_u64().unwrap() + 1);
    assert_eq!(verify(&search)["ok"], true);
    // Three MPs on one robot: the relaxation beats the leg bound, so the duals are there.
    assert!(bound > legs + 1e-6, "{rb}");
    let duals = &stated["duals"];
    assert_eq!(duals["mps"].as_object().unwrap().len(), 3, "{duals}");
    assert_eq!(duals["robots"].as_object().unwrap().len(), 1, "{duals}");
    let (mp, robot) = (
        duals["mps"].as_object().unwrap().keys().next().unwrap().clone(),
        duals["robots"]
            .as_object()
            .unwrap()
            .keys()
            .next()
            .unwrap()
            .clone(),
    );
    // A bound raised, with the lower bound and ratio made to agree with it, is caught: its
    // duals prove less.
    let cycle = plan["cycle_time_s"].as_f64().unwrap();
    let mut raised = plan.clone();
    raised["route_bound"]["bound_s"] = Value::from(bound + 0.5);
    raised["lower_bound_s"] = Value::from(bound + 0.5);
    raised["ratio_to_lower_bound"] = Value::from(cycle / (bound + 0.5));
    // Duals that prove nothing: the robots' μ above one in sum, a negative price.
    let mut mu = plan.clone();
    mu["route_bound"]["duals"]["robots"][&robot] = Value::from(1.5);
    let mut negative = plan.clone();
    negative["route_bound"]["duals"]["mps"][&mp] = Value::from(-1.0);
    // Duals naming an MP the cell does not have.
    let mut unknown = plan.clone();
    unknown["route_bound"]["duals"]["mps"]["no-such-mp"] = Value::from(0.0);
    // The duals taken away: the bound stated is then more than what is proved.
    let mut bare = plan.clone();
    bare["route_bound"]["duals"] = Value::Null;
    for (what, doc, says) in [
        ("raised", &raised, "its duals prove"),
        ("mu", &mu, "prove nothing"),
        ("negative", &negative, "prove nothing"),
        ("unknown", &unknown, "no-such-mp"),
        ("bare", &bare, "without its duals"),
    ] {
        let verdict = verify(doc);
        assert_eq!(verdict["ok"], false, "{what}");
        let details = details(&verdict);
        assert!(details.iter().any(|d| d.contains(says)), "{what}: {details:?}");
    }
    // A route bound taken away with the lower bound left at its value: the leg bound alone is
    // smaller.
    let mut dropped = plan.clone();
    dropped.as_object_mut().unwrap().remove("route_bound");
    assert_eq!(verify(&dropped)["ok"], false);
    // The run's time limit bounds the route bound too: cut before its first round, it is the
    // leg bound, the plan says the clock cut it, and the verifier derives it again.
    let cut_dir = dir.join("cut");
    let cut = json_ok(
        &[
            "plan",
            cell.to_str().unwrap(),
            "-o",
            cut_dir.to_str().unwrap(),
            "--json",
            "--route-bound",
            "0.01",
            "--time-limit",
            "0.000001",
        ],
        &dir,
    );
    let crb = &cut["route_bound"];
    assert_eq!(
        (&crb["cut_by_clock"], &crb["rounds"]),
        (&Value::from(true), &Value::from(0)),
        "{crb}"
    );
    assert_eq!(crb["bound_s"], crb["legs_s"]);
    assert_eq!(
        (&cut["time_limit_hit"], &cut["verified"]),
        (&Value::from(true), &Value::from(true))
    );
    let cut_plan: Value = serde_json::from_slice(&std::fs::read(cut_dir.join("plan.json")).unwrap()).unwrap();
    assert_eq!(verify(&cut_plan)["ok"], true);
    // An absurd budget is refused before anything runs.
    let out = cellplan(&["plan", cell.to_str().unwrap(), "--route-bound", "5000"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--route-bound"));
}

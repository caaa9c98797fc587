//! Stud-weld cells (paper 002) through the binary: plan, verify, report and compare with their
//! stable JSON keys, an unweldable stud (exit 3, the plan still written and verified), and a refused
//! weld time (exit 2 at its line, nothing written). Small copies of `examples/studweld-kr210`.
use super::*;

/// The example cell with its first `studs` studs plus `extra` lines, 3 gun rotations and 6
/// DMOC steps, paths absolute; `edit` applied to the cell text.
fn weld_cell(dir: &Path, studs: usize, extra: &str, edit: impl Fn(String) -> String) -> String {
    let ex = root().join("examples/studweld-kr210");
    let text = std::fs::read_to_string(ex.join("cell.toml"))
        .unwrap()
        .replace("../../data", &root().join("data").display().to_string())
        .replace("gun_rotation_step = 45", "gun_rotation_step = 120")
        .replace("steps = 12 ", "steps = 6 ");
    let csv = std::fs::read_to_string(ex.join("studs.csv")).unwrap();
    let mut lines: Vec<&str> = csv.lines().take(studs + 1).collect();
    lines.extend(extra.lines());
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("studs.csv"), lines.join("\n") + "\n").unwrap();
    let path = dir.join("cell.toml");
    std::fs::write(&path, edit(text)).unwrap();
    path.display().to_string()
}

#[test]
fn plan_verify_and_compare_a_stud_weld_cell() {
    let dir = scratch("studweld");
    let cache = dir.join("cache");
    let cell = weld_cell(&dir.join("cell"), 2, "", |t| t);
    let out = dir.join("out");
    let out_s = out.display().to_string();
    let plan = json_ok(&["plan", &cell, "-o", &out_s, "--json"], &cache);
    for key in [
        "cost",
        "travel_cost",
        "weld_cost",
        "cycle_time_s",
        "compute_s",
        "verified",
    ] {
        assert!(plan.get(key).is_some(), "plan --json lacks {key}: {plan}");
    }
    assert_eq!(plan["verified"], true);
    assert_eq!(plan["welded"], 2);
    let parts = plan["travel_cost"].as_f64().unwrap() + plan["weld_cost"].as_f64().unwrap();
    assert!((parts - plan["cost"].as_f64().unwrap()).abs() < 1e-9);
    // Two welds of 2 s each at least.
    assert!(plan["cycle_time_s"].as_f64().unwrap() > 4.0);
    let plan_file = out.join("plan.json").display().to_string();
    let v = json_ok(&["verify", &plan_file, &cell, "--json"], &cache);
    assert_eq!(v["ok"], true, "{v}");

    // The page: Table 2's figures as the plan states them, the cycle's torques, one torque and
    // one velocity chart per move, one row per weld.
    let page_file = out.join("report.html");
    run_ok(
        &[
            "report",
            &plan_file,
            &cell,
            "-o",
            &page_file.display().to_string(),
        ],
        &cache,
    );
    let page = std::fs::read_to_string(&page_file).unwrap();
    assert!(
        page.contains(&format!("id=\"cost\">{:.1}<", plan["cost"].as_f64().unwrap())),
        "{page}"
    );
    assert!(page.contains("id=\"cycle-torques\""));
    assert!(page.contains("verified: every move"));
    let moves = plan["welded"].as_u64().unwrap() + 1;
    for k in 1..=moves {
        assert!(page.contains(&format!("id=\"leg-{k}-torque\"")), "move {k}");
        assert!(page.contains(&format!("id=\"leg-{k}-velocity\"")), "move {k}");
    }
    assert!(!page.contains(&format!("id=\"leg-{}-torque\"", moves + 1)));
    assert_eq!(page.matches("<path d=\"M").count() as u64, (2 * moves + 1) * 6);

    // A changed torque is caught.
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&plan_file).unwrap()).unwrap();
    let leg = doc["legs"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .find(|l| l["motion"]["kind"] == "ocp")
        .expect("an OCP leg");
    let u = leg["motion"]["u"][1][1].as_f64().unwrap();
    leg["motion"]["u"][1][1] = Value::from(u + 10.0);
    let broken = dir.join("broken.json");
    std::fs::write(&broken, serde_json::to_string(&doc).unwrap()).unwrap();
    let out = cellplan(&["verify", &broken.display().to_string(), &cell], &cache);
    assert_eq!(
        out.status.code(),
        Some(4),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("Dynamics"));

    let cmp = json_ok(&["compare", &cell, "--json"], &cache);
    let strategies = cmp["strategies"].as_array().unwrap();
    let names: Vec<&str> = strategies
        .iter()
        .map(|s| s["sequencer"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["travel-time", "optimal-control"]);
    for s in strategies {
        for key in ["cost", "travel_cost", "weld_cost", "cycle_time_s", "verified"] {
            assert!(s.get(key).is_some(), "compare lacks {key}: {s}");
        }
        assert_eq!(s["verified"], true);
    }
    assert!(
        strategies[1]["cost"].as_f64().unwrap() <= strategies[0]["cost"].as_f64().unwrap() * (1.0 + 1e-9)
    );
}

#[test]
fn an_unweldable_stud_exits_3_with_the_rest_planned() {
    let dir = scratch("studweld-far");
    let cache = dir.join("cache");
    let cell = weld_cell(&dir.join("cell"), 1, "FAR,-3000,0,800,1,0,0,surface", |t| t);
    let out = dir.join("out");
    let o = cellplan(
        &["plan", &cell, "-o", &out.display().to_string(), "--json"],
        &cache,
    );
    assert_eq!(o.status.code(), Some(3), "{}", String::from_utf8_lossy(&o.stderr));
    let plan: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(plan["unweldable"][0][0], "FAR");
    assert_eq!(plan["unweldable"][0][1], "no-ik");
    assert_eq!(plan["verified"], true);
    assert!(out.join("plan.json").exists());
}

#[test]
fn a_non_positive_weld_time_is_exit_2_at_its_line() {
    let dir = scratch("studweld-bad");
    let cache = dir.join("cache");
    let cell = weld_cell(&dir.join("cell"), 1, "", |t| {
        t.replace("weld_time = 2.0 ", "weld_time = -2 ")
    });
    let out = dir.join("out");
    let o = cellplan(&["plan", &cell, "-o", &out.display().to_string()], &cache);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    let line = std::fs::read_to_string(&cell)
        .unwrap()
        .lines()
        .position(|l| l.starts_with("weld_time"))
        .unwrap()
        + 1;
    assert!(err.contains(&format!("cell.toml:{line}")), "{err}");
    assert!(!out.join("plan.json").exists());
}

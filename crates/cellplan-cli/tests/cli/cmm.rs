//! CMM-inspection cells (paper 003) through the binary: plan, reuse, verify, report, compare and
//! check with their stable JSON keys.
use super::*;

#[test]
fn plan_reuse_verify_report_and_compare_a_cmm_cell() {
    let dir = scratch("cmm");
    let cache = dir.join("cache");
    let out = dir.join("out");
    let out_s = out.display().to_string();
    let cell = "examples/cmm-block/cell.toml";
    let plan = json_ok(&["plan", cell, "-o", &out_s, "--json"], &cache);
    for key in [
        "tasks",
        "groups",
        "motion_time_s",
        "movement_s",
        "rotation_s",
        "inspection_s",
        "compute_s",
        "verified",
    ] {
        assert!(plan.get(key).is_some(), "plan --json lacks {key}: {plan}");
    }
    assert_eq!(plan["tasks"].as_array().unwrap().len(), 39);
    assert_eq!(plan["groups"], 5);
    assert_eq!(plan["verified"], true);
    let sum = plan["movement_s"].as_f64().unwrap()
        + plan["rotation_s"].as_f64().unwrap()
        + plan["inspection_s"].as_f64().unwrap();
    assert!((sum - plan["motion_time_s"].as_f64().unwrap()).abs() < 1e-9);
    for f in ["plan.json", "program.csv", "report.html"] {
        assert!(out.join(f).exists(), "{f} not written");
    }
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    for id in ["id=\"table3\"", "id=\"groups\"", "class=\"mp\"", "class=\"root\""] {
        assert!(page.contains(id), "the report lacks {id}");
    }
    let plan_file = out.join("plan.json").display().to_string();
    // Reuse a subset: stable keys, only the subset touched, verified.
    let reuse_dir = dir.join("reuse").display().to_string();
    let reused = json_ok(
        &[
            "reuse",
            &plan_file,
            "--tasks",
            "D1,S2,E3,B4",
            "-o",
            &reuse_dir,
            "--json",
        ],
        &cache,
    );
    for key in ["tasks", "motion_time_s", "compute_s", "verified"] {
        assert!(reused.get(key).is_some(), "reuse --json lacks {key}: {reused}");
    }
    let mut tasks: Vec<&str> = reused["tasks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap())
        .collect();
    tasks.sort_unstable();
    assert_eq!(tasks, ["B4", "D1", "E3", "S2"]);
    assert_eq!(reused["verified"], true);
    assert!(reused["motion_time_s"].as_f64().unwrap() < plan["motion_time_s"].as_f64().unwrap());
    // The reuse plan verifies on its own; a tampered one is refused with exit 4.
    let reuse_plan = dir.join("reuse/plan.json");
    let verdict = json_ok(
        &["verify", &reuse_plan.display().to_string(), cell, "--json"],
        &cache,
    );
    assert_eq!(verdict["ok"], true);
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&reuse_plan).unwrap()).unwrap();
    doc["motion_time_s"] = Value::from(doc["motion_time_s"].as_f64().unwrap() - 1.0);
    let bad = dir.join("bad.json");
    std::fs::write(&bad, doc.to_string()).unwrap();
    assert_eq!(
        cellplan(&["verify", &bad.display().to_string(), cell], &cache)
            .status
            .code(),
        Some(4)
    );
    // The report command.
    let page2 = dir.join("page.html");
    run_ok(
        &["report", &plan_file, cell, "-o", &page2.display().to_string()],
        &cache,
    );
    assert!(
        std::fs::read_to_string(&page2)
            .unwrap()
            .contains("id=\"motion-time\"")
    );
    // Compare: the three strategies of Table 4, all verified.
    let cmp = json_ok(&["compare", cell, "--random-tasks", "3", "--json"], &cache);
    let names: Vec<&str> = cmp["strategies"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["strategy"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["reuse-roots", "reuse-initial-path", "replan"]);
    for r in cmp["strategies"].as_array().unwrap() {
        assert_eq!(r["verified"], true, "{r}");
        assert!(r["motion_time_s"].as_f64().unwrap() > 0.0 && r["compute_s"].is_number());
    }
    // Check: the classification both ways.
    let check = json_ok(&["check", cell, "--json"], &cache);
    assert_eq!(check["mps"], 39);
    assert_eq!(check["groups_exact"], 5);
}

//! PCB-assembly cells (paper 004) through the binary: plan, verify, report, compare and check
//! with their stable JSON keys.
use super::*;

#[test]
fn plan_verify_report_and_compare_a_pcb_cell() {
    let dir = scratch("pcb");
    let cache = dir.join("cache");
    let out = dir.join("out");
    let out_s = out.display().to_string();
    let cell = "examples/pcb-paper-6/cell.toml";
    let plan = json_ok(
        &["plan", cell, "-o", &out_s, "--evaluations", "4000", "--json"],
        &cache,
    );
    for key in [
        "cycle_time_s",
        "lower_bound_s",
        "components",
        "robots",
        "compute_s",
    ] {
        assert!(plan.get(key).is_some(), "plan --json lacks {key}: {plan}");
    }
    assert_eq!(plan["components"], 6);
    assert_eq!(plan["verified"], true);
    let robots = plan["robots"].as_array().unwrap();
    assert_eq!(robots.len(), 2);
    let placed: u64 = robots.iter().map(|r| r["components"].as_u64().unwrap()).sum();
    assert_eq!(placed, 6);
    for r in robots {
        assert!(
            r["name"].is_string()
                && r["total_s"].as_f64().unwrap() <= plan["cycle_time_s"].as_f64().unwrap() + 1e-9
        );
    }
    assert!(plan["lower_bound_s"].as_f64().unwrap() <= plan["cycle_time_s"].as_f64().unwrap());
    for f in ["plan.json", "placement.csv", "report.html"] {
        assert!(out.join(f).exists(), "{f} not written");
    }
    let csv = std::fs::read_to_string(out.join("placement.csv")).unwrap();
    assert_eq!(csv.lines().count(), 7, "a header and one row per component");
    let page = std::fs::read_to_string(out.join("report.html")).unwrap();
    for id in ["id=\"board\"", "id=\"x-time\"", "id=\"gantt\"", "id=\"bins\""] {
        assert!(page.contains(id), "the report lacks {id}");
    }
    let plan_file = out.join("plan.json").display().to_string();
    let verdict = json_ok(&["verify", &plan_file, cell, "--json"], &cache);
    assert_eq!(verdict["ok"], true);
    assert!(verdict["violations"].as_array().unwrap().is_empty());
    // A tampered plan is refused with exit 4.
    let text = std::fs::read_to_string(out.join("plan.json")).unwrap();
    let mut doc: Value = serde_json::from_str(&text).unwrap();
    doc["cycle_time_s"] = Value::from(doc["cycle_time_s"].as_f64().unwrap() - 0.1);
    let bad = dir.join("bad.json");
    std::fs::write(&bad, doc.to_string()).unwrap();
    let res = cellplan(&["verify", &bad.display().to_string(), cell], &cache);
    assert_eq!(res.status.code(), Some(4));
    // The report command on the written plan.
    let page2 = dir.join("page.html");
    run_ok(
        &["report", &plan_file, cell, "-o", &page2.display().to_string()],
        &cache,
    );
    assert!(std::fs::read_to_string(&page2).unwrap().contains("id=\"x-time\""));
    // Compare: four one-robot configurations and two robots with and without avoidance.
    let cmp = json_ok(&["compare", cell, "--evaluations", "2000", "--json"], &cache);
    let rows = cmp["strategies"].as_array().unwrap();
    assert_eq!(rows.len(), 12);
    for r in rows {
        for key in [
            "optimizer",
            "configuration",
            "robots",
            "collision_avoidance",
            "cycle_time_s",
            "lower_bound_s",
            "verified",
            "compute_s",
        ] {
            assert!(r.get(key).is_some(), "compare row lacks {key}: {r}");
        }
        if r["robots"] == 1 || r["collision_avoidance"] == true {
            assert_eq!(r["verified"], true, "{r}");
        }
    }
    for conf in ["all-fixed", "moving-cds", "moving-table", "all-moving"] {
        assert!(rows.iter().any(|r| r["configuration"] == conf));
    }
    // A one-robot run with another configuration through `plan`.
    let one = json_ok(
        &[
            "plan",
            cell,
            "-o",
            &out_s,
            "--robots",
            "1",
            "--configuration",
            "all-fixed",
            "--optimizer",
            "ga",
            "--evaluations",
            "2000",
            "--json",
            "--no-report",
        ],
        &cache,
    );
    assert_eq!(one["robots"].as_array().unwrap().len(), 1);
    assert_eq!(one["configuration"], "all-fixed");
    assert_eq!(one["optimizer"], "ga");
}

#[test]
fn the_same_seed_gives_the_same_plan_on_one_thread_and_on_all() {
    let dir = scratch("pcb-threads");
    let cache = dir.join("cache");
    let mut plans = Vec::new();
    for threads in ["1", "2"] {
        let out = dir.join(format!("t{threads}"));
        let o = out.display().to_string();
        json_ok(
            &[
                "--threads",
                threads,
                "plan",
                "examples/pcb-bitsy-1r/cell.toml",
                "-o",
                &o,
                "--evaluations",
                "6000",
                "--json",
                "--no-report",
                "--seed",
                "3",
            ],
            &cache,
        );
        let mut doc: Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
        doc["compute_s"] = Value::from(0.0);
        plans.push(doc);
    }
    assert_eq!(plans[0], plans[1]);
}

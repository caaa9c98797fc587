//! `cellplan bench` on standard instances.
use super::*;
use serde_json::Value;
use std::path::Path;

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

/// `bench motion` on the first MBM problems: the stable fields, solved paths that the exact
/// re-check accepts, a peer's run re-checked (one path made to cut through a shelf), and the
/// refusals.
#[test]
fn bench_motion_plans_and_rechecks_exactly() {
    let dir = scratch("bench-motion");
    let scene = "bench/motion/mbm-ur5/box.json";
    let rows = json_ok(
        &["bench", "motion", scene, "--first", "2", "--json", "--with-paths"],
        &dir,
    );
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for row in rows {
        for key in [
            "problem",
            "planner",
            "solved",
            "time_s",
            "path_length",
            "validity_checks",
            "exact_valid",
        ] {
            assert!(!row[key].is_null(), "{key} missing in {row}");
        }
        assert_eq!(row["planner"], "leg");
        assert_eq!(row["solved"], true, "{row}");
        assert_eq!(row["exact_valid"], true, "{row}");
        assert!(row["exact_samples"].as_u64().unwrap() > 100);
    }
    // A peer's run: the first path as planned, and a second that stands still.
    let path = rows[0]["path"].as_array().unwrap().clone();
    let peer = serde_json::json!([
        {"problem": rows[0]["problem"], "planner": "peer", "solved": true, "time_s": 0.001,
         "path_length": 1.0, "validity_checks": null, "path": path},
        {"problem": rows[1]["problem"], "planner": "peer", "solved": true, "time_s": null,
         "path": [rows[1]["path"][0], rows[1]["path"][0]]},
    ]);
    let run = dir.join("peer.json");
    std::fs::write(&run, serde_json::to_string(&peer).unwrap()).unwrap();
    let recheck = || {
        json_ok(
            &[
                "bench",
                "motion",
                scene,
                "--recheck",
                run.to_str().unwrap(),
                "--json",
            ],
            &dir,
        )
    };
    let checked = recheck();
    assert_eq!(checked[0]["exact_valid"], true);
    assert_eq!(
        checked[1]["exact_valid"], true,
        "standing still at a valid start is valid"
    );
    // The elbow folded shut (3.1 rad) folds the wrist onto the upper arm: a self-collision.
    let mut folded = rows[0]["path"][0].clone();
    folded[2] = serde_json::json!(3.1);
    let cut = serde_json::json!([{"problem": rows[0]["problem"], "planner": "peer", "solved": true,
                                  "path": [rows[0]["path"][0], folded]}]);
    std::fs::write(&run, serde_json::to_string(&cut).unwrap()).unwrap();
    let checked = recheck();
    assert_eq!(checked[0]["exact_valid"], false, "{checked}");
    assert!(
        checked[0]["exact_contact"]
            .as_str()
            .unwrap()
            .contains("with link"),
        "{checked}"
    );
    // Refusals: an unknown planner (usage), a broken file (exit 2, file and line).
    let out = cellplan(&["bench", "motion", scene, "--planner", "rrt-sharp"], &dir);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("rrt-connect"));
    let bad = dir.join("bad.json");
    std::fs::write(
        &bad,
        "{\"format\": \"cellplan-motion-problems\",\n \"version\": 1,\n \"robot\": [}",
    )
    .unwrap();
    let out = cellplan(&["bench", "motion", bad.to_str().unwrap()], &dir);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bad.json"), "{stderr}");
    // A peer's run that is not a run: exit 2, the run file and its line, what to give.
    std::fs::write(&run, "[{\"problem\": \"x\",\n \"solved\": \"yes\"}]").unwrap();
    let out = cellplan(
        &["bench", "motion", scene, "--recheck", run.to_str().unwrap()],
        &dir,
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("peer.json:2:"), "{stderr}");
    assert!(stderr.contains("motion_vamp.py"), "{stderr}");
}

#[test]
fn bench_minmax_refuses_to_generate_an_instance_past_the_memory_allowed() {
    let dir = scratch("bench-minmax-large");
    let file = dir.join("mm.txt");
    let generate = |vehicles: &str, tasks: &str, alternatives: &str| {
        cellplan(
            &[
                "bench",
                "minmax",
                "--generate",
                "--vehicles",
                vehicles,
                "--tasks",
                tasks,
                "--alternatives",
                alternatives,
                "-o",
                file.to_str().unwrap(),
            ],
            &dir,
        )
    };
    // Absurd counts are refused before the points are made, large alternatives before the
    // matrices: both within a moment and without the memory they would take.
    for (vehicles, tasks, alternatives, says) in [
        ("4", "100000000000", "1..4", "before any cost is stored"),
        ("100000000", "1000", "1..4", "before any cost is stored"),
        ("15000000", "1", "1..1", "before any cost is stored"),
        ("2", "20000", "1..40", "could take more than the 512 MiB"),
    ] {
        let out = generate(vehicles, tasks, alternatives);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(2),
            "{vehicles} {tasks} {alternatives}: {stderr}"
        );
        assert!(stderr.contains(says), "{stderr}");
        assert!(stderr.contains("nothing written"), "{stderr}");
        assert!(!file.exists(), "nothing is written");
    }
    let out = generate("2", "30", "1..4");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(file.exists());
}

//! `cellplan plan` through the library on a reduced copy of the two-robot example (its first 8
//! MPs): every plan is re-checked here, independently of the planner — every MP measured
//! exactly once at a pose that meets the probe constraints, every leg re-sampled finely (joint
//! steps of 1 mrad) against the static scene at the margin, joint position, velocity and
//! acceleration limits from the written samples, the document's totals recomputed.
use cellplan_core::candidates::{CandidateTable, generate};
use cellplan_core::coord::{self, CoordSettings};
use cellplan_core::document as output;
use cellplan_core::plan::{self, Allocation, PlanSettings};
use cellplan_model::robot::Scratch;
use cellplan_model::{Cell, LoadOptions, TaskId};
use cellplan_optical::load;
use cellplan_optical::testing::{example_copy, repo_root, scratch_dir};
use cellplan_verify::{VerifySettings, ViolationKind, verify};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The two-robot example with only its first `n` MPs, written to a temporary folder.
fn small_cell(n: usize) -> PathBuf {
    example_copy(&format!("plan-test-{n}"), "autobody-2r-small", n, |text| text)
}

struct Fixture {
    cell: Cell,
    table: CandidateTable,
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let cell = load(&small_cell(8), &LoadOptions::default()).expect("the reduced cell loads");
        let table = generate(&cell);
        Fixture { cell, table }
    })
}

fn settings(allocation: Allocation) -> PlanSettings {
    PlanSettings {
        allocation,
        alternatives: 8,
        balanced_iterations: 60,
        // Never cut by the clock: the plan must depend only on the input and the seed.
        time_limit: std::time::Duration::from_secs(3600),
        ..PlanSettings::default()
    }
}

fn make(allocation: Allocation) -> output::Plan {
    let f = fixture();
    let s = settings(allocation);
    let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).expect("the reduced cell plans");
    let doc = build(&f.cell, &f.table, &outcome, &s);
    // The document survives its own JSON.
    let text = serde_json::to_string(&doc).unwrap();
    let back: output::Plan = serde_json::from_str(&text).unwrap();
    assert_eq!(serde_json::to_string(&back).unwrap(), text);
    check_plan(&f.cell, &doc);
    verified(&f.cell, &doc);
    doc
}

/// The plan document of a run, coordinated by `best`.
fn build(cell: &Cell, table: &CandidateTable, outcome: &plan::Outcome, s: &PlanSettings) -> output::Plan {
    let c = coord::coordinate_outcome(cell, table, outcome, &CoordSettings::default())
        .expect("coordination succeeds");
    output::build(cell, table, outcome, &c, s, 0.0, 0.0)
}

/// The verifier accepts the plan, robot–robot clearance included.
fn verified(cell: &Cell, doc: &output::Plan) {
    let report = verify(cell, doc, &VerifySettings::default());
    assert!(report.ok, "{:#?}", report.violations);
    assert!(report.configurations_checked > 0);
}

/// The independent re-check of a plan.
fn check_plan(cell: &Cell, doc: &output::Plan) {
    let process = cellplan_optical::of(cell).expect("an optical cell");
    assert_eq!(doc.format, output::FORMAT);
    assert_eq!(doc.robots.len(), cell.robots.len());
    let by_name: BTreeMap<&str, usize> = cell.tasks.iter().map(|t| (t.name.as_str(), t.id.0)).collect();
    let mut measured = vec![0usize; cell.tasks.len()];
    let mut scratch = Scratch::default();
    let mut times = Vec::new();
    for (robot, rp) in cell.robots.iter().zip(&doc.robots) {
        assert_eq!(rp.name, robot.name);
        assert!(
            rp.tasks.len() <= cell.planning.task_cap,
            "{} over its cap",
            rp.name
        );
        for v in &rp.tasks {
            let t = &cell.tasks[by_name[v.task.as_str()]];
            measured[t.id.0] += 1;
            assert!(robot.within_limits(&v.q));
            let tcp = robot.tcp_pose(&v.q);
            assert!((tcp.translation - glam::DVec3::from(v.tcp.xyz)).length() < 1e-6);
            let angle = process
                .measurement(t, &tcp)
                .unwrap_or_else(|r| panic!("{} does not measure {} from its pose: {r:?}", rp.name, v.task));
            assert!((angle - v.figures["view_angle_rad"]).abs() < 1e-6);
            robot.body_poses(&v.q, &mut scratch);
            assert!(
                robot
                    .contact_at(&cell.world, &scratch, cell.planning.clearance - 1e-6)
                    .is_none()
            );
            assert!(v.depart_s - v.arrive_s >= process.measure_time - 1e-9);
        }
        // Legs: chained home → … → home, re-sampled at 1 mrad per joint step.
        assert_eq!(rp.legs.len(), rp.tasks.len() + 1);
        let mut at = rp.home.clone();
        for (i, leg) in rp.legs.iter().enumerate() {
            let to = rp.tasks.get(i).map_or(&rp.home, |v| &v.q);
            assert!(
                dist(&leg.waypoints[0], &at) < 1e-9,
                "{} leg {i} starts elsewhere",
                rp.name
            );
            assert!(
                dist(leg.waypoints.last().unwrap(), to) < 1e-9,
                "{} leg {i} ends elsewhere",
                rp.name
            );
            for w in leg.waypoints.windows(2) {
                let steps = (dist(&w[0], &w[1]) / 1e-3).ceil().max(1.0) as usize;
                for s in 0..=steps {
                    let f = s as f64 / steps as f64;
                    let q: Vec<f64> = w[0].iter().zip(&w[1]).map(|(a, b)| a + f * (b - a)).collect();
                    assert!(
                        robot.within_limits(&q),
                        "{} leg {i} leaves the joint limits",
                        rp.name
                    );
                    robot.body_poses(&q, &mut scratch);
                    assert!(
                        robot
                            .contact_at(&cell.world, &scratch, cell.planning.clearance - 1e-6)
                            .is_none(),
                        "{} leg {i} ({} → {}) comes closer than the clearance at {q:?}",
                        rp.name,
                        leg.from,
                        leg.to
                    );
                }
            }
            at = to.clone();
        }
        // Samples: within limits; finite differences bound the mean velocity and acceleration.
        let tr = &rp.trajectory;
        assert!(tr.first().unwrap().t.abs() < 1e-12);
        assert!((tr.last().unwrap().t - rp.total_s).abs() < 1e-9);
        assert!(dist(&tr.first().unwrap().q, &rp.home) < 1e-9);
        assert!(dist(&tr.last().unwrap().q, &rp.home) < 1e-9);
        for s in tr {
            assert!(robot.within_limits(&s.q));
        }
        for w in tr.windows(3) {
            let (h1, h2) = (w[1].t - w[0].t, w[2].t - w[1].t);
            for j in 0..robot.dof() {
                let v = (w[1].q[j] - w[0].q[j]) / h1;
                assert!(
                    v.abs() <= robot.max_velocity[j] * (1.0 + 1e-6),
                    "{} joint {j} too fast",
                    rp.name
                );
                if (h1 - h2).abs() < 1e-9 {
                    let a = (w[2].q[j] - 2.0 * w[1].q[j] + w[0].q[j]) / (h1 * h1);
                    assert!(
                        a.abs() <= robot.max_acceleration[j] * (1.0 + 1e-6),
                        "{} joint {j} accelerates too hard",
                        rp.name
                    );
                }
            }
        }
        times.push(rp.total_s);
    }
    // Every measurable MP exactly once; the others listed as unmeasured.
    let unmeasured: Vec<&str> = doc.unmeasured.iter().map(|u| u.task.as_str()).collect();
    for t in &cell.tasks {
        let want = usize::from(!unmeasured.contains(&t.name.as_str()));
        assert_eq!(
            measured[t.id.0], want,
            "MP {} measured {} times",
            t.name, measured[t.id.0]
        );
    }
    let cycle = times.iter().copied().fold(0.0, f64::max);
    assert!((doc.cycle_time_s - cycle).abs() < 1e-9);
    let spread = cycle - times.iter().copied().fold(f64::INFINITY, f64::min);
    assert!((doc.delta_t_s - spread).abs() < 1e-9);
    assert!(
        doc.lower_bound_s > 0.0 && doc.lower_bound_s <= doc.cycle_time_s + 1e-9,
        "lower bound {} above the cycle time {} ({} unmeasured)",
        doc.lower_bound_s,
        doc.cycle_time_s,
        doc.unmeasured.len()
    );
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn every_strategy_gives_a_plan_that_rechecks_clean() {
    let f = fixture();
    let prox = make(Allocation::Proximity);
    // Proximity: every MP with the nearest robot able to measure it (the caps do not bind here).
    for (r, rp) in prox.robots.iter().enumerate() {
        for v in &rp.tasks {
            let t = f.cell.tasks.iter().find(|t| t.name == v.task).unwrap();
            let d = |i: usize| (f.cell.robots[i].base.translation - t.position).length();
            for other in f.table.robots_for(t.id) {
                assert!(
                    d(r) <= d(other.0) + 1e-12,
                    "MP {} is not with its nearest robot",
                    v.task
                );
            }
        }
    }
    let robust = make(Allocation::LocalRobust);
    assert!(robust.stats.local_sets_built >= robust.stats.local_sets_chosen);
    let balanced = make(Allocation::Balanced);
    for doc in [&prox, &robust, &balanced] {
        assert!(doc.stats.legs_planned >= doc.robots.iter().map(|r| r.legs.len()).sum::<usize>() / 2);
    }
}

#[test]
fn the_plan_does_not_depend_on_the_thread_count() {
    let f = fixture();
    let s = settings(Allocation::Balanced);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).unwrap();
            let mut doc = build(&f.cell, &f.table, &outcome, &s);
            doc.compute_s = output::ComputeTimes::default();
            doc
        })
    };
    let one = run(1);
    check_plan(&f.cell, &one);
    assert_eq!(one, run(2));
    let _ = TaskId(0);
}

/// Every key the schema (generated from the document's types) requires is in a written
/// plan, at every level.
#[test]
fn written_plans_have_every_key_the_schema_requires() {
    let schema: serde_json::Value = serde_json::from_str(&output::schema()).unwrap();
    let f = fixture();
    let s = PlanSettings {
        allocation: Allocation::Proximity,
        ..settings(Allocation::Proximity)
    };
    let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).unwrap();
    let doc = serde_json::to_value(build(&f.cell, &f.table, &outcome, &s)).unwrap();
    fn required(
        schema: &serde_json::Value,
        value: &serde_json::Value,
        root: &serde_json::Value,
        at: &str,
    ) -> usize {
        let schema = match schema.get("$ref").and_then(|r| r.as_str()) {
            Some(r) => root.pointer(r.trim_start_matches('#')).unwrap(),
            None => schema,
        };
        let mut checked = 0;
        if let Some(keys) = schema.get("required").and_then(|r| r.as_array()) {
            for k in keys {
                let k = k.as_str().unwrap();
                assert!(value.get(k).is_some(), "{at} lacks `{k}`");
                checked += 1;
            }
        }
        if let (Some(props), Some(obj)) = (
            schema.get("properties").and_then(|p| p.as_object()),
            value.as_object(),
        ) {
            for (k, sub) in props {
                if let Some(v) = obj.get(k) {
                    checked += required(sub, v, root, &format!("{at}.{k}"));
                }
            }
        }
        if let (Some(items), Some(arr)) = (schema.get("items"), value.as_array()) {
            for (i, v) in arr.iter().enumerate() {
                checked += required(items, v, root, &format!("{at}[{i}]"));
            }
        }
        checked
    }
    assert!(required(&schema, &doc, &schema, "plan") > 100);
    assert_eq!(doc["version"], output::VERSION);
}

/// Edits of a valid plan: each is refused when the document is read (a clean error naming
/// the place) or caught by the verifier, never accepted.
#[test]
fn edited_plans_are_refused_or_caught() {
    let f = fixture();
    let s = settings(Allocation::Balanced);
    let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).unwrap();
    let good = build(&f.cell, &f.table, &outcome, &s);
    let quiet = VerifySettings::default();
    assert!(verify(&f.cell, &good, &quiet).ok);
    let r = good.robots.iter().position(|r| r.tasks.len() >= 2).unwrap();
    let n = good.robots[r].trajectory.len();
    type Edit = fn(&mut output::Plan, usize, usize);
    // (what, edit, the violation it must cause; None: refused when read)
    let cases: Vec<(&str, Edit, Option<ViolationKind>)> = vec![
        (
            "a sample deleted",
            |p, r, n| drop(p.robots[r].trajectory.remove(n / 2)),
            Some(ViolationKind::Continuity),
        ),
        (
            "motion_s changed",
            |p, r, _| p.robots[r].motion_s += 0.25,
            Some(ViolationKind::Totals),
        ),
        (
            "measuring_s changed",
            |p, r, _| p.robots[r].measuring_s += 0.25,
            Some(ViolationKind::Totals),
        ),
        (
            "waiting_s changed",
            |p, r, _| p.robots[r].waiting_s += 0.25,
            Some(ViolationKind::Totals),
        ),
        (
            "end_s changed",
            |p, r, _| p.robots[r].end_s += 0.25,
            Some(ViolationKind::Totals),
        ),
        (
            "total_s changed",
            |p, r, _| p.robots[r].total_s -= 0.25,
            Some(ViolationKind::Totals),
        ),
        (
            "lower_bound_s changed",
            |p, _, _| p.lower_bound_s *= 0.9,
            Some(ViolationKind::Totals),
        ),
        (
            "ratio changed",
            |p, _, _| p.ratio_to_lower_bound *= 0.9,
            Some(ViolationKind::Totals),
        ),
        (
            "joints reversed",
            |p, r, _| p.robots[r].joints.reverse(),
            Some(ViolationKind::Format),
        ),
        (
            "a leg's duration changed",
            |p, r, _| p.robots[r].legs[1].duration_s += 0.25,
            Some(ViolationKind::Totals),
        ),
        (
            "a visit moved in time",
            |p, r, _| p.robots[r].tasks[1].arrive_s += 0.25,
            Some(ViolationKind::Continuity),
        ),
        (
            "a leg's stop renamed",
            |p, r, _| p.robots[r].legs[0].from = plan::Stop::Task("M1".into()),
            Some(ViolationKind::Continuity),
        ),
        (
            "a task done and listed as undoable",
            |p, r, _| {
                let task = p.robots[r].tasks[0].task.clone();
                p.unmeasured.push(output::UnmeasuredTask {
                    task,
                    reason: "no-ik".into(),
                    detail: None,
                });
            },
            Some(ViolationKind::Unmeasured),
        ),
        (
            "a task done and listed as without a path",
            |p, r, _| {
                let task = p.robots[r].tasks[0].task.clone();
                p.unmeasured.push(output::UnmeasuredTask {
                    task,
                    reason: output::NO_PATH.into(),
                    detail: Some("made up".into()),
                });
            },
            Some(ViolationKind::Unmeasured),
        ),
        (
            "the candidate count changed",
            |p, _, _| p.stats.candidates += 1,
            Some(ViolationKind::Totals),
        ),
        (
            "the candidate index changed",
            |p, r, _| p.robots[r].tasks[0].candidate += 1,
            Some(ViolationKind::ProbeConstraint),
        ),
        (
            "the clearance changed",
            |p, _, _| p.settings.clearance_m = 0.0,
            Some(ViolationKind::Totals),
        ),
        (
            "the wait count changed",
            |p, _, _| p.coordination.waits += 1,
            Some(ViolationKind::Totals),
        ),
        (
            "the strategy changed",
            |p, _, _| p.coordination.strategy = coord::Coordination::None,
            Some(ViolationKind::Totals),
        ),
        (
            "the uncoordinated cycle changed",
            |p, _, _| p.coordination.uncoordinated_cycle_time_s += 1.0,
            Some(ViolationKind::Totals),
        ),
        (
            "a recorded tool rotation changed",
            |p, r, _| p.robots[r].tasks[0].tcp.quat = [0.0, 0.0, 0.0, 1.0],
            Some(ViolationKind::ProbeConstraint),
        ),
        (
            "a sample of fewer joints",
            |p, r, n| {
                p.robots[r].trajectory[n / 2].q.pop();
            },
            None,
        ),
        (
            "a sample before the one before it",
            |p, r, n| p.robots[r].trajectory[n / 2].t -= 1.0,
            None,
        ),
        (
            "a waypoint at 1e9",
            |p, r, _| p.robots[r].legs[0].waypoints[0][0] = 1e9,
            None,
        ),
        ("a time of 1e12 s", |p, r, _| p.robots[r].end_s = 1e12, None),
        (
            "a wait at a leg that does not exist",
            |p, r, _| {
                p.robots[r].waits.push(output::WaitOut {
                    leg: 99,
                    waypoint: 0,
                    start_s: 0.0,
                    duration_s: 1.0,
                    reason: coord::WaitReason::GiveWay,
                    for_robot: None,
                })
            },
            None,
        ),
        ("another version", |p, _, _| p.version = 2, None),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (what, edit, expected) in cases {
        let mut doc = good.clone();
        edit(&mut doc, r, n);
        let path = dir.path().join("plan.json");
        std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
        match (output::read(&path), expected) {
            (Ok(read), Some(kind)) => {
                let report = verify(&f.cell, &read, &quiet);
                let kinds: Vec<ViolationKind> = report.violations.iter().map(|v| v.kind).collect();
                assert!(kinds.contains(&kind), "{what}: want {kind:?}, got {kinds:?}");
            }
            (Err(e), None) => {
                // The library verifier refuses it too, without walking it.
                let report = verify(&f.cell, &doc, &quiet);
                assert_eq!(report.violations.len(), 1, "{what}: {e}");
                assert_eq!(report.violations[0].kind, ViolationKind::Format, "{what}");
            }
            (Ok(_), None) => panic!("{what}: read as valid"),
            (Err(e), Some(_)) => panic!("{what}: refused when read ({e}); the verifier should name it"),
        }
    }
    // The coordination record erased: not a plan of this layout.
    let mut json = serde_json::to_value(&good).unwrap();
    json.as_object_mut().unwrap().remove("coordination");
    let path = dir.path().join("erased.json");
    std::fs::write(&path, serde_json::to_string_pretty(&json).unwrap()).unwrap();
    let e = output::read(&path).unwrap_err();
    assert!(e.to_string().contains("coordination"), "{e}");
    // A file too large is refused before it is read.
    let big = std::fs::File::create(dir.path().join("big.json")).unwrap();
    big.set_len(output::MAX_PLAN_BYTES + 1).unwrap();
    let e = output::read(&dir.path().join("big.json")).unwrap_err();
    assert!(matches!(e, output::DocumentError::TooLarge { .. }), "{e}");
}

/// Two robots 2 m apart facing a box, four MPs close together on its top, all nearer to R1
/// and measurable by both: proximity gives all four to R1; local robust sets group them
/// (closer than ε, same normal) and Algorithm 1 gives the set to R1 (the shorter tour from its
/// base); the balanced min-max splits them two and two (four measurements on one robot take
/// 6 s, two take 3 s).
#[test]
fn allocation_strategies_give_the_known_answers_on_a_hand_made_cell() {
    let fanuc = repo_root().join("data/robots/fanuc_r2000ic");
    let dir = scratch_dir("plan-known");
    let robot = |name: &str, y: i32| {
        format!(
            r#"
[[robots]]
name = "{name}"
urdf = "{f}/urdf/r2000ic125l.urdf"
packages = {{ fanuc_r2000ic_support = "{f}/fanuc_r2000ic_support" }}
opw = "{f}/fanuc_r2000ic_support/config/opw_parameters_r2000ic125l.yaml"
base = {{ xyz = [0, {y}, 0] }}
home = [0, -30, 0, 0, -60, 0]
tool = "probe"
"#,
            f = fanuc.display()
        )
    };
    let cell = format!(
        r#"name = "known"
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
{}{}
[[objects]]
name = "part"
box = [600, 600, 600]
pose = {{ xyz = [1900, 0, 300] }}

[tasks]
file = "tasks.csv"
"#,
        robot("R1", 1000),
        robot("R2", -1000)
    );
    std::fs::write(dir.join("cell.toml"), cell).unwrap();
    std::fs::write(
        dir.join("tasks.csv"),
        "id,x,y,z,nx,ny,nz\nA,1800,150,600,0,0,1\nB,1900,150,600,0,0,1\nC,1800,250,600,0,0,1\nD,1900,250,600,0,0,1\n",
    )
    .unwrap();
    let cell = load(&dir.join("cell.toml"), &LoadOptions::default()).expect("the hand-made cell loads");
    let table = generate(&cell);
    for t in 0..4 {
        assert_eq!(table.robots_for(TaskId(t)).len(), 2, "both robots measure MP {t}");
    }
    let graphs: Vec<_> = cell
        .robots
        .iter()
        .map(|r| plan::graph::RobotGraph::new(&cell, r, &table, plan::MoveModel::Trapezoid, 8, 0.02))
        .collect();
    let counts = |a: Allocation| {
        let s = settings(a);
        let got = plan::allocate::allocate(&cell, &table, &graphs, &s, None).unwrap();
        got.tasks.iter().map(Vec::len).collect::<Vec<_>>()
    };
    assert_eq!(counts(Allocation::Proximity), vec![4, 0]);
    assert_eq!(counts(Allocation::LocalRobust), vec![4, 0]);
    assert_eq!(counts(Allocation::Balanced), vec![2, 2]);
    // And the plans of all three recheck clean.
    for a in [
        Allocation::Proximity,
        Allocation::LocalRobust,
        Allocation::Balanced,
    ] {
        let s = settings(a);
        let outcome = plan::plan(&cell, &table, &s, &|_| {}).unwrap();
        let doc = build(&cell, &table, &outcome, &s);
        check_plan(&cell, &doc);
        verified(&cell, &doc);
    }
}

/// Faults injected into a good plan are each caught by the verifier.
#[test]
fn the_verifier_catches_injected_faults() {
    let f = fixture();
    let s = settings(Allocation::Balanced);
    let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).unwrap();
    let good = build(&f.cell, &f.table, &outcome, &s);
    let quiet = VerifySettings::default();
    assert!(verify(&f.cell, &good, &quiet).ok);
    let kinds = |doc: &output::Plan| -> Vec<ViolationKind> {
        verify(&f.cell, doc, &quiet)
            .violations
            .iter()
            .map(|v| v.kind)
            .collect()
    };
    let busy = good.robots.iter().position(|r| !r.tasks.is_empty()).unwrap();
    // A skipped MP.
    let mut skipped = good.clone();
    skipped.robots[busy].tasks.remove(0);
    assert!(kinds(&skipped).contains(&ViolationKind::MissingTask));
    // A joint-limit breach in the trajectory.
    let mut breach = good.clone();
    let n = breach.robots[busy].trajectory.len();
    breach.robots[busy].trajectory[n / 2].q[0] = 10.0;
    let k = kinds(&breach);
    assert!(
        k.contains(&ViolationKind::JointLimit) && k.contains(&ViolationKind::Velocity),
        "{k:?}"
    );
    // A measuring pose turned away from its MP.
    let mut turned = good.clone();
    turned.robots[busy].tasks[0].q[4] += 0.5; // tilt the wrist: the beam leaves the view cone
    assert!(kinds(&turned).contains(&ViolationKind::ProbeConstraint));
    // A cycle time that does not match.
    let mut fudged = good.clone();
    fudged.cycle_time_s -= 1.0;
    assert!(kinds(&fudged).contains(&ViolationKind::Totals));
    // A leg waypoint pushed into the part: the home-to-first-MP leg detoured through the car.
    let mut through = good.clone();
    let leg = &mut through.robots[busy].legs[0];
    let mid: Vec<f64> = leg.waypoints[0]
        .iter()
        .zip(leg.waypoints.last().unwrap())
        .map(|(a, b)| 0.5 * (a + b))
        .collect();
    let mut into = mid.clone();
    into[1] += 0.9; // lean far forward, into the car
    leg.waypoints.insert(1, into);
    let k = kinds(&through);
    assert!(
        k.iter().any(|k| matches!(
            k,
            ViolationKind::StaticClearance | ViolationKind::SelfCollision | ViolationKind::JointLimit
        )),
        "{k:?}"
    );
}

/// The two bundled example cells, whole, with the default settings: the plans re-check clean.
#[test]
fn both_example_cells_plan_and_recheck_clean() {
    for name in ["autobody-2r", "autobody-4r"] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../examples/{name}/cell.toml"));
        let cell = load(&path, &LoadOptions::default()).expect("the example loads");
        let table = generate(&cell);
        let s = PlanSettings {
            time_limit: std::time::Duration::from_secs(3600),
            ..PlanSettings::default()
        };
        let outcome = plan::plan(&cell, &table, &s, &|_| {}).expect("the example plans");
        let doc = build(&cell, &table, &outcome, &s);
        assert!(
            doc.unmeasured.is_empty(),
            "{name}: every MP of the examples is measurable"
        );
        check_plan(&cell, &doc);
        verified(&cell, &doc);
    }
}

/// The lazy bar: a robot whose best order cannot finish below the bar stops before planning a
/// leg; with no bar it finishes, and its real time is what the bar is measured against.
#[test]
fn sequencing_against_a_bar_stops_before_planning() {
    let f = fixture();
    let s = settings(Allocation::Balanced);
    let robot = &f.cell.robots[0];
    let graph =
        plan::graph::RobotGraph::new(&f.cell, robot, &f.table, plan::MoveModel::Trapezoid, 8, s.roomy);
    let tasks: Vec<TaskId> = (0..f.cell.tasks.len())
        .map(TaskId)
        .filter(|&t| !graph.alternatives[t.0].is_empty())
        .take(3)
        .collect();
    assert_eq!(tasks.len(), 3, "the robot measures at least three MPs");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(3600);
    let measure = cellplan_optical::of(&f.cell).unwrap().measure_time;
    // Three measurements alone take longer than this bar.
    let bar = 3.0 * measure - 1e-3;
    let run = |bar: f64, planned: &mut plan::sequence::Planned| {
        plan::sequence::sequence(&f.cell, robot, &graph, &tasks, &s, deadline, bar, None, planned).unwrap()
    };
    let mut planned = plan::sequence::Planned::new();
    let beaten = run(bar, &mut planned);
    assert!(beaten.beaten && beaten.nodes.is_empty() && beaten.legs.is_empty());
    assert!(planned.is_empty(), "no leg planned for a hopeless allocation");
    let done = run(f64::INFINITY, &mut planned);
    assert!(!done.beaten);
    assert_eq!(done.nodes.len(), 3);
    assert_eq!(done.legs.len(), 4);
    let real = plan::sequence::order_cost(&graph, &planned, &done.nodes);
    assert!(real < plan::sequence::NO_PATH && real > 3.0 * measure);
    // A bar just above the real time does not stop it.
    let kept = run(real + 1.0, &mut planned.clone());
    assert!(!kept.beaten);
}

/// What the planned legs say is used before any search: a leg between two nodes that planned
/// legs join is those legs end to end (shortcut), from one end to the other and clear of the
/// scene at the clearance (re-sampled at 1 mrad), with no sampling; a node a full search from
/// home's component did not reach is never searched again, and once two candidates of a task
/// are such nodes, none of its other candidates outside home's component is.
#[test]
fn planned_legs_join_nodes_and_unreached_nodes_are_not_searched_again() {
    use cellplan_motion::plan::PlanError as Motion;
    use plan::sequence::{Leg, Planned, Reach};
    let f = fixture();
    let cell = &f.cell;
    let s = settings(Allocation::Balanced);
    let robot = &cell.robots[0];
    let graph = plan::graph::RobotGraph::new(cell, robot, &f.table, plan::MoveModel::Trapezoid, 8, s.roomy);
    let full = s.final_max_samples;
    // Two candidates with straight legs home → a → b (planned the way the sequencer plans).
    let none = Planned::new();
    let reach = Reach::of(&graph, &none, full);
    let straight = |a: usize, b: usize| {
        reach
            .leg(cell, robot, &graph, &none, a, b, &s, false)
            .ok()
            .filter(|l| l.straight)
    };
    let nodes: Vec<usize> = (1..graph.len()).collect();
    let (a, b, home_a, a_b) = nodes
        .iter()
        .filter_map(|&a| straight(0, a).map(|l| (a, l)))
        .find_map(|(a, home_a)| {
            nodes
                .iter()
                .filter(|&&b| b > a && graph.node_task[b].map(|x| x.0) != graph.node_task[a].map(|x| x.0))
                .find_map(|&b| straight(a, b).map(|l| (a, b, home_a.clone(), l)))
        })
        .expect("two candidates with straight legs from home");
    let mut planned = Planned::new();
    planned.insert((0, a), Ok(home_a.clone()));
    planned.insert((a, b), Ok(a_b.clone()));
    let reach = Reach::of(&graph, &planned, full);
    assert!(reach.joined(0, b) && !reach.is_cut_off(b));
    let joined: Leg = reach
        .leg(cell, robot, &graph, &planned, 0, b, &s, true)
        .expect("the planned legs join home and b");
    assert_eq!(joined.samples, 0, "no sampling for joined nodes");
    assert!(dist(&joined.waypoints[0], &graph.q[0]) < 1e-12);
    assert!(dist(joined.waypoints.last().unwrap(), &graph.q[b]) < 1e-12);
    let mut scratch = Scratch::default();
    for w in joined.waypoints.windows(2) {
        let steps = (dist(&w[0], &w[1]) / 1e-3).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let q: Vec<f64> = w[0].iter().zip(&w[1]).map(|(x, y)| x + t * (y - x)).collect();
            assert!(robot.within_limits(&q));
            robot.body_poses(&q, &mut scratch);
            assert!(
                robot
                    .contact_at(&cell.world, &scratch, cell.planning.clearance - 1e-6)
                    .is_none(),
                "the joined leg comes closer than the clearance at {q:?}"
            );
        }
    }
    // A full search from home's component that found nothing cuts the node off; a search
    // between two nodes outside it does not.
    let task_nodes = |n: usize| graph.alternatives[graph.node_task[n].unwrap().0.0].clone();
    let other = (1..graph.len())
        .find(|&n| {
            !reach.joined(n, 0)
                && task_nodes(n).len() >= 4
                && task_nodes(n).iter().all(|&m| !reach.joined(m, 0))
        })
        .expect("a task with four candidates outside home's component");
    let siblings = task_nodes(other);
    let failed = |samples| {
        Err(plan::LegError::Motion(Motion::NoPath {
            samples,
            validity_calls: 10 * samples,
        }))
    };
    let mut cut = planned.clone();
    cut.insert((a, siblings[0]), failed(full));
    cut.insert(
        (siblings[2].min(siblings[3]), siblings[2].max(siblings[3])),
        failed(full),
    );
    let reach = Reach::of(&graph, &cut, full);
    assert!(reach.is_cut_off(siblings[0]));
    assert!(
        !reach.is_cut_off(siblings[1]),
        "one cut-off candidate leaves the task's others"
    );
    assert!(!reach.is_cut_off(siblings[2]) && !reach.is_cut_off(siblings[3]));
    match reach.leg(cell, robot, &graph, &cut, b, siblings[0], &s, true) {
        Err(plan::LegError::Unreached(u)) => assert_eq!(u.samples, full),
        other => panic!("a cut-off node is searched again: {other:?}"),
    }
    // A quick failure is no proof.
    let mut quick = planned.clone();
    quick.insert((a, siblings[0]), failed(60));
    assert!(!Reach::of(&graph, &quick, full).is_cut_off(siblings[0]));
    // Two candidates cut off: the task is given up on this robot.
    cut.insert((0, siblings[1]), failed(full));
    let reach = Reach::of(&graph, &cut, full);
    assert!(siblings.iter().all(|&n| reach.is_cut_off(n)));
    assert!(!reach.is_cut_off(a) && !reach.is_cut_off(b) && !reach.is_cut_off(0));
}

/// A leg the sampler cannot solve never loses the plan: with no samples at all (and no
/// roadmap), every leg that is not a straight segment fails; a task every order reaches only through such legs
/// is given up by its robot, tried on the other robot, and listed unmeasured (`no-path`, with
/// the planner's words) — the rest is planned and the verifier accepts the plan.
#[test]
fn a_task_without_a_path_is_given_up_and_the_rest_planned() {
    let f = fixture();
    let mut s = settings(Allocation::Balanced);
    s.motion.max_samples = 1;
    s.final_max_samples = 1;
    s.roadmap = false;
    s.alternatives = 1;
    let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).expect("a plan despite the legs");
    let doc = build(&f.cell, &f.table, &outcome, &s);
    assert!(
        !outcome.unreached.is_empty(),
        "this budget must leave some task without a path"
    );
    for u in &outcome.unreached {
        let name = &f.cell.tasks[u.0.0].name;
        let listed = doc.unmeasured.iter().find(|x| &x.task == name).expect("listed");
        assert_eq!(listed.reason, output::NO_PATH);
        assert!(
            listed
                .detail
                .as_deref()
                .is_some_and(|d| d.contains("no collision-free path"))
        );
        assert!(doc.robots.iter().all(|r| r.tasks.iter().all(|v| &v.task != name)));
    }
    let done: usize = doc.robots.iter().map(|r| r.tasks.len()).sum();
    assert_eq!(done + doc.unmeasured.len(), f.cell.tasks.len());
    assert!(done > 0);
    check_plan(&f.cell, &doc);
    verified(&f.cell, &doc);
    // With the robots at (or next to) their task cap, a task given up stays unmeasured rather
    // than push a robot over its cap (a random task set of `compare` once did: 15 MPs under
    // φ = 14, which the verifier rejected).
    let path = example_copy("plan-test-capped", "autobody-2r-small", 8, |text| {
        let t = text.replace("task_cap = 14", "task_cap = 4");
        assert!(t.contains("task_cap = 4"));
        t
    });
    let cell = load(&path, &LoadOptions::default()).expect("the capped cell loads");
    let table = generate(&cell);
    let outcome = plan::plan(&cell, &table, &s, &|_| {}).expect("a plan despite the legs");
    assert!(!outcome.unreached.is_empty());
    assert!(outcome.allocated.tasks.iter().all(|t| t.len() <= 4));
    let doc = build(&cell, &table, &outcome, &s);
    check_plan(&cell, &doc);
    verified(&cell, &doc);
}

/// The zones allocation starts from the nearest robot and only hands tasks on while the
/// robots' lower-bound times, sorted longest first, fall: its busiest robot is never busier
/// (on those bounds) than the proximity allocation's, every task goes to a robot that can do
/// it, and the plan it gives verifies.
#[test]
fn zones_never_make_the_busiest_robot_busier_than_proximity() {
    let f = fixture();
    let busiest = |allocation: Allocation| {
        let s = settings(allocation);
        let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).expect("the reduced cell plans");
        let worst = outcome
            .graphs
            .iter()
            .zip(&outcome.allocated.tasks)
            .map(|(g, tasks)| {
                let order = plan::sequence::best_order(g, tasks, &Default::default(), 0);
                plan::sequence::order_cost(g, &Default::default(), &order)
            })
            .fold(0.0, f64::max);
        for (r, tasks) in outcome.allocated.tasks.iter().enumerate() {
            for t in tasks {
                assert!(!f.table.get(*t, cellplan_model::RobotId(r)).candidates.is_empty());
            }
        }
        (worst, outcome, s)
    };
    let (prox, ..) = busiest(Allocation::Proximity);
    let (zones, outcome, s) = busiest(Allocation::Zones);
    assert!(zones <= prox + 1e-6, "zones {zones} vs proximity {prox}");
    let doc = build(&f.cell, &f.table, &outcome, &s);
    check_plan(&f.cell, &doc);
    verified(&f.cell, &doc);
}

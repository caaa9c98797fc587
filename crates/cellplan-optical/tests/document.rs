//! The plan document of `cellplan plan` and its verifier: every key the schema requires is
//! written, edited plans are refused or caught, injected faults are caught.
mod common;
use cellplan_core::coord;
use cellplan_core::document as output;
use cellplan_core::plan::{self, Allocation, PlanSettings};
use cellplan_verify::{VerifySettings, ViolationKind, verify};
use common::*;

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

/// The leg check proves its verdict between the configurations it measures: legs rerouted
/// through random via points, each checked densely here (every joint stepping at most 0.1
/// mrad) — a leg the verifier passes keeps at least the clearance less its tolerance from the
/// scene everywhere, and one that comes closer anywhere is reported.
#[test]
fn the_leg_check_is_proven_between_its_samples() {
    use cellplan_model::robot::Scratch;
    use rand::{RngExt, SeedableRng};
    let f = fixture();
    let s = settings(Allocation::Proximity);
    let outcome = plan::plan(&f.cell, &f.table, &s, &|_| {}).unwrap();
    let good = build(&f.cell, &f.table, &outcome, &s);
    let quiet = VerifySettings {
        robot_robot: false,
        ..VerifySettings::default()
    };
    let clearance = f.cell.planning.clearance;
    let floor = clearance - cellplan_verify::PROOF_TOLERANCE;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let (mut passed, mut caught) = (0, 0);
    for case in 0..16 {
        let mut doc = good.clone();
        let r = case % doc.robots.len();
        let robot = &f
            .cell
            .robots
            .iter()
            .find(|x| x.name == doc.robots[r].name)
            .unwrap();
        if doc.robots[r].legs.is_empty() {
            continue;
        }
        let l = rng.random_range(0..doc.robots[r].legs.len());
        let leg = &mut doc.robots[r].legs[l];
        let (a, b) = (leg.waypoints[0].clone(), leg.waypoints.last().unwrap().clone());
        let via: Vec<f64> = a
            .iter()
            .zip(&b)
            .map(|(x, y)| 0.5 * (x + y) + rng.random_range(-0.4..0.4))
            .collect();
        leg.waypoints = vec![a, via, b];
        leg.blends.clear();
        leg.straight = false;
        // The dense check of the new path.
        let mut scratch = Scratch::default();
        let mut bad = false;
        for w in leg.waypoints.windows(2) {
            let travel = w[0]
                .iter()
                .zip(&w[1])
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            let n = (travel / 1e-4).ceil() as usize;
            for k in 0..=n {
                let t = k as f64 / n as f64;
                let q: Vec<f64> = w[0].iter().zip(&w[1]).map(|(x, y)| x + t * (y - x)).collect();
                robot.body_poses(&q, &mut scratch);
                if !robot.within_limits(&q) || robot.contact_at(&f.cell.world, &scratch, floor).is_some() {
                    bad = true;
                    break;
                }
            }
        }
        let name = doc.robots[r].name.clone();
        let found = verify(&f.cell, &doc, &quiet).violations.iter().any(|v| {
            v.robot.as_deref() == Some(name.as_str())
                && matches!(
                    v.kind,
                    ViolationKind::StaticClearance | ViolationKind::SelfCollision | ViolationKind::JointLimit
                )
        });
        if bad {
            assert!(found, "case {case}: the path comes within {floor} m and passed");
            caught += 1;
        } else if !found {
            passed += 1;
        }
    }
    assert!(passed > 0 && caught > 0, "{passed} passed, {caught} caught");
}

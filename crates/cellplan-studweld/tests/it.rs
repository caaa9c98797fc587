//! Integration tests of the stud-weld process on small cells made from the example's
//! (`examples/studweld-kr210`): the refusals of bad input, the alternatives, the unweldable
//! report, and plans that go through the independent verifier (which must also catch broken
//! plans). Heavy runs (the whole example) are `#[ignore]`.
use cellplan_model::LoadOptions;
use cellplan_studweld::cell::WeldCell;
use cellplan_studweld::document::{WeldPlan, build};
use cellplan_studweld::leg::{Dmoc, LegSettings, Motion};
use cellplan_studweld::plan::run;
use cellplan_studweld::sequence::Sequencer;
use cellplan_verify::studweld::{WeldViolationKind, verify_weld};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// A copy of the example cell in a temporary folder with its first `studs` studs (plus
/// `extra` CSV lines), its data paths absolute, and `edit` applied to the cell text.
fn cell(studs: usize, extra: &str, edit: &dyn Fn(String) -> String) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let ex = root().join("examples/studweld-kr210");
    let text = std::fs::read_to_string(ex.join("cell.toml"))
        .unwrap()
        .replace("../../data", &root().join("data").display().to_string());
    let path = dir.path().join("cell.toml");
    std::fs::write(&path, edit(text)).unwrap();
    let csv = std::fs::read_to_string(ex.join("studs.csv")).unwrap();
    let mut lines: Vec<&str> = csv.lines().take(studs + 1).collect();
    lines.extend(extra.lines());
    std::fs::write(dir.path().join("studs.csv"), lines.join("\n") + "\n").unwrap();
    (dir, path)
}

/// A quick variant: 3 gun rotations, 6 DMOC steps.
fn quick(t: String) -> String {
    t.replace("gun_rotation_step = 45", "gun_rotation_step = 120")
        .replace("steps = 12 ", "steps = 6 ")
}

#[allow(clippy::result_large_err)]
fn load(path: &Path) -> Result<cellplan_model::Cell, cellplan_model::InputError> {
    cellplan_studweld::load(path, &LoadOptions::default())
}

#[test]
fn bad_weights_and_weld_time_are_refused_at_their_line() {
    for (from, to, key) in [
        ("weld_time = 2.0 ", "weld_time = 0 ", "weld_time"),
        ("effort = 1e-6", "effort = -1e-6", "effort"),
        ("time = 1.0,", "time = 0.0,", "time"),
    ] {
        let (_d, path) = cell(1, "", &|t| t.replace(from, to));
        let e = load(&path).err().unwrap_or_else(|| panic!("{key}: accepted"));
        let shown = format!("{e:?}");
        assert!(shown.contains(key), "{key}: {shown}");
        let line = e.line.unwrap_or(0);
        let text = std::fs::read_to_string(&path).unwrap();
        let at = text.lines().nth(line.saturating_sub(1)).unwrap_or("");
        assert!(at.contains(to.trim()), "{key}: line {line} is `{at}`");
    }
}

#[test]
fn a_urdf_without_inertials_names_the_link() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = std::fs::read_to_string(root().join("data/robots/kuka_kr210/urdf/kr210l150.urdf")).unwrap();
    // Drop link_3's <inertial>.
    let at = urdf.find("<link name=\"link_3\">").unwrap();
    let start = at + urdf[at..].find("<inertial>").unwrap();
    let end = start + urdf[start..].find("</inertial>").unwrap() + "</inertial>".len();
    let stripped = format!("{}{}", &urdf[..start], &urdf[end..]);
    let file = dir.path().join("kr210.urdf");
    std::fs::write(&file, stripped).unwrap();
    let (_d, path) = cell(1, "", &|t| {
        t.replace(
            &root()
                .join("data/robots/kuka_kr210/urdf/kr210l150.urdf")
                .display()
                .to_string(),
            &file.display().to_string(),
        )
    });
    let c = load(&path).unwrap();
    let e = WeldCell::new(&c).err().expect("refused");
    assert!(e.message.contains("`link_3`"), "{}", e.message);
}

#[test]
fn alternatives_are_ik_branches_times_rotations_each_on_the_stud() {
    let (_d, path) = cell(3, "", &|t| t);
    let c = load(&path).unwrap();
    let w = WeldCell::new(&c).unwrap();
    let alts = cellplan_studweld::alternatives::alternatives(&w);
    let validity = cellplan_core::motion::robot_validity(&c, w.robot, c.planning.clearance);
    for (s, list) in alts.per_stud.iter().enumerate() {
        // Table 1's range is 6–36.
        assert!((6..=40).contains(&list.len()), "stud {s}: {}", list.len());
        let rotations: std::collections::BTreeSet<u64> = list.iter().map(|a| a.rotation.to_bits()).collect();
        assert!(rotations.len() > 1, "stud {s}: one rotation only");
        for a in list {
            let tcp = w.robot.tcp_pose(&a.q);
            assert!((tcp.translation - c.tasks[s].position).length() < 1e-6);
            assert!(validity.is_valid(&a.q));
            assert!(a.weld_cost >= 2.0, "at least c_t · weld time");
        }
    }
}

#[test]
fn a_stud_out_of_reach_is_unweldable_and_the_rest_is_planned_and_verified() {
    let (_d, path) = cell(1, "FAR,-3000,0,800,1,0,0,surface", &quick);
    let c = load(&path).unwrap();
    let w = WeldCell::new(&c).unwrap();
    let out = run(&w, &[Sequencer::OptimalControl], &LegSettings::default()).unwrap();
    assert_eq!(out.alternatives.unweldable.len(), 1);
    assert_eq!(out.alternatives.unweldable[0].1.code(), "no-ik");
    let doc = build(&w, &out, &out.outcomes[0]);
    assert_eq!(doc.visits.len(), 1);
    assert_eq!(doc.unweldable[0].stud, "FAR");
    let r = verify_weld(&c, &doc);
    assert!(r.ok, "{:?}", r.violations);
    assert!(r.max_dynamics_residual < 1e-6);

    // The verifier catches a changed torque, a moved weld pose, a wrong total and a move bent
    // down into the part between its ends (its clearance is not proven).
    let kinds = |p: &WeldPlan| -> Vec<WeldViolationKind> {
        verify_weld(&c, p).violations.iter().map(|v| v.kind).collect()
    };
    let mut bad = doc.clone();
    first_ocp(&mut bad).u[1][1] += 5.0;
    assert!(
        kinds(&bad).contains(&WeldViolationKind::Dynamics),
        "{:?}",
        kinds(&bad)
    );
    let mut bad = doc.clone();
    bad.visits[0].q[5] += 0.01;
    assert!(
        kinds(&bad).contains(&WeldViolationKind::Weld),
        "{:?}",
        kinds(&bad)
    );
    let mut bad = doc.clone();
    bad.totals.weld_cost *= 0.5;
    assert!(
        kinds(&bad).contains(&WeldViolationKind::Total),
        "{:?}",
        kinds(&bad)
    );
    let mut bad = doc;
    let d = first_ocp(&mut bad);
    let n = d.q.len();
    for q in &mut d.q[1..n - 1] {
        q[1] += 0.9;
        q[2] += 0.9;
    }
    assert!(
        kinds(&bad).contains(&WeldViolationKind::Collision),
        "{:?}",
        kinds(&bad)
    );
}

#[test]
fn both_sequencers_plan_two_studs_and_their_plans_verify() {
    let (_d, path) = cell(2, "", &quick);
    let c = load(&path).unwrap();
    let w = WeldCell::new(&c).unwrap();
    let out = run(
        &w,
        &[Sequencer::TravelTime, Sequencer::OptimalControl],
        &LegSettings::default(),
    )
    .unwrap();
    let [old, new] = out.outcomes.as_slice() else {
        panic!()
    };
    for o in [old, new] {
        let doc = build(&w, &out, o);
        let r = verify_weld(&c, &doc);
        assert!(r.ok, "{}: {:?}", o.sequencer.name(), r.violations);
        assert_eq!(doc.visits.len(), 2);
        assert!((o.cost - o.travel_cost - o.weld_cost).abs() < 1e-9);
    }
    // The optimal-control sequence is chosen on J: with every edge of its tour solved and the
    // GTSP exact, it is no worse than the travel-time sequence under the same costs.
    assert!(new.sequence.converged && new.sequence.exact);
    assert!(
        new.cost <= old.cost * (1.0 + 1e-9),
        "new {} old {}",
        new.cost,
        old.cost
    );
}

#[test]
#[ignore = "the whole example: minutes (release: `cargo test -p cellplan-studweld --release -- --ignored`)"]
fn the_example_cell_plans_and_verifies() {
    let path = root().join("examples/studweld-kr210/cell.toml");
    let c = load(&path).unwrap();
    let w = WeldCell::new(&c).unwrap();
    let out = run(
        &w,
        &[Sequencer::TravelTime, Sequencer::OptimalControl],
        &LegSettings::default(),
    )
    .unwrap();
    assert!(out.alternatives.unweldable.is_empty());
    for o in &out.outcomes {
        let doc = build(&w, &out, o);
        let r = verify_weld(&c, &doc);
        assert!(r.ok, "{}: {:?}", o.sequencer.name(), r.violations);
        eprintln!(
            "{}: J {:.1} (travel {:.1}, welding {:.1}), cycle {:.2} s",
            o.sequencer.name(),
            o.cost,
            o.travel_cost,
            o.weld_cost,
            o.cycle_time
        );
    }
}

/// §2.4 on moves whose unconstrained optimum collides: the trust-region iteration starts from
/// the dynamics' trajectory nearest a path with room and returns a clear DMOC trajectory cheaper
/// than the timed path — where it used to fall back to the timed path.
#[test]
fn trust_regions_give_clear_trajectories_where_the_optimum_collides() {
    use cellplan_ocp::nlp;
    use cellplan_studweld::leg;
    let (_d, path) = cell(2, "", &quick);
    let c = load(&path).unwrap();
    let w = WeldCell::new(&c).unwrap();
    let alts = cellplan_studweld::alternatives::alternatives(&w);
    let s = LegSettings::default();
    let opt = nlp::Options {
        tol: 1e-8,
        max_iter: s.max_iter,
        ..nlp::Options::default()
    };
    let mut tried = 0;
    for a in alts.per_stud[1].iter().take(4) {
        let (from, to) = (&w.robot.home, &a.q);
        let p = leg::path(&w, from, to, &s).expect("a path from home");
        let m = cellplan_ocp::problem::Move {
            steps: leg::steps_for(&w, &p),
            ..leg::ocp(&w, from, to)
        };
        let free = nlp::ipm::solve(&m, &opt);
        if leg::clear(&w, &leg::unpack(&m, &free.x).q) {
            continue;
        }
        tried += 1;
        let l = leg::solve(&w, from, to, &s).unwrap();
        let Motion::Ocp(traj) = &l.motion else {
            panic!("a timed path: {:?}", l.fallback)
        };
        assert!(l.trust_iterations > 0 && l.fallback.is_none());
        assert!(leg::clear(&w, &traj.q));
        assert_eq!((traj.q.first(), traj.q.last()), (Some(from), Some(to)));
        let (timed, _, _) = leg::timed_path(&w, &p);
        assert!(l.cost < timed, "J {} against the timed path's {timed}", l.cost);
        assert!(
            l.cost >= free.objective - 1e-6,
            "J {} below the unconstrained optimum {}",
            l.cost,
            free.objective
        );
    }
    assert!(
        tried > 0,
        "no move of the first alternatives collides unconstrained"
    );
}

/// The first move of `p` solved as an optimal control problem, to edit.
fn first_ocp(p: &mut WeldPlan) -> &mut Dmoc {
    p.legs
        .iter_mut()
        .find_map(|l| match &mut l.motion {
            Motion::Ocp(d) => Some(d),
            _ => None,
        })
        .expect("an OCP leg")
}

//! The motion-problem format and the arm set up from it, on the MBM UR5 files of bench/motion
//! and on broken files.
use cellplan_motion::arm;
use cellplan_motion::plan::{self, PlannerParams, SegmentMotion, Termination, check_segment};
use cellplan_motion::problem::{ArmSetup, ProblemError, read_problems};
use std::path::{Path, PathBuf};

fn mbm(scene: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../bench/motion/mbm-ur5/{scene}.json"))
}

#[test]
fn reads_the_mbm_files_and_sets_up_the_ur5() {
    let set = read_problems(&mbm("box")).unwrap();
    assert_eq!(set.problems.len(), 100);
    assert_eq!(set.joints.len(), 6);
    let setup = ArmSetup::load(&set).unwrap();
    // One body per collision shape: the arm's links, the F/T sensor and the gripper's parts.
    assert!(setup.body_links.len() >= 17, "{}", setup.body_links.len());
    assert!(
        setup
            .body_sources
            .iter()
            .any(|s| s == "robotiq_85_left_finger_tip_link")
    );
    // The SRDF's rules leave out adjacent and never-touching pairs; the rest are checked.
    let named = |a: &str, b: &str| {
        setup.self_pairs.iter().any(|&(i, j)| {
            let (x, y) = (&setup.body_sources[i], &setup.body_sources[j]);
            (x == a && y == b) || (x == b && y == a)
        })
    };
    assert!(!named("forearm_link", "wrist_1_link"), "adjacent pair checked");
    assert!(named("base_link", "robotiq_85_left_finger_tip_link"));
    // The file's joint order maps to the chain's and back.
    let q = &set.problems[0].start;
    assert_eq!(&setup.to_file(&setup.to_chain(q)), q);
}

#[test]
fn starts_and_goals_of_the_mbm_problems_are_valid_with_fitted_bodies() {
    // With one hull per link (the gripper a solid block) most grasp goals were "in collision";
    // with one body per shape the starts and goals of the first problems are free.
    let set = read_problems(&mbm("table_pick")).unwrap();
    let mut setup = ArmSetup::load(&set).unwrap();
    let mut valid = 0;
    for p in &set.problems[..10] {
        setup.set_obstacles(&p.obstacles);
        let v = setup.validity(p.margin);
        valid += usize::from(v.is_valid(&setup.to_chain(&p.start)));
        valid += usize::from(v.is_valid(&setup.to_chain(&p.goals[0])));
    }
    assert!(valid >= 18, "{valid} of 20 starts and goals valid");
}

/// The UR5 among the shelves of `bookshelf_small`'s fourth problem, with its start and goal.
fn shelves() -> (ArmSetup, Vec<f64>, Vec<f64>) {
    let set = read_problems(&mbm("bookshelf_small")).unwrap();
    let mut setup = ArmSetup::load(&set).unwrap();
    let p = &set.problems[3];
    setup.set_obstacles(&p.obstacles);
    let (start, goal) = (setup.to_chain(&p.start), setup.to_chain(&p.goals[0]));
    (setup, start, goal)
}

#[test]
fn the_broad_phase_changes_no_answer() {
    use cellplan_motion::plan::StateValidity;
    let (setup, start, goal) = shelves();
    let fast = setup.validity(0.0);
    let mut exact = setup.validity(0.0);
    exact.broad_phase = false;
    // With the bounds taken at the sample, a part's bound grows with the step it is asked at,
    // so a step the broad phase shortens early (a part taken at its cover bound) may end a
    // little longer than the exact checker's: both proven. Without them, never longer.
    let (mut fast_fixed, mut exact_fixed) = (setup.validity(0.0), setup.validity(0.0));
    exact_fixed.broad_phase = false;
    fast_fixed.posed_radii = false;
    exact_fixed.posed_radii = false;
    let space = arm::joint_space(&setup.arm(), &[]);
    let mut q = Vec::new();
    let (mut valid, mut steps) = (0, 0);
    for k in 0..=200 {
        space.interpolate(&start, &goal, k as f64 / 200.0, &mut q);
        let a = fast.is_valid(&q);
        assert_eq!(a, exact.is_valid(&q), "at {k}");
        assert_eq!(
            a,
            fast.clearance(&q) > 0.0,
            "is_valid and clearance disagree at {k}"
        );
        valid += usize::from(a);
        let motion = SegmentMotion::new(&vec![1.0; q.len()], &vec![1.0; q.len()]);
        let s1 = fast.segment_step(&q, &motion, 1e-4, 1.0);
        let s2 = exact.segment_step(&q, &motion, 1e-4, 1.0);
        assert_eq!(s1.is_some(), s2.is_some(), "at {k}");
        if let (Some(s1), Some(s2)) = (s1, s2) {
            assert!(s1 <= s2 * 1.01, "{s1} > {s2} at {k}");
            steps += 1;
        }
        let s1 = fast_fixed.segment_step(&q, &motion, 1e-4, 1.0);
        let s2 = exact_fixed.segment_step(&q, &motion, 1e-4, 1.0);
        assert_eq!(s1.is_some(), s2.is_some(), "at {k}");
        if let (Some(s1), Some(s2)) = (s1, s2) {
            // The broad phase answers only what it proves: never a longer step (up to GJK's
            // own tolerance, which a remembered direction changes; DISTANCE_SLACK covers it).
            assert!(s1 <= s2 + 1e-9, "{s1} > {s2} at {k}");
        }
    }
    assert!(valid > 0 && steps > 0);
}

/// Segment checks with the broad phase (whose steps take a part at its cover bound when that
/// bound is enough for a good step, `ENOUGH_SHARE` in arm.rs) and with exact distances only
/// answer alike, on random segments near the shelves (valid and invalid ones).
#[test]
fn segment_checks_answer_as_with_exact_distances() {
    use rand::{RngExt, SeedableRng};
    let (setup, start, goal) = shelves();
    let fast = setup.validity(0.0);
    let mut exact = setup.validity(0.0);
    exact.broad_phase = false;
    let space = arm::joint_space(&setup.arm(), &[]);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let (mut valid, mut invalid) = (0, 0);
    let mut a = Vec::new();
    for _ in 0..40 {
        space.interpolate(&start, &goal, rng.random_range(0.0..1.0), &mut a);
        let b: Vec<f64> = a.iter().map(|x| x + rng.random_range(-0.4..0.4)).collect();
        let (f, e) = (
            check_segment(&space, &fast, &a, &b, 1e-4),
            check_segment(&space, &exact, &a, &b, 1e-4),
        );
        assert_eq!(f.valid, e.valid, "{a:?} → {b:?}");
        valid += usize::from(f.valid);
        invalid += usize::from(!f.valid);
    }
    assert!(valid >= 10 && invalid >= 5, "{valid} valid, {invalid} invalid");
}

#[test]
fn every_registered_planner_solves_an_mbm_problem_with_checked_segments() {
    let set = read_problems(&mbm("box")).unwrap();
    let mut setup = ArmSetup::load(&set).unwrap();
    let p = &set.problems[0];
    setup.set_obstacles(&p.obstacles);
    let v = setup.validity(p.margin);
    let space = arm::joint_space(&setup.arm(), &[]);
    let start = setup.to_chain(&p.start);
    let goals: Vec<Vec<f64>> = p.goals.iter().map(|g| setup.to_chain(g)).collect();
    for name in ["leg", "rrt-connect"] {
        let entry = plan::planner(name).unwrap();
        let query = plan::Problem::new(&space, &v, &start, &goals);
        let result = (entry.build)(&PlannerParams::default()).solve(&query, &Termination::samples(5_000));
        assert!(result.status.is_solved(), "{name}: {:?}", result.status);
        for w in result.waypoints.windows(2) {
            assert!(check_segment(&space, &v, &w[0], &w[1], 1e-4).valid, "{name}");
        }
    }
}

fn write(dir: &Path, text: &str) -> PathBuf {
    let f = dir.join("p.json");
    std::fs::write(&f, text).unwrap();
    f
}

#[test]
fn broken_files_are_refused_with_the_place() {
    let tmp = tempfile::tempdir().unwrap();
    let head = r#"{"format": "cellplan-motion-problems", "version": 1,
 "robot": {"urdf": "r.urdf"}, "joints": ["a", "b"],
 "problems": ["#;
    let cases: &[(&str, &str)] = &[
        ("{\"format\": 1", "1:"),
        (
            r#"{"format": "other", "version": 1, "robot": {"urdf": "r"}, "joints": ["a"], "problems": []}"#,
            "not \"cellplan-motion-problems\"",
        ),
        (
            &format!("{head}{{\"name\": \"p\", \"start\": [0, 0, 0], \"goals\": [[0, 0]]}}]}}"),
            "start has 3 values for 2 joints",
        ),
        (
            &format!("{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": []}}]}}"),
            "0 goals",
        ),
        (
            &format!("{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": [[0, 1e9]]}}]}}"),
            "not a joint value",
        ),
        (
            &format!(
                "{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": [[0, 0]], \"obstacles\": [{{\"shape\": \"cone\", \"pose\": {{\"xyz\": [0,0,0]}}}}]}}]}}"
            ),
            "unknown shape \"cone\"",
        ),
        (
            &format!(
                "{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": [[0, 0]], \"obstacles\": [{{\"shape\": \"sphere\", \"radius\": -1, \"pose\": {{\"xyz\": [0,0,0]}}}}]}}]}}"
            ),
            "radius = -1",
        ),
        (
            &format!(
                "{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": [[0, 0]], \"obstacles\": [{{\"shape\": \"box\", \"half_extents\": [1,1,1], \"pose\": {{\"xyz\": [0,0,0], \"quat_xyzw\": [0,0,0,2]}}}}]}}]}}"
            ),
            "not a unit quaternion",
        ),
        (
            &format!(
                "{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": [[0, 0]], \"obstacles\": [{{\"shape\": \"mesh\", \"pose\": {{\"xyz\": [0,0,0]}}}}]}}]}}"
            ),
            "a mesh needs `file`",
        ),
        (
            &format!(
                "{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": [[0, 0]], \"obstacles\": [{{\"name\": \"car\", \"shape\": \"mesh\", \"file\": \"none.stl\", \"pose\": {{\"xyz\": [0,0,0]}}}}]}}]}}"
            ),
            "obstacle 1 (\"car\"): ",
        ),
        (
            &format!(
                "{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": [[0, 0]], \"obstacles\": [{{\"shape\": \"mesh\", \"file\": \"m.obj\", \"scale\": 0, \"pose\": {{\"xyz\": [0,0,0]}}}}]}}]}}"
            ),
            "scale = 0",
        ),
        (
            r#"{"format": "cellplan-motion-problems", "version": 1, "joints": ["a"], "problems": [],
 "robot": {"urdf": "r.urdf", "tool": {"name": "probe", "shapes": []}}}"#,
            "robot.tool has 0 shapes",
        ),
        (
            r#"{"format": "cellplan-motion-problems", "version": 1, "joints": ["a"], "problems": [],
 "robot": {"urdf": "r.urdf", "tool": {"shapes": [{"shape": "box", "half_extents": [1, -1, 1], "pose": {"xyz": [0, 0, 0]}}]}}}"#,
            "robot.tool: shape 1: half_extents[1] = -1",
        ),
        (
            r#"{"format": "cellplan-motion-problems", "version": 1, "joints": ["a"], "problems": [],
 "robot": {"urdf": "r.urdf", "tool": {"shapes": [{"shape": "sphere", "radius": 0.1, "pose": {"xyz": [20, 0, 0]}}]}}}"#,
            "robot.tool: shape 1 reaches 20.100 m",
        ),
    ];
    for (text, expect) in cases {
        let f = write(tmp.path(), text);
        let e = read_problems(&f).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("p.json"), "{msg}");
        assert!(msg.contains(expect), "{msg} lacks {expect}");
        assert!(!e.hint().is_empty());
    }
    let missing = read_problems(&tmp.path().join("none.json")).unwrap_err();
    assert!(matches!(missing, ProblemError::Io { .. }));
    // A robot whose URDF is missing is refused when the arm is set up.
    let f = write(
        tmp.path(),
        &format!("{head}{{\"name\": \"p\", \"start\": [0, 0], \"goals\": [[0, 0]]}}]}}"),
    );
    let set = read_problems(&f).unwrap();
    assert!(matches!(ArmSetup::load(&set), Err(ProblemError::Robot(_))));
}

#[test]
fn the_tool_retracts_along_its_axis() {
    use cellplan_geom::{DQuat, DVec3, Pose};
    let set = read_problems(&mbm("table_pick")).unwrap();
    let setup = ArmSetup::load(&set).unwrap();
    let chain = &setup.model.chain;
    // A tool point 0.15 m out along the tip's z axis, turned a little.
    let tcp = Pose::from_parts(DVec3::new(0.0, 0.0, 0.15), DQuat::from_rotation_x(0.3));
    let q = setup.to_chain(&set.problems[0].goals[0]);
    let path = arm::tool_retract(chain, &tcp, &q, 0.1, 0.01).expect("a retract from a grasp");
    assert_eq!(path.len(), 11);
    assert_eq!(path[0], q);
    let at = |c: &[f64]| chain.fk_tip(c) * tcp;
    let start = at(&q);
    let axis = start.rotation * DVec3::Z;
    for (k, c) in path.iter().enumerate() {
        let p = at(c);
        // On the line behind the tool point, 1 cm per step, the orientation kept.
        let expected = start.translation - axis * (0.01 * k as f64);
        assert!((p.translation - expected).length() < 1e-5, "step {k}");
        assert!(p.rotation.angle_between(start.rotation) < 1e-5, "step {k}");
        assert!(chain.within_limits(c, 1e-9));
    }
    // Nothing to follow: no retract.
    assert!(arm::tool_retract(chain, &tcp, &q, 0.0, 0.01).is_none());
    assert!(arm::tool_retract(chain, &tcp, &q, f64::NAN, 0.01).is_none());
    // Far beyond the arm's reach: the line cannot be followed.
    assert!(arm::tool_retract(chain, &tcp, &q, 5.0, 0.01).is_none());
}

#[test]
fn a_robot_by_its_packages_among_mesh_obstacles() {
    // The car-body scene: a URDF with `package://` paths, the car body as a scaled OBJ mesh.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/motion/autobody-r2000/autobody.json");
    let set = read_problems(&path).unwrap();
    let body = &set.problems[0].obstacles[0];
    let cellplan_geom::ShapeSpec::Mesh(mesh) = &body.shape else {
        panic!("the car body is a mesh")
    };
    // Millimetres scaled to metres: the body is 4.4 m long.
    let length = mesh.vertices.iter().map(|v| v.y).fold(f64::MIN, f64::max)
        - mesh.vertices.iter().map(|v| v.y).fold(f64::MAX, f64::min);
    assert!((4.3..4.5).contains(&length), "{length}");
    // Every problem holds the same mesh, read once.
    let cellplan_geom::ShapeSpec::Mesh(again) = &set.problems[2].obstacles[0].shape else {
        panic!("the car body is a mesh")
    };
    assert!(std::sync::Arc::ptr_eq(mesh, again));
    let mut setup = ArmSetup::load(&set).unwrap();
    setup.set_obstacles(&set.problems[0].obstacles);
    let validity = setup.validity(0.01);
    assert!(validity.is_valid(&set.problems[0].start));
    // Reaching into the car body (joint 2 forward, the arm stretched down over it) collides
    // with its surface, the car body alone in the scene.
    setup.set_obstacles(&set.problems[0].obstacles[..1]);
    let validity = setup.validity(0.01);
    let mut exact = setup.validity(0.01);
    exact.broad_phase = false;
    let into = [0.0, 1.2, 0.6, 0.0, 0.0, 0.0];
    assert!(!validity.is_valid(&into), "the arm inside the car body's frame");
    assert!(!exact.is_valid(&into));
    assert!(validity.is_valid(&set.problems[0].start));
}

#[test]
fn the_tool_moves_with_the_tip_and_is_checked() {
    // The car-body scene's robot carries the README cell's probe: two bodies on the tip link
    // under the tool's name, never checked against the flange link it is mounted on, checked
    // against the links before it and the scene, and seen by the exact re-check too.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/motion/autobody-r2000/autobody.json");
    let set = read_problems(&path).unwrap();
    let tool = set.robot.tool.as_ref().expect("the scene has a tool");
    assert_eq!((tool.name.as_str(), tool.shapes.len()), ("probe", 2));
    let mut bare = set.clone();
    bare.robot.tool = None;
    let with = ArmSetup::load(&set).unwrap();
    let without = ArmSetup::load(&bare).unwrap();
    let probes: Vec<usize> = (0..with.body_sources.len())
        .filter(|&i| with.body_sources[i] == "probe")
        .collect();
    assert_eq!(probes.len(), 2);
    assert_eq!(with.body_links.len(), without.body_links.len() + 2);
    let tip = with.model.chain.links.len() - 1;
    assert!(probes.iter().all(|&i| with.body_links[i] == tip));
    let checked = |setup: &ArmSetup, a: &str, b: &str| {
        setup.self_pairs.iter().any(|&(i, j)| {
            let (x, y) = (&setup.body_sources[i], &setup.body_sources[j]);
            (x == a && y == b) || (x == b && y == a)
        })
    };
    assert!(
        !checked(&with, "probe", "link_6"),
        "the probe is checked against its flange"
    );
    assert!(checked(&with, "probe", "link_2") && checked(&with, "probe", "link_1"));
    // With an SRDF, its rules replace the adjacency rule, but the tool's mount still holds it.
    let tmp = tempfile::tempdir().unwrap();
    let srdf = tmp.path().join("r.srdf");
    std::fs::write(
        &srdf,
        r#"<robot name="r"><disable_collisions link1="base_link" link2="link_1" reason="Adjacent"/></robot>"#,
    )
    .unwrap();
    let mut ruled = set.clone();
    ruled.robot.srdf = Some(srdf);
    let ruled = ArmSetup::load(&ruled).unwrap();
    assert!(checked(&ruled, "link_5", "link_6") && checked(&ruled, "probe", "link_5"));
    assert!(
        !checked(&ruled, "probe", "link_6"),
        "the probe is checked against its flange"
    );
    // A tool named as a link of the URDF is refused, a link without shapes off the chain too
    // (the flange): SRDF rules naming it would apply to the tool.
    for link in ["link_6", "flange"] {
        let mut named = set.clone();
        named.robot.tool.as_mut().unwrap().name = link.into();
        let e = ArmSetup::load(&named).err().expect("refused");
        assert!(e.to_string().contains("as a link of the URDF"), "{e}");
    }
    // A ball where the probe's housing is at the start, clear of the arm without the tool.
    let chain = &with.model.chain;
    let q = with.to_chain(&set.problems[0].start);
    let housing = set.robot.base * chain.fk_tip(&q) * tool.shapes[1].1;
    let ball = cellplan_motion::problem::Obstacle {
        name: "ball".into(),
        shape: cellplan_geom::ShapeSpec::Sphere { radius: 0.02 },
        pose: cellplan_geom::Pose::from_translation(housing.translation),
    };
    let (mut with, mut without) = (with, without);
    with.set_obstacles(&[]);
    assert!(
        with.validity(0.0).is_valid(&q),
        "the arm with its probe is clear of itself"
    );
    with.set_obstacles(std::slice::from_ref(&ball));
    without.set_obstacles(std::slice::from_ref(&ball));
    assert!(!with.validity(0.0).is_valid(&q), "the probe holds the ball");
    assert!(without.validity(0.0).is_valid(&q), "the arm alone is clear of it");
    let mut exact = with.validity(0.0);
    exact.broad_phase = false;
    assert!(!exact.is_valid(&q));
}

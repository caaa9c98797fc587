//! The real robot files in data/robots: the FANUC R-2000iC/125L (OPW), the UR5 (DLS), and the
//! OPW parameters read off the FANUC, ABB and KUKA URDFs.
use cellplan_geom::ShapeSpec;
use cellplan_kin::{
    DlsIk, DlsParams, IkSolver, JointKind, KinError, OpwIk, OpwParameters, ParallelIk, TrackIk, load_urdf,
    pose_error,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::path::PathBuf;

fn data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

fn fanuc_packages() -> BTreeMap<String, PathBuf> {
    BTreeMap::from([(
        "fanuc_r2000ic_support".to_string(),
        data().join("robots/fanuc_r2000ic/fanuc_r2000ic_support"),
    )])
}

fn ur_packages() -> BTreeMap<String, PathBuf> {
    BTreeMap::from([(
        "ur_description".to_string(),
        data().join("robots/ur5/ur_description"),
    )])
}

fn fanuc_urdf() -> PathBuf {
    data().join("robots/fanuc_r2000ic/urdf/r2000ic125l.urdf")
}

fn fanuc_opw() -> OpwParameters {
    let path =
        data().join("robots/fanuc_r2000ic/fanuc_r2000ic_support/config/opw_parameters_r2000ic125l.yaml");
    OpwParameters::from_ros_yaml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn ur5_urdf() -> PathBuf {
    data().join("robots/ur5/urdf/ur5.urdf")
}

#[test]
fn fanuc_opw_matches_urdf() {
    let p = fanuc_opw();
    assert_eq!(p.c3, 1.730);
    assert!((p.offsets[2] + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    let model = load_urdf(&fanuc_urdf(), &fanuc_packages(), None).unwrap();
    let chain = &model.chain;
    assert_eq!(chain.tip_name(), "tool0");
    assert_eq!(chain.dof(), 6);
    let names: Vec<_> = chain.links.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "base_link",
            "link_1",
            "link_2",
            "link_3",
            "link_4",
            "link_5",
            "link_6",
            "tool0"
        ]
    );
    // One mesh per arm link; `base` and `flange` carry no geometry.
    for (i, shapes) in model.collision.iter().enumerate() {
        let expected = usize::from(i < 7);
        assert_eq!(shapes.len(), expected, "link {}", chain.links[i].name);
        if let Some((ShapeSpec::Mesh(m), _)) = shapes.first() {
            assert!(!m.triangles.is_empty());
            // ROS-I meshes are in metres: every link fits in a few metres and is not tiny.
            let (lo, hi) = m.aabb().unwrap();
            let size = (hi - lo).max_element();
            assert!(
                size > 0.1 && size < 3.0,
                "link {} mesh size {size}",
                chain.links[i].name
            );
        }
    }
    let ik = OpwIk::new(chain, p).expect("the ROS-I parameters match the URDF");
    let c = ik.flange_to_tip();
    println!("FANUC flange_to_tip C = {c:?}");
    assert!(c.translation.length() < 1e-12);
}

fn random_q(chain: &cellplan_kin::Chain, rng: &mut ChaCha8Rng) -> Vec<f64> {
    chain
        .joints
        .iter()
        .map(|j| rng.random_range(j.lower.max(-std::f64::consts::PI)..j.upper.min(std::f64::consts::PI)))
        .collect()
}

#[test]
fn fanuc_opw_solve_round_trip() {
    let model = load_urdf(&fanuc_urdf(), &fanuc_packages(), None).unwrap();
    let chain = &model.chain;
    let ik = OpwIk::new(chain, fanuc_opw()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut out = Vec::new();
    let mut worst = (0.0f64, 0.0f64);
    for _ in 0..500 {
        let q = random_q(chain, &mut rng);
        let target = chain.fk_tip(&q);
        out.clear();
        let raw = ik.solve(&target, &mut out);
        assert!((1..=8).contains(&raw), "raw branch count {raw}");
        assert!(
            out.iter()
                .any(|s| s.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-6)),
            "the configuration itself is among the solutions: {q:?} / {out:?}"
        );
        for s in &out {
            assert!(chain.within_limits(s, 0.0));
            let (dp, dr) = pose_error(&chain.fk_tip(s), &target);
            worst = (worst.0.max(dp), worst.1.max(dr));
        }
    }
    println!("FANUC OpwIk FK(IK) worst {:.2e} m {:.2e} rad", worst.0, worst.1);
    assert!(worst.0 < 1e-9 && worst.1 < 1e-9);
}

#[test]
fn fanuc_joints_4_and_6_get_two_pi_variants() {
    let model = load_urdf(&fanuc_urdf(), &fanuc_packages(), None).unwrap();
    let chain = &model.chain;
    let ik = OpwIk::new(chain, fanuc_opw()).unwrap();
    // Joints 4 and 6 range over ±360°: every branch comes with its ±2π variants.
    let q = [0.3, 0.2, -0.1, 0.5, 0.7, -0.4];
    let mut out = Vec::new();
    let raw = ik.solve(&chain.fk_tip(&q), &mut out);
    assert_eq!(raw, 8);
    assert!(out.len() > raw);
    let twins = out
        .iter()
        .filter(|s| (s[0] - q[0]).abs() < 1e-9 && (s[1] - q[1]).abs() < 1e-9 && (s[4] - q[4]).abs() < 1e-9)
        .count();
    assert_eq!(twins, 4, "q4 and q6 each in two turns: {out:?}");
}

#[test]
fn opw_parameters_that_do_not_fit_are_rejected() {
    let model = load_urdf(&fanuc_urdf(), &fanuc_packages(), None).unwrap();
    let mut p = fanuc_opw();
    p.c2 += 0.01;
    let err = OpwIk::for_robot(&model, p).unwrap_err();
    assert!(matches!(err, KinError::Opw { .. }), "{err}");
    let text = err.to_string();
    assert!(
        text.contains("do not match") && text.contains("r2000ic125l.urdf"),
        "{text}"
    );

    let mut p = fanuc_opw();
    p.sign_corrections[3] = 1.0;
    assert!(OpwIk::new(&model.chain, p).is_err());

    // The UR5 is no OPW arm.
    let ur5 = load_urdf(&ur5_urdf(), &ur_packages(), None).unwrap();
    let err = OpwIk::new(&ur5.chain, fanuc_opw()).unwrap_err();
    assert!(err.to_string().contains("do not match"), "{err}");
}

#[test]
fn ur5_loads_with_collision_meshes_only() {
    let model = load_urdf(&ur5_urdf(), &ur_packages(), None).unwrap();
    assert_eq!(model.name, "ur5_robot");
    let chain = &model.chain;
    let names: Vec<_> = chain.links.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "base_link",
            "base_link_inertia",
            "shoulder_link",
            "upper_arm_link",
            "forearm_link",
            "wrist_1_link",
            "wrist_2_link",
            "wrist_3_link",
            "flange",
            "tool0"
        ]
    );
    assert_eq!(chain.dof(), 6);
    assert!(chain.joints.iter().all(|j| j.kind == JointKind::Revolute));
    assert_eq!(chain.joints[2].name, "elbow_joint");
    assert!((chain.joints[2].upper - std::f64::consts::PI).abs() < 1e-12);
    let counts: Vec<usize> = model.collision.iter().map(Vec::len).collect();
    assert_eq!(counts, [0, 1, 1, 1, 1, 1, 1, 1, 0, 0]);
    // Collision origin of the upper arm: rpy (π/2, 0, -π/2), xyz (0, 0, 0.13585).
    let (_, pose) = &model.collision[3][0];
    assert!((pose.translation.z - 0.13585).abs() < 1e-12);
}

fn dls_round_trips(seed: u64, targets: usize) -> (usize, usize) {
    let model = load_urdf(&ur5_urdf(), &ur_packages(), None).unwrap();
    let chain = &model.chain;
    let ik = DlsIk::new(chain, DlsParams::default());
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut multi = 0;
    let mut solved = 0;
    let mut out = Vec::new();
    for _ in 0..targets {
        let q = random_q(chain, &mut rng);
        let target = chain.fk_tip(&q);
        out.clear();
        let distinct = ik.solve(&target, &mut out);
        let best = out
            .iter()
            .map(|s| {
                assert!(chain.within_limits(s, 0.0));
                let (dp, dr) = pose_error(&chain.fk_tip(s), &target);
                dp.max(dr)
            })
            .fold(f64::INFINITY, f64::min);
        if best < 1e-6 {
            solved += 1;
        }
        assert!(
            distinct <= 8,
            "a UR5 pose has at most 8 solutions modulo 2π: {distinct}"
        );
        if distinct > 1 {
            multi += 1;
        }
        for s in &out {
            let (dp, dr) = pose_error(&chain.fk_tip(s), &target);
            assert!(
                dp < 1e-6 && dr < 1e-6,
                "every returned solution reaches the target"
            );
        }
    }
    (solved, multi)
}

#[test]
fn ur5_dls_reaches_random_targets() {
    let n = 40;
    let (solved, multi) = dls_round_trips(11, n);
    println!("UR5 DLS: {solved}/{n} solved, {multi}/{n} with several distinct solutions");
    assert_eq!(solved, n);
    assert!(
        multi * 4 >= n * 3,
        "most targets have several distinct solutions: {multi}/{n}"
    );
}

/// The URDF `data/robots/{folder}/urdf/{file}`, its one package `package` in the folder of that
/// name beside it.
fn data_robot(folder: &str, file: &str, package: &str) -> cellplan_kin::RobotModel {
    let robot = data().join("robots").join(folder);
    let packages = BTreeMap::from([(package.to_string(), robot.join(package))]);
    load_urdf(&robot.join("urdf").join(file), &packages, None).unwrap()
}

fn abb_irb2400() -> cellplan_kin::RobotModel {
    data_robot("abb_irb2400", "irb2400.urdf", "abb_irb2400_support")
}

fn kr210() -> cellplan_kin::RobotModel {
    data_robot("kuka_kr210", "kr210l150.urdf", "kuka_kr210_support")
}

/// The seven lengths of two parameter sets, side by side.
fn lengths(p: &OpwParameters) -> [f64; 7] {
    [p.a1, p.a2, p.b, p.c1, p.c2, p.c3, p.c4]
}

/// Whether `ik` finds every configuration of `n` random ones within the limits again from its
/// tip (to `tol` rad per joint), and every solution it gives reaches the tip.
fn finds_every_configuration_again(
    ik: &dyn IkSolver,
    chain: &cellplan_kin::Chain,
    n: usize,
    seed: u64,
    tol: f64,
) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    for _ in 0..n {
        let q = random_q(chain, &mut rng);
        let target = chain.fk_tip(&q);
        out.clear();
        ik.solve(&target, &mut out);
        assert!(
            out.iter()
                .any(|s| s.iter().zip(&q).all(|(a, b)| (a - b).abs() < tol)),
            "{q:?} not among {out:?}"
        );
        for s in &out {
            let (dp, da) = pose_error(&chain.fk_tip(s), &target);
            assert!(dp < 1e-8 && da < 1e-8, "{s:?}: {dp} m, {da} rad");
        }
    }
}

#[test]
fn opw_parameters_read_off_the_fanuc_urdf_are_its_parameter_file() {
    let model = load_urdf(&fanuc_urdf(), &fanuc_packages(), None).unwrap();
    let ik = OpwIk::derive(&model.chain).expect("the R-2000iC is an OPW arm");
    let (got, file) = (ik.params(), fanuc_opw());
    for (a, b) in lengths(got).iter().zip(lengths(&file)) {
        assert!((a - b).abs() < 1e-12, "{got:?} against {file:?}");
    }
    // The same solutions as the solver built on the parameter file, for random targets.
    let from_file = OpwIk::for_robot(&model, file).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for _ in 0..200 {
        let target = model.chain.fk_tip(&random_q(&model.chain, &mut rng));
        a.clear();
        b.clear();
        ik.solve(&target, &mut a);
        from_file.solve(&target, &mut b);
        let key = |v: &mut Vec<Vec<f64>>| {
            v.sort_by(|x, y| x.partial_cmp(y).unwrap());
        };
        key(&mut a);
        key(&mut b);
        assert_eq!(a.len(), b.len(), "{a:?} against {b:?}");
        for (x, y) in a.iter().zip(&b) {
            assert!(
                x.iter().zip(y).all(|(u, v)| (u - v).abs() < 1e-9),
                "{x:?} against {y:?}"
            );
        }
    }
    finds_every_configuration_again(&ik, &model.chain, 200, 6, 1e-9);
}

#[test]
fn opw_parameters_read_off_the_abb_irb2400_urdf_are_the_published_set() {
    let model = abb_irb2400();
    let ik = OpwIk::derive(&model.chain).expect("the IRB 2400 is an OPW arm");
    // opw_kinematics' IRB 2400-10 set (the URDF's arm).
    let published = [0.100, -0.135, 0.0, 0.615, 0.705, 0.755, 0.085];
    for (a, b) in lengths(ik.params()).iter().zip(published) {
        assert!((a - b).abs() < 1e-9, "{:?}", ik.params());
    }
    finds_every_configuration_again(&ik, &model.chain, 200, 7, 1e-9);
}

#[test]
fn opw_parameters_are_read_off_the_kuka_kr210_urdf() {
    let model = kr210();
    let ik = OpwIk::derive(&model.chain).expect("the KR 210 is an OPW arm");
    // Its URDF, made from CAD, puts joint 1 2.8 mm off the root's origin: the OPW base is moved
    // onto it.
    let base = ik.base().translation;
    assert!(
        base.length() > 1e-3 && base.length() < 5e-3 && base.z == 0.0,
        "{base:?}"
    );
    finds_every_configuration_again(&ik, &model.chain, 200, 8, 1e-9);
}

#[test]
fn opw_parameters_are_read_off_the_abb_irb6640_urdf() {
    // Its balancing cylinder and piston hang on fixed joints off the chain.
    let model = data_robot("abb_irb6640", "irb6640.urdf", "abb_irb6600_support");
    let ik = OpwIk::derive(&model.chain).expect("the IRB 6640 is an OPW arm");
    assert!(ik.params().c2 > 1.0 && ik.params().c3 > 1.0, "{:?}", ik.params());
    finds_every_configuration_again(&ik, &model.chain, 200, 9, 1e-9);
}

fn ur10() -> cellplan_kin::RobotModel {
    data_robot("ur10", "ur10.urdf", "ur_description")
}

#[test]
fn the_universal_robots_get_the_closed_form_of_three_parallel_axes() {
    for (model, seed) in [
        (load_urdf(&ur5_urdf(), &ur_packages(), None).unwrap(), 10),
        (ur10(), 11),
    ] {
        let ik = ParallelIk::derive(&model.chain).expect("a UR arm has three parallel axes");
        // The UR URDFs state right angles to nine digits: near a singularity the joints move by
        // up to ~1e-4 rad for the same tip (every solution still reaches it to 1e-8).
        finds_every_configuration_again(&ik, &model.chain, 300, seed, 1e-3);
        // Eight branches for a target well inside the reach, and every solution the numeric
        // solver finds is one of them (to 1e-2 rad: near the elbow's singularity the two
        // solvers' answers for the same tip differ by ~1e-4 rad).
        let dls = DlsIk::new(&model.chain, DlsParams::default());
        let mut rng = ChaCha8Rng::seed_from_u64(seed + 100);
        let (mut closed, mut numeric) = (Vec::new(), Vec::new());
        let mut eight = 0;
        for _ in 0..50 {
            let target = model.chain.fk_tip(&random_q(&model.chain, &mut rng));
            closed.clear();
            numeric.clear();
            eight += usize::from(ik.solve(&target, &mut closed) == 8);
            dls.solve(&target, &mut numeric);
            for s in &numeric {
                assert!(
                    closed
                        .iter()
                        .any(|c| c.iter().zip(s).all(|(a, b)| (a - b).abs() < 1e-2)),
                    "the numeric {s:?} is not among {closed:?}"
                );
            }
        }
        assert!(eight >= 25, "{eight} of 50 targets with eight branches");
    }
    // Arms of the other kinds get none.
    let fanuc = load_urdf(&fanuc_urdf(), &fanuc_packages(), None).unwrap();
    assert!(ParallelIk::derive(&fanuc.chain).is_none());
    assert!(ParallelIk::derive(&kr210().chain).is_none());
}

#[test]
fn an_opw_arm_on_a_track_gets_sampled_track_positions_and_the_arms_closed_form() {
    let model = load_urdf(
        &data().join("robots/fanuc_r2000ic/urdf/r2000ic125l_on_track.urdf"),
        &fanuc_packages(),
        None,
    )
    .unwrap();
    assert_eq!(model.chain.dof(), 7);
    let ik = TrackIk::derive(&model.chain).expect("an R-2000iC on a track");
    let dls = DlsIk::new(&model.chain, DlsParams::default());
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let (mut out, mut numeric) = (Vec::new(), Vec::new());
    let (mut solved, mut centred) = (0, 0);
    for _ in 0..100 {
        let q = random_q(&model.chain, &mut rng);
        let target = model.chain.fk_tip(&q);
        out.clear();
        ik.solve(&target, &mut out);
        for s in &out {
            let (dp, da) = pose_error(&model.chain.fk_tip(s), &target);
            assert!(dp < 1e-8 && da < 1e-8, "{s:?}: {dp} m, {da} rad");
            assert!(model.chain.within_limits(s, 0.0), "{s:?}");
        }
        // Five track positions at most, 0.4 m apart, within the track's ±2 m.
        let samples = ik.samples(&target);
        assert!(!samples.is_empty() && samples.len() <= 5, "{samples:?}");
        assert!(samples.iter().all(|s| s.abs() <= 2.0));
        let mut sorted = samples.clone();
        sorted.sort_by(f64::total_cmp);
        assert!(sorted.windows(2).all(|w| w[1] - w[0] > 0.4 - 1e-9), "{samples:?}");
        // Where the numeric solver reaches a target with the track in the sampled stretch, so
        // does the closed form.
        numeric.clear();
        dls.solve(&target, &mut numeric);
        let (lo, hi) = (sorted[0], sorted[sorted.len() - 1]);
        if numeric.iter().any(|n| n[0] >= lo && n[0] <= hi) {
            centred += 1;
            solved += usize::from(!out.is_empty());
        }
    }
    assert!(centred >= 20 && solved == centred, "{solved} of {centred}");
    // A six-joint arm is no track robot.
    let fanuc = load_urdf(&fanuc_urdf(), &fanuc_packages(), None).unwrap();
    assert!(TrackIk::derive(&fanuc.chain).is_none());
}

#[test]
fn arms_that_are_not_opw_get_no_parameters() {
    // The UR5's wrist has no centre: its three wrist axes do not meet.
    let ur5 = load_urdf(&ur5_urdf(), &ur_packages(), None).unwrap();
    assert!(OpwParameters::candidates_for(&ur5.chain).is_empty());
    assert!(OpwIk::derive(&ur5.chain).is_none());
    // The R-2000iC with its wrist moved 5 mm sideways, or its forearm turned by 0.01 rad out of the arm's plane.
    let model = load_urdf(&fanuc_urdf(), &fanuc_packages(), None).unwrap();
    let wrist = model.chain.joint_link(4).unwrap();
    let mut moved = model.chain.clone();
    moved.links[wrist].origin.translation.y += 0.005;
    assert!(OpwIk::derive(&moved).is_none());
    let elbow = model.chain.joint_link(3).unwrap();
    let mut tilted = model.chain.clone();
    tilted.links[elbow].origin.rotation = cellplan_geom::DQuat::from_rotation_z(0.01);
    assert!(OpwIk::derive(&tilted).is_none());
}

//! Property tests: OPW round trips on the FANUC URDF and on random OPW geometries, and the
//! properties of `limit_variants`.
use cellplan_kin::{
    IkSolver, OpwIk, OpwParameters, RobotModel, limit_variants, load_urdf, pose_error, wrap_angle,
};
use proptest::prelude::*;
use std::collections::BTreeMap;
use std::f64::consts::{PI, TAU};
use std::path::PathBuf;
use std::sync::OnceLock;

fn fanuc() -> &'static (RobotModel, OpwIk) {
    static CELL: OnceLock<(RobotModel, OpwIk)> = OnceLock::new();
    CELL.get_or_init(|| {
        let data = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/robots/fanuc_r2000ic");
        let packages = BTreeMap::from([(
            "fanuc_r2000ic_support".to_string(),
            data.join("fanuc_r2000ic_support"),
        )]);
        let model = load_urdf(&data.join("urdf/r2000ic125l.urdf"), &packages, None).unwrap();
        let yaml = std::fs::read_to_string(
            data.join("fanuc_r2000ic_support/config/opw_parameters_r2000ic125l.yaml"),
        )
        .unwrap();
        let ik = OpwIk::new(&model.chain, OpwParameters::from_ros_yaml(&yaml).unwrap()).unwrap();
        (model, ik)
    })
}

/// Joint values within the FANUC's limits, as fractions of each range.
fn fanuc_q() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.0..1.0f64, 6).prop_map(|t| {
        let chain = &fanuc().0.chain;
        chain
            .joints
            .iter()
            .zip(t)
            .map(|(j, t)| j.lower + t * (j.upper - j.lower))
            .collect()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn fanuc_fk_ik_fk_round_trip(q in fanuc_q()) {
        let (model, ik) = fanuc();
        let chain = &model.chain;
        let target = chain.fk_tip(&q);
        let mut out = Vec::new();
        let raw = ik.solve(&target, &mut out);
        prop_assert!((1..=8).contains(&raw));
        prop_assert!(!out.is_empty());
        for s in &out {
            prop_assert!(chain.within_limits(s, 0.0));
            let (dp, dr) = pose_error(&chain.fk_tip(s), &target);
            prop_assert!(dp < 1e-9 && dr < 1e-9, "FK(IK) off by {} m {} rad", dp, dr);
        }
        let found = out.iter().any(|s| s.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-6));
        prop_assert!(found, "q = {:?} not among {:?}", q, out);
    }

    #[test]
    fn random_opw_geometry_round_trip(
        a1 in 0.0..0.5f64, a2 in -0.3..0.3f64, b in -0.2..0.2f64,
        c1 in 0.2..1.0f64, c2 in 0.3..1.2f64, c3 in 0.3..1.5f64, c4 in 0.05..0.3f64,
        offsets in prop::array::uniform6(-PI..PI),
        signs in prop::array::uniform6(prop::bool::ANY),
        q in prop::array::uniform6(-PI..PI),
    ) {
        let p = OpwParameters {
            a1, a2, b, c1, c2, c3, c4, offsets,
            sign_corrections: signs.map(|s| if s { 1.0 } else { -1.0 }),
        };
        let pose = p.forward(&q);
        let mut sols = Vec::new();
        p.inverse(&pose, &mut sols);
        for s in &sols {
            let (dp, dr) = pose_error(&p.forward(s), &pose);
            prop_assert!(dp < 1e-8 && dr < 1e-8, "{} {}", dp, dr);
        }
        let found = sols.iter().any(|s| s.iter().zip(&q).all(|(a, b)| wrap_angle(a - b).abs() < 1e-6));
        prop_assert!(found, "q = {:?} not among {:?}", q, sols);
    }

    #[test]
    fn limit_variants_properties(q in prop::array::uniform6(-15.0..15.0f64)) {
        let chain = &fanuc().0.chain;
        let mut out = Vec::new();
        limit_variants(&q, chain, &mut out);
        // Expected count: per joint, the number of turns k with q + 2πk in range.
        let expected: usize = chain.joints.iter().zip(&q).map(|(j, v)| {
            (-8..=8).filter(|k| {
                let x = v + TAU * f64::from(*k);
                x >= j.lower - 1e-9 && x <= j.upper + 1e-9
            }).count()
        }).product();
        prop_assert_eq!(out.len(), expected);
        for v in &out {
            prop_assert!(chain.within_limits(v, 0.0));
            for (a, b) in v.iter().zip(&q) {
                let turns = (a - b) / TAU;
                prop_assert!((turns - turns.round()).abs() < 1e-9);
            }
        }
        for w in out.windows(2) {
            prop_assert!(w[0] < w[1], "sorted and distinct");
        }
        if chain.within_limits(&q, 0.0) {
            prop_assert!(out.iter().any(|v| v.as_slice() == q.as_slice()));
        }
    }
}

/// The case proptest found: a configuration within the limits must come back bit for bit among
/// its variants (it did not when a variant was built as `(v − 2π) + 2π`).
#[test]
fn a_configuration_within_the_limits_is_its_own_variant() {
    let chain = &fanuc().0.chain;
    let q = [0.0, 0.0, 0.0, 0.10204323909409894, 0.0, 0.0];
    assert!(chain.within_limits(&q, 0.0));
    let mut out = Vec::new();
    limit_variants(&q, chain, &mut out);
    assert!(out.iter().any(|v| v.as_slice() == q.as_slice()), "{out:?}");
}

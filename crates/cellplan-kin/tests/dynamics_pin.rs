//! The recursive Newton–Euler dynamics against Pinocchio 4.1 on the KUKA KR 210 L150 (its
//! URDF's inertials) and the UR10: 1,000 random states each (bench/dynamics/*_pin.json, made by
//! bench/peers/dynamics_pin.py), torques, gravity torques and mass matrices.
use cellplan_kin::dynamics::Dynamics;
use cellplan_kin::load_urdf;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn check(reference: &str, package: (&str, &str)) {
    let text = std::fs::read_to_string(root().join(reference)).unwrap();
    let r: Value = serde_json::from_str(&text).unwrap();
    let urdf = root().join(r["urdf"].as_str().unwrap());
    let packages = BTreeMap::from([(package.0.to_string(), root().join(package.1))]);
    let model = load_urdf(&urdf, &packages, r["tip"].as_str()).unwrap();
    let names: Vec<&str> = model.chain.joints.iter().map(|j| j.name.as_str()).collect();
    let want: Vec<&str> = r["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_str().unwrap())
        .collect();
    assert_eq!(names, want);
    let d = Dynamics::new(&model.chain, &model.inertia);
    let vec = |v: &Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    // Error relative to each state's largest |τ| (single torques may be near zero).
    let rel = |got: &[f64], want: &[f64]| {
        let scale = want.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-12);
        got.iter()
            .zip(want)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / scale
    };
    let (mut worst_tau, mut worst_g, mut worst_m) = (0.0f64, 0.0f64, 0.0f64);
    let states = r["states"].as_array().unwrap();
    assert_eq!(states.len(), 1000);
    for s in states {
        let (q, v, a) = (vec(&s["q"]), vec(&s["v"]), vec(&s["a"]));
        worst_tau = worst_tau.max(rel(&d.inverse_dynamics(&q, &v, &a), &vec(&s["tau"])));
        if let Some(g) = s.get("g").filter(|g| !g.is_null()) {
            worst_g = worst_g.max(rel(&d.gravity_torques(&q), &vec(g)));
        }
        if let Some(m) = s.get("M").filter(|m| !m.is_null()) {
            let ours: Vec<f64> = d.mass_matrix(&q).concat();
            let theirs: Vec<f64> = m.as_array().unwrap().iter().flat_map(&vec).collect();
            worst_m = worst_m.max(rel(&ours, &theirs));
        }
    }
    eprintln!("{reference}: worst relative error τ {worst_tau:.2e}, g {worst_g:.2e}, M {worst_m:.2e}");
    assert!(worst_tau < 1e-9 && worst_g < 1e-9 && worst_m < 1e-9);
}

#[test]
fn torques_match_pinocchio_on_the_kr210() {
    check(
        "bench/dynamics/kr210_pin.json",
        ("kuka_kr210_support", "data/robots/kuka_kr210/kuka_kr210_support"),
    );
}

#[test]
fn torques_match_pinocchio_on_the_ur10() {
    check(
        "bench/dynamics/ur10_pin.json",
        ("ur_description", "data/robots/ur10/ur_description"),
    );
}

//! Kinematics benchmarks: FK of every link of the FANUC R-2000iC/125L, OPW inverse (all
//! branches), `OpwIk::solve` with ±2π variants, and DLS on the UR5.
use cellplan_geom::Pose;
use cellplan_kin::{DlsIk, DlsParams, IkSolver, OpwIk, OpwParameters, load_urdf};
use criterion::{Criterion, criterion_group, criterion_main};
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::PathBuf;

fn data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/robots")
}

fn kinematics(c: &mut Criterion) {
    let fanuc_dir = data().join("fanuc_r2000ic");
    let packages = BTreeMap::from([(
        "fanuc_r2000ic_support".to_string(),
        fanuc_dir.join("fanuc_r2000ic_support"),
    )]);
    let fanuc = load_urdf(&fanuc_dir.join("urdf/r2000ic125l.urdf"), &packages, None).expect("FANUC URDF");
    let yaml = std::fs::read_to_string(
        fanuc_dir.join("fanuc_r2000ic_support/config/opw_parameters_r2000ic125l.yaml"),
    )
    .expect("OPW yaml");
    let params = OpwParameters::from_ros_yaml(&yaml).expect("OPW parameters");
    let opw = OpwIk::new(&fanuc.chain, params.clone()).expect("OPW matches");

    let q = [0.3, 0.2, -0.4, 0.9, -0.7, 1.2];
    let mut poses = vec![Pose::IDENTITY; fanuc.chain.links.len()];
    c.bench_function("fk_all R-2000iC/125L (8 links)", |b| {
        b.iter(|| fanuc.chain.fk_all(black_box(&q), black_box(&mut poses)))
    });

    let flange = params.forward(&q);
    let mut raw = [[0.0; 6]; 8];
    c.bench_function("opw inverse, all branches", |b| {
        b.iter(|| params.inverse_into(black_box(&flange), &mut raw))
    });

    let target = fanuc.chain.fk_tip(&q);
    let mut out = Vec::with_capacity(64);
    c.bench_function("OpwIk::solve with limit variants (R-2000iC)", |b| {
        b.iter(|| {
            out.clear();
            opw.solve(black_box(&target), &mut out)
        })
    });

    let ur_dir = data().join("ur5");
    let ur_packages = BTreeMap::from([("ur_description".to_string(), ur_dir.join("ur_description"))]);
    let ur5 = load_urdf(&ur_dir.join("urdf/ur5.urdf"), &ur_packages, None).expect("UR5 URDF");
    let dls = DlsIk::new(&ur5.chain, DlsParams::default());
    let ur_target = ur5.chain.fk_tip(&[0.4, -1.1, 1.3, -0.6, 1.2, 0.3]);
    let mut out = Vec::with_capacity(512);
    c.bench_function("DlsIk::solve UR5 (16 seeds)", |b| {
        b.iter(|| {
            out.clear();
            dls.solve(black_box(&ur_target), &mut out)
        })
    });
}

/// The recursive Newton–Euler dynamics on the KR 210 L150 and the UR10 (issue 18): τ, M(q),
/// and τ with its exact derivatives by dual numbers.
fn dynamics(c: &mut Criterion) {
    use cellplan_kin::dynamics::Dynamics;
    let robots = [
        (
            "KR 210 L150",
            "kuka_kr210/urdf/kr210l150.urdf",
            "kuka_kr210_support",
            "kuka_kr210/kuka_kr210_support",
        ),
        (
            "UR10",
            "ur10/urdf/ur10.urdf",
            "ur_description",
            "ur10/ur_description",
        ),
    ];
    let (q, v, a) = (
        [0.3, -0.8, 0.9, 0.4, -0.7, 1.2],
        [0.5, -0.4, 0.3, 1.0, -0.9, 1.5],
        [2.0, -1.0, 3.0, -4.0, 5.0, -6.0],
    );
    for (name, urdf, pkg, dir) in robots {
        let packages = BTreeMap::from([(pkg.to_string(), data().join(dir))]);
        let model = load_urdf(&data().join(urdf), &packages, None).expect("URDF");
        let d = Dynamics::new(&model.chain, &model.inertia);
        c.bench_function(&format!("rnea {name}"), |b| {
            b.iter(|| d.inverse_dynamics(black_box(&q), black_box(&v), black_box(&a)))
        });
        c.bench_function(&format!("mass matrix {name}"), |b| {
            b.iter(|| d.mass_matrix(black_box(&q[..])))
        });
        c.bench_function(&format!("rnea with derivatives {name}"), |b| {
            b.iter(|| d.inverse_dynamics_derivatives(black_box(&q), black_box(&v), black_box(&a)))
        });
    }
}

criterion_group!(benches, kinematics, dynamics);
criterion_main!(benches);

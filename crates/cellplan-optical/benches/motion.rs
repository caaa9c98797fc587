//! Motion benchmarks on the bundled autobody-4r cell (robot R1): one clearance call (distance
//! to the car body, fixtures and the robot's self pairs), the conservative check of the
//! straight leg from home to a measuring candidate, and an RRT-Connect leg (with shortcutting)
//! between two candidates whose straight segment is blocked.
use cellplan_core::candidates::generate;
use cellplan_core::motion::{joint_space, plan_leg, robot_validity};
use cellplan_model::{LoadOptions, TaskId};
use cellplan_motion::plan::{PlanSettings, Planner, StateValidity, Straight, check_segment};
use cellplan_optical::load;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn motion_benches(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/autobody-4r/cell.toml");
    let cell = load(&path, &LoadOptions::default()).expect("example cell loads");
    let table = generate(&cell);
    let robot = &cell.robots[0];
    let margin = cell.planning.clearance;
    let space = joint_space(&cell, robot);
    let validity = robot_validity(&cell, robot, margin);
    let settings = PlanSettings::default();
    let candidates: Vec<Vec<f64>> = (0..cell.tasks.len())
        .filter_map(|t| table.get(TaskId(t), robot.id).candidates.first())
        .map(|c| c.q.clone())
        .filter(|q| validity.clearance(q) > settings.min_clearance)
        .collect();
    let near = candidates.first().expect("R1 measures something").clone();

    let mut group = c.benchmark_group("motion");
    group.bench_function("clearance, R-2000iC + probe (measuring pose)", |b| {
        b.iter(|| black_box(validity.clearance(black_box(&near))))
    });
    group.bench_function("clearance, R-2000iC + probe (home)", |b| {
        b.iter(|| black_box(validity.clearance(black_box(&robot.home))))
    });
    let check = check_segment(&space, &validity, &robot.home, &near, settings.min_clearance);
    eprintln!("straight home -> candidate: {check:?}");
    group.bench_function("straight leg check, home -> candidate", |b| {
        b.iter(|| black_box(check_segment(&space, &validity, &robot.home, &near, 1e-4)))
    });
    // The first pair of candidates whose straight segment is blocked.
    let blocked = candidates.iter().enumerate().find_map(|(i, a)| {
        candidates[i + 1..]
            .iter()
            .find(|b| Straight.plan(&space, &validity, a, b, &settings).is_err())
            .map(|b| (a.clone(), b.clone()))
    });
    if let Some((a, b)) = blocked {
        let leg = plan_leg(&cell, robot, &a, &b, &settings).expect("a path");
        eprintln!(
            "rrt-connect leg: {} waypoints, {} samples, {} validity calls",
            leg.waypoints.len(),
            leg.samples,
            leg.validity_calls
        );
        group.sample_size(10);
        group.bench_function(
            "rrt-connect leg with shortcutting, candidate -> candidate",
            |bench| bench.iter(|| black_box(plan_leg(&cell, robot, &a, &b, &settings))),
        );
    }
    group.finish();
}

criterion_group!(benches, motion_benches);
criterion_main!(benches);

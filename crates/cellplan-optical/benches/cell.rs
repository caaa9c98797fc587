//! Benchmarks on the bundled autobody-4r cell: one robot configuration's full collision check
//! against the car body, fixtures and itself; candidate generation for the whole cell; and,
//! on the zones plan of the cell, the coordination diagrams of its programs and one `best`
//! coordination of them (what ours does per plan it judges).
use cellplan_core::candidates::generate;
use cellplan_core::coord::{self, CoordSettings};
use cellplan_core::plan::{self, PlanSettings};
use cellplan_model::robot::Scratch;
use cellplan_model::{LoadOptions, TaskId};
use cellplan_optical::load;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;

fn cell_benches(c: &mut Criterion) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/autobody-4r/cell.toml");
    let cell = load(&path, &LoadOptions::default()).expect("example cell loads");
    let table = generate(&cell);
    let robot = &cell.robots[0];
    // A measuring configuration: the probe close to the car body.
    let near = (0..cell.tasks.len())
        .find_map(|t| table.get(TaskId(t), robot.id).candidates.first().cloned())
        .expect("R1 measures something");
    let clearance = cell.planning.clearance;
    let mut scratch = Scratch::default();
    c.bench_function(
        "collision check, R-2000iC + probe vs car body (measuring pose)",
        |b| {
            b.iter(|| {
                robot.body_poses(black_box(&near.q), &mut scratch);
                black_box(robot.contact_at(&cell.world, &scratch, clearance))
            })
        },
    );
    c.bench_function("collision check, R-2000iC + probe vs car body (home)", |b| {
        b.iter(|| {
            robot.body_poses(black_box(&robot.home), &mut scratch);
            black_box(robot.contact_at(&cell.world, &scratch, clearance))
        })
    });
    let mut group = c.benchmark_group("candidates");
    group.sample_size(10);
    group.bench_function("autobody-4r, 45 MPs x 4 robots", |b| {
        b.iter(|| black_box(generate(&cell)))
    });
    group.finish();
    let outcome = plan::plan(&cell, &table, &PlanSettings::default(), &|_| {}).expect("the cell plans");
    let programs: Vec<_> = outcome.robots.iter().map(|r| r.program.clone()).collect();
    let settings = CoordSettings {
        blend_deviation: 0.0,
        ..CoordSettings::default()
    };
    let mut group = c.benchmark_group("coordination");
    group.sample_size(10);
    group.bench_function("autobody-4r zones plan, diagrams of 6 robot pairs", |b| {
        b.iter(|| black_box(coord::conflict_boxes(&cell, &table, &programs, &settings).expect("boxes")))
    });
    group.bench_function("autobody-4r zones plan, best coordination", |b| {
        b.iter(|| {
            black_box(coord::coordinate(&cell, &table, programs.clone(), &settings).expect("coordinated"))
        })
    });
    group.finish();
}

criterion_group!(benches, cell_benches);
criterion_main!(benches);

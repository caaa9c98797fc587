//! Timing benchmarks: `move_time` for 6 joints, and timing a 6-waypoint 6-joint path exactly
//! and with parabolic blends (FANUC-like limits).
use cellplan_motion::timing::{Limits, move_time, time_path_blended, time_path_exact};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn timing(c: &mut Criterion) {
    let limits = Limits::new(
        vec![1.92, 1.92, 1.92, 3.0, 3.0, 4.36],
        vec![6.0, 6.0, 6.0, 10.0, 10.0, 14.0],
    )
    .expect("limits");
    let a = [0.0, 0.1, -0.2, 0.3, -0.4, 0.5];
    let b = [1.2, -0.4, 0.6, -1.0, 0.8, 2.0];
    c.bench_function("move_time 6 joints", |bench| {
        bench.iter(|| move_time(black_box(&a), black_box(&b), &limits))
    });

    let path: Vec<Vec<f64>> = vec![
        vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        vec![0.6, 0.2, -0.3, 0.4, 0.1, -0.5],
        vec![1.0, -0.1, 0.2, 0.9, -0.3, 0.2],
        vec![0.7, 0.4, 0.5, 0.2, 0.6, 1.0],
        vec![1.5, 0.3, -0.2, -0.4, 0.2, 1.6],
        vec![1.8, -0.2, 0.1, 0.3, -0.5, 0.9],
    ];
    let exact = time_path_exact(&path, &limits).expect("exact");
    let blended = time_path_blended(&path, &limits, &[0.05]).expect("blended");
    eprintln!(
        "6-waypoint path: exact {:.3} s, blended {:.3} s ({} blends, max deviation {:.4} rad)",
        exact.trajectory.duration(),
        blended.trajectory.duration(),
        blended.blends.len(),
        blended.deviation.iter().cloned().fold(0.0, f64::max)
    );
    c.bench_function("time_path_exact 6 waypoints", |bench| {
        bench.iter(|| time_path_exact(black_box(&path), &limits).expect("exact"))
    });
    c.bench_function("time_path_blended 6 waypoints", |bench| {
        bench.iter(|| time_path_blended(black_box(&path), &limits, &[0.05]).expect("blended"))
    });
}

criterion_group!(benches, timing);
criterion_main!(benches);

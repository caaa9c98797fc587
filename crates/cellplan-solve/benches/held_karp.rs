//! Exact Held–Karp on random Euclidean GTSP instances with depots (the robot-tour shape).
use cellplan_solve::held_karp::{HeldKarpLimits, solve};
use cellplan_solve::{CostMatrix, Gtsp};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn instance(clusters: usize, per: usize, seed: u64) -> Gtsp {
    let mut x = seed;
    let mut rnd = || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    let n = clusters * per + 1;
    let pts: Vec<(f64, f64)> = (0..n).map(|_| (rnd(), rnd())).collect();
    let costs = CostMatrix::from_fn(n, |i, j| {
        ((pts[i].0 - pts[j].0).powi(2) + (pts[i].1 - pts[j].1).powi(2)).sqrt()
    });
    let groups = (0..clusters)
        .map(|k| (k * per..(k + 1) * per).collect())
        .collect();
    Gtsp::new(costs, groups)
        .unwrap()
        .with_depots(Some(n - 1), None)
        .unwrap()
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("held-karp");
    group.sample_size(10);
    for (clusters, per) in [(8, 10), (12, 20)] {
        let p = instance(clusters, per, 7);
        group.bench_function(format!("{clusters} clusters x {per} alternatives"), |b| {
            b.iter(|| black_box(solve(&p, HeldKarpLimits::default()).unwrap().cost))
        });
    }
    group.finish();
}

criterion_group!(hk, benches);
criterion_main!(hk);

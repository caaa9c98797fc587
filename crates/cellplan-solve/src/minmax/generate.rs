//! Random instances shaped like the inspection cell of paper 000: robots on a line, tasks
//! (measurement points) on a surface in front of them, several jittered configurations per
//! task and robot, and a reach radius so that some tasks are exclusive and some shared.
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{MinMaxProblem, Vehicle};
use crate::problem::CostMatrix;

/// A random instance with `vehicles` robots and `tasks` tasks; every (robot, task) pair within
/// reach has between `alternatives.0` and `alternatives.1` nodes (inclusive).
///
/// Geometry (metres, cost = distance / speed, speed 0.8–1.2 m/s per robot): depots at
/// `(i, 0, 0)`; tasks at `x ∈ [−0.4, m − 0.6]`, `y ≈ 1` (a gently curved surface),
/// `z ∈ [0, 0.6]`; a robot reaches tasks with `|x − x_depot| ≤ 1.0` (the nearest robot always);
/// a node is the task point jittered by up to 5 cm per axis (a configuration in joint space
/// seen through its tool point); service 0.2–0.6 s per task. Caps are `⌈1.3·tasks/m⌉`, raised
/// until the caps admit an assignment.
///
/// # Panics
/// If `vehicles == 0`, or `alternatives.0 == 0` or `alternatives.0 > alternatives.1`.
pub fn generate(vehicles: usize, tasks: usize, alternatives: (usize, usize), seed: u64) -> MinMaxProblem {
    assert!(vehicles > 0, "at least one vehicle");
    assert!(
        alternatives.0 >= 1 && alternatives.0 <= alternatives.1,
        "alternatives must be a range lo..=hi with lo >= 1"
    );
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let m = vehicles;
    let pts: Vec<[f64; 3]> = (0..tasks)
        .map(|_| {
            let x = -0.4 + rng.random::<f64>() * (m as f64 - 0.2);
            let y = 1.0 + 0.15 * (x * 1.7).sin() + 0.05 * rng.random::<f64>();
            let z = 0.6 * rng.random::<f64>();
            [x, y, z]
        })
        .collect();
    let service: Vec<f64> = (0..tasks).map(|_| 0.2 + 0.4 * rng.random::<f64>()).collect();
    let mut vs = Vec::with_capacity(m);
    for v in 0..m {
        let speed = 0.8 + 0.4 * rng.random::<f64>();
        let depot_pt = [v as f64, 0.0, 0.0];
        let mut nodes = vec![depot_pt];
        let mut alts = vec![Vec::new(); tasks];
        for (t, pt) in pts.iter().enumerate() {
            let nearest = (pt[0].round().clamp(0.0, (m - 1) as f64)) as usize;
            if (pt[0] - v as f64).abs() > 1.0 && nearest != v {
                continue;
            }
            let k = rng.random_range(alternatives.0..=alternatives.1);
            for _ in 0..k {
                let mut q = *pt;
                for c in &mut q {
                    *c += 0.05 * (2.0 * rng.random::<f64>() - 1.0);
                }
                alts[t].push(nodes.len());
                nodes.push(q);
            }
        }
        let costs = CostMatrix::from_fn(nodes.len(), |i, j| {
            let (a, b) = (nodes[i], nodes[j]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt() / speed
        });
        vs.push(Vehicle {
            costs,
            depot: 0,
            cap: 0,
            alternatives: alts,
        });
    }
    let mut cap = (tasks * 13).div_ceil(10 * m);
    loop {
        for v in &mut vs {
            v.cap = cap;
        }
        let p = MinMaxProblem {
            vehicles: vs,
            tasks,
            service: service.clone(),
            balance_limit: None,
        };
        if p.validate().is_ok() {
            return p;
        }
        vs = p.vehicles;
        cap += 1;
    }
}

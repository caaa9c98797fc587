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
    match generate_within(vehicles, tasks, alternatives, seed, u64::MAX) {
        Ok(p) => p,
        Err(e) => panic!("{e}"),
    }
}

/// An instance [`generate`] would have made, refused because it could pass the memory allowed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct TooLarge(pub String);

/// [`generate`], but refused before anything large is allocated when the instance's dense cost
/// matrices could take more than `max_matrix_bytes` (8 bytes per entry, every reachable task
/// counted with `alternatives.1` nodes, the most it can get). The tasks' points are made first
/// (32 bytes per task, refused beyond `max_matrix_bytes` too), then the reach of every robot
/// counted, then the matrices; the instance is the one [`generate`] makes.
///
/// # Panics
/// As [`generate`].
pub fn generate_within(
    vehicles: usize,
    tasks: usize,
    alternatives: (usize, usize),
    seed: u64,
    max_matrix_bytes: u64,
) -> Result<MinMaxProblem, TooLarge> {
    assert!(vehicles > 0, "at least one vehicle");
    assert!(
        alternatives.0 >= 1 && alternatives.0 <= alternatives.1,
        "alternatives must be a range lo..=hi with lo >= 1"
    );
    let m = vehicles;
    // Every robot has a record, a depot and a matrix of its own (256 bytes, generously); every
    // task a point, a service time and a place in each robot's list of alternatives.
    let fixed = (m as u128) * 256 + (tasks as u128) * 32 + (m as u128) * (tasks as u128) * 24;
    if fixed > u128::from(max_matrix_bytes) {
        return Err(TooLarge(format!(
            "{m} robots and {tasks} tasks take {} MiB before any cost is stored, more than the {} MiB allowed",
            fixed >> 20,
            max_matrix_bytes >> 20
        )));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let pts: Vec<[f64; 3]> = (0..tasks)
        .map(|_| {
            let x = -0.4 + rng.random::<f64>() * (m as f64 - 0.2);
            let y = 1.0 + 0.15 * (x * 1.7).sin() + 0.05 * rng.random::<f64>();
            let z = 0.6 * rng.random::<f64>();
            [x, y, z]
        })
        .collect();
    let service: Vec<f64> = (0..tasks).map(|_| 0.2 + 0.4 * rng.random::<f64>()).collect();
    let reaches = |v: usize, pt: &[f64; 3]| {
        let nearest = (pt[0].round().clamp(0.0, (m - 1) as f64)) as usize;
        (pt[0] - v as f64).abs() <= 1.0 || nearest == v
    };
    let mut bytes = fixed;
    for v in 0..m {
        let reached = pts.iter().filter(|pt| reaches(v, pt)).count() as u128;
        let nodes = 1 + reached * alternatives.1 as u128;
        bytes = bytes.saturating_add(nodes.saturating_mul(nodes).saturating_mul(8));
        if bytes > u128::from(max_matrix_bytes) {
            return Err(TooLarge(format!(
                "robot {v} reaches {reached} tasks; with up to {} nodes each, the cost matrices of the robots up to it could take more than the {} MiB allowed",
                alternatives.1,
                max_matrix_bytes >> 20
            )));
        }
    }
    let mut vs = Vec::with_capacity(m);
    for v in 0..m {
        let speed = 0.8 + 0.4 * rng.random::<f64>();
        let depot_pt = [v as f64, 0.0, 0.0];
        let mut nodes = vec![depot_pt];
        let mut alts = vec![Vec::new(); tasks];
        for (t, pt) in pts.iter().enumerate() {
            if !reaches(v, pt) {
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
            costs: costs.into(),
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
            return Ok(p);
        }
        vs = p.vehicles;
        cap += 1;
    }
}

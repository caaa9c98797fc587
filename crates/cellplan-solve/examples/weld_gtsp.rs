//! Writes a GTSPLIB instance shaped like paper 002's stud-welding case (Table 1): a robot home
//! plus 20 welds with 6–36 alternative joint configurations each (Table 1's counts, 307 in
//! all), the weld cost of each alternative drawn from Table 1's range for that weld, travel
//! costs from the joint-space distance of the configurations (a synchronised-move time scaled
//! to the paper's magnitudes, plus an effort term). The weld cost is folded into every arc
//! entering the alternative (GTSPLIB has no node costs), so the matrix is asymmetric.
//!
//! `cargo run --release -p cellplan-solve --example weld_gtsp -- SEED > weld20.gtsp`
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// (alternatives, weld cost range) per stud, paper 002 Table 1.
const TABLE1: [(usize, f64, f64); 20] = [
    (6, 41.16, 41.44),
    (8, 79.11, 80.73),
    (16, 110.8, 223.3),
    (22, 95.69, 240.0),
    (27, 33.78, 330.0),
    (18, 58.36, 339.6),
    (10, 240.8, 350.8),
    (16, 176.9, 448.6),
    (20, 89.64, 307.2),
    (30, 48.63, 282.2),
    (16, 35.49, 295.5),
    (36, 50.55, 471.6),
    (16, 73.29, 228.7),
    (13, 140.1, 447.8),
    (16, 44.07, 417.3),
    (9, 173.1, 324.9),
    (9, 181.1, 329.3),
    (7, 174.5, 181.5),
    (6, 241.5, 242.5),
    (6, 222.9, 223.3),
];

/// Joint speeds (rad/s) of a large six-axis arm.
const SPEED: [f64; 6] = [1.75, 1.57, 1.57, 2.44, 2.09, 3.32];

fn main() {
    let seed: u64 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut configs: Vec<[f64; 6]> = vec![[0.0, -0.3, 0.2, 0.0, -0.9, 0.0]];
    let mut weld_cost = vec![0.0];
    let mut sets = Vec::new();
    for &(alts, lo, hi) in &TABLE1 {
        let base: [f64; 6] = [
            rng.random_range(-1.2..1.2),
            rng.random_range(-0.6..0.8),
            rng.random_range(-0.8..0.9),
            rng.random_range(-1.5..1.5),
            rng.random_range(-1.6..-0.2),
            rng.random_range(-1.5..1.5),
        ];
        let mut set = Vec::new();
        for a in 0..alts {
            let mut q = base;
            // Alternatives: wrist flips, ±2π turns of joints 4 and 6, elbow variants, and
            // small differences of the tool's free rotation about the stud.
            if a % 2 == 1 {
                q[3] += std::f64::consts::PI;
                q[4] = -q[4];
                q[5] += std::f64::consts::PI;
            }
            match (a / 2) % 4 {
                1 => q[5] -= std::f64::consts::TAU,
                2 => q[3] -= std::f64::consts::TAU,
                3 => {
                    q[1] += 0.5;
                    q[2] -= 1.0;
                }
                _ => {}
            }
            for x in &mut q {
                *x += rng.random_range(-0.08..0.08);
            }
            set.push(configs.len());
            configs.push(q);
            weld_cost.push(rng.random_range(lo..=hi));
        }
        sets.push(set);
    }
    let n = configs.len();
    println!("NAME : weld20-{seed}");
    println!("TYPE : GTSP (paper 002 Table 1 shape, cellplan weld_gtsp example, seed {seed})");
    println!("DIMENSION : {n}");
    println!("GTSP_SETS : {}", sets.len() + 1);
    println!("EDGE_WEIGHT_TYPE : EXPLICIT");
    println!("EDGE_WEIGHT_FORMAT : FULL_MATRIX");
    println!("EDGE_WEIGHT_SECTION");
    for i in 0..n {
        let row: Vec<String> = (0..n)
            .map(|j| {
                if i == j {
                    return "0".to_string();
                }
                let (a, b) = (configs[i], configs[j]);
                let time = (0..6).map(|k| (a[k] - b[k]).abs() / SPEED[k]).fold(0.0, f64::max);
                let effort: f64 = (0..6).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
                // Hundredths, as TSPLIB weights are integers.
                format!(
                    "{}",
                    ((30.0 * time + 5.0 * effort + weld_cost[j]) * 100.0).round() as i64
                )
            })
            .collect();
        println!("{}", row.join(" "));
    }
    println!("GTSP_SET_SECTION");
    println!("1 1 -1");
    for (k, set) in sets.iter().enumerate() {
        let ids: Vec<String> = set.iter().map(|i| (i + 1).to_string()).collect();
        println!("{} {} -1", k + 2, ids.join(" "));
    }
    println!("EOF");
}

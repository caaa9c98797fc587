//! Synthetic cells for tests and benchmarks (no files): a random board on a machine laid out
//! like paper 004's Fig. 1 / Fig. 6.
use crate::board::{Board, Component, Mount, Side};
use crate::cell::{ComponentType, Configuration, Drive, Feeder, MotionModel, PcbCell, Robot, Table};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;

/// A random cell: `n` components of `types` types on a 100 × 80 mm board, one or two robots.
pub fn random_cell(
    n: usize,
    types: usize,
    robots: usize,
    configuration: Configuration,
    seed: u64,
) -> PcbCell {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let components: Vec<Component> = (0..n)
        .map(|i| Component {
            reference: format!("U{i}"),
            value: format!("v{}", i % types.max(1)),
            footprint: "FP".into(),
            position: [rng.random_range(0.0..0.1), rng.random_range(0.0..0.08)],
            rotation: rng.random_range(0.0..std::f64::consts::TAU),
            side: Side::Front,
            mount: Mount::Smd,
            dnp: false,
            excluded: false,
            line: i + 1,
        })
        .collect();
    let mut kinds: Vec<ComponentType> = components
        .iter()
        .map(|c| ComponentType {
            footprint: c.footprint.clone(),
            value: c.value.clone(),
        })
        .collect();
    kinds.sort();
    kinds.dedup();
    let type_of = components
        .iter()
        .map(|c| {
            kinds
                .binary_search(&ComponentType {
                    footprint: c.footprint.clone(),
                    value: c.value.clone(),
                })
                .unwrap_or(0)
        })
        .collect();
    let drive = |speed| Drive {
        speed,
        acceleration: 10.0,
    };
    let feeder = |name: &str, x: f64| Feeder {
        name: name.into(),
        x,
        travel: [-0.05, 0.15],
        home: 0.0,
        bins: 12,
        pitch: 0.01,
        drive: drive(1.0),
    };
    let feeders = [feeder("CDS1", -0.15), feeder("CDS2", 0.30)];
    let gap = 0.03;
    let mut robot_list = vec![Robot {
        name: "R1".into(),
        drive: drive(2.0),
        home: [-0.2, 0.05],
        x: [-0.25, 0.35],
        x_given: [-0.25, 0.35],
        y: [-0.1, 0.3],
    }];
    if robots == 2 {
        robot_list[0].x[1] = feeders[1].x - gap;
        robot_list.push(Robot {
            name: "R2".into(),
            drive: drive(2.0),
            home: [0.33, 0.05],
            x: [feeders[0].x + gap, 0.35],
            x_given: [-0.25, 0.35],
            y: [-0.1, 0.3],
        });
    }
    PcbCell {
        name: format!("random-{n}"),
        path: PathBuf::from("random.toml"),
        board: Board {
            path: PathBuf::from("random.csv"),
            title: "random".into(),
            components: components.clone(),
            size: [0.1, 0.08],
        },
        components,
        types: kinds,
        type_of,
        robots: robot_list,
        feeders,
        table: Table {
            x: [-0.05, 0.15],
            y: [-0.02, 0.1],
            home: [0.0, 0.0],
            drive: drive(0.5),
        },
        pick_time: 0.02,
        place_time: 0.03,
        safety_gap: gap,
        collision_avoidance: true,
        configuration,
        motion: MotionModel::ConstantSpeed,
        given_bins: Vec::new(),
    }
}

/// A random decision for `cell`: a shuffled order, random robots where allowed, and random
/// rendezvous inside the feasible ranges.
pub fn random_decision(cell: &PcbCell, seed: u64) -> crate::sim::Decision {
    use crate::search::{initial, robot_can};
    use crate::sim::slot_lookup;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut d = initial(cell);
    let n = cell.len();
    for i in (1..n).rev() {
        let j = rng.random_range(0..=i);
        d.order.swap(i, j);
    }
    let lookup = slot_lookup(cell, &d);
    for c in 0..n {
        if cell.robots.len() == 2 {
            let r = rng.random_range(0..2);
            if robot_can(cell, &lookup, r, c) {
                d.robot[c] = r;
                d.feeder[c] = r;
            }
        }
        let Some(slot) = lookup[d.feeder[c]][cell.type_of[c]] else {
            continue;
        };
        if let Some(rg) = cell.pick_range(d.robot[c], d.feeder[c], slot) {
            d.carriage[c] = rng.random_range(rg[0]..=rg[1]);
        }
        if let Some(bx) = cell.place_box(d.robot[c], c) {
            d.table[c] = [
                rng.random_range(bx[0][0]..=bx[0][1]),
                rng.random_range(bx[1][0]..=bx[1][1]),
            ];
        }
    }
    d
}

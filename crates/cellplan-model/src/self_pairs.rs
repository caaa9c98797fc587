//! Which body pairs of a robot need self-collision checks, found by sampling as MoveIt's
//! setup assistant does: adjacent pairs, pairs always in contact and pairs never near each other
//! in many random configurations are left out. (MoveIt also drops pairs touching in the default
//! pose; here the loader refuses a home where any non-adjacent pair touches instead.) The result
//! depends only on the robot's geometry, so it is cached on disk keyed by a hash of that geometry.
use crate::hash::Fnv;
use crate::robot::{BodyFrame, Robot, Scratch};
use cellplan_geom::{CollisionWorld, Pose, ShapeSpec};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::hash::Hasher;
use std::path::{Path, PathBuf};

/// A pair closer than this in any sample is kept ("never in contact" must mean never near).
const NEAR: f64 = 0.02;
/// Bumped when the sampling rule changes, so old cache files are not reused.
const RULE_VERSION: u64 = 4;

/// Outcome of sampling one robot.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SelfPairs {
    /// Pairs to check.
    pub pairs: Vec<(usize, usize)>,
}

/// Every body pair `(i, j)`, `i < j`, that can be checked for self-collision at all: not on
/// the same frame (the shapes of one link, or of the tool, move together) and not adjacent in
/// the chain.
pub fn non_adjacent_pairs(robot: &Robot) -> Vec<(usize, usize)> {
    let n = robot.bodies.len();
    let adjacent = adjacent(robot);
    (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .filter(|&(i, j)| robot.bodies[i] != robot.bodies[j] && !adjacent.contains(&(i, j)))
        .collect()
}

/// Bodies adjacent in the chain: `a` is on the nearest frame up the chain from `b`'s that
/// carries bodies (links without geometry are skipped over; the tool's frame is the tip).
fn adjacent(robot: &Robot) -> Vec<(usize, usize)> {
    let chain = &robot.model.chain;
    let tip = chain.links.len() - 1;
    let bodies_of_link = |l: usize| {
        robot
            .bodies
            .iter()
            .enumerate()
            .filter(move |(_, b)| **b == BodyFrame::Link(l))
            .map(|(i, _)| i)
    };
    let mut pairs = Vec::new();
    for (bi, b) in robot.bodies.iter().enumerate() {
        // The link this body's frame hangs from, then walk towards the root.
        let mut l = match *b {
            BodyFrame::Link(0) => continue,
            BodyFrame::Link(l) => l - 1,
            BodyFrame::Tool => tip,
        };
        loop {
            let above: Vec<usize> = bodies_of_link(l).collect();
            if !above.is_empty() {
                pairs.extend(above.into_iter().map(|a| (a.min(bi), a.max(bi))));
                break;
            }
            if l == 0 {
                break;
            }
            l -= 1;
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// Samples `samples` random configurations (seeded) and returns the pairs to check.
pub fn sample_self_pairs(robot: &Robot, world: &CollisionWorld, samples: usize, seed: u64) -> SelfPairs {
    let candidates = non_adjacent_pairs(robot);
    let chain = &robot.model.chain;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let configs: Vec<Vec<f64>> = (0..samples)
        .map(|_| {
            chain
                .joints
                .iter()
                .map(|j| {
                    let (lo, hi) = (
                        j.lower.max(-std::f64::consts::PI),
                        j.upper.min(std::f64::consts::PI),
                    );
                    if hi > lo { rng.random_range(lo..hi) } else { lo }
                })
                .collect()
        })
        .collect();
    // Per pair: (samples in contact, samples near). Sums are order-free, so
    // the parallel split cannot change the result.
    let counts = configs
        .par_chunks(256)
        .map(|chunk| {
            let mut scratch = Scratch::default();
            let mut touch = vec![0usize; candidates.len()];
            let mut near = vec![0usize; candidates.len()];
            for q in chunk {
                robot.body_poses(q, &mut scratch);
                for (k, &(i, j)) in candidates.iter().enumerate() {
                    if world.bodies_within(robot.group, i, j, &scratch.bodies, NEAR) {
                        near[k] += 1;
                        if world.bodies_within(robot.group, i, j, &scratch.bodies, 0.0) {
                            touch[k] += 1;
                        }
                    }
                }
            }
            (touch, near)
        })
        .reduce(
            || (vec![0; candidates.len()], vec![0; candidates.len()]),
            |mut a, b| {
                for k in 0..a.0.len() {
                    a.0[k] += b.0[k];
                    a.1[k] += b.1[k];
                }
                a
            },
        );
    let pairs = candidates
        .iter()
        .enumerate()
        .filter(|&(k, _)| {
            let never = counts.1[k] == 0;
            let always = counts.0[k] == samples;
            !(never || always)
        })
        .map(|(_, &p)| p)
        .collect();
    SelfPairs { pairs }
}

fn hash_pose(h: &mut Fnv, p: &Pose) {
    for v in p.translation.to_array().into_iter().chain(p.rotation.to_array()) {
        h.write_u64(v.to_bits());
    }
}

fn hash_shape(h: &mut Fnv, s: &ShapeSpec) {
    match s {
        ShapeSpec::Box { half_extents } => {
            h.write_u8(1);
            half_extents
                .to_array()
                .iter()
                .for_each(|v| h.write_u64(v.to_bits()));
        }
        ShapeSpec::Cylinder { radius, half_height } => {
            h.write_u8(2);
            h.write_u64(radius.to_bits());
            h.write_u64(half_height.to_bits());
        }
        ShapeSpec::Sphere { radius } => {
            h.write_u8(3);
            h.write_u64(radius.to_bits());
        }
        ShapeSpec::Mesh(m) => {
            h.write_u8(4);
            for v in &m.vertices {
                v.to_array().iter().for_each(|x| h.write_u64(x.to_bits()));
            }
            for t in &m.triangles {
                t.iter().for_each(|&i| h.write_u32(i));
            }
        }
    }
}

/// A key for everything the sampling result depends on: the chain, its geometry, the tool,
/// the home configuration, the sample count and seed.
pub fn geometry_key(robot: &Robot, samples: usize, seed: u64) -> u64 {
    let mut h = Fnv::default();
    h.write_u64(RULE_VERSION);
    h.write_u64(samples as u64);
    h.write_u64(seed);
    let chain = &robot.model.chain;
    for l in &chain.links {
        h.write(l.name.as_bytes());
        hash_pose(&mut h, &l.origin);
        h.write_u64(l.joint.map_or(u64::MAX, |j| j as u64));
    }
    for j in &chain.joints {
        j.axis.to_array().iter().for_each(|v| h.write_u64(v.to_bits()));
        h.write_u64(j.lower.to_bits());
        h.write_u64(j.upper.to_bits());
    }
    for shapes in &robot.model.collision {
        h.write_u64(shapes.len() as u64);
        for (s, p) in shapes {
            hash_shape(&mut h, s);
            hash_pose(&mut h, p);
        }
    }
    hash_pose(&mut h, &robot.tool.tcp);
    for (s, p) in &robot.tool.shapes {
        hash_shape(&mut h, s);
        hash_pose(&mut h, p);
    }
    robot.home.iter().for_each(|v| h.write_u64(v.to_bits()));
    h.finish()
}

/// A cache entry to write once the run has succeeded (bad input writes nothing, not even this).
#[derive(Clone, Debug)]
pub struct PendingCache {
    /// The cache file.
    pub file: PathBuf,
    /// Its contents.
    pub text: String,
}

/// [`sample_self_pairs`] through a cache folder (`None`: no cache): a hit is read, a miss is
/// sampled and returned with the entry to write. A cache that cannot be read is ignored: it
/// only saves time.
pub fn cached_self_pairs(
    robot: &Robot,
    world: &CollisionWorld,
    samples: usize,
    seed: u64,
    cache_dir: Option<&Path>,
) -> (SelfPairs, Option<PendingCache>) {
    let file = cache_dir.map(|d| {
        d.join(format!(
            "self-pairs-{:016x}.json",
            geometry_key(robot, samples, seed)
        ))
    });
    if let Some(f) = &file
        && let Ok(text) = std::fs::read_to_string(f)
        && let Ok(cached) = serde_json::from_str::<SelfPairs>(&text)
        && cached.pairs.iter().all(|&(i, j)| i < j && j < robot.bodies.len())
    {
        return (cached, None);
    }
    let result = sample_self_pairs(robot, world, samples, seed);
    let pending = match (file, serde_json::to_string(&result)) {
        (Some(file), Ok(text)) => Some(PendingCache { file, text }),
        _ => None,
    };
    (result, pending)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> crate::Cell {
        crate::testing::example("autobody-2r", 2000)
    }

    #[test]
    fn adjacent_pairs_are_never_checked_and_reachable_pairs_are() {
        let cell = example();
        let robot = &cell.robots[0];
        let names: Vec<&str> = (0..robot.bodies.len())
            .map(|i| cell.world.body_name(robot.group, i))
            .collect();
        assert_eq!(names.first(), Some(&"base_link"));
        // The probe's two shapes are two bodies, never merged into one hull.
        let probe: Vec<usize> = (0..names.len())
            .filter(|&i| names[i].starts_with("tool:probe"))
            .collect();
        assert_eq!(probe.len(), 2, "{names:?}");
        assert!(probe.iter().all(|&i| robot.bodies[i] == BodyFrame::Tool));
        let last_link = probe[0] - 1;
        for (i, j) in (0..names.len()).flat_map(|i| (i + 1..names.len()).map(move |j| (i, j))) {
            let same_frame = robot.bodies[i] == robot.bodies[j];
            let chain_neighbours = j == i + 1 && j < probe[0];
            let tool_on_tip = i == last_link && probe.contains(&j);
            if same_frame || chain_neighbours || tool_on_tip {
                assert!(
                    !robot.self_pairs.contains(&(i, j)),
                    "adjacent {} / {} checked",
                    names[i],
                    names[j]
                );
            }
        }
        // The probe can swing down onto the robot's own base: that pair must be checked.
        assert!(
            probe.iter().any(|&p| robot.self_pairs.contains(&(0, p))),
            "{:?}",
            robot.self_pairs
        );
    }

    #[test]
    fn sampling_is_reproducible_and_cached() {
        let cell = example();
        let robot = &cell.robots[0];
        let a = sample_self_pairs(robot, &cell.world, 1500, 9);
        let b = sample_self_pairs(robot, &cell.world, 1500, 9);
        assert_eq!(a, b);
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("cache");
        let (first, pending) = cached_self_pairs(robot, &cell.world, 1500, 9, Some(&dir));
        assert_eq!(first, a);
        let pending = pending.expect("a miss yields an entry to write");
        assert!(
            !pending.file.exists(),
            "nothing is written before the run succeeds"
        );
        crate::io::write_atomic(&pending.file, pending.text.as_bytes()).unwrap();
        let (hit, again) = cached_self_pairs(robot, &cell.world, 1500, 9, Some(&dir));
        assert_eq!((hit, again.is_none()), (a.clone(), true));
        // A damaged cache entry is ignored.
        std::fs::write(&pending.file, "{not json").unwrap();
        let (redone, again) = cached_self_pairs(robot, &cell.world, 1500, 9, Some(&dir));
        assert_eq!((redone, again.is_some()), (a, true));
        // Another seed is another key.
        assert_ne!(geometry_key(robot, 1500, 9), geometry_key(robot, 1500, 10));
    }
}

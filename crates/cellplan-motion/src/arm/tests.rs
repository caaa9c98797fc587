//! The arm's motion bounds and its proof of pairs apart, on the MBM UR5 (bench/motion).
use super::turned::random_configuration;
use super::{Arm, apart_everywhere, body_radii, moved_by, pair_radii, pairs_that_may_touch};
use crate::plan::StateValidity;
use crate::problem::{ArmSetup, read_problems};
use cellplan_geom::{DVec3, Pose};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn ur5() -> ArmSetup {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/motion/mbm-ur5/table_pick.json");
    ArmSetup::load(&read_problems(&path).unwrap()).unwrap()
}

/// Each body's hull vertices in its own frame (none for a body without shapes).
fn hull_vertices(arm: &Arm) -> Vec<Vec<DVec3>> {
    (0..arm.body_links.len())
        .map(|i| {
            arm.world
                .body_hull(arm.group, i)
                .map_or(Vec::new(), |m| m.vertices)
        })
        .collect()
}

fn lerp(a: &[f64], b: &[f64], t: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + (y - x) * t).collect()
}

/// `Σ_k r_k·|b_k − a_k|` over the joints `joints`.
fn bound(radii: &[f64], a: &[f64], b: &[f64], joints: std::ops::Range<usize>) -> f64 {
    joints.map(|k| radii[k] * (b[k] - a[k]).abs()).sum()
}

/// Over random short segments, every hull vertex of every body travels no farther than its
/// radii allow (the tightened radius of its own joint included), and every self pair's
/// distance changes no more than the pair's radii allow (the proximal body's reach for the
/// first joint included). Each bound is also not slack by much for some segment: the test
/// would notice radii far too large as well as too small.
#[test]
fn body_and_pair_radii_bound_the_motion() {
    let setup = ur5();
    let arm = setup.arm();
    let n = arm.body_links.len();
    let radii: Vec<Vec<f64>> = (0..n).map(|i| body_radii(&arm, i)).collect();
    let hulls = hull_vertices(&arm);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut links, mut poses) = (Vec::new(), Vec::<Pose>::new());
    let mut tightest = vec![0.0f64; n];
    for _ in 0..60 {
        let a = random_configuration(&arm, &mut rng);
        let b: Vec<f64> = a.iter().map(|x| x + rng.random_range(-0.2..0.2)).collect();
        let steps = 40;
        let mut travelled = vec![0.0; n];
        let mut prev: Option<Vec<Pose>> = None;
        for s in 0..=steps {
            arm.body_poses(&lerp(&a, &b, s as f64 / steps as f64), &mut links, &mut poses);
            if let Some(p) = &prev {
                for i in 0..n {
                    let step = hulls[i]
                        .iter()
                        .map(|v| (poses[i].transform_point(*v) - p[i].transform_point(*v)).length())
                        .fold(0.0, f64::max);
                    travelled[i] += step;
                }
            }
            prev = Some(poses.clone());
        }
        for i in 0..n {
            let limit = bound(&radii[i], &a, &b, 0..arm.chain.dof());
            assert!(
                travelled[i] <= limit + 1e-9,
                "body {i}: {} > {limit}",
                travelled[i]
            );
            if limit > 0.0 {
                tightest[i] = tightest[i].max(travelled[i] / limit);
            }
        }
        // Pairs: the distance at the ends of the segment.
        let mut ends = Vec::new();
        for q in [&a, &b] {
            arm.body_poses(q, &mut links, &mut poses);
            ends.push(poses.clone());
        }
        for &(i, j) in arm.self_pairs {
            let (ma, mb) = (moved_by(&arm, i), moved_by(&arm, j));
            let (near, far) = if mb >= ma { (i, j) } else { (j, i) };
            let first = ma.min(mb);
            let pr = pair_radii(&arm, near, first, &radii[far]);
            let limit = bound(&pr, &a, &b, first..ma.max(mb));
            let d = |p: &[Pose]| arm.world.pair_distance(arm.group, i, j, p, 10.0);
            let (da, db) = (d(&ends[0]), d(&ends[1]));
            if da > 0.0 && db > 0.0 {
                assert!(
                    (db - da).abs() <= limit + 1e-6,
                    "pair ({i}, {j}): {da} -> {db}, bound {limit}"
                );
            }
        }
    }
    // The gripper's bodies turn about the wrist's last axis: their bound there is their reach
    // from it, nearly met by some segment.
    let gripper = (0..n).filter(|&i| arm.body_links[i] == arm.chain.links.len() - 1);
    for i in gripper {
        assert!(
            tightest[i] > 0.5,
            "body {i}: at most {} of its bound",
            tightest[i]
        );
    }
}

/// Pairs proven apart are apart in every sampled configuration; pairs seen touching are never
/// proven apart; and some are proven: the wrist's last link and the force sensor, which only
/// turns about its own axis in front of it.
#[test]
fn pairs_proven_apart_never_touch() {
    let setup = ur5();
    let all = Arm {
        self_pairs: &setup.self_pairs,
        ..setup.arm()
    };
    let may_touch = pairs_that_may_touch(&all);
    assert_eq!(may_touch, setup.checked_pairs);
    let apart: Vec<(usize, usize)> = setup
        .self_pairs
        .iter()
        .copied()
        .filter(|p| !may_touch.contains(p))
        .collect();
    let named = |a: &str, b: &str| {
        apart.iter().any(|&(i, j)| {
            let (x, y) = (&setup.body_sources[i], &setup.body_sources[j]);
            (x == a && y == b) || (x == b && y == a)
        })
    };
    assert!(named("wrist_2_link", "fts_robotside"), "{apart:?}");
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut links, mut poses) = (Vec::new(), Vec::<Pose>::new());
    let mut touched = std::collections::BTreeSet::new();
    for _ in 0..5000 {
        let q = random_configuration(&all, &mut rng);
        all.body_poses(&q, &mut links, &mut poses);
        for &(i, j) in all.self_pairs {
            if all.world.bodies_within(all.group, i, j, &poses, 0.0) {
                touched.insert((i, j));
            }
        }
    }
    assert!(
        touched.len() > 10,
        "the sampling finds contacts: {}",
        touched.len()
    );
    for p in &apart {
        assert!(!touched.contains(p), "{p:?} proven apart but touches");
    }
    // A touching pair fails the proof within any budget.
    let &(i, j) = touched.iter().next().unwrap();
    assert!(!apart_everywhere(&all, i, j, 1_000_000));
}

/// Paper 002's weights `w_j(q) = max_p ‖∂p/∂q_j‖₁`: at random configurations, no hull vertex
/// of a body that joint `j` moves is faster (central differences) than `w_j`, and `w_j` exceeds
/// the fastest vertex by no more than the covers' slack (2√3 times the largest sphere radius:
/// a sphere's centre is within its radius of some body point, not always on the body).
#[test]
fn point_speed_weights_bound_the_vertices_speeds_and_are_tight() {
    let setup = ur5();
    let arm = setup.arm();
    let n = arm.body_links.len();
    let hulls = hull_vertices(&arm);
    let largest = (0..n)
        .flat_map(|i| arm.world.body_cover(arm.group, i).iter().map(|s| s.radius))
        .fold(0.0f64, f64::max);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut links, mut lo, mut hi) = (Vec::new(), Vec::<Pose>::new(), Vec::<Pose>::new());
    let eps = 1e-6;
    for _ in 0..30 {
        let q = random_configuration(&arm, &mut rng);
        let w = super::point_speed_weights(&arm, &q);
        assert_eq!(w.len(), arm.chain.dof());
        for j in 0..arm.chain.dof() {
            let (mut a, mut b) = (q.clone(), q.clone());
            a[j] -= eps;
            b[j] += eps;
            arm.body_poses(&a, &mut links, &mut lo);
            arm.body_poses(&b, &mut links, &mut hi);
            let fastest = (0..n)
                .filter(|&i| j < moved_by(&arm, i))
                .flat_map(|i| {
                    let (lo, hi) = (lo[i], hi[i]);
                    hulls[i].iter().map(move |v| {
                        let d = (hi.transform_point(*v) - lo.transform_point(*v)) / (2.0 * eps);
                        d.x.abs() + d.y.abs() + d.z.abs()
                    })
                })
                .fold(0.0f64, f64::max);
            assert!(
                fastest <= w[j] + 1e-6,
                "joint {j}: a vertex moves at {fastest}, w {}",
                w[j]
            );
            assert!(
                w[j] <= fastest + 2.0 * 3f64.sqrt() * largest + 1e-6,
                "joint {j}: w {} far above the fastest vertex {fastest}",
                w[j]
            );
        }
    }
}

/// `clear_by` answers as `scene_and_self_clearance` compared with the thresholds, for
/// thresholds on both sides of each configuration's clearances (the value itself, one ulp
/// either way, a millimetre either way, and far) and for configurations outside the limits, with and without a margin;
/// `clear_of` as the clearance compared with a floor.
#[test]
fn clear_by_answers_as_the_clearances_compared() {
    let setup = ur5();
    let arm = setup.arm();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut yes, mut no) = (0, 0);
    for margin in [0.0, 0.01] {
        let validity = setup.validity(margin);
        for k in 0..150 {
            let mut q = random_configuration(&arm, &mut rng);
            if k % 25 == 0 {
                q[1] = arm.chain.joints[1].upper + 0.1;
            }
            let (scene, own) = validity.scene_and_self_clearance(&q);
            let near = |x: f64, rng: &mut ChaCha8Rng| {
                if x.is_finite() {
                    match rng.random_range(0..7) {
                        // The value itself and its neighbours: the caps must not round a
                        // part that meets its threshold below it.
                        0 => x,
                        1 => x.next_up(),
                        2 => x.next_down(),
                        k => x + [-1e-3, 1e-3, -0.2, 0.2][k - 3],
                    }
                } else {
                    rng.random_range(-0.1..0.1)
                }
            };
            for _ in 0..4 {
                let (s, o) = (near(scene, &mut rng), near(own, &mut rng));
                let expected = scene >= s && own >= o;
                assert_eq!(validity.clear_by(&q, s, o), expected, "{q:?} {s} {o}");
                if expected { yes += 1 } else { no += 1 }
            }
            // The planners' test of a query's ends: the clearance compared with the floor.
            let c = StateValidity::clearance(&validity, &q);
            for floor in [near(c, &mut rng), 1e-4] {
                assert_eq!(validity.clear_of(&q, floor), c >= floor, "{q:?} {floor}");
            }
        }
    }
    assert!(yes > 100 && no > 100, "{yes} {no}");
}

/// The tables of the pairs with two or three joints between their bodies bound the pair's
/// exact distance from below: at random configurations, and over intervals of their joint
/// (every configuration whose joint lies within the radius asked, the other joints anywhere);
/// they apply to the always-close pairs (the base and the upper arm among them) and clear most
/// of that pair's range.
#[test]
fn pair_tables_bound_the_exact_distances() {
    let setup = ur5();
    let arm = setup.arm();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let (mut links, mut poses) = (Vec::new(), Vec::<Pose>::new());
    let mut tables = 0;
    for &(i, j) in arm.self_pairs {
        let Some(t) = super::pair_table(&arm, i, j) else {
            continue;
        };
        tables += 1;
        let k = t.joint();
        let mut positive = 0;
        for _ in 0..150 {
            let q = random_configuration(&arm, &mut rng);
            arm.body_poses(&q, &mut links, &mut poses);
            let exact = arm.world.pair_distance(arm.group, i, j, &poses, 1.0);
            let at = t.least_within(q[k], 0.0);
            assert!(
                at <= exact + 1e-9,
                "pair ({i}, {j}): table {at} beyond the distance {exact}"
            );
            positive += usize::from(at > 0.0);
            // An interval about another value of the joint holding this configuration's.
            let radius = rng.random_range(0.0..0.6);
            let centre = q[k] + rng.random_range(-radius..=radius);
            let within = t.least_within(centre, radius);
            assert!(
                within <= exact + 1e-9,
                "pair ({i}, {j}): interval {within} beyond {exact}"
            );
            assert!(within <= t.least_within(centre, 0.0) + 1e-12);
        }
        if (i, j) == (0, 2) {
            assert!(
                positive > 75,
                "the base and the upper arm cleared in {positive} of 150"
            );
        }
    }
    assert!(tables >= 5, "only {tables} tables");
    // Out of range and non-finite values say nothing.
    let t = super::pair_table(&arm, 0, 2).expect("the base and the upper arm have a table");
    assert_eq!(t.least_within(f64::NAN, 0.0), 0.0);
    assert_eq!(t.least_within(0.0, f64::INFINITY), 0.0);
}

/// With the tables (a check asks them before exact distances, and a segment check skips a
/// pair its table clears over the step), every configuration and every segment gets the answer
/// it gets without them, with fewer validity calls; the tables are built for the close pairs
/// only (the base and the upper arm among them) and the same every time.
#[test]
fn pair_tables_change_no_answer() {
    let setup = ur5();
    let plain = crate::arm::Arm {
        pair_tables: None,
        ..setup.arm()
    };
    let tables = crate::arm::PairTables::build(&plain);
    assert!(
        tables.get(0, 2).is_some(),
        "no table for the base and the upper arm"
    );
    assert!(
        (2..plain.self_pairs.len() / 2).contains(&tables.len()),
        "{} tables for {} pairs",
        tables.len(),
        plain.self_pairs.len()
    );
    assert_eq!(tables.len(), setup.pair_tables.len());
    let with = crate::arm::Arm {
        pair_tables: Some(&tables),
        ..setup.arm()
    };
    let (a, b) = (
        super::ArmValidity::new(plain, 0.0, Vec::new()),
        super::ArmValidity::new(with, 0.0, Vec::new()),
    );
    let space = crate::arm::joint_space(&plain, &[1.0; 6]);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for _ in 0..400 {
        let q = random_configuration(&plain, &mut rng);
        assert_eq!(a.is_valid(&q), b.is_valid(&q));
    }
    let (mut calls_a, mut calls_b, mut valid) = (0, 0, 0);
    for _ in 0..300 {
        let p = random_configuration(&plain, &mut rng);
        let r: Vec<f64> = p.iter().map(|x| x + rng.random_range(-0.5..0.5)).collect();
        let (ca, cb) = (
            crate::plan::check_segment(&space, &a, &p, &r, 1e-9),
            crate::plan::check_segment(&space, &b, &p, &r, 1e-9),
        );
        assert_eq!(ca.valid, cb.valid, "{p:?} → {r:?}");
        valid += usize::from(ca.valid);
        calls_a += ca.calls;
        calls_b += cb.calls;
    }
    assert!(valid > 20, "only {valid} valid segments");
    assert!(
        calls_b < calls_a,
        "{calls_b} calls with the tables, {calls_a} without"
    );
}

/// Clusters (a link's bodies held by one sphere, tested against the scene or another link's
/// sphere first) settle parts exactly as the parts' own tests would: the same validity and the
/// same segment steps, bit for bit, on random configurations and segments among the obstacles
/// of `bookshelf_small`; and they do settle parts (fewer exact queries is not observable here,
/// so the test checks that some cluster and group exist and that some clear).
#[test]
fn clusters_change_no_answer() {
    use crate::plan::{SegmentMotion, StateValidity};
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../bench/motion/mbm-ur5/bookshelf_small.json");
    let set = read_problems(&path).unwrap();
    let mut setup = ArmSetup::load(&set).unwrap();
    setup.set_obstacles(&set.problems[3].obstacles);
    let with = setup.validity(0.0);
    let mut without = setup.validity(0.0);
    without.clusters = super::Clusters::default();
    assert!(
        with.clusters.scene.iter().flatten().count() >= 12,
        "{:?}",
        with.clusters.scene
    );
    assert!(with.clusters.pair.iter().flatten().flatten().count() >= 60);
    let space = crate::arm::joint_space(&setup.arm(), &[]);
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let (mut valid, mut steps) = (0, 0);
    for _ in 0..400 {
        let q = random_configuration(&setup.arm(), &mut rng);
        let v = with.is_valid(&q);
        assert_eq!(v, without.is_valid(&q), "{q:?}");
        valid += usize::from(v);
        let r: Vec<f64> = q.iter().map(|x| x + rng.random_range(-0.6..0.6)).collect();
        let motion = SegmentMotion::of(&space, &q, &r);
        let floor = [1e-9, 1e-4, 0.01][steps % 3];
        let (a, b) = (
            with.segment_step(&q, &motion, floor, 1.0),
            without.segment_step(&q, &motion, floor, 1.0),
        );
        assert_eq!(
            a.map(f64::to_bits),
            b.map(f64::to_bits),
            "{q:?} → {r:?}: {a:?} {b:?}"
        );
        steps += usize::from(a.is_some());
    }
    assert!(valid > 50 && steps > 50, "{valid} valid, {steps} steps");
    // Every sphere, placed, holds the hull vertices of the bodies it stands for: a link's
    // cluster its bodies', a body's own sphere that body's.
    let vertices = hull_vertices(&setup.arm());
    let links = setup.arm().body_links;
    let mut held = 0;
    for _ in 0..50 {
        let q = random_configuration(&setup.arm(), &mut rng);
        let (mut bl, mut bodies) = (Vec::new(), Vec::new());
        setup.arm().body_poses(&q, &mut bl, &mut bodies);
        for (c, &(first, _)) in cl_spheres(&with).iter().enumerate() {
            let sphere = with.clusters.placed(c, &bodies);
            // A link's cluster (the first spheres) or one body alone.
            let own: Vec<usize> = if c < with.clusters.spheres.len() - alone_count(&with) {
                (0..links.len()).filter(|&i| links[i] == links[first]).collect()
            } else {
                vec![first]
            };
            for i in own {
                for v in &vertices[i] {
                    let w = bodies[i].transform_point(*v);
                    assert!(
                        (w - sphere.centre).length() <= sphere.radius + 1e-9,
                        "sphere {c}, body {i}"
                    );
                    held += 1;
                }
            }
        }
    }
    assert!(held > 1000);
}

fn cl_spheres(v: &super::ArmValidity) -> Vec<(usize, cellplan_geom::spheres::Sphere)> {
    v.clusters.spheres.clone()
}

/// How many of the checker's spheres stand for one body alone (the last ones).
fn alone_count(v: &super::ArmValidity) -> usize {
    let links = v.arm.body_links;
    (0..links.len())
        .filter(|&i| links.iter().filter(|&&l| l == links[i]).count() >= 2)
        .count()
}

/// The bounds taken where a body stands ([`super::ArmValidity::posed_bound`]) hold: over random
/// samples and segment directions, every hull vertex of every moving body moves, within a
/// parameter `s ≤ t` of the sample either way, no farther than `s` times the body's bound over
/// `t`, and every self pair's distance changes by no more than its bound allows. They are also
/// tighter than the bounds that hold everywhere, by a sixth or more for the tool's bodies on
/// average: a test that would notice them reverting to those.
#[test]
fn posed_bounds_bound_the_motion() {
    use crate::plan::SegmentMotion;
    let setup = ur5();
    let arm = setup.arm();
    let v = setup.validity(0.0);
    let space = crate::arm::joint_space(&arm, &[]);
    let n = arm.body_links.len();
    let hulls = hull_vertices(&arm);
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let (mut links, mut poses, mut moved) = (Vec::new(), Vec::<Pose>::new(), Vec::<Pose>::new());
    let mut axes = super::PosedAxes::default();
    let (mut posed_sum, mut static_sum) = (0.0, 0.0);
    for _ in 0..80 {
        let q = random_configuration(&arm, &mut rng);
        let delta: Vec<f64> = q.iter().map(|_| rng.random_range(-1.5..1.5)).collect();
        let motion = SegmentMotion::new(&space.radii, &delta);
        let t = rng.random_range(0.02..0.6);
        arm.body_poses(&q, &mut links, &mut poses);
        axes.place(&v, &links);
        let bounds: Vec<f64> = v
            .moving
            .iter()
            .map(|(i, joints)| {
                let own = &v.body_radii[*i];
                let drift = motion.drift_with(joints, own);
                v.posed_bound(
                    motion.bound_with(joints, own),
                    drift,
                    *i,
                    joints,
                    &poses,
                    &axes,
                    &motion,
                    t,
                )
            })
            .collect();
        let pair_bounds: Vec<f64> = v
            .pairs
            .iter()
            .enumerate()
            .map(|(k, (_, _, joints, own))| {
                let drift = motion.drift_with(joints, own);
                v.posed_bound(
                    motion.bound_with(joints, own),
                    drift,
                    v.pair_far[k],
                    joints,
                    &poses,
                    &axes,
                    &motion,
                    t,
                )
            })
            .collect();
        for (k, (i, joints)) in v.moving.iter().enumerate() {
            let everywhere = motion.bound_with(joints, &v.body_radii[*i]);
            if joints.end == arm.chain.dof() {
                posed_sum += bounds[k];
                static_sum += everywhere;
            }
        }
        let distances = |p: &[Pose]| -> Vec<f64> {
            v.pairs
                .iter()
                .map(|&(i, j, _, _)| arm.world.pair_distance(arm.group, i, j, p, 10.0))
                .collect()
        };
        let at_q = distances(&poses);
        // The path each vertex travels, in 30 pieces each way.
        for sign in [-1.0, 1.0] {
            let mut travelled = vec![0.0; n];
            let mut prev = poses.clone();
            for piece in 1..=30 {
                let s = sign * t * piece as f64 / 30.0;
                let qs: Vec<f64> = q.iter().zip(&delta).map(|(x, d)| x + s * d).collect();
                arm.body_poses(&qs, &mut links, &mut moved);
                for (i, far) in travelled.iter_mut().enumerate() {
                    *far += hulls[i]
                        .iter()
                        .map(|p| (moved[i].transform_point(*p) - prev[i].transform_point(*p)).length())
                        .fold(0.0, f64::max);
                }
                prev.clone_from(&moved);
            }
            for (k, (i, _)) in v.moving.iter().enumerate() {
                let far = travelled[*i];
                assert!(
                    far <= t * bounds[k] + 1e-9,
                    "body {i}: {far} > {t} · {}",
                    bounds[k]
                );
            }
        }
        for s in [-1.0, -0.5, -0.1, 0.1, 0.5, 1.0] {
            let s = s * t;
            let qs: Vec<f64> = q.iter().zip(&delta).map(|(x, d)| x + s * d).collect();
            arm.body_poses(&qs, &mut links, &mut moved);
            for (k, d) in distances(&moved).into_iter().enumerate() {
                if d > 0.0 && at_q[k] > 0.0 {
                    assert!(
                        (d - at_q[k]).abs() <= s.abs() * pair_bounds[k] + 1e-6,
                        "pair {k}: {} -> {d}, bound {s} · {}",
                        at_q[k],
                        pair_bounds[k]
                    );
                }
            }
        }
    }
    assert!(posed_sum < 0.85 * static_sum, "{posed_sum} against {static_sum}");
}

/// A pair table's proof of contact holds: wherever it says a pair touches, the pair's exact
/// distance is zero (random configurations, and configurations whose table joint is moved to
/// within a hair of its sample spacing's edges); and it proves most of the base and upper arm's
/// contacts, the contacts most random configurations of the UR5 have.
#[test]
fn pair_tables_prove_only_real_contacts() {
    let setup = ur5();
    let arm = setup.arm();
    let tables = crate::arm::PairTables::build(&arm);
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let (mut links, mut poses) = (Vec::new(), Vec::<Pose>::new());
    let (mut base_contacts, mut base_proven, mut proofs) = (0, 0, 0);
    for _ in 0..3000 {
        let mut q = random_configuration(&arm, &mut rng);
        for &(i, j) in arm.self_pairs {
            let Some(t) = tables.get(i, j) else { continue };
            let k = t.joint();
            // Half the time, the joint a hair off the nearest sample's cell edge.
            if rng.random_bool(0.5) {
                let (lo, step) = (t.lo, t.step);
                let g = ((q[k] - lo) / step).round();
                let edge = lo + step * (g + 0.5 - 1e-9);
                if edge <= arm.chain.joints[k].upper {
                    q[k] = edge;
                }
            }
            arm.body_poses(&q, &mut links, &mut poses);
            let exact = arm.world.pair_distance(arm.group, i, j, &poses, 1.0);
            let proven = t.touches(q[k]);
            assert!(
                !proven || exact <= 0.0,
                "pair ({i}, {j}) proven in contact {exact} m apart at {q:?}"
            );
            proofs += usize::from(proven);
            if (i, j) == (0, 2) && exact <= 0.0 {
                base_contacts += 1;
                base_proven += usize::from(proven);
            }
            assert_eq!(
                tables.prove_contact(&q),
                arm.self_pairs
                    .iter()
                    .any(|&(a, b)| tables.get(a, b).is_some_and(|t| t.touches(q[t.joint()])))
            );
        }
    }
    assert!(proofs > 500, "only {proofs} proofs");
    assert!(
        2 * base_proven > base_contacts,
        "{base_proven} of {base_contacts} contacts of the base and the upper arm proven"
    );
    // Out of range and non-finite values prove nothing.
    let t = tables.get(0, 2).expect("a table for the base and the upper arm");
    assert!(!t.touches(f64::NAN) && !t.touches(f64::INFINITY));
}

/// The parts a check asks after its hint come in an order led by the self pairs most likely in
/// contact: every part once; the pairs `likely_contacts` lists first, in its order (the base
/// and the upper arm among them, every one in contact at some random configuration), then
/// the moving bodies; the same list every time.
#[test]
fn part_order_asks_likely_contacts_first() {
    let setup = ur5();
    let arm = setup.arm();
    let tables = crate::arm::PairTables::build(&arm);
    let likely = tables.likely_contacts().to_vec();
    assert_eq!(likely, crate::arm::PairTables::build(&arm).likely_contacts());
    assert!(likely.contains(&(0, 2)) && likely.len() >= 3, "{likely:?}");
    let v = super::ArmValidity::new(arm, 0.0, Vec::new());
    let (m, p) = (v.moving.len(), v.pairs.len());
    let mut sorted = v.order.clone();
    sorted.sort_unstable();
    assert_eq!(sorted, (0..m + p).collect::<Vec<_>>());
    let first: Vec<(usize, usize)> = v.order[..likely.len()]
        .iter()
        .map(|&k| (v.pairs[k - m].0, v.pairs[k - m].1))
        .collect();
    assert_eq!(first, likely);
    assert_eq!(
        v.order[likely.len()..likely.len() + m],
        (0..m).collect::<Vec<_>>()[..]
    );
    // Each listed pair is in contact somewhere: at some of 2,000 random configurations.
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let (mut links, mut poses) = (Vec::new(), Vec::<Pose>::new());
    let mut seen = vec![false; likely.len()];
    for _ in 0..2000 {
        let q = random_configuration(&arm, &mut rng);
        arm.body_poses(&q, &mut links, &mut poses);
        for (s, &(i, j)) in seen.iter_mut().zip(&likely) {
            *s |= arm.world.pair_distance(arm.group, i, j, &poses, 1e-6) <= 0.0;
        }
    }
    assert!(seen.iter().all(|&s| s), "{seen:?}");
}

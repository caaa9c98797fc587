//! The broad phase against the world's exact queries.
use super::BroadPhase;
use crate::world::tests::random_pose;
use crate::world::{CollisionWorld, GroupBody};
use crate::{DQuat, DVec3, Pose, ShapeSpec};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 + 1e-3 * b.abs()
}

fn hull_body(name: &str, half: DVec3) -> GroupBody {
    GroupBody {
        name: name.into(),
        shapes: vec![
            (ShapeSpec::Box { half_extents: half }, Pose::IDENTITY),
            (
                ShapeSpec::Sphere { radius: half.y },
                Pose::translation(half.x, 0.0, 0.0),
            ),
        ],
    }
}

/// The sphere of several bodies sharing a frame holds each one's outer sphere (and is not
/// much larger than it must be), and a sphere clears the scene at a threshold exactly when
/// every run's box is that far from it.
#[test]
fn a_sphere_of_bodies_holds_their_outer_spheres_and_clears_as_the_boxes_say() {
    let mut world = CollisionWorld::new();
    world.add_static(
        "box",
        &ShapeSpec::Box {
            half_extents: DVec3::new(0.3, 0.2, 0.05),
        },
        Pose::from_parts(DVec3::new(0.0, 0.0, -0.6), DQuat::from_rotation_z(0.4)),
    );
    world.add_static(
        "ball",
        &ShapeSpec::Sphere { radius: 0.15 },
        Pose::translation(0.8, 0.3, 0.2),
    );
    let bodies = (0..4)
        .map(|k| GroupBody {
            name: format!("b{k}"),
            shapes: vec![(
                ShapeSpec::Box {
                    half_extents: DVec3::new(0.02 + 0.03 * k as f64, 0.03, 0.02),
                },
                Pose::translation(0.1 * k as f64, 0.05 * k as f64, 0.0),
            )],
        })
        .collect();
    let g = world.add_group("arm", bodies);
    let broad = BroadPhase::new(&world, g, &[]);
    assert!(broad.outer_of(&[]).is_none());
    for set in [vec![0], vec![0, 1], vec![1, 3], vec![0, 1, 2, 3]] {
        let s = broad.outer_of(&set).unwrap();
        let mut needed = 0.0f64;
        for &i in &set {
            let o = broad.outer[i].unwrap();
            let reach = (o.centre - s.centre).length() + o.radius;
            assert!(
                reach <= s.radius,
                "{set:?}: body {i} reaches {reach} > {}",
                s.radius
            );
            needed = needed.max(reach);
        }
        assert!(
            s.radius <= needed * 1.3 + 1e-9,
            "{set:?}: {} for {needed}",
            s.radius
        );
    }
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut clear = 0;
    for _ in 0..2000 {
        let sphere = super::Sphere {
            centre: DVec3::new(
                rng.random_range(-1.0..1.5),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            ),
            radius: rng.random_range(0.0..0.3),
        };
        let best = rng.random_range(-0.1..0.5);
        let gap = broad
            .runs
            .iter()
            .map(|(lo, hi, _)| super::box_gap(sphere.centre, *lo, *hi).length() - sphere.radius)
            .fold(f64::INFINITY, f64::min);
        assert_eq!(
            broad.sphere_clears_scene(sphere, best),
            gap >= best.max(0.0),
            "{sphere:?} at {best}"
        );
        clear += usize::from(gap >= best.max(0.0));
    }
    assert!((200..1800).contains(&clear), "{clear} clear");
    let nan = super::Sphere {
        centre: DVec3::NAN,
        radius: 0.1,
    };
    assert!(!broad.sphere_clears_scene(nan, 0.0));
}

/// Over random placements, the broad phase (with its guesses of the separating directions)
/// gives the exact distances of the world's own
/// queries: to every object kind, to a parked group, between two bodies, under any cap —
/// up to GJK's tolerance: a seeded run stops at another point of its convergence, which is
/// slow against curved shapes (the ball: a few 1e-4 of the distance). Both answers are
/// certified lower bounds (see `hinted_distance`), so neither is ever too large. Asked to a
/// precision, they stay below the exact ones and within that share of them.
#[test]
fn broad_phase_distances_equal_the_exact_ones() {
    let mut world = CollisionWorld::new();
    world.add_static(
        "box",
        &ShapeSpec::Box {
            half_extents: DVec3::new(0.3, 0.2, 0.05),
        },
        Pose::from_parts(DVec3::new(0.0, 0.0, 0.0), DQuat::from_rotation_z(0.4)),
    );
    world.add_static(
        "drum",
        &ShapeSpec::Cylinder {
            radius: 0.1,
            half_height: 0.3,
        },
        Pose::from_parts(DVec3::new(0.6, 0.0, 0.0), DQuat::from_rotation_x(0.7)),
    );
    world.add_static(
        "ball",
        &ShapeSpec::Sphere { radius: 0.15 },
        Pose::translation(-0.5, 0.3, 0.2),
    );
    let sheet = crate::Mesh {
        vertices: vec![
            DVec3::new(-1.0, -1.0, 0.5),
            DVec3::new(1.0, -1.0, 0.5),
            DVec3::new(1.0, 1.0, 0.5),
            DVec3::new(-1.0, 1.0, 0.7),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    world.add_static(
        "sheet",
        &ShapeSpec::Mesh(std::sync::Arc::new(sheet)),
        Pose::IDENTITY,
    );
    let g = world.add_group(
        "arm",
        vec![
            hull_body("a", DVec3::new(0.2, 0.03, 0.04)),
            hull_body("b", DVec3::new(0.1, 0.05, 0.05)),
        ],
    );
    let other = world.add_group("parked", vec![hull_body("c", DVec3::new(0.15, 0.04, 0.04))]);
    let parked_poses = vec![Pose::translation(0.2, -0.5, -0.3)];
    let broad = BroadPhase::new(&world, g, &[(other, parked_poses.clone())]);
    assert_eq!(broad.object_count(), 5);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut placed = super::PlacedCovers::default();
    let (mut near, mut touching, mut coarse) = (0, 0, 0);
    for _ in 0..4000 {
        let poses = [random_pose(&mut rng, 0.8), random_pose(&mut rng, 0.8)];
        let cap = if rng.random_bool(0.5) {
            10.0
        } else {
            rng.random_range(0.0..0.2)
        };
        broad.place(&poses, &mut placed);
        for i in 0..2 {
            let exact = world
                .body_static_distance(g, i, &poses, cap)
                .min(world.body_group_distance(g, i, &poses, other, &parked_poses, cap));
            let fast = broad.scene_distance(&world, i, &poses, &placed, cap);
            assert!(close(fast, exact), "body {i}: {fast} vs {exact} (cap {cap})");
            let bound = broad.scene_bound(&world, i, &placed, cap);
            assert!(bound <= exact + 1e-9, "bound {bound} above {exact}");
            assert!(bound <= cap.max(0.0));
            if exact > 0.0 && exact < cap.min(0.05) {
                near += 1;
                // Tight enough to be of use near the objects.
                assert!(bound >= exact - 0.12, "bound {bound} far below {exact}");
            }
            touching += usize::from(exact == 0.0);
        }
        // To a precision: never above the distance, never below it by more than the share of
        // its excess over `above`, and on the same side of `above` as the distance.
        for share in [1e-2, 0.1] {
            let above = rng.random_range(0.0..0.05);
            let precision = crate::Precision { share, above };
            // The exact answers' own tolerance (see `close`).
            let check = |within: f64, exact: f64, what: &str| {
                let slack = 1e-9 + 1e-3 * exact;
                let low = above + (1.0 - share) * (exact - above) - slack;
                assert!(within <= exact + slack, "{what}: {within} above {exact}");
                if exact >= above + slack {
                    assert!(within >= low, "{what}: {within} vs {exact} to {precision:?}");
                } else if exact < above - slack {
                    assert!(within < above, "{what}: {within} vs {exact} to {precision:?}");
                }
                usize::from(within < exact - slack)
            };
            let exact = world
                .body_static_distance(g, 0, &poses, cap)
                .min(world.body_group_distance(g, 0, &poses, other, &parked_poses, cap));
            let within = broad.scene_distance_enough(&world, 0, &poses, &placed, (cap, cap, precision));
            coarse += check(within, exact, "scene");
            let exact = world.pair_distance(g, 0, 1, &poses, cap);
            let within = broad.pair_distance_or(&world, 0, 1, &poses, &placed, (cap, cap, precision), || 0.0);
            coarse += check(within, exact, "pair");
        }
        let exact = world.pair_distance(g, 0, 1, &poses, cap);
        let fast = broad.pair_distance(&world, 0, 1, &poses, &placed, cap);
        assert!(close(fast, exact), "pair: {fast} vs {exact} (cap {cap})");
        let bound = broad.pair_bound(0, 1, &placed, cap);
        assert!(bound <= exact + 1e-9, "pair bound {bound} above {exact}");
        // Another lower bound (asked before the covers when `enough >= cap`) changes no
        // answer: anywhere from nothing to the distance itself, with the cap far or just
        // above the distance.
        let share = if rng.random_bool(0.5) {
            1.0
        } else {
            rng.random_range(0.0..1.0)
        };
        for cap in [cap, exact + 5e-4] {
            let exact = world.pair_distance(g, 0, 1, &poses, cap);
            let other = || exact * share;
            for enough in [cap, cap + 1.0] {
                let with = broad.pair_distance_or(
                    &world,
                    0,
                    1,
                    &poses,
                    &placed,
                    (cap, enough, crate::Precision::EXACT),
                    other,
                );
                assert!(
                    close(with, exact),
                    "pair with another bound: {with} vs {exact} (cap {cap})"
                );
            }
        }
    }
    assert!(
        near > 50 && touching > 50 && coarse > 50,
        "the test places bodies near and on the objects ({near}, {touching}), and a precision \
         stops GJK short of the distance ({coarse})"
    );
    // A non-finite pose is at distance 0, bound and exact alike.
    let bad = [Pose::translation(f64::NAN, 0.0, 0.0), Pose::IDENTITY];
    broad.place(&bad, &mut placed);
    assert_eq!(broad.scene_bound(&world, 0, &placed, 1.0), 0.0);
    assert_eq!(broad.scene_distance(&world, 0, &bad, &placed, 1.0), 0.0);
    assert_eq!(broad.pair_bound(0, 1, &placed, 1.0), 0.0);
}

/// A sphere holding the first set lets `spheres_bound` pass over spheres of the second, and
/// changes neither the bound nor its direction: random sets placed by random poses, with caps
/// at which a pair is just within reach, just beyond it, or far.
#[test]
fn a_holding_sphere_changes_no_bound() {
    use super::{Sphere, spheres_bound};
    use std::cell::Cell;
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut passed, mut asked) = (0, 0);
    for _ in 0..300 {
        let local = |rng: &mut ChaCha8Rng| -> Vec<Sphere> {
            (0..rng.random_range(1..9))
                .map(|_| Sphere {
                    centre: DVec3::new(
                        rng.random_range(-0.5..0.5),
                        rng.random_range(-0.5..0.5),
                        rng.random_range(-0.5..0.5),
                    ),
                    radius: rng.random_range(0.01..0.2),
                })
                .collect()
        };
        let (la, lb) = (local(&mut rng), local(&mut rng));
        let holder_local = crate::spheres::enclosing(&la).expect("one sphere at least");
        let (pa, pb) = (random_pose(&mut rng, 1.0), random_pose(&mut rng, 1.0));
        let place = |l: &[Sphere], p: &Pose| -> Vec<Sphere> {
            l.iter()
                .map(|s| Sphere {
                    centre: p.transform_point(s.centre),
                    radius: s.radius,
                })
                .collect()
        };
        let a: Vec<Cell<Sphere>> = place(&la, &pa).into_iter().map(Cell::new).collect();
        let b = place(&lb, &pb);
        let holder = Sphere {
            centre: pa.transform_point(holder_local.centre),
            radius: holder_local.radius,
        };
        let mut caps = vec![0.0, 0.1, 1.0, f64::INFINITY];
        for sa in a.iter().map(Cell::get).take(2) {
            for sb in b.iter().take(2) {
                let d = (sb.centre - sa.centre).length() - sa.radius - sb.radius;
                caps.extend([d, d.next_up(), d.next_down()]);
            }
        }
        for cap in caps {
            let want = spheres_bound(&a, None, &b, cap);
            let got = spheres_bound(&a, Some(holder), &b, cap);
            assert_eq!(got.0.to_bits(), want.0.to_bits(), "cap {cap}");
            assert_eq!(got.1, want.1, "cap {cap}");
            // How often the holder let a sphere of `b` be passed over.
            asked += b.len();
            passed += b
                .iter()
                .filter(|sb| (sb.centre - holder.centre).length() - holder.radius - sb.radius >= cap + 1e-9)
                .count();
        }
    }
    assert!(passed > 1000 && passed < asked, "{passed} of {asked} passed over");
}

/// The squared tests of spheres against spheres and boxes give the answers of the distances
/// they stand for (random spheres, boxes and gaps, away from the boundary by more than
/// rounding), and a non-finite centre is never apart.
#[test]
fn squared_sphere_tests_agree_with_distances() {
    use crate::Sphere;
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let mut v = |s: f64| crate::random_vector(&mut rng, s);
    let (mut yes, mut no) = (0, 0);
    for _ in 0..20_000 {
        let a = Sphere {
            centre: v(1.0),
            radius: v(0.3).x.abs(),
        };
        let b = Sphere {
            centre: v(1.0),
            radius: v(0.3).y.abs(),
        };
        let gap = v(0.3).z;
        let d = (a.centre - b.centre).length() - a.radius - b.radius;
        if (d - gap).abs() > 1e-12 {
            assert_eq!(a.apart_by(&b, gap), d >= gap, "{a:?} {b:?} {gap}");
            if d >= gap { yes += 1 } else { no += 1 }
        }
        let (lo, size) = (v(1.0), v(0.5).abs());
        let hi = lo + size;
        let d = super::box_gap(a.centre, lo, hi).length() - a.radius;
        if (d - gap).abs() > 1e-12 {
            assert_eq!(super::sphere_box_apart(a.centre, a.radius, lo, hi, gap), d >= gap);
        }
    }
    assert!(yes > 1000 && no > 200, "{yes} {no}");
    let nan = Sphere {
        centre: DVec3::splat(f64::NAN),
        radius: 0.1,
    };
    let one = Sphere {
        centre: DVec3::ZERO,
        radius: 0.1,
    };
    assert!(!nan.apart_by(&one, 0.0) && !nan.apart_by(&one, -1.0));
    // (A box test with a non-finite centre sees it inside: apart only for a negative reach.)
    assert!(!super::sphere_box_apart(
        nan.centre,
        0.1,
        DVec3::ZERO,
        DVec3::ONE,
        0.0
    ));
}

use super::*;
use crate::DQuat;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
use std::sync::Arc;

/// A random rigid pose within `spread` of the origin (for the bounds' and broad phase's tests).
pub(super) fn random_pose(rng: &mut rand_chacha::ChaCha8Rng, spread: f64) -> Pose {
    use rand::RngExt;
    let t = DVec3::new(
        rng.random_range(-spread..spread),
        rng.random_range(-spread..spread),
        rng.random_range(-spread..spread),
    );
    let q = DQuat::from_xyzw(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    )
    .normalize();
    Pose::from_parts(t, q)
}

fn cube(h: f64) -> ShapeSpec {
    ShapeSpec::Box {
        half_extents: DVec3::splat(h),
    }
}

fn at(x: f64, y: f64, z: f64) -> Pose {
    Pose::from_translation(DVec3::new(x, y, z))
}

fn body(name: &str, shapes: Vec<(ShapeSpec, Pose)>) -> GroupBody {
    GroupBody {
        name: name.into(),
        shapes,
    }
}

/// A world with one static shape at `static_pose` and one group of one body.
fn one_on_one(s: &ShapeSpec, static_pose: Pose, b: &ShapeSpec) -> (CollisionWorld, GroupId) {
    let mut w = CollisionWorld::new();
    w.add_static("object", s, static_pose);
    let g = w.add_group("robot", vec![body("b", vec![(b.clone(), Pose::IDENTITY)])]);
    (w, g)
}

/// The closed surface of the box [0,1]³ (12 triangles).
fn unit_cube_mesh() -> Mesh {
    ShapeSpec::Box {
        half_extents: DVec3::splat(0.5),
    }
    .to_mesh()
    .transformed(&Pose::from_translation(DVec3::splat(0.5)))
}

#[test]
fn world_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<CollisionWorld>();
}

#[test]
fn names_and_counts() {
    let mut w = CollisionWorld::new();
    let a = w.add_static("table", &cube(0.5), Pose::IDENTITY);
    let b = w.add_static("fence", &cube(0.5), at(3.0, 0.0, 0.0));
    assert_eq!((a, b), (StaticId(0), StaticId(1)));
    assert_eq!(w.static_count(), 2);
    assert_eq!(w.static_name(b), "fence");
    let (lo, hi) = w.static_aabb(b).unwrap();
    assert!((lo - DVec3::new(2.5, -0.5, -0.5)).length() < 1e-12);
    assert!((hi - DVec3::new(3.5, 0.5, 0.5)).length() < 1e-12);
    let g = w.add_group(
        "r1",
        vec![
            body("base", vec![]),
            body("link", vec![(cube(0.1), Pose::IDENTITY)]),
        ],
    );
    assert_eq!(w.group_count(), 1);
    assert_eq!(w.group_name(g), "r1");
    assert_eq!(w.body_count(g), 2);
    assert_eq!(w.body_name(g, 1), "link");
    assert!(w.body_hull(g, 0).is_none());
    let hull = w.body_hull(g, 1).unwrap();
    assert_eq!(hull.aabb(), Some((DVec3::splat(-0.1), DVec3::splat(0.1))));
}

#[test]
fn box_margin_semantics() {
    let (w, g) = one_on_one(&cube(0.5), Pose::IDENTITY, &cube(0.5));
    // Faces 0.02 apart.
    let p = [at(1.02, 0.0, 0.0)];
    assert_eq!(w.group_vs_static(g, &p, 0.0), None);
    assert_eq!(w.group_vs_static(g, &p, 0.01), None);
    assert_eq!(
        w.group_vs_static(g, &p, 0.03),
        Some(BodyContact::Static {
            body: 0,
            object: StaticId(0)
        })
    );
    assert!((w.min_distance_to_static(g, &p) - 0.02).abs() < 1e-9);
    // Overlapping by 0.01.
    let p = [at(0.99, 0.3, -0.2)];
    assert!(w.group_vs_static(g, &p, 0.0).is_some());
    assert_eq!(w.min_distance_to_static(g, &p), 0.0);
    // A negative or NaN margin counts as zero.
    assert!(w.group_vs_static(g, &[at(1.02, 0.0, 0.0)], -1.0).is_none());
    assert!(w.group_vs_static(g, &[at(1.02, 0.0, 0.0)], f64::NAN).is_none());
}

#[test]
fn rotated_box_distance() {
    let (w, g) = one_on_one(&cube(0.5), Pose::IDENTITY, &cube(0.5));
    // Rotated 45° about z, the body's corner reaches 0.5·√2 towards the static box.
    let reach = 0.5 * 2f64.sqrt();
    let p = [Pose::from_parts(
        DVec3::new(0.5 + reach + 0.05, 0.0, 0.0),
        DQuat::from_rotation_z(FRAC_PI_4),
    )];
    assert!((w.min_distance_to_static(g, &p) - 0.05).abs() < 1e-9);
    assert!(w.group_vs_static(g, &p, 0.049).is_none());
    assert!(w.group_vs_static(g, &p, 0.051).is_some());
}

#[test]
fn static_cylinder_axis_is_z() {
    let cyl = ShapeSpec::Cylinder {
        radius: 0.1,
        half_height: 1.0,
    };
    let ball = ShapeSpec::Sphere { radius: 0.05 };
    let (w, g) = one_on_one(&cyl, Pose::IDENTITY, &ball);
    assert!(w.group_vs_static(g, &[at(0.0, 0.0, 0.9)], 0.0).is_some());
    assert!((w.min_distance_to_static(g, &[at(0.0, 0.0, 1.2)]) - 0.15).abs() < 1e-9);
    // Along x and y the cylinder is only 0.1 thick.
    assert!(w.group_vs_static(g, &[at(0.9, 0.0, 0.0)], 0.0).is_none());
    assert!(w.group_vs_static(g, &[at(0.0, 0.9, 0.0)], 0.0).is_none());
    assert!((w.min_distance_to_static(g, &[at(0.0, 0.5, 0.3)]) - 0.35).abs() < 1e-9);
    let (lo, hi) = w.static_aabb(StaticId(0)).unwrap();
    assert!((hi - DVec3::new(0.1, 0.1, 1.0)).length() < 1e-12 && (lo + hi).length() < 1e-12);
}

#[test]
fn body_cylinder_axis_is_z_and_follows_its_pose() {
    let cyl = ShapeSpec::Cylinder {
        radius: 0.1,
        half_height: 1.0,
    };
    let (w, g) = one_on_one(&ShapeSpec::Sphere { radius: 0.05 }, Pose::IDENTITY, &cyl);
    assert!(w.group_vs_static(g, &[at(0.0, 0.0, 1.0)], 0.0).is_some());
    assert!(w.group_vs_static(g, &[at(0.5, 0.0, 0.0)], 0.0).is_none());
    // Turned 90° about y, the axis lies along x.
    let turned = Pose::from_parts(DVec3::new(1.0, 0.0, 0.0), DQuat::from_rotation_y(FRAC_PI_2));
    assert!(w.group_vs_static(g, &[turned], 0.0).is_some());
    // The hull of a cylinder and another shape is conservative: it contains the cylinder.
    let mut w2 = CollisionWorld::new();
    w2.add_static("ball", &ShapeSpec::Sphere { radius: 0.01 }, at(0.1, 0.0, 0.0));
    let g2 = w2.add_group(
        "r",
        vec![body(
            "two",
            vec![(cyl.clone(), Pose::IDENTITY), (cube(0.01), at(0.0, 0.0, 3.0))],
        )],
    );
    assert!(w2.group_vs_static(g2, &[Pose::IDENTITY], 0.0).is_some());
}

#[test]
fn ray_hits_box() {
    let mut w = CollisionWorld::new();
    w.add_static("near", &cube(0.5), at(2.0, 0.0, 0.0));
    w.add_static("far", &cube(0.5), at(5.0, 0.0, 0.0));
    let hit = w.cast_ray_static(DVec3::ZERO, DVec3::X, 10.0).unwrap();
    assert_eq!(hit.object, StaticId(0));
    assert!((hit.distance - 1.5).abs() < 1e-12);
    // The direction is normalised.
    let hit = w.cast_ray_static(DVec3::ZERO, DVec3::X * 3.0, 10.0).unwrap();
    assert!((hit.distance - 1.5).abs() < 1e-12);
    // Too short, wrong way, degenerate.
    assert!(w.cast_ray_static(DVec3::ZERO, DVec3::X, 1.4).is_none());
    assert!(w.cast_ray_static(DVec3::ZERO, -DVec3::X, 10.0).is_none());
    assert!(w.cast_ray_static(DVec3::ZERO, DVec3::ZERO, 10.0).is_none());
    assert!(w.cast_ray_static(DVec3::ZERO, DVec3::X, f64::NAN).is_none());
    // From inside a box: solid, distance 0.
    let hit = w
        .cast_ray_static(DVec3::new(5.1, 0.0, 0.0), DVec3::Y, 10.0)
        .unwrap();
    assert_eq!((hit.object, hit.distance), (StaticId(1), 0.0));
    // From between the boxes, backwards.
    let hit = w
        .cast_ray_static(DVec3::new(4.0, 0.2, 0.2), -DVec3::X, 10.0)
        .unwrap();
    assert_eq!(hit.object, StaticId(0));
    assert!((hit.distance - 1.5).abs() < 1e-12);
}

#[test]
fn ray_hits_mesh_from_both_sides() {
    let mut w = CollisionWorld::new();
    let pose = Pose::from_parts(DVec3::new(10.0, 0.0, 0.0), DQuat::from_rotation_z(FRAC_PI_2));
    w.add_static("cube", &ShapeSpec::Mesh(Arc::new(unit_cube_mesh())), pose);
    // In the world the cube spans x ∈ [9, 10], y ∈ [0, 1], z ∈ [0, 1].
    let hit = w
        .cast_ray_static(DVec3::new(0.0, 0.5, 0.5), DVec3::X, 100.0)
        .unwrap();
    assert!((hit.distance - 9.0).abs() < 1e-9, "{hit:?}");
    // From inside, the surface is hit at the far wall.
    let hit = w
        .cast_ray_static(DVec3::new(9.3, 0.5, 0.5), DVec3::X, 100.0)
        .unwrap();
    assert!((hit.distance - 0.7).abs() < 1e-9, "{hit:?}");
    let hit = w
        .cast_ray_static(DVec3::new(9.3, 0.5, 0.5), -DVec3::Z, 100.0)
        .unwrap();
    assert!((hit.distance - 0.5).abs() < 1e-9, "{hit:?}");
    assert!(
        w.cast_ray_static(DVec3::new(9.3, 0.5, 0.5), -DVec3::Z, 0.4)
            .is_none()
    );
}

#[test]
fn mesh_is_a_surface_not_a_solid() {
    let mut w = CollisionWorld::new();
    w.add_static(
        "shell",
        &ShapeSpec::Mesh(Arc::new(unit_cube_mesh())),
        Pose::IDENTITY,
    );
    let g = w.add_group("r", vec![body("b", vec![(cube(0.1), Pose::IDENTITY)])]);
    // Wholly inside: no contact (documented), but the distance to the walls is right.
    assert!(w.group_vs_static(g, &[at(0.5, 0.5, 0.5)], 0.0).is_none());
    assert!((w.min_distance_to_static(g, &[at(0.5, 0.5, 0.5)]) - 0.4).abs() < 1e-9);
    assert!(w.group_vs_static(g, &[at(0.5, 0.5, 0.5)], 0.41).is_some());
    // Across a wall: contact.
    assert!(w.group_vs_static(g, &[at(0.95, 0.5, 0.5)], 0.0).is_some());
    // Outside, 0.05 from the wall.
    let p = [at(1.15, 0.5, 0.5)];
    assert!(w.group_vs_static(g, &p, 0.04).is_none());
    assert!(w.group_vs_static(g, &p, 0.06).is_some());
    assert!((w.min_distance_to_static(g, &p) - 0.05).abs() < 1e-9);
}

#[test]
fn first_contact_order_is_bodies_then_objects() {
    let mut w = CollisionWorld::new();
    w.add_static("a", &cube(0.5), at(0.0, 0.0, 0.0));
    w.add_static("b", &cube(0.5), at(0.0, 0.0, 0.0));
    w.add_static("c", &cube(0.5), at(5.0, 0.0, 0.0));
    let g = w.add_group(
        "r",
        vec![
            body("free", vec![(cube(0.1), Pose::IDENTITY)]),
            body("empty", vec![]),
            body("hits c", vec![(cube(0.1), Pose::IDENTITY)]),
            body("hits a and b", vec![(cube(0.1), Pose::IDENTITY)]),
        ],
    );
    let poses = [
        at(2.5, 0.0, 0.0),
        at(0.0, 0.0, 0.0),
        at(5.0, 0.0, 0.0),
        at(0.0, 0.0, 0.0),
    ];
    assert_eq!(
        w.group_vs_static(g, &poses, 0.0),
        Some(BodyContact::Static {
            body: 2,
            object: StaticId(2)
        })
    );
    let poses = [
        at(2.5, 0.0, 0.0),
        at(0.0, 0.0, 0.0),
        at(2.5, 0.0, 0.0),
        at(0.4, 0.0, 0.0),
    ];
    assert_eq!(
        w.group_vs_static(g, &poses, 0.0),
        Some(BodyContact::Static {
            body: 3,
            object: StaticId(0)
        })
    );
    // Distance: body 3 is 0.5 - 0.1 + ... well apart when moved away.
    let poses = [
        at(2.5, 0.0, 0.0),
        at(0.0, 0.0, 0.0),
        at(2.5, 0.0, 0.0),
        at(2.0, 0.0, 0.0),
    ];
    assert!((w.min_distance_to_static(g, &poses) - 1.4).abs() < 1e-9);
}

#[test]
fn empty_world_and_empty_bodies() {
    let mut w = CollisionWorld::new();
    let g = w.add_group(
        "r",
        vec![body("a", vec![]), body("b", vec![(cube(0.1), Pose::IDENTITY)])],
    );
    let p = [Pose::IDENTITY, Pose::IDENTITY];
    assert!(w.group_vs_static(g, &p, 1.0).is_none());
    assert_eq!(w.min_distance_to_static(g, &p), f64::INFINITY);
    assert!(w.cast_ray_static(DVec3::ZERO, DVec3::X, 1.0).is_none());
    // A body without shapes touches nothing, even at the same place.
    assert!(!w.bodies_within(g, 0, 1, &p, 1.0));
    w.add_static(
        "floor",
        &ShapeSpec::Mesh(Arc::new(Mesh::default())),
        Pose::IDENTITY,
    );
    assert!(w.group_vs_static(g, &p, 1.0).is_none());
    assert!(w.static_aabb(StaticId(0)).is_none());
}

#[test]
fn non_finite_poses_count_as_contact() {
    let (w, g) = one_on_one(&cube(0.5), at(10.0, 0.0, 0.0), &cube(0.1));
    let bad = [at(f64::NAN, 0.0, 0.0)];
    assert_eq!(
        w.group_vs_static(g, &bad, 0.0),
        Some(BodyContact::Static {
            body: 0,
            object: StaticId(0)
        })
    );
    assert_eq!(w.min_distance_to_static(g, &bad), 0.0);
    assert!(w.cast_ray_group(g, &bad, DVec3::ZERO, DVec3::X, 100.0).is_none());
}

fn three_boxes() -> (CollisionWorld, GroupId) {
    let mut w = CollisionWorld::new();
    let g = w.add_group(
        "r",
        (0..3)
            .map(|i| body(&format!("l{i}"), vec![(cube(0.5), Pose::IDENTITY)]))
            .collect(),
    );
    (w, g)
}

#[test]
fn self_pairs_are_filtered() {
    let (mut w, g) = three_boxes();
    // 0 and 2 overlap; 1 is far from both.
    let p = [at(0.0, 0.0, 0.0), at(5.0, 0.0, 0.0), at(0.5, 0.0, 0.0)];
    assert_eq!(w.group_self(g, &p, 0.0), None, "no pairs until set");
    assert!(w.bodies_within(g, 0, 2, &p, 0.0));
    assert!(w.bodies_within(g, 2, 0, &p, 0.0));
    assert!(!w.bodies_within(g, 0, 1, &p, 0.0));
    assert!(!w.bodies_within(g, 0, 0, &p, 0.0));
    assert!(!w.bodies_within(g, 0, 7, &p, 0.0));
    w.set_self_pairs(g, vec![(0, 1)]);
    assert_eq!(w.group_self(g, &p, 0.0), None);
    assert_eq!(w.group_self(g, &p, 4.1), Some(BodyContact::SelfPair(0, 1)));
    w.set_self_pairs(g, vec![(2, 0), (1, 2), (0, 2), (1, 1), (0, 9)]);
    assert_eq!(w.self_pairs(g), &[(0, 2), (1, 2)]);
    assert_eq!(w.group_self(g, &p, 0.0), Some(BodyContact::SelfPair(0, 2)));
    let apart = [at(0.0, 0.0, 0.0), at(5.0, 0.0, 0.0), at(1.1, 0.0, 0.0)];
    assert_eq!(w.group_self(g, &apart, 0.05), None);
    assert_eq!(w.group_self(g, &apart, 0.15), Some(BodyContact::SelfPair(0, 2)));
}

/// The three boxes and a second group (a cube and a sphere), with poses that keep them apart:
/// the closest pair is box 2 and the sphere, 0.1–0.25 apart.
fn two_groups() -> (CollisionWorld, GroupId, GroupId, [Pose; 3], [Pose; 2]) {
    let (mut w, a) = three_boxes();
    let b = w.add_group(
        "other",
        vec![
            body("x", vec![(cube(0.5), Pose::IDENTITY)]),
            body("y", vec![(ShapeSpec::Sphere { radius: 0.5 }, Pose::IDENTITY)]),
        ],
    );
    let pa = [at(0.0, 0.0, 0.0), at(0.0, 3.0, 0.0), at(0.0, 6.0, 0.0)];
    let pb = [at(10.0, 0.0, 0.0), at(1.2, 6.0, 0.0)];
    (w, a, b, pa, pb)
}

#[test]
fn group_vs_group_pairs() {
    let (w, a, b, pa, pb) = two_groups();
    assert_eq!(w.group_vs_group(a, &pa, b, &pb, 0.0), None);
    assert_eq!(w.group_vs_group(a, &pa, b, &pb, 0.1), None);
    assert_eq!(
        w.group_vs_group(a, &pa, b, &pb, 0.25),
        Some(BodyContact::Pair(2, 1))
    );
    assert_eq!(
        w.group_vs_group(b, &pb, a, &pa, 0.25),
        Some(BodyContact::Pair(1, 2))
    );
    let pb = [at(0.0, 3.5, 0.0), at(0.0, 6.5, 0.0)];
    assert_eq!(
        w.group_vs_group(a, &pa, b, &pb, 0.0),
        Some(BodyContact::Pair(1, 0))
    );
    // A group against itself: all pairs i < j, whatever the self-pair list.
    let close = [at(0.0, 0.0, 0.0), at(0.0, 3.0, 0.0), at(0.0, 3.9, 0.0)];
    assert_eq!(
        w.group_vs_group(a, &close, a, &close, 0.0),
        Some(BodyContact::Pair(1, 2))
    );
    assert_eq!(w.group_vs_group(a, &pa, a, &pa, 0.0), None);
}

#[test]
fn group_group_distance_is_the_closest_pair() {
    let (w, a, b, pa, pb) = two_groups();
    let d = w.group_group_distance(a, &pa, b, &pb, 10.0);
    assert!(d > 0.1 && d < 0.25, "{d}");
    assert!((w.group_group_distance(b, &pb, a, &pa, 10.0) - d).abs() < 1e-9);
    // The distance agrees with the margin test on both sides of it.
    assert!(w.group_vs_group(a, &pa, b, &pb, d - 1e-6).is_none());
    assert!(w.group_vs_group(a, &pa, b, &pb, d + 1e-6).is_some());
    // Capped below the distance: the cap.
    assert_eq!(w.group_group_distance(a, &pa, b, &pb, 0.05), 0.05);
    // Touching: 0.
    let pb = [at(0.0, 3.5, 0.0), at(0.0, 6.5, 0.0)];
    assert_eq!(w.group_group_distance(a, &pa, b, &pb, 10.0), 0.0);
    // A pose that is not finite counts as touching.
    let pb = [at(f64::NAN, 0.0, 0.0), at(20.0, 0.0, 0.0)];
    assert_eq!(w.group_group_distance(a, &pa, b, &pb, 10.0), 0.0);
}

/// The group distance (each body placed once, exact queries only where the sphere covers come
/// close) is the smallest body-to-group distance, at any poses and caps.
#[test]
fn group_group_distance_is_the_smallest_body_distance_at_random_poses() {
    use rand::{RngExt, SeedableRng};
    let (w, a, b, _, _) = two_groups();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let pose = |rng: &mut rand_chacha::ChaCha8Rng| {
        let t = DVec3::new(
            rng.random_range(-2.0..2.0),
            rng.random_range(-1.0..7.0),
            rng.random_range(-2.0..2.0),
        );
        let axis = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), 1.0).normalize();
        Pose {
            translation: t,
            rotation: DQuat::from_axis_angle(axis, rng.random_range(-3.0..3.0)),
        }
    };
    let (mut near, mut touching) = (0, 0);
    for _ in 0..400 {
        let pa: Vec<Pose> = (0..3).map(|_| pose(&mut rng)).collect();
        let pb: Vec<Pose> = (0..2).map(|_| pose(&mut rng)).collect();
        for cap in [0.05, 0.5, 10.0] {
            let d = w.group_group_distance(a, &pa, b, &pb, cap);
            let by_body = (0..3)
                .map(|i| w.body_group_distance(a, i, &pa, b, &pb, cap))
                .fold(cap, f64::min);
            assert!((d - by_body).abs() < 1e-9, "{d} against {by_body} (cap {cap})");
            // Asking any pair first gives the same answer, and leaves the closest pair.
            for start in [None, Some((0, 0)), Some((2, 1)), Some((1, 0)), Some((7, 7))] {
                let mut closest = start;
                let from = w.group_group_distance_from(a, &pa, b, &pb, cap, &mut closest);
                assert_eq!(from.to_bits(), d.to_bits(), "from {start:?}: {from} against {d}");
                if d < cap {
                    let (i, j) = closest.expect("a pair within the cap");
                    let pair = w.body_body_distance(a, i, &pa, b, j, &pb[j], cap);
                    assert!((pair - d).abs() < 1e-9, "pair {i}, {j} at {pair}, closest {d}");
                } else {
                    assert_eq!(closest, start, "nothing within the cap: the pair stays");
                }
            }
            near += usize::from(d > 0.0 && d < cap);
            touching += usize::from(d == 0.0);
        }
    }
    assert!(near > 50 && touching > 50, "{near} near, {touching} touching");
}

#[test]
fn ray_hits_group_bodies() {
    let (w, g) = three_boxes();
    let p = [at(2.0, 0.0, 0.0), at(5.0, 0.0, 0.0), at(0.0, 3.0, 0.0)];
    let (i, t) = w.cast_ray_group(g, &p, DVec3::ZERO, DVec3::X, 100.0).unwrap();
    assert_eq!(i, 0);
    assert!((t - 1.5).abs() < 1e-12);
    let (i, t) = w
        .cast_ray_group(g, &p, DVec3::new(10.0, 0.0, 0.0), -DVec3::X, 100.0)
        .unwrap();
    assert_eq!(i, 1);
    assert!((t - 4.5).abs() < 1e-12);
    assert!(w.cast_ray_group(g, &p, DVec3::ZERO, DVec3::Z, 100.0).is_none());
}

mod exact;

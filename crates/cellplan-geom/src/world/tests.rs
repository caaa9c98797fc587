use super::narrow::AxisCache;
use super::*;
use crate::{DQuat, load_mesh};
use parry3d_f64::query;
use parry3d_f64::shape::Triangle;
use proptest::prelude::*;
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

fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

#[test]
fn fanuc_link_against_car_body() {
    let car = load_mesh(&data_dir().join("parts/body-in-white/car5.obj"))
        .unwrap()
        .scaled(0.001);
    let link = load_mesh(
        &data_dir()
            .join("robots/fanuc_r2000ic/fanuc_r2000ic_support/meshes/r2000ic125l/collision/link_3.stl"),
    )
    .unwrap();
    let mut w = CollisionWorld::new();
    let car_id = w.add_static("car", &ShapeSpec::Mesh(Arc::new(car.clone())), Pose::IDENTITY);
    let g = w.add_group(
        "r",
        vec![body(
            "link_3",
            vec![(ShapeSpec::Mesh(Arc::new(link.clone())), Pose::IDENTITY)],
        )],
    );
    let hull = w.body_hull(g, 0).unwrap();
    // The hull contains the link's vertices' bounds.
    let (hl, hh) = hull.aabb().unwrap();
    let (ll, lh) = link.aabb().unwrap();
    assert!((hl - ll).length() < 1e-9 && (hh - lh).length() < 1e-9);

    // Far above the car.
    let far = [at(0.0, 2.0, 5.0)];
    assert!(w.group_vs_static(g, &far, 0.01).is_none());
    let d = w.min_distance_to_static(g, &far);
    assert!(d > 2.0 && d < 5.0, "{d}");
    // Centred on a vertex of the car's surface: contact.
    let v = car.vertices[car.triangles[3000][0] as usize];
    let centre = (ll + lh) / 2.0;
    let on = [Pose::from_translation(v - centre)];
    assert_eq!(
        w.group_vs_static(g, &on, 0.0),
        Some(BodyContact::Static {
            body: 0,
            object: car_id
        })
    );
    assert_eq!(w.min_distance_to_static(g, &on), 0.0);
    // A ray down onto the roof hits it.
    let (lo, hi) = car.aabb().unwrap();
    let mid = (lo + hi) / 2.0;
    let hit = w
        .cast_ray_static(DVec3::new(mid.x, mid.y, 3.0), -DVec3::Z, 10.0)
        .unwrap();
    assert!(
        hit.distance > 3.0 - hi.z - 1e-9 && hit.distance < 3.0 - lo.z,
        "{hit:?}"
    );
}

// ---------------------------------------------------------------------------------------
// Properties.

fn arb_shape() -> impl Strategy<Value = ShapeSpec> {
    prop_oneof![
        (0.05..1.0f64, 0.05..1.0f64, 0.05..1.0f64).prop_map(|(x, y, z)| ShapeSpec::Box {
            half_extents: DVec3::new(x, y, z)
        }),
        (0.05..1.0f64).prop_map(|radius| ShapeSpec::Sphere { radius }),
        (0.05..1.0f64, 0.05..1.0f64)
            .prop_map(|(radius, half_height)| ShapeSpec::Cylinder { radius, half_height }),
    ]
}

fn arb_pose() -> impl Strategy<Value = Pose> {
    (
        (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64),
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64),
        0.0..std::f64::consts::PI,
    )
        .prop_map(|((x, y, z), (ax, ay, az), angle)| {
            let axis = DVec3::new(ax, ay, az).try_normalize().unwrap_or(DVec3::Z);
            Pose::from_parts(DVec3::new(x, y, z), DQuat::from_axis_angle(axis, angle))
        })
}

/// An open, bent sheet: a mesh that is nothing like a solid.
fn sheet() -> Mesh {
    let n = 6;
    let mut vertices = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let (u, v) = (i as f64 / n as f64 * 3.0 - 1.5, j as f64 / n as f64 * 3.0 - 1.5);
            vertices.push(DVec3::new(u, v, 0.3 * (u * 1.7).sin() * v));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n as u32 {
        for j in 0..n as u32 {
            let k = i * (n as u32 + 1) + j;
            let r = n as u32 + 1;
            triangles.push([k, k + r, k + r + 1]);
            triangles.push([k, k + r + 1, k + 1]);
        }
    }
    Mesh { vertices, triangles }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn distance_is_non_negative_and_symmetric(
        a in arb_shape(), b in arb_shape(), pa in arb_pose(), pb in arb_pose()
    ) {
        let (w1, g1) = one_on_one(&a, pa, &b);
        let (w2, g2) = one_on_one(&b, pb, &a);
        let d1 = w1.min_distance_to_static(g1, &[pb]);
        let d2 = w2.min_distance_to_static(g2, &[pa]);
        prop_assert!(d1 >= 0.0 && d2 >= 0.0);
        prop_assert!((d1 - d2).abs() < 1e-6, "{} vs {}", d1, d2);
        // Contact agrees with the distance away from the boundary.
        for margin in [0.0, 0.05, 0.3] {
            let c1 = w1.group_vs_static(g1, &[pb], margin).is_some();
            let c2 = w2.group_vs_static(g2, &[pa], margin).is_some();
            if (d1 - margin).abs() > 1e-6 {
                prop_assert_eq!(c1, d1 <= margin, "d {} margin {}", d1, margin);
                prop_assert_eq!(c2, d1 <= margin, "d {} margin {}", d1, margin);
            }
        }
    }

    #[test]
    fn contact_is_monotone_in_margin(
        a in arb_shape(), b in arb_shape(), pa in arb_pose(), pb in arb_pose(),
        m1 in 0.0..0.5f64, dm in 0.0..0.5f64
    ) {
        let (w, g) = one_on_one(&a, pa, &b);
        if w.group_vs_static(g, &[pb], m1).is_some() {
            prop_assert!(w.group_vs_static(g, &[pb], m1 + dm).is_some());
        }
        // Same for body pairs.
        let mut w = CollisionWorld::new();
        let g = w.add_group("r", vec![
            body("a", vec![(a.clone(), Pose::IDENTITY)]),
            body("b", vec![(b.clone(), Pose::IDENTITY)]),
        ]);
        if w.bodies_within(g, 0, 1, &[pa, pb], m1) {
            prop_assert!(w.bodies_within(g, 0, 1, &[pa, pb], m1 + dm));
        }
    }

    #[test]
    fn mesh_contact_agrees_with_mesh_distance(
        a in arb_shape(), b in arb_shape(), pb in arb_pose(), margin in 0.0..0.3f64
    ) {
        let mut w = CollisionWorld::new();
        w.add_static("sheet", &ShapeSpec::Mesh(Arc::new(sheet())), at(0.1, -0.2, 0.0));
        // Two shapes: the body is their hull.
        let g = w.add_group("r", vec![body("ab", vec![(a, Pose::IDENTITY), (b, at(0.3, 0.0, 0.2))])]);
        let d = w.min_distance_to_static(g, &[pb]);
        prop_assert!(d >= 0.0);
        let c = w.group_vs_static(g, &[pb], margin).is_some();
        if (d - margin).abs() > 1e-6 {
            prop_assert_eq!(c, d <= margin, "d {} margin {}", d, margin);
        }
    }
}

/// A small deterministic generator (xorshift), uniform in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The fast paths (hill-climbing hulls, cached separating axes) against parry's own generic
/// distance query, on the real car body and robot links at random poses near the car.
#[test]
fn agrees_with_parry_on_car_and_links() {
    let car = load_mesh(&data_dir().join("parts/body-in-white/car5.obj"))
        .unwrap()
        .scaled(0.001);
    let car_shape = SharedShape::trimesh(car.vertices.clone(), car.triangles.clone()).unwrap();
    let mut w = CollisionWorld::new();
    w.add_static("car", &ShapeSpec::Mesh(Arc::new(car.clone())), Pose::IDENTITY);
    let dir = data_dir().join("robots/fanuc_r2000ic/fanuc_r2000ic_support/meshes/r2000ic125l/collision");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut checked, mut contacts) = (0, 0);
    for link in ["link_3", "link_5", "link_6"] {
        let mesh = load_mesh(&dir.join(format!("{link}.stl"))).unwrap();
        let hull = SharedShape::convex_hull(&mesh.vertices).unwrap();
        let (lo, hi) = mesh.aabb().unwrap();
        let centre = (lo + hi) / 2.0;
        let g = w.add_group(
            link,
            vec![body(
                link,
                vec![(ShapeSpec::Mesh(Arc::new(mesh)), Pose::IDENTITY)],
            )],
        );
        for _ in 0..40 {
            let v = car.vertices[(rng.next() * car.vertices.len() as f64) as usize];
            let axis = DVec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5)
                .try_normalize()
                .unwrap_or(DVec3::Z);
            let rot = DQuat::from_axis_angle(axis, rng.next() * 6.0);
            let lift = DVec3::new(0.0, 0.0, rng.next() * 0.4);
            let pose = Pose::from_parts(v - rot * centre + lift, rot);
            let want = query::distance(&Pose::IDENTITY, &*car_shape, &pose, &*hull)
                .unwrap()
                .distance
                .max(0.0);
            let got = w.min_distance_to_static(g, &[pose]);
            assert!((got - want).abs() < 1e-6, "{link}: {got} vs {want}");
            for margin in [0.0, 0.01, 0.05] {
                if (want - margin).abs() > 1e-6 {
                    let hit = w.group_vs_static(g, &[pose], margin).is_some();
                    assert_eq!(hit, want <= margin, "{link}: distance {want}, margin {margin}");
                    contacts += usize::from(hit);
                    checked += 1;
                }
            }
        }
    }
    // Both outcomes were exercised.
    assert!(
        contacts > 20 && checked - contacts > 20,
        "{contacts} of {checked}"
    );
}

/// Body pairs with large hulls (hill-climbing support on both sides) against parry.
#[test]
fn hull_pairs_agree_with_parry() {
    let dir = data_dir().join("robots/fanuc_r2000ic/fanuc_r2000ic_support/meshes/r2000ic125l/collision");
    let a = load_mesh(&dir.join("link_2.stl")).unwrap();
    let b = load_mesh(&dir.join("link_4.stl")).unwrap();
    let (ha, hb) = (
        SharedShape::convex_hull(&a.vertices).unwrap(),
        SharedShape::convex_hull(&b.vertices).unwrap(),
    );
    let centre = |m: &Mesh| {
        let (lo, hi) = m.aabb().unwrap();
        (lo + hi) / 2.0
    };
    let centres = [centre(&a), centre(&b)];
    let mut w = CollisionWorld::new();
    let g = w.add_group(
        "r",
        vec![
            body("a", vec![(ShapeSpec::Mesh(Arc::new(a)), Pose::IDENTITY)]),
            body("b", vec![(ShapeSpec::Mesh(Arc::new(b)), Pose::IDENTITY)]),
        ],
    );
    let link = |name: &str| {
        let m = load_mesh(&dir.join(format!("{name}.stl"))).unwrap();
        vec![body(name, vec![(ShapeSpec::Mesh(Arc::new(m)), Pose::IDENTITY)])]
    };
    let ga = w.add_group("one", link("link_2"));
    let gb = w.add_group("other", link("link_4"));
    let mut rng = Rng(12345);
    let (mut checked, mut contacts) = (0, 0);
    for _ in 0..300 {
        let mut pose = |centre: DVec3| {
            let axis = DVec3::new(rng.next() - 0.5, rng.next() - 0.5, rng.next() - 0.5)
                .try_normalize()
                .unwrap_or(DVec3::Z);
            let rot = DQuat::from_axis_angle(axis, rng.next() * 6.0);
            let t = DVec3::new(rng.next(), rng.next(), rng.next()) * 0.8;
            Pose::from_parts(t - rot * centre, rot)
        };
        let p = [pose(centres[0]), pose(centres[1])];
        let want = query::distance(&p[0], &*ha, &p[1], &*hb)
            .unwrap()
            .distance
            .max(0.0);
        for margin in [0.0, 0.02, 0.1] {
            if (want - margin).abs() > 1e-6 {
                let hit = w.bodies_within(g, 0, 1, &p, margin);
                assert_eq!(hit, want <= margin, "distance {want}, margin {margin}");
                let pair = w.group_vs_group(ga, &p[..1], gb, &p[1..], margin);
                assert_eq!(pair.is_some(), hit);
                contacts += usize::from(hit);
                checked += 1;
            }
        }
    }
    assert!(
        contacts > 50 && checked - contacts > 50,
        "{contacts} of {checked}"
    );
}

#[test]
fn capped_static_distance_skips_exempt_bodies() {
    let mut w = CollisionWorld::new();
    w.add_static("floor", &cube(0.5), at(0.0, 0.0, -0.5));
    w.add_static("wall", &cube(0.5), at(3.0, 0.0, 0.5));
    let g = w.add_group(
        "r",
        vec![
            body("base", vec![(cube(0.1), Pose::IDENTITY)]),
            body("arm", vec![(cube(0.1), Pose::IDENTITY)]),
        ],
    );
    // The base sits 0.05 above the floor; the arm is beside the floor (x = 2) and 0.4 from the wall.
    let p = [at(0.0, 0.0, 0.15), at(2.0, 0.0, 0.4)];
    assert!((w.group_static_distance(g, &p, 10.0) - 0.05).abs() < 1e-9);
    assert!((w.min_distance_to_static(g, &p) - 0.05).abs() < 1e-9);
    w.set_static_exempt(g, &[0]);
    assert!((w.group_static_distance(g, &p, 10.0) - 0.4).abs() < 1e-9);
    // The cap caps; a zero, negative or NaN cap gives 0.
    assert_eq!(w.group_static_distance(g, &p, 0.2), 0.2);
    assert!((w.group_static_distance(g, &p, 0.41) - 0.4).abs() < 1e-9);
    assert_eq!(w.group_static_distance(g, &p, -1.0), 0.0);
    assert_eq!(w.group_static_distance(g, &p, f64::NAN), 0.0);
    // The existing query still measures every body.
    assert!((w.min_distance_to_static(g, &p) - 0.05).abs() < 1e-9);
    // Touching gives 0, a non-finite pose of a moving body gives 0.
    assert_eq!(w.group_static_distance(g, &[p[0], at(2.45, 0.0, 0.4)], 1.0), 0.0);
    let bad = Pose::from_translation(DVec3::new(f64::NAN, 0.0, 0.0));
    assert_eq!(w.group_static_distance(g, &[p[0], bad], 1.0), 0.0);
    // Per body, exemption not consulted.
    assert!((w.body_static_distance(g, 0, &p, 10.0) - 0.05).abs() < 1e-9);
    assert!((w.body_static_distance(g, 1, &p, 10.0) - 0.4).abs() < 1e-9);
    assert_eq!(w.body_static_distance(g, 1, &p, 0.1), 0.1);
    assert_eq!(w.body_static_distance(g, 1, &[p[0], bad], 1.0), 0.0);
    assert_eq!(w.body_static_distance(g, 5, &p, 1.0), 1.0);
}

#[test]
fn capped_self_distance_over_checked_pairs() {
    let mut w = CollisionWorld::new();
    let g = w.add_group(
        "r",
        (0..3)
            .map(|i| body(&format!("l{i}"), vec![(cube(0.1), Pose::IDENTITY)]))
            .collect(),
    );
    // Gaps: (0, 1) 0.3, (1, 2) 0.6, (0, 2) 1.1.
    let poses = [at(0.0, 0.0, 0.0), at(0.5, 0.0, 0.0), at(1.3, 0.0, 0.0)];
    // No pair checked: the cap.
    assert_eq!(w.group_self_distance(g, &poses, 0.7), 0.7);
    w.set_self_pairs(g, vec![(0, 2), (1, 2)]);
    assert!((w.group_self_distance(g, &poses, 10.0) - 0.6).abs() < 1e-9);
    assert_eq!(w.group_self_distance(g, &poses, 0.5), 0.5);
    w.set_self_pairs(g, vec![(0, 2)]);
    assert!((w.group_self_distance(g, &poses, 10.0) - 1.1).abs() < 1e-9);
    // An overlapping unchecked pair (0, 1) is not seen; a checked one gives 0.
    let touching = [at(0.0, 0.0, 0.0), at(0.05, 0.0, 0.0), at(1.3, 0.0, 0.0)];
    assert!((w.group_self_distance(g, &touching, 10.0) - 1.1).abs() < 1e-9);
    w.set_self_pairs(g, vec![(0, 1), (0, 2)]);
    assert_eq!(w.group_self_distance(g, &touching, 10.0), 0.0);
    let bad = Pose::from_translation(DVec3::new(f64::INFINITY, 0.0, 0.0));
    assert_eq!(w.group_self_distance(g, &[poses[0], poses[1], bad], 10.0), 0.0);
    // One pair, checked or not.
    assert!((w.pair_distance(g, 1, 2, &poses, 10.0) - 0.6).abs() < 1e-9);
    assert!((w.pair_distance(g, 2, 1, &poses, 10.0) - 0.6).abs() < 1e-9);
    assert_eq!(w.pair_distance(g, 1, 2, &poses, 0.5), 0.5);
    assert_eq!(w.pair_distance(g, 0, 1, &touching, 10.0), 0.0);
    assert_eq!(w.pair_distance(g, 1, 1, &poses, 10.0), 10.0);
    assert_eq!(w.pair_distance(g, 0, 2, &[poses[0], poses[1], bad], 10.0), 0.0);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The capped queries give `min(exact distance, cap)`, against a primitive or the sheet mesh
    /// (statics) and between two bodies (self pairs).
    #[test]
    fn capped_distances_are_min_of_distance_and_cap(
        a in arb_shape(), b in arb_shape(), pa in arb_pose(), pb in arb_pose(),
        cap in 0.0..3.0f64, use_sheet in any::<bool>()
    ) {
        let (w, g) = if use_sheet {
            let mut w = CollisionWorld::new();
            w.add_static("sheet", &ShapeSpec::Mesh(Arc::new(sheet())), pa);
            let g = w.add_group("robot", vec![body("b", vec![(b.clone(), Pose::IDENTITY)])]);
            (w, g)
        } else {
            one_on_one(&a, pa, &b)
        };
        let d = w.min_distance_to_static(g, &[pb]);
        let capped = w.group_static_distance(g, &[pb], cap);
        prop_assert!((capped - d.min(cap)).abs() < 1e-6, "{} vs min({}, {})", capped, d, cap);

        let mut s = CollisionWorld::new();
        s.add_static("a", &a, pa);
        let g2 = s.add_group(
            "pair",
            vec![
                body("a", vec![(a.clone(), Pose::IDENTITY)]),
                body("b", vec![(b.clone(), Pose::IDENTITY)]),
            ],
        );
        s.set_self_pairs(g2, vec![(0, 1)]);
        let self_d = s.group_self_distance(g2, &[pa, pb], cap);
        let (wa, ga) = one_on_one(&a, pa, &b);
        let exact = wa.min_distance_to_static(ga, &[pb]);
        // Body `a` is a convex hull of `a`, the static `a` is exact: equal for these primitives.
        prop_assert!((self_d - exact.min(cap)).abs() < 1e-6, "{} vs min({}, {})", self_d, exact, cap);
    }
}

fn arb_unit() -> impl Strategy<Value = DVec3> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_map(|(x, y, z)| DVec3::new(x, y, z).try_normalize().unwrap_or(DVec3::Z))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// The cached-axis gaps used to skip triangles and BVH nodes in capped mesh distances never
    /// exceed the true distance from the triangle (or anything in the box) to the shape.
    #[test]
    fn cached_axis_gaps_are_lower_bounds(
        b in arb_shape(), pb in arb_pose(), axes in proptest::collection::vec(arb_unit(), 1..6),
        corners in proptest::collection::vec((-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64), 3)
    ) {
        let (shape, local) = body_shape(&[(b, Pose::IDENTITY)]).unwrap();
        let pose = pb * local;
        let convex = shape.as_support_map().unwrap();
        let v: Vec<DVec3> = corners.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect();
        let t = Triangle::new(v[0], v[1], v[2]);
        let mut cache = AxisCache::default();
        for d in axes {
            cache.push(d, d.dot(convex.support_point(&pose, -d)));
        }
        let exact = query::distance(&Pose::IDENTITY, &t, &pose, &*shape).unwrap().distance.max(0.0);
        let gap = cache.triangle_gap(&t);
        prop_assert!(gap <= exact + 1e-9, "triangle gap {} above distance {}", gap, exact);
        let (lo, hi) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
        let box_gap = cache.box_gap(lo, hi);
        prop_assert!(box_gap <= gap + 1e-9, "box gap {} above triangle gap {}", box_gap, gap);
    }

    /// Capped distances to a mesh against parry's own mesh distance (an independent path).
    #[test]
    fn capped_mesh_distance_agrees_with_parry(
        b in arb_shape(), pa in arb_pose(), pb in arb_pose(), cap in 0.0..3.0f64
    ) {
        let sheet = sheet();
        let mut w = CollisionWorld::new();
        w.add_static("sheet", &ShapeSpec::Mesh(Arc::new(sheet.clone())), pa);
        let g = w.add_group("robot", vec![body("b", vec![(b.clone(), Pose::IDENTITY)])]);
        let (shape, local) = body_shape(&[(b, Pose::IDENTITY)]).unwrap();
        let mesh = SharedShape::trimesh(sheet.vertices, sheet.triangles).unwrap();
        let exact = query::distance(&pa, &*mesh, &(pb * local), &*shape).unwrap().distance.max(0.0);
        let capped = w.group_static_distance(g, &[pb], cap);
        // Two GJK implementations on curved shapes (spheres) differ by a few 1e-6 (as before
        // the cached axes).
        prop_assert!((capped - exact.min(cap)).abs() < 1e-5, "{} vs min({}, {})", capped, exact, cap);
    }
}

//! Geometry benchmarks: loading the car body, a robot's convex links against the car's
//! triangle mesh (the planner's hot path), and rays against the car.
//!
//! `cargo bench -p cellplan-geom -- --quick`
use cellplan_geom::{CollisionWorld, DVec3, GroupBody, GroupId, Mesh, Pose, ShapeSpec, load_mesh};
use criterion::{Criterion, criterion_group, criterion_main};
use parry3d_f64::query;
use parry3d_f64::shape::SharedShape;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::Arc;

const MARGIN: f64 = 0.01;

fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

fn car_path() -> PathBuf {
    data().join("parts/body-in-white/car5.obj")
}

fn link(name: &str) -> Mesh {
    load_mesh(&data().join(format!(
        "robots/fanuc_r2000ic/fanuc_r2000ic_support/meshes/r2000ic125l/collision/{name}.stl"
    )))
    .expect("FANUC link mesh")
}

const LINKS: [&str; 7] = [
    "base_link",
    "link_1",
    "link_2",
    "link_3",
    "link_4",
    "link_5",
    "link_6",
];

struct Scene {
    world: CollisionWorld,
    car: Mesh,
    /// One group per link (for single-body benchmarks), then the robot (8 bodies).
    singles: Vec<GroupId>,
    robot: GroupId,
    centres: Vec<DVec3>,
}

fn scene() -> Scene {
    let car = load_mesh(&car_path()).expect("car").scaled(0.001);
    let mut world = CollisionWorld::new();
    world.add_static("car", &ShapeSpec::Mesh(Arc::new(car.clone())), Pose::IDENTITY);
    let floor = ShapeSpec::Box {
        half_extents: DVec3::new(5.0, 5.0, 0.05),
    };
    world.add_static(
        "floor",
        &floor,
        Pose::from_translation(DVec3::new(0.0, 2.2, -0.05)),
    );
    let fence = ShapeSpec::Box {
        half_extents: DVec3::new(0.05, 4.0, 1.0),
    };
    world.add_static(
        "fence_l",
        &fence,
        Pose::from_translation(DVec3::new(-3.0, 2.2, 1.0)),
    );
    world.add_static(
        "fence_r",
        &fence,
        Pose::from_translation(DVec3::new(3.0, 2.2, 1.0)),
    );
    let tool = vec![
        (
            ShapeSpec::Cylinder {
                radius: 0.04,
                half_height: 0.1,
            },
            Pose::IDENTITY,
        ),
        (
            ShapeSpec::Box {
                half_extents: DVec3::new(0.06, 0.03, 0.03),
            },
            Pose::from_translation(DVec3::new(0.0, 0.0, 0.12)),
        ),
    ];
    let mut bodies: Vec<GroupBody> = LINKS
        .iter()
        .map(|n| GroupBody {
            name: n.to_string(),
            shapes: vec![(ShapeSpec::Mesh(Arc::new(link(n))), Pose::IDENTITY)],
        })
        .collect();
    bodies.push(GroupBody {
        name: "tool".into(),
        shapes: tool,
    });
    let centres = bodies
        .iter()
        .map(|b| match &b.shapes[0].0 {
            ShapeSpec::Mesh(m) => {
                let (lo, hi) = m.aabb().unwrap();
                (lo + hi) / 2.0
            }
            _ => DVec3::ZERO,
        })
        .collect();
    let singles = bodies
        .iter()
        .map(|b| world.add_group(&b.name, vec![b.clone()]))
        .collect();
    let robot = world.add_group("robot", bodies);
    Scene {
        world,
        car,
        singles,
        robot,
        centres,
    }
}

/// The pose that puts body `i`'s centre on car vertex `v`, then lifts it until it is clear
/// of the scene by more than the margin (so that it is near, but not touching).
fn near_pose(s: &Scene, i: usize, vertex: usize) -> Pose {
    let v = s.car.vertices[vertex];
    let g = s.singles[i];
    let mut p = Pose::from_translation(v - s.centres[i]);
    while s.world.min_distance_to_static(g, &[p]) <= MARGIN * 1.5 {
        p.translation.z += 0.002;
    }
    p
}

fn robot_poses(s: &Scene, near: bool) -> Vec<Pose> {
    let n = s.car.vertices.len();
    (0..8)
        .map(|i| {
            if near && i >= 3 {
                // Wrist, hand and tool near the car at different places.
                near_pose(s, i, (i * 1931 + 77) % n)
            } else {
                // Upper arm and base beside the car.
                Pose::from_translation(DVec3::new(-2.0, 1.0 + 0.8 * i as f64, 1.0) - s.centres[i])
            }
        })
        .collect()
}

fn benches(c: &mut Criterion) {
    c.bench_function("load car5.obj (6.9k triangles)", |b| {
        b.iter(|| load_mesh(black_box(&car_path())).unwrap())
    });
    c.bench_function("build world (car TriMesh + 16 hulls)", |b| b.iter(scene));

    let s = scene();
    let w = &s.world;
    let l3 = s.singles[3];
    let far = [Pose::from_translation(DVec3::new(0.0, 2.0, 4.0))];
    let near = [near_pose(&s, 3, 3000)];
    let touch = [Pose::from_translation(s.car.vertices[3000] - s.centres[3])];
    assert!(w.group_vs_static(l3, &far, MARGIN).is_none());
    assert!(w.group_vs_static(l3, &near, MARGIN).is_none());
    assert!(w.group_vs_static(l3, &touch, MARGIN).is_some());

    let mut g = c.benchmark_group("link_3 hull vs car (margin 0.01)");
    for (name, p) in [("far", &far), ("near, clear", &near), ("touching", &touch)] {
        g.bench_function(name, |b| b.iter(|| w.group_vs_static(l3, black_box(p), MARGIN)));
    }
    g.bench_function("min distance, near", |b| {
        b.iter(|| w.min_distance_to_static(l3, black_box(&near)))
    });
    g.finish();

    // The same pair through parry's generic queries, to compare.
    let car_shape = SharedShape::trimesh(s.car.vertices.clone(), s.car.triangles.clone()).unwrap();
    let hull = SharedShape::convex_hull(&link("link_3").vertices).unwrap();
    let mut g = c.benchmark_group("parry queries, link_3 hull vs car");
    for (name, p) in [("near, clear", &near[0]), ("touching", &touch[0])] {
        g.bench_function(format!("contact(prediction 0.01), {name}"), |b| {
            b.iter(|| {
                query::contact(&Pose::IDENTITY, &*car_shape, black_box(p), &*hull, MARGIN)
                    .unwrap()
                    .is_some()
            })
        });
        g.bench_function(format!("closest_points(0.01), {name}"), |b| {
            b.iter(|| {
                query::closest_points(&Pose::IDENTITY, &*car_shape, black_box(p), &*hull, MARGIN).unwrap()
            })
        });
        g.bench_function(format!("intersection_test, {name}"), |b| {
            b.iter(|| {
                query::intersection_test(&Pose::IDENTITY, &*car_shape, black_box(p), &*hull)
                    .unwrap()
                    .intersecting
            })
        });
    }
    g.finish();

    let mut g = c.benchmark_group("robot (8 bodies) vs scene (margin 0.01)");
    let beside = robot_poses(&s, false);
    let reaching = robot_poses(&s, true);
    assert!(w.group_vs_static(s.robot, &beside, MARGIN).is_none());
    assert!(w.group_vs_static(s.robot, &reaching, MARGIN).is_none());
    g.bench_function("beside the car", |b| {
        b.iter(|| w.group_vs_static(s.robot, black_box(&beside), MARGIN))
    });
    g.bench_function("5 bodies near the car, clear", |b| {
        b.iter(|| w.group_vs_static(s.robot, black_box(&reaching), MARGIN))
    });
    g.bench_function("self pairs (all 28) + group_vs_static", |b| {
        b.iter(|| {
            for i in 0..8 {
                for j in i + 1..8 {
                    black_box(w.bodies_within(s.robot, i, j, &reaching, 0.0));
                }
            }
            w.group_vs_static(s.robot, black_box(&reaching), MARGIN)
        })
    });
    g.finish();

    let mut g = c.benchmark_group("ray vs scene");
    let (lo, hi) = s.car.aabb().unwrap();
    let mid = (lo + hi) / 2.0;
    let down = DVec3::new(mid.x + 0.1, mid.y + 0.3, 3.0);
    assert!(w.cast_ray_static(down, -DVec3::Z, 10.0).is_some());
    g.bench_function("down onto the roof", |b| {
        b.iter(|| w.cast_ray_static(black_box(down), -DVec3::Z, 10.0))
    });
    let along = DVec3::new(mid.x + 0.05, -1.0, mid.z);
    g.bench_function("along the car's length", |b| {
        b.iter(|| w.cast_ray_static(black_box(along), DVec3::Y, 10.0))
    });
    let miss = DVec3::new(0.0, 2.0, 3.0);
    g.bench_function("missing the car", |b| {
        b.iter(|| w.cast_ray_static(black_box(miss), DVec3::Z, 10.0))
    });
    g.finish();
}

criterion_group!(geometry, benches);
criterion_main!(geometry);

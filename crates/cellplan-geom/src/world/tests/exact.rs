//! The exact queries against parry's own and against each other: the real car body and robot
//! links, random hulls and primitives (property tests), capped distances, the mesh walk's
//! cached separating axes.
use super::*;
use crate::load_mesh;
use crate::world::narrow::AxisCache;
use parry3d_f64::query;
use parry3d_f64::shape::Triangle;
use proptest::prelude::*;

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
        // GJK stops within its tolerance of the true distance, which against curved shapes
        // (cylinders, balls) is a few millionths of it either way round.
        prop_assert!((d1 - d2).abs() < 1e-6 + 1e-4 * d1.max(d2), "{} vs {}", d1, d2);
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
        // Two GJK implementations on curved shapes (spheres, cylinders) differ by a few 1e-6,
        // at times by more than 1e-5 (a cylinder of radius 0.114 m at 0.244 m: ours 1.1e-5
        // below parry's; the case is kept in proptest-regressions). Ours may read up to 5e-5
        // lower (more cautious), never more than 1e-5 higher.
        let want = exact.min(cap);
        prop_assert!(capped < want + 1e-5, "{} above min({}, {})", capped, exact, cap);
        prop_assert!(capped > want - 5e-5, "{} below min({}, {})", capped, exact, cap);
    }
}

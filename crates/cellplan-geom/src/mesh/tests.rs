use super::*;

/// A flat square grid of `n` × `n` cells, two triangles each, on z = 0.
fn grid(n: u32) -> Mesh {
    let mut m = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            m.vertices.push(DVec3::new(i as f64, j as f64, 0.0));
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            m.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            m.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    m
}

#[test]
fn decimation_meets_the_budget_and_keeps_the_shape() {
    let m = grid(100);
    assert_eq!(m.triangles.len(), 20_000);
    let d = m.decimated(2_000);
    assert!(d.triangles.len() <= 2_000, "{}", d.triangles.len());
    // Bisection keeps as much as the budget allows: at least a quarter of it.
    assert!(d.triangles.len() >= 500, "{}", d.triangles.len());
    let (lo, hi) = d.aabb().unwrap();
    assert!(lo.x < 2.0 && lo.y < 2.0 && hi.x > 98.0 && hi.y > 98.0);
    assert!(d.vertices.iter().all(|v| v.z == 0.0));
    // Every vertex is used and every triangle is proper and faces +z like the input.
    let mut used = vec![false; d.vertices.len()];
    for i in 0..d.triangles.len() {
        d.triangles[i].iter().for_each(|&k| used[k as usize] = true);
        assert!(d.triangle_normal(i).z > 0.99);
    }
    assert!(used.iter().all(|&u| u));
    // Within budget: unchanged.
    assert_eq!(m.decimated(20_000), m);
}

/// Writes `bytes` to a fresh file named `*.{ext}` in the temp dir (kept: the caller removes it).
fn temp_file(ext: &str, bytes: &[u8]) -> PathBuf {
    let file = tempfile::Builder::new()
        .prefix("cellplan-geom-test-")
        .suffix(&format!(".{ext}"))
        .tempfile()
        .unwrap();
    std::fs::write(file.path(), bytes).unwrap();
    file.into_temp_path().keep().unwrap()
}

fn load_temp(ext: &str, bytes: &[u8]) -> Result<Mesh, MeshError> {
    let path = temp_file(ext, bytes);
    let result = load_mesh(&path);
    let _ = std::fs::remove_file(&path);
    result
}

/// The 12 triangles of the unit cube [0,1]³, outward counter-clockwise.
fn cube_triangles() -> Vec<[DVec3; 3]> {
    let v = |i: usize| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
    let quads = [
        [0, 2, 3, 1], // z = 0
        [4, 5, 7, 6], // z = 1
        [0, 1, 5, 4], // y = 0
        [2, 6, 7, 3], // y = 1
        [0, 4, 6, 2], // x = 0
        [1, 3, 7, 5], // x = 1
    ];
    quads
        .iter()
        .flat_map(|q| [[v(q[0]), v(q[1]), v(q[2])], [v(q[0]), v(q[2]), v(q[3])]])
        .collect()
}

fn binary_stl(header: &[u8], tris: &[[DVec3; 3]]) -> Vec<u8> {
    let mut out = vec![b' '; 80];
    out[..header.len()].copy_from_slice(header);
    out.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        out.extend([0u8; 12]);
        for v in t {
            for c in v.to_array() {
                out.extend((c as f32).to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    out
}

fn ascii_stl(tris: &[[DVec3; 3]]) -> String {
    let mut s = String::from("solid cube\n");
    for t in tris {
        s.push_str("  facet normal 0 0 0\n    outer loop\n");
        for v in t {
            s.push_str(&format!("      vertex {} {} {}\n", v.x, v.y, v.z));
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    s.push_str("endsolid cube\n");
    s
}

fn message(e: &MeshError) -> String {
    e.to_string()
}

fn assert_unit_cube(m: &Mesh) {
    assert_eq!(m.triangles.len(), 12);
    assert_eq!(m.vertices.len(), 8, "duplicated vertices are welded");
    assert_eq!(m.aabb(), Some((DVec3::ZERO, DVec3::ONE)));
    let area: f64 = (0..12).map(|i| m.triangle_area(i)).sum();
    assert!((area - 6.0).abs() < 1e-12);
    // Outward normals: the normal points away from the centre.
    for i in 0..12 {
        let [a, b, c] = m.corners(i);
        let centre = (a + b + c) / 3.0;
        assert!(m.triangle_normal(i).dot(centre - DVec3::splat(0.5)) > 0.0);
    }
}

#[test]
fn binary_stl_loads_and_welds() {
    let m = load_temp("stl", &binary_stl(b"binary", &cube_triangles())).unwrap();
    assert_unit_cube(&m);
}

#[test]
fn binary_stl_whose_header_says_solid_is_binary() {
    let bytes = binary_stl(b"solid exported by a careless tool", &cube_triangles());
    let m = load_temp("STL", &bytes).unwrap();
    assert_unit_cube(&m);
}

#[test]
fn ascii_stl_loads() {
    let m = load_temp("stl", ascii_stl(&cube_triangles()).as_bytes()).unwrap();
    assert_unit_cube(&m);
}

#[test]
fn truncated_binary_stl_is_diagnosed() {
    let mut bytes = binary_stl(b"x", &cube_triangles());
    bytes.truncate(84 + 50 * 3 + 20);
    let err = load_temp("stl", &bytes).unwrap_err();
    let msg = message(&err);
    assert!(msg.contains("ends after 3 of 12 triangles"), "{msg}");
    assert!(msg.contains("re-export"), "{msg}");
    assert!(matches!(err, MeshError::Parse { line: None, .. }));
    // Also when the header starts with "solid".
    let mut bytes = binary_stl(b"solid x", &cube_triangles());
    bytes.truncate(84 + 50 * 5);
    let msg = message(&load_temp("stl", &bytes).unwrap_err());
    assert!(msg.contains("ends after 5 of 12 triangles"), "{msg}");
}

#[test]
fn binary_stl_with_trailing_bytes_or_zero_count_loads() {
    let mut bytes = binary_stl(b"x", &cube_triangles());
    bytes.extend([0u8; 7]);
    assert_unit_cube(&load_temp("stl", &bytes).unwrap());
    let mut bytes = binary_stl(b"x", &cube_triangles());
    bytes[80..84].copy_from_slice(&0u32.to_le_bytes());
    assert_unit_cube(&load_temp("stl", &bytes).unwrap());
}

#[test]
fn binary_stl_rejects_nan() {
    let mut tris = cube_triangles();
    tris[4][1].y = f64::NAN;
    let msg = message(&load_temp("stl", &binary_stl(b"x", &tris)).unwrap_err());
    assert!(
        msg.contains("triangle 5 of 12") && msg.contains("non-finite"),
        "{msg}"
    );
}

#[test]
fn ascii_stl_bad_number_names_the_line() {
    let text = ascii_stl(&cube_triangles()).replacen("vertex 1 0 0", "vertex 1 0,5 0", 1);
    let line = text.lines().position(|l| l.contains("0,5")).unwrap() + 1;
    let err = load_temp("stl", text.as_bytes()).unwrap_err();
    match &err {
        MeshError::Parse { line: l, message, .. } => {
            assert_eq!(*l, Some(line));
            assert!(message.contains("`0,5` is not a number"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    assert!(message(&err).contains(&format!(":{line}: ")), "{err}");
}

#[test]
fn ascii_stl_structure_errors() {
    let text =
        "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n";
    let err = load_temp("stl", text.as_bytes()).unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(7), .. }), "{err}");
    assert!(message(&err).contains("has 2 vertices"), "{err}");

    let text = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n";
    let err = load_temp("stl", text.as_bytes()).unwrap_err();
    assert!(message(&err).contains("truncated"), "{err}");

    let text = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 inf\n";
    let err = load_temp("stl", text.as_bytes()).unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(4), .. }), "{err}");
    assert!(message(&err).contains("not finite"), "{err}");

    let text = "solid a\nbanana\n";
    let err = load_temp("stl", text.as_bytes()).unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(2), .. }), "{err}");
}

#[test]
fn empty_files_are_rejected() {
    let err = load_temp("stl", b"").unwrap_err();
    assert!(message(&err).contains("only 0 bytes"), "{err}");
    let err = load_temp("stl", b"solid empty\nendsolid empty\n").unwrap_err();
    assert!(message(&err).contains("no triangles"), "{err}");
    let err = load_temp("stl", &binary_stl(b"x", &[])).unwrap_err();
    assert!(message(&err).contains("no triangles"), "{err}");
    let err = load_temp("obj", b"").unwrap_err();
    assert!(message(&err).contains("no triangles"), "{err}");
    let err = load_temp("obj", b"# only vertices\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap_err();
    assert!(message(&err).contains("no triangles"), "{err}");
}

#[test]
fn obj_quads_negative_indices_and_corner_forms() {
    let text = "\
# a unit square and a triangle
mtllib x.mtl
o square
v 0 0 0
v 1 0 0 1.0
v 1 1 0
v 0 1 0
vt 0 0
vn 0 0 1
g g1
s off
usemtl red
f 1/1/1 2/1/1 3//1 4
o tri
v 5 5 5
v 6 5 5
v 5 6 5
f -3 -2/1 -1//1
v 9 9 9
";
    let m = load_temp("obj", text.as_bytes()).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]]);
    // The last vertex is not used by any face: dropped.
    assert_eq!(m.vertices.len(), 7);
    assert_eq!(m.vertices[4], DVec3::splat(5.0));
    assert_eq!(m.triangle_normal(0), DVec3::Z);
    assert!((m.triangle_area(1) - 0.5).abs() < 1e-15);
}

#[test]
fn obj_pentagon_is_fan_triangulated() {
    let text = "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\nf 1 2 3 4 5\n";
    let m = load_temp("obj", text.as_bytes()).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
}

#[test]
fn obj_index_errors_name_the_line() {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\nf 1 2 9\n";
    let err = load_temp("obj", text.as_bytes()).unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(6), .. }), "{err}");
    assert!(
        message(&err).contains("face refers to vertex 9 but only 4 are defined"),
        "{err}"
    );
    let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nf 1 2 -3\n").unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(3), .. }), "{err}");
    let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n").unwrap_err();
    assert!(message(&err).contains("start at 1"), "{err}");
    let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 x/2 3\n").unwrap_err();
    assert!(message(&err).contains("`x/2` is not a face corner"), "{err}");
    let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap_err();
    assert!(message(&err).contains("at least three"), "{err}");
}

#[test]
fn obj_bad_vertices_name_the_line() {
    let err = load_temp("obj", b"v 0 0 0\nv 1 0\n").unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(2), .. }), "{err}");
    assert!(message(&err).contains("three coordinates"), "{err}");
    let err = load_temp("obj", b"v 0 0 0\n\n\nv 1 nan 0\n").unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(4), .. }), "{err}");
    let err = load_temp("obj", b"v 0 0 0\nv 1 1.0.0 0\n").unwrap_err();
    assert!(message(&err).contains("`1.0.0` is not a number"), "{err}");
}

#[test]
fn zero_area_meshes_are_refused_alike_in_obj_and_stl() {
    // Two corners at the same point: STL welds them and drops the triangle; OBJ now too.
    let point = [DVec3::ZERO, DVec3::ZERO, DVec3::X];
    // Corners on one line: every triangle has zero area.
    let line = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
    for tri in [point, line] {
        let obj: String = tri
            .iter()
            .map(|v| format!("v {} {} {}\n", v.x, v.y, v.z))
            .chain(["f 1 2 3\nf 3 2 1\n".to_string()])
            .collect();
        for (ext, bytes) in [
            ("obj", obj.into_bytes()),
            ("stl", ascii_stl(&[tri, tri]).into_bytes()),
            ("stl", binary_stl(b"x", &[tri, tri])),
        ] {
            let err = load_temp(ext, &bytes).unwrap_err();
            assert!(matches!(err, MeshError::Parse { line: None, .. }), "{ext}: {err}");
            assert!(
                message(&err).contains("only degenerate ones, of zero area"),
                "{ext}: {err}"
            );
        }
    }
    // One proper triangle among degenerate ones is a mesh; the OBJ one at a repeated
    // point is dropped as STL drops it.
    let m = load_temp("obj", b"v 0 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n").unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
}

#[test]
fn far_coordinates_are_refused_with_line_or_triangle() {
    let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nv 0 1e30 0\nf 1 2 3\n").unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(3), .. }), "{err}");
    let msg = message(&err);
    assert!(
        msg.contains("vertex coordinate 1e30 exceeds 1e6 in magnitude — is the unit right?"),
        "{msg}"
    );
    let text = ascii_stl(&cube_triangles()).replacen("vertex 1 0 0", "vertex 1 -2e6 0", 1);
    let line = text.lines().position(|l| l.contains("-2e6")).unwrap() + 1;
    let err = load_temp("stl", text.as_bytes()).unwrap_err();
    assert!(
        matches!(err, MeshError::Parse { line: Some(l), .. } if l == line),
        "{err}"
    );
    assert!(message(&err).contains("-2e6 exceeds 1e6"), "{err}");
    let mut tris = cube_triangles();
    tris[6][2].z = 1e30;
    let err = load_temp("stl", &binary_stl(b"x", &tris)).unwrap_err();
    let msg = message(&err);
    assert!(
        msg.contains("triangle 7 of 12: coordinate 1.0000000150474662e30 exceeds 1e6"),
        "{msg}"
    );
    // Infinity in a binary STL (NaN is covered above) and in OBJ.
    tris[6][2].z = f64::INFINITY;
    let msg = message(&load_temp("stl", &binary_stl(b"x", &tris)).unwrap_err());
    assert!(msg.contains("triangle 7 of 12 has a non-finite"), "{msg}");
    let err = load_temp("obj", b"v 0 0 0\nv -inf 0 0\n").unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: Some(2), .. }), "{err}");
    // Exactly at the limit is fine.
    let m = load_temp("obj", b"v 0 0 0\nv 1e6 0 0\nv 0 -1e6 0\nf 1 2 3\n").unwrap();
    assert_eq!(m.triangles.len(), 1);
}

#[test]
fn oversized_mesh_files_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.stl");
    // Sparse: no disk used, but its size is over the limit.
    std::fs::File::create(&path)
        .unwrap()
        .set_len(MAX_FILE_BYTES + 1)
        .unwrap();
    let err = load_mesh(&path).unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: None, .. }), "{err}");
    let msg = message(&err);
    assert!(msg.contains("huge.stl"), "{msg}");
    assert!(
        msg.contains("the file is 1073741825 bytes, larger than the 1024 MiB a mesh file may have"),
        "{msg}"
    );
}

#[cfg(target_os = "linux")]
#[test]
fn endless_input_is_read_only_to_the_limit() {
    let err = read_file(Path::new("/dev/zero"), 4096).unwrap_err();
    assert!(matches!(err, MeshError::Parse { line: None, .. }), "{err}");
    assert!(
        message(&err).starts_with("/dev/zero: the file is more than 4096 bytes, larger than the 4096 bytes"),
        "{err}"
    );
    // By extension it is no mesh at all.
    let err = load_mesh(Path::new("/dev/zero")).unwrap_err();
    assert!(matches!(err, MeshError::Unsupported { .. }), "{err}");
}

#[test]
fn unsupported_and_missing_files() {
    let err = load_mesh(Path::new("part.step")).unwrap_err();
    assert!(matches!(err, MeshError::Unsupported { .. }), "{err}");
    let err = load_mesh(Path::new("/nonexistent/dir/part.stl")).unwrap_err();
    assert!(matches!(err, MeshError::Io { .. }), "{err}");
    assert!(message(&err).contains("/nonexistent/dir/part.stl"));
}

#[test]
fn mesh_methods() {
    let m = Mesh {
        vertices: vec![DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 3.0, 0.0)],
        triangles: vec![[0, 1, 2], [0, 0, 1]],
    };
    assert_eq!(Mesh::default().aabb(), None);
    assert_eq!(m.aabb(), Some((DVec3::ZERO, DVec3::new(2.0, 3.0, 0.0))));
    assert!((m.triangle_area(0) - 3.0).abs() < 1e-15);
    assert_eq!(m.triangle_normal(0), DVec3::Z);
    assert_eq!(m.triangle_normal(1), DVec3::ZERO);
    assert_eq!(m.triangle_area(1), 0.0);
    let s = m.scaled(0.001);
    assert_eq!(s.vertices[2], DVec3::new(0.0, 0.003, 0.0));
    assert_eq!(s.triangles, m.triangles);
    let pose = Pose::from_parts(
        DVec3::new(1.0, 0.0, 0.0),
        crate::DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2),
    );
    let t = m.transformed(&pose);
    assert!((t.vertices[1] - DVec3::new(1.0, 2.0, 0.0)).length() < 1e-12);
    assert!((t.triangle_area(0) - 3.0).abs() < 1e-12);
}

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

#[test]
fn real_fanuc_links_load() {
    let dir = data_dir().join("robots/fanuc_r2000ic/fanuc_r2000ic_support/meshes/r2000ic125l/collision");
    let mut names = 0;
    for link in [
        "base_link",
        "link_1",
        "link_2",
        "link_3",
        "link_4",
        "link_5",
        "link_6",
    ] {
        let path = dir.join(format!("{link}.stl"));
        let size = std::fs::metadata(&path).unwrap().len() as usize;
        let facets = (size - 84) / 50;
        let m = load_mesh(&path).unwrap();
        assert!(
            m.triangles.len() <= facets && m.triangles.len() * 100 >= facets * 99,
            "{link}"
        );
        // Closed collision meshes: V − E + F = 2 → V ≈ F/2 + 2 once welded.
        assert!(m.vertices.len() < m.triangles.len(), "{link}: not welded");
        let (lo, hi) = m.aabb().unwrap();
        let ext = hi - lo;
        assert!(
            ext.max_element() < 2.0 && ext.max_element() > 0.1,
            "{link}: {ext} (metres?)"
        );
        names += 1;
    }
    assert_eq!(names, 7);
    let m = load_mesh(&dir.join("link_3.stl")).unwrap();
    assert_eq!((m.triangles.len(), m.vertices.len()), (560, 282));
}

#[test]
fn real_car_body_loads() {
    let m = load_mesh(&data_dir().join("parts/body-in-white/car5.obj")).unwrap();
    assert_eq!(m.triangles.len(), 6931);
    assert_eq!(m.vertices.len(), 9752, "only the vertices faces use");
    let (lo, hi) = m.aabb().unwrap();
    let ext = hi - lo;
    assert!((ext.x - 1735.883).abs() < 0.01, "{ext}");
    assert!((ext.y - 4365.222).abs() < 0.01, "{ext}");
    assert!((ext.z - 1124.928).abs() < 0.01, "{ext}");
}

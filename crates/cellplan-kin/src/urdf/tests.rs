use super::*;
use std::f64::consts::FRAC_PI_2;

fn data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

fn no_packages() -> BTreeMap<String, PathBuf> {
    BTreeMap::new()
}

fn load(text: &str, tip: Option<&str>) -> Result<RobotModel, KinError> {
    load_urdf_str(text, Path::new("/virtual/robot.urdf"), &no_packages(), tip)
}

/// Line and message of a `KinError::Urdf`.
fn urdf_err(r: Result<RobotModel, KinError>) -> (Option<usize>, String, String) {
    match r {
        Err(KinError::Urdf {
            line, message, hint, ..
        }) => (line, message, hint),
        Err(e) => panic!("expected a URDF error, got {e}"),
        Ok(_) => panic!("expected a URDF error"),
    }
}

const PRIMITIVES: &str = r#"<?xml version="1.0"?>
<robot name="toy">
  <link name="base">
    <collision>
      <origin xyz="0 0 0.05" rpy="0 0 0"/>
      <geometry><box size="0.4 0.2 0.1"/></geometry>
    </collision>
  </link>
  <link name="arm">
    <collision>
      <origin xyz="0 0 0.25" rpy="0 0 1.5707963267948966"/>
      <geometry><cylinder radius="0.05" length="0.5"/></geometry>
    </collision>
    <collision>
      <geometry><capsule radius="0.02" length="0.1"/></geometry>
    </collision>
  </link>
  <link name="slider"/>
  <link name="hand">
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <link name="camera">
    <collision><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
  <link name="finger">
    <collision><geometry><sphere radius="0.005"/></geometry></collision>
  </link>
  <link name="side"/>
  <joint name="j_arm" type="continuous">
    <origin xyz="0 0 0.1"/>
    <parent link="base"/><child link="arm"/>
    <axis xyz="0 0 2"/>
  </joint>
  <joint name="j_slide" type="prismatic">
    <origin xyz="0 0 0.5"/>
    <parent link="arm"/><child link="slider"/>
    <axis xyz="1 0 0"/>
    <limit lower="-0.1" upper="0.3" effort="10" velocity="0.5"/>
  </joint>
  <joint name="j_hand" type="revolute">
    <origin xyz="0.1 0 0" rpy="0 1.5707963267948966 0"/>
    <parent link="slider"/><child link="hand"/>
    <axis xyz="0 1 0"/>
    <limit lower="-1" upper="2" effort="5" velocity="1.5"/>
  </joint>
  <joint name="j_camera" type="fixed">
    <origin xyz="0 0.2 0"/>
    <parent link="arm"/><child link="camera"/>
  </joint>
  <joint name="j_finger" type="prismatic">
    <origin xyz="0 0 0.1"/>
    <parent link="hand"/><child link="finger"/>
    <axis xyz="0 0 1"/>
    <limit lower="0" upper="0.05" effort="1" velocity="1"/>
  </joint>
  <joint name="j_side" type="fixed">
    <parent link="base"/><child link="side"/>
  </joint>
</robot>
"#;

#[test]
fn primitives_chain_and_attached_links() {
    let m = load(PRIMITIVES, None).unwrap();
    assert_eq!(m.name, "toy");
    let names: Vec<_> = m.chain.links.iter().map(|l| l.name.as_str()).collect();
    // The deepest leaf is the finger.
    assert_eq!(names, ["base", "arm", "slider", "hand", "finger"]);
    let j = &m.chain.joints;
    assert_eq!(j.len(), 4);
    assert_eq!(j[0].kind, JointKind::Continuous);
    assert_eq!((j[0].lower, j[0].upper), (-TAU, TAU));
    assert_eq!(j[0].axis, DVec3::Z, "axis normalised");
    assert_eq!(j[0].max_velocity, f64::INFINITY, "no <limit>: no velocity limit");
    assert_eq!(j[1].kind, JointKind::Prismatic);
    assert_eq!(
        (j[1].lower, j[1].upper, j[1].max_velocity, j[1].max_effort),
        (-0.1, 0.3, 0.5, 10.0)
    );
    assert_eq!((j[2].lower, j[2].upper), (-1.0, 2.0));
    assert_eq!(m.collision.len(), 5);

    // Base: a box with its origin.
    let [(ShapeSpec::Box { half_extents }, pose)] = m.collision[0].as_slice() else {
        panic!("{:?}", m.collision[0]);
    };
    assert_eq!(*half_extents, DVec3::new(0.2, 0.1, 0.05));
    assert_eq!(pose.translation, DVec3::new(0.0, 0.0, 0.05));

    // Arm: cylinder, capsule (cylinder + 2 spheres), and the camera's sphere moved 0.2 in y.
    let arm = &m.collision[1];
    assert_eq!(arm.len(), 5, "{arm:?}");
    let ShapeSpec::Cylinder { radius, half_height } = arm[0].0 else {
        panic!()
    };
    assert_eq!((radius, half_height), (0.05, 0.25));
    assert!((arm[0].1.rotation * DVec3::X - DVec3::Y).length() < 1e-12);
    assert!(matches!(arm[2].0, ShapeSpec::Sphere { radius } if radius == 0.02));
    assert!((arm[2].1.translation.z - 0.05).abs() < 1e-15);
    let ShapeSpec::Sphere { radius } = arm[4].0 else {
        panic!()
    };
    assert_eq!(radius, 0.01);
    assert!((arm[4].1.translation - DVec3::new(0.0, 0.2, 0.0)).length() < 1e-15);

    // Forward kinematics: hand at base + 0.1 + 0.5 up, then 0.1 along x, plus the slide.
    let tip_link = m.chain.link_index("hand").unwrap();
    let mut poses = vec![Pose::IDENTITY; m.chain.links.len()];
    m.chain.fk_all(&[FRAC_PI_2, 0.2, 0.0, 0.0], &mut poses);
    assert!(
        (poses[tip_link].translation - DVec3::new(0.0, 0.3, 0.6)).length() < 1e-12,
        "{:?}",
        poses[tip_link]
    );
}

#[test]
fn tip_can_be_chosen_and_everything_below_merges_into_it() {
    let m = load(PRIMITIVES, Some("hand")).unwrap();
    let names: Vec<_> = m.chain.links.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["base", "arm", "slider", "hand"]);
    assert_eq!(m.chain.dof(), 3);
    // The hand carries its sphere and the finger's (taken at zero travel, 0.1 along z).
    let hand = &m.collision[3];
    assert_eq!(hand.len(), 2);
    assert!((hand[1].1.translation - DVec3::new(0.0, 0.0, 0.1)).length() < 1e-15);

    let (line, msg, hint) = urdf_err(load(PRIMITIVES, Some("gripper")));
    assert_eq!(line, None);
    assert!(
        msg.contains("'gripper'") && msg.contains("base, arm, slider, hand, camera, finger, side"),
        "{msg}"
    );
    assert!(!hint.is_empty());
}

#[test]
fn tool0_is_the_default_tip() {
    let text = PRIMITIVES.replace("\"camera\"", "\"tool0\"");
    let m = load(&text, None).unwrap();
    assert_eq!(m.chain.tip_name(), "tool0");
    assert_eq!(m.chain.links.len(), 3);
    assert_eq!(m.chain.dof(), 1);
}

#[test]
fn rpy_is_fixed_axis_roll_pitch_yaw() {
    let text = r#"<robot name="r"><link name="a"/><link name="b"/>
      <joint name="j" type="fixed"><origin xyz="1 2 3" rpy="0.1 0.2 0.3"/>
      <parent link="a"/><child link="b"/></joint></robot>"#;
    let m = load(text, None).unwrap();
    let o = m.chain.links[1].origin;
    let expected = DQuat::from_euler(glam::EulerRot::ZYX, 0.3, 0.2, 0.1);
    assert!(o.rotation.angle_between(expected) < 1e-12);
    assert_eq!(o.translation, DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(m.chain.dof(), 0);
}

#[test]
fn malformed_xml_reports_the_line() {
    let text = "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n  <link name=\"a\">\n  </lnk>\n</robot>\n";
    let (line, msg, _) = urdf_err(load(text, None));
    assert_eq!(line, Some(4), "{msg}");
    assert!(msg.contains("not well-formed"), "{msg}");
    let (line, _, _) = urdf_err(load("solid cube\nfacet normal 0 0 1\n", None));
    assert_eq!(line, Some(1));
}

#[test]
fn other_xml_is_not_a_urdf() {
    let (line, msg, _) = urdf_err(load("<?xml version=\"1.0\"?>\n\n<sdf version=\"1.6\"/>\n", None));
    assert_eq!(line, Some(3));
    assert!(msg.contains("not a URDF"), "{msg}");
    let xacro = "<robot name=\"r\" xmlns:xacro=\"http://www.ros.org/wiki/xacro\">\n  <xacro:include filename=\"x.xacro\"/>\n</robot>";
    let (line, _, hint) = urdf_err(load(xacro, None));
    assert_eq!(line, Some(2));
    assert!(hint.contains("xacro"), "{hint}");
}

#[test]
fn structural_errors_report_the_line() {
    let cases: [(&str, &str, usize, &str); 8] = [
        ("type=\"prismatic\"", "type=\"slide\"", 34, "unknown type"),
        (
            "<parent link=\"arm\"/><child link=\"slider\"/>",
            "<child link=\"slider\"/>",
            34,
            "no <parent>",
        ),
        (
            "<limit lower=\"-0.1\" upper=\"0.3\" effort=\"10\" velocity=\"0.5\"/>",
            "",
            34,
            "no <limit>",
        ),
        ("<axis xyz=\"0 1 0\"/>", "<axis xyz=\"0 1\"/>", 43, "3 number"),
        (
            "<box size=\"0.4 0.2 0.1\"/>",
            "<box size=\"0.4 x 0.1\"/>",
            6,
            "3 number",
        ),
        (
            "<link name=\"side\"/>",
            "<link name=\"arm\"/>",
            28,
            "defined twice",
        ),
        (
            "<parent link=\"base\"/><child link=\"side\"/>",
            "<parent link=\"bse\"/><child link=\"side\"/>",
            56,
            "'bse'",
        ),
        (
            "<sphere radius=\"0.03\"/>",
            "<cone radius=\"0.03\"/>",
            20,
            "unknown geometry",
        ),
    ];
    for (from, to, want_line, want_msg) in cases {
        assert!(PRIMITIVES.contains(from), "{from}");
        let text = PRIMITIVES.replacen(from, to, 1);
        let (line, msg, _) = urdf_err(load(&text, None));
        assert_eq!(line, Some(want_line), "{to}: {msg}");
        assert!(msg.contains(want_msg), "{to}: {msg}");
    }
}

#[test]
fn trees_only() {
    // Two roots.
    let text = PRIMITIVES.replace(
        "<parent link=\"base\"/><child link=\"side\"/>",
        "<parent link=\"side\"/><child link=\"side\"/>",
    );
    let (_, msg, _) = urdf_err(load(&text, None));
    assert!(msg.contains("cycle") || msg.contains("root"), "{msg}");
    let two_roots = "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/></robot>";
    let (_, msg, _) = urdf_err(load(two_roots, None));
    assert!(msg.contains("2 root links") && msg.contains("a, b"), "{msg}");
    let two_parents = "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><link name=\"c\"/>\n<joint name=\"x\" type=\"fixed\"><parent link=\"a\"/><child link=\"c\"/></joint>\n<joint name=\"y\" type=\"fixed\"><parent link=\"b\"/><child link=\"c\"/></joint></robot>";
    let (line, msg, _) = urdf_err(load(two_parents, None));
    assert_eq!(line, Some(3));
    assert!(msg.contains("two joints"), "{msg}");
}

fn mesh_robot(filename: &str, scale: &str) -> String {
    format!(
        "<robot name=\"m\">\n<link name=\"base\"/>\n<link name=\"shell\">\n<visual><geometry><mesh filename=\"{filename}\"/></geometry></visual>\n<collision><geometry><mesh filename=\"{filename}\" {scale}/></geometry></collision>\n</link>\n<joint name=\"j\" type=\"fixed\"><parent link=\"base\"/><child link=\"shell\"/></joint>\n</robot>\n"
    )
}

#[test]
fn unknown_package_is_named_with_a_hint() {
    let text = mesh_robot("package://ur_description/meshes/ur5/collision/base.stl", "");
    let (line, msg, hint) = urdf_err(load(&text, None));
    assert_eq!(line, Some(5));
    assert!(msg.contains("'ur_description'") && msg.contains("shell"), "{msg}");
    assert!(hint.contains("add it under packages in the cell file"), "{hint}");
    let shown = load(&text, None).unwrap_err().to_string();
    assert!(shown.contains("/virtual/robot.urdf:5"), "{shown}");
}

#[test]
fn missing_mesh_names_link_and_file() {
    let packages = BTreeMap::from([(
        "ur_description".to_string(),
        data().join("robots/ur5/ur_description"),
    )]);
    let text = mesh_robot("package://ur_description/meshes/ur5/collision/nothere.stl", "");
    let err = load_urdf_str(&text, Path::new("/virtual/robot.urdf"), &packages, None).unwrap_err();
    let KinError::Mesh { link, source, .. } = &err else {
        panic!("{err}")
    };
    assert_eq!(link, "shell");
    assert!(matches!(source.as_ref(), MeshError::Io { path, .. } if path.ends_with("nothere.stl")));
    let shown = err.to_string();
    assert!(
        shown.contains("shell") && shown.contains("nothere.stl"),
        "{shown}"
    );
}

#[test]
fn mesh_paths_resolve_relative_file_and_package_with_scale() {
    let urdf = data().join("robots/ur5/urdf/virtual.urdf");
    let stl = data().join("robots/ur5/ur_description/meshes/ur5/collision/base.stl");
    let packages = BTreeMap::from([(
        "ur_description".to_string(),
        data().join("robots/ur5/ur_description"),
    )]);
    let load_one = |filename: &str, scale: &str| -> Arc<Mesh> {
        let m = load_urdf_str(&mesh_robot(filename, scale), &urdf, &packages, None).unwrap();
        assert_eq!(m.chain.links.len(), 2);
        match &m.collision[1][..] {
            [(ShapeSpec::Mesh(mesh), _)] => mesh.clone(),
            other => panic!("{other:?}"),
        }
    };
    let by_package = load_one("package://ur_description/meshes/ur5/collision/base.stl", "");
    let relative = load_one("../ur_description/meshes/ur5/collision/base.stl", "");
    let file = load_one(&format!("file://{}", stl.display()), "");
    assert!(!by_package.vertices.is_empty());
    assert_eq!(by_package, relative);
    assert_eq!(by_package, file);
    let scaled = load_one(
        "package://ur_description/meshes/ur5/collision/base.stl",
        "scale=\"2 2 -1\"",
    );
    assert_eq!(scaled.vertices.len(), by_package.vertices.len());
    let (v, w) = (by_package.vertices[5], scaled.vertices[5]);
    assert_eq!(w, DVec3::new(2.0 * v.x, 2.0 * v.y, -v.z));
    // Mirrored: winding flipped so normals still point out.
    let (t, u) = (by_package.triangles[3], scaled.triangles[3]);
    assert_eq!(u, [t[0], t[2], t[1]]);
}

#[test]
fn unsupported_scheme_and_unreadable_file() {
    let (line, msg, _) = urdf_err(load(&mesh_robot("http://example.com/a.stl", ""), None));
    assert_eq!(line, Some(5));
    assert!(msg.contains("http://"), "{msg}");
    let err = load_urdf(Path::new("/definitely/not/here.urdf"), &no_packages(), None).unwrap_err();
    assert!(matches!(err, KinError::Io { .. }), "{err}");
}

#[test]
fn floating_joint_on_the_chain_is_refused() {
    let text = PRIMITIVES.replace("type=\"continuous\"", "type=\"floating\"");
    let (line, msg, _) = urdf_err(load(&text, None));
    assert_eq!(line, Some(29));
    assert!(msg.contains("not supported"), "{msg}");
}

#[test]
fn limits_must_be_ordered() {
    let text = PRIMITIVES.replace("lower=\"-1\" upper=\"2\"", "lower=\"2\" upper=\"-1\"");
    let (line, msg, _) = urdf_err(load(&text, None));
    assert_eq!(line, Some(40));
    assert!(msg.contains("lower"), "{msg}");
}

#[test]
fn visual_and_inertial_are_checked_with_lines() {
    let cases = [
        (
            "<visual><geometry><box size=\"1 2\"/></geometry></visual>",
            "3 number",
        ),
        (
            "<inertial><mass value=\"abc\"/><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>",
            "1 number",
        ),
        (
            "<inertial><inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>",
            "without <mass>",
        ),
    ];
    for (inner, want) in cases {
        let text = PRIMITIVES.replacen(
            "<link name=\"slider\"/>",
            &format!("<link name=\"slider\">\n{inner}</link>"),
            1,
        );
        let (line, msg, _) = urdf_err(load(&text, None));
        assert_eq!(line, Some(19), "{msg}");
        assert!(msg.contains(want), "{msg}");
    }
    let text = PRIMITIVES.replace("effort=\"5\" velocity=\"1.5\"", "effort=\"5\"");
    let (line, msg, _) = urdf_err(load(&text, None));
    assert_eq!(line, Some(44));
    assert!(msg.contains("velocity"), "{msg}");
    // A visual mesh that is missing on disk is fine: visuals are not loaded.
    assert!(load(&PRIMITIVES.replacen("<link name=\"slider\"/>", "<link name=\"slider\"><visual><geometry><mesh filename=\"package://gone/x.dae\"/></geometry></visual></link>", 1), None).is_ok());
}

/// 1-based line of the first line of `text` holding `needle`.
fn line_with(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn absurd_numbers_are_refused_naming_the_element() {
    let cases: [(&str, &str, &str); 8] = [
        // (from, to, the message says)
        (
            "<origin xyz=\"0 0 0.1\"/>",
            "<origin xyz=\"0 0 inf\"/>",
            "attribute xyz=\"0 0 inf\" of <origin> in joint 'j_arm' is inf, not a finite number",
        ),
        (
            "<origin xyz=\"0 0 0.1\"/>",
            "<origin xyz=\"0 1e30 0.1\"/>",
            "attribute xyz=\"0 1e30 0.1\" of <origin> in joint 'j_arm': 1e30 m exceeds 1e4 m in magnitude — is the unit right?",
        ),
        (
            "<box size=\"0.4 0.2 0.1\"/>",
            "<box size=\"400 200 20000\"/>",
            "of <box> in link 'base': 2e4 m exceeds 1e4 m",
        ),
        (
            "<sphere radius=\"0.03\"/>",
            "<sphere radius=\"-inf\"/>",
            "of <sphere> in link 'hand' is -inf, not a finite number",
        ),
        (
            "lower=\"-1\" upper=\"2\"",
            "lower=\"-inf\" upper=\"2\"",
            "attribute lower=\"-inf\" of <limit> in joint 'j_hand' is -inf",
        ),
        (
            "lower=\"-0.1\" upper=\"0.3\"",
            "lower=\"-0.1\" upper=\"30000\"",
            "attribute upper=\"30000\" of <limit> in joint 'j_slide': 3e4 m exceeds 1e4 m",
        ),
        (
            "effort=\"5\" velocity=\"1.5\"",
            "effort=\"5\" velocity=\"inf\"",
            "attribute velocity=\"inf\" of <limit> in joint 'j_hand' is inf",
        ),
        (
            "<axis xyz=\"0 1 0\"/>",
            "<axis xyz=\"0 1 -inf\"/>",
            "of <axis> in joint 'j_hand' is -inf",
        ),
    ];
    for (from, to, says) in cases {
        assert!(PRIMITIVES.contains(from), "{from}");
        let text = PRIMITIVES.replacen(from, to, 1);
        let (line, msg, hint) = urdf_err(load(&text, None));
        assert_eq!(line, Some(line_with(&text, to)), "{to}: {msg}");
        assert!(msg.contains(says), "{to}: {msg}");
        assert!(!hint.is_empty());
    }
    // A revolute joint's limits are angles: large but finite is not a length error.
    let text = PRIMITIVES.replacen("lower=\"-1\" upper=\"2\"", "lower=\"-20000\" upper=\"2\"", 1);
    assert!(load(&text, None).is_ok());
}

#[test]
fn a_mesh_scaled_beyond_reason_is_refused() {
    let urdf = data().join("robots/ur5/urdf/virtual.urdf");
    let packages = BTreeMap::from([(
        "ur_description".to_string(),
        data().join("robots/ur5/ur_description"),
    )]);
    let file = "package://ur_description/meshes/ur5/collision/base.stl";
    let text = mesh_robot(file, "scale=\"1e6 1e6 1e6\"");
    let err = load_urdf_str(&text, &urdf, &packages, None).unwrap_err();
    let KinError::Urdf {
        line, message, hint, ..
    } = err
    else {
        panic!("{err}")
    };
    assert_eq!(line, Some(5));
    assert!(
        message.contains(&format!("collision mesh \"{file}\" of link 'shell' reaches"))
            && message.contains("beyond 1e4 m — is the unit right?"),
        "{message}"
    );
    assert!(hint.contains("scale=\"0.001 0.001 0.001\""), "{hint}");
    // The same mesh in metres loads.
    assert!(load_urdf_str(&mesh_robot(file, ""), &urdf, &packages, None).is_ok());
}

#[test]
fn oversized_and_non_utf8_urdf_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let huge = dir.path().join("huge.urdf");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(MAX_URDF_BYTES + 1)
        .unwrap();
    let err = load_urdf(&huge, &no_packages(), None).unwrap_err();
    let KinError::Urdf { line, message, .. } = &err else {
        panic!("{err}")
    };
    assert_eq!(*line, None);
    assert_eq!(
        message,
        "the file is 67108865 bytes, larger than the 64 MiB a URDF may have"
    );
    assert!(err.to_string().contains("huge.urdf"), "{err}");

    let latin1 = dir.path().join("latin1.urdf");
    std::fs::write(
        &latin1,
        b"<robot name=\"r\">\n<!-- caf\xe9 -->\n<link name=\"a\"/>\n</robot>\n",
    )
    .unwrap();
    let (line, msg, _) = urdf_err(load_urdf(&latin1, &no_packages(), None));
    assert_eq!(line, Some(2));
    assert!(msg.contains("(0xe9) is not UTF-8 text"), "{msg}");
}

#[cfg(target_os = "linux")]
#[test]
fn dev_zero_is_refused_not_read_forever() {
    // Reads MAX_URDF_BYTES + 1 bytes, then stops.
    let err = load_urdf(Path::new("/dev/zero"), &no_packages(), None).unwrap_err();
    let KinError::Urdf { line, message, .. } = &err else {
        panic!("{err}")
    };
    assert_eq!(*line, None);
    assert!(
        message.contains("more than 67108864 bytes, larger than the 64 MiB"),
        "{message}"
    );
    let err = read_urdf(Path::new("/dev/zero"), 100).unwrap_err();
    assert!(err.to_string().contains("more than 100 bytes"), "{err}");
}

//! The report and the exports of a coordinated plan of the crossing cell (the two-robot
//! example with the robots' paths crossing, from `cellplan_optical::testing`): the HTML page,
//! the drawn scene, the glTF and the CSV files.
use cellplan_core::coord::Coordination;
use cellplan_optical::testing::{document, fixture};
use cellplan_verify::{VerifySettings, verify};

/// Reads `count` × `width` little-endian floats of accessor `a` from the GLB's binary chunk.
fn floats(a: &gltf::Accessor, blob: &[u8], width: usize) -> Vec<f32> {
    let view = a.view().expect("accessors have views");
    let start = view.offset() + a.offset();
    blob[start..start + a.count() * width * 4]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// The report of a coordinated plan on the crossing cell: every chart and table is there, the
/// conflicts before coordination and the waits after are marked, and the viewer's data is the
/// plan's (its robots, samples and meshes).
#[test]
fn the_report_shows_the_plan_its_conflicts_and_its_waits() {
    use base64::Engine;
    use cellplan_report::html::{PlanReport, plan_html};
    use cellplan_report::scene::{MESH_BUDGET, Scene};
    let f = fixture();
    let (doc, c) = document(Coordination::FixedPriority);
    let verdict = verify(&f.cell, &doc, &VerifySettings::default());
    assert!(verdict.ok, "{:?}", verdict.violations);
    assert!(
        !c.before.is_empty() && c.waits > 0,
        "the crossing cell needs waits"
    );
    let scene = Scene::new(&f.cell, MESH_BUDGET);
    let page = plan_html(&PlanReport {
        plan: &doc,
        cell: &f.cell,
        scene: &scene,
        verification: Some(&verdict),
        plan_file: Some("plan.json"),
    })
    .unwrap();
    for id in [
        "summary",
        "robots",
        "view",
        "time",
        "play",
        "gantt",
        "timepos-before",
        "timepos-after",
        "conflicts",
        "waits",
        "settings",
        "cellplan-data",
    ] {
        assert!(page.contains(&format!("id=\"{id}\"")), "no #{id}");
    }
    assert!(page.contains(">verified<"));
    let visits: usize = doc.robots.iter().map(|r| r.tasks.len()).sum();
    let waits: usize = doc.robots.iter().map(|r| r.waits.len()).sum();
    let gantt = &page[page.find("id=\"gantt\"").unwrap()..];
    let gantt = &gantt[..gantt.find("</svg>").unwrap()];
    assert_eq!(gantt.matches("class=\"measuring\"").count(), visits);
    assert_eq!(gantt.matches("class=\"waiting\"").count(), waits);
    let chart = |id: &str| {
        let s = &page[page.find(&format!("id=\"{id}\"")).unwrap()..];
        s[..s.find("</svg>").unwrap()].to_string()
    };
    let before = chart("timepos-before");
    assert_eq!(
        before.matches("class=\"conflict\"").count(),
        doc.coordination.conflicts_before.len()
    );
    assert_eq!(before.matches("class=\"track\"").count(), doc.robots.len());
    let after = chart("timepos-after");
    assert_eq!(after.matches("class=\"wait\"").count(), waits);
    assert_eq!(after.matches("class=\"conflict\"").count(), 0);
    // The embedded data: JSON the script can read, no `</` that would end its element early.
    let open = "<script id=\"cellplan-data\" type=\"application/json\">";
    let data = &page[page.find(open).unwrap() + open.len()..];
    let data = &data[..data.find("</script>").unwrap()];
    assert!(!data.contains("</"));
    let v: serde_json::Value = serde_json::from_str(data).unwrap();
    let b64 = |s: &serde_json::Value| {
        base64::engine::general_purpose::STANDARD
            .decode(s.as_str().unwrap())
            .unwrap()
    };
    assert_eq!(v["robots"].as_array().unwrap().len(), doc.robots.len());
    for (r, rp) in v["robots"].as_array().unwrap().iter().zip(&doc.robots) {
        assert_eq!(r["name"], rp.name.as_str());
        assert_eq!(b64(&r["t"]).len(), 4 * rp.trajectory.len());
        assert_eq!(b64(&r["q"]).len(), 4 * rp.trajectory.len() * rp.joints.len());
        assert!(!b64(&r["before"]).is_empty());
    }
    for g in v["geometries"].as_array().unwrap() {
        let (p, i) = (b64(&g["p"]), b64(&g["i"]));
        let vertices = (p.len() / 12) as u32;
        assert!(p.len() % 12 == 0 && i.len() % 12 == 0 && !i.is_empty());
        assert!(
            i.chunks_exact(4)
                .all(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) < vertices)
        );
    }
    assert_eq!(v["tasks"].as_array().unwrap().len(), f.cell.tasks.len());
    assert_eq!(
        v["conflicts"].as_array().unwrap().len(),
        doc.coordination.conflicts_before.len()
    );
    // A plan for other robots is refused with a sentence.
    let mut other = doc.clone();
    other.robots[0].name = "R9".into();
    let err = plan_html(&PlanReport {
        plan: &other,
        cell: &f.cell,
        scene: &scene,
        verification: None,
        plan_file: None,
    })
    .unwrap_err();
    assert_eq!(
        err,
        cellplan_report::scene::Mismatch::NoRobot { robot: "R9".into() },
        "{err}"
    );
}

/// Robots of one model share their meshes; a small budget decimates every drawn mesh.
#[test]
fn the_scene_instances_robot_meshes_and_decimates_to_budget() {
    use cellplan_report::scene::Scene;
    let f = fixture();
    let full = Scene::new(&f.cell, usize::MAX);
    let parts: usize = full
        .robots
        .iter()
        .flat_map(|r| r.parts.iter().map(Vec::len))
        .sum();
    let per_robot = parts / full.robots.len();
    assert_eq!(full.robots.len(), 2);
    assert!(
        full.geometries.len() <= per_robot + full.statics.len(),
        "{} geometries for {} robot parts",
        full.geometries.len(),
        parts
    );
    let small = Scene::new(&f.cell, 300);
    assert!(small.geometries.iter().all(|g| g.indices.len() / 3 <= 300));
    assert!(
        small
            .geometries
            .iter()
            .any(|g| g.source_triangles > 300 && g.indices.len() / 3 >= 75),
        "the big meshes are decimated, not emptied"
    );
    // The scene's kinematics are the robot's.
    let robot = &f.cell.robots[0];
    let q = [0.3, -0.2, 0.4, 1.0, -0.7, 2.0];
    let a = full.robots[0].tcp_pose(&q);
    let b = robot.tcp_pose(&q);
    assert!((a.translation - b.translation).length() < 1e-9);
}

/// The glTF export is a valid GLB that a glTF reader loads, with one animation channel per
/// joint; replaying its node transforms at a sample puts each probe where the plan says.
#[test]
fn the_gltf_export_replays_the_plan() {
    use cellplan_geom::{DQuat, DVec3, Pose};
    use cellplan_report::scene::{MESH_BUDGET, Scene};
    let f = fixture();
    let (doc, _) = document(Coordination::FixedPriority);
    let scene = Scene::new(&f.cell, MESH_BUDGET);
    let bytes = cellplan_report::gltf::glb(&doc, &f.cell, &scene).unwrap();
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
        bytes.len()
    );
    let g = gltf::Gltf::from_slice(&bytes).expect("a valid glTF");
    let blob = g.blob.as_deref().expect("a binary chunk");
    let anim = g.animations().next().expect("an animation");
    let dofs: usize = doc.robots.iter().map(|r| r.joints.len()).sum();
    assert_eq!(anim.channels().count(), dofs);
    for rp in &doc.robots {
        let robot = f.cell.robot(&rp.name).unwrap();
        let k = rp.trajectory.len() / 2;
        let sample = &rp.trajectory[k];
        let node = |name: &str| g.nodes().find(|n| n.name() == Some(name)).unwrap();
        let trs = |n: &gltf::Node| {
            let (t, r, _) = n.transform().decomposed();
            (
                DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64),
                DQuat::from_xyzw(r[0] as f64, r[1] as f64, r[2] as f64, r[3] as f64),
            )
        };
        let (t, r) = trs(&node(&rp.name));
        let mut pose = Pose::from_parts(t, r);
        for link in &robot.model.chain.links {
            let n = node(&format!("{}/{}", rp.name, link.name));
            let (t, mut r) = trs(&n);
            if let Some(ch) = anim.channels().find(|c| c.target().node().index() == n.index()) {
                let input = floats(&ch.sampler().input(), blob, 1);
                assert_eq!(input.len(), rp.trajectory.len());
                assert!((input[k] as f64 - sample.t).abs() < 1e-4);
                let out = floats(&ch.sampler().output(), blob, 4);
                let q = &out[4 * k..4 * k + 4];
                r = DQuat::from_xyzw(q[0] as f64, q[1] as f64, q[2] as f64, q[3] as f64);
            }
            pose *= Pose::from_parts(t, r);
        }
        let tcp = (pose * robot.tool.tcp).translation;
        let want = robot.tcp_pose(&sample.q).translation;
        assert!((tcp - want).length() < 1e-4, "{}: {tcp} vs {want}", rp.name);
    }
}

/// The CSV export: two files per robot; trajectory rows are the plan's samples with the probe
/// pose of the robot's kinematics; the program lists every MP with its times.
#[test]
fn the_csv_export_carries_joints_probe_poses_and_the_program() {
    use cellplan_report::scene::{MESH_BUDGET, Scene};
    let f = fixture();
    let (doc, _) = document(Coordination::FixedPriority);
    let scene = Scene::new(&f.cell, MESH_BUDGET);
    let files = cellplan_report::csv::files(&doc, &scene).unwrap();
    assert_eq!(files.len(), 2 * doc.robots.len());
    for rp in &doc.robots {
        let robot = f.cell.robot(&rp.name).unwrap();
        let (_, traj) = files
            .iter()
            .find(|(n, _)| *n == format!("{}-trajectory.csv", rp.name))
            .unwrap();
        let mut rows = csv::Reader::from_reader(traj.as_bytes());
        let header = rows.headers().unwrap().clone();
        assert_eq!(header.len(), 1 + rp.joints.len() + 7 + 2);
        let records: Vec<csv::StringRecord> = rows.records().map(Result::unwrap).collect();
        assert_eq!(records.len(), rp.trajectory.len());
        let measuring = records
            .iter()
            .filter(|r| &r[header.len() - 2] == "measuring")
            .count();
        assert!(measuring > 0);
        let waiting = records
            .iter()
            .filter(|r| &r[header.len() - 2] == "waiting")
            .count();
        assert_eq!(waiting > 0, !rp.waits.is_empty());
        for (rec, s) in records.iter().zip(&rp.trajectory).step_by(17) {
            let num = |i: usize| rec[i].parse::<f64>().unwrap();
            assert!((num(0) - s.t).abs() < 1e-3);
            let q: Vec<f64> = (1..=rp.joints.len()).map(num).collect();
            assert!(q.iter().zip(&s.q).all(|(a, b)| (a - b).abs() < 1e-5));
            let p = robot.tcp_pose(&s.q).translation;
            let n = rp.joints.len();
            assert!((num(n + 1) - p.x).abs() < 1e-4 && (num(n + 3) - p.z).abs() < 1e-4);
        }
        let (_, prog) = files
            .iter()
            .find(|(n, _)| *n == format!("{}-program.csv", rp.name))
            .unwrap();
        let mut rows = csv::Reader::from_reader(prog.as_bytes());
        let records: Vec<csv::StringRecord> = rows.records().map(Result::unwrap).collect();
        let measures: Vec<&csv::StringRecord> = records.iter().filter(|r| &r[1] == "measure").collect();
        assert_eq!(measures.len(), rp.tasks.len());
        for (m, v) in measures.iter().zip(&rp.tasks) {
            assert_eq!(&m[2], v.task.as_str());
            let arrive: f64 = m[m.len() - 3].parse().unwrap();
            assert!((arrive - v.arrive_s).abs() < 1e-3);
        }
        assert_eq!(records.iter().filter(|r| &r[1] == "wait").count(), rp.waits.len());
        // The blends on the via points they round, with their radii.
        let blended: Vec<f64> = records
            .iter()
            .filter(|r| !r[r.len() - 1].is_empty())
            .map(|r| {
                assert_eq!(&r[1], "via");
                r[r.len() - 1].parse().unwrap()
            })
            .collect();
        let stated: Vec<f64> = rp
            .legs
            .iter()
            .flat_map(|l| l.blends.iter().map(|b| b.radius))
            .collect();
        assert_eq!(blended.len(), stated.len());
        assert!(blended.iter().zip(&stated).all(|(a, b)| (a - b).abs() < 1e-6));
        assert_eq!(&records[0][1], "home");
        assert_eq!(&records[records.len() - 1][1], "home");
    }
}

/// The cell drawing escapes the names it writes (robot names come from the cell file), in the
/// legend too.
#[test]
fn the_cell_drawing_escapes_robot_names() {
    let path = cellplan_optical::testing::example_copy("svg-test", "svg-2r", 2, |text| {
        text.replace("name = \"R2\"", "name = \"R<2>&\"")
    });
    let cell = cellplan_optical::load(&path, &cellplan_model::LoadOptions::default()).unwrap();
    let svg = cellplan_report::svg::render(&cell, None);
    assert!(
        svg.contains("δ R&lt;2&gt;&amp; (only R&lt;2&gt;&amp;)"),
        "the legend escapes"
    );
    assert!(!svg.contains("R<2>") && !svg.contains(">&<"));
}

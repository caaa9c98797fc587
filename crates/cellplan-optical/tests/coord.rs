//! Coordination on a two-robot cell built so that the robots' paths cross: the bundled
//! two-robot example with the second robot moved to 1 m from the first, and its first 8 MPs.
//! Every strategy must give a plan the verifier accepts; the uncoordinated plan must be
//! rejected, naming the conflict; injected faults must be caught.
use cellplan_core::candidates::{CandidateTable, generate};
use cellplan_core::coord::{self, CoordSettings, Coordination};
use cellplan_core::document as output;
use cellplan_core::plan::{self, Outcome, PlanSettings};
use cellplan_core::verify::{VerifySettings, ViolationKind, verify};
use cellplan_model::{Cell, LoadOptions};
use cellplan_optical::load;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn crossing_cell() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap();
    let example = root.join("examples/autobody-2r");
    let dir = std::env::temp_dir().join(format!("cellplan-coord-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(example.join("cell.toml"))
        .unwrap()
        .replace("../../data", &root.join("data").display().to_string())
        .replace("name = \"autobody-2r\"", "name = \"crossing-2r\"")
        .replace("xyz = [3100, 1100, 0]", "xyz = [3100, -100, 0]");
    assert!(text.contains("[3100, -100, 0]"), "the second robot is moved");
    std::fs::write(dir.join("cell.toml"), text).unwrap();
    let tasks = std::fs::read_to_string(example.join("tasks.csv")).unwrap();
    let keep: Vec<&str> = tasks.lines().filter(|l| !l.starts_with('#')).take(9).collect();
    std::fs::write(dir.join("tasks.csv"), keep.join("\n") + "\n").unwrap();
    dir.join("cell.toml")
}

struct Fixture {
    cell: Cell,
    table: CandidateTable,
    settings: PlanSettings,
    outcome: Outcome,
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let cell = load(&crossing_cell(), &LoadOptions::default()).expect("the crossing cell loads");
        let table = generate(&cell);
        let settings = PlanSettings {
            alternatives: 8,
            balanced_iterations: 60,
            time_limit: std::time::Duration::from_secs(3600),
            ..PlanSettings::default()
        };
        let outcome = plan::plan(&cell, &table, &settings, &|_| {}).expect("the crossing cell plans");
        Fixture {
            cell,
            table,
            settings,
            outcome,
        }
    })
}

fn document(strategy: Coordination) -> (output::Plan, coord::Coordinated) {
    let f = fixture();
    let c = coord::coordinate_outcome(
        &f.cell,
        &f.table,
        &f.outcome,
        &CoordSettings {
            strategy,
            ..CoordSettings::default()
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", strategy));
    (
        output::build(&f.cell, &f.table, &f.outcome, &c, &f.settings, 0.0, 0.0),
        c,
    )
}

#[test]
fn the_uncoordinated_plan_has_a_conflict_and_the_verifier_names_it() {
    let f = fixture();
    let (doc, c) = document(Coordination::None);
    assert!(!c.after.is_empty(), "the robots of this cell must meet");
    let first = &doc.coordination.conflicts_after[0];
    assert_eq!(first.robots, ["R1".to_string(), "R2".to_string()]);
    assert!(first.end_s > first.start_s);
    // Scenario 1 exactly when both probes are measuring.
    let measuring = first.activity.iter().all(|a| a.starts_with("measuring"));
    assert_eq!(first.scenario == 1, measuring, "{first:?}");
    let report = verify(&f.cell, &doc, &VerifySettings::default());
    assert!(!report.ok);
    let rr: Vec<_> = report
        .violations
        .iter()
        .filter(|v| v.kind == ViolationKind::RobotRobot)
        .collect();
    assert!(!rr.is_empty(), "{:#?}", report.violations);
    assert_eq!(rr[0].robot.as_deref(), Some("R1"));
    assert_eq!(rr[0].other.as_deref(), Some("R2"));
    // The verifier sees the contact where the planner's search found it (within its step).
    let t = rr[0].time_s.unwrap();
    assert!(t <= first.end_s && t + 0.05 >= first.start_s, "{t} vs {first:?}");
}

#[test]
fn every_strategy_gives_a_verified_conflict_free_plan() {
    let f = fixture();
    let (_, none) = document(Coordination::None);
    let free = coord::cycle_and_delta(&none.timed).0;
    for strategy in Coordination::RESOLVING {
        let (doc, c) = document(strategy);
        let report = verify(&f.cell, &doc, &VerifySettings::default());
        assert!(report.ok, "{}: {:#?}", strategy, report.violations);
        assert!(!c.before.is_empty(), "{}", strategy);
        assert!(c.after.is_empty());
        assert!(c.resolved >= 1);
        // Resolving costs time or nothing; never less than the robots passing through each other.
        assert!(doc.cycle_time_s >= free - 1e-9, "{}", strategy);
        // The waits are in the document where the strategy made them.
        let waits: usize = doc.robots.iter().map(|r| r.waits.len()).sum();
        assert_eq!(waits > 0, c.programs.iter().any(|p| !p.waits.is_empty()));
        if strategy == Coordination::DelayStartup {
            assert!(
                doc.robots
                    .iter()
                    .flat_map(|r| &r.waits)
                    .all(|w| w.leg == 0 && w.waypoint == 0)
            );
        }
    }
}

#[test]
fn best_is_no_worse_than_the_baselines_here() {
    let cycle = |s: Coordination| document(s).0.cycle_time_s;
    let best = cycle(Coordination::Best);
    for s in [Coordination::DelayStartup, Coordination::FixedPriority] {
        assert!(best <= cycle(s) + 1e-9, "best {best} vs {} {}", s, cycle(s));
    }
}

#[test]
fn coordination_does_not_depend_on_the_thread_count() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let (mut doc, _) = document(Coordination::Best);
                doc.compute_s = output::ComputeTimes::default();
                doc.coordination.compute_s = 0.0;
                doc
            })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn the_verifier_catches_injected_faults() {
    let f = fixture();
    let (good, _) = document(Coordination::FixedPriority);
    let settings = VerifySettings::default();
    assert!(verify(&f.cell, &good, &settings).ok);
    let kinds = |doc: &output::Plan| -> Vec<ViolationKind> {
        verify(&f.cell, doc, &settings)
            .violations
            .iter()
            .map(|v| v.kind)
            .collect()
    };
    // The cell as built differs from the plan: R2 stands 5 cm closer to R1. Where the plan
    // passes the robots by each other with little room, they now meet.
    let moved_path = crossing_cell().with_file_name("moved.toml");
    let text = std::fs::read_to_string(crossing_cell())
        .unwrap()
        .replace("xyz = [3100, -100, 0]", "xyz = [3100, -150, 0]");
    std::fs::write(&moved_path, text).unwrap();
    let moved = load(&moved_path, &LoadOptions::default()).unwrap();
    let k: Vec<ViolationKind> = verify(&moved, &good, &settings)
        .violations
        .iter()
        .map(|v| v.kind)
        .collect();
    assert!(k.contains(&ViolationKind::RobotRobot), "{k:?}");
    // A joint-limit breach.
    let mut breach = good.clone();
    let n = breach.robots[0].trajectory.len();
    breach.robots[0].trajectory[n / 2].q[0] = 10.0;
    assert!(kinds(&breach).contains(&ViolationKind::JointLimit));
    // A skipped MP.
    let mut skipped = good.clone();
    let busy = skipped.robots.iter().position(|r| !r.tasks.is_empty()).unwrap();
    skipped.robots[busy].tasks.remove(0);
    assert!(kinds(&skipped).contains(&ViolationKind::MissingTask));
    // Legs that no longer describe the motion: a via point of a sampled leg dropped, so the
    // trajectory leaves the joint path the scene was checked along.
    let mut rerouted = good.clone();
    let (r, l) = rerouted
        .robots
        .iter()
        .enumerate()
        .find_map(|(r, rp)| {
            rp.legs
                .iter()
                .position(|l| l.waypoints.len() >= 3)
                .map(|l| (r, l))
        })
        .expect("a leg with a via point");
    rerouted.robots[r].legs[l].waypoints.remove(1);
    assert!(
        kinds(&rerouted).contains(&ViolationKind::OffPath),
        "{:?}",
        kinds(&rerouted)
    );
    // A wait removed from the trajectory: the robots meet again.
    let mut hurried = good.clone();
    let (_, none) = document(Coordination::None);
    let doc_none = output::build(&f.cell, &f.table, &f.outcome, &none, &f.settings, 0.0, 0.0);
    for (r, rn) in hurried.robots.iter_mut().zip(&doc_none.robots) {
        r.trajectory = rn.trajectory.clone();
        r.total_s = rn.total_s;
    }
    hurried.cycle_time_s = doc_none.cycle_time_s;
    hurried.delta_t_s = doc_none.delta_t_s;
    assert!(kinds(&hurried).contains(&ViolationKind::RobotRobot));
}

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
    assert!(err.contains("R9"), "{err}");
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
            let arrive: f64 = m[m.len() - 2].parse().unwrap();
            assert!((arrive - v.arrive_s).abs() < 1e-3);
        }
        assert_eq!(records.iter().filter(|r| &r[1] == "wait").count(), rp.waits.len());
        assert_eq!(&records[0][1], "home");
        assert_eq!(&records[records.len() - 1][1], "home");
    }
}

/// The plan records each robot's probe track before coordination: from home to home, as long
/// as the uncoordinated program, and with the waits gone (so shorter than the plan's).
#[test]
fn the_plan_keeps_the_probe_tracks_before_coordination() {
    let f = fixture();
    let (doc, c) = document(Coordination::FixedPriority);
    let tracks = &doc.coordination.uncoordinated_probe;
    assert_eq!(tracks.len(), doc.robots.len());
    for ((tr, rp), prog) in tracks.iter().zip(&doc.robots).zip(&f.outcome.robots) {
        assert_eq!(tr.robot, rp.name);
        let robot = f.cell.robot(&rp.name).unwrap();
        let home = robot.tcp_pose(&rp.home).translation;
        for end in [tr.xyz.first().unwrap(), tr.xyz.last().unwrap()] {
            assert!((cellplan_geom::DVec3::from(*end) - home).length() < 1e-3);
        }
        let length = prog.program.duration();
        assert_eq!(tr.xyz.len(), (length / tr.dt_s).ceil() as usize + 1);
        assert!(length <= rp.total_s + 1e-9);
    }
    let waited: f64 = doc.robots.iter().map(|r| r.waiting_s).sum();
    assert!(waited > 0.0 && c.waits > 0);
}

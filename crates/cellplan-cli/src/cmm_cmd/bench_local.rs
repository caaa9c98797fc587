//! `cellplan bench cmm-local CELL`: a plan's local paths as problems for the OMPL peer.
use super::*;

/// `cellplan bench cmm-local CELL`: every root → MP path of the cell's plan as a problem for
/// the OMPL peer, with ours re-solved (straight segment, else RRT* with `samples` samples) and
/// timed; the JSON goes to stdout (docs in bench/peers/README.md).
pub fn bench_local(cell_path: &Path, samples: usize) -> Result<(), Failure> {
    use cellplan_cmm::motion::{CmmValidity, space};
    use cellplan_cmm::mrnc::{MrncSettings, local_path};
    use serde_json::json;
    let cell = load(cell_path)?;
    let req = Request {
        order: GtspMethod::Ils,
        classification: None,
        seed: 0,
        subset: None,
    };
    let out = run(&cell, &req).map_err(|e| Failure::Other(e.to_string()))?;
    let probe = cell.probe();
    let full = space(&probe, &cell.travel);
    let validity = CmmValidity {
        probe: &probe,
        margin: cell.clearance,
    };
    let s = MrncSettings {
        rrt_samples: samples,
        pretouch: cell.pretouch,
        ..MrncSettings::default()
    };
    let pose = |p: &cellplan_geom::Pose| json!({"xyz": p.translation.to_array(), "quat": [p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w]});
    let mut statics = Vec::new();
    for (k, (name, spec, p)) in cell.statics.iter().enumerate() {
        match spec {
            cellplan_geom::ShapeSpec::Mesh(_) if k == 0 => statics.push(json!({
                "name": name,
                "mesh": std::fs::canonicalize(&cell.part_file.0).unwrap_or(cell.part_file.0.clone()),
                "mesh_scale": cell.part_file.1,
                "pose": pose(p),
            })),
            cellplan_geom::ShapeSpec::Box { half_extents } => statics.push(json!({
                "name": name,
                "box": (*half_extents * 2.0).to_array(),
                "pose": pose(p),
            })),
            _ => {
                return Err(Failure::Usage(format!(
                    "cmm-local exports the part and box fixtures only; `{name}` is another shape"
                )));
            }
        }
    }
    let mut problems = Vec::new();
    for (g, group) in out.job.groups.iter().enumerate() {
        let (a, b) = group.paths.angles;
        let mut sp = full.clone();
        sp.lower[3] = a;
        sp.upper[3] = a;
        sp.lower[4] = b;
        sp.upper[4] = b;
        // Each MP from its root (the paths RRT-MRNC stores) and from the group's start (what
        // a planner without roots must solve).
        let pairs = group.members.iter().enumerate().flat_map(|(k, &mp)| {
            [("root", &group.paths.roots[k]), ("start", &group.paths.start)]
                .map(|(kind, from)| (k, mp, kind, from))
        });
        for (k, mp, kind, root) in pairs {
            let goal = &group.paths.approaches[k];
            let started = Instant::now();
            let found = local_path(&sp, &validity, root, goal, &s, k as u64);
            let time_s = started.elapsed().as_secs_f64();
            let length = |w: &[Vec<f64>]| {
                w.windows(2)
                    .map(|p| {
                        ((p[1][0] - p[0][0]).powi(2)
                            + (p[1][1] - p[0][1]).powi(2)
                            + (p[1][2] - p[0][2]).powi(2))
                        .sqrt()
                    })
                    .sum::<f64>()
            };
            let local = cellplan_cmm::mrnc::local_space(&sp, root, goal, s.local_margin);
            let (lo, hi) = (&local.lower[..3], &local.upper[..3]);
            problems.push(json!({
                "group": g,
                "mp": cell.mps[mp].name,
                "from": kind,
                "angles": [a, b],
                "start": &root[..3],
                "goal": &goal[..3],
                "bounds": {"lower": lo, "upper": hi},
                "ours": {
                    "solved": found.is_some(),
                    "length_m": found.as_ref().map(|f| length(&f.waypoints)),
                    "time_s": time_s,
                    "samples": samples,
                    "straight": found.as_ref().is_some_and(|f| f.straight),
                },
            }));
        }
    }
    let b = &cell.bodies;
    let h = &cell.head;
    let doc = json!({
        "cell": cell.name,
        "scene": {
            "statics": statics,
            "probe": {
                "l1": h.l1, "l2": h.l2, "ball_diameter": h.ball_diameter,
                "stem_diameter": b.stem_diameter, "extension_diameter": b.extension_diameter,
                "head": [b.head.0, b.head.1], "ram": [b.ram.0, b.ram.1],
            },
            "clearance": cell.clearance,
        },
        "problems": problems,
    });
    crate::print_json(&doc)
}

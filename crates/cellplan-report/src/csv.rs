//! CSV for robot post-processors. Per robot two files:
//! - `<robot>-trajectory.csv`: every trajectory sample — time, joint values, probe pose in the
//!   world (position in m, quaternion x, y, z, w), what the robot is doing and at which MP;
//! - `<robot>-program.csv`: the program as points a robot controller moves through — home, the
//!   via points of every leg (the collision-free joint path), each measuring pose with its
//!   arrival and departure, and the waits; `blend_rad` on a via point the robot passes without
//!   stopping: the blend radius (joint space, rad — the controller's zone or blend), empty
//!   where it stops.
use crate::playback::{Doing, intervals};
use crate::scene::{Scene, SceneRobot};
use cellplan_core::document::{Plan, RobotPlan};
use std::fmt::Write;

/// The files to write: `(file name, contents)`, two per robot.
pub fn files(plan: &Plan, scene: &Scene) -> Result<Vec<(String, String)>, crate::scene::Mismatch> {
    let order = scene.match_plan(plan)?;
    let mut out = Vec::new();
    for (rp, &k) in plan.robots.iter().zip(&order) {
        let sr = &scene.robots[k];
        out.push((format!("{}-trajectory.csv", safe(&rp.name)), trajectory(rp, sr)));
        out.push((format!("{}-program.csv", safe(&rp.name)), program(rp, sr)));
    }
    Ok(out)
}

/// A robot name usable as a file name.
fn safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A CSV field, quoted when needed.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The header: `first`, the joint names, the probe pose, `last`, comma-joined.
fn header(rp: &RobotPlan, first: &[&str], last: &[&str]) -> String {
    let names = first
        .iter()
        .map(|s| s.to_string())
        .chain(rp.joints.iter().map(|j| field(j)))
        .chain(["x_m", "y_m", "z_m", "qx", "qy", "qz", "qw"].map(String::from))
        .chain(last.iter().map(|s| s.to_string()));
    names.collect::<Vec<_>>().join(",") + "\n"
}

fn pose_fields(s: &mut String, sr: &SceneRobot, q: &[f64]) {
    for v in q {
        let _ = write!(s, ",{v:.6}");
    }
    let p = sr.tcp_pose(q);
    let (t, r) = (p.translation, p.rotation);
    let _ = write!(
        s,
        ",{:.5},{:.5},{:.5},{:.6},{:.6},{:.6},{:.6}",
        t.x, t.y, t.z, r.x, r.y, r.z, r.w
    );
}

fn trajectory(rp: &RobotPlan, sr: &SceneRobot) -> String {
    let iv = intervals(rp);
    let mut s = header(rp, &["t_s"], &["activity", "task"]);
    let mut k = 0;
    for sample in &rp.trajectory {
        while k + 1 < iv.len() && sample.t >= iv[k].end {
            k += 1;
        }
        let (what, task) = match iv.get(k).map(|i| i.doing) {
            Some(Doing::Measuring(v)) => ("measuring", rp.tasks[v].task.as_str()),
            Some(Doing::Waiting(_)) => ("waiting", ""),
            Some(Doing::Moving) if sample.t < rp.end_s => ("moving", ""),
            _ => ("home", ""),
        };
        let _ = write!(s, "{:.4}", sample.t);
        pose_fields(&mut s, sr, &sample.q);
        let _ = writeln!(s, ",{what},{}", field(task));
    }
    s
}

fn program(rp: &RobotPlan, sr: &SceneRobot) -> String {
    let mut s = header(
        rp,
        &["step", "kind", "name"],
        &["arrive_s", "depart_s", "blend_rad"],
    );
    let mut step = 0;
    let mut row = |s: &mut String, kind: &str, name: &str, q: &[f64], times: Option<(f64, f64)>| {
        step += 1;
        let _ = write!(s, "{step},{kind},{}", field(name));
        pose_fields(s, sr, q);
        match times {
            Some((a, d)) => {
                let _ = writeln!(s, ",{a:.4},{d:.4},");
            }
            None => s.push_str(",,,\n"),
        }
    };
    let first = rp.legs.first().map_or(0.0, |l| l.start_s);
    row(&mut s, "home", "home", &rp.home, Some((0.0, first)));
    for (k, leg) in rp.legs.iter().enumerate() {
        let name = format!("{} → {}", leg.from, leg.to);
        let last = leg.waypoints.len().saturating_sub(1);
        for (w, q) in leg.waypoints.iter().enumerate() {
            let wait = rp.waits.iter().find(|x| x.leg == k && x.waypoint == w);
            let wait_times = wait.map(|x| (x.start_s, x.start_s + x.duration_s));
            // A wait stands at its waypoint: at the leg's start (the previous stop, before the
            // motion), at a via point, or at its end.
            if w == 0
                && let Some(times) = wait_times
            {
                row(&mut s, "wait", &name, q, Some(times));
            }
            if w == last {
                match rp.tasks.get(k) {
                    Some(v) => row(&mut s, "measure", &v.task, &v.q, Some((v.arrive_s, v.depart_s))),
                    None => row(&mut s, "home", "home", q, Some((rp.end_s, rp.end_s))),
                }
            }
            if w > 0 {
                match wait_times {
                    Some(times) => row(&mut s, "wait", &name, q, Some(times)),
                    None if w < last => {
                        row(&mut s, "via", &name, q, None);
                        if let Some(b) = leg.blends.iter().find(|b| b.waypoint == w) {
                            // The row ends in ",,,\n": the radius goes in its last field.
                            s.truncate(s.len() - 1);
                            let _ = writeln!(s, "{:.6}", b.radius);
                        }
                    }
                    None => {}
                }
            }
        }
    }
    s
}

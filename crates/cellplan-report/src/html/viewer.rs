//! The data the report's 3D viewer (`viewer.js`) reads, as JSON: the meshes once each (base64
//! of little-endian f32 and u32), the statics, each robot's links and sampled trajectory with
//! its activity intervals, the tasks, the conflicts, the scene's bounds and a camera azimuth.
use super::shown_conflicts;
use crate::playback::{Doing, intervals};
use crate::scene::{Scene, SceneRobot, robot_colour};
use base64::Engine;
use cellplan_core::document::{Plan, RobotPlan};
use cellplan_geom::{DVec3, Pose};
use cellplan_model::Cell;
use serde_json::{Value, json};

fn b64<T: Copy>(values: &[T], bytes: impl Fn(T) -> [u8; 4]) -> String {
    let raw: Vec<u8> = values.iter().flat_map(|&v| bytes(v)).collect();
    base64::engine::general_purpose::STANDARD.encode(raw)
}

fn b64_f32(values: &[f32]) -> String {
    b64(values, f32::to_le_bytes)
}

fn b64_u32(values: &[u32]) -> String {
    b64(values, u32::to_le_bytes)
}

fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

/// `[x, y, z, qx, qy, qz, qw]`.
fn pose_json(p: &Pose) -> Value {
    let (t, q) = (p.translation, p.rotation);
    json!([t.x, t.y, t.z, q.x, q.y, q.z, q.w].map(round6))
}

/// The smallest box around everything the viewer draws: robot bases, probe paths and MPs.
struct Bounds {
    lo: DVec3,
    hi: DVec3,
}

impl Bounds {
    fn new() -> Self {
        Bounds {
            lo: DVec3::splat(f64::INFINITY),
            hi: DVec3::splat(f64::NEG_INFINITY),
        }
    }

    fn grow(&mut self, p: DVec3) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    /// `[lo, hi]` with a margin of 0.3 m, down to the floor (or a 2 m box when empty).
    fn json(&self) -> Value {
        let (mut lo, mut hi) = (self.lo, self.hi);
        if !lo.is_finite() {
            (lo, hi) = (DVec3::splat(-1.0), DVec3::splat(1.0));
        }
        lo = lo.min(DVec3::new(lo.x, lo.y, 0.0)) - DVec3::splat(0.3);
        hi += DVec3::splat(0.3);
        json!([[lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]])
    }
}

/// The data the viewer script reads: meshes, robots with their samples, MPs, conflicts, the
/// bounds of the scene and where to look from.
pub(super) fn viewer_data(
    plan: &Plan,
    cell: &Cell,
    scene: &Scene,
    order: &[usize],
    tracks: &[Vec<(f64, [f64; 3])>],
    t_end: f64,
) -> Value {
    let mut bounds = Bounds::new();
    let robots: Vec<Value> = plan
        .robots
        .iter()
        .zip(order)
        .enumerate()
        .map(|(r, (rp, &k))| robot_json(plan, r, rp, &scene.robots[k], &tracks[r], &mut bounds))
        .collect();
    let tasks = tasks_json(plan, cell, &mut bounds);
    let conflicts: Vec<Value> = shown_conflicts(plan)
        .iter()
        .map(|c| json!({"robots": c.robots, "start": c.start_s, "end": c.end_s, "p": c.probe_xyz}))
        .collect();
    json!({
        "t_end": t_end,
        "cycle": plan.cycle_time_s,
        "geometries": geometries_json(scene),
        "statics": statics_json(scene),
        "robots": robots,
        "tasks": tasks,
        "conflicts": conflicts,
        "bounds": bounds.json(),
        "camera_azimuth": camera_azimuth(cell),
    })
}

/// Every distinct mesh: positions and indices as base64 of little-endian f32 and u32.
fn geometries_json(scene: &Scene) -> Vec<Value> {
    scene
        .geometries
        .iter()
        .map(|g| {
            let flat: Vec<f32> = g.positions.iter().flatten().copied().collect();
            json!({"p": b64_f32(&flat), "i": b64_u32(&g.indices)})
        })
        .collect()
}

/// The part and fixtures: mesh, pose and colour.
fn statics_json(scene: &Scene) -> Vec<Value> {
    scene
        .statics
        .iter()
        .map(|s| json!({"name": s.name, "g": s.placed.geometry, "pose": pose_json(&s.placed.pose), "colour": s.colour}))
        .collect()
}

/// One robot for the viewer: its chain, samples (times and joints), probe path now and before
/// coordination, and what it does when.
fn robot_json(
    plan: &Plan,
    r: usize,
    rp: &RobotPlan,
    sr: &SceneRobot,
    track: &[(f64, [f64; 3])],
    bounds: &mut Bounds,
) -> Value {
    bounds.grow(sr.base.translation);
    let times: Vec<f32> = rp.trajectory.iter().map(|s| s.t as f32).collect();
    let q: Vec<f32> = rp
        .trajectory
        .iter()
        .flat_map(|s| s.q.iter().map(|&v| v as f32))
        .collect();
    let path: Vec<f32> = track
        .iter()
        .flat_map(|(_, p)| {
            bounds.grow(DVec3::from(*p));
            p.map(|v| v as f32)
        })
        .collect();
    let before: Vec<f32> = plan
        .coordination
        .uncoordinated_probe
        .iter()
        .find(|b| b.robot == rp.name)
        .map(|b| b.xyz.iter().flat_map(|p| p.map(|v| v as f32)).collect())
        .unwrap_or_default();
    json!({
        "name": rp.name,
        "colour": robot_colour(r),
        "base": pose_json(&sr.base),
        "tcp": pose_json(&sr.tcp),
        "links": links_json(sr),
        "dof": rp.joints.len(),
        "t": b64_f32(&times),
        "q": b64_f32(&q),
        "path": b64_f32(&path),
        "before": b64_f32(&before),
        "intervals": intervals_json(rp),
    })
}

/// A robot's links: origin, joint (index, axis, kind) and the meshes drawn on it.
fn links_json(sr: &SceneRobot) -> Vec<Value> {
    sr.parts
        .iter()
        .enumerate()
        .map(|(i, parts)| {
            let joint = sr.joint_of(i);
            let axis = joint.map_or(DVec3::Z, |(_, jt)| jt.axis);
            json!({
                "o": pose_json(&sr.model.chain.links[i].origin),
                "j": joint.map_or(-1, |(j, _)| j as i64),
                "axis": [axis.x, axis.y, axis.z],
                "prismatic": joint.is_some_and(|(_, jt)| !jt.is_rotational()),
                "parts": parts.iter().map(|p| json!({"g": p.geometry, "pose": pose_json(&p.pose)})).collect::<Vec<_>>(),
            })
        })
        .collect()
}

/// A robot's intervals as `[start, end, what it does]`.
fn intervals_json(rp: &RobotPlan) -> Vec<Value> {
    intervals(rp)
        .iter()
        .map(|i| {
            let what = match i.doing {
                Doing::Moving => "moving".to_string(),
                Doing::Measuring(v) => format!("measuring {}", rp.tasks[v].task),
                Doing::Waiting(w) => format!(
                    "waiting{}",
                    rp.waits[w]
                        .for_robot
                        .as_deref()
                        .map(|f| format!(" for {f}"))
                        .unwrap_or_default()
                ),
            };
            json!([round6(i.start), round6(i.end), what])
        })
        .collect()
}

/// The cell's MPs: position, normal and the robot that measures each (-1: none).
fn tasks_json(plan: &Plan, cell: &Cell, bounds: &mut Bounds) -> Vec<Value> {
    let robot_of = |name: &str| {
        plan.robots
            .iter()
            .position(|rp| rp.tasks.iter().any(|v| v.task == name))
            .map_or(-1, |r| r as i64)
    };
    cell.tasks
        .iter()
        .map(|t| {
            bounds.grow(t.position);
            let p = [t.position.x, t.position.y, t.position.z].map(round6);
            let n = [t.normal.x, t.normal.y, t.normal.z].map(round6);
            json!({
                "name": t.name,
                "p": p,
                "n": n,
                "r": robot_of(&t.name),
            })
        })
        .collect()
}

/// The camera's azimuth: look from the robots' side of the MPs, a little from the front.
fn camera_azimuth(cell: &Cell) -> f64 {
    let centroid = |v: &mut dyn Iterator<Item = DVec3>| {
        let (s, n) = v.fold((DVec3::ZERO, 0usize), |(s, n), p| (s + p, n + 1));
        s / n.max(1) as f64
    };
    let from = centroid(&mut cell.robots.iter().map(|r| r.base.translation))
        - centroid(&mut cell.tasks.iter().map(|t| t.position));
    if from.x.hypot(from.y) > 1e-6 {
        from.y.atan2(from.x) - 0.55
    } else {
        0.8
    }
}

//! The independent check of a CMM-inspection plan (paper 003), from the plan document and the
//! cell alone — none of the planner's probe model, clearance function or segment check is used:
//!
//! - the path starts and ends at the cell's home; every configuration lies within the travel
//!   and the head's angle ranges (on the index grid of an indexing head);
//! - every segment of the path — a straight move of the head centre with the angles turning
//!   linearly — keeps the whole probe (ball, stylus, extension, head, ram) the cell's clearance
//!   away from the part and the fixtures. The check is conservative between samples: on a
//!   segment no point of the probe moves farther than `|Δp| + ρ(|Δa| + |Δb|)` (ρ the ball's
//!   far side from the A-axis centre), so a piece whose two ends are clear by more than that
//!   together is clear throughout; other pieces are halved until they are, or until a contact
//!   is pinned down;
//! - every touch: the ball stands at the MP plus (ball radius + pretouch) along its normal, the
//!   probe's axis within θ of the normal, and the stroke to the surface and back keeps the probe
//!   (less its ball end) the touch clearance away;
//! - the MPs touched are the plan's `tasks`, each once; a whole plan measures every MP of the
//!   cell or says why not;
//! - the stored paths every reuse relies on are clear: each group's start to each root, every
//!   root to every other, each root's path to its MP, the way up from each start; the turn
//!   height lies above the part by the probe's reach;
//! - movement, rotation, inspection and motion time are recomputed.
use crate::motion::{box_gap, exact_shape};
use cellplan_cmm::cell::CmmCell;
use cellplan_cmm::document::{CmmPlan, Strategy};
use cellplan_geom::{DQuat, DVec3, Pose, ShapeSpec};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::query;
use parry3d_f64::shape::SharedShape;
use serde::Serialize;
use std::collections::HashSet;

/// Position tolerance (m).
const POS_TOL: f64 = 1e-6;
/// Angle tolerance (rad).
const ANGLE_TOL: f64 = 1e-9;
/// Relative tolerance of the stated times.
const TIME_TOL: f64 = 1e-6;
/// Distances beyond this are not needed exactly (m).
const CAP: f64 = 1.0;

/// What went wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CmmViolationKind {
    /// The document does not match the cell.
    Format,
    /// A configuration outside the travel or the head's ranges or grid.
    Range,
    /// The probe closer than the clearance to the part or a fixture.
    Collision,
    /// A touch in the wrong place, outside the MP's cone, or whose stroke collides.
    Touch,
    /// An MP touched twice, not listed, or neither measured nor reported.
    Task,
    /// A stored path (for reuse) that collides or does not join up.
    Stored,
    /// A stated time the check does not reproduce.
    Total,
}

/// One violation.
#[derive(Clone, Debug, Serialize)]
pub struct CmmViolation {
    /// What.
    pub kind: CmmViolationKind,
    /// The path segment (or waypoint), where it applies.
    pub at: Option<usize>,
    /// The MP, where it applies.
    pub mp: Option<String>,
    /// A sentence.
    pub detail: String,
}

/// The verdict.
#[derive(Clone, Debug, Serialize)]
pub struct CmmReport {
    /// No violation.
    pub ok: bool,
    /// Every violation.
    pub violations: Vec<CmmViolation>,
    /// Recomputed movement time (s).
    pub movement_s: f64,
    /// Recomputed rotation time (s).
    pub rotation_s: f64,
    /// Recomputed inspection time (s).
    pub inspection_s: f64,
    /// Recomputed motion time (s).
    pub motion_time_s: f64,
    /// Smallest probe distance found at a sample of the path (m).
    pub closest_m: f64,
    /// Configurations whose distance was measured.
    pub samples: usize,
    /// MPs touched.
    pub touched: usize,
}

/// A rigid body of the probe: its shape, its pose relative to the head frame (the A-axis
/// centre, z along the probe), and whether it turns with the head.
struct Body {
    shape: SharedShape,
    /// Pose in the probe frame (turning bodies) or the ram frame (the others).
    local: Pose,
    turns: bool,
}

struct Obstacle {
    shape: SharedShape,
    pose: Pose,
    aabb: Aabb,
}

/// The probe and the scene, built here from the cell's numbers.
struct Scene {
    moving: Vec<Body>,
    touching: Vec<Body>,
    obstacles: Vec<Obstacle>,
    /// Farthest point of a turning body from the A-axis centre (m).
    rho: f64,
    reach: f64,
}

fn cylinder_spec(diameter: f64, length: f64) -> ShapeSpec {
    ShapeSpec::Cylinder {
        radius: diameter / 2.0,
        half_height: length / 2.0,
    }
}

impl Scene {
    fn new(cell: &CmmCell) -> Option<Self> {
        let h = &cell.head;
        let b = &cell.bodies;
        let reach = h.l1 + h.l2;
        let make = |spec: ShapeSpec, at: Pose, turns: bool| -> Option<Body> {
            let (shape, local) = exact_shape(&spec)?;
            Some(Body {
                shape,
                local: at * local,
                turns,
            })
        };
        let along = |from: f64, to: f64| Pose::from_translation(DVec3::Z * (0.5 * (from + to)));
        let fixed = |spec: ShapeSpec, z: f64| make(spec, Pose::from_translation(DVec3::Z * z), false);
        let head = fixed(cylinder_spec(b.head.0, b.head.1), b.head.1 / 2.0)?;
        let ram = fixed(
            ShapeSpec::Box {
                half_extents: DVec3::new(b.ram.0 / 2.0, b.ram.0 / 2.0, b.ram.1 / 2.0),
            },
            b.head.1 + b.ram.1 / 2.0,
        )?;
        let moving = vec![
            make(
                ShapeSpec::Sphere {
                    radius: h.ball_diameter / 2.0,
                },
                Pose::from_translation(DVec3::Z * reach),
                true,
            )?,
            make(cylinder_spec(b.stem_diameter, h.l2), along(h.l1, reach), true)?,
            make(cylinder_spec(b.extension_diameter, h.l1), along(0.0, h.l1), true)?,
            fixed(cylinder_spec(b.head.0, b.head.1), b.head.1 / 2.0)?,
            fixed(
                ShapeSpec::Box {
                    half_extents: DVec3::new(b.ram.0 / 2.0, b.ram.0 / 2.0, b.ram.1 / 2.0),
                },
                b.head.1 + b.ram.1 / 2.0,
            )?,
        ];
        let stem_end = reach - b.stem_start;
        let touching = vec![
            make(
                cylinder_spec(b.stem_diameter, stem_end - h.l1),
                along(h.l1, stem_end),
                true,
            )?,
            make(cylinder_spec(b.extension_diameter, h.l1), along(0.0, h.l1), true)?,
            head,
            ram,
        ];
        let obstacles = cell
            .statics
            .iter()
            .filter_map(|(_, spec, pose)| {
                let (shape, local) = exact_shape(spec)?;
                let pose = *pose * local;
                Some(Obstacle {
                    aabb: shape.compute_aabb(&pose),
                    shape,
                    pose,
                })
            })
            .collect();
        let rho = reach + h.ball_diameter / 2.0;
        Some(Scene {
            moving,
            touching,
            obstacles,
            rho,
            reach,
        })
    }

    /// The distance of `bodies` at configuration `q` to the obstacles (capped at [`CAP`]).
    fn distance(&self, bodies: &[Body], q: &[f64; 5]) -> f64 {
        let centre = DVec3::new(q[0], q[1], q[2]);
        let turn = DQuat::from_rotation_arc(DVec3::Z, direction(q[3], q[4]));
        let probe = Pose::from_parts(centre, turn);
        let ram = Pose::from_translation(centre);
        let mut best = CAP;
        for body in bodies {
            let pose = if body.turns { probe } else { ram } * body.local;
            let aabb = body.shape.compute_aabb(&pose);
            for o in &self.obstacles {
                if box_gap(&aabb, &o.aabb) >= best {
                    continue;
                }
                // A pair parry cannot measure counts as touching: no blind pass.
                let d = query::distance(&pose, body.shape.as_ref(), &o.pose, o.shape.as_ref())
                    .map_or(0.0, |d| d.distance.max(0.0));
                best = best.min(d);
            }
        }
        best
    }
}

/// The probe's direction at head angles (a, b): straight down at a = 0, tilted toward +X at
/// b = 0.
fn direction(a: f64, b: f64) -> DVec3 {
    DVec3::new(a.sin() * b.cos(), a.sin() * b.sin(), -a.cos())
}

fn lerp(a: &[f64; 5], b: &[f64; 5], t: f64) -> [f64; 5] {
    std::array::from_fn(|j| a[j] + t * (b[j] - a[j]))
}

/// Checks a segment conservatively: `Err(t)` at the first parameter where the bodies come
/// within `clearance`. Adds the distances measured to `stats` (samples, closest).
fn segment(
    scene: &Scene,
    bodies: &[Body],
    a: &[f64; 5],
    b: &[f64; 5],
    clearance: f64,
    stats: &mut (usize, f64),
) -> Result<(), f64> {
    let linear = DVec3::new(b[0] - a[0], b[1] - a[1], b[2] - a[2]).length();
    let angular = (b[3] - a[3]).abs() + (b[4] - a[4]).abs();
    let length = linear + scene.rho * angular;
    let mut measure = |t: f64| {
        let d = scene.distance(bodies, &lerp(a, b, t));
        stats.0 += 1;
        stats.1 = stats.1.min(d);
        d - clearance
    };
    let d0 = measure(0.0);
    if d0 <= 0.0 {
        return Err(0.0);
    }
    let d1 = measure(1.0);
    if d1 <= 0.0 {
        return Err(1.0);
    }
    // Pieces to show clear, depth first from the start.
    let mut stack = vec![(0.0f64, 1.0f64, d0, d1)];
    while let Some((t0, t1, e0, e1)) = stack.pop() {
        if e0 + e1 >= length * (t1 - t0) {
            continue;
        }
        if (t1 - t0) * length < 1e-9 {
            return Err(t0);
        }
        let tm = 0.5 * (t0 + t1);
        let em = measure(tm);
        if em <= 0.0 {
            return Err(tm);
        }
        stack.push((tm, t1, em, e1));
        stack.push((t0, tm, e0, em));
    }
    Ok(())
}

/// Trapezoid or constant-speed time of a move of `d` (m or rad).
fn profile(d: f64, speed: f64, acceleration: Option<f64>) -> f64 {
    let d = d.abs();
    match acceleration {
        None => d / speed,
        Some(a) if d * a >= speed * speed => d / speed + speed / a,
        Some(a) => 2.0 * (d / a).sqrt(),
    }
}

fn close(stated: f64, derived: f64) -> bool {
    (stated - derived).abs() <= TIME_TOL * derived.abs().max(1.0)
}

fn push(
    v: &mut Vec<CmmViolation>,
    kind: CmmViolationKind,
    at: Option<usize>,
    mp: Option<&str>,
    detail: String,
) {
    v.push(CmmViolation {
        kind,
        at,
        mp: mp.map(str::to_string),
        detail,
    });
}

/// Verifies a CMM plan against its cell.
pub fn verify_cmm(cell: &CmmCell, plan: &CmmPlan) -> CmmReport {
    let mut v: Vec<CmmViolation> = Vec::new();
    let mut report = CmmReport {
        ok: false,
        violations: Vec::new(),
        movement_s: 0.0,
        rotation_s: 0.0,
        inspection_s: 0.0,
        motion_time_s: 0.0,
        closest_m: CAP,
        samples: 0,
        touched: 0,
    };
    let Some(scene) = Scene::new(cell) else {
        push(
            &mut v,
            CmmViolationKind::Format,
            None,
            None,
            "the cell's probe or part has a degenerate shape".into(),
        );
        report.violations = v;
        return report;
    };
    if plan.process != cellplan_cmm::cell::KIND || plan.cell != cell.name {
        push(
            &mut v,
            CmmViolationKind::Format,
            None,
            None,
            format!(
                "a plan of `{}` ({}) checked against cell `{}`",
                plan.cell, plan.process, cell.name
            ),
        );
    }
    let h = &cell.head;
    let t = &cell.travel;
    // Ranges.
    let in_range = |q: &[f64; 5]| -> Option<String> {
        if q.iter().any(|x| !x.is_finite()) {
            return Some("a coordinate is not a finite number".into());
        }
        let lin = [t.x, t.y, t.z];
        for j in 0..3 {
            if q[j] < lin[j][0] - POS_TOL || q[j] > lin[j][1] + POS_TOL {
                return Some(format!(
                    "{} = {:.4} m is outside the travel",
                    ["x", "y", "z"][j],
                    q[j]
                ));
            }
        }
        if q[3] < h.a_range[0] - ANGLE_TOL || q[3] > h.a_range[1] + ANGLE_TOL {
            return Some(format!(
                "A = {:.3}° is outside the head's range",
                q[3].to_degrees()
            ));
        }
        if q[4] < h.b_range[0] - ANGLE_TOL || q[4] > h.b_range[1] + ANGLE_TOL {
            return Some(format!(
                "B = {:.3}° is outside the head's range",
                q[4].to_degrees()
            ));
        }
        if let Some(s) = h.index_step {
            for (name, x) in [("A", q[3]), ("B", q[4])] {
                if ((x / s).round() * s - x).abs() > 1e-7 {
                    return Some(format!(
                        "{name} = {:.4}° is not on the head's {:.2}° index grid",
                        x.to_degrees(),
                        s.to_degrees()
                    ));
                }
            }
        }
        None
    };
    let path: Vec<[f64; 5]> = plan.path.iter().map(|w| w.q).collect();
    if path.is_empty() {
        push(
            &mut v,
            CmmViolationKind::Format,
            None,
            None,
            "the path is empty".into(),
        );
    }
    let home = cell.home;
    let at_home = |q: &[f64; 5]| q.iter().zip(&home).all(|(a, b)| (a - b).abs() <= POS_TOL);
    if plan.home != home {
        push(
            &mut v,
            CmmViolationKind::Format,
            None,
            None,
            "`home` is not the cell's home".into(),
        );
    }
    if !path.first().is_some_and(at_home) || !path.last().is_some_and(at_home) {
        push(
            &mut v,
            CmmViolationKind::Format,
            None,
            None,
            "the path must start and end at the cell's home".into(),
        );
    }
    for (i, q) in path.iter().enumerate() {
        if let Some(why) = in_range(q) {
            push(
                &mut v,
                CmmViolationKind::Range,
                Some(i),
                None,
                format!("waypoint {i}: {why}"),
            );
        }
    }
    // Segments.
    let mut stats = (0usize, CAP);
    let ranges_ok = !v.iter().any(|x| x.kind == CmmViolationKind::Range);
    if ranges_ok {
        for (i, w) in path.windows(2).enumerate() {
            if let Err(t) = segment(&scene, &scene.moving, &w[0], &w[1], cell.clearance, &mut stats) {
                push(
                    &mut v,
                    CmmViolationKind::Collision,
                    Some(i),
                    None,
                    format!(
                        "segment {i} (waypoints {i}–{}): the probe comes within {:.1} mm of the part or a fixture at {:.3} of it",
                        i + 1,
                        cell.clearance * 1e3,
                        t
                    ),
                );
            }
        }
    }
    // Touches.
    let r = h.ball_diameter / 2.0;
    let mut touched: Vec<&str> = Vec::new();
    let mut seen = HashSet::new();
    for (i, w) in plan.path.iter().enumerate() {
        let Some(id) = &w.touch else { continue };
        touched.push(id);
        if !seen.insert(id.as_str()) {
            push(
                &mut v,
                CmmViolationKind::Task,
                Some(i),
                Some(id),
                format!("MP {id} is touched twice"),
            );
            continue;
        }
        let Some(k) = cell.mp(id) else {
            push(
                &mut v,
                CmmViolationKind::Task,
                Some(i),
                Some(id),
                format!("MP {id} is not in the cell"),
            );
            continue;
        };
        let mp = &cell.mps[k];
        let q = w.q;
        let d = direction(q[3], q[4]);
        let ball = DVec3::new(q[0], q[1], q[2]) + d * scene.reach;
        let want = mp.position + mp.normal * (r + cell.pretouch);
        if (ball - want).length() > POS_TOL {
            push(
                &mut v,
                CmmViolationKind::Touch,
                Some(i),
                Some(id),
                format!(
                    "the ball stands {:.4} mm from MP {id}'s approach point ({:.1} mm off the surface along the normal)",
                    (ball - want).length() * 1e3,
                    (r + cell.pretouch) * 1e3
                ),
            );
            continue;
        }
        let angle = (-d).dot(mp.normal).clamp(-1.0, 1.0).acos();
        if angle > mp.theta_deg.to_radians() + 1e-9 {
            push(
                &mut v,
                CmmViolationKind::Touch,
                Some(i),
                Some(id),
                format!(
                    "the probe's axis is {:.2}° from MP {id}'s normal, its cone allows {}°",
                    angle.to_degrees(),
                    mp.theta_deg
                ),
            );
        }
        let back = mp.normal * cell.pretouch;
        let touch = [q[0] - back.x, q[1] - back.y, q[2] - back.z, q[3], q[4]];
        let mut s2 = (0usize, CAP);
        if segment(&scene, &scene.touching, &q, &touch, cell.touch_clearance, &mut s2).is_err() {
            push(
                &mut v,
                CmmViolationKind::Touch,
                Some(i),
                Some(id),
                format!(
                    "touching MP {id}, the probe (less its ball end) comes within {:.1} mm of the part",
                    cell.touch_clearance * 1e3
                ),
            );
        }
        stats.0 += s2.0;
    }
    report.touched = touched.len();
    if touched != plan.tasks.iter().map(String::as_str).collect::<Vec<_>>() {
        push(
            &mut v,
            CmmViolationKind::Task,
            None,
            None,
            "`tasks` is not the list of MPs touched along the path, in order".into(),
        );
    }
    let mut unmeasured = HashSet::new();
    for u in &plan.unmeasured {
        if cell.mp(&u.id).is_none() || seen.contains(u.id.as_str()) || !unmeasured.insert(u.id.as_str()) {
            push(
                &mut v,
                CmmViolationKind::Task,
                None,
                Some(&u.id),
                format!(
                    "MP {} is reported unmeasured but is unknown, touched or reported twice",
                    u.id
                ),
            );
        }
    }
    if plan.strategy == Strategy::Plan {
        for m in &cell.mps {
            if !seen.contains(m.name.as_str()) && !unmeasured.contains(m.name.as_str()) {
                push(
                    &mut v,
                    CmmViolationKind::Task,
                    None,
                    Some(&m.name),
                    format!("MP {} is neither measured nor reported unmeasured", m.name),
                );
            }
        }
    }
    // The stored paths.
    let top = scene
        .obstacles
        .iter()
        .map(|o| o.aabb.maxs.z)
        .fold(f64::NEG_INFINITY, f64::max);
    if plan.turn_height_m - scene.rho - cell.clearance <= top {
        push(
            &mut v,
            CmmViolationKind::Stored,
            None,
            None,
            format!(
                "the turn height {:.1} mm is not above the part ({:.1} mm) by the probe's reach and the clearance",
                plan.turn_height_m * 1e3,
                top * 1e3
            ),
        );
    }
    let mut stored = |what: String, a: &[f64; 5], b: &[f64; 5], v: &mut Vec<CmmViolation>| {
        if in_range(a).is_some() || in_range(b).is_some() {
            v.push(CmmViolation {
                kind: CmmViolationKind::Stored,
                at: None,
                mp: None,
                detail: format!("{what}: a configuration outside the machine's ranges"),
            });
        } else if segment(&scene, &scene.moving, a, b, cell.clearance, &mut stats).is_err() {
            v.push(CmmViolation {
                kind: CmmViolationKind::Stored,
                at: None,
                mp: None,
                detail: format!("{what} is not clear"),
            });
        }
    };
    for (g, group) in plan.groups.iter().enumerate() {
        let n = group.mps.len();
        if group.roots.len() != n || group.local.len() != n {
            v.push(CmmViolation {
                kind: CmmViolationKind::Stored,
                at: None,
                mp: None,
                detail: format!("group {g}: as many roots and local paths as MPs are needed"),
            });
            continue;
        }
        let angles = [group.angles_deg[0].to_radians(), group.angles_deg[1].to_radians()];
        let all = std::iter::once(&group.start)
            .chain(&group.roots)
            .chain(group.local.iter().flatten());
        if all
            .into_iter()
            .any(|q| (q[3] - angles[0]).abs() > 1e-9 || (q[4] - angles[1]).abs() > 1e-9)
        {
            v.push(CmmViolation {
                kind: CmmViolationKind::Stored,
                at: None,
                mp: None,
                detail: format!("group {g}: a stored configuration is not at the group's head angles"),
            });
        }
        let mut up = group.start;
        up[2] = up[2].max(plan.turn_height_m);
        stored(
            format!("group {g}: the way up from its start"),
            &group.start,
            &up,
            &mut v,
        );
        for k in 0..n {
            stored(
                format!("group {g}: start → root of {}", group.mps[k]),
                &group.start,
                &group.roots[k],
                &mut v,
            );
            for k2 in k + 1..n {
                stored(
                    format!("group {g}: root of {} → root of {}", group.mps[k], group.mps[k2]),
                    &group.roots[k],
                    &group.roots[k2],
                    &mut v,
                );
            }
            let local = &group.local[k];
            if local.first() != Some(&group.roots[k]) {
                v.push(CmmViolation {
                    kind: CmmViolationKind::Stored,
                    at: None,
                    mp: Some(group.mps[k].clone()),
                    detail: format!(
                        "group {g}: the path to {} does not start at its root",
                        group.mps[k]
                    ),
                });
            }
            for w in local.windows(2) {
                stored(
                    format!("group {g}: the path from its root to {}", group.mps[k]),
                    &w[0],
                    &w[1],
                    &mut v,
                );
            }
        }
    }
    // Times.
    let sp = &cell.speeds;
    let (mut movement, mut rotation) = (0.0, 0.0);
    for w in path.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        let lin = DVec3::new(b[0] - a[0], b[1] - a[1], b[2] - a[2]).length();
        let ang = (b[3] - a[3]).abs().max((b[4] - a[4]).abs());
        movement += profile(lin, sp.movement, sp.acceleration.map(|x| x.0));
        rotation += profile(ang, sp.rotation, sp.acceleration.map(|x| x.1));
    }
    let inspection = touched.len() as f64 * cell.inspection_s;
    let motion = movement + rotation + inspection;
    for (name, stated, derived) in [
        ("movement_s", plan.movement_s, movement),
        ("rotation_s", plan.rotation_s, rotation),
        ("inspection_s", plan.inspection_s, inspection),
        ("motion_time_s", plan.motion_time_s, motion),
    ] {
        if !close(stated, derived) {
            v.push(CmmViolation {
                kind: CmmViolationKind::Total,
                at: None,
                mp: None,
                detail: format!("`{name}` states {stated:.6} s, the path takes {derived:.6} s"),
            });
        }
    }
    report.movement_s = movement;
    report.rotation_s = rotation;
    report.inspection_s = inspection;
    report.motion_time_s = motion;
    report.samples = stats.0;
    report.closest_m = stats.1;
    report.ok = v.is_empty();
    report.violations = v;
    report
}

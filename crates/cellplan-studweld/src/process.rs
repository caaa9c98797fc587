//! The `stud-weld` process (paper 002): its `[process]` table, the gun poses of a stud (the gun's
//! axis along the stud's normal, turned about it in steps), and the work at a stud (holding the
//! pose for the weld time).
use cellplan_geom::{CollisionWorld, DQuat, DVec3, Pose};
use cellplan_model::{
    Figure, InputError, Process, ProcessInput, ProcessReason, Robot, Task, TaskId, Words, Work,
};
pub use cellplan_ocp::problem::Weights;
use serde::Deserialize;
use std::sync::Arc;

/// The `[process] kind` of stud-weld cells.
pub const KIND: &str = "stud-weld";

/// How far (m) the gun's TCP may be from the stud, and (rad) its axis from the stud's normal, in
/// a weld pose: the alternatives keep only poses within it and the verifier checks it. The
/// numeric IK stops within 1e-6 m and 1e-6 rad at the flange, so a TCP a lever `L` beyond the
/// flange misses by up to 1e-6·(1 + L) m; 10 µm and 10 µrad hold that for any gun shorter than
/// 9 m, and are far below a stud gun's accuracy (tenths of a millimetre).
pub const WELD_POSE_TOLERANCE: (f64, f64) = (1e-5, 1e-5);

/// Whether `tcp` welds at `position` along `-normal`, within [`WELD_POSE_TOLERANCE`]; the
/// distance and the angle either way.
pub fn weld_pose_error(tcp: &Pose, position: DVec3, normal: DVec3) -> (bool, f64, f64) {
    let off = (tcp.translation - position).length();
    let tilt = (tcp.rotation * DVec3::Z).angle_between(-normal.normalize());
    let ok = off <= WELD_POSE_TOLERANCE.0 && !tilt.is_nan() && tilt <= WELD_POSE_TOLERANCE.1;
    (ok, off, tilt)
}

/// Most gun rotations about the stud axis (a step of 1° gives 360).
pub const MAX_ROTATIONS: usize = 360;

/// The `[process]` table as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StudWeldSpec {
    /// Seconds the gun stands at a stud.
    weld_time: f64,
    /// c_t, c_e, c_v.
    #[serde(default)]
    cost: Option<CostSpec>,
    /// Step of the gun's rotation about the stud axis (file angle unit).
    gun_rotation_step: f64,
    /// Torque limit of every joint (N·m).
    max_torque: Vec<f64>,
    /// DMOC steps of one move (default 12).
    #[serde(default)]
    steps: Option<usize>,
    /// Most optimal-control problems one plan may solve (default 1500).
    #[serde(default)]
    ocp_budget: Option<usize>,
    /// Mass of the gun (kg, default 0), carried by the tip link.
    #[serde(default)]
    gun_mass: Option<f64>,
    /// The gun's centre of mass in the tip-link frame (file length unit).
    #[serde(default)]
    gun_com: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CostSpec {
    time: Option<f64>,
    effort: Option<f64>,
    velocity: Option<f64>,
}

/// The stud-weld process, in SI.
#[derive(Clone, Debug)]
pub struct StudWeld {
    /// Seconds the gun stands at each stud.
    pub weld_time: f64,
    /// The cost J = ∫ c_t + c_e uᵀu + c_v q̇ᵀq̇ dt.
    pub weights: Weights,
    /// Step of the gun's rotation about the stud axis (rad).
    pub rotation_step: f64,
    /// Torque limits (N·m), one per joint.
    pub max_torque: Vec<f64>,
    /// The cell file's line of `max_torque` (`None`: not known).
    pub max_torque_line: Option<usize>,
    /// DMOC steps per move.
    pub steps: usize,
    /// Most optimal-control problems one plan solves.
    pub ocp_budget: usize,
    /// Mass of the gun (kg) and its centre of mass in the tip-link frame (m).
    pub gun_mass: f64,
    /// See `gun_mass`.
    pub gun_com: DVec3,
}

static WORDS: Words = Words {
    task: "stud",
    tasks: "studs",
    working: "welding",
    tool: "gun",
};

fn positive(input: &ProcessInput, key: &str, v: f64) -> Result<f64, InputError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(input.error(
            key,
            format!("`{key}` must be positive, not {}", cellplan_model::shown(v)),
        ))
    }
}

/// `v` where it is positive and at most `most` (`unit`, with its leading space, or empty), else
/// an error at `key`.
fn within(input: &ProcessInput, key: &str, v: f64, most: f64, unit: &str) -> Result<f64, InputError> {
    let v = positive(input, key, v)?;
    if v > most {
        return Err(input.error(
            key,
            format!(
                "`{key}` of {}{unit} is beyond {}{unit}",
                cellplan_model::shown(v),
                cellplan_model::shown(most)
            ),
        ));
    }
    Ok(v)
}

/// Longest weld (s): an hour, as the CMM's longest inspection.
pub const MAX_WELD_TIME: f64 = 3600.0;

/// Largest torque limit (N·m): ten times the largest industrial robots' base axes.
pub const MAX_TORQUE: f64 = 1e6;

/// Heaviest gun (kg): beyond the payload of any industrial robot.
pub const MAX_GUN_MASS: f64 = 10_000.0;

/// Largest cost weight: the weights scale time (s), effort (N²·m²·s) and speed (rad²/s) into
/// one cost; beyond this one term swamps the others to rounding.
pub const MAX_WEIGHT: f64 = 1e9;

/// Builds the process from its `[process]` table.
pub fn build(input: &ProcessInput) -> Result<Arc<dyn Process>, InputError> {
    let s: StudWeldSpec = input.parse()?;
    let weld_time = within(input, "weld_time", s.weld_time, MAX_WELD_TIME, " s")?;
    let d = Weights::default();
    let weights = match &s.cost {
        None => d,
        Some(c) => Weights {
            time: within(input, "time", c.time.unwrap_or(d.time), MAX_WEIGHT, "")?,
            effort: within(input, "effort", c.effort.unwrap_or(d.effort), MAX_WEIGHT, "")?,
            velocity: within(
                input,
                "velocity",
                c.velocity.unwrap_or(d.velocity),
                MAX_WEIGHT,
                "",
            )?,
        },
    };
    let rotation_step = positive(input, "gun_rotation_step", s.gun_rotation_step)? * input.to_rad;
    if (std::f64::consts::TAU / rotation_step).ceil() as usize > MAX_ROTATIONS {
        return Err(input.error(
            "gun_rotation_step",
            format!("`gun_rotation_step` gives more than {MAX_ROTATIONS} rotations"),
        ));
    }
    for &t in &s.max_torque {
        within(input, "max_torque", t, MAX_TORQUE, " N·m")?;
    }
    if s.max_torque.is_empty() {
        return Err(input
            .error("max_torque", "`max_torque` lists no joint")
            .hint("one torque limit (N·m) per joint of the robot"));
    }
    let steps = s.steps.unwrap_or(12);
    if !(2..=200).contains(&steps) {
        return Err(input.error("steps", format!("`steps` must be 2 to 200, not {steps}")));
    }
    let ocp_budget = s.ocp_budget.unwrap_or(1500);
    let gun_mass = s.gun_mass.unwrap_or(0.0);
    if !(gun_mass.is_finite() && (0.0..=MAX_GUN_MASS).contains(&gun_mass)) {
        return Err(input.error(
            "gun_mass",
            format!(
                "`gun_mass` must be 0 to {} kg, not {}",
                cellplan_model::shown(MAX_GUN_MASS),
                cellplan_model::shown(gun_mass)
            ),
        ));
    }
    let gun_com = DVec3::from_array(s.gun_com.unwrap_or([0.0; 3])) * input.to_m;
    if !gun_com.is_finite() || gun_com.abs().max_element() > cellplan_model::tasks::MAX_COORDINATE {
        return Err(input.error(
            "gun_com",
            format!(
                "`gun_com` must be finite and within {} m of the tip link",
                cellplan_model::tasks::MAX_COORDINATE
            ),
        ));
    }
    // Where `max_torque` is written, for the check against the robot's joints (see
    // [`crate::WeldCell::new`]).
    let at = cellplan_model::process::key_span(input.text, &input.span, "max_torque");
    let max_torque_line = Some(cellplan_model::error::line_of(input.text, at.start));
    Ok(Arc::new(StudWeld {
        gun_mass,
        gun_com,
        weld_time,
        weights,
        rotation_step,
        max_torque: s.max_torque,
        max_torque_line,
        steps,
        ocp_budget,
    }))
}

impl StudWeld {
    /// The number of gun rotations about a stud's axis.
    pub fn rotations(&self) -> usize {
        ((std::f64::consts::TAU / self.rotation_step) - 1e-9)
            .ceil()
            .max(1.0) as usize
    }
}

/// The gun pose at a stud with the gun turned by `angle` about the stud axis: the TCP on the
/// stud, its z axis along the inward normal (`−n`), its x axis the stud frame's x turned by
/// `angle` about z. The stud frame's x is the world axis least aligned with `n`, made
/// orthogonal to it (a fixed rule, so the verifier rebuilds the same frame).
pub fn gun_pose(position: DVec3, normal: DVec3, angle: f64) -> Pose {
    let z = -normal.normalize();
    let pick = [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .min_by(|a, b| a.dot(z).abs().total_cmp(&b.dot(z).abs()))
        .unwrap_or(DVec3::X);
    let x0 = (pick - z * pick.dot(z)).normalize();
    let y0 = z.cross(x0);
    let frame = DQuat::from_mat3(&glam::DMat3::from_cols(x0, y0, z));
    Pose::from_parts(position, frame * DQuat::from_rotation_z(angle))
}

impl Process for StudWeld {
    fn kind(&self) -> &'static str {
        KIND
    }

    fn as_any(&self) -> &dyn std::any::Any {
        self
    }

    fn words(&self) -> &'static Words {
        &WORDS
    }

    fn parameters(&self) -> serde_json::Value {
        serde_json::json!({
            "weld_time_s": self.weld_time,
            "cost": { "time": self.weights.time, "effort": self.weights.effort, "velocity": self.weights.velocity },
            "gun_rotation_step_rad": self.rotation_step,
            "max_torque_nm": self.max_torque,
            "steps": self.steps,
            "ocp_budget": self.ocp_budget,
            "gun_mass_kg": self.gun_mass,
            "gun_com_m": self.gun_com.to_array(),
        })
    }

    fn tool_reach(&self) -> f64 {
        0.0
    }

    fn tool_poses(&self, task: &Task) -> Vec<Pose> {
        (0..self.rotations())
            .map(|k| gun_pose(task.position, task.normal, k as f64 * self.rotation_step))
            .collect()
    }

    /// The pose the joints reach must weld within [`WELD_POSE_TOLERANCE`], which the verifier
    /// checks (a numeric IK solution misses the asked pose a little).
    fn pose_check(&self, task: &Task, tcp: &Pose) -> Result<(), ProcessReason> {
        if weld_pose_error(tcp, task.position, task.normal).0 {
            Ok(())
        } else {
            Err(ProcessReason {
                rank: 0,
                code: "weld-pose",
                text: "the pose the joints reach is farther from the stud than the weld-pose tolerance",
            })
        }
    }

    fn reached_check(&self, _world: &CollisionWorld, _task: &Task, _tcp: &Pose) -> Result<(), ProcessReason> {
        Ok(())
    }

    fn arm_check(
        &self,
        _world: &CollisionWorld,
        _robot: &Robot,
        _bodies: &[Pose],
        _task: &Task,
        _tcp: &Pose,
    ) -> Result<(), ProcessReason> {
        Ok(())
    }

    fn work(&self, _task: &Task) -> Work {
        Work::Dwell(self.weld_time)
    }

    fn visit_figures(&self, _task: &Task, _tcp: &Pose) -> Vec<Figure> {
        Vec::new()
    }

    fn local_sets(&self, _tasks: &[Task], _members: &[TaskId], _radius: f64) -> Option<Vec<Vec<TaskId>>> {
        None
    }

    fn nearby_poses(&self, task: &Task, tcp: &Pose, step: f64) -> Vec<Pose> {
        // The gun turned by ±step about the stud axis.
        let axis = tcp.rotation * DVec3::Z;
        [-step, step]
            .into_iter()
            .map(|a| Pose::from_parts(task.position, DQuat::from_axis_angle(axis, a) * tcp.rotation))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gun_points_into_the_surface_and_turns_about_the_stud_axis() {
        let p = DVec3::new(0.8, -0.2, 1.1);
        for n in [DVec3::X, DVec3::new(0.7, 0.1, 0.7).normalize(), -DVec3::Z] {
            let a = gun_pose(p, n, 0.0);
            let b = gun_pose(p, n, 0.5);
            assert!((a.translation - p).length() < 1e-12);
            assert!((a.rotation * DVec3::Z + n).length() < 1e-12);
            assert!((b.rotation * DVec3::Z + n).length() < 1e-12);
            let turn = (a.rotation * DVec3::X).angle_between(b.rotation * DVec3::X);
            assert!((turn - 0.5).abs() < 1e-12, "{turn}");
        }
    }

    #[test]
    fn rotations_cover_the_circle_once() {
        let mut p = StudWeld {
            weld_time: 2.0,
            weights: Weights::default(),
            rotation_step: 45f64.to_radians(),
            max_torque: vec![1.0],
            max_torque_line: None,
            steps: 12,
            ocp_budget: 1,
            gun_mass: 0.0,
            gun_com: DVec3::ZERO,
        };
        assert_eq!(p.rotations(), 8);
        p.rotation_step = 50f64.to_radians();
        assert_eq!(p.rotations(), 8);
        p.rotation_step = 400f64.to_radians();
        assert_eq!(p.rotations(), 1);
    }
}

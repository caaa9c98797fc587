//! Paper 000 as a cellplan process: multi-robot optical inspection. The laser-triangulation
//! probe ([`probe`]: pose sampling around an MP, the measurement geometry — stripe, depth of
//! field, view angle, camera side — and the two beams), its `[process]` table and task column
//! (`tolerance`), the local robust MP sets of eq. 4 and the probe-orientation perturbation of
//! §4.2, behind [`cellplan_model::Process`]. The binary registers [`ENTRY`].
#![warn(missing_docs)]
#![allow(clippy::result_large_err)]

pub mod probe;
#[cfg(feature = "testing")]
pub mod testing;

use cellplan_geom::{CollisionWorld, DQuat, Pose};
use cellplan_model::process::{ColumnUnit, TaskColumn};
use cellplan_model::robot::BodyFrame;
use cellplan_model::{
    Figure, InputError, Process, ProcessEntry, ProcessInput, ProcessReason, Robot, Task, TaskId, Words, Work,
};
use glam::EulerRot;
pub use probe::{OpticalProcess, ProbePose, Rejection, Sampling};
use serde::Deserialize;
use std::sync::Arc;

/// `[process] kind` of this process.
pub const KIND: &str = "optical-inspection";

/// The registry entry.
pub const ENTRY: ProcessEntry = ProcessEntry {
    kind: KIND,
    summary: "optical inspection of measurement points by robots with laser-triangulation probes (paper 000)",
    task_columns: &[TaskColumn {
        name: "tolerance",
        unit: ColumnUnit::Angle,
    }],
    build,
};

/// Most probe poses sampled per MP (`(1 + tilt_steps · azimuth_steps) · spin_steps`).
pub const MAX_POSES_PER_TASK: usize = 20_000;

static WORDS: Words = Words {
    task: "MP",
    tasks: "MPs",
    working: "measuring",
    tool: "probe",
};

/// Parameters of `kind = "optical-inspection"` (lengths and angles in file units, times in s).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpticalSpec {
    /// Nominal distance from the laser source (the TCP) to the MP along the beam.
    pub standoff: f64,
    /// Depth of field: the MP must lie within standoff ± depth_of_field/2 (default 100 mm).
    pub depth_of_field: Option<f64>,
    /// θ0: largest angle between the beam and the MP normal (default 15°).
    pub view_angle: Option<f64>,
    /// Length of the laser stripe at the standoff; the MP must lie on it.
    pub stripe_length: f64,
    /// Triangulation baseline: camera offset from the laser source along the tool x axis.
    pub baseline: f64,
    /// Measuring time per MP in seconds, motion excluded (default 1.5).
    pub measure_time: Option<f64>,
    /// How finely probe poses are sampled.
    #[serde(default)]
    pub sampling: SamplingSpec,
}

/// `[process.sampling]`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SamplingSpec {
    /// Rings of tilt in (0, θ0] besides the normal itself.
    pub tilt_steps: usize,
    /// Directions per tilt ring.
    pub azimuth_steps: usize,
    /// Rotations of the probe about its beam.
    pub spin_steps: usize,
}

impl Default for SamplingSpec {
    fn default() -> Self {
        SamplingSpec {
            tilt_steps: 2,
            azimuth_steps: 8,
            spin_steps: 8,
        }
    }
}

/// Keys that moved from `[process]` to `[planning]`.
const PLANNING_KEYS: [&str; 3] = ["task_cap", "balance_limit", "clearance"];

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

/// Builds the process from its `[process]` table and checks the tasks' `tolerance` column.
pub fn build(input: &ProcessInput) -> Result<Arc<dyn Process>, InputError> {
    let o: OpticalSpec = input.parse().map_err(|e| {
        match PLANNING_KEYS
            .iter()
            .find(|k| e.message.contains(&format!("`{k}`")))
        {
            Some(k) => e.hint(format!(
                "`{k}` is shared by every process: it moved to the `[planning]` table"
            )),
            None => e,
        }
    })?;
    let standoff = positive(input, "standoff", o.standoff)? * input.to_m;
    let depth_of_field = match o.depth_of_field {
        Some(v) => positive(input, "depth_of_field", v)? * input.to_m,
        None => 0.100,
    };
    let view_angle = match o.view_angle {
        Some(v) => positive(input, "view_angle", v)? * input.to_rad,
        None => 15f64.to_radians(),
    };
    if view_angle >= std::f64::consts::FRAC_PI_2 {
        return Err(input.error("view_angle", "`view_angle` must be below 90°").hint(
            "θ0 is the largest angle between the beam and the surface normal; optical probes allow about 10–30°",
        ));
    }
    if depth_of_field / 2.0 >= standoff {
        return Err(input
            .error(
                "depth_of_field",
                "half the depth of field reaches past the laser source",
            )
            .hint("the depth of field must be smaller than twice the standoff"));
    }
    let stripe_length = positive(input, "stripe_length", o.stripe_length)? * input.to_m;
    let baseline = positive(input, "baseline", o.baseline)? * input.to_m;
    for (key, v) in [
        ("standoff", standoff),
        ("stripe_length", stripe_length),
        ("baseline", baseline),
    ] {
        if v > 10.0 {
            return Err(input
                .error(
                    key,
                    format!("`{key}` of {} m is beyond 10 m", cellplan_model::shown(v)),
                )
                .hint("an optical probe works at centimetres to a metre; check `units.length`"));
        }
    }
    let measure_time = match o.measure_time {
        Some(v) if v.is_finite() && (0.0..=3600.0).contains(&v) => v,
        Some(v) => {
            return Err(input.error(
                "measure_time",
                format!(
                    "`measure_time` must be between 0 and 3600 s, not {}",
                    cellplan_model::shown(v)
                ),
            ));
        }
        None => 1.5,
    };
    let s = o.sampling;
    if s.spin_steps == 0 || (s.tilt_steps > 0 && s.azimuth_steps == 0) {
        return Err(input
            .error(
                "spin_steps",
                "sampling needs at least one spin, and one azimuth per tilt ring",
            )
            .hint("e.g. tilt_steps = 2, azimuth_steps = 8, spin_steps = 8"));
    }
    let poses = s
        .tilt_steps
        .checked_mul(s.azimuth_steps)
        .and_then(|n| n.checked_add(1))
        .and_then(|n| n.checked_mul(s.spin_steps));
    if poses.is_none_or(|n| n > MAX_POSES_PER_TASK) {
        let key = if s.spin_steps > s.azimuth_steps.max(s.tilt_steps) {
            "spin_steps"
        } else if s.azimuth_steps > s.tilt_steps {
            "azimuth_steps"
        } else {
            "tilt_steps"
        };
        return Err(input
            .error(
                key,
                format!(
                    "sampling asks for (1 + {} × {}) × {} probe poses per MP, more than {MAX_POSES_PER_TASK}",
                    s.tilt_steps, s.azimuth_steps, s.spin_steps
                ),
            )
            .hint("a few hundred poses per MP are plenty: e.g. tilt_steps = 2, azimuth_steps = 8, spin_steps = 8"));
    }
    for task in input.tasks {
        if let Some(t) = probe::tolerance(task)
            && !(t > 0.0 && t < std::f64::consts::FRAC_PI_2)
        {
            return Err(input
                .task_error(
                    task,
                    format!(
                        "`tolerance` must be an angle above 0 and below 90°, not {:.4} rad",
                        t
                    ),
                )
                .hint("the largest angle between beam and normal for this task, in the cell's angle unit"));
        }
    }
    Ok(Arc::new(OpticalProcess {
        standoff,
        depth_of_field,
        view_angle,
        stripe_length,
        baseline,
        measure_time,
        sampling: Sampling {
            tilt_steps: s.tilt_steps,
            azimuth_steps: s.azimuth_steps,
            spin_steps: s.spin_steps,
        },
    }))
}

/// Orientation of a probe pose as FANUC (w, p, r): rotation Rz(r)·Ry(p)·Rx(w).
fn wpr(q: DQuat) -> [f64; 3] {
    let (r, p, w) = q.to_euler(EulerRot::ZYX);
    [w, p, r]
}

impl Process for OpticalProcess {
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
            "standoff_m": self.standoff,
            "depth_of_field_m": self.depth_of_field,
            "view_angle_rad": self.view_angle,
            "stripe_length_m": self.stripe_length,
            "baseline_m": self.baseline,
            "measure_time_s": self.measure_time,
            "sampling": self.sampling,
        })
    }

    fn tool_reach(&self) -> f64 {
        self.standoff
    }

    fn tool_poses(&self, task: &Task) -> Vec<Pose> {
        self.sample_poses(task).into_iter().map(|p| p.tcp).collect()
    }

    fn pose_check(&self, task: &Task, tcp: &Pose) -> Result<(), ProcessReason> {
        self.measurement(task, tcp).map(|_| ()).map_err(Rejection::reason)
    }

    fn reached_check(&self, world: &CollisionWorld, task: &Task, tcp: &Pose) -> Result<(), ProcessReason> {
        if self.beams_clear_of_statics(world, task, tcp) {
            Ok(())
        } else {
            Err(Rejection::BeamOccluded.reason())
        }
    }

    fn arm_check(
        &self,
        world: &CollisionWorld,
        robot: &Robot,
        bodies: &[Pose],
        task: &Task,
        tcp: &Pose,
    ) -> Result<(), ProcessReason> {
        // The beams start on the probe, so the probe itself is left out: only the arm can
        // block them.
        let tool: Vec<usize> = (0..robot.bodies.len())
            .filter(|&i| robot.bodies[i] == BodyFrame::Tool)
            .collect();
        for (from, dir, len) in self.beams(task, tcp) {
            if world
                .cast_ray_group_except(robot.group, bodies, from, dir, len, &tool)
                .is_some()
            {
                return Err(Rejection::BeamOccluded.reason());
            }
        }
        Ok(())
    }

    fn work(&self, _task: &Task) -> Work {
        Work::Dwell(self.measure_time)
    }

    fn visit_figures(&self, task: &Task, tcp: &Pose) -> Vec<Figure> {
        let beam = tcp.rotation * cellplan_geom::DVec3::Z;
        vec![Figure {
            key: "view_angle_rad",
            value: (-beam).dot(task.normal).clamp(-1.0, 1.0).acos(),
        }]
    }

    /// Eq. 4: MPs closer than `radius` whose admissible probe orientations — the cone of
    /// half-angle θ (the MP's tolerance, else θ0) about the normal — overlap, i.e. whose normals
    /// are at most θ_j + θ_k apart.
    fn local_sets(&self, tasks: &[Task], members: &[TaskId], radius: f64) -> Option<Vec<Vec<TaskId>>> {
        let half_angle = |t: TaskId| self.angle_limit(&tasks[t.0]);
        Some(
            members
                .iter()
                .map(|&j| {
                    members
                        .iter()
                        .copied()
                        .filter(|&k| {
                            let (a, b) = (&tasks[j.0], &tasks[k.0]);
                            let angle = a.normal.dot(b.normal).clamp(-1.0, 1.0).acos();
                            (a.position - b.position).length() < radius
                                && angle <= half_angle(j) + half_angle(k) + 1e-12
                        })
                        .collect()
                })
                .collect(),
        )
    }

    /// §4.2: the orientation (w, p, r) perturbed on the ±2-increment grid, the probe position
    /// fixed.
    fn nearby_poses(&self, _task: &Task, tcp: &Pose, step: f64) -> Vec<Pose> {
        let [w0, p0, r0] = wpr(tcp.rotation);
        let mut poses = Vec::with_capacity(124);
        for dw in -2..=2 {
            for dp in -2..=2 {
                for dr in -2..=2 {
                    if (dw, dp, dr) == (0, 0, 0) {
                        continue;
                    }
                    let (w, p, r) = (
                        w0 + f64::from(dw) * step,
                        p0 + f64::from(dp) * step,
                        r0 + f64::from(dr) * step,
                    );
                    let rotation = DQuat::from_euler(EulerRot::ZYX, r, p, w).normalize();
                    poses.push(Pose::from_parts(tcp.translation, rotation));
                }
            }
        }
        poses
    }
}

/// The optical process of `cell`, if it runs this process.
pub fn of(cell: &cellplan_model::Cell) -> Option<&OpticalProcess> {
    cell.process.as_any().downcast_ref()
}

/// Loads a cell with [`registry`] (for tests, benchmarks and embedding).
#[allow(clippy::result_large_err)]
pub fn load(
    path: &std::path::Path,
    opts: &cellplan_model::LoadOptions,
) -> Result<cellplan_model::Cell, InputError> {
    cellplan_model::load(path, &registry(), opts)
}

/// A registry with this process alone (for tests, benchmarks and embedding).
pub fn registry() -> cellplan_model::Registry {
    cellplan_model::Registry::new().with(ENTRY)
}

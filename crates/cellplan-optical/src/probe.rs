//! The optical probe of paper 000 §2.1: a laser-triangulation sensor measuring one point per
//! pose. The TCP is the laser source; its z axis is the beam; the camera sits `baseline` along
//! the TCP x axis; the laser stripe runs along the TCP y axis. An MP is measured admissibly
//! when it lies on the stripe within the depth of field, the angle between the beam and the MP
//! normal is within θ0, the camera sees the lit side, and neither the incident beam (source →
//! MP) nor the reflected beam (MP → camera) is blocked.
use cellplan_geom::{CollisionWorld, DQuat, DVec3, Pose};
use cellplan_model::{ProcessReason, Task};
use serde::Serialize;

/// How finely probe poses are sampled around an MP.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Sampling {
    /// Tilt rings in (0, θ0] besides the normal itself.
    pub tilt_steps: usize,
    /// Directions per ring.
    pub azimuth_steps: usize,
    /// Rotations about the beam.
    pub spin_steps: usize,
}

/// Parameters of the optical inspection process (SI).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OpticalProcess {
    /// Nominal source-to-MP distance (m).
    pub standoff: f64,
    /// Depth of field (m): the MP lies within standoff ± dof/2.
    pub depth_of_field: f64,
    /// θ0 (rad).
    pub view_angle: f64,
    /// Stripe length (m).
    pub stripe_length: f64,
    /// Source-to-camera distance along TCP x (m).
    pub baseline: f64,
    /// Measuring time per MP (s).
    pub measure_time: f64,
    /// Pose sampling.
    pub sampling: Sampling,
}

/// Half-thickness of the laser plane: how far off the stripe plane an MP may lie (m).
const PLANE_TOLERANCE: f64 = 1e-3;
/// Beams stop this short of the MP so the MP's own surface does not count as a blocker (m).
const BEAM_END_GAP: f64 = 2e-3;

/// Why the probe does not measure an MP from a pose (the process's reasons; the generic
/// ones — no IK, joint limits, collision — are the core's). Ordered by how far the pose got.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rejection {
    /// The beam meets the normal at more than θ0, or the camera sees the back side.
    ViewAngle,
    /// The MP is off the laser stripe.
    Stripe,
    /// The MP is outside the depth of field.
    DepthOfField,
    /// The incident or reflected beam is blocked (by a static object, or by the robot's arm).
    BeamOccluded,
}

impl Rejection {
    /// The reason as the core records it.
    pub fn reason(self) -> ProcessReason {
        let (rank, code, text) = match self {
            Rejection::ViewAngle => (0, "view-angle", "view angle beyond θ0"),
            Rejection::Stripe => (1, "stripe", "MP off the laser stripe"),
            Rejection::DepthOfField => (2, "depth-of-field", "MP outside the depth of field"),
            Rejection::BeamOccluded => (0, "beam-occluded", "beam occluded"),
        };
        ProcessReason { rank, code, text }
    }
}

/// A sampled probe pose for an MP.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbePose {
    /// TCP pose in the world.
    pub tcp: Pose,
    /// Angle between beam and normal (rad).
    pub tilt: f64,
    /// Direction of the tilt about the normal (rad).
    pub azimuth: f64,
    /// Rotation about the beam (rad).
    pub spin: f64,
}

/// A task's own limit on the beam-to-normal angle (rad): its `tolerance` column.
pub fn tolerance(task: &Task) -> Option<f64> {
    task.values.first().copied().flatten()
}

/// A unit vector perpendicular to `n`, chosen the same way for every caller.
fn perpendicular(n: DVec3) -> DVec3 {
    let helper = if n.z.abs() < 0.9 { DVec3::Z } else { DVec3::X };
    helper.cross(n).normalize()
}

impl OpticalProcess {
    /// The largest beam-to-normal angle allowed for `task` (its own tolerance, else θ0).
    pub fn angle_limit(&self, task: &Task) -> f64 {
        tolerance(task).unwrap_or(self.view_angle)
    }

    /// Probe poses to try for `task`: the normal and `tilt_steps` rings up to the angle limit
    /// with `azimuth_steps` directions each, every one with `spin_steps` rotations about the
    /// beam; the source at `standoff` from the MP.
    pub fn sample_poses(&self, task: &Task) -> Vec<ProbePose> {
        let n = task.normal;
        let u = perpendicular(n);
        let v = n.cross(u);
        let s = self.sampling;
        let limit = self.angle_limit(task);
        let mut axes = vec![(0.0, 0.0)];
        for ring in 1..=s.tilt_steps {
            let tilt = limit * ring as f64 / s.tilt_steps as f64;
            for k in 0..s.azimuth_steps.max(1) {
                axes.push((
                    tilt,
                    std::f64::consts::TAU * k as f64 / s.azimuth_steps.max(1) as f64,
                ));
            }
        }
        let mut poses = Vec::with_capacity(axes.len() * s.spin_steps.max(1));
        for (tilt, azimuth) in axes {
            // Axis from the MP towards the source.
            let a = n * tilt.cos() + (u * azimuth.cos() + v * azimuth.sin()) * tilt.sin();
            let z = -a;
            let x0 = perpendicular(z);
            let y0 = z.cross(x0);
            let base = DQuat::from_mat3(&cellplan_geom::DMat3::from_cols(x0, y0, z));
            for k in 0..s.spin_steps.max(1) {
                let spin = std::f64::consts::TAU * k as f64 / s.spin_steps.max(1) as f64;
                let rotation = (base * DQuat::from_rotation_z(spin)).normalize();
                poses.push(ProbePose {
                    tcp: Pose::from_parts(task.position + a * self.standoff, rotation),
                    tilt,
                    azimuth,
                    spin,
                });
            }
        }
        poses
    }

    /// Camera position for a TCP pose.
    pub fn camera(&self, tcp: &Pose) -> DVec3 {
        tcp.transform_point(DVec3::X * self.baseline)
    }

    /// Checks the measuring geometry of a TCP pose for `task` (no robot, no obstacles):
    /// returns the view angle (rad) or why the pose does not measure the MP.
    pub fn measurement(&self, task: &Task, tcp: &Pose) -> Result<f64, Rejection> {
        let beam = tcp.rotation * DVec3::Z;
        let view_angle = (-beam).dot(task.normal).clamp(-1.0, 1.0).acos();
        if view_angle > self.angle_limit(task) + 1e-7 {
            return Err(Rejection::ViewAngle);
        }
        let camera_ray = self.camera(tcp) - task.position;
        if camera_ray.dot(task.normal) <= 0.0 {
            return Err(Rejection::ViewAngle);
        }
        let local = tcp.inverse_transform_point(task.position);
        if local.x.abs() > PLANE_TOLERANCE || local.y.abs() > self.stripe_length / 2.0 {
            return Err(Rejection::Stripe);
        }
        if (local.z - self.standoff).abs() > self.depth_of_field / 2.0 + 1e-9 {
            return Err(Rejection::DepthOfField);
        }
        Ok(view_angle)
    }

    /// Whether the incident beam (source → MP) and the reflected beam (MP → camera) are clear
    /// of the static scene.
    pub fn beams_clear_of_statics(&self, world: &CollisionWorld, task: &Task, tcp: &Pose) -> bool {
        self.beams(task, tcp)
            .iter()
            .all(|&(from, dir, len)| world.cast_ray_static(from, dir, len).is_none())
    }

    /// The two beams as rays `(start, unit direction, length)`, each ending short of the MP.
    pub fn beams(&self, task: &Task, tcp: &Pose) -> [(DVec3, DVec3, f64); 2] {
        let ray = |from: DVec3| {
            let d = task.position - from;
            let len = d.length();
            (from, d / len, (len - BEAM_END_GAP).max(0.0))
        };
        [ray(tcp.translation), ray(self.camera(tcp))]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellplan_model::TaskId;
    use cellplan_model::tasks::Feature;

    fn process() -> OpticalProcess {
        OpticalProcess {
            standoff: 0.25,
            depth_of_field: 0.1,
            view_angle: 15f64.to_radians(),
            stripe_length: 0.06,
            baseline: 0.1,
            measure_time: 1.5,
            sampling: Sampling {
                tilt_steps: 2,
                azimuth_steps: 8,
                spin_steps: 4,
            },
        }
    }

    fn task(normal: DVec3) -> Task {
        Task {
            id: TaskId(0),
            name: "M1".into(),
            position: DVec3::new(1.0, 2.0, 0.5),
            normal: normal.normalize(),
            values: vec![None],
            feature: Feature::Surface,
            line: 2,
        }
    }

    #[test]
    fn every_sampled_pose_measures_its_mp() {
        let p = process();
        for n in [DVec3::X, DVec3::new(0.3, -0.2, 0.9), -DVec3::Z] {
            let t = task(n);
            let poses = p.sample_poses(&t);
            assert_eq!(poses.len(), (1 + 2 * 8) * 4);
            for pose in &poses {
                let angle = p.measurement(&t, &pose.tcp).expect("sampled pose must measure");
                // acos near 1 loses half the digits: 1e-7 is the honest tolerance.
                assert!((angle - pose.tilt).abs() < 1e-7);
                assert!(angle <= p.view_angle + 1e-9);
                let d = (pose.tcp.translation - t.position).length();
                assert!((d - p.standoff).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn rejections_name_the_broken_constraint() {
        let p = process();
        let t = task(DVec3::Z);
        let good = p.sample_poses(&t)[0].tcp;
        // Too far: outside the depth of field.
        let far = Pose::from_parts(good.translation + DVec3::Z * 0.1, good.rotation);
        assert_eq!(p.measurement(&t, &far), Err(Rejection::DepthOfField));
        // Shifted sideways along y: off the stripe.
        let side = Pose::from_parts(good.translation + good.rotation * DVec3::Y * 0.05, good.rotation);
        assert_eq!(p.measurement(&t, &side), Err(Rejection::Stripe));
        // Tilted 30° about the MP: beyond θ0.
        let tilt = DQuat::from_axis_angle(DVec3::X, 30f64.to_radians());
        let tilted = Pose::from_parts(
            t.position + tilt * (good.translation - t.position),
            tilt * good.rotation,
        );
        assert_eq!(p.measurement(&t, &tilted), Err(Rejection::ViewAngle));
        // A per-task tolerance overrides θ0.
        let mut loose = t.clone();
        loose.values = vec![Some(40f64.to_radians())];
        assert!(p.measurement(&loose, &tilted).is_ok());
    }

    #[test]
    fn beams_end_short_of_the_mp() {
        let p = process();
        let t = task(DVec3::Z);
        let pose = p.sample_poses(&t)[0].tcp;
        for (from, dir, len) in p.beams(&t, &pose) {
            let end = from + dir * len;
            assert!(((end - t.position).length() - BEAM_END_GAP).abs() < 1e-9);
        }
    }
}

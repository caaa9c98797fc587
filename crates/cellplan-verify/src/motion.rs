//! The exact re-check of joint paths (the motion benchmark's `exact_valid`), independent of
//! the planner's model: the robot's collision shapes **as the URDF gives them** — triangle
//! meshes as triangle meshes (not hulls, not sphere covers), primitives as primitives — posed
//! densely along every segment and tested with parry's exact queries against the obstacles and
//! against each other (the checked self pairs).
//!
//! Density: between two consecutive samples no vertex of any shape moves more than `max_step`
//! (m). The bound is this module's own: joint `j` moves a point at most `R_j·|Δq_j|`, `R_j` the
//! sum of the link offsets from joint `j` to the shape's link plus the shape's farthest point
//! from its link's origin. A triangle mesh is a surface: an obstacle that slips wholly inside a
//! link's mesh between two samples would be missed, which a step far below the obstacles' size
//! (1 mm against centimetres) rules out.
use cellplan_geom::{DQuat, Pose, ShapeSpec};
use cellplan_kin::{Chain, JointKind, RobotModel};
use parry3d_f64::query;
use parry3d_f64::shape::{Ball, Cuboid, Cylinder, SharedShape, TriMesh};

/// One shape of the robot, as given.
struct Part {
    /// Chain link it hangs on.
    link: usize,
    shape: SharedShape,
    /// Pose of `shape` in the link frame.
    local: Pose,
    /// Farthest point of the shape from the link origin (m).
    reach: f64,
}

/// The robot for exact checks: its chain, base and collision shapes as given, and the shape
/// pairs checked for self-collision.
pub struct ExactRobot<'a> {
    chain: &'a Chain,
    base: Pose,
    parts: Vec<Part>,
    pairs: Vec<(usize, usize)>,
    /// Per joint, the bound `R_j` (see the module documentation).
    radii: Vec<f64>,
}

/// A parry shape for a shape spec, with its pose in the spec's frame, and the farthest distance
/// of its points from that frame's origin. Meshes keep their triangles.
fn exact_shape(spec: &ShapeSpec) -> Option<(SharedShape, Pose, f64)> {
    match spec {
        ShapeSpec::Box { half_extents } => Some((
            SharedShape::new(Cuboid::new(half_extents.abs())),
            Pose::IDENTITY,
            half_extents.length(),
        )),
        ShapeSpec::Cylinder { radius, half_height } => Some((
            SharedShape::new(Cylinder::new(half_height.abs(), radius.abs())),
            // parry's cylinder axis is y; the spec's is z.
            Pose::from_rotation(DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2)),
            (radius * radius + half_height * half_height).sqrt(),
        )),
        ShapeSpec::Sphere { radius } => Some((SharedShape::new(Ball::new(radius.abs())), Pose::IDENTITY, radius.abs())),
        ShapeSpec::Mesh(m) => {
            let reach = m.vertices.iter().map(|v| v.length()).fold(0.0, f64::max);
            let tris: Vec<[u32; 3]> = m
                .triangles
                .iter()
                .copied()
                .filter(|t| t.iter().all(|&i| (i as usize) < m.vertices.len()))
                .collect();
            let mesh = TriMesh::new(m.vertices.clone(), tris).ok()?;
            Some((SharedShape::new(mesh), Pose::IDENTITY, reach))
        }
    }
}

impl<'a> ExactRobot<'a> {
    /// The robot of `model` standing at `base`, one part per collision shape in the order of
    /// `model.collision` (link by link, shape by shape — the order the problem loader gives its
    /// bodies), checking the part pairs `pairs`.
    pub fn new(model: &'a RobotModel, base: Pose, pairs: &[(usize, usize)]) -> Self {
        let mut parts = Vec::new();
        for (link, shapes) in model.collision.iter().enumerate() {
            for (spec, pose) in shapes {
                if let Some((shape, local, r)) = exact_shape(spec) {
                    parts.push(Part {
                        link,
                        shape,
                        local: *pose * local,
                        reach: pose.translation.length() + r,
                    });
                }
            }
        }
        let chain = &model.chain;
        let offsets: Vec<f64> = chain
            .links
            .iter()
            .map(|l| {
                let travel = l.joint.and_then(|j| chain.joints.get(j)).map_or(0.0, |j| {
                    if j.kind == JointKind::Prismatic {
                        j.lower.abs().max(j.upper.abs())
                    } else {
                        0.0
                    }
                });
                l.origin.translation.length() + travel
            })
            .collect();
        let radii = (0..chain.dof())
            .map(|j| {
                if chain.joints[j].kind == JointKind::Prismatic {
                    return 1.0;
                }
                let Some(lj) = chain.joint_link(j) else { return 0.0 };
                parts
                    .iter()
                    .filter(|p| p.link >= lj)
                    .map(|p| offsets[lj + 1..=p.link].iter().sum::<f64>() + p.reach)
                    .fold(0.0, f64::max)
            })
            .collect();
        ExactRobot {
            chain,
            base,
            parts,
            pairs: pairs.to_vec(),
            radii,
        }
    }

    /// Number of parts (collision shapes).
    pub fn part_count(&self) -> usize {
        self.parts.len()
    }
}

/// What the exact re-check found on a path.
#[derive(Clone, Debug, PartialEq)]
pub struct ExactCheck {
    /// No contact anywhere along the path (and every configuration within the joint limits).
    pub valid: bool,
    /// Configurations tested.
    pub samples: usize,
    /// The first contact: segment index, parameter on it, and what touched what.
    pub contact: Option<(usize, f64, String)>,
}

/// An obstacle for the exact check: a shape at a world pose.
pub struct ExactObstacle {
    /// Name, for the report.
    pub name: String,
    shape: SharedShape,
    pose: Pose,
}

impl ExactObstacle {
    /// The obstacle `spec` at `pose`; `None` for a degenerate shape.
    pub fn new(name: &str, spec: &ShapeSpec, pose: Pose) -> Option<Self> {
        let (shape, local, _) = exact_shape(spec)?;
        Some(ExactObstacle {
            name: name.to_string(),
            shape,
            pose: pose * local,
        })
    }
}

impl ExactRobot<'_> {
    /// The first contact at `q` (`None` when clear): a part within `margin` of an obstacle, or a
    /// checked pair touching. `poses` is scratch.
    fn contact_at(&self, q: &[f64], obstacles: &[ExactObstacle], margin: f64, links: &mut [Pose]) -> Option<String> {
        self.chain.fk_all(q, links);
        let world: Vec<Pose> = self.parts.iter().map(|p| self.base * links[p.link] * p.local).collect();
        for (p, pose) in self.parts.iter().zip(&world) {
            for o in obstacles {
                let hit = if margin > 0.0 {
                    query::distance(pose, &*p.shape, &o.pose, &*o.shape).map(|d| d.distance <= margin)
                } else {
                    query::intersection_test(pose, &*p.shape, &o.pose, &*o.shape).map(|r| r.intersecting)
                };
                // A pair parry cannot test counts as a contact: the check must not pass blind.
                if hit.unwrap_or(true) {
                    return Some(format!("link {} with obstacle {}", self.chain.links[p.link].name, o.name));
                }
            }
        }
        for &(i, j) in &self.pairs {
            let (Some(a), Some(b)) = (self.parts.get(i), self.parts.get(j)) else {
                continue;
            };
            let hit = query::intersection_test(&world[i], &*a.shape, &world[j], &*b.shape).map(|r| r.intersecting);
            if hit.unwrap_or(true) {
                return Some(format!(
                    "link {} with link {} (parts {i}, {j})",
                    self.chain.links[a.link].name, self.chain.links[b.link].name
                ));
            }
        }
        None
    }

    /// Re-checks the joint path `waypoints` (chain order): every segment sampled so that no
    /// point moves more than `max_step` (m) between samples, each sample within the joint limits
    /// and clear of the obstacles by more than `margin` and of itself.
    pub fn check_path(
        &self,
        waypoints: &[Vec<f64>],
        obstacles: &[ExactObstacle],
        margin: f64,
        max_step: f64,
    ) -> ExactCheck {
        let mut links = vec![Pose::IDENTITY; self.chain.links.len()];
        let mut samples = 0;
        let step = if max_step > 0.0 { max_step } else { 1e-3 };
        let fail = |samples, seg, t, what: String| ExactCheck {
            valid: false,
            samples,
            contact: Some((seg, t, what)),
        };
        if waypoints.is_empty() {
            return ExactCheck {
                valid: false,
                samples: 0,
                contact: Some((0, 0.0, "empty path".into())),
            };
        }
        let mut q = vec![0.0; self.chain.dof()];
        for seg in 0..waypoints.len().max(2) - 1 {
            let a = &waypoints[seg];
            let b = waypoints.get(seg + 1).unwrap_or(a);
            if a.len() != q.len() || b.len() != q.len() {
                return fail(samples, seg, 0.0, "wrong number of joint values".into());
            }
            let bound: f64 = a.iter().zip(b).zip(&self.radii).map(|((x, y), r)| r * (x - y).abs()).sum();
            if !bound.is_finite() {
                return fail(samples, seg, 0.0, "non-finite joint values".into());
            }
            let n = ((bound / step).ceil() as usize).max(1);
            // The first waypoint once; then every sample after the segment's start.
            let first = if seg == 0 { 0 } else { 1 };
            for k in first..=n {
                let t = k as f64 / n as f64;
                for (v, (x, y)) in q.iter_mut().zip(a.iter().zip(b)) {
                    *v = x + t * (y - x);
                }
                samples += 1;
                if !self.chain.within_limits(&q, 1e-9) {
                    return fail(samples, seg, t, "outside the joint limits".into());
                }
                if let Some(what) = self.contact_at(&q, obstacles, margin, &mut links) {
                    return fail(samples, seg, t, what);
                }
            }
        }
        ExactCheck {
            valid: true,
            samples,
            contact: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellplan_kin::load_urdf_str;
    use std::collections::BTreeMap;

    const ARM: &str = r#"<robot name="arm">
  <link name="base"/>
  <link name="l1"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.1 0.1"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#;

    #[test]
    fn a_sweep_through_an_obstacle_is_caught_between_waypoints() {
        let model = load_urdf_str(ARM, std::path::Path::new("arm.urdf"), &BTreeMap::new(), None).unwrap();
        let robot = ExactRobot::new(&model, Pose::IDENTITY, &[]);
        assert_eq!(robot.part_count(), 1);
        // A thin post at 45°, 0.8 m out: the bar sweeps through it from −1 to +1 rad.
        let post = ExactObstacle::new(
            "post",
            &ShapeSpec::Cylinder {
                radius: 0.01,
                half_height: 0.5,
            },
            Pose::translation(0.8 * 0.5f64.sqrt(), 0.8 * 0.5f64.sqrt(), 0.0),
        )
        .unwrap();
        let through = robot.check_path(&[vec![-1.0], vec![1.0]], std::slice::from_ref(&post), 0.0, 1e-3);
        assert!(!through.valid);
        let (seg, t, what) = through.contact.unwrap();
        assert_eq!(seg, 0);
        assert!(what.contains("post"));
        // It touches where the bar's near face (5 cm wide) meets the post (1 cm).
        let angle = -1.0 + 2.0 * t;
        assert!((angle - std::f64::consts::FRAC_PI_4).abs() < 0.1, "{angle}");
        let clear = robot.check_path(&[vec![-1.0], vec![0.5]], std::slice::from_ref(&post), 0.0, 1e-3);
        assert!(clear.valid, "{clear:?}");
        // About 0.1 mm per sample of the tip's 1.5 rad sweep at 1 m: 1,500 or more samples.
        assert!(clear.samples >= 1500, "{}", clear.samples);
        // A margin larger than the gap fails it.
        let close = robot.check_path(&[vec![0.5], vec![0.7]], std::slice::from_ref(&post), 0.0, 1e-3);
        assert!(close.valid);
        let near = robot.check_path(&[vec![0.5], vec![0.7]], std::slice::from_ref(&post), 0.05, 1e-3);
        assert!(!near.valid);
        // Beyond the limits.
        assert!(!robot.check_path(&[vec![0.0], vec![3.5]], &[], 0.0, 1e-3).valid);
    }
}

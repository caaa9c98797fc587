//! The exact re-check of joint paths (the motion benchmark's `exact_valid`), independent of
//! the planner's model: the robot's collision shapes **as the URDF gives them** — triangle
//! meshes as triangle meshes (not hulls, not sphere covers), primitives as primitives — posed
//! densely along every segment and tested with parry's exact queries against the obstacles and
//! against each other (the checked self pairs).
//!
//! Density: between two consecutive samples no point of any shape moves more than `max_step`
//! (m). The bound is this module's own: joint `j` moves a point at most `R_j·|Δq_j|`, `R_j` the
//! sum of the link offsets from joint `j` to the shape's link plus the shape's farthest point
//! from its link's origin. A pair measured far apart at one sample is not tested again until it
//! could have closed the distance (the distance over the motion per sample), which saves the
//! exact mesh–mesh queries without weakening the check; the distance of a mesh's convex hull,
//! which contains it, serves as that lower bound whenever the hull is clear (GJK instead of a
//! triangle search). A triangle mesh is a surface: an
//! obstacle that slips wholly inside a link's mesh between two samples would be missed, which a
//! step far below the obstacles' size (1 mm against centimetres) rules out.
use cellplan_geom::{DQuat, Pose, ShapeSpec};
use cellplan_kin::{Chain, RobotModel};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::query;
use parry3d_f64::shape::{Ball, Cuboid, Cylinder, SharedShape, TriMesh};

/// Joint values may pass their limits by this much (rad or m): paths written in single
/// precision (VAMP's) end a few 1e-7 beyond a goal that lies on a limit.
pub const LIMIT_TOLERANCE: f64 = 1e-5;

/// One shape of the robot, as given.
struct Part {
    /// Chain link it hangs on.
    link: usize,
    /// What the contact report calls it: the chain link, with the URDF link (a gripper's
    /// finger) or tool the shape belongs to where that is another.
    label: String,
    shape: SharedShape,
    /// Pose of `shape` in the link frame.
    local: Pose,
    /// Farthest point of the shape from the link origin (m).
    reach: f64,
    /// Bounds of `shape` in its own frame.
    aabb: Aabb,
    /// For a mesh, its convex hull (same frame): it contains the mesh, so its distance is a
    /// lower bound on the mesh's, found by GJK where the mesh needs a triangle search.
    hull: Option<SharedShape>,
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
    /// Per part, the joints that move it (`0..n`).
    part_joints: Vec<usize>,
}

/// A parry shape for a shape spec, with its pose in the spec's frame (how far its points reach
/// from that frame's origin is [`ShapeSpec::reach`]). Meshes keep their triangles.
pub(crate) fn exact_shape(spec: &ShapeSpec) -> Option<(SharedShape, Pose)> {
    match spec {
        ShapeSpec::Box { half_extents } => {
            Some((SharedShape::new(Cuboid::new(half_extents.abs())), Pose::IDENTITY))
        }
        ShapeSpec::Cylinder { radius, half_height } => Some((
            SharedShape::new(Cylinder::new(half_height.abs(), radius.abs())),
            // parry's cylinder axis is y; the spec's is z.
            Pose::from_rotation(DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2)),
        )),
        ShapeSpec::Sphere { radius } => Some((SharedShape::new(Ball::new(radius.abs())), Pose::IDENTITY)),
        ShapeSpec::Mesh(m) => {
            let tris: Vec<[u32; 3]> = m
                .triangles
                .iter()
                .copied()
                .filter(|t| t.iter().all(|&i| (i as usize) < m.vertices.len()))
                .collect();
            let mesh = TriMesh::new(m.vertices.clone(), tris).ok()?;
            Some((SharedShape::new(mesh), Pose::IDENTITY))
        }
    }
}

impl<'a> ExactRobot<'a> {
    /// The robot of `model` standing at `base`, one part per collision shape, checking every
    /// part of URDF link `a` against every part of link `b` for each `(a, b)` in `link_pairs`.
    pub fn new(model: &'a RobotModel, base: Pose, link_pairs: &[(String, String)]) -> Self {
        let mut parts = Vec::new();
        let mut sources: Vec<&str> = Vec::new();
        for (link, shapes) in model.collision.iter().enumerate() {
            for (k, (spec, pose)) in shapes.iter().enumerate() {
                if let Some((shape, local)) = exact_shape(spec) {
                    let r = spec.reach();
                    let source = model.collision_links[link].get(k).map_or("", String::as_str);
                    sources.push(source);
                    let name = &model.chain.links[link].name;
                    let label = if source.is_empty() || source == name {
                        format!("link {name}")
                    } else {
                        format!("link {name} ({source})")
                    };
                    let hull = match spec {
                        ShapeSpec::Mesh(m) => SharedShape::convex_hull(&m.vertices),
                        _ => None,
                    };
                    parts.push(Part {
                        link,
                        label,
                        aabb: shape.compute_local_aabb(),
                        hull,
                        shape,
                        local: *pose * local,
                        reach: pose.translation.length() + r,
                    });
                }
            }
        }
        let chain = &model.chain;
        let bodies: Vec<(usize, f64)> = parts.iter().map(|p| (p.link, p.reach)).collect();
        let radii = chain.joint_radii(&bodies);
        let joints_to = chain.joints_to();
        let part_joints = parts.iter().map(|p| joints_to[p.link]).collect();
        let mut pairs = Vec::new();
        for i in 0..parts.len() {
            for j in i + 1..parts.len() {
                let (a, b) = (sources[i], sources[j]);
                if link_pairs
                    .iter()
                    .any(|(x, y)| (x == a && y == b) || (x == b && y == a))
                {
                    pairs.push((i, j));
                }
            }
        }
        ExactRobot {
            chain,
            base,
            part_joints,
            parts,
            pairs,
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
    /// World bounds.
    aabb: Aabb,
}

impl ExactObstacle {
    /// The obstacle `spec` at `pose`; `None` for a degenerate shape.
    pub fn new(name: &str, spec: &ShapeSpec, pose: Pose) -> Option<Self> {
        let (shape, local) = exact_shape(spec)?;
        let pose = pose * local;
        Some(ExactObstacle {
            name: name.to_string(),
            aabb: shape.compute_aabb(&pose),
            shape,
            pose,
        })
    }
}

/// Distance between two boxes (0 when they overlap): a lower bound on the distance of anything
/// inside them.
pub(crate) fn box_gap(a: &Aabb, b: &Aabb) -> f64 {
    (a.mins - b.maxs)
        .max(b.mins - a.maxs)
        .max(cellplan_geom::DVec3::ZERO)
        .length()
}

/// For each tested pair (part–obstacle, then self pair), how much closer it may come before it
/// must be tested again (m): until then it is provably apart (see [`ExactRobot::contact_at`]).
struct Schedule {
    slack: Vec<f64>,
    /// Per pair, the joints that move its two members relative to each other.
    joints: Vec<std::ops::Range<usize>>,
}

impl Schedule {
    /// Takes one sample's motion off every slack: `prefix[j]` is the sum over joints `< j` of
    /// `R_j·|Δq_j|` per sample.
    fn advance(&mut self, prefix: &[f64]) {
        for (slack, r) in self.slack.iter_mut().zip(&self.joints) {
            *slack -= prefix[r.end] - prefix[r.start];
        }
    }
}

impl ExactRobot<'_> {
    /// The first contact at `q` (`None` when clear): a part within `margin` of an obstacle, or a
    /// checked pair touching. `links` is scratch.
    ///
    /// A pair found `d` beyond what is allowed (exact parry distance, or the gap of the two
    /// bounding boxes, which is smaller) cannot touch before the joints that move its members
    /// relative to each other have moved them `d`: the schedule holds that slack, which
    /// [`Schedule::advance`] spends sample by sample, and the pair is tested again only when it
    /// is spent. Two members of one link never move relative to each other: tested once.
    fn contact_at(
        &self,
        q: &[f64],
        obstacles: &[ExactObstacle],
        margin: f64,
        schedule: &mut Schedule,
        links: &mut [Pose],
    ) -> Option<String> {
        self.chain.fk_all(q, links);
        let world: Vec<Pose> = self
            .parts
            .iter()
            .map(|p| self.base * links[p.link] * p.local)
            .collect();
        let boxes: Vec<Aabb> = self
            .parts
            .iter()
            .zip(&world)
            .map(|(p, pose)| p.aabb.transform_by(pose))
            .collect();
        let n_obs = obstacles.len();
        for (pi, (p, pose)) in self.parts.iter().zip(&world).enumerate() {
            for (oi, o) in obstacles.iter().enumerate() {
                let slot = pi * n_obs + oi;
                if schedule.slack[slot] > 0.0 {
                    continue;
                }
                let gap = box_gap(&boxes[pi], &o.aabb) - margin;
                let d = if gap > 0.0 {
                    gap
                } else {
                    let hull = p
                        .hull
                        .as_ref()
                        .and_then(|h| query::distance(pose, &**h, &o.pose, &*o.shape).ok());
                    match hull.map(|d| d.distance - margin) {
                        Some(lower) if lower > 0.0 => lower,
                        _ => match query::distance(pose, &*p.shape, &o.pose, &*o.shape) {
                            Ok(d) => d.distance - margin,
                            // A pair parry cannot measure counts as a contact: no blind pass.
                            Err(_) => -1.0,
                        },
                    }
                };
                if d <= 0.0 {
                    return Some(format!("{} with obstacle {}", p.label, o.name));
                }
                schedule.slack[slot] = d;
            }
        }
        let base = self.parts.len() * n_obs;
        for (s, &(i, j)) in self.pairs.iter().enumerate() {
            let (Some(a), Some(b)) = (self.parts.get(i), self.parts.get(j)) else {
                continue;
            };
            let slot = base + s;
            if schedule.slack[slot] > 0.0 {
                continue;
            }
            let gap = box_gap(&boxes[i], &boxes[j]);
            let d = if gap > 0.0 {
                gap
            } else {
                let (ha, hb) = (
                    a.hull.as_ref().unwrap_or(&a.shape),
                    b.hull.as_ref().unwrap_or(&b.shape),
                );
                match query::distance(&world[i], &**ha, &world[j], &**hb)
                    .ok()
                    .map(|d| d.distance)
                {
                    Some(lower) if lower > 0.0 => lower,
                    _ => match query::distance(&world[i], &*a.shape, &world[j], &*b.shape) {
                        Ok(d) => d.distance,
                        Err(_) => -1.0,
                    },
                }
            };
            if d <= 0.0 {
                return Some(format!("{} with {} (parts {i}, {j})", a.label, b.label));
            }
            schedule.slack[slot] = if schedule.joints[slot].is_empty() {
                f64::INFINITY
            } else {
                d
            };
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
        let mut joints: Vec<std::ops::Range<usize>> = Vec::new();
        for &m in &self.part_joints {
            joints.extend(std::iter::repeat_n(0..m, obstacles.len()));
        }
        for &(i, j) in &self.pairs {
            let (a, b) = (
                self.part_joints.get(i).copied().unwrap_or(0),
                self.part_joints.get(j).copied().unwrap_or(0),
            );
            joints.push(a.min(b)..a.max(b));
        }
        let mut schedule = Schedule {
            slack: vec![0.0; joints.len()],
            joints,
        };
        let mut prefix = vec![0.0; self.chain.dof() + 1];
        for seg in 0..waypoints.len().max(2) - 1 {
            let a = &waypoints[seg];
            let b = waypoints.get(seg + 1).unwrap_or(a);
            if a.len() != q.len() || b.len() != q.len() {
                return fail(samples, seg, 0.0, "wrong number of joint values".into());
            }
            let bound: f64 = a
                .iter()
                .zip(b)
                .zip(&self.radii)
                .map(|((x, y), r)| r * (x - y).abs())
                .sum();
            if !bound.is_finite() {
                return fail(samples, seg, 0.0, "non-finite joint values".into());
            }
            let n = ((bound / step).ceil() as usize).max(1);
            for (j, ((x, y), r)) in a.iter().zip(b).zip(&self.radii).enumerate() {
                prefix[j + 1] = prefix[j] + r * (x - y).abs() / n as f64;
            }
            // The first waypoint once; then every sample after the segment's start.
            let first = if seg == 0 { 0 } else { 1 };
            for k in first..=n {
                let t = k as f64 / n as f64;
                for (v, (x, y)) in q.iter_mut().zip(a.iter().zip(b)) {
                    *v = x + t * (y - x);
                }
                if !self.chain.within_limits(&q, LIMIT_TOLERANCE) {
                    return fail(samples + 1, seg, t, "outside the joint limits".into());
                }
                if k > 0 {
                    schedule.advance(&prefix);
                }
                let hit = self.contact_at(&q, obstacles, margin, &mut schedule, &mut links);
                samples += 1;
                if let Some(what) = hit {
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

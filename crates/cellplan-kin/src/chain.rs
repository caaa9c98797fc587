//! Serial kinematic chains and forward kinematics.
use cellplan_geom::{DQuat, DVec3, Pose};

/// How a joint moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotation about the axis, within limits.
    Revolute,
    /// Rotation about the axis without limits (limits are set to ±2π by the loader).
    Continuous,
    /// Translation along the axis.
    Prismatic,
}

/// A movable joint.
#[derive(Clone, Debug)]
pub struct Joint {
    /// Name in the URDF.
    pub name: String,
    /// Kind of motion.
    pub kind: JointKind,
    /// Unit axis in the joint frame (= child link frame).
    pub axis: DVec3,
    /// Lower limit (rad or m).
    pub lower: f64,
    /// Upper limit (rad or m).
    pub upper: f64,
    /// Velocity limit (rad/s or m/s); infinite when the URDF states none (or 0).
    pub max_velocity: f64,
    /// Effort limit as stated (0 when unknown).
    pub max_effort: f64,
}

/// A link on the chain from the root to the tip.
#[derive(Clone, Debug)]
pub struct ChainLink {
    /// Name in the URDF.
    pub name: String,
    /// Pose of this link's frame in its parent link's frame at zero joint value
    /// (identity for the root).
    pub origin: Pose,
    /// Index into [`Chain::joints`] of the joint that moves this link, `None` when fixed.
    pub joint: Option<usize>,
}

/// A serial chain from a root link to a tip link. Link 0 is the root.
#[derive(Clone, Debug)]
pub struct Chain {
    /// Links from root to tip.
    pub links: Vec<ChainLink>,
    /// Movable joints from root to tip; `q[i]` is the value of `joints[i]`.
    pub joints: Vec<Joint>,
}

impl Chain {
    /// Number of movable joints.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }
    /// Index of the link named `name`.
    pub fn link_index(&self, name: &str) -> Option<usize> {
        self.links.iter().position(|l| l.name == name)
    }
    /// Poses of every link (in the root frame) at joint values `q`; `out.len() == links.len()`.
    ///
    /// Does not allocate. Missing joint values (a `q` shorter than [`Chain::dof`]) count as
    /// zero; when `out` is shorter than the chain only its first links are written.
    pub fn fk_all(&self, q: &[f64], out: &mut [Pose]) {
        self.fk_rest(q, out, 0);
    }
    /// [`Chain::fk_all`] for the links from `start` on, the links before it already in `out`
    /// (as `fk_all` gives them): the same poses as `fk_all` over the whole chain, the first
    /// `start` computed once.
    pub fn fk_rest(&self, q: &[f64], out: &mut [Pose], start: usize) {
        let mut parent = match start.checked_sub(1) {
            None => Pose::IDENTITY,
            Some(k) => match out.get(k) {
                Some(&pose) => pose,
                None => return,
            },
        };
        for (link, slot) in self.links.iter().zip(out.iter_mut()).skip(start) {
            let mut pose = parent * link.origin;
            if let Some(j) = link.joint {
                let value = q.get(j).copied().unwrap_or(0.0);
                if let Some(joint) = self.joints.get(j) {
                    pose = joint.apply(pose, value);
                }
            }
            *slot = pose;
            parent = pose;
        }
    }
    /// Pose of the tip (last link) in the root frame.
    pub fn fk_tip(&self, q: &[f64]) -> Pose {
        let mut pose = Pose::IDENTITY;
        for link in &self.links {
            pose *= link.origin;
            if let Some(j) = link.joint {
                let value = q.get(j).copied().unwrap_or(0.0);
                if let Some(joint) = self.joints.get(j) {
                    pose = joint.apply(pose, value);
                }
            }
        }
        pose
    }
    /// Whether every joint value lies within its limits (with tolerance `tol`).
    ///
    /// False when `q` does not hold exactly one finite value per joint.
    pub fn within_limits(&self, q: &[f64], tol: f64) -> bool {
        q.len() == self.joints.len()
            && self
                .joints
                .iter()
                .zip(q)
                .all(|(j, &v)| v.is_finite() && v >= j.lower - tol && v <= j.upper + tol)
    }
    /// Name of the root link (empty for an empty chain).
    pub fn root_name(&self) -> &str {
        self.links.first().map(|l| l.name.as_str()).unwrap_or("")
    }
    /// Name of the tip link (empty for an empty chain).
    pub fn tip_name(&self) -> &str {
        self.links.last().map(|l| l.name.as_str()).unwrap_or("")
    }
    /// Index into [`Chain::links`] of the link moved by joint `j`.
    pub fn joint_link(&self, j: usize) -> Option<usize> {
        self.links.iter().position(|l| l.joint == Some(j))
    }
    /// The middle of every joint's range (0 for a joint without finite limits).
    pub fn mid_configuration(&self) -> Vec<f64> {
        self.joints.iter().map(Joint::mid).collect()
    }

    /// For each link `k`, the number of joints up to and including it: the joints that move
    /// link `k` are `0..joints_to()[k]` (joints are numbered root to tip).
    pub fn joints_to(&self) -> Vec<usize> {
        self.links
            .iter()
            .scan(0, |n, l| {
                if let Some(j) = l.joint {
                    *n = (*n).max(j + 1);
                }
                Some(*n)
            })
            .collect()
    }

    /// For each joint, an upper bound (m) on the distance from its axis of any point of the
    /// `bodies` it moves, valid in every configuration; 1 for a prismatic joint, 0 for a joint
    /// that moves none. A body is `(link, reach)`: the index of the link it hangs on and the
    /// largest distance of its points from that link's frame origin.
    ///
    /// Why it bounds: joint `j`'s axis passes through the origin `o_j` of the link it moves. A
    /// point `p` of a body on link `k` downstream of `j` is `p = o_j + Σ_m R_m·t_m +
    /// Σ_prismatic R·axis·q + R_k·p_local`, with `t_m` the fixed origin offsets of the links
    /// after `j` up to `k`, so `|p − o_j| ≤ Σ_m |t_m| + Σ_prismatic max(|lower|, |upper|) +
    /// reach`. Along a straight joint-space segment, `p` then moves at most
    /// `Σ_j r_j·|b_j − a_j|`.
    pub fn joint_radii(&self, bodies: &[(usize, f64)]) -> Vec<f64> {
        let offset = self.link_offsets();
        let mut radii = vec![0.0; self.dof()];
        for &(k, reach) in bodies {
            for (r, b) in radii.iter_mut().zip(self.body_radii_with(&offset, k, reach)) {
                *r = f64::max(*r, b);
            }
        }
        for (j, r) in radii.iter_mut().enumerate() {
            if self.joints[j].kind == JointKind::Prismatic {
                *r = 1.0;
            }
        }
        radii
    }

    /// [`Chain::joint_radii`] for one body, `(link, reach)`: for each joint, a bound on the
    /// distance from its axis of any point of that body, valid in every configuration (0 for
    /// a joint that does not move the body, 1 for a prismatic joint that does). Tighter than
    /// the whole chain's radii for a body near the root, and for the relative motion of two
    /// bodies: along a segment, the points of a body on link `k` move relative to a body on an
    /// earlier link `a` by at most `Σ_j r_j·|b_j − a_j|` over the joints between `a` and `k`
    /// (the joints before `a` move both alike).
    pub fn body_radii(&self, link: usize, reach: f64) -> Vec<f64> {
        self.body_radii_with(&self.link_offsets(), link, reach)
    }

    /// Each link's largest offset from its parent's origin: the length of its fixed origin
    /// translation plus a prismatic joint's largest travel.
    fn link_offsets(&self) -> Vec<f64> {
        self.links
            .iter()
            .map(|l| {
                let travel = l.joint.and_then(|j| self.joints.get(j)).map_or(0.0, |j| {
                    if j.kind == JointKind::Prismatic {
                        j.lower.abs().max(j.upper.abs())
                    } else {
                        0.0
                    }
                });
                l.origin.translation.length() + travel
            })
            .collect()
    }

    /// The axis of revolute joint `j` in the frame of link `k` — a point on it and its unit
    /// direction — when that line stands still in link `k`'s frame: when no other joint lies
    /// between `k` and the link `j` moves (`k` is that link or a fixed descendant of it, or a
    /// fixed ancestor of it, joined to it only by `j`). `None` otherwise, and for a prismatic
    /// joint.
    ///
    /// A body on such a link turns about this line as `j` turns (or, on the ancestor side,
    /// sees the bodies beyond `j` turn about it): how far the body reaches from the line bounds
    /// the motion that `j` causes, in every configuration.
    pub fn joint_axis_in(&self, j: usize, k: usize) -> Option<(DVec3, DVec3)> {
        let joint = self.joints.get(j)?;
        let lj = self.joint_link(j)?;
        if !joint.is_rotational() || k >= self.links.len() {
            return None;
        }
        let fixed = |links: &[ChainLink]| links.iter().all(|l| l.joint.is_none());
        if k >= lj {
            // Link k in the frame of link lj, through fixed origins only.
            if !fixed(&self.links[lj + 1..=k]) {
                return None;
            }
            let t = self.links[lj + 1..=k]
                .iter()
                .fold(Pose::IDENTITY, |t, l| t * l.origin);
            let inv = t.inverse();
            Some((inv.translation, inv.rotation * joint.axis))
        } else {
            // Link lj (at joint value 0: the axis does not turn with it) in link k's frame.
            if !fixed(&self.links[k + 1..lj]) {
                return None;
            }
            let t = self.links[k + 1..=lj]
                .iter()
                .fold(Pose::IDENTITY, |t, l| t * l.origin);
            Some((t.translation, t.rotation * joint.axis))
        }
    }

    fn body_radii_with(&self, offset: &[f64], k: usize, reach: f64) -> Vec<f64> {
        (0..self.dof())
            .map(|j| {
                let Some(lj) = self.joint_link(j) else {
                    return 0.0;
                };
                if k < lj || k >= offset.len() {
                    return 0.0;
                }
                if self.joints[j].kind == JointKind::Prismatic {
                    return 1.0;
                }
                offset[lj + 1..=k].iter().sum::<f64>() + reach
            })
            .collect()
    }
}

impl Joint {
    /// The motion of the joint at value `value`: a rotation about the axis (revolute,
    /// continuous) or a translation along it (prismatic), in the joint frame.
    #[inline]
    pub fn motion(&self, value: f64) -> Pose {
        match self.kind {
            JointKind::Revolute | JointKind::Continuous => {
                Pose::from_rotation(DQuat::from_axis_angle(self.axis, value))
            }
            JointKind::Prismatic => Pose::from_translation(self.axis * value),
        }
    }
    /// `frame * self.motion(value)`, computed with less work.
    #[inline]
    pub fn apply(&self, frame: Pose, value: f64) -> Pose {
        match self.kind {
            JointKind::Revolute | JointKind::Continuous => Pose::from_parts(
                frame.translation,
                frame.rotation * DQuat::from_axis_angle(self.axis, value),
            ),
            JointKind::Prismatic => Pose::from_parts(
                frame.translation + frame.rotation * (self.axis * value),
                frame.rotation,
            ),
        }
    }
    /// Whether the joint rotates (revolute or continuous).
    pub fn is_rotational(&self) -> bool {
        matches!(self.kind, JointKind::Revolute | JointKind::Continuous)
    }
    /// Middle of the range, or 0 when a limit is not finite.
    pub fn mid(&self) -> f64 {
        if self.lower.is_finite() && self.upper.is_finite() {
            0.5 * (self.lower + self.upper)
        } else {
            0.0
        }
    }
    /// Clamps `value` into `[lower, upper]` (NaN becomes the middle of the range).
    pub fn clamp(&self, value: f64) -> f64 {
        if value.is_nan() {
            return self.mid();
        }
        value.max(self.lower).min(self.upper)
    }
}

/// Distance between two poses: `(translation distance (m), rotation angle (rad, in [0, π]))`.
pub fn pose_error(a: &Pose, b: &Pose) -> (f64, f64) {
    let dp = (a.translation - b.translation).length();
    let d = a.rotation.conjugate() * b.rotation;
    let s = DVec3::new(d.x, d.y, d.z).length();
    (dp, 2.0 * s.atan2(d.w.abs()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn joint(name: &str, kind: JointKind, axis: DVec3, lower: f64, upper: f64) -> Joint {
        Joint {
            name: name.into(),
            kind,
            axis,
            lower,
            upper,
            max_velocity: 1.0,
            max_effort: 0.0,
        }
    }

    /// base → (revolute z at 1 m up) l1 → (revolute y, 0.5 m along x) l2 → (prismatic x,
    /// 0.3 m along x) l3 → (fixed, rotated 90° about z) tip.
    fn arm() -> Chain {
        Chain {
            links: vec![
                ChainLink {
                    name: "base".into(),
                    origin: Pose::IDENTITY,
                    joint: None,
                },
                ChainLink {
                    name: "l1".into(),
                    origin: Pose::translation(0.0, 0.0, 1.0),
                    joint: Some(0),
                },
                ChainLink {
                    name: "l2".into(),
                    origin: Pose::translation(0.5, 0.0, 0.0),
                    joint: Some(1),
                },
                ChainLink {
                    name: "l3".into(),
                    origin: Pose::translation(0.3, 0.0, 0.0),
                    joint: Some(2),
                },
                ChainLink {
                    name: "tip".into(),
                    origin: Pose::from_rotation(DQuat::from_rotation_z(FRAC_PI_2)),
                    joint: None,
                },
            ],
            joints: vec![
                joint("j1", JointKind::Revolute, DVec3::Z, -PI, PI),
                joint("j2", JointKind::Continuous, DVec3::Y, -2.0 * PI, 2.0 * PI),
                joint("j3", JointKind::Prismatic, DVec3::X, 0.0, 0.2),
            ],
        }
    }

    /// The axis of a joint in a link's frame is where forward kinematics puts it, in every
    /// configuration; links with another joint between have none.
    #[test]
    fn joint_axes_in_link_frames() {
        let c = arm();
        assert_eq!(c.joint_axis_in(2, 3), None, "prismatic");
        assert_eq!(c.joint_axis_in(0, 2), None, "j2 lies between");
        assert_eq!(c.joint_axis_in(1, 4), None, "j3 lies between");
        let mut poses = vec![Pose::IDENTITY; c.links.len()];
        for (j, k) in [(0, 0), (0, 1), (1, 1), (1, 2)] {
            let (p, d) = c.joint_axis_in(j, k).expect("a fixed line");
            assert!((d.length() - 1.0).abs() < 1e-12);
            for t in 0..20 {
                let t = t as f64 / 20.0;
                c.fk_all(&[3.0 * t - 1.5, 5.0 * t - 2.0, 0.2 * t], &mut poses);
                let lj = c.joint_link(j).unwrap();
                let (wp, wd) = (poses[lj].translation, poses[lj].rotation * c.joints[j].axis);
                let (kp, kd) = (poses[k].transform_point(p), poses[k].rotation * d);
                assert!((kd - wd).length() < 1e-12, "{j} in {k}: {kd:?} vs {wd:?}");
                assert!(
                    (kp - wp).cross(wd).length() < 1e-12,
                    "{j} in {k}: {kp:?} off the axis"
                );
            }
        }
    }

    #[test]
    fn joints_to_and_joint_radii() {
        let c = arm();
        assert_eq!(c.joints_to(), [0, 1, 2, 3, 3]);
        // A body of reach 0.1 on the tip, one on the base (moved by no joint).
        let radii = c.joint_radii(&[(4, 0.1), (0, 5.0)]);
        // j1: l2's 0.5 m, l3's 0.3 m plus its 0.2 m of travel, the reach.
        assert!((radii[0] - 1.1).abs() < 1e-12, "{radii:?}");
        assert!((radii[1] - 0.6).abs() < 1e-12, "{radii:?}");
        assert_eq!(radii[2], 1.0);
        // The bound holds: the tip's origin stays within radii[0] − 0.1 of j1's axis (z
        // through the origin) wherever the joints are.
        let mut poses = vec![Pose::IDENTITY; c.links.len()];
        for k in 0..50 {
            let t = k as f64 / 50.0;
            c.fk_all(&[3.0 * t - 1.5, 12.0 * t, 0.2 * t], &mut poses);
            let p = poses[4].translation;
            assert!((p.x * p.x + p.y * p.y).sqrt() <= radii[0] - 0.1 + 1e-12);
        }
        assert_eq!(c.joint_radii(&[]), [0.0, 0.0, 1.0]);
    }

    #[test]
    fn body_radii_bound_relative_motion() {
        let c = arm();
        // A body of reach 0.1 on l2: j1 carries it 0.5 m out, j2 only its reach, j3 not at all.
        assert_eq!(c.body_radii(2, 0.1), [0.6, 0.1, 0.0]);
        // On the tip it is the whole arm's bound for that body alone.
        assert_eq!(c.body_radii(4, 0.1), c.joint_radii(&[(4, 0.1)]));
        // The whole arm's radii are the largest of its bodies'.
        let whole = c.joint_radii(&[(4, 0.1), (2, 0.7)]);
        let (tip, l2) = (c.body_radii(4, 0.1), c.body_radii(2, 0.7));
        for (j, w) in whole.iter().enumerate() {
            assert_eq!(*w, tip[j].max(l2[j]));
        }
        // Relative motion: a point of the tip body seen from l1's frame moves along a segment by
        // at most Σ_{j after l1} r_j·|Δq_j| (the joints before l1 move both alike).
        let r = c.body_radii(4, 0.1);
        let p_local = DVec3::new(0.0, 0.06, 0.08);
        let (a, b): ([f64; 3], [f64; 3]) = ([0.4, -2.0, 0.0], [-1.1, 1.5, 0.2]);
        let bound: f64 = (1..3).map(|j| r[j] * (b[j] - a[j]).abs()).sum();
        let mut poses = vec![Pose::IDENTITY; c.links.len()];
        let seen = |q: &[f64], poses: &mut Vec<Pose>| {
            c.fk_all(q, poses);
            poses[1]
                .inverse()
                .transform_point(poses[4].transform_point(p_local))
        };
        let start = seen(&a, &mut poses);
        let mut worst = 0.0f64;
        for k in 0..=200 {
            let t = k as f64 / 200.0;
            let q: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x + t * (y - x)).collect();
            worst = worst.max((seen(&q, &mut poses) - start).length());
        }
        assert!(worst > 0.3 && worst <= bound, "moved {worst}, bound {bound}");
    }

    #[test]
    fn forward_kinematics_of_every_link() {
        let c = arm();
        let mut poses = vec![Pose::IDENTITY; c.links.len()];
        c.fk_all(&[0.0, 0.0, 0.0], &mut poses);
        assert!((poses[3].translation - DVec3::new(0.8, 0.0, 1.0)).length() < 1e-15);

        // Turn the base by 90°: the arm points along y. Pitch j2 by 90° about y: it points down.
        let q = [FRAC_PI_2, FRAC_PI_2, 0.1];
        c.fk_all(&q, &mut poses);
        assert!((poses[1].translation - DVec3::new(0.0, 0.0, 1.0)).length() < 1e-15);
        assert!((poses[2].translation - DVec3::new(0.0, 0.5, 1.0)).length() < 1e-15);
        // l3 sits 0.3 m along l2's x, plus 0.1 of travel, which now points down (-z).
        assert!(
            (poses[3].translation - DVec3::new(0.0, 0.5, 0.6)).length() < 1e-12,
            "{:?}",
            poses[3]
        );
        assert_eq!(c.fk_tip(&q), poses[4]);
        // Tip x axis = l3's y axis = base -x after the base turn.
        assert!((poses[4].rotation * DVec3::X - DVec3::new(-1.0, 0.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn apply_equals_composition_with_motion() {
        let frame = Pose::from_parts(DVec3::new(0.1, -0.2, 0.3), DQuat::from_rotation_y(0.7));
        for j in arm().joints {
            let (dp, dr) = pose_error(&j.apply(frame, 0.37), &(frame * j.motion(0.37)));
            assert!(dp < 1e-15 && dr < 1e-15, "{:?}", j.kind);
        }
    }

    #[test]
    fn the_rest_of_a_chain_continues_its_first_links() {
        let c = arm();
        let q = [0.3, -1.1, 0.15];
        let mut all = vec![Pose::IDENTITY; c.links.len()];
        c.fk_all(&q, &mut all);
        for start in 0..=c.links.len() {
            let mut split = vec![Pose::from_parts(DVec3::splat(9.0), DQuat::IDENTITY); c.links.len()];
            c.fk_all(&q, &mut split[..start]);
            c.fk_rest(&q, &mut split, start);
            assert_eq!(split, all, "split at {start}");
        }
    }

    #[test]
    fn short_inputs_do_not_panic() {
        let c = arm();
        let mut two = [Pose::IDENTITY; 2];
        c.fk_all(&[0.3], &mut two);
        assert!((two[1].translation.z - 1.0).abs() < 1e-15);
        assert_eq!(c.fk_tip(&[]), c.fk_tip(&[0.0, 0.0, 0.0]));
    }

    #[test]
    fn names_and_limits() {
        let c = arm();
        assert_eq!(c.link_index("l2"), Some(2));
        assert_eq!(c.link_index("nope"), None);
        assert_eq!(c.root_name(), "base");
        assert_eq!(c.tip_name(), "tip");
        assert_eq!(c.joint_link(2), Some(3));
        assert!(c.within_limits(&[0.0, 5.0, 0.2], 0.0));
        assert!(!c.within_limits(&[0.0, 5.0, 0.2 + 1e-6], 0.0));
        assert!(c.within_limits(&[0.0, 5.0, 0.2 + 1e-6], 1e-5));
        assert!(!c.within_limits(&[0.0, 5.0], 0.0));
        assert!(!c.within_limits(&[f64::NAN, 0.0, 0.0], 1.0));
        assert_eq!(c.mid_configuration(), vec![0.0, 0.0, 0.1]);
    }

    #[test]
    fn pose_error_measures_both_parts() {
        let a = Pose::translation(1.0, 0.0, 0.0);
        let b = Pose::from_parts(DVec3::new(1.0, 2.0, 0.0), DQuat::from_rotation_x(0.25));
        let (dp, dr) = pose_error(&a, &b);
        assert!((dp - 2.0).abs() < 1e-15);
        assert!((dr - 0.25).abs() < 1e-15);
        // q and -q are the same rotation.
        let c = Pose::from_parts(b.translation, -b.rotation);
        assert!(pose_error(&b, &c).1 < 1e-15);
        // Tiny angles keep their precision.
        let d = Pose::from_rotation(DQuat::from_rotation_z(1e-12));
        assert!((pose_error(&Pose::IDENTITY, &d).1 - 1e-12).abs() < 1e-24);
    }
}

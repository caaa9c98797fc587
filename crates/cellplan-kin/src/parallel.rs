//! Closed-form inverse kinematics of six-joint arms with three parallel axes and an offset
//! wrist, the Universal Robots kind (Hawkins 2013 solves the UR5 and UR10 by their DH
//! parameters): joint 1 vertical; joints 2, 3 and 4 parallel and square to it; joint 5 square
//! to joint 4 and meeting it; joint 6 square to joint 5 and meeting it. Nothing of the robot's
//! own conventions is assumed: [`ParallelIk::derive`] measures the joint lines at the chain's
//! zero, and the solver turns each joint by the angle that carries its part of the arm from
//! where it is at zero to where the target needs it, about the joint's own axis. Every branch
//! is checked by forward kinematics before it is given out.
//!
//! With the elbow's point `P45` (where joints 4 and 5 meet) and the wrist's point `P56` (joints
//! 5 and 6):
//! - the planar part (joints 2–4) moves points square to its axis direction `n`, and joint 5's
//!   axis is square to `n`, so `P56 · n` is the same in every configuration: that fixes joint 1
//!   (two branches);
//! - joint 5 turns joint 6's axis about its own, square to `n`: the angle between `n` and joint
//!   6's axis fixes joint 5 (two branches) and the direction of joint 5's axis;
//! - joint 6 then turns the flange about its axis; `P45` lies back along joint 5's axis from
//!   `P56`, and the planar part reaches it like a two-link arm (two branches), joint 4 turning
//!   the last link onto joint 5's axis.
use crate::axes::{EPS, angle_about, closest, level_base, lines};
use crate::ik::finds_again;
use crate::{Chain, IkSolver, limit_variants, pose_error, wrap_angle};
use cellplan_geom::{DMat3, DVec3, Pose};

/// Configurations [`ParallelIk::derive`] checks its solver at.
const CHECKS: usize = 20;
/// Largest mismatch (m, rad) between a branch's forward kinematics and the target.
const MATCH: f64 = 1e-6;
/// How close (rad, per joint) [`ParallelIk::derive`]'s check wants a configuration found
/// again. The URDFs state their right angles to nine digits (`1.570796325`), so the axes are
/// parallel only to about 1e-9 rad; near the elbow's or the wrist's singularity the joint
/// values then move by up to ~1e-4 rad for the same tip (checked to [`MATCH`]), while another
/// branch differs by far more.
const FOUND: f64 = 1e-3;
/// Below this `sin` of joint 6's angle to the parallel axes, the wrist is singular (joints 4
/// and 6 aligned): no branch is given there (the planner's candidates come from many poses).
const SINGULAR: f64 = 1e-9;

/// The closed-form solver of a chain with three parallel axes and an offset wrist (see the
/// module documentation). Made by [`ParallelIk::derive`].
#[derive(Clone, Debug)]
pub struct ParallelIk {
    chain: Chain,
    /// The root frame to the base (the root moved level onto joint 1's axis).
    root_to_base: Pose,
    /// Joint 1's axis is `sign1 · z`.
    sign1: f64,
    /// At zero, in the base frame: the joints' directions (`u[1]`, `u[2]` and `u[3]` are
    /// parallel: `u[1]` is the parallel axes' direction `n`).
    u: [DVec3; 6],
    /// At zero: a point of joint 2's axis.
    a2: DVec3,
    /// `P56 − P45` along joint 5's axis (signed), and `P56 · n`.
    e: f64,
    lateral: f64,
    /// The planar link from joint 3's axis to joint 4's: its length.
    l3: f64,
    /// In the tip frame: `P56`, joint 6's axis and a direction square to it.
    p56_tip: DVec3,
    u6_tip: DVec3,
    v6_tip: DVec3,
    /// The joint angles' references at zero: joint 5 (from `n` to joint 6's axis about joint
    /// 5's), joint 6 (from joint 5's axis to `v6` about joint 6's), the elbow (link 2 to link 3
    /// about joint 3's axis) and joint 4 (link 3 to joint 5's axis about joint 4's).
    ref5: f64,
    ref6: f64,
    ref3: f64,
    ref4: f64,
    /// Link 2 at zero, square to `n`.
    e2: DVec3,
}

/// `v` without its part along the unit `n`.
fn flat(v: DVec3, n: DVec3) -> DVec3 {
    v - v.dot(n) * n
}

impl ParallelIk {
    /// The solver for `chain` when it is an arm with three parallel axes and an offset wrist
    /// (see the module documentation), checked: its inverse must find 20 deterministic
    /// pseudo-random configurations within the limits again from their tips. `None` for any
    /// other chain.
    pub fn derive(chain: &Chain) -> Option<Self> {
        let mut l = lines(chain)?;
        let shift = level_base(&mut l)?;
        let z = DVec3::Z;
        let n = l[1].dir;
        let parallel = |d: DVec3| d.cross(n).length() <= EPS;
        if n.dot(z).abs() > EPS || !parallel(l[2].dir) || !parallel(l[3].dir) {
            return None;
        }
        // Joints 4 and 5 meet, square; joints 5 and 6 meet, square.
        let (p4, p45) = closest(&l[3], &l[4])?;
        let (p5, p56) = closest(&l[4], &l[5])?;
        if (p4 - p45).length() > EPS
            || (p5 - p56).length() > EPS
            || l[3].dir.dot(l[4].dir).abs() > EPS
            || l[4].dir.dot(l[5].dir).abs() > EPS
        {
            return None;
        }
        let (a2, a3) = (l[1].point, l[2].point);
        let e2 = flat(a3 - a2, n);
        let e3 = flat(p45 - a3, n);
        let l3 = e3.length();
        if e2.length() < EPS || l3 < EPS {
            return None;
        }
        let u: [DVec3; 6] = std::array::from_fn(|j| l[j].dir);
        let base = Pose::from_translation(shift);
        let tip = base.inverse() * chain.fk_tip(&[0.0; 6]);
        let to_tip = tip.inverse();
        let u6_tip = (to_tip.rotation * u[5]).normalize();
        let helper = if u6_tip.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
        let v6_tip = u6_tip.cross(helper).normalize();
        let v6 = tip.rotation * v6_tip;
        let ik = ParallelIk {
            chain: chain.clone(),
            root_to_base: base.inverse(),
            sign1: l[0].dir.z.signum(),
            u,
            a2,
            e: (p56 - p45).dot(u[4]),
            lateral: p56.dot(n),
            l3,
            p56_tip: to_tip.transform_point(p56),
            u6_tip,
            v6_tip,
            ref5: angle_about(n, u[5], u[4]),
            ref6: angle_about(u[4], v6, u[5]),
            ref3: angle_about(e2, e3, u[2]),
            ref4: angle_about(e3, u[4], u[3]),
            e2,
        };
        ik.finds_again().then_some(ik)
    }

    /// Whether the inverse finds [`CHECKS`] deterministic pseudo-random configurations within
    /// the limits again (up to whole turns) from their tips.
    fn finds_again(&self) -> bool {
        finds_again(&self.chain, 0x0_9a2a_11e1, CHECKS, FOUND, |tip, out| {
            self.branches(tip, out)
        })
    }

    /// Every branch (up to 8) that puts the tip at `target` (root frame), joint values in
    /// (−π, π], each checked by forward kinematics; appended to `out`.
    fn branches(&self, target: &Pose, out: &mut Vec<[f64; 6]>) {
        let t = self.root_to_base * *target;
        let p56 = t.transform_point(self.p56_tip);
        let u6 = (t.rotation * self.u6_tip).normalize();
        let v6 = t.rotation * self.v6_tip;
        // Joint 1: P56 · n(φ) = lateral, with n(φ) = cos φ · n + sin φ · (z × n).
        let (n0, l2) = (self.u[1], self.e2.length());
        let side = DVec3::Z.cross(n0);
        let (a, b) = (p56.dot(n0), p56.dot(side));
        let r = a.hypot(b);
        if r < EPS || self.lateral.abs() > r {
            return;
        }
        let spread = (self.lateral / r).clamp(-1.0, 1.0).acos();
        for phi in [b.atan2(a) + spread, b.atan2(a) - spread] {
            let turn = DMat3::from_rotation_z(phi);
            let n = turn * n0;
            let u: [DVec3; 6] = std::array::from_fn(|j| turn * self.u[j]);
            let q1 = self.sign1 * phi;
            // Joint 5: the angle from n to joint 6's axis about joint 5's.
            let c = n.dot(u6).clamp(-1.0, 1.0);
            for gamma in [c.acos(), -c.acos()] {
                let s = gamma.sin();
                if s.abs() < SINGULAR {
                    continue;
                }
                let u5 = n.cross(u6) / s;
                let q5 = gamma - self.ref5;
                let q6 = angle_about(u5, flat(v6, u6), u6) - self.ref6;
                // The elbow's point, reached by the planar part from joint 2's axis.
                let p45 = p56 - self.e * u5;
                let a2 = turn * self.a2;
                let w = flat(p45 - a2, n);
                let d = w.length();
                if d < EPS {
                    continue;
                }
                let cos_in = (l2 * l2 + d * d - self.l3 * self.l3) / (2.0 * l2 * d);
                if !(-1.0 - 1e-12..=1.0 + 1e-12).contains(&cos_in) {
                    continue;
                }
                let alpha = cos_in.clamp(-1.0, 1.0).acos();
                let wh = w / d;
                for al in [alpha, -alpha] {
                    let e2 = l2 * (al.cos() * wh + al.sin() * n.cross(wh));
                    let e3 = w - e2;
                    let q2 = angle_about(turn * self.e2, e2, u[1]);
                    let q3 = angle_about(e2, e3, u[2]) - self.ref3;
                    let q4 = angle_about(e3, u5, u[3]) - self.ref4;
                    let q = [q1, q2, q3, q4, q5, q6].map(wrap_angle);
                    let (dp, da) = pose_error(&self.chain.fk_tip(&q), target);
                    if dp <= MATCH && da <= MATCH {
                        out.push(q);
                    }
                }
            }
        }
    }
}

impl IkSolver for ParallelIk {
    fn solve(&self, target: &Pose, out: &mut Vec<Vec<f64>>) -> usize {
        let mut found = Vec::with_capacity(8);
        self.branches(target, &mut found);
        for q in &found {
            limit_variants(q, &self.chain, out);
        }
        found.len()
    }
}

//! How far an arm's bodies can move: bounds per joint, per body and per self pair (the motion
//! bounds of [`super::ArmValidity`]'s segment steps), and paper 002's point-speed weights.
use super::{Arm, ArmValidity};
use crate::plan::SegmentMotion;
use cellplan_geom::{DVec3, Pose};
use std::ops::Range;

/// For each joint, an upper bound (m) on the distance from its axis of any point of any body it
/// moves, valid in every configuration (1 for a prismatic joint).
///
/// [`cellplan_kin::Chain::joint_radii`] (which says why it bounds motion) with each body's reach from its
/// link's origin taken from its sphere cover: at most `|c| + r` over the spheres `(c, r)`,
/// which contain the body. The root is fixed in the world, so the bound holds in world
/// coordinates.
pub fn joint_radii(arm: &Arm) -> Vec<f64> {
    let bodies: Vec<(usize, f64)> = arm
        .body_links
        .iter()
        .enumerate()
        .filter_map(|(i, &link)| Some((link, body_reach(arm, i)?)))
        .collect();
    arm.chain.joint_radii(&bodies)
}

/// The largest distance of body `i`'s points from its link's origin, from its cover (`None`
/// for a body without shapes).
fn body_reach(arm: &Arm, i: usize) -> Option<f64> {
    arm.world
        .body_cover(arm.group, i)
        .iter()
        .map(|s| s.centre.length() + s.radius)
        .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))
}

/// The chain link body `i` hangs on (the tip for a body without one).
fn body_link(arm: &Arm, i: usize) -> usize {
    let tip = arm.chain.links.len().saturating_sub(1);
    arm.body_links.get(i).copied().unwrap_or(tip).min(tip)
}

/// The number of joints that move body `i`: joints `0..moved_by(arm, i)`.
pub(super) fn moved_by(arm: &Arm, i: usize) -> usize {
    arm.chain.joints_to().get(body_link(arm, i)).copied().unwrap_or(0)
}

/// Body `i`'s radii: [`cellplan_kin::Chain::body_radii`] with its reach taken from its cover, and for the
/// last joint before its link — whose axis stands still in the body's frame
/// ([`cellplan_kin::Chain::joint_axis_in`]) — the reach of its cover from that axis, where smaller. A body
/// turning about an axis moves no farther than its points lie from it: the gripper's bodies,
/// centred on the wrist's last axis, reach a few centimetres from it, where the bound through
/// the link's origin counts the whole offset to the flange.
pub(super) fn body_radii(arm: &Arm, i: usize) -> Vec<f64> {
    let link = body_link(arm, i);
    let mut radii = arm
        .chain
        .body_radii(link, body_reach(arm, i).unwrap_or(f64::INFINITY));
    let last = arm
        .chain
        .joints_to()
        .get(link)
        .copied()
        .unwrap_or(0)
        .checked_sub(1);
    if let Some(j) = last
        && let Some(r) = axis_reach(arm, i, j, link)
        && let Some(slot) = radii.get_mut(j)
    {
        *slot = slot.min(r);
    }
    radii
}

/// The radii bounding how fast the distance of a self pair can fall: those of its distal body
/// (`far`, its [`body_radii`]), except for the first joint between the two, `first`, whose
/// axis stands still in the frame of the proximal body `near`: turning it turns the distal
/// body about that axis, or equally the proximal body about it the other way, so the distance
/// changes no faster than the nearer of the two bodies' reaches from the axis allows. The
/// upper arm reaches 0.64 m from the UR5's base axis; the base, 0.11 m.
pub(super) fn pair_radii(arm: &Arm, near: usize, first: usize, far: &[f64]) -> Vec<f64> {
    let mut radii = far.to_vec();
    if let Some(r) = axis_reach(arm, near, first, body_link(arm, near))
        && let Some(slot) = radii.get_mut(first)
    {
        *slot = slot.min(r);
    }
    radii
}

/// The largest distance of body `i`'s points (its cover, in the frame of its link `link`) from
/// the axis of joint `j` when that axis stands still in the link's frame; `None` when it does
/// not, or for a body without shapes.
fn axis_reach(arm: &Arm, i: usize, j: usize, link: usize) -> Option<f64> {
    let (p, d) = arm.chain.joint_axis_in(j, link)?;
    let cover = arm.world.body_cover(arm.group, i);
    (!cover.is_empty()).then(|| {
        cover
            .iter()
            .map(|s| (s.centre - p).cross(d).length() + s.radius)
            .fold(0.0, f64::max)
    })
}

/// Paper 002 §2.4's joint weights at `q`: for each joint `j`, `w_j(q) = max_p ‖∂p/∂q_j‖₁` over
/// the points `p` of the bodies joint `j` moves — bounded from above over their sphere covers,
/// which contain them: `‖a_j × (c − o_j)‖₁ + √3·r` for a sphere `(c, r)` and a turning joint
/// with unit axis `a_j` through `o_j` (`‖a_j × δ‖₁ ≤ √3 |δ|`), `‖a_j‖₁` for a sliding one. 0 for a
/// joint that moves no body. Each sphere holds some body point within `r` of its centre, so the
/// bound exceeds the exact maximum by at most `2√3` times the largest radius. Unlike
/// [`joint_radii`], which hold in every configuration, these hold at `q` only (to first order
/// nearby).
pub fn point_speed_weights(arm: &Arm, q: &[f64]) -> Vec<f64> {
    let chain = arm.chain;
    let mut links = Vec::new();
    let mut bodies = Vec::new();
    arm.body_poses(q, &mut links, &mut bodies);
    let moved: Vec<usize> = (0..arm.body_links.len()).map(|i| moved_by(arm, i)).collect();
    (0..chain.dof())
        .map(|j| {
            let (Some(joint), Some(k)) = (chain.joints.get(j), chain.joint_link(j)) else {
                return 0.0;
            };
            let frame = arm.base * links.get(k).copied().unwrap_or(Pose::IDENTITY);
            let a = (frame.rotation * joint.axis).normalize_or_zero();
            let o = frame.translation;
            let l1 = |v: cellplan_geom::DVec3| v.x.abs() + v.y.abs() + v.z.abs();
            // Every sphere of every body joint `j` moves.
            let mut spheres = bodies
                .iter()
                .enumerate()
                .filter(|(i, _)| moved.get(*i).is_some_and(|&m| j < m))
                .flat_map(|(i, pose)| arm.world.body_cover(arm.group, i).iter().map(move |s| (pose, s)));
            if !joint.is_rotational() {
                return if spheres.next().is_some() { l1(a) } else { 0.0 };
            }
            spheres
                .map(|(pose, s)| l1(a.cross(pose.transform_point(s.centre) - o)) + 3f64.sqrt() * s.radius)
                .fold(0.0, f64::max)
        })
        .collect()
}

/// Where the joint axes stand at one sample ([`ArmValidity::posed_bound`]).
#[derive(Clone, Debug, Default)]
pub(super) struct PosedAxes {
    /// Per joint: a point on its axis and its unit direction, in the world (`None` for a
    /// sliding joint). Empty when the checker's `posed_radii` is off.
    axes: Vec<Option<(DVec3, DVec3)>>,
}

impl PosedAxes {
    /// The axes of `v`'s arm at the link poses `links` (root frame).
    pub(super) fn place(&mut self, v: &ArmValidity, links: &[Pose]) {
        self.axes.clear();
        if !v.posed_radii {
            return;
        }
        self.axes.extend(v.axes.iter().map(|axis| {
            let &(link, local) = axis.as_ref()?;
            let frame = v.arm.base * *links.get(link)?;
            Some((frame.translation, frame.rotation * local))
        }));
    }
}

impl ArmValidity<'_> {
    /// A part's motion bound over a step of up to `t`, from where body `body` stands at the
    /// sample (posed in `bodies`; the axes in `posed`): `static_bound`, or the smaller
    /// [`SegmentMotion::bound_at`] with the reach of the body's outer sphere from each axis and
    /// the part's `drift` ([`SegmentMotion::drift_with`] over its joints and radii). The arm
    /// folded, its tool lies much nearer the first axes than the whole chain's length, which
    /// the radii that hold everywhere must allow for.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(super) fn posed_bound(
        &self,
        static_bound: f64,
        drift: f64,
        body: usize,
        joints: &Range<usize>,
        bodies: &[Pose],
        posed: &PosedAxes,
        motion: &SegmentMotion,
        t: f64,
    ) -> f64 {
        if posed.axes.is_empty() || static_bound <= 0.0 {
            return static_bound;
        }
        let (Some(Some(sphere)), Some(pose)) = (self.outer.get(body), bodies.get(body)) else {
            return static_bound;
        };
        let centre = pose.rotation * sphere.centre + pose.translation;
        let reach = |j: usize| match posed.axes.get(j) {
            Some(Some((point, dir))) => (centre - *point).cross(*dir).length() + sphere.radius,
            _ => f64::INFINITY,
        };
        motion.bound_at(joints, reach, drift, t).min(static_bound)
    }
}

//! Where an arm's bodies stand at a configuration ([`Arm::body_poses`], posed in two steps
//! for a validity check that may stop early), and the tool's straight retract along its axis
//! ([`tool_retract`]).
use super::Arm;
use cellplan_geom::{DVec3, Pose};
use cellplan_kin::Chain;

impl Arm<'_> {
    /// World poses of the arm's bodies at `q` into `out` (cleared first); `links` is scratch.
    pub fn body_poses(&self, q: &[f64], links: &mut Vec<Pose>, out: &mut Vec<Pose>) {
        self.body_poses_before(q, links, out, usize::MAX);
    }

    /// [`Arm::body_poses`] for the bodies on the chain's links before `end` only: the others
    /// get the identity, to be posed by [`Arm::body_poses_from`]; `links` holds the first
    /// `end` link poses. Whether some body was left out.
    pub(super) fn body_poses_before(
        &self,
        q: &[f64],
        links: &mut Vec<Pose>,
        out: &mut Vec<Pose>,
        end: usize,
    ) -> bool {
        let n = self.chain.links.len();
        links.resize(n, Pose::IDENTITY);
        self.chain.fk_all(q, &mut links[..end.min(n)]);
        out.clear();
        out.resize(self.body_links.len(), Pose::IDENTITY);
        self.compose(links, out, ..end)
    }

    /// The rest of [`Arm::body_poses_before`] with the same `end`: the link poses from `end` on
    /// and the poses of the bodies on them.
    pub(super) fn body_poses_from(&self, q: &[f64], links: &mut [Pose], out: &mut [Pose], end: usize) {
        self.chain.fk_rest(q, links, end);
        self.compose(links, out, end..);
    }

    /// Each body on a link within `range` posed in `out`: the world pose of its link (`links`,
    /// root frame). Whether some body's link lies outside `range`.
    fn compose(&self, links: &[Pose], out: &mut [Pose], range: impl std::ops::RangeBounds<usize>) -> bool {
        // A body on the same link as the one before shares its pose: composed once (and not at
        // all on a base at the world's origin, whose composition changes no value but the sign
        // of a zero).
        let at_origin = self.base.rotation == Pose::IDENTITY.rotation && self.base.translation == DVec3::ZERO;
        let mut last: Option<(usize, Pose)> = None;
        let mut outside = false;
        for (&l, slot) in self.body_links.iter().zip(out.iter_mut()) {
            if !range.contains(&l) {
                outside = true;
                continue;
            }
            let pose = match last {
                Some((k, pose)) if k == l => pose,
                _ if at_origin => links.get(l).copied().unwrap_or(Pose::IDENTITY),
                _ => self.base * links.get(l).copied().unwrap_or(Pose::IDENTITY),
            };
            last = Some((l, pose));
            *slot = pose;
        }
        outside
    }
}

/// The configurations that move the tool point `tcp` (a pose in the chain's tip frame) from
/// where it is at `q` backwards along its own z axis by `distance` (m), its orientation kept:
/// the retract before a leg, and reversed the approach after it (a probe, a gripper or a gun
/// leaves and reaches its work along its axis). The line is followed by damped least squares
/// in steps of at most `step` (m), each from the previous configuration; the first
/// configuration is `q`. `None` when the line leaves the reachable space or the joint limits,
/// or when a joint would jump (a change of branch) — a straight line of the tool is then not a
/// continuous motion of the arm.
pub fn tool_retract(chain: &Chain, tcp: &Pose, q: &[f64], distance: f64, step: f64) -> Option<Vec<Vec<f64>>> {
    use cellplan_kin::ik::{DlsIk, DlsParams};
    if !(distance.is_finite() && step.is_finite() && distance > 0.0 && step > 0.0) {
        return None;
    }
    let steps = (distance / step).ceil().clamp(1.0, 1000.0) as usize;
    let tip = chain.fk_tip(q);
    let targets: Vec<Pose> = (1..=steps)
        .map(|k| {
            let back = Pose::translation(0.0, 0.0, -distance * k as f64 / steps as f64);
            tip * *tcp * back * tcp.inverse()
        })
        .collect();
    let ik = DlsIk::new(
        chain,
        DlsParams {
            seeds: 1,
            ..DlsParams::default()
        },
    );
    // A joint may turn at most about 0.3 rad per step of at most `step`: far more than a
    // millimetre-scale step needs anywhere but next to a singularity.
    let mut path = vec![q.to_vec()];
    path.extend(ik.follow(q, &targets, 0.3)?);
    path.iter().all(|c| chain.within_limits(c, 1e-9)).then_some(path)
}

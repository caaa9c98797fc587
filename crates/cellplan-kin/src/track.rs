//! Inverse kinematics of a six-joint arm on a linear track (a prismatic first joint): the
//! track's position is sampled where the arm works best for the target, and the arm's own
//! closed form (OPW read off the URDF, see [`crate::OpwIk::derive`]) gives every branch at
//! each sample. A track adds one degree of freedom, so a target has a line of solutions; the
//! samples are the track position that puts joint 1's axis level with the target's wrist
//! centre (the arm reaching straight out to the side) and positions [`STEP`] apart around it,
//! [`SAMPLES`] in all, within the track's limits ([`TrackIk::samples`]).
use crate::ik::random_within_a_turn;
use crate::{Chain, ChainLink, IkSolver, JointKind, OpwIk, pose_error};
use cellplan_geom::{DVec3, Pose};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Track positions tried per target, at most (the nearest to the arm-beside-the-target position,
/// [`STEP`] apart, within the track's limits).
pub const SAMPLES: usize = 5;
/// Distance between two track positions tried (m).
pub const STEP: f64 = 0.4;
/// Largest mismatch (m, rad) between a solution's forward kinematics and the target.
const MATCH: f64 = 1e-6;
/// Targets [`TrackIk::derive`] checks the solver on.
const CHECKS: usize = 20;

/// The solver of an arm on a linear track (see the module documentation). Made by
/// [`TrackIk::derive`].
#[derive(Clone, Debug)]
pub struct TrackIk {
    chain: Chain,
    /// The arm alone (the chain from the carriage on), and its solver.
    arm: OpwIk,
    /// The carriage's pose in the root frame at track position 0, and the track's direction in
    /// the root frame.
    carriage: Pose,
    axis: DVec3,
    /// The wrist centre in the tip frame (where the arm's joints 4–6 meet), and joint 1's axis
    /// point in the carriage frame.
    wrist_tip: DVec3,
    shoulder: DVec3,
}

impl TrackIk {
    /// The solver for `chain` when its first joint is prismatic and the six rotational joints
    /// after it form an arm whose OPW parameters can be read off the URDF; checked on 20
    /// targets of random configurations (every solution must reach its target, and some must
    /// be found). `None` for any other chain.
    pub fn derive(chain: &Chain) -> Option<Self> {
        if chain.dof() != 7
            || chain.joints[0].kind != JointKind::Prismatic
            || !chain.joints[1..].iter().all(|j| j.is_rotational())
        {
            return None;
        }
        let moved = chain.joint_link(0)?;
        // The arm alone: the links from the carriage on, the carriage as its root.
        let mut links: Vec<ChainLink> = chain.links[moved..].to_vec();
        links[0] = ChainLink {
            name: links[0].name.clone(),
            origin: Pose::IDENTITY,
            joint: None,
        };
        for l in &mut links {
            l.joint = l.joint.map(|j| j - 1);
        }
        let arm_chain = Chain {
            links,
            joints: chain.joints[1..].to_vec(),
        };
        let arm = OpwIk::derive(&arm_chain)?;
        let carriage = chain.links[..=moved]
            .iter()
            .fold(Pose::IDENTITY, |p, l| p * l.origin);
        let axis = (carriage.rotation * chain.joints[0].axis).normalize();
        let p = arm.params();
        // At the arm's zero, the wrist centre is (a1 + a2, b, c1 + c2 + c3) in the OPW base, and
        // the flange c4 beyond it along the flange's z axis.
        let base = arm.base();
        let wrist_zero = base.transform_point(DVec3::new(p.a1 + p.a2, p.b, p.c1 + p.c2 + p.c3));
        let tip_zero = arm_chain.fk_tip(&[0.0; 6]);
        let ik = TrackIk {
            chain: chain.clone(),
            carriage,
            axis,
            wrist_tip: tip_zero.inverse().transform_point(wrist_zero),
            shoulder: base.translation,
            arm,
        };
        ik.checks_out().then_some(ik)
    }

    /// Whether the solver finds solutions for the tips of [`CHECKS`] deterministic
    /// pseudo-random configurations within the limits, each reaching its tip.
    fn checks_out(&self) -> bool {
        let mut rng = ChaCha8Rng::seed_from_u64(0x0_7ac4_0001);
        let mut out = Vec::new();
        let mut found = 0;
        for _ in 0..CHECKS {
            let mut q = vec![0.0; self.chain.dof()];
            random_within_a_turn(&self.chain, &mut rng, &mut q);
            let target = self.chain.fk_tip(&q);
            out.clear();
            self.solve(&target, &mut out);
            if out.iter().any(|s| {
                let (dp, da) = pose_error(&self.chain.fk_tip(s), &target);
                dp > MATCH || da > MATCH
            }) {
                return false;
            }
            found += usize::from(!out.is_empty());
        }
        found * 2 >= CHECKS
    }

    /// The track positions tried for `target` (root frame): the [`SAMPLES`] positions
    /// [`STEP`] apart within the track's limits nearest the one that puts joint 1's axis level
    /// with the target's wrist centre along the track (that position clamped onto the track
    /// first), nearest first.
    pub fn samples(&self, target: &Pose) -> Vec<f64> {
        let track = &self.chain.joints[0];
        let wrist = target.transform_point(self.wrist_tip);
        let shoulder = self.carriage.transform_point(self.shoulder);
        let ideal = (wrist - shoulder).dot(self.axis);
        let centre = ideal.clamp(track.lower, track.upper);
        let reach = SAMPLES as i64;
        let mut out: Vec<f64> = (-reach..=reach)
            .map(|k| centre + k as f64 * STEP)
            .filter(|s| *s >= track.lower && *s <= track.upper)
            .collect();
        out.sort_by(|a, b| {
            (a - ideal)
                .abs()
                .total_cmp(&(b - ideal).abs())
                .then(a.total_cmp(b))
        });
        out.truncate(SAMPLES);
        out
    }
}

impl IkSolver for TrackIk {
    fn solve(&self, target: &Pose, out: &mut Vec<Vec<f64>>) -> usize {
        let mut n = 0;
        let mut arm = Vec::new();
        let mut q = vec![0.0; 7];
        for s in self.samples(target) {
            let carriage = self.carriage * Pose::from_translation(self.chain.joints[0].axis * s);
            arm.clear();
            // The arm's solutions come within its limits, each whole-turn variant included.
            n += self.arm.solve(&(carriage.inverse() * *target), &mut arm);
            for a in &arm {
                q[0] = s;
                q[1..].copy_from_slice(a);
                let (dp, da) = pose_error(&self.chain.fk_tip(&q), target);
                if dp <= MATCH && da <= MATCH {
                    out.push(q.clone());
                }
            }
        }
        n
    }
}

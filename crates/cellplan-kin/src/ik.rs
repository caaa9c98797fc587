//! Inverse kinematics on a URDF chain.
use crate::{Chain, KinError, OpwParameters, RobotModel, pose_error};
use cellplan_geom::{DQuat, DVec3, Pose};
use nalgebra::{Matrix6, Vector6};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::cmp::Ordering;
use std::f64::consts::{PI, TAU};
use std::path::PathBuf;

/// Solves for joint values putting the chain tip at a pose given in the chain root frame.
pub trait IkSolver: Send + Sync {
    /// Appends to `out` every solution within the joint limits (for revolute joints whose range
    /// exceeds a turn, each ±2π variant that fits). Returns how many solutions existed before
    /// limit filtering (so a caller can tell "unreachable" from "outside the limits").
    fn solve(&self, target: &Pose, out: &mut Vec<Vec<f64>>) -> usize;
}

/// Tolerance (rad or m) by which a joint value may lie outside its limits and still count
/// as inside (it is then clamped onto the limit).
pub const LIMIT_TOLERANCE: f64 = 1e-9;

/// At most this many turns either side of a value are tried by [`limit_variants`] (guards
/// against absurd limits).
const MAX_TURNS: f64 = 4.0;

/// Appends to `out` every variant `q + 2πk` (per joint, `k` integer, revolute joints only) that
/// lies within `[lower, upper]`; none when a joint cannot be brought into range.
///
/// A value within [`LIMIT_TOLERANCE`] of a limit counts as inside and is clamped onto it, so
/// every variant passes `chain.within_limits(v, 0.0)`. Prismatic joints are only checked.
/// Order: lexicographic, ascending, the first joint varying slowest. Nothing is appended when
/// `q` does not hold one finite value per joint.
pub fn limit_variants(q: &[f64], chain: &Chain, out: &mut Vec<Vec<f64>>) {
    let n = chain.joints.len();
    if q.len() != n {
        return;
    }
    // Per joint: the value, the first admissible number of turns and how many fit. A variant is
    // `v + k·2π` in one step, so that k = 0 gives `v` itself, bit for bit.
    let mut ranges: Vec<(f64, f64, usize)> = Vec::with_capacity(n);
    for (joint, &v) in chain.joints.iter().zip(q) {
        if !v.is_finite() {
            return;
        }
        let lo = joint.lower - LIMIT_TOLERANCE;
        let hi = joint.upper + LIMIT_TOLERANCE;
        if joint.is_rotational() {
            let lo_eff = lo.max(v - MAX_TURNS * TAU);
            let hi_eff = hi.min(v + MAX_TURNS * TAU);
            let k_lo = ((lo_eff - v) / TAU).ceil();
            let k_hi = ((hi_eff - v) / TAU).floor();
            if matches!(k_lo.partial_cmp(&k_hi), None | Some(Ordering::Greater)) {
                return;
            }
            // Both are small integers (|k| ≤ MAX_TURNS + 1).
            ranges.push((v, k_lo, (k_hi - k_lo) as usize + 1));
        } else {
            if !(v >= lo && v <= hi) {
                return;
            }
            ranges.push((v, 0.0, 1));
        }
    }
    let mut idx = vec![0usize; n];
    loop {
        let variant: Vec<f64> = chain
            .joints
            .iter()
            .zip(&ranges)
            .zip(&idx)
            .map(|((joint, &(v, k_lo, _)), &i)| {
                (v + (k_lo + i as f64) * TAU).min(joint.upper).max(joint.lower)
            })
            .collect();
        out.push(variant);
        // Odometer increment, last joint fastest.
        let mut j = n;
        loop {
            if j == 0 {
                return;
            }
            j -= 1;
            idx[j] += 1;
            if idx[j] < ranges[j].2 {
                break;
            }
            idx[j] = 0;
        }
    }
}

/// Writes into `q` a pseudo-random configuration of `chain`: each joint uniform over its range
/// cut to (−π, π) (its middle where that is empty), for the checks the closed-form solvers make
/// of themselves when built.
pub(crate) fn random_within_a_turn(chain: &Chain, rng: &mut ChaCha8Rng, q: &mut [f64]) {
    for (v, joint) in q.iter_mut().zip(&chain.joints) {
        let lo = joint.lower.max(-PI);
        let hi = joint.upper.min(PI);
        *v = if lo < hi {
            rng.random_range(lo..hi)
        } else {
            joint.mid()
        };
    }
}

/// Whether a six-joint solver finds `checks` configurations of `chain` again from their tips
/// (drawn by [`random_within_a_turn`] from `seed`): `branches(tip, out)` appends the solver's
/// branches for a tip (root frame), and one of them must match the configuration to
/// `tolerance` rad per joint, up to whole turns. The closed-form solvers' check of themselves
/// when they read their parameters off a chain.
pub(crate) fn finds_again(
    chain: &Chain,
    seed: u64,
    checks: usize,
    tolerance: f64,
    mut branches: impl FnMut(&Pose, &mut Vec<[f64; 6]>),
) -> bool {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut q = [0.0; 6];
    let mut out = Vec::new();
    (0..checks).all(|_| {
        random_within_a_turn(chain, &mut rng, &mut q);
        out.clear();
        branches(&chain.fk_tip(&q), &mut out);
        out.iter().any(|s| {
            s.iter()
                .zip(&q)
                .all(|(a, b)| crate::wrap_angle(a - b).abs() <= tolerance)
        })
    })
}

/// OPW closed form applied to a 6-joint URDF chain: the constant transform between the OPW
/// flange frame and the chain tip is found and checked when built.
#[derive(Clone, Debug)]
pub struct OpwIk {
    chain: Chain,
    params: OpwParameters,
    /// The OPW base in the chain's root frame (the identity but for derived parameters, see
    /// [`OpwIk::derive`]), and its inverse.
    base: Pose,
    root_to_base: Pose,
    /// `C`: chain tip in the OPW flange frame (`chain.fk_tip(q) = params.forward(q) * C`).
    flange_to_tip: Pose,
    tip_to_flange: Pose,
}

/// How many configurations [`OpwIk::new`] checks the parameters at.
const OPW_CHECKS: usize = 20;
/// Largest mismatch (m, rad) [`OpwIk::new`] accepts between the chain and the OPW model.
const OPW_MATCH_TOLERANCE: f64 = 1e-6;

impl OpwIk {
    /// Builds the solver; fails when the parameters do not reproduce the chain's kinematics.
    ///
    /// The OPW base frame must be the chain root. The flange-to-tip transform `C` is taken at
    /// `q = 0`, then `chain.fk_tip(q) = params.forward(q) * C` is checked at 20 deterministic
    /// pseudo-random configurations within the limits.
    pub fn new(chain: &Chain, params: OpwParameters) -> Result<Self, KinError> {
        let source = PathBuf::from(format!("URDF chain {}→{}", chain.root_name(), chain.tip_name()));
        Self::build(chain, params, Pose::IDENTITY, source)
    }

    /// The solver for a chain given without OPW parameters, when it is an ortho-parallel arm
    /// with a spherical wrist: the parameters are read off the chain's geometry
    /// ([`OpwParameters::candidates_for`]), and the first set kept is one that reproduces the
    /// chain at 20 configurations (as [`OpwIk::new`] checks) and whose inverse
    /// finds each of those configurations again. `None` for any other chain (use the numeric
    /// solver).
    pub fn derive(chain: &Chain) -> Option<Self> {
        let source = PathBuf::from(format!("URDF chain {}→{}", chain.root_name(), chain.tip_name()));
        OpwParameters::candidates_for(chain)
            .into_iter()
            .filter_map(|(p, base)| Self::build(chain, p, base, source.clone()).ok())
            .find(|ik| ik.finds_again())
    }

    /// Whether the inverse finds [`OPW_CHECKS`] deterministic pseudo-random configurations
    /// within the limits again (up to whole turns) from their tips.
    fn finds_again(&self) -> bool {
        let mut raw = [[0.0; 6]; 8];
        finds_again(
            &self.chain,
            0x0_0f1d_a9a1,
            OPW_CHECKS,
            OPW_MATCH_TOLERANCE,
            |tip, out| {
                let flange = self.root_to_base * *tip * self.tip_to_flange;
                let n = self.params.inverse_into(&flange, &mut raw);
                out.extend_from_slice(&raw[..n]);
            },
        )
    }

    /// As [`OpwIk::new`] on the chain of `model`; errors name the URDF file.
    pub fn for_robot(model: &RobotModel, params: OpwParameters) -> Result<Self, KinError> {
        Self::build(&model.chain, params, Pose::IDENTITY, model.path.clone())
    }

    /// The solver with the OPW base at `base` in the chain's root frame.
    fn build(chain: &Chain, params: OpwParameters, base: Pose, source: PathBuf) -> Result<Self, KinError> {
        let fail = |message: String| KinError::Opw {
            path: source.clone(),
            line: None,
            message,
        };
        if chain.dof() != 6 || !chain.joints.iter().all(|j| j.is_rotational()) {
            let kinds: Vec<String> = chain
                .joints
                .iter()
                .map(|j| format!("{} ({:?})", j.name, j.kind))
                .collect();
            return Err(fail(format!(
                "OPW inverse kinematics needs 6 revolute joints, the chain {}→{} has {}: [{}]",
                chain.root_name(),
                chain.tip_name(),
                chain.dof(),
                kinds.join(", ")
            )));
        }
        let geometric = [
            params.a1, params.a2, params.b, params.c1, params.c2, params.c3, params.c4,
        ];
        let finite = geometric.iter().chain(&params.offsets).all(|v| v.is_finite());
        if !finite || params.sign_corrections.iter().any(|s| *s != 1.0 && *s != -1.0) {
            return Err(fail(format!(
                "OPW parameters must be finite and sign corrections ±1: {params:?}"
            )));
        }
        let zero = [0.0; 6];
        let root_to_base = base.inverse();
        let flange_to_tip = params.forward(&zero).inverse() * root_to_base * chain.fk_tip(&zero);
        let mut rng = ChaCha8Rng::seed_from_u64(0x0_0b5e_55ed);
        let mut q = [0.0; 6];
        for _ in 0..OPW_CHECKS {
            random_within_a_turn(chain, &mut rng, &mut q);
            let (dp, da) = pose_error(&chain.fk_tip(&q), &(base * params.forward(&q) * flange_to_tip));
            if !(dp <= OPW_MATCH_TOLERANCE && da <= OPW_MATCH_TOLERANCE) {
                let deg: Vec<String> = q.iter().map(|v| format!("{:.1}", v.to_degrees())).collect();
                return Err(fail(format!(
                    "the OPW parameters do not match the URDF chain {}→{}: at joints [{}] deg \
                     the chain tip and the OPW flange (with the transform found at zero) differ \
                     by {dp:.3e} m / {da:.3e} rad; check a1..c4, the joint offsets and sign \
                     corrections, and that the OPW base is the chain root",
                    chain.root_name(),
                    chain.tip_name(),
                    deg.join(", ")
                )));
            }
        }
        Ok(Self {
            chain: chain.clone(),
            params,
            base,
            root_to_base,
            flange_to_tip,
            tip_to_flange: flange_to_tip.inverse(),
        })
    }

    /// The chain tip in the OPW flange frame (`C` with `fk_tip(q) = forward(q) * C`).
    pub fn flange_to_tip(&self) -> Pose {
        self.flange_to_tip
    }
    /// The OPW parameters.
    pub fn params(&self) -> &OpwParameters {
        &self.params
    }
    /// The OPW base in the chain's root frame (the identity but for derived parameters).
    pub fn base(&self) -> Pose {
        self.base
    }
    /// The chain.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }
}

impl IkSolver for OpwIk {
    fn solve(&self, target: &Pose, out: &mut Vec<Vec<f64>>) -> usize {
        let flange = self.root_to_base * *target * self.tip_to_flange;
        let mut branches = [[0.0; 6]; 8];
        let n = self.params.inverse_into(&flange, &mut branches);
        for q in &branches[..n] {
            limit_variants(q, &self.chain, out);
        }
        n
    }
}

/// Tunables of [`DlsIk`].
#[derive(Clone, Debug)]
pub struct DlsParams {
    /// Number of seeds (the first is the middle of the joint ranges, the rest seeded random).
    pub seeds: usize,
    /// Iterations per seed.
    pub max_iterations: usize,
    /// Damping λ.
    pub damping: f64,
    /// Position tolerance (m).
    pub position_tolerance: f64,
    /// Orientation tolerance (rad).
    pub orientation_tolerance: f64,
    /// RNG seed for the random starts.
    pub rng_seed: u64,
}

impl Default for DlsParams {
    /// 16 seeds, 150 iterations, λ = 0.05, 1 µm and 1 µrad, RNG seed 0.
    fn default() -> Self {
        Self {
            seeds: 16,
            max_iterations: 150,
            damping: 0.05,
            position_tolerance: 1e-6,
            orientation_tolerance: 1e-6,
            rng_seed: 0,
        }
    }
}

/// Damped-least-squares numeric IK from several starts, returning distinct solutions.
#[derive(Clone, Debug)]
pub struct DlsIk {
    chain: Chain,
    params: DlsParams,
}

/// Largest joint change (rad or m) of one DLS step.
const MAX_STEP: f64 = 0.4;
/// A start whose error has not dropped by 0.1 % for this many iterations is abandoned.
const STALL_ITERATIONS: usize = 12;
/// Two solutions closer than this (joint-space Euclidean distance) are the same.
const DISTINCT: f64 = 1e-3;

impl DlsIk {
    /// A solver for `chain` (copied).
    pub fn new(chain: &Chain, params: DlsParams) -> Self {
        Self {
            chain: chain.clone(),
            params,
        }
    }

    /// The chain.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The tunables.
    pub fn params(&self) -> &DlsParams {
        &self.params
    }

    /// The start configurations: the middle of the ranges, then `seeds - 1` random ones.
    fn starts(&self) -> Vec<Vec<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.params.rng_seed);
        let mut starts = Vec::with_capacity(self.params.seeds.max(1));
        starts.push(self.chain.mid_configuration());
        for _ in 1..self.params.seeds {
            let q = self
                .chain
                .joints
                .iter()
                .map(|j| {
                    // Infinite (or absurd) limits: sample a turn either way, or a metre.
                    let (span, cap) = if j.is_rotational() {
                        (PI, 2.0 * TAU)
                    } else {
                        (1.0, 1e3)
                    };
                    let lo = if j.lower.is_finite() {
                        j.lower.max(-cap)
                    } else {
                        -span
                    };
                    let hi = if j.upper.is_finite() {
                        j.upper.min(cap)
                    } else {
                        span
                    };
                    if lo < hi {
                        rng.random_range(lo..hi)
                    } else {
                        j.mid()
                    }
                })
                .collect();
            starts.push(q);
        }
        starts
    }

    /// Follows a sequence of nearby tip targets from `start` (chain frame): DLS from the
    /// previous solution to each target in turn. `None` when a target is not reached, or when
    /// a joint moves more than `max_joint_step` (rad or m) between two targets — a jump to
    /// another branch, which would not be the continuous motion the targets describe. The
    /// configurations returned match `targets`, one each.
    pub fn follow(&self, start: &[f64], targets: &[Pose], max_joint_step: f64) -> Option<Vec<Vec<f64>>> {
        let mut poses = vec![Pose::IDENTITY; self.chain.links.len()];
        let mut q = start.to_vec();
        let mut out = Vec::with_capacity(targets.len());
        for target in targets {
            let before = q.clone();
            if !self.descend(target, &mut q, &mut poses) {
                return None;
            }
            if before.iter().zip(&q).any(|(a, b)| (a - b).abs() > max_joint_step) {
                return None;
            }
            out.push(q.clone());
        }
        Some(out)
    }

    /// Runs DLS from `q` (modified in place); true when it converged within the tolerances.
    fn descend(&self, target: &Pose, q: &mut [f64], poses: &mut [Pose]) -> bool {
        let chain = &self.chain;
        let n = chain.dof();
        for (v, j) in q.iter_mut().zip(&chain.joints) {
            *v = j.clamp(*v);
        }
        let mut jac = vec![Vector6::<f64>::zeros(); n];
        let mut dq = vec![0.0; n];
        let lambda0 = self.params.damping.max(0.0);
        let mut best = f64::INFINITY;
        let mut best_iteration = 0;
        for iteration in 0..=self.params.max_iterations {
            chain.fk_all(q, poses);
            let Some(tip) = poses.last() else {
                return false;
            };
            let ep = target.translation - tip.translation;
            let er = rotation_vector(target.rotation * tip.rotation.conjugate());
            if !(ep.is_finite() && er.is_finite()) {
                return false;
            }
            if ep.length() < self.params.position_tolerance && er.length() < self.params.orientation_tolerance
            {
                return true;
            }
            if n == 0 {
                return false;
            }
            // Geometric Jacobian: columns [z × (p_tip - p_j); z] (revolute), [z; 0] (prismatic).
            for (li, link) in chain.links.iter().enumerate() {
                let Some(j) = link.joint else { continue };
                let (Some(joint), Some(col)) = (chain.joints.get(j), jac.get_mut(j)) else {
                    continue;
                };
                let frame = poses[li];
                let z = frame.rotation * joint.axis;
                *col = if joint.is_rotational() {
                    let lin = z.cross(tip.translation - frame.translation);
                    Vector6::new(lin.x, lin.y, lin.z, z.x, z.y, z.z)
                } else {
                    Vector6::new(z.x, z.y, z.z, 0.0, 0.0, 0.0)
                };
            }
            let e = Vector6::new(ep.x, ep.y, ep.z, er.x, er.y, er.z);
            // Damping fades near the solution so the last steps converge fast.
            let lambda = lambda0 * (10.0 * e.norm()).min(1.0);
            let mut a = Matrix6::<f64>::identity() * (lambda * lambda + 1e-12);
            for col in &jac {
                a += col * col.transpose();
            }
            let y = match a.cholesky() {
                Some(ch) => ch.solve(&e),
                None => match a.lu().solve(&e) {
                    Some(y) => y,
                    None => return false,
                },
            };
            let mut max = 0.0f64;
            for (d, col) in dq.iter_mut().zip(&jac) {
                *d = col.dot(&y);
                max = max.max(d.abs());
            }
            let scale = if max > MAX_STEP { MAX_STEP / max } else { 1.0 };
            for ((v, d), joint) in q.iter_mut().zip(dq.iter()).zip(&chain.joints) {
                *v = step_within_limits(joint, *v + d * scale);
            }
            // Give up on a start that stopped making progress.
            let err = e.norm();
            if err < best * 0.999 {
                best = err;
                best_iteration = iteration;
            } else if iteration - best_iteration > STALL_ITERATIONS {
                return false;
            }
        }
        false
    }
}

impl IkSolver for DlsIk {
    /// Runs DLS from every start; the distinct converged solutions (joint distance above 1e-3,
    /// rotational joints compared modulo 2π) are expanded by [`limit_variants`], deduplicated,
    /// sorted lexicographically and appended. Returns the number of distinct converged
    /// solutions (modulo 2π).
    fn solve(&self, target: &Pose, out: &mut Vec<Vec<f64>>) -> usize {
        let mut poses = vec![Pose::IDENTITY; self.chain.links.len()];
        let mut found: Vec<Vec<f64>> = Vec::new();
        for mut q in self.starts() {
            if self.descend(target, &mut q, &mut poses)
                && !found
                    .iter()
                    .any(|f| turn_distance(&self.chain, f, &q) <= DISTINCT)
            {
                found.push(q);
            }
        }
        let mut all = Vec::new();
        for q in &found {
            limit_variants(q, &self.chain, &mut all);
        }
        all.sort_by(|a, b| lexicographic(a, b));
        let mut kept: Vec<Vec<f64>> = Vec::with_capacity(all.len());
        for q in all {
            if !kept.iter().any(|k| joint_distance(k, &q) <= DISTINCT) {
                kept.push(q);
            }
        }
        out.extend(kept);
        found.len()
    }
}

/// A joint value after a DLS step: a rotational joint that leaves its range comes back a
/// turn away when that fits (its ±2π variants are enumerated later anyway), else it is
/// clamped.
fn step_within_limits(joint: &crate::Joint, v: f64) -> f64 {
    if joint.is_rotational() {
        if v > joint.upper && v - TAU >= joint.lower {
            return v - TAU;
        }
        if v < joint.lower && v + TAU <= joint.upper {
            return v + TAU;
        }
    }
    joint.clamp(v)
}

/// Distance between two configurations, rotational joints compared modulo 2π.
fn turn_distance(chain: &Chain, a: &[f64], b: &[f64]) -> f64 {
    chain
        .joints
        .iter()
        .zip(a.iter().zip(b))
        .map(|(j, (x, y))| {
            let d = if j.is_rotational() {
                crate::wrap_angle(x - y)
            } else {
                x - y
            };
            d * d
        })
        .sum::<f64>()
        .sqrt()
}

fn lexicographic(a: &[f64], b: &[f64]) -> Ordering {
    for (x, y) in a.iter().zip(b) {
        match x.total_cmp(y) {
            Ordering::Equal => continue,
            o => return o,
        }
    }
    a.len().cmp(&b.len())
}

fn joint_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

/// Rotation vector (axis × angle, angle in [0, π]) of a unit quaternion.
pub(crate) fn rotation_vector(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = DVec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-300 {
        return 2.0 * v;
    }
    v * (2.0 * s.atan2(q.w) / s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ChainLink, Joint, JointKind};

    fn chain(limits: &[(JointKind, f64, f64)]) -> Chain {
        let mut links = vec![ChainLink {
            name: "root".into(),
            origin: Pose::IDENTITY,
            joint: None,
        }];
        let joints = limits
            .iter()
            .enumerate()
            .map(|(i, &(kind, lower, upper))| {
                links.push(ChainLink {
                    name: format!("l{i}"),
                    origin: Pose::translation(0.0, 0.0, 0.1),
                    joint: Some(i),
                });
                Joint {
                    name: format!("j{i}"),
                    kind,
                    axis: if i % 2 == 0 { DVec3::Z } else { DVec3::Y },
                    lower,
                    upper,
                    max_velocity: 1.0,
                    max_effort: 0.0,
                }
            })
            .collect();
        Chain { links, joints }
    }

    #[test]
    fn variants_of_a_full_turn_joint() {
        let c = chain(&[(JointKind::Revolute, -TAU, TAU), (JointKind::Revolute, -1.0, 1.0)]);
        let mut out = Vec::new();
        limit_variants(&[0.5, 0.2], &c, &mut out);
        assert_eq!(out, vec![vec![0.5 - TAU, 0.2], vec![0.5, 0.2]]);
        out.clear();
        // 0.2 + 2π and 0.2 - 2π are outside ±1: one value for joint 1.
        limit_variants(&[0.5, 0.2 + TAU], &c, &mut out);
        assert_eq!(out.len(), 2);
        assert!((out[1][1] - 0.2).abs() < 1e-12);
    }

    #[test]
    fn nothing_when_a_joint_cannot_be_brought_into_range() {
        let c = chain(&[(JointKind::Revolute, -1.0, 1.0), (JointKind::Revolute, -1.0, 1.0)]);
        let mut out = Vec::new();
        limit_variants(&[0.0, 2.0], &c, &mut out);
        assert!(out.is_empty());
        limit_variants(&[0.0], &c, &mut out);
        assert!(out.is_empty());
        limit_variants(&[0.0, f64::NAN], &c, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn prismatic_joints_get_no_turns() {
        let c = chain(&[
            (JointKind::Prismatic, -10.0, 10.0),
            (JointKind::Continuous, -TAU, TAU),
        ]);
        let mut out = Vec::new();
        limit_variants(&[0.5, 0.0], &c, &mut out);
        assert_eq!(out, vec![vec![0.5, -TAU], vec![0.5, 0.0], vec![0.5, TAU]]);
        out.clear();
        limit_variants(&[10.5, 0.0], &c, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn values_a_hair_outside_are_clamped_in() {
        let c = chain(&[(JointKind::Revolute, -1.0, 1.0)]);
        let mut out = Vec::new();
        limit_variants(&[1.0 + 5e-10], &c, &mut out);
        assert_eq!(out, vec![vec![1.0]]);
        out.clear();
        limit_variants(&[1.0 + 5e-9], &c, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn absurd_limits_stay_bounded() {
        let c = chain(&[(JointKind::Revolute, -1e12, 1e12)]);
        let mut out = Vec::new();
        limit_variants(&[0.0], &c, &mut out);
        assert_eq!(out.len(), 9);
    }

    #[test]
    fn dls_params_default_is_sane() {
        let p = DlsParams::default();
        assert!(p.seeds >= 1 && p.max_iterations > 0 && p.damping > 0.0);
        assert!(p.position_tolerance <= 1e-6 && p.orientation_tolerance <= 1e-6);
    }

    #[test]
    fn dls_solves_a_planar_arm_in_both_elbow_branches() {
        // Three revolute joints about y with 0.5 m links in x: a planar arm; target in its
        // plane with a reachable orientation.
        let mut c = chain(&[
            (JointKind::Revolute, -PI, PI),
            (JointKind::Revolute, -PI, PI),
            (JointKind::Revolute, -PI, PI),
        ]);
        for (i, l) in c.links.iter_mut().enumerate().skip(1) {
            l.origin = if i == 1 {
                Pose::IDENTITY
            } else {
                Pose::translation(0.5, 0.0, 0.0)
            };
        }
        for j in &mut c.joints {
            j.axis = DVec3::Y;
        }
        let q = [0.3, -0.8, 0.4];
        let target = c.fk_tip(&q);
        let ik = DlsIk::new(
            &c,
            DlsParams {
                seeds: 12,
                ..DlsParams::default()
            },
        );
        let mut out = Vec::new();
        let n = ik.solve(&target, &mut out);
        assert!(n >= 1);
        assert_eq!(
            n,
            out.len(),
            "no ±2π variants fit ±π limits (except at the boundary)"
        );
        assert!(out.iter().any(|s| joint_distance(s, &q) < 1e-4), "{out:?}");
        for s in &out {
            let (dp, dr) = pose_error(&c.fk_tip(s), &target);
            assert!(dp < 1e-6 && dr < 1e-6);
        }
        // Sorted and distinct.
        for w in out.windows(2) {
            assert_eq!(lexicographic(&w[0], &w[1]), Ordering::Less);
            assert!(joint_distance(&w[0], &w[1]) > DISTINCT);
        }
        // Deterministic.
        let mut again = Vec::new();
        ik.solve(&target, &mut again);
        assert_eq!(out, again);
        // Out of reach: nothing.
        let mut none = Vec::new();
        assert_eq!(ik.solve(&Pose::translation(5.0, 0.0, 0.0), &mut none), 0);
        assert!(none.is_empty());
    }

    #[test]
    fn rotation_vector_of_small_and_half_turns() {
        let v = rotation_vector(DQuat::from_rotation_x(1e-9));
        assert!((v - DVec3::new(1e-9, 0.0, 0.0)).length() < 1e-24);
        let v = rotation_vector(DQuat::from_rotation_z(3.0));
        assert!((v - DVec3::new(0.0, 0.0, 3.0)).length() < 1e-12);
        let v = rotation_vector(-DQuat::from_rotation_z(0.5));
        assert!((v - DVec3::new(0.0, 0.0, 0.5)).length() < 1e-12);
    }
}

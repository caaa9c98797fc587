//! Closed-form inverse kinematics of ortho-parallel arms with a spherical wrist (OPW;
//! Brandstötter, Angerer, Hofbaur 2014).
use cellplan_geom::{DMat3, DQuat, DVec3, Pose};
use std::f64::consts::{PI, TAU};

mod derive;
mod yaml;

/// OPW geometric parameters (metres), joint offsets (rad) and sign corrections (±1).
#[derive(Clone, Debug, PartialEq)]
pub struct OpwParameters {
    /// Shoulder offset along x.
    pub a1: f64,
    /// Elbow offset.
    pub a2: f64,
    /// Lateral offset.
    pub b: f64,
    /// Base height.
    pub c1: f64,
    /// Upper arm length.
    pub c2: f64,
    /// Forearm length.
    pub c3: f64,
    /// Wrist to flange.
    pub c4: f64,
    /// Added to the joint values of the model (rad).
    pub offsets: [f64; 6],
    /// ±1 per joint.
    pub sign_corrections: [f64; 6],
}

impl OpwParameters {
    /// Parses a ROS-Industrial `opw_parameters_*.yaml` (keys
    /// `opw_kinematics_geometric_parameters`, `opw_kinematics_joint_offsets`,
    /// `opw_kinematics_joint_sign_corrections`; `deg(x)` allowed). Errors carry the line.
    ///
    /// The reader handles the restricted YAML these files use: comments, a block mapping of
    /// the seven geometric parameters, and flow (`[a, b, ...]`) or block (`- a`) lists of six
    /// values. Other top-level keys (`dof`, `constraints`, ...) are ignored.
    pub fn from_ros_yaml(text: &str) -> Result<Self, (Option<usize>, String)> {
        yaml::parse(text)
    }

    /// The parameter sets a six-joint chain's geometry at zero allows (see `opw/derive.rs`),
    /// each with the OPW base in the chain's root frame (a level shift of the root onto joint
    /// 1's axis), the usual choice of axis directions first; empty when the chain is not an
    /// ortho-parallel arm with a spherical wrist and a vertical joint 1. Each must still be
    /// checked against the chain: [`crate::OpwIk::derive`] keeps the first that reproduces it.
    pub fn candidates_for(chain: &crate::Chain) -> Vec<(Self, Pose)> {
        derive::candidates(chain)
    }

    /// The ROS-Industrial convention maps a model (URDF) joint value `q` to the angle of the
    /// OPW model as `sign * q - offset`.
    #[inline]
    fn to_opw(&self, q: &[f64; 6]) -> [f64; 6] {
        std::array::from_fn(|i| q[i] * self.sign_corrections[i] - self.offsets[i])
    }

    /// Forward kinematics: flange pose in the base frame.
    pub fn forward(&self, q: &[f64; 6]) -> Pose {
        let t = self.to_opw(q);
        let psi3 = self.a2.atan2(self.c3);
        let k = self.a2.hypot(self.c3);
        let (s1, c1) = t[0].sin_cos();
        let (s2, c2) = t[1].sin_cos();
        let (s23, c23) = (t[1] + t[2]).sin_cos();
        let (s4, c4) = t[3].sin_cos();
        let (s5, c5) = t[4].sin_cos();
        let (s6, c6) = t[5].sin_cos();

        let (sk, ck) = (t[1] + t[2] + psi3).sin_cos();
        let cx1 = self.c2 * s2 + k * sk + self.a1;
        let cy1 = self.b;
        let cz1 = self.c2 * c2 + k * ck;
        let wrist = DVec3::new(cx1 * c1 - cy1 * s1, cx1 * s1 + cy1 * c1, cz1 + self.c1);

        // r_0c = Rz(θ1) · Ry(θ2 + θ3); r_ce = Rz(θ4) · Ry(θ5) · Rz(θ6).
        let r_0c = DMat3::from_cols(
            DVec3::new(c1 * c23, s1 * c23, -s23),
            DVec3::new(-s1, c1, 0.0),
            DVec3::new(c1 * s23, s1 * s23, c23),
        );
        let r_ce = DMat3::from_cols(
            DVec3::new(c4 * c5 * c6 - s4 * s6, s4 * c5 * c6 + c4 * s6, -s5 * c6),
            DVec3::new(-c4 * c5 * s6 - s4 * c6, -s4 * c5 * s6 + c4 * c6, s5 * s6),
            DVec3::new(c4 * s5, s4 * s5, c5),
        );
        let r = r_0c * r_ce;
        let translation = wrist + self.c4 * r.z_axis;
        Pose::from_parts(translation, DQuat::from_mat3(&r).normalize())
    }

    /// Every solution branch (up to 8) for a flange pose, joint values wrapped to (-π, π].
    /// Branches without a real solution are left out. `out` is cleared first.
    ///
    /// Branch order (as in ROS-Industrial `opw_kinematics`): shoulder i/ii × elbow up/down,
    /// then the same four with the wrist flipped. At a wrist singularity (θ5 ≈ 0 or π in the
    /// OPW model) θ4 is set to 0 (π for the flipped wrist) and θ6 takes the whole rotation.
    pub fn inverse(&self, pose: &Pose, out: &mut Vec<[f64; 6]>) {
        out.clear();
        let mut raw = [[0.0; 6]; 8];
        let n = self.inverse_into(pose, &mut raw);
        out.extend_from_slice(&raw[..n]);
    }

    /// As [`OpwParameters::inverse`] without allocating: the real branches are written to the
    /// front of `out` and their number returned.
    pub fn inverse_into(&self, pose: &Pose, out: &mut [[f64; 6]; 8]) -> usize {
        let n = self.inverse_opw(pose, out);
        for sol in &mut out[..n] {
            for ((v, off), sign) in sol.iter_mut().zip(&self.offsets).zip(&self.sign_corrections) {
                *v = wrap_angle((*v + off) * sign);
            }
        }
        n
    }

    /// The OPW-model angles of every real branch, written to the front of `out`; returns how
    /// many.
    fn inverse_opw(&self, pose: &Pose, out: &mut [[f64; 6]; 8]) -> usize {
        let r = DMat3::from_quat(pose.rotation);
        let c = pose.translation - self.c4 * r.z_axis;
        let (a1, a2, b, c1, c2, c3) = (self.a1, self.a2, self.b, self.c1, self.c2, self.c3);

        let nx1 = (c.x * c.x + c.y * c.y - b * b).sqrt() - a1;
        let tmp1 = c.y.atan2(c.x);
        let tmp2 = b.atan2(nx1 + a1);
        let theta1_i = tmp1 - tmp2;
        let theta1_ii = tmp1 + tmp2 - PI;

        let tmp3 = c.z - c1;
        let s1_2 = nx1 * nx1 + tmp3 * tmp3;
        let tmp4 = nx1 + 2.0 * a1;
        let s2_2 = tmp4 * tmp4 + tmp3 * tmp3;
        let kappa_2 = a2 * a2 + c3 * c3;
        let c2_2 = c2 * c2;

        let s1 = s1_2.sqrt();
        let s2 = s2_2.sqrt();

        let tmp13 = safe_acos((s1_2 + c2_2 - kappa_2) / (2.0 * s1 * c2));
        let tmp14 = nx1.atan2(tmp3);
        let theta2_i = -tmp13 + tmp14;
        let theta2_ii = tmp13 + tmp14;

        let tmp15 = safe_acos((s2_2 + c2_2 - kappa_2) / (2.0 * s2 * c2));
        let tmp16 = tmp4.atan2(tmp3);
        let theta2_iii = -tmp15 - tmp16;
        let theta2_iv = tmp15 - tmp16;

        let tmp9 = 2.0 * c2 * kappa_2.sqrt();
        let tmp10 = a2.atan2(c3);
        let tmp11 = safe_acos((s1_2 - c2_2 - kappa_2) / tmp9);
        let theta3_i = tmp11 - tmp10;
        let theta3_ii = -tmp11 - tmp10;
        let tmp12 = safe_acos((s2_2 - c2_2 - kappa_2) / tmp9);
        let theta3_iii = tmp12 - tmp10;
        let theta3_iv = -tmp12 - tmp10;

        let arms = [
            (theta1_i, theta2_i, theta3_i),
            (theta1_i, theta2_ii, theta3_ii),
            (theta1_ii, theta2_iii, theta3_iii),
            (theta1_ii, theta2_iv, theta3_iv),
        ];
        let mut wrists = [[0.0; 3]; 8];
        let mut valid = [false; 4];
        for (i, &(t1, t2, t3)) in arms.iter().enumerate() {
            if !(t1.is_finite() && t2.is_finite() && t3.is_finite()) {
                continue;
            }
            valid[i] = true;
            let (sn1, cs1) = t1.sin_cos();
            let (s23, c23) = (t2 + t3).sin_cos();
            // r_ce = r_0cᵀ · r, with r_0c = Rz(θ1) · Ry(θ2 + θ3).
            let r_0c = DMat3::from_cols(
                DVec3::new(cs1 * c23, sn1 * c23, -s23),
                DVec3::new(-sn1, cs1, 0.0),
                DVec3::new(cs1 * s23, sn1 * s23, c23),
            );
            let r_ce = r_0c.transpose() * r;
            let (x02, y12) = (r_ce.z_axis.x, r_ce.z_axis.y);
            let theta4 = if x02.hypot(y12) < WRIST_SINGULARITY {
                0.0
            } else {
                y12.atan2(x02)
            };
            wrists[i] = wrist_angles(&r_ce, theta4);
            wrists[i + 4] = wrist_angles(&r_ce, theta4 + PI);
        }
        let mut n = 0;
        for k in 0..8 {
            if !valid[k % 4] {
                continue;
            }
            let (t1, t2, t3) = arms[k % 4];
            let [t4, t5, t6] = wrists[k];
            out[n] = [t1, t2, t3, t4, t5, t6];
            n += 1;
        }
        n
    }
}

/// Below this, the wrist axis of joint 5 is taken as aligned with joint 4 (θ5 = 0 or π).
const WRIST_SINGULARITY: f64 = 1e-12;

/// θ4, θ5, θ6 from `r_ce = Rz(θ4) · Ry(θ5) · Rz(θ6)` with θ4 given; θ5 and θ6 follow from
/// `Rz(-θ4) · r_ce`, which stays well conditioned close to the singularity.
#[inline]
fn wrist_angles(r_ce: &DMat3, theta4: f64) -> [f64; 3] {
    let (s4, c4) = theta4.sin_cos();
    // Rows of Rz(-θ4) · r_ce: row0 = c4·R0 + s4·R1, row1 = -s4·R0 + c4·R1, row2 = R2.
    let s5 = c4 * r_ce.z_axis.x + s4 * r_ce.z_axis.y;
    let c5 = r_ce.z_axis.z;
    let s6 = -s4 * r_ce.x_axis.x + c4 * r_ce.x_axis.y;
    let c6 = -s4 * r_ce.y_axis.x + c4 * r_ce.y_axis.y;
    [theta4, s5.atan2(c5), s6.atan2(c6)]
}

/// `acos` that forgives rounding just past ±1 (NaN when clearly outside).
#[inline]
fn safe_acos(x: f64) -> f64 {
    if x.abs() <= 1.0 {
        x.acos()
    } else if x.abs() <= 1.0 + 1e-12 {
        if x > 0.0 { 0.0 } else { PI }
    } else {
        f64::NAN
    }
}

/// Wraps an angle to (-π, π].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    if a > -PI && a <= PI {
        return a;
    }
    let r = a.rem_euclid(TAU);
    if r > PI { r - TAU } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pose_error;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::f64::consts::FRAC_PI_2;

    const FANUC_YAML: &str = "#\n# comment\n#\nopw_kinematics_geometric_parameters:\n  a1:  0.312\n  a2:  -0.225\n  b:   0.000\n  c1:  0.670\n  c2:  1.075\n  c3:  1.730\n  c4:  0.215\nopw_kinematics_joint_offsets: [0, 0, deg(-90.0), 0, 0, deg(180.0)]\nopw_kinematics_joint_sign_corrections: [1, 1, -1, -1, -1, -1]\n";

    fn lateral() -> OpwParameters {
        // A made-up arm with a lateral offset b ≠ 0 and non-trivial signs and offsets.
        OpwParameters {
            a1: 0.15,
            a2: -0.11,
            b: 0.07,
            c1: 0.55,
            c2: 0.8,
            c3: 0.9,
            c4: 0.12,
            offsets: [0.1, -FRAC_PI_2, 0.3, 0.0, -0.2, PI],
            sign_corrections: [1.0, -1.0, 1.0, -1.0, 1.0, -1.0],
        }
    }

    #[test]
    fn parses_the_ros_industrial_file() {
        let p = OpwParameters::from_ros_yaml(FANUC_YAML).unwrap();
        assert_eq!(
            (p.a1, p.a2, p.b, p.c1, p.c2, p.c3, p.c4),
            (0.312, -0.225, 0.0, 0.670, 1.075, 1.730, 0.215)
        );
        assert_eq!(p.offsets, [0.0, 0.0, -FRAC_PI_2, 0.0, 0.0, PI]);
        assert_eq!(p.sign_corrections, [1.0, 1.0, -1.0, -1.0, -1.0, -1.0]);
    }

    #[test]
    fn parses_block_lists_flow_maps_and_ignores_other_keys() {
        let text = "dof: 6\nopw_kinematics_geometric_parameters: {a1: 1, a2: 2, b: 3, c1: 4, c2: 5, c3: 6, c4: 7}\nopw_kinematics_joint_offsets:\n  - 0\n  - deg(90)\n  - 0\n  - 0\n  - 0\n  - 0\nopw_kinematics_joint_sign_corrections: [1, 1,\n  1, 1, 1, -1]\nconstraints:\n  from: [deg(-179.0), 1]\n";
        let p = OpwParameters::from_ros_yaml(text).unwrap();
        assert_eq!(p.c4, 7.0);
        assert_eq!(p.offsets[1], FRAC_PI_2);
        assert_eq!(p.sign_corrections[5], -1.0);
    }

    #[test]
    fn errors_carry_lines() {
        let line_of = |text: &str| OpwParameters::from_ros_yaml(text).unwrap_err();
        let bad_number = FANUC_YAML.replace("c2:  1.075", "c2:  1.0x5");
        assert_eq!(line_of(&bad_number).0, Some(9));
        let bad_deg = FANUC_YAML.replace("deg(-90.0)", "deg(-90.0");
        let (l, m) = line_of(&bad_deg);
        assert_eq!(l, Some(12), "{m}");
        let five = FANUC_YAML.replace("[1, 1, -1, -1, -1, -1]", "[1, 1, -1, -1, -1]");
        let (l, m) = line_of(&five);
        assert_eq!(l, Some(13));
        assert!(m.contains("5 values"), "{m}");
        let bad_sign = FANUC_YAML.replace("[1, 1, -1,", "[1, 2, -1,");
        assert_eq!(line_of(&bad_sign).0, Some(13));
        let unknown = FANUC_YAML.replace("c4:  0.215", "c5:  0.215");
        let (l, m) = line_of(&unknown);
        assert_eq!(l, Some(11));
        assert!(m.contains("c5"), "{m}");
        let missing = FANUC_YAML.replace("opw_kinematics_joint_offsets", "joint_offsets");
        let (l, m) = line_of(&missing);
        assert_eq!(l, None);
        assert!(m.contains("opw_kinematics_joint_offsets"), "{m}");
        let twice = format!("{FANUC_YAML}opw_kinematics_joint_offsets: [0, 0, 0, 0, 0, 0]\n");
        assert_eq!(line_of(&twice).0, Some(14));
        assert_eq!(line_of("  a1: 1\n").0, Some(1));
    }

    #[test]
    fn wraps_angles() {
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * PI / 2.0) + FRAC_PI_2).abs() < 1e-15);
        assert!((wrap_angle(-7.0) - (-7.0 + TAU)).abs() < 1e-15);
        assert_eq!(wrap_angle(0.5), 0.5);
    }

    #[test]
    fn zero_pose_of_the_fanuc() {
        let p = OpwParameters::from_ros_yaml(FANUC_YAML).unwrap();
        // At zero the arm points up then forward: wrist centre at (a1 + c3 + c4... ) per URDF:
        // x = 0.312 + 1.730 + 0.215, z = 0.670 + 1.075 + 0.225.
        let f = p.forward(&[0.0; 6]);
        assert!(
            (f.translation - DVec3::new(2.257, 0.0, 1.970)).length() < 1e-12,
            "{f:?}"
        );
        // Flange z axis along base x.
        assert!((f.rotation * DVec3::Z - DVec3::X).length() < 1e-12);
    }

    #[test]
    fn lateral_offset_round_trip() {
        let p = lateral();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut sols = Vec::new();
        for _ in 0..2000 {
            let q: [f64; 6] = std::array::from_fn(|_| rng.random_range(-PI..PI));
            let pose = p.forward(&q);
            p.inverse(&pose, &mut sols);
            assert!(!sols.is_empty());
            for s in &sols {
                let (dp, dr) = pose_error(&p.forward(s), &pose);
                assert!(dp < 1e-9 && dr < 1e-9, "{dp} {dr} for {s:?} (q = {q:?})");
            }
            let found = sols
                .iter()
                .any(|s| s.iter().zip(&q).all(|(a, b)| wrap_angle(a - b).abs() < 1e-6));
            assert!(found, "q = {q:?} not among {sols:?}");
        }
    }

    #[test]
    fn wrist_singularity_is_deterministic() {
        let p = lateral();
        // θ5 (OPW) = sign5·q5 - offset5 = 0 ⇔ q5 = -0.2.
        let q = [0.4, 0.3, -0.5, 1.1, -0.2, -0.7];
        let pose = p.forward(&q);
        let mut a = Vec::new();
        let mut b = Vec::new();
        p.inverse(&pose, &mut a);
        p.inverse(&pose, &mut b);
        assert_eq!(a, b);
        assert!(a.len() >= 2 && a.len() % 2 == 0, "{a:?}");
        for s in &a {
            let (dp, dr) = pose_error(&p.forward(s), &pose);
            assert!(dp < 1e-9 && dr < 1e-9);
        }
        // The singular branch has OPW θ4 = 0 (q4 = 0) or π, and θ6 carries q4 + q6.
        let singular: Vec<_> = a.iter().filter(|s| (s[4] + 0.2).abs() < 1e-9).collect();
        assert!(!singular.is_empty());
        for s in singular {
            assert!(s[3].abs() < 1e-12 || (s[3].abs() - PI).abs() < 1e-12, "{s:?}");
        }
    }

    #[test]
    fn unreachable_pose_has_no_branch() {
        let p = lateral();
        let far = Pose::from_translation(DVec3::new(5.0, 0.0, 0.5));
        let mut sols = vec![[1.0; 6]];
        p.inverse(&far, &mut sols);
        assert!(sols.is_empty());
        let mut raw = [[0.0; 6]; 8];
        assert_eq!(p.inverse_into(&far, &mut raw), 0);
    }

    #[test]
    fn nan_pose_has_no_branch() {
        let p = lateral();
        let bad = Pose::from_translation(DVec3::new(f64::NAN, 0.0, 0.5));
        let mut sols = Vec::new();
        p.inverse(&bad, &mut sols);
        assert!(sols.is_empty());
    }
}

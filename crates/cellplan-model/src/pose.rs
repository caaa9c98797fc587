//! Poses as written in a cell file, turned into rigid transforms.
use crate::spec::PoseSpec;
use cellplan_geom::{DMat3, DQuat, DVec3, Pose};

/// Rotation from roll, pitch, yaw (radians) about fixed x, y, z: R = Rz(yaw)·Ry(pitch)·Rx(roll),
/// as in URDF.
pub fn rpy_to_quat(rpy: [f64; 3]) -> DQuat {
    DQuat::from_rotation_z(rpy[2]) * DQuat::from_rotation_y(rpy[1]) * DQuat::from_rotation_x(rpy[0])
}

/// Roll, pitch, yaw (radians) of a rotation; inverse of [`rpy_to_quat`].
pub fn quat_to_rpy(q: DQuat) -> [f64; 3] {
    let m = DMat3::from_quat(q);
    // m = Rz(y) Ry(p) Rx(r); m[col][row] in glam.
    let (r20, r21, r22) = (m.x_axis.z, m.y_axis.z, m.z_axis.z);
    let (r00, r10) = (m.x_axis.x, m.x_axis.y);
    let pitch = (-r20).clamp(-1.0, 1.0).asin();
    if r20.abs() < 1.0 - 1e-12 {
        [r21.atan2(r22), pitch, r10.atan2(r00)]
    } else {
        // Gimbal lock: put everything in yaw.
        let (r01, r11) = (m.y_axis.x, m.y_axis.y);
        [0.0, pitch, (-r01).atan2(r11)]
    }
}

/// Why a pose spec is not a pose.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PoseError {
    /// `xyz` (in metres) is not finite.
    #[error("the translation `xyz` is not finite")]
    Translation,
    /// `xyz` (in metres) has a coordinate beyond [`crate::tasks::MAX_COORDINATE`].
    #[error("the translation `xyz` lies {} m from its frame's origin, beyond {} m", crate::shown(*metres), crate::tasks::MAX_COORDINATE)]
    Far {
        /// Its largest coordinate's magnitude (m).
        metres: f64,
    },
    /// More than one of `rpy`, `quat`, `matrix`.
    #[error("give the rotation once: one of `rpy`, `quat` or `matrix`")]
    RotationTwice,
    /// `rpy` is not finite.
    #[error("`rpy` is not finite")]
    Rpy,
    /// An `rpy` angle beyond [`MAX_ANGLE`].
    #[error("`rpy` angle {} is beyond {MAX_TURNS} turns", crate::shown(*value))]
    RpyTurns {
        /// The angle as written.
        value: f64,
    },
    /// `quat` is not of unit length.
    #[error("`quat` must be a unit quaternion [x, y, z, w]; its length is {length:.6}")]
    Quat {
        /// Its length.
        length: f64,
    },
    /// `matrix` is not orthonormal.
    #[error(
        "`matrix` is not a rotation: its rows are not orthonormal (RᵀR differs from I by {deviation:.2e})"
    )]
    NotOrthonormal {
        /// Largest entry of |RᵀR − I|.
        deviation: f64,
    },
    /// `matrix` is orthonormal but mirrors.
    #[error("`matrix` is a reflection (determinant -1), not a rotation")]
    Reflection,
}

/// Largest magnitude of an `rpy` angle in turns. Beyond, the angle's sine and cosine keep none
/// of the digits it was written with.
pub const MAX_TURNS: f64 = 100.0;

/// [`MAX_TURNS`] in radians.
pub const MAX_ANGLE: f64 = MAX_TURNS * std::f64::consts::TAU;

/// Converts a pose spec with file units (metres per length unit, radians per angle unit).
/// Errors say what is wrong with the translation or the rotation.
pub fn pose_from_spec(spec: &PoseSpec, to_m: f64, to_rad: f64) -> Result<Pose, PoseError> {
    let t = DVec3::from_array(spec.xyz) * to_m;
    if !t.is_finite() {
        return Err(PoseError::Translation);
    }
    let far = t.abs().max_element();
    if far > crate::tasks::MAX_COORDINATE {
        return Err(PoseError::Far { metres: far });
    }
    let given = [spec.rpy.is_some(), spec.quat.is_some(), spec.matrix.is_some()]
        .iter()
        .filter(|&&b| b)
        .count();
    if given > 1 {
        return Err(PoseError::RotationTwice);
    }
    let rotation = if let Some(rpy) = spec.rpy {
        if rpy.iter().any(|v| !v.is_finite()) {
            return Err(PoseError::Rpy);
        }
        if let Some(&v) = rpy.iter().find(|v| (*v * to_rad).abs() > MAX_ANGLE) {
            return Err(PoseError::RpyTurns { value: v });
        }
        rpy_to_quat([rpy[0] * to_rad, rpy[1] * to_rad, rpy[2] * to_rad])
    } else if let Some(q) = spec.quat {
        let q = DQuat::from_xyzw(q[0], q[1], q[2], q[3]);
        let n = q.length();
        if !n.is_finite() || (n - 1.0).abs() > 1e-3 {
            return Err(PoseError::Quat { length: n });
        }
        q / n
    } else if let Some(rows) = spec.matrix {
        let m = DMat3::from_cols_array_2d(&rows).transpose();
        let err = (m.transpose() * m - DMat3::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        if !err.is_finite() || err > 1e-6 {
            return Err(PoseError::NotOrthonormal { deviation: err });
        }
        if m.determinant() < 0.0 {
            return Err(PoseError::Reflection);
        }
        DQuat::from_mat3(&m).normalize()
    } else {
        DQuat::IDENTITY
    };
    Ok(Pose::from_parts(t, rotation))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn rpy_matches_urdf_convention() {
        // Yaw 90°: x axis goes to y.
        let q = rpy_to_quat([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        assert!((q * DVec3::X - DVec3::Y).length() < 1e-12);
        // Roll 90°: y axis goes to z.
        let q = rpy_to_quat([std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
        assert!((q * DVec3::Y - DVec3::Z).length() < 1e-12);
    }

    #[test]
    fn units_are_applied() {
        let spec = PoseSpec {
            xyz: [1000.0, 0.0, 0.0],
            rpy: Some([0.0, 0.0, 90.0]),
            ..Default::default()
        };
        let p = pose_from_spec(&spec, 1e-3, std::f64::consts::PI / 180.0).unwrap();
        assert!((p.translation - DVec3::X).length() < 1e-12);
        assert!((p.rotation * DVec3::X - DVec3::Y).length() < 1e-12);
    }

    #[test]
    fn bad_rotations_are_refused() {
        let skew = PoseSpec {
            matrix: Some([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
            ..Default::default()
        };
        assert!(
            pose_from_spec(&skew, 1.0, 1.0)
                .unwrap_err()
                .to_string()
                .contains("orthonormal")
        );
        let mirror = PoseSpec {
            matrix: Some([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
            ..Default::default()
        };
        assert!(
            pose_from_spec(&mirror, 1.0, 1.0)
                .unwrap_err()
                .to_string()
                .contains("reflection")
        );
        let long = PoseSpec {
            quat: Some([0.0, 0.0, 0.0, 2.0]),
            ..Default::default()
        };
        assert!(
            pose_from_spec(&long, 1.0, 1.0)
                .unwrap_err()
                .to_string()
                .contains("unit quaternion")
        );
        let both = PoseSpec {
            rpy: Some([0.0; 3]),
            quat: Some([0.0, 0.0, 0.0, 1.0]),
            ..Default::default()
        };
        assert!(pose_from_spec(&both, 1.0, 1.0).is_err());
    }

    #[test]
    fn matrix_rows_are_rows() {
        // Rows of Rz(90°): [[0,-1,0],[1,0,0],[0,0,1]] maps x to y.
        let spec = PoseSpec {
            matrix: Some([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
            ..Default::default()
        };
        let p = pose_from_spec(&spec, 1.0, 1.0).unwrap();
        assert!((p.rotation * DVec3::X - DVec3::Y).length() < 1e-12);
    }

    proptest! {
        #[test]
        fn rpy_round_trips(r in -3.1f64..3.1, p in -1.5f64..1.5, y in -3.1f64..3.1) {
            let q = rpy_to_quat([r, p, y]);
            let back = rpy_to_quat(quat_to_rpy(q));
            for v in [DVec3::X, DVec3::Y, DVec3::Z] {
                prop_assert!((q * v - back * v).length() < 1e-9);
            }
        }
    }
}

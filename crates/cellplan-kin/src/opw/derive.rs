//! OPW parameters read off a URDF chain: where the joint axes of a six-joint arm lie at zero.
//!
//! An arm is ortho-parallel with a spherical wrist when, at any configuration, joint 1 turns
//! about a vertical line through the base origin, joints 2 and 3 about parallel lines square to
//! it, and joints 4, 5 and 6 about three lines through one point (the wrist centre), each square
//! to the next. Brandstötter et al. describe such an arm by seven lengths measured with every
//! link straight up (OPW zero); a URDF states the same arm at its own zero, where the forearm is
//! usually level. [`candidates`] measures the lines at the URDF's zero in a frame turned with
//! joint 1, and finds the lengths, offsets and signs that map one zero onto the other.
//!
//! Which way each axis points is a choice (an axis and its opposite describe the same line), so
//! the result is a short list, the usual choice first; the caller keeps the first that
//! reproduces the chain (see [`crate::OpwIk::derive`]): nothing here is trusted unchecked.
use super::OpwParameters;
use crate::Chain;
use crate::axes::{EPS, closest, level_base, lines};
use cellplan_geom::{DMat3, DVec3, Pose};

/// Every set of OPW parameters that the chain's geometry at zero allows, each with the OPW
/// base in the chain's root frame (the root moved level onto joint 1's axis), the usual choice
/// of axis directions first; empty when the chain is not an ortho-parallel arm with a spherical
/// wrist whose joint 1 turns about a line parallel to the root's z axis.
///
/// Each set still has to be checked against the chain: the geometry is tested here only as far
/// as needed to measure it.
pub(crate) fn candidates(chain: &Chain) -> Vec<(OpwParameters, Pose)> {
    let Some(mut l) = lines(chain) else {
        return Vec::new();
    };
    let z = DVec3::Z;
    // Joint 1: parallel to the root's z axis (either way); the OPW base is the root moved level
    // onto it.
    let Some(base) = level_base(&mut l) else {
        return Vec::new();
    };
    let sign1 = l[0].dir.z.signum();
    // Joints 2 and 3: parallel, square to joint 1.
    if l[1].dir.dot(z).abs() > EPS || l[2].dir.cross(l[1].dir).length() > EPS {
        return Vec::new();
    }
    // Joints 4, 5 and 6: through one point, each square to the next.
    let Some((w4, w5)) = closest(&l[3], &l[4]) else {
        return Vec::new();
    };
    let wrist = 0.5 * (w4 + w5);
    if (w4 - w5).length() > EPS
        || l[5].distance(wrist) > EPS
        || l[3].dir.dot(l[4].dir).abs() > EPS
        || l[4].dir.dot(l[5].dir).abs() > EPS
    {
        return Vec::new();
    }
    let tip = chain.fk_tip(&[0.0; 6]).translation - base;
    let mut out = Vec::new();
    for sign2 in [1.0, -1.0] {
        // The arm's frame after joint 1 at zero: y along joint 2, z up.
        let y = sign2 * l[1].dir;
        let x = y.cross(z);
        let theta1 = x.y.atan2(x.x);
        let (a1, c1) = (l[1].point.dot(x), l[1].point.dot(z));
        // Joint 3 from joint 2, in the arm's plane (x, z).
        let (u, v) = (l[2].point.dot(x) - a1, l[2].point.dot(z) - c1);
        let c2 = u.hypot(v);
        let theta2 = u.atan2(v);
        let sign3 = l[2].dir.dot(y).signum();
        // The forearm: joint 3 to the wrist centre, in the arm's plane; the wrist's lateral
        // offset across it.
        if l[3].dir.dot(y).abs() > EPS || c2 < EPS {
            continue;
        }
        let b = wrist.dot(y);
        let (fx, fz) = (wrist.dot(x) - l[2].point.dot(x), wrist.dot(z) - l[2].point.dot(z));
        for sign4 in [1.0, -1.0] {
            // OPW's joint 4 axis, at θ2 + θ3, is (sin, 0, cos) in the arm's frame.
            let f = sign4 * l[3].dir;
            let theta23 = f.dot(x).atan2(f.dot(z));
            let (s, c) = theta23.sin_cos();
            let c3 = fx * s + fz * c;
            let a2 = fx * c - fz * s;
            let theta3 = theta23 - theta2;
            // The frame at the wrist before its three joints: Rz(θ1) · Ry(θ2 + θ3).
            let r_c = DMat3::from_rotation_z(theta1) * DMat3::from_rotation_y(theta23);
            for sign5 in [1.0, -1.0] {
                // Joint 5's axis is Rz(θ4) · y there.
                let local = r_c.transpose() * (sign5 * l[4].dir);
                let theta4 = (-local.x).atan2(local.y);
                let r_4 = r_c * DMat3::from_rotation_z(theta4);
                for sign6 in [1.0, -1.0] {
                    // Joint 6's axis is Ry(θ5) · z there.
                    let axis6 = sign6 * l[5].dir;
                    let local = r_4.transpose() * axis6;
                    let theta5 = local.x.atan2(local.z);
                    out.push((
                        OpwParameters {
                            a1,
                            a2,
                            b,
                            c1,
                            c2,
                            c3,
                            c4: (tip - wrist).dot(axis6),
                            // The model's zero is OPW's (θ1..θ5, 0): `θ = sign · q − offset`.
                            offsets: [-theta1, -theta2, -theta3, -theta4, -theta5, 0.0],
                            sign_corrections: [sign1, sign2, sign3, sign4, sign5, sign6],
                        },
                        Pose::from_translation(base),
                    ));
                }
            }
        }
    }
    // The usual choice first (as the ROS-Industrial parameter files state them): the forearm,
    // the shoulder's offset and the flange ahead, then the wrist's zero at the URDF's (no half
    // turn on joints 4 and 5); else as found.
    let half = std::f64::consts::FRAC_PI_2;
    out.sort_by_key(|(p, _)| {
        (
            p.c3 < 0.0,
            p.a1 < 0.0,
            p.c4 < 0.0,
            p.offsets[3].abs() > half,
            p.offsets[4].abs() > half,
        )
    });
    out
}

//! A six-joint chain's joint lines at zero, for the closed-form solvers that read their
//! parameters off the chain ([`crate::OpwIk::derive`], [`crate::ParallelIk::derive`]).
use crate::Chain;
use cellplan_geom::{DVec3, Pose};

/// Tolerance of the geometric tests (unit vectors, and metres over a robot's size).
pub(crate) const EPS: f64 = 1e-7;

/// A joint's line at the chain's zero, in the root frame: a point on it and its unit direction.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Line {
    pub(crate) point: DVec3,
    pub(crate) dir: DVec3,
}

impl Line {
    /// Distance from `p` to the line.
    pub(crate) fn distance(&self, p: DVec3) -> f64 {
        (p - self.point).cross(self.dir).length()
    }
}

/// The closest points of two lines that are not parallel: the point on `a` and the point on
/// `b`.
pub(crate) fn closest(a: &Line, b: &Line) -> Option<(DVec3, DVec3)> {
    let w = a.point - b.point;
    let (p, q) = (a.dir.dot(b.dir), a.dir.dot(w));
    let r = b.dir.dot(w);
    let den = 1.0 - p * p;
    if den < EPS {
        return None;
    }
    let s = (p * r - q) / den;
    let t = (r - p * q) / den;
    Some((a.point + s * a.dir, b.point + t * b.dir))
}

/// The six joints' lines at zero, when the chain has six rotational joints.
pub(crate) fn lines(chain: &Chain) -> Option<[Line; 6]> {
    if chain.dof() != 6 || !chain.joints.iter().all(|j| j.is_rotational()) {
        return None;
    }
    let mut poses = vec![Pose::IDENTITY; chain.links.len()];
    chain.fk_all(&[0.0; 6], &mut poses);
    let mut out = [Line {
        point: DVec3::ZERO,
        dir: DVec3::Z,
    }; 6];
    for (j, line) in out.iter_mut().enumerate() {
        let pose = poses[chain.joint_link(j)?];
        let dir = (pose.rotation * chain.joints[j].axis).normalize();
        if !dir.is_finite() || !pose.translation.is_finite() {
            return None;
        }
        *line = Line {
            point: pose.translation,
            dir,
        };
    }
    Some(out)
}

/// Where the closed forms put their base: the root moved level onto joint 1's axis, when that
/// axis is parallel to the root's z axis (URDFs made from CAD put it millimetres off the root).
/// The lines are moved into that frame; `None` (and the lines untouched) for a joint 1 that is
/// not vertical.
pub(crate) fn level_base(l: &mut [Line; 6]) -> Option<DVec3> {
    if l[0].dir.cross(DVec3::Z).length() > EPS {
        return None;
    }
    let base = DVec3::new(l[0].point.x, l[0].point.y, 0.0);
    for line in l.iter_mut() {
        line.point -= base;
    }
    Some(base)
}

/// The signed angle (rad) that turns `a` into `b` about the unit axis `k` (both square to it).
pub(crate) fn angle_about(a: DVec3, b: DVec3, k: DVec3) -> f64 {
    a.cross(b).dot(k).atan2(a.dot(b))
}

//! A body turned about an axis: the convex hull of every position the body takes as it turns
//! a whole turn about a line, as a support map.
//!
//! A link that turns about a joint's axis sweeps a solid of revolution; for a self pair whose
//! proximal body is turned about the first joint between the two (or whose distal body is
//! turned about the last), the distance from that solid to the other body no longer depends on
//! that joint. A robot's base is nearly a solid of revolution about its first axis, a wrist
//! link about its own: the distance then depends on one joint only, and a table of it over that
//! joint bounds the pair's distance in every configuration (`cellplan_motion::arm`).
//!
//! In the frame of the axis, a point at height `z` along it and at radius `r` from it sweeps a
//! circle; the support of all those circles in a direction with axial part `d_a` and radial
//! part of length `s` is the largest `z·d_a + r·s` over the body's points.
use crate::DVec3;
use parry3d_f64::shape::SupportMap;

/// The convex hull of a point set turned a whole turn about a line.
#[derive(Clone, Debug)]
pub struct Revolved {
    /// A point of the line.
    origin: DVec3,
    /// Its unit direction.
    axis: DVec3,
    /// A unit vector across it (for directions along the axis).
    across: DVec3,
    /// The upper hull of the points' (height along the axis, radius from it).
    profile: Vec<(f64, f64)>,
}

impl Revolved {
    /// `points` turned about the line through `origin` along `axis` (any length but zero);
    /// `None` without points, for a zero or non-finite axis, or a non-finite point.
    pub fn new(points: &[DVec3], origin: DVec3, axis: DVec3) -> Option<Revolved> {
        let axis = axis.try_normalize()?;
        if points.is_empty() || !origin.is_finite() || !points.iter().all(|p| p.is_finite()) {
            return None;
        }
        let across = axis.any_orthonormal_vector();
        let mut profile: Vec<(f64, f64)> = points
            .iter()
            .map(|p| {
                let d = *p - origin;
                let z = d.dot(axis);
                (z, (d - axis * z).length())
            })
            .collect();
        // Only the points on the upper hull of the (z, r) profile can be a support (the radial
        // part of a direction is never negative).
        profile.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
        profile.dedup_by(|b, a| a.0 == b.0);
        let mut hull: Vec<(f64, f64)> = Vec::with_capacity(profile.len());
        for p in profile {
            while hull.len() >= 2 {
                let (o, a) = (hull[hull.len() - 2], hull[hull.len() - 1]);
                // Keep a chain turning clockwise: drop `a` when it lies on or below o → p.
                let cross = (a.0 - o.0) * (p.1 - o.1) - (a.1 - o.1) * (p.0 - o.0);
                if cross >= 0.0 {
                    hull.pop();
                } else {
                    break;
                }
            }
            hull.push(p);
        }
        Some(Revolved {
            origin,
            axis,
            across,
            profile: hull,
        })
    }

    /// An upper bound on the distance of the set's points from the line through `p` along
    /// the unit vector `d`: each point of the profile sweeps a circle, no farther from the line
    /// than its centre is plus its radius.
    pub fn reach_from(&self, p: DVec3, d: DVec3) -> f64 {
        self.profile
            .iter()
            .map(|&(z, r)| (self.origin + self.axis * z - p).cross(d).length() + r)
            .fold(0.0, f64::max)
    }
}

impl SupportMap for Revolved {
    fn local_support_point(&self, dir: DVec3) -> DVec3 {
        let da = dir.dot(self.axis);
        let radial = dir - self.axis * da;
        let s = radial.length();
        let out = if s > 1e-300 { radial / s } else { self.across };
        let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
        for &(z, r) in &self.profile {
            let v = z * da + r * s;
            if v > best.0 {
                best = (v, z, r);
            }
        }
        self.origin + self.axis * best.1 + out * best.2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DQuat, Pose};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Every point turned by any angle about the axis lies within the support in every
    /// direction, the support point lies on a profile point's circle, and the reach from the
    /// axis is the largest radius.
    #[test]
    fn the_support_bounds_every_turned_point() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut v = || {
            DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
        };
        let points: Vec<DVec3> = (0..40).map(|_| v() * 0.3).collect();
        let (origin, axis) = (v() * 0.2, v());
        let rev = Revolved::new(&points, origin, axis).expect("a set");
        let axis = axis.normalize();
        for k in 0..300 {
            let dir = v();
            let s = rev.local_support_point(dir);
            let h = s.dot(dir);
            let turn = Pose::from_parts(DVec3::ZERO, DQuat::from_axis_angle(axis, 0.021 * k as f64));
            for p in &points {
                let turned = origin + turn.transform_point(*p - origin);
                assert!(turned.dot(dir) <= h + 1e-12, "{} beyond {h}", turned.dot(dir));
            }
            let d = s - origin;
            let z = d.dot(axis);
            let r = (d - axis * z).length();
            assert!(
                rev.profile
                    .iter()
                    .any(|&(pz, pr)| (pz - z).abs() < 1e-9 && (pr - r).abs() < 1e-9),
                "({z}, {r}) not on the profile"
            );
        }
        let rmax = points
            .iter()
            .map(|p| ((*p - origin) - axis * (*p - origin).dot(axis)).length())
            .fold(0.0, f64::max);
        assert!((rev.reach_from(origin, axis) - rmax).abs() < 1e-12);
        assert!(Revolved::new(&[], origin, axis).is_none());
        assert!(Revolved::new(&points, origin, DVec3::ZERO).is_none());
    }
}

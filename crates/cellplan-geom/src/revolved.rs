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

/// A solid cylinder about a line: its centre on the line, the unit direction of the line,
/// and its half height along it and radius across it. As a support map, it stands in a body
/// turned about its axis for proofs of contact: a cylinder about a joint's axis inside a body
/// stays inside it whatever the joint's value ([`inner_cylinders`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// The centre, on the axis.
    pub centre: DVec3,
    /// The axis' unit direction.
    pub axis: DVec3,
    /// Half the length along the axis.
    pub half_height: f64,
    /// The radius across it.
    pub radius: f64,
}

impl Cylinder {
    /// The points at least `by` inside the cylinder (a cylinder `by` shorter at each end and
    /// `by` thinner); `None` when nothing is left.
    pub fn eroded(&self, by: f64) -> Option<Cylinder> {
        let (half_height, radius) = (self.half_height - by, self.radius - by);
        (half_height > 0.0 && radius > 0.0).then_some(Cylinder {
            half_height,
            radius,
            ..*self
        })
    }
}

impl SupportMap for Cylinder {
    fn local_support_point(&self, dir: DVec3) -> DVec3 {
        let da = dir.dot(self.axis);
        let radial = dir - self.axis * da;
        let s = radial.length();
        let out = if s > 1e-300 {
            radial * (self.radius / s)
        } else {
            DVec3::ZERO
        };
        self.centre + self.axis * self.half_height.copysign(da) + out
    }
}

/// Heights tried for each end of [`inner_cylinders`]' cylinders.
const INNER_HEIGHTS: usize = 24;

/// Cylinders about the line through `origin` along `axis` inside the convex hull of `points`,
/// their ends at `INNER_HEIGHTS` heights spread over the line's stretch inside the hull: the
/// one of largest volume, and the widest of those at least `2·min_half_height` long (when it
/// is another). Every point of them stays inside the hull however the hull is turned about the
/// line (a cylinder is a solid of revolution about it), so a body turned about a joint keeps
/// them in every position. Empty when the hull is flat, the line misses it or the points are
/// not finite.
///
/// The hull is the intersection of its faces' half-spaces `n·x ≤ c` (each `c` the points'
/// largest `n·x`, so rounding never lets a face cut into the hull). In the line's frame, a
/// face's normal has an axial part `a` and a radial part of length `b`; the circle of radius
/// `r` at height `z` lies in its half-space when `a·z + b·r ≤ c − n·origin`, and a cylinder
/// does when both its end circles do.
pub fn inner_cylinders(points: &[DVec3], origin: DVec3, axis: DVec3, min_half_height: f64) -> Vec<Cylinder> {
    inner_cylinders_opt(points, origin, axis, min_half_height).unwrap_or_default()
}

fn inner_cylinders_opt(
    points: &[DVec3],
    origin: DVec3,
    axis: DVec3,
    min_half_height: f64,
) -> Option<Vec<Cylinder>> {
    let axis = axis.try_normalize()?;
    if !origin.is_finite() || !points.iter().all(|p| p.is_finite()) {
        return None;
    }
    let hull = parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(points)?;
    let faces: Vec<(f64, f64, f64)> = hull
        .faces()
        .iter()
        .filter_map(|f| {
            let n = f.normal.try_normalize()?;
            let c = hull
                .points()
                .iter()
                .map(|p| n.dot(*p))
                .fold(f64::NEG_INFINITY, f64::max);
            let a = n.dot(axis);
            Some((a, (n - axis * a).length(), c - n.dot(origin)))
        })
        .collect();
    // The stretch of the line inside the hull.
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for &(a, _, c) in &faces {
        if a > 1e-12 {
            hi = hi.min(c / a);
        } else if a < -1e-12 {
            lo = lo.max(c / a);
        } else if c < 0.0 {
            return None;
        }
    }
    if !(lo.is_finite() && hi.is_finite() && hi > lo) {
        return None;
    }
    // The largest radius of a circle at height `z` in every half-space.
    let radius_at = |z: f64| {
        faces
            .iter()
            .filter(|f| f.1 > 1e-12)
            .map(|&(a, b, c)| (c - a * z) / b)
            .fold(f64::INFINITY, f64::min)
    };
    let heights: Vec<(f64, f64)> = (0..INNER_HEIGHTS)
        .map(|k| {
            let z = lo + (hi - lo) * k as f64 / (INNER_HEIGHTS - 1) as f64;
            (z, radius_at(z))
        })
        .collect();
    // (volume, cylinder) of the largest volume; (radius, cylinder) of the widest long enough.
    let mut roomiest: Option<(f64, Cylinder)> = None;
    let mut widest: Option<(f64, Cylinder)> = None;
    for (k, &(z0, r0)) in heights.iter().enumerate() {
        for &(z1, r1) in &heights[k + 1..] {
            let r = r0.min(r1);
            if !(r.is_finite() && r > 0.0) {
                continue;
            }
            let c = Cylinder {
                centre: origin + axis * (0.5 * (z0 + z1)),
                axis,
                half_height: 0.5 * (z1 - z0),
                radius: r,
            };
            let volume = r * r * (z1 - z0);
            if roomiest.as_ref().is_none_or(|(v, _)| volume > *v) {
                roomiest = Some((volume, c));
            }
            if c.half_height >= min_half_height && widest.as_ref().is_none_or(|(w, _)| r > *w) {
                widest = Some((r, c));
            }
        }
    }
    let mut out: Vec<Cylinder> = roomiest.map(|(_, c)| c).into_iter().collect();
    if let Some((_, c)) = widest
        && !out.contains(&c)
    {
        out.push(c);
    }
    Some(out)
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

    /// The inner cylinders lie inside the hull in every turn about the axis (every point of
    /// their end circles, turned, is within the hull's support in random directions); the
    /// widest is at least as wide as the roomiest and at least as long as asked; a regular
    /// prism about the axis gets nearly its inscribed radius; a line missing the hull gets none.
    #[test]
    fn inner_cylinders_stay_inside_the_turned_hull() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let mut v = |s: f64| crate::random_vector(&mut rng, s);
        let mut found = 0;
        for _ in 0..40 {
            let points: Vec<DVec3> = (0..30).map(|_| v(0.3)).collect();
            let (origin, axis) = (v(0.05), v(1.0));
            let cs = inner_cylinders(&points, origin, axis, 0.01);
            found += cs.len();
            let axis = axis.normalize();
            let dirs: Vec<DVec3> = (0..200).map(|_| v(1.0)).collect();
            for c in &cs {
                assert!((c.axis - axis).length() < 1e-12);
                let off = c.centre - origin;
                assert!(
                    (off - axis * off.dot(axis)).length() < 1e-12,
                    "centre off the line"
                );
                let across = axis.any_orthonormal_vector();
                for k in 0..24 {
                    let turn = DQuat::from_axis_angle(axis, k as f64 * 0.2618);
                    for end in [-1.0, 1.0] {
                        let p = c.centre + axis * (end * c.half_height) + turn * across * c.radius;
                        for d in &dirs {
                            let h = points.iter().map(|x| x.dot(*d)).fold(f64::NEG_INFINITY, f64::max);
                            assert!(p.dot(*d) <= h + 1e-9, "a rim point outside the hull");
                        }
                    }
                }
                // The support map is the cylinder's.
                for d in &dirs {
                    let sp = c.local_support_point(*d);
                    let rim = c.centre + axis * c.half_height.copysign(d.dot(axis));
                    assert!((sp - rim).length() <= c.radius + 1e-12);
                }
            }
            if let [roomiest, widest] = &cs[..] {
                assert!(widest.radius >= roomiest.radius && widest.half_height >= 0.01);
            }
        }
        assert!(found >= 40, "{found} cylinders");
        // A regular 32-gon prism, 0.2 high, radius 0.1, about the z axis.
        let prism: Vec<DVec3> = (0..64)
            .map(|k| {
                let a = (k % 32) as f64 * std::f64::consts::TAU / 32.0;
                DVec3::new(0.1 * a.cos(), 0.1 * a.sin(), if k < 32 { 0.0 } else { 0.2 })
            })
            .collect();
        let cs = inner_cylinders(&prism, DVec3::ZERO, DVec3::Z, 0.003);
        let inscribed = 0.1 * (std::f64::consts::PI / 32.0).cos();
        assert!(
            cs[0].radius > inscribed - 1e-9 && cs[0].radius <= inscribed + 1e-9,
            "{cs:?}"
        );
        assert!((cs[0].half_height - 0.1).abs() < 1e-9);
        assert!(inner_cylinders(&prism, DVec3::new(0.5, 0.0, 0.0), DVec3::Z, 0.0).is_empty());
        assert!(inner_cylinders(&prism, DVec3::ZERO, DVec3::ZERO, 0.0).is_empty());
        let c = cs[0];
        let e = c.eroded(0.01).expect("room left");
        assert!((e.radius - (c.radius - 0.01)).abs() < 1e-15 && (e.half_height - 0.09).abs() < 1e-12);
        assert!(c.eroded(0.1).is_none());
    }
}

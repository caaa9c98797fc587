//! Ray queries of the collision world: the first static object, or the first body of a group,
//! that a ray hits.
use super::{CollisionWorld, GroupId, Placement, RayHit, StaticId, place};
use crate::{DVec3, Pose};
use parry3d_f64::query::{Ray, RayCast};

impl CollisionWorld {
    /// First static object hit by the ray `origin + t·dir`, `0 ≤ t ≤ max_distance`.
    ///
    /// `dir` need not be unit length: it is normalised, and the distance is in metres. Boxes,
    /// cylinders and spheres are solid (a ray starting inside one hits it at distance 0);
    /// meshes are surfaces, hit from either side. Ties go to the object added first. `None`
    /// for a zero or non-finite direction.
    pub fn cast_ray_static(&self, origin: DVec3, dir: DVec3, max_distance: f64) -> Option<RayHit> {
        let (ray, max) = make_ray(origin, dir, max_distance)?;
        let mut best: Option<RayHit> = None;
        for (k, s) in self.statics.iter().enumerate() {
            let Some(shape) = s.shape.as_deref() else {
                continue;
            };
            let limit = best.map_or(max, |b| b.distance);
            if s.aabb.cast_local_ray(&ray, limit, true).is_none() {
                continue;
            }
            if let Some(t) = shape.cast_ray(&s.pose, &ray, limit, true)
                && best.is_none_or(|b| t < b.distance)
            {
                best = Some(RayHit {
                    object: StaticId(k as u32),
                    distance: t,
                });
            }
        }
        best
    }

    /// First body of group `g` at `poses` hit by the ray, as `(body, distance)`.
    ///
    /// Bodies are solid convex shapes (a ray starting inside one hits it at distance 0).
    /// Same conventions as [`CollisionWorld::cast_ray_static`].
    pub fn cast_ray_group(
        &self,
        g: GroupId,
        poses: &[Pose],
        origin: DVec3,
        dir: DVec3,
        max_distance: f64,
    ) -> Option<(usize, f64)> {
        self.cast_ray_group_except(g, poses, origin, dir, max_distance, &[])
    }

    /// [`CollisionWorld::cast_ray_group`] ignoring the bodies `except` (for rays that start on
    /// them, such as the beams of a probe, which must not hide the bodies behind it).
    pub fn cast_ray_group_except(
        &self,
        g: GroupId,
        poses: &[Pose],
        origin: DVec3,
        dir: DVec3,
        max_distance: f64,
        except: &[usize],
    ) -> Option<(usize, f64)> {
        let (ray, max) = make_ray(origin, dir, max_distance)?;
        let group = self.group(g);
        let mut best: Option<(usize, f64)> = None;
        for (i, (body, pose)) in group.bodies.iter().zip(poses).enumerate() {
            if except.contains(&i) {
                continue;
            }
            let Placement::At(p) = place(body, pose) else {
                continue;
            };
            let limit = best.map_or(max, |b| b.1);
            if p.aabb.cast_local_ray(&ray, limit, true).is_none() {
                continue;
            }
            if let Some(t) = p.shape.cast_ray(&p.pose, &ray, limit, true)
                && best.is_none_or(|b| t < b.1)
            {
                best = Some((i, t));
            }
        }
        best
    }
}

fn make_ray(origin: DVec3, dir: DVec3, max_distance: f64) -> Option<(Ray, f64)> {
    let dir = dir.try_normalize()?;
    if !origin.is_finite() || max_distance.is_nan() || max_distance < 0.0 {
        return None;
    }
    Some((Ray::new(origin, dir), max_distance))
}

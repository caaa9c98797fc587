//! Lower bounds on distances from the bodies' sphere covers (see [`crate::spheres`]): the
//! broad phase in front of the exact (GJK) distances of the world.
//!
//! Every bound here is at most the exact distance the matching exact query returns (the covers
//! contain the bodies), capped like it: `min(bound, cap)`, 0 for a non-finite pose. A caller
//! that only needs to know whether the distance reaches some value asks for the bound first and
//! runs the exact query only when the bound falls short.
use super::{CollisionWorld, GroupId, sanitize_margin};
use crate::spheres::Sphere;
use crate::{DVec3, Pose};

/// Distance from `p` to a box, 0 inside.
#[inline]
fn point_box_distance(p: DVec3, mins: DVec3, maxs: DVec3) -> f64 {
    (mins - p).max(p - maxs).max(DVec3::ZERO).length()
}

impl CollisionWorld {
    /// The sphere cover of body `i` of group `g` (body frame); empty for a body without shapes.
    pub fn body_cover(&self, g: GroupId, i: usize) -> &[Sphere] {
        self.group(g).bodies[i]
            .convex
            .as_ref()
            .map_or(&[], |c| c.cover.spheres.as_slice())
    }

    /// A lower bound on the distance from body `i` of `g` (at `poses[i]`) to the static scene,
    /// capped at `cap` (see [`CollisionWorld::body_static_distance`], which it never exceeds).
    ///
    /// Per object: the body's outer sphere against the object's bounding box first, then each
    /// sphere of the cover against the box and, if still below the bound so far, against the
    /// object itself (a point query: solid primitives, mesh surfaces).
    pub fn body_static_bound(&self, g: GroupId, i: usize, poses: &[Pose], cap: f64) -> f64 {
        let mut best = sanitize_margin(cap);
        let (Some(body), Some(pose)) = (self.group(g).bodies.get(i), poses.get(i)) else {
            return best;
        };
        let Some(convex) = body.convex.as_ref() else {
            return best;
        };
        let Some(outer) = convex.cover.outer else {
            return best;
        };
        if !pose.is_finite() {
            return if self.first_solid_static().is_some() {
                0.0
            } else {
                best
            };
        }
        let oc = pose.transform_point(outer.centre);
        // World centres of the cover, placed on first need.
        let mut placed: [DVec3; crate::spheres::MAX_SLABS] = [DVec3::ZERO; crate::spheres::MAX_SLABS];
        let mut n_placed = 0;
        for s in &self.statics {
            let Some(shape) = s.shape.as_deref() else {
                continue;
            };
            if point_box_distance(oc, s.aabb.mins, s.aabb.maxs) - outer.radius >= best {
                continue;
            }
            let solid = shape.as_trimesh().is_none();
            let spheres = &convex.cover.spheres;
            if n_placed == 0 {
                for (k, sp) in spheres.iter().enumerate().take(placed.len()) {
                    placed[k] = pose.transform_point(sp.centre);
                }
                n_placed = spheres.len().min(placed.len());
            }
            for (k, sp) in spheres.iter().enumerate() {
                let c = if k < n_placed {
                    placed[k]
                } else {
                    pose.transform_point(sp.centre)
                };
                if point_box_distance(c, s.aabb.mins, s.aabb.maxs) - sp.radius >= best {
                    continue;
                }
                let reach = best + sp.radius;
                if let Some(proj) = shape.project_point_with_max_dist(&s.pose, c, solid, reach) {
                    let d = if solid && proj.is_inside {
                        0.0
                    } else {
                        (proj.point - c).length()
                    };
                    best = best.min((d - sp.radius).max(0.0));
                    if best <= 0.0 {
                        return 0.0;
                    }
                }
            }
        }
        best
    }

    /// A lower bound on the distance between bodies `i` and `j` of `g` (whether or not the pair
    /// is checked), capped at `cap` (see [`CollisionWorld::pair_distance`]).
    pub fn pair_bound(&self, g: GroupId, i: usize, j: usize, poses: &[Pose], cap: f64) -> f64 {
        self.bodies_bound(g, i, poses, g, j, poses, cap)
    }

    /// A lower bound on the distance from body `i` of `g` (at `poses[i]`) to every body of
    /// group `other` (at `other_poses`), capped at `cap` (see
    /// [`CollisionWorld::body_group_distance`]).
    pub fn body_group_bound(
        &self,
        g: GroupId,
        i: usize,
        poses: &[Pose],
        other: GroupId,
        other_poses: &[Pose],
        cap: f64,
    ) -> f64 {
        let mut best = sanitize_margin(cap);
        for j in 0..self.group(other).bodies.len() {
            best = self.bodies_bound(g, i, poses, other, j, other_poses, best);
            if best <= 0.0 {
                return 0.0;
            }
        }
        best
    }

    /// The bound between body `i` of `ga` and body `j` of `gb`: outer spheres, then every pair
    /// of cover spheres.
    #[allow(clippy::too_many_arguments)]
    fn bodies_bound(
        &self,
        ga: GroupId,
        i: usize,
        poses_a: &[Pose],
        gb: GroupId,
        j: usize,
        poses_b: &[Pose],
        cap: f64,
    ) -> f64 {
        let best = sanitize_margin(cap);
        if ga == gb && i == j {
            return best;
        }
        let (Some(a), Some(b), Some(pa), Some(pb)) = (
            self.group(ga).bodies.get(i),
            self.group(gb).bodies.get(j),
            poses_a.get(i),
            poses_b.get(j),
        ) else {
            return best;
        };
        let (Some(ca), Some(cb)) = (a.convex.as_ref(), b.convex.as_ref()) else {
            return best;
        };
        let (Some(oa), Some(ob)) = (ca.cover.outer, cb.cover.outer) else {
            return best;
        };
        if !pa.is_finite() || !pb.is_finite() {
            return 0.0;
        }
        let gap =
            (pa.transform_point(oa.centre) - pb.transform_point(ob.centre)).length() - oa.radius - ob.radius;
        if gap >= best {
            return best;
        }
        // Both covers in the frame of `a`.
        let rel = pa.inv_mul(pb);
        let mut least = best;
        for sb in &cb.cover.spheres {
            let c = rel.transform_point(sb.centre);
            for sa in &ca.cover.spheres {
                let d = (c - sa.centre).length() - sa.radius - sb.radius;
                if d < least {
                    least = d;
                    if least <= 0.0 {
                        return 0.0;
                    }
                }
            }
        }
        least
    }
}

#[cfg(test)]
mod tests {
    use crate::world::tests::random_pose;
    use crate::world::{CollisionWorld, GroupBody};
    use crate::{DVec3, Pose, ShapeSpec};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Over random placements, every bound is at most the exact distance, and it is tight
    /// enough to be of use: within a few centimetres when the exact distance is small.
    #[test]
    fn bounds_never_exceed_exact_distances() {
        let mut world = CollisionWorld::new();
        world.add_static(
            "box",
            &ShapeSpec::Box {
                half_extents: DVec3::new(0.3, 0.2, 0.05),
            },
            Pose::translation(0.0, 0.0, 0.0),
        );
        world.add_static(
            "drum",
            &ShapeSpec::Cylinder {
                radius: 0.1,
                half_height: 0.3,
            },
            Pose::translation(0.6, 0.0, 0.0),
        );
        let sheet = crate::Mesh {
            vertices: vec![
                DVec3::new(-1.0, -1.0, 0.5),
                DVec3::new(1.0, -1.0, 0.5),
                DVec3::new(1.0, 1.0, 0.5),
                DVec3::new(-1.0, 1.0, 0.7),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        world.add_static(
            "sheet",
            &ShapeSpec::Mesh(std::sync::Arc::new(sheet)),
            Pose::IDENTITY,
        );
        let link = GroupBody {
            name: "link".into(),
            shapes: vec![
                (
                    ShapeSpec::Box {
                        half_extents: DVec3::new(0.2, 0.03, 0.04),
                    },
                    Pose::IDENTITY,
                ),
                (
                    ShapeSpec::Sphere { radius: 0.05 },
                    Pose::translation(0.2, 0.0, 0.0),
                ),
            ],
        };
        let drum = GroupBody {
            name: "drum".into(),
            shapes: vec![(
                ShapeSpec::Cylinder {
                    radius: 0.04,
                    half_height: 0.15,
                },
                Pose::IDENTITY,
            )],
        };
        let g = world.add_group("arm", vec![link, drum]);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut close = 0;
        for _ in 0..3000 {
            let poses = [random_pose(&mut rng, 0.8), random_pose(&mut rng, 0.8)];
            for i in 0..2 {
                let exact = world.body_static_distance(g, i, &poses, 10.0);
                let bound = world.body_static_bound(g, i, &poses, 10.0);
                assert!(bound <= exact + 1e-9, "static bound {bound} > exact {exact}");
                if exact > 0.0 && exact < 0.05 {
                    close += 1;
                    assert!(bound >= exact - 0.12, "bound {bound} far below {exact}");
                }
            }
            let exact = world.pair_distance(g, 0, 1, &poses, 10.0);
            let bound = world.pair_bound(g, 0, 1, &poses, 10.0);
            assert!(bound <= exact + 1e-9, "pair bound {bound} > exact {exact}");
            // Capped: never above the cap.
            assert!(world.pair_bound(g, 0, 1, &poses, 0.01) <= 0.01);
        }
        assert!(close > 20, "the test places bodies near the objects ({close})");
        // A non-finite pose is at distance 0.
        let bad = [Pose::translation(f64::NAN, 0.0, 0.0), Pose::IDENTITY];
        assert_eq!(world.body_static_bound(g, 0, &bad, 1.0), 0.0);
        assert_eq!(world.pair_bound(g, 0, 1, &bad, 1.0), 0.0);
    }
}

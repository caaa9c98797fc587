//! The collision world: a static scene and articulated body groups (one per robot).
//!
//! # Shapes
//!
//! - **Static objects** keep their exact shape: a box, a cylinder (axis z), a sphere, or a
//!   triangle mesh. A mesh is a **surface, not a solid**: a body wholly inside a closed mesh,
//!   touching none of its triangles, does not collide with it. That is the right model for
//!   sheet-metal parts such as car bodies (the robot works inside their openings); a solid
//!   that must not be entered is better stated with primitives (or a convex mesh as a body).
//! - **Bodies** of a group (robot links, the tool) are each **one convex shape**: the
//!   primitive itself when the body has exactly one box, cylinder or sphere, else the convex
//!   hull of all its shapes (cylinders and spheres enter the hull through circumscribing
//!   polytopes, so the hull is conservative: it contains every shape). A body without shapes
//!   never collides.
//!
//! # Queries
//!
//! "Closer than `margin`" means the distance between the two shapes is at most `margin`
//! (`margin = 0`: touching or overlapping). Queries report the **first** contact in a fixed
//! order (bodies in order, then objects or other bodies in order), so results are
//! deterministic. They allocate nothing, and the world is `Send + Sync`: share it across
//! threads by reference.
//!
//! Poses must be finite. A body at a non-finite pose is treated as colliding (with the first
//! static object, or with its pair partner), and as at distance 0; rays ignore it.
use crate::hull::FastHull;
use crate::shape::{body_shape, shape_as_mesh, static_shape};
use crate::spheres::Cover;
use crate::{DVec3, Mesh, Pose, ShapeSpec};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::shape::{Shape, SharedShape, SupportMap};

/// Index of a static object in a [`CollisionWorld`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct StaticId(pub u32);

/// Index of a body group (a robot with its tool) in a [`CollisionWorld`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct GroupId(pub u32);

/// One rigid body of a group (a robot link, or the tool): shapes fixed in the body frame.
#[derive(Clone, Debug)]
pub struct GroupBody {
    /// Name, for reports (the link name).
    pub name: String,
    /// Shapes and their poses in the body frame. They are merged into one convex hull.
    pub shapes: Vec<(ShapeSpec, Pose)>,
}

/// What touched what.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyContact {
    /// Body `body` of the group is within the margin of static object `object`.
    Static {
        /// Body index in the group.
        body: usize,
        /// The static object.
        object: StaticId,
    },
    /// Two bodies of the same group.
    SelfPair(usize, usize),
    /// Body `a` of the first group and body `b` of the second.
    Pair(usize, usize),
}

/// The first object a ray hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// The object hit.
    pub object: StaticId,
    /// Distance along the ray (the direction is unit length).
    pub distance: f64,
}

/// A static object: its parry shape at its world pose.
struct StaticObject {
    name: String,
    /// `None` for a shape with no geometry (it never collides).
    shape: Option<SharedShape>,
    /// World pose of the parry shape.
    pose: Pose,
    /// World AABB of the shape.
    aabb: Aabb,
}

/// One convex body of a group.
struct Body {
    name: String,
    /// `None` for a body without shapes (it never collides).
    convex: Option<BodyConvex>,
}

/// The convex shape of a body, with what speeds up its queries.
struct BodyConvex {
    /// A primitive or a `ConvexPolyhedron`.
    shape: SharedShape,
    /// Pose of `shape` in the body frame.
    local: Pose,
    /// Bounds of the shape in the body frame.
    local_aabb: Aabb,
    /// Hill-climbing support for large hulls.
    fast: Option<FastHull>,
    /// Spheres containing the shape (body frame), for lower bounds on distances.
    cover: Cover,
}

impl BodyConvex {
    fn new(shape: SharedShape, local: Pose) -> Option<Self> {
        shape.as_support_map()?;
        let fast = shape.as_convex_polyhedron().and_then(FastHull::new);
        Some(BodyConvex {
            local_aabb: shape.compute_aabb(&local),
            cover: Cover::of(&*shape, &local),
            shape,
            local,
            fast,
        })
    }

    fn support(&self) -> &dyn SupportMap {
        match &self.fast {
            Some(f) => f,
            // `new` checked that the shape is a support map; a ball is a harmless stand-in.
            None => self.shape.as_support_map().unwrap_or(&NO_SUPPORT),
        }
    }
}

const NO_SUPPORT: parry3d_f64::shape::Ball = parry3d_f64::shape::Ball { radius: 0.0 };

struct Group {
    name: String,
    bodies: Vec<Body>,
    /// Bodies left out of static checks (they never move: a robot's base on its floor).
    exempt: Vec<bool>,
    /// Sorted, deduplicated pairs `(i, j)`, `i < j < bodies.len()`.
    self_pairs: Vec<(usize, usize)>,
}

/// The static scene and the robots' bodies.
///
/// Group and object ids are only meaningful for the world that issued them: methods panic
/// on an id from elsewhere (a programming error, like an out-of-range index).
#[derive(Default)]
pub struct CollisionWorld {
    statics: Vec<StaticObject>,
    groups: Vec<Group>,
}

/// A body placed in the world for one query.
struct Placed<'a> {
    shape: &'a dyn Shape,
    support: &'a dyn SupportMap,
    /// World pose of the shape.
    pose: Pose,
    /// World AABB (conservative).
    aabb: Aabb,
}

impl CollisionWorld {
    /// An empty world.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a static object. Meshes become a triangle-mesh surface with a BVH.
    ///
    /// A shape without geometry (a mesh without valid triangles, non-finite dimensions) or a
    /// non-finite pose gives an object that never collides and no ray hits.
    pub fn add_static(&mut self, name: &str, shape: &ShapeSpec, pose: Pose) -> StaticId {
        let id = StaticId(self.statics.len() as u32);
        let converted = if pose.is_finite() {
            static_shape(shape)
        } else {
            None
        };
        let (shape, pose, aabb) = match converted {
            Some((s, local)) => {
                let world = pose * local;
                let aabb = s.compute_aabb(&world);
                (Some(s), world, aabb)
            }
            None => (None, Pose::IDENTITY, Aabb::new_invalid()),
        };
        self.statics.push(StaticObject {
            name: name.to_string(),
            shape,
            pose,
            aabb,
        });
        id
    }

    /// Removes every static object (their ids become invalid); the groups stay. For a scene whose
    /// obstacles change between queries while the robots stay.
    pub fn clear_statics(&mut self) {
        self.statics.clear();
    }

    /// Name of a static object.
    pub fn static_name(&self, id: StaticId) -> &str {
        &self.statics[id.0 as usize].name
    }

    /// Number of static objects.
    pub fn static_count(&self) -> usize {
        self.statics.len()
    }

    /// World-space bounds `(min, max)` of a static object; `None` when it has no geometry.
    pub fn static_aabb(&self, id: StaticId) -> Option<(DVec3, DVec3)> {
        let s = &self.statics[id.0 as usize];
        s.shape.as_ref().map(|_| (s.aabb.mins, s.aabb.maxs))
    }

    /// Adds a body group; each body becomes one convex hull (conservative).
    ///
    /// No self pairs are checked until [`CollisionWorld::set_self_pairs`] says which.
    pub fn add_group(&mut self, name: &str, bodies: Vec<GroupBody>) -> GroupId {
        let id = GroupId(self.groups.len() as u32);
        let bodies = bodies
            .into_iter()
            .map(|b| Body {
                convex: body_shape(&b.shapes).and_then(|(s, l)| BodyConvex::new(s, l)),
                name: b.name,
            })
            .collect::<Vec<_>>();
        self.groups.push(Group {
            name: name.to_string(),
            exempt: vec![false; bodies.len()],
            bodies,
            self_pairs: Vec::new(),
        });
        id
    }

    /// Leaves bodies of group `g` out of [`CollisionWorld::group_vs_static`]: bodies that never
    /// move (a robot's base standing on its floor or pedestal) would otherwise touch the scene
    /// in every configuration. Out-of-range indices are ignored.
    pub fn set_static_exempt(&mut self, g: GroupId, bodies: &[usize]) {
        let group = &mut self.groups[g.0 as usize];
        group.exempt.iter_mut().for_each(|e| *e = false);
        for &b in bodies {
            if let Some(e) = group.exempt.get_mut(b) {
                *e = true;
            }
        }
    }

    /// Whether body `i` of group `g` is left out of the static checks (see
    /// [`CollisionWorld::set_static_exempt`]); false for an index out of range.
    pub fn is_static_exempt(&self, g: GroupId, i: usize) -> bool {
        self.group(g).exempt.get(i).copied().unwrap_or(false)
    }

    /// Number of groups.
    pub fn group_count(&self) -> usize {
        self.groups.len()
    }

    /// Name of a group.
    pub fn group_name(&self, g: GroupId) -> &str {
        &self.group(g).name
    }

    /// Number of bodies in a group.
    pub fn body_count(&self, g: GroupId) -> usize {
        self.group(g).bodies.len()
    }

    /// Name of body `i` of group `g`.
    pub fn body_name(&self, g: GroupId, i: usize) -> &str {
        &self.group(g).bodies[i].name
    }

    /// The sphere cover of body `i` of group `g` (body frame; see [`crate::spheres`]); empty
    /// for a body without shapes.
    pub fn body_cover(&self, g: GroupId, i: usize) -> &[crate::Sphere] {
        self.group(g).bodies[i]
            .convex
            .as_ref()
            .map_or(&[], |c| c.cover.spheres.as_slice())
    }

    /// The points whose convex hull is body `i`'s convex shape, in the body frame: a convex
    /// polyhedron's vertices, a box's corners; `None` for other shapes and bodies without one.
    pub fn body_points(&self, g: GroupId, i: usize) -> Option<Vec<DVec3>> {
        let c = self.group(g).bodies.get(i)?.convex.as_ref()?;
        let points: Vec<DVec3> = if let Some(p) = c.shape.as_convex_polyhedron() {
            p.points().to_vec()
        } else if let Some(b) = c.shape.as_cuboid() {
            let h = b.half_extents;
            (0..8)
                .map(|k| {
                    DVec3::new(
                        if k & 1 == 0 { -h.x } else { h.x },
                        if k & 2 == 0 { -h.y } else { h.y },
                        if k & 4 == 0 { -h.z } else { h.z },
                    )
                })
                .collect()
        } else {
            return None;
        };
        Some(points.into_iter().map(|p| c.local.transform_point(p)).collect())
    }

    /// Body `i`'s convex shape as a support map, with its pose in the body frame; `None` for
    /// a body without shapes.
    pub fn body_support(&self, g: GroupId, i: usize) -> Option<(&dyn SupportMap, Pose)> {
        let c = self.group(g).bodies.get(i)?.convex.as_ref()?;
        Some((c.support(), c.local))
    }

    /// The convex shape that stands for body `i` of group `g`, as a mesh in the body frame
    /// (for drawing and checks); `None` for a body without shapes.
    pub fn body_hull(&self, g: GroupId, i: usize) -> Option<Mesh> {
        let c = self.group(g).bodies[i].convex.as_ref()?;
        shape_as_mesh(&*c.shape, &c.local)
    }

    /// Sets which self pairs `(i, j)` (i < j) of group `g` are checked; all others are skipped.
    ///
    /// Until this is called a group checks **no** self pairs. Pairs are normalised to
    /// `i < j`, sorted and deduplicated; pairs `(i, i)` and pairs naming a body the group does
    /// not have are dropped.
    pub fn set_self_pairs(&mut self, g: GroupId, pairs: Vec<(usize, usize)>) {
        let group = &mut self.groups[g.0 as usize];
        let n = group.bodies.len();
        let mut pairs: Vec<(usize, usize)> = pairs
            .into_iter()
            .map(|(i, j)| (i.min(j), i.max(j)))
            .filter(|&(i, j)| i != j && j < n)
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        group.self_pairs = pairs;
    }

    /// The self pairs checked for group `g` (see [`CollisionWorld::set_self_pairs`]).
    pub fn self_pairs(&self, g: GroupId) -> &[(usize, usize)] {
        &self.group(g).self_pairs
    }

    /// First contact of any body of `g` (at `poses`, world frame, one per body) with the static
    /// scene, closer than `margin`.
    ///
    /// Bodies are taken in order and, for each, the objects in order. A body whose AABB
    /// (loosened by `margin`) misses an object's AABB is not tested further against it.
    pub fn group_vs_static(&self, g: GroupId, poses: &[Pose], margin: f64) -> Option<BodyContact> {
        let group = self.group(g);
        debug_assert_eq!(poses.len(), group.bodies.len(), "one pose per body");
        let margin = sanitize_margin(margin);
        for (i, (body, pose)) in group.bodies.iter().zip(poses).enumerate() {
            if group.exempt[i] {
                continue;
            }
            let placed = match place(body, pose) {
                Placement::Empty => continue,
                Placement::Invalid => {
                    if let Some(object) = self.first_solid_static() {
                        return Some(BodyContact::Static { body: i, object });
                    }
                    continue;
                }
                Placement::At(p) => p,
            };
            let query_aabb = loosened(&placed.aabb, margin);
            for (k, s) in self.statics.iter().enumerate() {
                let Some(shape) = s.shape.as_deref() else {
                    continue;
                };
                if !overlap(&query_aabb, &s.aabb) {
                    continue;
                }
                if static_within(s, shape, &placed, margin) {
                    return Some(BodyContact::Static {
                        body: i,
                        object: StaticId(k as u32),
                    });
                }
            }
        }
        None
    }

    /// First checked self pair of `g` closer than `margin`.
    ///
    /// Only the pairs set by [`CollisionWorld::set_self_pairs`] are checked (none by default),
    /// in sorted order.
    pub fn group_self(&self, g: GroupId, poses: &[Pose], margin: f64) -> Option<BodyContact> {
        let group = self.group(g);
        debug_assert_eq!(poses.len(), group.bodies.len(), "one pose per body");
        let margin = sanitize_margin(margin);
        group
            .self_pairs
            .iter()
            .find(|&&(i, j)| bodies_touch(group, i, group, j, poses, poses, margin))
            .map(|&(i, j)| BodyContact::SelfPair(i, j))
    }

    /// First pair of bodies of two groups closer than `margin`.
    ///
    /// Every pair is checked (bodies of `a` in order, and for each the bodies of `b` in order),
    /// with an AABB pretest. `a` and `b` may be the same group (then every pair `(i, j)`,
    /// `i < j`, is checked, regardless of the self-pair list).
    pub fn group_vs_group(
        &self,
        a: GroupId,
        poses_a: &[Pose],
        b: GroupId,
        poses_b: &[Pose],
        margin: f64,
    ) -> Option<BodyContact> {
        let (ga, gb) = (self.group(a), self.group(b));
        debug_assert_eq!(poses_a.len(), ga.bodies.len(), "one pose per body");
        debug_assert_eq!(poses_b.len(), gb.bodies.len(), "one pose per body");
        let margin = sanitize_margin(margin);
        let na = ga.bodies.len().min(poses_a.len());
        let nb = gb.bodies.len().min(poses_b.len());
        for i in 0..na {
            for j in 0..nb {
                if a == b && j <= i {
                    continue;
                }
                if bodies_touch(ga, i, gb, j, poses_a, poses_b, margin) {
                    return Some(BodyContact::Pair(i, j));
                }
            }
        }
        None
    }

    /// Whether bodies `i` and `j` of group `g` are closer than `margin` (for pair sampling).
    ///
    /// Checks the pair regardless of the self-pair list. False when `i == j` or either index
    /// has no body or no pose.
    pub fn bodies_within(&self, g: GroupId, i: usize, j: usize, poses: &[Pose], margin: f64) -> bool {
        let group = self.group(g);
        let n = group.bodies.len().min(poses.len());
        if i == j || i >= n || j >= n {
            return false;
        }
        bodies_touch(group, i, group, j, poses, poses, sanitize_margin(margin))
    }

    fn group(&self, g: GroupId) -> &Group {
        &self.groups[g.0 as usize]
    }

    fn first_solid_static(&self) -> Option<StaticId> {
        self.statics
            .iter()
            .position(|s| s.shape.is_some())
            .map(|k| StaticId(k as u32))
    }
}

enum Placement<'a> {
    /// The body has no shape.
    Empty,
    /// The pose is not finite.
    Invalid,
    At(Placed<'a>),
}

fn place<'a>(body: &'a Body, pose: &Pose) -> Placement<'a> {
    place_with(body, pose, true)
}

/// [`place`], with the world box only when `with_aabb` (else an empty box).
fn place_with<'a>(body: &'a Body, pose: &Pose, with_aabb: bool) -> Placement<'a> {
    let Some(c) = body.convex.as_ref() else {
        return Placement::Empty;
    };
    if !pose.is_finite() {
        return Placement::Invalid;
    }
    Placement::At(Placed {
        shape: &*c.shape,
        support: c.support(),
        // The body-frame box, turned: looser than the shape's own world box, but O(1).
        aabb: if with_aabb {
            c.local_aabb.transform_by(pose)
        } else {
            Aabb::new_invalid()
        },
        pose: *pose * c.local,
    })
}

/// Whether body `i` of `ga` (at `poses_a[i]`) and body `j` of `gb` (at `poses_b[j]`) are
/// closer than `margin`. Bodies without shapes never touch; a missing pose means no test.
fn bodies_touch(
    ga: &Group,
    i: usize,
    gb: &Group,
    j: usize,
    poses_a: &[Pose],
    poses_b: &[Pose],
    margin: f64,
) -> bool {
    let (Some(ba), Some(bb), Some(pa), Some(pb)) =
        (ga.bodies.get(i), gb.bodies.get(j), poses_a.get(i), poses_b.get(j))
    else {
        return false;
    };
    let (a, b) = match (place(ba, pa), place(bb, pb)) {
        (Placement::Empty, _) | (_, Placement::Empty) => return false,
        (Placement::Invalid, _) | (_, Placement::Invalid) => return true,
        (Placement::At(a), Placement::At(b)) => (a, b),
    };
    if !overlap(&loosened(&a.aabb, margin), &b.aabb) {
        return false;
    }
    convex_within(&a.pose.inv_mul(&b.pose), a.support, b.support, margin)
}

/// Negative and NaN margins count as 0.
fn sanitize_margin(margin: f64) -> f64 {
    if margin > 0.0 { margin } else { 0.0 }
}

fn loosened(aabb: &Aabb, margin: f64) -> Aabb {
    Aabb::new(aabb.mins - DVec3::splat(margin), aabb.maxs + DVec3::splat(margin))
}

#[inline]
fn overlap(a: &Aabb, b: &Aabb) -> bool {
    a.mins.cmple(b.maxs).all() && b.mins.cmple(a.maxs).all()
}

#[inline]
fn box_overlap(a: &Aabb, mins: DVec3, maxs: DVec3) -> bool {
    a.mins.cmple(maxs).all() && mins.cmple(a.maxs).all()
}

fn aabb_distance(a: &Aabb, b: &Aabb) -> f64 {
    let gap = (a.mins - b.maxs).max(b.mins - a.maxs).max(DVec3::ZERO);
    gap.length()
}

mod broad;
mod distance;
mod narrow;
mod rays;

pub use broad::{BroadPhase, PlacedCovers};
pub use distance::{convex_distance, convex_overlap};
pub use narrow::Precision;

use narrow::{convex_within, static_within};

#[cfg(test)]
mod tests;

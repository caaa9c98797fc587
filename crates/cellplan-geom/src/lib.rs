//! Geometry for cellplan: meshes (STL, OBJ), primitive shapes and the collision world.
//!
//! Everything is in SI units (metres) and uses glam's `f64` types; poses are parry's
//! [`Pose`] (a rotation quaternion plus a translation, always rigid).
//!
//! - [`mesh`]: [`Mesh`] and its loaders, [`load_mesh`] (binary/ASCII STL, OBJ), with errors
//!   that name the file and line.
//! - [`pieces`]: convex pieces of concave meshes (V-HACD), for collision bodies that fit.
//! - [`read`]: reading input files with a size limit (meshes, URDFs, cell files).
//! - [`shape`]: [`ShapeSpec`], the shapes a cell file can state (box, cylinder, sphere, mesh).
//! - [`spheres`]: conservative sphere covers of bodies, the world's broad phase.
//! - [`world`]: [`CollisionWorld`], the static scene plus articulated body groups (robots),
//!   with contact, distance and ray queries.
#![warn(missing_docs)]

pub mod error;
mod hull;
pub mod mesh;
pub mod pieces;
pub mod read;
pub mod revolved;
pub mod shape;
pub mod spheres;
pub mod world;

pub use error::MeshError;
pub use glam::{DMat3, DQuat, DVec3};
pub use mesh::{Mesh, load_mesh};
pub use parry3d_f64::math::Pose;
pub use shape::ShapeSpec;
pub use spheres::Sphere;
pub use world::{
    BodyContact, BroadPhase, CollisionWorld, GroupBody, GroupId, PlacedCovers, Precision, RayHit, StaticId,
    convex_distance, convex_overlap,
};

/// A vector with each coordinate uniform in `(-s, s)`, for the tests.
#[cfg(test)]
pub(crate) fn random_vector(rng: &mut rand_chacha::ChaCha8Rng, s: f64) -> DVec3 {
    use rand::RngExt;
    DVec3::new(
        rng.random_range(-s..s),
        rng.random_range(-s..s),
        rng.random_range(-s..s),
    )
}

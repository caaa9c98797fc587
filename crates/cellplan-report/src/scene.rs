//! The cell as something to draw: shared geometry, static objects placed in the world, and each
//! robot as a kinematic tree whose links carry geometry. The HTML viewer and the glTF export
//! both draw from a [`Scene`], so they show the same thing.
//!
//! Geometry is instanced: robots of one URDF model share their link meshes, robots with one
//! tool share its shapes. Meshes above a triangle budget are decimated for drawing
//! ([`Mesh::decimated`]); collision checking never sees these copies.
use cellplan_core::document::Plan;
use cellplan_geom::{Mesh, Pose, ShapeSpec};
use cellplan_kin::{Joint, RobotModel};
use cellplan_model::Cell;
use std::collections::HashMap;
use std::sync::Arc;

/// Default triangle budget of one drawn mesh.
pub const MESH_BUDGET: usize = 40_000;

/// One drawable mesh in its own frame (metres, f32 for the GPU).
#[derive(Clone, Debug)]
pub struct Geometry {
    /// Where it came from (a file name or a primitive), for names in exports.
    pub label: String,
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Counter-clockwise triangles.
    pub indices: Vec<u32>,
    /// Triangles before decimation.
    pub source_triangles: usize,
}

/// A geometry placed in a frame.
#[derive(Clone, Copy, Debug)]
pub struct Placed {
    /// Index into [`Scene::geometries`].
    pub geometry: usize,
    /// Pose in the parent frame.
    pub pose: Pose,
}

/// A static object.
#[derive(Clone, Debug)]
pub struct StaticItem {
    /// Name in the cell file.
    pub name: String,
    /// Its geometry in the world.
    pub placed: Placed,
    /// Colour (linear-ish RGB in 0..1).
    pub colour: [f32; 3],
}

/// A robot: its URDF model (the chain whose forward kinematics place the links) and the
/// geometry drawn on each chain link.
#[derive(Clone, Debug)]
pub struct SceneRobot {
    /// Name in the cell.
    pub name: String,
    /// Colour.
    pub colour: [f32; 3],
    /// Pose of the chain root in the world.
    pub base: Pose,
    /// The URDF model (shared with the cell's robot).
    pub model: Arc<RobotModel>,
    /// Geometry per chain link, in the link's frame (the tool hangs on the last link).
    pub parts: Vec<Vec<Placed>>,
    /// TCP in the tip link's frame.
    pub tcp: Pose,
}

impl SceneRobot {
    /// The joint that moves chain link `i` (its index into the joint values, and the joint).
    pub fn joint_of(&self, i: usize) -> Option<(usize, &Joint)> {
        let chain = &self.model.chain;
        let j = chain.links.get(i)?.joint?;
        chain.joints.get(j).map(|jt| (j, jt))
    }

    /// Pose of chain link `i` in its parent link's frame at joint values `q` (a missing value
    /// counts as zero, as in [`cellplan_kin::Chain::fk_all`]).
    pub fn local_pose(&self, i: usize, q: &[f64]) -> Pose {
        let origin = self.model.chain.links[i].origin;
        match self.joint_of(i) {
            Some((j, joint)) => joint.apply(origin, q.get(j).copied().unwrap_or(0.0)),
            None => origin,
        }
    }

    /// World pose of the TCP at `q`.
    pub fn tcp_pose(&self, q: &[f64]) -> Pose {
        self.base * self.model.chain.fk_tip(q) * self.tcp
    }
}

/// Everything drawn of a cell.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Distinct meshes.
    pub geometries: Vec<Geometry>,
    /// Static objects.
    pub statics: Vec<StaticItem>,
    /// Robots, in cell order.
    pub robots: Vec<SceneRobot>,
}

/// Robot colours as RGB (the same as [`super::svg::ROBOT_COLOURS`]).
pub fn robot_colour(r: usize) -> [f32; 3] {
    let hex = super::svg::ROBOT_COLOURS[r % super::svg::ROBOT_COLOURS.len()];
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or(128) as f32 / 255.0;
    [byte(1), byte(3), byte(5)]
}

/// Why a plan cannot be drawn in a cell's scene.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Mismatch {
    /// A robot of the plan the cell does not have.
    #[error("the plan's robot {robot} is not in the cell")]
    NoRobot {
        /// Its name.
        robot: String,
    },
    /// A robot with another joint count.
    #[error("robot {robot} has {cell} joints in the cell, the plan gives {plan}")]
    Joints {
        /// Its name.
        robot: String,
        /// Joints in the cell.
        cell: usize,
        /// Joints in the plan.
        plan: usize,
    },
}

impl Scene {
    /// The scene of `cell`, meshes decimated to `budget` triangles each.
    pub fn new(cell: &Cell, budget: usize) -> Scene {
        let mut lib = Library {
            budget,
            geometries: Vec::new(),
            by_mesh: HashMap::new(),
            by_primitive: HashMap::new(),
        };
        let lowest_base = cell
            .robots
            .iter()
            .map(|r| r.base.translation.z)
            .fold(f64::INFINITY, f64::min);
        let largest = cell
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| matches!(o.shape, ShapeSpec::Mesh(_)))
            .max_by_key(|(_, o)| match &o.shape {
                ShapeSpec::Mesh(m) => m.triangles.len(),
                _ => 0,
            })
            .map(|(k, _)| k);
        let statics = cell
            .objects
            .iter()
            .enumerate()
            .map(|(k, o)| {
                let ground = o
                    .shape
                    .to_mesh()
                    .transformed(&o.pose)
                    .aabb()
                    .is_some_and(|(_, hi)| hi.z <= lowest_base + 1e-6);
                let colour = if ground {
                    [0.80, 0.81, 0.83]
                } else if Some(k) == largest {
                    [0.74, 0.76, 0.80]
                } else {
                    [0.42, 0.45, 0.50]
                };
                StaticItem {
                    name: o.name.clone(),
                    placed: Placed {
                        geometry: lib.add(&o.shape, &o.name),
                        pose: o.pose,
                    },
                    colour,
                }
            })
            .collect();
        let robots = cell
            .robots
            .iter()
            .map(|r| {
                let chain = &r.model.chain;
                let tip = chain.links.len().saturating_sub(1);
                let parts = chain
                    .links
                    .iter()
                    .enumerate()
                    .map(|(i, l)| {
                        let mut parts: Vec<Placed> = r.model.collision[i]
                            .iter()
                            .map(|(s, pose)| Placed {
                                geometry: lib.add(s, &l.name),
                                pose: *pose,
                            })
                            .collect();
                        if i == tip {
                            parts.extend(r.tool.shapes.iter().map(|(s, pose)| Placed {
                                geometry: lib.add(s, &r.tool.name),
                                pose: *pose,
                            }));
                        }
                        parts
                    })
                    .collect();
                SceneRobot {
                    name: r.name.clone(),
                    colour: robot_colour(r.id.0),
                    base: r.base,
                    model: r.model.clone(),
                    parts,
                    tcp: r.tool.tcp,
                }
            })
            .collect();
        Scene {
            geometries: lib.geometries,
            statics,
            robots,
        }
    }

    /// The scene's robots matched to a plan's, in the plan's order: an error names the first
    /// robot that does not fit (missing from the cell, or a different number of joints).
    pub fn match_plan(&self, plan: &Plan) -> Result<Vec<usize>, Mismatch> {
        plan.robots
            .iter()
            .map(|rp| {
                let k = self
                    .robots
                    .iter()
                    .position(|r| r.name == rp.name)
                    .ok_or_else(|| Mismatch::NoRobot {
                        robot: rp.name.clone(),
                    })?;
                let dof = self.robots[k].model.chain.dof();
                if rp.joints.len() != dof || rp.trajectory.iter().any(|s| s.q.len() != dof) {
                    return Err(Mismatch::Joints {
                        robot: rp.name.clone(),
                        cell: dof,
                        plan: rp.joints.len(),
                    });
                }
                Ok(k)
            })
            .collect()
    }

    /// Triangles drawn in all, counting every instance.
    pub fn drawn_triangles(&self) -> usize {
        let tri = |p: &Placed| self.geometries[p.geometry].indices.len() / 3;
        self.statics.iter().map(|s| tri(&s.placed)).sum::<usize>()
            + self
                .robots
                .iter()
                .flat_map(|r| r.parts.iter().flatten())
                .map(tri)
                .sum::<usize>()
    }
}

/// Distinct geometries, deduplicated: meshes by identity (robots of one model share their
/// `Arc`s), primitives by their parameters.
struct Library {
    budget: usize,
    geometries: Vec<Geometry>,
    by_mesh: HashMap<*const Mesh, usize>,
    by_primitive: HashMap<String, usize>,
}

impl Library {
    fn add(&mut self, shape: &ShapeSpec, label: &str) -> usize {
        let key = match shape {
            ShapeSpec::Mesh(m) => {
                if let Some(&k) = self.by_mesh.get(&Arc::as_ptr(m)) {
                    return k;
                }
                None
            }
            other => {
                let key = format!("{other:?}");
                if let Some(&k) = self.by_primitive.get(&key) {
                    return k;
                }
                Some(key)
            }
        };
        let mesh = shape.to_mesh();
        let source_triangles = mesh.triangles.len();
        let mesh = mesh.decimated(self.budget);
        let k = self.geometries.len();
        self.geometries.push(Geometry {
            label: label.to_string(),
            positions: mesh
                .vertices
                .iter()
                .map(|v| [v.x as f32, v.y as f32, v.z as f32])
                .collect(),
            indices: mesh.triangles.iter().flatten().copied().collect(),
            source_triangles,
        });
        match (shape, key) {
            (ShapeSpec::Mesh(m), _) => {
                self.by_mesh.insert(Arc::as_ptr(m), k);
            }
            (_, Some(key)) => {
                self.by_primitive.insert(key, k);
            }
            _ => {}
        }
        k
    }
}

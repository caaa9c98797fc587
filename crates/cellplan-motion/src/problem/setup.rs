//! The robot of a problem file set up in a collision world ([`ArmSetup`]; see the parent
//! module's documentation for how the robot is built).
use super::{Obstacle, ProblemError, ProblemSet};
use crate::arm::{Arm, ArmValidity, pairs_that_may_touch};
use cellplan_geom::pieces::convex_pieces;
use cellplan_geom::{CollisionWorld, DVec3, GroupBody, GroupId, Mesh, Pose, ShapeSpec};
use cellplan_kin::{RobotModel, load_urdf, srdf};
use std::collections::BTreeSet;
use std::sync::Arc;

/// A convex piece (its points) as a mesh shape (its hull's triangles).
fn piece_mesh(points: Vec<DVec3>) -> Option<ShapeSpec> {
    let hull = parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&points)?;
    let (vertices, triangles) = hull.to_trimesh();
    Some(ShapeSpec::Mesh(Arc::new(Mesh { vertices, triangles })))
}
/// A robot of a problem file set up in a collision world (see the module documentation); the
/// obstacles are swapped per problem with [`ArmSetup::set_obstacles`].
pub struct ArmSetup {
    /// The URDF model.
    pub model: RobotModel,
    /// The world: the arm's group and the current obstacles.
    pub world: CollisionWorld,
    /// The arm's group.
    pub group: GroupId,
    /// The chain link each body hangs on.
    pub body_links: Vec<usize>,
    /// The URDF link each body's shape belongs to.
    pub body_sources: Vec<String>,
    /// The body pairs to keep apart: every pair on different links but those the SRDF
    /// disables (without an SRDF, but those on one chain link or on parent and child), and but
    /// the tool with the link it is mounted on (what an exact re-check checks).
    pub self_pairs: Vec<(usize, usize)>,
    /// The pairs of `self_pairs` that the validity check asks: those not proven apart in
    /// every configuration within the joint limits ([`crate::arm::pairs_that_may_touch`]).
    pub checked_pairs: Vec<(usize, usize)>,
    /// Where the root stands.
    pub base: Pose,
    /// The tables of the close self pairs ([`crate::arm::PairTables::build`]).
    pub pair_tables: crate::arm::PairTables,
    /// For each chain joint, its index in the file's joint list.
    order: Vec<usize>,
}

impl ArmSetup {
    /// Loads the robot of `set`: the URDF (whose movable joints must be exactly the file's
    /// `joints`), one body per collision shape, the tool's shapes on the tip link (refused when
    /// the tool has the name of a link of the URDF), the SRDF's rules.
    pub fn load(set: &ProblemSet) -> Result<ArmSetup, ProblemError> {
        let mut model = load_urdf(&set.robot.urdf, &set.robot.packages, None)?;
        // The tool's bodies hang on the tip link, under the tool's name; the link it is mounted
        // on (the nearest one from the tip towards the root that has shapes) always touches it.
        let mut mount = BTreeSet::new();
        if let Some(tool) = &set.robot.tool {
            if model.link_names.contains(&tool.name) {
                return Err(ProblemError::Invalid {
                    path: set.path.clone(),
                    message: format!("robot.tool is named \"{}\", as a link of the URDF", tool.name),
                    hint: "give the tool a name no link of the URDF has".into(),
                });
            }
            let tip = model.collision.len().saturating_sub(1);
            if let Some(l) = (0..=tip).rev().find(|&l| !model.collision[l].is_empty()) {
                mount.extend(model.collision_links[l].iter().cloned());
            }
            for (shape, pose) in &tool.shapes {
                model.collision[tip].push((shape.clone(), *pose));
                model.collision_links[tip].push(tool.name.clone());
            }
        }
        let tool_name = set.robot.tool.as_ref().map(|t| t.name.as_str());
        let chain = &model.chain;
        let order = chain
            .joints
            .iter()
            .map(|j| set.joints.iter().position(|n| *n == j.name))
            .collect::<Option<Vec<usize>>>()
            .filter(|o| o.len() == set.joints.len())
            .ok_or_else(|| ProblemError::Invalid {
                path: set.path.clone(),
                message: format!(
                    "`joints` lists {:?}, but the chain from {} to {} moves {:?}",
                    set.joints,
                    chain.root_name(),
                    chain.tip_name(),
                    chain.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>()
                ),
                hint: "list every movable joint of the chain, once".into(),
            })?;
        let mut bodies = Vec::new();
        let mut body_links = Vec::new();
        let mut body_sources = Vec::new();
        for (l, shapes) in model.collision.iter().enumerate() {
            for (k, (shape, pose)) in shapes.iter().enumerate() {
                let source = model.collision_links[l][k].clone();
                // A markedly concave mesh of a link a joint moves becomes its convex pieces,
                // each a body (see the module documentation for why only those).
                let jointed = model.chain.links[l].joint.is_some() && model.chain.links[l].name == source;
                let pieces: Vec<ShapeSpec> = match shape {
                    ShapeSpec::Mesh(m) if jointed => convex_pieces(m).map_or_else(Vec::new, |pieces| {
                        pieces.into_iter().filter_map(piece_mesh).collect()
                    }),
                    _ => Vec::new(),
                };
                let parts = if pieces.is_empty() {
                    vec![shape.clone()]
                } else {
                    pieces
                };
                for (p, part) in parts.into_iter().enumerate() {
                    bodies.push(GroupBody {
                        name: format!("{source}#{k}.{p}"),
                        shapes: vec![(part, *pose)],
                    });
                    body_links.push(l);
                    body_sources.push(source.clone());
                }
            }
        }
        let mut world = CollisionWorld::new();
        let group = world.add_group(&model.name, bodies);
        let disabled: BTreeSet<(String, String)> = match &set.robot.srdf {
            Some(p) => srdf::read_disabled_pairs(p)?
                .into_iter()
                .flat_map(|d| [(d.link1.clone(), d.link2.clone()), (d.link2, d.link1)])
                .collect(),
            None => BTreeSet::new(),
        };
        let n = body_links.len();
        let mut self_pairs = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let (si, sj) = (&body_sources[i], &body_sources[j]);
                if si == sj || disabled.contains(&(si.clone(), sj.clone())) {
                    continue;
                }
                if tool_name.is_some_and(|t| si == t || sj == t) {
                    // The tool: never with the link it is mounted on (no link has the tool's
                    // name), with every other link, SRDF or not.
                    if mount.contains(si) || mount.contains(sj) {
                        continue;
                    }
                } else if set.robot.srdf.is_none() {
                    // No rules: links that never move relative to each other, and parent and
                    // child, are left out.
                    let (a, b) = (body_links[i].min(body_links[j]), body_links[i].max(body_links[j]));
                    if b - a <= 1 {
                        continue;
                    }
                }
                self_pairs.push((i, j));
            }
        }
        let mut setup = ArmSetup {
            base: set.robot.base,
            pair_tables: crate::arm::PairTables::default(),
            model,
            world,
            group,
            body_links,
            body_sources,
            checked_pairs: self_pairs.clone(),
            self_pairs,
            order,
        };
        setup.checked_pairs = pairs_that_may_touch(&setup.arm());
        setup.pair_tables = crate::arm::PairTables::build(&setup.arm());
        Ok(setup)
    }

    /// Replaces the obstacles of the world.
    pub fn set_obstacles(&mut self, obstacles: &[Obstacle]) {
        self.world.clear_statics();
        for o in obstacles {
            self.world.add_static(&o.name, &o.shape, o.pose);
        }
    }

    /// A configuration in the file's joint order, in the chain's order.
    pub fn to_chain(&self, q: &[f64]) -> Vec<f64> {
        self.order
            .iter()
            .map(|&k| q.get(k).copied().unwrap_or(f64::NAN))
            .collect()
    }

    /// A configuration in the chain's order, in the file's joint order.
    pub fn to_file(&self, q: &[f64]) -> Vec<f64> {
        let mut out = vec![f64::NAN; self.order.len()];
        for (c, &k) in self.order.iter().enumerate() {
            if let (Some(slot), Some(&v)) = (out.get_mut(k), q.get(c)) {
                *slot = v;
            }
        }
        out
    }

    /// The arm as the motion core sees it.
    pub fn arm(&self) -> Arm<'_> {
        Arm {
            world: &self.world,
            chain: &self.model.chain,
            base: self.base,
            group: self.group,
            body_links: &self.body_links,
            self_pairs: &self.checked_pairs,
            pair_tables: Some(&self.pair_tables),
        }
    }

    /// The self pairs to keep apart (`self_pairs`) by URDF link names (each once).
    pub fn link_pairs(&self) -> Vec<(String, String)> {
        let mut out: Vec<(String, String)> = self
            .self_pairs
            .iter()
            .map(|&(i, j)| (self.body_sources[i].clone(), self.body_sources[j].clone()))
            .collect();
        out.sort();
        out.dedup();
        out
    }

    /// The validity checker keeping `margin` from the obstacles.
    pub fn validity(&self, margin: f64) -> ArmValidity<'_> {
        ArmValidity::new(self.arm(), margin, Vec::new())
    }
}

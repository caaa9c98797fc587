//! A robot placed in the cell: its URDF chain, base, tool, IK and collision bodies.
use cellplan_geom::{BodyContact, CollisionWorld, GroupId, Pose, ShapeSpec};
use cellplan_kin::{IkSolver, RobotModel};
use serde::Serialize;
use std::sync::Arc;

/// Index of a robot in [`crate::Cell::robots`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct RobotId(pub usize);

/// The end effector a robot carries.
#[derive(Clone, Debug)]
pub struct Tool {
    /// Name in `[tools]`.
    pub name: String,
    /// Tool centre point in the tip-link frame.
    pub tcp: Pose,
    /// Shapes in the tip-link frame.
    pub shapes: Vec<(ShapeSpec, Pose)>,
}

/// Which inverse kinematics a robot uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum IkKind {
    /// Closed form for ortho-parallel arms, all branches.
    Opw,
    /// The same, its parameters read off the URDF (no `opw` given).
    OpwDerived,
    /// Closed form for arms with three parallel axes and an offset wrist (Universal Robots),
    /// read off the URDF, all branches.
    Parallel,
    /// An OPW arm on a linear track: track positions sampled around each target, the arm's
    /// closed form (read off the URDF) at each.
    Track,
    /// Damped least squares from several starts.
    Numeric,
}

/// What a collision body of a robot is attached to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyFrame {
    /// A chain link (index into `chain.links`).
    Link(usize),
    /// The tool (on the tip link).
    Tool,
}

/// A robot placed in the cell.
#[derive(Clone)]
pub struct Robot {
    /// Index in the cell.
    pub id: RobotId,
    /// Unique name.
    pub name: String,
    /// The URDF model (shared between robots of the same model).
    pub model: Arc<RobotModel>,
    /// Pose of the URDF root link in the world.
    pub base: Pose,
    /// Home configuration (where every tour starts and ends).
    pub home: Vec<f64>,
    /// The tool.
    pub tool: Tool,
    /// Inverse kinematics of the chain.
    pub ik: Arc<dyn IkSolver>,
    /// Which IK that is.
    pub ik_kind: IkKind,
    /// Joint velocity limits (rad/s or m/s).
    pub max_velocity: Vec<f64>,
    /// Joint acceleration limits (rad/s² or m/s²).
    pub max_acceleration: Vec<f64>,
    /// The robot's body group in the cell's collision world.
    pub group: GroupId,
    /// What each body of the group is attached to. A link or the tool may carry several bodies:
    /// one per collision shape (each its own convex body, never merged with the others).
    pub bodies: Vec<BodyFrame>,
    /// For each body, the chain link it hangs on (the tip link for the tool's bodies).
    pub body_links: Vec<usize>,
    /// For each body, its shape and pose in the frame of what it is attached to.
    pub body_shapes: Vec<(ShapeSpec, Pose)>,
    /// Body pairs checked for self-collision (the rest are adjacent, never or always in contact).
    pub self_pairs: Vec<(usize, usize)>,
    /// The tables of the close self pairs ([`cellplan_motion::arm::PairTables::build`]), shared
    /// by the robots of one geometry.
    pub pair_tables: Arc<cellplan_motion::arm::PairTables>,
    /// Upper bound on the distance from the base origin to the TCP (m): the sum of the
    /// chain's link offsets and the TCP offset.
    pub reach: f64,
}

impl std::fmt::Debug for Robot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Robot")
            .field("name", &self.name)
            .field("model", &self.model.name)
            .field("ik", &self.ik_kind)
            .finish_non_exhaustive()
    }
}

/// Reusable buffers for the hot path (one per thread).
#[derive(Default, Clone)]
pub struct Scratch {
    links: Vec<Pose>,
    /// Body poses in the world, after [`Robot::body_poses`].
    pub bodies: Vec<Pose>,
}

impl Robot {
    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.model.chain.dof()
    }

    /// TCP pose in the world at `q`.
    pub fn tcp_pose(&self, q: &[f64]) -> Pose {
        self.base * self.model.chain.fk_tip(q) * self.tool.tcp
    }

    /// The tip pose in the chain root frame that puts the TCP at `tcp` (world).
    pub fn tip_target(&self, tcp: &Pose) -> Pose {
        self.base.inverse() * *tcp * self.tool.tcp.inverse()
    }

    /// Appends every configuration within limits that puts the TCP at `tcp` (world); returns
    /// the number of solutions before joint-limit filtering.
    pub fn ik(&self, tcp: &Pose, out: &mut Vec<Vec<f64>>) -> usize {
        self.ik.solve(&self.tip_target(tcp), out)
    }

    /// World poses of the robot's collision bodies at `q` into `scratch.bodies`.
    pub fn body_poses(&self, q: &[f64], scratch: &mut Scratch) {
        self.link_poses(q, scratch);
        self.bodies_from_links(scratch);
    }

    /// The chain's link poses at `q` (in the chain's root frame) into `scratch.links`.
    pub fn link_poses(&self, q: &[f64], scratch: &mut Scratch) {
        let chain = &self.model.chain;
        scratch.links.resize(chain.links.len(), Pose::IDENTITY);
        chain.fk_all(q, &mut scratch.links);
    }

    /// The TCP's world pose from the link poses in `scratch.links` ([`Robot::link_poses`]):
    /// [`Robot::tcp_pose`] at the same `q`, bit for bit, without its forward kinematics.
    pub fn tcp_from_links(&self, scratch: &Scratch) -> Pose {
        let tip = scratch.links.last().copied().unwrap_or(Pose::IDENTITY);
        self.base * tip * self.tool.tcp
    }

    /// `scratch.bodies` from the link poses in `scratch.links` ([`Robot::link_poses`]): what
    /// [`Robot::body_poses`] gives at the same `q`.
    pub fn bodies_from_links(&self, scratch: &mut Scratch) {
        let chain = &self.model.chain;
        let tip = chain.links.len() - 1;
        scratch.bodies.clear();
        for b in &self.bodies {
            let local = match *b {
                BodyFrame::Link(i) => scratch.links[i],
                BodyFrame::Tool => scratch.links[tip],
            };
            scratch.bodies.push(self.base * local);
        }
    }

    /// First contact of the robot at `q` with the static scene (closer than `clearance`) or
    /// with itself. Call after [`Robot::body_poses`] for the same `q`.
    pub fn contact_at(
        &self,
        world: &CollisionWorld,
        scratch: &Scratch,
        clearance: f64,
    ) -> Option<BodyContact> {
        world
            .group_vs_static(self.group, &scratch.bodies, clearance)
            .or_else(|| world.group_self(self.group, &scratch.bodies, 0.0))
    }

    /// Whether every joint is within its limits.
    pub fn within_limits(&self, q: &[f64]) -> bool {
        q.len() == self.dof() && self.model.chain.within_limits(q, 1e-9)
    }

    /// The robot as the motion core sees it: chain, base, body group and self pairs in `world`
    /// (the cell's collision world).
    pub fn arm<'a>(&'a self, world: &'a CollisionWorld) -> cellplan_motion::arm::Arm<'a> {
        cellplan_motion::arm::Arm {
            world,
            chain: &self.model.chain,
            base: self.base,
            group: self.group,
            body_links: &self.body_links,
            self_pairs: &self.self_pairs,
            pair_tables: Some(&self.pair_tables),
        }
    }

    /// Joint names.
    pub fn joint_names(&self) -> Vec<&str> {
        self.model.chain.joints.iter().map(|j| j.name.as_str()).collect()
    }
}

//! Collision-free motion of one robot of a cell: the adapter between the cell model and the
//! generic planners of [`cellplan_motion::plan`].
//!
//! - [`joint_space`]: the robot's joint limits, metric weights `1/v_max` (a time-like
//!   metric) and per-joint Cartesian radii (see [`joint_radii`] for why they bound motion).
//! - [`RobotValidity`]: the clearance of a configuration — joint limits, distance of the
//!   moving bodies to the static scene (the robot's base bodies are exempt, as the loader sets
//!   them) minus the margin, and the distance of the robot's checked self pairs — split by the
//!   joints that can reduce each part.
//! - [`plan_leg`]: one leg, straight if clear, else RRT-Connect with shortcutting.
//!
//! Other robots are not obstacles here: coordinating robots is a later stage.
use cellplan_kin::JointKind;
use cellplan_model::Cell;
use cellplan_model::robot::{BodyFrame, Robot, Scratch};
use cellplan_motion::plan::{
    self, Clearance, JointSpace, PlanError, PlanSettings, PlannedPath, StateValidity, narrow_step,
};
use std::cell::RefCell;
use std::ops::Range;

pub use cellplan_motion::plan::{Planner, RrtConnect, Straight};

/// Clearances are capped at this (m) by default: larger values only lengthen the steps of a
/// segment check a little, and the cap lets the distance queries skip everything further.
pub const DEFAULT_CLEARANCE_CAP: f64 = 0.25;

/// Taken off every measured distance (m), for the tolerance of the GJK distance.
const DISTANCE_SLACK: f64 = 1e-6;

/// Vertex norms of a body's hull are multiplied by this: spheres and cylinders that are
/// bodies by themselves are drawn by [`cellplan_geom::CollisionWorld::body_hull`] with vertices
/// on their surface (12 × 24 and 32 sides), whose farthest vertex falls short of the farthest
/// surface point by less than 2 %.
const HULL_NORM_FACTOR: f64 = 1.05;

/// The robot's joint space: limits, radii from [`joint_radii`], weights `1/v_max`.
pub fn joint_space(cell: &Cell, robot: &Robot) -> JointSpace {
    let chain = &robot.model.chain;
    let lower = chain.joints.iter().map(|j| j.lower).collect();
    let upper = chain.joints.iter().map(|j| j.upper).collect();
    let weights = (0..chain.dof())
        .map(|j| match robot.max_velocity.get(j) {
            Some(&v) if v.is_finite() && v > 0.0 => 1.0 / v,
            _ => 1.0,
        })
        .collect();
    JointSpace::new(lower, upper, joint_radii(cell, robot)).with_weights(weights)
}

/// For each joint, an upper bound (m) on the distance from its axis of any point of any
/// collision body it moves, valid in every configuration (1 for a prismatic joint).
///
/// Why it bounds motion: joint `j`'s axis passes through the origin `o_j` of the link it
/// moves. A point `p` of a body attached to link `k` (or the tool, on the tip) downstream of
/// `j` is `p = o_j + Σ_m R_m·t_m + Σ_prismatic R·axis·q + R_k·p_local`, where `t_m` are the
/// fixed origin offsets of links after `j` up to `k` and `R` rotations, so by the triangle
/// inequality `|p − o_j| ≤ Σ_m |t_m| + Σ_prismatic max(|lower|, |upper|) + |p_local|`, and
/// `|p_local|` is at most the largest vertex norm of the body's convex hull (its vertices span
/// it; see `HULL_NORM_FACTOR` for tessellated primitives). Along a straight joint-space
/// segment the velocity of `p` is `Σ_j q̇_j·(axis_j × (p − o_j))` (revolute) plus
/// `q̇_j·axis_j` (prismatic), of norm at most `Σ_j r_j·|q̇_j|`; integrating over the segment,
/// `p` moves at most `Σ_j r_j·|b_j − a_j|`. The robot's base is fixed in the world, so the
/// bound holds in world coordinates. A joint that moves no body gets 0.
pub fn joint_radii(cell: &Cell, robot: &Robot) -> Vec<f64> {
    let chain = &robot.model.chain;
    let tip = chain.links.len().saturating_sub(1);
    // Largest |p_local| of each body, and the link it hangs on.
    let bodies: Vec<(usize, f64)> = robot
        .bodies
        .iter()
        .enumerate()
        .filter_map(|(i, frame)| {
            let link = match *frame {
                BodyFrame::Link(l) => l,
                BodyFrame::Tool => tip,
            };
            let hull = cell.world.body_hull(robot.group, i)?;
            let norm = hull.vertices.iter().map(|v| v.length()).fold(0.0, f64::max);
            Some((link, norm * HULL_NORM_FACTOR))
        })
        .collect();
    // Reach of each link's origin offset (and of a prismatic joint's travel) from its parent.
    let offset: Vec<f64> = chain
        .links
        .iter()
        .map(|l| {
            let travel = l.joint.and_then(|j| chain.joints.get(j)).map_or(0.0, |j| {
                if j.kind == JointKind::Prismatic {
                    j.lower.abs().max(j.upper.abs())
                } else {
                    0.0
                }
            });
            l.origin.translation.length() + travel
        })
        .collect();
    (0..chain.dof())
        .map(|j| {
            if chain.joints[j].kind == JointKind::Prismatic {
                return 1.0;
            }
            let Some(lj) = chain.joint_link(j) else {
                return 0.0;
            };
            bodies
                .iter()
                .filter(|&&(k, _)| k >= lj)
                .map(|&(k, norm)| offset[lj + 1..=k].iter().sum::<f64>() + norm)
                .fold(0.0, f64::max)
        })
        .collect()
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
    static CLEARANCES: RefCell<Vec<Clearance>> = const { RefCell::new(Vec::new()) };
}

/// The clearance of one robot's configurations in its cell (see the module documentation).
///
/// [`StateValidity::clearances`] splits it by the joints that can reduce each part: the
/// distance of a body on link `k` to the scene (minus the margin) by joints `0..=k`, the
/// distance of a self pair by the joints between its two links (a body moves relative to
/// another body of the chain only by those). Every distance is capped at [`Self::cap`].
#[derive(Clone)]
pub struct RobotValidity<'a> {
    /// The cell (its collision world).
    pub cell: &'a Cell,
    /// The robot.
    pub robot: &'a Robot,
    /// Required distance (m) from the static scene.
    pub margin: f64,
    /// Clearances are capped at this (m).
    pub cap: f64,
    /// Bodies checked against the scene (those moved by some joint), with their joints.
    moving: Vec<(usize, Range<usize>)>,
    /// Checked self pairs with the joints between them.
    pairs: Vec<(usize, usize, Range<usize>)>,
    /// The other robots parked at home (obstacles like the scene: see
    /// [`crate::candidates::parked_others`]).
    parked: Vec<(cellplan_geom::GroupId, Vec<cellplan_geom::Pose>)>,
}

impl<'a> RobotValidity<'a> {
    /// With the default cap [`DEFAULT_CLEARANCE_CAP`].
    pub fn new(cell: &'a Cell, robot: &'a Robot, margin: f64) -> Self {
        let chain = &robot.model.chain;
        let tip = chain.links.len().saturating_sub(1);
        // Joints up to and including link k: 0..joints_to[k] (joints are numbered root to tip).
        let joints_to: Vec<usize> = chain
            .links
            .iter()
            .scan(0, |n, l| {
                if let Some(j) = l.joint {
                    *n = (*n).max(j + 1);
                }
                Some(*n)
            })
            .collect();
        let link_of = |i: usize| match robot.bodies.get(i) {
            Some(BodyFrame::Link(l)) => *l,
            _ => tip,
        };
        // Bodies before the first joint never move; the loader exempts them from the scene.
        let moving = (0..robot.bodies.len())
            .map(|i| (i, 0..joints_to[link_of(i)]))
            .filter(|(_, r)| !r.is_empty())
            .collect();
        let pairs = robot
            .self_pairs
            .iter()
            .map(|&(i, j)| {
                let (a, b) = (joints_to[link_of(i)], joints_to[link_of(j)]);
                (i, j, a.min(b)..a.max(b))
            })
            .collect();
        RobotValidity {
            cell,
            robot,
            margin,
            cap: DEFAULT_CLEARANCE_CAP,
            moving,
            pairs,
            parked: crate::candidates::parked_others(cell, robot),
        }
    }

    /// Distance of body `i` (posed in `bodies`) to the scene and the parked robots, capped.
    fn body_scene_distance(&self, i: usize, bodies: &[cellplan_geom::Pose], cap: f64) -> f64 {
        let world = &self.cell.world;
        let g = self.robot.group;
        let mut d = world.body_static_distance(g, i, bodies, cap);
        for (other, poses) in &self.parked {
            if d <= 0.0 {
                break;
            }
            d = world.body_group_distance(g, i, bodies, *other, poses, d);
        }
        d
    }
}

impl StateValidity for RobotValidity<'_> {
    fn clearance(&self, q: &[f64]) -> f64 {
        CLEARANCES.with_borrow_mut(|out| {
            self.clearances(q, out);
            out.iter().map(|c| c.distance).fold(f64::INFINITY, f64::min)
        })
    }

    fn clearances(&self, q: &[f64], out: &mut Vec<Clearance>) {
        out.clear();
        if !self.robot.within_limits(q) {
            out.push(Clearance {
                distance: f64::NEG_INFINITY,
                joints: 0..usize::MAX,
            });
            return;
        }
        SCRATCH.with_borrow_mut(|scratch| {
            self.robot.body_poses(q, scratch);
            let world = &self.cell.world;
            let g = self.robot.group;
            let margin = self.margin.max(0.0);
            for (i, joints) in &self.moving {
                let d = self.body_scene_distance(*i, &scratch.bodies, self.cap + margin);
                out.push(Clearance {
                    distance: d - margin - DISTANCE_SLACK,
                    joints: joints.clone(),
                });
            }
            for (i, j, joints) in &self.pairs {
                let d = world.pair_distance(g, *i, *j, &scratch.bodies, self.cap);
                out.push(Clearance {
                    distance: d - DISTANCE_SLACK,
                    joints: joints.clone(),
                });
            }
        });
    }

    /// As the default, with every distance query capped where it stops mattering (see
    /// `capped_part`): bodies from the tool inwards (the tool is the usual tightest part, and
    /// its step then caps the others' queries), then the self pairs.
    fn segment_step(
        &self,
        q: &[f64],
        bound: &dyn Fn(&Range<usize>) -> f64,
        floor: f64,
        limit: f64,
    ) -> Option<f64> {
        if !self.robot.within_limits(q) {
            return None;
        }
        SCRATCH.with_borrow_mut(|scratch| {
            self.robot.body_poses(q, scratch);
            let world = &self.cell.world;
            let g = self.robot.group;
            let margin = self.margin.max(0.0);
            let mut step = limit;
            for (i, joints) in self.moving.iter().rev() {
                let b = bound(joints);
                let query = |cap: f64| self.body_scene_distance(*i, &scratch.bodies, cap);
                step = narrow_step(step, self.capped_part(query, margin, b, step, floor), b, floor)?;
            }
            for (i, j, joints) in &self.pairs {
                let b = bound(joints);
                let query = |cap: f64| world.pair_distance(g, *i, *j, &scratch.bodies, cap);
                step = narrow_step(step, self.capped_part(query, 0.0, b, step, floor), b, floor)?;
            }
            Some(step)
        })
    }
}

impl RobotValidity<'_> {
    /// The clearance of `q` from the static scene (minus the margin) and the smallest distance
    /// between its checked self pairs, each capped at [`Self::cap`] (the parts of
    /// [`StateValidity::clearances`], split); both negative infinity outside the joint limits.
    pub fn scene_and_self_clearance(&self, q: &[f64]) -> (f64, f64) {
        if !self.robot.within_limits(q) {
            return (f64::NEG_INFINITY, f64::NEG_INFINITY);
        }
        CLEARANCES.with_borrow_mut(|out| {
            self.clearances(q, out);
            // `clearances` lists the moving bodies first, then the pairs.
            let (scene, pairs) = out.split_at(self.moving.len());
            let min = |parts: &[Clearance]| parts.iter().map(|c| c.distance).fold(self.cap, f64::min);
            (min(scene), min(pairs))
        })
    }

    /// The distance query of one part, capped just where the answer stops mattering: the step
    /// found so far times the part's bound (or the floor when the part cannot move), and at
    /// most [`Self::cap`]. Returns the part's clearance (capped likewise).
    fn capped_part(
        &self,
        query: impl FnOnce(f64) -> f64,
        offset: f64,
        bound: f64,
        step: f64,
        floor: f64,
    ) -> f64 {
        let wanted = if bound > 0.0 {
            (step * bound).min(self.cap).max(floor)
        } else {
            floor
        };
        let cap = wanted + offset + DISTANCE_SLACK;
        let d = query(cap);
        // At the cap, the answer is `wanted` itself (subtracting back could round below it).
        if d >= cap {
            wanted
        } else {
            d - offset - DISTANCE_SLACK
        }
    }
}

/// One leg of `robot` from `from` to `to`, keeping the process clearance from the static
/// scene (see [`plan_leg_with_margin`]).
pub fn plan_leg(
    cell: &Cell,
    robot: &Robot,
    from: &[f64],
    to: &[f64],
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    plan_leg_with_margin(cell, robot, from, to, cell.planning.clearance, settings)
}

/// One leg keeping `margin` (m) from the static scene: the straight joint segment if it is
/// clear, else RRT-Connect, shortcut (see [`cellplan_motion::plan::plan_leg`]).
pub fn plan_leg_with_margin(
    cell: &Cell,
    robot: &Robot,
    from: &[f64],
    to: &[f64],
    margin: f64,
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    let space = joint_space(cell, robot);
    let validity = RobotValidity::new(cell, robot, margin);
    plan::plan_leg(&space, &validity, from, to, settings)
}

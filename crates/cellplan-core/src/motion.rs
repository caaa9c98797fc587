//! Collision-free motion of one robot of a cell: the adapter between the cell model and the
//! generic planners of [`cellplan_motion::plan`].
//!
//! - [`joint_space`]: the robot's joint limits, metric weights `1/v_max` (a time-like
//!   metric) and per-joint Cartesian radii (see [`joint_radii`] for why they bound motion).
//! - [`robot_validity`]: the clearance of a configuration ([`cellplan_motion::arm::ArmValidity`]
//!   for the robot's arm) — joint limits, distance of the moving bodies to the static scene and
//!   to the other robots parked at home, minus the margin, and the distance of the robot's
//!   checked self pairs — split by the joints that can reduce each part.
//! - [`plan_leg`]: one leg, straight if clear, else RRT-Connect with shortcutting.
//!
//! Robots moving at the same time are not obstacles here: coordinating them is a later stage.
use cellplan_model::Cell;
use cellplan_model::robot::Robot;
use cellplan_motion::arm::{self, ArmValidity};
use cellplan_motion::plan::{self, JointSpace, PlanError, PlanSettings, PlannedPath};

pub use cellplan_motion::arm::DEFAULT_CLEARANCE_CAP;
pub use cellplan_motion::plan::{Planner, RrtConnect, Straight};

/// The clearance of one robot's configurations in its cell: [`ArmValidity`] for the robot's
/// arm, with the other robots parked at home as obstacles (see
/// [`crate::candidates::parked_others`]).
pub type RobotValidity<'a> = ArmValidity<'a>;

/// The robot's joint space: limits, radii from [`joint_radii`], weights `1/v_max`.
pub fn joint_space(cell: &Cell, robot: &Robot) -> JointSpace {
    arm::joint_space(&robot.arm(&cell.world), &robot.max_velocity)
}

/// For each joint, an upper bound (m) on the distance from its axis of any point of any
/// collision body it moves (see [`cellplan_motion::arm::joint_radii`]).
pub fn joint_radii(cell: &Cell, robot: &Robot) -> Vec<f64> {
    arm::joint_radii(&robot.arm(&cell.world))
}

/// The validity checker of `robot` in its cell keeping `margin` (m) from the static scene and
/// `margin` + [`crate::coord::REPLAY_SLACK`] from the other robots parked at home — what the
/// coordination keeps between robots, so that a robot standing at home is never in the way of
/// a path planned past it.
pub fn robot_validity<'a>(cell: &'a Cell, robot: &'a Robot, margin: f64) -> RobotValidity<'a> {
    ArmValidity::new(
        robot.arm(&cell.world),
        margin,
        crate::candidates::parked_others(cell, robot),
    )
    .with_parked_extra(crate::coord::REPLAY_SLACK)
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

/// How far (m) a leg the sampler cannot solve backs the tool out along its axis at either end
/// before sampling again, tried in turn.
pub const RETRACT_DISTANCES: [f64; 2] = [0.1, 0.25];

/// The step (m) of the tool along its axis in a retract.
const RETRACT_STEP: f64 = 0.01;

/// One leg keeping `margin` (m) from the static scene: the straight joint segment if it is
/// clear, else RRT-Connect, shortcut (see [`cellplan_motion::plan::plan_leg`]). When the
/// sampler finds no path, the tool backs out along its axis at both ends (a probe at its
/// stand-off from a surface, deep in an opening, leaves it the way it came) by each of
/// [`RETRACT_DISTANCES`] in turn, and the sampler plans between the two retracted poses
/// ([`cellplan_motion::plan::plan_leg_via`]); the first that succeeds is the leg.
pub fn plan_leg_with_margin(
    cell: &Cell,
    robot: &Robot,
    from: &[f64],
    to: &[f64],
    margin: f64,
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    let space = joint_space(cell, robot);
    let validity = robot_validity(cell, robot, margin);
    let (mut samples, mut calls) = match plan::plan_leg(&space, &validity, from, to, settings) {
        Ok(path) => return Ok(path),
        Err(PlanError::NoPath {
            samples,
            validity_calls,
        }) => (samples, validity_calls),
        Err(e) => return Err(e),
    };
    let chain = &robot.model.chain;
    for distance in RETRACT_DISTANCES {
        let (Some(exit), Some(mut entry)) = (
            arm::tool_retract(chain, &robot.tool.tcp, from, distance, RETRACT_STEP),
            arm::tool_retract(chain, &robot.tool.tcp, to, distance, RETRACT_STEP),
        ) else {
            continue;
        };
        entry.reverse();
        match plan::plan_leg_via(&space, &validity, &exit, &entry, settings) {
            Ok(mut path) => {
                path.samples += samples;
                path.validity_calls += calls;
                return Ok(path);
            }
            Err(PlanError::NoPath {
                samples: s,
                validity_calls: c,
            }) => {
                samples += s;
                calls += c;
            }
            Err(_) => {}
        }
    }
    Err(PlanError::NoPath {
        samples,
        validity_calls: calls,
    })
}

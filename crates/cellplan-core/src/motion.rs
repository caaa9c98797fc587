//! Collision-free motion of one robot of a cell: the adapter between the cell model and the
//! generic planners of [`cellplan_motion::plan`].
//!
//! - [`joint_space`]: the robot's joint limits, metric weights `1/v_max` (a time-like
//!   metric) and per-joint Cartesian radii (see [`joint_radii`] for why they bound motion).
//! - [`robot_validity`]: the clearance of a configuration ([`cellplan_motion::arm::ArmValidity`]
//!   for the robot's arm) — joint limits, distance of the moving bodies to the static scene and
//!   to the other robots parked at home, minus the margin, and the distance of the robot's
//!   checked self pairs — split by the joints that can reduce each part.
//! - [`plan_leg`]: one leg, straight if clear, else RRT-Connect with shortcutting;
//!   [`plan_leg_with_margin`] adds the robot's shared roadmap ([`robot_roadmap`]) and the
//!   retract along the tool axis.
//!
//! Robots moving at the same time are not obstacles here: coordinating them is a later stage.
use cellplan_model::Cell;
use cellplan_model::robot::Robot;
use cellplan_motion::arm::{self, ArmValidity};
use cellplan_motion::plan::{
    self, JointSpace, PlanError, PlanSettings, PlannedPath, SharedRoadmap, SharedRoadmapSettings,
};

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

/// Distance (m) a leg keeps from the robots parked at home beyond what the coordination asks
/// between robots (the clearance and [`crate::coord::REPLAY_SLACK`]). The coordination's
/// timeline steps through time conservatively and counts a pass as a contact when its step
/// falls below 0.1 ms; a leg grazing a parked robot at exactly the coordination's distance
/// would be such a pass — a conflict no schedule can remove, since the parked robot stands
/// there from the start. Robot points move less than 1 mm in 0.1 ms at up to 10 m/s.
pub const HOME_STEP_SLACK: f64 = 0.002;

/// The validity checker of `robot` in its cell keeping `margin` (m) from the static scene and
/// `margin` + [`crate::coord::REPLAY_SLACK`] + [`HOME_STEP_SLACK`] from the other robots parked
/// at home — more than the coordination keeps between robots, so that a robot standing at
/// home is never in the way of a path planned past it.
pub fn robot_validity<'a>(cell: &'a Cell, robot: &'a Robot, margin: f64) -> RobotValidity<'a> {
    ArmValidity::new(
        robot.arm(&cell.world),
        margin,
        crate::candidates::parked_others(cell, robot),
    )
    .with_parked_extra(crate::coord::REPLAY_SLACK + HOME_STEP_SLACK)
}

/// One leg of `robot` from `from` to `to`, keeping the process clearance from the static
/// scene (see [`plan_leg_with_margin`]; no roadmap).
pub fn plan_leg(
    cell: &Cell,
    robot: &Robot,
    from: &[f64],
    to: &[f64],
    settings: &PlanSettings,
) -> Result<PlannedPath, PlanError> {
    plan_leg_with_margin(cell, robot, from, to, cell.planning.clearance, settings, None)
}

/// How far (m) a leg the sampler cannot solve backs the tool out along its axis at either end
/// before sampling again, tried in turn.
pub const RETRACT_DISTANCES: [f64; 2] = [0.1, 0.25];

/// The step (m) of the tool along its axis in a retract.
const RETRACT_STEP: f64 = 0.01;

/// The robot's roadmap in its cell (the other robots parked at home), for [`plan_leg_with_margin`]:
/// its nodes are `seeds` (the robot's task candidates and home: where its legs start and end)
/// and samples seeded by `seed` (half uniform, half near the seeds), checked with the process
/// clearance.
pub fn robot_roadmap(cell: &Cell, robot: &Robot, seeds: &[Vec<f64>], seed: u64) -> SharedRoadmap {
    let space = joint_space(cell, robot);
    let validity = robot_validity(cell, robot, cell.planning.clearance);
    let settings = SharedRoadmapSettings {
        seed,
        min_clearance: PlanSettings::default().min_clearance,
        ..SharedRoadmapSettings::default()
    };
    SharedRoadmap::build(&space, &validity, seeds, &settings).0
}

/// One leg keeping `margin` (m) from the static scene: the straight joint segment if it is
/// clear, else RRT-Connect, shortcut (see [`cellplan_motion::plan::plan_leg`]). When the
/// sampler finds no path, the tool backs out along its axis at both ends (a probe at its
/// stand-off from a surface, deep in an opening, leaves it the way it came) by each of
/// [`RETRACT_DISTANCES`] in turn, and the sampler plans between the two retracted poses
/// ([`cellplan_motion::plan::plan_leg_via_with`]). When none of those succeeds and a
/// `roadmap` of the robot is given (built by [`robot_roadmap`] with the same margin), the
/// same variants are tried through its shortest valid paths. The first that succeeds is the
/// leg. The roadmap is asked for lazily (built on first need).
pub fn plan_leg_with_margin<'r>(
    cell: &Cell,
    robot: &Robot,
    from: &[f64],
    to: &[f64],
    margin: f64,
    settings: &PlanSettings,
    roadmap: Option<&dyn Fn() -> &'r SharedRoadmap>,
) -> Result<PlannedPath, PlanError> {
    let space = joint_space(cell, robot);
    let validity = robot_validity(cell, robot, margin);
    let chain = &robot.model.chain;
    // The retracted variants (exit and entry polylines), made only once the direct leg has
    // failed: most legs never need them.
    type Polyline = Vec<Vec<f64>>;
    let retracts = std::cell::OnceCell::<Vec<(Polyline, Polyline)>>::new();
    let retracted = || {
        retracts.get_or_init(|| {
            RETRACT_DISTANCES
                .iter()
                .filter_map(|&distance| {
                    let exit = arm::tool_retract(chain, &robot.tool.tcp, from, distance, RETRACT_STEP)?;
                    let mut entry = arm::tool_retract(chain, &robot.tool.tcp, to, distance, RETRACT_STEP)?;
                    entry.reverse();
                    Some((exit, entry))
                })
                .collect()
        })
    };
    let sampler = |a: &[f64], b: &[f64]| plan::plan_leg(&space, &validity, a, b, settings);
    let through_roadmap = |a: &[f64], b: &[f64]| match roadmap {
        Some(r) => plan::roadmap_leg(&space, &validity, r(), a, b, settings),
        None => Err(PlanError::NoPath {
            samples: 0,
            validity_calls: 0,
        }),
    };
    let (mut samples, mut calls) = (0, 0);
    // Every variant with the sampler first (the legs it solves keep its paths), then every
    // variant through the roadmap: the direct leg, then each retract.
    let passes: [&plan::LegPlanner; 2] = [&sampler, &through_roadmap];
    for middle in passes.into_iter().take(if roadmap.is_some() { 2 } else { 1 }) {
        let direct = std::iter::once_with(|| middle(from, to));
        // Lazy: the retracts are made only when the direct leg has failed.
        let via = std::iter::once_with(retracted)
            .flatten()
            .map(|(exit, entry)| plan::plan_leg_via_with(&space, &validity, exit, entry, settings, middle));
        for (k, result) in direct.chain(via).enumerate() {
            match result {
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
                // An invalid end: no variant of the direct leg can help.
                Err(e) if k == 0 => return Err(e),
                Err(_) => {}
            }
        }
    }
    Err(PlanError::NoPath {
        samples,
        validity_calls: calls,
    })
}

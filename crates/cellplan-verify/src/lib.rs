//! `cellplan verify`: an independent check of a plan against its cell. It shares only the
//! geometry and kinematics primitives with the planner (forward kinematics, the collision
//! world, the process's checks) and reads nothing but the plan document, and it re-derives
//! every number the document states about the plan:
//! - `tasks`: every task done exactly once by a robot that has it as a candidate, at a pose
//!   the process accepts, with the figures the process gives; the unmeasured list exactly the
//!   tasks no robot can do, with their reasons;
//! - `paths`: the legs chained home → tasks → home, proven clear of the static scene and of
//!   the robot itself (conservative advancement on each body's and self pair's motion bound,
//!   from the bodies' shapes as the cell gives them: every configuration measured keeps the
//!   clearance, none between comes within [`PROOF_TOLERANCE`] of less); the trajectory walked
//!   forward along them;
//! - `timing`: the trajectory samples at the stated step, within joint position, velocity and
//!   acceleration limits; the program's clock (legs, waits, visits) re-derived and every robot
//!   total recomputed; each wait a standstill;
//! - `robots`: robot–robot clearance over the common timeline, proven the same way pair by
//!   pair (the robots' travel along their trajectories);
//! - `record`: the settings the cell fixes, the cycle time, Δt, the lower bound (recomputed
//!   from the candidates), the coordination record and the candidate count.
//!
//! Apart from plans of cells, [`motion`] re-checks bare joint paths (the motion benchmark's)
//! exactly, on the robot's collision meshes as given.
//!
//! Before any of that the document is [`validate`]d, and a plan too
//! large to check at the requested resolution is refused ([`workload`]).
pub mod cmm;
pub mod motion;
mod paths;
pub mod pcb;
mod record;
mod robots;
pub use robots::PROOF_TOLERANCE;
pub mod studweld;
mod tasks;
mod timing;

use cellplan_core::candidates::{self, CandidateTable};
use cellplan_core::document::{Plan, RobotPlan, validate};
use cellplan_model::Cell;
use cellplan_model::robot::Robot;
use serde::Serialize;

/// The verifier's resolution.
#[derive(Clone, Copy, Debug)]
pub struct VerifySettings {
    /// The scale (rad or m) of the leg check's work: it measures a piece of a leg at most twice
    /// per joint step of the piece's largest joint travel (and 2,000 times more) before it
    /// reports the rest unproven, and a plan whose legs would need more than [`MAX_CHECKS`]
    /// configurations at this step is refused as too large. The check itself steps as far as
    /// the bodies' motion bound proves the robot clear (see `paths`).
    pub joint_step: f64,
    /// Time step (s) of the robot–robot check inside a contact: how finely its interval is
    /// reported (between contacts the check steps as far as the motion bound allows, see
    /// `robots`); it also sets the check's budget of instants per pair.
    pub time_step: f64,
    /// Relative tolerance on velocity and acceleration limits.
    pub limit_tolerance: f64,
    /// Whether robot–robot clearance is checked (off for single-robot checks of motion plans
    /// that are not coordinated yet).
    pub robot_robot: bool,
}

impl Default for VerifySettings {
    fn default() -> Self {
        VerifySettings {
            joint_step: 1e-3,
            time_step: 0.01,
            limit_tolerance: 1e-6,
            robot_robot: true,
        }
    }
}

/// Most configurations the verifier checks against the scene, and most robot-time steps of
/// the robot–robot check, before it refuses a plan as too large to check.
pub const MAX_CHECKS: u64 = 50_000_000;

/// What is wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ViolationKind {
    /// The document is not a plan of this version, does not match the cell, or is too large
    /// to check.
    Format,
    /// A task of the cell done by nobody (and not listed as undoable).
    MissingTask,
    /// A task done more than once.
    DuplicateTask,
    /// A task id the cell does not have, or a task done by a robot that cannot do it.
    UnknownTask,
    /// The list of tasks nobody can do disagrees with the cell (a task listed that a robot
    /// can do or does, a reason that is not the furthest check passed).
    Unmeasured,
    /// A pose the process refuses for its task, or whose recorded tool pose disagrees with
    /// the joints.
    ProbeConstraint,
    /// A configuration outside the joint limits.
    JointLimit,
    /// A joint faster than its limit.
    Velocity,
    /// A joint accelerating harder than its limit.
    Acceleration,
    /// Closer than the clearance to the part or a fixture.
    StaticClearance,
    /// Two bodies of one robot touching.
    SelfCollision,
    /// Two robots closer than the clearance.
    RobotRobot,
    /// A trajectory that leaves its legs' joint paths (so the motion is not the one checked
    /// against the scene), goes back along them, or covers more path between two samples than
    /// the joint velocity limits allow.
    OffPath,
    /// Legs, visits, waits and trajectory that do not fit together (a gap, a jump, a missing
    /// sample, a robot not at its task while working, a wait that is not a standstill).
    Continuity,
    /// A stated figure that does not match the recomputed one.
    Totals,
}

/// One violation.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Violation {
    /// What.
    pub kind: ViolationKind,
    /// The robot (first robot for robot–robot).
    pub robot: Option<String>,
    /// The other robot (robot–robot only).
    pub other: Option<String>,
    /// When (s), where it applies.
    pub time_s: Option<f64>,
    /// The task, where it applies.
    pub task: Option<String>,
    /// A sentence.
    pub detail: String,
}

impl Violation {
    /// A violation about the whole plan.
    fn plan(kind: ViolationKind, detail: String) -> Self {
        Violation {
            kind,
            robot: None,
            other: None,
            time_s: None,
            task: None,
            detail,
        }
    }

    /// A violation of one robot.
    fn robot(
        kind: ViolationKind,
        robot: &str,
        time_s: Option<f64>,
        task: Option<&str>,
        detail: String,
    ) -> Self {
        Violation {
            kind,
            robot: Some(robot.to_string()),
            other: None,
            time_s,
            task: task.map(String::from),
            detail,
        }
    }
}

/// The verifier's verdict.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// True when there is no violation.
    pub ok: bool,
    /// Every violation (robot–robot ones merged per robot pair and time interval).
    pub violations: Vec<Violation>,
    /// Recomputed cycle time (s).
    pub cycle_time_s: f64,
    /// Recomputed Δt (s).
    pub delta_t_s: f64,
    /// Configurations checked against the scene.
    pub configurations_checked: usize,
    /// Instants at which a robot pair's distance was measured (summed over the pairs).
    pub pair_instants_checked: usize,
}

/// The checks a plan needs at `settings`' resolution: (configurations of the legs,
/// robot-time steps of the robot–robot check).
pub fn workload(plan: &Plan, settings: &VerifySettings) -> (u64, u64) {
    let configurations = plan
        .robots
        .iter()
        .flat_map(|rp| &rp.legs)
        .flat_map(|leg| leg.waypoints.windows(2))
        .map(|w| {
            (paths::max_abs_diff(&w[0], &w[1]) / settings.joint_step)
                .ceil()
                .max(1.0)
                + 1.0
        })
        .sum::<f64>();
    let horizon = plan
        .robots
        .iter()
        .filter_map(|rp| rp.trajectory.last().map(|s| s.t))
        .fold(0.0, f64::max);
    let timeline = if settings.robot_robot && plan.robots.len() > 1 {
        (horizon / settings.time_step).ceil() * plan.robots.len() as f64
    } else {
        0.0
    };
    (
        configurations.min(u64::MAX as f64) as u64,
        timeline.min(u64::MAX as f64) as u64,
    )
}

/// Why a plan is too large to check, if it is.
pub fn too_large(plan: &Plan, settings: &VerifySettings) -> Option<String> {
    let (configurations, timeline) = workload(plan, settings);
    if configurations > MAX_CHECKS {
        Some(format!(
            "its legs need {configurations} configuration checks at a joint step of {}, more than {MAX_CHECKS}",
            settings.joint_step
        ))
    } else if timeline > MAX_CHECKS {
        Some(format!(
            "its timeline needs {timeline} robot-time steps at a time step of {} s, more than {MAX_CHECKS}",
            settings.time_step
        ))
    } else {
        None
    }
}

/// Verify `plan` against `cell`; the candidate table the checks need is generated from the
/// cell.
pub fn verify(cell: &Cell, plan: &Plan, settings: &VerifySettings) -> Report {
    verify_with(cell, None, plan, settings)
}

/// Verify `plan` against `cell` with the cell's candidate table when the caller has it
/// already (the table is a function of the cell alone; `None` generates it).
pub fn verify_with(
    cell: &Cell,
    table: Option<&CandidateTable>,
    plan: &Plan,
    settings: &VerifySettings,
) -> Report {
    if let Err(e) = validate(plan) {
        return finish(
            vec![Violation::plan(ViolationKind::Format, e.to_string())],
            0.0,
            0.0,
            (0, 0),
        );
    }
    if let Some(why) = too_large(plan, settings) {
        return finish(
            vec![Violation::plan(
                ViolationKind::Format,
                format!("too large to check: {why}"),
            )],
            0.0,
            0.0,
            (0, 0),
        );
    }
    let generated;
    let table = match table {
        Some(t) => t,
        None => {
            generated = candidates::generate(cell);
            &generated
        }
    };
    let mut out = Vec::new();
    let robots = pair_robots(cell, plan, &mut out);
    tasks::check(cell, table, plan, &robots, &mut out);
    let checked = paths::check(cell, &robots, settings, &mut out);
    let times = timing::check(plan, &robots, settings, &mut out);
    let instants = if settings.robot_robot {
        robots::check(cell, &robots, &times, settings, &mut out)
    } else {
        0
    };
    let (cycle, delta) = record::check(cell, table, plan, &robots, &times, &mut out);
    finish(out, cycle, delta, (checked, instants))
}

/// The plan's robots matched to the cell's by name, in cell order; robots missing on either
/// side, or with other joints or another home, are reported and left out of the walk.
fn pair_robots<'a>(
    cell: &'a Cell,
    plan: &'a Plan,
    out: &mut Vec<Violation>,
) -> Vec<(&'a Robot, &'a RobotPlan)> {
    let mut robots = Vec::new();
    for robot in &cell.robots {
        let Some(rp) = plan.robots.iter().find(|r| r.name == robot.name) else {
            out.push(Violation::robot(
                ViolationKind::Format,
                &robot.name,
                None,
                None,
                "the plan has no entry for this robot".into(),
            ));
            continue;
        };
        let names = robot.joint_names();
        if rp.joints.iter().map(String::as_str).ne(names.iter().copied()) {
            out.push(Violation::robot(
                ViolationKind::Format,
                &rp.name,
                None,
                None,
                format!("joints {:?}, but the cell's robot has {names:?}", rp.joints),
            ));
            continue;
        }
        if paths::dist(&rp.home, &robot.home) > 1e-9 {
            out.push(Violation::robot(
                ViolationKind::Format,
                &rp.name,
                None,
                None,
                format!("home {:?}, but the cell's robot has {:?}", rp.home, robot.home),
            ));
        }
        robots.push((robot, rp));
    }
    for (k, rp) in plan.robots.iter().enumerate() {
        if !cell.robots.iter().any(|r| r.name == rp.name) {
            out.push(Violation::robot(
                ViolationKind::Format,
                &rp.name,
                None,
                None,
                "the cell has no such robot".into(),
            ));
        } else if plan.robots[..k].iter().any(|r| r.name == rp.name) {
            out.push(Violation::robot(
                ViolationKind::Format,
                &rp.name,
                None,
                None,
                "the plan has two entries for this robot".into(),
            ));
        }
    }
    robots
}

/// Per joint, a bound (m) on any point of the robot's bodies' distance from the joint's axis
/// ([`cellplan_kin::Chain::joint_radii`]), each body's reach from its link's origin its shape's
/// offset plus the shape's own reach (the shapes as the cell gives them, not the planner's
/// covers): along any joint motion, the bodies' points move at most `Σ_j R_j·∫|dq_j|`.
fn body_radii(robot: &Robot) -> Vec<f64> {
    let bodies: Vec<(usize, f64)> = robot
        .body_links
        .iter()
        .enumerate()
        .map(|(i, &link)| (link, body_reach(robot, i)))
        .collect();
    robot.model.chain.joint_radii(&bodies)
}

/// The largest distance of body `i`'s points from the origin of the link it hangs on: its
/// shape's offset plus the shape's own reach (infinite for a body without a shape).
fn body_reach(robot: &Robot, i: usize) -> f64 {
    robot.body_shapes.get(i).map_or(f64::INFINITY, |(shape, pose)| {
        pose.translation.length() + shape.reach()
    })
}

/// The farthest `x` in `[from, to]` at which `fits(x)` holds, for a `fits` that holds at `from`
/// and, once false, stays false (a bound that only grows along the way): `to` when it holds
/// there, else bisection to the last floating-point step.
fn farthest(from: f64, to: f64, mut fits: impl FnMut(f64) -> bool) -> f64 {
    if fits(to) {
        return to;
    }
    let (mut lo, mut hi) = (from, to);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if fits(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

fn finish(violations: Vec<Violation>, cycle: f64, delta: f64, (checked, instants): (usize, usize)) -> Report {
    Report {
        ok: violations.is_empty(),
        violations,
        cycle_time_s: cycle,
        delta_t_s: delta,
        configurations_checked: checked,
        pair_instants_checked: instants,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn farthest_finds_where_a_growing_bound_reaches_its_room() {
        // The whole way when it fits there.
        assert_eq!(super::farthest(0.2, 1.0, |x| x <= 2.0), 1.0);
        // Else the last point that fits, to the floating-point step, and never past it.
        let x = super::farthest(0.0, 1.0, |x| x * x <= 0.09);
        assert!(x <= 0.3 && 0.3 - x < 1e-12, "{x}");
        // Nothing beyond the start fits: the start.
        assert_eq!(super::farthest(0.5, 1.0, |x| x <= 0.5), 0.5);
    }
}

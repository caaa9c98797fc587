//! The independent check of a stud-weld plan (paper 002), from the plan document and the cell:
//!
//! - the document is of this cell and its process parameters; every stud is welded once or
//!   listed unweldable;
//! - every weld: the TCP (forward kinematics of the robot with its gun) on the stud within
//!   10 µm, the gun's axis along the inward normal within 10 µrad
//!   (`cellplan_studweld::process::WELD_POSE_TOLERANCE`), the joints within their limits,
//!   the pose collision-free at the cell's clearance, the gravity torques within the limits, the
//!   pose held from `start_s` to `end_s` = weld time, and its node cost re-derived;
//! - every move (`legs`): joins the welds (home at both ends), satisfies the discrete
//!   Euler–Lagrange equations of DMOC re-evaluated here with `cellplan_kin::dynamics` (the
//!   planner's `cellplan-ocp` is not used), keeps joint, velocity and torque limits, and keeps
//!   the clearance along the whole motion (each straight piece proven clear by the verifier's
//!   own conservative advancement, as inspection legs are: every position measured keeps the
//!   clearance, none between comes within 1 mm of less); J and the duration re-derived;
//! - the totals (travel, welding, J, cycle time) re-derived from the parts.
mod legs;

use cellplan_geom::DVec3;
use cellplan_kin::dynamics::{Dynamics, LinkInertia};
use cellplan_model::robot::Scratch;
use cellplan_model::{Cell, Robot};
use cellplan_studweld::StudWeld;
use cellplan_studweld::document::WeldPlan;
use serde::Serialize;

/// Relative tolerance of re-derived numbers.
const REL_TOL: f64 = 1e-6;

/// What went wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum WeldViolationKind {
    /// The document does not match the cell.
    Format,
    /// A stud welded twice, not at all without a reason, or unknown.
    Stud,
    /// A weld pose off the stud or its axis, or not held for the weld time.
    Weld,
    /// Joint limits.
    JointLimit,
    /// Speed limits.
    Velocity,
    /// Torque limits.
    Torque,
    /// The discrete Euler–Lagrange equations do not hold.
    Dynamics,
    /// Closer than the clearance to the scene or itself.
    Collision,
    /// Moves that do not join up.
    Continuity,
    /// A stated number the check does not reproduce.
    Total,
}

/// One violation.
#[derive(Clone, Debug, Serialize)]
pub struct WeldViolation {
    /// What.
    pub kind: WeldViolationKind,
    /// Where and by how much.
    pub detail: String,
}

/// The verdict.
#[derive(Clone, Debug, Serialize)]
pub struct WeldReport {
    /// No violation.
    pub ok: bool,
    /// The violations.
    pub violations: Vec<WeldViolation>,
    /// Largest relative residual of the discrete Euler–Lagrange equations over all moves.
    pub max_dynamics_residual: f64,
    /// Straight pieces proven clear.
    pub segments_checked: usize,
}

pub(crate) struct Ctx<'a> {
    pub cell: &'a Cell,
    pub robot: &'a Robot,
    pub process: &'a StudWeld,
    pub dynamics: Dynamics,
    pub out: Vec<WeldViolation>,
    pub max_residual: f64,
    pub segments: usize,
}

impl Ctx<'_> {
    pub fn fail(&mut self, kind: WeldViolationKind, detail: String) {
        self.out.push(WeldViolation { kind, detail });
    }
}

/// Whether `a` and `b` agree to `REL_TOL` relative (absolute below 1).
pub(crate) fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= REL_TOL * a.abs().max(b.abs()).max(1.0)
}

/// The robot's dynamics with the gun lumped into the tip link, gravity −z of the world in the
/// root frame (built here from the URDF's inertials and the process table).
fn dynamics(robot: &Robot, p: &StudWeld) -> Dynamics {
    let mut inertia = robot.model.inertia.clone();
    if p.gun_mass > 0.0
        && let Some(tip) = inertia.last_mut()
    {
        let gun = LinkInertia {
            mass: p.gun_mass,
            com: p.gun_com,
            inertia: glam::DMat3::ZERO,
        };
        *tip = Some(tip.unwrap_or(LinkInertia::ZERO).combined(&gun));
    }
    let mut d = Dynamics::new(&robot.model.chain, &inertia);
    d.gravity = robot.base.rotation.inverse() * DVec3::new(0.0, 0.0, -9.81);
    d
}

/// Checks `plan` against `cell`.
pub fn verify_weld(cell: &Cell, plan: &WeldPlan) -> WeldReport {
    let Some(process) = cell.process.as_any().downcast_ref::<StudWeld>() else {
        return report_of(vec![WeldViolation {
            kind: WeldViolationKind::Format,
            detail: "the cell is not a stud-weld cell".into(),
        }]);
    };
    let [robot] = cell.robots.as_slice() else {
        return report_of(vec![WeldViolation {
            kind: WeldViolationKind::Format,
            detail: "a stud-weld cell has one robot".into(),
        }]);
    };
    let mut c = Ctx {
        cell,
        robot,
        process,
        dynamics: dynamics(robot, process),
        out: Vec::new(),
        max_residual: 0.0,
        segments: 0,
    };
    if plan.cell != cell.name {
        c.fail(
            WeldViolationKind::Format,
            format!("plan of cell `{}`, not `{}`", plan.cell, cell.name),
        );
    }
    if plan.parameters != cell.process.parameters() {
        c.fail(
            WeldViolationKind::Format,
            "the process parameters differ from the cell's".into(),
        );
    }
    studs(&mut c, plan);
    welds(&mut c, plan);
    legs::check(&mut c, plan);
    totals(&mut c, plan);
    WeldReport {
        ok: c.out.is_empty(),
        violations: c.out,
        max_dynamics_residual: c.max_residual,
        segments_checked: c.segments,
    }
}

fn report_of(violations: Vec<WeldViolation>) -> WeldReport {
    WeldReport {
        ok: violations.is_empty(),
        violations,
        max_dynamics_residual: 0.0,
        segments_checked: 0,
    }
}

/// Every stud welded once or listed unweldable, nothing else.
fn studs(c: &mut Ctx, plan: &WeldPlan) {
    for task in &c.cell.tasks {
        let welded = plan.visits.iter().filter(|v| v.stud == task.name).count();
        let listed = plan.unweldable.iter().any(|u| u.stud == task.name);
        if welded + usize::from(listed) != 1 {
            c.fail(
                WeldViolationKind::Stud,
                format!(
                    "stud `{}` welded {welded} times, listed unweldable: {listed}",
                    task.name
                ),
            );
        }
    }
    for v in &plan.visits {
        if !c.cell.tasks.iter().any(|t| t.name == v.stud) {
            c.fail(WeldViolationKind::Stud, format!("unknown stud `{}`", v.stud));
        }
    }
}

/// The weld poses.
fn welds(c: &mut Ctx, plan: &WeldPlan) {
    let mut scratch = Scratch::default();
    let wt = c.process.weights;
    for v in &plan.visits {
        let Some(task) = c.cell.tasks.iter().find(|t| t.name == v.stud) else {
            continue;
        };
        if v.q.len() != c.robot.dof() {
            c.fail(
                WeldViolationKind::Format,
                format!("weld `{}`: {} joint values", v.stud, v.q.len()),
            );
            continue;
        }
        let tcp = c.robot.tcp_pose(&v.q);
        let (ok, off, tilt) = cellplan_studweld::process::weld_pose_error(&tcp, task.position, task.normal);
        if !ok {
            c.fail(
                WeldViolationKind::Weld,
                format!(
                    "weld `{}`: TCP {off:.2e} m from the stud, axis {tilt:.2e} rad off the normal",
                    v.stud
                ),
            );
        }
        if !c.robot.within_limits(&v.q) {
            c.fail(
                WeldViolationKind::JointLimit,
                format!("weld `{}` outside the joint limits", v.stud),
            );
        }
        c.robot.body_poses(&v.q, &mut scratch);
        if c.robot
            .contact_at(&c.cell.world, &scratch, c.cell.planning.clearance)
            .is_some()
        {
            c.fail(
                WeldViolationKind::Collision,
                format!("weld `{}` pose within the clearance", v.stud),
            );
        }
        let g = c.dynamics.gravity_torques(&v.q);
        if let Some(j) = (0..g.len()).find(|&j| g[j].abs() > c.process.max_torque[j] * (1.0 + 1e-9)) {
            c.fail(
                WeldViolationKind::Torque,
                format!(
                    "weld `{}`: holding needs {:.1} N·m on joint {}",
                    v.stud,
                    g[j],
                    j + 1
                ),
            );
        }
        let cost = c.process.weld_time * (wt.time + wt.effort * g.iter().map(|x| x * x).sum::<f64>());
        if !close(cost, v.weld_cost) {
            c.fail(
                WeldViolationKind::Total,
                format!(
                    "weld `{}`: cost {} stated, {cost} re-derived",
                    v.stud, v.weld_cost
                ),
            );
        }
        if !close(v.end_s - v.start_s, c.process.weld_time) {
            c.fail(
                WeldViolationKind::Weld,
                format!(
                    "weld `{}` held {} s, the weld takes {} s",
                    v.stud,
                    v.end_s - v.start_s,
                    c.process.weld_time
                ),
            );
        }
    }
}

/// Travel, welding, J and the cycle time.
fn totals(c: &mut Ctx, plan: &WeldPlan) {
    let travel: f64 = plan.legs.iter().map(|l| l.cost).sum();
    let weld: f64 = plan.visits.iter().map(|v| v.weld_cost).sum();
    let cycle: f64 =
        plan.legs.iter().map(|l| l.duration_s).sum::<f64>() + plan.visits.len() as f64 * c.process.weld_time;
    let t = plan.totals;
    for (what, stated, derived) in [
        ("travel_cost", t.travel_cost, travel),
        ("weld_cost", t.weld_cost, weld),
        ("cost", t.cost, travel + weld),
        ("cycle_time_s", t.cycle_time_s, cycle),
    ] {
        if !close(stated, derived) {
            c.fail(
                WeldViolationKind::Total,
                format!("{what}: {stated} stated, {derived} re-derived"),
            );
        }
    }
    // The clock: each move starts when the previous weld ends.
    let mut now = 0.0;
    for (i, l) in plan.legs.iter().enumerate() {
        if !close(l.start_s, now) {
            c.fail(
                WeldViolationKind::Continuity,
                format!("move {i} starts at {} s, not {now} s", l.start_s),
            );
        }
        now += l.duration_s;
        if let Some(v) = plan.visits.get(i) {
            if !close(v.start_s, now) {
                c.fail(
                    WeldViolationKind::Weld,
                    format!("weld `{}` starts at {} s, not {now} s", v.stud, v.start_s),
                );
            }
            now += c.process.weld_time;
        }
    }
}

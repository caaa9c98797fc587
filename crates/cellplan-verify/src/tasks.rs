//! Every task done exactly once, by a robot that can do it, at a pose the process accepts and
//! with the figures the process gives; the unmeasured list exactly the tasks nobody can do.
use super::{Violation, ViolationKind};
use cellplan_core::candidates::CandidateTable;
use cellplan_core::document::{Plan, RobotPlan, Visit};
use cellplan_geom::DVec3;
use cellplan_model::Cell;
use cellplan_model::robot::{Robot, Scratch};
use cellplan_model::tasks::{Task, TaskId};
use std::collections::BTreeMap;

/// The task checks (see the module).
pub(super) fn check(
    cell: &Cell,
    table: &CandidateTable,
    plan: &Plan,
    robots: &[(&Robot, &RobotPlan)],
    out: &mut Vec<Violation>,
) {
    let words = cell.process.words();
    let cap = cell.planning.task_cap;
    let by_name: BTreeMap<&str, usize> = cell.tasks.iter().map(|t| (t.name.as_str(), t.id.0)).collect();
    let mut count = vec![0usize; cell.tasks.len()];
    let mut scratch = Scratch::default();
    for (robot, rp) in robots {
        if rp.tasks.len() > cap {
            out.push(Violation::robot(
                ViolationKind::Totals,
                &rp.name,
                None,
                None,
                format!("{} {}, over the task cap {cap}", rp.tasks.len(), words.tasks),
            ));
        }
        for v in &rp.tasks {
            let Some(&t) = by_name.get(v.task.as_str()) else {
                out.push(Violation::robot(
                    ViolationKind::UnknownTask,
                    &rp.name,
                    Some(v.arrive_s),
                    Some(&v.task),
                    format!("no {} of the cell has this id", words.task),
                ));
                continue;
            };
            count[t] += 1;
            check_candidate(table, robot, rp, v, t, out);
            check_visit(cell, robot, rp, v, &cell.tasks[t], &mut scratch, out);
        }
    }
    check_counts(cell, table, plan, &count, out);
}

/// The visit's candidate: one the robot has for the task, and (unless coordination perturbed
/// it) the very configuration.
fn check_candidate(
    table: &CandidateTable,
    robot: &Robot,
    rp: &RobotPlan,
    v: &Visit,
    t: usize,
    out: &mut Vec<Violation>,
) {
    let candidates = &table.get(TaskId(t), robot.id).candidates;
    let detail = match candidates.get(v.candidate) {
        None => format!(
            "candidate {} of {} the robot has for this task",
            v.candidate,
            candidates.len()
        ),
        Some(c) if v.perturbation_rad.is_none() && super::paths::dist(&c.q, &v.q) > 1e-9 => {
            "the configuration is not the candidate it names (and no perturbation is stated)".into()
        }
        Some(_) => return,
    };
    let kind = if candidates.is_empty() {
        ViolationKind::UnknownTask
    } else {
        ViolationKind::ProbeConstraint
    };
    out.push(Violation::robot(
        kind,
        &rp.name,
        Some(v.arrive_s),
        Some(&v.task),
        detail,
    ));
}

/// One visit: joint limits, the recorded tool pose, the process's checks and figures, the
/// work's duration.
fn check_visit(
    cell: &Cell,
    robot: &Robot,
    rp: &RobotPlan,
    v: &Visit,
    task: &Task,
    scratch: &mut Scratch,
    out: &mut Vec<Violation>,
) {
    let process = cell.process.as_ref();
    let words = process.words();
    let mut push = |kind, detail: String| {
        out.push(Violation::robot(
            kind,
            &rp.name,
            Some(v.arrive_s),
            Some(&v.task),
            detail,
        ));
    };
    if !robot.within_limits(&v.q) {
        push(
            ViolationKind::JointLimit,
            "the configuration at the task is outside the joint limits".into(),
        );
        return;
    }
    let tcp = robot.tcp_pose(&v.q);
    let stated_rotation = glam::DQuat::from_array(v.tcp.quat);
    if (tcp.translation - DVec3::from(v.tcp.xyz)).length() > 1e-6
        || tcp.rotation.dot(stated_rotation).abs() < 1.0 - 1e-9
    {
        push(
            ViolationKind::ProbeConstraint,
            format!("the recorded {} pose disagrees with the joints", words.tool),
        );
    }
    robot.body_poses(&v.q, scratch);
    let accepted = process
        .pose_check(task, &tcp)
        .and_then(|()| process.reached_check(&cell.world, task, &tcp))
        .and_then(|()| process.arm_check(&cell.world, robot, &scratch.bodies, task, &tcp));
    if let Err(r) = accepted {
        push(
            ViolationKind::ProbeConstraint,
            format!(
                "the process refuses this pose for the {}: {} ({})",
                words.task, r.text, r.code
            ),
        );
    }
    let figures = process.visit_figures(task, &tcp);
    let stated: Vec<&str> = v.figures.keys().map(String::as_str).collect();
    let mut expected: Vec<&str> = figures.iter().map(|f| f.key).collect();
    expected.sort_unstable();
    if stated != expected {
        push(
            ViolationKind::Totals,
            format!("states the figures {stated:?}; the process gives {expected:?}"),
        );
    }
    for f in &figures {
        if let Some(&x) = v.figures.get(f.key)
            && (x - f.value).abs() > 1e-6
        {
            push(
                ViolationKind::Totals,
                format!("states {} = {x}, but the pose gives {}", f.key, f.value),
            );
        }
    }
    let work = process.work(task).duration();
    if (v.depart_s - v.arrive_s - work).abs() > 1e-6 {
        push(
            ViolationKind::Continuity,
            format!(
                "{} for {:.6} s; the work takes {work} s",
                words.working,
                v.depart_s - v.arrive_s
            ),
        );
    }
}

/// Each task done once, or listed as undoable with the reason the candidates give.
fn check_counts(cell: &Cell, table: &CandidateTable, plan: &Plan, count: &[usize], out: &mut Vec<Violation>) {
    let mut listed: BTreeMap<&str, &str> = BTreeMap::new();
    for u in &plan.unmeasured {
        if listed.insert(u.task.as_str(), u.reason.as_str()).is_some() {
            out.push(task_violation(
                ViolationKind::Unmeasured,
                &u.task,
                "listed twice as undoable".into(),
            ));
        }
        if !cell.tasks.iter().any(|t| t.name == u.task) {
            out.push(task_violation(
                ViolationKind::Unmeasured,
                &u.task,
                "listed as undoable, but the cell has no such task".into(),
            ));
        }
    }
    for (t, &n) in count.iter().enumerate() {
        let name = cell.tasks[t].name.as_str();
        let doable = !table.robots_for(TaskId(t)).is_empty();
        match (n, listed.get(name)) {
            (2.., _) => out.push(task_violation(
                ViolationKind::DuplicateTask,
                name,
                format!("done {n} times"),
            )),
            (1, Some(_)) => out.push(task_violation(
                ViolationKind::Unmeasured,
                name,
                "done, and listed as undoable".into(),
            )),
            (0, None) => out.push(task_violation(
                ViolationKind::MissingTask,
                name,
                "done by no robot and not listed as undoable".into(),
            )),
            _ => {}
        }
        if let Some(&reason) = listed.get(name) {
            let expected = cellplan_core::document::unmeasured_reason(table, t);
            // A task robots can reach may be given up when the planner found no path to it:
            // the plan says so (`no-path`); a search's failure is not a number to re-derive.
            if doable && reason != cellplan_core::document::NO_PATH {
                out.push(task_violation(
                    ViolationKind::Unmeasured,
                    name,
                    format!(
                        "listed as undoable for `{reason}`, but a robot has a candidate for it (only `{}` may be said of such a task)",
                        cellplan_core::document::NO_PATH
                    ),
                ));
            } else if !doable && reason != expected {
                out.push(task_violation(
                    ViolationKind::Unmeasured,
                    name,
                    format!("listed as undoable for `{reason}`; the candidates say `{expected}`"),
                ));
            }
        }
    }
}

fn task_violation(kind: ViolationKind, task: &str, detail: String) -> Violation {
    Violation {
        task: Some(task.to_string()),
        ..Violation::plan(kind, detail)
    }
}

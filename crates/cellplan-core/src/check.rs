//! The `cellplan check` report: candidates per task and robot, reachability classes, and every
//! task no robot can do with the reason, and every robot that can do none. Its JSON keys are
//! stable: scripts read `tasks`, `robots`, `candidates`, `unmeasurable`, `shared` and `idle`.
use crate::candidates::{CandidateTable, Classes, classes};
use crate::document::IdleRobotOut;
use cellplan_model::robot::IkKind;
use cellplan_model::{Cell, InputError, Rejection, RobotId, TaskId};
use serde::Serialize;
use serde_json::{Map, Value};
use std::fmt::Write;

/// Candidates of one task.
#[derive(Clone, Debug, Serialize)]
pub struct TaskCandidates {
    /// Task id.
    pub task: String,
    /// Robot name → number of candidates.
    pub robots: Map<String, Value>,
}

/// Why one robot cannot do a task.
#[derive(Clone, Debug, Serialize)]
pub struct RobotReason {
    /// Robot name.
    pub robot: String,
    /// Stable reason code (`no-ik`, `joint-limits`, `collision`, or the process's own, such as
    /// `beam-occluded`), `none` when it can.
    pub reason: &'static str,
    /// Sampled poses by the furthest stage they reached.
    pub poses: Map<String, Value>,
}

/// A task no robot can do.
#[derive(Clone, Debug, Serialize)]
pub struct Unmeasurable {
    /// Task id.
    pub task: String,
    /// One entry per robot.
    pub reasons: Vec<RobotReason>,
}

/// A task more than one robot can do.
#[derive(Clone, Debug, Serialize)]
pub struct Shared {
    /// Task id.
    pub task: String,
    /// The robots that can.
    pub robots: Vec<String>,
}

/// Q_il of paper 000.
#[derive(Clone, Debug, Serialize)]
pub struct PairClass {
    /// The two robots.
    pub robots: [String; 2],
    /// Tasks both can do.
    pub tasks: Vec<String>,
}

/// δ and Q classes by name.
#[derive(Clone, Debug, Serialize)]
pub struct ClassReport {
    /// δ_i: robot name → tasks only it can do.
    pub exclusive: Map<String, Value>,
    /// Q_il for every pair sharing tasks.
    pub pairs: Vec<PairClass>,
}

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct CheckReport {
    /// Cell name.
    pub cell: String,
    /// Number of tasks.
    pub tasks: usize,
    /// Robot names, in file order.
    pub robots: Vec<String>,
    /// Each robot's inverse kinematics, in file order: `opw` (the parameters given), `opw-derived`
    /// and `parallel` (closed forms read off the URDF), `track` (an OPW arm on a track),
    /// `numeric`.
    pub ik: Vec<IkKind>,
    /// Candidates per task and robot.
    pub candidates: Vec<TaskCandidates>,
    /// Total number of candidates.
    pub total_candidates: usize,
    /// Reachability classes.
    pub classes: ClassReport,
    /// Tasks more than one robot can do.
    pub shared: Vec<Shared>,
    /// Tasks no robot can do, with reasons.
    pub unmeasurable: Vec<Unmeasurable>,
    /// Robots that can do none of the tasks (they stay at home), with the reason, as a plan
    /// states them.
    pub idle: Vec<IdleRobotOut>,
}

fn names(cell: &Cell, tasks: &[TaskId]) -> Vec<String> {
    tasks.iter().map(|t| cell.tasks[t.0].name.clone()).collect()
}

/// Builds the report.
pub fn report(cell: &Cell, table: &CandidateTable) -> CheckReport {
    let cls: Classes = classes(table, cell.robots.len());
    let robots: Vec<String> = cell.robots.iter().map(|r| r.name.clone()).collect();
    let ik = cell.robots.iter().map(|r| r.ik_kind).collect();
    let candidates = cell
        .tasks
        .iter()
        .map(|t| TaskCandidates {
            task: t.name.clone(),
            robots: cell
                .robots
                .iter()
                .map(|r| {
                    (
                        r.name.clone(),
                        Value::from(table.get(t.id, r.id).candidates.len()),
                    )
                })
                .collect(),
        })
        .collect();
    let shared = cell
        .tasks
        .iter()
        .filter_map(|t| {
            let who = table.robots_for(t.id);
            (who.len() > 1).then(|| Shared {
                task: t.name.clone(),
                robots: who.iter().map(|r| cell.robots[r.0].name.clone()).collect(),
            })
        })
        .collect();
    let unmeasurable = cls
        .unmeasurable
        .iter()
        .map(|&t| Unmeasurable {
            task: cell.tasks[t.0].name.clone(),
            reasons: cell
                .robots
                .iter()
                .map(|r| {
                    let reach = table.get(t, r.id);
                    RobotReason {
                        robot: r.name.clone(),
                        reason: reach.reason().map_or("none", Rejection::code),
                        poses: reach
                            .rejected
                            .iter()
                            .map(|(k, v)| (k.code().to_string(), Value::from(*v)))
                            .collect(),
                    }
                })
                .collect(),
        })
        .collect();
    CheckReport {
        cell: cell.name.clone(),
        tasks: cell.tasks.len(),
        robots,
        ik,
        candidates,
        total_candidates: table.total(),
        classes: ClassReport {
            exclusive: cell
                .robots
                .iter()
                .map(|r| (r.name.clone(), Value::from(names(cell, &cls.exclusive[r.id.0]))))
                .collect(),
            pairs: cls
                .shared_pairs
                .iter()
                .map(|((a, b), t)| PairClass {
                    robots: [cell.robots[a.0].name.clone(), cell.robots[b.0].name.clone()],
                    tasks: names(cell, t),
                })
                .collect(),
        },
        shared,
        unmeasurable,
        idle: idle_robots_out(cell, table),
    }
}

/// [`idle_robots`] by name, each with [`idle_reason`]: what `check` reports and a plan states.
pub fn idle_robots_out(cell: &Cell, table: &CandidateTable) -> Vec<IdleRobotOut> {
    idle_robots(cell, table)
        .into_iter()
        .map(|r| IdleRobotOut {
            robot: cell.robots[r.0].name.clone(),
            reason: idle_reason(cell, table, r),
        })
        .collect()
}

/// The robots that can do none of the cell's tasks, in cell order. Such a robot stays at home:
/// a plan has no work for it, and Δt leaves it out ([`balance_spread`]).
pub fn idle_robots(cell: &Cell, table: &CandidateTable) -> Vec<RobotId> {
    cell.robots
        .iter()
        .map(|r| r.id)
        .filter(|&r| can_do_nothing(cell, table, r))
        .collect()
}

/// Whether `robot` has no candidate for any of the cell's tasks.
pub fn can_do_nothing(cell: &Cell, table: &CandidateTable, robot: RobotId) -> bool {
    cell.tasks
        .iter()
        .all(|t| table.get(t.id, robot).candidates.is_empty())
}

/// Why `robot` can do none of the tasks, for people: the rejections counted, the nearest task
/// and the robot's reach ("2 × out of reach (no IK solution); the nearest task is 4108 mm away
/// and its reach is at most 4527 mm").
pub fn idle_reason(cell: &Cell, table: &CandidateTable, robot: RobotId) -> String {
    let robot = &cell.robots[robot.0];
    let nearest = cell
        .tasks
        .iter()
        .map(|t| (t.position - robot.base.translation).length())
        .fold(f64::INFINITY, f64::min);
    let mut why = std::collections::BTreeMap::<Rejection, usize>::new();
    for t in &cell.tasks {
        if let Some(r) = table.get(t.id, robot.id).reason() {
            *why.entry(r).or_default() += 1;
        }
    }
    let why: Vec<String> = why
        .iter()
        .rev()
        .map(|(r, n)| format!("{n} × {}", r.text()))
        .collect();
    let unit = cell.units.length.to_m();
    let unit_name = if unit == 1.0 { "m" } else { "mm" };
    format!(
        "{}; the nearest task is {:.0} {unit_name} away and its reach is at most {:.0} {unit_name}",
        why.join(", "),
        nearest / unit,
        robot.reach / unit,
    )
}

/// Δt: the latest end less the earliest among `working`, the ends of the robots that can do
/// some task (those [`idle_robots`] does not list; a robot that can do a task but was given
/// none counts, at its end). 0 without any.
pub fn balance_spread(working: impl Iterator<Item = f64> + Clone) -> f64 {
    let hi = working.clone().fold(f64::NEG_INFINITY, f64::max);
    let lo = working.fold(f64::INFINITY, f64::min);
    if hi.is_finite() && lo.is_finite() {
        (hi - lo).max(0.0)
    } else {
        0.0
    }
}

/// A cell none of whose robots can do any task is a mistake in the cell, not a result: the
/// error points at the first robot's base. (A robot that can do none while others can is
/// planned idle at home, and `check` and `plan` say so: a task file may hold only some of the
/// part's tasks.)
pub fn idle_robot_error(cell: &Cell, table: &CandidateTable) -> Option<InputError> {
    let idle = idle_robots(cell, table);
    if idle.len() < cell.robots.len() || cell.tasks.is_empty() {
        return None;
    }
    let robot = &cell.robots[idle.first()?.0];
    Some(
        cell.error_at_robot_base(
            robot.id,
            format!(
                "no robot can do any of the {} tasks: robot `{}` can do none from this base ({})",
                cell.tasks.len(),
                robot.name,
                idle_reason(cell, table, robot.id),
            ),
        )
        .hint("move the robots' `base` towards the part (or check the tasks' positions and units)"),
    )
}

/// Task caps that cannot hold every task some robot can do are a mistake in the cell: the same
/// test `plan` makes (an assignment of every doable task within the caps), so `check` and `plan`
/// agree on what they refuse.
pub fn cap_error(cell: &Cell, table: &CandidateTable) -> Option<InputError> {
    let doable: Vec<TaskId> = cell
        .tasks
        .iter()
        .map(|t| t.id)
        .filter(|&t| !table.robots_for(t).is_empty())
        .collect();
    let cap = cell.planning.task_cap;
    let caps = vec![cap; cell.robots.len()];
    let stuck = cellplan_solve::minmax::assign_within_caps(doable.len(), &caps, |r, k| {
        !table.get(doable[k], RobotId(r)).candidates.is_empty()
    })
    .err()?;
    Some(
        InputError::new(
            &cell.path,
            format!(
                "with task_cap = {cap}, the robots cannot take every task they can do: task `{}` finds no robot with room",
                cell.tasks[doable[stuck].0].name
            ),
        )
        .hint("raise `task_cap` in the [planning] table, or add a robot that can reach those tasks"),
    )
}

/// A robot that can do more tasks than one robot's move-time graph holds
/// ([`crate::plan::graph::MAX_GRAPH_NODES`]): refused before any memory is spent on it.
pub fn graph_size_error(cell: &Cell, table: &CandidateTable) -> Option<InputError> {
    let limit = crate::plan::graph::MAX_GRAPH_NODES - 1;
    let (robot, n) = cell
        .robots
        .iter()
        .map(|r| {
            let n = cell
                .tasks
                .iter()
                .filter(|t| !table.get(t.id, r.id).candidates.is_empty())
                .count();
            (r, n)
        })
        .find(|(_, n)| *n > limit)?;
    Some(
        InputError::new(
            &cell.path,
            format!(
                "robot `{}` can do {n} of the cell's {} tasks; cellplan plans at most {limit} tasks a robot can do (its move-time graph is dense)",
                robot.name,
                cell.tasks.len()
            ),
        )
        .hint("split the task list into several runs, or add robots so that each can do fewer tasks"),
    )
}

/// The report as a table for people.
pub fn render_text(cell: &Cell, table: &CandidateTable, r: &CheckReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "cell `{}`: {} robots, {} tasks, {} candidates",
        r.cell,
        r.robots.len(),
        r.tasks,
        r.total_candidates
    );
    // Which inverse kinematics each robot got, grouped (a closed form read off the URDF is worth
    // knowing: the numeric solver is slower and may miss branches).
    let mut kinds: Vec<(IkKind, Vec<&str>)> = Vec::new();
    for (name, &kind) in r.robots.iter().zip(&r.ik) {
        match kinds.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, names)) => names.push(name),
            None => kinds.push((kind, vec![name])),
        }
    }
    for (kind, names) in kinds {
        let what = match kind {
            IkKind::Opw => "closed form (OPW, the parameters given)",
            IkKind::OpwDerived => "closed form (OPW, read off the URDF)",
            IkKind::Parallel => "closed form (three parallel axes, read off the URDF)",
            IkKind::Track => "track positions sampled, the arm's closed form (OPW, read off the URDF)",
            IkKind::Numeric => "numeric (damped least squares from several starts)",
        };
        let _ = writeln!(s, "inverse kinematics {what}: {}", names.join(", "));
    }
    let width = cell.tasks.iter().map(|t| t.name.len()).max().unwrap_or(4).max(4);
    let cols: Vec<usize> = r.robots.iter().map(|n| n.len().max(5)).collect();
    let _ = write!(s, "\n{:<width$}", "task");
    for (n, w) in r.robots.iter().zip(&cols) {
        let _ = write!(s, "  {n:>w$}");
    }
    let _ = writeln!(s, "  class");
    for t in &cell.tasks {
        let _ = write!(s, "{:<width$}", t.name);
        for (rb, w) in cell.robots.iter().zip(&cols) {
            let reach = table.get(t.id, rb.id);
            let cellv = if reach.candidates.is_empty() {
                "-".to_string()
            } else {
                reach.candidates.len().to_string()
            };
            let _ = write!(s, "  {cellv:>w$}");
        }
        let who: Vec<RobotId> = table.robots_for(t.id);
        let class = match who.len() {
            0 => "UNMEASURABLE".to_string(),
            1 => format!("δ {}", cell.robots[who[0].0].name),
            _ => format!(
                "Q {}",
                who.iter()
                    .map(|r| cell.robots[r.0].name.as_str())
                    .collect::<Vec<_>>()
                    .join("+")
            ),
        };
        let _ = writeln!(s, "  {class}");
    }
    let _ = writeln!(s);
    for (name, tasks) in &r.classes.exclusive {
        let n = tasks.as_array().map_or(0, Vec::len);
        let _ = writeln!(
            s,
            "δ {name}: {n} task{} only it can do",
            if n == 1 { "" } else { "s" }
        );
    }
    for p in &r.classes.pairs {
        let n = p.tasks.len();
        let plural = if n == 1 { "" } else { "s" };
        let _ = writeln!(
            s,
            "Q {}+{}: {n} task{plural} both can do",
            p.robots[0], p.robots[1]
        );
    }
    if r.unmeasurable.is_empty() {
        let _ = writeln!(s, "every task can be done by at least one robot");
    } else {
        let _ = writeln!(s, "\n{} task(s) no robot can do:", r.unmeasurable.len());
        for u in &r.unmeasurable {
            let parts: Vec<String> = u
                .reasons
                .iter()
                .map(|x| format!("{}: {}", x.robot, x.reason))
                .collect();
            let _ = writeln!(s, "  {}  {}", u.task, parts.join(", "));
        }
    }
    for i in &r.idle {
        let _ = writeln!(
            s,
            "robot `{}` can do none of the tasks: it stays at home ({})",
            i.robot, i.reason
        );
    }
    s
}

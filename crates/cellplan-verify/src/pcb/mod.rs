//! The independent check of a PCB-assembly plan (paper 004): every device replayed on one clock
//! from the plan document and the cell alone — nothing of the planner's simulation is used.
//!
//! - every device starts where the cell puts it (a fixed device anywhere within its travel, and
//!   then never moves), each move is straight, lasts exactly its drive's time for its length
//!   (so the speed and acceleration limits hold and the position at every instant is known),
//!   starts where the last one ended, never overlaps another move, and stays within travel;
//! - every component of the cell is placed exactly once; its pick and its placement are the
//!   robot's consecutive events; at the pick the robot and the feeder stand still at the same
//!   point for at least the pick time, the bin holding the component's type; at the placement
//!   the robot and the table stand still for at least the place time with the component landing
//!   at its board position and rotation;
//! - two robots never come closer in X than the safety gap (checked exactly on every piece of
//!   their motion, where the gap is linear or quadratic in time);
//! - the assembly time, each robot's totals and the lower bound are recomputed.
use cellplan_pcb::PcbCell;
use cellplan_pcb::bound::lower_bound;
use cellplan_pcb::cell::Drive;
use cellplan_pcb::document::{DeviceKind, PcbPlan};
use serde::Serialize;
use std::collections::HashMap;

mod replay;
use replay::{Replay, check_device, near, robot_gap};

/// Position tolerance (m).
pub(super) const POS_TOL: f64 = 1e-6;
/// Time tolerance (s).
pub(super) const TIME_TOL: f64 = 1e-6;

/// What went wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PcbViolationKind {
    /// The document does not match the cell (names, counts, settings).
    Format,
    /// A device starts elsewhere than it must.
    Start,
    /// A move that is not a full-drive straight move, overlaps another, or leaves the travel.
    Motion,
    /// A fixed device that moves.
    FixedMoved,
    /// A component not placed, placed twice, or unknown.
    Component,
    /// A bin entry that is wrong, or a pick from a bin not holding the type.
    Bin,
    /// Robot and feeder not together and still during a pick, or too short.
    Pick,
    /// Robot and table not together and still during a placement, wrong place, too short.
    Place,
    /// Picks and placements of a robot out of turn.
    Sequence,
    /// Robots closer than the safety gap.
    RobotRobot,
    /// A stated total that the replay does not reproduce.
    Total,
}

/// One violation.
#[derive(Clone, Debug, Serialize)]
pub struct PcbViolation {
    /// What.
    pub kind: PcbViolationKind,
    /// The device, where it applies.
    pub device: Option<String>,
    /// The component, where it applies.
    pub component: Option<String>,
    /// When, where it applies (s).
    pub time_s: Option<f64>,
    /// A sentence.
    pub detail: String,
}

/// The verdict.
#[derive(Clone, Debug, Serialize)]
pub struct PcbReport {
    /// No violation.
    pub ok: bool,
    /// Every violation.
    pub violations: Vec<PcbViolation>,
    /// Recomputed assembly time (s).
    pub cycle_time_s: f64,
    /// Recomputed lower bound (s).
    pub lower_bound_s: f64,
    /// Smallest X distance between the robots (m; infinite with one robot).
    pub closest_robots_m: f64,
    /// Robot–robot crossings found (counted also when not checked).
    pub crossings: usize,
}

/// Settings.
#[derive(Clone, Copy, Debug)]
pub struct PcbVerifySettings {
    /// Whether robots closer than the gap are violations (off only for plans made with
    /// collision avoidance off, whose crossings are then only counted).
    pub robot_robot: bool,
}

impl Default for PcbVerifySettings {
    fn default() -> Self {
        PcbVerifySettings { robot_robot: true }
    }
}

pub(super) fn v(
    kind: PcbViolationKind,
    device: Option<&str>,
    component: Option<&str>,
    time_s: Option<f64>,
    detail: String,
) -> PcbViolation {
    PcbViolation {
        kind,
        device: device.map(str::to_string),
        component: component.map(str::to_string),
        time_s,
        detail,
    }
}

/// Checks `plan` against `cell` (the cell as loaded; the plan's robots, configuration and
/// motion model choose the variant).
pub fn verify_pcb(cell: &PcbCell, plan: &PcbPlan, settings: &PcbVerifySettings) -> PcbReport {
    let mut out = Vec::new();
    let report = |out: Vec<PcbViolation>, cycle: f64, lb: f64, closest: f64, crossings: usize| PcbReport {
        ok: out.is_empty(),
        violations: out,
        cycle_time_s: cycle,
        lower_bound_s: lb,
        closest_robots_m: closest,
        crossings,
    };
    let n_robots = plan
        .devices
        .iter()
        .filter(|d| d.kind == DeviceKind::Robot)
        .count();
    let cell = match cell.variant(n_robots, plan.configuration, plan.motion) {
        Ok(c) => c,
        Err(e) => {
            out.push(v(
                PcbViolationKind::Format,
                None,
                None,
                None,
                format!("the plan does not fit the cell: {e}"),
            ));
            return report(out, 0.0, 0.0, f64::INFINITY, 0);
        }
    };
    if plan.process != cellplan_pcb::cell::KIND {
        out.push(v(
            PcbViolationKind::Format,
            None,
            None,
            None,
            format!("process `{}` is not `pcb-assembly`", plan.process),
        ));
    }
    if cell.robots.len() == 2 && plan.collision_avoidance != cell.collision_avoidance {
        out.push(v(
            PcbViolationKind::Format,
            None,
            None,
            None,
            format!(
                "the plan says collision avoidance {}, the cell {}",
                if plan.collision_avoidance { "on" } else { "off" },
                if cell.collision_avoidance { "on" } else { "off" }
            ),
        ));
    }
    if plan.cell != cell.name {
        out.push(v(
            PcbViolationKind::Format,
            None,
            None,
            None,
            format!("the plan is for cell `{}`, not `{}`", plan.cell, cell.name),
        ));
    }
    let model = cell.motion;
    // Devices: the cell's robots, both feeders, the table, each once.
    let mut replays: HashMap<&str, Replay> = HashMap::new();
    let mut expected: Vec<(String, DeviceKind, Drive)> = cell
        .robots
        .iter()
        .map(|r| (r.name.clone(), DeviceKind::Robot, r.drive))
        .collect();
    expected.extend(
        cell.feeders
            .iter()
            .map(|f| (f.name.clone(), DeviceKind::Feeder, f.drive)),
    );
    expected.push(("table".into(), DeviceKind::Table, cell.table.drive));
    if plan.devices.len() != expected.len() {
        out.push(v(
            PcbViolationKind::Format,
            None,
            None,
            None,
            format!("{} devices, the cell has {}", plan.devices.len(), expected.len()),
        ));
    }
    for (name, kind, drive) in &expected {
        match plan
            .devices
            .iter()
            .filter(|d| &d.name == name && d.kind == *kind)
            .count()
        {
            1 => {}
            k => {
                out.push(v(
                    PcbViolationKind::Format,
                    Some(name),
                    None,
                    None,
                    format!("device `{name}` appears {k} times"),
                ));
                continue;
            }
        }
        let dev = plan.devices.iter().find(|d| &d.name == name && d.kind == *kind);
        if let Some(dev) = dev {
            check_device(&cell, dev, *drive, &mut out);
            replays.insert(
                dev.name.as_str(),
                Replay {
                    dev,
                    drive: *drive,
                    model,
                },
            );
        }
    }
    // Without every device the replay cannot go on; anything else found so far is reported
    // with the rest.
    if expected
        .iter()
        .any(|(name, _, _)| !replays.contains_key(name.as_str()))
    {
        return report(out, 0.0, 0.0, f64::INFINITY, 0);
    }
    // Bins.
    let mut bin_type: HashMap<(usize, usize), usize> = HashMap::new();
    for b in &plan.bins {
        let Some(f) = cell.feeders.iter().position(|f| f.name == b.feeder) else {
            out.push(v(
                PcbViolationKind::Bin,
                Some(&b.feeder),
                None,
                None,
                "bin of an unknown feeder".into(),
            ));
            continue;
        };
        if b.bin >= cell.feeders[f].bins {
            out.push(v(
                PcbViolationKind::Bin,
                Some(&b.feeder),
                None,
                None,
                format!("bin {} beyond the feeder's {} bins", b.bin, cell.feeders[f].bins),
            ));
            continue;
        }
        let Some(t) = cell
            .types
            .iter()
            .position(|t| t.footprint == b.footprint && t.value == b.value)
        else {
            out.push(v(
                PcbViolationKind::Bin,
                Some(&b.feeder),
                None,
                None,
                format!(
                    "bin {} holds `{}` `{}`, not a placed type",
                    b.bin, b.footprint, b.value
                ),
            ));
            continue;
        };
        if bin_type.insert((f, b.bin), t).is_some() {
            out.push(v(
                PcbViolationKind::Bin,
                Some(&b.feeder),
                None,
                None,
                format!("bin {} listed twice", b.bin),
            ));
        }
        if let Some(g) = cell.given_bins.iter().find(|g| g.feeder == f && g.slot == b.bin)
            && g.kind != t
        {
            out.push(v(
                PcbViolationKind::Bin,
                Some(&b.feeder),
                None,
                None,
                format!("bin {} holds another type than the cell gives it", b.bin),
            ));
        }
    }
    if !cell.given_bins.is_empty() {
        let given: std::collections::HashSet<(usize, usize, usize)> = cell
            .given_bins
            .iter()
            .map(|g| (g.feeder, g.slot, g.kind))
            .collect();
        let stated: std::collections::HashSet<(usize, usize, usize)> =
            bin_type.iter().map(|(&(f, b), &t)| (f, b, t)).collect();
        if given != stated {
            out.push(v(
                PcbViolationKind::Bin,
                None,
                None,
                None,
                format!(
                    "the plan's bins ({}) are not the {} the cell gives",
                    stated.len(),
                    given.len()
                ),
            ));
        }
    }
    // Placements.
    let mut placed: HashMap<&str, usize> = HashMap::new();
    let mut events: HashMap<&str, Vec<(f64, f64, bool, &str)>> = HashMap::new();
    let mut end = 0.0f64;
    for p in &plan.placements {
        let who = Some(p.component.as_str());
        let Some(c) = cell.components.iter().position(|c| c.reference == p.component) else {
            out.push(v(
                PcbViolationKind::Component,
                Some(&p.robot),
                who,
                None,
                "not a component this cell places".into(),
            ));
            continue;
        };
        *placed.entry(cell.components[c].reference.as_str()).or_default() += 1;
        let Some(r) = cell.robots.iter().position(|r| r.name == p.robot) else {
            out.push(v(
                PcbViolationKind::Format,
                Some(&p.robot),
                who,
                None,
                "unknown robot".into(),
            ));
            continue;
        };
        let Some(f) = cell.feeders.iter().position(|f| f.name == p.feeder) else {
            out.push(v(
                PcbViolationKind::Format,
                Some(&p.feeder),
                who,
                None,
                "unknown feeder".into(),
            ));
            continue;
        };
        if !cell.feeders_of(r).contains(&f) {
            out.push(v(
                PcbViolationKind::Pick,
                Some(&p.robot),
                who,
                Some(p.pick.t[0]),
                format!("picks from {}, which it does not serve", p.feeder),
            ));
        }
        if bin_type.get(&(f, p.bin)) != Some(&cell.type_of[c]) {
            out.push(v(
                PcbViolationKind::Bin,
                Some(&p.feeder),
                who,
                Some(p.pick.t[0]),
                format!("bin {} does not hold the component's type", p.bin),
            ));
        }
        let robot = &replays[p.robot.as_str()];
        let feeder = &replays[p.feeder.as_str()];
        let table = &replays["table"];
        let fd = &cell.feeders[f];
        if p.pick.t[0] < -TIME_TOL || p.place.t[0] < -TIME_TOL {
            out.push(v(
                PcbViolationKind::Sequence,
                Some(&p.robot),
                who,
                Some(p.pick.t[0].min(p.place.t[0])),
                "an event before time 0".into(),
            ));
        }
        // The pick.
        if p.pick.t[1] - p.pick.t[0] < cell.pick_time - TIME_TOL || !p.pick.t.iter().all(|t| t.is_finite()) {
            out.push(v(
                PcbViolationKind::Pick,
                Some(&p.robot),
                who,
                Some(p.pick.t[0]),
                format!(
                    "pick lasts {:.4} s, less than the pick time {:.4} s",
                    p.pick.t[1] - p.pick.t[0],
                    cell.pick_time
                ),
            ));
        }
        let bin_point = [fd.x, p.pick.device[1] + p.bin as f64 * fd.pitch];
        if !near(p.pick.device, [fd.x, p.pick.device[1]]) || !near(p.pick.point, bin_point) {
            out.push(v(
                PcbViolationKind::Pick,
                Some(&p.robot),
                who,
                Some(p.pick.t[0]),
                "the pick point is not the bin's position on the feeder".into(),
            ));
        }
        if !robot.still_at(p.pick.t[0], p.pick.t[1], p.pick.point) {
            out.push(v(
                PcbViolationKind::Pick,
                Some(&p.robot),
                who,
                Some(p.pick.t[0]),
                format!(
                    "the robot is not standing at the pick point (it is at {:?})",
                    robot.at(p.pick.t[0])
                ),
            ));
        }
        if !feeder.still_at(p.pick.t[0], p.pick.t[1], p.pick.device) {
            out.push(v(
                PcbViolationKind::Pick,
                Some(&p.feeder),
                who,
                Some(p.pick.t[0]),
                format!(
                    "the feeder is not standing at carriage {:.4} m (it is at {:.4} m)",
                    p.pick.device[1],
                    feeder.at(p.pick.t[0])[1]
                ),
            ));
        }
        // The placement.
        if p.place.t[1] - p.place.t[0] < cell.place_time - TIME_TOL
            || !p.place.t.iter().all(|t| t.is_finite())
        {
            out.push(v(
                PcbViolationKind::Place,
                Some(&p.robot),
                who,
                Some(p.place.t[0]),
                format!(
                    "placement lasts {:.4} s, less than the place time {:.4} s",
                    p.place.t[1] - p.place.t[0],
                    cell.place_time
                ),
            ));
        }
        let b = cell.components[c].position;
        if !near(
            p.place.point,
            [p.place.device[0] + b[0], p.place.device[1] + b[1]],
        ) {
            out.push(v(
                PcbViolationKind::Place,
                Some(&p.robot),
                who,
                Some(p.place.t[0]),
                "the component would not land at its board position".into(),
            ));
        }
        let rot_err = (p.rotation_rad - cell.components[c].rotation).rem_euclid(std::f64::consts::TAU);
        if rot_err.min(std::f64::consts::TAU - rot_err) > 1e-9 {
            out.push(v(
                PcbViolationKind::Place,
                Some(&p.robot),
                who,
                Some(p.place.t[0]),
                format!(
                    "rotation {:.6} rad, the board says {:.6}",
                    p.rotation_rad, cell.components[c].rotation
                ),
            ));
        }
        if !robot.still_at(p.place.t[0], p.place.t[1], p.place.point) {
            out.push(v(
                PcbViolationKind::Place,
                Some(&p.robot),
                who,
                Some(p.place.t[0]),
                "the robot is not standing at the place point".into(),
            ));
        }
        if !table.still_at(p.place.t[0], p.place.t[1], p.place.device) {
            out.push(v(
                PcbViolationKind::Place,
                Some("table"),
                who,
                Some(p.place.t[0]),
                "the table is not standing at the placement's position".into(),
            ));
        }
        if p.place.t[0] < p.pick.t[1] - TIME_TOL {
            out.push(v(
                PcbViolationKind::Sequence,
                Some(&p.robot),
                who,
                Some(p.place.t[0]),
                "placed before it was picked".into(),
            ));
        }
        let list = events.entry(robot.dev.name.as_str()).or_default();
        list.push((
            p.pick.t[0],
            p.pick.t[1],
            true,
            cell.components[c].reference.as_str(),
        ));
        list.push((
            p.place.t[0],
            p.place.t[1],
            false,
            cell.components[c].reference.as_str(),
        ));
        end = end.max(p.place.t[1]);
    }
    for comp in &cell.components {
        match placed.get(comp.reference.as_str()).copied().unwrap_or(0) {
            1 => {}
            0 => out.push(v(
                PcbViolationKind::Component,
                None,
                Some(&comp.reference),
                None,
                "never placed".into(),
            )),
            k => out.push(v(
                PcbViolationKind::Component,
                None,
                Some(&comp.reference),
                None,
                format!("placed {k} times"),
            )),
        }
    }
    // One placement at a time (paper 004 §2.1.2: the components are placed one after the other,
    // on the one table).
    let mut places: Vec<(f64, f64, &str)> = plan
        .placements
        .iter()
        .map(|p| (p.place.t[0], p.place.t[1], p.component.as_str()))
        .collect();
    places.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in places.windows(2) {
        if w[1].0 < w[0].1 - TIME_TOL {
            out.push(v(
                PcbViolationKind::Place,
                None,
                Some(w[1].2),
                Some(w[1].0),
                format!(
                    "placed while {} is still being placed (one placement at a time)",
                    w[0].2
                ),
            ));
            break;
        }
    }
    // One nozzle: each robot's events alternate pick, place of the same component.
    for (robot, list) in &mut events {
        list.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.2.cmp(&a.2)));
        for (k, e) in list.iter().enumerate() {
            let want_pick = k % 2 == 0;
            let ok = e.2 == want_pick
                && (want_pick || list[k - 1].3 == e.3)
                && (k == 0 || e.0 >= list[k - 1].1 - TIME_TOL);
            if !ok {
                out.push(v(
                    PcbViolationKind::Sequence,
                    Some(robot),
                    Some(e.3),
                    Some(e.0),
                    "picks and placements not alternating for one component at a time".into(),
                ));
                break;
            }
        }
    }
    // Robots apart.
    let (closest, crossings) = if cell.robots.len() == 2 {
        let a = &replays[cell.robots[0].name.as_str()];
        let b = &replays[cell.robots[1].name.as_str()];
        robot_gap(a, b, cell.safety_gap)
    } else {
        (f64::INFINITY, 0)
    };
    if crossings > 0 && settings.robot_robot {
        out.push(v(
            PcbViolationKind::RobotRobot,
            Some(&cell.robots[0].name),
            None,
            None,
            format!(
                "{crossings} time(s) closer than the safety gap {:.4} m (closest {:.4} m)",
                cell.safety_gap, closest
            ),
        ));
    }
    // Totals.
    let lb = lower_bound(&cell);
    if (plan.cycle_time_s - end).abs() > TIME_TOL {
        out.push(v(
            PcbViolationKind::Total,
            None,
            None,
            None,
            format!(
                "assembly time stated {:.6} s, replayed {:.6} s",
                plan.cycle_time_s, end
            ),
        ));
    }
    if (plan.lower_bound_s - lb).abs() > 1e-9 * lb.max(1.0) {
        out.push(v(
            PcbViolationKind::Total,
            None,
            None,
            None,
            format!(
                "lower bound stated {:.6} s, recomputed {:.6} s",
                plan.lower_bound_s, lb
            ),
        ));
    }
    if lb > end + TIME_TOL && out.is_empty() {
        out.push(v(
            PcbViolationKind::Total,
            None,
            None,
            None,
            format!("the lower bound {lb:.6} s exceeds the assembly time {end:.6} s"),
        ));
    }
    for r in &cell.robots {
        let Some(stated) = plan.robots.iter().find(|s| s.name == r.name) else {
            out.push(v(
                PcbViolationKind::Total,
                Some(&r.name),
                None,
                None,
                "no totals for this robot".into(),
            ));
            continue;
        };
        let list = events.get(r.name.as_str());
        let comps = list.map_or(0, |l| l.len() / 2);
        let work: f64 = list.map_or(0.0, |l| l.iter().map(|e| e.1 - e.0).sum());
        let last = list.map_or(0.0, |l| l.iter().map(|e| e.1).fold(0.0, f64::max));
        let dev = replays[r.name.as_str()].dev;
        let motion: f64 = dev
            .moves
            .iter()
            .map(|m| (m.t[1].min(last) - m.t[0].min(last)).max(0.0))
            .sum();
        let wait = (last - motion - work).max(0.0);
        let bad = stated.components != comps
            || (stated.total_s - last).abs() > TIME_TOL
            || (stated.motion_s - motion).abs() > TIME_TOL
            || (stated.working_s - work).abs() > TIME_TOL
            || (stated.waiting_s - wait).abs() > TIME_TOL;
        if bad {
            out.push(v(PcbViolationKind::Total, Some(&r.name), None, None, format!(
                "totals stated {} components, {:.4} s total, {:.4} s moving, {:.4} s working, {:.4} s waiting; replayed {comps}, {last:.4}, {motion:.4}, {work:.4}, {wait:.4}",
                stated.components, stated.total_s, stated.motion_s, stated.working_s, stated.waiting_s
            )));
        }
    }
    if plan.robots.len() != cell.robots.len() {
        out.push(v(
            PcbViolationKind::Total,
            None,
            None,
            None,
            format!(
                "totals for {} robots, the plan has {}",
                plan.robots.len(),
                cell.robots.len()
            ),
        ));
    }
    report(out, end, lb, closest, crossings)
}

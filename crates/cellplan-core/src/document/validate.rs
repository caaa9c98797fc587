//! The document checked at the edge, before `verify`, `report` or `export` walk it: the layout
//! and version, every count and length consistent (joint counts, waypoint and sample lengths,
//! indices in range), times increasing, and every number within physical magnitudes, so that
//! nothing downstream can index out of range or run for hours on an edited file.
use super::{ActivityOut, FORMAT, Plan, RobotPlan, VERSION};
use cellplan_geom::read::{LimitedReadError, read_limited, show_bytes};
use cellplan_model::Cell;
use std::path::Path;

/// Largest plan file read (bytes).
pub const MAX_PLAN_BYTES: u64 = 256 << 20;
/// Largest time a plan may state (s): 10 days.
pub const MAX_TIME_S: f64 = 864_000.0;
/// Largest joint value (rad or m).
pub const MAX_JOINT: f64 = 1e3;
/// Largest coordinate (m), as for tasks.
pub const MAX_COORDINATE: f64 = cellplan_model::tasks::MAX_COORDINATE;
/// Most joints of a robot.
pub const MAX_JOINTS: usize = 64;

/// Why a plan document is refused.
#[derive(Debug, thiserror::Error)]
pub enum DocumentError {
    /// The file could not be read.
    #[error("cannot read the plan: {0}")]
    Read(#[source] std::io::Error),
    /// The file is too large.
    #[error("the plan is {size}, larger than {}", show_bytes(MAX_PLAN_BYTES))]
    TooLarge {
        /// The size found.
        size: String,
    },
    /// Not JSON of the document's layout.
    #[error("not a cellplan plan: {source}")]
    Json {
        /// The parser's error (with its line).
        #[source]
        source: serde_json::Error,
    },
    /// Another format or version.
    #[error("a `{format}` document of version {version}; this cellplan reads `{FORMAT}` version {VERSION}")]
    Version {
        /// The `format` found.
        format: String,
        /// The `version` found.
        version: u32,
    },
    /// A value out of place.
    #[error("{at}: {what}")]
    Invalid {
        /// Where in the document (`robots[1] (R2) trajectory[37]`).
        at: String,
        /// What is wrong.
        what: String,
    },
}

impl DocumentError {
    /// The line of the file, where the error has one.
    pub fn line(&self) -> Option<usize> {
        match self {
            DocumentError::Json { source } => Some(source.line()),
            _ => None,
        }
    }
}

/// Reads and [`validate`]s a plan document.
pub fn read(path: &Path) -> Result<Plan, DocumentError> {
    let bytes = read_limited(path, MAX_PLAN_BYTES).map_err(|e| match e {
        LimitedReadError::Io(e) => DocumentError::Read(e),
        LimitedReadError::TooLarge { size } => DocumentError::TooLarge { size },
    })?;
    match serde_json::from_slice::<Plan>(&bytes) {
        Ok(plan) => validate(&plan).map(|()| plan),
        // Not this layout: an old document gets the version answer, anything else the parser's.
        Err(source) => Err(other_version(&bytes).unwrap_or(DocumentError::Json { source })),
    }
}

/// The version error, when the bytes are a document of another format or version.
fn other_version(bytes: &[u8]) -> Option<DocumentError> {
    #[derive(serde::Deserialize)]
    struct Header {
        format: Option<String>,
        version: Option<u32>,
    }
    let h = serde_json::from_slice::<Header>(bytes).ok()?;
    (h.format.as_deref() != Some(FORMAT) || h.version != Some(VERSION)).then(|| DocumentError::Version {
        format: h.format.unwrap_or_default(),
        version: h.version.unwrap_or(0),
    })
}

fn invalid(at: impl Into<String>, what: impl Into<String>) -> DocumentError {
    DocumentError::Invalid {
        at: at.into(),
        what: what.into(),
    }
}

/// A time: finite, in [0, [`MAX_TIME_S`]].
fn time(at: &dyn Fn() -> String, key: &str, v: f64) -> Result<(), DocumentError> {
    if v.is_finite() && (0.0..=MAX_TIME_S).contains(&v) {
        Ok(())
    } else {
        Err(invalid(
            at(),
            format!(
                "`{key}` is {}; times lie between 0 and {MAX_TIME_S} s",
                cellplan_model::shown(v)
            ),
        ))
    }
}

/// A length of `dof` joint values, each within [`MAX_JOINT`].
fn joints(at: &dyn Fn() -> String, key: &str, q: &[f64], dof: usize) -> Result<(), DocumentError> {
    if q.len() != dof {
        return Err(invalid(
            at(),
            format!("`{key}` has {} values for {dof} joints", q.len()),
        ));
    }
    match q.iter().find(|x| !(x.is_finite() && x.abs() <= MAX_JOINT)) {
        Some(x) => Err(invalid(
            at(),
            format!("`{key}` holds {x}; joint values lie within ±{MAX_JOINT}"),
        )),
        None => Ok(()),
    }
}

/// A position within [`MAX_COORDINATE`].
fn position(at: &dyn Fn() -> String, key: &str, p: &[f64; 3]) -> Result<(), DocumentError> {
    if p.iter().all(|x| x.is_finite() && x.abs() <= MAX_COORDINATE) {
        Ok(())
    } else {
        Err(invalid(
            at(),
            format!("`{key}` is {p:?}; coordinates lie within ±{MAX_COORDINATE} m"),
        ))
    }
}

/// Checks sizes, indices, orders and magnitudes (see the module).
pub fn validate(plan: &Plan) -> Result<(), DocumentError> {
    if plan.format != FORMAT || plan.version != VERSION {
        return Err(DocumentError::Version {
            format: plan.format.clone(),
            version: plan.version,
        });
    }
    validate_top(plan)?;
    for (i, rp) in plan.robots.iter().enumerate() {
        validate_robot(i, rp)?;
    }
    validate_coordination(plan)
}

/// The top-level figures and settings.
fn validate_top(plan: &Plan) -> Result<(), DocumentError> {
    let top = || "the plan".to_string();
    for (key, v) in [
        ("cycle_time_s", plan.cycle_time_s),
        ("delta_t_s", plan.delta_t_s),
        ("lower_bound_s", plan.lower_bound_s),
        (
            "coordination.uncoordinated_cycle_time_s",
            plan.coordination.uncoordinated_cycle_time_s,
        ),
    ] {
        time(&top, key, v)?;
    }
    if let Some(v) = plan.settings.time_limit_s {
        time(&top, "settings.time_limit_s", v)?;
    }
    if !(plan.ratio_to_lower_bound.is_finite() && plan.ratio_to_lower_bound >= 0.0) {
        return Err(invalid(top(), "`ratio_to_lower_bound` is not a finite ratio"));
    }
    let s = &plan.settings;
    if !(s.sample_dt_s.is_finite() && (1e-4..=10.0).contains(&s.sample_dt_s)) {
        return Err(invalid(
            top(),
            format!(
                "`settings.sample_dt_s` is {}; it lies between 0.0001 and 10 s",
                s.sample_dt_s
            ),
        ));
    }
    for (key, v) in [
        ("settings.clearance_m", s.clearance_m),
        ("settings.local_set_radius_m", s.local_set_radius_m),
        ("settings.roomy_m", s.roomy_m),
    ] {
        if !(v.is_finite() && (0.0..=MAX_COORDINATE).contains(&v)) {
            return Err(invalid(top(), format!("`{key}` is {v}")));
        }
    }
    if let Some(g) = s.balance_limit_s {
        time(&top, "settings.balance_limit_s", g)?;
    }
    Ok(())
}

/// One robot: joint counts, lengths, indices, increasing times, magnitudes.
fn validate_robot(i: usize, rp: &RobotPlan) -> Result<(), DocumentError> {
    let here = || format!("robots[{i}] ({})", rp.name);
    let dof = rp.joints.len();
    if dof == 0 || dof > MAX_JOINTS {
        return Err(invalid(
            here(),
            format!("{dof} joints; a robot has 1 to {MAX_JOINTS}"),
        ));
    }
    joints(&here, "home", &rp.home, dof)?;
    for (key, v) in [
        ("start_s", rp.start_s),
        ("end_s", rp.end_s),
        ("motion_s", rp.motion_s),
        ("measuring_s", rp.measuring_s),
        ("waiting_s", rp.waiting_s),
        ("total_s", rp.total_s),
    ] {
        time(&here, key, v)?;
    }
    for (k, v) in rp.tasks.iter().enumerate() {
        let at = || format!("{} tasks[{k}] ({})", here(), v.task);
        joints(&at, "q", &v.q, dof)?;
        position(&at, "tcp.xyz", &v.tcp.xyz)?;
        let norm = v.tcp.quat.iter().map(|x| x * x).sum::<f64>().sqrt();
        if (norm - 1.0).abs().is_nan() || (norm - 1.0).abs() > 1e-6 {
            return Err(invalid(at(), format!("`tcp.quat` has norm {norm}, not 1")));
        }
        time(&at, "arrive_s", v.arrive_s)?;
        time(&at, "depart_s", v.depart_s)?;
        if v.depart_s < v.arrive_s {
            return Err(invalid(at(), "departs before it arrives"));
        }
        if let Some((key, x)) = v.figures.iter().find(|(_, x)| !x.is_finite()) {
            return Err(invalid(at(), format!("`{key}` is {x}")));
        }
        if let Some(p) = v.perturbation_rad
            && !p.iter().all(|x| x.is_finite() && x.abs() <= std::f64::consts::PI)
        {
            return Err(invalid(
                at(),
                format!("`perturbation_rad` is {p:?}; each lies within ±π"),
            ));
        }
    }
    validate_legs(&here, rp, dof)?;
    validate_waits(&here, rp)?;
    validate_trajectory(&here, rp, dof)
}

/// The legs: waypoints of the robot's joint count, times in range.
fn validate_legs(here: &dyn Fn() -> String, rp: &RobotPlan, dof: usize) -> Result<(), DocumentError> {
    for (k, leg) in rp.legs.iter().enumerate() {
        let at = || format!("{} legs[{k}]", here());
        time(&at, "start_s", leg.start_s)?;
        time(&at, "duration_s", leg.duration_s)?;
        if leg.waypoints.is_empty() {
            return Err(invalid(at(), "a leg without waypoints"));
        }
        for (w, q) in leg.waypoints.iter().enumerate() {
            joints(&at, &format!("waypoints[{w}]"), q, dof)?;
        }
        let mut previous = 0;
        for (b, blend) in leg.blends.iter().enumerate() {
            if blend.waypoint <= previous || blend.waypoint + 1 >= leg.waypoints.len() {
                return Err(invalid(
                    at(),
                    format!(
                        "blends[{b}] is at waypoint {} of a leg of {}: blends are at interior waypoints, in order",
                        blend.waypoint,
                        leg.waypoints.len()
                    ),
                ));
            }
            if !(blend.radius.is_finite() && blend.radius > 0.0 && blend.radius <= 1_000.0) {
                return Err(invalid(
                    at(),
                    format!("blends[{b}].radius is {}; it lies in (0, 1000]", blend.radius),
                ));
            }
            previous = blend.waypoint;
        }
    }
    Ok(())
}

/// The waits: at existing waypoints, in program order, times in range.
fn validate_waits(here: &dyn Fn() -> String, rp: &RobotPlan) -> Result<(), DocumentError> {
    let mut previous: Option<(usize, usize)> = None;
    for (k, w) in rp.waits.iter().enumerate() {
        let at = || format!("{} waits[{k}]", here());
        time(&at, "start_s", w.start_s)?;
        time(&at, "duration_s", w.duration_s)?;
        let Some(leg) = rp.legs.get(w.leg) else {
            return Err(invalid(at(), format!("leg {} does not exist", w.leg)));
        };
        if w.waypoint >= leg.waypoints.len() {
            return Err(invalid(
                at(),
                format!("waypoint {} of a leg of {}", w.waypoint, leg.waypoints.len()),
            ));
        }
        if previous.is_some_and(|p| p >= (w.leg, w.waypoint)) {
            return Err(invalid(at(), "waits are not in program order (one per waypoint)"));
        }
        previous = Some((w.leg, w.waypoint));
    }
    Ok(())
}

/// The trajectory: samples of the robot's joint count at increasing times.
fn validate_trajectory(here: &dyn Fn() -> String, rp: &RobotPlan, dof: usize) -> Result<(), DocumentError> {
    let mut last = f64::NEG_INFINITY;
    for (k, s) in rp.trajectory.iter().enumerate() {
        let at = || format!("{} trajectory[{k}]", here());
        time(&at, "t", s.t)?;
        if s.t <= last {
            return Err(invalid(
                at(),
                format!("time {} s is not after the sample before ({last} s)", s.t),
            ));
        }
        last = s.t;
        joints(&at, "q", &s.q, dof)?;
    }
    Ok(())
}

/// The coordination record: robots named, legs in range, magnitudes.
fn validate_coordination(plan: &Plan) -> Result<(), DocumentError> {
    let c = &plan.coordination;
    let robot = |name: &str| plan.robots.iter().find(|r| r.name == name);
    for (list, key) in [
        (&c.conflicts_before, "conflicts_before"),
        (&c.conflicts_after, "conflicts_after"),
    ] {
        for (k, x) in list.iter().enumerate() {
            let at = || format!("coordination.{key}[{k}]");
            time(&at, "start_s", x.start_s)?;
            time(&at, "end_s", x.end_s)?;
            for side in 0..2 {
                position(&at, "probe_xyz", &x.probe_xyz[side])?;
                let Some(rp) = robot(&x.robots[side]) else {
                    return Err(invalid(
                        at(),
                        format!("no robot `{}` in the plan", x.robots[side]),
                    ));
                };
                let leg = match &x.activity[side] {
                    ActivityOut::Moving { leg, .. } | ActivityOut::Waiting { leg, .. } => Some(*leg),
                    ActivityOut::Working { .. } => None,
                };
                if leg.is_some_and(|l| l >= rp.legs.len()) {
                    return Err(invalid(at(), format!("names a leg {} has not", rp.name)));
                }
            }
        }
    }
    for (k, track) in c.uncoordinated_probe.iter().enumerate() {
        let at = || format!("coordination.uncoordinated_probe[{k}]");
        if !(track.dt_s.is_finite() && (1e-3..=10.0).contains(&track.dt_s)) {
            return Err(invalid(at(), format!("`dt_s` is {}", track.dt_s)));
        }
        if track.xyz.len() as f64 > MAX_TIME_S / track.dt_s + 2.0 {
            return Err(invalid(at(), "more samples than the longest plan has"));
        }
        for p in &track.xyz {
            position(&at, "xyz", p)?;
        }
    }
    Ok(())
}

/// Whether the plan's robots are robots of `cell` with the same joints (in the same order),
/// as the report and the exports assume.
pub fn matches_cell(plan: &Plan, cell: &Cell) -> Result<(), DocumentError> {
    for (i, rp) in plan.robots.iter().enumerate() {
        let at = || format!("robots[{i}] ({})", rp.name);
        let Some(robot) = cell.robots.iter().find(|r| r.name == rp.name) else {
            return Err(invalid(
                at(),
                format!("the cell `{}` has no such robot", cell.name),
            ));
        };
        let names = robot.joint_names();
        if rp.joints.iter().map(String::as_str).ne(names.iter().copied()) {
            return Err(invalid(
                at(),
                format!("joints {:?}, but the cell's robot has {names:?}", rp.joints),
            ));
        }
    }
    Ok(())
}

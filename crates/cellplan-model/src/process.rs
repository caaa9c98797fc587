//! The process interface: what differs between the systems cellplan hosts (optical inspection,
//! weld sequencing, CMM inspection, PCB assembly), and the registry that finds a process by the
//! cell file's `[process] kind`.
//!
//! Everything else — robots, scene, collision, candidate tables, move-time graphs, solvers, legs,
//! timing, the common clock, coordination, the plan document, motion verification, the report
//! frame — is generic and lives once in the core, which never names a process. A process crate
//! implements [`Process`] and offers a [`ProcessEntry`]; the binary puts the entries into a
//! [`Registry`] and hands it to [`crate::load()`].
use crate::InputError;
use crate::robot::Robot;
use crate::tasks::{Task, TaskId};
use cellplan_geom::{CollisionWorld, Pose};
use serde::de::DeserializeOwned;
use std::fmt;
use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

/// A process's own reason for refusing a way of doing a task (for example the optical probe's
/// "view angle beyond θ0"). Reasons of one stage are ordered by `rank`: the higher, the further
/// the attempt got.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ProcessReason {
    /// Order among the process's reasons of the same stage (higher: got further).
    pub rank: u8,
    /// Stable short name, as in JSON (`view-angle`).
    pub code: &'static str,
    /// What it means, for people.
    pub text: &'static str,
}

/// Why a sampled tool pose yielded no candidate; ordered by how far it got.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Rejection {
    /// The process refused the tool pose itself (before any inverse kinematics).
    Pose(ProcessReason),
    /// No inverse-kinematics solution: out of reach.
    NoIk,
    /// Solutions exist but none within the joint limits.
    JointLimits,
    /// The process refused the pose once the robot reaches it (for example an occluded beam).
    Reached(ProcessReason),
    /// Every configuration hits the scene, the robot itself or a parked robot.
    Collision,
}

impl Rejection {
    /// Stable short name (as in JSON).
    pub fn code(self) -> &'static str {
        match self {
            Rejection::Pose(r) | Rejection::Reached(r) => r.code,
            Rejection::NoIk => "no-ik",
            Rejection::JointLimits => "joint-limits",
            Rejection::Collision => "collision",
        }
    }

    /// What it means, for people.
    pub fn text(self) -> &'static str {
        match self {
            Rejection::Pose(r) | Rejection::Reached(r) => r.text,
            Rejection::NoIk => "out of reach (no IK solution)",
            Rejection::JointLimits => "only outside the joint limits",
            Rejection::Collision => "every pose collides",
        }
    }
}

/// The work a machine does at a task, once it stands in the task's pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Work {
    /// Standing still for a time (a measurement, a weld): seconds.
    Dwell(f64),
}

impl Work {
    /// How long the work takes (s).
    pub fn duration(self) -> f64 {
        match self {
            Work::Dwell(s) => s,
        }
    }
}

/// A constraint between two tasks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Relation {
    /// The first task must be finished before the second starts.
    Precedes(TaskId, TaskId),
    /// Both tasks must be done by the same machine, one right after the other.
    Paired(TaskId, TaskId),
}

/// A process's words for reports and messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Words {
    /// One task ("MP").
    pub task: &'static str,
    /// Several tasks ("MPs").
    pub tasks: &'static str,
    /// Doing the work, as an activity ("measuring").
    pub working: &'static str,
    /// What the TCP is ("probe").
    pub tool: &'static str,
}

/// A figure a process states about one visit (for example the view angle), recomputed by the
/// verifier from the task and the tool pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figure {
    /// Key in the plan document (with its unit: `view_angle_rad`).
    pub key: &'static str,
    /// Value (SI).
    pub value: f64,
}

/// What a process is: its parameters, how a task becomes tool poses and which of them it
/// accepts, the work done at a task, the relations between tasks, its own strategies' hooks,
/// its checks for the verifier, and its words.
///
/// The core finds the candidates of a task as: [`tool_poses`](Process::tool_poses) →
/// [`pose_check`](Process::pose_check) → inverse kinematics and joint limits →
/// [`reached_check`](Process::reached_check) once per pose → per configuration
/// [`arm_check`](Process::arm_check), then collision with the scene, the robot itself and the
/// parked robots. The verifier repeats the checks on the plan's poses.
pub trait Process: Send + Sync + fmt::Debug {
    /// The `[process] kind` of the cell file.
    fn kind(&self) -> &'static str;

    /// The process as `Any`, so that its own crate can reach its parameters.
    fn as_any(&self) -> &dyn std::any::Any;

    /// Words for reports.
    fn words(&self) -> &'static Words;

    /// The process parameters as the plan document records them (SI, keys with units).
    fn parameters(&self) -> serde_json::Value;

    /// How far beyond the TCP's reach a task may lie and still be done (the optical probe's
    /// standoff), for the quick reach test (m).
    fn tool_reach(&self) -> f64;

    /// The tool poses that might do `task`, sampled.
    fn tool_poses(&self, task: &Task) -> Vec<Pose>;

    /// Whether the tool at `tcp` does `task`, before asking whether a robot reaches it.
    fn pose_check(&self, task: &Task, tcp: &Pose) -> Result<(), ProcessReason>;

    /// Checks of a reachable pose against the static scene (once per pose).
    fn reached_check(&self, world: &CollisionWorld, task: &Task, tcp: &Pose) -> Result<(), ProcessReason>;

    /// Checks of one configuration that involve the robot's own bodies (`bodies` as
    /// [`Robot::body_poses`] places them), before its collision check.
    fn arm_check(
        &self,
        world: &CollisionWorld,
        robot: &Robot,
        bodies: &[Pose],
        task: &Task,
        tcp: &Pose,
    ) -> Result<(), ProcessReason>;

    /// The work at `task`.
    fn work(&self, task: &Task) -> Work;

    /// Constraints between tasks (none for most processes).
    fn relations(&self) -> Vec<Relation> {
        Vec::new()
    }

    /// The figures the plan states for a visit of `task` with the tool at `tcp`.
    fn visit_figures(&self, task: &Task, tcp: &Pose) -> Vec<Figure>;

    /// Paper 000's local robust sets (eq. 4) of `members`: for each member, the members that
    /// may be done together with it from nearby poses within `radius` (m). `None` when the
    /// process has no such notion (then the local-robust allocation is refused).
    fn local_sets(&self, tasks: &[Task], members: &[TaskId], radius: f64) -> Option<Vec<Vec<TaskId>>>;

    /// Tool poses near `tcp` that could do the task instead (paper 000 §4.2's perturbation of
    /// the probe orientation by `step` rad), in a fixed order. Each is checked like any
    /// candidate before use.
    fn nearby_poses(&self, task: &Task, tcp: &Pose, step: f64) -> Vec<Pose>;
}

/// One column a process adds to the task CSV beside `id,x,y,z,nx,ny,nz,feature`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TaskColumn {
    /// Header name.
    pub name: &'static str,
    /// How its values convert to SI.
    pub unit: ColumnUnit,
}

/// The unit of a [`TaskColumn`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnUnit {
    /// The cell's length unit.
    Length,
    /// The cell's angle unit.
    Angle,
    /// A plain number.
    Number,
}

/// What a process constructor gets: its `[process]` table (without `kind`), the cell file's
/// text for errors that point at a line, the units, and the tasks as read.
pub struct ProcessInput<'a> {
    /// The cell file.
    pub path: &'a Path,
    /// Its text.
    pub text: &'a str,
    /// The `[process]` table's span.
    pub span: Range<usize>,
    /// Metres per file length unit.
    pub to_m: f64,
    /// Radians per file angle unit.
    pub to_rad: f64,
    /// The tasks, with this process's columns read into [`Task::values`].
    pub tasks: &'a [Task],
    /// The task file.
    pub tasks_path: &'a Path,
}

impl ProcessInput<'_> {
    /// Deserializes the `[process]` table (without `kind`) into `T`, keeping line numbers.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, InputError> {
        use serde::de::Error;
        let parsed = (|| {
            let root = toml::de::DeTable::parse(self.text)?;
            let process = root
                .get_ref()
                .get("process")
                .ok_or_else(|| toml::de::Error::custom("missing table `process`"))?;
            let mut table = process
                .get_ref()
                .as_table()
                .ok_or_else(|| toml::de::Error::custom("`process` must be a table"))?
                .clone();
            table.remove("kind");
            let value = toml::Spanned::new(process.span(), toml::de::DeValue::Table(table));
            T::deserialize(toml::de::ValueDeserializer::from(value))
        })();
        parsed.map_err(|e| {
            self.error_at(
                e.span().unwrap_or(self.span.clone()),
                format!("invalid process: {}", e.message().trim()),
            )
            .hint("docs/cell-format.md lists the process keys, their units and defaults")
        })
    }

    /// An error at a byte range of the cell file.
    pub fn error_at(&self, span: Range<usize>, message: impl Into<String>) -> InputError {
        InputError::at_span(self.path, self.text, span, message)
            .hint("docs/cell-format.md describes every key of the cell file, its unit and default")
    }

    /// An error at `key = …` inside the `[process]` table (or at the table).
    pub fn error(&self, key: &str, message: impl Into<String>) -> InputError {
        self.error_at(key_span(self.text, &self.span, key), message)
    }

    /// An error at a task's line of the task file.
    pub fn task_error(&self, task: &Task, message: impl Into<String>) -> InputError {
        InputError::at_line(self.tasks_path, Some(task.line), message)
    }
}

/// The span of `key = ...` inside `within` of `text` (extended to the next table header, since a
/// table's span may cover its header only), or `within` itself.
pub fn key_span(text: &str, within: &Range<usize>, key: &str) -> Range<usize> {
    let start = within.start.min(text.len());
    let first_line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
    let next_header = text[first_line_end..]
        .find("\n[")
        .map_or(text.len(), |i| first_line_end + i);
    let end = within.end.max(next_header).clamp(start, text.len());
    let hay = &text[start..end];
    let mut from = 0;
    while let Some(i) = hay[from..].find(key) {
        let at = from + i;
        let before_ok =
            at == 0 || !hay.as_bytes()[at - 1].is_ascii_alphanumeric() && hay.as_bytes()[at - 1] != b'_';
        let rest = hay[at + key.len()..].trim_start_matches([' ', '\t']);
        if before_ok && rest.starts_with('=') {
            let line_end = hay[at..].find('\n').map_or(hay.len(), |e| at + e);
            return start + at..start + line_end;
        }
        from = at + key.len();
    }
    within.clone()
}

/// A process as the registry knows it.
#[derive(Clone, Copy)]
pub struct ProcessEntry {
    /// `[process] kind`.
    pub kind: &'static str,
    /// One line for `--help` and errors.
    pub summary: &'static str,
    /// Columns the process adds to the task CSV.
    pub task_columns: &'static [TaskColumn],
    /// Builds the process from its table and the tasks.
    pub build: fn(&ProcessInput) -> Result<Arc<dyn Process>, InputError>,
}

impl fmt::Debug for ProcessEntry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ProcessEntry").field("kind", &self.kind).finish()
    }
}

/// The processes a binary knows, found by `kind`.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    entries: Vec<ProcessEntry>,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Registry::default()
    }

    /// Adds a process (a later entry of the same kind replaces the earlier one).
    pub fn with(mut self, entry: ProcessEntry) -> Self {
        self.entries.retain(|e| e.kind != entry.kind);
        self.entries.push(entry);
        self
    }

    /// The entry of `kind`.
    pub fn get(&self, kind: &str) -> Option<&ProcessEntry> {
        self.entries.iter().find(|e| e.kind == kind)
    }

    /// Every kind, in registration order.
    pub fn kinds(&self) -> Vec<&'static str> {
        self.entries.iter().map(|e| e.kind).collect()
    }

    /// The entry of `kind`, or an error at `span` of the cell file listing the known kinds.
    pub(crate) fn find(
        &self,
        kind: &str,
        path: &Path,
        text: &str,
        span: Range<usize>,
    ) -> Result<&ProcessEntry, InputError> {
        self.get(kind).ok_or_else(|| {
            InputError::at_span(path, text, span, format!("unknown process kind `{kind}`")).hint(format!(
                "this cellplan knows: {}",
                self.entries
                    .iter()
                    .map(|e| format!("`{}` ({})", e.kind, e.summary))
                    .collect::<Vec<_>>()
                    .join("; ")
            ))
        })
    }
}

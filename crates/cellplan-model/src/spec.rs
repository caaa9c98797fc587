//! The cell file as written (TOML), before units are applied and paths resolved.
//! `docs/cell-format.md` documents every key; keep the two in step.
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// The whole cell file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellSpec {
    /// A name for reports (default: the file's folder name).
    pub name: Option<String>,
    /// Units of every length and angle in this file and in the task list.
    #[serde(default)]
    pub units: UnitsSpec,
    /// What the cell does; its parameters are read in a second pass (the process crate's own
    /// spec) so that errors in them keep their line.
    pub process: Spanned<ProcessHeader>,
    /// Limits every process shares.
    #[serde(default)]
    pub planning: Option<Spanned<PlanningSpec>>,
    /// Named tools (end effectors) that robots carry.
    #[serde(default)]
    pub tools: BTreeMap<String, Spanned<ToolSpec>>,
    /// The robots.
    #[serde(default)]
    pub robots: Vec<Spanned<RobotSpec>>,
    /// Static objects: the part, fixtures, floor, guards.
    #[serde(default)]
    pub objects: Vec<Spanned<ShapeEntry>>,
    /// Where the tasks are.
    pub tasks: Spanned<TasksSpec>,
}

/// Length unit of the file.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum LengthUnit {
    /// Millimetres.
    Mm,
    /// Metres.
    #[default]
    M,
}

impl LengthUnit {
    /// Metres per unit.
    pub fn to_m(self) -> f64 {
        match self {
            LengthUnit::Mm => 1e-3,
            LengthUnit::M => 1.0,
        }
    }
}

/// Angle unit of the file.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum AngleUnit {
    /// Degrees.
    Deg,
    /// Radians.
    #[default]
    Rad,
}

impl AngleUnit {
    /// Radians per unit.
    pub fn to_rad(self) -> f64 {
        match self {
            AngleUnit::Deg => std::f64::consts::PI / 180.0,
            AngleUnit::Rad => 1.0,
        }
    }
}

/// `[units]`.
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnitsSpec {
    /// `"mm"` or `"m"` (default m).
    #[serde(default)]
    pub length: LengthUnit,
    /// `"deg"` or `"rad"` (default rad).
    #[serde(default)]
    pub angle: AngleUnit,
}

/// `[process]` on the first pass: the `kind`; the process reads the rest of the table itself
/// (see [`crate::ProcessInput::parse`]), so that errors inside it keep their line.
#[derive(Clone, Debug, Deserialize)]
pub struct ProcessHeader {
    /// The process, as registered ([`crate::Registry`]).
    pub kind: String,
    /// Everything else, read by the process.
    #[serde(flatten)]
    pub rest: toml::Table,
}

/// `[planning]`: limits every process shares (lengths in file units, times in s).
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanningSpec {
    /// Smallest allowed distance between a robot (with its tool) and static objects (default
    /// 10 mm).
    pub clearance: Option<f64>,
    /// φ: most tasks one robot may be given (default 14).
    pub task_cap: Option<usize>,
    /// γ: largest allowed difference between robots' times in seconds (default: none).
    pub balance_limit: Option<f64>,
}

/// A pose: `xyz` plus at most one of `rpy`, `quat` (x, y, z, w) or `matrix` (rows).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSpec {
    /// Translation (file length unit).
    #[serde(default)]
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw about fixed x, y, z (URDF convention; file angle unit).
    pub rpy: Option<[f64; 3]>,
    /// Unit quaternion `[x, y, z, w]`.
    pub quat: Option<[f64; 4]>,
    /// Rotation matrix, row by row; must be orthonormal with determinant +1.
    pub matrix: Option<[[f64; 3]; 3]>,
}

/// One shape: exactly one of `box`, `cylinder`, `sphere`, `mesh`, with its pose.
/// Used for static objects (which also need `name`) and tool shapes.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeEntry {
    /// Name (required for objects).
    pub name: Option<String>,
    /// Full size along x, y, z.
    #[serde(rename = "box")]
    pub box_size: Option<[f64; 3]>,
    /// A cylinder along its local z.
    pub cylinder: Option<CylinderSpec>,
    /// A sphere radius.
    pub sphere: Option<f64>,
    /// A mesh file (STL or OBJ), relative to the cell file.
    pub mesh: Option<String>,
    /// Unit of the mesh file's coordinates (default: the file's length unit).
    pub mesh_units: Option<LengthUnit>,
    /// Pose of the shape (in the world for objects, in the tip-link frame for tools).
    #[serde(default = "identity_pose")]
    pub pose: Spanned<PoseSpec>,
}

fn identity_pose() -> Spanned<PoseSpec> {
    Spanned::new(0..0, PoseSpec::default())
}

/// `cylinder = { radius = .., length = .. }`.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderSpec {
    /// Radius.
    pub radius: f64,
    /// Length along z.
    pub length: f64,
}

/// `[tools.NAME]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolSpec {
    /// The tool centre point in the robot's tip-link frame. For an optical probe: the laser
    /// source, z along the beam, x towards the camera.
    pub tcp: Spanned<PoseSpec>,
    /// The tool's body.
    #[serde(default, rename = "shape")]
    pub shapes: Vec<ShapeEntry>,
}

/// OPW parameters: a ROS-Industrial yaml path, or a table.
#[derive(Clone, Debug, Deserialize)]
#[serde(untagged)]
pub enum OpwSpec {
    /// Path to an `opw_parameters_*.yaml`, relative to the cell file.
    File(String),
    /// The parameters inline (file length unit; offsets in file angle unit).
    Inline(OpwInline),
}

/// Inline OPW parameters.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OpwInline {
    /// a1.
    pub a1: f64,
    /// a2.
    pub a2: f64,
    /// b.
    pub b: f64,
    /// c1.
    pub c1: f64,
    /// c2.
    pub c2: f64,
    /// c3.
    pub c3: f64,
    /// c4.
    pub c4: f64,
    /// Joint offsets (default zeros).
    #[serde(default)]
    pub offsets: [f64; 6],
    /// Sign corrections ±1 (default all +1).
    #[serde(default = "plus_ones")]
    pub sign_corrections: [f64; 6],
}

fn plus_ones() -> [f64; 6] {
    [1.0; 6]
}

/// `[[robots]]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSpec {
    /// Unique name.
    pub name: String,
    /// URDF file, relative to the cell file.
    pub urdf: Spanned<String>,
    /// ROS package name → folder, for `package://` URIs (relative to the cell file).
    #[serde(default)]
    pub packages: BTreeMap<String, String>,
    /// Tip link of the chain (default `tool0`, else the URDF's last link).
    pub tip: Option<String>,
    /// OPW parameters for the analytic IK; without them a numeric IK is used.
    pub opw: Option<Spanned<OpwSpec>>,
    /// Pose of the URDF root link in the world.
    pub base: Spanned<PoseSpec>,
    /// Home configuration (file angle unit for revolute joints).
    pub home: Option<Spanned<Vec<f64>>>,
    /// Name of the tool in `[tools]`.
    pub tool: Option<Spanned<String>>,
    /// Joint velocity limits overriding the URDF (file angle unit per second).
    pub max_velocity: Option<Spanned<Vec<f64>>>,
    /// Joint acceleration limits (file angle unit per s²); default: velocity / 0.25 s.
    pub max_acceleration: Option<Spanned<Vec<f64>>>,
}

/// `[tasks]`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TasksSpec {
    /// CSV file of tasks, relative to the cell file.
    pub file: String,
}

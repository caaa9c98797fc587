//! A planning problem without a cell: a robot (URDF, optional SRDF, the folders of its ROS
//! packages, where its root stands), obstacles (primitives, and meshes read from STL or OBJ
//! files), a start, one or more goals and a margin — the motion-problem format of
//! `docs/motion-problems.md` (one JSON file per scene, many problems in it) — and the arm set up
//! in a collision world to solve them ([`ArmSetup`]).
//!
//! The robot is built as the cell loader builds one: one convex body per collision shape of
//! every link (links rigidly attached off the chain, such as a gripper's fingers, keep their own
//! bodies; a markedly concave mesh of a link that a joint moves is cut into convex pieces,
//! [`cellplan_geom::pieces`] — the hulls of such links are what touch their neighbours across
//! the joint, while every piece multiplies the pairs to check, so rigid attachments such as
//! gripper fingers keep one hull per mesh), the SRDF's `disable_collisions` pairs left out of the self checks (without an SRDF:
//! every pair of bodies on different links that are not parent and child). Of the remaining
//! pairs, those proven apart in every configuration within the joint limits are not asked by
//! the validity check ([`crate::arm::pairs_that_may_touch`]). An optional tool ([`ToolRef`])
//! adds one body per shape on the chain's tip link under the tool's name, checked against every
//! link but the one it is mounted on, with or without an SRDF.
use cellplan_geom::read::{LimitedReadError, read_limited, show_bytes, utf8_text};
use cellplan_geom::{DQuat, DVec3, Mesh, Pose, ShapeSpec, load_mesh};
use cellplan_kin::KinError;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod setup;

pub use setup::ArmSetup;

/// The format name a problem file states.
pub const FORMAT: &str = "cellplan-motion-problems";
/// The version read.
pub const VERSION: u32 = 1;
/// Largest problem file read (256 MiB).
pub const MAX_FILE_BYTES: u64 = 256 << 20;
/// Most problems in one file.
pub const MAX_PROBLEMS: usize = 100_000;
/// Most obstacles in one problem.
pub const MAX_OBSTACLES: usize = 100_000;
/// Most goals in one problem.
pub const MAX_GOALS: usize = 10_000;
/// Shapes a tool may have, at most.
pub const MAX_TOOL_SHAPES: usize = 1_000;
/// How far a tool's points may lie from the tip link's origin (m): the exact re-check samples
/// a path more densely the farther the robot's points reach.
pub const MAX_TOOL_REACH_M: f64 = 10.0;
/// Largest length accepted (m): positions, sizes, margins.
pub const MAX_LENGTH_M: f64 = 1e4;
/// Bytes of mesh files one problem file may have read, in all (each file counted once): many
/// large meshes are refused before they fill the memory.
pub const MAX_MESH_BYTES: u64 = 2 << 30;

/// Why a problem file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ProblemError {
    /// The file cannot be read.
    #[error("cannot read {}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not valid JSON of this format.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// The content is refused.
    #[error("{}: {message}", path.display())]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong (naming the problem and member).
        message: String,
        /// What to do about it.
        hint: String,
    },
    /// The robot's URDF or SRDF cannot be used.
    #[error(transparent)]
    Robot(#[from] KinError),
}

impl ProblemError {
    /// What to do about it.
    pub fn hint(&self) -> &str {
        match self {
            ProblemError::Io { .. } => "check the path",
            ProblemError::Json { .. } => "see docs/motion-problems.md for the format",
            ProblemError::Invalid { hint, .. } => hint,
            ProblemError::Robot(KinError::Urdf { hint, .. }) => hint,
            ProblemError::Robot(_) => "check the robot's files",
        }
    }
}

/// A pose as written: position and unit quaternion (x, y, z, w).
#[derive(Deserialize)]
struct PoseDoc {
    xyz: [f64; 3],
    #[serde(default)]
    quat_xyzw: Option<[f64; 4]>,
    #[serde(default)]
    rpy: Option<[f64; 3]>,
}

#[derive(Deserialize)]
struct RobotDoc {
    urdf: String,
    #[serde(default)]
    srdf: Option<String>,
    #[serde(default)]
    base: Option<PoseDoc>,
    #[serde(default)]
    packages: BTreeMap<String, String>,
    #[serde(default)]
    tool: Option<ToolDoc>,
}

#[derive(Deserialize)]
struct ToolDoc {
    #[serde(default = "default_tool_name")]
    name: String,
    shapes: Vec<ObstacleDoc>,
}

fn default_tool_name() -> String {
    "tool".into()
}

#[derive(Deserialize)]
struct ObstacleDoc {
    #[serde(default)]
    name: String,
    shape: String,
    #[serde(default)]
    half_extents: Option<[f64; 3]>,
    #[serde(default)]
    radius: Option<f64>,
    #[serde(default)]
    length: Option<f64>,
    #[serde(default)]
    file: Option<String>,
    #[serde(default)]
    scale: Option<f64>,
    pose: PoseDoc,
}

#[derive(Deserialize)]
struct ProblemDoc {
    name: String,
    start: Vec<f64>,
    goals: Vec<Vec<f64>>,
    #[serde(default)]
    margin: f64,
    #[serde(default)]
    obstacles: Vec<ObstacleDoc>,
}

#[derive(Deserialize)]
struct FileDoc {
    format: String,
    version: u32,
    #[serde(default)]
    scene: String,
    #[serde(default)]
    source: String,
    robot: RobotDoc,
    joints: Vec<String>,
    problems: Vec<ProblemDoc>,
}

/// The robot of a problem file.
#[derive(Clone, Debug)]
pub struct RobotRef {
    /// The URDF (resolved against the problem file's folder).
    pub urdf: PathBuf,
    /// The SRDF, if given.
    pub srdf: Option<PathBuf>,
    /// The folders of the ROS packages its `package://` paths name (resolved against the
    /// problem file's folder).
    pub packages: BTreeMap<String, PathBuf>,
    /// Where the URDF's root link stands in the world.
    pub base: Pose,
    /// The tool on the chain's tip, if given.
    pub tool: Option<ToolRef>,
}

/// A tool mounted on the chain's tip link (`tool0` where the URDF has one): its shapes move
/// with that link.
#[derive(Clone, Debug)]
pub struct ToolRef {
    /// Its name: the link name its bodies take (SRDF rules may name it).
    pub name: String,
    /// Its shapes, each posed in the tip link's frame.
    pub shapes: Vec<(ShapeSpec, Pose)>,
}

/// An obstacle: a solid primitive, or a triangle mesh (its surface), at a world pose.
#[derive(Clone, Debug)]
pub struct Obstacle {
    /// Name (informative).
    pub name: String,
    /// Its shape (a cylinder's axis is its local z).
    pub shape: ShapeSpec,
    /// Pose of the shape's centre in the world.
    pub pose: Pose,
}

/// One query.
#[derive(Clone, Debug)]
pub struct Problem {
    /// Name (`scene/NNNN` in the MBM files).
    pub name: String,
    /// Start configuration, in the file's joint order.
    pub start: Vec<f64>,
    /// Goal configurations (a path may end at any), in the file's joint order.
    pub goals: Vec<Vec<f64>>,
    /// Clearance the path must keep from obstacles (m).
    pub margin: f64,
    /// The obstacles.
    pub obstacles: Vec<Obstacle>,
}

/// A problem file.
#[derive(Clone, Debug)]
pub struct ProblemSet {
    /// The file.
    pub path: PathBuf,
    /// Scene name.
    pub scene: String,
    /// Where the problems come from.
    pub source: String,
    /// The robot.
    pub robot: RobotRef,
    /// The joints a configuration lists, in order.
    pub joints: Vec<String>,
    /// The problems.
    pub problems: Vec<Problem>,
}

/// The pose of a written pose: `quat_xyzw` (normalised; its norm must be within 1 ± 0.01), or
/// `rpy` as in URDF, or the identity rotation.
fn pose_of(doc: &PoseDoc, what: &str) -> Result<Pose, String> {
    let t = DVec3::from_array(doc.xyz);
    if !t.is_finite() || t.abs().max_element() > MAX_LENGTH_M {
        return Err(format!(
            "{what}: position {:?} is not finite or beyond {MAX_LENGTH_M} m",
            doc.xyz
        ));
    }
    let rot = match (doc.quat_xyzw, doc.rpy) {
        (Some(q), _) => {
            let q = DQuat::from_xyzw(q[0], q[1], q[2], q[3]);
            let n = q.length();
            if !n.is_finite() || (n - 1.0).abs() > 0.01 {
                return Err(format!("{what}: quat_xyzw has norm {n}, not a unit quaternion"));
            }
            q / n
        }
        (None, Some([r, p, y])) => {
            if ![r, p, y].iter().all(|v| v.is_finite()) {
                return Err(format!("{what}: rpy is not finite"));
            }
            (DQuat::from_rotation_z(y) * DQuat::from_rotation_y(p) * DQuat::from_rotation_x(r)).normalize()
        }
        (None, None) => DQuat::IDENTITY,
    };
    Ok(Pose::from_parts(t, rot))
}

/// A length that must be finite, positive (or zero when `zero_ok`) and within bounds.
fn length(v: f64, what: &str, zero_ok: bool) -> Result<f64, String> {
    if !v.is_finite() || v < 0.0 || (!zero_ok && v == 0.0) || v > MAX_LENGTH_M {
        return Err(format!("{what} = {v} is not a length in (0, {MAX_LENGTH_M}] m"));
    }
    Ok(v)
}

/// The meshes of a problem file's obstacles, each read once (by file and scale bits), and the
/// bytes of files left to read ([`MAX_MESH_BYTES`] at first).
struct Meshes {
    read: BTreeMap<(PathBuf, u64), Arc<Mesh>>,
    budget: u64,
}

fn obstacle(doc: &ObstacleDoc, what: &str, dir: &Path, meshes: &mut Meshes) -> Result<Obstacle, String> {
    let pose = pose_of(&doc.pose, what)?;
    let need = |v: Option<f64>, key: &str| v.ok_or_else(|| format!("{what}: a {} needs `{key}`", doc.shape));
    let shape = match doc.shape.as_str() {
        "box" => {
            let h = doc
                .half_extents
                .ok_or_else(|| format!("{what}: a box needs `half_extents`"))?;
            for (k, v) in h.iter().enumerate() {
                length(*v, &format!("{what}: half_extents[{k}]"), true)?;
            }
            ShapeSpec::Box {
                half_extents: DVec3::from_array(h),
            }
        }
        "cylinder" => ShapeSpec::Cylinder {
            radius: length(need(doc.radius, "radius")?, &format!("{what}: radius"), false)?,
            half_height: length(need(doc.length, "length")?, &format!("{what}: length"), false)? / 2.0,
        },
        "sphere" => ShapeSpec::Sphere {
            radius: length(need(doc.radius, "radius")?, &format!("{what}: radius"), false)?,
        },
        "mesh" => {
            let file = doc
                .file
                .as_ref()
                .ok_or_else(|| format!("{what}: a mesh needs `file` (an STL or OBJ file)"))?;
            let scale = doc.scale.unwrap_or(1.0);
            if !(scale.is_finite() && scale > 0.0 && scale <= MAX_LENGTH_M) {
                return Err(format!("{what}: scale = {scale} is not in (0, {MAX_LENGTH_M}]"));
            }
            let path = dir.join(file);
            let mesh = match meshes.read.entry((path.clone(), scale.to_bits())) {
                std::collections::btree_map::Entry::Occupied(e) => e.get().clone(),
                std::collections::btree_map::Entry::Vacant(e) => {
                    let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
                    if bytes > meshes.budget {
                        return Err(format!(
                            "{what}: reading {} would take the mesh files of this problem file past {} in all",
                            path.display(),
                            show_bytes(MAX_MESH_BYTES)
                        ));
                    }
                    meshes.budget -= bytes;
                    let mut mesh = load_mesh(&path).map_err(|err| format!("{what}: {err}"))?;
                    if mesh.triangles.is_empty() {
                        return Err(format!("{what}: {} has no triangles", path.display()));
                    }
                    for v in &mut mesh.vertices {
                        *v *= scale;
                    }
                    if let Some(v) = mesh
                        .vertices
                        .iter()
                        .find(|v| !v.is_finite() || v.abs().max_element() > MAX_LENGTH_M)
                    {
                        return Err(format!(
                            "{what}: {} has the vertex {v} (scaled), beyond {MAX_LENGTH_M} m",
                            path.display()
                        ));
                    }
                    e.insert(Arc::new(mesh)).clone()
                }
            };
            ShapeSpec::Mesh(mesh)
        }
        other => {
            return Err(format!(
                "{what}: unknown shape \"{other}\" (box, cylinder, sphere or mesh)"
            ));
        }
    };
    Ok(Obstacle {
        name: doc.name.clone(),
        shape,
        pose,
    })
}

/// The tool of `robot.tool`: a name that can be a link name and one to [`MAX_TOOL_SHAPES`]
/// shapes, each read as an obstacle is (its pose in the tip link's frame), none reaching
/// farther than [`MAX_TOOL_REACH_M`] from that frame's origin.
fn tool(doc: &ToolDoc, dir: &Path, meshes: &mut Meshes) -> Result<ToolRef, String> {
    let name = doc.name.trim();
    if name.is_empty() || name.chars().any(char::is_control) {
        return Err(format!("robot.tool: name {:?} is not a link name", doc.name));
    }
    if doc.shapes.is_empty() || doc.shapes.len() > MAX_TOOL_SHAPES {
        return Err(format!(
            "robot.tool has {} shapes (1 to {MAX_TOOL_SHAPES})",
            doc.shapes.len()
        ));
    }
    let shapes = doc
        .shapes
        .iter()
        .enumerate()
        .map(|(k, d)| {
            let what = format!("robot.tool: shape {}", k + 1);
            let o = obstacle(d, &what, dir, meshes)?;
            let reach = o.pose.translation.length() + o.shape.reach();
            if reach > MAX_TOOL_REACH_M {
                return Err(format!(
                    "{what} reaches {reach:.3} m from the tip link, beyond the {MAX_TOOL_REACH_M} m a tool may"
                ));
            }
            Ok((o.shape, o.pose))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ToolRef {
        name: name.to_string(),
        shapes,
    })
}

fn configuration(q: &[f64], n: usize, what: &str) -> Result<Vec<f64>, String> {
    if q.len() != n {
        return Err(format!("{what} has {} values for {n} joints", q.len()));
    }
    if let Some(v) = q.iter().find(|v| !v.is_finite() || v.abs() > 1e3) {
        return Err(format!("{what} holds {v}, not a joint value"));
    }
    Ok(q.to_vec())
}

/// Reads a problem file (see the module documentation): refuses, naming the file, line or
/// problem, another format or version, files over [`MAX_FILE_BYTES`], more than
/// [`MAX_PROBLEMS`] problems, [`MAX_OBSTACLES`] obstacles or [`MAX_GOALS`] goals per problem,
/// configurations of the wrong length or with non-finite values, unknown shapes, non-unit
/// quaternions and absurd lengths. Members it does not know are ignored.
pub fn read_problems(path: &Path) -> Result<ProblemSet, ProblemError> {
    let invalid = |message: String, hint: &str| ProblemError::Invalid {
        path: path.to_path_buf(),
        message,
        hint: hint.to_string(),
    };
    let bytes = read_limited(path, MAX_FILE_BYTES).map_err(|e| match e {
        LimitedReadError::Io(source) => ProblemError::Io {
            path: path.to_path_buf(),
            source,
        },
        LimitedReadError::TooLarge { size } => invalid(
            format!(
                "the file is {size}, larger than the {} a problem file may have",
                show_bytes(MAX_FILE_BYTES)
            ),
            "split the problems over several files",
        ),
    })?;
    let text = utf8_text(bytes).map_err(|e| ProblemError::Json {
        path: path.to_path_buf(),
        line: e.line,
        column: 1,
        message: format!("byte {} is not UTF-8 text", e.offset),
    })?;
    let doc: FileDoc = serde_json::from_str(&text).map_err(|e| ProblemError::Json {
        path: path.to_path_buf(),
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    let hint = "see docs/motion-problems.md for the format";
    if doc.format != FORMAT || doc.version != VERSION {
        return Err(invalid(
            format!(
                "format \"{}\" version {}, not \"{FORMAT}\" version {VERSION}",
                doc.format, doc.version
            ),
            hint,
        ));
    }
    if doc.problems.len() > MAX_PROBLEMS {
        return Err(invalid(
            format!(
                "{} problems, more than the {MAX_PROBLEMS} a file may hold",
                doc.problems.len()
            ),
            "split the problems over several files",
        ));
    }
    let n = doc.joints.len();
    if n == 0 {
        return Err(invalid("`joints` is empty".into(), hint));
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    let base = match &doc.robot.base {
        Some(b) => pose_of(b, "robot.base").map_err(|m| invalid(m, hint))?,
        None => Pose::IDENTITY,
    };
    let mut meshes = Meshes {
        read: BTreeMap::new(),
        budget: MAX_MESH_BYTES,
    };
    let tool = match &doc.robot.tool {
        Some(t) => Some(tool(t, dir, &mut meshes).map_err(|m| invalid(m, hint))?),
        None => None,
    };
    let robot = RobotRef {
        tool,
        urdf: dir.join(&doc.robot.urdf),
        srdf: doc.robot.srdf.as_ref().map(|s| dir.join(s)),
        packages: doc
            .robot
            .packages
            .iter()
            .map(|(name, folder)| (name.clone(), dir.join(folder)))
            .collect(),
        base,
    };
    let mut problems = Vec::with_capacity(doc.problems.len());
    for (k, p) in doc.problems.iter().enumerate() {
        let what = format!("problem {} (\"{}\")", k + 1, p.name);
        let mut check = || -> Result<Problem, String> {
            if p.goals.is_empty() || p.goals.len() > MAX_GOALS {
                return Err(format!("{what} has {} goals (1 to {MAX_GOALS})", p.goals.len()));
            }
            if p.obstacles.len() > MAX_OBSTACLES {
                return Err(format!(
                    "{what} has {} obstacles (at most {MAX_OBSTACLES})",
                    p.obstacles.len()
                ));
            }
            let start = configuration(&p.start, n, &format!("{what}: start"))?;
            let goals = p
                .goals
                .iter()
                .enumerate()
                .map(|(g, q)| configuration(q, n, &format!("{what}: goal {}", g + 1)))
                .collect::<Result<Vec<_>, _>>()?;
            let margin = length(p.margin, &format!("{what}: margin"), true)?;
            let obstacles = p
                .obstacles
                .iter()
                .enumerate()
                .map(|(o, d)| {
                    obstacle(
                        d,
                        &format!("{what}: obstacle {} (\"{}\")", o + 1, d.name),
                        dir,
                        &mut meshes,
                    )
                })
                .collect::<Result<Vec<_>, _>>()?;
            Ok(Problem {
                name: p.name.clone(),
                start,
                goals,
                margin,
                obstacles,
            })
        };
        problems.push(check().map_err(|m| invalid(m, hint))?);
    }
    Ok(ProblemSet {
        path: path.to_path_buf(),
        scene: doc.scene,
        source: doc.source,
        robot,
        joints: doc.joints,
        problems,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_files_are_read_once_within_a_byte_budget() {
        let tmp = tempfile::tempdir().unwrap();
        let stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        for name in ["a.stl", "b.stl"] {
            std::fs::write(tmp.path().join(name), stl).unwrap();
        }
        let doc = |file: &str| ObstacleDoc {
            name: String::new(),
            shape: "mesh".into(),
            half_extents: None,
            radius: None,
            length: None,
            file: Some(file.into()),
            scale: Some(0.5),
            pose: PoseDoc {
                xyz: [0.0; 3],
                quat_xyzw: None,
                rpy: None,
            },
        };
        let size = stl.len() as u64;
        let mut meshes = Meshes {
            read: BTreeMap::new(),
            budget: size + size / 2,
        };
        let first = obstacle(&doc("a.stl"), "o", tmp.path(), &mut meshes).unwrap();
        // Read again: the same mesh, nothing spent.
        let again = obstacle(&doc("a.stl"), "o", tmp.path(), &mut meshes).unwrap();
        let (ShapeSpec::Mesh(m1), ShapeSpec::Mesh(m2)) = (&first.shape, &again.shape) else {
            panic!("meshes")
        };
        assert!(Arc::ptr_eq(m1, m2));
        assert_eq!(m1.vertices[1], DVec3::new(0.5, 0.0, 0.0), "scaled");
        assert_eq!(meshes.budget, size / 2);
        // A second file does not fit in what is left.
        let e = obstacle(&doc("b.stl"), "o", tmp.path(), &mut meshes).unwrap_err();
        assert!(e.contains("b.stl") && e.contains("in all"), "{e}");
    }
}

//! Reading URDF files.
use crate::{Chain, ChainLink, Joint, JointKind, KinError};
use cellplan_geom::read::{LimitedReadError, read_limited, show_bytes, utf8_text};
use cellplan_geom::{DQuat, DVec3, Mesh, MeshError, Pose, ShapeSpec, load_mesh};
use std::collections::{BTreeMap, HashMap};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod validate;
pub(crate) mod xml;

/// A robot read from a URDF: its serial chain and the collision geometry of each chain link.
#[derive(Clone, Debug)]
pub struct RobotModel {
    /// `<robot name>`.
    pub name: String,
    /// The URDF file.
    pub path: PathBuf,
    /// Chain from the URDF root link to the tip link.
    pub chain: Chain,
    /// Collision shapes per chain link (same index as `chain.links`), in the link frame, metres.
    /// Links rigidly attached off the chain have their shapes listed with their chain parent's
    /// (placed in its frame); [`RobotModel::collision_links`] says which URDF link each came from.
    pub collision: Vec<Vec<(ShapeSpec, Pose)>>,
    /// Beside [`RobotModel::collision`], shape by shape: the name of the URDF link the shape
    /// belongs to (the chain link itself, or a link rigidly attached off the chain, such as a
    /// gripper finger). SRDF collision rules name these links.
    pub collision_links: Vec<Vec<String>>,
    /// The name of every link of the URDF, on the chain or not, with shapes or not, in the
    /// file's order.
    pub link_names: Vec<String>,
    /// Inertial parameters per chain link (same index as `chain.links`), in the link frame:
    /// the link's own `<inertial>` with those of links rigidly attached off the chain lumped in;
    /// `None` where no `<inertial>` with a positive mass was given.
    pub inertia: Vec<Option<crate::dynamics::LinkInertia>>,
}

/// Loads a URDF. `packages` maps a ROS package name to its folder (for `package://name/...`);
/// relative mesh paths resolve against the URDF's folder. `tip` picks the chain's last link
/// (default: `tool0` when present, else the end of the longest root-to-leaf path).
///
/// Only `<collision>` geometry is read (visual meshes need not exist). Links off the chain
/// (e.g. `base`, `flange`, or anything below the tip) have their shapes merged into the chain
/// link they hang from; movable joints off the chain are taken at zero.
pub fn load_urdf(
    path: &Path,
    packages: &BTreeMap<String, PathBuf>,
    tip: Option<&str>,
) -> Result<RobotModel, KinError> {
    let text = read_urdf(path, MAX_URDF_BYTES)?;
    load_urdf_str(&text, path, packages, tip)
}

/// The text of `path`, at most `limit` bytes of UTF-8 (see [`cellplan_geom::read`]).
fn read_urdf(path: &Path, limit: u64) -> Result<String, KinError> {
    let refuse = |line: Option<usize>, message: String, hint: &str| KinError::Urdf {
        path: path.to_path_buf(),
        line,
        message,
        hint: hint.to_string(),
    };
    let bytes = read_limited(path, limit).map_err(|e| match e {
        LimitedReadError::Io(source) => KinError::Io {
            path: path.to_path_buf(),
            source,
        },
        LimitedReadError::TooLarge { size } => refuse(
            None,
            format!("the file is {size}, larger than the {} a URDF may have", show_bytes(limit)),
            "check that the path names a URDF (meshes belong in files of their own, named by <mesh filename>)",
        ),
    })?;
    utf8_text(bytes).map_err(|e| {
        refuse(
            Some(e.line),
            format!(
                "byte {} (0x{:02x}) is not UTF-8 text: this is not a URDF file",
                e.offset, e.byte
            ),
            "check that the path names a URDF, and save it as UTF-8",
        )
    })
}

/// As [`load_urdf`] on URDF text already read; `path` names the file in errors and relative
/// mesh paths resolve against its folder.
pub fn load_urdf_str(
    text: &str,
    path: &Path,
    packages: &BTreeMap<String, PathBuf>,
    tip: Option<&str>,
) -> Result<RobotModel, KinError> {
    Loader { text, path, packages }.load(tip)
}

struct Loader<'a> {
    text: &'a str,
    path: &'a Path,
    packages: &'a BTreeMap<String, PathBuf>,
}

/// Where an off-chain link hangs: its chain link and its pose in that link's frame.
#[derive(Clone, Copy)]
struct Attachment {
    chain_link: usize,
    pose: Pose,
}

impl Loader<'_> {
    fn err(&self, line: Option<usize>, message: impl Into<String>, hint: impl Into<String>) -> KinError {
        KinError::Urdf {
            path: self.path.to_path_buf(),
            line,
            message: message.into(),
            hint: hint.into(),
        }
    }

    /// Reads the URDF in named steps: parse and check the text, build the link tree, pick the
    /// chain from the root to the tip, turn its joints into [`Joint`]s, hang the off-chain
    /// links on the chain, and gather the collision shapes.
    fn load(&self, tip: Option<&str>) -> Result<RobotModel, KinError> {
        let (doc, robot) = self.parse()?;
        let tree = self.tree(&doc, &robot)?;
        let path_links = self.chain_path(&robot, &tree, tip)?;
        let (chain, chain_pos) = self.chain(&doc, &robot, &tree, &path_links)?;
        let attach = self.attachments(&robot, &tree, &chain_pos)?;
        let (collision, collision_links) = self.collision(&doc, &robot, &attach, chain.links.len())?;
        let inertia = inertias(&robot, &attach, chain.links.len());
        Ok(RobotModel {
            link_names: robot.links.iter().map(|l| l.name.clone()).collect(),
            inertia,
            name: robot.name.clone(),
            path: self.path.to_path_buf(),
            chain,
            collision,
            collision_links,
        })
    }

    /// The text as an XML document with lines (checked by [`Loader::validate`]) and as urdf-rs
    /// reads it.
    fn parse(&self) -> Result<(xml::Document, urdf_rs::Robot), KinError> {
        let doc = xml::parse(self.text).map_err(|(line, msg)| {
            self.err(
                Some(line),
                format!("not well-formed XML: {msg}"),
                "fix the XML syntax at that line (a URDF is an XML file with a <robot> root)",
            )
        })?;
        self.validate(&doc)?;
        let robot = urdf_rs::read_from_string(self.text).map_err(|e| {
            let msg = e.to_string();
            let msg = msg.strip_prefix("custom: ").unwrap_or(&msg);
            let line = self.guess_line(msg);
            self.err(
                line,
                format!("invalid URDF: {msg}"),
                if line.is_some() {
                    "check the element at that line against the URDF specification"
                } else {
                    "check the file against the URDF specification"
                },
            )
        })?;
        Ok((doc, robot))
    }

    /// The links as a tree: each link's parent joint and child joints, the one root, and a
    /// depth-first order from it. Refuses unknown links, two parents, no or several roots and
    /// cycles.
    fn tree<'r>(&self, doc: &xml::Document, robot: &'r urdf_rs::Robot) -> Result<Tree<'r>, KinError> {
        let link_index: HashMap<&str, usize> = robot
            .links
            .iter()
            .enumerate()
            .map(|(i, l)| (l.name.as_str(), i))
            .collect();
        let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
        let mut child_joints: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
        for (ji, joint) in robot.joints.iter().enumerate() {
            let line = elem_line(doc, "joint", &joint.name);
            let find = |name: &str, role: &str| {
                link_index.get(name).copied().ok_or_else(|| {
                    self.err(
                        line,
                        format!(
                            "joint '{}' names {role} link '{name}', which does not exist",
                            joint.name
                        ),
                        "every <parent link> and <child link> must name a <link> of the file",
                    )
                })
            };
            let parent = find(&joint.parent.link, "parent")?;
            let child = find(&joint.child.link, "child")?;
            if let Some(other) = parent_joint[child] {
                return Err(self.err(
                    line,
                    format!(
                        "link '{}' is the child of two joints ('{}' and '{}')",
                        joint.child.link, robot.joints[other].name, joint.name
                    ),
                    "a URDF is a tree: each link has at most one parent joint",
                ));
            }
            parent_joint[child] = Some(ji);
            child_joints[parent].push(ji);
        }
        let root = self.root(doc, robot, &parent_joint)?;
        let mut tree = Tree {
            link_index,
            parent_joint,
            child_joints,
            root,
            order: Vec::new(),
            depth: Vec::new(),
        };
        self.depth_first(doc, robot, &mut tree)?;
        Ok(tree)
    }

    /// Fills `tree.order` and `tree.depth` by a depth-first walk from the root; links never
    /// reached sit on a cycle.
    fn depth_first(
        &self,
        doc: &xml::Document,
        robot: &urdf_rs::Robot,
        tree: &mut Tree<'_>,
    ) -> Result<(), KinError> {
        let mut depth = vec![usize::MAX; robot.links.len()];
        let mut order = Vec::with_capacity(robot.links.len());
        let mut stack = vec![(tree.root, 0usize)];
        while let Some((l, d)) = stack.pop() {
            depth[l] = d;
            order.push(l);
            for &ji in tree.child_joints[l].iter().rev() {
                if let Some(&c) = tree.link_index.get(robot.joints[ji].child.link.as_str()) {
                    stack.push((c, d + 1));
                }
            }
        }
        if let Some(l) = (0..robot.links.len()).find(|&l| depth[l] == usize::MAX) {
            return Err(self.err(
                elem_line(doc, "link", &robot.links[l].name),
                format!("link '{}' is on a cycle of joints", robot.links[l].name),
                "a URDF is a tree: remove the joint that closes the loop",
            ));
        }
        (tree.order, tree.depth) = (order, depth);
        Ok(())
    }

    /// The one link without a parent joint.
    fn root(
        &self,
        doc: &xml::Document,
        robot: &urdf_rs::Robot,
        parent_joint: &[Option<usize>],
    ) -> Result<usize, KinError> {
        let roots: Vec<usize> = (0..robot.links.len())
            .filter(|&i| parent_joint[i].is_none())
            .collect();
        match roots.as_slice() {
            [r] => Ok(*r),
            [] => Err(self.err(
                None,
                if robot.links.is_empty() {
                    "the URDF has no <link>".to_string()
                } else {
                    "the joints form a cycle: no link is without a parent".to_string()
                },
                "a URDF is a tree with one root link",
            )),
            many => {
                let names: Vec<&str> = many.iter().map(|&i| robot.links[i].name.as_str()).collect();
                Err(self.err(
                    many.get(1)
                        .and_then(|&i| elem_line(doc, "link", &robot.links[i].name)),
                    format!(
                        "the URDF has {} root links (links without a parent joint): {}",
                        many.len(),
                        names.join(", ")
                    ),
                    "connect every link to the tree with a joint (a URDF has one root link)",
                ))
            }
        }
    }

    /// The links from the root to the tip, root first. The tip is `tip`, else `tool0` when
    /// present, else the deepest leaf (first in depth-first order on ties).
    fn chain_path(
        &self,
        robot: &urdf_rs::Robot,
        tree: &Tree<'_>,
        tip: Option<&str>,
    ) -> Result<Vec<usize>, KinError> {
        let tip_link = match tip {
            Some(name) => tree.link_index.get(name).copied().ok_or_else(|| {
                let names: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
                self.err(
                    None,
                    format!(
                        "tip link '{name}' does not exist; the links are: {}",
                        names.join(", ")
                    ),
                    "set the tip to one of these links",
                )
            })?,
            None => match tree.link_index.get("tool0") {
                Some(&t) => t,
                None => {
                    let mut best = tree.root;
                    for &l in &tree.order {
                        if tree.child_joints[l].is_empty() && tree.depth[l] > tree.depth[best] {
                            best = l;
                        }
                    }
                    best
                }
            },
        };
        let mut path_links = vec![tip_link];
        let mut cur = tip_link;
        while let Some(ji) = tree.parent_joint[cur] {
            cur = tree.link_index[robot.joints[ji].parent.link.as_str()];
            path_links.push(cur);
        }
        path_links.reverse();
        Ok(path_links)
    }

    /// The chain along `path_links`, and each link's position on it (`None` off the chain).
    fn chain(
        &self,
        doc: &xml::Document,
        robot: &urdf_rs::Robot,
        tree: &Tree<'_>,
        path_links: &[usize],
    ) -> Result<(Chain, Vec<Option<usize>>), KinError> {
        let mut links = Vec::with_capacity(path_links.len());
        let mut joints = Vec::new();
        let mut chain_pos: Vec<Option<usize>> = vec![None; robot.links.len()];
        for (ci, &l) in path_links.iter().enumerate() {
            chain_pos[l] = Some(ci);
            let name = robot.links[l].name.clone();
            let Some(ji) = tree.parent_joint[l] else {
                links.push(ChainLink {
                    name,
                    origin: Pose::IDENTITY,
                    joint: None,
                });
                continue;
            };
            let uj = &robot.joints[ji];
            let joint = match self.chain_joint(uj, elem_line(doc, "joint", &uj.name))? {
                None => None,
                Some(j) => {
                    joints.push(j);
                    Some(joints.len() - 1)
                }
            };
            links.push(ChainLink {
                name,
                origin: origin_pose(&uj.origin),
                joint,
            });
        }
        Ok((Chain { links, joints }, chain_pos))
    }

    /// The [`Joint`] of a URDF joint on the chain (`None` for a fixed one); `line` is its
    /// element's.
    fn chain_joint(&self, uj: &urdf_rs::Joint, line: Option<usize>) -> Result<Option<Joint>, KinError> {
        let kind = match uj.joint_type {
            urdf_rs::JointType::Fixed => return Ok(None),
            urdf_rs::JointType::Revolute => JointKind::Revolute,
            urdf_rs::JointType::Continuous => JointKind::Continuous,
            urdf_rs::JointType::Prismatic => JointKind::Prismatic,
            ref other => {
                return Err(self.err(
                    line,
                    format!(
                        "joint '{}' on the chain is of type {other:?}, which is not supported",
                        uj.name
                    ),
                    "the chain may hold revolute, continuous, prismatic and fixed joints only",
                ));
            }
        };
        let axis = DVec3::from_array(uj.axis.xyz.0);
        let len = axis.length();
        if !(len > 1e-12 && len.is_finite()) {
            return Err(self.err(
                line,
                format!(
                    "joint '{}' has a zero or invalid axis {:?}",
                    uj.name, uj.axis.xyz.0
                ),
                "give <axis xyz=\"...\"> a non-zero direction",
            ));
        }
        let (mut lower, mut upper) = (uj.limit.lower, uj.limit.upper);
        if kind == JointKind::Continuous {
            (lower, upper) = (-TAU, TAU);
        } else if kind == JointKind::Revolute && !(lower.is_finite() && upper.is_finite()) {
            // URDF 1.2: a revolute joint without limits turns freely.
            lower = if lower.is_finite() { lower } else { -TAU };
            upper = if upper.is_finite() { upper } else { TAU };
        }
        if lower.is_nan() || upper.is_nan() || lower > upper {
            return Err(self.err(
                line,
                format!("joint '{}' has limits lower {lower} > upper {upper}", uj.name),
                "make <limit lower> at most <limit upper>",
            ));
        }
        Ok(Some(Joint {
            name: uj.name.clone(),
            kind,
            axis: axis / len,
            lower,
            upper,
            // No <limit> (continuous) or a zero velocity: unknown, no limit.
            max_velocity: if uj.limit.velocity > 0.0 {
                uj.limit.velocity
            } else {
                f64::INFINITY
            },
            max_effort: uj.limit.effort,
        }))
    }

    /// Where each link's shapes go: walk up to the nearest chain link.
    fn attachments(
        &self,
        robot: &urdf_rs::Robot,
        tree: &Tree<'_>,
        chain_pos: &[Option<usize>],
    ) -> Result<Vec<Option<Attachment>>, KinError> {
        let mut attach: Vec<Option<Attachment>> = vec![None; robot.links.len()];
        for &l in &tree.order {
            attach[l] = Some(match chain_pos[l] {
                Some(ci) => Attachment {
                    chain_link: ci,
                    pose: Pose::IDENTITY,
                },
                None => {
                    // The parent comes earlier in depth-first order, so it is set already.
                    let ji = tree.parent_joint[l]
                        .ok_or_else(|| self.err(None, "internal: root off the chain", ""))?;
                    let p = tree.link_index[robot.joints[ji].parent.link.as_str()];
                    let up = attach[p].ok_or_else(|| self.err(None, "internal: unordered tree", ""))?;
                    Attachment {
                        chain_link: up.chain_link,
                        pose: up.pose * origin_pose(&robot.joints[ji].origin),
                    }
                }
            });
        }
        Ok(attach)
    }

    /// The collision shapes of every link, placed in the frame of the chain link it hangs
    /// from (`chain_links` of them), and beside them the URDF link each came from. Meshes named
    /// twice are loaded once.
    #[allow(clippy::type_complexity)]
    fn collision(
        &self,
        doc: &xml::Document,
        robot: &urdf_rs::Robot,
        attach: &[Option<Attachment>],
        chain_links: usize,
    ) -> Result<(Vec<Vec<(ShapeSpec, Pose)>>, Vec<Vec<String>>), KinError> {
        let mut collision: Vec<Vec<(ShapeSpec, Pose)>> = vec![Vec::new(); chain_links];
        let mut names: Vec<Vec<String>> = vec![Vec::new(); chain_links];
        let mut meshes: HashMap<PathBuf, Arc<Mesh>> = HashMap::new();
        let mesh_lines = mesh_lines(doc);
        for (l, link) in robot.links.iter().enumerate() {
            let Some(at) = attach[l] else { continue };
            for c in &link.collision {
                let pose = at.pose * origin_pose(&c.origin);
                for (shape, local) in self.shapes(&link.name, &c.geometry, &mut meshes, &mesh_lines)? {
                    collision[at.chain_link].push((shape, pose * local));
                    names[at.chain_link].push(link.name.clone());
                }
            }
        }
        Ok((collision, names))
    }

    /// The shapes of one `<collision>` geometry in the collision frame.
    fn shapes(
        &self,
        link: &str,
        g: &urdf_rs::Geometry,
        meshes: &mut HashMap<PathBuf, Arc<Mesh>>,
        mesh_lines: &HashMap<(&str, &str), usize>,
    ) -> Result<Vec<(ShapeSpec, Pose)>, KinError> {
        Ok(match g {
            urdf_rs::Geometry::Box { size } => vec![(
                ShapeSpec::Box {
                    half_extents: DVec3::from_array(size.0) * 0.5,
                },
                Pose::IDENTITY,
            )],
            urdf_rs::Geometry::Cylinder { radius, length } => vec![(
                ShapeSpec::Cylinder {
                    radius: *radius,
                    half_height: length * 0.5,
                },
                Pose::IDENTITY,
            )],
            urdf_rs::Geometry::Sphere { radius } => {
                vec![(ShapeSpec::Sphere { radius: *radius }, Pose::IDENTITY)]
            }
            urdf_rs::Geometry::Capsule { radius, length } => capsule(*radius, *length),
            urdf_rs::Geometry::Mesh { filename, scale } => {
                let line = mesh_lines
                    .get(&(link, filename.as_str()))
                    .copied()
                    .or_else(|| line_of(self.text, filename));
                let mesh = self.mesh(link, filename, line, meshes)?;
                let mesh = match scale {
                    Some(s) if s.0 != [1.0, 1.0, 1.0] => Arc::new(scale_mesh(&mesh, DVec3::from_array(s.0))),
                    _ => mesh,
                };
                self.check_mesh_reach(&mesh, link, filename, line)?;
                vec![(ShapeSpec::Mesh(mesh), Pose::IDENTITY)]
            }
        })
    }

    /// The mesh file `filename` of `link` (named on `line`), loaded once per file through
    /// `meshes`; a missing file is a mesh error naming the URI.
    fn mesh(
        &self,
        link: &str,
        filename: &str,
        line: Option<usize>,
        meshes: &mut HashMap<PathBuf, Arc<Mesh>>,
    ) -> Result<Arc<Mesh>, KinError> {
        let file = self.resolve(link, filename, line)?;
        if let Some(m) = meshes.get(&file) {
            return Ok(m.clone());
        }
        let mesh_err = |source| KinError::Mesh {
            urdf: self.path.to_path_buf(),
            line,
            link: link.to_string(),
            source: Box::new(source),
        };
        if !file.is_file() {
            return Err(mesh_err(MeshError::Io {
                path: file.clone(),
                source: std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!("no such file (from \"{filename}\")"),
                ),
            }));
        }
        let m = Arc::new(load_mesh(&file).map_err(mesh_err)?);
        meshes.insert(file, m.clone());
        Ok(m)
    }

    /// Refuses a scaled collision mesh reaching beyond [`MAX_LENGTH_M`] from its origin (metres
    /// from here on: such a mesh has the wrong unit).
    fn check_mesh_reach(
        &self,
        mesh: &Mesh,
        link: &str,
        filename: &str,
        line: Option<usize>,
    ) -> Result<(), KinError> {
        let reach = mesh
            .vertices
            .iter()
            .map(|v| v.abs().max_element())
            .fold(0.0, f64::max);
        if reach > MAX_LENGTH_M {
            return Err(self.err(
                line,
                format!(
                    "collision mesh \"{filename}\" of link '{link}' reaches {reach:e} m from \
                     its origin once scaled, beyond {MAX_LENGTH_M:e} m — is the unit right?"
                ),
                "URDF meshes are in metres: give a mesh in millimetres \
                 scale=\"0.001 0.001 0.001\"",
            ));
        }
        Ok(())
    }

    /// The file a mesh URI names.
    fn resolve(&self, link: &str, uri: &str, line: Option<usize>) -> Result<PathBuf, KinError> {
        let base = self.path.parent().unwrap_or(Path::new(""));
        if let Some(rest) = uri.strip_prefix("package://") {
            let (pkg, rel) = rest.split_once('/').unwrap_or((rest, ""));
            return match self.packages.get(pkg) {
                Some(dir) => Ok(dir.join(rel)),
                None => {
                    let known: Vec<&str> = self.packages.keys().map(String::as_str).collect();
                    Err(self.err(
                        line,
                        format!(
                            "mesh \"{uri}\" of link '{link}' is in ROS package '{pkg}', which is not known (known: {})",
                            if known.is_empty() { "none".to_string() } else { known.join(", ") }
                        ),
                        format!("add it under packages in the cell file: {pkg} = the folder holding the package"),
                    ))
                }
            };
        }
        let p = if let Some(rest) = uri.strip_prefix("file://") {
            PathBuf::from(rest)
        } else if uri.contains("://") {
            return Err(self.err(
                line,
                format!(
                    "mesh \"{uri}\" of link '{link}': only package://, file:// and plain paths are supported"
                ),
                "download the mesh and refer to it by a path",
            ));
        } else {
            PathBuf::from(uri)
        };
        Ok(if p.is_absolute() { p } else { base.join(p) })
    }
}

/// Largest URDF file read, in bytes (64 MiB; real robot descriptions are well under 1 MiB, and
/// meshes live in files of their own).
pub const MAX_URDF_BYTES: u64 = 64 << 20;

/// Largest length accepted in a URDF, in metres (10 km): an origin offset, a primitive's size,
/// a prismatic joint's limit, or a collision mesh's reach once scaled. Anything beyond is a
/// unit mistake or a damaged file.
pub const MAX_LENGTH_M: f64 = 1e4;

/// The link tree of a URDF (indices into `links` and `joints` of the urdf-rs robot).
struct Tree<'r> {
    link_index: HashMap<&'r str, usize>,
    /// Per link, the joint whose child it is (`None` for the root).
    parent_joint: Vec<Option<usize>>,
    /// Per link, the joints whose parent it is, in file order.
    child_joints: Vec<Vec<usize>>,
    root: usize,
    /// Depth-first order from the root.
    order: Vec<usize>,
    /// Per link, its number of joints from the root.
    depth: Vec<usize>,
}

/// Line of the top-level `<kind name="name">` element.
fn elem_line(doc: &xml::Document, kind: &str, name: &str) -> Option<usize> {
    doc.children(doc.root())
        .find(|e| e.name == kind && e.attr("name") == Some(name))
        .map(|e| e.line)
}

/// Line of each collision `<mesh>`, by link and filename, for errors.
fn mesh_lines(doc: &xml::Document) -> HashMap<(&str, &str), usize> {
    let mut lines = HashMap::new();
    for link in doc.children(doc.root()).filter(|e| e.name == "link") {
        let name = link.attr("name").unwrap_or_default();
        for c in doc.children(link).filter(|c| c.name == "collision") {
            for g in doc.children(c).filter(|g| g.name == "geometry") {
                for m in doc.children(g).filter(|m| m.name == "mesh") {
                    if let Some(f) = m.attr("filename") {
                        lines.entry((name, f)).or_insert(m.line);
                    }
                }
            }
        }
    }
    lines
}

/// 1-based line of the first occurrence of `needle` in `text`.
fn line_of(text: &str, needle: &str) -> Option<usize> {
    text.find(needle)
        .map(|i| text[..i].bytes().filter(|&b| b == b'\n').count() + 1)
}

/// A capsule along z of `radius` and cylinder `length`: a cylinder and two end spheres.
fn capsule(radius: f64, length: f64) -> Vec<(ShapeSpec, Pose)> {
    let h = length * 0.5;
    vec![
        (
            ShapeSpec::Cylinder {
                radius,
                half_height: h,
            },
            Pose::IDENTITY,
        ),
        (ShapeSpec::Sphere { radius }, Pose::translation(0.0, 0.0, h)),
        (ShapeSpec::Sphere { radius }, Pose::translation(0.0, 0.0, -h)),
    ]
}

/// The pose of a URDF `<origin xyz rpy>`: `Rz(yaw) · Ry(pitch) · Rx(roll)` then translation.
/// Per chain link, the inertials of the URDF links hanging from it, lumped in its frame.
fn inertias(
    robot: &urdf_rs::Robot,
    attach: &[Option<Attachment>],
    chain_links: usize,
) -> Vec<Option<crate::dynamics::LinkInertia>> {
    use crate::dynamics::LinkInertia;
    let mut out: Vec<Option<LinkInertia>> = vec![None; chain_links];
    for (l, link) in robot.links.iter().enumerate() {
        let Some(at) = attach.get(l).copied().flatten() else {
            continue;
        };
        let i = &link.inertial;
        if i.mass.value.is_nan() || i.mass.value <= 0.0 {
            continue;
        }
        let t = &i.inertia;
        let own = LinkInertia {
            mass: i.mass.value,
            com: DVec3::ZERO,
            inertia: glam::DMat3::from_cols_array(&[
                t.ixx, t.ixy, t.ixz, t.ixy, t.iyy, t.iyz, t.ixz, t.iyz, t.izz,
            ]),
        };
        // The inertial frame in the link frame, then the link frame in the chain link's.
        let pose = at.pose * origin_pose(&i.origin);
        let body = own.transformed(glam::DMat3::from_quat(pose.rotation), pose.translation);
        let slot = &mut out[at.chain_link];
        *slot = Some(match slot {
            Some(prev) => prev.combined(&body),
            None => body,
        });
    }
    out
}

fn origin_pose(o: &urdf_rs::Pose) -> Pose {
    let [r, p, y] = o.rpy.0;
    let rot = DQuat::from_rotation_z(y) * DQuat::from_rotation_y(p) * DQuat::from_rotation_x(r);
    Pose::from_parts(DVec3::from_array(o.xyz.0), rot.normalize())
}

/// A copy of `mesh` with its vertices scaled per axis (winding flipped for a mirroring scale).
fn scale_mesh(mesh: &Mesh, s: DVec3) -> Mesh {
    let mut m = Mesh {
        vertices: mesh.vertices.iter().map(|v| *v * s).collect(),
        triangles: mesh.triangles.clone(),
    };
    if s.x * s.y * s.z < 0.0 {
        for t in &mut m.triangles {
            t.swap(1, 2);
        }
    }
    m
}

#[cfg(test)]
mod tests;

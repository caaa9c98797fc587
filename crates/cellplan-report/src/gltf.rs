//! Binary glTF 2.0 (`.glb`) of the cell and the plan's motion: static objects, every robot as a
//! node chain (base → links, geometry on each link), the probe paths and MPs as lines, and one
//! animation that turns every joint along the plan's trajectory samples (linear
//! interpolation), so Blender or any glTF viewer replays the plan.
//!
//! glTF is Y-up; the cell is Z-up, so everything hangs under a root node turned −90° about x.
use crate::scene::{Scene, SceneRobot, robot_colour};
use cellplan_core::document::{Plan, RobotPlan, Sample};
use cellplan_geom::{DQuat, Pose};
use cellplan_model::Cell;
use serde_json::{Value, json};
use std::collections::HashMap;

/// Binary buffer and the views and accessors into it.
#[derive(Default)]
struct Buffers {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

impl Buffers {
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(v);
        self.views.len() - 1
    }

    /// Floats as `kind` ("SCALAR", "VEC3", "VEC4"), `width` values per element; min and max
    /// recorded (required for positions and animation inputs).
    fn floats(&mut self, data: &[f32], kind: &str, width: usize, target: Option<u32>) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let mut lo = vec![f32::INFINITY; width];
        let mut hi = vec![f32::NEG_INFINITY; width];
        for chunk in data.chunks(width) {
            for (k, &v) in chunk.iter().enumerate() {
                lo[k] = lo[k].min(v);
                hi[k] = hi[k].max(v);
            }
        }
        self.accessors.push(json!({
            "bufferView": view, "componentType": FLOAT, "count": data.len() / width,
            "type": kind, "min": lo, "max": hi,
        }));
        self.accessors.len() - 1
    }

    fn indices(&mut self, data: &[u32]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view, "componentType": UNSIGNED_INT, "count": data.len(), "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }
}

fn trs(p: &Pose) -> (Value, Value) {
    let (t, q) = (p.translation, p.rotation);
    (
        json!([t.x as f32, t.y as f32, t.z as f32]),
        json!([q.x as f32, q.y as f32, q.z as f32, q.w as f32]),
    )
}

fn node(name: &str, pose: &Pose) -> Value {
    let (t, r) = trs(pose);
    json!({"name": name, "translation": t, "rotation": r})
}

/// The `.glb` bytes of `plan` in `scene` (robots matched by name; see [`Scene::match_plan`]).
///
/// The steps: the static objects, each robot (its node chain with geometry and joint
/// animation, and its probe path), the MPs as lines, then the root and the container.
pub fn glb(plan: &Plan, cell: &Cell, scene: &Scene) -> Result<Vec<u8>, crate::scene::Mismatch> {
    let order = scene.match_plan(plan)?;
    let mut b = Builder::new(scene);
    b.statics();
    for (r, (rp, &k)) in plan.robots.iter().zip(&order).enumerate() {
        b.robot(r, rp, &scene.robots[k]);
    }
    for (r, rp) in plan.robots.iter().enumerate() {
        b.task_lines(r, rp, cell);
    }
    Ok(b.finish(plan))
}

/// The glTF document as it is built: buffers, nodes, meshes, materials (each colour once),
/// geometry accessors and meshes (each written on first use), the root's children and the
/// animation.
struct Builder<'s> {
    scene: &'s Scene,
    buf: Buffers,
    nodes: Vec<Value>,
    meshes: Vec<Value>,
    materials: Vec<Value>,
    material_of: HashMap<[u32; 3], usize>,
    /// Geometry index → (positions, indices) accessors.
    geometry: HashMap<usize, (usize, usize)>,
    /// (geometry, material) → mesh.
    mesh_of: HashMap<(usize, usize), usize>,
    roots: Vec<usize>,
    channels: Vec<Value>,
    samplers: Vec<Value>,
}

impl<'s> Builder<'s> {
    /// An empty document for `scene`.
    fn new(scene: &'s Scene) -> Self {
        Builder {
            scene,
            buf: Buffers::default(),
            nodes: Vec::new(),
            meshes: Vec::new(),
            materials: Vec::new(),
            material_of: HashMap::new(),
            geometry: HashMap::new(),
            mesh_of: HashMap::new(),
            roots: Vec::new(),
            channels: Vec::new(),
            samplers: Vec::new(),
        }
    }

    /// The material of colour `c`, added on first use.
    fn material(&mut self, c: [f32; 3]) -> usize {
        let materials = &mut self.materials;
        *self.material_of.entry(c.map(f32::to_bits)).or_insert_with(|| {
            materials.push(json!({
                "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 0.1, "roughnessFactor": 0.7},
                "doubleSided": true,
            }));
            materials.len() - 1
        })
    }

    /// The mesh of geometry `g` in material `mat`, its accessors and the mesh added on first use.
    fn mesh(&mut self, g: usize, mat: usize) -> usize {
        let (scene, buf) = (self.scene, &mut self.buf);
        let (pos, idx) = *self.geometry.entry(g).or_insert_with(|| {
            let geo = &scene.geometries[g];
            let flat: Vec<f32> = geo.positions.iter().flatten().copied().collect();
            (
                buf.floats(&flat, "VEC3", 3, Some(ARRAY_BUFFER)),
                buf.indices(&geo.indices),
            )
        });
        let meshes = &mut self.meshes;
        *self.mesh_of.entry((g, mat)).or_insert_with(|| {
            meshes.push(json!({
                "name": scene.geometries[g].label,
                "primitives": [{"attributes": {"POSITION": pos}, "indices": idx, "material": mat}],
            }));
            meshes.len() - 1
        })
    }

    /// Adds `n` under the root; returns its index.
    fn push_root(&mut self, n: Value) -> usize {
        self.nodes.push(n);
        let i = self.nodes.len() - 1;
        self.roots.push(i);
        i
    }

    /// A node for every static object, with its mesh unless it has no triangles.
    fn statics(&mut self) {
        for s in &self.scene.statics {
            let mut n = node(&s.name, &s.placed.pose);
            if !self.scene.geometries[s.placed.geometry].indices.is_empty() {
                let mat = self.material(s.colour);
                n["mesh"] = json!(self.mesh(s.placed.geometry, mat));
            }
            self.push_root(n);
        }
    }

    /// Robot `r`: its base node, a node per chain link (at the first sample) with its geometry
    /// and the animation of its joint, then its probe path.
    fn robot(&mut self, r: usize, rp: &RobotPlan, sr: &SceneRobot) {
        let colour = robot_colour(r).map(|x| 0.25 + 0.75 * x);
        let mat = self.material(colour);
        let base = self.push_root(node(&rp.name, &sr.base));
        let keys = keyframes(rp);
        let times: Vec<f32> = keys.iter().map(|s| s.t as f32).collect();
        let input = (!times.is_empty()).then(|| self.buf.floats(&times, "SCALAR", 1, None));
        let q0 = rp.trajectory.first().map_or(rp.home.clone(), |s| s.q.clone());
        let mut parent = base;
        for i in 0..sr.parts.len() {
            let link = self.link(rp, sr, i, &q0, mat);
            push_child(&mut self.nodes, parent, link);
            parent = link;
            if let (Some((_, joint)), Some(input)) = (sr.joint_of(i), input) {
                self.animate(sr, i, joint.is_rotational(), &keys, input, link);
            }
        }
        self.probe_path(r, rp, sr);
    }

    /// The node of chain link `i` at configuration `q0`, with a child node per part that has
    /// triangles; returns the link's node.
    fn link(&mut self, rp: &RobotPlan, sr: &SceneRobot, i: usize, q0: &[f64], mat: usize) -> usize {
        let name = &sr.model.chain.links[i].name;
        self.nodes
            .push(node(&format!("{}/{name}", rp.name), &sr.local_pose(i, q0)));
        let link = self.nodes.len() - 1;
        let mut children: Vec<usize> = Vec::new();
        for (p, part) in sr.parts[i].iter().enumerate() {
            if self.scene.geometries[part.geometry].indices.is_empty() {
                continue; // nothing to draw, and glTF has no empty accessors
            }
            let m = self.mesh(part.geometry, mat);
            let mut n = node(&format!("{}/{name}/{p}", rp.name), &part.pose);
            n["mesh"] = json!(m);
            self.nodes.push(n);
            children.push(self.nodes.len() - 1);
        }
        if !children.is_empty() {
            self.nodes[link]["children"] = json!(children);
        }
        link
    }

    /// The animation channel of chain link `i` (node `link`) over `keys` (times at accessor
    /// `input`): rotations for a rotational joint, else translations.
    fn animate(
        &mut self,
        sr: &SceneRobot,
        i: usize,
        rotational: bool,
        keys: &[&Sample],
        input: usize,
        link: usize,
    ) {
        let (path, kind, width, values): (&str, &str, usize, Vec<f32>) = if !rotational {
            let v = keys
                .iter()
                .flat_map(|s| {
                    let t = sr.local_pose(i, &s.q).translation;
                    [t.x as f32, t.y as f32, t.z as f32]
                })
                .collect();
            ("translation", "VEC3", 3, v)
        } else {
            let mut prev: Option<DQuat> = None;
            let v = keys
                .iter()
                .flat_map(|s| {
                    // Keep neighbouring quaternions in one hemisphere so that slerp
                    // takes the short way, as the joint does.
                    let mut q = sr.local_pose(i, &s.q).rotation;
                    if prev.is_some_and(|p| p.dot(q) < 0.0) {
                        q = -q;
                    }
                    prev = Some(q);
                    [q.x as f32, q.y as f32, q.z as f32, q.w as f32]
                })
                .collect();
            ("rotation", "VEC4", 4, v)
        };
        let output = self.buf.floats(&values, kind, width, None);
        self.samplers
            .push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        self.channels
            .push(json!({"sampler": self.samplers.len() - 1, "target": {"node": link, "path": path}}));
    }

    /// Robot `r`'s probe path as a line strip, in the world (under the root).
    fn probe_path(&mut self, r: usize, rp: &RobotPlan, sr: &SceneRobot) {
        let path: Vec<f32> = rp
            .trajectory
            .iter()
            .flat_map(|s| {
                let p = sr.tcp_pose(&s.q).translation;
                [p.x as f32, p.y as f32, p.z as f32]
            })
            .collect();
        let mat = self.material(robot_colour(r));
        self.lines(&format!("{} probe path", rp.name), &path, LINE_STRIP, mat);
    }

    /// Robot `r`'s MPs: a 10 cm normal line each, in the robot's colour.
    fn task_lines(&mut self, r: usize, rp: &RobotPlan, cell: &Cell) {
        let segments: Vec<f32> = rp
            .tasks
            .iter()
            .filter_map(|v| cell.tasks.iter().find(|t| t.name == v.task))
            .flat_map(|t| {
                let (a, b) = (t.position, t.position + t.normal * 0.1);
                [a.x, a.y, a.z, b.x, b.y, b.z].map(|x| x as f32)
            })
            .collect();
        let mat = self.material(robot_colour(r));
        self.lines(&format!("{} MPs", rp.name), &segments, LINES, mat);
    }

    /// A node under the root drawing `points` (x, y, z, … in the world) as lines (`mode`
    /// [`LINES`] or [`LINE_STRIP`]) in material `mat`; nothing when there are fewer than two
    /// points.
    fn lines(&mut self, name: &str, points: &[f32], mode: u32, mat: usize) {
        if points.len() < 6 {
            return;
        }
        let acc = self.buf.floats(points, "VEC3", 3, Some(ARRAY_BUFFER));
        self.meshes.push(json!({
            "name": name,
            "primitives": [{"attributes": {"POSITION": acc}, "mode": mode, "material": mat}],
        }));
        self.push_root(json!({"name": name, "mesh": self.meshes.len() - 1}));
    }

    /// The root node (turning Z-up into glTF's Y-up), the document and the GLB container.
    fn finish(mut self, plan: &Plan) -> Vec<u8> {
        let h = std::f32::consts::FRAC_1_SQRT_2;
        self.nodes
            .push(json!({"name": plan.cell, "rotation": [-h, 0.0, 0.0, h], "children": self.roots}));
        let root = self.nodes.len() - 1;
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": format!("cellplan {}", env!("CARGO_PKG_VERSION"))},
            "scene": 0,
            "scenes": [{"name": plan.cell, "nodes": [root]}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": self.materials,
            "accessors": self.buf.accessors,
            "bufferViews": self.buf.views,
            "buffers": [{"byteLength": self.buf.bin.len()}],
        });
        if !self.channels.is_empty() {
            doc["animations"] =
                json!([{"name": "plan", "channels": self.channels, "samplers": self.samplers}]);
        }
        container(&doc, self.buf.bin)
    }
}

/// The trajectory samples used as keyframes: times must increase strictly in f32, so samples
/// that would not are dropped (the last grid sample can sit within 1e-10 s of the end).
fn keyframes(rp: &RobotPlan) -> Vec<&Sample> {
    let mut last = f32::NEG_INFINITY;
    rp.trajectory
        .iter()
        .filter(|s| {
            let t = s.t as f32;
            let keep = t > last;
            last = last.max(t);
            keep
        })
        .collect()
}

const LINES: u32 = 1;
const LINE_STRIP: u32 = 3;

fn push_child(nodes: &mut [Value], parent: usize, child: usize) {
    match nodes[parent].get_mut("children").and_then(Value::as_array_mut) {
        Some(c) => c.push(json!(child)),
        None => nodes[parent]["children"] = json!([child]),
    }
}

/// The GLB container: header, JSON chunk (padded with spaces), BIN chunk (padded with zeros).
fn container(doc: &Value, mut bin: Vec<u8>) -> Vec<u8> {
    let mut json = doc.to_string().into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

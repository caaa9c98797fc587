//! Binary glTF 2.0 (`.glb`) of the cell and the plan's motion: static objects, every robot as a
//! node chain (base → links, geometry on each link), the probe paths and MPs as lines, and one
//! animation that turns every joint along the plan's trajectory samples (linear
//! interpolation), so Blender or any glTF viewer replays the plan.
//!
//! glTF is Y-up; the cell is Z-up, so everything hangs under a root node turned −90° about x.
use crate::scene::{Scene, robot_colour};
use cellplan_core::document::Plan;
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
pub fn glb(plan: &Plan, cell: &Cell, scene: &Scene) -> Result<Vec<u8>, String> {
    let order = scene.match_plan(plan)?;
    let mut buf = Buffers::default();
    let mut nodes: Vec<Value> = Vec::new();
    let mut meshes: Vec<Value> = Vec::new();
    let mut materials: Vec<Value> = Vec::new();
    let mut material_of: HashMap<[u32; 3], usize> = HashMap::new();
    let mut material = |c: [f32; 3], materials: &mut Vec<Value>| {
        *material_of.entry(c.map(f32::to_bits)).or_insert_with(|| {
            materials.push(json!({
                "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 0.1, "roughnessFactor": 0.7},
                "doubleSided": true,
            }));
            materials.len() - 1
        })
    };
    // Geometry accessors, written on first use.
    let mut geometry: HashMap<usize, (usize, usize)> = HashMap::new();
    let mut mesh_of: HashMap<(usize, usize), usize> = HashMap::new();
    let mut mesh = |g: usize, mat: usize, buf: &mut Buffers, meshes: &mut Vec<Value>| {
        let (pos, idx) = *geometry.entry(g).or_insert_with(|| {
            let geo = &scene.geometries[g];
            let flat: Vec<f32> = geo.positions.iter().flatten().copied().collect();
            (
                buf.floats(&flat, "VEC3", 3, Some(ARRAY_BUFFER)),
                buf.indices(&geo.indices),
            )
        });
        *mesh_of.entry((g, mat)).or_insert_with(|| {
            meshes.push(json!({
                "name": scene.geometries[g].label,
                "primitives": [{"attributes": {"POSITION": pos}, "indices": idx, "material": mat}],
            }));
            meshes.len() - 1
        })
    };

    let mut roots: Vec<usize> = Vec::new();
    for s in &scene.statics {
        let mut n = node(&s.name, &s.placed.pose);
        if !scene.geometries[s.placed.geometry].indices.is_empty() {
            let mat = material(s.colour, &mut materials);
            n["mesh"] = json!(mesh(s.placed.geometry, mat, &mut buf, &mut meshes));
        }
        nodes.push(n);
        roots.push(nodes.len() - 1);
    }

    let mut channels: Vec<Value> = Vec::new();
    let mut samplers: Vec<Value> = Vec::new();
    for (r, (rp, &k)) in plan.robots.iter().zip(&order).enumerate() {
        let sr = &scene.robots[k];
        let colour = robot_colour(r).map(|x| 0.25 + 0.75 * x);
        let mat = material(colour, &mut materials);
        nodes.push(node(&rp.name, &sr.base));
        let base = nodes.len() - 1;
        roots.push(base);
        // Keyframe times must increase strictly in f32: samples that would not are dropped
        // (the last grid sample can sit within 1e-10 s of the end).
        let mut last = f32::NEG_INFINITY;
        let keys: Vec<&cellplan_core::document::Sample> = rp
            .trajectory
            .iter()
            .filter(|s| {
                let t = s.t as f32;
                let keep = t > last;
                last = last.max(t);
                keep
            })
            .collect();
        let times: Vec<f32> = keys.iter().map(|s| s.t as f32).collect();
        let input = (!times.is_empty()).then(|| buf.floats(&times, "SCALAR", 1, None));
        let q0 = rp.trajectory.first().map_or(rp.home.clone(), |s| s.q.clone());
        let mut parent = base;
        for (i, parts) in sr.parts.iter().enumerate() {
            let name = &sr.model.chain.links[i].name;
            nodes.push(node(&format!("{}/{name}", rp.name), &sr.local_pose(i, &q0)));
            let link = nodes.len() - 1;
            let mut children: Vec<usize> = Vec::new();
            for (p, part) in parts.iter().enumerate() {
                if scene.geometries[part.geometry].indices.is_empty() {
                    continue; // nothing to draw, and glTF has no empty accessors
                }
                let m = mesh(part.geometry, mat, &mut buf, &mut meshes);
                let mut n = node(&format!("{}/{name}/{p}", rp.name), &part.pose);
                n["mesh"] = json!(m);
                nodes.push(n);
                children.push(nodes.len() - 1);
            }
            if !children.is_empty() {
                nodes[link]["children"] = json!(children);
            }
            push_child(&mut nodes, parent, link);
            parent = link;
            if let (Some((_, joint)), Some(input)) = (sr.joint_of(i), input) {
                let (path, kind, width, values): (&str, &str, usize, Vec<f32>) = if !joint.is_rotational() {
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
                let output = buf.floats(&values, kind, width, None);
                samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
                channels.push(json!({"sampler": samplers.len() - 1, "target": {"node": link, "path": path}}));
            }
        }
        // The probe path as a line strip, in the world (under the root).
        let path: Vec<f32> = rp
            .trajectory
            .iter()
            .flat_map(|s| {
                let p = sr.tcp_pose(&s.q).translation;
                [p.x as f32, p.y as f32, p.z as f32]
            })
            .collect();
        lines(
            &mut buf,
            &mut meshes,
            &mut nodes,
            &mut roots,
            &format!("{} probe path", rp.name),
            &path,
            LINE_STRIP,
            material(robot_colour(r), &mut materials),
        );
    }
    // MPs: a 10 cm normal line each, coloured by the robot that measures it.
    for (r, rp) in plan.robots.iter().enumerate() {
        let segments: Vec<f32> = rp
            .tasks
            .iter()
            .filter_map(|v| cell.tasks.iter().find(|t| t.name == v.task))
            .flat_map(|t| {
                let (a, b) = (t.position, t.position + t.normal * 0.1);
                [a.x, a.y, a.z, b.x, b.y, b.z].map(|x| x as f32)
            })
            .collect();
        let mat = material(robot_colour(r), &mut materials);
        lines(
            &mut buf,
            &mut meshes,
            &mut nodes,
            &mut roots,
            &format!("{} MPs", rp.name),
            &segments,
            LINES,
            mat,
        );
    }
    let h = std::f32::consts::FRAC_1_SQRT_2;
    nodes.push(json!({"name": plan.cell, "rotation": [-h, 0.0, 0.0, h], "children": roots}));
    let root = nodes.len() - 1;
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": format!("cellplan {}", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"name": plan.cell, "nodes": [root]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": buf.bin.len()}],
    });
    if !channels.is_empty() {
        doc["animations"] = json!([{"name": "plan", "channels": channels, "samplers": samplers}]);
    }
    Ok(container(&doc, buf.bin))
}

const LINES: u32 = 1;
const LINE_STRIP: u32 = 3;

/// A node under the root drawing `points` (x, y, z, … in the world) as lines (`mode`
/// [`LINES`] or [`LINE_STRIP`]) in material `mat`; nothing when there are fewer than two
/// points.
#[allow(clippy::too_many_arguments)]
fn lines(
    buf: &mut Buffers,
    meshes: &mut Vec<Value>,
    nodes: &mut Vec<Value>,
    roots: &mut Vec<usize>,
    name: &str,
    points: &[f32],
    mode: u32,
    mat: usize,
) {
    if points.len() < 6 {
        return;
    }
    let acc = buf.floats(points, "VEC3", 3, Some(ARRAY_BUFFER));
    meshes.push(json!({
        "name": name,
        "primitives": [{"attributes": {"POSITION": acc}, "mode": mode, "material": mat}],
    }));
    nodes.push(json!({"name": name, "mesh": meshes.len() - 1}));
    roots.push(nodes.len() - 1);
}

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

//! Triangle meshes and their loaders.
//!
//! The loaders are written by hand so that every error names the file, the line (for text
//! formats) and what to do about it:
//!
//! - **STL**, binary or ASCII. A file is binary when its size is exactly `84 + 50·n` for the
//!   triangle count `n` in its header (some binary files start with `solid`, so the first
//!   bytes decide nothing); otherwise a file that starts with `solid` is read as ASCII.
//!   Exactly duplicated vertices are welded, so the mesh comes out indexed.
//! - **OBJ**: `v x y z [w]` and `f` with `a`, `a/b`, `a//c`, `a/b/c` and negative (relative)
//!   indices; polygons are fan-triangulated; everything else (`vt`, `vn`, `g`, `o`, `s`,
//!   `usemtl`, `mtllib`, comments, ...) is ignored. Vertices no face refers to are dropped.
//!
//! Degenerate triangles (two corners at the same point) are dropped; a mesh without triangles,
//! or whose triangles all have zero area, is an error, whatever the format. Units stay those
//! of the file: the caller scales ([`Mesh::scaled`]).
//!
//! Bad input is refused, never a panic or an unbounded read: files are read up to
//! [`MAX_FILE_BYTES`], and a coordinate that is not finite or exceeds [`MAX_COORDINATE`] in
//! magnitude is refused with its line (text) or triangle (binary STL).
use crate::read::{LimitedReadError, read_limited, show_bytes};
use crate::{DVec3, MeshError, Pose};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Largest mesh file read, in bytes (1 GiB: some 21 million binary STL triangles).
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// Largest coordinate magnitude accepted, in the file's units: 1e6 is a kilometre in
/// millimetres, so anything beyond it is a unit mistake or a damaged file.
pub const MAX_COORDINATE: f64 = 1e6;

/// An indexed triangle mesh (metres once loaded by the cell loader; loaders keep file units).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<DVec3>,
    /// Counter-clockwise triangles as indices into `vertices`.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// Axis-aligned bounds `(min, max)`; `None` for an empty mesh.
    pub fn aabb(&self) -> Option<(DVec3, DVec3)> {
        let first = *self.vertices.first()?;
        Some(
            self.vertices
                .iter()
                .fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))),
        )
    }

    /// A copy with every vertex scaled by `factor` (unit conversion).
    pub fn scaled(&self, factor: f64) -> Mesh {
        Mesh {
            vertices: self.vertices.iter().map(|&v| v * factor).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// A copy with every vertex transformed by `pose`.
    pub fn transformed(&self, pose: &Pose) -> Mesh {
        Mesh {
            vertices: self.vertices.iter().map(|&v| pose.transform_point(v)).collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// Area of triangle `i`.
    ///
    /// # Panics
    /// If `i` or one of the triangle's indices is out of range.
    pub fn triangle_area(&self, i: usize) -> f64 {
        let [a, b, c] = self.corners(i);
        0.5 * (b - a).cross(c - a).length()
    }

    /// Unit normal of triangle `i` by the right-hand rule (zero for a degenerate triangle).
    ///
    /// # Panics
    /// If `i` or one of the triangle's indices is out of range.
    pub fn triangle_normal(&self, i: usize) -> DVec3 {
        let [a, b, c] = self.corners(i);
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// A copy with at most `max_triangles` triangles, by vertex clustering (Rossignac &
    /// Borrel): the bounding box is cut into cubic cells, the vertices of a cell merge into
    /// their mean, and triangles that collapse or repeat are dropped. The cell size is the
    /// smallest (found by bisection on the number of cells along the longest side) that meets
    /// the budget, so the result keeps as much detail as the budget allows. A mesh within the
    /// budget is returned unchanged. Meant for drawing, not for collision.
    pub fn decimated(&self, max_triangles: usize) -> Mesh {
        if self.triangles.len() <= max_triangles {
            return self.clone();
        }
        let Some((lo, hi)) = self.aabb() else {
            return self.clone();
        };
        let longest = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        // More cells per side keep more triangles; the count is monotone enough to bisect on.
        let (mut few, mut many) = (1usize, 2usize);
        let mut best = self.clustered(lo, longest, 1);
        loop {
            let m = self.clustered(lo, longest, many);
            if m.triangles.len() > max_triangles || many >= 1 << 16 {
                break;
            }
            (few, best) = (many, m);
            many *= 2;
        }
        while many - few > 1 {
            let mid = (few + many) / 2;
            let m = self.clustered(lo, longest, mid);
            if m.triangles.len() <= max_triangles {
                (few, best) = (mid, m);
            } else {
                many = mid;
            }
        }
        best
    }

    /// Vertex clustering on a grid of `n` cells along the longest side (see [`Mesh::decimated`]).
    fn clustered(&self, lo: DVec3, longest: f64, n: usize) -> Mesh {
        let size = longest / n as f64;
        let key = |v: DVec3| {
            let c = ((v - lo) / size).floor();
            let clamp = |x: f64| (x.max(0.0) as i64).min(n as i64);
            (clamp(c.x), clamp(c.y), clamp(c.z))
        };
        let mut cells: HashMap<(i64, i64, i64), u32> = HashMap::new();
        let mut sums: Vec<(DVec3, usize)> = Vec::new();
        let index: Vec<u32> = self
            .vertices
            .iter()
            .map(|&v| {
                let next = sums.len() as u32;
                let i = *cells.entry(key(v)).or_insert(next);
                if i == next {
                    sums.push((DVec3::ZERO, 0));
                }
                let s = &mut sums[i as usize];
                s.0 += v;
                s.1 += 1;
                i
            })
            .collect();
        let mut seen = std::collections::HashSet::new();
        let mut triangles = Vec::new();
        for t in &self.triangles {
            let [a, b, c] = t.map(|k| index[k as usize]);
            if a == b || b == c || a == c {
                continue;
            }
            // The same triangle in either winding is drawn once (keyed by its sorted corners).
            let mut sorted = [a, b, c];
            sorted.sort_unstable();
            if seen.insert(sorted) {
                triangles.push([a, b, c]);
            }
        }
        // Keep only the vertices some triangle still uses, in first-use order.
        let mut remap = vec![u32::MAX; sums.len()];
        let mut vertices = Vec::new();
        for t in &mut triangles {
            for k in t.iter_mut() {
                if remap[*k as usize] == u32::MAX {
                    remap[*k as usize] = vertices.len() as u32;
                    let (sum, count) = sums[*k as usize];
                    vertices.push(sum / count as f64);
                }
                *k = remap[*k as usize];
            }
        }
        Mesh { vertices, triangles }
    }

    /// The three corners of triangle `i`.
    ///
    /// # Panics
    /// If `i` or one of the triangle's indices is out of range.
    pub fn corners(&self, i: usize) -> [DVec3; 3] {
        self.triangles[i].map(|k| self.vertices[k as usize])
    }
}

mod obj;
mod stl;
#[cfg(test)]
mod tests;

pub use obj::parse_obj;
pub use stl::parse_stl;

/// Loads a mesh by extension: `.stl` (binary or ASCII) or `.obj`. Units are those of the file.
pub fn load_mesh(path: &Path) -> Result<Mesh, MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let parse: fn(&[u8], &Path) -> Result<Mesh, MeshError> = match ext.as_deref() {
        Some("stl") => parse_stl,
        Some("obj") => parse_obj,
        _ => {
            return Err(MeshError::Unsupported {
                path: path.to_path_buf(),
            });
        }
    };
    let bytes = read_file(path, MAX_FILE_BYTES)?;
    parse(&bytes, path)
}

/// The bytes of `path`, at most `limit` of them (see [`crate::read`]).
fn read_file(path: &Path, limit: u64) -> Result<Vec<u8>, MeshError> {
    read_limited(path, limit).map_err(|e| match e {
        LimitedReadError::Io(source) => MeshError::Io {
            path: path.to_path_buf(),
            source,
        },
        LimitedReadError::TooLarge { size } => parse_err(
            path,
            None,
            format!(
                "the file is {size}, larger than the {} a mesh file may have: check that the \
                 path names a mesh, or decimate the mesh (collision needs far fewer triangles)",
                show_bytes(limit)
            ),
        ),
    })
}

/// Drops the vertices no triangle uses, keeping the order of the others.
fn compact(vertices: Vec<DVec3>, mut triangles: Vec<[u32; 3]>) -> Mesh {
    let mut map = vec![u32::MAX; vertices.len()];
    for t in &triangles {
        for &i in t {
            map[i as usize] = 0;
        }
    }
    let mut kept = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.into_iter().enumerate() {
        if map[i] == 0 {
            map[i] = kept.len() as u32;
            kept.push(v);
        }
    }
    for t in &mut triangles {
        *t = t.map(|i| map[i as usize]);
    }
    Mesh {
        vertices: kept,
        triangles,
    }
}

/// Adds a triangle unless two of its corners are at the same point (the same vertex, or in
/// OBJ two vertices at the same position; STL welds those into one vertex).
fn push_triangle(triangles: &mut Vec<[u32; 3]>, vertices: &[DVec3], [a, b, c]: [u32; 3]) {
    let at = |k: u32| vertices[k as usize];
    if a != b && b != c && a != c && at(a) != at(b) && at(b) != at(c) && at(a) != at(c) {
        triangles.push([a, b, c]);
    }
}

/// The check every loader ends with: at least one triangle, and not all of zero area (each
/// corner on the line through the other two, to rounding relative to the mesh's size).
fn check_area(vertices: &[DVec3], triangles: &[[u32; 3]], path: &Path) -> Result<(), MeshError> {
    let corners = |t: &[u32; 3]| t.map(|k| vertices[k as usize]);
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for t in triangles {
        for v in corners(t) {
            (lo, hi) = (lo.min(v), hi.max(v));
        }
    }
    let size = (hi - lo).max_element();
    // Twice the area of a triangle whose corners are off a line by rounding only.
    let flat = size * size * 1e-12;
    let has_area = triangles.iter().any(|t| {
        let [a, b, c] = corners(t);
        (b - a).cross(c - a).length() > flat
    });
    if has_area { Ok(()) } else { Err(empty_error(path)) }
}

/// The message for a coordinate beyond [`MAX_COORDINATE`].
fn too_far(c: f64) -> String {
    format!(
        "{c:e} exceeds {MAX_COORDINATE:e} in magnitude — is the unit right? (coordinates are \
         in the file's units, and {MAX_COORDINATE:e} mm is already a kilometre); fix the export units \
         or re-export the mesh"
    )
}

fn number(word: &str, path: &Path, line: usize, what: &str) -> Result<f64, MeshError> {
    match word.parse::<f64>() {
        Ok(x) if x.is_finite() && x.abs() > MAX_COORDINATE => {
            Err(parse_err(path, Some(line), format!("{what} {}", too_far(x))))
        }
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(parse_err(
            path,
            Some(line),
            format!("{what} `{word}` is not finite: fix or re-export the mesh"),
        )),
        Err(_) => {
            let shown: String = word.chars().take(24).collect();
            Err(parse_err(
                path,
                Some(line),
                format!("{what} `{shown}` is not a number: the file is damaged or not a mesh of this format"),
            ))
        }
    }
}

fn empty_error(path: &Path) -> MeshError {
    parse_err(
        path,
        None,
        "the mesh has no triangles (or only degenerate ones, of zero area): check that the right \
         file was exported, with its surfaces"
            .into(),
    )
}

fn parse_err(path: &Path, line: Option<usize>, message: String) -> MeshError {
    MeshError::Parse {
        path: PathBuf::from(path),
        line,
        message,
    }
}

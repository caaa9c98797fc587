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
    let bytes = read_bounded(path, MAX_FILE_BYTES)?;
    parse(&bytes, path)
}

/// The bytes of `path`, at most `limit` of them. A regular file larger than `limit` is refused
/// before reading; anything else (a pipe, `/dev/zero`) is read up to `limit + 1` bytes and
/// refused if it has more.
fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, MeshError> {
    use std::io::Read as _;
    let io = |source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    };
    let too_large = |size: String| {
        let shown = if limit.is_multiple_of(1 << 20) {
            format!("{} MiB", limit >> 20)
        } else {
            format!("{limit} bytes")
        };
        parse_err(
            path,
            None,
            format!(
                "the file is {size}, larger than the {shown} a mesh file may have: check that the \
                 path names a mesh, or decimate the mesh (collision needs far fewer triangles)"
            ),
        )
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let stated = file.metadata().ok().filter(|m| m.is_file()).map(|m| m.len());
    if let Some(len) = stated
        && len > limit
    {
        return Err(too_large(format!("{len} bytes")));
    }
    // `stated <= limit` here, so the reservation is bounded.
    let mut bytes = Vec::with_capacity(stated.map_or(0, |l| l as usize + 1));
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(too_large(format!("more than {limit} bytes")));
    }
    Ok(bytes)
}

/// Parses the bytes of an STL file, binary or ASCII (`path` only names the file in errors).
pub fn parse_stl(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    let header_count = bytes
        .get(80..84)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64);
    let body_len = (bytes.len() as u64).saturating_sub(84);
    if let Some(n) = header_count
        && 84 + 50 * n == bytes.len() as u64
    {
        return parse_binary_stl(bytes, n as usize, path);
    }
    let starts_solid = {
        let start = bytes.iter().position(|b| !b.is_ascii_whitespace());
        start.is_some_and(|s| bytes[s..].starts_with(b"solid"))
    };
    if starts_solid {
        let ascii = parse_ascii_stl(bytes, path);
        // A binary file whose header starts with "solid" but whose size is off: when the text
        // reading fails on what is clearly not text, read it as binary (and diagnose it so).
        if ascii.is_ok() || looks_like_text(bytes) || header_count.is_none() {
            return ascii;
        }
    }
    match header_count {
        None => Err(parse_err(
            path,
            None,
            format!(
                "the file has only {} bytes: a binary STL has at least 84 (an 80-byte header and \
                 a triangle count) and an ASCII STL starts with `solid`; re-export it from CAD",
                bytes.len()
            ),
        )),
        // Some exporters leave the count at zero: take the triangles the size implies.
        Some(0) if body_len > 0 && body_len.is_multiple_of(50) => {
            parse_binary_stl(bytes, (body_len / 50) as usize, path)
        }
        // Trailing bytes after the last triangle are tolerated.
        Some(n) if 50 * n < body_len => parse_binary_stl(bytes, n as usize, path),
        Some(n) => Err(binary_size_error(n, body_len, path)),
    }
}

/// Parses the bytes of a Wavefront OBJ file (`path` only names the file in errors).
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    let mut vertices: Vec<DVec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut face: Vec<u32> = Vec::new();
    for (k, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line_no = k + 1;
        let text = String::from_utf8_lossy(raw);
        let text = text.split('#').next().unwrap_or("");
        let mut words = text.split_ascii_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        match keyword {
            "v" => {
                let mut xyz = [0.0; 3];
                for (i, c) in xyz.iter_mut().enumerate() {
                    let word = words.next().ok_or_else(|| {
                        parse_err(
                            path,
                            Some(line_no),
                            format!("a vertex needs three coordinates `v x y z`, this one has {i}"),
                        )
                    })?;
                    *c = number(word, path, line_no, "vertex coordinate")?;
                }
                // An optional weight `w` (and, in some exporters, a colour) follow: ignored.
                vertices.push(DVec3::from_array(xyz));
            }
            "f" => {
                face.clear();
                for word in words {
                    face.push(obj_index(word, vertices.len(), path, line_no)?);
                }
                if face.len() < 3 {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        format!(
                            "a face needs at least three vertices, this one has {}",
                            face.len()
                        ),
                    ));
                }
                for i in 1..face.len() - 1 {
                    push_triangle(&mut triangles, &vertices, [face[0], face[i], face[i + 1]]);
                }
            }
            // Texture coordinates, normals, groups, objects, smoothing, materials, lines,
            // points and free-form geometry play no part in collision.
            _ => {}
        }
    }
    check_area(&vertices, &triangles, path)?;
    Ok(compact(vertices, triangles))
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

/// Resolves one OBJ face corner (`a`, `a/b`, `a//c`, `a/b/c`) to a 0-based vertex index.
fn obj_index(word: &str, defined: usize, path: &Path, line: usize) -> Result<u32, MeshError> {
    let first = word.split('/').next().unwrap_or("");
    let i: i64 = first.parse().map_err(|_| {
        parse_err(
            path,
            Some(line),
            format!("`{word}` is not a face corner: expected a vertex number such as `12`, `12/5`, `12//7` or `-3`"),
        )
    })?;
    let resolved = if i > 0 {
        i - 1
    } else if i < 0 {
        defined as i64 + i
    } else {
        return Err(parse_err(
            path,
            Some(line),
            "face refers to vertex 0, but OBJ vertex numbers start at 1".to_string(),
        ));
    };
    if resolved < 0 || resolved >= defined as i64 {
        let message = if i > 0 {
            format!("face refers to vertex {i} but only {defined} are defined")
        } else {
            format!(
                "face refers to vertex {i} (counting back from the last) but only {defined} are defined before it"
            )
        };
        return Err(parse_err(
            path,
            Some(line),
            format!("{message}: the file is truncated or was exported with separate files per part"),
        ));
    }
    u32::try_from(resolved)
        .map_err(|_| parse_err(path, Some(line), "too many vertices (more than 4 billion)".into()))
}

fn parse_binary_stl(bytes: &[u8], n: usize, path: &Path) -> Result<Mesh, MeshError> {
    let mut weld = Welder::with_capacity(n / 2 + 3);
    let mut triangles = Vec::with_capacity(n);
    for (k, rec) in bytes[84..84 + 50 * n].chunks_exact(50).enumerate() {
        let f = |o: usize| f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64;
        let mut tri = [0u32; 3];
        for (c, idx) in tri.iter_mut().enumerate() {
            let base = 12 + 12 * c;
            let v = DVec3::new(f(base), f(base + 4), f(base + 8));
            if !v.is_finite() {
                return Err(parse_err(
                    path,
                    None,
                    format!(
                        "triangle {} of {n} has a non-finite coordinate ({v}): re-export the mesh from CAD",
                        k + 1
                    ),
                ));
            }
            if let Some(c) = v.to_array().into_iter().find(|c| c.abs() > MAX_COORDINATE) {
                return Err(parse_err(
                    path,
                    None,
                    format!("triangle {} of {n}: coordinate {}", k + 1, too_far(c)),
                ));
            }
            *idx = weld.index(v);
        }
        push_triangle(&mut triangles, &weld.vertices, tri);
    }
    check_area(&weld.vertices, &triangles, path)?;
    Ok(Mesh {
        vertices: weld.vertices,
        triangles,
    })
}

fn parse_ascii_stl(bytes: &[u8], path: &Path) -> Result<Mesh, MeshError> {
    let mut weld = Welder::with_capacity(1024);
    let mut triangles = Vec::new();
    // Corners of the current facet; `None` outside a facet.
    let mut facet: Option<Vec<u32>> = None;
    let mut facet_line = 0;
    for (k, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let line_no = k + 1;
        let text = String::from_utf8_lossy(raw);
        let mut words = text.split_ascii_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        match keyword {
            "solid" | "endsolid" | "outer" | "endloop" => {}
            "facet" => {
                if facet.is_some() {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        format!(
                            "`facet` inside the facet begun on line {facet_line}: an `endfacet` is missing"
                        ),
                    ));
                }
                facet = Some(Vec::with_capacity(3));
                facet_line = line_no;
            }
            "vertex" => {
                let Some(corners) = facet.as_mut() else {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        "`vertex` outside a facet: expected `facet normal ...` first".into(),
                    ));
                };
                let mut xyz = [0.0; 3];
                for (i, c) in xyz.iter_mut().enumerate() {
                    let word = words.next().ok_or_else(|| {
                        parse_err(
                            path,
                            Some(line_no),
                            format!("a vertex needs three coordinates `vertex x y z`, this one has {i}"),
                        )
                    })?;
                    *c = number(word, path, line_no, "vertex coordinate")?;
                }
                corners.push(weld.index(DVec3::from_array(xyz)));
            }
            "endfacet" => {
                let Some(corners) = facet.take() else {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        "`endfacet` without a `facet`".into(),
                    ));
                };
                if corners.len() < 3 {
                    return Err(parse_err(
                        path,
                        Some(line_no),
                        format!(
                            "the facet begun on line {facet_line} has {} vertices; a facet needs three",
                            corners.len()
                        ),
                    ));
                }
                for i in 1..corners.len() - 1 {
                    push_triangle(
                        &mut triangles,
                        &weld.vertices,
                        [corners[0], corners[i], corners[i + 1]],
                    );
                }
            }
            other => {
                let shown: String = other.chars().take(24).collect();
                return Err(parse_err(
                    path,
                    Some(line_no),
                    format!(
                        "unexpected `{shown}` in an ASCII STL (expected `solid`, `facet`, `outer loop`, \
                         `vertex`, `endloop`, `endfacet` or `endsolid`): the file is damaged or not an STL"
                    ),
                ));
            }
        }
    }
    if facet.is_some() {
        return Err(parse_err(
            path,
            Some(facet_line),
            "the file ends inside this facet: it is truncated; re-export it from CAD".into(),
        ));
    }
    check_area(&weld.vertices, &triangles, path)?;
    Ok(Mesh {
        vertices: weld.vertices,
        triangles,
    })
}

/// Welds exactly equal vertices (bit patterns, with `-0.0` taken as `0.0`).
struct Welder {
    vertices: Vec<DVec3>,
    map: HashMap<[u64; 3], u32>,
}

impl Welder {
    fn with_capacity(n: usize) -> Self {
        Welder {
            vertices: Vec::with_capacity(n),
            map: HashMap::with_capacity(n),
        }
    }

    fn index(&mut self, v: DVec3) -> u32 {
        // `+ 0.0` turns -0.0 into 0.0.
        let key = [
            (v.x + 0.0).to_bits(),
            (v.y + 0.0).to_bits(),
            (v.z + 0.0).to_bits(),
        ];
        let next = self.vertices.len() as u32;
        let i = *self.map.entry(key).or_insert(next);
        if i == next {
            self.vertices.push(v + DVec3::ZERO);
        }
        i
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

fn looks_like_text(bytes: &[u8]) -> bool {
    !bytes
        .iter()
        .any(|&b| b == 0 || (b < 0x20 && !b.is_ascii_whitespace()))
}

fn binary_size_error(n: u64, body_len: u64, path: &Path) -> MeshError {
    let whole = body_len / 50;
    parse_err(
        path,
        None,
        format!(
            "truncated binary STL: the header announces {n} triangles ({} bytes) but the file \
             ends after {whole} of {n} triangles: re-export it from CAD",
            84 + 50 * n
        ),
    )
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A flat square grid of `n` × `n` cells, two triangles each, on z = 0.
    fn grid(n: u32) -> Mesh {
        let mut m = Mesh::default();
        for j in 0..=n {
            for i in 0..=n {
                m.vertices.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let at = |i: u32, j: u32| j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                m.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                m.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        m
    }

    #[test]
    fn decimation_meets_the_budget_and_keeps_the_shape() {
        let m = grid(100);
        assert_eq!(m.triangles.len(), 20_000);
        let d = m.decimated(2_000);
        assert!(d.triangles.len() <= 2_000, "{}", d.triangles.len());
        // Bisection keeps as much as the budget allows: at least a quarter of it.
        assert!(d.triangles.len() >= 500, "{}", d.triangles.len());
        let (lo, hi) = d.aabb().unwrap();
        assert!(lo.x < 2.0 && lo.y < 2.0 && hi.x > 98.0 && hi.y > 98.0);
        assert!(d.vertices.iter().all(|v| v.z == 0.0));
        // Every vertex is used and every triangle is proper and faces +z like the input.
        let mut used = vec![false; d.vertices.len()];
        for i in 0..d.triangles.len() {
            d.triangles[i].iter().for_each(|&k| used[k as usize] = true);
            assert!(d.triangle_normal(i).z > 0.99);
        }
        assert!(used.iter().all(|&u| u));
        // Within budget: unchanged.
        assert_eq!(m.decimated(20_000), m);
    }

    /// Writes `bytes` to a fresh file named `*.{ext}` in the temp dir.
    fn temp_file(ext: &str, bytes: &[u8]) -> PathBuf {
        static N: AtomicUsize = AtomicUsize::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!("cellplan-geom-test-{}-{n}.{ext}", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        path
    }

    fn load_temp(ext: &str, bytes: &[u8]) -> Result<Mesh, MeshError> {
        let path = temp_file(ext, bytes);
        let result = load_mesh(&path);
        let _ = std::fs::remove_file(&path);
        result
    }

    /// The 12 triangles of the unit cube [0,1]³, outward counter-clockwise.
    fn cube_triangles() -> Vec<[DVec3; 3]> {
        let v = |i: usize| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
        let quads = [
            [0, 2, 3, 1], // z = 0
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        quads
            .iter()
            .flat_map(|q| [[v(q[0]), v(q[1]), v(q[2])], [v(q[0]), v(q[2]), v(q[3])]])
            .collect()
    }

    fn binary_stl(header: &[u8], tris: &[[DVec3; 3]]) -> Vec<u8> {
        let mut out = vec![b' '; 80];
        out[..header.len()].copy_from_slice(header);
        out.extend((tris.len() as u32).to_le_bytes());
        for t in tris {
            out.extend([0u8; 12]);
            for v in t {
                for c in v.to_array() {
                    out.extend((c as f32).to_le_bytes());
                }
            }
            out.extend([0u8; 2]);
        }
        out
    }

    fn ascii_stl(tris: &[[DVec3; 3]]) -> String {
        let mut s = String::from("solid cube\n");
        for t in tris {
            s.push_str("  facet normal 0 0 0\n    outer loop\n");
            for v in t {
                s.push_str(&format!("      vertex {} {} {}\n", v.x, v.y, v.z));
            }
            s.push_str("    endloop\n  endfacet\n");
        }
        s.push_str("endsolid cube\n");
        s
    }

    fn message(e: &MeshError) -> String {
        e.to_string()
    }

    fn assert_unit_cube(m: &Mesh) {
        assert_eq!(m.triangles.len(), 12);
        assert_eq!(m.vertices.len(), 8, "duplicated vertices are welded");
        assert_eq!(m.aabb(), Some((DVec3::ZERO, DVec3::ONE)));
        let area: f64 = (0..12).map(|i| m.triangle_area(i)).sum();
        assert!((area - 6.0).abs() < 1e-12);
        // Outward normals: the normal points away from the centre.
        for i in 0..12 {
            let [a, b, c] = m.corners(i);
            let centre = (a + b + c) / 3.0;
            assert!(m.triangle_normal(i).dot(centre - DVec3::splat(0.5)) > 0.0);
        }
    }

    #[test]
    fn binary_stl_loads_and_welds() {
        let m = load_temp("stl", &binary_stl(b"binary", &cube_triangles())).unwrap();
        assert_unit_cube(&m);
    }

    #[test]
    fn binary_stl_whose_header_says_solid_is_binary() {
        let bytes = binary_stl(b"solid exported by a careless tool", &cube_triangles());
        let m = load_temp("STL", &bytes).unwrap();
        assert_unit_cube(&m);
    }

    #[test]
    fn ascii_stl_loads() {
        let m = load_temp("stl", ascii_stl(&cube_triangles()).as_bytes()).unwrap();
        assert_unit_cube(&m);
    }

    #[test]
    fn truncated_binary_stl_is_diagnosed() {
        let mut bytes = binary_stl(b"x", &cube_triangles());
        bytes.truncate(84 + 50 * 3 + 20);
        let err = load_temp("stl", &bytes).unwrap_err();
        let msg = message(&err);
        assert!(msg.contains("ends after 3 of 12 triangles"), "{msg}");
        assert!(msg.contains("re-export"), "{msg}");
        assert!(matches!(err, MeshError::Parse { line: None, .. }));
        // Also when the header starts with "solid".
        let mut bytes = binary_stl(b"solid x", &cube_triangles());
        bytes.truncate(84 + 50 * 5);
        let msg = message(&load_temp("stl", &bytes).unwrap_err());
        assert!(msg.contains("ends after 5 of 12 triangles"), "{msg}");
    }

    #[test]
    fn binary_stl_with_trailing_bytes_or_zero_count_loads() {
        let mut bytes = binary_stl(b"x", &cube_triangles());
        bytes.extend([0u8; 7]);
        assert_unit_cube(&load_temp("stl", &bytes).unwrap());
        let mut bytes = binary_stl(b"x", &cube_triangles());
        bytes[80..84].copy_from_slice(&0u32.to_le_bytes());
        assert_unit_cube(&load_temp("stl", &bytes).unwrap());
    }

    #[test]
    fn binary_stl_rejects_nan() {
        let mut tris = cube_triangles();
        tris[4][1].y = f64::NAN;
        let msg = message(&load_temp("stl", &binary_stl(b"x", &tris)).unwrap_err());
        assert!(
            msg.contains("triangle 5 of 12") && msg.contains("non-finite"),
            "{msg}"
        );
    }

    #[test]
    fn ascii_stl_bad_number_names_the_line() {
        let text = ascii_stl(&cube_triangles()).replacen("vertex 1 0 0", "vertex 1 0,5 0", 1);
        let line = text.lines().position(|l| l.contains("0,5")).unwrap() + 1;
        let err = load_temp("stl", text.as_bytes()).unwrap_err();
        match &err {
            MeshError::Parse { line: l, message, .. } => {
                assert_eq!(*l, Some(line));
                assert!(message.contains("`0,5` is not a number"), "{message}");
            }
            other => panic!("{other:?}"),
        }
        assert!(message(&err).contains(&format!(":{line}: ")), "{err}");
    }

    #[test]
    fn ascii_stl_structure_errors() {
        let text = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n";
        let err = load_temp("stl", text.as_bytes()).unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(7), .. }), "{err}");
        assert!(message(&err).contains("has 2 vertices"), "{err}");

        let text = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n";
        let err = load_temp("stl", text.as_bytes()).unwrap_err();
        assert!(message(&err).contains("truncated"), "{err}");

        let text = "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 inf\n";
        let err = load_temp("stl", text.as_bytes()).unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(4), .. }), "{err}");
        assert!(message(&err).contains("not finite"), "{err}");

        let text = "solid a\nbanana\n";
        let err = load_temp("stl", text.as_bytes()).unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(2), .. }), "{err}");
    }

    #[test]
    fn empty_files_are_rejected() {
        let err = load_temp("stl", b"").unwrap_err();
        assert!(message(&err).contains("only 0 bytes"), "{err}");
        let err = load_temp("stl", b"solid empty\nendsolid empty\n").unwrap_err();
        assert!(message(&err).contains("no triangles"), "{err}");
        let err = load_temp("stl", &binary_stl(b"x", &[])).unwrap_err();
        assert!(message(&err).contains("no triangles"), "{err}");
        let err = load_temp("obj", b"").unwrap_err();
        assert!(message(&err).contains("no triangles"), "{err}");
        let err = load_temp("obj", b"# only vertices\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap_err();
        assert!(message(&err).contains("no triangles"), "{err}");
    }

    #[test]
    fn obj_quads_negative_indices_and_corner_forms() {
        let text = "\
# a unit square and a triangle
mtllib x.mtl
o square
v 0 0 0
v 1 0 0 1.0
v 1 1 0
v 0 1 0
vt 0 0
vn 0 0 1
g g1
s off
usemtl red
f 1/1/1 2/1/1 3//1 4
o tri
v 5 5 5
v 6 5 5
v 5 6 5
f -3 -2/1 -1//1
v 9 9 9
";
        let m = load_temp("obj", text.as_bytes()).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]]);
        // The last vertex is not used by any face: dropped.
        assert_eq!(m.vertices.len(), 7);
        assert_eq!(m.vertices[4], DVec3::splat(5.0));
        assert_eq!(m.triangle_normal(0), DVec3::Z);
        assert!((m.triangle_area(1) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn obj_pentagon_is_fan_triangulated() {
        let text = "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\nf 1 2 3 4 5\n";
        let m = load_temp("obj", text.as_bytes()).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }

    #[test]
    fn obj_index_errors_name_the_line() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\nf 1 2 9\n";
        let err = load_temp("obj", text.as_bytes()).unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(6), .. }), "{err}");
        assert!(
            message(&err).contains("face refers to vertex 9 but only 4 are defined"),
            "{err}"
        );
        let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nf 1 2 -3\n").unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(3), .. }), "{err}");
        let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf 0 1 2\n").unwrap_err();
        assert!(message(&err).contains("start at 1"), "{err}");
        let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 x/2 3\n").unwrap_err();
        assert!(message(&err).contains("`x/2` is not a face corner"), "{err}");
        let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nf 1 2\n").unwrap_err();
        assert!(message(&err).contains("at least three"), "{err}");
    }

    #[test]
    fn obj_bad_vertices_name_the_line() {
        let err = load_temp("obj", b"v 0 0 0\nv 1 0\n").unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(2), .. }), "{err}");
        assert!(message(&err).contains("three coordinates"), "{err}");
        let err = load_temp("obj", b"v 0 0 0\n\n\nv 1 nan 0\n").unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(4), .. }), "{err}");
        let err = load_temp("obj", b"v 0 0 0\nv 1 1.0.0 0\n").unwrap_err();
        assert!(message(&err).contains("`1.0.0` is not a number"), "{err}");
    }

    #[test]
    fn zero_area_meshes_are_refused_alike_in_obj_and_stl() {
        // Two corners at the same point: STL welds them and drops the triangle; OBJ now too.
        let point = [DVec3::ZERO, DVec3::ZERO, DVec3::X];
        // Corners on one line: every triangle has zero area.
        let line = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        for tri in [point, line] {
            let obj: String = tri
                .iter()
                .map(|v| format!("v {} {} {}\n", v.x, v.y, v.z))
                .chain(["f 1 2 3\nf 3 2 1\n".to_string()])
                .collect();
            for (ext, bytes) in [
                ("obj", obj.into_bytes()),
                ("stl", ascii_stl(&[tri, tri]).into_bytes()),
                ("stl", binary_stl(b"x", &[tri, tri])),
            ] {
                let err = load_temp(ext, &bytes).unwrap_err();
                assert!(matches!(err, MeshError::Parse { line: None, .. }), "{ext}: {err}");
                assert!(
                    message(&err).contains("only degenerate ones, of zero area"),
                    "{ext}: {err}"
                );
            }
        }
        // One proper triangle among degenerate ones is a mesh; the OBJ one at a repeated
        // point is dropped as STL drops it.
        let m = load_temp("obj", b"v 0 0 0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn far_coordinates_are_refused_with_line_or_triangle() {
        let err = load_temp("obj", b"v 0 0 0\nv 1 0 0\nv 0 1e30 0\nf 1 2 3\n").unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(3), .. }), "{err}");
        let msg = message(&err);
        assert!(
            msg.contains("vertex coordinate 1e30 exceeds 1e6 in magnitude — is the unit right?"),
            "{msg}"
        );
        let text = ascii_stl(&cube_triangles()).replacen("vertex 1 0 0", "vertex 1 -2e6 0", 1);
        let line = text.lines().position(|l| l.contains("-2e6")).unwrap() + 1;
        let err = load_temp("stl", text.as_bytes()).unwrap_err();
        assert!(
            matches!(err, MeshError::Parse { line: Some(l), .. } if l == line),
            "{err}"
        );
        assert!(message(&err).contains("-2e6 exceeds 1e6"), "{err}");
        let mut tris = cube_triangles();
        tris[6][2].z = 1e30;
        let err = load_temp("stl", &binary_stl(b"x", &tris)).unwrap_err();
        let msg = message(&err);
        assert!(
            msg.contains("triangle 7 of 12: coordinate 1.0000000150474662e30 exceeds 1e6"),
            "{msg}"
        );
        // Infinity in a binary STL (NaN is covered above) and in OBJ.
        tris[6][2].z = f64::INFINITY;
        let msg = message(&load_temp("stl", &binary_stl(b"x", &tris)).unwrap_err());
        assert!(msg.contains("triangle 7 of 12 has a non-finite"), "{msg}");
        let err = load_temp("obj", b"v 0 0 0\nv -inf 0 0\n").unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: Some(2), .. }), "{err}");
        // Exactly at the limit is fine.
        let m = load_temp("obj", b"v 0 0 0\nv 1e6 0 0\nv 0 -1e6 0\nf 1 2 3\n").unwrap();
        assert_eq!(m.triangles.len(), 1);
    }

    #[test]
    fn oversized_mesh_files_are_refused_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.stl");
        // Sparse: no disk used, but its size is over the limit.
        std::fs::File::create(&path)
            .unwrap()
            .set_len(MAX_FILE_BYTES + 1)
            .unwrap();
        let err = load_mesh(&path).unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: None, .. }), "{err}");
        let msg = message(&err);
        assert!(msg.contains("huge.stl"), "{msg}");
        assert!(
            msg.contains("the file is 1073741825 bytes, larger than the 1024 MiB a mesh file may have"),
            "{msg}"
        );
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn endless_input_is_read_only_to_the_limit() {
        let err = read_bounded(Path::new("/dev/zero"), 4096).unwrap_err();
        assert!(matches!(err, MeshError::Parse { line: None, .. }), "{err}");
        assert!(
            message(&err)
                .starts_with("/dev/zero: the file is more than 4096 bytes, larger than the 4096 bytes"),
            "{err}"
        );
        // By extension it is no mesh at all.
        let err = load_mesh(Path::new("/dev/zero")).unwrap_err();
        assert!(matches!(err, MeshError::Unsupported { .. }), "{err}");
    }

    #[test]
    fn unsupported_and_missing_files() {
        let err = load_mesh(Path::new("part.step")).unwrap_err();
        assert!(matches!(err, MeshError::Unsupported { .. }), "{err}");
        let err = load_mesh(Path::new("/nonexistent/dir/part.stl")).unwrap_err();
        assert!(matches!(err, MeshError::Io { .. }), "{err}");
        assert!(message(&err).contains("/nonexistent/dir/part.stl"));
    }

    #[test]
    fn mesh_methods() {
        let m = Mesh {
            vertices: vec![DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 3.0, 0.0)],
            triangles: vec![[0, 1, 2], [0, 0, 1]],
        };
        assert_eq!(Mesh::default().aabb(), None);
        assert_eq!(m.aabb(), Some((DVec3::ZERO, DVec3::new(2.0, 3.0, 0.0))));
        assert!((m.triangle_area(0) - 3.0).abs() < 1e-15);
        assert_eq!(m.triangle_normal(0), DVec3::Z);
        assert_eq!(m.triangle_normal(1), DVec3::ZERO);
        assert_eq!(m.triangle_area(1), 0.0);
        let s = m.scaled(0.001);
        assert_eq!(s.vertices[2], DVec3::new(0.0, 0.003, 0.0));
        assert_eq!(s.triangles, m.triangles);
        let pose = Pose::from_parts(
            DVec3::new(1.0, 0.0, 0.0),
            crate::DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2),
        );
        let t = m.transformed(&pose);
        assert!((t.vertices[1] - DVec3::new(1.0, 2.0, 0.0)).length() < 1e-12);
        assert!((t.triangle_area(0) - 3.0).abs() < 1e-12);
    }

    fn data_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
    }

    #[test]
    fn real_fanuc_links_load() {
        let dir = data_dir().join("robots/fanuc_r2000ic/fanuc_r2000ic_support/meshes/r2000ic125l/collision");
        let mut names = 0;
        for link in [
            "base_link",
            "link_1",
            "link_2",
            "link_3",
            "link_4",
            "link_5",
            "link_6",
        ] {
            let path = dir.join(format!("{link}.stl"));
            let size = std::fs::metadata(&path).unwrap().len() as usize;
            let facets = (size - 84) / 50;
            let m = load_mesh(&path).unwrap();
            assert!(
                m.triangles.len() <= facets && m.triangles.len() * 100 >= facets * 99,
                "{link}"
            );
            // Closed collision meshes: V − E + F = 2 → V ≈ F/2 + 2 once welded.
            assert!(m.vertices.len() < m.triangles.len(), "{link}: not welded");
            let (lo, hi) = m.aabb().unwrap();
            let ext = hi - lo;
            assert!(
                ext.max_element() < 2.0 && ext.max_element() > 0.1,
                "{link}: {ext} (metres?)"
            );
            names += 1;
        }
        assert_eq!(names, 7);
        let m = load_mesh(&dir.join("link_3.stl")).unwrap();
        assert_eq!((m.triangles.len(), m.vertices.len()), (560, 282));
    }

    #[test]
    fn real_car_body_loads() {
        let m = load_mesh(&data_dir().join("parts/body-in-white/car5.obj")).unwrap();
        assert_eq!(m.triangles.len(), 6931);
        assert_eq!(m.vertices.len(), 9752, "only the vertices faces use");
        let (lo, hi) = m.aabb().unwrap();
        let ext = hi - lo;
        assert!((ext.x - 1735.883).abs() < 0.01, "{ext}");
        assert!((ext.y - 4365.222).abs() < 0.01, "{ext}");
        assert!((ext.z - 1124.928).abs() < 0.01, "{ext}");
    }
}

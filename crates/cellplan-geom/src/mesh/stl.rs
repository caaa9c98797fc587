//! STL, binary or ASCII.
use super::{MAX_COORDINATE, Mesh, check_area, number, parse_err, push_triangle, too_far};
use crate::{DVec3, MeshError};
use std::collections::HashMap;
use std::path::Path;

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

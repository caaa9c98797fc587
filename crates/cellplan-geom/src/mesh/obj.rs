//! Wavefront OBJ.
use super::{Mesh, check_area, compact, number, parse_err, push_triangle};
use crate::{DVec3, MeshError};
use std::path::Path;

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

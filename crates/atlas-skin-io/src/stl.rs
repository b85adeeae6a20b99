//! STL triangle soups, ASCII and binary; corners at exactly the same position become one
//! vertex.

use crate::text::{read_bytes, Tokens};
use crate::{IoError, TriangleMesh};
use glam::Vec3;
use std::collections::HashMap;
use std::path::Path;

/// Size of the binary header: 80 bytes of text, then the u32 triangle count.
const BINARY_HEADER: usize = 84;
/// Size of one binary triangle record: normal, three corners (f32 × 12), attribute u16.
const BINARY_TRIANGLE: usize = 50;

/// Reads the STL at `path`. A file is binary when its size is exactly
/// 84 + 50 × (the triangle count in its header), otherwise ASCII when it is UTF-8 text
/// starting with `solid` (binary files may start with `solid` too).
pub fn read(path: &Path) -> Result<TriangleMesh, IoError> {
    let bytes = read_bytes(path)?;
    let binary_count = (bytes.len() >= BINARY_HEADER)
        .then(|| u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize);
    let corners = match binary_count {
        Some(count) if bytes.len() == BINARY_HEADER + BINARY_TRIANGLE * count => {
            read_binary(path, &bytes[BINARY_HEADER..])?
        }
        _ if bytes.starts_with(b"solid") && std::str::from_utf8(&bytes).is_ok() => {
            read_ascii(path, &String::from_utf8_lossy(&bytes))?
        }
        Some(count) => {
            return Err(IoError::invalid(
                path,
                format!(
                    "binary STL header announces {count} triangles ({} bytes) but the file has {} bytes",
                    BINARY_HEADER as u64 + BINARY_TRIANGLE as u64 * count as u64,
                    bytes.len()
                ),
            ))
        }
        None => return Err(IoError::invalid(path, "too short for an STL file")),
    };
    Ok(merge_corners(&corners))
}

/// Corner positions of binary triangle records, three per triangle.
fn read_binary(path: &Path, records: &[u8]) -> Result<Vec<Vec3>, IoError> {
    let mut corners = Vec::with_capacity(records.len() / BINARY_TRIANGLE * 3);
    for (triangle, record) in records.chunks_exact(BINARY_TRIANGLE).enumerate() {
        for corner in 0..3 {
            let start = 12 + corner * 12;
            let value = |k: usize| {
                let at = start + 4 * k;
                f32::from_le_bytes([record[at], record[at + 1], record[at + 2], record[at + 3]])
            };
            let p = Vec3::new(value(0), value(1), value(2));
            if !p.is_finite() {
                return Err(IoError::invalid(
                    path,
                    format!("triangle {triangle} has a non-finite corner {p}"),
                ));
            }
            corners.push(p);
        }
    }
    Ok(corners)
}

/// Corner positions of the `vertex` lines of an ASCII STL; every `outer loop` must have 3.
fn read_ascii(path: &Path, text: &str) -> Result<Vec<Vec3>, IoError> {
    let mut tokens = Tokens::new(path, text, None);
    let mut corners = Vec::new();
    let mut in_loop = 0;
    while let Some(token) = tokens.next_token() {
        match token {
            "vertex" => {
                corners.push(tokens.point()?);
                in_loop += 1;
            }
            "endloop" => {
                if in_loop != 3 {
                    return Err(tokens.error(format!("facet has {in_loop} vertices, 3 needed")));
                }
                in_loop = 0;
            }
            _ => {}
        }
    }
    if in_loop != 0 {
        return Err(tokens.error("the file ends inside a facet"));
    }
    Ok(corners)
}

/// One vertex per distinct position (compared bit for bit, with −0 = +0), in order of first
/// appearance, and the triangles over them.
fn merge_corners(corners: &[Vec3]) -> TriangleMesh {
    let mut mesh = TriangleMesh::default();
    let mut index_of: HashMap<[u32; 3], u32> = HashMap::new();
    let indices: Vec<u32> = corners
        .iter()
        .map(|&p| {
            let key = (p + Vec3::ZERO).to_array().map(f32::to_bits);
            *index_of.entry(key).or_insert_with(|| {
                mesh.positions.push(p);
                mesh.positions.len() as u32 - 1
            })
        })
        .collect();
    mesh.triangles = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;

    const ASCII: &str =
        "solid square\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
        vertex 1 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n\
        vertex 1 1 0\nvertex 0 1 -0\nendloop\nendfacet\nendsolid square\n";

    fn binary(triangles: &[[Vec3; 3]]) -> Vec<u8> {
        let mut bytes = b"solid but binary".to_vec();
        bytes.resize(80, b' ');
        bytes.extend((triangles.len() as u32).to_le_bytes());
        for t in triangles {
            bytes.extend([0u8; 12]);
            for p in t {
                for c in p.to_array() {
                    bytes.extend(c.to_le_bytes());
                }
            }
            bytes.extend([0u8; 2]);
        }
        bytes
    }

    #[test]
    fn ascii_and_binary_merge_equal_corners() {
        let ascii = read(&scratch_file("square.stl", ASCII)).unwrap();
        assert_eq!(ascii.positions.len(), 4);
        assert_eq!(ascii.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let (a, b, c, d) = (Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
        let binary = read(&scratch_file(
            "square-bin.stl",
            binary(&[[a, b, c], [a, c, d]]),
        ))
        .unwrap();
        assert_eq!(binary, ascii);
    }

    #[test]
    fn broken_files_are_errors() {
        let mut wrong_size = binary(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        wrong_size.pop();
        wrong_size[20] = 0xff; // not UTF-8, so not mistaken for ASCII
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (b"abc".to_vec(), "too short"),
            (
                wrong_size,
                "announces 1 triangles (134 bytes) but the file has 133 bytes",
            ),
            (
                binary(&[[Vec3::ZERO, Vec3::X, Vec3::NAN]]),
                "triangle 0 has a non-finite corner",
            ),
            (
                ASCII.replace("vertex 1 0 0\n", "").into_bytes(),
                ":6: facet has 2 vertices",
            ),
            (
                b"solid x\nouter loop\nvertex 0 0 0\n".to_vec(),
                "ends inside a facet",
            ),
        ];
        for (i, (bytes, expected)) in cases.into_iter().enumerate() {
            let error = read(&scratch_file(&format!("bad{i}.stl"), bytes)).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

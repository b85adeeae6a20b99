//! Wavefront OBJ meshes: `v` positions and `f` polygons, fan-triangulated, optionally only
//! the faces of one `g`/`o` group.

use crate::text::{
    check_index, is_plain_ascii, parse_field, parse_point, read_text, uncommented_lines, Words,
};
use crate::{IoError, TriangleMesh};
use std::path::Path;

/// Reads the OBJ at `path`: every `v` of the file (file order, so indices into the file's
/// vertex list stay valid) and the triangles of the kept faces.
///
/// A polygon `v0 v1 … vn` becomes the fan `(v0, vi, vi+1)`. Face corners may be `v`,
/// `v/vt`, `v//vn` or `v/vt/vn`; negative indices count back from the last vertex defined.
/// With `group`, only faces under a `g` (or `o`) statement naming it are kept; an unknown
/// group is an error listing the file's groups.
pub fn read(path: &Path, group: Option<&str>) -> Result<TriangleMesh, IoError> {
    let text = read_text(path)?;
    let ascii = is_plain_ascii(&text);
    let mut mesh = TriangleMesh::default();
    let mut groups: Vec<String> = Vec::new();
    let mut in_group = group.is_none();
    // The corners of the current face (one buffer for every face).
    let mut corners: Vec<u32> = Vec::new();
    for (index, content) in uncommented_lines(&text, '#').enumerate() {
        let line = index + 1;
        let mut tokens = Words::of(content, ascii);
        match tokens.next() {
            Some("v") => mesh.positions.push(parse_point(path, line, &mut tokens)?),
            Some("f") => {
                corners.clear();
                for corner in tokens {
                    corners.push(parse_corner(path, line, corner, mesh.positions.len())?);
                }
                if corners.len() < 3 {
                    return Err(IoError::syntax(
                        path,
                        line,
                        format!("face has {} vertices, at least 3 needed", corners.len()),
                    ));
                }
                if in_group {
                    for i in 1..corners.len() - 1 {
                        mesh.triangles
                            .push([corners[0], corners[i], corners[i + 1]]);
                    }
                }
            }
            Some("g" | "o") => {
                let names: Vec<&str> = tokens.collect();
                for name in &names {
                    if !groups.iter().any(|g| g == name) {
                        groups.push(name.to_string());
                    }
                }
                if let Some(wanted) = group {
                    in_group = names.contains(&wanted);
                }
            }
            _ => {}
        }
    }
    if let Some(wanted) = group {
        if !groups.iter().any(|g| g == wanted) {
            let listed = if groups.is_empty() {
                "the file has no groups".to_string()
            } else {
                format!("groups in the file: {}", groups.join(", "))
            };
            return Err(IoError::invalid(
                path,
                format!("no group named {wanted:?} ({listed})"),
            ));
        }
    }
    Ok(mesh)
}

/// The 0-based vertex index of a face corner `v[/vt[/vn]]`, with `defined` vertices so far.
fn parse_corner(path: &Path, line: usize, corner: &str, defined: usize) -> Result<u32, IoError> {
    // The bytes searched, not the characters: '/' is ASCII, so no byte of another
    // character is one (a character search cost about 145 instructions a corner).
    let vertex = match corner.bytes().position(|b| b == b'/') {
        Some(at) => &corner[..at],
        None => corner,
    };
    let index: i64 = parse_field(path, line, Some(vertex), "vertex index")?;
    // A negative index counts back from the last vertex defined so far: -1 is the last.
    let one_based = if index < 0 {
        defined as i64 + 1 + index
    } else {
        index
    };
    if index < 0 && one_based < 1 {
        return Err(IoError::syntax(
            path,
            line,
            format!("vertex index {index} is out of range ({defined} defined)"),
        ));
    }
    check_index(path, line, one_based, 1, defined, "vertex")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;
    use glam::Vec3;

    const QUADS: &str = "# two groups\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\n\
        g body\nf 1/1/1 2/2/2 3/3/3 4/4/4\ng helper\nf -1 -4 -3\n";

    #[test]
    fn polygons_are_fan_triangulated_with_negative_indices() {
        let mesh = read(&scratch_file("quads.obj", QUADS), None).unwrap();
        assert_eq!(mesh.positions.len(), 5);
        assert_eq!(mesh.positions[4], Vec3::Z);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [4, 1, 2]]);
    }

    #[test]
    fn a_group_keeps_only_its_faces() {
        let mesh = read(&scratch_file("group.obj", QUADS), Some("helper")).unwrap();
        assert_eq!(mesh.triangles, vec![[4, 1, 2]]);
        let error = read(&scratch_file("group2.obj", QUADS), Some("hair")).unwrap_err();
        assert!(
            error
                .to_string()
                .contains("no group named \"hair\" (groups in the file: body, helper)"),
            "{error}"
        );
    }

    #[test]
    fn bad_faces_name_their_line() {
        let cases = [
            ("v 0 0 0\nv 1 0 0\nf 1 2\n", ":3: face has 2 vertices"),
            (
                "v 0 0 0\nf 1 2 3\n",
                ":2: vertex index 2 is out of range (1 defined)",
            ),
            ("v 0 0 0\nf 0 1 1\n", ":2: vertex index 0 is out of range"),
            ("v 0 0 0\nf -2 1 1\n", ":2: vertex index -2 is out of range"),
            ("v 0 nan 0\n", ":1: y coordinate is NaN"),
            ("v 0 0\n", ":1: missing z coordinate"),
            ("v 0 0 0\nf 1 a 1\n", ":2: vertex index \"a\""),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error = read(&scratch_file(&format!("bad{i}.obj"), text), None).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

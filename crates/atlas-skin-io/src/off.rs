//! Object File Format (`.off`, Geomview): vertices and polygon faces, fan-triangulated.

use crate::text::{check_index, parse_field, parse_point, read_text};
use crate::{IoError, TriangleMesh};
use std::path::Path;

/// Reads the OFF at `path`:
///
/// ```text
/// OFF                 (or COFF, NOFF, CNOFF: extra per-vertex columns are ignored)
/// #V #F #E            (may follow OFF on the same line)
/// x y z               (#V lines)
/// n i0 … i(n−1)       (#F lines, 0-based indices, optional colour after them)
/// ```
///
/// Polygons become fans `(i0, ik, ik+1)`; `#` starts a comment.
pub fn read(path: &Path) -> Result<TriangleMesh, IoError> {
    let text = read_text(path)?;
    let mut lines = text.lines().enumerate().filter_map(|(index, raw)| {
        let content = raw.split('#').next().unwrap_or_default();
        let mut tokens = content.split_whitespace().peekable();
        tokens.peek()?;
        Some((index + 1, tokens))
    });
    let end =
        |what: &str| IoError::invalid(path, format!("unexpected end of file, expected {what}"));

    let (line, mut header) = lines.next().ok_or_else(|| end("the OFF header"))?;
    match header.next() {
        Some("OFF" | "COFF" | "NOFF" | "CNOFF") => {}
        other => {
            return Err(IoError::syntax(
                path,
                line,
                format!(
                    "expected the OFF header, found {:?}",
                    other.unwrap_or_default()
                ),
            ))
        }
    }
    let (line, mut counts) = match header.peek() {
        Some(_) => (line, header),
        None => lines
            .next()
            .ok_or_else(|| end("the vertex and face counts"))?,
    };
    let vertex_count: usize = parse_field(path, line, counts.next(), "vertex count")?;
    let face_count: usize = parse_field(path, line, counts.next(), "face count")?;

    let mut mesh = TriangleMesh::default();
    for _ in 0..vertex_count {
        let (line, mut tokens) = lines.next().ok_or_else(|| end("a vertex"))?;
        mesh.positions.push(parse_point(path, line, &mut tokens)?);
    }
    for _ in 0..face_count {
        let (line, mut tokens) = lines.next().ok_or_else(|| end("a face"))?;
        let corners: usize = parse_field(path, line, tokens.next(), "face size")?;
        if corners < 3 {
            return Err(IoError::syntax(
                path,
                line,
                format!("face has {corners} vertices, at least 3 needed"),
            ));
        }
        let face = (0..corners)
            .map(|_| {
                let index: i64 = parse_field(path, line, tokens.next(), "vertex index")?;
                check_index(path, line, index, 0, vertex_count, "vertex")
            })
            .collect::<Result<Vec<u32>, IoError>>()?;
        for k in 1..corners - 1 {
            mesh.triangles.push([face[0], face[k], face[k + 1]]);
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;

    #[test]
    fn quad_and_triangle_with_comments() {
        let text = "OFF # header\n4 2 0\n0 0 0\n1 0 0\n1 1 0 255 0 0\n0 1 0\n\
            4 0 1 2 3\n3 0 2 1 0.5 0.5 0.5\n";
        let mesh = read(&scratch_file("quad.off", text)).unwrap();
        assert_eq!(mesh.positions.len(), 4);
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 1]]);
        let same_line = read(&scratch_file(
            "inline.off",
            "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
        ));
        assert_eq!(same_line.unwrap().triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn broken_files_name_their_line() {
        let cases = [
            ("PLY\n", ":1: expected the OFF header"),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n",
                "unexpected end of file, expected a vertex",
            ),
            ("OFF\n1 1 0\n0 0 0\n2 0 0\n", ":4: face has 2 vertices"),
            (
                "OFF\n1 1 0\n0 0 0\n3 0 0 1\n",
                ":4: vertex index 1 is out of range (1 defined)",
            ),
            ("OFF\n1 0 0\n0 NaN 0\n", ":3: y coordinate is NaN"),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error = read(&scratch_file(&format!("bad{i}.off"), text)).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

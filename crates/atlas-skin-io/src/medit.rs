//! MEDIT `.mesh` files (INRIA, ASCII): surface triangles, or the boundary of a tetrahedral
//! mesh.

use crate::text::{check_index, read_text, Tokens};
use crate::{IoError, TriangleMesh};
use glam::Vec3;
use std::collections::HashMap;
use std::path::Path;

/// Reads the `.mesh` at `path`: all `Vertices` (file order) and the `Triangles`; a file with
/// `Tetrahedra` but no triangles gives the boundary of the tetrahedral mesh instead (the
/// faces of exactly one tetrahedron, oriented outward). Vertices no triangle uses, such as a
/// tetrahedral mesh's interior, stay in the list; the loader drops them.
pub fn read(path: &Path) -> Result<TriangleMesh, IoError> {
    let text = read_text(path)?;
    let mut tokens = Tokens::new(path, &text, Some('#'));
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut tetrahedra: Vec<[u32; 4]> = Vec::new();
    while let Some(keyword) = tokens.next_token() {
        match keyword {
            "MeshVersionFormatted" => {
                tokens.parse::<u32>("mesh version")?;
            }
            "Dimension" => {
                let dimension: u32 = tokens.parse("dimension")?;
                if dimension != 3 {
                    return Err(tokens.error(format!("dimension {dimension}, only 3 is supported")));
                }
            }
            "Vertices" => {
                let count: usize = tokens.parse("vertex count")?;
                positions.reserve(count.min(1 << 24));
                for _ in 0..count {
                    positions.push(tokens.point()?);
                    tokens.parse::<i64>("vertex reference")?;
                }
            }
            "Triangles" => {
                let count: usize = tokens.parse("triangle count")?;
                for _ in 0..count {
                    triangles.push(read_element::<3>(&mut tokens, positions.len())?);
                }
            }
            "Tetrahedra" => {
                let count: usize = tokens.parse("tetrahedron count")?;
                for _ in 0..count {
                    tetrahedra.push(read_element::<4>(&mut tokens, positions.len())?);
                }
            }
            "End" => break,
            other => match section_width(other) {
                Some(width) => {
                    let count: usize = tokens.parse("element count")?;
                    for _ in 0..count {
                        for _ in 0..width {
                            tokens.parse::<f64>("element value")?;
                        }
                    }
                }
                None => return Err(tokens.error(format!("unknown section {other:?}"))),
            },
        }
    }
    if triangles.is_empty() {
        triangles = tetrahedron_boundary(&positions, &tetrahedra);
    }
    Ok(TriangleMesh {
        positions,
        triangles,
    })
}

/// Numbers per element of the sections that are skipped.
fn section_width(keyword: &str) -> Option<usize> {
    match keyword {
        "Edges" => Some(3),
        "Quadrilaterals" => Some(5),
        "Hexahedra" => Some(9),
        "Corners" | "RequiredVertices" | "Ridges" | "RequiredEdges" => Some(1),
        "Normals" | "Tangents" => Some(3),
        "NormalAtVertices" | "TangentAtVertices" => Some(2),
        _ => None,
    }
}

/// N 1-based vertex indices followed by a reference number, as 0-based indices.
fn read_element<const N: usize>(
    tokens: &mut Tokens,
    vertex_count: usize,
) -> Result<[u32; N], IoError> {
    let mut element = [0u32; N];
    for slot in &mut element {
        let index: i64 = tokens.parse("vertex index")?;
        *slot = check_index(
            tokens.path(),
            tokens.line(),
            index,
            1,
            vertex_count,
            "vertex",
        )?;
    }
    tokens.parse::<i64>("element reference")?;
    Ok(element)
}

/// Faces that belong to exactly one tetrahedron, in order of first appearance, each turned
/// to face away from its tetrahedron: for a tetrahedron (a, b, c, d) with positive volume
/// det(b − a, c − a, d − a) > 0 the outward faces are (a, c, b), (a, b, d), (a, d, c),
/// (b, c, d).
fn tetrahedron_boundary(positions: &[Vec3], tetrahedra: &[[u32; 4]]) -> Vec<[u32; 3]> {
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut count: HashMap<[u32; 3], u32> = HashMap::new();
    for &[a, b, c, d] in tetrahedra {
        let [pa, pb, pc, pd] = [a, b, c, d].map(|v| positions[v as usize]);
        let positive = (pb - pa).cross(pc - pa).dot(pd - pa) >= 0.0;
        for face in [[a, c, b], [a, b, d], [a, d, c], [b, c, d]] {
            let face = if positive {
                face
            } else {
                [face[0], face[2], face[1]]
            };
            let mut key = face;
            key.sort_unstable();
            let seen = count.entry(key).or_insert(0);
            if *seen == 0 {
                faces.push(face);
            }
            *seen += 1;
        }
    }
    faces
        .into_iter()
        .filter(|face| {
            let mut key = *face;
            key.sort_unstable();
            count[&key] == 1
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;

    const TETS: &str = "MeshVersionFormatted 1\nDimension 3\nVertices\n5\n\
        0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n-1 -1 -1 0\n\
        Tetrahedra\n2\n1 2 3 4 0\n1 3 2 5 0\nEdges\n0\nEnd\n";

    #[test]
    fn tetrahedra_give_their_outward_boundary() {
        let mesh = read(&scratch_file("tets.mesh", TETS)).unwrap();
        assert_eq!(mesh.positions.len(), 5);
        // Two tetrahedra glued on face (1, 2, 3): 8 faces minus the shared pair.
        assert_eq!(mesh.triangles.len(), 6);
        // Outward faces enclose a positive volume: Σ a·(b×c)/6 = 1/6 + 1/6.
        let volume: f32 = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        assert!((volume - 1.0 / 3.0).abs() < 1e-6, "{volume}");
    }

    #[test]
    fn triangles_win_over_tetrahedra() {
        let text = TETS.replace("Edges\n0\n", "Triangles\n1\n1 2 3 7\n");
        let mesh = read(&scratch_file("tris.mesh", text)).unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn broken_files_name_their_line() {
        let cases = [
            ("Dimension 2\n", ":1: dimension 2"),
            ("Vertices\n2\n0 0 0 0\n", ":3: unexpected end of file"),
            (
                "Vertices\n1\n0 0 0 0\nTriangles\n1\n1 1 2 0\n",
                ":6: vertex index 2 is out of range (1 defined)",
            ),
            ("Vertices\n1\n0 inf 0 0\n", ":3: y coordinate is inf"),
            ("Prisms\n1\n", ":1: unknown section \"Prisms\""),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error = read(&scratch_file(&format!("bad{i}.mesh"), text)).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

//! MakeHuman `.mhw` skin weights (JSON): per bone, a list of `[vertex, weight]` over the
//! base mesh's full vertex list.

use crate::text::read_json;
use crate::IoError;
use atlas_skin_runtime::{Skeleton, VertexWeights};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Deserialize)]
struct Document {
    weights: BTreeMap<String, Vec<(u64, f64)>>,
}

/// Reads the `.mhw` at `path` as weights of `file_vertex_count` rows (one per vertex of the
/// base mesh file, in file order) over the joints of `skeleton`, matched by bone name.
/// Unknown bones, vertices out of range and negative or non-finite weights are errors;
/// rows are kept as stored (MakeHuman rounds them, so they may not sum to 1).
pub fn read(
    path: &Path,
    skeleton: &Skeleton,
    file_vertex_count: usize,
) -> Result<VertexWeights, IoError> {
    let document: Document = read_json(path)?;
    let mut rows: Vec<Vec<(u32, f32)>> = vec![Vec::new(); file_vertex_count];
    for (bone, entries) in &document.weights {
        let joint = skeleton.find(bone).ok_or_else(|| {
            IoError::invalid(path, format!("bone {bone:?} is not in the skeleton"))
        })? as u32;
        for &(vertex, weight) in entries {
            let row = usize::try_from(vertex)
                .ok()
                .and_then(|v| rows.get_mut(v))
                .ok_or_else(|| {
                    IoError::invalid(
                        path,
                        format!(
                            "bone {bone:?}: vertex {vertex} is out of range (the mesh file has {file_vertex_count} vertices)"
                        ),
                    )
                })?;
            if !weight.is_finite() || weight < 0.0 {
                return Err(IoError::invalid(
                    path,
                    format!("bone {bone:?}: vertex {vertex} has weight {weight}"),
                ));
            }
            if weight > 0.0 {
                row.push((joint, weight as f32));
            }
        }
    }
    Ok(VertexWeights::from_rows(rows))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    fn skeleton() -> Skeleton {
        Skeleton::from_positions(
            vec!["root".into(), "arm".into()],
            vec![NO_PARENT, 0],
            &[Vec3::ZERO, Vec3::X],
        )
        .unwrap()
    }

    #[test]
    fn weights_go_to_joints_by_name() {
        let text =
            r#"{"name": "w", "weights": {"arm": [[1, 0.25], [2, 1.0]], "root": [[1, 0.75]]}}"#;
        let weights = read(&scratch_file("w.mhw", text), &skeleton(), 3).unwrap();
        assert_eq!(weights.vertex_count(), 3);
        assert_eq!(weights.row(0).count(), 0);
        assert_eq!(weights.row(1).collect::<Vec<_>>(), [(1, 0.25), (0, 0.75)]);
        assert_eq!(weights.row(2).collect::<Vec<_>>(), [(1, 1.0)]);
    }

    #[test]
    fn broken_files_are_errors() {
        let cases = [
            (
                r#"{"weights": {"leg": [[0, 1]]}}"#,
                "bone \"leg\" is not in the skeleton",
            ),
            (
                r#"{"weights": {"arm": [[5, 1]]}}"#,
                "bone \"arm\": vertex 5 is out of range (the mesh file has 3 vertices)",
            ),
            (
                r#"{"weights": {"arm": [[0, -1]]}}"#,
                "vertex 0 has weight -1",
            ),
            (r#"{"weights": {"arm": [[0]]}}"#, ":1: invalid length 1"),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error =
                read(&scratch_file(&format!("bad{i}.mhw"), text), &skeleton(), 3).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

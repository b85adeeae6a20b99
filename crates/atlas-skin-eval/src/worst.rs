//! The vertices where a candidate deforms farthest from the reference: where to look first
//! when a weighting goes wrong.

use super::deform::VertexError;
use atlas_skin::geometry::point_segment_distance;
use atlas_skin_runtime::VertexWeights;
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// One joint's weight in a row, by name, with how far the joint's bones are from the
/// vertex.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointWeight {
    pub joint: String,
    pub weight: f32,
    /// Distance from the vertex to the nearest bone segment the joint moves
    /// ([`atlas_skin::skeleton::bones::bone_segments`]), in units of the diagonal (0 in
    /// JSON written before this field existed).
    #[serde(default)]
    pub bone_distance: f64,
    /// `bone_distance` over the distance to the nearest bone of any joint (1 for the
    /// nearest bone itself): a weight on a joint whose bones are several times farther than
    /// the nearest is a gross misassignment. Unbounded (`f64::INFINITY`, `null` in JSON,
    /// which has no infinity) when the vertex lies on another joint's bone.
    #[serde(default, with = "unbounded")]
    pub bone_distance_ratio: f64,
}

/// An `f64` that may be `+∞`, written `null` in JSON (serde_json writes every non-finite
/// number as `null`, and reads `null` back only into an `Option`).
mod unbounded {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else {
            s.serialize_none()
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
    }
}

/// A vertex with a large deformation error, and the two weight rows that cause it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorstVertex {
    /// Index of the vertex in the reference file's stored vertices.
    pub vertex: usize,
    /// Its rest position.
    pub position: [f32; 3],
    /// Its largest error over the random poses, in units of the diagonal.
    pub error: f64,
    /// The random pose (0-based, seed + pose) where that error occurs.
    pub pose: usize,
    /// Reference and candidate rows, heaviest first.
    pub reference: Vec<JointWeight>,
    pub candidate: Vec<JointWeight>,
}

/// The aligned rows [`worst_vertices`] reads: #M entries each.
pub struct Rows<'a> {
    pub stored: &'a [usize],
    pub positions: &'a [Vec3],
    pub reference: &'a VertexWeights,
    pub candidate: &'a VertexWeights,
    /// Joint names of the reference skeleton, which both rows index.
    pub names: &'a [String],
    /// Bone segments of the reference skeleton ([`atlas_skin::skeleton::bones::bone_segments`]).
    pub segments: &'a [(u32, DVec3, DVec3)],
    /// Length of the mesh's bounding-box diagonal.
    pub diagonal: f64,
}

/// The `count` rows with the largest `errors[m].max`, worst first (ties by row order).
pub fn worst_vertices(errors: &[VertexError], rows: &Rows, count: usize) -> Vec<WorstVertex> {
    let mut order: Vec<usize> = (0..errors.len()).collect();
    order.sort_by(|&a, &b| errors[b].max.total_cmp(&errors[a].max).then(a.cmp(&b)));
    order
        .into_iter()
        .take(count)
        .map(|m| WorstVertex {
            vertex: rows.stored[m],
            position: rows.positions[m].to_array(),
            error: errors[m].max,
            pose: errors[m].palette,
            reference: named_row(rows.reference, m, rows),
            candidate: named_row(rows.candidate, m, rows),
        })
        .collect()
}

/// Row `m` of `weights` with joint names and bone distances, heaviest first, zero weights
/// dropped.
fn named_row(weights: &VertexWeights, m: usize, rows: &Rows) -> Vec<JointWeight> {
    let p = rows.positions[m].as_dvec3();
    let bone_distance = |joint: Option<u32>| {
        rows.segments
            .iter()
            .filter(|&&(j, _, _)| joint.is_none() || joint == Some(j))
            .map(|&(_, a, b)| point_segment_distance(p, a, b))
            .fold(f64::INFINITY, f64::min)
    };
    let nearest = bone_distance(None);
    let mut row: Vec<JointWeight> = weights
        .row(m)
        .filter(|&(_, w)| w != 0.0)
        .map(|(j, weight)| {
            let distance = bone_distance(Some(j));
            JointWeight {
                joint: rows.names[j as usize].clone(),
                weight,
                bone_distance: distance / rows.diagonal,
                bone_distance_ratio: if nearest > 0.0 {
                    distance / nearest
                } else if distance > 0.0 {
                    f64::INFINITY
                } else {
                    1.0
                },
            }
        })
        .collect();
    row.sort_by(|a, b| b.weight.total_cmp(&a.weight));
    row
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_the_largest_errors_first_with_named_rows() {
        let errors = [0.1, 0.5, 0.3].map(|max| VertexError { max, palette: 2 });
        let weights =
            VertexWeights::from_rows([vec![(0, 1.0)], vec![(0, 0.25), (1, 0.75)], vec![(1, 1.0)]]);
        let candidate = VertexWeights::from_rows(vec![vec![(1, 1.0)]; 3]);
        let names = ["a".to_string(), "b".to_string()];
        let rows = Rows {
            stored: &[7, 8, 9],
            positions: &[Vec3::X, Vec3::Y, Vec3::Z],
            reference: &weights,
            candidate: &candidate,
            names: &names,
            // Joint a moves the bone along X from the origin, b the bone along Z from 2Y.
            segments: &[
                (0, DVec3::ZERO, DVec3::X),
                (1, DVec3::Y * 2.0, DVec3::new(0.0, 2.0, 1.0)),
            ],
            diagonal: 2.0,
        };
        let worst = worst_vertices(&errors, &rows, 2);
        assert_eq!(worst.len(), 2);
        assert_eq!((worst[0].vertex, worst[1].vertex), (8, 9));
        assert_eq!(worst[0].position, [0.0, 1.0, 0.0]);
        assert_eq!((worst[0].error, worst[0].pose), (0.5, 2));
        assert_eq!(worst[0].reference[0].joint, "b");
        assert_eq!(worst[0].reference[1].weight, 0.25);
        assert_eq!(worst[0].candidate.len(), 1);
        // Vertex 8 at (0, 1, 0): 1 from a's bone, 1 from b's; vertex 9 at Z: 1 and √(4 + 0) = 2.
        assert_eq!(worst[0].candidate[0].bone_distance, 0.5);
        assert_eq!(worst[0].candidate[0].bone_distance_ratio, 1.0);
        assert_eq!(worst[1].candidate[0].joint, "b");
        assert!((worst[1].candidate[0].bone_distance_ratio - 2.0).abs() < 1e-12);
        assert!(worst_vertices(&errors, &rows, 0).is_empty());
    }

    #[test]
    fn a_vertex_on_another_joints_bone_has_an_unbounded_ratio_that_survives_json() {
        let errors = [VertexError {
            max: 0.5,
            palette: 0,
        }];
        let reference = VertexWeights::from_rows([vec![(0, 1.0)]]);
        let candidate = VertexWeights::from_rows([vec![(1, 0.75), (0, 0.25)]]);
        let names = ["a".to_string(), "b".to_string()];
        let rows = Rows {
            stored: &[0],
            // On a's bone, 1 from b's.
            positions: &[Vec3::X * 0.5],
            reference: &reference,
            candidate: &candidate,
            names: &names,
            segments: &[
                (0, DVec3::ZERO, DVec3::X),
                (1, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)),
            ],
            diagonal: 1.0,
        };
        let worst = worst_vertices(&errors, &rows, 1);
        assert_eq!(worst[0].candidate[0].bone_distance_ratio, f64::INFINITY);
        assert_eq!(worst[0].candidate[1].bone_distance_ratio, 1.0);
        let json = serde_json::to_string(&worst).unwrap();
        assert!(json.contains(r#""bone_distance_ratio":null"#), "{json}");
        let back: Vec<WorstVertex> = serde_json::from_str(&json).unwrap();
        assert_eq!(back, worst);
        // Rows written before the field existed still read.
        let old: JointWeight = serde_json::from_str(r#"{"joint":"a","weight":1.0}"#).unwrap();
        assert_eq!(old.bone_distance_ratio, 0.0);
    }
}

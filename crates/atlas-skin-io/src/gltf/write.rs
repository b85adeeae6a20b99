//! Writing a skinned `.glb`: new weights into a copy of the input document, or a new
//! document for inputs that were not glTF.

use super::accessor::ComponentType;
use super::builder::{GlbBuilder, ARRAY_BUFFER};
use super::new_document::new_document;
use super::rewrite::rewrite_document;
use crate::output::OutputPlan;
use crate::{Character, IoError};
use atlas_skin_runtime::weights::prune_row;
use atlas_skin_runtime::{Clip, Skeleton, VertexWeights};
use serde_json::{Map, Value};
use std::path::Path;

/// Largest [`WriteOptions::max_influences`]: 8 JOINTS_n/WEIGHTS_n sets, beyond what any
/// engine skins with.
pub const MAX_INFLUENCES: usize = 32;

/// What the skinned writer adds to the document.
#[derive(Debug, Clone)]
pub struct WriteOptions {
    /// Largest number of joints per vertex (4 per JOINTS_n/WEIGHTS_n set; > 4 writes
    /// JOINTS_1/WEIGHTS_1, ...). From 1 to [`MAX_INFLUENCES`].
    pub max_influences: usize,
    /// Extra clips to add; `Track::node` is a skeleton joint index, mapped to the joint's
    /// node in the output.
    pub animations: Vec<Clip>,
    /// JSON put into `asset.extras` (merged key by key when both are objects).
    pub extras: Option<Value>,
}

impl Default for WriteOptions {
    fn default() -> Self {
        Self {
            max_influences: 4,
            animations: Vec::new(),
            extras: None,
        }
    }
}

/// Writes `character` skinned with `weights` as a glTF binary at `out`.
///
/// - `weights`: one row per vertex of `character.mesh`, joint indices into
///   `character.skeleton`.
/// - glTF input with a skin: the input document with JOINTS_n/WEIGHTS_n of the skinned
///   primitives replaced and everything else kept (external buffers and images embedded
///   into the single BIN chunk). Other input: a new document with the mesh, smooth normals,
///   joint nodes in the bind pose and a skin.
/// - Weights per vertex: the `max_influences` largest, normalised in the stored float32
///   (see `pack_weights`); a vertex without any weight is bound fully to joint 0.
///
/// # Errors
/// [`IoError::WouldOverwriteInput`] when `out` is the input file; [`IoError::Invalid`]
/// when the character has no skeleton, the weights do not match the mesh and skeleton, or
/// the input document cannot be rewritten; [`IoError::Write`] when writing fails. On error
/// no file is left at `out`.
pub fn write_skinned_glb(
    character: &Character,
    weights: &VertexWeights,
    options: &WriteOptions,
    out: &Path,
) -> Result<(), IoError> {
    let plan = OutputPlan::new([character.path.as_path()], [out])?;
    plan.write(out, &skinned_glb(character, weights, options, out)?)
}

/// The bytes [`write_skinned_glb`] writes (`out` only names the output in errors), for
/// callers that write through their own [`OutputPlan`].
///
/// # Errors
/// As [`write_skinned_glb`], without the write errors.
pub fn skinned_glb(
    character: &Character,
    weights: &VertexWeights,
    options: &WriteOptions,
    out: &Path,
) -> Result<Vec<u8>, IoError> {
    skinned_glb_of(character, None, weights, options, out)
}

/// [`skinned_glb`] for a caller that no longer needs the glTF input's JSON document: it is
/// moved out of `character.gltf` (leaving `Value::Null` there) into the output instead of
/// copied (a document of 160 kB, RobotExpressive's, took about 3 million instructions to
/// copy and as many to drop). The same bytes.
///
/// # Errors
/// As [`skinned_glb`].
pub fn skinned_glb_taking_document(
    character: &mut Character,
    weights: &VertexWeights,
    options: &WriteOptions,
    out: &Path,
) -> Result<Vec<u8>, IoError> {
    let document = character
        .gltf
        .as_mut()
        .map(|source| std::mem::take(&mut source.document));
    skinned_glb_of(character, document, weights, options, out)
}

/// [`skinned_glb`], the input's document given when the caller gave it up (else copied).
fn skinned_glb_of(
    character: &Character,
    document: Option<serde_json::Value>,
    weights: &VertexWeights,
    options: &WriteOptions,
    out: &Path,
) -> Result<Vec<u8>, IoError> {
    let skeleton = character.skeleton.as_ref().ok_or_else(|| {
        IoError::invalid(&character.path, "cannot write a skinned glTF: no skeleton")
    })?;
    if !(1..=MAX_INFLUENCES).contains(&options.max_influences) {
        return Err(IoError::invalid(
            out,
            format!(
                "max_influences is {}, outside 1..={MAX_INFLUENCES}",
                options.max_influences
            ),
        ));
    }
    if weights.vertex_count() != character.mesh.positions.len() {
        return Err(IoError::invalid(
            out,
            format!(
                "{} weight rows for {} mesh vertices",
                weights.vertex_count(),
                character.mesh.positions.len()
            ),
        ));
    }
    weights
        .validate(skeleton.len())
        .map_err(|e| IoError::invalid(out, format!("bad weights: {e}")))?;
    match character.gltf.as_ref() {
        Some(source) if source.skin.is_some() => {
            let document = document.unwrap_or_else(|| source.document.clone());
            rewrite_document(character, source, document, weights, options, out)
        }
        _ => new_document(character, skeleton, weights, options, out),
    }
}

/// Skin weights packed into glTF's fixed-width JOINTS_n/WEIGHTS_n sets.
///
/// - `sets`: number of 4-wide sets.
/// - `joints`, `weights`: #sets lists of #V × 4 values.
pub(crate) struct PackedWeights {
    pub joints: Vec<Vec<u32>>,
    pub weights: Vec<Vec<f32>>,
}

/// Packs the rows `vertices` of `weights` into `ceil(max_influences / 4)` sets.
///
/// Per vertex: the `max_influences` largest weights ([`VertexWeights::pruned`]: repeated
/// joints merged, zeros dropped), stored as float32 values that sum to 1 (see
/// [`stored_weights`]). A vertex without any weight is bound fully to joint 0. Unused slots
/// are joint 0 with weight 0, as glTF 2.0 ("Skinned Mesh Attributes") asks: a non-zero
/// joint is never stored with weight 0.
pub(crate) fn pack_weights(
    weights: &VertexWeights,
    vertices: impl ExactSizeIterator<Item = usize>,
    max_influences: usize,
) -> PackedWeights {
    let sets = max_influences.div_ceil(4);
    let vertex_count = vertices.len();
    let mut joints = vec![vec![0u32; 4 * vertex_count]; sets];
    let mut packed = vec![vec![0f32; 4 * vertex_count]; sets];
    // Buffers reused by every vertex.
    let (mut row, mut stored) = (Vec::new(), Vec::new());
    for (v, vertex) in vertices.enumerate() {
        prune_row(weights.row(vertex), max_influences, &mut row);
        if row.is_empty() {
            row.push((0, 1.0));
        }
        stored_weights(&mut row, &mut stored);
        for (k, &(joint, value)) in stored.iter().enumerate() {
            let (set, slot) = (k / 4, 4 * v + k % 4);
            joints[set][slot] = joint;
            packed[set][slot] = value;
        }
    }
    PackedWeights {
        joints,
        weights: packed,
    }
}

/// The float32 values stored for a row of positive weights `w` (not empty), into `stored`
/// (`row` loses the entries dropped).
///
/// `s_k = fl(w_k / Σ w)` for all but the last entry, and `s_last = fl(1 − Σ_{k<last} s_k)`
/// (the sum taken in f64), so the float32 sum is 1 within one rounding per addition: the
/// glTF-Validator accepts `|Σ s − 1| ≤ 2·10⁻⁷` per non-zero weight. An entry whose stored
/// value would be 0 (a weight negligible next to the others, or the remainder when the
/// others round up to 1) is dropped and the rest stored again, so every stored value is
/// positive; a single entry is stored as 1.
fn stored_weights(row: &mut Vec<(u32, f32)>, stored: &mut Vec<(u32, f32)>) {
    loop {
        let sum: f64 = row.iter().map(|&(_, w)| w as f64).sum();
        let last = row.len() - 1;
        let mut stored_sum = 0.0f64;
        stored.clear();
        stored.extend(row.iter().enumerate().map(|(k, &(joint, weight))| {
            let value = if k == last {
                (1.0 - stored_sum).max(0.0) as f32
            } else {
                (weight as f64 / sum) as f32
            };
            stored_sum += value as f64;
            (joint, value)
        }));
        match stored
            .iter()
            .position(|&(_, value)| value.is_nan() || value <= 0.0)
        {
            Some(zero) => {
                row.remove(zero);
            }
            None => return,
        }
    }
}

/// Appends the inverse bind matrices of `skeleton` as a MAT4 accessor; returns its index.
pub(crate) fn push_inverse_binds(builder: &mut GlbBuilder, skeleton: &Skeleton) -> usize {
    let matrices: Vec<f32> = skeleton
        .inverse_bind
        .iter()
        .flat_map(|m| m.to_cols_array())
        .collect();
    builder.push_f32_accessor(&matrices, "MAT4", false, None)
}

/// Appends packed weights as JOINTS/WEIGHTS accessors (joints as UNSIGNED_BYTE below 256
/// joints, else UNSIGNED_SHORT) and returns the accessor indices per set.
pub(crate) fn push_weight_accessors(
    builder: &mut GlbBuilder,
    packed: &PackedWeights,
    joint_count: usize,
) -> Vec<(usize, usize)> {
    let component = if joint_count <= 256 {
        ComponentType::U8
    } else {
        ComponentType::U16
    };
    packed
        .joints
        .iter()
        .zip(&packed.weights)
        .map(|(joints, weights)| {
            let j = builder.push_uint_accessor(joints, component, "VEC4", Some(ARRAY_BUFFER));
            let w = builder.push_f32_accessor(weights, "VEC4", false, Some(ARRAY_BUFFER));
            (j, w)
        })
        .collect()
}

/// Puts `extras` into `asset.extras`, merging key by key when both are objects.
pub(crate) fn merge_asset_extras(json: &mut Map<String, Value>, extras: &Value) {
    let asset = json
        .entry("asset")
        .or_insert_with(|| Value::Object(Map::new()));
    let Value::Object(asset) = asset else {
        return;
    };
    match (asset.get_mut("extras"), extras) {
        (Some(Value::Object(existing)), Value::Object(new)) => {
            existing.extend(new.iter().map(|(k, v)| (k.clone(), v.clone())));
        }
        _ => {
            asset.insert("extras".into(), extras.clone());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_weights_sum_to_one_in_f32() {
        let weights = VertexWeights::from_rows([
            vec![(0, 0.1), (1, 0.7), (2, 0.3), (1, 0.1), (3, 0.05), (4, 0.01)],
            vec![],
            vec![(2, 1.0 / 3.0), (1, 1.0 / 3.0), (0, 1.0 / 3.0)],
        ]);
        let packed = pack_weights(&weights, 0..3, 4);
        assert_eq!(packed.joints.len(), 1);
        assert_eq!(&packed.joints[0][0..4], &[1, 2, 0, 3]);
        assert_eq!(&packed.joints[0][4..8], &[0, 0, 0, 0]);
        assert_eq!(packed.weights[0][4], 1.0);
        for v in 0..3 {
            let sum: f32 = packed.weights[0][4 * v..4 * v + 4].iter().sum();
            assert!((sum - 1.0).abs() <= 1e-6, "vertex {v} sums to {sum}");
        }
        let wide = pack_weights(&weights, [0].into_iter(), 5);
        assert_eq!(wide.joints.len(), 2);
        assert_eq!(wide.joints[1][0], 4);
    }

    /// Rows where a weight is negligible next to the others (its stored value, or the
    /// remainder, rounds to 0 in float32; the demo character had such rows) and random
    /// rows: no non-zero joint is stored with weight 0, and the float32 sum taken as the
    /// glTF-Validator takes it (slot by slot, each slot across the sets) is within its
    /// tolerance of 2e-7 per non-zero weight.
    #[test]
    fn stored_weights_pass_the_validator_checks() {
        let mut rows = vec![
            vec![(22, 0.962_682_4), (21, 0.037_317_6), (29, 1e-9)],
            vec![(1, 0.664_466_7), (0, 0.335_533_3), (16, 3e-9)],
            vec![(5, 1.0), (6, 1e-30), (7, 1e-38)],
            vec![(3, 3e38), (4, 3e38)],
        ];
        let mut rng = atlas_skin_runtime::random_pose::SplitMix64::new(2008);
        for _ in 0..3000 {
            let influences = 1 + rng.next_u64() % 10;
            rows.push(
                (0..influences)
                    .map(|_| {
                        let scale = 10f64.powi(-((rng.next_u64() % 12) as i32));
                        (
                            (rng.next_u64() % 40) as u32,
                            (rng.next_f64() * scale) as f32,
                        )
                    })
                    .collect(),
            );
        }
        let weights = VertexWeights::from_rows(rows);
        for max_influences in [4, 8] {
            let packed = pack_weights(&weights, 0..weights.vertex_count(), max_influences);
            for v in 0..weights.vertex_count() {
                let mut sum = 0f32;
                let mut tolerance = 0f32;
                for slot in 4 * v..4 * v + 4 {
                    for (joints, stored) in packed.joints.iter().zip(&packed.weights) {
                        let (joint, weight) = (joints[slot], stored[slot]);
                        assert!(
                            weight > 0.0 || joint == 0,
                            "vertex {v}: joint {joint} stored with weight {weight}"
                        );
                        if weight > 0.0 {
                            sum += weight;
                            tolerance += 2e-7;
                        }
                    }
                }
                assert!(
                    (sum - 1.0).abs() <= tolerance,
                    "vertex {v}: sum {sum}, {:?}",
                    weights.row(v).collect::<Vec<_>>()
                );
            }
        }
    }
}

//! The JSON report of a skinned character (`atlas-skin skin --report`): the decomposition
//! with each joint's overlap width and cut curve, the region of every vertex, timings,
//! counts, how the pieces were weighted, and every warning.

use atlas_skin::pipeline::Skinned;
use atlas_skin::weights::pieces::PieceTreatment;
use atlas_skin::weights::WeightCounts;
use atlas_skin::{BoundaryKind, Decomposition};
use serde_json::{json, Map, Value};

/// Wall time of each stage of the method, in milliseconds, keyed by stage name.
pub fn stage_timings(skinned: &Skinned) -> Map<String, Value> {
    skinned
        .timings
        .0
        .iter()
        .map(|&(stage, ms)| (stage.name().to_string(), json!(ms)))
        .collect()
}

/// The JSON report: `decomposition` (the decomposition's own report, each joint with its
/// `overlap_width` and cut `curve`, and the region of every stored vertex),
/// `timings_ms`, `counts`, `warnings`.
///
/// - `input`: the character's name (its path, as displayed).
/// - `input_warnings`: what the reader noticed, listed before the method's warnings.
/// - `timings`: stage → milliseconds ([`stage_timings`], and any step of the caller).
pub fn skin_report(
    input: &str,
    input_warnings: &[String],
    skinned: &Skinned,
    timings: Map<String, Value>,
) -> Value {
    let decomposition = &skinned.decomposition;
    let mut decomposition_json = json!(decomposition.report());
    if let Some(joints) = decomposition_json["joints"].as_array_mut() {
        for (joint, decision) in joints.iter_mut().zip(&decomposition.joints) {
            let Some(k) = decision.boundary else { continue };
            let k = k as usize;
            joint["overlap_width"] = json!(skinned.overlaps.half_widths[k]);
            if let BoundaryKind::Cut { curve } = &decomposition.boundaries[k].kind {
                let points: Vec<[f64; 3]> = curve
                    .iter()
                    .map(|&v| decomposition.surface.positions[v as usize].to_array())
                    .collect();
                joint["curve"] = json!(points);
            }
        }
    }
    // Region of every stored vertex: that of the first face of its welded vertex.
    let mut vertex_region = vec![None; decomposition.welded_vertex_count];
    for (f, t) in decomposition.surface.triangles.iter().enumerate().rev() {
        for &v in t {
            if let Some(slot) = vertex_region.get_mut(v as usize) {
                *slot = Some(decomposition.face_region[f]);
            }
        }
    }
    decomposition_json["vertex_regions"] = json!(skinned
        .welded_of_stored
        .iter()
        .map(|&w| vertex_region.get(w as usize).copied().flatten())
        .collect::<Vec<_>>());

    let counts = &skinned.counts;
    let mut warnings = input_warnings.to_vec();
    warnings.extend(skinned.warnings.iter().cloned());
    let weight_counts = &counts.weights;
    if weight_counts.from_surface > 0 {
        warnings.push(format!(
            "fallback: {} vertices of decomposed pieces lie in regions no joint reaches and took \
             the weights of the nearest weighted vertex along their piece",
            weight_counts.from_surface
        ));
    }
    if weight_counts.from_bone > 0 {
        warnings.push(format!(
            "fallback: {} vertices lie in pieces that span a joint with no cut and no body \
             beneath: each is bound to its nearest bone",
            weight_counts.from_bone
        ));
    }
    if !weight_counts.inactive_soft_joints.is_empty() {
        let names: Vec<&str> = weight_counts
            .inactive_soft_joints
            .iter()
            .map(|&j| decomposition.joints[j as usize].name.as_str())
            .collect();
        warnings.push(format!(
            "{} soft boundaries have no cross-section near their joint and carry no weight: {}",
            names.len(),
            names.join(", ")
        ));
    }
    if counts.unreferenced_stored_vertices > 0 {
        warnings.push(format!(
            "{} stored vertices are used by no triangle: bound to their nearest bone",
            counts.unreferenced_stored_vertices
        ));
    }
    json!({
        "input": input,
        "decomposition": decomposition_json,
        "timings_ms": timings,
        "counts": {
            "vertices": counts.stored_vertices,
            "welded_vertices": counts.welded_vertices,
            "surface_vertices": counts.surface_vertices,
            "joints": counts.joints,
            "regions": decomposition.regions.len(),
            "unreachable_vertices": weight_counts.unreachable,
            "fallback_weighted_vertices": weight_counts.from_surface + weight_counts.from_bone
                + counts.unreferenced_stored_vertices,
            "max_influences": skinned.weights.max_influences(),
            "leaf_patches": weight_counts.leaf_patches.len(),
            "far_bone_vertices": weight_counts.far_bone_vertices,
            "duplicate_faces": counts.duplicate_faces,
            "inside_out_pieces": counts.inside_out_pieces,
        },
        "pieces": pieces_report(decomposition, weight_counts),
        "warnings": warnings,
    })
}

/// How the pieces were weighted: per treatment the number of pieces and vertices, and
/// every piece that was not decomposed (`attached`, `rigid` with its joint, `bones`).
fn pieces_report(decomposition: &Decomposition, counts: &WeightCounts) -> Value {
    let mut summary = serde_json::Map::new();
    let mut loose = Vec::new();
    for piece in &counts.pieces {
        let (name, joint) = match piece.treatment {
            PieceTreatment::Body => ("body", None),
            PieceTreatment::Attached => ("attached", None),
            PieceTreatment::Rigid(j) => ("rigid", Some(j)),
            PieceTreatment::Bones => ("bones", None),
        };
        let entry = summary
            .entry(name)
            .or_insert_with(|| json!({"pieces": 0, "vertices": 0, "fallback_vertices": 0}));
        for (key, add) in [
            ("pieces", 1),
            ("vertices", piece.vertices),
            ("fallback_vertices", piece.fallback_vertices),
        ] {
            entry[key] = json!(entry[key].as_u64().unwrap_or(0) + add as u64);
        }
        if piece.treatment != PieceTreatment::Body {
            loose.push(json!({
                "treatment": name,
                "joint": joint.map(|j| decomposition.joints[j as usize].name.clone()),
                "vertices": piece.vertices,
            }));
        }
    }
    json!({"by_treatment": summary, "not_decomposed": loose})
}

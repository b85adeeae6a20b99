//! The JSON report of a skinned character (`atlas-skin skin --report`): the decomposition
//! with each joint's overlap width and cut curve, the region of every vertex, timings,
//! counts, how the pieces were weighted, every warning with its topic, and what the
//! quality gate found and decided.

use crate::quality::{Findings, Verdict};
use atlas_skin::pipeline::Skinned;
use atlas_skin::report::SharedSideReport;
use atlas_skin::weights::pieces::PieceTreatment;
use atlas_skin::BoundaryKind;
use atlas_skin_io::gltf::GltfSource;
use serde::Serialize;
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;

/// Wall time of each stage of the method, in milliseconds, keyed by stage name.
pub fn stage_timings(skinned: &Skinned) -> Map<String, Value> {
    skinned
        .timings
        .0
        .iter()
        .map(|&(stage, ms)| (stage.name().to_string(), json!(ms)))
        .collect()
}

/// The JSON report: `binding` (`smooth` or `rigid`), `decomposition` (the decomposition's
/// own report, each joint with its `overlap_width` and cut `curve`, and the region of every
/// stored vertex), `timings_ms`, `counts`, `pieces` (how each piece and each stored vertex was weighted, see
/// [`TREATMENTS`]), `warnings` and their `warning_topics`, `quality` (the gate's findings
/// and verdict).
///
/// - `input`: the character's name (its path, as displayed).
/// - `findings`: what the reader and the method noticed ([`Findings::new`]).
/// - `verdict`: the quality gate's ([`Verdict::new`]; the default: no gate).
/// - `timings`: stage → milliseconds ([`stage_timings`], and any step of the caller).
pub fn skin_report(
    input: &str,
    findings: &Findings,
    verdict: &Verdict,
    skinned: &Skinned,
    timings: Map<String, Value>,
) -> Value {
    SkinReport::new(input, findings, verdict, skinned, &timings, None).to_value()
}

/// The JSON report of [`skin_report`] (with `vertex_ranges` when `gltf` is given), ready
/// to be written without the JSON values: [`SkinReport::to_text`] serialises it straight
/// to its pretty-printed text, the text of [`SkinReport::to_value`] (keys in the sorted
/// order of [`serde_json::Map`]: each struct below declares its fields in that order).
#[derive(Serialize)]
pub struct SkinReport<'a> {
    binding: &'static str,
    counts: ReportCounts,
    decomposition: ReportDecomposition,
    input: &'a str,
    pieces: ReportPieces,
    quality: ReportQuality<'a>,
    timings_ms: &'a Map<String, Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    vertex_ranges: Option<Vec<VertexRange>>,
    warning_topics: Vec<&'static str>,
    warnings: Vec<&'a str>,
}

/// What the quality gate found and decided ([`Findings`], [`Verdict`]), fields in sorted
/// order: `fail_on` (the conditions asked for), `reasons` (why the character is rejected),
/// `rejected`, and the joints two of the conditions name.
#[derive(Serialize)]
struct ReportQuality<'a> {
    fail_on: &'a [crate::quality::Condition],
    reasons: &'a [String],
    rejected: bool,
    soft_joints_without_weight: &'a [String],
    unweighted_joints: &'a [String],
}

#[derive(Serialize)]
struct ReportCounts {
    crowded_vertices: usize,
    duplicate_faces: usize,
    fallback_weighted_vertices: usize,
    far_bone_vertices: usize,
    inside_out_pieces: usize,
    joints: usize,
    max_influences: usize,
    merged_joints: usize,
    off_carrier_vertices: usize,
    regions: usize,
    sibling_blend_vertices: usize,
    surface_vertices: usize,
    transferred_vertices: usize,
    unreachable_vertices: usize,
    vertices: usize,
    welded_vertices: usize,
}

/// [`DecompositionReport`] with every joint's overlap width and curve and every stored
/// vertex's region, fields in sorted order.
#[derive(Serialize)]
struct ReportDecomposition {
    cuts: usize,
    joints: Vec<ReportJoint>,
    regions: Vec<ReportRegion>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    shared_sides: Vec<SharedSideReport>,
    skipped: usize,
    soft: usize,
    vertex_regions: Vec<Option<u32>>,
}

/// A [`JointReport`], fields in sorted order, with its overlap width and cut curve.
#[derive(Serialize)]
struct ReportJoint {
    #[serde(skip_serializing_if = "Option::is_none")]
    curve: Option<Vec<[f64; 3]>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    diameter: Option<f64>,
    name: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    normal: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    overlap_width: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    perimeter: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    point: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reason: Option<String>,
    region: Option<u32>,
    status: &'static str,
}

/// A [`RegionReport`], fields in sorted order.
#[derive(Serialize)]
struct ReportRegion {
    faces: usize,
    joint: Option<String>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    joints: Vec<String>,
    vertices: usize,
}

#[derive(Serialize)]
struct ReportPieces {
    by_treatment: BTreeMap<&'static str, TreatmentCount>,
    gaps: Vec<LoosePart>,
    not_decomposed: Vec<LoosePart>,
    treatments: [&'static str; 5],
    vertex_treatments: Vec<usize>,
}

#[derive(Serialize, Default)]
struct TreatmentCount {
    pieces: usize,
    vertices: usize,
}

/// A piece not decomposed, or a gap of a body piece.
#[derive(Serialize)]
struct LoosePart {
    joint: Option<String>,
    treatment: &'static str,
    vertices: usize,
}

#[derive(Serialize)]
struct VertexRange {
    count: usize,
    first: usize,
    mesh: usize,
    node: usize,
    primitive: usize,
}

impl<'a> SkinReport<'a> {
    /// The report of `skinned` (see [`skin_report`]); `gltf`: the source of a glTF input,
    /// for `vertex_ranges` ([`vertex_ranges`]).
    pub fn new(
        input: &'a str,
        findings: &'a Findings,
        verdict: &'a Verdict,
        skinned: &'a Skinned,
        timings: &'a Map<String, Value>,
        gltf: Option<&GltfSource>,
    ) -> Self {
        let decomposition = &skinned.decomposition;
        let counts = &skinned.counts;
        let weight_counts = &counts.weights;
        Self {
            binding: skinned.binding.name(),
            counts: ReportCounts {
                crowded_vertices: weight_counts.crowded_vertices,
                duplicate_faces: counts.duplicate_faces,
                fallback_weighted_vertices: counts.unreferenced_stored_vertices,
                far_bone_vertices: weight_counts.far_bone_vertices,
                inside_out_pieces: counts.inside_out_pieces,
                joints: counts.joints,
                merged_joints: skinned.decomposition.merged_joints.len(),
                max_influences: skinned.weights.max_influences(),
                off_carrier_vertices: weight_counts.off_carrier,
                regions: decomposition.regions.len(),
                sibling_blend_vertices: weight_counts.sibling_blend_vertices,
                surface_vertices: counts.surface_vertices,
                transferred_vertices: weight_counts.transferred,
                unreachable_vertices: weight_counts.unreachable,
                vertices: counts.stored_vertices,
                welded_vertices: counts.welded_vertices,
            },
            decomposition: ReportDecomposition::new(skinned),
            input,
            pieces: ReportPieces::new(skinned),
            quality: ReportQuality {
                fail_on: &verdict.fail_on,
                reasons: &verdict.reasons,
                rejected: verdict.rejected(),
                soft_joints_without_weight: &findings.soft_joints_without_weight,
                unweighted_joints: &findings.unweighted_joints,
            },
            timings_ms: timings,
            vertex_ranges: gltf.map(|source| {
                source
                    .primitives
                    .iter()
                    .map(|p| VertexRange {
                        count: p.vertices.len(),
                        first: p.vertices.start,
                        mesh: p.mesh,
                        node: p.node,
                        primitive: p.primitive,
                    })
                    .collect()
            }),
            warning_topics: findings.warnings.iter().map(|&(topic, _)| topic).collect(),
            warnings: findings.warnings.iter().map(|(_, w)| w.as_str()).collect(),
        }
    }

    /// The report as JSON values (what [`skin_report`] returns).
    pub fn to_value(&self) -> Value {
        serde_json::to_value(self).unwrap_or(Value::Null)
    }

    /// The report's pretty-printed JSON text, `serde_json::to_string_pretty` of
    /// [`SkinReport::to_value`] (the same bytes; tested), written without the values.
    pub fn to_text(&self) -> Result<Vec<u8>, serde_json::Error> {
        serde_json::to_vec_pretty(self)
    }
}

impl ReportDecomposition {
    fn new(skinned: &Skinned) -> Self {
        let decomposition = &skinned.decomposition;
        let report = decomposition.report();
        let joints = report
            .joints
            .into_iter()
            .zip(&decomposition.joints)
            .map(|(joint, decision)| {
                let boundary = decision.boundary.map(|k| k as usize);
                let curve = match boundary.map(|k| &decomposition.boundaries[k].kind) {
                    Some(BoundaryKind::Cut { curve }) => Some(
                        curve
                            .iter()
                            .map(|&v| decomposition.surface.positions[v as usize].to_array())
                            .collect(),
                    ),
                    _ => None,
                };
                ReportJoint {
                    curve,
                    diameter: joint.diameter,
                    name: joint.name,
                    normal: joint.normal,
                    overlap_width: boundary.map(|k| skinned.overlaps.half_widths[k]),
                    perimeter: joint.perimeter,
                    point: joint.point,
                    reason: joint.reason,
                    region: joint.region,
                    status: joint.status,
                }
            })
            .collect();
        let regions = report
            .regions
            .into_iter()
            .map(|region| ReportRegion {
                faces: region.faces,
                joint: region.joint,
                joints: region.joints,
                vertices: region.vertices,
            })
            .collect();
        ReportDecomposition {
            cuts: report.cuts,
            joints,
            regions,
            shared_sides: report.shared_sides,
            skipped: report.skipped,
            soft: report.soft,
            vertex_regions: vertex_regions(skinned),
        }
    }
}

/// Region of every stored vertex: that of the first face of its welded vertex.
fn vertex_regions(skinned: &Skinned) -> Vec<Option<u32>> {
    let decomposition = &skinned.decomposition;
    let mut vertex_region = vec![None; decomposition.welded_vertex_count];
    for (f, t) in decomposition.surface.triangles.iter().enumerate().rev() {
        for &v in t {
            if let Some(slot) = vertex_region.get_mut(v as usize) {
                *slot = Some(decomposition.face_region[f]);
            }
        }
    }
    skinned
        .welded_of_stored
        .iter()
        .map(|&w| vertex_region.get(w as usize).copied().flatten())
        .collect()
}

impl ReportPieces {
    /// How the pieces were weighted: per treatment the number of pieces and vertices
    /// (`by_treatment`), every piece that was not decomposed (`not_decomposed`:
    /// `attached`, `rigid` with its joint, `joints`), every gap of a body piece weighted as
    /// a whole (`gaps`: the parts no region with joints reaches, with the same
    /// treatments), and the treatment of every stored vertex (`vertex_treatments`: an
    /// index into `treatments`, [`TREATMENTS`]).
    fn new(skinned: &Skinned) -> Self {
        let decomposition = &skinned.decomposition;
        let counts = &skinned.counts.weights;
        let joint_name = |treatment: PieceTreatment| match treatment {
            PieceTreatment::Rigid(j) => Some(decomposition.joints[j as usize].name.clone()),
            _ => None,
        };
        let mut by_treatment: BTreeMap<&'static str, TreatmentCount> = BTreeMap::new();
        let mut not_decomposed = Vec::new();
        for piece in &counts.pieces {
            let name = TREATMENTS[treatment_index(piece.treatment)];
            let entry = by_treatment.entry(name).or_default();
            entry.pieces += 1;
            entry.vertices += piece.vertices;
            if piece.treatment != PieceTreatment::Body {
                not_decomposed.push(LoosePart {
                    joint: joint_name(piece.treatment),
                    treatment: name,
                    vertices: piece.vertices,
                });
            }
        }
        let gaps = counts
            .gaps
            .iter()
            .map(|gap| LoosePart {
                joint: joint_name(gap.treatment),
                treatment: TREATMENTS[treatment_index(gap.treatment)],
                vertices: gap.vertices.len(),
            })
            .collect();
        ReportPieces {
            by_treatment,
            gaps,
            not_decomposed,
            treatments: TREATMENTS,
            vertex_treatments: vertex_treatments(skinned),
        }
    }
}

/// Where the report's per-vertex arrays (`decomposition.vertex_regions`,
/// `pieces.vertex_treatments`) come from in a glTF input, whose written file keeps its
/// nodes, meshes and primitives: per triangle primitive read, its node, mesh and primitive
/// index and its stored vertices `first .. first + count` (primitives that share one
/// POSITION accessor share their range). The viewer colours every such primitive, not only
/// the largest skinned mesh (several skins, rigid meshes under joints).
pub fn vertex_ranges(source: &GltfSource) -> Value {
    json!(source
        .primitives
        .iter()
        .map(|p| json!({
            "node": p.node,
            "mesh": p.mesh,
            "primitive": p.primitive,
            "first": p.vertices.start,
            "count": p.vertices.len(),
        }))
        .collect::<Vec<_>>())
}

/// The treatments of the report's `pieces.treatments`, in that order: a vertex's piece was
/// decomposed (`body`), attached to the body surface, bound rigidly to one joint, bent at
/// its joints ([`PieceTreatment`]), or the vertex was weighted by a fallback (`fallback`: a
/// stored vertex no triangle uses, bound to its nearest bone; the warnings say how many).
pub const TREATMENTS: [&str; 5] = ["body", "attached", "rigid", "joints", "fallback"];
/// Index of `fallback` in [`TREATMENTS`].
const FALLBACK: usize = 4;

/// Index in [`TREATMENTS`] of a piece's treatment.
fn treatment_index(treatment: PieceTreatment) -> usize {
    match treatment {
        PieceTreatment::Body => 0,
        PieceTreatment::Attached => 1,
        PieceTreatment::Rigid(_) => 2,
        PieceTreatment::Joints => 3,
    }
}

/// The index in [`TREATMENTS`] of every stored vertex: `fallback` when no triangle uses
/// it, else the treatment of its gap when its welded vertex lies in a gap of a body piece,
/// else its piece's treatment (the piece of the split surface that holds its welded
/// vertex).
fn vertex_treatments(skinned: &Skinned) -> Vec<usize> {
    let d = &skinned.decomposition;
    let counts = &skinned.counts.weights;
    let piece_of = &d.topology.vertex_component;
    let mut of_surface: Vec<usize> = piece_of
        .iter()
        .map(|&c| treatment_index(counts.pieces[c as usize].treatment))
        .collect();
    for gap in &counts.gaps {
        for &v in &gap.vertices {
            of_surface[v as usize] = treatment_index(gap.treatment);
        }
    }
    skinned
        .welded_of_stored
        .iter()
        .map(|&w| of_surface.get(w as usize).copied().unwrap_or(FALLBACK))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quality::Condition;
    use atlas_skin::fixtures::demo::demo_character;
    use atlas_skin::fixtures::pieces::demo_in_pieces;
    use atlas_skin::fixtures::shapes::icosphere;
    use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
    use glam::Vec3;

    /// Grid step of the demo for these tests: coarse, so that the test is quick.
    const STEP: f64 = 0.02;

    /// The demo in 99 pieces ([`demo_in_pieces`]) with one more stored vertex that no
    /// triangle uses: each stored vertex gets the treatment of its piece; the eyeballs (the
    /// first pieces after the demo) are rigid, the body decomposed, the unused vertex a
    /// fallback; per loose treatment as many stored vertices as the pieces have.
    #[test]
    fn every_stored_vertex_gets_the_treatment_of_its_piece() {
        let mut character = demo_in_pieces(STEP);
        character.positions.push(Vec3::new(0.0, 1.0, 0.5));
        let (positions, triangles) = (&character.positions, &character.triangles);
        let skeleton = &character.skeleton;
        let input = SkinInput {
            positions,
            triangles,
            skeleton,
            end_joints: &[],
        };
        let skinned = skin(input, &SkinParams::default(), &mut |_| {}).expect("skinned");
        let findings = Findings::new(&[], &skinned);
        let report = skin_report(
            "pieces",
            &findings,
            &Verdict::default(),
            &skinned,
            Map::new(),
        );
        let pieces = &report["pieces"];
        assert_eq!(pieces["treatments"], json!(TREATMENTS));
        let names: Vec<&str> = pieces["vertex_treatments"]
            .as_array()
            .expect("vertex_treatments")
            .iter()
            .map(|k| TREATMENTS[k.as_u64().expect("an index") as usize])
            .collect();
        assert_eq!(names.len(), character.positions.len());

        let body = demo_character(STEP).positions.len();
        let eyes = 2 * icosphere(0.02, 2).positions.len();
        assert!(names[..body].iter().all(|&n| n == "body"));
        assert!(names[body..body + eyes].iter().all(|&n| n == "rigid"));
        assert_eq!(names.last(), Some(&"fallback"));
        assert_eq!(names.iter().filter(|&&n| n == "fallback").count(), 1);
        for name in ["attached", "rigid", "joints"] {
            let stored = names.iter().filter(|&&n| n == name).count();
            let expected = pieces["by_treatment"][name]["vertices"]
                .as_u64()
                .unwrap_or(0);
            assert_eq!(stored as u64, expected, "{name}");
        }
        assert!(pieces["by_treatment"]["attached"]["vertices"].as_u64() > Some(0));
    }

    /// The report built as JSON values, as it was before [`SkinReport`] (the reference):
    /// objects keyed in sorted order by [`serde_json::Map`].
    fn skin_report_reference(
        input: &str,
        findings: &Findings,
        verdict: &Verdict,
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
        let weight_counts = &counts.weights;
        let (warning_topics, warnings): (Vec<&str>, Vec<&str>) = findings
            .warnings
            .iter()
            .map(|(topic, message)| (*topic, message.as_str()))
            .unzip();
        json!({
            "input": input,
            "binding": skinned.binding.name(),
            "decomposition": decomposition_json,
            "timings_ms": timings,
            "counts": {
                "vertices": counts.stored_vertices,
                "welded_vertices": counts.welded_vertices,
                "surface_vertices": counts.surface_vertices,
                "joints": counts.joints,
                "regions": decomposition.regions.len(),
                "unreachable_vertices": weight_counts.unreachable,
                "fallback_weighted_vertices": counts.unreferenced_stored_vertices,
                "max_influences": skinned.weights.max_influences(),
                "far_bone_vertices": weight_counts.far_bone_vertices,
                "sibling_blend_vertices": weight_counts.sibling_blend_vertices,
                "merged_joints": decomposition.merged_joints.len(),
                "crowded_vertices": weight_counts.crowded_vertices,
                "off_carrier_vertices": weight_counts.off_carrier,
                "transferred_vertices": weight_counts.transferred,
                "duplicate_faces": counts.duplicate_faces,
                "inside_out_pieces": counts.inside_out_pieces,
            },
            "pieces": pieces_report_reference(skinned),
            "quality": {
                "fail_on": verdict.fail_on,
                "reasons": verdict.reasons,
                "rejected": verdict.rejected(),
                "soft_joints_without_weight": findings.soft_joints_without_weight,
                "unweighted_joints": findings.unweighted_joints,
            },
            "warning_topics": warning_topics,
            "warnings": warnings,
        })
    }

    /// The `pieces` of [`skin_report_reference`].
    fn pieces_report_reference(skinned: &Skinned) -> Value {
        let decomposition = &skinned.decomposition;
        let counts = &skinned.counts.weights;
        let mut summary = serde_json::Map::new();
        let joint_name = |treatment: PieceTreatment| match treatment {
            PieceTreatment::Rigid(j) => Some(decomposition.joints[j as usize].name.clone()),
            _ => None,
        };
        let mut loose = Vec::new();
        for piece in &counts.pieces {
            let name = TREATMENTS[treatment_index(piece.treatment)];
            let entry = summary
                .entry(name)
                .or_insert_with(|| json!({"pieces": 0, "vertices": 0}));
            for (key, add) in [("pieces", 1), ("vertices", piece.vertices)] {
                entry[key] = json!(entry[key].as_u64().unwrap_or(0) + add as u64);
            }
            if piece.treatment != PieceTreatment::Body {
                let joint = joint_name(piece.treatment);
                loose.push(json!({"treatment": name, "joint": joint, "vertices": piece.vertices}));
            }
        }
        let gaps: Vec<Value> = counts
            .gaps
            .iter()
            .map(|gap| {
                json!({
                    "treatment": TREATMENTS[treatment_index(gap.treatment)],
                    "joint": joint_name(gap.treatment),
                    "vertices": gap.vertices.len(),
                })
            })
            .collect();
        json!({
            "by_treatment": summary,
            "not_decomposed": loose,
            "gaps": gaps,
            "treatments": TREATMENTS,
            "vertex_treatments": vertex_treatments(skinned),
        })
    }

    /// [`SkinReport`] gives the reference's values, and its text is the reference's
    /// pretty-printed text byte for byte: the demo, the demo in pieces with a stored
    /// vertex no triangle uses (attached, rigid and fallback treatments), and glTF inputs
    /// with their vertex ranges (cesiumman; RobotExpressive: rigid meshes under joints).
    #[test]
    fn the_report_serialised_directly_is_the_reference_text() {
        let mut pieces = demo_in_pieces(STEP);
        pieces.positions.push(Vec3::new(0.0, 1.0, 0.5));
        let demo = demo_character(STEP);
        let mut cases = vec![
            ("demo", demo.positions, demo.triangles, demo.skeleton, None),
            (
                "pieces",
                pieces.positions,
                pieces.triangles,
                pieces.skeleton,
                None,
            ),
        ];
        let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
        for file in [
            "models/cesiumman/CesiumMan.glb",
            "bench/robotexpressive/RobotExpressive.glb",
        ] {
            let path = std::path::Path::new(data).join(file);
            let character = atlas_skin_io::load_character(&path, &Default::default())
                .unwrap_or_else(|e| panic!("{e}"));
            let skeleton = character.skeleton.clone().expect("skeleton");
            cases.push((
                file,
                character.mesh.positions,
                character.mesh.triangles,
                skeleton,
                character.gltf,
            ));
        }
        for (name, positions, triangles, skeleton, gltf) in cases {
            let input = SkinInput {
                positions: &positions,
                triangles: &triangles,
                skeleton: &skeleton,
                end_joints: &[],
            };
            let skinned = skin(input, &SkinParams::default(), &mut |_| {}).expect("skinned");
            let mut timings = stage_timings(&skinned);
            timings.insert("write".into(), json!(1.25));
            let warnings = vec!["a reader's warning".to_string()];
            let findings = Findings::new(&warnings, &skinned);
            let verdict = Verdict::new(&findings, &[Condition::Input, Condition::Fallback]);
            let mut reference =
                skin_report_reference(name, &findings, &verdict, &skinned, timings.clone());
            if let Some(source) = &gltf {
                reference["vertex_ranges"] = vertex_ranges(source);
            }
            let report =
                SkinReport::new(name, &findings, &verdict, &skinned, &timings, gltf.as_ref());
            assert_eq!(report.to_value(), reference, "{name}");
            let text = report.to_text().expect("text");
            let expected = serde_json::to_string_pretty(&reference).expect("reference text");
            assert!(text == expected.as_bytes(), "{name}");
        }
    }
}

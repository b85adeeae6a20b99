//! The Khronos glTF-Validator finds nothing in our outputs that their input did not already
//! have: no error, and no warning, information or hint (unused objects, joints stored with
//! zero weight, ...) beyond the input's own, code by code.

mod gltf_support;

use atlas_skin_io::gltf::{self, write_skinned_glb, WriteOptions};
use atlas_skin_io::{load_character, Character, LoadOptions};
use atlas_skin_runtime::VertexWeights;
use gltf_support::{
    assert_no_new_issues, data_dir, model_path, out_dir, validator_reports, GLTF_MODELS,
};
use std::path::PathBuf;

/// `weights` with every vertex also given a negligible influence (1e-9) of the next joint:
/// the stored value of such an influence, or the remainder that normalises the row, rounds
/// to 0 in float32.
fn with_negligible_influences(weights: &VertexWeights, joint_count: u32) -> VertexWeights {
    VertexWeights::from_rows((0..weights.vertex_count()).map(|v| {
        let mut row: Vec<(u32, f32)> = weights.row(v).collect();
        let first = row.first().map_or(0, |&(joint, _)| joint);
        row.push(((first + 1) % joint_count, 1e-9));
        row
    }))
}

/// Writes `character` with its reference weights, with those weights plus negligible
/// influences, and with both at 8 influences per vertex; returns the files written.
fn write_variants(character: &Character, name: &str, dir: &std::path::Path) -> Vec<PathBuf> {
    let weights = character
        .reference_weights
        .as_ref()
        .expect("reference weights");
    let joints = character.skeleton.as_ref().expect("a skeleton").len() as u32;
    let negligible = with_negligible_influences(weights, joints);
    let mut outputs = Vec::new();
    for max_influences in [4, 8] {
        let options = WriteOptions {
            max_influences,
            ..WriteOptions::default()
        };
        for (variant, weights) in [("reference", weights), ("negligible", &negligible)] {
            let out = dir.join(format!("{name}-{variant}-{max_influences}.glb"));
            write_skinned_glb(character, weights, &options, &out).unwrap();
            outputs.push(out);
        }
    }
    outputs
}

#[test]
fn gltf_corpus_outputs_add_no_validator_issues() {
    let dir = out_dir("validator_issues_gltf");
    let mut inputs = Vec::new();
    let mut outputs = Vec::new();
    for (model, file) in GLTF_MODELS {
        let input = model_path(model, file);
        let character = gltf::read(&input).unwrap();
        for output in write_variants(&character, model, &dir) {
            inputs.push(input.clone());
            outputs.push(output);
        }
    }
    let input_reports = validator_reports(&inputs);
    for (output, input) in validator_reports(&outputs).iter().zip(&input_reports) {
        assert_no_new_issues(output, Some(input));
    }
}

/// Characters that were not glTF get a new document, which must be free of any issue.
#[test]
fn new_documents_have_no_validator_issues() {
    let dir = out_dir("validator_issues_new");
    let models = data_dir().join("models");
    let mut outputs = Vec::new();
    for model in ["arm", "elephant"] {
        let options = LoadOptions {
            skeleton: Some(models.join(model).join(format!("{model}.tgf"))),
            weights: Some(models.join(model).join(format!("{model}-weights.dmat"))),
            ..LoadOptions::default()
        };
        let character =
            load_character(&models.join(model).join(format!("{model}.obj")), &options).unwrap();
        outputs.extend(write_variants(&character, model, &dir));
    }
    for output in validator_reports(&outputs) {
        assert_no_new_issues(&output, None);
    }
}

//! The Khronos glTF-Validator finds nothing in what `atlas-skin demo` and `atlas-skin skin`
//! write that the input did not already have: no error, and no warning, information or hint
//! (joints stored with zero weight, unused objects, ...) beyond the input's own, code by
//! code. The demo character has no input file, so its outputs must have none at all.

#[path = "../../atlas-skin-io/tests/gltf_support/mod.rs"]
mod gltf_support;
mod support;

use atlas_skin_corpus::MODELS;
use gltf_support::{assert_no_new_issues, out_dir, validator_reports};
use support::atlas_skin_ok;

#[test]
fn demo_and_skinned_corpus_outputs_add_no_validator_issues() {
    let dir = out_dir("cli_validator_issues");
    let path = |name: &str| dir.join(name).display().to_string();

    atlas_skin_ok(&["demo", "-o", &path("")]);
    atlas_skin_ok(&["skin", "-o", &path("demo-skinned.glb")]);
    atlas_skin_ok(&["skin", "--binding", "rigid", "-o", &path("demo-rigid.glb")]);
    let demo_outputs = [
        dir.join("demo.glb"),
        dir.join("demo-skinned.glb"),
        dir.join("demo-rigid.glb"),
    ];
    for report in validator_reports(&demo_outputs) {
        assert_no_new_issues(&report, None);
    }

    let mut inputs = Vec::new();
    let mut outputs = Vec::new();
    for model in MODELS.iter().filter(|m| m.is_gltf()) {
        let input = model.input_path();
        let out = format!("{}.glb", model.name);
        atlas_skin_ok(&["skin", &input.display().to_string(), "-o", &path(&out)]);
        inputs.push(input);
        outputs.push(dir.join(out));
    }
    let input_reports = validator_reports(&inputs);
    for (output, input) in validator_reports(&outputs).iter().zip(&input_reports) {
        assert_no_new_issues(output, Some(input));
    }
}

//! `eval` across units and axes: a character's FBX (centimetres, +Z up, read in metres and
//! +Y up) against the same character converted to glb by another tool (assimp, the Debian
//! package `assimp-utils` that `scripts/install-test-deps` installs), which keeps the
//! file's centimetres and axes: the candidate is fitted onto the reference (scale 0.01, a
//! quarter turn) and the weights are equal. A candidate of another shape is still refused.
//! (Blender's export in other axes: `blender_checks.rs`.)

mod support;

use atlas_skin_corpus::data_file;
use std::path::Path;
use std::process::Command;
use support::{atlas_skin, atlas_skin_ok, eval_json, out_dir};

#[test]
fn eval_fits_an_assimp_conversion_in_the_files_centimetres() {
    let dir = out_dir("eval-units");
    let fbx = data_file("fbx/Skeleton_heaps_ascii.fbx");
    let glb = dir.join("heaps-assimp.glb");
    let output = Command::new("assimp")
        .arg("export")
        .arg(&fbx)
        .arg(&glb)
        .arg("-fglb2")
        .output()
        .expect("assimp is missing: run scripts/install-test-deps (tests never skip)");
    assert!(
        output.status.success() && glb.is_file(),
        "assimp export failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );

    let e = eval_json(&fbx, &glb);
    let fit = &e["fit"];
    assert_eq!(fit["turn"], "z_up_to_y_up", "{fit}");
    assert!(
        (fit["scale"].as_f64().unwrap() - 0.01).abs() < 1e-8,
        "{fit}"
    );
    // assimp moves 31 of the 476 vertices (seams); every other one is paired.
    let (matched, vertices) = (
        e["matched"].as_u64().unwrap(),
        e["vertices"].as_u64().unwrap(),
    );
    assert!(10 * matched >= 9 * vertices, "{matched} of {vertices}");
    // Equal weights, to the rounding of assimp's float32 copy (L1 up to 4.5e-6 in a row).
    for figure in [&e["weights_l1"]["max"], &e["deform_random"]["max"]] {
        assert!(figure.as_f64().unwrap() < 1e-5, "{figure}");
    }
    let text = atlas_skin_ok(&[Path::new("eval"), &fbx, &glb]);
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(
        text.contains("scale 0.010000, Z-up turned to Y-up"),
        "{text}"
    );

    // Matched as stored: no fit in the JSON.
    let same = eval_json(&fbx, &fbx);
    assert!(same.get("fit").is_none(), "{same}");

    // Another character: nothing fits, a clear refusal.
    let other = data_file("fbx/assimp_huesitos.fbx");
    let refused = atlas_skin(&[Path::new("eval"), &fbx, &other]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert_eq!(refused.status.code(), Some(1));
    assert!(stderr.contains("not the same"), "{stderr}");
}

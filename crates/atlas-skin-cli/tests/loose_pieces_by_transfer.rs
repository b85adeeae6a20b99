//! `"loose_pieces": "transfer"` in a settings file (`atlas-skin skin --config`): the pieces
//! of KayKit's Knight that hold no bone (639 vertices of its split surface) weighted by weight
//! transfer from the pieces that hold bones, counted in the report, and judged against the
//! artist's weights; without it, the contact rule and a count of 0.

mod support;

use std::ffi::OsStr;

/// Skins the Knight (with `settings` as its settings file when given) and returns the
/// report's `counts.transferred_vertices` and the deform figures against its artist.
fn knight(settings: Option<&str>, stem: &str) -> (u64, serde_json::Value) {
    let input = atlas_skin_corpus::data_dir().join("bench/kaykit/Knight.glb");
    let dir = support::out_dir(&format!("loose-pieces-{stem}"));
    let (glb, report, config) = (
        dir.join("knight.glb"),
        dir.join("knight.json"),
        dir.join("settings.json"),
    );
    let mut args: Vec<&OsStr> = vec![
        "skin".as_ref(),
        input.as_ref(),
        "-o".as_ref(),
        glb.as_ref(),
        "--report".as_ref(),
        report.as_ref(),
    ];
    if let Some(settings) = settings {
        std::fs::write(&config, settings).unwrap();
        args.extend(["--config".as_ref(), config.as_os_str()]);
    }
    support::atlas_skin_ok(&args);
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report).unwrap()).expect("the report is JSON");
    let counted = report["counts"]["transferred_vertices"]
        .as_u64()
        .expect("the report counts transferred_vertices");
    (counted, support::deform_random(&input, &glb))
}

#[test]
fn a_settings_file_weights_the_knights_loose_pieces_by_transfer() {
    // Measured 0.00325 / 0.0575 deform mean / max (the contact rule: 0.00338 / 0.102).
    let (transferred, deform) = knight(Some(r#"{"loose_pieces": "transfer"}"#), "transfer");
    assert!(transferred > 0);
    assert!(deform["mean"].as_f64().unwrap() < 0.0034, "{deform}");
    assert!(deform["max"].as_f64().unwrap() < 0.06, "{deform}");
    let (transferred, _) = knight(None, "contact");
    assert_eq!(transferred, 0);
}

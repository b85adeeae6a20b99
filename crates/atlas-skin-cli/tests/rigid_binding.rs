//! `--binding rigid` on characters their artists bound rigidly (the `rigid_binding` flag of
//! the benchmark's manifests): every vertex of the written glb and of the rig_info file on
//! one joint with weight 1, the report saying so, the same weights from the settings file
//! and from `batch`, and a deformation closer to the artist's than the default's.

mod support;

use atlas_skin_io::{load_character, Character};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use support::{atlas_skin, atlas_skin_ok, deform_random, out_dir};

/// Rigidly bound characters of `../shared/data` on which the rigid binding deforms
/// clearly closer to the artist's weights than the default (docs/measurements.md, "Rigid
/// bindings": deform mean 0.43 to 0.89 times the default's).
const RIGID: [&str; 4] = [
    "bench/rignet-val/1168.glb",
    "bench/rignet-val/8228.glb",
    "bench/rignet-val/15008.glb",
    "bench-large/rignet-train/3099.glb",
];

fn data(name: &str) -> PathBuf {
    let path = atlas_skin_corpus::data_dir().join(name);
    assert!(path.is_file(), "{} is missing", path.display());
    path
}

/// `atlas-skin skin INPUT -o DIR/STEM.glb --report DIR/STEM.json FLAGS...`: the glb's path
/// and the report.
fn skin(input: &Path, dir: &Path, stem: &str, flags: &[&str]) -> (PathBuf, serde_json::Value) {
    let glb = dir.join(format!("{stem}.glb"));
    let report = dir.join(format!("{stem}.json"));
    let mut args: Vec<OsString> = vec![
        "skin".into(),
        input.into(),
        "-o".into(),
        glb.clone().into(),
        "--report".into(),
        report.clone().into(),
    ];
    args.extend(flags.iter().map(OsString::from));
    atlas_skin_ok(&args);
    let report = serde_json::from_slice(&std::fs::read(report).unwrap()).unwrap();
    (glb, report)
}

fn weights_of(glb: &Path) -> Character {
    load_character(glb, &Default::default()).unwrap()
}

/// Asserts that every stored vertex of `glb` has exactly one joint with weight 1 (the
/// other slots of the glTF's four weight zero) and returns its (joint index) per vertex.
fn assert_one_joint_each(glb: &Path) -> Vec<u32> {
    let character = weights_of(glb);
    let weights = character.reference_weights.as_ref().unwrap();
    assert_eq!(weights.vertex_count(), character.mesh.positions.len());
    (0..weights.vertex_count())
        .map(|v| {
            let row: Vec<(u32, f32)> = weights.row(v).filter(|&(_, w)| w != 0.0).collect();
            assert!(
                row.len() == 1 && row[0].1 == 1.0,
                "{}: vertex {v} has {row:?}",
                glb.display()
            );
            row[0].0
        })
        .collect()
}

#[test]
fn rigid_characters_get_one_joint_per_vertex_and_deform_closer_to_the_artist() {
    let dir = out_dir("rigid-binding");
    for name in RIGID {
        let input = data(name);
        let stem = name.replace('/', "-");
        let rig_info = dir.join(format!("{stem}.txt"));
        let (rigid, report) = skin(
            &input,
            &dir,
            &format!("{stem}-rigid"),
            &[
                "--binding",
                "rigid",
                "--rig-info",
                rig_info.to_str().unwrap(),
            ],
        );
        assert_eq!(report["binding"], "rigid", "{name}");
        assert_eq!(report["counts"]["max_influences"], 1, "{name}");
        let joints = assert_one_joint_each(&rigid);

        // rig_info: one joint of weight 1 on every `skin` line, the glb's joint.
        let text = std::fs::read_to_string(&rig_info).unwrap();
        let names = weights_of(&rigid).skeleton.unwrap().names;
        let lines: Vec<&str> = text.lines().filter(|l| l.starts_with("skin ")).collect();
        assert_eq!(lines.len(), joints.len(), "{name}");
        for line in lines {
            let fields: Vec<&str> = line.split_whitespace().collect();
            assert_eq!(fields.len(), 4, "{name}: {line}");
            let v: usize = fields[1].parse().unwrap();
            assert_eq!(fields[2], names[joints[v] as usize], "{name}: {line}");
            assert_eq!(fields[3].parse::<f64>().unwrap(), 1.0, "{name}: {line}");
        }

        let (smooth, smooth_report) = skin(&input, &dir, &format!("{stem}-smooth"), &[]);
        assert_eq!(smooth_report["binding"], "smooth", "{name}");
        // The decomposition is the smooth weights'.
        assert_eq!(
            report["decomposition"], smooth_report["decomposition"],
            "{name}"
        );
        let mean = |glb: &Path| deform_random(&input, glb)["mean"].as_f64().unwrap();
        let (rigid_mean, smooth_mean) = (mean(&rigid), mean(&smooth));
        assert!(
            rigid_mean < 0.95 * smooth_mean,
            "{name}: rigid {rigid_mean}, smooth {smooth_mean}"
        );
    }
}

#[test]
fn the_settings_file_and_batch_bind_rigidly_as_the_option_does() {
    let dir = out_dir("rigid-binding-settings");
    let input = data(RIGID[0]);
    let (option, _) = skin(&input, &dir, "option", &["--binding", "rigid"]);
    let config = dir.join("rigid.json");
    std::fs::write(&config, r#"{"binding": "rigid"}"#).unwrap();
    let config_arg = config.to_str().unwrap();
    let (from_file, report) = skin(&input, &dir, "file", &["--config", config_arg]);
    assert_eq!(report["binding"], "rigid");
    let expected = assert_one_joint_each(&option);
    assert_eq!(assert_one_joint_each(&from_file), expected);
    // The option overrides the file.
    let (overridden, report) = skin(
        &input,
        &dir,
        "overridden",
        &["--config", config_arg, "--binding", "smooth"],
    );
    assert_eq!(report["binding"], "smooth");
    let smooth = weights_of(&overridden).reference_weights.unwrap();
    assert!(smooth.max_influences() > 1);

    let out = dir.join("batch");
    let mut args: Vec<OsString> = vec!["batch".into()];
    args.extend(RIGID[..2].iter().map(|n| data(n).into_os_string()));
    args.extend([
        "-o".into(),
        out.clone().into(),
        "--binding".into(),
        "rigid".into(),
    ]);
    atlas_skin_ok(&args);
    let batched = out.join(input.file_name().unwrap());
    assert_eq!(assert_one_joint_each(&batched), expected);
    assert_one_joint_each(&out.join(data(RIGID[1]).file_name().unwrap()));
}

#[test]
fn an_unknown_binding_is_refused_naming_the_choices() {
    let dir = out_dir("rigid-binding-refused");
    let input = data(RIGID[0]);
    let output = atlas_skin(&[
        OsString::from("skin"),
        input.into(),
        "-o".into(),
        dir.join("out.glb").into(),
        "--binding".into(),
        "stiff".into(),
    ]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("stiff") && stderr.contains("smooth") && stderr.contains("rigid"),
        "{stderr}"
    );
    assert!(!dir.join("out.glb").exists());

    let config = dir.join("bad.json");
    std::fs::write(&config, r#"{"binding": "stiff"}"#).unwrap();
    let output = atlas_skin(&[
        OsString::from("skin"),
        data(RIGID[0]).into(),
        "-o".into(),
        dir.join("out.glb").into(),
        "--config".into(),
        config.clone().into(),
    ]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("bad.json") && stderr.contains("stiff"),
        "{stderr}"
    );
    assert!(!dir.join("out.glb").exists());
}

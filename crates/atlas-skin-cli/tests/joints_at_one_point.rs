//! Joints at one point that the rules leave without weight share their twins' weight
//! equally (`weights::twins`), on a corpus model and a character of the bench.

mod support;

use atlas_skin_corpus::SIMPLESKIN;
use atlas_skin_io::gltf::{write_skinned_glb, WriteOptions};
use atlas_skin_io::{load_character, LoadOptions};
use glam::{Mat4, Vec3};
use std::path::Path;

/// The weights `glb` holds, per stored vertex, as (joint name, weight) pairs.
fn named_rows(glb: &Path) -> Vec<Vec<(String, f32)>> {
    let character = load_character(glb, &LoadOptions::default()).expect("output loads");
    let names = character.skeleton.expect("output has a skeleton").names;
    let weights = character.reference_weights.expect("output has weights");
    (0..weights.vertex_count())
        .map(|v| {
            let mut row: Vec<(String, f32)> = weights
                .row(v)
                .map(|(j, w)| (names[j as usize].clone(), w))
                .collect();
            row.sort_by(|a, b| a.0.cmp(&b.0));
            row
        })
        .collect()
}

/// Khronos' SimpleSkin binds both joints at one point: the whole strip was rigid to the
/// root (deform max 0.416 of the diagonal against its own gradient weights, 2.2 times Blender's
/// bone heat). Every vertex now moves half with each, as bone heat's do, and the report and
/// a warning say so.
#[test]
fn a_skeleton_at_one_point_shares_every_vertex_equally() {
    let dir = support::out_dir("joints-at-one-point-simpleskin");
    let input = SIMPLESKIN.input_path();
    let (glb, report) = support::skin_with_report(&input, &dir, "simpleskin");
    assert_eq!(report["counts"]["twins_given_a_share"], 1, "{report}");
    let warnings = report["warnings"].to_string();
    assert!(
        warnings.contains("shares its twins' weight equally") && warnings.contains("node2"),
        "{warnings}"
    );
    let rows = named_rows(&glb);
    assert_eq!(rows.len(), 10);
    for row in rows {
        assert_eq!(
            row,
            [("node1".to_string(), 0.5), ("node2".to_string(), 0.5)],
            "every vertex half on each joint"
        );
    }
    let deform = support::deform_random(&input, &glb);
    // Measured 0.0518 / 0.208; Blender's bone heat 0.0535 / 0.186 (other poses).
    assert!(deform["max"].as_f64().unwrap() < 0.25, "{deform}");
}

/// rignet-val/15008 has three joints at each of two points (Dummy027 with Dummy031 and
/// Dummy032, Dummy028 with Dummy033 and Dummy034), whose pieces its artist splits among
/// them. The rules gave everything to the first of each three; the other two now take a
/// third each wherever it has weight (the character's deform mean 0.0040 → 0.0037).
#[test]
fn twin_joints_left_without_weight_take_an_equal_share() {
    let skinned = support::BenchSkin::new("rignet-val/15008", "joints-at-one-point-15008");
    assert_eq!(skinned.report["counts"]["twins_given_a_share"], 4);
    let mut shared = 0;
    for row in named_rows(&skinned.glb) {
        let weight = |name: &str| row.iter().find(|(n, _)| n == name).map_or(0.0, |&(_, w)| w);
        for [first, a, b] in [
            ["Dummy027", "Dummy031", "Dummy032"],
            ["Dummy028", "Dummy033", "Dummy034"],
        ] {
            let (w, x, y) = (weight(first), weight(a), weight(b));
            assert!(
                (w - x).abs() < 1e-3 && (x - y).abs() < 1e-3,
                "{first} {w}, {a} {x}, {b} {y}"
            );
            if w > 0.0 {
                shared += 1;
            }
        }
    }
    assert!(shared >= 50, "{shared} vertices shared among twins");
    // Measured 0.0037 / 0.240.
    skinned.assert_deform_below(0.0039, 0.26);
}

/// The demo's 35 joints bound at one point (a broken file): one class of twins larger than
/// a written vertex's influences is left as the rules weighted it, and the report counts
/// its joints beside the warning.
#[test]
fn a_class_too_large_to_share_is_counted_in_the_report() {
    let dir = support::out_dir("joints-at-one-point-too-many");
    support::atlas_skin_ok(&["demo".as_ref(), "-o".as_ref(), dir.as_os_str()]);
    let mut character =
        load_character(&dir.join("demo.glb"), &LoadOptions::default()).expect("demo loads");
    let weights = character
        .reference_weights
        .take()
        .expect("demo has weights");
    // A new document from the edited skeleton, not the demo's own rewritten.
    character.gltf = None;
    let skeleton = character.skeleton.as_mut().expect("demo has a skeleton");
    let joints = skeleton.len();
    skeleton.inverse_bind = vec![Mat4::from_translation(-Vec3::Y); joints];
    let input = dir.join("demo-at-one-point.glb");
    write_skinned_glb(&character, &weights, &WriteOptions::default(), &input).expect("write");
    let (_, report) = support::skin_with_report(&input, &dir, "one-point");
    let counts = &report["counts"];
    assert_eq!(counts["twins_too_many_to_share"], joints, "{counts}");
    assert_eq!(counts["twins_given_a_share"], 0, "{counts}");
    let warnings = report["warnings"].to_string();
    assert!(
        warnings.contains(&format!(
            "{joints} joints sit at one point in classes of more than 32"
        )),
        "{warnings}"
    );
}

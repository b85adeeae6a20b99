//! The HTML report in Debian's headless Chromium (tests/js/viewer.mjs with playwright-core):
//! no console error, no network request, a picture that is not blank and that changes with a
//! joint slider, the heat map, the pieces view and the animation time; the LBS/DQS switch;
//! GPU skinning equal to the runtime's reference; dragging a joint to pose it; on the demo
//! character, a benchmark character in pieces and MakeHuman skinned by `atlas-skin skin
//! --html`, on glTF files as they are, and with a BVH motion.

mod support;

use atlas_skin_corpus::{data_file, motion_path, node_json, CESIUMMAN, MAKEHUMAN, RIGGEDFIGURE};
use atlas_skin_runtime::{reference, VertexWeights};
use glam::{Mat4, Vec3};
use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use support::atlas_skin_ok as atlas_skin;

fn output_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report_browser");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs tests/js/viewer.mjs on the report `html`; returns its whole result. Screenshots go
/// to the test output folder as NAME-*.png.
fn run_viewer(name: &str, html: &Path) -> serde_json::Value {
    assert!(
        Path::new("/usr/bin/chromium").is_file(),
        "chromium is missing: run scripts/install-test-deps"
    );
    node_json("viewer.mjs", &[html, &output_dir().join(name)])
}

/// Drives the report `html` in Chromium; returns the checker's `checks` after asserting it
/// found no failure.
fn drive(name: &str, html: &Path) -> serde_json::Value {
    let result = run_viewer(name, html);
    assert_eq!(
        result["failures"],
        serde_json::json!([]),
        "{name}: {result:#}"
    );
    // regions, weights, pose-lbs, pose-dqs, and pieces when the view offers it.
    let pieces = usize::from(result["checks"]["pieces_offered"] == true);
    assert_eq!(
        result["screenshots"].as_array().map(Vec::len),
        Some(4 + pieces)
    );
    result["checks"].clone()
}

/// Skins `input` with `atlas-skin skin --report --html` into the test output folder as
/// NAME.glb, NAME.json and NAME.html; returns the report and the page's path.
fn skin_with_report(name: &str, input: Option<&Path>) -> (serde_json::Value, PathBuf) {
    let dir = output_dir();
    let [glb, json, html] = ["glb", "json", "html"].map(|e| dir.join(format!("{name}.{e}")));
    let mut args: Vec<&OsStr> = vec!["skin".as_ref()];
    args.extend(input.map(Path::as_os_str));
    args.extend([
        "-o".as_ref(),
        glb.as_os_str(),
        "--report".as_ref(),
        json.as_os_str(),
        "--html".as_ref(),
        html.as_os_str(),
    ]);
    atlas_skin(&args);
    let report = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    (report, html)
}

/// The name of the treatment of every stored vertex in the report's `pieces`, with the
/// number of vertices of each.
fn stored_treatments(report: &serde_json::Value) -> Vec<(String, usize)> {
    let pieces = &report["pieces"];
    let names = pieces["treatments"].as_array().expect("treatments");
    let mut counts = vec![0; names.len()];
    for k in pieces["vertex_treatments"]
        .as_array()
        .expect("vertex treatments")
    {
        counts[k.as_u64().expect("an index") as usize] += 1;
    }
    names
        .iter()
        .zip(counts)
        .filter(|&(_, count)| count > 0)
        .map(|(name, count)| (name.as_str().unwrap().to_string(), count))
        .collect()
}

/// The pieces view's legend ("name count" per treatment) lists the treatments of the
/// report's stored vertices, in its order, with their counts.
fn assert_legend_matches_report(checks: &serde_json::Value, report: &serde_json::Value) {
    let legend: Vec<String> = stored_treatments(report)
        .iter()
        .map(|(name, count)| format!("{name} {count}"))
        .collect();
    assert_eq!(
        checks["pieces_legend"],
        serde_json::json!(legend),
        "{checks:#}"
    );
}

/// Writes the report of `glb` (with `report_json` if given) with `atlas-skin report` and
/// drives it in Chromium.
fn check_in_browser(
    name: &str,
    glb: &Path,
    report_json: Option<&serde_json::Value>,
) -> serde_json::Value {
    let dir = output_dir();
    let html = dir.join(format!("{name}.html"));
    let mut args = vec![
        OsStr::new("report"),
        glb.as_os_str(),
        OsStr::new("-o"),
        html.as_os_str(),
    ];
    let json_path = dir.join(format!("{name}.json"));
    if let Some(value) = report_json {
        std::fs::write(&json_path, value.to_string()).unwrap();
        args.extend([OsStr::new("--report"), json_path.as_os_str()]);
    }
    atlas_skin(&args);
    drive(name, &html)
}

/// The shader's posed positions (LBS and DQS, read back with transform feedback) equal the
/// runtime crate's scalar reference skinning of the same weights and palette, within 1e-5
/// of the model's size (f32 arithmetic on both sides).
fn assert_gpu_skinning_matches_reference(checks: &serde_json::Value) {
    let probe = &checks["skinning_probe"];
    let numbers = |key: &str| -> Vec<f32> {
        let values = probe[key]
            .as_array()
            .unwrap_or_else(|| panic!("probe has no {key}"));
        values.iter().map(|v| v.as_f64().unwrap() as f32).collect()
    };
    let points =
        |key: &str| -> Vec<Vec3> { numbers(key).chunks(3).map(Vec3::from_slice).collect() };
    let rest = points("rest");
    let palette: Vec<Mat4> = numbers("palette")
        .chunks(16)
        .map(Mat4::from_cols_slice)
        .collect();
    let joints = numbers("joints");
    let weights = numbers("weights");
    let rows = joints
        .chunks(4)
        .zip(weights.chunks(4))
        .map(|(j, w)| (0..4).map(move |k| (j[k] as u32, w[k])));
    let weights = VertexWeights::from_rows(rows);
    let size = rest
        .iter()
        .fold(0.0f32, |m, p| m.max(p.abs().max_element()));
    for (key, skin) in [
        (
            "lbs",
            reference::linear_blend_positions as fn(&[Vec3], &VertexWeights, &[Mat4], &mut [Vec3]),
        ),
        ("dqs", reference::dual_quaternion_positions),
    ] {
        let mut expected = vec![Vec3::ZERO; rest.len()];
        skin(&rest, &weights, &palette, &mut expected);
        let gpu = points(key);
        assert_eq!(gpu.len(), expected.len());
        let error = gpu
            .iter()
            .zip(&expected)
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f32::max);
        assert!(
            error <= 1e-5 * size,
            "{key}: GPU differs from the reference by {error} (size {size})"
        );
    }
}

/// Dragging a joint poses it (tests/js/viewer.mjs, `dragJoint`): the pointer pressed on a
/// joint with children and moved 80 px across its bone turns the joint by 90° about the view
/// direction (the bone follows the pointer) without moving the camera; the picture and the
/// joint's sliders change, and "Reset pose" undoes it. Fails when dragging does nothing.
fn assert_dragging_a_joint_poses_it(checks: &serde_json::Value) {
    let number = |key: &str| checks[key].as_f64().unwrap_or(f64::NAN);
    assert!(
        checks["drag_joint"].is_string(),
        "no joint was dragged: {checks:#}"
    );
    assert_eq!(checks["drag_camera_unchanged"], true, "{checks:#}");
    assert!(
        (number("drag_rotation_degrees") - 90.0).abs() < 10.0,
        "{checks:#}"
    );
    assert!(number("drag_aim_error_degrees") < 10.0, "{checks:#}");
    assert!(number("drag_changed_fraction") > 0.002, "{checks:#}");
    assert_eq!(checks["drag_sliders_changed"], true, "{checks:#}");
    assert!(number("drag_reset_degrees") < 1e-6, "{checks:#}");
}

#[test]
fn cesiumman_without_a_report_shows_the_file_weights() {
    let checks = check_in_browser("cesiumman", &CESIUMMAN.input_path(), None);
    assert_gpu_skinning_matches_reference(&checks);
    assert_dragging_a_joint_poses_it(&checks);
    assert_eq!(checks["animations"], 1);
    // The bent joint's blend zone looks different under dual quaternions.
    assert!(
        checks["dqs_changed_fraction"].as_f64() > Some(0.0),
        "{checks:#}"
    );
    assert_eq!(checks["report_tables"], 0);
    assert_eq!(checks["curve_segments"], 0);
}

#[test]
fn cesiumman_with_a_report_shows_cuts_tables_and_warnings() {
    // CesiumMan's bind space is Z-up, the hips at z = 0.68: a cut curve around the waist
    // (16 points) and a cut given by its plane only (drawn as a 48-point circle).
    let waist: Vec<[f64; 3]> = (0..16)
        .map(|k| {
            let angle = k as f64 * std::f64::consts::TAU / 16.0;
            [0.15 * angle.cos(), 0.15 * angle.sin(), 0.75]
        })
        .collect();
    let report = serde_json::json!({
        "decomposition": {
            "joints": [
                { "name": "node 3", "status": "cut", "perimeter": 0.94, "diameter": 0.3,
                  "overlap_width": 0.15, "curve": waist },
                { "name": "node 20", "status": "soft", "reason": "cut crosses another",
                  "point": [0.0, 0.0, 1.3], "normal": [0.0, 0.0, 1.0], "diameter": 0.2 },
            ],
            "regions": [
                { "joint": "node 2", "joints": ["node 2", "node 20"], "faces": 100 },
                { "joint": "node 3", "joints": ["node 3"], "faces": 50 },
            ],
        },
        "timings_ms": { "weld": 1.5, "decompose": 20.25 },
        "warnings": ["</script><b>not markup</b>"],
        "vertices": 3273,
    });
    let checks = check_in_browser("cesiumman_report", &CESIUMMAN.input_path(), Some(&report));
    assert_eq!(checks["curve_segments"], 16 + 48);
    assert_eq!(
        checks["pieces_offered"], false,
        "no treatments in this report"
    );
    // Joints, regions, timings and counts; each with a header row.
    assert_eq!(checks["report_tables"], 4);
    assert_eq!(checks["report_rows"], 3 + 3 + 3 + 2);
}

#[test]
fn riggedfigure_opens_and_poses() {
    let checks = check_in_browser("riggedfigure", &RIGGEDFIGURE.input_path(), None);
    assert_gpu_skinning_matches_reference(&checks);
    assert_dragging_a_joint_poses_it(&checks);
    assert_eq!(checks["animations"], 1);
}

/// A glTF binary from its JSON and binary chunk (both padded to 4 bytes here).
fn glb(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut json = json.to_string().into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let mut bytes = Vec::new();
    for word in [0x4654_6c67, 2, (12 + 8 + json.len() + 8 + bin.len()) as u32] {
        bytes.extend_from_slice(&u32::to_le_bytes(word));
    }
    for (chunk, kind) in [(&json, 0x4E4F_534Au32), (&bin, 0x004E_4942)] {
        bytes.extend_from_slice(&(chunk.len() as u32).to_le_bytes());
        bytes.extend_from_slice(&kind.to_le_bytes());
        bytes.extend_from_slice(chunk);
    }
    bytes
}

/// One skinned triangle on one joint, with four animations of that joint whose values at
/// t = 0.5 are known: LINEAR translation 0 → 1 gives 0.5; STEP gives 0; CUBICSPLINE with
/// out-tangent 3 at the first key and zero in-tangent at the second gives the Hermite value
/// h00·0 + h10·3 + h01·1 + h11·0 = 0.375 + 0.5 = 0.875; LINEAR rotation from identity to
/// 180° about z gives 90° about z (slerp).
///
/// `joint` is the joint index every vertex names in JOINTS_0 (0 is the only valid one).
fn animated_triangle(joint: u8) -> Vec<u8> {
    let floats: &[&[f32]] = &[
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0], // POSITION
        &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], // WEIGHTS_0
        &[0.0, 1.0],                                    // key times
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0],                // translations
        &[
            0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0,
            0.0,
        ], // cubic
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0],      // rotations
    ];
    let mut bin: Vec<u8> = [joint, 0, 0, 0].repeat(3); // JOINTS_0: u8 × 4 per vertex
    let mut views = vec![serde_json::json!({ "buffer": 0, "byteOffset": 0, "byteLength": 12 })];
    for values in floats {
        views.push(serde_json::json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": values.len() * 4 }));
        bin.extend(values.iter().flat_map(|v| v.to_le_bytes()));
    }
    let accessor = |view: usize, count: usize, kind: &str, component: u32| serde_json::json!({ "bufferView": view, "count": count, "type": kind, "componentType": component });
    let mut position = accessor(1, 3, "VEC3", 5126);
    position["min"] = serde_json::json!([0.0, 0.0, 0.0]);
    position["max"] = serde_json::json!([1.0, 1.0, 0.0]);
    let mut times = accessor(3, 2, "SCALAR", 5126);
    times["min"] = serde_json::json!([0.0]);
    times["max"] = serde_json::json!([1.0]);
    let channel = |name: &str, path: &str, output: usize, interpolation: &str| {
        serde_json::json!({
            "name": name,
            "channels": [{ "sampler": 0, "target": { "node": 0, "path": path } }],
            "samplers": [{ "input": 3, "output": output, "interpolation": interpolation }],
        })
    };
    let json = serde_json::json!({
        "asset": { "version": "2.0" },
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": views,
        "accessors": [
            accessor(0, 3, "VEC4", 5121), position, accessor(2, 3, "VEC4", 5126), times,
            accessor(4, 2, "VEC3", 5126), accessor(5, 6, "VEC3", 5126), accessor(6, 2, "VEC4", 5126),
        ],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 1, "JOINTS_0": 0, "WEIGHTS_0": 2 } }] }],
        "nodes": [{ "name": "bone" }, { "name": "triangle", "mesh": 0, "skin": 0 }],
        "skins": [{ "joints": [0] }],
        "scenes": [{ "nodes": [0, 1] }],
        "animations": [
            channel("linear", "translation", 4, "LINEAR"),
            channel("step", "translation", 4, "STEP"),
            channel("cubic", "translation", 5, "CUBICSPLINE"),
            channel("turn", "rotation", 6, "LINEAR"),
        ],
    });
    glb(&json, &bin)
}

#[test]
fn animations_are_sampled_linear_step_cubic_and_slerp() {
    let path = output_dir().join("animated_triangle.glb");
    std::fs::write(&path, animated_triangle(0)).unwrap();
    let checks = check_in_browser("animated_triangle", &path, None);
    let value = |a: usize| -> Vec<f64> {
        let values = checks["half_time_poses"][a][0]["value"].as_array().unwrap();
        values.iter().map(|v| v.as_f64().unwrap()).collect()
    };
    let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
    assert!(close(&value(0), &[0.5, 0.0, 0.0]), "linear {:?}", value(0));
    assert!(close(&value(1), &[0.0, 0.0, 0.0]), "step {:?}", value(1));
    assert!(close(&value(2), &[0.875, 0.0, 0.0]), "cubic {:?}", value(2));
    let half = std::f64::consts::FRAC_1_SQRT_2;
    assert!(
        close(&value(3), &[0.0, 0.0, half, half]),
        "slerp {:?}",
        value(3)
    );
}

#[test]
fn the_demo_character_skinned_by_the_project_shows_its_cuts_and_plays_a_bvh_motion() {
    let (report, html) = skin_with_report("demo", None);
    let checks = drive("demo", &html);
    assert!(checks["curve_segments"].as_u64() > Some(0), "{checks:#}");
    assert_eq!(checks["report_tables"], 4);
    assert_gpu_skinning_matches_reference(&checks);
    assert_dragging_a_joint_poses_it(&checks);
    // One piece, decomposed: the pieces view has one colour.
    assert_eq!(
        stored_treatments(&report),
        [(
            "body".to_string(),
            report["counts"]["vertices"].as_u64().unwrap() as usize
        )]
    );
    assert_legend_matches_report(&checks, &report);

    let dir = output_dir();
    let [glb, json] = ["demo.glb", "demo.json"].map(|f| dir.join(f));
    let walk = motion_path("walk.bvh");
    let animated = dir.join("demo_walk.html");
    atlas_skin(&[
        "report".as_ref(),
        glb.as_os_str(),
        "--report".as_ref(),
        json.as_os_str(),
        "--bvh".as_ref(),
        walk.as_os_str(),
        "-o".as_ref(),
        animated.as_os_str(),
    ]);
    let checks = drive("demo_walk", &animated);
    assert_eq!(checks["animations"], 1, "{checks:#}");
}

/// A benchmark character in 23 pieces (rignet-val/10563: body pieces, one with a gap of 96
/// vertices that no region with joints reaches, attached, rigid and bent pieces): every
/// stored vertex has a treatment, the treatments present are those of the report's pieces
/// and gaps, the fallback's among them exactly when the report counts fallback vertices;
/// the pieces view shows them.
#[test]
fn a_character_in_pieces_shows_each_piece_treatment_in_its_colour() {
    let input = data_file("bench/rignet-val/10563.glb");
    let (report, html) = skin_with_report("pieces_10563", Some(&input));
    let counts = &report["counts"];
    let vertex_treatments = report["pieces"]["vertex_treatments"].as_array().unwrap();
    assert_eq!(
        Some(vertex_treatments.len() as u64),
        counts["vertices"].as_u64()
    );
    let present: Vec<String> = stored_treatments(&report)
        .into_iter()
        .map(|(name, _)| name)
        .collect();
    let by_treatment = report["pieces"]["by_treatment"].as_object().unwrap();
    let gaps = report["pieces"]["gaps"].as_array().unwrap();
    assert!(!gaps.is_empty(), "{:#}", report["pieces"]);
    let mut expected: Vec<&str> = ["body", "attached", "rigid", "joints"]
        .into_iter()
        .filter(|name| {
            by_treatment.contains_key(*name) || gaps.iter().any(|gap| gap["treatment"] == *name)
        })
        .collect();
    if counts["fallback_weighted_vertices"].as_u64() > Some(0) {
        expected.push("fallback");
    }
    assert_eq!(present, expected, "{:#}", report["pieces"]["by_treatment"]);
    assert!(present.len() >= 3, "a character in pieces: {present:?}");

    let checks = drive("pieces_10563", &html);
    assert_eq!(checks["pieces_offered"], true);
    assert_legend_matches_report(&checks, &report);
}

/// A character of several skinned meshes and rigid meshes under joints
/// (robotexpressive: 4 skins over one skeleton, 15 rigid meshes): the report says which
/// stored vertices every primitive holds (`vertex_ranges`, covering all of them once), and
/// the pieces view colours every mesh, not only the largest: its legend counts every
/// stored vertex of the report.
#[test]
fn a_character_of_many_meshes_shows_every_mesh_in_the_pieces_view() {
    let input = data_file("bench/robotexpressive/RobotExpressive.glb");
    let (report, html) = skin_with_report("pieces_robot", Some(&input));
    let ranges = report["vertex_ranges"].as_array().expect("vertex_ranges");
    assert_eq!(ranges.len(), 19, "{ranges:#?}");
    let mut next = 0;
    for range in ranges {
        assert_eq!(range["first"].as_u64(), Some(next), "{range}");
        next += range["count"].as_u64().expect("count");
    }
    assert_eq!(Some(next), report["counts"]["vertices"].as_u64());
    let checks = drive("pieces_robot", &html);
    assert_eq!(checks["pieces_offered"], true);
    assert_legend_matches_report(&checks, &report);
}

#[test]
fn makehuman_skinned_by_the_project_opens_with_its_163_joints() {
    let dir = output_dir();
    let [glb, html] = ["makehuman.glb", "makehuman.html"].map(|f| dir.join(f));
    let mut args: Vec<OsString> = vec!["skin".into()];
    args.extend(MAKEHUMAN.input_args(false));
    args.extend([
        "-o".into(),
        glb.into(),
        "--html".into(),
        html.clone().into(),
    ]);
    atlas_skin(&args);
    let checks = drive("makehuman", &html);
    assert!(checks["curve_segments"].as_u64() > Some(0), "{checks:#}");
    assert_gpu_skinning_matches_reference(&checks);
    assert_dragging_a_joint_poses_it(&checks);
}

#[test]
fn a_model_naming_a_missing_joint_shows_an_error_instead_of_a_broken_view() {
    let dir = output_dir();
    let [glb, html] = ["bad_joint.glb", "bad_joint.html"].map(|f| dir.join(f));
    std::fs::write(&glb, animated_triangle(5)).unwrap();
    atlas_skin(&[
        "report".as_ref(),
        glb.as_os_str(),
        "-o".as_ref(),
        html.as_os_str(),
    ]);
    let result = run_viewer("bad_joint", &html);
    let failures = result["failures"].to_string();
    assert!(
        failures.contains("viewer error: mesh 0 uses joint 5 but its skin has 1 joints"),
        "{result:#}"
    );
}

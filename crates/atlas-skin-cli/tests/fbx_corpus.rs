//! The FBX characters of ../shared/data/fbx: `inspect --json` agrees with the counts of
//! fbx/README.md, `skin` writes a glb the Khronos validator passes, and the KayKit knight
//! read from FBX and from the bench's glb is the same skinned character for `eval`.

mod support;

use atlas_skin_corpus::{data_file, node_check};
use atlas_skin_io::{load_character, LoadOptions};
use serde_json::Value;
use support::{atlas_skin_ok, out_dir};

/// One row of fbx/README.md: file, meshes, vertices (control points), skin joints, max
/// influences, skinned vertices whose weights sum to 1 (within 0.01) of all skinned ones.
struct Row {
    file: &'static str,
    meshes: usize,
    vertices: u64,
    joints: usize,
    max_influences: usize,
    summing_to_one: Option<(usize, usize)>,
}

const ROWS: [Row; 4] = [
    Row {
        file: "KayKit_Knight.fbx",
        meshes: 9,
        vertices: 3004,
        joints: 23,
        max_influences: 4,
        summing_to_one: Some((1982, 3004)),
    },
    Row {
        file: "Skeleton_heaps_ascii.fbx",
        meshes: 2,
        vertices: 476,
        joints: 18,
        max_influences: 2,
        summing_to_one: None,
    },
    Row {
        file: "assimp_animation_with_skeleton.fbx",
        meshes: 1,
        vertices: 1058,
        joints: 14,
        max_influences: 6,
        summing_to_one: Some((48, 1058)),
    },
    Row {
        file: "assimp_huesitos.fbx",
        meshes: 1,
        vertices: 62,
        joints: 9,
        max_influences: 4,
        summing_to_one: Some((6, 62)),
    },
];

fn fbx(file: &str) -> String {
    data_file(&format!("fbx/{file}"))
        .to_str()
        .expect("utf-8 path")
        .to_string()
}

#[test]
fn inspect_agrees_with_the_readme_and_skin_writes_valid_glbs() {
    let dir = out_dir("fbx-corpus");
    let mut outputs = Vec::new();
    for row in &ROWS {
        let input = fbx(row.file);
        let output = atlas_skin_ok(&["inspect", "--json", &input]);
        let report: Value = serde_json::from_slice(&output.stdout).expect("inspect prints JSON");
        let file = row.file;
        assert_eq!(
            report["parts"].as_array().unwrap().len(),
            row.meshes,
            "{file}"
        );
        assert_eq!(report["vertices"], row.vertices, "{file}");
        assert_eq!(
            report["joints"].as_array().unwrap().len(),
            row.joints,
            "{file}"
        );
        assert_eq!(report["reference_weights"], true, "{file}");
        let space = report["space"].as_str().expect("units and axes are stated");
        assert!(
            space.contains("converted to glTF's metres, +Y up"),
            "{space}"
        );
        let warnings = report["warnings"].to_string();
        match row.summing_to_one {
            Some((summing, of)) => assert!(
                warnings.contains(&format!("sum to 1 on {summing} of {of} skinned vertices")),
                "{file}: {warnings}"
            ),
            None => assert!(!warnings.contains("sum to 1"), "{file}: {warnings}"),
        }
        let character = load_character(input.as_ref(), &LoadOptions::default()).unwrap();
        let weights = character.reference_weights.expect("weights");
        assert_eq!(weights.max_influences(), row.max_influences, "{file}");
        for v in 0..weights.vertex_count() {
            let sum: f32 = weights.row(v).map(|(_, w)| w).sum();
            assert!(
                sum == 0.0 || (sum - 1.0).abs() < 1e-5,
                "{file}: row {v} sums to {sum}"
            );
        }

        let glb = dir.join(file.replace(".fbx", ".glb"));
        atlas_skin_ok(&["skin", &input, "-o", glb.to_str().unwrap()]);
        outputs.push(glb);
    }
    for result in node_check("validate.mjs", &outputs) {
        assert_eq!(result["errors"], 0, "{result}");
    }
    // Base colours reach the glb: one primitive per material.
    let heaps = load_character(&outputs[1], &LoadOptions::default()).unwrap();
    let document = heaps.gltf.unwrap().document;
    assert_eq!(
        document["meshes"][0]["primitives"]
            .as_array()
            .unwrap()
            .len(),
        2
    );
    let huesitos = load_character(&outputs[3], &LoadOptions::default()).unwrap();
    let document = huesitos.gltf.unwrap().document;
    let color = &document["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"];
    // Diffuse colour (0.514, 0.606, 0.891) × diffuse factor 0.8.
    let expected = [0.4112, 0.4849, 0.7130, 1.0];
    for (c, e) in color.as_array().unwrap().iter().zip(expected) {
        assert!((c.as_f64().unwrap() - e).abs() < 1e-3, "{color}");
    }
}

#[test]
fn heaps_units_and_axes_become_metres_y_up_and_the_sword_is_rigid_on_the_root() {
    let character = load_character(
        fbx("Skeleton_heaps_ascii.fbx").as_ref(),
        &LoadOptions::default(),
    )
    .unwrap();
    // The file is Z up in centimetres (a 12 cm figure): the head is 6 cm above the pelvis
    // along +Y once converted.
    let skeleton = character.skeleton.as_ref().unwrap();
    let positions = skeleton.bind_positions();
    let at = |name: &str| positions[skeleton.find(name).unwrap()];
    let rise = at("Bip001 Head") - at("Bip001 Pelvis");
    assert!((rise.y - 0.06).abs() < 0.002, "{rise}");
    assert!(rise.x.abs() < 1e-3 && rise.z.abs() < 1e-3, "{rise}");
    let sword = &character.parts[1];
    assert_eq!(
        sword.binding,
        atlas_skin_io::PartBinding::Rigid { joint: 0 }
    );
    assert_eq!(skeleton.parent(0), None);
    let weights = character.reference_weights.unwrap();
    assert!(sword
        .vertices
        .clone()
        .all(|v| weights.row(v).collect::<Vec<_>>() == [(0, 1.0)]));
    assert!(character
        .warnings
        .iter()
        .any(|w| w.contains("rigid on the root joint")));
}

#[test]
fn the_knight_from_fbx_and_from_glb_deform_alike() {
    let reference = fbx("KayKit_Knight.fbx");
    let glb = data_file("bench/kaykit/Knight.glb");
    for (a, b) in [
        (reference.as_str(), glb.to_str().unwrap()),
        (glb.to_str().unwrap(), reference.as_str()),
    ] {
        let output = atlas_skin_ok(&["eval", a, b, "--json"]);
        let evaluation: Value = serde_json::from_slice(&output.stdout).expect("eval prints JSON");
        assert_eq!(
            evaluation["matched"], evaluation["vertices"],
            "{evaluation}"
        );
        for figure in ["deform_random", "deform_random_dqs"] {
            let max = evaluation[figure]["max"].as_f64().unwrap();
            assert!(max < 1e-4, "{a} vs {b}: {figure} max {max}");
        }
    }
}

#[test]
fn pose_and_report_take_fbx() {
    let dir = out_dir("fbx-pose-report");
    let input = fbx("assimp_huesitos.fbx");
    let obj = dir.join("posed.obj");
    atlas_skin_ok(&["pose", &input, "--random", "3", "-o", obj.to_str().unwrap()]);
    let rest = load_character(input.as_ref(), &LoadOptions::default()).unwrap();
    let posed = support::obj_positions(&obj);
    assert_eq!(posed.len(), 62);
    let moved = posed
        .iter()
        .zip(&rest.mesh.positions)
        .filter(|(p, r)| glam::Vec3::from_array(**p).distance(**r) > 1e-3)
        .count();
    assert!(moved > 0, "a random pose moves the cylinder");
    let html = dir.join("report.html");
    atlas_skin_ok(&["report", &input, "-o", html.to_str().unwrap()]);
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.len() > 10_000 && page.contains("<html"),
        "{}",
        page.len()
    );
}

#[test]
fn the_bind_pose_comes_from_the_clusters_not_the_current_nodes() {
    // assimp's animation_with_skeleton was saved posed: node Bone.006 now sits at x = -8.29 m,
    // its cluster's TransformLink (the bind pose) at x = -7.02 m.
    let character = load_character(
        fbx("assimp_animation_with_skeleton.fbx").as_ref(),
        &LoadOptions::default(),
    )
    .unwrap();
    let skeleton = character.skeleton.unwrap();
    let at = skeleton.bind_positions()[skeleton.find("Bone.006").unwrap()];
    assert!((at.x + 7.0216).abs() < 1e-3, "{at}");
}

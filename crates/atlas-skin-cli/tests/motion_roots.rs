//! A root joint at the floor under the body, whose one child is the hips, moves no skin
//! (`cuts::joint_roles`, rule 2), on a real character: KayKit's Knight (bench), whose
//! `root` took the hem of its tabard and the pelvis around the hips (74 vertices' worth of
//! weight; its artist gives the root none) and moved them with the whole character.

mod support;

#[test]
fn the_knights_root_at_the_floor_moves_no_skin() {
    let input = atlas_skin_corpus::data_dir().join("bench/kaykit/Knight.glb");
    let dir = support::out_dir("motion-roots");
    let (glb, report) = support::skin_with_report(&input, &dir, "knight");
    let joints = report["decomposition"]["joints"].as_array().unwrap();
    let root = joints.iter().find(|j| j["name"] == "root").unwrap();
    assert_eq!(root["status"], "skipped", "{root}");
    let reason = root["reason"].as_str().unwrap();
    assert!(
        reason.starts_with("motion root") && reason.contains("hips"),
        "{reason}"
    );
    // No vertex of the written file is bound to the root.
    let character = atlas_skin_io::gltf::read(&glb).expect("readable");
    let skeleton = character.skeleton.expect("a skin");
    let root = skeleton.names.iter().position(|n| n == "root").unwrap() as u32;
    let weights = character.reference_weights.expect("weights");
    let on_root = (0..weights.vertex_count())
        .flat_map(|v| weights.row(v))
        .filter(|&(joint, weight)| joint == root && weight > 0.0)
        .count();
    assert_eq!(on_root, 0);
    // Measured 0.0030 / 0.071 (0.0034 / 0.102 with the root moving the pelvis).
    let deform = support::deform_random(&input, &glb);
    assert!(deform["max"].as_f64().unwrap() < 0.09, "{deform}");
}

//! A leaf joint at the ankle whose foot runs on across its leg bone owns the foot when a
//! closed cut fits (`cuts::joint_roles`, rule 5 (c)), on real characters:
//! rignet-val/12913 and rignet-val/8168 (bench), whose feet have no toe joints. The ray
//! along the leg bone leaves the sole within a radius and the foot lies more than 60° off
//! the bone, so the ankles were end sites: the feet moved with the shins while their
//! artists bind them to the ankles.

mod support;

/// Skins `name` of the bench, checks that `ankles` are cut, and returns the deform figures
/// against its artist's weights.
fn skinned_with_cut_ankles(name: &str, ankles: [&str; 2]) -> serde_json::Value {
    let input = atlas_skin_corpus::data_dir().join(format!("bench/rignet-val/{name}.glb"));
    let dir = support::out_dir("feet-past-a-leaf-at-the-ankle");
    let (glb, report) = support::skin_with_report(&input, &dir, name);
    let joints = report["decomposition"]["joints"].as_array().unwrap();
    for ankle in ankles {
        let joint = joints.iter().find(|j| j["name"] == ankle).unwrap();
        assert_eq!(joint["status"], "cut", "{name}: {joint}");
    }
    support::deform_random(&input, &glb)
}

#[test]
fn feet_without_toe_joints_move_with_their_ankles() {
    // Measured 0.0150 / 0.0198 deform mean; with the feet on the shins 0.0173 / 0.0215.
    let deform = skinned_with_cut_ankles("12913", ["ankle_l1", "ankle_r1"]);
    assert!(deform["mean"].as_f64().unwrap() < 0.016, "{deform}");
    let deform = skinned_with_cut_ankles("8168", ["L_asi_jnt", "R_asi_jnt"]);
    assert!(deform["mean"].as_f64().unwrap() < 0.0207, "{deform}");
}

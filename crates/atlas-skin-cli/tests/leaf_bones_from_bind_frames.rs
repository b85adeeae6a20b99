//! A leaf joint takes its direction from its bind frame when the rig's frames run along its
//! bones (`skeleton::bone_axis`), on real characters: KayKit's Barbarian (bench), made in
//! Blender, whose toe joints point forward while the foot bones they would continue point
//! down into the soles; and rignet-val/1168, whose frames are the world's.

mod support;

use glam::DVec3;

/// Skins `name` of the bench; returns the report and the deform figures against its
/// artist's weights.
fn skinned(name: &str) -> (serde_json::Value, serde_json::Value, std::path::PathBuf) {
    let input = atlas_skin_corpus::data_dir().join(format!("bench/{name}.glb"));
    let stem = name.replace('/', "-");
    // One folder per character: the tests run in parallel and `out_dir` empties it.
    let dir = support::out_dir(&format!("leaf-bones-from-bind-frames-{stem}"));
    let (glb, report) = support::skin_with_report(&input, &dir, &stem);
    let deform = support::deform_random(&input, &glb);
    (report, deform, input)
}

#[test]
fn toes_are_cut_across_the_direction_of_their_bind_frames() {
    let (report, deform, input) = skinned("kaykit/Barbarian");
    let decomposition = &report["decomposition"];
    assert_eq!(decomposition["bone_axis"], "+y");
    let character = atlas_skin_io::gltf::read(&input).expect("readable");
    let skeleton = character.skeleton.expect("a skin");
    for toe in ["toes.l", "toes.r"] {
        let j = skeleton.names.iter().position(|n| n == toe).expect(toe);
        let frame_y = (skeleton.inverse_bind[j].inverse().y_axis.truncate())
            .as_dvec3()
            .normalize();
        let joint = decomposition["joints"]
            .as_array()
            .unwrap()
            .iter()
            .find(|joint| joint["name"] == toe)
            .unwrap();
        assert_eq!(joint["status"], "cut", "{joint}");
        let normal: Vec<f64> = serde_json::from_value(joint["normal"].clone()).unwrap();
        let normal = DVec3::from_slice(&normal);
        // Between the foot bone and the toe's own (the bisector's mitre): 28° from the
        // frame's +Y; 41° when the toe continued the foot bone.
        let angle = normal.angle_between(frame_y).to_degrees();
        assert!(angle < 35.0, "{toe}: {angle}° from its frame's +Y");
    }
    // Measured 0.0020 (0.0022 with the toes continuing the feet).
    assert!(deform["mean"].as_f64().unwrap() < 0.0021, "{deform}");
}

#[test]
fn world_frames_leave_leaves_on_their_parents_bones() {
    let (report, _, _) = skinned("rignet-val/1168");
    assert!(report["decomposition"]["bone_axis"].is_null(), "{report}");
}

/// `inspect` names the axis before anything is skinned, in text and JSON.
#[test]
fn inspect_names_the_bone_axis() {
    let inspect = |name: &str, json: bool| {
        let input = atlas_skin_corpus::data_dir().join(format!("bench/{name}.glb"));
        let mut args = vec!["inspect".into(), input.into_os_string()];
        if json {
            args.push("--json".into());
        }
        String::from_utf8(support::atlas_skin_ok(&args).stdout).unwrap()
    };
    let text = inspect("kaykit/Barbarian", false);
    assert!(
        text.contains("bone axis:             +y of the bind frames"),
        "{text}"
    );
    let text = inspect("rignet-val/1168", false);
    assert!(text.contains("bone axis:             none"), "{text}");
    let json: serde_json::Value = serde_json::from_str(&inspect("kaykit/Barbarian", true)).unwrap();
    assert_eq!(json["bone_axis"], "+y");
}

//! Rigs and meshes as they come (issue 12, item 3): a WebXR hand whose joints are all
//! siblings, upper legs stored as roots, duplicate faces, a skeleton that does not sit in
//! its mesh. Each is either handled as the clean input is, with a warning saying what was
//! done, or refused with an error that says why.

use atlas_skin::fixtures::demo::{demo_character, DemoCharacter, DEFAULT_STEP};
use atlas_skin::pipeline::{skin, SkinError, SkinInput, SkinParams, Skinned};
use atlas_skin::skeleton::placement::PlacementError;
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use glam::{Mat4, Vec3};
use std::sync::OnceLock;

fn demo() -> &'static DemoCharacter {
    static DEMO: OnceLock<DemoCharacter> = OnceLock::new();
    DEMO.get_or_init(|| demo_character(DEFAULT_STEP))
}

fn run(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    skeleton: &Skeleton,
) -> Result<Skinned, SkinError> {
    let input = SkinInput {
        positions,
        triangles,
        skeleton,
        end_joints: &[],
    };
    skin(input, &SkinParams::default(), &mut |_| {})
}

/// The joints' decisions (name, status) and every boundary (joint, kind, plane, curve), as JSON.
fn boundaries(skinned: &Skinned) -> serde_json::Value {
    let d = &skinned.decomposition;
    serde_json::json!({
        "joints": d.joints,
        "boundaries": format!("{:?}", d.boundaries),
        "regions": d.regions.len(),
    })
}

/// The demo's left hand: the triangles past x = 0.70 (the wrist is at 0.74) and the wrist
/// with its eight digit joints, linked as in the demo, and the same joints as a WebXR hand
/// stores them: WebXR names, no parent links.
#[test]
fn a_webxr_hand_without_links_gets_the_boundaries_of_the_linked_hand() {
    let demo = demo();
    let webxr_names = [
        ("hand_l", "wrist"),
        ("index1_l", "index-finger-phalanx-proximal"),
        ("index2_l", "index-finger-phalanx-intermediate"),
        ("middle1_l", "middle-finger-phalanx-proximal"),
        ("middle2_l", "middle-finger-phalanx-intermediate"),
        ("ring1_l", "ring-finger-phalanx-proximal"),
        ("ring2_l", "ring-finger-phalanx-intermediate"),
        ("thumb1_l", "thumb-phalanx-proximal"),
        ("thumb2_l", "thumb-phalanx-distal"),
    ];
    let s = &demo.skeleton;
    let index_of = |name: &str| s.names.iter().position(|n| n == name).unwrap();
    let kept: Vec<usize> = webxr_names.iter().map(|(n, _)| index_of(n)).collect();
    let parents: Vec<u32> = kept
        .iter()
        .map(|&j| {
            s.parent(j)
                .and_then(|p| kept.iter().position(|&k| k == p))
                .map_or(NO_PARENT, |k| k as u32)
        })
        .collect();
    let binds: Vec<Mat4> = kept.iter().map(|&j| s.inverse_bind[j]).collect();
    let linked = Skeleton::new(
        kept.iter().map(|&j| s.names[j].clone()).collect(),
        parents,
        binds.clone(),
    )
    .unwrap();
    let webxr = Skeleton::new(
        webxr_names.iter().map(|(_, w)| w.to_string()).collect(),
        vec![NO_PARENT; kept.len()],
        binds,
    )
    .unwrap();
    let triangles: Vec<[u32; 3]> = demo
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| demo.positions[v as usize].x > 0.70))
        .copied()
        .collect();

    let from_links = run(&demo.positions, &triangles, &linked).unwrap();
    let from_names = run(&demo.positions, &triangles, &webxr).unwrap();
    assert!(from_links.warnings.iter().all(|w| !w.contains("inferred")));
    let warning = from_names.warnings.join("\n");
    assert!(
        warning.contains("have no parent links") && warning.contains("WebXR hand"),
        "{warning}"
    );
    assert_eq!(from_names.skeleton.parents, linked.parents);
    let cuts = from_links.decomposition.report().cuts;
    assert!(cuts >= 8, "the hand's digits are cut: {cuts}");
    let mut expected = boundaries(&from_links);
    for (joint, (_, webxr_name)) in expected["joints"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .zip(webxr_names)
    {
        joint["name"] = webxr_name.into();
    }
    assert_eq!(boundaries(&from_names), expected);
    assert_eq!(from_names.weights, from_links.weights);
}

/// The demo with both upper legs stored as roots: they are attached to the hips (the
/// nearest joint), said so, and the boundaries are those of the linked demo.
#[test]
fn upper_legs_stored_as_roots_are_attached_to_the_hips() {
    let demo = demo();
    let mut loose = demo.skeleton.clone();
    for name in ["upleg_l", "upleg_r"] {
        let j = loose.names.iter().position(|n| n == name).unwrap();
        loose.parents[j] = NO_PARENT;
    }
    let linked = run(&demo.positions, &demo.triangles, &demo.skeleton).unwrap();
    let inferred = run(&demo.positions, &demo.triangles, &loose).unwrap();
    let warning = inferred.warnings.join("\n");
    assert!(
        warning.contains("3 roots")
            && warning.contains("upleg_l → hips")
            && warning.contains("upleg_r → hips"),
        "{warning}"
    );
    assert_eq!(inferred.skeleton.parents, demo.skeleton.parents);
    assert_eq!(boundaries(&inferred), boundaries(&linked));
}

/// The demo's joints without any link and with neutral names: a tree from positions, a
/// warning, and the body is still cut at its limbs (not one rigid region).
#[test]
fn unlinked_joints_get_a_tree_from_positions() {
    let demo = demo();
    let loose = Skeleton::new(
        (0..demo.skeleton.len())
            .map(|j| format!("joint{j}"))
            .collect(),
        vec![NO_PARENT; demo.skeleton.len()],
        demo.skeleton.inverse_bind.clone(),
    )
    .unwrap();
    let skinned = run(&demo.positions, &demo.triangles, &loose).unwrap();
    let warning = skinned.warnings.join("\n");
    assert!(warning.contains("link(s) from positions"), "{warning}");
    let cuts = skinned.decomposition.report().cuts;
    assert!(cuts >= 30, "{cuts} cuts (33 with the demo's links)");
}

/// The demo with every face stored twice (once flipped, once as is) and the demo with a
/// third of its faces doubled: the same boundaries and weights as the clean demo, and the
/// count of removed faces.
#[test]
fn duplicate_faces_give_the_cuts_of_the_clean_mesh() {
    let demo = demo();
    let clean = run(&demo.positions, &demo.triangles, &demo.skeleton).unwrap();
    let flipped = demo.triangles.iter().map(|&[a, b, c]| [a, c, b]);
    let doubled: Vec<[u32; 3]> = demo.triangles.iter().copied().chain(flipped).collect();
    let some: Vec<[u32; 3]> = demo
        .triangles
        .iter()
        .copied()
        .chain(demo.triangles.iter().step_by(3).copied())
        .collect();
    for (triangles, removed) in [
        (doubled, demo.triangles.len()),
        (some, demo.triangles.len().div_ceil(3)),
    ] {
        let skinned = run(&demo.positions, &triangles, &demo.skeleton).unwrap();
        assert_eq!(skinned.counts.duplicate_faces, removed);
        assert!(skinned
            .warnings
            .iter()
            .any(|w| w.contains("duplicate faces")));
        assert_eq!(boundaries(&skinned), boundaries(&clean));
        assert_eq!(skinned.weights, clean.weights);
    }
}

/// The demo's skeleton transformed by `m` in the bind space (its inverse bind matrices
/// composed with `m⁻¹`).
fn moved(skeleton: &Skeleton, m: Mat4) -> Skeleton {
    Skeleton {
        inverse_bind: skeleton
            .inverse_bind
            .iter()
            .map(|&b| b * m.inverse())
            .collect(),
        ..skeleton.clone()
    }
}

/// A skeleton 1 m in front of the body is refused; one with all joints at one point, 1 m
/// to the side (arms still in the box) or upside down is skinned with warnings that say
/// the skeleton does not sit in the body.
#[test]
fn a_skeleton_that_does_not_sit_in_the_body_is_refused_or_warned_about() {
    let demo = demo();
    let skin_with = |skeleton: &Skeleton| run(&demo.positions, &demo.triangles, skeleton);

    let ahead = moved(
        &demo.skeleton,
        Mat4::from_translation(Vec3::new(0.0, 0.0, 1.0)),
    );
    let error = skin_with(&ahead).unwrap_err();
    assert!(
        matches!(
            error,
            SkinError::Placement(PlacementError::BesideMesh { .. })
        ),
        "{error:?}"
    );
    let source = std::error::Error::source(&error).unwrap().to_string();
    assert!(
        source.contains("no joint lies within the mesh's bounding box"),
        "{source}"
    );

    let one_point = Skeleton {
        inverse_bind: vec![Mat4::from_translation(-Vec3::Y); demo.skeleton.len()],
        ..demo.skeleton.clone()
    };
    let warnings = skin_with(&one_point).unwrap().warnings.join("\n");
    assert!(
        warnings.contains("all 35 joints sit at one point"),
        "{warnings}"
    );

    let aside = moved(
        &demo.skeleton,
        Mat4::from_translation(Vec3::new(1.0, 0.0, 0.0)),
    );
    let warnings = skin_with(&aside).unwrap().warnings.join("\n");
    assert!(
        warnings.contains("joints lie beside the mesh"),
        "{warnings}"
    );

    let centre = Vec3::new(0.0, 0.9, 0.0);
    let flip = Mat4::from_translation(centre)
        * Mat4::from_rotation_z(std::f32::consts::PI)
        * Mat4::from_translation(-centre);
    let upside_down = skin_with(&moved(&demo.skeleton, flip)).unwrap();
    let warnings = upside_down.warnings.join("\n");
    assert!(warnings.contains("may not sit in the body"), "{warnings}");
}

/// The demo with helper joints added as exporters leave them: a KayKit hand slot in the
/// left palm, a locator in the head, Unreal's foot IK chain (a root at the floor, a target
/// at each ankle) and a knee pole target in front of the knee. They move no skin and are
/// named in a warning; every joint of the demo keeps its decision (the locator, a child of
/// the head, turns the head's plane a little). `--force` gives a helper its skin back.
#[test]
fn joints_named_as_helpers_move_no_skin() {
    let demo = demo();
    let s = &demo.skeleton;
    let index_of = |name: &str| s.names.iter().position(|n| n == name).unwrap() as u32;
    let position = |name: &str| s.bind_positions()[index_of(name) as usize];
    let helpers = [
        ("handslot.l", index_of("hand_l"), Vec3::new(0.80, 1.40, 0.0)),
        ("loc_eye", index_of("head"), Vec3::new(0.0, 1.68, 0.08)),
        ("ik_foot_root", index_of("hips"), Vec3::ZERO),
        ("ik_foot_l", s.len() as u32 + 2, position("foot_l")),
        ("ik_foot_r", s.len() as u32 + 2, position("foot_r")),
        ("PoleTarget_l", index_of("hips"), Vec3::new(0.11, 0.5, 0.4)),
    ];
    let mut names = s.names.clone();
    let mut parents = s.parents.clone();
    let mut positions = s.bind_positions();
    for (name, parent, at) in helpers {
        names.push(name.into());
        parents.push(parent);
        positions.push(at);
    }
    let with_helpers = Skeleton::from_positions(names, parents, &positions).unwrap();
    let plain = run(&demo.positions, &demo.triangles, s).unwrap();
    let skin_with = |force: Vec<String>| {
        let params = SkinParams {
            decompose: atlas_skin::DecomposeParams {
                force,
                ..Default::default()
            },
            ..Default::default()
        };
        let input = SkinInput {
            positions: &demo.positions,
            triangles: &demo.triangles,
            skeleton: &with_helpers,
            end_joints: &[],
        };
        skin(input, &params, &mut |_| {}).unwrap()
    };
    let skinned = skin_with(Vec::new());
    let warning = skinned.warnings.join("\n");
    assert!(
        warning.contains("6 joint(s) named as helpers")
            && helpers.iter().all(|(name, ..)| warning.contains(name)),
        "{warning}"
    );
    let mut got = boundaries(&skinned);
    let helper_decisions = got["joints"].as_array_mut().unwrap().split_off(s.len());
    assert!(helper_decisions.iter().all(|j| j["reason"]
        .as_str()
        .unwrap()
        .starts_with("named as a helper")));
    let expected = boundaries(&plain);
    assert_eq!(got["joints"], expected["joints"]);
    assert_eq!(got["regions"], expected["regions"]);
    let weighted = |skinned: &Skinned, joint: usize| {
        skinned
            .weights
            .joints
            .iter()
            .zip(&skinned.weights.weights)
            .any(|(&j, &w)| j as usize == joint && w > 0.0)
    };
    assert!((s.len()..with_helpers.len()).all(|j| !weighted(&skinned, j)));

    // Forced, the slot in the palm is a joint again and takes part of the hand.
    let forced = skin_with(vec!["handslot.l".into()]);
    assert!(forced.decomposition.joints[s.len()].owns_skin);
    assert!(weighted(&forced, s.len()));
    assert!(!forced.warnings.join("\n").contains("handslot.l"));
}

//! Decomposition of the real characters of `../shared/data/models`.
//!
//! Every closed genus-0 model: regions = cuts + 1, every face in a region, no two curves
//! crossing or touching, its elbows, knees, wrists and ankles cut (by name where the file
//! names them, by the manifest's structure otherwise), and no joint inside the mesh without
//! a boundary unless it owns no geometry (root, end site, branching joint on the mirror
//! plane at the skin); the joints the paper's rules
//! miss (toes past the ball of a foot, branching joints on the mirror plane that own a part
//! of the trunk) have one. The open strip simpleskin finishes with a reason for every
//! joint.

mod decompose_checks;

use atlas_skin::mesh::weld::DEFAULT_WELD_TOLERANCE;
use atlas_skin::mesh::winding::winding_number;
use atlas_skin::{
    decompose, weld, DecomposeParams, Decomposition, JointStatus, SurfaceMesh, Topology,
};
use atlas_skin_corpus::{
    Model, ARM, CESIUMMAN, ELEPHANT, HAND, MAKEHUMAN, RIGGEDFIGURE, RIGGEDSIMPLE, SIMPLESKIN,
};
use atlas_skin_io::load_character;
use atlas_skin_runtime::Skeleton;
use decompose_checks::check_decomposition;

/// The model's welded mesh and skeleton, and their decomposition with the default
/// parameters.
fn decomposed(model: &Model) -> (SurfaceMesh, Skeleton, Decomposition) {
    let character = load_character(&model.input_path(), &model.load_options(false))
        .unwrap_or_else(|e| panic!("{}: {e}", model.name));
    let welded = weld(
        &character.mesh.positions,
        &character.mesh.triangles,
        DEFAULT_WELD_TOLERANCE,
    );
    let skeleton = character.skeleton.expect("the model has a skeleton");
    let d = decompose(
        &welded.mesh,
        &Topology::new(&welded.mesh),
        &skeleton,
        &DecomposeParams::default(),
    )
    .expect("decomposes");
    (welded.mesh, skeleton, d)
}

/// Reasons for which a joint inside the mesh may have no boundary: it owns no geometry.
const NO_GEOMETRY: [&str; 3] = [
    "root joint",
    "end site",
    "branching joint on the mirror plane",
];

/// Decomposes a closed genus-0 model, checks the invariants and that `required` joints
/// are cut; prints the report's summary.
fn check_closed_model(model: &Model, required: &[&str]) -> Decomposition {
    let (mesh, skeleton, d) = decomposed(model);
    let cuts = check_decomposition(&d, true);
    let positions = skeleton.bind_positions();
    for (j, decision) in d.joints.iter().enumerate() {
        if decision.status != JointStatus::Cut {
            eprintln!("{}: {} {:?}", model.name, decision.name, decision.status);
        }
        let inside = winding_number(&mesh, positions[j].as_dvec3()).abs() > 0.5;
        if let (true, JointStatus::Skipped(reason)) = (inside, &decision.status) {
            assert!(
                NO_GEOMETRY.iter().any(|r| reason.starts_with(r)),
                "{}: {} is inside the mesh but has no boundary: {reason}",
                model.name,
                decision.name
            );
        }
    }
    for name in required {
        let decision = d
            .joints
            .iter()
            .find(|j| j.name == *name)
            .unwrap_or_else(|| panic!("{}: no joint {name}", model.name));
        assert_eq!(
            decision.status,
            JointStatus::Cut,
            "{}: {name} is not cut",
            model.name
        );
    }
    let report = d.report();
    eprintln!(
        "{}: {} cuts, {} soft, {} skipped, {} regions",
        model.name,
        cuts,
        report.soft,
        report.skipped,
        d.regions.len()
    );
    d
}

/// Asserts that each of `names` has a boundary (cut or soft): it moves its part of the body.
fn assert_bounded(d: &Decomposition, model: &str, names: &[&str]) {
    for name in names {
        let decision = d
            .joints
            .iter()
            .find(|j| j.name == *name)
            .unwrap_or_else(|| panic!("{model}: no joint {name}"));
        assert!(
            decision.boundary.is_some(),
            "{model}: {name} has no boundary: {:?}",
            decision.status
        );
    }
}

#[test]
fn riggedsimple_cuts_its_leaf_joint() {
    let model = RIGGEDSIMPLE;
    let d = check_closed_model(&model, &["node3"]);
    assert_eq!(d.regions.len(), 2);
}

/// RiggedFigure and CesiumMan share the node layout (manifest `khronos_name`): elbows
/// node17/node14, wrists node18/node15, knees node8/node4, ankles node9/node5.
const FIGURE_LIMB_JOINTS: [&str; 8] = [
    "node17", "node14", "node18", "node15", "node8", "node4", "node9", "node5",
];

#[test]
fn riggedfigure_cuts_every_limb_joint() {
    let model = RIGGEDFIGURE;
    check_closed_model(&model, &FIGURE_LIMB_JOINTS);
}

#[test]
fn cesiumman_cuts_every_limb_joint() {
    let model = CESIUMMAN;
    let d = check_closed_model(&model, &FIGURE_LIMB_JOINTS);
    // The toes: leaves past the ball of the foot, whose bone points down into the sole.
    assert_bounded(&d, "cesiumman", &["node10", "node6"]);
}

#[test]
fn arm_cuts_its_chain() {
    let model = ARM;
    // Shoulder tgf_2, elbow tgf_3, wrist tgf_4 (manifest positions along +x).
    check_closed_model(&model, &["tgf_2", "tgf_3", "tgf_4"]);
}

#[test]
fn hand_cuts_its_fingers() {
    let model = HAND;
    // The wrist tgf_2 (five finger bones) and every finger joint but the tips.
    let mut required = vec!["tgf_2".to_string()];
    for first in [3, 6, 10, 14, 18] {
        let joints = if first == 3 { 3..5 } else { first..first + 3 };
        required.extend(joints.map(|j| format!("tgf_{j}")));
    }
    let required: Vec<&str> = required.iter().map(String::as_str).collect();
    check_closed_model(&model, &required);
}

#[test]
fn elephant_cuts_its_limbs() {
    let model = ELEPHANT;
    // Elbows tgf_9/tgf_13, wrists tgf_10/tgf_14, knees tgf_17/tgf_22, ankles tgf_18/tgf_23
    // (the second and third joints of the limb chains; manifest positions).
    check_closed_model(
        &model,
        &[
            "tgf_9", "tgf_13", "tgf_10", "tgf_14", "tgf_17", "tgf_22", "tgf_18", "tgf_23",
        ],
    );
}

#[test]
fn makehuman_body_cuts_every_limb_joint() {
    let model = MAKEHUMAN;
    let d = check_closed_model(
        &model,
        &[
            "lowerarm01.L",
            "lowerarm01.R",
            "wrist.L",
            "wrist.R",
            "lowerleg01.L",
            "lowerleg01.R",
            "foot.L",
            "foot.R",
        ],
    );
    // Branching joints on the mirror plane that own the head and the lower trunk.
    assert_bounded(&d, "makehuman", &["head", "spine01", "spine02"]);
}

#[test]
fn simpleskin_open_strip_finishes_with_reasons() {
    let (_, _, d) = decomposed(&SIMPLESKIN);
    check_decomposition(&d, false);
    assert_eq!(d.joints.len(), 2);
    assert!(d
        .joints
        .iter()
        .all(|j| !matches!(j.status, JointStatus::Cut)));
    let report = serde_json::to_value(d.report()).expect("serialisable");
    for joint in report["joints"].as_array().expect("joints") {
        assert!(joint["reason"].is_string(), "{joint}");
    }
}

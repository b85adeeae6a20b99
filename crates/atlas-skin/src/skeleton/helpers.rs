//! Helper joints by name (issue 12, "rigs as found"): joints that exporters and rigging
//! tools add to a skeleton to place things, not to deform the skin. A glTF skin lists them
//! beside the deforming joints and carries no flag that tells them apart, but their names
//! follow conventions:
//!
//! - attachment points: `*slot*`, `*socket*` (KayKit's `handslot.l`, engine sockets
//!   exported as bones);
//! - locators: `loc_*`, `loc.*`, `*locator*` (`loc_eye`, `loc_mouth`);
//! - IK targets and poles: `ik_*`, `ik.*`, `*target*`, `*pole*` (Unreal's `ik_foot_l`,
//!   `ik_hand_gun`; `PoleTargetL`);
//! - Unreal's virtual bones: `VB *`.
//!
//! Matched case-insensitively on the name after any namespace (`mixamorig:`, `Armature|`).
//! On the benchmark every joint so named (handslots of the 4 KayKit adventurers, locators
//! of 18 characters, IK targets and poles of 2) carries no weight of the artist's. A joint
//! is a helper when its name follows a convention and so do the names of every joint below
//! it, so that no deforming joint hangs from one.

use atlas_skin_runtime::Skeleton;

/// Whether `name` follows one of the conventions of the module documentation.
pub fn is_helper_name(name: &str) -> bool {
    let local = name.rsplit([':', '|']).next().unwrap_or(name);
    let name = local.to_lowercase();
    let starts = |prefixes: &[&str]| prefixes.iter().any(|p| name.starts_with(p));
    let contains = |words: &[&str]| words.iter().any(|w| name.contains(w));
    contains(&["slot", "socket", "locator", "target", "pole"])
        || starts(&["loc_", "loc.", "ik_", "ik.", "vb "])
}

/// #J: whether each joint of `skeleton` is a helper: named as one, as is every joint below
/// it.
pub fn helper_joints(skeleton: &Skeleton) -> Vec<bool> {
    // Joints with a deforming joint at or below them: each walk up from a deforming joint
    // stops at the first joint already marked, whose ancestors its own walk marked.
    let mut deforming_below = vec![false; skeleton.len()];
    for j in 0..skeleton.len() {
        if is_helper_name(&skeleton.names[j]) || deforming_below[j] {
            continue;
        }
        deforming_below[j] = true;
        for a in skeleton.ancestors(j) {
            if std::mem::replace(&mut deforming_below[a], true) {
                break;
            }
        }
    }
    deforming_below.into_iter().map(|d| !d).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    #[test]
    fn names_of_slots_locators_and_ik_targets_mark_helpers() {
        for name in [
            "handslot.l",
            "mixamorig:HandSlot_R",
            "loc_eye",
            "Loc_Mouth",
            "ik_foot_l",
            "ik_hand_gun",
            "PoleTargetL",
            "targetR",
            "VB hand_r_weapon",
            "Armature|weapon_socket",
        ] {
            assert!(is_helper_name(name), "{name}");
        }
        for name in [
            "LeftHand",
            "Head",
            "Bip01_L_Clavicle",
            "mixamorig:LeftToeBase",
            "lower_lip",
            "blocker",
            "spike_01",
            "Dummy015",
        ] {
            assert!(!is_helper_name(name), "{name}");
        }
    }

    #[test]
    fn a_helper_name_above_a_deforming_joint_is_no_helper() {
        // root → ik_root → (ik_foot_l, target_chain → knee)
        let skeleton = Skeleton::from_positions(
            ["root", "ik_root", "ik_foot_l", "target_chain", "knee"]
                .map(String::from)
                .to_vec(),
            vec![NO_PARENT, 0, 1, 1, 3],
            &[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE],
        )
        .expect("valid skeleton");
        assert_eq!(helper_joints(&skeleton), [false, false, true, false, false]);
    }
}

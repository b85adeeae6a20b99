//! The FBX reader on the corpus's FBX files (../shared/data/fbx).

use atlas_skin_corpus::data_file;
use atlas_skin_io::{fbx, Contents};

/// What skinning reads ([`fbx::read_contents`] with `Contents::ForSkinning`) is what
/// [`fbx::read`] reads but the stored weights: the same meshes, skeleton, rig, parts,
/// materials and conversion of units and axes, and the same warnings but those about the
/// stored weights (three of the four files have rows that do not sum to 1).
#[test]
fn reading_for_skinning_skips_only_the_stored_weights() {
    let mut files_with_sum_warnings = 0;
    for file in [
        "KayKit_Knight.fbx",
        "Skeleton_heaps_ascii.fbx",
        "assimp_animation_with_skeleton.fbx",
        "assimp_huesitos.fbx",
    ] {
        let path = data_file(&format!("fbx/{file}"));
        let whole = fbx::read(&path).unwrap();
        let skinning = fbx::read_contents(&path, Contents::ForSkinning).unwrap();
        assert_eq!(skinning.mesh, whole.mesh, "{file}");
        assert_eq!(skinning.skeleton, whole.skeleton, "{file}");
        assert_eq!(skinning.rig, whole.rig, "{file}");
        let about_other_things: Vec<&String> = whole
            .warnings
            .iter()
            .filter(|w| !w.starts_with("skin weights sum to 1 on"))
            .collect();
        assert_eq!(
            skinning.warnings.iter().collect::<Vec<_>>(),
            about_other_things,
            "{file}"
        );
        files_with_sum_warnings += usize::from(about_other_things.len() < whole.warnings.len());
        assert_eq!(skinning.file_vertex, whole.file_vertex, "{file}");
        assert_eq!(skinning.parts, whole.parts, "{file}");
        assert_eq!(skinning.materials, whole.materials, "{file}");
        assert_eq!(
            skinning.triangle_materials, whole.triangle_materials,
            "{file}"
        );
        assert_eq!(skinning.space, whole.space, "{file}");
        assert!(whole.reference_weights.is_some(), "{file}");
        assert!(skinning.reference_weights.is_none(), "{file}");
    }
    assert_eq!(files_with_sum_warnings, 3);
}

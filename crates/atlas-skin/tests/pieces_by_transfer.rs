//! The pieces that hold no bone weighted by transfer from the pieces that hold bones
//! (`loose_pieces: transfer`, crates/atlas-skin/src/weights/pieces_by_transfer.rs), on the
//! demo character: a patch on the thigh moves with the thigh, the pieces that hold bones
//! keep the contact run's weights, a prop far from the body keeps the contact rule's
//! weights with a warning.

use atlas_skin::fixtures::demo::{demo_character, DemoCharacter};
use atlas_skin::fixtures::shapes::icosphere;
use atlas_skin::mesh::SurfaceMesh;
use atlas_skin::pipeline::{skin, SkinInput, SkinParams, Skinned};
use atlas_skin::weights::pieces_by_transfer::LoosePieces;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;

/// The demo (coarse grid: a quick test) with `extra` moved by `offset` added; returns the
/// character and the first stored vertex of `extra` (its vertices run to the end).
fn demo_with(extra: &SurfaceMesh, offset: DVec3) -> (DemoCharacter, usize) {
    let mut demo = demo_character(0.02);
    let first = demo.positions.len();
    demo.positions
        .extend(extra.positions.iter().map(|&p| (p + offset).as_vec3()));
    demo.triangles
        .extend(extra.triangles.iter().map(|t| t.map(|v| v + first as u32)));
    (demo, first)
}

fn skinned(demo: &DemoCharacter, loose_pieces: LoosePieces) -> Skinned {
    let params = SkinParams {
        loose_pieces,
        ..SkinParams::default()
    };
    let input = SkinInput {
        positions: &demo.positions,
        triangles: &demo.triangles,
        skeleton: &demo.skeleton,
        end_joints: &[],
    };
    skin(input, &params, &mut |_| {}).expect("skinned")
}

fn joint(skeleton: &Skeleton, name: &str) -> u32 {
    skeleton.names.iter().position(|n| n == name).expect(name) as u32
}

/// A patch sewn on the front of the left thigh: the demo's own faces there (x > 0.07, y in
/// 0.6..0.75, z > 0.03), pushed out along their normals by 5 mm. No bone enters it and
/// no joint lies in its bounding box: a piece that holds no bone.
fn thigh_patch() -> SurfaceMesh {
    let demo = demo_character(0.02);
    let body = SurfaceMesh {
        positions: demo.positions.iter().map(|p| p.as_dvec3()).collect(),
        triangles: demo.triangles.clone(),
    };
    let normals = body.vertex_normals();
    let inside = |p: DVec3| p.x > 0.07 && p.x < 0.2 && (0.6..0.75).contains(&p.y) && p.z > 0.03;
    let mut local = vec![u32::MAX; body.positions.len()];
    let mut positions = Vec::new();
    for (v, &p) in body.positions.iter().enumerate() {
        if inside(p) {
            local[v] = positions.len() as u32;
            positions.push(p + 0.005 * normals[v]);
        }
    }
    let triangles = body
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| local[v as usize] != u32::MAX))
        .map(|t| t.map(|v| local[v as usize]))
        .collect();
    SurfaceMesh {
        positions,
        triangles,
    }
}

#[test]
fn a_patch_on_the_thigh_moves_with_the_thigh_and_the_body_keeps_its_weights() {
    let (demo, patch_start) = demo_with(&thigh_patch(), DVec3::ZERO);
    let (patch_end, skeleton) = (demo.positions.len(), &demo.skeleton);
    assert!(
        patch_end - patch_start > 20,
        "a patch of {} vertices",
        patch_end - patch_start
    );
    let contact = skinned(&demo, LoosePieces::Contact);
    let transfer = skinned(&demo, LoosePieces::Transfer);
    assert!(
        transfer
            .warnings
            .iter()
            .all(|w| !w.message.contains("contact rule")),
        "{:?}",
        transfer.warnings
    );
    let piece_of = &transfer.decomposition.topology.vertex_component;
    let pieces = &transfer.counts.weights.pieces;
    let patch_piece = piece_of[transfer.welded_of_stored[patch_start] as usize] as usize;
    assert!(!pieces[patch_piece].holds_bones);
    assert_eq!(contact.counts.weights.transferred, 0);
    assert_eq!(
        transfer.counts.weights.transferred,
        pieces[patch_piece].vertices
    );
    // Every other vertex keeps the contact run's weights.
    for v in 0..patch_start {
        let x: Vec<_> = contact.weights.row(v).collect();
        assert_eq!(
            x,
            transfer.weights.row(v).collect::<Vec<_>>(),
            "body vertex {v}"
        );
    }
    // The patch moves with the thigh under it: the left thigh's joint heaviest in every
    // row, next to no weight on an arm, the head or the other leg.
    let thigh = joint(skeleton, "upleg_l");
    let far: Vec<u32> = [
        "head",
        "upperarm_l",
        "upperarm_r",
        "hand_l",
        "upleg_r",
        "lowerleg_r",
    ]
    .iter()
    .map(|n| joint(skeleton, n))
    .collect();
    for v in patch_start..patch_end {
        let row: Vec<(u32, f32)> = transfer.weights.row(v).collect();
        let total: f32 = row.iter().map(|r| r.1).sum();
        assert!((total - 1.0).abs() < 1e-5, "patch vertex {v}: {row:?}");
        let on_far: f32 = row
            .iter()
            .filter(|(j, _)| far.contains(j))
            .map(|r| r.1)
            .sum();
        assert!(on_far < 1e-3, "patch vertex {v}: {row:?}");
        let heaviest = row.iter().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap().0;
        assert_eq!(heaviest, thigh, "patch vertex {v}: {row:?}");
    }
}

#[test]
fn a_prop_far_from_the_body_keeps_the_contact_rules_weights_with_a_warning() {
    // A ball half a metre in front of the chest: no vertex within the matching distance.
    let ball = icosphere(0.05, 2);
    let (demo, ball_start) = demo_with(&ball, DVec3::new(0.0, 1.3, 0.6));
    let contact = skinned(&demo, LoosePieces::Contact);
    let transfer = skinned(&demo, LoosePieces::Transfer);
    let piece_of = &transfer.decomposition.topology.vertex_component;
    let ball_piece = piece_of[transfer.welded_of_stored[ball_start] as usize] as usize;
    assert!(!transfer.counts.weights.pieces[ball_piece].holds_bones);
    let warning = transfer
        .warnings
        .iter()
        .find(|w| w.message.contains("keep the contact rule's weights"))
        .unwrap_or_else(|| panic!("a warning: {:?}", transfer.warnings));
    assert!(
        warning.message.contains("no vertex lies within"),
        "{warning}"
    );
    for v in 0..demo.positions.len() {
        let (x, y): (Vec<_>, Vec<_>) = (
            contact.weights.row(v).collect(),
            transfer.weights.row(v).collect(),
        );
        assert_eq!(x, y, "vertex {v}");
    }
}

#[test]
fn a_settings_file_selects_it() {
    let params: SkinParams = serde_json::from_str(r#"{"loose_pieces": "transfer"}"#).unwrap();
    assert_eq!(params.loose_pieces, LoosePieces::Transfer);
    assert_eq!(SkinParams::default().loose_pieces, LoosePieces::Contact);
    assert!(serde_json::from_str::<SkinParams>(r#"{"loose_pieces": "nearest"}"#).is_err());
}

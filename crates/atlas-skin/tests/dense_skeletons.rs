//! Skeletons denser than their mesh (issue 45): joints closer together than a small part of
//! their depth in the body are merged for cutting ([`atlas_skin::cuts::merged_joints`]),
//! with a warning, and every vertex is still weighted; a chain no denser than the body
//! keeps every joint; at most [`MOST_SOFT_SIDES`] soft joints act at a vertex
//! ([`atlas_skin::weights::crowding`]).

use atlas_skin::cuts::merged_joints::MERGE_DIVISOR;
use atlas_skin::fixtures::shapes::{capsule_chain, uv_sphere};
use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
use atlas_skin::weights::crowding::MOST_SOFT_SIDES;
use atlas_skin::{Skinned, SurfaceMesh};
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use glam::{DVec3, Vec3};

/// A chain of `count` joints `spacing` apart up +Y from the origin.
fn chain(count: usize, spacing: f32) -> Skeleton {
    let names = (0..count).map(|k| format!("j{k}")).collect();
    let parents = (0..count)
        .map(|k| if k == 0 { NO_PARENT } else { k as u32 - 1 })
        .collect();
    let joints: Vec<Vec3> = (0..count).map(|k| Vec3::Y * spacing * k as f32).collect();
    Skeleton::from_positions(names, parents, &joints).expect("a chain")
}

/// A capsule 0.4 long and 0.1 in radius along +Y, rings 1 cm apart.
fn capsule() -> SurfaceMesh {
    capsule_chain(&[DVec3::ZERO, DVec3::Y * 0.4], &[], 0.1, 16, 40).0
}

fn skin_with_defaults(mesh: &SurfaceMesh, skeleton: &Skeleton) -> Skinned {
    let positions: Vec<Vec3> = mesh.positions.iter().map(|p| p.as_vec3()).collect();
    let input = SkinInput {
        positions: &positions,
        triangles: &mesh.triangles,
        skeleton,
        end_joints: &[],
    };
    skin(input, &SkinParams::default(), &mut |_| {}).expect("skinned")
}

/// Every stored vertex weighted, each row summing to 1 (to the f32 of the output).
fn assert_rows_whole(skinned: &Skinned, vertex_count: usize) {
    let weights = &skinned.weights;
    assert_eq!(weights.vertex_count(), vertex_count);
    assert_eq!(skinned.counts.weights.unreachable, 0);
    for v in 0..vertex_count {
        let sum: f32 = weights.row(v).map(|(_, w)| w).sum();
        assert!((sum - 1.0).abs() < 1e-5, "vertex {v} sums to {sum}");
    }
}

/// 401 joints 1 mm apart in a capsule of radius 0.1 (several joints between two rings of
/// vertices): the joints within 1/8 of their depth of the joint kept above them are merged
/// into it, get no boundary and carry no weight, the report says how many, and every vertex
/// is weighted by the kept joints.
#[test]
fn a_chain_denser_than_its_mesh_is_cut_at_fewer_joints_with_a_warning() {
    let mesh = capsule();
    let skeleton = chain(401, 1e-3);
    let skinned = skin_with_defaults(&mesh, &skeleton);
    let merged = &skinned.decomposition.merged_joints;
    let positions = skeleton.bind_positions();
    let mut kept = vec![true; skeleton.len()];
    for m in merged {
        kept[m.joint as usize] = false;
    }
    // Joint 0 is the root; of the 400 others about one in 13 is kept (0.1 / 8 = 12.5 mm).
    assert!(
        (350..=380).contains(&merged.len()),
        "{} merged",
        merged.len()
    );
    for m in merged {
        let (j, into) = (m.joint as usize, m.into as usize);
        assert!(kept[into], "j{j} merged into j{into}, itself merged");
        assert!(
            skeleton.ancestors(j).any(|a| a == into),
            "j{j} into j{into}"
        );
        // Every joint between them is merged: `into` is the nearest kept ancestor.
        assert!(skeleton
            .ancestors(j)
            .take_while(|&a| a != into)
            .all(|a| !kept[a]));
        let distance = f64::from(positions[j].distance(positions[into]));
        assert!((distance - m.distance).abs() < 1e-6);
        assert!(m.distance < m.surface_distance / MERGE_DIVISOR, "{m:?}");
        assert!(skinned.decomposition.joints[j].boundary.is_none(), "j{j}");
    }
    let warning = skinned
        .warnings
        .iter()
        .find(|w| w.message.contains("merged for cutting"))
        .expect("a warning");
    assert!(
        warning
            .message
            .starts_with(&format!("{} joint(s) lie closer", merged.len())),
        "{warning}"
    );
    assert_rows_whole(&skinned, mesh.positions.len());
    for (&j, &w) in skinned.weights.joints.iter().zip(&skinned.weights.weights) {
        assert!(kept[j as usize] || w == 0.0, "merged j{j} carries {w}");
    }
    // The kept joints split the capsule between them: more than a handful move skin.
    let mut carries = vec![false; skeleton.len()];
    for (&j, &w) in skinned.weights.joints.iter().zip(&skinned.weights.weights) {
        carries[j as usize] |= w > 0.0;
    }
    assert!(carries.iter().filter(|&&c| c).count() >= 10);
}

/// 9 joints 5 cm apart in the same capsule: none merged, no warning.
#[test]
fn a_chain_no_denser_than_its_body_keeps_every_joint() {
    let mesh = capsule();
    let skinned = skin_with_defaults(&mesh, &chain(9, 0.05));
    assert!(skinned.decomposition.merged_joints.is_empty());
    assert!(!skinned
        .warnings
        .iter()
        .any(|w| w.message.contains("merged")));
    assert_rows_whole(&skinned, mesh.positions.len());
}

/// A tree of 4 children per joint, `depth` levels below the root at the centre, spread
/// through a ball of radius 0.9: each child a pseudo-random step from its parent, half as
/// long at every level (the shape of `scripts/joint-chains`' "tree of 5461 joints").
fn spread_tree(depth: usize) -> Skeleton {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut unit = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f32 / (1u64 << 53) as f32 * 2.0 - 1.0
    };
    let (mut joints, mut parents) = (vec![Vec3::ZERO], vec![NO_PARENT]);
    let (mut level, mut step) = (vec![0usize], 0.5f32);
    for _ in 0..depth {
        let mut below = Vec::new();
        for &p in &level {
            for _ in 0..4 {
                let q = loop {
                    let d = Vec3::new(unit(), unit(), unit());
                    let q = joints[p] + step * d.normalize_or(Vec3::Y);
                    if d.length() > 0.1 && q.length() < 0.9 {
                        break q;
                    }
                };
                parents.push(p as u32);
                joints.push(q);
                below.push(joints.len() - 1);
            }
        }
        level = below;
        step /= 2.0;
    }
    let names = (0..joints.len()).map(|k| format!("j{k}")).collect();
    Skeleton::from_positions(names, parents, &joints).expect("a tree")
}

/// A tree of 1,365 joints spread through a sphere: every section of every joint encloses
/// other bones, so most are soft, and far more soft sides would act at most vertices than
/// [`MOST_SOFT_SIDES`]: only the deepest act there, the report counts the vertices and
/// warns, and every vertex is weighted.
#[test]
fn a_tree_spread_through_a_blob_lets_a_bounded_number_of_soft_joints_act_at_a_vertex() {
    let mesh = uv_sphere(1.0, 20, 40);
    let skinned = skin_with_defaults(&mesh, &spread_tree(5));
    let crowded = skinned.counts.weights.crowded_vertices;
    assert!(crowded > 0);
    let warning = skinned
        .warnings
        .iter()
        .find(|w| w.message.contains("soft joints: only the"))
        .expect("a warning");
    assert!(
        warning.message.starts_with(&format!("{crowded} vertices"))
            && warning
                .message
                .contains(&format!("only the {MOST_SOFT_SIDES} deepest")),
        "{warning}"
    );
    assert_rows_whole(&skinned, mesh.positions.len());
}

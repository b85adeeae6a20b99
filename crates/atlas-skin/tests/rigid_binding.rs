//! [`Binding::Rigid`] through the whole method on tubes whose answer is known: the same
//! decomposition as the smooth weights, one joint of weight 1 per vertex, and the switch
//! from parent to child on the cut.

use atlas_skin::fixtures::shapes::{bent_cylinder, capsule_chain};
use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
use atlas_skin::weights::rigid::Binding;
use atlas_skin::{BoundaryKind, Skinned, SurfaceMesh};
use atlas_skin_runtime::Skeleton;
use glam::{DVec3, Vec3};

fn skinned(mesh: &SurfaceMesh, skeleton: &Skeleton, binding: Binding) -> Skinned {
    let positions: Vec<Vec3> = mesh.positions.iter().map(|p| p.as_vec3()).collect();
    let params = SkinParams {
        binding,
        ..SkinParams::default()
    };
    let input = SkinInput {
        positions: &positions,
        triangles: &mesh.triangles,
        skeleton,
        end_joints: &[],
    };
    skin(input, &params, &mut |_| {}).expect("skinned")
}

/// Skins `mesh` both ways and checks, for the joint `joint` whose cut is the only
/// boundary: the decomposition and overlaps are the smooth weights', every stored vertex
/// has one joint of weight 1, the vertices on the parent's side of the cut plane (farther
/// than `margin`) go to `joint`'s parent and those on the child's side to `joint`. Returns
/// how many vertices the smooth weights blend.
fn check_switch_on_the_cut(
    mesh: &SurfaceMesh,
    skeleton: &Skeleton,
    joint: u32,
    margin: f64,
) -> usize {
    let smooth = skinned(mesh, skeleton, Binding::Smooth);
    let rigid = skinned(mesh, skeleton, Binding::Rigid);
    assert_eq!(rigid.binding, Binding::Rigid);
    // Boundary has no PartialEq: compared through its Debug text, every field.
    assert_eq!(
        format!("{:?}", rigid.decomposition.boundaries),
        format!("{:?}", smooth.decomposition.boundaries)
    );
    assert_eq!(
        rigid.decomposition.face_region,
        smooth.decomposition.face_region
    );
    assert_eq!(rigid.overlaps.half_widths, smooth.overlaps.half_widths);
    let cut = &rigid.decomposition.boundaries[0];
    assert_eq!(rigid.decomposition.boundaries.len(), 1);
    assert_eq!(cut.joint, joint);
    assert!(matches!(cut.kind, BoundaryKind::Cut { .. }));
    let parent = skeleton.parents[joint as usize];
    let mut sides = [0, 0];
    for (v, p) in mesh.positions.iter().enumerate() {
        let row: Vec<(u32, f32)> = rigid.weights.row(v).collect();
        assert_eq!(row.len(), 1, "vertex {v}: {row:?}");
        assert_eq!(row[0].1, 1.0, "vertex {v}: {row:?}");
        let side = cut.normal.dot(*p - cut.point);
        if side < -margin {
            assert_eq!(row[0].0, parent, "vertex {v} at {p}, {side} from the cut");
            sides[0] += 1;
        } else if side > margin {
            assert_eq!(row[0].0, joint, "vertex {v} at {p}, {side} from the cut");
            sides[1] += 1;
        }
    }
    assert!(sides[0] > 50 && sides[1] > 50, "{sides:?}");
    (0..mesh.positions.len())
        .filter(|&v| smooth.weights.row(v).count() > 1)
        .count()
}

#[test]
fn a_straight_two_bone_capsule_switches_joint_on_its_cut() {
    let (mesh, skeleton) = capsule_chain(
        &[DVec3::ZERO, DVec3::Y * 4.0, DVec3::Y * 8.0],
        &["upper", "lower", "end"],
        0.5,
        16,
        12,
    );
    let blended = check_switch_on_the_cut(&mesh, &skeleton, 1, 1e-6);
    assert!(blended > 32, "the smooth weights blend {blended} vertices");
}

#[test]
fn a_bent_tube_switches_joint_on_its_cut() {
    let (mesh, skeleton) = bent_cylinder(0.5, 4.0, 60.0, 24, 16);
    let blended = check_switch_on_the_cut(&mesh, &skeleton, 1, 1e-6);
    assert!(blended > 24, "the smooth weights blend {blended} vertices");
}

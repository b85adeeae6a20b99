//! The whole method after welding ([`atlas_skin::pipeline::skin`]) on a bent tube: stages in
//! order, weights for every stored vertex, a smooth transition at the joint, settings
//! checked before any work.

use atlas_skin::pipeline::{skin, SkinError, SkinParams, Stage};
use atlas_skin::shapes::bent_cylinder;
use atlas_skin::weights::WeightsError;
use atlas_skin::weld::DEFAULT_WELD_TOLERANCE;
use atlas_skin::{weld, Topology};
use glam::Vec3;

#[test]
fn a_bent_tube_is_skinned_with_a_smooth_transition_at_its_joint() {
    let (mesh, skeleton) = bent_cylinder(0.5, 4.0, 60.0, 24, 16);
    let positions: Vec<Vec3> = mesh.positions.iter().map(|p| p.as_vec3()).collect();
    let welded = weld(&positions, &mesh.triangles, DEFAULT_WELD_TOLERANCE);
    let topology = Topology::new(&welded.mesh);
    let mut stages = Vec::new();
    let skinned = skin(
        &welded,
        &topology,
        &positions,
        &skeleton,
        &SkinParams::default(),
        &mut |stage| stages.push(stage),
    )
    .expect("skinned");
    assert_eq!(stages, [Stage::Decompose, Stage::Distances, Stage::Weights]);
    assert_eq!(skinned.weights.vertex_count(), positions.len());
    assert_eq!(skinned.counts.weights.unreachable, 0);
    assert!(skinned.weights.max_influences() <= 4);
    let (mut blended, mut far_from_joint) = (0, 0);
    for (v, p) in positions.iter().enumerate() {
        let row: Vec<(u32, f32)> = skinned.weights.row(v).collect();
        let sum: f32 = row.iter().map(|&(_, w)| w).sum();
        assert!((sum - 1.0).abs() < 1e-6 && row.iter().all(|&(_, w)| w > 0.0));
        blended += usize::from(row.len() > 1);
        // Far down the first segment only the root moves the tube.
        if p.y < 1.0 {
            far_from_joint += 1;
            assert_eq!(row, vec![(0, 1.0)], "vertex {v} at {p}");
        }
    }
    assert!(blended > 24, "{blended} blended vertices");
    assert!(far_from_joint > 24);
}

#[test]
fn bad_settings_are_refused_before_any_work() {
    let (mesh, skeleton) = bent_cylinder(0.5, 4.0, 60.0, 12, 4);
    let positions: Vec<Vec3> = mesh.positions.iter().map(|p| p.as_vec3()).collect();
    let welded = weld(&positions, &mesh.triangles, DEFAULT_WELD_TOLERANCE);
    let topology = Topology::new(&welded.mesh);
    let no_influences = SkinParams {
        max_influences: 0,
        ..SkinParams::default()
    };
    let mut unknown_joint = SkinParams::default();
    unknown_joint
        .weights
        .overlap
        .per_joint
        .insert("elbow".into(), 0.5);
    let mut negative = SkinParams::default();
    negative.weights.overlap.factor = -0.5;
    for (params, expected) in [
        (no_influences, WeightsError::NoInfluences),
        (
            unknown_joint,
            WeightsError::UnknownJoint {
                name: "elbow".into(),
            },
        ),
        (
            negative,
            WeightsError::BadOverlapFactor {
                joint: None,
                value: -0.5,
            },
        ),
    ] {
        let mut stages = Vec::new();
        let result = skin(
            &welded,
            &topology,
            &positions,
            &skeleton,
            &params,
            &mut |s| stages.push(s),
        );
        match result {
            Err(SkinError::Weights(error)) => assert_eq!(error, expected),
            other => panic!("expected {expected:?}, got {:?}", other.map(|_| ())),
        }
        assert!(stages.is_empty());
    }
}

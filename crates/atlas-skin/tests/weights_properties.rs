//! The invariants of the weights over random shapes: for every stored vertex, weights
//! non-negative, summing to 1, at most `max_influences` of them, on joints of the skeleton;
//! the same before pruning on every surface vertex. The shapes are bent tubes of random
//! joint counts and bends, some with a loose sphere beside them (a piece no region with
//! joints reaches) and with seams (stored vertices that weld into one).

use atlas_skin::fixtures::shapes::{capsule_chain, icosphere};
use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
use atlas_skin::weights::blend::Blend;
use glam::{DVec3, Vec3};
use proptest::prelude::*;

/// A zig-zag polyline in 3D: a first segment up the Y axis, then one turn per bend.
fn polyline(bends: &[(f64, f64)]) -> Vec<DVec3> {
    let mut points = vec![DVec3::ZERO, DVec3::Y * 2.0];
    let (mut heading, mut pitch) = (0.0f64, 0.0f64);
    for &(turn, lift) in bends {
        heading += turn;
        pitch += lift;
        let last = *points.last().expect("two points");
        let direction = DVec3::new(
            heading.sin() * pitch.cos(),
            heading.cos() * pitch.cos(),
            pitch.sin(),
        );
        points.push(last + 2.0 * direction);
    }
    points
}

proptest! {
    // No failure file: a failing case is printed, and the seeds are random in every run.
    #![proptest_config(ProptestConfig {
        cases: 24,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn weights_are_a_pruned_partition_of_unity_on_any_tube(
        bends in proptest::collection::vec((-1.7f64..1.7, -0.6f64..0.6), 1..5),
        radius in 0.2f64..0.6,
        sides in 6usize..16,
        max_influences in 1usize..=4,
        factor in 0.1f64..1.2,
        paper_blend in any::<bool>(),
        loose_piece in any::<bool>(),
        seams in any::<bool>(),
    ) {
        let points = polyline(&bends);
        let (tube, skeleton) = capsule_chain(&points, &[], radius, sides, 4);
        let mut positions: Vec<Vec3> = tube.positions.iter().map(|p| p.as_vec3()).collect();
        let mut triangles = tube.triangles.clone();
        if loose_piece {
            let sphere = icosphere(radius, 1);
            let offset = points[1] + DVec3::X * 4.0 * radius;
            let base = positions.len() as u32;
            positions.extend(sphere.positions.iter().map(|p| (*p + offset).as_vec3()));
            triangles.extend(sphere.triangles.iter().map(|t| t.map(|v| v + base)));
        }
        if seams {
            // Every other triangle refers to a copy of its first corner, as a UV seam does.
            for t in triangles.iter_mut().step_by(2) {
                positions.push(positions[t[0] as usize]);
                t[0] = positions.len() as u32 - 1;
            }
        }
        let mut params = SkinParams {
            max_influences,
            ..SkinParams::default()
        };
        params.overlap.factor = factor;
        if paper_blend {
            params.blend = Blend::Paper;
        }
        let input = SkinInput {
            positions: &positions,
            triangles: &triangles,
            skeleton: &skeleton,
            end_joints: &[],
        };
        let skinned = skin(input, &params, &mut |_| {}).expect("a tube skins");

        prop_assert_eq!(skinned.weights.vertex_count(), positions.len());
        for v in 0..positions.len() {
            let row: Vec<(u32, f32)> = skinned.weights.row(v).collect();
            prop_assert!(!row.is_empty() && row.len() <= max_influences, "vertex {}: {:?}", v, row);
            prop_assert!(row.iter().all(|&(j, w)| w >= 0.0 && (j as usize) < skeleton.len()));
            let sum: f32 = row.iter().map(|&(_, w)| w).sum();
            prop_assert!((sum - 1.0).abs() < 1e-5, "vertex {}: sum {}", v, sum);
        }
        let surface = &skinned.surface_weights;
        for v in 0..surface.vertex_count() {
            let row: Vec<(u32, f64)> = surface.row(v).collect();
            prop_assert!(row.iter().all(|&(_, w)| w > 0.0));
            let sum: f64 = row.iter().map(|&(_, w)| w).sum();
            prop_assert!((sum - 1.0).abs() < 1e-9, "surface vertex {}: sum {}", v, sum);
            let mut joints: Vec<u32> = row.iter().map(|&(j, _)| j).collect();
            joints.sort_unstable();
            joints.dedup();
            prop_assert_eq!(joints.len(), row.len(), "joints repeat at surface vertex {}", v);
        }
    }
}

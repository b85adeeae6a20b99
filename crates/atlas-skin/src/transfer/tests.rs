//! Transfer on shapes with known answers: a skirt around two legs (the tear that nearest
//! point copy makes and inpainting does not), constant weights carried exactly, a floating
//! piece bound where it comes nearest, the sparse solve against a dense one, bad input.

use super::inpaint::{dense_reference, System, FIXED};
use super::*;
use crate::fixtures::shapes::{capsule_chain, quad_grid, uv_sphere};
use glam::DVec3;
use std::f64::consts::TAU;

/// Two legs along +Y at x = ±0.15, radius 0.1, height 1: the left one (x < 0) weighted 1
/// on joint 0, the right one 1 on joint 1.
fn legs() -> (Vec<Vec3>, Vec<[u32; 3]>, VertexWeights) {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut rows = Vec::new();
    for (joint, x) in [(0u32, -0.15), (1, 0.15)] {
        let (leg, _) = capsule_chain(
            &[DVec3::new(x, 0.0, 0.0), DVec3::new(x, 1.0, 0.0)],
            &["a", "b"],
            0.1,
            32,
            20,
        );
        let first = positions.len() as u32;
        positions.extend(leg.positions.iter().map(|p| p.as_vec3()));
        triangles.extend(leg.triangles.iter().map(|t| t.map(|v| v + first)));
        rows.extend(leg.positions.iter().map(|_| vec![(joint, 1.0)]));
    }
    (positions, triangles, VertexWeights::from_rows(rows))
}

/// An open tube around +Y with an elliptic section of half-axes `rx`, `rz`, from `y0` to
/// `y1`: `sides` vertices per ring plus a seam copy of the first (stored twice, as a file
/// with UV seams stores it), `rings` + 1 rings; normals outward.
fn tube(rx: f64, rz: f64, y0: f64, y1: f64, sides: u32, rings: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let per_ring = sides + 1;
    let mut positions = Vec::new();
    for i in 0..=rings {
        let y = y0 + (y1 - y0) * f64::from(i) / f64::from(rings);
        for k in 0..per_ring {
            let a = TAU * f64::from(k % sides) / f64::from(sides);
            positions.push(Vec3::new(
                (rx * a.cos()) as f32,
                y as f32,
                (rz * a.sin()) as f32,
            ));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..rings {
        for k in 0..sides {
            let (a, b) = (i * per_ring + k, i * per_ring + k + 1);
            let (c, d) = (a + per_ring, b + per_ring);
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    (positions, triangles)
}

fn source_of(
    (positions, triangles, weights): &(Vec<Vec3>, Vec<[u32; 3]>, VertexWeights),
) -> TransferSource {
    TransferSource::new(positions, triangles, weights, 2).unwrap()
}

/// Weight of joint 0 in stored row `v`.
fn joint0(weights: &VertexWeights, v: usize) -> f64 {
    weights
        .row(v)
        .find(|&(j, _)| j == 0)
        .map_or(0.0, |(_, w)| f64::from(w))
}

/// The largest difference of joint 0's weight across an edge of the target.
fn largest_jump(weights: &VertexWeights, triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (joint0(weights, a as usize) - joint0(weights, b as usize)).abs())
        .fold(0.0, f64::max)
}

/// The skirt's sides touch the legs and take their weights; its front and back, between
/// the legs, are inpainted: a smooth passage from one leg to the other, about half and half in
/// the middle (exactly, but for the triangulation's diagonals all running one way). Copying the nearest point's weights instead (every vertex
/// matched: a huge distance and angle) jumps from one leg to the other across one edge.
#[test]
fn a_skirt_between_the_legs_does_not_tear() {
    let source = source_of(&legs());
    let (positions, triangles) = tube(0.27, 0.12, 0.4, 0.9, 48, 10);
    let params = TransferParams::default();
    let result = transfer_weights(&source, &positions, &triangles, &params).unwrap();
    assert!(
        result.counts.matched > 0 && result.counts.inpainted > 0,
        "{:?}",
        result.counts
    );
    assert_eq!(result.pieces.len(), 1);
    let front_middle = 12; // k = 12 of 48: a = 90°, x = 0, z = rz, on the first ring.
    assert!(positions[front_middle].x.abs() < 1e-6);
    let middle = joint0(&result.weights, front_middle);
    assert!((middle - 0.5).abs() < 0.1, "{middle}");
    let side = 0; // a = 0: x = +rx, on the right leg.
    assert_eq!(result.vertex_sources[side], VertexSource::Matched);
    assert!(joint0(&result.weights, side) < 1e-6);
    let smooth_jump = largest_jump(&result.weights, &triangles);
    assert!(smooth_jump < 0.2, "{smooth_jump}");

    let copy = TransferParams {
        distance: 10.0,
        angle_degrees: 90.0,
        smooth_iterations: 0,
        ..TransferParams::default()
    };
    let copied = transfer_weights(&source, &positions, &triangles, &copy).unwrap();
    assert_eq!(copied.counts.inpainted, 0);
    assert!(largest_jump(&copied.weights, &triangles) > 0.99);
}

/// The same skirt and legs in centimetres get the same weights as in metres: the
/// inpainting energy is weighed at the source's size, not at the file's unit (with the
/// paper's Q = −L + L M⁻¹ L the skirt's front in centimetres was inpainted almost
/// harmonically, in metres almost biharmonically).
#[test]
fn weights_do_not_depend_on_the_units() {
    let params = TransferParams::default();
    let (legs_m, skirt_m) = (legs(), tube(0.27, 0.12, 0.4, 0.9, 48, 10));
    let in_metres = transfer_weights(&source_of(&legs_m), &skirt_m.0, &skirt_m.1, &params).unwrap();
    let to_cm = |positions: &[Vec3]| positions.iter().map(|&p| p * 100.0).collect::<Vec<_>>();
    let legs_cm = (to_cm(&legs_m.0), legs_m.1.clone(), legs_m.2.clone());
    let in_cm = transfer_weights(
        &source_of(&legs_cm),
        &to_cm(&skirt_m.0),
        &skirt_m.1,
        &params,
    )
    .unwrap();
    assert!(in_metres.counts.inpainted > 100, "{:?}", in_metres.counts);
    assert_eq!(in_metres.vertex_sources, in_cm.vertex_sources);
    let largest = (0..skirt_m.0.len())
        .map(|v| (joint0(&in_metres.weights, v) - joint0(&in_cm.weights, v)).abs())
        .fold(0.0, f64::max);
    assert!(largest < 1e-4, "{largest}");
}

/// Every row sums to 1; the seam copies of a vertex get the same row.
#[test]
fn rows_sum_to_one_and_seam_copies_agree() {
    let source = source_of(&legs());
    let (positions, triangles) = tube(0.27, 0.12, 0.4, 0.9, 48, 10);
    let result =
        transfer_weights(&source, &positions, &triangles, &TransferParams::default()).unwrap();
    for v in 0..positions.len() {
        let total: f32 = result.weights.row(v).map(|(_, w)| w).sum();
        assert!((total - 1.0).abs() < 1e-5, "vertex {v}: {total}");
    }
    for ring in 0..=10 {
        let (first, copy) = (ring * 49, ring * 49 + 48);
        assert_eq!(
            result.weights.row(first).collect::<Vec<_>>(),
            result.weights.row(copy).collect::<Vec<_>>()
        );
    }
    assert_eq!(result.counts.welded_vertices, 11 * 48);
}

/// The reference implementation's example: constant weights (0.3, 0.7) on a sphere, a
/// plane above it only partly matched; the inpainted vertices get exactly the constant
/// (Q annihilates constants), smoothed or not. The plane wound facing down matches only
/// with flipped normals accepted; without, it matches nowhere and is bound whole.
#[test]
fn constant_weights_are_carried_exactly() {
    let sphere = uv_sphere(1.0, 24, 48);
    let positions: Vec<Vec3> = sphere.positions.iter().map(|p| p.as_vec3()).collect();
    let weights = VertexWeights::from_rows(positions.iter().map(|_| vec![(0, 0.3), (1, 0.7)]));
    let source = TransferSource::new(&positions, &sphere.triangles, &weights, 2).unwrap();
    // A 3 × 3 plane at z = 1.02, 31 × 31 vertices.
    let n = 31u32;
    let plane: Vec<Vec3> = (0..n * n)
        .map(|v| {
            let (x, y) = (v % n, v / n);
            Vec3::new(
                -1.5 + 3.0 * x as f32 / (n - 1) as f32,
                -1.5 + 3.0 * y as f32 / (n - 1) as f32,
                1.02,
            )
        })
        .collect();
    let mut triangles = Vec::new();
    quad_grid(
        (n - 1) as usize,
        (n - 1) as usize,
        |y, x| y as u32 * n + x as u32,
        &mut triangles,
    );
    // quad_grid winds the plane facing −Z: turned to face +Z, away from the sphere.
    let facing_down = triangles.clone();
    for t in &mut triangles {
        t.swap(1, 2);
    }
    let down = transfer_weights(&source, &plane, &facing_down, &TransferParams::default());
    assert_eq!(down.unwrap().counts.nearest, plane.len());
    let flipped = TransferParams {
        flipped_normals: true,
        ..TransferParams::default()
    };
    let down = transfer_weights(&source, &plane, &facing_down, &flipped).unwrap();
    let result = transfer_weights(&source, &plane, &triangles, &TransferParams::default()).unwrap();
    assert_eq!(down.counts, result.counts);
    assert!(result.counts.matched > 0 && result.counts.inpainted > result.counts.matched);
    for v in 0..plane.len() {
        let row: Vec<(u32, f32)> = result.weights.row(v).collect();
        assert_eq!(row.len(), 2, "vertex {v}: {row:?}");
        assert_eq!(row[0].0, 1);
        assert!(
            (row[0].1 - 0.7).abs() < 1e-5 && (row[1].1 - 0.3).abs() < 1e-5,
            "{row:?}"
        );
    }
}

/// A piece that matches nowhere (a small plate in front of the left leg, beyond the
/// matching distance) is bound whole to the leg where it comes nearest, and said so.
#[test]
fn a_piece_without_a_match_is_bound_where_it_comes_nearest() {
    let source = source_of(&legs());
    let (mut positions, mut triangles) = tube(0.27, 0.12, 0.4, 0.9, 48, 10);
    let first = positions.len() as u32;
    for p in [
        [-0.2, 0.5, 0.4],
        [-0.1, 0.5, 0.4],
        [-0.1, 0.6, 0.4],
        [-0.2, 0.6, 0.4],
    ] {
        positions.push(Vec3::from_array(p));
    }
    triangles.push([first, first + 1, first + 2]);
    triangles.push([first, first + 2, first + 3]);
    let result =
        transfer_weights(&source, &positions, &triangles, &TransferParams::default()).unwrap();
    assert_eq!(result.pieces.len(), 2);
    let plate = &result.pieces[1];
    assert!(plate.bound_to_nearest && plate.matched == 0 && plate.vertices == 4);
    assert!(!result.pieces[0].bound_to_nearest);
    for v in first as usize..positions.len() {
        assert_eq!(result.vertex_sources[v], VertexSource::Nearest);
        assert_eq!(result.weights.row(v).collect::<Vec<_>>(), [(0, 1.0)]);
    }
    assert_eq!(result.counts.nearest, 4);
}

/// The sparse Cholesky solve equals a dense solve of the same system.
#[test]
fn the_sparse_solve_equals_the_dense_reference() {
    let (positions, triangles) = tube(0.27, 0.12, 0.4, 0.9, 24, 8);
    let welded = weld(&positions, &triangles, DEFAULT_WELD_TOLERANCE);
    let ops = Operators::new(&welded.mesh, &Topology::new(&welded.mesh));
    let n = welded.mesh.vertex_count();
    // Fixed: the bottom and top rings with three joints varying around; unknown: the rest.
    let fixed_rows: Vec<Vec<(u32, f64)>> = (0..n)
        .map(|v| {
            let p = welded.mesh.positions[v];
            let a = p.z.atan2(p.x);
            let s = 0.5 + 0.5 * a.sin();
            if p.y < 0.41 {
                vec![(0, s), (1, 1.0 - s)]
            } else if p.y > 0.89 {
                vec![(1, 0.25), (2, 0.75)]
            } else {
                Vec::new()
            }
        })
        .collect();
    let unknown: Vec<u32> = (0..n as u32)
        .filter(|&v| fixed_rows[v as usize].is_empty())
        .collect();
    let mut slot = vec![FIXED; n];
    for (k, &v) in unknown.iter().enumerate() {
        slot[v as usize] = k as u32;
    }
    let system = System {
        operators: &ops,
        unknown: &unknown,
        slot: &slot,
        columns: 3,
        length: 1.7,
    };
    let fixed = |j: usize| fixed_rows[j].as_slice();
    let sparse = system.solve(&fixed).unwrap();
    let dense = dense_reference(&system, &fixed);
    assert_eq!(sparse.len(), unknown.len() * 3);
    let largest = sparse
        .iter()
        .zip(&dense)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(largest < 1e-9, "{largest}");
    // Rows of the solution sum to 1 (constants are in Q's kernel).
    for row in sparse.chunks(3) {
        assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-8);
    }
}

/// Bad input: clear errors, no result.
#[test]
fn bad_input_is_refused() {
    let source = source_of(&legs());
    let (positions, triangles) = tube(0.27, 0.12, 0.4, 0.9, 12, 3);
    let far: Vec<Vec3> = positions
        .iter()
        .map(|p| *p + Vec3::new(0.0, 0.0, 3.0))
        .collect();
    assert!(matches!(
        transfer_weights(&source, &far, &triangles, &TransferParams::default()),
        Err(TransferError::NotNear { .. })
    ));
    let centimetres: Vec<Vec3> = positions.iter().map(|p| *p * 100.0).collect();
    assert!(matches!(
        transfer_weights(
            &source,
            &centimetres,
            &triangles,
            &TransferParams::default()
        ),
        Err(TransferError::MismatchedSize { .. })
    ));
    assert_eq!(
        transfer_weights(&source, &positions, &[], &TransferParams::default()).unwrap_err(),
        TransferError::EmptyTarget
    );
    assert!(matches!(
        transfer_weights(
            &source,
            &positions[..3],
            &triangles,
            &TransferParams::default()
        ),
        Err(TransferError::TriangleVertexOutOfRange { .. })
    ));
    for params in [
        TransferParams {
            distance: 0.0,
            ..TransferParams::default()
        },
        TransferParams {
            angle_degrees: 120.0,
            ..TransferParams::default()
        },
        TransferParams {
            smooth_alpha: 1.5,
            ..TransferParams::default()
        },
    ] {
        assert!(matches!(
            transfer_weights(&source, &positions, &triangles, &params),
            Err(TransferError::Settings(_))
        ));
    }
}

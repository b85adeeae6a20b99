//! Known-answer tests of [`evaluate`] on a two-bone tube.

use super::*;
use approx::assert_relative_eq;
use atlas_skin::mesh::weld::{weld, DEFAULT_WELD_TOLERANCE};
use atlas_skin_runtime::NO_PARENT;

const RINGS: usize = 5;
const SIDES: usize = 6;

/// An open tube along X from 0 to 4: `RINGS` rings of `SIDES` vertices, radius 1.
fn tube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let positions = (0..RINGS)
        .flat_map(|i| {
            (0..SIDES).map(move |s| {
                let a = std::f32::consts::TAU * s as f32 / SIDES as f32;
                Vec3::new(i as f32, a.cos(), a.sin())
            })
        })
        .collect();
    let index = |i: usize, s: usize| (i * SIDES + s % SIDES) as u32;
    let triangles = (0..RINGS - 1)
        .flat_map(|i| {
            (0..SIDES).flat_map(move |s| {
                [
                    [index(i, s), index(i + 1, s), index(i + 1, s + 1)],
                    [index(i, s), index(i + 1, s + 1), index(i, s + 1)],
                ]
            })
        })
        .collect();
    (positions, triangles)
}

fn skeleton(names: [&str; 2]) -> Skeleton {
    Skeleton::from_positions(
        names.map(String::from).to_vec(),
        vec![NO_PARENT, 0],
        &[Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0)],
    )
    .unwrap()
}

/// Ring i: shoulder 1 − i/4, elbow i/4 (ring 0 all shoulder, ring 4 all elbow), times
/// `scale` (the reference may not sum to 1).
fn ramp(positions: &[Vec3], scale: f32) -> VertexWeights {
    VertexWeights::from_rows(positions.iter().map(|p| {
        let t = p.x / 4.0;
        [(0u32, (1.0 - t) * scale), (1, t * scale)]
            .into_iter()
            .filter(|&(_, w)| w > 0.0)
    }))
}

struct Fixture {
    positions: Vec<Vec3>,
    skeleton: Skeleton,
    weights: VertexWeights,
    welded: Welded,
    topology: Topology,
}

fn fixture(scale: f32) -> Fixture {
    let (positions, triangles) = tube();
    let welded = weld(&positions, &triangles, DEFAULT_WELD_TOLERANCE);
    let topology = Topology::new(&welded.mesh);
    Fixture {
        weights: ramp(&positions, scale),
        skeleton: skeleton(["shoulder", "elbow"]),
        positions,
        welded,
        topology,
    }
}

fn run(reference: &Fixture, candidate: Weighted) -> Result<Evaluation, EvalError> {
    let input = EvalInput {
        reference: Weighted {
            positions: &reference.positions,
            skeleton: &reference.skeleton,
            weights: &reference.weights,
        },
        surface: &reference.welded,
        topology: &reference.topology,
        candidate,
        animation: None,
    };
    evaluate(&input, &EvalOptions::default())
}

fn assert_all_zero(e: &Evaluation) {
    assert_eq!(e.matched, RINGS * SIDES);
    assert!(e.weights_l1.max < 1e-6, "{:?}", e.weights_l1);
    assert_eq!(e.weights_l1.dominant_agreement, 1.0);
    assert!(e.deform_random.max < 1e-6, "{:?}", e.deform_random);
    assert!(e.deform_random_dqs.max < 1e-6, "{:?}", e.deform_random_dqs);
    assert_eq!(e.bleeding.fraction, 0.0);
}

#[test]
fn identical_candidate_gives_zeros() {
    let f = fixture(1.0);
    let e = run(
        &f,
        Weighted {
            positions: &f.positions,
            skeleton: &f.skeleton,
            weights: &f.weights,
        },
    )
    .unwrap();
    assert_all_zero(&e);
    assert_eq!((e.vertices, e.joints), (RINGS * SIDES, 2));
    assert_eq!(e.validity.sums_off_one, 0);
}

#[test]
fn reference_rows_are_renormalised() {
    let reference = fixture(0.5);
    let candidate = fixture(1.0);
    let e = run(
        &reference,
        Weighted {
            positions: &candidate.positions,
            skeleton: &candidate.skeleton,
            weights: &candidate.weights,
        },
    )
    .unwrap();
    assert_all_zero(&e);
}

#[test]
fn permuted_and_split_candidate_still_matches() {
    let f = fixture(1.0);
    // Reverse the vertex order and append a seam duplicate of every tenth vertex.
    let mut order: Vec<usize> = (0..f.positions.len()).rev().collect();
    order.extend((0..f.positions.len()).step_by(10));
    let positions: Vec<Vec3> = order.iter().map(|&v| f.positions[v]).collect();
    let weights = VertexWeights::from_rows(order.iter().map(|&v| f.weights.row(v)));
    // Joints in another order too.
    let skeleton = Skeleton::from_positions(
        vec!["elbow".into(), "shoulder".into()],
        vec![1, NO_PARENT],
        &[Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO],
    )
    .unwrap();
    let weights = VertexWeights::from_rows(
        (0..weights.vertex_count()).map(|v| weights.row(v).map(|(j, w)| (1 - j, w))),
    );
    let e = run(
        &f,
        Weighted {
            positions: &positions,
            skeleton: &skeleton,
            weights: &weights,
        },
    )
    .unwrap();
    assert_all_zero(&e);
    assert_eq!(e.candidate_vertices, RINGS * SIDES + 3);
}

#[test]
fn swapped_joints_give_the_l1_by_hand() {
    let f = fixture(1.0);
    // Same weights, joint names exchanged: vertex weights (1 − t, t) become (t, 1 − t),
    // d = 2·|1 − 2t| with t = i/4 on ring i: 2, 1, 0, 1, 2 (mean 6/5); the heaviest joint
    // agrees only on the tied middle ring.
    let swapped = skeleton(["elbow", "shoulder"]);
    let e = run(
        &f,
        Weighted {
            positions: &f.positions,
            skeleton: &swapped,
            weights: &f.weights,
        },
    )
    .unwrap();
    assert_relative_eq!(e.weights_l1.mean, 1.2, epsilon = 1e-6);
    assert_relative_eq!(e.weights_l1.p95, 2.0, epsilon = 1e-6);
    assert_relative_eq!(e.weights_l1.max, 2.0, epsilon = 1e-6);
    assert_relative_eq!(e.weights_l1.dominant_agreement, 0.2, epsilon = 1e-12);
    assert!(e.deform_random.mean > 1e-3);
}

#[test]
fn weight_moved_to_the_far_end_bleeds() {
    let f = fixture(1.0);
    // The last ring (x = 4) is all elbow in the reference; the shoulder's reference
    // weight ends at ring 3, 1 away along the surface, beyond 5% of the diagonal
    // (√(16 + 4 + 4) · 0.05 ≈ 0.24). Moving the last ring to the shoulder makes its
    // weight, 1/5 of the total, bleed.
    let weights = VertexWeights::from_rows(f.positions.iter().enumerate().map(|(v, p)| {
        if p.x == 4.0 {
            vec![(0, 1.0)]
        } else {
            f.weights.row(v).collect()
        }
    }));
    let e = run(
        &f,
        Weighted {
            positions: &f.positions,
            skeleton: &f.skeleton,
            weights: &weights,
        },
    )
    .unwrap();
    assert_relative_eq!(e.bleeding.fraction, 0.2, epsilon = 1e-9);
}

#[test]
fn inputs_that_cannot_be_compared_are_errors() {
    let f = fixture(1.0);
    // "tail" matches no name, and lies far from the free "elbow".
    let other = Skeleton::from_positions(
        vec!["shoulder".into(), "tail".into()],
        vec![NO_PARENT, 0],
        &[Vec3::ZERO, Vec3::new(2.0, 5.0, 0.0)],
    )
    .unwrap();
    // Moved away: fitted back (a translation), every vertex paired.
    let far: Vec<Vec3> = f.positions.iter().map(|p| *p + Vec3::splat(10.0)).collect();
    let moved = run(
        &f,
        Weighted {
            positions: &far,
            skeleton: &f.skeleton,
            weights: &f.weights,
        },
    )
    .unwrap();
    let fit = moved.fit.expect("a fit");
    assert_relative_eq!(fit.translation[0], -10.0, epsilon = 1e-5);
    assert_eq!((moved.matched, moved.weights_l1.max), (30, 0.0));
    // Another shape: no fit pairs a vertex.
    let other_shape: Vec<Vec3> = f
        .positions
        .iter()
        .map(|p| Vec3::new(p.y, 3.0 * p.x, -p.z) + Vec3::splat(10.0))
        .collect();
    let short = VertexWeights::from_rows([[(0u32, 1.0f32)]]);
    let out_of_range = VertexWeights::from_rows(f.positions.iter().map(|_| [(2u32, 1.0f32)]));
    type Expected = fn(&EvalError) -> bool;
    let cases: [(Weighted, Expected); 4] = [
        (
            Weighted {
                positions: &f.positions,
                skeleton: &other,
                weights: &f.weights,
            },
            |e| matches!(e, EvalError::UnknownJoint { joint: 1, .. }),
        ),
        (
            Weighted {
                positions: &other_shape,
                skeleton: &f.skeleton,
                weights: &f.weights,
            },
            |e| matches!(e, EvalError::NoVertexMatched { .. }),
        ),
        (
            Weighted {
                positions: &f.positions,
                skeleton: &f.skeleton,
                weights: &short,
            },
            |e| {
                matches!(
                    e,
                    EvalError::RowCount {
                        which: "candidate",
                        rows: 1,
                        ..
                    }
                )
            },
        ),
        (
            Weighted {
                positions: &f.positions,
                skeleton: &f.skeleton,
                weights: &out_of_range,
            },
            |e| matches!(e, EvalError::CandidateJointOutOfRange { joint: 2, .. }),
        ),
    ];
    for (candidate, expected) in cases {
        let error = run(&f, candidate).unwrap_err();
        assert!(expected(&error), "unexpected {error:?}");
    }
}

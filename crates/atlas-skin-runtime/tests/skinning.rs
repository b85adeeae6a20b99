//! The fast skinning job against the scalar reference, and the properties the issue
//! names: identity pose = rest mesh, one rigid joint = that transform, the candy wrapper.

mod skinning_support;

use atlas_skin_runtime::reference::{
    dual_quaternion_positions, dual_quaternion_vectors, linear_blend_positions,
    linear_blend_vectors,
};
use atlas_skin_runtime::{
    CompactSkin, InstructionSet, RuntimeError, SkinningJob, SkinningMethod, SkinningPalette,
    Threading, VertexWeights, WeightFormat,
};
use glam::{Mat4, Quat, Vec3, Vec4};
use proptest::prelude::*;
use skinning_support::{diagonal, max_distance};

/// Output streams of one run (tangents stay zero when the run has none: the loops
/// specialise on the streams present, so tests run both ways).
struct Posed {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    tangents: Vec<Vec4>,
}

/// Every instruction set this CPU runs, the portable one first.
fn supported_sets() -> Vec<InstructionSet> {
    InstructionSet::ALL
        .into_iter()
        .filter(|s| s.is_supported())
        .collect()
}

/// [`run_job_aligned`] with the palette's hemispheres aligned to the skin.
#[allow(clippy::too_many_arguments)]
fn run_job(
    set: InstructionSet,
    skin: &CompactSkin,
    matrices: &[Mat4],
    method: SkinningMethod,
    threading: Threading,
    rest_positions: &[Vec3],
    rest_normals: &[Vec3],
    with_tangents: bool,
) -> Result<Posed, RuntimeError> {
    let streams = (rest_positions, rest_normals, with_tangents);
    run_job_aligned(set, skin, matrices, (method, true), threading, streams)
}

/// One job; `aligned`: the dual quaternions' hemispheres aligned to the skin
/// (`SkinningPalette::align_hemispheres`), which lets the vector loops leave out the sign
/// fix when every pair then agrees.
fn run_job_aligned(
    set: InstructionSet,
    skin: &CompactSkin,
    matrices: &[Mat4],
    (method, aligned): (SkinningMethod, bool),
    threading: Threading,
    (rest_positions, rest_normals, with_tangents): (&[Vec3], &[Vec3], bool),
) -> Result<Posed, RuntimeError> {
    let mut palette = SkinningPalette::new(matrices.len());
    palette.update(matrices, method)?;
    if aligned {
        palette.align_hemispheres(skin);
    }
    let rest_tangents: Vec<Vec4> = rest_normals
        .iter()
        .map(|n| n.any_orthonormal_vector().extend(-1.0))
        .collect();
    let n = rest_positions.len();
    let mut posed = Posed {
        positions: vec![Vec3::ZERO; n],
        normals: vec![Vec3::ZERO; n],
        tangents: vec![Vec4::ZERO; n],
    };
    SkinningJob {
        skin,
        palette: &palette,
        threading,
        rest_positions,
        rest_normals: Some(rest_normals),
        rest_tangents: with_tangents.then_some(rest_tangents.as_slice()),
        out_positions: &mut posed.positions,
        out_normals: Some(&mut posed.normals),
        out_tangents: with_tangents.then_some(posed.tangents.as_mut_slice()),
    }
    .run_with(set)?;
    Ok(posed)
}

/// A random rigid transform: rotation from four floats, translation from three.
fn rigid(r: [f32; 4], t: [f32; 3]) -> Mat4 {
    let q = Vec4::from(r);
    let q = if q.length() < 1e-3 {
        Quat::IDENTITY
    } else {
        Quat::from_vec4(q).normalize()
    };
    Mat4::from_rotation_translation(q, Vec3::from(t))
}

fn weights_strategy(vertices: usize, joints: u32) -> impl Strategy<Value = VertexWeights> {
    prop::collection::vec(
        prop::collection::vec((0..joints, 0.01f32..1.0), 1..7),
        vertices,
    )
    .prop_map(VertexWeights::from_rows)
}

/// Every way a skin stores its weights.
fn formats() -> impl Strategy<Value = WeightFormat> {
    prop::sample::select(vec![
        WeightFormat::Float32,
        WeightFormat::Unorm16,
        WeightFormat::Unorm8,
    ])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Every specialisation (K = 1…4 and N, sequential and parallel, every instruction set
    /// this CPU runs) matches the scalar reference within 1e-5 of the bounding-box
    /// diagonal.
    #[test]
    fn fast_paths_match_the_reference(
        rows in weights_strategy(300, 6),
        rotations in prop::collection::vec(prop::array::uniform4(-1.0f32..1.0), 6),
        translations in prop::collection::vec(prop::array::uniform3(-2.0f32..2.0), 6),
        points in prop::collection::vec(prop::array::uniform3(-1.0f32..1.0), 300),
        max_influences in 1usize..7,
        parallel in any::<bool>(),
        format in formats(),
    ) {
        let matrices: Vec<Mat4> = rotations.iter().zip(&translations).map(|(r, t)| rigid(*r, *t)).collect();
        let rest: Vec<Vec3> = points.iter().map(|p| Vec3::from(*p)).collect();
        let normals: Vec<Vec3> = rest.iter().map(|p| p.normalize_or(Vec3::Z)).collect();
        let skin = CompactSkin::with_format(&rows, 6, max_influences, format).unwrap();
        let reference_weights = skin.to_vertex_weights();
        let threading = if parallel { Threading::Parallel } else { Threading::Sequential };
        let mut expected_p = vec![Vec3::ZERO; rest.len()];
        let mut expected_n = vec![Vec3::ZERO; rest.len()];
        let tolerance = 1e-5 * diagonal(&rest);
        for (tangents, set) in [false, true].into_iter().flat_map(|t| supported_sets().into_iter().map(move |s| (t, s))) {
            for (method, aligned) in [(SkinningMethod::LinearBlend, false), (SkinningMethod::DualQuaternion, false), (SkinningMethod::DualQuaternion, true)] {
                let posed = run_job_aligned(set, &skin, &matrices, (method, aligned), threading, (&rest, &normals, tangents)).unwrap();
                match method {
                    SkinningMethod::LinearBlend => {
                        linear_blend_positions(&rest, &reference_weights, &matrices, &mut expected_p);
                        linear_blend_vectors(&normals, &reference_weights, &matrices, &mut expected_n);
                    }
                    SkinningMethod::DualQuaternion => {
                        dual_quaternion_positions(&rest, &reference_weights, &matrices, &mut expected_p);
                        dual_quaternion_vectors(&normals, &reference_weights, &matrices, &mut expected_n);
                    }
                }
                prop_assert!(max_distance(&posed.positions, &expected_p) <= tolerance, "{method:?} {set:?} positions, tangents: {tangents}, aligned: {aligned}");
                prop_assert!(max_distance(&posed.normals, &expected_n) <= 1e-5, "{method:?} {set:?} normals, tangents: {tangents}, aligned: {aligned}");
            }
        }
    }

    /// An identity palette reproduces the rest streams bit for bit.
    #[test]
    fn identity_pose_reproduces_the_rest_mesh_exactly(
        rows in weights_strategy(200, 5),
        points in prop::collection::vec(prop::array::uniform3(-100.0f32..100.0), 200),
        max_influences in 1usize..7,
        format in formats(),
    ) {
        let rest: Vec<Vec3> = points.iter().map(|p| Vec3::from(*p)).collect();
        let normals: Vec<Vec3> = rest.iter().map(|p| p.normalize_or(Vec3::Z)).collect();
        let skin = CompactSkin::with_format(&rows, 5, max_influences, format).unwrap();
        for method in [SkinningMethod::LinearBlend, SkinningMethod::DualQuaternion] {
            for (tangents, set) in [false, true].into_iter().flat_map(|t| supported_sets().into_iter().map(move |s| (t, s))) {
                let posed = run_job(set, &skin, &[Mat4::IDENTITY; 5], method, Threading::Sequential, &rest, &normals, tangents).unwrap();
                prop_assert_eq!(&posed.positions, &rest);
                prop_assert_eq!(&posed.normals, &normals);
            }
        }
    }
}

#[test]
fn one_rigid_joint_moves_the_mesh_rigidly() {
    let rest: Vec<Vec3> = (0..50)
        .map(|i| Vec3::new(i as f32 * 0.1, (i % 7) as f32, -(i % 3) as f32))
        .collect();
    let normals = vec![Vec3::Y; rest.len()];
    let weights = VertexWeights::from_rows(rest.iter().map(|_| vec![(1, 1.0)]));
    let skin = CompactSkin::new(&weights, 2, 4).unwrap();
    let moved = rigid([0.3, -0.2, 0.9, 0.5], [1.0, 2.0, -3.0]);
    for method in [SkinningMethod::LinearBlend, SkinningMethod::DualQuaternion] {
        let posed = run_job(
            InstructionSet::best(),
            &skin,
            &[Mat4::IDENTITY, moved],
            method,
            Threading::Parallel,
            &rest,
            &normals,
            true,
        )
        .unwrap();
        for (p, q) in rest.iter().zip(&posed.positions) {
            assert!(
                q.abs_diff_eq(moved.transform_point3(*p), 1e-5),
                "{method:?}"
            );
        }
        assert!(posed.normals[0].abs_diff_eq(moved.transform_vector3(Vec3::Y), 1e-6));
        assert_eq!(posed.tangents[0].w, -1.0);
    }
}

/// Kavan et al. 2007 §1: a cylinder along x bound to two joints, the far one twisted by
/// 150° about the axis. A ring at the middle (equal weights) keeps its edge lengths under
/// DQS, which blends to the 75° twist, and collapses towards the axis under LBS.
#[test]
fn candy_wrapper_dqs_keeps_edge_lengths_lbs_shrinks_them() {
    let ring = 24;
    let rest: Vec<Vec3> = (0..ring)
        .map(|i| {
            let a = std::f32::consts::TAU * i as f32 / ring as f32;
            Vec3::new(1.0, a.cos(), a.sin())
        })
        .collect();
    let normals: Vec<Vec3> = rest.iter().map(|p| Vec3::new(0.0, p.y, p.z)).collect();
    let weights = VertexWeights::from_rows(rest.iter().map(|_| vec![(0, 0.5), (1, 0.5)]));
    let skin = CompactSkin::new(&weights, 2, 4).unwrap();
    let twist = Mat4::from_rotation_x(150f32.to_radians());
    let edge = |p: &[Vec3], i: usize| p[i].distance(p[(i + 1) % ring]);
    let lbs = run_job(
        InstructionSet::best(),
        &skin,
        &[Mat4::IDENTITY, twist],
        SkinningMethod::LinearBlend,
        Threading::Sequential,
        &rest,
        &normals,
        false,
    )
    .unwrap();
    let dqs = run_job(
        InstructionSet::best(),
        &skin,
        &[Mat4::IDENTITY, twist],
        SkinningMethod::DualQuaternion,
        Threading::Sequential,
        &rest,
        &normals,
        false,
    )
    .unwrap();
    for i in 0..ring {
        assert!((edge(&dqs.positions, i) - edge(&rest, i)).abs() < 1e-5);
        // cos 75° ≈ 0.26: LBS shrinks the ring to about a quarter.
        assert!(edge(&lbs.positions, i) < 0.3 * edge(&rest, i));
    }
}

/// A table of invalid jobs, each rejected before any vertex is touched (as ozz's tests):
/// every case breaks one rule of a valid job.
#[test]
fn invalid_jobs_are_rejected() {
    let weights = VertexWeights::from_rows([vec![(0, 1.0)], vec![(1, 1.0)]]);
    let skin = CompactSkin::new(&weights, 2, 4).unwrap();
    let palette = SkinningPalette::new(2);
    let short_palette = SkinningPalette::new(1);
    let rest = [Vec3::ZERO; 2];
    let short = [Vec3::ZERO; 1];
    let tangents = [Vec4::ZERO; 2];
    for case in 0..7 {
        let mut out = [Vec3::ZERO; 2];
        let mut out_short = [Vec3::ZERO; 1];
        let mut out_normals = [Vec3::ZERO; 2];
        let mut out_tangents = [Vec4::ZERO; 2];
        let mut job = SkinningJob {
            skin: &skin,
            palette: &palette,
            threading: Threading::Sequential,
            rest_positions: &rest,
            rest_normals: None,
            rest_tangents: None,
            out_positions: &mut out,
            out_normals: None,
            out_tangents: None,
        };
        match case {
            0 => {
                assert!(job.run().is_ok());
                continue;
            }
            1 => job.palette = &short_palette,
            2 => job.rest_positions = &short,
            3 => job.out_positions = &mut out_short,
            4 => job.rest_normals = Some(&rest),
            5 => {
                job.rest_normals = Some(&short);
                job.out_normals = Some(&mut out_normals);
            }
            _ => {
                job.rest_tangents = Some(&tangents[..1]);
                job.out_tangents = Some(&mut out_tangents);
            }
        }
        // Every case is a buffer of the wrong size (or a missing output): refused as such,
        // by validation and by run alike.
        assert!(
            matches!(job.validate(), Err(RuntimeError::BufferSize { .. })),
            "case {case}: {:?}",
            job.validate()
        );
        assert!(
            matches!(job.run(), Err(RuntimeError::BufferSize { .. })),
            "case {case} ran"
        );
    }
}

/// Enough vertices for several parallel parts, every weight format, with and without
/// tangents, on rayon pools of 2 and 3 threads: the split must not change any result.
#[test]
fn parallel_run_equals_sequential_run_bit_for_bit() {
    let count = 3 * atlas_skin_runtime::skinning_job::PARALLEL_CHUNK + 17;
    let rest: Vec<Vec3> = (0..count)
        .map(|i| Vec3::new(i as f32, (i % 13) as f32, 1.0))
        .collect();
    let normals = vec![Vec3::Z; count];
    let weights = VertexWeights::from_rows(
        (0..count as u32).map(|i| vec![(i % 3, 1.0), ((i + 1) % 3, 0.5), (2, (i % 5) as f32)]),
    );
    let matrices = [
        rigid([0.1, 0.2, 0.3, 0.9], [1.0, 0.0, 0.0]),
        Mat4::IDENTITY,
        rigid([0.5, 0.0, 0.0, 0.5], [0.0, 2.0, 0.0]),
    ];
    let pools = [2, 3].map(|threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    });
    for format in [
        WeightFormat::Float32,
        WeightFormat::Unorm16,
        WeightFormat::Unorm8,
    ] {
        let skin = CompactSkin::with_format(&weights, 3, 4, format).unwrap();
        for (method, tangents) in [SkinningMethod::LinearBlend, SkinningMethod::DualQuaternion]
            .into_iter()
            .flat_map(|m| [(m, false), (m, true)])
        {
            let run = |threading| {
                run_job(
                    InstructionSet::best(),
                    &skin,
                    &matrices,
                    method,
                    threading,
                    &rest,
                    &normals,
                    tangents,
                )
                .unwrap()
            };
            let sequential = run(Threading::Sequential);
            for (threads, pool) in [2, 3].into_iter().zip(&pools) {
                let parallel = pool.install(|| run(Threading::Parallel));
                let what = format!("{format:?} {method:?} tangents {tangents} {threads} threads");
                assert_eq!(sequential.positions, parallel.positions, "{what}");
                assert_eq!(sequential.normals, parallel.normals, "{what}");
                assert_eq!(sequential.tangents, parallel.tangents, "{what}");
            }
        }
    }
}

/// Turns of up to 0.3 rad on a skin where every joint shares vertices with every other:
/// aligned, every pair agrees, so the vector loops blend without the sign fix, and still
/// match the scalar reference (which fixes signs against each vertex's first influence).
#[test]
fn aligned_dual_quaternions_match_the_reference() {
    use atlas_skin_runtime::random_pose::{random_rotations, SplitMix64};
    const JOINTS: usize = 6;
    let mut rng = SplitMix64::new(5);
    let rest: Vec<Vec3> = (0..400).map(|_| rng.unit_vector()).collect();
    let normals: Vec<Vec3> = (0..400).map(|_| rng.unit_vector()).collect();
    let weights = VertexWeights::from_rows((0..rest.len()).map(|v| {
        (0..1 + v % 4)
            .map(|i| (((v + 2 * i) % JOINTS) as u32, 0.1 + (i as f32)))
            .collect::<Vec<_>>()
    }));
    let skin = CompactSkin::new(&weights, JOINTS, 4).unwrap();
    let reference_weights = skin.to_vertex_weights();
    for seed in 0..4 {
        let matrices: Vec<Mat4> = random_rotations(JOINTS, 0.3, seed)
            .into_iter()
            .map(|q| Mat4::from_rotation_translation(q, rng.unit_vector()))
            .collect();
        let mut palette = SkinningPalette::new(JOINTS);
        palette
            .update(&matrices, SkinningMethod::DualQuaternion)
            .unwrap();
        palette.align_hemispheres(&skin);
        assert!(palette.hemispheres_agree(&skin), "seed {seed}");
        let mut expected_p = vec![Vec3::ZERO; rest.len()];
        let mut expected_n = vec![Vec3::ZERO; rest.len()];
        dual_quaternion_positions(&rest, &reference_weights, &matrices, &mut expected_p);
        dual_quaternion_vectors(&normals, &reference_weights, &matrices, &mut expected_n);
        for set in supported_sets() {
            let method = (SkinningMethod::DualQuaternion, true);
            let streams = (rest.as_slice(), normals.as_slice(), false);
            let posed = run_job_aligned(
                set,
                &skin,
                &matrices,
                method,
                Threading::Sequential,
                streams,
            )
            .unwrap();
            assert!(max_distance(&posed.positions, &expected_p) <= 1e-5 * diagonal(&rest));
            assert!(max_distance(&posed.normals, &expected_n) <= 1e-5);
        }
    }
}

/// A mesh of `PREFETCH_FROM` vertices and more, where the vector loops prefetch ahead of
/// the block they skin (up to the span's last full block): with and without normals and
/// tangents, sequential and parallel, every instruction set, still the scalar reference.
#[test]
fn large_meshes_prefetch_and_match_the_reference() {
    use atlas_skin_runtime::random_pose::{random_rotations, SplitMix64};
    use atlas_skin_runtime::skinning_job::PREFETCH_FROM;
    const JOINTS: usize = 7;
    let count = PREFETCH_FROM + 1003;
    let mut rng = SplitMix64::new(17);
    let rest: Vec<Vec3> = (0..count).map(|_| rng.unit_vector()).collect();
    let normals: Vec<Vec3> = (0..count).map(|_| rng.unit_vector()).collect();
    let weights = VertexWeights::from_rows((0..count).map(|v| {
        (0..1 + (v / 5) % 4)
            .map(|i| (((v + 3 * i) % JOINTS) as u32, 0.2 + (i as f32)))
            .collect::<Vec<_>>()
    }));
    let skin = CompactSkin::new(&weights, JOINTS, 4).unwrap();
    let reference_weights = skin.to_vertex_weights();
    let matrices: Vec<Mat4> = random_rotations(JOINTS, 1.0, 3)
        .into_iter()
        .map(|q| Mat4::from_rotation_translation(q, rng.unit_vector()))
        .collect();
    let mut expected_p = vec![Vec3::ZERO; count];
    let mut expected_n = vec![Vec3::ZERO; count];
    linear_blend_positions(&rest, &reference_weights, &matrices, &mut expected_p);
    linear_blend_vectors(&normals, &reference_weights, &matrices, &mut expected_n);
    let tolerance = 1e-5 * diagonal(&rest);
    for set in supported_sets() {
        for threading in [Threading::Sequential, Threading::Parallel] {
            for tangents in [false, true] {
                let posed = run_job(
                    set,
                    &skin,
                    &matrices,
                    SkinningMethod::LinearBlend,
                    threading,
                    &rest,
                    &normals,
                    tangents,
                )
                .unwrap();
                let what = format!("{set:?} {threading:?} tangents {tangents}");
                assert!(
                    max_distance(&posed.positions, &expected_p) <= tolerance,
                    "{what}"
                );
                assert!(max_distance(&posed.normals, &expected_n) <= 1e-5, "{what}");
            }
            // Positions only: the loops without normal streams.
            let mut palette = SkinningPalette::new(JOINTS);
            palette
                .update(&matrices, SkinningMethod::LinearBlend)
                .unwrap();
            let mut positions = vec![Vec3::ZERO; count];
            SkinningJob {
                skin: &skin,
                palette: &palette,
                threading,
                rest_positions: &rest,
                rest_normals: None,
                rest_tangents: None,
                out_positions: &mut positions,
                out_normals: None,
                out_tangents: None,
            }
            .run_with(set)
            .unwrap();
            assert!(
                max_distance(&positions, &expected_p) <= tolerance,
                "{set:?} {threading:?} positions only"
            );
        }
    }
}

//! The fast skinning job equals the scalar reference (atlas_skin_runtime::reference) within
//! 1e-5 of the bounding-box diagonal on every corpus model with weights, for linear blend
//! and dual quaternion skinning of seeded random poses, sequential and parallel, with and
//! without normals, with every instruction set this CPU runs (the portable loops always:
//! what a CPU without AVX2 or AVX-512 runs), with float and quantised weights, in the
//! mesh's vertex order and grouped by influence count (`VertexOrder`); and what quantising
//! the weights costs in accuracy (`QUANTISED_ERROR`).

#[path = "../../atlas-skin-runtime/tests/skinning_support/mod.rs"]
mod skinning_support;

use atlas_skin_io::LoadOptions;
use atlas_skin_runtime::pose::palette_from_world;
use atlas_skin_runtime::random_pose::random_rotations;
use atlas_skin_runtime::reference::{
    dual_quaternion_positions, dual_quaternion_vectors, linear_blend_positions,
    linear_blend_vectors,
};
use atlas_skin_runtime::{
    CompactSkin, InstructionSet, Rig, SkinningJob, SkinningMethod, SkinningPalette, Threading,
    VertexOrder, WeightFormat,
};
use glam::{Mat4, Vec3};
use skinning_support::{diagonal, max_distance};
use std::path::Path;

const MODELS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/models");

/// (folder, input, skeleton, group, weights)
type Model = (
    &'static str,
    &'static str,
    Option<&'static str>,
    Option<&'static str>,
    Option<&'static str>,
);

const CORPUS: [Model; 7] = [
    ("cesiumman", "CesiumMan.glb", None, None, None),
    ("riggedfigure", "RiggedFigure.glb", None, None, None),
    ("riggedsimple", "RiggedSimple.glb", None, None, None),
    ("simpleskin", "SimpleSkin.gltf", None, None, None),
    (
        "arm",
        "arm.obj",
        Some("arm.tgf"),
        None,
        Some("arm-weights.dmat"),
    ),
    (
        "elephant",
        "elephant.obj",
        Some("elephant.tgf"),
        None,
        Some("elephant-weights.dmat"),
    ),
    (
        "makehuman",
        "base.obj",
        Some("default.mhskel"),
        Some("body"),
        Some("default_weights.mhw"),
    ),
];

/// Largest distance, in units of the bounding-box diagonal, between the reference
/// deformation with quantised weights and with the float weights they come from, over the
/// corpus, its seeded poses and both methods (the figure docs state for `--weights`).
const QUANTISED_ERROR: [(WeightFormat, f32); 2] = [
    (WeightFormat::Unorm16, 1e-5),
    (WeightFormat::Unorm8, 2.5e-3),
];

#[test]
fn fast_paths_match_the_reference_on_the_corpus() {
    let mut quantised_error = [0.0f32; 2];
    // Aligned palettes whose every pair agreed (the loops without the sign fix ran), of all.
    let (mut agreed, mut aligned_palettes) = (0, 0);
    for (folder, input, skeleton, group, weights) in CORPUS {
        let dir = Path::new(MODELS).join(folder);
        let path = dir.join(input);
        assert!(path.exists(), "corpus file {} is missing", path.display());
        let options = LoadOptions {
            skeleton: skeleton.map(|s| dir.join(s)),
            group: group.map(String::from),
            weights: weights.map(|w| dir.join(w)),
        };
        let character = atlas_skin_io::load_character(&path, &options).expect("load");
        let skeleton = character.skeleton.as_ref().expect("skeleton");
        let rig = character
            .rig
            .clone()
            .unwrap_or_else(|| Rig::from_skeleton(skeleton));
        let mesh_rows = character.reference_weights.as_ref().expect("weights");
        let mesh_rest = &character.mesh.positions;
        let mesh_normals: Vec<Vec3> = mesh_rest
            .iter()
            .map(|p| (*p - mesh_rest[0]).normalize_or(Vec3::Y))
            .collect();
        // Elephant rows have up to 23 influences: the N path with 8. `grouped`: the
        // vertices reordered by influence count, as an engine would at load.
        for (max_influences, format, grouped) in [
            (4, WeightFormat::Float32, false),
            (8, WeightFormat::Float32, false),
            (4, WeightFormat::Unorm16, false),
            (8, WeightFormat::Unorm8, false),
            (4, WeightFormat::Float32, true),
        ] {
            let order = grouped.then(|| VertexOrder::by_influence_count(mesh_rows, max_influences));
            let reordered = order.as_ref().map(|order| {
                (
                    order.apply_weights(mesh_rows).expect("a row per vertex"),
                    order.apply(mesh_rest).expect("a position per vertex"),
                    order.apply(&mesh_normals).expect("a normal per vertex"),
                )
            });
            let (rows, rest, normals) = match &reordered {
                Some((rows, rest, normals)) => (rows, rest, normals),
                None => (mesh_rows, mesh_rest, &mesh_normals),
            };
            let skin = CompactSkin::with_format(rows, skeleton.len(), max_influences, format)
                .expect("valid weights");
            let reference_weights = skin.to_vertex_weights();
            let float_weights = CompactSkin::new(rows, skeleton.len(), max_influences)
                .expect("valid weights")
                .to_vertex_weights();
            let quantised_slot = QUANTISED_ERROR.iter().position(|&(f, _)| f == format);
            let tolerance = 1e-5 * diagonal(rest);
            for seed in 0..3 {
                let mut local = rig.rest.clone();
                let rotations = random_rotations(skeleton.len(), 1.0, seed);
                for (&node, q) in rig.joint_nodes.iter().zip(&rotations) {
                    local[node as usize].rotation *= *q;
                }
                let mut node_world = vec![Mat4::IDENTITY; rig.len()];
                let mut joint_world = vec![Mat4::IDENTITY; skeleton.len()];
                let mut matrices = vec![Mat4::IDENTITY; skeleton.len()];
                rig.world(&local, &mut node_world);
                rig.joint_world(&node_world, &mut joint_world);
                palette_from_world(&joint_world, &skeleton.inverse_bind, &mut matrices);
                // Dual quaternions as converted, and with their hemispheres aligned to the
                // skin (the vector loops then leave out the sign fix where every pair agrees).
                for (method, aligned) in [
                    (SkinningMethod::LinearBlend, false),
                    (SkinningMethod::DualQuaternion, false),
                    (SkinningMethod::DualQuaternion, true),
                ] {
                    let mut palette = SkinningPalette::new(skeleton.len());
                    palette.update(&matrices, method).expect("rigid palette");
                    if aligned {
                        palette.align_hemispheres(&skin);
                        agreed += usize::from(palette.hemispheres_agree(&skin));
                        aligned_palettes += 1;
                    }
                    let mut expected = vec![Vec3::ZERO; rest.len()];
                    let mut expected_normals = vec![Vec3::ZERO; rest.len()];
                    // The scalar reference of `method` with these weights: positions, normals.
                    let reference =
                        |weights, positions: &mut [Vec3], vectors: &mut [Vec3]| match method {
                            SkinningMethod::LinearBlend => {
                                linear_blend_positions(rest, weights, &matrices, positions);
                                linear_blend_vectors(normals, weights, &matrices, vectors);
                            }
                            SkinningMethod::DualQuaternion => {
                                dual_quaternion_positions(rest, weights, &matrices, positions);
                                dual_quaternion_vectors(normals, weights, &matrices, vectors);
                            }
                        };
                    reference(&reference_weights, &mut expected, &mut expected_normals);
                    if let Some(slot) = quantised_slot {
                        let mut float_expected = vec![Vec3::ZERO; rest.len()];
                        let mut float_normals = vec![Vec3::ZERO; rest.len()];
                        reference(&float_weights, &mut float_expected, &mut float_normals);
                        let error = max_distance(&expected, &float_expected) / diagonal(rest);
                        quantised_error[slot] = quantised_error[slot].max(error);
                    }
                    let sets = InstructionSet::ALL.into_iter().filter(|s| s.is_supported());
                    for (set, threading, with_normals) in sets.flat_map(|set| {
                        [Threading::Sequential, Threading::Parallel]
                            .into_iter()
                            .flat_map(move |t| [(set, t, true), (set, t, false)])
                    }) {
                        let mut positions = vec![Vec3::ZERO; rest.len()];
                        let mut out_normals = vec![Vec3::ZERO; rest.len()];
                        SkinningJob {
                            skin: &skin,
                            palette: &palette,
                            threading,
                            rest_positions: rest,
                            rest_normals: with_normals.then_some(normals.as_slice()),
                            rest_tangents: None,
                            out_positions: &mut positions,
                            out_normals: with_normals.then_some(out_normals.as_mut_slice()),
                            out_tangents: None,
                        }
                        .run_with(set)
                        .expect("valid job");
                        let what = format!(
                            "{folder}, K ≤ {max_influences} ({format:?}, grouped {grouped}), seed {seed}, {method:?} (aligned {aligned}), {threading:?}, {}, normals {with_normals}",
                            set.name()
                        );
                        let error = max_distance(&positions, &expected);
                        assert!(error <= tolerance, "{what}: positions off by {error}");
                        if with_normals {
                            let error = max_distance(&out_normals, &expected_normals);
                            assert!(error <= 1e-5, "{what}: normals off by {error}");
                        }
                    }
                }
            }
        }
    }
    eprintln!("{agreed} of {aligned_palettes} aligned palettes agree on every pair");
    assert!(
        agreed > 0,
        "no corpus pose ran the loops without the sign fix"
    );
    for ((format, bound), error) in QUANTISED_ERROR.iter().zip(quantised_error) {
        eprintln!("{format:?} weights move the corpus by at most {error:.2e} of the diagonal");
        assert!(error <= *bound, "{format:?}: {error} > {bound}");
    }
}

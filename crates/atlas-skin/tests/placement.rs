//! The weights do not depend on where a character stands in its file or on its unit:
//! real characters moved by a few of their diagonals and scaled by 100 get the weights
//! they get in place. The Knight of the bench (open pieces: its signed volume, taken about
//! the origin, changed sign when it was moved by two diagonals along z, which turned the
//! ray test of joint roles inside out and left its right hand without a cut).

use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
use atlas_skin_corpus::data_file;
use atlas_skin_io::{load_character, LoadOptions};
use atlas_skin_runtime::{Skeleton, VertexWeights};
use glam::{Affine3A, Mat4, Vec3};

/// The weights of `positions` and `skeleton` under `place` (a scaling and a translation
/// of the whole scene).
fn weights(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    skeleton: &Skeleton,
    place: Affine3A,
) -> VertexWeights {
    let moved: Vec<Vec3> = positions
        .iter()
        .map(|&p| place.transform_point3(p))
        .collect();
    let mut moved_skeleton = skeleton.clone();
    // Joint frames keep their rotation; their origins move with the scene.
    moved_skeleton.inverse_bind = skeleton
        .bind_world()
        .iter()
        .map(|bind| {
            let (_, rotation, origin) = bind.to_scale_rotation_translation();
            Mat4::from_rotation_translation(rotation, place.transform_point3(origin)).inverse()
        })
        .collect();
    moved_skeleton.tails = skeleton
        .tails
        .iter()
        .map(|t| t.map(|t| place.transform_point3(t)))
        .collect();
    let input = SkinInput {
        positions: &moved,
        triangles,
        skeleton: &moved_skeleton,
        end_joints: &[],
    };
    skin(input, &SkinParams::default(), &mut |_| {})
        .expect("skinned")
        .weights
}

/// The largest total variation ½ Σ_j |w_j − w'_j| of a vertex's row between two weightings.
fn largest_change(a: &VertexWeights, b: &VertexWeights, joints: usize) -> f64 {
    let mut row = vec![0.0f64; joints];
    (0..a.vertex_count())
        .map(|v| {
            row.iter_mut().for_each(|w| *w = 0.0);
            a.row(v).for_each(|(j, w)| row[j as usize] += f64::from(w));
            b.row(v).for_each(|(j, w)| row[j as usize] -= f64::from(w));
            0.5 * row.iter().map(|w| w.abs()).sum::<f64>()
        })
        .fold(0.0, f64::max)
}

fn check(relative: &str) {
    let character = load_character(&data_file(relative), &LoadOptions::default()).unwrap();
    let skeleton = character.skeleton.expect("a skeleton");
    let (positions, triangles) = (&character.mesh.positions, &character.mesh.triangles);
    let (lo, hi) = positions
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let diagonal = (hi - lo).length();
    let in_place = weights(positions, triangles, &skeleton, Affine3A::IDENTITY);
    // Rounding the moved positions to f32 moves a cut's crossings by an ulp, and a row by
    // up to 0.015 (CesiumMan); scaled by a power of two, nothing is rounded.
    let moved = |by: Vec3| Affine3A::from_translation(by * diagonal);
    for (what, place, bound) in [
        ("moved 2 diagonals along z", moved(Vec3::Z * 2.0), 0.02),
        (
            "moved (3, -2, 5) diagonals",
            moved(Vec3::new(3.0, -2.0, 5.0)),
            0.02,
        ),
        (
            "scaled by 100",
            Affine3A::from_scale(Vec3::splat(100.0)),
            0.02,
        ),
        (
            "scaled by 128",
            Affine3A::from_scale(Vec3::splat(128.0)),
            0.0,
        ),
    ] {
        let placed = weights(positions, triangles, &skeleton, place);
        let change = largest_change(&in_place, &placed, skeleton.len());
        println!("{relative}, {what}: largest change of a row {change:.5}");
        assert!(
            change <= bound,
            "{relative}, {what}: a row changed by {change}"
        );
    }
}

#[test]
fn the_knight_of_open_pieces_gets_the_same_weights_wherever_it_stands() {
    check("bench/kaykit/Knight.glb");
}

#[test]
fn cesium_man_gets_the_same_weights_wherever_it_stands() {
    check("models/cesiumman/CesiumMan.glb");
}

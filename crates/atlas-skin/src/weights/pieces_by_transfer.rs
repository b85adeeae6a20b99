//! Step 5, another way for the pieces that hold no bone (clothes, hair, props): their
//! weights carried from the pieces that hold bones by robust weight transfer
//! ([`crate::transfer`]: closest point matching within a distance and an angle, the rest
//! inpainted; Abdrashitov et al. 2023), instead of the contact rule of [`super::pieces`].
//! Selected by [`LoosePieces::Transfer`] (`"loose_pieces": "transfer"` in a settings
//! file); the contact rule stays the default.
//!
//! After [`super::pieces::weight_pieces`] has weighted every piece, the *source* is the
//! split surface's faces of the pieces that hold bones (body pieces and the pieces of
//! [`super::pieces`] that hold some) with their rows, the *target* the faces of the pieces
//! that hold none; every target vertex takes the row the transfer gives it. When the
//! transfer cannot run (no face holds a bone, or the target lies nowhere near the source),
//! the contact rule's rows stay and a warning says so.
//!
//! Measured on the benchmark (docs/measurements.md, "Pieces that hold no bone by weight
//! transfer"): it does not beat the contact rule, which stays the default.

use super::surface_weights::{PieceWeighting, SurfaceWeights};
use crate::decomposition::Decomposition;
use crate::transfer::{transfer_weights, TransferParams, TransferSource};
use atlas_skin_runtime::VertexWeights;
use serde::{Deserialize, Serialize};

/// How the pieces that hold no bone are weighted.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoosePieces {
    /// Carried by the body where they touch it ([`super::pieces`], "Contact").
    #[default]
    Contact,
    /// By weight transfer from the pieces that hold bones (this module).
    Transfer,
}

/// Re-weights the vertices of the pieces that hold no bone by transfer from the others
/// (module documentation); returns how many it re-weighted, or why it kept the contact
/// rule's rows (a warning for the report).
pub fn transfer_to_loose_pieces(
    decomposition: &Decomposition,
    pieces: &[PieceWeighting],
    joint_count: usize,
    weights: &mut SurfaceWeights,
) -> Result<usize, String> {
    let surface = &decomposition.surface;
    let piece_of = &decomposition.topology.vertex_component;
    let loose = |v: u32| !pieces[piece_of[v as usize] as usize].holds_bones;
    let n = surface.vertex_count();
    let mut local = vec![u32::MAX; n];
    let mut target_vertices: Vec<u32> = Vec::new();
    for v in (0..n as u32).filter(|&v| loose(v)) {
        local[v as usize] = target_vertices.len() as u32;
        target_vertices.push(v);
    }
    if target_vertices.is_empty() {
        return Ok(0);
    }
    // A face's corners lie in one piece.
    let (target, source): (Vec<[u32; 3]>, Vec<[u32; 3]>) =
        surface.triangles.iter().partition(|t| loose(t[0]));
    let why = |e: &dyn std::fmt::Display| {
        format!(
            "the {} vertices of the pieces that hold no bone keep the contact rule's \
             weights: weight transfer from the other pieces failed ({e})",
            target_vertices.len()
        )
    };
    let positions: Vec<glam::Vec3> = surface.positions.iter().map(|p| p.as_vec3()).collect();
    let rows = VertexWeights::from_rows((0..n).map(|v| {
        weights
            .row(v)
            .map(|(j, w)| (j, w as f32))
            .collect::<Vec<_>>()
    }));
    let source =
        TransferSource::new(&positions, &source, &rows, joint_count).map_err(|e| why(&e))?;
    let target_positions: Vec<glam::Vec3> = target_vertices
        .iter()
        .map(|&v| positions[v as usize])
        .collect();
    let target_triangles: Vec<[u32; 3]> = target
        .iter()
        .map(|t| t.map(|v| local[v as usize]))
        .collect();
    let transferred = transfer_weights(
        &source,
        &target_positions,
        &target_triangles,
        &TransferParams::default(),
    )
    .map_err(|e| why(&e))?;
    let mut out = SurfaceWeights {
        offsets: vec![0],
        ..SurfaceWeights::default()
    };
    for (v, &k) in local.iter().enumerate() {
        match k {
            u32::MAX => out.extend_row(weights.row(v).collect::<Vec<_>>()),
            k => out.extend_row(
                transferred
                    .weights
                    .row(k as usize)
                    .map(|(j, w)| (j, f64::from(w))),
            ),
        }
    }
    *weights = out;
    Ok(target_vertices.len())
}

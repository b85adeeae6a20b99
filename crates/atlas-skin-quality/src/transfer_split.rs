//! The transfer benchmark's question, from a character with artist weights: which of its
//! pieces hold no bone (clothes, hair, armour, props: the method's own decision, the
//! pieces of [`atlas_skin::weights::pieces`] with `holds_bones` false), and the character
//! cut in two: the rest (the *source*, with its artist weights) and those pieces (the
//! *target*, artist weights removed). Candidates are judged on the target's vertices
//! against the artist's weights ([`score`]): deformation under the benchmark's random
//! poses ([`atlas_skin_eval::deform`], LBS) and weight L1, per character and per piece.

use anyhow::{bail, Context, Result};
use atlas_skin::mesh::weld::UNREFERENCED;
use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
use atlas_skin_eval::deform::{deformation_error, random_pose_palettes, Skinning};
use atlas_skin_eval::weights_l1::weights_l1;
use atlas_skin_runtime::{Skeleton, VertexWeights};
use glam::{Mat4, Vec3};
use serde::Serialize;
use std::path::Path;

/// A character cut into source and target.
pub struct Split {
    pub skeleton: Skeleton,
    /// All stored positions and the artist's rows (renormalised).
    pub positions: Vec<Vec3>,
    pub artist: VertexWeights,
    /// Triangles of the pieces that hold bones.
    pub source_triangles: Vec<[u32; 3]>,
    /// The target's stored vertices (ascending) and its triangles over them (local
    /// indices).
    pub target_vertices: Vec<u32>,
    pub target_triangles: Vec<[u32; 3]>,
    /// Per target vertex: its piece (0.. in order of first vertex).
    pub target_piece: Vec<u32>,
    pub pieces: usize,
    /// Bounding-box diagonal of the whole character (the unit of deformation errors).
    pub diagonal: f64,
}

impl Split {
    /// The target's positions.
    pub fn target_positions(&self) -> Vec<Vec3> {
        self.target_vertices
            .iter()
            .map(|&v| self.positions[v as usize])
            .collect()
    }

    /// The artist's rows of the target's vertices.
    pub fn target_artist(&self) -> VertexWeights {
        VertexWeights::from_rows(
            self.target_vertices
                .iter()
                .map(|&v| self.artist.row(v as usize).collect::<Vec<_>>()),
        )
    }
}

/// Reads `path` (a glb with artist weights), skins it with the method's defaults to learn
/// which pieces hold no bone, and cuts it; `None` when it has no such piece or only such
/// pieces.
pub fn split_character(path: &Path) -> Result<Option<Split>> {
    let character = atlas_skin_io::load_character(path, &Default::default())
        .with_context(|| format!("reading {}", path.display()))?;
    let Some(skeleton) = character.skeleton.clone() else {
        bail!("{} has no skeleton", path.display());
    };
    let Some(artist) = character.reference_weights.as_ref() else {
        bail!("{} has no weights", path.display());
    };
    let mesh = &character.mesh;
    let skinned = skin(
        SkinInput {
            positions: &mesh.positions,
            triangles: &mesh.triangles,
            skeleton: &skeleton,
            end_joints: &character.end_joints,
        },
        &SkinParams::default(),
        &mut |_| {},
    )
    .with_context(|| format!("skinning {}", path.display()))?;
    let component = &skinned.decomposition.topology.vertex_component;
    let pieces = &skinned.counts.weights.pieces;
    let piece_of = |s: usize| -> Option<u32> {
        let w = skinned.welded_of_stored[s];
        (w != UNREFERENCED).then(|| component[w as usize])
    };
    let in_target = |s: usize| piece_of(s).is_some_and(|p| !pieces[p as usize].holds_bones);
    let target_vertices: Vec<u32> = (0..mesh.positions.len() as u32)
        .filter(|&s| in_target(s as usize))
        .collect();
    if target_vertices.is_empty() || target_vertices.len() == skinned.welded_of_stored.len() {
        return Ok(None);
    }
    let mut local = vec![u32::MAX; mesh.positions.len()];
    for (k, &v) in target_vertices.iter().enumerate() {
        local[v as usize] = k as u32;
    }
    let (target, source): (Vec<[u32; 3]>, Vec<[u32; 3]>) = mesh
        .triangles
        .iter()
        .partition(|t| t.iter().all(|&v| local[v as usize] != u32::MAX));
    if source.is_empty() || target.is_empty() {
        return Ok(None);
    }
    let mut piece_number = std::collections::HashMap::new();
    let target_piece: Vec<u32> = target_vertices
        .iter()
        .map(|&v| {
            let next = piece_number.len() as u32;
            *piece_number
                .entry(piece_of(v as usize).expect("a target vertex is referenced"))
                .or_insert(next)
        })
        .collect();
    let (lo, hi) = atlas_skin::geometry::bounding_box(
        mesh.positions
            .iter()
            .map(|p| p.as_dvec3())
            .collect::<Vec<_>>()
            .iter(),
    );
    Ok(Some(Split {
        artist: normalised(artist),
        positions: mesh.positions.clone(),
        skeleton,
        source_triangles: source,
        target_triangles: target
            .iter()
            .map(|t| t.map(|v| local[v as usize]))
            .collect(),
        target_vertices,
        target_piece,
        pieces: piece_number.len(),
        diagonal: (hi - lo).length(),
    }))
}

/// Rows rescaled to sum to 1 (the bench's files keep rows cut to 4 influences unscaled).
pub fn normalised(weights: &VertexWeights) -> VertexWeights {
    VertexWeights::from_rows((0..weights.vertex_count()).map(|v| {
        let total: f32 = weights.row(v).map(|(_, w)| w).sum();
        weights
            .row(v)
            .filter(|&(_, w)| w > 0.0)
            .map(|(j, w)| (j, w / total))
            .collect::<Vec<_>>()
    }))
}

/// How a candidate weighting of the target compares with the artist's.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct Score {
    /// Deformation error over the target's vertices and the poses (LBS), in units of the
    /// character's diagonal: mean and largest.
    pub deform_mean: f64,
    pub deform_max: f64,
    /// Mean per-vertex L1 distance of the rows.
    pub l1: f64,
    /// Largest deformation error of each piece.
    pub piece_max: Vec<f64>,
}

/// The benchmark's poses of `skeleton`: `atlas-skin eval`'s (10 seeded random poses, up
/// to 60° per joint, seed 0).
pub fn poses(skeleton: &Skeleton) -> Vec<Vec<Mat4>> {
    let options = atlas_skin_eval::EvalOptions::default();
    random_pose_palettes(skeleton, options.poses, options.max_angle, options.seed)
}

/// Scores `candidate` (one row per target vertex) on `split` under `palettes`.
pub fn score(split: &Split, candidate: &VertexWeights, palettes: &[Vec<Mat4>]) -> Score {
    let rest = split.target_positions();
    let artist = split.target_artist();
    let errors = deformation_error(
        &rest,
        &artist,
        candidate,
        palettes,
        Skinning::Linear,
        split.diagonal,
    );
    let mut piece_max = vec![0.0f64; split.pieces];
    for (e, &p) in errors.vertices.iter().zip(&split.target_piece) {
        piece_max[p as usize] = piece_max[p as usize].max(e.max);
    }
    Score {
        deform_mean: errors.total.mean,
        deform_max: errors.total.max,
        l1: weights_l1(&artist, candidate, split.skeleton.len()).mean,
        piece_max,
    }
}

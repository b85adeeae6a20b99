//! The weights stage's result before un-welding: weights of every vertex of the split
//! surface, and what could not be done as planned.

use serde::Serialize;

/// Weights of every vertex of the split surface, in compressed rows like
/// [`VertexWeights`](atlas_skin_runtime::VertexWeights): vertex v's (joint, weight) pairs are at `offsets[v]..offsets[v + 1]`,
/// weights positive and summing to 1, joints distinct.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceWeights {
    pub offsets: Vec<u32>,
    pub joints: Vec<u32>,
    pub weights: Vec<f64>,
}

impl SurfaceWeights {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The (joint, weight) pairs of vertex `v`.
    pub fn row(&self, v: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let range = self.offsets[v] as usize..self.offsets[v + 1] as usize;
        self.joints[range.clone()]
            .iter()
            .copied()
            .zip(self.weights[range].iter().copied())
    }

    /// The first `count` rows.
    pub(crate) fn first_rows(&self, count: usize) -> Self {
        let end = self.offsets[count] as usize;
        Self {
            offsets: self.offsets[..=count].to_vec(),
            joints: self.joints[..end].to_vec(),
            weights: self.weights[..end].to_vec(),
        }
    }

    pub(crate) fn extend_row(&mut self, row: impl IntoIterator<Item = (u32, f64)>) {
        for (j, w) in row {
            self.joints.push(j);
            self.weights.push(w);
        }
        self.offsets.push(self.joints.len() as u32);
    }
}

/// What the weights stage could not do as planned, for the report.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct WeightCounts {
    /// Surface vertices no region with joints reaches.
    pub unreachable: usize,
    /// Of those, vertices of pieces that span a joint with no body beneath, bent at the
    /// boundary planes of their joints.
    pub bent: usize,
    /// Of those, vertices of pieces attached to the body surface they sit on.
    pub attached: usize,
    /// Of the attached vertices, those whose body weights lay partly off the one part of
    /// the skeleton that carries their piece ([`super::carriers`]) and were replaced.
    pub off_carrier: usize,
    /// Of those, vertices of pieces bound rigidly to one joint.
    pub rigid: usize,
    /// Every piece (connected component of the split surface) and how it was weighted.
    pub pieces: Vec<PieceWeighting>,
    /// The gaps of body pieces weighted as a whole, like pieces without weights.
    pub gaps: Vec<GapWeighting>,
    /// Joints whose soft boundary is inactive (no cross-section near the joint).
    pub inactive_soft_joints: Vec<u32>,
    /// Vertices where more soft joints' sides would act than [`super::crowding`] lets in.
    pub crowded_vertices: usize,
    /// Vertices whose weights on far joints the guard removed (step 4).
    pub far_bone_vertices: usize,
    /// Vertices whose sibling blends gave weight to the siblings' common ancestor (step 3b).
    pub sibling_blend_vertices: usize,
    /// Vertices of the pieces that hold no bone weighted by transfer from the others
    /// ([`super::pieces_by_transfer`]; 0 under the default contact rule).
    pub transferred: usize,
}

/// How a piece was weighted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case", tag = "treatment", content = "joint")]
pub enum PieceTreatment {
    /// Decomposed with the joints it holds (steps 1–3).
    Body,
    /// Weights of the nearest point of the body surface.
    Attached,
    /// Weight 1 on one joint.
    Rigid(u32),
    /// Bent at the boundary planes of the joints whose bones it holds (or, holding none,
    /// of its vertices' nearest bones).
    Joints,
}

/// One piece of the split surface and how it was weighted.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct PieceWeighting {
    #[serde(flatten)]
    pub treatment: PieceTreatment,
    pub vertices: usize,
    /// A bone runs through it (body pieces, and the pieces of [`super::pieces`] that hold
    /// bones); false for the pieces that hold none (clothes, hair, props).
    #[serde(skip)]
    pub holds_bones: bool,
}

/// A gap of a body piece (vertices no region with joints reaches, joined by edges) and how
/// it was weighted as a whole.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct GapWeighting {
    #[serde(flatten)]
    pub treatment: PieceTreatment,
    /// Its split-surface vertices.
    pub vertices: Vec<u32>,
}

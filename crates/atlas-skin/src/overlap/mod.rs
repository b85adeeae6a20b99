//! Overlapping areas (Lu et al. 2008, §3.3): how far each boundary's transition reaches,
//! and the surface distances from each cut curve within that reach.
//!
//! Width: a boundary of approximate diameter D (the largest distance between two points of
//! its curve, [`crate::Boundary::diameter`]) gets the overlap half-width
//! w = factor × D on each side. The paper marks the vertices closer than D · 0.5 to the
//! curve as overlapping, so its choice is factor = 0.5; the follow-up paper (Lu et al.,
//! GRAPP 2009) makes the factor a user setting per joint, from quasi-rigid (small) to soft
//! (large). The transition between the two sides therefore spans 2w = 2 · factor · D of
//! surface distance.
//!
//! Distances are computed up to w exactly, with no margin: a vertex farther than w from a
//! curve weighs the same as one the band never reaches ([`crate::weights`]: its normalised
//! depth is ≥ 1 inside the region and ≤ 0 outside).
//!
//! Inputs: a [`Decomposition`], the decomposed skeleton (for per-joint factors by name),
//! [`OverlapParams`]. Output: [`Overlaps`]: one half-width per boundary and, per cut, the
//! band of surface distances ([`geodesic`]).

pub mod geodesic;

use crate::decomposition::{BoundaryKind, Decomposition};
use atlas_skin_runtime::Skeleton;
use geodesic::{march_distances, BandDistances, MarchScratch};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use thiserror::Error;

/// Why the overlaps cannot be computed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum OverlapError {
    #[error("overlap factor for unknown joint {name:?}")]
    UnknownJoint { name: String },
    #[error("overlap factor {value} {} is not a positive number", joint.as_ref().map_or("(global)".to_string(), |j| format!("for joint {j:?}")))]
    BadFactor { joint: Option<String>, value: f64 },
    #[error("the decomposition refers to joint {joint}, the skeleton has {count} joints")]
    JointOutOfRange { joint: u32, count: usize },
    #[error("the cut curve of joint {joint} uses vertex {vertex}, the surface has {count}")]
    CurveVertexOutOfRange {
        joint: u32,
        vertex: u32,
        count: usize,
    },
}

/// The paper's overlap factor (§3.3: "D_i * 0.5").
pub const PAPER_OVERLAP_FACTOR: f64 = 0.5;

/// Overlap widths: a global factor and per-joint overrides (by joint name).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OverlapParams {
    /// Half-width of every overlap band as a multiple of its boundary's diameter.
    pub factor: f64,
    /// Factor for the boundary of the named joint, replacing `factor`.
    pub per_joint: BTreeMap<String, f64>,
}

impl Default for OverlapParams {
    fn default() -> Self {
        Self {
            factor: PAPER_OVERLAP_FACTOR,
            per_joint: BTreeMap::new(),
        }
    }
}

impl OverlapParams {
    /// Checks that every factor is finite and positive and names a joint of `skeleton`.
    pub fn validate(&self, skeleton: &Skeleton) -> Result<(), OverlapError> {
        check_factor(None, self.factor)?;
        for (name, &factor) in &self.per_joint {
            if skeleton.find(name).is_none() {
                return Err(OverlapError::UnknownJoint { name: name.clone() });
            }
            check_factor(Some(name), factor)?;
        }
        Ok(())
    }

    /// The factor that applies to the boundary of the joint named `name`.
    pub fn factor_of(&self, name: &str) -> f64 {
        self.per_joint.get(name).copied().unwrap_or(self.factor)
    }
}

fn check_factor(joint: Option<&String>, value: f64) -> Result<(), OverlapError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(OverlapError::BadFactor {
            joint: joint.cloned(),
            value,
        })
    }
}

/// The overlap of every boundary of a decomposition.
#[derive(Debug, Clone, Default)]
pub struct Overlaps {
    /// #boundaries half-widths w = factor × D.
    pub half_widths: Vec<f64>,
    /// #boundaries surface distances from the cut curve within w (on both sides); empty
    /// for a soft boundary, whose signed plane distance is computed where it is used.
    pub bands: Vec<BandDistances>,
}

/// Half-widths of every boundary of `decomposition` (module documentation). Joint names
/// come from `skeleton`, which must be the decomposed one.
pub fn half_widths(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    params: &OverlapParams,
) -> Result<Vec<f64>, OverlapError> {
    params.validate(skeleton)?;
    decomposition
        .boundaries
        .iter()
        .map(|b| {
            let name =
                skeleton
                    .names
                    .get(b.joint as usize)
                    .ok_or(OverlapError::JointOutOfRange {
                        joint: b.joint,
                        count: skeleton.len(),
                    })?;
            Ok(params.factor_of(name) * b.diameter)
        })
        .collect()
}

/// Overlap bands of every boundary: half-widths and, for each cut, the geodesic distances
/// from its curve up to its half-width ([`march_distances`]), boundaries in parallel.
pub fn compute_overlaps(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    params: &OverlapParams,
) -> Result<Overlaps, OverlapError> {
    let half_widths = half_widths(decomposition, skeleton, params)?;
    let surface = &decomposition.surface;
    let vertex_count = surface.vertex_count();
    for b in &decomposition.boundaries {
        if let BoundaryKind::Cut { curve } = &b.kind {
            if let Some(&v) = curve.iter().find(|&&v| v as usize >= vertex_count) {
                return Err(OverlapError::CurveVertexOutOfRange {
                    joint: b.joint,
                    vertex: v,
                    count: vertex_count,
                });
            }
        }
    }
    let bands = decomposition
        .boundaries
        .par_iter()
        .zip(&half_widths)
        .map_init(
            || MarchScratch::new(vertex_count),
            |scratch, (boundary, &width)| match &boundary.kind {
                BoundaryKind::Cut { curve } => {
                    march_distances(surface, &decomposition.topology, curve, width, scratch)
                }
                BoundaryKind::Soft => BandDistances::default(),
            },
        )
        .collect();
    Ok(Overlaps { half_widths, bands })
}

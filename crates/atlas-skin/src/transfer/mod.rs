//! Skin weight transfer: the weights of a skinned surface (the *source*, a body) carried
//! onto other meshes in its rest space (the *targets*: clothes, hair, armour, props), after
//! *Robust Skin Weights Transfer via Weight Inpainting* (Abdrashitov, Raichstat, Monsen,
//! Hill, SIGGRAPH Asia 2023 Technical Communications, doi:10.1145/3610543.3626180).
//!
//! Copying the weights of the nearest source point everywhere (Blender's Data Transfer,
//! "nearest face interpolated") tears a garment where it hangs away from the body: a skirt
//! between the legs takes one leg's weights on one side and the other's on the other. The
//! method copies weights only where the garment lies on the body and fills in the rest by
//! the smoothest completion. On the welded target (seams joined), in order:
//!
//! 1. **Closest point matching** (§3.1, [`closest_point`]): every vertex p finds the nearest
//!    point q of the source surface; it is matched when |p − q| ≤ d and the angle between
//!    its normal and the source's interpolated normal at q is at most θ (or, with
//!    [`TransferParams::flipped_normals`], at least 180° − θ), and then takes the
//!    source's weights interpolated at q: w(p) = u w(a) + v w(b) + w w(c) over q's face
//!    abc. d is [`TransferParams::distance`] times the source's bounding-box diagonal
//!    (the paper's 5%, of the target's diagonal in its reference implementation; here of
//!    the source's, so that a small hat and a long coat are judged alike), θ = 30° by
//!    default.
//! 2. **Inpainting** (§3.2, [`inpaint`]): the other vertices' weights minimise
//!    tr(Wᵀ Q W), Q = −L + D² L M⁻¹ L (cotangent Laplacian L, Voronoi mass M:
//!    [`cotangent`]; D the source's bounding-box diagonal, so that the energy does not
//!    depend on the file's units), with the matched rows fixed: Q_uu W_u = −Q_uk W_k,
//!    solved by a sparse Cholesky factorisation (faer). Each connected piece of the target is solved
//!    on its own. Negative weights (the energy does not bound them) are dropped and the
//!    rows rescaled to sum to 1.
//! 3. **A piece with no matched vertex** (a button floating over a coat, a prop held away
//!    from the hand) has nothing to inpaint from: it is bound, whole, to the source's
//!    weights at the point where it comes nearest to the source (its vertex of smallest
//!    |p − q|), and the result says so ([`PieceSummary::bound_to_nearest`]).
//! 4. **Smoothing** near the seam between matched and inpainted weights (§3.3, optional:
//!    [`smooth`]), [`TransferParams::smooth_iterations`] rounds of
//!    w_i ← (1 − α) w_i + α · mean of the neighbours' rows, on the inpainted vertices and
//!    those within d of one along the surface.
//!
//! Weights are then written back per stored vertex (a stored vertex no triangle uses takes
//! the source's weights at its nearest point). Every row sums to 1, its weights sorted
//! from the largest; the caller keeps as many influences as it writes.
//!
//! A target that lies nowhere near the source (no vertex within d of it), or is more than
//! [`MAX_SIZE_RATIO`] times its size (another unit or space), is refused with
//! [`TransferError`], as are an empty mesh and a source without weights.

pub mod closest_point;
pub mod cotangent;
pub mod inpaint;
pub mod row_scratch;
pub mod smooth;

pub use closest_point::TransferSource;

use crate::mesh::spatial_index::morton_order;
use crate::mesh::weld::{DEFAULT_WELD_TOLERANCE, UNREFERENCED};
use crate::mesh::{weld, Topology};
use atlas_skin_runtime::VertexWeights;
use closest_point::{matches, merge_joints, normalise, Closest};
use cotangent::Operators;
use glam::Vec3;
use inpaint::{InpaintError, System, FIXED};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use thiserror::Error;

/// A target more than this many times the source's bounding-box diagonal is taken to be
/// in another space (centimetres against metres, say) and refused.
pub const MAX_SIZE_RATIO: f64 = 5.0;

/// Weights below this are dropped from a transferred row before it is rescaled.
pub const SMALLEST_WEIGHT: f64 = 1e-6;

/// Why a transfer failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum TransferError {
    #[error("invalid transfer settings: {0}")]
    Settings(String),
    #[error("the source has no triangles")]
    EmptySource,
    #[error("the target has no triangles")]
    EmptyTarget,
    #[error("the source's weights are unusable: {0}")]
    SourceWeights(String),
    #[error("{found} positions, but the triangles use vertex {vertex}")]
    TriangleVertexOutOfRange { vertex: u32, found: usize },
    #[error(
        "no vertex lies within {threshold:.4} of the source's surface (the nearest is \
         {nearest:.4} away): is it placed in the source's rest space, in the same units?"
    )]
    NotNear { nearest: f64, threshold: f64 },
    #[error(
        "it is {ratio:.1} times the size of the source (bounding-box diagonals {target:.4} \
         and {source_size:.4}): is it in the source's units and rest space?"
    )]
    MismatchedSize {
        ratio: f64,
        target: f64,
        source_size: f64,
    },
    #[error(transparent)]
    Inpaint(#[from] InpaintError),
}

/// The settings of a transfer (the paper's defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TransferParams {
    /// Matching distance d, as a fraction of the source's bounding-box diagonal (> 0).
    pub distance: f64,
    /// Matching angle θ between normals, in degrees (0 to 90).
    pub angle_degrees: f64,
    /// Also match where the target's normal points against the source's (within θ of the
    /// opposite way): for a single-sided garment wound the other way. Off by default: a
    /// vertex facing the source across a gap (the inner side of a sleeve facing the
    /// chest, teeth and eyes inside the head) would take the weights of a surface it does
    /// not lie on.
    pub flipped_normals: bool,
    /// Rounds of smoothing near the inpainted vertices (0: none).
    pub smooth_iterations: usize,
    /// Smoothing strength α per round (0 to 1).
    pub smooth_alpha: f64,
}

impl Default for TransferParams {
    fn default() -> Self {
        Self {
            distance: 0.05,
            angle_degrees: 30.0,
            flipped_normals: false,
            smooth_iterations: 10,
            smooth_alpha: 0.2,
        }
    }
}

impl TransferParams {
    /// Checks every setting's range.
    pub fn validate(&self) -> Result<(), TransferError> {
        if !(self.distance > 0.0 && self.distance.is_finite()) {
            return Err(TransferError::Settings(format!(
                "the matching distance must be positive, not {}",
                self.distance
            )));
        }
        if !(0.0..=90.0).contains(&self.angle_degrees) {
            return Err(TransferError::Settings(format!(
                "the matching angle must be between 0 and 90 degrees, not {}",
                self.angle_degrees
            )));
        }
        if !(0.0..=1.0).contains(&self.smooth_alpha) {
            return Err(TransferError::Settings(format!(
                "the smoothing strength must be between 0 and 1, not {}",
                self.smooth_alpha
            )));
        }
        Ok(())
    }
}

/// How a vertex got its weights.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexSource {
    /// From the source's surface at its closest point (§3.1).
    Matched,
    /// By inpainting (§3.2), smoothed or not.
    Inpainted,
    /// From the source where its piece (or the vertex, unused by triangles) comes nearest.
    Nearest,
}

impl VertexSource {
    /// The name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            VertexSource::Matched => "matched",
            VertexSource::Inpainted => "inpainted",
            VertexSource::Nearest => "nearest",
        }
    }
}

/// One connected piece of a target (welded).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PieceSummary {
    /// Welded vertices.
    pub vertices: usize,
    pub matched: usize,
    pub inpainted: usize,
    /// No vertex matched: bound whole to the source where it comes nearest.
    pub bound_to_nearest: bool,
    /// Its smallest distance to the source's surface.
    pub nearest_distance: f64,
}

/// Vertex counts of a transfer.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TransferCounts {
    pub stored_vertices: usize,
    pub welded_vertices: usize,
    /// Welded vertices by how they got their weights.
    pub matched: usize,
    pub inpainted: usize,
    pub nearest: usize,
    /// Inpainted vertices whose solved row had no positive weight (cut off from every
    /// matched vertex by zero-area faces): they copy the nearest weighted vertex along the
    /// edges.
    pub filled_along_edges: usize,
    /// Vertices the smoothing rounds changed.
    pub smoothed: usize,
    /// Stored vertices no triangle uses.
    pub unreferenced_stored_vertices: usize,
}

/// The weights of one target.
#[derive(Debug, Clone)]
pub struct Transferred {
    /// One row per stored target vertex, summing to 1, largest weight first.
    pub weights: VertexWeights,
    /// Per stored target vertex.
    pub vertex_sources: Vec<VertexSource>,
    /// The connected pieces of the welded target, by first vertex.
    pub pieces: Vec<PieceSummary>,
    pub counts: TransferCounts,
    /// The matching distance d in the source's units.
    pub distance: f64,
}

/// Transfers `source`'s weights onto the target mesh of stored `positions` and
/// `triangles` (the module's steps).
///
/// # Errors
/// See [`TransferError`]: settings, an empty target, a triangle index out of range, a
/// target nowhere near the source or of another size, a system that cannot be factored.
pub fn transfer_weights(
    source: &TransferSource,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    params: &TransferParams,
) -> Result<Transferred, TransferError> {
    params.validate()?;
    if triangles.is_empty() {
        return Err(TransferError::EmptyTarget);
    }
    let found = positions.len();
    if let Some(&vertex) = triangles.iter().flatten().find(|&&v| v as usize >= found) {
        return Err(TransferError::TriangleVertexOutOfRange { vertex, found });
    }
    let welded = weld(positions, triangles, DEFAULT_WELD_TOLERANCE);
    let mesh = &welded.mesh;
    let (source_size, target_size) = (source.diagonal(), mesh.diagonal());
    if target_size > MAX_SIZE_RATIO * source_size {
        return Err(TransferError::MismatchedSize {
            ratio: target_size / source_size,
            target: target_size,
            source_size,
        });
    }
    let topology = Topology::new(mesh);
    let normals = mesh.vertex_normals();
    let distance = params.distance * source_size;
    let min_cos = params.angle_degrees.to_radians().cos();

    // §3.1: the closest points, the vertices taken in Morton order (near each other in
    // space, whatever the stored order), in chunks whose queries start from the previous
    // vertex's face: the same points, found sooner (FaceSpheres::nearest_point_from).
    let order = morton_order(&mesh.positions);
    let in_order: Vec<Closest> = order
        .par_chunks(1024)
        .flat_map_iter(|chunk| {
            let mut hint = None;
            chunk
                .iter()
                .map(|&v| {
                    let c = source.closest(mesh.positions[v as usize], hint);
                    hint = Some(c.point.face);
                    c
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let mut closest = vec![in_order[0]; in_order.len()];
    for (&v, c) in order.iter().zip(&in_order) {
        closest[v as usize] = *c;
    }
    let nearest = closest
        .iter()
        .map(|c| c.point.distance)
        .fold(f64::INFINITY, f64::min);
    if nearest > distance {
        return Err(TransferError::NotNear {
            nearest,
            threshold: distance,
        });
    }
    let mut rows: Vec<Vec<(u32, f64)>> = closest
        .par_iter()
        .zip(&normals)
        .map(|(c, &n)| {
            let mut row = Vec::new();
            if matches(c, n, distance, min_cos, params.flipped_normals) {
                source.weights_at(c, &mut row);
            }
            row
        })
        .collect();
    let matched: Vec<bool> = rows.iter().map(|r| !r.is_empty()).collect();

    // Pieces: vertices by component.
    let n = mesh.vertex_count();
    let members = crate::rows::Rows::group(
        topology.component_count,
        (0..n).map(|v| (topology.vertex_component[v] as usize, v as u32)),
    );
    let operators = Operators::new(mesh, &topology);
    let mut sources = vec![VertexSource::Matched; n];
    let mut pieces = Vec::with_capacity(topology.component_count);
    let mut slot = vec![FIXED; n];
    let mut local_rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
    for piece in 0..topology.component_count {
        let vertices = members.row(piece);
        let nearest_vertex = vertices
            .iter()
            .copied()
            .min_by(|&a, &b| {
                closest[a as usize]
                    .point
                    .distance
                    .total_cmp(&closest[b as usize].point.distance)
            })
            .expect("a component has a vertex");
        let matched_count = vertices.iter().filter(|&&v| matched[v as usize]).count();
        let mut summary = PieceSummary {
            vertices: vertices.len(),
            matched: matched_count,
            inpainted: vertices.len() - matched_count,
            bound_to_nearest: false,
            nearest_distance: closest[nearest_vertex as usize].point.distance,
        };
        if matched_count == 0 {
            let mut row = Vec::new();
            source.weights_at(&closest[nearest_vertex as usize], &mut row);
            for &v in vertices {
                rows[v as usize].clone_from(&row);
                sources[v as usize] = VertexSource::Nearest;
            }
            summary.inpainted = 0;
            summary.bound_to_nearest = true;
        } else if matched_count < vertices.len() {
            inpaint_piece(
                &operators,
                source_size,
                vertices,
                &matched,
                &mut rows,
                &mut slot,
                &mut local_rows,
            )?;
            for &v in vertices.iter().filter(|&&v| !matched[v as usize]) {
                sources[v as usize] = VertexSource::Inpainted;
            }
        }
        pieces.push(summary);
    }
    let filled_along_edges = fill_along_edges(&topology, &mut rows);

    let inpainted: Vec<bool> = sources
        .iter()
        .map(|&s| s == VertexSource::Inpainted)
        .collect();
    let mut smoothed = 0;
    if params.smooth_iterations > 0 && inpainted.contains(&true) {
        let zone = smooth::zone(mesh, &topology, &inpainted, distance);
        let before: Vec<Vec<(u32, f64)>> = rows.clone();
        smooth::smooth(
            &topology,
            &zone,
            &mut rows,
            source.joint_count,
            params.smooth_iterations,
            params.smooth_alpha,
        );
        smoothed = (0..n)
            .filter(|&v| zone[v] && !same_row(&before[v], &rows[v]))
            .count();
    }

    let count = |kind: VertexSource| sources.iter().filter(|&&s| s == kind).count();
    let mut counts = TransferCounts {
        stored_vertices: positions.len(),
        welded_vertices: n,
        matched: count(VertexSource::Matched),
        inpainted: count(VertexSource::Inpainted),
        nearest: count(VertexSource::Nearest),
        filled_along_edges,
        smoothed,
        unreferenced_stored_vertices: 0,
    };
    let mut scratch = Vec::new();
    let mut stored_sources = Vec::with_capacity(positions.len());
    let weights = VertexWeights::from_rows(welded.welded_of_stored.iter().zip(positions).map(
        |(&w, &p)| {
            let row = if w == UNREFERENCED {
                counts.unreferenced_stored_vertices += 1;
                stored_sources.push(VertexSource::Nearest);
                let closest = source.closest(p.as_dvec3(), None);
                source.weights_at(&closest, &mut scratch);
                &scratch
            } else {
                stored_sources.push(sources[w as usize]);
                &rows[w as usize]
            };
            output_row(row)
        },
    ));
    Ok(Transferred {
        weights,
        vertex_sources: stored_sources,
        pieces,
        counts,
        distance,
    })
}

/// Inpaints the unmatched vertices of one piece (§3.2) into `rows`, with the energy's
/// `length` D ([`System::length`]); `slot` and `local_rows` are #V scratch, left as found
/// (`FIXED`, empty).
fn inpaint_piece(
    operators: &Operators,
    length: f64,
    vertices: &[u32],
    matched: &[bool],
    rows: &mut [Vec<(u32, f64)>],
    slot: &mut [u32],
    local_rows: &mut [Vec<(u32, f64)>],
) -> Result<(), InpaintError> {
    // The piece's joints, numbered in ascending order: the solution's columns.
    let mut joints: Vec<u32> = vertices
        .iter()
        .filter(|&&v| matched[v as usize])
        .flat_map(|&v| rows[v as usize].iter().map(|&(j, _)| j))
        .collect();
    joints.sort_unstable();
    joints.dedup();
    let column = |j: u32| joints.binary_search(&j).expect("a joint of the piece") as u32;
    let unknown: Vec<u32> = vertices
        .iter()
        .copied()
        .filter(|&v| !matched[v as usize])
        .collect();
    for (k, &v) in unknown.iter().enumerate() {
        slot[v as usize] = k as u32;
    }
    for &v in vertices.iter().filter(|&&v| matched[v as usize]) {
        local_rows[v as usize] = rows[v as usize]
            .iter()
            .map(|&(j, w)| (column(j), w))
            .collect();
    }
    let system = System {
        operators,
        unknown: &unknown,
        slot,
        columns: joints.len(),
        length,
    };
    let solution = system.solve(&|j| local_rows[j].as_slice());
    for &v in vertices {
        slot[v as usize] = FIXED;
        local_rows[v as usize] = Vec::new();
    }
    let solution = solution?;
    for (k, &v) in unknown.iter().enumerate() {
        let values = &solution[k * joints.len()..(k + 1) * joints.len()];
        let row = &mut rows[v as usize];
        row.clear();
        row.extend(joints.iter().zip(values).map(|(&j, &w)| (j, w)));
        normalise(row);
    }
    Ok(())
}

/// Gives every empty row the row of the nearest vertex with one along the edges (breadth
/// first from all of them at once); returns how many rows it filled.
fn fill_along_edges(topology: &Topology, rows: &mut [Vec<(u32, f64)>]) -> usize {
    let mut queue: VecDeque<u32> = (0..rows.len() as u32)
        .filter(|&v| !rows[v as usize].is_empty())
        .collect();
    let mut filled = 0;
    while let Some(v) = queue.pop_front() {
        for &u in topology.neighbors(v as usize) {
            if rows[u as usize].is_empty() {
                rows[u as usize] = rows[v as usize].clone();
                filled += 1;
                queue.push_back(u);
            }
        }
    }
    filled
}

fn same_row(a: &[(u32, f64)], b: &[(u32, f64)]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.0 == y.0 && (x.1 - y.1).abs() <= 1e-12)
}

/// A row as written: weights of at least [`SMALLEST_WEIGHT`], rescaled to sum to 1,
/// largest first (ties by joint).
fn output_row(row: &[(u32, f64)]) -> Vec<(u32, f32)> {
    let mut kept: Vec<(u32, f64)> = row
        .iter()
        .copied()
        .filter(|&(_, w)| w >= SMALLEST_WEIGHT)
        .collect();
    merge_joints(&mut kept);
    normalise(&mut kept);
    kept.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    kept.into_iter().map(|(j, w)| (j, w as f32)).collect()
}

#[cfg(test)]
mod tests;

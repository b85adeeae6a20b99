//! Skinning weights from a decomposition (Lu et al. 2008, §4 and §5), with the extensions
//! METHOD.md measured: soft boundaries with weights that change along the chain inside a
//! region, and weights for every vertex.
//!
//! For a vertex p of the split surface:
//!
//! 1. **Related regions and depths.** A region V_i is related to p when p lies in V_i (a
//!    face of p belongs to it) or within the overlap band of one of V_i's cut curves. Its
//!    normalised depth ([`crate::weights::blend`]) is, with g_k the surface distance from p to the
//!    curve of boundary k and w_k its overlap half-width ([`crate::overlap`]):
//!    λ_i = min_k (w_k + g_k) / (2 w_k) when p lies in V_i (∞ when no band reaches p),
//!    λ_i = max_k (w_k − g_k) / (2 w_k) when it does not (k over V_i's cuts reaching p).
//!    Both give ½ on a curve, so λ_i is continuous across it; regions with λ_i ≤ 0 are not
//!    related.
//! 2. **Blend** the related regions: ω_i from the λ_i by [`blend_regions`].
//! 3. **Chain weights inside a region.** A region is bound to its first joint; each other
//!    joint of the region with a soft boundary also moves part of it. Joint c's soft boundary
//!    (plane point o_c, normal n_c toward its child, half-width w_c) gives
//!    s_c(p) = max(β(clamp((w_c + n_c·(p − o_c)) / (2 w_c), 0, 1)), π_c(p)) · κ_c(p) on its
//!    child side and 0 elsewhere. κ_c ([`crate::weights::ownership`]) keeps the joint on its own
//!    part: with a(p) the distance from p to the nearest of the joint's own bones (its child
//!    bones and every bone below them) and b(p) to the nearest other bone of the region
//!    (bones of joints whose bone lies in it, except the joint's own upper bone, which meets
//!    its child bones at the joint), κ_c(p) = β(clamp(1 − (a − b) / w_c, 0, 1)), and 1 when
//!    the region has no other bone. It is 1 wherever the own bones are the nearer and falls
//!    to 0 within one half-width past the surface equidistant from both, as a cut's weight
//!    falls within its overlap band: a plane whose child side holds a sibling's part (a
//!    jaw's, the front of the neck) leaves that part to the bones that run inside it.
//!    π_c, the same formula with the bones of c's descendants that have no boundary of
//!    their own as own bones and c's child bones plus the region's other bones as others,
//!    carries c's part past its plane where such a bone is the nearest: a chin that hangs
//!    below the plane of the head joint but lies on the jaw bone moves with the head.
//!    The region's joints form a tree (each soft joint under its nearest ancestor among
//!    them, the bound joint at the root). Visiting the nodes parents first, the children c
//!    of a node take, with S = Σ_c s_c, the share min(1, S) of the mass of every node on
//!    the chain from the root to that node; child c receives the pooled amount times
//!    s_c / max(1, S). Taking from the whole chain rather than the node alone lets the
//!    head take the chin from the neck where the upper neck's plane does not reach it, and
//!    a shoulder take its arm from the spine where the chest's plane, beside it, does not.
//!    Masses are non-negative, sum to the region's weight ω, and are continuous.
//!
//!    The child side is not a half-space: it is the set of vertices reached *along the
//!    surface* from the joint's own cross-section (vertices within the plane's band and
//!    near the joint) without crossing the far edge of the band (n_c·(p − o_c) ≤ −w_c)
//!    where π_c = 0, leaving the region and its overlaps, or reaching κ_c = 0. A plane
//!    through a shoulder therefore never reaches a thigh that the hand touches, and a soft
//!    boundary acts only inside its own region: the surface-distance guarantee of §3.3
//!    holds for soft boundaries too (κ_c and π_c, Euclidean nearest-bone tests, only ever
//!    remove vertices from the flood or extend it within the region, never across a
//!    region's edge). A soft boundary with no cross-section near its joint is inactive
//!    (see `soft_sides`).
//!
//!    **3b. Leaf patches.** A leaf bone with a stated tail and no active boundary (a face
//!    bone lying in the skin) takes a share p_j of the region's weight at every vertex of
//!    its patch ([`crate::weights::patches`]): with P = Σ_j p_j over the region's patches, every
//!    joint of the region keeps its mass times 1 − min(1, P), and patch j receives
//!    ω p_j / max(1, P).
//! 4. **Fallback.** A vertex that no region with joints reaches (a loose piece, a
//!    degenerate bit, a region without joints) copies the weights of the nearest weighted
//!    vertex along the surface's edges (Dijkstra) when its component has one, and is bound
//!    to the nearest bone segment otherwise ([`crate::skeleton::bones`]).

pub mod blend;
pub mod ownership;
pub mod patches;

use crate::decomposition::{BoundaryKind, Decomposition};
use crate::mesh::edge_distance::EdgeDistances;
use crate::overlap::geodesic::BandDistances;
use crate::overlap::Overlaps;
use crate::rows::Rows;
use crate::skeleton::bones::{bone_segments, nearest_bone};
use atlas_skin_runtime::Skeleton;
use blend::{beta, blend_regions, Blend};
use glam::DVec3;
use ownership::Ownership;
use patches::{leaf_patches, Patch};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::VecDeque;
use thiserror::Error;

/// Vertices per parallel work item.
const CHUNK: usize = 2048;

/// What can be wrong with the inputs of the weights stage.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum WeightsError {
    #[error("the decomposition refers to joint {joint}, the skeleton has {count} joints")]
    JointOutOfRange { joint: u32, count: usize },
    #[error(
        "the decomposition has {decomposition} joint decisions, the skeleton {skeleton} joints"
    )]
    SkeletonMismatch {
        decomposition: usize,
        skeleton: usize,
    },
    #[error("the decomposition refers to region {region}, it has {count} regions")]
    RegionOutOfRange { region: u32, count: usize },
    #[error("an overlap band holds vertex {vertex}, the surface has {count}")]
    BandVertexOutOfRange { vertex: u32, count: usize },
    #[error("{what}: {found} entries, expected {expected}")]
    LengthMismatch {
        what: &'static str,
        found: usize,
        expected: usize,
    },
}

/// Weights of every vertex of the split surface, in compressed rows like
/// [`VertexWeights`]: vertex v's (joint, weight) pairs are at `offsets[v]..offsets[v + 1]`,
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

    fn extend_row(&mut self, row: impl IntoIterator<Item = (u32, f64)>) {
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
    /// Of those, vertices weighted from the nearest weighted vertex along the surface.
    pub from_surface: usize,
    /// Of those, vertices bound to the nearest bone (no weighted vertex in their component).
    pub from_bone: usize,
    /// Joints whose soft boundary is inactive (no cross-section near the joint).
    pub inactive_soft_joints: Vec<u32>,
    /// Leaf joints that move a patch of skin (step 3b).
    pub leaf_patches: Vec<u32>,
}

/// Weights of every vertex of `decomposition.surface` (module documentation).
///
/// - `skeleton`: the decomposed skeleton (#J joints, one decision each).
/// - `overlaps`: from [`crate::overlap::compute_overlaps`] on the same decomposition.
pub fn compute_weights(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
    blend: Blend,
) -> Result<(SurfaceWeights, WeightCounts), WeightsError> {
    validate(decomposition, skeleton, overlaps)?;
    let vertex_count = decomposition.surface.vertex_count();
    let bands = vertex_bands(&overlaps.bands, vertex_count);
    let related = related_regions(decomposition, overlaps, &bands);
    let region_vertices = region_vertices(decomposition, &related);
    let softs = soft_sides(
        decomposition,
        skeleton,
        overlaps,
        &related,
        &region_vertices,
    );
    let active: Vec<bool> = decomposition
        .joints
        .iter()
        .enumerate()
        .map(|(j, decision)| {
            decision.boundary.is_some_and(|k| {
                decomposition.boundaries[k as usize].kind != BoundaryKind::Soft
                    || softs.iter().any(|s| s.joint as usize == j)
            })
        })
        .collect();
    let patches = leaf_patches(decomposition, skeleton, &active, &region_vertices);
    let trees = region_trees(decomposition, skeleton, &softs);
    let mut weights = blend_vertices(decomposition, &related, &softs, &patches, &trees, blend);
    let mut counts = fill_unweighted(decomposition, skeleton, &mut weights);
    counts.leaf_patches = patches.iter().map(|p| p.joint).collect();
    counts.inactive_soft_joints = decomposition
        .boundaries
        .iter()
        .filter(|b| b.kind == BoundaryKind::Soft && !softs.iter().any(|s| s.joint == b.joint))
        .map(|b| b.joint)
        .collect();
    Ok((weights, counts))
}

fn validate(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
) -> Result<(), WeightsError> {
    let d = decomposition;
    let length = |what, found, expected| {
        if found == expected {
            Ok(())
        } else {
            Err(WeightsError::LengthMismatch {
                what,
                found,
                expected,
            })
        }
    };
    if d.joints.len() != skeleton.len() {
        return Err(WeightsError::SkeletonMismatch {
            decomposition: d.joints.len(),
            skeleton: skeleton.len(),
        });
    }
    length(
        "face regions",
        d.face_region.len(),
        d.surface.triangle_count(),
    )?;
    length(
        "overlap widths",
        overlaps.half_widths.len(),
        d.boundaries.len(),
    )?;
    length("overlap bands", overlaps.bands.len(), d.boundaries.len())?;
    length(
        "topology vertices",
        d.topology.vertex_face_offsets.len().saturating_sub(1),
        d.surface.vertex_count(),
    )?;
    let region_count = d.regions.len();
    let region_ok = |region: u32| {
        if (region as usize) < region_count {
            Ok(())
        } else {
            Err(WeightsError::RegionOutOfRange {
                region,
                count: region_count,
            })
        }
    };
    let joint_ok = |joint: u32| {
        if (joint as usize) < skeleton.len() {
            Ok(())
        } else {
            Err(WeightsError::JointOutOfRange {
                joint,
                count: skeleton.len(),
            })
        }
    };
    for &r in &d.face_region {
        region_ok(r)?;
    }
    for b in &d.boundaries {
        region_ok(b.parent_region)?;
        region_ok(b.child_region)?;
        joint_ok(b.joint)?;
    }
    for r in &d.regions {
        for &j in &r.joints {
            joint_ok(j)?;
        }
    }
    for band in &overlaps.bands {
        if let Some(&v) = band
            .vertices
            .iter()
            .find(|&&v| v as usize >= d.surface.vertex_count())
        {
            return Err(WeightsError::BandVertexOutOfRange {
                vertex: v,
                count: d.surface.vertex_count(),
            });
        }
    }
    Ok(())
}

/// Per vertex, the (boundary, surface distance) of every cut band that reaches it.
fn vertex_bands(bands: &[BandDistances], vertex_count: usize) -> Rows<(u32, f64)> {
    let entries = bands.iter().enumerate().flat_map(|(k, band)| {
        band.vertices
            .iter()
            .zip(&band.distances)
            .map(move |(&v, &g)| (v as usize, (k as u32, g)))
    });
    Rows::group(vertex_count, entries)
}

/// Step 1: per vertex, the (region, λ) of its related regions that hold joints.
fn related_regions(
    decomposition: &Decomposition,
    overlaps: &Overlaps,
    bands: &Rows<(u32, f64)>,
) -> Rows<(u32, f64)> {
    let d = decomposition;
    Rows::par_build(d.surface.vertex_count(), CHUNK, |v, _: &mut (), out| {
        let start = out.len();
        for &f in d.topology.faces_of_vertex(v) {
            let region = d.face_region[f as usize];
            if !out[start..].iter().any(|&(r, _)| r == region) {
                out.push((region, f64::INFINITY));
            }
        }
        let inside = out.len();
        for &(k, g) in bands.row(v) {
            let boundary = &d.boundaries[k as usize];
            let w = overlaps.half_widths[k as usize].max(f64::MIN_POSITIVE);
            for region in [boundary.parent_region, boundary.child_region] {
                match out[start..].iter().position(|&(r, _)| r == region) {
                    Some(i) if start + i < inside => {
                        let depth = &mut out[start + i].1;
                        *depth = depth.min((w + g) / (2.0 * w));
                    }
                    Some(i) => {
                        let depth = &mut out[start + i].1;
                        *depth = depth.max((w - g) / (2.0 * w));
                    }
                    None => out.push((region, (w - g) / (2.0 * w))),
                }
            }
        }
        let mut keep = start;
        for i in start..out.len() {
            let (region, depth) = out[i];
            if depth > 0.0 && !d.regions[region as usize].joints.is_empty() {
                out[keep] = (region, depth);
                keep += 1;
            }
        }
        out.truncate(keep);
    })
}

/// A soft boundary, ready for step 3.
struct SoftSide {
    joint: u32,
    region: u32,
    point: DVec3,
    normal: DVec3,
    half_width: f64,
    /// Bit v set when vertex v is on the child side reached along the surface.
    reached: Vec<u64>,
    /// (κ_c, π_c) of every reached vertex, by increasing vertex.
    ownership: Vec<(u32, f64, f64)>,
}

impl SoftSide {
    /// s_c(p) of the module documentation.
    fn share(&self, v: usize, position: DVec3) -> f64 {
        if self.reached[v / 64] & (1 << (v % 64)) == 0 {
            return 0.0;
        }
        let (kappa, beyond) = self
            .ownership
            .binary_search_by_key(&(v as u32), |&(u, _, _)| u)
            .map_or((0.0, 0.0), |i| (self.ownership[i].1, self.ownership[i].2));
        let signed = self.normal.dot(position - self.point);
        let w = self.half_width.max(f64::MIN_POSITIVE);
        beta(((w + signed) / (2.0 * w)).clamp(0.0, 1.0)).max(beyond) * kappa
    }
}

/// Transpose of `related`: the vertices each region reaches, increasing.
fn region_vertices(decomposition: &Decomposition, related: &Rows<(u32, f64)>) -> Vec<Vec<u32>> {
    let mut region_vertices: Vec<Vec<u32>> = vec![Vec::new(); decomposition.regions.len()];
    for v in 0..decomposition.surface.vertex_count() {
        for &(r, _) in related.row(v) {
            region_vertices[r as usize].push(v as u32);
        }
    }
    region_vertices
}

/// Step 3's child sides: for each soft boundary, a flood along edges from the vertices of
/// the joint's cross-section (within the band |n·(p − o)| ≤ w and within max(D, w) of the
/// joint), through vertices related to the boundary's region whose signed plane distance
/// exceeds −w and where κ > 0 ([`Ownership`]). A soft boundary with no
/// cross-section (diameter 0, or no band vertex near the joint where κ > 0: face bones in
/// a mouth cavity or an eye socket) is inactive: its joint gets no weight and its region's
/// other joints keep it.
fn soft_sides(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
    related: &Rows<(u32, f64)>,
    region_vertices: &[Vec<u32>],
) -> Vec<SoftSide> {
    let d = decomposition;
    let positions = &d.surface.positions;
    let vertex_count = d.surface.vertex_count();
    let segments = bone_segments(skeleton);
    // Joints with a boundary of their own (a cut, or a soft boundary with a section): π_c
    // leaves their bones, and the bones below them, to them.
    let mut handled = vec![false; skeleton.len()];
    for b in &d.boundaries {
        if b.kind != BoundaryKind::Soft || b.diameter > 0.0 {
            handled[b.joint as usize] = true;
        }
    }
    d.boundaries
        .par_iter()
        .enumerate()
        .filter(|(_, b)| b.kind == BoundaryKind::Soft && b.diameter > 0.0)
        .filter_map(|(k, b)| {
            let half_width = overlaps.half_widths[k];
            let owner = Ownership::new(
                skeleton,
                &d.joints,
                &segments,
                b.joint as usize,
                b.parent_region,
                half_width,
            );
            let beyond = owner.beyond(skeleton, &segments, b.joint as usize, &handled);
            let signed = |v: usize| b.normal.dot(positions[v] - b.point);
            let in_region = |v: usize| related.row(v).iter().any(|&(r, _)| r == b.parent_region);
            // Every vertex is examined once: κ depends on the vertex alone.
            let words = vertex_count.div_ceil(64);
            let (mut examined, mut reached) = (vec![0u64; words], vec![0u64; words]);
            let mut ownership = Vec::new();
            let mut queue = VecDeque::new();
            let mut visit = |v: u32, queue: &mut VecDeque<u32>| {
                let (word, bit) = (v as usize / 64, 1u64 << (v % 64));
                if examined[word] & bit != 0 {
                    return;
                }
                examined[word] |= bit;
                if !in_region(v as usize) {
                    return;
                }
                let p = positions[v as usize];
                let side = signed(v as usize);
                // π_c matters only where the plane's own term is below 1.
                let past = if side < half_width { beyond.at(p) } else { 0.0 };
                if side <= -half_width && past <= 0.0 {
                    return;
                }
                let kappa = owner.at(p);
                if kappa > 0.0 {
                    reached[word] |= bit;
                    ownership.push((v, kappa, past));
                    queue.push_back(v);
                }
            };
            let seed_radius = b.diameter.max(half_width);
            for &v in &region_vertices[b.parent_region as usize] {
                let p = positions[v as usize];
                if p.distance(b.point) <= seed_radius && signed(v as usize) <= half_width {
                    visit(v, &mut queue);
                }
            }
            if queue.is_empty() {
                return None;
            }
            while let Some(v) = queue.pop_front() {
                for &u in d.topology.neighbors(v as usize) {
                    visit(u, &mut queue);
                }
            }
            ownership.sort_unstable_by_key(|&(v, _, _)| v);
            Some(SoftSide {
                joint: b.joint,
                region: b.parent_region,
                point: b.point,
                normal: b.normal,
                half_width,
                reached,
                ownership,
            })
        })
        .collect()
}

/// The joints of one region as a tree for step 3: node 0 is the bound joint, node i > 0
/// the soft boundary `softs[i − 1]`; nodes listed parents first.
#[derive(Debug, Default)]
struct RegionTree {
    joints: Vec<u32>,
    /// Index into the `softs` vector of every node after the root.
    softs: Vec<usize>,
    children: Vec<Vec<usize>>,
    /// Parent node of every node (0 for the root).
    parents: Vec<usize>,
    order: Vec<usize>,
}

fn region_trees(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    softs: &[SoftSide],
) -> Vec<RegionTree> {
    decomposition
        .regions
        .iter()
        .enumerate()
        .map(|(r, region)| {
            let Some(&bound) = region.joints.first() else {
                return RegionTree::default();
            };
            let mut tree = RegionTree {
                joints: vec![bound],
                ..RegionTree::default()
            };
            for (s, soft) in softs.iter().enumerate() {
                if soft.region as usize == r && soft.joint != bound {
                    tree.joints.push(soft.joint);
                    tree.softs.push(s);
                }
            }
            tree.children = vec![Vec::new(); tree.joints.len()];
            tree.parents = vec![0; tree.joints.len()];
            for node in 1..tree.joints.len() {
                let parent = skeleton
                    .ancestors(tree.joints[node] as usize)
                    .find_map(|a| tree.joints.iter().position(|&j| j as usize == a))
                    .unwrap_or(0);
                tree.children[parent].push(node);
                tree.parents[node] = parent;
            }
            tree.order = vec![0];
            let mut i = 0;
            while i < tree.order.len() {
                let node = tree.order[i];
                tree.order.extend(tree.children[node].iter().copied());
                i += 1;
            }
            tree
        })
        .collect()
}

/// Per vertex, the (patch, p_j) of every leaf patch holding it.
fn patch_shares(patches: &[Patch], vertex_count: usize) -> Rows<(u32, f64)> {
    let entries = patches.iter().enumerate().flat_map(|(k, patch)| {
        patch
            .shares
            .iter()
            .map(move |&(v, share)| (v as usize, (k as u32, share)))
    });
    Rows::group(vertex_count, entries)
}

/// Per-chunk working memory of [`blend_vertices`].
#[derive(Default)]
struct BlendScratch {
    depths: Vec<f64>,
    region_weights: Vec<f64>,
    mass: Vec<f64>,
}

/// Steps 2 and 3 for every vertex.
fn blend_vertices(
    decomposition: &Decomposition,
    related: &Rows<(u32, f64)>,
    softs: &[SoftSide],
    patches: &[Patch],
    trees: &[RegionTree],
    blend: Blend,
) -> SurfaceWeights {
    let patch_shares = patch_shares(patches, decomposition.surface.vertex_count());
    let positions = &decomposition.surface.positions;
    let rows = Rows::par_build(
        positions.len(),
        CHUNK,
        |v, scratch: &mut BlendScratch, out| {
            let regions = related.row(v);
            scratch.depths.clear();
            scratch.depths.extend(regions.iter().map(|&(_, l)| l));
            scratch.region_weights.clear();
            scratch.region_weights.resize(regions.len(), 0.0);
            blend_regions(blend, &scratch.depths, &mut scratch.region_weights);
            let start = out.len();
            for (&(r, _), &omega) in regions.iter().zip(&scratch.region_weights) {
                let tree = &trees[r as usize];
                let mass = &mut scratch.mass;
                mass.clear();
                mass.resize(tree.joints.len(), 0.0);
                mass[0] = omega;
                for &node in &tree.order {
                    let share = |c: usize| softs[tree.softs[c - 1]].share(v, positions[v]);
                    let total: f64 = tree.children[node].iter().map(|&c| share(c)).sum();
                    if total <= 0.0 {
                        continue;
                    }
                    // The children take their shares of the mass of the whole chain from the
                    // root to `node`.
                    let mut pool = 0.0;
                    let mut a = node;
                    loop {
                        pool += mass[a];
                        mass[a] *= 1.0 - total.min(1.0);
                        if a == 0 {
                            break;
                        }
                        a = tree.parents[a];
                    }
                    for &c in &tree.children[node] {
                        mass[c] = pool * share(c) / total.max(1.0);
                    }
                }
                // Step 3b: the leaf patches take their shares of every joint's mass alike.
                let in_region = patch_shares
                    .row(v)
                    .iter()
                    .filter(move |&&(k, _)| patches[k as usize].region == r);
                let patch_total: f64 = in_region.clone().map(|&(_, p)| p).sum();
                let keep = 1.0 - patch_total.min(1.0);
                let patch_masses = in_region
                    .map(|&(k, p)| (patches[k as usize].joint, omega * p / patch_total.max(1.0)));
                let joint_masses = tree
                    .joints
                    .iter()
                    .zip(mass.iter())
                    .map(|(&j, &m)| (j, m * keep));
                for (joint, m) in joint_masses.chain(patch_masses) {
                    if m <= 0.0 {
                        continue;
                    }
                    match out[start..].iter_mut().find(|(j, _)| *j == joint) {
                        Some(entry) => entry.1 += m,
                        None => out.push((joint, m)),
                    }
                }
            }
        },
    );
    let (joints, weights) = rows.values.into_iter().unzip();
    SurfaceWeights {
        offsets: rows.offsets,
        joints,
        weights,
    }
}

/// Step 4: gives every vertex without weights the weights of the nearest weighted vertex
/// along the edges, or of the nearest bone; returns the counts.
fn fill_unweighted(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    weights: &mut SurfaceWeights,
) -> WeightCounts {
    let n = weights.vertex_count();
    let empty = |v: usize| weights.offsets[v] == weights.offsets[v + 1];
    let unreachable = (0..n).filter(|&v| empty(v)).count();
    if unreachable == 0 {
        return WeightCounts::default();
    }
    // Every vertex without weights copies the row of its nearest weighted vertex along the
    // edges (multi-source Dijkstra from every weighted vertex).
    let positions = &decomposition.surface.positions;
    let mut nearest = EdgeDistances::new(n);
    nearest.search(
        &decomposition.surface,
        &decomposition.topology,
        (0..n).filter(|&v| !empty(v)).map(|v| v as u32),
        f64::INFINITY,
    );
    let segments = bone_segments(skeleton);
    let mut counts = WeightCounts {
        unreachable,
        ..WeightCounts::default()
    };
    let mut filled = SurfaceWeights {
        offsets: vec![0],
        ..SurfaceWeights::default()
    };
    for (v, &p) in positions.iter().enumerate().take(n) {
        if !empty(v) {
            filled.extend_row(weights.row(v));
        } else if let Some(source) = nearest.source(v as u32) {
            counts.from_surface += 1;
            filled.extend_row(weights.row(source as usize));
        } else {
            counts.from_bone += 1;
            filled.extend_row(nearest_bone(&segments, p).map(|j| (j, 1.0)));
        }
    }
    *weights = filled;
    counts
}

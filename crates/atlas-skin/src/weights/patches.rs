//! Skin patches of leaf bones that the decomposition cannot cut (weights, step 3b).
//!
//! A face rig (MakeHuman's, for one) ends its chains in short leaf bones lying in the
//! skin: a lip corner, an eyelid, a cheek. No closed section crosses such a bone, so it
//! gets no boundary and, without this step, no weight. When the skeleton file states
//! where the bone ends ([`Skeleton::tails`]), the leaf instead moves the patch of its
//! region around its tail t, where its bone meets the skin: with a(p) = |p − t| and r the
//! region's patch radius,
//!
//!   p_j(p) = β(clamp(1 − a(p) / r, 0, 1)) · κ_j(p),
//!
//! κ_j as in [`crate::weights::ownership`] with half-width r / 2, so that neighbouring patches and
//! the other bones of the region split the skin between them. The radius is
//! [`RADIUS_PER_SPACING`] times the median spacing of the region's leaf tails (the
//! distance from a tail to the nearest other joint or tail): a dense rig moves small
//! patches. The distance is taken to the tail, not to the whole bone: eye and eyelid
//! bones start together at the centre of the eye, and the socket around it is the
//! head's. The patch is the part of the region reached along the surface from the vertex
//! nearest to the tail through vertices with p_j > 0. A leaf without a stated tail (a
//! glTF `HeadTop_End`) never has a patch: its bone has no known extent.
//!
//! The radius factor [`RADIUS_PER_SPACING`] was fitted on makehuman, the one corpus rig with
//! such bones (docs/measurements.md).

use crate::decomposition::Decomposition;
use crate::mesh::Topology;
use crate::skeleton::bone_tree::{BoneTree, Keys, Split};
use crate::skeleton::bones::bone_segments;
use crate::weights::blend::beta;
use crate::weights::ownership::{Ownership, OwnershipBones};
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet, VecDeque};
use std::ops::ControlFlow;

/// Patch radius as a multiple of the median spacing of the region's leaf tails.
pub const RADIUS_PER_SPACING: f64 = 3.0;

/// The patch of one leaf joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Patch {
    pub joint: u32,
    /// The region whose weights the patch takes a share of.
    pub region: u32,
    /// (vertex, p_j) of every vertex of the patch, by increasing vertex.
    pub shares: Vec<(u32, f64)>,
}

impl Patch {
    /// p_j at vertex `v` (0 outside the patch).
    pub fn share(&self, v: usize) -> f64 {
        self.shares
            .binary_search_by_key(&(v as u32), |&(u, _)| u)
            .map_or(0.0, |i| self.shares[i].1)
    }
}

/// The patches of every leaf joint of `skeleton` that has a tail, a region, skin of its
/// own (not forbidden, not outside the mesh) and no active boundary (`active[j]` false),
/// over the vertices each region reaches (`region_vertices[r]`, increasing).
pub fn leaf_patches(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    active: &[bool],
    region_vertices: &[Vec<u32>],
) -> Vec<Patch> {
    let children = skeleton.children();
    let heads: Vec<DVec3> = skeleton
        .bind_positions()
        .iter()
        .map(|p| p.as_dvec3())
        .collect();
    let candidates: Vec<(usize, u32, DVec3)> = (0..skeleton.len())
        .filter_map(|j| {
            let decision = &decomposition.joints[j];
            let tail = skeleton.tails[j]?.as_dvec3();
            let usable = children[j].is_empty()
                && !active[j]
                && decision.owns_skin
                && tail.distance(heads[j]) > 0.0;
            usable.then_some((j, decision.region?, tail))
        })
        .collect();
    let radii = region_radii(skeleton, &heads, &candidates);
    let bones = OwnershipBones::new(skeleton, &decomposition.joints, &bone_segments(skeleton));
    let positions = &decomposition.surface.positions;
    // The vertices of each region with a patch in a tree: the seed of each patch by a
    // descent, not a scan of the region per leaf (a region with thousands of leaves).
    let mut patched: Vec<u32> = radii.keys().copied().collect();
    patched.sort_unstable();
    let trees: HashMap<u32, BoneTree> = patched
        .par_iter()
        .map(|&r| (r, vertex_tree(positions, &region_vertices[r as usize])))
        .collect();
    candidates
        .par_iter()
        .filter_map(|&(j, region, tail)| {
            let radius = *radii.get(&region)?;
            let seed = nearest_vertex(trees.get(&region)?, tail)?;
            let owner = Ownership::new(&bones, j, region, 0.5 * radius);
            let share = |p: DVec3| {
                let a = p.distance(tail);
                if a >= radius {
                    return 0.0;
                }
                beta(1.0 - a / radius) * owner.at(p)
            };
            let shares = flood(
                positions,
                &decomposition.topology,
                &region_vertices[region as usize],
                seed,
                share,
            );
            (!shares.is_empty()).then_some(Patch {
                joint: j as u32,
                region,
                shares,
            })
        })
        .collect()
}

/// The patch radius of every region with candidates: [`RADIUS_PER_SPACING`] times the
/// median, over the region's candidates (joint, region, tail), of the distance from the
/// tail to the nearest position or tail of another joint. A dense rig (a face) moves
/// small patches, a sparse one large ones.
fn region_radii(
    skeleton: &Skeleton,
    heads: &[DVec3],
    candidates: &[(usize, u32, DVec3)],
) -> HashMap<u32, f64> {
    let mut spacings: HashMap<u32, Vec<f64>> = HashMap::new();
    if candidates.is_empty() {
        return HashMap::new();
    }
    // Every joint's position and tail as points keyed by the joint: the nearest of another
    // joint by a descent, not a scan of every joint per leaf.
    let points = BoneTree::new(
        (0..skeleton.len()).flat_map(|k| {
            let key = k as u32;
            std::iter::once((key, heads[k], heads[k]))
                .chain(skeleton.tails[k].map(|t| (key, t.as_dvec3(), t.as_dvec3())))
        }),
        Split::Space,
    );
    for &(j, region, tail) in candidates {
        let j = j as u32;
        let spacing = points.nearest_distance(tail, Keys::Outside(j, j + 1), |_, _| true);
        if spacing.is_finite() {
            spacings.entry(region).or_default().push(spacing);
        }
    }
    spacings
        .into_iter()
        .map(|(region, mut s)| {
            s.sort_unstable_by(f64::total_cmp);
            (region, RADIUS_PER_SPACING * s[s.len() / 2])
        })
        .collect()
}

/// The vertices `vertices` as points keyed by their index, in a tree.
fn vertex_tree(positions: &[DVec3], vertices: &[u32]) -> BoneTree {
    BoneTree::new(
        vertices.iter().map(|&v| {
            let p = positions[v as usize];
            (v, p, p)
        }),
        Split::Space,
    )
}

/// The vertex of `tree` ([`vertex_tree`]) nearest to `p`, the smallest index among equally
/// near ones; `None` for an empty tree.
fn nearest_vertex(tree: &BoneTree, p: DVec3) -> Option<u32> {
    let mut nearest: Option<(f64, u32)> = None;
    let _: ControlFlow<()> = tree.visit_nearest_first(p, f64::INFINITY, |v, d| match nearest {
        Some((best, _)) if d > best => ControlFlow::Break(()),
        Some((best, w)) if d == best && v > w => ControlFlow::Continue(()),
        _ => {
            nearest = Some((d, v));
            ControlFlow::Continue(())
        }
    });
    nearest.map(|(_, v)| v)
}

/// The vertices reached along edges from `seed` through vertices of `allowed` with
/// `share > 0`, with their shares, by increasing vertex.
fn flood(
    positions: &[DVec3],
    topology: &Topology,
    allowed: &[u32],
    seed: u32,
    share: impl Fn(DVec3) -> f64,
) -> Vec<(u32, f64)> {
    let mut seen = HashSet::new();
    let mut shares = Vec::new();
    let mut queue = VecDeque::from([seed]);
    seen.insert(seed);
    while let Some(v) = queue.pop_front() {
        let s = share(positions[v as usize]);
        if s <= 0.0 {
            continue;
        }
        shares.push((v, s));
        for &u in topology.neighbors(v as usize) {
            if allowed.binary_search(&u).is_ok() && seen.insert(u) {
                queue.push_back(u);
            }
        }
    }
    shares.sort_unstable_by_key(|&(v, _)| v);
    shares
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic scatter of points in the unit cube, with repeats (ties).
    fn scatter(n: usize) -> Vec<DVec3> {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut points: Vec<DVec3> = (0..n).map(|_| DVec3::new(next(), next(), next())).collect();
        for k in (0..n).step_by(7) {
            points[k] = points[k / 2];
        }
        points
    }

    #[test]
    fn the_nearest_vertex_from_the_tree_is_the_scan_s_first_nearest() {
        let positions = scatter(600);
        let vertices: Vec<u32> = (0..600).filter(|v| v % 3 != 1).collect();
        let tree = vertex_tree(&positions, &vertices);
        for p in scatter(200).into_iter().chain(positions.iter().copied()) {
            let scan = vertices.iter().copied().min_by(|&a, &b| {
                p.distance(positions[a as usize])
                    .total_cmp(&p.distance(positions[b as usize]))
            });
            assert_eq!(nearest_vertex(&tree, p), scan, "{p}");
        }
        assert_eq!(
            nearest_vertex(&vertex_tree(&positions, &[]), DVec3::ZERO),
            None
        );
    }
}

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
use crate::skeleton::bones::bone_segments;
use crate::weights::blend::beta;
use crate::weights::ownership::{Ownership, OwnershipBones};
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{HashMap, HashSet, VecDeque};

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
    candidates
        .par_iter()
        .filter_map(|&(j, region, tail)| {
            let radius = *radii.get(&region)?;
            let owner = Ownership::new(&bones, j, region, 0.5 * radius);
            let share = |p: DVec3| {
                let a = p.distance(tail);
                if a >= radius {
                    return 0.0;
                }
                beta(1.0 - a / radius) * owner.at(p)
            };
            let shares = flood(
                &decomposition.surface.positions,
                &decomposition.topology,
                &region_vertices[region as usize],
                |p| p.distance(tail),
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
    for &(j, region, tail) in candidates {
        let others = (0..skeleton.len())
            .filter(|&k| k != j)
            .flat_map(|k| std::iter::once(heads[k]).chain(skeleton.tails[k].map(|t| t.as_dvec3())));
        let spacing = others
            .map(|p| p.distance(tail))
            .fold(f64::INFINITY, f64::min);
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

/// The vertices reached along edges from the vertex of `allowed` nearest to the bone
/// (by `distance`) through vertices of `allowed` with `share > 0`, with their shares, by
/// increasing vertex.
fn flood(
    positions: &[DVec3],
    topology: &Topology,
    allowed: &[u32],
    distance: impl Fn(DVec3) -> f64,
    share: impl Fn(DVec3) -> f64,
) -> Vec<(u32, f64)> {
    let Some(&seed) = allowed.iter().min_by(|&&a, &&b| {
        distance(positions[a as usize]).total_cmp(&distance(positions[b as usize]))
    }) else {
        return Vec::new();
    };
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

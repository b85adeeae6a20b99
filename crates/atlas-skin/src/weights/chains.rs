//! Steps 2, 3 and 3b of the weights for every vertex: the related regions blended (§4),
//! each region's weight shared along the chain of its joints (soft boundaries) and with its
//! leaf patches (module documentation of [`crate::weights`]).

use super::blend::{blend_regions, Blend};
use super::patches::Patch;
use super::soft_sides::SoftSide;
use super::surface_weights::SurfaceWeights;
use crate::decomposition::Decomposition;
use crate::rows::{Rows, PAR_CHUNK};
use atlas_skin_runtime::Skeleton;

/// The joints of one region as a tree for step 3: node 0 is the bound joint, node i > 0
/// the soft boundary `softs[i − 1]`; nodes listed parents first.
#[derive(Debug, Default)]
pub struct RegionTree {
    joints: Vec<u32>,
    /// Index into the `softs` vector of every node after the root.
    softs: Vec<usize>,
    children: Vec<Vec<usize>>,
    /// Parent node of every node (0 for the root).
    parents: Vec<usize>,
    order: Vec<usize>,
}

pub fn region_trees(
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
pub fn blend_vertices(
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
        PAR_CHUNK,
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
                share_along_chain(
                    tree,
                    |c| softs[tree.softs[c - 1]].share(v, positions[v]),
                    omega,
                    mass,
                );
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

/// Step 3 at one vertex: the region's weight `omega` shared among the joints of its `tree`
/// (module documentation of [`crate::weights`]); `share(c)` is s_c of node c > 0. Fills
/// `mass` with one mass per node, non-negative and summing to `omega`.
fn share_along_chain(
    tree: &RegionTree,
    share: impl Fn(usize) -> f64,
    omega: f64,
    mass: &mut Vec<f64>,
) {
    mass.clear();
    mass.resize(tree.joints.len(), 0.0);
    mass[0] = omega;
    for &node in &tree.order {
        let total: f64 = tree.children[node].iter().map(|&c| share(c)).sum();
        if total <= 0.0 {
            continue;
        }
        // The children take their shares of the mass of the whole chain from the root to
        // `node`.
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
}

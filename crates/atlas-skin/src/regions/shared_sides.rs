//! Regions on the child side of several cuts, divided among them (an extension of Lu et al.
//! 2008 §3.2 to surfaces of higher genus).
//!
//! A cut's loop separates its child side from its parent side along the limb, but the
//! surface may join the child side to another part elsewhere: a hand fused to the hip, a
//! sleeve welded to the hand past the wrist, a tongue welded to the floor of the mouth.
//! Growing regions then joins the child sides of two cuts into one region, which binds to
//! one of the two joints and carries the other's part with it (the whole thigh moving with
//! the hand). Such a region R, the child side of the cuts of joints c₁ … c_k, is divided
//! among the families of those cuts: cuts whose joints descend from one another form one
//! family, headed by its joint nearest the root, whose part the weights vary along as
//! along any chain of joints sharing a region; unrelated joints (a hand and a hip) form
//! separate families, and only a region of two families or more is divided:
//!
//! 1. Each face f of R is labelled with the family whose bones are nearest to its
//!    centroid x_f among the bones behind the face: argmin_i min { |q − x_f| : q the point
//!    of a segment of S_i nearest to x_f, n_f · (q − x_f) < 0 }, where n_f is the face's
//!    outward normal and S_i holds the bone segments ([`bone_segments`]) of family i's
//!    joints and of the joints below them up to the next cut joints (the bones that lie in
//!    their sides). Where two parts touch, the skin of one lies near the other's bones,
//!    but in front of them: the thigh's skin under a resting hand faces the hand's bones
//!    and has the thigh bone behind it. A face with no bone behind it takes the nearest of
//!    all.
//! 2. Each part is grown from its cuts: breadth first over the edges of R from the faces
//!    along the loops of family i, into faces labelled i (the faces along a loop belong to
//!    its family whatever their label), so that every part is connected and touches its
//!    own cuts.
//! 3. Faces that no part reached that way (a patch labelled i cut off from family i's
//!    part) join the part they reach first, breadth first from every part at once.
//!
//! The part of the family whose head comes first in the skeleton's topological order keeps
//! R's index; the others become new regions. The line between two parts is a hard seam:
//! the surface there joins parts that move with unrelated bones.
//!
//! Dividing among related cuts too (a forearm and its hand, a spine and the arms of a
//! chunky torso) was measured on the benchmark and not kept (docs/pieces.md).

use super::find_edge;
use crate::cuts::joint_roles::orientation_sign;
use crate::decomposition::SharedSide;
use crate::geometry::segment_parameter;
use crate::mesh::{SurfaceMesh, Topology};
use crate::rows::Rows;
use crate::skeleton::bones::bone_segments;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use std::collections::VecDeque;

/// A cut of joint `joint` whose child side is region `region`, with its loop.
pub struct ChildSide<'a> {
    pub joint: u32,
    pub region: u32,
    pub curve: &'a [u32],
}

const UNASSIGNED: u32 = u32::MAX;

/// Divides every region that is the child side of more than one of `sides` (module
/// documentation), renumbering `face_region` in place and adding the new regions after
/// `region_count`. `sides` lists every cut with its child region (the joints of `sides`
/// are where one cut's bones end). Returns the divided regions.
pub fn divide_shared_sides(
    mesh: &SurfaceMesh,
    topology: &Topology,
    skeleton: &Skeleton,
    face_region: &mut [u32],
    region_count: &mut usize,
    sides: &[ChildSide],
) -> Vec<SharedSide> {
    // The cuts by child region (a counting sort: every character passes here).
    let by_region = Rows::group(
        *region_count,
        sides
            .iter()
            .enumerate()
            .map(|(k, s)| (s.region as usize, k as u32)),
    );
    let shared: Vec<Vec<&ChildSide>> = (0..*region_count)
        .map(|r| by_region.row(r))
        .filter(|group| group.len() > 1)
        .map(|group| group.iter().map(|&k| &sides[k as usize]).collect())
        .collect();
    if shared.is_empty() {
        return Vec::new();
    }
    let order = skeleton.topological_order();
    let mut rank = vec![0usize; skeleton.len()];
    for (k, &j) in order.iter().enumerate() {
        rank[j] = k;
    }
    let mut has_cut = vec![false; skeleton.len()];
    for side in sides {
        has_cut[side.joint as usize] = true;
    }
    // The cut joint each joint's bones belong to: itself when it has a cut, else its
    // parent's.
    let mut owner: Vec<Option<u32>> = vec![None; skeleton.len()];
    for &j in &order {
        owner[j] = if has_cut[j] {
            Some(j as u32)
        } else {
            skeleton.parent(j).and_then(|p| owner[p])
        };
    }
    let segments = bone_segments(skeleton);
    let mut divided = Vec::new();
    for mut group in shared {
        group.sort_by_key(|s| rank[s.joint as usize]);
        // Cuts whose joints descend from one another share the region along their chain
        // (the weights vary along it): one family each, headed by the joint nearest the
        // root.
        let mut families: Vec<Vec<&ChildSide>> = Vec::new();
        for side in group {
            let related = |family: &Vec<&ChildSide>| {
                family.iter().any(|m| {
                    skeleton
                        .ancestors(side.joint as usize)
                        .any(|a| a == m.joint as usize)
                })
            };
            match families.iter_mut().find(|f| related(f)) {
                Some(family) => family.push(side),
                None => families.push(vec![side]),
            }
        }
        if families.len() < 2 {
            continue;
        }
        let region = families[0][0].region;
        let bones: Vec<Vec<[DVec3; 2]>> = families
            .iter()
            .map(|family| {
                segments
                    .iter()
                    .filter(|&&(j, _, _)| family.iter().any(|m| owner[j as usize] == Some(m.joint)))
                    .map(|&(_, a, b)| [a, b])
                    .collect()
            })
            .collect();
        let part = divide(mesh, topology, face_region, region, &families, &bones);
        let mut regions = vec![region];
        for _ in 1..families.len() {
            regions.push(*region_count as u32);
            *region_count += 1;
        }
        for (f, &p) in part.iter().enumerate() {
            if p != UNASSIGNED {
                face_region[f] = regions[p as usize];
            }
        }
        divided.push(SharedSide {
            joints: families.iter().map(|f| f[0].joint).collect(),
            regions,
        });
    }
    divided
}

/// Steps 1–3 of the module documentation for one region: the index into `families` of
/// every face of `region` ([`UNASSIGNED`] for faces of other regions).
fn divide(
    mesh: &SurfaceMesh,
    topology: &Topology,
    face_region: &[u32],
    region: u32,
    families: &[Vec<&ChildSide>],
    bones: &[Vec<[DVec3; 2]>],
) -> Vec<u32> {
    let in_region = |f: usize| face_region[f] == region;
    let orientation = orientation_sign(mesh);
    let label = |f: usize| -> u32 {
        let [a, b, c] = mesh.corners(f);
        let x = (a + b + c) / 3.0;
        let outward = orientation * mesh.scaled_normal(f);
        // The distance to the nearest of `segments`, of those behind the face only when
        // `behind`.
        let distance = |segments: &[[DVec3; 2]], behind: bool| {
            segments
                .iter()
                .map(|&[s, t]| s + (t - s) * segment_parameter(x, s, t))
                .filter(|&q| !behind || outward.dot(q - x) < 0.0)
                .map(|q| q.distance(x))
                .fold(f64::INFINITY, f64::min)
        };
        let nearest = |behind: bool| {
            (0..bones.len())
                .map(|i| (distance(&bones[i], behind), i as u32))
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .filter(|&(d, _)| d.is_finite())
                .map(|(_, i)| i)
        };
        nearest(true).or_else(|| nearest(false)).unwrap_or(0)
    };
    let mut part = vec![UNASSIGNED; mesh.triangle_count()];
    let mut queue = VecDeque::new();
    for (i, side) in families
        .iter()
        .enumerate()
        .flat_map(|(i, family)| family.iter().map(move |side| (i, side)))
    {
        for (k, &a) in side.curve.iter().enumerate() {
            let b = side.curve[(k + 1) % side.curve.len()];
            let Some(e) = find_edge(topology, a, b) else {
                continue;
            };
            for &f in topology.faces_of_edge(e) {
                if in_region(f as usize) && part[f as usize] == UNASSIGNED {
                    part[f as usize] = i as u32;
                    queue.push_back(f as usize);
                }
            }
        }
    }
    let labels: Vec<u32> = (0..mesh.triangle_count())
        .map(|f| if in_region(f) { label(f) } else { UNASSIGNED })
        .collect();
    // Step 2: each part into its own label; step 3: the rest into whichever part comes.
    for same_label_only in [true, false] {
        if !same_label_only {
            queue.extend((0..part.len()).filter(|&f| part[f] != UNASSIGNED && in_region(f)));
        }
        while let Some(f) = queue.pop_front() {
            for g in topology.face_neighbors(f) {
                let g = g as usize;
                if !in_region(g) || part[g] != UNASSIGNED {
                    continue;
                }
                if same_label_only && labels[g] != part[f] {
                    continue;
                }
                part[g] = part[f];
                queue.push_back(g);
            }
        }
    }
    part
}

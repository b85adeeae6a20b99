//! Region growing on the split surface and binding of regions to joints (Lu et al. 2008
//! §3.2).
//!
//! Regions are the classes of faces joined across edges that are not on a cut loop. The
//! side of a cut is decided by the faces along its loop: the region whose faces lie on the
//! positive side of the plane (n · (x − J) > 0, the child side) is the child region.
//!
//! Binding: the region of a cut joint is its child region; a joint without a cut lies in
//! its parent's region; a root without a cut lies in the parent region of the first cut
//! below it (or, with no cut below, in the region of the face nearest to it). A region
//! that no joint is bound to but that lies on the parent side of a cut moves with that
//! cut's joint's nearest ancestor that owns skin ([`bind_parent_sides`]): a torso whose
//! root joint lies outside it, the part of a leg piece above its hip cut. A region's
//! joints are listed bound joint first — the cut joint whose child region it is, else its
//! joint nearest the root — then the others in the skeleton's topological order (along the
//! chain, parents before children).
//!
//! Inputs: the split surface ([`crate::cuts::split`]) and its topology, the cut loops, the
//! skeleton. Outputs: the region of every face, the regions on each side of every cut, the
//! region of every joint and the joints each region holds ([`Region`]).

pub mod holding;
pub mod shared_sides;

use crate::cuts::plane_section::Plane;
use crate::decomposition::Region;
use crate::mesh::{SurfaceMesh, Topology};
use crate::rows::Rows;
use crate::skeleton::bone_tree::BoneTree;
#[cfg(doc)]
use crate::skeleton::bones::bone_segments;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;

/// A face not yet grown into a region.
const NO_REGION: u32 = u32::MAX;

/// Face regions: #F region index of every face and the number of regions; regions are
/// numbered in the order of their first face.
pub fn grow_regions(
    mesh: &SurfaceMesh,
    topology: &Topology,
    loops: &[Vec<u32>],
) -> (Vec<u32>, usize) {
    let mut blocked = vec![false; topology.edges.len()];
    for curve_loop in loops {
        for (k, &a) in curve_loop.iter().enumerate() {
            let b = curve_loop[(k + 1) % curve_loop.len()];
            if let Some(e) = find_edge(topology, a, b) {
                blocked[e] = true;
            }
        }
    }
    let mut region = vec![NO_REGION; mesh.triangle_count()];
    let mut count = 0u32;
    let mut stack = Vec::new();
    for seed in 0..mesh.triangle_count() {
        if region[seed] != NO_REGION {
            continue;
        }
        region[seed] = count;
        stack.push(seed);
        while let Some(f) = stack.pop() {
            for &e in &topology.face_edges[f] {
                if blocked[e as usize] {
                    continue;
                }
                for &g in topology.faces_of_edge(e as usize) {
                    if region[g as usize] == NO_REGION {
                        region[g as usize] = count;
                        stack.push(g as usize);
                    }
                }
            }
        }
        count += 1;
    }
    (region, count as usize)
}

/// The faces of each of `region_count` regions, by increasing face (a counting sort of
/// `face_region`).
pub fn faces_by_region(face_region: &[u32], region_count: usize) -> Rows<u32> {
    Rows::group(
        region_count,
        (0u32..).zip(face_region).map(|(f, &r)| (r as usize, f)),
    )
}

/// The edge joining `a` and `b` (edges are sorted, so a binary search).
fn find_edge(topology: &Topology, a: u32, b: u32) -> Option<usize> {
    topology.edges.binary_search(&[a.min(b), a.max(b)]).ok()
}

/// (parent region, child region) of a cut: the regions of the faces along `curve_loop`,
/// voted by the side of `plane` their centroid lies on. `None` when one side has no face.
pub fn side_regions(
    mesh: &SurfaceMesh,
    topology: &Topology,
    face_region: &[u32],
    curve_loop: &[u32],
    plane: &Plane,
) -> Option<(u32, u32)> {
    let mut votes: Vec<(u32, f64)> = Vec::new();
    for (k, &a) in curve_loop.iter().enumerate() {
        let Some(e) = find_edge(topology, a, curve_loop[(k + 1) % curve_loop.len()]) else {
            continue;
        };
        for &f in topology.faces_of_edge(e) {
            let [x, y, z] = mesh.corners(f as usize);
            let side = plane.signed_distance((x + y + z) / 3.0).signum();
            let r = face_region[f as usize];
            match votes.iter_mut().find(|(region, _)| *region == r) {
                Some((_, total)) => *total += side,
                None => votes.push((r, side)),
            }
        }
    }
    let child = votes.iter().max_by(|x, y| x.1.total_cmp(&y.1))?;
    let parent = votes.iter().min_by(|x, y| x.1.total_cmp(&y.1))?;
    (child.1 > 0.0 && parent.1 < 0.0).then_some((parent.0, child.0))
}

/// Regions of joints and the regions' joint lists (see the module doc).
///
/// - `region_faces`: the faces of each region ([`faces_by_region`]).
/// - `cut_child`: #J child region of every joint with a separating cut, `None` otherwise.
/// - `cut_parent`: #J parent region of the same cuts.
/// - `positions`: #J bind positions.
/// - `holding(j, r)`: the region that holds joint j, which has no cut, when its parent
///   lies in region r ([`holding::HoldingRegions`] for a soft joint, r itself otherwise).
///
/// A region whose joint nearest the root lies in it because its parent's region does not
/// reach it (`holding` moved it there) continues that region across the gap between their
/// pieces: it is bound to the joint the parent's region is bound to, and the joints it
/// holds act in it as soft boundaries, as do the soft joints between those and the bound
/// joint (`weights::soft_sides`).
///
/// Returns (#J region of each joint, `None` when the surface is empty; the regions).
#[allow(clippy::too_many_arguments)]
pub fn bind_regions(
    mesh: &SurfaceMesh,
    face_region: &[u32],
    region_faces: &Rows<u32>,
    skeleton: &Skeleton,
    positions: &[DVec3],
    cut_child: &[Option<u32>],
    cut_parent: &[Option<u32>],
    holding: impl Fn(usize, Option<u32>) -> Option<u32>,
) -> (Vec<Option<u32>>, Vec<Region>) {
    let order = skeleton.topological_order();
    let mut joint_region: Vec<Option<u32>> = vec![None; skeleton.len()];
    for &j in &order {
        joint_region[j] = match (cut_child[j], skeleton.parent(j)) {
            (Some(child), _) => Some(child),
            (None, Some(p)) => holding(j, joint_region[p]),
            (None, None) => order
                .iter()
                .filter(|&&k| skeleton.ancestors(k).any(|a| a == j))
                .find_map(|&k| cut_parent[k])
                .or_else(|| nearest_face_region(mesh, face_region, positions[j])),
        };
    }

    // A vertex on a cut loop counts once for each region it borders: each vertex counted
    // at the first face of a region that uses it (O(V + F), where sorting the 3F (region,
    // vertex) pairs took 15% of the decomposition of a small character).
    let region_count = region_faces.len();
    let faces: Vec<usize> = (0..region_count)
        .map(|r| region_faces.row(r).len())
        .collect();
    let mut vertices = vec![0usize; region_count];
    let mut counted_in = vec![u32::MAX; mesh.positions.len()];
    for (r, count) in vertices.iter_mut().enumerate() {
        for &f in region_faces.row(r) {
            for &v in &mesh.triangles[f as usize] {
                if counted_in[v as usize] != r as u32 {
                    counted_in[v as usize] = r as u32;
                    *count += 1;
                }
            }
        }
    }
    let mut joints: Vec<Vec<u32>> = vec![Vec::new(); region_count];
    for &j in &order {
        if let Some(r) = joint_region[j] {
            joints[r as usize].push(j as u32);
        }
    }
    for (r, list) in joints.iter_mut().enumerate() {
        if let Some(k) = list
            .iter()
            .position(|&j| cut_child[j as usize] == Some(r as u32))
        {
            let bound = list.remove(k);
            list.insert(0, bound);
        }
    }
    // Regions whose first joint was moved there, in the order of those joints: the
    // parent's region, holding an earlier joint, is bound before.
    for &j in &order {
        let (Some(r), Some(p)) = (joint_region[j], skeleton.parent(j)) else {
            continue;
        };
        let parent_region = joint_region[p].filter(|&q| q != r);
        let first = joints[r as usize].first() == Some(&(j as u32));
        if let (true, None, Some(q)) = (first, cut_child[j], parent_region) {
            if let Some(&bound) = joints[q as usize].first() {
                joints[r as usize].insert(0, bound);
            }
        }
    }
    let regions = joints
        .into_iter()
        .zip(faces.iter().zip(&vertices))
        .map(|(joints, (&faces, &vertices))| Region {
            joints,
            faces,
            vertices,
        })
        .collect();
    (joint_region, regions)
}

/// Binds every region that no joint is bound to but that lies on the parent side of a cut
/// (a torso whose root joint lies outside it and was bound beside it; the part of a leg
/// piece above a hip cut whose parent lies in another piece; a chin left below the head's
/// cut). Such a region R on the parent side of the cut of joint k hangs from k when the
/// bones nearest to more than half of its faces are those of k or of the joints below it
/// (the chin lies nearer to the head's mouth bone than to the neck): it moves with k.
/// Otherwise it moves with the joint that moves that side: k's nearest ancestor that owns
/// skin. Of several such cuts, the joint nearest the root wins. Returns how many regions
/// were bound.
///
/// - `cut_parent`: #J parent region of every joint with a separating cut.
/// - `owns_skin`: #J whether the joint may take weight.
/// - `face_joints(r)`: the joint of the bone nearest to each face of region r
///   ([`nearest_bone_joints`]).
pub fn bind_parent_sides(
    regions: &mut [Region],
    skeleton: &Skeleton,
    cut_parent: &[Option<u32>],
    owns_skin: &[bool],
    face_joints: impl Fn(u32) -> Vec<u32>,
) -> usize {
    let order = skeleton.topological_order();
    let mut rank = vec![0usize; skeleton.len()];
    for (k, &j) in order.iter().enumerate() {
        rank[j] = k;
    }
    let mut chosen: Vec<Option<u32>> = vec![None; regions.len()];
    let mut nearest: Vec<Option<Vec<u32>>> = vec![None; regions.len()];
    for (k, parent_side) in cut_parent.iter().enumerate() {
        let Some(r) = *parent_side else { continue };
        if !regions[r as usize].joints.is_empty() {
            continue;
        }
        let faces = nearest[r as usize].get_or_insert_with(|| face_joints(r));
        let below_k =
            |j: &&u32| **j as usize == k || skeleton.ancestors(**j as usize).any(|a| a == k);
        let hangs = owns_skin[k] && 2 * faces.iter().filter(below_k).count() > faces.len();
        let mover = if hangs {
            Some(k)
        } else {
            skeleton.ancestors(k).find(|&a| owns_skin[a])
        };
        let Some(mover) = mover else {
            continue;
        };
        let slot = &mut chosen[r as usize];
        match *slot {
            Some(j) if rank[j as usize] <= rank[mover] => {}
            _ => *slot = Some(mover as u32),
        }
    }
    let mut bound = 0;
    for (region, joint) in regions.iter_mut().zip(chosen) {
        if let Some(joint) = joint {
            region.joints.push(joint);
            bound += 1;
        }
    }
    bound
}

/// The joint of the bone segment ([`bone_segments`], indexed by `bones`) nearest to the
/// centroid of each of `faces`, in their order.
pub fn nearest_bone_joints(
    mesh: &SurfaceMesh,
    faces: &[u32],
    bones: &BoneTree,
    segments: &[(u32, DVec3, DVec3)],
) -> Vec<u32> {
    faces
        .iter()
        .filter_map(|&f| {
            let [a, b, c] = mesh.corners(f as usize);
            let p = (a + b + c) / 3.0;
            let nearest = bones.within(p, bones.nearest(p)).into_iter().next()?;
            Some(segments[nearest as usize].0)
        })
        .collect()
}

fn nearest_face_region(mesh: &SurfaceMesh, face_region: &[u32], p: DVec3) -> Option<u32> {
    (0..mesh.triangle_count())
        .map(|f| {
            let [a, b, c] = mesh.corners(f);
            (((a + b + c) / 3.0).distance_squared(p), face_region[f])
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map(|(_, r)| r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    fn region(joints: Vec<u32>) -> Region {
        Region {
            joints,
            faces: 1,
            vertices: 3,
        }
    }

    /// Five joints named `names`: the first the root, the next three a chain below it,
    /// the last a second child of the root, at `positions`.
    fn two_branches(names: [&str; 5], positions: &[Vec3; 5]) -> Skeleton {
        Skeleton::from_positions(
            names.map(String::from).to_vec(),
            vec![NO_PARENT, 0, 1, 2, 0],
            positions,
        )
        .expect("a valid skeleton")
    }

    #[test]
    fn a_region_holding_a_joint_its_parents_region_does_not_reach_is_bound_like_that_region() {
        // root (0) → forearm (1, cut: region 1) → palm (2, soft) → finger (3, soft), and
        // root → head (4, soft). Region 0 is the root's, region 2 a separate hand piece
        // around the palm, region 3 a piece around nothing.
        let skeleton = two_branches(
            ["root", "forearm", "palm", "finger", "head"],
            &[Vec3::ZERO, Vec3::X, 2.0 * Vec3::X, 3.0 * Vec3::X, Vec3::Y],
        );
        let mesh = SurfaceMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 2]; 4],
        };
        let face_region = [0, 1, 2, 3];
        let cut_child = [None, Some(1), None, None, None];
        let cut_parent = [None, Some(0), None, None, None];
        // The palm lies in the hand piece, its finger follows it there; the head stays.
        let holding = |j: usize, parent_region: Option<u32>| match j {
            2 => Some(2),
            _ => parent_region,
        };
        let (joint_region, regions) = bind_regions(
            &mesh,
            &face_region,
            &faces_by_region(&face_region, 4),
            &skeleton,
            &skeleton
                .bind_positions()
                .iter()
                .map(|p| p.as_dvec3())
                .collect::<Vec<_>>(),
            &cut_child,
            &cut_parent,
            holding,
        );
        assert_eq!(joint_region, [Some(0), Some(1), Some(2), Some(2), Some(0)]);
        assert_eq!(regions[0].joints, vec![0, 4]);
        assert_eq!(regions[1].joints, vec![1]);
        // The hand piece continues the forearm's region: bound to the forearm, the palm
        // and the finger act in it.
        assert_eq!(regions[2].joints, vec![1, 2, 3]);
        assert!(regions[3].joints.is_empty());
    }

    #[test]
    fn a_region_without_joints_on_the_parent_side_of_a_cut_moves_with_the_cut_joints_parent() {
        // root (0) → spine (1) → arm (2) → hand (3), and a second branch root → leg (4).
        // Region 0 lies on the parent side of the arm's cut and of the leg's cut, region 1
        // is the arm's, region 2 the hand's, region 3 the leg's; region 4 lies on the parent
        // side of nothing.
        let skeleton = two_branches(
            ["root", "spine", "arm", "hand", "leg"],
            &[Vec3::ZERO, Vec3::Y, Vec3::X, 2.0 * Vec3::X, -Vec3::Y],
        );
        let cut_parent = [None, None, Some(0), Some(1), Some(0)];
        let fresh = || {
            vec![
                region(vec![]),
                region(vec![2]),
                region(vec![3]),
                region(vec![4]),
                region(vec![]),
            ]
        };
        // Of the two movers (spine for the arm's cut, root for the leg's), the root wins.
        let mut regions = fresh();
        assert_eq!(
            bind_parent_sides(&mut regions, &skeleton, &cut_parent, &[true; 5], |_| vec![]),
            1
        );
        assert_eq!(regions[0].joints, vec![0]);
        assert!(regions[4].joints.is_empty());
        assert_eq!(regions[1].joints, vec![2], "bound regions stay as they are");
        // A root that may not take weight (outside the body) hands the side to the spine.
        let mut regions = fresh();
        bind_parent_sides(
            &mut regions,
            &skeleton,
            &cut_parent,
            &[false, true, true, true, true],
            |_| vec![],
        );
        assert_eq!(regions[0].joints, vec![1]);
        // No ancestor may take weight: the region stays without joints.
        let mut regions = fresh();
        let none = [false, false, true, true, true];
        assert_eq!(
            bind_parent_sides(
                &mut regions,
                &skeleton,
                &[None, None, None, None, Some(0)],
                &none,
                |_| vec![],
            ),
            0
        );
        assert!(regions[0].joints.is_empty());
    }

    #[test]
    fn a_region_without_joints_nearest_to_the_cut_joints_bones_hangs_from_that_joint() {
        // root (0) → neck (1) → head (2) → mouth (3), and root → leg (4). Region 0 lies on
        // the parent side of the head's cut (a chin below it), region 1 is the head's.
        let skeleton = two_branches(
            ["root", "neck", "head", "mouth", "leg"],
            &[Vec3::ZERO, Vec3::Y, 2.0 * Vec3::Y, 2.5 * Vec3::Y, -Vec3::Y],
        );
        let cut_parent = [None, None, Some(0), None, None];
        let bind = |face_joints: Vec<u32>| {
            let mut regions = vec![region(vec![]), region(vec![2, 3])];
            bind_parent_sides(&mut regions, &skeleton, &cut_parent, &[true; 5], |r| {
                assert_eq!(r, 0);
                face_joints.clone()
            });
            regions[0].joints.clone()
        };
        // Most faces nearest to the mouth's or the head's bones: the region moves with the
        // head; half or fewer: with the neck, the head's parent, as before.
        assert_eq!(bind(vec![3, 3, 2, 1]), vec![2]);
        assert_eq!(bind(vec![3, 1, 1, 4]), vec![1]);
        assert_eq!(bind(vec![3, 2, 1, 1]), vec![1]);
        assert_eq!(bind(vec![]), vec![1]);
    }
}

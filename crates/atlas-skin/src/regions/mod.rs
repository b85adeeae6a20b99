//! Region growing on the split surface and binding of regions to joints (Lu et al. 2008
//! §3.2).
//!
//! Regions are the classes of faces joined across edges that are not on a cut loop. The
//! side of a cut is decided by the faces along its loop: the region whose faces lie on the
//! positive side of the plane (n · (x − J) > 0, the child side) is the child region.
//!
//! Binding: the region of a cut joint is its child region; a joint without a cut lies in
//! its parent's region; a root without a cut lies in the parent region of the first cut
//! below it (or, with no cut below, in the region of the face nearest to it). A region's
//! joints are listed bound joint first — the cut joint whose child region it is, else its
//! joint nearest the root — then the others in the skeleton's topological order (along the
//! chain, parents before children).
//!
//! Inputs: the split surface ([`crate::cuts::split`]) and its topology, the cut loops, the
//! skeleton. Outputs: the region of every face, the regions on each side of every cut, the
//! region of every joint and the joints each region holds ([`Region`]).

use crate::cuts::plane_section::Plane;
use crate::decomposition::Region;
use crate::mesh::{SurfaceMesh, Topology};
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
/// - `cut_child`: #J child region of every joint with a separating cut, `None` otherwise.
/// - `cut_parent`: #J parent region of the same cuts.
/// - `positions`: #J bind positions.
///
/// Returns (#J region of each joint, `None` when the surface is empty; the regions).
pub fn bind_regions(
    mesh: &SurfaceMesh,
    face_region: &[u32],
    region_count: usize,
    skeleton: &Skeleton,
    positions: &[DVec3],
    cut_child: &[Option<u32>],
    cut_parent: &[Option<u32>],
) -> (Vec<Option<u32>>, Vec<Region>) {
    let order = skeleton.topological_order();
    let mut joint_region: Vec<Option<u32>> = vec![None; skeleton.len()];
    for &j in &order {
        joint_region[j] = match (cut_child[j], skeleton.parent(j)) {
            (Some(child), _) => Some(child),
            (None, Some(p)) => joint_region[p],
            (None, None) => order
                .iter()
                .filter(|&&k| skeleton.ancestors(k).any(|a| a == j))
                .find_map(|&k| cut_parent[k])
                .or_else(|| nearest_face_region(mesh, face_region, positions[j])),
        };
    }

    let mut faces = vec![0usize; region_count];
    // A vertex on a cut loop counts once for each region it borders.
    let mut incidences: Vec<(u32, u32)> = Vec::with_capacity(3 * mesh.triangle_count());
    for (f, t) in mesh.triangles.iter().enumerate() {
        faces[face_region[f] as usize] += 1;
        incidences.extend(t.iter().map(|&v| (face_region[f], v)));
    }
    incidences.sort_unstable();
    incidences.dedup();
    let mut vertices = vec![0usize; region_count];
    for (r, _) in incidences {
        vertices[r as usize] += 1;
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

fn nearest_face_region(mesh: &SurfaceMesh, face_region: &[u32], p: DVec3) -> Option<u32> {
    (0..mesh.triangle_count())
        .map(|f| {
            let [a, b, c] = mesh.corners(f);
            (((a + b + c) / 3.0).distance_squared(p), face_region[f])
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map(|(_, r)| r)
}

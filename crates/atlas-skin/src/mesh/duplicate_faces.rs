//! Duplicate faces: triangles over the same three welded vertices, in either orientation
//! (a mesh stored twice, a two-sided copy of a shell). Left in, they make the surface
//! non-manifold along every edge they share, and plane sections through them no longer
//! close into simple loops (issue 12: a character's 33 cuts dropped to 20 with faces
//! doubled, to 0 with the whole mesh doubled; the test `rigs_as_found` checks the cuts of
//! the doubled demo).

use super::surface::SurfaceMesh;
use crate::rows::Rows;

/// Removes every triangle whose vertex set an earlier triangle already has, keeping the
/// first (stored order) and the order of the rest; returns how many were removed.
///
/// The triangles are grouped by their smallest vertex (a counting sort, which keeps the
/// stored order within a group: [`Rows::group_indexed`]); a triangle is a copy when an
/// earlier one of its group has the same other two vertices. O(V + F) for groups of
/// bounded size (a vertex's fan).
pub fn remove_duplicate_faces(mesh: &mut SurfaceMesh) -> usize {
    // Each triangle's vertex set as its sorted corners, sorted once (not at every
    // comparison within its group).
    let keys: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|&t| {
            let mut key = t;
            key.sort_unstable();
            key
        })
        .collect();
    let groups = Rows::group_indexed(
        mesh.vertex_count(),
        keys.len(),
        |f| Some(keys[f][0] as usize),
        |f| f as u32,
    );
    let mut copy = vec![false; keys.len()];
    for v in 0..groups.len() {
        let group = groups.row(v);
        for (k, &f) in group.iter().enumerate() {
            let key = keys[f as usize];
            copy[f as usize] = group[..k]
                .iter()
                .any(|&g| !copy[g as usize] && keys[g as usize] == key);
        }
    }
    let before = mesh.triangles.len();
    let mut f = 0;
    mesh.triangles.retain(|_| {
        f += 1;
        !copy[f - 1]
    });
    before - mesh.triangles.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;
    use std::collections::HashSet;

    /// The reference: a set of the sorted vertex triples seen so far.
    fn reference_remove(mesh: &mut SurfaceMesh) -> usize {
        let before = mesh.triangles.len();
        let mut seen = HashSet::new();
        mesh.triangles.retain(|t| {
            let mut key = *t;
            key.sort_unstable();
            seen.insert(key)
        });
        before - mesh.triangles.len()
    }

    /// Random triangles over few vertices (many copies, in both orientations, some with
    /// repeated corners): the same triangles removed as by the reference.
    #[test]
    fn grouping_removes_what_the_reference_removes() {
        let mut rng = atlas_skin_runtime::random_pose::SplitMix64::new(9);
        for n in [3u32, 5, 12] {
            let mut pick = || (rng.next_f64() * n as f64) as u32;
            let mesh = SurfaceMesh {
                positions: vec![DVec3::ZERO; n as usize],
                triangles: (0..200).map(|_| [pick(), pick(), pick()]).collect(),
            };
            let (mut fast, mut reference) = (mesh.clone(), mesh);
            assert_eq!(
                remove_duplicate_faces(&mut fast),
                reference_remove(&mut reference)
            );
            assert_eq!(fast.triangles, reference.triangles);
        }
    }

    /// A doubled triangle, a flipped copy and a triangle sharing only an edge: the copies
    /// go, the others stay in order.
    #[test]
    fn copies_in_either_orientation_are_removed() {
        let mut mesh = SurfaceMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            triangles: vec![[0, 1, 2], [1, 2, 0], [0, 2, 1], [0, 1, 3]],
        };
        assert_eq!(remove_duplicate_faces(&mut mesh), 2);
        assert_eq!(mesh.triangles, [[0, 1, 2], [0, 1, 3]]);
    }
}

//! Duplicate faces: triangles over the same three welded vertices, in either orientation
//! (a mesh stored twice, a two-sided copy of a shell). Left in, they make the surface
//! non-manifold along every edge they share, and plane sections through them no longer
//! close into simple loops (issue 12: a character's 33 cuts dropped to 20 with faces
//! doubled, to 0 with the whole mesh doubled; the test `rigs_as_found` checks the cuts of
//! the doubled demo).

use super::surface::SurfaceMesh;
use rustc_hash::FxHashSet;

/// Removes every triangle whose vertex set an earlier triangle already has, keeping the
/// first (stored order) and the order of the rest; returns how many were removed.
pub fn remove_duplicate_faces(mesh: &mut SurfaceMesh) -> usize {
    let before = mesh.triangles.len();
    let mut seen = FxHashSet::default();
    seen.reserve(before);
    mesh.triangles.retain(|t| {
        let mut key = *t;
        key.sort_unstable();
        seen.insert(key)
    });
    before - mesh.triangles.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

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

//! Welding coincident vertices.
//!
//! glTF and OBJ files split vertices along UV and normal seams; the method needs the
//! connected surface. Vertices closer than `relative_tolerance ×` the bounding-box diagonal
//! of the referenced vertices are merged (transitively), and a map is kept from every stored
//! vertex to its welded vertex so that results can be written back per stored vertex.

use super::surface::SurfaceMesh;
use super::union_find::UnionFind;
use crate::geometry::bounding_box;
use glam::{DVec3, Vec3};
use std::collections::HashMap;

/// The tolerance the corpus facts are computed with: 1e-6 × bounding-box diagonal.
pub const DEFAULT_WELD_TOLERANCE: f64 = 1e-6;

/// Marks a stored vertex that no triangle references (it has no welded vertex).
pub const UNREFERENCED: u32 = u32::MAX;

/// A welded surface and the maps between it and the stored vertices.
#[derive(Debug, Clone)]
pub struct Welded {
    /// The welded surface: only vertices some triangle references, triangles in stored order.
    pub mesh: SurfaceMesh,
    /// #stored: welded index of each stored vertex, [`UNREFERENCED`] for unused ones.
    pub welded_of_stored: Vec<u32>,
    /// #welded: the first stored vertex merged into each welded vertex.
    pub stored_of_welded: Vec<u32>,
    /// Number of stored vertices some triangle references.
    pub referenced_stored: usize,
}

/// Welds `positions` (#V stored) referenced by `triangles` (#F).
///
/// Each welded vertex takes the position of its first stored vertex. Complexity: expected
/// O(V) with a hash grid of cell size equal to the tolerance.
pub fn weld(positions: &[Vec3], triangles: &[[u32; 3]], relative_tolerance: f64) -> Welded {
    let stored: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
    let mut referenced = vec![false; stored.len()];
    for t in triangles {
        for &v in t {
            referenced[v as usize] = true;
        }
    }
    let used: Vec<DVec3> = (0..stored.len())
        .filter(|&v| referenced[v])
        .map(|v| stored[v])
        .collect();
    let (lo, hi) = bounding_box(&used);
    let tolerance = relative_tolerance * (hi - lo).length();

    let mut sets = UnionFind::new(stored.len());
    if tolerance > 0.0 {
        let cell = |p: DVec3| ((p - lo) / tolerance).floor().as_ivec3();
        let mut grid: HashMap<glam::IVec3, Vec<u32>> = HashMap::new();
        for v in 0..stored.len() {
            if !referenced[v] {
                continue;
            }
            let c = cell(stored[v]);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(bucket) = grid.get(&(c + glam::IVec3::new(dx, dy, dz))) else {
                            continue;
                        };
                        for &u in bucket {
                            if stored[u as usize].distance(stored[v]) <= tolerance {
                                sets.union(u, v as u32);
                            }
                        }
                    }
                }
            }
            grid.entry(c).or_default().push(v as u32);
        }
    }

    let mut welded_of_stored = vec![UNREFERENCED; stored.len()];
    let mut stored_of_welded = Vec::new();
    let mut welded_of_root: HashMap<u32, u32> = HashMap::new();
    for v in 0..stored.len() {
        if !referenced[v] {
            continue;
        }
        let root = sets.find(v as u32);
        let next = stored_of_welded.len() as u32;
        let w = *welded_of_root.entry(root).or_insert_with(|| {
            stored_of_welded.push(v as u32);
            next
        });
        welded_of_stored[v] = w;
    }
    let mesh = SurfaceMesh {
        positions: stored_of_welded
            .iter()
            .map(|&v| stored[v as usize])
            .collect(),
        triangles: triangles
            .iter()
            .map(|t| t.map(|v| welded_of_stored[v as usize]))
            .collect(),
    };
    Welded {
        mesh,
        welded_of_stored,
        stored_of_welded,
        referenced_stored: used.len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seam_vertices_merge_and_unused_vertices_are_dropped() {
        let positions = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::X, // duplicate of 1 across a seam
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(5.0, 5.0, 5.0), // referenced by nothing
        ];
        let welded = weld(&positions, &[[0, 1, 2], [3, 4, 2]], DEFAULT_WELD_TOLERANCE);
        assert_eq!(welded.mesh.vertex_count(), 4);
        assert_eq!(welded.referenced_stored, 5);
        assert_eq!(welded.welded_of_stored[3], welded.welded_of_stored[1]);
        assert_eq!(welded.welded_of_stored[5], UNREFERENCED);
        assert_eq!(welded.mesh.triangles[1][0], welded.mesh.triangles[0][1]);
    }
}

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
use rustc_hash::FxHashMap;
use std::collections::hash_map::Entry;

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
/// O(V) with a hash grid (`close_pairs`).
pub fn weld(positions: &[Vec3], triangles: &[[u32; 3]], relative_tolerance: f64) -> Welded {
    let stored: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
    let mut referenced = vec![false; stored.len()];
    for t in triangles {
        for &v in t {
            referenced[v as usize] = true;
        }
    }
    let used: Vec<u32> = (0..stored.len() as u32)
        .filter(|&v| referenced[v as usize])
        .collect();
    let (lo, hi) = bounding_box(used.iter().map(|&v| &stored[v as usize]));
    let tolerance = relative_tolerance * (hi - lo).length();

    let mut sets = UnionFind::new(stored.len());
    if tolerance > 0.0 {
        close_pairs(&stored, &used, lo, tolerance, |u, v| sets.union(u, v));
    }
    welded_from_sets(&stored, triangles, &used, &mut sets)
}

/// Side of a cell of [`close_pairs`]' grid, in tolerances.
const CELL_TOLERANCES: f64 = 64.0;

/// Calls `pair(u, v)` for every pair u < v of `used` vertices (in increasing order) at
/// most `tolerance` apart (and possibly for others: the caller merges them only through
/// union–find, where a pair found twice changes nothing, so every qualifying pair is
/// reported at least once and no other).
///
/// A hash grid of cell size s = [`CELL_TOLERANCES`] × tolerance with origin `lo`: a point
/// at offset x within its cell c along an axis (0 ≤ x < s) has every point within
/// `tolerance` in cell c, and also in c − 1 when x is within reach r = tolerance · 33/32
/// of the cell's lower side, in c + 1 when within r of its upper side (the 1/32 a margin
/// against rounding). Most points look into their own cell only, and a cell holds only
/// points within s of each other (on a real mesh, the copies of a seam vertex). Expected
/// O(V). (With cells of 2 × tolerance every point looked into 8 cells: 8 hash look-ups per
/// vertex, the weld's largest cost.)
fn close_pairs(
    stored: &[DVec3],
    used: &[u32],
    lo: DVec3,
    tolerance: f64,
    mut pair: impl FnMut(u32, u32),
) {
    const NONE: u32 = u32::MAX;
    let cell_size = CELL_TOLERANCES * tolerance;
    let reach = (1.0 + 1.0 / 32.0) / CELL_TOLERANCES;
    let mut first_in_cell: FxHashMap<[i64; 3], u32> = FxHashMap::default();
    first_in_cell.reserve(used.len());
    let mut next = vec![NONE; stored.len()];
    for &v in used {
        let p = stored[v as usize];
        let scaled = (p - lo) / cell_size;
        let cell = scaled.floor();
        let offset = scaled - cell;
        let steps = |x: f64| -> &'static [i64] {
            match (x < reach, x > 1.0 - reach) {
                (true, true) => &[-1, 0, 1],
                (true, false) => &[-1, 0],
                (false, true) => &[0, 1],
                (false, false) => &[0],
            }
        };
        let c = [cell.x as i64, cell.y as i64, cell.z as i64];
        for &dx in steps(offset.x) {
            for &dy in steps(offset.y) {
                for &dz in steps(offset.z) {
                    let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                    let Some(&head) = first_in_cell.get(&key) else {
                        continue;
                    };
                    let mut u = head;
                    while u != NONE {
                        if stored[u as usize].distance(p) <= tolerance {
                            pair(u, v);
                        }
                        u = next[u as usize];
                    }
                }
            }
        }
        match first_in_cell.entry(c) {
            Entry::Occupied(mut head) => {
                next[v as usize] = *head.get();
                *head.get_mut() = v;
            }
            Entry::Vacant(slot) => {
                slot.insert(v);
            }
        }
    }
}

/// The [`Welded`] surface of the merged `sets`: welded vertices numbered by their first
/// stored vertex, triangles in stored order.
fn welded_from_sets(
    stored: &[DVec3],
    triangles: &[[u32; 3]],
    used: &[u32],
    sets: &mut UnionFind,
) -> Welded {
    let mut welded_of_stored = vec![UNREFERENCED; stored.len()];
    let mut stored_of_welded = Vec::new();
    // Every set is represented by its smallest member, which comes first in `used`.
    for &v in used {
        let root = sets.find(v);
        if root == v {
            welded_of_stored[v as usize] = stored_of_welded.len() as u32;
            stored_of_welded.push(v);
        } else {
            welded_of_stored[v as usize] = welded_of_stored[root as usize];
        }
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

    use atlas_skin_runtime::random_pose::SplitMix64;

    /// The reference: every pair of referenced vertices compared, O(V²).
    fn reference_weld(positions: &[Vec3], triangles: &[[u32; 3]], relative: f64) -> Welded {
        let stored: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
        let mut used: Vec<u32> = triangles.iter().flatten().copied().collect();
        used.sort_unstable();
        used.dedup();
        let (lo, hi) = bounding_box(used.iter().map(|&v| &stored[v as usize]));
        let tolerance = relative * (hi - lo).length();
        let mut sets = UnionFind::new(stored.len());
        for (k, &u) in used.iter().enumerate() {
            for &v in &used[k + 1..] {
                if tolerance > 0.0 && stored[u as usize].distance(stored[v as usize]) <= tolerance {
                    sets.union(u, v);
                }
            }
        }
        welded_from_sets(&stored, triangles, &used, &mut sets)
    }

    /// Clusters of points closer and farther than the tolerance, on cell boundaries and
    /// off them, some unreferenced: the hash grid welds exactly as the reference.
    #[test]
    fn hash_grid_welds_as_the_reference() {
        let mut rng = SplitMix64::new(17);
        for case in 0..40 {
            let relative = [1e-6, 1e-3, 0.05, 0.0][case % 4];
            let mut positions = Vec::new();
            for _ in 0..60 {
                let centre = Vec3::new(
                    rng.next_f64() as f32,
                    rng.next_f64() as f32,
                    (rng.next_f64() * 0.1) as f32,
                );
                // A cluster of up to 4 points at distances around the tolerance.
                for _ in 0..1 + (rng.next_f64() * 4.0) as usize {
                    let jitter = (rng.next_f64() * 3.0 * relative * 1.42) as f32;
                    let axis = [Vec3::X, Vec3::Y, Vec3::Z][(rng.next_f64() * 3.0) as usize];
                    let snapped = if case % 3 == 0 {
                        centre
                    } else {
                        centre.round()
                    };
                    positions.push(snapped + axis * jitter);
                }
            }
            let n = positions.len() as u32;
            let triangles: Vec<[u32; 3]> = (0..n / 3)
                .filter(|k| k % 7 != 3)
                .map(|k| [3 * k, 3 * k + 1, (3 * k + 2) % n])
                .collect();
            let fast = weld(&positions, &triangles, relative);
            let reference = reference_weld(&positions, &triangles, relative);
            assert_eq!(
                fast.welded_of_stored, reference.welded_of_stored,
                "case {case}"
            );
            assert_eq!(fast.mesh.positions, reference.mesh.positions, "case {case}");
            assert_eq!(fast.mesh.triangles, reference.mesh.triangles, "case {case}");
            assert_eq!(fast.referenced_stored, reference.referenced_stored);
        }
    }

    /// Pairs just closer and just farther than the tolerance across the grid's cell sides
    /// (the first point at the origin, so that the sides are at multiples of the cell
    /// size), along one axis and across edges and corners of cells: welded as the
    /// reference welds them.
    #[test]
    fn pairs_across_cell_sides_weld_as_the_reference() {
        let relative = 1e-3;
        let far = Vec3::splat(1.0);
        let tolerance = relative * (far.as_dvec3().length());
        let cell = (CELL_TOLERANCES * tolerance) as f32;
        let t = tolerance as f32;
        let mut positions = vec![Vec3::ZERO, far];
        for k in 1..6 {
            let side = k as f32 * cell;
            for (before, after) in [(0.4, 0.5), (0.1, 0.85), (0.6, 0.6), (0.0, 0.99), (0.9, 0.0)] {
                for direction in [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE.normalize()] {
                    let start = Vec3::splat(side) - direction * before * t;
                    positions.push(start);
                    positions.push(start + direction * (before + after) * t);
                }
            }
        }
        let n = positions.len() as u32;
        let triangles: Vec<[u32; 3]> = (0..n).map(|k| [k, k, k]).collect();
        let fast = weld(&positions, &triangles, relative);
        let reference = reference_weld(&positions, &triangles, relative);
        assert_eq!(fast.welded_of_stored, reference.welded_of_stored);
        let merged = n as usize - fast.mesh.vertex_count();
        assert!(merged > 50, "{merged} merged");
    }

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

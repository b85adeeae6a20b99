//! Shortest-edge collapse that keeps a closed manifold surface's topology: coarsens the
//! marching-tetrahedra mesh to a target vertex count and removes its sliver triangles.

use glam::DVec3;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Collapses edges, shortest first, until at most `target_vertices` remain, then drops
/// unused vertices. An edge (a, b) collapses into `place(midpoint)` only when
/// - the link condition holds: a and b share exactly two neighbours (Dey et al. 1999),
///   which keeps a closed 2-manifold closed and its genus unchanged;
/// - no remaining triangle around a or b turns over: each keeps n_after · n_before > 0.3
///   |n_after| |n_before| (a guard against folds).
///
/// Returns the new (positions, triangles).
pub fn collapse_shortest_edges(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    target_vertices: usize,
    place: impl Fn(DVec3) -> DVec3,
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut positions = positions.to_vec();
    let mut triangles = triangles.to_vec();
    let mut face_alive = vec![true; triangles.len()];
    let mut faces_of: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            faces_of[v as usize].push(f as u32);
        }
    }
    let mut vertex_alive = vec![true; positions.len()];
    let mut version = vec![0u32; positions.len()];
    let mut alive_count = positions.len();

    // Min-heap on squared length; an entry is stale when either end changed since.
    let key = |d: f64| Reverse((d * 1e12) as u64);
    let mut heap = BinaryHeap::new();
    for t in &triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            if a < b {
                let d = positions[a as usize].distance_squared(positions[b as usize]);
                heap.push((key(d), a, b, 0u32, 0u32));
            }
        }
    }

    let neighbours = |v: u32, faces_of: &[Vec<u32>], triangles: &[[u32; 3]]| {
        let mut ring: Vec<u32> = faces_of[v as usize]
            .iter()
            .flat_map(|&f| triangles[f as usize])
            .filter(|&u| u != v)
            .collect();
        ring.sort_unstable();
        ring.dedup();
        ring
    };

    while alive_count > target_vertices {
        let Some((_, a, b, va, vb)) = heap.pop() else {
            break;
        };
        if !vertex_alive[a as usize]
            || !vertex_alive[b as usize]
            || version[a as usize] != va
            || version[b as usize] != vb
        {
            continue;
        }
        let ring_a = neighbours(a, &faces_of, &triangles);
        let ring_b = neighbours(b, &faces_of, &triangles);
        if !ring_a.contains(&b) {
            continue;
        }
        let shared = ring_a.iter().filter(|u| ring_b.contains(u)).count();
        if shared != 2 || alive_count <= 4 {
            continue;
        }
        let target = place((positions[a as usize] + positions[b as usize]) * 0.5);
        let folds = [a, b].iter().any(|&v| {
            faces_of[v as usize].iter().any(|&f| {
                let t = triangles[f as usize];
                if t.contains(&a) && t.contains(&b) {
                    return false;
                }
                let before = t.map(|u| positions[u as usize]);
                let after = t.map(|u| {
                    if u == a || u == b {
                        target
                    } else {
                        positions[u as usize]
                    }
                });
                let n0 = (before[1] - before[0]).cross(before[2] - before[0]);
                let n1 = (after[1] - after[0]).cross(after[2] - after[0]);
                n0.dot(n1) <= 0.3 * n0.length() * n1.length()
            })
        });
        if folds {
            continue;
        }
        // Collapse b into a.
        for f in std::mem::take(&mut faces_of[b as usize]) {
            let t = &mut triangles[f as usize];
            if t.contains(&a) {
                face_alive[f as usize] = false;
                for &u in t.iter() {
                    if u != b {
                        faces_of[u as usize].retain(|&g| g != f);
                    }
                }
            } else {
                for u in t.iter_mut() {
                    if *u == b {
                        *u = a;
                    }
                }
                faces_of[a as usize].push(f);
            }
        }
        positions[a as usize] = target;
        vertex_alive[b as usize] = false;
        alive_count -= 1;
        version[a as usize] += 1;
        // The ring's edges are offered again: a collapse refused before may be allowed now.
        for u in neighbours(a, &faces_of, &triangles) {
            version[u as usize] += 1;
        }
        for u in std::iter::once(a).chain(neighbours(a, &faces_of, &triangles)) {
            for w in neighbours(u, &faces_of, &triangles) {
                let d = positions[u as usize].distance_squared(positions[w as usize]);
                let (lo, hi) = (u.min(w), u.max(w));
                heap.push((key(d), lo, hi, version[lo as usize], version[hi as usize]));
            }
        }
    }

    let mut new_index = vec![u32::MAX; positions.len()];
    let mut kept = Vec::with_capacity(alive_count);
    for (v, p) in positions.iter().enumerate() {
        if vertex_alive[v] {
            new_index[v] = kept.len() as u32;
            kept.push(*p);
        }
    }
    let faces = triangles
        .iter()
        .zip(&face_alive)
        .filter(|(_, &alive)| alive)
        .map(|(t, _)| t.map(|v| new_index[v as usize]))
        .collect();
    (kept, faces)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::demo::marching_tetrahedra::fixtures::{assert_closed_sphere, unit_sphere};
    use crate::{MeshStats, SurfaceMesh, Topology};

    #[test]
    fn coarsened_sphere_stays_a_closed_sphere() {
        let (positions, triangles) = unit_sphere(0.08);
        let (positions, triangles) =
            collapse_shortest_edges(&positions, &triangles, 500, |p| p.normalize());
        assert_eq!(positions.len(), 500);
        let mesh = SurfaceMesh {
            positions,
            triangles,
        };
        assert_closed_sphere(&mesh);
        let stats = MeshStats::new(&mesh, &Topology::new(&mesh));
        assert_eq!(stats.degenerate_triangles, 0);
    }
}

//! Smoothing near the seam between matched and inpainted weights (Abdrashitov et al.
//! 2023, §3.3, optional).
//!
//! The zone Z: the inpainted vertices and every vertex reached from one of them, u, along
//! edges through vertices of Z without leaving the ball |p − p_u| < d (d the matching
//! distance): a breadth-first growth from all the inpainted vertices at once, each reached
//! vertex keeping the u it was reached from. On Z only, `iterations` rounds of
//!
//!   w_i ← (1 − α) w_i + α / |N(i)| Σ_{j ∈ N(i)} w_j,
//!
//! every vertex updated from the previous round's rows (Jacobi), N(i) the neighbours of i
//! by an edge. Rows keep summing to 1 (a convex combination of rows that do).

use crate::mesh::{SurfaceMesh, Topology};
use std::collections::VecDeque;

/// The zone Z of the module documentation, as a flag per vertex.
pub fn zone(
    mesh: &SurfaceMesh,
    topology: &Topology,
    inpainted: &[bool],
    distance: f64,
) -> Vec<bool> {
    let n = mesh.vertex_count();
    let mut origin = vec![u32::MAX; n];
    let mut queue = VecDeque::new();
    for v in (0..n).filter(|&v| inpainted[v]) {
        origin[v] = v as u32;
        queue.push_back(v as u32);
    }
    while let Some(v) = queue.pop_front() {
        let from = mesh.positions[origin[v as usize] as usize];
        for &w in topology.neighbors(v as usize) {
            if origin[w as usize] == u32::MAX
                && mesh.positions[w as usize].distance(from) < distance
            {
                origin[w as usize] = origin[v as usize];
                queue.push_back(w);
            }
        }
    }
    origin.iter().map(|&o| o != u32::MAX).collect()
}

/// Smooths the rows of the vertices of `zone` in place (the module's rounds).
pub fn smooth(
    topology: &Topology,
    zone: &[bool],
    rows: &mut [Vec<(u32, f64)>],
    iterations: usize,
    alpha: f64,
) {
    let members: Vec<usize> = (0..zone.len()).filter(|&v| zone[v]).collect();
    let mut next: Vec<Vec<(u32, f64)>> = vec![Vec::new(); members.len()];
    for _ in 0..iterations {
        for (slot, &v) in next.iter_mut().zip(&members) {
            let neighbours = topology.neighbors(v);
            slot.clear();
            if neighbours.is_empty() {
                slot.extend_from_slice(&rows[v]);
                continue;
            }
            let share = alpha / neighbours.len() as f64;
            slot.extend(rows[v].iter().map(|&(j, w)| (j, (1.0 - alpha) * w)));
            for &u in neighbours {
                slot.extend(rows[u as usize].iter().map(|&(j, w)| (j, share * w)));
            }
            super::closest_point::merge_joints(slot);
        }
        for (slot, &v) in next.iter_mut().zip(&members) {
            std::mem::swap(&mut rows[v], slot);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A strip of vertices 0..8 on a line (triangles to a row above): the zone grows from
    /// the inpainted vertex only as far as the distance allows.
    #[test]
    fn the_zone_grows_within_the_distance() {
        let mut positions = Vec::new();
        for x in 0..8 {
            positions.push(DVec3::new(x as f64, 0.0, 0.0));
        }
        for x in 0..8 {
            positions.push(DVec3::new(x as f64, 10.0, 0.0));
        }
        let triangles: Vec<[u32; 3]> = (0..7u32)
            .flat_map(|x| [[x, x + 1, x + 9], [x, x + 9, x + 8]])
            .collect();
        let mesh = SurfaceMesh {
            positions,
            triangles,
        };
        let topology = Topology::new(&mesh);
        let mut inpainted = vec![false; 16];
        inpainted[3] = true;
        let z = zone(&mesh, &topology, &inpainted, 2.5);
        let members: Vec<usize> = (0..16).filter(|&v| z[v]).collect();
        assert_eq!(members, [1, 2, 3, 4, 5]);
    }

    /// Smoothing keeps rows summing to 1 and moves a step towards the neighbours' mean.
    #[test]
    fn smoothing_is_a_convex_step() {
        let mesh = SurfaceMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            triangles: vec![[0, 1, 2]],
        };
        let topology = Topology::new(&mesh);
        let mut rows = vec![vec![(0, 1.0)], vec![(1, 1.0)], vec![(1, 1.0)]];
        smooth(&topology, &[true, false, false], &mut rows, 1, 0.2);
        assert_eq!(rows[0].len(), 2);
        assert!((rows[0][0].1 - 0.8).abs() < 1e-12 && (rows[0][1].1 - 0.2).abs() < 1e-12);
        assert_eq!(rows[1], vec![(1, 1.0)]);
    }
}

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

use super::row_scratch::RowScratch;
use crate::mesh::{SurfaceMesh, Topology};
use crate::rows::{Rows, PAR_CHUNK};
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

/// Smooths the rows of the vertices of `zone` in place (the module's rounds). The zone's
/// rows are packed in [`Rows`] in vertex order, rebuilt each round (in parallel chunks),
/// each new row summed in a dense array of the `joint_count` joints ([`RowScratch`]); the
/// rows of the neighbours outside the zone are read where they are.
pub fn smooth(
    topology: &Topology,
    zone: &[bool],
    rows: &mut [Vec<(u32, f64)>],
    joint_count: usize,
    iterations: usize,
    alpha: f64,
) {
    const OUTSIDE: u32 = u32::MAX;
    let members: Vec<usize> = (0..zone.len()).filter(|&v| zone[v]).collect();
    let mut slot = vec![OUTSIDE; zone.len()];
    for (k, &v) in members.iter().enumerate() {
        slot[v] = k as u32;
    }
    let mut current = Rows::group(
        members.len(),
        members
            .iter()
            .enumerate()
            .flat_map(|(k, &v)| rows[v].iter().map(move |&entry| (k, entry))),
    );
    for _ in 0..iterations {
        let rows = &*rows;
        let previous = &current;
        let row_of = |v: u32| match slot[v as usize] {
            OUTSIDE => rows[v as usize].as_slice(),
            k => previous.row(k as usize),
        };
        current = Rows::par_build(
            members.len(),
            PAR_CHUNK,
            |k, sum: &mut Option<RowScratch>, out| {
                let v = members[k];
                let neighbours = topology.neighbors(v);
                if neighbours.is_empty() {
                    out.extend_from_slice(previous.row(k));
                    return;
                }
                let sum = sum.get_or_insert_with(|| RowScratch::new(joint_count));
                let share = alpha / neighbours.len() as f64;
                for &(j, w) in previous.row(k) {
                    sum.add(j, (1.0 - alpha) * w);
                }
                for &u in neighbours {
                    for &(j, w) in row_of(u) {
                        sum.add(j, share * w);
                    }
                }
                sum.drain_into(out);
            },
        );
    }
    for (k, &v) in members.iter().enumerate() {
        rows[v].clear();
        rows[v].extend_from_slice(current.row(k));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The rounds as first written, each row merged by sorting its pieces (the reference
    /// [`smooth`] is compared with).
    fn smooth_reference(
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
                crate::transfer::closest_point::merge_joints(slot);
            }
            for (slot, &v) in next.iter_mut().zip(&members) {
                std::mem::swap(&mut rows[v], slot);
            }
        }
    }

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
        smooth(&topology, &[true, false, false], &mut rows, 2, 1, 0.2);
        assert_eq!(rows[0].len(), 2);
        assert!((rows[0][0].1 - 0.8).abs() < 1e-12 && (rows[0][1].1 - 0.2).abs() < 1e-12);
        assert_eq!(rows[1], vec![(1, 1.0)]);
    }

    /// On a sphere with rows of two to four of eight joints, the zone its upper half: the
    /// summed rows equal the reference's (sums in another order: within 1e-12).
    #[test]
    fn smoothing_equals_the_reference() {
        let mesh = crate::fixtures::shapes::uv_sphere(1.0, 24, 32);
        let topology = Topology::new(&mesh);
        let rows: Vec<Vec<(u32, f64)>> = mesh
            .positions
            .iter()
            .enumerate()
            .map(|(v, p)| {
                let count = 2 + v % 3;
                let mut row: Vec<(u32, f64)> = (0..count)
                    .map(|k| (((v * 5 + k * 3) % 8) as u32, 1.0 + p.x.abs() + k as f64))
                    .collect();
                crate::transfer::closest_point::merge_joints(&mut row);
                crate::transfer::closest_point::normalise(&mut row);
                row
            })
            .collect();
        let zone: Vec<bool> = mesh.positions.iter().map(|p| p.z > 0.0).collect();
        let (mut fast, mut reference) = (rows.clone(), rows);
        smooth(&topology, &zone, &mut fast, 8, 10, 0.2);
        smooth_reference(&topology, &zone, &mut reference, 10, 0.2);
        for (a, b) in fast.iter().zip(&reference) {
            assert_eq!(a.len(), b.len());
            for (x, y) in a.iter().zip(b) {
                assert!(x.0 == y.0 && (x.1 - y.1).abs() < 1e-12, "{a:?} {b:?}");
            }
        }
    }
}

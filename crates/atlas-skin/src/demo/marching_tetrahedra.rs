//! Isosurface extraction by marching tetrahedra (Doi & Koide 1991) on a regular grid.
//!
//! Every grid cube is split into six tetrahedra around its main diagonal (the Kuhn
//! triangulation), which neighbouring cubes share face for face, so the surface is closed and
//! manifold wherever the field is negative inside a bounded region: no ambiguous cases as in
//! marching cubes. Grid values of exactly zero count as outside (a consistent sign rule), so
//! every crossing lies strictly inside its edge. Triangles are first oriented per
//! tetrahedron towards the outside corners, then made consistent across the surface by a
//! walk over shared edges (a nearly flat triangle can defeat the local test), and finally
//! turned outward by the sign of the enclosed volume.

use glam::DVec3;
use std::collections::HashMap;

/// A regular grid: `counts` points per axis from `origin`, spacing `step`.
#[derive(Debug, Clone, Copy)]
pub struct Grid {
    pub origin: DVec3,
    pub step: f64,
    pub counts: [usize; 3],
}

impl Grid {
    fn point(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.step
    }

    fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.counts[1] + j) * self.counts[0] + i
    }
}

/// Cube corner offsets of the six Kuhn tetrahedra: each is the path from corner (0,0,0) to
/// (1,1,1) that steps along the axes in one of the six orders.
const KUHN_TETRAHEDRA: [[[usize; 3]; 4]; 6] = [
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1]],
    [[0, 0, 0], [1, 0, 0], [1, 0, 1], [1, 1, 1]],
    [[0, 0, 0], [0, 1, 0], [1, 1, 0], [1, 1, 1]],
    [[0, 0, 0], [0, 1, 0], [0, 1, 1], [1, 1, 1]],
    [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1]],
    [[0, 0, 0], [0, 0, 1], [0, 1, 1], [1, 1, 1]],
];

/// Extracts the surface {p : field(p) = 0} of a field that is negative inside, sampled on
/// `grid`. Triangles are oriented with normals pointing to positive values (outward).
/// Returns (positions, triangles); vertices are shared between triangles.
pub fn extract(grid: &Grid, field: impl Fn(DVec3) -> f64 + Sync) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    use rayon::prelude::*;
    let [nx, ny, nz] = grid.counts;
    let values: Vec<f64> = (0..nx * ny * nz)
        .into_par_iter()
        .map(|idx| {
            let (i, j, k) = (idx % nx, (idx / nx) % ny, idx / (nx * ny));
            let v = field(grid.point(i, j, k));
            if v == 0.0 {
                f64::MIN_POSITIVE
            } else {
                v
            }
        })
        .collect();

    let mut positions: Vec<DVec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut edge_vertex: HashMap<(usize, usize), u32> = HashMap::new();
    let mut crossing = |a: usize, b: usize, pa: DVec3, pb: DVec3, positions: &mut Vec<DVec3>| {
        let key = (a.min(b), a.max(b));
        *edge_vertex.entry(key).or_insert_with(|| {
            let (fa, fb) = (values[a], values[b]);
            let t = fa / (fa - fb);
            positions.push(pa + (pb - pa) * t);
            positions.len() as u32 - 1
        })
    };
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                for tet in &KUHN_TETRAHEDRA {
                    let ids = tet.map(|o| grid.index(i + o[0], j + o[1], k + o[2]));
                    let pts = tet.map(|o| grid.point(i + o[0], j + o[1], k + o[2]));
                    let inside: Vec<usize> = (0..4).filter(|&c| values[ids[c]] < 0.0).collect();
                    let outside: Vec<usize> = (0..4).filter(|&c| values[ids[c]] >= 0.0).collect();
                    if inside.is_empty() || outside.is_empty() {
                        continue;
                    }
                    let centroid =
                        |cs: &[usize]| cs.iter().map(|&c| pts[c]).sum::<DVec3>() / cs.len() as f64;
                    let outward = centroid(&outside) - centroid(&inside);
                    let mut cross = |a: usize, b: usize| {
                        crossing(ids[a], ids[b], pts[a], pts[b], &mut positions)
                    };
                    let polygon: Vec<u32> = match (inside.len(), outside.len()) {
                        (1, _) => outside.iter().map(|&o| cross(inside[0], o)).collect(),
                        (_, 1) => inside.iter().map(|&i| cross(i, outside[0])).collect(),
                        _ => {
                            let (i0, i1, o0, o1) = (inside[0], inside[1], outside[0], outside[1]);
                            vec![cross(i0, o0), cross(i0, o1), cross(i1, o1), cross(i1, o0)]
                        }
                    };
                    for t in 1..polygon.len() - 1 {
                        let mut tri = [polygon[0], polygon[t], polygon[t + 1]];
                        let [a, b, c] = tri.map(|v| positions[v as usize]);
                        if (b - a).cross(c - a).dot(outward) < 0.0 {
                            tri.swap(1, 2);
                        }
                        triangles.push(tri);
                    }
                }
            }
        }
    }
    orient_consistently(&positions, &mut triangles);
    (positions, triangles)
}

/// Flips triangles so that every manifold edge is traversed in opposite directions by its
/// two faces (breadth-first over each component from its first face), then flips whole
/// components whose signed volume Σ a·(b×c)/6 is negative.
fn orient_consistently(positions: &[DVec3], triangles: &mut [[u32; 3]]) {
    let mut faces_of_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            faces_of_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(f);
        }
    }
    let has_directed =
        |t: &[u32; 3], a: u32, b: u32| (0..3).any(|i| t[i] == a && t[(i + 1) % 3] == b);
    let mut visited = vec![false; triangles.len()];
    for start in 0..triangles.len() {
        if visited[start] {
            continue;
        }
        visited[start] = true;
        let mut component = vec![start];
        let mut queue = std::collections::VecDeque::from([start]);
        while let Some(f) = queue.pop_front() {
            let t = triangles[f];
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                let neighbours = &faces_of_edge[&(a.min(b), a.max(b))];
                if neighbours.len() != 2 {
                    continue;
                }
                for &g in neighbours {
                    if g == f || visited[g] {
                        continue;
                    }
                    if has_directed(&triangles[g], a, b) {
                        triangles[g].swap(1, 2);
                    }
                    visited[g] = true;
                    component.push(g);
                    queue.push_back(g);
                }
            }
        }
        let volume: f64 = component
            .iter()
            .map(|&f| {
                let [a, b, c] = triangles[f].map(|v| positions[v as usize]);
                a.dot(b.cross(c))
            })
            .sum();
        if volume < 0.0 {
            for &f in &component {
                triangles[f].swap(1, 2);
            }
        }
    }
}

/// Test fixtures shared by the demo's tests.
#[cfg(test)]
pub(crate) mod fixtures {
    use super::{extract, Grid};
    use crate::{MeshStats, SurfaceMesh, Topology};
    use glam::DVec3;

    /// The unit sphere by marching tetrahedra on a grid of spacing `step` around it.
    pub fn unit_sphere(step: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let count = (2.6 / step).ceil() as usize + 1;
        let grid = Grid {
            origin: DVec3::splat(-1.3),
            step,
            counts: [count; 3],
        };
        extract(&grid, |p| p.length() - 1.0)
    }

    /// Asserts that the surface is one closed, consistently oriented sphere.
    pub fn assert_closed_sphere(mesh: &SurfaceMesh) {
        let stats = MeshStats::new(mesh, &Topology::new(mesh));
        assert!(stats.closed);
        assert_eq!(stats.genus, Some(0));
        assert_eq!(stats.components, 1);
        assert_eq!(stats.inconsistently_oriented_edges, 0);
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::{assert_closed_sphere, unit_sphere};
    use crate::SurfaceMesh;
    use glam::DVec3;

    #[test]
    fn sphere_is_closed_genus_zero_and_outward() {
        let (positions, triangles) = unit_sphere(0.1);
        let mesh = SurfaceMesh {
            positions,
            triangles,
        };
        assert_closed_sphere(&mesh);
        assert!(crate::winding::winding_number(&mesh, DVec3::ZERO) > 0.99);
        for p in &mesh.positions {
            assert!((p.length() - 1.0).abs() < 0.02);
        }
    }
}

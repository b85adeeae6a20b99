//! The cotangent Laplacian and the Voronoi mass matrix of a triangle surface, the two
//! operators of the inpainting energy ([`super::inpaint`]).
//!
//! **Laplacian** (Pinkall and Polthier 1993; Meyer, Desbrun, Schröder, Barr 2003, Eq. 8):
//! for an edge ij with opposite angles α_ij and β_ij in its one or two faces,
//! L_ij = cot α_ij + cot β_ij, and L_ii = −Σ_j L_ij (symmetric, negative semi-definite,
//! rows summing to 0). This is twice libigl's `cotmatrix`, the scale the paper's reference
//! implementation uses (`L = 2 * igl.cotmatrix(V, F)`).
//!
//! **Mass** (Meyer et al. 2003, §3.3, the "mixed" Voronoi area, libigl's
//! `MASSMATRIX_TYPE_VORONOI`): each face of area A gives its corner i
//! (|e_ij|² cot ∠k + |e_ik|² cot ∠j) / 8 when no angle of the face is obtuse, else A/2 when
//! the obtuse angle is at i and A/4 when it is elsewhere; M is diagonal, M_ii the sum over
//! the faces around i (the areas of the faces partitioned among their corners).
//!
//! A face of zero area (a repeated corner, collinear corners) contributes nothing to
//! either: its angles are undefined. A vertex whose faces all have zero area has an empty
//! Laplacian row and mass 0.

use crate::mesh::{SurfaceMesh, Topology};
use crate::rows::Rows;
use crate::tolerance::FLAT;
use glam::DVec3;

/// The cotangent Laplacian as rows of off-diagonal entries `(j, L_ij)` (every neighbour
/// j ≠ i by an edge of positive-area faces, once), with the diagonal apart, and the
/// Voronoi mass of every vertex.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Operators {
    /// Row i: `(j, L_ij)` for the neighbours j of i, ascending j.
    pub off_diagonal: Rows<(u32, f64)>,
    /// L_ii = −Σ_j L_ij.
    pub diagonal: Vec<f64>,
    /// M_ii.
    pub mass: Vec<f64>,
}

/// cot of the angle between `a` and `b` (non-zero vectors): a·b / |a × b|.
fn cot(a: DVec3, b: DVec3) -> f64 {
    a.dot(b) / a.cross(b).length()
}

impl Operators {
    /// The operators of `mesh` with its `topology`, in O(V + F): each face's cotangents
    /// summed on its edges (`Topology::face_edges`), the rows then read off the edges in
    /// their order (a, b) ascending, which lists every vertex's neighbours ascending.
    pub fn new(mesh: &SurfaceMesh, topology: &Topology) -> Self {
        let n = mesh.vertex_count();
        let mut mass = vec![0.0; n];
        // Per edge: Σ cot of the angles opposite it, and whether a face gave it one.
        let mut edge_cot = vec![0.0; topology.edges.len()];
        let mut edge_used = vec![false; topology.edges.len()];
        for (f, t) in mesh.triangles.iter().enumerate() {
            let Some(cots) = face_cotangents(mesh, f) else {
                continue;
            };
            for (i, &cot_i) in cots.iter().enumerate() {
                // The edge opposite corner i runs from corner i + 1 to corner i + 2.
                let e = topology.face_edges[f][(i + 1) % 3] as usize;
                edge_cot[e] += cot_i;
                edge_used[e] = true;
            }
            add_face_mass(mesh, f, t, &cots, &mut mass);
        }
        let entries = topology
            .edges
            .iter()
            .zip(edge_cot.iter().zip(&edge_used))
            .filter(|(_, (_, &used))| used)
            .flat_map(|(&[a, b], (&w, _))| [(a as usize, (b, w)), (b as usize, (a, w))]);
        let off_diagonal = Rows::group(n, entries);
        let diagonal = (0..n)
            .map(|i| -off_diagonal.row(i).iter().map(|&(_, w)| w).sum::<f64>())
            .collect();
        Self {
            off_diagonal,
            diagonal,
            mass,
        }
    }

    /// L_ij (0 when i and j share no edge).
    pub fn laplacian(&self, i: usize, j: usize) -> f64 {
        if i == j {
            return self.diagonal[i];
        }
        let row = self.off_diagonal.row(i);
        row.binary_search_by_key(&(j as u32), |&(k, _)| k)
            .map_or(0.0, |slot| row[slot].1)
    }
}

/// The cotangents of face `f`'s three angles (corner i's between its edges to the two
/// other corners), `None` for a face of zero area (a repeated corner, or
/// |e₁ × e₂| ≤ FLAT · the longest squared edge).
fn face_cotangents(mesh: &SurfaceMesh, f: usize) -> Option<[f64; 3]> {
    let t = mesh.triangles[f];
    let p = mesh.corners(f);
    let double_area = mesh.scaled_normal(f).length();
    let longest = (0..3)
        .map(|i| p[i].distance_squared(p[(i + 1) % 3]))
        .fold(0.0, f64::max);
    if double_area.is_nan()
        || double_area <= FLAT * longest
        || t[0] == t[1]
        || t[1] == t[2]
        || t[0] == t[2]
    {
        return None;
    }
    Some(std::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        cot(p[j] - p[i], p[k] - p[i])
    }))
}

/// Adds face `f`'s mixed Voronoi areas (the module's formula) to its corners' masses.
fn add_face_mass(mesh: &SurfaceMesh, f: usize, t: &[u32; 3], cots: &[f64; 3], mass: &mut [f64]) {
    let p = mesh.corners(f);
    let area = 0.5 * mesh.scaled_normal(f).length();
    let obtuse = (0..3).find(|&i| cots[i] < 0.0);
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        mass[t[i] as usize] += match obtuse {
            None => {
                (p[i].distance_squared(p[j]) * cots[k] + p[i].distance_squared(p[k]) * cots[j])
                    / 8.0
            }
            Some(o) if o == i => area / 2.0,
            Some(_) => area / 4.0,
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::shapes::quad_grid;

    /// The operators assembled as first written (the reference [`Operators::new`]'s
    /// summing on the edges is compared with): every face's cotangents as entries
    /// (i, j, cot), sorted and merged.
    fn by_sorting(mesh: &SurfaceMesh) -> Operators {
        let n = mesh.vertex_count();
        let mut mass = vec![0.0; n];
        let mut entries: Vec<(u32, u32, f64)> = Vec::with_capacity(6 * mesh.triangle_count());
        for (f, t) in mesh.triangles.iter().enumerate() {
            let Some(cots) = face_cotangents(mesh, f) else {
                continue;
            };
            for (i, &cot_i) in cots.iter().enumerate() {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                // The edge jk is opposite corner i.
                entries.push((t[j], t[k], cot_i));
                entries.push((t[k], t[j], cot_i));
            }
            add_face_mass(mesh, f, t, &cots, &mut mass);
        }
        entries.sort_unstable_by_key(|&(i, j, _)| (i, j));
        let mut merged: Vec<(u32, u32, f64)> = Vec::with_capacity(entries.len());
        for (i, j, w) in entries {
            match merged.last_mut() {
                Some(last) if last.0 == i && last.1 == j => last.2 += w,
                _ => merged.push((i, j, w)),
            }
        }
        let off_diagonal = Rows::group(n, merged.iter().map(|&(i, j, w)| (i as usize, (j, w))));
        let diagonal = (0..n)
            .map(|i| -off_diagonal.row(i).iter().map(|&(_, w)| w).sum::<f64>())
            .collect();
        Operators {
            off_diagonal,
            diagonal,
            mass,
        }
    }

    fn mesh(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> SurfaceMesh {
        SurfaceMesh {
            positions: positions.iter().map(|&p| DVec3::from_array(p)).collect(),
            triangles: triangles.to_vec(),
        }
    }

    /// A right isosceles triangle: cot 90° = 0, cot 45° = 1; the obtuse-free masses are
    /// the Voronoi areas (1/4 at the right angle, 1/8 at the others: total 1/2).
    #[test]
    fn right_triangle_has_known_cotangents_and_masses() {
        let m = mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0, 1, 2]],
        );
        let ops = Operators::new(&m, &Topology::new(&m));
        assert!((ops.laplacian(1, 2) - 0.0).abs() < 1e-12);
        assert!((ops.laplacian(0, 1) - 1.0).abs() < 1e-12);
        assert!((ops.laplacian(0, 2) - 1.0).abs() < 1e-12);
        assert!((ops.laplacian(0, 0) + 2.0).abs() < 1e-12);
        assert!((ops.mass[0] - 0.25).abs() < 1e-12);
        assert!((ops.mass[1] - 0.125).abs() < 1e-12);
        assert!((ops.mass[2] - 0.125).abs() < 1e-12);
    }

    /// An obtuse triangle: half its area to the obtuse corner, a quarter to each other.
    #[test]
    fn obtuse_triangle_splits_its_area_by_halves_and_quarters() {
        let m = mesh(
            &[[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [2.0, 0.5, 0.0]],
            &[[0, 1, 2]],
        );
        let ops = Operators::new(&m, &Topology::new(&m));
        let area = 1.0;
        assert!((ops.mass[2] - area / 2.0).abs() < 1e-12);
        assert!((ops.mass[0] - area / 4.0).abs() < 1e-12);
        assert!((ops.mass[1] - area / 4.0).abs() < 1e-12);
    }

    /// On a planar grid the Laplacian of a linear function vanishes at interior vertices,
    /// the masses sum to the area, and L is symmetric.
    #[test]
    fn linear_functions_are_harmonic_on_a_plane() {
        let (nx, ny) = (6u32, 5u32);
        let mut positions = Vec::new();
        for y in 0..ny {
            for x in 0..nx {
                // Sheared so that the triangles are not all alike.
                positions.push([x as f64 + 0.3 * y as f64, y as f64 * 0.8, 0.0]);
            }
        }
        let mut triangles = Vec::new();
        let index = |y: usize, x: usize| y as u32 * nx + x as u32;
        quad_grid((ny - 1) as usize, (nx - 1) as usize, index, &mut triangles);
        let m = mesh(&positions, &triangles);
        let ops = Operators::new(&m, &Topology::new(&m));
        let f = |p: DVec3| 2.0 * p.x - 3.0 * p.y + 1.0;
        for y in 1..ny - 1 {
            for x in 1..nx - 1 {
                let i = (y * nx + x) as usize;
                let lf = ops.diagonal[i] * f(m.positions[i])
                    + ops
                        .off_diagonal
                        .row(i)
                        .iter()
                        .map(|&(j, w)| w * f(m.positions[j as usize]))
                        .sum::<f64>();
                assert!(lf.abs() < 1e-10, "vertex {i}: {lf}");
            }
        }
        let area: f64 = (0..m.triangle_count()).map(|f| m.triangle_area(f)).sum();
        assert!((ops.mass.iter().sum::<f64>() - area).abs() < 1e-10);
        for i in 0..m.vertex_count() {
            for &(j, w) in ops.off_diagonal.row(i) {
                assert!((ops.laplacian(j as usize, i) - w).abs() < 1e-12);
            }
        }
    }

    /// A face of zero area gives nothing: no row, no mass, no NaN.
    #[test]
    fn degenerate_faces_contribute_nothing() {
        let m = mesh(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            &[[0, 1, 2], [0, 1, 3], [1, 1, 3]],
        );
        let ops = Operators::new(&m, &Topology::new(&m));
        assert_eq!(ops.mass[2], 0.0);
        assert!(ops.off_diagonal.row(2).is_empty());
        assert!(ops.mass.iter().all(|m| m.is_finite()));
        assert!(ops.diagonal.iter().all(|d| d.is_finite()));
    }

    /// The operators summed on the edges equal the reference's (sums of three or more
    /// cotangents, on a non-manifold edge, in another order: within 1e-12), on a sphere,
    /// and on a fan with a non-manifold edge and a degenerate face.
    #[test]
    fn operators_equal_the_reference() {
        let fan = mesh(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.3, 1.0, 0.0],
                [0.5, -0.8, 0.2],
                [0.4, 0.1, 0.9],
                [2.0, 0.0, 0.0],
            ],
            &[[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 5, 5], [0, 1, 5]],
        );
        for m in [crate::fixtures::shapes::uv_sphere(1.0, 12, 16), fan] {
            let fast = Operators::new(&m, &Topology::new(&m));
            let reference = by_sorting(&m);
            assert_eq!(fast.mass, reference.mass);
            assert_eq!(fast.off_diagonal.offsets, reference.off_diagonal.offsets);
            for (a, b) in fast
                .off_diagonal
                .values
                .iter()
                .zip(&reference.off_diagonal.values)
            {
                assert!(a.0 == b.0 && (a.1 - b.1).abs() <= 1e-12, "{a:?} {b:?}");
            }
            for (a, b) in fast.diagonal.iter().zip(&reference.diagonal) {
                assert!((a - b).abs() <= 1e-12);
            }
        }
    }
}

//! Distances along the surface from a set of source vertices, computed only up to a cutoff
//! (the overlap bands of §3.3 never need more).
//!
//! Method: fast marching on triangle meshes (Kimmel & Sethian 1998, "Computing geodesic
//! paths on manifolds", PNAS 95(15), doi:10.1073/pnas.95.15.8431). Vertices are frozen in
//! increasing order of distance, as in Dijkstra's algorithm, but a vertex x is updated from
//! a triangle (x, a, b) whose corners a, b are frozen by a planar wavefront through
//! (a, T_a) and (b, T_b) instead of along the edges. The update (§"triangulated domains"):
//! find T_x such that the linear function T(p) = T_x + g·(p − x) on the triangle's plane
//! takes the values T_a, T_b at a, b with |g| = 1, i.e. with e = (1, 1), u = (T_a, T_b),
//! Q the Gram matrix of (a − x, b − x) and P = Q⁻¹:
//!
//! (eᵀPe) T_x² − 2 (eᵀPu) T_x + (uᵀPu − 1) = 0, larger root,
//!
//! accepted only when the wave comes from inside the triangle (−g in the cone of a − x and
//! b − x). Otherwise the edge updates T_a + |a − x|, T_b + |b − x| apply. An obtuse angle at
//! x is split, as the paper prescribes, by unfolding the triangle across the opposite edge
//! into the plane of (x, a, b) until a vertex falls inside the angle; the update then uses
//! the two acute halves.
//!
//! Measured error (tests/geodesic_sphere.rs, distance from one vertex of an icosphere
//! against the great-circle distance, vertices beyond 18° from the source): mean relative
//! error 1.4% at 2,562 vertices and 0.9% at 10,242; exact (1e-9) for a straight source
//! line on a flat grid. `cargo test -p atlas-skin --release --test geodesic_sphere --
//! --nocapture` prints the figures.

use crate::mesh::edge_distance::Nearest;
use crate::mesh::{SurfaceMesh, Topology};
use crate::tolerance::FLAT;
use glam::DVec3;
use std::collections::BinaryHeap;

/// Unfolding steps tried when splitting an obtuse angle before falling back to edges.
const MAX_UNFOLD_STEPS: usize = 4;

/// Vertices reached within the cutoff and their distances, in increasing distance.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BandDistances {
    /// #reached vertex indices.
    pub vertices: Vec<u32>,
    /// #reached distances, ascending, each ≤ the cutoff.
    pub distances: Vec<f64>,
}

/// Per-vertex working memory of [`march_distances`], owned by the caller so that repeated
/// calls (one per boundary) allocate nothing once warm. Between calls every entry is reset.
#[derive(Debug, Clone, Default)]
pub struct MarchScratch {
    distance: Vec<f64>,
    frozen: Vec<bool>,
    touched: Vec<u32>,
    heap: BinaryHeap<Nearest<u32>>,
}

impl MarchScratch {
    /// Scratch for a surface of `vertex_count` vertices.
    pub fn new(vertex_count: usize) -> Self {
        Self {
            distance: vec![f64::INFINITY; vertex_count],
            frozen: vec![false; vertex_count],
            touched: Vec::new(),
            heap: BinaryHeap::new(),
        }
    }

    fn reset(&mut self) {
        for &v in &self.touched {
            self.distance[v as usize] = f64::INFINITY;
            self.frozen[v as usize] = false;
        }
        self.touched.clear();
        self.heap.clear();
    }

    fn offer(&mut self, v: u32, d: f64) {
        let slot = &mut self.distance[v as usize];
        if d < *slot {
            if slot.is_infinite() {
                self.touched.push(v);
            }
            *slot = d;
            self.heap.push(Nearest {
                distance: d,
                key: v,
            });
        }
    }
}

/// Geodesic distance from `sources` (distance 0) to every vertex of `mesh` within
/// `cutoff`, by fast marching (see the module documentation).
///
/// - `mesh`, `topology`: the surface and its topology (#V vertices).
/// - `sources`: source vertex indices, each `< #V`; repeated entries are harmless.
/// - `cutoff`: largest distance computed; vertices farther away are not listed.
/// - `scratch`: working memory for #V vertices ([`MarchScratch::new`]); it is grown when
///   smaller and left reset.
///
/// The march crosses every edge, manifold or not; disconnected pieces are never reached.
pub fn march_distances(
    mesh: &SurfaceMesh,
    topology: &Topology,
    sources: &[u32],
    cutoff: f64,
    scratch: &mut MarchScratch,
) -> BandDistances {
    let vertex_count = mesh.vertex_count();
    if scratch.distance.len() < vertex_count {
        *scratch = MarchScratch::new(vertex_count);
    }
    let mut band = BandDistances::default();
    for &s in sources {
        scratch.offer(s, 0.0);
    }
    while let Some(Nearest {
        distance,
        key: vertex,
    }) = scratch.heap.pop()
    {
        let v = vertex as usize;
        if scratch.frozen[v] || distance > scratch.distance[v] {
            continue;
        }
        if distance > cutoff {
            break;
        }
        scratch.frozen[v] = true;
        band.vertices.push(vertex);
        band.distances.push(distance);
        for &f in topology.faces_of_vertex(v) {
            let t = mesh.triangles[f as usize];
            for (i, &x) in t.iter().enumerate() {
                if scratch.frozen[x as usize] {
                    continue;
                }
                let (a, b) = (t[(i + 1) % 3], t[(i + 2) % 3]);
                let d = triangle_update(mesh, topology, f as usize, x, a, b, scratch);
                if d.is_finite() {
                    scratch.offer(x, d);
                }
            }
        }
    }
    scratch.reset();
    band
}

/// Smallest arrival time at `x` through triangle `face` = (x, a, b) from its frozen
/// corners, splitting an obtuse angle at x by unfolding.
fn triangle_update(
    mesh: &SurfaceMesh,
    topology: &Topology,
    face: usize,
    x: u32,
    a: u32,
    b: u32,
    scratch: &MarchScratch,
) -> f64 {
    let known = |v: u32| scratch.frozen[v as usize].then(|| scratch.distance[v as usize]);
    let px = mesh.positions[x as usize];
    let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
    let (ta, tb) = (known(a), known(b));
    let mut best = f64::INFINITY;
    for (t, p) in [(ta, pa), (tb, pb)] {
        if let Some(t) = t {
            best = best.min(t + p.distance(px));
        }
    }
    let (Some(ta), Some(tb)) = (ta, tb) else {
        return best;
    };
    let (ea, eb) = (pa - px, pb - px);
    if ea.dot(eb) >= 0.0 {
        return best.min(planar_update(ea, eb, ta, tb));
    }
    // Obtuse at x: unfold across the opposite edge until a vertex c lies inside the angle.
    // `left`/`right` hold (vertex, position unfolded into the plane of x, a, b).
    let normal = ea.cross(eb);
    let (mut left, mut right) = ((a, pa), (b, pb));
    let mut across = face;
    for _ in 0..MAX_UNFOLD_STEPS {
        let Some((next_face, c)) = opposite_face(mesh, topology, across, left.0, right.0) else {
            break;
        };
        let hinge = [left.0, right.0].map(|v| mesh.positions[v as usize]);
        let pc = unfold(hinge, mesh.positions[c as usize], [left.1, right.1], px);
        let ec = pc - px;
        let after_left = ea.cross(ec).dot(normal) >= 0.0;
        let before_right = ec.cross(eb).dot(normal) >= 0.0;
        if after_left && before_right {
            if let Some(tc) = known(c) {
                best = best
                    .min(planar_update(ea, ec, ta, tc))
                    .min(planar_update(ec, eb, tc, tb));
            }
            return best;
        }
        across = next_face;
        if after_left {
            right = (c, pc);
        } else {
            left = (c, pc);
        }
    }
    best
}

/// The face other than `face` across edge (u, v) and its third vertex, when the edge is
/// manifold.
fn opposite_face(
    mesh: &SurfaceMesh,
    topology: &Topology,
    face: usize,
    u: u32,
    v: u32,
) -> Option<(usize, u32)> {
    let t = mesh.triangles[face];
    let edge = (0..3)
        .find(|&i| {
            let (p, q) = (t[i], t[(i + 1) % 3]);
            (p == u && q == v) || (p == v && q == u)
        })
        .map(|i| topology.face_edges[face][i] as usize)?;
    let faces = topology.faces_of_edge(edge);
    if faces.len() != 2 {
        return None;
    }
    let other = if faces[0] as usize == face {
        faces[1]
    } else {
        faces[0]
    } as usize;
    let c = mesh.triangles[other]
        .into_iter()
        .find(|&w| w != u && w != v)?;
    Some((other, c))
}

/// Hinge unfolding: where `c`, the apex of the triangle across the edge `hinge` (3D
/// positions), lands when that triangle is rotated about the edge into the plane of x,
/// given the edge's already unfolded positions `flat_hinge` in that plane. It lands on the
/// side of the edge opposite to x, at the same distance from the edge and the same foot
/// along it.
fn unfold(hinge: [DVec3; 2], c: DVec3, flat_hinge: [DVec3; 2], x: DVec3) -> DVec3 {
    let axis = (hinge[1] - hinge[0]).normalize_or_zero();
    let along = (c - hinge[0]).dot(axis);
    let height = (c - hinge[0] - axis * along).length();
    let flat_axis = (flat_hinge[1] - flat_hinge[0]).normalize_or_zero();
    let foot_c = flat_hinge[0] + flat_axis * along;
    let foot_x = flat_hinge[0] + flat_axis * (x - flat_hinge[0]).dot(flat_axis);
    let away = (foot_x - x).normalize_or_zero();
    foot_c + away * height
}

/// The planar-wavefront arrival time at the origin x from corners at offsets `ea`, `eb`
/// with times `ta`, `tb` (module documentation), or ∞ when the wave does not enter through
/// the triangle or the triangle is degenerate.
fn planar_update(ea: DVec3, eb: DVec3, ta: f64, tb: f64) -> f64 {
    let (aa, ab, bb) = (ea.dot(ea), ea.dot(eb), eb.dot(eb));
    let det = aa * bb - ab * ab;
    if det <= FLAT * aa * bb {
        return f64::INFINITY;
    }
    // P = Q⁻¹ = [[bb, −ab], [−ab, aa]] / det.
    let apply = |r0: f64, r1: f64| ((bb * r0 - ab * r1) / det, (aa * r1 - ab * r0) / det);
    let (pe0, pe1) = apply(1.0, 1.0);
    let (pu0, pu1) = apply(ta, tb);
    let e_pe = pe0 + pe1;
    let e_pu = pu0 + pu1;
    let u_pu = ta * pu0 + tb * pu1;
    let discriminant = e_pu * e_pu - e_pe * (u_pu - 1.0);
    if e_pe <= 0.0 || discriminant < 0.0 {
        return f64::INFINITY;
    }
    let t = (e_pu + discriminant.sqrt()) / e_pe;
    // g = c₀ ea + c₁ eb with c = P (u − t e); the wave enters through the triangle when
    // −g lies in the cone of ea and eb, i.e. c ≤ 0.
    let (c0, c1) = apply(ta - t, tb - t);
    if t < ta.max(tb) || c0 > 0.0 || c1 > 0.0 {
        return f64::INFINITY;
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planar_update_is_exact_for_a_plane_wave() {
        // Wave travelling along +y with T = y + 1; x at the origin is reached at T = 1 from
        // corners below it.
        let (ea, eb) = (DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, -0.5, 0.0));
        let t = planar_update(ea, eb, 0.0, 0.5);
        assert!((t - 1.0).abs() < 1e-12, "{t}");
    }

    #[test]
    fn planar_update_rejects_a_wave_arriving_from_outside_the_triangle() {
        // Wave along +y (T = y + 1): both corners lie at y = −1, to the lower right of x,
        // but the characteristic through x comes from straight below, outside the triangle.
        let (ea, eb) = (DVec3::new(1.0, -1.0, 0.0), DVec3::new(2.0, -1.0, 0.0));
        assert!(planar_update(ea, eb, 0.0, 0.0).is_infinite());
        // With corners on both sides of the vertical, the same wave enters through it.
        assert!(planar_update(DVec3::new(-1.0, -1.0, 0.0), eb, 0.0, 0.0).is_finite());
    }

    #[test]
    fn unfolding_puts_the_vertex_across_the_hinge() {
        let (u, v) = (DVec3::ZERO, DVec3::X);
        let c = DVec3::new(0.5, 0.0, 1.0);
        let x = DVec3::new(0.5, 1.0, 0.0);
        let unfolded = unfold([u, v], c, [u, v], x);
        assert!(unfolded.abs_diff_eq(DVec3::new(0.5, -1.0, 0.0), 1e-12));
    }
}

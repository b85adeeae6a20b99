//! Inserting cut curves into the surface as chains of edges (METHOD.md failure 1: marking
//! the intersected triangles as boundary faces swallows coarse meshes; splitting them keeps
//! the regions separated by the exact curve).
//!
//! The curves must not cross or touch (the conflict rule of [`crate::decompose()`]), but
//! several may pass through one face, as on a coarse mesh. Each face becomes the polygon of
//! its corners and the curve points on its edges (in boundary order), cut along every chord
//! a curve draws in it; chords that do not cross split a convex polygon into convex
//! pieces, each fanned into triangles from a corner that makes no zero-area triangle (or
//! from a new centre vertex when no corner does). Orientation is kept; faces no curve
//! meets are copied.

use crate::cuts::plane_section::{CrossingPoint, SectionCurve};
use crate::mesh::{SurfaceMesh, Topology};
use crate::tolerance::FLAT;

/// The surface with the curves inserted.
#[derive(Debug, Clone)]
pub struct SplitSurface {
    /// The input vertices unchanged and in order, then one new vertex per interior
    /// crossing (and a centre vertex for a rare polygon no corner can fan); every input
    /// face replaced by its pieces, in input face order.
    pub mesh: SurfaceMesh,
    /// Per curve, its closed loop of `mesh` vertices (consecutive ones joined by an edge).
    pub loops: Vec<Vec<u32>>,
}

/// Splits `mesh` (with its `topology`) along closed `curves` that neither cross nor touch.
/// O(V + F + curve points · log).
pub fn split_along_curves(
    mesh: &SurfaceMesh,
    topology: &Topology,
    curves: &[&SectionCurve],
) -> SplitSurface {
    let mut positions = mesh.positions.clone();
    // Every interior crossing as (crossed edge, t from edges[e][0], new vertex), and every
    // chord as (face, its vertex pairs on the split surface), in the curves' order; sorted
    // by edge and face below (stably: each edge's points and each face's chords keep that
    // order), they are looked up as runs instead of a list per edge and per face.
    let mut edge_points: Vec<(u32, f64, u32)> = Vec::new();
    let mut face_chords: Vec<(u32, [u32; 2])> = Vec::new();
    let mut loops = Vec::with_capacity(curves.len());
    for curve in curves {
        let vertices: Vec<u32> = curve
            .crossings
            .iter()
            .map(|crossing| match crossing.point {
                CrossingPoint::Vertex(v) => v,
                CrossingPoint::Interior(t) => {
                    let [a, b] = topology.edges[crossing.edge as usize];
                    positions.push(positions[a as usize].lerp(positions[b as usize], t));
                    let v = positions.len() as u32 - 1;
                    edge_points.push((crossing.edge, t, v));
                    v
                }
            })
            .collect();
        let n = vertices.len();
        for (i, &face) in curve.faces.iter().enumerate() {
            let (a, b) = (vertices[i], vertices[(i + 1) % n]);
            if a != b {
                face_chords.push((face, [a, b]));
            }
        }
        let mut curve_loop = vertices;
        curve_loop.dedup();
        if curve_loop.len() > 1 && curve_loop.first() == curve_loop.last() {
            curve_loop.pop();
        }
        loops.push(curve_loop);
    }
    edge_points.sort_by_key(|&(e, _, _)| e);
    face_chords.sort_by_key(|&(f, _)| f);
    let points_on = |e: u32| {
        let start = edge_points.partition_point(|p| p.0 < e);
        let end = start + edge_points[start..].partition_point(|p| p.0 == e);
        &edge_points[start..end]
    };

    // The faces a curve meets: those with a chord or around an edge with a new point (the
    // others are copied without a look-up).
    let mut met = vec![false; mesh.triangle_count()];
    for &(e, _, _) in &edge_points {
        for &f in topology.faces_of_edge(e as usize) {
            met[f as usize] = true;
        }
    }
    for &(f, _) in &face_chords {
        met[f as usize] = true;
    }
    let edges_with_points = edge_points.chunk_by(|x, y| x.0 == y.0).count();
    let mut triangles = Vec::with_capacity(mesh.triangle_count() + 4 * edges_with_points);
    // The faces' chords in face order, taken run by run as the faces are.
    let mut chords = face_chords.chunk_by(|x, y| x.0 == y.0).peekable();
    let mut along: Vec<(f64, u32)> = Vec::new();
    for (f, &t) in mesh.triangles.iter().enumerate() {
        if !met[f] {
            triangles.push(t);
            continue;
        }
        let edges = topology.face_edges[f];
        let mut boundary = Vec::with_capacity(8);
        for k in 0..3 {
            boundary.push(t[k]);
            let points = points_on(edges[k]);
            if !points.is_empty() {
                let forward = topology.edges[edges[k] as usize][0] == t[k];
                along.clear();
                along.extend(
                    points
                        .iter()
                        .map(|&(_, tau, v)| (if forward { tau } else { 1.0 - tau }, v)),
                );
                along.sort_by(|x, y| x.0.total_cmp(&y.0));
                boundary.extend(along.iter().map(|&(_, v)| v));
            }
        }
        let mut pieces = vec![boundary];
        if let Some(run) = chords.next_if(|run| run[0].0 == f as u32) {
            for &(_, [a, b]) in run {
                cut_piece(&mut pieces, a, b);
            }
        }
        for piece in &pieces {
            fan(piece, &mut positions, &mut triangles);
        }
    }
    SplitSurface {
        mesh: SurfaceMesh {
            positions,
            triangles,
        },
        loops,
    }
}

/// Cuts the piece holding both `a` and `b` along the chord ab (nothing when they are
/// neighbours on it: the chord is a side already).
fn cut_piece(pieces: &mut Vec<Vec<u32>>, a: u32, b: u32) {
    for p in 0..pieces.len() {
        let piece = &pieces[p];
        let (Some(i), Some(j)) = (
            piece.iter().position(|&v| v == a),
            piece.iter().position(|&v| v == b),
        ) else {
            continue;
        };
        let (i, j) = (i.min(j), i.max(j));
        if j - i == 1 || (i == 0 && j == piece.len() - 1) {
            return;
        }
        let inner = piece[i..=j].to_vec();
        let mut outer = piece[j..].to_vec();
        outer.extend_from_slice(&piece[..=i]);
        pieces[p] = inner;
        pieces.push(outer);
        return;
    }
}

/// Triangulates the convex polygon `piece` by a fan from the first corner whose fan has no
/// zero-area triangle (collinear points lie on the face's sides); failing that, from a new
/// vertex at its centroid.
fn fan(piece: &[u32], positions: &mut Vec<glam::DVec3>, triangles: &mut Vec<[u32; 3]>) {
    let n = piece.len();
    if n < 3 {
        return;
    }
    let scale = (0..n)
        .map(|k| {
            positions[piece[k] as usize].distance_squared(positions[piece[(k + 1) % n] as usize])
        })
        .fold(0.0, f64::max);
    let area2 = |a: u32, b: u32, c: u32, positions: &[glam::DVec3]| {
        let (pa, pb, pc) = (
            positions[a as usize],
            positions[b as usize],
            positions[c as usize],
        );
        (pb - pa).cross(pc - pa).length()
    };
    let flat = FLAT * scale;
    for apex in 0..n {
        let fan_ok = (1..n - 1).all(|k| {
            area2(
                piece[apex],
                piece[(apex + k) % n],
                piece[(apex + k + 1) % n],
                positions,
            ) > flat
        });
        if fan_ok {
            triangles.extend((1..n - 1).map(|k| {
                [
                    piece[apex],
                    piece[(apex + k) % n],
                    piece[(apex + k + 1) % n],
                ]
            }));
            return;
        }
    }
    let centre = piece
        .iter()
        .map(|&v| positions[v as usize])
        .sum::<glam::DVec3>()
        / n as f64;
    positions.push(centre);
    let c = positions.len() as u32 - 1;
    triangles.extend((0..n).map(|k| [c, piece[k], piece[(k + 1) % n]]));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cuts::plane_section::{vertex_snap_distances, DomainScratch, Plane, SectionDomain};
    use crate::fixtures::shapes::{icosphere, uv_sphere};
    use crate::mesh::MeshStats;
    use glam::DVec3;

    fn split_by(mesh: &SurfaceMesh, planes: &[Plane]) -> SplitSurface {
        let topology = Topology::new(mesh);
        let snap = vertex_snap_distances(mesh, &topology, 0.01);
        let mut domain = SectionDomain::new(
            mesh,
            &topology,
            &snap,
            (0..mesh.triangle_count() as u32).collect(),
            &mut DomainScratch::default(),
        );
        let curves: Vec<SectionCurve> = planes
            .iter()
            .flat_map(|plane| domain.closed_sections(plane))
            .collect();
        split_along_curves(mesh, &topology, &curves.iter().collect::<Vec<_>>())
    }

    fn area(mesh: &SurfaceMesh) -> f64 {
        (0..mesh.triangle_count())
            .map(|f| mesh.triangle_area(f))
            .sum()
    }

    #[test]
    fn splitting_keeps_the_surface_closed_and_puts_the_loop_on_the_plane() {
        let mesh = icosphere(1.0, 3);
        let planes = [
            Plane {
                point: DVec3::Z * 0.5,
                normal: DVec3::Z,
            },
            Plane {
                point: DVec3::Z * -0.4,
                normal: DVec3::new(0.1, 0.0, 1.0).normalize(),
            },
        ];
        let split = split_by(&mesh, &planes);
        let stats = MeshStats::new(&split.mesh, &Topology::new(&split.mesh));
        assert!(stats.closed && stats.genus == Some(0), "{stats:?}");
        assert_eq!(stats.inconsistently_oriented_edges, 0);
        assert_eq!(stats.degenerate_triangles, 0);
        assert!((area(&split.mesh) - area(&mesh)).abs() < 1e-9);
        assert_eq!(split.loops.len(), 2);
        for (curve_loop, plane) in split.loops.iter().zip(&planes) {
            assert!(curve_loop.len() > 8);
            for &v in curve_loop {
                let d = plane.signed_distance(split.mesh.positions[v as usize]);
                assert!(d.abs() < 0.01 * 0.3, "{d}");
            }
        }
    }

    #[test]
    fn a_curve_through_vertices_adds_no_vertex() {
        let mesh = uv_sphere(1.0, 8, 16);
        let split = split_by(
            &mesh,
            &[Plane {
                point: DVec3::ZERO,
                normal: DVec3::Z,
            }],
        );
        assert_eq!(split.mesh.vertex_count(), mesh.vertex_count());
        assert_eq!(split.mesh.triangles, mesh.triangles);
        assert_eq!(split.loops[0].len(), 16);
    }
}

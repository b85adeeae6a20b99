//! Inside-out pieces: closed connected components whose faces are wound consistently and
//! inward (negative signed volume V = Σ (a − o) · ((b − o) × (c − o)) / 6 over the
//! piece's triangles, the same for any point o; Zhang & Chen 2001), next
//! to a surface wound outward. The method reads a single orientation for the whole
//! surface (the ray test of joint roles), so such a piece would read as inside out; it is
//! turned outward before the method runs. Open pieces have no inside and stay as they are.

use super::surface::{cone_volume, SurfaceMesh};
use super::topology::Topology;
use crate::tolerance::NEGLIGIBLE;

/// Turns every closed component of negative signed volume outward (each of its triangles
/// [a, b, c] becomes [a, c, b]) when the mesh as a whole has positive signed volume
/// ([`SurfaceMesh::signed_volume`], about its centre), and
/// returns how many components were turned. `topology` is `mesh`'s and stays so: a turned
/// face's edges 0 and 2 exchange (edge i joins corners i and i + 1), and nothing else of a
/// topology depends on the winding (its edges, their faces and the vertices' rows are
/// ordered by vertex and face index).
pub fn turn_inside_out_pieces(mesh: &mut SurfaceMesh, topology: &mut Topology) -> usize {
    let (component, count) = (&topology.vertex_component, topology.component_count);
    let negligible = NEGLIGIBLE * mesh.diagonal().powi(3);
    if mesh.signed_volume() <= negligible {
        return 0;
    }
    // A piece is judged when it is closed and wound one way: every edge has two faces
    // that run along it in opposite directions. Its volume is then the same about any
    // point (here the mesh's centre). A piece closed by its edges but wound both ways has
    // no inside that a turn of all its faces would restore; it is left as it is.
    // Per edge: its faces running along it from its lower end (+1) and from its upper
    // end (−1); face f's edge i joins its corners i and i + 1.
    let mut direction = vec![0i32; topology.edges.len()];
    for (t, edges) in mesh.triangles.iter().zip(&topology.face_edges) {
        for (i, &e) in edges.iter().enumerate() {
            direction[e as usize] += if t[i] == topology.edges[e as usize][0] {
                1
            } else {
                -1
            };
        }
    }
    let mut closed = vec![true; count];
    for (e, edge) in topology.edges.iter().enumerate() {
        if topology.faces_of_edge(e).len() != 2 || direction[e] != 0 {
            closed[component[edge[0] as usize] as usize] = false;
        }
    }
    let centre = mesh.centre();
    let mut volume = vec![0.0; count];
    for t in &mesh.triangles {
        let corners = t.map(|v| mesh.positions[v as usize]);
        volume[component[t[0] as usize] as usize] += cone_volume(corners, centre);
    }
    let inward: Vec<bool> = (0..count)
        .map(|k| closed[k] && volume[k] < -negligible)
        .collect();
    for (t, edges) in mesh.triangles.iter_mut().zip(&mut topology.face_edges) {
        if inward[component[t[0] as usize] as usize] {
            t.swap(1, 2);
            edges.swap(0, 2);
        }
    }
    inward.iter().filter(|&&i| i).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::shapes::icosphere;
    use glam::DVec3;

    /// `body` and `piece` in one mesh.
    fn joined(body: &SurfaceMesh, piece: &SurfaceMesh) -> SurfaceMesh {
        let offset = body.positions.len() as u32;
        SurfaceMesh {
            positions: body
                .positions
                .iter()
                .chain(&piece.positions)
                .copied()
                .collect(),
            triangles: body
                .triangles
                .iter()
                .copied()
                .chain(piece.triangles.iter().map(|t| t.map(|v| v + offset)))
                .collect(),
        }
    }

    /// A sphere of radius `radius` centred at `centre`, wound inward.
    fn inward_sphere(radius: f64, centre: DVec3) -> SurfaceMesh {
        let mut sphere = icosphere(radius, 1);
        for p in &mut sphere.positions {
            *p += centre;
        }
        for t in &mut sphere.triangles {
            t.swap(1, 2);
        }
        sphere
    }

    /// A big outward sphere and a small one wound inward beside it: the small one is
    /// turned, the big one kept, and the topology is that of the turned mesh; a mesh that
    /// is inward as a whole is left alone.
    #[test]
    fn closed_inward_pieces_beside_an_outward_body_are_turned() {
        let body = icosphere(1.0, 2);
        let piece = inward_sphere(0.2, DVec3::new(3.0, 0.0, 0.0));
        let mut mesh = joined(&body, &piece);
        let mut topology = Topology::new(&mesh);
        assert_eq!(turn_inside_out_pieces(&mut mesh, &mut topology), 1);
        assert_eq!(topology, Topology::new(&mesh));
        assert_eq!(&mesh.triangles[..body.triangles.len()], &body.triangles[..]);
        let outward = body.signed_volume() - piece.signed_volume();
        assert!((mesh.signed_volume() - outward).abs() < 1e-9, "{outward}");

        let mut inward = body.clone();
        for t in &mut inward.triangles {
            t.swap(1, 2);
        }
        let mut topology = Topology::new(&inward);
        assert_eq!(turn_inside_out_pieces(&mut inward, &mut topology), 0);
    }

    /// The same body and piece anywhere: the piece is turned wherever they stand. A piece
    /// closed by its edges but wound both ways (half its faces turned) is left as it is.
    #[test]
    fn the_decision_does_not_depend_on_where_the_mesh_stands() {
        for shift in [
            DVec3::ZERO,
            DVec3::new(0.0, 0.0, 50.0),
            DVec3::new(-7.0, 20.0, 3.0),
        ] {
            let mut body = icosphere(1.0, 2);
            for p in &mut body.positions {
                *p += shift;
            }
            let piece = inward_sphere(0.2, DVec3::new(3.0, 0.0, 0.0) + shift);
            let mut mesh = joined(&body, &piece);
            let mut topology = Topology::new(&mesh);
            assert_eq!(
                turn_inside_out_pieces(&mut mesh, &mut topology),
                1,
                "{shift}"
            );

            let mut mixed = piece.clone();
            let half = mixed.triangles.len() / 2;
            for t in &mut mixed.triangles[..half] {
                t.swap(1, 2);
            }
            let mut mesh = joined(&body, &mixed);
            let before = mesh.triangles.clone();
            let mut topology = Topology::new(&mesh);
            assert_eq!(
                turn_inside_out_pieces(&mut mesh, &mut topology),
                0,
                "{shift}"
            );
            assert_eq!(mesh.triangles, before);
        }
    }
}

//! Inside-out pieces: closed connected components whose faces are wound inward (negative
//! signed volume V = Σ (a − o) · ((b − o) × (c − o)) / 6 over the piece's triangles, o
//! the mesh's centre, [`SurfaceMesh::signed_volume`]; Zhang & Chen 2001), next
//! to a surface wound outward. The method reads a single orientation for the whole
//! surface (the ray test of joint roles), so such a piece would read as inside out; it is
//! turned outward before the method runs. Open pieces have no inside and stay as they are.

use super::surface::{cone_volume, SurfaceMesh};
use super::topology::Topology;
use crate::tolerance::NEGLIGIBLE;

/// Turns every closed component of negative signed volume outward (each of its triangles
/// [a, b, c] becomes [a, c, b]) when the mesh as a whole has positive signed volume, and
/// returns how many components were turned. `topology` is `mesh`'s and stays so: a turned
/// face's edges 0 and 2 exchange (edge i joins corners i and i + 1), and nothing else of a
/// topology depends on the winding (its edges, their faces and the vertices' rows are
/// ordered by vertex and face index).
pub fn turn_inside_out_pieces(mesh: &mut SurfaceMesh, topology: &mut Topology) -> usize {
    let (component, count) = (&topology.vertex_component, topology.component_count);
    let mut volume = vec![0.0; count];
    let mut closed = vec![true; count];
    // About the mesh's centre, as `SurfaceMesh::signed_volume`: a closed piece's volume
    // does not depend on it, the whole mesh's (open pieces too) moves with the mesh.
    let centre = mesh.centre();
    for t in &mesh.triangles {
        let corners = t.map(|v| mesh.positions[v as usize]);
        volume[component[t[0] as usize] as usize] += cone_volume(corners, centre);
    }
    for (e, edge) in topology.edges.iter().enumerate() {
        if topology.faces_of_edge(e).len() != 2 {
            closed[component[edge[0] as usize] as usize] = false;
        }
    }
    let negligible = NEGLIGIBLE * mesh.diagonal().powi(3);
    if volume.iter().sum::<f64>() <= negligible {
        return 0;
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

    /// A big outward sphere and a small one wound inward beside it: the small one is
    /// turned, the big one kept, and the topology is that of the turned mesh; a mesh that
    /// is inward as a whole is left alone.
    #[test]
    fn closed_inward_pieces_beside_an_outward_body_are_turned() {
        let body = icosphere(1.0, 2);
        let mut piece = icosphere(0.2, 1);
        for p in &mut piece.positions {
            *p += DVec3::new(3.0, 0.0, 0.0);
        }
        for t in &mut piece.triangles {
            t.swap(1, 2);
        }
        let offset = body.positions.len() as u32;
        let mut mesh = SurfaceMesh {
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
        };
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
}

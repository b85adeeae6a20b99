//! Bleeding: candidate weight lying far, along the surface, from where the artist used
//! the joint at all (a hand bone moving the hip).

use atlas_skin::mesh::edge_distance::EdgeDistances;
use atlas_skin::mesh::weld::UNREFERENCED;
use atlas_skin::mesh::{SurfaceMesh, Topology};
use atlas_skin_runtime::VertexWeights;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Share of the candidate's weight that bleeds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Bleeding {
    pub fraction: f64,
}

/// The surface vertices where each joint has any reference weight > 0.
///
/// - `reference`: #R rows (stored vertices), joint indices below `joint_count`;
///   `surface_of_row`: #R surface vertex of each row, [`UNREFERENCED`] for rows on no
///   surface vertex (skipped). Returns #J sorted, deduplicated lists.
pub fn joint_sources(
    reference: &VertexWeights,
    surface_of_row: &[u32],
    joint_count: usize,
) -> Vec<Vec<u32>> {
    let mut sources = vec![Vec::new(); joint_count];
    for (v, &s) in surface_of_row.iter().enumerate() {
        if s == UNREFERENCED {
            continue;
        }
        for (j, w) in reference.row(v) {
            if w > 0.0 {
                sources[j as usize].push(s);
            }
        }
    }
    for list in &mut sources {
        list.sort_unstable();
        list.dedup();
    }
    sources
}

/// Fraction of candidate weight farther than `radius` from its joint's sources:
/// `Σ_{v,j} w⁺_cand(v, j) · [d_j(v) > radius] / Σ_{v,j} w⁺_cand(v, j)`, where `d_j` is the
/// shortest path along the edges of `surface` from `sources[j]` (infinite when
/// `sources[j]` is empty: all weight on a joint the reference never uses bleeds) and
/// `w⁺ = max(w, 0)`. Zero when the candidate has no positive weight.
///
/// - `surface`, `topology`: #S vertices; `sources`: #J lists of surface vertices;
///   `candidate`: #M rows, joint indices below #J; `surface_of_row`: #M surface vertex of
///   each candidate row.
///
/// Each joint's Dijkstra stops at `radius`, so the cost is that of the band around the
/// joint's sources; joints run in parallel.
pub fn bleeding(
    surface: &SurfaceMesh,
    topology: &Topology,
    sources: &[Vec<u32>],
    candidate: &VertexWeights,
    surface_of_row: &[u32],
    radius: f64,
) -> Bleeding {
    let mut weight_of_joint: Vec<Vec<(u32, f64)>> = vec![Vec::new(); sources.len()];
    for (v, &s) in surface_of_row.iter().enumerate() {
        for (j, w) in candidate.row(v) {
            if w > 0.0 {
                weight_of_joint[j as usize].push((s, f64::from(w)));
            }
        }
    }
    // Explicit folds from +0: an empty float `sum` is -0.
    let total = weight_of_joint
        .iter()
        .flatten()
        .fold(0.0, |sum, &(_, w)| sum + w);
    if total <= 0.0 {
        return Bleeding { fraction: 0.0 };
    }
    let bled: f64 = weight_of_joint
        .par_iter()
        .zip(sources)
        .filter(|(weights, _)| !weights.is_empty())
        .map_init(
            || EdgeDistances::new(surface.vertex_count()),
            |scratch, (weights, sources)| {
                scratch.search(surface, topology, sources.iter().copied(), radius);
                let far = weights
                    .iter()
                    .filter(|&&(s, _)| !scratch.reached(s))
                    .fold(0.0, |sum, &(_, w)| sum + w);
                scratch.clear();
                far
            },
        )
        .reduce(|| 0.0, |a, b| a + b);
    Bleeding {
        fraction: bled / total,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use glam::DVec3;

    /// A strip of unit squares along X: vertices (i, 0) and (i, 1) for i in 0..=n.
    fn strip(n: u32) -> (SurfaceMesh, Topology) {
        let positions = (0..=n)
            .flat_map(|i| {
                [
                    DVec3::new(i as f64, 0.0, 0.0),
                    DVec3::new(i as f64, 1.0, 0.0),
                ]
            })
            .collect();
        let triangles = (0..n)
            .flat_map(|i| {
                let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
                [[a, c, d], [a, d, b]]
            })
            .collect();
        let mesh = SurfaceMesh {
            positions,
            triangles,
        };
        let topology = Topology::new(&mesh);
        (mesh, topology)
    }

    #[test]
    fn weight_beyond_the_radius_bleeds_and_unused_joints_bleed_entirely() {
        let (mesh, topology) = strip(10);
        let rows: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
        // The reference uses joint 0 on the left end only (x = 0), joint 1 nowhere.
        let reference = VertexWeights::from_rows((0..mesh.vertex_count()).map(|v| {
            if v < 2 {
                vec![(0, 1.0)]
            } else {
                vec![]
            }
        }));
        let sources = joint_sources(&reference, &rows, 2);
        assert_eq!(sources, vec![vec![0, 1], vec![]]);

        // Candidate: joint 0 with weight 1 at x = 1 (near) and x = 5 (far, distance 5 > 2);
        // joint 1 with weight 0.5 at x = 0.
        let candidate = VertexWeights::from_rows((0..mesh.vertex_count()).map(|v| match v {
            2 | 10 => vec![(0, 1.0)],
            0 => vec![(1, 0.5)],
            _ => vec![],
        }));
        let b = bleeding(&mesh, &topology, &sources, &candidate, &rows, 2.0);
        assert_relative_eq!(b.fraction, 1.5 / 2.5, epsilon = 1e-12);

        // A larger radius reaches x = 5.
        let b = bleeding(&mesh, &topology, &sources, &candidate, &rows, 6.0);
        assert_relative_eq!(b.fraction, 0.5 / 2.5, epsilon = 1e-12);
    }

    #[test]
    fn identical_weights_do_not_bleed() {
        let (mesh, topology) = strip(4);
        let rows: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
        let weights =
            VertexWeights::from_rows((0..mesh.vertex_count()).map(|v| vec![((v / 5) as u32, 1.0)]));
        let sources = joint_sources(&weights, &rows, 2);
        let b = bleeding(&mesh, &topology, &sources, &weights, &rows, 0.0);
        assert_eq!(b.fraction.to_bits(), 0f64.to_bits());
    }
}

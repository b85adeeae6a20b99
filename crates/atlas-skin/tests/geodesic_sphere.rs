//! Fast-marching distances against exact answers: great-circle distances on refined
//! icospheres, straight-line distances on a flat grid.

use atlas_skin::fixtures::shapes::icosphere;
use atlas_skin::overlap::geodesic::{march_distances, MarchScratch};
use atlas_skin::{SurfaceMesh, Topology};
use glam::DVec3;

/// Mean relative error of distances from vertex 0 against great-circle distances, over the
/// vertices beyond one tenth of the sphere's half circumference (the relative error of any
/// method blows up at the source itself).
fn mean_relative_error(levels: usize) -> (usize, f64) {
    let mesh = icosphere(1.0, levels);
    let topology = Topology::new(&mesh);
    let mut scratch = MarchScratch::new(mesh.vertex_count());
    let band = march_distances(&mesh, &topology, &[0], 10.0, &mut scratch);
    assert_eq!(
        band.vertices.len(),
        mesh.vertex_count(),
        "every vertex reached"
    );
    let source = mesh.positions[0];
    let (mut sum, mut count) = (0.0, 0usize);
    for (&v, &d) in band.vertices.iter().zip(&band.distances) {
        let exact = source
            .dot(mesh.positions[v as usize])
            .clamp(-1.0, 1.0)
            .acos();
        if exact > 0.1 * std::f64::consts::PI {
            sum += (d - exact).abs() / exact;
            count += 1;
        }
    }
    (mesh.vertex_count(), sum / count as f64)
}

#[test]
fn sphere_error_is_below_two_percent_and_falls_with_refinement() {
    let coarse = mean_relative_error(4);
    let fine = mean_relative_error(5);
    println!(
        "icosphere {} vertices: mean relative error {:.4}",
        coarse.0, coarse.1
    );
    println!(
        "icosphere {} vertices: mean relative error {:.4}",
        fine.0, fine.1
    );
    assert!(coarse.0 >= 2_500 && fine.0 >= 10_000);
    assert!(fine.1 < 0.02, "error {} at {} vertices", fine.1, fine.0);
    assert!(
        fine.1 < coarse.1,
        "error does not fall: {} then {}",
        coarse.1,
        fine.1
    );
}

/// A flat n×n grid of unit cells, each split along alternating diagonals.
fn grid(n: usize) -> SurfaceMesh {
    let index = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let positions = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| DVec3::new(j as f64, i as f64, 0.0)))
        .collect();
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (
                index(i, j),
                index(i, j + 1),
                index(i + 1, j + 1),
                index(i + 1, j),
            );
            if (i + j) % 2 == 0 {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    SurfaceMesh {
        positions,
        triangles,
    }
}

#[test]
fn distance_from_a_line_on_a_plane_is_exact_and_stops_at_the_cutoff() {
    let n = 20;
    let mesh = grid(n);
    let topology = Topology::new(&mesh);
    let line: Vec<u32> = (0..=n as u32).collect();
    let mut scratch = MarchScratch::new(mesh.vertex_count());
    let band = march_distances(&mesh, &topology, &line, 7.5, &mut scratch);
    assert_eq!(band.vertices.len(), 8 * (n + 1));
    for (&v, &d) in band.vertices.iter().zip(&band.distances) {
        let exact = mesh.positions[v as usize].y;
        assert!((d - exact).abs() < 1e-9, "vertex {v}: {d} vs {exact}");
    }
    assert!(band.distances.windows(2).all(|w| w[0] <= w[1]));
    // The scratch is left reset: a second march gives the same answer.
    assert_eq!(
        march_distances(&mesh, &topology, &line, 7.5, &mut scratch),
        band
    );
}

#[test]
fn distance_from_a_point_on_a_plane_is_close_to_euclidean() {
    let n = 40;
    let mesh = grid(n);
    let topology = Topology::new(&mesh);
    let centre = (n / 2 * (n + 1) + n / 2) as u32;
    let mut scratch = MarchScratch::new(mesh.vertex_count());
    let band = march_distances(&mesh, &topology, &[centre], 15.0, &mut scratch);
    let origin = mesh.positions[centre as usize];
    let mut worst: f64 = 0.0;
    for (&v, &d) in band.vertices.iter().zip(&band.distances) {
        let exact = origin.distance(mesh.positions[v as usize]);
        if exact > 5.0 {
            worst = worst.max((d - exact).abs() / exact);
        }
    }
    assert!(worst < 0.05, "worst relative error {worst}");
}

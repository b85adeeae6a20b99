//! Speed of the band-limited fast marching (§3.3 distances).
//!
//! `cargo bench -p atlas-skin --bench geodesic`: icospheres of 2.5k, 41k and 164k
//! vertices, distances from one vertex over the whole sphere and within a band of 0.3
//! (about a tenth of the half circumference, the size of an overlap band).

use atlas_skin::fixtures::shapes::icosphere;
use atlas_skin::overlap::geodesic::{march_distances, MarchScratch};
use atlas_skin::Topology;
use divan::Bencher;

fn main() {
    divan::main();
}

#[divan::bench(args = [4, 6, 7], sample_count = 10)]
fn whole_sphere(bencher: Bencher, subdivisions: usize) {
    march(bencher, subdivisions, 10.0);
}

#[divan::bench(args = [4, 6, 7], sample_count = 10)]
fn band(bencher: Bencher, subdivisions: usize) {
    march(bencher, subdivisions, 0.3);
}

fn march(bencher: Bencher, subdivisions: usize, cutoff: f64) {
    let mesh = icosphere(1.0, subdivisions);
    let topology = Topology::new(&mesh);
    let mut scratch = MarchScratch::new(mesh.vertex_count());
    bencher
        .counter(mesh.vertex_count())
        .bench_local(|| march_distances(&mesh, &topology, &[0], cutoff, &mut scratch));
}

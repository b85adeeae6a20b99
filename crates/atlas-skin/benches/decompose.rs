//! Speed of the decomposition (cuts + split + regions, §3.1–3.2).
//!
//! `cargo bench -p atlas-skin --bench decompose`. Target: makehuman's body (26 756
//! triangles, 163 joints) under 100 ms in release on 2 cores.

use atlas_skin::fixtures::shapes::capsule_chain;
use atlas_skin::mesh::weld::DEFAULT_WELD_TOLERANCE;
use atlas_skin::{decompose, weld, DecomposeParams, SurfaceMesh, Topology};
use atlas_skin_corpus::MAKEHUMAN;
use atlas_skin_io::load_character;
use atlas_skin_runtime::Skeleton;
use divan::Bencher;
use glam::DVec3;

fn main() {
    divan::main();
}

fn makehuman_body() -> (SurfaceMesh, Skeleton) {
    let character = load_character(&MAKEHUMAN.input_path(), &MAKEHUMAN.load_options(false))
        .unwrap_or_else(|e| panic!("the corpus is needed for this benchmark: {e}"));
    let welded = weld(
        &character.mesh.positions,
        &character.mesh.triangles,
        DEFAULT_WELD_TOLERANCE,
    );
    let skeleton = character.skeleton.expect("makehuman has a skeleton");
    (welded.mesh, skeleton)
}

#[divan::bench(sample_count = 10)]
fn makehuman(bencher: Bencher) {
    let (mesh, skeleton) = makehuman_body();
    let topology = Topology::new(&mesh);
    let params = DecomposeParams::default();
    bencher.bench(|| decompose(&mesh, &topology, &skeleton, &params));
}

/// A zig-zag chain of eight joints, `sides` × `rings` per segment.
#[divan::bench(args = [(16, 8), (48, 24), (128, 64)], sample_count = 10)]
fn zigzag_chain(bencher: Bencher, (sides, rings): (usize, usize)) {
    let points: Vec<DVec3> = (0..8)
        .map(|k| DVec3::new(if k % 2 == 0 { 0.0 } else { 0.8 }, 2.0 * k as f64, 0.0))
        .collect();
    let (mesh, skeleton) = capsule_chain(&points, &[], 0.5, sides, rings);
    let topology = Topology::new(&mesh);
    let params = DecomposeParams::default();
    bencher
        .counter(mesh.triangle_count())
        .bench(|| decompose(&mesh, &topology, &skeleton, &params));
}

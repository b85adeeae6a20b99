//! Speed of the whole method after parsing ([`atlas_skin::pipeline::skin`]): welding,
//! topology, decomposition, overlaps, weights and weights per stored vertex.
//!
//! `cargo bench -p atlas-skin --bench pipeline`. Targets (release, 2 cores): cesiumman
//! ≤ 5 ms, makehuman's body ≤ 60 ms, a character of over a million triangles (makehuman's
//! body subdivided three times: 1.7M triangles) under 15 s and 4 GB; the peak resident
//! memory of the process is printed at the end.

use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
use atlas_skin_corpus::{Model, CESIUMMAN, MAKEHUMAN};
use atlas_skin_io::{load_character, Character, TriangleMesh};
use atlas_skin_runtime::Skeleton;
use divan::Bencher;
use std::collections::HashMap;

fn main() {
    divan::main();
    if let Ok(status) = std::fs::read_to_string("/proc/self/status") {
        if let Some(line) = status.lines().find(|l| l.starts_with("VmHWM")) {
            println!(
                "peak resident memory: {}",
                line.trim_start_matches("VmHWM:").trim()
            );
        }
    }
}

/// Reads a corpus model (mesh and skeleton, no reference weights).
fn load(model: &Model) -> Character {
    load_character(&model.input_path(), &model.load_options(false))
        .unwrap_or_else(|e| panic!("the corpus is needed for this benchmark: {e}"))
}

/// Splits every triangle into four at its edge midpoints, `levels` times (the surface and
/// its shape are unchanged; vertices and triangles grow fourfold per level).
fn subdivide(mesh: &TriangleMesh, levels: usize) -> TriangleMesh {
    let mut out = mesh.clone();
    for _ in 0..levels {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut positions = out.positions.clone();
        let mut midpoint = |a: u32, b: u32| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]) * 0.5);
                positions.len() as u32 - 1
            })
        };
        let triangles = out
            .triangles
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
        out = TriangleMesh {
            positions,
            triangles,
        };
    }
    out
}

fn bench_skin(bencher: Bencher, mesh: &TriangleMesh, skeleton: Option<Skeleton>) {
    let skeleton = skeleton.expect("the model has a skeleton");
    let params = SkinParams::default();
    let input = SkinInput {
        positions: &mesh.positions,
        triangles: &mesh.triangles,
        skeleton: &skeleton,
        end_joints: &[],
    };
    bencher
        .counter(mesh.triangles.len())
        .bench(|| skin(input, &params, &mut |_| {}).expect("skins"));
}

#[divan::bench(sample_count = 20)]
fn cesiumman(bencher: Bencher) {
    let character = load(&CESIUMMAN);
    bench_skin(bencher, &character.mesh, character.skeleton);
}

#[divan::bench(sample_count = 20)]
fn makehuman_body(bencher: Bencher) {
    let character = load(&MAKEHUMAN);
    bench_skin(bencher, &character.mesh, character.skeleton);
}

#[divan::bench(sample_count = 2, sample_size = 1)]
fn makehuman_body_subdivided_1m(bencher: Bencher) {
    let character = load(&MAKEHUMAN);
    let mesh = subdivide(&character.mesh, 3);
    bench_skin(bencher, &mesh, character.skeleton);
}

//! Speed of each stage of the method ([`atlas_skin::pipeline::skin`]) and of the whole, on
//! the demo character, two corpus humanoids and the largest character of
//! `../shared/data/bench` (RobotExpressive, 7.2k vertices: the benchmark has none of 20k+).
//!
//! `cargo bench -p atlas-skin --bench stages`. Each stage runs on the previous stages'
//! results, prepared once outside the timed loop: `weld` (with duplicate faces removed),
//! `topology`, `decompose` (§3.1–3.2), `overlap` (§3.3), `weights` (§4–5 with the guard
//! against far bones); `skin` is the whole pipeline. The whole `atlas-skin skin` process,
//! reading and writing included, is timed by `scripts/bench-vs-blender`.

use atlas_skin::fixtures::demo::{demo_character, DEFAULT_STEP};
use atlas_skin::mesh::duplicate_faces::remove_duplicate_faces;
use atlas_skin::mesh::weld::DEFAULT_WELD_TOLERANCE;
use atlas_skin::overlap::{compute_overlaps, OverlapParams, Overlaps};
use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
use atlas_skin::weights::blend::Blend;
use atlas_skin::weights::compute_weights;
use atlas_skin::{decompose, weld, DecomposeParams, Decomposition, SurfaceMesh, Topology};
use atlas_skin_corpus::{data_file, CESIUMMAN, MAKEHUMAN};
use atlas_skin_io::load_character;
use atlas_skin_runtime::Skeleton;
use divan::Bencher;
use glam::Vec3;
use std::collections::HashMap;
use std::sync::OnceLock;

fn main() {
    divan::main();
}

const CHARACTERS: &[&str] = &["demo", "cesiumman", "makehuman", "robotexpressive"];

/// A character as stored, and the results of every stage on it.
struct Prepared {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    skeleton: Skeleton,
    mesh: SurfaceMesh,
    topology: Topology,
    decomposition: Decomposition,
    overlaps: Overlaps,
}

fn prepared(name: &str) -> &'static Prepared {
    static CACHE: OnceLock<HashMap<&'static str, Prepared>> = OnceLock::new();
    &CACHE.get_or_init(|| CHARACTERS.iter().map(|&n| (n, prepare(n))).collect())[name]
}

fn prepare(name: &str) -> Prepared {
    let (positions, triangles, skeleton) = if name == "demo" {
        let demo = demo_character(DEFAULT_STEP);
        (demo.positions, demo.triangles, demo.skeleton)
    } else {
        let (path, options) = match name {
            "cesiumman" => (CESIUMMAN.input_path(), CESIUMMAN.load_options(false)),
            "makehuman" => (MAKEHUMAN.input_path(), MAKEHUMAN.load_options(false)),
            _ => (
                data_file("bench/robotexpressive/RobotExpressive.glb"),
                Default::default(),
            ),
        };
        let character = load_character(&path, &options)
            .unwrap_or_else(|e| panic!("the corpus is needed for this benchmark: {e}"));
        let skeleton = character.skeleton.expect("the character has a skeleton");
        (character.mesh.positions, character.mesh.triangles, skeleton)
    };
    let mut mesh = weld(&positions, &triangles, DEFAULT_WELD_TOLERANCE).mesh;
    remove_duplicate_faces(&mut mesh);
    let topology = Topology::new(&mesh);
    let decomposition =
        decompose(&mesh, &topology, &skeleton, &DecomposeParams::default()).expect("decomposes");
    let overlaps =
        compute_overlaps(&decomposition, &skeleton, &OverlapParams::default()).expect("overlaps");
    Prepared {
        positions,
        triangles,
        skeleton,
        mesh,
        topology,
        decomposition,
        overlaps,
    }
}

#[divan::bench(args = CHARACTERS, sample_count = 20)]
fn weld_stage(bencher: Bencher, name: &str) {
    let c = prepared(name);
    bencher.bench(|| {
        let mut mesh = weld(&c.positions, &c.triangles, DEFAULT_WELD_TOLERANCE).mesh;
        remove_duplicate_faces(&mut mesh)
    });
}

#[divan::bench(args = CHARACTERS, sample_count = 20)]
fn topology_stage(bencher: Bencher, name: &str) {
    let c = prepared(name);
    bencher.bench(|| Topology::new(&c.mesh));
}

#[divan::bench(args = CHARACTERS, sample_count = 20)]
fn decompose_stage(bencher: Bencher, name: &str) {
    let c = prepared(name);
    let params = DecomposeParams::default();
    bencher.bench(|| decompose(&c.mesh, &c.topology, &c.skeleton, &params));
}

#[divan::bench(args = CHARACTERS, sample_count = 20)]
fn overlap_stage(bencher: Bencher, name: &str) {
    let c = prepared(name);
    let params = OverlapParams::default();
    bencher.bench(|| compute_overlaps(&c.decomposition, &c.skeleton, &params));
}

#[divan::bench(args = CHARACTERS, sample_count = 20)]
fn weights_stage(bencher: Bencher, name: &str) {
    let c = prepared(name);
    bencher.bench(|| {
        compute_weights(
            &c.decomposition,
            &c.skeleton,
            &c.overlaps,
            Blend::default(),
            &Default::default(),
        )
        .expect("weights")
    });
}

#[divan::bench(args = CHARACTERS, sample_count = 20)]
fn whole_skin(bencher: Bencher, name: &str) {
    let c = prepared(name);
    let params = SkinParams::default();
    let input = SkinInput {
        positions: &c.positions,
        triangles: &c.triangles,
        skeleton: &c.skeleton,
        end_joints: &[],
    };
    bencher.bench(|| skin(input, &params, &mut |_| {}).expect("skins"));
}

//! Linear blend and dual quaternion skinning throughput: positions and normals, 4
//! influences per vertex, 1 and 2 threads, 1k to 1M vertices; and each instruction set
//! this CPU runs on 15k vertices, one thread.
//!
//! `cargo bench -p atlas-skin-runtime --bench skinning`

use atlas_skin_runtime::random_pose::{random_rotations, SplitMix64};
use atlas_skin_runtime::{
    CompactSkin, InstructionSet, SkinningJob, SkinningMethod, SkinningPalette, Threading,
    VertexWeights,
};
use divan::{counter::ItemsCount, Bencher};
use glam::{Mat4, Vec3};

const JOINTS: usize = 64;
const SIZES: [usize; 4] = [1_000, 15_000, 100_000, 1_000_000];

// This bench binary alone counts allocations: divan reports them per iteration.
#[global_allocator]
static ALLOC: divan::AllocProfiler = divan::AllocProfiler::system();

fn main() {
    divan::main();
}

/// A mesh of `count` random points with 4 random influences each, and a random rigid
/// palette.
struct Scene {
    skin: CompactSkin,
    rest_positions: Vec<Vec3>,
    rest_normals: Vec<Vec3>,
    matrices: Vec<Mat4>,
}

impl Scene {
    fn new(count: usize) -> Self {
        let mut rng = SplitMix64::new(count as u64);
        let rest_positions: Vec<Vec3> = (0..count).map(|_| rng.unit_vector() * 0.5).collect();
        let rest_normals: Vec<Vec3> = (0..count).map(|_| rng.unit_vector()).collect();
        let weights = VertexWeights::from_rows((0..count).map(|_| {
            (0..4)
                .map(|_| {
                    let joint = (rng.next_u64() % JOINTS as u64) as u32;
                    (joint, 0.1 + rng.next_f64() as f32)
                })
                .collect::<Vec<_>>()
        }));
        let skin = CompactSkin::new(&weights, JOINTS, 4).expect("valid weights");
        let matrices = random_rotations(JOINTS, 1.0, 7)
            .into_iter()
            .map(|q| Mat4::from_rotation_translation(q, rng.unit_vector()))
            .collect();
        Self {
            skin,
            rest_positions,
            rest_normals,
            matrices,
        }
    }
}

fn skin(
    bencher: Bencher,
    count: usize,
    method: SkinningMethod,
    threads: usize,
    set: InstructionSet,
) {
    let scene = Scene::new(count);
    let mut palette = SkinningPalette::new(JOINTS);
    palette
        .update(&scene.matrices, method)
        .expect("rigid palette");
    let mut out_positions = vec![Vec3::ZERO; count];
    let mut out_normals = vec![Vec3::ZERO; count];
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let threading = if threads == 1 {
        Threading::Sequential
    } else {
        Threading::Parallel
    };
    bencher.counter(ItemsCount::new(count)).bench_local(|| {
        pool.install(|| {
            SkinningJob {
                skin: &scene.skin,
                palette: &palette,
                threading,
                rest_positions: &scene.rest_positions,
                rest_normals: Some(&scene.rest_normals),
                rest_tangents: None,
                out_positions: &mut out_positions,
                out_normals: Some(&mut out_normals),
                out_tangents: None,
            }
            .run_with(set)
            .expect("valid job")
        })
    });
}

#[divan::bench(args = SIZES, consts = [1, 2])]
fn linear_blend<const THREADS: usize>(bencher: Bencher, count: usize) {
    skin(
        bencher,
        count,
        SkinningMethod::LinearBlend,
        THREADS,
        InstructionSet::best(),
    );
}

#[divan::bench(args = SIZES, consts = [1, 2])]
fn dual_quaternion<const THREADS: usize>(bencher: Bencher, count: usize) {
    skin(
        bencher,
        count,
        SkinningMethod::DualQuaternion,
        THREADS,
        InstructionSet::best(),
    );
}

/// The instruction sets this CPU runs, by name.
fn supported_sets() -> Vec<&'static str> {
    InstructionSet::ALL
        .into_iter()
        .filter(|set| set.is_supported())
        .map(InstructionSet::name)
        .collect()
}

#[divan::bench(args = supported_sets())]
fn linear_blend_by_instruction_set(bencher: Bencher, set: &str) {
    let set = InstructionSet::from_name(set).expect("a supported set");
    skin(bencher, 15_000, SkinningMethod::LinearBlend, 1, set);
}

#[divan::bench(args = supported_sets())]
fn dual_quaternion_by_instruction_set(bencher: Bencher, set: &str) {
    let set = InstructionSet::from_name(set).expect("a supported set");
    skin(bencher, 15_000, SkinningMethod::DualQuaternion, 1, set);
}

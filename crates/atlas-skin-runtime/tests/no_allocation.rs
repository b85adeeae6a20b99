//! A frame allocates nothing: preparing the palette (with its hemispheres aligned) and
//! skinning positions and normals (of a small mesh and of one whose loops prefetch), by
//! linear blend and by dual quaternions, with every instruction set this CPU runs, on one
//! thread and on a rayon pool of two. This test binary
//! alone replaces the global allocator by one that counts (the library and the
//! `atlas-skin` binary use the system's unchanged); it has no test harness
//! (`harness = false`), so that the only threads that run while it counts are its own
//! and the workers of the job.

use atlas_skin_runtime::random_pose::{random_rotations, SplitMix64};
use atlas_skin_runtime::{
    CompactSkin, InstructionSet, SkinningJob, SkinningMethod, SkinningPalette, Threading,
    VertexWeights,
};
use glam::{Mat4, Vec3};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

/// The system allocator, counting the allocations of every thread.
struct CountingAllocator;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

fn count() {
    ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
}

// SAFETY: forwards every call unchanged to `System`, which upholds the contract.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        System.alloc(layout)
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        System.alloc_zeroed(layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        System.realloc(ptr, layout, new_size)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// A small mesh, and one large enough for the loops that prefetch, on one thread and on
/// two.
fn main() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("thread pool");
    // Every worker of the pool started (a starting thread allocates, and would otherwise
    // do so while the first sequential frames count).
    pool.broadcast(|_| ());
    for vertices in [5_000, atlas_skin_runtime::skinning_job::PREFETCH_FROM + 8] {
        frames_allocate_nothing(vertices, Threading::Sequential);
        pool.install(|| frames_allocate_nothing(vertices, Threading::Parallel));
    }
    println!("a frame allocates nothing: ok");
}

fn frames_allocate_nothing(vertices: usize, threading: Threading) {
    const JOINTS: usize = 16;
    let mut rng = SplitMix64::new(3);
    let rest: Vec<Vec3> = (0..vertices).map(|_| rng.unit_vector()).collect();
    let normals: Vec<Vec3> = (0..vertices).map(|_| rng.unit_vector()).collect();
    let weights = VertexWeights::from_rows((0..vertices).map(|v| {
        (0..1 + v % 4)
            .map(|k| (((v + 5 * k) % JOINTS) as u32, 0.1 + k as f32))
            .collect::<Vec<_>>()
    }));
    let skin = CompactSkin::new(&weights, JOINTS, 4).expect("valid weights");
    let poses: Vec<Vec<Mat4>> = (0..4)
        .map(|seed| {
            random_rotations(JOINTS, 1.0, seed)
                .into_iter()
                .map(|q| Mat4::from_rotation_translation(q, Vec3::X))
                .collect()
        })
        .collect();
    let mut out_positions = vec![Vec3::ZERO; vertices];
    let mut out_normals = vec![Vec3::ZERO; vertices];
    for set in InstructionSet::ALL.into_iter().filter(|s| s.is_supported()) {
        for method in [SkinningMethod::LinearBlend, SkinningMethod::DualQuaternion] {
            let mut palette = SkinningPalette::new(JOINTS);
            let mut frame = |pose: &[Mat4]| {
                palette.update(pose, method).expect("rigid palette");
                palette.align_hemispheres(&skin);
                SkinningJob {
                    skin: &skin,
                    palette: &palette,
                    threading,
                    rest_positions: &rest,
                    rest_normals: Some(&normals),
                    rest_tangents: None,
                    out_positions: &mut out_positions,
                    out_normals: Some(&mut out_normals),
                    out_tangents: None,
                }
                .run_with(set)
                .expect("valid job");
            };
            // The first frame may set up lazily (CPU feature detection); the others count.
            frame(&poses[0]);
            let before = ALLOCATIONS.load(Ordering::Relaxed);
            for pose in &poses {
                frame(pose);
            }
            let allocations = ALLOCATIONS.load(Ordering::Relaxed) - before;
            assert_eq!(
                allocations,
                0,
                "{vertices}: {} {method:?} {threading:?}",
                set.name()
            );
        }
    }
}

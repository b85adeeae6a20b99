//! `atlas-skin bench`: time linear blend and dual quaternion skinning of a character
//! (positions and normals, up to 4 influences) over many frames, count the allocations a
//! frame makes, and measure the machine's copy bandwidth in the same run.
//!
//! `bandwidth_fraction = vertices/s × bytes read and written per vertex ÷ copy bandwidth`:
//! how close skinning comes to a plain copy of its streams. Near 1 the loop is memory
//! bound (a mesh that does not fit in cache); far below 1 it is compute bound.

use super::pose::{Posable, POSE_INFLUENCES};
use crate::input::InputArgs;
use anyhow::{ensure, Context, Result};
use atlas_skin_runtime::random_pose::random_rotations;
use atlas_skin_runtime::{
    CompactSkin, SkinningJob, SkinningMethod, SkinningPalette, Threading, VertexWeights,
};
use glam::{Mat4, Vec3};
use rayon::prelude::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// The binary's allocator: the system allocator, counting every allocation so that the
/// benchmark can report allocations per frame (a relaxed atomic increment per call).
struct CountingAllocator;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

// SAFETY: forwards every call unchanged to `System`, which upholds the contract.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc(layout)
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.alloc_zeroed(layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        System.realloc(ptr, layout, new_size)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// Distinct random poses cycled through the frames (palettes are prepared per frame).
const POSES: usize = 16;

/// Bytes the copy-bandwidth measurement moves per pass at least: beyond any cache.
const MIN_COPY_BYTES: usize = 256 << 20;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// Worker threads (1 = the sequential path).
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Replicate the mesh to this many vertices (default: the mesh as is).
    #[arg(long)]
    pub vertices: Option<usize>,
    /// Frames timed per method.
    #[arg(long, default_value_t = 200)]
    pub frames: usize,
    /// Print the figures as one JSON object.
    #[arg(long)]
    pub json: bool,
}

/// What one run measures.
#[derive(Debug, serde::Serialize)]
pub struct BenchReport {
    pub vertices: usize,
    pub threads: usize,
    pub frames: usize,
    pub influences: usize,
    pub lbs_vertices_per_second: f64,
    pub dqs_vertices_per_second: f64,
    pub allocations_per_frame: f64,
    /// Copy bandwidth counted as bytes read plus bytes written per second.
    pub memcpy_bytes_per_second: f64,
    /// Bytes a vertex reads (position, normal, joint indices, weights) and writes
    /// (position, normal).
    pub bytes_per_vertex: usize,
    /// For linear blend skinning (the memory-bound method).
    pub bandwidth_fraction: f64,
    pub dqs_bandwidth_fraction: f64,
}

pub fn run(args: Args) -> Result<()> {
    ensure!(args.threads >= 1, "--threads must be at least 1");
    ensure!(args.frames >= 1, "--frames must be at least 1");
    let character = args.input.load_skinned()?;
    let posable = Posable::new(&character)?;
    let weights = character
        .reference_weights
        .as_ref()
        .context("the character has no skin weights")?;
    let count = args.vertices.unwrap_or(posable.rest_positions.len());
    ensure!(count >= 1, "--vertices must be at least 1");
    let streams = Streams::replicate(&posable, weights, count)?;
    let palettes: Vec<Vec<Mat4>> = (0..POSES as u64)
        .map(|seed| {
            posable.palette(&posable.with_rotations(&random_rotations(
                posable.skeleton.len(),
                1.0,
                seed,
            )))
        })
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("cannot start the thread pool")?;
    let threading = if args.threads == 1 {
        Threading::Sequential
    } else {
        Threading::Parallel
    };
    let (lbs_seconds, lbs_allocations) = pool.install(|| {
        time_frames(
            &streams,
            &palettes,
            SkinningMethod::LinearBlend,
            threading,
            args.frames,
        )
    })?;
    let (dqs_seconds, dqs_allocations) = pool.install(|| {
        time_frames(
            &streams,
            &palettes,
            SkinningMethod::DualQuaternion,
            threading,
            args.frames,
        )
    })?;
    let copy_bandwidth = pool.install(|| copy_bandwidth(streams.bytes_per_vertex() * count));
    let frames = args.frames as f64;
    let lbs_rate = count as f64 * frames / lbs_seconds;
    let dqs_rate = count as f64 * frames / dqs_seconds;
    let bytes = streams.bytes_per_vertex();
    let report = BenchReport {
        vertices: count,
        threads: args.threads,
        frames: args.frames,
        influences: streams.skin.influences(),
        lbs_vertices_per_second: lbs_rate,
        dqs_vertices_per_second: dqs_rate,
        allocations_per_frame: (lbs_allocations + dqs_allocations) as f64 / (2.0 * frames),
        memcpy_bytes_per_second: copy_bandwidth,
        bytes_per_vertex: bytes,
        bandwidth_fraction: lbs_rate * bytes as f64 / copy_bandwidth,
        dqs_bandwidth_fraction: dqs_rate * bytes as f64 / copy_bandwidth,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&report);
    }
    Ok(())
}

fn print_report(r: &BenchReport) {
    println!(
        "{} vertices, {} influences, {} thread(s), {} frames per method",
        r.vertices, r.influences, r.threads, r.frames
    );
    println!(
        "linear blend:    {:8.1} M vertices/s ({:.0}% of copy bandwidth)",
        r.lbs_vertices_per_second / 1e6,
        100.0 * r.bandwidth_fraction
    );
    println!(
        "dual quaternion: {:8.1} M vertices/s ({:.0}% of copy bandwidth)",
        r.dqs_vertices_per_second / 1e6,
        100.0 * r.dqs_bandwidth_fraction
    );
    println!(
        "copy bandwidth:  {:8.1} GB/s read + written; {} bytes per vertex; {} allocations per frame",
        r.memcpy_bytes_per_second / 1e9,
        r.bytes_per_vertex,
        r.allocations_per_frame
    );
}

/// The skinning inputs and outputs, replicated to the requested vertex count.
struct Streams {
    skin: CompactSkin,
    rest_positions: Vec<Vec3>,
    rest_normals: Vec<Vec3>,
    out_positions: Vec<Vec3>,
    out_normals: Vec<Vec3>,
}

impl Streams {
    /// Vertex v is the character's vertex `v mod #V` (the mesh tiled in place: the same
    /// work per vertex, a working set that grows with `count`).
    fn replicate(posable: &Posable, weights: &VertexWeights, count: usize) -> Result<Self> {
        let original = posable.rest_positions.len();
        let tile = |v: usize| v % original;
        let rows =
            VertexWeights::from_rows((0..count).map(|v| weights.row(tile(v)).collect::<Vec<_>>()));
        let skin = CompactSkin::new(&rows, posable.skeleton.len(), POSE_INFLUENCES)
            .context("invalid skin weights")?;
        Ok(Self {
            skin,
            rest_positions: (0..count)
                .map(|v| posable.rest_positions[tile(v)])
                .collect(),
            rest_normals: (0..count).map(|v| posable.rest_normals[tile(v)]).collect(),
            out_positions: vec![Vec3::ZERO; count],
            out_normals: vec![Vec3::ZERO; count],
        })
    }

    /// Read: position, normal, K u16 joints, K − 1 f32 weights; written: position, normal.
    fn bytes_per_vertex(&self) -> usize {
        let vec3 = std::mem::size_of::<Vec3>();
        let k = self.skin.influences();
        2 * vec3 + 2 * k + 4 * (k - 1) + 2 * vec3
    }
}

/// Seconds for `frames` frames (palette preparation plus skinning) after one warm-up
/// frame, and the allocations made meanwhile.
fn time_frames(
    streams: &Streams,
    palettes: &[Vec<Mat4>],
    method: SkinningMethod,
    threading: Threading,
    frames: usize,
) -> Result<(f64, u64)> {
    let mut palette = SkinningPalette::new(streams.skin.joint_count());
    let mut out_positions = streams.out_positions.clone();
    let mut out_normals = streams.out_normals.clone();
    let mut frame = |k: usize| -> Result<()> {
        palette
            .update(&palettes[k % palettes.len()], method)
            .context("cannot skin the benchmark pose")?;
        SkinningJob {
            skin: &streams.skin,
            palette: &palette,
            threading,
            rest_positions: &streams.rest_positions,
            rest_normals: Some(&streams.rest_normals),
            rest_tangents: None,
            out_positions: &mut out_positions,
            out_normals: Some(&mut out_normals),
            out_tangents: None,
        }
        .run()?;
        Ok(())
    };
    frame(0)?;
    let allocations_before = ALLOCATIONS.load(Ordering::Relaxed);
    let start = Instant::now();
    for k in 0..frames {
        frame(k)?;
    }
    let seconds = start.elapsed().as_secs_f64();
    let allocations = ALLOCATIONS.load(Ordering::Relaxed) - allocations_before;
    std::hint::black_box((&out_positions, &out_normals));
    Ok((seconds, allocations))
}

/// Copy bandwidth of the current thread pool, bytes read plus written per second: the
/// best of a few parallel copies of at least [`MIN_COPY_BYTES`] (and at least
/// `working_set` bytes) in chunks of the skinning job's size.
fn copy_bandwidth(working_set: usize) -> f64 {
    let len = working_set.max(MIN_COPY_BYTES) / 8;
    let source = vec![1u64; len];
    let mut target = vec![0u64; len];
    let chunk = atlas_skin_runtime::skinning_job::PARALLEL_CHUNK * 8;
    let mut best = f64::MAX;
    for _ in 0..5 {
        let start = Instant::now();
        target
            .par_chunks_mut(chunk)
            .zip(source.par_chunks(chunk))
            .for_each(|(t, s)| t.copy_from_slice(s));
        best = best.min(start.elapsed().as_secs_f64());
        std::hint::black_box(&target);
    }
    2.0 * (len * 8) as f64 / best
}

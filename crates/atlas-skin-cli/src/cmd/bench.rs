//! `atlas-skin bench`: time linear blend and dual quaternion skinning of a character
//! (positions and normals, up to 4 influences) over many frames, and measure the machine's
//! copy bandwidth in the same run. (That a frame allocates nothing is a test of the runtime
//! crate, `tests/no_allocation.rs`, whose binary alone counts allocations.)
//!
//! `bandwidth_fraction = vertices/s × bytes read and written per vertex ÷ copy bandwidth`:
//! how close skinning comes to a plain copy of its streams. Near 1 the loop is memory
//! bound (a mesh that does not fit in cache); far below 1 it is compute bound.
//!
//! The copy moves as many bytes as a frame reads and writes, on the same thread pool, in
//! as many tasks as the skinning job, so that both see the same caches (a mesh that fits
//! in cache is compared with a copy that fits too). The machine is shared: samples of
//! both methods and copies are interleaved, so that every figure sees the same load, and
//! each figure is the median of its samples. A sample is one frame by default, or
//! `--batch` consecutive frames (what `scripts/bench-vs-ozz` uses to time atlas-skin as
//! ozz-animation's program times itself: samples of about 0.15 s, which include the
//! machine's other work as a frame of 60 µs rarely does).
//!
//! `--write-data` writes the benchmark's skinning data for a peer's program
//! ([`crate::skinning_data`]).

use super::pose::{Posable, POSE_INFLUENCES};
use crate::input::InputArgs;
use crate::skinning_data;
use anyhow::{Context, Result};
use atlas_skin_io::OutputPlan;
use atlas_skin_runtime::compact_skin::INFLUENCE_BLOCK;
use atlas_skin_runtime::random_pose::random_rotations;
use atlas_skin_runtime::skinning_job::PARALLEL_CHUNK;
use atlas_skin_runtime::{
    CompactSkin, InstructionSet, SkinningJob, SkinningMethod, SkinningPalette, Threading,
    VertexOrder, VertexWeights, WeightFormat,
};
use glam::{Mat4, Vec3};
use rayon::prelude::*;
use std::path::PathBuf;
use std::time::Instant;

/// Distinct random poses cycled through the frames (palettes are prepared per frame).
const POSES: usize = 16;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// Worker threads (1 = the sequential path).
    #[arg(long, default_value_t = 1,
          value_parser = crate::counts::count_between(1, crate::counts::MAX_THREADS))]
    pub threads: usize,
    /// Replicate the mesh to this many vertices (default: the mesh as is).
    #[arg(long,
          value_parser = crate::counts::count_between(1, crate::counts::MAX_BENCH_VERTICES))]
    pub vertices: Option<usize>,
    /// Timed samples per method.
    #[arg(long, default_value_t = 200,
          value_parser = crate::counts::count_between(1, crate::counts::MAX_BENCH_FRAMES))]
    pub frames: usize,
    /// Consecutive frames in one timed sample (1: every frame timed on its own; the
    /// side-by-side runner times samples of about 0.15 s, as ozz-animation's program does,
    /// so that both see the machine's load alike).
    #[arg(long, default_value_t = 1,
          value_parser = crate::counts::count_between(1, crate::counts::MAX_BENCH_BATCH))]
    pub batch: usize,
    /// The skinning loops: portable, avx2 or avx512 (default: the widest this CPU runs).
    #[arg(long, value_name = "NAME")]
    pub instruction_set: Option<String>,
    /// How the skin stores its weights: f32, or the normalised integers unorm16 or unorm8
    /// (fewer bytes per frame, weights rounded to 1.5e-5 or 3.9e-3).
    #[arg(long, value_name = "FORMAT", default_value = "f32",
          value_parser = ["f32", "unorm16", "unorm8"])]
    pub weight_format: String,
    /// The order of the vertices: as the mesh has them (mesh), or grouped by influence
    /// count window by window (influences: `VertexOrder::by_influence_count`, the order an
    /// engine applies once at load so that blocks of vertices blend alike).
    #[arg(long, value_name = "ORDER", default_value = "mesh",
          value_parser = ["mesh", "influences"])]
    pub vertex_order: String,
    /// Print the figures as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Also write the benchmark's skinning data (rest positions and normals, 4
    /// influences, the first pose's palette) for a peer's skinning job, in the format of
    /// `../shared/perf/README.md` (what `scripts/bench-vs-ozz` hands to ozz-animation).
    #[arg(long, value_name = "DATA.bin")]
    pub write_data: Option<PathBuf>,
}

/// What one run measures: rates from the median sample, bandwidth from the median copy.
#[derive(Debug, serde::Serialize)]
pub struct BenchReport {
    pub vertices: usize,
    pub threads: usize,
    pub frames: usize,
    pub batch: usize,
    /// The skinning loops that ran ([`InstructionSet::name`]).
    pub instruction_set: &'static str,
    /// How the skin stored its weights (`--weight-format`).
    pub weight_format: String,
    /// The order of the vertices (`--vertex-order`).
    pub vertex_order: String,
    /// Influences the loops blend per vertex on average (per block of 8 vertices, its
    /// longest row's; `CompactSkin::block_influences`).
    pub blended_influences: f64,
    pub influences: usize,
    pub lbs_vertices_per_second: f64,
    pub dqs_vertices_per_second: f64,
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
    let plan = OutputPlan::new(args.input.paths(), args.write_data.as_deref())?;
    let set = match &args.instruction_set {
        Some(name) => InstructionSet::from_name(name)?,
        None => InstructionSet::best(),
    };
    let character = args.input.load_skinned()?;
    let posable = Posable::new(&character)?;
    let weights = character
        .reference_weights
        .as_ref()
        .context("the character has no skin weights")?;
    let count = args.vertices.unwrap_or(posable.rest_positions.len());
    let format = WeightFormat::from_name(&args.weight_format)
        .with_context(|| format!("unknown weight format {:?}", args.weight_format))?;
    let grouped = args.vertex_order == "influences";
    let mut streams = Streams::replicate(&posable, weights, count, (format, grouped))?;
    let palettes: Vec<Vec<Mat4>> = (0..POSES as u64)
        .map(|seed| {
            posable.palette(&posable.with_rotations(&random_rotations(
                posable.skeleton.len(),
                1.0,
                seed,
            )))
        })
        .collect();
    if let Some(out) = &args.write_data {
        skinning_data::write(
            &plan,
            out,
            &streams.skin,
            &streams.rest_positions,
            &streams.rest_normals,
            &palettes[0],
        )?;
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .context("cannot start the thread pool")?;
    let threading = if args.threads == 1 {
        Threading::Sequential
    } else {
        Threading::Parallel
    };
    let timings = pool.install(|| {
        measure(
            &mut streams,
            &palettes,
            (threading, set),
            args.frames,
            args.batch,
        )
    })?;
    let lbs_rate = count as f64 / timings.lbs;
    let dqs_rate = count as f64 / timings.dqs;
    let copy_bandwidth = streams.copy_bytes() as f64 / timings.copy;
    let bytes = streams.bytes_per_vertex();
    let report = BenchReport {
        vertices: count,
        threads: args.threads,
        frames: args.frames,
        batch: args.batch,
        instruction_set: set.name(),
        weight_format: args.weight_format.clone(),
        vertex_order: args.vertex_order.clone(),
        blended_influences: streams.blended_influences(),
        influences: streams.skin.influences(),
        lbs_vertices_per_second: lbs_rate,
        dqs_vertices_per_second: dqs_rate,
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
        "{} vertices, {} influences ({} weights, {:.2} blended per vertex in the {} order), {} thread(s), {} loops, {} samples of {} frame(s) per method",
        r.vertices,
        r.influences,
        r.weight_format,
        r.blended_influences,
        r.vertex_order,
        r.threads,
        r.instruction_set,
        r.frames,
        r.batch
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
        "copy bandwidth:  {:8.1} GB/s read + written; {} bytes per vertex",
        r.memcpy_bytes_per_second / 1e9,
        r.bytes_per_vertex
    );
}

/// The skinning inputs and outputs, replicated to the requested vertex count.
struct Streams {
    skin: CompactSkin,
    rest_positions: Vec<Vec3>,
    rest_normals: Vec<Vec3>,
    out_positions: Vec<Vec3>,
    out_normals: Vec<Vec3>,
    /// Each half of a frame's bytes: what a copy pass reads and writes.
    copy_source: Vec<u64>,
    copy_target: Vec<u64>,
}

impl Streams {
    /// Vertex v is the character's vertex `v mod #V` (the mesh tiled in place: the same
    /// work per vertex, a working set that grows with `count`); `grouped`: then reordered
    /// by [`VertexOrder::by_influence_count`].
    fn replicate(
        posable: &Posable,
        weights: &VertexWeights,
        count: usize,
        (format, grouped): (WeightFormat, bool),
    ) -> Result<Self> {
        let original = posable.rest_positions.len();
        let rows = VertexWeights::from_rows(
            (0..count).map(|v| weights.row(v % original).collect::<Vec<_>>()),
        );
        let sources: Vec<usize> = if grouped {
            VertexOrder::by_influence_count(&rows, POSE_INFLUENCES)
                .sources()
                .to_vec()
        } else {
            (0..count).collect()
        };
        let rows = VertexWeights::from_rows(sources.iter().map(|&v| rows.row(v)));
        let tile = |i: usize| sources[i] % original;
        let skin = CompactSkin::with_format(&rows, posable.skeleton.len(), POSE_INFLUENCES, format)
            .context("invalid skin weights")?;
        let copy_len = (bytes_per_vertex(&skin) * count / 2).div_ceil(8);
        Ok(Self {
            skin,
            copy_source: vec![1; copy_len],
            copy_target: vec![0; copy_len],
            rest_positions: (0..count)
                .map(|v| posable.rest_positions[tile(v)])
                .collect(),
            rest_normals: (0..count).map(|v| posable.rest_normals[tile(v)]).collect(),
            out_positions: vec![Vec3::ZERO; count],
            out_normals: vec![Vec3::ZERO; count],
        })
    }

    fn bytes_per_vertex(&self) -> usize {
        bytes_per_vertex(&self.skin)
    }

    /// Influences blended per vertex: each block's longest row, for each of its vertices.
    fn blended_influences(&self) -> f64 {
        let count = self.skin.vertex_count();
        let blended: usize = (self.skin.block_influences().iter())
            .enumerate()
            .map(|(b, &k)| k as usize * (count - b * INFLUENCE_BLOCK).min(INFLUENCE_BLOCK))
            .sum();
        blended as f64 / count as f64
    }

    /// Bytes a copy pass reads plus writes: about those of a frame.
    fn copy_bytes(&self) -> usize {
        2 * std::mem::size_of_val(self.copy_source.as_slice())
    }

    /// Seconds per frame of `poses.len()` frames, each preparing `palette` for its pose
    /// and skinning every vertex with it.
    fn skin_frames<'p>(
        &mut self,
        palette: &mut SkinningPalette,
        poses: impl ExactSizeIterator<Item = &'p Vec<Mat4>>,
        method: SkinningMethod,
        (threading, set): (Threading, InstructionSet),
    ) -> Result<f64> {
        let count = poses.len() as f64;
        let start = Instant::now();
        for pose in poses {
            palette
                .update(pose, method)
                .context("cannot skin the benchmark pose")?;
            if method == SkinningMethod::DualQuaternion {
                palette.align_hemispheres(&self.skin);
            }
            SkinningJob {
                skin: &self.skin,
                palette,
                threading,
                rest_positions: &self.rest_positions,
                rest_normals: Some(&self.rest_normals),
                rest_tangents: None,
                out_positions: &mut self.out_positions,
                out_normals: Some(&mut self.out_normals),
                out_tangents: None,
            }
            .run_with(set)?;
        }
        Ok(start.elapsed().as_secs_f64() / count)
    }

    /// Seconds per pass of `passes` copies of the copy source to the copy target on the
    /// current thread pool, each in as many tasks as a skinning job of the same vertices.
    fn copy_passes(&mut self, passes: usize) -> f64 {
        let chunk = (PARALLEL_CHUNK * self.bytes_per_vertex() / 2).div_ceil(8);
        let start = Instant::now();
        for _ in 0..passes {
            self.copy_target
                .par_chunks_mut(chunk)
                .zip(self.copy_source.par_chunks(chunk))
                .for_each(|(target, source)| target.copy_from_slice(source));
        }
        start.elapsed().as_secs_f64() / passes as f64
    }
}

/// Bytes a vertex with k influences reads (position, normal, k u16 joints, k − 1
/// weights of the skin's format) and writes (position, normal).
fn bytes_per_vertex(skin: &CompactSkin) -> usize {
    let vec3 = std::mem::size_of::<Vec3>();
    let k = skin.influences();
    2 * vec3 + 2 * k + skin.weight_format().bytes() * (k - 1) + 2 * vec3
}

/// Median seconds of a frame of each method and of a copy pass.
struct Timings {
    lbs: f64,
    dqs: f64,
    copy: f64,
}

/// Times `frames` rounds of: `batch` linear blend frames, `batch` dual quaternion frames
/// (each a palette preparation plus skinning) and `batch` copies of
/// [`Streams::copy_bytes`], after one warm-up round (page faults of the first touch,
/// thread start-up).
fn measure(
    streams: &mut Streams,
    palettes: &[Vec<Mat4>],
    threading: (Threading, InstructionSet),
    frames: usize,
    batch: usize,
) -> Result<Timings> {
    let joints = streams.skin.joint_count();
    let mut lbs_palette = SkinningPalette::new(joints);
    let mut dqs_palette = SkinningPalette::new(joints);
    let mut seconds = [vec![0.0; frames], vec![0.0; frames], vec![0.0; frames]];
    for round in 0..=frames {
        let poses = || (round * batch..(round + 1) * batch).map(|f| &palettes[f % palettes.len()]);
        let lbs = streams.skin_frames(
            &mut lbs_palette,
            poses(),
            SkinningMethod::LinearBlend,
            threading,
        )?;
        let dqs = streams.skin_frames(
            &mut dqs_palette,
            poses(),
            SkinningMethod::DualQuaternion,
            threading,
        )?;
        let copy = streams.copy_passes(batch);
        // Round 0 warms up.
        if let Some(previous) = round.checked_sub(1) {
            for (samples, s) in seconds.iter_mut().zip([lbs, dqs, copy]) {
                samples[previous] = s;
            }
        }
    }
    std::hint::black_box((
        &streams.out_positions,
        &streams.out_normals,
        &streams.copy_target,
    ));
    let [lbs, dqs, copy] = seconds.map(median);
    Ok(Timings { lbs, dqs, copy })
}

/// The median of a non-empty sample.
fn median(mut samples: Vec<f64>) -> f64 {
    samples.sort_unstable_by(f64::total_cmp);
    samples[samples.len() / 2]
}

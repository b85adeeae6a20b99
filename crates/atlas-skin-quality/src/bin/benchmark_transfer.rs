//! `benchmark-transfer`: measures `atlas-skin transfer` (Abdrashitov et al. 2023's weight
//! transfer with inpainting) on real characters and writes docs/transfer.md. Run it through
//! `scripts/benchmark-transfer`.
//!
//! On every character of the tune set (`../shared/data/bench` and
//! `bench-large/rignet-train`) and the check set (`bench-large/rignet-check`), the pieces
//! that hold no bone (the method's own decision: clothes, hair, armour, props) lose their
//! artist weights and get them back by transfer from the rest of the character, by four
//! tools on the same pieces: atlas-skin, Blender's Data Transfer (nearest face
//! interpolated, through `bpy`), the paper's reference implementation (Python, libigl) and
//! a copy of the nearest source vertex's row. Each is judged against the artist's weights
//! on those vertices ([`atlas_skin_quality::transfer_split::score`]).
//!
//! Then speed: a 100,000-vertex garment on a 50,000-vertex body (CesiumMan refined by
//! longest-edge bisection, the garment its torso offset along the normals and refined
//! likewise), atlas-skin (in this process, on one thread, the median of three runs)
//! against the reference implementation, side by side in one run.

use anyhow::{Context, Result};
use atlas_skin::transfer::{transfer_weights, TransferParams, TransferSource};
use atlas_skin_quality::transfer_peers::{answers, job, Answer, Job, Peer};
use atlas_skin_quality::transfer_split::{poses, score, split_character, Score, Split};
use atlas_skin_runtime::VertexWeights;
use clap::Parser;
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

const WORKSPACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// Measures weight transfer on the benchmark characters; writes docs/transfer.md.
#[derive(Parser, Debug)]
#[command(name = "benchmark-transfer")]
struct Args {
    /// The data folder (bench/, bench-large/, models/).
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data"))]
    data: PathBuf,
    /// The reference implementation's sources.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/peers/robust-skin-weights-transfer/src"))]
    peer: PathBuf,
    /// At most this many characters per set (all by default): a quick look.
    #[arg(long)]
    limit: Option<usize>,
    /// Skip the speed run.
    #[arg(long)]
    no_speed: bool,
    /// Only the speed run.
    #[arg(long)]
    speed_only: bool,
    /// The page to write.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/transfer.md"))]
    page: PathBuf,
}

/// The four tools, in table order.
const TOOLS: [&str; 4] = ["atlas-skin", "blender", "reference", "nearest-vertex"];

#[derive(Debug, Clone, Serialize)]
struct CharacterResult {
    set: &'static str,
    name: String,
    target_vertices: usize,
    pieces: usize,
    /// Per tool (TOOLS order): its score, or its error.
    scores: Vec<Result<Score, String>>,
    atlas_seconds: f64,
    reference_seconds: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
struct Speed {
    body_vertices: usize,
    garment_vertices: usize,
    /// The median of `atlas_runs`.
    atlas_seconds: f64,
    atlas_runs: Vec<f64>,
    reference_seconds: Option<f64>,
    reference_error: Option<String>,
    matched: usize,
    inpainted: usize,
    threads: usize,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let workspace = Path::new(WORKSPACE);
    let cache = workspace.join("target/transfer-benchmark/cache");
    let blender = Peer {
        name: "blender",
        python: workspace.join("target/bpy-venv/bin/python"),
        script: workspace.join("scripts/transfer-peers/blender_data_transfer.py"),
        leading_args: Vec::new(),
    };
    let reference = Peer {
        name: "reference",
        python: workspace.join("target/transfer-peer-venv/bin/python"),
        script: workspace.join("scripts/transfer-peers/reference_transfer.py"),
        leading_args: vec![args.peer.clone().into_os_string()],
    };
    let mut results = Vec::new();
    if !args.speed_only {
        for (set, folders) in [
            (
                "tune",
                vec![
                    args.data.join("bench/kaykit"),
                    args.data.join("bench/robotexpressive"),
                    args.data.join("bench/rignet-val"),
                    args.data.join("bench-large/rignet-train"),
                ],
            ),
            ("check", vec![args.data.join("bench-large/rignet-check")]),
        ] {
            let mut files = Vec::new();
            for folder in &folders {
                files.extend(glb_files(folder)?);
            }
            if let Some(limit) = args.limit {
                files.truncate(limit);
            }
            results.extend(run_set(
                set,
                &args.data,
                &files,
                &[&blender, &reference],
                &cache,
            )?);
        }
    }
    let speed = if args.no_speed {
        None
    } else {
        Some(speed_run(&args.data, &reference, &cache)?)
    };
    let json_path = workspace.join("target/transfer-benchmark/results.json");
    std::fs::write(
        &json_path,
        serde_json::to_vec_pretty(&serde_json::json!({"characters": results, "speed": speed}))?,
    )?;
    let page = render(&results, speed.as_ref());
    std::fs::write(&args.page, page).with_context(|| format!("writing {}", args.page.display()))?;
    eprintln!("wrote {} and {}", args.page.display(), json_path.display());
    Ok(())
}

/// The `*.glb` files of `folder`, numbers in numeric order.
fn glb_files(folder: &Path) -> Result<Vec<PathBuf>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .with_context(|| {
            format!(
                "reading {} (the benchmark's data must be there)",
                folder.display()
            )
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    files.sort_by_key(|p| {
        let stem = p
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        (stem.parse::<u64>().unwrap_or(u64::MAX), stem)
    });
    Ok(files)
}

/// One character's own part: split, atlas-skin, nearest vertex.
struct Prepared {
    name: String,
    split: Split,
    atlas: VertexWeights,
    atlas_seconds: f64,
    nearest: VertexWeights,
    job: Job,
}

fn run_set(
    set: &'static str,
    data: &Path,
    files: &[PathBuf],
    peers: &[&Peer],
    cache: &Path,
) -> Result<Vec<CharacterResult>> {
    let params = TransferParams::default();
    eprintln!("{set}: {} characters", files.len());
    let prepared: Vec<Result<Option<Prepared>>> = files
        .par_iter()
        .map(|path| {
            let name = path
                .strip_prefix(data)
                .unwrap_or(path)
                .display()
                .to_string();
            let Some(split) = split_character(path)? else {
                return Ok(None);
            };
            let start = Instant::now();
            let source = TransferSource::new(
                &split.positions,
                &split.source_triangles,
                &split.artist,
                split.skeleton.len(),
            )?;
            let result = transfer_weights(
                &source,
                &split.target_positions(),
                &split.target_triangles,
                &params,
            )
            .with_context(|| format!("{name}: transfer"))?;
            let atlas_seconds = start.elapsed().as_secs_f64();
            let nearest = nearest_vertex_copy(&split);
            let job = job(
                &split,
                params.distance * source.diagonal(),
                params.angle_degrees,
            );
            Ok(Some(Prepared {
                name,
                split,
                atlas: result.weights,
                atlas_seconds,
                nearest,
                job,
            }))
        })
        .collect();
    let mut kept = Vec::new();
    for (path, p) in files.iter().zip(prepared) {
        match p {
            Ok(Some(p)) => kept.push(p),
            Ok(None) => {}
            Err(e) => eprintln!("{}: skipped: {e:#}", path.display()),
        }
    }
    let jobs: Vec<&Job> = kept.iter().map(|p| &p.job).collect();
    let peer_answers: Vec<HashMap<String, Answer>> = peers
        .iter()
        .map(|peer| answers(peer, &jobs, cache))
        .collect::<Result<_>>()?;
    Ok(kept
        .par_iter()
        .map(|p| {
            let palettes = poses(&p.split.skeleton);
            let peer_rows = |k: usize| peer_answers[k][&p.job.key].rows(&p.job);
            let scored = |rows: Result<VertexWeights, String>| -> Result<Score, String> {
                let rows = rows?;
                if rows.vertex_count() != p.split.target_vertices.len() {
                    return Err("wrong row count".into());
                }
                Ok(score(&p.split, &rows, &palettes))
            };
            CharacterResult {
                set,
                name: p.name.clone(),
                target_vertices: p.split.target_vertices.len(),
                pieces: p.split.pieces,
                scores: vec![
                    scored(Ok(p.atlas.clone())),
                    scored(peer_rows(0)),
                    scored(peer_rows(1)),
                    scored(Ok(p.nearest.clone())),
                ],
                atlas_seconds: p.atlas_seconds,
                reference_seconds: peer_answers[1][&p.job.key]
                    .weights
                    .as_ref()
                    .map(|_| peer_answers[1][&p.job.key].seconds),
            }
        })
        .collect())
}

/// Nearest vertex copy: every target vertex takes the artist row of the nearest vertex
/// of the source's triangles (by a scan of them all).
fn nearest_vertex_copy(split: &Split) -> VertexWeights {
    let mut used = vec![false; split.positions.len()];
    for &v in split.source_triangles.iter().flatten() {
        used[v as usize] = true;
    }
    let candidates: Vec<usize> = (0..used.len()).filter(|&v| used[v]).collect();
    let rows: Vec<Vec<(u32, f32)>> = split
        .target_positions()
        .par_iter()
        .map(|p| {
            let nearest = candidates
                .iter()
                .copied()
                .min_by(|&a, &b| {
                    p.distance_squared(split.positions[a])
                        .total_cmp(&p.distance_squared(split.positions[b]))
                })
                .expect("the source has vertices");
            split.artist.row(nearest).collect()
        })
        .collect();
    VertexWeights::from_rows(rows)
}

/// Refines a mesh to exactly `target` vertices by longest-edge bisection: in rounds, the
/// edges by decreasing length (ties by their ends), each split at its middle unless one
/// of its faces already has an edge split this round, until `target` is reached. A split
/// edge ab of face abc gives the faces a m c and m b c (the winding kept); the new
/// vertex m takes the mean of its ends' rows. The new vertices are numbered in the order
/// of the faces that first use them, as a modelling tool stores a subdivided mesh.
fn refine(
    positions: &mut Vec<Vec3>,
    triangles: &mut Vec<[u32; 3]>,
    rows: &mut Vec<Vec<(u32, f32)>>,
    target: usize,
) {
    while positions.len() < target {
        let mut faces_of_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (f, t) in triangles.iter().enumerate() {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                faces_of_edge
                    .entry((a.min(b), a.max(b)))
                    .or_default()
                    .push(f);
            }
        }
        let mut edges: Vec<((u32, u32), f32)> = faces_of_edge
            .keys()
            .map(|&(a, b)| {
                let length = positions[a as usize].distance(positions[b as usize]);
                ((a, b), length)
            })
            .collect();
        edges.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
        // Per face: the ends of its split edge.
        let mut split_of_face: Vec<Option<(u32, u32)>> = vec![None; triangles.len()];
        let mut splits = target - positions.len();
        for ((a, b), _) in edges {
            if splits == 0 {
                break;
            }
            let faces = &faces_of_edge[&(a, b)];
            if faces.iter().any(|&f| split_of_face[f].is_some()) {
                continue;
            }
            splits -= 1;
            for &f in faces {
                split_of_face[f] = Some((a, b));
            }
        }
        let mut middle: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(2 * triangles.len());
        for (t, split) in triangles.iter().zip(&split_of_face) {
            let Some((e0, e1)) = *split else {
                next.push(*t);
                continue;
            };
            let m = *middle.entry((e0, e1)).or_insert_with(|| {
                positions.push((positions[e0 as usize] + positions[e1 as usize]) * 0.5);
                let mut row: Vec<(u32, f32)> = rows[e0 as usize]
                    .iter()
                    .chain(&rows[e1 as usize])
                    .map(|&(j, w)| (j, w * 0.5))
                    .collect();
                row.sort_by_key(|&(j, _)| j);
                row.dedup_by(|n, k| {
                    let same = n.0 == k.0;
                    if same {
                        k.1 += n.1;
                    }
                    same
                });
                rows.push(row);
                positions.len() as u32 - 1
            });
            // The corner i whose edge to corner i + 1 was split.
            let i = (0..3)
                .find(|&i| {
                    let (a, b) = (t[i], t[(i + 1) % 3]);
                    (a.min(b), a.max(b)) == (e0, e1)
                })
                .expect("a split edge of the face");
            let (a, b, c) = (t[i], t[(i + 1) % 3], t[(i + 2) % 3]);
            next.extend([[a, m, c], [m, b, c]]);
        }
        *triangles = next;
    }
}

/// The speed run's sizes (the issue's: a 100k-vertex garment on a 50k-vertex body).
const BODY_VERTICES: usize = 50_000;
const GARMENT_VERTICES: usize = 100_000;
/// Runs of atlas-skin in the speed run (the median is reported).
const SPEED_RUNS: usize = 3;

/// The speed inputs and both tools' times (module documentation).
fn speed_run(data: &Path, reference: &Peer, cache: &Path) -> Result<Speed> {
    let path = data.join("models/cesiumman/CesiumMan.glb");
    let character = atlas_skin_io::load_character(&path, &Default::default())?;
    let weights = character
        .reference_weights
        .clone()
        .context("CesiumMan has weights")?;
    let joints = character.skeleton.as_ref().context("a skeleton")?.len();
    let welded = atlas_skin::mesh::weld(&character.mesh.positions, &character.mesh.triangles, 1e-6);
    let mut positions: Vec<Vec3> = welded.mesh.positions.iter().map(|p| p.as_vec3()).collect();
    let mut triangles = welded.mesh.triangles.clone();
    let mut rows: Vec<Vec<(u32, f32)>> = welded
        .stored_of_welded
        .iter()
        .map(|&s| weights.row(s as usize).collect())
        .collect();
    refine(&mut positions, &mut triangles, &mut rows, BODY_VERTICES);
    // The garment: the body's faces in the middle 40% of its tallest extent, pushed out
    // by 1% of the diagonal along the vertex normals.
    let body = atlas_skin::mesh::SurfaceMesh {
        positions: positions.iter().map(|p| p.as_dvec3()).collect(),
        triangles: triangles.clone(),
    };
    let (lo, hi) = body.bounding_box();
    let axis = (hi - lo).max_position();
    let (from, to) = (
        lo[axis] + 0.35 * (hi - lo)[axis],
        lo[axis] + 0.75 * (hi - lo)[axis],
    );
    let normals = body.vertex_normals();
    let offset = 0.01 * body.diagonal();
    let mut garment_index = HashMap::new();
    let mut garment: Vec<Vec3> = Vec::new();
    let mut garment_triangles: Vec<[u32; 3]> = Vec::new();
    for t in &triangles {
        let centre = t
            .iter()
            .map(|&v| body.positions[v as usize][axis])
            .sum::<f64>()
            / 3.0;
        if !(from..to).contains(&centre) {
            continue;
        }
        garment_triangles.push(t.map(|v| {
            *garment_index.entry(v).or_insert_with(|| {
                garment.push((body.positions[v as usize] + normals[v as usize] * offset).as_vec3());
                garment.len() as u32 - 1
            })
        }));
    }
    let mut garment_rows = vec![Vec::new(); garment.len()];
    refine(
        &mut garment,
        &mut garment_triangles,
        &mut garment_rows,
        GARMENT_VERTICES,
    );
    let body_weights = VertexWeights::from_rows(rows);
    let params = TransferParams::default();
    // One core: the method's parallel loops run on a pool of one thread.
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    // Three runs, the median reported (the machine may be shared): the source's
    // preparation and the transfer, each.
    let mut atlas_runs = Vec::with_capacity(SPEED_RUNS);
    let mut last = None;
    for _ in 0..SPEED_RUNS {
        let start = Instant::now();
        last = Some(one_thread.install(|| -> Result<_> {
            let source = TransferSource::new(&positions, &triangles, &body_weights, joints)?;
            let result = transfer_weights(&source, &garment, &garment_triangles, &params)?;
            Ok((source, result))
        })?);
        atlas_runs.push(start.elapsed().as_secs_f64());
    }
    let (source, result) = last.context("a run")?;
    let mut sorted = atlas_runs.clone();
    sorted.sort_by(f64::total_cmp);
    let atlas_seconds = sorted[SPEED_RUNS / 2];
    let split = Split {
        skeleton: character.skeleton.clone().context("a skeleton")?,
        artist: {
            let mut all: Vec<Vec<(u32, f32)>> = (0..positions.len())
                .map(|v| body_weights.row(v).collect())
                .collect();
            all.extend(std::iter::repeat_n(Vec::new(), garment.len()));
            VertexWeights::from_rows(all)
        },
        positions: positions.iter().chain(&garment).copied().collect(),
        source_triangles: triangles.clone(),
        target_vertices: (positions.len() as u32..(positions.len() + garment.len()) as u32)
            .collect(),
        target_triangles: garment_triangles.clone(),
        target_piece: vec![0; garment.len()],
        pieces: 1,
        diagonal: body.diagonal(),
    };
    let speed_job = job(
        &split,
        params.distance * source.diagonal(),
        params.angle_degrees,
    );
    // Never from the cache: both times come from this run.
    let fresh = cache.join("speed");
    let _ = std::fs::remove_dir_all(&fresh);
    let answer = answers(reference, &[&speed_job], &fresh)?
        .into_values()
        .next()
        .context("the reference's answer")?;
    Ok(Speed {
        body_vertices: positions.len(),
        garment_vertices: garment.len(),
        atlas_seconds,
        atlas_runs,
        reference_seconds: answer.weights.as_ref().map(|_| answer.seconds),
        reference_error: answer.error,
        matched: result.counts.matched,
        inpainted: result.counts.inpainted,
        threads: one_thread.current_num_threads(),
    })
}

/// Per set: averages over the characters every tool scored, pieces not torn, failures.
fn render(results: &[CharacterResult], speed: Option<&Speed>) -> String {
    let mut page = String::new();
    page.push_str(include_str!("benchmark_transfer_intro.md"));
    for set in ["tune", "check"] {
        let of_set: Vec<&CharacterResult> = results.iter().filter(|r| r.set == set).collect();
        if of_set.is_empty() {
            continue;
        }
        let complete: Vec<&CharacterResult> = of_set
            .iter()
            .copied()
            .filter(|r| r.scores.iter().all(Result::is_ok))
            .collect();
        let _ = writeln!(
            page,
            "\n## {set} set\n\n{} characters with pieces that hold no bone; {} scored by all \
             four tools ({} target vertices, {} pieces). Averages over those characters \
             (deformation in units of the character's bounding-box diagonal, LBS, the \
             benchmark's 10 random poses):\n",
            of_set.len(),
            complete.len(),
            complete.iter().map(|r| r.target_vertices).sum::<usize>(),
            complete.iter().map(|r| r.pieces).sum::<usize>(),
        );
        page.push_str("| tool | deform mean | deform max | weight L1 | failed on |\n| --- | --- | --- | --- | --- |\n");
        for (k, tool) in TOOLS.iter().enumerate() {
            let average = |f: fn(&Score) -> f64| {
                complete
                    .iter()
                    .map(|r| f(r.scores[k].as_ref().expect("complete")))
                    .sum::<f64>()
                    / complete.len().max(1) as f64
            };
            let failed = of_set.iter().filter(|r| r.scores[k].is_err()).count();
            let _ = writeln!(
                page,
                "| {tool} | {:.5} | {:.4} | {:.4} | {failed} |",
                average(|s| s.deform_mean),
                average(|s| s.deform_max),
                average(|s| s.l1)
            );
        }
        // Pieces: atlas-skin's largest error at most the better of Blender's and the
        // reference's (within 1e-6 of the diagonal).
        let pieces: usize = complete.iter().map(|r| r.pieces).sum();
        let at_most = |k: usize, others: &[usize]| -> usize {
            complete
                .iter()
                .map(|r| {
                    let max = |k: usize| &r.scores[k].as_ref().expect("complete").piece_max;
                    (0..r.pieces)
                        .filter(|&p| {
                            let best = others
                                .iter()
                                .map(|&j| max(j)[p])
                                .fold(f64::INFINITY, f64::min);
                            max(k)[p] <= best + 1e-6
                        })
                        .count()
                })
                .sum()
        };
        let not_torn = at_most(0, &[1, 2]);
        let (mut better_mean, mut better_max) = (0usize, 0usize);
        for r in &complete {
            let s = |k: usize| r.scores[k].as_ref().expect("complete");
            let best_mean = s(1).deform_mean.min(s(2).deform_mean);
            let best_max = s(1).deform_max.min(s(2).deform_max);
            better_mean += usize::from(s(0).deform_mean <= best_mean + 1e-9);
            better_max += usize::from(s(0).deform_max <= best_max + 1e-9);
        }
        let _ = writeln!(
            page,
            "\nPieces whose largest error under atlas-skin is at most the better of Blender's \
             and the reference's (within 1e-6): {not_torn} of {pieces} ({:.1}%). Characters \
             where atlas-skin's deform mean is at most the better of the two: {better_mean} \
             of {}; its max: {better_max}.",
            100.0 * not_torn as f64 / pieces.max(1) as f64,
            complete.len()
        );
        // The same test for every tool against the others, to read the count above by:
        // how often each of the three is at most the better of the other two, and
        // atlas-skin against each peer alone.
        let share = |n: usize| format!("{n} ({:.1}%)", 100.0 * n as f64 / pieces.max(1) as f64);
        let _ = writeln!(
            page,
            "\nThe same test for each tool, on the same pieces: its largest error at most the \
             better of the other two of atlas-skin, Blender and the reference: atlas-skin {}, \
             Blender {}, the reference {}. Atlas-skin's at most Blender's alone: {}; at most \
             the reference's alone: {}.",
            share(not_torn),
            share(at_most(1, &[0, 2])),
            share(at_most(2, &[0, 1])),
            share(at_most(0, &[1])),
            share(at_most(0, &[2])),
        );
        let atlas: f64 = complete.iter().map(|r| r.atlas_seconds).sum();
        let reference: f64 = complete.iter().filter_map(|r| r.reference_seconds).sum();
        let _ = writeln!(
            page,
            "\nTime over these characters: atlas-skin {atlas:.2} s (reading the split mesh \
             and the matching included), the reference {reference:.2} s (its matching, \
             inpainting and smoothing)."
        );
        let failures: Vec<String> = of_set
            .iter()
            .flat_map(|r| {
                r.scores.iter().enumerate().filter_map(move |(k, s)| {
                    s.as_ref().err().map(|e| {
                        format!(
                            "- {} on {}: {}",
                            TOOLS[k],
                            r.name,
                            e.lines().next().unwrap_or("")
                        )
                    })
                })
            })
            .collect();
        if !failures.is_empty() {
            let _ = writeln!(page, "\nFailures:\n\n{}", failures.join("\n"));
        }
    }
    if let Some(s) = speed {
        let _ = writeln!(
            page,
            "\n## Speed\n\nA {}-vertex garment on a {}-vertex body (CesiumMan refined by \
             longest-edge bisection; the garment its torso pushed out by 1% of the diagonal, \
             refined likewise), {} thread(s): \
             atlas-skin {:.3} s, the median of {} runs ({}; the source prepared, then \
             welding, matching, factorisation, smoothing; {} vertices matched, {} \
             inpainted), the reference implementation {}{}.",
            s.garment_vertices,
            s.body_vertices,
            s.threads,
            s.atlas_seconds,
            s.atlas_runs.len(),
            s.atlas_runs
                .iter()
                .map(|t| format!("{t:.3} s"))
                .collect::<Vec<_>>()
                .join(", "),
            s.matched,
            s.inpainted,
            s.reference_seconds
                .map_or_else(|| "failed".to_string(), |t| format!("{t:.3} s")),
            match s.reference_seconds {
                Some(t) => format!(": {:.1}× faster", t / s.atlas_seconds),
                None => format!(" ({})", s.reference_error.clone().unwrap_or_default()),
            }
        );
    }
    page
}

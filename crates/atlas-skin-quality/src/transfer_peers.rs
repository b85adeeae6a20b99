//! The other tools of the transfer benchmark, run as processes on the same source and
//! target: Blender's Data Transfer (through the `bpy` package,
//! `scripts/transfer-peers/blender_data_transfer.py`) and the paper's reference
//! implementation (Python with libigl and scipy, `scripts/transfer-peers/reference_transfer.py`
//! reading it from `../shared/peers`). Each job is a JSON file; answers are cached under
//! `target/transfer-benchmark/cache/<tool>/` by a hash of the job and of the script, so a
//! second run asks neither tool again (answers that are errors are not kept: a failure
//! may come from the tool's installation, and is asked again).

use crate::run::run_process;
use crate::transfer_split::Split;
use anyhow::{Context, Result};
use atlas_skin::mesh::weld;
use atlas_skin::mesh::weld::DEFAULT_WELD_TOLERANCE;
use atlas_skin_runtime::VertexWeights;
use glam::Vec3;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::collections::HashMap;
use std::ffi::OsString;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A tool run through Python.
#[derive(Debug, Clone)]
pub struct Peer {
    /// Cache folder name and display name.
    pub name: &'static str,
    pub python: PathBuf,
    pub script: PathBuf,
    /// Arguments before the job pairs.
    pub leading_args: Vec<OsString>,
}

/// One tool's answer to one job.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Answer {
    pub weights: Option<Vec<Vec<f64>>>,
    pub seconds: f64,
    pub error: Option<String>,
}

impl Answer {
    /// The rows of the stored target vertices (`job`'s welded rows copied to every stored
    /// vertex), negative entries dropped and each row rescaled to sum to 1 as a glTF
    /// exporter stores it (the reference implementation's rows are neither clamped nor
    /// normalised), or the tool's error.
    pub fn rows(&self, job: &Job) -> Result<VertexWeights, String> {
        let weights = self
            .weights
            .as_ref()
            .ok_or_else(|| self.error.clone().unwrap_or_else(|| "no weights".into()))?;
        if weights.len() != job.welded_vertices {
            return Err(format!(
                "{} rows for {} vertices",
                weights.len(),
                job.welded_vertices
            ));
        }
        Ok(VertexWeights::from_rows(job.welded_of_stored.iter().map(
            |&w| {
                let row = &weights[w as usize];
                let total: f64 = row.iter().filter(|&&w| w > 0.0).sum();
                row.iter()
                    .enumerate()
                    .filter(|&(_, &w)| w > 0.0)
                    .map(|(j, &w)| (j as u32, (w / total) as f32))
                    .collect::<Vec<_>>()
            },
        )))
    }
}

/// A job's text and its cache key; the target is welded (seams joined, as atlas-skin
/// welds it: the reference implementation solves on the mesh it is given).
pub struct Job {
    pub key: String,
    pub text: String,
    /// The welded vertex of every stored target vertex.
    pub welded_of_stored: Vec<u32>,
    pub welded_vertices: usize,
}

/// The job of `split`: the source compacted to the vertices its triangles use, its rows
/// dense; the target; the matching distance (absolute) and angle.
pub fn job(split: &Split, distance: f64, angle_degrees: f64) -> Job {
    let mut local = vec![u32::MAX; split.positions.len()];
    let mut used = Vec::new();
    for &v in split.source_triangles.iter().flatten() {
        if local[v as usize] == u32::MAX {
            local[v as usize] = used.len() as u32;
            used.push(v);
        }
    }
    let joints = split.skeleton.len();
    let dense = |v: u32| {
        let mut row = vec![0.0f64; joints];
        for (j, w) in split.artist.row(v as usize) {
            row[j as usize] += f64::from(w);
        }
        row
    };
    let flat = |p: &Vec3| [p.x, p.y, p.z];
    let welded = weld(
        &split.target_positions(),
        &split.target_triangles,
        DEFAULT_WELD_TOLERANCE,
    );
    let target_positions: Vec<Vec3> = welded.mesh.positions.iter().map(|p| p.as_vec3()).collect();
    let text = json!({
        "source": {
            "positions": used.iter().map(|&v| flat(&split.positions[v as usize])).collect::<Vec<_>>(),
            "triangles": split.source_triangles.iter().map(|t| t.map(|v| local[v as usize])).collect::<Vec<_>>(),
            "weights": used.iter().map(|&v| dense(v)).collect::<Vec<_>>(),
        },
        "target": {
            "positions": target_positions.iter().map(flat).collect::<Vec<_>>(),
            "triangles": welded.mesh.triangles,
        },
        "distance": distance,
        "angle_degrees": angle_degrees,
    })
    .to_string();
    let key = format!("{:016x}", hash_of(text.as_bytes()));
    Job {
        key,
        text,
        welded_vertices: welded.mesh.vertex_count(),
        welded_of_stored: welded.welded_of_stored,
    }
}

/// A 64-bit hash of `bytes` (the standard library's SipHash: a cache key, not a
/// checksum; a different toolchain may compute other keys, which only misses the cache).
fn hash_of(bytes: &[u8]) -> u64 {
    let mut hasher = std::hash::DefaultHasher::new();
    bytes.hash(&mut hasher);
    hasher.finish()
}

/// Jobs handed to one process.
pub const JOBS_PER_PROCESS: usize = 40;

/// Runs `peer` on every job whose answer is not cached (in batches of
/// [`JOBS_PER_PROCESS`]) and returns every job's answer by key.
pub fn answers(peer: &Peer, jobs: &[&Job], cache: &Path) -> Result<HashMap<String, Answer>> {
    let script = std::fs::read(&peer.script)
        .with_context(|| format!("reading {}", peer.script.display()))?;
    let folder = cache
        .join(peer.name)
        .join(format!("{:016x}", hash_of(&script)));
    std::fs::create_dir_all(&folder)?;
    let answer_path = |key: &str| folder.join(format!("{key}.json"));
    let missing: Vec<&Job> = jobs
        .iter()
        .copied()
        .filter(|j| !answer_path(&j.key).is_file())
        .collect();
    for (batch, chunk) in missing.chunks(JOBS_PER_PROCESS).enumerate() {
        eprintln!(
            "{}: jobs {}..{} of {} not cached",
            peer.name,
            batch * JOBS_PER_PROCESS + 1,
            batch * JOBS_PER_PROCESS + chunk.len(),
            missing.len()
        );
        let mut args = vec![peer.script.clone().into_os_string()];
        args.extend(peer.leading_args.iter().cloned());
        for job in chunk {
            let path = folder.join(format!("{}.job.json", job.key));
            std::fs::write(&path, &job.text)?;
            args.push(path.into_os_string());
            args.push(answer_path(&job.key).into_os_string());
        }
        run_process(&peer.python, &args, Duration::from_secs(3600))
            .with_context(|| format!("running {}", peer.name))?;
        for job in chunk {
            let _ = std::fs::remove_file(folder.join(format!("{}.job.json", job.key)));
        }
    }
    jobs.iter()
        .map(|job| {
            let path = answer_path(&job.key);
            let text =
                std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
            let answer: Answer = serde_json::from_slice(&text)
                .with_context(|| format!("parsing {}", path.display()))?;
            if answer.error.is_some() {
                std::fs::remove_file(&path)?;
            }
            Ok((job.key.clone(), answer))
        })
        .collect()
}

//! The weight-transfer job (`atlas-skin transfer`, the Python package's `transfer_file`):
//! read a skinned character (the source) and meshes placed in its rest space (the
//! targets), carry the source's weights onto them ([`atlas_skin::transfer`]: closest point
//! matching, inpainting), and write one skinned glTF binary with the source's skeleton and
//! meshes plus the targets, with the JSON and HTML reports when asked. Or, with
//! [`TransferJob::meshes`], re-weight named meshes of the source from its other meshes.
//! Outputs go through one [`OutputPlan`] as `skin`'s do: checked before any work,
//! complete or untouched, never over an input.

use crate::html::{write_html, HtmlError};
use crate::job::{Input, Outputs};
use atlas_skin::transfer::{
    transfer_weights, PieceSummary, TransferCounts, TransferError, TransferParams, TransferSource,
    Transferred,
};
use atlas_skin_io::gltf::{
    skinned_glb_taking_document, with_added_meshes, AddedMesh, WriteOptions,
};
use atlas_skin_io::{Character, IoError, LoadOptions, OutputPlan};
use atlas_skin_runtime::VertexWeights;
use glam::Vec3;
use serde::Serialize;
use serde_json::{json, Map, Value};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::time::Instant;
use thiserror::Error;

/// Why a transfer job failed; each message names the file.
#[derive(Debug, Error)]
pub enum TransferJobError {
    #[error(transparent)]
    Io(#[from] IoError),
    #[error("{} has no skeleton: the source must be a skinned character", path.display())]
    NoSkeleton { path: PathBuf },
    #[error("{} has no skin weights: skin it first (atlas-skin skin)", path.display())]
    NoWeights { path: PathBuf },
    #[error("cannot transfer weights from {}", path.display())]
    Source {
        path: PathBuf,
        #[source]
        source: TransferError,
    },
    #[error("cannot transfer weights onto {}", path.display())]
    Target {
        path: PathBuf,
        #[source]
        source: TransferError,
    },
    #[error("{}: {message}", path.display())]
    Meshes { path: PathBuf, message: String },
    #[error("give target meshes, or --meshes to re-weight meshes of the source (not both)")]
    Nothing,
    #[error("--max-influences must be between 1 and {max}, not {found}")]
    MaxInfluences { found: usize, max: usize },
    #[error("cannot serialise the report")]
    Report(#[source] serde_json::Error),
    #[error(transparent)]
    Html(#[from] HtmlError),
}

/// One transfer: the source, the targets (or the source's meshes to re-weight), settings
/// and outputs ([`Outputs::glb`], `report` and `html`; a transfer writes no debug view
/// and no rig_info).
#[derive(Debug, Clone, Default)]
pub struct TransferJob {
    pub source: Input,
    /// Mesh files in the source's rest space, each added to the output as one mesh.
    pub targets: Vec<PathBuf>,
    /// Names of meshes of the source (glTF mesh or node names, FBX mesh names) to
    /// re-weight from its other meshes, instead of targets.
    pub meshes: Vec<String>,
    pub params: TransferParams,
    /// Influences written per vertex (the largest, renormalised); 0 means 4.
    pub max_influences: usize,
    pub outputs: Outputs,
    /// Return the JSON report in the outcome.
    pub keep_report: bool,
}

/// What a finished transfer tells its caller.
#[derive(Debug, Clone)]
pub struct TransferOutcome {
    pub report: Option<Value>,
    /// Pieces bound where they come nearest, and the readers' warnings.
    pub warnings: Vec<String>,
    /// One line per target: vertices matched, inpainted, bound to the nearest point.
    pub summary: String,
    /// The weights of every target, one row per stored vertex (with [`TransferJob::meshes`]:
    /// one set, the named meshes' vertices in the source's stored order), for callers that
    /// want the arrays.
    pub weights: Vec<VertexWeights>,
}

/// The report of one target.
#[derive(Serialize)]
struct TargetReport {
    counts: TransferCounts,
    distance: f64,
    name: String,
    path: String,
    pieces: Vec<PieceSummary>,
    vertex_sources: Vec<&'static str>,
}

/// A mesh to transfer onto: its name and file (for messages), geometry.
struct Target {
    name: String,
    path: PathBuf,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// For meshes of the source: the source's stored vertex of every target vertex.
    source_vertices: Vec<u32>,
}

impl TransferJob {
    /// Runs the job (module documentation); `progress` is told each step as it starts.
    pub fn run(&self, progress: &mut dyn FnMut(&str)) -> Result<TransferOutcome, TransferJobError> {
        if self.targets.is_empty() == self.meshes.is_empty() {
            return Err(TransferJobError::Nothing);
        }
        let max_influences = if self.max_influences == 0 {
            4
        } else {
            self.max_influences
        };
        let max = atlas_skin_io::gltf::MAX_INFLUENCES;
        if max_influences > max {
            return Err(TransferJobError::MaxInfluences {
                found: max_influences,
                max,
            });
        }
        self.params
            .validate()
            .map_err(|source| TransferJobError::Source {
                path: self.source.path.clone().unwrap_or_default(),
                source,
            })?;
        let plan = OutputPlan::new(
            self.source
                .paths()
                .chain(self.targets.iter().map(PathBuf::as_path)),
            self.outputs.paths(),
        )?;
        let mut timings = Map::new();
        let start = Instant::now();
        progress("reading");
        let mut character = self.source.load()?;
        let path = character.path.clone();
        let Some(skeleton) = character.skeleton.clone() else {
            return Err(TransferJobError::NoSkeleton { path });
        };
        let Some(source_weights) = character.reference_weights.clone() else {
            return Err(TransferJobError::NoWeights { path });
        };
        let mut warnings = character.warnings.clone();
        let (source_triangles, targets) = if self.meshes.is_empty() {
            let targets = self
                .targets
                .iter()
                .map(|target| read_target(target, &mut warnings))
                .collect::<Result<Vec<_>, _>>()?;
            (character.mesh.triangles.clone(), targets)
        } else {
            let (kept, target) = split_named_meshes(&character, &self.meshes)?;
            (kept, vec![target])
        };
        timings.insert("read".into(), json!(ms(start)));

        progress("matching");
        let start = Instant::now();
        let source = TransferSource::new(
            &character.mesh.positions,
            &source_triangles,
            &source_weights,
            skeleton.len(),
        )
        .map_err(|source| TransferJobError::Source {
            path: path.clone(),
            source,
        })?;
        let mut results: Vec<Transferred> = Vec::with_capacity(targets.len());
        for target in &targets {
            progress(&format!("transferring onto {}", target.name));
            let result =
                transfer_weights(&source, &target.positions, &target.triangles, &self.params)
                    .map_err(|source| TransferJobError::Target {
                        path: target.path.clone(),
                        source,
                    })?;
            for piece in result.pieces.iter().filter(|p| p.bound_to_nearest) {
                warnings.push(format!(
                    "{}: a piece of {} vertices matched nowhere (nearest {:.4}, matching \
                     distance {:.4}): bound whole to the source where it comes nearest",
                    target.name, piece.vertices, piece.nearest_distance, result.distance
                ));
            }
            results.push(result);
        }
        timings.insert("transfer".into(), json!(ms(start)));

        progress("writing");
        let start = Instant::now();
        let options = WriteOptions {
            max_influences,
            ..WriteOptions::default()
        };
        let glb = if self.meshes.is_empty() {
            let glb = skinned_glb_taking_document(
                &mut character,
                &source_weights,
                &options,
                &self.outputs.glb,
            )?;
            let added: Vec<AddedMesh> = targets
                .iter()
                .zip(&results)
                .map(|(target, result)| AddedMesh {
                    name: &target.name,
                    positions: &target.positions,
                    triangles: &target.triangles,
                    weights: &result.weights,
                })
                .collect();
            with_added_meshes(&glb, &added, max_influences, &self.outputs.glb)?
        } else {
            let weights = replaced_rows(&source_weights, &targets[0], &results[0].weights);
            skinned_glb_taking_document(&mut character, &weights, &options, &self.outputs.glb)?
        };
        plan.write(&self.outputs.glb, &glb)?;
        timings.insert("write".into(), json!(ms(start)));

        let report = self.report(
            &path,
            &targets,
            &results,
            &timings,
            &warnings,
            max_influences,
        );
        if let Some(out) = &self.outputs.report {
            let text = serde_json::to_vec_pretty(&report).map_err(TransferJobError::Report)?;
            plan.write(out, &text)?;
        }
        if let Some(out) = &self.outputs.html {
            write_html(&glb, Some(&report), out, &plan)?;
        }
        let summary = targets
            .iter()
            .zip(&results)
            .map(|(target, result)| {
                let c = &result.counts;
                format!(
                    "{}: {} vertices, {} matched, {} inpainted, {} bound to the nearest point",
                    target.name, c.stored_vertices, c.matched, c.inpainted, c.nearest
                )
            })
            .chain([format!("-> {}", self.outputs.glb.display())])
            .collect::<Vec<_>>()
            .join("\n");
        Ok(TransferOutcome {
            report: self.keep_report.then_some(report),
            warnings,
            summary,
            weights: results.into_iter().map(|r| r.weights).collect(),
        })
    }

    fn report(
        &self,
        source: &Path,
        targets: &[Target],
        results: &[Transferred],
        timings: &Map<String, Value>,
        warnings: &[String],
        max_influences: usize,
    ) -> Value {
        let targets: Vec<TargetReport> = targets
            .iter()
            .zip(results)
            .map(|(target, result)| TargetReport {
                counts: result.counts.clone(),
                distance: result.distance,
                name: target.name.clone(),
                path: target.path.display().to_string(),
                pieces: result.pieces.clone(),
                vertex_sources: result.vertex_sources.iter().map(|s| s.name()).collect(),
            })
            .collect();
        json!({
            "input": source.display().to_string(),
            "max_influences": max_influences,
            "settings": self.params,
            "targets": targets,
            "timings_ms": timings,
            "warnings": warnings,
        })
    }
}

/// Reads a target mesh file (any format the tool reads; a skeleton or weights it has are
/// ignored, and so is the reader's warning that it has none).
fn read_target(path: &Path, warnings: &mut Vec<String>) -> Result<Target, TransferJobError> {
    let character = atlas_skin_io::load_character(path, &LoadOptions::default())?;
    warnings.extend(
        character
            .warnings
            .into_iter()
            .filter(|w| !w.starts_with("no skeleton"))
            .map(|w| format!("{}: {w}", path.display())),
    );
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "target".into());
    Ok(Target {
        name,
        path: path.to_path_buf(),
        positions: character.mesh.positions,
        triangles: character.mesh.triangles,
        source_vertices: Vec::new(),
    })
}

/// The mesh names of a character and the stored vertex range of each: glTF primitives
/// (by mesh name and by node name), FBX meshes.
fn named_ranges(character: &Character) -> Vec<(String, std::ops::Range<usize>)> {
    if let Some(source) = &character.gltf {
        let name = |key: &str, index: usize| {
            source.document[key][index]["name"]
                .as_str()
                .map(str::to_owned)
        };
        return source
            .primitives
            .iter()
            .flat_map(|p| {
                [name("meshes", p.mesh), name("nodes", p.node)]
                    .into_iter()
                    .flatten()
                    .map(|n| (n, p.vertices.clone()))
            })
            .collect();
    }
    character
        .parts
        .iter()
        .map(|part| (part.name.clone(), part.vertices.clone()))
        .collect()
}

/// The source's triangles outside the named meshes, and the named meshes as one target
/// (their vertices in stored order).
fn split_named_meshes(
    character: &Character,
    names: &[String],
) -> Result<(Vec<[u32; 3]>, Target), TransferJobError> {
    let ranges = named_ranges(character);
    let error = |message: String| TransferJobError::Meshes {
        path: character.path.clone(),
        message,
    };
    if ranges.is_empty() {
        return Err(error(
            "--meshes needs a source with named meshes (glTF, VRM or FBX)".into(),
        ));
    }
    let mut chosen = vec![false; character.mesh.positions.len()];
    for name in names {
        let found: Vec<_> = ranges.iter().filter(|(n, _)| n == name).collect();
        if found.is_empty() {
            let known: BTreeSet<&str> = ranges.iter().map(|(n, _)| n.as_str()).collect();
            return Err(error(format!(
                "no mesh named {name:?}; its meshes: {}",
                known.into_iter().collect::<Vec<_>>().join(", ")
            )));
        }
        for (_, range) in found {
            chosen[range.clone()].iter_mut().for_each(|c| *c = true);
        }
    }
    let (inside, outside): (Vec<[u32; 3]>, Vec<[u32; 3]>) = character
        .mesh
        .triangles
        .iter()
        .partition(|t| t.iter().all(|&v| chosen[v as usize]));
    if outside.is_empty() {
        return Err(error(
            "the named meshes are the whole character: no other mesh to take weights from".into(),
        ));
    }
    let vertices: Vec<u32> = (0..chosen.len() as u32)
        .filter(|&v| chosen[v as usize])
        .collect();
    let mut local = vec![u32::MAX; chosen.len()];
    for (k, &v) in vertices.iter().enumerate() {
        local[v as usize] = k as u32;
    }
    let target = Target {
        name: names.join("+"),
        path: character.path.clone(),
        positions: vertices
            .iter()
            .map(|&v| character.mesh.positions[v as usize])
            .collect(),
        triangles: inside
            .iter()
            .map(|t| t.map(|v| local[v as usize]))
            .collect(),
        source_vertices: vertices,
    };
    Ok((outside, target))
}

/// The source's rows with those of the re-weighted vertices (`target`'s, of the source)
/// replaced by `transferred`.
fn replaced_rows(
    source: &VertexWeights,
    target: &Target,
    transferred: &VertexWeights,
) -> VertexWeights {
    let mut replacement = vec![u32::MAX; source.vertex_count()];
    for (k, &v) in target.source_vertices.iter().enumerate() {
        replacement[v as usize] = k as u32;
    }
    VertexWeights::from_rows((0..source.vertex_count()).map(|v| match replacement[v] {
        u32::MAX => source.row(v).collect::<Vec<_>>(),
        k => transferred.row(k as usize).collect(),
    }))
}

fn ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

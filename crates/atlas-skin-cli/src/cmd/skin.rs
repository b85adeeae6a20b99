//! `atlas-skin skin`: the main job. Reads a character, computes its weights (cuts at the
//! joints, regions, geodesic overlaps, blended weights: [`atlas_skin::pipeline::skin`]) and
//! writes a skinned glTF binary, with an optional JSON report, debug view and HTML report.

use crate::counts::{check_count, MAX_INFLUENCES};
use crate::input::InputArgs;
use anyhow::{anyhow, bail, Context, Result};
use atlas_skin::pipeline::{skin, SkinInput, SkinParams, Skinned, Stage};
use atlas_skin::report::{debug_colors, debug_lines};
use atlas_skin::weights::blend::Blend;
use atlas_skin::weights::pieces::PieceTreatment;
use atlas_skin::weights::WeightCounts;
use atlas_skin::{BoundaryKind, Decomposition};
use atlas_skin_io::gltf::{debug_glb, skinned_glb, WriteOptions};
use atlas_skin_io::{Character, OutputPlan};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::{json, Value};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// The skinned glTF binary to write.
    #[arg(short, long, value_name = "OUT.glb")]
    pub output: PathBuf,
    /// Write a JSON report: decomposition, overlap widths, timings, counts, warnings.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Settings as JSON (any subset of `decompose`, `overlap` {`factor`, `per_joint`},
    /// `blend`, `max_influences`); the options below override it.
    #[arg(long, value_name = "FILE.json")]
    pub config: Option<PathBuf>,
    /// Overlap half-width as a multiple of each boundary's diameter (the paper: 0.5).
    #[arg(long, value_name = "F")]
    pub overlap: Option<f64>,
    /// Overlap factor for one joint, repeatable: from quasi-rigid (small) to soft (large).
    #[arg(long = "overlap-joint", value_name = "NAME=F")]
    pub overlap_joint: Vec<String>,
    /// How overlapping regions are blended: the normalised partition of unity (default)
    /// or the paper's Eq. 1.
    #[arg(long, value_enum)]
    pub blend: Option<BlendArg>,
    /// Give this joint a boundary even where the rules would not (repeatable).
    #[arg(long, value_name = "JOINT")]
    pub force: Vec<String>,
    /// Give this joint no boundary: its part moves with its parent's (repeatable).
    #[arg(long, value_name = "JOINT")]
    pub forbid: Vec<String>,
    /// Influences kept per vertex (the largest, renormalised).
    #[arg(long, value_name = "N",
          value_parser = crate::counts::count_between(1, crate::counts::MAX_INFLUENCES))]
    pub max_influences: Option<usize>,
    /// Write an unskinned glb with the regions as vertex colours and the cut curves.
    #[arg(long, value_name = "D.glb")]
    pub debug_glb: Option<PathBuf>,
    /// Write a self-contained HTML report with an interactive view of the result.
    #[arg(long, value_name = "R.html")]
    pub html: Option<PathBuf>,
    /// Also write the weights (as in the glb: the largest --max-influences, renormalised)
    /// and the skeleton in RigNet's rig_info text format; `skin` lines number the vertices
    /// as the mesh file does (OBJ order).
    #[arg(long, value_name = "OUT.txt")]
    pub rig_info: Option<PathBuf>,
}

/// `--blend` values.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum BlendArg {
    /// Normalised partition of unity: continuous everywhere.
    Pou,
    /// The paper's Eq. 1.
    Paper,
}

impl From<BlendArg> for Blend {
    fn from(arg: BlendArg) -> Self {
        match arg {
            BlendArg::Pou => Blend::PartitionOfUnity,
            BlendArg::Paper => Blend::Paper,
        }
    }
}

pub fn run(args: Args) -> Result<()> {
    let outputs = [
        Some(&args.output),
        args.report.as_ref(),
        args.debug_glb.as_ref(),
        args.html.as_ref(),
        args.rig_info.as_ref(),
    ]
    .into_iter()
    .flatten()
    .map(PathBuf::as_path);
    let plan = OutputPlan::new(args.input.paths().chain(args.config.as_deref()), outputs)?;
    let params = params(&args)?;
    let character = args.input.load()?;
    let Some(skeleton) = character.skeleton.clone() else {
        bail!(
            "{} has no skeleton: give one with --skeleton",
            character.path.display()
        );
    };
    let mut timings = serde_json::Map::new();
    let progress = progress_bar();
    let skinned = skin(
        SkinInput {
            positions: &character.mesh.positions,
            triangles: &character.mesh.triangles,
            skeleton: &skeleton,
            end_joints: &character.end_joints,
        },
        &params,
        &mut |stage: Stage| progress.set_message(stage.name()),
    )
    .with_context(|| format!("cannot skin {}", character.path.display()))?;
    for &(stage, ms) in &skinned.timings.0 {
        timings.insert(stage.name().into(), json!(ms));
    }

    progress.set_message("writing");
    let start = Instant::now();
    let options = WriteOptions {
        max_influences: params.max_influences,
        ..WriteOptions::default()
    };
    let glb = skinned_glb(&character, &skinned.weights, &options, &args.output)?;
    plan.write(&args.output, &glb)?;
    timings.insert("write".into(), json!(start.elapsed().as_secs_f64() * 1e3));
    let rig_info = args.rig_info.as_ref().map(|path| {
        let pruned = skinned.weights.pruned(params.max_influences);
        let text = atlas_skin_io::rig_info::to_text(&skeleton, &pruned, &character.file_vertex);
        (path, text)
    });
    progress.finish_and_clear();
    for warning in &skinned.warnings {
        eprintln!("warning: {warning}");
    }

    let report = report(&character, &skinned, timings);
    if let Some(path) = &args.report {
        let text = serde_json::to_string_pretty(&report)?;
        plan.write(path, text.as_bytes())?;
    }
    if let Some((path, text)) = &rig_info {
        plan.write(path, text.as_bytes())?;
    }
    if let Some(path) = &args.debug_glb {
        plan.write(path, &debug_view(&skinned, path)?)?;
    }
    if let Some(path) = &args.html {
        crate::html::write_html(&glb, Some(&report), path, &plan)?;
    }
    let d = skinned.decomposition.report();
    println!(
        "{}: {} vertices, {} joints ({} cut, {} soft, {} skipped), {} regions -> {}",
        character.path.display(),
        skinned.counts.stored_vertices,
        skinned.counts.joints,
        d.cuts,
        d.soft,
        d.skipped,
        skinned.decomposition.regions.len(),
        args.output.display()
    );
    Ok(())
}

/// Settings: the config file, then the command-line overrides.
fn params(args: &Args) -> Result<SkinParams> {
    let mut params: SkinParams = match &args.config {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            serde_json::from_str(&text)
                .with_context(|| format!("{} is not a valid settings file", path.display()))?
        }
        None => SkinParams::default(),
    };
    if let Some(factor) = args.overlap {
        params.overlap.factor = factor;
    }
    for entry in &args.overlap_joint {
        let Some((name, value)) = entry.rsplit_once('=') else {
            bail!("--overlap-joint {entry:?}: expected NAME=F");
        };
        let factor: f64 = value
            .parse()
            .with_context(|| format!("--overlap-joint {entry:?}: {value:?} is not a number"))?;
        params.overlap.per_joint.insert(name.to_string(), factor);
    }
    if let Some(blend) = args.blend {
        params.blend = blend.into();
    }
    if let Some(n) = args.max_influences {
        params.max_influences = n;
    }
    if let Some(path) = &args.config {
        check_count(params.max_influences, 1, MAX_INFLUENCES)
            .map_err(|e| anyhow!("{}: max_influences {e}", path.display()))?;
    }
    params.decompose.force.extend(args.force.iter().cloned());
    params.decompose.forbid.extend(args.forbid.iter().cloned());
    Ok(params)
}

/// A spinner with the current stage on stderr, hidden when stderr is not a terminal.
fn progress_bar() -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(Duration::from_millis(100));
    bar
}

/// The JSON report: `decomposition` (the decomposition's own report, each joint with its
/// `overlap_width` and cut `curve`, and the region of every stored vertex),
/// `timings_ms`, `counts`, `warnings`.
fn report(
    character: &Character,
    skinned: &Skinned,
    timings: serde_json::Map<String, Value>,
) -> Value {
    let decomposition = &skinned.decomposition;
    let mut decomposition_json = json!(decomposition.report());
    if let Some(joints) = decomposition_json["joints"].as_array_mut() {
        for (joint, decision) in joints.iter_mut().zip(&decomposition.joints) {
            let Some(k) = decision.boundary else { continue };
            let k = k as usize;
            joint["overlap_width"] = json!(skinned.overlaps.half_widths[k]);
            if let BoundaryKind::Cut { curve } = &decomposition.boundaries[k].kind {
                let points: Vec<[f64; 3]> = curve
                    .iter()
                    .map(|&v| decomposition.surface.positions[v as usize].to_array())
                    .collect();
                joint["curve"] = json!(points);
            }
        }
    }
    // Region of every stored vertex: that of the first face of its welded vertex.
    let mut vertex_region = vec![None; decomposition.welded_vertex_count];
    for (f, t) in decomposition.surface.triangles.iter().enumerate().rev() {
        for &v in t {
            if let Some(slot) = vertex_region.get_mut(v as usize) {
                *slot = Some(decomposition.face_region[f]);
            }
        }
    }
    decomposition_json["vertex_regions"] = json!(skinned
        .welded_of_stored
        .iter()
        .map(|&w| vertex_region.get(w as usize).copied().flatten())
        .collect::<Vec<_>>());

    let counts = &skinned.counts;
    let mut warnings = character.warnings.clone();
    warnings.extend(skinned.warnings.iter().cloned());
    let weight_counts = &counts.weights;
    if weight_counts.from_surface > 0 {
        warnings.push(format!(
            "fallback: {} vertices of decomposed pieces lie in regions no joint reaches and took \
             the weights of the nearest weighted vertex along their piece",
            weight_counts.from_surface
        ));
    }
    if !weight_counts.inactive_soft_joints.is_empty() {
        let names: Vec<&str> = weight_counts
            .inactive_soft_joints
            .iter()
            .map(|&j| decomposition.joints[j as usize].name.as_str())
            .collect();
        warnings.push(format!(
            "{} soft boundaries have no cross-section near their joint and carry no weight: {}",
            names.len(),
            names.join(", ")
        ));
    }
    if counts.unreferenced_stored_vertices > 0 {
        warnings.push(format!(
            "{} stored vertices are used by no triangle: bound to their nearest bone",
            counts.unreferenced_stored_vertices
        ));
    }
    json!({
        "input": character.path.display().to_string(),
        "decomposition": decomposition_json,
        "timings_ms": timings,
        "counts": {
            "vertices": counts.stored_vertices,
            "welded_vertices": counts.welded_vertices,
            "surface_vertices": counts.surface_vertices,
            "joints": counts.joints,
            "regions": decomposition.regions.len(),
            "unreachable_vertices": weight_counts.unreachable,
            "fallback_weighted_vertices": weight_counts.from_surface
                + counts.unreferenced_stored_vertices,
            "max_influences": skinned.weights.max_influences(),
            "leaf_patches": weight_counts.leaf_patches.len(),
            "far_bone_vertices": weight_counts.far_bone_vertices,
            "duplicate_faces": counts.duplicate_faces,
            "inside_out_pieces": counts.inside_out_pieces,
        },
        "pieces": pieces_report(decomposition, weight_counts),
        "warnings": warnings,
    })
}

/// How the pieces were weighted: per treatment the number of pieces and vertices, and
/// every piece that was not decomposed (`attached`, `rigid` with its joint, `joints`).
fn pieces_report(decomposition: &Decomposition, counts: &WeightCounts) -> Value {
    let mut summary = serde_json::Map::new();
    let mut loose = Vec::new();
    for piece in &counts.pieces {
        let (name, joint) = match piece.treatment {
            PieceTreatment::Body => ("body", None),
            PieceTreatment::Attached => ("attached", None),
            PieceTreatment::Rigid(j) => ("rigid", Some(j)),
            PieceTreatment::Joints => ("joints", None),
        };
        let entry = summary
            .entry(name)
            .or_insert_with(|| json!({"pieces": 0, "vertices": 0, "fallback_vertices": 0}));
        for (key, add) in [
            ("pieces", 1),
            ("vertices", piece.vertices),
            ("fallback_vertices", piece.fallback_vertices),
        ] {
            entry[key] = json!(entry[key].as_u64().unwrap_or(0) + add as u64);
        }
        if piece.treatment != PieceTreatment::Body {
            loose.push(json!({
                "treatment": name,
                "joint": joint.map(|j| decomposition.joints[j as usize].name.clone()),
                "vertices": piece.vertices,
            }));
        }
    }
    json!({"by_treatment": summary, "not_decomposed": loose})
}

/// The debug view (a glb): the split surface coloured by region, the cut curves as lines.
fn debug_view(skinned: &Skinned, path: &Path) -> Result<Vec<u8>> {
    let d = &skinned.decomposition;
    let positions: Vec<Vec3> = d.surface.positions.iter().map(|p| p.as_vec3()).collect();
    let lines: Vec<[Vec3; 2]> = debug_lines(d)
        .iter()
        .map(|[a, b]| [Vec3::from_array(*a), Vec3::from_array(*b)])
        .collect();
    debug_glb(
        &positions,
        &d.surface.triangles,
        &debug_colors(d),
        &lines,
        [0.0, 0.0, 0.0, 1.0],
        path,
    )
    .with_context(|| format!("cannot write {}", path.display()))
}

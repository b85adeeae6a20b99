//! The Python package `atlas_skin` (its native module `atlas_skin._atlas_skin`): the
//! method on numpy arrays (`compute_weights`), characters read into numpy (`load`, `demo`),
//! posing (`deform_lbs`, `deform_dqs`), the file job of `atlas-skin skin` (`skin_file`)
//! and of `atlas-skin batch` (`batch`), weight transfer on arrays (`transfer`) and the job
//! of `atlas-skin transfer` (`transfer_file`); `fail_on` (the quality gate) raises
//! `QualityGateError`. The GIL is released while Rust works; the signatures and their
//! documentation are in `python/atlas_skin/_atlas_skin.pyi`.

mod arrays;
mod errors;

use crate::errors::{no_panic, rejected, to_py_err, transfer_to_py_err, QualityGateError};
use atlas_skin::pipeline::{skin, SkinInput};
use atlas_skin::transfer::{transfer_weights, TransferParams, TransferSource};
use atlas_skin::weights::blend::Blend;
use atlas_skin::weights::rigid::Binding;
use atlas_skin_io::gltf::MAX_INFLUENCES;
use atlas_skin_io::{Character, LoadOptions};
use atlas_skin_job::batch::{
    collect_inputs, plan_jobs, run_batch, BatchError, BatchOptions, Record,
};
use atlas_skin_job::quality::{Condition, Findings, Verdict};
use atlas_skin_job::report::{skin_report, stage_timings};
use atlas_skin_job::transfer::TransferJob;
use atlas_skin_job::{error_chain, Input, JobError, Outputs, Settings, SkinJob};
use atlas_skin_runtime::{reference, Skeleton, NO_PARENT};
use glam::Vec3;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Mutex;
use std::time::Duration;

/// How the input of `compute_weights` is named in messages and in the report.
const ARRAYS_NAME: &str = "the given arrays";

/// The method's options, from the keyword arguments that Python passes beside a function's
/// own (see `MethodOptions` in the stub): a `None` value keeps the settings file's value or
/// the default; an unknown name is a `TypeError`.
fn method_settings(options: Option<&Bound<'_, PyDict>>) -> PyResult<Settings> {
    let mut settings = Settings::default();
    for (key, value) in options.into_iter().flat_map(|d| d.iter()) {
        let key: String = key.extract()?;
        if value.is_none() {
            continue;
        }
        let wrong_type = |e: PyErr| PyTypeError::new_err(format!("{key}: {e}"));
        match key.as_str() {
            "config" => settings.config = Some(value.extract().map_err(wrong_type)?),
            "overlap" => settings.overlap = Some(value.extract().map_err(wrong_type)?),
            "overlap_joints" => {
                let map: BTreeMap<String, f64> = value.extract().map_err(wrong_type)?;
                settings.overlap_joints = map.into_iter().collect();
            }
            "blend" => {
                let name: String = value.extract().map_err(wrong_type)?;
                let choices = [("pou", Blend::PartitionOfUnity), ("paper", Blend::Paper)];
                settings.blend = Some(one_of("blend", &name, &choices)?);
            }
            "binding" => {
                let name: String = value.extract().map_err(wrong_type)?;
                let choices = [("smooth", Binding::Smooth), ("rigid", Binding::Rigid)];
                settings.binding = Some(one_of("binding", &name, &choices)?);
            }
            "force" => settings.force = value.extract().map_err(wrong_type)?,
            "fail_on" => settings.fail_on = conditions(&value, wrong_type)?,
            "forbid" => settings.forbid = value.extract().map_err(wrong_type)?,
            "max_influences" => {
                let n: i64 = value.extract().map_err(wrong_type)?;
                settings.max_influences = Some(usize::try_from(n).map_err(|_| {
                    PyValueError::new_err(format!(
                        "max_influences {n} is outside 1..={MAX_INFLUENCES}"
                    ))
                })?);
            }
            other => {
                return Err(PyTypeError::new_err(format!(
                    "unexpected keyword argument {other:?}"
                )))
            }
        }
    }
    Ok(settings)
}

/// The value of `choices` named `name`, or a `ValueError` naming the option `key` and
/// its two choices (`blend must be "pou" or "paper", got "linear"`).
fn one_of<T: Copy>(key: &str, name: &str, choices: &[(&str, T); 2]) -> PyResult<T> {
    match choices.iter().find(|(n, _)| *n == name) {
        Some(&(_, value)) => Ok(value),
        None => Err(PyValueError::new_err(format!(
            "{key} must be \"{}\" or \"{}\", got {name:?}",
            choices[0].0, choices[1].0
        ))),
    }
}

/// The quality gate's conditions of `fail_on`: a list of names, or one string of names
/// separated by commas; `wrong_type` makes the error of anything else.
fn conditions(
    value: &Bound<'_, PyAny>,
    wrong_type: impl Fn(PyErr) -> PyErr,
) -> PyResult<Vec<Condition>> {
    let names: Vec<String> = match value.extract::<String>() {
        Ok(text) => text.split(',').map(|n| n.trim().to_string()).collect(),
        Err(_) => value.extract().map_err(wrong_type)?,
    };
    names
        .iter()
        .map(|name| name.parse().map_err(PyValueError::new_err))
        .collect()
}

/// A Python object from JSON (through the `json` module: dicts, lists, str, int, float).
fn json_object<'py>(py: Python<'py>, value: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?
        .call_method1("loads", (value.to_string(),))
}

/// The skeleton of `compute_weights`: positions, parents, optional names, tails and bind
/// frames.
fn skeleton_from_arrays(
    joint_positions: &Bound<'_, PyAny>,
    parents: &Bound<'_, PyAny>,
    names: Option<Vec<String>>,
    tails: Option<&Bound<'_, PyAny>>,
    inverse_bind: Option<&Bound<'_, PyAny>>,
) -> PyResult<Skeleton> {
    let positions = arrays::points(joint_positions, "joint_positions", 'J')?;
    let count = positions.len();
    if count == 0 {
        return Err(PyValueError::new_err(
            "joint_positions is empty: a skeleton needs at least one joint",
        ));
    }
    let parents = arrays::parents(parents, count)?;
    let names = match names {
        Some(names) if names.len() != count => {
            return Err(PyValueError::new_err(format!(
                "names has {} entries for {count} joints",
                names.len()
            )))
        }
        Some(names) => names,
        None => (0..count).map(|j| format!("joint{j}")).collect(),
    };
    let mut seen = HashSet::new();
    if let Some(name) = names.iter().find(|name| !seen.insert(name.as_str())) {
        return Err(PyValueError::new_err(format!(
            "names must be unique: {name:?} is given twice"
        )));
    }
    let invalid = |e| PyValueError::new_err(format!("invalid skeleton: {e}"));
    let skeleton = match inverse_bind {
        Some(matrices) => {
            let matrices = arrays::matrices(matrices, "inverse_bind", Some(count))?;
            let skeleton = Skeleton::new(names, parents, matrices).map_err(invalid)?;
            check_bind_positions(&skeleton, &positions)?;
            skeleton
        }
        None => Skeleton::from_positions(names, parents, &positions).map_err(invalid)?,
    };
    match tails {
        Some(tails) => skeleton
            .with_tails(arrays::optional_points(tails, "tails", count)?)
            .map_err(invalid),
        None => Ok(skeleton),
    }
}

/// The bind positions of `skeleton` (its frames' translations) are `positions`, to 10⁻⁴ of
/// their bounding box's diagonal (float32 matrices inverted).
fn check_bind_positions(skeleton: &Skeleton, positions: &[Vec3]) -> PyResult<()> {
    let (low, high) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(low, high), &p| (low.min(p), high.max(p)),
    );
    let tolerance = 1e-4 * low.distance(high).max(1e-6);
    let bind = skeleton.bind_positions();
    match (0..positions.len()).find(|&j| bind[j].distance(positions[j]) > tolerance) {
        Some(j) => Err(PyValueError::new_err(format!(
            "inverse_bind[{j}] places joint {} at {:?}, not at joint_positions[{j}] {:?}",
            skeleton.names[j],
            bind[j].to_array(),
            positions[j].to_array()
        ))),
        None => Ok(()),
    }
}

#[allow(clippy::too_many_arguments)]
#[pyfunction]
#[pyo3(signature = (
    vertices, triangles, joint_positions, parents, *, tails=None, inverse_bind=None,
    names=None, end_joints=None, **options
))]
fn compute_weights<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    triangles: &Bound<'py, PyAny>,
    joint_positions: &Bound<'py, PyAny>,
    parents: &Bound<'py, PyAny>,
    tails: Option<&Bound<'py, PyAny>>,
    inverse_bind: Option<&Bound<'py, PyAny>>,
    names: Option<Vec<String>>,
    end_joints: Option<Vec<i64>>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyTuple>> {
    let positions = arrays::points(vertices, "vertices", 'V')?;
    let triangles = arrays::triangles(triangles, positions.len())?;
    let skeleton = skeleton_from_arrays(joint_positions, parents, names, tails, inverse_bind)?;
    let end_joints = end_joints
        .unwrap_or_default()
        .into_iter()
        .map(|j| {
            u32::try_from(j)
                .ok()
                .filter(|&j| (j as usize) < skeleton.len())
                .ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "end_joints holds {j}, not a joint index below {}",
                        skeleton.len()
                    ))
                })
        })
        .collect::<PyResult<Vec<u32>>>()?;
    let settings = method_settings(options)?;
    let (weights, report, k, verdict) = py.detach(|| {
        no_panic(|| {
            let settings_error = |e| to_py_err(&JobError::Settings(e));
            let params = settings.params().map_err(settings_error)?;
            let fail_on = settings.fail_on().map_err(settings_error)?;
            let skinned = skin(
                SkinInput {
                    positions: &positions,
                    triangles: &triangles,
                    skeleton: &skeleton,
                    end_joints: &end_joints,
                },
                &params,
                &mut |_| {},
            )
            .map_err(|source| {
                to_py_err(&JobError::Skin {
                    path: ARRAYS_NAME.into(),
                    source,
                })
            })?;
            let findings = Findings::new(&[], &skinned);
            let verdict = Verdict::new(&findings, &fail_on);
            let timings = stage_timings(&skinned);
            let report = skin_report(ARRAYS_NAME, &findings, &verdict, &skinned, timings);
            Ok((skinned.weights, report, params.max_influences, verdict))
        })
    })?;
    if verdict.rejected() {
        let report = json_object(py, &report)?;
        return Err(rejected(py, ARRAYS_NAME, &verdict, report, None));
    }
    let (indices, weights) = arrays::weights_arrays(py, &weights, k)?;
    PyTuple::new(
        py,
        [
            indices.into_any(),
            weights.into_any(),
            json_object(py, &report)?,
        ],
    )
}

/// A character's arrays as a dict (see `load` in the stub).
fn character_dict<'py>(py: Python<'py>, character: &Character) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("path", character.path.display().to_string())?;
    dict.set_item(
        "positions",
        arrays::points_array(py, &character.mesh.positions)?,
    )?;
    dict.set_item(
        "triangles",
        arrays::rows_array(py, &character.mesh.triangles)?,
    )?;
    let empty = Skeleton {
        names: Vec::new(),
        parents: Vec::new(),
        inverse_bind: Vec::new(),
        tails: Vec::new(),
    };
    let skeleton = character.skeleton.as_ref().unwrap_or(&empty);
    dict.set_item("names", skeleton.names.clone())?;
    let parents: Vec<i64> = skeleton
        .parents
        .iter()
        .map(|&p| if p == NO_PARENT { -1 } else { i64::from(p) })
        .collect();
    dict.set_item("parents", PyArray1::from_vec(py, parents))?;
    dict.set_item(
        "joint_positions",
        arrays::points_array(py, &skeleton.bind_positions())?,
    )?;
    let tails: Vec<Vec3> = skeleton
        .tails
        .iter()
        .map(|t| t.unwrap_or(Vec3::NAN))
        .collect();
    dict.set_item("tails", arrays::points_array(py, &tails)?)?;
    dict.set_item(
        "inverse_bind",
        arrays::matrices_array(py, &skeleton.inverse_bind)?,
    )?;
    dict.set_item("end_joints", character.end_joints.clone())?;
    match &character.reference_weights {
        Some(weights) => {
            let (indices, values) = arrays::weights_arrays(py, weights, weights.max_influences())?;
            dict.set_item("indices", indices)?;
            dict.set_item("weights", values)?;
        }
        None => {
            dict.set_item("indices", py.None())?;
            dict.set_item("weights", py.None())?;
        }
    }
    dict.set_item("warnings", character.warnings.clone())?;
    Ok(dict)
}

/// The character file `path` with the companion files and OBJ group of the keyword arguments.
fn file_input(
    path: PathBuf,
    skeleton: Option<PathBuf>,
    group: Option<String>,
    weights: Option<PathBuf>,
) -> Input {
    Input {
        path: Some(path),
        load: LoadOptions {
            skeleton,
            group,
            weights,
        },
    }
}

#[pyfunction]
#[pyo3(signature = (path, *, skeleton=None, group=None, weights=None))]
fn load<'py>(
    py: Python<'py>,
    path: PathBuf,
    skeleton: Option<PathBuf>,
    group: Option<String>,
    weights: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let input = file_input(path, skeleton, group, weights);
    let character =
        py.detach(|| no_panic(|| input.load().map_err(|e| to_py_err(&JobError::Io(e)))))?;
    character_dict(py, &character)
}

#[pyfunction]
fn demo(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let character = py.detach(|| no_panic(|| Ok(atlas_skin_job::demo_character())))?;
    character_dict(py, &character)
}

/// Poses `positions` by linear blend (`method` "lbs") or dual quaternion ("dqs") skinning
/// (the runtime's reference implementations); `deform_lbs` and `deform_dqs` in Python.
#[pyfunction]
fn deform<'py>(
    py: Python<'py>,
    positions: &Bound<'py, PyAny>,
    indices: &Bound<'py, PyAny>,
    weights: &Bound<'py, PyAny>,
    palette: &Bound<'py, PyAny>,
    method: &str,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    type Skinning = fn(&[Vec3], &atlas_skin_runtime::VertexWeights, &[glam::Mat4], &mut [Vec3]);
    let deform: Skinning = match method {
        "lbs" => reference::linear_blend_positions,
        "dqs" => reference::dual_quaternion_positions,
        other => {
            return Err(PyValueError::new_err(format!(
                "method must be \"lbs\" or \"dqs\", got {other:?}"
            )))
        }
    };
    let positions = arrays::points(positions, "positions", 'V')?;
    let palette = arrays::palette(palette)?;
    let weights = arrays::vertex_weights(indices, weights, positions.len(), palette.len())?;
    let posed = py.detach(|| {
        no_panic(|| {
            let mut out = vec![Vec3::ZERO; positions.len()];
            deform(&positions, &weights, &palette, &mut out);
            Ok(out)
        })
    })?;
    arrays::points_array(py, &posed)
}

#[allow(clippy::too_many_arguments)]
#[pyfunction]
#[pyo3(signature = (
    input, output, *, report=None, html=None, debug_glb=None, rig_info=None, skeleton=None,
    group=None, weights=None, keep_rejected=false, **options
))]
fn skin_file<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    report: Option<PathBuf>,
    html: Option<PathBuf>,
    debug_glb: Option<PathBuf>,
    rig_info: Option<PathBuf>,
    skeleton: Option<PathBuf>,
    group: Option<String>,
    weights: Option<PathBuf>,
    keep_rejected: bool,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let job = SkinJob {
        input: file_input(input, skeleton, group, weights),
        settings: method_settings(options)?,
        outputs: Outputs {
            glb: output,
            report,
            html,
            debug_glb,
            rig_info,
        },
        keep_report: true,
        keep_rejected,
    };
    let outcome = py.detach(|| no_panic(|| job.run(&mut |_| {}).map_err(|e| to_py_err(&e))))?;
    let report = json_object(py, &outcome.report.unwrap_or_default())?;
    if outcome.verdict.rejected() {
        let what = job.input.path.as_deref().unwrap_or(Path::new("")).display();
        let kept = outcome.kept.as_deref();
        return Err(rejected(
            py,
            &what.to_string(),
            &outcome.verdict,
            report,
            kept,
        ));
    }
    Ok(report)
}

#[allow(clippy::too_many_arguments)]
#[pyfunction]
#[pyo3(signature = (
    inputs, out_dir, *, jobs=None, resume=false, report=false, html=false, log=None,
    progress=None, keep_rejected=false, **options
))]
fn batch<'py>(
    py: Python<'py>,
    inputs: &Bound<'py, PyAny>,
    out_dir: PathBuf,
    jobs: Option<usize>,
    resume: bool,
    report: bool,
    html: bool,
    log: Option<PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
    keep_rejected: bool,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let inputs: Vec<PathBuf> = match inputs.extract::<PathBuf>() {
        Ok(one) => vec![one],
        Err(_) => inputs.extract()?,
    };
    let options = BatchOptions {
        out_dir,
        jobs: jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        resume,
        report,
        html,
        log,
        keep_rejected,
        settings: method_settings(options)?,
    };
    let refused = |e: BatchError| PyValueError::new_err(error_chain(&e));
    let jobs = py.detach(|| {
        no_panic(|| {
            let files = collect_inputs(&inputs).map_err(refused)?;
            plan_jobs(&files, &options).map_err(refused)
        })
    })?;
    // The batch runs on a thread of its own; this thread passes each finished record to
    // `progress` and checks for signals (Ctrl-C) meanwhile, stopping the batch on an
    // exception from either. The channel holds at most `jobs` records: a worker that
    // finishes a file waits while this thread is that far behind, so a stop takes effect
    // within a few files whatever `progress` does and however the threads are scheduled
    // (with an unbounded channel, a slow `progress` or a starved calling thread let the
    // workers finish the whole batch before a Ctrl-C was seen).
    let stop = AtomicBool::new(false);
    let (sender, receiver) = mpsc::sync_channel::<Record>(options.jobs);
    // A receiver is not Sync; the lock only lets the wait run without the GIL.
    let receiver = Mutex::new(receiver);
    let mut interrupted: Option<PyErr> = None;
    let result = std::thread::scope(|scope| {
        let (jobs, options, stop) = (&jobs, &options, &stop);
        let worker = scope.spawn(move || {
            no_panic(|| {
                let on_record = |record: &Record| {
                    let _ = sender.send(record.clone());
                };
                run_batch(jobs, options, &on_record, stop).map_err(refused)
            })
        });
        loop {
            let next = py.detach(|| {
                let receiver = receiver.lock().unwrap_or_else(|e| e.into_inner());
                receiver.recv_timeout(Duration::from_millis(100))
            });
            let step = match next {
                Ok(record) => py.check_signals().and_then(|()| match &progress {
                    Some(callback) => serde_json::to_value(&record)
                        .map_err(|e| PyValueError::new_err(e.to_string()))
                        .and_then(|value| json_object(py, &value))
                        .and_then(|record| callback.call1((record,)).map(drop)),
                    None => Ok(()),
                }),
                Err(RecvTimeoutError::Timeout) => py.check_signals(),
                Err(RecvTimeoutError::Disconnected) => break,
            };
            if let Err(error) = step {
                stop.store(true, Ordering::Relaxed);
                interrupted.get_or_insert(error);
            }
        }
        py.detach(|| worker.join())
    });
    if let Some(error) = interrupted {
        return Err(error);
    }
    let (records, summary) = result.unwrap_or_else(|_| {
        Err(pyo3::exceptions::PyRuntimeError::new_err(
            "atlas-skin internal error: the batch thread ended abnormally",
        ))
    })?;
    json_object(
        py,
        &serde_json::json!({"records": records, "summary": summary}),
    )
}

/// Weight transfer on numpy arrays (`atlas_skin.transfer`): the source's weights carried
/// onto the target ([`atlas_skin::transfer`]); returns the target's `(V, K)` indices and
/// weights (the `max_influences` largest, renormalised) and what happened as a dict.
#[allow(clippy::too_many_arguments)]
#[pyfunction]
#[pyo3(signature = (
    source_vertices, source_triangles, source_indices, source_weights, target_vertices,
    target_triangles, *, joint_count=None, max_influences=4, distance=None,
    angle_degrees=None, flipped_normals=None, smooth_iterations=None, smooth_alpha=None
))]
fn transfer<'py>(
    py: Python<'py>,
    source_vertices: &Bound<'py, PyAny>,
    source_triangles: &Bound<'py, PyAny>,
    source_indices: &Bound<'py, PyAny>,
    source_weights: &Bound<'py, PyAny>,
    target_vertices: &Bound<'py, PyAny>,
    target_triangles: &Bound<'py, PyAny>,
    joint_count: Option<usize>,
    max_influences: usize,
    distance: Option<f64>,
    angle_degrees: Option<f64>,
    flipped_normals: Option<bool>,
    smooth_iterations: Option<usize>,
    smooth_alpha: Option<f64>,
) -> PyResult<Bound<'py, PyTuple>> {
    if !(1..=MAX_INFLUENCES).contains(&max_influences) {
        return Err(PyValueError::new_err(format!(
            "max_influences {max_influences} is outside 1..={MAX_INFLUENCES}"
        )));
    }
    let params = transfer_params(
        distance,
        angle_degrees,
        flipped_normals,
        smooth_iterations,
        smooth_alpha,
    );
    let positions = arrays::points(source_vertices, "source_vertices", 'V')?;
    let triangles = arrays::triangles(source_triangles, positions.len())?;
    let joints = joint_count.unwrap_or(u32::MAX as usize);
    let weights = arrays::vertex_weights(source_indices, source_weights, positions.len(), joints)?;
    let joints =
        joint_count.unwrap_or_else(|| weights.joints.iter().max().map_or(0, |&j| j as usize + 1));
    let targets = arrays::points(target_vertices, "target_vertices", 'V')?;
    let target_faces = arrays::triangles(target_triangles, targets.len())?;
    let result = py.detach(|| {
        no_panic(|| {
            let source = TransferSource::new(&positions, &triangles, &weights, joints)
                .map_err(|e| PyValueError::new_err(format!("the source: {}", error_chain(&e))))?;
            transfer_weights(&source, &targets, &target_faces, &params)
                .map_err(|e| PyValueError::new_err(format!("the target: {}", error_chain(&e))))
        })
    })?;
    let (indices, values) =
        arrays::weights_arrays(py, &result.weights.pruned(max_influences), max_influences)?;
    let info = serde_json::json!({
        "counts": result.counts,
        "pieces": result.pieces,
        "distance": result.distance,
        "vertex_sources": result.vertex_sources.iter().map(|s| s.name()).collect::<Vec<_>>(),
    });
    PyTuple::new(
        py,
        [
            indices.into_any(),
            values.into_any(),
            json_object(py, &info)?,
        ],
    )
}

/// The transfer settings from the keyword arguments (`None`: the default).
fn transfer_params(
    distance: Option<f64>,
    angle_degrees: Option<f64>,
    flipped_normals: Option<bool>,
    smooth_iterations: Option<usize>,
    smooth_alpha: Option<f64>,
) -> TransferParams {
    let default = TransferParams::default();
    TransferParams {
        distance: distance.unwrap_or(default.distance),
        angle_degrees: angle_degrees.unwrap_or(default.angle_degrees),
        flipped_normals: flipped_normals.unwrap_or(default.flipped_normals),
        smooth_iterations: smooth_iterations.unwrap_or(default.smooth_iterations),
        smooth_alpha: smooth_alpha.unwrap_or(default.smooth_alpha),
    }
}

/// The job of `atlas-skin transfer` (`atlas_skin.transfer_file`); returns the report.
#[allow(clippy::too_many_arguments)]
#[pyfunction]
#[pyo3(signature = (
    source, targets, output, *, meshes=None, report=None, html=None, skeleton=None,
    weights=None, max_influences=4, distance=None, angle_degrees=None,
    flipped_normals=None, smooth_iterations=None, smooth_alpha=None
))]
fn transfer_file<'py>(
    py: Python<'py>,
    source: PathBuf,
    targets: Vec<PathBuf>,
    output: PathBuf,
    meshes: Option<Vec<String>>,
    report: Option<PathBuf>,
    html: Option<PathBuf>,
    skeleton: Option<PathBuf>,
    weights: Option<PathBuf>,
    max_influences: usize,
    distance: Option<f64>,
    angle_degrees: Option<f64>,
    flipped_normals: Option<bool>,
    smooth_iterations: Option<usize>,
    smooth_alpha: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let job = TransferJob {
        source: file_input(source, skeleton, None, weights),
        targets,
        meshes: meshes.unwrap_or_default(),
        params: transfer_params(
            distance,
            angle_degrees,
            flipped_normals,
            smooth_iterations,
            smooth_alpha,
        ),
        max_influences,
        outputs: Outputs {
            glb: output,
            report,
            html,
            ..Outputs::default()
        },
        keep_report: true,
    };
    let outcome =
        py.detach(|| no_panic(|| job.run(&mut |_| {}).map_err(|e| transfer_to_py_err(&e))))?;
    json_object(py, &outcome.report.unwrap_or_default())
}

#[pymodule]
fn _atlas_skin(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("QualityGateError", m.py().get_type::<QualityGateError>())?;
    m.add_function(wrap_pyfunction!(compute_weights, m)?)?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(demo, m)?)?;
    m.add_function(wrap_pyfunction!(deform, m)?)?;
    m.add_function(wrap_pyfunction!(skin_file, m)?)?;
    m.add_function(wrap_pyfunction!(batch, m)?)?;
    m.add_function(wrap_pyfunction!(transfer, m)?)?;
    m.add_function(wrap_pyfunction!(transfer_file, m)?)?;
    Ok(())
}

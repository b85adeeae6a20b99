//! `atlas-skin animate`: put a BVH motion on a skinned character, as a glTF animation on
//! its skeleton (any glTF viewer plays it) or as a sequence of posed OBJ meshes.
//!
//! Every BVH frame is retargeted onto the character's rig by joint names
//! ([`atlas_skin_runtime::retarget`]); the animation has one LINEAR track, one key per
//! frame, for every joint rotation and translation the motion changes (in practice: the
//! matched joints' rotations and the root's translation).

use super::pose::{write_mesh, BvhMotion, Posable};
use crate::input::InputArgs;
use anyhow::{Context, Result};
use atlas_skin_io::gltf::{skinned_glb, WriteOptions};
use atlas_skin_io::{Character, OutputPlan};
use atlas_skin_runtime::{Clip, Interpolation, Property, SkinningMethod, Track, Trs};
use std::path::{Path, PathBuf};

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// The motion: a BVH file whose joint names match the character's (or are paired with
    /// them by --joint-map).
    #[arg(long)]
    pub bvh: PathBuf,
    /// JSON object pairing character joints (keys) with BVH joints (values) whose names
    /// differ; other joints are matched by name.
    #[arg(long, value_name = "MAP.json")]
    pub joint_map: Option<PathBuf>,
    /// Dual quaternion skinning for an OBJ sequence (a glb is skinned by its viewer).
    #[arg(long)]
    pub dqs: bool,
    /// Output: OUT.glb (the character with the animation), or OUT.obj for one posed mesh
    /// per frame, OUT_0001.obj, OUT_0002.obj, ...
    #[arg(short = 'o', long)]
    pub output: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let inputs = || {
        args.input
            .paths()
            .chain([args.bvh.as_path()])
            .chain(args.joint_map.as_deref())
    };
    let is_obj = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    if is_obj {
        // The frame count, hence the outputs, is known once the motion is read.
        let motion = BvhMotion::read(&args.bvh, args.joint_map.as_deref())?;
        let frames = obj_sequence_paths(&args.output, motion.frame_times().len());
        let plan = OutputPlan::new(inputs(), frames.iter().map(PathBuf::as_path))?;
        let character = args.input.load_skinned()?;
        let method = if args.dqs {
            SkinningMethod::DualQuaternion
        } else {
            SkinningMethod::LinearBlend
        };
        write_obj_sequence(&character, &motion, method, &frames, &plan)
    } else {
        let plan = OutputPlan::new(inputs(), [args.output.as_path()])?;
        let character = args.input.load_skinned()?;
        let motion = BvhMotion::read(&args.bvh, args.joint_map.as_deref())?;
        let (weights, options) = animation_options(&character, &motion)?;
        let glb = skinned_glb(&character, weights, &options, &args.output)?;
        plan.write(&args.output, &glb)
            .with_context(|| format!("cannot write {}", args.output.display()))
    }
}

/// The files of an OBJ sequence of `frames` frames written as `out`: OUT_0001.obj, ...
fn obj_sequence_paths(out: &Path, frames: usize) -> Vec<PathBuf> {
    let stem = out.with_extension("");
    (1..=frames)
        .map(|frame| PathBuf::from(format!("{}_{frame:04}.obj", stem.display())))
        .collect()
}

/// The character at `input` with the BVH motion at `bvh` (and the joint map at
/// `joint_map`) as a glTF animation, as the bytes of a `.glb` (for the HTML report).
pub fn animate_glb_bytes(input: &Path, bvh: &Path, joint_map: Option<&Path>) -> Result<Vec<u8>> {
    let character = atlas_skin_io::load_character(input, &Default::default())
        .with_context(|| format!("cannot load {}", input.display()))?;
    let motion = BvhMotion::read(bvh, joint_map)?;
    let (weights, options) = animation_options(&character, &motion)?;
    skinned_glb(&character, weights, &options, input).context("cannot make the animated glb")
}

/// The skinned glb of any input with weights (a glb as it is; other formats, e.g. FBX,
/// written with their own weights), for the viewer.
pub fn skinned_glb_bytes(input: &Path) -> Result<Vec<u8>> {
    if input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"))
    {
        return std::fs::read(input).with_context(|| format!("reading {}", input.display()));
    }
    let character = atlas_skin_io::load_character(input, &Default::default())
        .with_context(|| format!("cannot load {}", input.display()))?;
    let weights = character.reference_weights.as_ref().with_context(|| {
        format!(
            "{} has no skin weights: skin it first (atlas-skin skin)",
            input.display()
        )
    })?;
    Ok(skinned_glb(
        &character,
        weights,
        &WriteOptions::default(),
        input,
    )?)
}

/// The weights to write and the writer options carrying the retargeted animation.
fn animation_options<'a>(
    character: &'a Character,
    motion: &BvhMotion,
) -> Result<(&'a atlas_skin_runtime::VertexWeights, WriteOptions)> {
    let posable = Posable::new(character)?;
    let clip = retargeted_clip(&posable, motion)?;
    let weights = character
        .reference_weights
        .as_ref()
        .context("the character has no skin weights")?;
    Ok((
        weights,
        WriteOptions {
            animations: vec![clip],
            ..WriteOptions::default()
        },
    ))
}

/// The motion as a clip on the character's skeleton (`Track::node` = joint index): a
/// rotation track per joint whose local rotation changes, a translation track per joint
/// whose local translation changes, one LINEAR key per BVH frame.
pub fn retargeted_clip(posable: &Posable, motion: &BvhMotion) -> Result<Clip> {
    let rig = &posable.rig;
    let mut retarget = motion.retarget(rig)?;
    let times = motion.frame_times().to_vec();
    let mut frames: Vec<Vec<Trs>> = Vec::with_capacity(times.len());
    let mut local = rig.rest.clone();
    for &time in &times {
        retarget.apply(&motion.rig, &motion.sample(time), rig, &mut local);
        frames.push(local.clone());
    }
    let mut tracks = Vec::new();
    for (joint, &node) in rig.joint_nodes.iter().enumerate() {
        let node = node as usize;
        let rest = rig.rest[node];
        let rotations = frames.iter().map(|f| f[node].rotation.to_array());
        if frames.iter().any(|f| f[node].rotation != rest.rotation) {
            tracks.push(track(
                joint,
                Property::Rotation,
                &times,
                rotations.flatten(),
            ));
        }
        if frames
            .iter()
            .any(|f| f[node].translation != rest.translation)
        {
            let translations = frames.iter().map(|f| f[node].translation.to_array());
            tracks.push(track(
                joint,
                Property::Translation,
                &times,
                translations.flatten(),
            ));
        }
    }
    Ok(Clip {
        name: motion.clip.name.clone(),
        duration: times.last().copied().unwrap_or(0.0),
        tracks,
    })
}

fn track(
    joint: usize,
    property: Property,
    times: &[f32],
    values: impl Iterator<Item = f32>,
) -> Track {
    Track {
        node: joint as u32,
        property,
        interpolation: Interpolation::Linear,
        times: times.to_vec(),
        values: values.collect(),
    }
}

/// One posed OBJ per frame: `out` with `_0001`, `_0002`, … before the extension.
fn write_obj_sequence(
    character: &Character,
    motion: &BvhMotion,
    method: SkinningMethod,
    frames: &[PathBuf],
    plan: &OutputPlan,
) -> Result<()> {
    let posable = Posable::new(character)?;
    let rig = &posable.rig;
    let mut retarget = motion.retarget(rig)?;
    let mut local = rig.rest.clone();
    for (&time, path) in motion.frame_times().iter().zip(frames) {
        retarget.apply(&motion.rig, &motion.sample(time), rig, &mut local);
        let posed = posable.deform(&local, method)?;
        write_mesh(&posed, &character.mesh.triangles, path, plan)?;
    }
    Ok(())
}

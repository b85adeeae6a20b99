//! `atlas-skin eval`: compares candidate weights with reference (artist) weights on the same
//! mesh: weight difference, deformation error, bleeding, validity
//! ([`atlas_skin_eval`]).

use crate::input::{InputArgs, Prepared, ReadArgs};
use anyhow::{Context, Result};
use atlas_skin_eval::matching::{JointMatch, JointPair};
use atlas_skin_eval::{evaluate, Animation, EvalInput, EvalOptions, Evaluation, Weighted};
use atlas_skin_io::{Character, LoadOptions};
use std::path::PathBuf;

/// Arguments.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The reference character with its weights: .glb/.gltf/.vrm, .fbx, or a mesh with
    /// --skeleton and --weights (or an OBJ with RigNet's --skeleton X_rig.txt).
    pub reference: PathBuf,
    /// The candidate: a skinned file (.glb/.gltf/.vrm, .fbx) of the same character, e.g.
    /// another tool's export. Joints are matched by name, then by name ignoring case and
    /// punctuation, then by bind position; vertices by position (seams may be split
    /// differently).
    pub candidate: PathBuf,
    /// How to read the reference (--skeleton, --group, --weights).
    #[command(flatten)]
    pub read: ReadArgs,
    /// Number of seeded random poses.
    #[arg(long, default_value_t = 10,
          value_parser = crate::counts::count_between(1, crate::counts::MAX_EVAL_POSES))]
    pub poses: usize,
    /// Seed of the first random pose (pose i uses seed + i).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Number of frames of the reference's first animation (0 skips the animation figures).
    #[arg(long, default_value_t = 8,
          value_parser = crate::counts::count_between(0, crate::counts::MAX_EVAL_POSES))]
    pub anim_frames: usize,
    /// Keep only the N largest reference weights per vertex before renormalising
    /// (BASELINES.md does so with 4 for MakeHuman).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub prune_reference: Option<u16>,
    /// List the N vertices with the largest random-pose (LBS) error, with both weight rows
    /// (JSON key `worst_vertices`).
    #[arg(long, value_name = "N", default_value_t = 0,
          value_parser = crate::counts::count_between(0, crate::counts::MAX_WORST_VERTICES))]
    pub worst: usize,
    /// Print the figures as JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: Args) -> Result<()> {
    let reference_input = InputArgs {
        input: Some(args.reference.clone()),
        read: args.read.clone(),
    };
    let reference = Prepared::new(reference_input.load()?);
    let candidate = atlas_skin_io::load_character(&args.candidate, &LoadOptions::default())
        .with_context(|| format!("cannot load {}", args.candidate.display()))?;
    let options = EvalOptions {
        poses: args.poses,
        seed: args.seed,
        anim_frames: args.anim_frames,
        reference_max_influences: args.prune_reference.map(usize::from),
        worst: args.worst,
        ..EvalOptions::default()
    };
    let mut evaluation = compare(&reference, &candidate, &options);
    if !evaluation
        .as_ref()
        .is_ok_and(|e| 2 * e.matched >= e.vertices)
    {
        // Another tool may export the mesh in the scene's space rather than the skin's
        // bind space (Blender bakes a glTF's root rotation in): compare both at rest.
        if let (Some(placed_reference), Some(placed_candidate)) = (
            placed_at_rest(&reference.character),
            placed_at_rest(&candidate),
        ) {
            let placed = compare(
                &Prepared::new(placed_reference),
                &placed_candidate,
                &options,
            );
            if placed.as_ref().is_ok_and(|e| 2 * e.matched >= e.vertices) {
                eprintln!(
                    "warning: the two files' bind spaces differ; compared both in the placement \
                     their node trees give them at rest"
                );
                evaluation = placed;
            }
        }
    }
    let evaluation = evaluation?;
    if evaluation.matched < evaluation.vertices {
        eprintln!(
            "warning: {} of {} reference vertices have no candidate vertex at their position; \
             the figures cover the {} matched",
            evaluation.vertices - evaluation.matched,
            evaluation.vertices,
            evaluation.matched
        );
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&evaluation)?);
    } else {
        print!("{}", summary(&evaluation));
    }
    Ok(())
}

/// Evaluates `candidate`'s weights against `reference`'s.
fn compare(
    reference: &Prepared,
    candidate: &Character,
    options: &EvalOptions,
) -> Result<Evaluation> {
    let character = &reference.character;
    let input = EvalInput {
        reference: weighted(character, "reference")?,
        surface: &reference.welded,
        topology: &reference.topology,
        candidate: weighted(candidate, "candidate")?,
        animation: character
            .rig
            .as_ref()
            .zip(character.clips.first())
            .filter(|_| options.anim_frames > 0)
            .map(|(rig, clip)| Animation { rig, clip }),
    };
    evaluate(&input, options).with_context(|| {
        format!(
            "cannot compare {} with {}",
            candidate.path.display(),
            character.path.display()
        )
    })
}

/// `character` moved from its skin's bind space into the placement its node tree gives it
/// at rest: `T = W₀ · IBM₀`, the rest world matrix of joint 0 times its inverse bind
/// matrix (the identity when the bind pose is the rest pose in the same space). Positions
/// become `T · p` and inverse binds `IBM_j · T⁻¹`, so every joint's bind world becomes
/// `T · B_j` and skinning with the rig's world matrices is unchanged. `None` without a
/// skeleton and rig, or when T is not invertible.
fn placed_at_rest(character: &Character) -> Option<Character> {
    let (skeleton, rig) = (character.skeleton.as_ref()?, character.rig.as_ref()?);
    rig.validate().ok()?;
    let mut node_world = vec![glam::Mat4::IDENTITY; rig.len()];
    rig.world(&rig.rest, &mut node_world);
    let root_node = *rig.joint_nodes.first()? as usize;
    let placement = node_world[root_node] * *skeleton.inverse_bind.first()?;
    if placement.determinant().abs() < f32::EPSILON || !placement.is_finite() {
        return None;
    }
    let mut placed = character.clone();
    for p in &mut placed.mesh.positions {
        *p = placement.transform_point3(*p);
    }
    let inverse = placement.inverse();
    if let Some(skeleton) = placed.skeleton.as_mut() {
        for m in &mut skeleton.inverse_bind {
            *m *= inverse;
        }
    }
    Some(placed)
}

/// The mesh, skeleton and weights of `character`, which must have the last two.
fn weighted<'a>(character: &'a Character, role: &str) -> Result<Weighted<'a>> {
    let path = character.path.display();
    let skeleton = character
        .skeleton
        .as_ref()
        .with_context(|| format!("{path}: the {role} has no skeleton"))?;
    let weights = character
        .reference_weights
        .as_ref()
        .with_context(|| format!("{path}: the {role} has no skinning weights"))?;
    Ok(Weighted {
        positions: &character.mesh.positions,
        skeleton,
        weights,
    })
}

/// The figures as a few aligned lines.
fn summary(e: &Evaluation) -> String {
    let deform = |name: &str, d: Option<&atlas_skin_eval::DeformError>| match d {
        Some(d) => format!(
            "{name:<22} mean {:.4}  max {:.4}  (× diagonal)\n",
            d.mean, d.max
        ),
        None => format!("{name:<22} (no animation)\n"),
    };
    let v = &e.validity;
    [
        format!(
            "vertices {} (matched {}), joints {}; candidate: {} vertices, {} joints\n",
            e.vertices, e.matched, e.joints, e.candidate_vertices, e.candidate_joints
        ),
        joint_matches(&e.joint_matches),
        format!(
            "{:<22} mean {:.3}  p95 {:.3}  max {:.3}  dominant joint agrees {:.1}%\n",
            "weights L1",
            e.weights_l1.mean,
            e.weights_l1.p95,
            e.weights_l1.max,
            100.0 * e.weights_l1.dominant_agreement
        ),
        e.rignet.map_or_else(String::new, |r| {
            format!(
                "{:<22} precision {:.3}  recall {:.3}  L1 {:.3}  (RigNet's, over {} vertices)\n",
                "influences", r.precision, r.recall, r.l1, r.vertices
            )
        }),
        deform("deform, random (LBS)", Some(&e.deform_random)),
        deform("deform, random (DQS)", Some(&e.deform_random_dqs)),
        deform("deform, animation", e.deform_anim.as_ref()),
        format!("{:<22} {:.4}\n", "bleeding", e.bleeding.fraction),
        format!(
            "{:<22} {} negative, {} sums off 1, {} unweighted, influences max {} mean {:.2}\n",
            "validity",
            v.negative_weights,
            v.sums_off_one,
            v.unweighted_vertices,
            v.max_influences,
            v.mean_influences
        ),
    ]
    .into_iter()
    .chain(e.worst_vertices.iter().map(worst_line))
    .collect()
}

/// How the candidate's joints were matched: counts, then every pair not matched by the
/// same name.
fn joint_matches(pairs: &[JointPair]) -> String {
    let count = |how| pairs.iter().filter(|p| p.how == how).count();
    let mut text = format!(
        "{:<22} {} by name, {} ignoring case and punctuation, {} by bind position\n",
        "joints matched",
        count(JointMatch::Name),
        count(JointMatch::NameIgnoringCase),
        count(JointMatch::Position)
    );
    for pair in pairs.iter().filter(|p| p.how != JointMatch::Name) {
        let how = match pair.how {
            JointMatch::NameIgnoringCase => "name ignoring case and punctuation",
            _ => "bind position",
        };
        text += &format!(
            "  candidate {:?} -> reference {:?} ({how})\n",
            pair.candidate, pair.reference
        );
    }
    text
}

/// One line of the worst-vertex list: each joint's weight, and after `@` how many times
/// farther its bones are than the nearest bone (×1: the nearest).
fn worst_line(w: &atlas_skin_eval::WorstVertex) -> String {
    let row = |r: &[atlas_skin_eval::JointWeight]| {
        r.iter()
            .map(|jw| {
                format!(
                    "{} {:.2} @×{:.1}",
                    jw.joint, jw.weight, jw.bone_distance_ratio
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let [x, y, z] = w.position;
    format!(
        "worst vertex {} at ({x:.3}, {y:.3}, {z:.3}): {:.4} in pose {}; reference [{}], candidate [{}]\n",
        w.vertex,
        w.error,
        w.pose,
        row(&w.reference),
        row(&w.candidate)
    )
}

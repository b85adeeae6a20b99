//! `atlas-skin pose`: deform a skinned character by one pose and write the posed mesh.
//!
//! A pose is a set of local transforms of the character's rig (its glTF nodes, or its
//! skeleton's joints): a glTF animation sampled at a time, a BVH frame retargeted by joint
//! names ([`atlas_skin_runtime::retarget`]), a JSON pose file (docs/formats.md, "Pose
//! files") or a seeded random pose. Rotations given per joint (pose files, random poses)
//! are applied on top of the joint's rest rotation: `local = T · R_rest · R · S`.

use crate::input::InputArgs;
use anyhow::{anyhow, bail, ensure, Context, Result};
use atlas_skin_io::{Character, OutputPlan};
use atlas_skin_runtime::pose::palette_from_world;
use atlas_skin_runtime::random_pose::random_rotations;
use atlas_skin_runtime::retarget::Retarget;
use atlas_skin_runtime::{
    Clip, CompactSkin, Rig, Skeleton, SkinningJob, SkinningMethod, SkinningPalette, Threading, Trs,
};
use glam::{Mat4, Quat, Vec3};
use serde_json::Value;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Influences per vertex kept for posing: what glTF viewers (and three.js) skin with.
pub const POSE_INFLUENCES: usize = 4;

/// Largest joint rotation of a `--random` pose: 60°, the evaluation's random pose
/// (BASELINES.md).
pub const RANDOM_POSE_MAX_DEGREES: f32 = 60.0;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    #[command(flatten)]
    pub source: PoseSource,
    /// Seconds into the animation, with --anim.
    #[arg(long, default_value_t = 0.0, requires = "anim", value_parser = crate::counts::finite)]
    pub time: f32,
    /// Frame of the BVH motion (0 = first), with --bvh.
    #[arg(long, default_value_t = 0, requires = "bvh")]
    pub frame: usize,
    /// JSON object pairing character joints (keys) with BVH joints (values) whose names
    /// differ, with --bvh; other joints are matched by name.
    #[arg(long, value_name = "MAP.json", requires = "bvh")]
    pub joint_map: Option<PathBuf>,
    /// Dual quaternion skinning instead of linear blend skinning.
    #[arg(long)]
    pub dqs: bool,
    /// Output: .obj (positions, normals, triangles) or .glb (a static mesh).
    #[arg(short = 'o', long)]
    pub output: PathBuf,
}

/// Where the pose comes from (exactly one).
#[derive(clap::Args, Debug, Clone)]
#[group(required = true, multiple = false)]
pub struct PoseSource {
    /// A glTF animation of the input, by name (or by index when unnamed).
    #[arg(long)]
    pub anim: Option<String>,
    /// A BVH motion, mapped onto the skeleton by joint names.
    #[arg(long)]
    pub bvh: Option<PathBuf>,
    /// A JSON pose file: joint name → rotation (docs/formats.md, "Pose files").
    #[arg(long)]
    pub pose: Option<PathBuf>,
    /// A random pose: every joint turned up to 60° about a random axis, from this seed.
    #[arg(long)]
    pub random: Option<u64>,
}

pub fn run(args: Args) -> Result<()> {
    let source = &args.source;
    let inputs = [&source.bvh, &source.pose, &args.joint_map]
        .into_iter()
        .filter_map(|p| p.as_deref());
    let plan = OutputPlan::new(args.input.paths().chain(inputs), [args.output.as_path()])?;
    let character = args.input.load_skinned()?;
    let posable = Posable::new(&character)?;
    let local = match (&args.source.anim, &args.source.bvh, &args.source.pose) {
        (Some(name), _, _) => posable.sample_clip(find_clip(&character.clips, name)?, args.time)?,
        (_, Some(bvh), _) => posable.bvh_frame(bvh, args.joint_map.as_deref(), args.frame)?,
        (_, _, Some(pose)) => posable.with_rotations(&read_pose_file(pose, &posable.rig)?),
        _ => {
            let seed = args.source.random.context("no pose source given")?;
            posable.random(seed)
        }
    };
    let method = if args.dqs {
        SkinningMethod::DualQuaternion
    } else {
        SkinningMethod::LinearBlend
    };
    let posed = posable.deform(&local, method)?;
    write_mesh(&posed, &character.mesh.triangles, &args.output, &plan)
}

/// A skinned character ready to pose: its rig, skeleton, compact skin and rest streams.
pub struct Posable {
    pub skeleton: Skeleton,
    pub rig: Rig,
    pub skin: CompactSkin,
    pub rest_positions: Vec<Vec3>,
    pub rest_normals: Vec<Vec3>,
}

/// Posed vertex streams.
pub struct PosedMesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
}

impl Posable {
    /// Needs a skeleton and weights (the input's own, or from `--weights`); the rig is the
    /// character's (glTF nodes) or the skeleton's joints in their bind pose.
    pub fn new(character: &Character) -> Result<Self> {
        let skeleton = character
            .skeleton
            .clone()
            .context("the character has no skeleton to pose")?;
        let weights = character.reference_weights.as_ref().context(
            "the character has no skin weights: skin it first (atlas-skin skin) or give --weights",
        )?;
        let rig = character
            .rig
            .clone()
            .unwrap_or_else(|| Rig::from_skeleton(&skeleton));
        rig.validate().context("invalid node hierarchy")?;
        ensure!(
            rig.joint_nodes.len() == skeleton.len(),
            "the rig drives {} joints, the skeleton has {}",
            rig.joint_nodes.len(),
            skeleton.len()
        );
        ensure!(
            weights.vertex_count() == character.mesh.positions.len(),
            "{} weight rows for {} vertices",
            weights.vertex_count(),
            character.mesh.positions.len()
        );
        let skin = CompactSkin::new(weights, skeleton.len(), POSE_INFLUENCES)
            .context("invalid skin weights")?;
        let rest_normals = vertex_normals(&character.mesh.positions, &character.mesh.triangles);
        Ok(Self {
            skeleton,
            rig,
            skin,
            rest_positions: character.mesh.positions.clone(),
            rest_normals,
        })
    }

    /// The rig's local transforms of `clip` at `time` seconds.
    pub fn sample_clip(&self, clip: &Clip, time: f32) -> Result<Vec<Trs>> {
        clip.validate(self.rig.len())
            .with_context(|| format!("invalid animation {:?}", clip.name))?;
        let mut local = self.rig.rest.clone();
        clip.sample(time, &self.rig.rest, &mut local);
        Ok(local)
    }

    /// Frame `frame` of the BVH motion at `path`, retargeted onto the rig (with the joint
    /// map at `joint_map`, if any).
    pub fn bvh_frame(
        &self,
        path: &Path,
        joint_map: Option<&Path>,
        frame: usize,
    ) -> Result<Vec<Trs>> {
        let motion = BvhMotion::read(path, joint_map)?;
        let time = motion.frame_time(frame)?;
        let mut retarget = motion
            .retarget(&self.rig)
            .with_context(|| format!("cannot put {} on the character", path.display()))?;
        let mut local = self.rig.rest.clone();
        retarget.apply(&motion.rig, &motion.sample(time), &self.rig, &mut local);
        Ok(local)
    }

    /// The rest pose with joint `j` turned by `rotations[j]` after its rest rotation.
    pub fn with_rotations(&self, rotations: &[Quat]) -> Vec<Trs> {
        let mut local = self.rig.rest.clone();
        for (&node, rotation) in self.rig.joint_nodes.iter().zip(rotations) {
            let trs = &mut local[node as usize];
            trs.rotation = (trs.rotation * *rotation).normalize();
        }
        local
    }

    /// A reproducible random pose ([`random_rotations`], up to
    /// [`RANDOM_POSE_MAX_DEGREES`]).
    pub fn random(&self, seed: u64) -> Vec<Trs> {
        let rotations = random_rotations(
            self.skeleton.len(),
            RANDOM_POSE_MAX_DEGREES.to_radians(),
            seed,
        );
        self.with_rotations(&rotations)
    }

    /// Skinning palette of a pose: `joint_world[j] · inverse_bind[j]`.
    pub fn palette(&self, local: &[Trs]) -> Vec<Mat4> {
        let mut node_world = vec![Mat4::IDENTITY; self.rig.len()];
        let mut joint_world = vec![Mat4::IDENTITY; self.skeleton.len()];
        let mut palette = vec![Mat4::IDENTITY; self.skeleton.len()];
        self.rig.world(local, &mut node_world);
        self.rig.joint_world(&node_world, &mut joint_world);
        palette_from_world(&joint_world, &self.skeleton.inverse_bind, &mut palette);
        palette
    }

    /// The mesh deformed by a pose; normals renormalised.
    pub fn deform(&self, local: &[Trs], method: SkinningMethod) -> Result<PosedMesh> {
        let mut palette = SkinningPalette::new(self.skeleton.len());
        palette
            .update(&self.palette(local), method)
            .context("cannot skin this pose")?;
        let count = self.rest_positions.len();
        let mut posed = PosedMesh {
            positions: vec![Vec3::ZERO; count],
            normals: vec![Vec3::ZERO; count],
        };
        SkinningJob {
            skin: &self.skin,
            palette: &palette,
            threading: Threading::Parallel,
            rest_positions: &self.rest_positions,
            rest_normals: Some(&self.rest_normals),
            rest_tangents: None,
            out_positions: &mut posed.positions,
            out_normals: Some(&mut posed.normals),
            out_tangents: None,
        }
        .run()?;
        for n in &mut posed.normals {
            *n = n.normalize_or_zero();
        }
        Ok(posed)
    }
}

/// A BVH motion: its rig (one node per joint) and its clip, and the joint map that pairs
/// a character's joints with its joints.
pub struct BvhMotion {
    pub rig: Rig,
    pub clip: Clip,
    /// (character joint, motion joint) pairs from `--joint-map`, matched before names, and
    /// the file they come from.
    pub joint_map: Vec<(String, String)>,
    pub joint_map_path: Option<PathBuf>,
}

impl BvhMotion {
    /// Reads the BVH at `path` and, when given, the joint map at `joint_map`: a JSON object
    /// whose keys are character joints and values motion joints (docs/formats.md).
    pub fn read(path: &Path, joint_map_path: Option<&Path>) -> Result<Self> {
        let (_, rig, clip) = atlas_skin_io::bvh::read_motion(path)
            .with_context(|| format!("cannot read motion {}", path.display()))?;
        clip.validate(rig.len())
            .with_context(|| format!("invalid motion in {}", path.display()))?;
        let joint_map = match joint_map_path {
            Some(map) => read_joint_map(map)?,
            None => Vec::new(),
        };
        Ok(Self {
            rig,
            clip,
            joint_map,
            joint_map_path: joint_map_path.map(Path::to_path_buf),
        })
    }

    /// The mapping of this motion onto `rig` ([`Retarget::with_map`]).
    pub fn retarget(&self, rig: &Rig) -> Result<Retarget> {
        Retarget::with_map(&self.rig, rig, &self.joint_map).with_context(|| {
            match &self.joint_map_path {
                Some(map) => format!(
                    "cannot map the motion onto the character with {}",
                    map.display()
                ),
                None => "cannot map the motion onto the character".to_string(),
            }
        })
    }

    /// Key times of the frames (every track of a BVH clip has one key per frame).
    pub fn frame_times(&self) -> &[f32] {
        self.clip.tracks.first().map_or(&[], |t| t.times.as_slice())
    }

    /// Time of frame `frame`, or an error naming the frame count.
    pub fn frame_time(&self, frame: usize) -> Result<f32> {
        let times = self.frame_times();
        times.get(frame).copied().ok_or_else(|| {
            anyhow!(
                "frame {frame} out of range: the motion has {} frames",
                times.len()
            )
        })
    }

    /// The rig's local transforms at `time`.
    pub fn sample(&self, time: f32) -> Vec<Trs> {
        let mut local = self.rig.rest.clone();
        self.clip.sample(time, &self.rig.rest, &mut local);
        local
    }
}

/// The clip named `name`, or for a number, the clip at that index (glTF animations may be
/// unnamed).
pub fn find_clip<'a>(clips: &'a [Clip], name: &str) -> Result<&'a Clip> {
    clips
        .iter()
        .find(|c| c.name == name)
        .or_else(|| name.parse::<usize>().ok().and_then(|i| clips.get(i)))
        .ok_or_else(|| {
            let names: Vec<String> = clips
                .iter()
                .enumerate()
                .map(|(i, c)| format!("{i}: {:?}", c.name))
                .collect();
            anyhow!(
                "no animation {name:?}; the input has [{}]",
                names.join(", ")
            )
        })
}

/// Reads a pose file (docs/formats.md, "Pose files"): one rotation per joint name, a
/// quaternion `[x, y, z, w]` or `{"euler_degrees": [x, y, z], "order": "XYZ"}` (order
/// optional, default XYZ: `R = Rx · Ry · Rz`, as three.js's `Euler`). Returns one rotation
/// per skeleton joint (identity for joints not listed).
pub fn read_pose_file(path: &Path, rig: &Rig) -> Result<Vec<Quat>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read pose file {}", path.display()))?;
    let json: Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not valid JSON", path.display()))?;
    parse_pose(&json, rig).with_context(|| format!("invalid pose file {}", path.display()))
}

fn parse_pose(json: &Value, rig: &Rig) -> Result<Vec<Quat>> {
    let object = json
        .as_object()
        .context("a pose file is a JSON object: joint name → rotation")?;
    let mut rotations = vec![Quat::IDENTITY; rig.joint_nodes.len()];
    for (name, value) in object {
        let joint = rig
            .joint_nodes
            .iter()
            .position(|&n| rig.names[n as usize] == *name)
            .ok_or_else(|| anyhow!("no joint named {name:?}"))?;
        rotations[joint] = parse_rotation(value).with_context(|| format!("joint {name:?}"))?;
    }
    Ok(rotations)
}

fn parse_rotation(value: &Value) -> Result<Quat> {
    let floats = |v: &Value, n: usize| -> Result<Vec<f32>> {
        let items = v.as_array().filter(|a| a.len() == n);
        let items = items.with_context(|| format!("expected an array of {n} numbers"))?;
        items
            .iter()
            .map(|x| {
                x.as_f64()
                    .map(|x| x as f32)
                    .filter(|x| x.is_finite())
                    .context("expected a finite number")
            })
            .collect()
    };
    match value {
        Value::Array(_) => {
            let q = floats(value, 4)?;
            let q = Quat::from_xyzw(q[0], q[1], q[2], q[3]);
            ensure!(q.length() > 1e-6, "zero quaternion");
            Ok(q.normalize())
        }
        Value::Object(map) => {
            let angles = floats(
                map.get("euler_degrees")
                    .context("expected \"euler_degrees\": [x, y, z]")?,
                3,
            )?;
            let order = match map.get("order").map(|o| o.as_str()) {
                None => "XYZ",
                Some(Some(order)) => order,
                Some(None) => bail!("\"order\" must be a string such as \"XYZ\""),
            };
            let [x, y, z] = [angles[0], angles[1], angles[2]].map(f32::to_radians);
            euler_rotation(order, Vec3::new(x, y, z))
        }
        _ => bail!("a rotation is [x, y, z, w] or {{\"euler_degrees\": [x, y, z]}}"),
    }
}

/// The rotation of `angles` (radians about x, y, z) composed in `order`, a permutation
/// of "XYZ" spelled as three.js's `Euler.order`: "XYZ" means `R = Rx · Ry · Rz`.
fn euler_rotation(order: &str, angles: Vec3) -> Result<Quat> {
    let mut letters: Vec<char> = order.chars().collect();
    letters.sort_unstable();
    ensure!(
        letters == ['X', 'Y', 'Z'],
        "unknown Euler order {order:?} (XYZ, XZY, YXZ, YZX, ZXY or ZYX)"
    );
    Ok(order.chars().fold(Quat::IDENTITY, |q, axis| {
        q * match axis {
            'X' => Quat::from_rotation_x(angles.x),
            'Y' => Quat::from_rotation_y(angles.y),
            _ => Quat::from_rotation_z(angles.z),
        }
    }))
}

/// Area-weighted vertex normals: `n_v ∝ Σ_f (b − a) × (c − a)` over the triangles f = (a,
/// b, c) around v (zero for an unused vertex).
pub fn vertex_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    normals.iter().map(|n| n.normalize_or_zero()).collect()
}

/// Writes the posed mesh through `plan` as OBJ (`v`, `vn`, `f a//a b//b c//c`, full float
/// precision) or as a static glb, by the extension of `out`.
pub fn write_mesh(
    posed: &PosedMesh,
    triangles: &[[u32; 3]],
    out: &Path,
    plan: &OutputPlan,
) -> Result<()> {
    let extension = out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let bytes = match extension.as_deref() {
        Some("obj") => obj_text(posed, triangles).into_bytes(),
        Some("glb") => {
            atlas_skin_io::gltf::debug_glb(&posed.positions, triangles, &[], &[], [0.0; 4], out)?
        }
        _ => bail!("{}: the output must end in .obj or .glb", out.display()),
    };
    plan.write(out, &bytes)
        .with_context(|| format!("cannot write {}", out.display()))
}

fn obj_text(posed: &PosedMesh, triangles: &[[u32; 3]]) -> String {
    let mut text = String::with_capacity(64 * posed.positions.len());
    text.push_str("# posed by atlas-skin\n");
    for p in &posed.positions {
        // Writing to a String cannot fail.
        let _ = writeln!(text, "v {} {} {}", p.x, p.y, p.z);
    }
    for n in &posed.normals {
        let _ = writeln!(text, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in triangles {
        let [a, b, c] = t.map(|i| i + 1);
        let _ = writeln!(text, "f {a}//{a} {b}//{b} {c}//{c}");
    }
    text
}

/// The pairs of the joint map at `path` (a JSON object of strings), in key order.
fn read_joint_map(path: &Path) -> Result<Vec<(String, String)>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read joint map {}", path.display()))?;
    let map: std::collections::BTreeMap<String, String> = serde_json::from_str(&text)
        .with_context(|| {
            format!(
                "{}: a joint map is a JSON object from character joint names to motion joint names",
                path.display()
            )
        })?;
    Ok(map.into_iter().collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn rig() -> Rig {
        Rig {
            names: vec!["root".into(), "arm".into()],
            parents: vec![atlas_skin_runtime::animation::NO_PARENT_NODE, 0],
            rest: vec![Trs::IDENTITY; 2],
            joint_nodes: vec![0, 1],
        }
    }

    #[test]
    fn pose_files_give_quaternions_and_euler_angles() {
        let pose = json!({
            "arm": {"euler_degrees": [0.0, 0.0, 90.0]},
            "root": [0.0, 0.0, 0.0, 2.0]
        });
        let rotations = parse_pose(&pose, &rig()).unwrap();
        assert_eq!(rotations[0], Quat::IDENTITY);
        assert!(rotations[1].abs_diff_eq(Quat::from_rotation_z(90f32.to_radians()), 1e-6));
        let xyz = json!({"arm": {"euler_degrees": [30.0, 40.0, 0.0], "order": "XYZ"}});
        let expected =
            Quat::from_rotation_x(30f32.to_radians()) * Quat::from_rotation_y(40f32.to_radians());
        assert!(parse_pose(&xyz, &rig()).unwrap()[1].abs_diff_eq(expected, 1e-6));
    }

    #[test]
    fn bad_pose_files_are_rejected() {
        let cases = [
            json!([1, 2]),
            json!({"leg": [0, 0, 0, 1]}),
            json!({"arm": [0, 0, 0, 0]}),
            json!({"arm": [0, 0, 1]}),
            json!({"arm": {"euler_degrees": [0, 0]}}),
            json!({"arm": {"euler_degrees": [0, 0, 0], "order": "XXY"}}),
            json!({"arm": "up"}),
        ];
        for case in cases {
            assert!(parse_pose(&case, &rig()).is_err(), "accepted {case}");
        }
    }
}

//! Reading a character from any supported input (dispatch on the file extension), with an
//! optional skeleton file and weights file.

use crate::text::check_file;
use crate::{
    bvh, dmat, fbx, gltf, medit, mhskel, mhw, obj, off, ply, rig_info, skeleton_json, stl, tgf,
    Character, Contents, IoError, LoadOptions, TriangleMesh,
};
use atlas_skin_runtime::{Rig, VertexWeights};
use glam::Vec3;
use std::path::Path;

const MESH_EXTENSIONS: &str = ".glb, .gltf, .vrm, .fbx, .obj, .mesh, .off, .ply or .stl";
const SKELETON_EXTENSIONS: &str = ".tgf, .bvh, .mhskel, .json or RigNet's _rig.txt";
const WEIGHTS_EXTENSIONS: &str = ".dmat or .mhw";

/// Reads the character at `path` with `options`.
///
/// - `.glb`, `.gltf`, `.vrm`: mesh, skeleton, weights and animations from the document.
/// - `.fbx`: skinned and rigid meshes, skeleton and weights, converted to glTF's units
///   and axes ([`fbx::read`]).
/// - `.obj`, `.mesh`, `.off`, `.ply`, `.stl`: a mesh; vertices no (kept) triangle uses are
///   dropped and [`Character::file_vertex`] maps the rest back to the file's numbering.
/// - `options.skeleton` (`.tgf`, `.bvh`, `.mhskel`, `.json`, RigNet's `_rig.txt`) gives a
///   mesh its skeleton; without one the character has none and a warning says so. A
///   rig_info file's `skin` lines also give the reference weights.
/// - `options.weights` (`.dmat`, `.mhw`) gives reference weights, one row per vertex of
///   the mesh file.
///
/// Errors: a missing file, a directory, an empty file, an unknown extension, an input
/// without triangles, a skeleton without joints, weights whose rows do not match the mesh
/// file, and every reader's own errors.
pub fn load_character(path: &Path, options: &LoadOptions) -> Result<Character, IoError> {
    load_character_with(path, options, Contents::Everything)
}

/// [`load_character`], decoding of a glTF or FBX input only `contents` besides its meshes,
/// skeleton and rig ([`gltf::read_contents`], [`fbx::read_contents`]); other formats are
/// read whole.
pub fn load_character_with(
    path: &Path,
    options: &LoadOptions,
    contents: Contents,
) -> Result<Character, IoError> {
    check_file(path)?;
    let extension = extension_of(path);
    if options.group.is_some() && extension != "obj" {
        return Err(IoError::invalid(path, "--group applies to OBJ files only"));
    }
    let file_mesh = match extension.as_str() {
        "glb" | "gltf" | "vrm" | "fbx" => None,
        "obj" => Some(obj::read(path, options.group.as_deref())?),
        "mesh" => Some(medit::read(path)?),
        "off" => Some(off::read(path)?),
        "ply" => Some(ply::read(path)?),
        "stl" => Some(stl::read(path)?),
        _ => return Err(unsupported(path, extension, MESH_EXTENSIONS)),
    };
    let (mut character, file_positions) = match file_mesh {
        Some(file_mesh) => (compacted_character(path, &file_mesh), file_mesh.positions),
        None => {
            let character = if extension == "fbx" {
                fbx::read_contents(path, contents)?
            } else {
                gltf::read_contents(path, contents)?
            };
            let positions = character.mesh.positions.clone();
            (character, positions)
        }
    };
    if character.mesh.triangles.is_empty() {
        return Err(IoError::invalid(path, "the mesh has no triangles"));
    }

    let mut bone_joints = None;
    if let Some(skeleton_path) = &options.skeleton {
        if character.skeleton.is_some() {
            return Err(IoError::invalid(
                path,
                format!(
                    "the input has its own skeleton; --skeleton {} is for meshes without one",
                    skeleton_path.display()
                ),
            ));
        }
        bone_joints = attach_skeleton(&mut character, skeleton_path, &file_positions)?;
    } else if character.skeleton.is_none() {
        character.warnings.push(format!(
            "no skeleton: give one with --skeleton ({SKELETON_EXTENSIONS})"
        ));
    }
    if let Some(weights_path) = &options.weights {
        attach_weights(
            &mut character,
            weights_path,
            file_positions.len(),
            bone_joints.as_deref(),
        )?;
    }
    Ok(character)
}

fn extension_of(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

fn unsupported(path: &Path, extension: String, expected: &'static str) -> IoError {
    IoError::UnsupportedFormat {
        path: path.to_path_buf(),
        extension,
        expected,
    }
}

/// A character over the vertices the triangles of `file_mesh` use.
fn compacted_character(path: &Path, file_mesh: &TriangleMesh) -> Character {
    let (mesh, file_vertex) = file_mesh.without_unused_vertices();
    let dropped = file_mesh.positions.len() - mesh.positions.len();
    let mut character = Character::new(path, mesh);
    character.file_vertex = file_vertex;
    if dropped > 0 {
        character.warnings.push(format!(
            "{dropped} of the file's {} vertices are used by no kept triangle and were dropped",
            file_mesh.positions.len()
        ));
    }
    character
}

/// Reads the skeleton file into `character` (with its rig, and its clip for BVH). Returns,
/// for a TGF skeleton, the joint each bone edge a → b belongs to (a), which libigl's
/// per-bone weight columns need.
fn attach_skeleton(
    character: &mut Character,
    path: &Path,
    file_positions: &[Vec3],
) -> Result<Option<Vec<u32>>, IoError> {
    check_file(path)?;
    let mut bone_joints = None;
    let skeleton = match extension_of(path).as_str() {
        "tgf" => {
            let tgf = tgf::read(path)?;
            bone_joints = Some(tgf.bones.iter().map(|&[a, _]| a).collect());
            character.end_joints = (0..tgf.skeleton.len() as u32)
                .filter(|&j| !tgf.bones.iter().any(|&[a, _]| a == j))
                .collect();
            tgf.skeleton
        }
        "bvh" => {
            let (skeleton, rig, clip) = bvh::read_motion(path)?;
            character.rig = Some(rig);
            character.clips.push(clip);
            skeleton
        }
        "mhskel" => mhskel::read(path, file_positions)?,
        "json" => skeleton_json::read(path)?,
        "txt" => {
            let rig = rig_info::read(path, file_positions.len())?;
            if let Some(weights) = &rig.weights {
                let kept = kept_rows(character, weights, path, rig.skeleton.len())?;
                let missing: Vec<usize> = (0..kept.vertex_count())
                    .filter(|&v| kept.row(v).next().is_none())
                    .collect();
                match missing.first() {
                    Some(&first) => character.warnings.push(format!(
                        "{}: {} vertices of the mesh have no skin line (the first: vertex {}): \
                         the file's weights are not used (truncated file, or another mesh?)",
                        path.display(),
                        missing.len(),
                        character.file_vertex[first]
                    )),
                    None => character.reference_weights = Some(kept),
                }
            }
            rig.skeleton
        }
        other => return Err(unsupported(path, other.to_string(), SKELETON_EXTENSIONS)),
    };
    if skeleton.is_empty() {
        return Err(IoError::invalid(path, "the skeleton has no joint"));
    }
    if character.rig.is_none() {
        character.rig = Some(Rig::from_skeleton(&skeleton));
    }
    character.skeleton = Some(skeleton);
    Ok(bone_joints)
}

/// The rows of `file_weights` (one per vertex of the mesh file) of the character's kept
/// vertices, checked against `joint_count` joints.
fn kept_rows(
    character: &Character,
    file_weights: &VertexWeights,
    path: &Path,
    joint_count: usize,
) -> Result<VertexWeights, IoError> {
    let weights = VertexWeights::from_rows(
        character
            .file_vertex
            .iter()
            .map(|&v| file_weights.row(v as usize).collect::<Vec<_>>()),
    );
    weights
        .validate(joint_count)
        .map_err(|error| IoError::invalid(path, error.to_string()))?;
    Ok(weights)
}

/// Reads the weights file into `character.reference_weights`: one row per vertex of the
/// mesh file (`file_vertex_count`), then the rows of the kept vertices.
///
/// DMAT columns go to joints one to one, or for a TGF skeleton one per bone edge a → b
/// to joint a (columns of bones leaving the same joint are summed).
fn attach_weights(
    character: &mut Character,
    path: &Path,
    file_vertex_count: usize,
    bone_joints: Option<&[u32]>,
) -> Result<(), IoError> {
    check_file(path)?;
    let skeleton = character.skeleton.as_ref().ok_or_else(|| {
        IoError::invalid(path, "weights need a skeleton: give one with --skeleton")
    })?;
    let file_weights = match extension_of(path).as_str() {
        "dmat" => {
            let matrix = dmat::read(path)?;
            if matrix.rows != file_vertex_count {
                return Err(IoError::invalid(
                    path,
                    format!(
                        "{} rows, but the mesh file has {file_vertex_count} vertices",
                        matrix.rows
                    ),
                ));
            }
            let identity: Vec<u32> = (0..skeleton.len() as u32).collect();
            let column_joint = match bone_joints {
                Some(bones) if bones.len() == matrix.cols => bones,
                _ if matrix.cols == skeleton.len() => &identity,
                _ => {
                    let bones = bone_joints
                        .map(|b| format!(" or {} (one per TGF bone)", b.len()))
                        .unwrap_or_default();
                    return Err(IoError::invalid(
                        path,
                        format!(
                            "{} columns, expected {} (one per joint){bones}",
                            matrix.cols,
                            skeleton.len()
                        ),
                    ));
                }
            };
            matrix.to_weights(path, column_joint)?
        }
        "mhw" => mhw::read(path, skeleton, file_vertex_count)?,
        other => return Err(unsupported(path, other.to_string(), WEIGHTS_EXTENSIONS)),
    };
    let weights = kept_rows(character, &file_weights, path, skeleton.len())?;
    if character.reference_weights.is_some() {
        character.warnings.push(format!(
            "the input's own weights were replaced by {}",
            path.display()
        ));
    }
    character.reference_weights = Some(weights);
    Ok(())
}

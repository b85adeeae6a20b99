//! Reading a glTF document into a [`Character`]: the skinned meshes' triangles, the skin's
//! joints with their bind pose, the stored weights, the node rig and the animations.

use super::accessor::{read_floats, read_uints};
use super::animation::{read_clips, read_rig};
use super::bindings::{
    inverse_binds, mesh_instances, node_positions, skin_joints, Binding, MeshInstance,
};
use super::budget::DecodeBudget;
use super::container::read_container;
use super::document::{Document, Location};
use super::nodes::{unique_node_names, NodeTree};
use super::{GltfSource, PrimitiveSource};
use crate::{Character, Contents, IoError, TriangleMesh};
use atlas_skin_runtime::{Skeleton, VertexWeights, NO_PARENT};
use glam::{Mat4, Vec3};
use serde_json::Value;
use std::collections::HashMap;
use std::path::Path;

/// Reads a `.glb`, `.gltf` (embedded or external buffers) or `.vrm` file.
///
/// - Skin: the first skin used by a node that also has a mesh. The meshes of every skin
///   over the same joints, then the rigid meshes under a joint node (see
///   `mesh_instances`): their triangle primitives (TRIANGLES, or strips and fans
///   converted) are concatenated, positions in the first skin's bind space (stored
///   positions for its own meshes; node transforms of skinned meshes are not applied).
///   Without a skin, every mesh node's triangles are read with the node's world transform
///   applied, and the character has no skeleton.
/// - Primitives sharing a POSITION accessor share their vertices in `Character::mesh`.
/// - Skeleton: the skin's joints in skin order, each joint's parent the nearest ancestor
///   node that is a joint; names from the nodes (`node<index>` when missing, made unique);
///   bind pose from `inverseBindMatrices` (identity when absent).
/// - Reference weights: JOINTS_n/WEIGHTS_n as stored (not renormalised, zeros dropped),
///   weight 1 on their joint for rigid meshes.
///
/// # Errors
/// [`IoError`] naming the file and the problem for anything malformed: containers,
/// JSON, out-of-range accessors or indices, non-finite positions, node cycles.
pub fn read(path: &Path) -> Result<Character, IoError> {
    read_contents(path, Contents::Everything)
}

/// [`read`], decoding only `contents` besides the meshes, the skeleton, the rig and the
/// animations: with [`Contents::ForSkinning`] the character has no reference weights (the
/// stored weights are neither decoded nor checked).
pub fn read_contents(path: &Path, contents: Contents) -> Result<Character, IoError> {
    let everything = contents == Contents::Everything;
    let mut container = read_container(path)?;
    let budget = DecodeBudget::for_input(container.input_bytes);
    let doc = Document {
        json: &container.json,
        buffers: &container.buffers,
        path,
        budget: &budget,
    };
    reject_compressed_geometry(&doc)?;
    let tree = NodeTree::new(&doc)?;
    let skin = find_skin(&doc)?;
    let mut warnings = std::mem::take(&mut container.warnings);
    let (joints, binds, cleaned) = match skin {
        Some(skin) => {
            let joints = skin_joints(&doc, skin)?;
            let mut binds = inverse_binds(&doc, skin, joints.len())?;
            let cleaned: Vec<usize> = binds
                .iter_mut()
                .enumerate()
                .filter_map(|(joint, matrix)| {
                    let affine = affine_inverse_bind(*matrix)?;
                    *matrix = affine;
                    Some(joint)
                })
                .collect();
            if let Some(&first) = cleaned.first() {
                warnings.push(format!(
                    "skins[{skin}].inverseBindMatrices: {} matrices (first: joint {first}) are \
                     projective (last row not (0, 0, 0, 1)); made affine, and written so",
                    cleaned.len()
                ));
            }
            (joints, binds, cleaned)
        }
        None => (Vec::new(), Vec::new(), Vec::new()),
    };
    let names = unique_node_names(&doc, &joints)?;
    let instances = mesh_instances(&doc, &tree, skin.map(|s| (s, &joints[..], &binds[..])))?;
    warnings.extend(instances.warnings);
    let geometry = read_geometry(&doc, &instances.list, &mut warnings)?;
    if geometry.mesh.triangles.is_empty() {
        return Err(doc.error(if skin.is_some() {
            "the skinned meshes have no triangle primitive"
        } else {
            "the document has no mesh node with triangles"
        }));
    }
    let mut inverse_binds_cleaned = false;
    let (skeleton, reference_weights) = match skin {
        Some(_) => {
            let joint_names = joints.iter().map(|&n| names[n].clone()).collect();
            let skeleton = read_skeleton(&doc, &tree, &joints, binds, joint_names)?;
            let weights = match everything {
                true => read_reference_weights(&doc, &geometry.blocks, &joints)?,
                false => None,
            };
            inverse_binds_cleaned = !cleaned.is_empty();
            (Some(skeleton), weights)
        }
        None => (None, None),
    };
    let rig = read_rig(&tree, names, &joints);
    let clips = read_clips(&doc, &mut warnings)?;
    let mut character = Character::new(path, geometry.mesh);
    character.skeleton = skeleton;
    character.reference_weights = reference_weights;
    character.rig = Some(rig);
    character.clips = clips;
    character.warnings = warnings;
    character.gltf = Some(GltfSource {
        inverse_binds_cleaned,
        skin,
        primitives: geometry.primitives,
        document: container.json,
        buffers: container.buffers,
        images: container.images,
    });
    Ok(character)
}

/// Required extensions that store geometry this reader cannot decode (their accessors have
/// no plain data).
const COMPRESSED_GEOMETRY: [&str; 2] = ["KHR_draco_mesh_compression", "EXT_meshopt_compression"];

fn reject_compressed_geometry(doc: &Document) -> Result<(), IoError> {
    for extension in doc.array("extensionsRequired")? {
        if let Some(name) = extension
            .as_str()
            .filter(|n| COMPRESSED_GEOMETRY.contains(n))
        {
            return Err(doc.error(format!(
                "compressed geometry ({name}) is not supported; decompress the file first"
            )));
        }
    }
    Ok(())
}

/// The first skin (in node order) of a node that also has a mesh.
fn find_skin(doc: &Document) -> Result<Option<usize>, IoError> {
    let skin_count = doc.array("skins")?.len();
    for (index, node) in doc.array("nodes")?.iter().enumerate() {
        let location = Location::item("nodes", index);
        let has_mesh = doc.opt_index(node, &location, "mesh")?.is_some();
        if let (true, Some(skin)) = (has_mesh, doc.opt_index(node, &location, "skin")?) {
            if skin >= skin_count {
                return Err(doc.error(format!(
                    "{location}.skin is {skin} but the document has {skin_count} skins"
                )));
            }
            return Ok(Some(skin));
        }
    }
    Ok(None)
}

/// Vertices of one POSITION accessor (per node when a world transform was applied), shared
/// by the primitives that use it.
///
/// - `attributes`: the `attributes` object of the first primitive using them (where the
///   stored weights are read).
/// - `binding`: how they follow the skeleton.
/// - `first`, `count`: their range in the concatenated mesh.
struct VertexBlock<'a> {
    attributes: &'a Value,
    binding: Binding,
    location: String,
    first: usize,
    count: usize,
}

struct Geometry<'a> {
    mesh: TriangleMesh,
    blocks: Vec<VertexBlock<'a>>,
    primitives: Vec<PrimitiveSource>,
}

/// glTF primitive modes this reader turns into triangles.
const TRIANGLES: usize = 4;
const TRIANGLE_STRIP: usize = 5;
const TRIANGLE_FAN: usize = 6;

fn read_geometry<'a>(
    doc: &Document<'a>,
    instances: &[MeshInstance],
    warnings: &mut Vec<String>,
) -> Result<Geometry<'a>, IoError> {
    let mut mesh = TriangleMesh::default();
    let mut blocks: Vec<VertexBlock> = Vec::new();
    let mut block_of: HashMap<(usize, Option<usize>), usize> = HashMap::new();
    let mut primitives = Vec::new();
    for instance in instances {
        let mesh_location = format!("meshes[{}]", instance.mesh);
        let object = doc.item("meshes", instance.mesh)?;
        let Some(Value::Array(list)) = object.get("primitives") else {
            return Err(doc.error(format!("{mesh_location} has no primitives array")));
        };
        for (index, primitive) in list.iter().enumerate() {
            let location = format!("{mesh_location}.primitives[{index}]");
            let mode = doc
                .opt_index(primitive, &location, "mode")?
                .unwrap_or(TRIANGLES);
            if !matches!(mode, TRIANGLES | TRIANGLE_STRIP | TRIANGLE_FAN) {
                warnings.push(format!(
                    "{location} has mode {mode} (points or lines): skipped"
                ));
                continue;
            }
            let attributes = primitive
                .get("attributes")
                .filter(|a| a.is_object())
                .ok_or_else(|| doc.error(format!("{location} has no attributes object")))?;
            let position = doc.index(attributes, &format!("{location}.attributes"), "POSITION")?;
            let key = (position, instance.to_bind.map(|_| instance.node));
            let block = match block_of.get(&key) {
                Some(&block) => block,
                None => {
                    let first = mesh.positions.len();
                    let positions = read_positions(doc, position, &location, instance.to_bind)?;
                    blocks.push(VertexBlock {
                        attributes,
                        binding: instance.binding,
                        location: location.clone(),
                        first,
                        count: positions.len(),
                    });
                    mesh.positions.extend(positions);
                    block_of.insert(key, blocks.len() - 1);
                    blocks.len() - 1
                }
            };
            let (first, vertex_count) = (blocks[block].first, blocks[block].count);
            let indices = match doc.opt_index(primitive, &location, "indices")? {
                Some(accessor) => {
                    read_uints(doc, accessor, "SCALAR", &format!("{location}.indices"))?
                }
                None => {
                    doc.charge(4 * vertex_count as u64, &location)?;
                    (0..vertex_count as u32).collect()
                }
            };
            if let Some(bad) = indices.iter().find(|&&i| i as usize >= vertex_count) {
                return Err(doc.error(format!(
                    "{location}: index {bad} is out of range of its {vertex_count} vertices"
                )));
            }
            // A strip or fan makes 3 indices (12 bytes) of each index.
            doc.charge(12 * indices.len() as u64, &location)?;
            let first_triangle = mesh.triangles.len();
            let offset = first as u32;
            mesh.triangles.extend(
                triangles_of(mode, &indices, &location, doc)?
                    .into_iter()
                    .map(|t| t.map(|v| v + offset)),
            );
            primitives.push(PrimitiveSource {
                node: instance.node,
                mesh: instance.mesh,
                binding: instance.binding,
                primitive: index,
                position_accessor: position,
                vertices: first..first + vertex_count,
                triangles: first_triangle..mesh.triangles.len(),
            });
        }
    }
    Ok(Geometry {
        mesh,
        blocks,
        primitives,
    })
}

/// Positions of accessor `position` (VEC3), transformed by `world` (the instance's
/// transform to the bind space or to the world) when given; every
/// coordinate must be finite, as stored and after the transform. Errors show the stored
/// values (a transform would spread one NaN over all three coordinates).
fn read_positions(
    doc: &Document,
    position: usize,
    location: &str,
    world: Option<Mat4>,
) -> Result<Vec<Vec3>, IoError> {
    let values = read_floats(doc, position, "VEC3", &format!("{location} POSITION"))?;
    let stored: Vec<Vec3> = values.chunks_exact(3).map(Vec3::from_slice).collect();
    let accessor = format!("{location}: POSITION (accessors[{position}])");
    if let Some(bad) = stored.iter().position(|p| !p.is_finite()) {
        return Err(doc.error(format!(
            "{accessor} vertex {bad} is not finite: {}",
            stored[bad]
        )));
    }
    let Some(world) = world else {
        return Ok(stored);
    };
    let positions: Vec<Vec3> = stored.iter().map(|&p| world.transform_point3(p)).collect();
    match positions.iter().position(|p| !p.is_finite()) {
        Some(bad) => Err(doc.error(format!(
            "{accessor} vertex {bad} {} is not finite after its node's world transform: {}",
            stored[bad], positions[bad]
        ))),
        None => Ok(positions),
    }
}

/// Triangles of a primitive of `mode` with vertex `indices`: TRIANGLES as stored; strips
/// and fans converted (glTF 2.0 §3.7.2.1), skipping the degenerate triangles strips use as
/// restarts.
fn triangles_of(
    mode: usize,
    indices: &[u32],
    location: &str,
    doc: &Document,
) -> Result<Vec<[u32; 3]>, IoError> {
    if mode == TRIANGLES {
        if !indices.len().is_multiple_of(3) {
            return Err(doc.error(format!(
                "{location}: {} indices is not a multiple of 3",
                indices.len()
            )));
        }
        return Ok(indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect());
    }
    let triangles = (0..indices.len().saturating_sub(2)).map(|i| match mode {
        TRIANGLE_STRIP if i % 2 == 0 => [indices[i], indices[i + 1], indices[i + 2]],
        TRIANGLE_STRIP => [indices[i + 1], indices[i], indices[i + 2]],
        _ => [indices[0], indices[i + 1], indices[i + 2]],
    });
    Ok(triangles
        .filter(|[a, b, c]| a != b && b != c && a != c)
        .collect())
}

/// An inverse bind matrix made affine (glTF 2.0 asks for a last row of (0, 0, 0, 1)): a
/// last row (0, 0, 0, w) with w ≠ 0 divides the matrix by w (the same transform in
/// homogeneous coordinates); any other last row is replaced by (0, 0, 0, 1). `None` when
/// the matrix is affine already.
fn affine_inverse_bind(m: Mat4) -> Option<Mat4> {
    let last_row = m.row(3);
    if last_row == glam::Vec4::W {
        return None;
    }
    let scaled = if last_row.truncate() == Vec3::ZERO && last_row.w != 0.0 {
        m * (1.0 / last_row.w)
    } else {
        m
    };
    let mut columns = scaled.to_cols_array_2d();
    for column in &mut columns[..3] {
        column[3] = 0.0;
    }
    columns[3][3] = 1.0;
    Some(Mat4::from_cols_array_2d(&columns))
}

/// The skeleton over the skin's `joints` (node indices) with their inverse bind matrices.
fn read_skeleton(
    doc: &Document,
    tree: &NodeTree,
    joints: &[usize],
    inverse_bind: Vec<Mat4>,
    names: Vec<String>,
) -> Result<Skeleton, IoError> {
    let joint_of: HashMap<usize, u32> = joints
        .iter()
        .enumerate()
        .map(|(j, &node)| (node, j as u32))
        .collect();
    let parents = joints
        .iter()
        .map(|&node| {
            let mut current = tree.parents[node];
            while let Some(ancestor) = current {
                if let Some(&joint) = joint_of.get(&ancestor) {
                    return joint;
                }
                current = tree.parents[ancestor];
            }
            NO_PARENT
        })
        .collect();
    let skeleton =
        Skeleton::new(names, parents, inverse_bind).map_err(|cause| IoError::Skeleton {
            path: doc.path.to_path_buf(),
            cause,
        })?;
    Ok(skeleton)
}

/// The stored JOINTS_n/WEIGHTS_n of every vertex block, as stored (zeros dropped), joint
/// indices mapped from the block's skin to the skeleton (`skeleton_nodes`: the skeleton's
/// joint nodes); `None` when no block has JOINTS_0. Blocks without weights get empty rows;
/// rigid blocks weight 1 on their joint.
fn read_reference_weights(
    doc: &Document,
    blocks: &[VertexBlock],
    skeleton_nodes: &[usize],
) -> Result<Option<VertexWeights>, IoError> {
    // Built row by row in place (no list per vertex).
    let mut weights = VertexWeights {
        offsets: vec![0],
        ..VertexWeights::default()
    };
    let mut any = false;
    let end_row = |weights: &mut VertexWeights| weights.offsets.push(weights.joints.len() as u32);
    for block in blocks {
        let skin = match block.binding {
            Binding::Skin(skin) => skin,
            Binding::Rigid(joint) => {
                for _ in 0..block.count {
                    weights.joints.push(joint);
                    weights.weights.push(1.0);
                    end_row(&mut weights);
                }
                continue;
            }
            Binding::Unskinned => {
                for _ in 0..block.count {
                    end_row(&mut weights);
                }
                continue;
            }
        };
        let skeleton_index = node_positions(skeleton_nodes);
        let skeleton_joint: Vec<u32> = skin_joints(doc, skin)?
            .iter()
            .map(|node| skeleton_index.get(node).copied().unwrap_or(0))
            .collect();
        let joint_count = skeleton_joint.len();
        // Every set read and checked first, in set order (so the first error is the one a
        // set-by-set reading meets), then each vertex's entries of all sets in set order.
        let mut sets: Vec<(Vec<u32>, Vec<f32>)> = Vec::new();
        for set in 0.. {
            let location = format!("{}.attributes", block.location);
            let joints = doc.opt_index(block.attributes, &location, &format!("JOINTS_{set}"))?;
            let weights = doc.opt_index(block.attributes, &location, &format!("WEIGHTS_{set}"))?;
            let (Some(joints), Some(weights)) = (joints, weights) else {
                break;
            };
            any = true;
            let joints_values =
                read_uints(doc, joints, "VEC4", &format!("{location}.JOINTS_{set}"))?;
            let weight_values =
                read_floats(doc, weights, "VEC4", &format!("{location}.WEIGHTS_{set}"))?;
            for (name, values) in [
                ("JOINTS", joints_values.len()),
                ("WEIGHTS", weight_values.len()),
            ] {
                if values != 4 * block.count {
                    return Err(doc.error(format!(
                        "{location}: {name}_{set} has {} elements for {} vertices",
                        values / 4,
                        block.count
                    )));
                }
            }
            for (k, (&joint, &weight)) in joints_values.iter().zip(&weight_values).enumerate() {
                let v = k / 4;
                if !weight.is_finite() || weight < 0.0 {
                    return Err(doc.error(format!(
                        "{location}: WEIGHTS_{set} of vertex {v} has weight {weight}"
                    )));
                }
                if weight != 0.0 && joint as usize >= joint_count {
                    return Err(doc.error(format!(
                        "{location}: JOINTS_{set} of vertex {v} is joint {joint}, but the skin \
                         has {joint_count} joints"
                    )));
                }
            }
            sets.push((joints_values, weight_values));
        }
        for v in 0..block.count {
            for (joints_values, weight_values) in &sets {
                for k in 4 * v..4 * v + 4 {
                    let (joint, weight) = (joints_values[k], weight_values[k]);
                    if weight != 0.0 {
                        weights.joints.push(skeleton_joint[joint as usize]);
                        weights.weights.push(weight);
                    }
                }
            }
            end_row(&mut weights);
        }
    }
    Ok(any.then_some(weights))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projective_inverse_binds_become_affine() {
        let affine = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(affine_inverse_bind(affine), None);
        // The same transform with homogeneous weight 2.
        let doubled = affine * 2.0;
        assert_eq!(affine_inverse_bind(doubled), Some(affine));
        let mut projective = affine.to_cols_array_2d();
        projective[0][3] = 0.5;
        assert_eq!(
            affine_inverse_bind(Mat4::from_cols_array_2d(&projective)),
            Some(affine)
        );
    }
}

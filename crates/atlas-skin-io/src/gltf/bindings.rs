//! Which meshes of a glTF document belong to the character, and how each follows the
//! skeleton: the meshes of every skin over the skeleton's joints (several skins often share
//! one skeleton, each with its own inverse bind matrices), and rigid meshes parented to a
//! joint node.

use super::accessor::read_floats;
use super::document::{opt_str, Document, Location};
use super::nodes::NodeTree;
use crate::IoError;
use glam::Mat4;
use std::collections::{BTreeSet, HashMap};

/// How the vertices of a mesh read into the character follow the skeleton.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Binding {
    /// Skinned by `skins[skin]` (its joints are the skeleton's, maybe in another order).
    Skin(usize),
    /// A mesh without skin on a node under joint `joint` (a skeleton index): it moves
    /// rigidly with that joint.
    Rigid(u32),
    /// A mesh of a document without skin (no skeleton).
    Unskinned,
}

/// One use of a mesh by a node.
///
/// - `to_bind`: applied to the stored positions to bring them into the skeleton's bind space
///   (`None`: stored positions are already there).
pub(crate) struct MeshInstance {
    pub node: usize,
    pub mesh: usize,
    pub to_bind: Option<Mat4>,
    pub binding: Binding,
}

/// The meshes the character is made of, and warnings about meshes left out.
pub(crate) struct Instances {
    pub list: Vec<MeshInstance>,
    pub warnings: Vec<String>,
}

/// The inverse bind matrices of `skins[skin]` (identity when absent), one per joint.
pub(crate) fn inverse_binds(
    doc: &Document,
    skin: usize,
    joint_count: usize,
) -> Result<Vec<Mat4>, IoError> {
    let location = format!("skins[{skin}]");
    let object = doc.item("skins", skin)?;
    let Some(accessor) = doc.opt_index(object, &location, "inverseBindMatrices")? else {
        return Ok(vec![Mat4::IDENTITY; joint_count]);
    };
    let role = format!("{location}.inverseBindMatrices");
    let values = read_floats(doc, accessor, "MAT4", &role)?;
    if values.len() / 16 != joint_count {
        return Err(doc.error(format!(
            "{location}.inverseBindMatrices has {} matrices for {joint_count} joints",
            values.len() / 16
        )));
    }
    Ok(values.chunks_exact(16).map(Mat4::from_cols_slice).collect())
}

/// The joint node indices of `skin`: non-empty, in range, no node twice.
pub(crate) fn skin_joints(doc: &Document, skin: usize) -> Result<Vec<usize>, IoError> {
    let location = format!("skins[{skin}]");
    let joints = doc.indices(doc.item("skins", skin)?, &location, "joints")?;
    let node_count = doc.array("nodes")?.len();
    if joints.is_empty() {
        return Err(doc.error(format!("{location} has no joints")));
    }
    let mut seen = vec![false; node_count];
    for &node in &joints {
        if node >= node_count {
            return Err(doc.error(format!(
                "{location}.joints has node {node}, but the document has {node_count} nodes"
            )));
        }
        if std::mem::replace(&mut seen[node], true) {
            return Err(doc.error(format!("{location}.joints lists node {node} twice")));
        }
    }
    Ok(joints)
}

/// The meshes of the character.
///
/// - With a skin (`joints`: its joint nodes, `binds`: its inverse bind matrices): each mesh
///   used by a node whose skin has the same joints (as a set), once, in mesh order, its
///   positions brought into `skin`'s bind space by `IBM_skin[j]⁻¹ · IBM_other[j]` (glTF
///   2.0 §3.7.3: a skinned vertex v is at `world(j) · IBM[j] · v` in the bind pose, so a
///   vertex v of the other skin is where the vertex `IBM_skin[j]⁻¹ · IBM_other[j] · v` of
///   the first is; computed with the first joint). Then, in node order, each mesh node without
///   skin under a joint node J (its nearest joint ancestor), its positions taken to the
///   bind space by `IBM[J]⁻¹ · world(J)⁻¹ · world(node)` (where it sits relative to J in the
///   document's pose). Skinned meshes of skins over other joints are left out with a
///   warning, as are mesh nodes under no joint.
/// - Without a skin: every mesh node with its world transform.
pub(crate) fn mesh_instances(
    doc: &Document,
    tree: &NodeTree,
    skin: Option<(usize, &[usize], &[Mat4])>,
) -> Result<Instances, IoError> {
    let mesh_count = doc.array("meshes")?.len();
    let skin_count = doc.array("skins")?.len();
    let mut skinned: Vec<MeshInstance> = Vec::new();
    let mut rigid: Vec<MeshInstance> = Vec::new();
    let mut other_skins = BTreeSet::new();
    let mut loose = Vec::new();
    let mut to_bind_of_skin: HashMap<usize, Option<Mat4>> = HashMap::new();
    // Every node's world transform, computed once (linear in the node count).
    let worlds = tree.worlds();
    let joint_of = skin
        .map(|(_, joints, _)| node_positions(joints))
        .unwrap_or_default();
    for (node, object) in doc.array("nodes")?.iter().enumerate() {
        let location = Location::item("nodes", node);
        let Some(mesh) = doc.opt_index(object, &location, "mesh")? else {
            continue;
        };
        if mesh >= mesh_count {
            return Err(doc.error(format!(
                "{location}.mesh is {mesh} but the document has {mesh_count} meshes"
            )));
        }
        let Some((primary, joints, binds)) = skin else {
            skinned.push(MeshInstance {
                node,
                mesh,
                to_bind: Some(worlds[node]),
                binding: Binding::Unskinned,
            });
            continue;
        };
        match doc.opt_index(object, &location, "skin")? {
            Some(other) if other >= skin_count => {
                return Err(doc.error(format!(
                    "{location}.skin is {other} but the document has {skin_count} skins"
                )))
            }
            Some(other) => {
                let to_bind = match to_bind_of_skin.get(&other) {
                    Some(&to_bind) => to_bind,
                    None => {
                        let to_bind = shared_bind(doc, primary, joints, binds, other)?;
                        *to_bind_of_skin.entry(other).or_insert(to_bind)
                    }
                };
                match to_bind {
                    Some(to_bind) if !skinned.iter().any(|i| i.mesh == mesh) => {
                        skinned.push(MeshInstance {
                            node,
                            mesh,
                            to_bind: (other != primary).then_some(to_bind),
                            binding: Binding::Skin(other),
                        })
                    }
                    Some(_) => {}
                    None => {
                        other_skins.insert(other);
                    }
                }
            }
            None => match joint_ancestor(tree, &joint_of, node) {
                Some((joint, joint_node)) => rigid.push(MeshInstance {
                    node,
                    mesh,
                    to_bind: Some(
                        binds[joint as usize].inverse()
                            * worlds[joint_node].inverse()
                            * worlds[node],
                    ),
                    binding: Binding::Rigid(joint),
                }),
                None => loose.push(node_label(doc, node)?),
            },
        }
    }
    let mut warnings = Vec::new();
    if !other_skins.is_empty() {
        warnings.push(format!(
            "the meshes of {} are not read: their joints are not those of the skeleton read \
             (skins[{}])",
            other_skins
                .iter()
                .map(|s| format!("skins[{s}]"))
                .collect::<Vec<_>>()
                .join(", "),
            skin.map_or(0, |s| s.0)
        ));
    }
    if !loose.is_empty() {
        warnings.push(format!(
            "{} mesh node(s) without skin and under no joint are not read: {}",
            loose.len(),
            loose.join(", ")
        ));
    }
    // Document order of the skinned meshes, not of the nodes using them.
    skinned.sort_by_key(|i| i.mesh);
    skinned.extend(rigid);
    Ok(Instances {
        list: skinned,
        warnings,
    })
}

/// `IBM_primary[j]⁻¹ · IBM_other[j]` for the first joint j, when `skins[other]` has the same
/// joints as the primary skin (`None` otherwise).
fn shared_bind(
    doc: &Document,
    primary: usize,
    joints: &[usize],
    binds: &[Mat4],
    other: usize,
) -> Result<Option<Mat4>, IoError> {
    if other == primary {
        return Ok(Some(Mat4::IDENTITY));
    }
    let other_joints = skin_joints(doc, other)?;
    let same_set = other_joints.len() == joints.len()
        && other_joints
            .iter()
            .collect::<BTreeSet<_>>()
            .eq(&joints.iter().collect::<BTreeSet<_>>());
    if !same_set {
        return Ok(None);
    }
    let other_binds = inverse_binds(doc, other, other_joints.len())?;
    let k = other_joints
        .iter()
        .position(|&n| n == joints[0])
        .unwrap_or(0);
    Ok(Some(binds[0].inverse() * other_binds[k]))
}

/// `node` or its nearest ancestor that is a joint (`joint_of`: node → skeleton index, from
/// [`node_positions`]): its skeleton index and node.
fn joint_ancestor(
    tree: &NodeTree,
    joint_of: &HashMap<usize, u32>,
    node: usize,
) -> Option<(u32, usize)> {
    let mut current = Some(node);
    while let Some(ancestor) = current {
        if let Some(&j) = joint_of.get(&ancestor) {
            return Some((j, ancestor));
        }
        current = tree.parents[ancestor];
    }
    None
}

/// The position of every node in `nodes` (a skin's or the skeleton's joint list): node →
/// index, so that lookups stay linear in the joint count.
pub(crate) fn node_positions(nodes: &[usize]) -> HashMap<usize, u32> {
    nodes
        .iter()
        .enumerate()
        .map(|(i, &n)| (n, i as u32))
        .collect()
}

/// `nodes[i]` with the node's name when it has one.
fn node_label(doc: &Document, node: usize) -> Result<String, IoError> {
    let object = doc.item("nodes", node)?;
    Ok(match opt_str(object, "name") {
        Some(name) => format!("nodes[{node}] ({name})"),
        None => format!("nodes[{node}]"),
    })
}

//! The node hierarchy of a glTF document: parents, local transforms, names.

use super::document::{opt_str, Document, Location};
use crate::names::unique_names;
use crate::IoError;
use atlas_skin_runtime::forest::find_cycle;
use atlas_skin_runtime::Trs;
use glam::{Mat4, Quat, Vec3};
use std::collections::HashSet;

/// The node forest of a document, checked: child indices in range, at most one parent per
/// node, no cycle.
///
/// - `parents`: #N parent node of every node, `None` for roots.
/// - `local`: #N local transforms (from `matrix`, decomposed, or from T/R/S).
pub(crate) struct NodeTree {
    pub parents: Vec<Option<usize>>,
    pub local: Vec<Trs>,
}

impl NodeTree {
    pub fn new(doc: &Document) -> Result<Self, IoError> {
        let nodes = doc.array("nodes")?;
        let mut parents = vec![None; nodes.len()];
        let mut local = Vec::with_capacity(nodes.len());
        for (index, node) in nodes.iter().enumerate() {
            let location = Location::item("nodes", index);
            for child in doc.indices(node, &location, "children")? {
                if child >= nodes.len() {
                    return Err(doc.error(format!(
                        "{location}.children has node {child}, but the document has {} nodes",
                        nodes.len()
                    )));
                }
                if let Some(other) = parents[child].replace(index) {
                    return Err(doc.error(format!(
                        "node {child} is a child of both node {other} and node {index} (the node \
                         hierarchy must be a forest)"
                    )));
                }
            }
            local.push(local_transform(doc, node, &location)?);
        }
        if let Some(node) = find_cycle(nodes.len(), |n| parents[n]) {
            return Err(doc.error(format!(
                "the node hierarchy has a cycle through node {node}"
            )));
        }
        Ok(Self { parents, local })
    }

    /// World transform of every node: the product of the local matrices from its root
    /// down. Each node's is computed once, from its parent's (linear in the node count,
    /// whatever the order of the nodes).
    pub fn worlds(&self) -> Vec<Mat4> {
        let mut worlds: Vec<Option<Mat4>> = vec![None; self.parents.len()];
        let mut path = Vec::new();
        for start in 0..self.parents.len() {
            let mut current = Some(start);
            while let Some(node) = current.filter(|&n| worlds[n].is_none()) {
                path.push(node);
                current = self.parents[node];
            }
            let mut above = current.and_then(|n| worlds[n]).unwrap_or(Mat4::IDENTITY);
            for node in path.drain(..).rev() {
                above *= self.local[node].matrix();
                worlds[node] = Some(above);
            }
        }
        worlds.into_iter().flatten().collect()
    }
}

/// A node's local transform: `matrix` decomposed into T·R·S, or its `translation`,
/// `rotation`, `scale` (defaults identity).
fn local_transform(
    doc: &Document,
    node: &serde_json::Value,
    location: &Location,
) -> Result<Trs, IoError> {
    if let Some(m) = doc.opt_floats::<16>(node, location, "matrix")? {
        let (scale, rotation, translation) =
            Mat4::from_cols_array(&m).to_scale_rotation_translation();
        let trs = Trs {
            translation,
            rotation: rotation.normalize(),
            scale,
        };
        if !(trs.rotation.is_finite() && trs.scale.is_finite()) {
            return Err(doc.error(format!("{location}.matrix is not a T·R·S transform")));
        }
        return Ok(trs);
    }
    let translation = doc.opt_floats::<3>(node, location, "translation")?;
    let rotation = doc.opt_floats::<4>(node, location, "rotation")?;
    let scale = doc.opt_floats::<3>(node, location, "scale")?;
    let rotation = rotation.map_or(Quat::IDENTITY, Quat::from_array);
    if rotation.length_squared() < 1e-12 {
        return Err(doc.error(format!("{location}.rotation is a zero quaternion")));
    }
    Ok(Trs {
        translation: translation.map_or(Vec3::ZERO, Vec3::from_array),
        rotation: rotation.normalize(),
        scale: scale.map_or(Vec3::ONE, Vec3::from_array),
    })
}

/// A unique name for every node: its `name`, or `node<index>` when it has none; a repeated
/// name gets the suffix `.1`, `.2`, ... Nodes in `first` (the skin's joints, in skin order)
/// claim their names before the others, so joint names change only when joints collide.
pub(crate) fn unique_node_names(doc: &Document, first: &[usize]) -> Result<Vec<String>, IoError> {
    let nodes = doc.array("nodes")?;
    let base = |index: usize| {
        opt_str(&nodes[index], "name")
            .map(str::to_string)
            .unwrap_or_else(|| format!("node{index}"))
    };
    let first_set: HashSet<usize> = first.iter().copied().collect();
    let order: Vec<usize> = first
        .iter()
        .copied()
        .chain((0..nodes.len()).filter(|i| !first_set.contains(i)))
        .collect();
    let mut names = vec![String::new(); nodes.len()];
    for (&index, name) in order
        .iter()
        .zip(unique_names(order.iter().map(|&i| base(i)).collect()))
    {
        names[index] = name;
    }
    Ok(names)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;
    use std::path::Path;

    #[test]
    fn joints_claim_names_first_and_repeats_get_suffixes() {
        let json = json!({"nodes": [
            {"name": "a"}, {"name": "a"}, {}, {"name": "node2"},
            {"children": [0], "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]}
        ]});
        let doc = Document {
            json: &json,
            buffers: &[],
            path: Path::new("names.gltf"),
            budget: &crate::gltf::budget::DecodeBudget::for_input(0),
        };
        let names = unique_node_names(&doc, &[1]).unwrap();
        assert_eq!(names, ["a.1", "a", "node2", "node2.1", "node4"]);
        let tree = NodeTree::new(&doc).unwrap();
        assert_eq!(tree.parents[0], Some(4));
        let worlds = tree.worlds();
        assert_eq!(worlds[0].w_axis.truncate(), Vec3::new(0.0, 0.0, 5.0));
        assert_eq!(worlds[4], worlds[0]);
        assert_eq!(worlds[1], Mat4::IDENTITY);
    }
}

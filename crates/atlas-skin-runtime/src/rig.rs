//! A rig's world matrices from local transforms, and rigs built from skeletons.

use crate::animation::NO_PARENT_NODE;
use crate::{Rig, RuntimeError, Skeleton, Trs};
use glam::Mat4;

impl Rig {
    /// The rig of a skeleton alone: one node per joint, rest transforms decomposed from
    /// [`Skeleton::rest_local`] (the bind pose), joint j at node j.
    pub fn from_skeleton(skeleton: &Skeleton) -> Self {
        let rest = skeleton
            .rest_local()
            .iter()
            .map(|m| {
                let (scale, rotation, translation) = m.to_scale_rotation_translation();
                Trs {
                    translation,
                    rotation,
                    scale,
                }
            })
            .collect();
        Self {
            names: skeleton.names.clone(),
            parents: skeleton.parents.clone(),
            rest,
            joint_nodes: (0..skeleton.len() as u32).collect(),
        }
    }

    /// Index of the node named `name`.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Node indices ordered so that every parent comes before its children (a validated,
    /// acyclic rig).
    pub fn topological_order(&self) -> Vec<usize> {
        let mut children = vec![Vec::new(); self.len()];
        let mut stack = Vec::new();
        for (node, &parent) in self.parents.iter().enumerate().rev() {
            match parent {
                NO_PARENT_NODE => stack.push(node),
                p => children[p as usize].push(node),
            }
        }
        let mut order = Vec::with_capacity(self.len());
        while let Some(node) = stack.pop() {
            order.push(node);
            stack.extend(children[node].iter().copied());
        }
        order
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// True when the rig has no node.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Checks equal lengths, parents and joint nodes in range, no cycle, finite rest
    /// transforms. [`Rig::world`] assumes a validated rig.
    pub fn validate(&self) -> Result<(), RuntimeError> {
        let count = self.len();
        if self.parents.len() != count || self.rest.len() != count {
            return Err(RuntimeError::LengthMismatch {
                what: format!(
                    "rig: {count} names, {} parents, {} rest transforms",
                    self.parents.len(),
                    self.rest.len()
                ),
            });
        }
        let bad = |node: usize, what: String| RuntimeError::BadRig {
            node,
            name: self.names[node].clone(),
            what,
        };
        for (node, &parent) in self.parents.iter().enumerate() {
            if parent != NO_PARENT_NODE && parent as usize >= count {
                return Err(bad(node, format!("parent {parent} is not a node")));
            }
            let depth = self.ancestors(node).take(count + 1).count();
            if depth > count {
                return Err(bad(node, "the hierarchy has a cycle through it".into()));
            }
            let rest = &self.rest[node];
            let finite =
                rest.translation.is_finite() && rest.rotation.is_finite() && rest.scale.is_finite();
            if !finite {
                return Err(bad(node, "non-finite rest transform".into()));
            }
        }
        if let Some(&node) = self.joint_nodes.iter().find(|&&n| n as usize >= count) {
            return Err(RuntimeError::LengthMismatch {
                what: format!("rig: joint node {node}, but the rig has {count} nodes"),
            });
        }
        Ok(())
    }

    /// The parent, grandparent, … of `node`, up to its root.
    fn ancestors(&self, node: usize) -> impl Iterator<Item = usize> + '_ {
        let first = self.parents[node];
        std::iter::successors((first != NO_PARENT_NODE).then_some(first as usize), |&n| {
            let p = self.parents[n];
            (p != NO_PARENT_NODE).then_some(p as usize)
        })
    }

    /// World matrix of every node: `world[n] = world[parent(n)] · local[n].matrix()`
    /// (roots: `local[n].matrix()`).
    ///
    /// - `local`: #N local transforms (a [`crate::Clip::sample`] output, or `rest`).
    /// - `out_world`: #N matrices.
    ///
    /// glTF does not order parents before children, so a node whose parent comes later is
    /// composed by walking up its ancestors; nothing is allocated.
    pub fn world(&self, local: &[Trs], out_world: &mut [Mat4]) {
        debug_assert_eq!(local.len(), self.len());
        debug_assert_eq!(out_world.len(), self.len());
        for node in 0..self.len() {
            let parent = self.parents[node];
            let local_matrix = local[node].matrix();
            out_world[node] = if parent == NO_PARENT_NODE {
                local_matrix
            } else if (parent as usize) < node {
                out_world[parent as usize] * local_matrix
            } else {
                self.ancestors(node)
                    .fold(local_matrix, |m, a| local[a].matrix() * m)
            };
        }
    }

    /// World matrix of every skeleton joint: `out_joint_world[j] = node_world[joint_nodes[j]]`.
    ///
    /// - `node_world`: #N matrices from [`Rig::world`]; `out_joint_world`: #J matrices, the
    ///   input of [`crate::pose::palette_from_world`].
    pub fn joint_world(&self, node_world: &[Mat4], out_joint_world: &mut [Mat4]) {
        debug_assert_eq!(out_joint_world.len(), self.joint_nodes.len());
        for (out, &node) in out_joint_world.iter_mut().zip(&self.joint_nodes) {
            *out = node_world[node as usize];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec3};
    use std::f32::consts::FRAC_PI_2;

    #[test]
    fn world_composes_parents_in_any_index_order() {
        // Node 0's parent is node 1 (stored after it), as glTF allows.
        let rig = Rig {
            names: vec!["child".into(), "root".into()],
            parents: vec![1, NO_PARENT_NODE],
            rest: vec![
                Trs {
                    translation: Vec3::X,
                    ..Trs::IDENTITY
                },
                Trs {
                    rotation: Quat::from_rotation_z(FRAC_PI_2),
                    translation: Vec3::Y,
                    ..Trs::IDENTITY
                },
            ],
            joint_nodes: vec![0],
        };
        rig.validate().unwrap();
        assert_eq!(rig.topological_order(), vec![1, 0]);
        let mut world = [Mat4::ZERO; 2];
        rig.world(&rig.rest, &mut world);
        let child_origin = world[0].transform_point3(Vec3::ZERO);
        assert!(child_origin.abs_diff_eq(Vec3::new(0.0, 2.0, 0.0), 1e-6));
        let mut joints = [Mat4::ZERO; 1];
        rig.joint_world(&world, &mut joints);
        assert_eq!(joints[0], world[0]);
        let cyclic = Rig {
            parents: vec![1, 0],
            ..rig
        };
        assert!(cyclic.validate().is_err());
    }

    #[test]
    fn rig_of_a_skeleton_reproduces_its_bind_pose() {
        let skeleton = Skeleton::from_positions(
            vec!["hip".into(), "knee".into(), "foot".into()],
            vec![crate::NO_PARENT, 0, 1],
            &[Vec3::Y, Vec3::new(0.0, 0.5, 0.1), Vec3::ZERO],
        )
        .unwrap();
        let rig = Rig::from_skeleton(&skeleton);
        rig.validate().unwrap();
        let mut world = vec![Mat4::ZERO; 3];
        let mut joints = vec![Mat4::ZERO; 3];
        rig.world(&rig.rest, &mut world);
        rig.joint_world(&world, &mut joints);
        for (w, b) in joints.iter().zip(skeleton.bind_world()) {
            assert!(w.abs_diff_eq(b, 1e-6));
        }
        assert_eq!(rig.find("knee"), Some(1));
    }
}

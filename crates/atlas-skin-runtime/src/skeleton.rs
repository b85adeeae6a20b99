//! A joint hierarchy with its bind pose.

use crate::RuntimeError;
use glam::{Mat4, Vec3};

/// Sentinel parent index of a root joint.
pub const NO_PARENT: u32 = u32::MAX;

/// An animation skeleton: joints with names, a parent hierarchy and a bind pose.
///
/// - `names`: #J joint names, unique.
/// - `parents`: #J parent indices into the same arrays, [`NO_PARENT`] for roots.
/// - `inverse_bind`: #J matrices taking a point from the bind space of the mesh into the
///   joint's local frame (glTF's inverseBindMatrices). The bind pose of joint j is
///   `inverse_bind[j].inverse()`, its position the translation of that matrix.
///
/// - `tails`: #J bind-space far ends of the joints' bones where the file gives them
///   (MakeHuman bone tails, BVH end sites), `None` elsewhere. Skinning never reads them;
///   automatic weighting does: a leaf joint's bone runs from its position to its tail.
///
/// The rest pose used for posing is the bind pose: joint j's rest local transform is
/// `bind_world[parent]⁻¹ · bind_world[j]` (for a root, `bind_world[j]`).
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    pub names: Vec<String>,
    pub parents: Vec<u32>,
    pub inverse_bind: Vec<Mat4>,
    pub tails: Vec<Option<Vec3>>,
}

impl Skeleton {
    /// Builds a skeleton and validates it: equal lengths, parents in range, no cycle,
    /// finite invertible bind matrices.
    pub fn new(
        names: Vec<String>,
        parents: Vec<u32>,
        inverse_bind: Vec<Mat4>,
    ) -> Result<Self, RuntimeError> {
        let skeleton = Self {
            tails: vec![None; names.len()],
            names,
            parents,
            inverse_bind,
        };
        skeleton.validate()?;
        Ok(skeleton)
    }

    /// Builds a skeleton whose joints have the given bind-space positions and identity
    /// orientation (the case of TGF, BVH and MakeHuman skeletons).
    pub fn from_positions(
        names: Vec<String>,
        parents: Vec<u32>,
        positions: &[Vec3],
    ) -> Result<Self, RuntimeError> {
        let inverse_bind = positions
            .iter()
            .map(|p| Mat4::from_translation(-*p))
            .collect();
        Self::new(names, parents, inverse_bind)
    }

    /// The same skeleton with bone tails (see the type's documentation); checks that there
    /// is one entry per joint and that every tail is finite.
    pub fn with_tails(mut self, tails: Vec<Option<Vec3>>) -> Result<Self, RuntimeError> {
        self.tails = tails;
        self.validate()?;
        Ok(self)
    }

    /// Number of joints.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// True when the skeleton has no joint.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Checks the invariants listed on [`Skeleton::new`].
    pub fn validate(&self) -> Result<(), RuntimeError> {
        let count = self.names.len();
        if self.parents.len() != count
            || self.inverse_bind.len() != count
            || self.tails.len() != count
        {
            return Err(RuntimeError::LengthMismatch {
                what: format!(
                    "{} names, {} parents, {} inverse bind matrices, {} tails",
                    count,
                    self.parents.len(),
                    self.inverse_bind.len(),
                    self.tails.len()
                ),
            });
        }
        if let Some(joint) = self
            .tails
            .iter()
            .position(|t| t.is_some_and(|t| !t.is_finite()))
        {
            return Err(RuntimeError::BadTail {
                joint,
                name: self.names[joint].clone(),
            });
        }
        for (joint, &parent) in self.parents.iter().enumerate() {
            if parent != NO_PARENT && parent as usize >= count {
                return Err(RuntimeError::ParentOutOfRange {
                    joint,
                    parent,
                    count,
                });
            }
        }
        if let Some(joint) = crate::forest::find_cycle(count, |j| self.parent(j)) {
            return Err(RuntimeError::Cycle {
                joint,
                name: self.names[joint].clone(),
            });
        }
        for (joint, m) in self.inverse_bind.iter().enumerate() {
            let det = m.determinant();
            if !m.is_finite() || !det.is_finite() || det.abs() < 1e-12 {
                return Err(RuntimeError::BadBindMatrix {
                    joint,
                    name: self.names[joint].clone(),
                });
            }
        }
        Ok(())
    }

    /// Parent of joint `j`, `None` for a root.
    pub fn parent(&self, j: usize) -> Option<usize> {
        let p = self.parents[j];
        (p != NO_PARENT).then_some(p as usize)
    }

    /// The joints above `j`, nearest first: its parent, its grandparent, ... up to its
    /// root (a valid skeleton has no cycles).
    pub fn ancestors(&self, j: usize) -> impl Iterator<Item = usize> + '_ {
        std::iter::successors(self.parent(j), move |&a| self.parent(a))
    }

    /// Children of every joint, in index order.
    pub fn children(&self) -> Vec<Vec<usize>> {
        let mut children = vec![Vec::new(); self.len()];
        for j in 0..self.len() {
            if let Some(p) = self.parent(j) {
                children[p].push(j);
            }
        }
        children
    }

    /// Joint indices ordered so that every parent comes before its children.
    pub fn topological_order(&self) -> Vec<usize> {
        let children = self.children();
        let mut order = Vec::with_capacity(self.len());
        let mut stack: Vec<usize> = (0..self.len())
            .filter(|&j| self.parent(j).is_none())
            .rev()
            .collect();
        while let Some(j) = stack.pop() {
            order.push(j);
            stack.extend(children[j].iter().rev());
        }
        order
    }

    /// Bind-pose world transform of every joint: `inverse_bind[j]⁻¹`.
    pub fn bind_world(&self) -> Vec<Mat4> {
        self.inverse_bind.iter().map(|m| m.inverse()).collect()
    }

    /// Bind-pose position of every joint in the mesh's bind space.
    pub fn bind_positions(&self) -> Vec<Vec3> {
        self.bind_world()
            .iter()
            .map(|m| m.w_axis.truncate())
            .collect()
    }

    /// Rest local transform of every joint: `bind_world[parent]⁻¹ · bind_world[j]`.
    pub fn rest_local(&self) -> Vec<Mat4> {
        let world = self.bind_world();
        (0..self.len())
            .map(|j| match self.parent(j) {
                Some(p) => self.inverse_bind[p] * world[j],
                None => world[j],
            })
            .collect()
    }

    /// Index of the joint named `name`.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chain() -> Skeleton {
        Skeleton::from_positions(
            vec!["a".into(), "b".into(), "c".into()],
            vec![NO_PARENT, 0, 1],
            &[Vec3::ZERO, Vec3::Y, Vec3::Y * 2.0],
        )
        .unwrap()
    }

    #[test]
    fn invalid_skeletons_are_rejected() {
        let names = || vec!["a".to_string(), "b".to_string()];
        let ibm = || vec![Mat4::IDENTITY; 2];
        // Each case breaks one rule, and is refused for that rule.
        type Case = (Vec<u32>, Vec<Mat4>, fn(&RuntimeError) -> bool);
        let cases: Vec<Case> = vec![
            (vec![NO_PARENT], ibm(), |e| {
                matches!(e, RuntimeError::LengthMismatch { .. })
            }),
            (vec![NO_PARENT, 7], ibm(), |e| {
                matches!(e, RuntimeError::ParentOutOfRange { parent: 7, .. })
            }),
            (vec![1, 0], ibm(), |e| {
                matches!(e, RuntimeError::Cycle { .. })
            }),
            (vec![NO_PARENT, 1], ibm(), |e| {
                matches!(e, RuntimeError::Cycle { joint: 1, .. })
            }),
            (vec![NO_PARENT, 0], vec![Mat4::IDENTITY, Mat4::ZERO], |e| {
                matches!(e, RuntimeError::BadBindMatrix { joint: 1, .. })
            }),
            (
                vec![NO_PARENT, 0],
                vec![Mat4::IDENTITY, Mat4::from_translation(Vec3::NAN)],
                |e| matches!(e, RuntimeError::BadBindMatrix { joint: 1, .. }),
            ),
        ];
        for (p, m, expected) in cases {
            match Skeleton::new(names(), p.clone(), m) {
                Err(e) => assert!(expected(&e), "{p:?}: refused for another reason: {e:?}"),
                Ok(_) => panic!("accepted {p:?}"),
            }
        }
    }

    #[test]
    fn tails_need_one_finite_entry_per_joint() {
        assert_eq!(chain().tails, vec![None; 3]);
        let tails = vec![None, None, Some(Vec3::Y * 3.0)];
        assert_eq!(chain().with_tails(tails.clone()).unwrap().tails, tails);
        assert!(matches!(
            chain().with_tails(vec![None; 2]),
            Err(RuntimeError::LengthMismatch { .. })
        ));
        assert!(matches!(
            chain().with_tails(vec![None, Some(Vec3::NAN), None]),
            Err(RuntimeError::BadTail { joint: 1, .. })
        ));
    }

    #[test]
    fn rest_local_recomposes_bind_world() {
        let s = chain();
        let local = s.rest_local();
        let world = s.bind_world();
        for j in s.topological_order() {
            let composed = match s.parent(j) {
                Some(p) => world[p] * local[j],
                None => local[j],
            };
            assert!(composed.abs_diff_eq(world[j], 1e-6));
        }
        assert_eq!(s.bind_positions()[2], Vec3::Y * 2.0);
    }
}

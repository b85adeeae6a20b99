//! Moving a motion from one rig onto another whose joints have the same names, or names
//! paired by a joint map, but other rest orientations (a BVH capture onto a glTF
//! character).
//!
//! Rest poses differ: a BVH joint's rest orientation is the identity (its bind pose is
//! all rotations zero), a glTF joint's is whatever the artist's rest local rotations
//! compose to; the two skeletons' bone lengths differ too. Copying local rotations would
//! therefore twist every joint by the difference of the rest frames. Instead the
//! *world-space rotation delta* of every matched joint is transferred:
//!
//! `D_s = W_s · W_s,rest⁻¹` (source joint's world rotation relative to its rest), then the
//! target joint's world rotation is `W_t = D_s · W_t,rest` and its local rotation
//! `W_t,parent⁻¹ · W_t`. A bone that points along +y in both rests and is turned 30° about
//! z in the capture is turned 30° about z on the character, whatever its local axes.
//! Unmatched target joints keep their rest local transform (they follow their parent).
//! The root's displacement from its rest position is transferred scaled by the ratio of
//! the rigs' sizes. Both rigs' world frames are assumed to agree on up and facing (as
//! glTF and BVH both use +y up); a different convention shows as a constant tilt.

use crate::animation::NO_PARENT_NODE;
use crate::{Rig, RuntimeError, Trs};
use glam::{Mat4, Quat, Vec3};

/// A name-matched mapping from a source rig to a target rig, with the rest data and
/// scratch space it needs, so that [`Retarget::apply`] allocates nothing per frame.
#[derive(Debug, Clone)]
pub struct Retarget {
    /// Per target node: the matched source node.
    source_of: Vec<Option<usize>>,
    /// The matched pair whose source node is a source root: its displacement moves the
    /// target.
    root_pair: Option<(usize, usize)>,
    /// Target size ÷ source size (root displacement scale).
    scale: f32,
    source_rest_world: Vec<Mat4>,
    target_rest_world: Vec<Mat4>,
    target_order: Vec<usize>,
    source_world: Vec<Mat4>,
    target_world: Vec<Mat4>,
    target_parents: Vec<u32>,
}

/// A joint name reduced for matching: namespace prefixes (`mixamorig:Hips`) dropped,
/// lower case, separators (`_`, `-`, `.`, space) removed.
pub fn normalized_name(name: &str) -> String {
    let base = name.rsplit([':', '|']).next().unwrap_or(name);
    base.chars()
        .filter(|c| !matches!(c, '_' | '-' | '.' | ' '))
        .flat_map(char::to_lowercase)
        .collect()
}

impl Retarget {
    /// Matches the target rig's skeleton joints to the source rig's skeleton joints by
    /// [`normalized_name`] and precomputes both rest poses ([`Retarget::with_map`] with an
    /// empty map).
    pub fn new(source: &Rig, target: &Rig) -> Result<Self, RuntimeError> {
        Self::with_map(source, target, &[])
    }

    /// As [`Retarget::new`], but each (target joint, source joint) pair of `map`, by exact
    /// name, is matched first; the other target joints are matched by
    /// [`normalized_name`] among the source joints the map does not use.
    ///
    /// Errors: either rig invalid ([`Rig::validate`]),
    /// [`RuntimeError::UnknownMappedJoint`] when the map names a joint a rig does not have,
    /// [`RuntimeError::NoCommonJoints`] when nothing matches.
    pub fn with_map(
        source: &Rig,
        target: &Rig,
        map: &[(String, String)],
    ) -> Result<Self, RuntimeError> {
        source.validate()?;
        target.validate()?;
        let joint_named = |rig: &Rig, name: &str, which: &'static str| {
            rig.joint_nodes
                .iter()
                .map(|&n| n as usize)
                .find(|&n| rig.names[n] == name)
                .ok_or_else(|| RuntimeError::UnknownMappedJoint {
                    name: name.to_string(),
                    rig: which,
                })
        };
        let mut source_of = vec![None; target.len()];
        let mut mapped_sources = Vec::with_capacity(map.len());
        for (target_name, source_name) in map {
            let t = joint_named(target, target_name, "character")?;
            let s = joint_named(source, source_name, "motion")?;
            source_of[t] = Some(s);
            mapped_sources.push(s);
        }
        for &t in &target.joint_nodes {
            if source_of[t as usize].is_some() {
                continue;
            }
            let wanted = normalized_name(&target.names[t as usize]);
            source_of[t as usize] = source
                .joint_nodes
                .iter()
                .map(|&s| s as usize)
                .filter(|s| !mapped_sources.contains(s))
                .find(|&s| normalized_name(&source.names[s]) == wanted);
        }
        let matched = source_of.iter().flatten().count();
        if matched == 0 {
            let first = |rig: &Rig| rig.names.first().cloned().unwrap_or_default();
            return Err(RuntimeError::NoCommonJoints {
                source_joint: first(source),
                target_joint: first(target),
            });
        }
        let mut source_rest_world = vec![Mat4::IDENTITY; source.len()];
        let mut target_rest_world = vec![Mat4::IDENTITY; target.len()];
        source.world(&source.rest, &mut source_rest_world);
        target.world(&target.rest, &mut target_rest_world);
        let target_order = target.topological_order();
        let root_pair = target_order.iter().find_map(|&t| {
            source_of[t].and_then(|s| (source.parents[s] == NO_PARENT_NODE).then_some((t, s)))
        });
        let target_size = extent(
            source_of
                .iter()
                .enumerate()
                .filter_map(|(t, s)| s.map(|_| translation(&target_rest_world[t]))),
        );
        let source_size = extent(
            source_of
                .iter()
                .flatten()
                .map(|&s| translation(&source_rest_world[s])),
        );
        // A single matched joint has no extent: keep the displacement as captured.
        let scale = target_size / source_size;
        let scale = if scale.is_finite() && scale > 0.0 {
            scale
        } else {
            1.0
        };
        Ok(Self {
            source_of,
            root_pair,
            scale,
            source_world: source_rest_world.clone(),
            target_world: target_rest_world.clone(),
            source_rest_world,
            target_rest_world,
            target_order,
            target_parents: target.parents.clone(),
        })
    }

    /// Number of target joints that have a source joint.
    pub fn matched_count(&self) -> usize {
        self.source_of.iter().flatten().count()
    }

    /// Target local transforms for a source pose (see the module documentation).
    ///
    /// - `source`: the source rig; `source_local`: its #Ns local transforms (a sampled
    ///   clip frame).
    /// - `target`: the target rig; `out_target_local`: its #Nt local transforms.
    ///
    /// The rigs must be the ones given to [`Retarget::new`] (the mapping and rest data
    /// were computed from them).
    pub fn apply(
        &mut self,
        source: &Rig,
        source_local: &[Trs],
        target: &Rig,
        out_target_local: &mut [Trs],
    ) {
        debug_assert_eq!(out_target_local.len(), self.source_of.len());
        source.world(source_local, &mut self.source_world);
        out_target_local.copy_from_slice(&target.rest);
        for &t in &self.target_order {
            let parent_world = match self.target_parents[t] {
                NO_PARENT_NODE => Mat4::IDENTITY,
                p => self.target_world[p as usize],
            };
            if let Some(s) = self.source_of[t] {
                let delta = rotation(&self.source_world[s])
                    * rotation(&self.source_rest_world[s]).inverse();
                let world_rotation = delta * rotation(&self.target_rest_world[t]);
                let local = &mut out_target_local[t];
                local.rotation = (rotation(&parent_world).inverse() * world_rotation).normalize();
                if self.root_pair == Some((t, s)) {
                    let displacement = translation(&self.source_world[s])
                        - translation(&self.source_rest_world[s]);
                    let world_position =
                        translation(&self.target_rest_world[t]) + displacement * self.scale;
                    local.translation = parent_world.inverse().transform_point3(world_position);
                }
            }
            self.target_world[t] = parent_world * out_target_local[t].matrix();
        }
    }
}

fn rotation(m: &Mat4) -> Quat {
    m.to_scale_rotation_translation().1
}

fn translation(m: &Mat4) -> Vec3 {
    m.w_axis.truncate()
}

/// Bounding-box diagonal of a set of points.
fn extent(points: impl Iterator<Item = Vec3>) -> f32 {
    let (lo, hi) = points.fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    (hi - lo).length()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::FRAC_PI_2;

    /// A two-joint chain along +y, its second joint at height `length`, with the given
    /// rest rotations and names.
    fn chain(names: [&str; 2], length: f32, rest_rotations: [Quat; 2]) -> Rig {
        Rig {
            names: names.iter().map(|n| n.to_string()).collect(),
            parents: vec![NO_PARENT_NODE, 0],
            rest: vec![
                Trs {
                    rotation: rest_rotations[0],
                    ..Trs::IDENTITY
                },
                Trs {
                    // Rest translation expressed in the parent's rotated frame, so the
                    // child sits at (0, length, 0) in world whatever the rotation.
                    translation: rest_rotations[0].inverse() * Vec3::new(0.0, length, 0.0),
                    rotation: rest_rotations[0].inverse() * rest_rotations[1],
                    ..Trs::IDENTITY
                },
            ],
            joint_nodes: vec![0, 1],
        }
    }

    #[test]
    fn world_rotation_deltas_carry_over_whatever_the_rest_frames() {
        let source = chain(["Hips", "Spine"], 1.0, [Quat::IDENTITY; 2]);
        let target = chain(
            ["mixamorig:hips", "SPINE"],
            2.0,
            [Quat::from_rotation_x(0.7), Quat::from_rotation_y(-1.2)],
        );
        let mut retarget = Retarget::new(&source, &target).unwrap();
        assert_eq!(retarget.matched_count(), 2);
        let mut source_local = source.rest.clone();
        source_local[0].rotation = Quat::from_rotation_z(FRAC_PI_2);
        source_local[0].translation = Vec3::new(0.5, 0.0, 0.0);
        let mut target_local = target.rest.clone();
        retarget.apply(&source, &source_local, &target, &mut target_local);
        let mut world = vec![Mat4::IDENTITY; 2];
        target.world(&target_local, &mut world);
        // The hips turned 90° about z: the spine joint, 2 above the hips, swings to -x;
        // the root moved by 0.5 × (target size 2 / source size 1).
        assert!(translation(&world[0]).abs_diff_eq(Vec3::new(1.0, 0.0, 0.0), 1e-5));
        assert!(translation(&world[1]).abs_diff_eq(Vec3::new(-1.0, 0.0, 0.0), 1e-5));
        // Each joint's world rotation is the delta applied to its own rest rotation.
        let expected = Quat::from_rotation_z(FRAC_PI_2) * Quat::from_rotation_y(-1.2);
        assert!(rotation(&world[1]).angle_between(expected) < 1e-4);
    }

    #[test]
    fn a_joint_map_pairs_joints_whose_names_differ() {
        let source = chain(["Hips", "Spine"], 1.0, [Quat::IDENTITY; 2]);
        let target = chain(["node2", "node11"], 1.0, [Quat::IDENTITY; 2]);
        assert!(Retarget::new(&source, &target).is_err());
        let map = |pairs: &[(&str, &str)]| -> Vec<(String, String)> {
            pairs.iter().map(|&(t, s)| (t.into(), s.into())).collect()
        };
        let mut retarget = Retarget::with_map(
            &source,
            &target,
            &map(&[("node2", "Hips"), ("node11", "Spine")]),
        )
        .unwrap();
        assert_eq!(retarget.matched_count(), 2);
        let mut source_local = source.rest.clone();
        source_local[1].rotation = Quat::from_rotation_z(0.5);
        let mut target_local = target.rest.clone();
        retarget.apply(&source, &source_local, &target, &mut target_local);
        assert!(
            target_local[1]
                .rotation
                .angle_between(Quat::from_rotation_z(0.5))
                < 1e-5
        );
        // A map entry wins over a name match, and names a rig does not have are errors.
        let swapped = chain(["Spine", "Hips"], 1.0, [Quat::IDENTITY; 2]);
        let crossed = Retarget::with_map(&source, &swapped, &map(&[("Spine", "Hips")])).unwrap();
        assert_eq!(crossed.source_of, vec![Some(0), None]);
        for (pairs, name, rig) in [
            (&[("nodeX", "Hips")][..], "nodeX", "character"),
            (&[("node2", "Chest")][..], "Chest", "motion"),
        ] {
            assert_eq!(
                Retarget::with_map(&source, &target, &map(pairs)).unwrap_err(),
                RuntimeError::UnknownMappedJoint {
                    name: name.into(),
                    rig
                }
            );
        }
    }

    #[test]
    fn rigs_without_common_names_are_rejected() {
        let source = chain(["a", "b"], 1.0, [Quat::IDENTITY; 2]);
        let target = chain(["c", "d"], 1.0, [Quat::IDENTITY; 2]);
        assert!(Retarget::new(&source, &target).is_err());
        assert_eq!(normalized_name("mixamorig:Left_Up-Leg"), "leftupleg");
    }
}

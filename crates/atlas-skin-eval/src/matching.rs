//! Pairing a candidate's vertices and joints with the reference's: vertices by position
//! (the candidate may be reordered, welded or split along seams), joints by name, by name
//! ignoring case and punctuation, then by bind position (another tool's export of the same
//! character may rename them).

use super::EvalError;
use glam::{DVec3, I64Vec3, Vec3};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Marks a reference vertex with no candidate vertex within the tolerance.
pub const UNMATCHED: u32 = u32::MAX;

/// For every reference vertex, the nearest candidate vertex within `tolerance`
/// (Euclidean distance), or [`UNMATCHED`].
///
/// - `reference`: #R positions; `candidate`: #C positions; returns #R candidate indices.
///
/// A hash grid of cell size `tolerance` over the candidate makes this expected
/// O(R + C). A zero tolerance matches only identical positions.
pub fn match_vertices(reference: &[Vec3], candidate: &[Vec3], tolerance: f64) -> Vec<u32> {
    let cell_size = if tolerance > 0.0 { tolerance } else { 1.0 };
    // `as` saturates: far-away points may share a clamped cell, which only costs time.
    let cell = |p: Vec3| (p.as_dvec3() / cell_size).floor().as_i64vec3();
    let mut grid: HashMap<I64Vec3, Vec<u32>> = HashMap::new();
    for (c, p) in candidate.iter().enumerate() {
        grid.entry(cell(*p)).or_default().push(c as u32);
    }
    reference
        .iter()
        .map(|p| nearest_within(&grid, candidate, p.as_dvec3(), cell(*p), tolerance))
        .collect()
}

fn nearest_within(
    grid: &HashMap<I64Vec3, Vec<u32>>,
    candidate: &[Vec3],
    point: DVec3,
    home: I64Vec3,
    tolerance: f64,
) -> u32 {
    let mut best = (UNMATCHED, f64::INFINITY);
    for dx in -1..=1 {
        for dy in -1..=1 {
            for dz in -1..=1 {
                let key = home.saturating_add(I64Vec3::new(dx, dy, dz));
                for &c in grid.get(&key).into_iter().flatten() {
                    let d = candidate[c as usize].as_dvec3().distance(point);
                    if d <= tolerance && d < best.1 {
                        best = (c, d);
                    }
                }
            }
        }
    }
    best.0
}

/// How a candidate joint found its reference joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointMatch {
    /// The same name.
    Name,
    /// The same name once lowercased and stripped of everything but letters and digits
    /// (Blender's glTF importer calls an unnamed node 2 `Node_2` where we say `node2`).
    NameIgnoringCase,
    /// No name matched: the nearest free reference joint within the tolerance of its bind
    /// position.
    Position,
}

/// A candidate joint and the reference joint it was matched to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointPair {
    pub candidate: String,
    pub reference: String,
    pub how: JointMatch,
}

/// One skeleton's joints as [`match_joints`] compares them: names and bind positions.
#[derive(Debug, Clone, Copy)]
pub struct JointSet<'a> {
    pub names: &'a [String],
    pub positions: &'a [Vec3],
}

/// `name` lowercased, with only its letters and digits.
fn loose_name(name: &str) -> String {
    name.chars()
        .filter(|c| c.is_alphanumeric())
        .flat_map(char::to_lowercase)
        .collect()
}

/// The reference joint of every candidate joint (#K indices into the reference's #J).
///
/// Three passes, each over the candidate joints still unmatched and the reference joints
/// still free: the same name; the same `loose_name` when exactly one free reference
/// joint has it; then the nearest free reference joint whose bind position is within
/// `tolerance` (ties go to the lower index). Reference joints the candidate lacks are
/// fine (they carry no candidate weight); a candidate joint no pass matches is
/// [`EvalError::UnknownJoint`], since its weight could not be posed with the reference
/// skeleton.
pub fn match_joints(
    reference: JointSet,
    candidate: JointSet,
    tolerance: f64,
) -> Result<Vec<JointPair>, EvalError> {
    let mut found: Vec<Option<(u32, JointMatch)>> = vec![None; candidate.names.len()];
    let mut taken = vec![false; reference.names.len()];
    let exact: HashMap<&str, usize> = reference
        .names
        .iter()
        .enumerate()
        .map(|(j, name)| (name.as_str(), j))
        .collect();
    for (k, name) in candidate.names.iter().enumerate() {
        if let Some(&j) = exact.get(name.as_str()) {
            if !std::mem::replace(&mut taken[j], true) {
                found[k] = Some((j as u32, JointMatch::Name));
            }
        }
    }
    for (k, slot) in found.iter_mut().enumerate() {
        if slot.is_some() {
            continue;
        }
        let wanted = loose_name(&candidate.names[k]);
        let mut free = (0..reference.names.len())
            .filter(|&j| !taken[j] && loose_name(&reference.names[j]) == wanted);
        if let (Some(j), None) = (free.next(), free.next()) {
            taken[j] = true;
            *slot = Some((j as u32, JointMatch::NameIgnoringCase));
        }
    }
    for (k, slot) in found.iter_mut().enumerate() {
        if slot.is_some() {
            continue;
        }
        let at = candidate.positions[k].as_dvec3();
        let nearest = (0..reference.names.len())
            .filter(|&j| !taken[j])
            .map(|j| (j, reference.positions[j].as_dvec3().distance(at)))
            .filter(|&(_, d)| d <= tolerance)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((j, _)) = nearest {
            taken[j] = true;
            *slot = Some((j as u32, JointMatch::Position));
        }
    }
    found
        .into_iter()
        .enumerate()
        .map(|(k, pair)| match pair {
            Some((j, how)) => Ok(JointPair {
                candidate: candidate.names[k].clone(),
                reference: reference.names[j as usize].clone(),
                how,
            }),
            None => Err(EvalError::UnknownJoint {
                joint: k,
                name: candidate.names[k].clone(),
                tolerance,
            }),
        })
        .collect()
}

/// The reference joint index of every pair of [`match_joints`].
pub fn reference_indices(reference: &[String], pairs: &[JointPair]) -> Vec<u32> {
    let index: HashMap<&str, u32> = reference
        .iter()
        .enumerate()
        .map(|(j, name)| (name.as_str(), j as u32))
        .collect();
    pairs.iter().map(|p| index[p.reference.as_str()]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertices_match_the_nearest_within_tolerance() {
        let reference = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        // Reordered, one duplicated (a seam), one moved beyond the tolerance.
        let candidate = [
            Vec3::Y,
            Vec3::new(1.0, 0.0, 1e-7),
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.0, 0.0, 1.1),
        ];
        let matched = match_vertices(&reference, &candidate, 1e-5);
        assert_eq!(matched, vec![2, 3, 0, UNMATCHED]);
        assert_eq!(match_vertices(&reference, &candidate, 0.0)[1], 3);
    }

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn joints_match_by_name_then_loose_name_then_position() {
        let reference = names(&["hip", "knee", "foot", "toe"]);
        let at = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let candidate = names(&["foot", "HIP_", "bone7", "bone8"]);
        let candidate_at = [Vec3::Y, Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0005), Vec3::X];
        let set = |names, positions| JointSet { names, positions };
        let pairs =
            match_joints(set(&reference, &at), set(&candidate, &candidate_at), 1e-3).unwrap();
        let how: Vec<(&str, JointMatch)> = pairs
            .iter()
            .map(|p| (p.reference.as_str(), p.how))
            .collect();
        assert_eq!(
            how,
            [
                ("foot", JointMatch::Name),
                ("hip", JointMatch::NameIgnoringCase),
                ("toe", JointMatch::Position),
                ("knee", JointMatch::Position),
            ]
        );
        assert_eq!(reference_indices(&reference, &pairs), [2, 0, 3, 1]);
        // Too far from any free joint: not the same skeleton.
        let far = [Vec3::Y, Vec3::ZERO, Vec3::splat(5.0), Vec3::X];
        assert!(matches!(
            match_joints(set(&reference, &at), set(&candidate, &far), 1e-3),
            Err(EvalError::UnknownJoint { joint: 2, .. })
        ));
    }

    #[test]
    fn a_loose_name_shared_by_two_free_joints_falls_through_to_position() {
        let reference = names(&["Arm.L", "arm_l"]);
        let at = [Vec3::X, Vec3::NEG_X];
        let candidate = names(&["ARM-L"]);
        let pairs = match_joints(
            JointSet {
                names: &reference,
                positions: &at,
            },
            JointSet {
                names: &candidate,
                positions: &[Vec3::NEG_X],
            },
            1e-3,
        )
        .unwrap();
        assert_eq!(
            (pairs[0].reference.as_str(), pairs[0].how),
            ("arm_l", JointMatch::Position)
        );
    }
}

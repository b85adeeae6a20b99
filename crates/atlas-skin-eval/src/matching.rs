//! Pairing a candidate's vertices and joints with the reference's: vertices by position
//! (the candidate may be reordered, welded or split along seams), joints by name.

use super::EvalError;
use glam::{DVec3, I64Vec3, Vec3};
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

/// The reference joint of every candidate joint, found by name.
///
/// - `reference`: #J joint names (unique); `candidate`: #K joint names; returns #K
///   indices into `reference`.
///
/// Reference joints the candidate lacks are fine (they carry no candidate weight); a
/// candidate joint the reference lacks is [`EvalError::UnknownJoint`], since its weight
/// could not be posed with the reference skeleton.
pub fn match_joints(reference: &[String], candidate: &[String]) -> Result<Vec<u32>, EvalError> {
    let index: HashMap<&str, u32> = reference
        .iter()
        .enumerate()
        .map(|(j, name)| (name.as_str(), j as u32))
        .collect();
    candidate
        .iter()
        .enumerate()
        .map(|(k, name)| {
            index
                .get(name.as_str())
                .copied()
                .ok_or_else(|| EvalError::UnknownJoint {
                    joint: k,
                    name: name.clone(),
                })
        })
        .collect()
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

    #[test]
    fn joints_match_by_name_and_unknown_names_are_errors() {
        let names = |n: &[&str]| n.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let reference = names(&["hip", "knee", "foot"]);
        assert_eq!(
            match_joints(&reference, &names(&["foot", "hip"])).unwrap(),
            vec![2, 0]
        );
        assert!(matches!(
            match_joints(&reference, &names(&["hip", "tail"])),
            Err(EvalError::UnknownJoint { joint: 1, .. })
        ));
    }
}

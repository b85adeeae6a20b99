//! Fitting a candidate stored in other units or axes onto the reference: tools disagree on
//! both (an FBX in centimetres read in metres against another tool's glb in the file's
//! centimetres; Blender's +Z up against glTF's +Y up). A fit is a uniform scale, one of the
//! quarter turns between Y-up and Z-up, and a translation,
//!
//! `p_reference = s · R · p_candidate + t`,
//!
//! found from the bounding boxes of the meshes, or of the joints the skeletons pair by name
//! (when one file holds extra geometry), and kept when it pairs more vertices than the
//! positions as stored do ([`crate::evaluate`] tries it when fewer than half pair as
//! stored).

use crate::matching::{self, UNMATCHED};
use glam::{DMat3, DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// The turn `R` of a [`Fit`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxisTurn {
    /// The same axes.
    None,
    /// The candidate is Z-up, the reference Y-up: `(x, y, z) → (x, z, −y)`, a quarter
    /// turn about X (Blender's and 3ds Max's axes against glTF's).
    ZUpToYUp,
    /// The candidate is Y-up, the reference Z-up: `(x, y, z) → (x, −z, y)`.
    YUpToZUp,
}

impl AxisTurn {
    /// Every turn tried, the same axes first.
    pub const ALL: [AxisTurn; 3] = [AxisTurn::None, AxisTurn::ZUpToYUp, AxisTurn::YUpToZUp];

    /// The turn as a matrix acting on column vectors.
    pub fn matrix(self) -> DMat3 {
        match self {
            AxisTurn::None => DMat3::IDENTITY,
            AxisTurn::ZUpToYUp => DMat3::from_cols(DVec3::X, DVec3::NEG_Z, DVec3::Y),
            AxisTurn::YUpToZUp => DMat3::from_cols(DVec3::X, DVec3::Z, DVec3::NEG_Y),
        }
    }

    /// How the text summary says it.
    pub fn describe(self) -> &'static str {
        match self {
            AxisTurn::None => "axes kept",
            AxisTurn::ZUpToYUp => "Z-up turned to Y-up, (x, y, z) -> (x, z, -y)",
            AxisTurn::YUpToZUp => "Y-up turned to Z-up, (x, y, z) -> (x, -z, y)",
        }
    }
}

/// What a [`Fit`] was found from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitSource {
    /// The bounding boxes of the two meshes.
    BoundingBoxes,
    /// The bounding boxes of the joints the skeletons pair by name.
    Skeletons,
}

/// A similarity from the candidate's space to the reference's:
/// `p_reference = scale · turn · p_candidate + translation`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    pub scale: f64,
    pub turn: AxisTurn,
    pub translation: [f64; 3],
    pub from: FitSource,
}

impl Fit {
    /// `p` in the reference's space.
    pub fn apply(&self, p: Vec3) -> Vec3 {
        (self.scale * (self.turn.matrix() * p.as_dvec3()) + DVec3::from(self.translation)).as_vec3()
    }

    /// The fit that maps the box of `candidate` (turned by `turn`) onto the box of
    /// `reference`: `s = |diag(B_ref)| / |diag(R · B_cand)|` (a turn keeps the diagonal),
    /// `t = centre(B_ref) − s · centre(R · B_cand)`. `None` for an empty or flat box.
    fn of_boxes(
        reference: &[Vec3],
        candidate: &[Vec3],
        turn: AxisTurn,
        from: FitSource,
    ) -> Option<Fit> {
        let (reference_low, reference_high) = bounds(reference.iter().map(|p| p.as_dvec3()))?;
        let r = turn.matrix();
        let (low, high) = bounds(candidate.iter().map(|p| r * p.as_dvec3()))?;
        let scale = (reference_high - reference_low).length() / (high - low).length();
        if !(scale.is_finite() && scale > 0.0) {
            return None;
        }
        let translation = 0.5 * (reference_low + reference_high) - scale * 0.5 * (low + high);
        Some(Fit {
            scale,
            turn,
            translation: translation.to_array(),
            from,
        })
    }
}

/// Lowest and highest corners of `points`; `None` when there are none.
fn bounds(points: impl Iterator<Item = DVec3>) -> Option<(DVec3, DVec3)> {
    points.fold(None, |acc, p| match acc {
        None => Some((p, p)),
        Some((low, high)) => Some((low.min(p), high.max(p))),
    })
}

/// One side of a fit: a mesh's positions and the bind positions of its joints that the
/// other side's skeleton names alike (in the same order on both sides).
#[derive(Debug, Clone, Copy)]
pub struct Side<'a> {
    pub positions: &'a [Vec3],
    pub named_joints: &'a [Vec3],
}

/// The fit that pairs the most `reference` vertices with a candidate vertex within
/// `tolerance`, with its pairs ([`matching::match_vertices`] of the fitted candidate), or
/// `None` when no fit pairs any. Tried: each [`AxisTurn`] from the meshes' boxes, then
/// from the named joints' boxes; ties go to the first tried.
pub fn best_fit(reference: Side, candidate: Side, tolerance: f64) -> Option<(Fit, Vec<u32>)> {
    let sources = [
        (
            FitSource::BoundingBoxes,
            reference.positions,
            candidate.positions,
        ),
        (
            FitSource::Skeletons,
            reference.named_joints,
            candidate.named_joints,
        ),
    ];
    let mut best: Option<(Fit, Vec<u32>, usize)> = None;
    for (from, reference_points, candidate_points) in sources {
        for turn in AxisTurn::ALL {
            let Some(fit) = Fit::of_boxes(reference_points, candidate_points, turn, from) else {
                continue;
            };
            let fitted: Vec<Vec3> = candidate.positions.iter().map(|&p| fit.apply(p)).collect();
            let paired = matching::match_vertices(reference.positions, &fitted, tolerance);
            let count = paired.iter().filter(|&&c| c != UNMATCHED).count();
            if count > best.as_ref().map_or(0, |b| b.2) {
                best = Some((fit, paired, count));
            }
        }
    }
    best.map(|(fit, paired, _)| (fit, paired))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An asymmetric cloud (no turn maps it onto itself) and its joints.
    fn cloud() -> (Vec<Vec3>, Vec<Vec3>) {
        let positions = (0..60)
            .map(|i| {
                let t = i as f32;
                Vec3::new(
                    (t * 0.37).sin() * 0.3,
                    t * 0.03,
                    (t * 0.71).cos() * 0.1 + 0.02 * t,
                )
            })
            .collect();
        let joints = vec![
            Vec3::new(0.0, 0.1, 0.05),
            Vec3::new(0.1, 1.0, 0.3),
            Vec3::new(-0.2, 1.5, 0.9),
        ];
        (positions, joints)
    }

    /// The inverse of a fit: a candidate in centimetres, Z-up, moved.
    fn to_candidate(p: Vec3) -> Vec3 {
        let z_up = DVec3::new(f64::from(p.x), -f64::from(p.z), f64::from(p.y));
        (100.0 * z_up + DVec3::new(3.0, -40.0, 7.5)).as_vec3()
    }

    #[test]
    fn turns_are_rotations_with_their_inverses() {
        for turn in AxisTurn::ALL {
            let m = turn.matrix();
            assert!((m.determinant() - 1.0).abs() < 1e-12, "{turn:?}");
            assert!((m * m.transpose()).abs_diff_eq(DMat3::IDENTITY, 1e-12));
        }
        let there = AxisTurn::ZUpToYUp.matrix() * AxisTurn::YUpToZUp.matrix();
        assert!(there.abs_diff_eq(DMat3::IDENTITY, 1e-12));
        // A Z-up point (up is +z) comes out Y-up.
        assert_eq!(AxisTurn::ZUpToYUp.matrix() * DVec3::Z, DVec3::Y);
    }

    /// A copy in centimetres, Z-up and moved is fitted back from the meshes' boxes, every
    /// vertex paired; with extra geometry in the candidate (the boxes differ), from the
    /// skeletons' joints.
    #[test]
    fn scale_turn_and_translation_are_found_from_boxes_then_skeletons() {
        let (positions, joints) = cloud();
        let moved: Vec<Vec3> = positions.iter().map(|&p| to_candidate(p)).collect();
        let moved_joints: Vec<Vec3> = joints.iter().map(|&p| to_candidate(p)).collect();
        let reference = Side {
            positions: &positions,
            named_joints: &joints,
        };
        let tolerance = 1e-5;
        let all: Vec<u32> = (0..positions.len() as u32).collect();

        let candidate = Side {
            positions: &moved,
            named_joints: &moved_joints,
        };
        let (fit, paired) = best_fit(reference, candidate, tolerance).unwrap();
        assert_eq!(
            (fit.turn, fit.from),
            (AxisTurn::ZUpToYUp, FitSource::BoundingBoxes)
        );
        assert!((fit.scale - 0.01).abs() < 1e-9, "{fit:?}");
        assert_eq!(paired, all);

        let mut extra = moved.clone();
        extra.extend([Vec3::new(900.0, 0.0, 0.0), Vec3::new(-300.0, 50.0, 0.0)]);
        let candidate = Side {
            positions: &extra,
            named_joints: &moved_joints,
        };
        let (fit, paired) = best_fit(reference, candidate, tolerance).unwrap();
        assert_eq!(
            (fit.turn, fit.from),
            (AxisTurn::ZUpToYUp, FitSource::Skeletons)
        );
        assert_eq!(paired, all);

        // Another shape: nothing pairs.
        let other: Vec<Vec3> = positions
            .iter()
            .map(|p| Vec3::new(p.y, p.x * 3.0, -p.z))
            .collect();
        let candidate = Side {
            positions: &other,
            named_joints: &[],
        };
        assert!(best_fit(reference, candidate, tolerance).is_none());
    }
}

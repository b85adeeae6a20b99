//! Closest point matching (Abdrashitov et al. 2023, §3.1): for a target vertex p with unit
//! normal n_p, the nearest point q = u a + v b + w c of the source surface (face abc,
//! barycentric (u, v, w)), its interpolated normal n_q = normalize(u n_a + v n_b + w n_c)
//! and weights w(q) = u w(a) + v w(b) + w w(c). The vertex is *matched* when
//!
//!   |p − q| ≤ d  and  ∠(n_p, n_q) ≤ θ,
//!
//! d and θ the thresholds of [`super::TransferParams`]; with flipped normals accepted,
//! also when ∠(n_p, −n_q) ≤ θ (a single-sided garment may be wound either way). A matched
//! vertex takes w(q); the others are inpainted ([`super::inpaint`]).
//!
//! The nearest point comes from the project's face hierarchy
//! ([`FaceSpheres::nearest_point`], itself tested against a scan of every face).

use super::TransferError;
use crate::mesh::weld::DEFAULT_WELD_TOLERANCE;
use crate::mesh::{weld, FaceSpheres, NearestPoint, SurfaceMesh};
use atlas_skin_runtime::VertexWeights;
use glam::{DVec3, Vec3};

/// The skinned surface weights are taken from: welded (seams joined), with its face
/// hierarchy, unit vertex normals and the weights of every welded vertex.
#[derive(Debug, Clone)]
pub struct TransferSource {
    pub mesh: SurfaceMesh,
    spheres: FaceSpheres,
    normals: Vec<DVec3>,
    /// Per welded vertex: `(joint, weight)`, ascending joints, summing to 1 (or empty).
    weights: Vec<Vec<(u32, f64)>>,
    /// Number of joints of the skin.
    pub joint_count: usize,
}

/// The nearest source point of a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    pub point: NearestPoint,
    /// The interpolated unit normal there (zero when it vanishes).
    pub normal: DVec3,
}

impl TransferSource {
    /// The source of stored `positions` and `triangles` with `weights` (one row per stored
    /// vertex, joints below `joint_count`). Each welded vertex takes the row of its first
    /// stored vertex (the stored copies of a seam vertex carry one row), normalised.
    ///
    /// # Errors
    /// [`TransferError::EmptySource`] without triangles, [`TransferError::SourceWeights`]
    /// when the rows do not match the vertices or no vertex has a weight.
    pub fn new(
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        weights: &VertexWeights,
        joint_count: usize,
    ) -> Result<Self, TransferError> {
        if triangles.is_empty() {
            return Err(TransferError::EmptySource);
        }
        if weights.vertex_count() != positions.len() {
            return Err(TransferError::SourceWeights(format!(
                "{} weight rows for {} vertices",
                weights.vertex_count(),
                positions.len()
            )));
        }
        weights
            .validate(joint_count)
            .map_err(|e| TransferError::SourceWeights(e.to_string()))?;
        let welded = weld(positions, triangles, DEFAULT_WELD_TOLERANCE);
        let rows: Vec<Vec<(u32, f64)>> = welded
            .stored_of_welded
            .iter()
            .map(|&s| {
                let mut row: Vec<(u32, f64)> = weights
                    .row(s as usize)
                    .filter(|&(_, w)| w > 0.0)
                    .map(|(j, w)| (j, f64::from(w)))
                    .collect();
                row.sort_unstable_by_key(|&(j, _)| j);
                normalise(&mut row);
                row
            })
            .collect();
        if rows.iter().all(Vec::is_empty) {
            return Err(TransferError::SourceWeights(
                "no vertex has a weight: skin it first (atlas-skin skin)".into(),
            ));
        }
        Ok(Self {
            spheres: FaceSpheres::new(&welded.mesh),
            normals: welded.mesh.vertex_normals(),
            weights: rows,
            mesh: welded.mesh,
            joint_count,
        })
    }

    /// Diagonal of the source's bounding box.
    pub fn diagonal(&self) -> f64 {
        self.mesh.diagonal()
    }

    /// The nearest source point to `p`, the search started from face `hint` when given
    /// (the same result, [`FaceSpheres::nearest_point_from`]).
    pub fn closest(&self, p: DVec3, hint: Option<u32>) -> Closest {
        let point = self
            .spheres
            .nearest_point_from(&self.mesh, p, hint)
            .expect("the source has faces");
        let [a, b, c] = self.mesh.triangles[point.face as usize];
        let [u, v, w] = point.barycentric;
        let normal = (self.normals[a as usize] * u
            + self.normals[b as usize] * v
            + self.normals[c as usize] * w)
            .normalize_or_zero();
        Closest { point, normal }
    }

    /// w(q) = u w(a) + v w(b) + w w(c) at `closest`, ascending joints, normalised (empty
    /// when the three corners have no weight).
    pub fn weights_at(&self, closest: &Closest, out: &mut Vec<(u32, f64)>) {
        out.clear();
        let corners = self.mesh.triangles[closest.point.face as usize];
        for (&v, &b) in corners.iter().zip(&closest.point.barycentric) {
            out.extend(self.weights[v as usize].iter().map(|&(j, w)| (j, w * b)));
        }
        merge_joints(out);
        normalise(out);
    }
}

/// Whether a target vertex with unit normal `normal` matches `closest` (the module's rule):
/// `max_distance` d, `min_cos` cos θ.
pub fn matches(
    closest: &Closest,
    normal: DVec3,
    max_distance: f64,
    min_cos: f64,
    flipped: bool,
) -> bool {
    if closest.point.distance > max_distance
        || normal == DVec3::ZERO
        || closest.normal == DVec3::ZERO
    {
        return false;
    }
    let cos = normal.dot(closest.normal);
    cos >= min_cos || (flipped && -cos >= min_cos)
}

/// Sorts `row` by joint and sums the entries of one joint.
pub(crate) fn merge_joints(row: &mut Vec<(u32, f64)>) {
    row.sort_unstable_by_key(|&(j, _)| j);
    row.dedup_by(|next, kept| {
        if next.0 == kept.0 {
            kept.1 += next.1;
            true
        } else {
            false
        }
    });
}

/// Drops non-positive entries and scales the rest to sum to 1 (empty when none is left).
pub(crate) fn normalise(row: &mut Vec<(u32, f64)>) {
    row.retain(|&(_, w)| w > 0.0 && w.is_finite());
    let total: f64 = row.iter().map(|&(_, w)| w).sum();
    if total > 0.0 {
        for (_, w) in row.iter_mut() {
            *w /= total;
        }
    } else {
        row.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in z = 0, two faces, joint 0 on the left edge and 1 on the right.
    fn square() -> TransferSource {
        let positions = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let weights = VertexWeights::from_rows([
            vec![(0, 1.0)],
            vec![(1, 1.0)],
            vec![(1, 1.0)],
            vec![(0, 1.0)],
        ]);
        TransferSource::new(&positions, &[[0, 1, 2], [0, 2, 3]], &weights, 2).unwrap()
    }

    /// Weights are interpolated linearly across the face: at x = 0.25, 3/4 on joint 0.
    #[test]
    fn weights_are_interpolated_at_the_closest_point() {
        let source = square();
        let closest = source.closest(DVec3::new(0.25, 0.5, 0.1), None);
        assert!((closest.point.distance - 0.1).abs() < 1e-12);
        let mut row = Vec::new();
        source.weights_at(&closest, &mut row);
        assert_eq!(row.len(), 2);
        assert!((row[0].1 - 0.75).abs() < 1e-12 && (row[1].1 - 0.25).abs() < 1e-12);
        assert!((closest.normal - DVec3::Z).length() < 1e-12);
    }

    /// Distance and angle decide; a flipped normal matches only when flips are accepted.
    #[test]
    fn distance_and_angle_thresholds_decide_a_match() {
        let source = square();
        let closest = source.closest(DVec3::new(0.5, 0.5, 0.1), None);
        let cos30 = 30f64.to_radians().cos();
        assert!(matches(&closest, DVec3::Z, 0.2, cos30, false));
        assert!(!matches(&closest, DVec3::Z, 0.05, cos30, false));
        assert!(!matches(&closest, DVec3::X, 0.2, cos30, true));
        let tilted = DVec3::new(0.0, 40f64.to_radians().sin(), 40f64.to_radians().cos());
        assert!(!matches(&closest, tilted, 0.2, cos30, false));
        assert!(!matches(&closest, -DVec3::Z, 0.2, cos30, false));
        assert!(matches(&closest, -DVec3::Z, 0.2, cos30, true));
    }

    /// A source whose rows are all empty is refused; so are rows that do not match.
    #[test]
    fn a_source_without_weights_is_refused() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let empty = VertexWeights::from_rows([vec![], vec![], vec![]]);
        assert!(matches!(
            TransferSource::new(&positions, &[[0, 1, 2]], &empty, 1),
            Err(TransferError::SourceWeights(_))
        ));
        let short = VertexWeights::from_rows([vec![(0, 1.0)]]);
        assert!(matches!(
            TransferSource::new(&positions, &[[0, 1, 2]], &short, 1),
            Err(TransferError::SourceWeights(_))
        ));
        assert!(matches!(
            TransferSource::new(&positions, &[], &short, 1),
            Err(TransferError::EmptySource)
        ));
    }
}

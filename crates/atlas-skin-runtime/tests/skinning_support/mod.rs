//! Shared helpers of the skinning tests (also included by the CLI's `pose_corpus`):
//! distances between point sets.

use glam::Vec3;

/// The length of the diagonal of the bounding box of `points`.
pub fn diagonal(points: &[Vec3]) -> f32 {
    let (lo, hi) = points.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| {
        (lo.min(*p), hi.max(*p))
    });
    (hi - lo).length()
}

/// The largest distance between corresponding points of `a` and `b`.
pub fn max_distance(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.distance(*y))
        .fold(0.0, f32::max)
}

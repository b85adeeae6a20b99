//! Distances and extents of geometric primitives, shared by every stage.

use crate::tolerance::NORMAL_UNDERFLOW;
use glam::DVec3;

/// Parameter t ∈ [0, 1] of the point of segment `[a, b]` nearest to `p`:
/// t = clamp((p − a)·(b − a) / |b − a|², 0, 1), 0 for a point segment.
pub fn segment_parameter(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Distance from `p` to the segment `[a, b]`: |p − (a + t(b − a))| with t from
/// [`segment_parameter`].
pub fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    p.distance(a + (b - a) * segment_parameter(p, a, b))
}

/// Distance from `p` to triangle abc: |p − q| with q its nearest point
/// ([`closest_point_on_triangle`]).
pub fn point_triangle_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let [u, v, w] = closest_point_on_triangle(p, a, b, c);
    p.distance(a * u + b * v + c * w)
}

/// Barycentric coordinates (u, v, w), u + v + w = 1, all ≥ 0, of the point q = u a + v b + w c
/// of triangle abc nearest to `p` (Ericson, Real-Time Collision Detection §5.1.5, by
/// Voronoi regions); a degenerate triangle falls back to the nearest point of its edges.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> [f64; 3] {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let normal = ab.cross(ac);
    if normal.length_squared() <= NORMAL_UNDERFLOW {
        return closest_point_on_edges(p, a, b, c);
    }
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let t = d1 / (d1 - d3);
        return [1.0 - t, t, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / (d2 - d6);
        return [1.0 - t, 0.0, t];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - t, t];
    }
    let total = va + vb + vc;
    let (v, w) = (vb / total, vc / total);
    [1.0 - v - w, v, w]
}

/// The nearest point of the three edges of abc, as barycentric coordinates.
fn closest_point_on_edges(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> [f64; 3] {
    let candidates = [(a, b, [0usize, 1usize]), (b, c, [1, 2]), (c, a, [2, 0])];
    let (x, y, [i, k]) = candidates
        .into_iter()
        .min_by(|s, t| {
            point_segment_distance(p, s.0, s.1).total_cmp(&point_segment_distance(p, t.0, t.1))
        })
        .unwrap_or(candidates[0]);
    let t = segment_parameter(p, x, y);
    let mut bary = [0.0; 3];
    bary[i] += 1.0 - t;
    bary[k] += t;
    bary
}

/// Axis-aligned bounding box of points, `(0, 0)` when there are none.
pub fn bounding_box<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> (DVec3, DVec3) {
    let (lo, hi) = points.into_iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    if lo.x > hi.x {
        return (DVec3::ZERO, DVec3::ZERO);
    }
    (lo, hi)
}

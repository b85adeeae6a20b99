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

/// Distance from `p` to triangle abc (Ericson, Real-Time Collision Detection §5.1.5, by
/// Voronoi regions); degenerate triangles fall back to their edges.
pub fn point_triangle_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let normal = ab.cross(ac);
    if normal.length_squared() <= NORMAL_UNDERFLOW {
        return point_segment_distance(p, a, b)
            .min(point_segment_distance(p, b, c))
            .min(point_segment_distance(p, c, a));
    }
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(a);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p.distance(a + ab * (d1 / (d1 - d3)));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p.distance(a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return p.distance(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    (ap.dot(normal)).abs() / normal.length()
}

/// Axis-aligned bounding box of points, `(0, 0)` when there are none.
pub fn bounding_box(points: &[DVec3]) -> (DVec3, DVec3) {
    if points.is_empty() {
        return (DVec3::ZERO, DVec3::ZERO);
    }
    points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

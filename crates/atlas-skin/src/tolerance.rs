//! The method's numerical tolerances, one per purpose, each relative to the scale it
//! names, so that results do not depend on the model's units.

/// A triangle is degenerate (flat) when its area is at most this fraction of a squared
/// length of its own scale: the squared mesh diagonal for the mesh statistics, the longest
/// squared edge of a polygon for the split's fans. Also the bound on sin²θ under which two
/// edge vectors are parallel in the fast-marching update: |a|²|b|² − (a·b)² ≤ ε |a|²|b|².
pub const FLAT: f64 = 1e-12;

/// A ray is parallel to a triangle's plane when Möller–Trumbore's determinant is at most
/// this fraction of the triangle's longest squared edge (ray directions are unit).
pub const RAY_PARALLEL: f64 = 1e-14;

/// A length (a bone) or a volume is zero when it is at most this fraction of the
/// skeleton's or the mesh's diagonal (cubed for a volume).
pub const NEGLIGIBLE: f64 = 1e-9;

/// Squared normal length under which a triangle's plane is undefined: only a guard
/// against dividing by zero (nearly flat triangles are measured by their edges).
pub const NORMAL_UNDERFLOW: f64 = 1e-300;

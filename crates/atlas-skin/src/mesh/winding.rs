//! Generalized winding number (Jacobson, Kavan, Sorkine-Hornung 2013): which points are
//! inside a surface, robust to small holes.

use super::surface::SurfaceMesh;
use glam::DVec3;

/// w(p) = Σ_f Ω_f(p) / 4π, with Ω_f the signed solid angle of triangle f seen from p
/// (Van Oosterom & Strackee 1983):
/// tan(Ω/2) = a·(b×c) / (|a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b|), a, b, c = corners − p.
///
/// w ≈ 1 inside a closed outward-oriented surface, 0 outside, fractional near holes.
/// Cost O(F) per point.
pub fn winding_number(mesh: &SurfaceMesh, p: DVec3) -> f64 {
    faces_winding_number(&mesh.positions, &mesh.triangles, p)
}

/// [`winding_number`] of the surface made of `triangles` over `positions` (a part of a
/// mesh, without copying its points).
pub fn faces_winding_number(positions: &[DVec3], triangles: &[[u32; 3]], p: DVec3) -> f64 {
    let mut total = 0.0;
    for t in triangles {
        let a = positions[t[0] as usize] - p;
        let b = positions[t[1] as usize] - p;
        let c = positions[t[2] as usize] - p;
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * std::f64::consts::PI)
}

/// True when `p` is inside: |w(p)| > 0.5 (the sign depends on the surface's orientation).
pub fn is_inside(mesh: &SurfaceMesh, p: DVec3) -> bool {
    winding_number(mesh, p).abs() > 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetrahedron_inside_and_outside() {
        let mesh = SurfaceMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        };
        let w = winding_number(&mesh, DVec3::splat(0.1));
        assert!((w - 1.0).abs() < 1e-9, "{w}");
        assert!(winding_number(&mesh, DVec3::splat(2.0)).abs() < 1e-9);
        assert!(is_inside(&mesh, DVec3::splat(0.2)));
    }
}

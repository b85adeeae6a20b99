//! Generalized winding number (Jacobson, Kavan, Sorkine-Hornung 2013): which points are
//! inside a surface, robust to small holes.

use super::surface::SurfaceMesh;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

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
        let (numerator, denominator) = half_solid_angle_terms(positions, t, p);
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * PI)
}

/// a·(b×c) and |a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b| of triangle `t` seen from `p`
/// (tan(Ω/2) is their ratio, [`winding_number`]).
#[inline(always)]
fn half_solid_angle_terms(positions: &[DVec3], t: &[u32; 3], p: DVec3) -> (f64, f64) {
    let a = positions[t[0] as usize] - p;
    let b = positions[t[1] as usize] - p;
    let c = positions[t[2] as usize] - p;
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    (numerator, denominator)
}

/// |[`faces_winding_number`]| > ½: whether `p` is inside the surface of `triangles`, the
/// same answer for about three quarters of the work. The sum is first taken with each arc
/// tangent from a polynomial (Abramowitz & Stegun 4.4.49, within ε = 10⁻⁷ of the
/// library's `atan2`): with n faces, u = 2⁻⁵³ and γ_n = nu / (1 − nu), the two sums of n
/// terms of at most 2π, taken in the same order, differ by at most 2nε + 2 · 2πn γ_n (the
/// terms' differences plus each sum's rounding, Higham 2002 §4.2), so w and the
/// approximate w̃ differ by at most m = (2nε + 4πn γ_n) / 4π (and the rounding of one
/// division). When ||w̃| − ½| > m the answer is |w̃| > ½; otherwise (and when a term's
/// ratio is 0/0, infinite or NaN, where `atan2` depends on signed zeros)
/// [`faces_winding_number`] decides.
pub fn faces_inside(positions: &[DVec3], triangles: &[[u32; 3]], p: DVec3) -> bool {
    let exact = || faces_winding_number(positions, triangles, p).abs() > 0.5;
    let n = triangles.len() as f64;
    let nu = n * f64::EPSILON / 2.0;
    if nu >= 0.5 {
        return exact();
    }
    let mut total = 0.0;
    let mut bounded = true;
    for t in triangles {
        let (numerator, denominator) = half_solid_angle_terms(positions, t, p);
        let largest = numerator.abs().max(denominator.abs());
        bounded &= largest > 0.0 && largest < f64::INFINITY;
        total += 2.0 * atan2_approx(numerator, denominator);
    }
    let w = (total / (4.0 * PI)).abs();
    let gamma = nu / (1.0 - nu);
    let margin = (2.0 * n * ATAN_ERROR + 4.0 * PI * n * gamma) / (4.0 * PI) * (1.0 + 1e-6) + 1e-12;
    if bounded && (w - 0.5).abs() > margin {
        w > 0.5
    } else {
        exact()
    }
}

/// A bound on |[`atan2_approx`] − `atan2`|: the polynomial's 2·10⁻⁸ on [0, 1] (A&S
/// 4.4.49), the rounding of the ratio and of the quadrant's π/2 − r and π − r (a few
/// units of 10⁻¹⁶), and the library's error (one unit in the last place), with room.
const ATAN_ERROR: f64 = 1e-7;

/// atan(x) for 0 ≤ x ≤ 1: x (1 + a₂x² + a₄x⁴ + … + a₁₆x¹⁶), |error| ≤ 2·10⁻⁸
/// (Abramowitz & Stegun 1964, Handbook of Mathematical Functions, 4.4.49).
fn atan_unit(x: f64) -> f64 {
    const A: [f64; 8] = [
        -0.333_331_452_8,
        0.199_935_508_5,
        -0.142_088_994_4,
        0.106_562_639_3,
        -0.075_289_640_0,
        0.042_909_613_8,
        -0.016_165_736_7,
        0.002_866_225_7,
    ];
    let x2 = x * x;
    let series = A.iter().rev().fold(0.0, |acc, &a| acc * x2 + a);
    x * (1.0 + x2 * series)
}

/// atan2(y, x) within [`ATAN_ERROR`] for finite (x, y) ≠ (0, 0): the ratio of the smaller
/// to the larger |coordinate| in [0, 1], [`atan_unit`] of it, then the octant.
fn atan2_approx(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let r = atan_unit(ax.min(ay) / ax.max(ay));
    let r = if ay > ax { FRAC_PI_2 - r } else { r };
    let r = if x < 0.0 { PI - r } else { r };
    r.copysign(y)
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

    /// The polynomial arc tangent keeps within its bound of the library's, on a dense grid
    /// of [0, 1] and around the circle.
    #[test]
    fn the_polynomial_arc_tangent_keeps_its_bound() {
        let worst_unit = (0..=1_000_000)
            .map(|k| k as f64 / 1e6)
            .map(|x| (atan_unit(x) - x.atan()).abs())
            .fold(0.0, f64::max);
        assert!(worst_unit <= 2e-8, "{worst_unit}");
        let worst_circle = (0..100_000)
            .map(|k| std::f64::consts::TAU * k as f64 / 1e5)
            .flat_map(|angle| [0.5, 3.0, 1e-9].map(|r| (r * angle.sin(), r * angle.cos())))
            .map(|(y, x)| (atan2_approx(y, x) - y.atan2(x)).abs())
            .fold(0.0, f64::max);
        assert!(worst_circle <= ATAN_ERROR, "{worst_circle}");
        for (y, x) in [
            (0.0, 1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.0, -1.0),
            (-0.0, -1.0),
        ] {
            assert!(
                (atan2_approx(y, x) - f64::atan2(y, x)).abs() <= ATAN_ERROR,
                "{y} {x}"
            );
        }
    }

    /// The same answers as |w| > ½ of the exact sum: points in, out of and on a closed
    /// sphere, around an open cap of it (where w passes through ½), and at its vertices.
    #[test]
    fn inside_answers_as_the_exact_winding_number() {
        let sphere = crate::fixtures::shapes::icosphere(1.0, 3);
        let cap = crate::fixtures::shapes::faces_above(&sphere, 0.0);
        let mut rng = atlas_skin_runtime::random_pose::SplitMix64::new(5);
        let mut next = || rng.next_f64() * 3.0 - 1.5;
        let mut points: Vec<DVec3> = (0..3000)
            .map(|_| DVec3::new(next(), next(), next()))
            .collect();
        points.extend(&sphere.positions);
        points.extend(sphere.positions.iter().map(|&v| v * 0.999));
        let (mut inside, mut near_half) = (0, 0);
        for faces in [&sphere.triangles, &cap] {
            for &p in &points {
                let w = faces_winding_number(&sphere.positions, faces, p);
                assert_eq!(
                    faces_inside(&sphere.positions, faces, p),
                    w.abs() > 0.5,
                    "{p}"
                );
                inside += usize::from(w.abs() > 0.5);
                near_half += usize::from((w.abs() - 0.5).abs() < 0.05);
            }
        }
        assert!(inside > 500 && near_half > 10, "{inside} {near_half}");
    }
}

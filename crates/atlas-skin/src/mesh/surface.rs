//! The surface the algorithms work on.

use crate::geometry::bounding_box;
use glam::DVec3;

/// A triangle surface in double precision, after welding.
///
/// - `positions`: #V vertex positions.
/// - `triangles`: #F vertex index triples, all in range; a triangle may be degenerate
///   (repeated index or zero area) when the input had such faces.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceMesh {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl SurfaceMesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Axis-aligned bounding box `(min, max)`; `(0, 0)` for an empty mesh.
    pub fn bounding_box(&self) -> (DVec3, DVec3) {
        bounding_box(&self.positions)
    }

    /// Length of the bounding box diagonal.
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        (hi - lo).length()
    }

    /// The three corner positions of triangle `f`.
    #[inline]
    pub fn corners(&self, f: usize) -> [DVec3; 3] {
        // Indexed one by one: `array::map` was not inlined (a call and copies per face).
        let [a, b, c] = self.triangles[f];
        let at = |v: u32| self.positions[v as usize];
        [at(a), at(b), at(c)]
    }

    /// Area-weighted normal of triangle `f`: `(b − a) × (c − a)`, of length twice its area.
    pub fn scaled_normal(&self, f: usize) -> DVec3 {
        let [a, b, c] = self.corners(f);
        (b - a).cross(c - a)
    }

    /// Signed enclosed volume V = Σ_f a·(b × c) / 6 over the triangles' corners a, b, c:
    /// positive for a closed outward-oriented surface (divergence theorem).
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.positions[v as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Unit vertex normals n_v = normalize(Σ_{f ∋ v} (b − a) × (c − a)), the area-weighted
    /// mean of the normals of the faces around v; zero where that sum vanishes (a vertex
    /// no face uses, or only faces of zero area).
    pub fn vertex_normals(&self) -> Vec<DVec3> {
        let mut sums = vec![DVec3::ZERO; self.vertex_count()];
        for (f, t) in self.triangles.iter().enumerate() {
            let n = self.scaled_normal(f);
            for &v in t {
                sums[v as usize] += n;
            }
        }
        sums.into_iter().map(DVec3::normalize_or_zero).collect()
    }

    /// Area of triangle `f`.
    pub fn triangle_area(&self, f: usize) -> f64 {
        0.5 * self.scaled_normal(f).length()
    }
}

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

    /// Centre of the bounding box: the point [`Self::signed_volume`] is taken about.
    pub fn centre(&self) -> DVec3 {
        let (lo, hi) = self.bounding_box();
        0.5 * (lo + hi)
    }

    /// Signed volume V = Σ_f (a − o)·((b − o) × (c − o)) / 6 over the triangles' corners
    /// a, b, c, about the bounding box's centre o: the enclosed volume, positive, for a
    /// closed outward-oriented surface (divergence theorem), whatever o. On an open
    /// surface (a character of separate open pieces, a garment) the sum depends on o, the
    /// apex of the cones it adds up: taken about the origin, the same file moved by two of
    /// its diagonals could change sign and read as inside out; taken about its own centre
    /// it moves with the mesh and is positive when most of the surface faces away from its
    /// middle.
    pub fn signed_volume(&self) -> f64 {
        let o = self.centre();
        self.triangles
            .iter()
            .map(|t| cone_volume(t.map(|v| self.positions[v as usize]), o))
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

/// Signed volume of the tetrahedron from apex `o` over triangle `[a, b, c]`:
/// (a − o)·((b − o) × (c − o)) / 6.
pub fn cone_volume([a, b, c]: [DVec3; 3], o: DVec3) -> f64 {
    (a - o).dot((b - o).cross(c - o)) / 6.0
}

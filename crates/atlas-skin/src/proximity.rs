//! Point and ray queries against a surface, pruned by per-face bounding spheres: nearest
//! surface distance, faces near a point, first hit along a ray.
//!
//! Point queries visit a uniform grid of the sphere centres (about four faces per cell),
//! ray queries scan the spheres linearly; the exact test runs only on faces whose sphere
//! passes. The decomposition asks them once per joint, never once per candidate plane.

use crate::SurfaceMesh;
use glam::{DVec3, IVec3};

/// A bounding sphere per face (centre = centroid, radius = farthest corner from it), and
/// a grid of the centres.
#[derive(Debug, Clone, Default)]
pub struct FaceSpheres {
    pub centres: Vec<DVec3>,
    pub radii: Vec<f64>,
    /// Largest radius.
    max_radius: f64,
    grid: CentreGrid,
}

/// Cells of side `cell` from `origin`, `dims` per axis; cell k's faces are
/// `faces[offsets[k]..offsets[k + 1]]` (compressed rows, x fastest).
#[derive(Debug, Clone, Default)]
struct CentreGrid {
    origin: DVec3,
    cell: f64,
    dims: IVec3,
    offsets: Vec<u32>,
    faces: Vec<u32>,
}

impl CentreGrid {
    fn new(centres: &[DVec3]) -> Self {
        let (lo, hi) = crate::mesh::bounding_box(centres);
        let extent = (hi - lo).max(DVec3::splat(1e-12));
        let target_cells = (centres.len() / 4).max(1) as f64;
        let volume = extent.x.max(extent.length() * 1e-3)
            * extent.y.max(extent.length() * 1e-3)
            * extent.z.max(extent.length() * 1e-3);
        let cell = (volume / target_cells)
            .cbrt()
            .max(extent.max_element() / 256.0);
        let dims = ((extent / cell).floor().as_ivec3() + IVec3::ONE).min(IVec3::splat(257));
        let mut grid = Self {
            origin: lo,
            cell,
            dims,
            offsets: vec![0; (dims.x * dims.y * dims.z) as usize + 1],
            faces: vec![0; centres.len()],
        };
        let cells: Vec<usize> = centres
            .iter()
            .map(|c| grid.index(grid.cell_of(*c)))
            .collect();
        for &k in &cells {
            grid.offsets[k + 1] += 1;
        }
        for k in 1..grid.offsets.len() {
            grid.offsets[k] += grid.offsets[k - 1];
        }
        let mut fill = grid.offsets.clone();
        for (f, &k) in cells.iter().enumerate() {
            grid.faces[fill[k] as usize] = f as u32;
            fill[k] += 1;
        }
        grid
    }

    fn cell_of(&self, p: DVec3) -> IVec3 {
        ((p - self.origin) / self.cell)
            .floor()
            .as_ivec3()
            .clamp(IVec3::ZERO, self.dims - IVec3::ONE)
    }

    fn index(&self, c: IVec3) -> usize {
        (c.x + self.dims.x * (c.y + self.dims.y * c.z)) as usize
    }

    fn contains(&self, p: DVec3) -> bool {
        let q = (p - self.origin) / self.cell;
        q.cmpge(DVec3::ZERO).all() && q.cmplt(self.dims.as_dvec3()).all()
    }

    /// Faces whose centre lies in a cell of the box `lo..=hi` of cell coordinates, except
    /// the cells of the box `skip_lo..=skip_hi` (pass an empty box to keep all).
    fn faces_in(
        &self,
        lo: IVec3,
        hi: IVec3,
        skip_lo: IVec3,
        skip_hi: IVec3,
    ) -> impl Iterator<Item = u32> + '_ {
        let (lo, hi) = (lo.max(IVec3::ZERO), hi.min(self.dims - IVec3::ONE));
        (lo.z..=hi.z).flat_map(move |z| {
            (lo.y..=hi.y).flat_map(move |y| {
                (lo.x..=hi.x)
                    .map(move |x| IVec3::new(x, y, z))
                    .filter(move |c| !(c.cmpge(skip_lo).all() && c.cmple(skip_hi).all()))
                    .flat_map(move |c| {
                        let k = self.index(c);
                        self.faces[self.offsets[k] as usize..self.offsets[k + 1] as usize]
                            .iter()
                            .copied()
                    })
            })
        })
    }
}

/// The first surface point a ray meets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    pub face: u32,
    /// Distance along the (unit) ray direction.
    pub distance: f64,
}

impl FaceSpheres {
    /// Spheres of every face of `mesh` and their grid, in O(F).
    pub fn new(mesh: &SurfaceMesh) -> Self {
        let (centres, radii): (Vec<DVec3>, Vec<f64>) = (0..mesh.triangle_count())
            .map(|f| {
                let corners = mesh.corners(f);
                let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
                let radius = corners
                    .iter()
                    .map(|c| c.distance(centre))
                    .fold(0.0, f64::max);
                (centre, radius)
            })
            .unzip();
        let max_radius = radii.iter().copied().fold(0.0, f64::max);
        let grid = CentreGrid::new(&centres);
        Self {
            centres,
            radii,
            max_radius,
            grid,
        }
    }

    /// Distance from `p` to the nearest point of the surface, `f64::INFINITY` without faces.
    ///
    /// Shells of cells around p's cell are visited outwards; |p − c_f| − r_f bounds the
    /// distance to face f from below, so a face is tested exactly only when that bound is
    /// below the best distance so far, and the search stops once every centre beyond the
    /// shell (at least shell · cell away) is too far. A point outside the grid scans all.
    pub fn nearest_distance(&self, mesh: &SurfaceMesh, p: DVec3) -> f64 {
        let mut best = f64::INFINITY;
        let test = |f: u32, best: &mut f64| {
            let f = f as usize;
            if self.centres[f].distance(p) - self.radii[f] < *best {
                let [a, b, c] = mesh.corners(f);
                *best = best.min(point_triangle_distance(p, a, b, c));
            }
        };
        if self.centres.is_empty() {
            return best;
        }
        if !self.grid.contains(p) {
            for f in 0..self.centres.len() as u32 {
                test(f, &mut best);
            }
            return best;
        }
        let centre = self.grid.cell_of(p);
        let rings = self.grid.dims.max_element();
        for ring in 0..=rings {
            let r = IVec3::splat(ring);
            // Only the shell: the inner cells were visited by the earlier rings.
            let inner = IVec3::splat(ring - 1);
            for f in self
                .grid
                .faces_in(centre - r, centre + r, centre - inner, centre + inner)
            {
                test(f, &mut best);
            }
            if best <= ring as f64 * self.grid.cell - self.max_radius {
                break;
            }
        }
        best
    }

    /// Faces whose sphere meets the ball of `radius` around `p` (a superset of the faces
    /// that meet the ball), in face order.
    pub fn faces_near(&self, p: DVec3, radius: f64) -> Vec<u32> {
        if self.centres.is_empty() {
            return Vec::new();
        }
        let reach = DVec3::splat(radius + self.max_radius);
        let mut faces: Vec<u32> = self
            .grid
            .faces_in(
                self.grid.cell_of(p - reach),
                self.grid.cell_of(p + reach),
                IVec3::ONE,
                IVec3::ZERO,
            )
            .filter(|&f| {
                let f = f as usize;
                self.centres[f].distance_squared(p) <= (radius + self.radii[f]).powi(2)
            })
            .collect();
        faces.sort_unstable();
        faces
    }

    /// First face hit by the ray `origin + t · direction`, t > 0, `direction` unit length
    /// (Möller–Trumbore 1997 on faces whose sphere the ray meets).
    pub fn first_hit(&self, mesh: &SurfaceMesh, origin: DVec3, direction: DVec3) -> Option<RayHit> {
        let mut best: Option<RayHit> = None;
        for (f, (c, r)) in self.centres.iter().zip(&self.radii).enumerate() {
            let to_centre = *c - origin;
            let along = to_centre.dot(direction);
            if along < -r || (to_centre - direction * along).length_squared() > r * r {
                continue;
            }
            let [a, b, c] = mesh.corners(f);
            if let Some(t) = ray_triangle(origin, direction, a, b, c) {
                if best.is_none_or(|h| t < h.distance) {
                    best = Some(RayHit {
                        face: f as u32,
                        distance: t,
                    });
                }
            }
        }
        best
    }
}

/// Möller–Trumbore: t > 0 with origin + t·direction in triangle abc, None when parallel.
fn ray_triangle(origin: DVec3, direction: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (ab, ac) = (b - a, c - a);
    let p = direction.cross(ac);
    let det = ab.dot(p);
    if det.abs() <= 1e-14 * ab.length_squared().max(ac.length_squared()) {
        return None;
    }
    let s = origin - a;
    let u = s.dot(p) / det;
    let q = s.cross(ab);
    let v = direction.dot(q) / det;
    let t = ac.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some(t)
}

/// Distance from `p` to triangle abc (Ericson, Real-Time Collision Detection §5.1.5, by
/// Voronoi regions); degenerate triangles fall back to their edges.
pub fn point_triangle_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let normal = ab.cross(ac);
    if normal.length_squared() <= 1e-300 {
        return segment_distance(p, a, b)
            .min(segment_distance(p, b, c))
            .min(segment_distance(p, c, a));
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

fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + ab * t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::icosphere;

    #[test]
    fn point_triangle_distance_in_every_voronoi_region() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let cases = [
            (DVec3::new(0.2, 0.2, 1.0), 1.0),
            (DVec3::new(-1.0, -1.0, 0.0), 2f64.sqrt()),
            (DVec3::new(2.0, 0.0, 0.0), 1.0),
            (DVec3::new(0.5, -1.0, 0.0), 1.0),
            (DVec3::new(1.0, 1.0, 0.0), 0.5f64.sqrt()),
            (DVec3::new(-2.0, 0.5, 0.0), 2.0),
        ];
        for (p, expected) in cases {
            let d = point_triangle_distance(p, a, b, c);
            assert!((d - expected).abs() < 1e-12, "{p}: {d} vs {expected}");
        }
        assert!((point_triangle_distance(DVec3::Z, a, a, b) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn sphere_queries_match_the_geometry() {
        let mesh = icosphere(1.0, 3);
        let spheres = FaceSpheres::new(&mesh);
        let inner = spheres.nearest_distance(&mesh, DVec3::new(0.0, 0.0, 0.3));
        assert!((inner - 0.7).abs() < 0.01, "{inner}");
        let hit = spheres
            .first_hit(&mesh, DVec3::ZERO, DVec3::X)
            .expect("a ray from the centre leaves the sphere");
        assert!((hit.distance - 1.0).abs() < 0.01);
        assert!(spheres.first_hit(&mesh, DVec3::X * 2.0, DVec3::X).is_none());
        let near = spheres.faces_near(DVec3::Z, 0.2);
        assert!(!near.is_empty() && near.len() < mesh.triangle_count() / 4);
        assert!(near
            .iter()
            .all(|&f| spheres.centres[f as usize].distance(DVec3::Z) < 0.5));
    }

    #[test]
    fn grid_nearest_distance_matches_a_full_scan() {
        let (mesh, _) = crate::shapes::bent_cylinder(0.5, 3.0, 70.0, 24, 12);
        let spheres = FaceSpheres::new(&mesh);
        let full = |p: DVec3| {
            (0..mesh.triangle_count())
                .map(|f| {
                    let [a, b, c] = mesh.corners(f);
                    point_triangle_distance(p, a, b, c)
                })
                .fold(f64::INFINITY, f64::min)
        };
        let mut state = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..200 {
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let p = DVec3::new(next() * 5.0 - 1.5, next() * 7.0 - 1.0, next() * 3.0 - 1.5);
            let (grid, scan) = (spheres.nearest_distance(&mesh, p), full(p));
            assert!((grid - scan).abs() < 1e-12, "{p}: {grid} vs {scan}");
        }
    }
}

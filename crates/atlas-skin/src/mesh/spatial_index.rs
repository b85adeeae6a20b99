//! Point and ray queries against a surface, pruned by per-face bounding spheres: nearest
//! surface distance, faces near a point, first hit along a ray, faces near a segment.
//!
//! Faces near a point come from a uniform grid of the sphere centres (about four faces per
//! cell); the nearest point and ray hits descend a bounding volume hierarchy of the faces'
//! boxes (the faces in Morton order of their centres, halved recursively: depth ⌈log₂ F⌉
//! at most); the exact test runs only on faces whose sphere passes. Faces near a segment
//! descend the same hierarchy through the boxes grown by the distance asked.
//! The decomposition asks for faces near a point once per joint, and for faces near a
//! segment once per candidate plane of a large domain (the ray of its containment test).

use super::surface::SurfaceMesh;
use crate::geometry::closest_point_on_triangle;
use crate::rows::Rows;
use crate::tolerance::RAY_PARALLEL;
use glam::{DVec3, IVec3};

/// A bounding sphere per face (centre = centroid, radius = farthest corner from it), and
/// a grid of the centres.
#[derive(Debug, Clone, Default)]
pub struct FaceSpheres {
    pub centres: Vec<DVec3>,
    pub radii: Vec<f64>,
    /// Largest radius.
    max_radius: f64,
    /// Built by the first [`FaceSpheres::faces_near`]: the surfaces asked only for nearest
    /// points and rays (the guard's, the pieces' bodies) never build it.
    grid: std::sync::OnceLock<CentreGrid>,
    bvh: FaceBvh,
}

/// Cells of side `cell` from `origin`, `dims` per axis; row k of `faces` lists the faces
/// whose centre lies in cell k (x fastest). Also the grid of the joints of
/// [`crate::skeleton::nearest_point`] (a "face" is then a point).
#[derive(Debug, Clone, Default)]
pub(crate) struct CentreGrid {
    pub(crate) origin: DVec3,
    pub(crate) cell: f64,
    pub(crate) dims: IVec3,
    faces: Rows<u32>,
}

impl CentreGrid {
    /// About four centres per cell, at most 257 cells per axis.
    pub(crate) fn new(centres: &[DVec3]) -> Self {
        let (lo, hi) = crate::geometry::bounding_box(centres);
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
            faces: Rows::default(),
        };
        let cells: Vec<usize> = centres
            .iter()
            .map(|c| grid.index(grid.cell_of(*c)))
            .collect();
        let cell_count = (dims.x * dims.y * dims.z) as usize;
        grid.faces = Rows::group(
            cell_count,
            cells.iter().enumerate().map(|(f, &k)| (k, f as u32)),
        );
        grid
    }

    /// The cell holding `p`: ⌊(p − origin) / cell⌋ clamped to the grid. The cast truncates
    /// toward zero instead of flooring: the two differ only below 0, where the clamp makes
    /// both 0 (and the saturating cast treats infinities and NaN alike), so the cell is the
    /// same without a call of the library's `floor` per coordinate (the target has no
    /// rounding instruction).
    pub(crate) fn cell_of(&self, p: DVec3) -> IVec3 {
        ((p - self.origin) / self.cell)
            .as_ivec3()
            .clamp(IVec3::ZERO, self.dims - IVec3::ONE)
    }

    fn index(&self, c: IVec3) -> usize {
        (c.x + self.dims.x * (c.y + self.dims.y * c.z)) as usize
    }

    /// Faces whose centre lies in a cell of the box `lo..=hi` of cell coordinates, except
    /// the cells of the box `skip_lo..=skip_hi` (pass an empty box to keep all). Cells
    /// x-adjacent are adjacent in `faces`, so each row of the box (or each side of the
    /// skipped box in a row) is one slice.
    pub(crate) fn faces_in(
        &self,
        lo: IVec3,
        hi: IVec3,
        skip_lo: IVec3,
        skip_hi: IVec3,
    ) -> impl Iterator<Item = u32> + '_ {
        let (lo, hi) = (lo.max(IVec3::ZERO), hi.min(self.dims - IVec3::ONE));
        (lo.z..=hi.z)
            .flat_map(move |z| (lo.y..=hi.y).map(move |y| (y, z)))
            .flat_map(move |(y, z)| {
                let skipped = (skip_lo.y..=skip_hi.y).contains(&y)
                    && (skip_lo.z..=skip_hi.z).contains(&z)
                    && skip_lo.x <= skip_hi.x;
                let (left_end, right_start) = if skipped {
                    (skip_lo.x - 1, skip_hi.x + 1)
                } else {
                    (hi.x, hi.x + 1)
                };
                [
                    self.row(y, z, lo.x, left_end.min(hi.x)),
                    self.row(y, z, right_start.max(lo.x), hi.x),
                ]
            })
            .flatten()
            .copied()
    }

    /// Faces of the cells x0..=x1 of row (y, z), empty when x0 > x1.
    pub(crate) fn row(&self, y: i32, z: i32, x0: i32, x1: i32) -> &[u32] {
        if x0 > x1 {
            return &[];
        }
        let (k0, k1) = (
            self.index(IVec3::new(x0, y, z)),
            self.index(IVec3::new(x1, y, z)),
        );
        &self.faces.values[self.faces.offsets[k0] as usize..self.faces.offsets[k1 + 1] as usize]
    }
}

/// Sorts distinct face indices below `face_count`: by a bitmap of the faces, O(k + F/64),
/// when the k indices are at least F/256 of them, else by comparison, O(k log k).
fn sort_face_indices(faces: &mut [u32], face_count: usize) {
    if faces.len() * 256 < face_count {
        faces.sort_unstable();
        return;
    }
    let mut bits = vec![0u64; face_count.div_ceil(64)];
    for &f in faces.iter() {
        bits[f as usize / 64] |= 1 << (f % 64);
    }
    let sorted = bits.iter().enumerate().flat_map(|(w, &word)| {
        let mut rest = word;
        std::iter::from_fn(move || {
            (rest != 0).then(|| {
                let bit = rest.trailing_zeros();
                rest &= rest - 1;
                (w * 64) as u32 + bit
            })
        })
    });
    for (slot, f) in faces.iter_mut().zip(sorted) {
        *slot = f;
    }
}

/// The first surface point a ray meets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayHit {
    pub face: u32,
    /// Distance along the (unit) ray direction.
    pub distance: f64,
}

/// The point u a + v b + w c of face `face` (corners a, b, c) nearest to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearestPoint {
    pub face: u32,
    /// (u, v, w): non-negative, summing to 1.
    pub barycentric: [f64; 3],
    pub distance: f64,
}

impl NearestPoint {
    /// The nearest point of face `face` of `mesh` to `p`.
    pub fn on_face(mesh: &SurfaceMesh, face: u32, p: DVec3) -> Self {
        Self::on_corners(face, mesh.corners(face as usize), p)
    }

    /// [`Self::on_face`] of the face `face` whose corners are `[a, b, c]`.
    fn on_corners(face: u32, [a, b, c]: [DVec3; 3], p: DVec3) -> Self {
        let barycentric = closest_point_on_triangle(p, a, b, c);
        let [u, v, w] = barycentric;
        Self {
            face,
            barycentric,
            distance: p.distance(a * u + b * v + c * w),
        }
    }
}

impl FaceSpheres {
    /// Spheres of every face of `mesh` and their hierarchy, in O(F) (the grid is built
    /// when first needed). A radius is the square root of the largest squared distance,
    /// which equals the largest distance (the rounded square root is monotonic).
    pub fn new(mesh: &SurfaceMesh) -> Self {
        let mut centres = Vec::with_capacity(mesh.triangle_count());
        let mut radii = Vec::with_capacity(mesh.triangle_count());
        for f in 0..mesh.triangle_count() {
            let corners = mesh.corners(f);
            let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
            let farthest = corners
                .iter()
                .map(|c| c.distance_squared(centre))
                .fold(0.0, f64::max);
            centres.push(centre);
            radii.push(farthest.sqrt());
        }
        let max_radius = radii.iter().copied().fold(0.0, f64::max);
        let bvh = FaceBvh::new(mesh, &centres);
        Self {
            centres,
            radii,
            max_radius,
            grid: std::sync::OnceLock::new(),
            bvh,
        }
    }

    /// The grid of the face centres, built on first use.
    fn grid(&self) -> &CentreGrid {
        self.grid.get_or_init(|| CentreGrid::new(&self.centres))
    }

    /// Distance from `p` to the nearest point of the surface, `f64::INFINITY` without faces.
    pub fn nearest_distance(&self, mesh: &SurfaceMesh, p: DVec3) -> f64 {
        self.nearest_point(mesh, p)
            .map_or(f64::INFINITY, |nearest| nearest.distance)
    }

    /// The nearest point of the surface to `p` ([`NearestPoint`]: its face, barycentric
    /// coordinates and distance; of faces at the same distance, the lowest index), `None`
    /// without faces.
    ///
    /// Branch and bound on the hierarchy of face boxes: the distance from `p` to a node's
    /// box bounds the distance to each of its faces from below, so a node is opened only
    /// while that bound is at most the best distance so far, nearer child first, and a
    /// face is tested exactly only when |p − c_f| − r_f (its sphere) and the distance to its
    /// own box (padded as the nodes' are) are at most the best too. A query costs O(log F) boxes and a few triangles however far `p` lies from
    /// the surface (the grid's shells of cells grew with that distance). The result is
    /// that of a scan of all faces in index order keeping strictly nearer ones
    /// (`nearest_point_by_scan` in the tests): a face can be skipped only when its bound
    /// exceeds a distance already found, so it can neither win nor tie.
    pub fn nearest_point(&self, mesh: &SurfaceMesh, p: DVec3) -> Option<NearestPoint> {
        self.nearest_point_from(mesh, p, None)
    }

    /// [`Self::nearest_point`], the search started from face `hint` (a face near `p`: the
    /// nearest face of a neighbouring query point) instead of from nothing. The same
    /// result: the hint is one candidate among the others, tested first, so its distance
    /// prunes boxes and faces from the start (a face is still skipped only when its bound
    /// exceeds a distance found).
    pub fn nearest_point_from(
        &self,
        mesh: &SurfaceMesh,
        p: DVec3,
        hint: Option<u32>,
    ) -> Option<NearestPoint> {
        let nodes = &self.bvh.nodes;
        if nodes.is_empty() {
            return None;
        }
        let mut best: Option<NearestPoint> = hint
            .filter(|&f| (f as usize) < self.centres.len())
            .map(|f| NearestPoint::on_face(mesh, f, p));
        // The best distance so far (infinity before the first face).
        let mut limit = best.map_or(f64::INFINITY, |b| b.distance);
        // (node, squared distance from p to its box), on the call's stack: at most one
        // node per level plus one, and the tree's depth is below 32.
        let mut stack = [(0u32, 0.0f64); 64];
        stack[0] = (0, nodes[0].distance_squared(p));
        let mut size = 1;
        while size > 0 {
            size -= 1;
            let (k, gap) = stack[size];
            if gap > limit * limit {
                continue;
            }
            let node = &nodes[k as usize];
            if node.count > 0 {
                let (start, end) = (node.start as usize, (node.start + node.count) as usize);
                for &f in &self.bvh.faces[start..end] {
                    if self.centres[f as usize].distance(p) - self.radii[f as usize] > limit {
                        continue;
                    }
                    // The face's box bounds it more tightly than its sphere where the
                    // surface runs flat under p: the faces beside the nearest are skipped.
                    let corners = mesh.corners(f as usize);
                    let [lo, hi] = padded_box(corners, self.bvh.pad);
                    if box_distance_squared(lo, hi, p) > limit * limit {
                        continue;
                    }
                    let candidate = NearestPoint::on_corners(f, corners, p);
                    let nearer = candidate.distance < limit
                        || best.is_some_and(|b| candidate.distance == b.distance && f < b.face);
                    if nearer {
                        limit = candidate.distance;
                        best = Some(candidate);
                    }
                }
                continue;
            }
            let (first, second) = (k + 1, k + node.start);
            let (first_gap, second_gap) = (
                nodes[first as usize].distance_squared(p),
                nodes[second as usize].distance_squared(p),
            );
            // Pushed last, popped first: the nearer child.
            let (near, far) = if first_gap <= second_gap {
                ((first, first_gap), (second, second_gap))
            } else {
                ((second, second_gap), (first, first_gap))
            };
            stack[size] = far;
            stack[size + 1] = near;
            size += 2;
        }
        best
    }

    /// Faces whose sphere meets the ball of `radius` around `p` (a superset of the faces
    /// that meet the ball), in face order.
    pub fn faces_near(&self, p: DVec3, radius: f64) -> Vec<u32> {
        self.fewer_faces_near(p, radius, usize::MAX, |_| true)
            .unwrap_or_default()
    }

    /// The faces of [`Self::faces_near`] for which `keep` holds, when there are fewer than
    /// `limit`; `None` at the `limit`-th, found without looking further (a ball around a
    /// point deep in a large body holds most of the surface).
    pub fn fewer_faces_near(
        &self,
        p: DVec3,
        radius: f64,
        limit: usize,
        keep: impl Fn(u32) -> bool,
    ) -> Option<Vec<u32>> {
        if self.centres.is_empty() {
            return Some(Vec::new());
        }
        let reach = DVec3::splat(radius + self.max_radius);
        let grid = self.grid();
        let (lo, hi) = (grid.cell_of(p - reach), grid.cell_of(p + reach));
        // The rows of the box as plain loops: the faces of `CentreGrid::faces_in` (with
        // nothing skipped) in the same order, without its chain of adapters per face.
        let mut faces = Vec::new();
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for &f in grid.row(y, z, lo.x, hi.x) {
                    if self.is_near(f, p, radius) && keep(f) {
                        if faces.len() + 1 >= limit {
                            return None;
                        }
                        faces.push(f);
                    }
                }
            }
        }
        sort_face_indices(&mut faces, self.centres.len());
        Some(faces)
    }

    /// Whether face `f` is one of [`Self::faces_near`] `p` within `radius`: its sphere
    /// comes within `radius` of `p`.
    #[inline]
    pub fn is_near(&self, f: u32, p: DVec3, radius: f64) -> bool {
        let (centre, r) = (self.centres[f as usize], self.radii[f as usize]);
        centre.distance_squared(p) <= (radius + r).powi(2)
    }

    /// Whether every face is one of [`Self::faces_near`] `p` within `radius`; stops at the
    /// first that is not.
    pub fn all_near(&self, p: DVec3, radius: f64) -> bool {
        (0..self.centres.len() as u32).all(|f| self.is_near(f, p, radius))
    }

    /// The largest radius of a face's sphere.
    pub fn max_radius(&self) -> f64 {
        self.max_radius
    }

    /// Appends to `out` the faces whose sphere comes within `radius` of the segment
    /// `origin + t · direction`, 0 ≤ t ≤ `length` (`direction` unit length), in the
    /// hierarchy's order: a superset of the faces within `radius` of the segment. The
    /// hierarchy is descended through the boxes grown by `radius` that the segment meets,
    /// so a segment costs the boxes along it, not the faces of the mesh.
    pub fn faces_near_segment(
        &self,
        origin: DVec3,
        direction: DVec3,
        length: f64,
        radius: f64,
        out: &mut Vec<u32>,
    ) {
        let nodes = &self.bvh.nodes;
        let inverse = |d: f64| if d.abs() < 1e-300 { 1e300 } else { 1.0 / d };
        let segment = Segment {
            low_corner: origin + radius,
            high_corner: origin - radius,
            inverse: DVec3::new(
                inverse(direction.x),
                inverse(direction.y),
                inverse(direction.z),
            ),
            length,
        };
        if nodes.is_empty() || !nodes[0].segment_meets(&segment) {
            return;
        }
        // Nodes whose grown box the segment meets, not yet opened: at most one pending
        // sibling per level of a tree of depth ⌈log₂ F⌉ + 1 < 64.
        let mut stack = [0u32; 64];
        let mut size = 1;
        while size > 0 {
            size -= 1;
            let k = stack[size];
            let node = &nodes[k as usize];
            if node.count > 0 {
                let (start, end) = (node.start as usize, (node.start + node.count) as usize);
                for &f in &self.bvh.faces[start..end] {
                    let to_centre = self.centres[f as usize] - origin;
                    let t = to_centre.dot(direction).clamp(0.0, length);
                    let reach = self.radii[f as usize] + radius;
                    if (to_centre - direction * t).length_squared() <= reach * reach {
                        out.push(f);
                    }
                }
                continue;
            }
            for child in [k + node.start, k + 1] {
                if nodes[child as usize].segment_meets(&segment) {
                    stack[size] = child;
                    size += 1;
                }
            }
        }
    }

    /// First face hit by the ray `origin + t · direction`, t > 0, `direction` unit length
    /// (Möller–Trumbore 1997 on faces whose sphere the ray meets); of faces hit at the same
    /// t, the lowest index. The hierarchy is descended nearer child first and a node is
    /// skipped once its box starts beyond the best hit, so a ray costs O(log F) boxes and a
    /// few triangles where it runs clear of the surface.
    pub fn first_hit(&self, mesh: &SurfaceMesh, origin: DVec3, direction: DVec3) -> Option<RayHit> {
        self.ray_search(mesh, origin, direction, f64::INFINITY, false)
    }

    /// Whether the ray `origin + t · direction` hits a face at some 0 < t < `limit`: the
    /// same as `first_hit(..).is_some_and(|h| h.distance < limit)`, but boxes entered at
    /// `limit` or later are never opened and the search stops at the first hit found (a
    /// segment seen clear of the surface costs only the boxes along it).
    pub fn hit_before(
        &self,
        mesh: &SurfaceMesh,
        origin: DVec3,
        direction: DVec3,
        limit: f64,
    ) -> bool {
        self.ray_search(mesh, origin, direction, limit, true)
            .is_some()
    }

    /// The hit of [`Self::first_hit`] among those with t < `limit`; with `any`, the first
    /// such hit found instead of the nearest.
    fn ray_search(
        &self,
        mesh: &SurfaceMesh,
        origin: DVec3,
        direction: DVec3,
        limit: f64,
        any: bool,
    ) -> Option<RayHit> {
        let nodes = &self.bvh.nodes;
        let mut best: Option<RayHit> = None;
        if nodes.is_empty() {
            return best;
        }
        // A box entered beyond the best hit (or at the limit) holds no better hit.
        let beyond = |entry: f64, best: &Option<RayHit>| match best {
            Some(h) => entry > h.distance,
            None => entry >= limit,
        };
        // (node, t at which the ray enters its box): each box is tested once, when its
        // parent is opened.
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        if let Some(entry) = nodes[0].ray_entry(origin, direction) {
            stack.push((0, entry));
        }
        while let Some((k, entry)) = stack.pop() {
            if beyond(entry, &best) {
                continue;
            }
            let node = &nodes[k as usize];
            if node.count > 0 {
                let (start, end) = (node.start as usize, (node.start + node.count) as usize);
                for &f in &self.bvh.faces[start..end] {
                    let Some(t) = self.sphere_hit(mesh, f as usize, origin, direction) else {
                        continue;
                    };
                    let better = t < limit
                        && best.is_none_or(|h| t < h.distance || (t == h.distance && f < h.face));
                    if better {
                        best = Some(RayHit {
                            face: f,
                            distance: t,
                        });
                        if any {
                            return best;
                        }
                    }
                }
                continue;
            }
            let entry = |n: u32| {
                nodes[n as usize]
                    .ray_entry(origin, direction)
                    .map(|t| (n, t))
            };
            match (entry(k + 1), entry(k + node.start)) {
                // Pushed last, popped first: the child the ray enters first.
                (Some(first), Some(second)) if first.1 <= second.1 => {
                    stack.extend([second, first]);
                }
                (Some(first), Some(second)) => stack.extend([first, second]),
                (first, second) => stack.extend(first.or(second)),
            }
        }
        best
    }

    /// t of the ray's hit on face `f`, tested exactly only when the ray meets its sphere.
    fn sphere_hit(
        &self,
        mesh: &SurfaceMesh,
        f: usize,
        origin: DVec3,
        direction: DVec3,
    ) -> Option<f64> {
        let (c, r) = (self.centres[f], self.radii[f]);
        let to_centre = c - origin;
        let along = to_centre.dot(direction);
        if along < -r || (to_centre - direction * along).length_squared() > r * r {
            return None;
        }
        let [a, b, c] = mesh.corners(f);
        ray_triangle(origin, direction, a, b, c)
    }
}

/// Faces at most this many to a leaf of [`FaceBvh`].
const LEAF_FACES: usize = 4;

/// A bounding volume hierarchy of the faces' boxes, nodes in depth-first order: an inner
/// node k's first child is k + 1, its second child k + `start`.
#[derive(Debug, Clone, Default)]
struct FaceBvh {
    nodes: Vec<BvhNode>,
    /// Face indices, each leaf's a contiguous run.
    faces: Vec<u32>,
    /// What every box is grown by on each side ([`padded_box`]).
    pad: f64,
}

#[derive(Debug, Clone, Copy)]
struct BvhNode {
    lo: DVec3,
    hi: DVec3,
    /// A leaf's first entry of `faces`; an inner node's offset to its second child (the
    /// first follows it).
    start: u32,
    /// A leaf's face count; 0 for an inner node.
    count: u32,
}

impl FaceBvh {
    /// Orders the faces along a Morton (Z-order) curve of their centres, then halves that
    /// order recursively: O(F log F) for the sort, O(F) for the tree, depth
    /// ⌈log₂(F / LEAF_FACES)⌉ + 1. Boxes are padded by 1e-9 of the mesh's extent so that a
    /// hit Möller–Trumbore rounds out of its face's box is still found.
    fn new(mesh: &SurfaceMesh, centres: &[DVec3]) -> Self {
        let (lo, hi) = mesh.bounding_box();
        let pad = 1e-9 * (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let mut bvh = Self {
            // At most F nodes, so the list never grows (grown, it was copied once): a range
            // of more than LEAF_FACES faces is halved into two of at least 2, so a tree of
            // F ≥ 2 faces has at most F / 2 leaves and F − 1 nodes.
            nodes: Vec::with_capacity(centres.len()),
            faces: morton_order(centres),
            pad,
        };
        if !bvh.faces.is_empty() {
            bvh.build(0..bvh.faces.len(), mesh);
        }
        debug_assert!(bvh.nodes.len() <= centres.len());
        bvh
    }

    /// Appends the subtree of the faces `range` of `self.faces`; returns its box. A leaf's
    /// faces' boxes are taken from their corners there (a list of all the faces' boxes was
    /// 48 bytes a face of new memory: 260 MB at 5.4M triangles).
    fn build(&mut self, range: std::ops::Range<usize>, mesh: &SurfaceMesh) -> [DVec3; 2] {
        let index = self.nodes.len();
        self.nodes.push(BvhNode {
            lo: DVec3::ZERO,
            hi: DVec3::ZERO,
            start: range.start as u32,
            count: range.len() as u32,
        });
        let [lo, hi] = if range.len() <= LEAF_FACES {
            self.faces[range]
                .iter()
                .fold([DVec3::INFINITY, DVec3::NEG_INFINITY], |[lo, hi], &f| {
                    let [face_lo, face_hi] = padded_box(mesh.corners(f as usize), self.pad);
                    [lo.min(face_lo), hi.max(face_hi)]
                })
        } else {
            let middle = range.start + range.len() / 2;
            let [first_lo, first_hi] = self.build(range.start..middle, mesh);
            self.nodes[index].start = (self.nodes.len() - index) as u32;
            self.nodes[index].count = 0;
            let [second_lo, second_hi] = self.build(middle..range.end, mesh);
            [first_lo.min(second_lo), first_hi.max(second_hi)]
        };
        (self.nodes[index].lo, self.nodes[index].hi) = (lo, hi);
        [lo, hi]
    }
}

/// Bits of the code sorted by each pass of [`sort_by_code`].
const RADIX_BITS: u32 = 11;

/// `keyed` (Morton codes of 63 bits with their faces, the faces increasing) sorted by code
/// and then face, as `sort_unstable` sorts the pairs: a least significant digit radix
/// sort, ⌈63 / 11⌉ = 6 counting passes of 2¹¹ buckets, O(F) (a pass whose digit is the
/// same for every code is skipped). Each pass is stable, so faces of one code stay
/// increasing. The passes permute the same codes, so every pass's counts are taken in one
/// read of the codes before the first. (The comparison sort it replaces took about 200
/// instructions per face; the passes about 40.)
fn sort_by_code(mut keyed: Vec<(u64, u32)>) -> Vec<(u64, u32)> {
    const BUCKETS: usize = 1 << RADIX_BITS;
    const PASSES: usize = 63u32.div_ceil(RADIX_BITS) as usize;
    debug_assert!(keyed.windows(2).all(|w| w[0].1 < w[1].1));
    let digit =
        |code: u64, pass: usize| ((code >> (pass as u32 * RADIX_BITS)) as usize) & (BUCKETS - 1);
    let mut counts = vec![[0u32; BUCKETS]; PASSES];
    for &(code, _) in &keyed {
        for (pass, pass_counts) in counts.iter_mut().enumerate() {
            pass_counts[digit(code, pass)] += 1;
        }
    }
    let mut other = vec![(0u64, 0u32); keyed.len()];
    for (pass, slots) in counts.iter_mut().enumerate() {
        if slots.contains(&(keyed.len() as u32)) {
            continue;
        }
        let mut next = 0;
        for count in slots.iter_mut() {
            (*count, next) = (next, next + *count);
        }
        for &(code, face) in &keyed {
            let slot = &mut slots[digit(code, pass)];
            other[*slot as usize] = (code, face);
            *slot += 1;
        }
        std::mem::swap(&mut keyed, &mut other);
    }
    keyed
}

/// The indices of `points` along a Morton (Z-order) curve of their bounding box (ties by
/// index): points near each other in space come mostly near each other in the order.
/// O(n) (a radix sort of the codes).
pub fn morton_order(points: &[DVec3]) -> Vec<u32> {
    let (lo, hi) = crate::geometry::bounding_box(points);
    let scale = MORTON_CELLS / (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE));
    let keyed: Vec<(u64, u32)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (morton_code(((*p - lo) * scale).as_uvec3()), i as u32))
        .collect();
    sort_by_code(keyed).into_iter().map(|(_, i)| i).collect()
}

/// Cells per axis of the Morton code's grid (21 bits per axis fill 63 bits).
const MORTON_CELLS: f64 = ((1u32 << 21) - 1) as f64;

/// Interleaves the low 21 bits of x, y, z: bit i of x goes to bit 3i (Morton 1966).
fn morton_code(cell: glam::UVec3) -> u64 {
    let spread = |v: u32| {
        let mut v = u64::from(v.min((1 << 21) - 1));
        v = (v | v << 32) & 0x001f_0000_0000_ffff;
        v = (v | v << 16) & 0x001f_0000_ff00_00ff;
        v = (v | v << 8) & 0x100f_00f0_0f00_f00f;
        v = (v | v << 4) & 0x10c3_0c30_c30c_30c3;
        (v | v << 2) & 0x1249_2492_4924_9249
    };
    spread(cell.x) | spread(cell.y) << 1 | spread(cell.z) << 2
}

/// The box of a face's corners grown by `pad` on each side: a point of the face that a
/// computation rounds out of its exact box still lies in it.
#[inline(always)]
fn padded_box([a, b, c]: [DVec3; 3], pad: f64) -> [DVec3; 2] {
    [a.min(b).min(c) - pad, a.max(b).max(c) + pad]
}

/// Squared distance from `p` to the box `lo..=hi`, 0 inside it.
#[inline(always)]
fn box_distance_squared(lo: DVec3, hi: DVec3, p: DVec3) -> f64 {
    (lo - p).max(p - hi).max(DVec3::ZERO).length_squared()
}

impl BvhNode {
    /// Squared distance from `p` to the box, 0 inside it.
    fn distance_squared(&self, p: DVec3) -> f64 {
        box_distance_squared(self.lo, self.hi, p)
    }

    /// Smallest t ≥ 0 at which the ray is in the box (slab test), `None` when it misses.
    fn ray_entry(&self, origin: DVec3, direction: DVec3) -> Option<f64> {
        let (mut near, mut far) = (0.0f64, f64::INFINITY);
        for axis in 0..3 {
            let (o, d) = (origin[axis], direction[axis]);
            let (lo, hi) = (self.lo[axis], self.hi[axis]);
            if d == 0.0 {
                if o < lo || o > hi {
                    return None;
                }
                continue;
            }
            let (t0, t1) = ((lo - o) / d, (hi - o) / d);
            near = near.max(t0.min(t1));
            far = far.min(t0.max(t1));
        }
        (near <= far).then_some(near)
    }

    /// Whether `segment` meets the box grown by its radius on every side (slab test).
    #[inline(always)]
    fn segment_meets(&self, segment: &Segment) -> bool {
        // No NaN arises (see `Segment::inverse`), so plain comparisons stand for `min` and
        // `max` (which would test for NaN).
        let min = |a: f64, b: f64| if a < b { a } else { b };
        let max = |a: f64, b: f64| if a > b { a } else { b };
        let t0 = (self.lo - segment.low_corner) * segment.inverse;
        let t1 = (self.hi - segment.high_corner) * segment.inverse;
        let near = max(
            max(min(t0.x, t1.x), min(t0.y, t1.y)),
            max(min(t0.z, t1.z), 0.0),
        );
        let far = min(
            min(max(t0.x, t1.x), max(t0.y, t1.y)),
            min(max(t0.z, t1.z), segment.length),
        );
        near <= far
    }
}

/// The segment of [`FaceSpheres::faces_near_segment`] with what its box tests reuse.
struct Segment {
    /// origin + radius and origin − radius: a box grown by the radius is met where
    /// (lo − (o + r)) / d and (hi − (o − r)) / d bound t.
    low_corner: DVec3,
    high_corner: DVec3,
    /// 1 / direction per axis, with 10³⁰⁰ for a component below 10⁻³⁰⁰ (taken as 0): a
    /// product is then a finite number or ±∞, never NaN (0 · ∞), and an axis the segment
    /// runs parallel to limits nothing when the origin is inside its slab (on a side
    /// included) and stops the segment at once when outside.
    inverse: DVec3,
    length: f64,
}

/// Möller–Trumbore: t > 0 with origin + t·direction in triangle abc, None when parallel.
fn ray_triangle(origin: DVec3, direction: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (ab, ac) = (b - a, c - a);
    let p = direction.cross(ac);
    let det = ab.dot(p);
    if det.abs() <= RAY_PARALLEL * ab.length_squared().max(ac.length_squared()) {
        return None;
    }
    let s = origin - a;
    let u = s.dot(p) / det;
    let q = s.cross(ab);
    let v = direction.dot(q) / det;
    let t = ac.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::shapes::icosphere;
    use crate::geometry::point_triangle_distance;

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

    /// Faces near a segment: every face with a point within the radius of it (sampled
    /// along it) is listed, and only faces whose sphere comes that near; segments through,
    /// along the axes of and outside a sphere.
    #[test]
    fn faces_near_a_segment_contain_the_faces_within_reach() {
        let mesh = icosphere(1.0, 3);
        let spheres = FaceSpheres::new(&mesh);
        let cases = [
            (DVec3::ZERO, DVec3::X, 2.0, 0.05),
            (
                DVec3::new(0.1, 0.2, 0.3),
                DVec3::new(1.0, 2.0, -0.5).normalize(),
                1.5,
                0.01,
            ),
            (DVec3::new(0.0, 0.0, 0.99), DVec3::Y, 0.3, 0.02),
            (DVec3::new(3.0, 0.0, 0.0), DVec3::Z, 1.0, 0.1),
            (DVec3::new(-0.5, 0.0, 0.0), -DVec3::Z, 0.0, 0.0),
        ];
        for (origin, direction, length, radius) in cases {
            let mut near = Vec::new();
            spheres.faces_near_segment(origin, direction, length, radius, &mut near);
            let within_reach = (0..mesh.triangle_count()).filter(|&f| {
                let [a, b, c] = mesh.corners(f);
                (0..=200).any(|i| {
                    let p = origin + direction * (length * i as f64 / 200.0);
                    point_triangle_distance(p, a, b, c) <= radius
                })
            });
            for f in within_reach {
                assert!(near.contains(&(f as u32)), "{origin} {direction}: face {f}");
            }
            for &f in &near {
                let to_centre = spheres.centres[f as usize] - origin;
                let t = to_centre.dot(direction).clamp(0.0, length);
                let gap = (to_centre - direction * t).length();
                assert!(gap <= spheres.radii[f as usize] + radius + 1e-12);
            }
            assert!(near.len() < mesh.triangle_count() / 4);
        }
    }

    /// The reference for [`FaceSpheres::first_hit`]: every face, lowest index on ties.
    fn first_hit_by_scan(mesh: &SurfaceMesh, origin: DVec3, direction: DVec3) -> Option<RayHit> {
        (0..mesh.triangle_count())
            .filter_map(|f| {
                let [a, b, c] = mesh.corners(f);
                ray_triangle(origin, direction, a, b, c).map(|t| RayHit {
                    face: f as u32,
                    distance: t,
                })
            })
            .min_by(|x, y| x.distance.total_cmp(&y.distance).then(x.face.cmp(&y.face)))
    }

    #[test]
    fn hierarchy_ray_hits_match_a_full_scan() {
        let (mesh, _) = crate::fixtures::shapes::bent_cylinder(0.5, 3.0, 70.0, 24, 12);
        let spheres = FaceSpheres::new(&mesh);
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut hits = 0;
        for _ in 0..2000 {
            let origin = DVec3::new(next() * 0.6, next() * 1.5 + 1.5, next() * 0.6);
            let direction = DVec3::new(next(), next(), next()).normalize_or(DVec3::X);
            let fast = spheres.first_hit(&mesh, origin, direction);
            assert_eq!(
                fast,
                first_hit_by_scan(&mesh, origin, direction),
                "{origin} {direction}"
            );
            hits += usize::from(fast.is_some());
        }
        // Rays along the axes, through vertices and edges of the grid-aligned cylinder.
        for v in mesh.positions.iter().step_by(7) {
            for direction in [DVec3::X, DVec3::NEG_Y, DVec3::Z] {
                let origin = *v - direction;
                let fast = spheres.first_hit(&mesh, origin, direction);
                assert_eq!(
                    fast,
                    first_hit_by_scan(&mesh, origin, direction),
                    "{origin}"
                );
            }
        }
        assert!(hits > 1000, "{hits} rays of 2000 hit");
    }

    /// Rays from every joint of makehuman's body and cesiumman along its bones and six
    /// turned axes (the rays the decomposition casts), by the hierarchy and by a full scan.
    #[test]
    fn hierarchy_queries_match_a_full_scan_on_the_corpus() {
        let turn = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.1234, 0.2345, 0.3456);
        for (file, mesh, skeleton) in crate::fixtures::corpus::welded_humans() {
            let joints: Vec<DVec3> = skeleton
                .bind_positions()
                .iter()
                .map(|p| p.as_dvec3())
                .collect();
            let spheres = FaceSpheres::new(&mesh);
            let mut hits = 0;
            for (j, &p) in joints.iter().enumerate() {
                let bone = skeleton
                    .parent(j)
                    .and_then(|q| (p - joints[q]).try_normalize());
                let axes = [
                    DVec3::X,
                    DVec3::NEG_X,
                    DVec3::Y,
                    DVec3::NEG_Y,
                    DVec3::Z,
                    DVec3::NEG_Z,
                ];
                for direction in axes.into_iter().map(|a| turn * a).chain(bone) {
                    // The nearest surface point of points inside and around the body.
                    let mut hint = None;
                    for q in [p, p + direction * 0.1, p + direction] {
                        let scan = nearest_point_by_scan(&mesh, q);
                        assert_eq!(spheres.nearest_point(&mesh, q), scan, "{file} joint {j}");
                        // From the nearest face of the point before, as the pieces ask.
                        assert_eq!(
                            spheres.nearest_point_from(&mesh, q, hint),
                            scan,
                            "{file} joint {j}"
                        );
                        hint = scan.map(|s| s.face);
                    }
                    let fast = spheres.first_hit(&mesh, p, direction);
                    let scan = first_hit_by_scan(&mesh, p, direction);
                    assert_eq!(fast, scan, "{file} joint {j}");
                    // Bounded rays: short of the hit, at it and past it.
                    let t = scan.map_or(1.0, |h| h.distance);
                    for limit in [0.5 * t, t, t * (1.0 + 1e-9), 2.0 * t] {
                        assert_eq!(
                            spheres.hit_before(&mesh, p, direction, limit),
                            scan.is_some_and(|h| h.distance < limit),
                            "{file} joint {j} limit {limit}"
                        );
                    }
                    hits += usize::from(fast.is_some());
                }
            }
            assert!(hits > joints.len(), "{file}: {hits} hits");
        }
    }

    /// The cell by truncation is the cell by `floor`: points inside the grid, on cell
    /// sides, just below 0 and far outside on both sides, infinite and NaN coordinates.
    #[test]
    fn cells_by_truncation_are_the_cells_by_floor() {
        let grid = CentreGrid::new(&[DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)]);
        let by_floor = |p: DVec3| {
            ((p - grid.origin) / grid.cell)
                .floor()
                .as_ivec3()
                .clamp(IVec3::ZERO, grid.dims - IVec3::ONE)
        };
        let values = [
            -1e300,
            -3.5,
            -1.0,
            -0.5,
            -1e-300,
            -0.0,
            0.0,
            1e-300,
            grid.cell,
            grid.cell * 3.0,
            grid.cell * 3.0 - 1e-12,
            0.7,
            2.999,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for &x in &values {
            for &y in &values {
                for z in [0.3, -0.2, f64::NAN] {
                    let p = DVec3::new(x, y, z);
                    assert_eq!(grid.cell_of(p), by_floor(p), "{p}");
                }
            }
        }
    }

    #[test]
    fn morton_codes_interleave_the_axes() {
        let code = |x, y, z| morton_code(glam::UVec3::new(x, y, z));
        assert_eq!(
            [code(1, 0, 0), code(0, 1, 0), code(0, 0, 1), code(2, 0, 0)],
            [1, 2, 4, 8]
        );
        assert_eq!(code(3, 5, 6), 0b110_101_011);
        let top = (1 << 21) - 1;
        assert_eq!(code(top, top, top), (1u64 << 63) - 1);
    }

    /// The corners of a unit cube, listed backwards, come in Z-order: x fastest, then y,
    /// then z (a corner's code is x + 2y + 4z).
    #[test]
    fn morton_order_visits_a_cube_in_z_order() {
        let corners: Vec<DVec3> = (0..8)
            .rev()
            .map(|k| DVec3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2) as f64))
            .collect();
        assert_eq!(morton_order(&corners), [7, 6, 5, 4, 3, 2, 1, 0]);
    }

    #[test]
    fn codes_sort_by_radix_as_by_comparison() {
        // Random codes of 63 bits, codes repeated (faces of one code must stay in order),
        // codes differing only in their top or bottom digit, none and one face.
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            state >> 1
        };
        let random: Vec<u64> = (0..5000).map(|_| next()).collect();
        let repeated: Vec<u64> = (0..3000).map(|_| (next() % 17) << 40).collect();
        let top: Vec<u64> = (0..300).map(|i| ((i % 5) << 60) | 12345).collect();
        let bottom: Vec<u64> = (0..300).map(|i| (i * 7919) % 2048).collect();
        for codes in [random, repeated, top, bottom, vec![], vec![5]] {
            let keyed: Vec<(u64, u32)> = codes.iter().zip(0..).map(|(&c, f)| (c, f)).collect();
            let mut expected = keyed.clone();
            expected.sort_unstable();
            assert_eq!(sort_by_code(keyed), expected);
        }
    }

    #[test]
    fn face_indices_sort_by_bitmap_and_by_comparison() {
        // 100 of 100 000 faces sort by comparison, 4 of 130 by bitmap.
        for (face_count, step) in [(100_000, 1000), (130, 37)] {
            let mut faces: Vec<u32> = (0..face_count as u32).rev().step_by(step).collect();
            let mut expected = faces.clone();
            expected.sort_unstable();
            sort_face_indices(&mut faces, face_count);
            assert_eq!(faces, expected, "{face_count} faces");
        }
    }

    /// The reference of [`FaceSpheres::nearest_point`]: every face in index order, a face
    /// kept only when strictly nearer.
    fn nearest_point_by_scan(mesh: &SurfaceMesh, p: DVec3) -> Option<NearestPoint> {
        (0..mesh.triangle_count() as u32)
            .map(|f| NearestPoint::on_face(mesh, f, p))
            .fold(None, |best: Option<NearestPoint>, candidate| match best {
                Some(b) if b.distance <= candidate.distance => Some(b),
                _ => Some(candidate),
            })
    }

    #[test]
    fn nearest_point_and_faces_near_match_a_full_scan() {
        let (mesh, _) = crate::fixtures::shapes::bent_cylinder(0.5, 3.0, 70.0, 24, 12);
        let spheres = FaceSpheres::new(&mesh);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut previous = 0;
        for query in 0..400 {
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            // Every fourth point far outside the surface's box.
            let spread = if query % 4 == 3 { 40.0 } else { 1.0 };
            let p = DVec3::new(next() * 5.0 - 1.5, next() * 7.0 - 1.0, next() * 3.0 - 1.5) * spread;
            let scan = nearest_point_by_scan(&mesh, p).expect("faces");
            assert_eq!(spheres.nearest_point(&mesh, p), Some(scan), "{p}");
            assert_eq!(spheres.nearest_distance(&mesh, p), scan.distance);
            // Started from the answer, from a random face, from the previous query's face
            // or from no face (an index past the faces): the same answer.
            let random = (next() * mesh.triangle_count() as f64) as u32;
            for hint in [scan.face, random, previous, mesh.triangle_count() as u32] {
                assert_eq!(
                    spheres.nearest_point_from(&mesh, p, Some(hint)),
                    Some(scan),
                    "{p} from {hint}"
                );
            }
            previous = scan.face;
            let scan_distance = (0..mesh.triangle_count())
                .map(|f| {
                    let [a, b, c] = mesh.corners(f);
                    point_triangle_distance(p, a, b, c)
                })
                .fold(f64::INFINITY, f64::min);
            assert!((scan.distance - scan_distance).abs() < 1e-12, "{p}");
            let [u, v, w] = scan.barycentric;
            assert!(u.min(v).min(w) >= 0.0 && (u + v + w - 1.0).abs() < 1e-12);
            let radius = next();
            let near: Vec<u32> = (0..mesh.triangle_count() as u32)
                .filter(|&f| {
                    let f = f as usize;
                    spheres.centres[f].distance_squared(p) <= (radius + spheres.radii[f]).powi(2)
                })
                .collect();
            assert_eq!(spheres.faces_near(p, radius), near, "{p} {radius}");
            // With a limit and a filter: the kept faces below the limit, none at it.
            let odd: Vec<u32> = near.iter().copied().filter(|f| f % 2 == 1).collect();
            for limit in [odd.len().max(1), odd.len() + 1] {
                let fewer = spheres.fewer_faces_near(p, radius, limit, |f| f % 2 == 1);
                assert_eq!(fewer, (limit > odd.len()).then(|| odd.clone()), "{limit}");
            }
        }
    }
}

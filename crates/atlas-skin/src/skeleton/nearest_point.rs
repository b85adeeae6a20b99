//! The nearest of a fixed set of points (the joints, a surface's vertices) to a query
//! point, exactly: a uniform grid of a few points per cell, searched in growing shells of
//! cells until the best distance found cannot be beaten by a farther shell; and the points
//! within a radius, from the cells of the radius's box. (The nearest bone:
//! [`super::bone_tree`].) And the joints that sit at one point, from such a grid.

use crate::mesh::spatial_index::CentreGrid;
use glam::{DVec3, IVec3};

/// A skeleton's bind positions, and which of its joints sit at one point: within a radius
/// of each other. Found from a grid of the
/// distinct positions, the joints at each visited together: no pair of joints is visited,
/// so a skeleton of thousands of joints bound at one point (a broken file) costs as much
/// as one of thousands apart.
pub struct JointPoints {
    /// #J bind positions.
    bind: Vec<DVec3>,
    /// The distinct bind positions; the joints at position p are
    /// `joints[first[p]..first[p + 1]]`, increasing.
    first: Vec<usize>,
    joints: Vec<u32>,
    grid: PointGrid,
    radius: f64,
}

impl JointPoints {
    /// The joints at `bind` within `radius` of each other.
    pub fn within_radius(bind: Vec<DVec3>, radius: f64) -> Self {
        let key = |j: u32| bind[j as usize].to_array().map(f64::to_bits);
        let mut joints: Vec<u32> = (0..bind.len() as u32).collect();
        joints.sort_unstable_by_key(|&j| (key(j), j));
        let mut first = Vec::new();
        for (i, &j) in joints.iter().enumerate() {
            if i == 0 || key(joints[i - 1]) != key(j) {
                first.push(i);
            }
        }
        let points: Vec<DVec3> = first.iter().map(|&i| bind[joints[i] as usize]).collect();
        first.push(joints.len());
        Self {
            grid: PointGrid::new(&points),
            radius,
            first,
            joints,
            bind,
        }
    }

    /// The distinct positions within the radius of position p (p included) with a
    /// larger index, each once.
    fn positions_after(&self, p: usize) -> impl Iterator<Item = usize> + '_ {
        let point = self.bind[self.joints[self.first[p]] as usize];
        self.grid
            .within(point, self.radius)
            .into_iter()
            .map(|q| q as usize)
            .filter(move |&q| q > p)
    }

    /// The number of distinct positions.
    fn positions(&self) -> usize {
        self.first.len() - 1
    }

    /// The joints at position p, increasing.
    fn joints_at(&self, p: usize) -> &[u32] {
        &self.joints[self.first[p]..self.first[p + 1]]
    }

    /// How many pairs of joints sit at one point, counted by position: n (n − 1) / 2 at
    /// a position of n joints, n m between positions of n and m joints within the
    /// radius.
    pub fn pair_count(&self) -> usize {
        (0..self.positions())
            .map(|p| {
                let n = self.joints_at(p).len();
                let apart: usize = self
                    .positions_after(p)
                    .map(|q| self.joints_at(q).len())
                    .sum();
                n * (n - 1) / 2 + n * apart
            })
            .sum()
    }

    /// The joints at joint j's point with a larger index, increasing.
    pub fn after(&self, j: usize) -> Vec<u32> {
        let mut found: Vec<u32> = self
            .grid
            .within(self.bind[j], self.radius)
            .into_iter()
            .flat_map(|p| self.joints_at(p as usize))
            .copied()
            .filter(|&k| k as usize > j)
            .collect();
        found.sort_unstable();
        found
    }

    /// Whether joints j and k sit at one point.
    pub fn same_point(&self, j: usize, k: usize) -> bool {
        self.bind[j].distance(self.bind[k]) <= self.radius
    }
}

/// Below this many points a scan is cheaper than the grid's shells.
const SCAN_BELOW: usize = 64;

/// The points in the cells of a grid (`mesh::spatial_index::CentreGrid`).
#[derive(Debug, Clone)]
pub struct PointGrid {
    points: Vec<DVec3>,
    grid: CentreGrid,
}

impl PointGrid {
    /// A grid over `points` (about four per cell).
    pub fn new(points: &[DVec3]) -> Self {
        Self {
            points: points.to_vec(),
            grid: CentreGrid::new(points),
        }
    }

    /// The smallest `q.distance(p)` over the points (infinity when there are none): the
    /// same value as a scan of every point.
    pub fn nearest_distance(&self, p: DVec3) -> f64 {
        self.nearest(p)
            .map_or(f64::INFINITY, |(_, distance)| distance)
    }

    /// The index of the point nearest to `p` (the first of equals in a scan's order, in the
    /// grid's order of visits otherwise) and its distance; `None` when there are none.
    pub fn nearest(&self, p: DVec3) -> Option<(usize, f64)> {
        let distance = |k: u32| self.points[k as usize].distance(p);
        let mut best: Option<(usize, f64)> = None;
        let mut offer = |k: u32| {
            let d = distance(k);
            if best.is_none_or(|(_, b)| d < b) {
                best = Some((k as usize, d));
            }
            best.map_or(f64::INFINITY, |(_, b)| b)
        };
        if self.points.len() < SCAN_BELOW {
            (0..self.points.len() as u32).for_each(|k| {
                offer(k);
            });
        } else {
            shells(&self.grid, p, &mut offer);
        }
        best
    }

    /// The indices, increasing, of the points q with `q.distance(p)` ≤ `radius`: the same
    /// as a scan of every point. The cells searched are those of the box around p of half
    /// side radius (1 + 10⁻⁹): a point whose computed distance passes lies in that box
    /// despite the rounding of its distance.
    pub fn within(&self, p: DVec3, radius: f64) -> Vec<u32> {
        let reach = DVec3::splat(radius * (1.0 + 1e-9));
        let (lo, hi) = (self.grid.cell_of(p - reach), self.grid.cell_of(p + reach));
        let mut found: Vec<u32> = self
            .grid
            .faces_in(lo, hi, IVec3::ONE, IVec3::ZERO)
            .filter(|&k| self.points[k as usize].distance(p) <= radius)
            .collect();
        found.sort_unstable();
        found
    }

    /// The points of [`Self::within`] whose signed distance n · (q − p) to the plane
    /// through p with unit normal `normal` lies in `band` (low, high), in the same order,
    /// visiting only the cells that meet the band: a slab across the ball, not the ball.
    /// A cell's centre c reaches the band when n · (c − p) is within the cell's whole
    /// projected extent (cell side × (|n_x| + |n_y| + |n_z|), twice what a point of the
    /// cell can lie from its centre, a margin for the rounding of the cells' bounds); the
    /// cells of a row (y, z) that do are one run of x, n · (c − p) being linear in x.
    pub fn within_band(&self, p: DVec3, radius: f64, normal: DVec3, band: (f64, f64)) -> Vec<u32> {
        let reach = DVec3::splat(radius * (1.0 + 1e-9));
        let grid = &self.grid;
        let (lo, hi) = (grid.cell_of(p - reach), grid.cell_of(p + reach));
        let margin = grid.cell * normal.abs().element_sum();
        let (low, high) = (band.0 - margin, band.1 + margin);
        let step = normal.x * grid.cell;
        let mut found = Vec::new();
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                let first =
                    grid.origin + grid.cell * DVec3::new(0.5, y as f64 + 0.5, z as f64 + 0.5);
                let at_first = normal.dot(first - p);
                let (x0, x1) = if step.abs() <= f64::MIN_POSITIVE {
                    if (low..=high).contains(&at_first) {
                        (lo.x, hi.x)
                    } else {
                        continue;
                    }
                } else {
                    let (a, b) = ((low - at_first) / step, (high - at_first) / step);
                    let (from, to) = (a.min(b).floor(), a.max(b).ceil());
                    (
                        from.max(f64::from(lo.x)) as i32,
                        to.min(f64::from(hi.x)) as i32,
                    )
                };
                found.extend(grid.row(y, z, x0, x1).iter().copied().filter(|&k| {
                    let q = self.points[k as usize];
                    let signed = normal.dot(q - p);
                    q.distance(p) <= radius && band.0 <= signed && signed <= band.1
                }));
            }
        }
        found.sort_unstable();
        found
    }
}

/// Visits the items of `grid` in shells of cells around `p` until none can be nearer than
/// the distance `visit(item)` returns (the best so far). Shell r holds the cells at
/// Chebyshev distance r from p's (clamped) cell; an item in shell r lies at least (r − 1)
/// cells from p (r cells along an axis where p lies outside the grid) and at least as far
/// as p lies outside the grid.
fn shells(grid: &CentreGrid, p: DVec3, visit: &mut impl FnMut(u32) -> f64) {
    let mut best = f64::INFINITY;
    let centre = grid.cell_of(p);
    let outside = (grid.origin - p)
        .max(p - (grid.origin + grid.dims.as_dvec3() * grid.cell))
        .max(DVec3::ZERO)
        .length();
    for r in 0..=grid.dims.max_element() {
        let bound = outside.max((r - 1).max(0) as f64 * grid.cell);
        if bound > best {
            break;
        }
        let (inner_lo, inner_hi) = if r == 0 {
            (IVec3::ONE, IVec3::ZERO)
        } else {
            (centre - IVec3::splat(r - 1), centre + IVec3::splat(r - 1))
        };
        for k in grid.faces_in(
            centre - IVec3::splat(r),
            centre + IVec3::splat(r),
            inner_lo,
            inner_hi,
        ) {
            best = visit(k);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::random_pose::SplitMix64;

    /// Clustered, collinear, coincident and spread points, queried inside and far outside
    /// their box: the same nearest point and distance as a scan of every point, and the same points
    /// within radii of 0, of a point's exact distance (on the ball's boundary), just inside
    /// it, at random and infinite.
    #[test]
    fn grid_answers_as_a_scan() {
        let mut rng = SplitMix64::new(3);
        let mut random =
            |scale: f64| DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * scale;
        let sets: Vec<Vec<DVec3>> = vec![
            Vec::new(),
            vec![DVec3::ONE],
            vec![DVec3::ONE; 5],
            (0..300).map(|k| DVec3::Y * k as f64 * 0.01).collect(),
            (0..500).map(|_| random(2.0)).collect(),
            (0..200)
                .map(|k| {
                    if k % 2 == 0 {
                        random(0.01)
                    } else {
                        random(5.0)
                    }
                })
                .collect(),
        ];
        for points in &sets {
            let grid = PointGrid::new(points);
            let within = |p: DVec3, radius: f64| -> Vec<u32> {
                (0u32..)
                    .zip(points)
                    .filter(|(_, q)| q.distance(p) <= radius)
                    .map(|(k, _)| k)
                    .collect()
            };
            for k in 0..300 {
                let p = random(8.0) - DVec3::splat(2.0);
                let scanned = points
                    .iter()
                    .map(|q| q.distance(p))
                    .fold(f64::INFINITY, f64::min);
                assert_eq!(grid.nearest_distance(p), scanned);
                let nearest = grid.nearest(p);
                assert_eq!(nearest.map(|(_, d)| d), points.first().map(|_| scanned));
                if let Some((i, d)) = nearest {
                    assert_eq!(points[i].distance(p), d);
                }
                let exact = points
                    .get(k % points.len().max(1))
                    .map_or(1.0, |q| q.distance(p));
                for radius in [
                    0.0,
                    exact,
                    exact * (1.0 - 1e-12),
                    random(2.0).x,
                    f64::INFINITY,
                ] {
                    assert_eq!(
                        grid.within(p, radius),
                        within(p, radius),
                        "{p} within {radius}"
                    );
                }
            }
            if let Some(&q) = points.first() {
                assert!(grid.within(q, 0.0).contains(&0));
            }
        }
    }
}

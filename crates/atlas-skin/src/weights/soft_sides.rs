//! Step 3 of the weights, the child sides of the soft boundaries (METHOD.md
//! "extensions"): how far, along the surface, each soft joint's plane moves its region
//! (module documentation of [`crate::weights`]).

use super::blend::beta;
use super::crowding::{Crowding, BATCH};
use super::ownership::{Ownership, OwnershipBones};
use crate::ablation::{Rule, RulesOff};
use crate::decomposition::{Boundary, BoundaryKind, Decomposition};
use crate::geometry::point_segment_distance;
use crate::overlap::Overlaps;
use crate::rows::Rows;
use crate::skeleton::bones::bone_segments;
use crate::skeleton::nearest_point::PointGrid;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashSet;
use std::borrow::Cow;
use std::cell::RefCell;
use std::collections::VecDeque;

/// A soft boundary, ready for step 3.
pub struct SoftSide {
    pub joint: u32,
    pub region: u32,
    point: DVec3,
    normal: DVec3,
    half_width: f64,
    /// (v, κ_c) of every vertex v on the child side reached along the surface, by
    /// increasing vertex (s_c is 0 at the others).
    reached: Vec<(u32, f64)>,
}

impl SoftSide {
    /// The vertices reached along the surface with their κ_c, by increasing vertex.
    pub fn reached(&self) -> &[(u32, f64)] {
        &self.reached
    }

    /// Keeps the reached vertices v for which `keep(v)` holds, in order.
    pub fn retain_reached(&mut self, mut keep: impl FnMut(u32) -> bool) {
        self.reached.retain(|&(v, _)| keep(v));
    }

    /// s_c(p) of the module documentation at a reached vertex at `position`, with its
    /// `kappa` κ_c.
    pub fn share(&self, position: DVec3, kappa: f64) -> f64 {
        let signed = self.normal.dot(position - self.point);
        let w = self.half_width.max(f64::MIN_POSITIVE);
        beta(((w + signed) / (2.0 * w)).clamp(0.0, 1.0)) * kappa
    }
}

/// Step 3's child sides: for each soft boundary (in its region, and in a region that
/// continues that region across a gap below it: `continued_boundaries`), a flood along
/// edges from the vertices of
/// the joint's cross-section (within the band |n·(p − o)| ≤ w and within max(D, w) of the
/// joint), through vertices related to the boundary's region whose signed plane distance
/// exceeds −w and where κ > 0 ([`super::ownership`]). Where none of those vertices
/// qualifies and the joint has child bones (a coarse mesh whose faces are larger than the
/// section: KayKit's hips) or is a leaf whose part runs on past it for its bone's length
/// ([`Boundary::leaf_part_past`]), the seeds are those within d_N + max(D, w), d_N the
/// distance from the joint to the nearest vertex of the surface. Where still none
/// qualifies, a
/// joint with child bones that no region is bound to and that no other bone runs through
/// (a hair card's or a tail's joint beside a sheet, whose band is as thin as its depth)
/// is seeded from its own part: the vertices of its region on the child side of its plane
/// (n·(p − o) > 0) where its own bones are clearly the nearest (κ = 1). Else its region's
/// bound joint moved the whole chain, at bones twice as far as its own
/// (docs/measurements.md, "Own parts of chains on sheets"); such a side leaves alone the
/// vertices where a side below it in its region takes the whole share, which takes its
/// mass there anyway (the sides are found deepest joint first). A soft boundary with no
/// cross-section (diameter 0, or no seed: face bones in a mouth cavity or an eye socket,
/// whose leaf joints are not seeded farther) is inactive: its joint gets no weight and its
/// region's other joints keep it. At most [`super::crowding::MOST_SOFT_SIDES`] sides act at
/// a vertex, the deepest ([`super::crowding`]); returns the sides and how many vertices
/// more would have reached.
pub fn soft_sides(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
    related: &Rows<(u32, f64)>,
    rules_off: &RulesOff,
) -> (Vec<SoftSide>, usize) {
    let d = decomposition;
    let segments = bone_segments(skeleton);
    let bones = OwnershipBones::new(skeleton, &d.joints, &segments);
    // Every soft boundary with a section acts in its region; some also in a region that
    // continues it across a gap.
    let acting: Vec<(usize, Cow<Boundary>)> = d
        .boundaries
        .iter()
        .enumerate()
        .filter(|(_, b)| b.kind == BoundaryKind::Soft && b.diameter > 0.0)
        .map(|(k, b)| (k, Cow::Borrowed(b)))
        .chain(
            continued_boundaries(d, skeleton)
                .into_iter()
                .filter(|_| rules_off.on(Rule::ContinuedSoftSides))
                .map(|(k, b)| (k, Cow::Owned(b))),
        )
        .collect();
    let vertices = NearVertices::new(&d.surface.positions, acting.len());
    let children = skeleton.children();
    // Joints that a region is bound to move skin whatever their soft boundary does.
    let mut bound = vec![false; skeleton.len()];
    for region in &d.regions {
        if let Some(&joint) = region.joints.first() {
            bound[joint as usize] = true;
        }
    }
    let side = |(k, b): &(usize, Cow<Boundary>), taken: &Taken, crowding: &Crowding| {
        let (k, b) = (*k, b.as_ref());
        let half_width = overlaps.half_widths[k];
        let owner = Ownership::new(&bones, b.joint as usize, b.parent_region, half_width);
        // A vertex that enough deeper sides reach is not in play ([`super::crowding`]).
        let refused = RefCell::new(Vec::new());
        let in_region = |v: usize| {
            related.row(v).iter().any(|&(r, _)| r == b.parent_region)
                && (!crowding.full(v) || {
                    refused.borrow_mut().push(v as u32);
                    false
                })
        };
        let has_children = !children[b.joint as usize].is_empty();
        let seeds = Seeds {
            vertices: &vertices,
            beyond_nearest: (has_children || b.leaf_part_past) && rules_off.on(Rule::FartherSeeds),
            own_part: has_children
                && !b.bone_through
                && !bound[b.joint as usize]
                && rules_off.on(Rule::OwnPartSeeds),
            kappa: rules_off.on(Rule::OwnPart),
        };
        let below = |v: usize| taken.below(&bones, v, b.parent_region, b.joint);
        let side = child_side(d, b, half_width, &owner, in_region, below, &seeds);
        (side, refused.into_inner())
    };
    // The deepest joints first, those at one depth in parallel: where a joint's side takes
    // the whole share (s = 1), it takes the mass of every joint above it on its region's
    // chain (module documentation of `weights`, step 3), so the sides of those joints need
    // not reach there. Without this a chain of thousands of soft joints along a sheet,
    // each reaching every vertex below it, cost the product of joints and vertices.
    let mut depth = vec![0usize; skeleton.len()];
    for j in skeleton.topological_order() {
        if let Some(p) = skeleton.parent(j) {
            depth[j] = depth[p] + 1;
        }
    }
    let mut by_depth: Vec<usize> = (0..acting.len()).collect();
    by_depth.sort_by_key(|&i| std::cmp::Reverse(depth[acting[i].1.joint as usize]));
    let mut taken = Taken::new(d.surface.vertex_count());
    let mut crowding = Crowding::new(d.surface.vertex_count());
    let mut sides: Vec<(usize, SoftSide)> = Vec::with_capacity(acting.len());
    for level in by_depth
        .chunk_by(|&a, &b| depth[acting[a].1.joint as usize] == depth[acting[b].1.joint as usize])
    {
        // The level's sides all see the sides of the deeper levels only, whatever their
        // batches.
        let level_start = sides.len();
        for batch in level.chunks(BATCH) {
            let found: Vec<(usize, Option<SoftSide>, Vec<u32>)> = batch
                .par_iter()
                .map(|&i| {
                    let (s, refused) = side(&acting[i], &taken, &crowding);
                    (i, s, refused)
                })
                .collect();
            let mut found: Vec<(usize, SoftSide, Vec<u32>)> = found
                .into_iter()
                .filter_map(|(i, s, refused)| s.map(|s| (i, s, refused)))
                .collect();
            for &v in found.iter().flat_map(|f| &f.2) {
                crowding.refuse(v);
            }
            for (_, side, _) in &mut found {
                side.retain_reached(|v| crowding.admit(v));
            }
            sides.extend(found.into_iter().map(|(i, s, _)| (i, s)));
        }
        for (_, s) in &sides[level_start..] {
            taken.record(s, &d.surface.positions);
        }
    }
    sides.sort_unstable_by_key(|&(i, _)| i);
    let crowded = crowding.crowded_vertices();
    (sides.into_iter().map(|(_, s)| s).collect(), crowded)
}

/// Per vertex, a soft side that takes the whole share there (s = 1), by its region and
/// joint: the deepest recorded first ([`soft_sides`]).
struct Taken {
    /// #V (region, joint) of a side with s = 1 at the vertex.
    by: Vec<Option<(u32, u32)>>,
}

impl Taken {
    fn new(vertex_count: usize) -> Self {
        Self {
            by: vec![None; vertex_count],
        }
    }

    /// Records where `side` takes the whole share, where no side did before.
    fn record(&mut self, side: &SoftSide, positions: &[DVec3]) {
        for &(v, kappa) in side.reached() {
            let slot = &mut self.by[v as usize];
            if slot.is_none() && side.share(positions[v as usize], kappa) >= 1.0 {
                *slot = Some((side.region, side.joint));
            }
        }
    }

    /// Whether a side of a joint strictly below `joint` (in the skeleton of `bones`) in
    /// `region` takes the whole share at `v`.
    fn below(&self, bones: &OwnershipBones, v: usize, region: u32, joint: u32) -> bool {
        self.by[v]
            .is_some_and(|(r, d)| r == region && bones.strictly_below(d as usize, joint as usize))
    }
}

/// The soft boundaries that also act in a region continuing their region across a gap,
/// each as (boundary index, the boundary with that region on both sides). A region whose
/// joint nearest the root was moved there by the holding rule continues its parent's
/// region and is bound to the joint that region is bound to (`regions::bind_regions`); the
/// soft joints between that bound joint and a joint the region holds, which lie in the
/// parent's region, bend it too: a hair piece bound to the neck that holds the ponytail's
/// second joint also bends at its first, whose joint lies in the head (rignet-val/3615,
/// docs/measurements.md, "Soft joints above a continued region").
fn continued_boundaries(d: &Decomposition, skeleton: &Skeleton) -> Vec<(usize, Boundary)> {
    let mut continued = Vec::new();
    let mut seen = FxHashSet::default();
    for (r, region) in d.regions.iter().enumerate() {
        let r = r as u32;
        let Some((&bound, held)) = region.joints.split_first() else {
            continue;
        };
        if d.joints[bound as usize].region == Some(r) {
            continue;
        }
        for &h in held {
            for a in skeleton.ancestors(h as usize) {
                if a == bound as usize || d.joints[a].region == Some(r) {
                    break;
                }
                let Some(k) = d.joints[a].boundary.map(|k| k as usize) else {
                    continue;
                };
                let b = &d.boundaries[k];
                let acts = b.kind == BoundaryKind::Soft && b.diameter > 0.0;
                if acts && b.parent_region != r && seen.insert((k, r)) {
                    let in_region = Boundary {
                        parent_region: r,
                        child_region: r,
                        ..b.clone()
                    };
                    continued.push((k, in_region));
                }
            }
        }
    }
    continued
}

/// Below this many soft boundaries their seeds come from a scan of the surface's vertices.
/// (A tree of the vertices, which the grid replaced, cost about as much to build as 50
/// scans: 4.5 M instructions on the 3,273 vertices of cesiumman, which has one soft
/// boundary, and 32 M on makehuman's 13,380.)
const SCANNED_BOUNDARIES: usize = 32;

/// The surface's vertices within a distance of a point, increasing, and the distance to
/// the nearest, the distance from the point to a vertex q being [`point_segment_distance`]
/// to q as a segment (which is `q.distance(p)`): by a scan, or from a grid of the vertices
/// ([`PointGrid`], the same answers).
enum NearVertices<'a> {
    Scan(&'a [DVec3]),
    Grid(PointGrid),
}

impl<'a> NearVertices<'a> {
    /// A scan below [`SCANNED_BOUNDARIES`] queries, else the grid.
    fn new(positions: &'a [DVec3], queries: usize) -> Self {
        if queries < SCANNED_BOUNDARIES {
            return Self::Scan(positions);
        }
        Self::Grid(PointGrid::new(positions))
    }

    /// The vertices q within `radius` of `p` whose signed distance n · (q − p) to the plane
    /// through p with unit normal `normal` lies in `band` (low, high), increasing.
    fn within_band(&self, p: DVec3, radius: f64, normal: DVec3, band: (f64, f64)) -> Vec<u32> {
        match self {
            Self::Scan(positions) => (0u32..)
                .zip(positions.iter())
                .filter(|&(_, &q)| {
                    let signed = normal.dot(q - p);
                    q.distance(p) <= radius && band.0 <= signed && signed <= band.1
                })
                .map(|(v, _)| v)
                .collect(),
            Self::Grid(grid) => grid.within_band(p, radius, normal, band),
        }
    }

    /// The distance from `p` to the nearest vertex (infinity when there is none).
    fn nearest(&self, p: DVec3) -> f64 {
        match self {
            Self::Scan(positions) => positions
                .iter()
                .map(|&q| point_segment_distance(p, q, q))
                .fold(f64::INFINITY, f64::min),
            Self::Grid(grid) => grid.nearest_distance(p),
        }
    }
}

/// Where a soft boundary's flood starts: the surface's vertices as points, whether the
/// seeds may lie beyond the nearest vertex (a joint with child bones, or a leaf whose part
/// runs on past it), and whether, failing all else, they may be its own part (a joint with
/// child bones that no region is bound to and that no other bone runs through).
struct Seeds<'a> {
    vertices: &'a NearVertices<'a>,
    beyond_nearest: bool,
    own_part: bool,
    /// Whether κ_c applies (else 1): a developer switch ([`crate::ablation`]).
    kappa: bool,
}

/// The child side of the soft boundary `b` (half-width `half_width`, κ from `owner`): the
/// flood of [`soft_sides`] from the vertices near the joint (found in `seeds`), through
/// vertices where `in_region` holds (those the region reaches); `None` when no seed
/// qualifies (an inactive boundary).
fn child_side(
    d: &Decomposition,
    b: &Boundary,
    half_width: f64,
    owner: &Ownership,
    in_region: impl Fn(usize) -> bool,
    taken_below: impl Fn(usize) -> bool,
    seeds: &Seeds,
) -> Option<SoftSide> {
    let positions = &d.surface.positions;
    let signed = |v: usize| b.normal.dot(positions[v] - b.point);
    // Every vertex is examined once: κ depends on the vertex alone. (A set, not one bit
    // per vertex of the surface: thousands of soft boundaries each reach a few vertices;
    // hashed by Fx: the keys are vertex indices, not input an attacker chooses.)
    let mut examined = FxHashSet::default();
    // Seeded from its own part, the side leaves alone where a side below takes all.
    let own_part = std::cell::Cell::new(false);
    let mut reached = Vec::new();
    let mut queue = VecDeque::new();
    let mut visit = |v: u32, queue: &mut VecDeque<u32>| {
        if !examined.insert(v) {
            return;
        }
        if !in_region(v as usize) || (own_part.get() && taken_below(v as usize)) {
            return;
        }
        if signed(v as usize) <= -half_width {
            return;
        }
        let p = positions[v as usize];
        let kappa = if seeds.kappa { owner.at(p) } else { 1.0 };
        if kappa > 0.0 {
            reached.push((v, kappa));
            queue.push_back(v);
        }
    };
    // The seeds: the vertices near the joint (`visit` keeps those of the region; the
    // flood's result does not depend on their order).
    let seed_radius = b.diameter.max(half_width);
    let near_band = |radius: f64| {
        let band = (-half_width, half_width);
        seeds.vertices.within_band(b.point, radius, b.normal, band)
    };
    for v in near_band(seed_radius) {
        visit(v, &mut queue);
    }
    if queue.is_empty() && seeds.beyond_nearest {
        for v in near_band(seeds.vertices.nearest(b.point) + seed_radius) {
            visit(v, &mut queue);
        }
    }
    if queue.is_empty() && seeds.own_part {
        // No vertex near the joint: its own part, where its own bones are clearly the
        // nearest, on the child side of its plane.
        own_part.set(true);
        for (v, &p) in positions.iter().enumerate() {
            if signed(v) > 0.0 && !taken_below(v) && in_region(v) && owner.at(p) >= 1.0 {
                visit(v as u32, &mut queue);
            }
        }
    }
    if queue.is_empty() {
        return None;
    }
    while let Some(v) = queue.pop_front() {
        for &u in d.topology.neighbors(v as usize) {
            visit(u, &mut queue);
        }
    }
    reached.sort_unstable_by_key(|&(v, _)| v);
    Some(SoftSide {
        joint: b.joint,
        region: b.parent_region,
        point: b.point,
        normal: b.normal,
        half_width,
        reached,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::random_pose::SplitMix64;
    use atlas_skin_runtime::NO_PARENT;

    /// A side stops only where a side of a joint strictly below its own, in its own
    /// region, takes the whole share: root → a → b and root → c.
    #[test]
    fn a_side_stops_only_where_a_side_below_it_in_its_region_takes_all() {
        let names = ["root", "a", "b", "c"].map(String::from).to_vec();
        let positions = [0.0, 1.0, 2.0, 3.0].map(|y| glam::Vec3::new(0.0, y, 0.0));
        let skeleton = Skeleton::from_positions(names, vec![NO_PARENT, 0, 1, 0], &positions)
            .expect("skeleton");
        let decisions = super::super::ownership::one_region_decisions(4, 5);
        let bones = OwnershipBones::new(&skeleton, &decisions, &bone_segments(&skeleton));
        let mut taken = Taken::new(2);
        taken.by[0] = Some((5, 2));
        for (region, joint, below) in [
            (5, 1, true),
            (5, 0, true),
            (5, 2, false),
            (5, 3, false),
            (4, 1, false),
        ] {
            assert_eq!(
                taken.below(&bones, 0, region, joint),
                below,
                "{region} {joint}"
            );
        }
        // Nothing taken at vertex 1.
        assert!(!taken.below(&bones, 1, 5, 0));
    }

    /// The scan of the vertices finds what the grid of the vertices finds, at radii of 0, at
    /// a vertex's exact distance (on the ball's boundary), just inside it and at random,
    /// in bands across planes at random: unbounded, around the point, and ending at a
    /// vertex's exact signed distance, just short of it and past it.
    #[test]
    fn the_scan_finds_the_vertices_and_the_nearest_distance_the_grid_finds() {
        let mut rng = SplitMix64::new(3);
        let mut point = || DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64());
        let positions: Vec<DVec3> = (0..500).map(|_| point()).collect();
        let scan = NearVertices::new(&positions, SCANNED_BOUNDARIES - 1);
        let grid = NearVertices::new(&positions, SCANNED_BOUNDARIES);
        assert!(matches!(
            (&scan, &grid),
            (NearVertices::Scan(_), NearVertices::Grid(_))
        ));
        let everywhere = (f64::NEG_INFINITY, f64::INFINITY);
        let (mut banded, mut left_out) = (0, 0);
        for (k, &vertex) in positions.iter().enumerate().take(50) {
            let p = point();
            let normal = match k % 5 {
                0 => DVec3::X,
                _ => (point() - DVec3::splat(0.5)).normalize(),
            };
            assert_eq!(scan.nearest(p), grid.nearest(p), "nearest to {p}");
            let exact = p.distance(vertex);
            let at = normal.dot(vertex - p);
            for radius in [0.0, exact, exact * (1.0 - 1e-12), 0.3 * point().x, 2.0] {
                let found = scan.within_band(p, radius, normal, everywhere);
                let from_grid = grid.within_band(p, radius, normal, everywhere);
                assert_eq!(found, from_grid, "{p} within {radius}");
                assert_eq!(found.contains(&(k as u32)), radius >= exact);
                let short = at - at.abs() * 1e-12;
                for band in [(-0.1, 0.1), (at, at + 0.05), (at - 0.05, at), (-1.0, short)] {
                    let expected: Vec<u32> = found
                        .iter()
                        .copied()
                        .filter(|&v| {
                            (band.0..=band.1).contains(&normal.dot(positions[v as usize] - p))
                        })
                        .collect();
                    assert_eq!(scan.within_band(p, radius, normal, band), expected);
                    assert_eq!(grid.within_band(p, radius, normal, band), expected);
                    banded += expected.len();
                    left_out += found.len() - expected.len();
                }
            }
        }
        assert!(banded > 100 && left_out > 100, "{banded} {left_out}");
        assert_eq!(
            scan.within_band(positions[7], 0.0, DVec3::Y, everywhere),
            [7]
        );
    }
}

//! Rule 5's question at a leaf joint ([`super::joint_roles`], rule 5 (b) and (c)): does
//! the part of the surface nearest to the leaf reach a given distance past it? That part is
//! the set of surface vertices v nearer to the leaf's point p than to every bone not at the
//! leaf; the question is whether one of them with reach ≤ |v − p| ≤ 2 reach lies past p
//! within 60° of the leaf's bone.
//!
//! Such a v has the leaf's own bone among its nearest bones: that bone ends at p, so its
//! distance to v is at most |v − p|, while every other bone is farther than |v − p|. So
//! only the vertices whose nearest bones include a bone at the leaf are asked
//! ([`LeafReach`]), each vertex under its nearest bones, found once for all leaves: the
//! work over all leaves is bounded by the surface's vertices, where asking the vertices of
//! the faces within 2 reach of p (`leaf_reaches_in_ball`, the reference) cost a leaf deep
//! in a blob most of the surface (a tree of 4,096 leaves spread through a sphere of
//! 100,000 vertices: two thirds of its decomposition, issue 45). A vertex with more than
//! `MOST_NEAREST` nearest bones (bones lying along one another: thousands of siblings of
//! one root along a tube are all as near to each vertex of the tube) is listed under none
//! and asked by every leaf whose ball holds it, from a grid of those vertices, as the
//! reference asks every vertex.

use crate::geometry::point_segment_distance;
use crate::mesh::spatial_index::FaceSpheres;
use crate::mesh::SurfaceMesh;
use crate::rows::{Rows, PAR_CHUNK};
use crate::skeleton::bones::BoneIndex;
use crate::skeleton::nearest_point::PointGrid;
use glam::DVec3;

/// Rule 5 counts the vertices within 60° of the leaf's bone (cos 60° = ½): toes turn
/// about 45° from a foot bone, while the rim of a broad flat end (a pad under an end site)
/// lies across it.
const PAST_COSINE: f64 = 0.5;

/// A bone is among a vertex's nearest when its distance is within this fraction of the
/// nearest one's: far above the rounding of the distances (a few units in the last
/// place), so that a vertex is listed under every bone that may compute as near as the
/// nearest, the leaf's own bone included.
const NEAREST_TIE: f64 = 1e-6;

/// A vertex is listed under at most this many nearest bones (a real rig's bones meet a few
/// at a joint).
const MOST_NEAREST: usize = 8;

/// What rule 5's question reads: the surface, its faces indexed, the skeleton's bones, and
/// each bone's vertices (those of some face whose nearest bones include it).
pub struct LeafReach<'a> {
    mesh: &'a SurfaceMesh,
    spheres: &'a FaceSpheres,
    bones: &'a BoneIndex,
    /// The bones with an end at each joint.
    bones_at: Rows<u32>,
    /// The vertices, increasing, of each bone.
    vertices_of: Rows<u32>,
    /// The vertices of some face with more than `MOST_NEAREST` nearest bones,
    /// increasing, and a grid of their positions (when there are some).
    crowded: Vec<u32>,
    crowded_grid: Option<PointGrid>,
}

impl<'a> LeafReach<'a> {
    /// `joint_count`: the skeleton's joints (of which `bones` joins pairs).
    pub fn new(
        mesh: &'a SurfaceMesh,
        spheres: &'a FaceSpheres,
        bones: &'a BoneIndex,
        joint_count: usize,
    ) -> Self {
        let pairs = bones.pairs();
        let ends = (0u32..)
            .zip(pairs)
            .flat_map(|(k, &(p, c))| [(p, k), (c, k)]);
        let bones_at = Rows::group(joint_count, ends);
        let mut on_face = vec![false; mesh.vertex_count()];
        for &[a, b, c] in &mesh.triangles {
            for v in [a, b, c] {
                on_face[v as usize] = true;
            }
        }
        // Each vertex's nearest bones, or `None` (as one entry) for a crowded vertex.
        let nearest: Rows<Option<u32>> = Rows::par_build(
            mesh.vertex_count(),
            PAR_CHUNK,
            |v, _: &mut (), out: &mut Vec<Option<u32>>| {
                if on_face[v] {
                    let p = mesh.positions[v];
                    match bones.nearest_bones(p, NEAREST_TIE, MOST_NEAREST) {
                        Some(near) => out.extend(near.into_iter().map(Some)),
                        None => out.push(None),
                    }
                }
            },
        );
        let listed = (0..mesh.vertex_count()).flat_map(|v| {
            let row = nearest.row(v).iter();
            row.filter_map(move |&k| k.map(|k| (k as usize, v as u32)))
        });
        let vertices_of = Rows::group(pairs.len(), listed);
        let crowded: Vec<u32> = (0..mesh.vertex_count() as u32)
            .filter(|&v| nearest.row(v as usize) == [None])
            .collect();
        let crowded_grid = (!crowded.is_empty()).then(|| {
            let at: Vec<DVec3> = crowded
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .collect();
            PointGrid::new(&at)
        });
        Self {
            mesh,
            spheres,
            bones,
            bones_at,
            vertices_of,
            crowded,
            crowded_grid,
        }
    }

    /// Whether the part past leaf joint `leaf` at `p` reaches `reach` from it (module
    /// documentation), within 60° of the unit `direction`; with `on_piece` (the connected
    /// piece of every vertex, and one), only vertices of that piece count. A leaf with no
    /// bone of its own (both ends of its bones at one point) is asked by the ball.
    pub fn reaches(
        &self,
        leaf: usize,
        p: DVec3,
        direction: DVec3,
        reach: f64,
        on_piece: Option<(&[u32], u32)>,
    ) -> bool {
        let own = self.bones_at.row(leaf);
        if own.is_empty() {
            return leaf_reaches_in_ball(
                self.mesh,
                self.spheres,
                self.bones,
                leaf,
                (p, direction, reach),
                on_piece,
            );
        }
        let shell = Shell::new(self.mesh, p, direction, reach, on_piece);
        let crowded = self
            .crowded_grid
            .iter()
            .flat_map(|grid| grid.within(p, 2.0 * reach))
            .map(|i| self.crowded[i as usize]);
        let mut vertices: Vec<u32> = own
            .iter()
            .flat_map(|&k| self.vertices_of.row(k as usize))
            .copied()
            .chain(crowded)
            .filter(|&v| shell.holds(v))
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        shell.any_nearer_than_other_bones(self.bones, leaf, vertices)
    }
}

/// The vertices of rule 5's question at one leaf: reach ≤ |v − p| ≤ 2 reach, past p within
/// 60° of `direction`, on the piece when one is given.
struct Shell<'a> {
    mesh: &'a SurfaceMesh,
    p: DVec3,
    direction: DVec3,
    reach: f64,
    on_piece: Option<(&'a [u32], u32)>,
}

impl<'a> Shell<'a> {
    fn new(
        mesh: &'a SurfaceMesh,
        p: DVec3,
        direction: DVec3,
        reach: f64,
        on_piece: Option<(&'a [u32], u32)>,
    ) -> Self {
        Self {
            mesh,
            p,
            direction,
            reach,
            on_piece,
        }
    }

    fn holds(&self, v: u32) -> bool {
        let q = self.mesh.positions[v as usize];
        let d = q.distance(self.p);
        (self.reach..=2.0 * self.reach).contains(&d)
            && (q - self.p).dot(self.direction) >= PAST_COSINE * d
            && self
                .on_piece
                .is_none_or(|(pieces, piece)| pieces[v as usize] == piece)
    }

    /// Whether one of `vertices` (of the shell) is nearer to p than to every bone not at
    /// `leaf`.
    fn any_nearer_than_other_bones(
        &self,
        bones: &BoneIndex,
        leaf: usize,
        vertices: Vec<u32>,
    ) -> bool {
        if vertices.is_empty() {
            return false;
        }
        // A bone nearer than p to a vertex within ρ = 2 reach of p lies within 2ρ of p (3ρ
        // leaves room for rounding): the others need no test.
        let other_bones = bones.near(leaf, self.p, 6.0 * self.reach);
        vertices.into_iter().any(|v| {
            let q = self.mesh.positions[v as usize];
            let d = q.distance(self.p);
            !other_bones
                .iter()
                .any(|&[a, b]| point_segment_distance(q, a, b) <= d)
        })
    }
}

/// [`LeafReach::reaches`] asked of the vertices of every face within 2 reach of p: the
/// definition, and the reference of the tests. `question`: (p, direction, reach).
fn leaf_reaches_in_ball(
    mesh: &SurfaceMesh,
    spheres: &FaceSpheres,
    bones: &BoneIndex,
    leaf: usize,
    (p, direction, reach): (DVec3, DVec3, f64),
    on_piece: Option<(&[u32], u32)>,
) -> bool {
    let shell = Shell::new(mesh, p, direction, reach, on_piece);
    let mut vertices: Vec<u32> = spheres
        .faces_near(p, 2.0 * reach)
        .into_iter()
        .flat_map(|f| mesh.triangles[f as usize])
        .filter(|&v| shell.holds(v))
        .collect();
    vertices.sort_unstable();
    vertices.dedup();
    shell.any_nearer_than_other_bones(bones, leaf, vertices)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::shapes::capsule_chain;
    use crate::mesh::Topology;
    use atlas_skin_runtime::random_pose::SplitMix64;

    /// The answer from each bone's vertices is the ball's at every leaf of random trees
    /// spread through a tube and a sphere (leaves deep in the body, beside other bones, at
    /// a parent's point: no bone of their own) and of siblings along one line (crowded
    /// vertices), for reaches from a hundredth of the body to
    /// all of it, in random directions, with and without a piece; both answers occur.
    #[test]
    fn each_bones_vertices_answer_as_the_ball() {
        let mut rng = SplitMix64::new(45);
        let (tube, _) = capsule_chain(&[DVec3::ZERO, 2.0 * DVec3::Y], &[], 0.4, 16, 24);
        let sphere = crate::fixtures::shapes::icosphere(1.0, 4);
        let (mut yes, mut no, mut crowded) = (0, 0, 0);
        for mesh in [&tube, &sphere] {
            let spheres = FaceSpheres::new(mesh);
            let pieces = Topology::new(mesh).vertex_component;
            let (lo, hi) = mesh.bounding_box();
            let point = |rng: &mut SplitMix64| {
                lo + (hi - lo) * DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64())
            };
            for trial in 0..7 {
                // A random tree of 60 joints, the last few at their parent's point; last,
                // 59 siblings of one root along a line through the body (bones lying along
                // one another: crowded vertices).
                let mut positions = vec![point(&mut rng)];
                let mut parents = vec![usize::MAX];
                let line = (positions[0], point(&mut rng));
                for j in 1..60 {
                    let parent = if trial == 6 {
                        0
                    } else {
                        (rng.next_f64() * j as f64) as usize
                    };
                    parents.push(parent);
                    let at = if trial == 6 {
                        line.0.lerp(line.1, j as f64 / 59.0)
                    } else if j >= 56 {
                        positions[parent]
                    } else {
                        point(&mut rng)
                    };
                    positions.push(at);
                }
                let pairs: Vec<(usize, usize)> = (1..60)
                    .map(|c| (parents[c], c))
                    .filter(|&(p, c)| positions[p] != positions[c])
                    .collect();
                let bones = BoneIndex::new(pairs, &positions);
                let fast = LeafReach::new(mesh, &spheres, &bones, positions.len());
                crowded += fast.crowded.len();
                for leaf in (1..60).filter(|j| !parents.contains(j)) {
                    for reach in [0.01, 0.1, 0.3, 1.0, 3.0] {
                        let direction = (point(&mut rng) - point(&mut rng)).normalize_or(DVec3::Y);
                        let p = positions[leaf];
                        for on_piece in [None, Some((&pieces[..], 0))] {
                            let by_bones = fast.reaches(leaf, p, direction, reach, on_piece);
                            let question = (p, direction, reach);
                            let in_ball = leaf_reaches_in_ball(
                                mesh, &spheres, &bones, leaf, question, on_piece,
                            );
                            assert_eq!(by_bones, in_ball, "leaf {leaf} reach {reach}");
                            if by_bones {
                                yes += 1;
                            } else {
                                no += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(yes > 50 && no > 50 && crowded > 0, "{yes} {no} {crowded}");
    }
}

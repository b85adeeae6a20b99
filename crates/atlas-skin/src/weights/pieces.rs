//! Step 5 of the weights: every piece of the surface weighted on purpose.
//!
//! A piece is a connected component of the split surface (faces joined across edges,
//! cut curves included). After steps 1–3 a piece either holds regions with joints (a bone
//! runs through it and the decomposition cut it at the joints it holds: **body**) or holds
//! none (an eye, a hat, a belt, a shell whose joints were bound to another piece). Each
//! piece of the second kind is treated as a whole, by the geometry, with no flag. The
//! bones a piece *holds* are those that run inside it, for at least half their length
//! when some do (`held_bones`: a boot holds the foot's bones, a helmet the head's, an
//! upper-arm shell the upper arm's), else those that poke into it and are the nearest
//! bones to most of it, else, when no bone enters it, the bones around it
//! (`bones_around`: a hat above the head joint). A piece that encloses a *free* joint (no
//! boundary of its own, moving skin, bones no piece holds, no sibling at its point: the
//! root, an end site) holds that joint's bones and keeps, of the others, only those that
//! run inside it for half their length and do not leave it on the way from that joint
//! (`with_enclosed_joints`: a pedestal the feet stand in moves with the root, a wand with
//! its own joint, a head around a cap's joint bends between the two). When it holds some,
//! only they are its candidates,
//! otherwise the bones of the joints that carry it where it touches the body (**contact**,
//! below: a braid hanging from the head over the shoulder, a hair card). With J(p) the
//! joint of the candidate
//! bone segment nearest to p and d_B(p) the distance to it
//! ([`crate::skeleton::bones`]), J the most frequent J(p) over the piece, d_S(p) the
//! distance from p to the body surface S (the faces of body regions whose three corners
//! have weights; for a piece that holds no bone, also the faces of the pieces that hold
//! bones, weighted first: a hat sits on a head piece), in this order:
//!
//! 1. **rigid** to J when every J(p) = J: no joint's bisecting surface passes through the
//!    piece (eyes, buttons, armour plates, hats); every vertex gets weight 1 on J.
//! 2. **attached** to the body it sits on when d_S(p) < d_B(p) at every vertex: the body
//!    surface lies between the piece and its bones (clothes, belts, hair over the skin).
//!    Each vertex p takes the weights of the nearest point q = u a + v b + w c of S,
//!    interpolated over its face: w(p) = u w(a) + v w(b) + w w(c), so the piece bends
//!    where the body under it bends. A piece that holds no bone takes them only in its
//!    contact zone; every other vertex takes the row of the contact vertex nearest to it
//!    along the piece's edges (a lock of hair moves with the scalp it grows from, not with
//!    the shoulder its tip hangs over). The piece then moves with one part of the
//!    skeleton, the one that carries most of it ([`super::carriers`]: a knee pad reaching
//!    onto the other knee stays on its own).
//! 3. **rigid** to J when the piece is small next to J's bone: its bounding-box diagonal
//!    is at most L_J, the length of J's longest bone segment.
//! 4. **joints** otherwise: the piece spans a joint with no body beneath and no cut of its
//!    own (an arm modelled apart from the torso, an open sleeve) and bends at the boundary
//!    planes of the joints it holds, or, holding none, of the joints of its vertices'
//!    nearest bones (`HeldJoints`), with the transition of §4 across each plane: for a
//!    vertex p whose nearest of those bones is J's, the weight flows from the root of J's
//!    chain among those joints down to J, each joint c on the way passing on the share
//!    s_c(p) = β(clamp((w_c + n_c·(p − o_c)) / (2 w_c), 0, 1)) of its boundary (plane
//!    point o_c, normal n_c to the child side, half-width w_c of [`crate::overlap`]); J
//!    passes s_c(p) on to each of its children among them that has a boundary.
//!
//! Measured on the 64 scored characters of `../shared/data/bench` (docs/pieces.md):
//! attaching every piece whose vertices are mostly nearer to S than to a bone raised the
//! average deform mean from .0140 to .0162 (limb pieces beside the torso took the torso's
//! weights); the order above gives .0139 / .233 against .0140 / .239. Restricting the
//! candidates to the held bones then took .0127 / .229 to .0116 / .207 (33 characters
//! better on the mean, 6 worse; a shoe no longer takes the other foot, a head shell no
//! longer takes the hand that rests beside it). Holding a bone only for at least half its
//! length when some bone is held that far: .0097 / .191 to .0095 / .187, fallback share
//! 10.5% to 4.6% (21 characters better on the mean, 3 worse). Bending the pieces that hold
//! bones at their joints' planes instead of binding each vertex to its nearest held bone:
//! averages unchanged (3 characters better on the mean, 3 worse, all within 3%), fallback
//! share 4.6% to 2.2%; bending the pieces that hold none at the joints of their vertices'
//! nearest bones likewise: .0088 / .184 to .0088 / .183, fallback share 2.2% to 0.9%.
//! Weighting the pieces that hold bones first and letting the others sit on them too:
//! .0088 / .183 to .0084 / .176 (17 characters better on the mean, 6 worse; KayKit's
//! helmets and hoods now move with the head piece they sit on). A bone that only pokes into
//! a piece holding none for half its length is held only when it is the nearest bone to at
//! least half of the piece's vertices (2026-12-03, 8b26b8b: a strap across a chest that a
//! clavicle's bone crosses moved rigidly with the clavicle): deform mean −1.0%, max −0.9%
//! (7 characters better, 4 worse). A piece that no bone enters holds the bones around it
//! (2026-12-03, 22c13c7: KayKit Mage's hat was carried by the shoulders its brim lies on):
//! deform mean −1.2%, max −2.0% (7 characters better, 4 worse). A piece around a free joint
//! holds its bones (2026-12-03, e3e8b3a): around the root, rignet-val/9826's pedestal (bent
//! between the feet that stand in it, max .454; its artist binds it to the root): deform
//! mean −6.5%, max −5.0%, on that one character; around end sites, 12913's wand, 6789's and
//! 6808's heads around a cap's joint: mean −1.7%, max −0.6% more (3 better, 1 worse within
//! 1%).
//!
//! **Contact.** A piece that holds no bone is carried by the body where it touches it.
//! With d_S(p) as above and s the piece's bounding-box diagonal, its contact zone is
//! C = {p : d_S(p) ≤ min_q d_S(q) + γ s}, γ = `CONTACT_SHARE` = 0.2, and the joints
//! that carry it are K = {the joint of largest weight at the body point nearest to p :
//! p ∈ C}; its candidates are the bones of K (every bone when K has none). Before, every
//! bone was a candidate and every attached vertex took its own nearest body point: a hair
//! lock or a brim beside an arm took the arm. Measured on the 64 scored bench characters
//! (docs/pieces.md): deform mean .0083 → .0082, max .173 → .160 (mean 19 better, 9 worse;
//! max 8 better, none worse); γ from 0.05 to 0.5 gives max .160–.163, 0.2 the fewest
//! characters worse.
//!
//! **Gaps.** Inside a body piece, the vertices that no region with joints reaches (a region
//! left without joints beside cut ones: a head whose neck joint found no cross-section, a
//! ponytail welded to it) form gaps: classes of such vertices joined by edges. Each gap is
//! weighted as a whole by the same rules, as if it were a piece made of the faces that
//! touch it: a head gap holds the neck's bone and moves rigidly with it. Before, a gap's
//! vertices copied the weights of the nearest weighted vertex along the piece's edges (a
//! fallback: 500 vertices in 5 of the 65 bench characters); weighted as wholes: deform
//! mean .0084 → .0083, max .176 → .173 (mean 3 characters better, 2 worse: rignet-val/3613
//! .0079 → .0030, 3615 .0046 → .0022 and max .269 → .071; 10563 +5%, 7219 +5%), the clean
//! corpus unchanged. No vertex of a piece is left to a fallback.

use super::carriers::on_one_carrier;
pub use super::surface_weights::{GapWeighting, PieceTreatment, PieceWeighting};
use super::surface_weights::{SurfaceWeights, WeightCounts};
use crate::ablation::{Rule, RulesOff};
use crate::decomposition::Decomposition;
use crate::mesh::edge_distance::Nearest;
use crate::mesh::topology::Topology;
use crate::mesh::winding::faces_inside;
use crate::mesh::{FaceSpheres, SurfaceMesh};
use crate::overlap::Overlaps;
use crate::skeleton::bone_tree::BoneTree;
use crate::skeleton::bones::{bone_segments, nearest_bone_with_distance, NearestBone};
use crate::skeleton::nearest_point::JointPoints;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::{BinaryHeap, HashMap};
use std::sync::OnceLock;

/// Step 5: weights every vertex steps 1–3 left without weights, piece by piece (module
/// documentation); returns the counts and how each piece was weighted.
pub fn weight_pieces(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
    weights: &mut SurfaceWeights,
    rules_off: &RulesOff,
) -> WeightCounts {
    let surface = &decomposition.surface;
    let n = weights.vertex_count();
    let empty: Vec<bool> = (0..n)
        .map(|v| weights.offsets[v] == weights.offsets[v + 1])
        .collect();
    let topology = &decomposition.topology;
    let (piece_of, piece_count) = (&topology.vertex_component, topology.component_count);
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); piece_count];
    for (v, &c) in piece_of.iter().enumerate() {
        members[c as usize].push(v as u32);
    }
    let is_body: Vec<bool> = members
        .iter()
        .map(|vs| vs.iter().any(|&v| !empty[v as usize]))
        .collect();
    let mut pieces: Vec<PieceWeighting> = members
        .iter()
        .map(|vs| PieceWeighting {
            treatment: PieceTreatment::Body,
            vertices: vs.len(),
        })
        .collect();
    let unreachable = empty.iter().filter(|&&e| e).count();
    let mut counts = WeightCounts {
        unreachable,
        ..WeightCounts::default()
    };
    if unreachable == 0 {
        counts.pieces = pieces;
        return counts;
    }

    let mut rows: Vec<Option<Row>> = vec![None; n];
    let segments = bone_segments(skeleton);
    let mut faces: Vec<Vec<[u32; 3]>> = vec![Vec::new(); piece_count];
    for t in &surface.triangles {
        faces[piece_of[t[0] as usize] as usize].push(*t);
    }
    // What is weighted as a whole: the pieces without weights, then the gaps of the body
    // pieces (their parts that no region with joints reaches).
    let mut units: Vec<Unit> = Vec::new();
    if !segments.is_empty() {
        units.extend((0..piece_count).filter(|&c| !is_body[c]).map(|c| Unit {
            vertices: std::mem::take(&mut members[c]),
            faces: std::mem::take(&mut faces[c]),
            piece: c,
            gap: false,
        }));
        units.extend(body_gaps(decomposition, &empty, &is_body, piece_of));
    }
    // Built when a piece holds bones only where they poke into it.
    let bone_tree = OnceLock::new();
    let nearest_joint = |p: DVec3| {
        let tree: &BoneTree = bone_tree.get_or_init(|| {
            let ends: Vec<[DVec3; 2]> = segments.iter().map(|&(_, a, b)| [a, b]).collect();
            BoneTree::of_segments(&ends)
        });
        tree.within(p, tree.nearest(p))
            .into_iter()
            .min()
            .map(|k| segments[k as usize].0)
    };
    let held: Vec<HeldBones> = units
        .par_iter()
        .map(|unit| {
            held_bones(
                surface,
                &unit.vertices,
                &unit.faces,
                &segments,
                &nearest_joint,
                rules_off,
            )
        })
        .collect();
    let held = if rules_off.on(Rule::PiecesEnclosedJoints) {
        with_enclosed_joints(decomposition, skeleton, &units, held, &segments)
    } else {
        held.into_iter().map(|h| h.segments).collect()
    };
    let planes = boundary_planes(decomposition, overlaps);
    // Pieces that hold bones first, on the body surface; then the pieces that hold none,
    // on the body surface and the pieces of the first pass (a hat sits on a head piece).
    let mut body_faces: Vec<[u32; 3]> = surface
        .triangles
        .iter()
        .zip(&decomposition.face_region)
        .filter(|(_, &r)| !decomposition.regions[r as usize].joints.is_empty())
        .map(|(t, _)| *t)
        .collect();
    let mut current = weights.clone();
    for holding in [true, false] {
        let pass: Vec<usize> = (0..units.len())
            .filter(|&k| held[k].is_empty() != holding)
            .collect();
        if pass.is_empty() {
            continue;
        }
        // Indexed only when a piece of the pass asks for it (in many passes every piece is
        // rigid to its held bones).
        let body = OnceLock::new();
        let loose_piece = LoosePiece {
            surface,
            topology: &decomposition.topology,
            body: &body,
            body_faces: &body_faces,
            weights: &current,
            skeleton,
            planes: &planes,
            rules_off,
        };
        let weighted: Vec<UnitWeights> = pass
            .par_iter()
            .map(|&k| {
                let candidates = if holding { &held[k] } else { &segments };
                loose_piece.weight(&units[k].vertices, candidates, holding)
            })
            .collect();
        for (&k, weighted) in pass.iter().zip(weighted) {
            let UnitWeights {
                treatment,
                rows: unit_rows,
                off_carrier,
            } = weighted;
            let unit = &units[k];
            let count = unit.vertices.len();
            counts.off_carrier += off_carrier;
            match treatment {
                PieceTreatment::Attached => counts.attached += count,
                PieceTreatment::Rigid(_) => counts.rigid += count,
                PieceTreatment::Joints => counts.bent += count,
                PieceTreatment::Body => {}
            }
            if unit.gap {
                counts.gaps.push(GapWeighting {
                    treatment,
                    vertices: unit.vertices.clone(),
                });
            } else {
                pieces[unit.piece].treatment = treatment;
            }
            for (&v, row) in unit.vertices.iter().zip(unit_rows) {
                rows[v as usize] = Some(row);
            }
            body_faces.extend_from_slice(&unit.faces);
        }
        current = with_rows(weights, &rows);
    }
    // `current` is `weights` with every row of `rows` (with none when no pass ran: a copy).
    *weights = current;
    counts.pieces = pieces;
    counts
}

/// A set of vertices weighted as a whole (module documentation): a piece without
/// weights, or a gap of a body piece.
struct Unit {
    vertices: Vec<u32>,
    /// The faces with a corner among `vertices`.
    faces: Vec<[u32; 3]>,
    /// The piece it is or lies in.
    piece: usize,
    gap: bool,
}

/// The gaps of the body pieces: the classes of their vertices without weights joined by
/// edges between such vertices, each with the faces that have a corner in it.
fn body_gaps(
    decomposition: &Decomposition,
    empty: &[bool],
    is_body: &[bool],
    piece_of: &[u32],
) -> Vec<Unit> {
    let topology = &decomposition.topology;
    let mut gap_of = vec![u32::MAX; empty.len()];
    let mut gaps: Vec<Unit> = Vec::new();
    for start in 0..empty.len() {
        let piece = piece_of[start] as usize;
        if !empty[start] || !is_body[piece] || gap_of[start] != u32::MAX {
            continue;
        }
        let label = gaps.len() as u32;
        let mut vertices = vec![start as u32];
        gap_of[start] = label;
        let mut next = 0;
        while next < vertices.len() {
            let v = vertices[next] as usize;
            next += 1;
            for &u in topology.neighbors(v) {
                if empty[u as usize] && gap_of[u as usize] == u32::MAX {
                    gap_of[u as usize] = label;
                    vertices.push(u);
                }
            }
        }
        gaps.push(Unit {
            vertices,
            faces: Vec::new(),
            piece,
            gap: true,
        });
    }
    for t in &decomposition.surface.triangles {
        if let Some(&v) = t.iter().find(|&&v| gap_of[v as usize] != u32::MAX) {
            gaps[gap_of[v as usize] as usize].faces.push(*t);
        }
    }
    gaps
}

/// `weights` with the rows of `rows` where they are given.
fn with_rows(weights: &SurfaceWeights, rows: &[Option<Row>]) -> SurfaceWeights {
    let mut result = SurfaceWeights {
        offsets: vec![0],
        ..SurfaceWeights::default()
    };
    for (v, row) in rows.iter().enumerate() {
        match row {
            Some(row) => result.extend_row(row.iter().copied()),
            None => result.extend_row(weights.row(v)),
        }
    }
    result
}

/// The weighted surface of the body pieces: their faces whose three corners have weights,
/// with a spatial index.
struct BodySurface {
    mesh: SurfaceMesh,
    spheres: FaceSpheres,
}

impl BodySurface {
    /// The faces of `triangles` whose three corners have weights, indexed.
    fn new(surface: &SurfaceMesh, triangles: &[[u32; 3]], weights: &SurfaceWeights) -> Self {
        let weighted = |v: u32| weights.offsets[v as usize] != weights.offsets[v as usize + 1];
        let triangles: Vec<[u32; 3]> = triangles
            .iter()
            .filter(|t| t.iter().all(|&v| weighted(v)))
            .copied()
            .collect();
        let mesh = SurfaceMesh {
            positions: surface.positions.clone(),
            triangles,
        };
        let spheres = FaceSpheres::new(&mesh);
        Self { mesh, spheres }
    }

    /// The weights of the nearest point of the body surface to `p`, interpolated over its
    /// face, with the distance; `None` when there is no body surface. `hint`: the nearest
    /// face of the query before (a vertex of the same piece, usually nearby), where the
    /// search starts ([`FaceSpheres::nearest_point_from`]: the same answer); set to this
    /// query's.
    fn weights_at(
        &self,
        weights: &SurfaceWeights,
        p: DVec3,
        hint: &mut Option<u32>,
    ) -> Option<BodyPoint> {
        let nearest = self.spheres.nearest_point_from(&self.mesh, p, *hint)?;
        *hint = Some(nearest.face);
        let corners = self.mesh.triangles[nearest.face as usize];
        let mut row: Vec<(u32, f64)> = Vec::new();
        for (&v, &b) in corners.iter().zip(&nearest.barycentric) {
            for (j, w) in weights.row(v as usize) {
                match row.iter_mut().find(|(k, _)| *k == j) {
                    Some((_, total)) => *total += b * w,
                    None => row.push((j, b * w)),
                }
            }
        }
        row.retain(|&(_, w)| w > 0.0);
        Some(BodyPoint {
            row,
            distance: nearest.distance,
        })
    }
}

/// The nearest point of the body surface to a vertex: its interpolated weights, distance.
struct BodyPoint {
    row: Vec<(u32, f64)>,
    distance: f64,
}

/// A row of (joint, weight) pairs.
type Row = Vec<(u32, f64)>;

/// How one unit (a piece or a gap) was weighted: its treatment, the row of each of its
/// vertices, and how many rows lost the weights of joints off the piece's carrier
/// ([`on_one_carrier`]).
struct UnitWeights {
    treatment: PieceTreatment,
    rows: Vec<Row>,
    off_carrier: usize,
}

/// What weighting a piece without joints needs besides the piece.
struct LoosePiece<'a> {
    surface: &'a SurfaceMesh,
    topology: &'a Topology,
    /// The body surface of `body_faces` with `weights`, built on first use.
    body: &'a OnceLock<BodySurface>,
    body_faces: &'a [[u32; 3]],
    weights: &'a SurfaceWeights,
    skeleton: &'a Skeleton,
    planes: &'a [Option<Plane>],
    rules_off: &'a RulesOff,
}

impl LoosePiece<'_> {
    fn body(&self) -> &BodySurface {
        self.body
            .get_or_init(|| BodySurface::new(self.surface, self.body_faces, self.weights))
    }

    /// Weights one piece without joints (module documentation): how, and the row of each
    /// of `vertices`. `candidates` (not empty): the bones it holds when `holds`, else every
    /// bone, narrowed to the bones of the joints that carry its contact. The body surface
    /// is asked only when needed: for the contact, or when the nearest bones are not
    /// unanimous.
    fn weight(
        &self,
        vertices: &[u32],
        candidates: &[(u32, DVec3, DVec3)],
        holds: bool,
    ) -> UnitWeights {
        let positions: Vec<DVec3> = vertices
            .iter()
            .map(|&v| self.surface.positions[v as usize])
            .collect();
        let on_body = || -> Vec<Option<BodyPoint>> {
            positions
                .par_iter()
                .map_init(
                    || None,
                    |hint, &p| self.body().weights_at(self.weights, p, hint),
                )
                .collect()
        };
        let (lo, hi) = crate::geometry::bounding_box(&positions);
        let size = (hi - lo).length();
        let mut body_points: Option<Vec<Option<BodyPoint>>> = None;
        let mut contact: Option<Contact> = None;
        let carried: Vec<(u32, DVec3, DVec3)>;
        let candidates = if holds || !self.rules_off.on(Rule::PiecesContact) {
            candidates
        } else {
            let points = on_body();
            let touch = Contact::new(&points, size);
            carried = candidates
                .iter()
                .filter(|s| touch.joints.binary_search(&s.0).is_ok())
                .copied()
                .collect();
            body_points = Some(points);
            contact = Some(touch);
            if carried.is_empty() {
                candidates
            } else {
                &carried[..]
            }
        };
        let bones: Vec<Option<NearestBone>> = positions
            .par_iter()
            .map(|&p| nearest_bone_with_distance(candidates, p))
            .collect();
        let joints: Vec<Option<u32>> = bones.iter().map(|b| b.map(|b| b.joint)).collect();
        let rigid = |joint: u32| UnitWeights {
            treatment: PieceTreatment::Rigid(joint),
            rows: vec![vec![(joint, 1.0)]; vertices.len()],
            off_carrier: 0,
        };
        let dominant = most_frequent(&joints).unwrap_or(candidates[0].0);
        if joints.iter().all(|&j| j == Some(dominant)) {
            return rigid(dominant);
        }
        let points = body_points.unwrap_or_else(on_body);
        let attached = points.iter().zip(&bones).all(|(at, bone)| {
            at.as_ref()
                .is_some_and(|at| at.distance < bone.map_or(f64::INFINITY, |b| b.distance))
        });
        if attached {
            let body_rows: Vec<Row> = points
                .into_iter()
                .map(|at| at.map(|at| at.row).unwrap_or_default())
                .collect();
            let rows = match &contact {
                Some(touch) => self.carried_along(vertices, &touch.vertices, &body_rows),
                None => body_rows,
            };
            let one_carrier = self
                .rules_off
                .on(Rule::PiecesOneCarrier)
                .then(|| on_one_carrier(self.skeleton, &rows))
                .flatten();
            let Some((kept, keeps)) = one_carrier else {
                return UnitWeights {
                    treatment: PieceTreatment::Attached,
                    rows,
                    off_carrier: 0,
                };
            };
            let carried = self.carried_along(vertices, &keeps, &kept);
            return UnitWeights {
                treatment: PieceTreatment::Attached,
                off_carrier: rows.iter().zip(&carried).filter(|(a, b)| a != b).count(),
                rows: carried,
            };
        }
        if size <= longest_bone(candidates, dominant) && self.rules_off.on(Rule::PiecesSmallRigid) {
            return rigid(dominant);
        }
        // Bent at the joints it holds or, holding none, at the joints of its vertices'
        // nearest bones.
        let bending: Vec<(u32, DVec3, DVec3)> = if holds {
            candidates.to_vec()
        } else {
            candidates
                .iter()
                .filter(|s| joints.contains(&Some(s.0)))
                .copied()
                .collect()
        };
        let bend = HeldJoints::new(self.skeleton, self.planes, &bending);
        let rows = positions.iter().map(|&p| bend.row(p, &bending)).collect();
        UnitWeights {
            treatment: PieceTreatment::Joints,
            rows,
            off_carrier: 0,
        }
    }

    /// The rows of a piece carried along its edges from its `sources`: each vertex takes
    /// the row in `rows` of the source vertex nearest to it along the piece's edges (a
    /// multi-source Dijkstra). From the contact, the weights of a piece attached by its
    /// contact vary only where it lies on the body; from the rows that kept weight on the
    /// piece's carrier ([`on_one_carrier`]), the others take their nearest such row.
    fn carried_along(&self, vertices: &[u32], sources: &[bool], rows: &[Row]) -> Vec<Row> {
        let local: HashMap<u32, usize> =
            vertices.iter().enumerate().map(|(i, &v)| (v, i)).collect();
        let mut distance = vec![f64::INFINITY; vertices.len()];
        let mut source: Vec<usize> = (0..vertices.len()).collect();
        let mut heap = BinaryHeap::new();
        for (i, _) in sources.iter().enumerate().filter(|(_, &c)| c) {
            distance[i] = 0.0;
            heap.push(Nearest {
                distance: 0.0,
                key: i,
            });
        }
        while let Some(Nearest {
            distance: d,
            key: i,
        }) = heap.pop()
        {
            if d > distance[i] {
                continue;
            }
            let p = self.surface.positions[vertices[i] as usize];
            for u in self.topology.neighbors(vertices[i] as usize) {
                let Some(&k) = local.get(u) else { continue };
                let through = d + p.distance(self.surface.positions[*u as usize]);
                if through < distance[k] {
                    distance[k] = through;
                    source[k] = source[i];
                    heap.push(Nearest {
                        distance: through,
                        key: k,
                    });
                }
            }
        }
        source.iter().map(|&s| rows[s].clone()).collect()
    }
}

/// Where a piece that holds no bone touches the body, and the joints that carry it there.
struct Contact {
    /// Per vertex of the piece: within the contact zone.
    vertices: Vec<bool>,
    /// Sorted: the joint of largest weight at the body point nearest to each contact vertex.
    joints: Vec<u32>,
}

impl Contact {
    /// The contact zone of a piece of bounding-box diagonal `size` whose vertices' nearest
    /// body points are `points`: the vertices p with d_S(p) ≤ min_q d_S(q) + γ · size,
    /// γ = [`CONTACT_SHARE`].
    fn new(points: &[Option<BodyPoint>], size: f64) -> Self {
        let nearest = points
            .iter()
            .flatten()
            .map(|at| at.distance)
            .fold(f64::INFINITY, f64::min);
        let limit = nearest + CONTACT_SHARE * size;
        let vertices: Vec<bool> = points
            .iter()
            .map(|at| at.as_ref().is_some_and(|at| at.distance <= limit))
            .collect();
        let mut joints: Vec<u32> = points
            .iter()
            .zip(&vertices)
            .filter(|(_, &inside)| inside)
            .filter_map(|(at, _)| {
                let row = &at.as_ref()?.row;
                row.iter().max_by(|x, y| x.1.total_cmp(&y.1)).map(|x| x.0)
            })
            .collect();
        joints.sort_unstable();
        joints.dedup();
        Self { vertices, joints }
    }
}

/// γ: the contact zone of a piece that holds no bone reaches this share of the piece's size
/// beyond its nearest approach to the body (chosen on the benchmark, docs/pieces.md).
const CONTACT_SHARE: f64 = 0.2;

/// How many points along a bone segment are tested against a piece ([`held_bones`]).
const BONE_SAMPLES: usize = 8;

/// The bone segments a piece holds. A point a_k = a + (k + ½)/n · (b − a), k < n =
/// [`BONE_SAMPLES`], of a segment is inside the piece when the generalized winding number
/// of the piece's faces there is |w(a_k)| > ½ ([`crate::mesh::winding`]); an open piece
/// holds a point only where it wraps most of the way around it (a hair card or a cape
/// holds none). The piece holds the segments with at least half their points inside
/// (an upper-arm shell holds the upper arm, not the first inches of the forearm that its
/// elbow end covers); when it holds none that far, those with any point inside whose
/// joint's bones are the nearest bones of the skeleton (`nearest_joint`) to at least half
/// of the piece's vertices: a bone that pokes into a piece moves it only when the piece
/// lies around it, not when most of it lies nearer other bones (a strap across a chest
/// that a clavicle's bone crosses at the shoulder). Only segments whose box meets the
/// piece's box are tested. When no segment has a point inside, the piece holds the bones
/// of the joints *around* it ([`bones_around`]).
fn held_bones(
    surface: &SurfaceMesh,
    vertices: &[u32],
    faces: &[[u32; 3]],
    segments: &[(u32, DVec3, DVec3)],
    nearest_joint: &(dyn Fn(DVec3) -> Option<u32> + Sync),
    rules_off: &RulesOff,
) -> HeldBones {
    let held = held_bones_counting(surface, vertices, faces, segments, samples_inside);
    let segments =
        if !held.weakly || !rules_off.on(Rule::PiecesPokingBones) && !held.segments.is_empty() {
            held.segments
        } else if held.segments.is_empty() {
            if rules_off.on(Rule::PiecesBonesAround) {
                bones_around(surface, vertices, held.bounds, segments, nearest_joint)
            } else {
                Vec::new()
            }
        } else {
            let nearest = NearestJoints::of(surface, vertices, nearest_joint);
            held.segments
                .into_iter()
                .filter(|&(joint, _, _)| 2 * nearest.count(joint) >= vertices.len())
                .collect()
        };
    HeldBones {
        segments,
        mostly: !held.weakly,
        bounds: held.bounds,
    }
}

/// The bones a piece holds ([`held_bones`]), whether they run inside it for at least half
/// their length (else they only poke into it, or lie around it), and the piece's bounding
/// box (its low and high corners).
struct HeldBones {
    segments: Vec<(u32, DVec3, DVec3)>,
    mostly: bool,
    bounds: (DVec3, DVec3),
}

/// The joint of the nearest bone of the skeleton to each vertex of a piece.
struct NearestJoints(Vec<Option<u32>>);

impl NearestJoints {
    fn of(
        surface: &SurfaceMesh,
        vertices: &[u32],
        nearest_joint: &(dyn Fn(DVec3) -> Option<u32> + Sync),
    ) -> Self {
        Self(
            vertices
                .iter()
                .map(|&v| nearest_joint(surface.positions[v as usize]))
                .collect(),
        )
    }

    /// How many of the piece's vertices have `joint`'s bones as their nearest.
    fn count(&self, joint: u32) -> usize {
        self.0.iter().filter(|&&n| n == Some(joint)).count()
    }
}

/// A joint around a piece that no bone enters has its bones nearest to at least this share
/// of the piece's vertices ([`bones_around`]; chosen on the benchmark, docs/pieces.md).
const AROUND_SHARE: f64 = 0.25;

/// The bones of a piece that no bone enters, from the joints around it: the bone segments
/// with an end inside the piece's bounding box (`lo`, `hi`) whose joint's bones are the nearest bones of
/// the skeleton (`nearest_joint`) to at least a share σ = [`AROUND_SHARE`] of its
/// vertices. A piece hangs from the joints it is modelled around even where their
/// bones stay outside it: a hat above the head joint whose bone ends below the hat, a bag
/// hanging from its joint at a belt, a wing past the root joints of its chain (the chain's
/// bones all qualify, and the piece bends at their planes). A bone that ends inside the box
/// counts like one that starts there: a bracelet around a wrist holds the forearm's bone,
/// which ends at the wrist, as well as the hand's, and a belt around the waist the bones on
/// both sides of the joint inside it, so that neither is rigid to one of them. Without such
/// bones the piece holds none and is carried by the body it touches.
fn bones_around(
    surface: &SurfaceMesh,
    vertices: &[u32],
    (lo, hi): (DVec3, DVec3),
    segments: &[(u32, DVec3, DVec3)],
    nearest_joint: &(dyn Fn(DVec3) -> Option<u32> + Sync),
) -> Vec<(u32, DVec3, DVec3)> {
    let in_box = |q: DVec3| q.cmpge(lo).all() && q.cmple(hi).all();
    let inside: Vec<(u32, DVec3, DVec3)> = segments
        .iter()
        .copied()
        .filter(|&(_, a, b)| in_box(a) || in_box(b))
        .collect();
    // The nearest bones are found only for a piece with bones around it (most pieces that
    // no bone enters have none: a hair card, a cape).
    if inside.is_empty() {
        return inside;
    }
    let nearest = NearestJoints::of(surface, vertices, nearest_joint);
    let least = AROUND_SHARE * vertices.len() as f64;
    inside
        .into_iter()
        .filter(|&(joint, _, _)| nearest.count(joint) as f64 >= least)
        .collect()
}

/// The bones of the pieces that enclose a joint left free (module documentation): a joint
/// with no boundary of its own (the root, an end site, a joint whose surface was not found),
/// that moves skin (not a helper), whose bones no piece holds and that has no sibling at
/// its point (two eye-lid joints at the centre of one eye: the geometry cannot tell which
/// half is whose). A piece (not a gap: a gap's faces close around nothing) whose faces
/// enclose such joints (winding number |w| > ½ at the joint) holds their bones, with those
/// of its held bones ([`held_bones`]) that [`bones_kept_beside`] keeps.
fn with_enclosed_joints(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    units: &[Unit],
    held: Vec<HeldBones>,
    segments: &[(u32, DVec3, DVec3)],
) -> Vec<Vec<(u32, DVec3, DVec3)>> {
    let joints = JointPoints::new(skeleton);
    let bind = &joints.bind;
    let mut taken = vec![false; skeleton.len()];
    for segment in held.iter().flat_map(|h| &h.segments) {
        taken[segment.0 as usize] = true;
    }
    let mut siblings = joints.sibling_classes(skeleton, |_| true);
    let mut class_size = vec![0u32; skeleton.len()];
    for j in 0..skeleton.len() as u32 {
        class_size[siblings.find(j) as usize] += 1;
    }
    let mut twin = |j: usize| class_size[siblings.find(j as u32) as usize] > 1;
    let free: Vec<u32> = (0..skeleton.len())
        .filter(|&j| {
            let decision = &decomposition.joints[j];
            !taken[j] && decision.boundary.is_none() && decision.owns_skin && !twin(j)
        })
        .map(|j| j as u32)
        .collect();
    let positions = &decomposition.surface.positions;
    units
        .par_iter()
        .zip(held)
        .map(|(unit, held)| {
            if unit.gap || free.is_empty() {
                return held.segments;
            }
            let (lo, hi) = held.bounds;
            let enclosed: Vec<u32> = free
                .iter()
                .copied()
                .filter(|&j| {
                    let q = bind[j as usize];
                    q.cmpge(lo).all()
                        && q.cmple(hi).all()
                        && faces_inside(positions, &unit.faces, q)
                })
                .collect();
            if enclosed.is_empty() {
                held.segments
            } else {
                bones_kept_beside(skeleton, &enclosed, &held, segments)
            }
        })
        .collect()
}

/// The bones of a piece that encloses the free joints `enclosed` ([`with_enclosed_joints`]):
/// theirs, and of the bones it `held`, only those that run inside it for half their length
/// (`held.mostly`; a bone that only pokes into it yields to a joint inside it) and do not
/// hang from an enclosed joint through a joint whose bones it does not hold (a chain that
/// leaves the piece and comes back into it). A pedestal that encloses the root joint, with
/// the feet standing in it, moves with the root, not with the feet whose bones end inside it;
/// a wand around its own joint moves with that joint, not with the wrist whose bone runs
/// into its handle; a head piece around the joint of a cap at the back of the head bends
/// between the head, whose bone runs inside it, and the cap; a closed pair of shorts around
/// a hips root still bends at the thighs, whose bones start at the root.
fn bones_kept_beside(
    skeleton: &Skeleton,
    enclosed: &[u32],
    held: &HeldBones,
    segments: &[(u32, DVec3, DVec3)],
) -> Vec<(u32, DVec3, DVec3)> {
    let holds = |joint: usize| {
        enclosed.contains(&(joint as u32)) || held.segments.iter().any(|s| s.0 as usize == joint)
    };
    // Whether the chain from `joint` up to the enclosed joint above it (if any) stays in the
    // piece: every joint on the way holds bones in it.
    let through_the_piece = |joint: u32| {
        let mut k = joint as usize;
        let mut inside = true;
        while let Some(parent) = skeleton.parent(k) {
            if enclosed.contains(&(parent as u32)) {
                return inside;
            }
            inside &= holds(parent);
            k = parent;
        }
        true
    };
    segments
        .iter()
        .copied()
        .filter(|s| {
            enclosed.contains(&s.0)
                || (held.mostly && held.segments.contains(s) && through_the_piece(s.0))
        })
        .collect()
}

/// The segments of [`held_bones_counting`], whether they are held only weakly (none has
/// half its points inside), and the piece's bounding box (its low and high corners).
struct Held {
    segments: Vec<(u32, DVec3, DVec3)>,
    weakly: bool,
    bounds: (DVec3, DVec3),
}

/// ⌈n/2⌉ of the [`BONE_SAMPLES`]: a segment with this many points inside is held mostly.
const MOSTLY_INSIDE: usize = BONE_SAMPLES.div_ceil(2);

/// [`held_bones`], with `count(a, b, inside)` the number of points of the segment a–b
/// inside (as far as [`held_bones`] reads it: 0, 1 to [`MOSTLY_INSIDE`] − 1, or at least
/// [`MOSTLY_INSIDE`]).
fn held_bones_counting(
    surface: &SurfaceMesh,
    vertices: &[u32],
    faces: &[[u32; 3]],
    segments: &[(u32, DVec3, DVec3)],
    count: fn(DVec3, DVec3, &dyn Fn(DVec3) -> bool) -> usize,
) -> Held {
    let positions: Vec<DVec3> = vertices
        .iter()
        .map(|&v| surface.positions[v as usize])
        .collect();
    let (lo, hi) = crate::geometry::bounding_box(&positions);
    let inside = |q: DVec3| {
        q.cmpge(lo).all() && q.cmple(hi).all() && faces_inside(&surface.positions, faces, q)
    };
    let inside_counts: Vec<((u32, DVec3, DVec3), usize)> = segments
        .iter()
        .filter(|&&(_, a, b)| a.min(b).cmple(hi).all() && a.max(b).cmpge(lo).all())
        .map(|&(j, a, b)| ((j, a, b), count(a, b, &inside)))
        .filter(|&(_, count)| count > 0)
        .collect();
    let mostly = |count: usize| count >= MOSTLY_INSIDE;
    let weakly = !inside_counts.iter().any(|&(_, count)| mostly(count));
    let least = if weakly { 1 } else { MOSTLY_INSIDE };
    Held {
        segments: inside_counts
            .into_iter()
            .filter(|&(_, count)| count >= least)
            .map(|(segment, _)| segment)
            .collect(),
        weakly,
        bounds: (lo, hi),
    }
}

/// The k-th of the [`BONE_SAMPLES`] points of the segment a–b: a + (k + ½)/n · (b − a).
fn bone_sample(a: DVec3, b: DVec3, k: usize) -> DVec3 {
    a + (b - a) * ((k as f64 + 0.5) / BONE_SAMPLES as f64)
}

/// The points of the segment a–b `inside`, counted only as far as [`held_bones`] reads the
/// count: whether some are inside and whether [`MOSTLY_INSIDE`] are. The count stops at
/// [`MOSTLY_INSIDE`], or once some are inside and the points left cannot make
/// [`MOSTLY_INSIDE`] (each point's winding number is a sum over the piece's faces: on a
/// piece that holds a bone, half of them are skipped).
fn samples_inside(a: DVec3, b: DVec3, inside: &dyn Fn(DVec3) -> bool) -> usize {
    let mut count = 0;
    for k in 0..BONE_SAMPLES {
        let left = BONE_SAMPLES - k;
        if count >= MOSTLY_INSIDE || (count > 0 && count + left < MOSTLY_INSIDE) {
            break;
        }
        count += usize::from(inside(bone_sample(a, b, k)));
    }
    count
}

/// The joints whose bones a piece holds, as a forest (each under its nearest held
/// ancestor), with the plane and half-width of each one's boundary: how the piece bends.
struct HeldJoints {
    /// Held joints, sorted.
    joints: Vec<u32>,
    /// Nearest held ancestor of each held joint.
    parent: Vec<Option<u32>>,
    /// Boundary plane of each held joint that has a boundary.
    plane: Vec<Option<Plane>>,
}

/// A joint's boundary plane: a point, the unit normal to the child side, the overlap
/// half-width.
type Plane = (DVec3, DVec3, f64);

/// The boundary plane of every joint that has a boundary (#J).
fn boundary_planes(decomposition: &Decomposition, overlaps: &Overlaps) -> Vec<Option<Plane>> {
    decomposition
        .joints
        .iter()
        .map(|decision| {
            let k = decision.boundary? as usize;
            let boundary = &decomposition.boundaries[k];
            Some((boundary.point, boundary.normal, overlaps.half_widths[k]))
        })
        .collect()
}

impl HeldJoints {
    fn new(skeleton: &Skeleton, planes: &[Option<Plane>], held: &[(u32, DVec3, DVec3)]) -> Self {
        let mut joints: Vec<u32> = held.iter().map(|s| s.0).collect();
        joints.sort_unstable();
        joints.dedup();
        let parent = joints
            .iter()
            .map(|&j| {
                skeleton
                    .ancestors(j as usize)
                    .map(|a| a as u32)
                    .find(|a| joints.binary_search(a).is_ok())
            })
            .collect();
        let plane = joints.iter().map(|&j| planes[j as usize]).collect();
        Self {
            joints,
            parent,
            plane,
        }
    }

    fn index(&self, joint: u32) -> usize {
        self.joints.binary_search(&joint).unwrap_or(0)
    }

    /// s_c(p) = β(clamp((w + n·(p − o)) / (2w), 0, 1)) of held joint `k`'s boundary, 1
    /// without one.
    fn child_share(&self, k: usize, p: DVec3) -> f64 {
        self.plane[k].map_or(1.0, |(o, n, w)| {
            super::blend::beta(((w + n.dot(p - o)) / (2.0 * w)).clamp(0.0, 1.0))
        })
    }

    /// The row of a vertex at `p`: the mass flows from the root of its nearest held bone's
    /// chain down to that bone's joint J, each joint on the way passing the share s_c(p)
    /// on to the next; J then passes s_c(p) on to each of its held children that has a
    /// boundary (normalised when they sum past 1).
    fn row(&self, p: DVec3, held: &[(u32, DVec3, DVec3)]) -> Row {
        let Some(nearest) = nearest_bone_with_distance(held, p) else {
            return Row::new();
        };
        let mut path = vec![self.index(nearest.joint)];
        while let Some(up) = self.parent[*path.last().unwrap_or(&0)] {
            path.push(self.index(up));
        }
        path.reverse();
        let mut row: Row = Vec::new();
        let mut mass = 1.0;
        for pair in path.windows(2) {
            let share = self.child_share(pair[1], p);
            row.push((self.joints[pair[0]], mass * (1.0 - share)));
            mass *= share;
        }
        let last = *path.last().unwrap_or(&0);
        let children: Vec<(usize, f64)> = (0..self.joints.len())
            .filter(|&k| self.parent[k] == Some(self.joints[last]) && self.plane[k].is_some())
            .map(|k| (k, self.child_share(k, p)))
            .filter(|&(_, s)| s > 0.0)
            .collect();
        let total: f64 = children.iter().map(|c| c.1).sum();
        for &(k, s) in &children {
            row.push((self.joints[k], mass * s / total.max(1.0)));
        }
        row.push((self.joints[last], mass * (1.0 - total.min(1.0))));
        row.retain(|&(_, w)| w > 0.0);
        row
    }
}

/// Length of the longest bone segment of `joint`.
fn longest_bone(segments: &[(u32, DVec3, DVec3)], joint: u32) -> f64 {
    segments
        .iter()
        .filter(|s| s.0 == joint)
        .map(|&(_, a, b)| a.distance(b))
        .fold(0.0, f64::max)
}

/// The most frequent joint of a list (the smallest index on ties), `None` when empty.
fn most_frequent(joints: &[Option<u32>]) -> Option<u32> {
    let mut sorted: Vec<u32> = joints.iter().flatten().copied().collect();
    sorted.sort_unstable();
    sorted
        .chunk_by(|a, b| a == b)
        .max_by(|x, y| x.len().cmp(&y.len()).then(y[0].cmp(&x[0])))
        .map(|run| run[0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::shapes::{capsule_chain, faces_above, icosphere};
    use crate::skeleton::bones::nearest_bone;
    use atlas_skin_runtime::NO_PARENT;

    #[test]
    fn a_piece_that_holds_a_chain_bends_at_its_joints_planes() {
        // Held chain 0 → 1 → 2 along +X (joints at x = 0, 1, 2, bones to x = 3); joint 1's
        // plane at x = 1 with half-width 0.2, joint 2 without a boundary.
        let held = [
            (0, DVec3::ZERO, DVec3::X),
            (1, DVec3::X, 2.0 * DVec3::X),
            (2, 2.0 * DVec3::X, 3.0 * DVec3::X),
        ];
        let bend = HeldJoints {
            joints: vec![0, 1, 2],
            parent: vec![None, Some(0), Some(1)],
            plane: vec![None, Some((DVec3::X, DVec3::X, 0.2)), None],
        };
        let weight = |row: &Row, joint: u32| row.iter().find(|r| r.0 == joint).map_or(0.0, |r| r.1);
        let mut previous = 1.0;
        for k in 0..=60 {
            let p = DVec3::new(k as f64 * 0.05, 0.3, 0.0);
            let row = bend.row(p, &held);
            let total: f64 = row.iter().map(|r| r.1).sum();
            assert!((total - 1.0).abs() < 1e-12, "{row:?}");
            let root = weight(&row, 0);
            assert!(
                root <= previous + 1e-12,
                "the root's weight only falls: {row:?}"
            );
            previous = root;
            if p.x < 0.8 {
                assert_eq!(row, vec![(0, 1.0)]);
            }
            if (1.2..2.0).contains(&p.x) {
                assert_eq!(row, vec![(1, 1.0)]);
            }
            if p.x > 2.0 {
                assert_eq!(
                    row,
                    vec![(2, 1.0)],
                    "no boundary at joint 2: its bone decides"
                );
            }
        }
        // On joint 1's plane both sides weigh ½.
        let row = bend.row(DVec3::new(1.0, 0.3, 0.0), &held);
        assert!((weight(&row, 0) - 0.5).abs() < 1e-12 && (weight(&row, 1) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_piece_holds_the_bones_that_run_inside_it() {
        // A closed ball of radius 1 at the origin; bone 0 runs through it, bone 1 passes
        // beside it (0.2 from its surface, nearer to much of it than bone 0's far end),
        // bone 2 is far away. An open piece that does not wrap around bone 0 (a cap of
        // the ball, like a hair card on a head) holds nothing.
        let ball = icosphere(1.0, 3);
        let vertices: Vec<u32> = (0..ball.positions.len() as u32).collect();
        let segments = [
            (0, DVec3::new(0.0, -0.5, 0.0), DVec3::new(0.0, 0.5, 0.0)),
            (1, DVec3::new(1.2, -1.0, 0.0), DVec3::new(1.2, 1.0, 0.0)),
            (2, DVec3::new(5.0, 0.0, 0.0), DVec3::new(6.0, 0.0, 0.0)),
        ];
        let held = held_bones(
            &ball,
            &vertices,
            &ball.triangles,
            &segments,
            &|p| nearest_bone(&segments, p),
            &RulesOff::default(),
        );
        assert_eq!(joints_of(&held.segments), vec![0]);
        // Bone 3 starts inside and runs out: an eighth of it is inside. Held only when no
        // bone is held for half its length and its bones are the nearest to at least half
        // of the piece.
        let mut with_tip = segments.to_vec();
        with_tip.push((3, DVec3::new(0.0, 0.9, 0.0), DVec3::new(0.0, 1.9, 0.0)));
        let nearest_tip = |p: DVec3| nearest_bone(&with_tip, p);
        let held = held_bones(
            &ball,
            &vertices,
            &ball.triangles,
            &with_tip,
            &nearest_tip,
            &RulesOff::default(),
        );
        assert_eq!(joints_of(&held.segments), vec![0]);
        let tip_only = [with_tip[2], with_tip[3]];
        let held = held_bones(
            &ball,
            &vertices,
            &ball.triangles,
            &tip_only,
            &|p| nearest_bone(&tip_only, p),
            &RulesOff::default(),
        );
        assert_eq!(joints_of(&held.segments), vec![3]);
        let cap = faces_above(&ball, 0.8);
        assert!(!cap.is_empty());
        let mut cap_vertices: Vec<u32> = cap.iter().flatten().copied().collect();
        cap_vertices.sort_unstable();
        cap_vertices.dedup();
        assert!(held_bones(
            &ball,
            &cap_vertices,
            &cap,
            &segments,
            &|p| nearest_bone(&segments, p),
            &RulesOff::default()
        )
        .segments
        .is_empty());
    }

    #[test]
    fn a_piece_no_bone_enters_hangs_from_the_joints_around_it() {
        // A closed ball of radius 1 at the origin that no bone enters (a hat, a bag).
        let ball = icosphere(1.0, 3);
        let vertices: Vec<u32> = (0..ball.positions.len() as u32).collect();
        let far = (1, DVec3::new(5.0, 0.0, 0.0), DVec3::new(6.0, 0.0, 0.0));
        let held_with = |segments: &[(u32, DVec3, DVec3)]| {
            held_bones(
                &ball,
                &vertices,
                &ball.triangles,
                segments,
                &|p| nearest_bone(segments, p),
                &RulesOff::default(),
            )
            .segments
        };
        // Joint 0 sits outside the ball but inside its box, its bone running away from it:
        // the nearest bone to the whole ball.
        let around = (0, DVec3::new(0.0, 0.9, 0.9), DVec3::new(0.0, 2.0, 2.0));
        assert_eq!(joints_of(&held_with(&[around, far])), vec![0]);
        // The same joint outside the box: the piece holds nothing (the body it touches
        // carries it).
        let beyond = (0, DVec3::new(0.0, 1.1, 1.1), DVec3::new(0.0, 2.0, 2.0));
        assert!(held_with(&[beyond, far]).is_empty());
        // Two bones around it, each the nearest to half of it: both (the piece bends
        // between them), the second one ending inside the box (a forearm's bone ending at
        // the wrist inside a bracelet).
        let below = (2, DVec3::new(0.0, -2.0, -2.0), DVec3::new(0.0, -0.9, -0.9));
        assert_eq!(joints_of(&held_with(&[around, far, below])), vec![0, 2]);
        // A joint in a corner of the box, nearest to less than a quarter of the ball, between
        // bones that pass beside it outside the box: nothing.
        let corner = (0, DVec3::splat(0.95), DVec3::splat(1.5));
        let left = (1, DVec3::new(-1.2, -2.0, 0.0), DVec3::new(-1.2, 2.0, 0.0));
        let right = (2, DVec3::new(1.2, -2.0, 0.0), DVec3::new(1.2, 2.0, 0.0));
        let segments = [corner, left, right];
        let share = vertices
            .iter()
            .filter(|&&v| nearest_bone(&segments, ball.positions[v as usize]) == Some(0))
            .count() as f64
            / vertices.len() as f64;
        assert!(share > 0.0 && share < AROUND_SHARE, "{share}");
        assert!(held_with(&segments).is_empty());
    }

    #[test]
    fn a_piece_around_a_free_joint_keeps_the_bones_that_do_not_leave_it() {
        // Root 0 with a spine 1 and a leg 2 → 3 → 4 (thigh, shin, foot), and an arm from the
        // spine: a wrist 5 and a wand's joint 6. Each joint's bone runs to its child, a
        // leaf's on past it.
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let skeleton = Skeleton {
            names: (0..7).map(|k| format!("joint{k}")).collect(),
            parents: vec![NO_PARENT, 0, 0, 2, 3, 1, 5],
            tails: vec![None; 7],
            inverse_bind: vec![glam::Mat4::IDENTITY; 7],
        };
        let segments = [
            (0, p(0.0, 1.0), p(0.0, 2.0)),
            (0, p(0.0, 1.0), p(0.2, 0.9)),
            (1, p(0.0, 2.0), p(0.6, 2.0)),
            (2, p(0.2, 0.9), p(0.2, 0.5)),
            (3, p(0.2, 0.5), p(0.2, 0.1)),
            (4, p(0.2, 0.1), p(0.3, 0.0)),
            (5, p(0.6, 2.0), p(0.8, 2.0)),
            (6, p(0.8, 2.0), p(0.9, 2.0)),
        ];
        let kept = |enclosed: &[u32], held: &[(u32, DVec3, DVec3)], mostly: bool| {
            let held = HeldBones {
                segments: held.to_vec(),
                mostly,
                bounds: (DVec3::splat(-1.0), DVec3::splat(3.0)),
            };
            joints_of(&bones_kept_beside(&skeleton, enclosed, &held, &segments))
        };
        // A pedestal around the root that the foot stands in: the foot's chain leaves it at
        // the root and comes back; it moves with the root alone.
        assert_eq!(kept(&[0], &[segments[5]], true), vec![0, 0]);
        // Shorts around the root holding the thigh: the thigh hangs from the root.
        assert_eq!(kept(&[0], &[segments[3]], true), vec![0, 0, 2]);
        // A long skirt holding the thigh and the shin, but not the shin alone.
        assert_eq!(kept(&[0], &segments[3..5], true), vec![0, 0, 2, 3]);
        assert_eq!(kept(&[0], &[segments[4]], true), vec![0, 0]);
        // A wand around its joint that the wrist's bone only pokes into: the wand's joint.
        assert_eq!(kept(&[6], &[segments[6]], false), vec![6]);
        // A piece around the wand's joint that the wrist's bone runs through for half its
        // length (a head around a cap's joint): it bends between the two.
        assert_eq!(kept(&[6], &[segments[6]], true), vec![5, 6]);
    }

    fn joints_of(segments: &[(u32, DVec3, DVec3)]) -> Vec<u32> {
        segments.iter().map(|s| s.0).collect()
    }

    #[test]
    fn a_bone_that_pokes_into_a_piece_holds_it_only_where_it_is_the_nearest() {
        // A strap: a thin tube of radius 0.1 along x from 0 to 4. Bone 0 crosses its
        // thickness near one end (2 of its 8 points inside); bone 1 runs along the strap,
        // 0.3 from its surface, nearer to most of it.
        let (strap, _) = capsule_chain(&[DVec3::ZERO, 4.0 * DVec3::X], &[], 0.1, 8, 32);
        let vertices: Vec<u32> = (0..strap.positions.len() as u32).collect();
        let across = (0, DVec3::new(0.3, -0.42, 0.0), DVec3::new(0.3, 0.38, 0.0));
        let along = (1, DVec3::new(0.0, 0.4, 0.0), DVec3::new(4.0, 0.4, 0.0));
        let segments = [across, along];
        let held = held_bones(
            &strap,
            &vertices,
            &strap.triangles,
            &segments,
            &|p| nearest_bone(&segments, p),
            &RulesOff::default(),
        );
        assert!(held.segments.is_empty(), "{:?}", held.segments);
        // With the other bone far away, the bone that pokes in is the nearest to all of it.
        let far = (1, DVec3::new(0.0, 5.0, 0.0), DVec3::new(4.0, 5.0, 0.0));
        let segments = [across, far];
        let held = held_bones(
            &strap,
            &vertices,
            &strap.triangles,
            &segments,
            &|p| nearest_bone(&segments, p),
            &RulesOff::default(),
        );
        assert_eq!(joints_of(&held.segments), vec![0]);
    }

    /// Every point tested: the reference for [`samples_inside`].
    fn every_sample_inside(a: DVec3, b: DVec3, inside: &dyn Fn(DVec3) -> bool) -> usize {
        (0..BONE_SAMPLES)
            .filter(|&k| inside(bone_sample(a, b, k)))
            .count()
    }

    /// The count that stops early holds the same segments as counting every point: random
    /// segments in, out of and across a closed ball and an open cap of it, every length of
    /// run inside.
    #[test]
    fn held_bones_stop_counting_where_the_answer_is_known() {
        let ball = icosphere(1.0, 3);
        let vertices: Vec<u32> = (0..ball.positions.len() as u32).collect();
        let cap = faces_above(&ball, 0.3);
        let mut rng = atlas_skin_runtime::random_pose::SplitMix64::new(17);
        let mut point = || DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 3.0 - 1.5;
        let mut held_some = 0;
        for trial in 0..200 {
            let segments: Vec<(u32, DVec3, DVec3)> = (0..1 + trial % 4)
                .map(|j| (j as u32, point(), point()))
                .collect();
            for faces in [&ball.triangles, &cap] {
                let held = held_bones_counting(&ball, &vertices, faces, &segments, samples_inside);
                let reference =
                    held_bones_counting(&ball, &vertices, faces, &segments, every_sample_inside);
                assert_eq!(held.segments, reference.segments);
                assert_eq!(held.weakly, reference.weakly);
                held_some += usize::from(!held.segments.is_empty());
            }
        }
        assert!(held_some > 50, "{held_some}");
    }

    #[test]
    fn the_most_frequent_joint_takes_the_smallest_index_on_ties() {
        assert_eq!(most_frequent(&[Some(3), None, Some(1), Some(3)]), Some(3));
        assert_eq!(
            most_frequent(&[Some(2), Some(1), Some(2), Some(1)]),
            Some(1)
        );
        assert_eq!(most_frequent(&[None, None]), None);
    }
}

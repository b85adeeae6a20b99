//! The search for the cutting plane at a joint (Lu et al. 2008 §3.1).
//!
//! Candidate planes P(J, n) pass through the joint. With u the unit upper bone and l the
//! unit lower bone, the normals lie in the plane Q = span(u, l):
//! n(α) = cos α · a + sin α · b, with a = (u + l)/|u + l| the bisector and b the unit vector
//! of Q orthogonal to a. The paper samples a half circle; here a normal is kept only when
//! n · u > 0 and n · l > 0 (|α| < 90° − θ/2, θ the angle between the bones): the plane keeps
//! the upper bone on its parent side and the lower bone on its child side, and
//! n · (u + l) > 0 orients it to the child (METHOD.md failure 3). Without this a sharp bend
//! is cut lengthwise through its inner corner, a section as short as the true one. When u
//! and l are within 10° of each other Q is undefined and the normals sample a cone of
//! half-angle `cone_half_angle_deg` around a instead (with the same filter). Each plane is intersected only with the faces near J (a ball of radius
//! `neighbourhood_factor` × max(surface distance, bone length / 10), gathered once per joint,
//! doubled up to twice when it holds no closed section around J); a curve reaching the
//! border of that set is not closed and is discarded. Of the closed
//! curves (only those that can contain J are traced: `JointSections::sections_around`),
//! the one whose interior in the plane contains J is kept — unless another bone of
//! the skeleton (one not at J) passes through that interior: such a plane slices a torso
//! or a palm across other limbs, not the limb at J — and the plane of minimum perimeter F
//! wins. A pattern search around the best coarse sample refines it.

use super::params::DecomposeParams;
use crate::cuts::joint_roles::JointFrame;
use crate::cuts::plane_section::{
    closed_length, polygon_contains, DomainScratch, JointSections, Plane, SectionCurve,
};
use crate::mesh::spatial_index::FaceSpheres;
use crate::mesh::{SurfaceMesh, Topology};
use crate::skeleton::bones::BoneIndex;
use glam::DVec3;

/// How many times the neighbourhood doubles when it holds no closed section around the
/// joint (flat parts — hands, feet, a torso — have sections much wider than the joint's
/// surface distance).
const NEIGHBOURHOOD_ATTEMPTS: usize = 3;

/// Bones closer than this to collinear are cut with the cone of normals.
const COLLINEAR_DEGREES: f64 = 10.0;

/// A closed section around the joint.
#[derive(Debug, Clone, PartialEq)]
pub struct CutCandidate {
    pub plane: Plane,
    pub curve: SectionCurve,
    /// Crossing positions, in chain order.
    pub points: Vec<DVec3>,
    /// F: length of the closed curve.
    pub perimeter: f64,
}

/// The surface the cut search runs on, with what is built once for all joints.
#[derive(Debug, Clone, Copy)]
pub struct CutSurface<'a> {
    pub mesh: &'a SurfaceMesh,
    pub topology: &'a Topology,
    pub spheres: &'a FaceSpheres,
    /// #V snap distances ([`crate::cuts::plane_section::vertex_snap_distances`]).
    pub vertex_snap: &'a [f64],
    /// The largest of `vertex_snap`.
    pub max_snap: f64,
    pub params: &'a DecomposeParams,
}

/// What the search found at one joint.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CutSearch {
    /// Every acceptable closed section, best (shortest) first.
    pub candidates: Vec<CutCandidate>,
    /// Closed sections around the joint turned down because another bone passes through
    /// them (in the last neighbourhood tried).
    pub enclosing_other_bones: usize,
    /// A bone (parent, child) not at the joint that runs through it (or from another joint
    /// at the same place) and crosses every sampled plane there: every closed section
    /// around the joint encloses it, so none was searched ([`find_cut_candidates`]).
    pub through_joint: Option<(usize, usize)>,
}

/// A bone crosses a plane "at the joint" within this fraction of the joint's surface
/// distance r. Every closed section around the joint stays at least about r from it (its
/// points lie on the surface), so the crossing and the joint are on the same side of
/// every section's curve, up to rounding.
const AT_JOINT: f64 = 1e-6;

/// Every closed section around joint `joint` (its `frame`) that no other bone of `bones`
/// (one with neither end at the joint) passes through, found by the search; none when no
/// sampled plane gives one. `scratch`: working memory of the section domains, reused from
/// joint to joint.
///
/// A joint that another bone passes through (a sibling of a root along its brother's bone,
/// a twist joint placed on its parent's bone) has no such section when that bone crosses
/// every sampled plane at the joint: the search is then skipped ([`bone_through_joint`]);
/// [`search_cut_candidates`] is the search without this shortcut.
pub fn find_cut_candidates(
    surface: &CutSurface,
    joint: usize,
    frame: &JointFrame,
    bones: &BoneIndex,
    scratch: &mut DomainScratch,
) -> CutSearch {
    match bone_through_joint(surface.params, joint, frame, bones) {
        Some(bone) => CutSearch {
            through_joint: Some(bone),
            ..CutSearch::default()
        },
        None => search_cut_candidates(surface, joint, frame, bones, scratch),
    }
}

/// A bone not at `joint` that crosses every coarse sample plane of the search within
/// `AT_JOINT` × r of the joint (r its surface distance; exactly at the joint when r is
/// 0). Every closed section around the joint encloses such a crossing, so every sample
/// plane is turned down, no refinement follows, and the search finds nothing, in every
/// neighbourhood. The sections are not computed: on 10,000 siblings of one root, each
/// along the bones of the siblings beyond it, they cost a neighbourhood as long as the
/// bone per joint.
pub fn bone_through_joint(
    params: &DecomposeParams,
    joint: usize,
    frame: &JointFrame,
    bones: &BoneIndex,
) -> Option<(usize, usize)> {
    let basis = NormalBasis::new(frame.upper, frame.lower);
    let planes: Vec<Plane> = basis
        .coarse_samples(
            params.angle_step_deg.to_radians(),
            params.cone_half_angle_deg.to_radians(),
        )
        .into_iter()
        .map(|(alpha, beta)| Plane {
            point: frame.position,
            normal: basis.normal(alpha, beta),
        })
        .collect();
    if planes.is_empty() {
        return None;
    }
    let tolerance = AT_JOINT * frame.surface_distance;
    bones.find_near(joint, frame.position, tolerance, |[a, b]| {
        planes.iter().all(|plane| {
            crossing(plane, a, b).is_some_and(|x| x.distance(plane.point) <= tolerance)
        })
    })
}

/// Where the segment a–b crosses `plane`, when its ends lie on the two sides.
fn crossing(plane: &Plane, a: DVec3, b: DVec3) -> Option<DVec3> {
    let (da, db) = (plane.signed_distance(a), plane.signed_distance(b));
    ((da < 0.0) != (db < 0.0)).then(|| a + (b - a) * (da / (da - db)))
}

/// The search of [`find_cut_candidates`] without its shortcut.
pub fn search_cut_candidates(
    surface: &CutSurface,
    joint: usize,
    frame: &JointFrame,
    bones: &BoneIndex,
    scratch: &mut DomainScratch,
) -> CutSearch {
    let mut radius =
        surface.params.neighbourhood_factor * frame.surface_distance.max(0.1 * frame.bone_length);
    let mut last = CutSearch::default();
    for _ in 0..NEIGHBOURHOOD_ATTEMPTS {
        let near_bones = bones.near(joint, frame.position, 2.0 * radius);
        let (search, every_plane_encloses) =
            search_within(surface, frame, &near_bones, radius, scratch);
        if !search.candidates.is_empty()
            || every_plane_encloses
            || surface.spheres.all_near(frame.position, radius)
        {
            return search;
        }
        last = search;
        radius *= 2.0;
    }
    last
}

/// The search of [`find_cut_candidates`] on the sections of the faces near the joint
/// within `radius` ([`FaceSpheres::faces_near`]), and whether it
/// found no candidate because every sampled plane has a closed section around the joint
/// that encloses another bone. A larger neighbourhood then finds none either (issue 45: a
/// chain coiled in a capsule searched each of its joints in three neighbourhoods, the last
/// holding 40% of the surface): in one plane the closed sections around the joint are
/// nested, a larger neighbourhood keeps every section the smaller one closed and only adds
/// outer ones, which enclose the inner one and the bone it encloses, and it only adds
/// bones. (Sections of pieces that cross one another are not nested; the weights of the
/// 113 real characters of docs/measurements.md, "Many joints", are the same with and
/// without this.)
fn search_within(
    surface: &CutSurface,
    frame: &JointFrame,
    other_bones: &[[DVec3; 2]],
    radius: f64,
    scratch: &mut DomainScratch,
) -> (CutSearch, bool) {
    let (mesh, topology, params) = (surface.mesh, surface.topology, surface.params);
    let mut search = PlaneSearch {
        mesh,
        topology,
        other_bones,
        enclosing_other_bones: 0,
        position: frame.position,
        domain: JointSections::new(
            mesh,
            topology,
            (surface.vertex_snap, surface.max_snap),
            surface.spheres,
            (frame.position, radius),
            scratch,
        ),
        basis: NormalBasis::new(frame.upper, frame.lower),
        evaluated: Vec::new(),
    };
    let step = params.angle_step_deg.to_radians();
    // The planes found, as (α, β, index of the plane in `search.evaluated`).
    let mut found: Vec<(f64, f64, usize)> = search
        .basis
        .coarse_samples(step, params.cone_half_angle_deg.to_radians())
        .into_iter()
        .filter_map(|(alpha, beta)| search.evaluate(alpha, beta).map(|i| (alpha, beta, i)))
        .collect();
    let best = found
        .iter()
        .min_by(|x, y| search.perimeter(x.2).total_cmp(&search.perimeter(y.2)))
        .map(|&(alpha, beta, i)| (alpha, beta, search.perimeter(i)));
    if let Some((mut alpha, mut beta, mut perimeter)) = best {
        let basis = search.basis;
        let mut h = step / 2.0;
        for _ in 0..params.refine_iterations {
            let mut moves = vec![(alpha + h, beta), (alpha - h, beta)];
            if basis.cone {
                moves.extend([(alpha, beta + h), (alpha, beta - h)]);
            }
            let better = moves
                .into_iter()
                .filter(|&(a, b)| basis.separates(a, b))
                .filter_map(|(a, b)| {
                    search
                        .evaluate(a, b)
                        .map(|i| (a, b, search.perimeter(i), i))
                })
                .filter(|&(_, _, p, _)| p < perimeter)
                .min_by(|x, y| x.2.total_cmp(&y.2));
            match better {
                Some((a, b, p, i)) => {
                    (alpha, beta, perimeter) = (a, b, p);
                    found.push((a, b, i));
                }
                None => h /= 2.0,
            }
        }
    }
    let every_plane_encloses = found.is_empty()
        && !search.evaluated.is_empty()
        && search
            .evaluated
            .iter()
            .all(|(_, _, enclosing)| *enclosing > 0);
    let mut candidates = search.take_candidates(found.into_iter().map(|(_, _, i)| i));
    candidates.sort_by(|x, y| x.perimeter.total_cmp(&y.perimeter));
    let search = CutSearch {
        candidates,
        enclosing_other_bones: search.enclosing_other_bones,
        through_joint: None,
    };
    (search, every_plane_encloses)
}

/// The frame the normals are parametrised in:
/// n(α, β) ∝ cos α cos β · a + sin α cos β · b + sin β · c, with a the bisector of the bones. In the planar case β = 0 and b spans Q
/// with a; in the cone case b, c are any unit pair orthogonal to a.
#[derive(Debug, Clone, Copy)]
struct NormalBasis {
    upper: DVec3,
    lower: DVec3,
    a: DVec3,
    b: DVec3,
    c: DVec3,
    cone: bool,
}

impl NormalBasis {
    fn new(upper: DVec3, lower: DVec3) -> Self {
        let collinear = upper.dot(lower) >= COLLINEAR_DEGREES.to_radians().cos();
        let a = (upper + lower).try_normalize().unwrap_or(upper);
        let in_q = (lower - upper) - a * (lower - upper).dot(a);
        match in_q.try_normalize() {
            Some(b) if !collinear => Self {
                upper,
                lower,
                a,
                b,
                c: a.cross(b),
                cone: false,
            },
            _ => {
                let (b, c) = a.any_orthonormal_pair();
                Self {
                    upper,
                    lower,
                    a,
                    b,
                    c,
                    cone: true,
                }
            }
        }
    }

    /// Whether n(α, β) separates the bones: n · u > 0 and n · l > 0.
    fn separates(&self, alpha: f64, beta: f64) -> bool {
        let n = self.normal(alpha, beta);
        n.dot(self.upper) > 0.0 && n.dot(self.lower) > 0.0
    }

    fn normal(&self, alpha: f64, beta: f64) -> DVec3 {
        (alpha.cos() * beta.cos() * self.a
            + alpha.sin() * beta.cos() * self.b
            + beta.sin() * self.c)
            .normalize()
    }

    /// (α, β) of the coarse samples that separate the bones: α every `step` over the open
    /// half circle in the planar case; in the cone case, rings every 2·`step` of polar angle
    /// up to `half_angle`, each ring sampled about every 2·`step` of arc.
    fn coarse_samples(&self, step: f64, half_angle: f64) -> Vec<(f64, f64)> {
        let mut samples = self.all_samples(step, half_angle);
        samples.retain(|&(alpha, beta)| self.separates(alpha, beta));
        samples
    }

    fn all_samples(&self, step: f64, half_angle: f64) -> Vec<(f64, f64)> {
        let step = step.max(1e-3);
        if !self.cone {
            let count = (std::f64::consts::PI / step).ceil() as usize;
            let h = std::f64::consts::PI / count as f64;
            return (1..count)
                .map(|k| (-std::f64::consts::FRAC_PI_2 + k as f64 * h, 0.0))
                .collect();
        }
        let ring_step = 2.0 * step;
        let rings = (half_angle / ring_step).floor() as usize;
        let mut samples = vec![(0.0, 0.0)];
        for r in 1..=rings {
            let polar = r as f64 * ring_step;
            let count = ((std::f64::consts::TAU * polar.sin()) / ring_step)
                .ceil()
                .max(3.0) as usize;
            for k in 0..count {
                let azimuth = std::f64::consts::TAU * k as f64 / count as f64;
                let n = polar.cos() * self.a
                    + polar.sin() * (azimuth.cos() * self.b + azimuth.sin() * self.c);
                samples.push((n.dot(self.b).atan2(n.dot(self.a)), n.dot(self.c).asin()));
            }
        }
        samples
    }
}

/// One joint's search state: its face domain and buffers.
struct PlaneSearch<'a> {
    mesh: &'a SurfaceMesh,
    topology: &'a Topology,
    /// Bones not incident to J near it, as segments.
    other_bones: &'a [[DVec3; 2]],
    /// Count of sections around J turned down for enclosing another bone.
    enclosing_other_bones: usize,
    position: DVec3,
    domain: JointSections<'a>,
    basis: NormalBasis,
    /// Every plane evaluated, by the bits of its normal: its outcome and how many sections
    /// it turned down for enclosing another bone.
    evaluated: Vec<([u64; 3], Option<CutCandidate>, usize)>,
}

impl PlaneSearch<'_> {
    /// The shortest closed section of P(J, n(α, β)) around J that no other bone passes
    /// through, as the index of its plane in `evaluated`; `None` when there is none. The
    /// pattern search comes back to planes it has evaluated (a move from α to α + h tries
    /// α + h − h, which is often α to the bit): a plane's outcome depends on its normal
    /// alone (the point is J), so an evaluated normal's outcome is reused, its turned-down
    /// sections counted again as a new evaluation would. The sections stay in `evaluated`
    /// (not copied per use) until [`Self::take_candidates`].
    fn evaluate(&mut self, alpha: f64, beta: f64) -> Option<usize> {
        let normal = self.basis.normal(alpha, beta);
        let key = [normal.x.to_bits(), normal.y.to_bits(), normal.z.to_bits()];
        if let Some(i) = self.evaluated.iter().position(|e| e.0 == key) {
            let (_, best, enclosing) = &self.evaluated[i];
            self.enclosing_other_bones += enclosing;
            return best.is_some().then_some(i);
        }
        let before = self.enclosing_other_bones;
        let best = self.shortest_section(normal);
        let enclosing = self.enclosing_other_bones - before;
        let found = best.is_some();
        self.evaluated.push((key, best, enclosing));
        found.then_some(self.evaluated.len() - 1)
    }

    /// F of the section of evaluated plane `i` (one [`Self::evaluate`] gave).
    fn perimeter(&self, i: usize) -> f64 {
        self.evaluated[i]
            .1
            .as_ref()
            .map_or(f64::NAN, |c| c.perimeter)
    }

    /// The sections of the evaluated planes `planes` (indices [`Self::evaluate`] gave), in
    /// that order: each moved out of `evaluated`, copied only for a plane listed again.
    fn take_candidates(&mut self, planes: impl Iterator<Item = usize>) -> Vec<CutCandidate> {
        let mut taken_at: Vec<Option<usize>> = vec![None; self.evaluated.len()];
        let mut candidates: Vec<CutCandidate> = Vec::new();
        for i in planes {
            let candidate = match taken_at[i] {
                Some(k) => candidates[k].clone(),
                None => {
                    taken_at[i] = Some(candidates.len());
                    self.evaluated[i]
                        .1
                        .take()
                        .expect("an evaluated plane with a section")
                }
            };
            candidates.push(candidate);
        }
        candidates
    }

    /// [`Self::evaluate`] of the plane through J with unit `normal`, computed.
    fn shortest_section(&mut self, normal: DVec3) -> Option<CutCandidate> {
        let plane = Plane {
            point: self.position,
            normal,
        };
        let mut best: Option<CutCandidate> = None;
        for curve in self.domain.sections_around(&plane) {
            let points = curve.positions(self.mesh, self.topology);
            if !polygon_contains(&points, plane.normal, plane.point) {
                continue;
            }
            let encloses_other_bone = self.other_bones.iter().any(|&[a, b]| {
                crossing(&plane, a, b).is_some_and(|x| polygon_contains(&points, plane.normal, x))
            });
            if encloses_other_bone {
                self.enclosing_other_bones += 1;
                continue;
            }
            let perimeter = closed_length(&points);
            if best.as_ref().is_none_or(|b| perimeter < b.perimeter) {
                best = Some(CutCandidate {
                    plane,
                    curve,
                    points,
                    perimeter,
                });
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_point_to_the_child_side() {
        let upper = DVec3::Y;
        for lower in [
            DVec3::new(0.8, 0.6, 0.0),
            DVec3::Y,
            DVec3::new(0.0, 0.995, 0.0998),
        ] {
            let basis = NormalBasis::new(upper, lower.normalize());
            for (alpha, beta) in basis.coarse_samples(5f64.to_radians(), 30f64.to_radians()) {
                let n = basis.normal(alpha, beta);
                assert!(n.dot(upper) > 0.0 && n.dot(lower) > 0.0);
            }
        }
        assert!(NormalBasis::new(upper, DVec3::Y).cone);
        assert!(!NormalBasis::new(upper, DVec3::new(0.8, 0.6, 0.0)).cone);
    }

    /// A plane evaluated again gives what it gave, and counts its turned-down sections
    /// again, as computing it anew does: a bent tube, with and without another bone through
    /// the joint's sections, the coarse samples and moves of ±h from them, each twice. The
    /// sections taken out at the end are those computed, in the order asked, a plane asked
    /// for twice given twice.
    #[test]
    fn a_plane_evaluated_again_gives_what_computing_it_gives() {
        use crate::cuts::plane_section::vertex_snap_distances;
        use crate::fixtures::shapes::bent_cylinder;
        let (mesh, _) = bent_cylinder(0.2, 1.0, 60.0, 16, 8);
        let topology = Topology::new(&mesh);
        let snap = vertex_snap_distances(&mesh, &topology, 0.01);
        let spheres = FaceSpheres::new(&mesh);
        let joint = DVec3::Y;
        let through = [[
            joint + 0.05 * DVec3::X - 0.1 * DVec3::Y,
            joint + 0.05 * DVec3::X + 0.1 * DVec3::Y,
        ]];
        let max_snap = snap.iter().copied().fold(0.0, f64::max);
        let (mut scratch, mut other_scratch) = (DomainScratch::default(), DomainScratch::default());
        for other_bones in [&[][..], &through[..]] {
            let new_search = |domain| PlaneSearch {
                mesh: &mesh,
                topology: &topology,
                other_bones,
                enclosing_other_bones: 0,
                position: joint,
                domain,
                basis: NormalBasis::new(DVec3::Y, DVec3::new(0.6f64.sin(), 0.6f64.cos(), 0.0)),
                evaluated: Vec::new(),
            };
            // Every face: a ball far larger than the tube.
            let (snap, ball) = ((snap.as_slice(), max_snap), (joint, 100.0));
            let domain =
                |scratch| JointSections::new(&mesh, &topology, snap, &spheres, ball, scratch);
            let (mut reused, mut computed) = (
                new_search(domain(&mut scratch)),
                new_search(domain(&mut other_scratch)),
            );
            let h = 5f64.to_radians();
            let samples = reused.basis.coarse_samples(2.0 * h, 30f64.to_radians());
            let (mut asked, mut expected_sections) = (Vec::new(), Vec::new());
            for (alpha, beta) in samples
                .iter()
                .flat_map(|&(a, b)| [(a, b), (a + h, b), (a + h - h, b)])
            {
                for _ in 0..2 {
                    let expected = computed.shortest_section(computed.basis.normal(alpha, beta));
                    let plane = reused.evaluate(alpha, beta);
                    assert_eq!(plane.is_some(), expected.is_some());
                    if let (Some(i), Some(expected)) = (plane, expected) {
                        assert_eq!(reused.evaluated[i].1.as_ref(), Some(&expected));
                        assert_eq!(reused.perimeter(i), expected.perimeter);
                        asked.push(i);
                        expected_sections.push(expected);
                    }
                    assert_eq!(reused.enclosing_other_bones, computed.enclosing_other_bones);
                }
            }
            assert!(!asked.is_empty());
            assert_eq!(computed.enclosing_other_bones > 0, !other_bones.is_empty());
            assert!(reused.evaluated.len() < 3 * samples.len());
            assert!(asked.len() > reused.evaluated.iter().filter(|e| e.1.is_some()).count());
            assert_eq!(reused.take_candidates(asked.into_iter()), expected_sections);
        }
    }
}

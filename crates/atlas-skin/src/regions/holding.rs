//! The region that holds a soft joint on a surface of several pieces.
//!
//! On one connected surface a joint without a cut lies in its parent's region: no cut
//! separates them (§3.2). On a character made of pieces the parent's region can lie on
//! another piece than the one around the joint (a dress holding the shoulders and the
//! head while the root's region is the legs' piece; a hand piece holding the palm joints
//! while the forearm's cut left their parent's region on the sleeve). The joint's soft
//! boundary then finds none of its region near the joint and carries no weight
//! ([`crate::weights::soft_sides`]), and the piece around it moves with whatever joint
//! the rules for regions without joints give it.
//!
//! The rule, in two steps:
//! 1. A joint whose section (the best closed section of its soft boundary) lies on one
//!    region — more than half of the section's points are nearest to that region's
//!    faces — is held by that region: its boundary acts where its cross-section runs (a
//!    spine joint whose parent's region is a belt, while its section runs around the
//!    dress's torso; docs/pieces.md, "The section's region").
//! 2. Otherwise, with d_N the distance from the joint to the nearest face of the surface
//!    and D the diameter of the joint's section (its best closed section, else 2 d_N, as
//!    the soft boundary's), the parent's region holds the joint when one of its faces lies
//!    within d_N + ρ D of it (ρ = [`REACH`]): it reaches the joint's cross-section.
//! 3. Else a joint with child bones is held by the region nearest to its own bones where
//!    they leave it: of the points at k/8 of each child bone (k = 1..4,
//!    [`own_bone_points`]), the region of the nearest face to the most of them (the
//!    smallest region on ties). A thigh joint beside the hem of a shirt tucked into
//!    trousers acts on the trousers around its bone, not on the hem (rignet-val/9866,
//!    whose thighs moved with the waist: docs/pieces.md, "Soft joints beside another
//!    piece's hem"). A leaf, whose bone is a guess, is held by the region of the nearest
//!    face.
//!
//! [`super::bind_regions`] says what the holding region is bound to.

use crate::mesh::{FaceSpheres, NearestPoint, SurfaceMesh};
use glam::DVec3;

/// ρ: how far past the nearest surface, in section diameters, the parent's region may lie
/// and still hold the joint. Measured over the benchmark and the corpus (docs/pieces.md,
/// "Soft joints on another piece"): 0.5, 1, 2 and 4 change 15, 11, 10 and 6 characters;
/// 2 gives the lowest average deform mean, max and weight L1.
pub const REACH: f64 = 2.0;

/// Where a joint's own bones leave it (step 3 of the rule): the points at k/8 of the bone
/// from `joint` to each of `children` (k = 1..4), the half of each child bone nearest the
/// joint. None for a leaf.
pub fn own_bone_points(joint: DVec3, children: impl Iterator<Item = DVec3>) -> Vec<DVec3> {
    children
        .flat_map(|child| (1..=4).map(move |k| joint.lerp(child, k as f64 / 8.0)))
        .collect()
}

/// The faces of the split surface with their regions, for [`Self::holding_region`].
pub struct HoldingRegions<'a> {
    mesh: &'a SurfaceMesh,
    face_region: &'a [u32],
    spheres: &'a FaceSpheres,
}

impl<'a> HoldingRegions<'a> {
    /// The faces of `mesh` (the split surface) indexed by `spheres`, `face_region` the
    /// region of each.
    pub fn new(mesh: &'a SurfaceMesh, face_region: &'a [u32], spheres: &'a FaceSpheres) -> Self {
        Self {
            mesh,
            face_region,
            spheres,
        }
    }

    /// The region holding a soft joint at `position` when its parent lies in
    /// `parent_region` (module documentation): the region of more than half of `section`
    /// (the points of its best closed section, empty without one), else `parent_region`
    /// when it reaches the joint across `diameter`, the section's diameter, else the
    /// region nearest to the most of `own` (points along its child bones,
    /// [`own_bone_points`]; empty for a leaf), else the region of the nearest face.
    pub fn holding_region(
        &self,
        position: DVec3,
        section: &[DVec3],
        diameter: f64,
        parent_region: Option<u32>,
        own: &[DVec3],
    ) -> Option<u32> {
        if let Some(region) = self.section_region(section) {
            return Some(region);
        }
        let Some(nearest) = self.spheres.nearest_point(self.mesh, position) else {
            return parent_region;
        };
        let nearest_region = self.face_region[nearest.face as usize];
        let Some(parent) = parent_region else {
            return Some(nearest_region);
        };
        if parent == nearest_region {
            return Some(parent);
        }
        let reach = nearest.distance + REACH * diameter.max(0.0);
        let reaches = self
            .spheres
            .faces_near(position, reach)
            .into_iter()
            .filter(|&f| self.face_region[f as usize] == parent)
            .any(|f| NearestPoint::on_face(self.mesh, f, position).distance <= reach);
        if reaches {
            return Some(parent);
        }
        Some(self.most_frequent_region(own).unwrap_or(nearest_region))
    }

    /// The regions of the faces nearest to `points`, sorted.
    fn nearest_regions(&self, points: &[DVec3]) -> Vec<u32> {
        let mut regions: Vec<u32> = points
            .iter()
            .filter_map(|&p| self.spheres.nearest_point(self.mesh, p))
            .map(|nearest| self.face_region[nearest.face as usize])
            .collect();
        regions.sort_unstable();
        regions
    }

    /// The region whose faces are nearest to the most of `points`, the smallest on ties
    /// (step 3 of the rule); none without points.
    fn most_frequent_region(&self, points: &[DVec3]) -> Option<u32> {
        let regions = self.nearest_regions(points);
        let mut best: Option<&[u32]> = None;
        for run in regions.chunk_by(|a, b| a == b) {
            if best.is_none_or(|b| run.len() > b.len()) {
                best = Some(run);
            }
        }
        best.map(|run| run[0])
    }

    /// The region whose faces are nearest to more than half of `points` (step 1 of the
    /// rule), if any.
    fn section_region(&self, points: &[DVec3]) -> Option<u32> {
        self.nearest_regions(points)
            .chunk_by(|a, b| a == b)
            .find(|run| 2 * run.len() > points.len())
            .map(|run| run[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::shapes::icosphere;

    /// One piece per ball (centre, radius), region k the faces of ball k.
    fn balls(balls: &[(DVec3, f64)]) -> (SurfaceMesh, Vec<u32>) {
        let mut mesh = SurfaceMesh::default();
        let mut face_region = Vec::new();
        for (k, &(centre, radius)) in balls.iter().enumerate() {
            let ball = icosphere(radius, 2);
            let offset = mesh.vertex_count() as u32;
            mesh.positions
                .extend(ball.positions.iter().map(|&p| p + centre));
            mesh.triangles
                .extend(ball.triangles.iter().map(|t| t.map(|v| v + offset)));
            face_region.resize(mesh.triangle_count(), k as u32);
        }
        (mesh, face_region)
    }

    /// Two pieces: a ball of radius 1 at the origin (region 0) and one of radius 0.3 at
    /// x = 5 (region 1).
    fn two_balls() -> (SurfaceMesh, Vec<u32>) {
        balls(&[(DVec3::ZERO, 1.0), (DVec3::new(5.0, 0.0, 0.0), 0.3)])
    }

    #[test]
    fn a_joint_inside_another_piece_than_its_parents_region_is_held_by_that_piece() {
        let (mesh, face_region) = two_balls();
        let spheres = FaceSpheres::new(&mesh);
        let holders = HoldingRegions::new(&mesh, &face_region, &spheres);
        // At the centre of the small ball: its surface lies about 0.3 away, the big
        // ball's about 4: d_N + ρ D = 0.3 + 2 × 0.6 falls short of it.
        let centre = DVec3::new(5.0, 0.0, 0.0);
        assert_eq!(
            holders.holding_region(centre, &[], 0.6, Some(0), &[]),
            Some(1)
        );
        // A section wide enough to reach the big ball keeps the parent's region:
        // 0.3 + 2 × 2 ≥ 4.
        assert_eq!(
            holders.holding_region(centre, &[], 2.0, Some(0), &[]),
            Some(0)
        );
        // Its own region, or none, is always answered by the nearest piece.
        assert_eq!(
            holders.holding_region(centre, &[], 0.6, Some(1), &[]),
            Some(1)
        );
        assert_eq!(holders.holding_region(centre, &[], 0.6, None, &[]), Some(1));
        // Inside the big ball the parent's region holds the joint.
        assert_eq!(
            holders.holding_region(DVec3::ZERO, &[], 0.6, Some(0), &[]),
            Some(0)
        );
    }

    /// Points on the circle of radius `radius` about `centre` in the plane z = 0.
    fn circle(centre: DVec3, radius: f64, count: usize) -> Vec<DVec3> {
        (0..count)
            .map(|k| {
                let angle = std::f64::consts::TAU * k as f64 / count as f64;
                centre + radius * DVec3::new(angle.cos(), angle.sin(), 0.0)
            })
            .collect()
    }

    #[test]
    fn a_joint_is_held_by_the_region_its_section_runs_on() {
        let (mesh, face_region) = two_balls();
        let spheres = FaceSpheres::new(&mesh);
        let holders = HoldingRegions::new(&mesh, &face_region, &spheres);
        let centre = DVec3::new(5.0, 0.0, 0.0);
        let section = circle(centre, 0.3, 24);
        // A section wide enough for the parent's region to reach the joint (as above):
        // the section runs on the small ball, which holds the joint.
        assert_eq!(
            holders.holding_region(centre, &section, 2.0, Some(0), &[]),
            Some(1)
        );
        // A section around the big ball keeps the joint there, even at the small ball.
        let around_big = circle(DVec3::ZERO, 1.0, 24);
        assert_eq!(
            holders.holding_region(centre, &around_big, 0.6, Some(1), &[]),
            Some(0)
        );
        // Half on each: no region holds the section, the distances decide (as above).
        let mut halves = circle(centre, 0.3, 12);
        halves.extend(circle(DVec3::ZERO, 1.0, 12));
        assert_eq!(
            holders.holding_region(centre, &halves, 2.0, Some(0), &[]),
            Some(0)
        );
        assert_eq!(
            holders.holding_region(centre, &halves, 0.6, Some(0), &[]),
            Some(1)
        );
    }

    /// A thigh joint beside a shirt's hem: the hem (region 1) is the nearest piece, the
    /// parent's region (2) lies far away, and the thigh bone runs down inside the
    /// trousers (region 0). Its own bones decide; a leaf keeps the nearest piece.
    #[test]
    fn a_joint_beside_another_pieces_hem_is_held_by_the_piece_around_its_bone() {
        let (mesh, face_region) = balls(&[
            (DVec3::ZERO, 1.0),
            (DVec3::new(0.85, 0.0, 0.0), 0.1),
            (DVec3::new(-10.0, 0.0, 0.0), 1.0),
        ]);
        let spheres = FaceSpheres::new(&mesh);
        let holders = HoldingRegions::new(&mesh, &face_region, &spheres);
        let joint = DVec3::ZERO;
        let knee = DVec3::new(0.0, -0.9, 0.0);
        let thigh = own_bone_points(joint, [knee].into_iter());
        assert_eq!(thigh.len(), 4);
        assert!(thigh[0].distance(DVec3::new(0.0, -0.1125, 0.0)) < 1e-12);
        assert!(thigh[3].distance(DVec3::new(0.0, -0.45, 0.0)) < 1e-12);
        // The hem is nearest to the joint (0.75 against the trousers' 1) and to the
        // first point of the bone; the trousers to the other three.
        assert_eq!(
            holders.holding_region(joint, &[], 0.1, Some(2), &thigh),
            Some(0)
        );
        assert_eq!(
            holders.holding_region(joint, &[], 0.1, Some(2), &[]),
            Some(1)
        );
        // A bone that runs into the hem: the hem holds it.
        let into_hem = own_bone_points(joint, [DVec3::new(1.6, 0.0, 0.0)].into_iter());
        assert_eq!(
            holders.holding_region(joint, &[], 0.1, Some(2), &into_hem),
            Some(1)
        );
        // The parent's region, when it reaches the joint, still comes first.
        assert_eq!(
            holders.holding_region(joint, &[], 5.0, Some(2), &thigh),
            Some(2)
        );
    }

    #[test]
    fn a_surface_without_faces_keeps_the_parents_region() {
        let mesh = SurfaceMesh::default();
        let spheres = FaceSpheres::new(&mesh);
        let holders = HoldingRegions::new(&mesh, &[], &spheres);
        assert_eq!(
            holders.holding_region(DVec3::ZERO, &[], 1.0, Some(3), &[]),
            Some(3)
        );
        assert_eq!(
            holders.holding_region(DVec3::ZERO, &[], 1.0, None, &[]),
            None
        );
    }
}

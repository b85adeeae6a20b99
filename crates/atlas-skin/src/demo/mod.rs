//! The project's own demo character: a closed, genus-0 humanoid with hands, fingers, feet
//! and a 35-joint skeleton, generated in code so that the main job runs with no download.
//!
//! The body is the zero set of a smooth union of round cones (one per body part) and is
//! meshed by [`marching_tetrahedra`]; vertices are then relaxed along the surface for better
//! triangles. Y is up, the character faces +Z, units are metres, arms out in a T-pose with
//! the palms down and the fingers spread. Because the shape is known, so are the right
//! answers: which joints must be cut, which regions arise.

pub mod decimate;
pub mod marching_tetrahedra;

use atlas_skin_runtime::{Skeleton, NO_PARENT};
use glam::{DVec3, Vec3};
use marching_tetrahedra::Grid;

/// The demo character: mesh and skeleton.
#[derive(Debug, Clone)]
pub struct DemoCharacter {
    /// #V vertex positions (metres, Y up).
    pub positions: Vec<Vec3>,
    /// #F outward-oriented triangles.
    pub triangles: Vec<[u32; 3]>,
    pub skeleton: Skeleton,
}

/// Grid spacing of the default demo (metres).
pub const DEFAULT_STEP: f64 = 0.013;

/// Vertices of the default demo after coarsening.
pub const DEFAULT_VERTICES: usize = 16_000;

/// A tapered capsule: points within a radius interpolated from `radius_a` at `a` to
/// `radius_b` at `b` of the segment ab, after scaling space by `1 / squash` per axis (a
/// flattened part such as the palm has squash.y < 1).
struct RoundCone {
    a: DVec3,
    b: DVec3,
    radius_a: f64,
    radius_b: f64,
    squash: DVec3,
}

impl RoundCone {
    fn new(a: DVec3, b: DVec3, radius_a: f64, radius_b: f64) -> Self {
        Self {
            a,
            b,
            radius_a,
            radius_b,
            squash: DVec3::ONE,
        }
    }

    fn squashed(mut self, squash: DVec3) -> Self {
        self.squash = squash;
        self
    }

    /// A cheap lower bound of [`RoundCone::value`] from the part's bounding sphere:
    /// squashing only stretches distances, and the value is scaled by the smallest squash.
    fn lower_bound(&self, p: DVec3) -> f64 {
        let centre = (self.a + self.b) * 0.5;
        let reach = 0.5 * self.a.distance(self.b) + self.radius_a.max(self.radius_b);
        (p.distance(centre) - reach).max(0.0) * self.squash.min_element()
    }

    /// An implicit value: negative inside, about the distance to the surface near it.
    fn value(&self, p: DVec3) -> f64 {
        let centre = (self.a + self.b) * 0.5;
        let to_local = |q: DVec3| centre + (q - centre) / self.squash;
        let (p, a, b) = (to_local(p), to_local(self.a), to_local(self.b));
        let ab = b - a;
        let t = if ab.length_squared() > 0.0 {
            ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let radius = self.radius_a + (self.radius_b - self.radius_a) * t;
        ((p - (a + ab * t)).length() - radius) * self.squash.min_element()
    }
}

/// Polynomial smooth minimum (Quilez): min(a, b) rounded over a band of width `k`.
fn smooth_min(a: f64, b: f64, k: f64) -> f64 {
    let h = (k - (a - b).abs()).max(0.0) / k;
    a.min(b) - h * h * k * 0.25
}

struct Joint {
    name: String,
    parent: Option<usize>,
    position: DVec3,
}

/// Joints (name, parent, position) and body parts of the demo.
fn layout() -> (Vec<Joint>, Vec<RoundCone>) {
    let mut joints: Vec<Joint> = Vec::new();
    let mut add = |name: &str, parent: Option<usize>, position: DVec3| {
        joints.push(Joint {
            name: name.to_string(),
            parent,
            position,
        });
        joints.len() - 1
    };
    let v = DVec3::new;
    let hips = add("hips", None, v(0.0, 0.95, 0.0));
    let spine = add("spine", Some(hips), v(0.0, 1.12, 0.0));
    let chest = add("chest", Some(spine), v(0.0, 1.30, 0.0));
    let neck = add("neck", Some(chest), v(0.0, 1.50, 0.0));
    add("head", Some(neck), v(0.0, 1.60, 0.0));
    let mut parts = vec![
        RoundCone::new(v(-0.1, 0.93, 0.0), v(0.1, 0.93, 0.0), 0.13, 0.13)
            .squashed(v(1.0, 1.0, 0.75)),
        RoundCone::new(v(0.0, 0.95, 0.0), v(0.0, 1.36, 0.0), 0.15, 0.17)
            .squashed(v(1.0, 1.0, 0.65)),
        RoundCone::new(v(0.0, 1.36, 0.0), v(0.0, 1.62, 0.0), 0.05, 0.05),
        RoundCone::new(v(0.0, 1.71, 0.01), v(0.0, 1.71, 0.01), 0.11, 0.11),
    ];
    for (side, sx) in [("l", 1.0), ("r", -1.0)] {
        let m = |p: DVec3| DVec3::new(p.x * sx, p.y, p.z);
        let name = |n: &str| format!("{n}_{side}");
        // Arm, T-pose along ±X, palm down.
        let shoulder = add(&name("upperarm"), Some(chest), m(v(0.22, 1.40, 0.0)));
        let elbow = add(&name("lowerarm"), Some(shoulder), m(v(0.48, 1.40, 0.0)));
        let wrist = add(&name("hand"), Some(elbow), m(v(0.74, 1.40, 0.0)));
        parts.push(RoundCone::new(
            m(v(0.12, 1.40, 0.0)),
            m(v(0.48, 1.40, 0.0)),
            0.05,
            0.042,
        ));
        parts.push(RoundCone::new(
            m(v(0.48, 1.40, 0.0)),
            m(v(0.74, 1.40, 0.0)),
            0.042,
            0.034,
        ));
        parts.push(
            RoundCone::new(m(v(0.74, 1.40, 0.0)), m(v(0.84, 1.40, 0.0)), 0.05, 0.05)
                .squashed(v(1.0, 0.45, 1.0)),
        );
        // Three fingers fanned in the horizontal plane, and a thumb pointing forward. Each
        // digit's first joint sits `knuckle` along it from its base, where the digit has left
        // the palm: a section there rings one digit, not the palm with the others' bones.
        let digits = [
            ("index", v(0.84, 1.40, 0.045), 22.0_f64, 0.13, 0.021, 0.05),
            ("middle", v(0.84, 1.40, 0.0), 0.0, 0.14, 0.021, 0.055),
            ("ring", v(0.84, 1.40, -0.045), -22.0, 0.12, 0.020, 0.05),
            ("thumb", v(0.76, 1.40, 0.035), 70.0, 0.10, 0.022, 0.045),
        ];
        for (digit, base, degrees, length, radius, knuckle) in digits {
            let direction = v(degrees.to_radians().cos(), 0.0, degrees.to_radians().sin());
            let first = add(
                &name(&format!("{digit}1")),
                Some(wrist),
                m(base + direction * knuckle),
            );
            add(
                &name(&format!("{digit}2")),
                Some(first),
                m(base + direction * (knuckle + length) * 0.5),
            );
            parts.push(RoundCone::new(
                m(base),
                m(base + direction * length),
                radius,
                radius * 0.8,
            ));
        }
        // Leg.
        let hip = add(&name("upleg"), Some(hips), m(v(0.10, 0.90, 0.0)));
        let knee = add(&name("lowerleg"), Some(hip), m(v(0.11, 0.50, 0.0)));
        let ankle = add(&name("foot"), Some(knee), m(v(0.11, 0.09, -0.01)));
        add(&name("toe"), Some(ankle), m(v(0.11, 0.04, 0.12)));
        parts.push(RoundCone::new(
            m(v(0.10, 0.93, 0.0)),
            m(v(0.11, 0.50, 0.0)),
            0.075,
            0.055,
        ));
        parts.push(RoundCone::new(
            m(v(0.11, 0.50, 0.0)),
            m(v(0.11, 0.09, -0.01)),
            0.055,
            0.04,
        ));
        parts.push(
            RoundCone::new(
                m(v(0.11, 0.07, -0.04)),
                m(v(0.11, 0.045, 0.21)),
                0.045,
                0.035,
            )
            .squashed(v(1.0, 0.75, 1.0)),
        );
    }
    (joints, parts)
}

/// Joints of the demo that must get an exact closed cut: every chain joint and every leaf
/// that owns geometry. `hips` (the root, where spine and legs branch) and `chest` (where
/// neck and arms branch) lie on the symmetry axis and get none, as in the paper (§3.1).
pub fn expected_cut_joints() -> Vec<String> {
    let (joints, _) = layout();
    joints
        .into_iter()
        .map(|j| j.name)
        .filter(|n| n != "hips" && n != "chest")
        .collect()
}

/// Builds the demo character with grid spacing `step` (metres; [`DEFAULT_STEP`] for the
/// default), coarsened to [`DEFAULT_VERTICES`] × (DEFAULT_STEP / step)² vertices.
/// Deterministic: the same step gives the same mesh on every machine.
pub fn demo_character(step: f64) -> DemoCharacter {
    let scale = DEFAULT_STEP / step;
    demo_character_with(step, (DEFAULT_VERTICES as f64 * scale * scale) as usize)
}

/// Builds the demo character by marching tetrahedra on a grid of spacing `step`, then
/// coarsens it by edge collapse to `target_vertices` (when the grid gives more).
pub fn demo_character_with(step: f64, target_vertices: usize) -> DemoCharacter {
    let (joints, parts) = layout();
    const BLEND: f64 = 0.02;
    let field = |p: DVec3| {
        parts.iter().fold(f64::INFINITY, |acc, part| {
            // smooth_min(acc, v) == acc once v ≥ acc + BLEND: skip parts surely that far.
            if part.lower_bound(p) >= acc + BLEND {
                return acc;
            }
            let v = part.value(p);
            if acc.is_finite() {
                smooth_min(acc, v, BLEND)
            } else {
                v
            }
        })
    };
    let (lo, hi) = parts.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), part| {
            let r = part.radius_a.max(part.radius_b);
            (
                lo.min(part.a.min(part.b) - r),
                hi.max(part.a.max(part.b) + r),
            )
        },
    );
    let margin = 3.0 * step;
    let origin = lo - margin;
    let size = hi + margin - origin;
    let counts = [0, 1, 2].map(|axis| (size[axis] / step).ceil() as usize + 1);
    let grid = Grid {
        origin,
        step,
        counts,
    };
    let (positions, triangles) = marching_tetrahedra::extract(&grid, field);
    let (mut positions, triangles) =
        decimate::collapse_shortest_edges(&positions, &triangles, target_vertices, |p| {
            project_onto_surface(p, &field, step)
        });
    relax_onto_surface(&mut positions, &triangles, &field, step);

    let names = joints.iter().map(|j| j.name.clone()).collect();
    let parents = joints
        .iter()
        .map(|j| j.parent.map_or(NO_PARENT, |p| p as u32))
        .collect();
    let joint_positions: Vec<Vec3> = joints.iter().map(|j| j.position.as_vec3()).collect();
    let skeleton = Skeleton::from_positions(names, parents, &joint_positions)
        .expect("the demo skeleton is a valid tree");
    DemoCharacter {
        positions: positions.iter().map(|p| p.as_vec3()).collect(),
        triangles,
        skeleton,
    }
}

/// Moves `p` onto the zero set by three Newton steps along the field's gradient (central
/// differences): p ← p − f(p) ∇f / |∇f|².
fn project_onto_surface(mut p: DVec3, field: &impl Fn(DVec3) -> f64, step: f64) -> DVec3 {
    let h = step * 1e-3;
    for _ in 0..3 {
        let g = DVec3::new(
            field(p + DVec3::X * h) - field(p - DVec3::X * h),
            field(p + DVec3::Y * h) - field(p - DVec3::Y * h),
            field(p + DVec3::Z * h) - field(p - DVec3::Z * h),
        ) / (2.0 * h);
        let g2 = g.length_squared();
        if g2 > 1e-12 {
            p -= g * (field(p) / g2);
        }
    }
    p
}

/// Improves the coarsened triangles: a few rounds of moving each vertex half way to the
/// mean of its neighbours, then back onto the surface. Connectivity is unchanged.
fn relax_onto_surface(
    positions: &mut [DVec3],
    triangles: &[[u32; 3]],
    field: &(impl Fn(DVec3) -> f64 + Sync),
    step: f64,
) {
    use rayon::prelude::*;
    let mesh = crate::SurfaceMesh {
        positions: positions.to_vec(),
        triangles: triangles.to_vec(),
    };
    let topology = crate::Topology::new(&mesh);
    for _ in 0..3 {
        let smoothed: Vec<DVec3> = (0..positions.len())
            .into_par_iter()
            .map(|v| {
                let ring = topology.neighbors(v);
                let mean = ring.iter().map(|&u| positions[u as usize]).sum::<DVec3>()
                    / ring.len().max(1) as f64;
                let p = project_onto_surface(positions[v] * 0.5 + mean * 0.5, field, step);
                // A vertex never travels more than a grid step: keeps the mesh's topology.
                let moved = p - positions[v];
                positions[v] + moved.clamp_length_max(step)
            })
            .collect();
        positions.copy_from_slice(&smoothed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{weld, MeshStats, Topology};

    #[test]
    fn demo_is_closed_genus_zero_with_joints_inside() {
        let demo = demo_character(DEFAULT_STEP);
        let welded = weld(
            &demo.positions,
            &demo.triangles,
            crate::weld::DEFAULT_WELD_TOLERANCE,
        );
        let topology = Topology::new(&welded.mesh);
        let stats = MeshStats::new(&welded.mesh, &topology);
        assert_eq!(stats.components, 1);
        assert!(stats.closed);
        assert_eq!(stats.genus, Some(0));
        assert_eq!(stats.inconsistently_oriented_edges, 0);
        assert_eq!(
            stats.vertices,
            demo.positions.len(),
            "no duplicate vertices"
        );
        for (name, p) in demo
            .skeleton
            .names
            .iter()
            .zip(demo.skeleton.bind_positions())
        {
            assert!(
                crate::winding::is_inside(&welded.mesh, p.as_dvec3()),
                "joint {name} outside the mesh"
            );
        }
        assert_eq!(demo.skeleton.len(), 35);
        assert_eq!(expected_cut_joints().len(), 33);
    }
}

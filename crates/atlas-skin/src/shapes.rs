//! Procedural shapes with known answers, for tests, benchmarks and demos.
//!
//! Every builder returns a closed, consistently outward-oriented genus-0 triangle surface;
//! the tube builders also return the chain skeleton the tube was built around.

use crate::SurfaceMesh;
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use glam::{DVec3, Mat4};
use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// A tube of `radius` bent at its middle joint: a straight segment of `segment_length` from
/// the origin along +Y to the joint, then a second one turned by `bend_degrees` towards +X.
/// The cross-section has `sides` vertices; each segment has `rings_per_segment` rings.
///
/// The skeleton is the chain `root` (origin) → `joint` (the bend) → `end` (the far end of
/// the second segment, an end site inside the far cap); see [`capsule_chain`].
pub fn bent_cylinder(
    radius: f64,
    segment_length: f64,
    bend_degrees: f64,
    sides: usize,
    rings_per_segment: usize,
) -> (SurfaceMesh, Skeleton) {
    let bend = bend_degrees.to_radians();
    let joint = DVec3::Y * segment_length;
    let end = joint + segment_length * DVec3::new(bend.sin(), bend.cos(), 0.0);
    capsule_chain(
        &[DVec3::ZERO, joint, end],
        &["root", "joint", "end"],
        radius,
        sides,
        rings_per_segment,
    )
}

/// A tube of `radius` around the polyline `points` (at least two), closed by hemispherical
/// caps, with a chain skeleton whose joint `k` sits at `points[k]` and is named `names[k]`
/// (`joint{k}` when `names` is shorter).
///
/// At an interior point the two segments meet on the mitre plane (normal = sum of the two
/// unit directions), so the tube keeps its radius around each segment. Frames are carried
/// along the polyline by projection (no twist). `sides` ≥ 3 vertices per ring,
/// `rings_per_segment` ≥ 1 ring intervals per segment, 4 rings per cap.
pub fn capsule_chain(
    points: &[DVec3],
    names: &[&str],
    radius: f64,
    sides: usize,
    rings_per_segment: usize,
) -> (SurfaceMesh, Skeleton) {
    let sides = sides.max(3);
    let rings_per_segment = rings_per_segment.max(1);
    let skeleton = chain_skeleton(points, names);
    if points.len() < 2 {
        return (SurfaceMesh::default(), skeleton);
    }
    let directions: Vec<DVec3> = points
        .windows(2)
        .map(|w| (w[1] - w[0]).normalize_or(DVec3::Y))
        .collect();
    let mut side_axis = directions[0].any_orthonormal_vector();
    let circle = |axis: DVec3, dir: DVec3, k: usize| {
        let angle = TAU * k as f64 / sides as f64;
        let other = dir.cross(axis);
        radius * (angle.cos() * axis + angle.sin() * other)
    };

    // Ring centres and offsets, from the first cap's pole to the last.
    let cap_rings = 4;
    let mut rings: Vec<Vec<DVec3>> = Vec::new();
    let first = directions[0];
    for r in 1..cap_rings {
        let polar = FRAC_PI_2 * r as f64 / cap_rings as f64;
        let centre = points[0] - first * radius * polar.cos();
        rings.push(
            (0..sides)
                .map(|k| centre + circle(side_axis, first, k) * polar.sin())
                .collect(),
        );
    }
    for (s, dir) in directions.iter().enumerate() {
        if s > 0 {
            side_axis =
                (side_axis - dir * side_axis.dot(*dir)).normalize_or(dir.any_orthonormal_vector());
        }
        let (start, end) = (points[s], points[s + 1]);
        for r in 0..rings_per_segment {
            let centre = start.lerp(end, r as f64 / rings_per_segment as f64);
            let mitre = (s > 0 && r == 0).then(|| (directions[s - 1] + *dir).normalize_or(*dir));
            rings.push(
                (0..sides)
                    .map(|k| {
                        let offset = circle(side_axis, *dir, k);
                        match mitre {
                            // Slide the circle point along the tube axis onto the mitre plane.
                            Some(m) if dir.dot(m).abs() > 1e-9 => {
                                centre + offset - *dir * (offset.dot(m) / dir.dot(m))
                            }
                            _ => centre + offset,
                        }
                    })
                    .collect(),
            );
        }
    }
    let last = *directions.last().unwrap_or(&DVec3::Y);
    let tip = *points.last().unwrap_or(&DVec3::ZERO);
    for r in 0..cap_rings {
        let polar = FRAC_PI_2 * r as f64 / cap_rings as f64;
        let centre = tip + last * radius * polar.sin();
        rings.push(
            (0..sides)
                .map(|k| centre + circle(side_axis, last, k) * polar.cos())
                .collect(),
        );
    }

    let mut positions = vec![points[0] - first * radius];
    for ring in &rings {
        positions.extend_from_slice(ring);
    }
    positions.push(tip + last * radius);
    let end_pole = positions.len() as u32 - 1;
    let ring_start = |r: usize| 1 + (r * sides) as u32;
    let mut triangles = Vec::new();
    let next = |k: usize| ((k + 1) % sides) as u32;
    for k in 0..sides {
        triangles.push([0, ring_start(0) + next(k), ring_start(0) + k as u32]);
        let l = ring_start(rings.len() - 1);
        triangles.push([end_pole, l + k as u32, l + next(k)]);
    }
    for r in 0..rings.len() - 1 {
        let (a, b) = (ring_start(r), ring_start(r + 1));
        for k in 0..sides {
            let (k0, k1) = (k as u32, next(k));
            triangles.push([a + k0, a + k1, b + k1]);
            triangles.push([a + k0, b + k1, b + k0]);
        }
    }
    (
        SurfaceMesh {
            positions,
            triangles,
        },
        skeleton,
    )
}

/// A chain skeleton through `points`: joint `k` at `points[k]`, parent `k − 1`.
fn chain_skeleton(points: &[DVec3], names: &[&str]) -> Skeleton {
    let count = points.len();
    Skeleton {
        names: (0..count)
            .map(|k| {
                names
                    .get(k)
                    .map_or_else(|| format!("joint{k}"), |n| n.to_string())
            })
            .collect(),
        parents: (0..count)
            .map(|k| if k == 0 { NO_PARENT } else { k as u32 - 1 })
            .collect(),
        tails: vec![None; count],
        inverse_bind: points
            .iter()
            .map(|p| Mat4::from_translation(-p.as_vec3()))
            .collect(),
    }
}

/// A latitude–longitude sphere of `radius` around the origin: `stacks` ≥ 2 bands from pole
/// (+Z) to pole, `slices` ≥ 3 vertices per ring.
pub fn uv_sphere(radius: f64, stacks: usize, slices: usize) -> SurfaceMesh {
    let (stacks, slices) = (stacks.max(2), slices.max(3));
    let mut positions = vec![DVec3::Z * radius];
    for i in 1..stacks {
        let polar = PI * i as f64 / stacks as f64;
        for k in 0..slices {
            let azimuth = TAU * k as f64 / slices as f64;
            positions.push(
                radius
                    * DVec3::new(
                        polar.sin() * azimuth.cos(),
                        polar.sin() * azimuth.sin(),
                        polar.cos(),
                    ),
            );
        }
    }
    positions.push(-DVec3::Z * radius);
    let south = positions.len() as u32 - 1;
    let ring = |i: usize, k: usize| (1 + i * slices + k % slices) as u32;
    let mut triangles = Vec::new();
    for k in 0..slices {
        triangles.push([0, ring(0, k), ring(0, k + 1)]);
        triangles.push([south, ring(stacks - 2, k + 1), ring(stacks - 2, k)]);
    }
    for i in 0..stacks - 2 {
        for k in 0..slices {
            triangles.push([ring(i, k), ring(i + 1, k), ring(i + 1, k + 1)]);
            triangles.push([ring(i, k), ring(i + 1, k + 1), ring(i, k + 1)]);
        }
    }
    SurfaceMesh {
        positions,
        triangles,
    }
}

/// An icosahedron of circumradius `radius` around the origin, each face split `subdivisions`
/// times into four, new vertices pushed onto the sphere: 20 · 4^s triangles.
pub fn icosphere(radius: f64, subdivisions: usize) -> SurfaceMesh {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<DVec3> = [
        (-1.0, phi, 0.0),
        (1.0, phi, 0.0),
        (-1.0, -phi, 0.0),
        (1.0, -phi, 0.0),
        (0.0, -1.0, phi),
        (0.0, 1.0, phi),
        (0.0, -1.0, -phi),
        (0.0, 1.0, -phi),
        (phi, 0.0, -1.0),
        (phi, 0.0, 1.0),
        (-phi, 0.0, -1.0),
        (-phi, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize() * radius)
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let mut split = |a: u32, b: u32, positions: &mut Vec<DVec3>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (positions[a as usize] + positions[b as usize]).normalize() * radius;
                positions.push(m);
                positions.len() as u32 - 1
            })
        };
        let mut finer = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let ab = split(a, b, &mut positions);
            let bc = split(b, c, &mut positions);
            let ca = split(c, a, &mut positions);
            finer.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = finer;
    }
    SurfaceMesh {
        positions,
        triangles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{MeshStats, Topology};

    fn assert_closed_sphere(mesh: &SurfaceMesh, volume: f64, tolerance: f64) {
        let stats = MeshStats::new(mesh, &Topology::new(mesh));
        assert!(stats.closed, "{stats:?}");
        assert_eq!(stats.genus, Some(0));
        assert_eq!(stats.inconsistently_oriented_edges, 0);
        let v = mesh.signed_volume();
        assert!(
            (v - volume).abs() < tolerance * volume,
            "volume {v}, expected {volume}"
        );
    }

    #[test]
    fn spheres_are_closed_outward_and_of_the_right_volume() {
        let ball = 4.0 / 3.0 * PI;
        assert_closed_sphere(&uv_sphere(1.0, 32, 64), ball, 0.02);
        assert_closed_sphere(&icosphere(1.0, 3), ball, 0.02);
        assert_eq!(icosphere(1.0, 2).triangle_count(), 320);
    }

    fn skeleton_point(skeleton: &Skeleton, j: usize) -> DVec3 {
        skeleton.bind_positions()[j].as_dvec3()
    }

    #[test]
    fn tubes_are_closed_outward_and_keep_their_radius() {
        let (mesh, skeleton) = bent_cylinder(0.5, 3.0, 60.0, 48, 12);
        let capsule = PI * 0.25 * 6.0 + 4.0 / 3.0 * PI * 0.125;
        assert_closed_sphere(&mesh, capsule, 0.02);
        assert_eq!(skeleton.names, ["root", "joint", "end"]);
        assert!(skeleton.validate().is_ok());
        // Every tube vertex lies at the radius from the axis of a segment (mitre rings on
        // both), every cap vertex at the radius from an end point.
        let polyline = [
            DVec3::ZERO,
            skeleton_point(&skeleton, 1),
            skeleton_point(&skeleton, 2),
        ];
        for p in &mesh.positions {
            let off_axis = polyline
                .windows(2)
                .map(|w| {
                    let axis = (w[1] - w[0]).normalize();
                    let along = (*p - w[0]).dot(axis);
                    ((*p - w[0] - axis * along).length() - 0.5).abs()
                })
                .fold(f64::INFINITY, f64::min);
            let off_cap = (p.distance(polyline[0]) - 0.5)
                .abs()
                .min((p.distance(polyline[2]) - 0.5).abs());
            assert!(
                off_axis.min(off_cap) < 1e-6,
                "{p} off the tube by {off_axis}"
            );
        }
    }
}

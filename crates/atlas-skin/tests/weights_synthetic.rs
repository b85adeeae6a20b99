//! The weights stage on decompositions built by hand around tubes whose cut curves are
//! rings of the mesh: invariants, mirror symmetry, no leak across touching parts, soft
//! boundaries that stay on their own side of the surface.

use atlas_skin::fixtures::shapes::capsule_chain;
use atlas_skin::overlap::{compute_overlaps, OverlapParams};
use atlas_skin::pipeline::unweld_weights;
use atlas_skin::weights::blend::{beta, Blend};
use atlas_skin::weights::ownership::OWN_BONE_RATIO;
use atlas_skin::weights::pieces::PieceTreatment;
use atlas_skin::weights::{compute_weights, region_weights, SurfaceWeights};
use atlas_skin::{
    Boundary, BoundaryKind, Decomposition, JointDecision, JointStatus, Region, SurfaceMesh,
    Topology,
};
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use glam::{DVec3, Mat4, Vec3};
use std::collections::{HashMap, HashSet};

/// A boundary to build: the joint, its plane (point, normal toward the child) and, for a
/// soft boundary, its diameter.
struct Plane {
    joint: u32,
    point: DVec3,
    normal: DVec3,
}

/// Builds the decomposition a perfect §3.1–3.2 would give: each cut plane's curve is the
/// ring of `sides` mesh vertices lying on it (within 2 `radius` of the joint), regions are the face
/// floods between curves, the region on a cut's child side is bound to the cut's joint and
/// the remaining one to joint 0; each soft boundary joins the region nearest its point.
fn decompose_by_hand(
    mesh: &SurfaceMesh,
    skeleton: &Skeleton,
    cuts: &[Plane],
    softs: &[(Plane, f64)],
    radius: f64,
    sides: usize,
) -> Decomposition {
    let topology = Topology::new(mesh);
    let mut curves = Vec::new();
    let mut curve_edges = HashSet::new();
    for cut in cuts {
        let u = cut.normal.any_orthonormal_vector();
        let v = cut.normal.cross(u);
        let mut curve: Vec<u32> = (0..mesh.vertex_count() as u32)
            .filter(|&i| {
                let p = mesh.positions[i as usize] - cut.point;
                p.dot(cut.normal).abs() < 1e-9 && p.length() < radius * 2.0
            })
            .collect();
        let angle = |i: &u32| {
            let p = mesh.positions[*i as usize] - cut.point;
            p.dot(v).atan2(p.dot(u))
        };
        curve.sort_by(|a, b| angle(a).total_cmp(&angle(b)));
        assert_eq!(curve.len(), sides, "ring of joint {}", cut.joint);
        for k in 0..curve.len() {
            let (a, b) = (curve[k], curve[(k + 1) % curve.len()]);
            curve_edges.insert((a.min(b), a.max(b)));
        }
        curves.push(curve);
    }
    // Flood faces across edges that are not on a curve.
    let mut face_region = vec![u32::MAX; mesh.triangle_count()];
    let mut region_count = 0;
    for start in 0..mesh.triangle_count() {
        if face_region[start] != u32::MAX {
            continue;
        }
        face_region[start] = region_count;
        let mut stack = vec![start];
        while let Some(f) = stack.pop() {
            for (i, &e) in topology.face_edges[f].iter().enumerate() {
                let t = mesh.triangles[f];
                let (a, b) = (t[i], t[(i + 1) % 3]);
                if curve_edges.contains(&(a.min(b), a.max(b))) {
                    continue;
                }
                for &g in topology.faces_of_edge(e as usize) {
                    if face_region[g as usize] == u32::MAX {
                        face_region[g as usize] = region_count;
                        stack.push(g as usize);
                    }
                }
            }
        }
        region_count += 1;
    }
    let centroid = |f: usize| mesh.corners(f).iter().sum::<DVec3>() / 3.0;
    let mut boundaries = Vec::new();
    let mut bound: Vec<Option<u32>> = vec![None; region_count as usize];
    for (cut, curve) in cuts.iter().zip(&curves) {
        let on_curve: HashSet<u32> = curve.iter().copied().collect();
        let mut sides = [u32::MAX; 2];
        for (f, t) in mesh.triangles.iter().enumerate() {
            if t.iter().filter(|v| on_curve.contains(v)).count() == 2 {
                let child = cut.normal.dot(centroid(f) - cut.point) > 0.0;
                sides[child as usize] = face_region[f];
            }
        }
        bound[sides[1] as usize] = Some(cut.joint);
        let points: Vec<DVec3> = curve.iter().map(|&v| mesh.positions[v as usize]).collect();
        boundaries.push(Boundary {
            joint: cut.joint,
            kind: BoundaryKind::Cut {
                curve: curve.clone(),
            },
            point: cut.point,
            normal: cut.normal,
            perimeter: (0..points.len())
                .map(|k| points[k].distance(points[(k + 1) % points.len()]))
                .sum(),
            diameter: points
                .iter()
                .flat_map(|a| points.iter().map(move |b| a.distance(*b)))
                .fold(0.0, f64::max),
            parent_region: sides[0],
            child_region: sides[1],
            leaf_part_past: false,
            bone_through: false,
        });
    }
    let mut regions: Vec<Region> = bound
        .iter()
        .enumerate()
        .map(|(r, joint)| Region {
            joints: vec![joint.unwrap_or(0)],
            faces: face_region.iter().filter(|&&x| x == r as u32).count(),
            vertices: 0,
        })
        .collect();
    for (soft, diameter) in softs {
        let nearest = (0..mesh.triangle_count())
            .min_by(|&a, &b| {
                let da = centroid(a).distance(soft.point);
                da.total_cmp(&centroid(b).distance(soft.point))
            })
            .expect("faces");
        let region = face_region[nearest];
        regions[region as usize].joints.push(soft.joint);
        boundaries.push(Boundary {
            joint: soft.joint,
            kind: BoundaryKind::Soft,
            point: soft.point,
            normal: soft.normal,
            perimeter: std::f64::consts::PI * diameter,
            diameter: *diameter,
            parent_region: region,
            child_region: region,
            leaf_part_past: false,
            bone_through: false,
        });
    }
    let joints = (0..skeleton.len() as u32)
        .map(|j| {
            let boundary = boundaries.iter().position(|b| b.joint == j);
            JointDecision {
                name: skeleton.names[j as usize].clone(),
                status: match boundary.map(|k| &boundaries[k].kind) {
                    Some(BoundaryKind::Cut { .. }) => JointStatus::Cut,
                    Some(BoundaryKind::Soft) => JointStatus::Soft("test".into()),
                    None => JointStatus::Skipped("test".into()),
                },
                boundary: boundary.map(|k| k as u32),
                region: None,
                owns_skin: true,
            }
        })
        .collect();
    Decomposition {
        welded_vertex_count: mesh.vertex_count(),
        surface: mesh.clone(),
        topology,
        face_region,
        regions,
        boundaries,
        joints,
        shared_sides: Vec::new(),
        merged_joints: Vec::new(),
        surface_spheres: Default::default(),
    }
}

fn weights_of(decomposition: &Decomposition, skeleton: &Skeleton, blend: Blend) -> SurfaceWeights {
    let overlaps =
        compute_overlaps(decomposition, skeleton, &OverlapParams::default()).expect("overlaps");
    let (weights, counts) = compute_weights(
        decomposition,
        skeleton,
        &overlaps,
        blend,
        &Default::default(),
    )
    .expect("weights");
    assert_eq!(counts.unreachable, 0);
    weights
}

/// The weights of steps 1–3 alone (`weights::region_weights`: before the guard against far
/// bones), for tests of what the regions and their boundaries give.
fn region_weights_of(decomposition: &Decomposition, skeleton: &Skeleton) -> SurfaceWeights {
    let overlaps =
        compute_overlaps(decomposition, skeleton, &OverlapParams::default()).expect("overlaps");
    region_weights(
        decomposition,
        skeleton,
        &overlaps,
        Blend::PartitionOfUnity,
        &Default::default(),
    )
    .expect("weights")
    .weights
}

fn weight(weights: &SurfaceWeights, v: usize, joint: u32) -> f64 {
    weights
        .row(v)
        .find(|&(j, _)| j == joint)
        .map_or(0.0, |(_, w)| w)
}

/// Σω = 1 within 1e-9 and ω > 0 on every vertex.
fn assert_partition_of_unity(weights: &SurfaceWeights) {
    for v in 0..weights.vertex_count() {
        let sum: f64 = weights.row(v).map(|(_, w)| w).sum();
        assert!((sum - 1.0).abs() < 1e-9, "vertex {v}: Σω = {sum}");
        assert!(weights.row(v).all(|(_, w)| w > 0.0));
    }
}

/// Vertices per ring of the tubes.
const SIDES: usize = 24;

/// A tube of radius 1 bent like an arm reaching down to touch its own thigh, with a ring
/// exactly at every joint, and its joint positions. 11 rings per segment: no vertex of a
/// neighbouring ring falls on a joint's mitre plane.
fn hand_touching_thigh() -> (SurfaceMesh, Skeleton, Vec<DVec3>) {
    // Up the thigh, across, down the arm, and back toward the thigh: the hand's end cap
    // stops 0.05 short of the thigh's side.
    let points = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(0.0, 8.0, 0.0),
        DVec3::new(6.0, 8.0, 0.0),
        DVec3::new(6.0, 3.0, 0.0),
        DVec3::new(4.0, 3.0, 0.0),
        DVec3::new(2.05, 3.0, 0.0),
    ];
    let names = ["thigh", "hip", "shoulder", "elbow", "wrist", "hand_end"];
    let (mesh, skeleton) = capsule_chain(&points, &names, 1.0, SIDES, 11);
    (mesh, skeleton, points)
}

fn mitre(points: &[DVec3], k: usize) -> DVec3 {
    ((points[k] - points[k - 1]).normalize() + (points[k + 1] - points[k]).normalize()).normalize()
}

/// The cut at joint `k` of a chain through `points`, on its mitre plane.
fn mitre_cut(points: &[DVec3], k: usize) -> Plane {
    Plane {
        joint: k as u32,
        point: points[k],
        normal: mitre(points, k),
    }
}

#[test]
fn arm_joints_carry_no_weight_on_the_thigh_the_hand_touches() {
    let (mesh, skeleton, points) = hand_touching_thigh();
    let cuts: Vec<Plane> = (1..=3).map(|k| mitre_cut(&points, k)).collect();
    // The wrist's soft plane (normal −x at x = 4) has the whole thigh on its child side in
    // space.
    let softs = [(
        Plane {
            joint: 4,
            point: points[4],
            normal: DVec3::NEG_X,
        },
        2.0,
    )];
    let decomposition = decompose_by_hand(&mesh, &skeleton, &cuts, &softs, 1.0, SIDES);
    assert_eq!(decomposition.regions.len(), 4);
    for blend in [Blend::PartitionOfUnity, Blend::Paper] {
        let weights = weights_of(&decomposition, &skeleton, blend);
        assert_partition_of_unity(&weights);
        let mut thigh_vertices = 0;
        for (v, p) in mesh.positions.iter().enumerate() {
            if p.x.abs() <= 1.0 + 1e-9 && p.y < 5.0 {
                thigh_vertices += 1;
                assert_eq!(weight(&weights, v, 0), 1.0, "thigh vertex {v} at {p}");
            }
        }
        assert!(thigh_vertices > 100);
        let tip = nearest_vertex(&mesh, DVec3::new(1.05, 3.0, 0.0));
        assert_eq!(weight(&weights, tip, 4), 1.0);
        assert_eq!(weight(&weights, tip, 0), 0.0);
    }
}

/// The hip cut of [`hand_touching_thigh`] and soft boundaries for `soft_joints` (the
/// wrist's normal is −x, so that its child side x < 4 also holds, in space, the top bar
/// near the hip, far from the wrist along the surface).
fn one_arm_region(soft_joints: &[usize]) -> (SurfaceMesh, Skeleton, Decomposition) {
    let (mesh, skeleton, points) = hand_touching_thigh();
    let cuts = [mitre_cut(&points, 1)];
    let softs: Vec<(Plane, f64)> = soft_joints
        .iter()
        .map(|&k| {
            let normal = if k == 4 {
                DVec3::NEG_X
            } else {
                mitre(&points, k)
            };
            (
                Plane {
                    joint: k as u32,
                    point: points[k],
                    normal,
                },
                2.0,
            )
        })
        .collect();
    let decomposition = decompose_by_hand(&mesh, &skeleton, &cuts, &softs, 1.0, SIDES);
    assert_eq!(decomposition.regions.len(), 2);
    (mesh, skeleton, decomposition)
}

#[test]
fn a_soft_boundary_acts_only_on_its_own_side_along_the_surface() {
    // The wrist's soft boundary hangs directly under the region's bound joint (the hip),
    // so nothing but the surface flood keeps it off the top bar.
    let (mesh, skeleton, decomposition) = one_arm_region(&[4]);
    assert_eq!(decomposition.regions[1].joints, vec![1, 4]);
    let weights = weights_of(&decomposition, &skeleton, Blend::PartitionOfUnity);
    assert_partition_of_unity(&weights);
    let mut top_bar = 0;
    for (v, p) in mesh.positions.iter().enumerate() {
        if p.y > 6.0 && p.x > -1.0 {
            top_bar += 1;
            assert_eq!(weight(&weights, v, 4), 0.0, "wrist weight at {p}");
        }
    }
    assert!(top_bar > 100);
    let tip = nearest_vertex(&mesh, DVec3::new(1.05, 3.0, 0.0));
    assert_eq!(weight(&weights, tip, 4), 1.0);
}

fn nearest_vertex(mesh: &SurfaceMesh, p: DVec3) -> usize {
    (0..mesh.vertex_count())
        .min_by(|&a, &b| {
            let da = mesh.positions[a].distance(p);
            da.total_cmp(&mesh.positions[b].distance(p))
        })
        .expect("vertices")
}

#[test]
fn weights_move_along_the_chain_inside_a_region() {
    let (mesh, skeleton, decomposition) = one_arm_region(&[2, 3, 4]);
    assert_eq!(decomposition.regions[1].joints, vec![1, 2, 3, 4]);
    let weights = weights_of(&decomposition, &skeleton, Blend::PartitionOfUnity);
    assert_partition_of_unity(&weights);
    let dominant = |p: DVec3| {
        weights
            .row(nearest_vertex(&mesh, p))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(j, _)| j)
    };
    assert_eq!(dominant(DVec3::new(1.0, 9.0, 0.0)), Some(1));
    assert_eq!(dominant(DVec3::new(7.0, 6.0, 0.0)), Some(2));
    assert_eq!(dominant(DVec3::new(5.6, 2.0, 0.0)), Some(3));
    assert_eq!(dominant(DVec3::new(1.05, 3.0, 0.0)), Some(4));
    // Between two joints of the chain both carry weight.
    let elbow_side = weights.row(nearest_vertex(&mesh, DVec3::new(7.0, 2.0, 0.0)));
    assert!(
        elbow_side
            .filter(|&(j, w)| (j == 2 || j == 3) && w > 0.1)
            .count()
            == 2
    );
}

/// A straight tube along x from −6 to 6 whose quads are split along diagonals mirrored at
/// x = 0, so that the mesh is exactly symmetric under x → −x; rings every 0.25.
fn symmetric_tube() -> SurfaceMesh {
    let (sides, half_rings, step, radius) = (SIDES, 24usize, 0.25, 1.0);
    let ring_count = 2 * half_rings + 1;
    let mut positions = vec![DVec3::new(-6.5, 0.0, 0.0)];
    for r in 0..ring_count {
        let x = (r as f64 - half_rings as f64) * step;
        for k in 0..sides {
            let angle = std::f64::consts::TAU * k as f64 / sides as f64;
            positions.push(DVec3::new(x, radius * angle.cos(), radius * angle.sin()));
        }
    }
    positions.push(DVec3::new(6.5, 0.0, 0.0));
    let ring = |r: usize, k: usize| (1 + r * sides + k % sides) as u32;
    let last_pole = positions.len() as u32 - 1;
    let mut triangles = Vec::new();
    for k in 0..sides {
        triangles.push([0, ring(0, k + 1), ring(0, k)]);
        triangles.push([
            last_pole,
            ring(ring_count - 1, k),
            ring(ring_count - 1, k + 1),
        ]);
    }
    for r in 0..ring_count - 1 {
        for k in 0..sides {
            let (a0, a1, b0, b1) = (
                ring(r, k),
                ring(r, k + 1),
                ring(r + 1, k),
                ring(r + 1, k + 1),
            );
            if r < half_rings {
                triangles.extend([[a0, a1, b1], [a0, b1, b0]]);
            } else {
                triangles.extend([[a0, a1, b0], [a1, b1, b0]]);
            }
        }
    }
    SurfaceMesh {
        positions,
        triangles,
    }
}

#[test]
fn a_mirror_symmetric_mesh_gets_mirror_symmetric_weights() {
    let mesh = symmetric_tube();
    // root at 0; left chain at +2, +4, +5.5; right chain mirrored.
    let names = [
        "root", "upper.L", "lower.L", "end.L", "upper.R", "lower.R", "end.R",
    ];
    let xs = [0.0, 2.0, 4.0, 5.5, -2.0, -4.0, -5.5];
    let skeleton = Skeleton::new(
        names.iter().map(|n| n.to_string()).collect(),
        vec![NO_PARENT, 0, 1, 2, 0, 4, 5],
        xs.iter()
            .map(|&x| Mat4::from_translation(Vec3::new(-x as f32, 0.0, 0.0)))
            .collect(),
    )
    .expect("skeleton");
    let mirror_joint = [0u32, 4, 5, 6, 1, 2, 3];
    let cuts = [
        Plane {
            joint: 1,
            point: DVec3::new(2.0, 0.0, 0.0),
            normal: DVec3::X,
        },
        Plane {
            joint: 4,
            point: DVec3::new(-2.0, 0.0, 0.0),
            normal: DVec3::NEG_X,
        },
    ];
    let softs = [
        (
            Plane {
                joint: 2,
                point: DVec3::new(4.0, 0.0, 0.0),
                normal: DVec3::X,
            },
            2.0,
        ),
        (
            Plane {
                joint: 5,
                point: DVec3::new(-4.0, 0.0, 0.0),
                normal: DVec3::NEG_X,
            },
            2.0,
        ),
    ];
    let decomposition = decompose_by_hand(&mesh, &skeleton, &cuts, &softs, 1.0, SIDES);
    assert_eq!(decomposition.regions.len(), 3);
    let key = |p: DVec3| {
        let q = (p * 1e6).round();
        (q.x as i64, q.y as i64, q.z as i64)
    };
    let index: HashMap<_, usize> = mesh
        .positions
        .iter()
        .enumerate()
        .map(|(v, &p)| (key(p), v))
        .collect();
    for blend in [Blend::PartitionOfUnity, Blend::Paper] {
        let weights = weights_of(&decomposition, &skeleton, blend);
        assert_partition_of_unity(&weights);
        let mut blended = 0;
        for (v, p) in mesh.positions.iter().enumerate() {
            let m = index[&key(DVec3::new(-p.x, p.y, p.z))];
            for j in 0..skeleton.len() as u32 {
                let (here, there) = (
                    weight(&weights, v, j),
                    weight(&weights, m, mirror_joint[j as usize]),
                );
                assert!(
                    (here - there).abs() < 1e-9,
                    "vertex {v} joint {j}: {here} vs {there}"
                );
            }
            blended += usize::from(weights.row(v).count() > 1);
        }
        assert!(blended > 100, "only {blended} blended vertices");
    }
}

#[test]
fn unwelded_weights_keep_the_largest_influences_and_renormalise() {
    let surface = SurfaceWeights {
        offsets: vec![0, 3, 4],
        joints: vec![0, 1, 2, 1],
        weights: vec![0.2, 0.5, 0.3, 1.0],
    };
    let skeleton = Skeleton::from_positions(
        vec!["a".into(), "b".into(), "c".into()],
        vec![NO_PARENT, 0, 1],
        &[Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
    )
    .expect("skeleton");
    // Stored vertices: two copies of surface vertex 0, one of 1, one unreferenced near c.
    let welded_of_stored = [0, 1, 0, atlas_skin::mesh::weld::UNREFERENCED];
    let positions = [Vec3::ZERO, Vec3::X, Vec3::ZERO, Vec3::new(2.4, 0.0, 0.0)];
    let stored = unweld_weights(&surface, &welded_of_stored, &positions, &skeleton, 2);
    assert_eq!(stored.vertex_count(), 4);
    let row: Vec<_> = stored.row(0).collect();
    assert_eq!(row.iter().map(|r| r.0).collect::<Vec<_>>(), vec![1, 2]);
    assert!((row[0].1 - 0.625).abs() < 1e-6 && (row[1].1 - 0.375).abs() < 1e-6);
    assert_eq!(stored.row(2).collect::<Vec<_>>(), row);
    assert_eq!(stored.row(3).collect::<Vec<_>>(), vec![(2, 1.0)]);
}

#[test]
fn a_gap_of_a_decomposed_piece_is_weighted_as_a_whole() {
    let (mut mesh, skeleton, points) = hand_touching_thigh();
    // A loose tetrahedron beside the thigh bone, like an eye or a tooth.
    let base = mesh.vertex_count() as u32;
    mesh.positions.extend(
        [
            (-3.0, 4.0, 0.0),
            (-2.5, 4.0, 0.0),
            (-3.0, 4.5, 0.0),
            (-3.0, 4.0, 0.5),
        ]
        .map(|(x, y, z)| DVec3::new(x, y, z)),
    );
    mesh.triangles
        .extend([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]].map(|t| t.map(|v| base + v)));
    let cuts: Vec<Plane> = (1..=3).map(|k| mitre_cut(&points, k)).collect();
    let mut decomposition = decompose_by_hand(&mesh, &skeleton, &cuts, &[], 1.0, SIDES);
    // Take the joints from the tetrahedron's region and from the top bar's (the hip's).
    let region_of = |v: u32| {
        let f = mesh
            .triangles
            .iter()
            .position(|t| t.contains(&v))
            .expect("face");
        decomposition.face_region[f] as usize
    };
    let (loose, top_bar) = (
        region_of(base),
        region_of(nearest_vertex(&mesh, DVec3::new(3.0, 9.0, 0.0)) as u32),
    );
    decomposition.regions[loose].joints.clear();
    decomposition.regions[top_bar].joints.clear();

    let overlaps =
        compute_overlaps(&decomposition, &skeleton, &OverlapParams::default()).expect("overlaps");
    let (weights, counts) = compute_weights(
        &decomposition,
        &skeleton,
        &overlaps,
        Blend::PartitionOfUnity,
        &Default::default(),
    )
    .expect("weights");
    assert_partition_of_unity(&weights);
    // The tetrahedron spans no joint: rigid to the bone it sits by; the top bar, a region
    // of a decomposed piece that no region with joints reaches, is a gap weighted as a
    // whole: it holds the bone of joint 1 (the hip, across the bar) and nothing else, so it
    // moves rigidly with it, as the bar between hip and shoulder should.
    assert_eq!(counts.unreachable, counts.rigid);
    assert_eq!((counts.bent, counts.attached), (0, 0));
    let treatments: Vec<PieceTreatment> = counts.pieces.iter().map(|p| p.treatment).collect();
    assert_eq!(treatments, [PieceTreatment::Body, PieceTreatment::Rigid(0)]);
    for v in base..base + 4 {
        assert_eq!(weights.row(v as usize).collect::<Vec<_>>(), vec![(0, 1.0)]);
    }
    assert_eq!(counts.gaps.len(), 1, "{counts:?}");
    let gap = &counts.gaps[0];
    assert_eq!(gap.treatment, PieceTreatment::Rigid(1));
    assert_eq!(gap.vertices.len() + 4, counts.unreachable);
    let middle = nearest_vertex(&mesh, DVec3::new(3.0, 9.0, 0.0)) as u32;
    assert!(gap.vertices.contains(&middle));
    for &v in &gap.vertices {
        assert!(v < base && region_of(v) == top_bar);
        assert_eq!(weights.row(v as usize).collect::<Vec<_>>(), vec![(1, 1.0)]);
    }
}

/// A straight tube along x from 0 to 12 (radius 1), one region, and a fork at its root:
/// joint a (bone 2 → 5) has a soft boundary whose plane (normal +x at x = 2) puts the
/// whole rest of the tube on its child side, where a sibling branch b (bone 9 → 11) lies.
fn fork_in_one_region() -> (SurfaceMesh, Skeleton, Decomposition) {
    let ends = [DVec3::ZERO, DVec3::new(12.0, 0.0, 0.0)];
    let (mesh, _) = capsule_chain(&ends, &[], 1.0, SIDES, 48);
    let positions = [0.0f32, 2.0, 5.0, 9.0, 11.0].map(|x| Vec3::new(x, 0.0, 0.0));
    let skeleton = Skeleton::from_positions(
        ["root", "a", "a_end", "b", "b_end"]
            .map(String::from)
            .to_vec(),
        vec![NO_PARENT, 0, 1, 0, 3],
        &positions,
    )
    .expect("skeleton");
    let soft = Plane {
        joint: 1,
        point: DVec3::new(2.0, 0.0, 0.0),
        normal: DVec3::X,
    };
    let decomposition = decompose_by_hand(&mesh, &skeleton, &[], &[(soft, 2.0)], 1.0, SIDES);
    assert_eq!(decomposition.regions.len(), 1);
    (mesh, skeleton, decomposition)
}

#[test]
fn a_soft_boundary_stays_on_the_part_nearest_its_own_bones() {
    let (mesh, skeleton, mut decomposition) = fork_in_one_region();
    let far_end = nearest_vertex(&mesh, DVec3::new(12.0, 1.0, 0.0));
    let own_part = nearest_vertex(&mesh, DVec3::new(4.0, 1.0, 0.0));
    // Without the joints' regions the boundary knows no other bone: its child side is the
    // whole tube past the plane, branch b's part included.
    // (Steps 1–3 alone: the guard against far bones would then remove it.)
    let unbounded = region_weights_of(&decomposition, &skeleton);
    assert_eq!(weight(&unbounded, far_end, 1), 1.0);
    for decision in &mut decomposition.joints {
        decision.region = Some(0);
    }
    let weights = region_weights_of(&decomposition, &skeleton);
    assert_partition_of_unity(&weights);
    // The root's bone to b runs under a's part as near as a's own bone (a = b = 1, the
    // tube's radius, w = 1): a keeps κ = β(1 − (a − λ b) / w) there, not all of it.
    let tie = beta(1.0 - (1.0 - OWN_BONE_RATIO));
    assert!((weight(&weights, own_part, 1) - tie).abs() < 1e-12);
    assert!(tie > 0.5);
    let mut on_branch_b = 0;
    for (v, p) in mesh.positions.iter().enumerate() {
        if p.x >= 10.0 {
            on_branch_b += 1;
            assert_eq!(weight(&weights, v, 1), 0.0, "weight of a at {p}");
        }
    }
    assert!(on_branch_b > 100);
    // Between the parts a's weight falls without a jump between neighbours.
    for v in 0..mesh.vertex_count() {
        for &u in decomposition.topology.neighbors(v) {
            let step = (weight(&weights, v, 1) - weight(&weights, u as usize, 1)).abs();
            assert!(step < 0.5, "a's weight jumps by {step} from {v} to {u}");
        }
    }
}

//! Decomposition of procedural shapes with known answers.

mod decompose_checks;

use atlas_skin::fixtures::shapes::{bent_cylinder, capsule_chain, uv_sphere};
use atlas_skin::report::{debug_colors, debug_lines};
use atlas_skin::{
    decompose, BoundaryKind, DecomposeError, DecomposeParams, Decomposition, JointStatus,
    SurfaceMesh, Topology,
};
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use decompose_checks::check_decomposition;
use glam::{DVec3, Vec3};

fn run(mesh: &SurfaceMesh, skeleton: &Skeleton) -> Decomposition {
    decompose(
        mesh,
        &Topology::new(mesh),
        skeleton,
        &DecomposeParams::default(),
    )
    .expect("valid input")
}

fn status<'a>(d: &'a Decomposition, name: &str) -> &'a JointStatus {
    &d.joints
        .iter()
        .find(|j| j.name == name)
        .expect("joint")
        .status
}

fn skeleton(names: &[&str], parents: &[u32], positions: &[DVec3]) -> Skeleton {
    Skeleton::from_positions(
        names.iter().map(|n| n.to_string()).collect(),
        parents.to_vec(),
        &positions.iter().map(|p| p.as_vec3()).collect::<Vec<Vec3>>(),
    )
    .expect("valid skeleton")
}

#[test]
fn a_bent_cylinder_is_cut_through_the_joint_along_the_bisector() {
    for bend in [0.0, 30.0, 60.0, 90.0] {
        let (mesh, skeleton) = bent_cylinder(0.5, 3.0, bend, 64, 48);
        let d = run(&mesh, &skeleton);
        assert_eq!(check_decomposition(&d, true), 1, "bend {bend}");
        assert_eq!(d.regions.len(), 2);
        assert!(matches!(status(&d, "root"), JointStatus::Skipped(r) if r.contains("root")));
        assert!(matches!(status(&d, "end"), JointStatus::Skipped(r) if r.contains("end site")));
        let boundary = &d.boundaries[d.joints[1].boundary.expect("joint is cut") as usize];
        let rad = f64::to_radians(bend);
        let bisector = (DVec3::Y + DVec3::new(rad.sin(), rad.cos(), 0.0)).normalize();
        // Near the bisector the perimeter grows only to second order in the tilt (and the
        // more slowly the sharper the bend), so the mesh's chords move the minimum a little.
        let angle = boundary.normal.angle_between(bisector).to_degrees();
        assert!(
            angle < 5.0,
            "bend {bend}: normal {} is {angle}° off",
            boundary.normal
        );
        assert!(boundary.point.distance(DVec3::Y * 3.0) < 1e-6);
        // The curve lies on the plane and around the tube.
        let BoundaryKind::Cut { curve } = &boundary.kind else {
            panic!("not a cut")
        };
        // The mitre section is an ellipse around the joint with semi-axes r and
        // r / cos(bend / 2), its perimeter between 2πr and 2πr / cos(bend / 2).
        let (r, stretch) = (0.5, 1.0 / (rad / 2.0).cos());
        for &v in curve {
            let p = d.surface.positions[v as usize];
            assert!(boundary.normal.dot(p - boundary.point).abs() < 0.01);
            let distance = p.distance(boundary.point);
            assert!(
                distance > 0.98 * r && distance < 1.1 * r * stretch,
                "bend {bend}: {p}"
            );
        }
        let circle = std::f64::consts::TAU * r;
        assert!(boundary.perimeter > 0.99 * circle && boundary.perimeter < circle * stretch);
        // Child region beyond the joint, bound to it.
        let child = &d.regions[boundary.child_region as usize];
        assert_eq!(child.joints, [1, 2]);
        assert_eq!(d.regions[boundary.parent_region as usize].joints, [0]);
    }
}

#[test]
fn a_straight_chain_is_cut_perpendicular_at_every_inner_joint() {
    let points = [0.0, 2.0, 4.0, 6.0].map(|y| DVec3::Y * y);
    let (mesh, skeleton) = capsule_chain(&points, &[], 0.4, 24, 16);
    let d = run(&mesh, &skeleton);
    assert_eq!(check_decomposition(&d, true), 2);
    for j in [1, 2] {
        let b = &d.boundaries[d.joints[j].boundary.expect("cut") as usize];
        assert!(
            b.normal.angle_between(DVec3::Y).to_degrees() < 3.0,
            "{}",
            b.normal
        );
        assert!((b.diameter - 0.8).abs() < 0.02, "{}", b.diameter);
    }
    let bound: Vec<Vec<u32>> = [1, 2]
        .map(|j| {
            d.regions[d.boundaries[j - 1].child_region as usize]
                .joints
                .clone()
        })
        .into();
    assert_eq!(bound, [vec![1], vec![2, 3]]);
    let root = d.joints[0].region.expect("root region");
    assert_eq!(d.regions[root as usize].joints, [0]);
}

#[test]
fn a_leaf_whose_bone_runs_on_into_the_mesh_owns_its_part() {
    // Like riggedsimple: root at the bottom, one leaf joint half way up the tube.
    let (mesh, _) = capsule_chain(&[DVec3::ZERO, DVec3::Y * 6.0], &[], 0.5, 24, 30);
    let rig = skeleton(
        &["root", "middle"],
        &[NO_PARENT, 0],
        &[DVec3::ZERO, DVec3::Y * 3.0],
    );
    let d = run(&mesh, &rig);
    assert_eq!(check_decomposition(&d, true), 1);
    assert_eq!(*status(&d, "middle"), JointStatus::Cut);
    let b = &d.boundaries[0];
    assert!(b.normal.dot(DVec3::Y) > 0.999);
    assert_eq!(d.regions[b.child_region as usize].joints, [1]);
}

/// A tube of radius ½ bent by `bend` degrees at its middle (y = 3), decomposed with a rig
/// of two joints: `root` at the bottom and the leaf `leaf` at the bend; also the mesh and
/// the tube's own three-joint skeleton.
fn leaf_at_bend(bend: f64, leaf: &str) -> (Decomposition, SurfaceMesh, Skeleton) {
    let (mesh, bent) = bent_cylinder(0.5, 3.0, bend, 24, 16);
    let rig = skeleton(
        &["root", leaf],
        &[NO_PARENT, 0],
        &[DVec3::ZERO, DVec3::Y * 3.0],
    );
    let d = run(&mesh, &rig);
    check_decomposition(&d, true);
    (d, mesh, bent)
}

#[test]
fn a_leaf_whose_part_turns_away_from_its_bone_owns_it_and_an_end_site_does_not() {
    // A foot: the leaf sits at the bend, its bone points into the outer wall (the ray along
    // it leaves the surface about one radius away), the tube runs on past it, turned 45°
    // like toes beyond the ball of a foot.
    let (d, mesh, bent) = leaf_at_bend(45.0, "ball");
    let ball = d.joints.iter().find(|j| j.name == "ball").expect("ball");
    assert!(ball.boundary.is_some(), "{:?}", ball.status);
    // The chain's own end joint lies inside the far cap: an end site.
    let d = run(&mesh, &bent);
    assert!(matches!(status(&d, "end"), JointStatus::Skipped(r) if r.starts_with("end site")));
}

#[test]
fn joints_outside_the_mesh_are_skipped_and_explained() {
    let (mesh, _) = bent_cylinder(0.5, 3.0, 45.0, 24, 16);
    let rig = skeleton(
        &["root", "joint", "far", "farther"],
        &[NO_PARENT, 0, 1, 2],
        &[
            DVec3::ZERO,
            DVec3::Y * 3.0,
            DVec3::new(-20.0, 3.0, 0.0),
            DVec3::new(-21.0, 3.0, 0.0),
        ],
    );
    let d = run(&mesh, &rig);
    check_decomposition(&d, true);
    assert!(matches!(status(&d, "far"), JointStatus::Skipped(r) if r.contains("outside")));
    assert!(matches!(status(&d, "farther"), JointStatus::Skipped(r) if r.contains("outside")));
}

#[test]
fn parallel_cuts_through_the_same_faces_are_both_kept() {
    // Rings every 0.2: both planes cross the same band of faces without touching.
    let (mesh, _) = capsule_chain(&[DVec3::ZERO, DVec3::Y * 4.0], &[], 0.5, 24, 20);
    let rig = skeleton(
        &["root", "a", "b", "tip"],
        &[NO_PARENT, 0, 1, 2],
        &[DVec3::ZERO, DVec3::Y * 2.03, DVec3::Y * 2.1, DVec3::Y * 4.0],
    );
    let d = run(&mesh, &rig);
    assert_eq!(check_decomposition(&d, true), 2);
    let (a, b) = (&d.boundaries[0], &d.boundaries[1]);
    assert_eq!(
        a.child_region, b.parent_region,
        "the band between the cuts is a's"
    );
    assert_eq!(d.regions[a.child_region as usize].joints, [1]);
}

#[test]
fn of_two_crossing_cuts_one_becomes_soft() {
    // b's child bone runs sideways and down (staying above a's plane): a plane separating
    // b's bones tilts at least 13°, so it crosses a's perpendicular cut 0.08 below inside
    // the tube (0.08 / tan 13° < 0.5). b lies farther from a than 1/8 of its depth in the
    // body (0.062), so it is not merged into a for cutting (`cuts::merged_joints`).
    let (mesh, _) = capsule_chain(&[DVec3::ZERO, DVec3::Y * 4.0], &[], 0.5, 24, 20);
    let rig = skeleton(
        &["root", "a", "b", "side"],
        &[NO_PARENT, 0, 1, 2],
        &[
            DVec3::ZERO,
            DVec3::Y * 2.0,
            DVec3::Y * 2.08,
            DVec3::new(0.3, 2.01, 0.0),
        ],
    );
    let d = run(&mesh, &rig);
    assert_eq!(check_decomposition(&d, true), 1);
    let (cut, soft) = match (status(&d, "a"), status(&d, "b")) {
        (JointStatus::Cut, JointStatus::Soft(reason)) => ("a", (2, reason)),
        (JointStatus::Soft(reason), JointStatus::Cut) => ("b", (1, reason)),
        other => panic!("{other:?}"),
    };
    assert!(
        soft.1
            .contains(&format!("crosses or touches the cut of {cut}")),
        "{}",
        soft.1
    );
    let boundary = &d.boundaries[d.joints[soft.0].boundary.expect("soft boundary") as usize];
    assert_eq!(boundary.kind, BoundaryKind::Soft);
    assert_eq!(Some(boundary.child_region), d.joints[soft.0].region);
}

#[test]
fn a_section_enclosing_another_bone_is_no_cut() {
    // Two bones side by side in one tube, like metacarpals in a palm: every section
    // around a also holds the bone to b.
    let (mesh, _) = capsule_chain(&[DVec3::ZERO, DVec3::Y * 4.0], &[], 0.5, 24, 20);
    let rig = skeleton(
        &["root", "a", "a_end", "b", "b_end"],
        &[NO_PARENT, 0, 1, 0, 3],
        &[
            DVec3::ZERO,
            DVec3::new(-0.2, 2.0, 0.0),
            DVec3::new(-0.2, 3.5, 0.0),
            DVec3::new(0.2, 2.5, 0.0),
            DVec3::new(0.2, 3.5, 0.0),
        ],
    );
    let d = run(&mesh, &rig);
    check_decomposition(&d, true);
    assert!(
        matches!(status(&d, "a"), JointStatus::Soft(r) if r.contains("encloses another bone")),
        "{:?}",
        status(&d, "a")
    );
}

#[test]
fn open_and_degenerate_surfaces_finish_with_reasons() {
    // A tube without its caps, a flat strip, a surface with degenerate faces, no surface.
    let (tube, rig) = bent_cylinder(0.5, 3.0, 45.0, 24, 16);
    let open = SurfaceMesh {
        positions: tube.positions.clone(),
        triangles: tube.triangles[48..].to_vec(),
    };
    let strip = SurfaceMesh {
        positions: (0..10)
            .map(|k| DVec3::new((k % 2) as f64, (k / 2) as f64, 0.0))
            .collect(),
        triangles: (0..4u32)
            .flat_map(|r| [[2 * r, 2 * r + 1, 2 * r + 3], [2 * r, 2 * r + 3, 2 * r + 2]])
            .collect(),
    };
    let strip_rig = skeleton(&["a", "b"], &[NO_PARENT, 0], &[DVec3::ZERO, DVec3::Y * 2.0]);
    let mut degenerate = tube.clone();
    degenerate.triangles.extend([[0, 0, 1], [5, 6, 5]]);
    degenerate.positions.push(DVec3::splat(1e3));
    for (mesh, rig) in [
        (&open, &rig),
        (&strip, &strip_rig),
        (&degenerate, &rig),
        (&SurfaceMesh::default(), &rig),
    ] {
        let d = run(mesh, rig);
        check_decomposition(&d, false);
        assert_eq!(d.joints.len(), rig.len());
    }
}

#[test]
fn the_user_forces_and_forbids_cuts() {
    let (mesh, rig) = bent_cylinder(0.5, 3.0, 60.0, 24, 16);
    let topology = Topology::new(&mesh);
    let forbid = DecomposeParams {
        forbid: vec!["joint".into()],
        ..Default::default()
    };
    let d = decompose(&mesh, &topology, &rig, &forbid).expect("valid");
    assert_eq!(
        *status(&d, "joint"),
        JointStatus::Skipped("forbidden by the user".into())
    );
    assert_eq!(d.regions.len(), 1);
    let force = DecomposeParams {
        force: vec!["end".into()],
        ..Default::default()
    };
    let d = decompose(&mesh, &topology, &rig, &force).expect("valid");
    assert!(!matches!(status(&d, "end"), JointStatus::Skipped(_)));
    let params: DecomposeParams =
        serde_json::from_str(r#"{"angle_step_deg": 3, "forbid": ["joint"]}"#).expect("config");
    assert_eq!(params.angle_step_deg, 3.0);
    assert!(serde_json::from_str::<DecomposeParams>(r#"{"angel_step": 3}"#).is_err());
}

#[test]
fn invalid_requests_are_rejected() {
    let (mesh, rig) = bent_cylinder(0.5, 3.0, 60.0, 12, 4);
    let topology = Topology::new(&mesh);
    type Expected = fn(&DecomposeError) -> bool;
    let cases: Vec<(DecomposeParams, Expected)> = vec![
        (
            DecomposeParams {
                force: vec!["nobody".into()],
                ..Default::default()
            },
            |e| matches!(e, DecomposeError::UnknownJoint { .. }),
        ),
        (
            DecomposeParams {
                force: vec!["joint".into()],
                forbid: vec!["joint".into()],
                ..Default::default()
            },
            |e| matches!(e, DecomposeError::ForcedAndForbidden { .. }),
        ),
        (
            DecomposeParams {
                angle_step_deg: 0.0,
                ..Default::default()
            },
            |e| matches!(e, DecomposeError::BadParameter { .. }),
        ),
        (
            DecomposeParams {
                snap_fraction: f64::NAN,
                ..Default::default()
            },
            |e| matches!(e, DecomposeError::BadParameter { .. }),
        ),
    ];
    for (params, expected) in cases {
        let error = decompose(&mesh, &topology, &rig, &params).expect_err("rejected");
        assert!(expected(&error), "{error}");
    }
    let other = Topology::new(&uv_sphere(1.0, 4, 4));
    assert!(matches!(
        decompose(&mesh, &other, &rig, &DecomposeParams::default()),
        Err(DecomposeError::TopologyMismatch { .. })
    ));
    // The same faces over one vertex more: the topology's vertices are not the mesh's.
    let mut more = mesh.clone();
    more.positions.push(DVec3::ZERO);
    assert!(matches!(
        decompose(&more, &topology, &rig, &DecomposeParams::default()),
        Err(DecomposeError::TopologyMismatch { .. })
    ));
}

#[test]
fn the_report_and_debug_view_describe_every_joint_and_region() {
    let (mesh, rig) = bent_cylinder(0.5, 3.0, 60.0, 24, 16);
    let d = run(&mesh, &rig);
    let report = serde_json::to_value(d.report()).expect("serialisable");
    assert_eq!(report["cuts"], 1);
    let joint = &report["joints"][1];
    assert_eq!(joint["name"], "joint");
    assert_eq!(joint["status"], "cut");
    assert!(joint["perimeter"].as_f64().expect("perimeter") > 3.0);
    assert_eq!(joint["normal"].as_array().expect("normal").len(), 3);
    assert_eq!(report["joints"][0]["status"], "skipped");
    assert!(report["joints"][0]["reason"].is_string());
    assert_eq!(report["regions"].as_array().expect("regions").len(), 2);
    assert_eq!(report["regions"][1]["joints"][1], "end");
    let colors = debug_colors(&d);
    assert_eq!(colors.len(), d.surface.vertex_count());
    let mut distinct: Vec<[u32; 4]> = colors.iter().map(|c| c.map(f32::to_bits)).collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert_eq!(distinct.len(), d.regions.len());
    let BoundaryKind::Cut { curve } = &d.boundaries[0].kind else {
        panic!("cut")
    };
    assert_eq!(debug_lines(&d).len(), curve.len());
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(32))]

    /// Any zig-zag tube decomposes without panic into cuts + 1 regions, curves apart.
    #[test]
    fn zigzag_tubes_keep_the_invariants(
        bends in proptest::collection::vec(-1.7f64..1.7, 1..4),
        radius in 0.2f64..0.6,
        sides in 6usize..20,
    ) {
        let mut points = vec![DVec3::ZERO, DVec3::Y * 2.0];
        let mut heading = 0.0f64;
        for bend in &bends {
            heading += bend;
            let last = *points.last().expect("two points");
            points.push(last + 2.0 * DVec3::new(heading.sin(), heading.cos(), 0.0));
        }
        let (mesh, skeleton) = capsule_chain(&points, &[], radius, sides, 6);
        let d = run(&mesh, &skeleton);
        check_decomposition(&d, true);
        proptest::prop_assert_eq!(d.joints.len(), points.len());
    }
}

/// Siblings of a root along a tube (each along the bones of the siblings beyond it) and a
/// twist joint on its parent's bone: another bone passes through each of them, so the cut
/// search is skipped; the search without the shortcut finds no section either. The top
/// sibling, which no other bone passes, is searched and cut.
#[test]
fn joints_on_another_bone_skip_a_search_that_would_find_nothing() {
    use atlas_skin::cuts::joint_roles::{plan_joints, JointPlan};
    use atlas_skin::cuts::plane_search::{find_cut_candidates, search_cut_candidates, CutSurface};
    use atlas_skin::cuts::plane_section::{vertex_snap_distances, DomainScratch};
    use atlas_skin::mesh::FaceSpheres;
    use atlas_skin::skeleton::bones::{joint_pairs, BoneIndex};

    let (mesh, _) = capsule_chain(&[DVec3::ZERO, DVec3::Y * 10.0], &[], 0.5, 16, 80);
    let mut names = vec!["root".to_string()];
    let mut parents = vec![NO_PARENT];
    let mut positions = vec![DVec3::ZERO];
    for k in 1..=6 {
        names.push(format!("sibling{k}"));
        parents.push(0);
        positions.push(DVec3::Y * k as f64);
    }
    // A limb above the siblings: upper (7) → lower (9.5), with a twist joint at 8.
    names.extend(["upper", "lower", "twist"].map(String::from));
    parents.extend([6, 7, 7]);
    positions.extend([7.0, 9.5, 8.0].map(|y| DVec3::Y * y));
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let skeleton = skeleton(&names, &parents, &positions);

    let params = DecomposeParams::default();
    let topology = Topology::new(&mesh);
    let spheres = FaceSpheres::new(&mesh);
    let vertex_snap = vertex_snap_distances(&mesh, &topology, params.snap_fraction);
    let bones = BoneIndex::new(joint_pairs(&skeleton, &positions), &positions);
    let overrides = params.overrides(&skeleton).expect("no overrides");
    let plans = plan_joints(
        &mesh,
        &topology.vertex_component,
        &spheres,
        &skeleton,
        &positions,
        &bones,
        &overrides,
        &params,
    );
    let surface = CutSurface {
        mesh: &mesh,
        topology: &topology,
        spheres: &spheres,
        vertex_snap: &vertex_snap,
        max_snap: vertex_snap.iter().copied().fold(0.0, f64::max),
        params: &params,
    };
    let mut scratch = DomainScratch::default();
    let mut skipped = Vec::new();
    for (j, plan) in plans.iter().enumerate() {
        let (JointPlan::Boundary(frame) | JointPlan::Soft(frame, _)) = plan else {
            continue;
        };
        let fast = find_cut_candidates(&surface, j, frame, &bones, &mut scratch);
        let reference = search_cut_candidates(&surface, j, frame, &bones, &mut scratch);
        assert_eq!(fast.candidates, reference.candidates, "joint {}", names[j]);
        if fast.through_joint.is_some() {
            assert!(reference.enclosing_other_bones > 0, "joint {}", names[j]);
            skipped.push(names[j]);
        } else {
            assert_eq!(fast, reference, "joint {}", names[j]);
        }
    }
    // No bone runs past sibling6 (the highest of the root's), nor through upper or lower.
    assert_eq!(
        skipped,
        ["sibling1", "sibling2", "sibling3", "sibling4", "sibling5", "twist"]
    );

    let d = run(&mesh, &skeleton);
    assert!(
        matches!(status(&d, "twist"), JointStatus::Soft(r) if r.contains("upper -> lower runs through the joint")),
        "{:?}",
        status(&d, "twist")
    );
}

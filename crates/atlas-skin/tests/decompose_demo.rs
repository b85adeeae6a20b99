//! Decomposition of the project's demo character, whose right answer is known: every joint
//! of `demo::expected_cut_joints()` gets an exact closed cut, no other joint does, and the
//! cuts split the closed genus-0 body into cuts + 1 regions, each bound to its cut joint.

mod decompose_checks;

use atlas_skin::fixtures::demo::{demo_character, expected_cut_joints, DEFAULT_STEP};
use atlas_skin::mesh::weld::DEFAULT_WELD_TOLERANCE;
use atlas_skin::{decompose, weld, DecomposeParams, JointStatus, Topology};
use decompose_checks::check_decomposition;

#[test]
fn the_demo_character_gets_exactly_the_expected_cuts_and_regions() {
    let demo = demo_character(DEFAULT_STEP);
    let welded = weld(&demo.positions, &demo.triangles, DEFAULT_WELD_TOLERANCE);
    let d = decompose(
        &welded.mesh,
        &Topology::new(&welded.mesh),
        &demo.skeleton,
        &DecomposeParams::default(),
    )
    .expect("the demo decomposes");
    let cuts = check_decomposition(&d, true);

    let expected = expected_cut_joints();
    let cut: Vec<&str> = d
        .joints
        .iter()
        .filter(|j| j.status == JointStatus::Cut)
        .map(|j| j.name.as_str())
        .collect();
    for decision in &d.joints {
        assert_eq!(
            decision.status == JointStatus::Cut,
            expected.contains(&decision.name),
            "{}: {:?}",
            decision.name,
            decision.status
        );
    }
    assert_eq!(cuts, expected.len(), "cut joints: {cut:?}");
    // The chest branches on the mirror plane within its own cross-section: a soft boundary.
    let chest = d.joints.iter().find(|j| j.name == "chest").expect("chest");
    assert!(
        matches!(&chest.status, JointStatus::Soft(r) if r.contains("mirror plane")),
        "{:?}",
        chest.status
    );
    assert_eq!(d.regions.len(), expected.len() + 1);

    // Each cut joint's child region is its own: the region lists it first.
    for (j, decision) in d.joints.iter().enumerate() {
        if decision.status == JointStatus::Cut {
            let region = decision.region.expect("a cut joint has a region") as usize;
            assert_eq!(
                d.regions[region].joints.first(),
                Some(&(j as u32)),
                "{} is not bound to its region",
                decision.name
            );
        }
    }
}

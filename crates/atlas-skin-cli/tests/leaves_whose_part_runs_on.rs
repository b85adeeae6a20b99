//! A leaf whose part runs on past it for at least its bone's length owns that part
//! (`cuts::joint_roles`, rule 5 (d)), on a real character of the bench: rignet-val/14529,
//! whose feet reach 1.3 bone lengths past leaf joints deep in the ankles, and whose left
//! tail is a flat sheet running 0.26 past its tip joint `J_L_tail2` (bone 0.16). Both were
//! end sites: the feet moved with the knees, the tail's last third with `J_L_tail1` (deform
//! mean 0.0067, max 0.133 of the diagonal against the artist's weights, 1.55 times the
//! better baseline's max). The tail's tip gets a soft boundary but carries no weight since
//! 2026-12-05: the seeds from the far ends of the edges spanning its band were removed
//! (docs/ablation.md, `far_end_seeds`).

mod support;

#[test]
fn feet_and_a_tail_in_a_sheet_move_with_their_leaves() {
    let skinned = support::BenchSkin::new("rignet-val/14529", "leaves-whose-part-runs-on");
    for name in ["J_R_foot", "J_L_foot"] {
        assert_eq!(skinned.joint(name)["status"], "cut", "{name}");
    }
    // No closed section fits around a joint in a sheet: a soft boundary, whose band is as
    // thin as the joint's depth and spanned by one face, which no vertex seeds.
    assert_eq!(skinned.joint("J_L_tail2")["status"], "soft");
    let warnings = skinned.report["warnings"].to_string();
    assert!(
        warnings.contains("carry no weight: J_L_tail2"),
        "{warnings}"
    );
    let deform = skinned.deform();
    // Measured 0.0044 (the feet with their leaves).
    assert!(deform["mean"].as_f64().unwrap() < 0.0050, "{deform}");
}

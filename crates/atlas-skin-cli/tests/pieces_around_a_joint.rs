//! A piece that no bone enters hangs from the joints around it (`weights::pieces`,
//! `bones_around`), on a real character of the bench: KayKit's Mage, whose hat (557
//! vertices) sits above the head joint while the head's bone ends below it. No bone ran
//! inside the hat, so it was attached to the body it touches, where its brim lies on the
//! shoulders, and bent with them (deform mean 0.0063, max 0.190 of the diagonal against the
//! artist's weights, who binds the hat to the head).

mod support;

#[test]
fn a_hat_above_the_head_joint_moves_with_the_head() {
    let skinned = support::BenchSkin::new("kaykit/Mage", "pieces-around-a-joint");
    skinned.assert_rigid(557, "head");
    // Measured 0.0049 / 0.072.
    skinned.assert_deform_below(0.0056, 0.100);
}

//! An attached piece moves with one part of the skeleton (`weights::carriers`), on real
//! characters of the benchmark (`../shared/data/bench`):
//! - rignet-val/3613, whose knee pads reach past the gap between the knees: the edge of
//!   each pad took the other knee's weights from the body under it, and tore off when the
//!   legs moved (deform max 0.205 of the diagonal against the artist's weights, 3.7 times
//!   its better baseline's);
//! - KayKit's Mage, whose wide hat brim reaches out over its hands in the bind pose: the
//!   brim's ends moved with the wrists (deform max 0.339). The hat now holds the head's
//!   bones (`pieces_around_a_joint.rs`); the rule still moves rows of Mage's other
//!   attached pieces (16 rows).

mod support;

/// Skins `input`; returns the report's count of rows moved onto their piece's carrier and
/// the deform figures against the artist's weights.
fn skin_and_deform(input: &str, stem: &str) -> (u64, serde_json::Value) {
    support::count_and_deform(
        input,
        "attached-pieces-one-carrier",
        stem,
        "off_carrier_vertices",
    )
}

#[test]
fn knee_pads_across_the_gap_between_the_knees_move_with_their_own_knee() {
    let (off_carrier, deform) = skin_and_deform("bench/rignet-val/3613.glb", "3613");
    assert!(off_carrier > 0, "no row moved onto its carrier");
    // Measured 0.0027 / 0.073.
    assert!(deform["max"].as_f64().unwrap() < 0.12, "{deform}");
}

#[test]
fn a_hat_brim_over_the_hands_moves_with_the_head() {
    let (off_carrier, deform) = skin_and_deform("bench/kaykit/Mage.glb", "mage");
    assert!(off_carrier > 0, "no row moved onto its carrier");
    // Measured 0.0049 / 0.072 (0.0063 / 0.190 before the hat held the head's bones).
    assert!(deform["max"].as_f64().unwrap() < 0.26, "{deform}");
}

//! A bone that only pokes into a piece moves it only where it is the nearest bone to most
//! of it (`weights::pieces`, `held_bones`), on a real character of the bench:
//! rignet-val/1442, whose strap across the chest (48 vertices, from the right hip up to the
//! left shoulder) is crossed at the shoulder by the left clavicle's bone. The strap held
//! that bone alone and moved rigidly with the clavicle, while its artist binds it to the
//! spine (deform mean 0.0116, max 0.172 of the diagonal against the artist's weights).

mod support;

#[test]
fn a_strap_crossed_by_a_clavicle_is_not_rigid_to_it() {
    let skinned = support::BenchSkin::new("rignet-val/1442", "bones-that-poke-into-a-piece");
    let strap = skinned.whole_piece(48);
    assert_eq!(strap["treatment"], "attached", "{strap}");
    let on_clavicle: u64 = skinned
        .whole_pieces()
        .iter()
        .filter(|p| p["joint"] == "Bip01_L_Clavicle")
        .map(|p| p["vertices"].as_u64().unwrap())
        .sum();
    // Before, 48 + 16 + 16 + 9 + 9 vertices; now one small plate at the shoulder.
    assert!(on_clavicle <= 9, "{on_clavicle}");
    let deform = skinned.deform();
    // Measured 0.00779 / 0.135.
    assert!(deform["mean"].as_f64().unwrap() < 0.0090, "{deform}");
    assert!(deform["max"].as_f64().unwrap() < 0.150, "{deform}");
}

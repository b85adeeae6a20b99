//! A piece that encloses the skeleton's root joint holds the root's bones and, of the
//! others, only those that hang from the root through bones it holds (`weights::pieces`,
//! `bones_from_root`), on a real character of the bench: rignet-val/9826 stands on a
//! pedestal (108 vertices) around its root joint, with its feet's bones inside it. The
//! pedestal held the feet's bones and bent between them, and the two small pieces on it
//! (13 vertices each) moved with the nearer foot (deform max 0.454 of the diagonal against
//! the artist's weights, who binds all three to the root).

mod support;

#[test]
fn a_pedestal_around_the_root_moves_with_the_root() {
    let skinned = support::BenchSkin::new("rignet-val/9826", "pieces-around-the-root");
    let root = "rstr0156_00_fi";
    let pedestal = skinned.whole_piece(108);
    assert_eq!(pedestal["treatment"], "rigid", "{pedestal}");
    assert_eq!(pedestal["joint"], root, "{pedestal}");
    let on_it: Vec<_> = skinned
        .whole_pieces()
        .iter()
        .filter(|p| p["vertices"] == 13)
        .collect();
    assert_eq!(on_it.len(), 2);
    for piece in on_it {
        assert_eq!(piece["joint"], root, "{piece}");
    }
    let deform = skinned.deform();
    // Measured 0.0018 / 0.034.
    assert!(deform["mean"].as_f64().unwrap() < 0.0025, "{deform}");
    assert!(deform["max"].as_f64().unwrap() < 0.050, "{deform}");
}

//! A cut whose section is several times as long as its parent's yields to the joints it
//! would block (`cuts::conflicts`, [`WIDE_SECTION_RATIO`]), on a real character:
//! rignet-val/1431 (bench), a 3ds Max biped whose clavicles are children of the neck.
//! The clavicles' planes slice the sides of the chest (sections of 0.13 and 0.17 across
//! the neck's 0.03), and placed before the spine's they blocked every section of the chest
//! joint: the chest took the spine's weights and the clavicles the chest's sides. Deform
//! max 0.128 of the diagonal against the artist's weights, 1.52 times its better baseline's.
//!
//! [`WIDE_SECTION_RATIO`]: atlas_skin::cuts::conflicts::WIDE_SECTION_RATIO

mod support;

#[test]
fn a_clavicle_cut_across_the_chest_yields_to_the_chest() {
    let skinned = support::BenchSkin::new("rignet-val/1431", "sections-wider-than-the-parents");
    let chest = skinned.joint("bip01_Spine2");
    assert_eq!(chest["status"], "cut", "{chest}");
    let deform = skinned.deform();
    // Measured 0.0030 / 0.103; with the chest blocked 0.0051 / 0.128.
    assert!(deform["mean"].as_f64().unwrap() < 0.004, "{deform}");
    assert!(deform["max"].as_f64().unwrap() < 0.115, "{deform}");
}

//! What the pieces cost (issue 12): the whole method ([`atlas_skin::pipeline::skin`]) on the
//! demo dressed in 98 more pieces (eyes, hat, belt, limb shells, bracelets, shoes, buttons,
//! studs: about 30,000 vertices, [`atlas_skin::fixtures::pieces`]) against the demo alone.
//! The difference is what the pieces add: more vertices through every stage, and the
//! pieces step of the weights (held bones, body surface index, attachment).
//!
//! `cargo bench -p atlas-skin --bench pieces`. Target (release, 2 cores): under 300 ms for
//! the dressed demo.

use atlas_skin::fixtures::demo::{demo_character, DemoCharacter, DEFAULT_STEP};
use atlas_skin::fixtures::pieces::demo_in_pieces;
use atlas_skin::pipeline::{skin, SkinInput, SkinParams};
use divan::Bencher;

fn main() {
    divan::main();
}

fn bench_skin(bencher: Bencher, character: &DemoCharacter) {
    let params = SkinParams::default();
    let input = SkinInput {
        positions: &character.positions,
        triangles: &character.triangles,
        skeleton: &character.skeleton,
        end_joints: &[],
    };
    bencher
        .counter(character.positions.len())
        .bench(|| skin(input, &params, &mut |_| {}).expect("skins"));
}

#[divan::bench(sample_count = 10)]
fn demo_alone(bencher: Bencher) {
    bench_skin(bencher, &demo_character(DEFAULT_STEP));
}

#[divan::bench(sample_count = 10)]
fn demo_in_99_pieces(bencher: Bencher) {
    bench_skin(bencher, &demo_in_pieces(DEFAULT_STEP));
}

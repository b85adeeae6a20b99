//! A region without joints on the parent side of a cut hangs from the cut's joint when its
//! faces lie nearest to that joint's bones (`regions::bind_parent_sides`), on a real
//! character: rignet-val/7464 (bench), whose head's cut leaves the chin and muzzle below it.
//! Before, that region moved with the neck, the head's parent, while the artist binds it to
//! the head: deform max 0.100 of the diagonal against the artist's weights, 1.58 times its
//! better baseline's.

mod support;

#[test]
fn the_chin_below_the_heads_cut_moves_with_the_head() {
    let input = atlas_skin_corpus::data_dir().join("bench/rignet-val/7464.glb");
    let dir = support::out_dir("regions-below-a-cut");
    let (glb, report) = support::skin_with_report(&input, &dir, "7464");
    let decomposition = &report["decomposition"];
    let head = decomposition["joints"]
        .as_array()
        .unwrap()
        .iter()
        .find(|j| j["name"] == "Head")
        .unwrap();
    assert_eq!(head["status"], "cut", "{head}");
    // The head's own region, and one more: the chin, bound to the head without holding it.
    let regions = decomposition["regions"].as_array().unwrap();
    let moved_by_head: Vec<usize> = (0..regions.len())
        .filter(|&r| regions[r]["joint"] == "Head")
        .collect();
    assert_eq!(moved_by_head.len(), 2, "{regions:?}");
    assert!(moved_by_head.contains(&(head["region"].as_u64().unwrap() as usize)));
    let deform = support::deform_random(&input, &glb);
    // Measured 0.0025 / 0.037; with the chin on the neck 0.0049 / 0.100.
    assert!(deform["max"].as_f64().unwrap() < 0.06, "{deform}");
}

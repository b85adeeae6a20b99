//! A joint whose children part to both sides and whose mean turns back up its upper bone is
//! cut across its upper bone (`cuts::joint_roles`, rule 7), on a real character of the
//! bench: rignet-val/17193, whose pelvis (named `Jaw`) hangs below the waist, slanting
//! forward, with the thighs going out sideways and a little up and back. The bisector of
//! the waist bone and the thighs' mean tilted its soft boundary 40° back, and the back of
//! the waist moved with the pelvis (deform mean 0.0090, max 0.089 of the diagonal against
//! the artist's weights, who binds that skin to the waist).

mod support;

#[test]
fn a_pelvis_whose_thighs_part_sideways_is_cut_across_the_waist_bone() {
    let skinned = support::BenchSkin::new("rignet-val/17193", "children-that-spread-and-fold-back");
    let pelvis = skinned.joint("Jaw");
    assert_eq!(pelvis["status"], "soft", "{pelvis}");
    // The plane's normal is the waist bone's direction, from the waist (0, 0.112, −0.004)
    // to the pelvis (0, 0.042, 0.036); before, (−0.02, −0.75, −0.66).
    let normal: Vec<f64> = pelvis["normal"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let bone = [0.0, -0.070, 0.040];
    let length = bone.iter().map(|x| x * x).sum::<f64>().sqrt();
    let cosine: f64 = normal.iter().zip(bone).map(|(n, b)| n * b).sum::<f64>() / length;
    assert!(cosine > 0.999, "{pelvis}");
    let deform = skinned.deform();
    // Measured 0.00767 / 0.0668.
    assert!(deform["mean"].as_f64().unwrap() < 0.0083, "{deform}");
    assert!(deform["max"].as_f64().unwrap() < 0.078, "{deform}");
}

//! A surface of higher genus (issue 12, "awkward geometry"): the demo with its left hand
//! fused to its left thigh by a bridge of faces, so that the child side of the wrist's cut
//! runs on into the child side of the hip's cut. Each keeps moving with its own bone.

use atlas_skin::fixtures::demo::{demo_character, DemoCharacter, DEFAULT_STEP};
use atlas_skin::pipeline::{skin, SkinParams};
use atlas_skin::{Skinned, WarningTopic};
use glam::Vec3;

fn skinned(character: &DemoCharacter) -> Skinned {
    skin(character.input(), &SkinParams::default(), &mut |_| {}).expect("skinned")
}

/// The face whose centroid is nearest to `p`.
fn nearest_face(character: &DemoCharacter, p: Vec3) -> usize {
    let centroid = |t: &[u32; 3]| {
        t.iter()
            .map(|&v| character.positions[v as usize])
            .sum::<Vec3>()
            / 3.0
    };
    (0..character.triangles.len())
        .min_by(|&a, &b| {
            centroid(&character.triangles[a])
                .distance(p)
                .total_cmp(&centroid(&character.triangles[b]).distance(p))
        })
        .expect("faces")
}

/// `character` with faces `a` and `b` removed and their edges joined by a tube of six
/// triangles (a handle: the genus grows by one), oriented like the removed faces.
fn bridged(character: &DemoCharacter, a: usize, b: usize) -> DemoCharacter {
    let (ta, tb) = (character.triangles[a], character.triangles[b]);
    let p = |v: u32| character.positions[v as usize];
    // Face b's corner facing corner i of face a is b[(c − i) mod 3] (the faces face each
    // other, so their windings run opposite): the c with the shortest tube.
    let c = (0..3)
        .min_by(|&x, &y| {
            let length = |c: usize| {
                (0..3)
                    .map(|i| p(ta[i]).distance(p(tb[(c + 3 - i) % 3])))
                    .sum::<f32>()
            };
            length(x).total_cmp(&length(y))
        })
        .expect("three rotations");
    let k = |i: usize| tb[(c + 3 - i % 3) % 3];
    let mut triangles: Vec<[u32; 3]> = character
        .triangles
        .iter()
        .enumerate()
        .filter(|&(f, _)| f != a && f != b)
        .map(|(_, &t)| t)
        .collect();
    for i in 0..3 {
        let (a0, a1) = (ta[i], ta[(i + 1) % 3]);
        triangles.push([a0, a1, k(i + 1)]);
        triangles.push([a0, k(i + 1), k(i)]);
    }
    DemoCharacter {
        positions: character.positions.clone(),
        triangles,
        skeleton: character.skeleton.clone(),
    }
}

#[test]
fn a_hand_fused_to_the_thigh_moves_with_the_hand_and_the_thigh_with_the_hip() {
    let demo = demo_character(DEFAULT_STEP);
    let joint = |name: &str| {
        demo.skeleton
            .find(name)
            .unwrap_or_else(|| panic!("the demo has {name}")) as u32
    };
    let (hand, upleg) = (joint("hand_l"), joint("upleg_l"));
    let hand_at = demo.skeleton.bind_positions()[hand as usize];
    let under_hand = nearest_face(&demo, hand_at + Vec3::new(0.05, -0.05, 0.0));
    let beside_thigh = nearest_face(&demo, Vec3::new(0.25, 0.70, 0.0));
    let fused = bridged(&demo, under_hand, beside_thigh);

    let (before, after) = (skinned(&demo), skinned(&fused));
    let dominant = |s: &Skinned, v: usize| {
        s.weights
            .row(v)
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .map(|(j, _)| j)
            .expect("weighted")
    };
    let (mut thigh, mut palm, mut moved) = (0, 0, 0);
    for (v, p) in demo.positions.iter().enumerate() {
        moved += usize::from(dominant(&before, v) != dominant(&after, v));
        let on_thigh = p.x > 0.06 && (0.6..0.8).contains(&p.y);
        let on_palm = p.x > hand_at.x + 0.02 && p.x < hand_at.x + 0.08 && p.z.abs() < 0.03;
        if !(on_thigh || on_palm) {
            continue;
        }
        let expected = if on_thigh { upleg } else { hand };
        assert_eq!(dominant(&before, v), expected, "unfused vertex {v} at {p}");
        assert_eq!(dominant(&after, v), expected, "fused vertex {v} at {p}");
        thigh += usize::from(on_thigh);
        palm += usize::from(on_palm);
    }
    assert!(
        thigh > 100 && palm > 50,
        "{thigh} thigh and {palm} palm vertices"
    );
    // Elsewhere too, the bridge changes (almost) nothing.
    assert!(
        moved * 200 < demo.positions.len(),
        "{moved} of {} vertices changed their main joint",
        demo.positions.len()
    );
    // The decomposition and the warnings name the region the two cuts shared.
    let shared = &after.decomposition.shared_sides;
    assert_eq!(shared.len(), 1, "{shared:?}");
    let mut heads = shared[0].joints.clone();
    heads.sort_unstable();
    assert_eq!(heads, {
        let mut both = vec![hand, upleg];
        both.sort_unstable();
        both
    });
    assert!(before.decomposition.shared_sides.is_empty());
    assert!(
        after.warnings.iter().any(|w| w.topic == WarningTopic::Mesh
            && ["hand_l", "upleg_l", "divided"]
                .iter()
                .all(|part| w.message.contains(part))),
        "{:?}",
        after.warnings
    );
    assert!(before
        .warnings
        .iter()
        .all(|w| !w.message.contains("divided")));
}

#[test]
fn a_hand_fused_to_its_own_upper_arm_is_not_divided_from_it() {
    // The child sides of the wrist's and the shoulder's cuts join, but the shoulder's joint
    // is an ancestor of the wrist's: one chain shares the region, nothing is divided.
    let demo = demo_character(DEFAULT_STEP);
    let hand = demo.skeleton.find("hand_l").expect("the demo has hand_l");
    let hand_at = demo.skeleton.bind_positions()[hand];
    let under_hand = nearest_face(&demo, hand_at + Vec3::new(0.05, -0.05, 0.0));
    let under_arm = nearest_face(&demo, Vec3::new(0.35, 1.33, 0.0));
    let fused = skinned(&bridged(&demo, under_hand, under_arm));
    assert!(fused.decomposition.shared_sides.is_empty());
    assert!(fused
        .warnings
        .iter()
        .all(|w| !w.message.contains("divided")));
}

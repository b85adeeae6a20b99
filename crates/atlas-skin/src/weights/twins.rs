//! Joints at one point (step 6 of [`super`]): the weight of a class of twins.
//!
//! Two joints whose bind positions lie within `SAME_POINT` × the skeleton's diagonal of
//! each other and that are siblings or parent and child are twins; twins of twins belong
//! to one class. (A joint elsewhere in the tree at the same point, an IK target parented
//! to the root at the hand, moves on its own: sharing the hand's weight with it would drag
//! the skin.) Every rule of the method sees a class as one point: no plane, section or
//! bone length tells their parts apart. The rules give a class's weight to some of its
//! joints and leave others, that move skin too, without any weight at all: two eye-lid joints at the centre of one eye (the lid
//! goes to one of them), Khronos' SimpleSkin (both joints bound at one point: everything
//! goes to the root). Which one the artist meant the geometry cannot say, so the weight
//! is shared: the choice that is least wrong whatever the artist's choice was. With the
//! class's joints moved by transforms M_i, a vertex x weighted a_i against the artist's
//! t_i moves by an error |Σ_i (t_i − a_i) M_i x|; over every t of the simplex its worst
//! case is smallest at its centre, a_i = 1/n (for two joints |t − a| |(M₁ − M₂) x|, worst
//! case max(a, 1 − a), least at a = ½).
//!
//! The rule: in a class C of n joints that move skin (not helpers, not forbidden), of
//! which the set W got some weight and the others none, a vertex's class weight
//! m = Σ_{j∈W} w_j becomes w_j |W| / n on each j of W and m / n on each other joint of C.
//! Rows keep their sum; a class whose joints all have weight, or none, is left as it is,
//! and so is a class of more than [`LARGEST_CLASS`] joints (a skeleton of thousands of
//! joints bound at one point: shares no vertex can hold, each row as long as the class),
//! with a warning.

use super::SurfaceWeights;
use crate::skeleton::nearest_point::JointPoints;
use atlas_skin_runtime::Skeleton;

/// The most joints a class of twins may have to share its weight: as many influences as
/// a vertex of a written glTF holds (`atlas_skin_io`'s `MAX_INFLUENCES`).
pub const LARGEST_CLASS: usize = 32;

/// What [`share_among_twins`] did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct TwinShares {
    /// The joints given a share, increasing.
    pub given: Vec<u32>,
    /// The joints of the classes left alone for having more than [`LARGEST_CLASS`] joints.
    pub too_many: usize,
}

/// Shares the weight of every class of twins among its joints (module documentation).
///
/// - `owns_skin`: #J flags, false for the joints that move no skin (helpers, forbidden).
pub fn share_among_twins(
    skeleton: &Skeleton,
    owns_skin: &[bool],
    weights: &mut SurfaceWeights,
) -> TwinShares {
    let joints = JointPoints::new(skeleton);
    let count = skeleton.len();
    let moves_skin = |j: usize| owns_skin[j];
    let mut classes = joints.sibling_classes(skeleton, moves_skin);
    for j in (0..count).filter(|&j| moves_skin(j)) {
        if let Some(parent) = skeleton.parent(j) {
            if moves_skin(parent) && joints.same_point(j, parent) {
                classes.union(j as u32, parent as u32);
            }
        }
    }
    // A class is represented by its smallest joint: some joint is not its own
    // representative exactly when some class has two joints.
    if (0..count as u32).all(|j| classes.find(j) == j) {
        return TwinShares::default();
    }
    let mut weighted = vec![false; count];
    for (&j, &w) in weights.joints.iter().zip(&weights.weights) {
        weighted[j as usize] |= w > 0.0;
    }
    // Per class representative: its size n and how many of its joints have weight.
    let mut size = vec![0usize; count];
    let mut with_weight = vec![0usize; count];
    for j in (0..count).filter(|&j| moves_skin(j)) {
        let r = classes.find(j as u32) as usize;
        size[r] += 1;
        with_weight[r] += usize::from(weighted[j]);
    }
    let uneven = |r: usize| with_weight[r] > 0 && with_weight[r] < size[r];
    let shared = |r: usize| uneven(r) && size[r] <= LARGEST_CLASS;
    let too_many = (0..count)
        .filter(|&r| uneven(r) && size[r] > LARGEST_CLASS)
        .map(|r| size[r])
        .sum();
    let mut unweighted_of = vec![Vec::new(); count];
    let mut given = Vec::new();
    for j in (0..count).filter(|&j| moves_skin(j) && !weighted[j]) {
        let r = classes.find(j as u32) as usize;
        if shared(r) {
            unweighted_of[r].push(j as u32);
            given.push(j as u32);
        }
    }
    if given.is_empty() {
        return TwinShares { given, too_many };
    }
    let class_of: Vec<Option<usize>> = (0..count)
        .map(|j| {
            let r = classes.find(j as u32) as usize;
            (weighted[j] && shared(r)).then_some(r)
        })
        .collect();
    let mut result = SurfaceWeights {
        offsets: vec![0],
        ..SurfaceWeights::default()
    };
    let mut mass: Vec<(usize, f64)> = Vec::new();
    for v in 0..weights.vertex_count() {
        mass.clear();
        let kept = weights.row(v).map(|(j, w)| match class_of[j as usize] {
            Some(r) => {
                match mass.iter_mut().find(|(c, _)| *c == r) {
                    Some((_, m)) => *m += w,
                    None => mass.push((r, w)),
                }
                (j, w * with_weight[r] as f64 / size[r] as f64)
            }
            None => (j, w),
        });
        let kept: Vec<(u32, f64)> = kept.collect();
        let spread = mass.iter().flat_map(|&(r, m)| {
            let share = m / size[r] as f64;
            unweighted_of[r].iter().map(move |&j| (j, share))
        });
        result.extend_row(kept.into_iter().chain(spread));
    }
    *weights = result;
    TwinShares { given, too_many }
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    /// A chain of joints at `points`, each the child of the one before.
    fn skeleton_at(points: &[Vec3]) -> Skeleton {
        Skeleton::from_positions(
            (0..points.len()).map(|j| format!("j{j}")).collect(),
            (0..points.len() as u32)
                .map(|j| j.checked_sub(1).unwrap_or(NO_PARENT))
                .collect(),
            points,
        )
        .unwrap()
    }

    fn rows(weights: &SurfaceWeights) -> Vec<Vec<(u32, f64)>> {
        (0..weights.vertex_count())
            .map(|v| {
                let mut row: Vec<(u32, f64)> = weights.row(v).collect();
                row.sort_by_key(|&(j, _)| j);
                row
            })
            .collect()
    }

    fn weights_of(rows: &[&[(u32, f64)]]) -> SurfaceWeights {
        let mut weights = SurfaceWeights {
            offsets: vec![0],
            ..SurfaceWeights::default()
        };
        for row in rows {
            weights.extend_row(row.iter().copied());
        }
        weights
    }

    #[test]
    fn a_class_with_one_weighted_joint_shares_its_weight_equally() {
        // Joints 0, 1 and 3 at one point (3 a helper), joint 2 elsewhere.
        let p = Vec3::new(0.0, 1.0, 0.0);
        let skeleton = skeleton_at(&[p, p, Vec3::new(0.0, 2.0, 0.0), p]);
        let owns_skin = [true, true, true, false];
        let mut weights = weights_of(&[&[(0, 1.0)], &[(0, 0.4), (2, 0.6)], &[(2, 1.0)]]);
        let shares = share_among_twins(&skeleton, &owns_skin, &mut weights);
        assert_eq!(shares.given, vec![1]);
        assert_eq!(
            rows(&weights),
            vec![
                vec![(0, 0.5), (1, 0.5)],
                vec![(0, 0.2), (1, 0.2), (2, 0.6)],
                vec![(2, 1.0)],
            ]
        );
    }

    #[test]
    fn weighted_twins_keep_their_ratio_and_give_the_others_an_equal_share() {
        let p = Vec3::ZERO;
        let skeleton = skeleton_at(&[p, p, p]);
        let mut weights = weights_of(&[&[(0, 0.75), (1, 0.25)]]);
        assert_eq!(
            share_among_twins(&skeleton, &[true; 3], &mut weights).given,
            vec![2]
        );
        let row = &rows(&weights)[0];
        let expected = [(0, 0.5), (1, 1.0 / 6.0), (2, 1.0 / 3.0)];
        assert_eq!(row.len(), 3);
        for (&(j, w), &(k, x)) in row.iter().zip(&expected) {
            assert_eq!(j, k);
            assert!((w - x).abs() < 1e-12, "{row:?}");
        }
    }

    #[test]
    fn a_joint_at_the_point_but_elsewhere_in_the_tree_is_no_twin() {
        // j3, a target parented to the root, sits at the point of j2, the child of j1.
        let skeleton = Skeleton::from_positions(
            (0..4).map(|j| format!("j{j}")).collect(),
            vec![NO_PARENT, 0, 1, 0],
            &[Vec3::ZERO, Vec3::Y, 2.0 * Vec3::Y, 2.0 * Vec3::Y],
        )
        .unwrap();
        let before = weights_of(&[&[(2, 1.0)], &[(1, 0.5), (2, 0.5)]]);
        let mut weights = before.clone();
        assert_eq!(
            share_among_twins(&skeleton, &[true; 4], &mut weights),
            TwinShares::default()
        );
        assert_eq!(weights, before);
    }

    #[test]
    fn a_class_too_large_to_share_is_left_alone_and_counted() {
        let n = LARGEST_CLASS + 1;
        let skeleton = skeleton_at(&vec![Vec3::ZERO; n]);
        let before = weights_of(&[&[(0, 1.0)]]);
        let mut weights = before.clone();
        let shares = share_among_twins(&skeleton, &vec![true; n], &mut weights);
        assert_eq!(
            shares,
            TwinShares {
                given: Vec::new(),
                too_many: n
            }
        );
        assert_eq!(weights, before);
        // One joint fewer: every joint takes an equal share.
        let skeleton = skeleton_at(&vec![Vec3::ZERO; n - 1]);
        let mut weights = before.clone();
        let shares = share_among_twins(&skeleton, &vec![true; n - 1], &mut weights);
        assert_eq!(shares.given.len(), n - 2);
        assert!(weights
            .row(0)
            .all(|(_, w)| (w - 1.0 / (n - 1) as f64).abs() < 1e-12));
    }

    #[test]
    fn classes_all_weighted_or_apart_are_left_alone() {
        let skeleton = skeleton_at(&[Vec3::ZERO, Vec3::ZERO, Vec3::X, Vec3::X * 1.001]);
        let before = weights_of(&[&[(0, 0.5), (1, 0.5)], &[(2, 1.0)]]);
        let mut weights = before.clone();
        // 0 and 1 are both weighted; 3 is 10⁻³ from 2, a hundred times the radius.
        assert_eq!(
            share_among_twins(&skeleton, &[true; 4], &mut weights),
            TwinShares::default()
        );
        assert_eq!(weights, before);
    }
}

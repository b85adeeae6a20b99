//! Rigid bindings: every vertex moves with one joint, when the user asks for it
//! ([`Binding::Rigid`]).
//!
//! Many game characters are bound rigidly by their artists: each vertex follows a single
//! joint (plates of armour, low-poly limbs that overlap at the joints instead of bending).
//! No geometric cue tells such a character from a blended one (docs/pieces.md, "Rigid
//! bindings: no geometric cue"), so the method does not guess: the user says it.
//!
//! **The decomposition is kept.** Regions, cuts, overlaps, soft boundaries, patches,
//! pieces and every later step ([`crate::weights`], steps 1–6) are computed as for smooth
//! weights ω; then each vertex p takes one joint with weight 1: the row's **median in the
//! joint tree**, the deepest joint k whose subtree (k and its descendants) carries more
//! than half of the row,
//!
//! j*(p) = the deepest k with m_k(p) > ½,  m_k(p) = Σ_{i in subtree(k)} ω_i(p).
//!
//! Where one joint carries more than half of the row, j* is that joint (its subtree holds
//! more than half, its children's at most the rest); the rule differs from the heaviest
//! joint only where no joint does, where three or more joints meet (a crotch between two
//! thighs and the hips, a shoulder between the chest, a clavicle and the neck): there it
//! takes the common ancestor unless one branch holds most of the weight. A row split
//! exactly in half between a joint and its child goes to the joint. The result does not
//! depend on the order of the row.
//!
//! **Why the median.** It is the single joint whose motion is nearest the smooth row's in
//! expectation over independent rotations of the joints, the poses `atlas-skin eval`
//! draws. With small rotations θ_k about each joint's point o_k, linear blend skinning
//! moves p by Σ_i ω_i Σ_{k ∈ A(i)} θ_k × (p − o_k) (A(i): i and its ancestors), so the
//! rigid row of j differs from the smooth row by Σ_k θ_k × (p − o_k) (m_k − [k ∈ A(j)]).
//! With E θ_k θ_kᵀ = σ² I, independent, its expected squared norm is
//! Σ_k c |p − o_k|² (m_k − [k ∈ A(j)])², and choosing j changes the term of each k ∈ A(j)
//! by c |p − o_k|² (1 − 2 m_k): the sum is smallest when A(j) holds exactly the joints
//! with m_k > ½, whatever the distances. The heaviest joint instead minimises the weight
//! L1 distance 2(1 − ω_j), which ignores that a child moves with its parent.
//!
//! **Where the switch lies.** Two regions blend by β(λ) and β(1 − λ) (Lu et al. 2008, §4:
//! β(l) + β(1 − l) = 1, λ = ½ on the cut curve), so across a cut the joint changes exactly
//! on the cut curve of §3.1: the rigid boundary is the cut itself, as in the paper's atlas
//! before overlapping (§3.2). A soft boundary gives its child joint β(½) = ½ of the
//! chain's mass on its plane: the switch lies on that plane, in the middle of the soft
//! transition. A piece weighted rigidly stays so; an attached piece follows the body's
//! choice beneath it.
//!
//! Measured on the characters of the benchmark that their artists bound rigidly, against
//! the heaviest joint of the final row and of the row before the sibling blends (step 3b):
//! docs/measurements.md, "Rigid bindings".

use super::siblings::depths;
use super::SurfaceWeights;
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use serde::{Deserialize, Serialize};

/// How each vertex is bound to the skeleton.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Binding {
    /// Blended weights: each vertex may follow several joints (the method of
    /// [`crate::weights`]).
    #[default]
    Smooth,
    /// One joint per vertex, with weight 1: the median of its smooth row in the joint tree
    /// (module documentation).
    Rigid,
}

impl Binding {
    /// The name the command line, the settings file and the report use.
    pub fn name(self) -> &'static str {
        match self {
            Binding::Smooth => "smooth",
            Binding::Rigid => "rigid",
        }
    }
}

/// The heaviest joint of a row, ties to the lowest joint index; `None` for an empty row.
pub fn heaviest_joint(row: impl IntoIterator<Item = (u32, f64)>) -> Option<u32> {
    row.into_iter()
        .reduce(|best, next| {
            if next.1 > best.1 || (next.1 == best.1 && next.0 < best.0) {
                next
            } else {
                best
            }
        })
        .map(|(j, _)| j)
}

/// The joint tree that [`median_joint`] walks: each joint's parent and depth.
#[derive(Debug, Clone)]
pub struct JointTree<'a> {
    parents: &'a [u32],
    depths: Vec<u32>,
}

impl<'a> JointTree<'a> {
    /// The tree of a validated skeleton.
    pub fn new(skeleton: &'a Skeleton) -> Self {
        Self {
            parents: &skeleton.parents,
            depths: depths(skeleton),
        }
    }
}

/// The rigid joint of one row of weights (module documentation): the deepest joint whose
/// subtree (itself and its descendants) carries more than half of the row's weight. A
/// row's subtree masses only fall from a root down, and two subtrees that each hold more
/// than half cannot be disjoint, so these joints form one chain from the root and the
/// deepest is unique. In a forest where no tree holds more than half (never so in the
/// pipeline, whose skeleton has one root), the heaviest joint; `None` for an empty row.
///
/// - `masses`: scratch, (joint, subtree mass) of the row's joints and their ancestors.
pub fn median_joint(
    row: &[(u32, f64)],
    tree: &JointTree,
    masses: &mut Vec<(u32, f64)>,
) -> Option<u32> {
    masses.clear();
    for &(j, w) in row {
        let mut k = j;
        loop {
            match masses.iter_mut().find(|m| m.0 == k) {
                Some(m) => m.1 += w,
                None => masses.push((k, w)),
            }
            k = tree.parents[k as usize];
            if k == NO_PARENT {
                break;
            }
        }
    }
    let half = 0.5 * row.iter().map(|&(_, w)| w).sum::<f64>();
    masses
        .iter()
        .filter(|&&(_, m)| m > half)
        .max_by_key(|&&(k, _)| tree.depths[k as usize])
        .map(|&(k, _)| k)
        .or_else(|| heaviest_joint(row.iter().copied()))
}

/// `weights` bound rigidly: every row replaced by its [`median_joint`] with weight 1 (an
/// empty row stays empty).
///
/// - `skeleton`: the skeleton the weights are of.
pub fn bind_rigidly(weights: &SurfaceWeights, skeleton: &Skeleton) -> SurfaceWeights {
    let tree = JointTree::new(skeleton);
    let mut rigid = SurfaceWeights {
        offsets: vec![0],
        joints: Vec::with_capacity(weights.vertex_count()),
        weights: Vec::with_capacity(weights.vertex_count()),
    };
    let (mut row, mut masses) = (Vec::new(), Vec::new());
    for v in 0..weights.vertex_count() {
        row.clear();
        row.extend(weights.row(v));
        rigid.extend_row(median_joint(&row, &tree, &mut masses).map(|j| (j, 1.0)));
    }
    rigid
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use proptest::prelude::*;

    /// hips (root) → spine, thigh.L → knee.L, thigh.R: joints 0 to 4 (positions do not
    /// matter to the rule).
    fn legs() -> Skeleton {
        Skeleton::from_positions(
            ["hips", "spine", "thigh.L", "thigh.R", "knee.L"]
                .map(String::from)
                .to_vec(),
            vec![NO_PARENT, 0, 0, 0, 2],
            &[Vec3::ZERO, Vec3::Y, -Vec3::X, Vec3::X, -Vec3::X - Vec3::Y],
        )
        .unwrap()
    }

    fn rigid_rows(rows: &[&[(u32, f64)]], skeleton: &Skeleton) -> Vec<Vec<(u32, f64)>> {
        let mut smooth = SurfaceWeights {
            offsets: vec![0],
            ..SurfaceWeights::default()
        };
        for row in rows {
            smooth.extend_row(row.iter().copied());
        }
        let rigid = bind_rigidly(&smooth, skeleton);
        (0..rigid.vertex_count())
            .map(|v| rigid.row(v).collect())
            .collect()
    }

    #[test]
    fn each_row_takes_the_deepest_joint_holding_more_than_half() {
        let rows: [&[(u32, f64)]; 8] = [
            // A majority joint wins.
            &[(2, 0.7), (0, 0.3)],
            &[(4, 0.6), (3, 0.4)],
            // A crotch: the heaviest is thigh.L, but the hips' subtree holds the row.
            &[(2, 0.4), (3, 0.35), (0, 0.25)],
            // thigh.L's subtree holds 0.7, knee.L alone 0.35.
            &[(0, 0.3), (2, 0.35), (4, 0.35)],
            // Split in half between a joint and its child: the joint, in any order.
            &[(4, 0.5), (2, 0.5)],
            &[(2, 0.5), (4, 0.5)],
            &[(1, 1.0)],
            &[],
        ];
        assert_eq!(
            rigid_rows(&rows, &legs()),
            [
                vec![(2, 1.0)],
                vec![(4, 1.0)],
                vec![(0, 1.0)],
                vec![(2, 1.0)],
                vec![(2, 1.0)],
                vec![(2, 1.0)],
                vec![(1, 1.0)],
                vec![]
            ]
        );
    }

    #[test]
    fn in_a_forest_without_a_majority_the_heaviest_joint_ties_to_the_lowest_index() {
        let two_roots = Skeleton::from_positions(
            vec!["a".into(), "b".into()],
            vec![NO_PARENT, NO_PARENT],
            &[Vec3::ZERO, Vec3::X],
        )
        .unwrap();
        let rows: [&[(u32, f64)]; 3] = [
            &[(1, 0.5), (0, 0.5)],
            &[(1, 0.6), (0, 0.4)],
            &[(0, 0.2), (1, 0.8)],
        ];
        assert_eq!(
            rigid_rows(&rows, &two_roots),
            [vec![(0, 1.0)], vec![(1, 1.0)], vec![(1, 1.0)]]
        );
    }

    /// The module documentation's expected squared difference between the motion of the
    /// smooth row and that of joint j's rigid row, Σ_k d_k (m_k − [k ∈ A(j)])², with a
    /// positive factor d_k per joint (c |p − o_k|²): the reference the rule is compared with.
    fn expected_difference(row: &[(u32, f64)], parents: &[u32], d: &[f64], j: usize) -> f64 {
        let ancestors = |mut i: usize| {
            let mut chain = vec![i];
            while parents[i] != NO_PARENT {
                i = parents[i] as usize;
                chain.push(i);
            }
            chain
        };
        let mut mass = vec![0.0; parents.len()];
        for &(i, w) in row {
            for k in ancestors(i as usize) {
                mass[k] += w;
            }
        }
        let on_path = ancestors(j);
        (0..parents.len())
            .map(|k| d[k] * (mass[k] - f64::from(u8::from(on_path.contains(&k)))).powi(2))
            .sum()
    }

    proptest! {
        /// On random trees, rows and distances, the rule's joint has the least expected
        /// difference of all joints.
        #[test]
        fn the_median_minimises_the_expected_difference_of_motion(
            links in proptest::collection::vec(0.0..1.0f64, 1..12),
            raw in proptest::collection::vec((0usize..12, 0.01..1.0f64), 1..6),
            distances in proptest::collection::vec(0.01..4.0f64, 12),
        ) {
            // Joint i > 0 hangs from one of the joints before it.
            let count = links.len() + 1;
            let parents: Vec<u32> = std::iter::once(NO_PARENT)
                .chain(links.iter().enumerate().map(|(i, &u)| (u * (i + 1) as f64) as u32))
                .collect();
            let positions: Vec<Vec3> = (0..count).map(|i| Vec3::X * i as f32).collect();
            let names = (0..count).map(|i| format!("j{i}")).collect();
            let skeleton = Skeleton::from_positions(names, parents.clone(), &positions).unwrap();
            let mut row: Vec<(u32, f64)> = Vec::new();
            for &(j, w) in &raw {
                let j = (j % count) as u32;
                if !row.iter().any(|&(i, _)| i == j) {
                    row.push((j, w));
                }
            }
            let total: f64 = row.iter().map(|&(_, w)| w).sum();
            row.iter_mut().for_each(|(_, w)| *w /= total);
            let chosen = median_joint(&row, &JointTree::new(&skeleton), &mut Vec::new()).unwrap();
            let cost = |j| expected_difference(&row, &parents, &distances, j);
            let best = (0..count).map(cost).fold(f64::INFINITY, f64::min);
            prop_assert!(cost(chosen as usize) <= best + 1e-9, "{row:?} {parents:?}");
        }
    }

    #[test]
    fn names_are_those_of_the_settings_file() {
        for binding in [Binding::Smooth, Binding::Rigid] {
            let json = serde_json::to_string(&binding).unwrap();
            assert_eq!(json, format!("\"{}\"", binding.name()));
            assert_eq!(serde_json::from_str::<Binding>(&json).unwrap(), binding);
        }
    }
}

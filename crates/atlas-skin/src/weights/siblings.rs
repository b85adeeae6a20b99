//! Step 3b of the weights: blends between sibling joints pass through their common
//! ancestor (issue 13, item 1).
//!
//! Two joints j and k of which neither is an ancestor of the other (two thighs, a neck and a
//! clavicle, two palm bones) can share a vertex: where their regions' overlap bands meet (a
//! crotch whose pelvis region is pinched to nothing between the thigh cuts), or where two
//! soft boundaries of one region reach the same skin (the base of a neck between the
//! shoulders). Posed, such a vertex follows the average of two transforms that turn about
//! different pivots in unrelated directions and lands where neither limb is; artists give
//! that skin to the joint the two limbs hang from. So the part of the vertex the pair
//! shares goes to their lowest common ancestor a:
//!
//!   t_jk = f_jk · min(w_j, w_k),
//!   f_jk = 1 − β(clamp((d_a / min(d_j, d_k) − ρ₀) / (ρ₁ − ρ₀), 0, 1)),
//!
//! with w the vertex's weights of steps 1–3, d_x the distance from the vertex to the nearest
//! bone segment of joint x ([`JointBones::distance`]), β the transition function of §4
//! ([`super::blend::beta`]), ρ₀ = [`NEAR_RATIO`], ρ₁ = [`FAR_RATIO`]. On a midline
//! (w_j = w_k = ½) the vertex goes wholly to the ancestor; where one of the pair holds
//! little, only that little moves, so the weights change continuously as the pair's do. The
//! ancestor takes the weight only where its own bones are about as near as the
//! pair's (a pelvis joint high above a crotch that the thighs' bones pass beside is not, and
//! the crotch stays with the thighs). Each joint j gives t_jk to the ancestor of every pair it is
//! in, scaled by c_j = min(1, w_j / Σ_k t_jk) so that no weight goes negative:
//!
//!   w'_j = w_j − c_j Σ_k t_jk,   w'_a = w_a + Σ_{(j,k): a} (c_j + c_k) t_jk.
//!
//! Weight only moves between joints, so the row still sums to 1; every term is continuous
//! in w and in the distances, so the weights stay continuous over the surface. Measured on
//! the benchmark in docs/measurements.md, "Sibling blends through their common ancestor".

use super::blend::beta;
use super::surface_weights::SurfaceWeights;
use crate::skeleton::ancestry::Ancestry;
use crate::skeleton::bones::JointBones;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;

/// ρ₀: the ancestor takes the full share while its bones are at most this many times
/// farther from the vertex than the nearer of the pair's.
pub const NEAR_RATIO: f64 = 1.0;

/// ρ₁: the ancestor takes nothing once its bones are this many times farther.
pub const FAR_RATIO: f64 = 1.6;

/// Moves part of every sibling blend to the pair's common ancestor (module documentation);
/// returns how many vertices changed.
///
/// - `positions`: the vertices of the rows of `weights`.
/// - `joint_bones`: the bone segments of `skeleton` keyed by joint, for the d_x.
/// - `owns_skin`: per joint, whether it may take weight (an ancestor that owns no skin
///   takes none).
pub fn merge_sibling_blends(
    skeleton: &Skeleton,
    positions: &[DVec3],
    joint_bones: &JointBones,
    owns_skin: &[bool],
    weights: &mut SurfaceWeights,
) -> usize {
    let family = Family::new(skeleton, joint_bones, owns_skin);
    let mut row = Vec::new();
    let merge = |source: &SurfaceWeights, v: usize, row: &mut Vec<(u32, f64)>| {
        row.clear();
        row.extend(source.row(v));
        family.merge_row(positions[v], row)
    };
    let Some(first) = (0..positions.len()).find(|&v| merge(weights, v, &mut row)) else {
        return 0;
    };
    // The rows before the first that changes stay as they are.
    let source = std::mem::take(weights);
    *weights = source.first_rows(first);
    let mut changed = 0;
    for v in first..positions.len() {
        if merge(&source, v, &mut row) {
            changed += 1;
        }
        weights.extend_row(row.iter().copied());
    }
    changed
}

/// The skeleton's tree and bones as the rule needs them.
struct Family<'a> {
    ancestry: Ancestry,
    bones: &'a JointBones,
    owns_skin: Vec<bool>,
}

impl<'a> Family<'a> {
    fn new(skeleton: &Skeleton, bones: &'a JointBones, owns_skin: &[bool]) -> Self {
        Self {
            ancestry: Ancestry::new(skeleton),
            bones,
            owns_skin: owns_skin.to_vec(),
        }
    }

    /// d_j: the distance from `p` to the nearest bone segment of joint j.
    fn bone_distance(&self, p: DVec3, j: u32) -> f64 {
        self.bones.distance(p, j)
    }

    /// The rule on one row of (joint, weight) pairs at point p; whether it changed.
    fn merge_row(&self, p: DVec3, row: &mut Vec<(u32, f64)>) -> bool {
        // Transfers (giver, ancestor, amount) before the scaling c_j.
        let mut transfers: Vec<(usize, u32, f64)> = Vec::new();
        // Bone distances asked of each joint once per row: a row of many siblings asks
        // every pair, and their common ancestor may move thousands of bones.
        let mut known: Vec<(u32, f64)> = Vec::new();
        let mut distance = |j: u32| match known.iter().find(|e| e.0 == j) {
            Some(&(_, d)) => d,
            None => {
                let d = self.bone_distance(p, j);
                known.push((j, d));
                d
            }
        };
        for x in 0..row.len() {
            for y in x + 1..row.len() {
                let ((j, wj), (k, wk)) = (row[x], row[y]);
                let Some(a) = self.ancestry.sibling_ancestor(j, k) else {
                    continue;
                };
                if !self.owns_skin[a as usize] {
                    continue;
                }
                let near = distance(j).min(distance(k));
                let ratio = distance(a) / near;
                let reach =
                    1.0 - beta(((ratio - NEAR_RATIO) / (FAR_RATIO - NEAR_RATIO)).clamp(0.0, 1.0));
                let amount = reach * wj.min(wk);
                if amount > 0.0 {
                    transfers.push((x, a, amount));
                    transfers.push((y, a, amount));
                }
            }
        }
        if transfers.is_empty() {
            return false;
        }
        let mut outflow = vec![0.0; row.len()];
        for &(x, _, amount) in &transfers {
            outflow[x] += amount;
        }
        let scale: Vec<f64> = outflow
            .iter()
            .zip(row.iter())
            .map(|(&out, &(_, w))| if out > w { w / out } else { 1.0 })
            .collect();
        for (x, &out) in outflow.iter().enumerate() {
            row[x].1 = if scale[x] < 1.0 { 0.0 } else { row[x].1 - out };
        }
        for (x, a, amount) in transfers {
            let given = scale[x] * amount;
            match row.iter_mut().find(|e| e.0 == a) {
                Some(entry) => entry.1 += given,
                None => row.push((a, given)),
            }
        }
        row.retain(|&(_, w)| w > 0.0);
        true
    }
}

/// Each joint's depth (its number of ancestors), parents first in one pass: walking up
/// from every joint would cost the square of a chain's length.
pub(crate) fn depths(skeleton: &Skeleton) -> Vec<u32> {
    let mut depths = vec![0; skeleton.len()];
    for j in skeleton.topological_order() {
        if let Some(p) = skeleton.parent(j) {
            depths[j] = depths[p] + 1;
        }
    }
    depths
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::bones::bone_segments;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    /// A pelvis at the origin with two legs hanging from hips at x = ±h (y down), a spine up
    /// from the pelvis, and a knee under each hip: a crotch between the hips at height y.
    fn legs(h: f32) -> Skeleton {
        Skeleton::from_positions(
            ["pelvis", "spine", "hip.L", "knee.L", "hip.R", "knee.R"]
                .map(String::from)
                .to_vec(),
            vec![NO_PARENT, 0, 0, 2, 0, 4],
            &[
                Vec3::ZERO,
                Vec3::Y,
                Vec3::new(h, 0.0, 0.0),
                Vec3::new(h, -1.0, 0.0),
                Vec3::new(-h, 0.0, 0.0),
                Vec3::new(-h, -1.0, 0.0),
            ],
        )
        .unwrap()
    }

    fn merged(skeleton: &Skeleton, p: DVec3, row: &[(u32, f64)]) -> Vec<(u32, f64)> {
        let mut weights = SurfaceWeights {
            offsets: vec![0],
            ..SurfaceWeights::default()
        };
        weights.extend_row(row.iter().copied());
        merge_sibling_blends(
            skeleton,
            &[p],
            &JointBones::new(&bone_segments(skeleton)),
            &vec![true; skeleton.len()],
            &mut weights,
        );
        let mut row: Vec<(u32, f64)> = weights.row(0).collect();
        row.sort_by_key(|e| e.0);
        row
    }

    fn weight(row: &[(u32, f64)], joint: u32) -> f64 {
        row.iter().find(|e| e.0 == joint).map_or(0.0, |e| e.1)
    }

    #[test]
    fn depths_count_the_ancestors_with_parents_after_children_and_several_roots() {
        // Roots 1 and 4; the chain 1 → 3 → 0 → 2 → 6 runs against the index order.
        let parents = vec![3, NO_PARENT, 0, 1, NO_PARENT, 4, 2];
        let names = (0..parents.len()).map(|j| format!("j{j}")).collect();
        let skeleton =
            Skeleton::from_positions(names, parents, &[Vec3::ZERO; 7]).expect("a forest");
        let ancestors: Vec<u32> = (0..skeleton.len())
            .map(|j| skeleton.ancestors(j).count() as u32)
            .collect();
        assert_eq!(depths(&skeleton), ancestors);
        assert_eq!(ancestors, vec![2, 0, 3, 1, 0, 1, 4]);
    }

    #[test]
    fn rows_before_and_after_the_first_change_are_kept_in_place() {
        // The crotch of the first test between vertices whose rows do not change.
        let skeleton = legs(0.1);
        let crotch = DVec3::new(0.0, -0.05, 0.05);
        let (thigh, elsewhere) = (DVec3::new(0.1, -0.5, 0.05), DVec3::new(0.0, 1.0, 0.0));
        let rows: [&[(u32, f64)]; 4] = [
            &[(2, 1.0)],
            &[(2, 0.5), (4, 0.5)],
            &[(1, 0.7), (0, 0.3)],
            &[(2, 0.5), (3, 0.5)],
        ];
        let positions = [thigh, crotch, elsewhere, thigh];
        let mut weights = SurfaceWeights {
            offsets: vec![0],
            ..SurfaceWeights::default()
        };
        for row in rows {
            weights.extend_row(row.iter().copied());
        }
        let joint_bones = JointBones::new(&bone_segments(&skeleton));
        let owns_skin = vec![true; skeleton.len()];
        let merge = |weights: &mut SurfaceWeights, positions: &[DVec3]| {
            merge_sibling_blends(&skeleton, positions, &joint_bones, &owns_skin, weights)
        };
        let before = weights.clone();
        // Without the crotch nothing changes.
        let mut unchanged = before.first_rows(1);
        assert_eq!(merge(&mut unchanged, &positions[..1]), 0);
        assert_eq!(unchanged, before.first_rows(1));
        assert_eq!(merge(&mut weights, &positions), 1);
        assert_eq!(weights.vertex_count(), 4);
        for v in [0, 2, 3] {
            assert_eq!(
                weights.row(v).collect::<Vec<_>>(),
                before.row(v).collect::<Vec<_>>()
            );
        }
        let crotch_row = merged(&skeleton, crotch, rows[1]);
        let mut row: Vec<(u32, f64)> = weights.row(1).collect();
        row.sort_by_key(|e| e.0);
        assert_eq!(row, crotch_row);
        assert!(weight(&row, 0) > 0.0);
    }

    #[test]
    fn a_midline_between_two_thighs_goes_to_the_pelvis() {
        // Bones of the hips run from (±0.1, 0, 0) down: a crotch point at (0, -0.05, 0.05)
        // is 0.112 from each and 0.071 from the pelvis's bones (to the hips, to the spine).
        let skeleton = legs(0.1);
        let p = DVec3::new(0.0, -0.05, 0.05);
        let row = merged(&skeleton, p, &[(2, 0.5), (4, 0.5)]);
        // The pelvis's bones are the nearer (f = 1): each thigh gives min(½, ½), all of it.
        assert_eq!(row, vec![(0, 1.0)]);
    }

    #[test]
    fn a_pelvis_far_above_the_crotch_takes_nothing() {
        // Hips 1 apart, their bones running down from (±0.5, 0, 0): a crotch point 0.6 under
        // the pelvis is 0.6 from the pelvis's bones and 0.5 from the thighs' (ratio 1.2,
        // inside the fade) ...
        let skeleton = legs(0.5);
        let near = DVec3::new(0.0, -0.6, 0.0);
        let row = merged(&skeleton, near, &[(2, 0.5), (4, 0.5)]);
        assert!(weight(&row, 0) > 0.0 && weight(&row, 0) < 1.0, "{row:?}");
        // ... and at y = −1 it is 1 from them against the thighs' 0.5 (ratio 2 > ρ₁).
        let far = DVec3::new(0.0, -1.0, 0.0);
        let row = merged(&skeleton, far, &[(2, 0.5), (4, 0.5)]);
        assert_eq!(row, vec![(2, 0.5), (4, 0.5)]);
    }

    #[test]
    fn parents_and_children_are_left_alone_and_a_small_share_moves_only_itself() {
        let skeleton = legs(0.1);
        let p = DVec3::new(0.05, -0.05, 0.05);
        // A thigh and its own knee: not siblings.
        let row = [(2, 0.5), (3, 0.5)];
        assert_eq!(merged(&skeleton, p, &row), row.to_vec());
        // On the crotch's midline (f = 1) a thigh holding 0.05 gives it, and the other thigh
        // as much: the pelvis takes 0.1.
        let crotch = DVec3::new(0.0, -0.05, 0.05);
        let row = merged(&skeleton, crotch, &[(2, 0.95), (4, 0.05)]);
        assert!((weight(&row, 0) - 0.1).abs() < 1e-12, "{row:?}");
        assert!((weight(&row, 2) - 0.9).abs() < 1e-12, "{row:?}");
        assert_eq!(weight(&row, 4), 0.0, "{row:?}");
    }

    #[test]
    fn many_siblings_keep_a_partition_of_unity_and_change_continuously() {
        // Five fingers from one hand at the origin, their bones along +y, fanned in x.
        let mut positions = vec![Vec3::ZERO];
        let mut parents = vec![NO_PARENT];
        for f in 0..5 {
            let x = 0.1 * (f as f32 - 2.0);
            positions.push(Vec3::new(x, 0.5, 0.0));
            parents.push(0);
            positions.push(Vec3::new(x, 1.0, 0.0));
            parents.push(1 + 2 * f);
        }
        let names = (0..positions.len()).map(|j| format!("j{j}")).collect();
        let skeleton = Skeleton::from_positions(names, parents, &positions).unwrap();
        let p = DVec3::new(0.0, 0.45, 0.02);
        let fingers = [1u32, 3, 5, 7, 9];
        // The middle finger's share t grows from 0 to 1, the others share the rest.
        let row = |t: f64| -> Vec<(u32, f64)> {
            fingers
                .iter()
                .map(|&j| (j, if j == 5 { t } else { (1.0 - t) / 4.0 }))
                .filter(|e| e.1 > 0.0)
                .collect()
        };
        let h = 1e-7;
        for step in 0..100 {
            let t = step as f64 / 100.0;
            let out = merged(&skeleton, p, &row(t));
            assert!(out.iter().all(|e| e.1 >= 0.0), "{out:?}");
            assert!(
                (out.iter().map(|e| e.1).sum::<f64>() - 1.0).abs() < 1e-12,
                "{out:?}"
            );
            let next = merged(&skeleton, p, &row(t + h));
            let change: f64 = (0..skeleton.len() as u32)
                .map(|j| (weight(&next, j) - weight(&out, j)).abs())
                .sum();
            assert!(change < 100.0 * h, "t = {t}: {out:?} → {next:?}");
        }
    }
}

//! Transition function and region blending (Lu et al. 2008, §4 and §5).
//!
//! A vertex p lies in the overlapping parts of n *related regions* V_1 … V_n (§5). Each
//! related region i gives p a normalised depth λ_i > 0 (computed in [`crate::weights`]):
//! λ = ½ on the cut curve of ∂V_i, 1 at the inner edge of its overlap band, 0 at the outer
//! edge, ∞ deeper inside than any band reaches. For one boundary of diameter D with overlap
//! half-width w at surface distance g from p (positive on V_i's side), λ_i = (w + g)/(2w):
//! the distance from p to the boundary of V_i *grown by its overlap*, over the band's
//! width. With the paper's w = D/2 this is §4's d_i / D.

use serde::{Deserialize, Serialize};

/// The transition function of §4: β(l) = −2l³ + 3l², with β(0) = 0, β(1) = 1,
/// β'(0) = β'(1) = 0 and β(l) + β(1 − l) = 1.
pub fn beta(l: f64) -> f64 {
    l * l * (3.0 - 2.0 * l)
}

/// How the related regions of a vertex are blended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Blend {
    /// Normalised partition of unity (METHOD.md, stage 4): b_i = β(clamp(λ_i, 0, 1)),
    /// ω_j = b_j / Σ_i b_i. Equal to Eq. 1 where n = 2 (β(x) / (β(x) + β(1 − x)) = β(x))
    /// and continuous where a vertex enters a third region.
    #[default]
    PartitionOfUnity,
    /// The paper's Eq. 1 (§4): ω_j = 2/(n(n−1)) Σ_{i≠j} β(λ_j / (λ_i + λ_j)), ω_1 = 1 when
    /// n = 1. Jumps where n changes from 2 to 3.
    Paper,
}

/// Weights ω of the related regions of one vertex from their depths.
///
/// - `depths`: n normalised depths λ_i > 0 (possibly +∞).
/// - `weights`: n outputs, ω_i ≥ 0 with Σ ω_i = 1 (all 0 when n = 0).
pub fn blend_regions(blend: Blend, depths: &[f64], weights: &mut [f64]) {
    debug_assert_eq!(depths.len(), weights.len());
    match depths.len() {
        0 => {}
        1 => weights[0] = 1.0,
        n => match blend {
            Blend::PartitionOfUnity => {
                for (w, &l) in weights.iter_mut().zip(depths) {
                    *w = beta(l.clamp(0.0, 1.0));
                }
                let total: f64 = weights.iter().sum();
                for w in weights.iter_mut() {
                    *w /= total;
                }
            }
            Blend::Paper => {
                let scale = 2.0 / (n * (n - 1)) as f64;
                for (j, w) in weights.iter_mut().enumerate() {
                    let sum: f64 = (0..n)
                        .filter(|&i| i != j)
                        .map(|i| beta(depth_ratio(depths[j], depths[i])))
                        .sum();
                    *w = scale * sum;
                }
            }
        },
    }
}

/// d_j / (d_i + d_j) with ∞ handled as the limit: 1 when only d_j is infinite, 0 when only
/// d_i is, ½ when both are.
fn depth_ratio(d_j: f64, d_i: f64) -> f64 {
    match (d_j.is_infinite(), d_i.is_infinite()) {
        (true, true) => 0.5,
        (true, false) => 1.0,
        (false, true) => 0.0,
        (false, false) => d_j / (d_i + d_j),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beta_has_the_paper_properties() {
        assert_eq!(beta(0.0), 0.0);
        assert_eq!(beta(1.0), 1.0);
        for k in 0..=20 {
            let l = k as f64 / 20.0;
            assert!((beta(l) + beta(1.0 - l) - 1.0).abs() < 1e-12);
        }
        let slope = |l: f64| (beta(l + 1e-7) - beta(l - 1e-7)) / 2e-7;
        assert!(slope(1e-7).abs() < 1e-5 && slope(1.0 - 1e-7).abs() < 1e-5);
    }

    #[test]
    fn both_blends_agree_on_two_regions_and_match_beta() {
        for g in [-0.4, -0.1, 0.0, 0.2, 0.45] {
            let depths = [0.5 + g, 0.5 - g];
            let (mut pou, mut paper) = ([0.0; 2], [0.0; 2]);
            blend_regions(Blend::PartitionOfUnity, &depths, &mut pou);
            blend_regions(Blend::Paper, &depths, &mut paper);
            assert!((pou[0] - beta(0.5 + g)).abs() < 1e-12);
            assert!((pou[0] - paper[0]).abs() < 1e-12 && (pou[1] - paper[1]).abs() < 1e-12);
        }
    }

    #[test]
    fn paper_blend_jumps_where_a_third_region_enters_and_the_default_does_not() {
        // A vertex in the overlap of V_1 and V_2 as it enters V_3's band (λ_3 → 0⁺).
        let two = [0.7, 0.3];
        let three = [0.7, 0.3, 1e-9];
        let weight_of_first = |blend, depths: &[f64]| {
            let mut w = vec![0.0; depths.len()];
            blend_regions(blend, depths, &mut w);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(w.iter().all(|&x| x >= 0.0));
            w[0]
        };
        let paper_jump =
            (weight_of_first(Blend::Paper, &two) - weight_of_first(Blend::Paper, &three)).abs();
        let pou_jump = (weight_of_first(Blend::PartitionOfUnity, &two)
            - weight_of_first(Blend::PartitionOfUnity, &three))
        .abs();
        assert!(paper_jump > 0.1, "Eq. 1 jump {paper_jump}");
        assert!(pou_jump < 1e-9, "partition of unity jump {pou_jump}");
    }

    #[test]
    fn infinite_depth_takes_everything_in_the_paper_blend() {
        let mut w = [0.0; 2];
        blend_regions(Blend::Paper, &[f64::INFINITY, 0.2], &mut w);
        assert_eq!(w, [1.0, 0.0]);
    }
}

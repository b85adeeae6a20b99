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
//! weights; then each vertex takes the joint of largest weight in its smooth row, with
//! weight 1, ties going to the lowest joint index (so the result does not depend on the
//! order of the row):
//!
//! j*(p) = argmax_j ω_j(p),  w_{j*}(p) = 1.
//!
//! **Why the heaviest joint.**
//! - Of all single-joint rows it is the one nearest the smooth row: ‖e_j − ω‖₁ = 2(1 − ω_j),
//!   smallest for the largest ω_j. Under a pose with joint transforms T_i, linear blend
//!   skinning moves p to Σ_i ω_i T_i p, and the rigid row moves it to T_j p: they differ by
//!   Σ_{i≠j} ω_i (T_i − T_j) p, whose bound Σ_{i≠j} ω_i · max_i ‖(T_i − T_j) p‖ is smallest
//!   for the same j.
//! - It puts the switch where the method puts the boundary. Two regions blend by
//!   β(λ) and β(1 − λ) (Lu et al. 2008, §4: β(l) + β(1 − l) = 1, λ = ½ on the cut curve),
//!   so the heavier region changes exactly on the cut curve of §3.1: the rigid boundary is
//!   the cut itself, as in the paper's atlas before overlapping (§3.2). A soft boundary
//!   gives its child joint β(½) = ½ of the chain's mass on its plane, so the switch lies
//!   on that plane, in the middle of the soft transition. A piece weighted rigidly stays
//!   so; an attached piece follows the body's choice beneath it.
//!
//! Measured against the alternative of taking the heaviest joint before the sibling blends
//! (step 3c), and against the default smooth weights, on the rigidly bound characters of
//! the benchmark: docs/measurements.md, "Rigid bindings".

use super::SurfaceWeights;
use serde::{Deserialize, Serialize};

/// How each vertex is bound to the skeleton.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Binding {
    /// Blended weights: each vertex may follow several joints (the method of
    /// [`crate::weights`]).
    #[default]
    Smooth,
    /// One joint per vertex, with weight 1: the heaviest of its smooth row (module
    /// documentation).
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

/// `weights` bound rigidly: every row replaced by its heaviest joint with weight 1 (an
/// empty row stays empty).
pub fn bind_rigidly(weights: &SurfaceWeights) -> SurfaceWeights {
    let mut rigid = SurfaceWeights {
        offsets: vec![0],
        joints: Vec::with_capacity(weights.vertex_count()),
        weights: Vec::with_capacity(weights.vertex_count()),
    };
    for v in 0..weights.vertex_count() {
        rigid.extend_row(heaviest_joint(weights.row(v)).map(|j| (j, 1.0)));
    }
    rigid
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_row_keeps_its_heaviest_joint_ties_to_the_lowest_index() {
        let mut smooth = SurfaceWeights {
            offsets: vec![0],
            ..SurfaceWeights::default()
        };
        smooth.extend_row([(3, 0.2), (1, 0.7), (2, 0.1)]);
        smooth.extend_row([(5, 0.5), (2, 0.5)]);
        smooth.extend_row([(2, 0.5), (5, 0.5)]);
        smooth.extend_row([(4, 1.0)]);
        smooth.extend_row([]);
        let rigid = bind_rigidly(&smooth);
        let rows: Vec<Vec<(u32, f64)>> = (0..rigid.vertex_count())
            .map(|v| rigid.row(v).collect())
            .collect();
        assert_eq!(
            rows,
            [
                vec![(1, 1.0)],
                vec![(2, 1.0)],
                vec![(2, 1.0)],
                vec![(4, 1.0)],
                vec![]
            ]
        );
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

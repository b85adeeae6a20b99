//! Developer switches that turn single rules of the method off, so that each can be measured
//! alone on the benchmark (docs/ablation.md, `scripts/ablation`). They are settings of the
//! stage that owns the rule ([`crate::cuts::params::DecomposeParams::rules_off`] for the
//! cuts, [`crate::pipeline::SkinParams::weights_rules_off`] for the weights), read from a
//! settings file (`--config`); they are not user options and no command-line flag sets them.
//! A rule switched off falls back to what the method did before the rule existed.

use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

/// A rule of the method that can be switched off (docs/ablation.md says what each does and
/// what it is worth).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Rule {
    /// Cuts, rule 1: joints named as helpers (attachment slots, locators, IK targets) move
    /// no skin ([`crate::skeleton::helpers`]).
    HelperNames,
    /// Cuts, rule 4: a branching joint on the mirror plane whose branches start within its
    /// section gets a soft boundary instead of a searched cut.
    MirrorBranching,
    /// Cuts, rule 5 (c): a leaf whose part runs on past it on the piece around its upper
    /// bone owns it; off, it is an end site.
    LeafPartPast,
    /// Cuts: a joint keeps its cut only when its mirror twin gets one too.
    MirrorTwins,
    /// Weights, step 3b: sibling joints that share a vertex give part of their weight to
    /// their lowest common ancestor.
    SiblingBlends,
    /// Weights, step 4: weights on bones far from the vertex are removed.
    FarBoneGuard,
    /// Weights, step 3: κ_c keeps a soft joint on its own part (its own bones clearly the
    /// nearest, [`crate::weights::ownership`]); off, κ_c = 1.
    OwnPart,
    /// Weights, step 3: π_c carries a soft joint's part past its plane where the bones of
    /// its descendants without a boundary are the nearest; off, π_c = 0.
    PastPlane,
    /// Weights, step 3: a soft side whose band holds no vertex is seeded from the far ends
    /// of the edges that span its band.
    FarEndSeeds,
    /// Weights, step 3: failing that, a joint with child bones (or a leaf whose part runs
    /// on past it) is seeded within the nearest vertex's distance plus its band.
    FartherSeeds,
    /// Weights, step 3: failing that, a free joint with child bones is seeded from its own
    /// part (chains along sheets).
    OwnPartSeeds,
    /// Weights, step 3: soft joints between a continued region's bound joint and a joint it
    /// holds also bend that region.
    ContinuedSoftSides,
    /// Weights, step 5: a piece that no bone enters holds the bones around it.
    PiecesBonesAround,
    /// Weights, step 5: a bone that only pokes into a piece holds it only where it is the
    /// nearest bone to half of its vertices.
    PiecesPokingBones,
    /// Weights, step 5: a piece that encloses a free joint holds its bones.
    PiecesEnclosedJoints,
    /// Weights, step 5: a piece that holds no bone is carried by the joints where it
    /// touches the body, and its weights spread from that contact.
    PiecesContact,
    /// Weights, step 5: an attached piece moves with one part of the skeleton, the one that
    /// carries most of it ([`crate::weights::carriers`]).
    PiecesOneCarrier,
    /// Weights, step 5: a piece small next to its joint's bone is rigid to it.
    PiecesSmallRigid,
}

impl Rule {
    /// Every rule, in the order of docs/ablation.md.
    pub const ALL: [Rule; 18] = [
        Rule::HelperNames,
        Rule::MirrorBranching,
        Rule::LeafPartPast,
        Rule::MirrorTwins,
        Rule::SiblingBlends,
        Rule::FarBoneGuard,
        Rule::OwnPart,
        Rule::PastPlane,
        Rule::FarEndSeeds,
        Rule::FartherSeeds,
        Rule::OwnPartSeeds,
        Rule::ContinuedSoftSides,
        Rule::PiecesBonesAround,
        Rule::PiecesPokingBones,
        Rule::PiecesEnclosedJoints,
        Rule::PiecesContact,
        Rule::PiecesOneCarrier,
        Rule::PiecesSmallRigid,
    ];

    /// Whether the rule belongs to the cut stage (else to the weights).
    pub fn is_cut_rule(self) -> bool {
        self < Rule::SiblingBlends
    }
}

/// The rules switched off (none by default).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct RulesOff(pub BTreeSet<Rule>);

impl RulesOff {
    /// Whether `rule` applies.
    pub fn on(&self, rule: Rule) -> bool {
        !self.0.contains(&rule)
    }
}

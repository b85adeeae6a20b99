//! What the method noticed and handled ([`crate::pipeline::Skinned::warnings`]), each
//! warning with its topic: a person reads the message, a pipeline selects by topic (the
//! quality gate of `atlas-skin skin --fail-on`).

use serde::Serialize;
use std::fmt;

/// What a [`Warning`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WarningTopic {
    /// The surface: duplicate faces, closed pieces wound inside out, a surface that joins
    /// the sides of cuts (a higher genus).
    Mesh,
    /// Whether the skeleton sits in the mesh ([`crate::skeleton::placement`]): joints
    /// beside the mesh or outside its surface, joints at one point, zero-length bones, no
    /// boundary at all.
    Placement,
    /// What the method made of the skeleton to use it: a hierarchy inferred for several
    /// roots, leaf extensions capped, joints named as helpers that move no skin.
    Skeleton,
    /// The weights: soft joints whose boundary found no cross-section and that carry no
    /// weight (the job's report adds this warning from the weights' counts).
    Weights,
}

impl WarningTopic {
    /// Every topic, in the order of the enum.
    pub const ALL: [WarningTopic; 4] = [
        WarningTopic::Mesh,
        WarningTopic::Placement,
        WarningTopic::Skeleton,
        WarningTopic::Weights,
    ];

    /// The topic's name, as the report writes it.
    pub fn name(self) -> &'static str {
        match self {
            WarningTopic::Mesh => "mesh",
            WarningTopic::Placement => "placement",
            WarningTopic::Skeleton => "skeleton",
            WarningTopic::Weights => "weights",
        }
    }
}

/// One warning: its topic and the sentence that says what was noticed and what was done.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Warning {
    pub topic: WarningTopic,
    pub message: String,
}

impl Warning {
    pub fn new(topic: WarningTopic, message: impl Into<String>) -> Self {
        Self {
            topic,
            message: message.into(),
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

//! The quality gate of a job (`atlas-skin skin --fail-on LIST`): what the report records
//! of a skinned character that a pipeline may refuse ([`Findings`]: the warnings by topic,
//! the vertices weighted by a fallback, the soft joints and the joints with a boundary
//! that carry no weight), the conditions it may refuse it on ([`Condition`]), and the
//! verdict ([`Verdict`]). A rejected character's outputs are written, when kept, under the
//! names of [`rejected_name`].

use atlas_skin::pipeline::Skinned;
use atlas_skin::WarningTopic;
use serde::{Deserialize, Serialize};
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The topic of the warnings of the file's reader in the report's `warning_topics` (the
/// method's warnings carry a [`WarningTopic`]).
pub const INPUT_TOPIC: &str = "input";

/// A condition of the quality gate, named in `--fail-on`, the settings file's `fail_on`
/// and the report's `quality.fail_on`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Condition {
    /// Any warning at all.
    Warnings,
    /// A warning of the file's reader.
    Input,
    /// A warning about the mesh ([`WarningTopic::Mesh`]).
    Mesh,
    /// A warning about where the skeleton sits in the mesh ([`WarningTopic::Placement`]).
    Placement,
    /// A warning about what the method made of the skeleton ([`WarningTopic::Skeleton`]).
    Skeleton,
    /// A warning about the weights ([`WarningTopic::Weights`]).
    Weights,
    /// A vertex weighted by a fallback (the report's `counts.fallback_weighted_vertices`).
    Fallback,
    /// A soft joint whose boundary found no cross-section and that carries no weight.
    SoftJoints,
    /// A joint given a boundary (a cut or a soft boundary) that carries no weight.
    UnweightedJoints,
}

impl Condition {
    /// Every condition, in the order of the enum.
    pub const ALL: [Condition; 9] = [
        Condition::Warnings,
        Condition::Input,
        Condition::Mesh,
        Condition::Placement,
        Condition::Skeleton,
        Condition::Weights,
        Condition::Fallback,
        Condition::SoftJoints,
        Condition::UnweightedJoints,
    ];

    /// The name of `--fail-on`.
    pub fn name(self) -> &'static str {
        match self {
            Condition::Warnings => "warnings",
            Condition::Input => INPUT_TOPIC,
            Condition::Mesh => WarningTopic::Mesh.name(),
            Condition::Placement => WarningTopic::Placement.name(),
            Condition::Skeleton => WarningTopic::Skeleton.name(),
            Condition::Weights => WarningTopic::Weights.name(),
            Condition::Fallback => "fallback",
            Condition::SoftJoints => "soft-joints",
            Condition::UnweightedJoints => "unweighted-joints",
        }
    }

    /// What the condition refuses, for `--help`.
    pub fn description(self) -> &'static str {
        match self {
            Condition::Warnings => "any warning",
            Condition::Input => {
                "a warning of the file's reader (weights not summing to 1, \
                 channels or meshes left out, ...)"
            }
            Condition::Mesh => {
                "a warning about the mesh (duplicate faces, pieces wound inside \
                 out, a surface joining the sides of cuts, vertices no triangle uses)"
            }
            Condition::Placement => {
                "a warning about where the skeleton sits in the mesh \
                 (joints beside it or outside its surface, joints at one point, zero-length \
                 bones, no boundary at all)"
            }
            Condition::Skeleton => {
                "a warning about what the method made of the skeleton \
                 (a hierarchy inferred, leaf extensions capped, joints named as helpers)"
            }
            Condition::Weights => "a warning about the weights (soft joints without weight)",
            Condition::Fallback => {
                "a vertex weighted by a fallback \
                 (counts.fallback_weighted_vertices)"
            }
            Condition::SoftJoints => {
                "a soft joint that carries no weight (no cross-section \
                 near the joint)"
            }
            Condition::UnweightedJoints => {
                "a joint given a boundary (a cut or a soft \
                 boundary) that carries no weight"
            }
        }
    }

    /// The condition of a warning topic.
    fn of_topic(topic: &str) -> Option<Condition> {
        Condition::ALL
            .into_iter()
            .filter(|c| !matches!(c, Condition::Warnings))
            .find(|c| c.name() == topic)
    }
}

impl std::str::FromStr for Condition {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Condition::ALL
            .into_iter()
            .find(|c| c.name() == text)
            .ok_or_else(|| {
                let names: Vec<&str> = Condition::ALL.iter().map(|c| c.name()).collect();
                format!(
                    "{text:?} is not a condition of the quality gate (one of: {})",
                    names.join(", ")
                )
            })
    }
}

/// What the gate judges a skinned character by: everything the report records of it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Findings {
    /// Every warning of the report, in its order, with its topic ([`INPUT_TOPIC`] or a
    /// [`WarningTopic`]'s name): the reader's, the method's, then the soft joints that
    /// carry no weight (weights) and the stored vertices no triangle uses (mesh).
    pub warnings: Vec<(&'static str, String)>,
    /// Stored vertices weighted by a fallback (no triangle uses them: bound to their
    /// nearest bone).
    pub fallback_weighted_vertices: usize,
    /// Soft joints whose boundary found no cross-section near the joint and that carry no
    /// weight in the end (a joint given weight by a later step is not named).
    pub soft_joints_without_weight: Vec<String>,
    /// Joints given a boundary (a cut or a soft boundary) that carry no weight on any
    /// stored vertex (joints without a boundary, such as end sites and helpers, move with
    /// their parent by design and are not named).
    pub unweighted_joints: Vec<String>,
}

impl Findings {
    /// The findings of `skinned`, whose reader warned `input_warnings`.
    pub fn new(input_warnings: &[String], skinned: &Skinned) -> Self {
        let decomposition = &skinned.decomposition;
        let counts = &skinned.counts;
        let mut carries = vec![false; decomposition.joints.len()];
        for (&j, &w) in skinned.weights.joints.iter().zip(&skinned.weights.weights) {
            if w > 0.0 {
                carries[j as usize] = true;
            }
        }
        let name = |j: usize| decomposition.joints[j].name.clone();
        let soft_joints_without_weight: Vec<String> = counts
            .weights
            .inactive_soft_joints
            .iter()
            .map(|&j| j as usize)
            .filter(|&j| !carries[j])
            .map(name)
            .collect();
        let unweighted_joints = (0..decomposition.joints.len())
            .filter(|&j| decomposition.joints[j].boundary.is_some() && !carries[j])
            .map(name)
            .collect();
        let mut warnings: Vec<(&'static str, String)> = input_warnings
            .iter()
            .map(|w| (INPUT_TOPIC, w.clone()))
            .collect();
        warnings.extend(
            skinned
                .warnings
                .iter()
                .map(|w| (w.topic.name(), w.message.clone())),
        );
        if !soft_joints_without_weight.is_empty() {
            warnings.push((
                WarningTopic::Weights.name(),
                format!(
                    "{} soft boundaries have no cross-section near their joint and carry no \
                     weight: {}",
                    soft_joints_without_weight.len(),
                    soft_joints_without_weight.join(", ")
                ),
            ));
        }
        let fallback_weighted_vertices = counts.unreferenced_stored_vertices;
        if fallback_weighted_vertices > 0 {
            warnings.push((
                WarningTopic::Mesh.name(),
                format!(
                    "{fallback_weighted_vertices} stored vertices are used by no triangle: \
                     bound to their nearest bone"
                ),
            ));
        }
        Self {
            warnings,
            fallback_weighted_vertices,
            soft_joints_without_weight,
            unweighted_joints,
        }
    }

    /// Whether `condition` holds, and then why (one sentence per cause).
    fn causes(&self, condition: Condition) -> Vec<String> {
        let joints = |count: usize, names: &[String], what: &str| {
            if count == 0 {
                Vec::new()
            } else {
                vec![format!("{count} {what}: {}", names.join(", "))]
            }
        };
        match condition {
            Condition::Warnings if self.warnings.is_empty() => Vec::new(),
            Condition::Warnings => vec![format!("{} warning(s)", self.warnings.len())],
            Condition::Fallback if self.fallback_weighted_vertices == 0 => Vec::new(),
            Condition::Fallback => vec![format!(
                "{} vertices weighted by a fallback",
                self.fallback_weighted_vertices
            )],
            Condition::SoftJoints => joints(
                self.soft_joints_without_weight.len(),
                &self.soft_joints_without_weight,
                "soft joint(s) carry no weight",
            ),
            Condition::UnweightedJoints => joints(
                self.unweighted_joints.len(),
                &self.unweighted_joints,
                "joint(s) with a boundary carry no weight",
            ),
            topic => self
                .warnings
                .iter()
                .filter(|(t, _)| Condition::of_topic(t) == Some(topic))
                .map(|(_, message)| message.clone())
                .collect(),
        }
    }
}

/// The gate's verdict on one character.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Verdict {
    /// The conditions asked for (empty: no gate).
    pub fail_on: Vec<Condition>,
    /// Why the character is rejected, `CONDITION: cause` (empty: accepted).
    pub reasons: Vec<String>,
}

impl Verdict {
    /// Judges `findings` on `fail_on`: every cause of every condition that holds, in the
    /// order of `fail_on`.
    pub fn new(findings: &Findings, fail_on: &[Condition]) -> Self {
        let reasons = fail_on
            .iter()
            .flat_map(|&c| {
                findings
                    .causes(c)
                    .into_iter()
                    .map(move |cause| format!("{}: {cause}", c.name()))
            })
            .collect();
        Self {
            fail_on: fail_on.to_vec(),
            reasons,
        }
    }

    pub fn rejected(&self) -> bool {
        !self.reasons.is_empty()
    }
}

/// Where an output of a rejected character goes when kept: `.rejected` before the
/// extension (`out/knight.glb` → `out/knight.rejected.glb`), so that no rejected result
/// has the name of an accepted one.
pub fn rejected_name(path: &Path) -> PathBuf {
    let mut name: OsString = path.file_stem().unwrap_or_default().to_os_string();
    name.push(".rejected");
    if let Some(extension) = path.extension() {
        name.push(".");
        name.push(extension);
    }
    path.with_file_name(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn findings() -> Findings {
        Findings {
            warnings: vec![
                (INPUT_TOPIC, "weights do not sum to 1".into()),
                ("placement", "2 joints lie beside the mesh".into()),
                ("placement", "1 bone(s) have zero length".into()),
            ],
            fallback_weighted_vertices: 0,
            soft_joints_without_weight: Vec::new(),
            unweighted_joints: vec!["jaw".into(), "tail".into()],
        }
    }

    #[test]
    fn conditions_are_named_and_parsed_back() {
        for condition in Condition::ALL {
            assert_eq!(condition.name().parse::<Condition>(), Ok(condition));
            let json = serde_json::to_value(condition).unwrap();
            assert_eq!(json, condition.name());
            assert!(!condition.description().is_empty());
        }
        let error = "softjoints".parse::<Condition>().unwrap_err();
        assert!(error.contains("soft-joints") && error.contains("unweighted-joints"));
    }

    #[test]
    fn the_verdict_names_every_cause_of_the_conditions_asked_for() {
        let findings = findings();
        assert!(!Verdict::new(&findings, &[]).rejected());
        let clean = [
            Condition::Mesh,
            Condition::Skeleton,
            Condition::Weights,
            Condition::Fallback,
            Condition::SoftJoints,
        ];
        assert!(!Verdict::new(&findings, &clean).rejected());
        let verdict = Verdict::new(
            &findings,
            &[
                Condition::Placement,
                Condition::UnweightedJoints,
                Condition::Warnings,
                Condition::Input,
            ],
        );
        assert_eq!(
            verdict.reasons,
            [
                "placement: 2 joints lie beside the mesh",
                "placement: 1 bone(s) have zero length",
                "unweighted-joints: 2 joint(s) with a boundary carry no weight: jaw, tail",
                "warnings: 3 warning(s)",
                "input: weights do not sum to 1",
            ]
        );
    }

    #[test]
    fn rejected_outputs_are_named_apart() {
        let cases = [
            ("out/knight.glb", "out/knight.rejected.glb"),
            ("knight.v2.json", "knight.v2.rejected.json"),
            ("out/rig", "out/rig.rejected"),
        ];
        for (path, rejected) in cases {
            assert_eq!(rejected_name(Path::new(path)), Path::new(rejected));
        }
    }
}

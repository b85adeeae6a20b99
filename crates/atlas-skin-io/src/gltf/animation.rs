//! glTF animations (glTF 2.0 §3.11) as [`Clip`]s over the node [`Rig`], read and written.

use super::accessor::read_floats;
use super::builder::GlbBuilder;
use super::document::{opt_str, Document, Location};
use super::nodes::NodeTree;
use crate::IoError;
use atlas_skin_runtime::animation::NO_PARENT_NODE;
use atlas_skin_runtime::{Clip, Interpolation, Property, Rig, Track};
use serde_json::{json, Value};
use std::path::Path;

/// The rig of a document: every node with its parent, rest transform and (unique) name;
/// `joint_nodes` are the skin's joints.
pub(crate) fn read_rig(tree: &NodeTree, names: Vec<String>, joint_nodes: &[usize]) -> Rig {
    Rig {
        names,
        parents: tree
            .parents
            .iter()
            .map(|p| p.map_or(NO_PARENT_NODE, |p| p as u32))
            .collect(),
        rest: tree.local.clone(),
        joint_nodes: joint_nodes.iter().map(|&n| n as u32).collect(),
    }
}

/// Components of one key value of `property`.
fn components(property: Property) -> usize {
    match property {
        Property::Rotation => 4,
        Property::Translation | Property::Scale => 3,
    }
}

fn property_name(property: Property) -> &'static str {
    match property {
        Property::Translation => "translation",
        Property::Rotation => "rotation",
        Property::Scale => "scale",
    }
}

fn interpolation_name(interpolation: Interpolation) -> &'static str {
    match interpolation {
        Interpolation::Step => "STEP",
        Interpolation::Linear => "LINEAR",
        Interpolation::CubicSpline => "CUBICSPLINE",
    }
}

/// Number of floats a track with `keys` keys must have: #K × C, or #K × 3 × C for a cubic
/// spline (in-tangent, value, out-tangent per key).
fn expected_values(property: Property, interpolation: Interpolation, keys: usize) -> usize {
    let per_key = match interpolation {
        Interpolation::CubicSpline => 3,
        Interpolation::Step | Interpolation::Linear => 1,
    };
    keys * per_key * components(property)
}

/// Every animation's translation, rotation and scale channels. Morph-target `weights`
/// channels and channels without a target node are skipped with a warning.
pub(crate) fn read_clips(doc: &Document, warnings: &mut Vec<String>) -> Result<Vec<Clip>, IoError> {
    let node_count = doc.array("nodes")?.len();
    let mut clips = Vec::new();
    for (index, animation) in doc.array("animations")?.iter().enumerate() {
        let location = format!("animations[{index}]");
        let samplers = match animation.get("samplers") {
            Some(Value::Array(samplers)) => samplers.as_slice(),
            _ => return Err(doc.error(format!("{location} has no samplers array"))),
        };
        let channels = match animation.get("channels") {
            Some(Value::Array(channels)) => channels.as_slice(),
            _ => return Err(doc.error(format!("{location} has no channels array"))),
        };
        let mut tracks = Vec::new();
        let mut skipped = 0;
        for (c, channel) in channels.iter().enumerate() {
            let channel_location = Location::child(&location, "channels", c);
            let target = channel
                .get("target")
                .ok_or_else(|| doc.error(format!("{channel_location} has no target")))?;
            let property = match opt_str(target, "path") {
                Some("translation") => Property::Translation,
                Some("rotation") => Property::Rotation,
                Some("scale") => Property::Scale,
                _ => {
                    skipped += 1;
                    continue;
                }
            };
            let Some(node) = doc.opt_index(target, &channel_location, "node")? else {
                skipped += 1;
                continue;
            };
            if node >= node_count {
                return Err(doc.error(format!(
                    "{channel_location}.target.node is {node} but the document has {node_count} \
                     nodes"
                )));
            }
            let sampler_index = doc.index(channel, &channel_location, "sampler")?;
            let sampler = samplers.get(sampler_index).ok_or_else(|| {
                doc.error(format!(
                    "{channel_location}.sampler is {sampler_index} but {location} has {} samplers",
                    samplers.len()
                ))
            })?;
            let track = read_track(
                doc,
                sampler,
                &Location::child(&location, "samplers", sampler_index),
                node,
                property,
            )?;
            tracks.push(track);
        }
        if skipped > 0 {
            warnings.push(format!(
                "{location}: {skipped} channel(s) on morph weights or without a target node ignored"
            ));
        }
        let duration = tracks
            .iter()
            .filter_map(|t| t.times.last().copied())
            .fold(0.0, f32::max);
        clips.push(Clip {
            name: opt_str(animation, "name")
                .map(str::to_string)
                .unwrap_or_else(|| format!("animation{index}")),
            duration,
            tracks,
        });
    }
    Ok(clips)
}

/// The keys of one sampler driving `property` of `node`. Key times must be finite and
/// ascending; the value count must match the key count and interpolation.
fn read_track(
    doc: &Document,
    sampler: &Value,
    location: &Location,
    node: usize,
    property: Property,
) -> Result<Track, IoError> {
    let interpolation = match opt_str(sampler, "interpolation").unwrap_or("LINEAR") {
        "LINEAR" => Interpolation::Linear,
        "STEP" => Interpolation::Step,
        "CUBICSPLINE" => Interpolation::CubicSpline,
        other => {
            return Err(doc.error(format!(
                "{location}.interpolation {other:?} is not LINEAR, STEP or CUBICSPLINE"
            )))
        }
    };
    let input = doc.index(sampler, location, "input")?;
    let times = read_floats(doc, input, "SCALAR", &Location::field(location, "input"))?;
    if times.iter().any(|t| !t.is_finite()) || times.windows(2).any(|w| w[1] < w[0]) {
        return Err(doc.error(format!(
            "{location}: key times are not finite and ascending"
        )));
    }
    let value_type = if components(property) == 4 {
        "VEC4"
    } else {
        "VEC3"
    };
    let output = doc.index(sampler, location, "output")?;
    let values = read_floats(
        doc,
        output,
        value_type,
        &Location::field(location, "output"),
    )?;
    let expected = expected_values(property, interpolation, times.len());
    if values.len() != expected {
        return Err(doc.error(format!(
            "{location}: {} output values for {} keys of {} ({expected} expected)",
            values.len(),
            times.len(),
            property_name(property)
        )));
    }
    Ok(Track {
        node: node as u32,
        property,
        interpolation,
        times,
        values,
    })
}

/// Appends `clips` to the document being built, mapping each track's node (a skeleton
/// joint index) to its output node `joint_nodes[track.node]`.
///
/// # Errors
/// [`IoError::Invalid`] on `out` when a track's joint is out of range or its key and value
/// counts disagree.
pub(crate) fn append_clips(
    builder: &mut GlbBuilder,
    clips: &[Clip],
    joint_nodes: &[usize],
    out: &Path,
) -> Result<(), IoError> {
    for clip in clips {
        let mut samplers = Vec::with_capacity(clip.tracks.len());
        let mut channels = Vec::with_capacity(clip.tracks.len());
        for (t, track) in clip.tracks.iter().enumerate() {
            let node = *joint_nodes.get(track.node as usize).ok_or_else(|| {
                IoError::invalid(
                    out,
                    format!(
                        "clip {:?} track {t} animates joint {} but the skeleton has {} joints",
                        clip.name,
                        track.node,
                        joint_nodes.len()
                    ),
                )
            })?;
            let expected = expected_values(track.property, track.interpolation, track.times.len());
            let finite = track
                .times
                .iter()
                .chain(&track.values)
                .all(|v| v.is_finite());
            let increasing = track.times.windows(2).all(|w| w[0] < w[1]);
            if track.times.is_empty() || track.values.len() != expected || !finite || !increasing {
                return Err(IoError::invalid(
                    out,
                    format!(
                        "clip {:?} track {t}: {} keys and {} values (expected {expected}); keys \
                         must be finite, strictly increasing and at least one",
                        clip.name,
                        track.times.len(),
                        track.values.len()
                    ),
                ));
            }
            let input = builder.push_f32_accessor(&track.times, "SCALAR", true, None);
            let value_type = if components(track.property) == 4 {
                "VEC4"
            } else {
                "VEC3"
            };
            let output = builder.push_f32_accessor(&track.values, value_type, false, None);
            samplers.push(json!({
                "input": input,
                "output": output,
                "interpolation": interpolation_name(track.interpolation),
            }));
            channels.push(json!({
                "sampler": t,
                "target": {"node": node, "path": property_name(track.property)},
            }));
        }
        builder.push_item(
            "animations",
            json!({"name": clip.name, "samplers": samplers, "channels": channels}),
        );
    }
    Ok(())
}

//! Biovision BVH motion capture: the joint hierarchy (a skeleton in its zero-rotation bind
//! pose) and the MOTION section (a clip on a rig of the BVH joints).

use crate::text::{parse_finite, read_text, Tokens};
use crate::IoError;
use atlas_skin_runtime::animation::NO_PARENT_NODE;
use atlas_skin_runtime::{Clip, Interpolation, Property, Rig, Skeleton, Track, Trs};
use glam::{Quat, Vec3};
use std::path::Path;

/// One value per frame of a joint: a translation or a rotation (degrees) along an axis.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Channel {
    Position(usize),
    Rotation(usize),
}

impl Channel {
    fn from_name(name: &str) -> Option<Self> {
        let axis = |c: char| "XYZ".find(c.to_ascii_uppercase());
        let mut chars = name.chars();
        let first = chars.next()?;
        match chars.as_str().to_ascii_lowercase().as_str() {
            "position" => Some(Self::Position(axis(first)?)),
            "rotation" => Some(Self::Rotation(axis(first)?)),
            _ => None,
        }
    }
}

/// A joint of the hierarchy as written.
#[derive(Debug, Clone)]
struct Joint {
    name: String,
    parent: u32,
    offset: Vec3,
    channels: Vec<Channel>,
    /// OFFSET of the joint's End Site, if it has one: where its bone ends.
    end_site: Option<Vec3>,
    /// Line of the joint's `{`, for unclosed-brace errors.
    open_line: usize,
}

/// Reads the skeleton of the BVH at `path` (see [`read_motion`]).
pub fn read(path: &Path) -> Result<Skeleton, IoError> {
    read_motion(path).map(|(skeleton, _, _)| skeleton)
}

/// Reads the BVH at `path`: its skeleton, the rig of its joints and its motion.
///
/// - Joints are the ROOT and JOINT entries (End Sites are not joints), named as in the
///   file. A joint's bind position is the sum of the OFFSETs from its root down to it; its
///   orientation is the identity (the bind pose is all rotations zero), so its inverse
///   bind matrix is translation(−position). A joint with an End Site has its tail
///   ([`Skeleton::tails`]) at its position plus the End Site's OFFSET.
/// - The rig has one node per joint with rest transform translation(OFFSET).
/// - The clip (named after the file) has, per frame k at time k · frame time, for every
///   joint with rotation channels `R = R_c1 · R_c2 · R_c3` (the channels in file order,
///   each a rotation about its axis by the value in degrees, so the first listed is the
///   outermost) and for every joint with position channels the translation
///   OFFSET + (Xposition, Yposition, Zposition). Tracks are linear.
///
/// Unbalanced braces, channel counts that do not match their names, frames with the wrong
/// number of values and non-finite numbers are errors with their line.
pub fn read_motion(path: &Path) -> Result<(Skeleton, Rig, Clip), IoError> {
    let text = read_text(path)?;
    let mut tokens = Tokens::new(path, &text, None);
    tokens.expect("HIERARCHY")?;
    let joints = read_hierarchy(&mut tokens)?;
    let frames = read_frames(&mut tokens, &text, &joints)?;
    let skeleton = bind_skeleton(path, &joints)?;
    let rig = Rig {
        names: joints.iter().map(|j| j.name.clone()).collect(),
        parents: joints.iter().map(|j| j.parent).collect(),
        rest: joints
            .iter()
            .map(|j| Trs {
                translation: j.offset,
                ..Trs::IDENTITY
            })
            .collect(),
        joint_nodes: (0..joints.len() as u32).collect(),
    };
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let clip = motion_clip(name, &joints, &frames);
    Ok((skeleton, rig, clip))
}

/// Parses ROOT/JOINT/End Site blocks up to the `MOTION` keyword.
fn read_hierarchy(tokens: &mut Tokens) -> Result<Vec<Joint>, IoError> {
    let mut joints: Vec<Joint> = Vec::new();
    // Open blocks: the joint index, or None for an End Site.
    let mut open: Vec<Option<u32>> = Vec::new();
    loop {
        let Some(token) = tokens.next_token() else {
            return Err(unclosed_or(
                tokens,
                &joints,
                &open,
                "the file has no MOTION section",
            ));
        };
        match token {
            "ROOT" | "JOINT" => {
                let parent = match (token, open.last()) {
                    ("ROOT", None) => NO_PARENT_NODE,
                    ("JOINT", Some(Some(parent))) => *parent,
                    ("JOINT", Some(None)) => return Err(tokens.error("JOINT inside an End Site")),
                    _ => {
                        return Err(tokens.error(format!(
                            "{token} in the wrong place (ROOT at top level, JOINT inside a joint)"
                        )))
                    }
                };
                let name = tokens.word("joint name")?.to_string();
                tokens.expect("{")?;
                open.push(Some(joints.len() as u32));
                joints.push(Joint {
                    name,
                    parent,
                    offset: Vec3::ZERO,
                    channels: Vec::new(),
                    end_site: None,
                    open_line: tokens.line(),
                });
            }
            "End" => {
                if !matches!(open.last(), Some(Some(_))) {
                    return Err(tokens.error("End Site outside a joint"));
                }
                tokens.expect("Site")?;
                tokens.expect("{")?;
                open.push(None);
            }
            "OFFSET" => {
                let offset = tokens.point()?;
                match open.last() {
                    Some(Some(j)) => joints[*j as usize].offset = offset,
                    Some(None) => {
                        // The End Site's joint is the innermost open joint.
                        if let Some(Some(j)) = open.iter().rev().find(|b| b.is_some()) {
                            joints[*j as usize].end_site = Some(offset);
                        }
                    }
                    None => return Err(tokens.error("OFFSET outside a joint")),
                }
            }
            "CHANNELS" => {
                let Some(Some(j)) = open.last().copied() else {
                    return Err(tokens.error("CHANNELS outside a joint"));
                };
                let count: usize = tokens.parse("channel count")?;
                if count > 6 {
                    return Err(tokens.error(format!("{count} channels, at most 6 allowed")));
                }
                let mut channels = Vec::with_capacity(count);
                for k in 0..count {
                    let name = tokens.word("channel name")?;
                    let channel = Channel::from_name(name).ok_or_else(|| {
                        tokens.error(format!(
                            "CHANNELS {count} lists {k} channel names, then {name:?} (not a channel name)"
                        ))
                    })?;
                    if channels.contains(&channel) {
                        return Err(tokens.error(format!("channel {name} appears twice")));
                    }
                    channels.push(channel);
                }
                joints[j as usize].channels = channels;
            }
            "}" => {
                if open.pop().is_none() {
                    return Err(tokens.error("unmatched }"));
                }
            }
            "MOTION" => {
                if !open.is_empty() {
                    return Err(unclosed_or(tokens, &joints, &open, ""));
                }
                if joints.is_empty() {
                    return Err(tokens.error("the hierarchy has no joint"));
                }
                return Ok(joints);
            }
            other => return Err(tokens.error(format!("unexpected {other:?} in the hierarchy"))),
        }
    }
}

/// The error for blocks still open at this point (a missing `}`), else `otherwise`.
fn unclosed_or(
    tokens: &Tokens,
    joints: &[Joint],
    open: &[Option<u32>],
    otherwise: &str,
) -> IoError {
    match open.iter().rev().find_map(|j| *j) {
        Some(j) => {
            let joint = &joints[j as usize];
            tokens.error(format!(
                "missing }} for joint {:?} opened at line {}",
                joint.name, joint.open_line
            ))
        }
        None if !open.is_empty() => tokens.error("missing } for an End Site"),
        None => tokens.error(otherwise),
    }
}

/// Motion values: one row per frame, joints' channels in hierarchy order.
struct Frames {
    time_step: f32,
    rows: Vec<Vec<f32>>,
}

/// Parses `Frames: N`, `Frame Time: t` and N lines of values.
fn read_frames(tokens: &mut Tokens, text: &str, joints: &[Joint]) -> Result<Frames, IoError> {
    tokens.expect("Frames:")?;
    let count: usize = tokens.parse("frame count")?;
    tokens.expect("Frame")?;
    tokens.expect("Time:")?;
    let time_step = tokens.finite("frame time")?;
    if time_step <= 0.0 {
        return Err(tokens.error(format!("frame time {time_step} is not positive")));
    }
    let path = tokens.path();
    let width: usize = joints.iter().map(|j| j.channels.len()).sum();
    let mut rows = Vec::with_capacity(count.min(1 << 20));
    let lines = text.lines().enumerate().skip(tokens.line());
    for (index, raw) in lines.filter(|(_, raw)| !raw.trim().is_empty()) {
        let line = index + 1;
        if rows.len() == count {
            return Err(IoError::syntax(
                path,
                line,
                format!("more frames than the {count} announced"),
            ));
        }
        let row = raw
            .split_whitespace()
            .map(|token| parse_finite(path, line, Some(token), "channel value"))
            .collect::<Result<Vec<f32>, IoError>>()?;
        if row.len() != width {
            return Err(IoError::syntax(
                path,
                line,
                format!(
                    "frame {} has {} values, the hierarchy has {width} channels",
                    rows.len(),
                    row.len()
                ),
            ));
        }
        rows.push(row);
    }
    if rows.len() != count {
        return Err(IoError::invalid(
            path,
            format!(
                "the file has {} frames, its header announces {count}",
                rows.len()
            ),
        ));
    }
    Ok(Frames { time_step, rows })
}

/// The zero-rotation bind pose: positions are accumulated offsets.
fn bind_skeleton(path: &Path, joints: &[Joint]) -> Result<Skeleton, IoError> {
    let mut positions: Vec<Vec3> = Vec::with_capacity(joints.len());
    for joint in joints {
        let base = match joint.parent {
            NO_PARENT_NODE => Vec3::ZERO,
            parent => positions[parent as usize],
        };
        positions.push(base + joint.offset);
    }
    let names = joints.iter().map(|j| j.name.clone()).collect();
    let parents = joints.iter().map(|j| j.parent).collect();
    let tails = joints
        .iter()
        .zip(&positions)
        .map(|(joint, &p)| joint.end_site.map(|offset| p + offset))
        .collect();
    Skeleton::from_positions(names, parents, &positions)
        .and_then(|skeleton| skeleton.with_tails(tails))
        .map_err(|cause| IoError::Skeleton {
            path: path.to_path_buf(),
            cause,
        })
}

/// Converts the frames into rotation and translation tracks (see [`read_motion`]).
fn motion_clip(name: String, joints: &[Joint], frames: &Frames) -> Clip {
    let times: Vec<f32> = (0..frames.rows.len())
        .map(|k| k as f32 * frames.time_step)
        .collect();
    let mut tracks = Vec::new();
    let mut first_column = 0;
    for (node, joint) in joints.iter().enumerate() {
        let columns = first_column..first_column + joint.channels.len();
        first_column = columns.end;
        let has = |rotation: bool| {
            joint
                .channels
                .iter()
                .any(|c| matches!(c, Channel::Rotation(_)) == rotation)
        };
        let mut rotations = Vec::with_capacity(times.len() * 4);
        let mut translations = Vec::with_capacity(times.len() * 3);
        let mut previous = Quat::IDENTITY;
        for row in &frames.rows {
            let mut rotation = Quat::IDENTITY;
            let mut translation = joint.offset;
            for (channel, &value) in joint.channels.iter().zip(&row[columns.clone()]) {
                match *channel {
                    Channel::Position(axis) => translation[axis] += value,
                    Channel::Rotation(axis) => {
                        let mut unit = Vec3::ZERO;
                        unit[axis] = 1.0;
                        rotation *= Quat::from_axis_angle(unit, value.to_radians());
                    }
                }
            }
            // Same hemisphere as the previous key, so that interpolation takes the short way.
            let rotation = rotation.normalize();
            let rotation = if rotation.dot(previous) < 0.0 {
                -rotation
            } else {
                rotation
            };
            previous = rotation;
            rotations.extend(rotation.to_array());
            translations.extend(translation.to_array());
        }
        let track = |property, values| Track {
            node: node as u32,
            property,
            interpolation: Interpolation::Linear,
            times: times.clone(),
            values,
        };
        if has(true) {
            tracks.push(track(Property::Rotation, rotations));
        }
        if has(false) {
            tracks.push(track(Property::Translation, translations));
        }
    }
    Clip {
        name,
        duration: times.last().copied().unwrap_or(0.0),
        tracks,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;
    use atlas_skin_runtime::NO_PARENT;

    const BVH: &str = "HIERARCHY\nROOT Hips\n{\n  OFFSET 1 2 3\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n\
        \x20 JOINT Leg\n  {\n    OFFSET 0 -4 0\n    CHANNELS 3 Xrotation Zrotation Yrotation\n\
        \x20   End Site\n    {\n      OFFSET 0 -1 0\n    }\n  }\n}\n\
        MOTION\nFrames: 2\nFrame Time: 0.5\n0 0 0 0 0 0 0 0 0\n10 0 0 90 0 0 90 90 0\n";

    #[test]
    fn hierarchy_gives_the_zero_rotation_bind_pose() {
        let (skeleton, rig, clip) = read_motion(&scratch_file("walk.bvh", BVH)).unwrap();
        assert_eq!(skeleton.names, ["Hips", "Leg"]);
        assert_eq!(skeleton.parents, [NO_PARENT, 0]);
        assert_eq!(
            skeleton.bind_positions(),
            [Vec3::new(1.0, 2.0, 3.0), Vec3::new(1.0, -2.0, 3.0)]
        );
        assert_eq!(skeleton.tails, [None, Some(Vec3::new(1.0, -3.0, 3.0))]);
        assert_eq!(rig.rest[1].translation, Vec3::new(0.0, -4.0, 0.0));
        assert_eq!(clip.name, "walk");
        assert_eq!(clip.duration, 0.5);
        assert_eq!(clip.tracks.len(), 3);
    }

    #[test]
    fn motion_composes_rotations_in_channel_order() {
        let (_, _, clip) = read_motion(&scratch_file("order.bvh", BVH)).unwrap();
        let key = |track: &Track, k: usize, width: usize| {
            track.values[k * width..(k + 1) * width].to_vec()
        };
        let hips_rotation = &clip.tracks[0];
        assert_eq!(hips_rotation.property, Property::Rotation);
        let q = Quat::from_slice(&key(hips_rotation, 1, 4));
        assert!(q.abs_diff_eq(Quat::from_rotation_z(90f32.to_radians()), 1e-6));
        let hips_translation = &clip.tracks[1];
        assert_eq!(key(hips_translation, 1, 3), [11.0, 2.0, 3.0]);
        // Leg: Xrotation 90 then Zrotation 90: R = Rx · Rz, so R·X = Rx·Y = Z.
        let leg = Quat::from_slice(&key(&clip.tracks[2], 1, 4));
        assert!(
            (leg * Vec3::X).abs_diff_eq(Vec3::Z, 1e-6),
            "{}",
            leg * Vec3::X
        );
        assert_eq!(clip.tracks[2].times, [0.0, 0.5]);
    }

    #[test]
    fn broken_files_name_their_line() {
        let cases = [
            (
                BVH.replacen("    }\n  }\n}\n", "    }\n}\n", 1),
                ":15: missing } for joint \"Hips\" opened at line 3",
            ),
            (
                BVH.replace(
                    "CHANNELS 3 Xrotation Zrotation Yrotation",
                    "CHANNELS 3 Xrotation Zrotation",
                ),
                ":10: CHANNELS 3 lists 2 channel names, then \"End\"",
            ),
            (BVH.replace("CHANNELS 3", "CHANNELS 9"), ":9: 9 channels"),
            (
                BVH.replace("90 90 0\n", "90 90\n"),
                ":20: frame 1 has 8 values, the hierarchy has 9 channels",
            ),
            (
                BVH.replace("Frames: 2", "Frames: 3"),
                "the file has 2 frames, its header announces 3",
            ),
            (
                BVH.replace("OFFSET 0 -4 0", "OFFSET 0 nan 0"),
                ":8: y coordinate is NaN",
            ),
            (
                BVH.replace("Frame Time: 0.5", "Frame Time: 0"),
                ":18: frame time 0 is not positive",
            ),
            (
                BVH.replace("HIERARCHY", "HIERARCHIE"),
                ":1: expected \"HIERARCHY\"",
            ),
            (
                "HIERARCHY\nROOT a\n{\n".to_string(),
                "missing } for joint \"a\"",
            ),
            ("HIERARCHY\n}\n".to_string(), ":2: unmatched }"),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error = read_motion(&scratch_file(&format!("bad{i}.bvh"), text)).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

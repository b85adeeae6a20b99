//! RigNet's `rig_info` text format (`*_rig.txt`, beside an OBJ), as shipped by
//! ModelsResource-RigNetv1 and Articulation-XL: one record per line,
//!
//! ```text
//! joints NAME X Y Z          a joint and its bind position (mesh space)
//! root NAME                  the root joint
//! hier PARENT CHILD          one bone of the tree
//! skin V NAME W NAME W ...   weights of vertex V (0-based, OBJ order)
//! ```
//!
//! Joints have identity orientation in the bind pose (only positions are given).

use crate::names::unique_names;
use crate::text::{check_index, parse_field, parse_finite, parse_point, read_text};
use crate::IoError;
use atlas_skin_runtime::{Skeleton, VertexWeights, NO_PARENT};
use glam::Vec3;
use std::collections::HashMap;
use std::fmt::Write;
use std::path::Path;

/// What a rig_info file holds.
///
/// - `skeleton`: the `joints` in file order, parents from `hier`.
/// - `weights`: one row per vertex of the mesh file when the file has `skin` lines
///   (vertices without a line get an empty row), `None` without any.
#[derive(Debug, Clone)]
pub struct RigInfo {
    pub skeleton: Skeleton,
    pub weights: Option<VertexWeights>,
}

/// A `skin` record before its names are resolved: line, vertex, (joint name, weight).
type SkinLine = (usize, u32, Vec<(String, f32)>);

/// Reads the rig_info file at `path` for a mesh file of `vertex_count` vertices.
///
/// # Errors
/// [`IoError::Syntax`] with the line for: an unknown record, a missing or non-numeric
/// field, a non-finite position or weight, a negative weight, a name that is no joint, a
/// joint defined twice, a child with two parents, a vertex past the mesh's end or listed
/// twice, a `skin` line without a joint or with a name but no weight; [`IoError::Invalid`] for a file without
/// joints, a `root` that has a parent, and a `hier` cycle.
pub fn read(path: &Path, vertex_count: usize) -> Result<RigInfo, IoError> {
    let text = read_text(path)?;
    let mut names: Vec<String> = Vec::new();
    let mut positions: Vec<Vec3> = Vec::new();
    let mut index: HashMap<String, u32> = HashMap::new();
    // Later records may name joints defined further down: resolve them after the pass.
    let mut roots: Vec<(usize, String)> = Vec::new();
    let mut bones: Vec<(usize, String, String)> = Vec::new();
    let mut skins: Vec<SkinLine> = Vec::new();
    for (number, raw) in text.lines().enumerate() {
        let line = number + 1;
        let mut tokens = raw.split_whitespace();
        let Some(record) = tokens.next() else {
            continue;
        };
        let mut name = |what: &str| {
            tokens
                .next()
                .map(str::to_string)
                .ok_or_else(|| IoError::syntax(path, line, format!("missing {what}")))
        };
        match record {
            "joints" => {
                let joint = name("joint name")?;
                let position = parse_point(path, line, &mut tokens)?;
                if index.insert(joint.clone(), names.len() as u32).is_some() {
                    return Err(IoError::syntax(
                        path,
                        line,
                        format!("joint {joint:?} is defined twice"),
                    ));
                }
                names.push(joint);
                positions.push(position);
            }
            "root" => roots.push((line, name("root joint name")?)),
            "hier" => {
                let parent = name("parent joint name")?;
                bones.push((line, parent, name("child joint name")?));
            }
            "skin" => {
                let vertex: i64 = parse_field(path, line, tokens.next(), "vertex index")?;
                let vertex = check_index(path, line, vertex, 0, vertex_count, "vertex")?;
                let mut row = Vec::new();
                while let Some(joint) = tokens.next() {
                    let weight = parse_finite(path, line, tokens.next(), "weight")?;
                    if weight < 0.0 {
                        return Err(IoError::syntax(
                            path,
                            line,
                            format!("weight {weight} of joint {joint:?} is negative"),
                        ));
                    }
                    row.push((joint.to_string(), weight));
                }
                if row.is_empty() {
                    return Err(IoError::syntax(
                        path,
                        line,
                        format!("the skin line of vertex {vertex} names no joint"),
                    ));
                }
                skins.push((line, vertex, row));
            }
            other => {
                return Err(IoError::syntax(
                    path,
                    line,
                    format!("unknown record {other:?} (expected joints, root, hier or skin)"),
                ))
            }
        }
    }
    if names.is_empty() {
        return Err(IoError::invalid(path, "no joints line"));
    }
    let joint = |line: usize, name: &str| {
        index.get(name).copied().ok_or_else(|| {
            IoError::syntax(path, line, format!("{name:?} is not a joint of the file"))
        })
    };
    let mut parents = vec![NO_PARENT; names.len()];
    for (line, parent, child) in &bones {
        let (p, c) = (joint(*line, parent)?, joint(*line, child)?);
        if parents[c as usize] != NO_PARENT {
            return Err(IoError::syntax(
                path,
                *line,
                format!("joint {child:?} has a second parent {parent:?}"),
            ));
        }
        parents[c as usize] = p;
    }
    for (line, root) in &roots {
        let r = joint(*line, root)?;
        if parents[r as usize] != NO_PARENT {
            return Err(IoError::invalid(
                path,
                format!("root {root:?} has a parent in the hier lines"),
            ));
        }
    }
    let skeleton = Skeleton::from_positions(names, parents, &positions).map_err(|cause| {
        IoError::Skeleton {
            path: path.to_path_buf(),
            cause,
        }
    })?;
    let weights = if skins.is_empty() {
        None
    } else {
        let mut rows: Vec<Option<Vec<(u32, f32)>>> = vec![None; vertex_count];
        for (line, vertex, row) in skins {
            let row = row
                .iter()
                .map(|(name, weight)| Ok((joint(line, name)?, *weight)))
                .collect::<Result<Vec<_>, IoError>>()?;
            if rows[vertex as usize].replace(row).is_some() {
                return Err(IoError::syntax(
                    path,
                    line,
                    format!("vertex {vertex} has a second skin line"),
                ));
            }
        }
        Some(VertexWeights::from_rows(
            rows.into_iter().map(Option::unwrap_or_default),
        ))
    };
    Ok(RigInfo { skeleton, weights })
}

/// The rig_info text of `skeleton` (bind positions) and `weights`, one `skin` line per
/// row: `vertex_numbers[v]` is the number written for row v (the mesh file's vertex index).
/// Weights of 0 are left out, and so are rows without any (the reader refuses a `skin`
/// line without a joint); numbers are written with the fewest digits that read back
/// to the same f32. Names are single tokens in the format: whitespace in a joint name
/// becomes `_` (made unique again if that collides).
pub fn to_text(skeleton: &Skeleton, weights: &VertexWeights, vertex_numbers: &[u32]) -> String {
    let names = unique_names(
        skeleton
            .names
            .iter()
            .map(|n| n.split_whitespace().collect::<Vec<_>>().join("_"))
            .collect(),
    );
    let mut text = String::new();
    for (name, p) in names.iter().zip(skeleton.bind_positions()) {
        let _ = writeln!(text, "joints {name} {} {} {}", p.x, p.y, p.z);
    }
    for j in 0..skeleton.len() {
        match skeleton.parent(j) {
            None => {
                let _ = writeln!(text, "root {}", names[j]);
            }
            Some(p) => {
                let _ = writeln!(text, "hier {} {}", names[p], names[j]);
            }
        }
    }
    for (v, &number) in vertex_numbers.iter().enumerate() {
        let mut row = weights.row(v).filter(|&(_, w)| w > 0.0).peekable();
        if row.peek().is_none() {
            continue;
        }
        let _ = write!(text, "skin {number}");
        for (joint, weight) in row {
            let _ = write!(text, " {} {weight}", names[joint as usize]);
        }
        text.push('\n');
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;

    const RIG: &str = "joints hips 0 1 0\njoints knee 0 0.5 0.1\njoints foot 0 0 0\n\
        root hips\nhier hips knee\nhier knee foot\n\
        skin 0 hips 1.0\nskin 2 knee 0.25 foot 0.75\n";

    #[test]
    fn joints_tree_and_weights_are_read() {
        let rig = read(&scratch_file("rig.txt", RIG), 3).unwrap();
        let skeleton = &rig.skeleton;
        assert_eq!(skeleton.names, ["hips", "knee", "foot"]);
        assert_eq!(skeleton.parents, [NO_PARENT, 0, 1]);
        assert_eq!(skeleton.bind_positions()[1], Vec3::new(0.0, 0.5, 0.1));
        let weights = rig.weights.unwrap();
        assert_eq!(weights.row(0).collect::<Vec<_>>(), [(0, 1.0)]);
        assert_eq!(weights.row(1).count(), 0);
        assert_eq!(weights.row(2).collect::<Vec<_>>(), [(1, 0.25), (2, 0.75)]);
    }

    #[test]
    fn written_text_reads_back() {
        let rig = read(&scratch_file("rig2.txt", RIG), 3).unwrap();
        let weights = rig.weights.unwrap();
        let text = to_text(&rig.skeleton, &weights, &[0, 1, 2]);
        let again = read(&scratch_file("rig3.txt", &text), 3).unwrap();
        assert_eq!(again.skeleton, rig.skeleton);
        assert_eq!(again.weights.unwrap(), weights);
    }

    #[test]
    fn names_with_spaces_become_single_tokens() {
        let skeleton = Skeleton::from_positions(
            vec!["Bip001 Pelvis".into(), "Bip001_Pelvis".into()],
            vec![NO_PARENT, 0],
            &[Vec3::ZERO, Vec3::Y],
        )
        .unwrap();
        let weights = VertexWeights::from_rows([vec![(1, 1.0)]]);
        let text = to_text(&skeleton, &weights, &[0]);
        assert!(
            text.contains("hier Bip001_Pelvis Bip001_Pelvis.1\n"),
            "{text}"
        );
        assert!(text.ends_with("skin 0 Bip001_Pelvis.1 1\n"), "{text}");
    }

    #[test]
    fn broken_files_name_the_line() {
        let cases = [
            ("joints a 0 0\n", ":1: missing z coordinate"),
            (
                "joints a 0 x 0\n",
                ":1: y coordinate \"x\" is not a valid number",
            ),
            (
                "joints a 0 0 0\njoints a 1 1 1\n",
                ":2: joint \"a\" is defined twice",
            ),
            (
                "joints a 0 0 0\nhier a b\n",
                ":2: \"b\" is not a joint of the file",
            ),
            (
                "joints a 0 0 0\nskin 3 a 1\n",
                ":2: vertex index 3 is out of range (3 defined)",
            ),
            ("joints a 0 0 0\nskin 0 a\n", ":2: missing weight"),
            (
                "joints a 0 0 0\nskin 0\n",
                ":2: the skin line of vertex 0 names no joint",
            ),
            ("joints a 0 0 0\nskin 0 a nan\n", ":2: weight is NaN"),
            (
                "joints a 0 0 0\nskin 0 a -1\n",
                ":2: weight -1 of joint \"a\" is negative",
            ),
            (
                "joints a 0 0 0\nskin 0 a 1\nskin 0 a 1\n",
                ":3: vertex 0 has a second",
            ),
            ("joints a 0 0 0\nbones a\n", ":2: unknown record \"bones\""),
            (
                "joints a 0 0 0\njoints b 0 0 0\nhier a b\nhier b a\n",
                "invalid skeleton",
            ),
            (
                "joints a 0 0 0\njoints b 0 0 0\nroot b\nhier a b\n",
                "root \"b\" has a parent",
            ),
            ("root a\n", "no joints line"),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error = read(&scratch_file(&format!("bad_rig{i}.txt"), text), 3).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

//! libigl TGF skeletons ("trivial graph format"): joint points, then bone edges.

use crate::text::{check_index, parse_field, parse_point, read_text};
use crate::IoError;
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use glam::Vec3;
use std::path::Path;

/// A TGF skeleton and its bones.
#[derive(Debug, Clone, PartialEq)]
pub struct TgfSkeleton {
    /// Joints named `tgf_<k>` for the k-th joint line (1-based), identity orientation,
    /// inverse bind = translation(−position).
    pub skeleton: Skeleton,
    /// #B bone edges `[a, b]` (0-based joints, parent a → child b) in file order; libigl's
    /// per-bone data (weights columns, poses) follows this order.
    pub bones: Vec<[u32; 2]>,
}

/// Reads the TGF at `path`, as libigl's `readTGF` lays it out:
///
/// ```text
/// i x y z [...]        joint lines (the index column and extra columns are ignored)
/// #
/// a b [...]            bone edges, 1-based joint numbers
/// #
/// ...                  point handles and cage edges (ignored)
/// ```
///
/// A bone a → b makes a the parent of b; roots are joints no bone points to. A joint with
/// two parents, a cycle or an edge to an unknown joint is an error.
pub fn read(path: &Path) -> Result<TgfSkeleton, IoError> {
    let text = read_text(path)?;
    let mut section = 0;
    let mut positions: Vec<Vec3> = Vec::new();
    let mut bones: Vec<[u32; 2]> = Vec::new();
    let mut parents: Vec<u32> = Vec::new();
    let mut bone_lines: Vec<usize> = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let mut tokens = raw.split_whitespace();
        let Some(first) = tokens.next() else { continue };
        if first.starts_with('#') {
            section += 1;
            continue;
        }
        match section {
            0 => {
                parse_field::<f64>(path, line, Some(first), "joint index")?;
                positions.push(parse_point(path, line, &mut tokens)?);
            }
            1 => {
                let joint = |token: Option<&str>| -> Result<u32, IoError> {
                    let number: i64 = parse_field(path, line, token, "joint number")?;
                    check_index(path, line, number, 1, positions.len(), "joint")
                };
                let a = joint(Some(first))?;
                let b = joint(tokens.next())?;
                bones.push([a, b]);
                bone_lines.push(line);
            }
            _ => break,
        }
    }
    if positions.is_empty() {
        return Err(IoError::invalid(path, "no joint lines before the first #"));
    }
    parents.resize(positions.len(), NO_PARENT);
    for (&[a, b], &line) in bones.iter().zip(&bone_lines) {
        if a == b {
            return Err(IoError::syntax(
                path,
                line,
                format!("bone from joint {} to itself", a + 1),
            ));
        }
        if parents[b as usize] != NO_PARENT {
            return Err(IoError::syntax(
                path,
                line,
                format!(
                    "joint {} already has parent {}, a second bone comes from joint {}",
                    b + 1,
                    parents[b as usize] + 1,
                    a + 1
                ),
            ));
        }
        parents[b as usize] = a;
    }
    let names = (1..=positions.len()).map(|k| format!("tgf_{k}")).collect();
    let skeleton = Skeleton::from_positions(names, parents, &positions).map_err(|cause| {
        IoError::Skeleton {
            path: path.to_path_buf(),
            cause,
        }
    })?;
    Ok(TgfSkeleton { skeleton, bones })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;

    #[test]
    fn chain_with_extra_columns_and_a_branch() {
        let text = "1 0 0 0 9 9\n2 0 1 0\n3 0 2 0\n4 1 1 0\n#\n1 2 1 0\n2 3\n2 4\n#\n1\n";
        let tgf = read(&scratch_file("chain.tgf", text)).unwrap();
        assert_eq!(tgf.skeleton.names, ["tgf_1", "tgf_2", "tgf_3", "tgf_4"]);
        assert_eq!(tgf.skeleton.parents, [NO_PARENT, 0, 1, 1]);
        assert_eq!(tgf.bones, [[0, 1], [1, 2], [1, 3]]);
        assert_eq!(tgf.skeleton.bind_positions()[3], Vec3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn broken_skeletons_are_errors() {
        let cases = [
            (
                "1 0 0 0\n2 0 1 0\n#\n1 2\n2 1\n",
                "invalid skeleton: the joint hierarchy has a cycle",
            ),
            (
                "1 0 0 0\n2 0 1 0\n3 0 2 0\n#\n1 3\n2 3\n",
                ":6: joint 3 already has parent 1, a second bone comes from joint 2",
            ),
            ("1 0 0 0\n2 0 1 0\n3 0 2 0\n#\n1 2\n2 3\n3 1\n", "cycle"),
            (
                "1 0 0 0\n#\n1 2\n",
                ":3: joint index 2 is out of range (1 defined)",
            ),
            ("1 0 0 0\n#\n1 1\n", ":3: bone from joint 1 to itself"),
            ("1 0 x 0\n", ":1: y coordinate \"x\""),
            ("#\n", "no joint lines"),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error = read(&scratch_file(&format!("bad{i}.tgf"), text)).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}

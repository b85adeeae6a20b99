//! Rigs as found: a hierarchy for a skeleton whose joints carry no parent links among
//! themselves (a WebXR hand stores its 25 joints as siblings) or that has several roots
//! (upper legs stored as roots). The inferred tree is what the method uses; the input's
//! skeleton is left as it is.
//!
//! 1. Names, when no joint has a parent: the WebXR hand layout (`wrist`, then per digit
//!    `*-metacarpal`, `*-phalanx-proximal`, `*-phalanx-intermediate`, `*-phalanx-distal`,
//!    `*-tip`: each joint's parent is the previous of these its digit has, else the wrist),
//!    and numbered chains (`Bone`, `Bone.001`, `Bone.002`, or `_` before the number: each
//!    number's parent is the one before it).
//! 2. Positions, for the trees names did not join: Prim's minimum spanning tree (Prim 1957)
//!    over the trees, grown from the tree holding the joint nearest the mesh's centroid:
//!    repeatedly, the tree whose root is nearest (Euclidean, bind positions) to a joint
//!    already joined is joined there, its root becoming that joint's child, so bones point
//!    away from the body's centre and links stored in the file are kept. A root named for
//!    one side (`Left`/`Right`, `.L`/`.R`, `_l`/`_r`) is not joined to a joint named for the
//!    other when any other joint is available.

use super::placement::listed;
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use glam::DVec3;

/// How a skeleton's hierarchy was completed.
#[derive(Debug, Clone, PartialEq)]
pub struct Inferred {
    /// #J parent of every joint in the tree the method uses (one root).
    pub parents: Vec<u32>,
    /// Links made from names, as (child, parent) joint indices.
    pub by_name: Vec<(u32, u32)>,
    /// Links made from positions, as (child, parent) joint indices.
    pub by_position: Vec<(u32, u32)>,
    /// Which naming conventions gave links (`WebXR hand`, `numbered chains`).
    pub conventions: Vec<&'static str>,
}

impl Inferred {
    /// The warning the report gives: what was inferred, with the first links by name.
    pub fn warning(&self, skeleton: &Skeleton, had_links: bool) -> String {
        let name = |j: u32| skeleton.names[j as usize].as_str();
        let list = |links: &[(u32, u32)]| {
            listed(
                links
                    .iter()
                    .map(|&(c, p)| format!("{} → {}", name(c), name(p)))
                    .collect::<Vec<_>>()
                    .into_iter(),
            )
        };
        let mut parts = Vec::new();
        if !self.by_name.is_empty() {
            parts.push(format!(
                "{} link(s) from names ({}): {}",
                self.by_name.len(),
                self.conventions.join(", "),
                list(&self.by_name)
            ));
        }
        if !self.by_position.is_empty() {
            parts.push(format!(
                "{} link(s) from positions (each root to the nearest joint): {}",
                self.by_position.len(),
                list(&self.by_position)
            ));
        }
        let what = if had_links {
            format!(
                "the skeleton has {} roots",
                self.by_name.len() + self.by_position.len() + 1
            )
        } else {
            format!(
                "the skeleton's {} joints have no parent links among themselves",
                skeleton.len()
            )
        };
        format!(
            "{what}: hierarchy inferred for the method (the file's nodes are unchanged): {}",
            parts.join("; ")
        )
    }
}

/// The WebXR hand chain of a digit, proximal to distal (WebXR Hand Input, "Skeleton
/// joints").
const WEBXR_CHAIN: [&str; 5] = [
    "-metacarpal",
    "-phalanx-proximal",
    "-phalanx-intermediate",
    "-phalanx-distal",
    "-tip",
];

/// A tree for `skeleton` when it has more than one root; `None` when it has one.
///
/// - `centroid`: the mesh's vertex centroid (where the positional tree starts).
pub fn infer_hierarchy(skeleton: &Skeleton, centroid: DVec3) -> Option<Inferred> {
    let n = skeleton.len();
    let mut parents = skeleton.parents.clone();
    if parents.iter().filter(|&&p| p == NO_PARENT).count() <= 1 {
        return None;
    }
    let mut by_name = Vec::new();
    let mut conventions = Vec::new();
    if parents.iter().all(|&p| p == NO_PARENT) {
        for (rule, name) in [
            (
                webxr_parents as fn(&[String]) -> Vec<Option<u32>>,
                "WebXR hand",
            ),
            (numbered_parents, "numbered chains"),
        ] {
            let found = rule(&skeleton.names);
            let before = by_name.len();
            for (j, parent) in found.into_iter().enumerate() {
                if let (Some(p), true) = (parent, parents[j] == NO_PARENT) {
                    parents[j] = p;
                    by_name.push((j as u32, p));
                }
            }
            if by_name.len() > before {
                conventions.push(name);
            }
        }
        if has_cycle(&parents) {
            // Names that contradict each other: positions only.
            parents.fill(NO_PARENT);
            by_name.clear();
            conventions.clear();
        }
    }
    let positions: Vec<DVec3> = skeleton
        .bind_positions()
        .iter()
        .map(|p| p.as_dvec3())
        .collect();
    let sides: Vec<Side> = skeleton.names.iter().map(|n| side_of(n)).collect();
    let by_position = join_trees(&mut parents, &positions, &sides, centroid);
    debug_assert_eq!(parents.len(), n);
    Some(Inferred {
        parents,
        by_name,
        by_position,
        conventions,
    })
}

/// Parents from the WebXR hand names (see the module documentation); `None` for joints the
/// layout does not name and for the wrist.
fn webxr_parents(names: &[String]) -> Vec<Option<u32>> {
    let lower: Vec<String> = names.iter().map(|n| n.to_lowercase()).collect();
    let wrist = lower.iter().position(|n| n.ends_with("wrist"));
    let link = |name: &str| {
        WEBXR_CHAIN.iter().enumerate().find_map(|(rank, suffix)| {
            name.strip_suffix(suffix)
                .filter(|digit| !digit.is_empty())
                .map(|digit| (digit.to_string(), rank))
        })
    };
    let links: Vec<Option<(String, usize)>> = lower.iter().map(|n| link(n)).collect();
    links
        .iter()
        .map(|own| {
            let (digit, rank) = own.as_ref()?;
            let previous = links
                .iter()
                .enumerate()
                .filter_map(|(k, other)| {
                    let (d, r) = other.as_ref()?;
                    (d == digit && r < rank).then_some((r, k))
                })
                .max();
            previous.map(|(_, k)| k).or(wrist).map(|k| k as u32)
        })
        .collect()
}

/// Parents from numbered chains: `X.k` or `X_k` (k ≥ 1, digits) has the parent `X.(k−1)`
/// written with as many digits (`X_(k−1)`), or `X` itself when k − 1 = 0 and no `X.0…`
/// exists.
fn numbered_parents(names: &[String]) -> Vec<Option<u32>> {
    let index = |name: &str| names.iter().position(|n| n == name).map(|k| k as u32);
    names
        .iter()
        .map(|name| {
            let cut = name.rfind(['.', '_'])?;
            let (stem, digits) = (&name[..cut], &name[cut + 1..]);
            let separator = &name[cut..=cut];
            let number: u64 = digits
                .chars()
                .all(|c| c.is_ascii_digit())
                .then(|| digits.parse().ok())??;
            if stem.is_empty() || number == 0 {
                return None;
            }
            let previous = format!(
                "{stem}{separator}{:0width$}",
                number - 1,
                width = digits.len()
            );
            index(&previous).or_else(|| (number == 1).then(|| index(stem)).flatten())
        })
        .collect()
}

/// Whether following parents from some joint comes back to it.
fn has_cycle(parents: &[u32]) -> bool {
    (0..parents.len()).any(|start| {
        let mut j = start;
        for _ in 0..parents.len() {
            match parents[j] {
                NO_PARENT => return false,
                p => j = p as usize,
            }
        }
        true
    })
}

/// The side a joint's name gives it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    Left,
    Right,
    None,
}

/// `Left`/`Right` anywhere in the name, or a token `l`/`r` between separators
/// (`hand.L`, `thigh_r`, `Bip01 L Thigh`).
fn side_of(name: &str) -> Side {
    let lower = name.to_lowercase();
    let token = |t: &str| {
        lower
            .split(|c: char| !c.is_ascii_alphanumeric())
            .any(|part| part == t)
    };
    match (
        lower.contains("left") || token("l"),
        lower.contains("right") || token("r"),
    ) {
        (true, false) => Side::Left,
        (false, true) => Side::Right,
        _ => Side::None,
    }
}

/// Joins the trees of the forest `parents` (see the module documentation, step 2) and
/// returns the links made, (child, parent).
fn join_trees(
    parents: &mut [u32],
    positions: &[DVec3],
    sides: &[Side],
    centroid: DVec3,
) -> Vec<(u32, u32)> {
    let n = parents.len();
    let root_of = |parents: &[u32], mut j: usize| {
        while parents[j] != NO_PARENT {
            j = parents[j] as usize;
        }
        j
    };
    let start = (0..n)
        .min_by(|&a, &b| {
            positions[a]
                .distance_squared(centroid)
                .total_cmp(&positions[b].distance_squared(centroid))
        })
        .unwrap_or(0);
    let main = root_of(parents, start);
    let mut joined: Vec<bool> = (0..n).map(|j| root_of(parents, j) == main).collect();
    let mut links = Vec::new();
    loop {
        let opposite = |a: usize, b: usize| {
            matches!(
                (sides[a], sides[b]),
                (Side::Left, Side::Right) | (Side::Right, Side::Left)
            )
        };
        let best = |allow_opposite: bool| {
            (0..n)
                .filter(|&r| parents[r] == NO_PARENT && !joined[r])
                .flat_map(|r| (0..n).filter(|&a| joined[a]).map(move |a| (r, a)))
                .filter(|&(r, a)| allow_opposite || !opposite(r, a))
                .min_by(|&(r, a), &(s, b)| {
                    positions[r]
                        .distance_squared(positions[a])
                        .total_cmp(&positions[s].distance_squared(positions[b]))
                })
        };
        let Some((root, anchor)) = best(false).or_else(|| best(true)) else {
            break;
        };
        parents[root] = anchor as u32;
        links.push((root as u32, anchor as u32));
        for (j, joined) in joined.iter_mut().enumerate() {
            *joined = root_of(parents, j) == main;
        }
    }
    links
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn skeleton(names: &[&str], parents: &[u32], positions: &[[f32; 3]]) -> Skeleton {
        let positions: Vec<Vec3> = positions.iter().map(|&p| Vec3::from_array(p)).collect();
        Skeleton::from_positions(
            names.iter().map(|s| s.to_string()).collect(),
            parents.to_vec(),
            &positions,
        )
        .unwrap()
    }

    #[test]
    fn webxr_names_give_the_hand_tree_and_skip_missing_joints() {
        let names = [
            "thumb-phalanx-proximal",
            "wrist",
            "index-finger-phalanx-distal",
            "thumb-metacarpal",
            "index-finger-phalanx-proximal",
            "index-finger-tip",
        ];
        let far = [[0.0, 0.0, 9.0]; 6];
        let inferred =
            infer_hierarchy(&skeleton(&names, &[NO_PARENT; 6], &far), DVec3::ZERO).unwrap();
        assert_eq!(inferred.parents, [3, NO_PARENT, 4, 1, 1, 2]);
        assert_eq!(inferred.conventions, ["WebXR hand"]);
        assert!(inferred.by_position.is_empty());
    }

    #[test]
    fn numbered_chains_link_each_number_to_the_one_before() {
        let names = ["Bone", "Bone.002", "Bone.001", "tail_01", "tail_02"];
        let parents = numbered_parents(&names.map(String::from));
        assert_eq!(parents, [None, Some(2), Some(0), None, Some(3)]);
    }

    #[test]
    fn sides_come_from_words_and_single_letter_tokens() {
        for (name, side) in [
            ("LeftUpLeg", Side::Left),
            ("mixamorig:RightArm", Side::Right),
            ("hand.L", Side::Left),
            ("thigh_r", Side::Right),
            ("Bip01 L Thigh", Side::Left),
            ("spine", Side::None),
        ] {
            assert_eq!(side_of(name), side, "{name}");
        }
    }

    /// Upper legs stored as roots join the hips, not each other, and their own children
    /// stay theirs; the positional tree of unlinked joints grows from the centre outward.
    #[test]
    fn roots_join_the_nearest_joint_of_the_main_tree() {
        let names = ["hips", "spine", "thigh_l", "knee_l", "thigh_r", "knee_r"];
        let parents = [NO_PARENT, 0, NO_PARENT, 2, NO_PARENT, 4];
        let positions = [
            [0.0, 1.0, 0.0],
            [0.0, 1.3, 0.0],
            [0.1, 0.95, 0.0],
            [0.1, 0.5, 0.0],
            [-0.1, 0.95, 0.0],
            [-0.1, 0.5, 0.0],
        ];
        let rig = skeleton(&names, &parents, &positions);
        let inferred = infer_hierarchy(&rig, DVec3::new(0.0, 1.0, 0.0)).unwrap();
        assert_eq!(inferred.parents, [NO_PARENT, 0, 0, 2, 0, 4]);
        assert_eq!(inferred.by_position, [(2, 0), (4, 0)]);
        assert!(inferred.warning(&rig, true).contains("thigh_l → hips"));

        let loose = skeleton(&names, &[NO_PARENT; 6], &positions);
        let inferred = infer_hierarchy(&loose, DVec3::new(0.0, 1.0, 0.0)).unwrap();
        assert_eq!(inferred.parents, [NO_PARENT, 0, 0, 2, 0, 4]);
        assert!(inferred
            .warning(&loose, false)
            .starts_with("the skeleton's 6 joints have no parent links"));
        assert_eq!(
            infer_hierarchy(
                &skeleton(&names[..2], &[NO_PARENT, 0], &positions[..2]),
                DVec3::ZERO
            ),
            None
        );
    }
}

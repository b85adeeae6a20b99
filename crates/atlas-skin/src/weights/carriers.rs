//! The part of the skeleton that carries an attached piece (step 5, rule 2 of
//! [`super::pieces`]).
//!
//! An attached piece takes the weights of the body surface nearest to each of its
//! vertices. Where that surface belongs to two parts of the skeleton that are not joined
//! under the piece (a knee pad whose edge reaches past the gap between the knees onto the
//! other knee, a hat brim that reaches out over the hands in the bind pose), the piece
//! moves with both and tears apart when they move apart.
//!
//! The joints that *carry* the piece are those with more than τ = [`CARRYING_WEIGHT`] of
//! the weight of one of its rows. They are joined when one is the other's parent; the
//! classes of joined joints are the parts of the skeleton that carry the piece, and its
//! mass on a part is the sum of its rows' weights on the part's joints. When more than one
//! part carries it, only the part of the largest mass keeps its weights: every row keeps
//! its weights on that part's joints, renormalised, and a row left with none takes the row
//! of the nearest vertex that kept some (along the piece's edges, like the rows carried
//! from the contact). A piece carried by one connected part (a belt over the hips and both
//! thighs, joined through the hips) is unchanged.
//!
//! A limit: two carrying joints are joined only through carrying joints. A vest attached
//! over the chest whose armholes take more than τ of the upper arms while the clavicles
//! between carry less would lose the upper arms' weights at the armholes and move with
//! the spine there (not seen on the benchmark, where the rule turned 2 characters worse:
//! docs/pieces.md).
//!
//! Measured on the 65 bench characters, averages over the 65 (docs/pieces.md, "One
//! carrier per attached piece"): τ from 0.05 to 0.5 all lower the average deform max
//! (.1545 → .1460–.1477) and turn 8–9 characters better on the mean against 1–3 worse.

use atlas_skin_runtime::Skeleton;

/// τ: a joint carries a piece where it has more than this share of a row's weight (chosen
/// in the middle of the range measured, docs/pieces.md).
pub const CARRYING_WEIGHT: f64 = 0.25;

/// A row of (joint, weight) pairs.
type Row = Vec<(u32, f64)>;

/// The rows of a piece on the one part of `skeleton` that carries most of it (module
/// documentation), with whether each row kept some weight; `None` when one part (or none)
/// carries the whole piece.
pub fn on_one_carrier(skeleton: &Skeleton, rows: &[Row]) -> Option<(Vec<Row>, Vec<bool>)> {
    let mut carries = vec![false; skeleton.len()];
    for &(j, w) in rows.iter().flatten() {
        if w > CARRYING_WEIGHT {
            carries[j as usize] = true;
        }
    }
    // The part of each carrying joint: its topmost ancestor reached through carrying
    // joints (parents first, so a parent's part is known before its children's).
    let mut part: Vec<Option<usize>> = vec![None; skeleton.len()];
    for j in skeleton.topological_order() {
        if carries[j] {
            part[j] = Some(skeleton.parent(j).and_then(|p| part[p]).unwrap_or(j));
        }
    }
    let mut mass = vec![0.0; skeleton.len()];
    for &(j, w) in rows.iter().flatten() {
        if let Some(top) = part[j as usize] {
            mass[top] += w;
        }
    }
    let parts: Vec<usize> = (0..skeleton.len()).filter(|&j| mass[j] > 0.0).collect();
    if parts.len() < 2 {
        return None;
    }
    // The first of equal masses: the joint of the smallest index.
    let kept = parts
        .iter()
        .copied()
        .reduce(|best, j| if mass[j] > mass[best] { j } else { best })?;
    let on_kept = |j: u32| part[j as usize] == Some(kept);
    let mut keeps = Vec::with_capacity(rows.len());
    let rows = rows
        .iter()
        .map(|row| {
            let total: f64 = row.iter().filter(|x| on_kept(x.0)).map(|x| x.1).sum();
            keeps.push(total > 0.0);
            row.iter()
                .filter(|x| total > 0.0 && on_kept(x.0))
                .map(|&(j, w)| (j, w / total))
                .collect()
        })
        .collect();
    Some((rows, keeps))
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    /// hips (0) with two legs: thigh_l (1) → knee_l (2), thigh_r (3) → knee_r (4).
    fn legs() -> Skeleton {
        let names = ["hips", "thigh_l", "knee_l", "thigh_r", "knee_r"];
        let positions = [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.1, 0.9, 0.0),
            Vec3::new(0.1, 0.5, 0.0),
            Vec3::new(-0.1, 0.9, 0.0),
            Vec3::new(-0.1, 0.5, 0.0),
        ];
        Skeleton::from_positions(
            names.map(String::from).to_vec(),
            vec![NO_PARENT, 0, 1, 0, 3],
            &positions,
        )
        .expect("a valid skeleton")
    }

    #[test]
    fn a_pad_on_two_knees_moves_with_the_knee_under_most_of_it() {
        let skeleton = legs();
        // Three rows on the right knee and thigh, one on the left knee, one blending both
        // knees.
        let rows: Vec<Row> = vec![
            vec![(4, 1.0)],
            vec![(4, 0.6), (3, 0.4)],
            vec![(3, 1.0)],
            vec![(2, 1.0)],
            vec![(2, 0.5), (4, 0.5)],
        ];
        let (kept, keeps) = on_one_carrier(&skeleton, &rows).expect("two parts carry it");
        assert_eq!(keeps, [true, true, true, false, true]);
        assert_eq!(kept[0], vec![(4, 1.0)]);
        assert_eq!(kept[1], vec![(4, 0.6), (3, 0.4)]);
        assert!(kept[3].is_empty());
        assert_eq!(kept[4], vec![(4, 1.0)]);
    }

    #[test]
    fn a_piece_on_joints_joined_through_their_parent_is_one_carrier() {
        let skeleton = legs();
        // A skirt over both thighs and the hips between them.
        let rows: Vec<Row> = vec![
            vec![(1, 1.0)],
            vec![(0, 0.7), (1, 0.3)],
            vec![(0, 1.0)],
            vec![(3, 0.6), (0, 0.4)],
            vec![(4, 0.9), (2, 0.1)],
        ];
        assert!(on_one_carrier(&skeleton, &rows).is_none());
        // Weights at or under τ do not carry: the hips' tails do not join the thighs, but
        // neither do they make a part of their own.
        let tails: Vec<Row> = vec![vec![(1, 0.8), (0, 0.2)], vec![(1, 1.0)]];
        assert!(on_one_carrier(&skeleton, &tails).is_none());
    }
}

//! The conflict rule between cuts (§3.1; the paper leaves crossing cuts open, METHOD.md
//! "Stage 1"): which joint keeps a closed cut and which falls back to a soft boundary.
//!
//! Conflict rule. Two curves conflict when they cross or touch: they run through a common
//! vertex, or two of their chords in one face interleave or end within `snap_fraction` of
//! each other along the face's boundary. Curves that merely pass through the same faces
//! (parallel chords of a coarse mesh's large triangles) do not conflict. Joints are placed
//! in increasing order of their best perimeter, so the small cross-sections of fingers,
//! toes and distal limbs are placed before the palm, leg-root, neck and torso planes that
//! would cross them; branching joints on the mirror plane (a spine joint where the legs or
//! the arms branch) come after all others, whatever their perimeter. A joint whose best
//! curve conflicts with an already placed one tries its next-best closed sections (the
//! other sampled planes, by increasing perimeter); when none fits, it gets a soft boundary:
//! its plane restricted to the region that holds it (METHOD.md, "extensions"), which the
//! weights stage blends across; so does a joint that [`crate::cuts::joint_roles`] allows no cut.
//! Mirror twins are the exception to first come, first served: a joint keeps its cut only
//! when its mirror twin ([`crate::cuts::joint_roles::mirror_twins`]) gets one too. When a
//! twin ends without a cut (every section crosses a placed cut, such as the other thigh's
//! in legs modelled as one skirt-like piece, or no clean closed section exists around it),
//! the joint is denied its cut and the others are placed again without it, until no twin
//! is left with a cut whose twin has none: the two sides of a symmetric character bend
//! alike (docs/measurements.md, "Mirror twins").
//! A joint is left without a boundary only for the reasons of [`crate::cuts::joint_roles`], or
//! when no region holds it (an empty surface); the report says which.

use super::joint_roles::{JointFrame, JointPlan};
use super::plane_search::{CutCandidate, CutSearch};
use super::plane_section::{Chord, CrossingPoint, SectionCurve};
use crate::ablation::{Rule, RulesOff};
use crate::mesh::{SurfaceMesh, Topology};
use atlas_skin_runtime::Skeleton;
use std::collections::HashMap;

/// What the search of one joint found among the placed cuts.
#[derive(Debug, Clone, PartialEq)]
enum Search {
    /// The index of the first candidate that conflicts with no placed cut.
    Accepted(usize),
    /// Every candidate conflicts with a placed cut: the joints of those cuts.
    Blocked(Vec<u32>),
    /// Not placed: this mirror twin gets no cut (module documentation).
    TwinWithoutCut(u32),
}

/// Where the conflict rule put a joint's boundary.
#[derive(Debug, Clone, PartialEq)]
pub enum Placement {
    /// Index of the placed candidate.
    Cut {
        candidate: usize,
        frame: JointFrame,
    },
    Soft {
        reason: String,
        frame: JointFrame,
    },
    Skip(String),
}

/// The conflict rule of the module doc. Returns one placement per joint.
pub fn place_cuts(
    mesh: &SurfaceMesh,
    topology: &Topology,
    skeleton: &Skeleton,
    plans: &[JointPlan],
    searches: &[CutSearch],
    gap: f64,
    rules_off: &RulesOff,
) -> Vec<Placement> {
    let candidates: Vec<&[CutCandidate]> = searches.iter().map(|s| &s.candidates[..]).collect();
    let order = placement_order(plans, &candidates);
    let twins_alike = rules_off.on(Rule::MirrorTwins);
    // Joints denied a cut because their mirror twin gets none. The set only grows, so the
    // passes end; each pass places the others again without the denied joints' cuts.
    let mut denied: Vec<Option<u32>> = vec![None; plans.len()];
    let placed = loop {
        let placed = place_in_order(mesh, topology, &order, &candidates, &denied, gap);
        let mut grew = false;
        for (j, plan) in plans.iter().enumerate().filter(|_| twins_alike) {
            let Some(twin) = mirror_twin(plan) else {
                continue;
            };
            let without_cut = !matches!(placed[j], Some(Search::Accepted(_)));
            if without_cut && matches!(placed[twin as usize], Some(Search::Accepted(_))) {
                denied[twin as usize] = Some(j as u32);
                grew = true;
            }
        }
        if !grew {
            break placed;
        }
    };
    plans
        .iter()
        .zip(placed)
        .zip(searches)
        .map(|((plan, placed), search)| placement_of(plan, placed, search, skeleton))
        .collect()
}

/// One pass of the conflict rule: the joints of `order` in turn take their first candidate
/// that conflicts with no cut placed before, except the `denied` ones (their twin's index).
/// `None` for the joints that are not in `order`.
fn place_in_order(
    mesh: &SurfaceMesh,
    topology: &Topology,
    order: &[usize],
    candidates: &[&[CutCandidate]],
    denied: &[Option<u32>],
    gap: f64,
) -> Vec<Option<Search>> {
    let mut board = Board::default();
    let mut placed: Vec<Option<Search>> = vec![None; candidates.len()];
    for &j in order {
        if let Some(twin) = denied[j] {
            placed[j] = Some(Search::TwinWithoutCut(twin));
            continue;
        }
        let mut blockers: Vec<u32> = Vec::new();
        let mut accepted = None;
        for (k, candidate) in candidates[j].iter().enumerate() {
            let chords: Vec<Chord> = candidate.curve.chords(mesh, topology).collect();
            let vertices = curve_vertices(&candidate.curve);
            match board.fits(&chords, &vertices, gap) {
                Ok(()) => {
                    board.place(j as u32, chords, vertices);
                    accepted = Some(k);
                    break;
                }
                Err(others) => blockers.extend(others),
            }
        }
        placed[j] = Some(match accepted {
            Some(k) => Search::Accepted(k),
            None => Search::Blocked(blockers),
        });
    }
    placed
}

/// The cuts placed so far: their chords by face and the vertices they run through.
#[derive(Default)]
struct Board {
    chords: HashMap<u32, Vec<(u32, Chord)>>,
    vertex_owner: HashMap<u32, u32>,
}

impl Board {
    /// `Ok` when a curve with these `chords` through these `vertices` conflicts with no
    /// placed cut, else the owners of those it meets.
    fn fits(&self, chords: &[Chord], vertices: &[u32], gap: f64) -> Result<(), Vec<u32>> {
        let mut blockers: Vec<u32> = vertices
            .iter()
            .filter_map(|v| self.vertex_owner.get(v).copied())
            .collect();
        for chord in chords {
            if let Some(others) = self.chords.get(&chord.face) {
                blockers.extend(
                    others
                        .iter()
                        .filter(|(_, other)| chord.crosses_or_touches(other, gap))
                        .map(|(owner, _)| *owner),
                );
            }
        }
        if blockers.is_empty() {
            Ok(())
        } else {
            Err(blockers)
        }
    }

    fn place(&mut self, joint: u32, chords: Vec<Chord>, vertices: Vec<u32>) {
        for chord in chords {
            self.chords
                .entry(chord.face)
                .or_default()
                .push((joint, chord));
        }
        self.vertex_owner
            .extend(vertices.into_iter().map(|v| (v, joint)));
    }
}

/// The joint's mirror twin, when its plan searches a cut.
fn mirror_twin(plan: &JointPlan) -> Option<u32> {
    match plan {
        JointPlan::Boundary(frame) => frame.mirror_twin,
        _ => None,
    }
}

/// The joints that search a cut, in the order of the module documentation: by increasing
/// best perimeter, branching joints on the mirror plane after the others.
fn placement_order(plans: &[JointPlan], candidates: &[&[CutCandidate]]) -> Vec<usize> {
    let group = |j: usize| {
        u8::from(matches!(&plans[j], JointPlan::Boundary(frame) if frame.on_mirror_plane))
    };
    let mut order: Vec<usize> = (0..plans.len())
        .filter(|&j| matches!(plans[j], JointPlan::Boundary(_)) && !candidates[j].is_empty())
        .collect();
    order.sort_by(|&a, &b| {
        group(a).cmp(&group(b)).then(
            candidates[a][0]
                .perimeter
                .total_cmp(&candidates[b][0].perimeter),
        )
    });
    order
}

/// The placement of one joint: its plan, and for a joint that searched a cut, the accepted
/// candidate or the joints whose cuts blocked every candidate (`None`: it had none).
fn placement_of(
    plan: &JointPlan,
    placed: Option<Search>,
    search: &CutSearch,
    skeleton: &Skeleton,
) -> Placement {
    let frame = match plan {
        JointPlan::Skip(reason) | JointPlan::Exclude(reason) => {
            return Placement::Skip(reason.clone())
        }
        JointPlan::Soft(frame, reason) => {
            return Placement::Soft {
                reason: reason.clone(),
                frame: *frame,
            }
        }
        JointPlan::Boundary(frame) => *frame,
    };
    let reason = match placed {
        Some(Search::Accepted(candidate)) => return Placement::Cut { candidate, frame },
        Some(Search::TwinWithoutCut(twin)) => format!(
            "its mirror twin {} gets no cut: neither does it, so that the two sides bend alike",
            skeleton.names[twin as usize]
        ),
        Some(Search::Blocked(mut blockers)) => {
            blockers.sort_unstable();
            blockers.dedup();
            let names: Vec<&str> = blockers
                .iter()
                .map(|&b| skeleton.names[b as usize].as_str())
                .collect();
            format!(
                "every closed section found crosses or touches the cut of {}",
                names.join(", ")
            )
        }
        None => match search.through_joint {
            Some((p, c)) => format!(
                "the bone {} -> {} runs through the joint (or from it) and crosses every \
                 plane searched there: every closed section around the joint would enclose it",
                skeleton.names[p], skeleton.names[c]
            ),
            None if search.enclosing_other_bones > 0 => format!(
                "each of the {} closed sections around the joint also encloses another bone \
                 (a plane across a palm, a foot or the torso)",
                search.enclosing_other_bones
            ),
            None => "no closed cross-section around the joint near it (open surface, \
                     joint outside, or a section reaching far from the joint)"
                .into(),
        },
    };
    Placement::Soft { reason, frame }
}

/// The surface vertices a curve runs through.
fn curve_vertices(curve: &SectionCurve) -> Vec<u32> {
    let mut vertices: Vec<u32> = curve
        .crossings
        .iter()
        .filter_map(|c| match c.point {
            CrossingPoint::Vertex(v) => Some(v),
            CrossingPoint::Interior(_) => None,
        })
        .collect();
    vertices.sort_unstable();
    vertices.dedup();
    vertices
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cuts::plane_section::{closed_length, Plane};
    use atlas_skin_runtime::NO_PARENT;
    use glam::DVec3;

    fn boundary() -> JointPlan {
        JointPlan::Boundary(JointFrame {
            position: DVec3::ZERO,
            upper: DVec3::Y,
            lower: DVec3::Y,
            bone_length: 1.0,
            surface_distance: 0.1,
            on_mirror_plane: false,
            mirror_twin: None,
            leaf_part_past: false,
        })
    }

    /// Mirror twins (joints 1 and 2 of a tube along +Y) whose only sections cross each
    /// other inside the tube: two planes through its middle tilted ±30° about +Z; without
    /// `right_section` the second joint has none.
    fn placements_of_crossing_twins(twins: bool, right_section: bool) -> Vec<Placement> {
        use crate::cuts::plane_section::{vertex_snap_distances, DomainScratch, SectionDomain};
        use crate::fixtures::shapes::capsule_chain;
        let ends = [DVec3::ZERO, DVec3::Y];
        let (mesh, _) = capsule_chain(&ends, &[], 0.2, 16, 8);
        let topology = Topology::new(&mesh);
        let snap = vertex_snap_distances(&mesh, &topology, 0.01);
        let faces: Vec<u32> = (0..mesh.triangle_count() as u32).collect();
        let mut domain = SectionDomain::new(
            &mesh,
            &topology,
            &snap,
            faces,
            &mut DomainScratch::default(),
        );
        let middle = 0.5 * DVec3::Y;
        let mut search = |tilt: f64| {
            let plane = Plane {
                point: middle,
                normal: DVec3::new(tilt.sin(), tilt.cos(), 0.0),
            };
            let curve = domain.closed_sections(&plane).remove(0);
            let points = curve.positions(&mesh, &topology);
            CutSearch {
                candidates: vec![CutCandidate {
                    plane,
                    perimeter: closed_length(&points),
                    curve,
                    points,
                }],
                ..CutSearch::default()
            }
        };
        let left = search(30f64.to_radians());
        let right = search(-30f64.to_radians());
        let searches = [
            CutSearch::default(),
            left,
            if right_section {
                right
            } else {
                CutSearch::default()
            },
        ];
        let skeleton = Skeleton::from_positions(
            vec!["root".into(), "left".into(), "right".into()],
            vec![NO_PARENT, 0, 0],
            &[glam::Vec3::ZERO, middle.as_vec3(), middle.as_vec3()],
        )
        .expect("valid skeleton");
        let twin_of = |twin: u32| {
            let JointPlan::Boundary(frame) = boundary() else {
                unreachable!()
            };
            JointPlan::Boundary(JointFrame {
                mirror_twin: twins.then_some(twin),
                leaf_part_past: false,
                ..frame
            })
        };
        let plans = [JointPlan::Skip("root".into()), twin_of(2), twin_of(1)];
        place_cuts(
            &mesh,
            &topology,
            &skeleton,
            &plans,
            &searches,
            0.01,
            &RulesOff::default(),
        )
    }

    #[test]
    fn a_joint_keeps_its_cut_only_when_its_mirror_twin_gets_one() {
        let soft_reason = |p: &Placement| match p {
            Placement::Soft { reason, .. } => reason.clone(),
            other => panic!("expected a soft boundary, got {other:?}"),
        };
        let twins = placements_of_crossing_twins(true, true);
        assert!(soft_reason(&twins[1]).contains("mirror twin right"));
        assert!(soft_reason(&twins[2]).contains("mirror twin left"));
        // A twin without any section: the other is denied its cut.
        let lone = placements_of_crossing_twins(true, false);
        assert!(soft_reason(&lone[1]).contains("mirror twin right gets no cut"));
        assert!(soft_reason(&lone[2]).contains("no closed cross-section"));
        // Not twins: the first placed keeps its cut and blocks the other.
        let strangers = placements_of_crossing_twins(false, true);
        let cuts = strangers
            .iter()
            .filter(|p| matches!(p, Placement::Cut { .. }))
            .count();
        assert_eq!(cuts, 1);
        assert!(strangers[1..]
            .iter()
            .any(|p| matches!(p, Placement::Soft { reason, .. } if reason.contains("crosses"))));
    }
}

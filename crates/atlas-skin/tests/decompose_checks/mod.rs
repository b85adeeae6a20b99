//! Invariants every decomposition must satisfy, shared by the decomposition tests.

use atlas_skin::{BoundaryKind, Decomposition, JointStatus, MeshStats};
use std::collections::HashSet;

/// Checks the partition and the cuts; on a closed genus-0 surface also k − 1 cuts → k
/// regions. Returns the number of cuts.
pub fn check_decomposition(decomposition: &Decomposition, genus_zero: bool) -> usize {
    let d = decomposition;
    assert_eq!(d.face_region.len(), d.surface.triangle_count());
    assert!(d
        .face_region
        .iter()
        .all(|&r| (r as usize) < d.regions.len()));
    assert_eq!(
        d.regions.iter().map(|r| r.faces).sum::<usize>(),
        d.surface.triangle_count(),
        "every face is in exactly one region"
    );
    let cuts = d
        .joints
        .iter()
        .filter(|j| j.status == JointStatus::Cut)
        .count();
    // No two curves cross or touch: their loops share no vertex.
    let mut seen = HashSet::new();
    for boundary in &d.boundaries {
        match &boundary.kind {
            BoundaryKind::Cut { curve } => {
                assert!(curve.len() >= 3);
                assert_ne!(boundary.parent_region, boundary.child_region);
                for &v in curve {
                    assert!(seen.insert(v), "vertex {v} is on two cut curves");
                }
            }
            BoundaryKind::Soft => assert_eq!(boundary.parent_region, boundary.child_region),
        }
        assert!(boundary.perimeter.is_finite() && boundary.diameter.is_finite());
        assert!((boundary.normal.length() - 1.0).abs() < 1e-9);
    }
    for decision in &d.joints {
        match &decision.status {
            JointStatus::Cut => assert!(decision.boundary.is_some()),
            JointStatus::Soft(reason) | JointStatus::Skipped(reason) => {
                assert!(!reason.is_empty(), "{} has no reason", decision.name)
            }
        }
    }
    if genus_zero {
        let stats = MeshStats::new(&d.surface, &d.topology);
        assert!(stats.closed, "the split surface stays closed: {stats:?}");
        assert_eq!(stats.genus, Some(0));
        assert_eq!(d.regions.len(), cuts + 1, "k − 1 cuts give k regions");
    }
    cuts
}

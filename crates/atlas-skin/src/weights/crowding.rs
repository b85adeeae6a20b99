//! Vertices crowded by soft boundaries: at most [`MOST_SOFT_SIDES`] soft joints act at a
//! vertex (step 3 of [`crate::weights`]), so that the weights' cost is bounded by the
//! surface whatever the skeleton (issue 45).
//!
//! A soft boundary's child side floods its region along the surface past its plane, as far
//! as its own bones are the nearer ([`mod@super::soft_sides`]). Where the skeleton does not
//! follow the mesh's shape (a chain coiled in a capsule, a tree of joints spread through
//! one blob: every section of every joint encloses other bones, so every joint is soft),
//! hundreds of sides reach every vertex: on a 100,000-vertex capsule with a chain of 2,000
//! soft joints, 12 million (vertex, side) pairs, each a nearest-bone search, and every pair
//! of them at a vertex in the sibling blends. No vertex of the 113 real characters compared
//! in docs/measurements.md ("Many joints") is crowded: their weights are unchanged.
//!
//! The rule: the sides are found deepest joint first ([`mod@super::soft_sides`]), in batches of
//! [`BATCH`] in parallel. A side does not enter a vertex that [`MOST_SOFT_SIDES`] sides
//! found before its batch already reach (it is not in play for that side, as a vertex
//! outside its region is not); after each batch, the sides keep their vertices in batch
//! order while a vertex has room, and drop the rest. The deepest sides are the ones kept:
//! along a chain a side below takes the mass of every joint above it where its share is
//! whole (step 3), so the shallower ones are those that matter least. A vertex thus gets at
//! most [`MOST_SOFT_SIDES`] + [`BATCH`] − 1 sides computed, and keeps
//! [`MOST_SOFT_SIDES`].

use crate::warning::{Warning, WarningTopic};

/// The most soft joints that act at one vertex: far more than a real rig's soft joints
/// overlap at one point (none of the characters measured reaches it).
pub const MOST_SOFT_SIDES: u16 = 16;

/// Sides found in parallel before their vertices are counted.
pub const BATCH: usize = 16;

/// The warning when soft sides were left out at `crowded_vertices` vertices.
pub fn crowding_warning(crowded_vertices: usize) -> Option<Warning> {
    (crowded_vertices > 0).then(|| {
        Warning::new(
            WarningTopic::Weights,
            format!(
                "{crowded_vertices} vertices lie past the planes of more than {MOST_SOFT_SIDES} \
             soft joints: only the {MOST_SOFT_SIDES} deepest act there"
            ),
        )
    })
}

/// How many sides reach every vertex so far, and the vertices where one was left out.
pub struct Crowding {
    counts: Vec<u16>,
    crowded: Vec<bool>,
}

impl Crowding {
    pub fn new(vertex_count: usize) -> Self {
        Self {
            counts: vec![0; vertex_count],
            crowded: vec![false; vertex_count],
        }
    }

    /// Whether [`MOST_SOFT_SIDES`] sides already reach `v`: no other side enters it.
    pub fn full(&self, v: usize) -> bool {
        self.counts[v] >= MOST_SOFT_SIDES
    }

    /// Marks `v` crowded: a flood did not enter it because it was full.
    pub fn refuse(&mut self, v: u32) {
        self.crowded[v as usize] = true;
    }

    /// Counts one more side at `v` when it has room and returns true; otherwise marks it
    /// crowded and returns false (the side drops it). The sides of a batch are admitted in
    /// batch order.
    pub fn admit(&mut self, v: u32) -> bool {
        let v = v as usize;
        if self.counts[v] >= MOST_SOFT_SIDES {
            self.crowded[v] = true;
            return false;
        }
        self.counts[v] += 1;
        true
    }

    /// The vertices where a side was left out.
    pub fn crowded_vertices(&self) -> usize {
        self.crowded.iter().filter(|&&c| c).count()
    }
}

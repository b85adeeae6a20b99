//! One vertex's reference and candidate rows spread over the joints, for the figures that
//! compare the two rows joint by joint ([`crate::weights_l1`], [`crate::rignet_metrics`]).

use atlas_skin_runtime::VertexWeights;

/// Dense copies of two rows, reused from vertex to vertex: only the joints a row touched
/// are written, and cleared again before the next vertex.
pub(crate) struct RowPair {
    reference: Vec<f64>,
    candidate: Vec<f64>,
    touched: Vec<usize>,
}

impl RowPair {
    /// Room for rows on joints below `joint_count`.
    pub(crate) fn new(joint_count: usize) -> Self {
        Self {
            reference: vec![0.0; joint_count],
            candidate: vec![0.0; joint_count],
            touched: Vec::new(),
        }
    }

    /// Spreads vertex `v`'s rows of `reference` and `candidate` (repeated joints summed),
    /// replacing the previous vertex's.
    pub(crate) fn load(&mut self, reference: &VertexWeights, candidate: &VertexWeights, v: usize) {
        for &j in &self.touched {
            self.reference[j] = 0.0;
            self.candidate[j] = 0.0;
        }
        self.touched.clear();
        for (j, w) in reference.row(v) {
            self.reference[j as usize] += f64::from(w);
            self.touched.push(j as usize);
        }
        for (j, w) in candidate.row(v) {
            self.candidate[j as usize] += f64::from(w);
            self.touched.push(j as usize);
        }
        self.touched.sort_unstable();
        self.touched.dedup();
    }

    /// The joints either row holds, increasing, each with its (reference, candidate) weight.
    pub(crate) fn joints(&self) -> impl Iterator<Item = (usize, f64, f64)> + '_ {
        self.touched
            .iter()
            .map(|&j| (j, self.reference[j], self.candidate[j]))
    }
}

//! Weight inpainting (Abdrashitov et al. 2023, §3.2): the weights of the vertices that
//! found no match, as the smoothest completion of the matched ones.
//!
//! With L the cotangent Laplacian and M the Voronoi mass matrix of the target surface
//! ([`super::cotangent`]), the weights W (one column per joint) minimise
//!
//!   E(W) = tr(Wᵀ Q W),  Q = −L + D² L M⁻¹ L,
//!
//! subject to W_i = the matched weights at every matched vertex i: the Dirichlet energy
//! (−L, the paper's smoothness term) plus the squared Laplacian (L M⁻¹ L, the "Laplacian
//! energy", which makes the weights' gradient continuous across the matched border).
//!
//! D is a length, [`System::length`]: the transfer passes the source's bounding-box
//! diagonal. The paper's Q = −L + L M⁻¹ L (D = 1 in the file's units) is not the same
//! energy in centimetres as in metres: the Dirichlet energy ∫|∇w|² dA does not change when
//! the surface is scaled by s, the Laplacian energy ∫(Δw)² dA is divided by s², so the
//! same garment in centimetres was inpainted almost harmonically and in metres almost
//! biharmonically. With D² the two terms are weighed as the paper's on a character of
//! unit diagonal (the scale of its examples, and of the benchmark's characters, whose
//! diagonals are 1 to 1.7), whatever the units.
//!
//! Split into unknown (u) and matched (k) vertices, the minimiser solves
//!
//!   Q_uu W_u = −Q_uk W_k,
//!
//! one right-hand side per joint. Q_uu is symmetric and positive definite when every
//! unknown vertex is joined to a matched one through the surface (each piece is solved on
//! its own, [`super::transfer_weights`], and a piece without a matched vertex is not
//! solved), so it is factored once by a sparse Cholesky (faer's supernodal LLᵀ with an AMD
//! ordering) and solved for all the joints' columns at once. A diagonal shift of
//! [`REGULARISATION`] times the mean diagonal keeps the factorisation defined on an unknown
//! vertex cut off by zero-area faces (its weights then come out 0, and the caller fills
//! them, see [`super::transfer_weights`]).
//!
//! The rows of Q of unknown vertices are assembled directly: Q_ij = −L_ij +
//! D² Σ_m L_im L_mj / M_mm over the neighbours m of i (and i itself), so only the two-ring
//! of each unknown vertex is visited. `dense_reference` (tests) solves the same system
//! densely.

use super::cotangent::Operators;
use super::row_scratch::RowScratch;
use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};
use thiserror::Error;

/// The diagonal shift, relative to the mean of |Q_ii| over the unknown vertices.
pub const REGULARISATION: f64 = 1e-12;

/// Why the inpainting system could not be solved.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum InpaintError {
    #[error("the inpainting system of {unknowns} vertices could not be built: {reason}")]
    Build { unknowns: usize, reason: String },
    #[error("the inpainting system of {unknowns} vertices is not positive definite: {reason}")]
    Factor { unknowns: usize, reason: String },
}

/// The inpainting system of one piece: unknown vertices and the fixed rows of the others.
pub struct System<'a> {
    pub operators: &'a Operators,
    /// The unknown vertices (surface indices).
    pub unknown: &'a [u32],
    /// #V: the slot of every unknown vertex in `unknown`, [`FIXED`] for the others.
    pub slot: &'a [u32],
    /// Columns of the solution (the joints of the piece).
    pub columns: usize,
    /// D of Q = −L + D² L M⁻¹ L (> 0): the length at which the two energies are weighed
    /// as the paper weighs them at unit length.
    pub length: f64,
}

/// [`System::slot`] of a vertex that is not unknown.
pub const FIXED: u32 = u32::MAX;

impl System<'_> {
    /// The entries `(j, Q_ij)` of row `i` of Q (every j of the two-ring, once, ascending),
    /// appended to `out`; `scratch` is left as found.
    fn q_row(&self, i: usize, scratch: &mut RowScratch, out: &mut Vec<(u32, f64)>) {
        let ops = self.operators;
        let length2 = self.length * self.length;
        scratch.add(i as u32, -ops.diagonal[i]);
        for &(j, l) in ops.off_diagonal.row(i) {
            scratch.add(j, -l);
        }
        let ring = std::iter::once((i as u32, ops.diagonal[i]))
            .chain(ops.off_diagonal.row(i).iter().copied());
        for (m, l_im) in ring {
            let mass = ops.mass[m as usize];
            if mass <= 0.0 {
                // An empty Laplacian row (only zero-area faces around m): no term.
                continue;
            }
            let scale = length2 * l_im / mass;
            scratch.add(m, scale * ops.diagonal[m as usize]);
            for &(j, l_mj) in ops.off_diagonal.row(m as usize) {
                scratch.add(j, scale * l_mj);
            }
        }
        scratch.drain_into(out);
    }

    /// Q_uu (lower triangle, shifted by [`REGULARISATION`]) and −Q_uk W_k, with `fixed(j)`
    /// the sparse row `(column, weight)` of a fixed vertex j.
    fn assemble<'f>(
        &self,
        fixed: &dyn Fn(usize) -> &'f [(u32, f64)],
    ) -> (Vec<Triplet<u32, u32, f64>>, Mat<f64>) {
        let n = self.slot.len();
        let nu = self.unknown.len();
        let mut scratch = RowScratch::new(n);
        let mut row = Vec::new();
        let mut triplets = Vec::with_capacity(12 * nu);
        let mut rhs = Mat::<f64>::zeros(nu, self.columns);
        let mut diagonal_sum = 0.0;
        for (ui, &i) in self.unknown.iter().enumerate() {
            row.clear();
            self.q_row(i as usize, &mut scratch, &mut row);
            for &(j, q) in &row {
                let uj = self.slot[j as usize];
                if uj == FIXED {
                    for &(c, w) in fixed(j as usize) {
                        rhs[(ui, c as usize)] -= q * w;
                    }
                } else if uj as usize <= ui {
                    if uj as usize == ui {
                        diagonal_sum += q.abs();
                    }
                    triplets.push(Triplet::new(ui as u32, uj, q));
                }
            }
        }
        let shift = REGULARISATION * diagonal_sum / nu.max(1) as f64;
        for t in triplets.iter_mut().filter(|t| t.row == t.col) {
            t.val += shift;
        }
        (triplets, rhs)
    }

    /// W_u: row-major, `unknown.len() × columns`.
    pub fn solve<'f>(
        &self,
        fixed: &dyn Fn(usize) -> &'f [(u32, f64)],
    ) -> Result<Vec<f64>, InpaintError> {
        let nu = self.unknown.len();
        if nu == 0 {
            return Ok(Vec::new());
        }
        let (triplets, mut rhs) = self.assemble(fixed);
        let q =
            SparseColMat::<u32, f64>::try_new_from_triplets(nu, nu, &triplets).map_err(|e| {
                InpaintError::Build {
                    unknowns: nu,
                    reason: format!("{e:?}"),
                }
            })?;
        let llt = q
            .sp_cholesky(Side::Lower)
            .map_err(|e| InpaintError::Factor {
                unknowns: nu,
                reason: e.to_string(),
            })?;
        llt.solve_in_place(rhs.as_mut());
        Ok((0..nu)
            .flat_map(|ui| (0..self.columns).map(move |c| (ui, c)))
            .map(|(ui, c)| rhs[(ui, c)])
            .collect())
    }
}

/// The same minimiser by a dense Cholesky of the whole Q_uu (tests: the reference the
/// sparse path is compared with).
#[cfg(test)]
pub(crate) fn dense_reference<'f>(
    system: &System,
    fixed: &dyn Fn(usize) -> &'f [(u32, f64)],
) -> Vec<f64> {
    let nu = system.unknown.len();
    let (triplets, rhs) = system.assemble(fixed);
    let mut q = Mat::<f64>::zeros(nu, nu);
    for t in &triplets {
        q[(t.row as usize, t.col as usize)] += t.val;
        if t.row != t.col {
            q[(t.col as usize, t.row as usize)] += t.val;
        }
    }
    let solution = q.llt(Side::Lower).expect("positive definite").solve(&rhs);
    (0..nu)
        .flat_map(|ui| (0..system.columns).map(move |c| (ui, c)))
        .map(|(ui, c)| solution[(ui, c)])
        .collect()
}

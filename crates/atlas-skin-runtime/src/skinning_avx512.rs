//! Linear blend skinning of positions and normals with x86-64 AVX-512 (F, VL, DQ), chosen
//! at run time when the CPU has it ([`crate::InstructionSet::Avx512`]).
//!
//! A palette matrix is one 512-bit register `[c0 | c1 | c2 | c3]` (its columns; the
//! palette puts each matrix on a cache line of its own, so the load never straddles two),
//! so blending one influence is one load and one fused multiply-add, half the AVX2 loop's.
//! Position and normal are then transformed together as in the AVX2 loop, on the blended
//! matrix's two 256-bit halves, and written by masked stores of exactly three floats.
//! (Transforming in 512-bit registers too, `M ∘ [x x x x | y y y y | z z z z | 1 1 1 1]`
//! summed by lane shuffles, measured 15% slower: it needs the one shuffle port five times
//! per vertex.) The sums are the portable loop's (same blend order, implicit last weight).

use crate::skinning_avx2::{
    broadcast_load, half_products, load_index, prefetch_ahead, sum_both_halves, sum_halves,
};
use crate::skinning_job::{specialise, Kernel, Span};
use glam::Mat4;
use std::arch::x86_64::*;
use std::ops::Range;

/// True when this CPU runs the loops of this module.
pub(crate) fn available() -> bool {
    crate::skinning_avx2::available()
        && is_x86_feature_detected!("avx512f")
        && is_x86_feature_detected!("avx512vl")
        && is_x86_feature_detected!("avx512dq")
}

/// The linear blend loop for `k` influences with positions and optional normals, if the
/// CPU has AVX-512; tangents have no loop here (`None`).
pub(crate) fn linear_blend_kernel(k: usize, normals: bool, tangents: bool) -> Option<Kernel<Mat4>> {
    (available() && !tangents).then_some(specialise!(linear_blend_entry; k, normals, false))
}

fn linear_blend_entry<const K: usize, const NORMALS: bool, const TANGENTS: bool>(
    palette: &[Mat4],
    k: usize,
    span: Span,
) {
    // SAFETY: only handed out by `linear_blend_kernel` after `available()` and without
    // tangents; the job validated every joint index against the palette and every stream
    // length.
    unsafe { linear_blend_span::<K, NORMALS>(palette, k, span) }
}

broadcast_load!(
    /// `*x` in every lane of a 512-bit register (LLVM would load neighbouring weights as
    /// one pair and split it with shuffles).
    ///
    /// # Safety
    /// AVX-512F present; `x[i]` readable.
    #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
    broadcast,
    __m512,
    zmm_reg
);

/// `Σ_i ω_i M_i`, the last weight `1 − Σ explicit`, summed in every lane (no scalar
/// weight is moved into a vector register by a shuffle).
///
/// # Safety
/// AVX-512F present; `joints` has `k` valid palette indices, `explicit` `k − 1` weights.
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
#[inline]
unsafe fn blend_matrices(
    palette: *const f32,
    joints: *const u16,
    explicit: *const f32,
    k: usize,
) -> __m512 {
    let matrix = |i: usize| _mm512_loadu_ps(palette.add(16 * load_index(joints, i)));
    let mut blended = matrix(0);
    if k == 1 {
        return blended;
    }
    let mut sum = broadcast(explicit, 0);
    blended = _mm512_mul_ps(blended, sum);
    for i in 1..k - 1 {
        let w = broadcast(explicit, i);
        blended = _mm512_fmadd_ps(matrix(i), w, blended);
        sum = _mm512_add_ps(sum, w);
    }
    _mm512_fmadd_ps(
        matrix(k - 1),
        _mm512_sub_ps(_mm512_set1_ps(1.0), sum),
        blended,
    )
}

/// # Safety
/// AVX-512F, VL and DQ present; the job's validation holds (joint indices below the
/// palette length, streams of the span's length, `k ≥ 1` influences per vertex).
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
unsafe fn linear_blend_span<const K: usize, const NORMALS: bool>(
    palette: &[Mat4],
    k: usize,
    mut span: Span,
) {
    let k = if K == 0 { k } else { K };
    let block_loop = |used: usize| -> InfluenceBlockLoop {
        match used {
            1 => linear_blend_block::<1, NORMALS>,
            2 => linear_blend_block::<2, NORMALS>,
            3 => linear_blend_block::<3, NORMALS>,
            4 => linear_blend_block::<4, NORMALS>,
            _ => linear_blend_block::<0, NORMALS>,
        }
    };
    if span.prefetch {
        for (vertices, used) in span.blocks(k) {
            prefetch_ahead(&span, vertices.start, k);
            block_loop(used)(palette, &mut span, vertices, (k, used));
        }
    } else {
        // In cache: one call per run of blocks alike, not per block.
        for (vertices, used) in span.runs(k) {
            block_loop(used)(palette, &mut span, vertices, (k, used));
        }
    }
}

/// A loop over one block: palette, span, the block's vertices, (K, influences used).
type InfluenceBlockLoop = unsafe fn(&[Mat4], &mut Span, Range<usize>, (usize, usize));

/// Vertices `vertices` of the span, blending their first `USED` influences (or `used`
/// when `USED` is 0) of the `k` stored per row.
///
/// # Safety
/// As [`linear_blend_span`]; `vertices` within the span, `used ≤ k` covering every
/// positive weight of these rows.
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma")]
#[inline]
unsafe fn linear_blend_block<const USED: usize, const NORMALS: bool>(
    palette: &[Mat4],
    span: &mut Span,
    vertices: Range<usize>,
    (k, used): (usize, usize),
) {
    let used = if USED == 0 { used } else { USED };
    let palette = palette.as_ptr().cast::<f32>();
    let (joints, weights) = (span.joints.as_ptr(), span.weights.as_ptr());
    let rest_positions = span.rest_positions.as_ptr().cast::<f32>();
    let rest_normals = span.rest_normals.as_ptr().cast::<f32>();
    let out_positions = span.out_positions.as_mut_ptr().cast::<f32>();
    let out_normals = span.out_normals.as_mut_ptr().cast::<f32>();
    let (one, zero) = (_mm256_set1_ps(1.0), _mm256_setzero_ps());
    const XYZ: __mmask8 = 0b0111;
    for v in vertices {
        let m = blend_matrices(palette, joints.add(v * k), weights.add(v * (k - 1)), used);
        let (lo, hi) = (_mm512_castps512_ps256(m), _mm512_extractf32x8_ps::<1>(m));
        let position = half_products(lo, hi, rest_positions.add(3 * v), one);
        if NORMALS {
            let normal = half_products(lo, hi, rest_normals.add(3 * v), zero);
            let (p, n) = sum_both_halves(position, normal);
            _mm_mask_storeu_ps(out_positions.add(3 * v), XYZ, p);
            _mm_mask_storeu_ps(out_normals.add(3 * v), XYZ, n);
        } else {
            _mm_mask_storeu_ps(out_positions.add(3 * v), XYZ, sum_halves(position));
        }
    }
}

//! The skinning loops with x86-64 AVX2 and FMA instructions, chosen at run time when the
//! CPU has them (the portable loops in [`crate::skinning_job`] serve other CPUs).
//!
//! A palette matrix is two 256-bit registers, columns `[c0 | c1]` and `[c2 | c3]`, so that
//! blending one influence is two fused multiply-adds; transforming `p` is
//! `[c0 | c1]·[x x x x | y y y y] + [c2 | c3]·[z z z z | w w w w]` followed by adding the
//! two halves. Dual quaternions are blended per vertex as two 128-bit registers (real,
//! dual; one fused multiply-add each per influence, after the sign fix's dot product), or,
//! when the palette's hemispheres agree for the skin, as one 256-bit register without the
//! sign fix (one load and one fused multiply-add per influence, as linear blending), then
//! eight vertices at a time are
//! transposed to one register per component, normalised and applied with cross products
//! (no matrix, no square root). The arithmetic is the portable loops' (same blend order,
//! implicit last weight), so results agree with them to round-off and an identity palette
//! still reproduces the rest mesh exactly.

use crate::dual_quaternion::DualQuat;
use crate::skinning_job::{specialise, Kernel, Span};
use glam::{Mat4, Vec3, Vec4};
use std::arch::x86_64::*;
use std::ops::Range;

/// True when this CPU runs the loops of this module.
pub(crate) fn available() -> bool {
    is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
}

/// The linear blend loop for `k` influences and the given optional streams, if the CPU
/// has AVX2 and FMA.
pub(crate) fn linear_blend_kernel(k: usize, normals: bool, tangents: bool) -> Option<Kernel<Mat4>> {
    available().then_some(specialise!(linear_blend_entry; k, normals, tangents))
}

/// The dual quaternion loop, as [`linear_blend_kernel`].
pub(crate) fn dual_quaternion_kernel(
    k: usize,
    normals: bool,
    tangents: bool,
) -> Option<Kernel<DualQuat>> {
    available().then_some(specialise!(dual_quaternion_entry; k, normals, tangents))
}

fn linear_blend_entry<const K: usize, const NORMALS: bool, const TANGENTS: bool>(
    palette: &[Mat4],
    k: usize,
    span: Span,
) {
    // SAFETY: only handed out by `linear_blend_kernel` after `available()`; the job
    // validated every joint index against the palette and every stream length.
    unsafe { linear_blend_span::<K, NORMALS, TANGENTS>(palette, k, span) }
}

fn dual_quaternion_entry<const K: usize, const NORMALS: bool, const TANGENTS: bool>(
    palette: &[DualQuat],
    k: usize,
    span: Span,
) {
    // SAFETY: as in `linear_blend_entry`.
    unsafe { dual_quaternion_span::<K, NORMALS, TANGENTS>(palette, k, span) }
}

/// Defines `unsafe fn $name(x: *const f32, i: usize) -> $ty`: `x[i]` in every lane of a
/// `$ty` register by one broadcasting load (no shuffle unit), for the target features
/// given as attributes (AVX present; `x[i]` readable).
///
/// Written as one instruction of inline assembly: as an intrinsic, LLVM merges broadcasts
/// that meet in a blend, or that are summed, into scalar loads and shuffles (neighbouring
/// weights loaded as one pair and split), which moves the work back onto the one port that
/// shuffles (measured: the loop then runs 15% faster than before instead of 40%).
macro_rules! broadcast_load {
    ($(#[$attribute:meta])* $name:ident, $ty:ty, $register:ident) => {
        $(#[$attribute])*
        #[inline]
        unsafe fn $name(x: *const f32, i: usize) -> $ty {
            let out: $ty;
            std::arch::asm!(
                "vbroadcastss {out}, dword ptr [{x} + {i} * 4]",
                x = in(reg) x,
                i = in(reg) i,
                out = out($register) out,
                options(pure, readonly, nostack, preserves_flags),
            );
            out
        }
    };
}
pub(crate) use broadcast_load;

broadcast_load!(
    /// `*x` in every lane of a 256-bit register.
    ///
    /// # Safety
    /// AVX present; `x[i]` readable.
    #[target_feature(enable = "avx2,fma")]
    broadcast,
    __m256,
    ymm_reg
);

/// `*j` zero-extended, by one scalar load: as plain Rust, LLVM loads the four indices of
/// a vertex as one vector and extracts them with shuffles.
///
/// # Safety
/// `j[i]` readable.
#[inline(always)]
pub(crate) unsafe fn load_index(j: *const u16, i: usize) -> usize {
    let out: usize;
    std::arch::asm!(
        "movzx {out:e}, word ptr [{j} + {i} * 2]",
        j = in(reg) j,
        i = in(reg) i,
        out = out(reg) out,
        options(pure, readonly, nostack, preserves_flags),
    );
    out
}

/// `Σ_i ω_i M_i` as `(lo, hi)` = `([c0 | c1], [c2 | c3])`.
///
/// # Safety
/// AVX2 and FMA present; `joints` has `k` valid palette indices, `explicit` `k − 1` weights.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn blend_matrices(
    palette: *const f32,
    joints: *const u16,
    explicit: *const f32,
    k: usize,
) -> (__m256, __m256) {
    let matrix = |i: usize| palette.add(16 * load_index(joints, i));
    let first = matrix(0);
    let (mut lo, mut hi) = (_mm256_loadu_ps(first), _mm256_loadu_ps(first.add(8)));
    if k == 1 {
        return (lo, hi);
    }
    // Weights are broadcast from memory (a load, no shuffle) and summed in every lane, so
    // the implicit last weight needs no broadcast either.
    let mut sum = broadcast(explicit, 0);
    lo = _mm256_mul_ps(lo, sum);
    hi = _mm256_mul_ps(hi, sum);
    let mut add = |i: usize, w: __m256| {
        let m = matrix(i);
        lo = _mm256_fmadd_ps(_mm256_loadu_ps(m), w, lo);
        hi = _mm256_fmadd_ps(_mm256_loadu_ps(m.add(8)), w, hi);
    };
    for i in 1..k - 1 {
        let w = broadcast(explicit, i);
        add(i, w);
        sum = _mm256_add_ps(sum, w);
    }
    add(k - 1, _mm256_sub_ps(_mm256_set1_ps(1.0), sum));
    (lo, hi)
}

/// The blend `b̂ = Σ_i s_i ω_i q̂_i` of dual quaternions as its (real, dual) parts, with
/// the sign fix `s_i = sign(real(q̂_i) · real(q̂_0))` against the first influence; not
/// normalised.
///
/// Every step stays within 128-bit lanes (weights broadcast from memory, the signed
/// weight applied to the real and the dual part by one fused multiply-add each): no
/// cross-lane shuffle per influence.
///
/// # Safety
/// As [`blend_matrices`], `palette` pointing at dual quaternions (8 floats each).
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn blend_dual_quaternions(
    palette: *const f32,
    joints: *const u16,
    explicit: *const f32,
    k: usize,
) -> (__m128, __m128) {
    let quaternion = |i: usize| palette.add(8 * usize::from(joints.add(i).read()));
    let first = quaternion(0);
    let first_real = _mm_loadu_ps(first);
    let first_dual = _mm_loadu_ps(first.add(4));
    if k == 1 {
        return (first_real, first_dual);
    }
    let sign_mask = _mm_set1_ps(-0.0);
    let mut sum = _mm_broadcast_ss(&*explicit);
    let mut real = _mm_mul_ps(first_real, sum);
    let mut dual = _mm_mul_ps(first_dual, sum);
    let mut add = |q: *const f32, w: __m128| {
        let q_real = _mm_loadu_ps(q);
        // The dot product of the real parts in every lane; its sign bit flips w.
        let dot = _mm_dp_ps::<0xFF>(q_real, first_real);
        let signed = _mm_xor_ps(w, _mm_and_ps(dot, sign_mask));
        real = _mm_fmadd_ps(q_real, signed, real);
        dual = _mm_fmadd_ps(_mm_loadu_ps(q.add(4)), signed, dual);
    };
    for i in 1..k - 1 {
        let w = _mm_broadcast_ss(&*explicit.add(i));
        add(quaternion(i), w);
        sum = _mm_add_ps(sum, w);
    }
    add(quaternion(k - 1), _mm_sub_ps(_mm_set1_ps(1.0), sum));
    (real, dual)
}

/// The blend `b̂ = Σ_i ω_i q̂_i` as one register `[real | dual]`, without the sign fix:
/// for rows whose joints' real parts all have positive dot products with the first's
/// ([`crate::SkinningPalette::hemispheres_agree`]), where every sign is +1. One load and
/// one fused multiply-add per influence; the same sums in the same order as
/// [`blend_dual_quaternions`].
///
/// # Safety
/// As [`blend_dual_quaternions`].
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn blend_dual_quaternions_unsigned(
    palette: *const f32,
    joints: *const u16,
    explicit: *const f32,
    k: usize,
) -> __m256 {
    let quaternion = |i: usize| _mm256_loadu_ps(palette.add(8 * load_index(joints, i)));
    let first = quaternion(0);
    if k == 1 {
        return first;
    }
    let mut sum = broadcast(explicit, 0);
    let mut blended = _mm256_mul_ps(first, sum);
    for i in 1..k - 1 {
        let w = broadcast(explicit, i);
        blended = _mm256_fmadd_ps(quaternion(i), w, blended);
        sum = _mm256_add_ps(sum, w);
    }
    _mm256_fmadd_ps(
        quaternion(k - 1),
        _mm256_sub_ps(_mm256_set1_ps(1.0), sum),
        blended,
    )
}

/// [`blend_dual_quaternions`] of the first `used` influences of vertex `v` of a span with
/// `k` influences per vertex.
///
/// # Safety
/// As [`blend_dual_quaternions`]; `v` is a vertex of the span `joints` and `explicit` start,
/// `used ≤ k` covers every positive weight of its row.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn blend_vertex(
    palette: *const f32,
    (joints, explicit): (*const u16, *const f32),
    v: usize,
    k: usize,
    used: usize,
) -> (__m128, __m128) {
    blend_dual_quaternions(palette, joints.add(v * k), explicit.add(v * (k - 1)), used)
}

/// `2 / x` by the reciprocal estimate and one Newton step, `y' = y (2 − x y)` (relative
/// error ~1e-7, against ~1e-3 for the estimate alone), cheaper than a division.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn two_over(x: __m128) -> __m128 {
    let y = _mm_rcp_ps(x);
    let two = _mm_set1_ps(2.0);
    let refined = _mm_mul_ps(y, _mm_fnmadd_ps(x, y, two));
    _mm_add_ps(refined, refined)
}

/// `a × b` (lanes x, y, z; lane w is garbage), given `a_yzx` = `a` rotated to (y, z, x).
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn cross(a: __m128, a_yzx: __m128, b: __m128) -> __m128 {
    let b_yzx = _mm_shuffle_ps::<0b11_00_10_01>(b, b);
    let c = _mm_fmsub_ps(a, b_yzx, _mm_mul_ps(a_yzx, b));
    _mm_shuffle_ps::<0b11_00_10_01>(c, c)
}

/// A blended, not normalised, dual quaternion `b̂ = r + ε d` ready to move points and
/// vectors by `b̂ / ‖b̂‖` without a square root or a matrix: with `s = 2 / ‖r‖²`,
/// `v' = v + s · r⃗ × (r⃗ × v + r₀ v)` rotates `v`, and a point also gets the translation
/// `s (r₀ d⃗ − d₀ r⃗ + r⃗ × d⃗)`, so
/// `p' = p + s · (r⃗ × (r⃗ × p + r₀ p + d⃗) + r₀ d⃗ − d₀ r⃗)` (Kavan et al. 2007 §3–4).
struct BlendedDualQuaternion {
    real: __m128,
    real_yzx: __m128,
    real_w: __m128,
    dual: __m128,
    /// `r₀ d⃗ − d₀ r⃗`
    translation_part: __m128,
    scale: __m128,
}

impl BlendedDualQuaternion {
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn new((real, dual): (__m128, __m128)) -> Self {
        let real_w = _mm_permute_ps::<0xFF>(real);
        let dual_w = _mm_permute_ps::<0xFF>(dual);
        Self {
            real,
            real_yzx: _mm_shuffle_ps::<0b11_00_10_01>(real, real),
            real_w,
            dual,
            translation_part: _mm_fnmadd_ps(dual_w, real, _mm_mul_ps(real_w, dual)),
            scale: two_over(_mm_dp_ps::<0xFF>(real, real)),
        }
    }

    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn vector(&self, v: __m128) -> __m128 {
        let inner = _mm_fmadd_ps(self.real_w, v, cross(self.real, self.real_yzx, v));
        _mm_fmadd_ps(self.scale, cross(self.real, self.real_yzx, inner), v)
    }

    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn point(&self, p: __m128) -> __m128 {
        let inner = _mm_add_ps(
            _mm_fmadd_ps(self.real_w, p, cross(self.real, self.real_yzx, p)),
            self.dual,
        );
        let outer = _mm_add_ps(
            cross(self.real, self.real_yzx, inner),
            self.translation_part,
        );
        _mm_fmadd_ps(self.scale, outer, p)
    }
}

/// The halves `[c0·x + c2·z | c1·y + c3·w]` of `M v` for the blended matrix `(lo, hi)`
/// and the vector `v = (x, y, z, w)` read from memory, `w` given: x, y and z are
/// broadcast by loads and paired by blends, which need no shuffle unit (the loop is
/// bound by shuffles otherwise).
///
/// # Safety
/// AVX2 and FMA present; `v` points at 3 readable floats.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(crate) unsafe fn half_products(lo: __m256, hi: __m256, v: *const f32, w: __m256) -> __m256 {
    let xy = _mm256_blend_ps::<0xF0>(broadcast(v, 0), broadcast(v, 1));
    let zw = _mm256_blend_ps::<0xF0>(broadcast(v, 2), w);
    _mm256_fmadd_ps(hi, zw, _mm256_mul_ps(lo, xy))
}

/// `c0·x + c1·y + c2·z + c3·w` from [`half_products`].
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(crate) unsafe fn sum_halves(halves: __m256) -> __m128 {
    _mm_add_ps(
        _mm256_castps256_ps128(halves),
        _mm256_extractf128_ps::<1>(halves),
    )
}

/// [`sum_halves`] of a position's and a normal's [`half_products`]: `[p' | n']` from
/// `[a_p | b_p]` and `[a_n | b_n]` by two lane shuffles and one add, instead of two
/// extractions and two adds.
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(crate) unsafe fn sum_both_halves(position: __m256, normal: __m256) -> (__m128, __m128) {
    let both = _mm256_add_ps(
        _mm256_permute2f128_ps::<0x20>(position, normal),
        _mm256_permute2f128_ps::<0x31>(position, normal),
    );
    (
        _mm256_castps256_ps128(both),
        _mm256_extractf128_ps::<1>(both),
    )
}

/// Stores lanes x, y, z of `v` as 16 bytes, the fourth lane over the next vertex's x,
/// which that vertex's own store then writes: one store instead of two and a shuffle.
///
/// # Safety
/// `out` and the float after it are writable and belong to this span.
#[inline]
unsafe fn store_vec3_over_next(out: *mut Vec3, v: __m128) {
    _mm_storeu_ps(out.cast::<f32>(), v);
}

/// Vertices between the block being skinned and the block [`prefetch_block`] asks the
/// caches for: 128 vertices ahead are 1.5 KB of each position or normal stream, a few
/// hundred nanoseconds of the loop, about a memory access's latency. Measured at 1M
/// vertices on 2 threads, as linear blending's copy-bandwidth fraction over that of dual
/// quaternions (whose loop does not prefetch) in the same runs: 0.91–0.95 without
/// prefetching, 1.02–1.04 at 32 and 64 vertices ahead, 1.04–1.09 at 128, 1.06 at 256.
pub(crate) const PREFETCH_AHEAD: usize = 128;

/// Asks the caches for the streams of the block of [`crate::compact_skin::INFLUENCE_BLOCK`]
/// vertices from `v`, [`PREFETCH_AHEAD`] vertices before the loop reads them: the rest
/// positions and normals, joints and weights to read, the posed positions and normals to
/// write (a prefetch for writing, which owns the line before the stores arrive, so that
/// they do not wait for it). The hardware prefetcher follows the streams too; these hints
/// still gained (see [`PREFETCH_AHEAD`]). No prefetch goes past the span's end (it would
/// fetch lines of another task's span).
///
/// # Safety
/// SSE present (x86-64); `v + 8 ≤ span.len()`.
#[inline(always)]
pub(crate) unsafe fn prefetch_block(span: &Span, v: usize, k: usize) {
    // The first and last float of the block's 24 of a Vec3 stream: both its lines.
    let read = |p: *const f32| {
        _mm_prefetch::<_MM_HINT_T0>(p.cast());
        _mm_prefetch::<_MM_HINT_T0>(p.add(23).cast());
    };
    let write = |p: *const f32| {
        _mm_prefetch::<_MM_HINT_ET0>(p.cast());
        _mm_prefetch::<_MM_HINT_ET0>(p.add(23).cast());
    };
    read(span.rest_positions.as_ptr().cast::<f32>().add(3 * v));
    write(span.out_positions.as_ptr().cast::<f32>().add(3 * v));
    if !span.out_normals.is_empty() {
        read(span.rest_normals.as_ptr().cast::<f32>().add(3 * v));
        write(span.out_normals.as_ptr().cast::<f32>().add(3 * v));
    }
    _mm_prefetch::<_MM_HINT_T0>(span.joints.as_ptr().add(v * k).cast());
    if k > 1 {
        read(span.weights.as_ptr().add(v * (k - 1)));
    }
}

/// [`prefetch_block`] for the block [`PREFETCH_AHEAD`] vertices after `v`, if the span has
/// all of it.
///
/// # Safety
/// SSE present (x86-64).
#[inline(always)]
pub(crate) unsafe fn prefetch_ahead(span: &Span, v: usize, k: usize) {
    let ahead = v + PREFETCH_AHEAD;
    if ahead + crate::compact_skin::INFLUENCE_BLOCK <= span.len() {
        prefetch_block(span, ahead, k);
    }
}

#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn load_vec3(v: &Vec3, w: f32) -> __m128 {
    _mm_setr_ps(v.x, v.y, v.z, w)
}

/// Stores lanes x, y, z of `v` (x and y as one 8-byte store).
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn store_vec3(out: &mut Vec3, v: __m128) {
    let out = (out as *mut Vec3).cast::<f32>();
    out.cast::<f64>()
        .write_unaligned(_mm_cvtsd_f64(_mm_castps_pd(v)));
    *out.add(2) = _mm_cvtss_f32(_mm_movehl_ps(v, v));
}

/// Writes vertex v's posed streams, moving points (given as (x, y, z, 1)) by `point` and
/// directions (x, y, z, 0) by `vector`.
///
/// # Safety
/// AVX2 and FMA present; `v` below every present stream's length.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn write_vertex<const NORMALS: bool, const TANGENTS: bool>(
    span: &mut Span,
    v: usize,
    point: impl Fn(__m128) -> __m128,
    vector: impl Fn(__m128) -> __m128,
) {
    let p = point(load_vec3(span.rest_positions.get_unchecked(v), 1.0));
    store_vec3(span.out_positions.get_unchecked_mut(v), p);
    if NORMALS {
        let n = vector(load_vec3(span.rest_normals.get_unchecked(v), 0.0));
        store_vec3(span.out_normals.get_unchecked_mut(v), n);
    }
    if TANGENTS {
        let t: Vec4 = *span.rest_tangents.get_unchecked(v);
        let moved = vector(_mm_setr_ps(t.x, t.y, t.z, 0.0));
        let mut lanes = [0.0f32; 4];
        _mm_storeu_ps(lanes.as_mut_ptr(), moved);
        *span.out_tangents.get_unchecked_mut(v) = Vec4::new(lanes[0], lanes[1], lanes[2], t.w);
    }
}

/// Positions and normals in one pass; every vertex but the span's last stores each
/// vector as 16 bytes over the next vertex ([`store_vec3_over_next`]).
///
/// # Safety
/// AVX2 and FMA present; the job's validation holds (joint indices below the palette
/// length, streams of the span's length, `k ≥ 1` influences per vertex).
#[target_feature(enable = "avx2,fma")]
unsafe fn linear_blend_span<const K: usize, const NORMALS: bool, const TANGENTS: bool>(
    palette: &[Mat4],
    k: usize,
    mut span: Span,
) {
    let k = if K == 0 { k } else { K };
    let block_loop = |used: usize| -> BlockLoop {
        match used {
            1 => linear_blend_block::<1, NORMALS, TANGENTS>,
            2 => linear_blend_block::<2, NORMALS, TANGENTS>,
            3 => linear_blend_block::<3, NORMALS, TANGENTS>,
            4 => linear_blend_block::<4, NORMALS, TANGENTS>,
            _ => linear_blend_block::<0, NORMALS, TANGENTS>,
        }
    };
    if span.prefetch {
        for (vertices, used) in span.blocks(k) {
            prefetch_ahead(&span, vertices.start, k);
            block_loop(used)(palette, &mut span, vertices, k, used);
        }
    } else {
        // In cache: one call per run of blocks alike, not per block.
        for (vertices, used) in span.runs(k) {
            block_loop(used)(palette, &mut span, vertices, k, used);
        }
    }
}

/// A loop over one block of vertices: palette, span, the block's vertices, K (the
/// stride of the span's rows) and the influences the block uses.
type BlockLoop = unsafe fn(&[Mat4], &mut Span, Range<usize>, usize, usize);

/// Vertices `vertices` of the span, blending their first `USED` influences (or `used`
/// when `USED` is 0) of the `k` stored per row; every vertex but the span's last stores
/// each vector as 16 bytes over the next vertex ([`store_vec3_over_next`]).
///
/// # Safety
/// As [`linear_blend_span`]; `vertices` within the span, `used ≤ k` covering every
/// positive weight of these rows.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn linear_blend_block<const USED: usize, const NORMALS: bool, const TANGENTS: bool>(
    palette: &[Mat4],
    span: &mut Span,
    vertices: Range<usize>,
    k: usize,
    used: usize,
) {
    let used = if USED == 0 { used } else { USED };
    let palette = palette.as_ptr().cast::<f32>();
    let count = span.len();
    let (joints, weights) = (span.joints.as_ptr(), span.weights.as_ptr());
    let rest_positions = span.rest_positions.as_ptr().cast::<f32>();
    let rest_normals = span.rest_normals.as_ptr().cast::<f32>();
    let out_positions = span.out_positions.as_mut_ptr();
    let out_normals = span.out_normals.as_mut_ptr();
    let (one, zero) = (_mm256_set1_ps(1.0), _mm256_setzero_ps());
    for v in vertices {
        let (lo, hi) = blend_matrices(palette, joints.add(v * k), weights.add(v * (k - 1)), used);
        let position = half_products(lo, hi, rest_positions.add(3 * v), one);
        let last = v + 1 == count;
        if NORMALS {
            let normal = half_products(lo, hi, rest_normals.add(3 * v), zero);
            let (p, n) = sum_both_halves(position, normal);
            if last {
                store_vec3(&mut *out_positions.add(v), p);
                store_vec3(&mut *out_normals.add(v), n);
            } else {
                store_vec3_over_next(out_positions.add(v), p);
                store_vec3_over_next(out_normals.add(v), n);
            }
        } else if last {
            store_vec3(&mut *out_positions.add(v), sum_halves(position));
        } else {
            store_vec3_over_next(out_positions.add(v), sum_halves(position));
        }
        if TANGENTS {
            let t = span.rest_tangents.get_unchecked(v);
            let moved = sum_halves(half_products(lo, hi, (t as *const Vec4).cast(), zero));
            let mut lanes = [0.0f32; 4];
            _mm_storeu_ps(lanes.as_mut_ptr(), moved);
            *span.out_tangents.as_mut_ptr().add(v) = Vec4::new(lanes[0], lanes[1], lanes[2], t.w);
        }
    }
}

/// Vertices per batch of the dual quaternion loop: one per lane of a 256-bit register,
/// and one block of [`crate::compact_skin::INFLUENCE_BLOCK`].
const LANES: usize = 8;
const _: () = assert!(LANES == crate::compact_skin::INFLUENCE_BLOCK);

/// # Safety
/// As [`linear_blend_span`].
#[target_feature(enable = "avx2,fma")]
unsafe fn dual_quaternion_span<const K: usize, const NORMALS: bool, const TANGENTS: bool>(
    palette: &[DualQuat],
    k: usize,
    mut span: Span,
) {
    let k = if K == 0 { k } else { K };
    let palette = palette.as_ptr().cast::<f32>();
    let (joints, weights) = (span.joints.as_ptr(), span.weights.as_ptr());
    // Batches of eight vertices in structure-of-arrays form (tangents, rare, go one by
    // one): normalising and rotating costs a sixth of the one-vertex form per vertex.
    let batched = if TANGENTS {
        0
    } else {
        span.len() / LANES * LANES
    };
    let rows = (joints, weights);
    let unsigned = span.hemispheres_agree;
    // One call per run of blocks alike (`Span::runs`), not per batch.
    for (vertices, used) in span.runs(k) {
        let batches = vertices.start..vertices.end.min(batched);
        if batches.is_empty() {
            continue;
        }
        let run: BatchRun = match (used, unsigned) {
            (1, _) => dual_quaternion_run::<1, true, NORMALS>,
            (2, false) => dual_quaternion_run::<2, false, NORMALS>,
            (3, false) => dual_quaternion_run::<3, false, NORMALS>,
            (4, false) => dual_quaternion_run::<4, false, NORMALS>,
            (_, false) => dual_quaternion_run::<0, false, NORMALS>,
            (2, true) => dual_quaternion_run::<2, true, NORMALS>,
            (3, true) => dual_quaternion_run::<3, true, NORMALS>,
            (4, true) => dual_quaternion_run::<4, true, NORMALS>,
            (_, true) => dual_quaternion_run::<0, true, NORMALS>,
        };
        run(palette, rows, &mut span, batches, (k, used));
    }
    for v in batched..span.len() {
        let blend = BlendedDualQuaternion::new(blend_vertex(palette, rows, v, k, k));
        write_vertex::<NORMALS, TANGENTS>(
            &mut span,
            v,
            // SAFETY (both closures): AVX2 and FMA are present in this function.
            |p| unsafe { blend.point(p) },
            |n| unsafe { blend.vector(n) },
        );
    }
}

/// A [`dual_quaternion_run`]: palette, rows, span, vertices, (K, influences used).
type BatchRun =
    unsafe fn(*const f32, (*const u16, *const f32), &mut Span, Range<usize>, (usize, usize));

/// The batches of eight vertices in `vertices` (whole batches), blended over their first
/// `USED` influences (or `used` when `USED` is 0) by [`blend_batch`], positions and
/// optional normals moved and stored.
///
/// # Safety
/// As [`blend_batch`] for each batch; `vertices` within the span, a multiple of
/// [`LANES`] long and starting at a multiple of it.
#[target_feature(enable = "avx2,fma")]
unsafe fn dual_quaternion_run<const USED: usize, const UNSIGNED: bool, const NORMALS: bool>(
    palette: *const f32,
    rows: (*const u16, *const f32),
    span: &mut Span,
    vertices: Range<usize>,
    (k, used): (usize, usize),
) {
    for start in vertices.step_by(LANES) {
        let batch = blend_batch::<USED, UNSIGNED>(palette, rows, start, k, used);
        let positions = span.rest_positions.as_ptr().add(start);
        let moved = batch.point(load_vec3_batch(positions));
        store_vec3_batch(span.out_positions.as_mut_ptr().add(start), moved);
        if NORMALS {
            let normals = span.rest_normals.as_ptr().add(start);
            let moved = batch.vector(load_vec3_batch(normals));
            store_vec3_batch(span.out_normals.as_mut_ptr().add(start), moved);
        }
    }
}

/// The eight vertices from `start` blended over their first `USED` influences (or `used`
/// when `USED` is 0); `UNSIGNED`: without the sign fix
/// ([`blend_dual_quaternions_unsigned`], also right for one influence).
///
/// # Safety
/// As [`blend_vertex`] for each of the eight vertices; `UNSIGNED` only when the palette's
/// hemispheres agree for these rows.
#[target_feature(enable = "avx2,fma")]
unsafe fn blend_batch<const USED: usize, const UNSIGNED: bool>(
    palette: *const f32,
    rows: (*const u16, *const f32),
    start: usize,
    k: usize,
    used: usize,
) -> DualQuaternionBatch {
    let used = if USED == 0 { used } else { USED };
    if UNSIGNED {
        let (joints, explicit) = rows;
        let blend = |v: usize| {
            blend_dual_quaternions_unsigned(
                palette,
                joints.add(v * k),
                explicit.add(v * (k - 1)),
                used,
            )
        };
        let mut reals = [_mm256_setzero_ps(); LANES / 2];
        let mut duals = [_mm256_setzero_ps(); LANES / 2];
        for i in 0..LANES / 2 {
            let (low, high) = (blend(start + i), blend(start + i + LANES / 2));
            reals[i] = _mm256_permute2f128_ps::<0x20>(low, high);
            duals[i] = _mm256_permute2f128_ps::<0x31>(low, high);
        }
        return DualQuaternionBatch::new(reals, duals);
    }
    // Vertices i and i + 4 share a register (the transpose's input), built as soon as
    // both are blended: eight separate halves went through the stack and were read
    // back as whole registers, a store-to-load forwarding stall (measured: 10% of the
    // loop's time).
    let mut reals = [_mm256_setzero_ps(); LANES / 2];
    let mut duals = [_mm256_setzero_ps(); LANES / 2];
    for i in 0..LANES / 2 {
        let (real_low, dual_low) = blend_vertex(palette, rows, start + i, k, used);
        let (real_high, dual_high) = blend_vertex(palette, rows, start + i + LANES / 2, k, used);
        reals[i] = _mm256_set_m128(real_high, real_low);
        duals[i] = _mm256_set_m128(dual_high, dual_low);
    }
    DualQuaternionBatch::new(reals, duals)
}

/// Eight blended dual quaternions, one per lane: real `(x, y, z, w)`, dual `(x, y, z, w)`,
/// and `s = 2 / ‖real‖²`; moves points and vectors as [`BlendedDualQuaternion`] does.
struct DualQuaternionBatch {
    real: [__m256; 3],
    real_w: __m256,
    dual: [__m256; 3],
    /// `r₀ d⃗ − d₀ r⃗`
    translation_part: [__m256; 3],
    scale: __m256,
}

impl DualQuaternionBatch {
    /// From the eight vertices' real and dual parts, paired as `[q_i | q_{i+4}]`,
    /// transposed to one register per component.
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn new(reals: [__m256; LANES / 2], duals: [__m256; LANES / 2]) -> Self {
        let [rx, ry, rz, rw] = transpose(reals);
        let [dx, dy, dz, dw] = transpose(duals);
        let norm_squared = _mm256_fmadd_ps(
            rx,
            rx,
            _mm256_fmadd_ps(ry, ry, _mm256_fmadd_ps(rz, rz, _mm256_mul_ps(rw, rw))),
        );
        let y = _mm256_rcp_ps(norm_squared);
        let y = _mm256_mul_ps(y, _mm256_fnmadd_ps(norm_squared, y, _mm256_set1_ps(2.0)));
        let translation = |d: __m256, r: __m256| _mm256_fmsub_ps(rw, d, _mm256_mul_ps(dw, r));
        Self {
            real: [rx, ry, rz],
            real_w: rw,
            dual: [dx, dy, dz],
            translation_part: [
                translation(dx, rx),
                translation(dy, ry),
                translation(dz, rz),
            ],
            scale: _mm256_add_ps(y, y),
        }
    }

    /// `p + s · (r⃗ × (r⃗ × p + r₀ p + d⃗) + r₀ d⃗ − d₀ r⃗)`
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn point(&self, p: [__m256; 3]) -> [__m256; 3] {
        let inner = cross_batch(self.real, p);
        let inner: [__m256; 3] = std::array::from_fn(|i| {
            _mm256_add_ps(_mm256_fmadd_ps(self.real_w, p[i], inner[i]), self.dual[i])
        });
        let outer = cross_batch(self.real, inner);
        std::array::from_fn(|i| {
            _mm256_fmadd_ps(
                self.scale,
                _mm256_add_ps(outer[i], self.translation_part[i]),
                p[i],
            )
        })
    }

    /// `v + s · r⃗ × (r⃗ × v + r₀ v)`
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    unsafe fn vector(&self, v: [__m256; 3]) -> [__m256; 3] {
        let inner = cross_batch(self.real, v);
        let inner: [__m256; 3] =
            std::array::from_fn(|i| _mm256_fmadd_ps(self.real_w, v[i], inner[i]));
        let outer = cross_batch(self.real, inner);
        std::array::from_fn(|i| _mm256_fmadd_ps(self.scale, outer[i], v[i]))
    }
}

/// `a × b` for eight vector pairs in component registers.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn cross_batch(a: [__m256; 3], b: [__m256; 3]) -> [__m256; 3] {
    let [ax, ay, az] = a;
    let [bx, by, bz] = b;
    [
        _mm256_fmsub_ps(ay, bz, _mm256_mul_ps(az, by)),
        _mm256_fmsub_ps(az, bx, _mm256_mul_ps(ax, bz)),
        _mm256_fmsub_ps(ax, by, _mm256_mul_ps(ay, bx)),
    ]
}

/// Transposes eight 4-vectors `q_0 … q_7` given as pairs `[q_i | q_{i+4}]` (i < 4) into
/// four registers, register c holding component c of `q_0 … q_7` in order: two 4 × 4
/// transposes, one per 128-bit lane.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn transpose([a, b, c, d]: [__m256; LANES / 2]) -> [__m256; 4] {
    let ab_low = _mm256_unpacklo_ps(a, b);
    let ab_high = _mm256_unpackhi_ps(a, b);
    let cd_low = _mm256_unpacklo_ps(c, d);
    let cd_high = _mm256_unpackhi_ps(c, d);
    [
        _mm256_shuffle_ps::<0x44>(ab_low, cd_low),
        _mm256_shuffle_ps::<0xEE>(ab_low, cd_low),
        _mm256_shuffle_ps::<0x44>(ab_high, cd_high),
        _mm256_shuffle_ps::<0xEE>(ab_high, cd_high),
    ]
}

/// Lane orders of the three loaded registers `a = [x0 y0 z0 x1 y1 z1 x2 y2]`,
/// `b = [z2 x3 y3 z3 x4 y4 z4 x5]`, `c = [y5 z5 x6 y6 z6 x7 y7 z7]` once each component is
/// blended into one register: the x register holds `[x0 x3 x6 x1 x4 x7 x2 x5]`, and so on.
/// Blend masks pick, per lane, which of a, b, c holds that component there.
const MASK_147: i32 = 0b1001_0010;
const MASK_25: i32 = 0b0010_0100;
const MASK_036: i32 = 0b0100_1001;

/// Eight `Vec3`s (24 floats) as x, y, z registers.
///
/// # Safety
/// AVX2 present; `v` points at 8 readable `Vec3`s.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn load_vec3_batch(v: *const Vec3) -> [__m256; 3] {
    let f = v.cast::<f32>();
    let (a, b, c) = (
        _mm256_loadu_ps(f),
        _mm256_loadu_ps(f.add(8)),
        _mm256_loadu_ps(f.add(16)),
    );
    let x = _mm256_blend_ps::<MASK_25>(_mm256_blend_ps::<MASK_147>(a, b), c);
    let y = _mm256_blend_ps::<MASK_036>(_mm256_blend_ps::<MASK_25>(a, b), c);
    let z = _mm256_blend_ps::<MASK_147>(_mm256_blend_ps::<MASK_036>(a, b), c);
    [
        _mm256_permutevar8x32_ps(x, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5)),
        _mm256_permutevar8x32_ps(y, _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6)),
        _mm256_permutevar8x32_ps(z, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7)),
    ]
}

/// The inverse of [`load_vec3_batch`].
///
/// # Safety
/// AVX2 present; `out` points at 8 writable `Vec3`s.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn store_vec3_batch(out: *mut Vec3, [x, y, z]: [__m256; 3]) {
    let x = _mm256_permutevar8x32_ps(x, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5));
    let y = _mm256_permutevar8x32_ps(y, _mm256_setr_epi32(5, 0, 3, 6, 1, 4, 7, 2));
    let z = _mm256_permutevar8x32_ps(z, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7));
    let f = out.cast::<f32>();
    _mm256_storeu_ps(
        f,
        _mm256_blend_ps::<MASK_25>(_mm256_blend_ps::<MASK_147>(x, y), z),
    );
    _mm256_storeu_ps(
        f.add(8),
        _mm256_blend_ps::<MASK_25>(_mm256_blend_ps::<MASK_147>(z, x), y),
    );
    _mm256_storeu_ps(
        f.add(16),
        _mm256_blend_ps::<MASK_25>(_mm256_blend_ps::<MASK_147>(y, z), x),
    );
}

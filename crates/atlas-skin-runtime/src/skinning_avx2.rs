//! The skinning loops with x86-64 AVX2 and FMA instructions, chosen at run time when the
//! CPU has them (the portable loops in [`crate::skinning_job`] serve other CPUs).
//!
//! A palette matrix is two 256-bit registers, columns `[c0 | c1]` and `[c2 | c3]`, so that
//! blending one influence is two fused multiply-adds; transforming `p` is
//! `[c0 | c1]·[x x x x | y y y y] + [c2 | c3]·[z z z z | w w w w]` followed by adding the
//! two halves. A dual quaternion (real | dual) is one register, blended by one fused
//! multiply-add per influence and applied directly with cross products (no matrix). The arithmetic is the portable loops'
//! (same blend order, implicit last weight), so results agree with them to round-off and
//! an identity palette still reproduces the rest mesh exactly.

use crate::dual_quaternion::DualQuat;
use crate::skinning_job::{specialise, Kernel, Span};
use glam::{Mat4, Vec3, Vec4};
use std::arch::x86_64::*;

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
    let matrix = |i: usize| palette.add(16 * usize::from(*joints.add(i)));
    let first = matrix(0);
    let (mut lo, mut hi) = (_mm256_loadu_ps(first), _mm256_loadu_ps(first.add(8)));
    if k == 1 {
        return (lo, hi);
    }
    let w0 = _mm256_set1_ps(*explicit);
    lo = _mm256_mul_ps(lo, w0);
    hi = _mm256_mul_ps(hi, w0);
    let mut sum = *explicit;
    let mut add = |i: usize, w: f32| {
        let m = matrix(i);
        let w = _mm256_set1_ps(w);
        lo = _mm256_fmadd_ps(_mm256_loadu_ps(m), w, lo);
        hi = _mm256_fmadd_ps(_mm256_loadu_ps(m.add(8)), w, hi);
    };
    for i in 1..k - 1 {
        let w = *explicit.add(i);
        add(i, w);
        sum += w;
    }
    add(k - 1, 1.0 - sum);
    (lo, hi)
}

/// The blend `b̂ = Σ_i s_i ω_i q̂_i` of dual quaternions (real | dual), with the sign fix
/// `s_i = sign(real(q̂_i) · real(q̂_0))` against the first influence; not normalised.
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
) -> __m256 {
    let load = |i: usize| _mm256_loadu_ps(palette.add(8 * usize::from(*joints.add(i))));
    let first = load(0);
    let mut blend = first;
    if k > 1 {
        let first_real = _mm256_castps256_ps128(first);
        let sign_mask = _mm_set1_ps(-0.0);
        blend = _mm256_mul_ps(first, _mm256_set1_ps(*explicit));
        let mut sum = *explicit;
        let mut add = |i: usize, w: f32| {
            let q = load(i);
            // The dot product of the real parts in every lane; its sign bit flips w.
            let dot = _mm_dp_ps::<0xFF>(_mm256_castps256_ps128(q), first_real);
            let sign = _mm_and_ps(dot, sign_mask);
            let signed = _mm256_xor_ps(_mm256_set1_ps(w), _mm256_set_m128(sign, sign));
            blend = _mm256_fmadd_ps(q, signed, blend);
        };
        for i in 1..k - 1 {
            let w = *explicit.add(i);
            add(i, w);
            sum += w;
        }
        add(k - 1, 1.0 - sum);
    }
    blend
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
    unsafe fn new(blend: __m256) -> Self {
        let real = _mm256_castps256_ps128(blend);
        let dual = _mm256_extractf128_ps::<1>(blend);
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

/// `c0·x + c1·y + c2·z + c3·w` for `v = (x, y, z, w)`.
#[target_feature(enable = "avx2,fma")]
#[inline]
unsafe fn transform(lo: __m256, hi: __m256, v: __m128) -> __m128 {
    let v = _mm256_castps128_ps256(v);
    let xy = _mm256_permutevar8x32_ps(v, _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1));
    let zw = _mm256_permutevar8x32_ps(v, _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3));
    let sum = _mm256_fmadd_ps(hi, zw, _mm256_mul_ps(lo, xy));
    _mm_add_ps(_mm256_castps256_ps128(sum), _mm256_extractf128_ps::<1>(sum))
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
    let palette = palette.as_ptr().cast::<f32>();
    for v in 0..span.len() {
        let joints = span.joints.as_ptr().add(v * k);
        let explicit = span.weights.as_ptr().add(v * (k - 1));
        let (lo, hi) = blend_matrices(palette, joints, explicit, k);
        write_vertex::<NORMALS, TANGENTS>(
            &mut span,
            v,
            // SAFETY (both closures): AVX2 and FMA are present in this function.
            |p| unsafe { transform(lo, hi, p) },
            |n| unsafe { transform(lo, hi, n) },
        );
    }
}

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
    for v in 0..span.len() {
        let joints = span.joints.as_ptr().add(v * k);
        let explicit = span.weights.as_ptr().add(v * (k - 1));
        let blend =
            BlendedDualQuaternion::new(blend_dual_quaternions(palette, joints, explicit, k));
        write_vertex::<NORMALS, TANGENTS>(
            &mut span,
            v,
            // SAFETY (both closures): AVX2 and FMA are present in this function.
            |p| unsafe { blend.point(p) },
            |n| unsafe { blend.vector(n) },
        );
    }
}

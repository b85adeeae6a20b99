//! Deforming a mesh by a palette: linear blend and dual quaternion skinning over
//! caller-owned buffers (the shape of ozz-animation's SkinningJob).

use crate::compact_skin::{
    unorm16, unorm8, CompactSkin, StoredWeights, INFLUENCE_BLOCK, MAX_QUANTISED_INFLUENCES,
};
use crate::dual_quaternion::DualQuat;
use crate::instruction_set::InstructionSet;
use crate::skinning_palette::{SkinningMethod, SkinningPalette};
use crate::RuntimeError;
use glam::{Mat4, Quat, Vec3, Vec4};

/// Vertices per task when running on the rayon pool: large enough to amortise a task (a
/// few microseconds of skinning), small enough that a character of a few thousand
/// vertices gives each of two threads work (cesiumman's 3,273 vertices are two tasks)
/// and that a thread that cannot run leaves little for the others to wait for. Measured
/// against 4,096 on 2 threads (`atlas-skin bench`, 5 interleaved rounds): at load 2.7
/// cesiumman 1.34× (4,096 ran it on one thread), the demo and makehuman 1.03× and 1.02×;
/// at load 5.5, when the process had about two thirds of a core, the demo and cesiumman
/// level (1.01×), makehuman too spread to tell (interquartile range of its ratio to ozz
/// 0.90–1.42 against 1.27–1.40).
pub const PARALLEL_CHUNK: usize = 2048;
const _: () = assert!(
    PARALLEL_CHUNK.is_multiple_of(INFLUENCE_BLOCK),
    "spans split at block boundaries"
);

/// Vertices from which the vector loops of linear blending prefetch the streams ahead of
/// the block they skin: 65,536 vertices of positions and normals in and out, joints and
/// weights are 4.5 MB, beyond the second-level cache of one core, so the streams come
/// from the last level or memory; in cache the prefetches would only cost instructions.
/// (At 1M vertices on 2 threads they raised the copy-bandwidth fraction of linear blending
/// from 0.78 to 0.98, medians of 6 interleaved runs.)
pub const PREFETCH_FROM: usize = 1 << 16;

/// The sign bit of an IEEE 754 single.
const SIGN_BIT: u32 = 0x8000_0000;

/// Where a job runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Threading {
    /// On the calling thread only.
    #[default]
    Sequential,
    /// Split into chunks of [`PARALLEL_CHUNK`] vertices on the current rayon thread pool
    /// (use `ThreadPool::install` to choose the thread count).
    Parallel,
}

/// One skinning pass: reads the rest streams, writes the posed streams.
///
/// - `skin`: the weights, #V vertices over #J joints.
/// - `palette`: #J prepared matrices; its [`SkinningPalette::method`] chooses the blend.
/// - `rest_positions`, `out_positions`: #V bind-space and posed positions.
/// - `rest_normals`, `out_normals`: #V unit normals, both present or both absent.
/// - `rest_tangents`, `out_tangents`: #V tangents (xyz, w = handedness, copied), both
///   present or both absent.
///
/// Positions: LBS `p' = (Σ_i ω_i M_i) p`; DQS `p' = q̂(p)` with `q̂ = b̂ / ‖b̂‖`,
/// `b̂ = Σ_i ±ω_i q̂_i` (Kavan et al. 2007 §4, sign fix against the vertex's first, largest
/// influence). Normals and tangents: LBS by the blended matrix's linear part, not
/// renormalised (as ozz-animation: exact for rigid and uniformly scaled palettes; a
/// renderer normalises); DQS by the blended rotation (unit in, unit out).
///
/// [`SkinningJob::run`] checks only buffer lengths (O(1)); the skin and the palette were
/// validated when built, and the loop then trusts them and allocates nothing.
///
/// For dual quaternions, [`SkinningPalette::align_hemispheres`] after each palette update
/// lets the vector loops leave out the per-influence sign fix (checked per run, O(pairs)
/// of [`CompactSkin::pairs`]; the result is the same). A skin with quantised weights
/// ([`crate::WeightFormat`]) is run 64 vertices at a time, each piece's weights widened
/// to floats on the stack first. From [`PREFETCH_FROM`] vertices, the vector loops of
/// linear blending prefetch the streams of the block 128 vertices ahead.
///
/// The loop is specialised per influence count and stream set, and comes in the
/// [`InstructionSet`] families: [`SkinningJob::run`] takes the widest this CPU runs
/// (detected at run time), [`SkinningJob::run_with`] the one given. All do the same sums
/// in the same order; they differ by round-off (fused multiply-adds).
#[derive(Debug)]
pub struct SkinningJob<'a> {
    pub skin: &'a CompactSkin,
    pub palette: &'a SkinningPalette,
    pub threading: Threading,
    pub rest_positions: &'a [Vec3],
    pub rest_normals: Option<&'a [Vec3]>,
    pub rest_tangents: Option<&'a [Vec4]>,
    pub out_positions: &'a mut [Vec3],
    pub out_normals: Option<&'a mut [Vec3]>,
    pub out_tangents: Option<&'a mut [Vec4]>,
}

impl SkinningJob<'_> {
    /// Checks that every stream has the skin's #V elements, that optional streams come in
    /// (rest, out) pairs, and that the palette has the skin's #J joints.
    pub fn validate(&self) -> Result<(), RuntimeError> {
        let vertices = self.skin.vertex_count();
        let mismatch = |what: String| Err(RuntimeError::BufferSize { what });
        if self.palette.len() != self.skin.joint_count() {
            return mismatch(format!(
                "palette has {} joints, the skin {}",
                self.palette.len(),
                self.skin.joint_count()
            ));
        }
        let lengths = [
            ("rest positions", Some(self.rest_positions.len())),
            ("out positions", Some(self.out_positions.len())),
            ("rest normals", self.rest_normals.map(<[Vec3]>::len)),
            (
                "out normals",
                self.out_normals.as_deref().map(<[Vec3]>::len),
            ),
            ("rest tangents", self.rest_tangents.map(<[Vec4]>::len)),
            (
                "out tangents",
                self.out_tangents.as_deref().map(<[Vec4]>::len),
            ),
        ];
        for (name, len) in lengths {
            if let Some(len) = len.filter(|&len| len != vertices) {
                return mismatch(format!("{name}: {len}, the skin has {vertices} vertices"));
            }
        }
        if self.rest_normals.is_some() != self.out_normals.is_some() {
            return mismatch("normals must be given both as input and output".into());
        }
        if self.rest_tangents.is_some() != self.out_tangents.is_some() {
            return mismatch("tangents must be given both as input and output".into());
        }
        Ok(())
    }

    /// Validates, then deforms every vertex into the output buffers with the widest
    /// loops this CPU runs ([`InstructionSet::best`]).
    pub fn run(&mut self) -> Result<(), RuntimeError> {
        self.run_with(InstructionSet::best())
    }

    /// As [`SkinningJob::run`], with the loops of `set`.
    ///
    /// Errors: [`RuntimeError::UnsupportedInstructionSet`] when this CPU lacks `set`, and
    /// those of [`SkinningJob::validate`].
    pub fn run_with(&mut self, set: InstructionSet) -> Result<(), RuntimeError> {
        if !set.is_supported() {
            return Err(RuntimeError::UnsupportedInstructionSet {
                name: set.name().to_string(),
            });
        }
        self.validate()?;
        let (weights, quantised) = match self.skin.stored_weights() {
            StoredWeights::Float32(w) => (w.as_slice(), Quantised::None),
            StoredWeights::Unorm16(q) => (&[][..], Quantised::Unorm16(q)),
            StoredWeights::Unorm8(q) => (&[][..], Quantised::Unorm8(q)),
        };
        let span = Span {
            joints: self.skin.joints(),
            weights,
            quantised,
            block_influences: self.skin.block_influences(),
            hemispheres_agree: set != InstructionSet::Portable
                && self.palette.method() == SkinningMethod::DualQuaternion
                && self.palette.hemispheres_agree(self.skin),
            prefetch: self.skin.vertex_count() >= PREFETCH_FROM,
            rest_positions: self.rest_positions,
            rest_normals: self.rest_normals.unwrap_or_default(),
            rest_tangents: self.rest_tangents.unwrap_or_default(),
            out_positions: self.out_positions,
            out_normals: self.out_normals.as_deref_mut().unwrap_or_default(),
            out_tangents: self.out_tangents.as_deref_mut().unwrap_or_default(),
        };
        let k = self.skin.influences();
        let threading = self.threading;
        match self.palette.method() {
            SkinningMethod::LinearBlend => {
                dispatch(self.palette.matrices(), k, threading, span, set);
            }
            SkinningMethod::DualQuaternion => {
                dispatch(self.palette.dual_quaternions(), k, threading, span, set);
            }
        }
        Ok(())
    }
}

/// A blend of per-joint transforms into one per-vertex matrix.
trait Blend: Copy + Send + Sync {
    /// Blends the transforms of `joints` with weights `explicit` (#joints − 1 of them; the
    /// last is `1 − Σ explicit`).
    fn blend(palette: &[Self], joints: &[u16], explicit: &[f32]) -> Mat4;
    /// The AVX2 loop for `k` influences and the streams present, if the CPU has AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    fn avx2_kernel(k: usize, normals: bool, tangents: bool) -> Option<Kernel<Self>>;
    /// The AVX-512 loop, as [`Blend::avx2_kernel`]; `None` where the blend has none.
    #[cfg(target_arch = "x86_64")]
    fn avx512_kernel(_k: usize, _normals: bool, _tangents: bool) -> Option<Kernel<Self>> {
        None
    }
}

/// The vector loop of `set` (a supported family), or of the next narrower family when
/// `set` has none for this case; `None` for the portable loop.
fn simd_kernel<B: Blend>(
    set: InstructionSet,
    k: usize,
    normals: bool,
    tangents: bool,
) -> Option<Kernel<B>> {
    #[cfg(target_arch = "x86_64")]
    return match set {
        InstructionSet::Portable => None,
        InstructionSet::Avx2 => B::avx2_kernel(k, normals, tangents),
        InstructionSet::Avx512 => {
            B::avx512_kernel(k, normals, tangents).or_else(|| B::avx2_kernel(k, normals, tangents))
        }
    };
    #[cfg(not(target_arch = "x86_64"))]
    return None;
}

impl Blend for Mat4 {
    /// `Σ_i ω_i M_i`. Accumulating the implicit last weight after the explicit ones makes
    /// an identity palette give a diagonal of exactly 1 (the sum `S + fl(1 − S)` rounds to
    /// 1 for every `S` in [0, 1]).
    #[inline(always)]
    fn blend(palette: &[Self], joints: &[u16], explicit: &[f32]) -> Mat4 {
        let last = joints.len() - 1;
        let mut sum = 0.0;
        let mut blended = Mat4::ZERO;
        for (&joint, &w) in joints[..last].iter().zip(explicit) {
            blended += palette[usize::from(joint)] * w;
            sum += w;
        }
        blended + palette[usize::from(joints[last])] * (1.0 - sum)
    }

    #[cfg(target_arch = "x86_64")]
    fn avx2_kernel(k: usize, normals: bool, tangents: bool) -> Option<Kernel<Self>> {
        crate::skinning_avx2::linear_blend_kernel(k, normals, tangents)
    }

    #[cfg(target_arch = "x86_64")]
    fn avx512_kernel(k: usize, normals: bool, tangents: bool) -> Option<Kernel<Self>> {
        crate::skinning_avx512::linear_blend_kernel(k, normals, tangents)
    }
}

impl Blend for DualQuat {
    /// `b̂ / ‖b̂‖`, `b̂ = Σ_i s_i ω_i q̂_i`, `s_i = sign(real(q̂_i) · real(q̂_0))`, as the
    /// matrix of its rotation and translation: transforming a point and a normal by a
    /// matrix costs less than two quaternion rotations (Kavan et al. 2007 §4 do the same
    /// on the GPU).
    #[inline(always)]
    fn blend(palette: &[Self], joints: &[u16], explicit: &[f32]) -> Mat4 {
        let last = joints.len() - 1;
        let first = palette[usize::from(joints[0])].real;
        let mut real = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        let mut dual = real;
        let mut add = |joint: u16, w: f32| {
            let q = palette[usize::from(joint)];
            // w with the sign of the dot product, without a branch: neighbouring joints
            // of a random pose flip signs unpredictably.
            let sign_bit = q.real.dot(first).to_bits() & SIGN_BIT;
            let signed = f32::from_bits(w.to_bits() ^ sign_bit);
            real += q.real * signed;
            dual += q.dual * signed;
        };
        let mut sum = 0.0;
        for (&joint, &w) in joints[..last].iter().zip(explicit) {
            add(joint, w);
            sum += w;
        }
        add(joints[last], 1.0 - sum);
        DualQuat { real, dual }.normalized_matrix()
    }

    #[cfg(target_arch = "x86_64")]
    fn avx2_kernel(k: usize, normals: bool, tangents: bool) -> Option<Kernel<Self>> {
        crate::skinning_avx2::dual_quaternion_kernel(k, normals, tangents)
    }
}

/// Quantised explicit weights of a span (its `weights` then are widened by
/// [`run_dequantised`] before a loop sees them).
#[derive(Clone, Copy)]
pub(crate) enum Quantised<'a> {
    None,
    Unorm16(&'a [u16]),
    Unorm8(&'a [u8]),
}

impl<'a> Quantised<'a> {
    /// The first `at` weights and the rest.
    fn split_at(self, at: usize) -> (Self, Self) {
        match self {
            Self::None => (Self::None, Self::None),
            Self::Unorm16(q) => {
                let (a, b) = q.split_at(at.min(q.len()));
                (Self::Unorm16(a), Self::Unorm16(b))
            }
            Self::Unorm8(q) => {
                let (a, b) = q.split_at(at.min(q.len()));
                (Self::Unorm8(a), Self::Unorm8(b))
            }
        }
    }

    /// Writes the weights, widened to floats, to the start of `out` (long enough).
    fn widen_into(self, out: &mut [f32]) {
        match self {
            Self::None => {}
            Self::Unorm16(q) => out.iter_mut().zip(q).for_each(|(w, &q)| *w = unorm16(q)),
            Self::Unorm8(q) => out.iter_mut().zip(q).for_each(|(w, &q)| *w = unorm8(q)),
        }
    }
}

/// A contiguous range of vertices: its slice of every stream. Absent optional streams are
/// empty slices.
pub(crate) struct Span<'a> {
    pub(crate) joints: &'a [u16],
    /// The explicit weights as floats (empty while `quantised` holds them).
    pub(crate) weights: &'a [f32],
    pub(crate) quantised: Quantised<'a>,
    /// [`CompactSkin::block_influences`] of the span, which starts at a block boundary.
    pub(crate) block_influences: &'a [u32],
    /// For dual quaternions: every pair of joints of a row has real parts with a positive
    /// dot product ([`SkinningPalette::hemispheres_agree`]), so the sign fix may be left
    /// out.
    pub(crate) hemispheres_agree: bool,
    /// The job's streams exceed the caches ([`PREFETCH_FROM`]): the vector loops prefetch
    /// ahead of the block they skin.
    pub(crate) prefetch: bool,
    pub(crate) rest_positions: &'a [Vec3],
    pub(crate) rest_normals: &'a [Vec3],
    pub(crate) rest_tangents: &'a [Vec4],
    pub(crate) out_positions: &'a mut [Vec3],
    pub(crate) out_normals: &'a mut [Vec3],
    pub(crate) out_tangents: &'a mut [Vec4],
}

impl<'a> Span<'a> {
    pub(crate) fn len(&self) -> usize {
        self.out_positions.len()
    }

    /// The blocks of [`INFLUENCE_BLOCK`] vertices: each range with the influences its rows
    /// use, at most `k`.
    pub(crate) fn blocks(
        &self,
        k: usize,
    ) -> impl Iterator<Item = (std::ops::Range<usize>, usize)> + use<'a> {
        let count = self.len();
        let blocks: &'a [u32] = self.block_influences;
        blocks.iter().enumerate().map(move |(b, &used)| {
            let start = b * INFLUENCE_BLOCK;
            (
                start..(start + INFLUENCE_BLOCK).min(count),
                (used as usize).min(k),
            )
        })
    }

    /// Runs of consecutive blocks that use the same number of influences (at most `k`):
    /// each range of vertices with that number. Grouped by influence count
    /// ([`crate::VertexOrder::by_influence_count`]), a window's blocks form a few runs.
    pub(crate) fn runs(
        &self,
        k: usize,
    ) -> impl Iterator<Item = (std::ops::Range<usize>, usize)> + use<'a> {
        let count = self.len();
        let blocks: &'a [u32] = self.block_influences;
        let used = move |b: usize| (blocks[b] as usize).min(k);
        let mut start = 0;
        std::iter::from_fn(move || {
            if start == blocks.len() {
                return None;
            }
            let influences = used(start);
            let end = (start + 1..blocks.len())
                .find(|&b| used(b) != influences)
                .unwrap_or(blocks.len());
            let vertices = start * INFLUENCE_BLOCK..(end * INFLUENCE_BLOCK).min(count);
            start = end;
            Some((vertices, influences))
        })
    }

    /// The first `mid` vertices (a multiple of [`INFLUENCE_BLOCK`]) and the rest (`k`
    /// influences per vertex).
    fn split_at(self, mid: usize, k: usize) -> (Span<'a>, Span<'a>) {
        debug_assert!(mid.is_multiple_of(INFLUENCE_BLOCK));
        fn cut<T>(s: &[T], at: usize) -> (&[T], &[T]) {
            s.split_at(at.min(s.len()))
        }
        fn cut_mut<T>(s: &mut [T], at: usize) -> (&mut [T], &mut [T]) {
            let at = at.min(s.len());
            s.split_at_mut(at)
        }
        let (joints_a, joints_b) = cut(self.joints, mid * k);
        let (weights_a, weights_b) = cut(self.weights, mid * (k - 1));
        let (quantised_a, quantised_b) = self.quantised.split_at(mid * (k - 1));
        let (blocks_a, blocks_b) = cut(self.block_influences, mid / INFLUENCE_BLOCK);
        let (rest_p_a, rest_p_b) = cut(self.rest_positions, mid);
        let (rest_n_a, rest_n_b) = cut(self.rest_normals, mid);
        let (rest_t_a, rest_t_b) = cut(self.rest_tangents, mid);
        let (out_p_a, out_p_b) = cut_mut(self.out_positions, mid);
        let (out_n_a, out_n_b) = cut_mut(self.out_normals, mid);
        let (out_t_a, out_t_b) = cut_mut(self.out_tangents, mid);
        (
            Span {
                joints: joints_a,
                weights: weights_a,
                quantised: quantised_a,
                block_influences: blocks_a,
                hemispheres_agree: self.hemispheres_agree,
                prefetch: self.prefetch,
                rest_positions: rest_p_a,
                rest_normals: rest_n_a,
                rest_tangents: rest_t_a,
                out_positions: out_p_a,
                out_normals: out_n_a,
                out_tangents: out_t_a,
            },
            Span {
                joints: joints_b,
                weights: weights_b,
                quantised: quantised_b,
                block_influences: blocks_b,
                hemispheres_agree: self.hemispheres_agree,
                prefetch: self.prefetch,
                rest_positions: rest_p_b,
                rest_normals: rest_n_b,
                rest_tangents: rest_t_b,
                out_positions: out_p_b,
                out_normals: out_n_b,
                out_tangents: out_t_b,
            },
        )
    }
}

/// A loop over a span: palette, influences per vertex, the span.
pub(crate) type Kernel<B> = fn(&[B], usize, Span);

/// The loop `$kernel::<[$ty,] K, NORMALS, TANGENTS>` specialised for the influence count
/// `$k` (1, 2, 3, 4, or 0 for any other count read at run time) and the optional streams
/// present, as ozz-animation specialises its SkinningJob.
macro_rules! specialise {
    ($kernel:ident $(, $ty:ty)?; $k:expr, $normals:expr, $tangents:expr) => {
        match ($k, $normals, $tangents) {
            (1, false, _) => $kernel::<$($ty,)? 1, false, false> as $crate::skinning_job::Kernel<_>,
            (1, true, false) => $kernel::<$($ty,)? 1, true, false>,
            (1, true, true) => $kernel::<$($ty,)? 1, true, true>,
            (2, false, _) => $kernel::<$($ty,)? 2, false, false>,
            (2, true, false) => $kernel::<$($ty,)? 2, true, false>,
            (2, true, true) => $kernel::<$($ty,)? 2, true, true>,
            (3, false, _) => $kernel::<$($ty,)? 3, false, false>,
            (3, true, false) => $kernel::<$($ty,)? 3, true, false>,
            (3, true, true) => $kernel::<$($ty,)? 3, true, true>,
            (4, false, _) => $kernel::<$($ty,)? 4, false, false>,
            (4, true, false) => $kernel::<$($ty,)? 4, true, false>,
            (4, true, true) => $kernel::<$($ty,)? 4, true, true>,
            (_, false, _) => $kernel::<$($ty,)? 0, false, false>,
            (_, true, false) => $kernel::<$($ty,)? 0, true, false>,
            (_, true, true) => $kernel::<$($ty,)? 0, true, true>,
        }
    };
}
pub(crate) use specialise;

/// Picks the loop for the influence count and streams: the vector loop of `set` when
/// there is one, else the portable loop ([`skin_span`]).
fn dispatch<B: Blend>(
    palette: &[B],
    k: usize,
    threading: Threading,
    span: Span,
    set: InstructionSet,
) {
    let normals = !span.out_normals.is_empty();
    let tangents = !span.out_tangents.is_empty();
    let kernel = simd_kernel::<B>(set, k, normals, tangents)
        .unwrap_or_else(|| portable_kernel::<B>(k, normals, tangents));
    match threading {
        Threading::Sequential => run_dequantised(palette, k, span, kernel),
        Threading::Parallel => run_parallel(palette, k, span, kernel),
    }
}

/// Vertices per piece of [`run_dequantised`]: the widened weights of a piece
/// (≤ 64 × 7 floats, 1.8 KB) stay in the first-level cache.
const DEQUANTISED_PIECE: usize = 64;
const _: () = assert!(DEQUANTISED_PIECE.is_multiple_of(INFLUENCE_BLOCK));

/// Runs `kernel` on the span; with quantised weights, piece by piece of
/// [`DEQUANTISED_PIECE`] vertices, each piece's weights first widened to floats in a
/// buffer on the stack (the loops then read floats as ever; nothing is allocated).
fn run_dequantised<B: Blend>(palette: &[B], k: usize, span: Span, kernel: Kernel<B>) {
    if matches!(span.quantised, Quantised::None) {
        kernel(palette, k, span);
        return;
    }
    let mut widened = [0.0f32; DEQUANTISED_PIECE * (MAX_QUANTISED_INFLUENCES - 1)];
    let mut rest = span;
    while rest.len() > 0 {
        let (piece, tail) = rest.split_at(DEQUANTISED_PIECE, k);
        let explicit = piece.len() * (k - 1);
        piece.quantised.widen_into(&mut widened[..explicit]);
        kernel(
            palette,
            k,
            Span {
                weights: &widened[..explicit],
                quantised: Quantised::None,
                ..piece
            },
        );
        rest = tail;
    }
}

/// The portable loop for the influence count and streams.
fn portable_kernel<B: Blend>(k: usize, normals: bool, tangents: bool) -> Kernel<B> {
    specialise!(skin_span, B; k, normals, tangents)
}

/// Halves the span until it has at most [`PARALLEL_CHUNK`] vertices, running the halves
/// with `rayon::join` (work stealing balances the chunks; nothing is allocated).
///
/// This is what `par_chunks_mut` over vertex chunks does inside rayon (its producers split
/// in halves and join), written out because a span is up to eight slices of different
/// strides (K joints and K − 1 weights per vertex) of which the normal and tangent
/// streams may be empty, and a zip of `par_chunks_mut` stops at its shortest input (an
/// empty stream has no chunk): zipping would need one loop per set of present streams.
fn run_parallel<B: Blend>(palette: &[B], k: usize, span: Span, kernel: Kernel<B>) {
    if span.len() <= PARALLEL_CHUNK {
        run_dequantised(palette, k, span, kernel);
        return;
    }
    let chunks = span.len().div_ceil(PARALLEL_CHUNK);
    let (a, b) = span.split_at(chunks / 2 * PARALLEL_CHUNK, k);
    rayon::join(
        || run_parallel(palette, k, a, kernel),
        || run_parallel(palette, k, b, kernel),
    );
}

/// The hot loop. `K` is the influence count, or 0 for "read `k`"; `NORMALS` and
/// `TANGENTS` say which optional streams exist. Trusts the validated lengths.
#[inline(never)]
fn skin_span<B: Blend, const K: usize, const NORMALS: bool, const TANGENTS: bool>(
    palette: &[B],
    k: usize,
    span: Span,
) {
    let k = if K == 0 { k } else { K };
    let joint_rows = span.joints.chunks_exact(k);
    let explicit_len = k - 1;
    for (v, joints) in joint_rows.enumerate() {
        let explicit = &span.weights[v * explicit_len..(v + 1) * explicit_len];
        let m = B::blend(palette, joints, explicit);
        span.out_positions[v] = m.transform_point3(span.rest_positions[v]);
        if NORMALS {
            span.out_normals[v] = m.transform_vector3(span.rest_normals[v]);
        }
        if TANGENTS {
            let t = span.rest_tangents[v];
            span.out_tangents[v] = m.transform_vector3(t.truncate()).extend(t.w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random_pose::{random_rotations, SplitMix64};
    use crate::VertexWeights;

    /// Runs the portable loop directly on every stream.
    fn run_portable<B: Blend>(
        palette: &[B],
        skin: &CompactSkin,
        rest: &[Vec3],
        tangents: &[Vec4],
    ) -> (Vec<Vec3>, Vec<Vec3>, Vec<Vec4>) {
        let n = rest.len();
        let (mut p, mut nn, mut t) = (
            vec![Vec3::ZERO; n],
            vec![Vec3::ZERO; n],
            vec![Vec4::ZERO; n],
        );
        let span = Span {
            joints: skin.joints(),
            weights: match skin.stored_weights() {
                StoredWeights::Float32(w) => w,
                _ => unreachable!("the tests of this module use float weights"),
            },
            quantised: Quantised::None,
            block_influences: skin.block_influences(),
            hemispheres_agree: false,
            prefetch: false,
            rest_positions: rest,
            rest_normals: rest,
            rest_tangents: tangents,
            out_positions: &mut p,
            out_normals: &mut nn,
            out_tangents: &mut t,
        };
        portable_kernel::<B>(skin.influences(), true, true)(palette, skin.influences(), span);
        (p, nn, t)
    }

    /// Every instruction set's loops this CPU runs and the portable loops agree to
    /// round-off for every influence count and both methods.
    #[test]
    fn vector_and_portable_loops_agree() {
        let mut rng = SplitMix64::new(11);
        let joints = 9;
        let rest: Vec<Vec3> = (0..500).map(|_| rng.unit_vector()).collect();
        let tangents: Vec<Vec4> = rest
            .iter()
            .map(|v| v.any_orthonormal_vector().extend(1.0))
            .collect();
        let matrices: Vec<Mat4> = random_rotations(joints, 3.0, 5)
            .into_iter()
            .map(|q| Mat4::from_rotation_translation(q, rng.unit_vector()))
            .collect();
        for k in 1..=6 {
            let weights = VertexWeights::from_rows((0..rest.len()).map(|_| {
                (0..k)
                    .map(|_| {
                        (
                            (rng.next_u64() % joints as u64) as u32,
                            0.05 + rng.next_f64() as f32,
                        )
                    })
                    .collect::<Vec<_>>()
            }));
            let skin = CompactSkin::new(&weights, joints, k).unwrap();
            let sets = InstructionSet::ALL.into_iter().filter(|s| s.is_supported());
            for (method, set) in sets.flat_map(|set| {
                [SkinningMethod::LinearBlend, SkinningMethod::DualQuaternion].map(|m| (m, set))
            }) {
                let mut palette = SkinningPalette::new(joints);
                palette.update(&matrices, method).unwrap();
                let n = rest.len();
                let (mut p, mut nn, mut t) = (
                    vec![Vec3::ZERO; n],
                    vec![Vec3::ZERO; n],
                    vec![Vec4::ZERO; n],
                );
                SkinningJob {
                    skin: &skin,
                    palette: &palette,
                    threading: Threading::Sequential,
                    rest_positions: &rest,
                    rest_normals: Some(&rest),
                    rest_tangents: Some(&tangents),
                    out_positions: &mut p,
                    out_normals: Some(&mut nn),
                    out_tangents: Some(&mut t),
                }
                .run_with(set)
                .unwrap();
                let expected = match method {
                    SkinningMethod::LinearBlend => {
                        run_portable(palette.matrices(), &skin, &rest, &tangents)
                    }
                    SkinningMethod::DualQuaternion => {
                        run_portable(palette.dual_quaternions(), &skin, &rest, &tangents)
                    }
                };
                for v in 0..n {
                    assert!(
                        p[v].abs_diff_eq(expected.0[v], 1e-5),
                        "k {k} {method:?} {set:?} position {v}"
                    );
                    assert!(
                        nn[v].abs_diff_eq(expected.1[v], 1e-5),
                        "k {k} {method:?} {set:?} normal {v}"
                    );
                    assert!(
                        t[v].abs_diff_eq(expected.2[v], 1e-5),
                        "k {k} {method:?} {set:?} tangent {v}"
                    );
                }
            }
        }
    }
}

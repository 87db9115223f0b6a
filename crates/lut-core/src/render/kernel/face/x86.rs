//! x86-64 cube-face positions (see `face/mod.rs`): the face coordinates of 8
//! (AVX-512), 4 (AVX2) or 2 (SSE) pixels per `f64` vector, computed with the scalar
//! twin's operations in its order and rounded as it rounds them, written out as the row
//! kernels' Q.8 positions (nearest: the texel; bilinear: Q.16 then Q.8). AVX-512 takes 16
//! pixels per step (two `f64` vectors); the division then runs 8 lanes wide.
//!
//! Written once (`face_kernels!`) as the row kernels are (`row/x86.rs`): each
//! instruction set's module names its intrinsics with short aliases (`add_pd` is
//! `_mm256_add_pd` in `avx2`, `_mm_add_pd` in `sse41`; `V` the i32 vector of `N` lanes,
//! `D` the f64 vector of `N / 2`, `H` the rounded coordinates of one `D`) and holds what
//! differs in more than the prefix: joining two halves' coordinates (`join`), the lane
//! offsets (`iota_pd`).

#![allow(unsafe_code)]

use super::FaceRun;
use crate::geom::fixed::FX_ONE;
use crate::render::kernel::select::{Kernel, SelectedKernel};
use std::arch::x86_64::*;

/// The bordered Q.8 positions of a face run's first `m` pixels with a SIMD kernel (see
/// `face/mod.rs`; whole vectors written: `u` and `v` hold `m` rounded up to 16),
/// and the largest `v`; `None` (nothing written) for the scalar one.
#[inline(always)]
pub(super) fn positions<const BILINEAR: bool>(
    k: SelectedKernel,
    n: usize,
    r: &FaceRun,
    u: &mut [i32],
    v: &mut [i32],
    m: usize,
) -> Option<i32> {
    let whole = m.next_multiple_of(16);
    assert!(
        u.len() >= whole && v.len() >= whole,
        "position buffers too short"
    );
    Some(match k.0 {
        // SAFETY: `k` is a `SelectedKernel`, made only when the CPU runs the kernel; the
        // buffers hold whole vectors past `m` (asserted above).
        Kernel::Avx512 => unsafe { avx512::positions::<BILINEAR>(n, r, u, v, m) },
        // SAFETY: as above.
        Kernel::Avx2 => unsafe { avx2::positions::<BILINEAR>(n, r, u, v, m) },
        // SAFETY: as above.
        Kernel::Sse41 => unsafe { sse41::positions::<BILINEAR>(n, r, u, v, m) },
        Kernel::Scalar => return None,
    })
}

/// The face positions of one instruction set (`$feature`), in terms of the names its
/// module defines (see the module docs).
macro_rules! face_kernels {
    ($feature:literal) => {
        /// Face coordinates of the N / 2 pixels at lane offsets `i` (f64, from the run's
        /// start), as the scalar twin rounds them: Q.16 (`BILINEAR`, not yet biased) or
        /// whole texels; in the low lanes of the result.
        #[inline]
        #[target_feature(enable = $feature)]
        fn uv<const BILINEAR: bool>(r: &FaceRun, n: f64, i: D) -> (H, H) {
            let s = set1_pd;
            let dx = add_pd(s(r.dx), i);
            let a = add_pd(s(r.p[0]), mul_pd(dx, s(r.d[0])));
            let b = add_pd(s(r.p[1]), mul_pd(dx, s(r.d[1])));
            let m = add_pd(s(r.p[2]), mul_pd(dx, s(r.d[2])));
            let half = s(r.half);
            let q = div_pd(half, m);
            let u = add_pd(half, mul_pd(a, q));
            let v = sub_pd(half, mul_pd(b, q));
            // max(x, 0) gives 0 for NaN (the second operand), as f64::max does.
            let clamp = |x: D| min_pd(max_pd(x, zero_pd()), s(n));
            let fx = |x: D| {
                if BILINEAR {
                    cvtt_pd(add_pd(mul_pd(clamp(x), s(FX_ONE as f64)), s(0.5)))
                } else {
                    cvtt_pd(clamp(x))
                }
            };
            (fx(u), fx(v))
        }

        /// The bordered Q.8 positions of the run's pixels 0..m, N per step, whole vectors
        /// (the caller's buffers hold `m` rounded up to 16; lanes past `m` repeat pixel
        /// m − 1), and the largest `v`: bilinear `(q16 + FX_ONE) >> 8` of `uv`'s Q.16,
        /// nearest `(min(texel, n − 1) + 1) << 8` of its whole texels.
        ///
        /// # Safety
        /// `u` and `v` hold at least `m` rounded up to N entries.
        #[target_feature(enable = $feature)]
        pub(super) unsafe fn positions<const BILINEAR: bool>(
            n: usize,
            r: &FaceRun,
            u: &mut [i32],
            v: &mut [i32],
            m: usize,
        ) -> i32 {
            let (half, step) = (set1_pd((N / 2) as f64), set1_pd(N as f64));
            // Lane offsets past the end clamped to m − 1 (small whole numbers: exact).
            let last = set1_pd(m.saturating_sub(1) as f64);
            let (one, texel, side) = (set1(FX_ONE as i32), set1(1), set1(n as i32 - 1));
            let q8 = |x: V| {
                if BILINEAR {
                    srai::<8>(add(x, one))
                } else {
                    slli::<8>(add(min(x, side), texel))
                }
            };
            let mut top = set1(i32::MIN);
            let mut fi = iota_pd();
            let mut i = 0;
            while i < m {
                let (lo, hi) = (min_pd(fi, last), min_pd(add_pd(fi, half), last));
                let (u0, v0) = uv::<BILINEAR>(r, n as f64, lo);
                let (u1, v1) = uv::<BILINEAR>(r, n as f64, hi);
                let pu = q8(join(u0, u1));
                let pv = q8(join(v0, v1));
                top = max(top, pv);
                // SAFETY: i < m, so i + N ≤ m rounded up to N ≤ the buffers' lengths (the
                // caller's contract); unaligned stores.
                unsafe {
                    storeu(u.as_mut_ptr().add(i).cast(), pu);
                    storeu(v.as_mut_ptr().add(i).cast(), pv);
                }
                fi = add_pd(fi, step);
                i += N;
            }
            let mut lanes = [0i32; N];
            // SAFETY: `lanes` is N writable i32; unaligned store.
            unsafe { storeu(lanes.as_mut_ptr().cast(), top) };
            lanes.into_iter().max().unwrap_or(i32::MIN)
        }
    };
}

mod avx2 {
    use super::*;
    use std::arch::x86_64::{
        __m256d as D, __m256i as V, _mm256_add_epi32 as add, _mm256_add_pd as add_pd,
        _mm256_cvttpd_epi32 as cvtt_pd, _mm256_div_pd as div_pd, _mm256_max_epi32 as max,
        _mm256_max_pd as max_pd, _mm256_min_epi32 as min, _mm256_min_pd as min_pd,
        _mm256_mul_pd as mul_pd, _mm256_set1_epi32 as set1, _mm256_set1_pd as set1_pd,
        _mm256_setzero_pd as zero_pd, _mm256_slli_epi32 as slli, _mm256_srai_epi32 as srai,
        _mm256_storeu_si256 as storeu, _mm256_sub_pd as sub_pd,
    };

    /// Pixels per step.
    const N: usize = 8;
    /// The rounded coordinates of one `D` (4 lanes).
    type H = __m128i;

    face_kernels!("avx2");

    /// The lane offsets of the first half: 0, 1, 2, 3.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn iota_pd() -> D {
        _mm256_setr_pd(0.0, 1.0, 2.0, 3.0)
    }

    /// The two halves' coordinates (4 lanes each) as one vector.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn join(lo: __m128i, hi: __m128i) -> V {
        _mm256_set_m128i(hi, lo)
    }
}

mod avx512 {
    use super::*;
    use std::arch::x86_64::{
        __m512d as D, __m512i as V, _mm512_add_epi32 as add, _mm512_add_pd as add_pd,
        _mm512_cvttpd_epi32 as cvtt_pd, _mm512_div_pd as div_pd, _mm512_max_epi32 as max,
        _mm512_max_pd as max_pd, _mm512_min_epi32 as min, _mm512_min_pd as min_pd,
        _mm512_mul_pd as mul_pd, _mm512_set1_epi32 as set1, _mm512_set1_pd as set1_pd,
        _mm512_setzero_pd as zero_pd, _mm512_slli_epi32 as slli, _mm512_srai_epi32 as srai,
        _mm512_storeu_si512 as storeu, _mm512_sub_pd as sub_pd,
    };

    /// Pixels per step.
    const N: usize = 16;
    /// The rounded coordinates of one `D` (8 lanes).
    type H = __m256i;

    face_kernels!("avx2,avx512f,avx512bw,avx512vl,avx512dq");

    /// The lane offsets of the first half: 0..8.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn iota_pd() -> D {
        _mm512_setr_pd(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0)
    }

    /// The two halves' coordinates (8 lanes each) as one vector.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn join(lo: __m256i, hi: __m256i) -> V {
        _mm512_inserti64x4::<1>(_mm512_castsi256_si512(lo), hi)
    }
}

mod sse41 {
    use super::*;
    use std::arch::x86_64::{
        __m128d as D, __m128i as V, _mm_add_epi32 as add, _mm_add_pd as add_pd,
        _mm_cvttpd_epi32 as cvtt_pd, _mm_div_pd as div_pd, _mm_max_epi32 as max,
        _mm_max_pd as max_pd, _mm_min_epi32 as min, _mm_min_pd as min_pd, _mm_mul_pd as mul_pd,
        _mm_set1_epi32 as set1, _mm_set1_pd as set1_pd, _mm_setzero_pd as zero_pd,
        _mm_slli_epi32 as slli, _mm_srai_epi32 as srai, _mm_storeu_si128 as storeu,
        _mm_sub_pd as sub_pd,
    };

    /// Pixels per step.
    const N: usize = 4;
    /// The rounded coordinates of one `D` (2 low lanes).
    type H = __m128i;

    face_kernels!("sse4.1");

    /// The lane offsets of the first half: 0, 1.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn iota_pd() -> D {
        _mm_setr_pd(0.0, 1.0)
    }

    /// The two halves' coordinates (2 low lanes each) as one vector.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn join(lo: __m128i, hi: __m128i) -> V {
        _mm_unpacklo_epi64(lo, hi)
    }
}

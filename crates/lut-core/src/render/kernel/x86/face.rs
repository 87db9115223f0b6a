//! x86-64 cube-face runs (see `kernel/face.rs`): the face coordinates of 4 (AVX2) or 2
//! (SSE) pixels per `f64` vector, computed with the scalar twin's operations in its
//! order, rounded to Q.16 as it rounds them, then the map kernels' gather and blend
//! (`bilinear8` / `bilinear4` on absolute positions: base 0) or a nearest fetch.

use super::super::face::{face_side, FaceRun};
use super::row::PREFETCH_AHEAD;
use super::{padded, Kernel, Local, Selected, Texels};
use crate::geom::fixed::{FX_HALF, FX_ONE};
use std::arch::x86_64::*;

/// The face run with a SIMD kernel (`BLEND`: bilinear blended into `out` by `frac`);
/// `false` (nothing written) for the scalar one.
#[inline(always)]
pub(in super::super) fn face_span<const BILINEAR: bool, const BLEND: bool>(
    k: Selected,
    t: &Texels,
    r: &FaceRun,
    out: &mut [u32],
    frac: u32,
) -> bool {
    match k.0 {
        // SAFETY: `k` is a `Selected`, made only when the CPU runs the kernel.
        Kernel::Avx2 => unsafe { avx2::face::<BILINEAR, BLEND>(t, r, out, frac) },
        // SAFETY: as above.
        Kernel::Sse41 => unsafe { sse41::face::<BILINEAR, BLEND>(t, r, out, frac) },
        Kernel::Scalar => return false,
    }
    true
}

/// A [`Local`] for absolute positions in the face's texels (base 0): lane indices are
/// clamped into `[0, len − stride − 2]`, so every 2×2 read stays in the slice.
#[inline(always)]
fn absolute(t: &Texels) -> Local {
    Local {
        base: 0,
        fu: 0,
        fv: 0,
        du: 0,
        dv: 0,
        hi: (t.px.len() - t.stride() - 2) as i32,
        lo: 0,
    }
}

/// Prefetch the cache lines pixel `i` of the run (of `m` pixels) will read, as the row
/// kernels do ([`super::row::PREFETCH_AHEAD`] pixels ahead, see there why): its face
/// position from the run's projective line (as the kernels compute it, without their
/// rounding: a line off by one texel is prefetched at worst), its texel and for bilinear
/// the one below. Pixels past the run or behind the face are skipped.
#[inline(always)]
fn prefetch<const BILINEAR: bool>(t: &Texels, r: &FaceRun, i: usize, m: usize) {
    if i >= m {
        return;
    }
    let dx = r.dx + i as f64;
    let den = r.p[2] + dx * r.d[2];
    if den.is_nan() || den <= 0.0 {
        return;
    }
    let q = r.half / den;
    let n = face_side(t) as f64;
    let u = (r.half + (r.p[0] + dx * r.d[0]) * q).clamp(0.0, n);
    let v = (r.half - (r.p[1] + dx * r.d[1]) * q).clamp(0.0, n);
    let stride = t.stride();
    let at = t.px.as_ptr().wrapping_add(v as usize * stride + u as usize);
    // SAFETY: SSE is part of every x86-64 CPU; a prefetch reads nothing the program sees
    // and never faults, whatever the address.
    unsafe {
        _mm_prefetch::<_MM_HINT_T0>(at.cast());
        if BILINEAR {
            _mm_prefetch::<_MM_HINT_T0>(at.wrapping_add(stride).cast());
        }
    }
}

/// [`prefetch`] the first [`PREFETCH_AHEAD`] pixels of a run before drawing it.
#[inline(always)]
fn prefetch_start<const BILINEAR: bool>(t: &Texels, r: &FaceRun, m: usize) {
    for i in (0..PREFETCH_AHEAD.min(m)).step_by(8) {
        prefetch::<BILINEAR>(t, r, i, m);
    }
}

mod avx2 {
    use super::super::avx2::{bilinear8, lerp, merge, split};
    use super::*;

    /// Face coordinates of the 4 pixels at lane offsets `i` (f64, from the run's start),
    /// as the scalar twin rounds them: Q.16 (`BILINEAR`, not yet biased) or whole texels.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn uv4<const BILINEAR: bool>(r: &FaceRun, n: f64, i: __m256d) -> (__m128i, __m128i) {
        let s = _mm256_set1_pd;
        let dx = _mm256_add_pd(s(r.dx), i);
        let a = _mm256_add_pd(s(r.p[0]), _mm256_mul_pd(dx, s(r.d[0])));
        let b = _mm256_add_pd(s(r.p[1]), _mm256_mul_pd(dx, s(r.d[1])));
        let m = _mm256_add_pd(s(r.p[2]), _mm256_mul_pd(dx, s(r.d[2])));
        let half = s(r.half);
        let q = _mm256_div_pd(half, m);
        let u = _mm256_add_pd(half, _mm256_mul_pd(a, q));
        let v = _mm256_sub_pd(half, _mm256_mul_pd(b, q));
        // max(x, 0) gives 0 for NaN (the second operand), as f64::max does.
        let clamp = |x: __m256d| _mm256_min_pd(_mm256_max_pd(x, _mm256_setzero_pd()), s(n));
        let fx = |x: __m256d| {
            if BILINEAR {
                let y = _mm256_add_pd(_mm256_mul_pd(clamp(x), s(FX_ONE as f64)), s(0.5));
                _mm256_cvttpd_epi32(y)
            } else {
                _mm256_cvttpd_epi32(clamp(x))
            }
        };
        (fx(u), fx(v))
    }

    /// 8 pixels at lane offsets `lo` (lanes 0..4) and `hi` (4..8): bilinear (merged
    /// 0RGB) or nearest.
    #[inline]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments)]
    fn px8<const BILINEAR: bool, const BLEND: bool>(
        t: &Texels,
        r: &FaceRun,
        l: &Local,
        prev: __m256i,
        w: (__m256i, __m256i),
        lo: __m256d,
        hi: __m256d,
    ) -> __m256i {
        let n = face_side(t);
        let stride = t.stride();
        let (u0, v0) = uv4::<BILINEAR>(r, n as f64, lo);
        let (u1, v1) = uv4::<BILINEAR>(r, n as f64, hi);
        let (u, v) = (_mm256_set_m128i(u1, u0), _mm256_set_m128i(v1, v0));
        if BILINEAR {
            // + ½ texel: the border's +1 and the centres' −½ (CubeMap::bilinear).
            let h = _mm256_set1_epi32(FX_HALF as i32);
            let c = bilinear8(
                t.px,
                stride,
                l,
                _mm256_add_epi32(u, h),
                _mm256_add_epi32(v, h),
            );
            return if BLEND {
                merge(lerp(split(prev), c, w))
            } else {
                merge(c)
            };
        }
        let last = _mm256_set1_epi32(n as i32 - 1);
        let (x, y) = (_mm256_min_epi32(u, last), _mm256_min_epi32(v, last));
        let k = _mm256_add_epi32(
            _mm256_mullo_epi32(y, _mm256_set1_epi32(stride as i32)),
            _mm256_add_epi32(x, _mm256_set1_epi32(stride as i32 + 1)),
        );
        let k = _mm256_min_epi32(
            _mm256_max_epi32(k, _mm256_setzero_si256()),
            _mm256_set1_epi32(t.px.len() as i32 - 1),
        );
        let mut a = [0i32; 8];
        // SAFETY: `a` is 32 writable bytes; the store is unaligned.
        unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), k) };
        let p = t.px.as_ptr();
        // SAFETY: each a[j] is clamped to [0, len − 1] just above.
        let g = |j: usize| unsafe { p.add(a[j] as usize).read() } as i32;
        _mm256_setr_epi32(g(0), g(1), g(2), g(3), g(4), g(5), g(6), g(7))
    }

    /// The run, 8 pixels per step (`BLEND`: blended into `out` by `frac`); the tail's
    /// lanes past the end repeat the last pixel.
    #[target_feature(enable = "avx2")]
    pub(super) fn face<const BILINEAR: bool, const BLEND: bool>(
        t: &Texels,
        r: &FaceRun,
        out: &mut [u32],
        frac: u32,
    ) {
        let m = out.len();
        let l = absolute(t);
        let fw = _mm256_set1_epi32((frac as i32) * 0x10001);
        let w = (fw, _mm256_sub_epi16(_mm256_set1_epi16(256), fw));
        let (four, eight) = (_mm256_set1_pd(4.0), _mm256_set1_pd(8.0));
        let mut fi = _mm256_setr_pd(0.0, 1.0, 2.0, 3.0);
        prefetch_start::<BILINEAR>(t, r, m);
        let mut i = 0;
        while i + 8 <= m {
            prefetch::<BILINEAR>(t, r, i + PREFETCH_AHEAD, m);
            let q = out[i..i + 8].as_mut_ptr().cast::<__m256i>();
            let prev = if BLEND {
                // SAFETY: `q` points at 8 u32 of `out` (the slice above); unaligned load.
                unsafe { _mm256_loadu_si256(q) }
            } else {
                _mm256_setzero_si256()
            };
            let c = px8::<BILINEAR, BLEND>(t, r, &l, prev, w, fi, _mm256_add_pd(fi, four));
            // SAFETY: as above; unaligned store.
            unsafe { _mm256_storeu_si256(q, c) };
            fi = _mm256_add_pd(fi, eight);
            i += 8;
        }
        if i < m {
            // Lane offsets past the end clamped to m − 1 (small whole numbers: exact).
            let last = _mm256_set1_pd((m - 1) as f64);
            let (lo, hi) = (
                _mm256_min_pd(fi, last),
                _mm256_min_pd(_mm256_add_pd(fi, four), last),
            );
            let tail = &mut out[i..];
            let mut buf = padded::<8>(tail);
            let q = buf.as_mut_ptr().cast::<__m256i>();
            // SAFETY: `buf` holds 8 u32; unaligned load.
            let prev = unsafe { _mm256_loadu_si256(q) };
            let c = px8::<BILINEAR, BLEND>(t, r, &l, prev, w, lo, hi);
            // SAFETY: as above; unaligned store.
            unsafe { _mm256_storeu_si256(q, c) };
            let n = tail.len();
            tail.copy_from_slice(&buf[..n]);
        }
    }
}

mod sse41 {
    use super::super::sse41::{bilinear4, lerp, merge, split};
    use super::*;

    /// [`super::avx2`]'s `uv4` for 2 pixels.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn uv2<const BILINEAR: bool>(r: &FaceRun, n: f64, i: __m128d) -> (__m128i, __m128i) {
        let s = _mm_set1_pd;
        let dx = _mm_add_pd(s(r.dx), i);
        let a = _mm_add_pd(s(r.p[0]), _mm_mul_pd(dx, s(r.d[0])));
        let b = _mm_add_pd(s(r.p[1]), _mm_mul_pd(dx, s(r.d[1])));
        let m = _mm_add_pd(s(r.p[2]), _mm_mul_pd(dx, s(r.d[2])));
        let half = s(r.half);
        let q = _mm_div_pd(half, m);
        let u = _mm_add_pd(half, _mm_mul_pd(a, q));
        let v = _mm_sub_pd(half, _mm_mul_pd(b, q));
        // max(x, 0) gives 0 for NaN (the second operand), as f64::max does.
        let clamp = |x: __m128d| _mm_min_pd(_mm_max_pd(x, _mm_setzero_pd()), s(n));
        let fx = |x: __m128d| {
            if BILINEAR {
                _mm_cvttpd_epi32(_mm_add_pd(_mm_mul_pd(clamp(x), s(FX_ONE as f64)), s(0.5)))
            } else {
                _mm_cvttpd_epi32(clamp(x))
            }
        };
        (fx(u), fx(v))
    }

    /// 4 pixels at lane offsets `lo` (lanes 0..2) and `hi` (2..4).
    #[inline]
    #[target_feature(enable = "sse4.1")]
    #[allow(clippy::too_many_arguments)]
    fn px4<const BILINEAR: bool, const BLEND: bool>(
        t: &Texels,
        r: &FaceRun,
        l: &Local,
        prev: __m128i,
        w: (__m128i, __m128i),
        lo: __m128d,
        hi: __m128d,
    ) -> __m128i {
        let n = face_side(t);
        let stride = t.stride();
        let (u0, v0) = uv2::<BILINEAR>(r, n as f64, lo);
        let (u1, v1) = uv2::<BILINEAR>(r, n as f64, hi);
        let (u, v) = (_mm_unpacklo_epi64(u0, u1), _mm_unpacklo_epi64(v0, v1));
        if BILINEAR {
            let h = _mm_set1_epi32(FX_HALF as i32);
            let c = bilinear4(t.px, stride, l, _mm_add_epi32(u, h), _mm_add_epi32(v, h));
            return if BLEND {
                merge(lerp(split(prev), c, w))
            } else {
                merge(c)
            };
        }
        let last = _mm_set1_epi32(n as i32 - 1);
        let (x, y) = (_mm_min_epi32(u, last), _mm_min_epi32(v, last));
        let k = _mm_add_epi32(
            _mm_mullo_epi32(y, _mm_set1_epi32(stride as i32)),
            _mm_add_epi32(x, _mm_set1_epi32(stride as i32 + 1)),
        );
        let k = _mm_min_epi32(
            _mm_max_epi32(k, _mm_setzero_si128()),
            _mm_set1_epi32(t.px.len() as i32 - 1),
        );
        let mut a = [0i32; 4];
        // SAFETY: `a` is 16 writable bytes; the store is unaligned.
        unsafe { _mm_storeu_si128(a.as_mut_ptr().cast(), k) };
        let p = t.px.as_ptr();
        // SAFETY: each a[j] is clamped to [0, len − 1] just above.
        let g = |j: usize| unsafe { p.add(a[j] as usize).read() } as i32;
        _mm_setr_epi32(g(0), g(1), g(2), g(3))
    }

    /// The run, 4 pixels per step (see [`super::avx2`]'s `face`).
    #[target_feature(enable = "sse4.1")]
    pub(super) fn face<const BILINEAR: bool, const BLEND: bool>(
        t: &Texels,
        r: &FaceRun,
        out: &mut [u32],
        frac: u32,
    ) {
        let m = out.len();
        let l = absolute(t);
        let fw = _mm_set1_epi32((frac as i32) * 0x10001);
        let w = (fw, _mm_sub_epi16(_mm_set1_epi16(256), fw));
        let (two, four) = (_mm_set1_pd(2.0), _mm_set1_pd(4.0));
        let mut fi = _mm_setr_pd(0.0, 1.0);
        prefetch_start::<BILINEAR>(t, r, m);
        let mut i = 0;
        while i + 4 <= m {
            if i % 8 == 0 {
                prefetch::<BILINEAR>(t, r, i + PREFETCH_AHEAD, m);
            }
            let q = out[i..i + 4].as_mut_ptr().cast::<__m128i>();
            let prev = if BLEND {
                // SAFETY: `q` points at 4 u32 of `out` (the slice above); unaligned load.
                unsafe { _mm_loadu_si128(q) }
            } else {
                _mm_setzero_si128()
            };
            let c = px4::<BILINEAR, BLEND>(t, r, &l, prev, w, fi, _mm_add_pd(fi, two));
            // SAFETY: as above; unaligned store.
            unsafe { _mm_storeu_si128(q, c) };
            fi = _mm_add_pd(fi, four);
            i += 4;
        }
        if i < m {
            let last = _mm_set1_pd((m - 1) as f64);
            let (lo, hi) = (_mm_min_pd(fi, last), _mm_min_pd(_mm_add_pd(fi, two), last));
            let tail = &mut out[i..];
            let mut buf = padded::<4>(tail);
            let q = buf.as_mut_ptr().cast::<__m128i>();
            // SAFETY: `buf` holds 4 u32; unaligned load.
            let prev = unsafe { _mm_loadu_si128(q) };
            let c = px4::<BILINEAR, BLEND>(t, r, &l, prev, w, lo, hi);
            // SAFETY: as above; unaligned store.
            unsafe { _mm_storeu_si128(q, c) };
            let n = tail.len();
            tail.copy_from_slice(&buf[..n]);
        }
    }
}

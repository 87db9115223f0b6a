//! x86-64 span kernels: a checked span (`Local`, from the renderer's [`SpanJob`]s) drawn
//! 8 (AVX2) or 4 (SSE4.1) pixels per step, nearest and bilinear, and trilinear as
//! bilinear on a level blended into the one before; the batch entry points compiled
//! under each set's `target_feature`. The texel blend itself (`bilinear8`,
//! `bilinear4`, `split`, `lerp`, `merge`) is the parent module's, shared with the row
//! and face kernels. There are no AVX-512 span kernels: at 8–16 pixels per span a
//! 16-lane vector would be half empty, so `Kernel::Avx512` runs the AVX2 ones (an
//! AVX-512 CPU runs AVX2), and so do the cropped kernels built on them.

use super::super::jobs::{run_jobs, run_tri_jobs};
use super::super::select::{Kernel, Selected};
use super::super::{scalar, SpanJob, Texels};
use super::{padded, Local};
use std::arch::x86_64::*;

/// The batch kernels ([`super::jobs`]) with a SIMD kernel; `None` for the scalar one.
#[inline(always)]
pub(in super::super) fn jobs<const BILINEAR: bool>(
    k: Selected,
    t: &Texels,
    row: &mut [u32],
    jobs: &[SpanJob],
) -> Option<u64> {
    match k.0 {
        // SAFETY: `k` is a `Selected`, made only when the CPU runs the kernel.
        // (No AVX-512 span kernels: AVX-512 CPUs run AVX2, see `Kernel::Avx512`.)
        Kernel::Avx2 | Kernel::Avx512 => Some(unsafe { avx2::jobs::<BILINEAR>(t, row, jobs) }),
        // SAFETY: as above.
        Kernel::Sse41 => Some(unsafe { sse41::jobs::<BILINEAR>(t, row, jobs) }),
        Kernel::Scalar => None,
    }
}

/// The trilinear batch kernels ([`super::tri_jobs`]) with a SIMD kernel; `None` for the
/// scalar one.
#[inline(always)]
pub(in super::super) fn tri_jobs(
    k: Selected,
    levels: &[Texels],
    row: &mut [u32],
    jobs: &[SpanJob],
    lods: &[i32],
) -> Option<u64> {
    match k.0 {
        // SAFETY: `k` is a `Selected`, made only when the CPU runs the kernel.
        // (No AVX-512 span kernels: AVX-512 CPUs run AVX2, see `Kernel::Avx512`.)
        Kernel::Avx2 | Kernel::Avx512 => Some(unsafe { avx2::tri_jobs(levels, row, jobs, lods) }),
        // SAFETY: as above.
        Kernel::Sse41 => Some(unsafe { sse41::tri_jobs(levels, row, jobs, lods) }),
        Kernel::Scalar => None,
    }
}

/// The two batch entry points of one instruction set, written once: `tri_jobs` and `jobs`
/// compiled under that set's `target_feature`, so the span setup, the closures and the
/// module's own `bilinear`/`nearest` inline into one loop per set.
macro_rules! batch_entries {
    ($feature:literal) => {
        /// A batch of trilinear spans (see [`super::super::tri_jobs`]).
        #[target_feature(enable = $feature)]
        pub(super) fn tri_jobs(
            levels: &[Texels],
            row: &mut [u32],
            jobs: &[SpanJob],
            lods: &[i32],
        ) -> u64 {
            run_tri_jobs(
                levels,
                row,
                jobs,
                lods,
                |t, out, s| match Local::new(t, s, out.len(), true) {
                    Some(l) if out.len() >= 2 => bilinear::<false, 1>(t.px, t.stride(), out, l, 0),
                    _ => scalar::bilinear(t, out, s),
                },
                |t, out, s, frac| match Local::new(t, s, out.len(), true) {
                    Some(l) if out.len() >= 2 => {
                        bilinear::<true, 2>(t.px, t.stride(), out, l, frac)
                    }
                    _ => scalar::blend_bilinear(t, out, s, frac),
                },
            )
        }

        /// A batch of spans of one row (see [`super::super::jobs`]): the span setup and the
        /// kernel compiled together, the constants loaded once.
        #[target_feature(enable = $feature)]
        pub(super) fn jobs<const BILINEAR: bool>(
            t: &Texels,
            row: &mut [u32],
            jobs: &[SpanJob],
        ) -> u64 {
            run_jobs::<BILINEAR>(t, row, jobs, |out, s| {
                match Local::new(t, s, out.len(), BILINEAR) {
                    Some(l) if out.len() >= 2 && BILINEAR => {
                        bilinear::<false, 0>(t.px, t.stride(), out, l, 0)
                    }
                    Some(l) if out.len() >= 2 => nearest(t.px, t.stride(), out, l),
                    _ if BILINEAR => scalar::bilinear(t, out, s),
                    _ => scalar::nearest(t, out, s),
                }
            })
        }
    };
}

mod avx2 {
    use super::super::avx2::{bilinear8, indices, lerp, merge, split};
    use super::*;

    batch_entries!("avx2");

    /// `d · [0, 1, …, 7]` per lane without `vpmulld` (10 cycles of latency on the
    /// span's critical path): each lane adds d, 2d and 4d by the bits of its index.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn times_iota(d: __m256i) -> __m256i {
        let d2 = _mm256_add_epi32(d, d);
        let d4 = _mm256_add_epi32(d2, d2);
        let m1 = _mm256_setr_epi32(0, -1, 0, -1, 0, -1, 0, -1);
        let m2 = _mm256_setr_epi32(0, 0, -1, -1, 0, 0, -1, -1);
        let m4 = _mm256_setr_epi32(0, 0, 0, 0, -1, -1, -1, -1);
        let a = _mm256_add_epi32(_mm256_and_si256(d, m1), _mm256_and_si256(d2, m2));
        _mm256_add_epi32(a, _mm256_and_si256(d4, m4))
    }

    /// Bilinear (or, `BLEND`, blended into `out` by `frac`) along a checked span.
    ///
    /// `SITE` only tells call sites apart: each instantiation has one caller, so it is
    /// compiled into that caller (no call, no span setup passed through memory).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn bilinear<const BLEND: bool, const SITE: u8>(
        px: &[u32],
        stride: usize,
        out: &mut [u32],
        l: Local,
        frac: u32,
    ) {
        let m = out.len();
        let iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let (fu, fv) = (_mm256_set1_epi32(l.fu), _mm256_set1_epi32(l.fv));
        let (du, dv) = (_mm256_set1_epi32(l.du), _mm256_set1_epi32(l.dv));
        let fw = _mm256_set1_epi32((frac as i32) * 0x10001);
        let fwt = (fw, _mm256_sub_epi16(_mm256_set1_epi16(256), fw));
        let blend = |o: __m256i, c: (__m256i, __m256i)| {
            if BLEND {
                merge(lerp(split(o), c, fwt))
            } else {
                merge(c)
            }
        };
        // Lanes i < m hold f + i·d exactly (Local::new); the wrapping adds stay exact.
        let mut ru = _mm256_add_epi32(fu, times_iota(du));
        let mut rv = _mm256_add_epi32(fv, times_iota(dv));
        let (su, sv) = (_mm256_slli_epi32::<3>(du), _mm256_slli_epi32::<3>(dv));
        let mut i = 0;
        while i + 8 <= m {
            let c = bilinear8(px, stride, &l, ru, rv);
            let q = out[i..i + 8].as_mut_ptr().cast::<__m256i>();
            let o = if BLEND {
                // SAFETY: `q` points at 8 u32 of `out` (the slice above).
                unsafe { _mm256_loadu_si256(q) }
            } else {
                _mm256_setzero_si256()
            };
            // SAFETY: as above.
            unsafe { _mm256_storeu_si256(q, blend(o, c)) };
            ru = _mm256_add_epi32(ru, su);
            rv = _mm256_add_epi32(rv, sv);
            i += 8;
        }
        if i < m {
            // The tail: lanes past the end repeat the last pixel (inside the map).
            let idx = _mm256_min_epi32(
                _mm256_add_epi32(_mm256_set1_epi32(i as i32), iota),
                _mm256_set1_epi32(m as i32 - 1),
            );
            let ru = _mm256_add_epi32(fu, _mm256_mullo_epi32(idx, du));
            let rv = _mm256_add_epi32(fv, _mm256_mullo_epi32(idx, dv));
            let c = bilinear8(px, stride, &l, ru, rv);
            let tail = &mut out[i..];
            let mut buf = padded::<8>(tail);
            let q = buf.as_mut_ptr().cast::<__m256i>();
            // SAFETY: `buf` holds 8 u32.
            let o = unsafe { _mm256_loadu_si256(q) };
            // SAFETY: as above.
            unsafe { _mm256_storeu_si256(q, blend(o, c)) };
            let n = tail.len();
            tail.copy_from_slice(&buf[..n]);
        }
    }

    /// Nearest along a checked span.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn nearest(px: &[u32], stride: usize, out: &mut [u32], l: Local) {
        let m = out.len();
        let iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let (fu, fv) = (_mm256_set1_epi32(l.fu), _mm256_set1_epi32(l.fv));
        let (du, dv) = (_mm256_set1_epi32(l.du), _mm256_set1_epi32(l.dv));
        let st = _mm256_set1_epi32(stride as i32);
        let mut ru = _mm256_add_epi32(fu, times_iota(du));
        let mut rv = _mm256_add_epi32(fv, times_iota(dv));
        let (su, sv) = (_mm256_slli_epi32::<3>(du), _mm256_slli_epi32::<3>(dv));
        let p = px.as_ptr();
        let fetch = |a: &[i32; 8], j: usize| -> u32 {
            let k = (l.base as isize + a[j] as isize) as usize;
            // SAFETY: a[j] is clamped to [−base, last − base] with last < px.len().
            unsafe { p.add(k).read() }
        };
        let mut i = 0;
        while i + 8 <= m {
            let a = indices(ru, rv, st, &l);
            for (j, o) in out[i..i + 8].iter_mut().enumerate() {
                *o = fetch(&a, j);
            }
            ru = _mm256_add_epi32(ru, su);
            rv = _mm256_add_epi32(rv, sv);
            i += 8;
        }
        if i < m {
            let idx = _mm256_min_epi32(
                _mm256_add_epi32(_mm256_set1_epi32(i as i32), iota),
                _mm256_set1_epi32(m as i32 - 1),
            );
            let ru = _mm256_add_epi32(fu, _mm256_mullo_epi32(idx, du));
            let rv = _mm256_add_epi32(fv, _mm256_mullo_epi32(idx, dv));
            let a = indices(ru, rv, st, &l);
            for (j, o) in out[i..].iter_mut().enumerate() {
                *o = fetch(&a, j);
            }
        }
    }
}

mod sse41 {
    use super::super::sse41::{bilinear4, indices, lerp, merge, split};
    use super::*;

    batch_entries!("sse4.1");

    /// Bilinear (or, `BLEND`, blended into `out` by `frac`) along a checked span.
    ///
    /// `SITE` only tells call sites apart: each instantiation has one caller, so it is
    /// compiled into that caller (no call, no span setup passed through memory).
    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) fn bilinear<const BLEND: bool, const SITE: u8>(
        px: &[u32],
        stride: usize,
        out: &mut [u32],
        l: Local,
        frac: u32,
    ) {
        let m = out.len();
        let iota = _mm_setr_epi32(0, 1, 2, 3);
        let (fu, fv) = (_mm_set1_epi32(l.fu), _mm_set1_epi32(l.fv));
        let (du, dv) = (_mm_set1_epi32(l.du), _mm_set1_epi32(l.dv));
        let fw = _mm_set1_epi32((frac as i32) * 0x10001);
        let fwt = (fw, _mm_sub_epi16(_mm_set1_epi16(256), fw));
        let blend = |o: __m128i, c: (__m128i, __m128i)| {
            if BLEND {
                merge(lerp(split(o), c, fwt))
            } else {
                merge(c)
            }
        };
        let mut ru = _mm_add_epi32(fu, _mm_mullo_epi32(iota, du));
        let mut rv = _mm_add_epi32(fv, _mm_mullo_epi32(iota, dv));
        let (su, sv) = (_mm_slli_epi32::<2>(du), _mm_slli_epi32::<2>(dv));
        let mut i = 0;
        while i + 4 <= m {
            let c = bilinear4(px, stride, &l, ru, rv);
            let q = out[i..i + 4].as_mut_ptr().cast::<__m128i>();
            let o = if BLEND {
                // SAFETY: `q` points at 4 u32 of `out` (the slice above).
                unsafe { _mm_loadu_si128(q) }
            } else {
                _mm_setzero_si128()
            };
            // SAFETY: as above.
            unsafe { _mm_storeu_si128(q, blend(o, c)) };
            ru = _mm_add_epi32(ru, su);
            rv = _mm_add_epi32(rv, sv);
            i += 4;
        }
        if i < m {
            let idx = _mm_min_epi32(
                _mm_add_epi32(_mm_set1_epi32(i as i32), iota),
                _mm_set1_epi32(m as i32 - 1),
            );
            let ru = _mm_add_epi32(fu, _mm_mullo_epi32(idx, du));
            let rv = _mm_add_epi32(fv, _mm_mullo_epi32(idx, dv));
            let c = bilinear4(px, stride, &l, ru, rv);
            let tail = &mut out[i..];
            let mut buf = padded::<4>(tail);
            let q = buf.as_mut_ptr().cast::<__m128i>();
            // SAFETY: `buf` holds 4 u32.
            let o = unsafe { _mm_loadu_si128(q) };
            // SAFETY: as above.
            unsafe { _mm_storeu_si128(q, blend(o, c)) };
            let n = tail.len();
            tail.copy_from_slice(&buf[..n]);
        }
    }

    /// Nearest along a checked span.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) fn nearest(px: &[u32], stride: usize, out: &mut [u32], l: Local) {
        let m = out.len();
        let iota = _mm_setr_epi32(0, 1, 2, 3);
        let (fu, fv) = (_mm_set1_epi32(l.fu), _mm_set1_epi32(l.fv));
        let (du, dv) = (_mm_set1_epi32(l.du), _mm_set1_epi32(l.dv));
        let st = _mm_set1_epi32(stride as i32);
        let mut ru = _mm_add_epi32(fu, _mm_mullo_epi32(iota, du));
        let mut rv = _mm_add_epi32(fv, _mm_mullo_epi32(iota, dv));
        let (su, sv) = (_mm_slli_epi32::<2>(du), _mm_slli_epi32::<2>(dv));
        let p = px.as_ptr();
        let fetch = |a: &[i32; 4], j: usize| -> u32 {
            let k = (l.base as isize + a[j] as isize) as usize;
            // SAFETY: a[j] is clamped to [−base, last − base] with last < px.len().
            unsafe { p.add(k).read() }
        };
        let mut i = 0;
        while i + 4 <= m {
            let a = indices(ru, rv, st, &l);
            for (j, o) in out[i..i + 4].iter_mut().enumerate() {
                *o = fetch(&a, j);
            }
            ru = _mm_add_epi32(ru, su);
            rv = _mm_add_epi32(rv, sv);
            i += 4;
        }
        if i < m {
            let idx = _mm_min_epi32(
                _mm_add_epi32(_mm_set1_epi32(i as i32), iota),
                _mm_set1_epi32(m as i32 - 1),
            );
            let ru = _mm_add_epi32(fu, _mm_mullo_epi32(idx, du));
            let rv = _mm_add_epi32(fv, _mm_mullo_epi32(idx, dv));
            let a = indices(ru, rv, st, &l);
            for (j, o) in out[i..].iter_mut().enumerate() {
                *o = fetch(&a, j);
            }
        }
    }
}

//! x86-64 span kernels: a checked span (`Local`, from the renderer's [`SpanJob`]s) drawn
//! 8 (AVX2) or 4 (SSE4.1) pixels per step, nearest and bilinear, and trilinear as
//! bilinear on a level blended into the one before; the batch entry points compiled
//! under each set's `target_feature`. The texel blend itself (`bilinear8`,
//! `bilinear4`, `split`, `lerp`, `merge`) is the parent module's, shared with the row
//! kernels. There are no AVX-512 span kernels: at 8–16 pixels per span a
//! 16-lane vector would be half empty, so `Kernel::Avx512` runs the AVX2 ones (an
//! AVX-512 CPU runs AVX2), and so do the cropped kernels built on them.

#![allow(unsafe_code)]

use super::{run_jobs, run_tri_jobs, scalar, Span, SpanJob};
use crate::geom::fixed::FX_BITS;
use crate::render::kernel::select::{Kernel, SelectedKernel};
use crate::render::kernel::x86_lanes::{padded, Local};
use crate::render::kernel::Texels;
use std::arch::x86_64::*;

/// The span's start split for 32-bit lanes ([`Local`]); `None` when some lane value
/// `f + i·d` (i < len) would not fit an `i32`, or the slice holds 2³¹ pixels or more. `s`
/// was checked by `prepare` (steps below 2⁴⁶, fewer than 2¹⁶ pixels: the product below
/// cannot overflow).
#[inline(always)]
fn local(t: &Texels, s: Span, len: usize, bilinear: bool) -> Option<Local> {
    const LIM: u64 = i32::MAX as u64 - 0xFFFF;
    let reach = s.du.unsigned_abs().max(s.dv.unsigned_abs()) * (len as u64 - 1);
    let stride = t.stride();
    // The last index whose read (one pixel, or the 2×2 block) stays in the slice.
    let last =
        t.px.len()
            .wrapping_sub(if bilinear { stride + 2 } else { 1 });
    let base = (s.v >> FX_BITS) as usize * stride + (s.u >> FX_BITS) as usize;
    // (base ≤ last always holds for a checked span.)
    if reach > LIM || t.px.len() > i32::MAX as usize || base > last {
        return None;
    }
    Some(Local {
        base,
        fu: (s.u & 0xFFFF) as i32,
        fv: (s.v & 0xFFFF) as i32,
        du: s.du as i32,
        dv: s.dv as i32,
        hi: (last - base) as i32,
        lo: -(base as i32),
    })
}

/// The batch kernels ([`super::jobs`]) with a SIMD kernel; `None` for the scalar one.
#[inline(always)]
pub(super) fn jobs<const BILINEAR: bool>(
    k: SelectedKernel,
    t: &Texels,
    row: &mut [u32],
    jobs: &[SpanJob],
) -> Option<u64> {
    match k.0 {
        // SAFETY: `k` is a `SelectedKernel`, made only when the CPU runs the kernel.
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
pub(super) fn tri_jobs(
    k: SelectedKernel,
    levels: &[Texels],
    row: &mut [u32],
    jobs: &[SpanJob],
    lods: &[i32],
) -> Option<u64> {
    match k.0 {
        // SAFETY: `k` is a `SelectedKernel`, made only when the CPU runs the kernel.
        // (No AVX-512 span kernels: AVX-512 CPUs run AVX2, see `Kernel::Avx512`.)
        Kernel::Avx2 | Kernel::Avx512 => Some(unsafe { avx2::tri_jobs(levels, row, jobs, lods) }),
        // SAFETY: as above.
        Kernel::Sse41 => Some(unsafe { sse41::tri_jobs(levels, row, jobs, lods) }),
        Kernel::Scalar => None,
    }
}

/// The span kernels of one instruction set, written once (as the row kernels and the face positions
/// are: each set's module names its intrinsics with short aliases, `add` is
/// `_mm256_add_epi32` in `avx2` and `_mm_add_epi32` in `sse41`, `V` the vector of `N`
/// lanes, `LOG_N` its log2, and holds what differs in more than the prefix: `iota`,
/// `times_iota`): `bilinear` and `nearest` along a checked span, and the two batch entry
/// points `tri_jobs` and `jobs`, compiled under that set's `target_feature`, so the span
/// setup, the closures and the kernels inline into one loop per set.
macro_rules! span_kernels {
    ($feature:literal) => {
        /// A batch of trilinear spans (see [`super::tri_jobs`]).
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
                |t, out, s| match local(t, s, out.len(), true) {
                    Some(l) if out.len() >= 2 => bilinear::<false, 1>(t.px, t.stride(), out, l, 0),
                    _ => scalar::bilinear(t, out, s),
                },
                |t, out, s, frac| match local(t, s, out.len(), true) {
                    Some(l) if out.len() >= 2 => {
                        bilinear::<true, 2>(t.px, t.stride(), out, l, frac)
                    }
                    _ => scalar::blend_bilinear(t, out, s, frac),
                },
            )
        }

        /// A batch of spans of one row (see [`super::jobs`]): the span setup and the
        /// kernel compiled together, the constants loaded once.
        #[target_feature(enable = $feature)]
        pub(super) fn jobs<const BILINEAR: bool>(
            t: &Texels,
            row: &mut [u32],
            jobs: &[SpanJob],
        ) -> u64 {
            run_jobs::<BILINEAR>(t, row, jobs, |out, s| {
                match local(t, s, out.len(), BILINEAR) {
                    Some(l) if out.len() >= 2 && BILINEAR => {
                        bilinear::<false, 0>(t.px, t.stride(), out, l, 0)
                    }
                    Some(l) if out.len() >= 2 => nearest(t.px, t.stride(), out, l),
                    _ if BILINEAR => scalar::bilinear(t, out, s),
                    _ => scalar::nearest(t, out, s),
                }
            })
        }

        /// Bilinear (or, `BLEND`, blended into `out` by `frac`) along a checked span, N
        /// pixels per step.
        ///
        /// `SITE` only tells call sites apart: each instantiation has one caller, so it is
        /// compiled into that caller (no call, no span setup passed through memory).
        #[inline]
        #[target_feature(enable = $feature)]
        pub(super) fn bilinear<const BLEND: bool, const SITE: u8>(
            px: &[u32],
            stride: usize,
            out: &mut [u32],
            l: Local,
            frac: u32,
        ) {
            let m = out.len();
            let iota = iota();
            let (fu, fv) = (set1(l.fu), set1(l.fv));
            let (du, dv) = (set1(l.du), set1(l.dv));
            let fw = set1((frac as i32) * 0x10001);
            let fwt = (fw, sub16(set1_16(256), fw));
            let blend = |o: V, c: (V, V)| {
                if BLEND {
                    merge(lerp(split(o), c, fwt))
                } else {
                    merge(c)
                }
            };
            // Lanes i < m hold f + i·d exactly (`local`); the wrapping adds stay exact.
            let mut ru = add(fu, times_iota(du));
            let mut rv = add(fv, times_iota(dv));
            let (su, sv) = (slli::<LOG_N>(du), slli::<LOG_N>(dv));
            let mut i = 0;
            while i + N <= m {
                let c = bilinear_n(px, stride, &l, ru, rv);
                let q = out[i..i + N].as_mut_ptr().cast::<V>();
                let o = if BLEND {
                    // SAFETY: `q` points at N u32 of `out` (the slice above).
                    unsafe { loadu(q) }
                } else {
                    zero()
                };
                // SAFETY: as above.
                unsafe { storeu(q, blend(o, c)) };
                ru = add(ru, su);
                rv = add(rv, sv);
                i += N;
            }
            if i < m {
                // The tail: lanes past the end repeat the last pixel (inside the map).
                let idx = min(add(set1(i as i32), iota), set1(m as i32 - 1));
                let ru = add(fu, mullo(idx, du));
                let rv = add(fv, mullo(idx, dv));
                let c = bilinear_n(px, stride, &l, ru, rv);
                let tail = &mut out[i..];
                let mut buf = padded::<N>(tail);
                let q = buf.as_mut_ptr().cast::<V>();
                // SAFETY: `buf` holds N u32.
                let o = unsafe { loadu(q) };
                // SAFETY: as above.
                unsafe { storeu(q, blend(o, c)) };
                let n = tail.len();
                tail.copy_from_slice(&buf[..n]);
            }
        }

        /// Nearest along a checked span, N pixels per step.
        #[inline]
        #[target_feature(enable = $feature)]
        pub(super) fn nearest(px: &[u32], stride: usize, out: &mut [u32], l: Local) {
            let m = out.len();
            let iota = iota();
            let (fu, fv) = (set1(l.fu), set1(l.fv));
            let (du, dv) = (set1(l.du), set1(l.dv));
            let st = set1(stride as i32);
            let mut ru = add(fu, times_iota(du));
            let mut rv = add(fv, times_iota(dv));
            let (su, sv) = (slli::<LOG_N>(du), slli::<LOG_N>(dv));
            let p = px.as_ptr();
            let fetch = |a: &[i32; N], j: usize| -> u32 {
                let k = (l.base as isize + a[j] as isize) as usize;
                // SAFETY: a[j] is clamped to [−base, last − base] with last < px.len().
                unsafe { p.add(k).read() }
            };
            let mut i = 0;
            while i + N <= m {
                let a = indices(ru, rv, st, &l);
                for (j, o) in out[i..i + N].iter_mut().enumerate() {
                    *o = fetch(&a, j);
                }
                ru = add(ru, su);
                rv = add(rv, sv);
                i += N;
            }
            if i < m {
                let idx = min(add(set1(i as i32), iota), set1(m as i32 - 1));
                let ru = add(fu, mullo(idx, du));
                let rv = add(fv, mullo(idx, dv));
                let a = indices(ru, rv, st, &l);
                for (j, o) in out[i..].iter_mut().enumerate() {
                    *o = fetch(&a, j);
                }
            }
        }
    };
}

mod avx2 {
    use super::*;
    use crate::render::kernel::x86_lanes::avx2::{
        bilinear8 as bilinear_n, indices, lerp, merge, split,
    };
    use std::arch::x86_64::{
        __m256i as V, _mm256_add_epi32 as add, _mm256_loadu_si256 as loadu,
        _mm256_min_epi32 as min, _mm256_mullo_epi32 as mullo, _mm256_set1_epi16 as set1_16,
        _mm256_set1_epi32 as set1, _mm256_setzero_si256 as zero, _mm256_slli_epi32 as slli,
        _mm256_storeu_si256 as storeu, _mm256_sub_epi16 as sub16,
    };

    /// Pixels per step, and its log2.
    const N: usize = 8;
    const LOG_N: i32 = 3;

    span_kernels!("avx2");

    /// The lane indices 0..8.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn iota() -> V {
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)
    }

    /// `d · [0, 1, …, 7]` per lane without `vpmulld` (10 cycles of latency on the
    /// span's critical path): each lane adds d, 2d and 4d by the bits of its index.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn times_iota(d: V) -> V {
        let d2 = _mm256_add_epi32(d, d);
        let d4 = _mm256_add_epi32(d2, d2);
        let m1 = _mm256_setr_epi32(0, -1, 0, -1, 0, -1, 0, -1);
        let m2 = _mm256_setr_epi32(0, 0, -1, -1, 0, 0, -1, -1);
        let m4 = _mm256_setr_epi32(0, 0, 0, 0, -1, -1, -1, -1);
        let a = _mm256_add_epi32(_mm256_and_si256(d, m1), _mm256_and_si256(d2, m2));
        _mm256_add_epi32(a, _mm256_and_si256(d4, m4))
    }
}

mod sse41 {
    use super::*;
    use crate::render::kernel::x86_lanes::sse41::{
        bilinear4 as bilinear_n, indices, lerp, merge, split,
    };
    use std::arch::x86_64::{
        __m128i as V, _mm_add_epi32 as add, _mm_loadu_si128 as loadu, _mm_min_epi32 as min,
        _mm_mullo_epi32 as mullo, _mm_set1_epi16 as set1_16, _mm_set1_epi32 as set1,
        _mm_setzero_si128 as zero, _mm_slli_epi32 as slli, _mm_storeu_si128 as storeu,
        _mm_sub_epi16 as sub16,
    };

    /// Pixels per step, and its log2.
    const N: usize = 4;
    const LOG_N: i32 = 2;

    span_kernels!("sse4.1");

    /// The lane indices 0..4.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn iota() -> V {
        _mm_setr_epi32(0, 1, 2, 3)
    }

    /// `d · [0, 1, 2, 3]` per lane.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn times_iota(d: V) -> V {
        _mm_mullo_epi32(iota(), d)
    }
}

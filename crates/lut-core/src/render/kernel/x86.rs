//! x86-64 span kernels: SSE4.1 (4 pixels per step) and AVX2 (8 pixels per step); the
//! AVX-512 pieces (`avx512`: `split`, `lerp`, `merge`, the pair layout and `bilinear16`)
//! that the AVX-512 row and face kernels (`x86/row.rs`, `x86/face.rs`) share. There are
//! no AVX-512 span kernels: `Kernel::Avx512` runs the AVX2 ones here (an AVX-512 CPU
//! runs AVX2), and so do the cropped kernels built on them.
//!
//! All compute what `scalar.rs` computes, byte for byte (see the module docs of
//! [`super`]): positions in span-local `i32` lanes, lane indices stored to the stack and
//! clamped into the pixel slice, two 64-bit loads per bilinear pixel (its top and bottom
//! pairs), `shufps` to separate left and right texels, and the 8-bit blend in 16-bit
//! lanes, two channels per 32-bit lane (blue and red, then green and the unused top byte,
//! which is dropped at the end as `lerp_px` drops it).
//!
//! The only `unsafe` here: calling a `#[target_feature]` function (the CPU was checked:
//! [`Selected`] is only made for a supported kernel), the unaligned loads and stores,
//! whose indices are clamped into the slices they read or bounded by the loop, and the
//! prefetches of the row and face kernels ([`prefetch_texels`]), which read nothing.

#![allow(unsafe_code)]

use super::jobs::{run_jobs, run_tri_jobs, Span};
use super::select::{Kernel, Selected};
use super::{scalar, SpanJob, Texels};
use crate::geom::fixed::FX_BITS;
use std::arch::x86_64::*;

pub(super) mod face;
pub(super) mod nodes;
pub(super) mod row;

/// The span's start split for 32-bit lanes: `base` = the start pixel's index in the
/// slice, lanes hold `f + i·d` (Q.16, relative to that pixel).
#[derive(Debug, Clone, Copy)]
struct Local {
    base: usize,
    fu: i32,
    fv: i32,
    du: i32,
    dv: i32,
    /// Largest lane index (relative to `base`) whose reads stay inside the slice.
    hi: i32,
    /// Smallest (−base).
    lo: i32,
}

impl Local {
    /// `None` when some lane value `f + i·d` (i < len) would not fit an `i32`, or the
    /// slice holds 2³¹ pixels or more. `s` was checked by `prepare` (steps below 2⁴⁶,
    /// fewer than 2¹⁶ pixels: the product below cannot overflow).
    #[inline(always)]
    fn new(t: &Texels, s: Span, len: usize, bilinear: bool) -> Option<Local> {
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
}

/// The batch kernels ([`super::jobs`]) with a SIMD kernel; `None` for the scalar one.
#[inline(always)]
pub(super) fn jobs<const BILINEAR: bool>(
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
pub(super) fn tri_jobs(
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

/// How many pixels ahead the row kernels prefetch the texels they will read.
///
/// Why: a frame reads the map along curves that cross map rows, and each map row the
/// curve enters starts with cache misses the hardware prefetchers (which follow address
/// streams) cannot foresee; the row's positions, already in the buffers, say where the
/// reads will go. About 50 pixels is a few hundred nanoseconds of drawing, longer than a
/// trip to memory; 32–64 measured alike (`docs/performance.md`, "Prefetching").
pub(super) const PREFETCH_AHEAD: usize = 48;

/// Prefetch the cache line holding texel `at` and, for bilinear, the one `stride` texels
/// below it (the row kernels' and the face kernels' look-ahead). `at` need not point
/// into the map: a line off the map is a wasted prefetch, nothing more.
#[inline(always)]
fn prefetch_texels<const BILINEAR: bool>(at: *const u32, stride: usize) {
    // SAFETY: SSE is part of every x86-64 CPU; a prefetch reads nothing the program sees
    // and never faults, whatever the address.
    unsafe {
        _mm_prefetch::<_MM_HINT_T0>(at.cast());
        if BILINEAR {
            _mm_prefetch::<_MM_HINT_T0>(at.wrapping_add(stride).cast());
        }
    }
}

/// Copies `src[..n]` into a zeroed `[u32; N]` (tails shorter than a vector).
#[inline(always)]
fn padded<const N: usize>(src: &[u32]) -> [u32; N] {
    let mut a = [0u32; N];
    let n = src.len().min(N);
    a[..n].copy_from_slice(&src[..n]);
    a
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
    use super::*;

    batch_entries!("avx2");

    /// Per 32-bit lane: the fraction byte (bits 8..16) in both 16-bit halves.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn weights(r: __m256i) -> (__m256i, __m256i) {
        let m = _mm256_setr_epi8(
            1, -128, 1, -128, 5, -128, 5, -128, 9, -128, 9, -128, 13, -128, 13, -128, 1, -128, 1,
            -128, 5, -128, 5, -128, 9, -128, 9, -128, 13, -128, 13, -128,
        );
        let w = _mm256_shuffle_epi8(r, m);
        (w, _mm256_sub_epi16(_mm256_set1_epi16(256), w))
    }

    /// 0RGB pixels → (blue and red, green and top byte), one channel per 16-bit lane.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn split(p: __m256i) -> (__m256i, __m256i) {
        (
            _mm256_and_si256(p, _mm256_set1_epi32(0x00FF_00FF)),
            _mm256_srli_epi16::<8>(p),
        )
    }

    /// Per channel `(a·iw + b·w + 128) >> 8` (at most 255·256 + 128: no 16-bit overflow).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn lerp(
        a: (__m256i, __m256i),
        b: (__m256i, __m256i),
        w: (__m256i, __m256i),
    ) -> (__m256i, __m256i) {
        let r = _mm256_set1_epi16(128);
        let f = |x: __m256i, y: __m256i| {
            let s = _mm256_add_epi16(_mm256_mullo_epi16(x, w.1), _mm256_mullo_epi16(y, w.0));
            _mm256_srli_epi16::<8>(_mm256_add_epi16(s, r))
        };
        (f(a.0, b.0), f(a.1, b.1))
    }

    /// Split channels back to 0RGB (the top byte dropped).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn merge(c: (__m256i, __m256i)) -> __m256i {
        let g = _mm256_and_si256(_mm256_slli_epi32::<8>(c.1), _mm256_set1_epi32(0xFF00));
        _mm256_or_si256(c.0, g)
    }

    /// A vector whose lanes 0..8 are `g(0..8)`: the nearest texels, read one by one
    /// (the row and face kernels' nearest; hardware gathers measured slower).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn gather(g: impl Fn(usize) -> i32) -> __m256i {
        _mm256_setr_epi32(g(0), g(1), g(2), g(3), g(4), g(5), g(6), g(7))
    }

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

    /// Lane indices (relative to the span's base pixel) of positions `ru`, `rv`, clamped.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn indices(ru: __m256i, rv: __m256i, stride: __m256i, l: &Local) -> [i32; 8] {
        let x = _mm256_srai_epi32::<16>(ru);
        let y = _mm256_srai_epi32::<16>(rv);
        let i = _mm256_add_epi32(_mm256_mullo_epi32(y, stride), x);
        let i = _mm256_max_epi32(
            _mm256_min_epi32(i, _mm256_set1_epi32(l.hi)),
            _mm256_set1_epi32(l.lo),
        );
        let mut a = [0i32; 8];
        // SAFETY: `a` is 32 writable bytes; the store is unaligned.
        unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), i) };
        a
    }

    /// Bilinear samples at 8 lane positions (split channels).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn bilinear8(
        px: &[u32],
        stride: usize,
        l: &Local,
        ru: __m256i,
        rv: __m256i,
    ) -> (__m256i, __m256i) {
        let a = indices(ru, rv, _mm256_set1_epi32(stride as i32), l);
        let p = px.as_ptr();
        let pair = |j: usize, row: usize| -> i64 {
            let k = (l.base as isize + a[j] as isize) as usize + row;
            // SAFETY: a[j] is clamped to [−base, last − base], so k ≤ last + row where
            // last + stride + 1 < px.len() (Local::new): the 8 bytes at k are in `px`.
            unsafe { p.add(k).cast::<i64>().read_unaligned() }
        };
        let ta = _mm256_set_epi64x(pair(5, 0), pair(4, 0), pair(1, 0), pair(0, 0));
        let tb = _mm256_set_epi64x(pair(7, 0), pair(6, 0), pair(3, 0), pair(2, 0));
        let ba = _mm256_set_epi64x(
            pair(5, stride),
            pair(4, stride),
            pair(1, stride),
            pair(0, stride),
        );
        let bb = _mm256_set_epi64x(
            pair(7, stride),
            pair(6, stride),
            pair(3, stride),
            pair(2, stride),
        );
        let left = |x: __m256i, y: __m256i| {
            _mm256_castps_si256(_mm256_shuffle_ps::<0x88>(
                _mm256_castsi256_ps(x),
                _mm256_castsi256_ps(y),
            ))
        };
        let right = |x: __m256i, y: __m256i| {
            _mm256_castps_si256(_mm256_shuffle_ps::<0xDD>(
                _mm256_castsi256_ps(x),
                _mm256_castsi256_ps(y),
            ))
        };
        let wx = weights(ru);
        let top = lerp(split(left(ta, tb)), split(right(ta, tb)), wx);
        let bot = lerp(split(left(ba, bb)), split(right(ba, bb)), wx);
        lerp(top, bot, weights(rv))
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

/// The AVX-512 pieces the row and face kernels share (`x86/row.rs`, `x86/face.rs`): the
/// AVX2 ones on 16 lanes, the same arithmetic. There are no AVX-512 span kernels (the
/// batch entry points above): `Kernel::Avx512` runs the AVX2 ones.
///
/// Every function is `#[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,
/// avx512dq")]` (a list: `Kernel::Avx512` checks each).
mod avx512 {
    use super::*;

    /// Per 32-bit lane: the fraction byte (bits 8..16) in both 16-bit halves.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn weights(r: __m512i) -> (__m512i, __m512i) {
        let m = _mm512_set4_epi32(
            0x800D_800D_u32 as i32,
            0x8009_8009_u32 as i32,
            0x8005_8005_u32 as i32,
            0x8001_8001_u32 as i32,
        );
        let w = _mm512_shuffle_epi8(r, m);
        (w, _mm512_sub_epi16(_mm512_set1_epi16(256), w))
    }

    /// 0RGB pixels → (blue and red, green and top byte), one channel per 16-bit lane.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(super) fn split(p: __m512i) -> (__m512i, __m512i) {
        (
            _mm512_and_si512(p, _mm512_set1_epi32(0x00FF_00FF)),
            _mm512_srli_epi16::<8>(p),
        )
    }

    /// Per channel `(a·iw + b·w + 128) >> 8` (at most 255·256 + 128: no 16-bit overflow).
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(super) fn lerp(
        a: (__m512i, __m512i),
        b: (__m512i, __m512i),
        w: (__m512i, __m512i),
    ) -> (__m512i, __m512i) {
        let r = _mm512_set1_epi16(128);
        let f = |x: __m512i, y: __m512i| {
            let s = _mm512_add_epi16(_mm512_mullo_epi16(x, w.1), _mm512_mullo_epi16(y, w.0));
            _mm512_srli_epi16::<8>(_mm512_add_epi16(s, r))
        };
        (f(a.0, b.0), f(a.1, b.1))
    }

    /// Split channels back to 0RGB (the top byte dropped).
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(super) fn merge(c: (__m512i, __m512i)) -> __m512i {
        let g = _mm512_and_si512(_mm512_slli_epi32::<8>(c.1), _mm512_set1_epi32(0xFF00));
        _mm512_or_si512(c.0, g)
    }

    /// A vector whose lanes 0..16 are `g(0..16)`: the nearest texels, read one by one
    /// (`vpgatherdd` measured slower, docs/performance.md "AVX-512").
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(super) fn gather(g: impl Fn(usize) -> i32) -> __m512i {
        _mm512_setr_epi32(
            g(0),
            g(1),
            g(2),
            g(3),
            g(4),
            g(5),
            g(6),
            g(7),
            g(8),
            g(9),
            g(10),
            g(11),
            g(12),
            g(13),
            g(14),
            g(15),
        )
    }

    /// The 64-bit texel pairs of lanes 0..16 (`pair(k)`) as two vectors, (0, 1, 4, 5, 8,
    /// 9, 12, 13) and (2, 3, 6, 7, 10, 11, 14, 15), so that `shufps` (within 128-bit
    /// quarters) gives lanes 0..16 in order.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(super) fn pairs(pair: impl Fn(usize) -> i64) -> (__m512i, __m512i) {
        (
            _mm512_set_epi64(
                pair(13),
                pair(12),
                pair(9),
                pair(8),
                pair(5),
                pair(4),
                pair(1),
                pair(0),
            ),
            _mm512_set_epi64(
                pair(15),
                pair(14),
                pair(11),
                pair(10),
                pair(7),
                pair(6),
                pair(3),
                pair(2),
            ),
        )
    }

    /// The left texels of the pixels whose pairs [`pairs`] laid out in `x`, `y`.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(super) fn left(x: __m512i, y: __m512i) -> __m512i {
        _mm512_castps_si512(_mm512_shuffle_ps::<0x88>(
            _mm512_castsi512_ps(x),
            _mm512_castsi512_ps(y),
        ))
    }

    /// The right texels (see [`left`]).
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(super) fn right(x: __m512i, y: __m512i) -> __m512i {
        _mm512_castps_si512(_mm512_shuffle_ps::<0xDD>(
            _mm512_castsi512_ps(x),
            _mm512_castsi512_ps(y),
        ))
    }

    /// Bilinear samples at 16 lane positions (split channels; see `avx2::bilinear8`).
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(super) fn bilinear16(
        px: &[u32],
        stride: usize,
        l: &Local,
        ru: __m512i,
        rv: __m512i,
    ) -> (__m512i, __m512i) {
        let x = _mm512_srai_epi32::<16>(ru);
        let y = _mm512_srai_epi32::<16>(rv);
        let i = _mm512_add_epi32(_mm512_mullo_epi32(y, _mm512_set1_epi32(stride as i32)), x);
        let i = _mm512_max_epi32(
            _mm512_min_epi32(i, _mm512_set1_epi32(l.hi)),
            _mm512_set1_epi32(l.lo),
        );
        let mut a = [0i32; 16];
        // SAFETY: `a` is 64 writable bytes; the store is unaligned.
        unsafe { _mm512_storeu_si512(a.as_mut_ptr().cast(), i) };
        let p = px.as_ptr();
        let pair = |j: usize, row: usize| -> i64 {
            let k = (l.base as isize + a[j] as isize) as usize + row;
            // SAFETY: a[j] is clamped to [−base, last − base], so k ≤ last + row where
            // last + stride + 1 < px.len() (Local::new): the 8 bytes at k are in `px`.
            unsafe { p.add(k).cast::<i64>().read_unaligned() }
        };
        let (ta, tb) = pairs(|j| pair(j, 0));
        let (ba, bb) = pairs(|j| pair(j, stride));
        let wx = weights(ru);
        let top = lerp(split(left(ta, tb)), split(right(ta, tb)), wx);
        let bot = lerp(split(left(ba, bb)), split(right(ba, bb)), wx);
        lerp(top, bot, weights(rv))
    }
}

mod sse41 {
    use super::*;

    batch_entries!("sse4.1");

    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn weights(r: __m128i) -> (__m128i, __m128i) {
        let m = _mm_setr_epi8(
            1, -128, 1, -128, 5, -128, 5, -128, 9, -128, 9, -128, 13, -128, 13, -128,
        );
        let w = _mm_shuffle_epi8(r, m);
        (w, _mm_sub_epi16(_mm_set1_epi16(256), w))
    }

    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) fn split(p: __m128i) -> (__m128i, __m128i) {
        (
            _mm_and_si128(p, _mm_set1_epi32(0x00FF_00FF)),
            _mm_srli_epi16::<8>(p),
        )
    }

    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) fn lerp(
        a: (__m128i, __m128i),
        b: (__m128i, __m128i),
        w: (__m128i, __m128i),
    ) -> (__m128i, __m128i) {
        let r = _mm_set1_epi16(128);
        let f = |x: __m128i, y: __m128i| {
            let s = _mm_add_epi16(_mm_mullo_epi16(x, w.1), _mm_mullo_epi16(y, w.0));
            _mm_srli_epi16::<8>(_mm_add_epi16(s, r))
        };
        (f(a.0, b.0), f(a.1, b.1))
    }

    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) fn merge(c: (__m128i, __m128i)) -> __m128i {
        let g = _mm_and_si128(_mm_slli_epi32::<8>(c.1), _mm_set1_epi32(0xFF00));
        _mm_or_si128(c.0, g)
    }

    /// A vector whose lanes 0..4 are `g(0..4)`: the nearest texels, read one by one.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) fn gather(g: impl Fn(usize) -> i32) -> __m128i {
        _mm_setr_epi32(g(0), g(1), g(2), g(3))
    }

    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn indices(ru: __m128i, rv: __m128i, stride: __m128i, l: &Local) -> [i32; 4] {
        let x = _mm_srai_epi32::<16>(ru);
        let y = _mm_srai_epi32::<16>(rv);
        let i = _mm_add_epi32(_mm_mullo_epi32(y, stride), x);
        let i = _mm_max_epi32(_mm_min_epi32(i, _mm_set1_epi32(l.hi)), _mm_set1_epi32(l.lo));
        let mut a = [0i32; 4];
        // SAFETY: `a` is 16 writable bytes; the store is unaligned.
        unsafe { _mm_storeu_si128(a.as_mut_ptr().cast(), i) };
        a
    }

    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) fn bilinear4(
        px: &[u32],
        stride: usize,
        l: &Local,
        ru: __m128i,
        rv: __m128i,
    ) -> (__m128i, __m128i) {
        let a = indices(ru, rv, _mm_set1_epi32(stride as i32), l);
        let p = px.as_ptr();
        let pair = |j: usize, row: usize| -> i64 {
            let k = (l.base as isize + a[j] as isize) as usize + row;
            // SAFETY: a[j] is clamped to [−base, last − base], so k ≤ last + row where
            // last + stride + 1 < px.len() (Local::new): the 8 bytes at k are in `px`.
            unsafe { p.add(k).cast::<i64>().read_unaligned() }
        };
        let ta = _mm_set_epi64x(pair(1, 0), pair(0, 0));
        let tb = _mm_set_epi64x(pair(3, 0), pair(2, 0));
        let ba = _mm_set_epi64x(pair(1, stride), pair(0, stride));
        let bb = _mm_set_epi64x(pair(3, stride), pair(2, stride));
        let left = |x: __m128i, y: __m128i| {
            _mm_castps_si128(_mm_shuffle_ps::<0x88>(
                _mm_castsi128_ps(x),
                _mm_castsi128_ps(y),
            ))
        };
        let right = |x: __m128i, y: __m128i| {
            _mm_castps_si128(_mm_shuffle_ps::<0xDD>(
                _mm_castsi128_ps(x),
                _mm_castsi128_ps(y),
            ))
        };
        let wx = weights(ru);
        let top = lerp(split(left(ta, tb)), split(right(ta, tb)), wx);
        let bot = lerp(split(left(ba, bb)), split(right(ba, bb)), wx);
        lerp(top, bot, weights(rv))
    }

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

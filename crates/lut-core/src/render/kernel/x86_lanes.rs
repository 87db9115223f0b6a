//! The x86-64 lane helpers every operation's `x86.rs` shares (below them all: this
//! module uses none of them): the texel blend of each instruction set (`split`, `lerp`,
//! `merge`, the nearest `gather`, the clamped lane indices and the bilinear sample of a
//! vector of positions: `bilinear4` with SSE4.1, `bilinear8` with AVX2; the pair layout
//! with AVX-512), a checked span's start in lanes ([`Local`], made by `span/x86.rs`),
//! and the row kernels' prefetches.
//!
//! All compute what the scalar twins compute, byte for byte (see the module docs of
//! [`super`]): positions in span-local `i32` lanes, lane indices stored to the stack and
//! clamped into the pixel slice, two 64-bit loads per bilinear pixel (its top and bottom
//! pairs), `shufps` to separate left and right texels, and the 8-bit blend in 16-bit
//! lanes, two channels per 32-bit lane (blue and red, then green and the unused top byte,
//! which is dropped at the end as `lerp_px` drops it).
//!
//! The only `unsafe` here: the unaligned loads, whose indices are clamped into the slices
//! they read, and the prefetches ([`prefetch_texels`] and, for the rows the next scanline
//! reads, [`prefetch_next_rows`]), which read nothing. Each function is
//! `#[target_feature]` and is called only from kernels compiled under the same features.

#![allow(unsafe_code)]

use std::arch::x86_64::*;

/// A checked span's start split for 32-bit lanes (made by the span kernels,
/// `span/x86.rs`): `base` = the start pixel's index in the slice, lanes hold `f + i·d`
/// (Q.16, relative to that pixel).
#[derive(Debug, Clone, Copy)]
pub(super) struct Local {
    pub(super) base: usize,
    pub(super) fu: i32,
    pub(super) fv: i32,
    pub(super) du: i32,
    pub(super) dv: i32,
    /// Largest lane index (relative to `base`) whose reads stay inside the slice.
    pub(super) hi: i32,
    /// Smallest (−base).
    pub(super) lo: i32,
}

/// The least number of pixels ahead the row kernels prefetch the texels they will read
/// (see [`PREFETCH_TEXELS`]).
///
/// Why: a frame reads the map along curves that cross map rows, and each map row the
/// curve enters starts with cache misses the hardware prefetchers (which follow address
/// streams) cannot foresee; the row's positions, already in the buffers, say where the
/// reads will go. About 50 pixels is a few hundred nanoseconds of drawing, about a trip
/// to memory (`docs/performance.md`, "Prefetching").
pub(super) const PREFETCH_AHEAD: usize = 48;

/// How many map texels ahead along a run the row kernels prefetch (`row/x86.rs`,
/// `prefetch_ahead`: the pixels that cover this many texels, between
/// [`PREFETCH_AHEAD`] and this many pixels). On the AMD EPYC VM of
/// `docs/performance.md` ("Prefetch distance"), 256 pixels ahead drew the 8k frame at
/// hfov 90 (about a texel per pixel) ~15 % faster than 48, while the 32k map's (5.4
/// texels per pixel) was best near 48 pixels: about the same ~256 texels (1 KiB) of
/// map row ahead in both.
pub(super) const PREFETCH_TEXELS: usize = 256;

/// Prefetch into L2 the cache lines holding texel `at` and the one `stride` texels below
/// it (the rows the next scanline will read, `row/x86.rs`). `at` need not point into the
/// map: a line off the map is a wasted prefetch, nothing more.
#[inline(always)]
pub(super) fn prefetch_next_rows(at: *const u32, stride: usize) {
    // SAFETY: as in `prefetch_texels`: a prefetch never faults, whatever the address.
    unsafe {
        _mm_prefetch::<_MM_HINT_T1>(at.cast());
        _mm_prefetch::<_MM_HINT_T1>(at.wrapping_add(stride).cast());
    }
}

/// Prefetch the cache line holding texel `at` and, for bilinear, the one `stride` texels
/// below it (the row kernels' look-ahead). `at` need not point
/// into the map: a line off the map is a wasted prefetch, nothing more.
#[inline(always)]
pub(super) fn prefetch_texels<const BILINEAR: bool>(at: *const u32, stride: usize) {
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
pub(super) fn padded<const N: usize>(src: &[u32]) -> [u32; N] {
    let mut a = [0u32; N];
    let n = src.len().min(N);
    a[..n].copy_from_slice(&src[..n]);
    a
}

pub(super) mod avx2 {
    use super::*;

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
    pub(in crate::render::kernel) fn split(p: __m256i) -> (__m256i, __m256i) {
        (
            _mm256_and_si256(p, _mm256_set1_epi32(0x00FF_00FF)),
            _mm256_srli_epi16::<8>(p),
        )
    }

    /// Per channel `(a·iw + b·w + 128) >> 8` (at most 255·256 + 128: no 16-bit overflow).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(in crate::render::kernel) fn lerp(
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
    pub(in crate::render::kernel) fn merge(c: (__m256i, __m256i)) -> __m256i {
        let g = _mm256_and_si256(_mm256_slli_epi32::<8>(c.1), _mm256_set1_epi32(0xFF00));
        _mm256_or_si256(c.0, g)
    }

    /// A vector whose lanes 0..8 are `g(0..8)`: the nearest texels, read one by one
    /// (the row kernels' nearest; hardware gathers measured slower).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(in crate::render::kernel) fn gather(g: impl Fn(usize) -> i32) -> __m256i {
        _mm256_setr_epi32(g(0), g(1), g(2), g(3), g(4), g(5), g(6), g(7))
    }

    /// Lane indices (relative to the span's base pixel) of positions `ru`, `rv`, clamped.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(in crate::render::kernel) fn indices(
        ru: __m256i,
        rv: __m256i,
        stride: __m256i,
        l: &Local,
    ) -> [i32; 8] {
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
    pub(in crate::render::kernel) fn bilinear8(
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
            // last + stride + 1 < px.len() (`span/x86.rs`, `local`): the 8 bytes at k are in `px`.
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
}

/// The AVX-512 pieces of the row kernels (`row/x86.rs`): the AVX2 ones on 16 lanes, the
/// same arithmetic. There are no AVX-512 span kernels
/// (`span/x86.rs`): `Kernel::Avx512` runs the AVX2 ones.
///
/// Every function is `#[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,
/// avx512dq")]` (a list: `Kernel::Avx512` checks each).
pub(super) mod avx512 {
    use super::*;

    /// 0RGB pixels → (blue and red, green and top byte), one channel per 16-bit lane.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(in crate::render::kernel) fn split(p: __m512i) -> (__m512i, __m512i) {
        (
            _mm512_and_si512(p, _mm512_set1_epi32(0x00FF_00FF)),
            _mm512_srli_epi16::<8>(p),
        )
    }

    /// Per channel `(a·iw + b·w + 128) >> 8` (at most 255·256 + 128: no 16-bit overflow).
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(in crate::render::kernel) fn lerp(
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
    pub(in crate::render::kernel) fn merge(c: (__m512i, __m512i)) -> __m512i {
        let g = _mm512_and_si512(_mm512_slli_epi32::<8>(c.1), _mm512_set1_epi32(0xFF00));
        _mm512_or_si512(c.0, g)
    }

    /// A vector whose lanes 0..16 are `g(0..16)`: the nearest texels, read one by one
    /// (`vpgatherdd` measured slower, docs/performance.md "AVX-512").
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    pub(in crate::render::kernel) fn gather(g: impl Fn(usize) -> i32) -> __m512i {
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
    pub(in crate::render::kernel) fn pairs(pair: impl Fn(usize) -> i64) -> (__m512i, __m512i) {
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
}

pub(super) mod sse41 {
    use super::*;

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
    pub(in crate::render::kernel) fn split(p: __m128i) -> (__m128i, __m128i) {
        (
            _mm_and_si128(p, _mm_set1_epi32(0x00FF_00FF)),
            _mm_srli_epi16::<8>(p),
        )
    }

    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(in crate::render::kernel) fn lerp(
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
    pub(in crate::render::kernel) fn merge(c: (__m128i, __m128i)) -> __m128i {
        let g = _mm_and_si128(_mm_slli_epi32::<8>(c.1), _mm_set1_epi32(0xFF00));
        _mm_or_si128(c.0, g)
    }

    /// A vector whose lanes 0..4 are `g(0..4)`: the nearest texels, read one by one.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(in crate::render::kernel) fn gather(g: impl Fn(usize) -> i32) -> __m128i {
        _mm_setr_epi32(g(0), g(1), g(2), g(3))
    }

    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(in crate::render::kernel) fn indices(
        ru: __m128i,
        rv: __m128i,
        stride: __m128i,
        l: &Local,
    ) -> [i32; 4] {
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
    pub(in crate::render::kernel) fn bilinear4(
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
            // last + stride + 1 < px.len() (`span/x86.rs`, `local`): the 8 bytes at k are in `px`.
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
}

//! x86-64 row kernels (see `kernel/row.rs`): 8 (AVX2) or 4 (SSE4.1) pixels per step, the
//! seam wrap and the pole clamp as lane compares, the texels read as the map kernels read
//! them (two 64-bit loads per bilinear pixel) and blended with their `split`, `lerp` and
//! `merge`; the left half's pixels reversed in the register before the store.

use super::super::row::{sample_lv_scalar, Level, Positions, SpanQ8};
use super::{Kernel, Selected, Texels};
use std::arch::x86_64::*;

/// The row kernel with a SIMD kernel (see `row::sample_lv_scalar`); `false` (nothing
/// written) for the scalar one.
#[inline(always)]
pub(in super::super) fn sample_q8<
    const BILINEAR: bool,
    const MIRROR: bool,
    const LEVEL: bool,
    const BLEND: bool,
>(
    k: Selected,
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
    lv: &Level,
) -> bool {
    match k.0 {
        // SAFETY: `k` is a `Selected`, made only when the CPU runs the kernel.
        Kernel::Avx2 => unsafe {
            avx2::sample_q8::<BILINEAR, MIRROR, LEVEL, BLEND>(t, u, v, out, lv)
        },
        // SAFETY: as above.
        Kernel::Sse41 => unsafe {
            sse41::sample_q8::<BILINEAR, MIRROR, LEVEL, BLEND>(t, u, v, out, lv)
        },
        Kernel::Scalar => return false,
    }
    true
}

/// [`expand`](super::super::row::expand) with a SIMD kernel; the buffers back, untouched,
/// for the scalar one.
#[inline(always)]
pub(in super::super) fn expand<'a>(
    k: Selected,
    spans: &[SpanQ8],
    p: Positions<'a>,
) -> Option<Positions<'a>> {
    match k.0 {
        // SAFETY: `k` is a `Selected`, made only when the CPU runs the kernel.
        Kernel::Avx2 => unsafe { avx2::expand(spans, p) },
        // SAFETY: as above.
        Kernel::Sse41 => unsafe { sse41::expand(spans, p) },
        Kernel::Scalar => return Some(p),
    }
    None
}

/// The largest index whose read (one texel, or the 2×2 block) stays inside `t`.
#[inline(always)]
fn last_index<const BILINEAR: bool>(t: &Texels) -> usize {
    t.px.len() - if BILINEAR { t.stride() + 2 } else { 1 }
}

/// How many pixels ahead the row kernels prefetch the texels they will read.
///
/// Why: a frame reads the map along curves that cross map rows, and each map row the
/// curve enters starts with cache misses the hardware prefetchers (which follow address
/// streams) cannot foresee; the row's positions, already in the buffers, say where the
/// reads will go. About 50 pixels is a few hundred nanoseconds of drawing, longer than a
/// trip to memory; 32–64 measured alike (`docs/performance.md`, "Prefetching").
pub(super) const PREFETCH_AHEAD: usize = 48;

/// Prefetch the cache lines position `j` of (`u`, `v`) (Q.8, on level `k`) will read:
/// its texel, and for bilinear the one below. Positions past the run are skipped;
/// positions off the map (a seam not yet wrapped) prefetch a wrong line, which is
/// harmless: a prefetch never faults and changes no result.
#[inline(always)]
fn prefetch<const BILINEAR: bool>(t: &Texels, (u, v): (&[i32], &[i32]), j: usize, k: u32) {
    if let (Some(&u), Some(&v)) = (u.get(j), v.get(j)) {
        let stride = t.stride() as isize;
        let (x, y) = ((u >> (8 + k)) as isize, (v >> (8 + k)) as isize);
        let at =
            t.px.as_ptr()
                .wrapping_offset(y.wrapping_mul(stride).wrapping_add(x));
        // SAFETY: SSE is part of every x86-64 CPU; a prefetch reads nothing the program
        // sees and never faults, whatever the address.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(at.cast());
            if BILINEAR {
                _mm_prefetch::<_MM_HINT_T0>(at.wrapping_offset(stride).cast());
            }
        }
    }
}

/// The pixels between prefetches for a run of positions `u` (Q.8, on level `k`): 8, or
/// 4 where the run steps more than 2 texels per pixel on average (zoomed out on the full
/// resolution: 8 pixels then cross more than one 16-texel cache line).
#[inline(always)]
fn prefetch_every(u: &[i32], k: u32) -> usize {
    match (u.first(), u.last()) {
        (Some(&a), Some(&b)) if ((b - a).unsigned_abs() >> (8 + k)) as usize > 2 * u.len() => 4,
        _ => 8,
    }
}

/// [`prefetch`] the first [`PREFETCH_AHEAD`] positions of a run, every `every` pixels,
/// before drawing it (the kernel's loop prefetches the rest as far ahead).
#[inline(always)]
fn prefetch_start<const BILINEAR: bool>(t: &Texels, uv: (&[i32], &[i32]), k: u32, every: usize) {
    for j in (0..PREFETCH_AHEAD.min(uv.0.len())).step_by(every) {
        prefetch::<BILINEAR>(t, uv, j, k);
    }
}

/// One vector's texel indices and 8-bit fractions (x, y) from Q.8 positions, written once
/// per instruction set: `$v` the vector type, `$p` the intrinsics' prefix.
macro_rules! lanes {
    ($feature:literal, $v:ty, $set1:ident, $add:ident, $sub:ident, $and:ident, $andnot:ident,
     $or:ident, $gt:ident, $min:ident, $max:ident, $minu:ident, $srai:ident, $mullo:ident,
     $zero:ident, $sra:ident) => {
        /// (indices clamped to `last`, fx, fy) of positions (u, v), Q.8 (see
        /// `row::sample_at`: bilinear biased by −½, x wrapped, y clamped with fy dropped).
        #[inline]
        #[target_feature(enable = $feature)]
        fn lanes<const BILINEAR: bool>(t: &Texels, u: $v, v: $v, last: usize) -> ($v, $v, $v) {
            let (w, h1) = (t.width as i32, t.height as i32 - 1);
            let zero = $zero();
            let (u, v) = if BILINEAR {
                ($sub(u, $set1(128)), $sub(v, $set1(128)))
            } else {
                (u, v)
            };
            let wv = $set1(w);
            let x = $srai::<8>(u);
            let x = $add(x, $and($gt(zero, x), wv));
            let x = $add(x, $and($gt(zero, x), wv));
            let x = $sub(x, $and($gt(x, $set1(w - 1)), wv));
            let x = $sub(x, $and($gt(x, $set1(w - 1)), wv));
            let x = $min($max(x, zero), $set1(w - 1));
            let y = $srai::<8>(v);
            let ff = $set1(0xFF);
            let (fx, fy) = if BILINEAR {
                let off = $or($gt(zero, y), $gt(y, $set1(h1 - 1)));
                ($and(u, ff), $andnot(off, $and(v, ff)))
            } else {
                (zero, zero)
            };
            let y = $min($max(y, zero), $set1(h1));
            let i = $add($mullo(y, $set1(t.stride() as i32)), x);
            ($minu(i, $set1(last as i32)), fx, fy)
        }

        /// Level-0 positions (u, v) on level `lv.k`: u wrapped into the level-0 map
        /// (within two widths of it), both shifted right by k (see `row::wrap_q8`).
        #[inline]
        #[target_feature(enable = $feature)]
        fn on_level(u: $v, v: $v, lv: &Level) -> ($v, $v) {
            let zero = $zero();
            let wv = $set1(lv.wq);
            let u = $add(u, $and($gt(zero, u), wv));
            let u = $add(u, $and($gt(zero, u), wv));
            let top = $set1(lv.wq - 1);
            let u = $sub(u, $and($gt(u, top), wv));
            let u = $sub(u, $and($gt(u, top), wv));
            let k = _mm_cvtsi32_si128(lv.k as i32);
            ($sra(u, k), $sra(v, k))
        }
    };
}

/// `expand` (see `row::expand_scalar`) for one instruction set, `$n` lanes: the three
/// position lines of each span, a vector per step, stored whole (the next span overwrites
/// what lies past a span).
macro_rules! expand_kernel {
    ($feature:literal, $n:literal, $shift:literal, $iota:expr, $set1:ident, $add:ident,
     $sub:ident, $mullo:ident, $srai:ident, $slli:ident, $store:ident) => {
        #[inline]
        #[target_feature(enable = $feature)]
        pub(super) fn expand(spans: &[SpanQ8], p: Positions<'_>) {
            let iota = $iota;
            for s in spans {
                let (k, m) = (s.k as usize, s.m as usize);
                let r = k..k + m.next_multiple_of($n);
                let cu = p.u[r.clone()].chunks_exact_mut($n);
                let out = cu.zip(p.v[r.clone()].chunks_exact_mut($n));
                let (du, dv) = ($set1(s.du), $set1(s.dv));
                let (iu, iv) = ($mullo(iota, du), $mullo(iota, dv));
                let (mut lu, mut lv) = ($add($set1(s.lu), iu), $add($set1(s.lv), iv));
                let mut ll = $sub($set1(s.ll), iu);
                let (su, sv) = ($slli::<$shift>(du), $slli::<$shift>(dv));
                let (hu, hv, hl) = ($set1(s.hu), $set1(s.hv), $set1(s.hl));
                for ((cu, cv), cl) in out.zip(p.ul[r].chunks_exact_mut($n)) {
                    let a = $add(hu, $srai::<8>(lu));
                    let b = $add(hv, $srai::<8>(lv));
                    let c = $add(hl, $srai::<8>(ll));
                    // SAFETY: `cu`, `cv`, `cl` are $n writable i32 each; unaligned stores.
                    unsafe {
                        $store(cu.as_mut_ptr().cast(), a);
                        $store(cv.as_mut_ptr().cast(), b);
                        $store(cl.as_mut_ptr().cast(), c);
                    }
                    lu = $add(lu, su);
                    lv = $add(lv, sv);
                    ll = $sub(ll, su);
                }
            }
        }
    };
}

mod avx2 {
    use super::super::avx2::{lerp, merge, split};
    use super::*;

    lanes!(
        "avx2",
        __m256i,
        _mm256_set1_epi32,
        _mm256_add_epi32,
        _mm256_sub_epi32,
        _mm256_and_si256,
        _mm256_andnot_si256,
        _mm256_or_si256,
        _mm256_cmpgt_epi32,
        _mm256_min_epi32,
        _mm256_max_epi32,
        _mm256_min_epu32,
        _mm256_srai_epi32,
        _mm256_mullo_epi32,
        _mm256_setzero_si256,
        _mm256_sra_epi32
    );

    /// An 8-bit weight per 32-bit lane as (w, 256 − w) in both 16-bit halves.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn weight(f: __m256i) -> (__m256i, __m256i) {
        let w = _mm256_or_si256(f, _mm256_slli_epi32::<16>(f));
        (w, _mm256_sub_epi16(_mm256_set1_epi16(256), w))
    }

    expand_kernel!(
        "avx2",
        8,
        3,
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
        _mm256_set1_epi32,
        _mm256_add_epi32,
        _mm256_sub_epi32,
        _mm256_mullo_epi32,
        _mm256_srai_epi32,
        _mm256_slli_epi32,
        _mm256_storeu_si256
    );

    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn sample_q8<
        const BILINEAR: bool,
        const MIRROR: bool,
        const LEVEL: bool,
        const BLEND: bool,
    >(
        t: &Texels,
        u: &[i32],
        v: &[i32],
        out: &mut [u32],
        lv: &Level,
    ) {
        let n = out.len();
        let (u, v) = (&u[..n], &v[..n]);
        let last = last_index::<BILINEAR>(t);
        let stride = t.stride();
        let p = t.px.as_ptr();
        let rev = _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0);
        let k = if LEVEL { lv.k } else { 0 };
        let every = prefetch_every(u, k);
        prefetch_start::<BILINEAR>(t, (u, v), k, every);
        let mut j = 0;
        while j + 8 <= n {
            prefetch::<BILINEAR>(t, (u, v), j + PREFETCH_AHEAD, k);
            if every < 8 {
                prefetch::<BILINEAR>(t, (u, v), j + PREFETCH_AHEAD + 4, k);
            }
            let (cu, cv): (&[i32; 8], &[i32; 8]) = (
                u[j..j + 8].try_into().expect("8"),
                v[j..j + 8].try_into().expect("8"),
            );
            // SAFETY: `cu`, `cv` are 8 readable i32; the loads are unaligned.
            let (uu, vv) = unsafe {
                (
                    _mm256_loadu_si256(cu.as_ptr().cast()),
                    _mm256_loadu_si256(cv.as_ptr().cast()),
                )
            };
            let (uu, vv) = if LEVEL {
                on_level(uu, vv, lv)
            } else {
                (uu, vv)
            };
            let (i, fx, fy) = lanes::<BILINEAR>(t, uu, vv, last);
            let mut a = [0u32; 8];
            // SAFETY: `a` is 32 writable bytes; the store is unaligned.
            unsafe { _mm256_storeu_si256(a.as_mut_ptr().cast(), i) };
            let c = if BILINEAR {
                let pair = |k: usize, row: usize| -> i64 {
                    // SAFETY: a[k] ≤ last = len − stride − 2 (clamped in `lanes`), so the
                    // 8 bytes at a[k] + row (row ≤ stride) are inside `t.px`.
                    unsafe { p.add(a[k] as usize + row).cast::<i64>().read_unaligned() }
                };
                let q = |row: usize, h: usize| {
                    _mm256_set_epi64x(
                        pair(5 + h, row),
                        pair(4 + h, row),
                        pair(1 + h, row),
                        pair(h, row),
                    )
                };
                let (ta, tb, ba, bb) = (q(0, 0), q(0, 2), q(stride, 0), q(stride, 2));
                let shuf = |x: __m256i, y: __m256i, left: bool| {
                    let (x, y) = (_mm256_castsi256_ps(x), _mm256_castsi256_ps(y));
                    _mm256_castps_si256(if left {
                        _mm256_shuffle_ps::<0x88>(x, y)
                    } else {
                        _mm256_shuffle_ps::<0xDD>(x, y)
                    })
                };
                let wx = weight(fx);
                let top = lerp(split(shuf(ta, tb, true)), split(shuf(ta, tb, false)), wx);
                let bot = lerp(split(shuf(ba, bb, true)), split(shuf(ba, bb, false)), wx);
                merge(lerp(top, bot, weight(fy)))
            } else {
                // SAFETY: a[k] ≤ last = len − 1 (clamped in `lanes`).
                let g = |k: usize| unsafe { p.add(a[k] as usize).read() } as i32;
                _mm256_setr_epi32(g(0), g(1), g(2), g(3), g(4), g(5), g(6), g(7))
            };
            let (c, at) = if MIRROR {
                (_mm256_permutevar8x32_epi32(c, rev), n - j - 8)
            } else {
                (c, j)
            };
            let o: &mut [u32; 8] = (&mut out[at..at + 8]).try_into().expect("8");
            let c = if BLEND {
                let cw: &[u32; 8] = lv.w[j..j + 8].try_into().expect("8");
                // SAFETY: `cw` and `o` are 8 readable u32; the loads are unaligned.
                let (f, prev) = unsafe {
                    (
                        _mm256_loadu_si256(cw.as_ptr().cast()),
                        _mm256_loadu_si256(o.as_ptr().cast()),
                    )
                };
                let f = if MIRROR {
                    _mm256_permutevar8x32_epi32(f, rev)
                } else {
                    f
                };
                merge(lerp(split(prev), split(c), weight(f)))
            } else {
                c
            };
            // SAFETY: `o` is 8 writable u32; the store is unaligned.
            unsafe { _mm256_storeu_si256(o.as_mut_ptr().cast(), c) };
            j += 8;
        }
        let rest = if MIRROR {
            &mut out[..n - j]
        } else {
            &mut out[j..]
        };
        let lv = Level {
            w: if BLEND { &lv.w[j..] } else { lv.w },
            ..*lv
        };
        sample_lv_scalar::<BILINEAR, MIRROR, LEVEL, BLEND>(t, &u[j..], &v[j..], rest, &lv);
    }
}

mod sse41 {
    use super::super::sse41::{lerp, merge, split};
    use super::*;

    lanes!(
        "sse4.1",
        __m128i,
        _mm_set1_epi32,
        _mm_add_epi32,
        _mm_sub_epi32,
        _mm_and_si128,
        _mm_andnot_si128,
        _mm_or_si128,
        _mm_cmpgt_epi32,
        _mm_min_epi32,
        _mm_max_epi32,
        _mm_min_epu32,
        _mm_srai_epi32,
        _mm_mullo_epi32,
        _mm_setzero_si128,
        _mm_sra_epi32
    );

    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn weight(f: __m128i) -> (__m128i, __m128i) {
        let w = _mm_or_si128(f, _mm_slli_epi32::<16>(f));
        (w, _mm_sub_epi16(_mm_set1_epi16(256), w))
    }

    expand_kernel!(
        "sse4.1",
        4,
        2,
        _mm_setr_epi32(0, 1, 2, 3),
        _mm_set1_epi32,
        _mm_add_epi32,
        _mm_sub_epi32,
        _mm_mullo_epi32,
        _mm_srai_epi32,
        _mm_slli_epi32,
        _mm_storeu_si128
    );

    #[inline]
    #[target_feature(enable = "sse4.1")]
    pub(super) fn sample_q8<
        const BILINEAR: bool,
        const MIRROR: bool,
        const LEVEL: bool,
        const BLEND: bool,
    >(
        t: &Texels,
        u: &[i32],
        v: &[i32],
        out: &mut [u32],
        lv: &Level,
    ) {
        let n = out.len();
        let (u, v) = (&u[..n], &v[..n]);
        let last = last_index::<BILINEAR>(t);
        let stride = t.stride();
        let p = t.px.as_ptr();
        let k = if LEVEL { lv.k } else { 0 };
        let every = prefetch_every(u, k);
        prefetch_start::<BILINEAR>(t, (u, v), k, every);
        let mut j = 0;
        while j + 4 <= n {
            if j & (every - 1) == 0 {
                prefetch::<BILINEAR>(t, (u, v), j + PREFETCH_AHEAD, k);
            }
            let (cu, cv): (&[i32; 4], &[i32; 4]) = (
                u[j..j + 4].try_into().expect("4"),
                v[j..j + 4].try_into().expect("4"),
            );
            // SAFETY: `cu`, `cv` are 4 readable i32; the loads are unaligned.
            let (uu, vv) = unsafe {
                (
                    _mm_loadu_si128(cu.as_ptr().cast()),
                    _mm_loadu_si128(cv.as_ptr().cast()),
                )
            };
            let (uu, vv) = if LEVEL {
                on_level(uu, vv, lv)
            } else {
                (uu, vv)
            };
            let (i, fx, fy) = lanes::<BILINEAR>(t, uu, vv, last);
            let mut a = [0u32; 4];
            // SAFETY: `a` is 16 writable bytes; the store is unaligned.
            unsafe { _mm_storeu_si128(a.as_mut_ptr().cast(), i) };
            let c = if BILINEAR {
                let pair = |k: usize, row: usize| -> i64 {
                    // SAFETY: a[k] ≤ last = len − stride − 2 (clamped in `lanes`), so the
                    // 8 bytes at a[k] + row (row ≤ stride) are inside `t.px`.
                    unsafe { p.add(a[k] as usize + row).cast::<i64>().read_unaligned() }
                };
                let ta = _mm_set_epi64x(pair(1, 0), pair(0, 0));
                let tb = _mm_set_epi64x(pair(3, 0), pair(2, 0));
                let ba = _mm_set_epi64x(pair(1, stride), pair(0, stride));
                let bb = _mm_set_epi64x(pair(3, stride), pair(2, stride));
                let shuf = |x: __m128i, y: __m128i, left: bool| {
                    let (x, y) = (_mm_castsi128_ps(x), _mm_castsi128_ps(y));
                    _mm_castps_si128(if left {
                        _mm_shuffle_ps::<0x88>(x, y)
                    } else {
                        _mm_shuffle_ps::<0xDD>(x, y)
                    })
                };
                let wx = weight(fx);
                let top = lerp(split(shuf(ta, tb, true)), split(shuf(ta, tb, false)), wx);
                let bot = lerp(split(shuf(ba, bb, true)), split(shuf(ba, bb, false)), wx);
                merge(lerp(top, bot, weight(fy)))
            } else {
                // SAFETY: a[k] ≤ last = len − 1 (clamped in `lanes`).
                let g = |k: usize| unsafe { p.add(a[k] as usize).read() } as i32;
                _mm_setr_epi32(g(0), g(1), g(2), g(3))
            };
            let (c, at) = if MIRROR {
                (_mm_shuffle_epi32::<0x1B>(c), n - j - 4)
            } else {
                (c, j)
            };
            let o: &mut [u32; 4] = (&mut out[at..at + 4]).try_into().expect("4");
            let c = if BLEND {
                let cw: &[u32; 4] = lv.w[j..j + 4].try_into().expect("4");
                // SAFETY: `cw` and `o` are 4 readable u32; the loads are unaligned.
                let (f, prev) = unsafe {
                    (
                        _mm_loadu_si128(cw.as_ptr().cast()),
                        _mm_loadu_si128(o.as_ptr().cast()),
                    )
                };
                let f = if MIRROR {
                    _mm_shuffle_epi32::<0x1B>(f)
                } else {
                    f
                };
                merge(lerp(split(prev), split(c), weight(f)))
            } else {
                c
            };
            // SAFETY: `o` is 4 writable u32; the store is unaligned.
            unsafe { _mm_storeu_si128(o.as_mut_ptr().cast(), c) };
            j += 4;
        }
        let rest = if MIRROR {
            &mut out[..n - j]
        } else {
            &mut out[j..]
        };
        let lv = Level {
            w: if BLEND { &lv.w[j..] } else { lv.w },
            ..*lv
        };
        sample_lv_scalar::<BILINEAR, MIRROR, LEVEL, BLEND>(t, &u[j..], &v[j..], rest, &lv);
    }
}

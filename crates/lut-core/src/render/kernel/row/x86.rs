//! x86-64 row kernels (see `row/mod.rs`): 16 (AVX-512), 8 (AVX2) or 4 (SSE4.1) pixels
//! per step, the seam wrap and the pole clamp as lane compares, the texels read as the map kernels read
//! them (two 64-bit loads per bilinear pixel) and blended with their `split`, `lerp` and
//! `merge`; the left half's pixels reversed in the register before the store. Each
//! kernel prefetches the texels of the position about [`PREFETCH_TEXELS`] map texels
//! ahead along the run (`prefetch_ahead`: 256 pixels where a pixel steps a texel or
//! less, at least [`PREFETCH_AHEAD`]; the frame is bound by memory latency, not
//! instructions: see there), and with it, into L2, the rows the next scanline will read
//! that this one does not (`next_rows`, from the offset `Texels::toward_next_scanline`
//! carries; only where a run reads half a texel² of map a pixel or more:
//! `next_scanline`).
//!
//! The kernels are written once (`row_kernels!`) and expanded in each instruction set's
//! module, where short names stand for that set's intrinsics (`add` is
//! `_mm256_add_epi32` in `avx2`, `_mm_add_epi32` in `sse41`; `V` the vector type, `N` its
//! lanes) and a few functions hold what differs in more than the prefix: the lane
//! layout of the texel pairs (`pairs`), the nearest gather (`gather`, in `x86_lanes.rs` beside
//! `split`, `lerp` and `merge`), the reversal
//! (`reverse`), `iota`, the compares (`add_if_below`, `sub_if_above`, `zero_outside`:
//! vector compares and masks in AVX2 and SSE4.1, `vector_compares!`; mask registers and
//! masked adds in AVX-512), and the kernel for the last pixels of a run (`tail`: the
//! scalar one, or for AVX-512 the AVX2 one, so that a run of 8–15 pixels, common in the
//! trilinear level runs, still goes 8 at a time). Every function is `#[target_feature]`
//! and `#[inline]`, compiled into the entry points as before: the same code per set as
//! when each was written out.
//!
//! AVX-512 (`avx512`, 16 `i32` lanes): `shufps` works within 128-bit quarters there too,
//! so `pairs` lays the pairs out as (0, 1, 4, 5, 8, 9, 12, 13) and (2, 3, …, 15). Plain
//! 64-bit loads, as AVX2 does, measured faster than `vpgatherdq` for the pairs (and
//! scalar loads faster than `vpgatherdd` for nearest) on AMD Zen 5: see
//! `docs/performance.md`, "AVX-512".

#![allow(unsafe_code)]

use super::scalar::sample_lv as sample_lv_scalar;
use super::{Level, Positions, SpanQ8};
use crate::render::kernel::select::{Kernel, SelectedKernel};
use crate::render::kernel::x86_lanes::{
    prefetch_next_rows, prefetch_texels, PREFETCH_AHEAD, PREFETCH_TEXELS,
};
use crate::render::kernel::Texels;
use std::arch::x86_64::*;

/// The row kernel with a SIMD kernel (see `scalar::sample_lv`); `false` (nothing
/// written) for the scalar one.
#[inline(always)]
pub(super) fn sample_q8<
    const BILINEAR: bool,
    const MIRROR: bool,
    const LEVEL: bool,
    const BLEND: bool,
>(
    k: SelectedKernel,
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
    lv: &Level,
) -> bool {
    match k.0 {
        // SAFETY: `k` is a `SelectedKernel`, made only when the CPU runs the kernel.
        Kernel::Avx512 => unsafe {
            avx512::sample_q8::<BILINEAR, MIRROR, LEVEL, BLEND>(t, u, v, out, lv)
        },
        // SAFETY: as above.
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

/// `SelectedKernel::expand` with a SIMD kernel; the buffers back, untouched,
/// for the scalar one.
#[inline(always)]
pub(super) fn expand<'a, const MIRROR: bool>(
    k: SelectedKernel,
    spans: &[SpanQ8],
    p: Positions<'a>,
) -> Option<Positions<'a>> {
    match k.0 {
        // SAFETY: `k` is a `SelectedKernel`, made only when the CPU runs the kernel.
        Kernel::Avx512 => unsafe { avx512::expand::<MIRROR>(spans, p) },
        // SAFETY: as above.
        Kernel::Avx2 => unsafe { avx2::expand::<MIRROR>(spans, p) },
        // SAFETY: as above.
        Kernel::Sse41 => unsafe { sse41::expand::<MIRROR>(spans, p) },
        Kernel::Scalar => return Some(p),
    }
    None
}

/// The largest index whose read (one texel, or the 2×2 block) stays inside `t`.
#[inline(always)]
fn last_index<const BILINEAR: bool>(t: &Texels) -> usize {
    t.px.len() - if BILINEAR { t.stride() + 2 } else { 1 }
}

/// Prefetch the cache lines position `j` of (`u`, `v`) (Q.8, on level `k`) will read:
/// its texel, and for bilinear the one below. Positions past the run are skipped;
/// positions off the map (a seam not yet wrapped) prefetch a wrong line, which is
/// harmless: a prefetch never faults and changes no result.
///
/// With `dv` not 0 (the run's [`next_scanline`]), also the two rows from [`next_rows`]
/// on, into L2.
#[inline(always)]
fn prefetch<const BILINEAR: bool>(t: &Texels, u: &[i32], v: &[i32], j: usize, k: u32, dv: i32) {
    if let (Some(&u), Some(&v)) = (u.get(j), v.get(j)) {
        let stride = t.stride() as isize;
        let (x, y) = ((u >> (8 + k)) as isize, (v >> (8 + k)) as isize);
        let row = t.px.as_ptr().wrapping_offset(x);
        prefetch_texels::<BILINEAR>(row.wrapping_offset(y.wrapping_mul(stride)), t.stride());
        if dv != 0 {
            let y = next_rows::<BILINEAR>(v, dv, k) as isize;
            prefetch_next_rows(row.wrapping_offset(y.wrapping_mul(stride)), t.stride());
        }
    }
}

/// The next scanline's offset (`Texels::next_dv`, level-0 Q.8 rows) for a run of
/// positions `u` (Q.8, on level `k`) whose next scanline's rows are worth prefetching,
/// else 0: where the run reads half a texel² of the map per pixel or more (texels per
/// pixel along the run times rows per scanline). Below that a frame reads so little of
/// the map that it stays in the cache, and the prefetches only cost: the 4096x2048 map's
/// frame at hfov 90 (0.5 texels a pixel, 0.6 rows a scanline) drew ~10 % slower with
/// them, the 8192x4096 map's (1.1 and 1.2) ~20 % faster, and cube-face runs (whose
/// texels get denser toward the faces' edges) ~10 % faster than with a row a scanline as
/// the bound.
#[inline(always)]
fn next_scanline(t: &Texels, u: &[i32], k: u32) -> i32 {
    let dv = t.next_dv();
    let rows = u64::from(dv.unsigned_abs() >> k);
    let travel = match (u.first(), u.last()) {
        (Some(&a), Some(&b)) => u64::from(b.abs_diff(a) >> k),
        _ => 0,
    };
    // rows (Q.8) × texels (Q.8) / pixels ≥ ½ (Q.16).
    if rows * travel >= (1 << 15) * u.len() as u64 {
        dv
    } else {
        0
    }
}

/// The first of the two map rows (on level `k`) that [`prefetch`] fetches for the next
/// scanline, whose position at this pixel is `dv` rows (level-0 Q.8) from `v`'s: its
/// row Y = ⌊(v + dv) / 2^(8+k)⌋ unless that is a row this scanline reads (y, and for
/// bilinear y + 1), then the first row past them in the direction of `dv`. The next
/// scanline reads Y (and Y + 1), so this covers what it reads anew when `dv` is right,
/// and when the true offset is smaller (the rows of a scanline's edges move less than
/// its centre's, where `dv` is measured) the rows just past this one's.
#[inline(always)]
fn next_rows<const BILINEAR: bool>(v: i32, dv: i32, k: u32) -> i32 {
    let s = 8 + k;
    let (y, ny) = (v >> s, v.saturating_add(dv) >> s);
    match (BILINEAR, dv > 0) {
        (true, true) => ny.max(y + 2),
        (true, false) => ny.min(y - 2),
        (false, true) => ny.max(y + 1),
        (false, false) => ny.min(y - 1) - 1,
    }
}

/// How far ahead (pixels) a run of positions `u` (Q.8, on level `k`) prefetches: the
/// pixels that cover about [`PREFETCH_TEXELS`] texels of the map along the run (from its
/// ends), at least [`PREFETCH_AHEAD`] and at most `PREFETCH_TEXELS` pixels.
#[inline(always)]
fn prefetch_ahead(u: &[i32], k: u32) -> usize {
    match (u.first(), u.last()) {
        (Some(&a), Some(&b)) => {
            let travel = ((b - a).unsigned_abs() >> (8 + k)) as usize;
            (PREFETCH_TEXELS * u.len() / travel.max(1)).clamp(PREFETCH_AHEAD, PREFETCH_TEXELS)
        }
        _ => PREFETCH_TEXELS,
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

/// The row kernels of one instruction set (`$feature`), in terms of the names its module
/// defines: `V` (the vector of `N` i32 lanes), `N`, `LOG2_N`, the intrinsic aliases
/// (`add`, `sub`, `and`, `or`, `min`, `max`, `minu`, `srai`, `slli`, `sra`, `mullo`,
/// `set1`, `set1_16`, `sub16`, `zero`, `loadu`, `storeu`, `shuffle_ps`, `to_ps`,
/// `from_ps`), `iota`, `pairs`, `gather`, `reverse`, `add_if_below`, `sub_if_above`,
/// `zero_outside` and `tail`, and the map kernels' `split`, `lerp`, `merge` and `gather`.
macro_rules! row_kernels {
    ($feature:literal) => {
        /// (indices clamped to `last`, fx, fy) of positions (u, v), Q.8 (see
        /// `row::sample_at`: bilinear biased by −½, x wrapped, y clamped with fy dropped;
        /// when every lane is inside the map, one test (`within`) and none of that).
        #[inline]
        #[target_feature(enable = $feature)]
        fn lanes<const BILINEAR: bool>(t: &Texels, u: V, v: V, last: usize) -> (V, V, V) {
            let (w, h1) = (t.width as i32, t.height as i32 - 1);
            let zero = zero();
            let (u, v) = if BILINEAR {
                (sub(u, set1(128)), sub(v, set1(128)))
            } else {
                (u, v)
            };
            let (x, y) = (srai::<8>(u), srai::<8>(v));
            let ff = set1(0xFF);
            // The common case first: every lane inside the map (as unsigned, x ≤ W − 1
            // and y ≤ H − 2, the last row a bilinear read starts on, or H − 1 for
            // nearest), where the wrap and the clamps below change nothing.
            let y_in = if BILINEAR { h1 - 1 } else { h1 };
            if y_in >= 0 && within(x, set1(w - 1), y, set1(y_in)) {
                let (fx, fy) = if BILINEAR {
                    (and(u, ff), and(v, ff))
                } else {
                    (zero, zero)
                };
                let i = add(mullo(y, set1(t.stride() as i32)), x);
                return (minu(i, set1(last as i32)), fx, fy);
            }
            let wv = set1(w);
            let x = add_if_below(x, zero, wv);
            let x = add_if_below(x, zero, wv);
            let x = sub_if_above(x, set1(w - 1), wv);
            let x = sub_if_above(x, set1(w - 1), wv);
            let x = min(max(x, zero), set1(w - 1));
            let (fx, fy) = if BILINEAR {
                (and(u, ff), zero_outside(y, set1(h1 - 1), and(v, ff)))
            } else {
                (zero, zero)
            };
            let y = min(max(y, zero), set1(h1));
            let i = add(mullo(y, set1(t.stride() as i32)), x);
            (minu(i, set1(last as i32)), fx, fy)
        }

        /// Level-0 positions (u, v) on level `lv.k`: u wrapped into the level-0 map
        /// (within two widths of it), both shifted right by k (see `row::wrap_q8`).
        #[inline]
        #[target_feature(enable = $feature)]
        fn on_level(u: V, v: V, lv: &Level) -> (V, V) {
            let zero = zero();
            let wv = set1(lv.wq);
            let u = add_if_below(u, zero, wv);
            let u = add_if_below(u, zero, wv);
            let top = set1(lv.wq - 1);
            let u = sub_if_above(u, top, wv);
            let u = sub_if_above(u, top, wv);
            let k = _mm_cvtsi32_si128(lv.k as i32);
            (sra(u, k), sra(v, k))
        }

        /// An 8-bit weight per 32-bit lane as (w, 256 − w) in both 16-bit halves.
        #[inline]
        #[target_feature(enable = $feature)]
        fn weight(f: V) -> (V, V) {
            let w = or(f, slli::<16>(f));
            (w, sub16(set1_16(256), w))
        }

        /// The left texels of the pixels whose pairs `pairs` laid out in `x`, `y`.
        #[inline]
        #[target_feature(enable = $feature)]
        fn left(x: V, y: V) -> V {
            from_ps(shuffle_ps::<0x88>(to_ps(x), to_ps(y)))
        }

        /// The right texels (see `left`).
        #[inline]
        #[target_feature(enable = $feature)]
        fn right(x: V, y: V) -> V {
            from_ps(shuffle_ps::<0xDD>(to_ps(x), to_ps(y)))
        }

        /// `expand` (see `row::expand_scalar`): the position lines of each span (u, v,
        /// and with `MIRROR` the left half's u), a vector per step, stored whole (the
        /// next span overwrites what lies past a span). One bounds check per span: its
        /// last vector's end against the shortest buffer.
        #[inline]
        #[target_feature(enable = $feature)]
        pub(super) fn expand<const MIRROR: bool>(spans: &[SpanQ8], p: Positions<'_>) {
            let len = p.u.len().min(p.v.len());
            let len = if MIRROR { len.min(p.ul.len()) } else { len };
            let (pu, pv, pl) = (p.u.as_mut_ptr(), p.v.as_mut_ptr(), p.ul.as_mut_ptr());
            let iota = iota();
            for s in spans {
                let (k, m) = (s.k as usize, s.m as usize);
                // m rounded up to whole vectors (N a power of two; u32 + u32 and the
                // rounding do not overflow a usize).
                let end = k + ((m + N - 1) & !(N - 1));
                assert!(
                    end <= len,
                    "span {k}..{end} past the position buffers ({len})"
                );
                let (du, dv) = (set1(s.du), set1(s.dv));
                let (iu, iv) = (mullo(iota, du), mullo(iota, dv));
                let (mut lu, mut lv) = (add(set1(s.lu), iu), add(set1(s.lv), iv));
                let mut ll = sub(set1(s.ll), iu);
                let (su, sv) = (slli::<LOG2_N>(du), slli::<LOG2_N>(dv));
                let (hu, hv, hl) = (set1(s.hu), set1(s.hv), set1(s.hl));
                // Whole vectors from k to `end`; the lines step after a vector only if
                // another follows (a span of at most N pixels, the common case, is one
                // store per line and no update).
                let mut j = k;
                while j < end {
                    // SAFETY: j + N ≤ end ≤ len, the length of `u`, `v` (and of `ul` when
                    // MIRROR, the only case it is written): N writable i32 at j of each;
                    // unaligned stores.
                    unsafe {
                        storeu(pu.add(j).cast(), add(hu, srai::<8>(lu)));
                        storeu(pv.add(j).cast(), add(hv, srai::<8>(lv)));
                        if MIRROR {
                            storeu(pl.add(j).cast(), add(hl, srai::<8>(ll)));
                        }
                    }
                    j += N;
                    if j >= end {
                        break;
                    }
                    lu = add(lu, su);
                    lv = add(lv, sv);
                    if MIRROR {
                        ll = sub(ll, su);
                    }
                }
            }
        }

        /// The row kernel (see `row::sample_lv_scalar`), N pixels per step, the rest
        /// (fewer than N) with `tail` (the scalar one, or for AVX-512 the AVX2 one).
        #[inline]
        #[target_feature(enable = $feature)]
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
            // Prefetched up to (not including) `ahead`, every `every` positions, `pfa`
            // positions past the vector being drawn.
            let k = if LEVEL { lv.k } else { 0 };
            let every = prefetch_every(u, k);
            let pfa = prefetch_ahead(u, k);
            let next = next_scanline(t, u, k);
            let mut ahead = 0;
            let mut j = 0;
            while j + N <= n {
                while ahead < j + N + pfa {
                    prefetch::<BILINEAR>(t, u, v, ahead, k, next);
                    ahead += every;
                }
                let (cu, cv): (&[i32; N], &[i32; N]) = (
                    u[j..j + N].try_into().expect("N"),
                    v[j..j + N].try_into().expect("N"),
                );
                // SAFETY: `cu`, `cv` are N readable i32; the loads are unaligned.
                let (uu, vv) = unsafe { (loadu(cu.as_ptr().cast()), loadu(cv.as_ptr().cast())) };
                let (uu, vv) = if LEVEL {
                    on_level(uu, vv, lv)
                } else {
                    (uu, vv)
                };
                let (i, fx, fy) = lanes::<BILINEAR>(t, uu, vv, last);
                let mut a = [0u32; N];
                // SAFETY: `a` is N writable u32; the store is unaligned.
                unsafe { storeu(a.as_mut_ptr().cast(), i) };
                let c = if BILINEAR {
                    let pair = |k: usize, row: usize| -> i64 {
                        // SAFETY: a[k] ≤ last = len − stride − 2 (clamped in `lanes`), so
                        // the 8 bytes at a[k] + row (row ≤ stride) are inside `t.px`.
                        unsafe { p.add(a[k] as usize + row).cast::<i64>().read_unaligned() }
                    };
                    let (ta, tb) = pairs(|k| pair(k, 0));
                    let (ba, bb) = pairs(|k| pair(k, stride));
                    let wx = weight(fx);
                    let top = lerp(split(left(ta, tb)), split(right(ta, tb)), wx);
                    let bot = lerp(split(left(ba, bb)), split(right(ba, bb)), wx);
                    merge(lerp(top, bot, weight(fy)))
                } else {
                    // SAFETY: a[k] ≤ last = len − 1 (clamped in `lanes`).
                    let g = |k: usize| unsafe { p.add(a[k] as usize).read() } as i32;
                    gather(g)
                };
                let (c, at) = if MIRROR {
                    (reverse(c), n - j - N)
                } else {
                    (c, j)
                };
                let o: &mut [u32; N] = (&mut out[at..at + N]).try_into().expect("N");
                let c = if BLEND {
                    let cw: &[u32; N] = lv.w[j..j + N].try_into().expect("N");
                    let (pw, po) = (cw.as_ptr().cast(), o.as_ptr().cast());
                    // SAFETY: `cw` and `o` are N readable u32; the loads are unaligned.
                    let (f, prev) = unsafe { (loadu(pw), loadu(po)) };
                    let f = if MIRROR { reverse(f) } else { f };
                    merge(lerp(split(prev), split(c), weight(f)))
                } else {
                    c
                };
                // SAFETY: `o` is N writable u32; the store is unaligned.
                unsafe { storeu(o.as_mut_ptr().cast(), c) };
                j += N;
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
            tail::<BILINEAR, MIRROR, LEVEL, BLEND>(t, &u[j..], &v[j..], rest, &lv);
        }
    };
}

/// The lane compares of `lanes` and `on_level` for a set whose compares give vectors
/// (`gt`: all-ones or zero per lane), in terms of its aliases.
macro_rules! vector_compares {
    ($feature:literal) => {
        /// `x + w` where `x < lo`, else `x`.
        #[inline]
        #[target_feature(enable = $feature)]
        fn add_if_below(x: V, lo: V, w: V) -> V {
            add(x, and(gt(lo, x), w))
        }

        /// `x − w` where `x > hi`, else `x`.
        #[inline]
        #[target_feature(enable = $feature)]
        fn sub_if_above(x: V, hi: V, w: V) -> V {
            sub(x, and(gt(x, hi), w))
        }

        /// `f` where 0 ≤ `y` ≤ `hi`, else 0.
        #[inline]
        #[target_feature(enable = $feature)]
        fn zero_outside(y: V, hi: V, f: V) -> V {
            andnot(or(gt(zero(), y), gt(y, hi)), f)
        }

        /// Whether every lane has `x` ≤ `xm` and `y` ≤ `ym` as unsigned (0 ≤ x ≤ xm,
        /// 0 ≤ y ≤ ym for non-negative bounds).
        #[inline]
        #[target_feature(enable = $feature)]
        fn within(x: V, xm: V, y: V, ym: V) -> bool {
            let ok = and(eq(minu(x, xm), x), eq(minu(y, ym), y));
            movemask(ok) == ALL_LANES
        }
    };
}

mod avx2 {
    use super::sample_lv_scalar as tail;
    use super::*;
    use crate::render::kernel::x86_lanes::avx2::{gather, lerp, merge, split};
    use std::arch::x86_64::{
        __m256i as V, _mm256_add_epi32 as add, _mm256_and_si256 as and,
        _mm256_andnot_si256 as andnot, _mm256_castps_si256 as from_ps,
        _mm256_castsi256_ps as to_ps, _mm256_cmpgt_epi32 as gt, _mm256_loadu_si256 as loadu,
        _mm256_max_epi32 as max, _mm256_min_epi32 as min, _mm256_min_epu32 as minu,
        _mm256_mullo_epi32 as mullo, _mm256_or_si256 as or, _mm256_set1_epi16 as set1_16,
        _mm256_set1_epi32 as set1, _mm256_setzero_si256 as zero, _mm256_shuffle_ps as shuffle_ps,
        _mm256_slli_epi32 as slli, _mm256_sra_epi32 as sra, _mm256_srai_epi32 as srai,
        _mm256_storeu_si256 as storeu, _mm256_sub_epi16 as sub16, _mm256_sub_epi32 as sub,
    };
    use std::arch::x86_64::{_mm256_cmpeq_epi32 as eq, _mm256_movemask_epi8 as movemask};

    /// Pixels per step, and its log2.
    const N: usize = 8;
    const LOG2_N: i32 = 3;
    /// `movemask` of a vector with every lane set.
    const ALL_LANES: i32 = -1;

    row_kernels!("avx2");
    vector_compares!("avx2");

    /// The lane numbers.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn iota() -> V {
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)
    }

    /// The 64-bit texel pairs of lanes 0..8 (`pair(k)`) as two vectors, (0, 1, 4, 5) and
    /// (2, 3, 6, 7), so that `shufps` (within 128-bit halves) gives lanes 0..8 in order.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn pairs(pair: impl Fn(usize) -> i64) -> (V, V) {
        (
            _mm256_set_epi64x(pair(5), pair(4), pair(1), pair(0)),
            _mm256_set_epi64x(pair(7), pair(6), pair(3), pair(2)),
        )
    }

    /// The lanes in reverse order.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn reverse(c: V) -> V {
        _mm256_permutevar8x32_epi32(c, _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0))
    }
}

mod avx512 {
    use super::avx2::sample_q8 as tail;
    use super::*;
    use crate::render::kernel::x86_lanes::avx512::{gather, lerp, merge, pairs, split};
    use std::arch::x86_64::{
        __m512i as V, _mm512_add_epi32 as add, _mm512_and_si512 as and,
        _mm512_castps_si512 as from_ps, _mm512_castsi512_ps as to_ps, _mm512_loadu_si512 as loadu,
        _mm512_max_epi32 as max, _mm512_min_epi32 as min, _mm512_min_epu32 as minu,
        _mm512_mullo_epi32 as mullo, _mm512_or_si512 as or, _mm512_set1_epi16 as set1_16,
        _mm512_set1_epi32 as set1, _mm512_setzero_si512 as zero, _mm512_shuffle_ps as shuffle_ps,
        _mm512_slli_epi32 as slli, _mm512_sra_epi32 as sra, _mm512_srai_epi32 as srai,
        _mm512_storeu_si512 as storeu, _mm512_sub_epi16 as sub16, _mm512_sub_epi32 as sub,
    };

    /// Pixels per step, and its log2.
    const N: usize = 16;
    const LOG2_N: u32 = 4;

    row_kernels!("avx2,avx512f,avx512bw,avx512vl,avx512dq");

    /// `x + w` where `x < lo`, else `x` (a masked add).
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn add_if_below(x: V, lo: V, w: V) -> V {
        _mm512_mask_add_epi32(x, _mm512_cmplt_epi32_mask(x, lo), x, w)
    }

    /// `x − w` where `x > hi`, else `x` (a masked subtract).
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn sub_if_above(x: V, hi: V, w: V) -> V {
        _mm512_mask_sub_epi32(x, _mm512_cmpgt_epi32_mask(x, hi), x, w)
    }

    /// Whether every lane has `x` ≤ `xm` and `y` ≤ `ym` as unsigned (two mask compares).
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn within(x: V, xm: V, y: V, ym: V) -> bool {
        _mm512_cmple_epu32_mask(x, xm) & _mm512_cmple_epu32_mask(y, ym) == 0xFFFF
    }

    /// `f` where 0 ≤ `y` ≤ `hi`, else 0.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn zero_outside(y: V, hi: V, f: V) -> V {
        let inside = _mm512_mask_cmple_epi32_mask(_mm512_cmpge_epi32_mask(y, zero()), y, hi);
        _mm512_maskz_mov_epi32(inside, f)
    }

    /// The lane numbers.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn iota() -> V {
        _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15)
    }

    /// The lanes in reverse order.
    #[inline]
    #[target_feature(enable = "avx2,avx512f,avx512bw,avx512vl,avx512dq")]
    fn reverse(c: V) -> V {
        let r = _mm512_setr_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
        _mm512_permutexvar_epi32(r, c)
    }
}

mod sse41 {
    use super::sample_lv_scalar as tail;
    use super::*;
    use crate::render::kernel::x86_lanes::sse41::{gather, lerp, merge, split};
    use std::arch::x86_64::{
        __m128i as V, _mm_add_epi32 as add, _mm_and_si128 as and, _mm_andnot_si128 as andnot,
        _mm_castps_si128 as from_ps, _mm_castsi128_ps as to_ps, _mm_cmpgt_epi32 as gt,
        _mm_loadu_si128 as loadu, _mm_max_epi32 as max, _mm_min_epi32 as min,
        _mm_min_epu32 as minu, _mm_mullo_epi32 as mullo, _mm_or_si128 as or,
        _mm_set1_epi16 as set1_16, _mm_set1_epi32 as set1, _mm_setzero_si128 as zero,
        _mm_shuffle_ps as shuffle_ps, _mm_slli_epi32 as slli, _mm_sra_epi32 as sra,
        _mm_srai_epi32 as srai, _mm_storeu_si128 as storeu, _mm_sub_epi16 as sub16,
        _mm_sub_epi32 as sub,
    };
    use std::arch::x86_64::{_mm_cmpeq_epi32 as eq, _mm_movemask_epi8 as movemask};

    /// Pixels per step, and its log2.
    const N: usize = 4;
    const LOG2_N: i32 = 2;
    /// `movemask` of a vector with every lane set.
    const ALL_LANES: i32 = 0xFFFF;

    row_kernels!("sse4.1");
    vector_compares!("sse4.1");

    /// The lane numbers.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn iota() -> V {
        _mm_setr_epi32(0, 1, 2, 3)
    }

    /// The 64-bit texel pairs of lanes 0..4 (`pair(k)`) as two vectors, (0, 1) and
    /// (2, 3), so that `shufps` gives lanes 0..4 in order.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn pairs(pair: impl Fn(usize) -> i64) -> (V, V) {
        (
            _mm_set_epi64x(pair(1), pair(0)),
            _mm_set_epi64x(pair(3), pair(2)),
        )
    }

    /// The lanes in reverse order.
    #[inline]
    #[target_feature(enable = "sse4.1")]
    fn reverse(c: V) -> V {
        _mm_shuffle_epi32::<0x1B>(c)
    }
}

#[cfg(test)]
mod tests {
    use super::{next_rows, next_scanline};
    use crate::render::kernel::Texels;

    /// [`next_scanline`] keeps the next scanline's offset where a run reads half a texel²
    /// of the map per pixel or more, on level 0 and on level 1 (where a level-0 offset
    /// and travel are halved), in either direction, and gives 0 below that.
    #[test]
    fn next_scanline_only_where_the_run_reads_half_a_texel_squared_a_pixel() {
        let px = vec![0u32; 9 * 9];
        let t = Texels::new(&px, 8, 8, true).unwrap();
        // A 100-pixel run travelling `tx` texels (Q.8 positions), next scanline `dv` rows.
        let run = |tx: f64, dv: f64, k: u32| {
            let u: Vec<i32> = (0..100)
                .map(|i| (i as f64 * tx / 99.0 * 256.0) as i32)
                .collect();
            let dv = (dv * 256.0) as i32;
            next_scanline(&t.toward_next_scanline(dv), &u, k) == dv
        };
        for sign in [1.0, -1.0] {
            assert!(run(107.0, sign * 1.24, 0), "the 8k map's frame");
            assert!(!run(53.0, sign * 0.62, 0), "the 4k map's frame");
            assert!(run(100.0, sign * 0.51, 0) && !run(100.0, sign * 0.49, 0));
            assert!(run(200.0, sign * 1.02, 1) && !run(200.0, sign * 0.98, 1));
        }
    }

    /// The two rows [`next_rows`] gives hold every row the next scanline reads that this
    /// one does not (this one reads y and for bilinear y + 1; the next one ⌊(v + dv)⌋ and
    /// for bilinear the row below), on every level, down and up the map, for offsets
    /// below a row to several rows, and for every fraction of `v` in the tested rows.
    #[test]
    fn next_rows_hold_the_rows_the_next_scanline_reads_anew() {
        for k in 0..3u32 {
            let s = 8 + k;
            for dv in (-2000..=2000).step_by(7).filter(|&d: &i32| d != 0) {
                for v in (1000 << s)..(1000 << s) + (3 << s) {
                    for bilinear in [false, true] {
                        let (y, ny) = (v >> s, (v + dv) >> s);
                        let rows = |a: i32| if bilinear { vec![a, a + 1] } else { vec![a] };
                        let first = if bilinear {
                            next_rows::<true>(v, dv, k)
                        } else {
                            next_rows::<false>(v, dv, k)
                        };
                        for r in rows(ny) {
                            assert!(
                                rows(y).contains(&r) || r == first || r == first + 1,
                                "k {k}, v {v}, dv {dv}, bilinear {bilinear}: row {r} of the \
                                 next scanline not fetched (rows {first}, {})",
                                first + 1
                            );
                        }
                    }
                }
            }
        }
    }
}

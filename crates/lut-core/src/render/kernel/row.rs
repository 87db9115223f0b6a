//! Row kernels: a run of a scanline's positions expanded from its spans, and the gather
//! (nearest) or gather-and-blend (bilinear; trilinear: bilinear on a pyramid level,
//! written or blended in by per-position weights, [`sample_level`]) pass over them, for
//! full 360° maps (the LUT renderer's rows, `render/rowpass.rs`).
//!
//! The positions are `i32` Q.8 map coordinates (the 8 fraction bits are all the bilinear
//! weights use), one per pixel, in the order of the right half of the scanline; the left
//! half's (its mirror image: Λ negated) are kept in the same order and written to the
//! row reversed. Per pixel the kernel wraps x by up to two map widths either way in lanes,
//! clamps y at the poles (dropping the weight there as the per-pixel sampler does), and
//! gathers: no span checks, no refusals, no per-span setup.
//!
//! [`sample_lv_scalar`] and [`expand_scalar`] are the reference: every SIMD kernel
//! (`x86/row.rs`) writes the same pixels and positions (`tests/row_pass.rs`), and the
//! pixels equal the per-pixel samplers' (`EnvMap::nearest` / `EnvMap::bilinear` at the
//! wrapped position u/256, v/256; on pyramid levels `EnvMap::trilinear`).

use super::select::{active, Selected};
use super::Texels;
use crate::map::sample::lerp_px;

#[cfg(target_arch = "x86_64")]
use super::x86;

/// The sample of `t` at the Q.8 position (u, v): x wrapped into the map (u within two map
/// widths of it: −2W ≤ x < 3W), y clamped; bilinear reads the 2×2 block around
/// (u − ½, v − ½).
#[inline(always)]
pub(super) fn sample_at<const BILINEAR: bool>(t: &Texels, u: i32, v: i32) -> u32 {
    let (w, h1, stride) = (t.width as i32, t.height as i32 - 1, t.stride());
    let (u, v) = if BILINEAR { (u - 128, v - 128) } else { (u, v) };
    let mut x = u >> 8;
    // One test for the common case (inside the map).
    if x as u32 >= w as u32 {
        x = wrap_x(x, w);
    }
    let x = x as usize;
    let y = v >> 8;
    if BILINEAR {
        let fx = (u & 0xFF) as u32;
        let (y, fy) = if (y as u32) < h1 as u32 {
            (y, (v & 0xFF) as u32)
        } else if y < 0 {
            (0, 0)
        } else {
            (h1, 0)
        };
        let i = y as usize * stride + x;
        let q = &t.px[i..i + stride + 2];
        lerp_px(
            lerp_px(q[0], q[1], fx),
            lerp_px(q[stride], q[stride + 1], fx),
            fy,
        )
    } else {
        let y = if (y as u32) <= h1 as u32 {
            y
        } else {
            y.clamp(0, h1)
        };
        t.px[y as usize * stride + x]
    }
}

/// x (outside `0..w`) wrapped by up to two map widths either way, then clamped.
#[inline(always)]
fn wrap_x(mut x: i32, w: i32) -> i32 {
    if x < 0 {
        x += w;
    }
    if x < 0 {
        x += w;
    }
    if x >= w {
        x -= w;
    }
    if x >= w {
        x -= w;
    }
    x.clamp(0, w - 1)
}

/// A pyramid level for the trilinear row kernels ([`sample_level`]): the level's index
/// `k` (positions are level-0 Q.8: level k reads (u wrapped into the map) >> k and
/// v >> k, as `EnvMap::trilinear` shifts its Q.16 positions), the level-0 map's width
/// in Q.8 (`wq`), and with `BLEND` the weight of the level per position (`w[j]` for
/// position j, 0..=255: `out = lerp(out, sample, w)`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Level<'a> {
    pub(crate) k: u32,
    pub(crate) wq: i32,
    pub(crate) w: &'a [u32],
}

/// No level: the map itself (plain nearest or bilinear).
const LEVEL0: Level<'static> = Level {
    k: 0,
    wq: 0,
    w: &[],
};

/// u (within two map widths of the map, `wq` its width, Q.8) wrapped into `0..wq`.
#[inline(always)]
pub(crate) fn wrap_q8(mut u: i32, wq: i32) -> i32 {
    if u < 0 {
        u += wq;
    }
    if u < 0 {
        u += wq;
    }
    if u >= wq {
        u -= wq;
    }
    if u >= wq {
        u -= wq;
    }
    u
}

/// The scalar kernel: `out[j]` = the sample at (`u[j]`, `v[j]`), or with `MIRROR` (the
/// left half) `out[n − 1 − j]` (n = `out.len()` ≤ the positions); on a pyramid level
/// with `LEVEL` (u wrapped into the level-0 map, then u and v shifted right by `lv.k`)
/// and blended into `out` by the weights `lv.w` with `BLEND` (`lerp_px(out, sample,
/// w[j])`).
#[inline(always)]
pub(super) fn sample_lv_scalar<
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
    for (j, (&uu, &vv)) in u[..n].iter().zip(&v[..n]).enumerate() {
        let at = if MIRROR { n - 1 - j } else { j };
        let (uu, vv) = if LEVEL {
            (wrap_q8(uu, lv.wq) >> lv.k, vv >> lv.k)
        } else {
            (uu, vv)
        };
        let s = sample_at::<BILINEAR>(t, uu, vv);
        out[at] = if BLEND {
            lerp_px(out[at], s, lv.w[j])
        } else {
            s
        };
    }
}

/// [`sample_lv_scalar`] (no level, no blend) with kernel `k`.
#[inline]
pub(super) fn sample_q8_with<const BILINEAR: bool, const MIRROR: bool>(
    k: Selected,
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
) {
    sample_lv_with::<BILINEAR, MIRROR, false, false>(k, t, u, v, out, &LEVEL0);
}

/// [`sample_lv_scalar`] with kernel `k`.
#[inline]
pub(super) fn sample_lv_with<
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
) {
    assert!(
        u.len() >= out.len() && v.len() >= out.len() && (!BLEND || lv.w.len() >= out.len()),
        "a position (and a weight) per pixel"
    );
    assert!(
        !LEVEL || (lv.k < 31 && lv.wq > 0),
        "a level below 31 of a map"
    );
    #[cfg(target_arch = "x86_64")]
    if x86::row::sample_q8::<BILINEAR, MIRROR, LEVEL, BLEND>(k, t, u, v, out, lv) {
        return;
    }
    let _ = k;
    sample_lv_scalar::<BILINEAR, MIRROR, LEVEL, BLEND>(t, u, v, out, lv);
}

/// The trilinear row kernel: bilinear samples of pyramid level `t` (level `lv.k` of a
/// map `lv.wq` / 256 wide) at level-0 Q.8 positions (`u` within two map widths of the
/// map, as [`sample_q8`] takes them), into `out` (`BLEND` false) or blended into it by
/// the weights `lv.w` (`BLEND` true: `out = lerp_px(out, sample, w[j])`, the blend of
/// `EnvMap::trilinear`); `MIRROR` as [`sample_q8`], the weights indexed like the
/// positions. With the [`active_kernel`](super::active_kernel).
///
/// # Panics
/// When there are fewer positions (or weights, with `BLEND`) than pixels, `lv.k` ≥ 31
/// or `lv.wq` ≤ 0.
#[inline]
pub(crate) fn sample_level<const MIRROR: bool, const BLEND: bool>(
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
    lv: &Level,
) {
    sample_lv_with::<true, MIRROR, true, BLEND>(active(), t, u, v, out, lv);
}

/// [`sample_lv_scalar`] (no level, no blend) with the [`active_kernel`](super::active_kernel): the row pass's
/// pixels. Positions u must lie within two map widths of the map, as the row pass's do
/// (a span starts in the map and travels less than a width); outside, x is clamped
/// (never a read outside the map). y is clamped.
///
/// # Panics
/// When there are fewer positions than pixels.
#[inline]
pub(crate) fn sample_q8<const BILINEAR: bool, const MIRROR: bool>(
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
) {
    sample_q8_with::<BILINEAR, MIRROR>(active(), t, u, v, out);
}

/// A span of a row's positions (see [`expand`]): pixel `k + j` (j < m) of the buffers
/// gets `hu + ((lu + j·du) >> 8)`, `hv + ((lv + j·dv) >> 8)` and, for the mirror image
/// in the left half, `hl + ((ll − j·du) >> 8)`: the Q.8 (floored) positions of Q.16
/// starts `256·h + l` (0 ≤ l < 256) and steps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct SpanQ8 {
    pub(crate) k: u32,
    pub(crate) m: u32,
    pub(crate) hu: i32,
    pub(crate) lu: i32,
    pub(crate) du: i32,
    pub(crate) hv: i32,
    pub(crate) lv: i32,
    pub(crate) dv: i32,
    pub(crate) hl: i32,
    pub(crate) ll: i32,
}

impl SpanQ8 {
    /// The span of `m` pixels from buffer position `k` whose Q.16 positions start at
    /// (`u`, `v`), and `ul` for the mirror image (0 where there is none), and step by
    /// (`du`, `dv`) a pixel (the mirror image by −`du`): each start split into its whole
    /// Q.8 value and its low byte, as the lanes take them. The steps must fit an `i32`.
    #[inline(always)]
    pub(crate) fn from_q16(
        (k, m): (usize, usize),
        (u, v, ul): (i64, i64, i64),
        (du, dv): (i64, i64),
    ) -> SpanQ8 {
        SpanQ8 {
            k: k as u32,
            m: m as u32,
            hu: (u >> 8) as i32,
            lu: (u & 0xFF) as i32,
            du: du as i32,
            hv: (v >> 8) as i32,
            lv: (v & 0xFF) as i32,
            dv: dv as i32,
            hl: (ul >> 8) as i32,
            ll: (ul & 0xFF) as i32,
        }
    }
}

/// The position buffers of a run: u and v of the right half, u of the left half (its v
/// is the right half's), indexed alike. `ul` is written only by a mirrored expand
/// (`expand::<true>`); without a mirror image it may be empty.
pub(crate) struct Positions<'a> {
    pub(crate) u: &'a mut [i32],
    pub(crate) v: &'a mut [i32],
    pub(crate) ul: &'a mut [i32],
}

/// The scalar kernel of [`expand`]: exactly pixels `k..k + m` of each span.
#[inline(always)]
pub(super) fn expand_scalar<const MIRROR: bool>(spans: &[SpanQ8], p: Positions<'_>) {
    for s in spans {
        let r = s.k as usize..(s.k + s.m) as usize;
        let (mut lu, mut lv) = (s.lu, s.lv);
        for (a, b) in p.u[r.clone()].iter_mut().zip(&mut p.v[r.clone()]) {
            *a = s.hu.wrapping_add(lu >> 8);
            *b = s.hv.wrapping_add(lv >> 8);
            lu = lu.wrapping_add(s.du);
            lv = lv.wrapping_add(s.dv);
        }
        if MIRROR {
            let mut ll = s.ll;
            for c in &mut p.ul[r] {
                *c = s.hl.wrapping_add(ll >> 8);
                ll = ll.wrapping_sub(s.du);
            }
        }
    }
}

/// Expand `spans` (in order of `k`, each starting where the one before ended) into the
/// position buffers, which hold at least 16 entries past the last span (the SIMD kernels
/// write whole vectors; the next span overwrites what lies past a span): u and v, and
/// with `MIRROR` the mirror image's u (`ul`; the row pass's left half). The row pass's
/// per-pixel positions, one kernel call per run.
///
/// # Panics
/// When a span (rounded up to 16 pixels) does not fit in the buffers.
#[inline]
pub(crate) fn expand<const MIRROR: bool>(spans: &[SpanQ8], p: Positions<'_>) {
    expand_with::<MIRROR>(active(), spans, p);
}

/// [`expand`] with kernel `k`.
#[inline]
pub(super) fn expand_with<const MIRROR: bool>(k: Selected, spans: &[SpanQ8], p: Positions<'_>) {
    #[cfg(target_arch = "x86_64")]
    let p = match x86::row::expand::<MIRROR>(k, spans, p) {
        None => return,
        Some(p) => p,
    };
    let _ = k;
    expand_scalar::<MIRROR>(spans, p);
}

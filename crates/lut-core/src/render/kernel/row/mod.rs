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
//! This file holds the types and the dispatch; `scalar.rs` is the reference
//! (`sample_lv`, `expand`): every SIMD kernel (`x86.rs`) writes the same pixels and positions (`kernel/tests/row_pass.rs`), and the
//! pixels equal the per-pixel samplers' (`EnvMap::nearest` / `EnvMap::bilinear` at the
//! wrapped position u/256, v/256; on pyramid levels `EnvMap::trilinear`).

use super::select::SelectedKernel;
use super::Texels;

mod scalar;
#[cfg(target_arch = "x86_64")]
mod x86;

/// A pyramid level for the trilinear row kernels ([`SelectedKernel::sample_level`]): the level's index
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
pub(super) const LEVEL0: Level<'static> = Level {
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

/// A span of a row's positions (see [`SelectedKernel::expand`]): pixel `k + j` (j < m) of the buffers
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

/// Where a [`SpanQ8`] writes: `m` pixels of the position buffers from `k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct SpanAt {
    /// The first pixel's index in the buffers.
    pub(crate) k: u32,
    /// Pixels.
    pub(crate) m: u32,
}

/// A span's first position, Q.16 map pixels: `u`, `v`, and `ul` for the mirror image (0
/// where there is none).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Q16Start {
    pub(crate) u: i64,
    pub(crate) v: i64,
    pub(crate) ul: i64,
}

/// A span's step per pixel, Q.16 map pixels (the mirror image's u steps by −`du`). Each
/// must fit an `i32`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Q16Step {
    pub(crate) du: i64,
    pub(crate) dv: i64,
}

impl SpanQ8 {
    /// The span of `at.m` pixels from buffer position `at.k` whose Q.16 positions start
    /// at `start` and step by `step` a pixel: each start split into its whole Q.8 value
    /// and its low byte, as the lanes take them.
    #[inline(always)]
    pub(crate) fn from_q16(at: SpanAt, start: Q16Start, step: Q16Step) -> SpanQ8 {
        let Q16Start { u, v, ul } = start;
        let Q16Step { du, dv } = step;
        SpanQ8 {
            k: at.k,
            m: at.m,
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

impl SelectedKernel {
    /// The row kernel: `out[j]` = the sample at (`u[j]`, `v[j]`), or with `MIRROR` (the
    /// left half) `out[n − 1 − j]` (n = `out.len()` ≤ the positions); on a pyramid level
    /// with `LEVEL` (u wrapped into the level-0 map, then u and v shifted right by
    /// `lv.k`) and blended into `out` by the weights `lv.w` with `BLEND`
    /// (`lerp_px(out, sample, w[j])`). The general form of [`SelectedKernel::sample_q8`]
    /// and [`SelectedKernel::sample_level`] (the cube faces' blended runs call it).
    ///
    /// # Panics
    /// When there are fewer positions (or weights, with `BLEND`) than pixels, or with
    /// `LEVEL` when `lv.k` ≥ 31 or `lv.wq` ≤ 0.
    #[inline]
    pub(crate) fn sample_lv<
        const BILINEAR: bool,
        const MIRROR: bool,
        const LEVEL: bool,
        const BLEND: bool,
    >(
        self,
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
        if x86::sample_q8::<BILINEAR, MIRROR, LEVEL, BLEND>(self, t, u, v, out, lv) {
            return;
        }
        scalar::sample_lv::<BILINEAR, MIRROR, LEVEL, BLEND>(t, u, v, out, lv);
    }

    /// The row pass's pixels: [`SelectedKernel::sample_lv`] with no level and no
    /// blend. Positions u must lie within two map widths of the map, as the row pass's
    /// do (a span starts in the map and travels less than a width); outside, x is
    /// clamped (never a read outside the map). y is clamped.
    ///
    /// # Panics
    /// When there are fewer positions than pixels.
    #[inline]
    pub(crate) fn sample_q8<const BILINEAR: bool, const MIRROR: bool>(
        self,
        t: &Texels,
        u: &[i32],
        v: &[i32],
        out: &mut [u32],
    ) {
        self.sample_lv::<BILINEAR, MIRROR, false, false>(t, u, v, out, &LEVEL0);
    }

    /// The trilinear row kernel: bilinear samples of pyramid level `t` (level `lv.k` of
    /// a map `lv.wq` / 256 wide) at level-0 Q.8 positions (`u` within two map widths of
    /// the map, as [`SelectedKernel::sample_q8`] takes them), into `out` (`BLEND` false)
    /// or blended into it by the weights `lv.w` (`BLEND` true: `out = lerp_px(out,
    /// sample, w[j])`, the blend of `EnvMap::trilinear`); `MIRROR` as
    /// [`SelectedKernel::sample_q8`], the weights indexed like the positions.
    ///
    /// # Panics
    /// When there are fewer positions (or weights, with `BLEND`) than pixels, `lv.k` ≥ 31
    /// or `lv.wq` ≤ 0.
    #[inline]
    pub(crate) fn sample_level<const MIRROR: bool, const BLEND: bool>(
        self,
        t: &Texels,
        u: &[i32],
        v: &[i32],
        out: &mut [u32],
        lv: &Level,
    ) {
        self.sample_lv::<true, MIRROR, true, BLEND>(t, u, v, out, lv);
    }

    /// Expand `spans` (in order of `k`, each starting where the one before ended) into
    /// the position buffers, which hold at least 16 entries past the last span (the SIMD
    /// kernels write whole vectors; the next span overwrites what lies past a span): u
    /// and v, and with `MIRROR` the mirror image's u (`ul`; the row pass's left half).
    /// The row pass's per-pixel positions, one kernel call per run.
    ///
    /// # Panics
    /// When a span (rounded up to 16 pixels) does not fit in the buffers.
    #[inline]
    pub(crate) fn expand<const MIRROR: bool>(self, spans: &[SpanQ8], p: Positions<'_>) {
        #[cfg(target_arch = "x86_64")]
        let p = match x86::expand::<MIRROR>(self, spans, p) {
            None => return,
            Some(p) => p,
        };
        scalar::expand::<MIRROR>(spans, p);
    }
}

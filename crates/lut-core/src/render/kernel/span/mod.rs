//! Span kernels: a run of output pixels whose map positions step linearly in Q.16
//! ([`Steps`]), sampled with no clamp and no wrap when the whole run lies inside the map
//! (checked at its two ends by [`prepare`]); batches of a row's spans ([`SpanJob`],
//! [`run_jobs`], [`run_tri_jobs`]); partial maps' spans ([`SelectedKernel::cropped_span`]);
//! and the renderer's entries on an [`EnvMap`] (the kernel, else the per-pixel
//! samplers: [`sample_span`], [`sample_spans`], [`trilinear_spans`],
//! [`nearest_span_direct`], [`sample_span_cropped`]).
//!
//! This file holds the types and the dispatch; `scalar.rs` the portable kernels (the
//! reference), `x86.rs` the SSE4.1 and AVX2 ones (`Kernel::Avx512` runs AVX2 here).

#[cfg(test)]
use super::level_texels;
use super::select::{active, SelectedKernel};
use super::{texels, Texels};
use crate::geom::fixed::{Fx, FX_BITS, FX_HALF, FX_ONE};
use crate::map::envmap::EnvMap;
use crate::map::sample::lerp_px;

mod scalar;
#[cfg(target_arch = "x86_64")]
mod x86;

/// Longest span the trilinear kernel blends in one piece (the second level restarts its
/// position every this many pixels, as the per-pixel path always has).
pub const TRILINEAR_CHUNK: usize = 64;

/// Most spans in one batch ([`SelectedKernel::bilinear_spans`]: one bit per span in its
/// answer).
pub const MAX_JOBS: usize = 32;

/// Positions stepping linearly along a run of pixels: pixel `i` samples
/// (u + i·du, v + i·dv), Q.16 map coordinates.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Steps {
    /// Position of the first pixel, horizontal.
    pub u: Fx,
    /// Position of the first pixel, vertical.
    pub v: Fx,
    /// Horizontal step per pixel.
    pub du: Fx,
    /// Vertical step per pixel.
    pub dv: Fx,
}

/// One span of an output row, for the batch kernels: `len` pixels from column `x` on
/// sample (u + i·du, v + i·dv), Q.16 map coordinates.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SpanJob {
    /// First output column.
    pub x: u32,
    /// Pixels.
    pub len: u32,
    /// Position of the first pixel.
    pub u: Fx,
    /// Position of the first pixel.
    pub v: Fx,
    /// Step per pixel.
    pub du: Fx,
    /// Step per pixel.
    pub dv: Fx,
}

impl SpanJob {
    /// The span's positions.
    #[inline(always)]
    pub fn steps(&self) -> Steps {
        Steps {
            u: self.u,
            v: self.v,
            du: self.du,
            dv: self.dv,
        }
    }
}

/// A partial map's place in the full panorama, for [`SelectedKernel::cropped_span`]: the
/// stored [`Texels`] hold columns `left..left + width` (mod `full_width`) and rows
/// `top..top + height` of a `full_width × full_height` panorama.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// Full panorama width in pixels.
    pub full_width: u32,
    /// Full panorama height in pixels.
    pub full_height: u32,
    /// First stored column, in `0..full_width`.
    pub left: u32,
    /// First stored row.
    pub top: u32,
    /// The background colour (0RGB) outside the stored pixels.
    pub background: u32,
}

/// A span checked to lie inside its map: the start (already biased by −½ for bilinear
/// and wrapped into the map) and the step, Q.16.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Span {
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
}

impl SelectedKernel {
    /// Nearest samples along a span: `out[i]` = the pixel containing
    /// (u + i·du, v + i·dv) of `s` (for a wrapping map u may start up to one period
    /// outside [0, W)). Returns `false`, writing nothing, when some position falls
    /// outside the map: the caller then samples per pixel (with clamps and wraps).
    #[inline]
    pub fn nearest_span(self, t: &Texels, out: &mut [u32], s: Steps) -> bool {
        span::<false>(self, t, out, s)
    }

    /// Bilinear samples along a span: the four pixel centres around each position
    /// − ½, 8-bit weights (see [`SelectedKernel::nearest_span`] for the coordinates and
    /// the return value).
    #[inline]
    pub fn bilinear_span(self, t: &Texels, out: &mut [u32], s: Steps) -> bool {
        span::<true>(self, t, out, s)
    }

    /// [`SelectedKernel::nearest_span`] for a batch of spans of one output row (at most
    /// [`MAX_JOBS`]): one call for many short spans. Returns a mask of the spans left
    /// unwritten because they leave the map (bit i: `spans[i]`).
    ///
    /// # Panics
    /// When a span does not fit in `row`, or there are more than [`MAX_JOBS`] spans.
    #[inline]
    pub fn nearest_spans(self, t: &Texels, row: &mut [u32], spans: &[SpanJob]) -> u64 {
        jobs::<false>(self, t, row, spans)
    }

    /// [`SelectedKernel::bilinear_span`] for a batch of spans of one output row (see
    /// [`SelectedKernel::nearest_spans`]).
    ///
    /// # Panics
    /// As [`SelectedKernel::nearest_spans`].
    #[inline]
    pub fn bilinear_spans(self, t: &Texels, row: &mut [u32], spans: &[SpanJob]) -> u64 {
        jobs::<true>(self, t, row, spans)
    }

    /// Trilinear samples along a span with level of detail `lod` (Q.8, 256 = one
    /// level, as `lod_q8` in the pyramid module computes it): `levels[0]` is the map,
    /// `levels[k]` its pyramid level k (half the size of level k − 1). `lod` ≤ 0 is
    /// bilinear on level 0; otherwise levels k = `lod >> 8` and k + 1 (each clamped to
    /// the last) are sampled bilinearly at the positions and steps shifted right by their
    /// index and blended by `lod & 0xFF` (level k alone when that is 0 or both clamp to
    /// the same level); the second level restarts its position every
    /// [`TRILINEAR_CHUNK`] pixels. Returns `false` when a level's span leaves its map;
    /// `out` may then hold partial results and the caller samples it another way.
    ///
    /// # Panics
    /// When `levels` is empty.
    #[inline]
    pub fn trilinear_span(self, levels: &[Texels], out: &mut [u32], s: Steps, lod: i32) -> bool {
        trilinear(self, levels, out, s, lod)
    }

    /// [`SelectedKernel::trilinear_span`] for a batch of spans of one output row,
    /// `lods[i]` the level of detail of `spans[i]` (see
    /// [`SelectedKernel::nearest_spans`] for the batch and the answer).
    ///
    /// # Panics
    /// As [`SelectedKernel::nearest_spans`], and when `lods` and `spans` differ in length
    /// or `levels` is empty.
    #[inline]
    pub fn trilinear_spans(
        self,
        levels: &[Texels],
        row: &mut [u32],
        spans: &[SpanJob],
        lods: &[i32],
    ) -> u64 {
        tri_jobs(self, levels, row, spans, lods)
    }

    /// Nearest (`BILINEAR` false) or bilinear samples of a partial map along a span of
    /// full-panorama positions (see [`Window`]; `t` holds the stored pixels, wrapping
    /// only when they span 360°). Handled when the whole span lies in the stored
    /// pixels' interior (where the crop changes nothing: the plain span kernel on the
    /// stored pixels) or wholly in the background; otherwise (a span over the crop's
    /// edge) it returns `false`, writing nothing, and the caller samples per pixel.
    #[inline]
    pub fn cropped_span<const BILINEAR: bool>(
        self,
        t: &Texels,
        w: &Window,
        out: &mut [u32],
        s: Steps,
    ) -> bool {
        cropped::<BILINEAR>(self, t, w, out, s)
    }
}

/// Check a span and wrap its start (see [`SelectedKernel::nearest_span`]). Positions or steps
/// of 2⁴⁶ or more (no map comes near) and spans of 2¹⁶ pixels or more are refused, so
/// the arithmetic below cannot overflow.
#[inline(always)]
fn prepare<const BILINEAR: bool>(t: &Texels, m: usize, s: Steps) -> Option<Span> {
    let big = s.u.unsigned_abs() | s.v.unsigned_abs() | s.du.unsigned_abs() | s.dv.unsigned_abs();
    if (big >> 46 | m as u64 >> 16) != 0 {
        return None;
    }
    let wfx = (t.width as i64) << FX_BITS;
    let hfx = (t.height as i64) << FX_BITS;
    // Bilinear reads the pixel centres around (u − ½, v − ½).
    let bias = if BILINEAR { FX_HALF } else { 0 };
    let mut uu = s.u - bias;
    if t.wraps && !(0..wfx).contains(&uu) {
        // One period off at most on the renderer's path; a division otherwise.
        uu += if uu < 0 { wfx } else { -wfx };
        if !(0..wfx).contains(&uu) {
            uu = uu.rem_euclid(wfx);
        }
    }
    let vv = s.v - bias;
    let n = m as i64 - 1;
    let (u_end, v_end) = (uu + s.du * n, vv + s.dv * n);
    // Nearest may read column W and row H (padding equal to the clamped pixel);
    // bilinear needs x0, y0 ≤ W − 1, H − 1 so that x0 + 1, y0 + 1 are the padding.
    let (u_lim, v_lim) = if BILINEAR {
        (wfx, hfx)
    } else {
        (wfx + FX_ONE, hfx + FX_ONE)
    };
    // Both ends inside [0, lim): the unsigned comparison also rejects negatives.
    let inside = |a: Fx, lim: Fx| (a as u64) < lim as u64;
    (inside(uu, u_lim) && inside(u_end, u_lim) && inside(vv, v_lim) && inside(v_end, v_lim))
        .then_some(Span {
            u: uu,
            v: vv,
            du: s.du,
            dv: s.dv,
        })
}

/// Runs `run` on every span of `jobs` inside the map (the slice of `row` it covers and
/// the checked span); returns a mask of the spans refused (bit i: `jobs[i]`).
///
/// # Panics
/// When a span does not fit in `row`, or there are more than [`MAX_JOBS`] spans.
#[inline(always)]
fn run_jobs<const BILINEAR: bool>(
    t: &Texels,
    row: &mut [u32],
    jobs: &[SpanJob],
    mut run: impl FnMut(&mut [u32], Span),
) -> u64 {
    assert!(jobs.len() <= MAX_JOBS, "{} spans in one batch", jobs.len());
    let mut refused = 0u64;
    for (i, j) in jobs.iter().enumerate() {
        let out = &mut row[j.x as usize..j.x as usize + j.len as usize];
        if out.is_empty() {
            continue;
        }
        match prepare::<BILINEAR>(t, out.len(), j.steps()) {
            Some(s) => run(out, s),
            None => refused |= 1 << i,
        }
    }
    refused
}

/// The batch kernels with kernel `k`.
#[inline]
fn jobs<const BILINEAR: bool>(
    k: SelectedKernel,
    t: &Texels,
    row: &mut [u32],
    jobs: &[SpanJob],
) -> u64 {
    #[cfg(target_arch = "x86_64")]
    if let Some(r) = x86::jobs::<BILINEAR>(k, t, row, jobs) {
        return r;
    }
    let _ = k;
    run_jobs::<BILINEAR>(t, row, jobs, |out, s| {
        if BILINEAR {
            scalar::bilinear(t, out, s)
        } else {
            scalar::nearest(t, out, s)
        }
    })
}

/// The job of a whole slice `out` at positions `s`; `None` for 2¹⁶ pixels or more
/// (which `prepare` refuses too).
#[inline(always)]
fn whole(out: &[u32], s: Steps) -> Option<SpanJob> {
    (out.len() >> 16 == 0).then_some(SpanJob {
        x: 0,
        len: out.len() as u32,
        u: s.u,
        v: s.v,
        du: s.du,
        dv: s.dv,
    })
}

/// One span: a batch of one (each SIMD loop then has a single caller, the batch loop,
/// and is compiled into it).
#[inline(always)]
fn span<const BILINEAR: bool>(k: SelectedKernel, t: &Texels, out: &mut [u32], s: Steps) -> bool {
    whole(out, s).is_some_and(|job| jobs::<BILINEAR>(k, t, out, &[job]) == 0)
}

/// One trilinear span: a batch of one.
#[inline(always)]
fn trilinear(k: SelectedKernel, levels: &[Texels], out: &mut [u32], s: Steps, lod: i32) -> bool {
    whole(out, s).is_some_and(|job| tri_jobs(k, levels, out, &[job], &[lod]) == 0)
}

/// The trilinear batch kernels with kernel `k`.
#[inline]
fn tri_jobs(
    k: SelectedKernel,
    levels: &[Texels],
    row: &mut [u32],
    jobs: &[SpanJob],
    lods: &[i32],
) -> u64 {
    #[cfg(target_arch = "x86_64")]
    if let Some(r) = x86::tri_jobs(k, levels, row, jobs, lods) {
        return r;
    }
    let _ = k;
    run_tri_jobs(
        levels,
        row,
        jobs,
        lods,
        scalar::bilinear,
        scalar::blend_bilinear,
    )
}

/// Runs the trilinear spans of `jobs` (level of detail `lods[i]`, Q.8, as
/// `lod_q8` in `map/pyramid.rs`) on `levels` with the kernels `bil` (bilinear) and `blend`
/// (bilinear blended into the output); returns the mask of spans refused.
///
/// The levels are resolved as the map's pyramid resolves them: `lod` ≤ 0 is bilinear on
/// level 0; otherwise level k = `lod >> 8` and k + 1 (each clamped to the last level)
/// blended by `lod & 0xFF`, or level k alone when the weight is 0 or both clamp to the
/// same level. Level k reads the level-0 positions and steps shifted right by k; the
/// second level restarts its position every [`TRILINEAR_CHUNK`] pixels.
///
/// # Panics
/// When a span does not fit in `row`, `lods` and `jobs` differ in length, there are more
/// than [`MAX_JOBS`] spans, or `levels` is empty.
#[inline(always)]
fn run_tri_jobs(
    levels: &[Texels],
    row: &mut [u32],
    jobs: &[SpanJob],
    lods: &[i32],
    mut bil: impl FnMut(&Texels, &mut [u32], Span),
    mut blend: impl FnMut(&Texels, &mut [u32], Span, u32),
) -> u64 {
    assert!(jobs.len() <= MAX_JOBS, "{} spans in one batch", jobs.len());
    assert_eq!(jobs.len(), lods.len(), "one level of detail per span");
    let last = levels.len().checked_sub(1).expect("level 0 at least");
    let mut refused = 0u64;
    for (i, (j, &lod)) in jobs.iter().zip(lods).enumerate() {
        let out = &mut row[j.x as usize..j.x as usize + j.len as usize];
        if out.is_empty() {
            continue;
        }
        let (ka, kb, frac) = if lod <= 0 {
            (0, 0, 0)
        } else {
            let k = (lod >> 8) as usize;
            (k.min(last), (k + 1).min(last), (lod & 0xFF) as u32)
        };
        let shifted = |k: usize| Steps {
            u: j.u >> k,
            v: j.v >> k,
            du: j.du >> k,
            dv: j.dv >> k,
        };
        let Some(sa) = prepare::<true>(&levels[ka], out.len(), shifted(ka)) else {
            refused |= 1 << i;
            continue;
        };
        bil(&levels[ka], out, sa);
        if frac == 0 || kb == ka {
            continue;
        }
        // The second level, its start recomputed every TRILINEAR_CHUNK pixels.
        let (mut u, mut v) = (j.u, j.v);
        for chunk in out.chunks_mut(TRILINEAR_CHUNK) {
            let at = Steps {
                u: u >> kb,
                v: v >> kb,
                ..shifted(kb)
            };
            let Some(sb) = prepare::<true>(&levels[kb], chunk.len(), at) else {
                refused |= 1 << i;
                break;
            };
            blend(&levels[kb], chunk, sb, frac);
            // (Wrapping: only far outside any map, where prepare() then refuses.)
            u = u.wrapping_add(j.du.wrapping_mul(chunk.len() as i64));
            v = v.wrapping_add(j.dv.wrapping_mul(chunk.len() as i64));
        }
    }
    refused
}

/// [`SelectedKernel::cropped_span`].
fn cropped<const BILINEAR: bool>(
    k: SelectedKernel,
    t: &Texels,
    w: &Window,
    out: &mut [u32],
    s: Steps,
) -> bool {
    let Steps { u, v, du, dv } = s;
    let m = out.len();
    if m == 0 {
        return true;
    }
    let n = m as i64 - 1;
    let (Some(eu), Some(ev)) = (du.checked_mul(n), dv.checked_mul(n)) else {
        return false;
    };
    let fw = (w.full_width as i64) << FX_BITS;
    let fh = (w.full_height as i64) << FX_BITS;
    let top = (w.top as i64) << FX_BITS;
    let bottom = top + ((t.height as i64) << FX_BITS);
    let Some(v_end) = v.checked_add(ev) else {
        return false;
    };
    // Wholly above or below the stored rows (v is clamped into the panorama first, so
    // only a crop not touching the panorama's edge has background there).
    let (v_lo, v_hi) = (v.min(v_end), v.max(v_end));
    if (w.top > 0 && v_hi < top) || (bottom < fh && v_lo >= bottom) {
        out.fill(w.background);
        return true;
    }
    // The stored-pixel column of the start, on the sheet [0, W) of the panorama.
    let Some(su) = u.checked_sub((w.left as i64) << FX_BITS) else {
        return false;
    };
    let su = su.rem_euclid(fw.max(1));
    let Some(su_end) = su.checked_add(eu) else {
        return false;
    };
    let sv = v - top;
    let sv_end = v_end - top;
    let cw = (t.width as i64) << FX_BITS;
    let ch = (t.height as i64) << FX_BITS;
    let narrow = (t.width as i64) < w.full_width as i64;
    if narrow {
        let (lo, hi) = (su.min(su_end), su.max(su_end));
        // Wholly in the uncovered longitudes of this sheet.
        if lo >= cw && hi < fw {
            out.fill(w.background);
            return true;
        }
        // Covered needs su < cw (and ≥ 0, which the span kernels check with the bias).
        if hi >= cw {
            return false;
        }
    }
    // Covered rows: sv in [0, ch); the span kernels check sv (− ½ for bilinear) ≥ 0.
    if sv.max(sv_end) >= ch {
        return false;
    }
    let stored = Steps {
        u: su,
        v: sv,
        du,
        dv,
    };
    span::<BILINEAR>(k, t, out, stored)
}

/// Sample a run of positions stepping linearly: `out[i]` = the `BILINEAR` (else nearest)
/// sample of `map` at (u + i·du, v + i·dv). Identical to calling [`EnvMap::bilinear`] /
/// [`EnvMap::nearest`] per pixel with u wrapped into [0, W) for 360° maps.
///
/// When the whole run stays inside the map (after one wrap of its start), the span
/// kernel runs (no clamps, no wrap tests, SIMD where the CPU has it). Otherwise the run
/// falls back to the per-pixel functions.
#[inline]
pub(crate) fn sample_span<const BILINEAR: bool>(map: &EnvMap, out: &mut [u32], s: Steps) {
    if map.projection.scaled_rows() {
        // Rows wrap within their own length (`EnvMap::bilinear`): per pixel.
        return sample_span_slow::<BILINEAR>(map, out, s);
    }
    if !span::<BILINEAR>(active(), &texels(map), out, s) {
        sample_span_slow::<BILINEAR>(map, out, s);
    }
}

/// Nearest samples of one span straight into `out`, with no batch: the renderer's short
/// nearest spans. At the 8 pixels of a span at hfov 90 the scalar loop costs less than
/// queueing the span and setting up SIMD lanes for it (docs/performance.md, "Nearest
/// without the batch"); the bytes are the scalar kernel's, which every SIMD kernel
/// equals (`tests/`). `t` is [`texels`] of `map`, or `None` for
/// maps whose rows wrap within their own length (per pixel, as [`sample_spans`]).
#[inline(always)]
pub(crate) fn nearest_span_direct(map: &EnvMap, t: Option<&Texels>, out: &mut [u32], s: Steps) {
    match t.and_then(|t| Some((t, prepare::<false>(t, out.len(), s)?))) {
        Some((t, c)) => scalar::nearest(t, out, c),
        None => sample_span_slow::<false>(map, out, s),
    }
}

/// [`sample_span`] for a batch of spans of one output row (at most [`MAX_JOBS`]): one
/// kernel call for them all; spans leaving the map are sampled per pixel.
pub(crate) fn sample_spans<const BILINEAR: bool>(map: &EnvMap, row: &mut [u32], spans: &[SpanJob]) {
    let t = texels(map);
    // Maps whose rows wrap within their own length (scaled rows): every span per pixel.
    let mut refused = if map.projection.scaled_rows() {
        (1u64 << spans.len()) - 1
    } else {
        jobs::<BILINEAR>(active(), &t, row, spans)
    };
    while refused != 0 {
        let j = &spans[refused.trailing_zeros() as usize];
        refused &= refused - 1;
        let (x, n) = (j.x as usize, j.len as usize);
        sample_span_slow::<BILINEAR>(map, &mut row[x..x + n], j.steps());
    }
}

/// [`sample_span`] for a run that leaves the map: per pixel, wrapping and clamping.
#[inline(never)]
fn sample_span_slow<const BILINEAR: bool>(map: &EnvMap, out: &mut [u32], s: Steps) {
    let wfx = (map.width as i64) << FX_BITS;
    let wraps = map.projection.wraps();
    let (mut u, mut v) = (s.u, s.v);
    for o in out.iter_mut() {
        let uu = if wraps { u.rem_euclid(wfx) } else { u };
        *o = if BILINEAR {
            map.bilinear(uu, v)
        } else {
            map.nearest(uu, v)
        };
        u += s.du;
        v += s.dv;
    }
}

/// [`EnvMap::trilinear`] over a run of positions stepping linearly (see [`sample_span`]),
/// one level of detail for the run: bilinear spans on the two pyramid levels around
/// `lod`, blended (the second level restarting every [`TRILINEAR_CHUNK`] pixels).
#[cfg(test)]
pub(crate) fn trilinear_span(map: &EnvMap, out: &mut [u32], s: Steps, lod: i32) {
    if lod <= 0 {
        return sample_span::<true>(map, out, s);
    }
    if map.crop.is_some() {
        // Partial maps: per pixel (their levels are read as the padded map's).
        return put_trilinear(map, out, s, lod);
    }
    let levels = level_texels(map);
    if trilinear(active(), &levels, out, s, lod) {
        return;
    }
    trilinear_span_slow(map, out, s, lod);
}

/// [`trilinear_span`] pixel by pixel: [`EnvMap::trilinear`] at each position, u wrapped
/// into the panorama.
#[cfg(test)]
fn put_trilinear(map: &EnvMap, out: &mut [u32], s: Steps, lod: i32) {
    let wfx = (map.width() as i64) << FX_BITS;
    for (i, o) in out.iter_mut().enumerate() {
        let i = i as i64;
        *o = map.trilinear((s.u + i * s.du).rem_euclid(wfx), s.v + i * s.dv, lod);
    }
}

/// The positions of level `k` of a map (level 0's shifted right by `k`).
#[inline(always)]
fn on_level(s: Steps, k: u32) -> Steps {
    Steps {
        u: s.u >> k,
        v: s.v >> k,
        du: s.du >> k,
        dv: s.dv >> k,
    }
}

/// [`trilinear_span`] where a level's span leaves its map: per level, with the per-pixel
/// fallbacks.
#[inline(never)]
fn trilinear_span_slow(map: &EnvMap, out: &mut [u32], s: Steps, lod: i32) {
    let k = (lod >> 8) as usize;
    let frac = (lod & 0xFF) as u32;
    let (a_map, ka) = map.level(k);
    let (b_map, kb) = map.level(k + 1);
    sample_span::<true>(a_map, out, on_level(s, ka));
    if frac == 0 || kb == ka {
        return;
    }
    let mut scratch = [0u32; TRILINEAR_CHUNK];
    let (mut u, mut v) = (s.u, s.v);
    for chunk in out.chunks_mut(scratch.len()) {
        let sc = &mut scratch[..chunk.len()];
        sample_span::<true>(b_map, sc, on_level(Steps { u, v, ..s }, kb));
        for (o, b) in chunk.iter_mut().zip(sc.iter()) {
            *o = lerp_px(*o, *b, frac);
        }
        u += s.du * chunk.len() as i64;
        v += s.dv * chunk.len() as i64;
    }
}

/// [`trilinear_span`] for a batch of spans of one output row (`lods[i]` the level of
/// detail of `spans[i]`): one kernel call for them all. `levels` is [`level_texels`]
/// (taken once per frame). For the renderer's trilinear rows of full maps (a partial
/// map's spans go pixel by pixel: `TriSink::span`).
pub(crate) fn trilinear_spans(
    map: &EnvMap,
    levels: &[Texels],
    row: &mut [u32],
    spans: &[SpanJob],
    lods: &[i32],
) {
    let mut refused = if map.projection.scaled_rows() {
        (1u64 << spans.len()) - 1 // per pixel, as `sample_spans`
    } else {
        tri_jobs(active(), levels, row, spans, lods)
    };
    while refused != 0 {
        let i = refused.trailing_zeros() as usize;
        refused &= refused - 1;
        let j = &spans[i];
        let o = &mut row[j.x as usize..(j.x + j.len) as usize];
        trilinear_span_slow(map, o, j.steps(), lods[i]);
    }
}

/// A run of [`EnvMap::nearest_cropped`] (`BILINEAR` false) or
/// [`EnvMap::bilinear_cropped`] samples at full-panorama positions (u + i·du, v + i·dv),
/// u wrapped per pixel. Spans inside the stored pixels or wholly in the background take
/// the span kernels ([`SelectedKernel::cropped_span`]); spans over the crop's edge are
/// sampled per pixel.
pub(crate) fn sample_span_cropped<const BILINEAR: bool>(map: &EnvMap, out: &mut [u32], s: Steps) {
    let Some(c) = map.crop else {
        return sample_span::<BILINEAR>(map, out, s);
    };
    let w = Window {
        full_width: c.full_width(),
        full_height: c.full_height(),
        left: c.left(),
        top: c.top(),
        background: map.background,
    };
    if cropped::<BILINEAR>(active(), &texels(map), &w, out, s) {
        return;
    }
    let (mut u, mut v) = (s.u, s.v);
    for o in out.iter_mut() {
        *o = if BILINEAR {
            map.bilinear_cropped(u, v)
        } else {
            map.nearest_cropped(u, v)
        };
        u += s.du;
        v += s.dv;
    }
}

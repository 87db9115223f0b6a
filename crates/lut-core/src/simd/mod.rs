//! Span kernels: the LUT renderer's inner loops, in portable scalar code and in x86-64
//! SIMD (SSE4.1, AVX2), chosen once per process.
//!
//! A *span* is a run of output pixels whose map positions step linearly in Q.16:
//! pixel `i` samples (u + i·du, v + i·dv). The renderer reads its table every 8–64
//! pixels; a span that stays inside the map (checked at its two ends: positions are
//! linear, so every pixel between is inside too) is sampled with no clamps or wraps, the
//! padding column and row of the map making x + 1 and y + 1 readable at the last column
//! and row. A span that leaves the map is refused (nothing is written) and the caller
//! samples it per pixel.
//!
//! The kernels take plain data ([`Texels`]: the padded pixel slice and its size;
//! [`SpanJob`]: a span's place in the output row and its Q.16 start and step), so they do
//! not depend on the rest of the crate.
//!
//! # Batches
//! Spans are short (8–16 pixels at hfov 90), so what a span costs besides its pixels
//! (the range check, the lane setup, a call) matters as much as the blend. The renderer
//! queues a row's spans and hands up to [`MAX_JOBS`] of them to one call
//! ([`Kernel::bilinear_spans`], [`Kernel::nearest_spans`], [`Kernel::trilinear_spans`]):
//! the kernel is chosen once per batch, and the span checks and the SIMD loop are
//! compiled into one `#[target_feature]` function (each SIMD loop has a single caller, so
//! it is inlined there; a non-inlined kernel taking its span setup through memory cost a
//! failed store-to-load forward per span, and made AVX2 nearest slower than scalar).
//! Single spans are batches of one.
//!
//! # Identical bytes
//! Every SIMD kernel computes exactly what its scalar twin in `scalar.rs` computes: the
//! same 8-bit weights, the same rounding (`(a·(256 − w) + b·w + 128) >> 8` per channel, in
//! 16-bit lanes where it cannot overflow: at most 255·256 + 128), the same positions. The
//! property tests in `tests.rs` compare the bytes of every available kernel with the
//! scalar one over random spans and batches (the seam, the last column and row, the
//! poles, partial maps, lengths 1..=64, odd output offsets, negative and huge steps, 1×1
//! and 2×1 maps, 65536-wide maps), and the scalar one with the per-pixel samplers. The
//! whole test suite also runs with the scalar kernel forced (`LUTPANO_KERNEL=scalar`, see
//! `scripts/test.sh`).
//!
//! # Positions in 32-bit lanes
//! Q.16 positions of a 65536-wide map reach 2³² and do not fit an `i32` lane. The SIMD
//! kernels split the span's start into a whole pixel (x₀, y₀), folded into one base
//! index, and a fraction f < 1; lanes hold the span-local `f + i·du`, exact in `i32` as
//! long as `|du|·(len − 1) + 1` stays below 2³¹ (32768 map pixels of travel per span).
//! Spans that travel further (only far zoomed out on a huge map) run the scalar kernel.
//! Lane indices are also clamped to the slice before each load, so memory safety never
//! rests on that arithmetic; equality with the scalar twin is what the tests prove.
//!
//! # Measured and chosen (see `docs/performance.md`, "Span kernels")
//! - Loads, not gathers: each bilinear pixel reads its 2×2 block with two 64-bit loads
//!   (top pair, bottom pair); two `shufps` separate the left and right texels of 8
//!   pixels. On the development machine (which reports no Gather Data Sampling
//!   mitigation) `vpgatherdq` of the pairs was 5–10 % faster, `vpgatherdd` for nearest no
//!   faster; gathers are several times slower on CPUs with that microcode fix and on AMD
//!   Zen 2/3, so the loads stay.
//! - One pass, not two: writing a batch's per-pixel indices and weights first, then
//!   gathering and blending all its pixels in one loop, took more instructions per pixel
//!   (bilinear 67.6 against 62.8 per frame pixel, nearest 62.2 against 49.5): the fixed
//!   cost of a span (checks, lane setup) stays, and the results must be copied back.
//! - No AVX-512 kernel yet: at 8–16 pixels per span the per-span cost, not the blend,
//!   dominates the kernel, and a 16-lane vector would be half empty on 8-pixel spans.
//!
//! # Choosing the kernel once
//! [`active_kernel`] is decided on first use: the `LUTPANO_KERNEL` environment variable
//! (`auto`, `scalar`, `sse41`, `avx2`; read once) or else the best kernel the CPU runs
//! ([`Kernel::best`], from `is_x86_feature_detected!`). [`set_kernel`] changes it (the
//! benchmarks compare kernels in one run); [`kernel_info`] tells what runs and which CPU
//! features were detected. The choice costs one relaxed atomic load per batch, never a
//! test per pixel.
//!
//! Why not a crate: `multiversion` (0.9, MIT/Apache-2.0, maintained) compiles one generic
//! function for several targets, but these kernels are different code per instruction set
//! (a 4-lane and an 8-lane layout, scalar index arithmetic), and its dispatcher cannot be
//! forced to a lower level at run time, which the tests and benchmarks need. `pulp`
//! (0.22, MIT, maintained) is a portable SIMD abstraction whose API changes between 0.x
//! releases and does not express the paired 64-bit loads and byte shuffles these kernels
//! are made of. The standard library's detection (itself cached in an atomic) plus one
//! atomic byte for the choice is all the dispatch needs.
//!
//! aarch64 and x86 CPUs without SSE4.1 run the scalar kernel.

mod scalar;
mod select;
#[cfg(test)]
mod tests;
#[cfg(target_arch = "x86_64")]
mod x86;

use select::{active, Selected};
pub use select::{
    active_kernel, cpu_features, kernel_from_env, kernel_info, parse_kernel, set_kernel, Kernel,
    KernelError, KernelInfo, KernelSource, KERNEL_ENV,
};

use crate::fixed::{Fx, FX_BITS, FX_HALF, FX_ONE};

/// Longest span the trilinear kernel blends in one piece (the second level restarts its
/// position every this many pixels, as the per-pixel path always has).
pub const TRILINEAR_CHUNK: usize = 64;

/// Most spans in one batch ([`Kernel::bilinear_spans`]: one bit per span in its answer).
pub const MAX_JOBS: usize = 32;

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

/// A map's pixels as the kernels read them: `(width + 1) × (height + 1)` 0RGB `u32`,
/// row-major, the last column and row being padding (column `width` repeats column 0
/// for maps that wrap horizontally, else column `width − 1`; row `height` repeats row
/// `height − 1`).
#[derive(Debug, Clone, Copy)]
pub struct Texels<'a> {
    px: &'a [u32],
    width: u32,
    height: u32,
    wraps: bool,
}

impl<'a> Texels<'a> {
    /// The padded pixels of a `width × height` map; `wraps`: the map is 360° wide (a
    /// span may start one period off and is wrapped once). `None` when `px` does not
    /// hold `(width + 1) × (height + 1)` pixels, a side is 0, or it holds 2³¹ or more.
    pub fn new(px: &'a [u32], width: u32, height: u32, wraps: bool) -> Option<Texels<'a>> {
        let n = (width as usize + 1).checked_mul(height as usize + 1)?;
        (width > 0 && height > 0 && px.len() == n && n <= i32::MAX as usize).then_some(Texels {
            px,
            width,
            height,
            wraps,
        })
    }

    /// Pixels per row, padding included.
    #[inline(always)]
    pub fn stride(&self) -> usize {
        self.width as usize + 1
    }
}

/// A partial map's place in the full panorama, for [`Kernel::cropped_span`]: the stored
/// [`Texels`] hold columns `left..left + width` (mod `full_width`) and rows
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

/// Most pyramid levels the trilinear kernels take (level 0, the map, included).
pub const MAX_LEVELS: usize = 32;

/// A span checked to lie inside its map: the start (already biased by −½ for bilinear
/// and wrapped into the map) and the step, Q.16.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Span {
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
}

/// [`Kernel::nearest_span`] with the [`active_kernel`].
#[inline]
pub(crate) fn nearest_span(t: &Texels, out: &mut [u32], u: Fx, v: Fx, du: Fx, dv: Fx) -> bool {
    span::<false>(active(), t, out, (u, v), (du, dv))
}

/// [`Kernel::bilinear_span`] with the [`active_kernel`].
#[inline]
pub(crate) fn bilinear_span(t: &Texels, out: &mut [u32], u: Fx, v: Fx, du: Fx, dv: Fx) -> bool {
    span::<true>(active(), t, out, (u, v), (du, dv))
}

/// [`Kernel::trilinear_span`] with the [`active_kernel`].
#[inline]
pub(crate) fn trilinear_span(
    levels: &[Texels],
    lod: i32,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
) -> bool {
    trilinear(active(), levels, lod, out, (u, v), (du, dv))
}

/// [`Kernel::trilinear_spans`] with the [`active_kernel`].
#[inline]
pub(crate) fn trilinear_spans(
    levels: &[Texels],
    row: &mut [u32],
    spans: &[SpanJob],
    lods: &[i32],
) -> u64 {
    tri_jobs(active(), levels, row, spans, lods)
}

/// [`Kernel::cropped_span`] with the [`active_kernel`].
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn cropped_span(
    bilinear: bool,
    t: &Texels,
    w: &Window,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
) -> bool {
    cropped(active(), bilinear, t, w, out, (u, v), (du, dv))
}

/// Check a span and wrap its start (see [`Kernel::nearest_span`]). Positions or steps
/// of 2⁴⁶ or more (no map comes near) and spans of 2¹⁶ pixels or more are refused, so
/// the arithmetic below cannot overflow.
#[inline(always)]
fn prepare<const BILINEAR: bool>(t: &Texels, m: usize, uv: (Fx, Fx), d: (Fx, Fx)) -> Option<Span> {
    let big = uv.0.unsigned_abs() | uv.1.unsigned_abs() | d.0.unsigned_abs() | d.1.unsigned_abs();
    if (big >> 46 | m as u64 >> 16) != 0 {
        return None;
    }
    let wfx = (t.width as i64) << FX_BITS;
    let hfx = (t.height as i64) << FX_BITS;
    // Bilinear reads the pixel centres around (u − ½, v − ½).
    let bias = if BILINEAR { FX_HALF } else { 0 };
    let mut uu = uv.0 - bias;
    if t.wraps && !(0..wfx).contains(&uu) {
        // One period off at most on the renderer's path; a division otherwise.
        uu += if uu < 0 { wfx } else { -wfx };
        if !(0..wfx).contains(&uu) {
            uu = uu.rem_euclid(wfx);
        }
    }
    let vv = uv.1 - bias;
    let n = m as i64 - 1;
    let (u_end, v_end) = (uu + d.0 * n, vv + d.1 * n);
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
            du: d.0,
            dv: d.1,
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
        match prepare::<BILINEAR>(t, out.len(), (j.u, j.v), (j.du, j.dv)) {
            Some(s) => run(out, s),
            None => refused |= 1 << i,
        }
    }
    refused
}

/// The batch kernels with kernel `k`.
#[inline]
fn jobs<const BILINEAR: bool>(k: Selected, t: &Texels, row: &mut [u32], jobs: &[SpanJob]) -> u64 {
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

/// [`Kernel::nearest_spans`] with the [`active_kernel`].
#[inline]
pub(crate) fn nearest_spans(t: &Texels, row: &mut [u32], spans: &[SpanJob]) -> u64 {
    jobs::<false>(active(), t, row, spans)
}

/// [`Kernel::bilinear_spans`] with the [`active_kernel`].
#[inline]
pub(crate) fn bilinear_spans(t: &Texels, row: &mut [u32], spans: &[SpanJob]) -> u64 {
    jobs::<true>(active(), t, row, spans)
}

/// One span: a batch of one (each SIMD loop then has a single caller, the batch loop,
/// and is compiled into it).
#[inline(always)]
fn span<const BILINEAR: bool>(
    k: Selected,
    t: &Texels,
    out: &mut [u32],
    (u, v): (Fx, Fx),
    (du, dv): (Fx, Fx),
) -> bool {
    if out.len() >> 16 != 0 {
        return false; // prepare() refuses these too
    }
    let job = SpanJob {
        x: 0,
        len: out.len() as u32,
        u,
        v,
        du,
        dv,
    };
    jobs::<BILINEAR>(k, t, out, &[job]) == 0
}

/// One trilinear span: a batch of one.
#[inline(always)]
fn trilinear(
    k: Selected,
    levels: &[Texels],
    lod: i32,
    out: &mut [u32],
    (u, v): (Fx, Fx),
    (du, dv): (Fx, Fx),
) -> bool {
    if out.len() >> 16 != 0 {
        return false; // prepare() refuses these too
    }
    let job = SpanJob {
        x: 0,
        len: out.len() as u32,
        u,
        v,
        du,
        dv,
    };
    tri_jobs(k, levels, out, &[job], &[lod]) == 0
}

/// The trilinear batch kernels with kernel `k`.
#[inline]
fn tri_jobs(
    k: Selected,
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
/// `crate::pyramid::lod_q8`) on `levels` with the kernels `bil` (bilinear) and `blend`
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
        let shifted = |k: usize| ((j.u >> k, j.v >> k), (j.du >> k, j.dv >> k));
        let (uv, d) = shifted(ka);
        let Some(sa) = prepare::<true>(&levels[ka], out.len(), uv, d) else {
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
            let uv = (u >> kb, v >> kb);
            let Some(sb) = prepare::<true>(&levels[kb], chunk.len(), uv, shifted(kb).1) else {
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

fn cropped(
    k: Selected,
    bilinear: bool,
    t: &Texels,
    w: &Window,
    out: &mut [u32],
    (u, v): (Fx, Fx),
    (du, dv): (Fx, Fx),
) -> bool {
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
    if bilinear {
        span::<true>(k, t, out, (su, sv), (du, dv))
    } else {
        span::<false>(k, t, out, (su, sv), (du, dv))
    }
}

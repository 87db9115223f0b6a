//! Span kernels: the LUT renderer's inner loops, in portable scalar code and in x86-64
//! SIMD (SSE4.1, AVX2, AVX-512), chosen once per process.
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
//! # The rules a kernel keeps, and why
//! * **No per-pixel dispatch.** The sampler (nearest or bilinear), the partial-map crop
//!   test and the trilinear level are chosen once per frame (a monomorphized sink per
//!   combination in `render/sink.rs`) or once per span (the level of detail), never per
//!   pixel; the instruction set once per process.
//! * **No division inside a span.** Longitude is wrapped once at the start of a span (one
//!   period off at most on the renderer's path; `rem_euclid` only for a start further
//!   off), never per pixel.
//! * **No clamps inside a span.** The whole span is checked against the map once: when its
//!   first and last positions lie inside, every position between does (the steps are
//!   linear), and the padding column and row of the map (`map/envmap.rs`) make `x + 1` and
//!   `y + 1` readable at the last column and row. A span that leaves the map falls back to
//!   the per-pixel samplers, which wrap and clamp.
//!
//! The numbers that first showed it (callgrind instruction counts, `docs/ARCHITECTURE.md`
//! "What was measured and changed"): the nearest inner loop was ~10 instructions per
//! pixel, but ~25 per pixel went to span overhead (a table read, two `i64::rem_euclid`
//! divisions and the sampler's clamps every 4 pixels), and a plain gather along
//! precomputed indices (the same memory accesses) was 3–4× faster than the kernel.
//!
//! # Layout
//! `mod.rs` (this file): the kernels' data types and the entries the renderer calls on an
//! [`EnvMap`]; `jobs.rs`: the span check, batches and the dispatch; `scalar.rs`: the
//! portable kernels (the reference); `x86.rs`: the SSE4.1, AVX2 and AVX-512 texel blend
//! the x86 kernels share (the only module where `unsafe` is allowed, with its children:
//! `x86/span.rs` the span kernels, `x86/row.rs`, `x86/face.rs`, `x86/nodes.rs`);
//! `select.rs`: choosing the kernel;
//! `tests/`: the property tests (`row_pass.rs`: the row kernels'); `face.rs`:
//! cube-face runs, whose positions (a projective line evaluated exactly per pixel) are
//! computed in a pass of their own and drawn by the row kernels (the cube scanline
//! renderer's nearest, bilinear and trilinear runs);
//! `row.rs` (and `x86/row.rs`): the row pass's kernels (`render/rowpass.rs`), a run's
//! Q.8 positions expanded from its spans and one gather-and-blend pass over them, with
//! no per-span check (the LUT rows of full maps, trilinear's pyramid levels by
//! `sample_level`; the span kernels draw the rest); `nodes.rs` (and `x86/nodes.rs`): a
//! scanline's table nodes, the two table rows blended once for the walk's reads.
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
//! Single spans are batches of one. Nearest spans of up to 8 pixels skip the batch:
//! the renderer samples them at once with the scalar loop (`nearest_span_direct`),
//! which costs less than the queueing and the lane setup at that length.
//!
//! # Identical bytes
//! Every SIMD kernel computes exactly what its scalar twin in `scalar.rs` computes: the
//! same 8-bit weights, the same rounding (`(a·(256 − w) + b·w + 128) >> 8` per channel, in
//! 16-bit lanes where it cannot overflow: at most 255·256 + 128), the same positions. The
//! property tests in `tests/` compare the bytes of every available kernel with the
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
//! - AVX-512 (`Kernel::Avx512`, 16 lanes) for the row kernels (`x86/row.rs`: runs of
//!   hundreds of positions, no per-span cost) and the cube-face positions (`x86/face.rs`:
//!   the `f64` division 8 lanes wide), not for the span kernels: at 8–16 pixels per span
//!   the per-span cost, not the blend, dominates them, and a 16-lane vector would be half
//!   empty on 8-pixel spans; `Kernel::Avx512` runs their AVX2 code. On AMD Zen 5 plain
//!   loads beat `vpgatherdq` / `vpgatherdd` in the AVX-512 row kernels too
//!   (`docs/performance.md`, "AVX-512").
//!
//! # Choosing the kernel once
//! [`active_kernel`] is decided on first use: the `LUTPANO_KERNEL` environment variable
//! (`auto`, `scalar`, `sse41`, `avx2`, `avx512`; read once) or else the best kernel the CPU runs
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

mod face;
mod jobs;
mod nodes;
mod row;
mod scalar;
mod select;
#[cfg(test)]
mod tests;
#[cfg(target_arch = "x86_64")]
mod x86;

pub use select::{
    active_kernel, cpu_features, kernel_from_env, kernel_info, parse_kernel, set_kernel, Kernel,
    KernelError, KernelInfo, KernelSource, KERNEL_ENV,
};

pub(crate) use face::{face_rows, face_rows_blend, FaceBuf, FaceRun};
pub(crate) use nodes::{blend_nodes, simd_blend};
pub(crate) use row::{expand, sample_level, sample_q8, wrap_q8, Level, Positions, SpanQ8};

use crate::geom::fixed::{Fx, FX_BITS};
use crate::map::envmap::EnvMap;
use crate::map::sample::lerp_px;

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
    /// How far the next scanline's reads lie below this one's (map rows, level-0 Q.8 as
    /// the row kernels' positions, negative: above; 0: not known), for the row kernels'
    /// prefetch of the rows it will read ([`Texels::toward_next_scanline`]).
    next_dv: i32,
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
            next_dv: 0,
        })
    }

    /// These texels, read by a scanline whose next scanline reads `dv` map rows (level-0
    /// Q.8, negative: above) further down at the same pixel.
    ///
    /// Why: the x86 row kernels prefetch the texels a run will read a few hundred pixels
    /// ahead into L1; with `dv` known they also prefetch, into L2, the rows the next
    /// scanline will read that this one does not. Those lines then come from L2 instead
    /// of L3 or memory when that scanline's own prefetches ask for them: the 8k frame at
    /// hfov 90 (about 1.2 map rows a scanline) drew about 25 % faster on one thread
    /// (docs/performance.md, "The next scanline's rows"). A wrong `dv` costs only
    /// useless prefetches; no result depends on it.
    #[inline(always)]
    pub(crate) fn toward_next_scanline(self, dv: i32) -> Texels<'a> {
        Texels {
            next_dv: dv,
            ..self
        }
    }

    /// See [`Texels::toward_next_scanline`] (read by the x86 row kernels only).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    #[inline(always)]
    pub(crate) fn next_dv(&self) -> i32 {
        self.next_dv
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

/// The stored pixels of `map` as the kernels read them.
#[inline]
pub(crate) fn texels(map: &EnvMap) -> Texels<'_> {
    let (px, _) = map.padded();
    // A partial map's stored pixels wrap only when the crop spans 360°.
    let wraps = map
        .crop
        .map_or(map.projection.wraps(), |c| c.width() == c.full_width());
    Texels::new(px, map.width, map.height, wraps)
        .expect("a map holds (width + 1) x (height + 1) pixels, fewer than 2^31")
}

/// The texels of level 0 (`map`) and of each pyramid level, as the span kernels take
/// them, and how many there are (the pyramid is built here if it was not).
pub(crate) fn level_texels(map: &EnvMap) -> ([Texels<'_>; MAX_LEVELS], usize) {
    let mut t = [texels(map); MAX_LEVELS];
    let levels = map.pyramid();
    let n = 1 + levels.len().min(MAX_LEVELS - 1);
    for (d, l) in t[1..n].iter_mut().zip(levels) {
        *d = texels(l);
    }
    (t, n)
}

/// Sample a run of positions stepping linearly: `out[i]` = the `BILINEAR` (else nearest)
/// sample of `map` at (u + i·du, v + i·dv). Identical to calling [`EnvMap::bilinear`] /
/// [`EnvMap::nearest`] per pixel with u wrapped into [0, W) for 360° maps.
///
/// When the whole run stays inside the map (after one wrap of its start), the span
/// kernel runs ([`Kernel`]: no clamps, no wrap tests, SIMD where the CPU has it).
/// Otherwise the run falls back to the per-pixel functions.
#[inline]
pub(crate) fn sample_span<const BILINEAR: bool>(
    map: &EnvMap,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
) {
    if map.projection.scaled_rows() {
        // Rows wrap within their own length (`EnvMap::bilinear`): per pixel.
        return sample_span_slow::<BILINEAR>(map, out, u, v, du, dv);
    }
    let t = texels(map);
    let done = if BILINEAR {
        jobs::bilinear_span(&t, out, u, v, du, dv)
    } else {
        jobs::nearest_span(&t, out, u, v, du, dv)
    };
    if !done {
        sample_span_slow::<BILINEAR>(map, out, u, v, du, dv);
    }
}

/// Nearest samples of one span straight into `out`, with no batch: the renderer's short
/// nearest spans. At the 8 pixels of a span at hfov 90 the scalar loop costs less than
/// queueing the span and setting up SIMD lanes for it (docs/performance.md, "Nearest
/// without the batch"); the bytes are the scalar kernel's, which every SIMD kernel
/// equals (`tests/`). `t` is [`texels`] of `map`, or `None` for
/// maps whose rows wrap within their own length (per pixel, as [`sample_spans`]).
#[inline(always)]
pub(crate) fn nearest_span_direct(
    map: &EnvMap,
    t: Option<&Texels>,
    out: &mut [u32],
    (u, v): (Fx, Fx),
    (du, dv): (Fx, Fx),
) {
    match t.and_then(|t| Some((t, jobs::prepare::<false>(t, out.len(), (u, v), (du, dv))?))) {
        Some((t, s)) => scalar::nearest(t, out, s),
        None => sample_span_slow::<false>(map, out, u, v, du, dv),
    }
}

/// [`sample_span`] for a batch of spans of one output row (at most [`MAX_JOBS`]): one
/// kernel call for them all; spans leaving the map are sampled per pixel.
pub(crate) fn sample_spans<const BILINEAR: bool>(map: &EnvMap, row: &mut [u32], spans: &[SpanJob]) {
    let t = texels(map);
    // Maps whose rows wrap within their own length (scaled rows): every span per pixel.
    let mut refused = if map.projection.scaled_rows() {
        (1u64 << spans.len()) - 1
    } else if BILINEAR {
        jobs::bilinear_spans(&t, row, spans)
    } else {
        jobs::nearest_spans(&t, row, spans)
    };
    while refused != 0 {
        let j = &spans[refused.trailing_zeros() as usize];
        refused &= refused - 1;
        let (x, n) = (j.x as usize, j.len as usize);
        sample_span_slow::<BILINEAR>(map, &mut row[x..x + n], j.u, j.v, j.du, j.dv);
    }
}

/// [`sample_span`] for a run that leaves the map: per pixel, wrapping and clamping.
#[inline(never)]
fn sample_span_slow<const BILINEAR: bool>(
    map: &EnvMap,
    out: &mut [u32],
    mut u: Fx,
    mut v: Fx,
    du: Fx,
    dv: Fx,
) {
    let wfx = (map.width as i64) << FX_BITS;
    let wraps = map.projection.wraps();
    for o in out.iter_mut() {
        let uu = if wraps { u.rem_euclid(wfx) } else { u };
        *o = if BILINEAR {
            map.bilinear(uu, v)
        } else {
            map.nearest(uu, v)
        };
        u += du;
        v += dv;
    }
}

/// [`EnvMap::trilinear`] over a run of positions stepping linearly (see [`sample_span`]),
/// one level of detail for the run: bilinear spans on the two pyramid levels around
/// `lod`, blended (the second level restarting every [`TRILINEAR_CHUNK`] pixels).
#[cfg(test)]
pub(crate) fn trilinear_span(
    map: &EnvMap,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
    lod: i32,
) {
    if lod <= 0 {
        return sample_span::<true>(map, out, u, v, du, dv);
    }
    if map.crop.is_some() {
        // Partial maps: per pixel (their levels are read as the padded map's).
        return put_trilinear(map, out, (u, v), (du, dv), lod);
    }
    let (levels, n) = level_texels(map);
    if jobs::trilinear_span(&levels[..n], lod, out, u, v, du, dv) {
        return;
    }
    trilinear_span_slow(map, out, u, v, du, dv, lod);
}

/// [`trilinear_span`] pixel by pixel: [`EnvMap::trilinear`] at each position, u wrapped
/// into the panorama.
#[cfg(test)]
fn put_trilinear(map: &EnvMap, out: &mut [u32], (u, v): (Fx, Fx), (du, dv): (Fx, Fx), lod: i32) {
    let wfx = (map.width() as i64) << FX_BITS;
    for (i, o) in out.iter_mut().enumerate() {
        let i = i as i64;
        *o = map.trilinear((u + i * du).rem_euclid(wfx), v + i * dv, lod);
    }
}

/// [`trilinear_span`] where a level's span leaves its map: per level, with the per-pixel
/// fallbacks.
#[inline(never)]
fn trilinear_span_slow(map: &EnvMap, out: &mut [u32], u: Fx, v: Fx, du: Fx, dv: Fx, lod: i32) {
    let k = (lod >> 8) as usize;
    let frac = (lod & 0xFF) as u32;
    let (a_map, ka) = map.level(k);
    let (b_map, kb) = map.level(k + 1);
    sample_span::<true>(a_map, out, u >> ka, v >> ka, du >> ka, dv >> ka);
    if frac == 0 || kb == ka {
        return;
    }
    let mut scratch = [0u32; TRILINEAR_CHUNK];
    let (mut u, mut v) = (u, v);
    for chunk in out.chunks_mut(scratch.len()) {
        let s = &mut scratch[..chunk.len()];
        sample_span::<true>(b_map, s, u >> kb, v >> kb, du >> kb, dv >> kb);
        for (o, b) in chunk.iter_mut().zip(s.iter()) {
            *o = lerp_px(*o, *b, frac);
        }
        u += du * chunk.len() as i64;
        v += dv * chunk.len() as i64;
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
        jobs::trilinear_spans(levels, row, spans, lods)
    };
    while refused != 0 {
        let i = refused.trailing_zeros() as usize;
        refused &= refused - 1;
        let j = &spans[i];
        let o = &mut row[j.x as usize..(j.x + j.len) as usize];
        trilinear_span_slow(map, o, j.u, j.v, j.du, j.dv, lods[i]);
    }
}

/// A run of [`EnvMap::nearest_cropped`] (`BILINEAR` false) or
/// [`EnvMap::bilinear_cropped`] samples at full-panorama positions (u + i·du, v + i·dv),
/// u wrapped per pixel. Spans inside the stored pixels or wholly in the background take
/// the span kernels ([`Kernel::cropped_span`]); spans over the crop's edge are sampled
/// per pixel.
pub(crate) fn sample_span_cropped<const BILINEAR: bool>(
    map: &EnvMap,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
) {
    let Some(c) = map.crop else {
        return sample_span::<BILINEAR>(map, out, u, v, du, dv);
    };
    let w = Window {
        full_width: c.full_width(),
        full_height: c.full_height(),
        left: c.left(),
        top: c.top(),
        background: map.background,
    };
    if jobs::cropped_span(BILINEAR, &texels(map), &w, out, u, v, du, dv) {
        return;
    }
    let (mut u, mut v) = (u, v);
    for o in out.iter_mut() {
        *o = if BILINEAR {
            map.bilinear_cropped(u, v)
        } else {
            map.nearest_cropped(u, v)
        };
        u += du;
        v += dv;
    }
}

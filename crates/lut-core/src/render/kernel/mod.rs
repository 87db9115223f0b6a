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
//! One folder per operation, as fast_image_resize lays out its SIMD: each operation's
//! `mod.rs` holds its types and its dispatch (methods of [`SelectedKernel`], the one way
//! to call it), `scalar.rs` the portable twin (the reference), `x86.rs` the SSE4.1, AVX2
//! and AVX-512 forms.
//! - `span/`: the span kernels (a run stepping linearly, checked inside the map once;
//!   batches of a row's spans; partial maps) and the renderer's entries on an
//!   [`EnvMap`] (`sample_span`, `sample_spans`, `trilinear_spans`, …, which fall back
//!   to the per-pixel samplers).
//! - `row/`: the row pass's kernels (`render/rowpass.rs`): a run's Q.8 positions
//!   expanded from its spans and one gather-and-blend pass over them, with no per-span
//!   check (the LUT rows of full maps, trilinear's pyramid levels).
//! - `face/`: cube-face runs, whose positions (a projective line evaluated exactly per
//!   pixel) are computed in a pass of their own and drawn by the row kernels (the cube
//!   scanline renderer's nearest, bilinear and trilinear runs).
//! - `nodes/`: a scanline's table nodes, the two table rows blended once for the walk's
//!   reads (the scalar twin is `lut::Band::blend_nodes`).
//! - `shade/`: the lighting's shading rows (light factor × sRGB byte through the
//!   shading table, `light/shade_table.rs`).
//! - `x86_lanes.rs`: the lane helpers the x86 forms share (texel blends, prefetches),
//!   below every operation; `select.rs`: choosing the kernel (CPU detection,
//!   `LUTPANO_KERNEL`), used by every operation and using none; `tests/`: the
//!   property tests (`row_pass.rs`: the row kernels').
//!
//! The imports run one way: `face` uses `row`; every `x86.rs` uses `x86_lanes`; all use
//! `select` and this file's [`Texels`]; nothing below uses what is above it (the layout
//! test in `lib.rs` checks it file by file).
//!
//! # Batches
//! Spans are short (8–16 pixels at hfov 90), so what a span costs besides its pixels
//! (the range check, the lane setup, a call) matters as much as the blend. The renderer
//! queues a row's spans and hands up to [`MAX_JOBS`] of them to one call
//! ([`SelectedKernel::bilinear_spans`], [`SelectedKernel::nearest_spans`],
//! [`SelectedKernel::trilinear_spans`]):
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
//! - AVX-512 (`Kernel::Avx512`, 16 lanes) for the row kernels (`row/x86.rs`: runs of
//!   hundreds of positions, no per-span cost) and the cube-face positions (`face/x86.rs`:
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
//! test per pixel. Every operation is a method of [`SelectedKernel`] (a kernel this CPU
//! runs: [`Kernel::select`] checks, `active()` is the active one), so the renderer, the
//! tests and the benchmarks call the same function.
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
mod nodes;
mod row;
mod select;
mod shade;
mod span;
#[cfg(test)]
mod tests;
#[cfg(target_arch = "x86_64")]
mod x86_lanes;

pub use select::{
    active_kernel, cpu_features, kernel_from_env, kernel_info, parse_kernel, set_kernel, Kernel,
    KernelError, KernelInfo, KernelSource, SelectedKernel, KERNEL_ENV,
};
pub use span::{SpanJob, Steps, Window, MAX_JOBS, TRILINEAR_CHUNK};

pub(crate) use face::{ChunkLevels, ChunkWeights, FaceBuf, FaceRun};
pub(crate) use row::{wrap_q8, Level, Positions, Q16Start, Q16Step, SpanAt, SpanQ8};
pub(crate) use select::active;
pub(crate) use shade::{Light, ShadeTable};
pub(crate) use span::{nearest_span_direct, sample_span_cropped, sample_spans, trilinear_spans};

use crate::map::envmap::EnvMap;

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
/// them (the pyramid is built here if it was not).
pub(crate) fn level_texels(map: &EnvMap) -> LevelTexels<'_> {
    let mut t = [texels(map); MAX_LEVELS];
    let levels = map.pyramid();
    let n = 1 + levels.len().min(MAX_LEVELS - 1);
    for (d, l) in t[1..n].iter_mut().zip(levels) {
        *d = texels(l);
    }
    LevelTexels { t, n }
}

/// A map's levels as [`level_texels`] returns them, without allocating: derefs to the
/// slice of the first `n` (level 0 first).
#[derive(Clone, Copy)]
pub(crate) struct LevelTexels<'a> {
    /// The levels' texels; past `n`, copies of level 0.
    t: [Texels<'a>; MAX_LEVELS],
    /// How many levels there are (1 to [`MAX_LEVELS`]).
    n: usize,
}

impl<'a> std::ops::Deref for LevelTexels<'a> {
    type Target = [Texels<'a>];

    fn deref(&self) -> &[Texels<'a>] {
        &self.t[..self.n]
    }
}

//! Sinks: where the scanline walk (`render/scanline.rs`) writes. One monomorphized sink
//! per sampler and map kind (full or partial), so the choice is made once per frame and
//! never per pixel; a trilinear sink that sets its level of detail once per span; and a
//! sink of sampling positions, for measuring them against the exact mapping.

use super::exact::{sample_at, sample_at_level, sample_at_lod, ExactFootprint};
use super::kernel::{
    nearest_span_direct, sample_span_cropped, sample_spans, texels, trilinear_spans, SpanJob,
    Texels, MAX_JOBS,
};
use super::setup::LvStep;
use super::steps::STEP_REGIONS;
use super::walk::wrap_u;
use crate::geom::fixed::{from_fx, Fx, FX_ONE};
use crate::map::envmap::EnvMap;
use crate::map::pyramid::{lod_q8, nearest_level_of};
use crate::map::sample::Sampler;

/// Where a renderer writes: pixels, or (for measurement) sampling positions.
pub(crate) trait Sink {
    fn put(&mut self, x: usize, u: Fx, v: Fx);
    /// The span `s`: `s.len` pixels from `s.x` on at (u + i·du, v + i·dv), u wrapped per
    /// pixel into [0, W) (`w_fx` = W in Q.16); v inside the map.
    #[inline(always)]
    fn span(&mut self, s: SpanJob, w_fx: Fx) {
        put_run(self, s, w_fx);
    }
    fn background(&mut self, x: usize);
    fn exact(&mut self, x: usize, uv: Option<(f64, f64)>);
    /// The pyramid level pixel `x` (evaluated exactly) reads, known before its position
    /// (bilinear with a level per region: from the mapping's derivative); `None`: the
    /// sink takes positions through [`Sink::exact`].
    #[inline(always)]
    fn exact_level(&mut self, _x: usize) -> Option<u32> {
        None
    }
    /// Pixel `x` at `uv` on level `k` (as [`Sink::exact_level`] gave it).
    #[inline(always)]
    fn exact_on(&mut self, x: usize, uv: Option<(f64, f64)>, _k: u32) {
        self.exact(x, uv);
    }
    /// The per-pixel step (dΛ, dV) of the span about to be emitted (its horizontal
    /// footprint): the trilinear sink picks its pyramid level from it.
    #[inline(always)]
    fn footprint(&mut self, _step: LvStep, _region: usize) {}
    /// Whether the row pass asks this sink for each span's level of detail
    /// ([`Sink::span_lod`]: the trilinear sink).
    const LOD: bool = false;
    /// The level of detail (Q.8) of a span with step (dΛ, dV) in `region` (as
    /// [`Sink::footprint`] sets it).
    #[inline(always)]
    fn span_lod(&mut self, _step: LvStep, _region: usize) -> i32 {
        0
    }
    /// The pixel footprint (level-0 map pixels) of the spans that follow, known as a whole
    /// (the grid renderer's cells): the trilinear sink picks its pyramid level from it.
    #[inline(always)]
    fn set_footprint(&mut self, _footprint: f64) {}
    /// Write what the sink still holds (called at the end of each row).
    #[inline(always)]
    fn flush(&mut self) {}
}

/// Spans of one row waiting for a batch kernel (`kernel::sample_spans`): one kernel call
/// per [`MAX_JOBS`] spans instead of one per span.
pub(crate) struct Batch {
    jobs: [SpanJob; MAX_JOBS],
    /// Level of detail per span (trilinear only).
    lods: [i32; MAX_JOBS],
    n: usize,
}

impl Batch {
    pub(crate) fn new() -> Batch {
        Batch {
            jobs: [SpanJob::default(); MAX_JOBS],
            lods: [0; MAX_JOBS],
            n: 0,
        }
    }

    /// Queue a span with its level of detail (trilinear); `true` when the batch is full
    /// (flush it).
    #[inline(always)]
    fn push_lod(&mut self, s: SpanJob, lod: i32) -> bool {
        self.lods[self.n] = lod;
        self.push(s)
    }

    /// Queue a span (nearest or bilinear: no level); `true` when the batch is full.
    #[inline(always)]
    fn push(&mut self, s: SpanJob) -> bool {
        self.jobs[self.n] = s;
        self.n += 1;
        self.n == MAX_JOBS
    }

    /// Sample the queued spans into `row` (nearest or bilinear).
    #[inline]
    fn flush<const BILINEAR: bool>(&mut self, map: &EnvMap, row: &mut [u32]) {
        if self.n > 0 {
            sample_spans::<BILINEAR>(map, row, &self.jobs[..self.n]);
            self.n = 0;
        }
    }

    /// Sample the queued spans into `row`, trilinear with their levels of detail
    /// (`levels`: `kernel::level_texels`).
    #[inline]
    fn flush_trilinear(&mut self, map: &EnvMap, levels: &[Texels], row: &mut [u32]) {
        if self.n > 0 {
            trilinear_spans(map, levels, row, &self.jobs[..self.n], &self.lods[..self.n]);
            self.n = 0;
        }
    }
}

/// [`Sink::span`] pixel by pixel through [`Sink::put`].
#[inline(always)]
pub(crate) fn put_run<S: Sink + ?Sized>(s: &mut S, job: SpanJob, w_fx: Fx) {
    let (x, m) = (job.x as usize, job.len as usize);
    let (mut u, mut v) = (job.u, job.v);
    for i in 0..m {
        s.put(x + i, wrap_u(u, w_fx), v);
        u += job.du;
        v += job.dv;
    }
}

/// Nearest spans shorter than this (the 8-pixel spans of hfov 90 and wider) are sampled
/// at once by the scalar loop (`kernel::nearest_span_direct`), without the batch;
/// longer ones go to the batch kernels, where the SIMD lane setup pays. Callgrind, 1080p
/// from 8k, AVX2 (docs/performance.md), measured on the LUT frame before the row pass
/// took its full-map rows (this sink now serves the grid renderer and the rows that go
/// span by span): 45.8 → 44.0 instructions per pixel at hfov 90; with 16- and 32-pixel
/// spans direct too, hfov 50 went from 25.5 to 28.4.
const NEAREST_DIRECT: usize = 9;

/// Writes sampled pixels. `CROP`: a partial map (see `map/crop.rs`): full-panorama
/// (u, v) are looked up in the crop, background outside; a const parameter so the
/// full-map kernel keeps no per-pixel crop test.
pub(crate) struct PixelSink<'a, const BILINEAR: bool, const CROP: bool> {
    pub(crate) row: &'a mut [u32],
    pub(crate) map: &'a EnvMap,
    /// Spans waiting for the batch kernel (full maps, bilinear).
    pub(crate) batch: Batch,
    /// The map's texels for nearest spans, sampled at once without the batch (`None`
    /// for maps whose rows wrap within their length: per pixel).
    texels: Option<Texels<'a>>,
}

impl<'a, const BILINEAR: bool, const CROP: bool> PixelSink<'a, BILINEAR, CROP> {
    /// The sink writing `row` from `map`.
    #[inline]
    pub(crate) fn new(row: &'a mut [u32], map: &'a EnvMap) -> Self {
        PixelSink {
            row,
            map,
            batch: Batch::new(),
            texels: (!map.projection.scaled_rows()).then(|| texels(map)),
        }
    }
}

impl<const BILINEAR: bool, const CROP: bool> Sink for PixelSink<'_, BILINEAR, CROP> {
    #[inline(always)]
    fn put(&mut self, x: usize, u: Fx, v: Fx) {
        self.row[x] = match (BILINEAR, CROP) {
            (true, false) => self.map.bilinear(u, v),
            (false, false) => self.map.nearest(u, v),
            (true, true) => self.map.bilinear_cropped(u, v),
            (false, true) => self.map.nearest_cropped(u, v),
        };
    }
    #[inline(always)]
    fn span(&mut self, s: SpanJob, _w_fx: Fx) {
        let (x, m) = (s.x as usize, s.len as usize);
        if CROP {
            sample_span_cropped::<BILINEAR>(self.map, &mut self.row[x..x + m], s.steps());
        } else if !BILINEAR && m < NEAREST_DIRECT {
            let out = &mut self.row[x..x + m];
            nearest_span_direct(self.map, self.texels.as_ref(), out, s.steps());
        } else if self.batch.push(s) {
            self.batch.flush::<BILINEAR>(self.map, self.row);
        }
    }
    #[inline(always)]
    fn flush(&mut self) {
        self.batch.flush::<BILINEAR>(self.map, self.row);
    }
    #[inline(always)]
    fn background(&mut self, x: usize) {
        self.row[x] = self.map.background();
    }
    #[inline]
    fn exact(&mut self, x: usize, uv: Option<(f64, f64)>) {
        let s = if BILINEAR {
            Sampler::Bilinear
        } else {
            Sampler::Nearest
        };
        self.row[x] = sample_at(self.map, s, uv);
    }
}

/// A sink dropped with spans still queued writes them (the renderers call
/// [`Sink::flush`] at the end of each row; this keeps a sink used without it correct).
impl<const BILINEAR: bool, const CROP: bool> Drop for PixelSink<'_, BILINEAR, CROP> {
    fn drop(&mut self) {
        self.batch.flush::<BILINEAR>(self.map, self.row);
    }
}

/// Trilinear sampling (see `map/pyramid.rs`): the level of detail is set per span from
/// the span's step and the scanline's vertical footprint; pixels evaluated exactly get
/// the exact renderer's level of detail, from their own exact footprint.
pub(crate) struct TriSink<'a> {
    pub(crate) row: &'a mut [u32],
    pub(crate) map: &'a EnvMap,
    /// The map's levels as the span kernels read them.
    pub(crate) levels: &'a [Texels<'a>],
    /// Vertical footprint per region of this scanline, in level-0 map pixels.
    pub(crate) fy: [f32; STEP_REGIONS],
    pub(crate) lod: i32,
    /// The frame's exact footprints.
    pub(crate) fp: &'a ExactFootprint,
    /// This row's index (in the frame).
    pub(crate) y: usize,
    /// Spans waiting for the batch kernel, with their levels of detail.
    pub(crate) batch: Batch,
    /// Bilinear with a level per region (`Renderer::set_region_lod`): every level of
    /// detail is rounded to the nearest whole level ([`nearest_level`]), so each span is
    /// bilinear on one level, level 0 (the map) where the footprint is at most √2.
    pub(crate) nearest: bool,
}

impl TriSink<'_> {
    /// Set the level of detail (Q.8; rounded to a whole level in `nearest` mode).
    #[inline(always)]
    pub(crate) fn set_lod(&mut self, lod: i32) {
        self.lod = if self.nearest {
            (nearest_level(lod) as i32) << 8
        } else {
            lod
        };
    }

    /// Set the level of detail for a footprint of `f` level-0 map pixels per screen
    /// pixel: in `nearest` mode the whole level [`nearest_level_of`] (no logarithm: this
    /// runs once per span), else [`lod_q8`].
    #[inline(always)]
    fn set_footprint_of(&mut self, f: f64) {
        if self.nearest {
            self.lod = (nearest_level_of(f) as i32) << 8;
        } else {
            self.lod = lod_q8(f);
        }
    }
}

/// The pyramid level nearest to the footprint whose trilinear level of detail is `lod`
/// (Q.8, [`lod_q8`]: log2(footprint) − ½, 0 up to a footprint of √2): k = ⌊log2(f) + ½⌋
/// = ⌊lod/256⌋ + 1 for lod > 0, else 0. Footprints in (2^(k−½), 2^(k+½)] read level k,
/// which then reads between 0.71 and 1.41 of its texels per pixel. (Clamped to the last
/// level by the readers, as `EnvMap::trilinear` does.)
#[inline(always)]
pub(crate) fn nearest_level(lod: i32) -> u32 {
    if lod <= 0 {
        0
    } else {
        (lod >> 8) as u32 + 1
    }
}

impl Sink for TriSink<'_> {
    #[inline(always)]
    fn put(&mut self, x: usize, u: Fx, v: Fx) {
        self.row[x] = self.map.trilinear(u, v, self.lod);
    }
    #[inline(always)]
    fn span(&mut self, s: SpanJob, w_fx: Fx) {
        if self.map.crop.is_some() {
            // A partial map: per pixel (`EnvMap::trilinear` reads its levels as the
            // padded full map's; the span kernels know full maps only).
            return put_run(self, s, w_fx);
        }
        if self.batch.push_lod(s, self.lod) {
            self.batch.flush_trilinear(self.map, self.levels, self.row);
        }
    }
    #[inline(always)]
    fn flush(&mut self) {
        self.batch.flush_trilinear(self.map, self.levels, self.row);
    }
    #[inline(always)]
    fn background(&mut self, x: usize) {
        self.row[x] = self.map.background();
    }
    #[inline]
    fn exact(&mut self, x: usize, uv: Option<(f64, f64)>) {
        // Pole zones, pixels beyond the table: their own exact footprint, as the exact
        // renderer (a span's or the scanline's footprint can be far off there: at hfov
        // 170 the edge columns beyond the wide table see a fraction of the centre's).
        if self.nearest {
            // Bilinear with a level per region: one level, from the footprint's
            // derivative (no further exact positions: `ExactFootprint::derivative`).
            self.row[x] = match uv {
                Some(at) => {
                    let f = self.fp.derivative(x as f64 + 0.5, self.y as f64 + 0.5, at);
                    let last = self.levels.len() as u32 - 1;
                    sample_at_level(self.map, at, nearest_level_of(f).min(last))
                }
                None => self.map.background(),
            };
            return;
        }
        let lod = self.fp.lod(x, self.y, uv);
        self.row[x] = sample_at_lod(self.map, uv, lod);
    }
    #[inline]
    fn exact_level(&mut self, x: usize) -> Option<u32> {
        if !self.nearest {
            return None;
        }
        let f = self.fp.derivative_of(x as f64 + 0.5, self.y as f64 + 0.5)?;
        Some(nearest_level_of(f).min(self.levels.len() as u32 - 1))
    }
    #[inline]
    fn exact_on(&mut self, x: usize, uv: Option<(f64, f64)>, k: u32) {
        self.row[x] = match uv {
            Some(at) => sample_at_level(self.map, at, k),
            None => self.map.background(),
        };
    }
    #[inline(always)]
    fn footprint(&mut self, step: LvStep, region: usize) {
        let fx = step.dl.unsigned_abs().max(step.dv.unsigned_abs()) as f64 / FX_ONE as f64;
        self.set_footprint_of(fx.max(self.fy[region] as f64));
    }
    const LOD: bool = true;
    #[inline(always)]
    fn span_lod(&mut self, step: LvStep, region: usize) -> i32 {
        self.footprint(step, region);
        self.lod
    }
    #[inline(always)]
    fn set_footprint(&mut self, footprint: f64) {
        self.set_lod(lod_q8(footprint));
    }
}

/// See the [`PixelSink`] drop: queued spans are written.
impl Drop for TriSink<'_> {
    fn drop(&mut self) {
        self.batch.flush_trilinear(self.map, self.levels, self.row);
    }
}

/// Writes sampling positions instead of pixels (for measuring them).
pub(crate) struct PosSink<'a> {
    pub(crate) row: &'a mut [Option<(f64, f64)>],
}

impl Sink for PosSink<'_> {
    fn put(&mut self, x: usize, u: Fx, v: Fx) {
        self.row[x] = Some((from_fx(u), from_fx(v)));
    }
    fn background(&mut self, x: usize) {
        self.row[x] = None;
    }
    fn exact(&mut self, x: usize, uv: Option<(f64, f64)>) {
        self.row[x] = uv;
    }
}

/// The sinks of a frame, one per output row, for renderers that draw across rows (the
/// grid renderer's cells).
pub(crate) trait RowSinks: Sync {
    /// The output element: a pixel or a position.
    type Px: Send;
    /// The sink of one row.
    type S<'r>: Sink
    where
        Self: 'r;
    /// The sink writing `row`, output row `y`.
    fn sink<'r>(&'r self, row: &'r mut [Self::Px], y: usize) -> Self::S<'r>;
}

/// [`PixelSink`]s of a map.
pub(crate) struct PixelRows<'a, const BILINEAR: bool, const CROP: bool> {
    pub(crate) map: &'a EnvMap,
}

impl<const BILINEAR: bool, const CROP: bool> RowSinks for PixelRows<'_, BILINEAR, CROP> {
    type Px = u32;
    type S<'r>
        = PixelSink<'r, BILINEAR, CROP>
    where
        Self: 'r;
    #[inline]
    fn sink<'r>(&'r self, row: &'r mut [u32], _y: usize) -> Self::S<'r> {
        PixelSink::new(row, self.map)
    }
}

/// [`TriSink`]s of a map, their level of detail set per cell ([`Sink::set_footprint`]).
pub(crate) struct TriRows<'a> {
    pub(crate) map: &'a EnvMap,
    /// The map's levels as the span kernels read them (`kernel::level_texels`).
    pub(crate) levels: &'a [Texels<'a>],
    pub(crate) exact: &'a ExactFootprint,
}

impl RowSinks for TriRows<'_> {
    type Px = u32;
    type S<'r>
        = TriSink<'r>
    where
        Self: 'r;
    #[inline]
    fn sink<'r>(&'r self, row: &'r mut [u32], y: usize) -> Self::S<'r> {
        TriSink {
            row,
            map: self.map,
            levels: self.levels,
            fy: [0.0; STEP_REGIONS],
            lod: 0,
            fp: self.exact,
            y,
            batch: Batch::new(),
            nearest: false,
        }
    }
}

/// [`PosSink`]s.
pub(crate) struct PosRows;

impl RowSinks for PosRows {
    type Px = Option<(f64, f64)>;
    type S<'r> = PosSink<'r>;
    #[inline]
    fn sink<'r>(&'r self, row: &'r mut [Option<(f64, f64)>], _y: usize) -> Self::S<'r> {
        PosSink { row }
    }
}

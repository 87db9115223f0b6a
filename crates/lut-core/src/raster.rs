//! The LUT renderer: per-frame scanline setup and the scanline kernels.
//!
//! Per frame (and only per frame) each output scanline gets: its table rows (band and
//! blend weight, from pitch), its column scale (from zoom), its index-interpolation step
//! (from an error bound), and the pixel ranges that the table covers and that must be
//! evaluated exactly (near a pole, or beyond the table's field of view). Yaw is one
//! column offset added to u. Nothing else is recomputed when the view turns.
//!
//! Per scanline the kernel reads the table every Nth pixel and steps map coordinates in
//! Q.16 fixed point between reads. Longitude is unwrapped across each span, so a span
//! over the ±180° seam steps continuously and wraps per pixel instead of smearing across
//! the whole map.

use crate::camera::{check_size, Camera, View};
use crate::envmap::{EnvMap, Sampler};
use crate::error::ViewError;
use crate::exact::{check_buffer, render_exact};
use crate::fixed::{to_fx, Fx, FX_BITS, FX_ONE};
use crate::lut::{LutTable, Surface, TableKind, TableSpec};
use crate::projection::Projection;
use crate::rows::for_each_row;
use crate::simd::{SpanJob, Texels, MAX_JOBS};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// hfov (degrees) above which the wide-FOV table is used (the patent's 60°).
pub const LUT_SWITCH_HFOV: f64 = 60.0;

/// Largest sampling-position error, in source pixels, index interpolation may add to a
/// span (on top of [`crate::lut::TABLE_ERROR_BUDGET`]).
pub const SPAN_ERROR_BUDGET: f64 = 0.02;

/// Largest step the adaptive mode takes.
pub const ADAPTIVE_MAX_STEP: u32 = 64;

/// Each scanline is cut into this many regions of |X| (distance from the screen's
/// centre column), each with its own index step: the curvature of the map coordinates
/// peaks in one region and is small elsewhere, so a per-region step is several times
/// longer on average than one step per scanline, at the same error bound.
const STEP_REGIONS: usize = 8;

/// Which renderer draws the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RendererKind {
    /// The scanline-coherent LUT renderer.
    Lut,
    /// The exact per-pixel renderer.
    Exact,
}

/// Which table the LUT renderer reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LutChoice {
    /// Wide above [`LUT_SWITCH_HFOV`], high-resolution at or below it.
    Auto,
    /// Always the wide-FOV table.
    Wide,
    /// Always the high-resolution table (pixels beyond it are evaluated exactly).
    High,
}

/// Index interpolation step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IndexStep {
    /// Read the table every N pixels, N in {1, 2, 4, 8, 16}; shortened per scanline where
    /// the error bound requires it (near the poles).
    Fixed(u32),
    /// The longest power-of-two step (up to [`ADAPTIVE_MAX_STEP`]) whose error bound stays
    /// within [`SPAN_ERROR_BUDGET`], per scanline.
    Adaptive,
}

/// Options of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderOptions {
    /// LUT or exact.
    pub renderer: RendererKind,
    /// Pixel interpolation.
    pub sampler: Sampler,
    /// Index interpolation.
    pub index_step: IndexStep,
    /// Table choice.
    pub lut: LutChoice,
    /// The surface the tables are built on.
    pub surface: Surface,
    /// Render row bands on the rayon pool (output identical either way).
    pub threads: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            renderer: RendererKind::Lut,
            sampler: Sampler::Bilinear,
            index_step: IndexStep::Adaptive,
            lut: LutChoice::Auto,
            surface: Surface::Cylinder,
            threads: true,
        }
    }
}

/// Which path rendered a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RenderPath {
    /// The wide-FOV table (plus exact pixels where it cannot be trusted).
    LutWide,
    /// The high-resolution table (plus exact pixels where it cannot be trusted).
    LutHigh,
    /// The exact renderer.
    Exact,
}

impl RenderPath {
    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            RenderPath::LutWide => "lut-wide",
            RenderPath::LutHigh => "lut-high",
            RenderPath::Exact => "exact",
        }
    }
}

/// What rendered a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderReport {
    /// The path.
    pub path: RenderPath,
    /// Pixels the LUT path evaluated exactly (pole zones, beyond the table). Equal to
    /// `pixels` for the exact path.
    pub exact_pixels: u64,
    /// Pixels in the frame.
    pub pixels: u64,
    /// Bytes of the table used (0 for exact).
    pub table_bytes: usize,
    /// Largest index step used on any scanline.
    pub max_step: u32,
    /// Smallest index step used on any scanline.
    pub min_step: u32,
}

/// Sampling positions of a frame, row-major; `None` where the background shows.
pub type Positions = Vec<Option<(f64, f64)>>;

/// Per-scanline setup, computed once per frame.
#[derive(Debug, Clone, Copy, Default)]
struct Scan {
    /// The table covers part of this row.
    lut: bool,
    band: usize,
    wa: i64,
    neg_v: bool,
    back: bool,
    /// Column coordinate per unit of X (X = x + ½ − W/2).
    col_per_x: f64,
    /// t per unit of X (1/ρ).
    t_per_x: f64,
    /// sin and cos of the (unfolded) scanline angle.
    sa: f64,
    ca: f64,
    /// log2 of the index step per region of |X| (see [`STEP_REGIONS`]).
    shifts: [u8; STEP_REGIONS],
    /// Regions per unit of |X|.
    region_per_x: f64,
    /// Angle between this scanline and the next at the centre column (radians).
    row_angle: f64,
    /// Vertical pixel footprint per region (level-0 map pixels; trilinear only): the
    /// distance between this scanline's and the next one's table positions.
    fy: [f32; STEP_REGIONS],
    lut_lo: i64,
    lut_hi: i64,
    zone_lo: i64,
    zone_hi: i64,
}

/// Per-frame constants shared by all rows.
#[derive(Debug, Clone, Copy)]
struct Frame {
    w_out: usize,
    proj: Projection,
    mw: f64,
    mh: f64,
    map_w_fx: Fx,
    half_map_w_fx: Fx,
    map_h_fx: Fx,
    half_map_h_fx: Fx,
    /// W/2 + yaw, in map pixels, Q.16 (rectangular maps: u = Λ + off).
    off_fx: Fx,
    /// yaw in map pixels, Q.16 (scaled rows: u = W/2 + s · wrap(Λ + yaw)).
    yaw_fx: Fx,
    yaw: f64,
    coverage: bool,
    scaled: bool,
}

/// The renderer: owns the tables for one map geometry and per-frame scratch.
#[derive(Debug, Default)]
pub struct Renderer {
    tables: Vec<(Surface, TableKind, LutTable)>,
    geometry: Option<(u32, u32, Projection)>,
    scans: Vec<Scan>,
    /// Row scale per map row (Q.30: multiplied by Λ up to W/2, so Q.16 would lose up to
    /// 0.06 px), for elliptical and diamond maps.
    row_scale: Vec<i64>,
}

/// Where a renderer writes: pixels, or (for measurement) sampling positions.
trait Sink {
    fn put(&mut self, x: usize, u: Fx, v: Fx);
    /// `m` pixels from `x` on at (u + i·du, v + i·dv), u wrapped per pixel into [0, W)
    /// (`w_fx` = W in Q.16); v inside the map.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn span(&mut self, x: usize, m: usize, u: Fx, v: Fx, du: Fx, dv: Fx, w_fx: Fx) {
        put_run(self, x, m, (u, v), (du, dv), w_fx);
    }
    fn background(&mut self, x: usize);
    fn exact(&mut self, x: usize, uv: Option<(f64, f64)>);
    /// The per-pixel step (dΛ, dV) of the span about to be emitted (its horizontal
    /// footprint): the trilinear sink picks its pyramid level from it.
    #[inline(always)]
    fn footprint(&mut self, _dl: Fx, _dv: Fx, _region: usize) {}
    /// Write what the sink still holds (called at the end of each row).
    #[inline(always)]
    fn flush(&mut self) {}
}

/// Spans of one row waiting for a batch kernel ([`EnvMap::sample_spans`]): one kernel
/// call per [`MAX_JOBS`] spans instead of one per span.
struct Batch {
    jobs: [SpanJob; MAX_JOBS],
    /// Level of detail per span (trilinear only).
    lods: [i32; MAX_JOBS],
    n: usize,
}

impl Batch {
    fn new() -> Batch {
        Batch {
            jobs: [SpanJob::default(); MAX_JOBS],
            lods: [0; MAX_JOBS],
            n: 0,
        }
    }

    /// Queue a span; `true` when the batch is full (flush it).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn push(&mut self, x: usize, m: usize, u: Fx, v: Fx, du: Fx, dv: Fx, lod: i32) -> bool {
        self.jobs[self.n] = SpanJob {
            x: x as u32,
            len: m as u32,
            u,
            v,
            du,
            dv,
        };
        self.lods[self.n] = lod;
        self.n += 1;
        self.n == MAX_JOBS
    }

    /// Sample the queued spans into `row` (nearest or bilinear).
    #[inline]
    fn flush<const BILINEAR: bool>(&mut self, map: &EnvMap, row: &mut [u32]) {
        if self.n > 0 {
            map.sample_spans::<BILINEAR>(row, &self.jobs[..self.n]);
            self.n = 0;
        }
    }

    /// Sample the queued spans into `row`, trilinear with their levels of detail
    /// (`levels`: [`EnvMap::level_texels`]).
    #[inline]
    fn flush_trilinear(&mut self, map: &EnvMap, levels: &[Texels], row: &mut [u32]) {
        if self.n > 0 {
            map.trilinear_spans(levels, row, &self.jobs[..self.n], &self.lods[..self.n]);
            self.n = 0;
        }
    }
}

/// [`Sink::span`] pixel by pixel through [`Sink::put`].
#[inline(always)]
fn put_run<S: Sink + ?Sized>(s: &mut S, x: usize, m: usize, uv: (Fx, Fx), d: (Fx, Fx), w_fx: Fx) {
    let (mut u, mut v) = uv;
    for i in 0..m {
        s.put(x + i, wrap_u(u, w_fx), v);
        u += d.0;
        v += d.1;
    }
}

/// Writes sampled pixels. `CROP`: a partial map (see [`crate::coverage`]): full-panorama
/// (u, v) are looked up in the crop, background outside; a const parameter so the
/// full-map kernel keeps no per-pixel crop test.
struct PixelSink<'a, const BILINEAR: bool, const CROP: bool> {
    row: &'a mut [u32],
    map: &'a EnvMap,
    batch: Batch,
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
    fn span(&mut self, x: usize, m: usize, u: Fx, v: Fx, du: Fx, dv: Fx, _w_fx: Fx) {
        if CROP {
            self.map
                .sample_span_cropped::<BILINEAR>(&mut self.row[x..x + m], u, v, du, dv);
        } else if self.batch.push(x, m, u, v, du, dv, 0) {
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
        self.row[x] = crate::exact::sample_at(self.map, s, uv);
    }
}

/// Trilinear sampling (see [`crate::pyramid`]): the level of detail is set per span from
/// the span's step and the scanline's vertical footprint.
struct TriSink<'a> {
    row: &'a mut [u32],
    map: &'a EnvMap,
    /// The map's levels as the span kernels read them.
    levels: &'a [Texels<'a>],
    /// Vertical footprint per region of this scanline, in level-0 map pixels.
    fy: [f32; STEP_REGIONS],
    lod: i32,
    /// Spans waiting for the batch kernel, with their levels of detail.
    batch: Batch,
}

impl Sink for TriSink<'_> {
    #[inline(always)]
    fn put(&mut self, x: usize, u: Fx, v: Fx) {
        self.row[x] = self.map.trilinear(u, v, self.lod);
    }
    #[inline(always)]
    fn span(&mut self, x: usize, m: usize, u: Fx, v: Fx, du: Fx, dv: Fx, _w_fx: Fx) {
        if self.batch.push(x, m, u, v, du, dv, self.lod) {
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
        // Pole zones and pixels beyond the table: the footprint of the nearest span (or
        // of the scanline, before the first span).
        self.row[x] = crate::exact::sample_at_lod(self.map, uv, self.lod);
    }
    #[inline(always)]
    fn footprint(&mut self, dl: Fx, dv: Fx, region: usize) {
        let fx = dl.unsigned_abs().max(dv.unsigned_abs()) as f64 / FX_ONE as f64;
        self.lod = crate::pyramid::lod_q8(fx.max(self.fy[region] as f64));
    }
}

struct PosSink<'a> {
    row: &'a mut [Option<(f64, f64)>],
}

impl Sink for PosSink<'_> {
    fn put(&mut self, x: usize, u: Fx, v: Fx) {
        self.row[x] = Some((crate::fixed::from_fx(u), crate::fixed::from_fx(v)));
    }
    fn background(&mut self, x: usize) {
        self.row[x] = None;
    }
    fn exact(&mut self, x: usize, uv: Option<(f64, f64)>) {
        self.row[x] = uv;
    }
}

impl Renderer {
    /// A renderer for `map`'s geometry. Tables are built on first use and kept.
    pub fn new(map: &EnvMap) -> Renderer {
        let mut r = Renderer::default();
        r.set_geometry(map.width(), map.height(), map.projection());
        r
    }

    fn set_geometry(&mut self, w: u32, h: u32, p: Projection) {
        if self.geometry == Some((w, h, p)) {
            return;
        }
        self.geometry = Some((w, h, p));
        self.tables.clear();
        self.row_scale.clear();
        if p.scaled_rows() {
            self.row_scale = (0..=h)
                .map(|j| (p.row_scale_at_v(j as f64, h as f64) * ROW_SCALE_ONE).round() as i64)
                .collect();
        }
    }

    /// Build (if needed) and return the table of the given kind.
    pub fn table(&mut self, surface: Surface, kind: TableKind) -> &LutTable {
        let (w, h, p) = self.geometry.expect("geometry set in new()");
        if let Some(i) = self
            .tables
            .iter()
            .position(|(s, k, _)| *s == surface && *k == kind)
        {
            return &self.tables[i].2;
        }
        let spec = TableSpec::default_for(surface, kind, w);
        self.tables
            .push((surface, kind, LutTable::build(spec, p, w, h)));
        &self.tables.last().expect("just pushed").2
    }

    /// Which table `opts` selects for `view`.
    pub fn table_kind(view: View, opts: &RenderOptions) -> TableKind {
        match opts.lut {
            LutChoice::Wide => TableKind::Wide,
            LutChoice::High => TableKind::High,
            LutChoice::Auto => {
                if view.hfov_deg() > LUT_SWITCH_HFOV {
                    TableKind::Wide
                } else {
                    TableKind::High
                }
            }
        }
    }

    /// Render `view` of `map` into `out` (row-major 0RGB, `width × height`).
    ///
    /// # Errors
    /// [`ViewError`] for a bad size, buffer length or index step.
    pub fn render(
        &mut self,
        map: &EnvMap,
        view: View,
        opts: &RenderOptions,
        out: &mut [u32],
        width: u32,
        height: u32,
    ) -> Result<RenderReport, ViewError> {
        check_size(width, height)?;
        check_buffer(out, width, height)?;
        check_step(opts.index_step)?;
        let pixels = width as u64 * height as u64;
        if opts.renderer == RendererKind::Exact {
            render_exact(map, view, opts.sampler, out, width, height, opts.threads)?;
            return Ok(RenderReport {
                path: RenderPath::Exact,
                exact_pixels: pixels,
                pixels,
                table_bytes: 0,
                max_step: 1,
                min_step: 1,
            });
        }
        self.set_geometry(map.width(), map.height(), map.projection());
        let (frame, report) = self.prepare(view, opts, width, height);
        let table = self.find(opts.surface, Self::table_kind(view, opts));
        let scans = &self.scans;
        let row_scale = &self.row_scale[..];
        let w = width as usize;
        let bilinear = opts.sampler != Sampler::Nearest;
        if opts.sampler == Sampler::Trilinear && map.crop().is_none() {
            // The pyramid is built here once, before the rows run in parallel.
            let (levels, n) = map.level_texels();
            let levels = &levels[..n];
            for_each_row(out, w, opts.threads, |y, row| {
                let scan = &scans[y];
                let mut s = TriSink {
                    row,
                    map,
                    levels,
                    fy: scan.fy,
                    lod: crate::pyramid::lod_q8(scan.fy[0] as f64),
                    batch: Batch::new(),
                };
                render_row(scan, table, &frame, row_scale, &mut s);
                s.flush();
            });
            return Ok(report);
        }
        // One monomorphized kernel per (sampler, partial map): no per-pixel dispatch.
        fn rows<const BILINEAR: bool, const CROP: bool>(
            out: &mut [u32],
            w: usize,
            threads: bool,
            k: (&[Scan], &LutTable, &Frame, &[i64]),
            map: &EnvMap,
        ) {
            let (scans, table, frame, row_scale) = k;
            for_each_row(out, w, threads, |y, row| {
                let mut s = PixelSink::<BILINEAR, CROP> {
                    row,
                    map,
                    batch: Batch::new(),
                };
                render_row(&scans[y], table, frame, row_scale, &mut s);
                s.flush();
            });
        }
        let k = (&scans[..], table, &frame, row_scale);
        match (bilinear, map.crop().is_some()) {
            (true, false) => rows::<true, false>(out, w, opts.threads, k, map),
            (false, false) => rows::<false, false>(out, w, opts.threads, k, map),
            (true, true) => rows::<true, true>(out, w, opts.threads, k, map),
            (false, true) => rows::<false, true>(out, w, opts.threads, k, map),
        }
        Ok(report)
    }

    /// The map positions the LUT renderer samples for `view` (row-major, `None` =
    /// background): the same kernel as [`Renderer::render`], writing positions instead of
    /// pixels. Used to measure the sampling-position error against the exact map.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    #[allow(clippy::too_many_arguments)]
    pub fn positions(
        &mut self,
        map_w: u32,
        map_h: u32,
        projection: Projection,
        view: View,
        opts: &RenderOptions,
        width: u32,
        height: u32,
    ) -> Result<(Positions, RenderReport), ViewError> {
        check_size(width, height)?;
        check_step(opts.index_step)?;
        self.set_geometry(map_w, map_h, projection);
        let (frame, report) = self.prepare(view, opts, width, height);
        let table = self.find(opts.surface, Self::table_kind(view, opts));
        let mut out = vec![None; width as usize * height as usize];
        let scans = &self.scans;
        let row_scale = &self.row_scale[..];
        for_each_row(&mut out, width as usize, true, |y, row| {
            let mut s = PosSink { row };
            render_row(&scans[y], table, &frame, row_scale, &mut s);
        });
        Ok((out, report))
    }

    fn find(&self, surface: Surface, kind: TableKind) -> &LutTable {
        &self
            .tables
            .iter()
            .find(|(s, k, _)| *s == surface && *k == kind)
            .expect("table built in prepare()")
            .2
    }

    /// Per-frame setup: one [`Scan`] per output row.
    fn prepare(
        &mut self,
        view: View,
        opts: &RenderOptions,
        width: u32,
        height: u32,
    ) -> (Frame, RenderReport) {
        let kind = Self::table_kind(view, opts);
        let (mw, mh, proj) = self.geometry.expect("geometry set");
        self.table(opts.surface, kind);
        let table = self
            .tables
            .iter()
            .find(|(s, k, _)| *s == opts.surface && *k == kind)
            .map(|(_, _, t)| t)
            .expect("table built above");
        let scans = &mut self.scans;
        let cam = Camera::new(view, width, height);
        let f = cam.focal;
        let (mwf, mhf) = (mw as f64, mh as f64);
        let yaw = view.yaw();
        let yaw_px = yaw / TAU * mwf;
        let frame = Frame {
            w_out: width as usize,
            proj,
            mw: mwf,
            mh: mhf,
            map_w_fx: (mw as i64) << FX_BITS,
            half_map_w_fx: (mw as i64) << (FX_BITS - 1),
            map_h_fx: (mh as i64) << FX_BITS,
            half_map_h_fx: to_fx(mhf * 0.5),
            off_fx: to_fx(mwf * 0.5 + yaw_px),
            yaw_fx: to_fx(yaw_px),
            yaw,
            coverage: !proj.full_sphere(),
            scaled: proj.scaled_rows(),
        };
        let nominal = match opts.index_step {
            IndexStep::Fixed(n) => n,
            IndexStep::Adaptive => ADAPTIVE_MAX_STEP,
        };
        // Second-derivative bound factors of the map coordinates (see step_for()).
        let (v1, v2) = proj.profile_derivative_bounds(mwf, mhf);
        let coupling = proj.row_scale_coupling(mwf, mhf);
        let bounds = StepBounds {
            lam_px: mwf / TAU,
            v1,
            v2,
            coupling,
        };
        let pitch = view.pitch();
        let half_w = width as f64 * 0.5;
        scans.clear();
        let mut exact_pixels = 0u64;
        let (mut max_step, mut min_step) = (0u32, u32::MAX);
        for y in 0..height {
            let yc = height as f64 * 0.5 - (y as f64 + 0.5);
            let rho = yc.hypot(f);
            let alpha = pitch + yc.atan2(f);
            let (sa, ca) = alpha.sin_cos();
            let neg_v = alpha < 0.0;
            let mut a = alpha.abs();
            let back = a > FRAC_PI_2;
            if back {
                a = PI - a;
            }
            let mut scan = Scan {
                neg_v,
                back,
                sa,
                ca,
                t_per_x: 1.0 / rho,
                row_angle: f / (f * f + yc * yc),
                lut_lo: 0,
                lut_hi: -1,
                zone_lo: 0,
                zone_hi: -1,
                ..Scan::default()
            };
            let row_coord = match opts.surface {
                Surface::Cylinder => {
                    scan.col_per_x = 1.0 / rho;
                    Some(a)
                }
                Surface::Plane => {
                    if back || a >= table.row_max() {
                        None
                    } else {
                        scan.col_per_x = 1.0 / (rho * a.cos());
                        Some(a.tan())
                    }
                }
            };
            if let Some(rc) = row_coord.filter(|rc| *rc <= table.row_max()) {
                let (band, wa) = table.row_position(rc);
                scan.lut = true;
                scan.band = band;
                scan.wa = wa;
                let xc = table.col_max() / scan.col_per_x;
                let (lo, hi) = x_range(half_w, xc, width);
                scan.lut_lo = lo;
                scan.lut_hi = hi;
                let zone = table.zone(band);
                let mut t_min = 0.0;
                if zone >= 0.0 {
                    let xz = zone / scan.col_per_x;
                    let (zl, zh) = x_range(half_w, xz, width);
                    scan.zone_lo = zl;
                    scan.zone_hi = zh;
                    t_min = xz * scan.t_per_x;
                }
                let (sn, c) = (a.sin().abs(), a.cos().abs());
                let reg_x = half_w / STEP_REGIONS as f64;
                scan.region_per_x = 1.0 / reg_x;
                for (r, shift) in scan.shifts.iter_mut().enumerate() {
                    let (x_lo, x_hi) = (r as f64 * reg_x, (r + 1) as f64 * reg_x);
                    let n = step_for(&bounds, (sn, c), t_min, x_lo, x_hi, scan.t_per_x, nominal);
                    *shift = n.trailing_zeros() as u8;
                    max_step = max_step.max(n);
                    min_step = min_step.min(n);
                }
            }
            exact_pixels += exact_count(&scan, width as i64);
            scans.push(scan);
        }
        if min_step == u32::MAX {
            min_step = 1;
            max_step = max_step.max(1);
        }
        if opts.sampler == crate::envmap::Sampler::Trilinear {
            vertical_footprints(scans, table, &frame);
        }
        let report = RenderReport {
            path: match kind {
                TableKind::Wide => RenderPath::LutWide,
                TableKind::High => RenderPath::LutHigh,
            },
            exact_pixels,
            pixels: width as u64 * height as u64,
            table_bytes: table.bytes(),
            max_step,
            min_step,
        };
        (frame, report)
    }
}

/// The vertical footprint of every scanline per region (see [`Scan::fy`]): table positions
/// of the region's centre column on this scanline and the next (the previous one for the
/// last row), Λ taken the short way round the seam; where the table does not cover both,
/// the scanline's angular spacing in map pixels.
fn vertical_footprints(scans: &mut [Scan], table: &LutTable, fr: &Frame) {
    let n = scans.len();
    let half_w = fr.w_out as f64 * 0.5;
    let reg_x = half_w / STEP_REGIONS as f64;
    let px_per_rad = fr.mw / TAU;
    for y in 0..n {
        let other = if y + 1 < n {
            y + 1
        } else {
            y.saturating_sub(1)
        };
        let mut fy = [0f32; STEP_REGIONS];
        for (r, f) in fy.iter_mut().enumerate() {
            let x = ((half_w + (r as f64 + 0.5) * reg_x - 0.5).round() as i64)
                .clamp(0, fr.w_out as i64 - 1);
            let usable = |s: &Scan| {
                s.lut && x >= s.lut_lo && x <= s.lut_hi && !(x >= s.zone_lo && x <= s.zone_hi)
            };
            *f = if other != y && usable(&scans[y]) && usable(&scans[other]) {
                let (l0, v0) = read(&scans[y], table, fr, x);
                let (l1, v1) = read(&scans[other], table, fr, x);
                let mut dl = (l1 - l0).unsigned_abs() as i64;
                if dl > fr.half_map_w_fx {
                    dl = (fr.map_w_fx - dl).abs();
                }
                (dl.max((v1 - v0).abs()) as f64 / FX_ONE as f64) as f32
            } else {
                (scans[y].row_angle * px_per_rad) as f32
            };
        }
        scans[y].fy = fy;
    }
}

fn check_step(s: IndexStep) -> Result<(), ViewError> {
    match s {
        IndexStep::Fixed(n) if !matches!(n, 1 | 2 | 4 | 8 | 16) => Err(ViewError::BadIndexStep(n)),
        _ => Ok(()),
    }
}

/// Inclusive pixel range with |x + ½ − W/2| ≤ r, clamped to the row (empty: lo > hi).
fn x_range(half_w: f64, r: f64, width: u32) -> (i64, i64) {
    if r.is_nan() || r < 0.0 {
        return (0, -1);
    }
    let r = r.min(1e12);
    let lo = (half_w - 0.5 - r).ceil().max(0.0) as i64;
    let hi = (half_w - 0.5 + r).floor().min(width as f64 - 1.0) as i64;
    (lo, hi)
}

/// Pixels of a row the LUT path evaluates exactly.
fn exact_count(s: &Scan, w: i64) -> u64 {
    if !s.lut || s.lut_lo > s.lut_hi {
        return w as u64;
    }
    let outside = s.lut_lo + (w - 1 - s.lut_hi);
    let zl = s.zone_lo.max(s.lut_lo);
    let zh = s.zone_hi.min(s.lut_hi);
    let zone = if zl <= zh { zh - zl + 1 } else { 0 };
    (outside + zone) as u64
}

/// Factors of the second-derivative bound of the map coordinates along a scanline.
struct StepBounds {
    /// W / 2π: Λ pixels per radian of longitude.
    lam_px: f64,
    /// max |dV/dφ| and |d²V/dφ²| over the covered latitudes.
    v1: f64,
    v2: f64,
    /// How a V error turns into a u error through the row scale.
    coupling: f64,
}

/// The longest power-of-two step ≤ `nominal` whose linear-interpolation error is bounded
/// by [`SPAN_ERROR_BUDGET`] for every span that starts at |X| ∈ [x_lo, x_hi] (pixels from
/// the screen's centre column) on this scanline.
///
/// Along a scanline at folded angle `a` (s = sin a, c = cos a) the direction is
/// (t, s, c), λ = atan2(t, c), φ = atan2(s, ρ) with ρ = √(t²+c²), and t = X/ρ_screen
/// linear in the pixel (`dt` per pixel). |λ_tt| = 2|t|c/ρ⁴ exactly: unimodal in |t|
/// with its peak 0.6495/c² at |t| = c/√3, so its maximum over an interval is at the point
/// of the interval nearest the peak. φ_t = −s·t/(ρ(1+t²)) and
/// φ_tt = −s·(c²(1+t²) − 2t²ρ²)/(ρ³(1+t²)²), whose second factor is at most 1/ρ in size
/// (checked on a dense grid of t and c): |φ_tt| ≤ s/ρ, largest at the smallest |t|, and
/// |φ_t| ≤ s. Pixels with |t| < `t_min` are evaluated exactly (pole zone) and bound no
/// span. A span of n pixels from |X| in [x_lo, x_hi] covers |X| ∈ [x_lo − n, x_hi + n];
/// linear interpolation over it errs by at most (n·dt)²/8 · max|f''| there. (Bounds
/// checked numerically; 10 % margin added.)
fn step_for(
    b: &StepBounds,
    sc: (f64, f64),
    t_min: f64,
    x_lo: f64,
    x_hi: f64,
    dt: f64,
    nominal: u32,
) -> u32 {
    let mut n = nominal.max(1);
    loop {
        let reach = n as f64;
        let t_lo = ((x_lo - reach) * dt).max(t_min).max(0.0);
        let t_hi = ((x_hi + reach) * dt).max(t_lo);
        let bound = span_bound(b, sc, t_lo, t_hi);
        let len = reach * dt;
        if n == 1 || (bound.is_finite() && len * len / 8.0 * bound <= SPAN_ERROR_BUDGET) {
            return n;
        }
        n >>= 1;
    }
}

/// Bound on the second derivative (in source pixels per unit t²) of the map position
/// along a scanline over |t| ∈ [t_lo, t_hi] (see [`step_for`]).
fn span_bound(b: &StepBounds, (s, c): (f64, f64), t_lo: f64, t_hi: f64) -> f64 {
    let lam_tt = if c <= 0.0 {
        if t_lo > 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    } else {
        let t = (c / 3f64.sqrt()).clamp(t_lo, t_hi);
        let r2 = t * t + c * c;
        2.0 * t * c / (r2 * r2)
    };
    let rho_min = (t_lo * t_lo + c * c).sqrt();
    let phi_tt = if rho_min > 0.0 {
        1.125 * s / rho_min
    } else {
        f64::INFINITY
    };
    let v_tt = b.v1 * phi_tt + b.v2 * s * s;
    1.1 * (b.lam_px * lam_tt + (1.0 + b.coupling) * v_tt)
}

/// Render one scanline into `sink`.
#[inline]
fn render_row<S: Sink>(scan: &Scan, table: &LutTable, fr: &Frame, row_scale: &[i64], sink: &mut S) {
    let w = fr.w_out as i64;
    if !scan.lut || scan.lut_lo > scan.lut_hi {
        exact_run(scan, fr, 0, w - 1, sink);
        return;
    }
    exact_run(scan, fr, 0, scan.lut_lo - 1, sink);
    let zl = scan.zone_lo.max(scan.lut_lo);
    let zh = scan.zone_hi.min(scan.lut_hi);
    if zl <= zh {
        lut_run(scan, table, fr, row_scale, scan.lut_lo, zl - 1, sink);
        exact_run(scan, fr, zl, zh, sink);
        lut_run(scan, table, fr, row_scale, zh + 1, scan.lut_hi, sink);
    } else {
        lut_run(scan, table, fr, row_scale, scan.lut_lo, scan.lut_hi, sink);
    }
    exact_run(scan, fr, scan.lut_hi + 1, w - 1, sink);
}

/// Exact evaluation of pixels x0..=x1 of a scanline (pole zones, beyond the table).
#[inline(never)]
fn exact_run<S: Sink>(scan: &Scan, fr: &Frame, x0: i64, x1: i64, sink: &mut S) {
    let half_w = fr.w_out as f64 * 0.5;
    let c2 = scan.ca * scan.ca;
    for x in x0.max(0)..=x1 {
        let t = (x as f64 + 0.5 - half_w) * scan.t_per_x;
        let lambda = t.atan2(scan.ca) + fr.yaw;
        let phi = scan.sa.atan2((t * t + c2).sqrt());
        sink.exact(x as usize, fr.proj.uv(lambda, phi, fr.mw, fr.mh));
    }
}

/// Unfolded table read at pixel x: (Λ, V) in Q.16 for the yaw-0 frame.
#[inline(always)]
fn read(scan: &Scan, table: &LutTable, fr: &Frame, x: i64) -> (Fx, Fx) {
    let big_x = x as f64 + 0.5 - fr.w_out as f64 * 0.5;
    let (mut l, mut v) = table.lookup(scan.band, scan.wa, big_x.abs() * scan.col_per_x);
    if scan.back {
        l = fr.half_map_w_fx - l;
    }
    if big_x < 0.0 {
        l = -l;
    }
    if scan.neg_v {
        v = -v;
    }
    (l, v)
}

/// LUT evaluation of pixels x0..=x1: table reads every 2^shift pixels (the shift of the
/// region the span starts in), fixed-point steps between.
#[inline(always)]
fn lut_run<S: Sink>(
    scan: &Scan,
    table: &LutTable,
    fr: &Frame,
    row_scale: &[i64],
    x0: i64,
    x1: i64,
    sink: &mut S,
) {
    if x0 > x1 {
        return;
    }
    let half_w = fr.w_out as f64 * 0.5;
    let last_region = STEP_REGIONS - 1;
    let mut xs = x0;
    let (mut l0, mut v0) = read(scan, table, fr, xs);
    loop {
        let big_x = (xs as f64 + 0.5 - half_w).abs();
        let region = ((big_x * scan.region_per_x) as usize).min(last_region);
        let shift = scan.shifts[region] as u32;
        let n = 1i64 << shift;
        let xe = (xs + n).min(x1);
        if xe == xs {
            emit(fr, row_scale, xs, 1, (l0, v0), (0, 0), sink);
            return;
        }
        let (mut l1, v1) = read(scan, table, fr, xe);
        // Unwrap longitude across the span: a ±180° seam is a jump of one map width.
        let d = l1 - l0;
        if d > fr.half_map_w_fx {
            l1 -= fr.map_w_fx;
        } else if d < -fr.half_map_w_fx {
            l1 += fr.map_w_fx;
        }
        let m = xe - xs;
        let (dl, dv) = if m == n {
            ((l1 - l0) >> shift, (v1 - v0) >> shift)
        } else {
            ((l1 - l0) / m, (v1 - v0) / m)
        };
        sink.footprint(dl, dv, region);
        if xe == x1 {
            // Last span: emit through x1 inclusive, ending exactly on the read value.
            emit(fr, row_scale, xs, m, (l0, v0), (dl, dv), sink);
            emit(fr, row_scale, x1, 1, (l1, v1), (0, 0), sink);
            return;
        }
        emit(fr, row_scale, xs, m, (l0, v0), (dl, dv), sink);
        xs = xe;
        l0 = l1;
        v0 = v1;
    }
}

/// Emit `m` pixels from `x` on, starting at (Λ, V) and stepping by (dΛ, dV).
#[inline(always)]
fn emit<S: Sink>(
    fr: &Frame,
    row_scale: &[i64],
    x: i64,
    m: i64,
    start: (Fx, Fx),
    step: (Fx, Fx),
    sink: &mut S,
) {
    let (l, vv) = start;
    let (dl, dvv) = step;
    // v = H/2 − V
    let mut v = fr.half_map_h_fx - vv;
    let dv = -dvv;
    let x = x as usize;
    let m = m as usize;
    if fr.scaled {
        let mut lw = l + fr.yaw_fx;
        for i in 0..m {
            // wrap Λ + yaw into (−W/2, W/2], as λ into (−π, π]
            let mut a = lw;
            if a > fr.half_map_w_fx || a <= -fr.half_map_w_fx {
                a = fr.half_map_w_fx - (fr.half_map_w_fx - a).rem_euclid(fr.map_w_fx);
            }
            let s = row_scale_at(row_scale, v, fr.mh as usize);
            let u = fr.half_map_w_fx + ((s * a) >> ROW_SCALE_BITS);
            sink.put(x + i, u, v);
            lw += dl;
            v += dv;
        }
        return;
    }
    let wfx = fr.map_w_fx;
    let mut u = wrap_u(l + fr.off_fx, wfx);
    if !(0..wfx).contains(&u) {
        u = u.rem_euclid(wfx);
    }
    if fr.coverage {
        for i in 0..m {
            let uu = wrap_u(u, wfx);
            if v < 0 || v > fr.map_h_fx {
                sink.background(x + i);
            } else {
                sink.put(x + i, uu, v);
            }
            u += dl;
            v += dv;
        }
    } else {
        sink.span(x, m, u, v, dl, dv, wfx);
    }
}

#[inline(always)]
fn wrap_u(u: Fx, w: Fx) -> Fx {
    if u >= w {
        u - w
    } else if u < 0 {
        u + w
    } else {
        u
    }
}

/// Fractional bits of the row scale s.
const ROW_SCALE_BITS: u32 = 30;
const ROW_SCALE_ONE: f64 = (1u64 << ROW_SCALE_BITS) as f64;

/// Row scale s(v) (Q.30), linear between map rows.
#[inline(always)]
fn row_scale_at(rs: &[i64], v: Fx, h: usize) -> i64 {
    let vi = (v >> FX_BITS).clamp(0, h as i64 - 1) as usize;
    let fr = (v - ((vi as i64) << FX_BITS)).clamp(0, 1 << FX_BITS);
    rs[vi] + (((rs[vi + 1] - rs[vi]) * fr) >> FX_BITS)
}

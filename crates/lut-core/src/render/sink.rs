//! Sinks: where the scanline walk (`render/scanline.rs`) writes. One monomorphized sink
//! per sampler and map kind (full or partial), so the choice is made once per frame and
//! never per pixel; a trilinear sink that sets its level of detail once per span; and a
//! sink of sampling positions, for measuring them against the exact mapping.

use super::exact::{sample_at, sample_at_lod, ExactFootprint};
use super::kernel::{sample_span, trilinear_span};
use super::scanline::wrap_u;
use super::steps::STEP_REGIONS;
use crate::geom::fixed::{from_fx, Fx, FX_ONE};
use crate::map::envmap::EnvMap;
use crate::map::pyramid::lod_q8;
use crate::map::sample::Sampler;

/// Where a renderer writes: pixels, or (for measurement) sampling positions.
pub(crate) trait Sink {
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
    /// The pixel footprint (level-0 map pixels) of the spans that follow, known as a whole
    /// (the grid renderer's cells): the trilinear sink picks its pyramid level from it.
    #[inline(always)]
    fn set_footprint(&mut self, _footprint: f64) {}
}

/// [`Sink::span`] pixel by pixel through [`Sink::put`].
#[inline(always)]
pub(crate) fn put_run<S: Sink + ?Sized>(
    s: &mut S,
    x: usize,
    m: usize,
    uv: (Fx, Fx),
    d: (Fx, Fx),
    w_fx: Fx,
) {
    let (mut u, mut v) = uv;
    for i in 0..m {
        s.put(x + i, wrap_u(u, w_fx), v);
        u += d.0;
        v += d.1;
    }
}

/// Writes sampled pixels. `CROP`: a partial map (see `map/crop.rs`): full-panorama
/// (u, v) are looked up in the crop, background outside; a const parameter so the
/// full-map kernel keeps no per-pixel crop test.
pub(crate) struct PixelSink<'a, const BILINEAR: bool, const CROP: bool> {
    pub(crate) row: &'a mut [u32],
    pub(crate) map: &'a EnvMap,
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
    fn span(&mut self, x: usize, m: usize, u: Fx, v: Fx, du: Fx, dv: Fx, w_fx: Fx) {
        if CROP {
            put_run(self, x, m, (u, v), (du, dv), w_fx); // per pixel: the crop test
        } else {
            sample_span::<BILINEAR>(self.map, &mut self.row[x..x + m], u, v, du, dv);
        }
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

/// Trilinear sampling (see `map/pyramid.rs`): the level of detail is set per span from
/// the span's step and the scanline's vertical footprint; pixels evaluated exactly get
/// the exact renderer's level of detail, from their own exact footprint.
pub(crate) struct TriSink<'a> {
    pub(crate) row: &'a mut [u32],
    pub(crate) map: &'a EnvMap,
    /// Vertical footprint per region of this scanline, in level-0 map pixels.
    pub(crate) fy: [f32; STEP_REGIONS],
    pub(crate) lod: i32,
    /// The frame's exact footprints and this row's index.
    pub(crate) exact: (&'a ExactFootprint, usize),
}

impl Sink for TriSink<'_> {
    #[inline(always)]
    fn put(&mut self, x: usize, u: Fx, v: Fx) {
        self.row[x] = self.map.trilinear(u, v, self.lod);
    }
    #[inline(always)]
    fn span(&mut self, x: usize, m: usize, u: Fx, v: Fx, du: Fx, dv: Fx, _w_fx: Fx) {
        trilinear_span(self.map, &mut self.row[x..x + m], u, v, du, dv, self.lod);
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
        let (fp, y) = self.exact;
        self.row[x] = sample_at_lod(self.map, uv, fp.lod(x, y, uv));
    }
    #[inline(always)]
    fn footprint(&mut self, dl: Fx, dv: Fx, region: usize) {
        let fx = dl.unsigned_abs().max(dv.unsigned_abs()) as f64 / FX_ONE as f64;
        self.lod = lod_q8(fx.max(self.fy[region] as f64));
    }
    #[inline(always)]
    fn set_footprint(&mut self, footprint: f64) {
        self.lod = lod_q8(footprint);
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
        PixelSink { row, map: self.map }
    }
}

/// [`TriSink`]s of a map, their level of detail set per cell ([`Sink::set_footprint`]).
pub(crate) struct TriRows<'a> {
    pub(crate) map: &'a EnvMap,
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
            fy: [0.0; STEP_REGIONS],
            lod: 0,
            exact: (self.exact, y),
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

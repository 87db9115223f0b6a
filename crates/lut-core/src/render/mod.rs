//! Rendering: the frame type, the [`Scene`] (a map or a cube map) and the one render
//! entry, [`Renderer::render`].
//!
//! The LUT renderer (US 5,748,194) is split by what runs how often:
//! * per frame, `setup.rs`: each scanline's table rows, column scale, index steps (from
//!   the analytic bounds of `steps.rs`) and exact-pixel ranges; nothing else is
//!   recomputed when the view turns;
//! * per scanline, `scanline.rs`: the table read every Nth pixel of the right half (the
//!   left half is its mirror image), map coordinates stepped in Q.16 fixed point between
//!   reads, longitude unwrapped across each span (a span over the ±180° seam steps
//!   continuously and wraps per pixel instead of smearing across the whole map);
//!   `rowpass.rs`, for full maps (any sampler): the walk's positions for a run
//!   of the row at once, then one gather pass (`kernel/row.rs`); `rows.rs` runs the rows
//!   on one thread or in bands on rayon;
//! * per pixel, `kernel/`: the row and span kernels, with the rules they keep;
//! * `sink.rs`: where a scanline's spans go otherwise (pixels per sampler, or positions).
//!
//! `exact.rs` is the per-pixel reference renderer, `cube.rs` the cube renderers,
//! `heat.rs` the error heat map (per-pixel sampling-position error of a renderer),
//! `grid.rs` the per-view adaptive grid (every output projection, with the same span
//! kernels), `projected.rs` cube maps in the other output projections.
//!
//! Which draws a frame: [`RendererKind::Exact`] the exact renderer; [`RendererKind::Grid`]
//! the grid; [`RendererKind::Lut`] the table for rectilinear views and the grid for the
//! other output projections (they are not scanline-coherent, so no table applies).

pub(crate) mod cube;
pub(crate) mod exact;
pub(crate) mod frame;
pub(crate) mod grid;
pub(crate) mod heat;
pub(crate) mod kernel;
pub(crate) mod projected;
pub(crate) mod rowpass;
pub(crate) mod rows;
pub(crate) mod scanline;
pub(crate) mod setup;
pub(crate) mod sink;
pub(crate) mod steps;

use crate::cube::CubeMap;
use crate::error::ViewError;
use crate::geom::camera::{check_size, Camera, View};
use crate::geom::mapping::{exact_uv, exact_uv_at};
use crate::geom::projection::Projection;
use crate::lut::{LutTable, Surface, TableKind, TableSpec};
use crate::map::envmap::EnvMap;
use crate::map::pyramid::lod_q8;
use crate::map::sample::Sampler;
use crate::named::Named;
use cube::{render_cube, CubeRenderer};
use exact::{render_exact, ExactFootprint};
use frame::Frame;
use grid::{Grid, GridStats};
use kernel::{level_texels, texels};
use rowpass::{pixel_row, position_row, tri_row};
use rows::{for_each_band_init, for_each_row, for_each_row_init, post_bands};
use scanline::{RowScratch, ScratchLoan, ROW_SCALE_ONE};
use setup::{check_step, prepare, Scan, Setup};
use sink::{Batch, PixelRows, PosRows, RowSinks, TriRows, TriSink};
use std::f64::consts::TAU;

/// hfov (degrees) above which the wide-FOV table is used (the patent's 60°).
pub const LUT_SWITCH_HFOV: f64 = 60.0;

/// What to render: a map (any projection, full or partial) or a cube map.
#[derive(Debug, Clone, Copy)]
pub enum Scene<'a> {
    /// An environment map, drawn by the LUT or the exact renderer.
    Map(&'a EnvMap),
    /// A cube map, drawn by one of the cube renderers.
    Cube(&'a CubeMap),
}

impl<'a> From<&'a EnvMap> for Scene<'a> {
    fn from(m: &'a EnvMap) -> Self {
        Scene::Map(m)
    }
}

impl<'a> From<&'a CubeMap> for Scene<'a> {
    fn from(c: &'a CubeMap) -> Self {
        Scene::Cube(c)
    }
}

/// Which renderer draws the frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RendererKind {
    /// The scanline-coherent LUT renderer (rectilinear views; the grid draws the other
    /// output projections).
    Lut,
    /// The per-view adaptive grid of exact positions (every output projection).
    Grid,
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
    /// The longest power-of-two step (up to [`crate::ADAPTIVE_MAX_STEP`]) whose error
    /// bound stays within [`crate::SPAN_ERROR_BUDGET`], per region of each scanline.
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
    /// The cube renderer, for a [`Scene::Cube`] (both give the same pixels).
    pub cube: CubeRenderer,
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
            cube: CubeRenderer::Accelerated,
        }
    }
}

impl Named for RendererKind {
    const ALL: &'static [Self] = &[RendererKind::Lut, RendererKind::Grid, RendererKind::Exact];
    fn name(self) -> &'static str {
        match self {
            RendererKind::Lut => "lut",
            RendererKind::Grid => "grid",
            RendererKind::Exact => "exact",
        }
    }
    fn help(self) -> &'static str {
        match self {
            RendererKind::Lut => {
                "The scanline-coherent LUT renderer (the grid draws non-rectilinear views)"
            }
            RendererKind::Grid => "A per-view adaptive grid of exact positions, any projection",
            RendererKind::Exact => "The exact per-pixel renderer",
        }
    }
}

impl Named for LutChoice {
    const ALL: &'static [Self] = &[LutChoice::Auto, LutChoice::Wide, LutChoice::High];
    fn name(self) -> &'static str {
        match self {
            LutChoice::Auto => "auto",
            LutChoice::Wide => "wide",
            LutChoice::High => "high",
        }
    }
    fn help(self) -> &'static str {
        match self {
            LutChoice::Auto => "Wide above 60 degrees hfov, high-resolution at or below",
            LutChoice::Wide => "The wide-FOV table",
            LutChoice::High => "The high-resolution table",
        }
    }
}

/// The steps rendering accepts, the adaptive one first (the default). A `Fixed` step
/// outside {1, 2, 4, 8, 16}, which rendering refuses, is named `invalid`.
impl Named for IndexStep {
    const ALL: &'static [Self] = &[
        IndexStep::Adaptive,
        IndexStep::Fixed(1),
        IndexStep::Fixed(2),
        IndexStep::Fixed(4),
        IndexStep::Fixed(8),
        IndexStep::Fixed(16),
    ];
    fn name(self) -> &'static str {
        match self {
            IndexStep::Adaptive => "adaptive",
            IndexStep::Fixed(1) => "1",
            IndexStep::Fixed(2) => "2",
            IndexStep::Fixed(4) => "4",
            IndexStep::Fixed(8) => "8",
            IndexStep::Fixed(16) => "16",
            IndexStep::Fixed(_) => "invalid",
        }
    }
    fn help(self) -> &'static str {
        match self {
            IndexStep::Adaptive => "The longest step the error bound allows, per scanline region",
            IndexStep::Fixed(1) => "Read the table at every pixel",
            IndexStep::Fixed(2) => "Read the table every 2nd pixel, interpolate between",
            IndexStep::Fixed(4) => "Read the table every 4th pixel, interpolate between",
            IndexStep::Fixed(8) => "Read the table every 8th pixel, interpolate between",
            IndexStep::Fixed(16) => "Read the table every 16th pixel, interpolate between",
            IndexStep::Fixed(_) => "Not a step rendering accepts",
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
    /// The per-view grid (plus exact pixels where no cell can be trusted).
    Grid,
    /// The exact renderer.
    Exact,
    /// A cube map, with the given renderer (rectilinear views).
    Cube(CubeRenderer),
    /// A cube map in another output projection, per pixel.
    CubeProjected,
}

impl RenderPath {
    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            RenderPath::LutWide => "lut-wide",
            RenderPath::LutHigh => "lut-high",
            RenderPath::Grid => "grid",
            RenderPath::Exact => "exact",
            RenderPath::Cube(CubeRenderer::Basic) => "cube-basic",
            RenderPath::Cube(CubeRenderer::Accelerated) => "cube-accelerated",
            RenderPath::CubeProjected => "cube-per-pixel",
        }
    }
}

/// What rendered a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderReport {
    /// The path.
    pub path: RenderPath,
    /// Pixels the LUT path evaluated exactly (pole zones, beyond the table), or the grid
    /// (cells that failed their budget at the smallest size, the edge of a fisheye's
    /// disc). Equal to `pixels` for the exact path, 0 for a cube map.
    pub exact_pixels: u64,
    /// Pixels in the frame.
    pub pixels: u64,
    /// Bytes of the table used (0 for exact and the grid; the texels for a cube map).
    pub table_bytes: usize,
    /// Largest index step used on any scanline (the grid: the largest interpolated cell
    /// side, 0 when every pixel was exact or background).
    pub max_step: u32,
    /// Smallest index step used on any scanline (the grid: the smallest cell side).
    pub min_step: u32,
}

impl RenderReport {
    /// The report of the exact renderer: every one of `pixels` evaluated exactly.
    fn exact(pixels: u64) -> RenderReport {
        RenderReport {
            path: RenderPath::Exact,
            exact_pixels: pixels,
            pixels,
            table_bytes: 0,
            max_step: 1,
            min_step: 1,
        }
    }
}

/// Sampling positions of a frame, row-major; `None` where the background shows.
pub type Positions = Vec<Option<(f64, f64)>>;

/// Work run on bands of finished rows right after a renderer wrote them, while they are
/// still in cache ([`Renderer::render_with`]): `hook(y0, rows)` gets whole rows of the
/// frame from row `y0` on. Every band starts at a multiple of [`HOOK_BAND_ROWS`] and
/// holds a multiple of it (the frame's last band may hold fewer); every row is in
/// exactly one band. Bands may run in parallel.
pub type BandHook<'a> = &'a (dyn Fn(usize, &mut [u32]) + Sync);

/// The row alignment of the bands a [`BandHook`] gets.
pub const HOOK_BAND_ROWS: usize = 16;

/// The renderer: owns the tables for one map geometry and per-frame scratch.
#[derive(Debug, Default)]
pub struct Renderer {
    tables: Vec<(Surface, TableKind, LutTable)>,
    geometry: Option<(u32, u32, Projection)>,
    scans: Vec<Scan>,
    /// Row scale per map row (Q.30: multiplied by Λ up to W/2, so Q.16 would lose up to
    /// 0.06 px), for elliptical and diamond maps.
    row_scale: Vec<i64>,
    /// Bilinear reads the pyramid level matching the footprint
    /// ([`Renderer::set_bilinear_level`]).
    bilinear_level: bool,
    /// Still bilinear and trilinear frames read the pyramid level matching the frame's
    /// smallest footprint ([`Renderer::set_still_level`]).
    still_level: bool,
    /// The renderer of frames drawn from a pyramid level: its tables are for the level's
    /// geometry.
    level: Option<Box<Renderer>>,
}

/// The table of `surface` and `kind` among `tables` (built by [`Renderer::table`]).
fn find(tables: &[(Surface, TableKind, LutTable)], surface: Surface, kind: TableKind) -> &LutTable {
    &tables
        .iter()
        .find(|(s, k, _)| *s == surface && *k == kind)
        .expect("table built before it is looked up")
        .2
}

impl Renderer {
    /// A renderer for `map`'s geometry. Tables are built on first use and kept.
    pub fn new(map: &EnvMap) -> Renderer {
        let mut r = Renderer::default();
        r.set_geometry(map.width(), map.height(), map.projection());
        r
    }

    /// Bilinear frames read the pyramid level that matches the screen (`on`), or the map
    /// itself (`false`, the default): what the window draws while the view moves.
    ///
    /// Zoomed out on a big map, a bilinear frame reads texels far apart: each sample a
    /// cache miss, so the frame costs more the bigger the map. With this on, the frame is
    /// drawn as a plain bilinear frame of pyramid level k, one level for the whole frame,
    /// where 2^k is the power of two nearest to the footprint at the view's centre (map
    /// pixels per screen pixel; k = ⌊log2(footprint) + ½⌋, the nearest mip level, so the
    /// centre reads between 0.71 and 1.41 level texels per pixel), with the level's own
    /// look-up tables: a 32768-wide map at 1080p and hfov 90 (footprint 5.4) is drawn from
    /// its 8192-wide level exactly as an 8192-wide map would be, at that map's cost, and
    /// aliases less than bilinear on the map. Only levels that divide the map's sides
    /// exactly are used (positions on them are exact; a 6000×3000 map goes down to level
    /// 3, 750×375); footprints below √2 at the centre are plain bilinear, byte for byte.
    /// Towards the edges of a wide view the footprint shrinks (at hfov 90 to about half),
    /// so the edges are magnified there as they are on a map of the level's size. Partial
    /// maps (no pyramid) are unaffected. The pyramid is built on the first such frame if
    /// it was not (`EnvMap::pyramid`); the level's tables on the first frame of a level.
    pub fn set_bilinear_level(&mut self, on: bool) {
        self.bilinear_level = on;
    }

    /// Whether bilinear reads the pyramid level ([`Renderer::set_bilinear_level`]).
    pub fn bilinear_level(&self) -> bool {
        self.bilinear_level
    }

    /// Still frames, bilinear and trilinear (bilinear frames not drawn on the level of
    /// [`Renderer::set_bilinear_level`]), are drawn from the deepest pyramid level on which
    /// no pixel of the frame is magnified by more than √2 (`on`: what the viewer draws when
    /// the view stands still), or from the map itself at every zoom (`false`, the default:
    /// the samplers as the golden images and the accuracy tables define them).
    ///
    /// Zoomed out, bilinear on the map reads texels far apart: it aliases (a pixel
    /// covering four texels shows one of them, and the pick moves as the view moves), and
    /// the frame's cost grows with the map (each sample a cache miss: a 32768-wide map at
    /// 1080p and hfov 90 took 4x the 8192-wide map's frame). Trilinear does not alias, but
    /// its level of detail (with its −½ bias) reaches levels finer than the map's
    /// 8192-wide level towards the edges of a wide view, where a rectilinear view's pixels
    /// are smallest, and blends two of them there: 4x the 8192-wide map's frame as well.
    /// With this on, the frame is drawn as a plain bilinear or trilinear frame of pyramid
    /// level k, with the level's own tables (and, for trilinear, the level's own pyramid,
    /// a third of the level's bytes, built on its first trilinear frame unless
    /// [`build_frame_levels`] built it before: the window does while loading), where
    /// k = ⌊log2(m) + ½⌋ and m is the smallest footprint in the frame (map pixels per
    /// screen pixel: the larger of the exact distances to the next pixel right and below,
    /// `frame_min_footprint`, sampled on a grid over the frame that includes its corners
    /// and edges). Every pixel then reads at least 1/√2 level texels (where the footprint
    /// is smallest, a level texel is at most √2 pixels wide), and where the footprint is
    /// larger, bilinear reads fewer texels than on the map and trilinear reads the same
    /// levels as on the map. The price: trilinear no longer blends in finer levels than k
    /// where the footprint is smallest (the −½ bias's extra sharpness there), as on a
    /// smaller map of the same scene. So a 32768-wide map at hfov 90 is drawn as its
    /// 8192-wide level would be drawn, at that map's cost. Frames whose smallest footprint
    /// is at most √2 (any view that is not zoomed out: 1080p at hfov 90 or 120 on a map up
    /// to 8192 wide) are drawn from the map, byte for byte; so are partial maps (no
    /// pyramid) and nearest frames. Only levels that divide the map's sides exactly are
    /// used ([`Renderer::set_bilinear_level`]). The exact renderer
    /// ([`RendererKind::Exact`]) draws the same level, so the two stay comparable. The
    /// pyramid is built on the first such frame if it was not (`EnvMap::pyramid`).
    pub fn set_still_level(&mut self, on: bool) {
        self.still_level = on;
    }

    /// Whether still frames read a pyramid level ([`Renderer::set_still_level`]).
    pub fn still_level(&self) -> bool {
        self.still_level
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

    /// The pyramid level a frame of `view` on `width × height` pixels is drawn from instead
    /// of `map` ([`Renderer::set_bilinear_level`], [`Renderer::set_still_level`]), or
    /// `None` for the map itself.
    fn level_map<'m>(
        &self,
        map: &'m EnvMap,
        view: View,
        sampler: Sampler,
        (width, height): (u32, u32),
    ) -> Option<&'m EnvMap> {
        if map.crop().is_some() {
            return None;
        }
        let k = match sampler {
            Sampler::Bilinear if self.bilinear_level => {
                let centre =
                    2.0 * (view.hfov() * 0.5).tan() / width as f64 * map.width() as f64 / TAU;
                frame_level(centre, map.width(), map.height())
            }
            Sampler::Bilinear | Sampler::Trilinear if self.still_level => {
                let m = frame_min_footprint(view, width, height, geometry_of(map));
                frame_level(m, map.width(), map.height())
            }
            _ => 0,
        };
        (k > 0).then(|| map.level(k).0)
    }

    /// Per-frame setup for the geometry set last: builds the table `opts` selects (if
    /// needed) and fills one [`Scan`] per row (see `setup.rs`).
    fn prepare_frame(
        &mut self,
        view: View,
        opts: &RenderOptions,
        width: u32,
        height: u32,
    ) -> (Setup, RenderReport) {
        let kind = Self::table_kind(view, opts);
        let geometry = self.geometry.expect("geometry set before a frame");
        self.table(opts.surface, kind);
        let table = find(&self.tables, opts.surface, kind);
        prepare(
            table,
            kind,
            geometry,
            &mut self.scans,
            view,
            opts,
            width,
            height,
        )
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

    /// Render `view` of `scene` into `frame`: the one render entry for maps (LUT or exact,
    /// as `opts.renderer` says) and cube maps (with `opts.cube`).
    ///
    /// # Errors
    /// [`ViewError::BadIndexStep`] for an index step not in {1, 2, 4, 8, 16} (the frame's
    /// size was checked when it was made).
    pub fn render(
        &mut self,
        scene: Scene<'_>,
        view: View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
    ) -> Result<RenderReport, ViewError> {
        self.render_inner(scene, view, opts, frame, None)
    }

    /// [`Renderer::render`], then `hook` on every band of rows of the frame (see
    /// [`BandHook`]): the LUT renderer's bilinear and nearest frames call it on each band
    /// as soon as its rows are drawn, while they are in cache (so a pass over the frame
    /// after the render, such as lighting it, costs no second trip through memory); the
    /// other renderers draw the whole frame first. The pixels are the same either way.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_with(
        &mut self,
        scene: Scene<'_>,
        view: View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
        hook: BandHook<'_>,
    ) -> Result<RenderReport, ViewError> {
        self.render_inner(scene, view, opts, frame, Some(hook))
    }

    fn render_inner(
        &mut self,
        scene: Scene<'_>,
        view: View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
        hook: Option<BandHook<'_>>,
    ) -> Result<RenderReport, ViewError> {
        let report = self.render_fused(scene, view, opts, frame, hook)?;
        if let (Some(hook), false) = (hook, report.1) {
            let w = frame.width() as usize;
            post_bands(frame.pixels_mut(), w, HOOK_BAND_ROWS, opts.threads, hook);
        }
        Ok(report.0)
    }

    /// The frame, and whether `hook` ran on it already (fused into the row bands).
    fn render_fused(
        &mut self,
        scene: Scene<'_>,
        view: View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
        hook: Option<BandHook<'_>>,
    ) -> Result<(RenderReport, bool), ViewError> {
        check_step(opts.index_step)?;
        let (width, height) = (frame.width(), frame.height());
        let pixels = width as u64 * height as u64;
        let map = match scene {
            Scene::Map(map) => map,
            Scene::Cube(cube) if !view.projection().is_rectilinear() => {
                projected::render_cube(cube, view, opts.sampler, frame, opts.threads);
                let report = RenderReport {
                    path: RenderPath::CubeProjected,
                    exact_pixels: 0,
                    pixels,
                    table_bytes: cube.bytes(),
                    max_step: 1,
                    min_step: 1,
                };
                return Ok((report, false));
            }
            Scene::Cube(cube) => {
                render_cube(cube, view, opts.sampler, opts.cube, frame, opts.threads);
                let report = RenderReport {
                    path: RenderPath::Cube(opts.cube),
                    exact_pixels: 0,
                    pixels,
                    table_bytes: cube.bytes(),
                    max_step: 1,
                    min_step: 1,
                };
                return Ok((report, false));
            }
        };
        if let Some(level) = self.level_map(map, view, opts.sampler, (width, height)) {
            // A frame drawn from a pyramid level (`set_bilinear_level`, `set_still_level`):
            // a plain frame of the level, with tables for its geometry, as the level
            // would be drawn were it the map (the exact renderer's too).
            let r = self
                .level
                .get_or_insert_with(|| Box::new(Renderer::new(level)));
            return r.render_fused(Scene::Map(level), view, opts, frame, hook);
        }
        if opts.renderer == RendererKind::Exact {
            render_exact(map, view, opts.sampler, frame, opts.threads);
            return Ok((RenderReport::exact(pixels), false));
        }
        self.set_geometry(map.width(), map.height(), map.projection());
        if uses_grid(view, opts) {
            return Ok((self.render_grid(map, view, opts, frame), false));
        }
        let (setup, report) = self.prepare_frame(view, opts, width, height);
        let table = find(&self.tables, opts.surface, Self::table_kind(view, opts));
        let scans = &self.scans;
        let row_scale = &self.row_scale[..];
        let w = width as usize;
        let out = frame.pixels_mut();
        let bilinear = opts.sampler != Sampler::Nearest;
        if opts.sampler == Sampler::Trilinear {
            // The pyramid is built here once, before the rows run in parallel.
            let (levels, n) = level_texels(map);
            let levels = &levels[..n];
            let fp = ExactFootprint::new(view, width, height, geometry_of(map));
            let row = |scratch: &mut ScratchLoan, y: usize, row: &mut [u32]| {
                let scan = &scans[y];
                let mut s = TriSink {
                    row,
                    map,
                    levels,
                    fy: scan.fy,
                    lod: 0,
                    exact: (&fp, y),
                    batch: Batch::new(),
                };
                s.set_lod(lod_q8(scan.fy[0] as f64));
                tri_row((scan, table, &setup, row_scale), scratch, &mut s);
            };
            return Ok(match hook {
                Some(post) => {
                    let (b, t) = (HOOK_BAND_ROWS, opts.threads);
                    for_each_band_init(out, w, b, t, RowScratch::loan, row, post);
                    (report, true)
                }
                None => {
                    for_each_row_init(out, w, opts.threads, RowScratch::loan, row);
                    (report, false)
                }
            });
        }
        // One monomorphized kernel per (sampler, partial map): no per-pixel dispatch.
        // `hook` runs on each band of rows as soon as it is drawn.
        fn rows<const BILINEAR: bool, const CROP: bool>(
            out: &mut [u32],
            w: usize,
            threads: bool,
            k: (&[Scan], &LutTable, &Setup, &[i64]),
            map: &EnvMap,
            hook: Option<BandHook<'_>>,
        ) {
            let (scans, table, setup, row_scale) = k;
            let t = texels(map);
            let row = |scratch: &mut ScratchLoan, y: usize, row: &mut [u32]| {
                let lut = (&scans[y], table, setup, row_scale);
                pixel_row::<BILINEAR, CROP>(lut, scratch, (map, &t), row);
            };
            match hook {
                Some(post) => {
                    for_each_band_init(out, w, HOOK_BAND_ROWS, threads, RowScratch::loan, row, post)
                }
                None => for_each_row_init(out, w, threads, RowScratch::loan, row),
            }
        }
        let k = (&scans[..], table, &setup, row_scale);
        let t = opts.threads;
        match (bilinear, map.crop().is_some()) {
            (true, false) => rows::<true, false>(out, w, t, k, map, hook),
            (false, false) => rows::<false, false>(out, w, t, k, map, hook),
            (true, true) => rows::<true, true>(out, w, t, k, map, hook),
            (false, true) => rows::<false, true>(out, w, t, k, map, hook),
        }
        Ok((report, hook.is_some()))
    }

    /// The grid renderer's frame (see `grid.rs`): pixels through the sinks of the
    /// sampler (and partial map), as the LUT path.
    fn render_grid(
        &self,
        map: &EnvMap,
        view: View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
    ) -> RenderReport {
        let (width, height) = (frame.width(), frame.height());
        let geometry = geometry_of(map);
        let setup = Setup::new(width, geometry, 0.0);
        let grid = Grid::new(view, width, height, &setup, &self.row_scale);
        let out = frame.pixels_mut();
        let t = opts.threads;
        fn px<R: RowSinks<Px = u32>>(g: &Grid, out: &mut [u32], r: &R, t: bool) -> GridStats {
            g.render(out, r, t, false)
        }
        let stats = if opts.sampler == Sampler::Trilinear {
            let (levels, n) = level_texels(map); // builds the pyramid
            let exact = ExactFootprint::new(view, width, height, geometry);
            let rows = TriRows {
                map,
                levels: &levels[..n],
                exact: &exact,
            };
            grid.render(out, &rows, t, true)
        } else {
            match (opts.sampler != Sampler::Nearest, map.crop().is_some()) {
                (true, false) => px(&grid, out, &PixelRows::<true, false> { map }, t),
                (false, false) => px(&grid, out, &PixelRows::<false, false> { map }, t),
                (true, true) => px(&grid, out, &PixelRows::<true, true> { map }, t),
                (false, true) => px(&grid, out, &PixelRows::<false, true> { map }, t),
            }
        };
        grid_report(stats, width, height)
    }

    /// Build the grid renderer's cells for `view` of a `map_w × map_h` map in
    /// `projection` on a `width × height` output without drawing them: the per-view part
    /// of a grid frame alone (its cost is inside every grid frame; `viewer bench` times
    /// it). The report counts the exact pixels and the cell sizes as a grid frame's does.
    ///
    /// # Errors
    /// [`ViewError::BadSize`] for a bad output size.
    #[allow(clippy::too_many_arguments)]
    pub fn build_grid(
        &mut self,
        map_w: u32,
        map_h: u32,
        projection: Projection,
        view: View,
        width: u32,
        height: u32,
        threads: bool,
    ) -> Result<RenderReport, ViewError> {
        check_size(width, height)?;
        self.set_geometry(map_w, map_h, projection);
        let setup = Setup::new(width, (map_w, map_h, projection), 0.0);
        let grid = Grid::new(view, width, height, &setup, &self.row_scale);
        Ok(grid_report(grid.build(threads), width, height))
    }

    /// The map positions the renderer `opts` selects samples for `view` (row-major,
    /// `None` = background): the same kernels as [`Renderer::render`] (the LUT's or the
    /// grid's), writing positions instead of pixels; the exact positions for the exact
    /// renderer. Used to measure the sampling-position error against the exact map.
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
        let pixels = width as u64 * height as u64;
        let mut out = vec![None; pixels as usize];
        if opts.renderer == RendererKind::Exact {
            let cam = Camera::new(view, width, height);
            let (mw, mh) = (map_w as f64, map_h as f64);
            for_each_row(&mut out, width as usize, opts.threads, |y, row| {
                for (x, p) in row.iter_mut().enumerate() {
                    *p = exact_uv(&cam, projection, mw, mh, x as u32, y as u32);
                }
            });
            return Ok((out, RenderReport::exact(pixels)));
        }
        if uses_grid(view, opts) {
            let setup = Setup::new(width, (map_w, map_h, projection), 0.0);
            let grid = Grid::new(view, width, height, &setup, &self.row_scale);
            let stats = grid.render(&mut out, &PosRows, opts.threads, false);
            return Ok((out, grid_report(stats, width, height)));
        }
        let (setup, report) = self.prepare_frame(view, opts, width, height);
        let table = find(&self.tables, opts.surface, Self::table_kind(view, opts));
        let scans = &self.scans;
        let row_scale = &self.row_scale[..];
        // The pixels' path: the row pass on full maps.
        let pass = rowpass::applies(&setup);
        let wq = (map_w as i32) << 8;
        for_each_row_init(
            &mut out,
            width as usize,
            opts.threads,
            RowScratch::loan,
            |scratch, y, row| {
                let lut = (&scans[y], table, &setup, row_scale);
                position_row(lut, scratch, pass.then_some(wq), row);
            },
        );
        Ok((out, report))
    }
}

/// The map geometry the renderers use: (width, height, projection) of the full panorama.
/// The pyramid level a bilinear frame on the level reads for a footprint of `centre`
/// map pixels per screen pixel at the view's centre, on a `w × h` map
/// ([`Renderer::set_bilinear_level`]): the nearest level, k = ⌊log2(centre) + ½⌋, or the
/// deepest level above it whose sides divide the map's exactly (level k of a map with
/// sides divisible by 2^k is exactly the map at 1/2^k scale; see `map/pyramid.rs`).
/// Levels end at a side of 2, as the pyramid does.
pub(crate) fn frame_level(centre: f64, w: u32, h: u32) -> usize {
    // (NaN too.)
    if centre.partial_cmp(&std::f64::consts::SQRT_2) != Some(std::cmp::Ordering::Greater) {
        return 0;
    }
    let want = (centre.log2() + 0.5).floor().min(31.0) as u32;
    (1..=want)
        .take_while(|&k| exact_level(k, w, h))
        .last()
        .map_or(0, |k| k as usize)
}

/// Whether level `k` (1 ≤ k ≤ 31) of a `w × h` map is exactly the map at 1/2^k scale and
/// at least 2 pixels on its shorter side: the levels frames are drawn from
/// ([`frame_level`]).
fn exact_level(k: u32, w: u32, h: u32) -> bool {
    w.is_multiple_of(1 << k) && h.is_multiple_of(1 << k) && (w.min(h) >> k) >= 2
}

/// Build now what frames drawn from pyramid levels need, so that no frame waits for it
/// ([`Renderer::set_still_level`], [`Renderer::set_bilinear_level`]): `map`'s pyramid and
/// the own pyramid of every level a frame can be drawn from (trilinear still frames of a
/// level read the level's pyramid; its levels equal the map's below it, so this holds
/// about a ninth of the map's bytes again: 0.22 GiB for a 32768×16384 map). The window
/// calls it on its loading thread. Partial maps (drawn from the map itself) build
/// nothing.
pub fn build_frame_levels(map: &EnvMap) {
    if map.crop().is_some() {
        return;
    }
    for (i, level) in map.pyramid().iter().enumerate() {
        let k = i as u32 + 1;
        if k > 31 || !exact_level(k, map.width(), map.height()) {
            break;
        }
        level.pyramid();
    }
}

/// The smallest footprint in a frame of `view` on `width × height` pixels of a map of
/// `geometry`, in map pixels per screen pixel ([`Renderer::set_still_level`]): the
/// minimum of the exact footprint (the larger of the map-pixel distances to the exact
/// positions one pixel right and one below, `ExactFootprint::footprint`) over a grid of
/// 17 × 9 points spanning the frame, corners and edges included (in a rectilinear view
/// the footprint is smallest at the edges, where the view's rays meet the sphere at a
/// slant). The centre is taken first: the minimum is at most the centre's footprint, so a
/// frame that is not zoomed out (centre at most √2) stops there and costs one
/// footprint. Points the map does not cover are skipped; with none covered, 0.
pub(crate) fn frame_min_footprint(
    view: View,
    width: u32,
    height: u32,
    geometry: (u32, u32, Projection),
) -> f64 {
    let fp = ExactFootprint::new(view, width, height, geometry);
    let at = |x: f64, y: f64| -> Option<f64> {
        let uv = exact_uv_at(&fp.cam, fp.proj, fp.mw, fp.mh, x, y)?;
        let f = fp.footprint(x, y, uv);
        f.is_finite().then_some(f)
    };
    let (w, h) = (width as f64, height as f64);
    let centre = at(w * 0.5, h * 0.5);
    if centre.is_some_and(|c| c <= std::f64::consts::SQRT_2) {
        return centre.unwrap_or(0.0);
    }
    const NX: u32 = 17;
    const NY: u32 = 9;
    // Pixel centres from the first to the last, in NX × NY steps.
    let x_at = |i: u32| 0.5 + (w - 1.0) * i as f64 / (NX - 1) as f64;
    let y_at = |j: u32| 0.5 + (h - 1.0) * j as f64 / (NY - 1) as f64;
    (0..NY)
        .flat_map(|j| (0..NX).map(move |i| (i, j)))
        .filter_map(|(i, j)| at(x_at(i), y_at(j)))
        .chain(centre)
        .reduce(f64::min)
        .unwrap_or(0.0)
}

fn geometry_of(map: &EnvMap) -> (u32, u32, Projection) {
    (map.width(), map.height(), map.projection())
}

/// True when the grid draws a map frame: asked for, or a view the table cannot draw.
fn uses_grid(view: View, opts: &RenderOptions) -> bool {
    opts.renderer == RendererKind::Grid
        || (opts.renderer == RendererKind::Lut && !view.projection().is_rectilinear())
}

/// The report of a grid frame.
fn grid_report(stats: GridStats, width: u32, height: u32) -> RenderReport {
    RenderReport {
        path: RenderPath::Grid,
        exact_pixels: stats.exact_pixels,
        pixels: width as u64 * height as u64,
        table_bytes: 0,
        max_step: stats.max_cell,
        min_step: stats.min_cell,
    }
}

#[cfg(test)]
mod tests {
    use super::{frame_level, frame_min_footprint};
    use crate::geom::camera::View;
    use crate::geom::mapping::exact_uv_at;
    use crate::geom::projection::Projection;
    use crate::render::exact::ExactFootprint;

    /// The smallest footprint of a frame, sampled on 17 × 9 points, against the minimum
    /// over every pixel centre of the frame: never more than 3 % above it (the samples
    /// include the corners and edges, where a rectilinear view's footprint is smallest)
    /// and at most 2 % below (the samples are not all pixel centres), on views at the
    /// horizon, tilted, near a pole, across the seam and wide; and the level chosen from
    /// it is the one the brute-force minimum gives.
    #[test]
    fn frame_min_footprint_is_the_frames_smallest() {
        let geometry = (2048, 1024, Projection::Equirect);
        for (yaw, pitch, hfov, w, h) in [
            (10.0, 0.0, 90.0, 64, 48),
            (0.0, 45.0, 100.0, 96, 64),
            (30.0, 80.0, 90.0, 80, 60),
            (180.0, -30.0, 120.0, 97, 41),
            (0.0, 0.0, 150.0, 128, 64),
            (0.0, 0.0, 60.0, 1, 1),
        ] {
            let view = View::new(yaw, pitch, hfov).unwrap();
            let fp = ExactFootprint::new(view, w, h, geometry);
            let brute = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x as f64 + 0.5, y as f64 + 0.5)))
                .filter_map(|(x, y)| {
                    let uv = exact_uv_at(&fp.cam, fp.proj, fp.mw, fp.mh, x, y)?;
                    Some(fp.footprint(x, y, uv))
                })
                .fold(f64::INFINITY, f64::min);
            let got = frame_min_footprint(view, w, h, geometry);
            assert!(
                got <= brute * 1.03 && got >= brute * 0.98,
                "{yaw} {pitch} {hfov} {w}x{h}: sampled {got} against {brute}"
            );
            assert_eq!(
                frame_level(got, 2048, 1024),
                frame_level(brute, 2048, 1024),
                "{yaw} {pitch} {hfov}: {got} against {brute}"
            );
        }
        // Not zoomed out: the centre's footprint, at most √2, without the grid.
        let view = View::new(0.0, 0.0, 20.0).unwrap();
        assert!(frame_min_footprint(view, 160, 120, geometry) <= std::f64::consts::SQRT_2);
    }

    /// `build_frame_levels` builds the map's pyramid and the own pyramid of exactly the
    /// levels frames can be drawn from: 48×24 divides down to level 3 (6×3), not 4.
    #[test]
    fn build_frame_levels_builds_the_levels_frames_use() {
        let px: Vec<u32> = (0..48 * 24u32)
            .map(|i| i.wrapping_mul(2654435761))
            .collect();
        let map = crate::EnvMap::from_pixels(48, 24, &px, Projection::Equirect).unwrap();
        super::build_frame_levels(&map);
        let levels = map.pyramid();
        assert!(levels.len() > 3);
        let built: Vec<bool> = levels.iter().map(|l| l.pyramid_bytes() > 0).collect();
        assert!(built[..3].iter().all(|&b| b), "{built:?}");
        assert!(built[3..].iter().all(|&b| !b), "{built:?}");
    }

    /// The level of a bilinear frame on the level: the nearest power of two to the
    /// centre's footprint, among the levels that divide the map's sides.
    #[test]
    fn frame_level_is_the_nearest_level_that_divides_the_map() {
        let (w, h) = (32768, 16384);
        // 1080p, hfov 90: 2 tan 45° / 1920 · W / 2π map pixels per screen pixel.
        let centre = |w: u32, hfov: f64| {
            2.0 * (hfov.to_radians() / 2.0).tan() / 1920.0 * w as f64 / std::f64::consts::TAU
        };
        assert_eq!(frame_level(centre(w, 90.0), w, h), 2); // 5.43: the 8192-wide level
        assert_eq!(frame_level(centre(w, 120.0), w, h), 3); // 9.41: the 4096-wide level
        assert_eq!(frame_level(centre(16384, 90.0), 16384, 8192), 1); // 2.72
        assert_eq!(frame_level(centre(8192, 90.0), 8192, 4096), 0); // 1.36: the map
        assert_eq!(frame_level(centre(8192, 120.0), 8192, 4096), 1); // 2.35
                                                                     // The boundaries: √2 and 2√2.
        for (fp, k) in [
            (0.3, 0),
            (1.41, 0),
            (1.42, 1),
            (2.82, 1),
            (2.83, 2),
            (1e9, 13),
        ] {
            assert_eq!(frame_level(fp, w, h), k, "footprint {fp}");
        }
        assert_eq!(frame_level(f64::NAN, w, h), 0);
        // Levels that do not divide the map are skipped: 6000x3000 divides down to level
        // 3 (750x375); 6002x3001 only level 0.
        assert_eq!(frame_level(40.0, 6000, 3000), 3);
        assert_eq!(frame_level(40.0, 6002, 3001), 0);
        // Never below a side of 2.
        assert_eq!(frame_level(1e6, 64, 32), 4);
    }
}

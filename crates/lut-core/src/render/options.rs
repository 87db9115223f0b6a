//! What a frame is asked for and what it reports: the
//! [`RenderOptions`] and their named values, the [`RenderReport`], and the band hook's
//! types.

use crate::lut::Surface;
use crate::map::sample::Sampler;
use crate::named::Named;
use crate::render::cube::CubeRenderer;
#[cfg(doc)]
use crate::render::Renderer;

/// hfov (degrees) above which the wide-FOV table is used (the patent's 60°).
pub const LUT_SWITCH_HFOV: f64 = 60.0;

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
    /// The cube renderer, for a cube map (both give the same pixels).
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
    /// A tiled pyramid, drawn at `level` (1 = coarsest); `coarser`: some tiles were not
    /// decoded yet and were drawn from a coarser level.
    Tiles {
        /// The level the frame wanted.
        level: u32,
        /// Part of the frame was drawn coarser than wanted.
        coarser: bool,
    },
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
            RenderPath::Tiles { coarser: false, .. } => "tiles",
            RenderPath::Tiles { coarser: true, .. } => "tiles-coarser",
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
    pub(crate) fn exact(pixels: u64) -> RenderReport {
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

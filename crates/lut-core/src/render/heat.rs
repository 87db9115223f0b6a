//! The live error heat map: per output pixel, the sampling-position error of the renderer
//! in use against the exact map (source pixels, the angular metric of
//! [`crate::position_error`]), on a logarithmic colour scale from [`HEAT_MIN`] to
//! [`HEAT_MAX`] pixels. A diagnostic: it costs about one exact render (the exact position
//! of every pixel) plus the renderer's positions.

use super::{MapGeometry, RenderOptions, Renderer};
use crate::error::ViewError;
use crate::geom::accuracy::{position_errors, ErrorStats};
use crate::geom::camera::{check_size, Camera, View};
use crate::map::envmap::EnvMap;

/// The error shown at the bottom of the scale (and below it), source pixels.
pub const HEAT_MIN: f64 = 0.001;
/// The error shown at the top of the scale (and above it), source pixels.
pub const HEAT_MAX: f64 = 1.0;
/// The colour of pixels with no map position (background), 0RGB.
pub const HEAT_BACKGROUND: u32 = 0x0040_4040;
/// The colour of pixels where one of the renderer and the exact map shows the
/// background and the other does not (a coverage mismatch), 0RGB.
pub const HEAT_MISMATCH: u32 = 0x00FF_00FF;

/// Stops of the colour scale, evenly spaced in log10(error) from [`HEAT_MIN`] to
/// [`HEAT_MAX`]: dark blue, blue, cyan, green, yellow, orange, red, dark red (after
/// the "turbo" map, so equal steps of the logarithm look like equal steps).
const STOPS: [u32; 8] = [
    0x30_12_3B, 0x45_6B_E3, 0x1A_E4_B6, 0x72_FE_5E, 0xC7_EF_34, 0xFA_BA_39, 0xE4_46_0A, 0x7A_04_03,
];

/// Position in [0, 1] of an error on the logarithmic scale (0 at [`HEAT_MIN`] and below,
/// 1 at [`HEAT_MAX`] and above).
pub fn heat_scale(error_px: f64) -> f64 {
    if error_px.is_nan() || error_px <= HEAT_MIN {
        return 0.0;
    }
    ((error_px.log10() - HEAT_MIN.log10()) / (HEAT_MAX.log10() - HEAT_MIN.log10())).min(1.0)
}

/// The heat map colour (0RGB) of a sampling-position error in source pixels.
pub fn heat_color(error_px: f64) -> u32 {
    let t = heat_scale(error_px) * (STOPS.len() - 1) as f64;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let ch = |s: u32| {
        let (x, y) = ((a >> s & 0xFF) as f64, (b >> s & 0xFF) as f64);
        ((x + (y - x) * f).round() as u32) << s
    };
    ch(16) | ch(8) | ch(0)
}

/// Per-pixel sampling-position errors of one frame and their summary.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorMap {
    /// Output width.
    pub width: u32,
    /// Output height.
    pub height: u32,
    /// Row-major: `Some(error)` in source pixels, `Some(∞)` for a coverage mismatch,
    /// `None` where both the renderer and the exact map show the background.
    pub errors: Vec<Option<f64>>,
    /// The summary: its `max` is the largest finite error of `errors`.
    pub stats: ErrorStats,
}

impl ErrorMap {
    /// The errors of the renderer `opts` selects for `view` of `map` on a
    /// `width × height` output: the renderer's sampling positions
    /// ([`Renderer::positions`], the same kernels as its frames) against the exact map;
    /// for a frame the renderer draws from a pyramid level ([`Renderer::set_still_level`],
    /// [`Renderer::set_bilinear_level`]) the level's positions against the exact level,
    /// in the level's pixels (the texels that frame reads). A panorama of any kind:
    /// [`crate::Panorama::error_map`].
    ///
    /// # Errors
    /// As [`Renderer::render`], and a bad output size.
    pub fn measure(
        renderer: &mut Renderer,
        map: &EnvMap,
        view: View,
        opts: &RenderOptions,
        width: u32,
        height: u32,
    ) -> Result<ErrorMap, ViewError> {
        check_size(width, height)?;
        if let Some((level, r)) = renderer.level_renderer(map, view, opts.sampler, width, height) {
            return ErrorMap::measure(r, level, view, opts, width, height);
        }
        let (mw, mh, p) = (map.width(), map.height(), map.projection());
        let (positions, _) = renderer.positions(MapGeometry::of(map), view, opts, width, height)?;
        let (errors, stats) = position_errors(&positions, view, width, height, p, mw, mh);
        Ok(ErrorMap {
            width,
            height,
            errors,
            stats,
        })
    }

    /// The error map of a renderer that computes every pixel's position exactly (the
    /// cube renderers): 0 wherever the view has a direction, none elsewhere.
    pub(crate) fn exact(view: View, width: u32, height: u32) -> ErrorMap {
        let cam = Camera::new(view, width, height);
        let errors: Vec<Option<f64>> = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| cam.pixel_lat_long(x, y).map(|_| 0.0))
            .collect();
        let stats = ErrorStats {
            count: errors.len() as u64,
            ..ErrorStats::default()
        };
        ErrorMap {
            width,
            height,
            errors,
            stats,
        }
    }

    /// The heat map image, 0RGB row-major: [`heat_color`] of each error,
    /// [`HEAT_BACKGROUND`] without a position, [`HEAT_MISMATCH`] for a mismatch.
    pub fn colors(&self) -> Vec<u32> {
        self.errors
            .iter()
            .map(|e| match e {
                None => HEAT_BACKGROUND,
                Some(e) if e.is_finite() => heat_color(*e),
                Some(_) => HEAT_MISMATCH,
            })
            .collect()
    }
}

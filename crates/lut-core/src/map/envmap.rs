//! Environment maps in memory: pixels and the projection that tells how to read them. No
//! files and no decoder types here (loading is `io/`); the samplers are `map/sample.rs`.
//!
//! Pixels are `u32` **0RGB** (`0x00RRGGBB`, softbuffer's format), 8-bit sRGB filtered as
//! stored. The map is kept with one extra column and one extra row of padding so the
//! bilinear sampler never branches on the right or bottom edge: column `W` repeats column
//! 0 for maps that wrap horizontally (column `W − 1` otherwise), and row `H` repeats row
//! `H − 1` (vertical clamp).

use crate::error::{MapError, SizeProblem};
use crate::geom::coverage::Crop;
use crate::geom::fixed::{Fx, FX_BITS};
use crate::geom::limits::{MAX_MAP_HEIGHT, MAX_MAP_PIXELS, MAX_MAP_WIDTH};
use crate::geom::projection::Projection;

/// An environment map: pixels plus the projection that tells how to read them.
#[derive(Clone)]
pub struct EnvMap {
    /// Stored width (the crop's width for a partial map).
    pub(crate) width: u32,
    /// Stored height.
    pub(crate) height: u32,
    pub(crate) projection: Projection,
    /// (width + 1) × (height + 1) pixels, row-major, padded as described in the module docs.
    data: Vec<u32>,
    pub(crate) background: u32,
    /// For a partial panorama: where the stored pixels sit in the full one (see
    /// `map/crop.rs`).
    pub(crate) crop: Option<Crop>,
    /// Compass heading of longitude 0 (GPano `PoseHeadingDegrees`).
    pub(crate) pose_heading: Option<f64>,
    /// The view the file asks to be opened at (GPano `InitialView*`).
    pub(crate) start_view: Option<crate::geom::coverage::StartView>,
    /// Minification pyramid levels 1.. (see `map/pyramid.rs`), built on first use.
    pub(crate) levels: std::sync::OnceLock<Vec<EnvMap>>,
    /// Elliptical and diamond maps: per row, the first and last pixel whose centre lies
    /// in the row's extent (the samplers wrap within it, see `map/sample.rs`).
    pub(crate) row_extent: Vec<(i64, i64)>,
}

impl std::fmt::Debug for EnvMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EnvMap")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("projection", &self.projection)
            .field("crop", &self.crop)
            .finish()
    }
}

/// Check map dimensions against the supported limits.
///
/// # Errors
/// [`MapError::Size`] naming `what`.
pub fn check_map_size(what: &str, width: u32, height: u32) -> Result<(), MapError> {
    let problem = if width == 0 || height == 0 {
        Some(SizeProblem::Empty)
    } else if width > MAX_MAP_WIDTH || height > MAX_MAP_HEIGHT {
        Some(SizeProblem::SidesAbove {
            max_width: MAX_MAP_WIDTH,
            max_height: MAX_MAP_HEIGHT,
        })
    } else if width as u64 * height as u64 > MAX_MAP_PIXELS {
        Some(SizeProblem::PixelsAbove {
            max: MAX_MAP_PIXELS,
        })
    } else if width < 2 || height < 2 {
        Some(SizeProblem::TooSmall)
    } else {
        None
    };
    match problem {
        Some(problem) => Err(MapError::Size {
            what: what.to_string(),
            width,
            height,
            problem,
        }),
        None => Ok(()),
    }
}

impl EnvMap {
    /// Build a map from row-major 0RGB pixels (`width × height`).
    ///
    /// # Errors
    /// [`MapError::Size`] for empty or oversized maps or a pixel count mismatch.
    pub fn from_pixels(
        width: u32,
        height: u32,
        pixels: &[u32],
        projection: Projection,
    ) -> Result<EnvMap, MapError> {
        check_map_size("pixel buffer", width, height)?;
        if pixels.len() != width as usize * height as usize {
            return Err(MapError::Size {
                what: "pixel buffer".into(),
                width,
                height,
                problem: SizeProblem::BufferLength { len: pixels.len() },
            });
        }
        let (w, h) = (width as usize, height as usize);
        let stride = w + 1;
        let mut data = vec![0u32; stride * (h + 1)];
        for y in 0..h {
            let src = &pixels[y * w..(y + 1) * w];
            let dst = &mut data[y * stride..(y + 1) * stride];
            dst[..w].copy_from_slice(src);
            dst[w] = if projection.wraps() {
                src[0]
            } else {
                src[w - 1]
            };
        }
        let (top, last) = data.split_at_mut(h * stride);
        last.copy_from_slice(&top[(h - 1) * stride..h * stride]);
        Ok(EnvMap::from_padded(width, height, projection, data))
    }

    /// A map from its padded buffer (`(width + 1) × (height + 1)`, padding filled).
    pub(crate) fn from_padded(
        width: u32,
        height: u32,
        projection: Projection,
        data: Vec<u32>,
    ) -> EnvMap {
        debug_assert_eq!(data.len(), (width as usize + 1) * (height as usize + 1));
        EnvMap {
            width,
            height,
            projection,
            data,
            background: 0,
            crop: None,
            pose_heading: None,
            start_view: None,
            levels: std::sync::OnceLock::new(),
            row_extent: row_extents(width, height, projection),
        }
    }

    /// A map like this one (size, projection, crop, background, pose, start view) holding
    /// `data` instead, a padded buffer of the same size with its padding filled; its
    /// pyramid is built on first use. (The lit copy of `light/bake.rs`.)
    pub(crate) fn with_padded(&self, data: Vec<u32>) -> EnvMap {
        debug_assert_eq!(data.len(), self.data.len());
        EnvMap {
            width: self.width,
            height: self.height,
            projection: self.projection,
            data,
            background: self.background,
            crop: self.crop,
            pose_heading: self.pose_heading,
            start_view: self.start_view,
            levels: std::sync::OnceLock::new(),
            row_extent: self.row_extent.clone(),
        }
    }

    /// Whether the padding column repeats column 0 (the stored pixels span 360°) rather
    /// than the last column.
    pub(crate) fn pads_by_wrapping(&self) -> bool {
        match self.crop {
            Some(c) => c.width() == c.full_width(),
            None => self.projection.wraps(),
        }
    }

    /// The padded pixel buffer, `(stored width + 1) × (stored height + 1)` row-major, and
    /// its stride (stored width + 1): what the span kernels read.
    #[inline(always)]
    pub(crate) fn padded(&self) -> (&[u32], usize) {
        (&self.data, self.width as usize + 1)
    }

    /// Width in pixels: the full panorama's width, which every renderer's geometry uses
    /// (for a partial map the stored pixels are narrower: [`EnvMap::crop`]).
    pub fn width(&self) -> u32 {
        self.crop.map_or(self.width, |c| c.full_width())
    }
    /// Height in pixels (the full panorama's, as [`EnvMap::width`]).
    pub fn height(&self) -> u32 {
        self.crop.map_or(self.height, |c| c.full_height())
    }
    /// The projection.
    pub fn projection(&self) -> Projection {
        self.projection
    }
    /// The color shown for directions the map does not cover (0RGB).
    pub fn background(&self) -> u32 {
        self.background
    }
    /// Set the background color (0RGB).
    pub fn set_background(&mut self, rgb: u32) {
        let rgb = rgb & 0x00FF_FFFF;
        // A partial map's pyramid levels hold the background where they cross the crop's
        // edge: built again (on first use) for a new one.
        if self.crop.is_some() && rgb != self.background {
            self.levels = std::sync::OnceLock::new();
        }
        self.background = rgb;
    }
    /// Memory held by the pixels, in bytes.
    pub fn bytes(&self) -> usize {
        self.data.len() * 4
    }

    /// Stored pixel (x, y), `x < W`, `y < H` (for a partial map: of the stored crop,
    /// `x <` [`EnvMap::stored_width`]).
    ///
    /// # Panics
    /// When (x, y) lies outside the stored pixels and their padding column and row.
    #[inline]
    pub fn pixel(&self, x: u32, y: u32) -> u32 {
        self.data[y as usize * (self.width as usize + 1) + x as usize]
    }

    /// True when (u, v) (Q.16) lies inside the map's vertical coverage. Only the cylinder
    /// can fail this; the full-sphere maps clamp.
    #[inline]
    pub fn covers(&self, v: Fx) -> bool {
        v >= 0 && v <= (self.height as i64) << FX_BITS
    }
}

/// The pixels of each row of an elliptical or diamond map that lie on the sphere: those
/// whose centre is within the row's extent `|u − W/2| ≤ s(φ)·W/2` (φ at the row's
/// centre), as [`Projection::direction`] has it. A row narrower than a pixel keeps its
/// centre pixel. Empty for the other projections.
fn row_extents(w: u32, h: u32, p: Projection) -> Vec<(i64, i64)> {
    if !p.scaled_rows() {
        return Vec::new();
    }
    let (wf, hf) = (w as f64, h as f64);
    (0..h)
        .map(|j| {
            let e = p.row_scale_at_v(j as f64 + 0.5, hf) * wf * 0.5;
            let lo = (wf * 0.5 - e - 0.5 - 1e-9).ceil().max(0.0) as i64;
            let hi = (wf * 0.5 + e - 0.5 + 1e-9).floor().min(wf - 1.0) as i64;
            if lo <= hi {
                (lo, hi)
            } else {
                let c = (w as i64 / 2).min(w as i64 - 1);
                (c, c)
            }
        })
        .collect()
}

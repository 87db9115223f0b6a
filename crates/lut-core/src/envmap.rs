//! Environment maps in memory, and the nearest / bilinear samplers every renderer shares.
//!
//! Pixels are `u32` **0RGB** (`0x00RRGGBB`, softbuffer's format), 8-bit sRGB filtered as
//! stored. The map is kept with one extra column and one extra row of padding so the
//! bilinear sampler never branches on the right or bottom edge: column `W` repeats column
//! 0 for maps that wrap horizontally (column `W − 1` otherwise), and row `H` repeats row
//! `H − 1` (vertical clamp).

use crate::error::MapError;
use crate::fixed::{Fx, FX_BITS, FX_HALF};
use crate::projection::Projection;
use crate::simd::SpanJob;
use std::path::Path;

/// Largest accepted map side. 65536 wide is the widest map whose fixed-point path is
/// tested (see `tests/stability.rs`); the table format allows up to 131068.
pub const MAX_MAP_WIDTH: u32 = 65536;
/// Largest accepted map height.
pub const MAX_MAP_HEIGHT: u32 = 65536;
/// Largest accepted pixel count of a map (32768 × 16384 × 2).
pub const MAX_MAP_PIXELS: u64 = 1 << 30;

/// Pixel interpolation (the patent's FIG. 10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Sampler {
    /// The source pixel containing (u, v).
    Nearest,
    /// The four pixel centers around (u − ½, v − ½), weighted by the fractions.
    Bilinear,
    /// Bilinear on the two pyramid levels around the pixel footprint, blended
    /// (minification anti-aliasing, see [`crate::pyramid`]). Where no footprint is known
    /// (single samples, cube maps, partial maps) it is bilinear.
    Trilinear,
}

impl Sampler {
    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Sampler::Nearest => "nearest",
            Sampler::Bilinear => "bilinear",
            Sampler::Trilinear => "trilinear",
        }
    }
}

impl std::str::FromStr for Sampler {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "nearest" => Ok(Sampler::Nearest),
            "bilinear" => Ok(Sampler::Bilinear),
            "trilinear" => Ok(Sampler::Trilinear),
            o => Err(format!(
                "unknown sampler '{o}' (expected nearest, bilinear or trilinear)"
            )),
        }
    }
}

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
    /// [`crate::coverage`]).
    pub(crate) crop: Option<crate::coverage::Crop>,
    /// Compass heading of longitude 0 (GPano `PoseHeadingDegrees`).
    pub(crate) pose_heading: Option<f64>,
    /// Minification pyramid levels 1.. (see [`crate::pyramid`]), built on first use.
    pub(crate) levels: std::sync::OnceLock<Vec<EnvMap>>,
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
    let reason = if width == 0 || height == 0 {
        Some("the image is empty".to_string())
    } else if width > MAX_MAP_WIDTH || height > MAX_MAP_HEIGHT {
        Some(format!(
            "sides above {MAX_MAP_WIDTH}x{MAX_MAP_HEIGHT} are not supported"
        ))
    } else if width as u64 * height as u64 > MAX_MAP_PIXELS {
        Some(format!("more than {MAX_MAP_PIXELS} pixels"))
    } else if width < 2 || height < 2 {
        Some("a map needs at least 2x2 pixels".to_string())
    } else {
        None
    };
    match reason {
        Some(reason) => Err(MapError::Size {
            what: what.to_string(),
            width,
            height,
            reason,
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
                reason: format!("buffer holds {} pixels", pixels.len()),
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

    /// Build a map from a decoded image (any colour type; converted to 8-bit RGB; HDR
    /// images through the default [`Tone`]).
    ///
    /// # Errors
    /// As [`EnvMap::from_pixels`].
    pub fn from_image(
        img: &image::DynamicImage,
        projection: Projection,
    ) -> Result<EnvMap, MapError> {
        Self::from_image_toned(img, projection, Tone::default())
    }

    /// As [`EnvMap::from_image`], with HDR (floating-point) images shown through `tone`:
    /// exposure, the tone curve `x / (1 + x)`, then sRGB encoding. Negative and NaN values
    /// are clamped to 0 (and +∞ to white), never propagated. 8-bit images are used as
    /// stored.
    ///
    /// # Errors
    /// As [`EnvMap::from_pixels`].
    pub fn from_image_toned(
        img: &image::DynamicImage,
        projection: Projection,
        tone: Tone,
    ) -> Result<EnvMap, MapError> {
        crate::load::image_to_map("image", img, projection, tone, &mut |_| {})
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
            levels: std::sync::OnceLock::new(),
        }
    }

    /// The padded pixel buffer (for tests comparing two load paths).
    #[cfg(test)]
    pub(crate) fn raw(&self) -> &[u32] {
        &self.data
    }

    /// Decode an image file (format from its contents) and check it can be the given
    /// projection. `None` means *auto*: a 2:1 image is equirectangular, anything else is
    /// an error asking for an explicit projection.
    ///
    /// The pixel limit ([`crate::load::DEFAULT_MAX_PIXELS`]) is checked from the header
    /// before the image is decoded; [`EnvMap::load_with`] takes another limit and reports
    /// progress.
    ///
    /// # Errors
    /// [`MapError`] naming the file and the reason.
    pub fn load(path: &Path, projection: Option<Projection>) -> Result<EnvMap, MapError> {
        let opts = crate::load::LoadOptions {
            projection,
            ..Default::default()
        };
        Self::load_with(path, &opts, &mut |_| {})
    }

    /// As [`EnvMap::load`] for an in-memory encoded image; `what` names it in errors.
    ///
    /// # Errors
    /// [`MapError`] naming `what` and the reason.
    pub fn decode(
        bytes: &[u8],
        what: &str,
        projection: Option<Projection>,
    ) -> Result<EnvMap, MapError> {
        Self::decode_toned(bytes, what, projection, Tone::default())
    }

    /// As [`EnvMap::decode`], showing HDR images through `tone` (see
    /// [`EnvMap::from_image_toned`]).
    ///
    /// # Errors
    /// [`MapError`] naming `what` and the reason.
    pub fn decode_toned(
        bytes: &[u8],
        what: &str,
        projection: Option<Projection>,
        tone: Tone,
    ) -> Result<EnvMap, MapError> {
        let opts = crate::load::LoadOptions {
            projection,
            tone,
            ..Default::default()
        };
        Self::decode_with(bytes, what, &opts, &mut |_| {})
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
        self.background = rgb & 0x00FF_FFFF;
    }
    /// Memory held by the pixels, in bytes.
    pub fn bytes(&self) -> usize {
        self.data.len() * 4
    }

    /// Stored pixel (x, y), `x < W`, `y < H` (for a partial map: of the stored crop,
    /// `x <` [`EnvMap::stored_width`]).
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

    /// Sample at (u, v) (Q.16 map coordinates; u is expected in [0, W) for wrapping maps
    /// and is clamped otherwise). For a partial map, (u, v) are full-panorama
    /// coordinates and uncovered positions give the background.
    #[inline(always)]
    pub fn sample(&self, sampler: Sampler, u: Fx, v: Fx) -> u32 {
        if self.crop.is_some() {
            return self.sample_cropped(sampler, u, v);
        }
        match sampler {
            Sampler::Nearest => self.nearest(u, v),
            Sampler::Bilinear | Sampler::Trilinear => self.bilinear(u, v),
        }
    }

    /// Sample a run of positions stepping linearly: `out[i]` = the `BILINEAR` (else
    /// nearest) sample at (u + i·du, v + i·dv). Identical to calling [`EnvMap::bilinear`]
    /// / [`EnvMap::nearest`] per pixel with u wrapped into [0, W) for 360° maps.
    ///
    /// This is the LUT renderer's inner loop. When the whole run stays inside the map
    /// (after one wrap of its start), it runs the span kernel ([`crate::Kernel`]: no clamps,
    /// no wrap tests, SIMD where the CPU has it). Otherwise it falls back to the per-pixel
    /// functions.
    #[inline]
    pub fn sample_span<const BILINEAR: bool>(&self, out: &mut [u32], u: Fx, v: Fx, du: Fx, dv: Fx) {
        let t = self.texels();
        let done = if BILINEAR {
            crate::simd::bilinear_span(&t, out, u, v, du, dv)
        } else {
            crate::simd::nearest_span(&t, out, u, v, du, dv)
        };
        if !done {
            self.sample_span_slow::<BILINEAR>(out, u, v, du, dv);
        }
    }

    /// [`EnvMap::sample_span`] for a batch of spans of one output row (at most
    /// [`crate::MAX_JOBS`]): one kernel call for them all; spans leaving the map are
    /// sampled per pixel.
    pub(crate) fn sample_spans<const BILINEAR: bool>(&self, row: &mut [u32], jobs: &[SpanJob]) {
        let t = self.texels();
        let mut refused = if BILINEAR {
            crate::simd::bilinear_spans(&t, row, jobs)
        } else {
            crate::simd::nearest_spans(&t, row, jobs)
        };
        while refused != 0 {
            let j = &jobs[refused.trailing_zeros() as usize];
            refused &= refused - 1;
            let (x, n) = (j.x as usize, j.len as usize);
            self.sample_span_slow::<BILINEAR>(&mut row[x..x + n], j.u, j.v, j.du, j.dv);
        }
    }

    /// The stored pixels as the span kernels read them.
    #[inline]
    pub(crate) fn texels(&self) -> crate::simd::Texels<'_> {
        // A partial map's stored pixels wrap only when the crop spans 360°.
        let wraps = self
            .crop
            .map_or(self.projection.wraps(), |c| c.width() == c.full_width());
        crate::simd::Texels::new(&self.data, self.width, self.height, wraps)
            .expect("a map holds (width + 1) x (height + 1) pixels, fewer than 2^31")
    }

    #[inline(never)]
    fn sample_span_slow<const BILINEAR: bool>(
        &self,
        out: &mut [u32],
        mut u: Fx,
        mut v: Fx,
        du: Fx,
        dv: Fx,
    ) {
        let wfx = (self.width as i64) << FX_BITS;
        let wraps = self.projection.wraps();
        for o in out.iter_mut() {
            let uu = if wraps { u.rem_euclid(wfx) } else { u };
            *o = if BILINEAR {
                self.bilinear(uu, v)
            } else {
                self.nearest(uu, v)
            };
            u += du;
            v += dv;
        }
    }

    /// Nearest: the pixel containing (u, v), clamped into the image. (u, v) are stored
    /// coordinates: for a partial map use [`EnvMap::nearest_cropped`].
    #[inline(always)]
    pub fn nearest(&self, u: Fx, v: Fx) -> u32 {
        let w = self.width as i64;
        let h = self.height as i64;
        let x = (u >> FX_BITS).clamp(0, w - 1);
        let y = (v >> FX_BITS).clamp(0, h - 1);
        self.data[y as usize * (w as usize + 1) + x as usize]
    }

    /// Bilinear over the four pixel centers around (u − ½, v − ½), 8-bit weights;
    /// wraps in u for 360° maps, clamps otherwise and in v. (u, v) are stored
    /// coordinates: for a partial map use [`EnvMap::bilinear_cropped`].
    #[inline(always)]
    pub fn bilinear(&self, u: Fx, v: Fx) -> u32 {
        let w = self.width as i64;
        let h = self.height as i64;
        let uu = u - FX_HALF;
        let vv = v - FX_HALF;
        let mut x0 = uu >> FX_BITS;
        let mut fx = ((uu >> (FX_BITS - 8)) & 0xFF) as u32;
        let mut y0 = vv >> FX_BITS;
        let mut fy = ((vv >> (FX_BITS - 8)) & 0xFF) as u32;
        if x0 < 0 {
            if self.projection.wraps() && x0 == -1 {
                x0 = w - 1; // column W (padding) is column 0
            } else {
                x0 = 0;
                fx = 0;
            }
        } else if x0 >= w {
            if self.projection.wraps() && x0 == w {
                x0 = 0;
            } else {
                x0 = w - 1;
                fx = 0;
            }
        }
        if y0 < 0 {
            y0 = 0;
            fy = 0;
        } else if y0 >= h - 1 {
            y0 = h - 1; // row H (padding) repeats row H-1
            fy = 0;
        }
        let stride = w as usize + 1;
        let i = y0 as usize * stride + x0 as usize;
        let row0 = &self.data[i..i + 2];
        let row1 = &self.data[i + stride..i + stride + 2];
        let top = lerp_px(row0[0], row0[1], fx);
        let bot = lerp_px(row1[0], row1[1], fx);
        lerp_px(top, bot, fy)
    }
}

/// How HDR (floating-point) images become 8-bit display pixels.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tone {
    /// Exposure in stops: linear values are multiplied by 2^EV before the tone curve.
    pub exposure_ev: f64,
}

/// One linear HDR value → 8-bit sRGB: clamp (negative, NaN → 0; +∞ → 1), the curve
/// x/(1+x), then the sRGB transfer function.
#[inline]
pub fn tone_map(x: f32) -> u8 {
    let y = if x.is_nan() || x <= 0.0 {
        0.0
    } else if x.is_infinite() {
        1.0
    } else {
        x / (1.0 + x)
    };
    let s = if y <= 0.003_130_8 {
        12.92 * y
    } else {
        1.055 * y.powf(1.0 / 2.4) - 0.055
    };
    (s.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// Pick the projection for an image: explicit, or auto (2:1 → equirect, else an error).
///
/// # Errors
/// [`MapError::Projection`] when auto cannot decide or an equirect is not 2:1.
pub fn resolve_projection(
    what: &str,
    w: u32,
    h: u32,
    projection: Option<Projection>,
) -> Result<Projection, MapError> {
    match projection {
        Some(Projection::Equirect) | None if w != 2 * h => Err(MapError::Projection {
            what: what.into(),
            reason: if projection.is_none() {
                format!(
                    "image is {w}x{h}, not 2:1, so it is not taken as equirectangular; \
                     give --projection cylinder|sine|elliptical|diamond"
                )
            } else {
                format!("an equirectangular map must be 2:1, this image is {w}x{h}")
            },
        }),
        None => Ok(Projection::Equirect),
        Some(p) => Ok(p),
    }
}

/// Blend two 0RGB pixels: `a · (256 − w) + b · w`, rounded, two channels per multiply.
#[inline(always)]
pub fn lerp_px(a: u32, b: u32, w: u32) -> u32 {
    let iw = 256 - w;
    let rb = (((a & 0x00FF_00FF) * iw + (b & 0x00FF_00FF) * w + 0x0080_0080) >> 8) & 0x00FF_00FF;
    let g = (((a & 0x0000_FF00) * iw + (b & 0x0000_FF00) * w + 0x0000_8000) >> 8) & 0x0000_FF00;
    rb | g
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::to_fx;

    fn ramp(w: u32, h: u32, p: Projection) -> EnvMap {
        let px: Vec<u32> = (0..w * h).map(|i| (i % w) << 16 | (i / w) << 8).collect();
        EnvMap::from_pixels(w, h, &px, p).unwrap()
    }

    #[test]
    fn lerp_endpoints_and_middle() {
        assert_eq!(lerp_px(0x102030, 0x405060, 0), 0x102030);
        assert_eq!(lerp_px(0x000000, 0xFFFFFF, 128), 0x808080);
        assert_eq!(lerp_px(0xFFFFFF, 0xFFFFFF, 255), 0xFFFFFF);
    }

    #[test]
    fn bilinear_at_centers_is_the_pixel() {
        let m = ramp(16, 8, Projection::Equirect);
        for (x, y) in [(0, 0), (15, 7), (3, 4)] {
            let s = m.bilinear(to_fx(x as f64 + 0.5), to_fx(y as f64 + 0.5));
            assert_eq!(s, m.pixel(x, y));
        }
    }

    #[test]
    fn bilinear_wraps_horizontally() {
        let m = ramp(16, 8, Projection::Equirect);
        // halfway between column 15 and column 0
        let s = m.bilinear(to_fx(16.0), to_fx(2.5));
        assert_eq!(s >> 16, 8); // (15*128 + 0*128 + 128) >> 8 = 8
        let s0 = m.bilinear(to_fx(0.0), to_fx(2.5));
        assert_eq!(s, s0);
    }

    #[test]
    fn clamp_maps_do_not_wrap() {
        let m = ramp(16, 8, Projection::Elliptical);
        assert_eq!(m.bilinear(to_fx(0.1), to_fx(0.1)), m.pixel(0, 0));
        assert_eq!(m.bilinear(to_fx(15.9), to_fx(7.9)), m.pixel(15, 7));
    }

    #[test]
    fn tone_map_clamps_and_curves() {
        assert_eq!(tone_map(f32::NAN), 0);
        assert_eq!(tone_map(-3.0), 0);
        assert_eq!(tone_map(f32::NEG_INFINITY), 0);
        assert_eq!(tone_map(f32::INFINITY), 255);
        assert_eq!(tone_map(0.0), 0);
        // 1 -> 0.5 linear -> sRGB 0.7354 -> 188
        assert_eq!(tone_map(1.0), 188);
        assert!(tone_map(2.0) > tone_map(1.0));
    }

    #[test]
    fn hdr_images_are_toned_and_clamped() {
        let mut img = image::Rgb32FImage::new(4, 2);
        for (i, p) in img.pixels_mut().enumerate() {
            let v = [f32::NAN, -1.0, 1.0, f32::INFINITY, 0.5, 2.0, 0.0, 1e9][i];
            *p = image::Rgb([v, v, v]);
        }
        let dynimg = image::DynamicImage::ImageRgb32F(img);
        let m = EnvMap::from_image(&dynimg, Projection::Equirect).unwrap();
        let g = |x, y| m.pixel(x, y) & 0xFF;
        assert_eq!((g(0, 0), g(1, 0), g(2, 0), g(3, 0)), (0, 0, 188, 255));
        let brighter =
            EnvMap::from_image_toned(&dynimg, Projection::Equirect, Tone { exposure_ev: 1.0 })
                .unwrap();
        // +1 EV on 0.5 is 1.0
        assert_eq!(brighter.pixel(0, 1) & 0xFF, 188);
    }

    #[test]
    fn auto_projection() {
        assert!(resolve_projection("x", 100, 50, None).is_ok());
        assert!(resolve_projection("x", 100, 60, None).is_err());
        assert!(resolve_projection("x", 100, 60, Some(Projection::Equirect)).is_err());
        assert!(resolve_projection("x", 100, 60, Some(Projection::Cylinder)).is_ok());
    }
}

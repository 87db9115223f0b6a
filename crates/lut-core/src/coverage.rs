//! Partial panoramas: maps that cover only part of the sphere.
//!
//! A phone or stitcher panorama often covers, say, 240° × 80° of the sphere. Such a map is
//! kept as an [`EnvMap`] that stores **only the covered pixels** plus a [`Crop`]: where
//! those pixels sit in the full equirectangular panorama they were cut from. Every
//! renderer uses the *full* panorama's geometry ([`EnvMap::width`], [`EnvMap::height`]), so
//! the tables and the exact renderer do not change; only sampling looks at the crop:
//!
//! * a full-panorama position (u, v) is **covered** when the pixel containing it lies in
//!   the crop (the same rule for nearest and bilinear, so both show the same edge);
//! * outside the crop the map's background colour is returned;
//! * inside, bilinear clamps to the crop's edge texels (as the map's top and bottom rows
//!   clamp), so the border is crisp and nothing outside the crop bleeds in;
//! * a crop as wide as the full panorama wraps across the ±180° seam like a full map, and
//!   a crop that straddles the seam (`left + width > full width`) is read across it.
//!
//! The coverage comes from GPano XMP metadata ([`crate::gpano`]) or is given explicitly
//! as a [`Coverage`] (`HFOVxVFOV[±YAW±PITCH]`, degrees). [`crate::viewlimit`] keeps a view
//! inside it.

use crate::envmap::{EnvMap, Tone};
use crate::error::MapError;
use crate::fixed::{Fx, FX_BITS, FX_HALF};
use crate::projection::Projection;
use crate::{Sampler, MAX_MAP_WIDTH};

/// Why a coverage, a crop or GPano metadata cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CoverageError {
    /// A `--coverage` text that does not follow the grammar.
    #[error("coverage '{text}': {reason}")]
    Syntax {
        /// The text as given.
        text: String,
        /// What is wrong with it.
        reason: String,
    },
    /// Metadata or a coverage that does not describe a usable part of a panorama.
    #[error("{what}: {reason}")]
    Invalid {
        /// The file, metadata field or value concerned.
        what: String,
        /// Why.
        reason: String,
    },
    /// The image itself cannot be read or used.
    #[error(transparent)]
    Map(#[from] MapError),
}

fn invalid(what: impl Into<String>, reason: impl Into<String>) -> CoverageError {
    CoverageError::Invalid {
        what: what.into(),
        reason: reason.into(),
    }
}

/// The part of the sphere a panorama covers, in degrees: a longitude range `hfov` wide
/// centred on `yaw`, and a latitude range `vfov` high centred on `pitch`.
///
/// Text form (the `--coverage` option): `HFOVxVFOV[±YAW±PITCH]`, e.g. `360x90`,
/// `120x60+30-10` (120° × 60° centred on yaw 30°, pitch −10°), `200x100-170+0` (straddles
/// the ±180° seam). Numbers are plain decimals (`12`, `12.5`); YAW and PITCH each carry
/// their sign (`+` or `-`) and come together or not at all (default `+0+0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coverage {
    hfov: f64,
    vfov: f64,
    yaw: f64,
    pitch: f64,
}

impl Coverage {
    /// The whole sphere.
    pub const FULL: Coverage = Coverage {
        hfov: 360.0,
        vfov: 180.0,
        yaw: 0.0,
        pitch: 0.0,
    };

    /// A validated coverage: `hfov` in (0, 360], `vfov` in (0, 180], `yaw` any finite
    /// value (reduced to (−180, 180]), and `pitch ± vfov/2` inside [−90, 90].
    ///
    /// # Errors
    /// [`CoverageError::Invalid`] naming the value.
    pub fn new(hfov: f64, vfov: f64, yaw: f64, pitch: f64) -> Result<Coverage, CoverageError> {
        let all = [hfov, vfov, yaw, pitch];
        if all.iter().any(|v| !v.is_finite()) {
            return Err(invalid(
                "coverage",
                format!("angles must be finite, got {hfov}x{vfov} at {yaw}, {pitch}"),
            ));
        }
        if !(hfov > 0.0 && hfov <= 360.0) {
            return Err(invalid(
                "coverage",
                format!("horizontal extent {hfov} is not in (0, 360] degrees"),
            ));
        }
        if !(vfov > 0.0 && vfov <= 180.0) {
            return Err(invalid(
                "coverage",
                format!("vertical extent {vfov} is not in (0, 180] degrees"),
            ));
        }
        const EPS: f64 = 1e-9;
        if pitch + vfov / 2.0 > 90.0 + EPS || pitch - vfov / 2.0 < -90.0 - EPS {
            return Err(invalid(
                "coverage",
                format!(
                    "{vfov} degrees high centred on pitch {pitch} reaches past a pole \
                     (pitch ± vfov/2 must stay in [-90, 90])"
                ),
            ));
        }
        Ok(Coverage {
            hfov,
            vfov,
            yaw: crate::camera::wrap_deg(yaw),
            pitch,
        })
    }

    /// Horizontal extent in degrees, (0, 360].
    pub fn hfov(&self) -> f64 {
        self.hfov
    }
    /// Vertical extent in degrees, (0, 180].
    pub fn vfov(&self) -> f64 {
        self.vfov
    }
    /// Longitude of the centre in degrees, (−180, 180].
    pub fn yaw(&self) -> f64 {
        self.yaw
    }
    /// Latitude of the centre in degrees.
    pub fn pitch(&self) -> f64 {
        self.pitch
    }
    /// True when the coverage spans all longitudes.
    pub fn full_width(&self) -> bool {
        self.hfov >= 360.0
    }
    /// Southern and northern latitude limits in degrees.
    pub fn lat_range(&self) -> (f64, f64) {
        (
            (self.pitch - self.vfov / 2.0).max(-90.0),
            (self.pitch + self.vfov / 2.0).min(90.0),
        )
    }

    /// True when direction (λ, φ) (radians) lies inside (edges included, with `eps`
    /// degrees of slack).
    pub fn contains(&self, lambda: f64, phi: f64, eps: f64) -> bool {
        let (lo, hi) = self.lat_range();
        let phi = phi.to_degrees();
        if phi < lo - eps || phi > hi + eps {
            return false;
        }
        if self.full_width() {
            return true;
        }
        let d = crate::camera::wrap_deg(lambda.to_degrees() - self.yaw);
        d.abs() <= self.hfov / 2.0 + eps
    }

    /// Where an `image_w × image_h` image covering this area sits in the full
    /// equirectangular panorama: full size `round(image_w · 360 / hfov)` ×
    /// `round(image_h · 180 / vfov)` (pixels need not be square), and the crop's top-left
    /// corner rounded to the nearest full-panorama pixel (so the placement is exact to
    /// half a source pixel).
    ///
    /// # Errors
    /// [`CoverageError::Invalid`] when the full panorama would exceed the supported map
    /// size, or the image is too small.
    pub fn crop_for_image(&self, image_w: u32, image_h: u32) -> Result<Crop, CoverageError> {
        let fw = (image_w as f64 * 360.0 / self.hfov).round();
        let fh = (image_h as f64 * 180.0 / self.vfov).round();
        let what = format!("coverage {self}");
        if fw > MAX_MAP_WIDTH as f64 || fh > crate::envmap::MAX_MAP_HEIGHT as f64 {
            return Err(invalid(
                what,
                format!(
                    "a {image_w}x{image_h} image covering it makes a {fw}x{fh} full \
                     panorama; sides above {MAX_MAP_WIDTH} are not supported"
                ),
            ));
        }
        let (fw, fh) = (fw.max(image_w as f64) as u32, fh.max(image_h as f64) as u32);
        let left = ((self.yaw - self.hfov / 2.0 + 180.0) / 360.0 * fw as f64).round();
        let left = (left as i64).rem_euclid(fw as i64) as u32;
        let top = ((90.0 - self.pitch - self.vfov / 2.0) / 180.0 * fh as f64).round();
        // Rounding may push the last row one pixel past the bottom: pull it back.
        let top = (top.max(0.0) as u32).min(fh - image_h);
        Crop::new(fw, fh, left, top, image_w, image_h).map_err(|e| match e {
            CoverageError::Invalid { reason, .. } => invalid(format!("coverage {self}"), reason),
            other => other,
        })
    }
}

impl std::fmt::Display for Coverage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}x{}{:+}{:+}",
            self.hfov, self.vfov, self.yaw, self.pitch
        )
    }
}

impl std::str::FromStr for Coverage {
    type Err = CoverageError;

    /// Parse `HFOVxVFOV[±YAW±PITCH]` (see [`Coverage`]).
    fn from_str(s: &str) -> Result<Coverage, CoverageError> {
        let syntax = |reason: &str| CoverageError::Syntax {
            text: s.to_string(),
            reason: format!(
                "{reason}; expected HFOVxVFOV or HFOVxVFOV±YAW±PITCH, e.g. 120x60+30-10"
            ),
        };
        let t = s.trim();
        let (h, rest) = t
            .split_once(['x', 'X'])
            .ok_or_else(|| syntax("no 'x' between the horizontal and vertical extent"))?;
        // VFOV runs up to the first sign; then YAW and PITCH, each starting with a sign.
        let (v, centre) = match rest.find(['+', '-']) {
            Some(i) => (&rest[..i], Some(&rest[i..])),
            None => (rest, None),
        };
        let num = |x: &str, name: &str, signed: bool| -> Result<f64, CoverageError> {
            let body = if signed { &x[1..] } else { x };
            let ok = !body.is_empty()
                && body.chars().all(|c| c.is_ascii_digit() || c == '.')
                && body.chars().filter(|&c| c == '.').count() <= 1
                && body.chars().any(|c| c.is_ascii_digit());
            if !ok {
                return Err(syntax(&format!("{name} '{x}' is not a decimal number")));
            }
            x.parse::<f64>()
                .map_err(|_| syntax(&format!("{name} '{x}' is not a decimal number")))
        };
        let hfov = num(h, "HFOV", false)?;
        let vfov = num(v, "VFOV", false)?;
        let (yaw, pitch) = match centre {
            None => (0.0, 0.0),
            Some(c) => {
                let j = c[1..]
                    .find(['+', '-'])
                    .map(|j| j + 1)
                    .ok_or_else(|| syntax("YAW and PITCH must both be given, each with a sign"))?;
                (num(&c[..j], "YAW", true)?, num(&c[j..], "PITCH", true)?)
            }
        };
        Coverage::new(hfov, vfov, yaw, pitch).map_err(|e| match e {
            CoverageError::Invalid { reason, .. } => CoverageError::Syntax {
                text: s.to_string(),
                reason,
            },
            other => other,
        })
    }
}

/// Where a partial map's stored pixels sit in the full equirectangular panorama, in
/// full-panorama pixels. `left` is in `0..full_width`; the crop may run past the right
/// edge and continue at column 0 (it straddles the ±180° seam).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Crop {
    full_width: u32,
    full_height: u32,
    left: u32,
    top: u32,
    width: u32,
    height: u32,
}

impl Crop {
    /// A validated crop: sizes nonzero and at most 65536, `width ≤ full_width`,
    /// `top + height ≤ full_height`; `left` is taken modulo `full_width`.
    ///
    /// # Errors
    /// [`CoverageError::Invalid`] naming the values.
    pub fn new(
        full_width: u32,
        full_height: u32,
        left: u32,
        top: u32,
        width: u32,
        height: u32,
    ) -> Result<Crop, CoverageError> {
        let what = format!(
            "crop {width}x{height} at ({left}, {top}) of a {full_width}x{full_height} panorama"
        );
        if full_width < 2 || full_height < 2 || width < 2 || height < 2 {
            return Err(invalid(what, "every size must be at least 2 pixels"));
        }
        if full_width > MAX_MAP_WIDTH || full_height > crate::envmap::MAX_MAP_HEIGHT {
            return Err(invalid(
                what,
                format!("full panorama sides above {MAX_MAP_WIDTH} are not supported"),
            ));
        }
        if width > full_width {
            return Err(invalid(what, "the crop is wider than the full panorama"));
        }
        if top as u64 + height as u64 > full_height as u64 {
            return Err(invalid(what, "the crop runs below the full panorama"));
        }
        Ok(Crop {
            full_width,
            full_height,
            left: left % full_width,
            top,
            width,
            height,
        })
    }

    /// Full panorama width in pixels (the map's [`EnvMap::width`]).
    pub fn full_width(&self) -> u32 {
        self.full_width
    }
    /// Full panorama height in pixels.
    pub fn full_height(&self) -> u32 {
        self.full_height
    }
    /// First covered column of the full panorama.
    pub fn left(&self) -> u32 {
        self.left
    }
    /// First covered row of the full panorama.
    pub fn top(&self) -> u32 {
        self.top
    }
    /// Covered (stored) width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Covered (stored) height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// True when the crop is the whole panorama.
    pub fn is_full(&self) -> bool {
        self.width == self.full_width && self.height == self.full_height
    }
    /// True when the crop straddles the ±180° seam.
    pub fn straddles_seam(&self) -> bool {
        self.width < self.full_width && self.left + self.width > self.full_width
    }

    /// The covered area in degrees (equirectangular geometry).
    pub fn coverage(&self) -> Coverage {
        let (fw, fh) = (self.full_width as f64, self.full_height as f64);
        let hfov = self.width as f64 / fw * 360.0;
        let vfov = self.height as f64 / fh * 180.0;
        let west = self.left as f64 / fw * 360.0 - 180.0;
        let north = 90.0 - self.top as f64 / fh * 180.0;
        Coverage {
            hfov,
            vfov,
            yaw: crate::camera::wrap_deg(west + hfov / 2.0),
            pitch: north - vfov / 2.0,
        }
    }

    /// Stored-pixel position of full-panorama position (u, v) (Q.16), or `None` when
    /// the pixel containing it is not covered.
    #[inline]
    fn locate(&self, u: Fx, v: Fx) -> Option<(Fx, Fx)> {
        let wfx = (self.full_width as i64) << FX_BITS;
        let hfx = (self.full_height as i64) << FX_BITS;
        // Renderers pass u in [0, W); anything else is wrapped, v is clamped as the full
        // map clamps it.
        let u = if (0..wfx).contains(&u) {
            u
        } else {
            u.rem_euclid(wfx)
        };
        let v = v.clamp(0, hfx - 1);
        let mut su = u - ((self.left as i64) << FX_BITS);
        if su < 0 {
            su += wfx;
        }
        let sv = v - ((self.top as i64) << FX_BITS);
        if su >= (self.width as i64) << FX_BITS || sv < 0 || sv >= (self.height as i64) << FX_BITS {
            return None;
        }
        Some((su, sv))
    }
}

/// What a decoded panorama turned out to cover.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CoverageSource {
    /// The whole sphere (no metadata, or metadata describing the whole panorama).
    Full,
    /// GPano XMP metadata in the file.
    Xmp,
    /// An explicit [`Coverage`] given by the caller.
    Explicit,
}

impl EnvMap {
    /// Where the stored pixels sit in the full panorama, for a partial map.
    pub fn crop(&self) -> Option<Crop> {
        self.crop
    }

    /// The covered area in degrees ([`Coverage::FULL`] for a whole map; for projections
    /// other than equirectangular the crop is not used and this is also `FULL`).
    pub fn coverage(&self) -> Coverage {
        self.crop.map_or(Coverage::FULL, |c| c.coverage())
    }

    /// Compass heading, in degrees, of the map's centre column (longitude 0): GPano
    /// `PoseHeadingDegrees`, when the file has it.
    pub fn pose_heading_deg(&self) -> Option<f64> {
        self.pose_heading
    }

    /// Set (or clear) the compass heading of longitude 0 (see
    /// [`EnvMap::pose_heading_deg`]). Non-finite values clear it.
    pub fn set_pose_heading_deg(&mut self, heading: Option<f64>) {
        self.pose_heading = heading
            .filter(|h| h.is_finite())
            .map(|h| h.rem_euclid(360.0));
    }

    /// Width of the stored pixels (the crop's width for a partial map, else
    /// [`EnvMap::width`]).
    pub fn stored_width(&self) -> u32 {
        self.width
    }
    /// Height of the stored pixels.
    pub fn stored_height(&self) -> u32 {
        self.height
    }

    /// Turn a map holding the pixels of `crop` (`crop.width() × crop.height()`) into a
    /// partial equirectangular map of the full panorama. A crop that is the whole
    /// panorama gives an ordinary map.
    ///
    /// # Errors
    /// [`CoverageError::Invalid`] when the stored size is not the crop's size.
    pub fn into_partial(self, crop: Crop) -> Result<EnvMap, CoverageError> {
        if (self.width, self.height) != (crop.width, crop.height) {
            return Err(invalid(
                format!(
                    "crop {}x{} of a {}x{} panorama",
                    crop.width, crop.height, crop.full_width, crop.full_height
                ),
                format!("the image is {}x{}", self.width, self.height),
            ));
        }
        // The padding column must repeat column 0 only when the crop spans 360°.
        let wrap = crop.width == crop.full_width;
        let mut m = if self.projection.wraps() == wrap {
            self
        } else {
            let (w, h) = (self.width, self.height);
            let px: Vec<u32> = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| self.pixel(x, y))
                .collect();
            // (elliptical maps pad by repeating the last column)
            let pad_as = if wrap {
                Projection::Equirect
            } else {
                Projection::Elliptical
            };
            let mut m = EnvMap::from_pixels(w, h, &px, pad_as)?;
            m.background = self.background;
            m.pose_heading = self.pose_heading;
            m
        };
        // Bilinear only wraps for column −1 / W; a non-360° crop never asks for those
        // (see `bilinear_cropped`), so the projection can say equirect in both cases.
        m.projection = Projection::Equirect;
        m.crop = if crop.is_full() { None } else { Some(crop) };
        Ok(m)
    }

    /// Nearest sample at a full-panorama position (Q.16) of a partial map: the covered
    /// pixel containing it, or the background. For a map without a crop it is
    /// [`EnvMap::nearest`].
    #[inline]
    pub fn nearest_cropped(&self, u: Fx, v: Fx) -> u32 {
        match self.crop {
            None => self.nearest(u, v),
            Some(c) => match c.locate(u, v) {
                Some((su, sv)) => self.nearest(su, sv),
                None => self.background,
            },
        }
    }

    /// Bilinear sample at a full-panorama position (Q.16) of a partial map: background
    /// where the containing pixel is not covered; inside, the four nearest covered pixel
    /// centres, clamped to the crop's edge texels (wrapping only for a 360°-wide crop).
    /// For a map without a crop it is [`EnvMap::bilinear`].
    #[inline]
    pub fn bilinear_cropped(&self, u: Fx, v: Fx) -> u32 {
        match self.crop {
            None => self.bilinear(u, v),
            Some(c) => match c.locate(u, v) {
                Some((su, sv)) => {
                    // Left edge: clamp to column 0 rather than wrap to the last column
                    // (the right edge reads the padding column, which repeats the last).
                    let su = if c.width < c.full_width {
                        su.max(FX_HALF)
                    } else {
                        su
                    };
                    self.bilinear(su, sv)
                }
                None => self.background,
            },
        }
    }

    /// A run of [`EnvMap::nearest_cropped`] (`BILINEAR` false) or
    /// [`EnvMap::bilinear_cropped`] samples at full-panorama positions (u + i·du,
    /// v + i·dv), u wrapped per pixel. Spans inside the stored pixels or wholly in the
    /// background take the span kernels ([`crate::Kernel::cropped_span`]); spans over the
    /// crop's edge are sampled per pixel.
    pub fn sample_span_cropped<const BILINEAR: bool>(
        &self,
        out: &mut [u32],
        u: Fx,
        v: Fx,
        du: Fx,
        dv: Fx,
    ) {
        let Some(c) = self.crop else {
            return self.sample_span::<BILINEAR>(out, u, v, du, dv);
        };
        let w = crate::simd::Window {
            full_width: c.full_width,
            full_height: c.full_height,
            left: c.left,
            top: c.top,
            background: self.background,
        };
        if crate::simd::cropped_span(BILINEAR, &self.texels(), &w, out, u, v, du, dv) {
            return;
        }
        let (mut u, mut v) = (u, v);
        for o in out.iter_mut() {
            *o = if BILINEAR {
                self.bilinear_cropped(u, v)
            } else {
                self.nearest_cropped(u, v)
            };
            u += du;
            v += dv;
        }
    }

    /// [`EnvMap::sample`] for a partial map.
    #[inline]
    pub(crate) fn sample_cropped(&self, sampler: Sampler, u: Fx, v: Fx) -> u32 {
        match sampler {
            Sampler::Nearest => self.nearest_cropped(u, v),
            Sampler::Bilinear | Sampler::Trilinear => self.bilinear_cropped(u, v),
        }
    }

    /// Decode an image file's bytes as a possibly partial panorama.
    ///
    /// * `coverage` given: the image covers that area (equirectangular); any GPano
    ///   metadata is ignored.
    /// * otherwise, for JPEGs with GPano XMP (see [`crate::gpano`]) and an `auto` or
    ///   equirectangular projection: the metadata places the image in the full panorama
    ///   and supplies the compass heading;
    /// * otherwise: as [`EnvMap::decode_toned`].
    ///
    /// # Errors
    /// [`CoverageError`] naming `what` for bad metadata or coverage (an explicit
    /// coverage overrides bad metadata), or the image's [`MapError`].
    pub fn decode_partial(
        bytes: &[u8],
        what: &str,
        projection: Option<Projection>,
        coverage: Option<Coverage>,
        tone: Tone,
    ) -> Result<(EnvMap, CoverageSource), CoverageError> {
        let opts = crate::LoadOptions {
            projection,
            tone,
            ..crate::LoadOptions::default()
        };
        Self::decode_partial_with(bytes, what, &opts, coverage, &mut |_| {})
    }

    /// As [`EnvMap::decode_partial`], with the pixel limit and projection of `opts` and
    /// progress reports (see [`EnvMap::decode_with`]).
    ///
    /// # Errors
    /// As [`EnvMap::decode_partial`].
    pub fn decode_partial_with(
        bytes: &[u8],
        what: &str,
        opts: &crate::LoadOptions,
        coverage: Option<Coverage>,
        progress: &mut dyn FnMut(crate::LoadProgress),
    ) -> Result<(EnvMap, CoverageSource), CoverageError> {
        place_partial(bytes, what, opts, coverage, |o| {
            EnvMap::decode_with(bytes, what, o, progress)
        })
    }

    /// As [`EnvMap::decode_partial_with`], streamed from a file (see
    /// [`EnvMap::load_with`]): only the file's first 256 KiB are read for the metadata (an
    /// XMP packet sits in an APP1 segment of at most 64 KiB before the image data).
    ///
    /// # Errors
    /// As [`EnvMap::decode_partial`]; unreadable files are [`MapError::Decode`].
    pub fn load_partial_with(
        path: &std::path::Path,
        opts: &crate::LoadOptions,
        coverage: Option<Coverage>,
        progress: &mut dyn FnMut(crate::LoadProgress),
    ) -> Result<(EnvMap, CoverageSource), CoverageError> {
        use std::io::Read;
        let what = path.display().to_string();
        let io_err = |e: std::io::Error| MapError::Decode {
            path: path.to_path_buf(),
            reason: e.to_string(),
        };
        let mut head = Vec::new();
        std::fs::File::open(path)
            .map_err(io_err)?
            .take(256 * 1024)
            .read_to_end(&mut head)
            .map_err(io_err)?;
        place_partial(&head, &what, opts, coverage, |o| {
            EnvMap::load_with(path, o, progress)
        })
    }
}

/// Decide how a panorama is placed (explicit coverage, GPano metadata found in `head`, or
/// full), decode it with `decode`, and crop it into place.
fn place_partial(
    head: &[u8],
    what: &str,
    opts: &crate::LoadOptions,
    coverage: Option<Coverage>,
    decode: impl FnOnce(&crate::LoadOptions) -> Result<EnvMap, MapError>,
) -> Result<(EnvMap, CoverageSource), CoverageError> {
    let projection = opts.projection;
    let equirect = matches!(projection, None | Some(Projection::Equirect));
    if coverage.is_some() && !equirect {
        return Err(invalid(
            what,
            "a coverage applies to equirectangular panoramas only",
        ));
    }
    let meta = if coverage.is_none() && equirect {
        crate::gpano::read_jpeg(head).map_err(|e| invalid(what, e.to_string()))?
    } else {
        None
    };
    let heading = meta.as_ref().and_then(|g| g.pose_heading_degrees);
    let has_crop = coverage.is_some() || meta.as_ref().is_some_and(|g| g.has_crop());
    if !has_crop {
        let mut m = decode(opts)?;
        m.set_pose_heading_deg(heading);
        return Ok((m, CoverageSource::Full));
    }
    // Decoded as "elliptical" only so that any aspect ratio is accepted and the padding
    // column repeats the last column (no wrap); `into_partial` makes it the crop of an
    // equirect (re-padded if the crop spans 360°).
    let mut m = decode(&crate::LoadOptions {
        projection: Some(Projection::Elliptical),
        ..*opts
    })?;
    let (iw, ih) = (m.width(), m.height());
    let (crop, source) = match (coverage, &meta) {
        (Some(c), _) => (c.crop_for_image(iw, ih), CoverageSource::Explicit),
        (None, Some(g)) => (g.crop_for_image(iw, ih), CoverageSource::Xmp),
        // Not reached (`has_crop` needs one of them); the whole sphere is harmless.
        (None, None) => (Coverage::FULL.crop_for_image(iw, ih), CoverageSource::Full),
    };
    let crop = crop.map_err(|e| invalid(what, e.to_string()))?;
    m.set_pose_heading_deg(heading);
    let m = m.into_partial(crop)?;
    let source = if m.crop.is_none() {
        CoverageSource::Full
    } else {
        source
    };
    Ok((m, source))
}

/// Compass heading (degrees clockwise from north, [0, 360)) of the view centre at `yaw`
/// for a map whose longitude 0 faces `pose_heading` (GPano `PoseHeadingDegrees`, see
/// [`EnvMap::pose_heading_deg`]): yaw stays relative to the map; positive yaw turns
/// right, which is clockwise seen from above, so the heading is the sum.
pub fn compass_heading(pose_heading: f64, yaw: f64) -> f64 {
    let h = (pose_heading + yaw).rem_euclid(360.0);
    if h >= 360.0 {
        0.0
    } else {
        h
    }
}

/// The nearest of the eight compass points (N, NE, … NW) to heading `h` in degrees.
pub fn compass_point(h: f64) -> &'static str {
    const POINTS: [&str; 8] = ["N", "NE", "E", "SE", "S", "SW", "W", "NW"];
    POINTS[((h.rem_euclid(360.0) + 22.5) / 45.0) as usize % 8]
}

/// Image size from the header, without decoding.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::to_fx;

    #[test]
    fn grammar() {
        let c: Coverage = "120x60+30-10".parse().unwrap();
        assert_eq!(
            (c.hfov(), c.vfov(), c.yaw(), c.pitch()),
            (120.0, 60.0, 30.0, -10.0)
        );
        let c: Coverage = "360x90".parse().unwrap();
        assert_eq!((c.yaw(), c.pitch()), (0.0, 0.0));
        let c: Coverage = "200.5X100-170+0".parse().unwrap();
        assert_eq!((c.hfov(), c.yaw()), (200.5, -170.0));
        let c: Coverage = "90x45-0-22.5".parse().unwrap();
        assert_eq!((c.yaw(), c.pitch()), (0.0, -22.5));
        assert_eq!("10x10+540+0".parse::<Coverage>().unwrap().yaw(), 180.0);
        for bad in [
            "",
            "120",
            "120x",
            "x60",
            "120x60+30",
            "120x60+30-",
            "120x60 30 10",
            "1e2x60",
            "120x60+30-10+5",
            "0x60",
            "361x60",
            "120x181",
            "120x60+0+80",
            "-120x60",
            "120x-60",
            "nanx60",
            "1..2x60",
            "120x60++3+4",
        ] {
            let e = bad.parse::<Coverage>();
            assert!(
                matches!(e, Err(CoverageError::Syntax { .. })),
                "'{bad}' gave {e:?}"
            );
        }
        // the message names the text
        let msg = "120x60+30".parse::<Coverage>().unwrap_err().to_string();
        assert!(msg.contains("120x60+30") && msg.contains("PITCH"), "{msg}");
    }

    #[test]
    fn display_round_trips() {
        for s in ["120x60+30-10", "360x180+0+0", "200.5x100-170+0"] {
            let c: Coverage = s.parse().unwrap();
            assert_eq!(c.to_string().parse::<Coverage>().unwrap(), c);
        }
    }

    #[test]
    fn crop_for_image_places_the_image() {
        // 90 x 45 degrees centred on yaw -45, pitch 22.5, 400x200 image: the full
        // panorama is 1600x800; west edge -90 deg -> column 400; north edge 45 -> row 200.
        let c = Coverage::new(90.0, 45.0, -45.0, 22.5).unwrap();
        let k = c.crop_for_image(400, 200).unwrap();
        assert_eq!(
            (k.full_width(), k.full_height(), k.left(), k.top()),
            (1600, 800, 400, 200)
        );
        let back = k.coverage();
        assert!((back.hfov() - 90.0).abs() < 1e-9 && (back.yaw() + 45.0).abs() < 1e-9);
        assert!((back.pitch() - 22.5).abs() < 1e-9 && (back.vfov() - 45.0).abs() < 1e-9);
        // straddling the seam: 100 deg centred on 180
        let k = Coverage::new(100.0, 180.0, 180.0, 0.0)
            .unwrap()
            .crop_for_image(100, 180)
            .unwrap();
        assert_eq!((k.full_width(), k.left()), (360, 310));
        assert!(k.straddles_seam());
        // too narrow for the supported full width
        let e = Coverage::new(0.1, 10.0, 0.0, 0.0)
            .unwrap()
            .crop_for_image(1000, 100);
        assert!(matches!(e, Err(CoverageError::Invalid { .. })));
    }

    #[test]
    fn crop_validation() {
        assert!(Crop::new(100, 50, 0, 0, 101, 10).is_err());
        assert!(Crop::new(100, 50, 0, 45, 10, 10).is_err());
        assert!(Crop::new(0, 50, 0, 0, 10, 10).is_err());
        assert!(Crop::new(100, 50, 0, 0, 0, 10).is_err());
        assert_eq!(Crop::new(100, 50, 250, 0, 10, 10).unwrap().left(), 50);
    }

    fn partial(crop: Crop) -> EnvMap {
        let (w, h) = (crop.width(), crop.height());
        let px: Vec<u32> = (0..w * h)
            .map(|i| 0x010000 * (i % w) + 0x100 * (i / w) + 1)
            .collect();
        let mut m = EnvMap::from_pixels(w, h, &px, Projection::Elliptical)
            .unwrap()
            .into_partial(crop)
            .unwrap();
        m.set_background(0xABCDEF);
        m
    }

    #[test]
    fn sampling_inside_outside_and_across_the_seam() {
        // 10 columns from column 95 of 100: 95..100 and 0..5
        let m = partial(Crop::new(100, 50, 95, 10, 10, 20).unwrap());
        assert_eq!((m.width(), m.height(), m.stored_width()), (100, 50, 10));
        let at = |u: f64, v: f64| m.nearest_cropped(to_fx(u), to_fx(v));
        assert_eq!(at(95.5, 10.5), m.pixel(0, 0));
        assert_eq!(at(99.5, 29.5), m.pixel(4, 19));
        assert_eq!(at(0.5, 12.5), m.pixel(5, 2));
        assert_eq!(at(4.99, 12.5), m.pixel(9, 2));
        for (u, v) in [
            (5.0, 12.5),
            (94.99, 12.5),
            (50.0, 20.0),
            (97.0, 9.99),
            (97.0, 30.0),
        ] {
            assert_eq!(at(u, v), 0xABCDEF, "({u}, {v})");
            assert_eq!(m.bilinear_cropped(to_fx(u), to_fx(v)), 0xABCDEF);
        }
        // bilinear across the seam blends stored columns 4 and 5
        let b = m.bilinear_cropped(to_fx(100.0), to_fx(12.5));
        assert_eq!(b, crate::envmap::lerp_px(m.pixel(4, 2), m.pixel(5, 2), 128));
        // edges clamp to the edge texels
        assert_eq!(m.bilinear_cropped(to_fx(95.1), to_fx(10.1)), m.pixel(0, 0));
        assert_eq!(m.bilinear_cropped(to_fx(4.9), to_fx(29.9)), m.pixel(9, 19));
        // sample() goes through the crop
        assert_eq!(
            m.sample(Sampler::Nearest, to_fx(0.5), to_fx(12.5)),
            m.pixel(5, 2)
        );
        assert_eq!(
            m.sample(Sampler::Bilinear, to_fx(50.0), to_fx(12.5)),
            0xABCDEF
        );
    }

    #[test]
    fn full_width_crop_wraps() {
        let m = partial(Crop::new(16, 20, 0, 5, 16, 6).unwrap());
        let b = m.bilinear_cropped(to_fx(0.0), to_fx(7.5));
        assert_eq!(
            b,
            crate::envmap::lerp_px(m.pixel(15, 2), m.pixel(0, 2), 128)
        );
        let b = m.bilinear_cropped(to_fx(15.9999), to_fx(7.5));
        assert_eq!(
            b,
            crate::envmap::lerp_px(m.pixel(15, 2), m.pixel(0, 2), 128)
        );
        assert_eq!(m.nearest_cropped(to_fx(3.5), to_fx(4.9)), 0xABCDEF);
        assert_eq!(m.nearest_cropped(to_fx(3.5), to_fx(11.0)), 0xABCDEF);
    }

    #[test]
    fn whole_crop_is_a_plain_map() {
        let m = partial(Crop::new(16, 8, 0, 0, 16, 8).unwrap());
        assert!(m.crop().is_none());
        assert_eq!(m.coverage(), Coverage::FULL);
        let b = m.bilinear(to_fx(0.0), to_fx(2.5));
        assert_eq!(
            b,
            crate::envmap::lerp_px(m.pixel(15, 2), m.pixel(0, 2), 128)
        );
    }

    #[test]
    fn wrong_stored_size_is_an_error() {
        let m = EnvMap::from_pixels(4, 4, &[0; 16], Projection::Cylinder).unwrap();
        let e = m.into_partial(Crop::new(100, 50, 0, 0, 5, 4).unwrap());
        assert!(matches!(e, Err(CoverageError::Invalid { .. })));
    }

    #[test]
    fn heading_adds_the_pose_and_wraps() {
        assert_eq!(compass_heading(350.0, 20.0), 10.0);
        assert_eq!(compass_heading(90.0, -90.0), 0.0);
        assert_eq!(compass_heading(0.0, 180.0), 180.0);
        assert_eq!(compass_heading(-45.0, 0.0), 315.0);
        assert_eq!(compass_point(0.0), "N");
        assert_eq!(compass_point(350.0), "N");
        assert_eq!(compass_point(213.0), "SW");
        assert_eq!(compass_point(-90.0), "W");
    }

    #[test]
    fn contains_handles_the_seam() {
        let c = Coverage::new(60.0, 40.0, 170.0, 10.0).unwrap();
        let r = f64::to_radians;
        assert!(c.contains(r(-160.0), r(0.0), 0.0));
        assert!(c.contains(r(145.0), r(29.0), 0.0));
        assert!(!c.contains(r(-150.0), r(0.0), 0.0));
        assert!(!c.contains(r(170.0), r(31.0), 0.0));
        assert!(!c.contains(r(170.0), r(-11.0), 0.0));
    }
}

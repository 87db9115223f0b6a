//! Coverage: the part of the sphere a partial panorama covers, and where its stored pixels
//! sit in the full panorama.
//!
//! A phone or stitcher panorama often covers, say, 240° × 80° of the sphere. Such a map
//! stores **only the covered pixels** plus a [`Crop`]: where those pixels sit in the full
//! equirectangular panorama they were cut from. Every renderer uses the *full* panorama's
//! geometry, so the tables and the exact renderer do not change; only sampling looks at the
//! crop (the cropped samplers of `map/crop.rs`):
//!
//! * a full-panorama position (u, v) is **covered** when the pixel containing it lies in
//!   the crop (the same rule for nearest and bilinear, so both show the same edge);
//! * outside the crop the map's background colour is returned;
//! * inside, bilinear clamps to the crop's edge texels (as the map's top and bottom rows
//!   clamp), so the border is crisp and nothing outside the crop bleeds in;
//! * a crop as wide as the full panorama wraps across the ±180° seam like a full map, and
//!   a crop that straddles the seam (`left + width > full width`) is read across it.
//!
//! The coverage comes from GPano XMP metadata (`io/gpano.rs`) or is given explicitly as a
//! [`Coverage`] (`HFOVxVFOV[±YAW±PITCH]`, degrees). The view limit (`geom/viewlimit.rs`)
//! keeps a view inside it.

use crate::error::{AngleProblem, CoverageError, CropProblem, SyntaxProblem};
use crate::geom::camera::wrap_deg;
use crate::geom::fixed::{Fx, FX_BITS};
use crate::geom::limits::{MAX_MAP_HEIGHT, MAX_MAP_WIDTH};

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
    /// [`CoverageError::Angles`] saying which angle.
    pub fn new(hfov: f64, vfov: f64, yaw: f64, pitch: f64) -> Result<Coverage, CoverageError> {
        let all = [hfov, vfov, yaw, pitch];
        if all.iter().any(|v| !v.is_finite()) {
            return Err(CoverageError::Angles(AngleProblem::NonFinite {
                hfov,
                vfov,
                yaw,
                pitch,
            }));
        }
        if !(hfov > 0.0 && hfov <= 360.0) {
            return Err(CoverageError::Angles(AngleProblem::Hfov(hfov)));
        }
        if !(vfov > 0.0 && vfov <= 180.0) {
            return Err(CoverageError::Angles(AngleProblem::Vfov(vfov)));
        }
        const EPS: f64 = 1e-9;
        if pitch + vfov / 2.0 > 90.0 + EPS || pitch - vfov / 2.0 < -90.0 - EPS {
            return Err(CoverageError::Angles(AngleProblem::PastPole {
                vfov,
                pitch,
            }));
        }
        Ok(Coverage {
            hfov,
            vfov,
            yaw: wrap_deg(yaw),
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
        let d = wrap_deg(lambda.to_degrees() - self.yaw);
        d.abs() <= self.hfov / 2.0 + eps
    }

    /// Where an `image_w × image_h` image covering this area sits in the full
    /// equirectangular panorama: full size `round(image_w · 360 / hfov)` ×
    /// `round(image_h · 180 / vfov)` (pixels need not be square), and the crop's top-left
    /// corner rounded to the nearest full-panorama pixel (so the placement is exact to
    /// half a source pixel).
    ///
    /// # Errors
    /// [`CoverageError::FullTooLarge`] when the full panorama would exceed the supported
    /// map size, [`CoverageError::Crop`] when the image is too small.
    pub fn crop_for_image(&self, image_w: u32, image_h: u32) -> Result<Crop, CoverageError> {
        let fw = (image_w as f64 * 360.0 / self.hfov).round();
        let fh = (image_h as f64 * 180.0 / self.vfov).round();
        if fw > MAX_MAP_WIDTH as f64 || fh > MAX_MAP_HEIGHT as f64 {
            return Err(CoverageError::FullTooLarge {
                coverage: self.to_string(),
                image_width: image_w,
                image_height: image_h,
                full_width: fw,
                full_height: fh,
                max: MAX_MAP_WIDTH,
            });
        }
        let (fw, fh) = (fw.max(image_w as f64) as u32, fh.max(image_h as f64) as u32);
        let left = ((self.yaw - self.hfov / 2.0 + 180.0) / 360.0 * fw as f64).round();
        let left = (left as i64).rem_euclid(fw as i64) as u32;
        let top = ((90.0 - self.pitch - self.vfov / 2.0) / 180.0 * fh as f64).round();
        // Rounding may push the last row one pixel past the bottom: pull it back.
        let top = (top.max(0.0) as u32).min(fh - image_h);
        Crop::new(fw, fh, left, top, image_w, image_h).map_err(|e| match e {
            CoverageError::Crop { problem, .. } => CoverageError::Crop {
                what: format!("coverage {self}"),
                problem,
            },
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
        let syntax = |problem: SyntaxProblem| CoverageError::Syntax {
            text: s.to_string(),
            problem,
        };
        let t = s.trim();
        let (h, rest) = t
            .split_once(['x', 'X'])
            .ok_or_else(|| syntax(SyntaxProblem::NoX))?;
        // VFOV runs up to the first sign; then YAW and PITCH, each starting with a sign.
        let (v, centre) = match rest.find(['+', '-']) {
            Some(i) => (&rest[..i], Some(&rest[i..])),
            None => (rest, None),
        };
        let num = |x: &str, part: &'static str, signed: bool| -> Result<f64, CoverageError> {
            let bad = || {
                syntax(SyntaxProblem::NotDecimal {
                    part,
                    text: x.to_string(),
                })
            };
            let body = if signed { &x[1..] } else { x };
            let ok = !body.is_empty()
                && body.chars().all(|c| c.is_ascii_digit() || c == '.')
                && body.chars().filter(|&c| c == '.').count() <= 1
                && body.chars().any(|c| c.is_ascii_digit());
            if !ok {
                return Err(bad());
            }
            x.parse::<f64>().map_err(|_| bad())
        };
        let hfov = num(h, "HFOV", false)?;
        let vfov = num(v, "VFOV", false)?;
        let (yaw, pitch) = match centre {
            None => (0.0, 0.0),
            Some(c) => {
                let j = c[1..]
                    .find(['+', '-'])
                    .map(|j| j + 1)
                    .ok_or_else(|| syntax(SyntaxProblem::YawPitchPair))?;
                (num(&c[..j], "YAW", true)?, num(&c[j..], "PITCH", true)?)
            }
        };
        Coverage::new(hfov, vfov, yaw, pitch).map_err(|e| match e {
            CoverageError::Angles(a) => syntax(SyntaxProblem::Angles(a)),
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
    /// [`CoverageError::Crop`] naming the values.
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
            return Err(CoverageError::Crop {
                what,
                problem: CropProblem::TooSmall,
            });
        }
        if full_width > MAX_MAP_WIDTH || full_height > MAX_MAP_HEIGHT {
            return Err(CoverageError::Crop {
                what,
                problem: CropProblem::FullSidesAbove { max: MAX_MAP_WIDTH },
            });
        }
        if width > full_width {
            return Err(CoverageError::Crop {
                what,
                problem: CropProblem::Wider,
            });
        }
        if top as u64 + height as u64 > full_height as u64 {
            return Err(CoverageError::Crop {
                what,
                problem: CropProblem::Below,
            });
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

    /// Full panorama width in pixels (the map's [`crate::EnvMap::width`]).
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
            yaw: wrap_deg(west + hfov / 2.0),
            pitch: north - vfov / 2.0,
        }
    }

    /// Stored-pixel position of full-panorama position (u, v) (Q.16), or `None` when
    /// the pixel containing it is not covered.
    #[inline]
    pub(crate) fn locate(&self, u: Fx, v: Fx) -> Option<(Fx, Fx)> {
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

/// The view a panorama asks to be opened at (GPano `InitialView*`, see
/// [`crate::GPano::start_view`]), relative to the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartView {
    /// Yaw in degrees, (−180, 180].
    pub yaw_deg: f64,
    /// Pitch in degrees, [−90, 90].
    pub pitch_deg: f64,
    /// Horizontal field of view in degrees, when the file gives one.
    pub hfov_deg: Option<f64>,
}

/// Compass heading (degrees clockwise from north, [0, 360)) of the view centre at `yaw`
/// for a map whose longitude 0 faces `pose_heading` (GPano `PoseHeadingDegrees`, see
/// [`crate::EnvMap::pose_heading_deg`]): yaw stays relative to the map; positive yaw turns
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

#[cfg(test)]
mod tests {
    use super::*;

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
        assert!(matches!(e, Err(CoverageError::FullTooLarge { .. })));
    }

    #[test]
    fn crop_validation() {
        assert!(Crop::new(100, 50, 0, 0, 101, 10).is_err());
        assert!(Crop::new(100, 50, 0, 45, 10, 10).is_err());
        assert!(Crop::new(0, 50, 0, 0, 10, 10).is_err());
        assert!(Crop::new(100, 50, 0, 0, 0, 10).is_err());
        assert_eq!(Crop::new(100, 50, 250, 0, 10, 10).unwrap().left(), 50);
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

//! Output projections (view models): how an output pixel becomes a camera-space direction.
//!
//! The formulas are exactly those of `docs/conventions.md` ("Output projections"). For
//! output pixel centre (x + ½, y + ½) of a W × H image, `px = x + ½ − W/2` and
//! `py = H/2 − (y + ½)` (right and up), `ρ = √(px² + py²)`, and θ is the angle of the
//! direction from the view axis Z:
//!
//! | projection | radius ↔ angle | f from hfov | hfov range |
//! |---|---|---|---|
//! | rectilinear | ρ = f tan θ | (W/2) / tan(hfov/2) | (0, 180) |
//! | stereographic | ρ = 2f tan(θ/2) | (W/2) / (2 tan(hfov/4)) | (0, 360) |
//! | fisheye (equidistant) | ρ = f θ | (W/2) / (hfov/2) | (0, 360] |
//! | equisolid | ρ = 2f sin(θ/2) | (W/2) / (2 sin(hfov/4)) | (0, 360] |
//!
//! Pannini (parameter d ≥ 0; d = 0 is rectilinear, d = 1 the classic) works on azimuth
//! φ and elevation ε: `S = (d + 1)/(d + cos φ)`, `px = f S sin φ`, `py = f S tan ε`,
//! `f = (W/2)(d + cos(hfov/2)) / ((d + 1) sin(hfov/2))`. Its hfov range is
//! `(0, 2·acos(−min(d, 1/d)))`: for d ≤ 1 the conventions' `2·acos(−d)`; for d > 1 the
//! horizontal mapping `S sin φ` turns back at `cos φ = −1/d` (where its inverse's square
//! root vanishes), so a wider hfov would put the frame's edge on the far branch, which the
//! inverse cannot reach: the range stops where the edge is still at hfov/2.
//!
//! A pixel whose radius has no angle (fisheye θ > π, equisolid ρ > 2f, Pannini with
//! d > 1 beyond the turning point) has no direction: it shows the background.

use crate::error::ViewError;
use crate::named::{parse_name, unknown_name, Named};
use glam::DVec3;
use std::f64::consts::PI;

/// How output pixels map to directions around the view axis (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ViewProjection {
    /// The pinhole camera: straight lines stay straight (hfov below 180°).
    #[default]
    Rectilinear,
    /// Conformal; at pitch −90° with a wide hfov, the "little planet" (hfov below 360°).
    Stereographic,
    /// Equidistant fisheye: radius proportional to the angle (hfov up to 360°).
    Fisheye,
    /// Equal-area fisheye (hfov up to 360°).
    Equisolid,
    /// Pannini with parameter d ≥ 0 (0: rectilinear, 1: classic): vertical lines stay
    /// vertical at pitch 0, wide views without rectilinear stretching.
    Pannini(f64),
}

/// Pannini's classic parameter, the default of `--pannini-d`.
pub const PANNINI_D_DEFAULT: f64 = 1.0;

/// Largest Pannini parameter accepted (far beyond it the projection is a cylinder to
/// within rounding; the limit keeps `f` well conditioned).
pub const PANNINI_D_MAX: f64 = 1000.0;

impl ViewProjection {
    /// The name used on the command line (see [`crate::Named`]).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }

    /// True for the pinhole camera, the only scanline-coherent projection (the LUT and
    /// the cube scanline renderer draw only these views).
    pub fn is_rectilinear(self) -> bool {
        match self {
            ViewProjection::Rectilinear => true,
            ViewProjection::Pannini(d) => d == 0.0,
            _ => false,
        }
    }

    /// The same projection with Pannini's parameter set to `d` (others unchanged).
    pub fn with_pannini_d(self, d: f64) -> ViewProjection {
        match self {
            ViewProjection::Pannini(_) => ViewProjection::Pannini(d),
            p => p,
        }
    }

    /// Pannini's parameter, or `None` for the other projections.
    pub fn pannini_d(self) -> Option<f64> {
        match self {
            ViewProjection::Pannini(d) => Some(d),
            _ => None,
        }
    }

    /// The largest hfov in degrees and whether it is included: `(180, false)` for
    /// rectilinear, `(360, true)` for fisheye and equisolid, …
    pub fn hfov_max(self) -> (f64, bool) {
        match self {
            ViewProjection::Rectilinear => (180.0, false),
            ViewProjection::Stereographic => (360.0, false),
            ViewProjection::Fisheye | ViewProjection::Equisolid => (360.0, true),
            ViewProjection::Pannini(d) => {
                let m = if d <= 1.0 { d } else { 1.0 / d };
                // Rounded to 1e-9° so that 240 reads 240 (acos rounding gives 240.00…03).
                let max = 2.0 * (-m).acos().to_degrees();
                ((max * 1e9).round() / 1e9, false)
            }
        }
    }

    /// Check the projection's parameter and that `hfov_deg` is in its range.
    ///
    /// # Errors
    /// [`ViewError::BadPanniniD`] for a negative, non-finite or huge d;
    /// [`ViewError::HfovOutOfRange`] (rectilinear) or [`ViewError::HfovForProjection`]
    /// (the others) for an hfov outside the projection's range.
    pub fn check(self, hfov_deg: f64) -> Result<(), ViewError> {
        if let ViewProjection::Pannini(d) = self {
            if !(d.is_finite() && (0.0..=PANNINI_D_MAX).contains(&d)) {
                return Err(ViewError::BadPanniniD {
                    d,
                    max: PANNINI_D_MAX,
                });
            }
        }
        let (max, inclusive) = self.hfov_max();
        let mut ok = hfov_deg > 0.0 && (hfov_deg < max || (inclusive && hfov_deg == max));
        if let ViewProjection::Pannini(_) = self {
            // Within a rounding of the widest, the focal length vanishes: refuse that too.
            let f = self.focal(1000, hfov_deg.to_radians());
            ok &= f.is_finite() && f > 1e-9;
        }
        if !ok && self == ViewProjection::Rectilinear {
            return Err(ViewError::HfovOutOfRange(hfov_deg));
        }
        if !ok {
            return Err(ViewError::HfovForProjection {
                hfov: hfov_deg,
                projection: self.name(),
                max,
                inclusive,
            });
        }
        Ok(())
    }

    /// Focal length f in pixels for an output `width` pixels wide and `hfov` radians, so
    /// that the left and right edges through the centre row are at ±hfov/2.
    pub fn focal(self, width: u32, hfov: f64) -> f64 {
        let half_w = width as f64 / 2.0;
        match self {
            ViewProjection::Rectilinear => half_w / (hfov / 2.0).tan(),
            ViewProjection::Stereographic => half_w / (2.0 * (hfov / 4.0).tan()),
            ViewProjection::Fisheye => half_w / (hfov / 2.0),
            ViewProjection::Equisolid => half_w / (2.0 * (hfov / 4.0).sin()),
            ViewProjection::Pannini(d) => {
                let (s, c) = (hfov / 2.0).sin_cos();
                half_w * (d + c) / ((d + 1.0) * s)
            }
        }
    }

    /// The largest radius (pixels from the image centre) with a direction, for the
    /// radial projections that have one (fisheye: f·π, equisolid: 2f); `None` when every
    /// radius has one.
    pub fn max_radius(self, f: f64) -> Option<f64> {
        match self {
            ViewProjection::Fisheye => Some(f * PI),
            ViewProjection::Equisolid => Some(2.0 * f),
            _ => None,
        }
    }

    /// Pannini with d > 1: the largest |px| with a direction, `f (d + 1)/√(d² − 1)`
    /// (where the inverse's square root vanishes); `None` otherwise.
    pub fn max_abs_px(self, f: f64) -> Option<f64> {
        match self {
            ViewProjection::Pannini(d) if d > 1.0 => Some(f * (d + 1.0) / (d * d - 1.0).sqrt()),
            _ => None,
        }
    }

    /// Camera-space direction (X right, Y up, Z forward; not normalized) of the image
    /// point `(px, py)` (pixels from the image centre, y up) for focal length `f`, or
    /// `None` where the projection has no direction.
    #[inline]
    pub fn direction(self, f: f64, px: f64, py: f64) -> Option<DVec3> {
        match self {
            ViewProjection::Rectilinear => Some(DVec3::new(px, py, f)),
            ViewProjection::Pannini(d) => pannini_direction(d, f, px, py),
            _ => {
                let rho = px.hypot(py);
                if rho == 0.0 {
                    return Some(DVec3::Z);
                }
                let r = rho / f;
                let theta = match self {
                    ViewProjection::Stereographic => 2.0 * (r * 0.5).atan(),
                    ViewProjection::Fisheye => {
                        if r > PI {
                            return None;
                        }
                        r
                    }
                    _ => {
                        // Equisolid.
                        if r > 2.0 {
                            return None;
                        }
                        2.0 * (r * 0.5).asin()
                    }
                };
                let (s, c) = theta.sin_cos();
                Some(DVec3::new(s * px / rho, s * py / rho, c))
            }
        }
    }

    /// The inverse of [`ViewProjection::direction`]: image point `(px, py)` (from the
    /// centre, y up) of a camera-space direction, or `None` where the projection does not
    /// show it (behind a rectilinear camera, the antipode of the view axis, …).
    pub fn image_point(self, f: f64, d: DVec3) -> Option<(f64, f64)> {
        match self {
            ViewProjection::Rectilinear => (d.z > 0.0).then(|| (f * d.x / d.z, f * d.y / d.z)),
            ViewProjection::Pannini(k) => {
                let horiz = d.x.hypot(d.z);
                let cos_phi = d.z / horiz;
                // 1 + cos φ without cancellation behind the camera: sin²φ / (1 − cos φ).
                let one_plus_cos = if d.z >= 0.0 {
                    1.0 + cos_phi
                } else {
                    d.x * d.x / (horiz * (horiz - d.z))
                };
                // On the invertible branch only (see the module docs): S finite for
                // d ≤ 1, up to the turning point cos φ = −1/d for d > 1.
                let shown = if k > 1.0 {
                    cos_phi >= -1.0 / k
                } else {
                    cos_phi > -k
                };
                if !shown || horiz == 0.0 {
                    return None;
                }
                let s = (k + 1.0) / ((k - 1.0) + one_plus_cos);
                Some((f * s * d.x / horiz, f * s * d.y / horiz))
            }
            _ => {
                let r = d.x.hypot(d.y);
                let theta = r.atan2(d.z);
                let rho = match self {
                    ViewProjection::Stereographic => {
                        if theta >= PI {
                            return None;
                        }
                        2.0 * f * (theta / 2.0).tan()
                    }
                    ViewProjection::Fisheye => f * theta,
                    _ => 2.0 * f * (theta / 2.0).sin(),
                };
                if r == 0.0 {
                    return (d.z > 0.0).then_some((0.0, 0.0));
                }
                Some((rho * d.x / r, rho * d.y / r))
            }
        }
    }
}

/// Pannini's inverse (conventions): `X = px/f`, `Y = py/f`, `k = X²/(d + 1)²`,
/// `cos φ = (−k d + √D)/(k + 1)` with `D = k²d² − (k + 1)(k d² − 1) = 1 + k(1 − d²)`,
/// `S = (d + 1)/(d + cos φ)`, `sin φ = X/S`, `tan ε = Y/S`; the direction is
/// `(sin φ, tan ε, cos φ)`.
///
/// Evaluated in forms without cancellation (equal in exact arithmetic): `cos φ =
/// (1 − k d²)/(k d + √D)` (the numerator times its conjugate is `(k + 1)(1 − k d²)`) and
/// `d + cos φ = (d + √D)/(k + 1)`; near the widest hfov `cos φ → −d` and the textbook
/// forms lose most digits.
#[inline]
fn pannini_direction(d: f64, f: f64, px: f64, py: f64) -> Option<DVec3> {
    let x = px / f;
    let y = py / f;
    let k = x * x / ((d + 1.0) * (d + 1.0));
    let disc = 1.0 + k * (1.0 - d * d);
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let cos_phi = ((1.0 - k * d * d) / (k * d + root)).clamp(-1.0, 1.0);
    let s = (d + 1.0) * (k + 1.0) / (d + root);
    if !(s.is_finite() && s > 0.0) {
        return None;
    }
    Some(DVec3::new(x / s, y / s, cos_phi))
}

impl std::fmt::Display for ViewProjection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ViewProjection::Pannini(d) => write!(f, "pannini (d = {d})"),
            p => f.write_str(p.name()),
        }
    }
}

impl std::str::FromStr for ViewProjection {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.to_ascii_lowercase();
        parse_name(&s)
            .or(match s.as_str() {
                "perspective" => Some(ViewProjection::Rectilinear),
                "little-planet" | "planet" => Some(ViewProjection::Stereographic),
                "equidistant" => Some(ViewProjection::Fisheye),
                "panini" => Some(ViewProjection::Pannini(PANNINI_D_DEFAULT)),
                _ => None,
            })
            .ok_or_else(|| unknown_name::<ViewProjection>("view projection", &s))
    }
}

impl Named for ViewProjection {
    const ALL: &'static [Self] = &[
        ViewProjection::Rectilinear,
        ViewProjection::Stereographic,
        ViewProjection::Fisheye,
        ViewProjection::Equisolid,
        ViewProjection::Pannini(PANNINI_D_DEFAULT),
    ];
    fn name(self) -> &'static str {
        match self {
            ViewProjection::Rectilinear => "rectilinear",
            ViewProjection::Stereographic => "stereographic",
            ViewProjection::Fisheye => "fisheye",
            ViewProjection::Equisolid => "equisolid",
            ViewProjection::Pannini(_) => "pannini",
        }
    }
    fn help(self) -> &'static str {
        match self {
            ViewProjection::Rectilinear => "Pinhole camera, straight lines straight (hfov < 180)",
            ViewProjection::Stereographic => {
                "Stereographic; pitch -90 and a wide hfov give the little planet (hfov < 360)"
            }
            ViewProjection::Fisheye => "Equidistant fisheye (hfov <= 360)",
            ViewProjection::Equisolid => "Equal-area fisheye (hfov <= 360)",
            ViewProjection::Pannini(_) => {
                "Pannini with --pannini-d D (0: rectilinear, 1: classic); verticals stay vertical"
            }
        }
    }
}

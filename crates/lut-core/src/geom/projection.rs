//! Environment-map projections on surfaces of revolution: direction (λ, φ) ↔ map (u, v).
//!
//! Pure math, no pixels. Formulas are exactly those of `docs/conventions.md`:
//!
//! | projection | u | v |
//! |---|---|---|
//! | equirectangular | (λ + π) / 2π · W | (π/2 − φ) / π · H |
//! | cylindrical | (λ + π) / 2π · W | H/2 − r · tan φ, r = W / 2π |
//! | sine | (λ + π) / 2π · W | H/2 · (1 − sin φ) |
//! | elliptical | W/2 + cos φ · λ / 2π · W | (π/2 − φ) / π · H |
//! | diamond | W/2 + (1 − \|φ\| / (π/2)) · λ / 2π · W | (π/2 − φ) / π · H |
//!
//! Every projection is written as `v = H/2 − V(φ)` with an odd *profile* `V`, and
//! `u = W/2 + s(φ) · Λ` with `Λ = λ · W / 2π` and a per-row scale `s` (1 for the
//! rectangular maps). The LUT stores `(Λ, V)`; both are odd in their angle, which is what
//! makes the patent's one-eighth symmetry work for every projection here.

use crate::named::{parse_name, unknown_name, Named};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::fmt;
use std::str::FromStr;

/// The surface of revolution an environment map was sampled on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Projection {
    /// Spherical, latitude/longitude (2:1).
    Equirect,
    /// Cylindrical: `v = H/2 − r tan φ`, limited vertical coverage.
    Cylinder,
    /// Sine distribution (equal-area): `v = H/2 (1 − sin φ)`.
    Sine,
    /// Elliptical (sinusoidal): scanlines scaled by `cos φ`.
    Elliptical,
    /// Diamond: scanlines scaled linearly to 0 at the poles.
    Diamond,
}

impl Projection {
    /// All projections, in documentation order.
    pub const ALL: [Projection; 5] = [
        Projection::Equirect,
        Projection::Cylinder,
        Projection::Sine,
        Projection::Elliptical,
        Projection::Diamond,
    ];

    /// The lower-case name used on the command line (see [`crate::Named`]).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }

    /// True when map rows are 360° of longitude end to end, so sampling wraps in u.
    /// Elliptical and diamond rows are shorter than the image: they clamp instead.
    pub fn wraps(self) -> bool {
        matches!(
            self,
            Projection::Equirect | Projection::Cylinder | Projection::Sine
        )
    }

    /// True when every direction has a map position (all but the cylinder).
    pub fn full_sphere(self) -> bool {
        !matches!(self, Projection::Cylinder)
    }

    /// True when u depends on φ as well as λ (elliptical, diamond).
    pub fn scaled_rows(self) -> bool {
        matches!(self, Projection::Elliptical | Projection::Diamond)
    }

    /// The odd profile `V(φ)` in map pixels, positive up: `v = H/2 − V(φ)`.
    #[inline]
    pub fn profile(self, phi: f64, w: f64, h: f64) -> f64 {
        match self {
            Projection::Equirect | Projection::Elliptical | Projection::Diamond => phi / PI * h,
            Projection::Cylinder => w / TAU * phi.tan(),
            Projection::Sine => h * 0.5 * phi.sin(),
        }
    }

    /// The row scale `s(φ)`: `u = W/2 + s(φ) · λ / 2π · W`.
    #[inline]
    pub fn row_scale(self, phi: f64) -> f64 {
        match self {
            Projection::Elliptical => phi.cos().max(0.0),
            Projection::Diamond => (1.0 - phi.abs() / FRAC_PI_2).max(0.0),
            _ => 1.0,
        }
    }

    /// The row scale as a function of the map row coordinate `v` (used per pixel by the
    /// LUT renderer, which interpolates `v`, not φ).
    #[inline]
    pub fn row_scale_at_v(self, v: f64, h: f64) -> f64 {
        let phi = FRAC_PI_2 - v / h * PI;
        self.row_scale(phi)
    }

    /// Maximum |φ| this map covers, radians.
    pub fn max_latitude(self, w: f64, h: f64) -> f64 {
        match self {
            Projection::Cylinder => (h / 2.0 / (w / TAU)).atan(),
            _ => FRAC_PI_2,
        }
    }

    /// Map position (u, v) in continuous pixel coordinates of a direction, or `None`
    /// when the map does not cover it (above or below a cylinder).
    ///
    /// `lambda` may be any real longitude; it is reduced to (−π, π].
    #[inline]
    pub fn uv(self, lambda: f64, phi: f64, w: f64, h: f64) -> Option<(f64, f64)> {
        let lambda = wrap_pi(lambda);
        let v = h * 0.5 - self.profile(phi, w, h);
        if !self.full_sphere() && !(0.0..=h).contains(&v) {
            return None;
        }
        let u = w * 0.5 + self.row_scale(phi) * lambda / TAU * w;
        Some((u, v))
    }

    /// The inverse: direction (λ, φ) of a map position, or `None` outside the map's
    /// valid area (outside the ellipse/diamond, or outside the image).
    pub fn direction(self, u: f64, v: f64, w: f64, h: f64) -> Option<(f64, f64)> {
        if !(0.0..=h).contains(&v) || !(0.0..=w).contains(&u) {
            return None;
        }
        let big_v = h * 0.5 - v;
        let phi = match self {
            Projection::Equirect | Projection::Elliptical | Projection::Diamond => big_v / h * PI,
            Projection::Cylinder => (big_v / (w / TAU)).atan(),
            Projection::Sine => (big_v / (h * 0.5)).clamp(-1.0, 1.0).asin(),
        };
        let s = self.row_scale(phi);
        if s <= 0.0 {
            return Some((0.0, phi));
        }
        let lambda = (u - w * 0.5) / w * TAU / s;
        if lambda.abs() > PI + 1e-12 {
            return None;
        }
        Some((lambda.clamp(-PI, PI), phi))
    }

    /// Bounds `(max |dV/dφ|, max |d²V/dφ²|)` in map pixels over the covered latitudes;
    /// used to bound index-interpolation error.
    pub fn profile_derivative_bounds(self, w: f64, h: f64) -> (f64, f64) {
        match self {
            Projection::Equirect | Projection::Elliptical | Projection::Diamond => (h / PI, 0.0),
            Projection::Sine => (h * 0.5, h * 0.5),
            Projection::Cylinder => {
                let r = w / TAU;
                let m = self.max_latitude(w, h);
                let sec2 = 1.0 / (m.cos() * m.cos());
                (r * sec2, 2.0 * r * sec2 * m.tan())
            }
        }
    }

    /// How much a v error turns into a u error through the row scale, at most
    /// (`(W/2) · max |ds/dv|`): 0 for rectangular maps.
    pub fn row_scale_coupling(self, w: f64, h: f64) -> f64 {
        match self {
            Projection::Elliptical => w * 0.5 * PI / h,
            Projection::Diamond => w * 0.5 * 2.0 / h,
            _ => 0.0,
        }
    }
}

impl fmt::Display for Projection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Projection {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        // The names in any case, and a few aliases.
        let s = s.to_ascii_lowercase();
        parse_name(&s)
            .or(match s.as_str() {
                "equirectangular" | "spherical" | "sphere" => Some(Projection::Equirect),
                "cylindrical" => Some(Projection::Cylinder),
                "sinusoidal" => Some(Projection::Elliptical),
                _ => None,
            })
            .ok_or_else(|| unknown_name::<Projection>("projection", &s))
    }
}

impl Named for Projection {
    const ALL: &'static [Self] = &Projection::ALL;
    fn name(self) -> &'static str {
        match self {
            Projection::Equirect => "equirect",
            Projection::Cylinder => "cylinder",
            Projection::Sine => "sine",
            Projection::Elliptical => "elliptical",
            Projection::Diamond => "diamond",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Projection::Equirect => "Spherical, latitude/longitude (2:1)",
            Projection::Cylinder => "Cylindrical: limited vertical coverage",
            Projection::Sine => "Sine distribution (equal-area)",
            Projection::Elliptical => "Elliptical (sinusoidal): rows scaled by cos(latitude)",
            Projection::Diamond => "Diamond: rows scaled linearly to 0 at the poles",
        }
    }
}

/// Reduce an angle to (−π, π].
#[inline]
pub fn wrap_pi(a: f64) -> f64 {
    if a > -PI && a <= PI {
        return a;
    }
    let r = a.rem_euclid(TAU);
    if r > PI {
        r - TAU
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn center_of_map_is_lon0_lat0() {
        for p in Projection::ALL {
            let (u, v) = p.uv(0.0, 0.0, 2000.0, 1000.0).unwrap();
            assert!((u - 1000.0).abs() < 1e-9 && (v - 500.0).abs() < 1e-9, "{p}");
        }
    }

    #[test]
    fn round_trip_direction() {
        let (w, h) = (4096.0, 2048.0);
        for p in Projection::ALL {
            for i in 0..50 {
                let lam = -3.1 + i as f64 * 0.124;
                let phi = -1.2 + i as f64 * 0.048;
                let Some((u, v)) = p.uv(lam, phi, w, h) else {
                    continue;
                };
                let (l2, p2) = p.direction(u, v, w, h).unwrap();
                assert!((l2 - lam).abs() < 1e-9, "{p} lam {lam} {l2}");
                assert!((p2 - phi).abs() < 1e-9, "{p} phi {phi} {p2}");
            }
        }
    }

    #[test]
    fn cylinder_coverage() {
        let p = Projection::Cylinder;
        assert!(p.uv(0.0, 1.5, 2000.0, 600.0).is_none());
        assert!(p.uv(0.0, 0.1, 2000.0, 600.0).is_some());
    }

    #[test]
    fn wrap_pi_range() {
        for a in [-10.0, -PI, -PI + 1e-9, 0.0, PI, 7.0, 1e9, -1e9] {
            let w = wrap_pi(a);
            assert!(w > -PI && w <= PI, "{a} -> {w}");
            assert!(((w - a) / TAU - ((w - a) / TAU).round()).abs() < 1e-6);
        }
    }
}

//! Procedural test maps: a latitude/longitude grid over a colour field, so seams, poles
//! and lines show. Generated for any projection by evaluating one function of direction
//! at each map pixel's center, so the same scene can be rendered from every projection.

use crate::error::MapError;
use crate::geom::projection::Projection;
use crate::map::envmap::EnvMap;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The test scene's colour in direction (λ, φ) (0RGB): a smooth hue field by longitude
/// and a brightness ramp by latitude, with dark grid lines every 15° (10° of latitude),
/// a white line on the meridian λ = 0 and a red one at the ±180° seam.
pub fn scene_color(lambda: f64, phi: f64) -> u32 {
    let l = lambda.to_degrees();
    let p = phi.to_degrees();
    let line = |v: f64, every: f64, width: f64| {
        let m = v.rem_euclid(every);
        m < width || m > every - width
    };
    if l.abs() < 0.4 {
        return 0xFFFFFF;
    }
    if l.abs() > 179.6 {
        return 0xFF2020;
    }
    let near_pole = p.abs() > 80.0;
    if (!near_pole && line(l, 15.0, 0.4)) || line(p, 10.0, 0.3) {
        return 0x202020;
    }
    let h = (lambda + PI) / (2.0 * PI);
    let bright = 0.55 + 0.45 * (phi / PI + 0.5);
    let r = 0.5 + 0.5 * (2.0 * PI * h).cos();
    let g = 0.5 + 0.5 * (2.0 * PI * (h - 1.0 / 3.0)).cos();
    let b = 0.5 + 0.5 * (2.0 * PI * (h - 2.0 / 3.0)).cos();
    let c = |x: f64| ((x * bright).clamp(0.0, 1.0) * 255.0).round() as u32;
    c(r) << 16 | c(g) << 8 | c(b)
}

/// A `w × h` map of [`scene_color`] in `projection`; pixels outside an elliptical or
/// diamond map's valid area are black.
///
/// # Errors
/// [`MapError::Size`] for unsupported sizes.
pub fn grid_map(w: u32, h: u32, projection: Projection) -> Result<EnvMap, MapError> {
    crate::map::envmap::check_map_size("generated map", w, h)?;
    let (wf, hf) = (w as f64, h as f64);
    let mut px = vec![0u32; w as usize * h as usize];
    px.par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, p) in row.iter_mut().enumerate() {
                *p = match projection.direction(x as f64 + 0.5, y as f64 + 0.5, wf, hf) {
                    Some((l, ph)) => scene_color(l, ph),
                    None => 0,
                };
            }
        });
    EnvMap::from_pixels(w, h, &px, projection)
}

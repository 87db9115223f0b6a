//! Measuring a renderer's sampling positions against the exact map.
//!
//! **The metric.** The sampling-position error of a pixel is the distance, in source
//! pixels, between the map position (u, v) a renderer sampled and the exact one, with the
//! u difference taken around the wrap (for 360° maps) and scaled by `cos φ / s(φ)` (`s` is
//! the projection's row scale, 1 for rectangular maps). The scale turns a longitude error
//! into the same angle measured in pixels at the map's equator: near a pole a whole map
//! row is almost one direction, so an unscaled u error there says nothing about the image.
//! Both the scaled ("angular") and the raw distances are reported.

use crate::geom::camera::{Camera, View};
use crate::geom::mapping::exact_uv;
use crate::geom::projection::Projection;
use rayon::prelude::*;

/// Angular-metric position error of `got` against `exact` at latitude `phi`.
#[inline]
pub fn position_error(
    p: Projection,
    w: f64,
    _h: f64,
    phi: f64,
    exact: (f64, f64),
    got: (f64, f64),
) -> f64 {
    let s = p.row_scale(phi);
    let du = wrap_du(p, w, s, got.0 - exact.0);
    let dv = got.1 - exact.1;
    ((du * u_scale(p, phi)).powi(2) + dv * dv).sqrt()
}

/// The factor the metric scales a u difference by at latitude `phi`: `cos φ / s(φ)`
/// (at most 2; 1 where the row scale vanishes).
#[inline]
pub(crate) fn u_scale(p: Projection, phi: f64) -> f64 {
    let s = p.row_scale(phi);
    if s > 1e-9 {
        (phi.cos() / s).min(2.0)
    } else {
        1.0
    }
}

/// A u difference reduced around the row's wrap: W for 360° maps, s(φ)·W for elliptical
/// and diamond rows (λ = −π and λ = +π are the same direction at opposite row ends).
#[inline]
fn wrap_du(p: Projection, w: f64, s: f64, du: f64) -> f64 {
    let period = if p.wraps() {
        w
    } else if p.scaled_rows() {
        s * w
    } else {
        return du;
    };
    if period <= 0.0 {
        return 0.0; // the pole row of a scaled map is a single point
    }
    du - (du / period).round() * period
}

/// Raw (unscaled) position error, wrap-aware.
#[inline]
pub fn raw_error(p: Projection, w: f64, phi: f64, exact: (f64, f64), got: (f64, f64)) -> f64 {
    let du = wrap_du(p, w, p.row_scale(phi), got.0 - exact.0);
    let dv = got.1 - exact.1;
    (du * du + dv * dv).sqrt()
}

/// Summary of sampling-position errors over a frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ErrorStats {
    /// Pixels compared.
    pub count: u64,
    /// Max angular-metric error, source pixels.
    pub max: f64,
    /// Mean angular-metric error.
    pub mean: f64,
    /// Max raw (unscaled u) error.
    pub max_raw: f64,
    /// Pixels where one side had a map position and the other showed background.
    pub coverage_mismatch: u64,
    /// Output pixel with the largest error.
    pub worst_pixel: (u32, u32),
}

impl ErrorStats {
    /// Merge another frame's stats into this one.
    pub fn merge(&mut self, o: &ErrorStats) {
        let n = self.count + o.count;
        if n > 0 {
            self.mean = (self.mean * self.count as f64 + o.mean * o.count as f64) / n as f64;
        }
        self.count = n;
        if o.max > self.max {
            self.max = o.max;
            self.worst_pixel = o.worst_pixel;
        }
        self.max_raw = self.max_raw.max(o.max_raw);
        self.coverage_mismatch += o.coverage_mismatch;
    }
}

/// Compare per-pixel positions (row-major, `None` = background) against the exact map of
/// `view` for a map of `map_w × map_h` in projection `p` (the summary of
/// [`position_errors`]).
pub fn compare_positions(
    positions: &[Option<(f64, f64)>],
    view: View,
    width: u32,
    height: u32,
    p: Projection,
    map_w: u32,
    map_h: u32,
) -> ErrorStats {
    position_errors(positions, view, width, height, p, map_w, map_h).1
}

/// Per-pixel sampling-position errors of `positions` (row-major, `None` = background)
/// against the exact map of `view`, and their summary: `Some(error)` (angular metric,
/// source pixels) where both have a map position, `Some(∞)` where only one has (a
/// coverage mismatch, unless the covered side is within half a pixel of the map's edge:
/// then `None`), `None` where both show the background. Rows run in parallel; the
/// summary merges them in row order, so it does not depend on the thread count.
pub fn position_errors(
    positions: &[Option<(f64, f64)>],
    view: View,
    width: u32,
    height: u32,
    p: Projection,
    map_w: u32,
    map_h: u32,
) -> (Vec<Option<f64>>, ErrorStats) {
    let cam = Camera::new(view, width, height);
    let (w, h) = (map_w as f64, map_h as f64);
    let mut errors = vec![None; width as usize * height as usize];
    let rows: Vec<ErrorStats> = errors
        .par_chunks_mut(width.max(1) as usize)
        .enumerate()
        .map(|(y, row)| {
            let y = y as u32;
            let mut st = ErrorStats::default();
            let mut sum = 0.0;
            for (x, e) in row.iter_mut().enumerate() {
                let x = x as u32;
                let got = positions[(y * width + x) as usize];
                st.count += 1;
                match (exact_uv(&cam, p, w, h, x, y), got) {
                    (Some(ex), Some(g)) => {
                        let phi = cam.pixel_lat_long(x, y).map_or(0.0, |d| d.1);
                        let err = position_error(p, w, h, phi, ex, g);
                        sum += err;
                        if err > st.max || !err.is_finite() {
                            st.max = if err.is_finite() { err } else { f64::INFINITY };
                            st.worst_pixel = (x, y);
                        }
                        st.max_raw = st.max_raw.max(raw_error(p, w, phi, ex, g));
                        *e = Some(err);
                    }
                    (None, None) => {}
                    (Some(c), None) | (None, Some(c)) => {
                        // Only a mismatch if the covered side is not right at the edge.
                        if !(c.1 < 0.5 || c.1 > h - 0.5) {
                            st.coverage_mismatch += 1;
                            *e = Some(f64::INFINITY);
                        }
                    }
                }
            }
            if st.count > 0 {
                st.mean = sum / st.count as f64;
            }
            st
        })
        .collect();
    let mut st = ErrorStats::default();
    for r in &rows {
        st.merge(r);
    }
    (errors, st)
}

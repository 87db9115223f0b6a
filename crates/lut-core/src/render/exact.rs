//! The exact renderer: per output pixel, f64 ray → (λ, φ) → (u, v) → sample.
//!
//! Plain and obviously right on purpose: it is the yardstick every fast path is measured
//! against. It shares only the sampler with the LUT renderer (so image differences are
//! geometry differences).

use super::frame::Frame;
use super::rows::for_each_row;
use super::setup::MapGeometry;
use crate::geom::camera::{Camera, View};
use crate::geom::fixed::to_fx;
use crate::geom::mapping::{exact_uv, exact_uv_at};
use crate::geom::projection::Projection;
use crate::map::envmap::EnvMap;
use crate::map::pyramid::lod_q8;
use crate::map::sample::Sampler;

/// Sample `map` at an f64 position, wrapping u for 360° maps (background if uncovered).
#[inline]
pub fn sample_at(map: &EnvMap, sampler: Sampler, uv: Option<(f64, f64)>) -> u32 {
    match uv {
        None => map.background(),
        Some((u, v)) => map.sample(sampler, to_fx(wrap_u(map, u)), to_fx(v)),
    }
}

/// Wrap u into [0, W) for 360° maps (f64 rounding can give W itself: that is 0).
fn wrap_u(map: &EnvMap, u: f64) -> f64 {
    let w = map.width() as f64;
    if map.projection().wraps() {
        let r = u.rem_euclid(w);
        if r >= w {
            0.0
        } else {
            r
        }
    } else {
        u
    }
}

/// [`sample_at`] with the trilinear sampler at level of detail `lod` (Q.8, see
/// `map/pyramid.rs`).
#[inline]
pub fn sample_at_lod(map: &EnvMap, uv: Option<(f64, f64)>, lod: i32) -> u32 {
    match uv {
        None => map.background(),
        Some((u, v)) => map.trilinear(to_fx(wrap_u(map, u)), to_fx(v), lod),
    }
}

/// [`sample_at`] bilinear on pyramid level `k` (a level the map has; 0: the map, as
/// [`sample_at`] with [`Sampler::Bilinear`], byte for byte), at the level-0 position `at`.
#[inline]
pub(crate) fn sample_at_level(map: &EnvMap, at: (f64, f64), k: u32) -> u32 {
    if k == 0 {
        return sample_at(map, Sampler::Bilinear, Some(at));
    }
    map.level_bilinear(k, to_fx(wrap_u(map, at.0)), to_fx(at.1))
}

/// The exact level of detail of single pixels: the camera and map geometry of a frame.
/// The exact renderer's trilinear pixels, and the pixels the LUT and grid renderers
/// evaluate exactly (pole zones, beyond a table, cells at a disc's edge), take their level
/// of detail from it, so such a pixel is the exact renderer's pixel.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ExactFootprint {
    pub(crate) cam: Camera,
    pub(crate) proj: Projection,
    pub(crate) mw: f64,
    pub(crate) mh: f64,
}

impl ExactFootprint {
    /// For `view` of `map` on a `width × height` output.
    pub(crate) fn new(view: View, width: u32, height: u32, map: MapGeometry) -> Self {
        ExactFootprint {
            cam: Camera::new(view, width, height),
            proj: map.projection,
            mw: map.width as f64,
            mh: map.height as f64,
        }
    }

    /// Exact pixel footprint at image point (x, y) with exact position `at`: the larger
    /// of the map-pixel distances to the exact positions of the points one pixel to the
    /// right and one below (u differences taken the short way round the seam).
    pub(crate) fn footprint(&self, x: f64, y: f64, at: (f64, f64)) -> f64 {
        let (u0, v0) = at;
        let mut f: f64 = 0.0;
        for (dx, dy) in [(1.0, 0.0), (0.0, 1.0)] {
            if let Some((u, v)) =
                exact_uv_at(&self.cam, self.proj, self.mw, self.mh, x + dx, y + dy)
            {
                let mut du = (u - u0).abs();
                if self.proj.wraps() && du > self.mw * 0.5 {
                    du = self.mw - du;
                }
                f = f.max(du).max((v - v0).abs());
            }
        }
        f
    }

    /// The footprint at image point (x, y) with exact position `at` from the derivative of
    /// the mapping instead of the positions one pixel away ([`ExactFootprint::footprint`]
    /// takes two more exact positions, four `atan2`): the larger over the two screen axes
    /// of max(|dΛ|, |dV|) per pixel, dλ and dφ from the ray and its change per pixel
    /// (the ray is linear in the pixel), V's slope from the projection. Equal to the
    /// footprint to first order; near a pole (where the positions one pixel away wrap
    /// round it) it is larger. For rectilinear views of equirectangular, sine and
    /// cylindrical maps (rows that do not scale); the others take
    /// [`ExactFootprint::footprint`]. (`Renderer::set_region_lod`'s exact pixels.)
    pub(crate) fn derivative(&self, x: f64, y: f64, at: (f64, f64)) -> f64 {
        self.derivative_of(x, y)
            .unwrap_or_else(|| self.footprint(x, y, at))
    }

    /// [`ExactFootprint::derivative`] without the exact position: `None` for the views
    /// and maps it does not cover.
    pub(crate) fn derivative_of(&self, x: f64, y: f64) -> Option<f64> {
        let slope = match self.proj {
            Projection::Equirect | Projection::Sine | Projection::Cylinder
                if self.cam.view().projection().is_rectilinear() =>
            {
                self.proj
            }
            _ => return None,
        };
        let d = self.cam.world_ray(x, y);
        let r2 = d.x * d.x + d.z * d.z;
        let n2 = r2 + d.y * d.y;
        let r = r2.sqrt();
        // (On the axis through the poles: r is 0, or NaN for a NaN ray.)
        if r.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Some(f64::INFINITY);
        }
        // dV/dφ: H/π; (H/2)·cos φ; (W/2π)/cos² φ (cos φ = r/|d|).
        let dv_dphi = match slope {
            Projection::Sine => self.mh * 0.5 * r / n2.sqrt(),
            Projection::Cylinder => self.mw / std::f64::consts::TAU * n2 / r2,
            _ => self.mh / std::f64::consts::PI,
        };
        let lam_px = self.mw / std::f64::consts::TAU;
        let mut f: f64 = 0.0;
        for dd in [
            self.cam.world_ray(x + 1.0, y) - d,
            self.cam.world_ray(x, y + 1.0) - d,
        ] {
            let dl = (d.z * dd.x - d.x * dd.z) / r2;
            let dphi = (dd.y * r2 - d.y * (d.x * dd.x + d.z * dd.z)) / (n2 * r);
            f = f.max((dl * lam_px).abs()).max((dphi * dv_dphi).abs());
        }
        Some(f)
    }

    /// The level of detail (Q.8) of pixel (x, y) whose exact position is `uv` (0 where the
    /// map does not cover it).
    #[inline]
    pub(crate) fn lod(&self, x: usize, y: usize, uv: Option<(f64, f64)>) -> i32 {
        uv.map_or(0, |at| {
            lod_q8(self.footprint(x as f64 + 0.5, y as f64 + 0.5, at))
        })
    }
}

/// Render `view` of `map` into `frame`, exactly (also reached through
/// [`crate::Renderer::render`] with [`crate::RendererKind::Exact`]). With
/// [`Sampler::Trilinear`] the level of detail comes from the exact footprint of each pixel
/// (differences of the exact mapping to the next pixel right and below).
///
/// `threads`: split rows across the rayon pool when true; output is identical either way.
pub fn render_exact(
    map: &EnvMap,
    view: View,
    sampler: Sampler,
    frame: &mut Frame<'_>,
    threads: bool,
) {
    let (width, height) = (frame.width(), frame.height());
    let out = frame.pixels_mut();
    let cam = Camera::new(view, width, height);
    let (mw, mh) = (map.width() as f64, map.height() as f64);
    let proj = map.projection();
    if sampler == Sampler::Trilinear {
        map.pyramid();
        let fp = ExactFootprint { cam, proj, mw, mh };
        for_each_row(out, width as usize, threads, |y, line| {
            for (x, px) in line.iter_mut().enumerate() {
                let uv = exact_uv_at(&cam, proj, mw, mh, x as f64 + 0.5, y as f64 + 0.5);
                *px = sample_at_lod(map, uv, fp.lod(x, y, uv));
            }
        });
        return;
    }
    for_each_row(out, width as usize, threads, |y, line| {
        for (x, px) in line.iter_mut().enumerate() {
            *px = sample_at(
                map,
                sampler,
                exact_uv(&cam, proj, mw, mh, x as u32, y as u32),
            );
        }
    });
}

/// Render `view` supersampled `n × n` per output pixel (exact geometry, box filter over
/// the sub-samples, in 8-bit sRGB as stored): the reference for minification quality.
pub fn render_exact_supersampled(
    map: &EnvMap,
    view: View,
    sampler: Sampler,
    n: u32,
    frame: &mut Frame<'_>,
    threads: bool,
) {
    let (width, height) = (frame.width(), frame.height());
    let out = frame.pixels_mut();
    let n = n.max(1);
    let cam = Camera::new(view, width, height);
    let (mw, mh) = (map.width() as f64, map.height() as f64);
    let proj = map.projection();
    let inv = 1.0 / n as f64;
    for_each_row(out, width as usize, threads, |y, line| {
        for (x, px) in line.iter_mut().enumerate() {
            let (mut r, mut g, mut b) = (0u32, 0u32, 0u32);
            for sy in 0..n {
                for sx in 0..n {
                    let pxf = x as f64 + (sx as f64 + 0.5) * inv;
                    let pyf = y as f64 + (sy as f64 + 0.5) * inv;
                    let c = sample_at(map, sampler, exact_uv_at(&cam, proj, mw, mh, pxf, pyf));
                    r += c >> 16 & 0xFF;
                    g += c >> 8 & 0xFF;
                    b += c & 0xFF;
                }
            }
            let nn = n * n;
            let half = nn / 2;
            *px = (((r + half) / nn) << 16) | (((g + half) / nn) << 8) | ((b + half) / nn);
        }
    });
}

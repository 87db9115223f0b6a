//! The exact mapping: output pixel (or image point) → ray (in the view's output
//! projection) → (λ, φ) → map (u, v), in f64. The yardstick of every fast path (`render/exact.rs` samples it; the accuracy
//! metric compares against it).

use crate::geom::camera::{dir_to_lat_long, Camera};
use crate::geom::projection::Projection;

/// Exact map position of the center of output pixel (x, y), or `None` when the map does
/// not cover that direction (or the view's projection has none there).
#[inline]
pub fn exact_uv(
    cam: &Camera,
    projection: Projection,
    map_w: f64,
    map_h: f64,
    x: u32,
    y: u32,
) -> Option<(f64, f64)> {
    exact_uv_at(
        cam,
        projection,
        map_w,
        map_h,
        x as f64 + 0.5,
        y as f64 + 0.5,
    )
}

/// Exact map position of an arbitrary image-plane point (used for supersampling).
#[inline]
pub fn exact_uv_at(
    cam: &Camera,
    projection: Projection,
    map_w: f64,
    map_h: f64,
    px: f64,
    py: f64,
) -> Option<(f64, f64)> {
    let (lambda, phi) = dir_to_lat_long(cam.ray(px, py)?);
    projection.uv(lambda, phi, map_w, map_h)
}

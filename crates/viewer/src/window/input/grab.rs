//! The geometry under the cursor: the world direction at a point of the view, the yaw and
//! pitch that put a direction at a point (grab drags and zooms toward the cursor, in every
//! output projection), and the zoom limit from the map's resolution.

use super::{moved, steer_rect, HFOV_MAX, HFOV_MIN};
use glam::DVec3;
use lut_core::View;
use lut_core::{dir_to_lat_long, wrap_deg, Camera};

/// The narrowest hfov at which one map pixel covers `screen_px_per_map_px` screen pixels
/// at the center of a `scene_width`-pixel view, for a map whose pixels span
/// `map_px_deg` degrees (360 / width for a map, 90 / face size for a cube map). With
/// focal length f (pixels), a center pixel spans 1/f radians; f = ratio / map pixel.
pub fn resolution_hfov(map_px_deg: f64, scene_width: u32, screen_px_per_map_px: f64) -> f64 {
    let map_px = map_px_deg.to_radians();
    if !(map_px > 0.0 && screen_px_per_map_px > 0.0) || scene_width == 0 {
        return HFOV_MIN;
    }
    let f = screen_px_per_map_px / map_px;
    (2.0 * (f64::from(scene_width) / 2.0 / f).atan())
        .to_degrees()
        .clamp(HFOV_MIN, HFOV_MAX)
}

/// World direction (unit) through image-plane point `pos` of a `size` scene for `look`
/// (in its projection); zero where the projection has none (outside a fisheye's disc).
pub fn dir_at(look: &View, pos: (f64, f64), size: (u32, u32)) -> DVec3 {
    Camera::new(*look, size.0.max(1), size.1.max(1))
        .ray(pos.0, pos.1)
        .map_or(DVec3::ZERO, DVec3::normalize_or_zero)
}

/// Yaw and pitch (degrees) that put world direction `dir` at image-plane point `pos` of a
/// `size` scene with field of view `hfov`, pitch clamped to ±90°. Of the two exact
/// solutions the one nearer `prev_pitch` wins; when no pitch within ±90° reaches (a
/// direction near a pole under a cursor near the edge), the nearest one is taken.
/// Rectilinear; [`solve_grab_in`] for any projection.
pub fn solve_grab(
    dir: DVec3,
    pos: (f64, f64),
    size: (u32, u32),
    hfov: f64,
    prev_pitch: f64,
) -> (f64, f64) {
    let base = steer_rect(0.0, 0.0, hfov);
    solve_grab_in(dir, pos, size, base, prev_pitch).unwrap_or((0.0, prev_pitch))
}

/// [`solve_grab`] in `base`'s projection and hfov (its yaw and pitch are ignored);
/// `None` when `pos` has no direction in that projection or `dir` is zero.
pub fn solve_grab_in(
    dir: DVec3,
    pos: (f64, f64),
    size: (u32, u32),
    base: View,
    prev_pitch: f64,
) -> Option<(f64, f64)> {
    let base = moved(base, 0.0, 0.0, base.hfov_deg());
    let cam = Camera::new(base, size.0.max(1), size.1.max(1));
    // At yaw 0 and pitch 0 the world ray is the camera-space ray.
    let c = cam.ray(pos.0, pos.1)?.normalize_or_zero();
    if dir == DVec3::ZERO || c == DVec3::ZERO {
        return None;
    }
    let d = dir.normalize_or_zero();
    // Pitching the camera ray c by p gives height c.y cos p + c.z sin p = R sin(α + p);
    // it must equal the target's height d.y (yaw does not change heights).
    let r = (c.y * c.y + c.z * c.z).sqrt();
    let alpha = c.y.atan2(c.z);
    let half_pi = std::f64::consts::FRAC_PI_2;
    let pitch = if r <= 1e-12 {
        prev_pitch.to_radians()
    } else if (d.y / r).abs() >= 1.0 {
        (half_pi.copysign(d.y) - alpha).clamp(-half_pi, half_pi)
    } else {
        let a = (d.y / r).asin();
        let cands = [a - alpha, std::f64::consts::PI - a - alpha].map(|p| {
            // Into (−π, π], then nearest legal pitch.
            let p = wrap_deg(p.to_degrees()).to_radians();
            (p, p.clamp(-half_pi, half_pi))
        });
        let prev = prev_pitch.to_radians();
        // Prefer exact solutions (p == clamped) and, among them, the one nearest `prev`.
        let score = |(p, q): (f64, f64)| (p - q).abs() * 1e3 + (q - prev).abs();
        if score(cands[0]) <= score(cands[1]) {
            cands[0].1
        } else {
            cands[1].1
        }
    };
    let (sp, cp) = pitch.sin_cos();
    let z1 = c.z * cp - c.y * sp;
    let (lambda_d, _) = dir_to_lat_long(d);
    let lambda_c = c.x.atan2(z1);
    let yaw = wrap_deg((lambda_d - lambda_c).to_degrees());
    Some((yaw, pitch.to_degrees()))
}

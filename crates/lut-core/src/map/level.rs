//! A level horizon: an equirectangular map taken with a tilted camera, resampled once
//! through the rotation that levels it, so every renderer (the LUT's scanline coherence
//! assumes an upright sphere) draws the level map as it is.
//!
//! The rotation is Pannellum's (`horizonPitch`, `horizonRoll`; GPano's
//! `PosePitchDegrees`, `PoseRollDegrees` are the same numbers, as Pannellum reads them):
//! a world direction d (yaw right, pitch up) is found in the tilted image at
//! `horizon_rotation(pitch, roll) · d` (libpannellum.js `render`: in its frame, forward,
//! right, up, the image direction is Ry(pitch)·Rx(roll) applied to the world's).
//! Each pixel of the level map is the source sampled there, bilinear in f64 (the
//! conventions' bilinear: the four pixel centres around (u − ½, v − ½), u wrapping,
//! v clamped), rounded once per channel.

use crate::geom::camera::lat_long_to_dir;
use crate::geom::projection::Projection;
use crate::map::envmap::EnvMap;
use glam::{DMat3, DVec3};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

/// The rotation taking a world direction (this project's X right, Y up, Z forward) to
/// the direction in a panorama whose horizon has pitch `pitch_deg` and roll `roll_deg`
/// (Pannellum's `horizonPitch`/`horizonRoll`).
pub fn horizon_rotation(pitch_deg: f64, roll_deg: f64) -> DMat3 {
    let (sp, cp) = pitch_deg.to_radians().sin_cos();
    let (sr, cr) = roll_deg.to_radians().sin_cos();
    // Pannellum's Ry(P)·Rx(R) on (forward, right, up) = (Z, X, Y), written on (X, Y, Z).
    DMat3::from_cols(
        DVec3::new(cr, sr * cp, sr * sp),
        DVec3::new(-sr, cr * cp, cr * sp),
        DVec3::new(0.0, -sp, cp),
    )
}

/// The f64 bilinear sample of a full equirectangular map at (u, v) (pixel coordinates),
/// per channel unrounded.
pub fn bilinear_f64(map: &EnvMap, u: f64, v: f64) -> [f64; 3] {
    let (w, h) = (map.width() as i64, map.height() as i64);
    let (uu, vv) = (u - 0.5, v - 0.5);
    let (x0, y0) = (uu.floor(), vv.floor());
    let (fx, fy) = (uu - x0, vv - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let px = |x: i64, y: i64| {
        let p = map.pixel(x.rem_euclid(w) as u32, y.clamp(0, h - 1) as u32);
        [
            ((p >> 16) & 0xFF) as f64,
            ((p >> 8) & 0xFF) as f64,
            (p & 0xFF) as f64,
        ]
    };
    let (a, b, c, d) = (
        px(x0, y0),
        px(x0 + 1, y0),
        px(x0, y0 + 1),
        px(x0 + 1, y0 + 1),
    );
    let mut out = [0.0; 3];
    for i in 0..3 {
        let top = a[i] + (b[i] - a[i]) * fx;
        let bot = c[i] + (d[i] - c[i]) * fx;
        out[i] = top + (bot - top) * fy;
    }
    out
}

/// Where (u, v) world direction `d` falls in a `w × h` equirectangular map.
pub fn equirect_uv(d: DVec3, w: u32, h: u32) -> (f64, f64) {
    let lambda = d.x.atan2(d.z);
    let phi = (d.y / d.length()).clamp(-1.0, 1.0).asin();
    (
        (lambda + PI) / TAU * w as f64,
        (PI / 2.0 - phi) / PI * h as f64,
    )
}

/// `map` (a full equirectangular map) re-levelled: the map a level camera would have
/// taken, same size, its pose heading and start view kept. `None` for other projections
/// and partial maps (not re-levelled; the caller says so).
pub fn level_horizon(map: &EnvMap, pitch_deg: f64, roll_deg: f64) -> Option<EnvMap> {
    if map.projection() != Projection::Equirect || map.crop().is_some() {
        return None;
    }
    let (w, h) = (map.width(), map.height());
    let m = horizon_rotation(pitch_deg, roll_deg);
    let lambdas: Vec<f64> = (0..w)
        .map(|i| (i as f64 + 0.5) / w as f64 * TAU - PI)
        .collect();
    let mut pixels = vec![0u32; w as usize * h as usize];
    pixels
        .par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(j, row)| {
            let phi = PI / 2.0 - (j as f64 + 0.5) / h as f64 * PI;
            for (out, &lambda) in row.iter_mut().zip(&lambdas) {
                let d = m * lat_long_to_dir(lambda, phi);
                let (u, v) = equirect_uv(d, w, h);
                let c = bilinear_f64(map, u, v);
                let q = |x: f64| x.round().clamp(0.0, 255.0) as u32;
                *out = (q(c[0]) << 16) | (q(c[1]) << 8) | q(c[2]);
            }
        });
    let mut out = EnvMap::from_pixels(w, h, &pixels, Projection::Equirect).ok()?;
    out.set_pose_heading_deg(map.pose_heading_deg());
    out.set_start_view(map.start_view());
    out.set_background(map.background());
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pannellum's own formulas (libpannellum.js `render`, horizon pose): the view's
    /// (pitch, yaw) in the world to the (pitch, yaw) read in the image, radians.
    fn pannellum(pitch: f64, yaw: f64, hp: f64, hr: f64) -> (f64, f64) {
        let x = hr.cos() * pitch.sin() * hp.sin()
            + pitch.cos() * (hp.cos() * yaw.cos() + hr.sin() * hp.sin() * yaw.sin());
        let y = -pitch.sin() * hr.sin() + pitch.cos() * hr.cos() * yaw.sin();
        let z = hr.cos() * hp.cos() * pitch.sin()
            + pitch.cos() * (-yaw.cos() * hp.sin() + hp.cos() * hr.sin() * yaw.sin());
        (z.clamp(-1.0, 1.0).asin(), y.atan2(x))
    }

    #[test]
    fn the_rotation_is_pannellums() {
        for &(hp, hr) in &[(10.0, 0.0), (0.0, 15.0), (-7.5, 22.0), (30.0, -40.0)] {
            let m = horizon_rotation(hp, hr);
            for &(yaw, pitch) in &[(0.0, 0.0), (40.0, 10.0), (-130.0, -35.0), (170.0, 60.0)] {
                let (yaw, pitch): (f64, f64) = (f64::to_radians(yaw), f64::to_radians(pitch));
                let d = m * lat_long_to_dir(yaw, pitch);
                let (lam, phi) = (d.x.atan2(d.z), d.y.asin());
                let (p2, y2) = pannellum(pitch, yaw, f64::to_radians(hp), f64::to_radians(hr));
                assert!((phi - p2).abs() < 1e-12, "pitch {phi} vs {p2}");
                let dy = (lam - y2 + PI).rem_euclid(TAU) - PI;
                assert!(dy.abs() < 1e-12, "yaw {lam} vs {y2}");
            }
            // A rotation: orthonormal, determinant 1.
            assert!((m.determinant() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn level_maps_and_unsupported_ones() {
        let map = crate::map::synth::grid_map(64, 32, Projection::Equirect).unwrap();
        let same = level_horizon(&map, 0.0, 0.0).unwrap();
        // No rotation: each pixel centre samples itself exactly.
        for y in 0..32 {
            for x in 0..64 {
                assert_eq!(same.pixel(x, y), map.pixel(x, y), "({x}, {y})");
            }
        }
        let cyl = EnvMap::from_pixels(4, 2, &[0; 8], Projection::Cylinder).unwrap();
        assert!(level_horizon(&cyl, 5.0, 0.0).is_none());
    }
}

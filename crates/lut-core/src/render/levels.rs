//! Which pyramid level a frame is drawn from, when it is drawn from one: the level choice
//! of [`Renderer::set_bilinear_level`] (moving bilinear frames) and
//! [`Renderer::set_still_level`] (still bilinear and trilinear frames), and
//! [`build_frame_levels`], which builds what such frames read ahead of them.
//!
//! Zoomed out, a frame of the map itself reads texels far apart: bilinear aliases (a
//! pixel covering four texels shows one of them, and the pick moves as the view moves)
//! and costs more the bigger the map (each sample a cache miss: a 32768-wide map at
//! 1080p and hfov 90 took 4x the 8192-wide map's frame); trilinear does not alias, but
//! its level of detail (with its −½ bias) reaches levels finer than the 8192-wide one
//! towards the edges of a wide view, where a rectilinear view's pixels are smallest, and
//! blends two of them there (4x as well). A frame drawn from level k is instead a plain
//! frame of the level, with the level's own tables (a nested `Renderer`) and, for
//! trilinear, the level's own pyramid (equal to the map's levels below k), as the level
//! would be drawn were it the map; so its cost follows the screen, not the map.
//!
//! * **Moving frames** ([`centre_footprint`]): k = ⌊log2(c) + ½⌋, c the footprint at the
//!   view's centre; the centre reads 0.71–1.41 level texels per pixel, the edges of a
//!   wide view fewer (they are magnified there, as on a map of the level's size).
//! * **Still frames** ([`frame_min_footprint`]): k = ⌊log2(m) + ½⌋, m the frame's
//!   smallest footprint: the deepest level on which no pixel is magnified by more than
//!   √2. Where the footprint is larger, bilinear reads fewer texels than on the map and
//!   trilinear the same levels as on the map; what trilinear gives up is blending in
//!   levels finer than k where the footprint is smallest, as on a smaller map of the
//!   same scene.
//!
//! Either way, footprints of at most √2 draw from the map itself, byte for byte (1080p at
//! hfov 90 or 120 on a map up to 8192 wide, for still frames), and only levels that
//! divide the map's sides exactly are used, so positions on them are exact
//! ([`frame_level`]). Partial maps (no pyramid of their own) are always drawn from the
//! map.

use crate::geom::camera::View;
use crate::geom::mapping::exact_uv_at;
use crate::map::envmap::EnvMap;
use crate::render::exact::ExactFootprint;
use crate::render::setup::MapGeometry;
#[cfg(doc)]
use crate::render::Renderer;
use std::f64::consts::TAU;

/// The footprint at the centre of a rectilinear view of `hfov` (radians) on `width`
/// columns, in map pixels per screen pixel of a `map_width`-wide 360° map, at the
/// horizon: 2 tan(hfov/2) / width · map_width / 2π (moving frames,
/// [`Renderer::set_bilinear_level`]).
pub(crate) fn centre_footprint(hfov: f64, width: u32, map_width: u32) -> f64 {
    2.0 * (hfov * 0.5).tan() / width as f64 * map_width as f64 / TAU
}

/// The pyramid level a bilinear frame on the level reads for a footprint of `centre`
/// map pixels per screen pixel at the view's centre, on a `w × h` map
/// ([`Renderer::set_bilinear_level`]): the nearest level, k = ⌊log2(centre) + ½⌋, or the
/// deepest level above it whose sides divide the map's exactly (level k of a map with
/// sides divisible by 2^k is exactly the map at 1/2^k scale; see `map/pyramid.rs`).
/// Levels end at a side of 2, as the pyramid does.
pub(crate) fn frame_level(centre: f64, w: u32, h: u32) -> usize {
    // (NaN too.)
    if centre.partial_cmp(&std::f64::consts::SQRT_2) != Some(std::cmp::Ordering::Greater) {
        return 0;
    }
    let want = (centre.log2() + 0.5).floor().min(31.0) as u32;
    (1..=want)
        .take_while(|&k| exact_level(k, w, h))
        .last()
        .map_or(0, |k| k as usize)
}

/// Whether level `k` (1 ≤ k ≤ 31) of a `w × h` map is exactly the map at 1/2^k scale and
/// at least 2 pixels on its shorter side: the levels frames are drawn from
/// ([`frame_level`]).
fn exact_level(k: u32, w: u32, h: u32) -> bool {
    w.is_multiple_of(1 << k) && h.is_multiple_of(1 << k) && (w.min(h) >> k) >= 2
}

/// Build now what frames drawn from pyramid levels need, so that no frame waits for it
/// ([`Renderer::set_still_level`], [`Renderer::set_bilinear_level`]): `map`'s pyramid and
/// the own pyramid of every level a frame can be drawn from (trilinear still frames of a
/// level read the level's pyramid; its levels equal the map's below it, so this holds
/// about a ninth of the map's bytes again: 0.22 GiB for a 32768×16384 map). The window
/// calls it on its loading thread. Partial maps (drawn from the map itself) build
/// nothing.
pub fn build_frame_levels(map: &EnvMap) {
    if map.crop().is_some() {
        return;
    }
    for (i, level) in map.pyramid().iter().enumerate() {
        let k = i as u32 + 1;
        if k > 31 || !exact_level(k, map.width(), map.height()) {
            break;
        }
        level.pyramid();
    }
}

/// The smallest footprint in a frame of `view` on `width × height` pixels of a map of
/// `geometry`, in map pixels per screen pixel ([`Renderer::set_still_level`]): the
/// minimum of the exact footprint (the larger of the map-pixel distances to the exact
/// positions one pixel right and one below, `ExactFootprint::footprint`) over a grid of
/// 17 × 9 points spanning the frame, corners and edges included (in a rectilinear view
/// the footprint is smallest at the edges, where the view's rays meet the sphere at a
/// slant). The centre is taken first: the minimum is at most the centre's footprint, so a
/// frame that is not zoomed out (centre at most √2) stops there and costs one
/// footprint. Points the map does not cover are skipped; with none covered, 0.
pub(crate) fn frame_min_footprint(
    view: View,
    width: u32,
    height: u32,
    geometry: MapGeometry,
) -> f64 {
    let fp = ExactFootprint::new(view, width, height, geometry);
    let at = |x: f64, y: f64| -> Option<f64> {
        let uv = exact_uv_at(&fp.cam, fp.proj, fp.mw, fp.mh, x, y)?;
        let f = fp.footprint(x, y, uv);
        f.is_finite().then_some(f)
    };
    let (w, h) = (width as f64, height as f64);
    let centre = at(w * 0.5, h * 0.5);
    if centre.is_some_and(|c| c <= std::f64::consts::SQRT_2) {
        return centre.unwrap_or(0.0);
    }
    const NX: u32 = 17;
    const NY: u32 = 9;
    // Pixel centres from the first to the last, in NX × NY steps.
    let x_at = |i: u32| 0.5 + (w - 1.0) * i as f64 / (NX - 1) as f64;
    let y_at = |j: u32| 0.5 + (h - 1.0) * j as f64 / (NY - 1) as f64;
    (0..NY)
        .flat_map(|j| (0..NX).map(move |i| (i, j)))
        .filter_map(|(i, j)| at(x_at(i), y_at(j)))
        .chain(centre)
        .reduce(f64::min)
        .unwrap_or(0.0)
}

/// The largest footprint in a frame of `view` on `width × height` pixels of a map of
/// `geometry`, in map pixels per screen pixel, sampled as [`frame_min_footprint`] on
/// 17 × 9 points spanning the frame (corners and edges included) and its centre
/// (`Renderer::set_region_lod`: a frame whose largest sampled footprint is at most √2 is
/// drawn without the pyramid; one that is larger between the points is drawn with it
/// only if some point is above √2, which costs sharpness nowhere, only the speed there).
/// Points the map does not cover are skipped; a pole in view gives a footprint near it
/// that grows without bound, caught by the points around it. With none covered, 0.
pub(crate) fn frame_max_footprint(
    view: View,
    width: u32,
    height: u32,
    geometry: MapGeometry,
) -> f64 {
    let fp = ExactFootprint::new(view, width, height, geometry);
    let at = |x: f64, y: f64| -> Option<f64> {
        let uv = exact_uv_at(&fp.cam, fp.proj, fp.mw, fp.mh, x, y)?;
        let f = fp.footprint(x, y, uv);
        // (At a pole itself the footprint is unbounded: as large as it gets.)
        Some(if f.is_finite() { f } else { f64::MAX })
    };
    let (w, h) = (width as f64, height as f64);
    const NX: u32 = 17;
    const NY: u32 = 9;
    let x_at = |i: u32| 0.5 + (w - 1.0) * i as f64 / (NX - 1) as f64;
    let y_at = |j: u32| 0.5 + (h - 1.0) * j as f64 / (NY - 1) as f64;
    (0..NY)
        .flat_map(|j| (0..NX).map(move |i| (i, j)))
        .filter_map(|(i, j)| at(x_at(i), y_at(j)))
        .chain(at(w * 0.5, h * 0.5))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::{centre_footprint, frame_level, frame_min_footprint};
    use crate::geom::camera::View;
    use crate::geom::mapping::exact_uv_at;
    use crate::geom::projection::Projection;
    use crate::render::exact::ExactFootprint;
    use crate::render::setup::MapGeometry;

    /// The smallest footprint of a frame, sampled on 17 × 9 points, against the minimum
    /// over every pixel centre of the frame: never more than 3 % above it (the samples
    /// include the corners and edges, where a rectilinear view's footprint is smallest)
    /// and at most 2 % below (the samples are not all pixel centres), on views at the
    /// horizon, tilted, near a pole, across the seam and wide; and the level chosen from
    /// it is the one the brute-force minimum gives.
    #[test]
    fn frame_min_footprint_is_the_frames_smallest() {
        let geometry = MapGeometry {
            width: 2048,
            height: 1024,
            projection: Projection::Equirect,
        };
        for (yaw, pitch, hfov, w, h) in [
            (10.0, 0.0, 90.0, 64, 48),
            (0.0, 45.0, 100.0, 96, 64),
            (30.0, 80.0, 90.0, 80, 60),
            (180.0, -30.0, 120.0, 97, 41),
            (0.0, 0.0, 150.0, 128, 64),
            (0.0, 0.0, 60.0, 1, 1),
        ] {
            let view = View::new(yaw, pitch, hfov).unwrap();
            let fp = ExactFootprint::new(view, w, h, geometry);
            let brute = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x as f64 + 0.5, y as f64 + 0.5)))
                .filter_map(|(x, y)| {
                    let uv = exact_uv_at(&fp.cam, fp.proj, fp.mw, fp.mh, x, y)?;
                    Some(fp.footprint(x, y, uv))
                })
                .fold(f64::INFINITY, f64::min);
            let got = frame_min_footprint(view, w, h, geometry);
            assert!(
                got <= brute * 1.03 && got >= brute * 0.98,
                "{yaw} {pitch} {hfov} {w}x{h}: sampled {got} against {brute}"
            );
            assert_eq!(
                frame_level(got, 2048, 1024),
                frame_level(brute, 2048, 1024),
                "{yaw} {pitch} {hfov}: {got} against {brute}"
            );
        }
        // Not zoomed out: the centre's footprint, at most √2, without the grid.
        let view = View::new(0.0, 0.0, 20.0).unwrap();
        assert!(frame_min_footprint(view, 160, 120, geometry) <= std::f64::consts::SQRT_2);
    }

    /// `build_frame_levels` builds the map's pyramid and the own pyramid of exactly the
    /// levels frames can be drawn from: 48×24 divides down to level 3 (6×3), not 4.
    #[test]
    fn build_frame_levels_builds_the_levels_frames_use() {
        let px: Vec<u32> = (0..48 * 24u32)
            .map(|i| i.wrapping_mul(2654435761))
            .collect();
        let map = crate::EnvMap::from_pixels(48, 24, &px, Projection::Equirect).unwrap();
        super::build_frame_levels(&map);
        let levels = map.pyramid();
        assert!(levels.len() > 3);
        let built: Vec<bool> = levels.iter().map(|l| l.pyramid_bytes() > 0).collect();
        assert!(built[..3].iter().all(|&b| b), "{built:?}");
        assert!(built[3..].iter().all(|&b| !b), "{built:?}");
    }

    /// The level of a bilinear frame on the level: the nearest power of two to the
    /// centre's footprint, among the levels that divide the map's sides.
    #[test]
    fn frame_level_is_the_nearest_level_that_divides_the_map() {
        let (w, h) = (32768, 16384);
        // 1080p, hfov 90: 2 tan 45° / 1920 · W / 2π map pixels per screen pixel.
        let centre = |w: u32, hfov: f64| {
            2.0 * (hfov.to_radians() / 2.0).tan() / 1920.0 * w as f64 / std::f64::consts::TAU
        };
        assert!((centre_footprint(90f64.to_radians(), 1920, w) - centre(w, 90.0)).abs() < 1e-12);
        assert_eq!(frame_level(centre(w, 90.0), w, h), 2); // 5.43: the 8192-wide level
        assert_eq!(frame_level(centre(w, 120.0), w, h), 3); // 9.41: the 4096-wide level
        assert_eq!(frame_level(centre(16384, 90.0), 16384, 8192), 1); // 2.72
        assert_eq!(frame_level(centre(8192, 90.0), 8192, 4096), 0); // 1.36: the map
        assert_eq!(frame_level(centre(8192, 120.0), 8192, 4096), 1); // 2.35
                                                                     // The boundaries: √2 and 2√2.
        for (fp, k) in [
            (0.3, 0),
            (1.41, 0),
            (1.42, 1),
            (2.82, 1),
            (2.83, 2),
            (1e9, 13),
        ] {
            assert_eq!(frame_level(fp, w, h), k, "footprint {fp}");
        }
        assert_eq!(frame_level(f64::NAN, w, h), 0);
        // Levels that do not divide the map are skipped: 6000x3000 divides down to level
        // 3 (750x375); 6002x3001 only level 0.
        assert_eq!(frame_level(40.0, 6000, 3000), 3);
        assert_eq!(frame_level(40.0, 6002, 3001), 0);
        // Never below a side of 2.
        assert_eq!(frame_level(1e6, 64, 32), 4);
    }
}

//! The view limit: keep every edge ray of a view inside a panorama's [`Coverage`].
//!
//! For an output of aspect `height / width`, [`limit_view`] returns the view nearest the
//! requested one whose whole frame (the continuous rectangle, so every border pixel's
//! centre ray too) lies in the coverage: hfov is reduced first if the frame cannot fit at
//! any pitch, then pitch is clamped, then yaw (yaw is free when the coverage spans 360°).
//! Longitudes are compared modulo 360°, so coverages that straddle the ±180° seam work.
//!
//! Geometry (camera of `docs/conventions.md`, focal length 1, `a = tan(hfov/2)`,
//! `b = a · height/width`): an image-plane point (x, y) seen at pitch θ has latitude
//! `atan2(y cos θ + sin θ, √(x² + (cos θ − y sin θ)²))` and longitude relative to yaw
//! `atan2(x, cos θ − y sin θ)`.
//! * The north pole is in the frame when `θ + atan b ≥ 90°` (south: `θ − atan b ≤ −90°`);
//!   then all longitudes are seen and only a 360°-wide coverage reaching the pole holds it.
//! * Otherwise every frame point has `cos θ − y sin θ > 0`, so the longitude extent is
//!   `± max |atan2(x, cos θ − y sin θ)|` over the four corners; the latitude extremes of
//!   the border are at the corners, the top and bottom edge centres, or the one critical
//!   point of each side edge (`y = cos θ (a² + 1) / sin θ`); the frame's interior adds no
//!   extremes (latitude has no interior maximum away from a pole).
//! * Every ray's latitude grows with θ while the pole is outside the frame, so the
//!   highest latitude seen is nondecreasing in θ, and so is the lowest: the pitches that
//!   fit form an interval, found by bisection (always keeping the side that fits).

use crate::geom::camera::{dir_to_lat_long, wrap_deg, Camera, View};
use crate::geom::coverage::Coverage;

/// How far the frame reaches, for one pitch: latitude extremes and the half-width in
/// longitude around the view's yaw (degrees; 180 when a pole is in the frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameExtent {
    /// Lowest latitude seen.
    pub lat_min: f64,
    /// Highest latitude seen.
    pub lat_max: f64,
    /// Largest |longitude − yaw| seen.
    pub half_lon: f64,
}

/// The extent of a view's frame at pitch `pitch_deg` with `tan(hfov/2) = a` and
/// `tan(vfov/2) = b`.
pub fn frame_extent(pitch_deg: f64, a: f64, b: f64) -> FrameExtent {
    let t = pitch_deg.to_radians();
    let (s, c) = t.sin_cos();
    let half_v = b.atan().to_degrees();
    let north = pitch_deg + half_v >= 90.0;
    let south = pitch_deg - half_v <= -90.0;
    let lat = |x: f64, y: f64| {
        let z = c - y * s;
        (y * c + s).atan2((x * x + z * z).sqrt()).to_degrees()
    };
    let mut pts = vec![(a, b), (-a, b), (a, -b), (-a, -b), (0.0, b), (0.0, -b)];
    if s.abs() > 1e-12 {
        let y = c * (a * a + 1.0) / s;
        if y.abs() <= b {
            pts.push((a, y));
        }
    }
    let mut lat_min = f64::INFINITY;
    let mut lat_max = f64::NEG_INFINITY;
    for &(x, y) in &pts {
        let l = lat(x, y);
        lat_min = lat_min.min(l);
        lat_max = lat_max.max(l);
    }
    if north {
        lat_max = 90.0;
    }
    if south {
        lat_min = -90.0;
    }
    let half_lon = if north || south {
        180.0
    } else {
        [b, -b]
            .iter()
            .map(|&y| a.atan2(c - y * s).to_degrees())
            .fold(0.0, f64::max)
    };
    FrameExtent {
        lat_min,
        lat_max,
        half_lon,
    }
}

/// `tan(hfov/2)` and `tan(vfov/2)` of a view on a `width × height` output.
fn tans(hfov_deg: f64, width: u32, height: u32) -> (f64, f64) {
    let a = (hfov_deg.to_radians() / 2.0).tan();
    (a, a * height.max(1) as f64 / width.max(1) as f64)
}

/// True when the whole frame of `view` on a `width × height` output lies in `cov`.
///
/// Exact for rectilinear views (the analysis of the module docs); for other output
/// projections the directions of a 65 × 65 lattice of image points spanning the frame
/// (borders included) are checked, since their frames have no such closed form.
pub fn view_inside(view: View, width: u32, height: u32, cov: &Coverage) -> bool {
    if !view.projection().is_rectilinear() {
        return sampled_inside(view, width, height, cov);
    }
    let (a, b) = tans(view.hfov_deg(), width, height);
    let e = frame_extent(view.pitch_deg(), a, b);
    let (lo, hi) = cov.lat_range();
    if e.lat_min < lo - INSIDE_SLACK_DEG || e.lat_max > hi + INSIDE_SLACK_DEG {
        return false;
    }
    cov.full_width()
        || wrap_deg(view.yaw_deg() - cov.yaw()).abs() + e.half_lon
            <= cov.hfov() / 2.0 + INSIDE_SLACK_DEG
}

/// How far (degrees) a frame may reach past the coverage and still count as inside: a
/// view that [`limit_view`] fitted exactly to the coverage (its frame as tall as the
/// coverage) lands on the boundary, and recomputing its extent from the stored angles can
/// overshoot by a few ulps (found by the property test: 1e-14° at a vfov of 54.7°).
/// A nanodegree is far below a pixel of any map.
const INSIDE_SLACK_DEG: f64 = 1e-9;

/// [`view_inside`] for a non-rectilinear view: the directions of a lattice of image points.
fn sampled_inside(view: View, width: u32, height: u32, cov: &Coverage) -> bool {
    const N: u32 = 64;
    let cam = Camera::new(view, width, height);
    (0..=N).all(|i| {
        (0..=N).all(|j| {
            let px = width as f64 * i as f64 / N as f64;
            let py = height as f64 * j as f64 / N as f64;
            cam.ray(px, py).is_none_or(|d| {
                let (l, p) = dir_to_lat_long(d);
                cov.contains(l, p, 1e-4)
            })
        })
    })
}

/// The interval of pitches at which a frame with tangents (a, b) fits `cov` vertically
/// (and, for a coverage narrower than 360°, horizontally at some yaw), or `None`.
fn pitch_interval(a: f64, b: f64, cov: &Coverage) -> Option<(f64, f64)> {
    let (lo, hi) = cov.lat_range();
    let fits_top = |p: f64| frame_extent(p, a, b).lat_max <= hi;
    let fits_bottom = |p: f64| frame_extent(p, a, b).lat_min >= lo;
    // Highest pitch whose top fits (lat_max is nondecreasing in pitch).
    let top = bisect_last(-90.0, 90.0, fits_top)?;
    // Lowest pitch whose bottom fits (lat_min is nondecreasing in pitch).
    let bottom = bisect_first(-90.0, 90.0, fits_bottom)?;
    let (mut p0, mut p1) = (bottom, top);
    if !cov.full_width() {
        // half_lon grows with |pitch|: the largest |pitch| whose width fits.
        let fits_wide = |p: f64| frame_extent(p, a, b).half_lon <= cov.hfov() / 2.0;
        let m = bisect_last(0.0, 90.0, fits_wide)?;
        p0 = p0.max(-m);
        p1 = p1.min(m);
    }
    (p0 <= p1).then_some((p0, p1))
}

/// Largest x in [lo, hi] with `ok(x)`, for `ok` true up to some point and false after;
/// `None` when `ok(lo)` fails. The result always satisfies `ok`.
fn bisect_last(lo: f64, hi: f64, ok: impl Fn(f64) -> bool) -> Option<f64> {
    if !ok(lo) {
        return None;
    }
    if ok(hi) {
        return Some(hi);
    }
    let (mut good, mut bad) = (lo, hi);
    for _ in 0..64 {
        let mid = 0.5 * (good + bad);
        if ok(mid) {
            good = mid;
        } else {
            bad = mid;
        }
    }
    Some(good)
}

/// Smallest x in [lo, hi] with `ok(x)`, for `ok` false up to some point and true after.
fn bisect_first(lo: f64, hi: f64, ok: impl Fn(f64) -> bool) -> Option<f64> {
    bisect_last(-hi, -lo, |x| ok(-x)).map(|x| -x)
}

/// The view nearest `view` whose whole frame on a `width × height` output lies inside
/// `cov` (see the module docs). A view that already fits is returned unchanged; a
/// coverage so small that no view fits returns `view` unchanged.
///
/// Rectilinear views only: a view in another output projection is returned unchanged
/// (its frame has no closed form here; outside the coverage it shows the background).
pub fn limit_view(view: View, width: u32, height: u32, cov: &Coverage) -> View {
    if !view.projection().is_rectilinear() {
        return view;
    }
    if view_inside(view, width, height, cov) {
        return view;
    }
    let fits = |h: f64| {
        let (a, b) = tans(h, width, height);
        pitch_interval(a, b, cov).is_some()
    };
    let hfov = if fits(view.hfov_deg()) {
        view.hfov_deg()
    } else {
        match bisect_last(1e-6, view.hfov_deg(), fits) {
            Some(h) => h,
            None => return view,
        }
    };
    let (a, b) = tans(hfov, width, height);
    let Some((p0, p1)) = pitch_interval(a, b, cov) else {
        return view;
    };
    let pitch = view.pitch_deg().clamp(p0, p1);
    let yaw = if cov.full_width() {
        view.yaw_deg()
    } else {
        // A hair of slack so the result passes `view_inside` after yaw is re-wrapped.
        let room = (cov.hfov() / 2.0 - frame_extent(pitch, a, b).half_lon - 1e-9).max(0.0);
        cov.yaw() + wrap_deg(view.yaw_deg() - cov.yaw()).clamp(-room, room)
    };
    View::new(yaw, pitch, hfov).unwrap_or(view)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::camera::{dir_to_lat_long, Camera};
    use proptest::prelude::*;

    /// Every border pixel's centre ray of `view` lies in `cov` (0.0001° slack).
    fn border_inside(view: View, w: u32, h: u32, cov: &Coverage) -> Result<(), String> {
        let cam = Camera::new(view, w, h);
        let border = (0..w)
            .flat_map(|x| [(x, 0), (x, h - 1)])
            .chain((0..h).flat_map(|y| [(0, y), (w - 1, y)]));
        for (x, y) in border {
            let (l, p) = dir_to_lat_long(cam.world_ray(x as f64 + 0.5, y as f64 + 0.5));
            if !cov.contains(l, p, 1e-4) {
                return Err(format!(
                    "{view:?} pixel ({x}, {y}) at ({:.4}, {:.4}) is outside {cov}",
                    l.to_degrees(),
                    p.to_degrees()
                ));
            }
        }
        Ok(())
    }

    #[test]
    fn extent_at_the_horizon_is_the_fov() {
        let (a, b) = tans(90.0, 200, 100);
        let e = frame_extent(0.0, a, b);
        assert!((e.half_lon - 45.0).abs() < 1e-9);
        assert!((e.lat_max - b.atan().to_degrees()).abs() < 1e-9);
        assert!((e.lat_min + e.lat_max).abs() < 1e-9);
        // looking up past the pole: all longitudes
        assert_eq!(frame_extent(80.0, a, b).half_lon, 180.0);
        assert_eq!(frame_extent(80.0, a, b).lat_max, 90.0);
    }

    #[test]
    fn fitting_views_are_unchanged() {
        let cov = Coverage::new(120.0, 60.0, 30.0, -10.0).unwrap();
        let v = View::new(30.0, -10.0, 40.0).unwrap();
        assert_eq!(limit_view(v, 160, 90, &cov), v);
        let full = Coverage::FULL;
        let v = View::new(123.0, 89.0, 120.0).unwrap();
        assert_eq!(limit_view(v, 160, 90, &full), v);
    }

    #[test]
    fn clamps_at_the_seam() {
        // 100 x 50 degrees centred on yaw 180: from 130 across the seam to -130
        let cov = Coverage::new(100.0, 50.0, 180.0, 5.0).unwrap();
        for yaw in [-179.0, 179.0, -120.0, 120.0, 0.0, 90.0, -90.0] {
            let v = View::new(yaw, 30.0, 90.0).unwrap();
            let l = limit_view(v, 320, 180, &cov);
            border_inside(l, 320, 180, &cov).unwrap();
            assert!(view_inside(l, 320, 180, &cov));
        }
        // a view inside near the seam keeps its yaw
        let v = View::new(-175.0, 5.0, 30.0).unwrap();
        assert_eq!(limit_view(v, 320, 180, &cov).yaw_deg(), -175.0);
    }

    #[test]
    fn hfov_shrinks_to_fit() {
        let cov = Coverage::new(60.0, 30.0, 0.0, 0.0).unwrap();
        let l = limit_view(View::new(0.0, 0.0, 120.0).unwrap(), 400, 300, &cov);
        assert!(l.hfov_deg() < 60.0, "{l:?}");
        border_inside(l, 400, 300, &cov).unwrap();
        // vertically it is the frame's height that limits: vfov ~ 30
        let (_, b) = tans(l.hfov_deg(), 400, 300);
        assert!((2.0 * b.atan().to_degrees() - 30.0).abs() < 1e-3);
    }

    #[test]
    fn full_width_coverage_leaves_yaw_free_and_allows_the_pole() {
        let cov = Coverage::new(360.0, 90.0, 0.0, 45.0).unwrap(); // 0..90 north
        let v = View::new(77.0, -40.0, 90.0).unwrap();
        let l = limit_view(v, 200, 100, &cov);
        assert_eq!(l.yaw_deg(), 77.0);
        border_inside(l, 200, 100, &cov).unwrap();
        let up = limit_view(View::new(10.0, 90.0, 90.0).unwrap(), 200, 100, &cov);
        assert_eq!(up.pitch_deg(), 90.0);
        border_inside(up, 200, 100, &cov).unwrap();
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        #[test]
        fn limited_views_stay_inside(
            chfov in 5.0f64..=360.0, cvfov in 5.0f64..=180.0,
            cyaw in -180.0f64..180.0, cpitch_t in 0.0f64..=1.0,
            yaw in -400.0f64..400.0, pitch in -90.0f64..=90.0, hfov in 1.0f64..170.0,
            w in 2u32..64, h in 2u32..64,
        ) {
            let cp = (90.0 - cvfov / 2.0) * (2.0 * cpitch_t - 1.0);
            let cov = Coverage::new(chfov, cvfov, cyaw, cp).unwrap();
            let v = View::new(yaw, pitch, hfov).unwrap();
            let l = limit_view(v, w, h, &cov);
            prop_assert!(view_inside(l, w, h, &cov), "{:?} -> {:?} in {}", v, l, cov);
            if let Err(e) = border_inside(l, w, h, &cov) {
                prop_assert!(false, "{}", e);
            }
            prop_assert!(l.hfov_deg() <= v.hfov_deg());
            // idempotent
            prop_assert_eq!(limit_view(l, w, h, &cov), l);
        }
    }
}

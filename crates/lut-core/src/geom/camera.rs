//! The camera of `docs/conventions.md`: yaw/pitch/hfov and an output projection → rays
//! through output pixel centers.

use crate::error::ViewError;
use crate::geom::limits::MAX_OUTPUT_SIDE;
use crate::geom::view_projection::{ViewProjection, PANNINI_D_MAX};
use glam::DVec3;

/// A validated view: angles in degrees as the user gives them, normalized, and the
/// output projection.
///
/// * yaw is reduced to (−180, 180] (any finite value is legal),
/// * pitch is clamped to [−90, 90],
/// * hfov must lie in the projection's range: the open interval (0, 180) for the
///   rectilinear camera ([`View::new`]), up to 360 for the others
///   ([`View::with_projection`], see [`ViewProjection`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    yaw: f64,
    pitch: f64,
    hfov: f64,
    projection: ViewProjection,
}

impl View {
    /// Validate and normalize a rectilinear view.
    ///
    /// # Errors
    /// [`ViewError::NonFinite`] for NaN/infinite angles, [`ViewError::HfovOutOfRange`]
    /// for an hfov outside (0, 180).
    pub fn new(yaw_deg: f64, pitch_deg: f64, hfov_deg: f64) -> Result<View, ViewError> {
        View::with_projection(yaw_deg, pitch_deg, hfov_deg, ViewProjection::Rectilinear)
    }

    /// Validate and normalize a view in output projection `projection`.
    ///
    /// # Errors
    /// [`ViewError::NonFinite`] for NaN/infinite angles; as [`ViewProjection::check`] for
    /// an hfov outside the projection's range or a bad Pannini parameter.
    pub fn with_projection(
        yaw_deg: f64,
        pitch_deg: f64,
        hfov_deg: f64,
        projection: ViewProjection,
    ) -> Result<View, ViewError> {
        for (name, value) in [("yaw", yaw_deg), ("pitch", pitch_deg), ("hfov", hfov_deg)] {
            if !value.is_finite() {
                return Err(ViewError::NonFinite { name, value });
            }
        }
        projection.check(hfov_deg)?;
        Ok(View {
            yaw: wrap_deg(yaw_deg),
            pitch: pitch_deg.clamp(-90.0, 90.0),
            hfov: hfov_deg,
            projection,
        })
    }

    /// A rectilinear view from any angles: the infallible form of [`View::new`]. Yaw is
    /// wrapped into (−180, 180], pitch clamped to [−90, 90] and hfov into the projection's
    /// range, as [`View::clamped_in`] does.
    pub fn clamped(yaw_deg: f64, pitch_deg: f64, hfov_deg: f64) -> View {
        View::clamped_in(yaw_deg, pitch_deg, hfov_deg, ViewProjection::Rectilinear)
    }

    /// A view in `projection` from any angles: the infallible form of
    /// [`View::with_projection`]. Yaw is wrapped into (−180, 180], pitch clamped to
    /// [−90, 90], hfov clamped to [[`View::HFOV_MIN`], the widest the projection takes]
    /// (just short of it where that end is open), and a Pannini d into
    /// [0, [`PANNINI_D_MAX`]].
    ///
    /// Angles that are not numbers do not pass through: a NaN yaw or pitch (and an
    /// infinite yaw, which has no direction) becomes 0, a NaN hfov the default view's
    /// 90° (clamped as above), a NaN Pannini d 0. Infinite pitch and hfov clamp to their
    /// ends. The result always holds finite, in-range angles, so
    /// [`View::with_projection`] accepts them unchanged.
    pub fn clamped_in(
        yaw_deg: f64,
        pitch_deg: f64,
        hfov_deg: f64,
        projection: ViewProjection,
    ) -> View {
        let projection = match projection {
            ViewProjection::Pannini(d) if d.is_nan() => ViewProjection::Pannini(0.0),
            ViewProjection::Pannini(d) => ViewProjection::Pannini(d.clamp(0.0, PANNINI_D_MAX)),
            p => p,
        };
        let yaw = if yaw_deg.is_finite() {
            wrap_deg(yaw_deg)
        } else {
            0.0
        };
        let pitch = if pitch_deg.is_nan() {
            0.0
        } else {
            pitch_deg.clamp(-90.0, 90.0)
        };
        let hfov = if hfov_deg.is_nan() { 90.0 } else { hfov_deg };
        let (max, _) = projection.hfov_max();
        let mut hfov = hfov.clamp(View::HFOV_MIN, max);
        if projection.check(hfov).is_err() {
            // Past the widest end (open, or where the focal length vanishes): the widest
            // accepted hfov below it, by bisection from the narrowest (always accepted).
            let (mut ok, mut bad) = (View::HFOV_MIN, hfov);
            for _ in 0..64 {
                let mid = 0.5 * (ok + bad);
                if projection.check(mid).is_ok() {
                    ok = mid;
                } else {
                    bad = mid;
                }
            }
            hfov = ok;
        }
        View {
            yaw,
            pitch,
            hfov,
            projection,
        }
    }

    /// The narrowest hfov [`View::clamped`] gives, degrees.
    pub const HFOV_MIN: f64 = 1e-3;

    /// This view in another output projection (same yaw, pitch and hfov).
    ///
    /// # Errors
    /// As [`View::with_projection`].
    pub fn projected(self, projection: ViewProjection) -> Result<View, ViewError> {
        View::with_projection(self.yaw, self.pitch, self.hfov, projection)
    }

    /// The output projection.
    pub fn projection(&self) -> ViewProjection {
        self.projection
    }

    /// Yaw in degrees, (−180, 180].
    pub fn yaw_deg(&self) -> f64 {
        self.yaw
    }
    /// Pitch in degrees, [−90, 90].
    pub fn pitch_deg(&self) -> f64 {
        self.pitch
    }
    /// Horizontal field of view in degrees (in the projection's range).
    pub fn hfov_deg(&self) -> f64 {
        self.hfov
    }
    /// Yaw in radians.
    pub fn yaw(&self) -> f64 {
        self.yaw.to_radians()
    }
    /// Pitch in radians.
    pub fn pitch(&self) -> f64 {
        self.pitch.to_radians()
    }
    /// hfov in radians.
    pub fn hfov(&self) -> f64 {
        self.hfov.to_radians()
    }
}

impl Default for View {
    fn default() -> Self {
        View {
            yaw: 0.0,
            pitch: 0.0,
            hfov: 90.0,
            projection: ViewProjection::Rectilinear,
        }
    }
}

/// Reduce degrees to (−180, 180], exactly for integers and well-behaved for huge values.
pub fn wrap_deg(a: f64) -> f64 {
    if a > -180.0 && a <= 180.0 {
        return a;
    }
    let r = a.rem_euclid(360.0);
    if r > 180.0 {
        r - 360.0
    } else {
        r
    }
}

/// Check an output size against `1..=MAX_OUTPUT_SIDE`.
///
/// # Errors
/// [`ViewError::BadSize`] when a side is 0 or too large.
pub fn check_size(width: u32, height: u32) -> Result<(), ViewError> {
    if width == 0 || height == 0 || width > MAX_OUTPUT_SIDE || height > MAX_OUTPUT_SIDE {
        return Err(ViewError::BadSize {
            width,
            height,
            max: MAX_OUTPUT_SIDE,
        });
    }
    Ok(())
}

/// A camera for one output size: pixel centers → world rays, f64 throughout.
#[derive(Debug, Clone, Copy)]
pub struct Camera {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Focal length in pixels of the view's projection ([`ViewProjection::focal`];
    /// (W/2) / tan(hfov/2) for the rectilinear camera).
    pub focal: f64,
    projection: ViewProjection,
    /// sin and cos of pitch.
    sp: f64,
    cp: f64,
    /// sin and cos of yaw.
    sy: f64,
    cy: f64,
    view: View,
}

impl Camera {
    /// A camera for `view` rendering a `width × height` image.
    pub fn new(view: View, width: u32, height: u32) -> Camera {
        let projection = view.projection();
        let focal = projection.focal(width, view.hfov());
        let (sp, cp) = view.pitch().sin_cos();
        let (sy, cy) = view.yaw().sin_cos();
        Camera {
            width,
            height,
            focal,
            projection,
            sp,
            cp,
            sy,
            cy,
            view,
        }
    }

    /// The view this camera was made for.
    pub fn view(&self) -> View {
        self.view
    }

    /// The output projection.
    pub fn projection(&self) -> ViewProjection {
        self.projection
    }

    /// Camera-space ray through a point of the rectilinear image plane (pixel
    /// coordinates, pixel centers at +0.5): X right, Y up, Z forward. For a rectilinear
    /// view only (the scanline renderers' model); [`Camera::ray`] handles every projection.
    #[inline]
    pub fn camera_ray(&self, px: f64, py: f64) -> DVec3 {
        debug_assert!(
            self.projection.is_rectilinear(),
            "camera_ray of a {} view",
            self.projection
        );
        DVec3::new(
            px - self.width as f64 / 2.0,
            self.height as f64 / 2.0 - py,
            self.focal,
        )
    }

    /// World direction (not normalized) of the rectilinear ray through image point
    /// (px, py): rotated by pitch about X (Z toward +Y), then by yaw about Y (Z toward
    /// +X). For a rectilinear view only (the LUT's and the cube renderers' model);
    /// [`Camera::ray`] handles every projection.
    #[inline]
    pub fn world_ray(&self, px: f64, py: f64) -> DVec3 {
        self.rotate(self.camera_ray(px, py))
    }

    /// World direction (not normalized) of image point (px, py) (pixel coordinates,
    /// centers at +0.5) in the view's projection, or `None` where the projection has no
    /// direction (outside a fisheye's disc). Equal to [`Camera::world_ray`] for a
    /// rectilinear view.
    #[inline]
    pub fn ray(&self, px: f64, py: f64) -> Option<DVec3> {
        if self.projection == ViewProjection::Rectilinear {
            return Some(self.world_ray(px, py));
        }
        let (cx, cy) = (px - self.width as f64 / 2.0, self.height as f64 / 2.0 - py);
        self.projection
            .direction(self.focal, cx, cy)
            .map(|d| self.rotate(d))
    }

    /// A camera-space direction turned into the world: by pitch about X, then yaw about Y.
    #[inline]
    pub fn rotate(&self, d: DVec3) -> DVec3 {
        // pitch about X
        let y1 = d.y * self.cp + d.z * self.sp;
        let z1 = d.z * self.cp - d.y * self.sp;
        // yaw about Y
        let x2 = d.x * self.cy + z1 * self.sy;
        let z2 = z1 * self.cy - d.x * self.sy;
        DVec3::new(x2, y1, z2)
    }

    /// (λ, φ) of the ray through the center of output pixel (x, y), or `None` where the
    /// projection has no direction.
    #[inline]
    pub fn pixel_lat_long(&self, x: u32, y: u32) -> Option<(f64, f64)> {
        self.ray(x as f64 + 0.5, y as f64 + 0.5)
            .map(dir_to_lat_long)
    }

    /// The inverse of [`Camera::ray`]: image position (pixel coordinates) of a world
    /// direction, or `None` when the view does not show it (behind a rectilinear camera).
    pub fn project(&self, d: DVec3) -> Option<(f64, f64)> {
        // undo yaw
        let x1 = d.x * self.cy - d.z * self.sy;
        let z1 = d.x * self.sy + d.z * self.cy;
        // undo pitch
        let y0 = d.y * self.cp - z1 * self.sp;
        let z0 = z1 * self.cp + d.y * self.sp;
        let (px, py) = self
            .projection
            .image_point(self.focal, DVec3::new(x1, y0, z0))?;
        Some((px + self.width as f64 / 2.0, self.height as f64 / 2.0 - py))
    }
}

/// longitude λ = atan2(X, Z) in (−π, π], latitude φ = atan2(Y, √(X²+Z²)).
#[inline]
pub fn dir_to_lat_long(d: DVec3) -> (f64, f64) {
    let lambda = d.x.atan2(d.z);
    let phi = d.y.atan2((d.x * d.x + d.z * d.z).sqrt());
    (lambda, phi)
}

/// Unit direction of (λ, φ).
#[inline]
pub fn lat_long_to_dir(lambda: f64, phi: f64) -> DVec3 {
    let (sl, cl) = lambda.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(cp * sl, sp, cp * cl)
}

#[cfg(test)]
mod clamped_tests {
    use super::*;

    /// `View::clamped` wraps yaw into (−180, 180] and clamps pitch and hfov, agreeing with
    /// `View::new` wherever that accepts the angles.
    #[test]
    fn clamped_wraps_and_clamps() {
        let v = View::clamped(540.0, 100.0, 200.0);
        assert_eq!((v.yaw_deg(), v.pitch_deg()), (180.0, 90.0));
        assert!(
            v.hfov_deg() < 180.0 && v.hfov_deg() > 179.9,
            "{}",
            v.hfov_deg()
        );
        let v = View::clamped(-190.0, -95.0, 0.0);
        assert_eq!((v.yaw_deg(), v.pitch_deg()), (170.0, -90.0));
        assert_eq!(v.hfov_deg(), View::HFOV_MIN);
        assert_eq!(View::clamped(-180.0, 0.0, 90.0).yaw_deg(), 180.0);
        for (y, p, h) in [
            (10.0, 20.0, 90.0),
            (-179.5, -89.0, 1.0),
            (725.0, 45.0, 179.0),
        ] {
            assert_eq!(
                View::clamped(y, p, h),
                View::new(y, p, h).unwrap(),
                "{y} {p} {h}"
            );
        }
        // The widest end of each projection: accepted by the fallible form.
        for p in [
            ViewProjection::Rectilinear,
            ViewProjection::Stereographic,
            ViewProjection::Pannini(1.0),
            ViewProjection::Pannini(f64::INFINITY),
        ] {
            let v = View::clamped_in(0.0, 0.0, f64::INFINITY, p);
            let back = View::with_projection(0.0, 0.0, v.hfov_deg(), v.projection());
            assert_eq!(back, Ok(v), "{p:?}");
            assert!(
                v.hfov_deg() > 0.99 * v.projection().hfov_max().0,
                "{p:?} {v:?}"
            );
        }
    }

    /// NaN does not pass through: it becomes the documented value, every angle of the
    /// result is finite, and the fallible form accepts it.
    #[test]
    fn clamped_replaces_nan() {
        let nan = f64::NAN;
        let v = View::clamped(nan, nan, nan);
        assert_eq!((v.yaw_deg(), v.pitch_deg(), v.hfov_deg()), (0.0, 0.0, 90.0));
        let v = View::clamped(f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY);
        assert_eq!((v.yaw_deg(), v.pitch_deg()), (0.0, -90.0));
        assert!(v.hfov_deg().is_finite());
        let v = View::clamped_in(30.0, nan, 400.0, ViewProjection::Pannini(nan));
        assert_eq!(v.projection(), ViewProjection::Pannini(0.0));
        assert_eq!((v.yaw_deg(), v.pitch_deg()), (30.0, 0.0));
        for v in [v, View::clamped(nan, 1.0, 1.0)] {
            assert!(v.yaw_deg().is_finite() && v.pitch_deg().is_finite());
            assert!(v.hfov_deg().is_finite());
            let back =
                View::with_projection(v.yaw_deg(), v.pitch_deg(), v.hfov_deg(), v.projection());
            assert_eq!(back, Ok(v));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation() {
        assert!(View::new(f64::NAN, 0.0, 90.0).is_err());
        assert!(View::new(0.0, f64::INFINITY, 90.0).is_err());
        assert!(View::new(0.0, 0.0, 0.0).is_err());
        assert!(View::new(0.0, 0.0, 180.0).is_err());
        assert!(View::new(0.0, 0.0, 179.99).is_ok());
        let v = View::new(540.0, 100.0, 90.0).unwrap();
        assert_eq!(v.yaw_deg(), 180.0);
        assert_eq!(v.pitch_deg(), 90.0);
        assert_eq!(View::new(-180.0, 0.0, 1.0).unwrap().yaw_deg(), 180.0);
        let big = View::new(1e9, 0.0, 1.0).unwrap().yaw_deg();
        assert!(big > -180.0 && big <= 180.0);
    }

    #[test]
    fn center_ray_follows_yaw_and_pitch() {
        let cam = Camera::new(View::new(30.0, 20.0, 90.0).unwrap(), 100, 100);
        let (l, p) = dir_to_lat_long(cam.world_ray(50.0, 50.0));
        assert!((l.to_degrees() - 30.0).abs() < 1e-9);
        assert!((p.to_degrees() - 20.0).abs() < 1e-9);
        // right of center is larger longitude, above is larger latitude
        let (l2, _) = dir_to_lat_long(cam.world_ray(60.0, 50.0));
        assert!(l2 > l);
        let (_, p2) = dir_to_lat_long(cam.world_ray(50.0, 40.0));
        assert!(p2 > p);
    }

    #[test]
    fn project_inverts_world_ray() {
        let cam = Camera::new(View::new(-70.0, 35.0, 100.0).unwrap(), 640, 480);
        for (x, y) in [(0.5, 0.5), (320.0, 240.0), (639.5, 10.0)] {
            let d = cam.world_ray(x, y);
            let (px, py) = cam.project(d).unwrap();
            assert!((px - x).abs() < 1e-9 && (py - y).abs() < 1e-9);
        }
    }
}

//! The camera of `docs/conventions.md`: yaw/pitch/hfov → rays through output pixel centers.

use crate::error::ViewError;
use crate::geom::limits::MAX_OUTPUT_SIDE;
use glam::DVec3;

/// A validated view: angles in degrees as the user gives them, normalized.
///
/// * yaw is reduced to (−180, 180] (any finite value is legal),
/// * pitch is clamped to [−90, 90],
/// * hfov must lie in the open interval (0, 180).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    yaw: f64,
    pitch: f64,
    hfov: f64,
}

impl View {
    /// Validate and normalize a view.
    ///
    /// # Errors
    /// [`ViewError::NonFinite`] for NaN/infinite angles, [`ViewError::HfovOutOfRange`]
    /// for an hfov outside (0, 180).
    pub fn new(yaw_deg: f64, pitch_deg: f64, hfov_deg: f64) -> Result<View, ViewError> {
        for (name, value) in [("yaw", yaw_deg), ("pitch", pitch_deg), ("hfov", hfov_deg)] {
            if !value.is_finite() {
                return Err(ViewError::NonFinite { name, value });
            }
        }
        if !(hfov_deg > 0.0 && hfov_deg < 180.0) {
            return Err(ViewError::HfovOutOfRange(hfov_deg));
        }
        Ok(View {
            yaw: wrap_deg(yaw_deg),
            pitch: pitch_deg.clamp(-90.0, 90.0),
            hfov: hfov_deg,
        })
    }

    /// Yaw in degrees, (−180, 180].
    pub fn yaw_deg(&self) -> f64 {
        self.yaw
    }
    /// Pitch in degrees, [−90, 90].
    pub fn pitch_deg(&self) -> f64 {
        self.pitch
    }
    /// Horizontal field of view in degrees, (0, 180).
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
    /// Focal length in pixels: (W/2) / tan(hfov/2).
    pub focal: f64,
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
        let focal = (width as f64 / 2.0) / (view.hfov() / 2.0).tan();
        let (sp, cp) = view.pitch().sin_cos();
        let (sy, cy) = view.yaw().sin_cos();
        Camera {
            width,
            height,
            focal,
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

    /// Camera-space ray through a point of the image plane (pixel coordinates, pixel
    /// centers at +0.5): X right, Y up, Z forward.
    #[inline]
    pub fn camera_ray(&self, px: f64, py: f64) -> DVec3 {
        DVec3::new(
            px - self.width as f64 / 2.0,
            self.height as f64 / 2.0 - py,
            self.focal,
        )
    }

    /// World direction (not normalized) of the ray through image point (px, py): rotated
    /// by pitch about X (Z toward +Y), then by yaw about Y (Z toward +X).
    #[inline]
    pub fn world_ray(&self, px: f64, py: f64) -> DVec3 {
        let d = self.camera_ray(px, py);
        // pitch about X
        let y1 = d.y * self.cp + d.z * self.sp;
        let z1 = d.z * self.cp - d.y * self.sp;
        // yaw about Y
        let x2 = d.x * self.cy + z1 * self.sy;
        let z2 = z1 * self.cy - d.x * self.sy;
        DVec3::new(x2, y1, z2)
    }

    /// (λ, φ) of the ray through the center of output pixel (x, y).
    #[inline]
    pub fn pixel_lat_long(&self, x: u32, y: u32) -> (f64, f64) {
        dir_to_lat_long(self.world_ray(x as f64 + 0.5, y as f64 + 0.5))
    }

    /// The inverse of [`Camera::world_ray`]: image-plane position (pixel coordinates) of
    /// a world direction, or `None` when it is behind the camera.
    pub fn project(&self, d: DVec3) -> Option<(f64, f64)> {
        // undo yaw
        let x1 = d.x * self.cy - d.z * self.sy;
        let z1 = d.x * self.sy + d.z * self.cy;
        // undo pitch
        let y0 = d.y * self.cp - z1 * self.sp;
        let z0 = z1 * self.cp + d.y * self.sp;
        if z0 <= 0.0 {
            return None;
        }
        let s = self.focal / z0;
        Some((
            x1 * s + self.width as f64 / 2.0,
            self.height as f64 / 2.0 - y0 * s,
        ))
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

//! Hotspot markers on a rendered view: where each hotspot's direction falls in the
//! frame (any output projection), and the markers drawn there.
//!
//! A hotspot is shown where the view's projection has an image point for its direction
//! and that point's own ray comes back to the direction (so a direction behind a
//! rectilinear viewer, or outside a fisheye's disc, is not drawn), inside the frame.

use super::{HotspotKind, TourScene};
use glam::DVec3;
use lut_core::{lat_long_to_dir, Camera, View};

/// Marker radius in pixels (outline included).
pub const MARKER_RADIUS: f64 = 9.0;
/// A scene link's fill (0RGB).
pub const SCENE_COLOR: u32 = 0x00FF_B000;
/// An info hotspot's fill (0RGB).
pub const INFO_COLOR: u32 = 0x0030_A0FF;
/// The outline.
pub const OUTLINE_COLOR: u32 = 0x0010_1010;

/// Where a hotspot is in a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placed {
    /// The hotspot's index in its scene.
    pub index: usize,
    /// Its centre, pixel coordinates (pixel centres at +0.5).
    pub x: f64,
    /// Its centre, pixel coordinates.
    pub y: f64,
}

/// The image position of a direction (yaw, pitch in degrees) in `view` on a `w × h`
/// frame, `None` where the view does not show it.
pub fn place(view: View, w: u32, h: u32, yaw: f64, pitch: f64) -> Option<(f64, f64)> {
    let cam = Camera::new(view, w, h);
    place_dir(&cam, lat_long_to_dir(yaw.to_radians(), pitch.to_radians()))
}

/// The image position of unit direction `d` in `cam`'s frame, `None` where it does not
/// show it (the test of [`place`]).
pub fn place_dir(cam: &Camera, d: DVec3) -> Option<(f64, f64)> {
    let (w, h) = (cam.width, cam.height);
    let (x, y) = cam.project(d)?;
    if !(x.is_finite() && y.is_finite()) || x < 0.0 || y < 0.0 || x > w as f64 || y > h as f64 {
        return None;
    }
    // The point's own ray must come back to the direction.
    let back = cam.ray(x, y)?.normalize();
    (back.dot(d) > 1.0 - 1e-9).then_some((x, y))
}

/// The direction (yaw, pitch, degrees) seen at pixel position (`x`, `y`) of a `w × h`
/// frame of `view` (the inverse of [`place`]); `None` where the projection has none.
pub fn direction_at(view: View, w: u32, h: u32, x: f64, y: f64) -> Option<(f64, f64)> {
    let d = Camera::new(view, w, h).ray(x, y)?.normalize();
    if !d.is_finite() {
        return None;
    }
    let (lambda, phi) = lut_core::dir_to_lat_long(d);
    Some((lambda.to_degrees(), phi.to_degrees()))
}

/// Every hotspot of `scene` the view shows, in hotspot order.
pub fn placed(scene: &TourScene, view: View, w: u32, h: u32) -> Vec<Placed> {
    scene
        .hotspots
        .iter()
        .enumerate()
        .filter_map(|(index, hs)| {
            place(view, w, h, hs.yaw, hs.pitch).map(|(x, y)| Placed { index, x, y })
        })
        .collect()
}

/// Draw the markers of `scene` seen in `view` into `out` (`w × h`, 0RGB): a disc per
/// hotspot (scene links amber, info blue) with a dark outline, centred on its direction.
pub fn draw(scene: &TourScene, view: View, out: &mut [u32], w: u32, h: u32) -> Vec<Placed> {
    let list = placed(scene, view, w, h);
    for p in &list {
        let fill = match scene.hotspots[p.index].kind {
            HotspotKind::Scene { .. } => SCENE_COLOR,
            HotspotKind::Info { .. } => INFO_COLOR,
        };
        disc(out, w, h, p.x, p.y, fill);
    }
    list
}

/// A disc of radius [`MARKER_RADIUS`] centred at (cx, cy): the fill inside
/// `MARKER_RADIUS - 2`, the outline around it. Symmetric about its centre, so the
/// centroid of its pixels is the centre (to the pixel grid's rounding).
pub fn disc(out: &mut [u32], w: u32, h: u32, cx: f64, cy: f64, fill: u32) {
    let r = MARKER_RADIUS;
    let x0 = (cx - r).floor().max(0.0) as i64;
    let x1 = ((cx + r).ceil() as i64).min(w as i64 - 1);
    let y0 = (cy - r).floor().max(0.0) as i64;
    let y1 = ((cy + r).ceil() as i64).min(h as i64 - 1);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let dx = x as f64 + 0.5 - cx;
            let dy = y as f64 + 0.5 - cy;
            let d2 = dx * dx + dy * dy;
            if d2 <= r * r {
                let c = if d2 <= (r - 2.0) * (r - 2.0) {
                    fill
                } else {
                    OUTLINE_COLOR
                };
                out[y as usize * w as usize + x as usize] = c;
            }
        }
    }
}

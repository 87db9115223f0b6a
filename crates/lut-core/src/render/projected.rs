//! Cube maps in the output projections that are not rectilinear (stereographic, fisheye,
//! equisolid, Pannini): per pixel, the view's ray ([`Camera::ray`]) → face by the largest
//! |coordinate| → face coordinates → sample, as the basic cube renderer does for the
//! rectilinear camera. Pixels with no direction (outside a fisheye's disc) are black, the
//! cube's background.

use super::frame::Frame;
use super::rows::for_each_row;
use crate::cube::CubeMap;
use crate::geom::camera::{Camera, View};
use crate::map::sample::Sampler;

/// Render `view` (any output projection) of `cube` into `frame`, per pixel.
pub(crate) fn render_cube(
    cube: &CubeMap,
    view: View,
    sampler: Sampler,
    frame: &mut Frame<'_>,
    threads: bool,
) {
    let (width, height) = (frame.width(), frame.height());
    let cam = Camera::new(view, width, height);
    for_each_row(frame.pixels_mut(), width as usize, threads, |y, line| {
        for (x, px) in line.iter_mut().enumerate() {
            *px = cam
                .ray(x as f64 + 0.5, y as f64 + 0.5)
                .map_or(0, |d| cube.sample_dir(sampler, d));
        }
    });
}

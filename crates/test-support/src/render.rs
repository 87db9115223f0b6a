//! Frames rendered into new buffers, for tests that compare whole images.

use lut_core::{
    render_exact, EnvMap, Frame, Panorama, RenderOptions, RenderReport, Renderer, Sampler, View,
};

/// `view` of `map` rendered by `r` with `opts` into a new `w × h` buffer.
///
/// # Panics
/// On a bad size or a render error (tests pass valid requests).
pub fn render_frame(
    r: &mut Renderer,
    map: &EnvMap,
    view: View,
    opts: &RenderOptions,
    w: u32,
    h: u32,
) -> (Vec<u32>, RenderReport) {
    let mut out = vec![0u32; w as usize * h as usize];
    let report = r
        .render(
            map,
            view,
            opts,
            &mut Frame::new(&mut out, w, h).expect("frame"),
        )
        .expect("render");
    (out, report)
}

/// `view` of `pano` (a map or a cube map) rendered with `opts` into a new `w × h`
/// buffer.
///
/// # Panics
/// On a bad size or a render error (tests pass valid requests).
pub fn pano_frame(
    pano: &mut Panorama,
    view: View,
    opts: &RenderOptions,
    w: u32,
    h: u32,
) -> (Vec<u32>, RenderReport) {
    let mut out = vec![0u32; w as usize * h as usize];
    let report = pano
        .render(view, opts, &mut Frame::new(&mut out, w, h).expect("frame"))
        .expect("render");
    (out, report)
}

/// `view` of `map` rendered by the exact renderer into a new `w × h` buffer (one
/// thread).
pub fn exact_frame(map: &EnvMap, view: View, sampler: Sampler, w: u32, h: u32) -> Vec<u32> {
    let mut out = vec![0u32; w as usize * h as usize];
    render_exact(
        map,
        view,
        sampler,
        &mut Frame::new(&mut out, w, h).expect("frame"),
        false,
    );
    out
}

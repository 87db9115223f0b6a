//! Rendering a [`Panorama`] (lut-core's one panorama type: a map with its LUT renderer,
//! or a cube map) into a pixel buffer, [`render_scene`], lit as its rows are drawn
//! ([`render_scene_lit`]), and its error map ([`measure_errors`]). `viewer render`, the
//! window (frames and "Save view…") and `viewer bench` all render through them.

use lut_core::{
    ErrorMap, Frame, FrameShader, Panorama, RenderOptions, RenderReport, View, ViewError,
};

/// Render `view` of `pano` into `out` (`width × height` 0RGB pixels) through lut-core's
/// one render entry ([`Panorama::render`]: a map with its renderer and tables, a cube map
/// with `opts.cube`).
///
/// # Errors
/// As `Frame::new` and `Renderer::render`: a bad size or buffer, a bad option.
pub fn render_scene(
    pano: &mut Panorama,
    view: View,
    opts: &RenderOptions,
    out: &mut [u32],
    width: u32,
    height: u32,
) -> Result<RenderReport, ViewError> {
    render_scene_lit(pano, view, opts, out, width, height, None)
}

/// [`render_scene`], lit by `shader` (made for `width × height`) as the rows are drawn:
/// the renderer runs [`FrameShader::shade_band`] on each band of rows while it is in
/// cache ([`Panorama::render_with`]), so lighting costs no second pass over the
/// frame. The pixels are those of [`render_scene`] then `IlluminanceMap::shade_frame`.
///
/// # Errors
/// As [`render_scene`].
///
/// # Panics
/// When `shader` was made for another frame size (a caller's bug).
pub fn render_scene_lit(
    pano: &mut Panorama,
    view: View,
    opts: &RenderOptions,
    out: &mut [u32],
    width: u32,
    height: u32,
    shader: Option<&FrameShader<'_>>,
) -> Result<RenderReport, ViewError> {
    let mut frame = Frame::new(out, width, height)?;
    match shader {
        Some(s) => {
            assert_eq!(s.size(), (width, height), "shader made for another frame");
            let hook = |y0: usize, rows: &mut [u32]| s.shade_band(y0, rows);
            pano.render_with(view, opts, &mut frame, &hook)
        }
        None => pano.render(view, opts, &mut frame),
    }
}

/// The error map ([`lut_core::ErrorMap`]) of the renderer `opts` selects for `view` of
/// `pano` on a `width × height` output ([`Panorama::error_map`]): what `viewer render
/// --error-map` writes and the window's heat map shows.
///
/// # Errors
/// As [`render_scene`].
pub fn measure_errors(
    pano: &mut Panorama,
    view: View,
    opts: &RenderOptions,
    width: u32,
    height: u32,
) -> Result<ErrorMap, ViewError> {
    pano.error_map(view, opts, width, height)
}

#[cfg(test)]
mod tests {
    use super::*;
    use lut_core::{CubeMap, CubeRenderer, Projection, RenderPath, Renderer, Sampler};

    /// The map path is the map's renderer, the cube path lut-core's cube renderer, with
    /// the options given: same pixels as calling lut-core directly.
    #[test]
    fn renders_maps_and_cubes_as_lut_core_does() {
        let map = lut_core::grid_map(128, 64, Projection::Equirect).unwrap();
        let view = View::new(30.0, 10.0, 90.0).unwrap();
        let (w, h) = (40, 24);
        let opts = RenderOptions {
            sampler: Sampler::Nearest,
            ..RenderOptions::default()
        };
        let mut want = vec![0u32; (w * h) as usize];
        let direct = Renderer::new(&map)
            .render(&map, view, &opts, &mut Frame::new(&mut want, w, h).unwrap())
            .unwrap();
        let cube = CubeMap::from_envmap(&map, 16, Sampler::Bilinear).unwrap();
        let mut pano = Panorama::map(map);
        let mut got = vec![1u32; want.len()];
        let report = render_scene(&mut pano, view, &opts, &mut got, w, h).unwrap();
        assert_eq!(report, direct);
        assert_eq!(direct.path, RenderPath::LutWide);
        assert_eq!(got, want);

        for kind in [CubeRenderer::Basic, CubeRenderer::Accelerated] {
            let opts = RenderOptions { cube: kind, ..opts };
            let mut pano = Panorama::cube(cube.clone());
            let mut got = vec![1u32; want.len()];
            let report = render_scene(&mut pano, view, &opts, &mut got, w, h).unwrap();
            assert_eq!(report.path, RenderPath::Cube(kind));
            let mut want = vec![0u32; got.len()];
            let mut direct = Panorama::cube(cube.clone());
            direct
                .render(view, &opts, &mut Frame::new(&mut want, w, h).unwrap())
                .unwrap();
            assert_eq!(got, want);
            assert!(pano.as_map().is_none());
        }
        // A bad size is an error, not a panic.
        let mut pano = Panorama::cube(cube);
        assert!(render_scene(&mut pano, view, &opts, &mut got, 0, h).is_err());
    }
}

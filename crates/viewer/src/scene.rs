//! What the viewer renders — a map with its LUT renderer (which owns the tables), or a
//! cube map — and the one function that renders it, [`render_scene`], through lut-core's
//! one render entry. `viewer render`, the window (frames and "Save view…") and `viewer
//! bench` all render through it.

use lut_core::{
    CubeMap, EnvMap, ErrorMap, Frame, FrameShader, RenderOptions, RenderReport, Renderer, View,
    ViewError,
};
use std::sync::Arc;

/// A panorama ready to render, owning its data (and, for a map, its tables). The pixels
/// are shared (`Arc`), not copied, with the window's baking thread, which lights them
/// while frames are drawn from them.
pub enum Scene {
    /// A map on a surface of revolution, with its LUT renderer.
    Map {
        /// The map.
        map: Arc<EnvMap>,
        /// Its renderer (tables built on first use).
        renderer: Renderer,
    },
    /// A cube map.
    Cube(Arc<CubeMap>),
}

impl Scene {
    /// A map with a new renderer.
    pub fn map(map: EnvMap) -> Scene {
        let renderer = Renderer::new(&map);
        Scene::Map {
            map: Arc::new(map),
            renderer,
        }
    }

    /// A cube map.
    pub fn cube(cube: CubeMap) -> Scene {
        Scene::Cube(Arc::new(cube))
    }

    /// The scene to pass to [`render_scene`].
    pub fn as_mut(&mut self) -> SceneRef<'_> {
        match self {
            Scene::Map { map, renderer } => SceneRef::Map { map, renderer },
            Scene::Cube(cube) => SceneRef::Cube(cube),
        }
    }

    /// The map, if the scene is one.
    pub fn env_map(&self) -> Option<&EnvMap> {
        match self {
            Scene::Map { map, .. } => Some(map),
            Scene::Cube(_) => None,
        }
    }
}

/// A scene borrowed for one render.
pub enum SceneRef<'a> {
    /// A map and its renderer.
    Map {
        /// The map.
        map: &'a EnvMap,
        /// Its renderer.
        renderer: &'a mut Renderer,
    },
    /// A cube map.
    Cube(&'a CubeMap),
}

/// Render `view` of `scene` into `out` (`width × height` 0RGB pixels) through lut-core's
/// one render entry: a map with its renderer (and tables), a cube map with
/// `opts.cube`.
///
/// # Errors
/// As `Frame::new` and `Renderer::render`: a bad size or buffer, a bad option.
pub fn render_scene(
    scene: SceneRef<'_>,
    view: View,
    opts: &RenderOptions,
    out: &mut [u32],
    width: u32,
    height: u32,
) -> Result<RenderReport, ViewError> {
    render_scene_lit(scene, view, opts, out, width, height, None)
}

/// [`render_scene`], lit by `shader` (made for `width × height`) as the rows are drawn:
/// the renderer runs [`FrameShader::shade_band`] on each band of rows while it is in
/// cache (lut-core's `Renderer::render_with`), so lighting costs no second pass over the
/// frame. The pixels are those of [`render_scene`] then `IlluminanceMap::shade_frame`.
///
/// # Errors
/// As [`render_scene`].
///
/// # Panics
/// When `shader` was made for another frame size (a caller's bug).
pub fn render_scene_lit(
    scene: SceneRef<'_>,
    view: View,
    opts: &RenderOptions,
    out: &mut [u32],
    width: u32,
    height: u32,
    shader: Option<&FrameShader<'_>>,
) -> Result<RenderReport, ViewError> {
    let mut frame = Frame::new(out, width, height)?;
    let mut cube_renderer = Renderer::default();
    let (scene, renderer) = match scene {
        SceneRef::Map { map, renderer } => (lut_core::Scene::Map(map), renderer),
        SceneRef::Cube(cube) => (lut_core::Scene::Cube(cube), &mut cube_renderer),
    };
    match shader {
        Some(s) => {
            assert_eq!(s.size(), (width, height), "shader made for another frame");
            let hook = |y0: usize, rows: &mut [u32]| s.shade_band(y0, rows);
            renderer.render_with(scene, view, opts, &mut frame, &hook)
        }
        None => renderer.render(scene, view, opts, &mut frame),
    }
}

/// The error map ([`lut_core::ErrorMap`]) of the renderer `opts` selects for `view` of
/// `scene` on a `width × height` output: what `viewer render --error-map` writes and the
/// window's heat map shows.
///
/// # Errors
/// As [`render_scene`].
pub fn measure_errors(
    scene: SceneRef<'_>,
    view: View,
    opts: &RenderOptions,
    width: u32,
    height: u32,
) -> Result<ErrorMap, ViewError> {
    match scene {
        SceneRef::Map { map, renderer } => ErrorMap::measure(
            renderer,
            lut_core::Scene::Map(map),
            view,
            opts,
            width,
            height,
        ),
        SceneRef::Cube(cube) => ErrorMap::measure(
            &mut Renderer::default(),
            lut_core::Scene::Cube(cube),
            view,
            opts,
            width,
            height,
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lut_core::{CubeRenderer, Projection, RenderPath, Sampler};

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
            .render(
                lut_core::Scene::Map(&map),
                view,
                &opts,
                &mut Frame::new(&mut want, w, h).unwrap(),
            )
            .unwrap();
        let cube = CubeMap::from_envmap(&map, 16, Sampler::Bilinear).unwrap();
        let mut scene = Scene::map(map);
        let mut got = vec![1u32; want.len()];
        let report = render_scene(scene.as_mut(), view, &opts, &mut got, w, h).unwrap();
        assert_eq!(report, direct);
        assert_eq!(direct.path, RenderPath::LutWide);
        assert_eq!(got, want);

        for kind in [CubeRenderer::Basic, CubeRenderer::Accelerated] {
            let opts = RenderOptions { cube: kind, ..opts };
            Renderer::default()
                .render(
                    lut_core::Scene::Cube(&cube),
                    view,
                    &opts,
                    &mut Frame::new(&mut want, w, h).unwrap(),
                )
                .unwrap();
            let mut scene = Scene::cube(cube.clone());
            let report = render_scene(scene.as_mut(), view, &opts, &mut got, w, h).unwrap();
            assert_eq!(report.path, RenderPath::Cube(kind));
            assert_eq!(got, want);
            assert!(scene.env_map().is_none());
        }
        // A bad size is an error, not a panic.
        let mut scene = Scene::cube(cube);
        assert!(render_scene(scene.as_mut(), view, &opts, &mut got, 0, h).is_err());
    }
}

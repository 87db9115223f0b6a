//! What the viewer renders — a map through its LUT renderer, or a cube map — and the one
//! function that renders it, [`render_scene`]. `viewer render`, the window (frames and
//! "Save view…") and `viewer bench` all render through it, so the choice between the map
//! and the cube renderer is made in one place.

use lut_core::cube::CubeMap;
use lut_core::{CubeRenderer, EnvMap, RenderOptions, RenderReport, Renderer, View, ViewError};

/// A panorama ready to render, owning its data (and, for a map, its tables).
pub enum Scene {
    /// A map on a surface of revolution, with its LUT renderer.
    Map {
        /// The map.
        map: EnvMap,
        /// Its renderer (tables built on first use).
        renderer: Renderer,
    },
    /// A cube map.
    Cube(CubeMap),
}

impl Scene {
    /// A map with a new renderer.
    pub fn map(map: EnvMap) -> Scene {
        let renderer = Renderer::new(&map);
        Scene::Map { map, renderer }
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

/// How to render a scene: the map options (of which a cube map uses the sampler and the
/// threads) and the cube renderer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneOptions {
    /// Options of the map renderer; a cube map reads `sampler` and `threads`.
    pub render: RenderOptions,
    /// The cube renderer.
    pub cube: CubeRenderer,
}

impl SceneOptions {
    /// `render` for maps, the default (scanline) renderer for cubes.
    pub fn new(render: RenderOptions) -> SceneOptions {
        SceneOptions {
            render,
            cube: CubeRenderer::default(),
        }
    }
}

/// What rendered a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SceneReport {
    /// The map renderer's report.
    Map(RenderReport),
    /// A cube map, by this renderer.
    Cube(CubeRenderer),
}

/// Render `view` of `scene` into `out` (`width × height` 0RGB pixels).
///
/// # Errors
/// As `Renderer::render` and `lut_core::cube::render`: a bad size or buffer, a bad option.
pub fn render_scene(
    scene: SceneRef<'_>,
    view: View,
    opts: &SceneOptions,
    out: &mut [u32],
    width: u32,
    height: u32,
) -> Result<SceneReport, ViewError> {
    match scene {
        SceneRef::Map { map, renderer } => renderer
            .render(map, view, &opts.render, out, width, height)
            .map(SceneReport::Map),
        SceneRef::Cube(cube) => lut_core::cube::render(
            cube,
            view,
            opts.render.sampler,
            opts.cube,
            out,
            width,
            height,
            opts.render.threads,
        )
        .map(|()| SceneReport::Cube(opts.cube)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lut_core::{Projection, RenderPath, Sampler};

    /// The map path is `Renderer::render`, the cube path `cube::render`, with the options
    /// given: same pixels as calling them directly.
    #[test]
    fn renders_maps_and_cubes_as_their_renderers_do() {
        let map = lut_core::synth::grid_map(128, 64, Projection::Equirect).unwrap();
        let view = View::new(30.0, 10.0, 90.0).unwrap();
        let (w, h) = (40, 24);
        let opts = SceneOptions::new(RenderOptions {
            sampler: Sampler::Nearest,
            ..RenderOptions::default()
        });
        let mut want = vec![0u32; (w * h) as usize];
        let direct = Renderer::new(&map)
            .render(&map, view, &opts.render, &mut want, w, h)
            .unwrap();
        let cube = CubeMap::from_envmap(&map, 16, Sampler::Bilinear).unwrap();
        let mut scene = Scene::map(map);
        let mut got = vec![1u32; want.len()];
        let report = render_scene(scene.as_mut(), view, &opts, &mut got, w, h).unwrap();
        assert_eq!(report, SceneReport::Map(direct));
        assert_eq!(direct.path, RenderPath::LutWide);
        assert_eq!(got, want);

        for kind in [CubeRenderer::Basic, CubeRenderer::Accelerated] {
            let opts = SceneOptions { cube: kind, ..opts };
            lut_core::cube::render(&cube, view, Sampler::Nearest, kind, &mut want, w, h, true)
                .unwrap();
            let mut scene = Scene::Cube(cube.clone());
            let report = render_scene(scene.as_mut(), view, &opts, &mut got, w, h).unwrap();
            assert_eq!(report, SceneReport::Cube(kind));
            assert_eq!(got, want);
            assert!(scene.env_map().is_none());
        }
        // A bad size is an error, not a panic.
        let mut scene = Scene::Cube(cube);
        assert!(render_scene(scene.as_mut(), view, &opts, &mut got, 0, h).is_err());
    }
}

//! Cube-map inputs for the viewer: loading from the command line or a dropped folder, and
//! rendering a view (the entry points `render --projection cube` and the window use).

use anyhow::Result;
use lut_core::{CubeMap, CubeRenderer, Layout, Naming};
use lut_core::{Frame, RenderOptions, Renderer, Scene};
use lut_core::{Sampler, View};
use std::path::PathBuf;

/// Load a cube map from `inputs` (a folder, six face files, or one layout image).
///
/// `layout`: `files`, `cross`, `strip`, `3x2` or `None` to detect it (a folder or six
/// files are `files`; one image is recognized by its aspect ratio). `naming`:
/// `conventions`, `cube2`, `irrlicht` or `None` for the default the file names imply (see
/// `docs/cube.md`).
///
/// # Errors
/// Unknown layout or naming names, and every [`lut_core::CubeError`], with the file named.
pub fn load_cube(
    inputs: &[PathBuf],
    layout: Option<&str>,
    naming: Option<&str>,
) -> Result<CubeMap> {
    let layout = layout
        .map(|s| s.parse::<Layout>().map_err(anyhow::Error::msg))
        .transpose()?;
    let naming = naming
        .map(|s| s.parse::<Naming>().map_err(anyhow::Error::msg))
        .transpose()?;
    Ok(lut_core::load_cube(inputs, layout, naming)?)
}

/// True when `inputs` look like a cube map rather than one panorama image: a folder, six
/// or more files, or one image whose aspect ratio is a cube layout (4:3, 6:1, 3:2). For
/// the window's drop handler and `render`'s auto projection.
pub fn looks_like_cube(inputs: &[PathBuf]) -> bool {
    match inputs {
        [one] if one.is_dir() => true,
        [one] => image::ImageReader::open(one)
            .ok()
            .and_then(|r| r.with_guessed_format().ok())
            .and_then(|r| r.into_dimensions().ok())
            .map(|(w, h)| Layout::detect(w, h).is_some())
            .unwrap_or(false),
        many => many.len() >= 6,
    }
}

/// Render one view of `cube` into a new `width × height` 0RGB buffer (accelerated
/// renderer, rows across threads).
///
/// # Errors
/// A bad size.
#[allow(dead_code)] // the window's cube support
pub fn render_view(
    cube: &CubeMap,
    view: View,
    sampler: Sampler,
    width: u32,
    height: u32,
) -> Result<Vec<u32>> {
    let mut out = vec![0u32; width as usize * height as usize];
    Renderer::default().render(
        Scene::Cube(cube),
        view,
        &RenderOptions {
            sampler,
            cube: CubeRenderer::Accelerated,
            threads: true,
            ..RenderOptions::default()
        },
        &mut Frame::new(&mut out, width, height)?,
    )?;
    Ok(out)
}

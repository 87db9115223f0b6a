//! Opening panoramas: a map from a file or the bundled sample (with the pixel limit,
//! partial panoramas placed by `--coverage` or GPano XMP), a cube map from a folder, face
//! files or a layout image; and the texts the panel and `viewer render -v` show about a
//! partial map (coverage, compass heading).

use crate::args::CubeArgs;
use anyhow::{anyhow, Result};
use lut_core::{compass_heading, compass_point};
use lut_core::{Coverage, CoverageSource, CubeMap, EnvMap, Layout, LoadOptions, MapError};
use std::path::{Path, PathBuf};

/// The command-line hint for a library map error: which flag changes the outcome.
pub fn map_error_hint(e: &MapError) -> Option<&'static str> {
    match e {
        MapError::TooManyPixels { .. } => Some("raise the limit with --max-pixels"),
        MapError::UnknownProjection { .. } => {
            Some("give --projection cylinder|sine|elliptical|diamond")
        }
        _ => None,
    }
}

/// A library map error as one line, with its command-line hint (see [`map_error_hint`]).
pub fn map_error(e: MapError) -> anyhow::Error {
    match map_error_hint(&e) {
        Some(hint) => anyhow!("{e}; {hint}"),
        None => anyhow::Error::new(e),
    }
}

/// Load the panorama at `path` (the bundled sample when `None`) with `opts`: projection,
/// tone and the pixel limit (`--max-pixels`, checked from the header before decoding).
/// The file is streamed into the map, never held whole by this function. GPano XMP is
/// not read (see [`load_panorama_partial`]).
pub fn load_panorama(path: Option<&Path>, opts: &LoadOptions) -> Result<EnvMap> {
    Ok(match path {
        Some(p) => lut_core::load_map(p, opts, &mut |_| {}).map_err(map_error)?,
        None => lut_core::decode_map(
            crate::assets::SAMPLE_JPEG,
            crate::assets::SAMPLE_NAME,
            opts,
            &mut |_| {},
        )
        .map_err(map_error)?,
    })
}

/// Turn a placement error into one line that says how to override bad metadata (or, for
/// an image that cannot be read, the hint of [`map_error`]).
pub fn coverage_error(e: lut_core::CoverageError, coverage: Option<Coverage>) -> anyhow::Error {
    if let lut_core::CoverageError::Map(m) = e {
        return map_error(m);
    }
    let hint = match (&e, coverage) {
        (lut_core::CoverageError::Syntax { .. }, _) | (_, Some(_)) => "",
        // Bad metadata or a placement that does not fit, and no coverage given.
        (_, None) => {
            " (give --coverage HFOVxVFOV±YAW±PITCH to place the image yourself, e.g. \
             --coverage 360x180 to show it as a full panorama)"
        }
    };
    anyhow::anyhow!("{e}{hint}")
}

/// Load a panorama (`None`: the bundled sample) with the pixel limit, projection and tone
/// of `opts`, placed by `coverage` when given, else by the GPano XMP in the file (JPEG),
/// else as a full panorama; `progress` as in `lut_core::load_map`. Bad metadata is an
/// error that says how to override it.
pub fn load_panorama_partial(
    path: Option<&Path>,
    opts: &LoadOptions,
    coverage: Option<Coverage>,
    progress: &mut dyn FnMut(lut_core::LoadProgress),
) -> Result<(EnvMap, CoverageSource)> {
    match path {
        Some(p) => lut_core::load_partial(p, opts, coverage, progress),
        None => lut_core::decode_partial(
            crate::assets::SAMPLE_JPEG,
            crate::assets::SAMPLE_NAME,
            opts,
            coverage,
            progress,
        ),
    }
    .map_err(|e| coverage_error(e, coverage))
}

/// "covers 120°×60° around yaw 30°, pitch −10° (stored 2000×1000 of 6000×3000)" for a
/// partial map, `None` for a full one.
pub fn coverage_text(map: &EnvMap) -> Option<String> {
    let crop = map.crop()?;
    let c = crop.coverage();
    Some(format!(
        "covers {:.1}°×{:.1}° around yaw {:.1}°, pitch {:.1}° (stored {}×{} of {}×{})",
        c.hfov(),
        c.vfov(),
        c.yaw(),
        c.pitch(),
        crop.width(),
        crop.height(),
        crop.full_width(),
        crop.full_height()
    ))
}

/// "heading 213° (SW)" for the view centre, when the map knows its heading.
pub fn heading_text(map: &EnvMap, yaw: f64) -> Option<String> {
    let h = compass_heading(map.pose_heading_deg()?, yaw);
    Some(format!("heading {h:.0}° ({})", compass_point(h)))
}

/// Load a cube map from `inputs` (a folder, six face files, or one layout image) with
/// `--layout` (detected when omitted: a folder or six files are `files`, one image is
/// recognized by its aspect ratio) and `--naming` (omitted: what the file names imply, see
/// `docs/cube.md`).
///
/// # Errors
/// Every [`lut_core::CubeError`], with the file named.
pub fn load_cube(inputs: &[PathBuf], cube: CubeArgs) -> Result<CubeMap> {
    Ok(lut_core::load_cube(inputs, cube.layout, cube.naming)?)
}

/// True when `path` is a tiled pyramid: a folder holding `config.json`, or a `.json`
/// file (Pannellum's multires configuration; anything else in it is refused when opened),
/// or a Marzipano scene's folder ([`marzipano_data_js`]).
pub fn is_tiled(path: &Path) -> bool {
    if path.is_dir() {
        path.join("config.json").exists()
            || marzipano_data_js(path).is_some()
            || pannellum_inline(path).is_some()
    } else {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    }
}

/// Files of a folder looked at when one describing a tile folder is searched for.
const MAX_FILES_LOOKED_AT: usize = 256;

/// The regular files of `dir` (at most [`MAX_FILES_LOOKED_AT`]), sorted by name.
fn files_in(dir: &Path) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = rd
        .filter_map(Result::ok)
        .take(MAX_FILES_LOOKED_AT)
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// The tour file of the Marzipano tool export whose scene folder `path` is: a folder
/// (without `config.json`) named `tiles/<id>`, the export's `data.js` beside `tiles/`,
/// or, renamed, the file beside `tiles/` that assigns `APP_DATA` (by content, whatever
/// its name) and lists scene `<id>`.
pub fn marzipano_data_js(path: &Path) -> Option<PathBuf> {
    if !path.is_dir() || path.join("config.json").exists() {
        return None;
    }
    let tiles = path.parent()?;
    if tiles.file_name()? != "tiles" {
        return None;
    }
    let export = tiles.parent()?;
    let js = export.join("data.js");
    if js.is_file() {
        return Some(js);
    }
    let id = path.file_name()?.to_string_lossy().into_owned();
    files_in(export).into_iter().find(|f| {
        crate::tour::sniff(f) == Some(crate::tour::Format::Marzipano)
            && crate::tour::load(f).is_ok_and(|l| {
                l.tour
                    .scene(&id)
                    .is_some_and(|s| matches!(s.source, crate::tour::Source::MarzipanoTiles { .. }))
            })
    })
}

/// The Pannellum config (a tour or a single-scene config) with a multires scene whose
/// tiles are in `dir` and whose `multiRes` numbers are inline (no `config.json` in
/// `dir`): the nearest found in `dir` or a folder above it (a scene's `basePath` never
/// leaves its config's folder), its `.json` files in name order; with the scene's id.
pub fn pannellum_inline(dir: &Path) -> Option<(PathBuf, String)> {
    if !dir.is_dir() || dir.join("config.json").exists() {
        return None;
    }
    let want = std::fs::canonicalize(dir).ok()?;
    for folder in want.ancestors().take(8) {
        for f in files_in(folder) {
            let json = f
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("json"));
            if !json || crate::tour::sniff(&f) != Some(crate::tour::Format::Pannellum) {
                continue;
            }
            let Ok(loaded) = crate::tour::load(&f) else {
                continue;
            };
            let t = &loaded.tour;
            let found = t.scenes.iter().find(|s| match &s.source {
                crate::tour::Source::Multires(m) => t
                    .multires_base(&s.id, m)
                    .ok()
                    .and_then(|d| std::fs::canonicalize(d).ok())
                    .is_some_and(|d| d == want),
                _ => false,
            });
            if let Some(s) = found {
                return Some((f.clone(), s.id.clone()));
            }
        }
    }
    None
}

/// The pyramid of multires scene `id` of the Pannellum config `file`, from its inline
/// `multiRes` numbers.
///
/// # Errors
/// The config does not read, has no such multires scene, or its numbers are refused.
pub fn inline_config(file: &Path, id: &str) -> Result<lut_core::MultiresConfig> {
    let loaded = crate::tour::load(file)?;
    let scene = loaded.tour.scene(id).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: no scene \"{}\" opens in it",
            file.display(),
            lut_core::one_line(id)
        )
    })?;
    let crate::tour::Source::Multires(m) = &scene.source else {
        anyhow::bail!("{}: scene \"{id}\" is not multires", file.display());
    };
    loaded
        .tour
        .multires_config(file, m)
        .map_err(anyhow::Error::msg)
}

/// The pyramid of the Marzipano scene whose tile folder is `dir` (`tiles/<id>`): its
/// levels as the `data.js` beside `tiles/` lists them for scene `<id>`.
///
/// # Errors
/// The `data.js` does not read as a tour, does not list the scene (or lists it without
/// levels), or the levels are refused ([`lut_core::MultiresConfig::marzipano`]).
pub fn marzipano_config(js: &Path, dir: &Path) -> Result<lut_core::MultiresConfig> {
    let id = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let loaded = crate::tour::load(js)?;
    let scene = loaded.tour.scene(&id).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: no scene \"{}\" (the tile folder {}) opens in it",
            js.display(),
            lut_core::one_line(&id),
            dir.display()
        )
    })?;
    let crate::tour::Source::MarzipanoTiles { levels, .. } = &scene.source else {
        anyhow::bail!("{}: scene \"{id}\" is not Marzipano tiles", js.display());
    };
    Ok(lut_core::MultiresConfig::marzipano(js, dir, levels)?)
}

/// Open the tiled pyramid at `path` (a Pannellum multires folder or configuration, or a
/// Marzipano scene's tile folder) with a cache of `cache_mib` MiB and a decoding thread
/// per core (at most 8).
pub fn open_tiled(path: &Path, cache_mib: u64) -> Result<lut_core::TiledPanorama> {
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(2)
        .clamp(1, 8);
    let budget = (cache_mib as usize).saturating_mul(1 << 20);
    if let Some(js) = marzipano_data_js(path) {
        let cfg = marzipano_config(&js, path)?;
        return Ok(lut_core::TiledPanorama::with_config(cfg, budget, threads));
    }
    if let Some((file, id)) = pannellum_inline(path) {
        let cfg = inline_config(&file, &id)?;
        return Ok(lut_core::TiledPanorama::with_config(cfg, budget, threads));
    }
    Ok(lut_core::TiledPanorama::open(path, budget, threads)?)
}

/// True when `inputs` look like a cube map rather than one panorama image: a folder, six
/// or more files, or one image whose aspect ratio is a cube layout (4:3, 6:1, 3:2). For
/// the window's drop handler.
pub fn looks_like_cube(inputs: &[PathBuf]) -> bool {
    match inputs {
        [one] if one.is_dir() => true,
        // Only a regular file is looked into: opening a FIFO would block the window.
        [one] => lut_core::open_regular(one)
            .ok()
            .map(|f| image::ImageReader::new(std::io::BufReader::new(f)))
            .and_then(|r| r.with_guessed_format().ok())
            .and_then(|r| r.into_dimensions().ok())
            .map(|(w, h)| Layout::detect(w, h).is_some())
            .unwrap_or(false),
        many => many.len() >= 6,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_layouts_are_recognized_by_aspect_ratio() {
        let tmp = tempfile::tempdir().unwrap();
        let img = |name: &str, w: u32, h: u32| {
            let p = tmp.path().join(name);
            image::RgbImage::new(w, h).save(&p).unwrap();
            p
        };
        assert!(looks_like_cube(&[img("cross.png", 64, 48)]));
        assert!(looks_like_cube(&[img("strip.png", 96, 16)]));
        assert!(looks_like_cube(&[img("grid.png", 48, 32)]));
        assert!(!looks_like_cube(&[img("pano.png", 64, 32)]));
        assert!(looks_like_cube(&[tmp.path().to_path_buf()]));
        assert!(!looks_like_cube(&[tmp.path().join("missing.png")]));
        #[cfg(unix)]
        {
            // A FIFO named like an image: answered at once (not a cube), never opened
            // for reading, which would block until a writer came.
            let fifo = tmp.path().join("pipe.png");
            assert!(std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .unwrap()
                .success());
            assert!(!looks_like_cube(&[fifo]));
        }
        let six: Vec<PathBuf> = (0..6).map(|i| PathBuf::from(format!("{i}.png"))).collect();
        assert!(looks_like_cube(&six));
        assert!(!looks_like_cube(&six[..2]));
    }

    #[test]
    fn the_bundled_sample_loads_and_is_full() {
        let map = load_panorama(None, &LoadOptions::default()).unwrap();
        assert_eq!(map.width(), 2 * map.height());
        assert!(coverage_text(&map).is_none());
        let (partial, _) =
            load_panorama_partial(None, &LoadOptions::default(), None, &mut |_| {}).unwrap();
        assert_eq!(
            (partial.width(), partial.height()),
            (map.width(), map.height())
        );
    }
}

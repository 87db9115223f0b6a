//! What the window opens ([`Source`]) and the loading thread's work ([`load`]): read,
//! decode, convert, build the tables and the pyramid, reporting each step. No window
//! types: the event loop runs [`load`] on a thread and forwards its reports.

use super::ui::LoadStep;
use lut_core::{Coverage, EnvMap, Layout, LoadOptions, Naming, Panorama, PanoramaKind, Projection};
use std::path::PathBuf;

/// Where a panorama comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// The bundled sample.
    Sample,
    /// One image file: a map.
    File(PathBuf),
    /// A cube map: a folder, face files or one layout image, with the layout if given.
    Cube {
        /// The folder or files.
        paths: Vec<PathBuf>,
        /// `--layout`, if given.
        layout: Option<Layout>,
    },
}

impl Source {
    /// The name in the load status and `--print-view`'s "loaded" line.
    pub fn name(&self) -> String {
        match self {
            Source::Sample => crate::assets::SAMPLE_NAME.to_string(),
            Source::File(p) => p.display().to_string(),
            Source::Cube { paths, .. } => match paths.as_slice() {
                [one] => one.display().to_string(),
                many => format!(
                    "{} cube faces in {}",
                    many.len(),
                    many.first()
                        .and_then(|p| p.parent())
                        .map_or_else(|| ".".into(), |d| d.display().to_string())
                ),
            },
        }
    }

    /// The files or folder this source was opened from: one image file, a cube's folder,
    /// layout image or face files; none for the bundled sample.
    pub fn paths(&self) -> Vec<PathBuf> {
        match self {
            Source::Sample => Vec::new(),
            Source::File(p) => vec![p.clone()],
            Source::Cube { paths, .. } => paths.clone(),
        }
    }

    /// The one file or folder this source is (`None`: the sample, or several face files).
    pub fn single_path(&self) -> Option<&std::path::Path> {
        match self {
            Source::File(p) => Some(p),
            Source::Cube { paths, .. } if paths.len() == 1 => Some(&paths[0]),
            _ => None,
        }
    }

    /// The short name in the title and the map readout.
    pub fn short_name(&self) -> String {
        let file_name = |p: &PathBuf| {
            p.file_name().map_or_else(
                || p.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            )
        };
        match self {
            Source::Sample => "courtyard (bundled sample)".into(),
            Source::File(p) => file_name(p),
            Source::Cube { paths, .. } => match paths.as_slice() {
                [one] => file_name(one),
                many => format!("{} cube faces", many.len()),
            },
        }
    }

    /// The source that opens what `paths` were dropped or given as: a folder or several
    /// files are a cube map; one image is a cube map when its aspect ratio is a cube
    /// layout's (4:3, 6:1, 3:2) or `cube` is set or a layout is forced.
    pub fn of_paths(paths: Vec<PathBuf>, cube: bool, layout: Option<Layout>) -> Option<Source> {
        let cube = cube || layout.is_some() || crate::panorama::looks_like_cube(&paths);
        match paths.as_slice() {
            [] => None,
            [one] if !cube => Some(Source::File(one.clone())),
            _ => Some(Source::Cube { paths, layout }),
        }
    }

    /// The source to reopen with a projection chosen in the panel: a cube map's single
    /// layout image opens as a map.
    pub fn as_map(self) -> Source {
        match self {
            Source::Cube { paths, .. } if paths.len() == 1 && !paths[0].is_dir() => {
                Source::File(paths[0].clone())
            }
            other => other,
        }
    }
}

/// A loaded panorama with its renderer (tables built on the loading thread).
pub struct Loaded {
    /// The map or cube map.
    pub scene: Panorama,
    /// Where it came from.
    pub source: Source,
    /// The projection it was opened with (`None`: auto).
    pub projection: Option<Projection>,
    /// An HDR file (`.hdr`, `.exr`): shown through the panel's exposure.
    pub hdr: bool,
    /// The exposure it was decoded with (stops).
    pub exposure_ev: f64,
}

impl Loaded {
    /// Size and projection for `--print-view`: "W×H projection" (a cube: its face size).
    pub fn describe(&self) -> (u32, u32, &'static str) {
        let (w, h) = self.scene.size();
        let kind = match self.scene.as_map() {
            Some(map) => map.projection().name(),
            None => self.scene.kind().name(),
        };
        (w, h, kind)
    }

    /// The size as the title shows it: "W×H" for a map, "cube, Npx faces", "tiled
    /// pyramid, Npx faces".
    pub fn size_label(&self) -> String {
        let (w, h, _) = self.describe();
        match self.scene.kind() {
            PanoramaKind::Map => format!("{w}×{h}"),
            kind => format!("{}, {w}px faces", kind.noun()),
        }
    }

    /// The map readout: name, size, projection and memory.
    pub fn label(&self) -> String {
        let (w, h, proj) = self.describe();
        let name = self.source.short_name();
        match self.scene.kind() {
            PanoramaKind::Map => format!(
                "{name} ({w}×{h}, {proj}, {} in memory)",
                format_bytes(self.scene.bytes())
            ),
            _ => format!("{name} ({})", self.size_label()),
        }
    }

    /// The map, if the panorama is one.
    pub fn map(&self) -> Option<&EnvMap> {
        self.scene.as_map()
    }
}

/// A byte count for the readout: "2.00 GiB", "12.3 MiB".
pub fn format_bytes(b: usize) -> String {
    let b = b as f64;
    if b >= f64::from(1u32 << 30) {
        format!("{:.2} GiB", b / f64::from(1u32 << 30))
    } else {
        format!("{:.1} MiB", b / f64::from(1u32 << 20))
    }
}

/// One load for the loading thread.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadRequest {
    /// Which load (a later one supersedes it).
    pub id: u64,
    /// What to open.
    pub source: Source,
    /// Projection, tone, pixel limit.
    pub opts: LoadOptions,
    /// Cube face naming from the command line.
    pub naming: Option<Naming>,
    /// `--coverage`, when it applies to this source.
    pub coverage: Option<Coverage>,
    /// A tour scene's horizon to level (pitch, roll, degrees): cube maps and full
    /// equirectangular maps are re-levelled once here; other panoramas are shown as they
    /// are.
    pub horizon: Option<(f64, f64)>,
}

/// The loading thread's work: read, decode, convert, build tables, reporting each step
/// to `progress` (see `lut_core::load` for which decoders measure their progress).
///
/// # Errors
/// The file's error, one line, naming it.
pub fn load(
    req: LoadRequest,
    progress: &mut dyn FnMut(LoadStep, Option<f32>),
) -> Result<Box<Loaded>, String> {
    let LoadRequest {
        source,
        opts,
        naming,
        coverage,
        horizon,
        ..
    } = req;
    let hdr = matches!(&source, Source::File(p) if super::export::is_hdr_path(p));
    // A tiled pyramid (a folder with config.json, or the .json): level 1 decoded here,
    // the rest on its decoding threads as frames ask for it (frames never wait).
    if let Some(p) = source
        .single_path()
        .filter(|p| crate::panorama::is_tiled(p))
    {
        progress(LoadStep::Decoding, None);
        let pano = crate::panorama::open_tiled(p, super::prefs::TILE_CACHE_MIB)
            .map_err(|e| format!("{e:#}"))?;
        return Ok(Box::new(Loaded {
            scene: Panorama::tiled(pano, false),
            source,
            projection: opts.projection,
            hdr: false,
            exposure_ev: opts.tone.exposure_ev,
        }));
    }
    let path = match &source {
        Source::Cube { paths, layout } => {
            progress(LoadStep::Decoding, None);
            let cube = crate::args::CubeArgs {
                layout: *layout,
                naming,
            };
            let mut cube = crate::panorama::load_cube(paths, cube).map_err(|e| format!("{e:#}"))?;
            // A tour scene's horizon: the faces re-levelled once, as a map is.
            if let Some((p, r)) = horizon {
                cube = lut_core::level_cube_horizon(&cube, p, r).map_err(|e| format!("{e:#}"))?;
            }
            // The face pyramid (the window's default sampler is trilinear) now, so the
            // first frames do not wait for it.
            let mut scene = Panorama::cube(cube);
            let surface = lut_core::RenderOptions::default().surface;
            scene.prepare(surface, &mut |f| progress(LoadStep::Tables, Some(f)));
            return Ok(Box::new(Loaded {
                scene,
                source,
                projection: opts.projection,
                hdr: false,
                exposure_ev: opts.tone.exposure_ev,
            }));
        }
        Source::Sample => None,
        Source::File(p) => Some(p.as_path()),
    };
    // The same loading as `viewer render` (streamed from the file, the pixel limit
    // checked from the header first; partial panoramas placed by GPano XMP or the
    // command line's --coverage); 8-bit images ignore the tone.
    let mut on_progress = |p: lut_core::LoadProgress| progress(p.phase.into(), p.fraction);
    let (map, _) = crate::panorama::load_panorama_partial(path, &opts, coverage, &mut on_progress)
        .map_err(|e| format!("{e:#}"))?;
    // Build both tables and the pyramid (the window's default sampler is trilinear), and
    // the levels' own pyramids (zoomed-out still frames are drawn from a level,
    // `Renderer::set_still_level`), now, so the first frames do not wait for them.
    lut_core::fault_point("loader");
    let map = match horizon {
        Some((p, r)) => lut_core::level_horizon(&map, p, r).unwrap_or(map),
        None => map,
    };
    let mut scene = Panorama::map(map);
    let surface = lut_core::RenderOptions::default().surface;
    scene.prepare(surface, &mut |f| progress(LoadStep::Tables, Some(f)));
    Ok(Box::new(Loaded {
        scene,
        source,
        projection: opts.projection,
        hdr,
        exposure_ev: opts.tone.exposure_ev,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn png(dir: &Path, name: &str, w: u32, h: u32) -> PathBuf {
        let p = dir.join(name);
        image::RgbImage::from_fn(w, h, |x, y| image::Rgb([x as u8, y as u8, 9]))
            .save(&p)
            .unwrap();
        p
    }

    fn request(source: Source) -> LoadRequest {
        LoadRequest {
            id: 1,
            source,
            opts: LoadOptions::default(),
            naming: None,
            coverage: None,
            horizon: None,
        }
    }

    #[test]
    fn a_file_loads_with_its_tables_and_reports_every_step() {
        let tmp = tempfile::tempdir().unwrap();
        let p = png(tmp.path(), "pano.png", 64, 32);
        let mut steps = Vec::new();
        let loaded = load(request(Source::File(p.clone())), &mut |s, f| {
            steps.push((s, f))
        })
        .unwrap();
        assert_eq!(loaded.describe(), (64, 32, "equirect"));
        assert_eq!(
            loaded.label(),
            "pano.png (64×32, equirect, 0.0 MiB in memory)"
        );
        assert!(!loaded.hdr && loaded.projection.is_none());
        assert_eq!(steps.last(), Some(&(LoadStep::Tables, Some(1.0))));
        assert!(steps.iter().any(|s| s.0 == LoadStep::Decoding));
        let map = loaded.map().unwrap();
        assert!(map.pyramid_bytes() > 0, "pyramid built");
        // 64×32: levels 1 to 3 (down to 8×4) have pyramids of their own (level 4, 4×2,
        // has none: pyramids end at a side of 2).
        assert!(map.pyramid()[..3].iter().all(|l| l.pyramid_bytes() > 0));
        // A bad file: one line naming it.
        std::fs::write(tmp.path().join("bad.png"), b"not a png").unwrap();
        let e = load(
            request(Source::File(tmp.path().join("bad.png"))),
            &mut |_, _| {},
        )
        .err()
        .unwrap();
        assert!(e.contains("bad.png") && !e.contains('\n'), "{e}");
    }

    #[test]
    fn sources_of_dropped_paths() {
        let tmp = tempfile::tempdir().unwrap();
        let pano = png(tmp.path(), "pano.png", 64, 32);
        let cross = png(tmp.path(), "cross.png", 64, 48);
        assert_eq!(Source::of_paths(vec![], false, None), None);
        assert_eq!(
            Source::of_paths(vec![pano.clone()], false, None),
            Some(Source::File(pano.clone()))
        );
        let as_cube = Source::of_paths(vec![cross.clone()], false, None).unwrap();
        assert!(
            matches!(&as_cube, Source::Cube { paths, layout: None } if paths == std::slice::from_ref(&cross))
        );
        assert_eq!(as_cube.clone().as_map(), Source::File(cross.clone()));
        let forced = Source::of_paths(vec![pano.clone()], false, Some(Layout::Strip)).unwrap();
        assert!(matches!(
            forced,
            Source::Cube {
                layout: Some(Layout::Strip),
                ..
            }
        ));
        let folder = Source::of_paths(vec![tmp.path().to_path_buf()], false, None).unwrap();
        assert_eq!(folder.clone().as_map(), folder, "a folder stays a cube");
        let six: Vec<PathBuf> = (0..6)
            .map(|i| tmp.path().join(format!("{i}.jpg")))
            .collect();
        let faces = Source::of_paths(six, false, None).unwrap();
        assert_eq!(faces.short_name(), "6 cube faces");
        assert!(faces.name().starts_with("6 cube faces in "));
        assert_eq!(Source::Sample.short_name(), "courtyard (bundled sample)");
        assert_eq!(format_bytes(3 << 29), "1.50 GiB");
        assert_eq!(format_bytes(5 << 20), "5.0 MiB");
    }

    #[test]
    fn a_cube_folder_loads_as_a_cube() {
        let dir = test_support::test_data("cube/skyfantasy");
        let mut steps = Vec::new();
        let loaded = load(
            request(Source::Cube {
                paths: vec![dir],
                layout: None,
            }),
            &mut |s, f| steps.push((s, f)),
        )
        .unwrap();
        let (n, _, kind) = loaded.describe();
        assert_eq!(kind, "cube");
        assert_eq!(loaded.label(), format!("skyfantasy (cube, {n}px faces)"));
        assert!(loaded.map().is_none());
        // Decoding, then the face pyramid (the default sampler is trilinear), built.
        assert_eq!(
            steps,
            [
                (LoadStep::Decoding, None),
                (LoadStep::Tables, Some(0.0)),
                (LoadStep::Tables, Some(1.0))
            ]
        );
        let Some(cube) = loaded.scene.as_cube() else {
            panic!("a cube folder loads as a cube");
        };
        assert!(
            cube.pyramid_bytes() > 0,
            "the face pyramid is built while loading"
        );
    }
}

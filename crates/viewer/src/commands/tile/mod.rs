//! `viewer tile INPUT -o DIR`: a Pannellum `multires` pyramid (tiled cube faces at every
//! level, fallback faces, `config.json`) exactly as Pannellum's `generate.py` writes it,
//! from an equirectangular JPEG, PNG or TIFF read in row bands (memory bounded whatever
//! its size), from a cube map, from any panorama the viewer opens, or from a generated
//! pattern (`--synthetic WxH`). See docs/huge.md ("Gigapixel panoramas: tiled pyramids").
//!
//! Modules: [`layout`] (generate.py's sizes, names and config), [`bands`] (row-band
//! readers), [`source`] (the faces' pixels: exact inverse mapping, the block store),
//! [`resample`] (the streaming level and fallback resampler), [`write`] (the pyramid
//! writer, [`write_pyramid`]), `jpeg` (tile encoding).

pub mod bands;
mod jpeg;
pub mod layout;
pub mod resample;
pub mod source;
mod synth;
pub mod write;

pub use layout::{Layout, FACES};
pub use source::{CubeSource, FaceSource, MapSource, Rect, StoreSource, Synthetic};
pub use write::{encode, prepare_dir, write_pyramid, Progress, Report, Stage, TileOptions};

use crate::args::{CubeArgs, MaxPixelsArg, ProjectionArg, ProjectionOpt};
use crate::usage;
use anyhow::Result;
use clap::Args;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Arguments of `viewer tile`.
#[derive(Args, Debug)]
pub struct TileArgs {
    /// The panorama: an equirectangular JPEG, PNG or TIFF (read in bands), a cube map (a
    /// folder, six face files or one layout image) or any panorama the viewer opens.
    /// Omit with --synthetic.
    #[arg(value_name = "INPUT")]
    pub inputs: Vec<PathBuf>,
    /// The output folder (created; an empty folder or an earlier pyramid only).
    #[arg(short = 'o', long = "output", value_name = "DIR")]
    pub output: PathBuf,
    /// Tile side in pixels (Pannellum's tileResolution; at most the cube face).
    #[arg(long, default_value_t = layout::DEFAULT_TILE_SIZE, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub tile_size: u32,
    /// JPEG quality, 1 to 100 (generate.py's default).
    #[arg(long, default_value_t = layout::DEFAULT_QUALITY, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub quality: u8,
    /// PNG tiles instead of JPEG (generate.py --png).
    #[arg(long)]
    pub png: bool,
    /// Fallback face side in pixels (for viewers without WebGL); 0 writes none.
    #[arg(long, default_value_t = layout::DEFAULT_FALLBACK_SIZE, value_parser = clap::value_parser!(u32).range(0..=16384))]
    pub fallback_size: u32,
    /// Cube face side in pixels; default generate.py's 8 * int(width / pi / 8) (a cube
    /// map's own face size).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(layout::MAX_CUBE_SIZE)))]
    pub cube_size: Option<u32>,
    /// The starting horizontal field of view written to config.json (generate.py --hfov).
    #[arg(long, default_value_t = layout::DEFAULT_HFOV, value_parser = parse_hfov)]
    pub hfov: f64,
    /// Instead of an input, a generated latitude/longitude grid on a colour field standing
    /// for a WxH equirect (any size: nothing of that size is held or written but tiles).
    #[arg(long, value_name = "WxH", value_parser = parse_synthetic, conflicts_with = "inputs")]
    pub synthetic: Option<(u64, u64)>,
    /// No progress bar (it is shown only when standard error is a terminal).
    #[arg(short, long)]
    pub quiet: bool,
    /// `--projection` of the input (auto: 2:1 images are equirectangular, folders and
    /// several files cube maps).
    #[command(flatten)]
    pub projection: ProjectionOpt,
    /// A cube map's `--layout` and `--naming`.
    #[command(flatten)]
    pub cube: CubeArgs,
    /// The pixel limit for the input.
    #[command(flatten)]
    pub limit: MaxPixelsArg,
}

fn parse_hfov(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v < 360.0 => Ok(v),
        _ => Err(format!(
            "hfov '{s}' must be a number of degrees in (0, 360)"
        )),
    }
}

/// `WxH` of a synthetic panorama: whole numbers, W at least 26 (a face of 8 pixels),
/// W at most 1.6 million.
fn parse_synthetic(s: &str) -> Result<(u64, u64), String> {
    let bad = || format!("synthetic size '{s}' must look like WIDTHxHEIGHT, e.g. 16384x8192");
    let (a, b) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u64 = a.trim().parse().map_err(|_| bad())?;
    let h: u64 = b.trim().parse().map_err(|_| bad())?;
    let cube = layout::cube_size_for(w, 360.0);
    if h == 0 || cube == 0 || cube > u64::from(layout::MAX_CUBE_SIZE) {
        return Err(format!(
            "synthetic size '{s}': the width must give a cube face of 8 to {} pixels (26 to about 1.6 million)",
            layout::MAX_CUBE_SIZE
        ));
    }
    Ok((w, h))
}

/// A progress bar on standard error: percent, count, elapsed and ETA, at most ten
/// redraws a second; nothing when quiet or standard error is not a terminal.
struct Bar {
    on: bool,
    start: Instant,
    last: Option<Instant>,
    stage: Option<Stage>,
}

impl Bar {
    fn new(quiet: bool) -> Bar {
        Bar {
            on: !quiet && std::io::stderr().is_terminal(),
            start: Instant::now(),
            last: None,
            stage: None,
        }
    }

    fn show(&mut self, p: Progress) {
        if !self.on {
            return;
        }
        if self.stage != Some(p.stage) {
            if self.stage.is_some() {
                crate::errln!("");
            }
            self.stage = Some(p.stage);
            self.start = Instant::now();
            self.last = None;
        }
        let now = Instant::now();
        let end = p.done >= p.total;
        if !end
            && self
                .last
                .is_some_and(|l| now.duration_since(l).as_millis() < 100)
        {
            return;
        }
        self.last = Some(now);
        let f = if p.total == 0 {
            1.0
        } else {
            p.done as f64 / p.total as f64
        };
        let el = now.duration_since(self.start).as_secs_f64();
        let eta = if f > 0.0 && !end {
            format!(", ETA {:.0} s", el * (1.0 - f) / f)
        } else {
            String::new()
        };
        let what = match p.stage {
            Stage::Reading => "reading rows",
            Stage::Tiles => "tiles",
        };
        let w = 30;
        let fill = ((f * w as f64) as usize).min(w);
        let mut e = std::io::stderr().lock();
        use std::io::Write;
        let _ = write!(
            e,
            "\r[{}{}] {:5.1}% {what} {}/{} {:.0} s{eta}   ",
            "#".repeat(fill),
            " ".repeat(w - fill),
            100.0 * f,
            p.done,
            p.total,
            el
        );
        let _ = e.flush();
    }

    fn finish(&mut self) {
        if self.on && self.stage.is_some() {
            crate::errln!("");
        }
    }
}

/// The source for `a`'s input (pass 1 for a streamed file happens here).
fn open_source(a: &TileArgs, bar: &mut Bar) -> Result<Box<dyn FaceSource>> {
    if let Some((w, _)) = a.synthetic {
        return Ok(Box::new(Synthetic { width: w }));
    }
    if a.inputs.is_empty() {
        return Err(usage!("tile needs an INPUT panorama (or --synthetic WxH)"));
    }
    // A tiled pyramid (a Pannellum multires folder or config, a Marzipano scene's tile
    // folder): its finest level, texel for texel, re-tiled.
    if let [input] = a.inputs.as_slice() {
        if crate::panorama::is_tiled(input) {
            let mut t = crate::panorama::open_tiled(input, 256)?;
            let cube = t.full_cube()?;
            return Ok(Box::new(CubeSource(cube)));
        }
    }
    if a.projection.value.reads_cube(&a.inputs) {
        let cube = crate::panorama::load_cube(&a.inputs, a.cube)?;
        return Ok(Box::new(CubeSource(cube)));
    }
    let [input] = a.inputs.as_slice() else {
        return Err(usage!(
            "tile takes one panorama file, or a cube map (a folder, six faces); got {} inputs",
            a.inputs.len()
        ));
    };
    let projection = a.projection.value.map_only("tile")?;
    let equirect = matches!(
        a.projection.value,
        ProjectionArg::Auto | ProjectionArg::Map(lut_core::Projection::Equirect)
    );
    if equirect && !is_partial(input) {
        if let Some(format) = bands::sniff(input)? {
            if let Some(mut rows) = bands::open(input, format, a.limit.max_pixels)? {
                let (w, h) = (rows.width(), rows.height());
                if u64::from(w) == 2 * u64::from(h) {
                    let total = u64::from(h);
                    let store = StoreSource::build(rows.as_mut(), &a.output, &mut |done| {
                        bar.show(Progress {
                            stage: Stage::Reading,
                            done: u64::from(done),
                            total,
                        })
                    })?;
                    return Ok(Box::new(store));
                }
                if format == bands::BandFormat::Tiff {
                    anyhow::bail!(
                        "{}: the TIFF is {w}x{h}, not 2:1; tile reads a TIFF as a full equirectangular panorama only",
                        input.display()
                    );
                }
            }
        }
    }
    // Anything else the viewer opens: decoded whole (within --max-pixels), partial
    // panoramas placed by their GPano metadata.
    let opts = a.limit.options(projection, lut_core::Tone::default());
    let (map, _) = crate::panorama::load_panorama_partial(Some(input), &opts, None, &mut |_| {})?;
    Ok(Box::new(MapSource(map)))
}

/// A JPEG whose GPano metadata has crop fields (it may cover less than the sphere): read
/// whole and placed by the map loader, not streamed.
fn is_partial(path: &Path) -> bool {
    use std::io::Read;
    let Ok(f) = lut_core::open_regular(path) else {
        return false;
    };
    let mut head = Vec::new();
    if f.take(1 << 20).read_to_end(&mut head).is_err() {
        return false;
    }
    lut_core::read_gpano(&head)
        .ok()
        .flatten()
        .is_some_and(|g| g.has_crop())
}

/// Run `viewer tile`.
pub fn run(a: TileArgs) -> Result<()> {
    if a.synthetic.is_none() && a.inputs.is_empty() {
        return Err(usage!("tile needs an INPUT panorama (or --synthetic WxH)"));
    }
    // The folder is checked (and an earlier pyramid's config removed) before the input
    // is read: the block store lives in it.
    prepare_dir(&a.output)?;
    let mut bar = Bar::new(a.quiet);
    let opts = TileOptions {
        tile_size: a.tile_size,
        quality: a.quality,
        png: a.png,
        fallback_size: a.fallback_size,
        hfov: a.hfov,
        cube_size: a.cube_size,
    };
    let result = open_source(&a, &mut bar)
        .and_then(|source| write_pyramid(source.as_ref(), &a.output, &opts, &mut |p| bar.show(p)));
    bar.finish();
    let report = result?;
    let l = &report.layout;
    crate::outln!(
        "{}: {} tiles ({} left out as black), faces {} px, tiles {} px, {} levels",
        a.output.display(),
        report.tiles_written,
        report.tiles_missing,
        l.cube_size,
        l.tile_size,
        l.max_level
    )
}

//! Writing the pyramid: the output folder's checks, the faces band by band (the top
//! level's tiles rendered from the source in parallel, each level below streamed from the
//! one above, the fallback face from the top level), the tiles encoded in parallel, and
//! `config.json` last, atomically.

use super::layout::{
    config_text, cube_size_for, missing_tiles_string, tile_path, ConfigExtras, Layout, MissingTile,
    DEFAULT_FALLBACK_SIZE, DEFAULT_HFOV, DEFAULT_QUALITY, DEFAULT_TILE_SIZE, FACES,
};
use super::resample::Resampler;
use super::source::{FaceSource, Rect};
use anyhow::{anyhow, bail, Context, Result};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// How to write a pyramid.
#[derive(Debug, Clone, PartialEq)]
pub struct TileOptions {
    /// Tile side (generate.py `--tilesize`, 512); the pyramid's is `min(this, cube)`.
    pub tile_size: u32,
    /// JPEG quality 1..=100 (generate.py's default 75).
    pub quality: u8,
    /// PNG tiles instead of JPEG (generate.py `--png`).
    pub png: bool,
    /// Fallback face side (generate.py `--fallbacksize`, 1024; 0: none).
    pub fallback_size: u32,
    /// The starting hfov written to the config (generate.py `--hfov`, 100).
    pub hfov: f64,
    /// The cube face side; `None`: generate.py's `8 * int(width / pi / 8)` of the
    /// source's width (or a cube source's own face size).
    pub cube_size: Option<u32>,
}

impl Default for TileOptions {
    fn default() -> Self {
        TileOptions {
            tile_size: DEFAULT_TILE_SIZE,
            quality: DEFAULT_QUALITY,
            png: false,
            fallback_size: DEFAULT_FALLBACK_SIZE,
            hfov: DEFAULT_HFOV,
            cube_size: None,
        }
    }
}

/// Where a run is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Pass 1: input rows streamed into the block store.
    Reading,
    /// Pass 2: tiles written (of all levels and faces).
    Tiles,
}

/// A progress report: `done` of `total` in `stage`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Progress {
    /// The stage.
    pub stage: Stage,
    /// Units done (rows, tiles).
    pub done: u64,
    /// Units in all.
    pub total: u64,
}

/// What was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Report {
    /// The pyramid's geometry.
    pub layout: Layout,
    /// Tile files written (not counting fallback faces).
    pub tiles_written: u64,
    /// Tiles left out as uniform black (listed in `missingTiles`, as generate.py does).
    pub tiles_missing: u64,
    /// Face pixels rendered from the source (the top level, 6 · cube²).
    pub face_pixels: u64,
}

/// A name in a pyramid folder: `config.json`, `fallback/` or a level folder.
fn is_tile_name(name: &str, fallback: bool) -> bool {
    let Some((stem, ext)) = name.rsplit_once('.') else {
        return false;
    };
    if !matches!(ext, "jpg" | "png") {
        return false;
    }
    let mut c = stem.chars();
    let Some(letter) = c.next() else { return false };
    if !"fbudlr".contains(letter) {
        return false;
    }
    let rest: String = c.collect();
    if fallback {
        return rest.is_empty();
    }
    rest.split_once('_').is_some_and(|(a, b)| {
        !a.is_empty()
            && !b.is_empty()
            && a.bytes().all(|d| d.is_ascii_digit())
            && b.bytes().all(|d| d.is_ascii_digit())
    })
}

/// Make `dir` ready for a pyramid: created if missing; an empty folder is used as it
/// is; a folder holding a pyramid (a finished one, or what an interrupted run left:
/// `config.json`, `fallback/` and level folders holding only tiles) is emptied,
/// `config.json` first, so it never looks complete while it is rewritten. Anything else
/// in it is refused, before anything is removed.
///
/// # Errors
/// `dir` is a file, holds other files, or cannot be created or emptied.
pub fn prepare_dir(dir: &Path) -> Result<()> {
    let name = dir.display();
    match std::fs::symlink_metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return std::fs::create_dir_all(dir)
                .with_context(|| format!("{name}: cannot create the output folder"));
        }
        Err(e) => return Err(anyhow!("{name}: {e}")),
        Ok(m) if !m.is_dir() => bail!("{name}: the output must be a folder; this is a file"),
        Ok(_) => {}
    }
    let other = |what: &str| {
        anyhow!("{name}: the output folder holds {what}, which is not part of a pyramid; viewer tile writes into an empty folder or over a pyramid only")
    };
    let mut levels = Vec::new();
    for e in std::fs::read_dir(dir).with_context(|| format!("{name}: cannot read the folder"))? {
        let e = e.with_context(|| format!("{name}: cannot read the folder"))?;
        let n = e.file_name().to_string_lossy().into_owned();
        let ft = e
            .file_type()
            .with_context(|| format!("{name}: cannot read the folder"))?;
        if n == "config.json" && ft.is_file() {
            continue;
        }
        let fallback = n == "fallback";
        let level = !n.is_empty() && n.len() <= 3 && n.bytes().all(|b| b.is_ascii_digit());
        if !(ft.is_dir() && (fallback || level)) {
            return Err(other(&format!("'{n}'")));
        }
        for t in std::fs::read_dir(e.path())
            .with_context(|| format!("{name}/{n}: cannot read the folder"))?
        {
            let t = t.with_context(|| format!("{name}/{n}: cannot read the folder"))?;
            let tn = t.file_name().to_string_lossy().into_owned();
            let is_file = t.file_type().is_ok_and(|f| f.is_file());
            if !is_file || !is_tile_name(&tn, fallback) {
                return Err(other(&format!("'{n}/{tn}'")));
            }
        }
        levels.push(e.path());
    }
    let config = dir.join("config.json");
    if config.exists() {
        std::fs::remove_file(&config)
            .with_context(|| format!("{}: cannot remove", config.display()))?;
    }
    for l in levels {
        std::fs::remove_dir_all(&l).with_context(|| format!("{}: cannot remove", l.display()))?;
    }
    Ok(())
}

/// The layout a source gets with `opts`.
///
/// # Errors
/// A face size of 0 or above the maximum, a tile size of 0.
pub fn layout_for(source: &dyn FaceSource, opts: &TileOptions) -> Result<Layout> {
    let cube = match (opts.cube_size, source.face_size(), source.width()) {
        (Some(c), _, _) => u64::from(c),
        (None, Some(n), _) => u64::from(n),
        (None, None, Some(w)) => cube_size_for(w, 360.0),
        (None, None, None) => bail!("the source has no size"),
    };
    Layout::new(cube, opts.tile_size).map_err(|e| anyhow!("{e}"))
}

struct Ctx<'a> {
    dir: &'a Path,
    opts: &'a TileOptions,
    layout: &'a Layout,
    ext: &'static str,
    missing: Mutex<Vec<MissingTile>>,
    written: std::sync::atomic::AtomicU64,
}

impl Ctx<'_> {
    /// Write tile `(face_index, level, row, col)` of `size` (w, h) RGB8 pixels, or list
    /// it as missing when every pixel is black (generate.py: a tile of the background
    /// colour alone is not written).
    fn tile(&self, id: (usize, u32, u32, u32), px: &[u8], size: (u32, u32)) -> Result<()> {
        let (fi, level, row, col) = id;
        let (w, h) = size;
        if px.iter().all(|&b| b == 0) {
            self.missing
                .lock()
                .map_err(|_| anyhow!("a tile thread failed"))?
                .push((fi, level, col, row));
            return Ok(());
        }
        let path = self
            .dir
            .join(tile_path(level, FACES[fi].0, row, col, self.ext));
        write_image_file(&path, px, w, h, self.opts)?;
        self.written
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Ok(())
    }

    /// Write every tile of a band of rows (`rows` rows of a level `size` wide).
    fn band(&self, fi: usize, level: u32, band_row: u32, band: &[u8], size: u32) -> Result<()> {
        let ts = self.layout.tile_size;
        let rows = (band.len() / (3 * size as usize)) as u32;
        (0..size.div_ceil(ts)).into_par_iter().try_for_each(|c| {
            let x0 = c * ts;
            let w = ts.min(size - x0);
            let mut px = Vec::with_capacity((3 * w * rows) as usize);
            for r in 0..rows as usize {
                let at = 3 * (r * size as usize + x0 as usize);
                px.extend_from_slice(&band[at..at + 3 * w as usize]);
            }
            self.tile((fi, level, band_row, c), &px, (w, rows))
        })
    }
}

/// Encode RGB8 pixels as the options say and write them to `path`.
fn write_image_file(path: &Path, px: &[u8], w: u32, h: u32, opts: &TileOptions) -> Result<()> {
    let bytes = encode(px, w, h, opts)?;
    std::fs::write(path, bytes).with_context(|| format!("{}: cannot write", path.display()))
}

/// Encode RGB8 pixels as JPEG (quality `opts.quality`) or PNG.
///
/// # Errors
/// The encoder's.
pub fn encode(px: &[u8], w: u32, h: u32, opts: &TileOptions) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    if opts.png {
        use image::ImageEncoder;
        image::codecs::png::PngEncoder::new(&mut out)
            .write_image(px, w, h, image::ExtendedColorType::Rgb8)
            .map_err(|e| anyhow!("cannot encode PNG tile: {e}"))?;
    } else {
        super::jpeg::encode_rgb(px, w, h, opts.quality, &mut out)?;
    }
    Ok(out)
}

/// One level below the top: its resampler from the level above and its band of rows.
struct LevelBand {
    level: u32,
    size: u32,
    resampler: Resampler,
    band: Vec<u8>,
    band_row: u32,
    rows_done: u32,
}

/// Push rows of the level above into `chain[0]`; write each band of tiles it completes
/// and pass it on down.
fn feed(ctx: &Ctx<'_>, fi: usize, chain: &mut [LevelBand], rows: &[u8]) -> Result<()> {
    let Some((first, rest)) = chain.split_first_mut() else {
        return Ok(());
    };
    let ts = ctx.layout.tile_size;
    let row_bytes = 3 * first.size as usize;
    let mut bands: Vec<(u32, Vec<u8>)> = Vec::new();
    {
        let LevelBand {
            resampler,
            band,
            band_row,
            rows_done,
            size,
            ..
        } = first;
        let size = *size;
        resampler.push_rows(rows, &mut |row| {
            band.extend_from_slice(row);
            *rows_done += 1;
            if band.len() == ts as usize * row_bytes || *rows_done == size {
                bands.push((*band_row, std::mem::take(band)));
                *band_row += 1;
            }
        });
    }
    for (br, b) in bands {
        ctx.band(fi, first.level, br, &b, first.size)?;
        feed(ctx, fi, rest, &b)?;
    }
    Ok(())
}

/// Write the pyramid of `source` into `dir` (see [`prepare_dir`]): every tile of every
/// level of the six faces, the fallback faces, then `config.json` (atomically, last).
/// `progress` is called from this thread between bands of tiles.
///
/// # Errors
/// The folder cannot be prepared or written; the source fails; bad options.
pub fn write_pyramid(
    source: &dyn FaceSource,
    dir: &Path,
    opts: &TileOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Report> {
    if !(1..=100).contains(&opts.quality) {
        bail!("--quality {}: must be 1 to 100", opts.quality);
    }
    if !(opts.hfov.is_finite() && opts.hfov > 0.0 && opts.hfov < 360.0) {
        bail!("--hfov {}: must be in (0, 360)", opts.hfov);
    }
    let layout = layout_for(source, opts)?;
    prepare_dir(dir)?;
    let ext = if opts.png { "png" } else { "jpg" };
    for l in 1..=layout.max_level {
        let p = dir.join(l.to_string());
        std::fs::create_dir_all(&p).with_context(|| format!("{}: cannot create", p.display()))?;
    }
    let fb = opts.fallback_size;
    if fb > 0 {
        let p = dir.join("fallback");
        std::fs::create_dir_all(&p).with_context(|| format!("{}: cannot create", p.display()))?;
    }
    let ctx = Ctx {
        dir,
        opts,
        layout: &layout,
        ext,
        missing: Mutex::new(Vec::new()),
        written: 0.into(),
    };
    let total = layout.tile_count();
    let mut done = 0u64;
    progress(Progress {
        stage: Stage::Tiles,
        done,
        total,
    });
    let n = layout.cube_size;
    let ts = layout.tile_size;
    let top = layout.max_level;
    for (fi, &(letter, face)) in FACES.iter().enumerate() {
        let mut chain: Vec<LevelBand> = (1..top)
            .rev()
            .map(|level| {
                let size = layout.level_size(level);
                let above = layout.level_size(level + 1);
                LevelBand {
                    level,
                    size,
                    resampler: Resampler::new((above, above), (size, size)),
                    band: Vec::new(),
                    band_row: 0,
                    rows_done: 0,
                }
            })
            .collect();
        let mut fallback = (fb > 0).then(|| (Resampler::new((n, n), (fb, fb)), Vec::new()));
        for band_row in 0..n.div_ceil(ts) {
            let y0 = band_row * ts;
            let h = ts.min(n - y0);
            let tiles: Vec<Vec<u8>> = (0..n.div_ceil(ts))
                .into_par_iter()
                .map(|c| -> Result<Vec<u8>> {
                    let x0 = c * ts;
                    let w = ts.min(n - x0);
                    let mut px = vec![0u8; (3 * w * h) as usize];
                    source.render(face, n, Rect { x: x0, y: y0, w, h }, &mut px)?;
                    ctx.tile((fi, top, band_row, c), &px, (w, h))?;
                    Ok(px)
                })
                .collect::<Result<_>>()?;
            let mut band = Vec::with_capacity((3 * n * h) as usize);
            for r in 0..h as usize {
                for (c, t) in tiles.iter().enumerate() {
                    let w = ts.min(n - c as u32 * ts) as usize;
                    band.extend_from_slice(&t[3 * r * w..3 * (r + 1) * w]);
                }
            }
            drop(tiles);
            feed(&ctx, fi, &mut chain, &band)?;
            if let Some((r, face_px)) = fallback.as_mut() {
                r.push_rows(&band, &mut |row| face_px.extend_from_slice(row));
            }
            done = ctx.written.load(std::sync::atomic::Ordering::Relaxed)
                + ctx.missing.lock().map(|m| m.len() as u64).unwrap_or(0);
            progress(Progress {
                stage: Stage::Tiles,
                done,
                total,
            });
        }
        if let Some((_, face_px)) = fallback {
            let path = dir.join("fallback").join(format!("{letter}.{ext}"));
            write_image_file(&path, &face_px, fb, fb, opts)?;
        }
    }
    let missing = ctx
        .missing
        .into_inner()
        .map_err(|_| anyhow!("a tile thread failed"))?;
    let extras = ConfigExtras {
        hfov: opts.hfov,
        extension: ext,
        fallback: fb > 0,
        missing_tiles: missing_tiles_string(&layout, &missing),
    };
    write_config(dir, &config_text(&layout, &extras))?;
    let written = ctx.written.into_inner();
    progress(Progress {
        stage: Stage::Tiles,
        done: total,
        total,
    });
    Ok(Report {
        layout: layout.clone(),
        tiles_written: written,
        tiles_missing: missing.len() as u64,
        face_pixels: 6 * u64::from(n) * u64::from(n),
    })
}

/// Write `config.json` through the one output writer ([`crate::output::write_image_atomic`]:
/// a temporary file in the folder, renamed, removed on an error or a signal; an ordinary
/// file's permissions, so a web server can serve it like the tiles).
fn write_config(dir: &Path, text: &str) -> Result<()> {
    let path: PathBuf = dir.join("config.json");
    crate::output::write_image_atomic(&path, |w| Ok(w.write_all(text.as_bytes())?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_names() {
        assert!(is_tile_name("f0_12.jpg", false));
        assert!(is_tile_name("r3_4.png", false));
        assert!(!is_tile_name("x0_1.jpg", false));
        assert!(!is_tile_name("f0_.jpg", false));
        assert!(!is_tile_name("f0_1.jpeg", false));
        assert!(is_tile_name("u.jpg", true));
        assert!(!is_tile_name("u0_0.jpg", true));
    }
}

//! A small pyramid writer for tests and benchmarks: tiles from a function, PNG or JPEG,
//! the configuration written last (an interrupted run never looks complete). The levels
//! and sizes are the generator's (`generate.py`): `ceil(log2(cube / tile)) + 1` levels,
//! one fewer in its edge case, each `int(size / 2)` of the one above. (`viewer tile`
//! builds real pyramids from images.)

use super::config::{face_letter, level_size};
use super::id::TileId;
use crate::cube::Face;
use std::path::Path;

/// The generator's number of levels for faces of `cube` texels cut into `tile` squares.
pub fn generator_levels(cube: u32, tile: u32) -> u32 {
    let tile = tile.min(cube).max(1);
    let mut levels = ((cube as f64 / tile as f64).log2().ceil() as u32) + 1;
    if levels >= 2 && (cube >> (levels - 2)) == tile {
        levels -= 1;
    }
    levels
}

/// Write a pyramid into `dir` (created): faces of `cube` texels, `tile` tiles, `ext`
/// `"png"` or `"jpg"` (quality 90); `texels(id, x0, y0, w, h)` gives tile `id`'s `w × h`
/// 0RGB texels (its top-left texel at `(x0, y0)` of its level's face). Returns the
/// number of levels.
///
/// # Errors
/// A file that cannot be written, as a message naming it.
pub fn write_pyramid(
    dir: &Path,
    cube: u32,
    tile: u32,
    ext: &str,
    texels: &(dyn Fn(TileId, u32, u32, u32, u32) -> Vec<u32> + Sync),
) -> Result<u32, String> {
    use rayon::prelude::*;
    let tile = tile.min(cube);
    let levels = generator_levels(cube, tile);
    let mut jobs = Vec::new();
    for level in 1..=levels {
        let size = level_size(cube, levels, level);
        let n = size.div_ceil(tile);
        std::fs::create_dir_all(dir.join(level.to_string()))
            .map_err(|e| format!("{}: {e}", dir.display()))?;
        for face in Face::ALL {
            for y in 0..n {
                for x in 0..n {
                    jobs.push((
                        TileId {
                            level: level as u8,
                            face,
                            y,
                            x,
                        },
                        size,
                    ));
                }
            }
        }
    }
    jobs.par_iter().try_for_each(|&(id, size)| {
        let (x0, y0) = (id.x * tile, id.y * tile);
        let (w, h) = ((size - x0).min(tile), (size - y0).min(tile));
        let px = texels(id, x0, y0, w, h);
        let rgb: Vec<u8> = px
            .iter()
            .flat_map(|p| [(p >> 16) as u8, (p >> 8) as u8, *p as u8])
            .collect();
        let path = dir.join(id.level.to_string()).join(format!(
            "{}{}_{}.{ext}",
            face_letter(id.face),
            id.y,
            id.x
        ));
        let img = image::RgbImage::from_raw(w, h, rgb).ok_or("tile buffer")?;
        let r = if ext == "png" {
            img.save_with_format(&path, image::ImageFormat::Png)
        } else {
            let f = std::fs::File::create(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let mut enc =
                image::codecs::jpeg::JpegEncoder::new_with_quality(std::io::BufWriter::new(f), 90);
            enc.encode_image(&img)
        };
        r.map_err(|e| format!("{}: {e}", path.display()))
    })?;
    let config = format!(
        "{{\n    \"type\": \"multires\",\n    \"multiRes\": {{\n        \"path\": \"/%l/%s%y_%x\",\n        \"extension\": \"{ext}\",\n        \"tileResolution\": {tile},\n        \"maxLevel\": {levels},\n        \"cubeResolution\": {cube}\n    }}\n}}\n"
    );
    let tmp = dir.join("config.json.part");
    std::fs::write(&tmp, config).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, dir.join("config.json"))
        .map_err(|e| format!("{}: {e}", dir.display()))?;
    Ok(levels)
}

/// Write a Marzipano scene's tiles into `dir` (created; the scene's `tiles/<id>`) as the
/// Marzipano tool lays them out: `{z}/{f}/{y}/{x}.jpg` for `levels` given as
/// `(tileSize, size)` in size order (`z` the index), faces `b d f l r u`; with `preview`,
/// level 0 (one tile a face) as `preview.jpg` instead, its six faces stacked in
/// `bdflru` order. `texels(z, letter, x0, y0, w, h)` gives the tile's `w × h` 0RGB texels
/// (its top-left texel at `(x0, y0)` of face `letter` at level `z`). `quality`: JPEG
/// quality, or `None` for PNG bytes under the `.jpg` names (lossless, for tests that
/// compare pixels; the reader, as browsers, goes by the bytes).
///
/// # Errors
/// A file that cannot be written, as a message naming it.
pub fn write_marzipano(
    dir: &Path,
    levels: &[(u32, u32)],
    preview: bool,
    quality: Option<u8>,
    texels: &(dyn Fn(u32, char, u32, u32, u32, u32) -> Vec<u32> + Sync),
) -> Result<(), String> {
    use rayon::prelude::*;
    let save = |path: &Path, w: u32, h: u32, px: &[u32]| -> Result<(), String> {
        let rgb: Vec<u8> = px
            .iter()
            .flat_map(|p| [(p >> 16) as u8, (p >> 8) as u8, *p as u8])
            .collect();
        if let Some(d) = path.parent() {
            std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))?;
        }
        let img = image::RgbImage::from_raw(w, h, rgb).ok_or("tile buffer")?;
        let r = match quality {
            None => img.save_with_format(path, image::ImageFormat::Png),
            Some(q) => {
                let f =
                    std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
                image::codecs::jpeg::JpegEncoder::new_with_quality(std::io::BufWriter::new(f), q)
                    .encode_image(&img)
            }
        };
        r.map_err(|e| format!("{}: {e}", path.display()))
    };
    let mut jobs = Vec::new();
    for (z, &(tile, size)) in levels.iter().enumerate() {
        if preview && z == 0 {
            continue;
        }
        let n = size.div_ceil(tile);
        for f in "bdflru".chars() {
            for y in 0..n {
                for x in 0..n {
                    jobs.push((z as u32, f, y, x, tile, size));
                }
            }
        }
    }
    jobs.par_iter().try_for_each(|&(z, f, y, x, tile, size)| {
        let (x0, y0) = (x * tile, y * tile);
        let (w, h) = ((size - x0).min(tile), (size - y0).min(tile));
        let px = texels(z, f, x0, y0, w, h);
        save(&dir.join(format!("{z}/{f}/{y}/{x}.jpg")), w, h, &px)
    })?;
    if preview {
        let s = levels.first().map_or(0, |l| l.1);
        let strip: Vec<u32> = "bdflru"
            .chars()
            .flat_map(|f| texels(0, f, 0, 0, s, s))
            .collect();
        save(&dir.join("preview.jpg"), s, 6 * s, &strip)?;
    }
    Ok(())
}

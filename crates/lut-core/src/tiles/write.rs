//! A small pyramid writer for tests and benchmarks: tiles from a function, PNG or JPEG,
//! the configuration written last (an interrupted run never looks complete). The levels
//! and sizes are the generator's (`generate.py`): `ceil(log2(cube / tile)) + 1` levels,
//! one fewer in its edge case, each `int(size / 2)` of the one above. (`viewer tile`
//! builds real pyramids from images.)

use super::config::{face_letter, level_size, TileId};
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

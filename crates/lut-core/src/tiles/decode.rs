//! Reading one tile file: a regular file, its header's size checked against the tile's
//! before a pixel is decoded (a decompression bomb or a tile of the wrong size is refused
//! from its header), decoded behind `catch_unwind` (a decoder's panic is the tile's error,
//! never the viewer's), into 0RGB texels.

use super::config::{MultiresConfig, TileId};
use std::io::Read;
use std::path::Path;

/// A tile file is read up to 64 MiB (a 512² tile is ~50 KiB as JPEG, 1 MiB as PNG).
pub const MAX_TILE_FILE_BYTES: u64 = 64 << 20;

/// Decode tile `id` of `cfg`: `w × h` row-major 0RGB texels, or why not (one line).
///
/// # Errors
/// The file cannot be read, is not a JPEG or PNG of the tile's size, or is corrupt.
pub fn decode_tile(cfg: &MultiresConfig, id: TileId) -> Result<Vec<u32>, String> {
    let want = cfg.tile_dims(id);
    decode_file(&cfg.tile_path(id), want)
}

/// Decode the image at `path`, which must be `want` (width, height).
///
/// # Errors
/// As [`decode_tile`].
pub fn decode_file(path: &Path, want: (u32, u32)) -> Result<Vec<u32>, String> {
    let f = crate::file::open_regular(path).map_err(|e| format!("cannot read: {e}"))?;
    let mut bytes = Vec::new();
    f.take(MAX_TILE_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read: {e}"))?;
    if bytes.len() as u64 > MAX_TILE_FILE_BYTES {
        return Err(format!("larger than {MAX_TILE_FILE_BYTES} bytes"));
    }
    decode_bytes(&bytes, want)
}

/// Decode an image held in memory (see [`decode_file`]).
///
/// # Errors
/// As [`decode_tile`].
pub fn decode_bytes(bytes: &[u8], want: (u32, u32)) -> Result<Vec<u32>, String> {
    let dims = imagesize::blob_size(bytes).map_err(|e| format!("not an image: {e}"))?;
    if (dims.width as u64, dims.height as u64) != (want.0 as u64, want.1 as u64) {
        return Err(format!(
            "{}×{} pixels, the tile should be {}×{}",
            dims.width, dims.height, want.0, want.1
        ));
    }
    let decoded = std::panic::catch_unwind(|| -> Result<Vec<u32>, String> {
        let mut r = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| e.to_string())?;
        match r.format() {
            Some(image::ImageFormat::Jpeg) | Some(image::ImageFormat::Png) => {}
            _ => return Err("not a JPEG or PNG tile".into()),
        }
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(want.0);
        limits.max_image_height = Some(want.1);
        limits.max_alloc = Some(want.0 as u64 * want.1 as u64 * 8 + (1 << 20));
        r.limits(limits);
        let img = r.decode().map_err(|e| e.to_string())?;
        if (img.width(), img.height()) != want {
            return Err(format!("decoded as {}×{}", img.width(), img.height()));
        }
        let rgb = img.into_rgb8();
        Ok(rgb
            .pixels()
            .map(|p| ((p[0] as u32) << 16) | ((p[1] as u32) << 8) | p[2] as u32)
            .collect())
    });
    match decoded {
        Ok(r) => r.map_err(|e| format!("cannot decode: {e}")),
        Err(_) => Err("the decoder failed (panicked) on this file".into()),
    }
}

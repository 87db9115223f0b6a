//! Reading one tile file: a regular file, its header's size checked against the tile's
//! before a pixel is decoded (a decompression bomb or a tile of the wrong size is refused
//! from its header), decoded behind the decoders' one containment (`guard::catch_quiet`:
//! a decoder's panic is the tile's error, never the viewer's), into 0RGB texels.

use super::config::MultiresConfig;
use super::id::TileId;
use std::path::Path;

/// A tile file is read up to 64 MiB (a 512² tile is ~50 KiB as JPEG, 1 MiB as PNG).
pub const MAX_TILE_FILE_BYTES: u64 = 64 << 20;

/// Decode tile `id` of `cfg`: `w × h` row-major 0RGB texels, or why not (one line).
///
/// # Errors
/// The file cannot be read, is not a JPEG or PNG of the tile's size, or is corrupt.
pub fn decode_tile(cfg: &MultiresConfig, id: TileId) -> Result<Vec<u32>, String> {
    let want = cfg.tile_dims(id);
    if let Some((path, k)) = cfg.preview_face(id) {
        // A Marzipano preview: the six faces of level 1 stacked top to bottom.
        let (w, h) = want;
        let strip = decode_file(&path, (w, 6 * h))?;
        let n = w as usize * h as usize;
        return Ok(strip[k * n..(k + 1) * n].to_vec());
    }
    decode_file(&cfg.tile_path(id), want)
}

/// Decode the image at `path`, which must be `want` (width, height).
///
/// # Errors
/// As [`decode_tile`].
pub fn decode_file(path: &Path, want: (u32, u32)) -> Result<Vec<u32>, String> {
    // The one reader of small input files: a FIFO or device refused without blocking.
    let bytes = crate::file::read_regular(path, MAX_TILE_FILE_BYTES)
        .map_err(|e| format!("cannot read: {e}"))?;
    decode_bytes(&bytes, want)
}

/// Decode an image held in memory (see [`decode_file`]).
///
/// # Errors
/// As [`decode_tile`].
pub fn decode_bytes(bytes: &[u8], want: (u32, u32)) -> Result<Vec<u32>, String> {
    // The decoders' one containment (docs/reliability.md, class 2), around the header's
    // reading too: a panic is this tile's error, kept off standard error.
    match crate::guard::catch_quiet(|| decode_contained(bytes, want)) {
        Ok(r) => r,
        Err(m) => Err(format!("the decoder failed on this file ({m})")),
    }
}

fn decode_contained(bytes: &[u8], want: (u32, u32)) -> Result<Vec<u32>, String> {
    crate::guard::fault_point("decoder");
    crate::guard::fault_point("tile");
    let dims = imagesize::blob_size(bytes).map_err(|e| format!("not an image: {e}"))?;
    if (dims.width as u64, dims.height as u64) != (want.0 as u64, want.1 as u64) {
        return Err(format!(
            "{}×{} pixels, the tile should be {}×{}",
            dims.width, dims.height, want.0, want.1
        ));
    }
    if bytes.starts_with(&[0xFF, 0xD8]) {
        return decode_jpeg(bytes, want);
    }
    let mut r = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot decode: {e}"))?;
    match r.format() {
        Some(image::ImageFormat::Png) => {}
        _ => return Err("cannot decode: not a JPEG or PNG tile".into()),
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(want.0);
    limits.max_image_height = Some(want.1);
    limits.max_alloc = Some(want.0 as u64 * want.1 as u64 * 8 + (1 << 20));
    r.limits(limits);
    let img = r.decode().map_err(|e| format!("cannot decode: {e}"))?;
    if (img.width(), img.height()) != want {
        return Err(format!(
            "cannot decode: decoded as {}×{}",
            img.width(),
            img.height()
        ));
    }
    let rgb = img.into_rgb8();
    Ok(rgb
        .pixels()
        .map(|p| ((p[0] as u32) << 16) | ((p[1] as u32) << 8) | p[2] as u32)
        .collect())
}

/// A JPEG tile through the map loader's strict decoder (`crate::jpeg`): a tile whose data
/// ends before its last rows, or is corrupt, is refused rather than drawn with a grey or
/// repeated part (docs/reliability.md, class 3), and its header must fit its bytes.
fn decode_jpeg(bytes: &[u8], want: (u32, u32)) -> Result<Vec<u32>, String> {
    let reason = |e: crate::error::MapError| match e {
        crate::error::MapError::Decode { reason, .. } => format!("cannot decode: {reason}"),
        other => other.to_string(),
    };
    let mut b = bytes.to_vec();
    let scan = crate::jpeg::prepare(&mut b, "tile").map_err(reason)?;
    let j = crate::jpeg::Jpeg::new(&b, "tile").map_err(reason)?;
    if (j.width, j.height) != want {
        return Err(format!(
            "{}×{} pixels, the tile should be {}×{}",
            j.width, j.height, want.0, want.1
        ));
    }
    crate::jpeg::check_jpeg_size("tile", want.0.into(), want.1.into(), scan).map_err(reason)?;
    let bpp = usize::from(j.color.bytes_per_pixel());
    let mut out = vec![0u8; want.0 as usize * want.1 as usize * bpp];
    j.decode_into(&mut out, "tile").map_err(reason)?;
    Ok(out
        .chunks_exact(bpp)
        .map(|p| match bpp {
            1 | 2 => u32::from(p[0]) * 0x01_01_01,
            _ => (u32::from(p[0]) << 16) | (u32::from(p[1]) << 8) | u32::from(p[2]),
        })
        .collect())
}

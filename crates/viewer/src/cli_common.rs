//! Helpers shared by the subcommands: parsing sizes and angles, loading panoramas,
//! writing images atomically.

use anyhow::{anyhow, Context, Result};
use lut_core::{EnvMap, Projection};
use std::path::{Path, PathBuf};

/// Parse "WxH" into (w, h), each in 1..=MAX_OUTPUT_SIDE.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (a, b) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size '{s}' must look like WIDTHxHEIGHT, e.g. 1280x720"))?;
    let w: u32 = a
        .trim()
        .parse()
        .map_err(|_| format!("size '{s}': width '{a}' is not a whole number"))?;
    let h: u32 = b
        .trim()
        .parse()
        .map_err(|_| format!("size '{s}': height '{b}' is not a whole number"))?;
    lut_core::check_size(w, h).map_err(|e| format!("size '{s}': {e}"))?;
    Ok((w, h))
}

/// Parse a finite angle in degrees.
pub fn parse_angle(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a number of degrees"))?;
    if !v.is_finite() {
        return Err(format!("'{s}' is not a finite number of degrees"));
    }
    Ok(v)
}

/// `auto` or a projection name.
pub fn parse_projection(s: &str) -> Result<Option<Projection>, String> {
    if s == "auto" {
        Ok(None)
    } else {
        s.parse().map(Some)
    }
}

/// The command-line hint for a library map error: which flag changes the outcome.
pub fn map_error_hint(e: &lut_core::MapError) -> Option<&'static str> {
    match e {
        lut_core::MapError::TooManyPixels { .. } => Some("raise the limit with --max-pixels"),
        lut_core::MapError::UnknownProjection { .. } => {
            Some("give --projection cylinder|sine|elliptical|diamond")
        }
        _ => None,
    }
}

/// A library map error as one line, with its command-line hint (see [`map_error_hint`]).
pub fn map_error(e: lut_core::MapError) -> anyhow::Error {
    match map_error_hint(&e) {
        Some(hint) => anyhow!("{e}; {hint}"),
        None => anyhow::Error::new(e),
    }
}

/// Load the panorama at `path` (the bundled sample when `None`) with `opts`: projection,
/// tone and the pixel limit (`--max-pixels`, checked from the header before decoding).
/// The file is streamed into the map, never held whole by this function.
pub fn load_panorama_opts(path: Option<&Path>, opts: &lut_core::LoadOptions) -> Result<EnvMap> {
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

/// Write 0RGB pixels as an 8-bit RGB PNG atomically: a temporary file in the same folder,
/// then rename. On any error nothing is left at `out`.
pub fn write_png_atomic(out: &Path, pixels: &[u32], width: u32, height: u32) -> Result<()> {
    let mut rgb = Vec::with_capacity(pixels.len() * 3);
    for p in pixels {
        rgb.extend_from_slice(&[(p >> 16) as u8, (p >> 8) as u8, *p as u8]);
    }
    let img = image::RgbImage::from_raw(width, height, rgb)
        .ok_or_else(|| anyhow!("internal: pixel buffer does not match {width}x{height}"))?;
    // The format follows the extension (PNG unless it names another encoder we have).
    let format = match image::ImageFormat::from_path(out) {
        Ok(f @ (image::ImageFormat::Jpeg | image::ImageFormat::Png)) => f,
        _ => image::ImageFormat::Png,
    };
    write_image_atomic(out, |tmp| {
        img.write_to(tmp, format)
            .map_err(|e| anyhow!("{}: cannot encode the image: {e}", out.display()))
    })
}

/// Atomically write a file produced by `write` (which gets a seekable temp file).
pub fn write_image_atomic(
    out: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<&mut std::fs::File>) -> Result<()>,
) -> Result<()> {
    let dir: PathBuf = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(anyhow!(
            "{}: cannot write: folder '{}' does not exist",
            out.display(),
            dir.display()
        ));
    }
    let mut tmp = tempfile::Builder::new()
        .prefix(".viewer-")
        .suffix(".tmp")
        .tempfile_in(&dir)
        .with_context(|| format!("{}: cannot create a temporary file", out.display()))?;
    {
        let mut bw = std::io::BufWriter::new(tmp.as_file_mut());
        write(&mut bw)?;
        use std::io::Write;
        bw.flush()
            .with_context(|| format!("{}: cannot write", out.display()))?;
    }
    // tempfile creates 0600 files; a rendered image is an ordinary file.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = tmp
            .as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644));
    }
    tmp.persist(out)
        .map_err(|e| anyhow!("{}: cannot write: {}", out.display(), e.error))?;
    Ok(())
}

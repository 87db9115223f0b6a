//! Writing images: 0RGB pixels to RGB bytes, and files written atomically (a temporary
//! file in the same folder, then a rename), so a failed write leaves nothing behind.

use anyhow::{anyhow, Context, Result};
use std::path::{Path, PathBuf};

/// 0RGB pixels as packed 8-bit RGB bytes (`R G B R G B …`).
pub fn rgb24(pixels: &[u32]) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(pixels.len() * 3);
    for p in pixels {
        rgb.extend_from_slice(&[(p >> 16) as u8, (p >> 8) as u8, *p as u8]);
    }
    rgb
}

/// Write 0RGB pixels as an 8-bit RGB PNG atomically: a temporary file in the same folder,
/// then rename. On any error nothing is left at `out`.
pub fn write_png_atomic(out: &Path, pixels: &[u32], width: u32, height: u32) -> Result<()> {
    let img = image::RgbImage::from_raw(width, height, rgb24(pixels))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb24_drops_the_top_byte() {
        assert_eq!(
            rgb24(&[0xFF12_3456, 0x00AB_CDEF]),
            [0x12, 0x34, 0x56, 0xAB, 0xCD, 0xEF]
        );
    }

    #[test]
    fn png_round_trips_and_failures_leave_nothing() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("a.png");
        let px = [0x0010_2030u32, 0x0040_5060, 0x0070_8090, 0x00A0_B0C0];
        write_png_atomic(&out, &px, 2, 2).unwrap();
        let img = image::open(&out).unwrap().to_rgb8();
        assert_eq!(img.into_raw(), rgb24(&px));
        assert!(write_png_atomic(&out, &px, 3, 2).is_err());
        let nowhere = tmp.path().join("no/such/b.png");
        let e = write_png_atomic(&nowhere, &px, 2, 2).unwrap_err();
        assert!(format!("{e:#}").contains("does not exist"), "{e:#}");
        assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 1);
    }
}

//! Writing images: the format chosen by the file name, files replaced atomically,
//! special files written into (never replaced), inputs never overwritten, and temporary
//! files removed on SIGINT/SIGTERM.
//!
//! * **Format**: `.png`, or `.jpg` / `.jpeg` (quality 95), in any case. Any other
//!   extension is a usage error (exit 2), decided before anything is loaded: `out.bmp`
//!   never gets PNG bytes. A name without an extension is accepted when it names a
//!   device or FIFO (`-o /dev/stdout`: PNG) or leads to a file that has one (`/dev/stdout`
//!   redirected to `view.png`).
//! * **Regular files** (new or existing, also through symbolic links, which are
//!   followed: the link stays, its target is replaced) are written to a temporary file
//!   `.viewer-XXXXXX.tmp` in the target's folder and renamed over the target, so a failed
//!   or interrupted write leaves the old file (or nothing) and never half an image. An
//!   existing file keeps its permissions.
//! * **Character devices and FIFOs** (`/dev/null`, `/dev/stdout`, a named pipe) are
//!   written into directly, never replaced by a regular file. Block devices, sockets and
//!   folders are refused.
//! * **Inputs**: [`check_not_input`] refuses an output that is one of the inputs (the
//!   same file by device and inode: through symbolic links and hard links too).
//! * **Signals**: the temporary files being written are registered; the handler in
//!   [`crate::signals`] removes them ([`remove_temporaries`]) before the process dies.

use crate::usage;
use anyhow::{anyhow, Context, Result};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// 0RGB pixels as packed 8-bit RGB bytes (`R G B R G B …`).
pub fn rgb24(pixels: &[u32]) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(pixels.len() * 3);
    for p in pixels {
        rgb.extend_from_slice(&[(p >> 16) as u8, (p >> 8) as u8, *p as u8]);
    }
    rgb
}

/// An image format the viewer writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageKind {
    /// PNG, 8-bit RGB.
    Png,
    /// JPEG, quality 95.
    Jpeg,
}

/// The format a name's extension asks for: `None` without an extension, `Some(Err(ext))`
/// for one the viewer does not write.
fn kind_of_extension(p: &Path) -> Option<Result<ImageKind, String>> {
    let ext = p.extension()?.to_string_lossy().to_ascii_lowercase();
    Some(match ext.as_str() {
        "png" => Ok(ImageKind::Png),
        "jpg" | "jpeg" => Ok(ImageKind::Jpeg),
        _ => Err(ext),
    })
}

/// True when `p` exists and is a character device or a FIFO (written into directly).
fn is_stream(p: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        std::fs::metadata(p).is_ok_and(|m| {
            let t = m.file_type();
            t.is_char_device() || t.is_fifo()
        })
    }
    #[cfg(not(unix))]
    {
        let _ = p;
        false
    }
}

/// The format `out` is written in (see the module docs), decided from its name (and,
/// without an extension, from what it names) before anything is loaded.
///
/// # Errors
/// A usage error (exit 2) for an extension the viewer does not write, or a plain file
/// name without one.
pub fn output_kind(out: &Path) -> Result<ImageKind> {
    let unsupported = |ext: &str| {
        usage!(
            "{}: cannot write '.{ext}' images; give a name ending in .png, .jpg or .jpeg",
            out.display()
        )
    };
    match kind_of_extension(out) {
        Some(Ok(k)) => Ok(k),
        Some(Err(ext)) => Err(unsupported(&ext)),
        None if is_stream(out) => Ok(ImageKind::Png),
        None => match std::fs::canonicalize(out)
            .ok()
            .as_deref()
            .and_then(kind_of_extension)
        {
            Some(Ok(k)) => Ok(k),
            _ => Err(usage!(
                "{}: no file type in the name; give a name ending in .png, .jpg or .jpeg",
                out.display()
            )),
        },
    }
}

/// Write 0RGB pixels as an image in the format `out` names (see [`output_kind`]),
/// atomically or into a special file (see the module docs).
///
/// # Errors
/// An unsupported name (usage), a refused or unwritable target, an encoding failure.
pub fn write_image(out: &Path, pixels: &[u32], width: u32, height: u32) -> Result<()> {
    let kind = output_kind(out)?;
    let rgb = rgb24(pixels);
    if rgb.len() != width as usize * height as usize * 3 {
        return Err(anyhow!(
            "internal: pixel buffer does not match {width}x{height}"
        ));
    }
    write_image_atomic(out, |w| {
        let r =
            match kind {
                ImageKind::Png => image::ImageEncoder::write_image(
                    image::codecs::png::PngEncoder::new(w),
                    &rgb,
                    width,
                    height,
                    image::ExtendedColorType::Rgb8,
                ),
                ImageKind::Jpeg => image::codecs::jpeg::JpegEncoder::new_with_quality(w, 95)
                    .encode(&rgb, width, height, image::ExtendedColorType::Rgb8),
            };
        r.map_err(|e| match e {
            image::ImageError::IoError(io) => anyhow::Error::new(io),
            other => anyhow!("cannot encode the image: {other}"),
        })
    })
}

/// [`write_image`] under its old name (the format follows the extension: PNG or JPEG).
///
/// # Errors
/// As [`write_image`].
pub fn write_png_atomic(out: &Path, pixels: &[u32], width: u32, height: u32) -> Result<()> {
    write_image(out, pixels, width, height)
}

/// Temporary files being written (removed by the signal handling).
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// Remove every temporary file being written and return the lock of the list, which
/// the caller holds until the process ends (so no write starts or finishes meanwhile).
pub fn remove_temporaries() -> MutexGuard<'static, Vec<PathBuf>> {
    let list = temporaries();
    for p in list.iter() {
        let _ = std::fs::remove_file(p);
    }
    list
}

/// A temporary file, listed while it exists: dropping it removes the file (unless it
/// was renamed into place), then its entry.
struct Temporary {
    file: Option<tempfile::NamedTempFile>,
    path: PathBuf,
}

impl Temporary {
    /// A new temporary file in `dir`, listed under the list's lock (a signal cannot
    /// slip in between).
    fn new(dir: &Path) -> std::io::Result<Temporary> {
        let mut list = temporaries();
        let file = tempfile::Builder::new()
            .prefix(".viewer-")
            .suffix(".tmp")
            .tempfile_in(dir)?;
        let path = file.path().to_path_buf();
        list.push(path.clone());
        Ok(Temporary {
            file: Some(file),
            path,
        })
    }

    fn file(&mut self) -> &mut std::fs::File {
        self.file.as_mut().expect("not yet renamed").as_file_mut()
    }

    /// Rename into place, under the list's lock: a signal sees the file before or
    /// after, never during.
    fn persist(mut self, target: &Path) -> std::io::Result<()> {
        let _list = temporaries();
        let file = self.file.take().expect("not yet renamed");
        file.persist(target).map(|_| ()).map_err(|e| e.error)
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        drop(self.file.take());
        temporaries().retain(|q| q != &self.path);
    }
}

/// Where a write goes.
enum Target {
    /// A regular file (new or replaced), written beside and renamed into place; the
    /// permissions to keep.
    Atomic(PathBuf, Option<std::fs::Permissions>),
    /// A character device or FIFO, written into.
    Stream,
}

/// Follow a chain of symbolic links from `p` whose end does not exist yet (a link to the
/// file to create).
fn dangling_target(p: &Path) -> Result<PathBuf> {
    let mut at = p.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => {
                let t = std::fs::read_link(&at)
                    .with_context(|| format!("{}: cannot read the link", at.display()))?;
                at = match at.parent() {
                    Some(dir) if t.is_relative() => dir.join(t),
                    _ => t,
                };
            }
            _ => return Ok(at),
        }
    }
    Err(anyhow!(
        "{}: cannot write: too many levels of symbolic links",
        p.display()
    ))
}

fn target_of(out: &Path) -> Result<Target> {
    let cannot = |why: &str| anyhow!("{}: cannot write: {why}", out.display());
    match std::fs::metadata(out) {
        Ok(m) if m.is_file() => {
            let real = std::fs::canonicalize(out)
                .with_context(|| format!("{}: cannot write", out.display()))?;
            Ok(Target::Atomic(real, Some(m.permissions())))
        }
        Ok(m) if m.is_dir() => Err(cannot("it is a folder")),
        Ok(m) => {
            #[cfg(unix)]
            {
                use std::os::unix::fs::FileTypeExt;
                let t = m.file_type();
                if t.is_char_device() || t.is_fifo() {
                    return Ok(Target::Stream);
                }
                if t.is_block_device() {
                    return Err(cannot(
                        "it is a block device (an image is never written onto a disk)",
                    ));
                }
                if t.is_socket() {
                    return Err(cannot("it is a socket"));
                }
            }
            let _ = m;
            Err(cannot("it is not a regular file"))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            Ok(Target::Atomic(dangling_target(out)?, None))
        }
        Err(e) => Err(anyhow::Error::new(e).context(format!("{}: cannot write", out.display()))),
    }
}

/// Write a file produced by `write` at `out`: atomically for a regular file (a temporary
/// file in the same folder, then a rename; on any error or signal nothing is left but
/// the old file), straight into a device or FIFO (see the module docs).
///
/// # Errors
/// A refused target, a missing folder, the writer's or the file system's error.
pub fn write_image_atomic(
    out: &Path,
    write: impl FnOnce(&mut dyn Write) -> Result<()>,
) -> Result<()> {
    let (target, perms) = match target_of(out)? {
        Target::Stream => {
            // Encoded first, so an encoding error writes nothing.
            let mut bytes = Vec::new();
            write(&mut bytes)?;
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .open(out)
                .with_context(|| format!("{}: cannot write", out.display()))?;
            return f
                .write_all(&bytes)
                .and_then(|()| f.flush())
                .with_context(|| format!("{}: cannot write", out.display()));
        }
        Target::Atomic(t, p) => (t, p),
    };
    let dir: PathBuf = match target.parent() {
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
    let mut tmp = Temporary::new(&dir)
        .with_context(|| format!("{}: cannot create a temporary file", out.display()))?;
    {
        let mut bw = std::io::BufWriter::new(tmp.file());
        write(&mut bw).with_context(|| format!("{}: cannot write", out.display()))?;
        bw.flush()
            .with_context(|| format!("{}: cannot write", out.display()))?;
    }
    // tempfile creates 0600 files; a rendered image is an ordinary file (or keeps the
    // permissions of the file it replaces).
    #[cfg(unix)]
    let perms = perms.unwrap_or_else(|| {
        use std::os::unix::fs::PermissionsExt;
        std::fs::Permissions::from_mode(0o644)
    });
    #[cfg(unix)]
    let _ = tmp.file().set_permissions(perms);
    #[cfg(not(unix))]
    let _ = perms;
    tmp.persist(&target)
        .map_err(|e| anyhow!("{}: cannot write: {e}", out.display()))
}

/// The identity of a file: device and inode on Unix, the canonical path elsewhere.
type FileId = (u64, u64, PathBuf);

/// The [`FileId`] of `p`, if it exists.
fn file_id(p: &Path) -> Option<FileId> {
    let m = std::fs::metadata(p).ok()?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        Some((m.dev(), m.ino(), PathBuf::new()))
    }
    #[cfg(not(unix))]
    {
        let _ = m;
        Some((0, 0, std::fs::canonicalize(p).ok()?))
    }
}

/// Refuse outputs that are one of the inputs: the same file, however it is named
/// (symbolic or hard links). A folder among the inputs stands for the cube faces read
/// from it. Outputs that do not exist yet cannot be inputs.
///
/// # Errors
/// Naming the output and the input it would overwrite (exit status 1).
pub fn check_not_input(outputs: &[PathBuf], inputs: &[PathBuf]) -> Result<()> {
    let mut read: Vec<PathBuf> = Vec::new();
    for i in inputs {
        if i.is_dir() {
            read.extend(lut_core::cube_face_files(i).unwrap_or_default());
        } else {
            read.push(i.clone());
        }
    }
    let ids: Vec<(Option<FileId>, &PathBuf)> = read.iter().map(|p| (file_id(p), p)).collect();
    for out in outputs {
        let Some(id) = file_id(out) else { continue };
        if let Some((_, input)) = ids.iter().find(|(i, _)| i.as_ref() == Some(&id)) {
            return Err(anyhow!(
                "{}: refusing to write over an input ({} is the same file)",
                out.display(),
                input.display()
            ));
        }
    }
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
        write_image(&out, &px, 2, 2).unwrap();
        let img = image::open(&out).unwrap().to_rgb8();
        assert_eq!(img.into_raw(), rgb24(&px));
        assert!(write_image(&out, &px, 3, 2).is_err());
        let nowhere = tmp.path().join("no/such/b.png");
        let e = write_image(&nowhere, &px, 2, 2).unwrap_err();
        assert!(format!("{e:#}").contains("does not exist"), "{e:#}");
        assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 1);
        // Other tests write files at the same time in this process: none of ours is left
        // in the list.
        assert!(!temporaries().iter().any(|p| p.starts_with(tmp.path())));
    }

    #[test]
    fn the_format_follows_the_extension_or_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let px = [0x0080_4020u32; 64];
        for (name, format) in [
            ("a.PNG", image::ImageFormat::Png),
            ("b.jpg", image::ImageFormat::Jpeg),
            ("c.JPEG", image::ImageFormat::Jpeg),
        ] {
            let p = tmp.path().join(name);
            write_image(&p, &px, 8, 8).unwrap();
            let bytes = std::fs::read(&p).unwrap();
            assert_eq!(image::guess_format(&bytes).unwrap(), format, "{name}");
        }
        for name in ["d.bmp", "e.exr", "f"] {
            let p = tmp.path().join(name);
            let e = write_image(&p, &px, 8, 8).unwrap_err();
            assert_eq!(crate::exit::code(&e), 2, "{name}: {e:#}");
            assert!(!p.exists(), "{name}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn links_are_followed_and_permissions_kept() {
        use std::os::unix::fs::PermissionsExt;
        let tmp = tempfile::tempdir().unwrap();
        let px = [0x0010_2030u32; 4];
        let real = tmp.path().join("real.png");
        std::fs::write(&real, b"old").unwrap();
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o600)).unwrap();
        let link = tmp.path().join("link.png");
        std::os::unix::fs::symlink("real.png", &link).unwrap();
        write_image(&link, &px, 2, 2).unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert!(image::open(&real).is_ok());
        let mode = std::fs::metadata(&real).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600);
        // A link to a file that does not exist yet creates the file.
        let ahead = tmp.path().join("ahead.png");
        std::os::unix::fs::symlink("later.png", &ahead).unwrap();
        write_image(&ahead, &px, 2, 2).unwrap();
        assert!(image::open(tmp.path().join("later.png")).is_ok());
    }

    #[cfg(unix)]
    #[test]
    fn devices_are_written_into_and_never_replaced() {
        let px = [0u32; 4];
        write_image(Path::new("/dev/null"), &px, 2, 2).unwrap();
        assert!(!std::fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_file());
        let full = Path::new("/dev/full");
        if full.exists() {
            let e = write_image(full, &px, 2, 2).unwrap_err();
            assert!(format!("{e:#}").contains("space"), "{e:#}");
        }
    }

    #[test]
    fn outputs_that_are_inputs_are_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let a = tmp.path().join("a.png");
        std::fs::write(&a, b"x").unwrap();
        let b = tmp.path().join("b.png");
        assert!(check_not_input(std::slice::from_ref(&b), std::slice::from_ref(&a)).is_ok());
        let e = check_not_input(std::slice::from_ref(&a), std::slice::from_ref(&a)).unwrap_err();
        assert!(e.to_string().contains("a.png"), "{e}");
        #[cfg(unix)]
        {
            let hard = tmp.path().join("hard.png");
            std::fs::hard_link(&a, &hard).unwrap();
            assert!(check_not_input(&[hard], std::slice::from_ref(&a)).is_err());
            let soft = tmp.path().join("soft.png");
            std::os::unix::fs::symlink(&a, &soft).unwrap();
            assert!(check_not_input(std::slice::from_ref(&a), &[soft]).is_err());
        }
    }
}

//! Opening input files safely: only regular files are read. A FIFO (named pipe), a
//! device, a socket or a folder given where an image or a photometric file is expected
//! is refused with a reason, and opening it never blocks (a FIFO with no writer would
//! block an ordinary `open` forever). Depends on nothing else in the crate; `io` and
//! `light` use it.

use std::fs::File;
use std::io;
use std::path::Path;

/// What kind of non-regular file `meta` describes, in words ("a FIFO (named pipe)"),
/// or `None` for a regular file.
pub(crate) fn special_kind(meta: &std::fs::Metadata) -> Option<&'static str> {
    let t = meta.file_type();
    if t.is_file() {
        return None;
    }
    if t.is_dir() {
        return Some("a folder");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if t.is_char_device() {
            return Some("a character device");
        }
        if t.is_block_device() {
            return Some("a block device");
        }
        if t.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a regular file")
}

/// The error for a file of kind `kind` where a regular file is needed.
fn not_regular(kind: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("not a regular file ({kind}); only regular files are read"),
    )
}

/// Open `path` for reading if it is a regular file (symbolic links followed).
///
/// On Unix the file is opened with `O_NONBLOCK`, so opening a FIFO returns at once, and
/// the opened file itself is checked (no window between a check and the open). Regular
/// files ignore `O_NONBLOCK`: reads behave as usual.
///
/// # Errors
/// The open's own error (missing, no permission, a symbolic-link loop, ...), or
/// [`io::ErrorKind::InvalidInput`] naming the kind of a file that is not regular.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let mut opts = std::fs::OpenOptions::new();
    opts.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        opts.custom_flags(libc::O_NONBLOCK);
    }
    #[cfg(not(unix))]
    {
        // No non-blocking open: look first (a FIFO cannot be swapped in on these
        // systems the way it can on Unix).
        if let Some(kind) = special_kind(&std::fs::metadata(path)?) {
            return Err(not_regular(kind));
        }
    }
    let f = opts.open(path)?;
    match special_kind(&f.metadata()?) {
        None => Ok(f),
        Some(kind) => Err(not_regular(kind)),
    }
}

/// Read the whole of `path`, a regular file (opened as by [`open_regular`]: never
/// blocks on a FIFO), refusing one larger than `max_bytes` before reading it all. The
/// one reader for every small input file: scene files, settings, tours, tile configs.
///
/// # Errors
/// As [`open_regular`], the read's own error, or [`io::ErrorKind::InvalidData`] for a
/// file over `max_bytes` ("larger than N bytes, the limit for ...").
pub fn read_regular(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    use std::io::Read;
    let f = open_regular(path)?;
    let mut bytes = Vec::new();
    f.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("the file size exceeds the limit of {max_bytes} bytes for this kind of file"),
        ));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_open_and_folders_do_not() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        std::fs::write(&p, "x").unwrap();
        assert!(open_regular(&p).is_ok());
        let e = open_regular(dir.path()).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        assert!(e.to_string().contains("a folder"), "{e}");
        let missing = open_regular(&dir.path().join("missing")).unwrap_err();
        assert_eq!(missing.kind(), io::ErrorKind::NotFound);
        assert_eq!(read_regular(&p, 1).unwrap(), b"x");
        std::fs::write(&p, "xyz").unwrap();
        let e = read_regular(&p, 2).unwrap_err();
        assert!(e.to_string().contains("limit of 2 bytes"), "{e}");
        assert!(read_regular(dir.path(), 10).is_err());
    }

    #[cfg(unix)]
    #[test]
    fn fifos_and_devices_are_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.jpg");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo");
        assert!(status.success());
        // No writer: a blocking open would never return.
        let e = open_regular(&fifo).unwrap_err();
        assert!(e.to_string().contains("FIFO"), "{e}");
        assert!(read_regular(&fifo, 10)
            .unwrap_err()
            .to_string()
            .contains("FIFO"));
        let e = open_regular(Path::new("/dev/null")).unwrap_err();
        assert!(e.to_string().contains("character device"), "{e}");
        // Through a symbolic link too.
        let link = dir.path().join("link.jpg");
        std::os::unix::fs::symlink(&fifo, &link).unwrap();
        assert!(open_regular(&link)
            .unwrap_err()
            .to_string()
            .contains("FIFO"));
    }
}

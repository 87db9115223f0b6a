//! What a file opened or dropped on the window is, judged by its content: a scene file,
//! a luminaire (IES or EULUMDAT), or anything else (a panorama to load).

use super::scene_file::is_scene;
use std::io::Read;
use std::path::Path;

/// What a file is, for routing it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A scene file (`"format": "lutpano-scene"`).
    Scene,
    /// A luminaire: IES or EULUMDAT by content, or a `.ies`/`.ldt` name (so a damaged
    /// luminaire file gets the luminaire parser's error, not an image decoder's).
    Light,
    /// Anything else: a panorama, a cube face, a folder.
    Other,
}

/// How much of a file is read to judge it.
const HEAD_BYTES: u64 = 64 << 10;

/// The kind of the file at `path`: by its first 64 KiB; a file that cannot be read, or is
/// not a regular file (a FIFO would block the window on open, a device might never end),
/// is judged by its extension (the loader then reports why it cannot be read).
pub fn file_kind(path: &Path) -> FileKind {
    let by_name = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ies") || e.eq_ignore_ascii_case("ldt"));
    let mut head = Vec::new();
    // The one check for every input path: regular files only, never blocking.
    let read = lut_core::open_regular(path)
        .and_then(|f| f.take(HEAD_BYTES).read_to_end(&mut head))
        .is_ok();
    if read {
        let text = String::from_utf8_lossy(&head);
        if is_scene(&text) {
            return FileKind::Scene;
        }
        if lut_core::detect_format(&text).is_some() {
            return FileKind::Light;
        }
    }
    if by_name {
        FileKind::Light
    } else {
        FileKind::Other
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn data(p: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(p)
    }

    /// A FIFO is judged by its name without being opened: opening it for reading would
    /// block until a writer comes (the window froze on a dropped FIFO in the soak).
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_not_opened() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe.ies");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        let (tx, rx) = std::sync::mpsc::channel();
        let p = fifo.clone();
        std::thread::spawn(move || tx.send(file_kind(&p)).unwrap());
        let kind = rx.recv_timeout(std::time::Duration::from_secs(10));
        assert_eq!(
            kind,
            Ok(FileKind::Light),
            "file_kind blocked on a FIFO or misjudged it"
        );
    }

    #[test]
    fn routed_by_content() {
        let dir = tempfile::tempdir().unwrap();
        // An EULUMDAT file under a name that says nothing.
        let ldt = dir.path().join("lamp.txt");
        std::fs::copy(data("tests/data/ldt/wallwasher_c0_c180.ldt"), &ldt).unwrap();
        assert_eq!(file_kind(&ldt), FileKind::Light);
        let ies = dir.path().join("lamp.dat");
        std::fs::copy(data("tests/data/ies/label_lines.ies"), &ies).unwrap();
        assert_eq!(file_kind(&ies), FileKind::Light);
        assert_eq!(
            file_kind(&data("assets/interior_lit.json")),
            FileKind::Scene
        );
        assert_eq!(file_kind(&data("assets/interior.jpg")), FileKind::Other);
        // A JPEG named .ldt is still offered to the luminaire parser (its error names
        // the file and line); a folder and a missing file by name.
        let fake = dir.path().join("photo.ldt");
        std::fs::copy(data("assets/interior.jpg"), &fake).unwrap();
        assert_eq!(file_kind(&fake), FileKind::Light);
        assert_eq!(file_kind(dir.path()), FileKind::Other);
        assert_eq!(file_kind(Path::new("missing.IES")), FileKind::Light);
        assert_eq!(file_kind(Path::new("missing.jpg")), FileKind::Other);
    }
}

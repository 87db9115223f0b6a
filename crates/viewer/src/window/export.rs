//! Pure helpers for the window's HDR exposure control and "Save view…" export: which
//! files get the exposure slider, the exposure steps, the export size and the file name.
//! Unit-tested without a display.

use super::input::EXPOSURE_RANGE_EV;
use std::path::{Path, PathBuf};

/// Longest side of an exported image, pixels (a 4x export of a huge window stays sane).
pub const EXPORT_MAX_SIDE: u32 = 16384;

/// True for files decoded as floating-point images (Radiance `.hdr`, OpenEXR `.exr`),
/// which are shown through an exposure; 8-bit images ignore it.
pub fn is_hdr_path(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("hdr") || e.eq_ignore_ascii_case("exr"))
}

/// `ev` moved by `delta` stops, held within [`EXPOSURE_RANGE_EV`] (a non-finite result
/// stays at `ev`).
pub fn step_exposure(ev: f64, delta: f64) -> f64 {
    let n = ev + delta;
    if n.is_finite() {
        n.clamp(EXPOSURE_RANGE_EV.0, EXPOSURE_RANGE_EV.1)
    } else {
        ev
    }
}

/// Size of an export of a `scene`-sized view at `scale`: each side times the scale, at
/// least 1 and at most [`EXPORT_MAX_SIDE`] (both sides shrink together, keeping the
/// aspect ratio, when the longer one would exceed it).
pub fn export_size(scene: (u32, u32), scale: u32) -> (u32, u32) {
    let s = u64::from(scale.max(1));
    let (w, h) = (u64::from(scene.0.max(1)) * s, u64::from(scene.1.max(1)) * s);
    let max = u64::from(EXPORT_MAX_SIDE);
    let long = w.max(h);
    let (w, h) = if long > max {
        ((w * max / long).max(1), (h * max / long).max(1))
    } else {
        (w, h)
    };
    (w as u32, h as u32)
}

/// The first `view-N.png` (N = 1, 2, …) in `dir` for which `exists` is false.
pub fn next_view_path(dir: &Path, exists: impl Fn(&Path) -> bool) -> PathBuf {
    (1u64..)
        .map(|n| dir.join(format!("view-{n}.png")))
        .find(|p| !exists(p))
        .unwrap_or_else(|| dir.join("view.png"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hdr_by_extension() {
        assert!(is_hdr_path(Path::new("a/b.hdr")));
        assert!(is_hdr_path(Path::new("B.EXR")));
        assert!(!is_hdr_path(Path::new("pano.jpg")));
        assert!(!is_hdr_path(Path::new("pano.png")));
        assert!(!is_hdr_path(Path::new("hdr")));
    }

    #[test]
    fn exposure_steps_clamp() {
        assert_eq!(step_exposure(0.0, 0.5), 0.5);
        assert_eq!(step_exposure(0.0, -0.5), -0.5);
        assert_eq!(step_exposure(7.8, 0.5), 8.0);
        assert_eq!(step_exposure(-7.8, -0.5), -8.0);
        assert_eq!(step_exposure(1.0, f64::NAN), 1.0);
    }

    #[test]
    fn export_sizes() {
        assert_eq!(export_size((800, 600), 1), (800, 600));
        assert_eq!(export_size((800, 600), 2), (1600, 1200));
        assert_eq!(export_size((800, 600), 4), (3200, 2400));
        assert_eq!(export_size((0, 0), 0), (1, 1));
        // Capped at EXPORT_MAX_SIDE, aspect ratio kept.
        assert_eq!(export_size((8000, 4000), 4), (16384, 8192));
    }

    #[test]
    fn view_paths_skip_existing() {
        let dir = Path::new("out");
        assert_eq!(next_view_path(dir, |_| false), dir.join("view-1.png"));
        let taken = [dir.join("view-1.png"), dir.join("view-2.png")];
        assert_eq!(
            next_view_path(dir, |p| taken.iter().any(|t| t == p)),
            dir.join("view-3.png")
        );
    }
}

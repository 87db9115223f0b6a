//! The panoramas next to the current one: PageUp / PageDown open the previous / next
//! image in the same folder, in natural order (`pano2` before `pano10`, case ignored),
//! wrapping around at the ends. Only files the loader decodes count
//! ([`PANORAMA_EXTENSIONS`]).

use std::cmp::Ordering;
use std::path::{Path, PathBuf};

/// Extensions of the image formats the loader decodes (the `image` crate's features in
/// the workspace: JPEG, PNG, Radiance HDR, OpenEXR), lower case. A test decodes one file
/// of each through the loader.
pub const PANORAMA_EXTENSIONS: &[&str] = &["jpg", "jpeg", "png", "hdr", "exr"];

/// True when `path`'s extension is one the loader decodes (any case).
pub fn is_panorama_file(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        PANORAMA_EXTENSIONS
            .iter()
            .any(|x| x.eq_ignore_ascii_case(e))
    })
}

/// Natural order of file names: digit runs compare as numbers, letters ignore case; names
/// equal that way fall back to plain order, so the order is total.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    alphanumeric_sort::compare_str(a.to_lowercase(), b.to_lowercase()).then_with(|| a.cmp(b))
}

fn name_of(p: &Path) -> String {
    p.file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned())
}

/// Sort paths by file name in natural order.
pub fn sort_natural(paths: &mut [PathBuf]) {
    paths.sort_by(|a, b| natural_cmp(&name_of(a), &name_of(b)));
}

/// The panorama files in `dir` (not folders, not other files), in natural order.
///
/// # Errors
/// The folder cannot be read.
pub fn panoramas_in(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if is_panorama_file(&path) && path.is_file() {
            files.push(path);
        }
    }
    sort_natural(&mut files);
    Ok(files)
}

/// Which way to step through a folder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// PageUp.
    Previous,
    /// PageDown.
    Next,
}

/// The file `step` away from `current` among `sorted` (natural order), wrapping around;
/// when `current` is not among them (deleted, or not a panorama) the neighbour of its
/// place in the order. `None` when there is no other file.
pub fn neighbour(sorted: &[PathBuf], current: &Path, step: Step) -> Option<PathBuf> {
    let others: Vec<&PathBuf> = sorted.iter().filter(|p| p.as_path() != current).collect();
    if others.is_empty() {
        return None;
    }
    let name = name_of(current);
    // Files before `current` in the order.
    let before = others
        .iter()
        .take_while(|p| natural_cmp(&name_of(p), &name) == Ordering::Less)
        .count();
    let n = others.len();
    let i = match step {
        Step::Next => before % n,
        Step::Previous => (before + n - 1) % n,
    };
    Some(others[i].clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paths(names: &[&str]) -> Vec<PathBuf> {
        names.iter().map(|n| PathBuf::from("/d").join(n)).collect()
    }

    #[test]
    fn natural_order_numbers_and_case() {
        let mut v = paths(&["pano10.jpg", "Pano2.jpg", "pano1.jpg", "b.png", "A.exr"]);
        sort_natural(&mut v);
        let names: Vec<String> = v.iter().map(|p| name_of(p)).collect();
        assert_eq!(
            names,
            ["A.exr", "b.png", "pano1.jpg", "Pano2.jpg", "pano10.jpg"]
        );
        // Total: names equal but for case keep a fixed order.
        assert_eq!(natural_cmp("a.jpg", "A.jpg"), Ordering::Greater);
        assert_eq!(natural_cmp("a.jpg", "a.jpg"), Ordering::Equal);
    }

    #[test]
    fn next_and_previous_wrap_around() {
        let v = paths(&["a1.jpg", "a2.jpg", "a10.jpg"]);
        let at = |n: &str| PathBuf::from("/d").join(n);
        assert_eq!(neighbour(&v, &at("a1.jpg"), Step::Next), Some(at("a2.jpg")));
        assert_eq!(
            neighbour(&v, &at("a2.jpg"), Step::Next),
            Some(at("a10.jpg"))
        );
        assert_eq!(
            neighbour(&v, &at("a10.jpg"), Step::Next),
            Some(at("a1.jpg"))
        );
        assert_eq!(
            neighbour(&v, &at("a1.jpg"), Step::Previous),
            Some(at("a10.jpg"))
        );
        assert_eq!(
            neighbour(&v, &at("a10.jpg"), Step::Previous),
            Some(at("a2.jpg"))
        );
        // The current file gone from the folder: its place in the order counts.
        assert_eq!(
            neighbour(&v, &at("a5.jpg"), Step::Next),
            Some(at("a10.jpg"))
        );
        assert_eq!(
            neighbour(&v, &at("a5.jpg"), Step::Previous),
            Some(at("a2.jpg"))
        );
        // Alone in the folder: nowhere to go.
        assert_eq!(neighbour(&v[..1], &at("a1.jpg"), Step::Next), None);
        assert_eq!(neighbour(&[], &at("a1.jpg"), Step::Next), None);
    }

    #[test]
    fn a_folder_lists_only_panorama_files_in_natural_order() {
        let tmp = tempfile::tempdir().unwrap();
        for n in [
            "p10.jpg",
            "p9.JPG",
            "notes.txt",
            "p1.exr",
            "light.ies",
            "q.hdr",
        ] {
            std::fs::write(tmp.path().join(n), b"x").unwrap();
        }
        std::fs::create_dir(tmp.path().join("sub.jpg")).unwrap();
        let names: Vec<String> = panoramas_in(tmp.path())
            .unwrap()
            .iter()
            .map(|p| name_of(p))
            .collect();
        assert_eq!(names, ["p1.exr", "p9.JPG", "p10.jpg", "q.hdr"]);
        assert!(panoramas_in(&tmp.path().join("missing")).is_err());
    }

    /// Every listed extension is one the loader decodes (a tiny file of each format).
    #[test]
    fn every_listed_extension_loads() {
        use image::{DynamicImage, ImageFormat};
        let tmp = tempfile::tempdir().unwrap();
        let rgb = DynamicImage::ImageRgb8(image::RgbImage::from_pixel(8, 4, image::Rgb([9; 3])));
        let float =
            DynamicImage::ImageRgb32F(image::Rgb32FImage::from_pixel(8, 4, image::Rgb([0.5; 3])));
        for ext in PANORAMA_EXTENSIONS {
            let p = tmp.path().join(format!("pano.{ext}"));
            let format = ImageFormat::from_extension(ext).expect("a known extension");
            let img = if matches!(format, ImageFormat::Hdr | ImageFormat::OpenExr) {
                &float
            } else {
                &rgb
            };
            img.save_with_format(&p, format).unwrap();
            let map = lut_core::load_map(&p, &lut_core::LoadOptions::default(), &mut |_| {});
            assert!(map.is_ok(), "{ext}: {:?}", map.err());
            assert!(is_panorama_file(&p));
        }
        assert!(!is_panorama_file(Path::new("a.ies")));
        assert!(!is_panorama_file(Path::new("jpg")));
    }
}

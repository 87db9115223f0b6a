//! Golden images: a rendered image compared with its stored truth in `tests/truth/`.
//!
//! Identical bytes are required. `REGENERATE=1` rewrites the truth after an intended
//! change; a missing truth is an error (never created silently), so a test cannot pass by
//! writing its own answer. On a mismatch the actual image and a difference image go to
//! `target/golden-out/<name>-{actual,diff}.png`.
//!
//! A truth only catches regressions: every golden test also checks its image against an
//! independent path (the exact renderer, or an analytic expectation) with a stated
//! tolerance, so a truth is never just re-blessed.

use crate::pixels::to_rgb;
use crate::repo_root;
use std::path::PathBuf;

/// The stored truth of `name`.
pub fn truth_path(name: &str) -> PathBuf {
    repo_root().join("tests/truth").join(format!("{name}.png"))
}

/// True when the run asks to rewrite truths (`REGENERATE` set).
pub fn regenerating() -> bool {
    std::env::var_os("REGENERATE").is_some()
}

/// Compare the 0RGB image `px` (`w × h`) with the truth `name`, or rewrite the truth when
/// [`regenerating`].
///
/// # Panics
/// When the truth is missing or unreadable (it says how to create it), differs in size,
/// or differs in any pixel (after writing the actual and difference images).
pub fn compare_to_truth(name: &str, px: &[u32], w: u32, h: u32) {
    let path = truth_path(name);
    let img = to_rgb(px, w, h);
    if regenerating() {
        img.save(&path)
            .unwrap_or_else(|e| panic!("{}: cannot write: {e}", path.display()));
        return;
    }
    let truth = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "{}: {e} (a missing truth is an error: run with REGENERATE=1 to create it, \
                 after checking the image against an independent path)",
                path.display()
            )
        })
        .to_rgb8();
    assert_eq!(truth.dimensions(), (w, h), "{name}: size changed");
    let mut worst = 0u8;
    let mut count = 0usize;
    let mut diff = image::RgbImage::new(w, h);
    for ((a, b), d) in img.pixels().zip(truth.pixels()).zip(diff.pixels_mut()) {
        let m = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap_or(0);
        if m > 0 {
            count += 1;
        }
        worst = worst.max(m);
        *d = image::Rgb([m, m, m]);
    }
    if count > 0 {
        let out = repo_root().join("target/golden-out");
        std::fs::create_dir_all(&out).expect("create target/golden-out");
        img.save(out.join(format!("{name}-actual.png")))
            .expect("write the actual image");
        diff.save(out.join(format!("{name}-diff.png")))
            .expect("write the difference image");
        panic!("{name}: {count} pixels differ from the truth, worst by {worst}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_truth_is_an_error_not_a_new_truth() {
        if regenerating() {
            return;
        }
        let name = "test-support-does-not-exist";
        let r = std::panic::catch_unwind(|| compare_to_truth(name, &[0], 1, 1));
        assert!(r.is_err());
        assert!(!truth_path(name).exists(), "the missing truth was created");
    }

    #[test]
    fn a_stored_truth_matches_itself_and_not_a_changed_image() {
        if regenerating() {
            return;
        }
        // A 1x1 truth of the golden suite: its own pixel matches, another does not.
        let name = "equirect_bilinear_tiny";
        let img = image::open(truth_path(name)).unwrap().to_rgb8();
        let p = img.get_pixel(0, 0);
        let px = (u32::from(p[0]) << 16) | (u32::from(p[1]) << 8) | u32::from(p[2]);
        compare_to_truth(name, &[px], 1, 1);
        let r = std::panic::catch_unwind(|| compare_to_truth(name, &[px ^ 0x010000], 1, 1));
        assert!(r.is_err());
    }
}

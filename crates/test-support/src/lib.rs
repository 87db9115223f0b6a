//! What every lutpano test binary shares: golden-image comparison against stored truths
//! ([`golden`]), pixel statistics ([`pixels`]: PSNR, per-channel differences), a counting
//! global allocator ([`alloc`]), header-only decompression bombs ([`bombs`]) and frames
//! rendered into new buffers ([`render`]), geometry computed independently of the
//! library ([`geometry`]), synthetic photometric files and sphere directions for the
//! light tests ([`light_fixtures`]), and small OpenEXR files of every compression
//! ([`exr_files`]).
//!
//! A dev-dependency of `lut-core` and `viewer`; never published.

pub mod alloc;
pub mod bombs;
pub mod exr_files;
pub mod geometry;
pub mod golden;
pub mod light_fixtures;
pub mod pixels;
pub mod render;

use std::path::PathBuf;

/// The workspace root (tests read `tests/truth`, `tests/data` and the sample assets from
/// it).
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A file of the committed test data, `tests/data/<rel>`.
pub fn test_data(rel: &str) -> PathBuf {
    repo_root().join("tests/data").join(rel)
}

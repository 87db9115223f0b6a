//! What every lutpano test binary shares: golden-image comparison against stored truths
//! ([`golden`]), pixel statistics ([`pixels`]: PSNR, per-channel differences), a counting
//! global allocator ([`alloc`]) and header-only decompression bombs ([`bombs`]).
//!
//! A dev-dependency of `lut-core` and `viewer`; never published.

pub mod alloc;
pub mod bombs;
pub mod golden;
pub mod pixels;

use std::path::PathBuf;

/// The workspace root (tests read `tests/truth`, `tests/data` and the sample assets from
/// it).
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

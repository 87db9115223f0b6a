//! The bundled sample panorama, embedded in the binary so it works from any directory.

/// `assets/courtyard.jpg`: CC0, Greg Zaal (HDRI Haven / Poly Haven); see `assets/README.md`.
pub const SAMPLE_JPEG: &[u8] = include_bytes!("../../../assets/courtyard.jpg");
/// Name used in messages.
pub const SAMPLE_NAME: &str = "bundled sample (assets/courtyard.jpg)";

//! What the fuzz targets share: how the photometric parsers read bytes, the check that
//! their messages are safe for a terminal, and map decoding through lut-core's loader
//! with a small pixel limit.

use image::ImageFormat;
use lut_core::{EnvMap, LoadOptions, Projection};

/// The pixel limit of the map targets (2^18): small, so a header claiming a huge image is
/// refused at once and the fuzzer spends its time in the decoders.
pub const MAX_PIXELS: u64 = 1 << 18;

/// As the library reads photometric files: UTF-8 when valid, else ISO-8859-1.
pub fn text(data: &[u8]) -> String {
    match std::str::from_utf8(data) {
        Ok(s) => s.to_string(),
        Err(_) => data.iter().map(|&b| char::from(b)).collect(),
    }
}

/// A message quoting a file's bytes must carry no control character (escape sequences,
/// line breaks) to the terminal.
pub fn assert_safe(msg: &str) {
    assert!(
        !msg.chars().any(char::is_control),
        "raw control character in {msg:?}"
    );
}

/// The loader's options of the map targets: any aspect ratio (elliptical), the small
/// pixel limit.
pub fn map_options() -> LoadOptions {
    LoadOptions {
        projection: Some(Projection::Elliptical),
        max_pixels: MAX_PIXELS,
        ..LoadOptions::default()
    }
}

/// Decodes `data` as a map through lut-core's loader when `image` takes it for `format`
/// (the other inputs are skipped: each target stays in its own decoder). A map that loads
/// must have a size inside the limit. Returns whether the input was of `format`.
pub fn fuzz_map(data: &[u8], format: ImageFormat) -> bool {
    if image::guess_format(data).ok() != Some(format) {
        return false;
    }
    if let Ok(m) = lut_core::decode_map(data, "fuzz", &map_options(), &mut |_| {}) {
        check_map(&m);
    }
    true
}

fn check_map(m: &EnvMap) {
    assert!(m.width() >= 1 && m.height() >= 1);
    assert!(u64::from(m.width()) * u64::from(m.height()) <= MAX_PIXELS);
}

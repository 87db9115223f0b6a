//! Maps from EXR bytes through lut-core's loader with a small pixel limit (2^18), any
//! aspect ratio (elliptical projection).
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::{LoadOptions, Projection};

fuzz_target!(|data: &[u8]| {
    if image::guess_format(data).ok() != Some(image::ImageFormat::OpenExr) {
        return;
    }
    let opts = LoadOptions {
        projection: Some(Projection::Elliptical),
        max_pixels: 1 << 18,
        ..LoadOptions::default()
    };
    if let Ok(m) = lut_core::decode_map(data, "fuzz", &opts, &mut |_| {}) {
        assert!(m.width() >= 1 && m.height() >= 1);
        assert!(u64::from(m.width()) * u64::from(m.height()) <= 1 << 18);
    }
});

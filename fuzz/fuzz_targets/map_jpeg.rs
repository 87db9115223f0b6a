//! Maps from JPEG bytes through lut-core's loader with a small pixel limit (2^18), any
//! aspect ratio (elliptical projection), and as a possibly partial panorama (GPano XMP).
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::{LoadOptions, Projection};

fuzz_target!(|data: &[u8]| {
    if image::guess_format(data).ok() != Some(image::ImageFormat::Jpeg) {
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
    let auto = LoadOptions {
        projection: None,
        ..opts
    };
    let _ = lut_core::decode_partial(data, "fuzz", &auto, None, &mut |_| {});
});

//! Maps from JPEG bytes through lut-core's loader with a small pixel limit, any aspect
//! ratio (elliptical projection), and as a possibly partial panorama (GPano XMP).
#![no_main]
use libfuzzer_sys::fuzz_target;
use lutpano_fuzz::{fuzz_map, map_options};

fuzz_target!(|data: &[u8]| {
    if fuzz_map(data, image::ImageFormat::Jpeg) {
        let auto = lut_core::LoadOptions {
            projection: None,
            ..map_options()
        };
        let _ = lut_core::decode_partial(data, "fuzz", &auto, None, &mut |_| {});
    }
});

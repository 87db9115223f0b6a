//! Maps from HDR bytes through lut-core's loader with a small pixel limit, any aspect
//! ratio (elliptical projection).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    lutpano_fuzz::fuzz_map(data, image::ImageFormat::Hdr);
});

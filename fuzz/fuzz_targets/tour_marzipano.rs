//! Marzipano tool exports (`tour::parse` of a `data.js`: the `APP_DATA` literal reader,
//! radians and downward pitch converted, tile levels, the limits of `lut_core::limits`).
//! No file the tour names is opened.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use viewer::tour;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("tour/data.js");
    lutpano_fuzz::check_tour(tour::parse(data, path), path, true);
});

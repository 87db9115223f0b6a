//! Pannellum tour and single-scene configs (`tour::parse` of a `.json`: the JSON literal
//! reader with line numbers, scenes and hotspots each left out with a problem, the limits
//! of `lut_core::limits`). No file the tour names is opened.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use viewer::tour;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("tour/tour.json");
    lutpano_fuzz::check_tour(tour::parse(data, path), path, false);
});

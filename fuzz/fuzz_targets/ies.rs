//! IES LM-63 files: the parser and the photometric model built from it. Error messages
//! must quote the file's bytes safely (no control character reaches a terminal). (The
//! light table built from a file is fuzzed by `light_table`, which is slower.)
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::{IesFile, Photometry};
use lutpano_fuzz::{assert_safe, text};

fuzz_target!(|data: &[u8]| {
    match IesFile::parse(&text(data), "fuzz.ies") {
        Err(e) => assert_safe(&e.to_string()),
        Ok(ies) => match Photometry::from_ies(&ies) {
            Err(e) => assert_safe(&e.to_string()),
            Ok(p) => {
                let _ = p.max_candela();
            }
        },
    }
});

//! IES LM-63 files: the parser and the photometric model built from it. Error messages
//! must quote the file's bytes safely (no control character reaches a terminal). (The
//! light table built from a file is fuzzed by `light_table`, which is slower.)
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::{IesFile, Photometry};

/// As the library reads files: UTF-8 when valid, else ISO-8859-1.
fn text(data: &[u8]) -> String {
    match std::str::from_utf8(data) {
        Ok(s) => s.to_string(),
        Err(_) => data.iter().map(|&b| char::from(b)).collect(),
    }
}

fn safe(msg: &str) {
    assert!(!msg.chars().any(char::is_control), "raw control character in {msg:?}");
}

fuzz_target!(|data: &[u8]| {
    match IesFile::parse(&text(data), "fuzz.ies") {
        Err(e) => safe(&e.to_string()),
        Ok(ies) => match Photometry::from_ies(&ies) {
            Err(e) => safe(&e.to_string()),
            Ok(p) => {
                let _ = p.max_candela();
            }
        },
    }
});

//! EULUMDAT (.ldt) files: the parser, the photometric model built from it, and the
//! format detection by content. Error messages must quote the file's bytes safely. (The
//! light table is fuzzed by `light_table`.)
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::{detect_format, LdtFile, Photometry};
use lutpano_fuzz::{assert_safe, text};

fuzz_target!(|data: &[u8]| {
    let t = text(data);
    let _ = detect_format(&t);
    match LdtFile::parse(&t, "fuzz.ldt") {
        Err(e) => assert_safe(&e.to_string()),
        Ok(ldt) => {
            let p = Photometry::from_ldt(&ldt);
            let _ = p.max_candela();
        }
    }
});

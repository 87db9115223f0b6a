//! `--light FILE@X,Y,Z[:YAW,PITCH]` (the viewer's parser; no file is opened).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(s) = std::str::from_utf8(data) else {
        return;
    };
    match viewer::lighting::parse_light(s) {
        Ok(spec) => {
            assert!(!spec.file.as_os_str().is_empty());
            assert!(spec.position.iter().all(|v| v.is_finite()));
            assert!(spec.aim.0.is_finite() && spec.aim.1.is_finite());
        }
        Err(e) => assert!(!e.is_empty()),
    }
});

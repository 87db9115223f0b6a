//! Scene files (`SceneFile::parse`: UTF-8, JSON behind the containment, the limits
//! module's checks, format, version, view). No file named inside is opened.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use viewer::lighting::SceneFile;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.json");
    match SceneFile::parse(data, path) {
        Ok(scene) => {
            // Within every limit, the view in range.
            scene.check_limits().expect("parse checks the limits");
            assert!(scene.lights.len() <= lut_core::limits::MAX_LIGHTS);
            if let Some(v) = scene.view {
                assert!(v.hfov > 0.0 && v.hfov <= 360.0 && v.yaw.is_finite());
                assert!((-90.0..=90.0).contains(&v.pitch));
            }
            // What it writes reads back the same.
            let text = serde_json::to_string(&scene).expect("a scene serializes");
            let again = SceneFile::parse(text.as_bytes(), path).expect("its own output parses");
            assert_eq!(again, scene);
        }
        Err(e) => {
            // The message as the viewer prints it: one line, no control character.
            let line = lut_core::one_line(&format!("{e:#}"));
            lutpano_fuzz::assert_safe(&line);
            assert!(line.chars().count() <= lut_core::MESSAGE_MAX_CHARS + 40);
        }
    }
});

//! The window's settings file (`Prefs::parse`: field by field, unknown fields kept).
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use viewer::window::prefs::Prefs;

fuzz_target!(|data: &[u8]| {
    let path = Path::new("settings.json");
    let (prefs, problems) = Prefs::parse(data, path);
    // Every value in range whatever the file held.
    assert!(prefs.recent.len() <= viewer::window::prefs::MAX_RECENT);
    assert!(prefs.zoom_limit.is_none_or(|z| z.is_finite() && z > 0.0));
    assert!(prefs.auto_rotate_speed.is_finite() && prefs.auto_rotate_idle_s.is_finite());
    for p in &problems {
        lutpano_fuzz::assert_safe(&lut_core::one_line(p));
    }
    // What is written back reads back the same, unknown fields included, with no problem.
    let text = prefs.to_json().expect("settings serialize");
    let (again, problems) = Prefs::parse(text.as_bytes(), path);
    assert!(problems.is_empty(), "{problems:?} in {text}");
    assert_eq!(again, prefs);
});

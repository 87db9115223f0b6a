//! The scene-file and settings parsers fed mutated copies of their fuzz seeds (issue 32),
//! with the fuzz targets' assertions (`fuzz/fuzz_targets/scene_file.rs`, `settings.rs`).
//! Not coverage-guided like the libFuzzer targets (scripts/fuzz.sh), but it runs on the
//! stable toolchain in the suite: random byte flips, insertions, deletions and JSON
//! fragments spliced in, a fixed number of cases.

use proptest::prelude::*;
use std::path::Path;
use viewer::lighting::SceneFile;
use viewer::window::prefs::{Prefs, MAX_RECENT};

fn seeds(target: &str) -> Vec<Vec<u8>> {
    let dir = test_support::repo_root().join("fuzz/seeds").join(target);
    let mut v: Vec<Vec<u8>> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| std::fs::read(e.unwrap().path()).unwrap())
        .collect();
    v.sort();
    assert!(!v.is_empty(), "{}", dir.display());
    v
}

/// JSON fragments that reach the parsers' corners: extremes, wrong types, escapes.
const FRAGMENTS: &[&str] = &[
    "1e308",
    "-1e308",
    "1e-320",
    "NaN",
    "null",
    "true",
    "\"\\u001b]0;t\\u0007\"",
    "[]",
    "{}",
    "99999999999999999999",
    "-0",
    "\"x\"",
    ",",
    ":",
    "\"lights\": [",
    "\"zoom_limit\": ",
    "\"\\ud800\"",
    "10000",
];

#[derive(Debug, Clone)]
enum Edit {
    Flip(usize, u8),
    Insert(usize, usize),
    Delete(usize, usize),
}

fn edits() -> impl Strategy<Value = Vec<Edit>> {
    prop::collection::vec(
        prop_oneof![
            (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Flip(i, b)),
            (any::<usize>(), 0..FRAGMENTS.len()).prop_map(|(i, f)| Edit::Insert(i, f)),
            (any::<usize>(), 1usize..16).prop_map(|(i, n)| Edit::Delete(i, n)),
        ],
        1..6,
    )
}

fn mutate(seed: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut v = seed.to_vec();
    for e in edits {
        let at = |i: usize, len: usize| if len == 0 { 0 } else { i % (len + 1) };
        match *e {
            Edit::Flip(i, b) if !v.is_empty() => {
                let k = i % v.len();
                v[k] ^= b;
            }
            Edit::Flip(..) => {}
            Edit::Insert(i, f) => {
                let k = at(i, v.len());
                v.splice(k..k, FRAGMENTS[f].bytes());
            }
            Edit::Delete(i, n) => {
                let k = at(i, v.len());
                let end = (k + n).min(v.len());
                v.drain(k..end);
            }
        }
    }
    v
}

fn safe(msg: &str) {
    let line = lut_core::one_line(msg);
    assert!(!line.chars().any(char::is_control), "{line:?}");
    assert!(line.chars().count() <= lut_core::MESSAGE_MAX_CHARS + 40);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_scene_files(pick in any::<usize>(), e in edits()) {
        let all = seeds("scene_file");
        let data = mutate(&all[pick % all.len()], &e);
        let path = Path::new("fuzz.json");
        match SceneFile::parse(&data, path) {
            Ok(scene) => {
                scene.check_limits().unwrap();
                prop_assert!(scene.lights.len() <= lut_core::limits::MAX_LIGHTS);
                if let Some(v) = scene.view {
                    prop_assert!(v.hfov > 0.0 && v.hfov <= 360.0 && v.yaw.is_finite());
                }
                let text = serde_json::to_string(&scene).unwrap();
                let again = SceneFile::parse(text.as_bytes(), path).unwrap();
                prop_assert_eq!(again, scene);
            }
            Err(err) => safe(&format!("{err:#}")),
        }
    }

    #[test]
    fn mutated_settings(pick in any::<usize>(), e in edits()) {
        let all = seeds("settings");
        let data = mutate(&all[pick % all.len()], &e);
        let path = Path::new("settings.json");
        let (prefs, problems) = Prefs::parse(&data, path);
        prop_assert!(prefs.recent.len() <= MAX_RECENT);
        prop_assert!(prefs.zoom_limit.is_none_or(|z| z.is_finite() && z > 0.0));
        for p in &problems {
            safe(p);
        }
        let text = prefs.to_json().unwrap();
        let (again, problems) = Prefs::parse(text.as_bytes(), path);
        prop_assert!(problems.is_empty(), "{:?} in {}", problems, text);
        prop_assert_eq!(again, prefs);
    }
}

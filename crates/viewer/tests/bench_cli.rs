//! `viewer bench --json` end to end on a small generated map: every configuration gets
//! its timings when the configurations take turns pass by pass, and `--only-default`
//! (what `scripts/peers.py --rounds` runs between its rounds of OpenCV) measures the
//! LUT's default nearest and bilinear alone, on the hfov-90 set.

mod common;
use common::viewer;

fn rows(args: &[&str]) -> Vec<serde_json::Value> {
    let mut a = vec![
        "bench",
        "--json",
        "--map-size",
        "256x128",
        "--size",
        "64x36",
    ];
    a.extend_from_slice(args);
    let o = viewer(&a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("a JSON array")
}

fn key(r: &serde_json::Value) -> String {
    format!(
        "{} {} {} {}",
        r["renderer"], r["sampler"], r["index_step"], r["hfov"]
    )
}

#[test]
fn every_configuration_is_timed_when_the_passes_take_turns() {
    let all = rows(&["--passes", "2", "--no-minify"]);
    assert!(all.len() > 20, "{} rows", all.len());
    for r in &all {
        let (med, min) = (r["ms_median"].as_f64(), r["ms_min"].as_f64());
        assert!(
            matches!((med, min), (Some(m), Some(n)) if m > 0.0 && n > 0.0 && n <= m),
            "{}: {med:?} {min:?}",
            key(r)
        );
    }
    assert!(all.iter().any(|r| r["renderer"] == "cube-scanline"));
}

#[test]
fn only_default_measures_the_luts_default_nearest_and_bilinear() {
    let only = rows(&["--passes", "1", "--only-default"]);
    let keys: Vec<String> = only.iter().map(key).collect();
    assert_eq!(
        keys,
        [
            r#""lut" "nearest" "adaptive" 90.0"#,
            r#""lut" "bilinear" "adaptive" 90.0"#
        ],
        "{only:?}"
    );
    assert!(only
        .iter()
        .all(|r| r["lut"] == "wide" && r["ms_median"].as_f64() > Some(0.0)));
    let o = viewer(&["bench", "--only-default", "--plot", "/tmp/x.png"]);
    assert!(!o.status.success(), "--only-default with --plot");
}

#[test]
fn given_views_are_timed_alone_and_every_row_carries_its_view() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("export");
    let d = dir.to_str().unwrap();
    let all = rows(&[
        "--passes",
        "1",
        "--no-cube",
        "--view",
        "30,90,90",
        "--view",
        "0,-45,150",
        "--export-maps",
        d,
    ]);
    let views: Vec<&serde_json::Value> = all.iter().map(|r| &r["view"]).collect();
    let zenith = serde_json::json!([30.0, 90.0, 90.0]);
    let wide = serde_json::json!([0.0, -45.0, 150.0]);
    // One set per view, in the order given, each with every configuration; no
    // minification set (every row has a view) and one frame per row.
    let n = all.len() / 2;
    assert!(n > 10 && all.len() == 2 * n, "{} rows", all.len());
    assert!(views[..n].iter().all(|v| **v == zenith), "{views:?}");
    assert!(views[n..].iter().all(|v| **v == wide), "{views:?}");
    assert!(all.iter().all(|r| r["frames"] == 1));
    assert_eq!(all[0]["hfov"], 90.0);
    assert_eq!(all[n]["hfov"], 150.0);
    // The export has exactly the given views, for scripts/peers.py.
    let meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("views.json")).unwrap()).unwrap();
    let ex: Vec<[f64; 3]> = meta["views"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| {
            [
                v["yaw"].as_f64().unwrap(),
                v["pitch"].as_f64().unwrap(),
                v["hfov"].as_f64().unwrap(),
            ]
        })
        .collect();
    assert_eq!(ex, [[30.0, 90.0, 90.0], [0.0, -45.0, 150.0]]);
    assert!(dir.join("mapx_01.f32").exists());

    // Without --view, rows have no view field.
    let only = rows(&["--passes", "1", "--only-default"]);
    assert!(only.iter().all(|r| r.get("view").is_none()), "{only:?}");
    // --only-default keeps the given views.
    let only = rows(&["--passes", "1", "--only-default", "--view", "0,80,90"]);
    assert_eq!(only.len(), 2);
    assert!(only
        .iter()
        .all(|r| r["view"] == serde_json::json!([0.0, 80.0, 90.0])));
}

#[test]
fn a_bad_view_is_a_one_line_error() {
    for bad in ["30,90", "0,95,90", "0,0,abc", "0,0,179.99,1"] {
        let o = viewer(&["bench", "--json", "--view", bad]);
        assert!(!o.status.success(), "--view {bad}");
        assert_eq!(o.status.code(), Some(2), "--view {bad}");
        let err = String::from_utf8_lossy(&o.stderr);
        // One line (clap adds its "For more information" hint to a bad value).
        let lines = err
            .lines()
            .filter(|l| !l.is_empty() && !l.starts_with("For more information"))
            .count();
        assert_eq!(lines, 1, "not one line: {err}");
        assert!(err.contains(bad) && err.contains("view"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(o.stdout.is_empty(), "--view {bad}");
    }
}

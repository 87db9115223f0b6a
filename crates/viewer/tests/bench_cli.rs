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

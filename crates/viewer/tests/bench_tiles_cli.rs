//! `viewer bench-tiles` run tiny: a 2048-wide synthetic pyramid of 64-px tiles generated
//! into the given cache folder and reused, measured in a child process with small frames.
//! Checks the JSON's fields hold what they say (not how fast: timings on a shared machine
//! are not results).

use std::process::Command;

fn bench(cache: &std::path::Path) -> serde_json::Value {
    let out = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .arg("bench-tiles")
        .args(["--widths", "2048", "--tile-size", "64", "--size", "160x90"])
        .args([
            "--frames",
            "6",
            "--cache-mib",
            "64",
            "--threads",
            "2",
            "--json",
        ])
        .arg("--cache")
        .arg(cache)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn bench_tiles_json_on_a_tiny_pyramid() {
    let dir = tempfile::tempdir().unwrap();
    let rows = bench(dir.path());
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 1);
    let r = &rows[0];
    let f = |k: &str| {
        r[k].as_f64()
            .unwrap_or_else(|| panic!("{k} missing or not a number: {r}"))
    };
    // The generator's layout for 2048 wide: face 8·int(2048/π/8) = 648, tiles of 64.
    assert_eq!(f("width"), 2048.0);
    assert_eq!(f("cube"), 648.0);
    assert_eq!(f("tile"), 64.0);
    assert_eq!(f("max_level"), 5.0);
    assert_eq!((f("frame_width"), f("frame_height")), (160.0, 90.0));
    assert_eq!(f("threads"), 2.0);
    // Cold on Linux: the files were dropped from the page cache.
    assert_eq!(r["cold"].as_bool(), Some(cfg!(target_os = "linux")));
    // The first picture comes after the open, and both take time.
    assert!(
        f("open_ms") > 0.0 && f("first_picture_ms") >= f("open_ms"),
        "{r}"
    );
    // The view got sharp (every tile of the view decoded).
    assert!(f("sharp_ms") >= 0.0, "{r}");
    for k in ["pan_resident", "pan_arriving"] {
        let (m, p) = (f(&format!("{k}_ms_median")), f(&format!("{k}_ms_p99")));
        assert!(m > 0.0 && p >= m, "{k}: {r}");
    }
    // Resident tiles: every frame at its level; the arriving pan crossed levels.
    assert_eq!(f("pan_resident_coarser"), 0.0, "{r}");
    let levels = r["pan_arriving_levels"].as_array().unwrap();
    assert!(levels[0].as_u64() < levels[1].as_u64(), "{r}");
    assert!(f("tiles_decoded") >= 6.0, "{r}");
    assert!(f("tiles_per_s_per_thread") > 0.0 && f("mpixel_per_s_per_thread") > 0.0);
    // Mpixel / tiles: at most a 64 × 64 tile each.
    let px_per_tile = f("mpixel_per_s_per_thread") * 1e6 / f("tiles_per_s_per_thread");
    assert!(
        px_per_tile > 0.0 && px_per_tile <= 4096.0 + 1e-6,
        "{px_per_tile}"
    );
    assert!(f("peak_rss_bytes") > f("cache_bytes") && f("cache_bytes") > 0.0);
    assert_eq!(f("cache_budget_bytes"), 64.0 * 1048576.0);
    // The pyramid is reused: its config untouched by a second run.
    let cfg = dir.path().join("synthetic_2048x1024_t64/config.json");
    let before = std::fs::metadata(&cfg).unwrap().modified().unwrap();
    bench(dir.path());
    assert_eq!(std::fs::metadata(&cfg).unwrap().modified().unwrap(), before);

    // --replot: the chart from the JSON; a file that is not that JSON leaves no PNG.
    let json = dir.path().join("run.json");
    std::fs::write(&json, serde_json::to_string(&rows).unwrap()).unwrap();
    let png = dir.path().join("chart.png");
    let replot = |json: &std::path::Path| {
        Command::new(env!("CARGO_BIN_EXE_viewer"))
            .arg("bench-tiles")
            .arg("--replot")
            .arg(json)
            .arg("--plot")
            .arg(&png)
            .output()
            .unwrap()
    };
    let o = replot(&json);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(&png).unwrap();
    assert_eq!((img.width(), img.height()), (1500, 760));
    std::fs::remove_file(&png).unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "[{\"width\": 1}]").unwrap();
    let o = replot(&bad);
    assert_eq!(o.status.code(), Some(1));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("bad.json") && e.trim().lines().count() == 1,
        "{e}"
    );
    assert!(!png.exists());
}

#[test]
fn bench_tiles_refuses_bad_widths() {
    let out = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .args(["bench-tiles", "--widths", "12"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("'12'"));
}

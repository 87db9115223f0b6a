//! `--max-pixels` on the commands that open a panorama: a file over the limit is refused
//! from its header with one line naming the file, its size, the limit and the flag, and
//! a nonzero exit; raising the limit lets it through.

use std::path::PathBuf;
use std::process::Output;

mod common;
use common::{s, viewer};

fn tmpdir(name: &str) -> PathBuf {
    common::tmpdir("viewer-maxpx", name)
}

use test_support::bombs::png_header_only;

fn assert_refused(o: &Output, parts: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "succeeded: {err}");
    assert!(!err.contains("panicked"), "panicked: {err}");
    assert_eq!(err.trim().lines().count(), 1, "not one line: {err}");
    for p in parts {
        assert!(err.contains(p), "'{p}' missing from: {err}");
    }
}

#[test]
fn header_only_bomb_is_refused_by_render() {
    let d = tmpdir("bomb");
    let bomb = d.join("bomb.png");
    std::fs::write(&bomb, png_header_only(100_000, 100_000)).unwrap();
    let out = d.join("out.png");
    let o = viewer(&["render", s(&bomb), "-o", s(&out)]);
    assert_refused(
        &o,
        &["bomb.png", "100000x100000", "536870912", "--max-pixels"],
    );
    assert!(!out.exists());
}

#[test]
fn the_limit_applies_to_render_convert_and_bench() {
    let d = tmpdir("small");
    let pano = d.join("pano.png");
    image::RgbImage::from_pixel(64, 32, image::Rgb([10, 200, 30]))
        .save(&pano)
        .unwrap();
    let out = d.join("out.png");
    let parts = ["pano.png", "64x32", "2048 pixels", "2000", "--max-pixels"];
    for limit in ["2000", "2k", "0.002M"] {
        let o = viewer(&[
            "render",
            s(&pano),
            "-o",
            s(&out),
            "--size",
            "32x16",
            "--max-pixels",
            limit,
        ]);
        assert_refused(&o, &parts);
    }
    assert!(!out.exists());
    let cube = d.join("cube");
    let o = viewer(&[
        "convert",
        s(&pano),
        s(&cube),
        "--to",
        "cube",
        "--max-pixels",
        "2000",
    ]);
    assert_refused(&o, &parts);
    let o = viewer(&["bench", s(&pano), "--max-pixels", "2000"]);
    assert_refused(&o, &parts);
    // At the limit it loads.
    let o = viewer(&[
        "render",
        s(&pano),
        "-o",
        s(&out),
        "--size",
        "32x16",
        "--max-pixels",
        "2048",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists());
    // A bad value is a usage error.
    let o = viewer(&["render", s(&pano), "-o", s(&out), "--max-pixels", "0"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("pixel limit '0'"));
}

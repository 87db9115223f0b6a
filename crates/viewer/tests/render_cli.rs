//! `viewer render` end to end: defaults, options, and every bad input the issue lists
//! (a one-line message naming the value and the reason, a nonzero exit, no panic, no file).

use std::path::{Path, PathBuf};

mod common;
use common::{s, viewer};

fn tmpdir(name: &str) -> PathBuf {
    common::tmpdir("viewer-render-cli", name)
}

/// A bad invocation: exit code nonzero, a message naming `needle`, no panic, no output file.
fn assert_refused(args: &[&str], out: &Path, needle: &str) {
    let o = viewer(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} succeeded");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: message does not name '{needle}': {err}"
    );
    assert!(!out.exists(), "{args:?} left an output file");
    let Ok(dir) = std::fs::read_dir(out.parent().unwrap()) else {
        return; // the output folder does not exist, so nothing can be in it
    };
    let leftovers: Vec<_> = dir
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{args:?} left temporary files");
}

#[test]
fn renders_the_bundled_sample_with_defaults() {
    let d = tmpdir("defaults");
    let out = d.join("view.png");
    let o = viewer(&["render", "-o", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(&out).unwrap();
    assert_eq!((img.width(), img.height()), (1280, 720));
    // The courtyard photo is not a flat colour.
    let rgb = img.to_rgb8();
    let first = rgb.get_pixel(0, 0);
    assert!(rgb.pixels().any(|p| p != first));
}

/// `--still-level`: zoomed out (64 columns at hfov 90 of the 1024-wide sample), the frame
/// comes from a pyramid level, so it differs from the frame of the map; and its
/// neighbouring pixels differ less (the level averages what the map's texels alias).
/// Zoomed in (hfov 60 over 320 columns), the two are the same image.
#[test]
fn still_level_draws_zoomed_out_frames_from_a_level() {
    let d = tmpdir("still-level");
    let render = |name: &str, size: &str, hfov: &str, still: bool| {
        let out = d.join(name);
        let mut args = vec!["render", "-o", s(&out), "--size", size, "--hfov", hfov];
        if still {
            args.push("--still-level");
        }
        let o = viewer(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        image::open(&out).unwrap().to_rgb8()
    };
    // Sum of the differences between horizontal neighbours: aliasing raises it.
    let roughness = |img: &image::RgbImage| -> u64 {
        (0..img.height())
            .flat_map(|y| (1..img.width()).map(move |x| (x, y)))
            .map(|(x, y)| {
                let (p, q) = (img.get_pixel(x - 1, y), img.get_pixel(x, y));
                (0..3).map(|c| u64::from(p[c].abs_diff(q[c]))).sum::<u64>()
            })
            .sum()
    };
    let map = render("map.png", "64x36", "90", false);
    let level = render("level.png", "64x36", "90", true);
    assert!(map != level);
    assert!(
        roughness(&level) < roughness(&map),
        "{} against {}",
        roughness(&level),
        roughness(&map)
    );
    assert!(
        render("in-map.png", "320x180", "60", false)
            == render("in-level.png", "320x180", "60", true)
    );
}

#[test]
fn lut_and_exact_agree_on_the_sample() {
    let d = tmpdir("agree");
    let a = d.join("lut.png");
    let b = d.join("exact.png");
    let common = [
        "--yaw", "-135", "--pitch", "62", "--hfov", "100", "--size", "321x177",
    ];
    let mut args = vec!["render", "-o", s(&a)];
    args.extend_from_slice(&common);
    assert!(viewer(&args).status.success());
    let mut args = vec!["render", "-o", s(&b), "--renderer", "exact"];
    args.extend_from_slice(&common);
    assert!(viewer(&args).status.success());
    let (a, b) = (
        image::open(&a).unwrap().to_rgb8(),
        image::open(&b).unwrap().to_rgb8(),
    );
    let mut worst = 0u8;
    let mut sum = 0u64;
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            let d = p[c].abs_diff(q[c]);
            worst = worst.max(d);
            sum += d as u64;
        }
    }
    let mean = sum as f64 / (a.len() as f64);
    // Photograph, bilinear, 0.05 px position bound: small differences only.
    assert!(worst <= 20 && mean < 0.3, "worst {worst} mean {mean}");
}

#[test]
fn every_option_parses_and_renders() {
    let d = tmpdir("options");
    let out = d.join("o.png");
    for extra in [
        vec!["--sampler", "nearest"],
        vec!["--index-step", "16"],
        vec!["--index-step", "adaptive"],
        vec!["--lut", "high", "--hfov", "40"],
        vec!["--lut", "wide"],
        vec!["--lut-surface", "plane"],
        vec!["--projection", "equirect"],
        vec!["--size", "1x1"],
        vec!["--yaw", "1e9", "--pitch", "-400"],
    ] {
        let mut args = vec!["render", "-o", s(&out)];
        args.extend_from_slice(&extra);
        let o = viewer(&args);
        assert!(
            o.status.success(),
            "{extra:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

#[test]
fn bad_inputs_are_refused_cleanly() {
    let d = tmpdir("bad");
    let out = d.join("never.png");
    let o = s(&out);
    // angles
    assert_refused(&["render", "-o", o, "--yaw", "nan"], &out, "nan");
    assert_refused(&["render", "-o", o, "--pitch", "inf"], &out, "inf");
    assert_refused(&["render", "-o", o, "--hfov", "0"], &out, "hfov");
    assert_refused(&["render", "-o", o, "--hfov", "180"], &out, "180");
    assert_refused(&["render", "-o", o, "--hfov", "-5"], &out, "hfov");
    // sizes
    assert_refused(&["render", "-o", o, "--size", "0x10"], &out, "0x10");
    assert_refused(
        &["render", "-o", o, "--size", "100000x10"],
        &out,
        "100000x10",
    );
    assert_refused(&["render", "-o", o, "--size", "big"], &out, "big");
    // options
    assert_refused(&["render", "-o", o, "--index-step", "3"], &out, "3");
    assert_refused(
        &["render", "-o", o, "--projection", "mercator"],
        &out,
        "mercator",
    );
    // files
    let missing = d.join("missing.jpg");
    assert_refused(&["render", s(&missing), "-o", o], &out, "missing.jpg");
    let corrupt = d.join("corrupt.jpg");
    std::fs::write(&corrupt, b"\xFF\xD8\xFF\xE0 this is not really a jpeg").unwrap();
    assert_refused(&["render", s(&corrupt), "-o", o], &out, "corrupt.jpg");
    let text = d.join("notes.txt");
    std::fs::write(&text, "hello").unwrap();
    assert_refused(&["render", s(&text), "-o", o], &out, "notes.txt");
    let square = d.join("square.png");
    image::RgbImage::new(64, 64).save(&square).unwrap();
    assert_refused(&["render", s(&square), "-o", o], &out, "2:1");
    assert_refused(
        &["render", s(&square), "-o", o, "--projection", "equirect"],
        &out,
        "2:1",
    );
    // output folder that does not exist
    let nowhere = d.join("no/such/dir/out.png");
    assert_refused(&["render", "-o", s(&nowhere)], &nowhere, "does not exist");
}

#[test]
fn non_2to1_maps_render_with_an_explicit_projection() {
    let d = tmpdir("cyl");
    let src = d.join("cyl.png");
    let mut img = image::RgbImage::new(256, 96);
    for (x, y, p) in img.enumerate_pixels_mut() {
        *p = image::Rgb([x as u8, y as u8, 128]);
    }
    img.save(&src).unwrap();
    let out = d.join("o.png");
    for proj in ["cylinder", "sine", "elliptical", "diamond"] {
        let o = viewer(&[
            "render",
            s(&src),
            "-o",
            s(&out),
            "--projection",
            proj,
            "--size",
            "64x48",
            "--pitch",
            "80",
        ]);
        assert!(
            o.status.success(),
            "{proj}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}

/// Issue 33 (10): `viewer render` starts at a file's GPano start view, as the window
/// does: the tagged file renders exactly as the untagged one at those angles given on
/// the command line, and each angle given overrides the file's.
#[test]
fn renders_a_files_gpano_start_view() {
    let d = tmpdir("gpano-start");
    let plain = test_support::repo_root().join("assets/courtyard.jpg");
    let src = std::fs::read(&plain).unwrap();
    let xmp = lut_core::xmp_packet(&[
        ("ProjectionType", "equirectangular"),
        ("InitialViewHeadingDegrees", "120"),
        ("InitialViewPitchDegrees", "10"),
        ("InitialHorizontalFOVDegrees", "60"),
    ]);
    let tagged = d.join("tagged.jpg");
    std::fs::write(&tagged, lut_core::insert_xmp(&src, &xmp).unwrap()).unwrap();
    let render = |name: &str, input: &Path, extra: &[&str]| {
        let out = d.join(name);
        let mut args = vec!["render", s(input), "-o", s(&out), "--size", "320x200"];
        args.extend_from_slice(extra);
        let o = viewer(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        image::open(&out).unwrap().to_rgb8()
    };
    let own = render("own.png", &tagged, &[]);
    let given = render(
        "given.png",
        &plain,
        &["--yaw", "120", "--pitch", "10", "--hfov", "60"],
    );
    let default = render("default.png", &plain, &[]);
    assert!(
        own == given,
        "the file's start view is not the one rendered"
    );
    assert!(own != default, "the start view changes the picture");
    // The command line's yaw wins; the file's pitch and hfov stay.
    let over = render("over.png", &tagged, &["--yaw", "0"]);
    let want = render(
        "over-want.png",
        &plain,
        &["--yaw", "0", "--pitch", "10", "--hfov", "60"],
    );
    assert!(over == want, "--yaw overrides the file's heading only");
}

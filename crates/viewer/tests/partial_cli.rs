//! `viewer render` with partial panoramas: GPano XMP in a JPEG, `--coverage`, bad
//! metadata, `--view-limit`.

use lut_core::{insert_xmp, xmp_packet};
use std::path::{Path, PathBuf};

mod common;
use common::{s, viewer};

fn tmpdir(name: &str) -> PathBuf {
    common::tmpdir("viewer-partial-cli", name)
}

/// A 240×120 JPEG, never darker than 40 per channel, tagged as columns 360..600 (across
/// the seam of a 480-wide panorama: longitudes 90° to −90° through 180°) and rows 60..180
/// of a 480×240 panorama: 180° × 90° centred on yaw 180, pitch 0.
fn tagged(dir: &Path, xmp_fields: &[(&str, &str)]) -> PathBuf {
    let img = image::RgbImage::from_fn(240, 120, |x, y| {
        image::Rgb([
            40 + (x / 2) as u8,
            40 + y as u8,
            if (x / 20 + y / 20).is_multiple_of(2) {
                60
            } else {
                200
            },
        ])
    });
    let mut jpeg = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut jpeg),
        image::ImageFormat::Jpeg,
    )
    .unwrap();
    let path = dir.join("pano.jpg");
    std::fs::write(&path, insert_xmp(&jpeg, &xmp_packet(xmp_fields)).unwrap()).unwrap();
    path
}

const GOOD: [(&str, &str); 7] = [
    ("FullPanoWidthPixels", "480"),
    ("FullPanoHeightPixels", "240"),
    ("CroppedAreaLeftPixels", "360"),
    ("CroppedAreaTopPixels", "60"),
    ("CroppedAreaImageWidthPixels", "240"),
    ("CroppedAreaImageHeightPixels", "120"),
    ("PoseHeadingDegrees", "90"),
];

fn render(args: &[&str]) -> (image::RgbImage, String) {
    let o = viewer(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{args:?}: {err}");
    let out = args[args.iter().position(|a| *a == "-o").unwrap() + 1];
    (image::open(out).unwrap().to_rgb8(), err)
}

fn black(img: &image::RgbImage) -> usize {
    img.pixels().filter(|p| p.0 == [0, 0, 0]).count()
}

#[test]
fn gpano_jpeg_shows_its_part_and_background_elsewhere() {
    let d = tmpdir("gpano");
    let pano = tagged(&d, &GOOD);
    let out = d.join("v.png");
    // looking at the covered area's centre (yaw 180): no background
    let (img, err) = render(&[
        "render",
        s(&pano),
        "-o",
        s(&out),
        "--yaw",
        "180",
        "--hfov",
        "60",
        "--size",
        "64x32",
        "-v",
    ]);
    assert_eq!(black(&img), 0);
    assert!(
        err.contains("partial panorama: covers 180.0°×90.0°"),
        "{err}"
    );
    // the heading of the view centre: pose 90 + yaw 180
    assert!(err.contains("heading 270°"), "{err}");
    // looking the other way (yaw 0): all background (default black)
    let (img, _) = render(&[
        "render",
        s(&pano),
        "-o",
        s(&out),
        "--yaw",
        "0",
        "--hfov",
        "60",
        "--size",
        "64x32",
    ]);
    assert_eq!(black(&img), 64 * 32);
    // the exact renderer agrees about both
    let (img, _) = render(&[
        "render",
        s(&pano),
        "-o",
        s(&out),
        "--yaw",
        "0",
        "--hfov",
        "60",
        "--size",
        "64x32",
        "--renderer",
        "exact",
    ]);
    assert_eq!(black(&img), 64 * 32);
}

#[test]
fn view_limit_pulls_the_view_inside() {
    let d = tmpdir("limit");
    let pano = tagged(&d, &GOOD);
    let out = d.join("v.png");
    // half outside: the view reaches 45° west of yaw 100, past the west edge at 90°
    let (img, _) = render(&[
        "render",
        s(&pano),
        "-o",
        s(&out),
        "--yaw",
        "100",
        "--pitch",
        "40",
        "--size",
        "96x54",
    ]);
    assert!(black(&img) > 0);
    let (img, err) = render(&[
        "render",
        s(&pano),
        "-o",
        s(&out),
        "--yaw",
        "100",
        "--pitch",
        "40",
        "--size",
        "96x54",
        "--view-limit",
        "-v",
    ]);
    assert_eq!(black(&img), 0, "{err}");
    assert!(err.contains("view (limited)"), "{err}");
}

#[test]
fn coverage_places_an_untagged_image_and_overrides_bad_metadata() {
    let d = tmpdir("coverage");
    let out = d.join("v.png");
    // crop runs below the full panorama: refused with a hint
    let mut bad = GOOD;
    bad[3] = ("CroppedAreaTopPixels", "200");
    let pano = tagged(&d, &bad);
    let o = viewer(&["render", s(&pano), "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("pano.jpg") && err.contains("below") && err.contains("--coverage"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    assert!(!out.exists());
    // --coverage overrides the metadata: 120 x 60 centred on yaw -30, pitch +10
    let (img, _) = render(&[
        "render",
        s(&pano),
        "-o",
        s(&out),
        "--coverage",
        "120x60-30+10",
        "--yaw",
        "-30",
        "--pitch",
        "10",
        "--hfov",
        "40",
        "--size",
        "64x32",
    ]);
    assert_eq!(black(&img), 0);
    let (img, _) = render(&[
        "render",
        s(&pano),
        "-o",
        s(&out),
        "--coverage",
        "120x60-30+10",
        "--yaw",
        "150",
        "--hfov",
        "40",
        "--size",
        "64x32",
    ]);
    assert_eq!(black(&img), 64 * 32);
    // grammar errors name the text
    for bad in ["120x60+30", "120", "400x60", "120x60+0+80"] {
        let o = viewer(&["render", s(&pano), "-o", s(&out), "--coverage", bad]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{bad}");
        assert!(err.contains(bad), "{bad}: {err}");
    }
    // a coverage for a cube map is refused
    let o = viewer(&[
        "render",
        "--projection",
        "cube",
        s(&test_support::test_data("cube/skyfantasy")),
        "-o",
        s(&out),
        "--coverage",
        "90x90",
    ]);
    assert!(!o.status.success());
}

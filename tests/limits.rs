//! The pixel limit refuses huge images from their header, before any pixel buffer is
//! allocated (decompression-bomb defence). A counting global allocator measures the
//! peak bytes allocated during each load; a control load with the limit raised shows the
//! same measurement does see the map's buffer, so the tests can fail.

use lut_core::{LoadOptions, MapError};
use test_support::alloc::Counting;
use test_support::bombs::{jpeg_header_only, png_header_only};

#[global_allocator]
static GLOBAL: Counting = Counting::new();

/// Peak bytes allocated above the starting level while `f` runs.
fn peak_during<T>(f: impl FnOnce() -> T) -> (T, usize) {
    GLOBAL.peak_during(f)
}

/// Allowed during a refused load: the 1 MiB file read buffer, format guessing, the
/// header, the error message (the files claim 30 to 40 GB of pixels).
const SMALL: usize = 4 << 20;

fn check_refused(e: MapError, name: &str, w: u64, h: u64, limit: u64) {
    let msg = e.to_string();
    assert!(
        matches!(e, MapError::TooManyPixels { width, height, limit: l, .. } if width == w && height == h && l == limit),
        "{msg}"
    );
    for part in [name.to_string(), format!("{w}x{h}"), limit.to_string()] {
        assert!(msg.contains(&part), "'{part}' missing from: {msg}");
    }
    // The library names no command-line flag; the viewer adds "--max-pixels" (checked by
    // the viewer's max_pixels_cli test).
    assert!(
        !msg.contains("--"),
        "a flag name in a library message: {msg}"
    );
}

#[test]
fn header_only_huge_files_are_refused_without_allocating() {
    let _g = GLOBAL.exclusive();
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "huge.png",
            png_header_only(100_000, 100_000),
            100_000,
            100_000,
        ),
        ("huge.jpg", jpeg_header_only(65_000, 65_000), 65_000, 65_000),
    ];
    for (name, bytes, w, h) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        let opts = LoadOptions::default();
        // From a file (streamed) and from memory.
        let (r, peak) = peak_during(|| lut_core::load_map(&path, &opts, &mut |_| {}));
        check_refused(r.unwrap_err(), name, w, h, opts.max_pixels);
        assert!(peak < SMALL, "{name}: {peak} bytes allocated");
        let (r, peak) = peak_during(|| lut_core::decode_map(&bytes, name, &opts, &mut |_| {}));
        check_refused(r.unwrap_err(), name, w, h, opts.max_pixels);
        assert!(peak < SMALL, "{name}: {peak} bytes allocated");
        // The default options keep the same default limit.
        assert!(matches!(
            lut_core::load_map(&path, &LoadOptions::default(), &mut |_| {}),
            Err(MapError::TooManyPixels { .. })
        ));
    }
}

#[test]
fn a_real_bomb_is_refused_and_the_control_load_does_allocate() {
    let _g = GLOBAL.exclusive();
    // 8000 × 4000 black: 96 MB of RGB in a PNG of about 100 KB.
    let (w, h) = (8000u32, 4000u32);
    let img = image::RgbImage::new(w, h);
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    drop(img);
    assert!(png.len() < 1 << 20, "{} bytes", png.len());
    let map_bytes = (w as usize + 1) * (h as usize + 1) * 4;

    let refuse = LoadOptions {
        max_pixels: 10_000_000,
        ..LoadOptions::default()
    };
    let (r, peak) = peak_during(|| lut_core::decode_map(&png, "bomb.png", &refuse, &mut |_| {}));
    check_refused(r.unwrap_err(), "bomb.png", w.into(), h.into(), 10_000_000);
    assert!(peak < SMALL, "{peak} bytes allocated");

    // Control: the same file under a limit it fits is decoded, and the counter sees
    // the map's buffer; decoding into that buffer keeps the peak near the map alone.
    let allow = LoadOptions {
        max_pixels: u64::from(w) * u64::from(h),
        ..LoadOptions::default()
    };
    let (r, peak) = peak_during(|| lut_core::decode_map(&png, "bomb.png", &allow, &mut |_| {}));
    let map = r.unwrap();
    assert_eq!((map.width(), map.height()), (w, h));
    assert!(peak >= map_bytes, "{peak} < {map_bytes}");
    assert!(
        peak < map_bytes + map_bytes / 4,
        "peak {peak} bytes for a {map_bytes}-byte map: an intermediate image buffer?"
    );
}

//! Damaged and unusual inputs found from outside (issue 15), each refused with a message
//! naming the file, or read correctly: truncated and corrupt JPEGs, a tiny JPEG claiming
//! a huge size, FIFOs where files are expected, a symbolic-link loop as a cube face, a
//! damaged DWAB EXR, a luminance-only EXR, an impossible GPano crop. A counting allocator
//! measures what a refused file costs.

use lut_core::{CubeError, LoadOptions, MapError, Projection, Tone};
use std::path::{Path, PathBuf};
use std::time::Duration;
use test_support::alloc::Counting;

#[global_allocator]
static GLOBAL: Counting = Counting::new();

fn courtyard() -> Vec<u8> {
    std::fs::read(test_support::repo_root().join("assets/courtyard.jpg")).unwrap()
}

fn load(path: &Path) -> Result<lut_core::EnvMap, MapError> {
    lut_core::load_map(path, &LoadOptions::default(), &mut |_| {})
}

fn decode(bytes: &[u8], name: &str) -> Result<lut_core::EnvMap, MapError> {
    lut_core::decode_map(bytes, name, &LoadOptions::default(), &mut |_| {})
}

/// Run `f` on a thread; fail (instead of hanging the test run) if it takes longer than
/// `secs`.
fn within<T: Send + 'static>(secs: u64, what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(secs))
        .unwrap_or_else(|_| panic!("{what}: still blocked after {secs} s"))
}

#[test]
fn truncated_and_corrupt_jpegs_are_refused() {
    let _g = GLOBAL.exclusive();
    let dir = tempfile::tempdir().unwrap();
    let full = courtyard();
    let sos = full.windows(2).position(|w| w == [0xFF, 0xDA]).unwrap();
    let sos_len = usize::from(u16::from_be_bytes([full[sos + 2], full[sos + 3]]));
    let mut corrupt = full.clone();
    for k in (full.len() / 2..full.len() / 2 + 2000).step_by(7) {
        corrupt[k] ^= 0x55;
    }
    let progressive = std::fs::read(test_support::test_data("jpeg/progressive.jpg")).unwrap();
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("cut10.jpg", full[..full.len() / 10].to_vec()),
        ("cut50.jpg", full[..full.len() / 2].to_vec()),
        ("after-scan-header.jpg", full[..sos + 2 + sos_len].to_vec()),
        ("no-end-marker.jpg", full[..full.len() - 2].to_vec()),
        ("corrupt.jpg", corrupt),
        (
            "progressive-cut50.jpg",
            progressive[..progressive.len() / 2].to_vec(),
        ),
    ];
    for (name, bytes) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        for e in [load(&path).unwrap_err(), decode(&bytes, name).unwrap_err()] {
            let msg = e.to_string();
            assert!(
                msg.contains(name) && (msg.contains("truncated") || msg.contains("corrupt")),
                "{name}: {msg}"
            );
        }
        // The window's and render's path (placement by GPano or coverage) too.
        let e =
            lut_core::load_partial(&path, &LoadOptions::default(), None, &mut |_| {}).unwrap_err();
        assert!(e.to_string().contains(name), "{e}");
    }
    // The whole files still load.
    assert!(decode(&full, "courtyard.jpg").is_ok());
    let p = decode(&progressive, "progressive.jpg").unwrap();
    let gray = std::fs::read(test_support::test_data("jpeg/gray.jpg")).unwrap();
    let g = decode(&gray, "gray.jpg").unwrap();
    assert_eq!((p.width(), p.height(), g.width()), (128, 64, 128));
    // A gray JPEG is gray in the map.
    let px = g.pixel(40, 30);
    assert_eq!(px & 0xFF, (px >> 8) & 0xFF);
}

#[test]
fn a_tiny_jpeg_claiming_a_huge_size_is_refused_before_allocating() {
    let _g = GLOBAL.exclusive();
    // 32768 x 16384 (inside the default pixel limit) in 2.3 KB: a header, a comment and
    // a little scan data.
    let mut bytes = test_support::bombs::jpeg_header_only(32768, 16384);
    bytes.truncate(bytes.len() - 2);
    bytes.extend_from_slice(&[0xFF, 0xFE, 0x08, 0xE8]);
    bytes.extend(std::iter::repeat_n(b'x', 0x08E8 - 2));
    bytes.extend_from_slice(&[0xFF, 0xD9]);
    assert!((2200..2400).contains(&bytes.len()), "{}", bytes.len());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("claims-32k.jpg");
    std::fs::write(&path, &bytes).unwrap();
    let (r, peak) = GLOBAL.peak_during(|| load(&path));
    let msg = r.unwrap_err().to_string();
    assert!(
        msg.contains("claims-32k.jpg") && msg.contains("32768x16384") && msg.contains("at most"),
        "{msg}"
    );
    assert!(
        peak < 4 << 20,
        "{peak} bytes allocated for a refused 2.3 KB file"
    );
    let (r, peak) = GLOBAL.peak_during(|| decode(&bytes, "claims-32k.jpg"));
    assert!(r.is_err());
    assert!(peak < 4 << 20, "{peak} bytes allocated from memory");
}

#[cfg(unix)]
#[test]
fn fifos_are_refused_without_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let mkfifo = |p: &Path| {
        assert!(std::process::Command::new("mkfifo")
            .arg(p)
            .status()
            .unwrap()
            .success())
    };
    let pano = dir.path().join("pano.jpg");
    mkfifo(&pano);
    let p = pano.clone();
    let e = within(10, "load_map on a FIFO", move || load(&p).unwrap_err());
    assert!(
        e.to_string().contains("pano.jpg") && e.to_string().contains("FIFO"),
        "{e}"
    );
    let p = pano.clone();
    let e = within(10, "load_partial on a FIFO", move || {
        lut_core::load_partial(&p, &LoadOptions::default(), None, &mut |_| {}).unwrap_err()
    });
    assert!(e.to_string().contains("FIFO"), "{e}");
    let p = pano.clone();
    let e = within(10, "a layout image that is a FIFO", move || {
        lut_core::load_layout_image(&p, None).unwrap_err()
    });
    assert!(e.to_string().contains("FIFO"), "{e}");
    // A face in a cube folder.
    let faces = dir.path().join("faces");
    std::fs::create_dir(&faces).unwrap();
    for f in ["front", "right", "back", "left", "up"] {
        image::RgbImage::new(8, 8)
            .save(faces.join(format!("{f}.png")))
            .unwrap();
    }
    mkfifo(&faces.join("down.png"));
    let f = faces.clone();
    let e = within(10, "a cube face that is a FIFO", move || {
        lut_core::load_cube(&[f], None, None).unwrap_err()
    });
    assert!(
        matches!(&e, CubeError::Read { path, .. } if path.ends_with("down.png")),
        "{e}"
    );
    assert!(e.to_string().contains("FIFO"), "{e}");
    // A photometric file.
    let light = dir.path().join("lamp.ies");
    mkfifo(&light);
    let e = within(10, "an IES file that is a FIFO", move || {
        lut_core::Photometry::load(&light).unwrap_err()
    });
    assert!(e.to_string().contains("FIFO"), "{e}");
}

#[cfg(unix)]
#[test]
fn a_symlink_loop_face_is_named_with_its_reason() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["front", "right", "back", "left", "up"] {
        image::RgbImage::new(8, 8)
            .save(dir.path().join(format!("{f}.png")))
            .unwrap();
    }
    let down = dir.path().join("down.png");
    let other = dir.path().join("other.png");
    std::os::unix::fs::symlink(&other, &down).unwrap();
    std::os::unix::fs::symlink(&down, &other).unwrap();
    let e = lut_core::load_cube(&[dir.path().to_path_buf()], None, None).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("down.png") && msg.contains("symbolic links") && !msg.contains("missing"),
        "{msg}"
    );
    // A link to nothing says so.
    std::fs::remove_file(&other).unwrap();
    let msg = lut_core::load_cube(&[dir.path().to_path_buf()], None, None)
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("down.png") && msg.contains("symbolic link to a missing file"),
        "{msg}"
    );
}

/// The DWA chunk leaders of a scan-line EXR: (offset of each chunk's first count).
fn dwa_leaders(bytes: &[u8]) -> Vec<usize> {
    let reader = exr::block::read(std::io::Cursor::new(bytes), false).unwrap();
    let header = reader.headers()[0].clone();
    let n = header.chunk_count;
    // The offset table follows the header; each chunk: y (4 bytes), size (4), data.
    let table_end = {
        let mut at = 8; // magic and version
        loop {
            let name_end = at + bytes[at..].iter().position(|&b| b == 0).unwrap();
            if name_end == at {
                break name_end + 1;
            }
            let type_end =
                name_end + 1 + bytes[name_end + 1..].iter().position(|&b| b == 0).unwrap();
            let size = i32::from_le_bytes(bytes[type_end + 1..type_end + 5].try_into().unwrap());
            at = type_end + 5 + size as usize;
        }
    };
    (0..n)
        .map(|i| {
            let o = table_end + 8 * i;
            u64::from_le_bytes(bytes[o..o + 8].try_into().unwrap()) as usize + 8
        })
        .collect()
}

#[test]
fn a_damaged_dwab_exr_is_refused_within_bounded_memory() {
    let _g = GLOBAL.exclusive();
    let good = std::fs::read(test_support::test_data("hdr/interior.exr")).unwrap();
    let (ok, legit_peak) = GLOBAL.peak_during(|| decode(&good, "interior.exr"));
    ok.unwrap();
    let leaders = dwa_leaders(&good);
    assert_eq!(
        leaders.len(),
        2,
        "interior.exr has two 256-line DWAB chunks"
    );
    // Each count of the leader raised to 572 MB and to 2^40 (the latter used to abort
    // the process: "memory allocation of ... bytes failed").
    for (field, name) in [
        (1, "unknown"),
        (6, "RLE"),
        (7, "RLE raw"),
        (8, "AC"),
        (9, "DC"),
    ] {
        for value in [572u64 << 20, 1 << 40] {
            let mut bad = good.clone();
            let at = leaders[1] + 8 * field;
            bad[at..at + 8].copy_from_slice(&value.to_le_bytes());
            let (r, peak) = GLOBAL.peak_during(|| decode(&bad, "damaged.exr"));
            let msg = r.unwrap_err().to_string();
            assert!(
                msg.contains("damaged.exr") && msg.contains("damaged"),
                "{name}: {msg}"
            );
            assert!(
                peak < legit_peak + (32 << 20),
                "{name} {value}: {peak} bytes allocated (a good load takes {legit_peak})"
            );
        }
    }
    // Truncated: the blocks no longer cover the image.
    let e = decode(&good[..good.len() * 6 / 10], "cut.exr").unwrap_err();
    assert!(e.to_string().contains("cut.exr"), "{e}");
}

/// Found by the `map_exr` fuzz target: a damaged B44A block whose differences underflow.
/// exr's B44 decoder computes them in unsigned arithmetic that wraps, as OpenEXR's C
/// reference does; with overflow checks on (this profile, the fuzz build) it panicked.
/// exr is now built without overflow checks in every profile (Cargo.toml): the file
/// decodes to whatever its blocks say (B44 has no checksum) or is refused, never a panic.
#[test]
fn a_damaged_b44a_exr_does_not_panic() {
    let r = decode_found("map_exr-b44a-underflow.exr", "b44a.exr", 1 << 18);
    if let Ok((w, h)) = r {
        assert!(w >= 1 && h >= 1 && u64::from(w) * u64::from(h) <= 1 << 18);
    }
}

/// Decode the fuzz finding `file` (`tests/data/fuzz/`) as `name` under a pixel limit, as
/// the fuzz targets do: its size, or the error's message. Fails the test if it panics.
fn decode_found(file: &str, name: &str, max_pixels: u64) -> Result<(u32, u32), String> {
    let bytes = std::fs::read(test_support::test_data(&format!("fuzz/{file}"))).unwrap();
    let opts = LoadOptions {
        projection: Some(Projection::Elliptical),
        max_pixels,
        ..LoadOptions::default()
    };
    std::panic::catch_unwind(|| {
        lut_core::decode_map(&bytes, name, &opts, &mut |_| {})
            .map(|m| (m.width(), m.height()))
            .map_err(|e| e.to_string())
    })
    .unwrap_or_else(|_| panic!("decoding {file} panicked"))
}

/// A damaged JPEG (found by the `map_jpeg` fuzz target) on which zune-jpeg 0.5.15's AVX2
/// IDCT unwraps a slice that is too short: refused with an error naming the file, not a
/// panic. (Without AVX2 the scalar IDCT runs, which may decode it or refuse it: either
/// is fine, a panic is not.)
#[test]
fn a_jpeg_that_trips_the_decoder_is_refused() {
    match decode_found("map_jpeg-idct-avx2-unwrap.jpg", "trips.jpg", 1 << 24) {
        Err(msg) => {
            assert!(msg.contains("trips.jpg"), "{msg}");
            assert!(!msg.contains('\n'), "one line: {msg}");
        }
        Ok((w, h)) => assert!(w >= 1 && h >= 1),
    }
}

#[test]
fn a_luminance_only_exr_loads_as_gray() {
    use exr::prelude::{Blocks, Compression};
    use test_support::exr_files::{exr_file, exr_value};
    let bytes = exr_file(64, 32, &["Y"], Compression::ZIP16, Blocks::ScanLines, false);
    let map = lut_core::decode_map(
        &bytes,
        "luminance.exr",
        &LoadOptions {
            tone: Tone { exposure_ev: 0.0 },
            ..LoadOptions::default()
        },
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(
        (map.width(), map.height(), map.projection()),
        (64, 32, Projection::Equirect)
    );
    let mut negative = 0;
    for y in 0..32 {
        for x in 0..64 {
            let v = exr_value(0, x, y, 64);
            negative += usize::from(v < 0.0);
            let want = u32::from(lut_core::tone_map(v)) * 0x0001_0101;
            assert_eq!(map.pixel(x as u32, y as u32), want, "({x},{y}) Y {v}");
        }
    }
    assert!(
        negative > 0,
        "the ramp starts below zero (clamped to black)"
    );
}

#[test]
fn a_gpano_left_edge_past_the_panorama_is_refused() {
    let mut jpeg = Vec::new();
    image::RgbImage::new(512, 256)
        .write_to(
            &mut std::io::Cursor::new(&mut jpeg),
            image::ImageFormat::Jpeg,
        )
        .unwrap();
    let xmp = lut_core::xmp_packet(&[
        ("FullPanoWidthPixels", "512"),
        ("FullPanoHeightPixels", "256"),
        ("CroppedAreaLeftPixels", "4000000000"),
        ("CroppedAreaTopPixels", "0"),
        ("CroppedAreaImageWidthPixels", "512"),
        ("CroppedAreaImageHeightPixels", "256"),
    ]);
    let tagged = lut_core::insert_xmp(&jpeg, &xmp).unwrap();
    let e = lut_core::decode_partial(
        &tagged,
        "far-left.jpg",
        &LoadOptions::default(),
        None,
        &mut |_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("far-left.jpg") && e.contains("CroppedAreaLeftPixels"),
        "{e}"
    );
}

#[test]
fn cube_face_files_are_listed_as_the_loader_reads_them() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["front", "right", "back", "left", "up", "down"] {
        image::RgbImage::new(8, 8)
            .save(dir.path().join(format!("sky_{f}.png")))
            .unwrap();
    }
    std::fs::write(dir.path().join("notes.txt"), "x").unwrap();
    image::RgbImage::new(8, 8)
        .save(dir.path().join("pano.png"))
        .unwrap();
    let files: Vec<PathBuf> = lut_core::cube_face_files(dir.path()).unwrap();
    let names: Vec<String> = files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "sky_back.png",
            "sky_down.png",
            "sky_front.png",
            "sky_left.png",
            "sky_right.png",
            "sky_up.png"
        ]
    );
    assert!(lut_core::load_cube(&[dir.path().to_path_buf()], None, None).is_ok());
}

/// A small real JPEG whose frame header claims `w × h`, with `pad` bytes of comment
/// segments before the frame header (padding that is not image data).
fn jpeg_claiming(w: u16, h: u16, pad: usize) -> Vec<u8> {
    let img =
        image::RgbImage::from_fn(64, 32, |x, y| image::Rgb([(x * 7) as u8, (y * 5) as u8, 9]));
    let mut real = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut real, 90)
        .encode(img.as_raw(), 64, 32, image::ExtendedColorType::Rgb8)
        .unwrap();
    let sof = real.windows(2).position(|w| w == [0xFF, 0xC0]).unwrap();
    real[sof + 5..sof + 7].copy_from_slice(&h.to_be_bytes());
    real[sof + 7..sof + 9].copy_from_slice(&w.to_be_bytes());
    let mut out = real[..2].to_vec();
    let mut left = pad;
    while left > 0 {
        let n = left.min(0xFFFD);
        out.extend_from_slice(&[0xFF, 0xFE]);
        out.extend_from_slice(&u16::try_from(n + 2).unwrap().to_be_bytes());
        out.extend(std::iter::repeat_n(b'x', n));
        left -= n;
    }
    out.extend_from_slice(&real[2..]);
    out
}

#[test]
fn a_padded_jpeg_claiming_a_huge_size_commits_memory_for_its_data_only() {
    let _g = GLOBAL.exclusive();
    // 1.2 MB of comments: the file is large enough for 32768 x 16384 by the file-size
    // bound, but its image data is a few kilobytes.
    let bytes = jpeg_claiming(32768, 16384, 1_200_000);
    assert!(bytes.len() > 1_200_000);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("padded-32k.jpg");
    std::fs::write(&path, &bytes).unwrap();
    let (r, peak) = GLOBAL.peak_during(|| load(&path));
    let msg = r.unwrap_err().to_string();
    assert!(
        msg.contains("padded-32k.jpg") && msg.contains("32768x16384") && msg.contains("image data"),
        "{msg}"
    );
    // The file itself is read (1.2 MB); nothing of the claimed size (2 GiB) is.
    assert!(
        peak < 8 << 20,
        "{peak} bytes allocated for a refused padded file"
    );
}

#[test]
fn a_jpeg_claiming_more_lines_than_its_data_is_refused() {
    // The data holds 32 lines; the header claims more: refused, never filled in with a
    // repeated pattern. (The same image with its own height loads.)
    let any_shape = |bytes: &[u8], name: &str| {
        let opts = LoadOptions {
            projection: Some(Projection::Elliptical),
            ..LoadOptions::default()
        };
        lut_core::decode_map(bytes, name, &opts, &mut |_| {})
    };
    assert!(any_shape(&jpeg_claiming(64, 32, 0), "ok.jpg").is_ok());
    for h in [40, 64, 256, 4096] {
        let e = any_shape(&jpeg_claiming(64, h, 0), "short.jpg").expect_err("filled in");
        let msg = e.to_string();
        assert!(
            msg.contains("short.jpg") && msg.contains("truncated"),
            "{h}: {msg}"
        );
    }
}

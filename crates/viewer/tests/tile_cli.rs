//! `viewer tile`: the pyramid against Pannellum's own generate.py (file set, tile sizes,
//! config text, pixels), the top level's faces against the exact renderer's 90° views,
//! TIFF inputs (striped and tiled, 8 and 16 bits) against the same pixels as PNG, a large
//! synthetic pyramid in bounded memory, output folders and bad inputs.

mod common;

use common::{s, tmpdir, viewer};
use lut_core::{Face, Frame, Projection, Sampler};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use test_support::pixels::psnr;
use test_support::test_data;
use viewer::tile::FACES;

/// Every file under `dir`, relative, with its contents.
fn files(dir: &Path) -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
                out.insert(rel, p);
            }
        }
    }
    out
}

fn rgb_u32(img: &image::RgbImage) -> Vec<u32> {
    img.pixels()
        .map(|p| u32::from(p[0]) << 16 | u32::from(p[1]) << 8 | u32::from(p[2]))
        .collect()
}

fn load(p: &Path) -> image::RgbImage {
    image::open(p)
        .unwrap_or_else(|e| panic!("{}: {e}", p.display()))
        .to_rgb8()
}

/// The top level of `face` (letter) assembled from its tiles.
fn top_face(dir: &Path, letter: char, n: u32, tile: u32, level: u32, ext: &str) -> Vec<u32> {
    let mut face = vec![0u32; (n * n) as usize];
    for row in 0..n.div_ceil(tile) {
        for col in 0..n.div_ceil(tile) {
            let t = load(&dir.join(format!("{level}/{letter}{row}_{col}.{ext}")));
            for (y, line) in t.rows().enumerate() {
                for (x, p) in line.enumerate() {
                    let (fx, fy) = (col * tile + x as u32, row * tile + y as u32);
                    face[(fy * n + fx) as usize] =
                        u32::from(p[0]) << 16 | u32::from(p[1]) << 8 | u32::from(p[2]);
                }
            }
        }
    }
    face
}

#[test]
fn pyramid_matches_generate_py_files_config_and_pixels() {
    let theirs = test_data("multires/generate-py");
    let input = test_data("multires/courtyard-512.jpg");
    let out = tmpdir("tile", "genpy").join("pyr");
    let o = viewer(&[
        "tile",
        s(&input),
        "-o",
        s(&out),
        "--tile-size",
        "64",
        "--fallback-size",
        "128",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (ours, want) = (files(&out), files(&theirs));
    assert_eq!(
        ours.keys().collect::<Vec<_>>(),
        want.keys().collect::<Vec<_>>(),
        "the same files"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("config.json")).unwrap(),
        std::fs::read_to_string(theirs.join("config.json")).unwrap(),
        "config.json byte for byte"
    );
    // Every tile: the same size; pixels close (nona and Pillow's Lanczos resample
    // differently from our bilinear and area averages, and both sides are JPEG q75).
    let mut worst = f64::INFINITY;
    for (rel, p) in &want {
        if rel.ends_with(".json") {
            continue;
        }
        let (a, b) = (load(&ours[rel]), load(p));
        assert_eq!(a.dimensions(), b.dimensions(), "{rel}");
        let db = psnr(&rgb_u32(&a), &rgb_u32(&b));
        worst = worst.min(db);
        assert!(db >= 26.0, "{rel}: {db:.1} dB against generate.py's tile");
    }
    // The whole top-level faces (orientation: a face turned or swapped would be ~12 dB).
    for (letter, _) in FACES {
        let a = top_face(&out, letter, 160, 64, 3, "jpg");
        let b = top_face(&theirs, letter, 160, 64, 3, "jpg");
        let db = psnr(&a, &b);
        assert!(db >= 30.0, "face {letter}: {db:.1} dB against generate.py");
        eprintln!("face {letter}: {db:.1} dB against generate.py");
    }
    eprintln!("worst tile against generate.py: {worst:.1} dB");
}

/// The exact renderer's 90° view of `face` of a map: the definition of a cube face.
fn exact_face(map: &lut_core::EnvMap, face: Face, n: u32) -> Vec<u32> {
    let mut px = vec![0u32; (n * n) as usize];
    let mut frame = Frame::new(&mut px, n, n).unwrap();
    lut_core::render_exact(map, face.view(), Sampler::Bilinear, &mut frame, true);
    px
}

#[test]
fn top_level_faces_are_the_exact_renderers_views() {
    // A 2:1 PNG of the grid scene, streamed through the block store; PNG tiles.
    let dir = tmpdir("tile", "exact");
    let (w, h) = (1000u32, 500u32);
    let map = lut_core::grid_map(w, h, Projection::Equirect).unwrap();
    let px: Vec<u32> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| map.pixel(x, y))
        .collect();
    let png = dir.join("grid.png");
    test_support::pixels::to_rgb(&px, w, h).save(&png).unwrap();
    let out = dir.join("pyr");
    let o = viewer(&[
        "tile",
        s(&png),
        "-o",
        s(&out),
        "--png",
        "--tile-size",
        "100",
        "-q",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let n = 8 * (1000.0 / std::f64::consts::PI / 8.0) as u32; // 312
    let cfg = std::fs::read_to_string(out.join("config.json")).unwrap();
    assert!(cfg.contains(&format!("\"cubeResolution\": {n}")), "{cfg}");
    let level = 3; // 312 / 100: levels 312, 156, 78
    assert!(cfg.contains(&format!("\"maxLevel\": {level}")), "{cfg}");
    for (letter, face) in FACES {
        let ours = top_face(&out, letter, n, 100, level, "png");
        let want = exact_face(&map, face, n);
        let db = psnr(&ours, &want);
        assert!(
            db >= 45.0,
            "face {letter} ({face:?}): {db:.1} dB against the exact view"
        );
        eprintln!("face {letter}: {db:.1} dB against the exact view");
    }
}

/// Write `px` (RGB8, w × h) as an uncompressed TIFF: striped (`tile: None`) or tiled.
fn write_tiff(path: &Path, px: &[u8], w: u32, h: u32, sixteen: bool, tile: Option<u32>) {
    use tiff::encoder::{colortype, TiffEncoder};
    use tiff::tags::Tag;
    let f = std::fs::File::create(path).unwrap();
    let mut enc = TiffEncoder::new(std::io::BufWriter::new(f)).unwrap();
    let samples16: Vec<u16> = px.iter().map(|&v| u16::from(v) * 257).collect();
    match tile {
        None if sixteen => enc
            .write_image::<colortype::RGB16>(w, h, &samples16)
            .unwrap(),
        None => enc.write_image::<colortype::RGB8>(w, h, px).unwrap(),
        Some(t) => {
            let mut dir = enc.image_directory().unwrap();
            let (mut offsets, mut counts) = (Vec::new(), Vec::new());
            for ty in 0..h.div_ceil(t) {
                for tx in 0..w.div_ceil(t) {
                    // a full tile, padded past the image's edges
                    let mut t8 = vec![0u8; (t * t * 3) as usize];
                    for y in 0..t {
                        for x in 0..t {
                            let (ix, iy) = (tx * t + x, ty * t + y);
                            if ix < w && iy < h {
                                let s = ((iy * w + ix) * 3) as usize;
                                let d = ((y * t + x) * 3) as usize;
                                t8[d..d + 3].copy_from_slice(&px[s..s + 3]);
                            }
                        }
                    }
                    let off = if sixteen {
                        let t16: Vec<u16> = t8.iter().map(|&v| u16::from(v) * 257).collect();
                        counts.push(t16.len() as u32 * 2);
                        dir.write_data(&t16[..]).unwrap()
                    } else {
                        counts.push(t8.len() as u32);
                        dir.write_data(&t8[..]).unwrap()
                    };
                    offsets.push(off as u32);
                }
            }
            let bits: u16 = if sixteen { 16 } else { 8 };
            dir.write_tag(Tag::ImageWidth, w).unwrap();
            dir.write_tag(Tag::ImageLength, h).unwrap();
            dir.write_tag(Tag::BitsPerSample, &[bits, bits, bits][..])
                .unwrap();
            dir.write_tag(Tag::Compression, 1u16).unwrap();
            dir.write_tag(Tag::PhotometricInterpretation, 2u16).unwrap();
            dir.write_tag(Tag::SamplesPerPixel, 3u16).unwrap();
            dir.write_tag(Tag::PlanarConfiguration, 1u16).unwrap();
            dir.write_tag(Tag::TileWidth, t).unwrap();
            dir.write_tag(Tag::TileLength, t).unwrap();
            dir.write_tag(Tag::TileOffsets, &offsets[..]).unwrap();
            dir.write_tag(Tag::TileByteCounts, &counts[..]).unwrap();
            dir.finish().unwrap();
        }
    }
}

#[test]
fn tiff_inputs_striped_and_tiled_8_and_16_bit_give_the_pngs_pyramid() {
    let dir = tmpdir("tile", "tiff");
    let (w, h) = (600u32, 300u32);
    let map = lut_core::grid_map(w, h, Projection::Equirect).unwrap();
    let mut px = Vec::with_capacity((w * h * 3) as usize);
    for y in 0..h {
        for x in 0..w {
            let c = map.pixel(x, y);
            px.extend_from_slice(&[(c >> 16) as u8, (c >> 8) as u8, c as u8]);
        }
    }
    let png = dir.join("in.png");
    image::RgbImage::from_raw(w, h, px.clone())
        .unwrap()
        .save(&png)
        .unwrap();
    let reference = dir.join("png-pyr");
    let args = ["--png", "--tile-size", "64", "--fallback-size", "64", "-q"];
    let run = |input: &Path, out: &Path| {
        let mut a = vec!["tile", s(input), "-o", s(out)];
        a.extend(args);
        let o = viewer(&a);
        assert!(
            o.status.success(),
            "{}: {}",
            input.display(),
            String::from_utf8_lossy(&o.stderr)
        );
    };
    run(&png, &reference);
    let want = files(&reference);
    for (name, sixteen, tile) in [
        ("strips8.tif", false, None),
        ("strips16.tif", true, None),
        ("tiles8.tif", false, Some(48)),
        ("tiles16.tif", true, Some(64)),
    ] {
        let tif = dir.join(name);
        write_tiff(&tif, &px, w, h, sixteen, tile);
        let out = dir.join(format!("{name}-pyr"));
        run(&tif, &out);
        let got = files(&out);
        assert_eq!(
            got.keys().collect::<Vec<_>>(),
            want.keys().collect::<Vec<_>>(),
            "{name}"
        );
        for (rel, p) in &want {
            let same = std::fs::read(p).unwrap() == std::fs::read(&got[rel]).unwrap();
            assert!(same, "{name}: {rel} differs from the PNG input's");
        }
    }
}

/// Peak resident memory of a finished child, from `/proc/self/status` of a wrapper
/// shell: `viewer` is run under `sh -c` and the shell reads the child's VmHWM through
/// `/usr/bin/time` when present, else the test measures the process by polling.
fn peak_rss_kib(args: &[&str]) -> (std::process::ExitStatus, u64, String) {
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_viewer"))
        .args(args)
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let status_path = format!("/proc/{}/status", child.id());
    let mut peak = 0u64;
    let status = loop {
        if let Ok(t) = std::fs::read_to_string(&status_path) {
            if let Some(l) = t.lines().find(|l| l.starts_with("VmHWM:")) {
                let kib: u64 = l.split_whitespace().nth(1).unwrap().parse().unwrap();
                peak = peak.max(kib);
            }
        }
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let mut err = String::new();
    use std::io::Read;
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (status, peak, err)
}

#[test]
fn a_large_synthetic_pyramid_in_bounded_memory() {
    // 12000 px wide: faces of 3816 px, 6 × 14.6 Mpx = 87 Mpx of faces (262 MB of RGB,
    // 44 MB a face); the writer holds a band of tiles per level, so well under 120 MiB.
    let out = tmpdir("tile", "synthetic").join("pyr");
    let (status, peak_kib, err) = peak_rss_kib(&[
        "tile",
        "--synthetic",
        "12000x6000",
        "-o",
        s(&out),
        "--quality",
        "40",
        "--fallback-size",
        "0",
    ]);
    assert!(status.success(), "{err}");
    assert!(peak_kib > 0, "VmHWM was read");
    assert!(peak_kib < 120 * 1024, "peak RSS {} MiB", peak_kib / 1024);
    eprintln!("peak RSS {} MiB", peak_kib / 1024);
    let cfg = std::fs::read_to_string(out.join("config.json")).unwrap();
    assert!(
        cfg.contains("\"cubeResolution\": 3816") && !cfg.contains("fallbackPath"),
        "{cfg}"
    );
    // 3816 / 512: 8 tiles a side at the top, levels 3816 1908 954 477
    assert!(cfg.contains("\"maxLevel\": 4"), "{cfg}");
    let n = files(&out).len();
    assert_eq!(n, 1 + 6 * (8 * 8 + 4 * 4 + 2 * 2 + 1), "tiles written");
    // the last tile of a row is short: 3816 - 7 * 512 = 232 px; level 1 one tile of 477
    let t = load(&out.join("4/f7_7.jpg"));
    assert_eq!(t.dimensions(), (232, 232));
    assert_eq!(load(&out.join("1/u0_0.jpg")).dimensions(), (477, 477));
}

fn one_line(err: &[u8]) -> String {
    let e = String::from_utf8_lossy(err).trim().to_string();
    assert_eq!(e.lines().count(), 1, "one line: {e}");
    assert!(!e.contains("panicked"), "{e}");
    e
}

#[test]
fn output_folders_other_files_refused_pyramids_replaced() {
    let dir = tmpdir("tile", "outdir");
    let input = test_data("multires/courtyard-512.jpg");
    // a folder with something else in it: refused, untouched
    let busy = dir.join("busy");
    std::fs::create_dir_all(&busy).unwrap();
    std::fs::write(busy.join("notes.txt"), "mine").unwrap();
    let o = viewer(&["tile", s(&input), "-o", s(&busy), "--tile-size", "64"]);
    assert_eq!(o.status.code(), Some(1));
    let e = one_line(&o.stderr);
    assert!(e.contains("notes.txt") && e.contains("busy"), "{e}");
    assert_eq!(
        std::fs::read_to_string(busy.join("notes.txt")).unwrap(),
        "mine"
    );
    assert_eq!(files(&busy).len(), 1);
    // a file as the output
    let file = dir.join("file.jpg");
    std::fs::write(&file, "x").unwrap();
    let o = viewer(&["tile", s(&input), "-o", s(&file)]);
    assert_eq!(o.status.code(), Some(1));
    one_line(&o.stderr);
    // an earlier pyramid (other tile size) is replaced entirely: no stale tiles
    let pyr = dir.join("pyr");
    let o = viewer(&[
        "tile",
        s(&input),
        "-o",
        s(&pyr),
        "--tile-size",
        "32",
        "--fallback-size",
        "0",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(pyr.join("4").exists());
    let o = viewer(&[
        "tile",
        s(&input),
        "-o",
        s(&pyr),
        "--tile-size",
        "64",
        "--fallback-size",
        "128",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ours: Vec<String> = files(&pyr).into_keys().collect();
    let theirs: Vec<String> = files(&test_data("multires/generate-py"))
        .into_keys()
        .collect();
    assert_eq!(ours, theirs);
}

#[test]
fn bad_inputs_fail_in_one_line_and_leave_nothing_that_looks_complete() {
    let dir = tmpdir("tile", "bad");
    let good = std::fs::read(test_data("multires/courtyard-512.jpg")).unwrap();
    // a truncated JPEG: the decoder's warning is an error, after pass 1 began
    let cut = dir.join("cut.jpg");
    std::fs::write(&cut, &good[..good.len() / 2]).unwrap();
    // an image that is not 2:1 (equirect assumed: the map loader's message)
    let square = dir.join("square.png");
    image::RgbImage::new(64, 64).save(&square).unwrap();
    let text = dir.join("text.jpg");
    std::fs::write(&text, "not an image").unwrap();
    let cases: [(&str, Vec<String>, i32, &str); 7] = [
        ("cut", vec![s(&cut).into()], 1, "cut.jpg"),
        (
            "missing",
            vec![s(&dir.join("nope.jpg")).into()],
            1,
            "nope.jpg",
        ),
        ("text", vec![s(&text).into()], 1, "text.jpg"),
        ("square", vec![s(&square).into()], 1, "square.png"),
        ("none", vec![], 2, "INPUT"),
        (
            "tile0",
            vec![s(&cut).into(), "--tile-size".into(), "0".into()],
            2,
            "tile-size",
        ),
        (
            "synthetic",
            vec!["--synthetic".into(), "10x5".into()],
            2,
            "10x5",
        ),
    ];
    for (name, extra, code, says) in cases {
        let out = dir.join(format!("out-{name}"));
        let mut args = vec!["tile".to_string(), "-o".into(), s(&out).into()];
        args.extend(extra);
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = viewer(&refs);
        assert_eq!(
            o.status.code(),
            Some(code),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        if code == 1 {
            let e = one_line(&o.stderr);
            assert!(e.contains(says), "{name}: {e}");
        } else {
            let e = String::from_utf8_lossy(&o.stderr);
            assert!(e.contains(says), "{name}: {e}");
        }
        assert!(!out.join("config.json").exists(), "{name}: no config.json");
    }
    // a pyramid left by a run that failed part way is replaced by the next run
    let out = dir.join("out-cut");
    let o = viewer(&[
        "tile",
        s(&test_data("multires/courtyard-512.jpg")),
        "-o",
        s(&out),
        "--tile-size",
        "64",
        "--fallback-size",
        "128",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("config.json").exists());
}

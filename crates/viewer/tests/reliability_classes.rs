//! Issue 32: each class of fault, through the one mechanism that now covers it
//! (docs/reliability.md, "The classes"): the limits module, the decoder containment, image
//! data bounding memory, the one input-file check, the one way of echoing input, finite
//! JSON with one exit status per option. Every run is a real `viewer` process with a
//! time-out, so a hang is a failure, not a stuck test run.

mod common;

use common::{s, tmpdir};
use std::io::Read;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Run `viewer args` with `env`, killing it after `secs` (a failure: it hung).
fn run_env(args: &[&str], env: &[(&str, &str)], secs: u64) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_viewer"));
    cmd.args(args)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for (k, v) in env {
        cmd.env(k, v);
    }
    let mut child = cmd.spawn().expect("run viewer");
    // Both pipes drained while it runs: a command printing more than a pipe holds must
    // not block on it (that would look like a hang).
    let drain = |mut r: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut v = Vec::new();
            let _ = r.read_to_end(&mut v);
            v
        })
    };
    let out = drain(Box::new(child.stdout.take().unwrap()));
    let err = drain(Box::new(child.stderr.take().unwrap()));
    let t0 = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return Output {
                status,
                stdout: out.join().unwrap(),
                stderr: err.join().unwrap(),
            };
        }
        if t0.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("viewer {args:?} still running after {secs} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn run(args: &[&str]) -> Output {
    run_env(args, &[], 20)
}

/// The exit status and the one line of standard error (clap's "For more information"
/// hint aside); fails on more lines, a panic or a control character.
fn one_line(out: &Output) -> (i32, String) {
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with("For more information"))
        .collect();
    assert_eq!(lines.len(), 1, "one line: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        !out.stderr
            .iter()
            .any(|&b| b < 0x20 && b != b'\n' || b == 0x7f),
        "a control character on stderr: {err:?}"
    );
    (out.status.code().unwrap_or(-1), lines[0].to_string())
}

fn iso() -> String {
    s(&test_support::test_data("ies/isotropic_10000lm.ies")).to_string()
}

fn png(dir: &Path, name: &str) -> String {
    let p = dir.join(name);
    image::RgbImage::from_fn(64, 32, |x, y| image::Rgb([x as u8 * 3, y as u8 * 5, 7]))
        .save(&p)
        .unwrap();
    s(&p).to_string()
}

// ---- 1. Numbers that size work or memory: the limits module --------------------------

#[test]
fn room_sides_light_counts_and_multipliers_are_checked_against_their_limits() {
    let light = format!("{}@0,2,0", iso());
    let t0 = Instant::now();
    // A room typed in millimetres, a room of 1e300, in every command that takes one.
    for room in ["4170x2990x2700", "1e300x5x3", "5x5x101"] {
        for cmd in [
            vec!["lux", "--at", "0,0,0"],
            vec!["render", "-o", "/dev/null", "--size", "64x32"],
        ] {
            let mut a = cmd.clone();
            a.extend_from_slice(&["--room", room, "--light", &light]);
            let (code, line) = one_line(&run(&a));
            assert_eq!(code, 2, "{a:?}: {line}");
            assert!(
                line.contains("room side") && line.contains("exceeds the limit of 100 m"),
                "{line}"
            );
        }
    }
    let (_, line) = one_line(&run(&[
        "lux",
        "--at",
        "0,0,0",
        "--room",
        "4170x2990x2700",
        "--light",
        &light,
    ]));
    assert!(
        line.contains("room side 4170 m exceeds the limit of 100 m"),
        "{line}"
    );
    // 201 luminaires on the command line: counted before a file is read.
    let mut a = vec!["lux", "--at", "0,0,0"];
    let lights: Vec<String> = (0..201).map(|_| light.clone()).collect();
    for l in &lights {
        a.extend_from_slice(&["--light", l]);
    }
    let (code, line) = one_line(&run(&a));
    assert_eq!(code, 2, "{line}");
    assert!(
        line.contains("luminaires 201 exceeds the limit of 200"),
        "{line}"
    );
    // A multiplier past its limit.
    let (code, line) = one_line(&run(&[
        "lux",
        "--at",
        "0,0,0",
        "--light",
        &light,
        "--light-multiplier",
        "1e308",
    ]));
    assert_eq!(code, 2, "{line}");
    assert!(line.contains("exceeds the limit of 1000000"), "{line}");
    assert!(t0.elapsed() < Duration::from_secs(60));
}

/// A scene file with `lights` luminaires and this room.
fn scene_file(dir: &Path, name: &str, room: [f64; 3], lights: usize, pano: &str) -> String {
    let light = serde_json::json!({"file": iso(), "position": [0.0, 2.0, 0.0]});
    let v = serde_json::json!({
        "format": "lutpano-scene", "version": 1, "panorama": pano,
        "room": {"width": room[0], "depth": room[1], "height": room[2], "camera_height": 1.5},
        "lights": vec![light; lights],
        "exposure_lux": 300.0, "ambient": 0.15
    });
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
    s(&p).to_string()
}

#[test]
fn scene_files_are_checked_against_the_same_limits_before_any_work() {
    let dir = tmpdir("classes", "scene-limits");
    let pano = png(&dir, "p.png");
    // 10 000 luminaires: refused at once (not minutes of loading), naming the limit.
    let many = scene_file(&dir, "many.json", [5.0, 5.0, 2.7], 10_000, &pano);
    let t0 = Instant::now();
    let (code, line) = one_line(&run(&["lux", "--scene", &many, "--at", "0,0,0"]));
    assert!(code == 1 || code == 2, "{line}");
    assert!(line.contains("10000 exceeds the limit of 200"), "{line}");
    assert!(t0.elapsed() < Duration::from_secs(10), "{:?}", t0.elapsed());
    // A 1000 m room in a scene file.
    let big = scene_file(&dir, "big.json", [1000.0, 5.0, 2.7], 1, &pano);
    for a in [
        vec!["lux", "--scene", &big, "--at", "0,0,0"],
        vec![
            "render",
            "--scene",
            &big,
            "-o",
            "/dev/null",
            "--size",
            "64x32",
        ],
    ] {
        let (code, line) = one_line(&run(&a));
        assert!(code == 1 || code == 2, "{line}");
        assert!(line.contains("1000 m exceeds the limit of 100 m"), "{line}");
    }
    // At the limit it works, in bounded time (the map's nodes are bounded too).
    let edge = scene_file(&dir, "edge.json", [100.0, 100.0, 100.0], 1, &pano);
    let out = run(&[
        "render",
        "--scene",
        &edge,
        "-o",
        "/dev/null",
        "--size",
        "64x32",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A tiled pyramid's `config.json` in `dir` with these `multiRes` numbers.
fn tile_config(dir: &Path, tile: &str, cube: &str, levels: &str) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join("config.json"),
        format!(
            "{{\"type\":\"multires\",\"multiRes\":{{\"path\":\"/%l/%s%y_%x\",\
             \"extension\":\"jpg\",\"tileResolution\":{tile},\"maxLevel\":{levels},\
             \"cubeResolution\":{cube}}}}}"
        ),
    )
    .unwrap();
    dir.to_path_buf()
}

#[test]
fn tile_configs_and_tours_are_checked_against_the_same_limits() {
    let dir = tmpdir("classes", "tile-limits");
    // Each number of a tiled pyramid's configuration, past its limit: refused at open,
    // the limit in the one line (lut_core::limits).
    for (tile, cube, levels, limit) in [
        (
            "512",
            "1e300",
            "3",
            lut_core::limits::MAX_CUBE_RESOLUTION.to_string(),
        ),
        (
            "100000",
            "1000",
            "3",
            lut_core::limits::MAX_TILE_RESOLUTION.to_string(),
        ),
        (
            "512",
            "1000",
            "60",
            lut_core::limits::MAX_TILE_LEVELS.to_string(),
        ),
    ] {
        let pyr = tile_config(&dir.join(format!("p{tile}-{levels}")), tile, cube, levels);
        let (code, line) = one_line(&run(&["render", s(&pyr), "-o", "/dev/null"]));
        assert_eq!(code, 1, "{line}");
        assert!(
            line.contains("config.json") && line.contains(&format!("..={limit}")),
            "{limit}: {line}"
        );
    }
    // A tour of more scenes than the limit: the rest are left out with one line naming it.
    let n = lut_core::limits::MAX_TOUR_SCENES + 1;
    let scenes: Vec<String> = (0..n)
        .map(|i| format!("\"s{i}\":{{\"panorama\":\"a.png\"}}"))
        .collect();
    let tour = dir.join("big.json");
    std::fs::write(
        &tour,
        format!(
            "{{\"default\":{{\"firstScene\":\"s0\"}},\"scenes\":{{{}}}}}",
            scenes.join(",")
        ),
    )
    .unwrap();
    let out = run(&["tour", "check", s(&tour)]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8_lossy(&out.stdout);
    let limit = format!("more than {} scenes", lut_core::limits::MAX_TOUR_SCENES);
    assert_eq!(
        text.lines().filter(|l| l.contains(&limit)).count(),
        1,
        "{}",
        &text[..text.len().min(500)]
    );
}

// ---- 2. Decoders behind one containment ---------------------------------------------

/// PNG chunk.
fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut v = u32::try_from(data.len()).unwrap().to_be_bytes().to_vec();
    v.extend_from_slice(kind);
    v.extend_from_slice(data);
    let mut h = crc32(kind);
    h = crc32_update(h, data);
    v.extend_from_slice(&(!h).to_be_bytes());
    v
}

fn crc32(d: &[u8]) -> u32 {
    crc32_update(0xFFFF_FFFF, d)
}

fn crc32_update(mut c: u32, d: &[u8]) -> u32 {
    for &b in d {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 == 1 {
                0xEDB8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    c
}

/// A 64×32 palette PNG with this PLTE chunk (`None`: the chunk's bytes as given, e.g.
/// with a wrong length or checksum).
fn palette_png(plte: &[u8], raw_plte: Option<Vec<u8>>, depth: u8) -> Vec<u8> {
    let (w, h) = (64u32, 32u32);
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[depth, 3, 0, 0, 0]);
    let row = (w as usize * depth as usize).div_ceil(8);
    let mut raw = Vec::new();
    for y in 0..h as usize {
        raw.push(0);
        raw.extend((0..row).map(|x| ((x * 37 + y) % 256) as u8));
    }
    // Stored (uncompressed) deflate blocks: no compressor needed.
    let mut z = vec![0x78, 0x01];
    for (i, part) in raw.chunks(65535).enumerate() {
        let last = (i + 1) * 65535 >= raw.len();
        z.push(u8::from(last));
        let n = u16::try_from(part.len()).unwrap();
        z.extend_from_slice(&n.to_le_bytes());
        z.extend_from_slice(&(!n).to_le_bytes());
        z.extend_from_slice(part);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &x in &raw {
        a = (a + u32::from(x)) % 65521;
        b = (b + a) % 65521;
    }
    z.extend_from_slice(&((b << 16) | a).to_be_bytes());
    let mut v = b"\x89PNG\r\n\x1a\n".to_vec();
    v.extend(chunk(b"IHDR", &ihdr));
    v.extend(raw_plte.unwrap_or_else(|| chunk(b"PLTE", plte)));
    v.extend(chunk(b"IDAT", &z));
    v.extend(chunk(b"IEND", &[]));
    v
}

#[test]
fn damaged_palette_pngs_exit_1_with_one_line() {
    let dir = tmpdir("classes", "plte");
    let good = palette_png(&[10, 20, 30].repeat(256), None, 8);
    let mut bad_crc = chunk(b"PLTE", &[1, 2, 3, 4, 5, 6]);
    let n = bad_crc.len();
    bad_crc[n - 1] ^= 0xFF;
    let mut wrong_len = chunk(b"PLTE", &[1, 2, 3, 4, 5, 6]);
    wrong_len[3] = 200;
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("good", good),
        ("two-bytes", palette_png(&[1, 2], None, 8)),
        ("empty", palette_png(&[], None, 8)),
        ("one-entry", palette_png(&[1, 2, 3], None, 8)),
        ("one-entry-4bit", palette_png(&[1, 2, 3], None, 4)),
        ("too-long", palette_png(&[7; 3 * 300], None, 8)),
        ("bad-crc", palette_png(&[], Some(bad_crc), 8)),
        ("wrong-length", palette_png(&[], Some(wrong_len), 8)),
    ];
    for (name, bytes) in cases {
        let p = dir.join(format!("{name}.png"));
        std::fs::write(&p, bytes).unwrap();
        let out = run(&["render", s(&p), "-o", "/dev/null", "--size", "64x32"]);
        match out.status.code() {
            // A palette too short for the indices: decoded (missing entries black).
            Some(0) => assert!(out.stderr.is_empty(), "{name}"),
            _ => {
                let (code, line) = one_line(&out);
                assert_eq!(code, 1, "{name}: {line}");
                assert!(line.contains(&format!("{name}.png")), "{line}");
            }
        }
        if name == "good" {
            assert!(out.status.success());
        }
    }
}

#[test]
fn a_panic_in_any_decoder_is_the_files_error() {
    // The fault point panics inside the containment every image decoder runs behind.
    let dir = tmpdir("classes", "contain");
    let img = image::RgbImage::from_fn(64, 32, |x, _| image::Rgb([x as u8, 1, 2]));
    for ext in ["png", "jpg", "exr", "hdr"] {
        let p = dir.join(format!("a.{ext}"));
        match ext {
            "exr" | "hdr" => image::DynamicImage::ImageRgb8(img.clone())
                .into_rgb32f()
                .save(&p)
                .unwrap(),
            _ => img.save(&p).unwrap(),
        }
        let args = ["render", s(&p), "-o", "/dev/null", "--size", "64x32"];
        assert!(run(&args).status.success(), "{ext} loads without the fault");
        let faces = dir.join("faces");
        let convert = ["convert", s(&p), s(&faces), "--to", "cube"];
        assert!(
            run(&convert).status.success(),
            "{ext} converts without the fault"
        );
        let out = run_env(&args, &[(lut_core::FAULT_ENV, "decoder")], 20);
        let (code, line) = one_line(&out);
        assert_eq!(code, 1, "{line}");
        assert!(
            line.contains(&format!("a.{ext}")) && line.contains("damaged"),
            "{line}"
        );
        // convert too (a cube's faces go through the same loader).
        let out = run_env(&convert, &[(lut_core::FAULT_ENV, "decoder")], 20);
        assert_eq!(one_line(&out).0, 1);
    }
}

#[test]
fn a_panic_in_the_tour_tile_config_and_band_readers_is_the_files_error() {
    // The same fault point, inside the same containment, on the new input paths.
    let dir = tmpdir("classes", "contain-new");
    let tour = test_support::test_data("tours/pannellum/tour.json");
    let js = test_support::test_data("tours/marzipano/data.js");
    let pyr = test_support::test_data("multires/generate-py");
    let pano = png(&dir, "a.png");
    let tiles = dir.join("tiles");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["tour", "check", s(&tour)], "tour.json"),
        (vec!["tour", "check", s(&js)], "data.js"),
        (
            vec!["render", s(&pyr), "-o", "/dev/null", "--size", "64x32"],
            "config.json",
        ),
        (
            vec!["tile", pano.as_str(), "-o", s(&tiles), "--quiet"],
            "a.png",
        ),
    ];
    for (args, name) in cases {
        assert!(
            run(&args).status.success(),
            "{args:?} works without the fault"
        );
        let out = run_env(&args, &[(lut_core::FAULT_ENV, "decoder")], 20);
        let (code, line) = one_line(&out);
        assert_eq!(code, 1, "{args:?}: {line}");
        assert!(line.contains(name) && line.contains("damaged"), "{line}");
    }
}

// ---- 3. Image data shorter than its header ------------------------------------------

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
fn jpegs_shorter_than_their_header_are_refused() {
    let dir = tmpdir("classes", "short-jpeg");
    let cases = [
        ("more-lines.jpg", jpeg_claiming(64, 128, 0), "truncated"),
        (
            "padded-32k.jpg",
            jpeg_claiming(32768, 16384, 1_200_000),
            "image data",
        ),
    ];
    for (name, bytes, why) in cases {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        let t0 = Instant::now();
        // Any aspect ratio (the header's is 1:2 or 2:1).
        for a in [
            vec![
                "render",
                s(&p),
                "-o",
                "/dev/null",
                "--size",
                "64x32",
                "--projection",
                "elliptical",
            ],
            vec![
                "convert",
                s(&p),
                s(&dir),
                "--to",
                "cube",
                "--projection",
                "elliptical",
            ],
        ] {
            let (code, line) = one_line(&run(&a));
            assert_eq!(code, 1, "{line}");
            assert!(line.contains(name) && line.contains(why), "{line}");
        }
        assert!(t0.elapsed() < Duration::from_secs(20));
    }
}

// ---- 4. Special files: one check for every input path --------------------------------

#[cfg(unix)]
#[test]
fn fifos_as_scene_files_are_refused_without_blocking() {
    let dir = tmpdir("classes", "fifo");
    let fifo = dir.join("scene.json");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for a in [
        vec!["lux", "--scene", s(&fifo), "--at", "0,0,0"],
        vec!["render", "--scene", s(&fifo), "-o", "/dev/null"],
    ] {
        let (code, line) = one_line(&run(&a));
        assert_eq!(code, 1, "{line}");
        assert!(line.contains("FIFO"), "{line}");
    }
    // A FIFO as a luminaire file, and a folder as a scene.
    let light = format!("{}@0,2,0", s(&fifo));
    let (code, line) = one_line(&run(&["lux", "--light", &light, "--at", "0,0,0"]));
    assert_eq!(code, 1, "{line}");
    assert!(line.contains("FIFO"), "{line}");
    let (code, line) = one_line(&run(&["lux", "--scene", s(&dir), "--at", "0,0,0"]));
    assert_eq!(code, 1, "{line}");
    assert!(line.contains("folder"), "{line}");
}

#[cfg(unix)]
#[test]
fn fifos_as_tours_tile_configs_and_tiles_are_refused_without_blocking() {
    let dir = tmpdir("classes", "fifo-new");
    let mkfifo = |p: &Path| {
        assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
    };
    // A FIFO as a tour file (either format) and as a tile configuration (named, or as
    // the config.json of a folder).
    let (tour, js, cfg) = (dir.join("t.json"), dir.join("data.js"), dir.join("c.json"));
    let pyr = dir.join("pyr");
    std::fs::create_dir_all(&pyr).unwrap();
    for p in [&tour, &js, &cfg, &pyr.join("config.json")] {
        mkfifo(p);
    }
    for a in [
        vec!["tour", "check", s(&tour)],
        vec!["tour", "check", s(&js)],
        vec!["tour", "convert", s(&tour), "-o", s(&dir.join("out.json"))],
        vec!["render", s(&cfg), "-o", "/dev/null"],
        vec!["render", s(&pyr), "-o", "/dev/null"],
    ] {
        let (code, line) = one_line(&run(&a));
        assert_eq!(code, 1, "{a:?}: {line}");
        assert!(line.contains("FIFO"), "{line}");
    }
    // A FIFO as one tile of a pyramid: the tile is refused (its error named), never
    // waited on; the frame is made without it.
    let good = test_support::test_data("multires/generate-py");
    let copy = dir.join("copy");
    copy_tree(&good, &copy);
    let tile = std::fs::read_dir(copy.join("1"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "jpg"))
        .expect("a level-1 tile");
    std::fs::remove_file(&tile).unwrap();
    mkfifo(&tile);
    let out = run(&["render", s(&copy), "-o", "/dev/null", "--size", "64x32"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // The frame is made, with a warning naming the tile and why.
    let name = tile.file_name().unwrap().to_str().unwrap();
    assert!(
        err.lines()
            .any(|l| l.starts_with("warning:") && l.contains(name) && l.contains("FIFO")),
        "{err}"
    );
}

/// Copy the files of `from` (one level of folders deep) into `to`.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let dst = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_tree(&e.path(), &dst);
        } else {
            std::fs::copy(e.path(), dst).unwrap();
        }
    }
}

/// Every level-1 JPEG tile of a copy of the test pyramid in `dir`, and the copy.
fn pyramid_copy(dir: &Path) -> (std::path::PathBuf, Vec<std::path::PathBuf>) {
    let copy = dir.join("pyr");
    copy_tree(&test_support::test_data("multires/generate-py"), &copy);
    let mut tiles: Vec<_> = std::fs::read_dir(copy.join("1"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "jpg"))
        .collect();
    tiles.sort();
    (copy, tiles)
}

#[test]
fn a_panic_in_a_tile_decode_is_that_tiles_error() {
    // The fault point inside the tile decoder's containment (`tile`), on every tile:
    // each is its own error, named in a warning; the frame is still made (from the
    // background), and nothing waits for a tile whose decoding thread died.
    let dir = tmpdir("classes", "contain-tile");
    let (pyr, tiles) = pyramid_copy(&dir);
    let args = ["render", s(&pyr), "-o", "/dev/null", "--size", "64x32"];
    let out = run_env(&args, &[(lut_core::FAULT_ENV, "tile")], 20);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for t in &tiles {
        let name = t.file_name().unwrap().to_str().unwrap();
        assert!(
            err.lines().any(|l| l.starts_with("warning:")
                && l.contains(name)
                && l.contains("the decoder failed")),
            "{name}: {err}"
        );
    }
    // Without the fault: no warning.
    let out = run(&args);
    assert_eq!(out.status.code(), Some(0));
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_jpeg_tile_shorter_than_its_header_is_a_named_warning_never_filled_in() {
    // A tile cut short: `image`'s lenient JPEG decoder fills the missing rows with grey
    // and reports success; through the map loader's strict decoder it is the tile's
    // error, named, and the frame is drawn from the coarser level instead.
    let dir = tmpdir("classes", "short-tile");
    let (pyr, tiles) = pyramid_copy(&dir);
    let tile = &tiles[0];
    let bytes = std::fs::read(tile).unwrap();
    let cut = &bytes[..bytes.len() * 2 / 3];
    assert!(
        image::load_from_memory(cut).is_ok(),
        "the lenient decoder takes the cut tile (else this test proves nothing)"
    );
    std::fs::write(tile, cut).unwrap();
    let out = run(&["render", s(&pyr), "-o", "/dev/null", "--size", "64x32"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    let name = tile.file_name().unwrap().to_str().unwrap();
    assert!(
        err.lines()
            .any(|l| l.starts_with("warning:") && l.contains(name) && l.contains("truncated")),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}

#[cfg(unix)]
#[test]
fn tour_and_pyramid_outputs_are_whole_ordinary_files() {
    use std::os::unix::fs::PermissionsExt;
    // `tour convert` and `viewer tile` write their JSON through the one output writer:
    // renamed into place whole, with an ordinary file's permissions (a temporary file's
    // 0600 would keep a web server from serving the tour or the pyramid), no temporary
    // file left beside it.
    let dir = tmpdir("classes", "outputs");
    let src = test_support::test_data("tours/pannellum");
    copy_tree(&src, &dir.join("tour"));
    let out_json = dir.join("tour").join("converted.json");
    let out = run(&[
        "tour",
        "convert",
        s(&dir.join("tour/tour.json")),
        "-o",
        s(&out_json),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let pano = png(&dir, "a.png");
    let tiles = dir.join("tiles");
    let out = run(&["tile", &pano, "-o", s(&tiles), "--quiet"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for (f, folder) in [
        (out_json.clone(), dir.join("tour")),
        (tiles.join("config.json"), tiles.clone()),
    ] {
        let mode = std::fs::metadata(&f).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode & 0o044, 0o044, "{}: mode {mode:o}", f.display());
        serde_json::from_str::<serde_json::Value>(&std::fs::read_to_string(&f).unwrap()).unwrap();
        for e in std::fs::read_dir(folder).unwrap() {
            let n = e.unwrap().file_name().to_string_lossy().into_owned();
            assert!(!n.ends_with(".tmp"), "a temporary file left: {n}");
        }
    }
}

// ---- 5. Text from input echoed: escaped and shortened ------------------------------

#[test]
fn echoed_names_and_numbers_are_escaped_and_shortened() {
    let dir = tmpdir("classes", "echo");
    // A scene whose panorama path holds an escape sequence that would retitle the
    // terminal, and a luminaire path with a line break.
    let scene = scene_file(
        &dir,
        "esc.json",
        [5.0, 5.0, 2.7],
        0,
        "\u{1b}]0;owned\u{7}\n.jpg",
    );
    let out = run(&["render", "--scene", &scene, "-o", "/dev/null"]);
    let (code, line) = one_line(&out);
    assert_eq!(code, 1, "{line}");
    assert!(line.contains("\\u{1b}]0;owned\\u{7}\\n.jpg"), "{line}");
    // A 100 000-character file name and a 309-digit number are shortened.
    let long = dir.join("n".repeat(200)).join("x".repeat(100_000));
    let nines = "9".repeat(309);
    for a in [
        vec![
            "render".to_string(),
            s(&long).to_string(),
            "-o".into(),
            "/dev/null".into(),
        ],
        vec!["render".into(), "--hfov".into(), nines.clone()],
        vec!["lux".into(), "--at".into(), format!("{nines},0,0")],
        vec![
            "lux".into(),
            "--room".into(),
            format!("{nines}x1x1"),
            "--at".into(),
            "0,0,0".into(),
        ],
    ] {
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        let out = run(&a);
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(err.len() < 1500, "{} bytes: {}", err.len(), &err[..300]);
        assert!(err.contains("characters)"), "{err}");
        assert!(matches!(out.status.code(), Some(1 | 2)), "{err}");
    }
}

#[test]
fn text_from_tours_is_escaped_and_shortened_on_every_line() {
    let dir = tmpdir("classes", "echo-tour");
    // Scene ids, titles and paths holding an escape sequence (it would retitle the
    // terminal), a line break, a bidi override, and a 100 000-character path: every
    // line `tour check` prints (standard output and error) is one safe, short line.
    let long = "x".repeat(100_000);
    let tour = dir.join("t.json");
    std::fs::write(
        &tour,
        format!(
            "{{\"default\":{{\"firstScene\":\"a\\u001b]0;owned\\u0007\"}},\"scenes\":{{\
             \"a\\u001b]0;owned\\u0007\":{{\"title\":\"t\\n\\u202e\",\"panorama\":\"p\\u001b[2J.jpg\",\
             \"hotSpots\":[{{\"pitch\":0,\"yaw\":0,\"type\":\"scene\",\"sceneId\":\"{long}\"}}]}},\
             \"b\":{{\"panorama\":\"{long}.jpg\"}},\"c\":{{\"panorama\":\"q\\u001b[2J.jpg\"}}}}}}"
        ),
    )
    .unwrap();
    let out = run(&["tour", "check", s(&tour)]);
    assert_eq!(out.status.code(), Some(1));
    for (what, bytes) in [("stdout", &out.stdout), ("stderr", &out.stderr)] {
        assert!(
            !bytes.iter().any(|&b| b < 0x20 && b != b'\n' || b == 0x7f),
            "a control character on {what}: {:?}",
            String::from_utf8_lossy(bytes)
        );
        let text = String::from_utf8_lossy(bytes);
        assert!(!text.contains('\u{202e}'), "{what}: {text}");
        for l in text.lines() {
            assert!(
                l.chars().count() <= lut_core::MESSAGE_MAX_CHARS,
                "{what}: {l}"
            );
        }
    }
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("\\u{1b}[2J"), "{text}");
    assert!(text.contains("characters)"), "{text}");
}

// ---- 6. Output that is not a number: refused, one status per option -----------------

#[test]
fn json_never_holds_null_and_options_exit_alike_in_every_command() {
    let light = format!("{}@0,2,0", iso());
    // The same bad multiplier exits 2 in lux and render.
    for v in ["nan", "inf", "-1", "1e308"] {
        let m = format!("--light-multiplier={v}");
        let lux = run(&["lux", "--at", "0,0,0", "--light", &light, &m]);
        let render = run(&[
            "render",
            "-o",
            "/dev/null",
            "--size",
            "64x32",
            "--light",
            &light,
            &m,
        ]);
        assert_eq!(one_line(&lux).0, 2, "lux {v}");
        assert_eq!(one_line(&render).0, 2, "render {v}");
    }
    // Denormal normals have a direction: finite JSON, the unit normal.
    let out = run(&[
        "lux",
        "--json",
        "--light",
        &light,
        "--at",
        "0,1,0:5e-324,0,0",
        "--at",
        "0,1,0:0,1e-310,0",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(!text.contains("null"), "{text}");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["points"][0]["normal"], serde_json::json!([1.0, 0.0, 0.0]));
    assert_eq!(v["points"][1]["normal"], serde_json::json!([0.0, 1.0, 0.0]));
    // The largest multiplier accepted still gives finite lux.
    let out = run(&[
        "lux",
        "--json",
        "--light",
        &light,
        "--at",
        "0,0,0",
        "--light-multiplier",
        "1e6",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["points"][0]["lux"].as_f64().unwrap().is_finite());
}

#[test]
fn report_json_goes_through_the_one_json_writer() {
    // `viewer report --json` holds only finite numbers (never null), at the largest
    // multiplier accepted too.
    let dir = tmpdir("classes", "report-json");
    let light = format!("{}@0,2.5,0", iso());
    for m in ["1", "1e6"] {
        let out_json = dir.join(format!("r{m}.json"));
        let out = run(&[
            "report",
            "--room",
            "5x5x3",
            "--light",
            &light,
            "--light-multiplier",
            m,
            "--json",
            s(&out_json),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(&out_json).unwrap();
        assert!(!text.contains("null"), "{text}");
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert!(v["total_flux_lm"].as_f64().unwrap().is_finite());
    }
}

#[test]
fn report_text_and_page_escape_and_shorten_the_luminaire_file_names() {
    // A photometric file whose name holds an escape sequence (it would retitle the
    // terminal) and a long run: the text on standard output and the HTML page echo it
    // escaped and shortened; the JSON keeps it exactly (escaped by JSON itself).
    let dir = tmpdir("classes", "report-names");
    let name = format!("a\u{1b}]0;owned\u{7}{}.ies", "x".repeat(230));
    let lamp = dir.join(&name);
    std::fs::copy(iso(), &lamp).unwrap();
    let light = format!("{}@0,2.5,0", s(&lamp));
    let (j, h) = (dir.join("r.json"), dir.join("r.html"));
    let out = run(&[
        "report",
        "--room",
        "5x5x3",
        "--light",
        &light,
        "--json",
        s(&j),
        "--html",
        s(&h),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let page = std::fs::read_to_string(&h).unwrap();
    for (what, t) in [("stdout", text.as_ref()), ("page", page.as_str())] {
        assert!(
            !t.bytes().any(|b| b < 0x20 && b != b'\n' || b == 0x7f),
            "a control character in the {what}"
        );
        assert!(!t.contains(&"x".repeat(220)), "{what}: the name in full");
        assert!(t.contains("characters)"), "{what}: not shortened");
    }
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&j).unwrap()).unwrap();
    assert!(
        v.to_string().contains(&"x".repeat(230)),
        "the JSON keeps the name"
    );
}

// ---- 8. The window: a missing file and a damaged one alike --------------------------

#[test]
fn the_window_treats_a_missing_and_a_damaged_panorama_alike() {
    // Without a display the window cannot open: a missing panorama and a damaged one
    // get the same answer (neither is judged before the window, which shows either as
    // its error over the bundled sample).
    let dir = tmpdir("classes", "window");
    let damaged = dir.join("damaged.jpg");
    std::fs::write(&damaged, b"\xFF\xD8\xFF garbage").unwrap();
    let missing = dir.join("missing.jpg");
    let env = [("DISPLAY", ""), ("WAYLAND_DISPLAY", "")];
    let a = one_line(&run_env(&[s(&damaged)], &env, 20));
    let b = one_line(&run_env(&[s(&missing)], &env, 20));
    assert_eq!(a, b);
    assert_eq!(a.0, 1);
    assert!(a.1.contains("no display"), "{}", a.1);
}

//! The faults found from outside (issue 15), end to end through the `viewer` binary:
//! damaged inputs, special files as inputs and outputs, outputs that are inputs, closed
//! and full standard output, signals during a write, output formats, and the one rule for
//! exit statuses (0 done, 1 a file or device failed, 2 a usage error).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

mod common;
use common::{s, viewer};

fn tmpdir(name: &str) -> PathBuf {
    common::tmpdir("viewer-reliability-cli", name)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Exit status `code`, no panic, and a message containing every one of `needles`.
fn assert_exit(o: &Output, code: i32, needles: &[&str], what: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{what}: {err}");
    assert!(!err.contains("panicked"), "{what} panicked: {err}");
    for n in needles {
        assert!(err.contains(n), "{what}: '{n}' missing from: {err}");
    }
}

/// No `.viewer-*.tmp` left in `dir`.
fn no_temporaries(dir: &Path) {
    let left: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".viewer-") && n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

fn sample_jpeg() -> Vec<u8> {
    std::fs::read(test_support::repo_root().join("assets/courtyard.jpg")).unwrap()
}

#[test]
fn damaged_jpegs_are_refused_by_render_and_convert() {
    let d = tmpdir("damaged");
    let full = sample_jpeg();
    let out = d.join("out.png");
    for (name, cut) in [
        ("cut10.jpg", full.len() / 10),
        ("cut50.jpg", full.len() / 2),
    ] {
        let p = d.join(name);
        std::fs::write(&p, &full[..cut]).unwrap();
        let o = viewer(&["render", s(&p), "-o", s(&out), "--size", "64x32"]);
        assert_exit(&o, 1, &[name, "truncated"], name);
        let faces = d.join("faces");
        let o = viewer(&["convert", s(&p), s(&faces), "--to", "cube"]);
        assert_exit(&o, 1, &[name, "truncated"], name);
        assert!(!out.exists() && !faces.exists());
    }
    // 32768 x 16384 claimed by a 2.3 KB file: refused from its size, not decoded.
    let mut tiny = test_support::bombs::jpeg_header_only(32768, 16384);
    tiny.truncate(tiny.len() - 2);
    tiny.extend_from_slice(&[0xFF, 0xFE, 0x08, 0xE8]);
    tiny.extend(std::iter::repeat_n(b'x', 0x08E8 - 2));
    tiny.extend_from_slice(&[0xFF, 0xD9]);
    let p = d.join("claims-32k.jpg");
    std::fs::write(&p, &tiny).unwrap();
    let o = viewer(&["render", s(&p), "-o", s(&out)]);
    assert_exit(&o, 1, &["claims-32k.jpg", "32768x16384", "at most"], "tiny");
    no_temporaries(&d);
}

#[test]
fn outputs_that_are_inputs_are_refused() {
    let d = tmpdir("same");
    let pano = d.join("pano.jpg");
    std::fs::write(&pano, sample_jpeg()).unwrap();
    let before = std::fs::read(&pano).unwrap();
    let o = viewer(&["render", s(&pano), "-o", s(&pano), "--size", "32x16"]);
    assert_exit(&o, 1, &["pano.jpg", "input"], "same name");
    #[cfg(unix)]
    {
        let hard = d.join("hard.jpg");
        std::fs::hard_link(&pano, &hard).unwrap();
        let o = viewer(&["render", s(&pano), "-o", s(&hard), "--size", "32x16"]);
        assert_exit(&o, 1, &["hard.jpg", "input"], "hard link");
        let soft = d.join("soft.jpg");
        std::os::unix::fs::symlink(&pano, &soft).unwrap();
        let o = viewer(&["render", s(&soft), "-o", s(&pano), "--size", "32x16"]);
        assert_exit(&o, 1, &["input"], "symbolic link");
    }
    // convert: one of the input faces as the output, and a face folder written over its
    // own faces.
    let faces = d.join("faces");
    let o = viewer(&[
        "convert",
        s(&pano),
        s(&faces),
        "--to",
        "cube",
        "--face-size",
        "8",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let front = faces.join("front.png");
    let o = viewer(&["convert", s(&faces), s(&front), "--to", "equirect"]);
    assert_exit(&o, 1, &["front.png", "input"], "a face as output");
    let o = viewer(&[
        "convert",
        s(&front),
        s(&faces),
        "--to",
        "cube",
        "--projection",
        "equirect",
    ]);
    // (front.png is square, so it is refused as an equirect or as an input; either way
    // it must not be overwritten)
    assert!(!o.status.success());
    assert_eq!(std::fs::read(&pano).unwrap(), before, "the input changed");
    assert!(image::open(&front).is_ok());
    no_temporaries(&d);
}

#[cfg(unix)]
fn mkfifo(p: &Path) {
    assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
}

#[cfg(unix)]
#[test]
fn special_files_are_written_into_never_replaced() {
    use std::os::unix::fs::FileTypeExt;
    let o = viewer(&["render", "-o", "/dev/null", "--size", "32x16"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    // A FIFO with a reader gets the PNG and stays a FIFO.
    let d = tmpdir("fifo-out");
    let fifo = d.join("view.png");
    mkfifo(&fifo);
    let f = fifo.clone();
    let reader = std::thread::spawn(move || std::fs::read(f).unwrap());
    let o = viewer(&["render", "-o", s(&fifo), "--size", "32x16"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = reader.join().unwrap();
    let img = image::load_from_memory(&bytes).unwrap();
    assert_eq!((img.width(), img.height()), (32, 16));
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    // Standard output as the file (no extension: PNG).
    let o = viewer(&["render", "-o", "/dev/stdout", "--size", "32x16"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        image::guess_format(&o.stdout).unwrap(),
        image::ImageFormat::Png
    );
    // A full device: an error, not a panic.
    if Path::new("/dev/full").exists() {
        let o = viewer(&["render", "-o", "/dev/full", "--size", "32x16"]);
        assert_exit(&o, 1, &["/dev/full", "space"], "/dev/full");
    }
    no_temporaries(&d);
}

#[cfg(unix)]
#[test]
fn fifos_as_inputs_are_refused_without_blocking() {
    let d = tmpdir("fifo-in");
    let fifo = d.join("pano.jpg");
    mkfifo(&fifo);
    let out = d.join("o.png");
    let t = Instant::now();
    let o = viewer(&["render", s(&fifo), "-o", s(&out)]);
    assert_exit(&o, 1, &["pano.jpg", "FIFO"], "FIFO panorama");
    // A FIFO face in a cube folder.
    let faces = d.join("faces");
    std::fs::create_dir(&faces).unwrap();
    for f in ["front", "right", "back", "left", "up"] {
        image::RgbImage::new(8, 8)
            .save(faces.join(format!("{f}.png")))
            .unwrap();
    }
    mkfifo(&faces.join("down.png"));
    let o = viewer(&["render", s(&faces), "-o", s(&out), "--size", "32x16"]);
    assert_exit(&o, 1, &["down.png", "FIFO"], "FIFO face");
    // Both answered (a blocking open would still be waiting).
    assert!(t.elapsed() < Duration::from_secs(60));
    // A symbolic-link loop as a face: named, with the reason.
    std::fs::remove_file(faces.join("down.png")).unwrap();
    std::os::unix::fs::symlink("loop.png", faces.join("down.png")).unwrap();
    std::os::unix::fs::symlink("down.png", faces.join("loop.png")).unwrap();
    let o = viewer(&["render", s(&faces), "-o", s(&out), "--size", "32x16"]);
    assert_exit(&o, 1, &["down.png", "symbolic links"], "link loop");
}

#[test]
fn ies_messages_never_echo_raw_control_characters() {
    let d = tmpdir("ies");
    let p = d.join("hostile.ies");
    std::fs::write(
        &p,
        "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 \x1b]0;pwned\x07 3 1 1 2 0 0 0\n",
    )
    .unwrap();
    let o = viewer(&["ies", s(&p)]);
    assert_exit(&o, 1, &["hostile.ies"], "hostile IES");
    assert!(
        !o.stderr.iter().any(|&b| b == 0x1b || b == 0x07),
        "raw control bytes in: {:?}",
        stderr(&o)
    );
}

fn ies_file() -> PathBuf {
    test_support::test_data("ies/type_b_full.ies")
}

#[test]
fn a_closed_pipe_ends_quietly_and_a_full_disk_is_an_error() {
    // The reader is gone before the viewer writes: EPIPE on the first line.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let o = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .args(["ies", s(&ies_file())])
        .stdout(writer)
        .stderr(Stdio::piped())
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    assert_exit(&o, 0, &[], "closed pipe");
    assert!(stderr(&o).is_empty(), "{}", stderr(&o));
    #[cfg(unix)]
    if Path::new("/dev/full").exists() {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_viewer"))
            .args(["ies", s(&ies_file())])
            .stdout(full)
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_exit(&o, 1, &["standard output", "space"], "full stdout");
        // The error itself cannot be printed to a full stderr: still no panic (101).
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = Command::new(env!("CARGO_BIN_EXE_viewer"))
            .args(["ies", "/no/such/file.ies"])
            .stderr(full)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1));
    }
}

/// Start a render big enough to take a while, wait until its temporary file exists, send
/// `signal`; the process must die of it and leave neither the temporary nor the output.
#[cfg(unix)]
fn interrupt_a_write(signal: &str, number: i32) {
    use std::os::unix::process::ExitStatusExt;
    let d = tmpdir(&format!("signal-{signal}"));
    let out = d.join("big.png");
    let mut child = Command::new(env!("CARGO_BIN_EXE_viewer"))
        .args([
            "render",
            "-o",
            s(&out),
            "--size",
            "4096x4096",
            "--sampler",
            "nearest",
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let tmp_exists = || {
        std::fs::read_dir(&d)
            .unwrap()
            .filter_map(|e| e.ok())
            .any(|e| {
                let n = e.file_name().to_string_lossy().into_owned();
                n.starts_with(".viewer-") && n.ends_with(".tmp")
            })
    };
    while !tmp_exists() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "the render finished before its temporary file was seen"
        );
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "no temporary file"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    assert!(Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let status = child.wait().unwrap();
    assert_eq!(status.signal(), Some(number), "{status:?}");
    no_temporaries(&d);
    assert!(!out.exists(), "a half-written output");
}

#[cfg(unix)]
#[test]
fn signals_during_a_write_leave_no_temporary_file() {
    interrupt_a_write("TERM", 15);
    interrupt_a_write("INT", 2);
}

#[test]
fn a_stale_temporary_file_does_not_matter() {
    let d = tmpdir("stale");
    // What a SIGKILL might leave behind, with the name pattern the viewer uses.
    let stale = d.join(".viewer-AbCd12.tmp");
    std::fs::write(&stale, b"half an image").unwrap();
    let out = d.join("o.png");
    let o = viewer(&["render", "-o", s(&out), "--size", "32x16"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(image::open(&out).is_ok());
    assert_eq!(std::fs::read(&stale).unwrap(), b"half an image");
}

#[test]
fn output_formats_follow_the_name() {
    let d = tmpdir("formats");
    for (name, format) in [
        ("a.png", image::ImageFormat::Png),
        ("b.JPG", image::ImageFormat::Jpeg),
    ] {
        let p = d.join(name);
        let o = viewer(&["render", "-o", s(&p), "--size", "32x16"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let bytes = std::fs::read(&p).unwrap();
        assert_eq!(image::guess_format(&bytes).unwrap(), format, "{name}");
    }
    for name in ["c.bmp", "d.exr", "noext"] {
        let p = d.join(name);
        let o = viewer(&["render", "-o", s(&p), "--size", "32x16"]);
        assert_exit(&o, 2, &[name, ".png"], name);
        assert!(!p.exists());
        let o = viewer(&[
            "convert",
            s(&test_support::repo_root().join("assets/courtyard.jpg")),
            s(&p),
            "--to",
            "cube",
            "--layout",
            "cross",
        ]);
        assert_exit(&o, 2, &[name], name);
        assert!(!p.exists());
    }
    no_temporaries(&d);
}

/// The rule: every bad command-line value exits 2, whichever parser finds it; a file
/// that cannot be used exits 1.
#[test]
fn exit_statuses_follow_one_rule() {
    let d = tmpdir("codes");
    let out = d.join("o.png");
    let o = s(&out);
    let sample = test_support::repo_root().join("assets/courtyard.jpg");
    let sample = s(&sample);
    let faces = test_support::test_data("cube/skyfantasy");
    let faces = s(&faces);
    let ies = ies_file();
    let ies = s(&ies);
    let light = format!("{ies}@0,2,0");
    let outside = format!("{ies}@99,2,0");
    let new_faces = d.join("faces");
    let new_faces = s(&new_faces);
    let usage: Vec<Vec<&str>> = vec![
        vec!["render", "-o", o, "--hfov", "180"],
        vec!["render", "-o", o, "--hfov", "0"],
        vec!["render", "-o", o, "--size", "0x10"],
        vec!["render", "-o", o, "--sampler", "cubic"],
        vec!["render", "-o", o, "--yaw", "nan"],
        vec!["render", "-o", o, "--no-such-flag"],
        vec!["render", "-o", o, "--max-pixels", "0"],
        vec!["render", "-o", o, "--coverage", "120x60+30"],
        vec!["render", faces, "-o", o, "--coverage", "120x60"],
        vec![
            "render",
            sample,
            sample,
            "-o",
            o,
            "--projection",
            "equirect",
        ],
        vec!["render", "-o", o, "--light", "lamp.ies"],
        vec!["render", "-o", o, "--light", &light, "--exposure-lux", "-1"],
        vec!["render", "-o", o, "--light", &light, "--room", "0x5x3"],
        vec![
            "render",
            "-o",
            o,
            "--light",
            &light,
            "--camera-height",
            "-1",
        ],
        vec!["render", "-o", o, "--light", &outside],
        vec![
            "render",
            "-o",
            o,
            "--pannini-d",
            "1",
            "--view-projection",
            "fisheye",
        ],
        vec![
            "render",
            "-o",
            o,
            "--view-projection",
            "fisheye",
            "--view-limit",
        ],
        vec![
            "render",
            "-o",
            o,
            "--view-projection",
            "fisheye",
            "--hfov",
            "400",
        ],
        vec!["render", "-o", o, "--error-map", "heat.bmp"],
        vec!["convert", sample, o, "--to", "sphere"],
        vec!["convert", faces, o, "--to", "equirect", "--size", "100x100"],
        vec!["convert", faces, o, "--to", "equirect", "--face-size", "8"],
        vec![
            "convert", sample, new_faces, "--to", "cube", "--size", "8x8",
        ],
        vec![
            "convert",
            sample,
            new_faces,
            "--to",
            "cube",
            "--face-size",
            "0",
        ],
        vec!["convert", sample, sample, new_faces, "--to", "cube"],
        vec![
            "convert",
            sample,
            new_faces,
            "--to",
            "cube",
            "--projection",
            "cube",
        ],
        vec!["convert", sample, "c.png", "--to", "cube"],
        vec![
            "render",
            sample,
            "-o",
            o,
            "--layout",
            "cross",
            "--projection",
            "cube",
            "--naming",
            "x",
        ],
        vec!["render", faces, "-o", o, "--layout", "cross"],
        vec!["ies", ies, "--sample", "30"],
        vec!["bench", "--passes", "0"],
        vec!["bench", "--threads", "0"],
    ];
    for args in &usage {
        let r = viewer(args);
        assert_exit(&r, 2, &[], &format!("{args:?}"));
    }
    let missing = d.join("missing.jpg");
    let nowhere = d.join("no/such/o.png");
    let text = d.join("notes.jpg");
    std::fs::write(&text, "not an image").unwrap();
    let files: Vec<Vec<&str>> = vec![
        vec!["render", s(&missing), "-o", o],
        vec!["render", s(&text), "-o", o],
        vec!["render", "-o", s(&nowhere)],
        vec!["convert", s(&missing), new_faces, "--to", "cube"],
        vec!["ies", "/no/such/file.ies"],
        vec!["render", "-o", o, "--light", "/no/such/lamp.ies@0,2,0"],
    ];
    for args in &files {
        let r = viewer(args);
        assert_exit(&r, 1, &[], &format!("{args:?}"));
    }
}

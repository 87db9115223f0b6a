//! `LUTPANO_KERNEL`: a bad value is refused with a one-line message before anything runs;
//! the scalar kernel renders the same bytes as the one the CPU picks.

use std::process::{Command, Output};

mod common;
use common::s;

fn viewer_with(kernel: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_viewer"))
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .env("LUTPANO_KERNEL", kernel)
        .output()
        .expect("run viewer")
}

#[test]
fn a_bad_kernel_name_is_refused() {
    let d = common::tmpdir("viewer-kernel-env", "bad");
    let out = d.join("view.png");
    let o = viewer_with("avx3", &["render", "-o", s(&out)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("LUTPANO_KERNEL=avx3") && err.contains("unknown kernel"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.exists());
}

#[test]
fn scalar_and_auto_render_the_same_bytes() {
    let d = common::tmpdir("viewer-kernel-env", "same");
    let mut images = Vec::new();
    for (kernel, sampler) in [
        ("scalar", "bilinear"),
        ("auto", "bilinear"),
        ("scalar", "nearest"),
        ("auto", "nearest"),
        ("scalar", "trilinear"),
        ("auto", "trilinear"),
    ] {
        let out = d.join(format!("{kernel}-{sampler}.png"));
        let o = viewer_with(
            kernel,
            &[
                "render",
                "--sampler",
                sampler,
                "--hfov",
                "130",
                "--yaw",
                "170",
                "-o",
                s(&out),
            ],
        );
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        images.push(image::open(&out).unwrap().to_rgb8());
    }
    for pair in images.chunks(2) {
        assert_eq!(pair[0].as_raw(), pair[1].as_raw());
    }
}

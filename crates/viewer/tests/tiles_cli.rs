//! `viewer render` of a tiled pyramid (a folder or its config.json): the frame waits for
//! its tiles (flat pyramid: every pixel the colour), bad configurations exit 1 with one
//! line naming the file.

use std::process::Command;

fn viewer() -> Command {
    Command::new(env!("CARGO_BIN_EXE_viewer"))
}

#[test]
fn a_pyramid_renders_from_its_folder_and_its_config() {
    let dir = tempfile::tempdir().unwrap();
    let pyr = dir.path().join("pyr");
    let c = 0x00_33_66_99u32;
    lut_core::write_pyramid(&pyr, 1000, 128, "jpg", &|_, _, _, w, h| {
        vec![c; (w * h) as usize]
    })
    .unwrap();
    for (input, args) in [
        (pyr.clone(), vec!["--hfov", "30", "--pitch", "60"]),
        (
            pyr.join("config.json"),
            vec!["--yaw", "45", "--hfov", "120"],
        ),
    ] {
        let out = dir.path().join("o.png");
        let st = viewer()
            .arg("render")
            .arg(&input)
            .args([
                "-o",
                out.to_str().unwrap(),
                "--size",
                "120x80",
                "--cache-mib",
                "64",
            ])
            .args(&args)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        let img = image::open(&out).unwrap().to_rgb8();
        // JPEG tiles of one colour decode within a level or two of it.
        for p in img.pixels() {
            for (a, b) in p.0.iter().zip([0x33u8, 0x66, 0x99]) {
                assert!(a.abs_diff(b) <= 2, "{p:?}");
            }
        }
    }
}

#[test]
fn a_bad_pyramid_is_one_line_and_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("config.json"),
        "{\"type\":\"multires\",\"multiRes\":{\"path\":\"/%l/%s%y_%x\",\"extension\":\"jpg\",\"tileResolution\":512,\"maxLevel\":60,\"cubeResolution\":1000000000000}}",
    )
    .unwrap();
    let out = dir.path().join("o.png");
    let st = viewer()
        .arg("render")
        .arg(dir.path())
        .args(["-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(1));
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("config.json") && err.contains("multiRes"),
        "{err}"
    );
    assert!(!out.exists());
}

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

/// The pyramid Pannellum's generate.py wrote (tests/data/multires/generate-py, fallback
/// faces of 128 px) opens from its six level-1 tiles: generate.py makes level 1 a single
/// tile a face (`maxLevel` is chosen so), smaller than its fallback faces, so using the
/// fallback faces as the coarsest ancestor would read as many files and decode more
/// texels. docs/huge.md ("fallbackPath").
#[test]
fn a_generate_py_pyramid_opens_from_six_tiles_not_its_fallback_faces() {
    let dir = test_support::test_data("multires/generate-py");
    let cfg = lut_core::MultiresConfig::open(&dir).unwrap();
    assert_eq!(cfg.tiles_across(1), 1, "level 1 is one tile a face");
    let fallback =
        image::image_dimensions(cfg.fallback_path(lut_core::Face::Front).unwrap()).unwrap();
    assert_eq!(fallback, (128, 128));
    assert!(
        fallback.0 > cfg.level_size(1),
        "fallback faces are larger than level 1"
    );
    let pano = lut_core::TiledPanorama::open(&dir, 64 << 20, 1).unwrap();
    let d = pano.decode_stats();
    assert_eq!(d.tiles, 6, "six files at open");
    assert_eq!(d.texels, 6 * u64::from(cfg.level_size(1)).pow(2));
}

/// The heat map of a tiled frame is 0 everywhere (the cube renderer's positions are
/// exact): `viewer render --error-map` says so and why, a map's does not.
#[test]
fn the_heat_map_of_tiles_says_why_it_is_zero() {
    let dir = tempfile::tempdir().unwrap();
    let heat = dir.path().join("heat.png");
    let run = |input: &std::path::Path| {
        let o = viewer()
            .arg("render")
            .arg(input)
            .arg("-o")
            .arg(dir.path().join("o.png"))
            .args(["--size", "96x64", "--cache-mib", "64", "--error-map"])
            .arg(&heat)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let e = run(&test_support::test_data("multires/generate-py"));
    assert!(
        e.contains("0 everywhere by construction") && e.contains("tiles"),
        "{e}"
    );
    let img = image::open(&heat).unwrap();
    assert!(img.width() >= 96);
    let e = run(&test_support::test_data("multires/courtyard-512.jpg"));
    assert!(!e.contains("by construction"), "{e}");
}

//! `viewer render` with the output projections (`--view-projection`, `--pannini-d`), the
//! grid renderer, the error heat map (`--error-map`, `-v`) and the diamond table, end to
//! end; and the elliptical seam repro.

use std::path::{Path, PathBuf};

mod common;
use common::{s, viewer};
use lut_core::{
    ErrorMap, LoadOptions, Projection, RenderOptions, Renderer, RendererKind, View, ViewProjection,
};

fn tmpdir(name: &str) -> PathBuf {
    common::tmpdir("viewer-views-cli", name)
}

fn courtyard() -> PathBuf {
    test_support::repo_root().join("assets/courtyard.jpg")
}

fn load(path: &Path) -> lut_core::EnvMap {
    lut_core::load_map(path, &LoadOptions::default(), &mut |_| {}).unwrap()
}

fn run_ok(args: &[&str]) -> String {
    let o = viewer(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{args:?}: {err}");
    err
}

/// A bad invocation: nonzero exit, a one-line message naming `needle`, no output file.
fn refused(args: &[&str], out: &Path, needle: &str) {
    let o = viewer(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{args:?} succeeded");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert!(err.contains(needle), "{args:?}: '{needle}' not in: {err}");
    assert!(!out.exists(), "{args:?} wrote {}", out.display());
}

/// The little planet, a fisheye and a Pannini view: the files are lut-core's grid render
/// of the same map, byte for byte, and `-v` names the grid and the projection.
#[test]
fn renders_every_projection_as_lut_core_does() {
    let d = tmpdir("projections");
    let src = courtyard();
    let map = load(&src);
    let mut r = Renderer::new(&map);
    for (name, proj, pitch, hfov, extra) in [
        (
            "planet",
            ViewProjection::Stereographic,
            -90.0,
            300.0,
            vec![],
        ),
        ("fisheye", ViewProjection::Fisheye, 10.0, 200.0, vec![]),
        (
            "pannini",
            ViewProjection::Pannini(0.7),
            0.0,
            160.0,
            vec!["--pannini-d", "0.7"],
        ),
    ] {
        let out = d.join(format!("{name}.png"));
        let (p, h) = (pitch.to_string(), hfov.to_string());
        let mut args = vec![
            "render",
            s(&src),
            "-o",
            s(&out),
            "--view-projection",
            proj.name(),
            "--pitch",
            &p,
            "--hfov",
            &h,
            "--size",
            "160x120",
            "-v",
        ];
        args.extend(extra.iter().copied());
        let err = run_ok(&args);
        assert!(
            err.contains("path grid") && err.contains("view projection"),
            "{err}"
        );
        let view = View::with_projection(0.0, pitch, hfov, proj).unwrap();
        let (want, _) = test_support::render::render_frame(
            &mut r,
            &map,
            view,
            &RenderOptions::default(),
            160,
            120,
        );
        let got = image::open(&out).unwrap().to_rgb8();
        assert_eq!(
            got.into_raw(),
            test_support::pixels::to_rgb(&want, 160, 120).into_raw(),
            "{name}"
        );
    }
}

#[test]
fn bad_projection_requests_are_refused() {
    let d = tmpdir("bad");
    let out = d.join("x.png");
    let o = s(&out);
    let c = courtyard();
    let base = ["render", s(&c), "-o", o];
    let with = |extra: &[&'static str]| {
        let mut v: Vec<&str> = base.to_vec();
        v.extend_from_slice(extra);
        v
    };
    refused(
        &with(&["--view-projection", "fisheye", "--hfov", "400"]),
        &out,
        "(0, 360] degrees for the fisheye",
    );
    refused(
        &with(&["--view-projection", "stereographic", "--hfov", "360"]),
        &out,
        "got 360",
    );
    refused(
        &with(&["--hfov", "200"]),
        &out,
        "--view-projection stereographic",
    );
    refused(
        &with(&["--view-projection", "pannini", "--pannini-d", "-1"]),
        &out,
        "got -1",
    );
    refused(
        &with(&["--view-projection", "pannini", "--pannini-d", "nan"]),
        &out,
        "'nan'",
    );
    refused(
        &with(&["--view-projection", "fisheye", "--pannini-d", "2"]),
        &out,
        "--pannini-d applies",
    );
    refused(
        &with(&["--view-projection", "mercator"]),
        &out,
        "'mercator'",
    );
    refused(
        &with(&[
            "--view-projection",
            "fisheye",
            "--hfov",
            "180",
            "--view-limit",
        ]),
        &out,
        "--view-limit applies to rectilinear views",
    );
    refused(&with(&["--lut-surface", "rhombus"]), &out, "'rhombus'");
}

/// `--error-map` writes the heat map with its legend, and `-v` prints its max and mean:
/// the same numbers as lut-core's `ErrorMap` of the same view and renderer.
#[test]
fn error_map_and_verbose_report_the_measured_error() {
    let d = tmpdir("heat");
    let src = courtyard();
    let map = load(&src);
    let mut r = Renderer::new(&map);
    for (renderer, proj, hfov) in [
        ("lut", "rectilinear", "120"),
        ("grid", "rectilinear", "90"),
        ("lut", "equisolid", "250"),
    ] {
        let out = d.join(format!("{renderer}-{proj}.png"));
        let heat = d.join(format!("{renderer}-{proj}-err.png"));
        let err = run_ok(&[
            "render",
            s(&src),
            "-o",
            s(&out),
            "--renderer",
            renderer,
            "--view-projection",
            proj,
            "--hfov",
            hfov,
            "--pitch",
            "70",
            "--size",
            "300x150",
            "--error-map",
            s(&heat),
            "-v",
        ]);
        let proj: ViewProjection = proj.parse().unwrap();
        let view = View::with_projection(0.0, 70.0, hfov.parse().unwrap(), proj).unwrap();
        let opts = RenderOptions {
            renderer: if renderer == "grid" {
                RendererKind::Grid
            } else {
                RendererKind::Lut
            },
            ..RenderOptions::default()
        };
        let em = ErrorMap::measure(&mut r, &map, view, &opts, 300, 150).unwrap();
        let line = viewer::heatmap::summary(&em);
        assert!(err.contains(&line), "{line} not in: {err}");
        assert!(
            em.stats.max <= 0.05 && em.stats.max > 0.0,
            "{}",
            em.stats.max
        );
        let img = image::open(&heat).unwrap().to_rgb8();
        assert_eq!(
            img.dimensions(),
            (420, 150 + viewer::heatmap::LEGEND_HEIGHT)
        );
        // The frame part is the heat map's colours.
        let colors = em.colors();
        for (x, y) in [
            (0u32, 0u32),
            (150, 75),
            (299, 149),
            (em.stats.worst_pixel.0, em.stats.worst_pixel.1),
        ] {
            let c = colors[(y * 300 + x) as usize];
            let p = img.get_pixel(x, y);
            assert_eq!(
                [p[0], p[1], p[2]],
                [(c >> 16) as u8, (c >> 8) as u8, c as u8]
            );
        }
    }
}

/// The diamond table (FIG. 8B) from the command line: `-v` names its size, and its
/// image agrees with the exact renderer's as the cylinder's does.
#[test]
fn diamond_table_from_the_command_line() {
    let d = tmpdir("diamond");
    let (a, b) = (d.join("diamond.png"), d.join("exact.png"));
    let view = [
        "--yaw", "-135", "--pitch", "62", "--hfov", "100", "--size", "321x177",
    ];
    let mut args = vec!["render", "-o", s(&a), "--lut-surface", "diamond", "-v"];
    args.extend_from_slice(&view);
    let err = run_ok(&args);
    assert!(
        err.contains("path lut-wide") && !err.contains("table 0 bytes"),
        "{err}"
    );
    let mut args = vec!["render", "-o", s(&b), "--renderer", "exact"];
    args.extend_from_slice(&view);
    run_ok(&args);
    let (a, b) = (
        image::open(&a).unwrap().to_rgb8(),
        image::open(&b).unwrap().to_rgb8(),
    );
    let (mut worst, mut sum) = (0u8, 0u64);
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            worst = worst.max(p[c].abs_diff(q[c]));
            sum += p[c].abs_diff(q[c]) as u64;
        }
    }
    let mean = sum as f64 / a.len() as f64;
    assert!(worst <= 20 && mean < 0.3, "worst {worst} mean {mean}");
}

/// The repro of the elliptical seam: an elliptical map, one colour on the
/// sphere and black outside, rendered at `--yaw 180 --pitch -30 --hfov 100`: every
/// pixel is that colour (a dark line at the seam was a blend with the black outside).
#[test]
fn elliptical_seam_repro_shows_no_dark_line() {
    let d = tmpdir("seam");
    for proj in [Projection::Elliptical, Projection::Diamond] {
        let (w, h) = (1024u32, 512u32);
        let mut img = image::RgbImage::new(w, h);
        for (x, y, p) in img.enumerate_pixels_mut() {
            let on = proj
                .direction(x as f64 + 0.5, y as f64 + 0.5, w as f64, h as f64)
                .is_some();
            *p = if on {
                image::Rgb([200, 180, 160])
            } else {
                image::Rgb([0, 0, 0])
            };
        }
        let src = d.join(format!("{}.png", proj.name()));
        img.save(&src).unwrap();
        for sampler in ["nearest", "bilinear", "trilinear"] {
            let out = d.join(format!("{}-{sampler}.png", proj.name()));
            run_ok(&[
                "render",
                s(&src),
                "--projection",
                proj.name(),
                "--yaw",
                "180",
                "--pitch",
                "-30",
                "--hfov",
                "100",
                "--size",
                "480x270",
                "--sampler",
                sampler,
                "-o",
                s(&out),
            ]);
            let got = image::open(&out).unwrap().to_rgb8();
            let darkest = got.pixels().map(|p| p[2]).min().unwrap();
            assert!(
                darkest >= 159,
                "{proj} {sampler}: a pixel of blue {darkest} (160 on the sphere)"
            );
        }
    }
}

//! Tours (issue 30): the Pannellum and Marzipano test tours open with their scenes,
//! hotspots and start views; a saved tour round-trips; `viewer tour check` finds each
//! planted problem with its place; bad input opens the rest of the tour.

use std::path::{Path, PathBuf};

mod common;
use common::{s, viewer};
use viewer::tour::{self, Angles, HotspotKind, Source, TargetAngle, Tour};

fn data(rel: &str) -> PathBuf {
    test_support::repo_root().join("tests/data/tours").join(rel)
}

fn tmpdir(name: &str) -> PathBuf {
    common::tmpdir("viewer-tours", name)
}

fn close(a: f64, b: f64, eps: f64, what: &str) {
    assert!((a - b).abs() <= eps, "{what}: {a} vs {b}");
}

#[test]
fn the_pannellum_tour_opens_with_its_scenes_hotspots_and_start_views() {
    let l = tour::load(&data("pannellum/tour.json")).unwrap();
    assert!(l.problems.is_empty(), "{:?}", l.problems);
    let t = &l.tour;
    assert_eq!(t.first_scene, "courtyard");
    assert_eq!(t.fade_ms, Some(1000.0));
    let ids: Vec<_> = t.scenes.iter().map(|s| s.id.as_str()).collect();
    assert_eq!(ids, ["courtyard", "interior", "courtyardCube"]);
    let c = t.scene("courtyard").unwrap();
    assert_eq!(c.source, Source::Equirect("courtyard.jpg".into()));
    assert_eq!(
        c.start,
        Angles {
            yaw: 20.0,
            pitch: -5.0,
            hfov: 90.0
        }
    );
    assert_eq!(c.north_offset, 30.0);
    assert_eq!(c.title.as_deref(), Some("Courtyard"));
    assert_eq!(c.hotspots.len(), 3);
    let h = &c.hotspots[0];
    assert_eq!(
        (h.yaw, h.pitch, h.text.as_str()),
        (60.0, -2.0, "Into the room")
    );
    let HotspotKind::Scene { scene_id, target } = &h.kind else {
        panic!("{h:?}")
    };
    assert_eq!(scene_id, "interior");
    assert_eq!(target.yaw, TargetAngle::SameAzimuth);
    assert_eq!(target.pitch, TargetAngle::Value(0.0));
    assert_eq!(target.hfov, TargetAngle::Scene);
    assert_eq!(
        c.hotspots[1].kind,
        HotspotKind::Info {
            url: Some("https://hdrihaven.com".into())
        }
    );
    // Defaults: Pannellum's pitch 0 where the scene gives none; "./" kept.
    let i = t.scene("interior").unwrap();
    assert_eq!(
        i.start,
        Angles {
            yaw: -30.0,
            pitch: 0.0,
            hfov: 100.0
        }
    );
    assert_eq!(i.source, Source::Equirect("./interior.jpg".into()));
    let cube = t.scene("courtyardCube").unwrap();
    let Source::Cube(faces) = &cube.source else {
        panic!("{:?}", cube.source)
    };
    assert_eq!(faces[4].as_deref(), Some("cube/up.jpg"));
    assert_eq!(cube.start, tour::DEFAULT_START);
    // Members not interpreted are kept (saved back).
    assert_eq!(t.default_extra["author"], "lutpano tests");
}

#[test]
fn arrival_follows_pannellums_rules_including_same_azimuth() {
    let t = tour::load(&data("pannellum/tour.json")).unwrap().tour;
    let c = t.scene("courtyard").unwrap();
    let now = Angles {
        yaw: 50.0,
        pitch: 12.0,
        hfov: 75.0,
    };
    // sameAzimuth: the same compass direction (north 30 here, 120 there), pitch given,
    // hfov the target's own.
    let (i, a) = t.arrival(c, now, &c.hotspots[0]).unwrap();
    assert_eq!(t.scenes[i].id, "interior");
    assert_eq!(
        a,
        Angles {
            yaw: 50.0 + 30.0 - 120.0,
            pitch: 0.0,
            hfov: 100.0
        }
    );
    // Values, wrapped: 200 -> -160.
    let int = t.scene("interior").unwrap();
    let (_, a) = t.arrival(int, now, &int.hotspots[0]).unwrap();
    assert_eq!(
        a,
        Angles {
            yaw: -160.0,
            pitch: -10.0,
            hfov: 70.0
        }
    );
    // "same": the current view's yaw and hfov; pitch the target's own.
    let cube = t.scene("courtyardCube").unwrap();
    let (_, a) = t.arrival(cube, now, &cube.hotspots[0]).unwrap();
    assert_eq!(
        a,
        Angles {
            yaw: 50.0,
            pitch: -5.0,
            hfov: 75.0
        }
    );
    // Info hotspots go nowhere.
    assert!(t.arrival(c, now, &c.hotspots[1]).is_none());
}

#[test]
fn the_marzipano_tour_opens_with_angles_converted() {
    let l = tour::load(&data("marzipano/data.js")).unwrap();
    assert!(l.problems.is_empty(), "{:?}", l.problems);
    let t = &l.tour;
    assert_eq!(t.title.as_deref(), Some("Test tour"));
    assert_eq!(t.first_scene, "0-courtyard");
    let c = &t.scenes[0];
    assert_eq!(c.title.as_deref(), Some("Courtyard"));
    // Radians to degrees; Marzipano's pitch is positive down.
    close(c.start.yaw, 20.0, 1e-9, "start yaw");
    close(c.start.pitch, -5.0, 1e-9, "start pitch");
    // fov 75° vertical at 16:9.
    let hfov = 2.0
        * ((37.5f64).to_radians().tan() * 16.0 / 9.0)
            .atan()
            .to_degrees();
    close(c.start.hfov, hfov, 1e-9, "start hfov");
    let Source::MarzipanoTiles {
        dir,
        levels,
        face_size,
    } = &c.source
    else {
        panic!()
    };
    assert_eq!(
        (dir.as_str(), levels.as_slice(), *face_size),
        ("tiles/0-courtyard", &[(64, 64, false)][..], 64)
    );
    let link = &c.hotspots[0];
    close(link.yaw, 60.0, 1e-9, "link yaw");
    close(link.pitch, -2.0, 1e-9, "link pitch");
    assert_eq!(link.text, "Interior", "a link's text is its target's name");
    assert!(matches!(&link.kind, HotspotKind::Scene { scene_id, .. } if scene_id == "1-interior"));
    let info = &c.hotspots[1];
    close(info.pitch, 10.0, 1e-9, "info pitch");
    assert_eq!(info.text, "Courtyard: CC0, Greg Zaal.");
    // The second scene is written as a JavaScript literal (unquoted keys, trailing commas).
    let i = &t.scenes[1];
    close(i.start.yaw, -30.0, 1e-9, "yaw");
    close(i.hotspots[0].yaw, -120.0, 1e-9, "link yaw");
}

fn same_content(a: &Tour, b: &Tour) {
    assert_eq!(a.first_scene, b.first_scene);
    assert_eq!(a.fade_ms, b.fade_ms);
    assert_eq!(a.default_extra, b.default_extra);
    assert_eq!(a.scenes.len(), b.scenes.len());
    for (x, y) in a.scenes.iter().zip(&b.scenes) {
        assert_eq!((&x.id, &x.title, &x.source), (&y.id, &y.title, &y.source));
        assert_eq!(
            (x.start, x.north_offset, x.horizon),
            (y.start, y.north_offset, y.horizon)
        );
        assert_eq!(x.extra, y.extra);
        assert_eq!(x.hotspots.len(), y.hotspots.len(), "{}", x.id);
        for (h, k) in x.hotspots.iter().zip(&y.hotspots) {
            assert_eq!(
                (h.yaw, h.pitch, &h.text, &h.kind, &h.extra),
                (k.yaw, k.pitch, &k.text, &k.kind, &k.extra)
            );
        }
    }
}

#[test]
fn a_saved_tour_round_trips() {
    let d = tmpdir("roundtrip");
    let mut t = tour::load(&data("pannellum/tour.json")).unwrap().tour;
    // With a horizon and an edit, so those are saved too.
    t.scenes[1].horizon = tour::Horizon {
        pitch: 3.5,
        roll: -2.0,
    };
    t.scenes[0].hotspots[1].yaw = -41.25;
    let out = d.join("saved.json");
    let left_out = tour::pannellum::save(&t, &out).unwrap();
    assert!(left_out.is_empty());
    let back = tour::load(&out).unwrap();
    assert!(back.problems.is_empty(), "{:?}", back.problems);
    same_content(&t, &back.tour);
    // Saved again: the same text (stable).
    let again = d.join("again.json");
    tour::pannellum::save(&back.tour, &again).unwrap();
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&again).unwrap());
    // What Pannellum reads: the documented members.
    let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!(v["default"]["firstScene"], "courtyard");
    assert_eq!(v["scenes"]["interior"]["horizonPitch"], 3.5);
    assert_eq!(
        v["scenes"]["courtyard"]["hotSpots"][0]["targetYaw"],
        "sameAzimuth"
    );
    assert_eq!(v["scenes"]["courtyardCube"]["type"], "cubemap");
}

#[test]
fn a_single_scene_config_opens_as_a_one_scene_tour() {
    let d = tmpdir("single");
    let f = d.join("pano.json");
    std::fs::write(
        &f,
        r#"{"type": "equirectangular", "panorama": "a.jpg", "yaw": 10, "horizonRoll": 4,
            "hotSpots": [{"pitch": 1, "yaw": 2, "type": "info", "text": "hi"}]}"#,
    )
    .unwrap();
    let l = tour::load(&f).unwrap();
    assert!(l.problems.is_empty(), "{:?}", l.problems);
    assert_eq!(l.tour.scenes.len(), 1);
    assert_eq!(l.tour.first_scene, "pano");
    assert_eq!(l.tour.scenes[0].horizon.roll, 4.0);
    assert_eq!(l.tour.scenes[0].hotspots[0].text, "hi");
}

/// A tour with one planted problem per scene or hotspot; `needle` in its line.
const PLANTED: &str = r#"{
  "default": {"firstScene": "a", "hfov": 80},
  "scenes": {
    "a": {"panorama": "a.jpg", "hotSpots": [
      {"pitch": 0, "yaw": 10, "type": "scene", "sceneId": "nowhere"},
      {"pitch": 400, "yaw": 10, "type": "info"},
      {"pitch": 0, "yaw": 10, "type": "teleport"},
      {"pitch": 0, "yaw": 20, "type": "scene", "sceneId": "b", "targetYaw": "north"},
      {"yaw": 5, "type": "info"},
      {"pitch": 0, "yaw": 30, "type": "scene", "sceneId": "b"}
    ]},
    "b": {"panorama": "../outside.jpg"},
    "c": {"type": "sphere", "panorama": "c.jpg"},
    "d": {"panorama": "missing.jpg", "hfov": -5, "pitch": 1e300},
    "e": {"type": "cubemap", "cubeMap": ["f.jpg", "r.jpg"]},
    "f": {"panorama": "http://example.com/x.jpg"},
    "g": {"panorama": "a.jpg"}
  }
}"#;

#[test]
fn planted_problems_each_get_a_message_with_their_place_and_the_rest_opens() {
    let d = tmpdir("planted");
    let f = d.join("t.json");
    std::fs::write(&f, PLANTED).unwrap();
    std::fs::write(d.join("a.jpg"), b"not checked by reading").unwrap();
    let l = tour::load(&f).unwrap();
    let msgs: Vec<String> = l.problems.iter().map(|p| p.to_string()).collect();
    let has = |line: usize, needle: &str| {
        assert!(
            msgs.iter()
                .any(|m| m.contains(&format!("t.json:{line}:")) && m.contains(needle)),
            "line {line} '{needle}' not in {msgs:#?}"
        )
    };
    has(5, "links to scene \"nowhere\", which is not in the tour");
    has(6, "400 is not in [-90, 90]");
    has(7, "unknown hotspot type \"teleport\"");
    has(8, "targetYaw: is not a number, \"same\" or \"sameAzimuth\"");
    has(9, "scenes.a.hotSpots[4].pitch: missing");
    has(12, "leaves the tour's folder");
    has(13, "unknown type \"sphere\"");
    has(14, "scenes.d.hfov: -5 is not in");
    has(14, "scenes.d.pitch: 1e300 is not in");
    has(15, "not an array of six faces");
    has(16, "is a URL");
    // The link to the scene left out ("b") is named too.
    has(10, "links to scene \"b\"");
    // The rest opens: a (with its good hotspots), d (with defaults), g.
    let ids: Vec<_> = l.tour.scenes.iter().map(|s| s.id.as_str()).collect();
    assert_eq!(ids, ["a", "d", "g"]);
    let a = l.tour.scene("a").unwrap();
    assert_eq!(a.hotspots.len(), 3, "{:?}", a.hotspots);
    assert_eq!(a.start.hfov, 80.0, "default's hfov applies");
    let dd = l.tour.scene("d").unwrap();
    assert_eq!((dd.start.hfov, dd.start.pitch), (80.0, 0.0));
}

#[test]
fn a_hundred_thousand_hotspots_are_cut_with_one_message() {
    let d = tmpdir("many");
    let f = d.join("t.json");
    let hs: Vec<String> = (0..100_000)
        .map(|i| format!("{{\"pitch\": 0, \"yaw\": {}, \"type\": \"info\"}}", i % 360))
        .collect();
    std::fs::write(
        &f,
        format!(
            "{{\"panorama\": \"a.jpg\", \"hotSpots\": [{}]}}",
            hs.join(",\n")
        ),
    )
    .unwrap();
    let l = tour::load(&f).unwrap();
    assert_eq!(l.problems.len(), 1, "{:?}", l.problems);
    assert!(
        l.problems[0].message.contains("100000 hotspots"),
        "{}",
        l.problems[0]
    );
    assert_eq!(l.tour.scenes[0].hotspots.len(), tour::MAX_HOTSPOTS);
}

#[test]
fn syntax_errors_and_non_tours_are_one_line_with_the_line() {
    let d = tmpdir("syntax");
    for (name, text, needle) in [
        (
            "a.json",
            "{\n\"scenes\": {\n\"x\": {\"panorama\": \"a.jpg\",}\n",
            "t.json:4",
        ),
        ("b.json", "[1, 2]", "not an object"),
        ("c.js", "var X = {};", "no `APP_DATA =`"),
        ("d.js", "var APP_DATA = {scenes: 3};", "no scenes array"),
    ] {
        let f = d.join(name);
        std::fs::write(&f, text).unwrap();
        let e = format!("{:#}", tour::load(&f).unwrap_err());
        let needle = needle.replace("t.json", name);
        assert!(e.contains(&needle) && !e.contains('\n'), "{name}: {e}");
    }
}

fn check_lines(path: &Path) -> (bool, Vec<String>, String) {
    let o = viewer(&["tour", "check", s(path)]);
    let out = String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(str::to_string)
        .collect();
    (
        o.status.success(),
        out,
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn tour_check_passes_the_test_tours() {
    for t in ["pannellum/tour.json", "marzipano/data.js"] {
        let (ok, out, err) = check_lines(&data(t));
        assert!(ok, "{t}: {out:?} {err}");
        assert!(out.last().unwrap().contains("no problems"), "{out:?}");
    }
}

#[test]
fn tour_check_finds_each_planted_problem_one_line_each() {
    let d = tmpdir("check");
    // The test tour's files, then one problem planted at a time.
    let src = data("pannellum");
    for f in ["courtyard.jpg", "interior.jpg"] {
        std::fs::copy(src.join(f), d.join(f)).unwrap();
    }
    std::fs::create_dir_all(d.join("cube")).unwrap();
    for f in ["front", "right", "back", "left", "up", "down"] {
        std::fs::copy(
            src.join(format!("cube/{f}.jpg")),
            d.join(format!("cube/{f}.jpg")),
        )
        .unwrap();
    }
    let good = std::fs::read_to_string(src.join("tour.json")).unwrap();
    let t = d.join("tour.json");
    std::fs::write(&t, &good).unwrap();
    assert!(check_lines(&t).0, "the copy is clean");
    for (what, from, to, needle) in [
        (
            "a missing file",
            "\"courtyard.jpg\"",
            "\"gone.jpg\"",
            "tour.json:11: scenes.courtyard.panorama: \"gone.jpg\": no such file",
        ),
        (
            "a missing cube face",
            "cube/up.jpg",
            "cube/top.jpg",
            "scenes.courtyardCube.cubeMap[4]: \"cube/top.jpg\": no such file",
        ),
        (
            "a link to no scene",
            "\"sceneId\": \"interior\"",
            "\"sceneId\": \"hall\"",
            "tour.json:17: scenes.courtyard.hotSpots[0].sceneId: links to scene \"hall\"",
        ),
        (
            "a bad first scene",
            "\"firstScene\": \"courtyard\"",
            "\"firstScene\": \"lobby\"",
            "tour.json:3: default.firstScene: scene \"lobby\" is not in the tour",
        ),
        (
            "a path leaving the folder",
            "\"./interior.jpg\"",
            "\"../interior.jpg\"",
            "scenes.interior.panorama: \"../interior.jpg\" leaves the tour's folder",
        ),
        (
            "an unknown type",
            "\"type\": \"cubemap\"",
            "\"type\": \"cube\"",
            "scenes.courtyardCube.type: unknown type \"cube\"",
        ),
        (
            "an absurd number",
            "\"northOffset\": 120",
            "\"northOffset\": 1e9",
            "scenes.interior.northOffset: 1e9 is not in",
        ),
        (
            "an unreachable scene",
            "\"sceneId\": \"courtyardCube\"",
            "\"sceneId\": \"courtyard\"",
            "scenes.courtyardCube: no link leads here from the first scene",
        ),
    ] {
        std::fs::write(&t, good.replacen(from, to, 1)).unwrap();
        let (ok, out, err) = check_lines(&t);
        assert!(!ok, "{what}: passed");
        assert!(
            out.iter().any(|l| l.contains(needle)),
            "{what}: '{needle}' not in {out:#?}"
        );
        assert!(err.contains("problem"), "{what}: {err}");
        assert!(!err.contains("panicked"));
    }
}

#[test]
fn tour_convert_writes_a_pannellum_config_beside_the_tour() {
    let d = tmpdir("convert");
    let t = d.join("tour.json");
    std::fs::copy(data("pannellum/tour.json"), &t).unwrap();
    let out = d.join("out.json");
    let o = viewer(&["tour", "convert", s(&t), "-o", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let back = tour::load(&out).unwrap();
    same_content(&tour::load(&t).unwrap().tour, &back.tour);
    // Elsewhere: refused (the paths are relative to the tour), exit 2, nothing written.
    let other = tmpdir("convert-other").join("x.json");
    let o = viewer(&["tour", "convert", s(&t), "-o", s(&other)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!other.exists());
}

/// The LUT path on a re-levelled map against the exact rotated reference: each output
/// pixel's ray, rotated into the tilted image (Pannellum's rotation), sampled bilinear
/// in f64 from the original map. The re-levelled map's texel centres are exact; the
/// renderer's sampling positions on it keep their 0.05 px bound; what differs is the
/// second bilinear interpolation (the map resampled once, then the frame), bounded here.
#[test]
fn a_levelled_horizon_matches_the_exact_rotated_reference() {
    use lut_core::{
        bilinear_f64, equirect_uv, grid_map, horizon_rotation, level_horizon, Camera, Frame,
        Projection, RenderOptions, Renderer, View,
    };
    let map = grid_map(1024, 512, Projection::Equirect).unwrap();
    let (hp, hr) = (8.0, -12.0);
    let level = level_horizon(&map, hp, hr).unwrap();
    let m = horizon_rotation(hp, hr);
    let mut r = Renderer::new(&level);
    let (w, h) = (320u32, 200u32);
    for (yaw, pitch, hfov) in [(0.0, 0.0, 90.0), (75.0, 30.0, 60.0), (-140.0, -50.0, 110.0)] {
        let view = View::new(yaw, pitch, hfov).unwrap();
        let mut out = vec![0u32; (w * h) as usize];
        let mut f = Frame::new(&mut out, w, h).unwrap();
        r.render(&level, view, &RenderOptions::default(), &mut f)
            .unwrap();
        let cam = Camera::new(view, w, h);
        let exact = |m: glam::DMat3| {
            let mut reference = vec![0u32; (w * h) as usize];
            for y in 0..h {
                for x in 0..w {
                    let d = m * cam.ray(x as f64 + 0.5, y as f64 + 0.5).unwrap().normalize();
                    let (u, v) = equirect_uv(d, map.width(), map.height());
                    let c = bilinear_f64(&map, u, v);
                    let q = |v: f64| v.round().clamp(0.0, 255.0) as u32;
                    reference[(y * w + x) as usize] = (q(c[0]) << 16) | (q(c[1]) << 8) | q(c[2]);
                }
            }
            reference
        };
        let reference = exact(m);
        // The control: the inverse rotation (a sign error) must be far off.
        let wrong = test_support::pixels::psnr(&out, &exact(m.transpose()));
        let mut worst = 0.0f64;
        for (a, b) in out.iter().zip(&reference) {
            for s in [0, 8, 16] {
                worst = worst.max((((a >> s) & 0xFF) as f64 - ((b >> s) & 0xFF) as f64).abs());
            }
        }
        let p = test_support::pixels::psnr(&out, &reference);
        // Measured: 34-35 dB on this grid (its lines are 1-2 texels wide, the worst case
        // for a second interpolation); the inverse rotation is > 15 dB worse.
        eprintln!("view {yaw}/{pitch}/{hfov}: PSNR {p:.1} dB, worst channel {worst}, inverse rotation {wrong:.1} dB");
        assert!(
            p > 32.0,
            "view {yaw}/{pitch}/{hfov}: PSNR {p:.1} dB (worst channel {worst})"
        );
        assert!(
            wrong < p - 15.0,
            "the inverse rotation is as close: {wrong:.1} dB"
        );
    }
}

/// A GPano file whose pose says the camera was tilted opens level: the map loaded is the
/// re-levelled one.
#[test]
fn a_gpano_file_with_pose_opens_level() {
    let d = tmpdir("gpano-pose");
    let src = std::fs::read(test_support::repo_root().join("assets/courtyard.jpg")).unwrap();
    let xmp = lut_core::xmp_packet(&[
        ("ProjectionType", "equirectangular"),
        ("PosePitchDegrees", "6"),
        ("PoseRollDegrees", "-9"),
    ]);
    let tilted = d.join("tilted.jpg");
    std::fs::write(&tilted, lut_core::insert_xmp(&src, &xmp).unwrap()).unwrap();
    let opts = lut_core::LoadOptions::default();
    let (opened, _) = lut_core::load_partial(&tilted, &opts, None, &mut |_| {}).unwrap();
    let plain = lut_core::load_map(
        &test_support::repo_root().join("assets/courtyard.jpg"),
        &opts,
        &mut |_| {},
    )
    .unwrap();
    let expected = lut_core::level_horizon(&plain, 6.0, -9.0).unwrap();
    let (w, h) = (plain.width(), plain.height());
    let mut differs = 0;
    for y in 0..h {
        for x in 0..w {
            assert_eq!(opened.pixel(x, y), expected.pixel(x, y), "({x}, {y})");
            differs += usize::from(opened.pixel(x, y) != plain.pixel(x, y));
        }
    }
    assert!(differs > (w * h / 2) as usize, "the pose changed the map");
}

/// `render --tour --scene`: the markers sit on their hotspots' directions (within 1 px)
/// in every output projection, and are not drawn where the view does not show them.
#[test]
fn render_tour_scene_markers_sit_on_their_directions() {
    use viewer::tour::markers::{INFO_COLOR, SCENE_COLOR};
    let d = tmpdir("markers");
    // A grey panorama, so the markers are the only colours.
    let grey = image::RgbImage::from_pixel(256, 128, image::Rgb([128, 128, 128]));
    grey.save(d.join("grey.jpg")).unwrap();
    let t = d.join("t.json");
    std::fs::write(
        &t,
        r#"{"default": {"firstScene": "s"}, "scenes": {"s": {"panorama": "grey.jpg",
          "hotSpots": [
            {"pitch": 10, "yaw": 20, "type": "scene", "sceneId": "s"},
            {"pitch": -25, "yaw": -35, "type": "info", "text": "i"},
            {"pitch": 0, "yaw": 180, "type": "info", "text": "behind"}]}}}"#,
    )
    .unwrap();
    let tour = tour::load(&t).unwrap().tour;
    let scene = tour.scene("s").unwrap();
    let (w, h) = (400u32, 300u32);
    for (proj, hfov) in [
        ("rectilinear", 100.0),
        ("stereographic", 200.0),
        ("fisheye", 180.0),
        ("equisolid", 160.0),
        ("pannini", 150.0),
    ] {
        let out = d.join(format!("{proj}.png"));
        let o = viewer(&[
            "render",
            "--tour",
            s(&t),
            "--scene",
            "s",
            "-o",
            s(&out),
            "--size",
            "400x300",
            "--view-projection",
            proj,
            "--hfov",
            &hfov.to_string(),
            "--yaw",
            "0",
        ]);
        assert!(
            o.status.success(),
            "{proj}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let img = image::open(&out).unwrap().to_rgb8();
        let vp = match lut_core::parse_name::<lut_core::ViewProjection>(proj).unwrap() {
            lut_core::ViewProjection::Pannini(_) => {
                lut_core::ViewProjection::Pannini(lut_core::PANNINI_D_DEFAULT)
            }
            p => p,
        };
        let view = lut_core::View::with_projection(0.0, 0.0, hfov, vp).unwrap();
        for (i, color) in [(0usize, SCENE_COLOR), (1, INFO_COLOR), (2, INFO_COLOR)] {
            let hs = &scene.hotspots[i];
            let expect = tour::markers::place(view, w, h, hs.yaw, hs.pitch);
            // The centroid of the marker's fill colour.
            let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
            for (x, y, p) in img.enumerate_pixels() {
                let c = ((p[0] as u32) << 16) | ((p[1] as u32) << 8) | p[2] as u32;
                let near = |a: u32, b: u32| {
                    (0..3).all(|k| ((a >> (8 * k)) & 0xFF).abs_diff((b >> (8 * k)) & 0xFF) <= 2)
                };
                if near(c, color) {
                    if let Some((ex, ey)) = expect {
                        // Only this hotspot's pixels (the two info markers are far apart).
                        if (x as f64 + 0.5 - ex).hypot(y as f64 + 0.5 - ey) > 20.0 {
                            continue;
                        }
                    }
                    sx += x as f64 + 0.5;
                    sy += y as f64 + 0.5;
                    n += 1.0;
                }
            }
            match expect {
                Some((ex, ey)) => {
                    assert!(n > 20.0, "{proj}: hotspot {i} not drawn");
                    let (cx, cy) = (sx / n, sy / n);
                    assert!(
                        (cx - ex).hypot(cy - ey) <= 1.0,
                        "{proj}: hotspot {i} at ({cx:.2}, {cy:.2}), direction at ({ex:.2}, {ey:.2})"
                    );
                }
                None => assert!(i == 2, "{proj}: hotspot {i} should be shown"),
            }
        }
        // Behind the viewer (yaw 180) in the rectilinear view: not drawn anywhere.
        if proj == "rectilinear" {
            assert!(tour::markers::place(view, w, h, 180.0, 0.0).is_none());
        }
    }
}

/// Members at a tour config's root other than `default` and `scenes` (Pannellum merges
/// them over every scene) are saved at the root as they were, and a second save is the
/// first: moved into `default`, the scene options among them were dropped on the next
/// read (the tour_pannellum fuzz target found it with `pitch`, `northOffset` and the
/// horizon at the root of a tour none of whose scenes opened).
#[test]
fn root_members_of_a_tour_stay_at_the_root_and_saving_is_stable() {
    let path = Path::new("tour/tour.json");
    let text = br#"{"pitch": -5, "northOffset": 45, "horizonPitch": 1.5, "custom": {"a": 1},
        "default": {"firstScene": "a", "author": "x"},
        "scenes": {"a": {"panorama": "a.jpg", "yaw": 10}, "b": {"type": "multires"}}}"#;
    let loaded = tour::parse(text, path).unwrap();
    assert_eq!(loaded.tour.scenes.len(), 1, "b has no multiRes: left out");
    let (saved, _) = tour::pannellum::to_text(&loaded.tour);
    let v: serde_json::Value = serde_json::from_str(&saved).unwrap();
    assert_eq!(v["pitch"], -5.0, "{saved}");
    assert_eq!(v["northOffset"], 45.0, "{saved}");
    assert_eq!(v["horizonPitch"], 1.5, "{saved}");
    assert_eq!(v["custom"]["a"], 1.0, "{saved}");
    assert!(v["default"].get("pitch").is_none(), "{saved}");
    assert_eq!(v["default"]["author"], "x", "{saved}");
    let again = tour::parse(saved.as_bytes(), path).unwrap();
    assert_eq!(tour::pannellum::to_text(&again.tour).0, saved);
    // No scene left at all: still stable.
    let none =
        br#"{"pitch": -5, "default": {"firstScene": "b"}, "scenes": {"b": {"type": "multires"}}}"#;
    let t1 = tour::pannellum::to_text(&tour::parse(none, path).unwrap().tour).0;
    let t2 = tour::pannellum::to_text(&tour::parse(t1.as_bytes(), path).unwrap().tour).0;
    assert_eq!(t1, t2);
}

/// The scenes of `tests/data/tours/marzipano-tiles` (their `data.js` levels as
/// `(tileSize, size)`, with a preview strip or not) and their sources.
/// A scene of that tour: id, source image, levels `(tileSize, size)`, with a preview.
type MarzipanoScene = (&'static str, &'static str, &'static [(u32, u32)], bool);

const MARZIPANO_TILES: [MarzipanoScene; 2] = [
    (
        "0-courtyard",
        "pannellum/courtyard.jpg",
        &[(16, 16), (16, 32), (48, 96)],
        true,
    ),
    (
        "1-interior",
        "pannellum/interior.jpg",
        &[(32, 32), (32, 64)],
        false,
    ),
];

/// Writes `tests/data/tours/marzipano-tiles/tiles/` (run once by hand, the files kept;
/// README.md there): each level the cube `CubeMap::from_envmap` makes of the scene's
/// source at the level's size (bilinear), cut as the Marzipano tool cuts it, JPEG q90.
#[test]
#[ignore = "writes the test data; run by hand (see tests/data/tours/marzipano-tiles/README.md)"]
fn make_marzipano_tiles_test_data() {
    use lut_core::{CubeMap, Face, Sampler};
    let root = data("marzipano-tiles/tiles");
    for (id, src, levels, preview) in MARZIPANO_TILES {
        let map = lut_core::load_map(&data(src), &Default::default(), &mut |_| {}).unwrap();
        let cubes: Vec<CubeMap> = levels
            .iter()
            .map(|l| CubeMap::from_envmap(&map, l.1, Sampler::Bilinear).unwrap())
            .collect();
        let dir = root.join(id);
        let _ = std::fs::remove_dir_all(&dir);
        lut_core::write_marzipano(&dir, levels, preview, Some(90), &|z, f, x0, y0, w, h| {
            // Marzipano's letters are our faces in the same orientation (tests/tiles.rs,
            // a_marzipano_scene_renders_its_levels_cubes, checks it with its geometry).
            let face = match f {
                'b' => Face::Back,
                'd' => Face::Down,
                'f' => Face::Front,
                'l' => Face::Left,
                'r' => Face::Right,
                _ => Face::Up,
            };
            let c = &cubes[z as usize];
            (y0..y0 + h)
                .flat_map(|y| (x0..x0 + w).map(move |x| c.pixel(face, x, y)))
                .collect()
        })
        .unwrap();
    }
}

/// The Marzipano test tour's scenes open their tiles (the courtyard: a fallback-only
/// preview strip and levels of 32 and 96 texels, three times apart; the interior: no
/// preview, level 0 from its tiles): `viewer render --tour data.js --scene ID` and the
/// scene's tile folder opened alone render the views of the scene's source (the
/// equirectangular image the tiles were cut from) at ≥ 30 dB (the tiles are q90 JPEG of
/// cubes resampled from that image, up to 1.5 times its resolution and down to 0.8;
/// measured worst 32 dB), and the source turned 90° comes nowhere near (measured 20 dB).
#[test]
fn marzipano_tour_scenes_render_their_tiles_like_their_sources() {
    use test_support::pixels::psnr;
    let tour = data("marzipano-tiles/data.js");
    let d = tmpdir("marzipano-tiles");
    let render = |out: &Path, pano: &[&str], view: (f64, f64, f64)| {
        let (y, p, f) = (view.0.to_string(), view.1.to_string(), view.2.to_string());
        let mut args = vec!["render"];
        args.extend_from_slice(pano);
        args.extend_from_slice(&[
            "--yaw",
            &y,
            "--pitch",
            &p,
            "--hfov",
            &f,
            "--size",
            "96x72",
            "-o",
            s(out),
        ]);
        let o = viewer(&args);
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let img = image::open(out).unwrap().to_rgb8();
        img.pixels()
            .map(|p| u32::from(p[0]) << 16 | u32::from(p[1]) << 8 | u32::from(p[2]))
            .collect::<Vec<u32>>()
    };
    // Away from the hotspots (markers are drawn on the tour's renders).
    let views = [
        (0.0, 0.0, 70.0),
        (150.0, 20.0, 80.0),
        (-100.0, -60.0, 60.0),
        (45.0, 80.0, 90.0),
        (200.0, -80.0, 100.0),
    ];
    let (mut worst, mut best_wrong) = (f64::INFINITY, 0.0f64);
    for (id, src, _, _) in MARZIPANO_TILES {
        let folder = data(&format!("marzipano-tiles/tiles/{id}"));
        for (k, v) in views.iter().enumerate() {
            let a = render(
                &d.join(format!("{id}-{k}-tour.png")),
                &["--tour", s(&tour), "--scene", id],
                *v,
            );
            let b = render(&d.join(format!("{id}-{k}-folder.png")), &[s(&folder)], *v);
            let want = render(&d.join(format!("{id}-{k}-src.png")), &[s(&data(src))], *v);
            for (what, got) in [("tour", &a), ("folder", &b)] {
                let p = psnr(got, &want);
                worst = worst.min(p);
                assert!(p >= 30.0, "{id} {what} {v:?}: {p:.1} dB");
            }
            let turned = (v.0 + 90.0, v.1, v.2);
            let wrong = render(
                &d.join(format!("{id}-{k}-turned.png")),
                &[s(&data(src))],
                turned,
            );
            best_wrong = best_wrong.max(psnr(&a, &wrong));
        }
    }
    assert!(
        best_wrong < worst - 6.0,
        "control {best_wrong:.1} dB, worst {worst:.1} dB"
    );
    eprintln!("Marzipano tour tiles against their sources: worst {worst:.1} dB, turned {best_wrong:.1} dB");
    let o = viewer(&["tour", "check", s(&tour)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let q = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_tree(&p, &q);
        } else {
            std::fs::copy(&p, &q).unwrap();
        }
    }
}

/// Marzipano levels the reader refuses (a size that is not a multiple of its tile side,
/// as Marzipano refuses it) and a missing preview: `tour check` names each with its
/// place, `render` of that scene fails in one line naming the data.js, and the other
/// scene still renders.
#[test]
fn bad_marzipano_levels_are_named_by_check_and_render() {
    let d = tmpdir("marzipano-bad");
    copy_tree(&data("marzipano-tiles"), &d);
    let js = d.join("data.js");
    let text = std::fs::read_to_string(&js).unwrap().replacen(
        "\"tileSize\": 48,\n          \"size\": 96",
        "\"tileSize\": 48,\n          \"size\": 100",
        1,
    );
    std::fs::write(&js, text).unwrap();
    std::fs::remove_file(d.join("tiles/1-interior/0/u/0/0.jpg")).unwrap();
    let (ok, lines, _) = check_lines(&js);
    assert!(!ok);
    assert!(
        lines.iter().any(|l| l.contains("scenes.0-courtyard.levels")
            && l.contains("size 100 is not a multiple of its tileSize 48")),
        "{lines:?}"
    );
    assert!(
        lines
            .iter()
            .any(|l| l.contains("scenes.1-interior.levels (face u, level 0)")),
        "{lines:?}"
    );
    let out = d.join("c.png");
    let o = viewer(&[
        "render",
        "--tour",
        s(&js),
        "--scene",
        "0-courtyard",
        "-o",
        s(&out),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    let last = err.lines().last().unwrap_or("");
    assert!(
        last.contains("data.js") && last.contains("not a multiple of its tileSize 48"),
        "{err}"
    );
    let o = viewer(&[
        "render",
        "--tour",
        s(&js),
        "--scene",
        "1-interior",
        "-o",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A Pannellum tour's multires scene (its `multiRes` block naming the pyramid folder in
/// `basePath`, as Pannellum's tours do) renders through `viewer render --tour` as the
/// pyramid folder rendered alone does (the same pixels: one reader, the window's rule),
/// and a basePath that holds no pyramid, or leaves the tour's folder, is one line naming
/// the scene.
#[test]
fn a_pannellum_multires_scene_renders_through_its_base_path() {
    let d = tmpdir("pannellum-multires");
    copy_tree(
        &test_support::test_data("multires/generate-py"),
        &d.join("tiles/court"),
    );
    let tour = d.join("tour.json");
    std::fs::write(
        &tour,
        r#"{"default": {"firstScene": "court"}, "scenes": {
  "court": {"type": "multires", "hfov": 80, "yaw": 30, "pitch": -10,
            "multiRes": {"basePath": "tiles/court", "path": "/%l/%s%y_%x",
                         "fallbackPath": "/fallback/%s", "extension": "jpg",
                         "tileResolution": 64, "maxLevel": 3, "cubeResolution": 160}},
  "empty": {"type": "multires", "multiRes": {"basePath": "nothing-here"}},
  "out": {"type": "multires", "multiRes": {"basePath": "../elsewhere"}}}}"#,
    )
    .unwrap();
    let pixels = |args: &[&str], out: &Path| {
        let mut a = vec!["render"];
        a.extend_from_slice(args);
        a.extend_from_slice(&["--size", "96x72", "-o", s(out)]);
        let o = viewer(&a);
        assert!(
            o.status.success(),
            "{a:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        image::open(out).unwrap().to_rgb8().into_raw()
    };
    let via_tour = pixels(&["--tour", s(&tour), "--scene", "court"], &d.join("a.png"));
    let alone = pixels(
        &[
            s(&d.join("tiles/court")),
            "--yaw",
            "30",
            "--pitch",
            "-10",
            "--hfov",
            "80",
        ],
        &d.join("b.png"),
    );
    assert_eq!(
        via_tour, alone,
        "the tour's scene is not its pyramid at its start view"
    );
    let turned = pixels(
        &[
            s(&d.join("tiles/court")),
            "--yaw",
            "120",
            "--pitch",
            "-10",
            "--hfov",
            "80",
        ],
        &d.join("c.png"),
    );
    assert_ne!(
        via_tour, turned,
        "the control view renders the same picture"
    );
    for (scene, says) in [("empty", "nothing-here"), ("out", "scene \"out\"")] {
        let out = d.join(format!("{scene}.png"));
        let o = viewer(&[
            "render",
            "--tour",
            s(&tour),
            "--scene",
            scene,
            "-o",
            s(&out),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{scene}: {err}");
        // The tour's own problems come first (the "out" scene is left out at load); the
        // error is one line, the last, naming the scene.
        let last = err.trim().lines().last().unwrap_or_default();
        assert!(
            last.starts_with("viewer: ") && last.contains(says),
            "{scene}: {err}"
        );
        assert_eq!(err.matches("viewer: ").count(), 1, "{scene}: {err}");
        assert!(!out.exists(), "{scene}: an output was written");
    }
}

/// A multires scene whose `multiRes` numbers are inline in the tour (no config.json in
/// its basePath folder) renders with those numbers: the same pixels as the pyramid with
/// its config.json; `tour check` passes it; numbers that are refused are one line.
#[test]
fn an_inline_multires_scene_renders_with_its_numbers() {
    let d = tmpdir("pannellum-inline-multires");
    let src = test_support::test_data("multires/generate-py");
    copy_tree(&src, &d.join("tiles/court"));
    std::fs::remove_file(d.join("tiles/court/config.json")).unwrap();
    let tour = d.join("tour.json");
    std::fs::write(
        &tour,
        r#"{"default": {"firstScene": "court"}, "scenes": {
  "court": {"type": "multires", "hfov": 80, "yaw": 30, "pitch": -10,
            "multiRes": {"basePath": "tiles/court", "path": "/%l/%s%y_%x",
                         "fallbackPath": "/fallback/%s", "extension": "jpg",
                         "tileResolution": 64, "maxLevel": 3, "cubeResolution": 160}},
  "bad": {"type": "multires", "multiRes": {"basePath": "tiles/court", "path": "/%l/%s%y_%x",
          "extension": "jpg", "tileResolution": 64, "maxLevel": 0, "cubeResolution": 160}}}}"#,
    )
    .unwrap();
    let pixels = |args: &[&str], out: &Path| {
        let mut a = vec!["render"];
        a.extend_from_slice(args);
        a.extend_from_slice(&["--size", "96x72", "-o", s(out)]);
        let o = viewer(&a);
        assert!(
            o.status.success(),
            "{a:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        image::open(out).unwrap().to_rgb8().into_raw()
    };
    let view = ["--yaw", "30", "--pitch", "-10", "--hfov", "80"];
    let via_tour = pixels(&["--tour", s(&tour), "--scene", "court"], &d.join("a.png"));
    let mut with_config = vec![s(&src)];
    with_config.extend_from_slice(&view);
    let want = pixels(&with_config, &d.join("b.png"));
    assert_eq!(via_tour, want, "the inline numbers are not the pyramid's");
    // The folder alone opens through the tour that describes it.
    let court = d.join("tiles/court");
    let mut alone = vec![s(&court)];
    alone.extend_from_slice(&view);
    assert_eq!(pixels(&alone, &d.join("c.png")), want);
    let turned = pixels(
        &[s(&src), "--yaw", "120", "--pitch", "-10", "--hfov", "80"],
        &d.join("d.png"),
    );
    assert_ne!(
        via_tour, turned,
        "the control view renders the same picture"
    );
    let o = viewer(&[
        "render",
        "--tour",
        s(&tour),
        "--scene",
        "bad",
        "-o",
        s(&d.join("bad.png")),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let last = err.trim().lines().last().unwrap_or_default();
    assert!(
        last.contains("scene \"bad\"") && last.contains("maxLevel"),
        "{err}"
    );
    // tour check names the refused numbers, once, with the scene's place.
    let (ok, lines, _) = check_lines(&tour);
    assert!(!ok);
    let bad: Vec<&String> = lines.iter().filter(|l| l.contains("maxLevel")).collect();
    assert_eq!(bad.len(), 1, "{lines:?}");
    assert!(bad[0].contains("scenes.bad.multiRes"), "{lines:?}");
    assert!(
        !lines.iter().any(|l| l.contains("scenes.court")),
        "{lines:?}"
    );
}

/// The Marzipano test tours saved as Pannellum: each tile scene whose levels fit
/// Pannellum's multires is a multires scene reading the Marzipano tiles unchanged, and
/// renders the same pixels through the saved tour as through the Marzipano one (and its
/// tile folder alone, Marzipano's reader); a scene whose levels do not fit is named with
/// the reason, one line, and left out. The tour file is renamed: a Marzipano export is
/// recognised by its content, whatever the file's name.
#[test]
fn a_marzipano_tour_saved_as_pannellum_keeps_its_tile_scenes() {
    let render = |args: &[&str], view: (f64, f64, f64), out: &Path| {
        let (y, p, f) = (view.0.to_string(), view.1.to_string(), view.2.to_string());
        let mut a = vec!["render"];
        a.extend_from_slice(args);
        a.extend_from_slice(&[
            "--yaw",
            &y,
            "--pitch",
            &p,
            "--hfov",
            &f,
            "--size",
            "96x72",
            "-o",
            s(out),
        ]);
        let o = viewer(&a);
        assert!(
            o.status.success(),
            "{a:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        image::open(out).unwrap().to_rgb8().into_raw()
    };
    let views = [
        (0.0, 0.0, 70.0),
        (150.0, 20.0, 80.0),
        (-100.0, -60.0, 60.0),
        (45.0, 80.0, 90.0),
        (200.0, -80.0, 100.0),
    ];
    // (test tour, scenes that fit, scene that does not and why)
    /// The scene left out and why.
    type Unfit<'a> = Option<(&'a str, &'a str)>;
    let cases: [(&str, &[&str], Unfit); 2] = [
        (
            "marzipano-tiles",
            &["1-interior"],
            Some(("0-courtyard", "tiles of 16 and 48 px")),
        ),
        ("marzipano", &["0-courtyard", "1-interior"], None),
    ];
    for (name, fit, unfit) in cases {
        let d = tmpdir(&format!("marzipano-saved-{name}"));
        copy_tree(&data(name), &d);
        let js = d.join("my-tour.js");
        std::fs::rename(d.join("data.js"), &js).unwrap();
        let out = d.join("tour.json");
        let o = viewer(&["tour", "convert", s(&js), "-o", s(&out)]);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert!(o.status.success(), "{name}: {err}");
        match unfit {
            Some((id, why)) => {
                let lines: Vec<&str> = err.lines().filter(|l| l.contains("left out")).collect();
                assert_eq!(lines.len(), 1, "{name}: {err}");
                assert!(
                    lines[0].contains(&format!("scene {id}: ")) && lines[0].contains(why),
                    "{name}: {err}"
                );
            }
            None => assert!(!err.contains("left out"), "{name}: {err}"),
        }
        let saved = tour::load(&out).unwrap();
        assert!(saved.problems.is_empty(), "{:?}", saved.problems);
        let ids: Vec<&str> = saved.tour.scenes.iter().map(|s| s.id.as_str()).collect();
        assert_eq!(ids, fit, "{name}");
        if let Some((id, why)) = unfit {
            // --tile: the scene that does not fit re-tiled as a Pannellum pyramid, and
            // saved reading it: close to the Marzipano tiles (JPEG written again).
            let out2 = d.join("tiled.json");
            let o = viewer(&["tour", "convert", "--tile", s(&js), "-o", s(&out2)]);
            let err = String::from_utf8_lossy(&o.stderr).to_string();
            assert!(o.status.success(), "{name}: {err}");
            assert!(
                err.contains(&format!("scene {id}: "))
                    && err.contains(why)
                    && err.contains(&format!("tiles/{id}-pannellum")),
                "{err}"
            );
            let back = tour::load(&out2).unwrap();
            assert_eq!(back.tour.scenes.len(), fit.len() + 1);
            let c = viewer(&["tour", "check", s(&out2)]);
            assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stdout));
            let (mut worst, mut control) = (f64::INFINITY, 0.0f64);
            for (k, v) in views.iter().enumerate() {
                let a = render(
                    &["--tour", s(&out2), "--scene", id],
                    *v,
                    &d.join(format!("t{k}.png")),
                );
                let b = render(
                    &["--tour", s(&js), "--scene", id],
                    *v,
                    &d.join(format!("m{k}.png")),
                );
                let turned = (v.0 + 90.0, v.1, v.2);
                let c = render(
                    &["--tour", s(&js), "--scene", id],
                    turned,
                    &d.join(format!("c{k}.png")),
                );
                let px = |x: &[u8]| -> Vec<u32> {
                    x.chunks(3)
                        .map(|p| u32::from(p[0]) << 16 | u32::from(p[1]) << 8 | u32::from(p[2]))
                        .collect()
                };
                worst = worst.min(test_support::pixels::psnr(&px(&a), &px(&b)));
                control = control.max(test_support::pixels::psnr(&px(&a), &px(&c)));
            }
            eprintln!("{name} {id} re-tiled: worst {worst:.1} dB, turned {control:.1} dB");
            assert!(
                worst >= 30.0 && control < worst - 6.0,
                "worst {worst:.1}, control {control:.1}"
            );
        }
        let c = viewer(&["tour", "check", s(&out)]);
        assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stdout));
        for id in fit {
            let sc = saved.tour.scene(id).unwrap();
            let Source::Multires(m) = &sc.source else {
                panic!("{id}: {:?}", sc.source)
            };
            assert_eq!(m["basePath"], format!("tiles/{id}"));
            let folder = d.join(format!("tiles/{id}"));
            for (k, v) in views.iter().enumerate() {
                let a = render(
                    &["--tour", s(&out), "--scene", id],
                    *v,
                    &d.join(format!("{id}-{k}-p.png")),
                );
                let b = render(
                    &["--tour", s(&js), "--scene", id],
                    *v,
                    &d.join(format!("{id}-{k}-m.png")),
                );
                assert_eq!(a, b, "{name} {id} {v:?}: the saved tour draws other pixels");
                // Without markers: the Pannellum reading (inline numbers, through the
                // saved tour) against Marzipano's (the folder beside my-tour.js).
                let c = render(&[s(&folder)], *v, &d.join(format!("{id}-{k}-f.png")));
                // The Marzipano tour moved out of the export: the folder opens through
                // the saved Pannellum config that describes it.
                let away = d.with_extension("away.js");
                std::fs::rename(&js, &away).unwrap();
                let p = render(&[s(&folder)], *v, &d.join(format!("{id}-{k}-fp.png")));
                std::fs::rename(&away, &js).unwrap();
                assert_eq!(c, p, "{name} {id} {v:?}: the two readers differ");
            }
        }
    }
}

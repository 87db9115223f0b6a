//! Scene files: saved and reopened with everything the window edits (round trip through
//! the file, also after moving the folder), `viewer render --scene` drawing exactly what
//! the same options on the command line draw, and clean failures for bad files.

mod common;

use common::{s, tmpdir, viewer};
use lut_core::Interpolation;
use std::path::Path;
use viewer::lighting::{is_scene_file, LightsState, SceneFile, ScenePanorama, SceneView};

fn data(rel: &str) -> std::path::PathBuf {
    test_support::test_data(rel)
}

/// A state with every field away from its default.
fn edited_state() -> LightsState {
    let mut st = LightsState {
        room: (4.2, 5.6, 2.7),
        camera_height: 1.45,
        room_yaw: -12.5,
        room_center: (0.3, -0.4),
        multiplier: 1.7,
        exposure_lux: 420.0,
        auto_exposure: true,
        ambient: 0.08,
        false_color: true,
        false_color_max: 1500.0,
        ..LightsState::default()
    };
    st.set_interpolation(Interpolation::CatmullRom).unwrap();
    st.load_and_add(&data("ldt/office_louvre_2x28w.ldt"))
        .unwrap();
    st.load_and_add(&data("ies/type_b_full.ies")).unwrap();
    st.load_and_add(&data("ldt/office_louvre_2x28w.ldt"))
        .unwrap();
    st.lights[0].position = [0.5, 2.65, 1.0];
    st.lights[1].position = [-1.5, 2.2, -2.6];
    st.lights[1].yaw = 35.0;
    st.lights[1].pitch = -20.0;
    st.lights[1].multiplier = 0.4;
    st.lights[2].enabled = false;
    st.check().unwrap();
    st
}

fn same_state(a: &LightsState, b: &LightsState) {
    assert_eq!(a.room, b.room);
    assert_eq!(a.camera_height, b.camera_height);
    assert_eq!(a.room_yaw, b.room_yaw);
    assert_eq!(a.room_center, b.room_center);
    assert_eq!(a.multiplier, b.multiplier);
    assert_eq!(a.interpolation, b.interpolation);
    assert_eq!(a.exposure_lux, b.exposure_lux);
    assert_eq!(a.auto_exposure, b.auto_exposure);
    assert_eq!(a.ambient, b.ambient);
    assert_eq!(a.false_color, b.false_color);
    assert_eq!(a.false_color_max, b.false_color_max);
    assert_eq!(a.lights.len(), b.lights.len());
    for (x, y) in a.lights.iter().zip(&b.lights) {
        assert_eq!(
            std::fs::canonicalize(&x.path).unwrap(),
            std::fs::canonicalize(&y.path).unwrap()
        );
        assert_eq!(*x.table, *y.table);
        assert_eq!(
            (x.position, x.yaw, x.pitch, x.multiplier, x.enabled),
            (y.position, y.yaw, y.pitch, y.multiplier, y.enabled)
        );
    }
}

#[test]
fn a_scene_round_trips_through_its_file() {
    let dir = tmpdir("scene", "round-trip");
    let st = edited_state();
    let view = SceneView {
        yaw: 30.0,
        pitch: -25.0,
        hfov: 110.0,
    };
    let pano = test_support::repo_root().join("assets/courtyard.jpg");
    let file = SceneFile::from_state(&st, std::slice::from_ref(&pano), Some(view), &dir);
    let path = dir.join("room.json");
    file.save(&path).unwrap();
    assert!(is_scene_file(&path));
    let back = SceneFile::load(&path).unwrap();
    assert_eq!(back, file);
    // Written relative to the scene's folder.
    assert!(back.lights.iter().all(|l| l.file.is_relative()));
    let st2 = back.to_state(&dir).unwrap();
    same_state(&st, &st2);
    assert_eq!(back.view, Some(view));
    assert_eq!(
        std::fs::canonicalize(&back.panorama_paths(&dir)[0]).unwrap(),
        std::fs::canonicalize(&pano).unwrap()
    );
    // The lit frame is the same.
    let v = lut_core::View::new(30.0, -25.0, 110.0).unwrap();
    let base: Vec<u32> = (0..64 * 40)
        .map(|i| (i * 7919) as u32 & 0xff_ffff)
        .collect();
    let (mut a, mut b) = (base.clone(), base);
    st.clone().light_frame(v, &mut a, 64, 40).unwrap();
    st2.clone().light_frame(v, &mut b, 64, 40).unwrap();
    assert_eq!(a, b);
}

#[test]
fn a_scene_moves_with_its_files() {
    // A folder holding the scene, its panorama and a luminaire, copied elsewhere.
    let a = tmpdir("scene", "move-a");
    std::fs::copy(data("ies/label_lines.ies"), a.join("lamp.ies")).unwrap();
    std::fs::copy(
        test_support::repo_root().join("assets/courtyard.jpg"),
        a.join("p.jpg"),
    )
    .unwrap();
    let mut st = LightsState::default();
    st.load_and_add(&a.join("lamp.ies")).unwrap();
    SceneFile::from_state(&st, &[a.join("p.jpg")], None, &a)
        .save(&a.join("s.json"))
        .unwrap();
    let b = tmpdir("scene", "move-b");
    for f in ["lamp.ies", "p.jpg", "s.json"] {
        std::fs::copy(a.join(f), b.join(f)).unwrap();
    }
    std::fs::remove_dir_all(&a).unwrap();
    let loaded = SceneFile::load(&b.join("s.json")).unwrap();
    assert_eq!(
        loaded.panorama,
        Some(ScenePanorama::One(Path::new("p.jpg").into()))
    );
    let st2 = loaded.to_state(&b).unwrap();
    assert_eq!(st2.lights[0].path, b.join("lamp.ies"));
}

#[test]
fn a_cube_opened_from_six_face_files_round_trips() {
    // A scene saved while a cube opened from six separate face files is shown records
    // those files (relative to the scene's folder, in their order), and reopens them:
    // `render --scene` draws what the six files given on the command line draw.
    let dir = tmpdir("scene", "faces");
    let faces_dir = dir.join("faces");
    std::fs::create_dir_all(&faces_dir).unwrap();
    let mut faces = Vec::new();
    for f in ["ft", "rt", "bk", "lf", "up", "dn"] {
        let name = format!("skyfantasy_{f}.jpg");
        std::fs::copy(
            data(&format!("cube/skyfantasy/{name}")),
            faces_dir.join(&name),
        )
        .unwrap();
        faces.push(faces_dir.join(&name));
    }
    // An unrelated image in the same folder: opening the folder would not be the same.
    std::fs::copy(
        test_support::repo_root().join("assets/courtyard.jpg"),
        faces_dir.join("other.jpg"),
    )
    .unwrap();
    let mut st = LightsState::default();
    st.load_and_add(&data("ies/label_lines.ies")).unwrap();
    let view = SceneView {
        yaw: 10.0,
        pitch: 5.0,
        hfov: 90.0,
    };
    let file = SceneFile::from_state(&st, &faces, Some(view), &dir);
    let relative: Vec<std::path::PathBuf> = faces
        .iter()
        .map(|f| f.strip_prefix(&dir).unwrap().to_path_buf())
        .collect();
    assert_eq!(file.panorama, Some(ScenePanorama::Faces(relative)));
    let path = dir.join("cube.json");
    file.save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("\"panorama\": ["), "{text}");
    let back = SceneFile::load(&path).unwrap();
    assert_eq!(back, file);
    assert_eq!(back.panorama_paths(&dir), faces);
    let by_scene = dir.join("scene.png");
    let out = viewer(&[
        "render",
        "--scene",
        s(&path),
        "-o",
        s(&by_scene),
        "--size",
        "96x64",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let by_files = dir.join("files.png");
    let mut args = vec!["render"];
    args.extend(faces.iter().map(|f| s(f)));
    args.extend_from_slice(&["--scene", s(&path), "-o", s(&by_files), "--size", "96x64"]);
    let out = viewer(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        image::open(&by_scene).unwrap().to_rgb8().as_raw(),
        image::open(&by_files).unwrap().to_rgb8().as_raw()
    );
    // An empty list is refused, naming the file.
    let empty = dir.join("empty.json");
    std::fs::write(
        &empty,
        text.replace(
            &text[text.find("\"panorama\"").unwrap()..text.find("\"view\"").unwrap()],
            "\"panorama\": [],\n  ",
        ),
    )
    .unwrap();
    let e = SceneFile::load(&empty).unwrap_err().to_string();
    assert!(e.contains("empty.json") && e.contains("empty list"), "{e}");
}

#[test]
fn render_with_a_scene_draws_what_the_options_draw() {
    let dir = tmpdir("scene", "render");
    let lamp = data("ldt/office_louvre_2x28w.ldt");
    let flood = data("ies/type_b_full.ies");
    let pano = test_support::repo_root().join("assets/courtyard.jpg");
    let opts = [
        "--room",
        "5x6x2.8",
        "--camera-height",
        "1.5",
        "--room-yaw",
        "15",
        "--room-center",
        "0.3,-0.5",
        "--exposure-lux",
        "250",
        "--ambient",
        "0.1",
    ];
    let l1 = format!("{}@0.5,2.7,1", lamp.display());
    let l2 = format!("{}@-1.5,2.2,-2:40,-30", flood.display());
    let by_flags = dir.join("flags.png");
    let mut args = vec!["render", s(&pano), "-o", s(&by_flags), "--size", "160x100"];
    args.extend_from_slice(&["--yaw", "20", "--pitch", "-30", "--hfov", "100"]);
    args.extend_from_slice(&opts);
    args.extend_from_slice(&["--light", &l1, "--light", &l2]);
    let out = viewer(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The same as a scene file (panorama and view in it), rendered with --scene alone.
    let scene = serde_json::json!({
        "format": "lutpano-scene", "version": 1,
        "panorama": pano, "view": {"yaw": 20.0, "pitch": -30.0, "hfov": 100.0},
        "room": {"width": 5.0, "depth": 6.0, "height": 2.8, "camera_height": 1.5,
                 "yaw": 15.0, "center": [0.3, -0.5]},
        "lights": [
            {"file": lamp, "position": [0.5, 2.7, 1.0]},
            {"file": flood, "position": [-1.5, 2.2, -2.0], "yaw": 40.0, "pitch": -30.0}
        ],
        "exposure_lux": 250.0, "ambient": 0.1
    });
    let sp = dir.join("room.json");
    std::fs::write(&sp, serde_json::to_string_pretty(&scene).unwrap()).unwrap();
    let by_scene = dir.join("scene.png");
    let out = viewer(&[
        "render",
        "--scene",
        s(&sp),
        "-o",
        s(&by_scene),
        "--size",
        "160x100",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (a, b) = (
        image::open(&by_flags).unwrap(),
        image::open(&by_scene).unwrap(),
    );
    assert_eq!(a.to_rgb8().as_raw(), b.to_rgb8().as_raw());
    // Options override the scene: another exposure changes the picture.
    let brighter = dir.join("brighter.png");
    let out = viewer(&[
        "render",
        "--scene",
        s(&sp),
        "-o",
        s(&brighter),
        "--size",
        "160x100",
        "--exposure-lux",
        "80",
    ]);
    assert!(out.status.success());
    assert_ne!(
        image::open(&brighter).unwrap().to_rgb8().as_raw(),
        b.to_rgb8().as_raw()
    );
}

#[test]
fn bad_scene_files_fail_with_one_line() {
    let dir = tmpdir("scene", "bad");
    let good = serde_json::json!({
        "format": "lutpano-scene", "version": 1,
        "room": {"width": 5.0, "depth": 5.0, "height": 2.7, "camera_height": 1.6},
        "lights": [{"file": data("ies/label_lines.ies"), "position": [0.0, 2.6, 0.0]}],
        "exposure_lux": 300.0, "ambient": 0.15
    });
    let case = |name: &str, edit: &dyn Fn(&mut serde_json::Value)| -> String {
        let mut v = good.clone();
        edit(&mut v);
        let p = dir.join(name);
        std::fs::write(&p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
        let out = viewer(&[
            "render",
            "--scene",
            s(&p),
            "-o",
            s(&dir.join("x.png")),
            "--size",
            "8x8",
        ]);
        let e = String::from_utf8_lossy(&out.stderr).to_string();
        // A problem of the file, not of the command line (exit.rs): 1, not 2.
        assert_eq!(out.status.code(), Some(1), "{name}: {e}");
        assert_eq!(e.trim_end().lines().count(), 1, "{name}: {e}");
        assert!(e.contains(name), "{name}: {e}");
        assert!(!dir.join("x.png").exists(), "{name}: an output was written");
        e
    };
    let e = case("typo.json", &|v| v["ambiant"] = 0.2.into());
    assert!(e.contains("ambiant") && e.contains("line"), "{e}");
    let e = case("version.json", &|v| v["version"] = 7.into());
    assert!(e.contains("version 7"), "{e}");
    let e = case("nolamp.json", &|v| {
        v["lights"][0]["file"] = "/no/lamp.ies".into()
    });
    assert!(e.contains("/no/lamp.ies"), "{e}");
    let e = case("outside.json", &|v| {
        v["lights"][0]["position"] = serde_json::json!([0, 5, 0])
    });
    assert!(e.contains("outside the room"), "{e}");
    let e = case("interp.json", &|v| v["interpolation"] = "cubic".into());
    assert!(e.contains("cubic") && e.contains("catmull-rom"), "{e}");
    let e = case("room.json", &|v| v["room"]["camera_height"] = 3.0.into());
    assert!(e.contains("camera height"), "{e}");
    // The view's angles: an hfov no projection takes, and one the view projection of
    // the command line (rectilinear) does not.
    let view = |hfov: f64| {
        move |v: &mut serde_json::Value| {
            v["view"] = serde_json::json!({"yaw": 0.0, "pitch": 0.0, "hfov": hfov})
        }
    };
    let e = case("pitch.json", &|v| {
        v["view"] = serde_json::json!({"yaw": 0.0, "pitch": 120.0, "hfov": 90.0})
    });
    assert!(e.contains("\"pitch\"") && e.contains("120"), "{e}");
    let e = case("hfov.json", &view(500.0));
    assert!(e.contains("\"view\"") && e.contains("500"), "{e}");
    let e = case("wide.json", &view(250.0));
    assert!(e.contains("\"view\"") && e.contains("250"), "{e}");
    assert!(e.contains("--view-projection"), "{e}");
    // The same hfov given on the command line is a usage error (exit 2), file or not.
    let out = viewer(&[
        "render",
        "--scene",
        s(&dir.join("wide.json")),
        "-o",
        s(&dir.join("x.png")),
        "--size",
        "8x8",
        "--hfov",
        "250",
    ]);
    let e = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{e}");
    assert!(e.contains("invalid view"), "{e}");
}

//! The document's transitions, without a window: loads started, reported and finished
//! (or failed, or superseded), drops, errors kept and cleared, what the readouts show.

use super::*;
use lut_core::Projection;
use std::path::Path;

fn file(name: &str) -> Source {
    Source::File(PathBuf::from(name))
}

/// A loaded equirectangular map of `w × w/2` from `source`.
fn loaded(source: Source, w: u32, hdr: bool, exposure_ev: f64) -> Box<Loaded> {
    let map = lut_core::grid_map(w, w / 2, Projection::Equirect).unwrap();
    Box::new(Loaded {
        scene: lut_core::Panorama::map(map),
        source,
        projection: None,
        hdr,
        exposure_ev,
    })
}

/// The load requests among `fx`.
fn loads(fx: &[Effect]) -> Vec<&LoadRequest> {
    fx.iter()
        .filter_map(|e| match e {
            Effect::Load(r) => Some(r),
            _ => None,
        })
        .collect()
}

fn request(e: Effect) -> LoadRequest {
    match e {
        Effect::Load(r) => r,
        other => panic!("not a load: {other:?}"),
    }
}

fn done(id: u64, result: Result<Box<Loaded>, String>) -> LoadEvent {
    LoadEvent::Done { id, result }
}

/// The start view of a file without one.
const DEFAULT_START: StartView = StartView {
    yaw_deg: 0.0,
    pitch_deg: 0.0,
    hfov_deg: None,
};

fn doc() -> Document {
    Document::new(None, 1000, None)
}

#[test]
fn a_load_starts_reports_progress_and_shows_its_panorama() {
    let mut d = doc();
    let r = request(d.open(file("a.png"), None, StartArgs::default(), 0.5));
    assert_eq!(r.id, 1);
    assert_eq!(r.source, file("a.png"));
    assert_eq!(r.opts.max_pixels, 1000);
    assert_eq!(r.opts.tone.exposure_ev, 0.5);
    assert_eq!(
        (r.opts.projection, r.coverage, r.naming),
        (None, None, None)
    );
    let st = d.loading().unwrap();
    assert_eq!(
        (st.name.as_str(), st.step, st.fraction),
        ("a.png", LoadStep::Reading, None)
    );

    let fx = d.on_event(
        LoadEvent::Progress {
            id: 1,
            step: LoadStep::Decoding,
            fraction: Some(0.5),
        },
        0.0,
    );
    assert!(fx.is_empty());
    let st = d.loading().unwrap();
    assert_eq!((st.step, st.fraction), (LoadStep::Decoding, Some(0.5)));
    assert!(d.current().is_none(), "nothing shown while loading");

    let fx = d.on_event(done(1, Ok(loaded(file("a.png"), 64, false, 0.5))), 0.0);
    assert_eq!(
        fx,
        [
            Effect::PrintView("loaded a.png 64x32 equirect".into()),
            Effect::Title("viewer: a.png (64×32)".into()),
            Effect::StartView(DEFAULT_START),
            Effect::Opened(PathBuf::from("a.png")),
        ]
    );
    assert!(d.loading().is_none());
    assert_eq!(d.current().unwrap().source, file("a.png"));
    assert_eq!(d.generation(), 1);
    assert_eq!(d.error(), None);
    // The readouts after the load.
    assert_eq!(d.readouts.map, "a.png (64×32, equirect, 0.0 MiB in memory)");
    assert!(!d.readouts.hdr);
    assert_eq!(d.readouts.partial, None);
    assert_eq!(d.readouts.pose_heading, None);
    assert_eq!(d.partial_coverage(), None);
}

#[test]
fn a_drop_while_loading_supersedes_the_load() {
    let mut d = doc();
    d.open(file("a.png"), None, StartArgs::default(), 0.0);
    d.drop_path(PathBuf::from("b.png"));
    assert!(d.has_drops());
    let fx = d.open_drops(0.0);
    assert!(!d.has_drops());
    assert_eq!(loads(&fx).len(), 1);
    assert_eq!(
        (loads(&fx)[0].id, &loads(&fx)[0].source),
        (2, &file("b.png"))
    );
    assert_eq!(d.loading().unwrap().name, "b.png");
    // The first load's reports are stale now.
    let p = LoadEvent::Progress {
        id: 1,
        step: LoadStep::Tables,
        fraction: Some(0.9),
    };
    assert!(d.on_event(p, 0.0).is_empty());
    assert_eq!(d.loading().unwrap().step, LoadStep::Reading);
    assert!(d
        .on_event(done(1, Ok(loaded(file("a.png"), 64, false, 0.0))), 0.0)
        .is_empty());
    assert!(d.current().is_none());
    assert!(d.on_event(done(1, Err("late".into())), 0.0).is_empty());
    assert_eq!(d.error(), None);
    d.on_event(done(2, Ok(loaded(file("b.png"), 32, false, 0.0))), 0.0);
    assert_eq!(d.current().unwrap().source, file("b.png"));
    assert_eq!(d.generation(), 1);
}

#[test]
fn a_second_drop_keeps_the_picture_until_ready_and_after_it_fails() {
    let mut d = doc();
    d.open(file("a.png"), None, StartArgs::default(), 0.0);
    d.on_event(done(1, Ok(loaded(file("a.png"), 64, false, 0.0))), 0.0);
    d.drop_path(PathBuf::from("c.jpg"));
    let r = request(d.open_drops(0.0).remove(0));
    assert_eq!(
        d.current().unwrap().source,
        file("a.png"),
        "shown while c loads"
    );
    let fx = d.on_event(done(r.id, Err("c.jpg: not 2:1".into())), 0.0);
    assert_eq!(
        fx,
        [Effect::Stderr("viewer: c.jpg: not 2:1".into())],
        "no fallback: a is still shown"
    );
    assert_eq!(
        d.last_file(),
        Some(Path::new("c.jpg")),
        "PageDown steps from c"
    );
    assert_eq!(d.current().unwrap().source, file("a.png"));
    assert_eq!(d.error(), Some("c.jpg: not 2:1"));
    assert_eq!(d.generation(), 1);
    // Choosing a projection retries the file that failed, with it.
    *d.panel_parts().projection = Some(Projection::Cylinder);
    let r = request(d.projection_changed(0.0).unwrap());
    assert_eq!(r.source, file("c.jpg"));
    assert_eq!(r.opts.projection, Some(Projection::Cylinder));
    // Its success clears the error and takes the projection it was opened with.
    let mut c = loaded(file("c.jpg"), 32, false, 0.0);
    c.projection = Some(Projection::Cylinder);
    d.on_event(done(r.id, Ok(c)), 0.0);
    assert_eq!(d.error(), None);
    assert_eq!(d.projection(), Some(Projection::Cylinder));
    assert_eq!(d.generation(), 2);
}

#[test]
fn a_failed_first_load_opens_the_sample_and_keeps_the_error() {
    let mut d = Document::new(Some(Projection::Sine), 1000, None);
    let r = request(d.open(file("bad.png"), None, StartArgs::default(), 0.0));
    assert_eq!(r.opts.projection, Some(Projection::Sine));
    let fx = d.on_event(done(r.id, Err("bad.png: truncated".into())), 2.0);
    assert_eq!(fx.len(), 2);
    assert_eq!(
        fx[..1],
        [Effect::Stderr("viewer: bad.png: truncated".into())]
    );
    let sample = loads(&fx)[0].clone();
    assert_eq!((sample.id, &sample.source), (2, &Source::Sample));
    assert_eq!(sample.opts.projection, None, "the sample in auto");
    assert_eq!(sample.opts.tone.exposure_ev, 2.0);
    assert_eq!(
        d.last_file(),
        Some(Path::new("bad.png")),
        "PageDown steps from the failed file, not the sample"
    );
    // The sample's success keeps the message, and the projection still applies to the
    // failed file.
    d.on_event(done(2, Ok(loaded(Source::Sample, 64, false, 0.0))), 0.0);
    assert_eq!(d.error(), Some("bad.png: truncated"));
    assert_eq!(d.projection(), Some(Projection::Sine));
    let r = request(d.projection_changed(0.0).unwrap());
    assert_eq!(r.source, file("bad.png"));
    // Dismissed: the error goes and the choice is the sample's again.
    d.dismiss_error();
    assert_eq!((d.error(), d.projection()), (None, None));
    let r = request(d.projection_changed(0.0).unwrap());
    assert_eq!(r.source, Source::Sample);
}

#[test]
fn a_failed_sample_after_a_failed_load_does_not_loop() {
    // Issue 32: a missing file (as any damaged one) falls back to the sample; when the
    // sample fails too (a loader panic turned into an error), the error stays on show
    // and no further load starts: never a loop of loads or an endless progress bar.
    let mut d = Document::new(None, 1000, None);
    let r = request(d.open(file("missing.jpg"), None, StartArgs::default(), 0.0));
    let fx = d.on_event(done(r.id, Err("missing.jpg: No such file".into())), 0.0);
    let sample = loads(&fx)[0].clone();
    assert_eq!(sample.source, Source::Sample);
    let fx = d.on_event(
        done(
            sample.id,
            Err("loading failed (an internal error: x)".into()),
        ),
        0.0,
    );
    assert!(loads(&fx).is_empty(), "no second fallback: {fx:?}");
    assert_eq!(d.error(), Some("loading failed (an internal error: x)"));
    // Messages are escaped and shortened like every echoed line.
    let r = request(d.open(file("b.png"), None, StartArgs::default(), 0.0));
    d.on_event(done(r.id, Err("b\u{1b}[2J.png\nbad".into())), 0.0);
    assert!(
        !d.error().unwrap().chars().any(char::is_control),
        "{:?}",
        d.error()
    );
}

#[test]
fn the_next_success_clears_a_kept_error() {
    let mut d = doc();
    let r = request(d.open(file("bad.png"), None, StartArgs::default(), 0.0));
    d.on_event(done(r.id, Err("bad".into())), 0.0);
    d.on_event(done(2, Ok(loaded(Source::Sample, 64, false, 0.0))), 0.0);
    assert!(d.error().is_some());
    d.drop_path(PathBuf::from("good.png"));
    let r = request(d.open_drops(0.0).remove(0));
    d.on_event(
        done(r.id, Ok(loaded(file("good.png"), 64, false, 0.0))),
        0.0,
    );
    assert_eq!(d.error(), None);
    assert_eq!(
        d.readouts.map,
        "good.png (64×32, equirect, 0.0 MiB in memory)"
    );
}

#[test]
fn luminaires_and_scenes_are_routed_by_content() {
    let data = |p: &str| Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(p);
    let dir = tempfile::tempdir().unwrap();
    // A EULUMDAT file whose name says nothing, with a panorama and a scene file.
    let ldt = dir.path().join("downlight");
    std::fs::copy(data("tests/data/ldt/office_louvre_2x28w.ldt"), &ldt).unwrap();
    let scene = data("assets/interior_lit.json");
    let pano = data("assets/interior.jpg");
    let mut d = doc();
    for p in [&ldt, &pano, &scene] {
        d.drop_path(p.clone());
    }
    let fx = d.open_drops(0.0);
    assert_eq!(fx[0], Effect::OpenScene(scene.clone()));
    assert_eq!(fx[1], Effect::AddLights(vec![ldt.clone()]));
    assert_eq!(loads(&fx)[0].source, Source::File(pano));
    // Opened from the dialog: the same routing.
    assert_eq!(
        d.open_path(ldt.clone(), 0.0),
        Some(Effect::AddLights(vec![ldt]))
    );
    assert_eq!(
        d.open_path(scene.clone(), 0.0),
        Some(Effect::OpenScene(scene))
    );
}

#[test]
fn dropped_ies_files_add_lights_and_six_files_are_a_cube() {
    let mut d = doc();
    for p in ["lamp.IES", "b.ies"] {
        d.drop_path(PathBuf::from(p));
    }
    assert_eq!(
        d.open_drops(0.0),
        [
            Effect::AddLights(vec![PathBuf::from("lamp.IES"), PathBuf::from("b.ies")]),
            Effect::ShowPanel
        ]
    );
    assert!(d.loading().is_none());
    let faces: Vec<PathBuf> = ["ft", "rt", "bk", "lf", "up", "dn"]
        .iter()
        .map(|f| PathBuf::from(format!("sky/{f}.jpg")))
        .collect();
    for f in &faces {
        d.drop_path(f.clone());
    }
    d.drop_path(PathBuf::from("lamp.ies"));
    let fx = d.open_drops(0.0);
    assert_eq!(fx.len(), 3);
    assert_eq!(
        loads(&fx)[0].source,
        Source::Cube {
            paths: faces,
            layout: None
        }
    );
    assert!(d.open_drops(0.0).is_empty(), "nothing left");
}

#[test]
fn exposure_reloads_hdr_files_only_when_it_changed() {
    let mut d = doc();
    d.open(file("a.png"), None, StartArgs::default(), 0.0);
    d.on_event(done(1, Ok(loaded(file("a.png"), 64, false, 0.0))), 0.0);
    assert_eq!(d.reload_exposure(1.0), None, "8-bit images ignore it");
    d.drop_path(PathBuf::from("sky.hdr"));
    let r = request(d.open_drops(0.0).remove(0));
    let mut hdr = loaded(file("sky.hdr"), 64, true, 0.0);
    hdr.projection = Some(Projection::Equirect);
    d.on_event(done(r.id, Ok(hdr)), 0.0);
    assert!(d.readouts.hdr);
    assert_eq!(d.reload_exposure(0.0), None, "unchanged");
    let r = request(d.reload_exposure(1.5).unwrap());
    assert_eq!(r.source, file("sky.hdr"));
    assert_eq!(r.opts.tone.exposure_ev, 1.5);
    assert_eq!(r.opts.projection, Some(Projection::Equirect));
    // While that load runs, a slider dragged on waits for it; then the latest value
    // loads (the running load would show 1.5, the user asked for 0).
    assert_eq!(d.reload_exposure(0.5), None);
    assert_eq!(d.reload_exposure(0.0), None);
    let mut at = loaded(file("sky.hdr"), 64, true, 1.5);
    at.projection = Some(Projection::Equirect);
    let fx = d.on_event(done(r.id, Ok(at)), 0.0);
    let again = loads(&fx);
    assert_eq!(again.len(), 1);
    assert_eq!(again[0].opts.tone.exposure_ev, 0.0);
    // A reload keeps the view: no start view.
    assert!(!fx.iter().any(|e| matches!(e, Effect::StartView(_))));
}

#[test]
fn opened_files_start_at_their_own_view_reloads_keep_it() {
    let mut d = doc();
    let args = StartArgs {
        yaw: Some(30.0),
        pitch: None,
        hfov: Some(50.0),
    };
    let r = request(d.open(file("a.jpg"), None, args, 0.0));
    // The file's own start view, partly overridden by the command line.
    let mut map = lut_core::grid_map(64, 32, Projection::Equirect).unwrap();
    map.set_start_view(Some(StartView {
        yaw_deg: -100.0,
        pitch_deg: 12.0,
        hfov_deg: Some(70.0),
    }));
    let mut a = loaded(file("a.jpg"), 64, false, 0.0);
    a.scene = lut_core::Panorama::map(map);
    let fx = d.on_event(done(r.id, Ok(a)), 0.0);
    let want = StartView {
        yaw_deg: 30.0,
        pitch_deg: 12.0,
        hfov_deg: Some(50.0),
    };
    assert!(fx.contains(&Effect::StartView(want)), "{fx:?}");
    // Another projection: a reload, the view stays.
    *d.panel_parts().projection = Some(Projection::Equirect);
    let r = request(d.projection_changed(0.0).unwrap());
    let fx = d.on_event(done(r.id, Ok(loaded(file("a.jpg"), 64, false, 0.0))), 0.0);
    assert!(!fx.iter().any(|e| matches!(e, Effect::StartView(_))));
    // The next file opened: its own (default) view, not a.jpg's or the command line's.
    let r = request(d.open_path(PathBuf::from("b.jpg"), 0.0).unwrap());
    assert!(r.coverage.is_none());
    let fx = d.on_event(done(r.id, Ok(loaded(file("b.jpg"), 64, false, 0.0))), 0.0);
    assert!(fx.contains(&Effect::StartView(DEFAULT_START)));
    assert!(fx.contains(&Effect::Opened(PathBuf::from("b.jpg"))));
    assert_eq!(d.last_file(), Some(Path::new("b.jpg")));
    // A folder (a cube map) is opened: there is no file to step from.
    let dir = tempfile::tempdir().unwrap();
    let r = request(d.open_path(dir.path().to_path_buf(), 0.0).unwrap());
    assert!(matches!(r.source, Source::Cube { .. }));
    assert_eq!(d.last_file(), None);
    // The sample is not a recent file.
    let r = request(d.open(Source::Sample, None, StartArgs::default(), 0.0));
    let fx = d.on_event(done(r.id, Ok(loaded(Source::Sample, 64, false, 0.0))), 0.0);
    assert!(!fx.iter().any(|e| matches!(e, Effect::Opened(_))));
}

#[test]
fn readouts_of_the_previous_panorama_go_with_it() {
    let mut d = doc();
    d.readouts.table_bytes = 12345;
    d.readouts.scene = (800, 500);
    d.readouts.render_ms = 7.0;
    d.readouts.path = Some(lut_core::RenderPath::LutWide);
    let r = request(d.open_path(PathBuf::from("c.png"), 0.0).unwrap());
    d.on_event(done(r.id, Ok(loaded(file("c.png"), 32, false, 0.0))), 0.0);
    assert_eq!(d.readouts.table_bytes, 0);
    assert_eq!(d.readouts.path, None);
    assert_eq!(d.readouts.render_ms, 0.0);
    assert_eq!(d.readouts.map, "c.png (32×16, equirect, 0.0 MiB in memory)");
}

#[test]
fn coverage_applies_to_the_command_line_source_only() {
    let mut d = doc();
    let cov: Coverage = "180x90".parse().unwrap();
    let r = request(d.open(file("strip.jpg"), Some(cov), StartArgs::default(), 0.0));
    assert_eq!(r.coverage, Some(cov));
    d.on_event(done(r.id, Err("x".into())), 0.0);
    d.drop_path(PathBuf::from("other.jpg"));
    let r = request(d.open_drops(0.0).remove(0));
    assert_eq!(r.coverage, None);
    d.on_event(done(r.id, Err("y".into())), 0.0);
    d.drop_path(PathBuf::from("strip.jpg"));
    let r = request(d.open_drops(0.0).remove(0));
    assert_eq!(r.coverage, Some(cov), "the same file again");
}

#[test]
fn readouts_of_a_partial_panorama() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("half.png");
    image::RgbImage::from_pixel(64, 64, image::Rgb([200, 100, 50]))
        .save(&p)
        .unwrap();
    // The document's pixel limit goes to the loader: 1000 pixels refuse this image.
    let cov: Coverage = "180x90+90+0".parse().unwrap();
    let r = request(doc().open(
        Source::File(p.clone()),
        Some(cov),
        StartArgs::default(),
        0.0,
    ));
    let e = super::super::loader::load(r, &mut |_, _| {}).err().unwrap();
    assert!(e.contains("above the limit of 1000 pixels"), "{e}");
    let mut d = Document::new(None, lut_core::DEFAULT_MAX_PIXELS, None);
    let r = request(d.open(
        Source::File(p.clone()),
        Some(cov),
        StartArgs::default(),
        0.0,
    ));
    let loaded = super::super::loader::load(r.clone(), &mut |_, _| {}).unwrap();
    let fx = d.on_event(done(r.id, Ok(loaded)), 0.0);
    let partial = d.readouts.partial.clone().expect("a partial map");
    assert!(
        partial.starts_with("covers 180.0°×90.0° around yaw 90.0°"),
        "{partial}"
    );
    assert!(fx.contains(&Effect::PrintView(format!("partial {partial}"))));
    assert_eq!(d.partial_coverage().map(|c| c.hfov()), Some(180.0));
    assert!(
        // The map's size is the full panorama's (the stored crop is 64×64).
        d.readouts.map.starts_with("half.png (128×128, equirect"),
        "{}",
        d.readouts.map
    );
    assert_eq!(
        fx[0],
        Effect::PrintView(format!(
            "loaded {} 128x128 equirect",
            Path::new(&p).display()
        ))
    );
}

#[test]
fn a_load_that_cannot_start_is_an_error() {
    let mut d = doc();
    let r = request(d.open(file("a.png"), None, StartArgs::default(), 0.0));
    d.load_not_started(r.id + 1, "stale");
    assert!(d.loading().is_some());
    d.load_not_started(r.id, "no threads");
    assert!(d.loading().is_none());
    assert_eq!(d.error(), Some("cannot start loading: no threads"));
    assert!(d.panel_parts().loading.is_none());
}

/// Issue 33 (4): a panorama opened on its own (dialog, recent list, PageUp/Down, a drop
/// of panoramas only) starts a new scene; one opened with a scene, with luminaires in
/// the same drop or from the command line keeps the scene's room and lights; reloads
/// never clear them.
#[test]
fn a_panorama_opened_on_its_own_starts_a_new_scene() {
    let new_scene = |fx: &[Effect]| fx.contains(&Effect::NewScene);
    let mut d = doc();
    // The command line (and a scene file, which opens its panorama the same way).
    // (An HDR file: only those reload for another exposure.)
    let r = request(d.open(file("a.hdr"), None, StartArgs::default(), 0.0));
    let fx = d.on_event(done(r.id, Ok(loaded(file("a.hdr"), 64, true, 0.0))), 0.0);
    assert!(!new_scene(&fx), "{fx:?}");
    // Another exposure: a reload.
    let r = request(d.reload_exposure(1.0).unwrap());
    let fx = d.on_event(done(r.id, Ok(loaded(file("a.hdr"), 64, true, 1.0))), 0.0);
    assert!(!new_scene(&fx), "a reload keeps the scene: {fx:?}");
    // The Open dialog, the recent list, PageDown.
    let r = request(d.open_path(PathBuf::from("b.jpg"), 0.0).unwrap());
    let fx = d.on_event(done(r.id, Ok(loaded(file("b.jpg"), 64, false, 0.0))), 0.0);
    assert!(new_scene(&fx), "{fx:?}");
    assert_eq!(fx[0], Effect::NewScene, "before the new start view");
    // A failed open clears nothing.
    let r = request(d.open_path(PathBuf::from("c.jpg"), 0.0).unwrap());
    let fx = d.on_event(done(r.id, Err("c.jpg: truncated".into())), 0.0);
    assert!(!new_scene(&fx), "{fx:?}");
    // A drop of a panorama alone; then one with a luminaire file.
    let dir = tempfile::tempdir().unwrap();
    let ies = dir.path().join("lamp.ies");
    std::fs::write(&ies, "IESNA:LM-63-2002\n").unwrap();
    d.drop_path(PathBuf::from("d.jpg"));
    let r = loads(&d.open_drops(0.0))[0].clone();
    let fx = d.on_event(done(r.id, Ok(loaded(file("d.jpg"), 64, false, 0.0))), 0.0);
    assert!(new_scene(&fx), "{fx:?}");
    d.drop_path(PathBuf::from("e.jpg"));
    d.drop_path(ies);
    let fx = d.open_drops(0.0);
    assert!(
        fx.iter().any(|e| matches!(e, Effect::AddLights(_))),
        "{fx:?}"
    );
    let r = loads(&fx)[0].clone();
    let fx = d.on_event(done(r.id, Ok(loaded(file("e.jpg"), 64, false, 0.0))), 0.0);
    assert!(!new_scene(&fx), "dropped with its lights: {fx:?}");
}

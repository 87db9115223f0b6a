//! The panel's "Lights" section drawn offscreen (no display): with luminaires it opens
//! and shows the scene buttons, the room's fitting fields, each light's switch and fields
//! (only the selected light's when one is selected), the exposure's "automatic" switch and
//! the interpolation choice; the work plane's Em and U0 and the "Report…" button.

use viewer::lighting::LightsState;
use viewer::window::input::{steer_rect, AutoRotate};
use viewer::window::quality::Settings;
use viewer::window::ui::{self, PanelModel, Readouts};

/// Every text the panel draws in two UI passes over `lights`.
fn panel_texts(lights: &mut LightsState) -> Vec<String> {
    let ctx = egui::Context::default();
    let mut settings = Settings::default();
    let mut projection = None;
    let mut zoom_limit = None;
    let mut auto_rotate = AutoRotate::default();
    let readouts = Readouts::default();
    let mut texts = Vec::new();
    for _ in 0..2 {
        let raw = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(900.0, 4000.0),
            )),
            ..Default::default()
        };
        let out = ctx.run_ui(raw, |ui| {
            ui::side_panel(
                ui,
                PanelModel {
                    settings: &mut settings,
                    projection: &mut projection,
                    look: steer_rect(0.0, 0.0, 90.0),
                    readouts: &readouts,
                    loading: None,
                    zoom_limit: &mut zoom_limit,
                    auto_rotate: &mut auto_rotate,
                    lights,
                },
            );
        });
        texts.clear();
        for s in out.shapes {
            collect(&s.shape, &mut texts);
        }
    }
    texts
}

fn collect(shape: &egui::Shape, out: &mut Vec<String>) {
    match shape {
        egui::Shape::Text(t) => out.push(t.galley.job.text.clone()),
        egui::Shape::Vec(v) => v.iter().for_each(|s| collect(s, out)),
        _ => {}
    }
}

fn lamp() -> std::path::PathBuf {
    test_support::test_data("ies/label_lines.ies")
}

#[test]
fn the_lights_section_shows_the_room_and_each_light() {
    let mut lights = LightsState::default();
    lights.load_and_add(&lamp()).unwrap();
    lights.load_and_add(&lamp()).unwrap();
    let t = panel_texts(&mut lights);
    for want in [
        "Lights (2)",
        "Open scene…",
        "Save scene…",
        "Show room",
        "Camera height",
        "Room turn",
        "Room centre",
        "1. label_lines.ies",
        "2. label_lines.ies",
        "automatic",
        "Interpolation",
        "linear",
        "Work plane",
        "Report…",
    ] {
        assert!(t.iter().any(|s| s == want), "no '{want}' in {t:?}");
    }
    // No light selected: every light's fields; one selected: only its own.
    let count = |t: &[String]| t.iter().filter(|s| *s == "multiplier").count();
    assert_eq!(count(&t), 2, "{t:?}");
    lights.selected = Some(1);
    assert_eq!(count(&panel_texts(&mut lights)), 1);
    // The lit panorama's state, as the window sets it.
    lights.lit_panorama = "lit panorama: 43 MiB, baked in 41 ms".into();
    let t = panel_texts(&mut lights);
    assert!(
        t.iter()
            .any(|s| s == "lit panorama: 43 MiB, baked in 41 ms"),
        "{t:?}"
    );
    // The work plane's figures, as the window sets them from the solving thread.
    lights.work_plane = "Em 512 lx  U0 0.64".into();
    let t = panel_texts(&mut lights);
    assert!(t.iter().any(|s| s == "Em 512 lx  U0 0.64"), "{t:?}");
}

#[test]
fn without_lights_the_section_stays_closed() {
    let t = panel_texts(&mut LightsState::default());
    assert!(t.iter().any(|s| s == "Lights (0)"), "{t:?}");
    assert!(!t.iter().any(|s| s == "Room turn"), "{t:?}");
    assert!(!t.iter().any(|s| s == "Report…"), "{t:?}");
}

//! The egui panel painted offscreen on the CPU, exactly as the window paints it, with no
//! display: it shows up on the right, the scene to its left is untouched, and its pixels
//! are the panel's colours with text and widgets on them.

use viewer::lighting::LightsState;
use viewer::window::input::{Look, Settings};
use viewer::window::paint::{Compositor, SceneRect, BACKGROUND};
use viewer::window::ui::{self, LoadStatus, PanelModel, Readouts, BUTTON_LABELS, PANEL_WIDTH};

const W: u32 = 800;
const H: u32 = 500;
const SCENE_COLOR: u32 = 0x00FF_00FF;

struct Painted {
    frame: Vec<u32>,
    scene: Option<SceneRect>,
}

/// Run `passes` UI passes at `ppp` pixels per point and paint the last one.
fn paint_panel(
    ppp: f32,
    passes: usize,
    loading: Option<&LoadStatus>,
    error: Option<&str>,
) -> Painted {
    let ctx = egui::Context::default();
    ctx.set_visuals(egui::Visuals::dark());
    let mut compositor = Compositor::new();
    let mut settings = Settings::default();
    let mut projection = None;
    let mut lights = LightsState::default();
    let readouts = Readouts {
        map: "test map (256×128, equirect)".into(),
        render_ms: 3.5,
        ..Readouts::default()
    };
    let mut frame = vec![0u32; (W * H) as usize];
    let mut scene = None;
    for _ in 0..passes {
        let mut raw = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(W as f32 / ppp, H as f32 / ppp),
            )),
            ..Default::default()
        };
        raw.viewports
            .entry(egui::ViewportId::ROOT)
            .or_default()
            .native_pixels_per_point = Some(ppp);
        let out = ctx.run_ui(raw, |ui| {
            ui::side_panel(
                ui,
                PanelModel {
                    settings: &mut settings,
                    projection: &mut projection,
                    look: Look::new(12.5, -3.0, 75.0),
                    readouts: &readouts,
                    loading,
                    error,
                    lights: &mut lights,
                },
            );
            scene = SceneRect::from_points(ui.available_rect_before_wrap(), ppp, W, H);
        });
        let prims = ctx.tessellate(out.shapes, out.pixels_per_point);
        let r = scene.expect("the scene keeps most of the window");
        let pixels = vec![SCENE_COLOR; (r.w * r.h) as usize];
        compositor.compose(
            &mut frame,
            W,
            H,
            Some((&pixels, r)),
            &prims,
            &out.textures_delta,
            out.pixels_per_point,
        );
    }
    let p =
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("window_panel_{ppp}.png"));
    let _ = test_support::pixels::to_rgb(&frame, W, H).save(&p); // for a human look only
    Painted { frame, scene }
}

fn check(ppp: f32) {
    let Painted { frame, scene } = paint_panel(ppp, 3, None, None);
    let scene = scene.expect("scene rect");
    let panel_px = (PANEL_WIDTH * ppp).round() as u32;
    // The scene fills the window left of the panel.
    assert_eq!(
        (scene.x, scene.y, scene.h),
        (0, 0, H),
        "scene rect {scene:?}"
    );
    assert!(
        scene.w.abs_diff(W - panel_px) <= 2 * ppp.ceil() as u32 + 2,
        "scene width {} for a {panel_px}px panel",
        scene.w
    );
    // The scene's pixels are untouched by the panel.
    for y in 0..H {
        for x in 0..scene.w {
            let p = frame[(y * W + x) as usize];
            assert_eq!(p, SCENE_COLOR, "scene pixel ({x},{y}) = {p:06x}");
        }
    }
    // The panel: no scene colour, mostly the panel fill, and enough ink for its text and
    // widgets, with text near the top (the heading).
    let fill = egui::Visuals::dark().panel_fill;
    let fill = (u32::from(fill.r()) << 16) | (u32::from(fill.g()) << 8) | u32::from(fill.b());
    let (mut n, mut fills, mut ink, mut top_ink) = (0u32, 0u32, 0u32, 0u32);
    for y in 0..H {
        for x in scene.w + 2..W {
            let p = frame[(y * W + x) as usize];
            assert_ne!(p, SCENE_COLOR, "panel pixel ({x},{y}) shows the scene");
            assert_ne!(p, BACKGROUND, "panel pixel ({x},{y}) unpainted");
            n += 1;
            if p == fill {
                fills += 1;
            } else {
                ink += 1;
                let lum = ((p >> 16) & 255) + ((p >> 8) & 255) + (p & 255);
                if y < (40.0 * ppp) as u32 && lum > 3 * 120 {
                    top_ink += 1;
                }
            }
        }
    }
    assert!(fills * 2 > n, "panel fill covers {fills} of {n} pixels");
    assert!(ink * 20 > n, "panel ink: {ink} of {n} pixels");
    assert!(
        top_ink > 50,
        "heading text at the top: {top_ink} bright pixels"
    );
}

#[test]
fn panel_paints_on_the_right_at_1x() {
    check(1.0);
}

#[test]
fn panel_paints_on_the_right_at_hidpi() {
    // A HiDPI window: the panel scales with the pixels per point.
    check(1.5);
}

#[test]
fn load_progress_and_errors_show_in_the_panel() {
    let plain = paint_panel(1.0, 3, None, None).frame;
    let busy = paint_panel(
        1.0,
        3,
        Some(&LoadStatus {
            fraction: Some(0.3),
            ..LoadStatus::new("big.jpg".into())
        }),
        Some("big.jpg: cannot read image: unsupported format"),
    )
    .frame;
    // The error is drawn in its red-orange colour somewhere in the panel.
    let reddish = |p: &u32| {
        let (r, g, b) = ((p >> 16) & 255, (p >> 8) & 255, p & 255);
        r > 180 && g < 150 && b < 140
    };
    assert_eq!(plain.iter().filter(|p| reddish(p)).count(), 0);
    assert!(busy.iter().filter(|p| reddish(p)).count() > 30);
    assert_ne!(plain, busy);
}

#[test]
fn button_labels_have_glyphs_in_the_default_fonts() {
    let ctx = egui::Context::default();
    // One pass loads the fonts.
    let _ = ctx.run_ui(egui::RawInput::default(), |ui| {
        ui.label("x");
    });
    let font = egui::FontId::proportional(14.0);
    for label in BUTTON_LABELS {
        assert!(
            ctx.fonts_mut(|f| f.has_glyphs(&font, label)),
            "no glyph for button label {label:?}"
        );
    }
}

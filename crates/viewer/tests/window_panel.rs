//! The egui panel and the viewing overlay painted offscreen on the CPU, exactly as the
//! window paints them, with no display: the panel shows up on the right, the scene to its
//! left is untouched, and its pixels are the panel's colours with text and widgets on
//! them; the toolbar, notices and help draw over the scene.

use viewer::lighting::LightsState;
use viewer::window::input::{steer_rect, AutoRotate};
use viewer::window::notices::Notices;
use viewer::window::overlay::{self, ToolbarModel, TOOLBAR_LABELS};
use viewer::window::paint::{Compositor, SceneRect, BACKGROUND};
use viewer::window::quality::Settings;
use viewer::window::ui::{self, LoadStatus, PanelModel, Readouts, BUTTON_LABELS, PANEL_WIDTH};

const W: u32 = 800;
const H: u32 = 500;
const SCENE_COLOR: u32 = 0x00FF_00FF;

struct Painted {
    frame: Vec<u32>,
    scene: Option<SceneRect>,
}

/// What to draw over the scene besides the panel.
#[derive(Default)]
struct Overlays<'a> {
    error: Option<&'a str>,
    help: bool,
    toolbar: bool,
    /// The error heat map on, with these (max, mean) measured.
    heat: Option<(f64, f64)>,
}

/// Run `passes` UI passes at `ppp` pixels per point and paint the last one.
fn paint_panel(
    ppp: f32,
    passes: usize,
    loading: Option<&LoadStatus>,
    over: Overlays<'_>,
) -> Painted {
    let ctx = egui::Context::default();
    ctx.set_visuals(egui::Visuals::dark());
    let mut compositor = Compositor::new();
    let mut settings = Settings {
        heat_map: over.heat.is_some(),
        ..Settings::default()
    };
    let mut projection = None;
    let mut lights = LightsState::default();
    let mut zoom_limit = Some(2.0);
    let mut auto_rotate = AutoRotate::default();
    let readouts = Readouts {
        map: "test map (256×128, equirect)".into(),
        render_ms: 3.5,
        heat: over.heat,
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
                    look: steer_rect(12.5, -3.0, 75.0),
                    readouts: &readouts,
                    loading,
                    zoom_limit: &mut zoom_limit,
                    auto_rotate: &mut auto_rotate,
                    lights: &mut lights,
                },
            );
            let rect = ui.available_rect_before_wrap();
            scene = SceneRect::from_points(rect, ppp, W, H);
            overlay::notices(ui.ctx(), rect, over.error, &Notices::default());
            if over.help {
                overlay::help(ui.ctx(), rect);
            }
            if over.toolbar {
                overlay::toolbar(
                    ui.ctx(),
                    ToolbarModel {
                        scene: rect,
                        title: "test.jpg (256×128)",
                        recent: &[],
                        panel: true,
                        help: over.help,
                    },
                );
            }
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
    let Painted { frame, scene } = paint_panel(ppp, 3, None, Overlays::default());
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
fn load_progress_in_the_panel_and_errors_in_a_notice() {
    let plain = paint_panel(1.0, 3, None, Overlays::default()).frame;
    let busy = paint_panel(
        1.0,
        3,
        Some(&LoadStatus {
            fraction: Some(0.3),
            ..LoadStatus::new("big.jpg".into())
        }),
        Overlays {
            error: Some("big.jpg: cannot read image: unsupported format"),
            ..Overlays::default()
        },
    )
    .frame;
    // The error is drawn in its red-orange colour, in a notice over the scene.
    let reddish = |p: &u32| {
        let (r, g, b) = ((p >> 16) & 255, (p >> 8) & 255, p & 255);
        r > 180 && g < 150 && b < 140
    };
    assert_eq!(plain.iter().filter(|p| reddish(p)).count(), 0);
    assert!(busy.iter().filter(|p| reddish(p)).count() > 30);
    let scene_w = W - (PANEL_WIDTH as u32);
    let in_scene = busy
        .chunks_exact(W as usize)
        .flat_map(|row| &row[..scene_w as usize])
        .filter(|p| reddish(p))
        .count();
    assert!(in_scene > 30, "the notice is over the scene: {in_scene}");
    assert_ne!(plain, busy);
}

/// The help overlay and the toolbar draw over the scene (the scene colour is covered
/// where they are, and only there).
#[test]
fn the_help_and_the_toolbar_cover_part_of_the_scene() {
    let bare = paint_panel(1.0, 3, None, Overlays::default()).frame;
    let over = paint_panel(
        1.0,
        3,
        None,
        Overlays {
            help: true,
            toolbar: true,
            ..Overlays::default()
        },
    )
    .frame;
    let scene_px = |f: &[u32]| f.iter().filter(|&&p| p == SCENE_COLOR).count();
    let (a, b) = (scene_px(&bare), scene_px(&over));
    assert!(
        b < a * 8 / 10,
        "help and toolbar cover the scene: {b} of {a}"
    );
    assert!(b > a / 10, "but not all of it: {b} of {a}");
    // The toolbar is at the top left: the corner is covered, the bottom left is not.
    let at = |x: u32, y: u32| over[(y * W + x) as usize];
    assert_ne!(at(20, 20), SCENE_COLOR);
    assert_eq!(at(20, H - 5), SCENE_COLOR);
}

#[test]
fn button_labels_have_glyphs_in_the_default_fonts() {
    let ctx = egui::Context::default();
    // One pass loads the fonts.
    let _ = ctx.run_ui(egui::RawInput::default(), |ui| {
        ui.label("x");
    });
    let font = egui::FontId::proportional(14.0);
    let mono = egui::FontId::monospace(14.0);
    let help: Vec<String> = overlay::help_rows().into_iter().map(|r| r.0).collect();
    let help: Vec<&str> = help.iter().map(String::as_str).collect();
    for label in BUTTON_LABELS.iter().chain(&TOOLBAR_LABELS).chain(&help) {
        for font in [&font, &mono] {
            assert!(
                ctx.fonts_mut(|f| f.has_glyphs(font, label)),
                "no glyph for label {label:?} in {font:?}"
            );
        }
    }
}

/// The heat map toggle shows the legend's colour bar in the panel (the colours of
/// `lut_core::heat_color` from 0.001 to 1 px), and only then.
#[test]
fn the_heat_map_legend_is_in_the_panel() {
    let scale: std::collections::HashSet<u32> = (0..=2000)
        .map(|i| lut_core::heat_color(10f64.powf(-3.0 + 3.0 * f64::from(i) / 2000.0)))
        .collect();
    let count = |over: Overlays<'_>| {
        let p = paint_panel(1.0, 3, None, over);
        let scene_w = p.scene.expect("scene").w;
        p.frame
            .chunks_exact(W as usize)
            .flat_map(|row| &row[scene_w as usize + 2..])
            .filter(|c| scale.contains(c))
            .count()
    };
    let off = count(Overlays::default());
    let on = count(Overlays {
        heat: Some((0.0123, 0.0014)),
        ..Overlays::default()
    });
    // A 200×12 point bar, less the budget mark.
    assert!(on > 1500, "legend pixels {on}");
    assert!(off < 50, "no legend without the heat map: {off}");
    let rows = ui::readout_rows(
        &steer_rect(0.0, 0.0, 90.0),
        &Readouts {
            heat: Some((0.0123, 0.0014)),
            ..Readouts::default()
        },
    );
    let row = |k: &str| rows.iter().find(|r| r.0 == k).map(|r| r.1.as_str());
    assert_eq!(row("error max"), Some("0.0123 px"));
    assert_eq!(row("error mean"), Some("0.00140 px"));
}

/// Issue 33 (6): at the default window size (1024×640) every text the panel draws, with
/// the longest readouts (over the budget, nearest quality, a long map name), lies within
/// the panel's frame: it wraps or elides instead of running past the window's edge.
#[test]
fn the_panels_text_stays_within_its_frame() {
    let (w, h) = (1024.0_f32, 640.0_f32);
    let ctx = egui::Context::default();
    ctx.set_visuals(egui::Visuals::dark());
    let mut settings = Settings::default();
    let mut projection = None;
    let mut lights = LightsState::default();
    let mut zoom_limit = Some(2.0);
    let mut auto_rotate = AutoRotate::default();
    let readouts = Readouts {
        map: "a_rather_long_panorama_file_name_2024.jpg (16384×8192, equirect)".into(),
        render_ms: 16.88,
        full_ms: Some(16.88),
        ui_ms: 1.25,
        fps: 59.0,
        scene: (794, 640),
        level: Some(viewer::window::quality::Level::Nearest),
        sampler: Some(lut_core::Sampler::Nearest),
        pixels: 794 * 640,
        exact_pixels: 1234,
        table_bytes: 12_345_678,
        pose_heading: Some(123.4),
        heat: Some((0.0123, 0.0014)),
        ..Readouts::default()
    };
    let mut shapes = Vec::new();
    let mut panel_left = 0.0;
    for _ in 0..3 {
        let raw = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2(w, h),
            )),
            ..Default::default()
        };
        let out = ctx.run_ui(raw, |ui| {
            ui::side_panel(
                ui,
                PanelModel {
                    settings: &mut settings,
                    projection: &mut projection,
                    look: steer_rect(12.5, -3.0, 75.0),
                    readouts: &readouts,
                    loading: None,
                    zoom_limit: &mut zoom_limit,
                    auto_rotate: &mut auto_rotate,
                    lights: &mut lights,
                },
            );
            panel_left = ui.available_rect_before_wrap().max.x;
        });
        shapes = out.shapes;
    }
    assert!(
        (panel_left - (w - PANEL_WIDTH)).abs() < 20.0,
        "the panel starts at {panel_left}"
    );
    let mut texts = 0;
    let mut check = |s: &egui::Shape| {
        if let egui::Shape::Text(t) = s {
            if t.galley.text().trim().is_empty() {
                return;
            }
            texts += 1;
            let r = t.visual_bounding_rect();
            assert!(
                r.min.x >= panel_left - 1.0 && r.max.x <= w + 0.5,
                "text {:?} at {r:?} leaves the panel ({panel_left}..{w})",
                t.galley.text()
            );
        }
    };
    fn walk(s: &egui::Shape, f: &mut dyn FnMut(&egui::Shape)) {
        match s {
            egui::Shape::Vec(v) => v.iter().for_each(|s| walk(s, f)),
            s => f(s),
        }
    }
    for c in &shapes {
        walk(&c.shape, &mut check);
    }
    assert!(texts > 30, "only {texts} texts drawn");
}

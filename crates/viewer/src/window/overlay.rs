//! The viewing UI over the full-width scene: a slim toolbar (open, recent files, save,
//! zoom, reset, fullscreen, the current file, the panel and help buttons), a compass
//! showing the heading, the notices, and the help overlay (`?` / F1) that lists every key
//! of [`super::keys::BINDINGS`] and every mouse action. Immediate mode from plain data, so
//! the tests paint it offscreen.

use super::keys::{BINDINGS, MOUSE_HELP};
use super::notices::{Level, Notices};
use lut_core::View;
use std::path::PathBuf;

/// Toolbar button labels (glyphs the default egui fonts have: a test checks): open,
/// recent, save, zoom out, zoom in, reset, fullscreen, panel, help.
pub const TOOLBAR_LABELS: [&str; 9] = ["🗁 Open", "⏷", "💾 Save", "−", "+", "⟲", "⛶", "⚙", "?"];

/// Colour of error text (notices, the lights section).
pub const ERROR_COLOR: egui::Color32 = egui::Color32::from_rgb(255, 120, 100);

/// What the toolbar shows.
pub struct ToolbarModel<'a> {
    /// The scene's rectangle (points): the toolbar sits at its top left.
    pub scene: egui::Rect,
    /// The current file: name and size.
    pub title: &'a str,
    /// Recent files, newest first.
    pub recent: &'a [PathBuf],
    /// The panel is shown (the ⚙ button is highlighted).
    pub panel: bool,
    /// The help is shown.
    pub help: bool,
}

/// What the user did in the toolbar.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ToolbarOutput {
    /// Open… pressed.
    pub open: bool,
    /// A recent file chosen.
    pub open_recent: Option<PathBuf>,
    /// Save… pressed.
    pub save: bool,
    /// Zoom out one step.
    pub zoom_out: bool,
    /// Zoom in one step.
    pub zoom_in: bool,
    /// Back to the start view.
    pub reset: bool,
    /// Fullscreen on/off.
    pub fullscreen: bool,
    /// Panel on/off.
    pub panel: bool,
    /// Help on/off.
    pub help: bool,
}

fn bar_frame(ui: &egui::Ui) -> egui::Frame {
    egui::Frame::popup(ui.style())
        .fill(ui.visuals().window_fill.gamma_multiply(0.85))
        .inner_margin(egui::Margin::symmetric(6, 4))
}

/// The toolbar at the top left of the scene.
pub fn toolbar(ctx: &egui::Context, m: ToolbarModel<'_>) -> ToolbarOutput {
    let mut out = ToolbarOutput::default();
    egui::Area::new(egui::Id::new("toolbar"))
        .fixed_pos(m.scene.min + egui::vec2(8.0, 8.0))
        .order(egui::Order::Foreground)
        .show(ctx, |ui| {
            bar_frame(ui).show(ui, |ui| {
                // Room for the compass on the right; the file name shrinks first.
                ui.set_max_width((m.scene.width() - 2.0 * COMPASS_RADIUS - 48.0).max(200.0));
                ui.horizontal(|ui| {
                    let [open, recent, save, zout, zin, reset, full, panel, help] = TOOLBAR_LABELS;
                    out.open = ui
                        .button(open)
                        .on_hover_text("Open a panorama (Ctrl+O)")
                        .clicked();
                    ui.add_enabled_ui(!m.recent.is_empty(), |ui| {
                        ui.menu_button(recent, |ui| {
                            ui.set_max_width(RECENT_MENU_WIDTH);
                            for p in m.recent {
                                let (name, folder) = recent_label(p, RECENT_FOLDER_CHARS);
                                let mut job = egui::text::LayoutJob::default();
                                let style = ui.style();
                                egui::RichText::new(name).strong().append_to(
                                    &mut job,
                                    style,
                                    egui::FontSelection::Default,
                                    egui::Align::Center,
                                );
                                egui::RichText::new(format!("  {folder}"))
                                    .weak()
                                    .small()
                                    .append_to(
                                        &mut job,
                                        style,
                                        egui::FontSelection::Default,
                                        egui::Align::Center,
                                    );
                                let b = ui
                                    .add(egui::Button::new(job).truncate())
                                    .on_hover_text(p.display().to_string());
                                if b.clicked() {
                                    out.open_recent = Some(p.clone());
                                    ui.close();
                                }
                            }
                            // Moving the pointer away from the menu closes it.
                            let near = ui.min_rect().expand(RECENT_MENU_MARGIN);
                            let away = ui
                                .ctx()
                                .pointer_latest_pos()
                                .is_some_and(|pos| !near.contains(pos));
                            if away {
                                ui.close();
                            }
                        })
                        .response
                        .on_hover_text("Recent files");
                    });
                    out.save = ui
                        .button(save)
                        .on_hover_text("Save the view (Ctrl+S)")
                        .clicked();
                    ui.separator();
                    out.zoom_out = ui.button(zout).on_hover_text("Zoom out (−)").clicked();
                    out.zoom_in = ui.button(zin).on_hover_text("Zoom in (+)").clicked();
                    out.reset = ui.button(reset).on_hover_text("Start view (R)").clicked();
                    out.fullscreen = ui.button(full).on_hover_text("Fullscreen (F)").clicked();
                    ui.separator();
                    // Framed buttons (a selectable label looks disabled), lit when on.
                    out.panel = ui
                        .add(egui::Button::new(panel).selected(m.panel))
                        .on_hover_text("Engineering panel (H)")
                        .clicked();
                    out.help = ui
                        .add(egui::Button::new(help).selected(m.help))
                        .on_hover_text("Keys and mouse (? or F1)")
                        .clicked();
                    ui.separator();
                    ui.add(egui::Label::new(egui::RichText::new(m.title).strong()).truncate())
                        .on_hover_text(m.title);
                });
            });
        });
    out
}

/// The first-run hint's text.
pub const FIRST_RUN_HINT: &str = "Drag to look around · scroll to zoom · ? for every key";

/// The first-run hint, centred low over the scene (it takes no input: the drag that
/// dismisses it goes to the view).
pub fn first_run_hint(ctx: &egui::Context, scene: egui::Rect) {
    egui::Area::new(egui::Id::new("first_run_hint"))
        .pivot(egui::Align2::CENTER_BOTTOM)
        .fixed_pos(egui::pos2(scene.center().x, scene.max.y - 56.0))
        .order(egui::Order::Foreground)
        .interactable(false)
        .show(ctx, |ui| {
            bar_frame(ui).show(ui, |ui| {
                ui.label(egui::RichText::new(FIRST_RUN_HINT).size(16.0).strong());
            });
        });
}

/// Width of the recent-files menu, points.
pub const RECENT_MENU_WIDTH: f32 = 380.0;
/// The recent-files menu closes when the pointer is this far (points) from it.
pub const RECENT_MENU_MARGIN: f32 = 48.0;
/// The folder beside a recent file's name is elided to this many characters.
pub const RECENT_FOLDER_CHARS: usize = 40;

/// A recent file's label: its name, and its folder elided at the start to at most `max`
/// characters ("…/photos/2024" keeps the end, the part that tells folders apart).
pub fn recent_label(p: &std::path::Path, max: usize) -> (String, String) {
    let name = p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let folder = p
        .parent()
        .map(|d| d.display().to_string())
        .unwrap_or_default();
    let n = folder.chars().count();
    let folder = if n > max && max > 1 {
        let tail: String = folder.chars().skip(n - (max - 1)).collect();
        format!("…{tail}")
    } else {
        folder
    };
    (name, folder)
}

/// Radius of the compass, points.
pub const COMPASS_RADIUS: f32 = 22.0;

/// The compass at the top right of the scene: the needle points to north when the
/// panorama knows its heading (GPano `PoseHeadingDegrees`), else to the map's centre
/// (yaw 0); the text is the heading (or the yaw).
pub fn compass(ctx: &egui::Context, scene: egui::Rect, look: &View, pose_heading: Option<f64>) {
    let r = COMPASS_RADIUS;
    let center = egui::pos2(scene.max.x - r - 12.0, scene.min.y + r + 12.0);
    let heading = pose_heading.map(|p| lut_core::compass_heading(p, look.yaw_deg()));
    // Screen angle of north (or yaw 0), clockwise from up: minus the view's heading.
    let ahead = heading.unwrap_or(look.yaw_deg());
    egui::Area::new(egui::Id::new("compass"))
        .fixed_pos(center - egui::vec2(r, r))
        .order(egui::Order::Foreground)
        .interactable(false)
        .show(ctx, |ui| {
            let (rect, _) =
                ui.allocate_exact_size(egui::vec2(2.0 * r, 2.0 * r + 14.0), egui::Sense::hover());
            let c = egui::pos2(rect.center().x, rect.min.y + r);
            let p = ui.painter();
            let v = ui.visuals();
            p.circle(c, r, v.window_fill.gamma_multiply(0.85), v.window_stroke);
            let a = (-ahead as f32).to_radians();
            let dir = egui::vec2(a.sin(), -a.cos());
            let side = egui::vec2(dir.y, -dir.x) * 4.0;
            let tip = c + dir * (r - 4.0);
            p.add(egui::Shape::convex_polygon(
                vec![tip, c + side, c - side],
                egui::Color32::from_rgb(220, 60, 50),
                egui::Stroke::NONE,
            ));
            p.add(egui::Shape::convex_polygon(
                vec![c - dir * (r - 4.0), c - side, c + side],
                v.text_color(),
                egui::Stroke::NONE,
            ));
            let text = match heading {
                Some(h) => format!("{h:.0}° {}", lut_core::compass_point(h)),
                None => format!("yaw {:.0}°", look.yaw_deg()),
            };
            let galley = p.layout_no_wrap(text, egui::FontId::proportional(11.0), v.text_color());
            let at = egui::pos2(c.x - galley.size().x / 2.0, rect.max.y - galley.size().y);
            p.rect_filled(
                egui::Rect::from_min_size(at, galley.size()).expand(2.0),
                3.0,
                v.window_fill.gamma_multiply(0.85),
            );
            p.galley(at, galley, v.text_color());
        });
}

/// The tiles-loading indicator's text: `None` when no tile is pending.
pub fn tiles_loading_text(pending: usize) -> Option<String> {
    match pending {
        0 => None,
        1 => Some("loading 1 tile".into()),
        n => Some(format!("loading {n} tiles")),
    }
}

/// A small indicator at the bottom left of the scene while tiles of a tiled pyramid are
/// decoding (the frame meanwhile drawn from a coarser level): the count pending.
pub fn tiles_loading(ctx: &egui::Context, scene: egui::Rect, pending: usize) {
    let Some(text) = tiles_loading_text(pending) else {
        return;
    };
    egui::Area::new(egui::Id::new("tiles-loading"))
        .fixed_pos(egui::pos2(scene.min.x + 10.0, scene.max.y - 28.0))
        .order(egui::Order::Foreground)
        .interactable(false)
        .show(ctx, |ui| {
            let (fg, bg) = (ui.visuals().text_color(), ui.visuals().window_fill);
            let galley = ui
                .painter()
                .layout_no_wrap(text, egui::FontId::proportional(12.0), fg);
            let (rect, _) =
                ui.allocate_exact_size(galley.size() + egui::vec2(8.0, 4.0), egui::Sense::hover());
            let p = ui.painter();
            p.rect_filled(rect, 3.0, bg.gamma_multiply(0.85));
            p.galley(rect.min + egui::vec2(4.0, 2.0), galley, fg);
        });
}

/// What the notices area reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NoticesOutput {
    /// Notices dismissed with ✖.
    pub dismissed: Vec<u64>,
    /// The document's error was dismissed.
    pub dismiss_error: bool,
}

/// The notices at the bottom left of the scene: the document's error first (it stays
/// until dismissed or another panorama opens), then the posted notices.
pub fn notices(
    ctx: &egui::Context,
    scene: egui::Rect,
    error: Option<&str>,
    list: &Notices,
) -> NoticesOutput {
    let mut out = NoticesOutput::default();
    if error.is_none() && list.list().is_empty() {
        return out;
    }
    egui::Area::new(egui::Id::new("notices"))
        .anchor(
            egui::Align2::LEFT_BOTTOM,
            egui::vec2(
                scene.min.x + 8.0,
                scene.max.y - ctx.content_rect().max.y - 8.0,
            ),
        )
        .order(egui::Order::Foreground)
        .show(ctx, |ui| {
            ui.set_max_width((scene.width() - 16.0).max(160.0));
            let row = |ui: &mut egui::Ui, text: &str, err: bool| -> bool {
                let mut closed = false;
                bar_frame(ui).show(ui, |ui| {
                    ui.horizontal(|ui| {
                        closed = ui.small_button("✖").on_hover_text("Dismiss").clicked();
                        let t = egui::RichText::new(text);
                        ui.label(if err { t.color(ERROR_COLOR) } else { t });
                    });
                });
                closed
            };
            if let Some(e) = error {
                out.dismiss_error = row(ui, e, true);
            }
            for n in list.list() {
                if row(ui, &n.text, n.level == Level::Error) {
                    out.dismissed.push(n.id);
                }
            }
        });
    out
}

/// The help's rows: (keys or mouse input, what it does), every key binding then every
/// mouse action.
pub fn help_rows() -> Vec<(String, &'static str)> {
    BINDINGS
        .iter()
        .map(|b| (b.keys_label(), b.help))
        .chain(MOUSE_HELP.iter().map(|(k, h)| (k.to_string(), *h)))
        .collect()
}

/// The help's columns are at least this wide (points), else they go one under the other.
pub const HELP_COLUMN_MIN: f32 = 380.0;
/// Room for a key's name in the help (points); its description wraps in the rest.
pub const HELP_KEY_WIDTH: f32 = 130.0;

/// The help overlay in the middle of the scene; true when its close button was pressed.
/// Keys on the left, the mouse on the right (one column under the other in a narrow
/// window).
pub fn help(ctx: &egui::Context, scene: egui::Rect) -> bool {
    let mut close = false;
    let rows = help_rows();
    let (keys, mouse) = rows.split_at(BINDINGS.len());
    // The width inside the frame: the scene's less a margin, and two columns only when
    // each gets a readable width; every description wraps within its column.
    let width = (scene.width() - 40.0).clamp(160.0, 900.0);
    let two = width >= 2.0 * HELP_COLUMN_MIN + 20.0;
    let column = if two { (width - 20.0) / 2.0 } else { width };
    // Each row: the key in a fixed-width cell, its description wrapping in the rest of
    // the column (no grid: a grid sizes its columns from their widest cell, wider than
    // the window at 1024 px).
    let key_width = HELP_KEY_WIDTH.min(column * 0.4);
    let grid = |ui: &mut egui::Ui, rows: &[(String, &str)]| {
        ui.vertical(|ui| {
            ui.set_width(column);
            for (k, h) in rows {
                ui.horizontal_top(|ui| {
                    ui.vertical(|ui| {
                        ui.set_width(key_width);
                        ui.add(egui::Label::new(egui::RichText::new(k).monospace()).wrap());
                    });
                    ui.vertical(|ui| {
                        ui.set_width((column - key_width - ui.spacing().item_spacing.x).max(40.0));
                        ui.add(egui::Label::new(*h).wrap());
                    });
                });
            }
        });
    };
    egui::Area::new(egui::Id::new("help"))
        .fixed_pos(scene.center())
        .pivot(egui::Align2::CENTER_CENTER)
        .order(egui::Order::Foreground)
        .fade_in(false)
        .constrain_to(scene)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.set_max_width(width);
                ui.horizontal(|ui| {
                    ui.heading("Keys and mouse");
                    close = ui
                        .small_button("✖")
                        .on_hover_text("Close (Esc, ? or F1)")
                        .clicked();
                });
                egui::ScrollArea::vertical()
                    .max_height((scene.height() - 70.0).max(60.0))
                    .show(ui, |ui| {
                        if two {
                            ui.horizontal_top(|ui| {
                                grid(ui, keys);
                                ui.separator();
                                grid(ui, mouse);
                            });
                        } else {
                            // (No separator: it would take the whole width.)
                            grid(ui, keys);
                            ui.add_space(10.0);
                            grid(ui, mouse);
                        }
                    });
            });
        });
    close
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_help_lists_every_binding_and_mouse_action() {
        let rows = help_rows();
        assert_eq!(rows.len(), BINDINGS.len() + MOUSE_HELP.len());
        for b in BINDINGS {
            assert!(
                rows.iter()
                    .any(|(k, h)| *k == b.keys_label() && *h == b.help),
                "{:?} missing",
                b.action
            );
        }
        assert!(rows.iter().any(|(k, _)| k == "Ctrl+O"));
        assert!(rows.iter().any(|(k, _)| k == "double-click"));
    }

    #[test]
    fn a_recent_label_is_the_name_and_its_folder_elided_at_the_start() {
        let (n, f) = recent_label(std::path::Path::new("/a/b/c.jpg"), 40);
        assert_eq!((n.as_str(), f.as_str()), ("c.jpg", "/a/b"));
        let long = std::path::Path::new("/home/someone/Pictures/panoramas/2024/summer/x.jpg");
        let (n, f) = recent_label(long, 16);
        assert_eq!(n, "x.jpg");
        assert_eq!(f.chars().count(), 16);
        assert_eq!(f, "…mas/2024/summer", "the end of the folder kept");
    }

    /// One UI pass of the toolbar in a 1024×640 window with `events`; whether a popup
    /// (the recent-files menu) is open after it.
    fn toolbar_pass(ctx: &egui::Context, recent: &[PathBuf], events: Vec<egui::Event>) -> bool {
        let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1024.0, 640.0));
        let raw = egui::RawInput {
            screen_rect: Some(screen),
            events,
            ..Default::default()
        };
        let _ = ctx.run_ui(raw, |ui| {
            toolbar(
                ui.ctx(),
                ToolbarModel {
                    scene: screen,
                    title: "a.jpg",
                    recent,
                    panel: false,
                    help: false,
                },
            );
        });
        egui::Popup::is_any_open(ctx)
    }

    /// Issue 33 (7): the recent-files menu closes on Esc and when the pointer moves away.
    #[test]
    fn the_recent_menu_closes_on_escape_and_moving_away() {
        let recent = vec![PathBuf::from("/p/one.jpg"), PathBuf::from("/p/two.jpg")];
        let move_to = |x: f32, y: f32| egui::Event::PointerMoved(egui::pos2(x, y));
        let click = |x: f32, y: f32, pressed: bool| egui::Event::PointerButton {
            pos: egui::pos2(x, y),
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        };
        for close in ["escape", "away"] {
            let ctx = egui::Context::default();
            assert!(!toolbar_pass(&ctx, &recent, Vec::new()));
            // The ⏷ button: find it by trying the toolbar's start (it follows "Open").
            let mut opened = false;
            for x in (60..140).step_by(4) {
                let x = x as f32;
                toolbar_pass(&ctx, &recent, vec![move_to(x, 20.0)]);
                toolbar_pass(&ctx, &recent, vec![click(x, 20.0, true)]);
                if toolbar_pass(&ctx, &recent, vec![click(x, 20.0, false)]) {
                    opened = true;
                    // Staying near it keeps it open.
                    assert!(toolbar_pass(&ctx, &recent, vec![move_to(x, 30.0)]));
                    assert!(toolbar_pass(&ctx, &recent, Vec::new()));
                    break;
                }
            }
            assert!(opened, "the recent menu did not open");
            let ev = match close {
                "escape" => egui::Event::Key {
                    key: egui::Key::Escape,
                    physical_key: None,
                    pressed: true,
                    repeat: false,
                    modifiers: egui::Modifiers::NONE,
                },
                _ => move_to(900.0, 500.0),
            };
            toolbar_pass(&ctx, &recent, vec![ev]);
            assert!(
                !toolbar_pass(&ctx, &recent, Vec::new()),
                "{close}: still open"
            );
        }
    }

    /// Issue 33 (2): the help fits the scene of any window from 640×400 (its frame
    /// inside the scene, scrolled when taller), at 1024×640 too.
    #[test]
    fn the_help_fits_the_window() {
        for (w, h) in [
            (640.0, 400.0),
            (1024.0, 640.0),
            (800.0, 500.0),
            (1920.0, 1080.0),
            // The scene beside the panel in a 640×400 window.
            (640.0 - crate::window::ui::PANEL_WIDTH, 400.0),
        ] {
            let ctx = egui::Context::default();
            let scene = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(w, h));
            for _ in 0..3 {
                let raw = egui::RawInput {
                    screen_rect: Some(scene),
                    ..Default::default()
                };
                let _ = ctx.run_ui(raw, |ui| {
                    help(ui.ctx(), scene);
                });
            }
            let r = ctx
                .memory(|m| m.area_rect(egui::Id::new("help")))
                .expect("the help was drawn");
            assert!(
                scene.contains_rect(r),
                "{w}x{h}: the help {r:?} is not inside the window"
            );
            // Not squeezed: half the window at least, or its full width (900 points and
            // its frame) in a large one.
            assert!(
                r.width() > (w * 0.5).min(900.0),
                "{w}x{h}: the help is {r:?}"
            );
        }
    }
}

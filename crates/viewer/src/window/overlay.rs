//! The viewing UI over the full-width scene: a slim toolbar (open, recent files, save,
//! zoom, reset, fullscreen, the current file, the panel and help buttons), a compass
//! showing the heading, the notices, and the help overlay (`?` / F1) that lists every key
//! of [`super::keys::BINDINGS`] and every mouse action. Immediate mode from plain data, so
//! the tests paint it offscreen.

use super::input::Look;
use super::keys::{BINDINGS, MOUSE_HELP};
use super::notices::{Level, Notices};
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
                            for p in m.recent {
                                if ui.button(p.display().to_string()).clicked() {
                                    out.open_recent = Some(p.clone());
                                    ui.close();
                                }
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
                    out.panel = ui
                        .selectable_label(m.panel, panel)
                        .on_hover_text("Engineering panel (H)")
                        .clicked();
                    out.help = ui
                        .selectable_label(m.help, help)
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

/// Radius of the compass, points.
pub const COMPASS_RADIUS: f32 = 22.0;

/// The compass at the top right of the scene: the needle points to north when the
/// panorama knows its heading (GPano `PoseHeadingDegrees`), else to the map's centre
/// (yaw 0); the text is the heading (or the yaw).
pub fn compass(ctx: &egui::Context, scene: egui::Rect, look: &Look, pose_heading: Option<f64>) {
    let r = COMPASS_RADIUS;
    let center = egui::pos2(scene.max.x - r - 12.0, scene.min.y + r + 12.0);
    let heading = pose_heading.map(|p| lut_core::compass_heading(p, look.yaw));
    // Screen angle of north (or yaw 0), clockwise from up: minus the view's heading.
    let ahead = heading.unwrap_or(look.yaw);
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
                None => format!("yaw {:.0}°", look.yaw),
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

/// The help overlay in the middle of the scene; true when its close button was pressed.
/// Keys on the left, the mouse on the right (one column under the other in a narrow
/// window).
pub fn help(ctx: &egui::Context, scene: egui::Rect) -> bool {
    let mut close = false;
    let rows = help_rows();
    let (keys, mouse) = rows.split_at(BINDINGS.len());
    let grid = |ui: &mut egui::Ui, id: &str, rows: &[(String, &str)]| {
        egui::Grid::new(id).striped(true).show(ui, |ui| {
            for (k, h) in rows {
                ui.monospace(k);
                ui.label(*h);
                ui.end_row();
            }
        });
    };
    egui::Area::new(egui::Id::new("help"))
        .fixed_pos(scene.center())
        .pivot(egui::Align2::CENTER_CENTER)
        .order(egui::Order::Foreground)
        .fade_in(false)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.set_max_width((scene.width() - 32.0).clamp(200.0, 900.0));
                ui.horizontal(|ui| {
                    ui.heading("Keys and mouse");
                    close = ui
                        .small_button("✖")
                        .on_hover_text("Close (Esc, ? or F1)")
                        .clicked();
                });
                egui::ScrollArea::vertical()
                    .max_height((scene.height() - 60.0).max(100.0))
                    .show(ui, |ui| {
                        if scene.width() > 860.0 {
                            ui.horizontal_top(|ui| {
                                grid(ui, "help_keys", keys);
                                ui.separator();
                                grid(ui, "help_mouse", mouse);
                            });
                        } else {
                            // (No separator: it would take the whole width.)
                            grid(ui, "help_keys", keys);
                            ui.add_space(10.0);
                            grid(ui, "help_mouse", mouse);
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
}

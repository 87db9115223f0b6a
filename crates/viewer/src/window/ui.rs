//! The egui control panel (right side): the paper's turn and zoom buttons, the settings,
//! the readouts, and the load status. Immediate mode: drawn from plain data each frame,
//! so a test can paint it offscreen without a window.

use super::input::{AaMode, DragStyle, Held, Look, Settings};
use lut_core::{IndexStep, LutChoice, Projection, RenderPath, RendererKind, Sampler};

/// Width of the panel, in points.
pub const PANEL_WIDTH: f32 = 230.0;

/// Labels of the turn and zoom buttons: up, left, reset, right, down, zoom in, zoom out.
/// (Glyphs the default egui fonts have: a test checks.)
pub const BUTTON_LABELS: [&str; 7] = ["⬆", "⬅", "R", "➡", "⬇", "+", "−"];

/// Numbers shown under "Readouts".
#[derive(Debug, Clone, Default)]
pub struct Readouts {
    /// Renderer path of the last rendered frame.
    pub path: Option<RenderPath>,
    /// Bytes of the table(s) in use.
    pub table_bytes: usize,
    /// Pixels the last frame evaluated exactly / in total.
    pub exact_pixels: u64,
    /// Pixels of the last frame.
    pub pixels: u64,
    /// Milliseconds the last scene render took.
    pub render_ms: f64,
    /// Milliseconds the last UI pass and paint took.
    pub ui_ms: f64,
    /// Frames per second while frames are being drawn (0 when idle).
    pub fps: f64,
    /// Scene size in pixels.
    pub scene: (u32, u32),
    /// Panorama description: name, size, projection.
    pub map: String,
}

/// A background load in progress.
#[derive(Debug, Clone, PartialEq)]
pub enum LoadStatus {
    /// Reading the file: bytes done, total.
    Reading {
        /// File name.
        name: String,
        /// Bytes read so far.
        done: u64,
        /// File size.
        total: u64,
    },
    /// Decoding and building tables.
    Decoding {
        /// File name.
        name: String,
    },
}

/// What the panel shows and edits.
pub struct PanelModel<'a> {
    /// Settings the panel edits.
    pub settings: &'a mut Settings,
    /// Projection choice for the current file (`None` = auto); the panel edits it.
    pub projection: &'a mut Option<Projection>,
    /// The current view.
    pub look: Look,
    /// Readouts.
    pub readouts: &'a Readouts,
    /// A load in progress.
    pub loading: Option<&'a LoadStatus>,
    /// The last load error.
    pub error: Option<&'a str>,
}

/// What the user did in the panel this frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PanelOutput {
    /// Turn / zoom buttons held down.
    pub held: Held,
    /// Reset pressed.
    pub reset: bool,
    /// The projection choice changed: reload with it.
    pub projection_changed: bool,
    /// The error was dismissed.
    pub dismiss_error: bool,
}

/// Name of a renderer path for the readout.
pub fn path_label(p: Option<RenderPath>) -> &'static str {
    match p {
        Some(RenderPath::LutWide) => "wide-FOV LUT",
        Some(RenderPath::LutHigh) => "high-resolution LUT",
        Some(RenderPath::Exact) => "exact (no LUT)",
        None => "none yet",
    }
}

fn step_label(s: IndexStep) -> String {
    match s {
        IndexStep::Adaptive => "adaptive".into(),
        IndexStep::Fixed(n) => n.to_string(),
    }
}

fn kib(bytes: usize) -> String {
    if bytes >= 1 << 20 {
        format!("{:.1} MiB", bytes as f64 / f64::from(1u32 << 20))
    } else {
        format!("{:.1} KiB", bytes as f64 / 1024.0)
    }
}

/// Draw the panel on the right of `ui`; the rest of `ui` is left for the scene.
pub fn side_panel(ui: &mut egui::Ui, m: PanelModel<'_>) -> PanelOutput {
    let mut out = PanelOutput::default();
    egui::Panel::right("controls")
        .resizable(false)
        .exact_size(PANEL_WIDTH)
        .show_inside(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| panel_contents(ui, m, &mut out));
        });
    out
}

fn panel_contents(ui: &mut egui::Ui, m: PanelModel<'_>, out: &mut PanelOutput) {
    ui.heading("Panorama viewer");
    ui.label(&m.readouts.map);

    if let Some(l) = m.loading {
        ui.separator();
        match l {
            LoadStatus::Reading { name, done, total } => {
                ui.label(format!("Loading {name}"));
                let f = if *total > 0 {
                    *done as f32 / *total as f32
                } else {
                    0.0
                };
                ui.add(egui::ProgressBar::new(f).show_percentage());
            }
            LoadStatus::Decoding { name } => {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.label(format!("Decoding {name}"));
                });
            }
        }
    }
    if let Some(e) = m.error {
        ui.separator();
        ui.colored_label(egui::Color32::from_rgb(255, 120, 100), e);
        if ui.small_button("Dismiss").clicked() {
            out.dismiss_error = true;
        }
    }

    ui.separator();
    // The paper's direction buttons: turn at a steady speed while held.
    let held_btn = |ui: &mut egui::Ui, text: &str, hint: &str| {
        ui.add_sized([44.0, 28.0], egui::Button::new(text))
            .on_hover_text(hint)
            .is_pointer_button_down_on()
    };
    egui::Grid::new("turn").spacing([4.0, 4.0]).show(ui, |ui| {
        ui.label("");
        out.held.up = held_btn(ui, BUTTON_LABELS[0], "Look up (hold)");
        ui.label("");
        out.held.zoom_in = held_btn(ui, BUTTON_LABELS[5], "Zoom in (hold)");
        ui.end_row();
        out.held.left = held_btn(ui, BUTTON_LABELS[1], "Turn left (hold)");
        out.reset = ui
            .add_sized([44.0, 28.0], egui::Button::new(BUTTON_LABELS[2]))
            .on_hover_text("Reset the view")
            .clicked();
        out.held.right = held_btn(ui, BUTTON_LABELS[3], "Turn right (hold)");
        out.held.zoom_out = held_btn(ui, BUTTON_LABELS[6], "Zoom out (hold)");
        ui.end_row();
        ui.label("");
        out.held.down = held_btn(ui, BUTTON_LABELS[4], "Look down (hold)");
        ui.end_row();
    });

    ui.separator();
    let r = m.readouts;
    egui::Grid::new("readouts").num_columns(2).show(ui, |ui| {
        let mut row = |k: &str, v: String| {
            ui.label(k);
            ui.monospace(v);
            ui.end_row();
        };
        row("yaw", format!("{:8.2}°", m.look.yaw));
        row("pitch", format!("{:8.2}°", m.look.pitch));
        row("hfov", format!("{:8.2}°", m.look.hfov));
        row("in use", path_label(r.path).into());
        row("table", kib(r.table_bytes));
        if r.pixels > 0 && r.exact_pixels > 0 {
            row(
                "exact px",
                format!("{:.1}%", 100.0 * r.exact_pixels as f64 / r.pixels as f64),
            );
        }
        row("scene", format!("{}×{}", r.scene.0, r.scene.1));
        row("render", format!("{:6.2} ms", r.render_ms));
        row("UI", format!("{:6.2} ms", r.ui_ms));
        row("fps", format!("{:6.1}", r.fps));
    });

    ui.separator();
    let s = &mut *m.settings;
    egui::Grid::new("settings").num_columns(2).show(ui, |ui| {
        ui.label("Anti-aliasing");
        egui::ComboBox::from_id_salt("aa")
            .selected_text(s.aa.label())
            .show_ui(ui, |ui| {
                for a in [AaMode::Always, AaMode::StillOnly, AaMode::Off] {
                    ui.selectable_value(&mut s.aa, a, a.label());
                }
            });
        ui.end_row();

        ui.label("Sampler");
        egui::ComboBox::from_id_salt("sampler")
            .selected_text(s.sampler.name())
            .show_ui(ui, |ui| {
                for x in [Sampler::Bilinear, Sampler::Nearest] {
                    ui.selectable_value(&mut s.sampler, x, x.name());
                }
            });
        ui.end_row();

        ui.label("Index step");
        egui::ComboBox::from_id_salt("step")
            .selected_text(step_label(s.index_step))
            .show_ui(ui, |ui| {
                let steps = [IndexStep::Adaptive]
                    .into_iter()
                    .chain([1, 2, 4, 8, 16].map(IndexStep::Fixed));
                for x in steps {
                    ui.selectable_value(&mut s.index_step, x, step_label(x));
                }
            });
        ui.end_row();

        ui.label("Drag");
        egui::ComboBox::from_id_salt("drag")
            .selected_text(match s.drag {
                DragStyle::Grab => "grab",
                DragStyle::Qtvr => "QTVR",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut s.drag, DragStyle::Grab, "grab");
                ui.selectable_value(&mut s.drag, DragStyle::Qtvr, "QTVR");
            });
        ui.end_row();

        ui.label("Inertia");
        ui.checkbox(&mut s.inertia, "after grab");
        ui.end_row();

        ui.label("Renderer");
        egui::ComboBox::from_id_salt("renderer")
            .selected_text(match s.renderer {
                RendererKind::Lut => "LUT",
                RendererKind::Exact => "exact",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut s.renderer, RendererKind::Lut, "LUT");
                ui.selectable_value(&mut s.renderer, RendererKind::Exact, "exact");
            });
        ui.end_row();

        ui.label("LUT");
        egui::ComboBox::from_id_salt("lut")
            .selected_text(lut_label(s.lut))
            .show_ui(ui, |ui| {
                for x in [LutChoice::Auto, LutChoice::Wide, LutChoice::High] {
                    ui.selectable_value(&mut s.lut, x, lut_label(x));
                }
            });
        ui.end_row();

        ui.label("Projection");
        let before = *m.projection;
        egui::ComboBox::from_id_salt("projection")
            .selected_text(m.projection.map_or("auto", Projection::name))
            .show_ui(ui, |ui| {
                ui.selectable_value(m.projection, None, "auto");
                for p in Projection::ALL {
                    ui.selectable_value(m.projection, Some(p), p.name());
                }
            })
            .response
            .on_hover_text("How the image maps the sphere; auto takes 2:1 images as equirect");
        out.projection_changed = *m.projection != before;
        ui.end_row();
    });

    ui.separator();
    ui.small("Drag to look, wheel to zoom. Keys: arrows/WASD turn, +/− zoom, R reset, F fullscreen, Esc leave it, H/Tab panel. Drop an image to open it.");
}

fn lut_label(l: LutChoice) -> &'static str {
    match l {
        LutChoice::Auto => "auto (by hfov)",
        LutChoice::Wide => "wide-FOV",
        LutChoice::High => "high-res",
    }
}

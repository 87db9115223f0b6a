//! The engineering panel (right side, key H): the paper's turn and zoom buttons, the
//! render settings, the readouts, navigation, the image and the lights, in sections
//! ([`SECTIONS`]); and the load status. Immediate mode: drawn from plain data each frame,
//! so a test can paint it offscreen without a window. The viewing overlay (toolbar,
//! compass, notices, help) is `overlay.rs`.

use super::input::{AutoRotate, Held};
use super::quality::{Level, Settings, FRAME_BUDGET_MS};
use crate::lighting::LightsState;
use lut_core::{CubeRenderer, Named, Projection, RenderPath, Sampler, View};

mod projection;
pub use projection::{heat_label, PANEL_PANNINI_D_MAX};

/// Width of the panel, in points.
pub const PANEL_WIDTH: f32 = 230.0;

/// Labels of the turn and zoom buttons: up, left, reset, right, down, zoom in, zoom out.
/// (Glyphs the default egui fonts have: a test checks.)
pub const BUTTON_LABELS: [&str; 7] = ["⬆", "⬅", "R", "➡", "⬇", "+", "−"];

/// What the readouts show: the last rendered frame's numbers (reset when another
/// panorama is shown, so nothing of the previous one is left).
#[derive(Debug, Clone, Default)]
pub struct Readouts {
    /// A tiled pyramid's cache counters, tiles pending and the last frame's path.
    pub tiles: Option<(lut_core::CacheStats, usize, RenderPath)>,
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
    /// Scenes rendered in the last second (0 when idle).
    pub fps: f64,
    /// Scene size in pixels.
    pub scene: (u32, u32),
    /// The quality of the last rendered frame.
    pub level: Option<Level>,
    /// The sampler that rendered it.
    pub sampler: Option<Sampler>,
    /// The last full-quality frame's time at the current size (for the budget readout).
    pub full_ms: Option<f64>,
    /// Panorama description: name, size, projection.
    pub map: String,
    /// The scene is a cube map, rendered by this renderer (`None`: a LUT-rendered map).
    pub cube: Option<CubeRenderer>,
    /// The panorama is an HDR file (`.hdr`, `.exr`): the exposure slider is enabled.
    pub hdr: bool,
    /// A partial panorama: what it covers (the view-limit checkbox is shown).
    pub partial: Option<String>,
    /// Compass heading of the map's longitude 0 (GPano `PoseHeadingDegrees`).
    pub pose_heading: Option<f64>,
    /// The heat map's (max, mean) sampling-position error, source pixels, while it is
    /// shown.
    pub heat: Option<(f64, f64)>,
    /// Why that heat map is 0 everywhere, when it is by construction (cube maps, tiled
    /// pyramids: [`crate::heatmap::exact_note`]).
    pub heat_note: Option<&'static str>,
}

/// A step of loading a panorama in the window, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum LoadStep {
    /// Reading the compressed file (JPEG: read whole before decoding).
    Reading,
    /// Decoding pixels.
    Decoding,
    /// Writing the pixels into the map (0RGB, padding).
    Converting,
    /// Building the look-up tables and the minification pyramid.
    Tables,
}

impl LoadStep {
    /// Every step, in order.
    pub const ALL: [LoadStep; 4] = [
        LoadStep::Reading,
        LoadStep::Decoding,
        LoadStep::Converting,
        LoadStep::Tables,
    ];

    /// The label shown while the step runs.
    pub fn label(self) -> &'static str {
        match self {
            LoadStep::Reading => "reading the file",
            LoadStep::Decoding => "decoding",
            LoadStep::Converting => "converting to the map",
            LoadStep::Tables => "building look-up tables and pyramid",
        }
    }

    /// 1-based position in [`LoadStep::ALL`].
    pub fn number(self) -> usize {
        self as usize + 1
    }
}

impl From<lut_core::LoadPhase> for LoadStep {
    fn from(p: lut_core::LoadPhase) -> Self {
        match p {
            lut_core::LoadPhase::Reading => LoadStep::Reading,
            lut_core::LoadPhase::Decoding => LoadStep::Decoding,
            lut_core::LoadPhase::Converting => LoadStep::Converting,
        }
    }
}

/// A background load in progress: what the loading thread last reported.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadStatus {
    /// File name.
    pub name: String,
    /// The current step.
    pub step: LoadStep,
    /// Done fraction of the step; `None` when the decoder reports no progress (JPEG
    /// decoding, cube maps): drawn as an indeterminate bar with the elapsed time.
    pub fraction: Option<f32>,
    /// When the load started.
    pub started: std::time::Instant,
}

impl LoadStatus {
    /// A load of `name` that has not reported yet.
    pub fn new(name: String) -> Self {
        LoadStatus {
            name,
            step: LoadStep::Reading,
            fraction: None,
            started: std::time::Instant::now(),
        }
    }

    /// Take a progress report. Steps only move forward and a step's fraction only
    /// grows (a late or out-of-order report is ignored). True when something changed.
    pub fn advance(&mut self, step: LoadStep, fraction: Option<f32>) -> bool {
        let fraction = fraction.map(|f| if f.is_nan() { 0.0 } else { f.clamp(0.0, 1.0) });
        if step < self.step {
            return false;
        }
        if step == self.step {
            match (self.fraction, fraction) {
                (_, None) => return false,
                (Some(old), Some(new)) if new <= old => return false,
                _ => {}
            }
        }
        self.step = step;
        self.fraction = fraction;
        true
    }
}

/// A bar that says "busy, amount unknown": a block sliding to and fro with the time, never
/// a fraction.
fn indeterminate_bar(ui: &mut egui::Ui, t: f64) {
    let w = ui.available_width().min(200.0);
    let (rect, _) = ui.allocate_exact_size(egui::vec2(w, 12.0), egui::Sense::hover());
    let v = ui.visuals();
    ui.painter().rect_filled(rect, 4.0, v.extreme_bg_color);
    let block = rect.width() * 0.25;
    let phase = (t * 0.6).rem_euclid(2.0) as f32;
    let x = if phase < 1.0 { phase } else { 2.0 - phase } * (rect.width() - block);
    let r = egui::Rect::from_min_size(
        rect.min + egui::vec2(x, 0.0),
        egui::vec2(block, rect.height()),
    );
    ui.painter().rect_filled(r, 4.0, v.selection.bg_fill);
}

/// The load's name, step, and a bar: the step's fraction when known, else an
/// indeterminate bar with the elapsed time and the reason (repainted 5 times a second,
/// not every frame, so drawing does not slow the decoder down).
pub fn load_progress(ui: &mut egui::Ui, l: &LoadStatus) {
    let t = l.started.elapsed().as_secs_f64();
    ui.label(format!("Loading {}", l.name));
    ui.label(format!(
        "step {}/{}: {} · {t:.1} s",
        l.step.number(),
        LoadStep::ALL.len(),
        l.step.label()
    ));
    match l.fraction {
        Some(f) => {
            ui.add(egui::ProgressBar::new(f).show_percentage());
        }
        None => {
            indeterminate_bar(ui, t);
            ui.small(if l.step == LoadStep::Decoding {
                "this decoder reports no progress"
            } else {
                "no progress reported for this step"
            });
        }
    }
    ui.ctx()
        .request_repaint_after(std::time::Duration::from_millis(200));
}

/// [`load_progress`] in a box in the middle of the window, for when the panel is hidden
/// or there is no picture yet.
pub fn loading_overlay(ctx: &egui::Context, l: &LoadStatus) {
    egui::Area::new(egui::Id::new("loading"))
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .interactable(false)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.set_width(260.0);
                load_progress(ui, l);
            });
        });
}

/// What the panel shows and edits.
pub struct PanelModel<'a> {
    /// Settings the panel edits.
    pub settings: &'a mut Settings,
    /// Projection choice for the current file (`None` = auto); the panel edits it.
    pub projection: &'a mut Option<Projection>,
    /// The current view.
    pub look: View,
    /// Readouts.
    pub readouts: &'a Readouts,
    /// A load in progress.
    pub loading: Option<&'a LoadStatus>,
    /// Zoom limit in screen pixels per map pixel (`None`: off).
    pub zoom_limit: &'a mut Option<f64>,
    /// Auto-rotation.
    pub auto_rotate: &'a mut AutoRotate,
    /// The luminaires and their shading; the "Lights" section edits them.
    pub lights: &'a mut LightsState,
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
    /// The exposure changed (also while the slider is dragged): re-decode.
    pub exposure_changed: bool,
    /// "Save view…" was pressed.
    pub save_view: bool,
    /// "Open scene…" was pressed.
    pub open_scene: bool,
    /// "Save scene…" was pressed.
    pub save_scene: bool,
    /// "Report…" was pressed (the lights' report against EN 12464-1).
    pub report: bool,
    /// An output projection was chosen (or Pannini's d changed).
    pub view_projection: Option<lut_core::ViewProjection>,
    /// "Little planet" was pressed.
    pub planet: bool,
}

/// The "in use" readout: the cube renderer for a cube map ("cube (scanline)"), else the
/// LUT path.
pub fn in_use_label(r: &Readouts) -> String {
    match r.cube {
        Some(k) => format!("cube ({})", k.name()),
        None => path_label(r.path).into(),
    }
}

/// Name of a renderer path for the readout.
pub fn path_label(p: Option<RenderPath>) -> &'static str {
    match p {
        Some(RenderPath::LutWide) => "wide-FOV LUT",
        Some(RenderPath::LutHigh) => "high-resolution LUT",
        Some(RenderPath::Grid) => "per-view grid",
        Some(RenderPath::Exact) => "exact (no LUT)",
        Some(RenderPath::Cube(_)) => "cube map",
        Some(RenderPath::CubeProjected) => "cube map (per pixel)",
        Some(RenderPath::Tiles { coarser: false, .. }) => "tiled pyramid",
        Some(RenderPath::Tiles { coarser: true, .. }) => "tiled pyramid (tiles loading: coarser)",
        None => "none yet",
    }
}

/// The readout rows (label, value) the panel shows, in order; `--print-view` prints the
/// same strings, so a test reads what is drawn.
pub fn readout_rows(look: &View, r: &Readouts) -> Vec<(&'static str, String)> {
    let mut rows = vec![
        ("yaw", format!("{:8.2}°", look.yaw_deg())),
        ("pitch", format!("{:8.2}°", look.pitch_deg())),
        ("hfov", format!("{:8.2}°", look.hfov_deg())),
    ];
    if !look.projection().is_rectilinear() {
        rows.push(("projection", look.projection().to_string()));
    }
    if let Some((max, mean)) = r.heat {
        rows.push(("error max", format!("{max:.4} px")));
        rows.push(("error mean", format!("{mean:.5} px")));
    }
    if let Some(p) = r.pose_heading {
        let h = lut_core::compass_heading(p, look.yaw_deg());
        rows.push((
            "heading",
            format!("{h:8.2}° {}", lut_core::compass_point(h)),
        ));
    }
    rows.push(("in use", in_use_label(r)));
    let coarser = matches!(
        r.tiles,
        Some((_, _, RenderPath::Tiles { coarser: true, .. }))
    );
    rows.push((
        "quality",
        match (r.level, r.sampler) {
            (Some(l), Some(s)) if coarser => {
                format!("{} ({}), coarser than wanted", s.name(), l.label())
            }
            (Some(l), Some(s)) => format!("{} ({})", s.name(), l.label()),
            _ => "none yet".into(),
        },
    ));
    if let Some((st, pending, path)) = &r.tiles {
        if let RenderPath::Tiles { level, .. } = path {
            rows.push(("tile level", format!("{level}")));
        }
        rows.push((
            "tile cache",
            format!(
                "{} tiles, {:.1} of {:.0} MiB, hit rate {:.1} %",
                st.tiles,
                st.bytes as f64 / 1048576.0,
                st.budget as f64 / 1048576.0,
                st.hit_rate() * 100.0
            ),
        ));
        if *pending > 0 {
            rows.push(("tiles", format!("loading {pending} tiles")));
        }
    }
    rows.push(("table", kib(r.table_bytes)));
    if r.pixels > 0 && r.exact_pixels > 0 {
        rows.push((
            "exact px",
            format!("{:.1}%", 100.0 * r.exact_pixels as f64 / r.pixels as f64),
        ));
    }
    rows.push(("scene", format!("{}×{}", r.scene.0, r.scene.1)));
    rows.push(("render", format!("{:6.2} ms", r.render_ms)));
    if let Some(f) = r.full_ms {
        rows.push((
            "full frame",
            format!(
                "{f:6.2} ms {}",
                if f <= FRAME_BUDGET_MS {
                    "fits"
                } else {
                    "over budget"
                }
            ),
        ));
    }
    rows.push(("UI", format!("{:6.2} ms", r.ui_ms)));
    rows.push(("fps", format!("{:4.0}", r.fps)));
    rows
}

/// What a readout of [`readout_rows`] measures (its hover text).
pub fn readout_help(key: &str) -> &'static str {
    match key {
        "yaw" | "pitch" => "The view's direction, degrees",
        "hfov" => "The view's horizontal field of view, degrees",
        "heading" => "The compass heading of the view (from the file's GPano pose)",
        "projection" => "The output projection of the view",
        "error max" | "error mean" => {
            "The LUT's sampling error against the exact projection, in source pixels \
             (the heat map's max and mean over the frame)"
        }
        "in use" => "The renderer and table that drew the frame shown",
        "quality" => "The sampler and quality level of the frame shown",
        "tile level" => "The pyramid level the frame's tiles come from",
        "tile cache" => "Tiles in memory, their size against the budget, and the hit rate",
        "tiles" => "Tiles still loading (the frame shows coarser ones meanwhile)",
        "table" => "Memory of the look-up tables",
        "exact px" => "Share of the frame's pixels computed exactly (no LUT)",
        "scene" => "The scene's size in pixels",
        "render" => {
            "render: the time to compute the last frame's scene pixels (the panorama \
             through the LUT, at whatever quality that frame had), ms"
        }
        "full frame" => {
            "full frame: the recent full-quality renders' time at this size, against the \
             16 ms budget of a 60 Hz display (fits / over budget); moving frames degrade \
             when it is over"
        }
        "UI" => "The time to build and paint the panel and the overlays, ms",
        "fps" => "Frames drawn in the last second (0 when idle)",
        _ => "",
    }
}

/// A combo box of every value of `T`, by name, each with its help as the tooltip.
pub(super) fn named_combo<T: Named + PartialEq>(
    ui: &mut egui::Ui,
    id: &str,
    value: &mut T,
) -> egui::Response {
    egui::ComboBox::from_id_salt(id)
        .selected_text(value.name())
        .show_ui(ui, |ui| {
            for &x in T::ALL {
                let item = ui.selectable_value(value, x, x.name());
                if !x.help().is_empty() {
                    item.on_hover_text(x.help());
                }
            }
        })
        .response
}

fn kib(bytes: usize) -> String {
    if bytes >= 1 << 20 {
        format!("{:.1} MiB", bytes as f64 / f64::from(1u32 << 20))
    } else {
        format!("{:.1} KiB", bytes as f64 / 1024.0)
    }
}

/// A panel section: draws its own collapsible header and contents.
pub type Section = fn(&mut egui::Ui, &mut PanelModel<'_>, &mut PanelOutput);

/// The panel's sections, top to bottom. A feature adds its section here (a function
/// drawing a `CollapsingHeader`).
pub const SECTIONS: &[Section] = &[
    view_section,
    projection::projection_section,
    readouts_section,
    rendering_section,
    navigation_section,
    image_section,
    save_section,
    super::lights_panel::lights_section,
];

/// Draw the panel on the right of `ui`; the rest of `ui` is left for the scene.
pub fn side_panel(ui: &mut egui::Ui, mut m: PanelModel<'_>) -> PanelOutput {
    let mut out = PanelOutput::default();
    egui::Panel::right("controls")
        .resizable(false)
        .exact_size(PANEL_WIDTH)
        .show_inside(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.heading("Engineering panel");
                ui.label(&m.readouts.map);
                if let Some(l) = m.loading {
                    ui.separator();
                    load_progress(ui, l);
                }
                for section in SECTIONS {
                    section(ui, &mut m, &mut out);
                }
                ui.small("H hides this panel; ? or F1 lists every key.");
            });
        });
    out
}

fn section(ui: &mut egui::Ui, title: &str, open: bool, body: impl FnOnce(&mut egui::Ui)) {
    egui::CollapsingHeader::new(title)
        .id_salt(title)
        .default_open(open)
        .show(ui, body);
}

/// The paper's direction buttons (turn at a steady speed while held) and the view.
fn view_section(ui: &mut egui::Ui, _m: &mut PanelModel<'_>, out: &mut PanelOutput) {
    section(ui, "View", true, |ui| {
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
                .on_hover_text("Back to the start view")
                .clicked();
            out.held.right = held_btn(ui, BUTTON_LABELS[3], "Turn right (hold)");
            out.held.zoom_out = held_btn(ui, BUTTON_LABELS[6], "Zoom out (hold)");
            ui.end_row();
            ui.label("");
            out.held.down = held_btn(ui, BUTTON_LABELS[4], "Look down (hold)");
            ui.end_row();
        });
    });
}

fn readouts_section(ui: &mut egui::Ui, m: &mut PanelModel<'_>, _out: &mut PanelOutput) {
    section(ui, "Readouts", true, |ui| {
        egui::Grid::new("readouts").num_columns(2).show(ui, |ui| {
            for (k, v) in readout_rows(&m.look, m.readouts) {
                // Every readout says what it measures; long values wrap in the panel.
                let tip = readout_help(k);
                ui.label(k).on_hover_text(tip);
                ui.add(egui::Label::new(egui::RichText::new(v).monospace()).wrap())
                    .on_hover_text(tip);
                ui.end_row();
            }
        });
    });
}

fn rendering_section(ui: &mut egui::Ui, m: &mut PanelModel<'_>, _out: &mut PanelOutput) {
    let s = &mut *m.settings;
    section(ui, "Rendering", true, |ui| {
        egui::Grid::new("rendering").num_columns(2).show(ui, |ui| {
            ui.label("Anti-aliasing");
            named_combo(ui, "aa", &mut s.aa);
            ui.end_row();
            ui.label("Sampler");
            named_combo(ui, "sampler", &mut s.sampler);
            ui.end_row();
            ui.label("Index step");
            named_combo(ui, "step", &mut s.index_step);
            ui.end_row();
            ui.label("Renderer");
            named_combo(ui, "renderer", &mut s.renderer);
            ui.end_row();
            ui.label("Cube");
            named_combo(ui, "cube_renderer", &mut s.cube_renderer)
                .on_hover_text("Renderer for cube maps: basic (per pixel) or scanline");
            ui.end_row();
            ui.label("LUT");
            named_combo(ui, "lut", &mut s.lut);
            ui.end_row();
        });
    });
}

/// Zoom limit choices: (label, screen pixels per map pixel).
pub const ZOOM_LIMITS: [(&str, Option<f64>); 4] = [
    ("1 map px : 1 screen px", Some(1.0)),
    ("1 map px : 2 screen px", Some(2.0)),
    ("1 map px : 4 screen px", Some(4.0)),
    ("off (inspection)", None),
];

fn navigation_section(ui: &mut egui::Ui, m: &mut PanelModel<'_>, _out: &mut PanelOutput) {
    section(ui, "Navigation", false, |ui| {
        ui.spacing_mut().slider_width = 90.0;
        egui::Grid::new("navigation").num_columns(2).show(ui, |ui| {
            let s = &mut *m.settings;
            ui.label("Drag");
            named_combo(ui, "drag", &mut s.drag);
            ui.end_row();
            ui.label("Inertia");
            ui.checkbox(&mut s.inertia, "after grab");
            ui.end_row();
            ui.label("Zoom limit");
            let label = ZOOM_LIMITS
                .iter()
                .find(|z| z.1 == *m.zoom_limit)
                .map_or("custom", |z| z.0);
            egui::ComboBox::from_id_salt("zoom_limit")
                .selected_text(label)
                .show_ui(ui, |ui| {
                    for (l, v) in ZOOM_LIMITS {
                        ui.selectable_value(m.zoom_limit, v, l);
                    }
                })
                .response
                .on_hover_text(
                    "The narrowest view: how many screen pixels one map pixel may cover",
                );
            ui.end_row();
            let a = &mut *m.auto_rotate;
            ui.label("Auto-rotate");
            ui.checkbox(&mut a.enabled, "on (Space)");
            ui.end_row();
            ui.label("Speed");
            ui.add(egui::Slider::new(&mut a.speed_deg_s, -30.0..=30.0).suffix("°/s"));
            ui.end_row();
            ui.label("After idle");
            ui.add(egui::Slider::new(&mut a.idle_s, 0.0..=60.0).suffix(" s"));
            ui.end_row();
        });
    });
}

fn image_section(ui: &mut egui::Ui, m: &mut PanelModel<'_>, out: &mut PanelOutput) {
    section(ui, "Image", false, |ui| {
        egui::Grid::new("image").num_columns(2).show(ui, |ui| {
            ui.label("Projection");
            let before = *m.projection;
            egui::ComboBox::from_id_salt("projection")
                .selected_text(m.projection.map_or("auto", Projection::name))
                .show_ui(ui, |ui| {
                    ui.selectable_value(m.projection, None, "auto");
                    for p in Projection::ALL {
                        ui.selectable_value(m.projection, Some(p), p.name())
                            .on_hover_text(Named::help(p));
                    }
                })
                .response
                .on_hover_text("How the image maps the sphere; auto takes 2:1 images as equirect");
            out.projection_changed = *m.projection != before;
            ui.end_row();

            ui.label("Exposure (EV)");
            ui.spacing_mut().slider_width = 64.0;
            let (lo, hi) = super::input::EXPOSURE_RANGE_EV;
            let slider = ui
                .add_enabled(
                    m.readouts.hdr,
                    egui::Slider::new(&mut m.settings.exposure_ev, lo..=hi)
                        .step_by(0.1)
                        .max_decimals(1),
                )
                .on_hover_text("HDR panoramas (.hdr, .exr): stops of exposure; keys [ and ]")
                .on_disabled_hover_text("Only for HDR panoramas (.hdr, .exr)");
            out.exposure_changed = slider.changed();
            ui.end_row();
        });
        if let Some(p) = &m.readouts.partial {
            ui.label(format!("Partial panorama: {p}"));
            ui.checkbox(&mut m.settings.view_limit, "Keep the view inside")
                .on_hover_text(
                    "Limit pitch, yaw and zoom so the view's edges stay in the covered area",
                );
        }
    });
}

fn save_section(ui: &mut egui::Ui, m: &mut PanelModel<'_>, out: &mut PanelOutput) {
    section(ui, "Save", false, |ui| {
        ui.horizontal(|ui| {
            ui.label("Size");
            egui::ComboBox::from_id_salt("export_scale")
                .selected_text(format!("{}x", m.settings.export_scale))
                .show_ui(ui, |ui| {
                    for k in super::input::EXPORT_SCALES {
                        ui.selectable_value(&mut m.settings.export_scale, k, format!("{k}x"));
                    }
                })
                .response
                .on_hover_text("Size of the saved view: the scene's size times this");
        });
        out.save_view = ui
            .button("Save view…")
            .on_hover_text("Choose a file and write the view to it (Ctrl+S or P)")
            .clicked();
    });
}

/// The "Lights" section: add, place, aim and remove luminaires; multiplier, exposure,
/// false colour; the lux at the pointer.
#[cfg(test)]
mod tests {
    use super::{LoadStatus, LoadStep};

    /// Issue 33 (6): every readout the panel can show says what it measures, and
    /// "render" and "full frame" say which time each is.
    #[test]
    fn every_readout_has_a_hover_text() {
        use super::{readout_help, readout_rows, Readouts};
        use crate::window::input::steer_rect;
        let r = Readouts {
            full_ms: Some(20.0),
            heat: Some((0.01, 0.001)),
            pose_heading: Some(10.0),
            pixels: 100,
            exact_pixels: 5,
            ..Readouts::default()
        };
        for (k, _) in readout_rows(&steer_rect(0.0, 0.0, 90.0), &r) {
            assert!(!readout_help(k).is_empty(), "no hover text for {k}");
        }
        assert!(readout_help("render").starts_with("render: "));
        assert!(readout_help("full frame").starts_with("full frame: "));
    }

    #[test]
    fn advance_ignores_late_and_backward_reports() {
        let mut s = LoadStatus::new("x".into());
        assert!(s.advance(LoadStep::Decoding, Some(0.5)));
        assert!(
            !s.advance(LoadStep::Decoding, Some(0.4)),
            "a fraction went back"
        );
        assert!(!s.advance(LoadStep::Reading, Some(0.9)), "a step went back");
        assert!(
            !s.advance(LoadStep::Decoding, None),
            "a known fraction became unknown"
        );
        assert!(s.advance(LoadStep::Decoding, Some(f32::INFINITY)));
        assert_eq!(s.fraction, Some(1.0));
        assert!(s.advance(LoadStep::Converting, None));
        assert_eq!((s.step, s.fraction), (LoadStep::Converting, None));
    }

    /// What the window shows during real loads (the loading thread's events, with the
    /// table step it adds): steps only move forward, a step's known fractions grow and
    /// every step ends at 1; JPEG decoding is shown as unknown, not as a made-up number.
    #[test]
    fn progress_of_real_loads_is_monotone_and_ends_at_one() {
        let img = image::DynamicImage::ImageRgb8(image::RgbImage::from_fn(512, 256, |x, y| {
            image::Rgb([(x % 251) as u8, (y % 241) as u8, ((x * y) % 239) as u8])
        }));
        for format in [image::ImageFormat::Png, image::ImageFormat::Jpeg] {
            let mut bytes = Vec::new();
            img.write_to(&mut std::io::Cursor::new(&mut bytes), format)
                .unwrap();
            let mut st = LoadStatus::new("t".into());
            let mut shown = vec![(st.step, st.fraction)];
            let opts = lut_core::LoadOptions::default();
            lut_core::decode_map(&bytes, "t", &opts, &mut |p| {
                if st.advance(p.phase.into(), p.fraction) {
                    shown.push((st.step, st.fraction));
                }
            })
            .unwrap();
            for f in [0.0, 0.5, 1.0] {
                if st.advance(LoadStep::Tables, Some(f)) {
                    shown.push((st.step, st.fraction));
                }
            }
            assert!(shown.windows(2).all(|w| w[0].0 <= w[1].0), "{shown:?}");
            for step in LoadStep::ALL {
                let fr: Vec<Option<f32>> =
                    shown.iter().filter(|s| s.0 == step).map(|s| s.1).collect();
                let known: Vec<f32> = fr.iter().flatten().copied().collect();
                assert!(known.windows(2).all(|w| w[0] < w[1]), "{step:?} {fr:?}");
                if step != LoadStep::Reading || format == image::ImageFormat::Jpeg {
                    assert_eq!(fr.last(), Some(&Some(1.0)), "{format:?} {step:?} {fr:?}");
                }
            }
            let decoding_first = shown.iter().find(|s| s.0 == LoadStep::Decoding).unwrap().1;
            match format {
                image::ImageFormat::Jpeg => assert_eq!(decoding_first, None),
                _ => assert!(decoding_first.is_some()),
            }
            assert_eq!(shown.last(), Some(&(LoadStep::Tables, Some(1.0))));
        }
    }
}

//! The panel's "Projection" section (issue 12): the output projection, Pannini's d, the
//! little planet, and the error heat map toggle with its max, mean and legend.

use super::{section, PanelModel, PanelOutput};
use crate::heatmap::{BUDGET_PX, TICKS};
use lut_core::{heat_color, heat_scale, Named, ViewProjection, HEAT_MAX, HEAT_MIN};

/// Largest Pannini d the panel's slider offers (the CLI takes up to
/// `lut_core::PANNINI_D_MAX`).
pub const PANEL_PANNINI_D_MAX: f64 = 3.0;

/// The heat map's readout: "max 0.0123 px, mean 0.00140 px".
pub fn heat_label(max: f64, mean: f64) -> String {
    format!("max {max:.4} px, mean {mean:.5} px")
}

pub(super) fn projection_section(ui: &mut egui::Ui, m: &mut PanelModel<'_>, out: &mut PanelOutput) {
    let s = &mut *m.settings;
    let current = m.look.projection();
    section(ui, "Projection", true, |ui| {
        egui::Grid::new("projection").num_columns(2).show(ui, |ui| {
            ui.label("Output");
            egui::ComboBox::from_id_salt("view_projection")
                .selected_text(current.name())
                .show_ui(ui, |ui| {
                    for &p in ViewProjection::ALL {
                        let on = p.name() == current.name();
                        let item = ui.selectable_label(on, p.name()).on_hover_text(p.help());
                        if item.clicked() && !on {
                            out.view_projection = Some(p.with_pannini_d(s.pannini_d));
                        }
                    }
                })
                .response
                .on_hover_text("How the view maps to the screen (V cycles)");
            ui.end_row();
            if let ViewProjection::Pannini(d) = current {
                ui.label("Pannini d");
                let mut v = d;
                let slider = egui::Slider::new(&mut v, 0.0..=PANEL_PANNINI_D_MAX).max_decimals(2);
                if ui
                    .add(slider)
                    .on_hover_text("0: rectilinear, 1: classic Pannini")
                    .changed()
                {
                    s.pannini_d = v;
                    out.view_projection = Some(ViewProjection::Pannini(v));
                }
                ui.end_row();
            }
        });
        out.planet = ui
            .button("Little planet on/off (L)")
            .on_hover_text("Stereographic, looking straight down, 300° wide; again: back")
            .clicked();
        ui.checkbox(&mut s.heat_map, "Error heat map (E)")
            .on_hover_text(
                "Per pixel the sampling-position error of the renderer in use against the \
                 exact map, source pixels, log scale",
            );
        if s.heat_map {
            match m.readouts.heat {
                Some((max, mean)) => {
                    ui.monospace(heat_label(max, mean));
                    if let Some(note) = m.readouts.heat_note {
                        ui.label(egui::RichText::new(note).small());
                    }
                }
                None => {
                    ui.label("(measured with the next frame)");
                }
            }
            legend(ui);
        }
    });
}

/// The heat map's colour bar from [`HEAT_MIN`] to [`HEAT_MAX`] px (log scale), its
/// ticks and the 0.05 px budget, as `viewer render --error-map` draws it.
fn legend(ui: &mut egui::Ui) {
    let width = ui.available_width().min(200.0);
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 30.0), egui::Sense::hover());
    let p = ui.painter_at(rect);
    let bar = egui::Rect::from_min_size(rect.min, egui::vec2(width, 12.0));
    let n = 64;
    for i in 0..n {
        let t = (i as f64 + 0.5) / n as f64;
        let e = 10f64.powf(HEAT_MIN.log10() + t * (HEAT_MAX.log10() - HEAT_MIN.log10()));
        let c = heat_color(e);
        let x0 = bar.left() + width * i as f32 / n as f32;
        let x1 = bar.left() + width * (i + 1) as f32 / n as f32;
        let r = egui::Rect::from_x_y_ranges(x0..=x1, bar.y_range());
        let rgb = egui::Color32::from_rgb((c >> 16) as u8, (c >> 8) as u8, c as u8);
        p.rect_filled(r, 0.0, rgb);
    }
    let ink = ui.visuals().text_color();
    let at = |e: f64| bar.left() + width * heat_scale(e) as f32;
    let b = at(BUDGET_PX);
    p.line_segment(
        [
            egui::pos2(b, bar.top() - 2.0),
            egui::pos2(b, bar.bottom() + 2.0),
        ],
        egui::Stroke::new(2.0_f32, ink),
    );
    let font = egui::FontId::proportional(10.0);
    for t in TICKS {
        let align = if t == HEAT_MAX {
            egui::Align2::RIGHT_TOP
        } else if t == HEAT_MIN {
            egui::Align2::LEFT_TOP
        } else {
            egui::Align2::CENTER_TOP
        };
        let label = if t == HEAT_MAX {
            "1 px".to_string()
        } else {
            format!("{t}")
        };
        p.text(
            egui::pos2(at(t), bar.bottom() + 3.0),
            align,
            label,
            font.clone(),
            ink,
        );
    }
}

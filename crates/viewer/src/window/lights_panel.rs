//! The panel's "Lights" section: scene files, the room fitted to the photograph (size,
//! camera height, turn, centre; "Show room" draws it over the view), the luminaires
//! (selected in the list or by a click on their marker; position, aim, multiplier, on/off,
//! remove), the exposure (automatic or set), the surfaces' reflectances (inter-reflections),
//! interpolation and false colours; the work plane's Em and U0, live, and "Report…".

use super::ui::{named_combo, PanelModel, PanelOutput};
use crate::lighting::format_lux;

/// Colour of a selected luminaire's row and of errors.
const SELECTED: egui::Color32 = egui::Color32::from_rgb(255, 255, 255);
const ERROR: egui::Color32 = egui::Color32::from_rgb(255, 120, 100);

/// The "Lights" section (one of [`super::ui::SECTIONS`]).
pub fn lights_section(ui: &mut egui::Ui, m: &mut PanelModel<'_>, out: &mut PanelOutput) {
    let l = &mut *m.lights;
    egui::CollapsingHeader::new(format!("Lights ({})", l.lights.len()))
        .id_salt("lights")
        .default_open(!l.lights.is_empty())
        .show(ui, |ui| {
            ui.horizontal(|ui| {
                ui.label("lux at cursor");
                ui.monospace(format_lux(l.lux_at_cursor));
            });
            if !l.lights.is_empty() {
                ui.horizontal(|ui| {
                    ui.label("Work plane");
                    ui.monospace(&l.work_plane).on_hover_text(
                        "Maintained illuminance Em and uniformity U0 = Emin/Em on the work \
                         plane (0.75 m) on EN 12464-1's grid, with the inter-reflections, as \
                         `viewer report` computes them; solved on a thread of its own after \
                         each change",
                    );
                });
                out.report = ui
                    .button("Report…")
                    .on_hover_text(
                        "Write the lighting report (work plane, floor, ceiling, walls against \
                         EN 12464-1 office writing; luminaires; UGR) as HTML, JSON or PNG",
                    )
                    .clicked();
            }
            ui.horizontal(|ui| {
                out.open_scene = ui
                    .button("Open scene…")
                    .on_hover_text("A scene file: panorama, room, luminaires, exposure")
                    .clicked();
                out.save_scene = ui
                    .button("Save scene…")
                    .on_hover_text("Save the panorama, view, room and luminaires")
                    .clicked();
            });
            ui.horizontal(|ui| {
                let field = ui.add(
                    egui::TextEdit::singleline(&mut l.path_input)
                        .hint_text("file.ies / .ldt")
                        .desired_width(110.0),
                );
                let enter = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
                if (ui.button("Add light").clicked() || enter) && !l.path_input.trim().is_empty() {
                    let path = std::path::PathBuf::from(l.path_input.trim());
                    if l.load_and_add(&path).is_ok() {
                        l.path_input.clear();
                        l.selected = Some(l.lights.len() - 1);
                    }
                }
            });
            for e in [&l.error, &l.scene_error].into_iter().flatten() {
                ui.colored_label(ERROR, e);
            }
            if !l.lit_panorama.is_empty() {
                ui.label(&l.lit_panorama).on_hover_text(
                    "Once the lighting has settled the panorama is lit once, on a thread \
                     of its own, and panned like an unlit one; while it changes, and until \
                     the bake is done, each frame is lit",
                );
            }
            room_fields(ui, l);
            lights_list(ui, l);
            shading_fields(ui, l);
        });
}

/// The room box: shown over the view, size, camera height, turn and centre.
fn room_fields(ui: &mut egui::Ui, l: &mut crate::lighting::LightsState) {
    ui.checkbox(&mut l.show_room, "Show room").on_hover_text(
        "Draw the room box and the luminaires over the view; fit the box's edges to \
             the photograph's walls, floor and ceiling (drag an edge onto them). Click a \
             luminaire to select it, drag it to move it along the ceiling or its wall.",
    );
    ui.horizontal(|ui| {
        ui.label("Room");
        for v in [&mut l.room.0, &mut l.room.1, &mut l.room.2] {
            ui.add(
                egui::DragValue::new(v)
                    .speed(0.01)
                    .range(0.5..=lut_core::limits::MAX_ROOM_SIDE)
                    .max_decimals(2),
            )
            .on_hover_text("Width (X) × depth (Z) × height (Y), metres");
        }
    });
    egui::Grid::new("room_fit").num_columns(2).show(ui, |ui| {
        ui.label("Camera height");
        ui.add(
            egui::DragValue::new(&mut l.camera_height)
                .speed(0.01)
                .range(0.05..=100.0)
                .suffix(" m"),
        );
        ui.end_row();
        ui.label("Room turn");
        ui.add(
            egui::DragValue::new(&mut l.room_yaw)
                .speed(0.2)
                .range(-180.0..=180.0)
                .suffix("°"),
        )
        .on_hover_text("The box's turn about the vertical axis");
        ui.end_row();
        ui.label("Room centre");
        ui.horizontal(|ui| {
            for v in [&mut l.room_center.0, &mut l.room_center.1] {
                ui.add(egui::DragValue::new(v).speed(0.01).max_decimals(2))
                    .on_hover_text("X, Z of the room's centre from below the camera, metres");
            }
        });
        ui.end_row();
    });
}

/// The luminaires: select, switch, multiplier, position, aim, remove.
fn lights_list(ui: &mut egui::Ui, l: &mut crate::lighting::LightsState) {
    let mut remove = None;
    for (i, light) in l.lights.iter_mut().enumerate() {
        ui.push_id(("light", i), |ui| {
            let selected = l.selected == Some(i);
            ui.horizontal(|ui| {
                ui.checkbox(&mut light.enabled, "")
                    .on_hover_text("Switched on");
                let name = egui::RichText::new(format!("{}. {}", i + 1, light.name()));
                let name = if selected {
                    name.color(SELECTED).strong()
                } else {
                    name
                };
                if ui.selectable_label(selected, name).clicked() {
                    l.selected = if selected { None } else { Some(i) };
                }
                if ui.small_button("✖").on_hover_text("Remove").clicked() {
                    remove = Some(i);
                }
            });
            if !(selected || l.selected.is_none()) {
                return;
            }
            ui.horizontal(|ui| {
                for (axis, v) in ["X", "Y", "Z"].iter().zip(light.position.iter_mut()) {
                    ui.label(*axis);
                    ui.add(egui::DragValue::new(v).speed(0.01).max_decimals(2));
                }
            });
            ui.horizontal(|ui| {
                ui.label("yaw");
                ui.add(
                    egui::DragValue::new(&mut light.yaw)
                        .speed(1.0)
                        .range(-180.0..=180.0)
                        .suffix("°"),
                );
                ui.label("pitch");
                ui.add(
                    egui::DragValue::new(&mut light.pitch)
                        .speed(1.0)
                        .range(-90.0..=90.0)
                        .suffix("°"),
                );
            });
            ui.horizontal(|ui| {
                ui.label("multiplier");
                ui.add(
                    egui::DragValue::new(&mut light.multiplier)
                        .speed(0.01)
                        .range(0.0..=1000.0)
                        .max_decimals(2),
                );
            });
        });
    }
    if let Some(i) = remove {
        l.lights.remove(i);
        l.selected = match l.selected {
            Some(s) if s == i => None,
            Some(s) if s > i => Some(s - 1),
            s => s,
        };
    }
}

/// Multiplier, exposure (automatic or set), ambient, interpolation, false colours.
fn shading_fields(ui: &mut egui::Ui, l: &mut crate::lighting::LightsState) {
    // Sliders narrow enough that their value fields fit the fixed-width panel.
    ui.spacing_mut().slider_width = 64.0;
    egui::Grid::new("light_opts").num_columns(2).show(ui, |ui| {
        ui.label("Multiplier");
        ui.add(egui::Slider::new(&mut l.multiplier, 0.0..=10.0).logarithmic(true))
            .on_hover_text("Every luminaire's intensity times this");
        ui.end_row();
        ui.label("Exposure");
        let slider = ui.add_enabled(
            !l.auto_exposure,
            egui::Slider::new(&mut l.exposure_lux, 1.0..=5000.0)
                .logarithmic(true)
                .suffix(" lx"),
        );
        slider.on_hover_text("Illuminance that looks as bright as the photograph");
        ui.end_row();
        ui.label("");
        ui.checkbox(&mut l.auto_exposure, "automatic")
            .on_hover_text("Follow the lights: 95 % of the room's surface below the exposure");
        ui.end_row();
        ui.label("Ambient");
        ui.add(egui::Slider::new(&mut l.ambient, 0.0..=1.0));
        ui.end_row();
        ui.label("Reflected");
        ui.checkbox(&mut l.indirect, "inter-reflections")
            .on_hover_text("Add the light the floor, walls and ceiling reflect (radiosity)");
        ui.end_row();
        if l.indirect {
            for (name, v) in [
                ("Floor ρ", &mut l.reflectances.floor),
                ("Walls ρ", &mut l.reflectances.walls),
                ("Ceiling ρ", &mut l.reflectances.ceiling),
            ] {
                ui.label(name);
                ui.add(egui::Slider::new(v, 0.0..=0.95))
                    .on_hover_text("Diffuse reflectance of the surface, 0 (black) to 0.95");
                ui.end_row();
            }
        }
        ui.label("Interpolation");
        let mut interp = l.interpolation;
        named_combo(ui, "light_interp", &mut interp);
        if interp != l.interpolation {
            if let Err(e) = l.set_interpolation(interp) {
                l.error = Some(format!("{e:#}"));
            }
        }
        ui.end_row();
        ui.label("False colour");
        ui.checkbox(&mut l.false_color, "illuminance")
            .on_hover_text("The lux as colours, with their legend at the view's right edge");
        ui.end_row();
        if l.false_color {
            ui.label("Scale top");
            ui.add(
                egui::Slider::new(&mut l.false_color_max, 10.0..=10000.0)
                    .logarithmic(true)
                    .suffix(" lx"),
            );
            ui.end_row();
        }
    });
}

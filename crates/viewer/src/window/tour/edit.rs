//! Editing the tour in the window: the Edit toggle in the tour bar opens a panel whose
//! buttons build the edit operations of [`crate::tour::edit`] from the pointer and the
//! view: a click on the scene picks a spot (or, on a marker, selects that hotspot);
//! then a link to a scene of the tour or an info hotspot with text is added at the
//! spot, the selected hotspot is moved there or deleted; the scene's start view is the
//! current view, north the view's centre; its horizon is levelled with the pitch and
//! roll sliders or by dragging its horizon line (the level mode, [`super::level`]; the
//! scene reloads, levelled); scenes are added (a panorama file inside
//! the tour's folder) and removed; Ctrl+Z undoes, Ctrl+Shift+Z or Ctrl+Y redoes; Save
//! writes a Pannellum config (the tour's own file, or `data.json` beside a Marzipano
//! `data.js`).

use super::{scene_source, Pending, TourAction, TourNav};
use crate::tour::edit::{self, History, Op};
use crate::tour::{markers, Angles, Format, Horizon};
use lut_core::View;
use std::path::PathBuf;

/// The horizon sliders' range, degrees.
pub const HORIZON_RANGE: f64 = 30.0;

/// The editor's state (off until the Edit toggle is pressed).
#[derive(Debug, Clone, Default)]
pub struct Editor {
    /// Edit mode: clicks pick spots and hotspots instead of following links.
    pub on: bool,
    /// The edits and their undo.
    pub history: History,
    /// The hotspot selected in the scene shown.
    pub selected: Option<usize>,
    /// The spot clicked (yaw, pitch), where hotspots are added or moved to.
    pub spot: Option<(f64, f64)>,
    /// The text of a hotspot to add.
    pub text: String,
    /// The scene a new link goes to.
    pub target: usize,
    /// A panorama file to add as a scene (a path, relative to the tour's folder or not).
    pub scene_file: String,
    /// Where the edit panel's text field and Add info and Save buttons were drawn
    /// (centres, window points; empty when the panel is not shown), for `--print-view`'s
    /// `tour ui` line (the Xvfb test clicks them).
    pub ui_at: Vec<(&'static str, egui::Pos2)>,
    /// The level-horizon mode (a drag on the horizon line levels the scene).
    pub level: super::LevelMode,
}

/// What the edit panel's user asked.
#[derive(Debug, Clone, PartialEq)]
pub enum EditRequest {
    /// Add a link to scene `target` at the spot.
    AddLink,
    /// Add an info hotspot at the spot.
    AddInfo,
    /// Move the selected hotspot to the spot.
    Move,
    /// Delete the selected hotspot.
    Delete,
    /// The current view is the scene's start view.
    SetStart,
    /// The view's centre faces north.
    SetNorth,
    /// Level the horizon by this pitch and roll.
    Horizon(Horizon),
    /// The level-horizon mode on or off (drag the horizon line).
    Level,
    /// Add the panorama file as a scene.
    AddScene,
    /// Remove scene `i`.
    RemoveScene(usize),
    /// Undo.
    Undo,
    /// Redo.
    Redo,
    /// Save.
    Save,
}

impl TourNav {
    /// In edit mode, a click at (`x`, `y`) of a `w × h` frame of `look`: on a marker it
    /// selects the hotspot, elsewhere it picks the spot. False when not editing.
    pub fn edit_click(&mut self, look: &View, w: u32, h: u32, x: f64, y: f64) -> bool {
        if !self.editor.on {
            return false;
        }
        match self.hotspot_at(look, w, h, x, y) {
            Some(i) => self.editor.selected = Some(i),
            None => self.editor.spot = markers::direction_at(*look, w, h, x, y),
        }
        true
    }

    /// Where a save goes: the Pannellum config itself, or `data.json` beside a Marzipano
    /// `data.js`.
    pub fn save_path(&self) -> PathBuf {
        match crate::tour::sniff(&self.path) {
            // Beside it, never over it (a Marzipano export named `.json`).
            Some(Format::Marzipano) | None => match self.path.with_extension("json") {
                p if p == self.path => self.path.with_extension("pannellum.json"),
                p => p,
            },
            Some(Format::Pannellum) => self.path.clone(),
        }
    }

    /// Carry out `req` at the view `look`: the notice to show and, when the scene shown
    /// changed or must reload (a new horizon), what to load.
    pub fn edit_request(&mut self, req: EditRequest, look: View) -> Vec<TourAction> {
        let cur = self.current;
        let spot = self.editor.spot;
        let sel = self
            .editor
            .selected
            .filter(|&i| i < self.scene().hotspots.len());
        let need_spot = || TourAction::Error("click the scene where it goes first".into());
        let need_sel = || TourAction::Error("click a hotspot's marker to select it first".into());
        let op = match req {
            EditRequest::AddLink | EditRequest::AddInfo => {
                let Some((yaw, pitch)) = spot else {
                    return vec![need_spot()];
                };
                let target = if req == EditRequest::AddLink {
                    match self.tour.scenes.get(self.editor.target) {
                        Some(s) => Some(s.id.clone()),
                        None => return vec![TourAction::Error("choose a scene to link to".into())],
                    }
                } else {
                    None
                };
                let text = match (&target, self.editor.text.trim()) {
                    (Some(id), "") => self
                        .tour
                        .scene(id)
                        .and_then(|s| s.title.clone())
                        .unwrap_or_else(|| id.clone()),
                    (_, t) => t.to_string(),
                };
                let index = self.scene().hotspots.len();
                let hotspot = Box::new(edit::new_hotspot(yaw, pitch, &text, target.as_deref()));
                self.editor.selected = Some(index);
                (
                    if target.is_some() {
                        "add link"
                    } else {
                        "add info"
                    },
                    Op::InsertHotspot {
                        scene: cur,
                        index,
                        hotspot,
                    },
                )
            }
            EditRequest::Move => {
                let (Some(i), Some((yaw, pitch))) = (sel, spot) else {
                    return vec![if sel.is_none() {
                        need_sel()
                    } else {
                        need_spot()
                    }];
                };
                let mut h = self.scene().hotspots[i].clone();
                h.yaw = edit::wrap180(yaw);
                h.pitch = pitch.clamp(-90.0, 90.0);
                (
                    "move hotspot",
                    Op::SetHotspot {
                        scene: cur,
                        index: i,
                        hotspot: Box::new(h),
                    },
                )
            }
            EditRequest::Delete => {
                let Some(i) = sel else {
                    return vec![need_sel()];
                };
                self.editor.selected = None;
                (
                    "delete hotspot",
                    Op::RemoveHotspot {
                        scene: cur,
                        index: i,
                    },
                )
            }
            EditRequest::SetStart => (
                "set start view",
                Op::SetStart {
                    scene: cur,
                    start: Angles {
                        yaw: look.yaw_deg(),
                        pitch: look.pitch_deg(),
                        hfov: look.hfov_deg(),
                    },
                },
            ),
            EditRequest::SetNorth => (
                "set north",
                Op::SetNorth {
                    scene: cur,
                    north: edit::north_facing(look.yaw_deg()),
                },
            ),
            EditRequest::Horizon(h) => (
                "level horizon",
                Op::SetHorizon {
                    scene: cur,
                    horizon: h,
                },
            ),
            EditRequest::Level => {
                return match self.level_toggle() {
                    Ok(true) => vec![TourAction::Info(
                        "level horizon: drag the green line (the panorama's horizon) onto \
                         the level; Esc or Enter: done"
                            .into(),
                    )],
                    Ok(false) => vec![],
                    Err(e) => vec![TourAction::Error(e)],
                };
            }
            EditRequest::AddScene => {
                let f = PathBuf::from(self.editor.scene_file.trim());
                let f = if f.is_relative() {
                    self.tour.dir.join(f)
                } else {
                    f
                };
                if !f.is_file() {
                    return vec![TourAction::Error(format!(
                        "{}: no such file to add as a scene",
                        f.display()
                    ))];
                }
                match edit::scene_for_file(&self.tour, &f) {
                    Ok(s) => (
                        "add scene",
                        Op::InsertScene {
                            index: self.tour.scenes.len(),
                            scene: Box::new(s),
                        },
                    ),
                    Err(e) => return vec![TourAction::Error(e)],
                }
            }
            EditRequest::RemoveScene(i) => {
                if i == cur {
                    return vec![TourAction::Error(
                        "the scene shown cannot be removed: go to another scene first".into(),
                    )];
                }
                match edit::remove_scene(&self.tour, i) {
                    Some(op) => ("remove scene", op),
                    None => return vec![],
                }
            }
            EditRequest::Undo | EditRequest::Redo => {
                let before = self.before();
                let name = if req == EditRequest::Undo {
                    self.editor.history.undo(&mut self.tour)
                } else {
                    self.editor.history.redo(&mut self.tour)
                };
                let Some(name) = name else {
                    return vec![];
                };
                let verb = if req == EditRequest::Undo {
                    "undone"
                } else {
                    "redone"
                };
                let mut out = vec![TourAction::Info(format!("{name}: {verb}"))];
                out.extend(self.after(before, look));
                return out;
            }
            EditRequest::Save => {
                let to = self.save_path();
                return vec![match crate::tour::pannellum::save(&self.tour, &to) {
                    Ok(left_out) => {
                        self.editor.history.saved();
                        let mut m = format!("saved {}", to.display());
                        if !left_out.is_empty() {
                            // Each scene left out with its reason (Marzipano levels
                            // Pannellum's multires cannot describe).
                            m += &format!(
                                "; left out: scene {} (`viewer tour convert --tile` writes \
                                 a Pannellum pyramid for it)",
                                left_out.join("; scene ")
                            );
                        }
                        TourAction::Info(m)
                    }
                    Err(e) => TourAction::Error(format!("{e:#}")),
                }];
            }
        };
        let before = self.before();
        match self.editor.history.edit(&mut self.tour, op.0, op.1) {
            Ok(()) => self.after(before, look),
            Err(e) => vec![TourAction::Error(e)],
        }
    }

    /// What an edit may change that the window must follow: the scene shown (its id),
    /// the number of scenes, its horizon.
    fn before(&self) -> (String, usize, Horizon) {
        let s = self.scene();
        (s.id.clone(), self.tour.scenes.len(), s.horizon)
    }

    /// After an edit: the scene shown found again by its id (or the first scene, when an
    /// undo took it away); the history of visits dropped when scenes came or went (its
    /// indices would be wrong); a reload when the shown scene's horizon changed.
    fn after(&mut self, (id, n, horizon): (String, usize, Horizon), look: View) -> Vec<TourAction> {
        if self.tour.scenes.len() != n {
            self.back.clear();
            self.forward.clear();
        }
        if self.tour.scenes.is_empty() {
            return vec![TourAction::Error("the tour has no scenes left".into())];
        }
        let Some(i) = self.tour.index(&id) else {
            let first = self
                .tour
                .first()
                .and_then(|f| self.tour.index(&f.id))
                .unwrap_or(0);
            self.current = first.min(self.tour.scenes.len() - 1);
            self.editor.selected = None;
            let view = self.scene().start;
            return vec![self.go(self.current, view)];
        };
        self.current = i;
        if self
            .editor
            .selected
            .is_some_and(|s| s >= self.scene().hotspots.len())
        {
            self.editor.selected = None;
        }
        self.editor.target = self.editor.target.min(self.tour.scenes.len() - 1);
        if self.scene().horizon != horizon {
            return vec![self.reload(look)];
        }
        vec![]
    }

    /// Load the scene shown again (a new horizon), arriving at `look`, no crossfade.
    fn reload(&mut self, look: View) -> TourAction {
        match scene_source(&self.tour, self.current) {
            Ok(source) => {
                self.pending = Some(Pending {
                    scene: self.current,
                    source: source.clone(),
                    view: Self::angles(look),
                    fade: false,
                });
                TourAction::Load(source)
            }
            Err(e) => TourAction::Error(e),
        }
    }
}

/// The ids of the panel's text fields.
const TEXT_IDS: [&str; 2] = ["tour-edit-text", "tour-edit-scene-file"];

/// Whether one of the edit panel's text fields has the keyboard (Ctrl+Z is then the
/// field's, not the tour's).
pub fn typing(ctx: &egui::Context) -> bool {
    ctx.memory(|m| TEXT_IDS.iter().any(|id| m.has_focus(egui::Id::new(id))))
}

/// The edit panel under the tour bar; returns what was asked.
pub fn edit_panel(ctx: &egui::Context, scene: egui::Rect, nav: &mut TourNav) -> Vec<EditRequest> {
    let mut out = Vec::new();
    let cur = nav.current();
    let names: Vec<String> = nav
        .tour
        .scenes
        .iter()
        .map(|s| s.title.clone().unwrap_or_else(|| s.id.clone()))
        .collect();
    let horizon = nav.scene().horizon;
    let (undo, redo) = nav.editor.history.next();
    let (undo, redo) = (undo.map(str::to_string), redo.map(str::to_string));
    let modified = nav.editor.history.modified();
    let save_to = nav.save_path();
    let ed = &mut nav.editor;
    ed.ui_at.clear();
    egui::Area::new(egui::Id::new("tour-edit"))
        .fixed_pos(scene.min + egui::vec2(8.0, 84.0))
        .order(egui::Order::Foreground)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style())
                .fill(ui.visuals().window_fill.gamma_multiply(0.9))
                .inner_margin(egui::Margin::symmetric(6, 4))
                .show(ui, |ui| {
                    ui.horizontal(|ui| {
                        let tip = |n: &Option<String>, k: &str| {
                            n.as_ref()
                                .map_or(format!("nothing to {k}"), |n| format!("{k} {n}"))
                        };
                        if ui
                            .add_enabled(undo.is_some(), egui::Button::new("Undo"))
                            .on_hover_text(format!("{} (Ctrl+Z)", tip(&undo, "undo")))
                            .clicked()
                        {
                            out.push(EditRequest::Undo);
                        }
                        if ui
                            .add_enabled(redo.is_some(), egui::Button::new("Redo"))
                            .on_hover_text(format!("{} (Ctrl+Shift+Z, Ctrl+Y)", tip(&redo, "redo")))
                            .clicked()
                        {
                            out.push(EditRequest::Redo);
                        }
                        let label = if modified { "Save*" } else { "Save" };
                        let save = ui.button(label).on_hover_text(format!(
                            "Save as a Pannellum config: {}",
                            save_to.display()
                        ));
                        ed.ui_at.push(("save", save.rect.center()));
                        if save.clicked() {
                            out.push(EditRequest::Save);
                        }
                    });
                    ui.label(match ed.spot {
                        Some((y, p)) => {
                            format!("Spot: yaw {y:.1}°, pitch {p:.1}° (click the scene to move it)")
                        }
                        None => "Click the scene to pick a spot, a marker to select it".into(),
                    });
                    ui.horizontal(|ui| {
                        ui.label("Text");
                        let text = ui.add(
                            egui::TextEdit::singleline(&mut ed.text)
                                .id(egui::Id::new(TEXT_IDS[0]))
                                .desired_width(160.0),
                        );
                        ed.ui_at.push(("text", text.rect.center()));
                    });
                    ui.horizontal(|ui| {
                        egui::ComboBox::from_id_salt("tour-edit-target")
                            .selected_text(names.get(ed.target).cloned().unwrap_or_default())
                            .show_ui(ui, |ui| {
                                for (i, n) in names.iter().enumerate() {
                                    ui.selectable_value(&mut ed.target, i, n);
                                }
                            });
                        if ui
                            .button("Add link")
                            .on_hover_text("A link to that scene at the spot")
                            .clicked()
                        {
                            out.push(EditRequest::AddLink);
                        }
                        let info = ui
                            .button("Add info")
                            .on_hover_text("An info hotspot with the text at the spot");
                        ed.ui_at.push(("add-info", info.rect.center()));
                        if info.clicked() {
                            out.push(EditRequest::AddInfo);
                        }
                    });
                    ui.horizontal(|ui| {
                        ui.label(match ed.selected {
                            Some(i) => format!("Hotspot {i}"),
                            None => "No hotspot selected".into(),
                        });
                        if ui
                            .add_enabled(ed.selected.is_some(), egui::Button::new("Move to spot"))
                            .clicked()
                        {
                            out.push(EditRequest::Move);
                        }
                        if ui
                            .add_enabled(ed.selected.is_some(), egui::Button::new("Delete"))
                            .clicked()
                        {
                            out.push(EditRequest::Delete);
                        }
                    });
                    ui.horizontal(|ui| {
                        if ui
                            .button("Start view here")
                            .on_hover_text("The scene starts at the current view")
                            .clicked()
                        {
                            out.push(EditRequest::SetStart);
                        }
                        if ui
                            .button("North is here")
                            .on_hover_text("The view's centre faces north (northOffset)")
                            .clicked()
                        {
                            out.push(EditRequest::SetNorth);
                        }
                    });
                    ui.horizontal(|ui| {
                        let lv = ui
                            .selectable_label(ed.level.on, "Level horizon")
                            .on_hover_text(
                                "Drag the horizon line (green) to level the scene; \
                                 Esc or Enter: done (T)",
                            );
                        ed.ui_at.push(("level", lv.rect.center()));
                        if lv.clicked() {
                            out.push(EditRequest::Level);
                        }
                        if ed.level.on {
                            ui.label("drag the green line; Esc/Enter: done");
                        }
                    });
                    let (mut p, mut r) = (horizon.pitch, horizon.roll);
                    let range = -HORIZON_RANGE..=HORIZON_RANGE;
                    let sp = ui.add(
                        egui::Slider::new(&mut p, range.clone())
                            .step_by(0.1)
                            // A value set elsewhere (a drag of the horizon line, a file's
                            // 40°) is shown as it is, not snapped or clamped into an edit.
                            .clamping(egui::SliderClamping::Edits)
                            .text("horizon pitch °"),
                    );
                    let sr = ui.add(
                        egui::Slider::new(&mut r, range)
                            .step_by(0.1)
                            // A value set elsewhere (a drag of the horizon line, a file's
                            // 40°) is shown as it is, not snapped or clamped into an edit.
                            .clamping(egui::SliderClamping::Edits)
                            .text("horizon roll °"),
                    );
                    // Applied when the slider is let go (each change re-levels the map).
                    let done =
                        |s: &egui::Response| s.drag_stopped() || (s.changed() && !s.dragged());
                    if (done(&sp) || done(&sr)) && (p, r) != (horizon.pitch, horizon.roll) {
                        out.push(EditRequest::Horizon(Horizon { pitch: p, roll: r }));
                    }
                    ui.horizontal(|ui| {
                        ui.add(
                            egui::TextEdit::singleline(&mut ed.scene_file)
                                .id(egui::Id::new(TEXT_IDS[1]))
                                .hint_text("panorama in the tour's folder")
                                .desired_width(160.0),
                        );
                        if ui.button("Add scene").clicked() {
                            out.push(EditRequest::AddScene);
                        }
                    });
                    ui.horizontal(|ui| {
                        ui.menu_button("Remove scene…", |ui| {
                            for (i, n) in names.iter().enumerate() {
                                if ui.add_enabled(i != cur, egui::Button::new(n)).clicked() {
                                    out.push(EditRequest::RemoveScene(i));
                                    ui.close();
                                }
                            }
                        });
                    });
                });
        });
    out
}

#[cfg(test)]
mod tests {
    use super::super::tests::{sample, shown};
    use super::*;
    use crate::tour::HotspotKind;
    use crate::window::input::steer_rect;
    use crate::window::loader::Source;

    #[test]
    fn a_click_picks_a_spot_or_selects_a_marker_and_the_panel_edits_there() {
        let mut nav = sample();
        shown(&mut nav);
        let look = steer_rect(60.0, -2.0, 90.0);
        let (w, h) = (400, 300);
        assert!(
            !nav.edit_click(&look, w, h, 100.0, 100.0),
            "not editing: not the editor's"
        );
        nav.editor.on = true;
        // A spot: the direction under the pointer, which the markers put back there.
        assert!(nav.edit_click(&look, w, h, 100.0, 80.0));
        let (yaw, pitch) = nav.editor.spot.unwrap();
        let (x, y) = markers::place(look, w, h, yaw, pitch).unwrap();
        assert!(
            (x - 100.0).abs() < 1e-6 && (y - 80.0).abs() < 1e-6,
            "{x},{y}"
        );
        assert!(
            yaw < 60.0 && pitch > -2.0,
            "left of and above the centre: {yaw},{pitch}"
        );
        // A link to the cube scene there, with that scene's title as its text.
        nav.editor.target = 2;
        let a = nav.edit_request(EditRequest::AddLink, look);
        assert!(a.is_empty(), "{a:?}");
        let hs = nav.scene().hotspots.last().unwrap().clone();
        assert!((hs.yaw - yaw).abs() < 1e-9 && (hs.pitch - pitch).abs() < 1e-9);
        assert_eq!(hs.text, "Courtyard (cube)");
        assert!(
            matches!(&hs.kind, HotspotKind::Scene { scene_id, .. } if scene_id == "courtyardCube")
        );
        assert_eq!(nav.hotspot_at(&look, w, h, 100.0, 80.0), Some(3));
        // Select hotspot 0 (the view's centre), move it to a new spot, delete it.
        assert!(nav.edit_click(&look, w, h, 200.0, 150.0));
        assert_eq!(nav.editor.selected, Some(0));
        nav.edit_click(&look, w, h, 300.0, 200.0);
        assert!(nav.edit_request(EditRequest::Move, look).is_empty());
        assert_eq!(nav.hotspot_at(&look, w, h, 300.0, 200.0), Some(0));
        assert_eq!(nav.hotspot_at(&look, w, h, 200.0, 150.0), None);
        nav.edit_request(EditRequest::Delete, look);
        assert_eq!(nav.scene().hotspots.len(), 3);
        assert_eq!(nav.editor.selected, None);
        assert!(matches!(
            nav.edit_request(EditRequest::Delete, look)[..],
            [TourAction::Error(_)]
        ));
        // Undo three times: the tour as it was opened.
        for _ in 0..3 {
            assert!(matches!(
                nav.edit_request(EditRequest::Undo, look)[..],
                [TourAction::Info(_)]
            ));
        }
        assert_eq!(nav.tour, sample().tour);
        assert!(!nav.editor.history.modified());
        assert!(nav.edit_request(EditRequest::Undo, look).is_empty());
    }

    #[test]
    fn start_north_and_a_new_horizon_reload_the_scene_at_the_view() {
        let mut nav = sample();
        shown(&mut nav);
        nav.editor.on = true;
        let look = steer_rect(-25.0, 4.0, 70.0);
        nav.edit_request(EditRequest::SetStart, look);
        assert_eq!(
            nav.scene().start,
            Angles {
                yaw: -25.0,
                pitch: 4.0,
                hfov: 70.0
            }
        );
        nav.edit_request(EditRequest::SetNorth, look);
        assert_eq!(nav.scene().north_offset, 25.0);
        let h = Horizon {
            pitch: 3.0,
            roll: -2.0,
        };
        let a = nav.edit_request(EditRequest::Horizon(h), look);
        let [TourAction::Load(src)] = &a[..] else {
            panic!("a new horizon reloads the scene: {a:?}");
        };
        assert_eq!(nav.horizon_for(src), Some((3.0, -2.0)));
        let frame = vec![0u32; 4];
        let v = nav.arrived(src, Some((&frame, (2, 2))), 1.0).unwrap();
        assert_eq!((v.yaw, v.pitch, v.hfov), (-25.0, 4.0, 70.0));
        assert!(!nav.animating(1.1), "a reload does not crossfade");
        // Undo the horizon: reloaded level.
        let a = nav.edit_request(EditRequest::Undo, look);
        assert!(
            matches!(&a[..], [TourAction::Info(_), TourAction::Load(_)]),
            "{a:?}"
        );
        assert_eq!(nav.scene().horizon, Horizon::default());
    }

    #[test]
    fn scenes_come_and_go_and_the_shown_one_is_followed_by_its_id() {
        let mut nav = sample();
        shown(&mut nav);
        nav.editor.on = true;
        let look = steer_rect(0.0, 0.0, 90.0);
        // The scene shown cannot be removed.
        assert!(matches!(
            nav.edit_request(EditRequest::RemoveScene(0), look)[..],
            [TourAction::Error(_)]
        ));
        nav.editor.scene_file = "interior.jpg".into();
        assert!(nav.edit_request(EditRequest::AddScene, look).is_empty());
        assert_eq!(nav.tour.scenes.len(), 4);
        assert_eq!(nav.tour.scenes[3].id, "interior-2");
        nav.editor.scene_file = "no-such.jpg".into();
        assert!(matches!(
            nav.edit_request(EditRequest::AddScene, look)[..],
            [TourAction::Error(_)]
        ));
        // Go to the new scene, then undo its adding: back to the first scene.
        let a = nav.choose(3, look).unwrap();
        let TourAction::Load(src) = a else { panic!() };
        nav.arrived(&src, None, 0.0).unwrap();
        assert_eq!(nav.scene().id, "interior-2");
        let a = nav.edit_request(EditRequest::Undo, look);
        assert!(
            matches!(&a[..], [TourAction::Info(_), TourAction::Load(Source::File(p))] if p.ends_with("courtyard.jpg")),
            "{a:?}"
        );
        assert_eq!(nav.can_go(), (false, false), "the visits are dropped");
        // Removing scene 1 (interior) takes the courtyard's link to it.
        let src = scene_source(&nav.tour, 0).unwrap();
        nav.arrived(&src, None, 0.0).unwrap();
        assert_eq!(nav.current(), 0);
        assert!(nav
            .edit_request(EditRequest::RemoveScene(1), look)
            .is_empty());
        assert_eq!(nav.tour.scenes.len(), 2);
        assert_eq!(nav.scene().hotspots.len(), 2);
        assert_eq!(nav.scene().id, "courtyard");
    }

    #[test]
    fn save_writes_a_pannellum_config_that_reads_back() {
        let dir = tempfile::tempdir().unwrap();
        for f in ["tour.json", "courtyard.jpg", "interior.jpg"] {
            std::fs::copy(
                test_support::test_data(&format!("tours/pannellum/{f}")),
                dir.path().join(f),
            )
            .unwrap();
        }
        let path = dir.path().join("tour.json");
        let loaded = crate::tour::load(&path).unwrap();
        let (mut nav, _) = TourNav::start(loaded.tour, path.clone()).unwrap();
        shown(&mut nav);
        nav.editor.on = true;
        let look = steer_rect(10.0, 0.0, 90.0);
        nav.editor.spot = Some((12.0, -3.0));
        nav.editor.text = "A plaque".into();
        nav.edit_request(EditRequest::AddInfo, look);
        nav.edit_request(
            EditRequest::Horizon(Horizon {
                pitch: 1.5,
                roll: 0.5,
            }),
            look,
        );
        assert!(nav.editor.history.modified());
        let a = nav.edit_request(EditRequest::Save, look);
        assert!(
            matches!(&a[..], [TourAction::Info(m)] if m.starts_with("saved")),
            "{a:?}"
        );
        assert!(!nav.editor.history.modified());
        let back = crate::tour::load(&path).unwrap().tour;
        let s = back.scene("courtyard").unwrap();
        assert_eq!(
            s.horizon,
            Horizon {
                pitch: 1.5,
                roll: 0.5
            }
        );
        let h = s.hotspots.last().unwrap();
        assert_eq!((h.yaw, h.pitch, h.text.as_str()), (12.0, -3.0, "A plaque"));
        assert_eq!(back.scenes.len(), 3);
    }
}

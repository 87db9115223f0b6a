//! The tour in the event loop: opening one, the scene shown, clicks and hover on its
//! hotspots, back/forward and the scene list (the state is `crate::window::tour`).

use super::App;
use crate::window::input::{steer_rect, HFOV_HOME};
use crate::window::loader::Source;
use crate::window::tour::{self, TourAction, TourNav};
use lut_core::{StartView, View};
use std::path::PathBuf;

impl App {
    /// Read the tour at `path` and start it: its problems on stderr and as notices (the
    /// rest of the tour opens), its first scene loading. Returns that scene's source.
    ///
    /// # Errors
    /// The file is not a tour, or no scene of it opens (one line).
    pub(super) fn start_tour(&mut self, path: PathBuf) -> anyhow::Result<Source> {
        let loaded = crate::tour::load(&path)?;
        let t = self.now();
        for p in &loaded.problems {
            crate::errln!("viewer: {p}");
        }
        match loaded.problems.len() {
            0 => {}
            1 => {
                self.notices.error(loaded.problems[0].to_string(), t);
            }
            n => {
                self.notices.error(
                    format!(
                        "{}, and {} more problems (on stderr; `viewer tour check` lists them)",
                        loaded.problems[0],
                        n - 1
                    ),
                    t,
                );
            }
        }
        let (nav, source) =
            TourNav::start(loaded.tour, path.clone()).map_err(anyhow::Error::msg)?;
        if self.print_view {
            let _ = crate::outln!(
                "tour opened {} scenes={} problems={}",
                path.display(),
                nav.tour.scenes.len(),
                loaded.problems.len()
            );
        }
        self.tour = Some(nav);
        let p = std::path::absolute(&path).unwrap_or(path);
        self.prefs.add_recent(p);
        Ok(source)
    }

    /// Open the tour at `path` from the window (dialog, recent list, drop); an error is
    /// a notice and what is shown stays.
    pub(super) fn open_tour(&mut self, path: PathBuf) {
        let before = self.tour.take();
        match self.start_tour(path) {
            Ok(source) => {
                let fx = self.doc.open(
                    source,
                    None,
                    Default::default(),
                    self.ctl.settings.exposure_ev,
                );
                self.apply(vec![fx]);
            }
            Err(e) => {
                self.tour = before;
                self.tour_failed(&e);
            }
        }
    }

    /// A tour that does not open: its error on stderr and as a notice, one line escaped
    /// and shortened as every echoed text (what is shown stays).
    pub(super) fn tour_failed(&mut self, e: &anyhow::Error) {
        let m = lut_core::one_line(&format!("{e:#}"));
        crate::errln!("viewer: {m}");
        let t = self.now();
        self.notices.error(m, t);
    }

    /// A panorama was shown at start view `v` (the document's effect): a tour scene
    /// arrives at the view its link names (crossfading from the last frame); anything
    /// else leaves the tour.
    pub(super) fn tour_start_view(&mut self, v: StartView) -> View {
        let file = steer_rect(v.yaw_deg, v.pitch_deg, v.hfov_deg.unwrap_or(HFOV_HOME));
        let Some(nav) = self.tour.as_mut() else {
            return file;
        };
        let Some(source) = self.doc.current().map(|c| c.source.clone()) else {
            return file;
        };
        let old = self
            .scene_key
            .as_ref()
            .map(|k| (self.scene.as_slice(), k.size))
            .filter(|(px, (w, h))| px.len() == *w as usize * *h as usize);
        let t = self.start.elapsed().as_secs_f64();
        match nav.arrived(&source, old, t) {
            Some(a) => {
                let title = format!("viewer: {} ({})", nav.title(), self.title);
                if let Some(g) = &self.gfx {
                    g.window.set_title(&title);
                }
                if self.print_view {
                    let _ = crate::outln!(
                        "tour arrived {} yaw={:.4} pitch={:.4} hfov={:.4}",
                        nav.scene().id,
                        a.yaw,
                        a.pitch,
                        a.hfov
                    );
                }
                self.printed_tour.clear();
                steer_rect(a.yaw, a.pitch, a.hfov)
            }
            None => {
                self.tour = None;
                file
            }
        }
    }

    /// What a tour click, button or key asks.
    fn tour_do(&mut self, a: TourAction, t: f64) {
        match a {
            TourAction::Load(source) => {
                let fx = self.doc.open(
                    source,
                    None,
                    Default::default(),
                    self.ctl.settings.exposure_ev,
                );
                self.apply(vec![fx]);
            }
            TourAction::Info(text) => {
                self.notices.info(text, t);
            }
            TourAction::Error(e) => {
                self.notices.error(e, t);
            }
        }
    }

    /// The tour's part of the UI pass: the tour bar, the hotspot under the pointer and
    /// its text, Alt+←/→ and the mouse's back/forward buttons. `cursor`: the pointer in
    /// scene pixels and in points; `size`: the scene's.
    pub(super) fn tour_ui(
        &mut self,
        ui: &egui::Ui,
        scene: egui::Rect,
        cursor: Option<((f64, f64), egui::Pos2)>,
        size: (u32, u32),
        t: f64,
    ) {
        let Some(nav) = self.tour.as_mut() else {
            return;
        };
        let look = self.ctl.look();
        let bar = if self.dialogs.is_open() {
            tour::TourBarOutput::default()
        } else {
            tour::tour_bar(ui.ctx(), scene, nav)
        };
        let hover = cursor.and_then(|((x, y), _)| nav.hotspot_at(&look, size.0, size.1, x, y));
        nav.set_hover(hover);
        if let (Some(i), Some((_, at))) = (hover, cursor) {
            let text = &nav.scene().hotspots[i].text;
            if !text.is_empty() {
                // Escaped and shortened as every echoed text (docs/reliability.md, class 5).
                tour::hover_text(ui.ctx(), at, &lut_core::shown(text));
            }
        }
        let (alt_back, alt_fwd, m_back, m_fwd) = ui.input(|i| {
            let key = |k: egui::Key| {
                i.events.iter().any(|e| {
                    matches!(e, egui::Event::Key { key, pressed: true, modifiers, .. }
                        if *key == k && modifiers.alt)
                })
            };
            (
                key(egui::Key::ArrowLeft),
                key(egui::Key::ArrowRight),
                i.pointer.button_pressed(egui::PointerButton::Extra1),
                i.pointer.button_pressed(egui::PointerButton::Extra2),
            )
        });
        if bar.edit {
            nav.editor.on = !nav.editor.on;
            if !nav.editor.on {
                nav.level_leave();
            }
        }
        // Enter ends the level mode as Esc does (not while typing in a field).
        if nav.editor.level.on
            && !tour::typing(ui.ctx())
            && ui.input(|i| i.key_pressed(egui::Key::Enter))
        {
            nav.level_leave();
        }
        let mut edits = if nav.editor.on && !self.dialogs.is_open() {
            tour::edit_panel(ui.ctx(), scene, nav)
        } else {
            nav.editor.ui_at.clear();
            Vec::new()
        };
        if self.print_view {
            // Where the Edit toggle and the edit panel's controls are, when that changed
            // (scripts/window-tour-edit.sh clicks them).
            let mut line = String::from("tour ui");
            let at = bar.edit_at.map(|p| ("edit", p));
            for (name, p) in at.iter().chain(nav.editor.ui_at.iter()) {
                line += &format!(" {name}={:.0},{:.0}", p.x, p.y);
            }
            if tour::typing(ui.ctx()) {
                line += " typing";
            }
            if line != self.printed_tour_ui {
                let _ = crate::outln!("{line}");
                self.printed_tour_ui = line;
            }
        }
        if nav.editor.on && !tour::typing(ui.ctx()) {
            edits.extend(ui.input(|i| {
                let key = |k: egui::Key, shift: bool| {
                    i.events.iter().any(|e| {
                        matches!(e, egui::Event::Key { key, pressed: true, modifiers, .. }
                            if *key == k && modifiers.command && modifiers.shift == shift)
                    })
                };
                if key(egui::Key::Z, false) {
                    Some(tour::EditRequest::Undo)
                } else if key(egui::Key::Z, true) || key(egui::Key::Y, false) {
                    Some(tour::EditRequest::Redo)
                } else {
                    None
                }
            }));
        }
        let mut did = Vec::new();
        for r in edits {
            if self.print_view {
                let _ = crate::outln!("tour edit {r:?}");
            }
            did.extend(nav.edit_request(r, look));
        }
        for a in did {
            self.tour_do(a, t);
        }
        let Some(nav) = self.tour.as_mut() else {
            return;
        };
        let action = if bar.back || alt_back || m_back {
            nav.step(false, look)
        } else if bar.forward || alt_fwd || m_fwd {
            nav.step(true, look)
        } else {
            bar.chosen.and_then(|i| nav.choose(i, look))
        };
        if let Some(a) = action {
            self.tour_do(a, t);
        }
    }

    /// A click at `at` (scene pixels) of a `size` scene: on a hotspot's marker it is the
    /// hotspot's (true).
    pub(super) fn tour_click(&mut self, at: (f64, f64), size: (u32, u32), t: f64) -> bool {
        let Some(nav) = self.tour.as_mut() else {
            return false;
        };
        let look = self.ctl.look();
        // Editing: the click picks a spot or selects a hotspot.
        if nav.edit_click(&look, size.0, size.1, at.0, at.1) {
            if self.print_view {
                let ed = &nav.editor;
                let _ = match (ed.spot, ed.selected) {
                    (Some((y, p)), _) => {
                        crate::outln!(
                            "tour edit spot yaw={y:.4} pitch={p:.4} selected={:?}",
                            ed.selected
                        )
                    }
                    (None, s) => crate::outln!("tour edit spot - selected={s:?}"),
                };
            }
            return true;
        }
        let Some(i) = nav.hotspot_at(&look, size.0, size.1, at.0, at.1) else {
            return false;
        };
        if self.print_view {
            let _ = crate::outln!("tour click {} hotspot {i}", nav.scene().id);
        }
        if let Some(a) = nav.click(i, look, t) {
            self.tour_do(a, t);
        }
        true
    }

    /// The T key: the level-horizon mode on or off (a tour's; else a notice).
    pub(super) fn tour_level_key(&mut self, t: f64) {
        match self.tour.as_mut() {
            Some(nav) => {
                let a = nav.edit_request(tour::EditRequest::Level, self.ctl.look());
                for a in a {
                    self.tour_do(a, t);
                }
            }
            None => {
                self.notices.info(
                    "level horizon: a tour's (open the panorama through a Pannellum config \
                     to save its horizonPitch/horizonRoll)",
                    t,
                );
            }
        }
    }

    /// Esc in the level mode leaves it (true); else Esc is the window's.
    pub(super) fn tour_level_leave(&mut self) -> bool {
        match self.tour.as_mut() {
            Some(nav) if nav.editor.level.on => {
                nav.level_leave();
                true
            }
            _ => false,
        }
    }

    /// A press at `at` (scene pixels) of a `size` scene: on the horizon line in the level
    /// mode it grabs the line (true).
    pub(super) fn tour_level_press(&mut self, at: (f64, f64), size: (u32, u32)) -> bool {
        let look = self.ctl.look();
        let Some(nav) = self.tour.as_mut() else {
            return false;
        };
        let grabbed = nav.level_press(&look, size.0, size.1, at.0, at.1);
        if grabbed && self.print_view {
            let _ = crate::outln!("tour level grab {:.1},{:.1}", at.0, at.1);
        }
        grabbed
    }

    /// True while the horizon line is dragged.
    pub(super) fn tour_level_dragging(&self) -> bool {
        self.tour.as_ref().is_some_and(|n| n.level_dragging())
    }

    /// The horizon line dragged to `at`.
    pub(super) fn tour_level_drag(&mut self, at: (f64, f64), size: (u32, u32)) {
        let look = self.ctl.look();
        if let Some(nav) = self.tour.as_mut() {
            nav.level_drag(&look, size.0, size.1, at.0, at.1);
        }
    }

    /// The horizon line let go: one edit, the scene reloads levelled.
    pub(super) fn tour_level_release(&mut self, t: f64) {
        let look = self.ctl.look();
        let Some(nav) = self.tour.as_mut() else {
            return;
        };
        let (set, actions) = nav.level_release(look);
        if let (Some(h), true) = (set, self.print_view) {
            let _ = crate::outln!("tour level set pitch={:.4} roll={:.4}", h.pitch, h.roll);
        }
        for a in actions {
            self.tour_do(a, t);
        }
    }

    /// The glide's view this frame (it moves the view as a start view does).
    pub(super) fn tour_glide(&mut self, t: f64) -> bool {
        match self.tour.as_mut().and_then(|n| n.glide_look(t)) {
            Some(l) => {
                self.ctl.set_home(l);
                true
            }
            None => false,
        }
    }

    /// `--print-view`: the tour scene and where its hotspots are, when that changed.
    pub(super) fn print_tour(&mut self, look: &View, size: (u32, u32)) {
        let Some(nav) = &self.tour else {
            return;
        };
        if !self.print_view || nav.animating(self.now()) {
            return;
        }
        let mut line = nav.describe(look, size.0, size.1);
        if nav.editor.level.on {
            // The level mode: a point of the horizon line near the centre column.
            line += &match nav.level_line_point(look, size.0, size.1) {
                Some((x, y)) => format!(" level line={x:.1},{y:.1}"),
                None => " level line=-".into(),
            };
        }
        if line != self.printed_tour {
            let _ = crate::outln!("{line}");
            self.printed_tour = line;
        }
    }
}

//! Tours in the window: a Pannellum or Marzipano tour opened (command line, Open dialog,
//! recent list, drop), its hotspots drawn over the scene in every output projection, the
//! hotspot's text on hover, a click on a scene link gliding toward it and crossfading
//! into the target scene at the view the link names, back and forward through the
//! scenes visited (Alt+←/→, the mouse's back/forward buttons, the ◀ ▶ buttons), the
//! scene list, and the Edit toggle (the editor is [`edit`]).
//!
//! [`TourNav`] is the state (pure: no window, no thread; times are the window's clock in
//! seconds), unit-tested below; the event loop (`app`) calls it at a few hooks: opening,
//! a scene shown (`arrived`), the frame's look (`glide_look`), the composed scene
//! (`compose`), and the small tour bar ([`tour_bar`]).
//!
//! A scene's horizon (`horizonPitch`/`horizonRoll`) is levelled on the loading thread,
//! the map (or a cube's faces) re-levelled once at load as `viewer render` does
//! (`lut_core::level_horizon`, `lut_core::level_cube_horizon`); tile scenes are shown as
//! they are.

mod edit;
mod level;

pub use edit::{edit_panel, typing, EditRequest, Editor};
pub use level::LevelMode;

use super::input::moved;
use super::loader::Source;
use crate::tour::{self, markers, Angles, HotspotKind, Tour};
use lut_core::View;
use std::path::{Path, PathBuf};

/// How long the glide toward a clicked scene link lasts, seconds.
pub const GLIDE_S: f64 = 0.45;
/// The glide ends at this fraction of the hfov it started at (a step into the link).
pub const GLIDE_ZOOM: f64 = 0.7;
/// The crossfade when the tour gives none: Pannellum's default `sceneFadeDuration`.
pub const DEFAULT_FADE_MS: f64 = 1000.0;
/// Longest crossfade taken from a tour (a typo of 10^6 ms does not freeze the window).
pub const MAX_FADE_MS: f64 = 5000.0;
/// A marker under the pointer: within this many pixels of its centre.
pub const PICK_RADIUS: f64 = markers::MARKER_RADIUS + 2.0;
/// The hovered marker's outline.
const HOVER_COLOR: u32 = 0x00FF_FFFF;

/// A scene visited: its index and the view it was left at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Visit {
    /// The scene's index in the tour.
    pub scene: usize,
    /// The view.
    pub view: Angles,
}

/// A scene asked for and loading: where it arrives.
#[derive(Debug, Clone, PartialEq)]
struct Pending {
    scene: usize,
    source: Source,
    view: Angles,
    /// Crossfade from the scene left (not for a reload of the same scene).
    fade: bool,
}

/// The glide toward a clicked link.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Glide {
    from: View,
    to: (f64, f64, f64),
    t0: f64,
}

/// What a click, a button or a key asks of the window.
#[derive(Debug, Clone, PartialEq)]
pub enum TourAction {
    /// Load this source (the scene to go to); the arrival comes through
    /// [`TourNav::arrived`].
    Load(Source),
    /// Show this text (an info hotspot, or why a link goes nowhere).
    Info(String),
    /// A problem to show as an error.
    Error(String),
}

/// The tour open in the window and where the user is in it.
pub struct TourNav {
    /// The tour.
    pub tour: Tour,
    /// Its file.
    pub path: PathBuf,
    /// The scene shown.
    current: usize,
    back: Vec<Visit>,
    forward: Vec<Visit>,
    pending: Option<Pending>,
    glide: Option<Glide>,
    /// The crossfade: the old scene's last frame, its size, and when it started.
    fade: Option<(Vec<u32>, (u32, u32), f64)>,
    /// The scene composed with the fade and the markers.
    buf: Vec<u32>,
    /// The hotspot under the pointer.
    hover: Option<usize>,
    /// The editor (edit mode, undo, the spot and hotspot picked).
    pub editor: Editor,
    /// The horizon correction the scene shown was levelled with at load.
    shown_horizon: tour::Horizon,
}

/// The source of scene `i` of `tour`: an equirectangular file, six cube faces, or a
/// Pannellum multires / Marzipano tile scene when it is a tiled pyramid this viewer
/// reads (a folder with `config.json`).
///
/// # Errors
/// A path that leaves the tour's folder, a missing cube face, tiles in a layout this
/// viewer does not read: one line naming the scene.
pub fn scene_source(tour: &Tour, i: usize) -> Result<Source, String> {
    let s = &tour.scenes[i];
    let file = |rel: &str| {
        tour.resolve(rel)
            .map_err(|why| format!("scene \"{}\": {why}", s.id))
    };
    match &s.source {
        tour::Source::Equirect(p) => Ok(Source::File(file(p)?)),
        tour::Source::Cube(faces) => {
            let mut paths = Vec::new();
            for f in faces {
                let Some(f) = f else {
                    return Err(format!(
                        "scene \"{}\": a cube face is missing (null): the window needs all six",
                        s.id
                    ));
                };
                paths.push(file(f)?);
            }
            Ok(Source::Cube {
                paths,
                layout: None,
            })
        }
        tour::Source::Multires(v) => tour.multires_dir(&s.id, v).map(Source::File),
        tour::Source::MarzipanoTiles { dir, .. } => {
            let d = file(dir)?;
            if crate::panorama::is_tiled(&d) {
                Ok(Source::File(d))
            } else {
                Err(format!(
                    "scene \"{}\": Marzipano tiles open from a Marzipano export's data.js \
                     beside tiles/<id> ({} is not such a folder)",
                    s.id,
                    d.display()
                ))
            }
        }
    }
}

/// Yaw difference `to - from` wrapped to (-180, 180].
fn wrap(d: f64) -> f64 {
    let w = (d + 180.0).rem_euclid(360.0) - 180.0;
    if w == -180.0 {
        180.0
    } else {
        w
    }
}

/// Smoothstep easing of `p` in [0, 1].
fn ease(p: f64) -> f64 {
    let p = p.clamp(0.0, 1.0);
    p * p * (3.0 - 2.0 * p)
}

impl TourNav {
    /// A tour read from `path`, starting in its first scene that opens. Returns the
    /// state and the first scene's source; its start view comes through
    /// [`TourNav::arrived`].
    ///
    /// # Errors
    /// No scene of the tour opens (each scene's reason, joined).
    pub fn start(tour: Tour, path: PathBuf) -> Result<(TourNav, Source), String> {
        let first = tour.first().and_then(|f| tour.index(&f.id)).unwrap_or(0);
        // A tour whose every scene was left out has none to try (no index 0 either).
        let order = (!tour.scenes.is_empty())
            .then_some(first)
            .into_iter()
            .chain((0..tour.scenes.len()).filter(|&i| i != first));
        let mut why = Vec::new();
        for i in order {
            match scene_source(&tour, i) {
                Ok(source) => {
                    let view = tour.scenes[i].start;
                    let nav = TourNav {
                        tour,
                        path,
                        current: i,
                        back: Vec::new(),
                        forward: Vec::new(),
                        pending: Some(Pending {
                            scene: i,
                            source: source.clone(),
                            view,
                            fade: true,
                        }),
                        glide: None,
                        fade: None,
                        buf: Vec::new(),
                        hover: None,
                        editor: Editor::default(),
                        shown_horizon: tour::Horizon::default(),
                    };
                    return Ok((nav, source));
                }
                Err(e) => why.push(e),
            }
        }
        if why.is_empty() {
            why.push("it has no scenes".into());
        }
        Err(format!(
            "{}: no scene of the tour opens: {}",
            path.display(),
            why.join("; ")
        ))
    }

    /// The scene shown (or, before the first one arrives, the one loading).
    pub fn current(&self) -> usize {
        self.current
    }

    /// The scene shown.
    pub fn scene(&self) -> &tour::TourScene {
        &self.tour.scenes[self.current]
    }

    /// Whether back and forward have somewhere to go.
    pub fn can_go(&self) -> (bool, bool) {
        (!self.back.is_empty(), !self.forward.is_empty())
    }

    /// The view `look` as tour angles.
    fn angles(look: View) -> Angles {
        Angles {
            yaw: look.yaw_deg(),
            pitch: look.pitch_deg(),
            hfov: look.hfov_deg(),
        }
    }

    /// Ask for scene `i` arriving at `view`.
    fn go(&mut self, i: usize, view: Angles) -> TourAction {
        match scene_source(&self.tour, i) {
            Ok(source) => {
                self.pending = Some(Pending {
                    scene: i,
                    source: source.clone(),
                    view,
                    fade: true,
                });
                TourAction::Load(source)
            }
            Err(e) => {
                self.glide = None;
                TourAction::Error(e)
            }
        }
    }

    /// A click on hotspot `index` of the scene shown, seen at `look`, at time `t`: a
    /// scene link glides toward the hotspot and loads its target (the view it arrives at
    /// by Pannellum's rules); an info hotspot gives its text and link.
    pub fn click(&mut self, index: usize, look: View, t: f64) -> Option<TourAction> {
        let scene = self.tour.scenes.get(self.current)?;
        let hs = scene.hotspots.get(index)?;
        match &hs.kind {
            HotspotKind::Info { url } => {
                let mut text = hs.text.clone();
                if let Some(u) = url {
                    text = if text.is_empty() {
                        u.clone()
                    } else {
                        format!("{text} ({u})")
                    };
                }
                Some(TourAction::Info(if text.is_empty() {
                    "(no text)".into()
                } else {
                    text
                }))
            }
            HotspotKind::Scene { scene_id, .. } => {
                let Some((i, view)) = self.tour.arrival(scene, Self::angles(look), hs) else {
                    return Some(TourAction::Error(format!(
                        "the link goes to scene \"{scene_id}\", which is not in the tour"
                    )));
                };
                self.back.push(Visit {
                    scene: self.current,
                    view: Self::angles(look),
                });
                self.forward.clear();
                self.glide = Some(Glide {
                    from: look,
                    to: (hs.yaw, hs.pitch, look.hfov_deg() * GLIDE_ZOOM),
                    t0: t,
                });
                Some(self.go(i, view))
            }
        }
    }

    /// The scene list's choice: scene `i` at its start view.
    pub fn choose(&mut self, i: usize, look: View) -> Option<TourAction> {
        if i >= self.tour.scenes.len() || (i == self.current && self.pending.is_none()) {
            return None;
        }
        self.back.push(Visit {
            scene: self.current,
            view: Self::angles(look),
        });
        self.forward.clear();
        let view = self.tour.scenes[i].start;
        Some(self.go(i, view))
    }

    /// Back (`forward` false) or forward through the scenes visited, each at the view
    /// it was left at.
    pub fn step(&mut self, forward: bool, look: View) -> Option<TourAction> {
        let here = Visit {
            scene: self.current,
            view: Self::angles(look),
        };
        let to = if forward {
            let v = self.forward.pop()?;
            self.back.push(here);
            v
        } else {
            let v = self.back.pop()?;
            self.forward.push(here);
            v
        };
        self.glide = None;
        Some(self.go(to.scene, to.view))
    }

    /// A panorama was shown from `source`: when it is the scene asked for, it is now the
    /// current scene, and its arrival view is returned (the caller goes there and starts
    /// the crossfade from `old_frame`, the last frame of the scene left, `size` pixels,
    /// at `t`). `None`: not a scene of this tour (the tour is left).
    pub fn arrived(
        &mut self,
        source: &Source,
        old_frame: Option<(&[u32], (u32, u32))>,
        t: f64,
    ) -> Option<Angles> {
        let shown = self.horizon_for(source);
        let p = self.pending.take_if(|p| p.source == *source)?;
        self.current = p.scene;
        self.shown_horizon = shown.map_or_else(tour::Horizon::default, |(pitch, roll)| {
            tour::Horizon { pitch, roll }
        });
        self.glide = None;
        self.hover = None;
        self.fade = old_frame
            .filter(|_| p.fade)
            .map(|(px, size)| (px.to_vec(), size, t));
        Some(p.view)
    }

    /// The crossfade's duration, seconds.
    fn fade_s(&self) -> f64 {
        self.tour
            .fade_ms
            .filter(|f| f.is_finite() && *f >= 0.0)
            .unwrap_or(DEFAULT_FADE_MS)
            .min(MAX_FADE_MS)
            / 1000.0
    }

    /// The glide's look at time `t` (`None`: no glide). The glide ends at the hotspot,
    /// zoomed in; it stops when the target scene arrives.
    pub fn glide_look(&mut self, t: f64) -> Option<View> {
        let g = self.glide?;
        let p = ((t - g.t0) / GLIDE_S).clamp(0.0, 1.0);
        let e = ease(p);
        let (yaw, pitch, hfov) = g.to;
        let look = moved(
            g.from,
            g.from.yaw_deg() + wrap(yaw - g.from.yaw_deg()) * e,
            g.from.pitch_deg() + (pitch - g.from.pitch_deg()) * e,
            g.from.hfov_deg() * (hfov / g.from.hfov_deg()).powf(e),
        );
        if p >= 1.0 {
            self.glide = None;
        }
        Some(look)
    }

    /// True while the glide or the crossfade runs (a frame is due every refresh).
    pub fn animating(&self, t: f64) -> bool {
        self.glide.is_some() || self.fade.as_ref().is_some_and(|f| t - f.2 < self.fade_s())
    }

    /// The hotspot of the scene shown under (`x`, `y`) of a `w × h` frame of `look`.
    pub fn hotspot_at(&self, look: &View, w: u32, h: u32, x: f64, y: f64) -> Option<usize> {
        if self.pending.is_some() && self.glide.is_some() {
            return None;
        }
        markers::placed(self.scene(), *look, w, h)
            .into_iter()
            .map(|p| (p.index, (p.x - x).hypot(p.y - y)))
            .filter(|(_, d)| *d <= PICK_RADIUS)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// The hotspot under the pointer (its marker is highlighted).
    pub fn set_hover(&mut self, hover: Option<usize>) {
        self.hover = hover;
    }

    /// The scene as shown: `scene` (`w × h`, the frame of `look`) faded from the old
    /// scene while the crossfade runs, with the hotspot markers over it (not while
    /// fading or gliding into another scene).
    pub fn compose(&mut self, scene: &[u32], w: u32, h: u32, look: &View, t: f64) -> &[u32] {
        self.buf.clear();
        self.buf.extend_from_slice(scene);
        let fade_s = self.fade_s();
        let mut fading = false;
        if let Some((old, size, t0)) = &self.fade {
            let a = if fade_s > 0.0 {
                ((t - t0) / fade_s).clamp(0.0, 1.0)
            } else {
                1.0
            };
            if a < 1.0 && *size == (w, h) && old.len() == self.buf.len() {
                blend(&mut self.buf, old, a);
                fading = true;
            }
            if a >= 1.0 || *size != (w, h) {
                self.fade = None;
            }
        }
        if !fading && self.glide.is_none() {
            let view = *look;
            // The level mode: the scene turned while its horizon is dragged (or reloads
            // levelled), the horizon line.
            let mut buf = std::mem::take(&mut self.buf);
            self.level_draw(scene, &mut buf, w, h, look);
            self.buf = buf;
            let placed = markers::draw(&self.tour.scenes[self.current], view, &mut self.buf, w, h);
            if let Some(p) = placed.iter().find(|p| Some(p.index) == self.hover) {
                ring(&mut self.buf, w, h, p.x, p.y);
            }
            if self.editor.on {
                let sel = self.editor.selected;
                if let Some(p) = placed.iter().find(|p| Some(p.index) == sel) {
                    ring(&mut self.buf, w, h, p.x, p.y);
                }
                if let Some((x, y)) = self
                    .editor
                    .spot
                    .and_then(|(yaw, pitch)| markers::place(view, w, h, yaw, pitch))
                {
                    cross(&mut self.buf, w, h, x, y);
                }
            }
        }
        &self.buf
    }

    /// One line for `--print-view` naming the scene shown and where each of its
    /// hotspots is in a `w × h` frame of `look`: `tour scene ID i/n hotspots 0@x,y ...`.
    pub fn describe(&self, look: &View, w: u32, h: u32) -> String {
        let s = self.scene();
        let list: Vec<String> = markers::placed(s, *look, w, h)
            .iter()
            .map(|p| format!("{}@{:.1},{:.1}", p.index, p.x, p.y))
            .collect();
        format!(
            "tour scene {} {}/{} hotspots {}",
            lut_core::shown(&s.id),
            self.current + 1,
            self.tour.scenes.len(),
            if list.is_empty() {
                "-".into()
            } else {
                list.join(" ")
            }
        )
    }

    /// The window title's name for the scene shown: the tour file, the scene's title.
    pub fn title(&self) -> String {
        let file = self.path.file_name().map_or_else(
            || self.path.display().to_string(),
            |n| n.to_string_lossy().into(),
        );
        let s = self.scene();
        // Escaped and shortened as every echoed text (docs/reliability.md, class 5): the
        // window system's title gets no control character and no megabyte of text.
        lut_core::shown(&format!("{file}: {}", s.title.as_deref().unwrap_or(&s.id)))
    }

    /// The horizon to level a load of `source` by (pitch, roll), when it is a scene of
    /// the tour with one.
    pub fn horizon_for(&self, source: &Source) -> Option<(f64, f64)> {
        let i = match &self.pending {
            Some(p) if p.source == *source => p.scene,
            _ => self.current,
        };
        let h = self.tour.scenes.get(i)?.horizon;
        (!h.is_level() && scene_source(&self.tour, i).ok().as_ref() == Some(source))
            .then_some((h.pitch, h.roll))
    }
}

/// `dst = old·(1 − a) + dst·a` per 8-bit channel.
fn blend(dst: &mut [u32], old: &[u32], a: f64) {
    let k = (a * 256.0).round() as u32;
    for (d, &o) in dst.iter_mut().zip(old) {
        let mut out = 0;
        for shift in [0, 8, 16] {
            let n = (*d >> shift) & 0xFF;
            let o = (o >> shift) & 0xFF;
            out |= ((o * (256 - k) + n * k) >> 8) << shift;
        }
        *d = out;
    }
}

/// A one-pixel ring around a marker (the hovered one).
fn ring(out: &mut [u32], w: u32, h: u32, cx: f64, cy: f64) {
    let r = markers::MARKER_RADIUS + 1.5;
    let (x0, x1) = (
        (cx - r - 1.0).floor().max(0.0) as i64,
        (cx + r + 1.0).ceil() as i64,
    );
    let (y0, y1) = (
        (cy - r - 1.0).floor().max(0.0) as i64,
        (cy + r + 1.0).ceil() as i64,
    );
    for y in y0..=y1.min(h as i64 - 1) {
        for x in x0..=x1.min(w as i64 - 1) {
            let d = (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy);
            if (d - r).abs() <= 0.75 {
                out[y as usize * w as usize + x as usize] = HOVER_COLOR;
            }
        }
    }
}

/// A small cross at (cx, cy): the spot picked in edit mode.
fn cross(out: &mut [u32], w: u32, h: u32, cx: f64, cy: f64) {
    let (x, y) = (cx.floor() as i64, cy.floor() as i64);
    for d in -6..=6i64 {
        for (px, py) in [(x + d, y), (x, y + d)] {
            if (0..w as i64).contains(&px) && (0..h as i64).contains(&py) {
                out[py as usize * w as usize + px as usize] = HOVER_COLOR;
            }
        }
    }
}

/// Whether `path` is a tour file (a Pannellum config or a Marzipano `data.js`).
pub fn is_tour(path: &Path) -> bool {
    path.is_file() && tour::sniff(path).is_some()
}

/// What the user did in the tour bar.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct TourBarOutput {
    /// ◀ pressed.
    pub back: bool,
    /// ▶ pressed.
    pub forward: bool,
    /// A scene chosen in the list.
    pub chosen: Option<usize>,
    /// The Edit toggle pressed.
    pub edit: bool,
    /// The Edit toggle's centre (window points), for `--print-view`'s `tour ui` line.
    pub edit_at: Option<egui::Pos2>,
}

/// The tour bar below the toolbar: back, forward, and the scene list.
pub fn tour_bar(ctx: &egui::Context, scene: egui::Rect, nav: &TourNav) -> TourBarOutput {
    let mut out = TourBarOutput::default();
    let (can_back, can_forward) = nav.can_go();
    egui::Area::new(egui::Id::new("tour-bar"))
        .fixed_pos(scene.min + egui::vec2(8.0, 48.0))
        .order(egui::Order::Foreground)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style())
                .fill(ui.visuals().window_fill.gamma_multiply(0.85))
                .inner_margin(egui::Margin::symmetric(6, 4))
                .show(ui, |ui| {
                    ui.horizontal(|ui| {
                        out.back = ui
                            .add_enabled(can_back, egui::Button::new("◀"))
                            .on_hover_text("Back to the scene before (Alt+←, mouse back)")
                            .clicked();
                        out.forward = ui
                            .add_enabled(can_forward, egui::Button::new("▶"))
                            .on_hover_text("Forward again (Alt+→, mouse forward)")
                            .clicked();
                        // Escaped and shortened as every echoed text.
                        let name = |s: &tour::TourScene| {
                            lut_core::shown(s.title.as_deref().unwrap_or(&s.id))
                        };
                        egui::ComboBox::from_id_salt("tour-scenes")
                            .selected_text(name(nav.scene()))
                            .show_ui(ui, |ui| {
                                for (i, s) in nav.tour.scenes.iter().enumerate() {
                                    if ui.selectable_label(i == nav.current(), name(s)).clicked() {
                                        out.chosen = Some(i);
                                    }
                                }
                            });
                        let edit = ui.selectable_label(nav.editor.on, "Edit").on_hover_text(
                            "Edit the tour: hotspots, start view, north, horizon, scenes; \
                                 undo, save",
                        );
                        out.edit_at = Some(edit.rect.center());
                        out.edit = edit.clicked();
                    });
                });
        });
    out
}

/// The hotspot's text by the pointer.
pub fn hover_text(ctx: &egui::Context, at: egui::Pos2, text: &str) {
    egui::Area::new(egui::Id::new("tour-hover"))
        .fixed_pos(at + egui::vec2(14.0, 10.0))
        .order(egui::Order::Tooltip)
        .interactable(false)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.label(text);
            });
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::window::input::steer_rect;

    /// The Pannellum test tour, started (its first scene loading).
    pub fn sample() -> TourNav {
        let path = test_support::test_data("tours/pannellum/tour.json");
        let loaded = tour::load(&path).unwrap();
        assert!(loaded.problems.is_empty(), "{:?}", loaded.problems);
        let (nav, source) = TourNav::start(loaded.tour, path).unwrap();
        assert!(matches!(&source, Source::File(p) if p.ends_with("courtyard.jpg")));
        nav
    }

    /// `nav`'s current scene arrived (its panorama shown), as the window reports it.
    pub fn shown(nav: &mut TourNav) {
        let src = scene_source(&nav.tour, nav.current()).unwrap();
        nav.arrived(&src, None, 0.0).unwrap();
    }

    fn arrive(nav: &mut TourNav, a: &TourAction, t: f64) -> Angles {
        let TourAction::Load(src) = a else {
            panic!("not a load: {a:?}");
        };
        let frame = vec![0u32; 4];
        nav.arrived(src, Some((&frame, (2, 2))), t).unwrap()
    }

    #[test]
    fn a_link_glides_to_its_hotspot_and_arrives_at_its_target_view() {
        let mut nav = sample();
        let src = scene_source(&nav.tour, 0).unwrap();
        // The first scene arrives at its start view.
        let start = nav.arrived(&src, None, 0.0).unwrap();
        assert_eq!((start.yaw, start.pitch, start.hfov), (20.0, -5.0, 90.0));
        let look = steer_rect(start.yaw, start.pitch, start.hfov);
        // Hotspot 0: to "interior", targetYaw sameAzimuth, targetPitch 0.
        let a = nav.click(0, look, 10.0).unwrap();
        assert!(nav.animating(10.0));
        let mid = nav.glide_look(10.0 + GLIDE_S / 2.0).unwrap();
        assert!(mid.yaw_deg() > 20.0 && mid.yaw_deg() < 60.0, "{mid:?}");
        // Just past its duration: the glide's last look, at the hotspot (zoomed in).
        let end = nav.glide_look(10.0 + GLIDE_S + 1e-3).unwrap();
        assert!((end.yaw_deg() - 60.0).abs() < 1e-9 && (end.pitch_deg() + 2.0).abs() < 1e-9);
        assert!((end.hfov_deg() - 90.0 * GLIDE_ZOOM).abs() < 1e-9);
        assert!(nav.glide_look(11.0).is_none(), "the glide ended");
        let v = arrive(&mut nav, &a, 11.0);
        assert_eq!(nav.scene().id, "interior");
        // sameAzimuth: 20 + 30 (courtyard north) - 120 (interior north) = -70.
        assert!((v.yaw + 70.0).abs() < 1e-9, "{v:?}");
        assert_eq!((v.pitch, v.hfov), (0.0, 100.0));
        // The crossfade runs for the tour's 1000 ms.
        assert!(nav.animating(11.5) && !nav.animating(12.01));
        // Back returns to the courtyard at the view it was left at; forward again.
        let back = nav.step(false, steer_rect(v.yaw, v.pitch, v.hfov)).unwrap();
        let v0 = arrive(&mut nav, &back, 13.0);
        assert_eq!(nav.scene().id, "courtyard");
        assert_eq!((v0.yaw, v0.pitch, v0.hfov), (20.0, -5.0, 90.0));
        assert_eq!(nav.can_go(), (false, true));
        let fwd = nav.step(true, steer_rect(1.0, 2.0, 80.0)).unwrap();
        let v1 = arrive(&mut nav, &fwd, 14.0);
        assert_eq!(nav.scene().id, "interior");
        assert!((v1.yaw + 70.0).abs() < 1e-9);
        assert_eq!(nav.can_go(), (true, false));
        // A panorama that is not the scene asked for is not an arrival.
        assert!(nav
            .arrived(&Source::File("elsewhere.jpg".into()), None, 15.0)
            .is_none());
    }

    #[test]
    fn info_hotspots_give_their_text_and_the_scene_list_goes_to_start_views() {
        let mut nav = sample();
        let look = steer_rect(0.0, 0.0, 90.0);
        assert_eq!(
            nav.click(1, look, 0.0),
            Some(TourAction::Info(
                "The courtyard (CC0, Greg Zaal). (https://hdrihaven.com)".into()
            ))
        );
        assert!(!nav.animating(0.0), "an info hotspot does not glide");
        let a = nav.choose(2, look).unwrap();
        let TourAction::Load(Source::Cube { paths, .. }) = &a else {
            panic!("the cube scene loads six faces: {a:?}");
        };
        assert_eq!(paths.len(), 6);
        let v = arrive(&mut nav, &a, 1.0);
        assert_eq!((v.yaw, v.pitch, v.hfov), (0.0, 0.0, 100.0));
        assert_eq!(nav.title(), "tour.json: Courtyard (cube)");
    }

    #[test]
    fn the_marker_under_the_pointer_is_the_hotspot_and_it_is_drawn_there() {
        let mut nav = sample();
        let src = scene_source(&nav.tour, 0).unwrap();
        nav.arrived(&src, None, 0.0);
        let look = steer_rect(60.0, -2.0, 90.0);
        let (w, h) = (400, 300);
        // Hotspot 0 is at yaw 60, pitch -2: the centre of this view.
        let (cx, cy) = (200.0, 150.0);
        assert_eq!(nav.hotspot_at(&look, w, h, cx + 3.0, cy - 2.0), Some(0));
        assert_eq!(nav.hotspot_at(&look, w, h, cx + 40.0, cy), None);
        let scene = vec![0x0020_2020; (w * h) as usize];
        let out = nav.compose(&scene, w, h, &look, 0.0).to_vec();
        assert_eq!(out[150 * 400 + 200], markers::SCENE_COLOR);
        assert_eq!(out[150 * 400 + 240], 0x0020_2020);
        assert!(nav
            .describe(&look, w, h)
            .starts_with("tour scene courtyard 1/3 hotspots 0@200.0,150.0"));
    }

    #[test]
    fn a_crossfade_blends_the_old_frame_into_the_new() {
        let mut d = vec![0x00FF_FFFF; 2];
        blend(&mut d, &[0, 0], 0.5);
        assert_eq!(d[0], 0x007F_7F7F, "{:06x}", d[0]);
        let mut d = vec![0x0012_3456];
        blend(&mut d, &[0x00AB_CDEF], 0.0);
        assert_eq!(d[0], 0x00AB_CDEF);
        let mut d = vec![0x0012_3456];
        blend(&mut d, &[0x00AB_CDEF], 1.0);
        assert_eq!(d[0], 0x0012_3456);
    }

    #[test]
    fn a_tour_with_no_scene_that_opens_is_one_clear_error() {
        let mut t = Tour::new(PathBuf::from("/nowhere"));
        let s = sample().tour.scenes[0].clone();
        t.scenes.push(tour::TourScene {
            source: tour::Source::Equirect("../outside.jpg".into()),
            ..s
        });
        let e = TourNav::start(t, PathBuf::from("t.json")).err().unwrap();
        assert!(
            e.contains("no scene of the tour opens") && e.contains("leaves"),
            "{e}"
        );
    }

    #[test]
    fn a_tour_with_no_scene_left_is_an_error_not_a_panic() {
        // Every scene left out (a path leaving the folder, say): nothing to start in.
        let path = PathBuf::from("t.json");
        let loaded = crate::tour::parse(
            br#"{"default": {"firstScene": "a"}, "scenes": {"a": {"panorama": "../x.jpg"}}}"#,
            &path,
        )
        .unwrap();
        assert!(loaded.tour.scenes.is_empty());
        let Err(e) = TourNav::start(loaded.tour, path) else {
            panic!("a tour without scenes started")
        };
        assert!(e.contains("no scene of the tour opens"), "{e}");
        let Err(e) = TourNav::start(Tour::new(PathBuf::new()), PathBuf::from("u.json")) else {
            panic!("an empty tour started")
        };
        assert!(e.contains("it has no scenes"), "{e}");
    }
}

//! What the user's actions do: keys, toolbar and panel buttons, the dialogs' choices,
//! the document's effects; opening files (dialog, recent list, the folder's next and
//! previous) and saving the view.

use super::frame::FrameRequests;
use super::{App, AppEvent};
use crate::window::dialogs::Chosen;
use crate::window::document::{Effect, LoadEvent};
use crate::window::folder::{self, Step};
use crate::window::keys::{KeyAction, EXPOSURE_KEY_STEP_EV};
use crate::window::loader::{LoadRequest, Source};
use crate::window::quality::Level;
use std::path::{Path, PathBuf};
use winit::event_loop::ActiveEventLoop;
use winit::window::Fullscreen;

impl App {
    /// Carry out what the document asks, then redraw.
    pub(super) fn apply(&mut self, effects: Vec<Effect>) {
        for e in effects {
            match e {
                Effect::Load(req) => self.spawn_load(req),
                Effect::AddLights(paths) => {
                    let t = self.now();
                    for p in &paths {
                        // The error is also kept in the Lights section.
                        if let Err(e) = self.lights.load_and_add(p) {
                            self.notices.error(e, t);
                        }
                    }
                    if let Some(msg) = self.lights.lights_added() {
                        if self.print_view {
                            let _ = crate::outln!("notice {msg}");
                        }
                        self.notices.info(msg, t);
                    }
                }
                Effect::OpenScene(p) => self.open_scene(p),
                Effect::Title(t) => {
                    if let Some(g) = &self.gfx {
                        g.window.set_title(&t);
                    }
                    self.title = t.trim_start_matches("viewer: ").to_string();
                }
                Effect::PrintView(line) => {
                    if self.print_view {
                        let _ = crate::outln!("{line}");
                    }
                }
                Effect::Stderr(line) => crate::errln!("{line}"),
                Effect::ShowPanel => self.prefs.panel = true,
                Effect::StartView(v) => {
                    // The new panorama's zoom range first: the old one's limit must not
                    // clamp the new start view.
                    self.update_zoom_range();
                    // A tour's scene arrives at the view its link names.
                    let home = self.tour_start_view(v);
                    self.ctl.set_home(home);
                }
                Effect::NewScene => self.new_scene(),
                Effect::Opened(p) => {
                    let p = std::path::absolute(&p).unwrap_or(p);
                    self.prefs.add_recent(p);
                    self.save_prefs(true);
                }
            }
        }
        self.request_redraw();
    }

    /// Run `req` on a loading thread that reports to the event loop.
    fn spawn_load(&mut self, mut req: LoadRequest) {
        // A tour scene's horizon is levelled as it loads.
        req.horizon = self.tour.as_ref().and_then(|t| t.horizon_for(&req.source));
        let (id, proxy) = (req.id, self.proxy.clone());
        let spawned = std::thread::Builder::new()
            .name("viewer-load".into())
            .spawn(move || {
                // Behind the one containment: a panic anywhere in the loading (a decoder,
                // the tables) is this load's error, shown by the window, never a thread
                // that dies and a progress bar that waits for ever.
                let result = lut_core::catch_quiet(|| {
                    crate::window::loader::load(req, &mut |step, fraction| {
                        let _ = proxy.send_event(AppEvent::Load(LoadEvent::Progress {
                            id,
                            step,
                            fraction,
                        }));
                    })
                })
                .unwrap_or_else(|panic| {
                    Err(format!("loading failed (an internal error: {panic})"))
                });
                let _ = proxy.send_event(AppEvent::Load(LoadEvent::Done { id, result }));
            });
        if let Err(e) = spawned {
            self.doc.load_not_started(id, &e.to_string());
        }
    }

    /// What the UI pass collected: held buttons and keys, actions, choices.
    pub(super) fn apply_requests(&mut self, req: FrameRequests, t: f64, el: &ActiveEventLoop) {
        self.ctl.set_held(req.held.or(req.panel.held), t);
        if req.panel.reset {
            self.ctl.key(KeyAction::Reset);
        }
        for id in req.notices.dismissed {
            self.notices.dismiss(id);
        }
        if req.notices.dismiss_error {
            self.doc.dismiss_error();
        }
        if req.panel.projection_changed {
            let fx = self.doc.projection_changed(self.ctl.settings.exposure_ev);
            self.apply(fx.into_iter().collect());
        }
        if let Some(p) = req.panel.view_projection {
            self.ctl.set_projection(p);
        }
        if req.panel.planet {
            self.do_action(KeyAction::LittlePlanet, t, el);
        }
        if req.panel.exposure_changed {
            // Applied while the slider is dragged (the document paces the reloads).
            let fx = self.doc.reload_exposure(self.ctl.settings.exposure_ev);
            self.apply(fx.into_iter().collect());
        }
        if req.panel.save_view {
            self.do_action(KeyAction::SaveView, t, el);
        }
        if req.panel.save_scene {
            self.start_save_scene_dialog();
        }
        if req.panel.open_scene {
            self.start_open_dialog(true);
        }
        if req.panel.report {
            self.start_report_dialog();
        }
        if let Some(p) = req.open_recent {
            if p.exists() {
                self.open_path(p);
            } else {
                self.notices
                    .error(format!("{}: no longer there", p.display()), t);
                self.prefs.remove_recent(&p);
            }
        }
        match req.chosen {
            Some(Chosen::Open(p)) => {
                if self.print_view {
                    let _ = crate::outln!("dialog picked {}", p.display());
                }
                self.open_path(p);
            }
            Some(Chosen::Save(p)) => self.save_view_to(&p, t),
            Some(Chosen::SaveScene(p)) => self.save_scene_to(&p, t),
            Some(Chosen::SaveReport(p)) => self.write_report(p, t),
            None => {}
        }
        if !req.keys.is_empty() {
            // Keys and buttons count as input (auto-rotation waits again).
            self.ctl.interacted(t);
        }
        for a in req.keys {
            self.do_action(a, t, el);
        }
    }

    /// One action of a key, a toolbar button or the panel.
    fn do_action(&mut self, a: KeyAction, t: f64, el: &ActiveEventLoop) {
        match a {
            KeyAction::ExposureDown | KeyAction::ExposureUp => {
                let d = if a == KeyAction::ExposureUp {
                    EXPOSURE_KEY_STEP_EV
                } else {
                    -EXPOSURE_KEY_STEP_EV
                };
                let s = &mut self.ctl.settings;
                let ev = crate::window::export::step_exposure(s.exposure_ev, d);
                if !self.doc.readouts.hdr {
                    self.notices
                        .info("exposure: only for HDR panoramas (.hdr, .exr)", t);
                } else if ev != s.exposure_ev {
                    s.exposure_ev = ev;
                    self.notices.info(format!("exposure {ev:+.1} EV"), t);
                    let fx = self.doc.reload_exposure(ev);
                    self.apply(fx.into_iter().collect());
                }
            }
            KeyAction::SaveView => self.start_save_dialog(),
            KeyAction::Open => self.start_open_dialog(false),
            KeyAction::OpenNext => self.open_neighbour(Step::Next, t),
            KeyAction::OpenPrevious => self.open_neighbour(Step::Previous, t),
            KeyAction::TogglePanel => self.prefs.panel = !self.prefs.panel,
            KeyAction::Help => {
                self.show_help = !self.show_help;
                if self.print_view {
                    let _ =
                        crate::outln!("help {}", if self.show_help { "shown" } else { "hidden" });
                }
            }
            KeyAction::AutoRotate => {
                let on = !self.ctl.auto_rotate.enabled;
                self.ctl.auto_rotate.enabled = on;
                if on {
                    self.ctl.start_rotation(t);
                }
                let a = &self.ctl.auto_rotate;
                let msg = if on {
                    format!(
                        "auto-rotate on (Space: off); after input it resumes after {:.0} s idle",
                        a.idle_s
                    )
                } else {
                    "auto-rotate off".to_string()
                };
                self.notices.info(msg, t);
            }
            KeyAction::CycleProjection => {
                let p = self.ctl.cycle_projection(self.ctl.settings.pannini_d);
                self.notices.info(format!("projection: {p}"), t);
            }
            KeyAction::LittlePlanet => {
                let msg = if self.ctl.toggle_planet(t) {
                    "little planet (L returns)"
                } else {
                    "back from the little planet"
                };
                self.notices.info(msg, t);
            }
            KeyAction::HeatMap => {
                let s = &mut self.ctl.settings;
                s.heat_map = !s.heat_map;
                let exact = self.doc.current().and_then(|c| {
                    crate::heatmap::exact_note(c.scene.kind()).map(|_| c.scene.kind())
                });
                let msg = match (s.heat_map, exact) {
                    (true, Some(kind)) => format!(
                        "error heat map on: 0 everywhere, this {}'s renderer computes every position exactly (E: off; why in the panel)",
                        kind.noun()
                    ),
                    (true, None) => "error heat map on (E: off; legend in the panel)".into(),
                    (false, _) => "error heat map off".into(),
                };
                self.notices.info(msg, t);
            }
            KeyAction::Quit => el.exit(),
            KeyAction::ToggleFullscreen => {
                if let Some(g) = &self.gfx {
                    let full = g.window.fullscreen().is_some();
                    g.window
                        .set_fullscreen((!full).then_some(Fullscreen::Borderless(None)));
                }
            }
            KeyAction::LevelHorizon => self.tour_level_key(t),
            KeyAction::LeaveFullscreen if self.tour_level_leave() => {}
            KeyAction::LeaveFullscreen => {
                self.show_help = false;
                if let Some(g) = &self.gfx {
                    g.window.set_fullscreen(None);
                }
            }
            other => self.ctl.key(other),
        }
    }

    /// Open a file or folder (the Open dialog, the recent list, the folder's neighbours).
    fn open_path(&mut self, p: PathBuf) {
        if crate::window::tour::is_tour(&p) {
            return self.open_tour(p);
        }
        let fx = self.doc.open_path(p, self.ctl.settings.exposure_ev);
        self.apply(fx.into_iter().collect());
    }

    /// PageUp / PageDown: the previous or next panorama in the current file's folder.
    fn open_neighbour(&mut self, step: Step, t: f64) {
        let Some(cur) = self.doc.last_file().map(Path::to_path_buf) else {
            self.notices
                .info("no file to step from (the bundled sample is open)", t);
            return;
        };
        let dir = match cur.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        match folder::panoramas_in(&dir) {
            Ok(list) => match folder::neighbour(&list, &cur, step) {
                Some(p) => self.open_path(p),
                None => {
                    self.notices.info("no other panorama in this folder", t);
                }
            },
            Err(e) => {
                self.notices.error(format!("{}: {e}", dir.display()), t);
            }
        }
    }

    /// The Open dialog, in the current file's folder (else the last recent file's, else
    /// the working folder).
    fn start_open_dialog(&mut self, scene: bool) {
        let dir = self
            .doc
            .last_file()
            .or(self.prefs.recent.first().map(PathBuf::as_path))
            .and_then(Path::parent)
            .filter(|d| d.is_dir())
            .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        if scene {
            self.dialogs.open_scene(&self.egui_ctx, &dir);
        } else {
            self.dialogs.open_panorama(&self.egui_ctx, &dir);
        }
        if self.print_view {
            let _ = crate::outln!("dialog open {}", dir.display());
        }
    }

    /// The Save dialog, in the folder saved to last (else the user's pictures folder,
    /// else the working folder), with the first free `view-N.png` there.
    fn start_save_dialog(&mut self) {
        let dir = self
            .prefs
            .save_dir
            .clone()
            .filter(|d| d.is_dir())
            .or_else(|| {
                directories::UserDirs::new()
                    .and_then(|u| u.picture_dir().map(Path::to_path_buf))
                    .filter(|d| d.is_dir())
            })
            .unwrap_or_else(|| PathBuf::from("."));
        let name = crate::window::export::next_view_path(&dir, |p| p.exists());
        let name = name
            .file_name()
            .map_or_else(|| "view.png".into(), |n| n.to_string_lossy().into_owned());
        self.dialogs.save_view(&self.egui_ctx, &dir, &name);
        if self.print_view {
            let _ = crate::outln!("dialog save {}", dir.display());
        }
    }

    /// Render the current view at the scene's size times the export scale, full quality
    /// (the chosen sampler, trilinear by default, never a degraded frame), lit as shown,
    /// and write it to `path` (PNG, or JPEG for `.jpg`); the saved path is a notice.
    fn save_view_to(&mut self, path: &Path, t: f64) {
        let scene = match self.doc.readouts.scene {
            (w, h) if w > 0 && h > 0 => (w, h),
            _ => self.gfx.as_ref().map_or((1024, 640), |g| {
                let s = g.window.inner_size();
                (s.width, s.height)
            }),
        };
        let (w, h) = crate::window::export::export_size(scene, self.ctl.settings.export_scale);
        // Never over the panorama on show (a name picked in the dialog can be its file).
        let inputs: Vec<PathBuf> = match self.doc.current().map(|l| &l.source) {
            Some(Source::File(p)) => vec![p.clone()],
            Some(Source::Cube { paths, .. }) => paths.clone(),
            _ => Vec::new(),
        };
        let result = crate::output::check_not_input(&[path.to_path_buf()], &inputs)
            .map_err(|e| format!("{e:#}"))
            .and_then(|()| self.render_export(w, h))
            .and_then(|px| {
                crate::output::write_image(path, &px, w, h).map_err(|e| format!("{e:#}"))
            });
        let status = match result {
            Ok(()) => {
                self.prefs.save_dir = path.parent().map(Path::to_path_buf);
                let msg = format!("saved {} ({w}×{h})", path.display());
                self.notices.info(&msg, t);
                msg
            }
            Err(e) => {
                let msg = format!("save failed: {e}");
                self.notices.error(&msg, t);
                msg
            }
        };
        if self.print_view {
            let _ = crate::outln!("{status}");
        }
    }

    /// The current view rendered into a new `w`×`h` buffer with the window's renderer
    /// and options at full quality, then lit as the scene is.
    fn render_export(&mut self, w: u32, h: u32) -> Result<Vec<u32>, String> {
        let cur = self
            .doc
            .current_mut()
            .ok_or_else(|| "no panorama loaded".to_string())?;
        let opts = self.ctl.settings.render_options(Level::Full);
        let view = self.ctl.look();
        let mut buf = vec![0u32; w as usize * h as usize];
        self.lights
            .render_lit(
                &mut self.lit,
                false,
                &mut cur.scene,
                view,
                &opts,
                &mut buf,
                (w, h),
            )
            .map_err(|e| e.to_string())?;
        Ok(buf)
    }
}

//! One frame: route the keys, run the UI pass (panel, scene input, overlays, dialogs),
//! apply what the user did, render the scene at the quality the rule picks, compose it
//! with egui, and decide when the next frame is due.

use super::{App, SceneKey};
use crate::scene::{measure_errors, render_scene, render_scene_lit};
use crate::window::dialogs::Chosen;
use crate::window::input::{resolution_hfov, wheel_notches, Held, WIDE_HFOV_MAX};
use crate::window::keys::{KeyAction, Route};
use crate::window::overlay::{self, NoticesOutput, ToolbarModel};
use crate::window::paint::SceneRect;
use crate::window::quality::{frame_level, FRAME_BUDGET_MS};
use crate::window::ui::{self, PanelModel, PanelOutput};
use anyhow::{anyhow, Result};
use lut_core::{Camera, CubeRenderer, RenderOptions, RenderPath, Sampler, View};
use std::num::NonZeroU32;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use winit::event_loop::ActiveEventLoop;

/// Things the UI pass asks the app to do after it.
#[derive(Default)]
pub(super) struct FrameRequests {
    /// Key, toolbar and panel actions, in order.
    pub keys: Vec<KeyAction>,
    pub held: Held,
    pub panel: PanelOutput,
    pub open_recent: Option<PathBuf>,
    pub notices: NoticesOutput,
    pub chosen: Option<Chosen>,
    pub scene_rect: Option<SceneRect>,
    /// The pointer over the scene, in scene pixels.
    pub cursor: Option<(f64, f64)>,
}

impl App {
    /// Build this frame's UI and collect what the user did.
    fn build_ui(&mut self, ui: &mut egui::Ui, t: f64, win: (u32, u32)) -> FrameRequests {
        let mut req = FrameRequests::default();
        let ppp = ui.ctx().pixels_per_point();
        if self.prefs.panel {
            let look = self.ctl.look();
            let doc = self.doc.panel_parts();
            self.drawn_readouts = ui::readout_rows(&look, doc.readouts);
            req.panel = ui::side_panel(
                ui,
                PanelModel {
                    settings: &mut self.ctl.settings,
                    projection: doc.projection,
                    look,
                    readouts: doc.readouts,
                    loading: doc.loading,
                    zoom_limit: &mut self.prefs.zoom_limit,
                    auto_rotate: &mut self.ctl.auto_rotate,
                    lights: &mut self.lights,
                },
            );
        }
        // The scene: everything the panel leaves. Drags and wheel go through egui so a
        // click on the panel or an overlay is never taken for a drag.
        let rect = ui.available_rect_before_wrap();
        let resp = ui.interact(rect, egui::Id::new("scene"), egui::Sense::click_and_drag());
        self.overlays(ui.ctx(), rect, &mut req);
        if let Some(l) = self.doc.loading() {
            if !self.prefs.panel || self.doc.current().is_none() {
                // Nothing else shows the load: a box over the scene.
                ui::loading_overlay(ui.ctx(), l);
            }
        }
        let export = self.doc.readouts.scene;
        let dialog_was_open = self.dialogs.is_open();
        req.chosen = self
            .dialogs
            .update(ui.ctx(), &mut self.ctl.settings.export_scale, &|k| {
                crate::window::export::export_size(export, k)
            });
        if self.print_view {
            if dialog_was_open && !self.dialogs.is_open() && req.chosen.is_none() {
                let _ = crate::outln!("dialog closed");
            }
            // A menu (the recent files) opened or closed.
            let menu = egui::Popup::is_any_open(ui.ctx());
            if menu != std::mem::replace(&mut self.menu_open, menu) {
                let _ = crate::outln!("menu {}", if menu { "open" } else { "closed" });
            }
        }
        req.scene_rect = SceneRect::from_points(rect, ppp, win.0, win.1);
        let Some(sr) = req.scene_rect else {
            return req;
        };
        let size = (sr.w, sr.h);
        let to_px = |p: egui::Pos2| {
            (
                f64::from(p.x * ppp) - f64::from(sr.x),
                f64::from(p.y * ppp) - f64::from(sr.y),
            )
        };
        req.cursor = resp.hover_pos().map(to_px);
        let tour_cursor = resp.hover_pos().map(|p| (to_px(p), p));
        self.tour_ui(ui, rect, tour_cursor, size, t);
        let primary = egui::PointerButton::Primary;
        if resp.drag_started_by(primary) {
            let origin = ui
                .input(|i| i.pointer.press_origin())
                .or(resp.interact_pointer_pos());
            if self.prefs.first_run_hint {
                // The first drag: the hint has done its job, for good.
                self.prefs.first_run_hint = false;
                self.save_prefs(true);
                if self.print_view {
                    let _ = crate::outln!("hint gone");
                }
            }
            if let Some(o) = origin {
                // On a luminaire's marker the drag moves the luminaire.
                let shift = ui.input(|i| i.modifiers.shift);
                // In a tour's level mode, on the horizon line the drag levels it.
                if !self.tour_level_press(to_px(o), size)
                    && !self.press_light(to_px(o), size, shift)
                {
                    self.ctl.press(to_px(o), size, t);
                }
            }
        }
        if self.tour_level_dragging() {
            match resp.interact_pointer_pos() {
                Some(p) if resp.dragged_by(primary) => self.tour_level_drag(to_px(p), size),
                _ => self.tour_level_release(t),
            }
        }
        if self.scene_drag.is_some() {
            match resp.interact_pointer_pos() {
                Some(p) if resp.dragged_by(primary) => self.drag_light(to_px(p), size),
                _ => self.end_light_drag(),
            }
        }
        if resp.clicked_by(primary) {
            if let Some(p) = resp.interact_pointer_pos() {
                // On a tour's hotspot the click is the hotspot's.
                if !self.tour_click(to_px(p), size, t) {
                    self.click_scene(to_px(p), size);
                }
            }
        }
        if self.ctl.dragging() {
            match resp.interact_pointer_pos() {
                Some(p) if resp.dragged_by(primary) => self.ctl.drag_to(to_px(p), size, t),
                // Released, or the drag ended some other way (pointer gone): never leave
                // a QTVR turn running.
                _ => self.ctl.release(t),
            }
        }
        if resp.double_clicked() {
            if let Some(p) = resp.interact_pointer_pos() {
                self.ctl.double_click(to_px(p), size, t);
            }
        }
        if resp.contains_pointer() {
            let notches: f64 = ui.input(|i| {
                i.events
                    .iter()
                    .map(|e| match e {
                        egui::Event::MouseWheel { unit, delta, .. } => {
                            wheel_notches(*unit, delta.y)
                        }
                        _ => 0.0,
                    })
                    .sum()
            });
            if notches != 0.0 {
                self.ctl.interacted(t);
                let cursor = resp.hover_pos().map(to_px);
                self.ctl.wheel(notches, cursor, size);
                if let Some(p) = resp.interact_pointer_pos().filter(|_| self.ctl.dragging()) {
                    // Keep a grab in progress consistent with the new zoom.
                    self.ctl.press(to_px(p), size, t);
                }
            }
        }
        req
    }

    /// The viewing UI over the scene: toolbar, compass, notices, help (only the notices
    /// while a dialog is open: it is modal, and drawn below egui's foreground).
    fn overlays(&mut self, ctx: &egui::Context, scene: egui::Rect, req: &mut FrameRequests) {
        req.notices = overlay::notices(ctx, scene, self.doc.error(), &self.notices);
        if self.dialogs.is_open() {
            return;
        }
        let bar = overlay::toolbar(
            ctx,
            ToolbarModel {
                scene,
                title: &self.title,
                recent: &self.prefs.recent,
                panel: self.prefs.panel,
                help: self.show_help,
            },
        );
        for (on, a) in [
            (bar.open, KeyAction::Open),
            (bar.save, KeyAction::SaveView),
            (bar.zoom_out, KeyAction::ZoomOut),
            (bar.zoom_in, KeyAction::ZoomIn),
            (bar.reset, KeyAction::Reset),
            (bar.fullscreen, KeyAction::ToggleFullscreen),
            (bar.panel, KeyAction::TogglePanel),
            (bar.help, KeyAction::Help),
        ] {
            if on {
                req.keys.push(a);
            }
        }
        req.open_recent = bar.open_recent;
        let pose = self.doc.readouts.pose_heading;
        overlay::compass(ctx, scene, &self.ctl.look(), pose);
        // While the last frame was drawn coarser than wanted (a redraw is then due, so
        // the indicator goes with the frame that is sharp).
        if let Some((_, pending, RenderPath::Tiles { coarser: true, .. })) =
            &self.doc.readouts.tiles
        {
            overlay::tiles_loading(ctx, scene, (*pending).max(1));
        }
        if self.prefs.first_run_hint && self.doc.current().is_some() {
            overlay::first_run_hint(ctx, scene);
            if !std::mem::replace(&mut self.hint_drawn, true) && self.print_view {
                let _ = crate::outln!("hint shown");
            }
        }
        if self.show_help && overlay::help(ctx, scene) {
            req.keys.push(KeyAction::Help);
        }
        if self.show_help && self.print_view {
            // Where the help was laid out, against the scene (the window tests check it
            // fits): printed when either changes.
            let help = ctx.memory(|m| m.area_rect(egui::Id::new("help")));
            if let Some(r) = help.filter(|&r| self.help_printed != Some((r, scene))) {
                self.help_printed = Some((r, scene));
                let _ = crate::outln!(
                    "help rect {:.0},{:.0},{:.0},{:.0} scene {:.0},{:.0},{:.0},{:.0}",
                    r.min.x,
                    r.min.y,
                    r.max.x,
                    r.max.y,
                    scene.min.x,
                    scene.min.y,
                    scene.max.x,
                    scene.max.y
                );
            }
        }
    }

    /// The hfov range for the current panorama in a `scene_width`-pixel scene: zooming
    /// in always reaches the zoom reach (50° by default), and further where the map's
    /// resolution allows (the zoom limit; off: the global minimum), up to the widest view.
    pub(super) fn update_zoom_range(&mut self) {
        let min = self
            .zoom_limit_hfov()
            .map_or(0.0, |l| l.min(self.prefs.zoom_reach));
        self.ctl.set_zoom_range(min, WIDE_HFOV_MAX);
    }

    /// The zoom limit's hfov for the current panorama and scene (`None`: off, or nothing
    /// shown).
    fn zoom_limit_hfov(&self) -> Option<f64> {
        let map_px_deg = self.doc.current().map(|c| match c.map() {
            Some(m) => 360.0 / f64::from(m.width()),
            None => 90.0 / f64::from(c.describe().0.max(1)),
        })?;
        let ratio = self.prefs.zoom_limit?;
        Some(resolution_hfov(map_px_deg, self.scene_width, ratio))
    }

    pub(super) fn redraw(&mut self, el: &ActiveEventLoop) -> Result<()> {
        let t = self.now();
        let Some(g) = self.gfx.as_mut() else {
            return Ok(());
        };
        let size = g.window.inner_size();
        let (w, h) = (size.width, size.height);
        let (Some(nw), Some(nh)) = (NonZeroU32::new(w), NonZeroU32::new(h)) else {
            // Minimized (0×0): draw nothing, and run no UI pass whose texture updates
            // would be lost.
            return Ok(());
        };
        self.last_redraw = Some(Instant::now());
        let ui_t0 = Instant::now();
        let mut raw = g.egui_winit.take_egui_input(&g.window);
        let ctx = self.egui_ctx.clone();
        // Shortcuts first, whatever egui has focused; a text field or a dialog gets them.
        let route = if self.dialogs.is_open() {
            Route::Modal
        } else if ctx.text_edit_focused() {
            Route::TextEditing
        } else {
            Route::Shortcuts
        };
        let keys = self.shortcuts.route(&mut raw.events, route);
        if !keys.is_empty() {
            // A shortcut (Esc, PageDown, …) taken from egui closes an open menu (the
            // recent files): egui never sees the key that would close it.
            egui::Popup::close_all(&ctx);
        }
        let look_before = self.ctl.look();
        let mut req = FrameRequests::default();
        let full = ctx.run_ui(raw, |ui| req = self.build_ui(ui, t, (w, h)));
        req.keys.splice(0..0, keys);
        req.held = self.shortcuts.held();
        let (scene_rect, cursor) = (req.scene_rect, req.cursor);
        self.apply_requests(req, t, el);
        if let Some(r) = scene_rect {
            self.scene_width = r.w;
        }
        self.update_zoom_range();
        // The view limit: a partial map's coverage at the scene's size, when the panel's
        // "Keep the view inside" is on.
        let limit = match (scene_rect, self.doc.partial_coverage()) {
            (Some(r), Some(c)) if self.ctl.settings.view_limit => Some((c, (r.w, r.h))),
            _ => None,
        };
        self.ctl.set_limit(limit);
        // A tour's glide toward a clicked link moves the view (drawn as motion).
        let gliding = self.tour_glide(t);
        let mut frame = self.ctl.frame(t);
        let tour_moving = self.tour.as_ref().is_some_and(|n| n.animating(t));
        frame.fast |= gliding;
        if self.ctl.take_zoomed_past_widest() && frame.look.projection().is_rectilinear() {
            self.notices.info(
                "widest rectilinear view: V for a wide projection, L for a little planet",
                t,
            );
        }
        if self.ctl.take_zoomed_past_narrowest() {
            let (min, _) = self.ctl.zoom_range();
            let msg = zoom_stop_notice(min, self.prefs.zoom_limit);
            if self.print_view {
                let _ = crate::outln!("notice {msg}");
            }
            self.notices.info(msg, t);
        }
        let mut ui_ms = ui_t0.elapsed().as_secs_f64() * 1e3;
        if let Some(r) = scene_rect {
            self.render_scene(r, frame.look, frame.fast);
        }
        let lux_changed = self.update_lux(cursor, scene_rect, frame.look);
        let Some(g) = self.gfx.as_mut() else {
            return Ok(());
        };
        g.egui_winit
            .handle_platform_output(&g.window, full.platform_output);
        let t1 = Instant::now();
        let prims = ctx.tessellate(full.shapes, full.pixels_per_point);
        if g.surface_size != (w, h) {
            g.surface
                .resize(nw, nh)
                .map_err(|e| anyhow!("cannot resize the drawing surface to {w}x{h}: {e}"))?;
            g.surface_size = (w, h);
        }
        let mut buffer = g
            .surface
            .buffer_mut()
            .map_err(|e| anyhow!("cannot get the drawing buffer: {e}"))?;
        let scene = match (scene_rect, &self.scene_key) {
            (Some(r), Some(k)) if k.size == (r.w, r.h) => Some((
                match self.tour.as_mut() {
                    // A tour: the crossfade and the hotspot markers over the scene.
                    Some(nav) => nav.compose(&self.scene, r.w, r.h, &frame.look, t),
                    None => self.scene.as_slice(),
                },
                r,
            )),
            _ => None,
        };
        self.compositor.compose(
            &mut buffer,
            w,
            h,
            scene,
            &prims,
            &full.textures_delta,
            full.pixels_per_point,
        );
        ui_ms += t1.elapsed().as_secs_f64() * 1e3;
        buffer
            .present()
            .map_err(|e| anyhow!("cannot show the frame: {e}"))?;
        self.doc.readouts.ui_ms = ui_ms;
        let now = Instant::now();
        self.count_fps(now);
        self.print_readouts();
        if let Some(r) = scene_rect {
            self.print_tour(&frame.look, (r.w, r.h));
        }
        self.save_prefs(false);

        // When is the next frame due?
        let mut next: Option<Instant> = None;
        let mut want = |at: Instant| next = Some(next.map_or(at, |n: Instant| n.min(at)));
        let delay = full
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .map_or(Duration::MAX, |v| v.repaint_delay);
        if delay < Duration::from_secs(3600) {
            want(now + delay);
        }
        let at = |s: f64| self.start + Duration::from_secs_f64(s.max(0.0));
        if let Some(s) = self.ctl.wake_at() {
            want(at(s));
        }
        if let Some(s) = self.notices.next_expiry() {
            want(at(s));
        }
        if self.prefs.panel {
            let rows = ui::readout_rows(&self.ctl.look(), &self.doc.readouts);
            if self.ctl.look() != look_before
                || lux_changed
                || !same_rows(&rows, &self.drawn_readouts)
            {
                // The readouts were drawn before this frame's input and render.
                want(now);
            }
            if let Some(&last) = self.renders.back() {
                // The fps readout falls to 0 one second after the last render.
                want(last + Duration::from_millis(1010));
            }
        }
        if self.notices.expire(t) {
            want(now);
        }
        if tour_moving {
            // The glide and the crossfade: a frame every refresh.
            want(now);
        }
        if self.lit.refining() || self.baked.pending() {
            // The coarse illuminance map shown: the full one next; or the lighting has
            // settled: the lit panorama next.
            want(now);
        }
        if let Some(n) = next {
            // At most one frame per display refresh, whoever asks.
            let n = n.max(now + self.frame_interval);
            self.next_frame_at = Some(self.next_frame_at.map_or(n, |o| o.min(n)));
        }
        Ok(())
    }

    /// Scenes rendered in the last second.
    fn count_fps(&mut self, now: Instant) {
        while self
            .renders
            .front()
            .is_some_and(|&f| now.duration_since(f) > Duration::from_secs(1))
        {
            self.renders.pop_front();
        }
        self.doc.readouts.fps = self.renders.len() as f64;
    }

    /// `--print-view`: the readouts as the panel drew them, when they changed.
    fn print_readouts(&mut self) {
        if !(self.print_view && self.prefs.panel) {
            return;
        }
        let line: Vec<String> = self
            .drawn_readouts
            .iter()
            .filter(|(k, _)| *k != "UI")
            .map(|(k, v)| format!("{k}={}", v.trim()))
            .collect();
        let line = format!("readouts {}", line.join("; "));
        if line != self.printed_readouts {
            let _ = crate::outln!("{line}");
            self.printed_readouts = line;
        }
    }

    /// Render the scene for `rect` at the quality the rule picks (unless the cached one
    /// already shows it), then light it when there are luminaires.
    fn render_scene(&mut self, rect: SceneRect, look: View, fast: bool) {
        let generation = self.doc.generation();
        let pixels = u64::from(rect.w) * u64::from(rect.h);
        let s = self.ctl.settings;
        let (level, degraded) = frame_level(s.aa, fast, &self.times, pixels, FRAME_BUDGET_MS);
        if self.doc.current().is_none() {
            return;
        }
        let opts = s.render_options(level);
        // While the view moves, bilinear frames read the pyramid level that matches the
        // screen (`Renderer::set_bilinear_level`): a huge map then pans at the cost of the
        // level it shows. A still frame (trilinear by default, or bilinear) is drawn from
        // the deepest level on which no pixel is magnified by more than √2
        // (`Renderer::set_still_level`): the map itself unless the view is zoomed out, and
        // then the cost of the level, not of a 32k map. Bilinear frames drawn from the map
        // (or a level) read, span by span, the pyramid level nearest the footprint there
        // (`Renderer::set_region_lod`; a cube's bilinear frames the face pyramid level
        // nearest each 16 pixels' footprint): looking at a pole or across a wide view costs
        // about 0.65-0.75x the CPU time of the map itself there and aliases less; where
        // pixels magnify the frame is the same, byte for byte (docs/performance.md,
        // issue 34).
        let bilinear_level = fast && opts.sampler == Sampler::Bilinear;
        let lit = self.update_lit();
        // Once the lighting has settled, frames pan the lit panorama (unlit frames of it);
        // while it changes, each frame is lit from the illuminance map.
        let from_baked = self.update_baked(lit.as_ref());
        let key = SceneKey {
            look,
            size: (rect.w, rect.h),
            level,
            renderer: opts.renderer,
            sampler: opts.sampler,
            index_step: opts.index_step,
            lut: opts.lut,
            cube_renderer: opts.cube,
            bilinear_level,
            heat_map: s.heat_map,
            map_generation: generation,
            lights: self.lights.key(),
            lit: (
                self.lit.generation(),
                self.lights.show_room,
                self.lights.selected,
            ),
            baked: from_baked,
        };
        if self.scene_key.as_ref() == Some(&key) {
            return;
        }
        let Some(cur) = self.doc.current_mut() else {
            return;
        };
        fit(&mut self.scene, rect.w as usize * rect.h as usize);
        let t0 = Instant::now();
        let view = look;
        let k = level.scale();
        // A full-size frame is lit as its rows are drawn (no second pass over it); a
        // smaller one is lit after it is scaled up, in `light_scene`.
        let cam = Camera::new(view, rect.w, rect.h);
        let shader = match (&lit, k == 1 && !s.heat_map && !from_baked) {
            (Some(map), true) => match map.frame_shader(&cam, &self.lights.shade_options()) {
                Ok(shader) => Some(shader),
                Err(e) => {
                    self.lights.scene_error = Some(e.to_string());
                    None
                }
            },
            _ => None,
        };
        let lit_while_drawn = shader.is_some();
        let scene = match self.baked.copy_mut() {
            Some(lit_copy) if from_baked => lit_copy,
            _ => &mut cur.scene,
        };
        scene.set_bilinear_level(bilinear_level);
        scene.set_still_level(true);
        scene.set_region_lod(true);
        let result = if k == 1 {
            render_scene_lit(
                scene,
                view,
                &opts,
                &mut self.scene,
                rect.w,
                rect.h,
                shader.as_ref(),
            )
        } else {
            let (sw, sh) = (rect.w.div_ceil(k), rect.h.div_ceil(k));
            fit(&mut self.small, sw as usize * sh as usize);
            let r = render_scene(scene, view, &opts, &mut self.small, sw, sh);
            crate::window::paint::upscale_bilinear(
                &self.small,
                sw,
                sh,
                &mut self.scene,
                rect.w,
                rect.h,
            );
            r
        };
        let report = match result {
            Ok(r) => r,
            Err(e) => {
                self.doc.set_error(format!("render failed: {e}"));
                self.scene_key = None;
                return;
            }
        };
        self.doc.readouts.heat = None;
        self.doc.readouts.heat_note = None;
        if s.heat_map {
            self.show_heat_map(view, &opts, rect, k);
        } else {
            let unlit = lit.as_deref().filter(|_| !lit_while_drawn && !from_baked);
            self.light_scene(lit.as_deref(), unlit, view, rect);
        }
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        self.times.record(level, ms, pixels);
        // A frame read from a pyramid level is not the still frame: one is due. A frame of
        // a tiled pyramid drawn coarser than wanted (tiles still decoding) is redrawn too.
        let tiles_loading = matches!(report.path, RenderPath::Tiles { coarser: true, .. });
        self.ctl
            .rendered(degraded || bilinear_level || tiles_loading);
        self.renders.push_back(Instant::now());
        let tiles = match self.doc.current().and_then(|c| c.scene.tiles_status()) {
            Some((mut stats, pending, notices)) => {
                // The budget of the settings (`--cache-mib`), applied to the open pyramid.
                let budget = (self.prefs.tile_cache_mib as usize).saturating_mul(1 << 20);
                if stats.budget != budget {
                    if let Some(c) = self.doc.current_mut() {
                        c.scene.set_tile_cache_bytes(budget);
                    }
                    stats.budget = budget;
                }
                // One notice per tile that could not be decoded (drawn from its ancestor).
                for n in notices {
                    let t = self.now();
                    self.notices.error(n, t);
                }
                Some((stats, pending))
            }
            None => None,
        };
        let r = &mut self.doc.readouts;
        r.table_bytes = report.table_bytes;
        r.exact_pixels = report.exact_pixels;
        r.pixels = report.pixels;
        let path = match report.path {
            RenderPath::Cube(kind) => {
                (r.path, r.cube) = (None, Some(kind));
                match kind {
                    CubeRenderer::Basic => "CubeBasic".to_string(),
                    CubeRenderer::Accelerated => "CubeScanline".to_string(),
                }
            }
            path => {
                (r.path, r.cube) = (Some(path), None);
                format!("{path:?}")
            }
        };
        r.render_ms = ms;
        r.scene = (rect.w, rect.h);
        r.tiles = tiles.map(|(stats, pending)| (stats, pending, report.path));
        r.level = Some(level);
        r.sampler = Some(opts.sampler);
        r.full_ms = self.times.full_ms(pixels);
        self.scene_key = (!tiles_loading).then_some(key);
        if self.print_view {
            let _ = crate::outln!(
                "view yaw={:.4} pitch={:.4} hfov={:.4} path={path} sampler={} level={} fast={} \
                 ms={ms:.2} size={}x{} lights={} proj={} lit={}",
                look.yaw_deg(),
                look.pitch_deg(),
                look.hfov_deg(),
                opts.sampler.name(),
                level.label().replace(' ', "-"),
                fast,
                rect.w,
                rect.h,
                self.lights.lights.len(),
                look.projection().name(),
                match (from_baked, &lit) {
                    (true, _) => "baked",
                    (false, Some(_)) => "frame",
                    (false, None) => "none",
                }
            );
        }
    }

    /// Replace the scene by the heat map of `view` with `opts` (measured at the frame's
    /// size, `rect` divided by `k`, as the frame was rendered) and put its max and mean in
    /// the readouts.
    fn show_heat_map(
        &mut self,
        view: lut_core::View,
        opts: &RenderOptions,
        rect: SceneRect,
        k: u32,
    ) {
        let Some(cur) = self.doc.current_mut() else {
            return;
        };
        let (sw, sh) = (rect.w.div_ceil(k), rect.h.div_ceil(k));
        let note = crate::heatmap::exact_note(cur.scene.kind());
        match measure_errors(&mut cur.scene, view, opts, sw, sh) {
            Ok(em) => {
                let colors = em.colors();
                if k == 1 {
                    self.scene.copy_from_slice(&colors);
                } else {
                    crate::window::paint::upscale_bilinear(
                        &colors,
                        sw,
                        sh,
                        &mut self.scene,
                        rect.w,
                        rect.h,
                    );
                }
                self.doc.readouts.heat = Some((em.stats.max, em.stats.mean));
                self.doc.readouts.heat_note = note;
            }
            Err(e) => self.doc.set_error(format!("heat map failed: {e}")),
        }
    }

    /// The illuminance at the pointer for the readout; true when it changed.
    fn update_lux(
        &mut self,
        cursor: Option<(f64, f64)>,
        rect: Option<SceneRect>,
        look: View,
    ) -> bool {
        // The scene the illuminance map was built from: its inter-reflections come from
        // the solving thread (never solved here, on the UI thread).
        let lux =
            match (cursor, rect, self.lit.scene()) {
                (Some((x, y)), Some(r), Some(scene)) if r.w > 0 && r.h > 0 => Some(
                    lut_core::lux_at(scene, &lut_core::Camera::new(look, r.w, r.h), x, y),
                ),
                _ => None,
            };
        let changed = lux.map(f64::to_bits) != self.lights.lux_at_cursor.map(f64::to_bits);
        self.lights.lux_at_cursor = lux;
        changed
    }
}

/// Make `buf` hold `n` pixels. Frames of the same size reuse it as it is; a smaller
/// scene gives the excess back (a window once maximized and shrunk again would otherwise
/// keep the largest frame's buffers for the rest of the session).
fn fit(buf: &mut Vec<u32>, n: usize) {
    buf.resize(n, 0);
    buf.shrink_to_fit();
}

/// Readout rows equal but for the UI time (which every frame changes).
fn same_rows(a: &[(&'static str, String)], b: &[(&'static str, String)]) -> bool {
    let keep = |r: &&(&str, String)| r.0 != "UI";
    a.iter().filter(keep).eq(b.iter().filter(keep))
}

/// The notice when a zoom in stops at `min_hfov`: why it stops there, and where to change
/// it (`limit`: the zoom limit in screen pixels per map pixel, `None`: off).
pub fn zoom_stop_notice(min_hfov: f64, limit: Option<f64>) -> String {
    match limit {
        Some(r) => format!(
            "zoom stops at {min_hfov:.0}°: narrower, one map pixel would cover more than {r} \
             screen pixels (change it: P, Navigation, Zoom limit)"
        ),
        None => format!("narrowest view: {min_hfov:.0}°"),
    }
}

#[cfg(test)]
mod tests {
    use super::fit;

    #[test]
    fn a_smaller_scene_gives_its_buffer_back_and_the_same_size_reuses_it() {
        let mut buf = Vec::new();
        fit(&mut buf, 1280 * 800);
        assert_eq!(buf.len(), 1280 * 800);
        fit(&mut buf, 800 * 500);
        assert_eq!(buf.len(), 800 * 500);
        assert!(
            buf.capacity() < 1280 * 800,
            "kept {} pixels",
            buf.capacity()
        );
        let at = buf.as_ptr();
        fit(&mut buf, 800 * 500);
        assert_eq!(buf.as_ptr(), at, "the same size reallocated");
    }

    #[test]
    fn the_zoom_stop_notice_says_why_and_where() {
        let m = super::zoom_stop_notice(50.0, Some(2.0));
        assert!(m.contains("50°") && m.contains("2 screen pixels"), "{m}");
        assert!(m.contains("Zoom limit"), "names the setting: {m}");
        assert_eq!(super::zoom_stop_notice(1.0, None), "narrowest view: 1°");
    }
}

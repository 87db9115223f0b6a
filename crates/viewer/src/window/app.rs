//! The event loop: winit window, softbuffer surface, egui input and panel, lut-core
//! renders. Event-driven: a frame is drawn only when input arrives, egui asks for one
//! (its `repaint_delay`, never the `RedrawRequested` echo), something animates, or the
//! full-quality frame after fast motion is due. What is shown and loading is the
//! [`Document`]'s (pure, unit-tested); this module carries out its effects (loading
//! threads, the title, printing) and draws.

use super::document::{Document, Effect, LoadEvent};
use super::input::{
    key_action, wheel_notches, Controller, Held, KeyAction, Look, Turn, EXPOSURE_KEY_STEP_EV,
    TURN_KEYS,
};
use super::loader::{self, LoadRequest, Source};
use super::paint::{Compositor, SceneRect};
use super::ui::{self, PanelModel};
use super::OpenArgs;
use crate::lighting::{LightsKey, LightsState};
use crate::scene::render_scene;
use anyhow::{anyhow, Result};
use lut_core::{CubeRenderer, IndexStep, LutChoice, RenderPath, RendererKind, Sampler};
use std::collections::VecDeque;
use std::num::NonZeroU32;
use std::rc::Rc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{
    ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy, OwnedDisplayHandle,
};
use winit::window::{Fullscreen, Window, WindowId};

/// What a cached scene was rendered from: when it matches, the scene is reused.
#[derive(Debug, Clone, PartialEq)]
struct SceneKey {
    look: Look,
    size: (u32, u32),
    renderer: RendererKind,
    sampler: Sampler,
    index_step: IndexStep,
    lut: LutChoice,
    cube_renderer: CubeRenderer,
    map_generation: u64,
    lights: LightsKey,
}

/// Window, surface and egui-winit state: they exist between `resumed` and exit.
struct Gfx {
    window: Rc<Window>,
    surface: softbuffer::Surface<OwnedDisplayHandle, Rc<Window>>,
    egui_winit: egui_winit::State,
    surface_size: (u32, u32),
}

/// Things the UI pass asks the app to do after it.
#[derive(Default)]
struct FrameRequests {
    keys: Vec<KeyAction>,
    held: Held,
    panel: ui::PanelOutput,
    scene_rect: Option<SceneRect>,
    /// The pointer over the scene, in scene pixels.
    cursor: Option<(f64, f64)>,
}

struct App {
    print_view: bool,
    initial_size: (u32, u32),
    proxy: EventLoopProxy<LoadEvent>,
    softbuffer: softbuffer::Context<OwnedDisplayHandle>,
    start: Instant,
    gfx: Option<Gfx>,
    egui_ctx: egui::Context,
    compositor: Compositor,
    ctl: Controller,
    /// What is shown and loading.
    doc: Document,
    show_panel: bool,
    scene: Vec<u32>,
    scene_key: Option<SceneKey>,
    next_frame_at: Option<Instant>,
    frame_times: VecDeque<Instant>,
    fatal: Option<anyhow::Error>,
    /// The luminaires (panel state).
    lights: LightsState,
}

/// Open the window and run until it is closed.
pub fn run(args: OpenArgs, lights: LightsState) -> Result<()> {
    let input = &args.input;
    let event_loop = create_event_loop()?;
    let softbuffer = softbuffer::Context::new(event_loop.owned_display_handle())
        .map_err(|e| anyhow!("cannot use the display for software drawing: {e}"))?;
    let proxy = event_loop.create_proxy();
    let mut app = App {
        print_view: args.print_view,
        initial_size: args.size,
        proxy,
        softbuffer,
        start: Instant::now(),
        gfx: None,
        egui_ctx: egui::Context::default(),
        compositor: Compositor::new(),
        ctl: Controller::default(),
        doc: Document::new(
            input.projection.value.map(),
            args.limit.max_pixels,
            input.cube.naming,
        ),
        show_panel: true,
        scene: Vec::new(),
        scene_key: None,
        next_frame_at: None,
        frame_times: VecDeque::new(),
        fatal: None,
        lights,
    };
    app.ctl.settings.view_limit = !args.no_view_limit;
    app.ctl.settings.cube_renderer = input.cube_renderer;
    // One image in auto is a map (as `viewer render` takes it); `--projection cube` or
    // `--layout` makes it a cube.
    let source = if input.projection.value.reads_cube(&args.panorama) || input.cube.layout.is_some()
    {
        Source::of_paths(args.panorama.clone(), true, input.cube.layout)
    } else {
        args.panorama.first().cloned().map(Source::File)
    };
    let open = app.doc.open(
        source.unwrap_or(Source::Sample),
        input.coverage,
        app.ctl.settings.exposure_ev,
    );
    app.apply(vec![open]);
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    match app.fatal {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Create the event loop, turning a missing display (an error, or a panic deep in a
/// platform backend) into a clear error.
fn create_event_loop() -> Result<EventLoop<LoadEvent>> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let built = std::panic::catch_unwind(|| EventLoop::<LoadEvent>::with_user_event().build());
    std::panic::set_hook(hook);
    let no_display = "cannot open a window: no usable display (is DISPLAY or WAYLAND_DISPLAY set \
                      and the X11/Wayland libraries installed? `viewer render` works without one)";
    match built {
        Ok(Ok(el)) => Ok(el),
        Ok(Err(e)) => Err(anyhow!("{no_display}: {e}")),
        Err(p) => {
            let why = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(anyhow!("{no_display}: {why}"))
        }
    }
}

impl App {
    fn request_redraw(&self) {
        if let Some(g) = &self.gfx {
            g.window.request_redraw();
        }
    }

    /// Carry out what the document asks, then redraw.
    fn apply(&mut self, effects: Vec<Effect>) {
        for e in effects {
            match e {
                Effect::Load(req) => self.spawn_load(req),
                Effect::AddLights(paths) => {
                    for p in &paths {
                        // The error (if any) is shown in the Lights section.
                        let _ = self.lights.load_and_add(p);
                    }
                }
                Effect::Title(t) => {
                    if let Some(g) = &self.gfx {
                        g.window.set_title(&t);
                    }
                }
                Effect::PrintView(line) => {
                    if self.print_view {
                        let _ = crate::outln!("{line}");
                    }
                }
                Effect::Stderr(line) => crate::errln!("{line}"),
                Effect::ShowPanel => self.show_panel = true,
            }
        }
        self.request_redraw();
    }

    /// Run `req` on a loading thread that reports to the event loop.
    fn spawn_load(&mut self, req: LoadRequest) {
        let (id, proxy) = (req.id, self.proxy.clone());
        let spawned = std::thread::Builder::new()
            .name("viewer-load".into())
            .spawn(move || {
                let result = loader::load(req, &mut |step, fraction| {
                    let _ = proxy.send_event(LoadEvent::Progress { id, step, fraction });
                });
                let _ = proxy.send_event(LoadEvent::Done { id, result });
            });
        if let Err(e) = spawned {
            self.doc.load_not_started(id, &e.to_string());
        }
    }

    /// Build this frame's UI and collect what the user did.
    fn build_ui(&mut self, ui: &mut egui::Ui, t: f64, win: (u32, u32)) -> FrameRequests {
        let mut req = FrameRequests::default();
        let ppp = ui.ctx().pixels_per_point();
        if !ui.ctx().egui_wants_keyboard_input() {
            ui.input(|i| {
                for ev in &i.events {
                    if let egui::Event::Key {
                        key,
                        pressed: true,
                        repeat,
                        modifiers,
                        ..
                    } = ev
                    {
                        match key_action(*key, *modifiers) {
                            Some(KeyAction::Turn(_)) | None => {}
                            Some(a @ (KeyAction::ZoomIn | KeyAction::ZoomOut)) => req.keys.push(a),
                            Some(a) if !repeat => req.keys.push(a),
                            Some(_) => {}
                        }
                    }
                }
                let plain = !(i.modifiers.ctrl || i.modifiers.command);
                for k in TURN_KEYS {
                    if plain && i.key_down(k) {
                        match key_action(k, egui::Modifiers::NONE) {
                            Some(KeyAction::Turn(Turn::Left)) => req.held.left = true,
                            Some(KeyAction::Turn(Turn::Right)) => req.held.right = true,
                            Some(KeyAction::Turn(Turn::Up)) => req.held.up = true,
                            Some(KeyAction::Turn(Turn::Down)) => req.held.down = true,
                            _ => {}
                        }
                    }
                }
            });
        }
        if self.show_panel {
            let look = self.ctl.look();
            let doc = self.doc.panel_parts();
            req.panel = ui::side_panel(
                ui,
                PanelModel {
                    settings: &mut self.ctl.settings,
                    projection: doc.projection,
                    look,
                    readouts: doc.readouts,
                    loading: doc.loading,
                    error: doc.error,
                    lights: &mut self.lights,
                },
            );
        }
        if let Some(l) = self.doc.loading() {
            if !self.show_panel || self.doc.current().is_none() {
                // Nothing else shows the load: a box over the scene.
                ui::loading_overlay(ui.ctx(), l);
            }
        }
        // The scene: everything the panel leaves. Drags and wheel go through egui so a
        // click on the panel is never taken for a drag (hit-testing is egui's).
        let rect = ui.available_rect_before_wrap();
        let resp = ui.interact(rect, egui::Id::new("scene"), egui::Sense::drag());
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
        let primary = egui::PointerButton::Primary;
        if resp.drag_started_by(primary) {
            let origin = ui
                .input(|i| i.pointer.press_origin())
                .or(resp.interact_pointer_pos());
            if let Some(o) = origin {
                self.ctl.press(to_px(o), size, t);
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

    fn apply_requests(&mut self, req: &FrameRequests, t: f64, el: &ActiveEventLoop) {
        self.ctl.set_held(req.held.or(req.panel.held), t);
        let ev = self.ctl.settings.exposure_ev;
        if req.panel.reset {
            self.ctl.key(KeyAction::Reset);
        }
        if req.panel.dismiss_error {
            self.doc.dismiss_error();
        }
        if req.panel.projection_changed {
            let fx = self.doc.projection_changed(ev);
            self.apply(fx.into_iter().collect());
        }
        if req.panel.exposure_commit {
            let fx = self.doc.reload_exposure(ev);
            self.apply(fx.into_iter().collect());
        }
        if req.panel.save_view {
            self.save_view();
        }
        for &a in &req.keys {
            match a {
                KeyAction::ExposureDown | KeyAction::ExposureUp => {
                    let d = if a == KeyAction::ExposureUp {
                        EXPOSURE_KEY_STEP_EV
                    } else {
                        -EXPOSURE_KEY_STEP_EV
                    };
                    let s = &mut self.ctl.settings;
                    let ev = super::export::step_exposure(s.exposure_ev, d);
                    if ev != s.exposure_ev && self.doc.readouts.hdr {
                        s.exposure_ev = ev;
                        let fx = self.doc.reload_exposure(ev);
                        self.apply(fx.into_iter().collect());
                    }
                }
                KeyAction::SaveView => self.save_view(),
                KeyAction::TogglePanel => self.show_panel = !self.show_panel,
                KeyAction::Quit => el.exit(),
                KeyAction::ToggleFullscreen => {
                    if let Some(g) = &self.gfx {
                        let full = g.window.fullscreen().is_some();
                        g.window
                            .set_fullscreen((!full).then_some(Fullscreen::Borderless(None)));
                    }
                }
                KeyAction::LeaveFullscreen => {
                    if let Some(g) = &self.gfx {
                        g.window.set_fullscreen(None);
                    }
                }
                other => self.ctl.key(other),
            }
        }
    }

    /// "Save view…" / P: render the current view at the scene's size times the export
    /// scale, full quality (the chosen sampler, trilinear by default, never the fast
    /// nearest), lit as shown, and write it to `view-N.png` in the current directory.
    fn save_view(&mut self) {
        let scene = match self.doc.readouts.scene {
            (w, h) if w > 0 && h > 0 => (w, h),
            _ => self.gfx.as_ref().map_or((1024, 640), |g| {
                let s = g.window.inner_size();
                (s.width, s.height)
            }),
        };
        let (w, h) = super::export::export_size(scene, self.ctl.settings.export_scale);
        let status = match self.render_export(w, h) {
            Ok(pixels) => {
                let path = super::export::next_view_path(std::path::Path::new("."), |p| p.exists());
                match crate::output::write_png_atomic(&path, &pixels, w, h) {
                    Ok(()) => format!("saved {} ({w}×{h})", path.display()),
                    Err(e) => format!("save failed: {e:#}"),
                }
            }
            Err(e) => format!("save failed: {e}"),
        };
        if self.print_view {
            let _ = crate::outln!("{status}");
        }
        self.doc.readouts.export_status = Some(status);
        self.show_panel = true;
        self.request_redraw();
    }

    /// The current view rendered into a new `w`×`h` buffer with the window's renderer
    /// and options at full quality, then lit as the scene is.
    fn render_export(&mut self, w: u32, h: u32) -> Result<Vec<u32>, String> {
        let cur = self
            .doc
            .current_mut()
            .ok_or_else(|| "no panorama loaded".to_string())?;
        let opts = lut_core::RenderOptions {
            sampler: self.ctl.settings.sampler,
            ..self.ctl.settings.render_options(false)
        };
        let view = self.ctl.look().view();
        let mut buf = vec![0u32; w as usize * h as usize];
        render_scene(cur.scene.as_mut(), view, &opts, &mut buf, w, h).map_err(|e| e.to_string())?;
        self.lights.light_frame(view, &mut buf, w, h)?;
        Ok(buf)
    }

    /// Render the scene for `rect` unless the cached one already shows it, then light it
    /// when there are luminaires.
    fn render_scene(&mut self, rect: SceneRect, look: Look, fast: bool) {
        let generation = self.doc.generation();
        let Some(cur) = self.doc.current_mut() else {
            return;
        };
        let opts = self.ctl.settings.render_options(fast);
        let key = SceneKey {
            look,
            size: (rect.w, rect.h),
            renderer: opts.renderer,
            sampler: opts.sampler,
            index_step: opts.index_step,
            lut: opts.lut,
            cube_renderer: opts.cube,
            map_generation: generation,
            lights: self.lights.key(),
        };
        if self.scene_key.as_ref() == Some(&key) {
            return;
        }
        self.scene.resize(rect.w as usize * rect.h as usize, 0);
        let t0 = Instant::now();
        let view = look.view();
        let result = render_scene(
            cur.scene.as_mut(),
            view,
            &opts,
            &mut self.scene,
            rect.w,
            rect.h,
        );
        match result {
            Ok(report) => {
                let readouts = &mut self.doc.readouts;
                readouts.table_bytes = report.table_bytes;
                readouts.exact_pixels = report.exact_pixels;
                readouts.pixels = report.pixels;
                let path = match report.path {
                    RenderPath::Cube(kind) => {
                        readouts.path = None;
                        readouts.cube = Some(kind);
                        match kind {
                            CubeRenderer::Basic => "CubeBasic".to_string(),
                            CubeRenderer::Accelerated => "CubeScanline".to_string(),
                        }
                    }
                    path => {
                        readouts.path = Some(path);
                        readouts.cube = None;
                        format!("{path:?}")
                    }
                };
                self.light_scene(view, rect);
                let readouts = &mut self.doc.readouts;
                readouts.render_ms = t0.elapsed().as_secs_f64() * 1e3;
                readouts.scene = (rect.w, rect.h);
                self.scene_key = Some(key);
                if self.print_view {
                    let _ = crate::outln!(
                        "view yaw={:.4} pitch={:.4} hfov={:.4} path={path} sampler={} fast={} size={}x{} lights={}",
                        look.yaw,
                        look.pitch,
                        look.hfov,
                        opts.sampler.name(),
                        fast,
                        rect.w,
                        rect.h,
                        self.lights.lights.len()
                    );
                }
            }
            Err(e) => {
                self.doc.set_error(format!("render failed: {e}"));
                self.scene_key = None;
            }
        }
    }

    /// Light the freshly rendered scene (as `viewer render --light ...` does); a scene
    /// that cannot be built (a light outside the room) is reported in the panel and the
    /// frame is left unlit.
    fn light_scene(&mut self, view: lut_core::View, rect: SceneRect) {
        let result = self
            .lights
            .light_frame(view, &mut self.scene, rect.w, rect.h);
        self.lights.scene_error = result.err();
    }

    /// The illuminance at the pointer for the readout; true when it changed.
    fn update_lux(
        &mut self,
        cursor: Option<(f64, f64)>,
        rect: Option<SceneRect>,
        look: Look,
    ) -> bool {
        let lux = match (cursor, rect, self.lights.scene()) {
            (Some((x, y)), Some(r), Ok(Some(scene))) if r.w > 0 && r.h > 0 => Some(
                lut_core::lux_at(&scene, &lut_core::Camera::new(look.view(), r.w, r.h), x, y),
            ),
            _ => None,
        };
        let changed = lux.map(f64::to_bits) != self.lights.lux_at_cursor.map(f64::to_bits);
        self.lights.lux_at_cursor = lux;
        changed
    }

    fn redraw(&mut self, el: &ActiveEventLoop) -> Result<()> {
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
        let t = self.start.elapsed().as_secs_f64();
        let ui_t0 = Instant::now();
        let raw = g.egui_winit.take_egui_input(&g.window);
        let ctx = self.egui_ctx.clone();
        let look_before = self.ctl.look();
        let mut req = FrameRequests::default();
        let full = ctx.run_ui(raw, |ui| req = self.build_ui(ui, t, (w, h)));
        self.apply_requests(&req, t, el);
        // The view limit: a partial map's coverage at the scene's size, when the panel's
        // "Keep the view inside" is on.
        let limit = match (req.scene_rect, self.doc.partial_coverage()) {
            (Some(r), Some(c)) if self.ctl.settings.view_limit => Some((c, (r.w, r.h))),
            _ => None,
        };
        self.ctl.set_limit(limit);
        let frame = self.ctl.frame(t);
        let mut ui_ms = ui_t0.elapsed().as_secs_f64() * 1e3;
        if let Some(r) = req.scene_rect {
            self.render_scene(r, frame.look, frame.fast);
        }
        let lux_changed = self.update_lux(req.cursor, req.scene_rect, frame.look);
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
        let scene = match (req.scene_rect, &self.scene_key) {
            (Some(r), Some(k)) if k.size == (r.w, r.h) => Some((self.scene.as_slice(), r)),
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
        self.frame_times.push_back(now);
        while self
            .frame_times
            .front()
            .is_some_and(|&f| now.duration_since(f) > Duration::from_secs(1))
        {
            self.frame_times.pop_front();
        }
        self.doc.readouts.fps = match (self.frame_times.front(), self.frame_times.len()) {
            (Some(&f), n) if n >= 2 => (n - 1) as f64 / now.duration_since(f).as_secs_f64(),
            _ => 0.0,
        };

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
        if let Some(at) = self.ctl.wake_at() {
            want(self.start + Duration::from_secs_f64(at.max(0.0)));
        }
        if (self.ctl.look() != look_before || lux_changed) && self.show_panel {
            // The readouts were drawn before this frame's input moved the view.
            want(now);
        }
        self.next_frame_at = next;
        Ok(())
    }
}

impl ApplicationHandler<LoadEvent> for App {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        let (w, h) = self.initial_size;
        let attrs = Window::default_attributes()
            .with_title("viewer")
            .with_inner_size(winit::dpi::LogicalSize::new(f64::from(w), f64::from(h)));
        let window = match el.create_window(attrs) {
            Ok(w) => Rc::new(w),
            Err(e) => {
                self.fatal = Some(anyhow!("cannot create a window: {e}"));
                el.exit();
                return;
            }
        };
        let surface = match softbuffer::Surface::new(&self.softbuffer, window.clone()) {
            Ok(s) => s,
            Err(e) => {
                self.fatal = Some(anyhow!("cannot draw into the window: {e}"));
                el.exit();
                return;
            }
        };
        let egui_winit = egui_winit::State::new(
            self.egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            window.theme(),
            None,
        );
        window.request_redraw();
        self.gfx = Some(Gfx {
            window,
            surface,
            egui_winit,
            surface_size: (0, 0),
        });
    }

    fn user_event(&mut self, _el: &ActiveEventLoop, ev: LoadEvent) {
        let fx = self.doc.on_event(ev, self.ctl.settings.exposure_ev);
        self.apply(fx);
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(g) = self.gfx.as_mut() else {
            return;
        };
        let response = g.egui_winit.on_window_event(&g.window, &event);
        match event {
            WindowEvent::CloseRequested => el.exit(),
            WindowEvent::RedrawRequested => {
                // egui-winit answers "repaint" to this very event: ignore that, or the idle
                // viewer would redraw forever.
                if let Err(e) = self.redraw(el) {
                    self.fatal = Some(e);
                    el.exit();
                }
            }
            WindowEvent::DroppedFile(path) => self.doc.drop_path(path),
            WindowEvent::Resized(_) | WindowEvent::ScaleFactorChanged { .. } => {
                g.window.request_redraw()
            }
            _ => {
                if response.repaint {
                    g.window.request_redraw();
                }
            }
        }
    }

    fn about_to_wait(&mut self, el: &ActiveEventLoop) {
        if self.doc.has_drops() {
            let fx = self.doc.open_drops(self.ctl.settings.exposure_ev);
            self.apply(fx);
        }
        match self.next_frame_at {
            Some(at) if at <= Instant::now() => {
                self.next_frame_at = None;
                self.request_redraw();
                el.set_control_flow(ControlFlow::Wait);
            }
            Some(at) => el.set_control_flow(ControlFlow::WaitUntil(at)),
            None => el.set_control_flow(ControlFlow::Wait),
        }
    }
}

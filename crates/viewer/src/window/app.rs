//! The event loop: winit window, softbuffer surface, egui input and panel, lut-core
//! renders, background loads. Event-driven: a frame is drawn only when input arrives,
//! egui asks for one (its `repaint_delay`, never the `RedrawRequested` echo), something
//! animates, or the full-quality frame after fast motion is due.

use super::input::{
    key_action, wheel_notches, Controller, Held, KeyAction, Look, Turn, EXPOSURE_KEY_STEP_EV,
    TURN_KEYS,
};
use super::lights::{LightsKey, LightsState};
use super::paint::{Compositor, SceneRect};
use super::ui::{self, LoadStatus, LoadStep, PanelModel, Readouts};
use super::OpenArgs;
use crate::render_cmd::{CubeRendererArg, ProjectionArg};
use anyhow::{anyhow, Result};
use lut_core::{
    Camera, EnvMap, IndexStep, LutChoice, Projection, Renderer, RendererKind, Sampler, Tone,
};
use lut_core::{CubeMap, CubeRenderer, Frame, RenderOptions, RenderPath};
use std::collections::VecDeque;
use std::num::NonZeroU32;
use std::path::PathBuf;
use std::rc::Rc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{
    ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy, OwnedDisplayHandle,
};
use winit::window::{Fullscreen, Window, WindowId};

/// Where a panorama comes from.
#[derive(Debug, Clone, PartialEq)]
enum Source {
    Sample,
    File(PathBuf),
    /// A cube map: a folder, face files or one layout image, with the layout if given.
    Cube {
        paths: Vec<PathBuf>,
        layout: Option<String>,
    },
}

impl Source {
    fn name(&self) -> String {
        match self {
            Source::Sample => crate::assets::SAMPLE_NAME.to_string(),
            Source::File(p) => p.display().to_string(),
            Source::Cube { paths, .. } => match paths.as_slice() {
                [one] => one.display().to_string(),
                many => format!(
                    "{} cube faces in {}",
                    many.len(),
                    many.first()
                        .and_then(|p| p.parent())
                        .map_or_else(|| ".".into(), |d| d.display().to_string())
                ),
            },
        }
    }

    /// The source that opens what `paths` were dropped or given as: a folder or several
    /// files are a cube map; one image is a cube map when its aspect ratio is a cube
    /// layout's (4:3, 6:1, 3:2) or a layout is forced.
    fn of_paths(paths: Vec<PathBuf>, cube: bool, layout: Option<String>) -> Option<Source> {
        let cube = cube || layout.is_some() || crate::cube_cmd::looks_like_cube(&paths);
        match paths.as_slice() {
            [] => None,
            [one] if !cube => Some(Source::File(one.clone())),
            _ => Some(Source::Cube { paths, layout }),
        }
    }
}

/// What is shown: a map on a surface of revolution with its LUT renderer, or a cube map.
enum Scene {
    Map { map: EnvMap, renderer: Renderer },
    Cube(CubeMap),
}

impl Scene {
    /// Render `view` into `frame` through lut-core's one render entry.
    fn render(
        &mut self,
        view: lut_core::View,
        opts: &RenderOptions,
        frame: &mut Frame<'_>,
    ) -> Result<lut_core::RenderReport, lut_core::ViewError> {
        match self {
            Scene::Map { map, renderer } => {
                renderer.render(lut_core::Scene::Map(map), view, opts, frame)
            }
            Scene::Cube(cube) => {
                Renderer::default().render(lut_core::Scene::Cube(cube), view, opts, frame)
            }
        }
    }
}

/// A loaded panorama with its renderer (tables built on the loading thread).
struct Loaded {
    scene: Scene,
    source: Source,
    projection: Option<Projection>,
    /// An HDR file (`.hdr`, `.exr`): shown through the panel's exposure.
    hdr: bool,
    /// The exposure it was decoded with (stops).
    exposure_ev: f64,
}

impl Loaded {
    /// Size and projection for the readout and `--print-view`: "W×H projection".
    fn describe(&self) -> (u32, u32, &'static str) {
        match &self.scene {
            Scene::Map { map, .. } => (map.width(), map.height(), map.projection().name()),
            Scene::Cube(c) => (c.face_size(), c.face_size(), "cube"),
        }
    }
}

/// Messages from the loading thread.
enum UserEvent {
    Progress {
        id: u64,
        step: LoadStep,
        fraction: Option<f32>,
    },
    Done {
        id: u64,
        result: Result<Box<Loaded>, String>,
    },
}

/// The loading thread's work: read, decode, convert, build tables, reporting each step
/// (see `lut_core::load` for which decoders measure their progress).
fn load(
    proxy: &EventLoopProxy<UserEvent>,
    id: u64,
    source: Source,
    opts: &lut_core::LoadOptions,
    naming: Option<&str>,
    coverage: Option<lut_core::Coverage>,
) -> Result<Box<Loaded>, String> {
    let hdr = matches!(&source, Source::File(p) if super::export::is_hdr_path(p));
    let send = |step: LoadStep, fraction: Option<f32>| {
        let _ = proxy.send_event(UserEvent::Progress { id, step, fraction });
    };
    let mut on_progress = |p: lut_core::LoadProgress| send(p.phase.into(), p.fraction);
    let map = match &source {
        Source::Cube { paths, layout } => {
            send(LoadStep::Decoding, None);
            let cube = crate::cube_cmd::load_cube(paths, layout.as_deref(), naming)
                .map_err(|e| format!("{e:#}"))?;
            return Ok(Box::new(Loaded {
                scene: Scene::Cube(cube),
                source,
                projection: opts.projection,
                hdr: false,
                exposure_ev: opts.tone.exposure_ev,
            }));
        }
        // The same loading as `viewer render` (streamed from the file, the pixel limit
        // checked from the header first; partial panoramas placed by GPano XMP or the
        // command line's --coverage); 8-bit images ignore the tone.
        Source::Sample => {
            crate::partial::load_panorama_partial(None, opts, coverage, &mut on_progress)
                .map_err(|e| format!("{e:#}"))?
                .0
        }
        Source::File(p) => {
            crate::partial::load_panorama_partial(Some(p), opts, coverage, &mut on_progress)
                .map_err(|e| format!("{e:#}"))?
                .0
        }
    };
    // Build both tables and the pyramid (the window's default sampler is trilinear) now,
    // so the first frames do not wait for them.
    send(LoadStep::Tables, Some(0.0));
    let mut renderer = Renderer::new(&map);
    let surface = lut_core::RenderOptions::default().surface;
    renderer.table(surface, lut_core::TableKind::Wide);
    send(LoadStep::Tables, Some(0.3));
    renderer.table(surface, lut_core::TableKind::High);
    send(LoadStep::Tables, Some(0.5));
    map.pyramid();
    send(LoadStep::Tables, Some(1.0));
    Ok(Box::new(Loaded {
        scene: Scene::Map { map, renderer },
        source,
        projection: opts.projection,
        hdr,
        exposure_ev: opts.tone.exposure_ev,
    }))
}

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
    proxy: EventLoopProxy<UserEvent>,
    softbuffer: softbuffer::Context<OwnedDisplayHandle>,
    start: Instant,
    gfx: Option<Gfx>,
    egui_ctx: egui::Context,
    compositor: Compositor,
    ctl: Controller,
    current: Option<Box<Loaded>>,
    map_generation: u64,
    /// Projection chosen in the panel for the current (or failed) file.
    projection: Option<Projection>,
    /// The source the projection choice applies to: the current one, or a failed one.
    projection_source: Option<Source>,
    loading: Option<(u64, Source, LoadStatus)>,
    next_load_id: u64,
    error: Option<String>,
    /// The running load is the fallback after a failed one: its success keeps the error.
    keep_error: bool,
    show_panel: bool,
    scene: Vec<u32>,
    scene_key: Option<SceneKey>,
    readouts: Readouts,
    next_frame_at: Option<Instant>,
    frame_times: VecDeque<Instant>,
    fatal: Option<anyhow::Error>,
    /// `--max-pixels`: the pixel limit for every panorama opened.
    max_pixels: u64,
    /// Cube face naming from the command line (for every cube opened).
    naming: Option<String>,
    /// The luminaires (panel state).
    lights: LightsState,
    /// Paths dropped since the last event batch: one drop of several items arrives as one
    /// event per item, and they open together (six face files are one cube map).
    pending_drops: Vec<PathBuf>,
    /// `--coverage`, for the source given on the command line only.
    coverage: Option<(Source, lut_core::Coverage)>,
}

/// Open the window and run until it is closed.
pub fn run(args: OpenArgs, lights: LightsState) -> Result<()> {
    let projection = match args.input.projection {
        ProjectionArg::Map(p) => Some(p),
        ProjectionArg::Auto | ProjectionArg::Cube => None,
    };
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
        current: None,
        map_generation: 0,
        projection,
        projection_source: None,
        loading: None,
        next_load_id: 0,
        error: None,
        keep_error: false,
        show_panel: true,
        scene: Vec::new(),
        scene_key: None,
        readouts: Readouts::default(),
        next_frame_at: None,
        frame_times: VecDeque::new(),
        fatal: None,
        max_pixels: args.limit.max_pixels,
        naming: args.input.naming.clone(),
        lights,
        pending_drops: Vec::new(),
        coverage: None,
    };
    app.ctl.settings.view_limit = !args.no_view_limit;
    app.ctl.settings.cube_renderer = match args.input.cube_renderer {
        CubeRendererArg::Basic => CubeRenderer::Basic,
        CubeRendererArg::Scanline => CubeRenderer::Accelerated,
    };
    let cube = match args.input.projection {
        ProjectionArg::Cube => true,
        ProjectionArg::Map(_) => false,
        ProjectionArg::Auto => args.panorama.len() > 1 || args.panorama.iter().any(|p| p.is_dir()),
    };
    // One image in auto is a map (as `viewer render` takes it); `--projection cube` or
    // `--layout` makes it a cube.
    let source = if cube || args.input.layout.is_some() {
        Source::of_paths(args.panorama, true, args.input.layout)
    } else {
        args.panorama.first().cloned().map(Source::File)
    };
    let source = source.unwrap_or(Source::Sample);
    app.coverage = args.input.coverage.map(|c| (source.clone(), c));
    app.start_load(source, projection);
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
fn create_event_loop() -> Result<EventLoop<UserEvent>> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let built = std::panic::catch_unwind(|| EventLoop::<UserEvent>::with_user_event().build());
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

    /// Load `source` on a background thread; the current panorama stays until it is done.
    fn start_load(&mut self, source: Source, projection: Option<Projection>) {
        self.next_load_id += 1;
        let id = self.next_load_id;
        let status = LoadStatus::new(source.name());
        self.loading = Some((id, source.clone(), status));
        self.keep_error = false;
        let proxy = self.proxy.clone();
        let naming = self.naming.clone();
        let opts = lut_core::LoadOptions {
            projection,
            tone: Tone {
                exposure_ev: self.ctl.settings.exposure_ev,
            },
            max_pixels: self.max_pixels,
        };
        let coverage = self
            .coverage
            .as_ref()
            .filter(|(s, _)| *s == source)
            .map(|(_, c)| *c);
        let spawned = std::thread::Builder::new()
            .name("viewer-load".into())
            .spawn(move || {
                let result = load(&proxy, id, source, &opts, naming.as_deref(), coverage);
                let _ = proxy.send_event(UserEvent::Done { id, result });
            });
        if let Err(e) = spawned {
            self.loading = None;
            self.error = Some(format!("cannot start loading: {e}"));
        }
        self.request_redraw();
    }

    fn on_load_event(&mut self, ev: UserEvent) {
        let current_id = self.loading.as_ref().map(|l| l.0);
        match ev {
            UserEvent::Progress { id, step, fraction } if Some(id) == current_id => {
                if let Some((_, _, st)) = &mut self.loading {
                    st.advance(step, fraction);
                }
            }
            UserEvent::Done { id, result } if Some(id) == current_id => {
                let source = self.loading.take().map(|l| l.1);
                match result {
                    Ok(loaded) => {
                        let (mw, mh, proj) = loaded.describe();
                        if self.print_view {
                            println!("loaded {} {mw}x{mh} {proj}", loaded.source.name());
                        }
                        self.readouts.map = match loaded.scene {
                            Scene::Cube(_) => {
                                format!("{} (cube, {mw}px faces)", short_name(&loaded.source))
                            }
                            Scene::Map { ref map, .. } => format!(
                                "{} ({mw}×{mh}, {proj}, {} in memory)",
                                short_name(&loaded.source),
                                format_bytes(map.bytes())
                            ),
                        };
                        if let Some(g) = &self.gfx {
                            g.window
                                .set_title(&format!("viewer: {}", short_name(&loaded.source)));
                        }
                        if !std::mem::take(&mut self.keep_error) {
                            self.error = None;
                            self.projection = loaded.projection;
                            self.projection_source = Some(loaded.source.clone());
                        }
                        self.readouts.hdr = loaded.hdr;
                        let map = match &loaded.scene {
                            Scene::Map { map, .. } => Some(map),
                            Scene::Cube(_) => None,
                        };
                        self.readouts.partial = map.and_then(crate::partial::coverage_text);
                        self.readouts.pose_heading = map.and_then(EnvMap::pose_heading_deg);
                        if self.print_view {
                            if let Some(p) = &self.readouts.partial {
                                println!("partial {p}");
                            }
                        }
                        self.current = Some(loaded);
                        self.map_generation += 1;
                    }
                    Err(e) => {
                        eprintln!("viewer: {e}");
                        self.error = Some(e);
                        self.show_panel = true;
                        // A projection chosen next retries this file.
                        self.projection_source = source;
                        if self.current.is_none() {
                            // Nothing to keep showing: fall back to the bundled sample.
                            self.start_load(Source::Sample, None);
                            self.keep_error = true;
                        }
                    }
                }
            }
            _ => {} // from a superseded load
        }
        self.request_redraw();
    }

    /// Open what was dropped: `.ies` files add lights, the rest is one panorama or cube.
    fn open_dropped(&mut self) {
        let (ies, rest): (Vec<PathBuf>, Vec<PathBuf>) = std::mem::take(&mut self.pending_drops)
            .into_iter()
            .partition(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("ies")));
        for p in &ies {
            // The error (if any) is shown in the Lights section.
            let _ = self.lights.load_and_add(p);
            self.show_panel = true;
        }
        if let Some(source) = Source::of_paths(rest, false, None) {
            self.start_load(source, None);
        }
        self.request_redraw();
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
            let loading = self.loading.as_ref().map(|l| &l.2);
            let look = self.ctl.look();
            req.panel = ui::side_panel(
                ui,
                PanelModel {
                    settings: &mut self.ctl.settings,
                    projection: &mut self.projection,
                    look,
                    readouts: &self.readouts,
                    loading,
                    error: self.error.as_deref(),
                    lights: &mut self.lights,
                },
            );
        }
        if let Some((_, _, l)) = &self.loading {
            if !self.show_panel || self.current.is_none() {
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
        if req.panel.reset {
            self.ctl.key(KeyAction::Reset);
        }
        if req.panel.dismiss_error {
            self.error = None;
            self.projection_source = self.current.as_ref().map(|c| c.source.clone());
            self.projection = self.current.as_ref().and_then(|c| c.projection);
        }
        if req.panel.projection_changed {
            let source = self
                .projection_source
                .clone()
                .or_else(|| self.current.as_ref().map(|c| c.source.clone()));
            // A projection chosen for a cube's single layout image opens it as a map.
            let source = source.map(|s| match s {
                Source::Cube { paths, .. } if paths.len() == 1 && !paths[0].is_dir() => {
                    Source::File(paths[0].clone())
                }
                other => other,
            });
            if let Some(s) = source {
                self.start_load(s, self.projection);
            }
        }
        if req.panel.exposure_commit {
            self.reload_exposure();
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
                    if ev != s.exposure_ev && self.readouts.hdr {
                        s.exposure_ev = ev;
                        self.reload_exposure();
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

    /// Decode the current HDR file again with the panel's exposure (on the loading
    /// thread; the view and the current picture stay until it is ready).
    fn reload_exposure(&mut self) {
        let Some(cur) = self.current.as_ref().filter(|c| c.hdr) else {
            return;
        };
        if cur.exposure_ev == self.ctl.settings.exposure_ev && self.loading.is_none() {
            return;
        }
        let (source, projection) = (cur.source.clone(), cur.projection);
        self.start_load(source, projection);
    }

    /// "Save view…" / P: render the current view at the scene's size times the export
    /// scale, full quality (the chosen sampler, trilinear by default, never the fast
    /// nearest), lit as shown, and write it to `view-N.png` in the current directory.
    fn save_view(&mut self) {
        let scene = match self.readouts.scene {
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
                match crate::cli_common::write_png_atomic(&path, &pixels, w, h) {
                    Ok(()) => format!("saved {} ({w}×{h})", path.display()),
                    Err(e) => format!("save failed: {e:#}"),
                }
            }
            Err(e) => format!("save failed: {e}"),
        };
        if self.print_view {
            println!("{status}");
        }
        self.readouts.export_status = Some(status);
        self.show_panel = true;
        self.request_redraw();
    }

    /// The current view rendered into a new `w`×`h` buffer with the window's renderer
    /// and options at full quality, then lit as the scene is.
    fn render_export(&mut self, w: u32, h: u32) -> Result<Vec<u32>, String> {
        let cur = self
            .current
            .as_mut()
            .ok_or_else(|| "no panorama loaded".to_string())?;
        let opts = lut_core::RenderOptions {
            sampler: self.ctl.settings.sampler,
            ..self.ctl.settings.render_options(false)
        };
        let view = self.ctl.look().view();
        let mut buf = vec![0u32; w as usize * h as usize];
        let mut frame = Frame::new(&mut buf, w, h).map_err(|e| e.to_string())?;
        cur.scene
            .render(view, &opts, &mut frame)
            .map_err(|e| e.to_string())?;
        if let Some(scene) = self.lights.scene()? {
            lut_core::shade_frame(
                &scene,
                &Camera::new(view, w, h),
                &mut buf,
                w,
                h,
                &self.lights.shade_options(),
            )
            .map_err(|e| e.to_string())?;
        }
        Ok(buf)
    }

    /// Render the scene for `rect` unless the cached one already shows it, then light it
    /// when there are luminaires.
    fn render_scene(&mut self, rect: SceneRect, look: Look, fast: bool) {
        let Some(cur) = self.current.as_mut() else {
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
            cube_renderer: self.ctl.settings.cube_renderer,
            map_generation: self.map_generation,
            lights: self.lights.key(),
        };
        if self.scene_key.as_ref() == Some(&key) {
            return;
        }
        self.scene.resize(rect.w as usize * rect.h as usize, 0);
        let t0 = Instant::now();
        let view = look.view();
        let result = Frame::new(&mut self.scene, rect.w, rect.h)
            .and_then(|mut frame| cur.scene.render(view, &opts, &mut frame))
            .map(|report| {
                self.readouts.table_bytes = report.table_bytes;
                self.readouts.exact_pixels = report.exact_pixels;
                self.readouts.pixels = report.pixels;
                match report.path {
                    RenderPath::Cube(kind) => {
                        self.readouts.path = None;
                        self.readouts.cube = Some(kind);
                        match kind {
                            CubeRenderer::Basic => "CubeBasic".to_string(),
                            CubeRenderer::Accelerated => "CubeScanline".to_string(),
                        }
                    }
                    path => {
                        self.readouts.path = Some(path);
                        self.readouts.cube = None;
                        format!("{path:?}")
                    }
                }
            });
        match result {
            Ok(path) => {
                self.light_scene(view, rect);
                self.readouts.render_ms = t0.elapsed().as_secs_f64() * 1e3;
                self.readouts.scene = (rect.w, rect.h);
                self.scene_key = Some(key);
                if self.print_view {
                    println!(
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
                self.error = Some(format!("render failed: {e}"));
                self.scene_key = None;
            }
        }
    }

    /// The view limit for this frame: a partial map's coverage at the scene's size, when
    /// the panel's "Keep the view inside" is on.
    fn view_limit(&self, rect: Option<SceneRect>) -> Option<(lut_core::Coverage, (u32, u32))> {
        let r = rect?;
        match &self.current.as_ref()?.scene {
            Scene::Map { map, .. } if self.ctl.settings.view_limit && map.crop().is_some() => {
                Some((map.coverage(), (r.w, r.h)))
            }
            _ => None,
        }
    }

    /// Light the freshly rendered scene (as `viewer render --light ...` does); a scene
    /// that cannot be built (a light outside the room) is reported in the panel and the
    /// frame is left unlit.
    fn light_scene(&mut self, view: lut_core::View, rect: SceneRect) {
        let result = self.lights.scene().and_then(|scene| match scene {
            None => Ok(()),
            Some(scene) => lut_core::shade_frame(
                &scene,
                &Camera::new(view, rect.w, rect.h),
                &mut self.scene,
                rect.w,
                rect.h,
                &self.lights.shade_options(),
            )
            .map_err(|e| e.to_string()),
        });
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
                lut_core::lux_at(&scene, &Camera::new(look.view(), r.w, r.h), x, y),
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
        self.ctl.set_limit(self.view_limit(req.scene_rect));
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
        self.readouts.ui_ms = ui_ms;

        let now = Instant::now();
        self.frame_times.push_back(now);
        while self
            .frame_times
            .front()
            .is_some_and(|&f| now.duration_since(f) > Duration::from_secs(1))
        {
            self.frame_times.pop_front();
        }
        self.readouts.fps = match (self.frame_times.front(), self.frame_times.len()) {
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

/// A byte count for the readout: "2.00 GiB", "12.3 MiB".
fn format_bytes(b: usize) -> String {
    let b = b as f64;
    if b >= f64::from(1u32 << 30) {
        format!("{:.2} GiB", b / f64::from(1u32 << 30))
    } else {
        format!("{:.1} MiB", b / f64::from(1u32 << 20))
    }
}

fn short_name(s: &Source) -> String {
    match s {
        Source::Sample => "courtyard (bundled sample)".into(),
        Source::File(p) => p.file_name().map_or_else(
            || p.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        ),
        Source::Cube { paths, .. } => match paths.as_slice() {
            [one] => one.file_name().map_or_else(
                || one.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            ),
            many => format!("{} cube faces", many.len()),
        },
    }
}

impl ApplicationHandler<UserEvent> for App {
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

    fn user_event(&mut self, _el: &ActiveEventLoop, ev: UserEvent) {
        self.on_load_event(ev);
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
            WindowEvent::DroppedFile(path) => self.pending_drops.push(path),
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
        if !self.pending_drops.is_empty() {
            self.open_dropped();
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

//! The event loop: winit window, softbuffer surface, egui input and UI, lut-core
//! renders. Event-driven: a frame is drawn only when input arrives, egui asks for one
//! (its `repaint_delay`, never the `RedrawRequested` echo), something animates, a notice
//! expires, or the full-quality frame after degraded motion is due; frames come at most
//! once per display refresh. What is shown and loading is the [`Document`]'s (pure,
//! unit-tested); this module carries out its effects (loading threads, the title,
//! printing).
//!
//! * `frame.rs`: one frame: routing keys, the UI pass, the scene render at the chosen
//!   quality, composing, and when the next frame is due.
//! * `actions.rs`: what keys, buttons and dialogs do; settings kept between runs.
//! * `lights.rs`: the lit scene from the illuminance map, the room and luminaires over
//!   it, luminaires picked and dragged in the view, scene files opened and saved.

mod actions;
mod frame;
mod lights;
mod tour;

use lights::SceneDrag;

use super::dialogs::Dialogs;
use super::document::{Document, LoadEvent, StartArgs};
use super::input::{AutoRotate, Controller};
use super::keys::Shortcuts;
use super::loader::Source;
use super::notices::Notices;
use super::paint::Compositor;
use super::prefs::Prefs;
use super::quality::{FrameTimes, Level};
use super::OpenArgs;
use crate::lighting::{LightsKey, LightsState, LitCache, LitPanorama};
use anyhow::{anyhow, Result};
use lut_core::{CubeRenderer, IndexStep, LutChoice, RendererKind, Sampler, View};
use std::collections::VecDeque;
use std::path::PathBuf;
use std::rc::Rc;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{
    ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy, OwnedDisplayHandle,
};
use winit::window::{Icon, Window, WindowId};

/// What a cached scene was rendered from: when it matches, the scene is reused.
#[derive(Debug, Clone, PartialEq)]
struct SceneKey {
    look: View,
    size: (u32, u32),
    level: Level,
    renderer: RendererKind,
    sampler: Sampler,
    index_step: IndexStep,
    lut: LutChoice,
    cube_renderer: CubeRenderer,
    heat_map: bool,
    /// Bilinear read from the pyramid level matching the footprint (while moving).
    bilinear_level: bool,
    map_generation: u64,
    lights: LightsKey,
    /// The illuminance map's generation, the room shown, the selected light.
    lit: (u64, bool, Option<usize>),
    /// Drawn from the lit panorama (when its bake arrives, the view is drawn from it).
    baked: bool,
}

/// Window, surface and egui-winit state: they exist between `resumed` and exit.
struct Gfx {
    window: Rc<Window>,
    surface: softbuffer::Surface<OwnedDisplayHandle, Rc<Window>>,
    egui_winit: egui_winit::State,
    surface_size: (u32, u32),
}

/// What other threads tell the event loop.
enum AppEvent {
    /// From the loading thread.
    Load(LoadEvent),
    /// The baking thread finished a lit panorama ([`LitPanorama`]).
    Baked,
}

struct App {
    print_view: bool,
    initial_size: (u32, u32),
    proxy: EventLoopProxy<AppEvent>,
    softbuffer: softbuffer::Context<OwnedDisplayHandle>,
    start: Instant,
    gfx: Option<Gfx>,
    egui_ctx: egui::Context,
    compositor: Compositor,
    ctl: Controller,
    /// What is shown and loading.
    doc: Document,
    /// Shortcut keys and the turn keys held.
    shortcuts: Shortcuts,
    /// Short messages over the scene.
    notices: Notices,
    /// The Open and Save dialogs.
    dialogs: Dialogs,
    /// Settings kept between runs (the panel shown, the zoom limit and recent files live
    /// here; the rest is copied from the controller before saving).
    prefs: Prefs,
    /// Where they are kept (`None`: nowhere to keep them).
    prefs_dir: Option<PathBuf>,
    /// What was last written there.
    prefs_saved: Prefs,
    prefs_saved_at: f64,
    /// The help overlay is shown.
    show_help: bool,
    /// The first-run hint was drawn (and reported with `--print-view`).
    hint_drawn: bool,
    /// The help overlay's rectangle and the scene's last printed with `--print-view`.
    help_printed: Option<(egui::Rect, egui::Rect)>,
    /// A menu was open at the last frame (printed with `--print-view` when it changes).
    menu_open: bool,
    /// The scene at its size; a degraded frame's lower-resolution render.
    scene: Vec<u32>,
    small: Vec<u32>,
    scene_key: Option<SceneKey>,
    /// The last render time of each quality level.
    times: FrameTimes,
    /// Width of the scene in pixels at the last frame (for the zoom limit).
    scene_width: u32,
    next_frame_at: Option<Instant>,
    /// When scenes were rendered in the last second (the fps readout).
    renders: VecDeque<Instant>,
    /// When the last frame was drawn, and the display's refresh interval.
    last_redraw: Option<Instant>,
    /// When freed heap memory was last given back (`super::heap`).
    last_trim: Instant,
    frame_interval: Duration,
    /// The readouts as last drawn (for the follow-up frame and `--print-view`).
    drawn_readouts: Vec<(&'static str, String)>,
    printed_readouts: String,
    /// The current panorama for the toolbar: name and size.
    title: String,
    fatal: Option<anyhow::Error>,
    /// The luminaires (panel state).
    lights: LightsState,
    /// Their illuminance map, rebuilt when they change.
    lit: LitCache,
    /// The panorama lit once the lighting has settled, panned as an unlit one.
    baked: LitPanorama,
    /// The inter-reflections and the work plane's figures, solved off the UI thread.
    solver: crate::lighting::Solver,
    /// A lighting report being written on a thread of its own: the line to show when
    /// it is done.
    report_job: Option<std::sync::mpsc::Receiver<Result<String, String>>>,
    /// What a drag in the view moves instead of the view (a luminaire, a room corner,
    /// an edge, or with Shift an edge's floor or ceiling).
    scene_drag: Option<SceneDrag>,
    /// The scene file opened or saved last.
    scene_file: Option<PathBuf>,
    /// The luminaires' marker positions as last printed (`--print-view`).
    printed_markers: String,
    /// The tour open, if any (`crate::window::tour`).
    tour: Option<super::tour::TourNav>,
    /// The tour's scene and hotspot positions as last printed (`--print-view`).
    printed_tour: String,
    /// The last `tour ui` line printed (`--print-view`).
    printed_tour_ui: String,
}

/// Open the window and run until it is closed.
pub fn run(args: OpenArgs, lights: LightsState) -> Result<()> {
    let input = &args.input;
    let event_loop = create_event_loop()?;
    let softbuffer = softbuffer::Context::new(event_loop.owned_display_handle())
        .map_err(|e| anyhow!("cannot use the display for software drawing: {e}"))?;
    let proxy = event_loop.create_proxy();
    // The baking thread wakes the event loop as the loading thread does (no polling).
    let wake_on_bake: crate::lighting::Wake = {
        let proxy = proxy.clone();
        std::sync::Arc::new(move || {
            let _ = proxy.send_event(AppEvent::Baked);
        })
    };
    let prefs_dir = super::prefs::config_dir();
    let mut notices = Notices::default();
    let mut prefs = match &prefs_dir {
        Some(d) => {
            let (p, msg) = Prefs::load(d);
            if let Some(m) = msg {
                crate::errln!("viewer: {m}");
                notices.error(m, 0.0);
            }
            p
        }
        None => Prefs::default(),
    };
    // `--cache-mib`: this run's budget, and the next runs' (saved with the settings: the
    // file as read differs, so the next save writes it).
    let prefs_saved = prefs.clone();
    if let Some(mib) = args.cache_mib {
        prefs.tile_cache_mib = mib;
    }
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
        shortcuts: Shortcuts::default(),
        notices,
        dialogs: Dialogs::new(),
        prefs_saved,
        prefs,
        prefs_dir,
        prefs_saved_at: 0.0,
        show_help: false,
        hint_drawn: false,
        help_printed: None,
        menu_open: false,
        scene: Vec::new(),
        small: Vec::new(),
        scene_key: None,
        times: FrameTimes::default(),
        scene_width: args.size.0,
        next_frame_at: None,
        renders: VecDeque::new(),
        last_redraw: None,
        last_trim: Instant::now(),
        frame_interval: Duration::from_secs_f64(super::input::DEFAULT_FRAME_S),
        drawn_readouts: Vec::new(),
        printed_readouts: String::new(),
        title: String::new(),
        fatal: None,
        lights,
        lit: LitCache::default(),
        solver: crate::lighting::Solver::start(wake_on_bake.clone()),
        report_job: None,
        baked: LitPanorama::new(rayon::current_num_threads(), wake_on_bake),
        scene_drag: None,
        scene_file: args.lights.room.scene.clone(),
        printed_markers: String::new(),
        tour: None,
        printed_tour: String::new(),
        printed_tour_ui: String::new(),
    };
    app.take_prefs();
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
    let start = StartArgs {
        yaw: args.yaw,
        pitch: args.pitch,
        hfov: args.hfov,
    };
    // A tour file: its first scene. A tour that does not open is shown as its error over
    // the bundled sample, as a missing or damaged panorama is (docs/reliability.md,
    // class 8: one behaviour).
    let source = match args.panorama.as_slice() {
        [one] if super::tour::is_tour(one) => match app.start_tour(one.clone()) {
            Ok(s) => Some(s),
            Err(e) => {
                app.tour_failed(&e);
                None
            }
        },
        _ => source,
    };
    let open = app.doc.open(
        source.unwrap_or(Source::Sample),
        input.coverage,
        start,
        app.ctl.settings.exposure_ev,
    );
    app.apply(vec![open]);
    event_loop
        .run_app(&mut app)
        .map_err(|e| anyhow!("the window's event loop failed: {e}"))?;
    app.save_prefs(true);
    match app.fatal {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Create the event loop, turning a missing display (an error, or a panic deep in a
/// platform backend) into a clear error.
fn create_event_loop() -> Result<EventLoop<AppEvent>> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let built = std::panic::catch_unwind(|| EventLoop::<AppEvent>::with_user_event().build());
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

    /// Seconds on the window's clock.
    fn now(&self) -> f64 {
        self.start.elapsed().as_secs_f64()
    }

    /// A frame is wanted: now, or at the next display refresh when the last frame was
    /// drawn less than one refresh ago (input events come faster than the display).
    fn want_frame(&mut self) {
        let at = self
            .last_redraw
            .map_or_else(Instant::now, |l| l + self.frame_interval);
        if at <= Instant::now() {
            self.request_redraw();
        } else {
            self.next_frame_at = Some(self.next_frame_at.map_or(at, |n| n.min(at)));
        }
    }

    /// The settings kept between runs into the controller.
    fn take_prefs(&mut self) {
        let p = &self.prefs;
        let s = &mut self.ctl.settings;
        s.aa = p.aa;
        s.sampler = p.sampler;
        s.drag = p.drag;
        s.inertia = p.inertia;
        s.export_scale = p.export_scale;
        self.ctl.auto_rotate = AutoRotate {
            enabled: p.auto_rotate,
            speed_deg_s: p.auto_rotate_speed,
            idle_s: p.auto_rotate_idle_s,
        };
    }

    /// The controller's settings into the kept ones; written when they changed (at most
    /// once a second unless `now`).
    fn save_prefs(&mut self, now: bool) {
        let s = self.ctl.settings;
        let a = self.ctl.auto_rotate;
        let p = &mut self.prefs;
        (p.aa, p.sampler, p.drag, p.inertia, p.export_scale) =
            (s.aa, s.sampler, s.drag, s.inertia, s.export_scale);
        (p.auto_rotate, p.auto_rotate_speed, p.auto_rotate_idle_s) =
            (a.enabled, a.speed_deg_s, a.idle_s);
        let t = self.now();
        if self.prefs == self.prefs_saved || (!now && t - self.prefs_saved_at < 1.0) {
            return;
        }
        let Some(dir) = &self.prefs_dir else {
            return;
        };
        self.prefs_saved_at = t;
        self.prefs_saved = self.prefs.clone();
        if let Err(e) = self.prefs.save(dir) {
            let m = format!("settings not saved: {e:#}");
            crate::errln!("viewer: {m}");
            self.notices.error(m, t);
        }
    }
}

impl ApplicationHandler<AppEvent> for App {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        let (w, h) = self.initial_size;
        let n = super::paint::ICON_SIZE;
        let attrs = Window::default_attributes()
            .with_title("viewer")
            .with_window_icon(Icon::from_rgba(super::paint::icon_rgba(), n, n).ok())
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
        // Animation and key turns at the display's refresh (60 Hz where unknown).
        let hz = window
            .current_monitor()
            .and_then(|m| m.refresh_rate_millihertz())
            .map(|mhz| f64::from(mhz) / 1000.0)
            .filter(|hz| (10.0..=1000.0).contains(hz))
            .unwrap_or(60.0);
        self.frame_interval = Duration::from_secs_f64(1.0 / hz);
        self.ctl.set_frame_interval(1.0 / hz);
        if self.print_view {
            let _ = crate::outln!("refresh {hz:.1} Hz");
        }
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

    fn user_event(&mut self, _el: &ActiveEventLoop, ev: AppEvent) {
        match ev {
            AppEvent::Load(ev) => {
                let fx = self.doc.on_event(ev, self.ctl.settings.exposure_ev);
                self.apply(fx);
            }
            // The next frame takes the bake (if it is still for the current lighting).
            AppEvent::Baked => self.request_redraw(),
        }
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
            WindowEvent::DroppedFile(path) if super::tour::is_tour(&path) => self.open_tour(path),
            WindowEvent::DroppedFile(path) => self.doc.drop_path(path),
            WindowEvent::Resized(_) | WindowEvent::ScaleFactorChanged { .. } => {
                g.window.request_redraw()
            }
            _ => {
                if response.repaint {
                    self.want_frame();
                }
            }
        }
    }

    fn about_to_wait(&mut self, el: &ActiveEventLoop) {
        if self.doc.has_drops() {
            let fx = self.doc.open_drops(self.ctl.settings.exposure_ev);
            self.apply(fx);
        }
        let now = Instant::now();
        // Freed heap memory back to the system once the window has settled (or every
        // few seconds while it keeps drawing): see `super::heap`.
        let mut trim_at = super::heap::next_trim(self.last_redraw, self.last_trim);
        if trim_at.is_some_and(|at| at <= now) {
            super::heap::give_back();
            self.last_trim = Instant::now();
            trim_at = None;
        }
        let wake = match self.next_frame_at {
            Some(at) if at <= now => {
                self.next_frame_at = None;
                self.request_redraw();
                // The redraw comes next; the trim waits for it to settle.
                None
            }
            Some(at) => Some(trim_at.map_or(at, |t| t.min(at))),
            None => trim_at,
        };
        el.set_control_flow(wake.map_or(ControlFlow::Wait, ControlFlow::WaitUntil));
    }
}

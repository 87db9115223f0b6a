//! Drag, wheel, keys and held buttons → the view. Pure: no window, no clock of its own.
//!
//! Time comes in as seconds (`t`, any origin) and positions as image-plane pixel
//! coordinates of the scene area (x right, y down, the conventions' pixel grid), so every
//! behaviour here is unit-tested without a display.
//!
//! * **Grab** drag (default): the world direction under the cursor when the button went
//!   down stays under the cursor; yaw and pitch are solved from it exactly
//!   ([`solve_grab`]). Optional inertia continues the last drag velocity after release.
//! * **QTVR** drag (the cubic-panorama paper, section 5 (1)): turning speed is
//!   proportional to the cursor's distance from where the button went down, and continues
//!   while the button is held.
//! * **Wheel** zooms by a factor per notch, using the size of the delta (one xdotool notch
//!   can arrive as two half events), toward the cursor: the direction under the cursor
//!   stays under it.
//! * **Held** keys and panel buttons turn or zoom at a steady rate (the paper's (2), (3)).
//! * **Anti-aliasing** ([`AaMode`]): in *Still only*, a frame whose view moves faster
//!   than [`FAST_HFOV_PER_S`] is rendered with nearest sampling; [`SETTLE_S`] after the
//!   motion stops one full-quality frame is due ([`Controller::wake_at`]).

use glam::DVec3;
use lut_core::{dir_to_lat_long, wrap_deg};
use lut_core::{
    Camera, CubeRenderer, IndexStep, LutChoice, Named, RenderOptions, RendererKind, Sampler, View,
};

/// Narrowest horizontal field of view the wheel and keys reach, degrees.
pub const HFOV_MIN: f64 = 1.0;
/// Widest horizontal field of view, degrees (rectilinear views stretch badly beyond).
pub const HFOV_MAX: f64 = 170.0;
/// hfov of the initial view and of a reset.
pub const HFOV_HOME: f64 = 90.0;
/// hfov is divided by this per wheel notch up (and per + key press).
pub const ZOOM_PER_NOTCH: f64 = 1.12;
/// Pixels of a pixel-precise wheel delta (touchpads) counted as one notch.
pub const PIXELS_PER_NOTCH: f64 = 50.0;
/// Held turn keys and buttons: angular speed in fields of view per second.
pub const TURN_HFOV_PER_S: f64 = 0.6;
/// Held zoom buttons: hfov halves (or doubles) in this many seconds.
pub const ZOOM_HALVING_S: f64 = 1.0;
/// QTVR: turning speed in fields of view per second per (cursor offset / scene width).
/// The cursor at the window's edge (offset W/2) turns one field of view per second.
pub const QTVR_GAIN: f64 = 2.0;
/// QTVR: offsets below this many pixels do not turn (a steady hand is not perfectly still).
pub const QTVR_DEAD_ZONE_PX: f64 = 3.0;
/// Inertia: velocity decays as exp(-INERTIA_DECAY · t).
pub const INERTIA_DECAY: f64 = 4.0;
/// Inertia stops below this speed, in fields of view per second.
pub const INERTIA_STOP_HFOV_PER_S: f64 = 0.02;
/// A view moving faster than this (fields of view per second) counts as "turning fast".
pub const FAST_HFOV_PER_S: f64 = 0.1;
/// After the last fast frame, the full-quality frame is due this many seconds later.
pub const SETTLE_S: f64 = 0.1;
/// Frame interval while something animates (held keys, QTVR, inertia), seconds.
pub const ANIMATION_FRAME_S: f64 = 1.0 / 60.0;
/// Longest time step applied by one tick (a stalled frame must not jump the view).
const MAX_TICK_S: f64 = 0.1;

/// The view as the user steers it, in degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Look {
    /// Yaw in (−180, 180].
    pub yaw: f64,
    /// Pitch in [−90, 90].
    pub pitch: f64,
    /// Horizontal field of view in [`HFOV_MIN`], [`HFOV_MAX`].
    pub hfov: f64,
}

impl Look {
    /// A look with its angles normalized and clamped.
    pub fn new(yaw: f64, pitch: f64, hfov: f64) -> Look {
        Look {
            yaw: wrap_deg(yaw),
            pitch: pitch.clamp(-90.0, 90.0),
            hfov: hfov.clamp(HFOV_MIN, HFOV_MAX),
        }
    }

    /// The lut-core view. A `Look` always holds finite, in-range angles, so this cannot
    /// fail; the fallback keeps it total anyway.
    pub fn view(&self) -> View {
        View::new(self.yaw, self.pitch, self.hfov).unwrap_or_default()
    }
}

impl Default for Look {
    fn default() -> Self {
        Look::new(0.0, 0.0, HFOV_HOME)
    }
}

/// How a mouse drag turns the view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DragStyle {
    /// The scene point under the cursor stays under the cursor (Pannellum).
    #[default]
    Grab,
    /// Turning speed proportional to the distance from the press point (QuickTime VR).
    Qtvr,
}

/// When to spend time on anti-aliasing (the paper's three modes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AaMode {
    /// Always the chosen sampler (trilinear by default) with index interpolation.
    Always,
    /// Nearest sampling while the view turns fast, full quality once it stops.
    #[default]
    StillOnly,
    /// Always nearest sampling.
    Off,
}

impl Named for DragStyle {
    const ALL: &'static [Self] = &[DragStyle::Grab, DragStyle::Qtvr];
    fn name(self) -> &'static str {
        match self {
            DragStyle::Grab => "grab",
            DragStyle::Qtvr => "QTVR",
        }
    }
    fn help(self) -> &'static str {
        match self {
            DragStyle::Grab => "The scene point under the cursor stays under the cursor",
            DragStyle::Qtvr => "Turning speed proportional to the distance from the press point",
        }
    }
}

/// The labels in the panel and docs.
impl Named for AaMode {
    const ALL: &'static [Self] = &[AaMode::Always, AaMode::StillOnly, AaMode::Off];
    fn name(self) -> &'static str {
        match self {
            AaMode::Always => "Always",
            AaMode::StillOnly => "Still only",
            AaMode::Off => "Off",
        }
    }
    fn help(self) -> &'static str {
        match self {
            AaMode::Always => "Always the chosen sampler",
            AaMode::StillOnly => {
                "Nearest sampling while the view turns fast, full quality once it stops"
            }
            AaMode::Off => "Always nearest sampling",
        }
    }
}

/// Everything the panel lets the user choose that affects motion or rendering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Drag style.
    pub drag: DragStyle,
    /// Keep turning after a grab drag is released.
    pub inertia: bool,
    /// Anti-aliasing mode.
    pub aa: AaMode,
    /// Sampler of full-quality frames.
    pub sampler: Sampler,
    /// LUT index step.
    pub index_step: IndexStep,
    /// LUT or exact renderer.
    pub renderer: RendererKind,
    /// Which LUT (auto by hfov, or forced).
    pub lut: LutChoice,
    /// Cube maps: the paper's basic (per pixel) or accelerated (per scanline) renderer.
    pub cube_renderer: CubeRenderer,
    /// HDR panoramas (`.hdr`, `.exr`): exposure in stops (`lut_core::Tone`).
    pub exposure_ev: f64,
    /// "Save view…": the export is the scene's size times this (1, 2 or 4).
    pub export_scale: u32,
    /// Partial panoramas: keep the view's edges inside the covered area.
    pub view_limit: bool,
}

impl Default for Settings {
    fn default() -> Self {
        let o = RenderOptions::default();
        Settings {
            drag: DragStyle::Grab,
            inertia: true,
            aa: AaMode::default(),
            // Trilinear: bilinear when zoomed in, anti-aliased from the pyramid when
            // zoomed out (built on the loader thread).
            sampler: Sampler::Trilinear,
            index_step: o.index_step,
            renderer: o.renderer,
            lut: o.lut,
            cube_renderer: CubeRenderer::Accelerated,
            exposure_ev: 0.0,
            export_scale: 1,
            view_limit: true,
        }
    }
}

impl Settings {
    /// The sampler of a frame: `fast` is true while the view turns fast.
    pub fn sampler_for(&self, fast: bool) -> Sampler {
        match self.aa {
            AaMode::Always => self.sampler,
            AaMode::StillOnly if fast => Sampler::Nearest,
            AaMode::StillOnly => self.sampler,
            AaMode::Off => Sampler::Nearest,
        }
    }

    /// Render options of a frame of a map or a cube map (the same options `viewer
    /// render` takes).
    pub fn render_options(&self, fast: bool) -> RenderOptions {
        RenderOptions {
            renderer: self.renderer,
            sampler: self.sampler_for(fast),
            index_step: self.index_step,
            lut: self.lut,
            threads: true,
            cube: self.cube_renderer,
            ..RenderOptions::default()
        }
    }
}

/// Turn and zoom inputs that act while held (keys and panel buttons together).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Held {
    /// Turn left (yaw decreases).
    pub left: bool,
    /// Turn right (yaw increases).
    pub right: bool,
    /// Look up.
    pub up: bool,
    /// Look down.
    pub down: bool,
    /// Zoom in (hfov decreases).
    pub zoom_in: bool,
    /// Zoom out.
    pub zoom_out: bool,
}

impl Held {
    /// True when any input is held.
    pub fn any(&self) -> bool {
        self.left || self.right || self.up || self.down || self.zoom_in || self.zoom_out
    }

    /// Union of two sets of held inputs.
    pub fn or(self, o: Held) -> Held {
        Held {
            left: self.left || o.left,
            right: self.right || o.right,
            up: self.up || o.up,
            down: self.down || o.down,
            zoom_in: self.zoom_in || o.zoom_in,
            zoom_out: self.zoom_out || o.zoom_out,
        }
    }
}

/// A direction of turning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Turn {
    /// Yaw decreases.
    Left,
    /// Yaw increases.
    Right,
    /// Pitch increases.
    Up,
    /// Pitch decreases.
    Down,
}

/// What a key does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KeyAction {
    /// Turn while held.
    Turn(Turn),
    /// One zoom step in.
    ZoomIn,
    /// One zoom step out.
    ZoomOut,
    /// Back to the initial view (the paper's RESIZE).
    Reset,
    /// Toggle fullscreen.
    ToggleFullscreen,
    /// Leave fullscreen.
    LeaveFullscreen,
    /// Show or hide the panel.
    TogglePanel,
    /// Close the window (Ctrl+Q or Ctrl+W).
    Quit,
    /// HDR panoramas: exposure down [`EXPOSURE_KEY_STEP_EV`] stops (`[`).
    ExposureDown,
    /// HDR panoramas: exposure up [`EXPOSURE_KEY_STEP_EV`] stops (`]`).
    ExposureUp,
    /// Save the current view as a PNG (`P`).
    SaveView,
}

/// Stops the `[` and `]` keys change the exposure of an HDR panorama by.
pub const EXPOSURE_KEY_STEP_EV: f64 = 0.5;

/// Exposure range of the panel slider and the `[` `]` keys, in stops.
pub const EXPOSURE_RANGE_EV: (f64, f64) = (-8.0, 8.0);

/// Scale factors the export offers: the scene's size times this.
pub const EXPORT_SCALES: [u32; 3] = [1, 2, 4];

/// The key bindings: arrows and WASD turn, + and − zoom (= too, so + works without
/// Shift), R resets, F toggles fullscreen, Esc leaves it, H or Tab toggles the panel,
/// Ctrl+Q or Ctrl+W closes the window, `[` and `]` change an HDR panorama's exposure by
/// half a stop, P saves the view as a PNG. Other Ctrl/Cmd combinations do nothing.
pub fn key_action(key: egui::Key, modifiers: egui::Modifiers) -> Option<KeyAction> {
    use egui::Key as K;
    if modifiers.command || modifiers.ctrl {
        return matches!(key, K::Q | K::W).then_some(KeyAction::Quit);
    }
    Some(match key {
        K::ArrowLeft | K::A => KeyAction::Turn(Turn::Left),
        K::ArrowRight | K::D => KeyAction::Turn(Turn::Right),
        K::ArrowUp | K::W => KeyAction::Turn(Turn::Up),
        K::ArrowDown | K::S => KeyAction::Turn(Turn::Down),
        K::Plus | K::Equals => KeyAction::ZoomIn,
        K::Minus => KeyAction::ZoomOut,
        K::R => KeyAction::Reset,
        K::F => KeyAction::ToggleFullscreen,
        K::Escape => KeyAction::LeaveFullscreen,
        K::H | K::Tab => KeyAction::TogglePanel,
        K::OpenBracket => KeyAction::ExposureDown,
        K::CloseBracket => KeyAction::ExposureUp,
        K::P => KeyAction::SaveView,
        _ => return None,
    })
}

/// Keys that turn while held, for polling their state each frame.
pub const TURN_KEYS: [egui::Key; 8] = [
    egui::Key::ArrowLeft,
    egui::Key::ArrowRight,
    egui::Key::ArrowUp,
    egui::Key::ArrowDown,
    egui::Key::A,
    egui::Key::D,
    egui::Key::W,
    egui::Key::S,
];

/// Wheel notches from one wheel event: line deltas are notches, pixel deltas are divided
/// by [`PIXELS_PER_NOTCH`], page deltas count ten notches a page. Positive = away from
/// the user = zoom in.
pub fn wheel_notches(unit: egui::MouseWheelUnit, delta_y: f32) -> f64 {
    let d = f64::from(delta_y);
    match unit {
        egui::MouseWheelUnit::Line => d,
        egui::MouseWheelUnit::Point => d / PIXELS_PER_NOTCH,
        egui::MouseWheelUnit::Page => d * 10.0,
    }
}

/// World direction (unit) through image-plane point `pos` of a `size` scene for `look`.
pub fn dir_at(look: &Look, pos: (f64, f64), size: (u32, u32)) -> DVec3 {
    Camera::new(look.view(), size.0.max(1), size.1.max(1))
        .world_ray(pos.0, pos.1)
        .normalize_or_zero()
}

/// Yaw and pitch (degrees) that put world direction `dir` at image-plane point `pos` of a
/// `size` scene with field of view `hfov`, pitch clamped to ±90°. Of the two exact
/// solutions the one nearer `prev_pitch` wins; when no pitch within ±90° reaches (a
/// direction near a pole under a cursor near the edge), the nearest one is taken.
pub fn solve_grab(
    dir: DVec3,
    pos: (f64, f64),
    size: (u32, u32),
    hfov: f64,
    prev_pitch: f64,
) -> (f64, f64) {
    let base = Look::new(0.0, 0.0, hfov);
    let cam = Camera::new(base.view(), size.0.max(1), size.1.max(1));
    let c = cam.camera_ray(pos.0, pos.1).normalize_or_zero();
    let d = dir.normalize_or_zero();
    // Pitching the camera ray c by p gives height c.y cos p + c.z sin p = R sin(α + p);
    // it must equal the target's height d.y (yaw does not change heights).
    let r = (c.y * c.y + c.z * c.z).sqrt();
    let alpha = c.y.atan2(c.z);
    let half_pi = std::f64::consts::FRAC_PI_2;
    let pitch = if r <= 1e-12 {
        prev_pitch.to_radians()
    } else if (d.y / r).abs() >= 1.0 {
        (half_pi.copysign(d.y) - alpha).clamp(-half_pi, half_pi)
    } else {
        let a = (d.y / r).asin();
        let cands = [a - alpha, std::f64::consts::PI - a - alpha].map(|p| {
            // Into (−π, π], then nearest legal pitch.
            let p = wrap_deg(p.to_degrees()).to_radians();
            (p, p.clamp(-half_pi, half_pi))
        });
        let prev = prev_pitch.to_radians();
        // Prefer exact solutions (p == clamped) and, among them, the one nearest `prev`.
        let score = |(p, q): (f64, f64)| (p - q).abs() * 1e3 + (q - prev).abs();
        if score(cands[0]) <= score(cands[1]) {
            cands[0].1
        } else {
            cands[1].1
        }
    };
    let (sp, cp) = pitch.sin_cos();
    let z1 = c.z * cp - c.y * sp;
    let (lambda_d, _) = dir_to_lat_long(d);
    let lambda_c = c.x.atan2(z1);
    let yaw = wrap_deg((lambda_d - lambda_c).to_degrees());
    (yaw, pitch.to_degrees())
}

/// A drag in progress.
#[derive(Debug, Clone, Copy)]
enum Drag {
    /// The world direction that stays under the cursor.
    Grab { dir: DVec3 },
    /// Press point and current cursor position.
    Qtvr {
        origin: (f64, f64),
        current: (f64, f64),
        width: f64,
    },
}

/// One frame's decision: what to show and whether it may be rendered cheaply.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// The view to render.
    pub look: Look,
    /// True while the view turns fast (Still-only mode renders it with nearest sampling).
    pub fast: bool,
}

/// The view state machine.
#[derive(Debug, Clone)]
pub struct Controller {
    look: Look,
    home: Look,
    /// Panel settings (drag style, inertia, AA mode, render options).
    pub settings: Settings,
    drag: Option<Drag>,
    held: Held,
    /// Inertia velocity, degrees per second (yaw, pitch).
    velocity: (f64, f64),
    /// Recent grab samples (t, unwrapped yaw, pitch) for the release velocity.
    samples: Vec<(f64, f64, f64)>,
    last_tick: Option<f64>,
    /// Time and look of the previous frame, for the speed measurement.
    prev_frame: Option<(f64, Look)>,
    fast_until: f64,
    last_frame_fast: bool,
    /// The view limit in force: the covered area and the scene size it holds for.
    limit: Option<(lut_core::Coverage, (u32, u32))>,
}

impl Controller {
    /// A controller starting (and resetting) at `home`.
    pub fn new(home: Look) -> Controller {
        Controller {
            look: home,
            home,
            settings: Settings::default(),
            drag: None,
            held: Held::default(),
            velocity: (0.0, 0.0),
            samples: Vec::new(),
            last_tick: None,
            prev_frame: None,
            fast_until: f64::NEG_INFINITY,
            last_frame_fast: false,
            limit: None,
        }
    }

    /// Keep every edge of a `size` scene inside `coverage` from now on (`None`: no
    /// limit), and pull the current view in at once (`lut_core::limit_view`).
    pub fn set_limit(&mut self, limit: Option<(lut_core::Coverage, (u32, u32))>) {
        self.limit = limit;
        self.apply_limit();
    }

    /// Apply the view limit; motion that ran into it stops in that direction.
    fn apply_limit(&mut self) {
        let Some((cov, (w, h))) = self.limit else {
            return;
        };
        if w == 0 || h == 0 {
            return;
        }
        let v = lut_core::limit_view(self.look.view(), w, h, &cov);
        let l = Look::new(v.yaw_deg(), v.pitch_deg(), v.hfov_deg());
        if l != self.look {
            if l.yaw != self.look.yaw {
                self.velocity.0 = 0.0;
            }
            if l.pitch != self.look.pitch {
                self.velocity.1 = 0.0;
            }
            self.look = l;
        }
    }

    /// The current view.
    pub fn look(&self) -> Look {
        self.look
    }

    /// True while a drag is in progress.
    pub fn dragging(&self) -> bool {
        self.drag.is_some()
    }

    /// The mouse button went down at `pos` in a `size` scene.
    pub fn press(&mut self, pos: (f64, f64), size: (u32, u32), t: f64) {
        self.velocity = (0.0, 0.0);
        self.samples.clear();
        self.drag = Some(match self.settings.drag {
            DragStyle::Grab => {
                self.samples.push((t, self.look.yaw, self.look.pitch));
                Drag::Grab {
                    dir: dir_at(&self.look, pos, size),
                }
            }
            DragStyle::Qtvr => {
                self.touch_tick(t);
                Drag::Qtvr {
                    origin: pos,
                    current: pos,
                    width: f64::from(size.0.max(1)),
                }
            }
        });
    }

    /// The cursor moved to `pos` with the button down.
    pub fn drag_to(&mut self, pos: (f64, f64), size: (u32, u32), t: f64) {
        match &mut self.drag {
            Some(Drag::Grab { dir }) => {
                let (yaw, pitch) = solve_grab(*dir, pos, size, self.look.hfov, self.look.pitch);
                let prev_yaw = self.samples.last().map_or(self.look.yaw, |s| s.1);
                let unwrapped = prev_yaw + wrap_deg(yaw - wrap_deg(prev_yaw));
                self.look = Look::new(yaw, pitch, self.look.hfov);
                self.samples.push((t, unwrapped, pitch));
                // Only the last 100 ms matter for the release velocity.
                let keep_from = self.samples.iter().position(|s| s.0 >= t - 0.1);
                if let Some(k) = keep_from {
                    self.samples.drain(..k.min(self.samples.len() - 1));
                }
            }
            Some(Drag::Qtvr { current, .. }) => *current = pos,
            None => {}
        }
    }

    /// The mouse button was released.
    pub fn release(&mut self, t: f64) {
        if let Some(Drag::Grab { .. }) = self.drag {
            self.velocity = (0.0, 0.0);
            if self.settings.inertia {
                if let (Some(first), Some(last)) = (self.samples.first(), self.samples.last()) {
                    let dt = last.0 - first.0;
                    // A pause before release means the user stopped: no throw.
                    if dt > 0.01 && t - last.0 < 0.05 {
                        self.velocity = ((last.1 - first.1) / dt, (last.2 - first.2) / dt);
                        self.last_tick = Some(t);
                    }
                }
            }
        }
        self.samples.clear();
        self.drag = None;
    }

    /// Wheel turned by `notches` (positive zooms in) with the cursor at `cursor` (`None`:
    /// zoom about the center).
    pub fn wheel(&mut self, notches: f64, cursor: Option<(f64, f64)>, size: (u32, u32)) {
        let hfov = self.look.hfov / ZOOM_PER_NOTCH.powf(notches);
        self.zoom_to(hfov, cursor, size);
    }

    /// Set hfov (clamped), keeping the direction under `cursor` where it is.
    pub fn zoom_to(&mut self, hfov: f64, cursor: Option<(f64, f64)>, size: (u32, u32)) {
        let hfov = hfov.clamp(HFOV_MIN, HFOV_MAX);
        if hfov == self.look.hfov {
            return;
        }
        match cursor {
            Some(pos) => {
                let dir = dir_at(&self.look, pos, size);
                let (yaw, pitch) = solve_grab(dir, pos, size, hfov, self.look.pitch);
                self.look = Look::new(yaw, pitch, hfov);
                // A grab in progress keeps its point under the cursor at the new zoom.
            }
            None => self.look = Look::new(self.look.yaw, self.look.pitch, hfov),
        }
    }

    /// A discrete key action that changes the view (the others are the window's).
    pub fn key(&mut self, action: KeyAction) {
        let size = (1, 1);
        match action {
            KeyAction::ZoomIn => self.zoom_to(self.look.hfov / ZOOM_PER_NOTCH, None, size),
            KeyAction::ZoomOut => self.zoom_to(self.look.hfov * ZOOM_PER_NOTCH, None, size),
            KeyAction::Reset => {
                self.look = self.home;
                self.velocity = (0.0, 0.0);
            }
            _ => {}
        }
    }

    /// The keys and buttons held during this frame.
    pub fn set_held(&mut self, held: Held, t: f64) {
        if held.any() && !self.held.any() {
            self.touch_tick(t);
        }
        self.held = held;
    }

    /// True while the view changes without further input (held keys or buttons, a QTVR
    /// drag off its press point, inertia).
    pub fn animating(&self) -> bool {
        self.held.any() || self.qtvr_rate().is_some() || self.velocity != (0.0, 0.0)
    }

    /// QTVR turning rate (deg/s yaw, pitch) when the cursor is off the press point.
    fn qtvr_rate(&self) -> Option<(f64, f64)> {
        let Some(Drag::Qtvr {
            origin,
            current,
            width,
        }) = self.drag
        else {
            return None;
        };
        let (dx, dy) = (current.0 - origin.0, current.1 - origin.1);
        if dx.hypot(dy) < QTVR_DEAD_ZONE_PX {
            return None;
        }
        let k = QTVR_GAIN * self.look.hfov / width;
        // Cursor right of the press point turns right; above it, looks up.
        Some((k * dx, -k * dy))
    }

    fn touch_tick(&mut self, t: f64) {
        if !self.animating() {
            self.last_tick = Some(t);
        }
    }

    /// Advance continuous motion to time `t`. Returns true when the view changed.
    pub fn tick(&mut self, t: f64) -> bool {
        let dt = match self.last_tick {
            Some(t0) => (t - t0).clamp(0.0, MAX_TICK_S),
            None => 0.0,
        };
        self.last_tick = Some(t);
        if dt == 0.0 {
            return false;
        }
        let before = self.look;
        let mut yaw_rate = 0.0;
        let mut pitch_rate = 0.0;
        let turn = TURN_HFOV_PER_S * self.look.hfov;
        let h = self.held;
        yaw_rate += turn * (f64::from(u8::from(h.right)) - f64::from(u8::from(h.left)));
        pitch_rate += turn * (f64::from(u8::from(h.up)) - f64::from(u8::from(h.down)));
        if let Some((y, p)) = self.qtvr_rate() {
            yaw_rate += y;
            pitch_rate += p;
        }
        if self.velocity != (0.0, 0.0) && self.drag.is_none() {
            yaw_rate += self.velocity.0;
            pitch_rate += self.velocity.1;
            let decay = (-INERTIA_DECAY * dt).exp();
            self.velocity = (self.velocity.0 * decay, self.velocity.1 * decay);
            let speed = self.velocity.0.hypot(self.velocity.1);
            if speed < INERTIA_STOP_HFOV_PER_S * self.look.hfov {
                self.velocity = (0.0, 0.0);
            }
        }
        let zoom = f64::from(u8::from(h.zoom_out)) - f64::from(u8::from(h.zoom_in));
        let hfov = self.look.hfov * (zoom * dt * std::f64::consts::LN_2 / ZOOM_HALVING_S).exp();
        let pitch = self.look.pitch + pitch_rate * dt;
        if pitch.abs() >= 90.0 {
            // At the pole, throwing further up does nothing: drop the vertical inertia.
            self.velocity.1 = 0.0;
        }
        self.look = Look::new(self.look.yaw + yaw_rate * dt, pitch, hfov);
        self.look != before
    }

    /// Decide frame `t`: advance continuous motion, measure how fast the view moves and
    /// whether this frame may be rendered cheaply.
    pub fn frame(&mut self, t: f64) -> Frame {
        self.tick(t);
        self.apply_limit();
        if let Some((t0, prev)) = self.prev_frame {
            let dt = t - t0;
            if dt > 0.0 && prev != self.look {
                let cos_p = self.look.pitch.to_radians().cos();
                let dyaw = wrap_deg(self.look.yaw - prev.yaw) * cos_p;
                let dpitch = self.look.pitch - prev.pitch;
                let dzoom = (self.look.hfov / prev.hfov).ln().abs() * self.look.hfov;
                let speed = (dyaw.hypot(dpitch) + dzoom) / dt;
                if speed > FAST_HFOV_PER_S * self.look.hfov {
                    self.fast_until = t + SETTLE_S;
                }
            }
        }
        self.prev_frame = Some((t, self.look));
        let fast = t < self.fast_until;
        self.last_frame_fast = fast && self.settings.aa == AaMode::StillOnly;
        Frame {
            look: self.look,
            fast,
        }
    }

    /// When the next frame is due without new input: the next animation frame, or the
    /// full-quality frame after fast motion stopped; `None` when nothing is pending.
    pub fn wake_at(&self) -> Option<f64> {
        let last = self.prev_frame.map(|(t, _)| t);
        if self.animating() {
            return Some(last.map_or(0.0, |t| t + ANIMATION_FRAME_S));
        }
        if self.last_frame_fast {
            return Some(self.fast_until);
        }
        None
    }
}

impl Default for Controller {
    fn default() -> Self {
        Controller::new(Look::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: (u32, u32) = (800, 500);
    const CENTER: (f64, f64) = (400.0, 250.0);

    fn close(a: f64, b: f64, eps: f64, what: &str) {
        assert!((a - b).abs() <= eps, "{what}: {a} vs {b} (eps {eps})");
    }

    /// Where the world direction `dir` appears in the scene for `look`.
    fn screen_pos(look: &Look, dir: DVec3) -> (f64, f64) {
        Camera::new(look.view(), SIZE.0, SIZE.1)
            .project(dir)
            .expect("direction in front of the camera")
    }

    /// Drive a drag from `from` to `to` in `steps` motion events at 60 Hz starting at `t0`.
    fn drag(c: &mut Controller, from: (f64, f64), to: (f64, f64), steps: u32, t0: f64) -> f64 {
        c.press(from, SIZE, t0);
        let mut t = t0;
        for i in 1..=steps {
            t = t0 + f64::from(i) / 60.0;
            let f = f64::from(i) / f64::from(steps);
            let p = (from.0 + (to.0 - from.0) * f, from.1 + (to.1 - from.1) * f);
            c.drag_to(p, SIZE, t);
            c.frame(t);
        }
        t
    }

    #[test]
    fn grab_keeps_the_grabbed_point_under_the_cursor() {
        for &(yaw, pitch, hfov) in &[(0.0, 0.0, 90.0), (170.0, 40.0, 60.0), (-30.0, -70.0, 120.0)] {
            for &(from, to) in &[
                ((400.0, 250.0), (500.0, 250.0)),
                ((100.0, 50.0), (700.0, 400.0)),
                ((600.0, 450.0), (300.0, 100.0)),
            ] {
                let mut c = Controller::new(Look::new(yaw, pitch, hfov));
                let start = c.look();
                let dir = dir_at(&start, from, SIZE);
                drag(&mut c, from, to, 10, 0.0);
                let l = c.look();
                assert!(l.pitch.abs() <= 90.0);
                if l.pitch.abs() < 89.999 {
                    let p = screen_pos(&l, dir);
                    close(p.0, to.0, 1e-6, "x under cursor");
                    close(p.1, to.1, 1e-6, "y under cursor");
                }
            }
        }
    }

    #[test]
    fn grab_signs_drag_right_turns_left_drag_down_looks_up() {
        let mut c = Controller::default();
        drag(&mut c, CENTER, (CENTER.0 + 100.0, CENTER.1), 5, 0.0);
        assert!(c.look().yaw < -5.0, "yaw {}", c.look().yaw);
        close(
            c.look().pitch,
            0.0,
            1e-9,
            "pitch unchanged by a horizontal drag at the horizon",
        );
        let mut c = Controller::default();
        drag(&mut c, CENTER, (CENTER.0, CENTER.1 + 100.0), 5, 0.0);
        assert!(c.look().pitch > 5.0, "pitch {}", c.look().pitch);
        close(
            c.look().yaw,
            0.0,
            1e-9,
            "yaw unchanged by a vertical drag at the center",
        );
        // A horizontal drag at the center moves yaw by exactly the angle between the rays.
        let mut c = Controller::default();
        drag(&mut c, CENTER, (CENTER.0 + 400.0, CENTER.1), 3, 0.0);
        close(
            c.look().yaw,
            -45.0,
            1e-9,
            "edge of a 90° view to the center",
        );
    }

    #[test]
    fn grab_pitch_stays_within_90() {
        let mut c = Controller::new(Look::new(0.0, 80.0, 100.0));
        drag(&mut c, (400.0, 0.0), (400.0, 499.0), 20, 0.0);
        assert!(c.look().pitch <= 90.0 && c.look().pitch >= -90.0);
        close(c.look().pitch, 90.0, 1e-9, "clamped at the zenith");
        let mut c = Controller::new(Look::new(0.0, -80.0, 100.0));
        drag(&mut c, (400.0, 499.0), (400.0, 0.0), 20, 0.0);
        close(c.look().pitch, -90.0, 1e-9, "clamped at the nadir");
    }

    #[test]
    fn qtvr_speed_is_proportional_to_distance_and_continues_while_held() {
        let mut c = Controller::default();
        c.settings.drag = DragStyle::Qtvr;
        c.frame(0.0);
        c.press(CENTER, SIZE, 0.0);
        c.drag_to((CENTER.0 + 100.0, CENTER.1), SIZE, 0.0);
        assert!(c.animating());
        let mut t = 0.0;
        for _ in 0..60 {
            t += 1.0 / 60.0;
            c.frame(t);
        }
        // 1 s at QTVR_GAIN · hfov · dx / width degrees per second.
        let expect = QTVR_GAIN * 90.0 * 100.0 / 800.0;
        close(c.look().yaw, expect, 1e-6, "one second of turning right");
        // Twice the distance, twice the speed; above the press point looks up.
        c.drag_to((CENTER.0, CENTER.1 - 200.0), SIZE, t);
        let y0 = c.look().yaw;
        for _ in 0..30 {
            t += 1.0 / 60.0;
            c.frame(t);
        }
        close(
            c.look().yaw,
            y0,
            1e-9,
            "no horizontal offset, no yaw change",
        );
        close(
            c.look().pitch,
            expect,
            1e-6,
            "half a second at twice the speed",
        );
        // Release stops it at once; QTVR has no inertia.
        c.release(t);
        assert!(!c.animating());
        let l = c.look();
        c.frame(t + 0.5);
        assert_eq!(c.look(), l);
    }

    #[test]
    fn qtvr_dead_zone() {
        let mut c = Controller::default();
        c.settings.drag = DragStyle::Qtvr;
        c.press(CENTER, SIZE, 0.0);
        c.drag_to((CENTER.0 + 2.0, CENTER.1 + 1.0), SIZE, 0.0);
        assert!(!c.animating());
        c.frame(1.0);
        assert_eq!(c.look(), Look::default());
    }

    #[test]
    fn wheel_zooms_by_delta_size_within_limits() {
        let mut a = Controller::default();
        a.wheel(1.0, None, SIZE);
        close(a.look().hfov, 90.0 / ZOOM_PER_NOTCH, 1e-12, "one notch in");
        // One notch delivered as two half events (xdotool) zooms the same.
        let mut b = Controller::default();
        b.wheel(0.5, None, SIZE);
        b.wheel(0.5, None, SIZE);
        close(
            b.look().hfov,
            a.look().hfov,
            1e-12,
            "two halves = one notch",
        );
        a.wheel(-2.0, None, SIZE);
        close(
            a.look().hfov,
            90.0 * ZOOM_PER_NOTCH,
            1e-12,
            "two notches out",
        );
        for _ in 0..200 {
            a.wheel(1.0, None, SIZE);
        }
        assert_eq!(a.look().hfov, HFOV_MIN);
        for _ in 0..200 {
            a.wheel(-1.0, None, SIZE);
        }
        assert_eq!(a.look().hfov, HFOV_MAX);
        assert_eq!(wheel_notches(egui::MouseWheelUnit::Line, 1.0), 1.0);
        assert_eq!(wheel_notches(egui::MouseWheelUnit::Point, -50.0), -1.0);
    }

    #[test]
    fn wheel_zooms_toward_the_cursor() {
        let mut c = Controller::new(Look::new(20.0, 10.0, 90.0));
        let cursor = (650.0, 120.0);
        let dir = dir_at(&c.look(), cursor, SIZE);
        c.wheel(3.0, Some(cursor), SIZE);
        assert!(c.look().hfov < 90.0);
        let p = screen_pos(&c.look(), dir);
        close(p.0, cursor.0, 1e-6, "x stays under the cursor");
        close(p.1, cursor.1, 1e-6, "y stays under the cursor");
        // Zooming in toward a point right of and above the center turns right and up.
        assert!(c.look().yaw > 20.0 && c.look().pitch > 10.0);
    }

    #[test]
    fn wheel_crosses_the_lut_switch() {
        let map =
            lut_core::grid_map(256, 128, lut_core::Projection::Equirect).expect("synthetic map");
        let mut r = lut_core::Renderer::new(&map);
        let (w, h) = (64, 40);
        let mut out = vec![0u32; w * h];
        let mut c = Controller::default();
        let mut paths = Vec::new();
        // Zoom in notch by notch from 90° to well below the switch.
        while c.look().hfov > 40.0 {
            let opts = c.settings.render_options(false);
            let report = r
                .render(
                    lut_core::Scene::Map(&map),
                    c.look().view(),
                    &opts,
                    &mut lut_core::Frame::new(&mut out, w as u32, h as u32).expect("frame"),
                )
                .expect("render");
            let want = if c.look().hfov > lut_core::LUT_SWITCH_HFOV {
                lut_core::RenderPath::LutWide
            } else {
                lut_core::RenderPath::LutHigh
            };
            assert_eq!(report.path, want, "hfov {}", c.look().hfov);
            paths.push(report.path);
            c.wheel(1.0, None, (w as u32, h as u32));
        }
        assert!(paths.contains(&lut_core::RenderPath::LutWide));
        assert!(paths.contains(&lut_core::RenderPath::LutHigh));
    }

    #[test]
    fn still_only_renders_nearest_while_fast_then_one_full_frame() {
        let mut c = Controller::default();
        c.settings.aa = AaMode::StillOnly;
        c.frame(0.0);
        // A fast drag: 300 px in 0.25 s.
        c.press(CENTER, SIZE, 0.0);
        let mut t = 0.0;
        for i in 1..=15 {
            t = f64::from(i) / 60.0;
            c.drag_to((CENTER.0 + 20.0 * f64::from(i), CENTER.1), SIZE, t);
            let f = c.frame(t);
            assert!(f.fast, "frame at {t} is fast");
            assert_eq!(c.settings.sampler_for(f.fast), Sampler::Nearest);
        }
        c.release(t + 0.2); // paused before release: no inertia
                            // Nothing moves now; a full-quality frame is due within ~150 ms.
        let due = c.wake_at().expect("a full-quality frame is pending");
        assert!(due > t && due <= t + 0.15, "due {due}, stopped at {t}");
        let f = c.frame(due);
        assert!(!f.fast);
        assert_eq!(c.settings.sampler_for(f.fast), Sampler::Trilinear);
        // Exactly one: after it, nothing is pending.
        assert_eq!(c.wake_at(), None);
    }

    #[test]
    fn slow_motion_stays_full_quality_and_modes_always_off() {
        let mut c = Controller::default();
        c.frame(0.0);
        c.press(CENTER, SIZE, 0.0);
        // Half a pixel per frame at 60 Hz: about 0.05 fields of view per second, below
        // the threshold.
        for i in 1..=30 {
            let t = f64::from(i) / 60.0;
            c.drag_to((CENTER.0 + 0.5 * f64::from(i), CENTER.1), SIZE, t);
            assert!(!c.frame(t).fast);
        }
        let s = Settings {
            aa: AaMode::Always,
            ..Settings::default()
        };
        assert_eq!(s.sampler_for(true), Sampler::Trilinear);
        let s = Settings {
            aa: AaMode::Off,
            ..Settings::default()
        };
        assert_eq!(s.sampler_for(false), Sampler::Nearest);
        // Always and Off never schedule a refinement frame.
        let mut c = Controller::default();
        c.settings.aa = AaMode::Always;
        c.frame(0.0);
        c.press(CENTER, SIZE, 0.0);
        c.drag_to((CENTER.0 + 300.0, CENTER.1), SIZE, 0.05);
        assert!(c.frame(0.05).fast);
        c.release(0.5);
        assert_eq!(c.wake_at(), None);
    }

    #[test]
    fn key_bindings() {
        use egui::Key as K;
        let cases = [
            (K::ArrowLeft, KeyAction::Turn(Turn::Left)),
            (K::A, KeyAction::Turn(Turn::Left)),
            (K::ArrowRight, KeyAction::Turn(Turn::Right)),
            (K::D, KeyAction::Turn(Turn::Right)),
            (K::ArrowUp, KeyAction::Turn(Turn::Up)),
            (K::W, KeyAction::Turn(Turn::Up)),
            (K::ArrowDown, KeyAction::Turn(Turn::Down)),
            (K::S, KeyAction::Turn(Turn::Down)),
            (K::Plus, KeyAction::ZoomIn),
            (K::Equals, KeyAction::ZoomIn),
            (K::Minus, KeyAction::ZoomOut),
            (K::R, KeyAction::Reset),
            (K::F, KeyAction::ToggleFullscreen),
            (K::Escape, KeyAction::LeaveFullscreen),
            (K::H, KeyAction::TogglePanel),
            (K::Tab, KeyAction::TogglePanel),
            (K::OpenBracket, KeyAction::ExposureDown),
            (K::CloseBracket, KeyAction::ExposureUp),
            (K::P, KeyAction::SaveView),
        ];
        let none = egui::Modifiers::NONE;
        for (k, a) in cases {
            assert_eq!(key_action(k, none), Some(a), "{k:?}");
        }
        assert_eq!(key_action(K::Q, none), None);
        assert_eq!(key_action(K::Space, none), None);
        for k in TURN_KEYS {
            assert!(matches!(key_action(k, none), Some(KeyAction::Turn(_))));
        }
        let ctrl = egui::Modifiers::CTRL;
        assert_eq!(key_action(K::Q, ctrl), Some(KeyAction::Quit));
        assert_eq!(key_action(K::W, ctrl), Some(KeyAction::Quit));
        assert_eq!(key_action(K::A, ctrl), None, "Ctrl+A does not turn");
    }

    #[test]
    fn held_turns_at_a_steady_speed_and_reset_restores() {
        let mut c = Controller::default();
        c.frame(0.0);
        c.set_held(
            Held {
                right: true,
                ..Held::default()
            },
            0.0,
        );
        for i in 1..=60 {
            c.frame(f64::from(i) / 60.0);
        }
        close(
            c.look().yaw,
            TURN_HFOV_PER_S * 90.0,
            1e-9,
            "one second right",
        );
        c.set_held(
            Held {
                up: true,
                ..Held::default()
            },
            1.0,
        );
        // Long enough to pass the zenith: pitch clamps at 90.
        for i in 61..=600 {
            c.frame(f64::from(i) / 60.0);
        }
        assert_eq!(c.look().pitch, 90.0);
        c.set_held(Held::default(), 10.0);
        assert!(!c.animating());
        c.key(KeyAction::ZoomIn);
        close(c.look().hfov, 90.0 / ZOOM_PER_NOTCH, 1e-12, "+ key");
        c.key(KeyAction::Reset);
        assert_eq!(c.look(), Look::default());
    }

    #[test]
    fn view_limit_holds_against_keys_zoom_and_reset() {
        // 100° x 50° across the seam (yaw 130 to -130), a 200x100 scene
        let cov = lut_core::Coverage::new(100.0, 50.0, 180.0, 0.0).unwrap();
        let size = (200, 100);
        let inside = |c: &Controller| lut_core::view_inside(c.look().view(), 200, 100, &cov);
        let mut c = Controller::default();
        c.set_limit(Some((cov, size)));
        // the home view (yaw 0, hfov 90) cannot fit: pulled in, narrowed
        assert!(inside(&c), "{:?}", c.look());
        assert!(c.look().hfov < 90.0);
        c.frame(0.0);
        for held in [
            Held {
                right: true,
                ..Held::default()
            },
            Held {
                up: true,
                ..Held::default()
            },
            Held {
                left: true,
                down: true,
                ..Held::default()
            },
            Held {
                zoom_out: true,
                ..Held::default()
            },
        ] {
            c.set_held(held, 0.0);
            for i in 1..=300 {
                c.frame(f64::from(i) / 60.0);
                assert!(inside(&c), "{held:?} frame {i}: {:?}", c.look());
            }
            c.set_held(Held::default(), 5.0);
            c.frame(0.0);
        }
        c.key(KeyAction::Reset);
        c.frame(6.0);
        assert!(inside(&c));
        // switched off: the view may leave
        c.set_limit(None);
        c.key(KeyAction::Reset);
        c.frame(7.0);
        assert_eq!(c.look(), Look::default());
    }

    #[test]
    fn held_zoom_buttons_and_clamping() {
        let mut c = Controller::default();
        c.frame(0.0);
        c.set_held(
            Held {
                zoom_in: true,
                ..Held::default()
            },
            0.0,
        );
        for i in 1..=60 {
            c.frame(f64::from(i) / 60.0);
        }
        close(c.look().hfov, 45.0, 1e-9, "halved in one second");
        for i in 61..=1200 {
            c.frame(f64::from(i) / 60.0);
        }
        assert_eq!(c.look().hfov, HFOV_MIN);
        // A stalled frame does not jump the view by more than MAX_TICK_S of motion.
        let mut c = Controller::default();
        c.frame(0.0);
        c.set_held(
            Held {
                right: true,
                ..Held::default()
            },
            0.0,
        );
        c.frame(100.0);
        close(
            c.look().yaw,
            TURN_HFOV_PER_S * 90.0 * MAX_TICK_S,
            1e-9,
            "stall",
        );
        let big = Look::new(725.0, -200.0, 500.0);
        assert_eq!(big, Look::new(5.0, -90.0, HFOV_MAX));
    }

    #[test]
    fn grab_inertia_continues_then_stops() {
        let mut c = Controller::default();
        c.frame(0.0);
        let t = drag(&mut c, CENTER, (CENTER.0 - 200.0, CENTER.1), 10, 0.0);
        c.release(t);
        assert!(c.animating(), "thrown");
        let y0 = c.look().yaw;
        c.frame(t + 1.0 / 60.0);
        assert!(
            c.look().yaw > y0,
            "keeps turning right after a leftward drag"
        );
        let mut tt = t;
        for _ in 0..600 {
            tt += 1.0 / 60.0;
            c.frame(tt);
        }
        assert!(!c.animating(), "inertia stops");
        // Without inertia: no throw.
        let mut c = Controller::default();
        c.settings.inertia = false;
        let t = drag(&mut c, CENTER, (CENTER.0 - 200.0, CENTER.1), 10, 0.0);
        c.release(t);
        assert!(!c.animating());
    }

    #[test]
    fn solve_grab_at_the_pole_is_finite() {
        let dir = DVec3::Y;
        for pos in [CENTER, (0.0, 0.0), (799.0, 499.0)] {
            let (y, p) = solve_grab(dir, pos, SIZE, 90.0, 0.0);
            assert!(y.is_finite() && p.is_finite() && p.abs() <= 90.0);
        }
    }
}

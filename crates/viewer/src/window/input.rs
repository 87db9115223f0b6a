//! Drag, wheel, keys and held buttons → the view. Pure: no window, no clock of its own.
//!
//! Time comes in as seconds (`t`, any origin) and positions as image-plane pixel
//! coordinates of the scene area (x right, y down, the conventions' pixel grid), so every
//! behaviour here is unit-tested without a display.
//!
//! * **Grab** drag (default): the world direction under the cursor when the button went
//!   down stays under the cursor; yaw and pitch are solved from it exactly
//!   ([`solve_grab`]). Optional inertia continues the last drag velocity after release
//!   and stops within about a second ([`INERTIA_DECAY`]).
//! * **QTVR** drag (the cubic-panorama paper, section 5 (1)): turning speed is
//!   proportional to the cursor's distance from where the button went down, and continues
//!   while the button is held.
//! * **Wheel** zooms by a factor per notch, using the size of the delta (one xdotool notch
//!   can arrive as two half events), toward the cursor: the direction under the cursor
//!   stays under it. A **double-click** zooms in twice toward the point, animated.
//! * **Held** keys and panel buttons turn or zoom at a steady rate (the paper's (2), (3)).
//! * **Zoom range** ([`Controller::set_zoom_range`]): the window keeps hfov between the
//!   map's resolution limit and the widest view.
//! * **Auto-rotate** ([`AutoRotate`]): turns at a steady speed after an idle delay; any
//!   input stops it until the delay has passed again.
//! * **Speed**: a frame whose view moves faster than [`FAST_HFOV_PER_S`] is "fast" (the
//!   window may render it cheaper, `quality.rs`); [`SETTLE_S`] after the motion stops
//!   one full-quality frame is due ([`Controller::wake_at`]) when the last was degraded.

use super::keys::KeyAction;
use super::quality::Settings;
use glam::DVec3;
use lut_core::{wrap_deg, Named, View, ViewProjection};

mod grab;
mod projection;
pub use grab::{dir_at, resolution_hfov, solve_grab, solve_grab_in};
pub use projection::{widest_hfov, PLANET_HFOV, PLANET_S, WIDE_HFOV_MAX};

/// Narrowest horizontal field of view the wheel and keys reach, degrees.
pub const HFOV_MIN: f64 = 1.0;
/// Widest horizontal field of view of a rectilinear view, degrees (they stretch badly
/// beyond); the wide projections go further ([`widest_hfov`]).
pub const HFOV_MAX: f64 = 170.0;
/// hfov of the default start view.
pub const HFOV_HOME: f64 = 90.0;
/// hfov is divided by this per wheel notch up (and per + key press).
pub const ZOOM_PER_NOTCH: f64 = 1.12;
/// A double-click divides hfov by this.
pub const DOUBLE_CLICK_ZOOM: f64 = 2.0;
/// The double-click zoom's animation, seconds.
pub const DOUBLE_CLICK_S: f64 = 0.25;
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
/// Inertia: velocity decays as exp(-INERTIA_DECAY · t). With the stop speed and the
/// speed cap below, the fastest throw stops within a second, as Pannellum's does (its
/// friction 0.15 per 60 Hz frame); a typical flick coasts a third to half a field of view.
pub const INERTIA_DECAY: f64 = 6.0;
/// Inertia stops below this speed, in fields of view per second.
pub const INERTIA_STOP_HFOV_PER_S: f64 = 0.05;
/// A throw is capped at this speed, in fields of view per second.
pub const INERTIA_MAX_HFOV_PER_S: f64 = 8.0;
/// A view moving faster than this (fields of view per second) counts as "turning fast".
pub const FAST_HFOV_PER_S: f64 = 0.1;
/// After the last fast frame, the full-quality frame is due this many seconds later.
pub const SETTLE_S: f64 = 0.1;
/// Frame interval while something animates where the display's refresh rate is unknown.
pub const DEFAULT_FRAME_S: f64 = 1.0 / 60.0;
/// Longest time step applied by one tick (a stalled frame must not jump the view).
const MAX_TICK_S: f64 = 0.1;

/// Exposure range of the panel slider and the `[` `]` keys, in stops.
pub const EXPOSURE_RANGE_EV: (f64, f64) = (-8.0, 8.0);

/// Scale factors the export offers: the scene's size times this.
pub const EXPORT_SCALES: [u32; 3] = [1, 2, 4];

/// The view as the window steers it: `lut_core`'s [`View`] with the window's hfov range
/// ([`HFOV_MIN`] to the projection's [`widest_hfov`], narrower than [`View::clamped_in`]'s;
/// a NaN hfov is [`HFOV_HOME`]), then [`View::clamped_in`]'s wrapping and clamping of the
/// angles (NaN included). Every view the window holds is made here or by [`moved`].
pub fn steer(yaw: f64, pitch: f64, hfov: f64, projection: ViewProjection) -> View {
    let hfov = if hfov.is_nan() { HFOV_HOME } else { hfov };
    let hfov = hfov.clamp(HFOV_MIN, widest_hfov(projection));
    View::clamped_in(yaw, pitch, hfov, projection)
}

/// `view`'s projection at another yaw, pitch and hfov, as [`steer`] makes it.
pub fn moved(view: View, yaw: f64, pitch: f64, hfov: f64) -> View {
    steer(yaw, pitch, hfov, view.projection())
}

/// The rectilinear view [`steer`] makes: the start views of files and tours.
pub fn steer_rect(yaw: f64, pitch: f64, hfov: f64) -> View {
    steer(yaw, pitch, hfov, ViewProjection::Rectilinear)
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

/// Auto-rotation: a steady turn after the user has left the view alone for a while.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutoRotate {
    /// On or off.
    pub enabled: bool,
    /// Degrees per second; positive turns right.
    pub speed_deg_s: f64,
    /// Seconds without input before it starts (again).
    pub idle_s: f64,
}

impl Default for AutoRotate {
    fn default() -> Self {
        AutoRotate {
            enabled: false,
            speed_deg_s: 5.0,
            idle_s: 3.0,
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

/// An animated zoom toward a point (double-click).
#[derive(Debug, Clone, Copy)]
struct ZoomAnim {
    dir: DVec3,
    pos: (f64, f64),
    size: (u32, u32),
    from: f64,
    to: f64,
    t0: f64,
}

/// One frame's decision: what to show and whether it may be rendered cheaply.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// The view to render.
    pub look: View,
    /// True while the view turns fast (the window may render it cheaper).
    pub fast: bool,
}

/// The view state machine.
#[derive(Debug, Clone)]
pub struct Controller {
    look: View,
    home: View,
    /// Panel settings (drag style, inertia, AA mode, render options).
    pub settings: Settings,
    /// Auto-rotation settings.
    pub auto_rotate: AutoRotate,
    drag: Option<Drag>,
    held: Held,
    /// Inertia velocity, degrees per second (yaw, pitch).
    velocity: (f64, f64),
    /// Recent grab samples (t, unwrapped yaw, pitch) for the release velocity.
    samples: Vec<(f64, f64, f64)>,
    last_tick: Option<f64>,
    /// Time and look of the previous frame, for the speed measurement.
    prev_frame: Option<(f64, View)>,
    fast_until: f64,
    /// The last frame was rendered below full quality because the view moved.
    degraded: bool,
    /// The view limit in force: the covered area and the scene size it holds for.
    limit: Option<(lut_core::Coverage, (u32, u32))>,
    /// hfov range: the map's resolution limit and the widest view.
    zoom_range: (f64, f64),
    /// A zoom out was stopped at the widest view (the hook for wide projections).
    zoomed_past_widest: bool,
    /// A zoom in was stopped at the narrowest view (the window says why).
    zoomed_past_narrowest: bool,
    /// The hfov a change of the zoom range narrowed or widened the view from (a
    /// fullscreen's wider limit): the view returns to it once the range allows again;
    /// any zoom by the user forgets it.
    wanted_hfov: Option<f64>,
    zoom_anim: Option<ZoomAnim>,
    /// Frame interval while animating (the display's refresh).
    frame_s: f64,
    /// Time of the last user input (auto-rotation waits for the idle delay after it).
    last_input: f64,
    /// Auto-rotation is turning the view now.
    rotating: bool,
    /// The little planet (`projection.rs`): the look to return to and the transition.
    planet: Option<projection::Planet>,
}

impl Controller {
    /// A controller starting (and resetting) at `home`.
    pub fn new(home: View) -> Controller {
        Controller {
            look: home,
            home,
            settings: Settings::default(),
            auto_rotate: AutoRotate::default(),
            drag: None,
            held: Held::default(),
            velocity: (0.0, 0.0),
            samples: Vec::new(),
            last_tick: None,
            prev_frame: None,
            fast_until: f64::NEG_INFINITY,
            degraded: false,
            limit: None,
            zoom_range: (HFOV_MIN, HFOV_MAX),
            zoomed_past_widest: false,
            zoomed_past_narrowest: false,
            wanted_hfov: None,
            zoom_anim: None,
            frame_s: DEFAULT_FRAME_S,
            last_input: f64::NEG_INFINITY,
            rotating: false,
            planet: None,
        }
    }

    /// A new panorama: `home` is its start view; the view goes there and every motion
    /// stops.
    pub fn set_home(&mut self, home: View) {
        self.home = home;
        self.velocity = (0.0, 0.0);
        self.zoom_anim = None;
        // A jump to another panorama is not motion: no speed is measured across it.
        self.prev_frame = None;
        // The projection the user picked stays (a little planet's return view goes).
        self.planet = None;
        self.wanted_hfov = None;
        self.look = moved(
            self.look,
            home.yaw_deg(),
            home.pitch_deg(),
            self.clamp_hfov(home.hfov_deg()),
        );
        self.apply_limit();
    }

    /// The start view the view resets to.
    pub fn home(&self) -> View {
        self.home
    }

    /// Animation frames come every `seconds` (the display's refresh interval).
    pub fn set_frame_interval(&mut self, seconds: f64) {
        if seconds.is_finite() && seconds > 0.0 {
            self.frame_s = seconds;
        }
    }

    /// Keep hfov within `min`..=`max` from now on (the map's resolution limit and the
    /// widest view; the projection's [`widest_hfov`] holds too; the start view's hfov is
    /// always within reach), and pull the current view in at once. A view pulled in
    /// returns to its hfov when a later range allows it again (leaving fullscreen).
    pub fn set_zoom_range(&mut self, min: f64, max: f64) {
        let max = max.clamp(HFOV_MIN, WIDE_HFOV_MAX);
        let min = min.clamp(HFOV_MIN, max);
        self.zoom_range = (min, max);
        let want = self.wanted_hfov.unwrap_or(self.look.hfov_deg());
        let h = self.clamp_hfov(want);
        self.wanted_hfov = (h != want).then_some(want);
        if h != self.look.hfov_deg() {
            self.look = moved(self.look, self.look.yaw_deg(), self.look.pitch_deg(), h);
        }
    }

    /// The hfov range in force.
    pub fn zoom_range(&self) -> (f64, f64) {
        (self.narrowest(), self.widest())
    }

    /// True (once) when a zoom in was stopped at the narrowest view since the last call.
    pub fn take_zoomed_past_narrowest(&mut self) -> bool {
        std::mem::take(&mut self.zoomed_past_narrowest)
    }

    /// True (once) when a zoom out was stopped at the widest view since the last call:
    /// where the window hands over to wide output projections.
    pub fn take_zoomed_past_widest(&mut self) -> bool {
        std::mem::take(&mut self.zoomed_past_widest)
    }

    fn clamp_hfov(&self, hfov: f64) -> f64 {
        hfov.clamp(self.narrowest(), self.widest())
    }

    /// The narrowest hfov now: the zoom range's, or the start view's when narrower (a
    /// file's start view is shown whatever the map's resolution), at most the widest.
    fn narrowest(&self) -> f64 {
        self.zoom_range
            .0
            .min(self.home.hfov_deg().max(HFOV_MIN))
            .min(self.widest())
    }

    /// The widest hfov now: the zoom range's, at most the projection's [`widest_hfov`].
    fn widest(&self) -> f64 {
        self.zoom_range.1.min(widest_hfov(self.look.projection()))
    }

    /// Keep every edge of a `size` scene inside `coverage` from now on (`None`: no
    /// limit), and pull the current view in at once (`lut_core::limit_view`).
    pub fn set_limit(&mut self, limit: Option<(lut_core::Coverage, (u32, u32))>) {
        self.limit = limit;
        self.apply_limit();
    }

    /// Apply the view limit; motion that ran into it stops in that direction (and
    /// auto-rotation turns back).
    fn apply_limit(&mut self) {
        let Some((cov, (w, h))) = self.limit else {
            return;
        };
        // The limit is a rectilinear frame's (wide projections show the background).
        if w == 0 || h == 0 || !self.look.projection().is_rectilinear() {
            return;
        }
        let v = lut_core::limit_view(self.look, w, h, &cov);
        let l = moved(self.look, v.yaw_deg(), v.pitch_deg(), v.hfov_deg());
        if l != self.look {
            if l.yaw_deg() != self.look.yaw_deg() {
                self.velocity.0 = 0.0;
                if self.rotating {
                    self.auto_rotate.speed_deg_s = -self.auto_rotate.speed_deg_s;
                }
            }
            if l.pitch_deg() != self.look.pitch_deg() {
                self.velocity.1 = 0.0;
            }
            self.look = l;
        }
    }

    /// The current view.
    pub fn look(&self) -> View {
        self.look
    }

    /// True while a drag is in progress.
    pub fn dragging(&self) -> bool {
        self.drag.is_some()
    }

    /// Auto-rotation switched on by the user at time `t` (Space, the panel): it turns at
    /// once, without the idle delay.
    pub fn start_rotation(&mut self, t: f64) {
        self.auto_rotate.enabled = true;
        self.touch_tick(t);
        self.rotating = true;
    }

    /// The user did something at time `t` (a press, a key, the wheel): auto-rotation
    /// stops until the idle delay has passed again, and a zoom animation ends.
    pub fn interacted(&mut self, t: f64) {
        self.last_input = t;
        self.rotating = false;
        self.zoom_anim = None;
        self.finish_planet_transition();
    }

    /// The mouse button went down at `pos` in a `size` scene.
    pub fn press(&mut self, pos: (f64, f64), size: (u32, u32), t: f64) {
        self.interacted(t);
        self.velocity = (0.0, 0.0);
        self.samples.clear();
        self.drag = Some(match self.settings.drag {
            DragStyle::Grab => {
                self.samples
                    .push((t, self.look.yaw_deg(), self.look.pitch_deg()));
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
        self.last_input = t;
        match &mut self.drag {
            Some(Drag::Grab { dir }) => {
                let Some((yaw, pitch)) =
                    solve_grab_in(*dir, pos, size, self.look, self.look.pitch_deg())
                else {
                    return;
                };
                let prev_yaw = self.samples.last().map_or(self.look.yaw_deg(), |s| s.1);
                let unwrapped = prev_yaw + wrap_deg(yaw - wrap_deg(prev_yaw));
                self.look = moved(self.look, yaw, pitch, self.look.hfov_deg());
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
        self.last_input = t;
        if let Some(Drag::Grab { .. }) = self.drag {
            self.velocity = (0.0, 0.0);
            if self.settings.inertia {
                if let (Some(first), Some(last)) = (self.samples.first(), self.samples.last()) {
                    let dt = last.0 - first.0;
                    // A pause before release means the user stopped: no throw.
                    if dt > 0.01 && t - last.0 < 0.05 {
                        let v = ((last.1 - first.1) / dt, (last.2 - first.2) / dt);
                        let max = INERTIA_MAX_HFOV_PER_S * self.look.hfov_deg();
                        let k = (max / v.0.hypot(v.1)).min(1.0);
                        self.velocity = (v.0 * k, v.1 * k);
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
        let hfov = self.look.hfov_deg() / ZOOM_PER_NOTCH.powf(notches);
        self.zoom_to(hfov, cursor, size);
    }

    /// A double-click at `pos` of a `size` scene at time `t`: zoom in by
    /// [`DOUBLE_CLICK_ZOOM`] toward the point over [`DOUBLE_CLICK_S`].
    pub fn double_click(&mut self, pos: (f64, f64), size: (u32, u32), t: f64) {
        self.interacted(t);
        self.velocity = (0.0, 0.0);
        self.wanted_hfov = None;
        let to = self.clamp_hfov(self.look.hfov_deg() / DOUBLE_CLICK_ZOOM);
        if to >= self.look.hfov_deg() {
            self.zoomed_past_narrowest = true;
        }
        if to < self.look.hfov_deg() {
            self.zoom_anim = Some(ZoomAnim {
                dir: dir_at(&self.look, pos, size),
                pos,
                size,
                from: self.look.hfov_deg(),
                to,
                t0: t,
            });
            self.touch_tick(t);
        }
    }

    /// Set hfov (clamped to the zoom range), keeping the direction under `cursor` where
    /// it is.
    pub fn zoom_to(&mut self, hfov: f64, cursor: Option<(f64, f64)>, size: (u32, u32)) {
        if hfov > self.widest() && self.look.hfov_deg() >= self.widest() {
            self.zoomed_past_widest = true;
        }
        if hfov < self.narrowest() && self.look.hfov_deg() <= self.narrowest() {
            self.zoomed_past_narrowest = true;
        }
        self.wanted_hfov = None;
        let hfov = self.clamp_hfov(hfov);
        if hfov == self.look.hfov_deg() {
            return;
        }
        match cursor {
            Some(pos) => {
                let dir = dir_at(&self.look, pos, size);
                let to = moved(self.look, self.look.yaw_deg(), self.look.pitch_deg(), hfov);
                self.look = match solve_grab_in(dir, pos, size, to, self.look.pitch_deg()) {
                    Some((yaw, pitch)) => moved(to, yaw, pitch, hfov),
                    // No direction under the cursor: zoom about the centre.
                    None => to,
                };
                // A grab in progress keeps its point under the cursor at the new zoom.
            }
            None => self.look = moved(self.look, self.look.yaw_deg(), self.look.pitch_deg(), hfov),
        }
    }

    /// A discrete key action that changes the view (the others are the window's).
    pub fn key(&mut self, action: KeyAction) {
        let size = (1, 1);
        match action {
            KeyAction::ZoomIn => self.zoom_to(self.look.hfov_deg() / ZOOM_PER_NOTCH, None, size),
            KeyAction::ZoomOut => self.zoom_to(self.look.hfov_deg() * ZOOM_PER_NOTCH, None, size),
            KeyAction::Reset => {
                // The start view in the projection in use.
                let h = self.home;
                self.planet = None;
                self.wanted_hfov = None;
                self.look = moved(
                    self.look,
                    h.yaw_deg(),
                    h.pitch_deg(),
                    self.clamp_hfov(h.hfov_deg()),
                );
                self.velocity = (0.0, 0.0);
                self.zoom_anim = None;
            }
            _ => {}
        }
    }

    /// The keys and buttons held during this frame.
    pub fn set_held(&mut self, held: Held, t: f64) {
        if held.any() {
            if !self.held.any() {
                self.touch_tick(t);
            }
            self.interacted(t);
        }
        self.held = held;
    }

    /// True while the view changes without further input (held keys or buttons, a QTVR
    /// drag off its press point, inertia, a zoom animation, auto-rotation).
    pub fn animating(&self) -> bool {
        self.held.any()
            || self.qtvr_rate().is_some()
            || self.velocity != (0.0, 0.0)
            || self.zoom_anim.is_some()
            || self.rotating
            || self.planet_moving()
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
        let k = QTVR_GAIN * self.look.hfov_deg() / width;
        // Cursor right of the press point turns right; above it, looks up.
        Some((k * dx, -k * dy))
    }

    fn touch_tick(&mut self, t: f64) {
        if !self.animating() {
            self.last_tick = Some(t);
        }
    }

    /// When auto-rotation starts (again), if it is on and not turning yet.
    fn rotation_due(&self) -> Option<f64> {
        let idle = self.drag.is_none() && !self.held.any() && self.velocity == (0.0, 0.0);
        (self.auto_rotate.enabled && !self.rotating && idle && self.zoom_anim.is_none())
            .then(|| self.last_input + self.auto_rotate.idle_s.max(0.0))
    }

    /// Advance continuous motion to time `t`. Returns true when the view changed.
    pub fn tick(&mut self, t: f64) -> bool {
        if !self.auto_rotate.enabled {
            self.rotating = false;
        } else if self.rotation_due().is_some_and(|at| t >= at) {
            self.touch_tick(t);
            self.rotating = true;
        }
        let dt = match self.last_tick {
            Some(t0) => (t - t0).clamp(0.0, MAX_TICK_S),
            None => 0.0,
        };
        self.last_tick = Some(t);
        let before = self.look;
        self.step_planet(t);
        if let Some(z) = self.zoom_anim {
            // Ease in and out, geometric in hfov, the grabbed point fixed under the cursor.
            let p = ((t - z.t0) / DOUBLE_CLICK_S).clamp(0.0, 1.0);
            let e = p * p * (3.0 - 2.0 * p);
            let hfov = z.from * (z.to / z.from).powf(e);
            let to = moved(self.look, self.look.yaw_deg(), self.look.pitch_deg(), hfov);
            self.look = solve_grab_in(z.dir, z.pos, z.size, to, self.look.pitch_deg())
                .map_or(to, |(yaw, pitch)| moved(to, yaw, pitch, hfov));
            if p >= 1.0 {
                self.zoom_anim = None;
            }
        }
        if dt == 0.0 {
            return self.look != before;
        }
        let mut yaw_rate = 0.0;
        let mut pitch_rate = 0.0;
        let turn = TURN_HFOV_PER_S * self.look.hfov_deg();
        let h = self.held;
        yaw_rate += turn * (f64::from(u8::from(h.right)) - f64::from(u8::from(h.left)));
        pitch_rate += turn * (f64::from(u8::from(h.up)) - f64::from(u8::from(h.down)));
        if let Some((y, p)) = self.qtvr_rate() {
            yaw_rate += y;
            pitch_rate += p;
        }
        if self.rotating {
            yaw_rate += self.auto_rotate.speed_deg_s;
        }
        if self.velocity != (0.0, 0.0) && self.drag.is_none() {
            yaw_rate += self.velocity.0;
            pitch_rate += self.velocity.1;
            let decay = (-INERTIA_DECAY * dt).exp();
            self.velocity = (self.velocity.0 * decay, self.velocity.1 * decay);
            let speed = self.velocity.0.hypot(self.velocity.1);
            if speed < INERTIA_STOP_HFOV_PER_S * self.look.hfov_deg() {
                self.velocity = (0.0, 0.0);
            }
        }
        let zoom = f64::from(u8::from(h.zoom_out)) - f64::from(u8::from(h.zoom_in));
        let hfov =
            self.look.hfov_deg() * (zoom * dt * std::f64::consts::LN_2 / ZOOM_HALVING_S).exp();
        if hfov > self.widest() && h.zoom_out {
            self.zoomed_past_widest = true;
        }
        if hfov < self.narrowest() && h.zoom_in {
            self.zoomed_past_narrowest = true;
        }
        if h.zoom_in || h.zoom_out {
            self.wanted_hfov = None;
        }
        let pitch = self.look.pitch_deg() + pitch_rate * dt;
        if pitch.abs() >= 90.0 {
            // At the pole, throwing further up does nothing: drop the vertical inertia.
            self.velocity.1 = 0.0;
        }
        self.look = moved(
            self.look,
            self.look.yaw_deg() + yaw_rate * dt,
            pitch,
            self.clamp_hfov(hfov),
        );
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
                let cos_p = self.look.pitch_deg().to_radians().cos();
                let dyaw = wrap_deg(self.look.yaw_deg() - prev.yaw_deg()) * cos_p;
                let dpitch = self.look.pitch_deg() - prev.pitch_deg();
                let dzoom =
                    (self.look.hfov_deg() / prev.hfov_deg()).ln().abs() * self.look.hfov_deg();
                let speed = (dyaw.hypot(dpitch) + dzoom) / dt;
                if speed > FAST_HFOV_PER_S * self.look.hfov_deg() {
                    self.fast_until = t + SETTLE_S;
                }
            }
        }
        self.prev_frame = Some((t, self.look));
        Frame {
            look: self.look,
            fast: t < self.fast_until,
        }
    }

    /// The window rendered the last frame below the quality a still view gets
    /// (`degraded`): a full-quality frame is due once the view settles.
    pub fn rendered(&mut self, degraded: bool) {
        self.degraded = degraded;
    }

    /// When the next frame is due without new input: the next animation frame, the
    /// full-quality frame after degraded motion, or the start of auto-rotation; `None`
    /// when nothing is pending.
    pub fn wake_at(&self) -> Option<f64> {
        let last = self.prev_frame.map(|(t, _)| t);
        if self.animating() {
            return Some(last.map_or(0.0, |t| t + self.frame_s));
        }
        let refine = self.degraded.then_some(self.fast_until);
        match (refine, self.rotation_due()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

impl Default for Controller {
    fn default() -> Self {
        Controller::new(View::default())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::window::quality::{frame_level, AaMode, FrameTimes, Level, FRAME_BUDGET_MS};
    use lut_core::Camera;
    use lut_core::Sampler;

    const SIZE: (u32, u32) = (800, 500);
    const CENTER: (f64, f64) = (400.0, 250.0);

    fn close(a: f64, b: f64, eps: f64, what: &str) {
        assert!((a - b).abs() <= eps, "{what}: {a} vs {b} (eps {eps})");
    }

    /// Where the world direction `dir` appears in the scene for `look`.
    fn screen_pos(look: &View, dir: DVec3) -> (f64, f64) {
        Camera::new(*look, SIZE.0, SIZE.1)
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

    /// Hold `held` from `t0` for `frames` frames at 60 Hz.
    fn hold(c: &mut Controller, held: Held, t0: f64, frames: u32) {
        c.set_held(held, t0);
        for i in 1..=frames {
            c.frame(t0 + f64::from(i) / 60.0);
        }
    }

    #[test]
    fn grab_keeps_the_grabbed_point_under_the_cursor() {
        for &(yaw, pitch, hfov) in &[(0.0, 0.0, 90.0), (170.0, 40.0, 60.0), (-30.0, -70.0, 120.0)] {
            for &(from, to) in &[
                ((400.0, 250.0), (500.0, 250.0)),
                ((100.0, 50.0), (700.0, 400.0)),
                ((600.0, 450.0), (300.0, 100.0)),
            ] {
                let mut c = Controller::new(steer_rect(yaw, pitch, hfov));
                let start = c.look();
                let dir = dir_at(&start, from, SIZE);
                drag(&mut c, from, to, 10, 0.0);
                let l = c.look();
                assert!(l.pitch_deg().abs() <= 90.0);
                if l.pitch_deg().abs() < 89.999 {
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
        assert!(c.look().yaw_deg() < -5.0, "yaw {}", c.look().yaw_deg());
        close(
            c.look().pitch_deg(),
            0.0,
            1e-9,
            "pitch unchanged by a horizontal drag at the horizon",
        );
        let mut c = Controller::default();
        drag(&mut c, CENTER, (CENTER.0, CENTER.1 + 100.0), 5, 0.0);
        assert!(c.look().pitch_deg() > 5.0, "pitch {}", c.look().pitch_deg());
        close(
            c.look().yaw_deg(),
            0.0,
            1e-9,
            "yaw unchanged by a vertical drag at the center",
        );
        // A horizontal drag at the center moves yaw by exactly the angle between the rays.
        let mut c = Controller::default();
        drag(&mut c, CENTER, (CENTER.0 + 400.0, CENTER.1), 3, 0.0);
        close(
            c.look().yaw_deg(),
            -45.0,
            1e-9,
            "edge of a 90° view to the center",
        );
    }

    #[test]
    fn grab_pitch_stays_within_90() {
        let mut c = Controller::new(steer_rect(0.0, 80.0, 100.0));
        drag(&mut c, (400.0, 0.0), (400.0, 499.0), 20, 0.0);
        assert!(c.look().pitch_deg() <= 90.0 && c.look().pitch_deg() >= -90.0);
        close(c.look().pitch_deg(), 90.0, 1e-9, "clamped at the zenith");
        let mut c = Controller::new(steer_rect(0.0, -80.0, 100.0));
        drag(&mut c, (400.0, 499.0), (400.0, 0.0), 20, 0.0);
        close(c.look().pitch_deg(), -90.0, 1e-9, "clamped at the nadir");
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
        close(
            c.look().yaw_deg(),
            expect,
            1e-6,
            "one second of turning right",
        );
        // Twice the distance, twice the speed; above the press point looks up.
        c.drag_to((CENTER.0, CENTER.1 - 200.0), SIZE, t);
        let y0 = c.look().yaw_deg();
        for _ in 0..30 {
            t += 1.0 / 60.0;
            c.frame(t);
        }
        close(
            c.look().yaw_deg(),
            y0,
            1e-9,
            "no horizontal offset, no yaw change",
        );
        close(
            c.look().pitch_deg(),
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
        assert_eq!(c.look(), View::default());
    }

    #[test]
    fn wheel_zooms_by_delta_size_within_limits() {
        let mut a = Controller::default();
        a.wheel(1.0, None, SIZE);
        close(
            a.look().hfov_deg(),
            90.0 / ZOOM_PER_NOTCH,
            1e-12,
            "one notch in",
        );
        // One notch delivered as two half events (xdotool) zooms the same.
        let mut b = Controller::default();
        b.wheel(0.5, None, SIZE);
        b.wheel(0.5, None, SIZE);
        close(
            b.look().hfov_deg(),
            a.look().hfov_deg(),
            1e-12,
            "two halves = one notch",
        );
        a.wheel(-2.0, None, SIZE);
        close(
            a.look().hfov_deg(),
            90.0 * ZOOM_PER_NOTCH,
            1e-12,
            "two notches out",
        );
        for _ in 0..200 {
            a.wheel(1.0, None, SIZE);
        }
        assert_eq!(a.look().hfov_deg(), HFOV_MIN);
        for _ in 0..200 {
            a.wheel(-1.0, None, SIZE);
        }
        assert_eq!(a.look().hfov_deg(), HFOV_MAX);
        assert_eq!(wheel_notches(egui::MouseWheelUnit::Line, 1.0), 1.0);
        assert_eq!(wheel_notches(egui::MouseWheelUnit::Point, -50.0), -1.0);
    }

    #[test]
    fn wheel_zooms_toward_the_cursor() {
        let mut c = Controller::new(steer_rect(20.0, 10.0, 90.0));
        let cursor = (650.0, 120.0);
        let dir = dir_at(&c.look(), cursor, SIZE);
        c.wheel(3.0, Some(cursor), SIZE);
        assert!(c.look().hfov_deg() < 90.0);
        let p = screen_pos(&c.look(), dir);
        close(p.0, cursor.0, 1e-6, "x stays under the cursor");
        close(p.1, cursor.1, 1e-6, "y stays under the cursor");
        // Zooming in toward a point right of and above the center turns right and up.
        assert!(c.look().yaw_deg() > 20.0 && c.look().pitch_deg() > 10.0);
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
        while c.look().hfov_deg() > 40.0 {
            let opts = c.settings.render_options(Level::Full);
            let report = r
                .render(
                    &map,
                    c.look(),
                    &opts,
                    &mut lut_core::Frame::new(&mut out, w as u32, h as u32).expect("frame"),
                )
                .expect("render");
            let want = if c.look().hfov_deg() > lut_core::LUT_SWITCH_HFOV {
                lut_core::RenderPath::LutWide
            } else {
                lut_core::RenderPath::LutHigh
            };
            assert_eq!(report.path, want, "hfov {}", c.look().hfov_deg());
            paths.push(report.path);
            c.wheel(1.0, None, (w as u32, h as u32));
        }
        assert!(paths.contains(&lut_core::RenderPath::LutWide));
        assert!(paths.contains(&lut_core::RenderPath::LutHigh));
    }

    /// What the window does with a frame: pick its level and tell the controller
    /// whether a full-quality frame is still owed; the sampler it rendered with.
    fn render(c: &mut Controller, f: Frame, times: &FrameTimes) -> Sampler {
        let px = u64::from(SIZE.0) * u64::from(SIZE.1);
        let (level, degraded) = frame_level(c.settings.aa, f.fast, times, px, FRAME_BUDGET_MS);
        c.rendered(degraded);
        level.sampler(c.settings.sampler)
    }

    #[test]
    fn still_only_renders_nearest_while_fast_then_one_full_frame() {
        let mut c = Controller::default();
        c.settings.aa = AaMode::StillOnly;
        let times = FrameTimes::default();
        c.frame(0.0);
        // A fast drag: 300 px in 0.25 s.
        c.press(CENTER, SIZE, 0.0);
        let mut t = 0.0;
        for i in 1..=15 {
            t = f64::from(i) / 60.0;
            c.drag_to((CENTER.0 + 20.0 * f64::from(i), CENTER.1), SIZE, t);
            let f = c.frame(t);
            assert!(f.fast, "frame at {t} is fast");
            assert_eq!(render(&mut c, f, &times), Sampler::Nearest);
        }
        c.release(t + 0.2); // paused before release: no inertia
                            // Nothing moves now; a full-quality frame is due within ~150 ms.
        let due = c.wake_at().expect("a full-quality frame is pending");
        assert!(due > t && due <= t + 0.15, "due {due}, stopped at {t}");
        let f = c.frame(due);
        assert!(!f.fast);
        assert_eq!(render(&mut c, f, &times), Sampler::Trilinear);
        // Exactly one: after it, nothing is pending.
        assert_eq!(c.wake_at(), None);
    }

    #[test]
    fn adaptive_moves_at_full_quality_when_it_fits_and_owes_nothing_after() {
        let mut c = Controller::default();
        assert_eq!(c.settings.aa, AaMode::Adaptive);
        let mut times = FrameTimes::default();
        times.record(Level::Full, 7.0, u64::from(SIZE.0 * SIZE.1));
        c.frame(0.0);
        c.press(CENTER, SIZE, 0.0);
        let mut t = 0.0;
        for i in 1..=15 {
            t = f64::from(i) / 60.0;
            c.drag_to((CENTER.0 + 20.0 * f64::from(i), CENTER.1), SIZE, t);
            let f = c.frame(t);
            assert!(f.fast);
            assert_eq!(render(&mut c, f, &times), Sampler::Trilinear, "no pop");
        }
        c.release(t + 0.2);
        assert_eq!(c.wake_at(), None, "the last frame was already full quality");
        // A full frame over the budget: moving frames degrade, then one full frame.
        times.record(Level::Full, 40.0, u64::from(SIZE.0 * SIZE.1));
        c.press(CENTER, SIZE, t + 0.3);
        c.drag_to((CENTER.0 - 100.0, CENTER.1), SIZE, t + 0.32);
        let f = c.frame(t + 0.32);
        assert!(f.fast);
        assert_ne!(render(&mut c, f, &times), Sampler::Trilinear);
        c.release(t + 0.6);
        let due = c.wake_at().expect("a full-quality frame is owed");
        let f = c.frame(due);
        assert_eq!(render(&mut c, f, &times), Sampler::Trilinear);
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
        for aa in [AaMode::Always, AaMode::Off] {
            let mut c = Controller::default();
            c.settings.aa = aa;
            c.frame(0.0);
            c.press(CENTER, SIZE, 0.0);
            c.drag_to((CENTER.0 + 300.0, CENTER.1), SIZE, 0.05);
            let f = c.frame(0.05);
            assert!(f.fast);
            render(&mut c, f, &FrameTimes::default());
            c.release(0.5);
            assert_eq!(c.wake_at(), None, "{aa:?}");
        }
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
            c.look().yaw_deg(),
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
        assert_eq!(c.look().pitch_deg(), 90.0);
        c.set_held(Held::default(), 10.0);
        assert!(!c.animating());
        c.key(KeyAction::ZoomIn);
        close(c.look().hfov_deg(), 90.0 / ZOOM_PER_NOTCH, 1e-12, "+ key");
        c.key(KeyAction::Reset);
        assert_eq!(c.look(), View::default());
    }

    #[test]
    fn view_limit_holds_against_keys_zoom_and_reset() {
        // 100° x 50° across the seam (yaw 130 to -130), a 200x100 scene
        let cov = lut_core::Coverage::new(100.0, 50.0, 180.0, 0.0).unwrap();
        let size = (200, 100);
        let inside = |c: &Controller| lut_core::view_inside(c.look(), 200, 100, &cov);
        let mut c = Controller::default();
        c.set_limit(Some((cov, size)));
        // the home view (yaw 0, hfov 90) cannot fit: pulled in, narrowed
        assert!(inside(&c), "{:?}", c.look());
        assert!(c.look().hfov_deg() < 90.0);
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
        assert_eq!(c.look(), View::default());
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
        close(c.look().hfov_deg(), 45.0, 1e-9, "halved in one second");
        for i in 61..=1200 {
            c.frame(f64::from(i) / 60.0);
        }
        assert_eq!(c.look().hfov_deg(), HFOV_MIN);
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
            c.look().yaw_deg(),
            TURN_HFOV_PER_S * 90.0 * MAX_TICK_S,
            1e-9,
            "stall",
        );
        let big = steer_rect(725.0, -200.0, 500.0);
        assert_eq!(
            (big.yaw_deg(), big.pitch_deg(), big.hfov_deg()),
            (5.0, -90.0, HFOV_MAX)
        );
        // The window's hfov range is narrower than View::clamped's.
        assert!(View::clamped(0.0, 0.0, 0.5).hfov_deg() < HFOV_MIN);
        assert_eq!(steer_rect(0.0, 0.0, 0.5).hfov_deg(), HFOV_MIN);
        // NaN does not pass through (View::clamped_in): the home angles.
        let nan = f64::NAN;
        assert_eq!(steer_rect(nan, nan, nan), View::default());
        assert_eq!(
            steer_rect(nan, 10.0, 60.0),
            View::new(0.0, 10.0, 60.0).unwrap()
        );
    }

    #[test]
    fn grab_inertia_continues_then_stops() {
        let mut c = Controller::default();
        c.frame(0.0);
        let t = drag(&mut c, CENTER, (CENTER.0 - 200.0, CENTER.1), 10, 0.0);
        c.release(t);
        assert!(c.animating(), "thrown");
        let y0 = c.look().yaw_deg();
        c.frame(t + 1.0 / 60.0);
        assert!(
            c.look().yaw_deg() > y0,
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
    fn a_flick_stops_within_a_second() {
        // The fastest throw (capped) and a typical one both stop within about a second,
        // and a typical one coasts less than a field of view (Pannellum's feel).
        for (px, frames) in [(2000.0, 6), (300.0, 10)] {
            let mut c = Controller::default();
            c.frame(0.0);
            let t = drag(&mut c, CENTER, (CENTER.0 - px, CENTER.1), frames, 0.0);
            let y0 = c.look().yaw_deg();
            c.release(t);
            assert!(c.animating(), "thrown");
            let mut tt = t;
            while c.animating() {
                tt += 1.0 / 60.0;
                c.frame(tt);
                assert!(tt - t < 1.05, "still coasting after {:.2} s", tt - t);
            }
            let coast = wrap_deg(c.look().yaw_deg() - y0).abs();
            assert!(coast > 1.0, "{px} px flick coasted only {coast}°");
            if px < 1000.0 {
                assert!(coast < 90.0, "a typical flick coasted {coast}°");
            }
        }
    }

    #[test]
    fn resolution_limit_is_two_screen_pixels_per_map_pixel() {
        // 1024-pixel map (0.3516° per pixel) in an 800-pixel view: at the limit a map
        // pixel spans two screen pixels at the center.
        let hfov = resolution_hfov(360.0 / 1024.0, 800, 2.0);
        let f = 400.0 / (hfov.to_radians() / 2.0).tan();
        close(
            (360.0f64 / 1024.0).to_radians() * f,
            2.0,
            1e-9,
            "screen pixels per map pixel",
        );
        assert!((101.0..102.0).contains(&hfov), "{hfov}");
        // A sharper map zooms further in; one screen pixel per map pixel (Marzipano's
        // limit) stops earlier.
        assert!(resolution_hfov(360.0 / 8192.0, 800, 2.0) < 20.0);
        assert!(resolution_hfov(360.0 / 1024.0, 800, 1.0) > hfov);
        // Nonsense gives the global minimum.
        assert_eq!(resolution_hfov(0.0, 800, 2.0), HFOV_MIN);
        assert_eq!(resolution_hfov(0.35, 0, 2.0), HFOV_MIN);
    }

    #[test]
    fn zoom_range_holds_against_wheel_keys_buttons_and_reset() {
        let mut c = Controller::new(steer_rect(0.0, 0.0, 100.0));
        c.set_zoom_range(80.0, 120.0);
        assert_eq!(c.look().hfov_deg(), 100.0, "inside the range: untouched");
        for _ in 0..50 {
            c.wheel(1.0, Some((100.0, 100.0)), SIZE);
        }
        assert_eq!(c.look().hfov_deg(), 80.0);
        assert!(c.take_zoomed_past_narrowest(), "the window says why");
        assert!(!c.take_zoomed_past_narrowest(), "reported once");
        c.key(KeyAction::Reset);
        assert_eq!(c.look().hfov_deg(), 100.0, "the start view");
        assert!(!c.take_zoomed_past_widest());
        for _ in 0..50 {
            c.key(KeyAction::ZoomOut);
        }
        assert_eq!(c.look().hfov_deg(), 120.0);
        assert!(c.take_zoomed_past_widest(), "the hook for wide projections");
        assert!(!c.take_zoomed_past_widest(), "reported once");
        c.frame(0.0);
        let zoom_in = Held {
            zoom_in: true,
            ..Held::default()
        };
        hold(&mut c, zoom_in, 0.0, 120);
        assert_eq!(c.look().hfov_deg(), 80.0);
        // Off for inspection: the global range.
        c.set_zoom_range(HFOV_MIN, HFOV_MAX);
        c.wheel(30.0, None, SIZE);
        assert!(c.look().hfov_deg() < 10.0);
    }

    #[test]
    fn the_start_view_is_shown_whatever_the_zoom_range() {
        // A file's 60° start view on a map whose resolution stops the zoom at 80°: the
        // view opens at 60° and zooming in goes no further than it.
        let mut c = Controller::new(steer_rect(0.0, 0.0, 60.0));
        c.set_zoom_range(80.0, 120.0);
        assert_eq!(
            c.look().hfov_deg(),
            60.0,
            "the start view is not pulled out"
        );
        c.wheel(1.0, None, SIZE);
        assert_eq!(c.look().hfov_deg(), 60.0);
        assert!(c.take_zoomed_past_narrowest());
        c.wheel(-3.0, None, SIZE);
        assert!(c.look().hfov_deg() > 80.0);
        for _ in 0..20 {
            c.key(KeyAction::ZoomIn);
        }
        assert_eq!(
            c.look().hfov_deg(),
            60.0,
            "the start view stays within reach"
        );
        c.set_home(steer_rect(0.0, 0.0, 30.0));
        assert_eq!(c.look().hfov_deg(), 30.0, "a new file's start view too");
    }

    #[test]
    fn a_view_pulled_in_by_the_range_returns_when_the_range_allows() {
        // Fullscreen: a wider scene raises the resolution limit (50° -> 70°), which pulls
        // the view out; leaving it lowers the limit again and the view comes back.
        let mut c = Controller::default();
        c.set_zoom_range(50.0, HFOV_MAX);
        c.wheel(10.0, None, SIZE);
        assert_eq!(c.look().hfov_deg(), 50.0);
        c.set_zoom_range(70.0, HFOV_MAX);
        assert_eq!(c.look().hfov_deg(), 70.0, "pulled out in the wider scene");
        c.set_zoom_range(60.0, HFOV_MAX);
        assert_eq!(c.look().hfov_deg(), 60.0, "as close as the range allows");
        c.set_zoom_range(50.0, HFOV_MAX);
        assert_eq!(c.look().hfov_deg(), 50.0, "back as it was");
        // A zoom by the user in between is the new view to keep.
        c.set_zoom_range(70.0, HFOV_MAX);
        c.wheel(-1.0, None, SIZE);
        let h = c.look().hfov_deg();
        assert!(h > 70.0);
        c.set_zoom_range(50.0, HFOV_MAX);
        assert_eq!(c.look().hfov_deg(), h, "the user's zoom stays");
    }

    #[test]
    fn double_click_zooms_in_toward_the_point_animated() {
        let mut c = Controller::default();
        c.frame(0.0);
        let p = (600.0, 150.0);
        let dir = dir_at(&c.look(), p, SIZE);
        c.double_click(p, SIZE, 0.0);
        assert!(c.animating());
        let mut t = 0.0;
        let mut prev = c.look().hfov_deg();
        while c.animating() {
            t += 1.0 / 60.0;
            c.frame(t);
            assert!(c.look().hfov_deg() <= prev, "zooms in monotonically");
            prev = c.look().hfov_deg();
            let q = screen_pos(&c.look(), dir);
            close(q.0, p.0, 1e-6, "x under the cursor");
            close(q.1, p.1, 1e-6, "y under the cursor");
            assert!(t < DOUBLE_CLICK_S + 0.1);
        }
        close(
            c.look().hfov_deg(),
            90.0 / DOUBLE_CLICK_ZOOM,
            1e-9,
            "halved",
        );
        // At the limit a double-click does nothing.
        let mut c = Controller::default();
        c.set_zoom_range(90.0, HFOV_MAX);
        c.double_click(p, SIZE, 0.0);
        assert!(!c.animating());
    }

    #[test]
    fn auto_rotate_starts_after_the_idle_delay_and_stops_on_input() {
        let mut c = Controller {
            auto_rotate: AutoRotate {
                enabled: true,
                idle_s: 2.0,
                ..AutoRotate::default()
            },
            ..Controller::default()
        };
        let speed = c.auto_rotate.speed_deg_s;
        c.interacted(0.0);
        c.frame(0.0);
        assert!(!c.animating());
        assert_eq!(c.wake_at(), Some(2.0), "wakes when the idle delay ends");
        c.frame(1.0);
        assert_eq!(c.look().yaw_deg(), 0.0, "nothing before the delay");
        c.frame(2.0);
        assert!(c.animating());
        let mut t = 2.0;
        for _ in 0..60 {
            t += 1.0 / 60.0;
            c.frame(t);
        }
        close(c.look().yaw_deg(), speed, 1e-6, "one second of rotation");
        // At the default speed the view does not count as moving fast.
        assert!(!c.frame(t).fast);
        // A key stops it; it resumes after the delay.
        c.interacted(t);
        assert!(!c.animating());
        c.frame(t + 1.0);
        close(c.look().yaw_deg(), speed, 1e-6, "stopped");
        assert_eq!(c.wake_at(), Some(t + 2.0));
        c.auto_rotate.enabled = false;
        assert_eq!(c.wake_at(), None);
    }

    #[test]
    fn auto_rotation_switched_on_turns_at_once() {
        let mut c = Controller::default();
        c.frame(0.0);
        c.interacted(10.0); // the Space key itself
        c.start_rotation(10.0);
        assert!(c.animating());
        // Half a second of display frames (a tick's step is capped, as after a stall).
        for i in 0..=30 {
            c.frame(10.0 + f64::from(i) / 60.0);
        }
        let speed = c.auto_rotate.speed_deg_s;
        close(
            c.look().yaw_deg(),
            speed * 0.5,
            1e-6,
            "half a second of rotation, no delay",
        );
    }

    #[test]
    fn a_new_home_is_the_start_view_and_reset_returns_to_it() {
        let mut c = Controller::default();
        let t = drag(&mut c, CENTER, (CENTER.0 - 200.0, CENTER.1), 10, 0.0);
        c.release(t);
        c.set_home(steer_rect(120.0, -10.0, 70.0));
        assert_eq!(c.look(), steer_rect(120.0, -10.0, 70.0));
        assert!(!c.animating(), "the old file's inertia does not carry over");
        c.wheel(2.0, None, SIZE);
        c.key(KeyAction::Reset);
        assert_eq!(c.look(), c.home());
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

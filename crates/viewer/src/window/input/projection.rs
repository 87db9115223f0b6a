//! Output projections in the window (issue 12): the widest hfov of each, choosing and
//! cycling them, and the little planet preset with its animated transition.
//!
//! * [`Controller::set_projection`] and [`Controller::cycle_projection`] keep yaw and
//!   pitch and clamp hfov to the new projection's [`widest_hfov`].
//! * [`Controller::toggle_planet`]: into the little planet (stereographic, pitch −90°,
//!   hfov [`PLANET_HFOV`]) and back to the look it left, each way over [`PLANET_S`]
//!   seconds (eased; yaw, pitch and hfov move together in the stereographic projection).
//!   The glide starts (and ends) at the stereographic hfov with the same centre scale as
//!   the look it leaves (returns to), so the centre of the picture does not jump where the
//!   projection changes; only the periphery does. Any input finishes a transition at once.

use super::{moved, steer, Controller, HFOV_MAX, HFOV_MIN};
use lut_core::{wrap_deg, Named, View, ViewProjection};

/// The widest hfov the window allows in any projection (a full-sphere fisheye).
pub const WIDE_HFOV_MAX: f64 = 360.0;
/// The little planet's hfov, degrees: the nadir at the centre, the horizon a circle, the
/// sky at the corners.
pub const PLANET_HFOV: f64 = 300.0;
/// Seconds a transition into or out of the little planet takes.
pub const PLANET_S: f64 = 0.8;

/// The widest hfov the window lets the user zoom out to in `p`: its range (one degree
/// short of an excluded end), at most [`HFOV_MAX`] for rectilinear views (they stretch
/// badly beyond), 340° for stereographic (the last degrees blow the opposite pole up
/// without end) and 300° for Pannini.
pub fn widest_hfov(p: ViewProjection) -> f64 {
    let (max, inclusive) = p.hfov_max();
    let max = if inclusive { max } else { max - 1.0 };
    let cap = match p {
        _ if p.is_rectilinear() => HFOV_MAX,
        ViewProjection::Stereographic => 340.0,
        ViewProjection::Pannini(_) => 300.0,
        _ => WIDE_HFOV_MAX,
    };
    max.min(cap).max(HFOV_MIN)
}

/// The stereographic hfov whose centre scale (the focal length: every projection maps
/// small angles θ to radius f·θ) equals `l`'s.
fn stereo_hfov_like(l: View) -> f64 {
    let f = l.projection().focal(1000, l.hfov_deg().to_radians());
    let h = (4.0 * (250.0 / f).atan()).to_degrees();
    h.clamp(HFOV_MIN, widest_hfov(ViewProjection::Stereographic))
}

/// The little planet: the look to return to and the transition in progress.
#[derive(Debug, Clone, Copy)]
pub(super) struct Planet {
    /// The look before the little planet (where the key returns).
    back: View,
    /// The transition in progress.
    moving: Option<Transition>,
}

#[derive(Debug, Clone, Copy)]
struct Transition {
    from: View,
    to: View,
    t0: f64,
    /// True when leaving the little planet (`back`'s projection returns at the end).
    leaving: bool,
}

impl Controller {
    /// Show the view in `p`: yaw and pitch kept, hfov clamped to `p`'s widest; leaves
    /// the little planet.
    pub fn set_projection(&mut self, p: ViewProjection) {
        self.planet = None;
        let l = self.look;
        self.look = steer(l.yaw_deg(), l.pitch_deg(), l.hfov_deg(), p);
    }

    /// The next projection of [`ViewProjection::ALL`] after the one in use (Pannini with
    /// parameter `pannini_d`); returns it.
    pub fn cycle_projection(&mut self, pannini_d: f64) -> ViewProjection {
        let all = ViewProjection::ALL;
        let name = self.look.projection().name();
        let i = all.iter().position(|p| p.name() == name).unwrap_or(0);
        let next = all[(i + 1) % all.len()].with_pannini_d(pannini_d);
        self.set_projection(next);
        next
    }

    /// True while the little planet is shown (or the transition into it runs).
    pub fn in_planet(&self) -> bool {
        self.planet
            .is_some_and(|p| !p.moving.is_some_and(|m| m.leaving))
    }

    /// Into the little planet at time `t`, or back to the look it left when it is shown.
    /// Returns true when going in.
    pub fn toggle_planet(&mut self, t: f64) -> bool {
        self.finish_planet_transition();
        let stereo = ViewProjection::Stereographic;
        let l = self.look;
        let from = steer(l.yaw_deg(), l.pitch_deg(), stereo_hfov_like(l), stereo);
        let (back, to, leaving) = match self.planet {
            None => (l, steer(l.yaw_deg(), -90.0, PLANET_HFOV, stereo), false),
            Some(p) => {
                let b = p.back;
                let to = steer(b.yaw_deg(), b.pitch_deg(), stereo_hfov_like(b), stereo);
                (b, to, true)
            }
        };
        let moving = Some(Transition {
            from,
            to,
            t0: t,
            leaving,
        });
        self.velocity = (0.0, 0.0);
        self.zoom_anim = None;
        self.planet = Some(Planet { back, moving });
        self.look = from;
        self.touch_tick(t);
        !leaving
    }

    /// True while a transition into or out of the little planet runs.
    pub(super) fn planet_moving(&self) -> bool {
        self.planet.is_some_and(|p| p.moving.is_some())
    }

    /// Advance the transition to time `t`.
    pub(super) fn step_planet(&mut self, t: f64) {
        let Some(m) = self.planet.and_then(|p| p.moving) else {
            return;
        };
        let s = ((t - m.t0) / PLANET_S).clamp(0.0, 1.0);
        if s >= 1.0 {
            self.finish_planet_transition();
            return;
        }
        let e = s * s * (3.0 - 2.0 * s);
        let (f, to) = (m.from, m.to);
        let yaw = f.yaw_deg() + wrap_deg(to.yaw_deg() - f.yaw_deg()) * e;
        let lerp = |a: f64, b: f64| a + (b - a) * e;
        self.look = moved(
            f,
            yaw,
            lerp(f.pitch_deg(), to.pitch_deg()),
            lerp(f.hfov_deg(), to.hfov_deg()),
        );
    }

    /// End a transition at its target now (any input does).
    pub(super) fn finish_planet_transition(&mut self) {
        let Some(mut p) = self.planet else {
            return;
        };
        let Some(m) = p.moving.take() else {
            return;
        };
        if m.leaving {
            let b = p.back;
            self.look = moved(b, b.yaw_deg(), b.pitch_deg(), self.clamp_hfov(b.hfov_deg()));
            self.planet = None;
        } else {
            self.look = m.to;
            self.planet = Some(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::window::input::{dir_at, steer_rect, DEFAULT_FRAME_S};

    const SIZE: (u32, u32) = (400, 300);

    fn close(a: f64, b: f64, tol: f64, what: &str) {
        assert!((a - b).abs() <= tol, "{what}: {a} vs {b}");
    }

    /// A controller as the window sets it up: the zoom range up to the widest view.
    fn controller(look: View) -> Controller {
        let mut c = Controller::new(look);
        c.set_zoom_range(HFOV_MIN, WIDE_HFOV_MAX);
        c
    }

    #[test]
    fn widest_views_are_in_each_projections_range() {
        use ViewProjection as P;
        assert_eq!(widest_hfov(P::Rectilinear), HFOV_MAX);
        assert_eq!(widest_hfov(P::Pannini(0.0)), HFOV_MAX);
        assert_eq!(widest_hfov(P::Stereographic), 340.0);
        assert_eq!(widest_hfov(P::Fisheye), 360.0);
        assert_eq!(widest_hfov(P::Equisolid), 360.0);
        assert_eq!(widest_hfov(P::Pannini(1.0)), 300.0);
        // d = 3: the range ends at 2·acos(−1/3) = 218.94°.
        let w = widest_hfov(P::Pannini(3.0));
        close(
            w,
            2.0 * (-1.0f64 / 3.0).acos().to_degrees() - 1.0,
            1e-9,
            "d = 3",
        );
        for p in [
            P::Stereographic,
            P::Fisheye,
            P::Equisolid,
            P::Pannini(0.5),
            P::Pannini(3.0),
        ] {
            let l = steer(10.0, -30.0, 1000.0, p);
            assert_eq!(l.hfov_deg(), widest_hfov(p), "{p}");
            assert!(
                View::with_projection(l.yaw_deg(), l.pitch_deg(), l.hfov_deg(), p).is_ok(),
                "{p}"
            );
            assert_eq!(l.projection(), p);
        }
    }

    #[test]
    fn cycling_visits_every_projection_and_clamps_hfov() {
        let mut c = controller(steer_rect(30.0, 10.0, 90.0));
        let names: Vec<&str> = (0..5).map(|_| c.cycle_projection(0.7).name()).collect();
        assert_eq!(
            names,
            [
                "stereographic",
                "fisheye",
                "equisolid",
                "pannini",
                "rectilinear"
            ]
        );
        assert_eq!((c.look().yaw_deg(), c.look().pitch_deg()), (30.0, 10.0));
        // Pannini carries the panel's d.
        c.set_projection(ViewProjection::Pannini(0.7));
        assert_eq!(c.look().projection(), ViewProjection::Pannini(0.7));
        // Zoomed out to a 300° fisheye, back to rectilinear: hfov comes in to 170.
        c.set_projection(ViewProjection::Fisheye);
        c.zoom_to(300.0, None, SIZE);
        assert_eq!(c.look().hfov_deg(), 300.0);
        c.set_projection(ViewProjection::Rectilinear);
        assert_eq!(c.look().hfov_deg(), HFOV_MAX);
        assert_eq!(c.zoom_range().1, HFOV_MAX);
        c.zoom_to(200.0, None, SIZE);
        assert_eq!(c.look().hfov_deg(), HFOV_MAX);
        assert!(c.take_zoomed_past_widest(), "past the rectilinear widest");
    }

    #[test]
    fn little_planet_goes_in_and_comes_back_animated() {
        let start = steer_rect(40.0, 10.0, 80.0);
        let mut c = controller(start);
        c.frame(0.0);
        assert!(c.toggle_planet(1.0), "going in");
        assert!(c.in_planet() && c.animating());
        assert_eq!(c.wake_at(), Some(0.0 + DEFAULT_FRAME_S));
        // Halfway: stereographic, between the two looks (smoothstep: half way).
        c.frame(1.0 + PLANET_S / 2.0);
        let mid = c.look();
        assert_eq!(mid.projection(), ViewProjection::Stereographic);
        close(mid.pitch_deg(), (10.0 - 90.0) / 2.0, 1e-9, "pitch half way");
        // From the stereographic hfov with rectilinear 80°'s centre scale (91.0°).
        let h0 = 4.0 * (40f64.to_radians().tan() / 2.0).atan().to_degrees();
        close(h0, 91.0, 0.05, "matched hfov");
        close(
            mid.hfov_deg(),
            (h0 + PLANET_HFOV) / 2.0,
            1e-9,
            "hfov half way",
        );
        assert!(
            c.frame(1.0 + PLANET_S / 2.0 + 0.05).fast,
            "the transition is motion"
        );
        c.frame(1.0 + PLANET_S + 0.01);
        let planet = steer(40.0, -90.0, PLANET_HFOV, ViewProjection::Stereographic);
        assert_eq!(c.look(), planet);
        assert!(!c.animating() && c.in_planet());
        // Turn the planet, then leave: back to the look it left, projection included.
        c.set_held(
            crate::window::input::Held {
                right: true,
                ..Default::default()
            },
            3.0,
        );
        c.frame(3.05);
        c.set_held(crate::window::input::Held::default(), 3.05);
        assert!(c.look().yaw_deg() != 40.0 && c.look().pitch_deg() == -90.0);
        assert!(!c.toggle_planet(4.0), "coming back");
        assert!(!c.in_planet());
        c.frame(4.0 + PLANET_S / 3.0);
        assert_eq!(c.look().projection(), ViewProjection::Stereographic);
        // Just before the end: the stereographic hfov of the same centre scale.
        c.frame(4.0 + PLANET_S * 0.999);
        close(c.look().hfov_deg(), h0, 1e-3, "glides to the matched hfov");
        c.frame(4.0 + PLANET_S + 0.01);
        assert_eq!(c.look(), start);
        assert!(!c.animating());
    }

    #[test]
    fn input_during_the_transition_finishes_it() {
        let mut c = controller(steer_rect(0.0, 0.0, 90.0));
        c.frame(0.0);
        c.toggle_planet(0.0);
        c.frame(0.1);
        c.interacted(0.1);
        assert_eq!(c.look().pitch_deg(), -90.0);
        assert_eq!(c.look().hfov_deg(), PLANET_HFOV);
        assert!(!c.animating());
        // Reset leaves the little planet: the start view in the projection in use.
        c.key(crate::window::keys::KeyAction::Reset);
        assert_eq!(
            c.look(),
            steer(0.0, 0.0, 90.0, ViewProjection::Stereographic)
        );
        assert!(!c.in_planet());
    }

    /// A grab drag and a wheel zoom keep the grabbed direction under the cursor in every
    /// wide projection; a press outside a fisheye's disc grabs nothing.
    #[test]
    fn grab_and_zoom_keep_the_point_under_the_cursor() {
        for p in [
            ViewProjection::Stereographic,
            ViewProjection::Fisheye,
            ViewProjection::Equisolid,
            ViewProjection::Pannini(1.0),
        ] {
            let mut c = controller(steer(20.0, -30.0, 150.0, p));
            let (a, b) = ((150.0, 120.0), (230.0, 170.0));
            let dir = dir_at(&c.look(), a, SIZE);
            c.press(a, SIZE, 0.0);
            c.drag_to(b, SIZE, 0.05);
            c.release(1.0);
            let got = dir_at(&c.look(), b, SIZE);
            assert!(got.dot(dir) > 1.0 - 1e-9, "{p}: drag {got} vs {dir}");
            let before = dir_at(&c.look(), a, SIZE);
            c.wheel(-2.0, Some(a), SIZE);
            assert!(c.look().hfov_deg() > 150.0, "{p}");
            let after = dir_at(&c.look(), a, SIZE);
            assert!(
                after.dot(before) > 1.0 - 1e-9,
                "{p}: zoom {after} vs {before}"
            );
        }
        // A 360° fisheye in a wide window: the corners have no direction.
        let mut c = controller(steer(0.0, 0.0, 360.0, ViewProjection::Fisheye));
        let look = c.look();
        assert_eq!(dir_at(&look, (1.0, 1.0), SIZE), glam::DVec3::ZERO);
        c.press((1.0, 1.0), SIZE, 0.0);
        c.drag_to((100.0, 100.0), SIZE, 0.05);
        assert_eq!(c.look(), look, "nothing grabbed");
    }
}

//! Levelling a scene's horizon by dragging it: the horizon line of a correction (the
//! equator of the panorama's sphere as the correction turns it, a great circle) placed
//! in a view of any output projection, the point of it under the pointer, and the
//! correction that brings a grabbed point of it under the cursor.
//!
//! The correction is Pannellum's (`horizonPitch`, `horizonRoll`,
//! [`lut_core::horizon_rotation`] R): the world direction d shows the panorama's
//! direction R·d, so the panorama's equator {e : e.y = 0} is seen at the world
//! directions Rᵀ·e. A grab takes the point e (its longitude λ on the equator); a drag to
//! the cursor's world direction c asks for the correction R' (pitch and roll only: no
//! yaw) with R'ᵀ·e = c, i.e. R'·c = e, solved in closed form by [`solve`].

use super::{edit::wrap180, markers, Horizon};
use glam::DVec3;
use lut_core::{horizon_rotation, Camera, View};
use std::f64::consts::{PI, TAU};

/// A press within this many pixels of the horizon line grabs it.
pub const LINE_PICK_PX: f64 = 8.0;
/// Points taken along the great circle to draw it.
const LINE_STEPS: usize = 1440;

/// The equator point at longitude `lambda` (radians).
fn equator(lambda: f64) -> DVec3 {
    let (s, c) = lambda.sin_cos();
    DVec3::new(s, 0.0, c)
}

/// The horizon line of correction `h` in a `w × hh` frame of `view`: polylines of
/// pixel positions (pixel centres at +0.5), cut where the projection does not show the
/// circle (behind a rectilinear viewer, outside a fisheye's disc) or jumps.
pub fn line(h: Horizon, view: View, w: u32, hh: u32) -> Vec<Vec<(f64, f64)>> {
    let cam = Camera::new(view, w, hh);
    let rt = horizon_rotation(h.pitch, h.roll).transpose();
    let jump = f64::from(w.max(hh)) / 8.0;
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    for i in 0..=LINE_STEPS {
        let lambda = i as f64 / LINE_STEPS as f64 * TAU - PI;
        match markers::place_dir(&cam, rt * equator(lambda)) {
            Some(p) => {
                if let Some(&q) = cur.last() {
                    if (p.0 - q.0).hypot(p.1 - q.1) > jump {
                        out.push(std::mem::take(&mut cur));
                    }
                }
                cur.push(p);
            }
            None => out.push(std::mem::take(&mut cur)),
        }
    }
    out.push(cur);
    out.retain(|l| l.len() >= 2);
    out
}

/// Where the equator point at longitude `lambda` of correction `h` is in a `w × hh`
/// frame of `view` (`None`: not shown).
pub fn landed(h: Horizon, lambda: f64, view: View, w: u32, hh: u32) -> Option<(f64, f64)> {
    let rt = horizon_rotation(h.pitch, h.roll).transpose();
    markers::place_dir(&Camera::new(view, w, hh), rt * equator(lambda))
}

/// A press at (`x`, `y`) of a `w × hh` frame of `view` on the horizon line of `h`: the
/// longitude (radians) of the equator point grabbed, the one nearest the pointer's
/// direction, when it is drawn within [`LINE_PICK_PX`] of the pointer.
pub fn grab(h: Horizon, view: View, w: u32, hh: u32, x: f64, y: f64) -> Option<f64> {
    let d = Camera::new(view, w, hh).ray(x, y)?.normalize();
    if !d.is_finite() {
        return None;
    }
    let e = horizon_rotation(h.pitch, h.roll) * d;
    let flat = DVec3::new(e.x, 0.0, e.z);
    if flat.length() < 1e-9 {
        return None;
    }
    let lambda = flat.x.atan2(flat.z);
    let (px, py) = landed(h, lambda, view, w, hh)?;
    ((px - x).hypot(py - y) <= LINE_PICK_PX).then_some(lambda)
}

/// The correction (pitch and roll, degrees; no yaw) that shows the equator point at
/// longitude `lambda` in world direction `c` (R'·c = that point), the solution nearest
/// `near` (a drag moves continuously from it). Where no pitch and roll reach `c` (a
/// point at the side, λ near ±90°, can only move along the plane across the view's
/// axis: a rotation without yaw keeps its distance from the forward axis), the
/// nearest reachable correction.
pub fn solve(lambda: f64, c: DVec3, near: Horizon) -> Horizon {
    let c = c.normalize();
    let e = equator(lambda);
    // R' = Rx(pitch)·Rz(roll). Rz(r) turns c to c' with c'.x = cos r·c.x − sin r·c.y,
    // which must be sin λ: with c.x = a cos φ, c.y = a sin φ, a cos(r + φ) = sin λ.
    let a = c.x.hypot(c.y);
    let phi = c.y.atan2(c.x);
    let k = if a > 1e-12 {
        (e.x / a).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let base = k.acos();
    let mut cands = Vec::with_capacity(4);
    for r in [base - phi, -base - phi] {
        let (sr, cr) = r.sin_cos();
        // Then Rx(p) turns (c'.y, c'.z) onto (0, cos λ): z + iy is multiplied by e^{-ip}.
        let (y1, z1) = (sr * c.x + cr * c.y, c.z);
        let arg = y1.atan2(z1);
        let ps: [f64; 2] = if y1.hypot(z1) < 1e-12 {
            [near.pitch.to_radians(); 2]
        } else {
            [arg, arg - PI]
        };
        for p in ps {
            let h = Horizon {
                pitch: wrap180(p.to_degrees()),
                roll: wrap180(r.to_degrees()),
            };
            let miss = (horizon_rotation(h.pitch, h.roll) * c - e).length();
            let far = wrap180(h.pitch - near.pitch).powi(2) + wrap180(h.roll - near.roll).powi(2);
            cands.push((miss, far, h));
        }
    }
    let least = cands.iter().map(|c| c.0).fold(f64::INFINITY, f64::min);
    cands
        .into_iter()
        .filter(|c| c.0 <= least + 1e-9)
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(near, |c| c.2)
}

/// A drag of the grabbed point (longitude `lambda`) to (`x`, `y`) of a `w × hh` frame
/// of `view`: the new correction, nearest `near` (`None` where the projection has no
/// direction under the cursor).
pub fn drag(
    lambda: f64,
    near: Horizon,
    view: View,
    w: u32,
    hh: u32,
    x: f64,
    y: f64,
) -> Option<Horizon> {
    let c = Camera::new(view, w, hh).ray(x, y)?;
    (c.is_finite() && c.length() > 0.0).then(|| solve(lambda, c, near))
}

#[cfg(test)]
mod tests {
    use super::*;
    use lut_core::ViewProjection;

    fn view(yaw: f64, pitch: f64, hfov: f64, p: ViewProjection) -> View {
        View::new(yaw, pitch, hfov).unwrap().projected(p).unwrap()
    }

    /// A point of the drawn line near pixel column `x` (its polyline vertex nearest).
    fn on_line(h: Horizon, v: View, w: u32, hh: u32, x: f64) -> (f64, f64) {
        line(h, v, w, hh)
            .into_iter()
            .flatten()
            .min_by(|a, b| (a.0 - x).abs().total_cmp(&(b.0 - x).abs()))
            .unwrap()
    }

    #[test]
    fn a_dragged_point_of_the_line_lands_under_the_cursor() {
        let (w, hh) = (800, 500);
        for proj in [
            ViewProjection::Rectilinear,
            ViewProjection::Stereographic,
            ViewProjection::Fisheye,
        ] {
            let v = view(30.0, -5.0, 100.0, proj);
            let mut h = Horizon {
                pitch: 2.0,
                roll: -3.0,
            };
            for &(gx, tx, ty) in &[
                (400.0, 420.0, 180.0),
                (250.0, 240.0, 300.0),
                (600.0, 640.0, 200.0),
            ] {
                let (x, y) = on_line(h, v, w, hh, gx);
                let lambda = grab(h, v, w, hh, x, y).expect("the line is grabbed on it");
                // Moved in small steps, as a pointer does; each lands under its cursor.
                let mut near = h;
                for s in 1..=10 {
                    let f = f64::from(s) / 10.0;
                    let (cx, cy) = (x + (tx - x) * f, y + (ty - y) * f);
                    near = drag(lambda, near, v, w, hh, cx, cy).unwrap();
                    let (lx, ly) = landed(near, lambda, v, w, hh).unwrap();
                    assert!(
                        (lx - cx).hypot(ly - cy) < 1.0,
                        "{proj}: the grabbed point at {lx:.3},{ly:.3}, the cursor at {cx:.3},{cy:.3} ({near:?})"
                    );
                }
                assert!(
                    near != h,
                    "{proj}: a drag of {:.0} px changes the correction",
                    (tx - x).hypot(ty - y)
                );
                // The new line passes under the cursor: grabbed there again, same point.
                let again = grab(near, v, w, hh, tx, ty).unwrap();
                assert!((wrap180((again - lambda).to_degrees())).abs() < 1e-6);
                h = near;
            }
        }
    }

    #[test]
    fn dragging_up_ahead_pitches_and_at_the_side_rolls() {
        let (w, hh) = (800, 500);
        let level = Horizon::default();
        // Looking along yaw 0: the centre of the line dragged up by angle a pitches by a.
        let v = view(0.0, 0.0, 90.0, ViewProjection::Rectilinear);
        let lambda = grab(level, v, w, hh, 400.0, 250.0).unwrap();
        assert!(lambda.abs() < 1e-9);
        let f = 400.0; // (W/2) / tan(45°)
        let h = drag(lambda, level, v, w, hh, 400.0, 250.0 - 40.0).unwrap();
        let a = (40.0f64 / f).atan().to_degrees();
        assert!((h.pitch - a).abs() < 1e-6 && h.roll.abs() < 1e-6, "{h:?}");
        // Looking along yaw 90: the same drag rolls, by −a.
        let v = view(90.0, 0.0, 90.0, ViewProjection::Rectilinear);
        let lambda = grab(level, v, w, hh, 400.0, 250.0).unwrap();
        let h = drag(lambda, level, v, w, hh, 400.0, 250.0 - 40.0).unwrap();
        assert!((h.roll + a).abs() < 1e-6 && h.pitch.abs() < 1e-6, "{h:?}");
        // Away from the line nothing is grabbed.
        assert!(grab(level, v, w, hh, 400.0, 250.0 - 3.0 * LINE_PICK_PX).is_none());
    }

    #[test]
    fn an_unreachable_cursor_gives_the_nearest_correction() {
        // The equator's point at yaw 90 cannot be brought to the forward axis without yaw.
        let h = solve(
            PI / 2.0,
            DVec3::new(0.0, 0.1, 1.0),
            Horizon {
                pitch: 1.0,
                roll: 2.0,
            },
        );
        assert!(h.pitch.is_finite() && h.roll.is_finite(), "{h:?}");
        let got = horizon_rotation(h.pitch, h.roll).transpose() * equator(PI / 2.0);
        let want = DVec3::new(0.0, 0.1, 1.0).normalize();
        // The nearest reachable: in the plane z = 0, as close to the cursor as it gets.
        assert!(got.z.abs() < 1e-9 && got.dot(want) > 0.099 * 0.99, "{got}");
    }

    #[test]
    fn the_line_of_a_level_horizon_is_the_views_horizon() {
        let v = view(10.0, 0.0, 90.0, ViewProjection::Rectilinear);
        let l = line(Horizon::default(), v, 400, 300);
        assert_eq!(l.len(), 1, "one piece in front of the viewer");
        for &(x, y) in &l[0] {
            assert!((y - 150.0).abs() < 1e-6, "{x},{y}");
        }
        // A tilted horizon is not flat.
        let tilted = Horizon {
            pitch: 0.0,
            roll: 10.0,
        };
        let l = line(tilted, v, 400, 300);
        let ys: Vec<f64> = l.iter().flatten().map(|p| p.1).collect();
        let spread = ys.iter().cloned().fold(f64::MIN, f64::max)
            - ys.iter().cloned().fold(f64::MAX, f64::min);
        assert!(spread > 20.0, "{spread}");
    }
}

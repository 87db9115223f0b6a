//! The level-horizon mode of the tour editor: the scene's horizon line (the equator of
//! its panorama as the correction turns it, [`crate::tour::level`]) drawn over the
//! scene in every output projection with the view's level horizon dashed beside it; a
//! drag that starts on the line moves the grabbed point of it to the cursor, the scene
//! turning with it live (the frame shown re-projected through the change of
//! correction); on release the correction is one edit (undo/redo) and the scene reloads
//! levelled (the map re-levelled on the loading thread, as the sliders do). Esc or
//! Enter leaves the mode.

use super::{TourAction, TourNav};
use crate::tour::level;
use crate::tour::{Horizon, Source as SceneSource};
use glam::DMat3;
use lut_core::{horizon_rotation, Camera, View};
use rayon::prelude::*;

/// The horizon line's colour (0RGB).
const LINE_COLOR: u32 = 0x0040_FF60;
/// The line's dark edge.
const EDGE_COLOR: u32 = 0x0010_1010;
/// The dashed level reference.
const LEVEL_COLOR: u32 = 0x00FF_FFFF;
/// Where the re-projected preview has nothing (outside the frame it is made from).
const EMPTY_COLOR: u32 = 0x0020_2020;
/// The preview's grid: exact positions every this many pixels, interpolated between.
const WARP_CELL: usize = 8;

/// The level mode's state.
#[derive(Debug, Clone, Default)]
pub struct LevelMode {
    /// The mode is on: the line is drawn, a drag on it levels.
    pub on: bool,
    /// The grabbed point's longitude on the panorama's equator, radians.
    grab: Option<f64>,
    /// The correction while dragging.
    preview: Option<Horizon>,
}

impl TourNav {
    /// Whether the scene shown can be levelled here (tile scenes are shown as they are).
    fn levellable(&self) -> Result<(), String> {
        match self.scene().source {
            SceneSource::Multires(_) | SceneSource::MarzipanoTiles { .. } => Err(format!(
                "scene \"{}\" is tiles, which are shown unlevelled: its horizon is set in \
                 the saved config only",
                self.scene().id
            )),
            _ => Ok(()),
        }
    }

    /// The level mode on or off (on turns the editor on: its edits are undone there).
    pub fn level_toggle(&mut self) -> Result<bool, String> {
        if self.editor.level.on {
            self.level_leave();
            return Ok(false);
        }
        self.levellable()?;
        self.editor.on = true;
        self.editor.level.on = true;
        Ok(true)
    }

    /// Leave the level mode (a drag in progress is dropped).
    pub fn level_leave(&mut self) {
        self.editor.level = LevelMode::default();
    }

    /// The correction the scene is shown with: the one being dragged, else the scene's.
    pub fn level_target(&self) -> Horizon {
        self.editor.level.preview.unwrap_or(self.scene().horizon)
    }

    /// A press at (`x`, `y`) of a `w × h` frame of `look`: on the horizon line (level
    /// mode) it grabs the line (true); elsewhere it is the view's.
    pub fn level_press(&mut self, look: &View, w: u32, h: u32, x: f64, y: f64) -> bool {
        if !self.editor.level.on || self.levellable().is_err() {
            return false;
        }
        let cur = self.level_target();
        match level::grab(cur, *look, w, h, x, y) {
            Some(lambda) => {
                self.editor.level.grab = Some(lambda);
                self.editor.level.preview = Some(cur);
                true
            }
            None => false,
        }
    }

    /// True while the line is dragged.
    pub fn level_dragging(&self) -> bool {
        self.editor.level.grab.is_some()
    }

    /// The grabbed point dragged to (`x`, `y`).
    pub fn level_drag(&mut self, look: &View, w: u32, h: u32, x: f64, y: f64) {
        let Some(lambda) = self.editor.level.grab else {
            return;
        };
        let near = self.level_target();
        if let Some(hz) = level::drag(lambda, near, *look, w, h, x, y) {
            self.editor.level.preview = Some(hz);
        }
    }

    /// The drag let go: the correction reached is one edit (the scene reloads levelled).
    /// Returns the new correction, when it changed, and what to do.
    pub fn level_release(&mut self, look: View) -> (Option<Horizon>, Vec<TourAction>) {
        let preview = self.editor.level.preview.take();
        self.editor.level.grab = None;
        match preview {
            Some(p) if p != self.scene().horizon => {
                // Rounded as a slider step would be finer than anyone sees: 0.001°.
                let r = |a: f64| (a * 1000.0).round() / 1000.0;
                let p = Horizon {
                    pitch: r(p.pitch),
                    roll: r(p.roll),
                };
                let out = self.edit_request(super::EditRequest::Horizon(p), look);
                (Some(p), out)
            }
            _ => (None, Vec::new()),
        }
    }

    /// A point of the horizon line near the frame's centre column (`--print-view`'s
    /// `tour level line` and the window test's grab).
    pub fn level_line_point(&self, look: &View, w: u32, h: u32) -> Option<(f64, f64)> {
        let mid = f64::from(w) / 2.0;
        level::line(self.level_target(), *look, w, h)
            .into_iter()
            .flatten()
            .min_by(|a, b| (a.0 - mid).abs().total_cmp(&(b.0 - mid).abs()))
    }

    /// Draw the level mode over `buf` (the composed scene, `w × h`, of `look`): the
    /// scene turned by the correction being dragged (or loading), the level reference
    /// dashed and the horizon line.
    pub(super) fn level_draw(&self, scene: &[u32], buf: &mut [u32], w: u32, h: u32, look: &View) {
        let target = self.level_target();
        if target != self.shown_horizon && self.levellable().is_ok() {
            // The frame shows the panorama levelled by `shown` (L(d) = P(S·d)); the
            // target wants P(T·d) = L(Sᵀ·T·d).
            let s = horizon_rotation(self.shown_horizon.pitch, self.shown_horizon.roll);
            let t = horizon_rotation(target.pitch, target.roll);
            warp(scene, buf, w, h, look, s.transpose() * t);
        }
        if !self.editor.level.on {
            return;
        }
        for l in level::line(Horizon::default(), *look, w, h) {
            polyline(buf, w, h, &l, 0.8, LEVEL_COLOR, Some(10.0));
        }
        for l in level::line(target, *look, w, h) {
            polyline(buf, w, h, &l, 2.5, EDGE_COLOR, None);
            polyline(buf, w, h, &l, 1.3, LINE_COLOR, None);
        }
    }
}

/// `out` (`w × h`) the frame `src` of `look` seen through rotation `m`: each pixel the
/// pixel of `src` at `m` of its direction (nearest; [`EMPTY_COLOR`] where `src` has
/// none). Positions are exact every [`WARP_CELL`] pixels and interpolated between
/// (a preview while dragging, not a render: the reload draws the scene exactly);
/// cells with a corner the view has no direction for are done per pixel.
fn warp(src: &[u32], out: &mut [u32], w: u32, h: u32, look: &View, m: DMat3) {
    let cam = Camera::new(*look, w, h);
    let (wu, hu) = (w as usize, h as usize);
    if src.len() != wu * hu || out.len() != src.len() {
        return;
    }
    let at = |x: f64, y: f64| -> Option<(f64, f64)> {
        let d = cam.ray(x, y)?;
        let p = crate::tour::markers::place_dir(&cam, (m * d).normalize());
        p.filter(|p| p.0.is_finite() && p.1.is_finite())
    };
    let g = WARP_CELL;
    let (gw, gh) = (wu.div_ceil(g) + 1, hu.div_ceil(g) + 1);
    let nodes: Vec<Option<(f64, f64)>> = (0..gw * gh)
        .into_par_iter()
        .map(|k| at((k % gw * g) as f64 + 0.5, (k / gw * g) as f64 + 0.5))
        .collect();
    let pick = |p: Option<(f64, f64)>| -> u32 {
        match p {
            Some((x, y)) if x >= 0.0 && y >= 0.0 && x < w as f64 && y < h as f64 => {
                src[y as usize * wu + x as usize]
            }
            _ => EMPTY_COLOR,
        }
    };
    // A band of cells per task (rayon); along each pixel row of a cell the position
    // steps linearly between the cell's left and right edges.
    out.par_chunks_mut(wu * g)
        .enumerate()
        .for_each(|(cj, band)| {
            let rows = band.len() / wu;
            for ci in 0..gw - 1 {
                let n = |i: usize, j: usize| nodes[(cj + j) * gw + ci + i];
                let corners = [n(0, 0), n(1, 0), n(0, 1), n(1, 1)];
                // A cell whose corners spread far apart (a seam of the view) is exact.
                let smooth = match corners {
                    [Some(a), Some(b), Some(c), Some(d)] => [b, c, d]
                        .iter()
                        .all(|p| (p.0 - a.0).hypot(p.1 - a.1) < 4.0 * g as f64)
                        .then_some((a, b, c, d)),
                    _ => None,
                };
                let x1 = ((ci + 1) * g).min(wu);
                for r in 0..rows {
                    let row = &mut band[r * wu..(r + 1) * wu];
                    match smooth {
                        Some((a, b, c, d)) => {
                            let fy = r as f64 / g as f64;
                            let l = (a.0 + (c.0 - a.0) * fy, a.1 + (c.1 - a.1) * fy);
                            let rt = (b.0 + (d.0 - b.0) * fy, b.1 + (d.1 - b.1) * fy);
                            let step = ((rt.0 - l.0) / g as f64, (rt.1 - l.1) / g as f64);
                            let mut p = l;
                            for px in &mut row[ci * g..x1] {
                                *px = pick(Some(p));
                                p = (p.0 + step.0, p.1 + step.1);
                            }
                        }
                        None => {
                            let y = (cj * g + r) as f64 + 0.5;
                            for (x, px) in row.iter_mut().enumerate().take(x1).skip(ci * g) {
                                *px = pick(at(x as f64 + 0.5, y));
                            }
                        }
                    }
                }
            }
        });
}

/// A polyline of half-width `r` pixels in `color`, dashed (`dash` pixels on, as many
/// off) when asked.
fn polyline(
    out: &mut [u32],
    w: u32,
    h: u32,
    pts: &[(f64, f64)],
    r: f64,
    color: u32,
    dash: Option<f64>,
) {
    let mut run = 0.0;
    for s in pts.windows(2) {
        let (a, b) = (s[0], s[1]);
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let n = (len / 0.5).ceil().max(1.0) as usize;
        for k in 0..n {
            let f = k as f64 / n as f64;
            let here = run + len * f;
            if dash.is_some_and(|d| (here / d) as u64 % 2 == 1) {
                continue;
            }
            dot(
                out,
                w,
                h,
                a.0 + (b.0 - a.0) * f,
                a.1 + (b.1 - a.1) * f,
                r,
                color,
            );
        }
        run += len;
    }
}

/// The pixels whose centres are within `r` of (cx, cy).
fn dot(out: &mut [u32], w: u32, h: u32, cx: f64, cy: f64, r: f64, color: u32) {
    let x0 = (cx - r).floor().max(0.0) as i64;
    let x1 = ((cx + r).ceil() as i64).min(w as i64 - 1);
    let y0 = (cy - r).floor().max(0.0) as i64;
    let y1 = ((cy + r).ceil() as i64).min(h as i64 - 1);
    for y in y0..=y1 {
        for x in x0..=x1 {
            if (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy) <= r {
                out[y as usize * w as usize + x as usize] = color;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{sample, shown};
    use super::super::EditRequest;
    use super::*;
    use crate::window::input::steer_rect;

    #[test]
    fn the_preview_shows_each_pixel_from_where_the_rotation_sends_it() {
        use lut_core::ViewProjection;
        let (w, h) = (400u32, 300u32);
        // Each source pixel holds its own index, so the output names where it came from.
        let src: Vec<u32> = (0..w * h).collect();
        let m = horizon_rotation(4.0, -3.0);
        for proj in [ViewProjection::Rectilinear, ViewProjection::Fisheye] {
            let look = View::new(20.0, -5.0, 100.0)
                .unwrap()
                .projected(proj)
                .unwrap();
            let mut out = vec![0u32; src.len()];
            warp(&src, &mut out, w, h, &look, m);
            let cam = Camera::new(look, w, h);
            let (mut checked, mut empty) = (0, 0);
            for y in (0..h).step_by(7) {
                for x in (0..w).step_by(5) {
                    let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                    let got = out[(y * w + x) as usize];
                    let want = cam
                        .ray(px, py)
                        .and_then(|d| crate::tour::markers::place_dir(&cam, (m * d).normalize()));
                    match want
                        .filter(|p| p.0 >= 1.0 && p.1 >= 1.0)
                        .filter(|p| p.0 < f64::from(w) - 1.0 && p.1 < f64::from(h) - 1.0)
                    {
                        Some((sx, sy)) => {
                            assert!(got < w * h, "{proj} ({x}, {y}): nothing shown");
                            let (gx, gy) = (f64::from(got % w) + 0.5, f64::from(got / w) + 0.5);
                            assert!(
                                (gx - sx).abs() <= 1.0 && (gy - sy).abs() <= 1.0,
                                "{proj} ({x}, {y}): from {gx},{gy}, not {sx:.2},{sy:.2}"
                            );
                            checked += 1;
                        }
                        None if want.is_none() => {
                            assert_eq!(got, EMPTY_COLOR, "{proj} ({x}, {y})");
                            empty += 1;
                        }
                        None => {}
                    }
                }
            }
            assert!(checked > 2000, "{proj}: {checked}");
            if proj == ViewProjection::Rectilinear {
                assert!(
                    empty > 0,
                    "a turned rectilinear frame has uncovered corners"
                );
            }
        }
    }

    #[test]
    fn a_drag_on_the_line_levels_the_scene_in_one_undoable_edit() {
        let mut nav = sample();
        shown(&mut nav);
        let look = steer_rect(20.0, 0.0, 90.0);
        let (w, h) = (400, 300);
        // Off: a press is the view's.
        assert!(!nav.level_press(&look, w, h, 200.0, 150.0));
        assert_eq!(nav.level_toggle(), Ok(true));
        assert!(nav.editor.on, "the level mode is the editor's");
        // Away from the line: the view's; on it: grabbed.
        assert!(!nav.level_press(&look, w, h, 200.0, 100.0));
        let (x, y) = nav.level_line_point(&look, w, h).unwrap();
        assert!(
            (y - 150.0).abs() < 1.0,
            "a level scene's line is the view's horizon"
        );
        assert!(nav.level_press(&look, w, h, x, y));
        nav.level_drag(&look, w, h, x + 5.0, y - 10.0);
        nav.level_drag(&look, w, h, x + 10.0, y - 20.0);
        let moving = nav.level_target();
        assert!(
            moving.pitch > 0.0,
            "dragged up ahead: pitched up {moving:?}"
        );
        // While dragging the scene is not edited yet; the frame is turned.
        assert!(nav.scene().horizon.is_level());
        let scene: Vec<u32> = (0..w * h).collect();
        let mut buf = scene.clone();
        nav.level_draw(&scene, &mut buf, w, h, &look);
        assert_ne!(buf, scene);
        let (set, a) = nav.level_release(look);
        let set = set.unwrap();
        assert!((set.pitch - moving.pitch).abs() < 1e-3 && (set.roll - moving.roll).abs() < 1e-3);
        assert_eq!(nav.scene().horizon, set);
        let [TourAction::Load(src)] = &a[..] else {
            panic!("the scene reloads levelled: {a:?}");
        };
        assert_eq!(nav.horizon_for(src), Some((set.pitch, set.roll)));
        // The grabbed point stays under the cursor (to the 0.001° rounding).
        let near = level::line(set, look, w, h)
            .into_iter()
            .flatten()
            .map(|p| (p.0 - (x + 10.0)).hypot(p.1 - (y - 20.0)))
            .fold(f64::INFINITY, f64::min);
        assert!(near < 1.0, "the line passes {near} px from the cursor");
        // Undo: level again.
        nav.edit_request(EditRequest::Undo, look);
        assert!(nav.scene().horizon.is_level());
        nav.edit_request(EditRequest::Redo, look);
        assert_eq!(nav.scene().horizon, set);
        // A press and release without a move is no edit.
        let (x, y) = nav.level_line_point(&look, w, h).unwrap();
        assert!(nav.level_press(&look, w, h, x, y));
        assert_eq!(nav.level_release(look).0, None);
        nav.level_leave();
        assert!(!nav.editor.level.on && nav.editor.on);
    }
}

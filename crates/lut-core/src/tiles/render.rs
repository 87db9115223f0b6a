//! Frames from tiles: the cube scanline renderer's runs (a scanline is a 3-D line, cut
//! into face runs, each verified), each run split at the tile edges of the frame's level
//! and drawn on its tile's bordered texels with the cube kernels (`face_rows`: exact
//! positions per pixel, then the row kernels' gather and blend). A tile not decoded is
//! drawn from its nearest decoded ancestor (the run re-split at that level's tile edges),
//! so a frame never has a hole. Other output projections, and the few pixels the run
//! check leaves, are drawn per pixel with the same arithmetic (`TileStore::bilinear`).
//!
//! # Splitting a run at tile edges
//! On a run the face coordinate `u = h + h·a/m` (`a`, `m` linear in the pixel, `m > 0`) is
//! monotonic, so the pixel where it crosses a tile edge `X` solves a linear equation:
//! `a − r·m = 0` with `r = (X − h)/h`. A piece of the run on tile `(x0, y0)` is drawn as a
//! face run whose coordinates are shifted by the tile's origin: `a' = a − (x0/h)·m`,
//! `b' = b + (y0/h)·m` give `u' = u − x0`, `v' = v − y0` (the kernels clamp them into the
//! tile, whose border holds the neighbours' texels). A pixel assigned to the wrong side of
//! an edge by rounding reads the same texels through the border.

use super::id::{TileId, TileMap, TileSet};
use super::store::TileStore;
use crate::cube::{face_axes, face_of, face_uv, Face};
use crate::geom::camera::{Camera, View};
use crate::map::sample::Sampler;
use crate::render::kernel::{active, FaceBuf, FaceRun, Texels};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::Mutex;

/// What a frame from tiles did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TileFrame {
    /// The level the frame wanted (1 = coarsest).
    pub level: u32,
    /// Tiles of that level the frame read, each with its squared distance (output pixels)
    /// from the view's centre; `false`: not decoded (drawn from an ancestor).
    pub touched: Vec<(TileId, f64, bool)>,
    /// Coarser tiles the frame fell back through that are not decoded either (the
    /// ancestors of tiles it lacked), coarsest first.
    pub ancestors: Vec<TileId>,
}

impl TileFrame {
    /// Tiles the frame wanted and did not have, nearest the centre first.
    pub fn missed(&self) -> Vec<TileId> {
        let mut m: Vec<_> = self.touched.iter().filter(|t| !t.2).collect();
        m.sort_by(|a, b| a.1.total_cmp(&b.1));
        let mut out: Vec<TileId> = self.ancestors.clone();
        out.extend(m.into_iter().map(|t| t.0));
        out
    }

    /// Whether some of the frame was drawn coarser than wanted.
    pub fn coarser(&self) -> bool {
        self.touched.iter().any(|t| !t.2)
    }
}

/// The texels of the top level (the full face) per output pixel the frame's level is
/// chosen by: still (`still`), the frame's smallest footprint at 17 × 9 points (as
/// `set_still_level` for maps); moving, the footprint at the centre. Infinite when no
/// point has one.
pub fn frame_footprint(store: &TileStore, view: View, width: u32, height: u32, still: bool) -> f64 {
    let cfg = store.config();
    let cam = Camera::new(view, width.max(1), height.max(1));
    let half = cfg.cube as f64 / 2.0;
    let foot = |x: f64, y: f64| -> Option<f64> {
        let d = cam.ray(x, y)?;
        let face = face_of(d);
        let (u, v) = face_uv(face, d, half);
        let mut fp: f64 = 0.0;
        for (dx, dy) in [(1.0, 0.0), (0.0, 1.0)] {
            let d2 = cam.ray(x + dx, y + dy)?;
            if face_axes(face, d2).2 <= 0.0 {
                return None;
            }
            let (u2, v2) = face_uv(face, d2, half);
            fp = fp.max((u2 - u).abs().max((v2 - v).abs()));
        }
        fp.is_finite().then_some(fp)
    };
    let (w, h) = (width as f64, height as f64);
    if still {
        let mut m = f64::INFINITY;
        for j in 0..9 {
            for i in 0..17 {
                let x = (i as f64 / 16.0 * (w - 1.0)).max(0.0) + 0.5;
                let y = (j as f64 / 8.0 * (h - 1.0)).max(0.0) + 0.5;
                if let Some(f) = foot(x, y) {
                    m = m.min(f);
                }
            }
        }
        m
    } else {
        foot(w / 2.0, h / 2.0).unwrap_or(f64::INFINITY)
    }
}

/// The level a frame of `view` at `width × height` is drawn from. Still (`still`): the
/// coarsest level on which no pixel is magnified by more than √2 (the frame's smallest
/// footprint, at 17 × 9 points, as `set_still_level` for maps); moving: the level whose
/// texels are nearest one per pixel at the centre (⌊log2(footprint) + ½⌋ levels down).
pub fn frame_level(store: &TileStore, view: View, width: u32, height: u32, still: bool) -> u32 {
    let cfg = store.config();
    let m = frame_footprint(store, view, width, height, still);
    if !m.is_finite() || m <= 0.0 {
        return cfg.max_level;
    }
    // Levels below `first_level` are fallbacks only (Marzipano's `fallbackOnly`).
    for l in cfg.first_level()..=cfg.max_level {
        let fl = m * cfg.level_size(l) as f64 / cfg.cube as f64;
        // Where levels halve, the first with fl ≥ 1/√2 has fl in [0.71, 1.41) (a level
        // r times its parent's: [0.71, 0.71·r)).
        if fl >= std::f64::consts::FRAC_1_SQRT_2 {
            return l;
        }
    }
    cfg.max_level
}

/// Trilinear between two levels: `(fine, t)`, the frame drawn as `(1 − t)·fine + t·(fine −
/// 1)`. `fine` is the coarsest level whose texels are at least one per pixel (footprint
/// `m_l` ≥ 1, [`frame_footprint`] scaled to the level), `t = log(m_l) / log(r)` in
/// [0, 1), `r` the ratio of `fine`'s size to its parent's (2 where levels halve, so
/// `log2(m_l)`): 0 when a texel is a pixel, toward 1 as `fine` gets minified by `r`
/// (where its parent's texels are one per pixel). `t` is 0 when the top level is
/// magnified (no finer level) and on the first level a frame may use (no coarser one:
/// level 1, or the first that is not a fallback only).
pub fn trilinear_levels(
    store: &TileStore,
    view: View,
    width: u32,
    height: u32,
    still: bool,
) -> (u32, f64) {
    let cfg = store.config();
    let m = frame_footprint(store, view, width, height, still);
    if !m.is_finite() || m <= 0.0 {
        return (cfg.max_level, 0.0);
    }
    let first = cfg.first_level();
    for l in first..=cfg.max_level {
        let ml = m * cfg.level_size(l) as f64 / cfg.cube as f64;
        if ml >= 1.0 {
            let t = if l == first {
                0.0
            } else {
                let r = cfg.level_size(l) as f64 / cfg.level_size(l - 1) as f64;
                (ml.ln() / r.ln()).clamp(0.0, 1.0)
            };
            return (l, t);
        }
    }
    (cfg.max_level, 0.0)
}

/// Per-frame constants (as the cube renderer's `Rays`).
#[derive(Clone, Copy)]
struct Rays {
    b: DVec3,
    r1: DVec3,
    r2: DVec3,
    focal: f64,
    w: u32,
    h: u32,
    delta: f64,
}

impl Rays {
    fn new(view: View, w: u32, h: u32) -> Rays {
        let focal = (w as f64 / 2.0) / (view.hfov() / 2.0).tan();
        let (sp, cp) = view.pitch().sin_cos();
        let (sy, cy) = view.yaw().sin_cos();
        Rays {
            b: DVec3::new(cy, 0.0, -sy),
            r1: DVec3::new(-sp * sy, cp, -sp * cy),
            r2: DVec3::new(cp * sy, sp, cp * cy),
            focal,
            w,
            h,
            delta: 1e-9 * (focal + w as f64 + h as f64),
        }
    }
    fn dx(&self, x: usize) -> f64 {
        x as f64 + 0.5 - self.w as f64 / 2.0
    }
    fn row(&self, y: usize) -> DVec3 {
        let dy = self.h as f64 / 2.0 - (y as f64 + 0.5);
        dy * self.r1 + self.focal * self.r2
    }
}

/// A band's scratch and what it saw.
#[derive(Default)]
struct Band {
    buf: FaceBuf,
    touched: TileMap<(f64, bool)>,
    ancestors: TileSet,
    /// Pieces read at the frame's level and from an ancestor, added to the store's
    /// counters once a band (shared atomics per piece cost both threads).
    hits: u64,
    misses: u64,
}

/// One frame's fixed inputs.
struct Ctx<'a> {
    store: &'a TileStore,
    level: u32,
    bilinear: bool,
    cx: f64,
    cy: f64,
}

impl Ctx<'_> {
    fn note(&self, band: &mut Band, id: TileId, x: f64, y: f64, hit: bool) {
        let d = (x - self.cx).powi(2) + (y - self.cy).powi(2);
        let e = band.touched.entry(id).or_insert((d, hit));
        e.0 = e.0.min(d);
        if hit {
            band.hits += 1;
        } else {
            band.misses += 1;
        }
    }

    /// Draw `run` (face coordinates of level `l`) on `face` into `out` (row `y`, first
    /// pixel `x`), split at level `l`'s tile edges.
    #[allow(clippy::too_many_arguments)]
    fn run(
        &self,
        l: u32,
        face: Face,
        run: &FaceRun,
        out: &mut [u32],
        band: &mut Band,
        x: usize,
        y: usize,
    ) {
        let n = out.len();
        if n == 0 {
            return;
        }
        let cfg = self.store.config();
        let t = cfg.tile_size(l) as f64;
        let tiles = cfg.tiles_across(l);
        let at = |i: usize| {
            let dx = run.dx + i as f64;
            let (a, b, m) = (
                run.p[0] + dx * run.d[0],
                run.p[1] + dx * run.d[1],
                run.p[2] + dx * run.d[2],
            );
            let q = run.half / m;
            (run.half + a * q, run.half - b * q)
        };
        let cell = |c: f64| ((c.max(0.0) / t) as u32).min(tiles - 1);
        let ((u0, v0), (u1, v1)) = (at(0), at(n - 1));
        let mut cuts: Vec<usize> = vec![0, n];
        // The pixel where coordinate `axis` (0: u, 1: v) reaches `edge`.
        let cross = |axis: usize, edge: f64| -> Option<usize> {
            let r = (edge - run.half) / run.half;
            let (p, d) = if axis == 0 {
                (run.p[0] - r * run.p[2], run.d[0] - r * run.d[2])
            } else {
                (run.p[1] + r * run.p[2], run.d[1] + r * run.d[2])
            };
            if d == 0.0 {
                return None;
            }
            let dx = -p / d;
            let i = (dx - run.dx).ceil();
            (i.is_finite() && i > 0.0 && i < n as f64).then_some(i as usize)
        };
        for (axis, c0, c1) in [(0, cell(u0), cell(u1)), (1, cell(v0), cell(v1))] {
            for k in c0.min(c1) + 1..=c0.max(c1) {
                cuts.extend(cross(axis, k as f64 * t));
            }
        }
        cuts.sort_unstable();
        cuts.dedup();
        for w in cuts.windows(2) {
            let (s, e) = (w[0], w[1]);
            if s >= e {
                continue;
            }
            let (um, vm) = at((s + e - 1) / 2);
            let id = TileId {
                level: l as u8,
                face,
                x: cell(um),
                y: cell(vm),
            };
            let sub = FaceRun {
                dx: run.dx + s as f64,
                ..*run
            };
            self.piece(id, &sub, &mut out[s..e], band, x + s, y);
        }
    }

    /// A bilinear piece reading within a texel of its tile's edge reads the border: where
    /// that border still holds an ancestor's texels, the tiles it stands for are wanted
    /// (not hit), so a waiting frame loads them (refilling the border) and a moving one
    /// counts as coarser until they arrive.
    #[allow(clippy::too_many_arguments)]
    fn note_stale_border(
        &self,
        band: &mut Band,
        id: TileId,
        tile: &super::store::Tile,
        run: &FaceRun,
        n: usize,
        x: usize,
        y: usize,
    ) {
        let t = self.store.config().tile_size(id.level as u32) as f64;
        let at = |i: usize| {
            let dx = run.dx + i as f64;
            let (a, b, m) = (
                run.p[0] + dx * run.d[0],
                run.p[1] + dx * run.d[1],
                run.p[2] + dx * run.d[2],
            );
            let q = run.half / m;
            (run.half + a * q, run.half - b * q)
        };
        // A run on a face is a straight segment of the face: its ends bound it.
        let ((u0, v0), (u1, v1)) = (at(0), at(n.saturating_sub(1)));
        let (x0, y0) = (id.x as f64 * t, id.y as f64 * t);
        let (x1, y1) = (x0 + tile.w as f64, y0 + tile.h as f64);
        let near = u0.min(u1) < x0 + 1.0
            || u0.max(u1) > x1 - 1.0
            || v0.min(v1) < y0 + 1.0
            || v0.max(v1) > y1 - 1.0;
        if !near {
            return;
        }
        let xm = x as f64 + n as f64 / 2.0;
        let d = (xm - self.cx).powi(2) + (y as f64 + 0.5 - self.cy).powi(2);
        for &s in tile.stale_border() {
            if self.store.get(s).is_none() && !self.store.config().is_missing(s) {
                let e = band.touched.entry(s).or_insert((d, false));
                e.0 = e.0.min(d);
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn piece(
        &self,
        id: TileId,
        run: &FaceRun,
        out: &mut [u32],
        band: &mut Band,
        x: usize,
        y: usize,
    ) {
        let cfg = self.store.config();
        let l = id.level as u32;
        if cfg.is_missing(id) {
            out.fill(cfg.background);
            return;
        }
        let tile = self.store.get(id);
        if l == self.level {
            let xm = x as f64 + out.len() as f64 / 2.0;
            self.note(band, id, xm, y as f64 + 0.5, tile.is_some());
        }
        if let Some(tile) = tile {
            if self.bilinear && l == self.level && !tile.stale_border().is_empty() {
                self.note_stale_border(band, id, tile, run, out.len(), x, y);
            }
            let t = cfg.tile_size(l) as f64;
            let (kx, ky) = (id.x as f64 * t / run.half, id.y as f64 * t / run.half);
            let shifted = FaceRun {
                p: [run.p[0] - kx * run.p[2], run.p[1] + ky * run.p[2], run.p[2]],
                d: [run.d[0] - kx * run.d[2], run.d[1] + ky * run.d[2], run.d[2]],
                ..*run
            };
            let side = cfg.tile_size(l) + 1;
            let texels = Texels::new(&tile.px, side, side, false).expect("a bordered tile");
            if self.bilinear {
                active().face_rows::<true>(&texels, &shifted, out, &mut band.buf);
            } else {
                active().face_rows::<false>(&texels, &shifted, out, &mut band.buf);
            }
            return;
        }
        if l != self.level && !self.store.settled(id) {
            band.ancestors.insert(id);
        }
        if l <= 1 {
            out.fill(cfg.background);
            return;
        }
        let half = cfg.level_size(l - 1) as f64 / 2.0;
        let up = FaceRun { half, ..*run };
        self.run(l - 1, id.face, &up, out, band, x, y);
    }

    fn pixel(&self, face: Face, d: DVec3) -> u32 {
        let half = self.store.config().level_size(self.level) as f64 / 2.0;
        let (u, v) = face_uv(face, d, half);
        if self.bilinear {
            self.store.bilinear(self.level, face, u, v, true)
        } else {
            self.store.nearest(self.level, face, u, v, true)
        }
    }
}

fn margin(face: Face, d: DVec3) -> f64 {
    let (a, b, m) = face_axes(face, d);
    (m - a.abs()).min(m - b.abs())
}

/// Face changes between pixels `lo` and `hi` of a scanline (the cube renderer's search).
fn split(
    face_at: &impl Fn(usize) -> Face,
    lo: usize,
    hi: usize,
    fl: Face,
    fh: Face,
    out: &mut Vec<(usize, usize, Face)>,
) {
    if fl == fh {
        match out.last_mut() {
            Some(last) if last.2 == fl && lo <= last.1 + 1 => last.1 = last.1.max(hi),
            _ => out.push((lo, hi, fl)),
        }
        return;
    }
    if hi <= lo + 1 {
        split(face_at, lo, lo, fl, fl, out);
        split(face_at, hi, hi, fh, fh, out);
        return;
    }
    let mid = lo + (hi - lo) / 2;
    let fm = face_at(mid);
    split(face_at, lo, mid, fl, fm, out);
    split(face_at, mid, hi, fm, fh, out);
}

/// Draw `view` from the tiles of `store` at `level` into `pixels` (`width × height`,
/// row-major 0RGB). Nearest or bilinear (trilinear is drawn bilinear on the level, which
/// [`frame_level`] keeps within √2 of one texel per pixel). Rows go to rayon bands when
/// `threads`; the bytes do not depend on it.
///
/// # Panics
/// When `pixels` is not `width × height`.
pub fn render_tiles(
    store: &TileStore,
    view: View,
    sampler: Sampler,
    level: u32,
    pixels: &mut [u32],
    width: u32,
    height: u32,
) -> TileFrame {
    let (w, h) = (width as usize, height as usize);
    assert_eq!(pixels.len(), w * h, "pixels for the frame");
    let level = level.clamp(1, store.config().max_level);
    let ctx = Ctx {
        store,
        level,
        bilinear: sampler != Sampler::Nearest,
        cx: w as f64 / 2.0,
        cy: h as f64 / 2.0,
    };
    let seen: Mutex<TileMap<(f64, bool)>> = Mutex::default();
    let up: Mutex<TileSet> = Mutex::default();
    if w == 0 || h == 0 {
        return TileFrame {
            level,
            ..TileFrame::default()
        };
    }
    let rays = Rays::new(view, width, height);
    let cam = Camera::new(view, width, height);
    let rect = view.projection().is_rectilinear();
    let half = store.config().level_size(level) as f64 / 2.0;
    let rows_per = (16384 / w).clamp(1, h);
    let band_rows = |(bi, chunk): (usize, &mut [u32])| {
        let mut band = Band::default();
        let mut segs = Vec::new();
        for (r, line) in chunk.chunks_exact_mut(w).enumerate() {
            let y = bi * rows_per + r;
            if !rect {
                for (x, px) in line.iter_mut().enumerate() {
                    *px = match cam.ray(x as f64 + 0.5, y as f64 + 0.5) {
                        Some(d) => ctx.pixel(face_of(d), d),
                        None => 0,
                    };
                }
                continue;
            }
            let p = rays.row(y);
            let ray = |x: usize| p + rays.dx(x) * rays.b;
            let face_at = |x: usize| face_of(ray(x));
            segs.clear();
            split(&face_at, 0, w - 1, face_at(0), face_at(w - 1), &mut segs);
            for &(s0, s1, face) in &segs {
                let ok = |x: usize| margin(face, ray(x)) > rays.delta;
                let (mut a, mut e) = (s0, s1 + 1);
                for _ in 0..2 {
                    if a < e && !ok(a) {
                        line[a] = ctx.pixel(face_of(ray(a)), ray(a));
                        a += 1;
                    }
                    if a < e && !ok(e - 1) {
                        line[e - 1] = ctx.pixel(face_of(ray(e - 1)), ray(e - 1));
                        e -= 1;
                    }
                }
                if a >= e {
                    continue;
                }
                if !(ok(a) && ok(e - 1)) {
                    for (x, px) in line.iter_mut().enumerate().take(e).skip(a) {
                        *px = ctx.pixel(face_of(ray(x)), ray(x));
                    }
                    continue;
                }
                let (pa, pb, pm) = face_axes(face, p);
                let (ba, bb, bm) = face_axes(face, rays.b);
                let run = FaceRun {
                    p: [pa, pb, pm],
                    d: [ba, bb, bm],
                    dx: rays.dx(a),
                    half,
                };
                ctx.run(level, face, &run, &mut line[a..e], &mut band, a, y);
            }
        }
        store.count_many(band.hits, band.misses);
        up.lock()
            .unwrap_or_else(|e| e.into_inner())
            .extend(band.ancestors);
        let mut all = seen.lock().unwrap_or_else(|e| e.into_inner());
        for (id, (d, hit)) in band.touched {
            let e = all.entry(id).or_insert((d, hit));
            e.0 = e.0.min(d);
        }
    };
    pixels
        .par_chunks_mut(w * rows_per)
        .enumerate()
        .with_max_len(1)
        .for_each(band_rows);
    let mut touched: Vec<_> = seen
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .map(|(id, (d, hit))| (id, d, hit))
        .collect();
    touched.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    let mut ancestors: Vec<TileId> = up
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .collect();
    ancestors.sort();
    TileFrame {
        level,
        touched,
        ancestors,
    }
}

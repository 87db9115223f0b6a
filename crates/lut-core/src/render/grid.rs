//! The grid renderer: a per-view adaptive grid of exact map positions, interpolated with
//! the LUT renderer's span kernels. It draws every output projection (the views that are
//! not scanline-coherent, where the patent's table does not apply) and rectilinear views
//! too (`--renderer grid`), within the same 0.05 px sampling-position budget.
//!
//! # Cells
//! The image is cut into square cells of [`GRID_CELL`] pixels. A cell's *nodes* are the
//! exact map positions (Λ = λ·W/2π and the profile V, as the LUT stores them) of the
//! pixel centres at its four corners: pixel (x0, y0) and the first pixels of the next
//! cells right and below, (x0 + g, y0 + g). Inside the cell positions are interpolated
//! bilinearly, which along each pixel row is linear: every row of a cell is one span of
//! `render/kernel` (start and step in Q.16), exactly as between two table reads.
//!
//! # Splitting
//! Each cell is measured: the exact positions at the midpoints of its four edges and its
//! centre (the corners of its four children, so nothing measured is wasted when it
//! splits) against the bilinear interpolation there. From these nine points come the
//! second differences along the top edge, the middle row and the bottom edge, and along
//! the left edge, the middle column and the right edge: with second derivatives constant
//! over the cell the interpolation error is at most the largest row difference plus the
//! largest column difference (and the centre's own error). That sum is the cell's
//! *estimate*, in the angular metric of [`crate::position_error`] with the u weight
//! (cos φ / s) taken at its largest over the nine points; on elliptical and diamond maps
//! the u error is bounded as s·|ΔΛ| + |Λ|·max|ds/dv|·|ΔV| (no cancellation assumed: the
//! diamond's row scale has a kink at the equator). A cell splits into four when its
//! estimate exceeds [`GRID_CELL_BUDGET`] (0.03 px, leaving 0.02 px of the 0.05 px bound
//! for what the estimate misses and for fixed point), or when the estimate cannot be
//! trusted because the derivatives change fast over the cell:
//! * the metric's u weight varies by more than 2× over its points (near a pole of the
//!   map, where cos φ → 0),
//! * opposite edges differ in length by more than 2× (near a singular point of the view:
//!   the centre of a 360° little planet holds a hemisphere),
//! * it lies within twice its size of the edge of the valid area (below),
//! * on elliptical and diamond maps, the seam may cross it (below).
//!
//! A cell whose estimate is above the budget but within [`GRID_HALVES_LIMIT`] (twice it,
//! and trusted) becomes its four half-size children without measuring them: halving the
//! side quarters the interpolation error, so each child is within half the budget. A cell
//! of [`GRID_MIN_CELL`] (2) pixels is never measured: its four pixels are its corner and
//! the three points a measurement would take, so they are evaluated and drawn exactly.
//! The bound is not proven: it is measured, over random views of every output
//! projection on every map projection and over the hard views (`tests/views.rs`).
//!
//! # Seam, poles, the edge of the valid disc
//! * **Seam**: longitude is unwrapped per cell (each node relative to the first corner, a
//!   jump of more than half the map is one map width) and stepped continuously along the
//!   row's span; the sinks wrap u per pixel (`scanline::emit`), so no span interpolates
//!   across the map. On elliptical and diamond maps the two ends of a row are as far
//!   apart as the row is long, which depends on v: a pixel whose interpolated Λ wraps to
//!   the other end than its exact Λ is off by the change of that length over its v
//!   error, which the cell's points cannot see; cells the seam may cross are split down
//!   to exact pixels there (a line two pixels wide).
//! * **Poles**: near a pole of the map longitude turns fast and the metric's weight
//!   changes; cells around it split down to the smallest cell and the one holding the
//!   pole is evaluated exactly, as the LUT's exact zones are.
//! * **Valid area**: a fisheye or equisolid view has directions only inside a disc (its
//!   rim is the antipode of the view axis), a Pannini view with d > 1 only inside a
//!   vertical strip (its edges are where the mapping turns back). A cell entirely inside
//!   and at least twice its size from the edge is interpolated, one entirely outside is
//!   background, and the others split down to the smallest cell, which is evaluated
//!   exactly per pixel (each pixel shows its direction or the background).
//! * **Coverage** (cylindrical maps): nodes keep the map position outside the covered
//!   rows; the sinks show the background per pixel where the interpolated v leaves the
//!   map, as on the LUT path. A cell whose measured points are all far beyond the same
//!   edge of the map (and whose scale changes little) is background.
//!
//! # Cost
//! The grid is built per view, inside the frame: rows of cells run in parallel bands, each
//! band measures its cells and draws them at once (no grid is stored). The report gives
//! the exact pixels and the smallest and largest cell side (in `min_step`/`max_step`).

use super::scanline::emit;
use super::setup::{Lv, LvStep, Setup};
use super::sink::{RowSinks, Sink};
use crate::geom::accuracy::u_scale;
use crate::geom::camera::{Camera, View};
use crate::geom::fixed::to_fx;
use rayon::prelude::*;
use std::f64::consts::TAU;

/// Side of the largest grid cell, in output pixels.
pub const GRID_CELL: u32 = 32;

/// Side of the smallest grid cell, evaluated exactly: its four pixels are its corner and
/// the three points a measurement would take, so measuring it would cost more than
/// evaluating it.
pub const GRID_MIN_CELL: u32 = 2;
const _: () = assert!(GRID_MIN_CELL == 2, "Leaf::Exact holds a 2x2 cell's pixels");

/// The largest estimated sampling-position error (source pixels, angular metric) a grid
/// cell may have; above it the cell splits (see the module docs).
pub const GRID_CELL_BUDGET: f64 = 0.03;

/// A cell whose estimate is above [`GRID_CELL_BUDGET`] but at most this (and whose
/// estimate can be trusted) becomes its four half-size children without measuring them:
/// halving the side quarters the interpolation error (second derivatives unchanged), so
/// each child's estimate would be at most half the budget. This saves the measurement of
/// most leaves (their five points cost more than the rest of the build).
pub const GRID_HALVES_LIMIT: f64 = 2.0 * GRID_CELL_BUDGET;

/// What to do with a measured cell.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Verdict {
    /// One leaf.
    Accept(Leaf),
    /// Its four children, interpolated without measuring.
    Halves,
    /// Split and measure the children.
    Split,
}

/// Largest |V| a node keeps (cylindrical maps far beyond their coverage).
const V_CLAMP: f64 = 1e7;

/// An exact node: Λ and V in map pixels, and the direction (λ, φ) (for the error metric
/// and for exact pixels).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    l: f64,
    v: f64,
    lambda: f64,
    phi: f64,
    cos_phi: f64,
}

/// Where the view's projection has directions, in pixel coordinates.
#[derive(Debug, Clone, Copy)]
enum Valid {
    /// Everywhere (rectilinear, stereographic, Pannini with d ≤ 1).
    All,
    /// Within `r` of the image centre (fisheye, equisolid).
    Disc { cx: f64, cy: f64, r: f64 },
    /// Within `half` of the centre column (Pannini, d > 1).
    Strip { cx: f64, half: f64 },
}

/// How a cell lies against the valid area.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Class {
    Inside,
    Outside,
    Straddle,
}

impl Valid {
    fn of(cam: &Camera) -> Valid {
        let (cx, cy) = (cam.width as f64 / 2.0, cam.height as f64 / 2.0);
        let p = cam.projection();
        if let Some(r) = p.max_radius(cam.focal) {
            Valid::Disc { cx, cy, r }
        } else if let Some(half) = p.max_abs_px(cam.focal) {
            Valid::Strip { cx, half }
        } else {
            Valid::All
        }
    }

    /// Class of the cell whose nodes span `[x0, x0 + g] × [y0, y0 + g]` (pixel-centre
    /// coordinates) and whose pixel centres span `[x0, x0 + g − 1]` likewise: inside when
    /// every point of the node square has a direction and lies at least `2g` from the
    /// edge of the valid area (where the mapping is singular: the antipode of the view
    /// axis on a disc's rim, the turning point on a strip's edge, with derivatives
    /// growing without bound, so five points per cell would underestimate the error),
    /// outside when no pixel centre has a direction.
    fn classify(self, x0: f64, y0: f64, g: f64) -> Class {
        // Distance range of an interval [a, b] from c along one axis.
        let near = |a: f64, b: f64, c: f64| {
            if c < a {
                a - c
            } else if c > b {
                c - b
            } else {
                0.0
            }
        };
        let far = |a: f64, b: f64, c: f64| (c - a).abs().max((b - c).abs());
        let shrink = 1.0 - 1e-9;
        match self {
            Valid::All => Class::Inside,
            Valid::Disc { cx, cy, r } => {
                let (fx, fy) = (far(x0, x0 + g, cx), far(y0, y0 + g, cy));
                if fx.hypot(fy) <= (r - 2.0 * g) * shrink {
                    return Class::Inside;
                }
                let (nx, ny) = (near(x0, x0 + g - 1.0, cx), near(y0, y0 + g - 1.0, cy));
                if nx.hypot(ny) > r {
                    Class::Outside
                } else {
                    Class::Straddle
                }
            }
            Valid::Strip { cx, half } => {
                if far(x0, x0 + g, cx) <= (half - 2.0 * g) * shrink {
                    Class::Inside
                } else if near(x0, x0 + g - 1.0, cx) > half {
                    Class::Outside
                } else {
                    Class::Straddle
                }
            }
        }
    }
}

/// A point of the table's plane in f64 map pixels (the grid's [`Lv`] before rounding to
/// Q.16): a node's position, or one interpolated between nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct LvF {
    /// Λ, map pixels of longitude from the view's centre column (unwrapped next to the
    /// cell's first corner).
    l: f64,
    /// V, map pixels above the horizon.
    v: f64,
}

impl LvF {
    /// The point halfway to `b`.
    #[inline]
    fn mid(self, b: LvF) -> LvF {
        LvF {
            l: (self.l + b.l) * 0.5,
            v: (self.v + b.v) * 0.5,
        }
    }

    /// The point a fraction `t` of the way to `b`.
    #[inline]
    fn toward(self, b: LvF, t: f64) -> LvF {
        LvF {
            l: self.l + (b.l - self.l) * t,
            v: self.v + (b.v - self.v) * t,
        }
    }
}

/// An interpolated cell to draw: its top-left pixel (`x0`, `y0`), its side `g` in
/// pixels, and its corner nodes `k` (as [`Leaf::Interp`]).
#[derive(Debug, Clone, Copy)]
struct InterpCell {
    x0: u32,
    y0: u32,
    g: u32,
    k: [LvF; 4],
}

/// What a cell becomes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Leaf {
    /// Bilinear between the four corner nodes (Λ unwrapped, V): top-left, top-right,
    /// bottom-left, bottom-right.
    Interp([LvF; 4]),
    /// A cell of the smallest size: its pixels (x0, y0), (x0 + 1, y0), (x0, y0 + 1),
    /// (x0 + 1, y0 + 1) evaluated exactly (`None`: no direction, the background).
    Exact([Option<Node>; 4]),
    /// Every pixel shows the background.
    Background,
}

/// What a frame (or a band of it) rendered.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GridStats {
    /// Pixels evaluated exactly.
    pub(crate) exact_pixels: u64,
    /// Smallest and largest side of an interpolated cell (0 and 0 when none).
    pub(crate) min_cell: u32,
    pub(crate) max_cell: u32,
}

impl GridStats {
    fn empty() -> GridStats {
        GridStats {
            exact_pixels: 0,
            min_cell: u32::MAX,
            max_cell: 0,
        }
    }

    /// Count one leaf of side `g` at (x0, y0) of a `w × h` frame.
    fn add(&mut self, leaf: &Leaf, x0: u32, y0: u32, g: u32, w: u32, h: u32) {
        match leaf {
            Leaf::Interp(_) => {
                self.min_cell = self.min_cell.min(g);
                self.max_cell = self.max_cell.max(g);
            }
            Leaf::Exact(_) => {
                let (xs, ys) = ((x0 + g).min(w) - x0, (y0 + g).min(h) - y0);
                self.exact_pixels += xs as u64 * ys as u64;
            }
            Leaf::Background => {}
        }
    }

    /// 0 for the smallest cell when no cell was interpolated.
    fn finish(self) -> GridStats {
        if self.min_cell == u32::MAX {
            GridStats {
                min_cell: 0,
                ..self
            }
        } else {
            self
        }
    }

    fn merge(self, o: GridStats) -> GridStats {
        GridStats {
            exact_pixels: self.exact_pixels + o.exact_pixels,
            min_cell: self.min_cell.min(o.min_cell),
            max_cell: self.max_cell.max(o.max_cell),
        }
    }
}

/// One frame's grid: the exact mapping and the map's geometry.
pub(crate) struct Grid<'a> {
    cam: Camera,
    fr: &'a Setup,
    row_scale: &'a [i64],
    valid: Valid,
    lam_px: f64,
    w: u32,
    h: u32,
}

impl<'a> Grid<'a> {
    /// The grid of `view` on a `width × height` output, drawn through `fr` (a
    /// [`Setup`] with yaw 0: node positions include the yaw) and `row_scale` (the
    /// renderer's row scales, for elliptical and diamond maps).
    pub(crate) fn new(
        view: View,
        width: u32,
        height: u32,
        fr: &'a Setup,
        row_scale: &'a [i64],
    ) -> Grid<'a> {
        let cam = Camera::new(view, width, height);
        Grid {
            valid: Valid::of(&cam),
            cam,
            fr,
            row_scale,
            lam_px: fr.mw / TAU,
            w: width,
            h: height,
        }
    }

    /// The exact node at pixel-centre coordinates (x, y), or `None` without a direction.
    #[inline]
    fn node(&self, x: f64, y: f64) -> Option<Node> {
        let d = self.cam.ray(x, y)?;
        // λ = atan2(X, Z), φ = atan2(Y, √(X² + Z²)) as `dir_to_lat_long`, with atan where
        // the second argument is positive (the same angle to an ulp, at about half the
        // instructions: the build is mostly these calls) and cos φ from the vector (the
        // error metric's weight).
        let horiz = (d.x * d.x + d.z * d.z).sqrt();
        let lambda = if d.z > 0.0 {
            (d.x / d.z).atan()
        } else {
            d.x.atan2(d.z)
        };
        let phi = if horiz > 0.0 {
            (d.y / horiz).atan()
        } else {
            d.y.atan2(horiz)
        };
        let len = (horiz * horiz + d.y * d.y).sqrt();
        let v = self
            .fr
            .proj
            .profile(phi, self.fr.mw, self.fr.mh)
            .clamp(-V_CLAMP, V_CLAMP);
        Some(Node {
            l: lambda * self.lam_px,
            v,
            lambda,
            phi,
            cos_phi: if len > 0.0 { horiz / len } else { 0.0 },
        })
    }

    /// Λ of `l` unwrapped next to `reference` (the same direction, within half a map).
    #[inline]
    fn unwrap(&self, l: f64, reference: f64) -> f64 {
        let w = self.fr.mw;
        l + ((reference - l) / w).round() * w
    }

    /// True when the seam (Λ = ±W/2, where `emit` wraps an elliptical or diamond row)
    /// may pass through a cell whose points' Λ (unwrapped next to `r`) are `pts`: such a
    /// cell is split down to exact pixels. On these maps the two ends of a row lie at
    /// distances from the centre that depend on the row, so a pixel whose interpolated
    /// Λ wraps on the other side of the seam from its exact Λ is off by the change of the
    /// row's length over its v error, which the cell's points do not see (the metric of
    /// [`crate::position_error`] wraps at the exact row's length). The margin covers the
    /// interpolation error of Λ, up to budget / cos φ.
    fn crosses_seam(&self, pts: &[&Node; 9], r: f64) -> bool {
        let (mut lo, mut hi, mut cos_min) = (f64::INFINITY, f64::NEG_INFINITY, 1.0f64);
        for n in pts {
            let l = self.unwrap(n.l, r);
            lo = lo.min(l);
            hi = hi.max(l);
            cos_min = cos_min.min(n.cos_phi);
        }
        let margin = 1.0 + 2.0 * GRID_CELL_BUDGET / cos_min.max(1e-9);
        let half = self.fr.mw * 0.5;
        // An odd multiple of W/2 within [lo − margin, hi + margin].
        let k = ((lo - margin - half) / self.fr.mw).ceil();
        half + k * self.fr.mw <= hi + margin
    }

    /// True when every measured point of a cell is beyond the same edge of a cylindrical
    /// map by a wide margin (background, whatever the interpolation error; asked only of
    /// cells whose scale changes little, so no covered band hides between the points).
    fn all_uncovered(&self, pts: &[&Node]) -> bool {
        if self.fr.proj.full_sphere() {
            return false;
        }
        let h = self.fr.mh;
        let margin = h * 0.25 + 16.0;
        let above = pts.iter().all(|n| n.v > h * 0.5 + margin);
        let below = pts.iter().all(|n| n.v < -h * 0.5 - margin);
        above || below
    }

    /// Measure the cell at (x0, y0) of side g with corner nodes `c` and emit its leaves
    /// through `leaf(x0, y0, g, leaf)`.
    fn cell(
        &self,
        x0: u32,
        y0: u32,
        g: u32,
        c: [Option<Node>; 4],
        leaf: &mut impl FnMut(u32, u32, u32, Leaf),
    ) {
        if x0 >= self.w || y0 >= self.h {
            return;
        }
        let (xa, ya, gf) = (x0 as f64 + 0.5, y0 as f64 + 0.5, g as f64);
        let class = self.valid.classify(xa, ya, gf);
        if class == Class::Outside {
            return leaf(x0, y0, g, Leaf::Background);
        }
        let hf = gf * 0.5;
        if g <= GRID_MIN_CELL {
            // The smallest cell's four pixels are its corner and the three points a
            // measurement would take: evaluate them and show them exactly.
            let px = [
                c[0],
                self.node(xa + hf, ya),
                self.node(xa, ya + hf),
                self.node(xa + hf, ya + hf),
            ];
            return leaf(x0, y0, g, Leaf::Exact(px));
        }
        // Top, left, centre, right, bottom: the children's new corners.
        let m = [
            self.node(xa + hf, ya),
            self.node(xa, ya + hf),
            self.node(xa + hf, ya + hf),
            self.node(xa + gf, ya + hf),
            self.node(xa + hf, ya + gf),
        ];
        let verdict = if class == Class::Inside {
            self.interpolate(&c, &m)
        } else {
            Verdict::Split
        };
        if let Verdict::Accept(l) = verdict {
            return leaf(x0, y0, g, l);
        }
        let hg = g / 2;
        let [top, left, centre, right, bottom] = m;
        let children = [
            (x0, y0, [c[0], top, left, centre]),
            (x0 + hg, y0, [top, c[1], centre, right]),
            (x0, y0 + hg, [left, centre, c[2], bottom]),
            (x0 + hg, y0 + hg, [centre, right, bottom, c[3]]),
        ];
        for (cx, cy, k) in children {
            if verdict == Verdict::Halves {
                // The parent's estimate predicts a quarter of it for each half-size child
                // (within half the budget): interpolated without measuring it.
                if cx < self.w && cy < self.h {
                    leaf(cx, cy, hg, self.leaf_of(&k));
                }
            } else {
                self.cell(cx, cy, hg, k, leaf);
            }
        }
    }

    /// The interpolated leaf of corner nodes `k` (all with a direction), Λ unwrapped next
    /// to the first.
    fn leaf_of(&self, k: &[Option<Node>; 4]) -> Leaf {
        let r = k[0].map_or(0.0, |n| n.l);
        let at = |n: &Option<Node>| {
            n.map_or(LvF { l: r, v: 0.0 }, |n| LvF {
                l: self.unwrap(n.l, r),
                v: n.v,
            })
        };
        Leaf::Interp([at(&k[0]), at(&k[1]), at(&k[2]), at(&k[3])])
    }

    /// What to do with a cell (see the module docs): one interpolated (or background)
    /// leaf if its estimate is within budget and can be trusted; its four children as
    /// leaves if the estimate is within [`GRID_HALVES_LIMIT`]; else split and measure.
    fn interpolate(&self, c: &[Option<Node>; 4], m: &[Option<Node>; 5]) -> Verdict {
        let [Some(c0), Some(c1), Some(c2), Some(c3)] = *c else {
            return Verdict::Split;
        };
        let [Some(top), Some(left), Some(centre), Some(right), Some(bottom)] = *m else {
            return Verdict::Split;
        };
        let pts = [&c0, &c1, &c2, &c3, &top, &left, &centre, &right, &bottom];
        let p = self.fr.proj;
        // The metric's weight of u differences (cos φ / s), at its largest over the
        // cell's points: the errors below are weighted by it, not by each point's own.
        let (mut w_max, mut w_min) = (0.0f64, f64::INFINITY);
        for n in pts {
            // cos φ / s(φ): cos φ on rectangular maps (s = 1).
            let w = if self.fr.scaled {
                u_scale(p, n.phi)
            } else {
                n.cos_phi
            };
            w_max = w_max.max(w);
            w_min = w_min.min(w);
        }
        let r = c0.l;
        let k = |n: &Node| LvF {
            l: self.unwrap(n.l, r),
            v: n.v,
        };
        let mid = LvF::mid;
        // Weighted distance between the exact position of `e` and the (Λ, V) `got`.
        // Weighted distance between the exact position of `e` and the (Λ, V) `got`. On
        // elliptical and diamond maps u = W/2 + s(v)·Λ: the u error is bounded by
        // s·|ΔΛ| + |Λ|·max|ds/dv|·|ΔV| rather than taken with its sign (the diamond's
        // s has a kink at the equator, where the two terms cancel on one side of it and
        // add on the other); seam-crossing cells are split before (`crosses_seam`).
        let half = self.fr.mw * 0.5;
        let ds_dv = p.row_scale_coupling(self.fr.mw, self.fr.mh) / half;
        let err = |e: &Node, got: LvF| {
            let LvF { l: el, v: ev } = k(e);
            let (dl, dv) = ((got.l - el).abs(), (got.v - ev).abs());
            let du = if self.fr.scaled {
                let a = if el > half || el <= -half {
                    half - (half - el).rem_euclid(self.fr.mw)
                } else {
                    el
                };
                p.row_scale(e.phi) * dl + a.abs() * ds_dv * dv
            } else {
                dl
            };
            let du = du * w_max;
            (du * du + dv * dv).sqrt()
        };
        let [k0, k1, k2, k3] = [k(&c0), k(&c1), k(&c2), k(&c3)];
        // Second differences along the rows (top edge, middle row, bottom edge) and the
        // columns (left, middle, right): the interpolation error of each line's middle.
        let ex = err(&top, mid(k0, k1))
            .max(err(&centre, mid(k(&left), k(&right))))
            .max(err(&bottom, mid(k2, k3)));
        let ey = err(&left, mid(k0, k2))
            .max(err(&centre, mid(k(&top), k(&bottom))))
            .max(err(&right, mid(k1, k3)));
        let e_centre = err(&centre, mid(mid(k0, k1), mid(k2, k3)));
        let estimate = e_centre.max(ex + ey);
        // The estimate assumes derivatives that change little over the cell. Near a pole
        // of the map the metric's weight changes fast (cos φ → 0), and near a singular
        // point of the view (the centre of a 360° little planet holds a hemisphere) the
        // scale does: split such cells rather than trust five points.
        let len = |a: LvF, b: LvF| {
            let (du, dv) = ((b.l - a.l) * w_max, b.v - a.v);
            (du * du + dv * dv).sqrt()
        };
        let even = |a: f64, b: f64| a.max(b) <= 2.0 * a.min(b) + 0.01;
        let smooth = w_max <= 2.0 * w_min
            && even(len(k0, k1), len(k2, k3))
            && even(len(k0, k2), len(k1, k3));
        if !smooth || (self.fr.scaled && self.crosses_seam(&pts, r)) {
            return Verdict::Split;
        }
        if self.all_uncovered(&pts) {
            return Verdict::Accept(Leaf::Background);
        }
        // NaN fails both.
        if estimate <= GRID_CELL_BUDGET {
            Verdict::Accept(Leaf::Interp([k0, k1, k2, k3]))
        } else if estimate <= GRID_HALVES_LIMIT {
            Verdict::Halves
        } else {
            Verdict::Split
        }
    }

    /// Measure and draw the band of cells whose top row is `y0` into `rows` (its output
    /// rows, `w` wide) through `sinks`.
    fn band<R: RowSinks>(
        &self,
        y0: u32,
        rows: &mut [R::Px],
        sinks: &R,
        footprint: bool,
    ) -> GridStats {
        let w = self.w as usize;
        let mut stats = GridStats::empty();
        self.visit_band(y0, &mut |x0, cy0, cg, leaf| {
            stats.add(&leaf, x0, cy0, cg, self.w, self.h);
            let ys = (cy0 - y0) as usize..((cy0 + cg).min(self.h) - y0) as usize;
            let xs = x0 as usize..((x0 + cg).min(self.w)) as usize;
            match leaf {
                Leaf::Interp(k) => {
                    let cell = InterpCell {
                        x0,
                        y0: cy0,
                        g: cg,
                        k,
                    };
                    self.draw_interp(rows, w, y0, cell, sinks, footprint);
                }
                Leaf::Exact(px) => {
                    for r in ys {
                        let y = y0 as usize + r;
                        let mut s = sinks.sink(&mut rows[r * w..(r + 1) * w], y);
                        for x in xs.clone() {
                            let i = (x - x0 as usize) + 2 * (y - cy0 as usize);
                            let uv = px[i].and_then(|n| {
                                self.fr.proj.uv(n.lambda, n.phi, self.fr.mw, self.fr.mh)
                            });
                            s.exact(x, uv);
                        }
                    }
                }
                Leaf::Background => {
                    for r in ys {
                        let mut s = sinks.sink(&mut rows[r * w..(r + 1) * w], y0 as usize + r);
                        for x in xs.clone() {
                            s.background(x);
                        }
                    }
                }
            }
        });
        stats
    }

    /// Measure the cells of the band whose top row is `y0`, calling `leaf` for each.
    fn visit_band(&self, y0: u32, leaf: &mut impl FnMut(u32, u32, u32, Leaf)) {
        let g = GRID_CELL;
        let cells = self.w.div_ceil(g);
        let node_row = |y: u32| -> Vec<Option<Node>> {
            (0..=cells)
                .map(|i| self.node((i * g) as f64 + 0.5, y as f64 + 0.5))
                .collect()
        };
        let (top, bottom) = (node_row(y0), node_row(y0 + g));
        for i in 0..cells as usize {
            let corners = [top[i], top[i + 1], bottom[i], bottom[i + 1]];
            self.cell(i as u32 * g, y0, g, corners, leaf);
        }
    }

    /// Measure every cell of the frame without drawing: the grid's per-view build alone
    /// (what `viewer bench` times), in parallel bands when `threads`.
    pub(crate) fn build(&self, threads: bool) -> GridStats {
        let run = |b: u32| {
            let mut stats = GridStats::empty();
            self.visit_band(b * GRID_CELL, &mut |x0, y0, g, leaf| {
                stats.add(&leaf, x0, y0, g, self.w, self.h);
            });
            stats
        };
        let bands = self.h.div_ceil(GRID_CELL);
        let stats = if threads {
            // One band per task: the threads share the work to the last band
            // (`rows::rows_per_task`).
            (0..bands)
                .into_par_iter()
                .with_max_len(1)
                .map(run)
                .reduce(GridStats::empty, GridStats::merge)
        } else {
            (0..bands)
                .map(run)
                .fold(GridStats::empty(), GridStats::merge)
        };
        stats.finish()
    }

    /// Draw an interpolated cell: each of its rows one span from the left edge's
    /// position to (one pixel short of) the right edge's.
    fn draw_interp<R: RowSinks>(
        &self,
        rows: &mut [R::Px],
        w: usize,
        band_y0: u32,
        cell: InterpCell,
        sinks: &R,
        footprint: bool,
    ) {
        let InterpCell { x0, y0, g, k } = cell;
        let gf = g as f64;
        let m = (x0 + g).min(self.w) - x0;
        let fp = if footprint {
            // The larger per-pixel step of the cell, along x or y, in map pixels.
            let d = |a: LvF, b: LvF| (b.l - a.l).abs().max((b.v - a.v).abs());
            d(k[0], k[1])
                .max(d(k[0], k[2]))
                .max(d(k[2], k[3]))
                .max(d(k[1], k[3]))
                / gf
        } else {
            0.0
        };
        for y in y0..(y0 + g).min(self.h) {
            let t = (y - y0) as f64 / gf;
            let (left, right) = (k[0].toward(k[2], t), k[1].toward(k[3], t));
            let r = (y - band_y0) as usize;
            let mut s = sinks.sink(&mut rows[r * w..(r + 1) * w], y as usize);
            if footprint {
                s.set_footprint(fp);
            }
            emit(
                self.fr,
                self.row_scale,
                x0 as i64,
                m as i64,
                Lv {
                    l: to_fx(left.l),
                    v: to_fx(left.v),
                },
                LvStep {
                    dl: to_fx((right.l - left.l) / gf),
                    dv: to_fx((right.v - left.v) / gf),
                },
                &mut s,
            );
        }
    }

    /// Render the whole frame `out` (`w × h`, row-major) through `sinks`, in parallel
    /// bands of cells when `threads`. `footprint`: tell the sinks each cell's footprint
    /// (trilinear).
    pub(crate) fn render<R: RowSinks>(
        &self,
        out: &mut [R::Px],
        sinks: &R,
        threads: bool,
        footprint: bool,
    ) -> GridStats {
        let band_len = GRID_CELL as usize * self.w as usize;
        let run = |(b, rows): (usize, &mut [R::Px])| {
            self.band(b as u32 * GRID_CELL, rows, sinks, footprint)
        };
        let stats = if threads {
            out.par_chunks_mut(band_len)
                .enumerate()
                .with_max_len(1)
                .map(run)
                .reduce(GridStats::empty, GridStats::merge)
        } else {
            out.chunks_mut(band_len)
                .enumerate()
                .map(run)
                .fold(GridStats::empty(), GridStats::merge)
        };
        stats.finish()
    }
}

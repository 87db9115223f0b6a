//! The scanline-coherent look-up table (US 5,748,194, FIGS. 5-8B).
//!
//! ## Surface and coordinates
//! The table lives on a surface of extrusion concentric with the sphere whose axis is
//! parallel to the screen scanlines (the camera's X axis, in the yaw-0 frame):
//!
//! * [`Surface::Cylinder`] (FIGS. 5-7): a point is `(t, sin a, cos a)`; the row coordinate
//!   is the angle `a` about the axis, the column coordinate the distance `t` along it.
//!   A screen scanline at height `Y` under pitch θ is the row `a = θ + atan(Y/f)` and its
//!   pixels are `t = X / √(Y² + f²)`: one row, one scale factor per scanline. The cylinder
//!   allows a full 360° of pitch.
//! * [`Surface::Plane`] (FIG. 8A): the plane `z = 1`; a point is `(x, y, 1)`, rows are
//!   `y = tan a`, columns `x = t / cos a`. It cannot show a scanline at |a| ≥ 90°; such
//!   scanlines (and everything beyond the table) fall back to exact evaluation.
//! * [`Surface::Diamond`] (FIG. 8B): an extruded diamond `|y| + |z| = 1`, four planar
//!   faces; in the stored face `y + z = 1` a point is `(x, r, 1 − r)`. The scanline of
//!   angle a meets it at the row `r = sin a / (sin a + cos a)` and its pixels are at
//!   `x = t / (sin a + cos a)`: again one row and one scale per scanline, and a full
//!   360° of pitch with planar faces. Its grid step is 1/√2 of the cylinder's (so its
//!   columns are nowhere coarser in t; see `DIAMOND_STEP`).
//!
//! Each entry holds the environment-map indices of its surface point for the map's
//! projection, `Λ = λ · W / 2π` and `V = profile(φ)` (see [`crate::Projection`]), as
//! `i32` **Q15.16** fixed point.
//!
//! ## One-eighth symmetry (FIG. 6E, region 681)
//! Only `a ∈ [0, π/2]`, `t ≥ 0` is stored. The other seven regions follow by sign and
//! reflection: `t → −t` negates Λ; `a → −a` negates V; `a → π − a` (behind the viewer)
//! maps Λ to `W/2 − Λ`. For the plane only the first two apply (a quarter is stored).
//! The diamond's point for a is the cylinder's direction scaled, so the same eighth
//! (`r ∈ [0, 1]`, `x ≥ 0`) and the same three rules hold.
//!
//! ## Accuracy bookkeeping
//! At build time every table cell is checked against the exact map. Cells whose bilinear
//! interpolation error exceeds [`TABLE_ERROR_BUDGET`] (only those near the poles, where
//! longitude turns fast) are recorded per row band as an *exact zone*: the renderer
//! evaluates pixels there directly instead of reading the table.
//!
//! A cell is checked by an analytic bound when it can be: bilinear interpolation errs by
//! at most `step²/8 · (sup|f_rr| + sup|f_tt|)`, and the second derivatives of λ and φ on
//! the surface have closed forms whose worst case over a cell is at one of its corners
//! (see `CellGeom`). Cells (first in blocks of 16) whose bound is within 90 % of the
//! budget are proven and not measured; the others — near the poles, and near a cylinder
//! map's top edge — are measured against the exact map at five points. The zones are the
//! same as measuring everything (a unit test compares both for every projection, surface
//! and table kind); for an 8192-wide map 1.4 % of the wide table's cells and 0.6 % of the
//! high table's are measured. The bounds are derived for the cylinder and the plane (in
//! `bounds.rs`); the diamond's faces have none yet, so every diamond cell is measured
//! (its build takes about ten times the cylinder's).

mod bounds;

use crate::geom::projection::Projection;
use crate::named::Named;
use bounds::{CellBounds, PROOF_BLOCK};
#[cfg(test)]
use bounds::{CellGeom, PROVEN_LIMIT};
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// Largest sampling-position error, in source pixels (angular metric, see
/// [`crate::position_error`]), the table's own bilinear interpolation may add outside the
/// exact zones.
pub const TABLE_ERROR_BUDGET: f64 = 0.02;

/// The surface of extrusion the table is built on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Surface {
    /// The cylinder of FIGS. 5-7 (full 360° of pitch; the default).
    Cylinder,
    /// The planar table of FIG. 8A.
    Plane,
    /// The extruded diamond of FIG. 8B: four planar faces, a full 360° of pitch.
    Diamond,
}

impl Surface {
    /// Name used on the command line (see [`crate::Named`]).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }
}

impl Named for Surface {
    const ALL: &'static [Self] = &[Surface::Cylinder, Surface::Plane, Surface::Diamond];
    fn name(self) -> &'static str {
        match self {
            Surface::Cylinder => "cylinder",
            Surface::Plane => "plane",
            Surface::Diamond => "diamond",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Surface::Cylinder => "Cylinder (FIGS. 5-7)",
            Surface::Plane => "Plane (FIG. 8A)",
            Surface::Diamond => "Extruded diamond (FIG. 8B): planar faces, full pitch",
        }
    }
}

/// Which of the two tables (patent claim 5: one permitting a wider view, one finer).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TableKind {
    /// The wide-FOV table: columns up to `tan(75°)` (hfov 150° without fallback).
    Wide,
    /// The high-resolution table: half the grid step, columns up to `tan(31°)`.
    High,
}

/// Resolution of a table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableSpec {
    /// The surface.
    pub surface: Surface,
    /// Grid step of both coordinates (radians of `a`, or units of `t`; plane: units).
    pub step: f64,
    /// Largest row coordinate stored (`π/2` for the cylinder).
    pub row_max: f64,
    /// Largest column coordinate stored.
    pub col_max: f64,
}

impl TableSpec {
    /// The default resolution for a map `map_w` pixels wide.
    ///
    /// The step is chosen so that near a pole the table error stays under
    /// [`TABLE_ERROR_BUDGET`] down to ~0.15 rad from the pole (error ≈ (W/2π)·Δ²/(8ρ) in
    /// the angular metric), clamped to [0.0005, 0.01]; the high table halves it.
    pub fn default_for(surface: Surface, kind: TableKind, map_w: u32) -> TableSpec {
        let w = map_w.max(2) as f64;
        let base = (8.0 * TABLE_ERROR_BUDGET * 0.15 * TAU / w)
            .sqrt()
            .clamp(0.0005, 0.01);
        let (step, hfov_max) = match kind {
            TableKind::Wide => (base, 150f64),
            TableKind::High => (base * 0.5, 62.0),
        };
        let t_max = (hfov_max.to_radians() / 2.0).tan();
        match surface {
            Surface::Cylinder => TableSpec {
                surface,
                step,
                row_max: FRAC_PI_2,
                col_max: t_max,
            },
            Surface::Diamond => TableSpec {
                surface,
                step: step * DIAMOND_STEP,
                row_max: 1.0,
                // x = t / (sin a + cos a) ≤ t.
                col_max: t_max,
            },
            Surface::Plane => {
                // The plane stores |a| <= 60 deg (wide) / 45 deg (high): beyond, exact.
                let a_max: f64 = match kind {
                    TableKind::Wide => 60f64.to_radians(),
                    TableKind::High => 45f64.to_radians(),
                };
                let t_max = t_max.min(60f64.to_radians().tan()); // hfov <= 120
                TableSpec {
                    surface,
                    step,
                    row_max: a_max.tan(),
                    col_max: t_max / a_max.cos(),
                }
            }
        }
    }
}

/// A built table for one map geometry (width, height, projection) and one [`TableSpec`].
#[derive(Clone)]
pub struct LutTable {
    spec: TableSpec,
    projection: Projection,
    map_w: u32,
    map_h: u32,
    /// Number of row nodes (rows = bands + 1).
    rows: usize,
    /// Number of column nodes.
    cols: usize,
    inv_step: f64,
    /// (Λ, V) per node, Q15.16, row-major.
    entries: Vec<[i32; 2]>,
    /// Per row band: column coordinate at and below which pixels are evaluated exactly
    /// (negative: none).
    zone: Vec<f32>,
    /// Largest measured cell error outside the exact zones (source pixels).
    max_cell_error: f64,
}

impl std::fmt::Debug for LutTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LutTable")
            .field("spec", &self.spec)
            .field("rows", &self.rows)
            .field("cols", &self.cols)
            .field("bytes", &self.bytes())
            .finish()
    }
}

/// Largest |V| stored (Q15.16 holds ±32767); cylinder maps far beyond coverage clamp here.
const V_CLAMP: f64 = 32000.0;

/// The `(y, z)` direction components shared by a whole table row (the column coordinate
/// is the `x` component): `(sin a, cos a)` on the cylinder, `(row, 1)` on the plane,
/// `(row, 1 − row)` on the diamond's face `y + z = 1`.
#[inline]
fn row_yz(surface: Surface, row: f64) -> (f64, f64) {
    match surface {
        Surface::Cylinder => row.sin_cos(),
        Surface::Plane => (row, 1.0),
        Surface::Diamond => (row, 1.0 - row),
    }
}

/// The diamond's grid step relative to the cylinder's: a step of the diamond's column
/// coordinate `x = t/(sin a + cos a)` is up to √2 steps of `t` (at a = 45°), and one of
/// its row coordinate `r = sin a/(sin a + cos a)` up to two of the angle a; at 1/√2 of
/// the cylinder's step the columns are nowhere coarser than the cylinder's. Measured on
/// an 8k map (wide table, hfov 90 views): at the cylinder's step the table is 1.6 MB but
/// 4.2 % of pixels fall in exact zones, at 1/√2 3.2 MB and 0.5 %, at ½ 6.4 MB and 0.1 %
/// (the cylinder: 2.5 MB, 1.3 %).
const DIAMOND_STEP: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// Exact (Λ, V, φ) of the direction `(x, y, z)`, in map pixels, before fixed-point rounding.
#[inline]
fn entry_of_dir(p: Projection, w: f64, h: f64, x: f64, y: f64, z: f64) -> (f64, f64, f64) {
    let lambda = atan2_pos(x, z);
    let phi = atan2_pos(y, (x * x + z * z).sqrt());
    let big_l = lambda / TAU * w;
    let big_v = p.profile(phi, w, h).clamp(-V_CLAMP, V_CLAMP);
    (big_l, big_v, phi)
}

/// Exact (Λ, V, φ) of a surface point, in map pixels, before fixed-point rounding.
#[inline]
fn exact_entry(
    surface: Surface,
    p: Projection,
    w: f64,
    h: f64,
    row: f64,
    col: f64,
) -> (f64, f64, f64) {
    let (y, z) = row_yz(surface, row);
    entry_of_dir(p, w, h, col, y, z)
}

/// `atan2(y, x)`, as `atan(y / x)` when `x > 0`: the same angle to an ulp or two, and
/// about 1.5× faster than `atan2` (the table build is mostly these calls).
#[inline]
fn atan2_pos(y: f64, x: f64) -> f64 {
    if x > 0.0 {
        (y / x).atan()
    } else {
        y.atan2(x)
    }
}

/// Q15.16 of a map coordinate (saturating; NaN gives 0).
///
/// Rounds to nearest (ties to even) by adding 1.5·2⁵²: for |y| ≤ 2³¹ the sum's unit in the
/// last place is 1, so it is rounded to an integer, and its low 32 mantissa bits are that
/// integer in two's complement. `f64::round` is a library call on the baseline x86-64
/// target, and a saturating `as i32` another ~20 instructions: together 15 % of the build.
#[inline]
fn q16(x: f64) -> i32 {
    const MAGIC: f64 = 6755399441055744.0;
    let y = (x * 65536.0).clamp(i32::MIN as f64, i32::MAX as f64);
    if y.is_nan() {
        return 0;
    }
    (y + MAGIC).to_bits() as u32 as i32
}

impl LutTable {
    /// Build the table for a map of `map_w × map_h` in `projection` (rows in parallel).
    ///
    /// The cells are then checked for the exact zones: by an analytic error bound where it
    /// proves a cell within budget, else by measuring it (see the module doc).
    /// The table must fit Q15.16: maps up to 131068 pixels wide.
    pub fn build(spec: TableSpec, projection: Projection, map_w: u32, map_h: u32) -> LutTable {
        LutTable::build_checked(spec, projection, map_w, map_h, ZoneCheck::Bounded)
    }

    /// [`LutTable::build`] with a choice of how the cells are checked (tests compare both).
    fn build_checked(
        spec: TableSpec,
        projection: Projection,
        map_w: u32,
        map_h: u32,
        check: ZoneCheck,
    ) -> LutTable {
        let rows = ((spec.row_max / spec.step).ceil() as usize).max(1) + 1;
        let cols = ((spec.col_max / spec.step).ceil() as usize).max(1) + 1;
        // Use exactly `step` so node r is at r*step; the last node may pass row_max a bit.
        let step = spec.step;
        let (w, h) = (map_w as f64, map_h as f64);
        let mut entries = vec![[0i32; 2]; rows * cols];
        entries
            .par_chunks_mut(cols)
            .enumerate()
            .for_each(|(r, line)| {
                // The row's (y, z) once per row: the cylinder's sin/cos is not per node.
                let (y, z) = row_yz(spec.surface, r as f64 * step);
                for (k, e) in line.iter_mut().enumerate() {
                    let (l, v, _) = entry_of_dir(projection, w, h, k as f64 * step, y, z);
                    *e = [q16(l), q16(v)];
                }
            });
        let mut table = LutTable {
            spec,
            projection,
            map_w,
            map_h,
            rows,
            cols,
            inv_step: 1.0 / step,
            entries,
            zone: vec![-1.0; rows - 1],
            max_cell_error: 0.0,
        };
        table.measure_zones(check);
        table
    }

    /// Check every cell against the exact map; record the exact zone of each band.
    ///
    /// With [`ZoneCheck::Bounded`] a cell whose analytic error bound ([`CellBounds`]) is
    /// at most [`PROVEN_LIMIT`] is not measured: its error is at most the bound, so it
    /// cannot be above [`TABLE_ERROR_BUDGET`] at any point, let alone at the five measured
    /// ones, and the zones come out identical to measuring everything. Its bound stands in
    /// for its measured error in [`LutTable::max_cell_error`].
    fn measure_zones(&mut self, check: ZoneCheck) {
        let (w, h) = (self.map_w as f64, self.map_h as f64);
        let step = 1.0 / self.inv_step;
        let p = self.projection;
        let surface = self.spec.surface;
        let cols = self.cols;
        let entries = &self.entries;
        let bounds = CellBounds::new(surface, p, w, h, step, check);
        // The largest error of cell (b, k) at the five measured points.
        let measure = |b: usize, k: usize| {
            let n = |rr: usize, kk: usize| {
                let e = entries[rr * cols + kk];
                (e[0] as f64 / 65536.0, e[1] as f64 / 65536.0)
            };
            let (e00, e01, e10, e11) = (n(b, k), n(b, k + 1), n(b + 1, k), n(b + 1, k + 1));
            let mut cell = 0.0f64;
            for (fr, fc) in MEASURE_POINTS {
                let row = (b as f64 + fr) * step;
                let col = (k as f64 + fc) * step;
                let (el, ev, phi) = exact_entry(surface, p, w, h, row, col);
                let bl = |a: f64, bb: f64, c: f64, d: f64| {
                    let top = a + (bb - a) * fc;
                    let bot = c + (d - c) * fc;
                    top + (bot - top) * fr
                };
                let il = bl(e00.0, e01.0, e10.0, e11.0);
                let iv = bl(e00.1, e01.1, e10.1, e11.1);
                cell = cell.max(entry_error(p, w, h, (el, ev, phi), (il, iv)));
            }
            cell
        };
        let results: Vec<(f32, f64)> = (0..self.rows - 1)
            .into_par_iter()
            .map(|b| {
                let mut zone = -1.0f32;
                let mut worst_ok = 0.0f64;
                let mut errs = Vec::with_capacity(cols);
                let band = bounds.band(b);
                let mut k = 0;
                while k < cols - 1 {
                    // A block of cells proven at once (its bounds hold for each cell in it).
                    let k_end = (k + PROOF_BLOCK).min(cols - 1);
                    if let Some(bound) = band.as_ref().and_then(|band| band.cells(k, k_end)) {
                        errs.resize(k_end, bound);
                        k = k_end;
                        continue;
                    }
                    for k in k..k_end {
                        let cell = match band.as_ref().and_then(|band| band.cells(k, k + 1)) {
                            Some(bound) => bound,
                            None => measure(b, k),
                        };
                        errs.push(cell);
                        if cell > TABLE_ERROR_BUDGET {
                            zone = ((k + 1) as f64 * step) as f32;
                        }
                    }
                    k = k_end;
                }
                if zone < 0.0 {
                    worst_ok = errs.iter().fold(0.0, |a, &e| a.max(e));
                } else {
                    for (k, e) in errs.iter().enumerate() {
                        if (k as f64 * step) as f32 >= zone {
                            worst_ok = worst_ok.max(*e);
                        }
                    }
                }
                (zone, worst_ok)
            })
            .collect();
        for (b, (z, e)) in results.into_iter().enumerate() {
            self.zone[b] = z;
            self.max_cell_error = self.max_cell_error.max(e);
        }
    }

    /// The spec this table was built with.
    pub fn spec(&self) -> TableSpec {
        self.spec
    }
    /// The projection the entries are for.
    pub fn projection(&self) -> Projection {
        self.projection
    }
    /// Map size the entries are for.
    pub fn map_size(&self) -> (u32, u32) {
        (self.map_w, self.map_h)
    }
    /// Row and column node counts.
    pub fn dims(&self) -> (usize, usize) {
        (self.rows, self.cols)
    }
    /// Bytes held by the table (entries and zone list).
    pub fn bytes(&self) -> usize {
        self.entries.len() * std::mem::size_of::<[i32; 2]>() + self.zone.len() * 4
    }
    /// Bytes the same table would take without the symmetry folding: the same grid step,
    /// entry size and zone list over the full ranges of both coordinates — rows over the
    /// whole circle `a ∈ [−π, π]` for the cylinder (`±row_max` for the plane), columns
    /// over `±col_max` — on the nodes `j·step` with both range ends included.
    ///
    /// The folded cylinder table is one eighth of this plus its fold lines (the nodes at
    /// `t = 0` and `a = 0, π/2`, which the eight regions share, and the last row node
    /// rounded up past π/2): under 1 % above one eighth for the default tables (1/7.93 at
    /// 2k, 1/7.97 at 8k, 1/7.99 at 64k). The plane folds only in two directions, so it is
    /// about one quarter (1/3.98-1/4.00).
    pub fn unfolded_bytes(&self) -> usize {
        let step = 1.0 / self.inv_step;
        let rows = match self.spec.surface {
            Surface::Cylinder => 2 * (PI / step).ceil() as usize + 1,
            Surface::Plane => 2 * (self.rows - 1) + 1,
            // Four faces, each r ∈ [0, 1].
            Surface::Diamond => 4 * (1.0 / step).ceil() as usize + 1,
        };
        let cols = 2 * (self.cols - 1) + 1;
        rows * cols * std::mem::size_of::<[i32; 2]>() + (rows - 1) * 4
    }
    /// Largest cell error outside the exact zones, in source pixels: measured at five
    /// points per cell, or, for a cell the analytic bound proved (see [`LutTable::build`]),
    /// that bound (so this is at least the measured maximum).
    pub fn max_cell_error(&self) -> f64 {
        self.max_cell_error
    }
    /// Largest column coordinate the table covers.
    pub fn col_max(&self) -> f64 {
        (self.cols - 1) as f64 / self.inv_step
    }
    /// Table nodes per unit of the column (and row) coordinate.
    pub(crate) fn nodes_per_unit(&self) -> f64 {
        self.inv_step
    }
    /// Largest row coordinate the table covers.
    pub fn row_max(&self) -> f64 {
        (self.rows - 1) as f64 / self.inv_step
    }

    /// Row band and Q.16 blend weight for a (folded, non-negative) row coordinate.
    #[inline]
    pub fn row_position(&self, row: f64) -> (usize, i64) {
        let f = (row * self.inv_step).max(0.0);
        let mut b = f.floor() as usize;
        let mut frac = f - b as f64;
        if b >= self.rows - 1 {
            b = self.rows - 2;
            frac = 1.0;
        }
        (b, (frac * 65536.0).round() as i64)
    }

    /// Exact-zone column limit of a band (negative when the band has none).
    #[inline]
    pub fn zone(&self, band: usize) -> f64 {
        self.zone[band] as f64
    }

    /// Read the table at column coordinate `col ≥ 0` in band `band` with row weight `wa`
    /// (Q.16): two table rows blended, two columns interpolated. Returns folded (Λ, V) in
    /// Q.16. Columns beyond the table clamp to its last node.
    #[inline(always)]
    pub fn lookup(&self, band: usize, wa: i64, col: f64) -> (i64, i64) {
        self.band(band, wa).lookup(col)
    }

    /// The two node rows of band `band` with row weight `wa` (Q.16), for reading many
    /// columns of one scanline (see [`Band::lookup`]).
    #[inline(always)]
    pub(crate) fn band(&self, band: usize, wa: i64) -> Band<'_> {
        let i0 = band * self.cols;
        let (top, bot) = self.entries[i0..i0 + 2 * self.cols].split_at(self.cols);
        Band {
            top,
            bot,
            wa,
            scale: self.inv_step * 65536.0,
        }
    }
}

/// One band of a [`LutTable`] with its row weight: the reads of one scanline.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Band<'a> {
    top: &'a [[i32; 2]],
    bot: &'a [[i32; 2]],
    wa: i64,
    /// Q.16 column nodes per unit of column coordinate.
    scale: f64,
}

impl Band<'_> {
    /// [`LutTable::lookup`] in this band: folded (Λ, V) in Q.16 at column coordinate
    /// `col ≥ 0`, two table rows blended, two columns interpolated; columns beyond the
    /// table clamp to its last node.
    #[inline(always)]
    pub(crate) fn lookup(&self, col: f64) -> (i64, i64) {
        // (col · inv_step) · 2^16 and col · (inv_step · 2^16) round alike (a power of two).
        self.lookup_q(((col * self.scale) as i64) << 16)
    }

    /// [`Band::lookup`] at node coordinate `c` (column coordinate × nodes per unit, Q.32,
    /// `c ≥ 0`): what the scanline walk reads, its coordinate stepped in integers.
    #[inline(always)]
    pub(crate) fn lookup_q(&self, c: i64) -> (i64, i64) {
        let (k, wk) = self.node_q(c);
        let (a, b) = (self.top[k], self.top[k + 1]);
        let bot = &self.bot[k..k + 2];
        let (c, d) = (bot[0], bot[1]);
        let wa = self.wa;
        let l0 = blend(a[0], c[0], wa);
        let l1 = blend(b[0], d[0], wa);
        let v0 = blend(a[1], c[1], wa);
        let v1 = blend(b[1], d[1], wa);
        (l0 + (((l1 - l0) * wk) >> 16), v0 + (((v1 - v0) * wk) >> 16))
    }

    /// The node left of node coordinate `c ≥ 0` (Q.32; at most the last but one) and the
    /// Q.16 weight of the next one.
    #[inline(always)]
    pub(crate) fn node_q(&self, c: i64) -> (usize, i64) {
        let n = self.top.len();
        let k = (c >> 32) as usize;
        if k >= n - 1 {
            (n - 2, 1 << 16)
        } else {
            (k, (c >> 16) & 0xFFFF)
        }
    }

    /// A band of the given rows (kernel tests: values a table would not hold).
    #[cfg(test)]
    pub(crate) fn from_rows<'a>(top: &'a [[i32; 2]], bot: &'a [[i32; 2]], wa: i64) -> Band<'a> {
        Band {
            top,
            bot,
            wa,
            scale: 1.0,
        }
    }

    /// The two rows' nodes `k0..k0 + n` and the blend weight of the lower one (Q.16):
    /// what [`Band::blend_nodes`] blends, for the SIMD kernel that does the same (x86-64
    /// only, so unused elsewhere).
    #[inline]
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    pub(crate) fn rows(&self, k0: usize, n: usize) -> (&[[i32; 2]], &[[i32; 2]], i64) {
        (&self.top[k0..k0 + n], &self.bot[k0..k0 + n], self.wa)
    }

    /// Nodes `k0..k0 + out.len()` with the two rows blended (what [`Band::lookup`] blends
    /// per read), for [`Blended`].
    #[inline]
    pub(crate) fn blend_nodes(&self, k0: usize, out: &mut [[i32; 2]]) {
        let k1 = k0 + out.len();
        let wa = self.wa;
        for ((o, a), c) in out.iter_mut().zip(&self.top[k0..k1]).zip(&self.bot[k0..k1]) {
            // Between the two nodes: fits i32.
            *o = [blend(a[0], c[0], wa) as i32, blend(a[1], c[1], wa) as i32];
        }
    }
}

/// Row blend of two nodes' values with the Q.16 weight `wa` of the lower one.
#[inline(always)]
fn blend(top: i32, bot: i32, wa: i64) -> i64 {
    top as i64 + (((bot as i64 - top as i64) * wa) >> 16)
}

/// A scanline's nodes blended once ([`Band::blend_nodes`] from node `k0` on): the same
/// reads as [`Band::lookup`] for the columns whose nodes it holds, without the row blend.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Blended<'a> {
    pub(crate) band: Band<'a>,
    pub(crate) k0: usize,
    pub(crate) nodes: &'a [[i32; 2]],
}

impl Blended<'_> {
    /// [`Band::lookup_q`]; `c`'s node and the next must be among the blended ones.
    #[inline(always)]
    pub(crate) fn lookup_q(&self, c: i64) -> (i64, i64) {
        let (k, wk) = self.band.node_q(c);
        let pair = &self.nodes[k - self.k0..k - self.k0 + 2];
        let (a, b) = (pair[0], pair[1]);
        let (l0, l1) = (a[0] as i64, b[0] as i64);
        let (v0, v1) = (a[1] as i64, b[1] as i64);
        (l0 + (((l1 - l0) * wk) >> 16), v0 + (((v1 - v0) * wk) >> 16))
    }
}

/// How [`LutTable::build_checked`] checks the table cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ZoneCheck {
    /// Skip the measurement of cells an analytic bound proves (the default).
    Bounded,
    /// Measure every cell (the reference the bounded check is tested against).
    #[cfg_attr(not(test), allow(dead_code))]
    MeasureAll,
}

/// Points of a cell, as (row, column) fractions, measured against the exact map.
const MEASURE_POINTS: [(f64, f64); 5] = [
    (0.5, 0.5),
    (0.0, 0.5),
    (0.5, 0.0),
    (0.25, 0.75),
    (0.75, 0.25),
];

/// Sampling-position error between an exact (Λ, V, φ) and an interpolated (Λ, V), in the
/// angular metric of [`crate::position_error`], after turning both into map (u, v).
fn entry_error(p: Projection, w: f64, h: f64, exact: (f64, f64, f64), got: (f64, f64)) -> f64 {
    let (el, ev, phi) = exact;
    let (il, iv) = got;
    let ve = h * 0.5 - ev;
    let vi = h * 0.5 - iv;
    if !p.full_sphere() {
        let ine = (0.0..=h).contains(&ve);
        let ini = (0.0..=h).contains(&vi);
        if !ine && !ini {
            return 0.0; // both background
        }
        if ine != ini {
            return f64::INFINITY;
        }
    }
    let se = p.row_scale(phi);
    let ue = w * 0.5 + se * el;
    let ui = if p.scaled_rows() {
        // After unfolding and yaw, |Λ| can be anything up to W/2, so an error in the row
        // scale (through v) counts at its worst: u = W/2 + s·Λ, |Λ| ≤ W/2.
        let ds = (p.row_scale_at_v(vi, h) - se).abs();
        ue + se * (il - el).abs() + w * 0.5 * ds
    } else {
        w * 0.5 + il
    };
    crate::geom::accuracy::position_error(p, w, h, phi, (ue, ve), (ui, vi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lookup_hits_nodes_exactly() {
        let spec = TableSpec::default_for(Surface::Cylinder, TableKind::Wide, 2048);
        let t = LutTable::build(spec, Projection::Equirect, 2048, 1024);
        let step = 1.0 / t.inv_step;
        for (r, k) in [(0usize, 0usize), (10, 20), (100, 3)] {
            let (b, wa) = t.row_position(r as f64 * step);
            let (l, v) = t.lookup(b, wa, k as f64 * step);
            let (el, ev, _) = exact_entry(
                Surface::Cylinder,
                Projection::Equirect,
                2048.0,
                1024.0,
                r as f64 * step,
                k as f64 * step,
            );
            assert!((l as f64 / 65536.0 - el).abs() < 1e-3, "{r} {k}");
            assert!((v as f64 / 65536.0 - ev).abs() < 1e-3, "{r} {k}");
        }
    }

    /// The nodes blended once per scanline read what the per-read blend reads, bit for
    /// bit, at nodes, between them and beyond the last one.
    #[test]
    fn blended_nodes_read_as_the_band() {
        let spec = TableSpec::default_for(Surface::Cylinder, TableKind::Wide, 2048);
        let t = LutTable::build(spec, Projection::Equirect, 2048, 1024);
        let step = 1.0 / t.inv_step;
        for row in [0.0, 0.37, 1.0, 1.5, t.row_max()] {
            let (b, wa) = t.row_position(row);
            let band = t.band(b, wa);
            let (k0, k1) = (5, t.cols - 1);
            let mut nodes = vec![[0i32; 2]; k1 + 1 - k0];
            band.blend_nodes(k0, &mut nodes);
            let blended = Blended {
                band,
                k0,
                nodes: &nodes,
            };
            let mut col = k0 as f64 * step;
            while col < t.col_max() + 3.0 * step {
                let c = ((col * band.scale) as i64) << 16;
                assert_eq!(blended.lookup_q(c), band.lookup(col), "row {row} col {col}");
                assert_eq!(band.lookup_q(c), band.lookup(col), "row {row} col {col}");
                assert_eq!(
                    band.lookup(col),
                    t.lookup(b, wa, col),
                    "row {row} col {col}"
                );
                col += step * 0.173;
            }
        }
    }

    #[test]
    fn zones_only_near_the_pole() {
        let spec = TableSpec::default_for(Surface::Cylinder, TableKind::Wide, 8192);
        let t = LutTable::build(spec, Projection::Equirect, 8192, 4096);
        let bands = t.rows - 1;
        // the equatorial band has no zone, the polar band has one
        assert!(t.zone(0) < 0.0);
        assert!(t.zone(bands - 1) > 0.0);
        // zones shrink away from the pole
        let step = 1.0 / t.inv_step;
        for b in 0..bands {
            let a = b as f64 * step;
            if a < 1.2 {
                assert!(t.zone(b) < 0.0, "band {b} at a={a} has zone {}", t.zone(b));
            }
        }
        assert!(t.max_cell_error() <= TABLE_ERROR_BUDGET);
    }

    /// Every projection, every surface, both kinds, on a small map (and the cylinder
    /// projection on a tall and a wide one: its coverage edge is where cells straddle).
    fn configs() -> Vec<(Surface, TableKind, Projection, u32, u32)> {
        let mut v = Vec::new();
        for surface in [Surface::Cylinder, Surface::Plane, Surface::Diamond] {
            for kind in [TableKind::Wide, TableKind::High] {
                for p in Projection::ALL {
                    v.push((surface, kind, p, 2048, 1024));
                }
                v.push((surface, kind, Projection::Cylinder, 2048, 3000));
                v.push((surface, kind, Projection::Cylinder, 4096, 600));
            }
        }
        v
    }

    #[test]
    fn bounded_check_gives_the_measured_zones() {
        let mut cases = configs();
        // The default configuration the renderer uses, at the benchmark's map size.
        cases.push((
            Surface::Cylinder,
            TableKind::Wide,
            Projection::Equirect,
            8192,
            4096,
        ));
        cases.push((
            Surface::Cylinder,
            TableKind::High,
            Projection::Equirect,
            8192,
            4096,
        ));
        for (surface, kind, p, w, h) in cases {
            let spec = TableSpec::default_for(surface, kind, w);
            let fast = LutTable::build_checked(spec, p, w, h, ZoneCheck::Bounded);
            let full = LutTable::build_checked(spec, p, w, h, ZoneCheck::MeasureAll);
            let what = format!("{surface:?} {kind:?} {p} {w}x{h}");
            assert!(fast.entries == full.entries, "{what}");
            for b in 0..fast.rows - 1 {
                assert_eq!(
                    fast.zone[b].to_bits(),
                    full.zone[b].to_bits(),
                    "{what}: band {b}"
                );
            }
            // A proven cell reports its bound, which is at least its measured error.
            assert!(
                full.max_cell_error() <= fast.max_cell_error() + 1e-12,
                "{what}: {} > {}",
                full.max_cell_error(),
                fast.max_cell_error()
            );
            assert!(fast.max_cell_error() <= TABLE_ERROR_BUDGET, "{what}");
        }
    }

    /// The bound of every proven cell against the error measured on a 9×9 grid of points
    /// in the cell (edges included), for the cells whose bound is in the upper half of
    /// what is proven (where a bound that is too small would show) and a sample of others.
    #[test]
    fn proven_bounds_hold_inside_cells() {
        let mut checked_near = 0usize;
        for (surface, kind, p, w, h) in configs() {
            let spec = TableSpec::default_for(surface, kind, w);
            let t = LutTable::build(spec, p, w, h);
            let (wf, hf) = (w as f64, h as f64);
            let step = spec.step;
            let bounds = CellBounds::new(surface, p, wf, hf, step, ZoneCheck::Bounded);
            for b in 0..t.rows - 1 {
                let Some(band) = bounds.band(b) else { continue };
                for k in 0..t.cols - 1 {
                    let Some(bound) = band.cells(k, k + 1) else {
                        continue;
                    };
                    let near = bound > 0.5 * PROVEN_LIMIT;
                    if !near && (b * 7 + k) % 97 != 0 {
                        continue;
                    }
                    checked_near += near as usize;
                    let e = |rr: usize, kk: usize| {
                        let e = t.entries[rr * t.cols + kk];
                        (e[0] as f64 / 65536.0, e[1] as f64 / 65536.0)
                    };
                    let (e00, e01, e10, e11) = (e(b, k), e(b, k + 1), e(b + 1, k), e(b + 1, k + 1));
                    for i in 0..9 {
                        for j in 0..9 {
                            let (fr, fc) = (i as f64 / 8.0, j as f64 / 8.0);
                            let ex = exact_entry(
                                surface,
                                p,
                                wf,
                                hf,
                                (b as f64 + fr) * step,
                                (k as f64 + fc) * step,
                            );
                            let bl = |a: f64, bb: f64, c: f64, d: f64| {
                                let top = a + (bb - a) * fc;
                                top + (c + (d - c) * fc - top) * fr
                            };
                            let got = (
                                bl(e00.0, e01.0, e10.0, e11.0),
                                bl(e00.1, e01.1, e10.1, e11.1),
                            );
                            let err = entry_error(p, wf, hf, ex, got);
                            assert!(
                                err <= bound,
                                "{surface:?} {kind:?} {p} {w}x{h} cell ({b},{k}) at ({fr},{fc}): \
                                 error {err} > bound {bound}"
                            );
                        }
                    }
                }
            }
        }
        // The check must have looked at cells near the limit, not only easy ones.
        assert!(checked_near > 100, "{checked_near}");
    }

    /// The geometry bounds against central finite differences of λ and φ at points inside
    /// cells, from the equator to 1e-3 rad from the pole and from t = 0 to the widest
    /// column, on both surfaces.
    #[test]
    fn geometry_bounds_dominate_derivatives() {
        let lam_phi = |surface: Surface, r: f64, t: f64| {
            let (y, z) = row_yz(surface, r);
            (t.atan2(z), y.atan2((t * t + z * z).sqrt()))
        };
        let mut n = 0;
        for surface in [Surface::Cylinder, Surface::Plane] {
            let r_top = match surface {
                Surface::Cylinder => FRAC_PI_2 - 1e-3,
                Surface::Plane => 1.8,
                Surface::Diamond => unreachable!("no closed-form bounds for the diamond"),
            };
            for (ri, r0) in (0..60).map(|i| (i, r_top * (1.0 - (i as f64 / 60.0).powi(3)))) {
                for t0 in [0.0, 1e-3, 0.01, 0.05, 0.2, 0.7, 1.5, 3.7] {
                    let hstep = [0.002f64, 0.01, 0.05][ri % 3].min(r0.max(1e-3));
                    let (r0, r1, t1) = ((r0 - hstep).max(0.0), r0, t0 + hstep);
                    let g = match surface {
                        Surface::Cylinder => {
                            let (s0, c0) = r0.sin_cos();
                            let (s1, c1) = r1.sin_cos();
                            CellGeom::cylinder(s0, c0, s1, c1, t0, t1)
                        }
                        Surface::Plane => CellGeom::plane(r0, r1, t0, t1),
                        Surface::Diamond => unreachable!(),
                    }
                    .expect("cell below the pole");
                    for i in 0..=4 {
                        for j in 0..=4 {
                            let r = r0 + (r1 - r0) * i as f64 / 4.0;
                            let t = t0 + (t1 - t0) * j as f64 / 4.0;
                            let d = 1e-5 * hstep;
                            let f = |dr: f64, dt: f64| lam_phi(surface, r + dr, t + dt);
                            let c = f(0.0, 0.0);
                            let (rp, rm, tp, tm) = (f(d, 0.0), f(-d, 0.0), f(0.0, d), f(0.0, -d));
                            let second = |p: f64, m: f64, c: f64| (p - 2.0 * c + m) / (d * d);
                            let first = |p: f64, m: f64| (p - m) / (2.0 * d);
                            // Finite differences carry rounding noise ~1e-16/d²·|f|.
                            let tol = |b: f64| b * 1.01 + 1e-16 / (d * d) * 8.0;
                            let what = format!("{surface:?} r={r} t={t} {g:?}");
                            assert!(
                                second(rp.0, rm.0, c.0).abs() <= tol(g.lam_rr),
                                "λ_rr {what}"
                            );
                            assert!(
                                second(tp.0, tm.0, c.0).abs() <= tol(g.lam_tt),
                                "λ_tt {what}"
                            );
                            assert!(
                                second(rp.1, rm.1, c.1).abs() <= tol(g.phi_rr),
                                "φ_rr {what}"
                            );
                            assert!(
                                second(tp.1, tm.1, c.1).abs() <= tol(g.phi_tt),
                                "φ_tt {what}"
                            );
                            assert!(
                                first(rp.1, rm.1).abs() <= g.phi_r * 1.0001 + 1e-9,
                                "φ_r {what}"
                            );
                            assert!(
                                first(tp.1, tm.1).abs() <= g.phi_t * 1.0001 + 1e-9,
                                "φ_t {what}"
                            );
                            let phi = c.1;
                            assert!(phi.tan() <= g.tan_max * (1.0 + 1e-12), "tan max {what}");
                            assert!(phi.tan() >= g.tan_min * (1.0 - 1e-12), "tan min {what}");
                            assert!(phi.cos() <= g.cos_max * (1.0 + 1e-12), "cos {what}");
                            n += 1;
                        }
                    }
                }
            }
        }
        assert!(n > 10_000);
    }

    #[test]
    fn folded_table_is_an_eighth_of_the_unfolded_one() {
        for w in [2048u32, 4096, 8192, 16384, 65536] {
            for kind in [TableKind::Wide, TableKind::High] {
                for (surface, fold) in [
                    (Surface::Cylinder, 8.0),
                    (Surface::Plane, 4.0),
                    (Surface::Diamond, 8.0),
                ] {
                    if surface == Surface::Diamond && w > 16384 {
                        continue; // every cell measured: slow to build, nothing new
                    }
                    let spec = TableSpec::default_for(surface, kind, w);
                    let t = LutTable::build(spec, Projection::Equirect, w, w / 2);
                    let ratio = t.unfolded_bytes() as f64 / t.bytes() as f64;
                    // Exactly `fold` but for the shared fold lines: within 1 %, never more.
                    assert!(
                        ratio <= fold && ratio >= fold * 0.99,
                        "{surface:?} {kind:?} {w}: unfolded/folded = {ratio}"
                    );
                }
            }
        }
    }

    /// The diamond (FIG. 8B): its surface points are the cylinder's directions (the
    /// face y + z = 1 meets the plane of angle a at r = sin a/(sin a + cos a), a column x
    /// there is t = x (sin a + cos a)), and outside the exact zones every cell is within
    /// the table budget at a 5×5 grid of points (edges included), not only at the five
    /// measured ones, for every full-sphere projection (a cylindrical map's coverage edge
    /// is where a point between the measured ones can fall on the other side: the render
    /// property tests count those pixels).
    #[test]
    fn diamond_cells_within_budget_outside_the_zones() {
        for p in Projection::ALL.into_iter().filter(|p| p.full_sphere()) {
            let (w, h) = (2048, 1024);
            let kinds: &[TableKind] = match p {
                Projection::Equirect => &[TableKind::Wide, TableKind::High],
                _ => &[TableKind::Wide],
            };
            for &kind in kinds {
                let spec = TableSpec::default_for(Surface::Diamond, kind, w);
                let t = LutTable::build(spec, p, w, h);
                let (wf, hf) = (w as f64, h as f64);
                let step = spec.step;
                let mut worst = 0.0f64;
                for b in 0..t.rows - 1 {
                    for k in 0..t.cols - 1 {
                        if t.zone(b) >= 0.0 && (k as f64 * step) < t.zone(b) {
                            continue;
                        }
                        let e = |rr: usize, kk: usize| {
                            let e = t.entries[rr * t.cols + kk];
                            (e[0] as f64 / 65536.0, e[1] as f64 / 65536.0)
                        };
                        let (e00, e01, e10, e11) =
                            (e(b, k), e(b, k + 1), e(b + 1, k), e(b + 1, k + 1));
                        for i in 0..5 {
                            for j in 0..5 {
                                let (fr, fc) = (i as f64 / 4.0, j as f64 / 4.0);
                                let (r, x) = ((b as f64 + fr) * step, (k as f64 + fc) * step);
                                // The same direction on the cylinder.
                                let a = r.atan2(1.0 - r);
                                let tc = x * (a.sin() + a.cos());
                                let ex = exact_entry(Surface::Cylinder, p, wf, hf, a, tc);
                                let ed = exact_entry(Surface::Diamond, p, wf, hf, r, x);
                                assert!((ex.0 - ed.0).abs() < 1e-6 && (ex.1 - ed.1).abs() < 1e-6);
                                let bl = |a: f64, bb: f64, c: f64, d: f64| {
                                    let top = a + (bb - a) * fc;
                                    top + (c + (d - c) * fc - top) * fr
                                };
                                let got = (
                                    bl(e00.0, e01.0, e10.0, e11.0),
                                    bl(e00.1, e01.1, e10.1, e11.1),
                                );
                                worst = worst.max(entry_error(p, wf, hf, ed, got));
                            }
                        }
                    }
                }
                assert!(worst <= TABLE_ERROR_BUDGET * 1.1, "{p} {kind:?}: {worst}");
                assert!(t.max_cell_error() <= TABLE_ERROR_BUDGET, "{p} {kind:?}");
            }
        }
    }

    #[test]
    fn q16_rounds_to_nearest_and_saturates() {
        for x in [
            0.0, 1.0, -1.0, 0.3, -0.3, 1234.567, -32767.9, 32767.99, 1e-9, -1e-9,
        ] {
            let y = x * 65536.0;
            let got = q16(x);
            assert!((got as f64 - y).abs() <= 0.5, "{x}: {got} vs {y}");
            assert_eq!(got, y.round() as i32, "{x}");
        }
        // ties go to even
        assert_eq!(q16(0.5 / 65536.0), 0);
        assert_eq!(q16(1.5 / 65536.0), 2);
        assert_eq!(q16(-1.5 / 65536.0), -2);
        assert_eq!(q16(1e9), i32::MAX);
        assert_eq!(q16(-1e9), i32::MIN);
        assert_eq!(q16(f64::NAN), 0);
        assert_eq!(q16(f64::INFINITY), i32::MAX);
    }
}

//! The scanline-coherent look-up table (US 5,748,194, FIGS. 5-8A).
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
//!
//! Each entry holds the environment-map indices of its surface point for the map's
//! projection, `Λ = λ · W / 2π` and `V = profile(φ)` (see [`crate::projection`]), as
//! `i32` **Q15.16** fixed point.
//!
//! ## One-eighth symmetry (FIG. 6E, region 681)
//! Only `a ∈ [0, π/2]`, `t ≥ 0` is stored. The other seven regions follow by sign and
//! reflection: `t → −t` negates Λ; `a → −a` negates V; `a → π − a` (behind the viewer)
//! maps Λ to `W/2 − Λ`. For the plane only the first two apply (a quarter is stored).
//!
//! ## Accuracy bookkeeping
//! At build time every table cell is measured against the exact map at five interior
//! points. Cells whose bilinear interpolation error exceeds [`TABLE_ERROR_BUDGET`] (only
//! those near the poles, where longitude turns fast) are recorded per row band as an
//! *exact zone*: the renderer evaluates pixels there directly instead of reading the table.

use crate::projection::Projection;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, TAU};

/// Largest sampling-position error, in source pixels (angular metric, see
/// [`crate::accuracy`]), the table's own bilinear interpolation may add outside the
/// exact zones.
pub const TABLE_ERROR_BUDGET: f64 = 0.02;

/// The surface of extrusion the table is built on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Surface {
    /// The cylinder of FIGS. 5-7 (full 360° of pitch; the default).
    Cylinder,
    /// The planar table of FIG. 8A.
    Plane,
}

impl Surface {
    /// Name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Surface::Cylinder => "cylinder",
            Surface::Plane => "plane",
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

/// Direction `(x, y, z)` of the surface point at (row, col).
#[inline]
fn surface_dir(surface: Surface, row: f64, col: f64) -> (f64, f64, f64) {
    match surface {
        Surface::Cylinder => {
            let (s, c) = row.sin_cos();
            (col, s, c)
        }
        Surface::Plane => (col, row, 1.0),
    }
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
    let (x, y, z) = surface_dir(surface, row, col);
    let lambda = x.atan2(z);
    let phi = y.atan2((x * x + z * z).sqrt());
    let big_l = lambda / TAU * w;
    let big_v = p.profile(phi, w, h).clamp(-V_CLAMP, V_CLAMP);
    (big_l, big_v, phi)
}

impl LutTable {
    /// Build the table for a map of `map_w × map_h` in `projection` (rows in parallel).
    ///
    /// The table must fit Q15.16: maps up to 131068 pixels wide.
    pub fn build(spec: TableSpec, projection: Projection, map_w: u32, map_h: u32) -> LutTable {
        let rows = ((spec.row_max / spec.step).ceil() as usize).max(1) + 1;
        let cols = ((spec.col_max / spec.step).ceil() as usize).max(1) + 1;
        // Use exactly `step` so node r is at r*step; the last node may pass row_max a bit.
        let step = spec.step;
        let (w, h) = (map_w as f64, map_h as f64);
        let q = |x: f64| {
            (x * 65536.0)
                .round()
                .clamp(i32::MIN as f64, i32::MAX as f64) as i32
        };
        let mut entries = vec![[0i32; 2]; rows * cols];
        entries
            .par_chunks_mut(cols)
            .enumerate()
            .for_each(|(r, line)| {
                let row = r as f64 * step;
                for (k, e) in line.iter_mut().enumerate() {
                    let (l, v, _) =
                        exact_entry(spec.surface, projection, w, h, row, k as f64 * step);
                    *e = [q(l), q(v)];
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
        table.measure_zones();
        table
    }

    /// Measure every cell against the exact map; record the exact zone of each band.
    fn measure_zones(&mut self) {
        let (w, h) = (self.map_w as f64, self.map_h as f64);
        let step = 1.0 / self.inv_step;
        let p = self.projection;
        let surface = self.spec.surface;
        let cols = self.cols;
        let entries = &self.entries;
        let results: Vec<(f32, f64)> = (0..self.rows - 1)
            .into_par_iter()
            .map(|b| {
                let mut zone = -1.0f32;
                let mut worst_ok = 0.0f64;
                let mut errs = Vec::with_capacity(cols);
                for k in 0..cols - 1 {
                    let n = |rr: usize, kk: usize| {
                        let e = entries[rr * cols + kk];
                        (e[0] as f64 / 65536.0, e[1] as f64 / 65536.0)
                    };
                    let (e00, e01, e10, e11) = (n(b, k), n(b, k + 1), n(b + 1, k), n(b + 1, k + 1));
                    let mut cell = 0.0f64;
                    for (fr, fc) in [
                        (0.5, 0.5),
                        (0.0, 0.5),
                        (0.5, 0.0),
                        (0.25, 0.75),
                        (0.75, 0.25),
                    ] {
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
                    errs.push(cell);
                    if cell > TABLE_ERROR_BUDGET {
                        zone = ((k + 1) as f64 * step) as f32;
                    }
                }
                for (k, e) in errs.iter().enumerate() {
                    if (k as f64 * step) as f32 >= zone {
                        worst_ok = worst_ok.max(*e);
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
    /// Largest measured cell error outside the exact zones, in source pixels.
    pub fn max_cell_error(&self) -> f64 {
        self.max_cell_error
    }
    /// Largest column coordinate the table covers.
    pub fn col_max(&self) -> f64 {
        (self.cols - 1) as f64 / self.inv_step
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
        let fc = (col * self.inv_step * 65536.0) as i64;
        let mut k = (fc >> 16) as usize;
        let mut wk = fc & 0xFFFF;
        if k >= self.cols - 1 {
            k = self.cols - 2;
            wk = 1 << 16;
        }
        let i0 = band * self.cols + k;
        let i1 = i0 + self.cols;
        let (a, b) = (self.entries[i0], self.entries[i0 + 1]);
        let (c, d) = (self.entries[i1], self.entries[i1 + 1]);
        let blend = |top: i32, bot: i32| top as i64 + (((bot as i64 - top as i64) * wa) >> 16);
        let l0 = blend(a[0], c[0]);
        let l1 = blend(b[0], d[0]);
        let v0 = blend(a[1], c[1]);
        let v1 = blend(b[1], d[1]);
        (l0 + (((l1 - l0) * wk) >> 16), v0 + (((v1 - v0) * wk) >> 16))
    }
}

/// Sampling-position error between an exact (Λ, V, φ) and an interpolated (Λ, V), in the
/// angular metric of [`crate::accuracy`], after turning both into map (u, v).
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
    crate::accuracy::position_error(p, w, h, phi, (ue, ve), (ui, vi))
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
}

//! Per-frame setup: everything the LUT renderer computes once per frame and never per
//! pixel. Each output scanline gets its table rows (band and blend weight, from pitch),
//! its column scale (from zoom), its index step per region (from the step bounds of
//! `render/steps.rs`), the pixel ranges the table covers and those evaluated exactly
//! (near a pole, or beyond the table's field of view), and for trilinear sampling its
//! vertical footprint. Yaw is one column offset added to u.

use super::steps::{step_for, StepBounds, StepLine, XRange, ADAPTIVE_MAX_STEP, STEP_REGIONS};
use super::{IndexStep, RenderOptions, RenderPath, RenderReport};
use crate::error::ViewError;
use crate::geom::camera::Camera;
use crate::geom::fixed::{to_fx, Fx, FX_BITS, FX_ONE};
use crate::geom::projection::Projection;
use crate::lut::{LutTable, Surface, TableKind};
use crate::map::envmap::EnvMap;
use crate::map::pyramid::nearest_level_of;
use crate::map::sample::Sampler;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// The map a renderer draws from, as its geometry: the full panorama's size in pixels
/// and its projection (a partial map's full size). What [`crate::Renderer::positions`]
/// and [`crate::Renderer::build_grid`] need of a map without its pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MapGeometry {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The map's projection.
    pub projection: Projection,
}

impl MapGeometry {
    /// A `width × height` map in `projection`.
    pub const fn new(width: u32, height: u32, projection: Projection) -> MapGeometry {
        MapGeometry {
            width,
            height,
            projection,
        }
    }

    /// The geometry of `map` (a partial map's full size).
    pub fn of(map: &EnvMap) -> MapGeometry {
        MapGeometry {
            width: map.width(),
            height: map.height(),
            projection: map.projection(),
        }
    }
}

/// A point of the table's plane: Λ (map pixels of longitude from the view's centre
/// column, yaw 0) and V (map pixels above the horizon), both Q.16.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Lv {
    /// Λ, Q.16 map pixels.
    pub(crate) l: Fx,
    /// V, Q.16 map pixels.
    pub(crate) v: Fx,
}

impl From<(Fx, Fx)> for Lv {
    /// A table read `(Λ, V)` ([`crate::lut::Band::lookup_q`]).
    #[inline(always)]
    fn from((l, v): (Fx, Fx)) -> Lv {
        Lv { l, v }
    }
}

/// The per-pixel step of a span in the table's plane: dΛ and dV, Q.16 map pixels per
/// output pixel.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct LvStep {
    /// dΛ per pixel, Q.16.
    pub(crate) dl: Fx,
    /// dV per pixel, Q.16.
    pub(crate) dv: Fx,
}

/// An inclusive range of a row's pixel columns (empty when `lo > hi`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Cols {
    /// The first column.
    pub(crate) lo: i64,
    /// The last column (inclusive).
    pub(crate) hi: i64,
}

impl Cols {
    /// No column.
    pub(crate) const EMPTY: Cols = Cols { lo: 0, hi: -1 };

    /// The columns in both ranges.
    #[inline]
    pub(crate) fn and(self, o: Cols) -> Cols {
        Cols {
            lo: self.lo.max(o.lo),
            hi: self.hi.min(o.hi),
        }
    }

    /// Column `x` is in the range.
    #[inline]
    pub(crate) fn contains(self, x: i64) -> bool {
        x >= self.lo && x <= self.hi
    }

    /// No column in the range.
    #[inline]
    pub(crate) fn is_empty(self) -> bool {
        self.lo > self.hi
    }
}

impl Default for Cols {
    fn default() -> Cols {
        Cols::EMPTY
    }
}

/// Per-scanline setup, computed once per frame.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Scan {
    /// The table covers part of this row.
    pub(crate) lut: bool,
    pub(crate) band: usize,
    pub(crate) wa: i64,
    pub(crate) neg_v: bool,
    pub(crate) back: bool,
    /// Column coordinate per unit of X (X = x + ½ − W/2).
    pub(crate) col_per_x: f64,
    /// Table node coordinate (Q.32) per unit of 2X (a whole number per pixel): the
    /// scanline walk's integer column step.
    pub(crate) node_per_2x: i64,
    /// t per unit of X (1/ρ).
    pub(crate) t_per_x: f64,
    /// sin and cos of the (unfolded) scanline angle.
    pub(crate) sa: f64,
    pub(crate) ca: f64,
    /// log2 of the index step per region of |X| (see [`STEP_REGIONS`]).
    pub(crate) shifts: [u8; STEP_REGIONS],
    /// log2 of the index step the row pass walks each region with: `shifts`, or with a
    /// level per region (`Renderer::set_region_lod`) at least that, from the budget of
    /// the level the region's spans read at least (`steps::lod_budget`). The regions'
    /// first reads (`walk::Half::of`) stay those of `shifts`, so a region's pixels do not
    /// depend on the steps of the regions before it.
    pub(crate) lod_shifts: [u8; STEP_REGIONS],
    /// Angle between this scanline and the next at the centre column (radians).
    pub(crate) row_angle: f64,
    /// Vertical pixel footprint per region (level-0 map pixels; trilinear only): the
    /// distance between this scanline's and the next one's table positions.
    pub(crate) fy: [f32; STEP_REGIONS],
    /// Map rows (Q.8, positive: down) from this scanline's read at the centre column to
    /// the next scanline's: the row kernels prefetch the rows it will read
    /// (`Texels::toward_next_scanline`).
    pub(crate) next_dv: i32,
    /// The columns the table covers (empty: none).
    pub(crate) lut_cols: Cols,
    /// The columns of the table's zone this row evaluates exactly (empty: none).
    pub(crate) zone_cols: Cols,
}

/// Per-frame constants shared by all rows.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Setup {
    pub(crate) w_out: usize,
    pub(crate) proj: Projection,
    pub(crate) mw: f64,
    pub(crate) mh: f64,
    pub(crate) map_w_fx: Fx,
    pub(crate) half_map_w_fx: Fx,
    pub(crate) map_h_fx: Fx,
    pub(crate) half_map_h_fx: Fx,
    /// W/2 + yaw, in map pixels, Q.16 (rectangular maps: u = Λ + off).
    pub(crate) off_fx: Fx,
    /// 2·`off_fx` wrapped into [0, W): u of a pixel's mirror image (X → −X) is this
    /// minus its u (modulo W).
    pub(crate) mirror_fx: Fx,
    /// yaw in map pixels, Q.16 (scaled rows: u = W/2 + s · wrap(Λ + yaw)).
    pub(crate) yaw_fx: Fx,
    pub(crate) yaw: f64,
    pub(crate) coverage: bool,
    pub(crate) scaled: bool,
    /// Where the step regions of a scanline start, in units of 2|X| (region r: 2|X| ≥
    /// `region_2x[r]`, r < [`STEP_REGIONS`]; each region is W/16 pixels wide).
    pub(crate) region_2x: [i64; STEP_REGIONS],
}

impl Setup {
    /// The constants of a frame `w_out` pixels wide of `map`, turned by `yaw` radians (0
    /// for renderers whose positions already include the yaw).
    pub(crate) fn new(w_out: u32, map: MapGeometry, yaw: f64) -> Setup {
        let (mw, mh, proj) = (map.width, map.height, map.projection);
        let (mwf, mhf) = (mw as f64, mh as f64);
        let yaw_px = yaw / TAU * mwf;
        Setup {
            w_out: w_out as usize,
            proj,
            mw: mwf,
            mh: mhf,
            map_w_fx: (mw as i64) << FX_BITS,
            half_map_w_fx: (mw as i64) << (FX_BITS - 1),
            map_h_fx: (mh as i64) << FX_BITS,
            half_map_h_fx: to_fx(mhf * 0.5),
            off_fx: to_fx(mwf * 0.5 + yaw_px),
            mirror_fx: (2 * to_fx(mwf * 0.5 + yaw_px)).rem_euclid((mw as i64).max(1) << FX_BITS),
            yaw_fx: to_fx(yaw_px),
            yaw,
            coverage: !proj.full_sphere(),
            scaled: proj.scaled_rows(),
            region_2x: std::array::from_fn(|r| (r * w_out as usize).div_ceil(STEP_REGIONS) as i64),
        }
    }
}

/// Frames with at least this many rows set their rows up on two threads (when the frame
/// runs threaded).
const PARALLEL_SETUP_ROWS: usize = 64;

/// Per-frame setup: one [`Scan`] per output row of `cam`'s frame.
pub(crate) fn prepare(
    table: &LutTable,
    kind: TableKind,
    map: MapGeometry,
    scans: &mut Vec<Scan>,
    cam: &Camera,
    opts: &RenderOptions,
    lod_cap: Option<u32>,
) -> (Setup, RenderReport) {
    let (view, width, height) = (cam.view(), cam.width, cam.height);
    let f = cam.focal;
    let (mwf, mhf) = (map.width as f64, map.height as f64);
    let proj = map.projection;
    let frame = Setup::new(width, map, view.yaw());
    let nominal = match opts.index_step {
        IndexStep::Fixed(n) => n,
        IndexStep::Adaptive => ADAPTIVE_MAX_STEP,
    };
    // Second-derivative bound factors of the map coordinates (see step_for()).
    let (v1, v2) = proj.profile_derivative_bounds(mwf, mhf);
    let coupling = proj.row_scale_coupling(mwf, mhf);
    let bounds = StepBounds {
        lam_px: mwf / TAU,
        v1,
        v2,
        coupling,
        lod_cap: None,
    };
    // Steps on the level read (adaptive steps of the row pass's maps only).
    let lod_bounds =
        (opts.index_step == IndexStep::Adaptive && !proj.scaled_rows() && proj.full_sphere())
            .then_some(lod_cap)
            .flatten()
            .map(|cap| StepBounds {
                lod_cap: Some(cap),
                ..bounds
            });
    let pitch = view.pitch();
    let half_w = width as f64 * 0.5;
    // One scanline's setup (independent of the others: the rows are set up in parallel).
    let row_scan = |y: u32, hint: &[u8; STEP_REGIONS]| -> Scan {
        let yc = height as f64 * 0.5 - (y as f64 + 0.5);
        let rho = yc.hypot(f);
        let alpha = pitch + yc.atan2(f);
        let (sa, ca) = alpha.sin_cos();
        let neg_v = alpha < 0.0;
        let mut a = alpha.abs();
        let back = a > FRAC_PI_2;
        if back {
            a = PI - a;
        }
        // The centre column's map row on this scanline and the next (the latitude of
        // a scanline's centre is its angle folded into [−π/2, π/2]).
        let v_at = |al: f64| -proj.profile(al.sin().clamp(-1.0, 1.0).asin(), mwf, mhf);
        let dv = v_at(pitch + (yc - 1.0).atan2(f)) - v_at(alpha);
        let next_dv = (dv * 256.0)
            .round()
            .clamp(-(1 << 24) as f64, (1 << 24) as f64) as i32;
        let mut scan = Scan {
            neg_v,
            back,
            next_dv,
            sa,
            ca,
            t_per_x: 1.0 / rho,
            row_angle: f / (f * f + yc * yc),
            lut_cols: Cols::EMPTY,
            zone_cols: Cols::EMPTY,
            ..Scan::default()
        };
        let row_coord = match opts.surface {
            Surface::Cylinder => {
                scan.col_per_x = 1.0 / rho;
                Some(a)
            }
            Surface::Diamond => {
                // The scanline's plane meets the face y + z = 1 (folded a ∈ [0, π/2]) at
                // r = sin a/(sin a + cos a); its pixels at x = t/(sin a + cos a).
                let (s, c) = a.sin_cos();
                scan.col_per_x = 1.0 / (rho * (s + c));
                Some(s / (s + c))
            }
            Surface::Plane => {
                if back || a >= table.row_max() {
                    None
                } else {
                    scan.col_per_x = 1.0 / (rho * a.cos());
                    Some(a.tan())
                }
            }
        };
        if let Some(rc) = row_coord.filter(|rc| *rc <= table.row_max()) {
            let (band, wa) = table.row_position(rc);
            scan.lut = true;
            scan.band = band;
            scan.wa = wa;
            let q = scan.col_per_x * table.nodes_per_unit() * (1u64 << 31) as f64;
            // (At most 2^47: times 2|X| ≤ 2^15 it cannot overflow; a column that far clamps.)
            scan.node_per_2x = q.round().min((1u64 << 47) as f64) as i64;
            let xc = table.col_max() / scan.col_per_x;
            scan.lut_cols = x_range(half_w, xc, width);
            let zone = table.zone(band);
            let mut t_min = 0.0;
            if zone >= 0.0 {
                let xz = zone / scan.col_per_x;
                scan.zone_cols = x_range(half_w, xz, width);
                t_min = xz * scan.t_per_x;
            }
            let line = StepLine {
                s: a.sin().abs(),
                c: a.cos().abs(),
                t_min,
                dt: scan.t_per_x,
                k_floor: 0,
            };
            let reg_x = half_w / STEP_REGIONS as f64;
            for (r, shift) in scan.shifts.iter_mut().enumerate() {
                let xs = XRange {
                    lo: r as f64 * reg_x,
                    hi: (r + 1) as f64 * reg_x,
                };
                let n = step_for(&bounds, line, xs, nominal, 1 << hint[r]);
                *shift = n.trailing_zeros() as u8;
            }
            // (Longer with a level per region: `lod_steps`, once the vertical footprints
            // are known.)
            scan.lod_shifts = scan.shifts;
        }
        scan
    };
    scans.clear();
    scans.resize(height as usize, Scan::default());
    // Each row's steps searched from the row before's (`step_for`: the same steps).
    let set_up = |y0: usize, rows: &mut [Scan]| {
        let mut hint = [nominal.trailing_zeros() as u8; STEP_REGIONS];
        for (i, s) in rows.iter_mut().enumerate() {
            *s = row_scan((y0 + i) as u32, &hint);
            if s.lut {
                hint = s.shifts;
            }
        }
    };
    if opts.threads && scans.len() >= PARALLEL_SETUP_ROWS {
        // Half the rows on each of two threads: the setup is about 8 % of a 2-thread
        // frame's instructions (its atan2, sin_cos and step bounds per row), which ran on
        // one thread while the other waited.
        let mid = scans.len() / 2;
        let (a, b) = scans.split_at_mut(mid);
        rayon::join(|| set_up(0, a), || set_up(mid, b));
    } else {
        set_up(0, scans);
    }
    let mut exact_pixels = 0u64;
    let (mut max_step, mut min_step) = (0u32, u32::MAX);
    for scan in scans.iter() {
        exact_pixels += exact_count(scan, width as i64);
        if scan.lut {
            for &shift in &scan.shifts {
                max_step = max_step.max(1 << shift);
                min_step = min_step.min(1 << shift);
            }
        }
    }
    if min_step == u32::MAX {
        min_step = 1;
        max_step = max_step.max(1);
    }
    if opts.sampler == Sampler::Trilinear {
        vertical_footprints(scans, table, &frame, opts.threads);
    }
    if let Some(lb) = &lod_bounds {
        let steps = LodSteps {
            bounds: lb,
            table,
            nominal,
            half_w,
        };
        if opts.threads && scans.len() >= PARALLEL_SETUP_ROWS {
            let mid = scans.len() / 2;
            let (a, b) = scans.split_at_mut(mid);
            rayon::join(|| steps.fill(a), || steps.fill(b));
        } else {
            steps.fill(scans);
        }
    }
    let report = RenderReport {
        path: match kind {
            TableKind::Wide => RenderPath::LutWide,
            TableKind::High => RenderPath::LutHigh,
        },
        exact_pixels,
        pixels: width as u64 * height as u64,
        table_bytes: table.bytes(),
        max_step,
        min_step,
    };
    (frame, report)
}

/// The steps of a frame drawn with a level per region (`Renderer::set_region_lod`): each
/// region's [`Scan::lod_shifts`], the longest step within the budget of the level its
/// spans read at least (`steps::lod_budget`: from the step's own Λ footprint and the
/// region's vertical footprint [`Scan::fy`], which every span's level includes).
struct LodSteps<'a> {
    bounds: &'a StepBounds,
    table: &'a LutTable,
    nominal: u32,
    half_w: f64,
}

impl LodSteps<'_> {
    fn fill(&self, scans: &mut [Scan]) {
        let reg_x = self.half_w / STEP_REGIONS as f64;
        for scan in scans.iter_mut().filter(|s| s.lut) {
            let zone = self.table.zone(scan.band);
            let t_min = if zone >= 0.0 {
                zone / scan.col_per_x * scan.t_per_x
            } else {
                0.0
            };
            for r in 0..STEP_REGIONS {
                let line = StepLine {
                    s: scan.sa.abs(),
                    c: scan.ca.abs(),
                    t_min,
                    dt: scan.t_per_x,
                    k_floor: nearest_level_of(scan.fy[r] as f64),
                };
                let xs = XRange {
                    lo: r as f64 * reg_x,
                    hi: (r + 1) as f64 * reg_x,
                };
                let hint = 1 << scan.shifts[r];
                let n = step_for(self.bounds, line, xs, self.nominal, hint);
                scan.lod_shifts[r] = n.trailing_zeros() as u8;
            }
        }
    }
}

/// The vertical footprint of every scanline per region (see [`Scan::fy`]): table positions
/// of the region's centre column on this scanline and the next (the previous one for the
/// last row), Λ taken the short way round the seam; where the table does not cover both,
/// the scanline's angular spacing in map pixels.
fn vertical_footprints(scans: &mut [Scan], table: &LutTable, fr: &Setup, threads: bool) {
    let half_w = fr.w_out as f64 * 0.5;
    let reg_x = half_w / STEP_REGIONS as f64;
    let px_per_rad = fr.mw / TAU;
    // The footprint of scanline `row` against its neighbour `other` (none: a one-row frame).
    let footprint = |row: &Scan, other: Option<&Scan>| {
        let mut fy = [0f32; STEP_REGIONS];
        for (r, f) in fy.iter_mut().enumerate() {
            let x = ((half_w + (r as f64 + 0.5) * reg_x - 0.5).round() as i64)
                .clamp(0, fr.w_out as i64 - 1);
            let usable = |s: &Scan| s.lut && s.lut_cols.contains(x) && !s.zone_cols.contains(x);
            *f = match other {
                Some(o) if usable(row) && usable(o) => {
                    let (p0, p1) = (read(row, table, fr, x), read(o, table, fr, x));
                    let mut dl = (p1.l - p0.l).unsigned_abs() as i64;
                    if dl > fr.half_map_w_fx {
                        dl = (fr.map_w_fx - dl).abs();
                    }
                    (dl.max((p1.v - p0.v).abs()) as f64 / FX_ONE as f64) as f32
                }
                _ => (row.row_angle * px_per_rad) as f32,
            };
        }
        fy
    };
    // Rows in order, each against the next (`next`: the one after the last, if any) or,
    // for the frame's last row, the one before. A row's `fy` is never read here, so it
    // is written as soon as it is known.
    let fill = |rows: &mut [Scan], next: Option<&Scan>| {
        for i in 0..rows.len() {
            let other = match rows.get(i + 1).or(next) {
                Some(o) => Some(o),
                None => i.checked_sub(1).map(|p| &rows[p]),
            };
            let fy = footprint(&rows[i], other);
            rows[i].fy = fy;
        }
    };
    if threads && scans.len() >= PARALLEL_SETUP_ROWS {
        // Two halves on two threads, as the rest of the setup (serial, this was ~10 % of
        // a two-thread trilinear frame, one thread working while the other waited); the
        // first half's last row reads a copy of the second half's first scan.
        let (a, b) = scans.split_at_mut(scans.len() / 2);
        let first_b = b[0];
        rayon::join(|| fill(a, Some(&first_b)), || fill(b, None));
    } else {
        fill(scans, None);
    }
}

pub(crate) fn check_step(s: IndexStep) -> Result<(), ViewError> {
    match s {
        IndexStep::Fixed(n) if !matches!(n, 1 | 2 | 4 | 8 | 16) => Err(ViewError::BadIndexStep(n)),
        _ => Ok(()),
    }
}

/// Inclusive pixel range with |x + ½ − W/2| ≤ r, clamped to the row (empty: lo > hi).
fn x_range(half_w: f64, r: f64, width: u32) -> Cols {
    if r.is_nan() || r < 0.0 {
        return Cols::EMPTY;
    }
    let r = r.min(1e12);
    let lo = (half_w - 0.5 - r).ceil().max(0.0) as i64;
    let hi = (half_w - 0.5 + r).floor().min(width as f64 - 1.0) as i64;
    Cols { lo, hi }
}

/// Pixels of a row the LUT path evaluates exactly.
fn exact_count(s: &Scan, w: i64) -> u64 {
    let lut = s.lut_cols;
    if !s.lut || lut.is_empty() {
        return w as u64;
    }
    let outside = lut.lo + (w - 1 - lut.hi);
    let z = s.zone_cols.and(lut);
    let zone = if z.is_empty() { 0 } else { z.hi - z.lo + 1 };
    (outside + zone) as u64
}

/// Unfolded table read at pixel x: (Λ, V) in Q.16 for the yaw-0 frame.
#[inline]
pub(crate) fn read(scan: &Scan, table: &LutTable, fr: &Setup, x: i64) -> Lv {
    let a = 2 * x + 1 - fr.w_out as i64;
    let band = table.band(scan.band, scan.wa);
    let u = Unfold::new(scan, fr, a < 0);
    u.apply(band.lookup_q(a.abs() * scan.node_per_2x).into())
}

/// The one-eighth unfolding of one half of a scanline, hoisted out of its reads: Λ =
/// ±Λ₈ + offset (behind the viewer W/2 − Λ₈, negated left of the centre), V = ±V₈ (negated
/// below the horizon), as sign masks.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Unfold {
    neg_l: i64,
    off_l: i64,
    neg_v: i64,
}

impl Unfold {
    #[inline(always)]
    pub(crate) fn new(scan: &Scan, fr: &Setup, left: bool) -> Unfold {
        let mask = |b: bool| -(b as i64);
        let off = if scan.back { fr.half_map_w_fx } else { 0 };
        Unfold {
            neg_l: mask(scan.back != left),
            off_l: if left { -off } else { off },
            neg_v: mask(scan.neg_v),
        }
    }

    #[inline(always)]
    pub(crate) fn apply(&self, p: Lv) -> Lv {
        Lv {
            l: ((p.l ^ self.neg_l) - self.neg_l) + self.off_l,
            v: (p.v ^ self.neg_v) - self.neg_v,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::geom::camera::{Camera, View};
    use crate::geom::mapping::exact_uv_at;
    use crate::geom::projection::Projection;
    use crate::map::synth::grid_map;
    use crate::render::{Frame, RenderOptions, Renderer};

    /// Each scanline's `next_dv` (what the row kernels prefetch for the next scanline) is
    /// the map-row offset from its centre column's read to the next scanline's: against
    /// the exact positions of the centre column (X = 0) on both rows, within 1/256 row
    /// (its Q.8 rounding), on views at the horizon, tilted, past the north pole at the
    /// top (the offset turns negative there) and past the south pole at the bottom, on
    /// an equirectangular and a sine map.
    #[test]
    fn next_dv_is_the_next_scanlines_offset_at_the_centre() {
        let (w, h) = (64u32, 48u32);
        for proj in [Projection::Equirect, Projection::Sine] {
            let map = grid_map(512, 256, proj).unwrap();
            let mut r = Renderer::new(&map);
            for (yaw, pitch, hfov) in [
                (0.0, 0.0, 90.0),
                (40.0, 45.0, 70.0),
                (10.0, 80.0, 90.0),
                (200.0, -75.0, 120.0),
            ] {
                let view = View::new(yaw, pitch, hfov).unwrap();
                let mut px = vec![0u32; (w * h) as usize];
                let mut frame = Frame::new(&mut px, w, h).unwrap();
                r.render(&map, view, &RenderOptions::default(), &mut frame)
                    .unwrap();
                let cam = Camera::new(view, w, h);
                let v_at = |y: f64| {
                    exact_uv_at(&cam, proj, 512.0, 256.0, w as f64 / 2.0, y)
                        .unwrap()
                        .1
                };
                let mut negative = false;
                for y in 0..h as usize {
                    let want = v_at(y as f64 + 1.5) - v_at(y as f64 + 0.5);
                    let got = r.scans[y].next_dv as f64 / 256.0;
                    assert!(
                        (got - want).abs() <= 1.0 / 256.0 + 1e-9 * want.abs(),
                        "{proj:?} {yaw} {pitch} {hfov}, row {y}: {got} against {want}"
                    );
                    negative |= got < 0.0;
                }
                assert_eq!(
                    negative,
                    pitch.abs() > 60.0,
                    "{proj:?} {pitch}: the rows past a pole"
                );
            }
        }
    }
}

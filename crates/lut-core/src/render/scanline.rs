//! The scanline walk: per output row, the pixels the table covers are stepped span by
//! span (a table read every 2^shift pixels, Q.16 steps between, longitude unwrapped across
//! each span so a span over the ±180° seam steps continuously), and the rest (pole zones,
//! beyond the table) are evaluated exactly. Spans go to a [`Sink`].

use super::setup::{Scan, Setup};
use super::sink::Sink;
use super::steps::STEP_REGIONS;
use crate::geom::fixed::{Fx, FX_BITS};
use crate::lut::{Band, Blended, LutTable};

/// Room for a run's blended table nodes (a run that reads more blends per read).
pub(crate) const BLEND_NODES: usize = 512;

/// Room for a scanline's blended table nodes, kept from row to row (no allocation).
pub(crate) type Scratch = [[i32; 2]; BLEND_NODES];

/// Render one scanline into `sink` (`scratch`: room for its blended table nodes).
#[inline]
pub(crate) fn render_row<S: Sink>(
    scan: &Scan,
    table: &LutTable,
    fr: &Setup,
    row_scale: &[i64],
    scratch: &mut Scratch,
    sink: &mut S,
) {
    let w = fr.w_out as i64;
    if !scan.lut || scan.lut_lo > scan.lut_hi {
        exact_run(scan, fr, 0, w - 1, sink);
        return;
    }
    exact_run(scan, fr, 0, scan.lut_lo - 1, sink);
    let zl = scan.zone_lo.max(scan.lut_lo);
    let zh = scan.zone_hi.min(scan.lut_hi);
    if zl <= zh {
        lut_run(
            scan,
            table,
            fr,
            row_scale,
            (scan.lut_lo, zl - 1),
            scratch,
            sink,
        );
        exact_run(scan, fr, zl, zh, sink);
        lut_run(
            scan,
            table,
            fr,
            row_scale,
            (zh + 1, scan.lut_hi),
            scratch,
            sink,
        );
    } else {
        lut_run(
            scan,
            table,
            fr,
            row_scale,
            (scan.lut_lo, scan.lut_hi),
            scratch,
            sink,
        );
    }
    exact_run(scan, fr, scan.lut_hi + 1, w - 1, sink);
}

/// Exact evaluation of pixels x0..=x1 of a scanline (pole zones, beyond the table).
#[inline(never)]
fn exact_run<S: Sink>(scan: &Scan, fr: &Setup, x0: i64, x1: i64, sink: &mut S) {
    let half_w = fr.w_out as f64 * 0.5;
    let c2 = scan.ca * scan.ca;
    for x in x0.max(0)..=x1 {
        let t = (x as f64 + 0.5 - half_w) * scan.t_per_x;
        let lambda = t.atan2(scan.ca) + fr.yaw;
        let phi = scan.sa.atan2((t * t + c2).sqrt());
        sink.exact(x as usize, fr.proj.uv(lambda, phi, fr.mw, fr.mh));
    }
}

/// Unfolded table read at pixel x: (Λ, V) in Q.16 for the yaw-0 frame.
#[inline(always)]
pub(crate) fn read(scan: &Scan, table: &LutTable, fr: &Setup, x: i64) -> (Fx, Fx) {
    let big_x = x as f64 + 0.5 - fr.w_out as f64 * 0.5;
    read_band(scan, &table.band(scan.band, scan.wa), fr, big_x)
}

/// The table reads of a scanline: straight from its band, or from its nodes blended once.
trait Nodes {
    fn lookup(&self, col: f64) -> (Fx, Fx);
}

impl Nodes for Band<'_> {
    #[inline(always)]
    fn lookup(&self, col: f64) -> (Fx, Fx) {
        Band::lookup(self, col)
    }
}

impl Nodes for Blended<'_> {
    #[inline(always)]
    fn lookup(&self, col: f64) -> (Fx, Fx) {
        Blended::lookup(self, col)
    }
}

/// Whether to blend a run's `nodes` once instead of two per read: when there are at
/// most 2 nodes per read, the reads estimated from the run's length and the mean step of
/// the regions. (Callgrind: about 20 instructions per blended node against 27 saved per
/// read puts the break-even near 1.35; a limit of 1.25 and one of 2 measured alike on
/// the benchmark views, docs/performance.md.) Only the cost depends on it, not the
/// output.
#[inline(never)]
fn blend_pays(scan: &Scan, nodes: usize, pixels: usize) -> bool {
    // Reads per 256 pixels, summed over the regions.
    let per_256: usize = scan.shifts.iter().map(|&s| 256 >> s).sum();
    nodes * 256 * STEP_REGIONS <= 2 * pixels * per_256
}

/// [`read`] in the scanline's band, at X = x + ½ − W/2.
#[inline(always)]
fn read_band<N: Nodes>(scan: &Scan, band: &N, fr: &Setup, big_x: f64) -> (Fx, Fx) {
    let (mut l, mut v) = band.lookup(big_x.abs() * scan.col_per_x);
    if scan.back {
        l = fr.half_map_w_fx - l;
    }
    if big_x < 0.0 {
        l = -l;
    }
    if scan.neg_v {
        v = -v;
    }
    (l, v)
}

/// LUT evaluation of pixels x0..=x1: table reads every 2^shift pixels (the shift of the
/// region the span starts in), fixed-point steps between.
#[inline(always)]
fn lut_run<S: Sink>(
    scan: &Scan,
    table: &LutTable,
    fr: &Setup,
    row_scale: &[i64],
    (x0, x1): (i64, i64),
    scratch: &mut Scratch,
    sink: &mut S,
) {
    if x0 > x1 {
        return;
    }
    let band = table.band(scan.band, scan.wa);
    // The nodes the run reads: from the smallest |X| to the largest (the column and its
    // node are monotonic in |X|), and the next node.
    let half_w = fr.w_out as f64 * 0.5;
    let (xa, xb) = (x0 as f64 + 0.5 - half_w, x1 as f64 + 0.5 - half_w);
    let x_min = if xa < 0.0 && xb > 0.0 {
        0.0
    } else {
        xa.abs().min(xb.abs())
    };
    let k0 = band.node(x_min * scan.col_per_x).0;
    let k1 = band.node(xa.abs().max(xb.abs()) * scan.col_per_x).0 + 1;
    let count = k1 + 1 - k0;
    if count <= BLEND_NODES && blend_pays(scan, count, (x1 - x0 + 1) as usize) {
        let nodes = &mut scratch[..count];
        band.blend_nodes(k0, nodes);
        let blended = Blended { band, k0, nodes };
        lut_run_in(scan, &blended, fr, row_scale, x0, x1, sink);
        return;
    }
    lut_run_in(scan, &band, fr, row_scale, x0, x1, sink);
}

/// [`lut_run`] with the scanline's nodes read through `band`.
#[inline(always)]
fn lut_run_in<S: Sink, N: Nodes>(
    scan: &Scan,
    band: &N,
    fr: &Setup,
    row_scale: &[i64],
    x0: i64,
    x1: i64,
    sink: &mut S,
) {
    let half_w = fr.w_out as f64 * 0.5;
    let last_region = STEP_REGIONS as i64 - 1;
    let mut xs = x0;
    // X of xs, carried from span to span (whole numbers plus ½: exact in f64).
    let mut big_x = xs as f64 + 0.5 - half_w;
    let (mut l0, mut v0) = read_band(scan, band, fr, big_x);
    loop {
        // Through i64 (as usize: the same value, as |X| ≥ 0, but a longer conversion).
        let region = ((big_x.abs() * scan.region_per_x) as i64).min(last_region) as usize;
        let shift = scan.shifts[region] as u32;
        let n = 1i64 << shift;
        let xe = (xs + n).min(x1);
        if xe == xs {
            emit(fr, row_scale, xs, 1, (l0, v0), (0, 0), sink);
            return;
        }
        let big_xe = xe as f64 + 0.5 - half_w;
        let (mut l1, v1) = read_band(scan, band, fr, big_xe);
        // Unwrap longitude across the span: a ±180° seam is a jump of one map width.
        let d = l1 - l0;
        if d > fr.half_map_w_fx {
            l1 -= fr.map_w_fx;
        } else if d < -fr.half_map_w_fx {
            l1 += fr.map_w_fx;
        }
        let m = xe - xs;
        let (dl, dv) = if m == n {
            ((l1 - l0) >> shift, (v1 - v0) >> shift)
        } else {
            ((l1 - l0) / m, (v1 - v0) / m)
        };
        sink.footprint(dl, dv, region);
        if xe == x1 {
            // Last span: emit through x1 inclusive, ending exactly on the read value.
            emit(fr, row_scale, xs, m, (l0, v0), (dl, dv), sink);
            emit(fr, row_scale, x1, 1, (l1, v1), (0, 0), sink);
            return;
        }
        emit(fr, row_scale, xs, m, (l0, v0), (dl, dv), sink);
        xs = xe;
        big_x = big_xe;
        l0 = l1;
        v0 = v1;
    }
}

/// Emit `m` pixels from `x` on, starting at (Λ, V) and stepping by (dΛ, dV) (also the
/// grid renderer's spans).
#[inline(always)]
pub(crate) fn emit<S: Sink>(
    fr: &Setup,
    row_scale: &[i64],
    x: i64,
    m: i64,
    start: (Fx, Fx),
    step: (Fx, Fx),
    sink: &mut S,
) {
    let (l, vv) = start;
    let (dl, dvv) = step;
    // v = H/2 − V
    let mut v = fr.half_map_h_fx - vv;
    let dv = -dvv;
    let x = x as usize;
    let m = m as usize;
    if fr.scaled {
        let mut lw = l + fr.yaw_fx;
        for i in 0..m {
            // wrap Λ + yaw into (−W/2, W/2], as λ into (−π, π]
            let mut a = lw;
            if a > fr.half_map_w_fx || a <= -fr.half_map_w_fx {
                a = fr.half_map_w_fx - (fr.half_map_w_fx - a).rem_euclid(fr.map_w_fx);
            }
            let s = row_scale_at(row_scale, v, fr.mh as usize);
            let u = fr.half_map_w_fx + ((s * a) >> ROW_SCALE_BITS);
            sink.put(x + i, u, v);
            lw += dl;
            v += dv;
        }
        return;
    }
    let wfx = fr.map_w_fx;
    let mut u = wrap_u(l + fr.off_fx, wfx);
    if !(0..wfx).contains(&u) {
        u = u.rem_euclid(wfx);
    }
    if fr.coverage {
        for i in 0..m {
            let uu = wrap_u(u, wfx);
            if v < 0 || v > fr.map_h_fx {
                sink.background(x + i);
            } else {
                sink.put(x + i, uu, v);
            }
            u += dl;
            v += dv;
        }
    } else {
        sink.span(x, m, u, v, dl, dv, wfx);
    }
}

#[inline(always)]
pub(crate) fn wrap_u(u: Fx, w: Fx) -> Fx {
    if u >= w {
        u - w
    } else if u < 0 {
        u + w
    } else {
        u
    }
}

/// Fractional bits of the row scale s.
const ROW_SCALE_BITS: u32 = 30;
pub(crate) const ROW_SCALE_ONE: f64 = (1u64 << ROW_SCALE_BITS) as f64;

/// Row scale s(v) (Q.30), linear between map rows.
#[inline(always)]
fn row_scale_at(rs: &[i64], v: Fx, h: usize) -> i64 {
    let vi = (v >> FX_BITS).clamp(0, h as i64 - 1) as usize;
    let fr = (v - ((vi as i64) << FX_BITS)).clamp(0, 1 << FX_BITS);
    rs[vi] + (((rs[vi + 1] - rs[vi]) * fr) >> FX_BITS)
}

//! The scanline walk: per output row, the pixels the table covers are read every 2^shift
//! pixels outward from the screen's centre column in both halves (the same reads for both:
//! the one-eighth symmetry), the column coordinate stepped in whole numbers; Q.16 steps
//! between reads, longitude unwrapped across each span so a span over the ±180° seam
//! steps continuously. The rest (pole zones, beyond the table) is evaluated exactly.
//! Spans go to a [`Sink`].

use super::kernel::{active, SpanJob};
use super::rows::Loan;
use super::setup::{Lv, LvStep, Scan, Setup, Unfold};
use super::sink::Sink;
use super::steps::STEP_REGIONS;
use super::walk::{read_at, span_step, wrap_u, Half, HalfBuf, Nodes};
use crate::geom::fixed::{Fx, FX_BITS};
use crate::geom::mapping::atan2_fast;
use crate::lut::LutTable;

/// Room for a run's blended table nodes (a run that reads more blends per read).
pub(crate) const BLEND_NODES: usize = 512;

/// Room for a scanline's blended table nodes, kept from row to row (no allocation).
pub(crate) type Scratch = [[i32; 2]; BLEND_NODES];

/// What a row task keeps from row to row (made once per task: no allocation per frame):
/// room for the blended table nodes and for a run of a row's positions (the row pass).
pub(crate) struct RowScratch {
    pub(crate) nodes: Scratch,
    pub(crate) row: HalfBuf,
}

impl RowScratch {
    pub(crate) fn new() -> RowScratch {
        RowScratch {
            nodes: [[0; 2]; BLEND_NODES],
            row: HalfBuf::new(),
        }
    }

    /// A row task's scratch, kept by its thread between tasks ([`Loan`]): made afresh
    /// per task, its ~70 KB were zeroed for every rayon job, about 175 times (12 MB) a
    /// 1080p frame on two threads (docs/performance.md, "Prefetch distance").
    pub(crate) fn loan() -> ScratchLoan {
        Loan::take(&KEPT, RowScratch::new)
    }
}

thread_local! {
    /// The scratch a thread's last row task gave back ([`RowScratch::loan`]).
    static KEPT: std::cell::Cell<Option<Box<RowScratch>>> = const { std::cell::Cell::new(None) };
}

/// A [`RowScratch`] on loan from the thread ([`RowScratch::loan`]).
pub(crate) type ScratchLoan = Loan<RowScratch>;

/// Render one scanline into `sink` (`scratch`: room for its blended table nodes).
///
/// The table covers a run of pixels symmetric about the screen's centre column (X = 0),
/// less the exact zone around it near a pole: the *right half* from `xa` to `xe` and its
/// mirror image, the *left half*. The table is read for the right half only, every
/// 2^shift pixels outward from the centre (the shift of the region the span starts in,
/// [`Half`]), the column coordinate a whole-number step per pixel
/// (`Scan::node_per_2x`), no floating point per read; each span is emitted twice, for
/// the left half mirrored (the one-eighth symmetry: X → −X negates Λ; see
/// [`emit_mirror`]) and for the right half. The exact pixels go first.
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
    let Some(h) = Half::exact_rest(scan, fr, sink) else {
        return;
    };
    with_nodes!(scan, table, &h, scratch, |nodes| {
        let mut spans = RightSpans::new(scan, nodes, fr, &h);
        while let Some(s) = spans.next(scan, fr) {
            let (d, m) = (s.d, s.m);
            sink.footprint(s.step, s.region);
            emit_mirror(fr, row_scale, w - h.xa - d - m, m, s.start, s.step, sink);
            emit(fr, row_scale, h.xa + d, m, s.start, s.step, sink);
        }
    });
}

/// `$body` with `$nodes` bound to the half `$h`'s table nodes: blended once into
/// `$scratch` when that pays ([`blend_pays`]; the right half's reads only), else read
/// straight from the band (the body is compiled for both).
macro_rules! with_nodes {
    ($scan:expr, $table:expr, $h:expr, $scratch:expr, |$nodes:ident| $body:expr) => {{
        let (scan, h) = ($scan, $h);
        let band = $table.band(scan.band, scan.wa);
        // From the smallest |X| to the largest, and the next node.
        let k0 = band.node_q(h.a0 * scan.node_per_2x).0;
        let k1 = band.node_q((h.a0 + 2 * h.dn) * scan.node_per_2x).0 + 1;
        let count = k1 + 1 - k0;
        if count <= BLEND_NODES && blend_pays(scan, count, (h.dn + 1) as usize) {
            let nodes = &mut $scratch[..count];
            $crate::render::kernel::active().blend_nodes(&band, k0, nodes);
            let $nodes = &$crate::lut::Blended { band, k0, nodes };
            $body
        } else {
            let $nodes = &band;
            $body
        }
    }};
}
pub(super) use with_nodes;

impl Half {
    /// The right half of `scan`, after evaluating exactly into `sink` the pixels neither
    /// half covers (beyond the table, the pole zone between the halves; the whole row
    /// when there is no half).
    #[inline]
    pub(super) fn exact_rest<S: Sink>(scan: &Scan, fr: &Setup, sink: &mut S) -> Option<Half> {
        let w = fr.w_out as i64;
        let Some(h) = Half::of(scan, fr) else {
            exact_run(scan, fr, 0, w - 1, sink);
            return None;
        };
        exact_run(scan, fr, 0, w - 2 - h.xe, sink);
        exact_run(scan, fr, w - h.xa, h.xa - 1, sink);
        exact_run(scan, fr, h.xe + 1, w - 1, sink);
        Some(h)
    }
}

/// Exact evaluation of pixels x0..=x1 of a scanline (pole zones, beyond the table).
#[inline(never)]
fn exact_run<S: Sink>(scan: &Scan, fr: &Setup, x0: i64, x1: i64, sink: &mut S) {
    let half_w = fr.w_out as f64 * 0.5;
    let c2 = scan.ca * scan.ca;
    for x in x0.max(0)..=x1 {
        let t = (x as f64 + 0.5 - half_w) * scan.t_per_x;
        if let Some(k) = sink.exact_level(x as usize) {
            // Read on level k ≥ 1 (with a level per region), the position may be off by
            // far less than a pixel of the level: `atan2_fast`, within 1e-9 rad.
            let (lambda, phi) = if k >= 1 {
                let lambda = atan2_fast(t, scan.ca) + fr.yaw;
                (lambda, atan2_fast(scan.sa, (t * t + c2).sqrt()))
            } else {
                (
                    t.atan2(scan.ca) + fr.yaw,
                    scan.sa.atan2((t * t + c2).sqrt()),
                )
            };
            sink.exact_on(x as usize, fr.proj.uv(lambda, phi, fr.mw, fr.mh), k);
            continue;
        }
        let lambda = t.atan2(scan.ca) + fr.yaw;
        let phi = scan.sa.atan2((t * t + c2).sqrt());
        sink.exact(x as usize, fr.proj.uv(lambda, phi, fr.mw, fr.mh));
    }
}

/// Whether to blend a run's `nodes` once instead of two per read: when there are at
/// most 1.25 nodes per read (5 with a SIMD blend, `SelectedKernel::simd_blend`), the reads
/// estimated from the run's length and the mean step of the regions. (Callgrind: about
/// 20 instructions per node blended in scalar code against 27 saved per read puts the
/// break-even near 1.35; with the row pass, which reads only the right half, a limit of
/// 2 blended at about 1.9 nodes per read and cost 0.6 instructions per pixel at hfov 90,
/// docs/performance.md. The AVX2 blend costs about 5 instructions a node.) Only the cost
/// depends on it, not the output.
#[inline(never)]
pub(super) fn blend_pays(scan: &Scan, nodes: usize, pixels: usize) -> bool {
    // Reads per 256 pixels, summed over the regions.
    let per_256: usize = scan.shifts.iter().map(|&s| 256 >> s).sum();
    let quarters = if active().simd_blend() { 20 } else { 5 };
    4 * nodes * 256 * STEP_REGIONS <= quarters * pixels * per_256
}

/// One span of a half: pixels `xa + d..xa + d + m`, starting at `start` and stepping by
/// `step` per pixel, in step region `region`.
#[derive(Debug, Clone, Copy)]
pub(super) struct RightSpan {
    /// The first pixel's offset from the half's first pixel.
    pub(super) d: i64,
    /// Pixels.
    pub(super) m: i64,
    /// (Λ, V) at the first pixel.
    pub(super) start: Lv,
    /// (dΛ, dV) per pixel.
    pub(super) step: LvStep,
    /// The step region the span lies in.
    pub(super) region: usize,
}

/// The right half's spans, outward from its first pixel: [`RightSpans::next`] gives
/// each [`RightSpan`] (Λ unwrapped from span to span), the last pixel as a span of one
/// with no step. (An iterator the callers loop over, rather than a closure: it stays
/// inlined.)
pub(super) struct RightSpans<'n, N: Nodes> {
    nodes: &'n N,
    h: Half,
    u: Unfold,
    d: i64,
    r: usize,
    p0: Lv,
    done: bool,
}

impl<'n, N: Nodes> RightSpans<'n, N> {
    #[inline(always)]
    pub(super) fn new(scan: &Scan, nodes: &'n N, fr: &Setup, h: &Half) -> Self {
        let u = Unfold::new(scan, fr, false);
        RightSpans {
            nodes,
            h: *h,
            u,
            d: 0,
            r: h.r0,
            p0: read_at(scan, nodes, h, &u, 0),
            done: false,
        }
    }

    #[inline(always)]
    pub(super) fn next(&mut self, scan: &Scan, fr: &Setup) -> Option<RightSpan> {
        let (d, h) = (self.d, &self.h);
        if d == h.dn {
            if self.done {
                return None;
            }
            self.done = true;
            return Some(RightSpan {
                d,
                m: 1,
                start: self.p0,
                step: LvStep::default(),
                region: self.r,
            });
        }
        while self.r + 1 < STEP_REGIONS && d >= h.e[self.r + 1] {
            self.r += 1;
        }
        let shift = scan.shifts[self.r] as u32;
        let d1 = (d + (1 << shift)).min(h.dn);
        let p1 = read_at(scan, self.nodes, h, &self.u, d1);
        let m = d1 - d;
        let start = self.p0;
        let (p1, step) = span_step(fr, start, p1, m, shift);
        self.d = d1;
        self.p0 = p1;
        Some(RightSpan {
            d,
            m,
            start,
            step,
            region: self.r,
        })
    }
}

/// Emit the mirror image of the right-half span (Λ, V) + j·(dΛ, dV), j < m (X → −X
/// negates Λ) as the `m` pixels from `x` on (left to right: j = m − 1 first).
#[inline(always)]
fn emit_mirror<S: Sink>(
    fr: &Setup,
    row_scale: &[i64],
    x: i64,
    m: i64,
    start: Lv,
    step: LvStep,
    sink: &mut S,
) {
    let end = Lv {
        l: -(start.l + (m - 1) * step.dl),
        v: start.v + (m - 1) * step.dv,
    };
    let step = LvStep {
        dl: step.dl,
        dv: -step.dv,
    };
    emit(fr, row_scale, x, m, end, step, sink);
}

/// Emit `m` pixels from `x` on, starting at (Λ, V) and stepping by (dΛ, dV) (also the
/// grid renderer's spans).
#[inline(always)]
pub(crate) fn emit<S: Sink>(
    fr: &Setup,
    row_scale: &[i64],
    x: i64,
    m: i64,
    start: Lv,
    step: LvStep,
    sink: &mut S,
) {
    let Lv { l, v: vv } = start;
    let LvStep { dl, dv: dvv } = step;
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
        let job = SpanJob {
            x: x as u32,
            len: m as u32,
            u,
            v,
            du: dl,
            dv,
        };
        sink.span(job, wfx);
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

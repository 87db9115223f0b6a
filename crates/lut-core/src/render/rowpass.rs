//! The row pass: a LUT scanline of a full 360° map (equirectangular, sine) drawn with
//! nearest or bilinear sampling as a run of positions and one gather pass, instead of
//! span by span through a [`Sink`].
//!
//! Only the right half of the table-covered pixels is walked (`scanline.rs`: reads every
//! 2^shift pixels outward from the centre, the column coordinate stepped in whole
//! numbers, one-eighth unfolding as sign masks hoisted per half, the seam unwrapped per
//! span); each span's pixels get their Q.8 map position (u wrapped once at the span's
//! start, v = H/2 − V) in a buffer of [`HALF_CHUNK`] pixels. The left half is the right
//! half mirrored: the same reads with Λ negated, so its positions are `mirror − u`
//! (`mirror` = 2·(W/2 + yaw) mod W) and the same v, its pixels in reverse order. Each
//! full buffer goes to the row kernels (`kernel/row.rs`: x wrapped and y clamped in
//! lanes, then the gather and blend), for the left half and then the right one.
//!
//! The pixels sample exactly the positions [`row_pass`] writes; `Renderer::positions`
//! reads the same buffers, so the measured sampling error is this pass's.

use super::kernel::{expand, SpanQ8};
use super::scanline::{blend_pays, mirror_q8, with_nodes, wrap_u, Half, RightSpans};
use super::scanline::{Scratch, BLEND_NODES};
use super::setup::{Scan, Setup};
use super::sink::Sink;
use crate::geom::fixed::{Fx, FX_ONE};
use crate::lut::{Blended, LutTable};

/// Pixels of a half row whose positions are buffered before the row kernels run.
pub(crate) const HALF_CHUNK: usize = 512;

/// A buffer's room: a chunk, then up to one more span (64 pixels) and the last pixel.
const ROOM: usize = HALF_CHUNK + 72;

/// Room for a chunk of a half row's positions (Q.8) and its spans, kept from row to row.
pub(crate) struct HalfBuf {
    u: [i32; ROOM],
    v: [i32; ROOM],
    /// The spans not yet expanded into `u`, `v` (at most one per pixel of a chunk).
    spans: [SpanQ8; HALF_CHUNK + 2],
    n_spans: usize,
}

impl HalfBuf {
    pub(crate) fn new() -> HalfBuf {
        HalfBuf {
            u: [0; ROOM],
            v: [0; ROOM],
            spans: [SpanQ8::default(); HALF_CHUNK + 2],
            n_spans: 0,
        }
    }

    /// Expand the recorded spans into the positions (`kernel::expand`).
    #[inline]
    fn expand(&mut self) {
        expand(&self.spans[..self.n_spans], &mut self.u, &mut self.v);
        self.n_spans = 0;
    }
}

/// A run of positions of a scanline: pixel `right + j` samples (`u[j]`, `v[j]`) (Q.8 map
/// coordinates), and pixel `left_end − 1 − j` samples (`mirror − u[j]`, `v[j]`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct HalfRun<'a> {
    pub(crate) right: usize,
    pub(crate) left_end: usize,
    pub(crate) mirror: i32,
    pub(crate) u: &'a [i32],
    pub(crate) v: &'a [i32],
}

/// Whether the row pass draws the LUT rows of `fr`'s map (full 360° maps whose rows do
/// not scale: equirectangular and sine; the others go span by span).
pub(crate) fn applies(fr: &Setup) -> bool {
    !fr.scaled && !fr.coverage
}

/// One scanline: exact pixels to `sink`, the table-covered ones as runs to `run`.
#[inline]
pub(crate) fn row_pass<S: Sink>(
    scan: &Scan,
    table: &LutTable,
    fr: &Setup,
    (scratch, buf): (&mut Scratch, &mut HalfBuf),
    sink: &mut S,
    mut run: impl FnMut(&mut S, HalfRun<'_>),
) {
    let Some(h) = Half::exact_rest(scan, fr, sink) else {
        return;
    };
    let mirror = mirror_q8(fr) as i32;
    let (xa, w) = (h.xa as usize, fr.w_out);
    let wq = (fr.mw as i32) << 8;
    let mut flush = |buf: &mut HalfBuf, sink: &mut S, c0: i64, n: i64| {
        buf.expand();
        let c0 = c0 as usize;
        // The mirror one width up when that puts the run's first left pixel inside the
        // map (the kernels then seldom wrap; the samples are the same).
        let mirror = if mirror < buf.u[0] {
            mirror + wq
        } else {
            mirror
        };
        let r = HalfRun {
            right: xa + c0,
            left_end: w - xa - c0,
            mirror,
            u: &buf.u[..n as usize],
            v: &buf.v[..n as usize],
        };
        run(sink, r);
    };
    // The first pixel in the buffer.
    let mut c0 = 0i64;
    with_nodes!(scan, table, &h, scratch, |nodes| {
        let mut spans = RightSpans::new(scan, nodes, fr, &h);
        while let Some((d, m, p0, step, _)) = spans.next(scan, fr) {
            fill(fr, buf, (d - c0) as usize, m as usize, p0, step);
            let end = d + m;
            if end - c0 >= HALF_CHUNK as i64 || end > h.dn {
                flush(buf, sink, c0, end - c0);
                c0 = end;
            }
        }
    });
}

/// Q.8 positions of `m` pixels from (Λ, V) by (dΛ, dV) (Q.16) at `k` of `buf`: u =
/// Λ + W/2 + yaw wrapped into [0, W) at the start, v = H/2 − V. Recorded as a span for
/// `kernel::expand` (`i32` lanes relative to the start's whole Q.8 value); a span that
/// travels too far for them (a map width or more: far zoomed out on a tiny map) is
/// written here, u wrapped per pixel.
#[inline(always)]
fn fill(fr: &Setup, buf: &mut HalfBuf, k: usize, m: usize, (l, vv): (Fx, Fx), (dl, dvv): (Fx, Fx)) {
    let wfx = fr.map_w_fx;
    let mut u = wrap_u(l + fr.off_fx, wfx);
    if !(0..wfx).contains(&u) {
        u = u.rem_euclid(wfx);
    }
    let v = fr.half_map_h_fx - vv;
    let dv = -dvv;
    // Lanes run up to 8 past the span. (|v| < 2³², as table entries and H/2 are i32:
    // v >> 8 fits.)
    let reach = dl.unsigned_abs().max(dv.unsigned_abs()) * (m as u64 + 8);
    if reach + FX_ONE as u64 <= (wfx as u64).min(1 << 30) {
        buf.spans[buf.n_spans] = SpanQ8 {
            k: k as u32,
            m: m as u32,
            hu: (u >> 8) as i32,
            lu: (u & 0xFF) as i32,
            du: dl as i32,
            hv: (v >> 8) as i32,
            lv: (v & 0xFF) as i32,
            dv: dv as i32,
        };
        buf.n_spans += 1;
        return;
    }
    // The spans recorded before are expanded first (their last vector may reach here).
    buf.expand();
    let (mut u, mut v) = (u, v);
    for (a, b) in buf.u[k..k + m].iter_mut().zip(&mut buf.v[k..k + m]) {
        *a = (u.rem_euclid(wfx) >> 8) as i32;
        *b = (v >> 8) as i32;
        u += dl;
        v += dv;
    }
}

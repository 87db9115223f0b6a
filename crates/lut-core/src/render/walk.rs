//! The scanline walk's pieces that the walk of spans (`scanline.rs`) and the row pass
//! (`rowpass.rs`) share: a scanline's right half and where its table reads fall
//! ([`Half`]), a read at an offset ([`read_at`], through [`Nodes`]: the band or its
//! blended nodes), the span between two reads ([`span_step`]), the wrap of a
//! longitude into the map ([`wrap_u`]), and the half-row position buffers of the row
//! pass ([`HalfBuf`], [`HalfRun`]). Both walks import this module; it imports neither
//! (nor the sinks), so `render/` has no file circle.

use super::kernel::{active, Positions, SpanQ8};
use super::setup::{Lv, LvStep, Scan, Setup, Unfold};
use super::steps::STEP_REGIONS;
use crate::geom::fixed::Fx;
use crate::lut::{Band, Blended};

/// The right half of a scanline's table-covered pixels, `xa..=xe` (`xa` the first pixel
/// right of the centre or of the exact zone), and where its table reads fall: at pixel
/// offsets d from `xa`, from 0 on by the step of the region d lies in, and at `dn`.
/// The reads of region r are `e[r] + k·2^shift[r]` below `e[r + 1]`, so both halves can
/// walk them in either direction.
#[derive(Debug, Clone, Copy)]
pub(super) struct Half {
    pub(super) xa: i64,
    pub(super) xe: i64,
    /// 2X at `xa` (≥ 0).
    pub(super) a0: i64,
    /// `xe − xa`.
    pub(super) dn: i64,
    /// The first read in each region (regions before `xa`'s: 0).
    pub(super) e: [i64; STEP_REGIONS],
    /// The region of `xa`.
    pub(super) r0: usize,
}

impl Half {
    /// The right half of `scan` (`None`: the table covers none of it).
    #[inline]
    pub(super) fn of(scan: &Scan, fr: &Setup) -> Option<Half> {
        let lut = scan.lut_cols;
        if !scan.lut || lut.is_empty() {
            return None;
        }
        let w = fr.w_out as i64;
        let mut xa = w / 2;
        let zone = scan.zone_cols.and(lut);
        if !zone.is_empty() {
            xa = xa.max(zone.hi + 1);
        }
        let xe = lut.hi.min(w - 1);
        if xe < xa {
            return None;
        }
        let a0 = 2 * xa + 1 - w;
        let thr = &fr.region_2x;
        let mut r0 = 0;
        while r0 + 1 < STEP_REGIONS && a0 >= thr[r0 + 1] {
            r0 += 1;
        }
        let mut e = [0i64; STEP_REGIONS];
        for r in r0..STEP_REGIONS - 1 {
            let n = 1i64 << scan.shifts[r];
            // The first offset in region r + 1, then the first read there.
            let t = (thr[r + 1] - a0 + 1).div_euclid(2);
            let gap = (t - e[r]).max(0);
            e[r + 1] = e[r] + (gap + n - 1) / n * n;
        }
        Some(Half {
            xa,
            xe,
            a0,
            dn: xe - xa,
            e,
            r0,
        })
    }

    /// Where region `r`'s reads end: the first read of the next region (none after the
    /// last one).
    #[inline(always)]
    pub(super) fn region_end(&self, r: usize) -> i64 {
        if r + 1 < STEP_REGIONS {
            self.e[r + 1]
        } else {
            i64::MAX
        }
    }
}

/// The table reads of a scanline: straight from its band, or from its nodes blended once.
pub(super) trait Nodes {
    /// The table's (Λ, V) at node coordinate `c` ([`Band::lookup_q`]), before unfolding.
    fn read_q(&self, c: i64) -> Lv;
}

impl Nodes for Band<'_> {
    #[inline(always)]
    fn read_q(&self, c: i64) -> Lv {
        Band::lookup_q(self, c).into()
    }
}

impl Nodes for Blended<'_> {
    #[inline(always)]
    fn read_q(&self, c: i64) -> Lv {
        Blended::lookup_q(self, c).into()
    }
}

/// The unfolded read at offset d of the half `h`.
#[inline(always)]
pub(super) fn read_at<N: Nodes>(scan: &Scan, nodes: &N, h: &Half, u: &Unfold, d: i64) -> Lv {
    u.apply(nodes.read_q((h.a0 + 2 * d) * scan.node_per_2x))
}

/// The span from `p0` to the next read `p1` over `m` pixels (`shift`: log2 of the
/// region's step, used when m is the whole step): `p1` with Λ unwrapped across the ±180°
/// seam (a jump of one map width), and the per-pixel step.
#[inline(always)]
pub(super) fn span_step(fr: &Setup, p0: Lv, p1: Lv, m: i64, shift: u32) -> (Lv, LvStep) {
    let d = p1.l - p0.l;
    let mut l1 = p1.l;
    if d > fr.half_map_w_fx {
        l1 -= fr.map_w_fx;
    } else if d < -fr.half_map_w_fx {
        l1 += fr.map_w_fx;
    }
    let step = if m == 1i64 << shift {
        LvStep {
            dl: (l1 - p0.l) >> shift,
            dv: (p1.v - p0.v) >> shift,
        }
    } else {
        LvStep {
            dl: (l1 - p0.l) / m,
            dv: (p1.v - p0.v) / m,
        }
    };
    (Lv { l: l1, v: p1.v }, step)
}

/// `u` (at most one period `w` outside `0..w`) wrapped into `0..w`.
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

/// Pixels of a half row whose positions are buffered before the row kernels run: a whole
/// half row up to 2048-pixel frames, so a 1080p row is drawn as two runs rather than
/// four (each run starts with a burst of prefetches its first pixels wait for: 512 drew
/// the 8k frame at hfov 90 about 3 % slower, docs/performance.md "Prefetch distance").
pub(crate) const HALF_CHUNK: usize = 1024;

/// A buffer's room: a chunk, then up to one more span (64 pixels) and the last pixel,
/// and the 15 positions past it a 16-lane `kernel::expand` writes.
pub(super) const ROOM: usize = HALF_CHUNK + 80;

/// Room for a chunk of a half row's positions (Q.8) and its spans, kept from row to row.
pub(crate) struct HalfBuf {
    pub(super) u: [i32; ROOM],
    pub(super) v: [i32; ROOM],
    /// The left half's u (its v is the right half's).
    pub(super) ul: [i32; ROOM],
    /// The spans not yet expanded into `u`, `v` (at most one per pixel of a chunk).
    pub(super) spans: [SpanQ8; HALF_CHUNK + 2],
    pub(super) n_spans: usize,
    /// The runs of equal level of detail (trilinear), in order: at most one per span.
    pub(super) segs: [Seg; HALF_CHUNK + 2],
    pub(super) n_segs: usize,
    /// Room for per-position weights (trilinear: the second level's).
    pub(super) w: [u32; ROOM],
}

/// Positions from `start` (of a [`HalfRun`]) to the next `Seg`'s start (or the run's end)
/// have the level of detail `lod` (Q.8, ≥ 0; 0: level 0 alone, plain bilinear).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Seg {
    pub(crate) start: u32,
    pub(crate) lod: i32,
}

impl HalfBuf {
    pub(crate) fn new() -> HalfBuf {
        HalfBuf {
            u: [0; ROOM],
            v: [0; ROOM],
            ul: [0; ROOM],
            spans: [SpanQ8::default(); HALF_CHUNK + 2],
            n_spans: 0,
            segs: [Seg::default(); HALF_CHUNK + 2],
            n_segs: 0,
            w: [0; ROOM],
        }
    }

    /// The span from position `start` on has level of detail `lod` (a new [`Seg`]
    /// unless it equals the last one's; below 0 is 0).
    #[inline(always)]
    pub(super) fn push_lod(&mut self, start: u32, lod: i32) {
        let lod = lod.max(0);
        if self.n_segs == 0 || self.segs[self.n_segs - 1].lod != lod {
            self.segs[self.n_segs] = Seg { start, lod };
            self.n_segs += 1;
        }
    }

    /// Expand the recorded spans into the positions (`kernel::expand`).
    #[inline]
    pub(super) fn expand(&mut self) {
        let p = Positions {
            u: &mut self.u,
            v: &mut self.v,
            ul: &mut self.ul,
        };
        active().expand::<true>(&self.spans[..self.n_spans], p);
        self.n_spans = 0;
    }
}

/// A run of positions of a scanline: pixel `right + j` samples (`u[j]`, `v[j]`) (Q.8 map
/// coordinates), and pixel `left_end − 1 − j`, its mirror image, (`ul[j]`, `v[j]`);
/// for a sink that asks ([`Sink::LOD`]) the levels of detail of its positions (`segs`),
/// and room for a weight per position (`w`).
#[derive(Debug)]
pub(crate) struct HalfRun<'a> {
    pub(crate) right: usize,
    pub(crate) left_end: usize,
    pub(crate) u: &'a [i32],
    pub(crate) v: &'a [i32],
    pub(crate) ul: &'a [i32],
    pub(crate) segs: &'a [Seg],
    pub(crate) w: &'a mut [u32],
}

//! The row pass: a LUT scanline of a full 360° map (equirectangular, sine) drawn as a run
//! of positions and one gather pass, instead of span by span through a [`Sink`]: nearest
//! and bilinear ([`pixel_row`]), trilinear ([`tri_row`]: each span's level of detail
//! recorded, runs on one level sampled together, the next level blended in), partial
//! maps (`crop_run`; trilinear: `crop_tri_run`, the same grouping, each level's pass
//! chunk by chunk as `crop_run`).
//!
//! Only the right half of the table-covered pixels is walked (`scanline.rs`: reads every
//! 2^shift pixels outward from the centre, the column coordinate stepped in whole
//! numbers, one-eighth unfolding as sign masks hoisted per half, the seam unwrapped per
//! span). The left half is the right half mirrored: the same reads with Λ negated, so
//! each span's mirror image has u = 2·(W/2 + yaw) − u (`Setup::mirror_fx`), the same v,
//! and its pixels in reverse order. Each span is recorded and `kernel::expand` writes
//! the floored Q.8 map positions of both (u wrapped once at the span's start, v = H/2 −
//! V) into buffers of [`HALF_CHUNK`] pixels of the half; each full buffer goes to the
//! row kernels (`kernel/row.rs`: x wrapped and y clamped in lanes, then the gather and
//! blend), for the left half and then the right one.
//!
//! The pixels sample exactly the positions [`row_pass`] writes; `Renderer::positions`
//! reads the same buffers, so the measured sampling error is this pass's.

use super::kernel::{
    active, wrap_q8, Level, Q16Start, Q16Step, SelectedKernel, SpanAt, SpanQ8, Texels,
};
use super::scanline::{blend_pays, render_row, with_nodes};
use super::scanline::{RowScratch, BLEND_NODES};
use super::setup::{Lv, LvStep, Scan, Setup, Unfold};
use super::sink::Sink;
use super::sink::{PixelSink, PosSink, TriSink};
use super::steps::STEP_REGIONS;
use super::walk::{read_at, span_step, wrap_u, Half, HalfBuf, HalfRun, Nodes, HALF_CHUNK};
use crate::geom::fixed::FX_ONE;
use crate::lut::LutTable;
use crate::map::envmap::EnvMap;
use crate::map::sample::lerp_px;

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
    scratch: &mut RowScratch,
    sink: &mut S,
    mut run: impl FnMut(&mut S, HalfRun<'_>),
) {
    let RowScratch {
        nodes: scratch,
        row: buf,
    } = scratch;
    let Some(h) = Half::exact_rest(scan, fr, sink) else {
        return;
    };
    let (xa, w) = (h.xa as usize, fr.w_out);
    let mut flush = |buf: &mut HalfBuf, sink: &mut S, c0: i64, n: i64| {
        buf.expand();
        let (c0, n) = (c0 as usize, n as usize);
        let r = HalfRun {
            right: xa + c0,
            left_end: w - xa - c0,
            u: &buf.u[..n],
            v: &buf.v[..n],
            ul: &buf.ul[..n],
            segs: &buf.segs[..buf.n_segs],
            w: &mut buf.w[..n],
        };
        run(sink, r);
        buf.n_segs = 0;
    };
    // The first pixel in the buffer.
    let mut c0 = 0i64;
    with_nodes!(scan, table, &h, scratch, |nodes| {
        // The spans of `RightSpans`, walked region by region: inside a region every span
        // is the region's whole step (its reads lie a whole number of steps apart,
        // `Half`), so the tight loop below needs no region lookup, no clamp to the half's
        // end and no division; the one span that ends the half short goes through
        // `span_step` as in `RightSpans::next`.
        let un = Unfold::new(scan, fr, false);
        let (dn, npx) = (h.dn, scan.node_per_2x);
        let mut p0 = read_at(scan, nodes, &h, &un, 0);
        let (mut d, mut r) = (0i64, h.r0);
        while d < dn {
            while r + 1 < STEP_REGIONS && d >= h.e[r + 1] {
                r += 1;
            }
            // (The walk's step: `shifts`, longer with a level per region.)
            let shift = scan.lod_shifts[r] as u32;
            let n = 1i64 << shift;
            let stop = h.region_end(r).min(dn);
            let mut c = (h.a0 + 2 * d) * npx;
            let dc = 2 * n * npx;
            let lim = step_limit(fr, n as usize);
            while d + n <= stop {
                c += dc;
                let p1 = un.apply(nodes.read_q(c));
                let (p1, step) = span_step(fr, p0, p1, n, shift);
                if S::LOD {
                    let lod = sink.span_lod(step, r);
                    buf.push_lod((d - c0) as u32, lod);
                }
                let at = BufSpan {
                    k: (d - c0) as usize,
                    m: n as usize,
                };
                fill_within(fr, buf, at, p0, step, lim);
                p0 = p1;
                d += n;
                if d - c0 >= HALF_CHUNK as i64 {
                    flush(buf, sink, c0, d - c0);
                    c0 = d;
                }
            }
            if d < dn && d < h.region_end(r) {
                // A span that ends short of the step (at the half's end, or at the
                // region's end when the walk's step is longer than `shifts`).
                let d1 = (d + n).min(dn).min(h.region_end(r));
                let p1 = read_at(scan, nodes, &h, &un, d1);
                let m = d1 - d;
                let (p1, step) = span_step(fr, p0, p1, m, shift);
                if S::LOD {
                    let lod = sink.span_lod(step, r);
                    buf.push_lod((d - c0) as u32, lod);
                }
                let at = BufSpan {
                    k: (d - c0) as usize,
                    m: m as usize,
                };
                fill(fr, buf, at, p0, step);
                p0 = p1;
                d = d1;
                if d - c0 >= HALF_CHUNK as i64 {
                    flush(buf, sink, c0, d - c0);
                    c0 = d;
                }
            }
        }
        // The last pixel, a span of one.
        if S::LOD {
            let lod = sink.span_lod(LvStep::default(), r);
            buf.push_lod((d - c0) as u32, lod);
        }
        let at = BufSpan {
            k: (d - c0) as usize,
            m: 1,
        };
        fill(fr, buf, at, p0, LvStep::default());
        flush(buf, sink, c0, d + 1 - c0);
    });
}

/// Where a span's pixels go in the half-row buffers: `m` pixels from position `k`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BufSpan {
    /// The first pixel's position in the buffers.
    pub(crate) k: usize,
    /// Pixels.
    pub(crate) m: usize,
}

/// Q.8 positions of `at.m` pixels from `start` (Λ, V) by `step` (dΛ, dV) (Q.16) at
/// `at.k` of `buf`: u = Λ + W/2 + yaw wrapped into [0, W) at the start, v = H/2 − V, and
/// the mirror image's u = W/2 + yaw − Λ (`Setup::mirror_fx` − u). Recorded as a span
/// for `kernel::expand` (`i32` lanes relative to the starts' whole Q.8 values); a span
/// that travels too far for them (a map width or more: far zoomed out on a tiny map) is
/// written here, u wrapped per pixel.
#[inline(always)]
fn fill(fr: &Setup, buf: &mut HalfBuf, at: BufSpan, start: Lv, step: LvStep) {
    fill_within(fr, buf, at, start, step, step_limit(fr, at.m));
}

/// The largest |dΛ|, |dV| (Q.16 per pixel) a span of `m` pixels may step and still be
/// recorded for `kernel::expand` (see [`fill`]): its lanes, up to 16 past the span, stay
/// less than min(W, 2³⁰) − 1 pixels from its start. (The same test as
/// `max(|dΛ|, |dV|)·(m + 16) + 1 px ≤ min(W, 2³⁰)`, with the division done once per
/// step length instead of the product per span.)
#[inline(always)]
fn step_limit(fr: &Setup, m: usize) -> u64 {
    ((fr.map_w_fx as u64).min(1 << 30) - FX_ONE as u64) / (m as u64 + 16)
}

/// [`fill`] with the span's [`step_limit`] given.
#[inline(always)]
fn fill_within(fr: &Setup, buf: &mut HalfBuf, at: BufSpan, start: Lv, step: LvStep, lim: u64) {
    let BufSpan { k, m } = at;
    let Lv { l, v: vv } = start;
    let LvStep { dl, dv: dvv } = step;
    let wfx = fr.map_w_fx;
    let mut u = wrap_u(l + fr.off_fx, wfx);
    // (As unsigned: below 0 or from W on.)
    if u as u64 >= wfx as u64 {
        u = u.rem_euclid(wfx);
    }
    // In [0, W] (the kernels' common case: inside the map).
    let mut ul = fr.mirror_fx - u;
    if ul < 0 {
        ul += wfx;
    }
    let v = fr.half_map_h_fx - vv;
    let dv = -dvv;
    // Lanes run up to 16 past the span. (|v| < 2³², as table entries and H/2 are i32:
    // v >> 8 fits.)
    if dl.unsigned_abs().max(dv.unsigned_abs()) <= lim {
        buf.spans[buf.n_spans] = SpanQ8::from_q16(
            SpanAt {
                k: k as u32,
                m: m as u32,
            },
            Q16Start { u, v, ul },
            Q16Step { du: dl, dv },
        );
        buf.n_spans += 1;
        return;
    }
    // The spans recorded before are expanded first (their last vector may reach here).
    buf.expand();
    let (mut u, mut v, mut ul) = (u, v, ul);
    for j in k..k + m {
        buf.u[j] = (u.rem_euclid(wfx) >> 8) as i32;
        buf.v[j] = (v >> 8) as i32;
        buf.ul[j] = (ul.rem_euclid(wfx) >> 8) as i32;
        u += dl;
        v += dv;
        ul -= dl;
    }
}

/// A scanline of the LUT renderer: what its walk reads.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LutRow<'a> {
    /// The scanline's setup: its table rows, scale, index steps and zones.
    pub(crate) scan: &'a Scan,
    /// The table.
    pub(crate) table: &'a LutTable,
    /// The frame's setup.
    pub(crate) fr: &'a Setup,
    /// The map's row scale s(v) per map row (Q.30, `scanline::ROW_SCALE_ONE`) for
    /// projections whose rows scale; empty for the others.
    pub(crate) row_scale: &'a [i64],
}

/// Draw one LUT scanline of `map` (`t`: its texels) into `row`: the row pass where it
/// applies ([`applies`]; partial maps through [`crop_run`]), else span by span through
/// the sink.
#[inline]
pub(crate) fn pixel_row<const BILINEAR: bool, const CROP: bool>(
    lut: LutRow<'_>,
    scratch: &mut RowScratch,
    map: &EnvMap,
    t: &Texels<'_>,
    row: &mut [u32],
) {
    let LutRow {
        scan,
        table,
        fr,
        row_scale,
    } = lut;
    let mut s = PixelSink::<BILINEAR, CROP>::new(row, map);
    if !applies(fr) {
        render_row(scan, table, fr, row_scale, &mut scratch.nodes, &mut s);
        s.flush();
        return;
    }
    let wq = (map.width() as i32) << 8;
    let t = &t.toward_next_scanline(scan.next_dv);
    row_pass(scan, table, fr, scratch, &mut s, |s, r| {
        let n = r.u.len();
        if CROP {
            crop_run(s, t, wq, r);
            return;
        }
        active().sample_q8::<BILINEAR, true>(t, r.ul, r.v, &mut s.row[r.left_end - n..r.left_end]);
        active().sample_q8::<BILINEAR, false>(t, r.u, r.v, &mut s.row[r.right..r.right + n]);
    });
}

/// Draw one trilinear LUT scanline into `s` (its level of detail set for the
/// scanline): the row pass where it applies ([`applies`]; [`tri_run`], partial maps
/// [`crop_tri_run`]), else span by span through the sink.
#[inline]
pub(crate) fn tri_row(lut: LutRow<'_>, scratch: &mut RowScratch, s: &mut TriSink<'_>) {
    let LutRow {
        scan,
        table,
        fr,
        row_scale,
    } = lut;
    if !applies(fr) {
        render_row(scan, table, fr, row_scale, &mut scratch.nodes, s);
        s.flush();
        return;
    }
    let levels = s.levels;
    let wq = (s.map.width() as i32) << 8;
    if s.map.crop().is_some() {
        let (map, crop) = (s.map, crop_levels(s.map, levels));
        row_pass(scan, table, fr, scratch, s, |s, r| {
            crop_tri_run(map, &crop, wq, r, s.row);
        });
        return;
    }
    let dv = scan.next_dv;
    row_pass(scan, table, fr, scratch, s, |s, r| {
        tri_run(levels, wq, dv, r, s.row);
    });
}

/// The first pyramid level and the second level's weight of level of detail `lod` (Q.8)
/// with levels `0..=last`, as `EnvMap::trilinear` resolves them: 0 and 0 for `lod` ≤ 0;
/// else k = `lod >> 8` clamped to `last`, weight `lod & 0xFF` (the second level, k + 1,
/// counts only below `last`).
#[inline(always)]
fn resolve(lod: i32, last: usize) -> Resolved {
    if lod <= 0 {
        Resolved { k: 0, weight: 0 }
    } else {
        Resolved {
            k: ((lod >> 8) as usize).min(last),
            weight: (lod & 0xFF) as u32,
        }
    }
}

/// A level of detail resolved to pyramid levels ([`resolve`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Resolved {
    /// The first level, k.
    k: usize,
    /// The weight of the second level, k + 1, out of 256 (0: the first level alone).
    weight: u32,
}

/// A trilinear run (`levels`: level 0, the map `wq` / 256 wide, and its pyramid; `dv`:
/// the next scanline's offset, `Texels::toward_next_scanline`): the
/// positions are grouped by their first level ka (consecutive [`Seg`]s); each group is
/// sampled bilinearly on level ka (level 0: the bilinear row kernel, which is all of a
/// magnified run), then, unless ka is the last level, level ka + 1 is blended in by each
/// position's weight from the group's first segment with a weight not 0 to its last
/// (the segments between with weight 0 are blended by 0: `lerp_px` by 0 is the
/// identity). Per pixel that is
/// `EnvMap::trilinear` at the position (u wrapped into the map) with the span's level of
/// detail.
fn tri_run(levels: &[Texels], wq: i32, dv: i32, r: HalfRun<'_>, row: &mut [u32]) {
    tri_run_with(active(), levels, (wq, dv), r, row);
}

/// [`tri_run`] with kernel `kernel` (the tests run every kernel the CPU has; `wd`: the
/// map's width and the next scanline's offset, Q.8).
#[inline(always)]
fn tri_run_with(
    kernel: SelectedKernel,
    levels: &[Texels],
    wd: (i32, i32),
    r: HalfRun<'_>,
    row: &mut [u32],
) {
    let (wq, dv) = wd;
    tri_groups(levels.len() - 1, r, row, |k, w, Uv { u, v }, out| {
        let t = &levels[k].toward_next_scanline(dv);
        let lv = Level {
            k: k as u32,
            wq,
            w: w.unwrap_or(&[]),
        };
        match (k, w.is_some(), out) {
            (0, false, Out::Left(o)) => kernel.sample_q8::<true, true>(t, u, v, o),
            (0, false, Out::Right(o)) => kernel.sample_q8::<true, false>(t, u, v, o),
            (_, false, Out::Left(o)) => kernel.sample_level::<true, false>(t, u, v, o, &lv),
            (_, false, Out::Right(o)) => kernel.sample_level::<false, false>(t, u, v, o, &lv),
            (_, true, Out::Left(o)) => kernel.sample_level::<true, true>(t, u, v, o, &lv),
            (_, true, Out::Right(o)) => kernel.sample_level::<false, true>(t, u, v, o, &lv),
        }
    });
}

/// Where a pass of [`tri_groups`] writes: the left half's pixels (reversed: position j
/// is `o[len − 1 − j]`) or the right half's (in order).
enum Out<'a> {
    Left(&'a mut [u32]),
    Right(&'a mut [u32]),
}

/// The level-0 positions of a group of [`tri_groups`] (Q.8, indexed alike; the left
/// half's u for its pass).
#[derive(Debug, Clone, Copy)]
struct Uv<'a> {
    u: &'a [i32],
    v: &'a [i32],
}

/// The grouping of [`tri_run`] over levels `0..=last`: `pass(k, w, uv, out)` samples
/// level k bilinearly at the level-0 positions `uv` into `out`, written (`w` `None`)
/// or blended in by the weights `w` (one per position).
fn tri_groups(
    last: usize,
    r: HalfRun<'_>,
    row: &mut [u32],
    mut pass: impl FnMut(usize, Option<&[u32]>, Uv<'_>, Out<'_>),
) {
    let n = r.u.len();
    let segs = r.segs;
    let end = |i: usize| segs.get(i).map_or(n, |s| s.start as usize);
    let mut i = 0;
    while i < segs.len() {
        let ka = resolve(segs[i].lod, last).k;
        let mut e = i + 1;
        while e < segs.len() && resolve(segs[e].lod, last).k == ka {
            e += 1;
        }
        let (a, b) = (segs[i].start as usize, end(e));
        let (u, ul, v) = (&r.u[a..b], &r.ul[a..b], &r.v[a..b]);
        let (left, right) = (r.left_end - b..r.left_end - a, r.right + a..r.right + b);
        pass(ka, None, Uv { u: ul, v }, Out::Left(&mut row[left]));
        pass(ka, None, Uv { u, v }, Out::Right(&mut row[right]));
        // The second level over the segments from the first to the last with a weight.
        let weighted = |j: &usize| resolve(segs[*j].lod, last).weight != 0;
        let (Some(f), Some(l)) = ((i..e).find(weighted), (i..e).rev().find(weighted)) else {
            i = e;
            continue;
        };
        i = e;
        if ka == last {
            continue;
        }
        let (a, b) = (segs[f].start as usize, end(l + 1));
        for (j, s) in segs.iter().enumerate().take(l + 1).skip(f) {
            let w = resolve(s.lod, last).weight;
            r.w[s.start as usize - a..end(j + 1) - a].fill(w);
        }
        let w = Some(&r.w[..b - a]);
        let (u, ul, v) = (&r.u[a..b], &r.ul[a..b], &r.v[a..b]);
        let (left, right) = (r.left_end - b..r.left_end - a, r.right + a..r.right + b);
        pass(ka + 1, w, Uv { u: ul, v }, Out::Left(&mut row[left]));
        pass(ka + 1, w, Uv { u, v }, Out::Right(&mut row[right]));
    }
}

/// A pyramid level of a partial map as [`crop_tri_run`] reads it: level `k`'s stored
/// texels `t` and where they sit in the padded full map's level k (Q.8: the first column
/// and row, the stored width and height, the level's full width and height; the columns
/// continue at 0 past the seam).
pub(crate) struct CropLevel<'a> {
    k: u32,
    t: &'a Texels<'a>,
    left: i32,
    top: i32,
    cw: i32,
    ch: i32,
    fw: i32,
    fh: i32,
}

/// The levels of partial map `map` for [`crop_tri_run`] (`levels`: its
/// `kernel::level_texels`).
pub(crate) fn crop_levels<'a>(map: &'a EnvMap, levels: &'a [Texels<'a>]) -> Vec<CropLevel<'a>> {
    let pyramid = map.pyramid();
    levels
        .iter()
        .enumerate()
        .map(|(k, t)| CropLevel::new(k as u32, if k == 0 { map } else { &pyramid[k - 1] }, t))
        .collect()
}

impl<'a> CropLevel<'a> {
    /// Level `k` of a partial map: `m` (the map itself for level 0, else its pyramid's
    /// level k) and its stored texels `t`.
    fn new(k: u32, m: &EnvMap, t: &'a Texels<'a>) -> CropLevel<'a> {
        let (fw, fh) = (m.width() as i32, m.height() as i32);
        let (left, top, cw, ch) = m.crop().map_or((0, 0, fw, fh), |c| {
            let (l, t) = (c.left() as i32, c.top() as i32);
            (l, t, c.width() as i32, c.height() as i32)
        });
        CropLevel {
            k,
            t,
            left: left << 8,
            top: top << 8,
            cw: cw << 8,
            ch: ch << 8,
            fw: fw << 8,
            fh: fh << 8,
        }
    }

    /// The level-k Q.8 column of level-0 position `u` (within two panorama widths of it,
    /// `wq` the panorama's width), relative to the first stored column: in `0..fw`, the
    /// columns continuing at 0 past the seam.
    #[inline(always)]
    fn column(&self, u: i32, wq: i32) -> i32 {
        let x = (wrap_q8(u, wq) >> self.k) - self.left;
        if x < 0 {
            x + self.fw
        } else {
            x
        }
    }

    /// Whether the sample at (x, vk) (level-k Q.8: x relative to the stored first column,
    /// in `0..fw`; vk absolute) is the background: level 0 where the pixel holding it is
    /// not stored (v clamped into the panorama, as `Crop::locate`), the other levels
    /// where none of its four texels is (`EnvMap::bilinear_padded`). May say no when
    /// it is (the caller then samples per pixel), never yes when it is not.
    #[inline(always)]
    fn misses(&self, x: i32, vk: i32) -> bool {
        let vc = vk.clamp(0, self.fh - 1) - self.top;
        if self.k == 0 {
            return x >= self.cw || !(0..self.ch).contains(&vc);
        }
        // Rows y0 and y0 + 1 (clamped into the level, which stays among them).
        let y0 = (vc - 128) >> 8;
        (self.cw + 128..self.fw - 128).contains(&x) || y0 + 1 < 0 || y0 >= self.ch >> 8
    }
}

/// One level's pass of a partial map's trilinear run ([`crop_tri_run`]): level `lv.k`'s
/// samples at level-0 positions (`u` within two panorama widths of it, `wq` its width,
/// Q.8) written into `out` or, with `BLEND`, blended in by `w` (`MIRROR`: `out`
/// reversed, as [`sample_level`]); per pixel `EnvMap::level_bilinear`. As [`crop_run`],
/// chunk by chunk: a chunk whose samples all read stored texels away from the stored
/// rectangle's edge goes to the row kernels at positions moved onto the texels, one
/// wholly in the background is the background, the others go per pixel.
fn crop_level_pass<const MIRROR: bool, const BLEND: bool>(
    map: &EnvMap,
    lv: &CropLevel<'_>,
    wq: i32,
    uv: Uv<'_>,
    w: &[u32],
    out: &mut [u32],
) {
    let Uv { u, v } = uv;
    let n = out.len();
    let bg = map.background();
    let (mut su, mut sv) = ([0i32; CROP_CHUNK], [0i32; CROP_CHUNK]);
    let (lo, hi_u, hi_v) = (128, lv.cw - 128, lv.ch - 128);
    for j0 in (0..n).step_by(CROP_CHUNK) {
        let m = CROP_CHUNK.min(n - j0);
        let (mut inside, mut outside) = (true, true);
        for j in 0..m {
            let vk = v[j0 + j] >> lv.k;
            let x = lv.column(u[j0 + j], wq);
            let y = vk - lv.top;
            inside &= (lo..hi_u).contains(&x) && (lo..hi_v).contains(&y);
            outside &= lv.misses(x, vk);
            (su[j], sv[j]) = (x, y);
        }
        let o = if MIRROR {
            &mut out[n - j0 - m..n - j0]
        } else {
            &mut out[j0..j0 + m]
        };
        let w = if BLEND { &w[j0..j0 + m] } else { &[][..] };
        let at = |j: usize| if MIRROR { m - 1 - j } else { j };
        if inside {
            let (su, sv) = (&su[..m], &sv[..m]);
            if BLEND {
                // (Level 0 of the stored texels: u wrapped by the stored width, a no-op.)
                let l = Level { k: 0, wq: lv.cw, w };
                active().sample_level::<MIRROR, true>(lv.t, su, sv, o, &l);
            } else {
                active().sample_q8::<true, MIRROR>(lv.t, su, sv, o);
            }
        } else if outside {
            for j in 0..m {
                let p = &mut o[at(j)];
                *p = if BLEND { lerp_px(*p, bg, w[j]) } else { bg };
            }
        } else {
            for j in 0..m {
                let uf = (wrap_q8(u[j0 + j], wq) as i64) << 8;
                let s = map.level_bilinear(lv.k, uf, (v[j0 + j] as i64) << 8);
                let p = &mut o[at(j)];
                *p = if BLEND { lerp_px(*p, s, w[j]) } else { s };
            }
        }
    }
}

/// A trilinear run of partial map `map` (the panorama `wq` / 256 wide; `levels`: its
/// [`crop_levels`]): [`tri_run`]'s grouping, each level's pass by [`crop_level_pass`].
/// Per pixel that is `EnvMap::trilinear` at the position (u wrapped into the panorama)
/// with the span's level of detail.
fn crop_tri_run(map: &EnvMap, levels: &[CropLevel], wq: i32, r: HalfRun<'_>, row: &mut [u32]) {
    tri_groups(levels.len() - 1, r, row, |k, w, uv, out| {
        let lv = &levels[k];
        match (w, out) {
            (None, Out::Left(o)) => crop_level_pass::<true, false>(map, lv, wq, uv, &[], o),
            (None, Out::Right(o)) => crop_level_pass::<false, false>(map, lv, wq, uv, &[], o),
            (Some(w), Out::Left(o)) => crop_level_pass::<true, true>(map, lv, wq, uv, w, o),
            (Some(w), Out::Right(o)) => crop_level_pass::<false, true>(map, lv, wq, uv, w, o),
        }
    });
}

/// Pixels of a partial map's run checked and sampled together by [`crop_run`].
const CROP_CHUNK: usize = 64;

/// A run of a partial map's scanline: each chunk of [`CROP_CHUNK`] pixels of a half whose
/// positions all lie inside the stored pixels — away from their first and last row and
/// column, where the crop samplers meet the background or the padding — is sampled by
/// the row kernels on the stored texels at the positions moved onto them (the same
/// texels and weights as `EnvMap::bilinear_cropped` / `nearest_cropped` there); a chunk
/// whose pixels all fall on uncovered pixels (as `Crop::locate` decides, v clamped into
/// the panorama first) is the background; the other chunks go pixel by pixel through
/// the crop samplers. `wq`: the panorama's width, Q.8.
#[inline]
fn crop_run<const BILINEAR: bool, const CROP: bool>(
    s: &mut PixelSink<'_, BILINEAR, CROP>,
    t: &Texels<'_>,
    wq: i32,
    r: HalfRun<'_>,
) {
    if s.map.crop().is_none() {
        return;
    }
    // The stored pixels as level 0 of the partial map's pyramid sees them (the same
    // column arithmetic, the same test for the background).
    let lv = CropLevel::new(0, s.map, t);
    let (cw, ch, top) = (lv.cw, lv.ch, lv.top);
    // The stored pixels' interior, in Q.8 positions relative to their first pixel.
    let (lo, hi_u, hi_v) = if BILINEAR {
        (128, cw - 128, ch - 128)
    } else {
        (0, cw, ch)
    };
    let bg = s.map.background();
    let q = |u: i32| (u.rem_euclid(wq) as i64) << 8;
    let n = r.u.len();
    let (mut su, mut sl, mut sv) = ([0i32; CROP_CHUNK], [0i32; CROP_CHUNK], [0i32; CROP_CHUNK]);
    for j0 in (0..n).step_by(CROP_CHUNK) {
        let m = CROP_CHUNK.min(n - j0);
        let (mut right_in, mut left_in) = (true, true);
        let (mut right_out, mut left_out) = (true, true);
        for j in 0..m {
            let v = r.v[j0 + j];
            let (a, b) = (lv.column(r.u[j0 + j], wq), lv.column(r.ul[j0 + j], wq));
            let v_in = (lo..hi_v).contains(&(v - top));
            right_in &= v_in && (lo..hi_u).contains(&a);
            left_in &= v_in && (lo..hi_u).contains(&b);
            right_out &= lv.misses(a, v);
            left_out &= lv.misses(b, v);
            (su[j], sl[j], sv[j]) = (a, b, v - top);
        }
        let lend = r.left_end - j0;
        if left_in {
            active().sample_q8::<BILINEAR, true>(t, &sl[..m], &sv[..m], &mut s.row[lend - m..lend]);
        } else if left_out {
            s.row[lend - m..lend].fill(bg);
        } else {
            for j in j0..j0 + m {
                s.put(r.left_end - 1 - j, q(r.ul[j]), (r.v[j] as i64) << 8);
            }
        }
        let rs = r.right + j0;
        if right_in {
            active().sample_q8::<BILINEAR, false>(t, &su[..m], &sv[..m], &mut s.row[rs..rs + m]);
        } else if right_out {
            s.row[rs..rs + m].fill(bg);
        } else {
            for j in j0..j0 + m {
                s.put(r.right + j, q(r.u[j]), (r.v[j] as i64) << 8);
            }
        }
    }
}

/// The sampling positions of one LUT scanline into `row`: the row pass's (`wq` = 256·W,
/// when the row pass draws these pixels), else the span walk's.
#[inline]
pub(crate) fn position_row(
    lut: LutRow<'_>,
    scratch: &mut RowScratch,
    wq: Option<i32>,
    row: &mut [Option<(f64, f64)>],
) {
    let LutRow {
        scan,
        table,
        fr,
        row_scale,
    } = lut;
    let mut s = PosSink { row };
    let Some(wq) = wq else {
        render_row(scan, table, fr, row_scale, &mut scratch.nodes, &mut s);
        return;
    };
    row_pass(scan, table, fr, scratch, &mut s, |s, r| {
        // As the row kernels sample them: Q.8, u wrapped into the map; the left half
        // first (the centre pixel of an odd width is the right half's).
        let px = |u: i32, v: i32| Some((u.rem_euclid(wq) as f64 / 256.0, v as f64 / 256.0));
        for (j, (&u, &v)) in r.ul.iter().zip(r.v).enumerate() {
            s.row[r.left_end - 1 - j] = px(u, v);
        }
        for (j, (&u, &v)) in r.u.iter().zip(r.v).enumerate() {
            s.row[r.right + j] = px(u, v);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::projection::Projection;
    use crate::render::kernel::level_texels;
    use crate::render::walk::Seg;

    /// A xorshift generator: each call a number below its argument.
    fn xorshift(mut seed: u64) -> impl FnMut(u64) -> u64 {
        move |n| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        }
    }

    /// Up to 40 segments over `n` positions (the first at 0) with levels of detail
    /// −1..9 (Q.8).
    fn random_segs(rnd: &mut impl FnMut(u64) -> u64, n: usize) -> Vec<Seg> {
        let mut starts: Vec<u32> = (0..rnd(40)).map(|_| rnd(n as u64) as u32).collect();
        starts.push(0);
        starts.sort_unstable();
        starts.dedup();
        starts
            .iter()
            .map(|&start| Seg {
                start,
                lod: rnd(10 * 256) as i32 - 256,
            })
            .collect()
    }

    /// `draw` a run of positions (`u`, the left half's `ul`, `v`) with levels of detail
    /// `segs` into a row of 2n + 2 pixels (the right half from n + 1, the left one
    /// ending at n); every pixel must be `at(u, v, lod)` of its position and segment,
    /// and the pixel between the halves unwritten (`what` names the case).
    fn check_run(
        (u, ul, v, segs): (&[i32], &[i32], &[i32], &[Seg]),
        draw: impl FnOnce(HalfRun<'_>, &mut [u32]),
        at: impl Fn(i32, i32, i32) -> u32,
        what: &str,
    ) {
        let n = u.len();
        let lod_at = |j: usize| {
            segs.iter()
                .rev()
                .find(|s| s.start as usize <= j)
                .unwrap()
                .lod
        };
        let mut wts = vec![0u32; n];
        let mut row = vec![0u32; 2 * n + 2];
        let r = HalfRun {
            right: n + 1,
            left_end: n,
            u,
            v,
            ul,
            segs,
            w: &mut wts,
        };
        draw(r, &mut row);
        for j in 0..n {
            let lod = lod_at(j);
            assert_eq!(
                row[n + 1 + j],
                at(u[j], v[j], lod),
                "{what} right {j} lod {lod}"
            );
            assert_eq!(
                row[n - 1 - j],
                at(ul[j], v[j], lod),
                "{what} left {j} lod {lod}"
            );
        }
        assert_eq!(row[n], 0, "the pixel between the halves is not written");
    }

    /// A trilinear run ([`tri_run`]: segments of levels of detail grouped by level, the
    /// second level blended in over part of a group) writes, pixel by pixel on both
    /// halves, `EnvMap::trilinear` at the position (u wrapped into the map) with its
    /// segment's level of detail: random runs of 1..=600 positions within two map widths
    /// of the map and v beyond the poles, 1..=40 segments of levels −1..9 (the last
    /// levels clamped), on maps with even and odd level sides.
    #[test]
    fn tri_run_is_trilinear_per_pixel() {
        let mut rnd = xorshift(0x2545_F491_4F6C_DD1D);
        for (w, h) in [(64u32, 32u32), (300, 150), (96, 40), (6, 3)] {
            let px: Vec<u32> = (0..w * h)
                .map(|i| i.wrapping_mul(2_654_435_761) & 0xFF_FFFF)
                .collect();
            let m = EnvMap::from_pixels(w, h, &px, Projection::Equirect).unwrap();
            let levels = level_texels(&m);
            let (wq, hq) = ((w as i64) << 8, (h as i64) << 8);
            for _ in 0..60 {
                let n = 1 + rnd(600) as usize;
                let mut pos = |lo: i64, hi: i64| -> Vec<i32> {
                    (0..n)
                        .map(|_| (lo + rnd((hi - lo) as u64) as i64) as i32)
                        .collect()
                };
                let (u, ul, v) = (
                    pos(256 - wq, 2 * wq - 256),
                    pos(256 - wq, 2 * wq - 256),
                    pos(-hq / 2, hq + hq / 2),
                );
                let segs = random_segs(&mut rnd, n);
                let at = |uq: i32, vq: i32, lod: i32| {
                    let uu = ((uq as i64) << 8).rem_euclid((w as i64) << 16);
                    m.trilinear(uu, (vq as i64) << 8, lod)
                };
                check_run(
                    (&u, &ul, &v, &segs),
                    |r, row| tri_run(&levels, wq as i32, 0, r, row),
                    at,
                    &format!("{w}x{h}"),
                );
            }
        }
    }

    /// The runs of bilinear with a level per region (`Renderer::set_region_lod`): whole
    /// levels (weights 0, so no level is blended in), level 0 by the bilinear row kernel
    /// and the others by the level kernel. With every kernel the CPU runs, the scalar
    /// twin included, each pixel on both halves is `EnvMap::level_bilinear` of its
    /// segment's level (clamped to the last) at its position: runs of 1..=600 positions
    /// within two map widths of the map and beyond the poles, 1..=40 segments of levels
    /// 0..12, on maps with even and odd level sides.
    #[test]
    fn whole_level_runs_agree_on_every_kernel() {
        use crate::render::kernel::Kernel;
        let mut rnd = xorshift(0x1234_5678_9ABC_DEF1);
        for (w, h) in [(64u32, 32u32), (300, 150), (96, 40), (2048, 1024)] {
            let px: Vec<u32> = (0..w * h)
                .map(|i| i.wrapping_mul(2_654_435_761) & 0xFF_FFFF)
                .collect();
            let m = EnvMap::from_pixels(w, h, &px, Projection::Equirect).unwrap();
            let levels = level_texels(&m);
            let last = levels.len() as u32 - 1;
            let (wq, hq) = ((w as i64) << 8, (h as i64) << 8);
            for _ in 0..40 {
                let n = 1 + rnd(600) as usize;
                let mut pos = |lo: i64, hi: i64| -> Vec<i32> {
                    (0..n)
                        .map(|_| (lo + rnd((hi - lo) as u64) as i64) as i32)
                        .collect()
                };
                let (u, ul, v) = (
                    pos(256 - wq, 2 * wq - 256),
                    pos(256 - wq, 2 * wq - 256),
                    pos(-hq / 2, hq + hq / 2),
                );
                let mut segs = random_segs(&mut rnd, n);
                for s in &mut segs {
                    s.lod = (rnd(13) as i32) << 8;
                }
                let at = |uq: i32, vq: i32, lod: i32| {
                    let uu = ((uq as i64) << 8).rem_euclid((w as i64) << 16);
                    let k = ((lod >> 8) as u32).min(last);
                    m.level_bilinear(k, uu, (vq as i64) << 8)
                };
                for k in Kernel::available() {
                    check_run(
                        (&u, &ul, &v, &segs),
                        |r, row| tri_run_with(k.selected(), &levels, (wq as i32, 0), r, row),
                        at,
                        &format!("{w}x{h} {k:?}"),
                    );
                }
            }
        }
    }

    /// A partial map's trilinear run ([`crop_tri_run`]: [`tri_run`]'s grouping, each
    /// level's chunks on the row kernels inside the stored texels, the background
    /// outside, per pixel over the edge) writes `EnvMap::trilinear` per pixel on both
    /// halves: runs of 1..=600 positions walking a quarter pixel or less per pixel (so
    /// whole chunks fall inside, outside and across the edges on every level) from
    /// anywhere within two widths of the panorama and beyond the poles, with 1..=40
    /// segments of levels −1..9, on crops with odd and even origins and sides, across
    /// the seam and 360° wide.
    #[test]
    fn crop_tri_run_is_trilinear_per_pixel() {
        use crate::geom::coverage::Crop;
        let mut rnd = xorshift(0x9E37_79B9_7F4A_7C15);
        for (fw, fh, left, top, cw, ch) in [
            (300u32, 150u32, 101u32, 37u32, 123u32, 77u32),
            (300, 150, 250, 0, 120, 90),
            (300, 150, 0, 40, 300, 61),
            (96, 40, 95, 3, 33, 36),
            (64, 32, 10, 10, 2, 2),
        ] {
            let crop = Crop::new(fw, fh, left, top, cw, ch).unwrap();
            let px: Vec<u32> = (0..cw * ch)
                .map(|i| i.wrapping_mul(2_654_435_761) & 0xFF_FFFF)
                .collect();
            let m = EnvMap::from_pixels(cw, ch, &px, Projection::Equirect).unwrap();
            let mut m = m.into_partial(crop).unwrap();
            m.set_background(0x12_3456);
            let levels = level_texels(&m);
            let crop_lv = crop_levels(&m, &levels);
            let (wq, hq) = ((fw as i64) << 8, (fh as i64) << 8);
            for _ in 0..60 {
                let n = 1 + rnd(600) as usize;
                let mut walk = |lo: i64, hi: i64| -> Vec<i32> {
                    let (mut p, d) = (lo + rnd((hi - lo) as u64) as i64, rnd(129) as i64 - 64);
                    (0..n)
                        .map(|_| {
                            p = (p + d + rnd(9) as i64 - 4).clamp(lo, hi - 1);
                            p as i32
                        })
                        .collect()
                };
                let (u, ul, v) = (
                    walk(256 - wq, 2 * wq - 256),
                    walk(256 - wq, 2 * wq - 256),
                    walk(-hq / 2, hq + hq / 2),
                );
                let segs = random_segs(&mut rnd, n);
                let at = |uq: i32, vq: i32, lod: i32| {
                    let uu = ((uq as i64) << 8).rem_euclid((fw as i64) << 16);
                    m.trilinear(uu, (vq as i64) << 8, lod)
                };
                let c = (fw, fh, left, top, cw, ch);
                check_run(
                    (&u, &ul, &v, &segs),
                    |r, row| crop_tri_run(&m, &crop_lv, wq as i32, r, row),
                    at,
                    &format!("{c:?}"),
                );
            }
        }
    }
}

//! The kernels' plumbing: a span's range check and wrap ([`prepare`]), batches of spans
//! ([`run_jobs`], [`run_tri_jobs`]), the dispatch to the chosen kernel, and partial maps'
//! spans ([`cropped`]). The public entries are in [`super`] and on [`Kernel`].

use super::select::{active, Selected};
use super::{scalar, SpanJob, Texels, Window, MAX_JOBS, TRILINEAR_CHUNK};
use crate::geom::fixed::{Fx, FX_BITS, FX_HALF, FX_ONE};

#[cfg(target_arch = "x86_64")]
use super::x86;

/// A span checked to lie inside its map: the start (already biased by −½ for bilinear
/// and wrapped into the map) and the step, Q.16.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Span {
    pub(super) u: Fx,
    pub(super) v: Fx,
    pub(super) du: Fx,
    pub(super) dv: Fx,
}

/// [`super::Kernel::nearest_span`] with the [`active_kernel`](super::active_kernel).
#[inline]
pub(crate) fn nearest_span(t: &Texels, out: &mut [u32], u: Fx, v: Fx, du: Fx, dv: Fx) -> bool {
    span::<false>(active(), t, out, (u, v), (du, dv))
}

/// [`super::Kernel::bilinear_span`] with the [`active_kernel`](super::active_kernel).
#[inline]
pub(crate) fn bilinear_span(t: &Texels, out: &mut [u32], u: Fx, v: Fx, du: Fx, dv: Fx) -> bool {
    span::<true>(active(), t, out, (u, v), (du, dv))
}

/// [`super::Kernel::trilinear_span`] with the [`active_kernel`](super::active_kernel).
#[cfg(test)]
#[inline]
pub(crate) fn trilinear_span(
    levels: &[Texels],
    lod: i32,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
) -> bool {
    trilinear(active(), levels, lod, out, (u, v), (du, dv))
}

/// [`super::Kernel::trilinear_spans`] with the [`active_kernel`](super::active_kernel).
#[inline]
pub(crate) fn trilinear_spans(
    levels: &[Texels],
    row: &mut [u32],
    spans: &[SpanJob],
    lods: &[i32],
) -> u64 {
    tri_jobs(active(), levels, row, spans, lods)
}

/// [`super::Kernel::cropped_span`] with the [`active_kernel`](super::active_kernel).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn cropped_span(
    bilinear: bool,
    t: &Texels,
    w: &Window,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
) -> bool {
    cropped(active(), bilinear, t, w, out, (u, v), (du, dv))
}

/// Check a span and wrap its start (see [`super::Kernel::nearest_span`]). Positions or steps
/// of 2⁴⁶ or more (no map comes near) and spans of 2¹⁶ pixels or more are refused, so
/// the arithmetic below cannot overflow.
#[inline(always)]
pub(super) fn prepare<const BILINEAR: bool>(
    t: &Texels,
    m: usize,
    uv: (Fx, Fx),
    d: (Fx, Fx),
) -> Option<Span> {
    let big = uv.0.unsigned_abs() | uv.1.unsigned_abs() | d.0.unsigned_abs() | d.1.unsigned_abs();
    if (big >> 46 | m as u64 >> 16) != 0 {
        return None;
    }
    let wfx = (t.width as i64) << FX_BITS;
    let hfx = (t.height as i64) << FX_BITS;
    // Bilinear reads the pixel centres around (u − ½, v − ½).
    let bias = if BILINEAR { FX_HALF } else { 0 };
    let mut uu = uv.0 - bias;
    if t.wraps && !(0..wfx).contains(&uu) {
        // One period off at most on the renderer's path; a division otherwise.
        uu += if uu < 0 { wfx } else { -wfx };
        if !(0..wfx).contains(&uu) {
            uu = uu.rem_euclid(wfx);
        }
    }
    let vv = uv.1 - bias;
    let n = m as i64 - 1;
    let (u_end, v_end) = (uu + d.0 * n, vv + d.1 * n);
    // Nearest may read column W and row H (padding equal to the clamped pixel);
    // bilinear needs x0, y0 ≤ W − 1, H − 1 so that x0 + 1, y0 + 1 are the padding.
    let (u_lim, v_lim) = if BILINEAR {
        (wfx, hfx)
    } else {
        (wfx + FX_ONE, hfx + FX_ONE)
    };
    // Both ends inside [0, lim): the unsigned comparison also rejects negatives.
    let inside = |a: Fx, lim: Fx| (a as u64) < lim as u64;
    (inside(uu, u_lim) && inside(u_end, u_lim) && inside(vv, v_lim) && inside(v_end, v_lim))
        .then_some(Span {
            u: uu,
            v: vv,
            du: d.0,
            dv: d.1,
        })
}

/// Runs `run` on every span of `jobs` inside the map (the slice of `row` it covers and
/// the checked span); returns a mask of the spans refused (bit i: `jobs[i]`).
///
/// # Panics
/// When a span does not fit in `row`, or there are more than [`MAX_JOBS`] spans.
#[inline(always)]
pub(super) fn run_jobs<const BILINEAR: bool>(
    t: &Texels,
    row: &mut [u32],
    jobs: &[SpanJob],
    mut run: impl FnMut(&mut [u32], Span),
) -> u64 {
    assert!(jobs.len() <= MAX_JOBS, "{} spans in one batch", jobs.len());
    let mut refused = 0u64;
    for (i, j) in jobs.iter().enumerate() {
        let out = &mut row[j.x as usize..j.x as usize + j.len as usize];
        if out.is_empty() {
            continue;
        }
        match prepare::<BILINEAR>(t, out.len(), (j.u, j.v), (j.du, j.dv)) {
            Some(s) => run(out, s),
            None => refused |= 1 << i,
        }
    }
    refused
}

/// The batch kernels with kernel `k`.
#[inline]
pub(super) fn jobs<const BILINEAR: bool>(
    k: Selected,
    t: &Texels,
    row: &mut [u32],
    jobs: &[SpanJob],
) -> u64 {
    #[cfg(target_arch = "x86_64")]
    if let Some(r) = x86::jobs::<BILINEAR>(k, t, row, jobs) {
        return r;
    }
    let _ = k;
    run_jobs::<BILINEAR>(t, row, jobs, |out, s| {
        if BILINEAR {
            scalar::bilinear(t, out, s)
        } else {
            scalar::nearest(t, out, s)
        }
    })
}

/// [`super::Kernel::nearest_spans`] with the [`active_kernel`](super::active_kernel).
#[inline]
pub(crate) fn nearest_spans(t: &Texels, row: &mut [u32], spans: &[SpanJob]) -> u64 {
    jobs::<false>(active(), t, row, spans)
}

/// [`super::Kernel::bilinear_spans`] with the [`active_kernel`](super::active_kernel).
#[inline]
pub(crate) fn bilinear_spans(t: &Texels, row: &mut [u32], spans: &[SpanJob]) -> u64 {
    jobs::<true>(active(), t, row, spans)
}

/// The job of a whole slice `out` starting at (u, v) with steps (du, dv); `None` for
/// 2¹⁶ pixels or more (which `prepare` refuses too).
#[inline(always)]
fn whole(out: &[u32], (u, v): (Fx, Fx), (du, dv): (Fx, Fx)) -> Option<SpanJob> {
    (out.len() >> 16 == 0).then_some(SpanJob {
        x: 0,
        len: out.len() as u32,
        u,
        v,
        du,
        dv,
    })
}

/// One span: a batch of one (each SIMD loop then has a single caller, the batch loop,
/// and is compiled into it).
#[inline(always)]
pub(super) fn span<const BILINEAR: bool>(
    k: Selected,
    t: &Texels,
    out: &mut [u32],
    uv: (Fx, Fx),
    d: (Fx, Fx),
) -> bool {
    whole(out, uv, d).is_some_and(|job| jobs::<BILINEAR>(k, t, out, &[job]) == 0)
}

/// One trilinear span: a batch of one.
#[inline(always)]
pub(super) fn trilinear(
    k: Selected,
    levels: &[Texels],
    lod: i32,
    out: &mut [u32],
    uv: (Fx, Fx),
    d: (Fx, Fx),
) -> bool {
    whole(out, uv, d).is_some_and(|job| tri_jobs(k, levels, out, &[job], &[lod]) == 0)
}

/// The trilinear batch kernels with kernel `k`.
#[inline]
pub(super) fn tri_jobs(
    k: Selected,
    levels: &[Texels],
    row: &mut [u32],
    jobs: &[SpanJob],
    lods: &[i32],
) -> u64 {
    #[cfg(target_arch = "x86_64")]
    if let Some(r) = x86::tri_jobs(k, levels, row, jobs, lods) {
        return r;
    }
    let _ = k;
    run_tri_jobs(
        levels,
        row,
        jobs,
        lods,
        scalar::bilinear,
        scalar::blend_bilinear,
    )
}

/// Runs the trilinear spans of `jobs` (level of detail `lods[i]`, Q.8, as
/// `lod_q8` in `map/pyramid.rs`) on `levels` with the kernels `bil` (bilinear) and `blend`
/// (bilinear blended into the output); returns the mask of spans refused.
///
/// The levels are resolved as the map's pyramid resolves them: `lod` ≤ 0 is bilinear on
/// level 0; otherwise level k = `lod >> 8` and k + 1 (each clamped to the last level)
/// blended by `lod & 0xFF`, or level k alone when the weight is 0 or both clamp to the
/// same level. Level k reads the level-0 positions and steps shifted right by k; the
/// second level restarts its position every [`TRILINEAR_CHUNK`] pixels.
///
/// # Panics
/// When a span does not fit in `row`, `lods` and `jobs` differ in length, there are more
/// than [`MAX_JOBS`] spans, or `levels` is empty.
#[inline(always)]
pub(super) fn run_tri_jobs(
    levels: &[Texels],
    row: &mut [u32],
    jobs: &[SpanJob],
    lods: &[i32],
    mut bil: impl FnMut(&Texels, &mut [u32], Span),
    mut blend: impl FnMut(&Texels, &mut [u32], Span, u32),
) -> u64 {
    assert!(jobs.len() <= MAX_JOBS, "{} spans in one batch", jobs.len());
    assert_eq!(jobs.len(), lods.len(), "one level of detail per span");
    let last = levels.len().checked_sub(1).expect("level 0 at least");
    let mut refused = 0u64;
    for (i, (j, &lod)) in jobs.iter().zip(lods).enumerate() {
        let out = &mut row[j.x as usize..j.x as usize + j.len as usize];
        if out.is_empty() {
            continue;
        }
        let (ka, kb, frac) = if lod <= 0 {
            (0, 0, 0)
        } else {
            let k = (lod >> 8) as usize;
            (k.min(last), (k + 1).min(last), (lod & 0xFF) as u32)
        };
        let shifted = |k: usize| ((j.u >> k, j.v >> k), (j.du >> k, j.dv >> k));
        let (uv, d) = shifted(ka);
        let Some(sa) = prepare::<true>(&levels[ka], out.len(), uv, d) else {
            refused |= 1 << i;
            continue;
        };
        bil(&levels[ka], out, sa);
        if frac == 0 || kb == ka {
            continue;
        }
        // The second level, its start recomputed every TRILINEAR_CHUNK pixels.
        let (mut u, mut v) = (j.u, j.v);
        for chunk in out.chunks_mut(TRILINEAR_CHUNK) {
            let uv = (u >> kb, v >> kb);
            let Some(sb) = prepare::<true>(&levels[kb], chunk.len(), uv, shifted(kb).1) else {
                refused |= 1 << i;
                break;
            };
            blend(&levels[kb], chunk, sb, frac);
            // (Wrapping: only far outside any map, where prepare() then refuses.)
            u = u.wrapping_add(j.du.wrapping_mul(chunk.len() as i64));
            v = v.wrapping_add(j.dv.wrapping_mul(chunk.len() as i64));
        }
    }
    refused
}

pub(super) fn cropped(
    k: Selected,
    bilinear: bool,
    t: &Texels,
    w: &Window,
    out: &mut [u32],
    (u, v): (Fx, Fx),
    (du, dv): (Fx, Fx),
) -> bool {
    let m = out.len();
    if m == 0 {
        return true;
    }
    let n = m as i64 - 1;
    let (Some(eu), Some(ev)) = (du.checked_mul(n), dv.checked_mul(n)) else {
        return false;
    };
    let fw = (w.full_width as i64) << FX_BITS;
    let fh = (w.full_height as i64) << FX_BITS;
    let top = (w.top as i64) << FX_BITS;
    let bottom = top + ((t.height as i64) << FX_BITS);
    let Some(v_end) = v.checked_add(ev) else {
        return false;
    };
    // Wholly above or below the stored rows (v is clamped into the panorama first, so
    // only a crop not touching the panorama's edge has background there).
    let (v_lo, v_hi) = (v.min(v_end), v.max(v_end));
    if (w.top > 0 && v_hi < top) || (bottom < fh && v_lo >= bottom) {
        out.fill(w.background);
        return true;
    }
    // The stored-pixel column of the start, on the sheet [0, W) of the panorama.
    let Some(su) = u.checked_sub((w.left as i64) << FX_BITS) else {
        return false;
    };
    let su = su.rem_euclid(fw.max(1));
    let Some(su_end) = su.checked_add(eu) else {
        return false;
    };
    let sv = v - top;
    let sv_end = v_end - top;
    let cw = (t.width as i64) << FX_BITS;
    let ch = (t.height as i64) << FX_BITS;
    let narrow = (t.width as i64) < w.full_width as i64;
    if narrow {
        let (lo, hi) = (su.min(su_end), su.max(su_end));
        // Wholly in the uncovered longitudes of this sheet.
        if lo >= cw && hi < fw {
            out.fill(w.background);
            return true;
        }
        // Covered needs su < cw (and ≥ 0, which the span kernels check with the bias).
        if hi >= cw {
            return false;
        }
    }
    // Covered rows: sv in [0, ch); the span kernels check sv (− ½ for bilinear) ≥ 0.
    if sv.max(sv_end) >= ch {
        return false;
    }
    if bilinear {
        span::<true>(k, t, out, (su, sv), (du, dv))
    } else {
        span::<false>(k, t, out, (su, sv), (du, dv))
    }
}

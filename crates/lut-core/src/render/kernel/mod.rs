//! Span kernels: the LUT renderer's inner loop. A *span* is a run of output pixels between
//! two table reads; its map positions step linearly in Q.16 fixed point, `(u + i·du,
//! v + i·dv)`, and each pixel is one sample of the map.
//!
//! # The rules a kernel keeps, and why
//! * **No per-pixel dispatch.** The sampler (nearest or bilinear), the partial-map crop
//!   test and the trilinear level are chosen once per frame (a monomorphized sink per
//!   combination in `render/sink.rs`) or once per span (the level of detail), never per
//!   pixel.
//! * **No division inside a span.** Longitude is wrapped once at the start of a span (one
//!   period off at most on the renderer's path; `rem_euclid` only for a start further
//!   off), never per pixel.
//! * **No clamps inside a span.** The whole span is checked against the map once: when its
//!   first and last positions lie inside, every position between does (the steps are
//!   linear), and the padding column and row of the map (`map/envmap.rs`) make `x + 1` and
//!   `y + 1` readable at the last column and row. A span that leaves the map falls back to
//!   the per-pixel samplers, which wrap and clamp.
//!
//! The numbers that showed it (callgrind instruction counts, `docs/ARCHITECTURE.md` "What
//! was measured and changed"): the nearest inner loop was ~10 instructions per pixel, but
//! ~25 per pixel went to span overhead (a table read, two `i64::rem_euclid` divisions and
//! the sampler's clamps every 4 pixels), and a plain gather along precomputed indices (the
//! same memory accesses) was 3–4× faster than the kernel. Removing the divisions and
//! clamps (this module) and lengthening the spans (per-region index steps) took the
//! nearest frame from 15.4 to about 12 ms at 1080p on 2 threads.
//!
//! # Layout
//! [`scalar`] holds the portable kernels: functions over the map's padded pixel slice,
//! its stride, the output slice and the span's Q.16 start and step, with every position
//! known to be inside (the checks above are done here, once per span). SIMD twins of
//! them go next to it (one file per instruction set), each with a test that it agrees
//! with the scalar kernel.

pub(crate) mod scalar;

use crate::geom::fixed::{Fx, FX_BITS, FX_HALF, FX_ONE};
use crate::map::envmap::EnvMap;
use crate::map::sample::lerp_px;

/// Sample a run of positions stepping linearly: `out[i]` = the `BILINEAR` (else nearest)
/// sample of `map` at (u + i·du, v + i·dv). Identical to calling [`EnvMap::bilinear`] /
/// [`EnvMap::nearest`] per pixel with u wrapped into [0, W) for 360° maps.
///
/// When the whole run stays inside the map (after one wrap of its start), the scalar
/// kernel runs with no clamps and no wrap tests. Otherwise the run falls back to the
/// per-pixel functions.
#[inline]
pub(crate) fn sample_span<const BILINEAR: bool>(
    map: &EnvMap,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
) {
    let m = out.len() as i64;
    if m == 0 {
        return;
    }
    if map.projection.scaled_rows() {
        // Rows wrap within their own length (`EnvMap::bilinear`): per pixel.
        return sample_span_slow::<BILINEAR>(map, out, u, v, du, dv);
    }
    let wfx = (map.width as i64) << FX_BITS;
    let hfx = (map.height as i64) << FX_BITS;
    // Bilinear reads the pixel centres around (u − ½, v − ½).
    let bias = if BILINEAR { FX_HALF } else { 0 };
    let wraps = map.projection.wraps();
    let mut uu = u - bias;
    if wraps && !(0..wfx).contains(&uu) {
        // One period off at most on the renderer's path; a division otherwise.
        uu += if uu < 0 { wfx } else { -wfx };
        if !(0..wfx).contains(&uu) {
            uu = uu.rem_euclid(wfx);
        }
    }
    let vv = v - bias;
    let (u_end, v_end) = (uu + du * (m - 1), vv + dv * (m - 1));
    // Nearest may read column W and row H (padding equal to the clamped pixel);
    // bilinear needs x0, y0 ≤ W − 1, H − 1 so that x0 + 1, y0 + 1 are the padding.
    let (u_lim, v_lim) = if BILINEAR {
        (wfx, hfx)
    } else {
        (wfx + FX_ONE, hfx + FX_ONE)
    };
    let inside = |a: Fx, lim: Fx| a >= 0 && a < lim;
    if !(inside(uu, u_lim) && inside(u_end, u_lim) && inside(vv, v_lim) && inside(v_end, v_lim)) {
        sample_span_slow::<BILINEAR>(map, out, u, v, du, dv);
        return;
    }
    let (data, stride) = map.padded();
    if BILINEAR {
        scalar::bilinear_span(data, stride, out, uu, vv, du, dv);
    } else {
        scalar::nearest_span(data, stride, out, uu, vv, du, dv);
    }
}

/// [`sample_span`] for a run that leaves the map: per pixel, wrapping and clamping.
#[inline(never)]
fn sample_span_slow<const BILINEAR: bool>(
    map: &EnvMap,
    out: &mut [u32],
    mut u: Fx,
    mut v: Fx,
    du: Fx,
    dv: Fx,
) {
    let wfx = (map.width as i64) << FX_BITS;
    let wraps = map.projection.wraps();
    for o in out.iter_mut() {
        let uu = if wraps { u.rem_euclid(wfx) } else { u };
        *o = if BILINEAR {
            map.bilinear(uu, v)
        } else {
            map.nearest(uu, v)
        };
        u += du;
        v += dv;
    }
}

/// [`EnvMap::trilinear`] over a run of positions stepping linearly (see [`sample_span`]),
/// one level of detail for the run: bilinear spans on the two pyramid levels around
/// `lod`, blended in chunks of 64 pixels.
pub(crate) fn trilinear_span(
    map: &EnvMap,
    out: &mut [u32],
    u: Fx,
    v: Fx,
    du: Fx,
    dv: Fx,
    lod: i32,
) {
    if lod <= 0 || map.crop.is_some() {
        return sample_span::<true>(map, out, u, v, du, dv);
    }
    let k = (lod >> 8) as usize;
    let frac = (lod & 0xFF) as u32;
    let (a_map, ka) = map.level(k);
    let (b_map, kb) = map.level(k + 1);
    sample_span::<true>(a_map, out, u >> ka, v >> ka, du >> ka, dv >> ka);
    if frac == 0 || kb == ka {
        return;
    }
    let mut scratch = [0u32; 64];
    let (mut u, mut v) = (u, v);
    for chunk in out.chunks_mut(scratch.len()) {
        let s = &mut scratch[..chunk.len()];
        sample_span::<true>(b_map, s, u >> kb, v >> kb, du >> kb, dv >> kb);
        for (o, b) in chunk.iter_mut().zip(s.iter()) {
            *o = lerp_px(*o, *b, frac);
        }
        u += du * chunk.len() as i64;
        v += dv * chunk.len() as i64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::fixed::to_fx;
    use crate::geom::projection::Projection;
    use crate::map::synth::grid_map;

    /// The span kernels against the per-pixel samplers, inside the map, across the seam
    /// and off its edges (the slow path), for a wrapping and a clamping projection.
    #[test]
    fn spans_equal_per_pixel_samples() {
        for proj in [Projection::Equirect, Projection::Elliptical] {
            let m = grid_map(64, 32, proj).unwrap();
            let wfx = 64i64 << FX_BITS;
            for &(u, v, du, dv) in &[
                (3.3, 4.2, 0.7, 0.1),
                (60.0, 10.0, 0.5, 0.0),
                (-2.0, 31.5, 0.25, 0.02),
                (10.0, 0.1, -0.3, -0.01),
                (0.2, 16.0, 1.9, 0.4),
            ] {
                let (u, v, du, dv) = (to_fx(u), to_fx(v), to_fx(du), to_fx(dv));
                let mut nb = vec![0u32; 40];
                let mut nn = vec![0u32; 40];
                sample_span::<true>(&m, &mut nb, u, v, du, dv);
                sample_span::<false>(&m, &mut nn, u, v, du, dv);
                for i in 0..40 {
                    let uu = u + du * i as i64;
                    let uu = if proj.wraps() { uu.rem_euclid(wfx) } else { uu };
                    let vv = v + dv * i as i64;
                    assert_eq!(nb[i], m.bilinear(uu, vv), "{proj} bilinear pixel {i}");
                    assert_eq!(nn[i], m.nearest(uu, vv), "{proj} nearest pixel {i}");
                }
            }
        }
    }

    #[test]
    fn span_equals_per_pixel() {
        let m = crate::map::synth::grid_map(256, 128, Projection::Equirect).unwrap();
        for lod in [0, 100, 256, 300, 700, 5000] {
            let (u, v, du, dv) = (to_fx(250.3), to_fx(40.2), to_fx(1.7), to_fx(-0.4));
            let mut out = vec![0u32; 100];
            trilinear_span(&m, &mut out, u, v, du, dv, lod);
            for (i, o) in out.iter().enumerate() {
                let uu = (u + du * i as i64).rem_euclid(256 << FX_BITS);
                let vv = v + dv * i as i64;
                // The span steps each level by du >> k (truncated): up to i/65536 px
                // off after i pixels, which can move an 8-bit weight by one step.
                let want = m.trilinear(uu, vv, lod);
                for s in [0, 8, 16] {
                    let (a, b) = ((o >> s) & 0xFF, (want >> s) & 0xFF);
                    assert!(
                        a.abs_diff(b) <= 2,
                        "lod {lod} pixel {i}: {o:06x} vs {want:06x}"
                    );
                }
            }
        }
    }
}

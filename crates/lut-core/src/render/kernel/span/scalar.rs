//! The portable span kernels, one pixel at a time: what every machine runs without
//! SIMD, and the reference the SIMD kernels must equal byte for byte. Every position of
//! a span is inside the map (checked once by `prepare`), so the loops neither
//! clamp nor wrap nor divide. For bilinear the position is already biased by −½ (the
//! top-left of the four pixel centres around it).

use super::Span;
use crate::geom::fixed::FX_BITS;
use crate::map::sample::lerp_px;
use crate::render::kernel::Texels;

/// `out[i]` = the pixel containing (u + i·du, v + i·dv) of a span checked inside.
#[inline(always)]
pub(super) fn nearest(t: &Texels, out: &mut [u32], s: Span) {
    let stride = t.stride();
    let (mut u, mut v) = (s.u, s.v);
    for o in out.iter_mut() {
        *o = t.px[(v >> FX_BITS) as usize * stride + (u >> FX_BITS) as usize];
        u += s.du;
        v += s.dv;
    }
}

/// The bilinear sample of a span checked inside (start already biased by −½): the 2×2
/// block whose top-left pixel contains the position, weighted by its 8-bit fractions.
#[inline(always)]
fn bilinear_at(px: &[u32], stride: usize, u: i64, v: i64) -> u32 {
    let x0 = (u >> FX_BITS) as usize;
    let y0 = (v >> FX_BITS) as usize;
    let fx = ((u >> (FX_BITS - 8)) & 0xFF) as u32;
    let fy = ((v >> (FX_BITS - 8)) & 0xFF) as u32;
    let i = y0 * stride + x0;
    // One bounds check for the 2×2 block.
    let q = &px[i..i + stride + 2];
    lerp_px(
        lerp_px(q[0], q[1], fx),
        lerp_px(q[stride], q[stride + 1], fx),
        fy,
    )
}

/// Bilinear samples along a span checked inside.
#[inline(always)]
pub(super) fn bilinear(t: &Texels, out: &mut [u32], s: Span) {
    let stride = t.stride();
    let (mut u, mut v) = (s.u, s.v);
    for o in out.iter_mut() {
        *o = bilinear_at(t.px, stride, u, v);
        u += s.du;
        v += s.dv;
    }
}

/// `out[i]` = lerp(out[i], bilinear sample i, frac): the second level of a trilinear span.
pub(super) fn blend_bilinear(t: &Texels, out: &mut [u32], s: Span, frac: u32) {
    let stride = t.stride();
    let (mut u, mut v) = (s.u, s.v);
    for o in out.iter_mut() {
        *o = lerp_px(*o, bilinear_at(t.px, stride, u, v), frac);
        u += s.du;
        v += s.dv;
    }
}

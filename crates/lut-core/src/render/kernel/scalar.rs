//! The portable span kernels (see the [module rules](super)): every position of the span
//! is inside the map, so the loops neither clamp nor wrap nor divide.
//!
//! Arguments, shared by every twin of these kernels: `data` is the map's padded pixel
//! buffer (`map/envmap.rs`), `stride` its row length (stored width + 1), `out` the span's
//! output pixels, `(u, v)` the first position and `(du, dv)` the step per pixel, Q.16 map
//! pixels. For bilinear the position is already biased by −½ (the top-left of the four
//! pixel centres around it).

use crate::geom::fixed::{Fx, FX_BITS};
use crate::map::sample::lerp_px;

/// Bilinear span: `out[i]` blends the 2×2 block at (u + i·du, v + i·dv) (biased by −½)
/// with 8-bit weights. Every position must satisfy `0 ≤ u < W`, `0 ≤ v < H` (Q.16).
#[inline(always)]
pub(crate) fn bilinear_span(
    data: &[u32],
    stride: usize,
    out: &mut [u32],
    mut u: Fx,
    mut v: Fx,
    du: Fx,
    dv: Fx,
) {
    for o in out.iter_mut() {
        let x0 = (u >> FX_BITS) as usize;
        let y0 = (v >> FX_BITS) as usize;
        let fx = ((u >> (FX_BITS - 8)) & 0xFF) as u32;
        let fy = ((v >> (FX_BITS - 8)) & 0xFF) as u32;
        let i = y0 * stride + x0;
        // One bounds check for the 2×2 block.
        let q = &data[i..i + stride + 2];
        *o = lerp_px(
            lerp_px(q[0], q[1], fx),
            lerp_px(q[stride], q[stride + 1], fx),
            fy,
        );
        u += du;
        v += dv;
    }
}

/// Nearest span: `out[i]` is the pixel containing (u + i·du, v + i·dv). Every position
/// must satisfy `0 ≤ u < W + 1`, `0 ≤ v < H + 1` (Q.16; column W and row H are padding).
#[inline(always)]
pub(crate) fn nearest_span(
    data: &[u32],
    stride: usize,
    out: &mut [u32],
    mut u: Fx,
    mut v: Fx,
    du: Fx,
    dv: Fx,
) {
    for o in out.iter_mut() {
        *o = data[(v >> FX_BITS) as usize * stride + (u >> FX_BITS) as usize];
        u += du;
        v += dv;
    }
}

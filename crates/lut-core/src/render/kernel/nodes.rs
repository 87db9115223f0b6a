//! The row blend of a scanline's table nodes (see `lut::Band::blend_nodes`, the scalar
//! twin): each of the band's two table rows' values, `top + ((bot − top)·wa >> 16)` in
//! 64-bit arithmetic, for a run of nodes at once, so the scanline walk reads one blended
//! node per column instead of blending two rows at every read.
//!
//! Why a kernel: blending once pays when it costs less than the per-read blends it saves
//! (`render::scanline::blend_pays`). In scalar code a node costs about 20 instructions
//! against 27 saved per read, so it pays only up to about 1.3 nodes per read, and the
//! 8k frame at hfov 90 reads about 2 nodes apart; the AVX2 kernel blends 2 nodes in about
//! 10 instructions, so it pays up to about 5 nodes per read.

use super::select::{active, Kernel, Selected};
use crate::lut::Band;

/// Blend the band's nodes `k0..k0 + out.len()` into `out` with the active kernel: what
/// `Band::blend_nodes` writes, bit for bit.
#[inline]
pub(crate) fn blend_nodes(band: &Band, k0: usize, out: &mut [[i32; 2]]) {
    blend_nodes_with(active(), band, k0, out);
}

/// [`blend_nodes`] with kernel `k`.
#[inline]
pub(super) fn blend_nodes_with(k: Selected, band: &Band, k0: usize, out: &mut [[i32; 2]]) {
    #[cfg(target_arch = "x86_64")]
    {
        let (top, bot, wa) = band.rows(k0, out.len());
        if super::x86::nodes::blend(k, (top, bot, wa), out) {
            return;
        }
    }
    let _ = k;
    band.blend_nodes(k0, out);
}

/// Whether the active kernel blends nodes in SIMD lanes (the walk's cost model,
/// `blend_pays`, counts about 4 instructions a node then instead of 20).
#[inline]
pub(crate) fn simd_blend() -> bool {
    matches!(active().0, Kernel::Avx2 | Kernel::Avx512)
}

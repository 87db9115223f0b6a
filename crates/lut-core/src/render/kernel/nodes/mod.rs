//! The row blend of a scanline's table nodes (see `lut::Band::blend_nodes`, the scalar
//! twin, so this operation has no `scalar.rs`): each of the band's two table rows'
//! values, `top + ((bot − top)·wa >> 16)` in 64-bit arithmetic, for a run of nodes at
//! once, so the scanline walk reads one blended node per column instead of blending two
//! rows at every read.
//!
//! Why a kernel: blending once pays when it costs less than the per-read blends it saves
//! (`render::scanline::blend_pays`). In scalar code a node costs about 20 instructions
//! against 27 saved per read, so it pays only up to about 1.3 nodes per read, and the
//! 8k frame at hfov 90 reads about 2 nodes apart; the AVX2 kernel blends 2 nodes in about
//! 10 instructions, so it pays up to about 5 nodes per read.

use super::select::{Kernel, SelectedKernel};
use crate::lut::Band;

#[cfg(target_arch = "x86_64")]
mod x86;

/// The band's two table rows over a run of nodes, and the blend weight of the lower one
/// (`wa`, Q.16, 0..=2^16), as `Band::rows` gives them.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy)]
struct NodeRows<'a> {
    top: &'a [[i32; 2]],
    bot: &'a [[i32; 2]],
    wa: i64,
}

impl SelectedKernel {
    /// Blend the band's nodes `k0..k0 + out.len()` into `out`: what `Band::blend_nodes`
    /// (the scalar twin) writes, bit for bit.
    #[inline]
    pub(crate) fn blend_nodes(self, band: &Band, k0: usize, out: &mut [[i32; 2]]) {
        #[cfg(target_arch = "x86_64")]
        {
            let (top, bot, wa) = band.rows(k0, out.len());
            if x86::blend(self, NodeRows { top, bot, wa }, out) {
                return;
            }
        }
        band.blend_nodes(k0, out);
    }

    /// Whether this kernel blends nodes in SIMD lanes (the walk's cost model,
    /// `blend_pays`, counts about 4 instructions a node then instead of 20).
    #[inline]
    pub(crate) fn simd_blend(self) -> bool {
        matches!(self.0, Kernel::Avx2 | Kernel::Avx512)
    }
}

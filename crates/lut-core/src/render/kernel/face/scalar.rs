//! The cube-face positions' portable twin: one pixel at a time, the reference the SIMD
//! forms (`x86.rs`) equal (`face/mod.rs`'s tests).

use super::FaceRun;
use crate::geom::fixed::{FX_BITS, FX_ONE};

/// A position on a cube face, in face texels from its top-left corner (unbordered; the
/// arithmetic of `face_uv`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct FacePos {
    /// Texels right of the face's left edge.
    pub(super) u: f64,
    /// Texels down from the face's top edge.
    pub(super) v: f64,
}

/// The exact face position of pixel `i` of the run (the arithmetic of `face_uv`).
#[inline(always)]
pub(super) fn exact(r: &FaceRun, i: usize) -> FacePos {
    // (Runs are shorter than 2³² pixels: u32 converts to f64 in one instruction.)
    let dx = r.dx + f64::from(i as u32);
    let a = r.p[0] + dx * r.d[0];
    let b = r.p[1] + dx * r.d[1];
    let m = r.p[2] + dx * r.d[2];
    let q = r.half / m;
    FacePos {
        u: r.half + a * q,
        v: r.half - b * q,
    }
}

/// The bordered Q.8 positions of the run's pixels 0..m, exact (see the module docs), one
/// pixel at a time: the SIMD kernels' scalar twin. Returns the largest `v` (`i32::MIN`
/// for no pixel).
pub(super) fn positions<const BILINEAR: bool>(
    n: usize,
    r: &FaceRun,
    u: &mut [i32],
    v: &mut [i32],
    m: usize,
) -> i32 {
    let (nf, topf, one) = (n as f64, ((n as i64) << FX_BITS) as f64, FX_ONE as f64);
    let q8 = |x: f64| {
        if BILINEAR {
            // `CubeMap::bilinear`'s Q.16 (rounded half up, clamped into the face; NaN → 0:
            // the float clamped first gives the same integer), + 1 texel (the border).
            ((((x * one + 0.5).max(0.0).min(topf) as i64) + FX_ONE) >> 8) as i32
        } else {
            // `CubeMap::nearest`'s texel (NaN → 0), + 1 (the border), in Q.8.
            (((x.max(0.0).min(nf) as i32).min(n as i32 - 1)) + 1) << 8
        }
    };
    let mut top = i32::MIN;
    for (i, (pu, pv)) in u[..m].iter_mut().zip(&mut v[..m]).enumerate() {
        let at = exact(r, i);
        *pu = q8(at.u);
        *pv = q8(at.v);
        top = top.max(*pv);
    }
    top
}

//! Row kernels: a run of a scanline's positions expanded from its spans, and the gather
//! (nearest) or gather-and-blend (bilinear) pass over them, for full 360° maps (the LUT
//! renderer's rows, `render/rowpass.rs`).
//!
//! The positions are `i32` Q.8 map coordinates (the 8 fraction bits are all the bilinear
//! weights use), one per pixel, in the order of the right half of the scanline; the left
//! half's (its mirror image: Λ negated) are kept in the same order and written to the
//! row reversed. Per pixel the kernel wraps x by up to two map widths either way in lanes,
//! clamps y at the poles (dropping the weight there as the per-pixel sampler does), and
//! gathers: no span checks, no refusals, no per-span setup.
//!
//! [`sample_q8_scalar`] and [`expand_scalar`] are the reference: every SIMD kernel
//! (`x86/row.rs`) writes the same pixels and positions (`tests.rs`), and the pixels equal
//! the per-pixel samplers' (`EnvMap::nearest` / `EnvMap::bilinear` at the wrapped
//! position u/256, v/256).

use super::select::{active, Selected};
use super::Texels;
use crate::map::sample::lerp_px;

#[cfg(target_arch = "x86_64")]
use super::x86;

/// The sample of `t` at the Q.8 position (u, v): x wrapped into the map (u within two map
/// widths of it: −2W ≤ x < 3W), y clamped; bilinear reads the 2×2 block around
/// (u − ½, v − ½).
#[inline(always)]
pub(super) fn sample_at<const BILINEAR: bool>(t: &Texels, u: i32, v: i32) -> u32 {
    let (w, h1, stride) = (t.width as i32, t.height as i32 - 1, t.stride());
    let (u, v) = if BILINEAR { (u - 128, v - 128) } else { (u, v) };
    let mut x = u >> 8;
    // One test for the common case (inside the map).
    if x as u32 >= w as u32 {
        x = wrap_x(x, w);
    }
    let x = x as usize;
    let y = v >> 8;
    if BILINEAR {
        let fx = (u & 0xFF) as u32;
        let (y, fy) = if (y as u32) < h1 as u32 {
            (y, (v & 0xFF) as u32)
        } else if y < 0 {
            (0, 0)
        } else {
            (h1, 0)
        };
        let i = y as usize * stride + x;
        let q = &t.px[i..i + stride + 2];
        lerp_px(
            lerp_px(q[0], q[1], fx),
            lerp_px(q[stride], q[stride + 1], fx),
            fy,
        )
    } else {
        let y = if (y as u32) <= h1 as u32 {
            y
        } else {
            y.clamp(0, h1)
        };
        t.px[y as usize * stride + x]
    }
}

/// x (outside `0..w`) wrapped by up to two map widths either way, then clamped.
#[inline(always)]
fn wrap_x(mut x: i32, w: i32) -> i32 {
    if x < 0 {
        x += w;
    }
    if x < 0 {
        x += w;
    }
    if x >= w {
        x -= w;
    }
    if x >= w {
        x -= w;
    }
    x.clamp(0, w - 1)
}

/// The scalar kernel: `out[j]` = the sample at (`u[j]`, `v[j]`), or with `MIRROR` (the
/// left half) `out[n − 1 − j]` (n = `out.len()` ≤ the positions).
#[inline(always)]
pub(super) fn sample_q8_scalar<const BILINEAR: bool, const MIRROR: bool>(
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
) {
    let n = out.len();
    for (j, (&uu, &vv)) in u[..n].iter().zip(&v[..n]).enumerate() {
        let at = if MIRROR { n - 1 - j } else { j };
        out[at] = sample_at::<BILINEAR>(t, uu, vv);
    }
}

/// [`sample_q8_scalar`] with kernel `k`.
#[inline]
pub(super) fn sample_q8_with<const BILINEAR: bool, const MIRROR: bool>(
    k: Selected,
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
) {
    assert!(
        u.len() >= out.len() && v.len() >= out.len(),
        "a position per pixel"
    );
    #[cfg(target_arch = "x86_64")]
    if x86::row::sample_q8::<BILINEAR, MIRROR>(k, t, u, v, out) {
        return;
    }
    let _ = k;
    sample_q8_scalar::<BILINEAR, MIRROR>(t, u, v, out);
}

/// [`sample_q8_scalar`] with the [`active_kernel`](super::active_kernel): the row pass's
/// pixels. Positions u must lie within two map widths of the map, as the row pass's do
/// (a span starts in the map and travels less than a width); outside, x is clamped
/// (never a read outside the map). y is clamped.
///
/// # Panics
/// When there are fewer positions than pixels.
#[inline]
pub(crate) fn sample_q8<const BILINEAR: bool, const MIRROR: bool>(
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
) {
    sample_q8_with::<BILINEAR, MIRROR>(active(), t, u, v, out);
}

/// A span of a row's positions (see [`expand`]): pixel `k + j` (j < m) of the buffers
/// gets `hu + ((lu + j·du) >> 8)`, `hv + ((lv + j·dv) >> 8)` and, for the mirror image
/// in the left half, `hl + ((ll − j·du) >> 8)`: the Q.8 (floored) positions of Q.16
/// starts `256·h + l` (0 ≤ l < 256) and steps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct SpanQ8 {
    pub(crate) k: u32,
    pub(crate) m: u32,
    pub(crate) hu: i32,
    pub(crate) lu: i32,
    pub(crate) du: i32,
    pub(crate) hv: i32,
    pub(crate) lv: i32,
    pub(crate) dv: i32,
    pub(crate) hl: i32,
    pub(crate) ll: i32,
}

/// The position buffers of a run: u and v of the right half, u of the left half (its v
/// is the right half's), indexed alike.
pub(crate) struct Positions<'a> {
    pub(crate) u: &'a mut [i32],
    pub(crate) v: &'a mut [i32],
    pub(crate) ul: &'a mut [i32],
}

/// The scalar kernel of [`expand`]: exactly pixels `k..k + m` of each span.
#[inline(always)]
pub(super) fn expand_scalar(spans: &[SpanQ8], p: Positions<'_>) {
    for s in spans {
        let r = s.k as usize..(s.k + s.m) as usize;
        let (mut lu, mut lv, mut ll) = (s.lu, s.lv, s.ll);
        let out = p.u[r.clone()].iter_mut().zip(&mut p.v[r.clone()]);
        for ((a, b), c) in out.zip(&mut p.ul[r]) {
            *a = s.hu.wrapping_add(lu >> 8);
            *b = s.hv.wrapping_add(lv >> 8);
            *c = s.hl.wrapping_add(ll >> 8);
            lu = lu.wrapping_add(s.du);
            lv = lv.wrapping_add(s.dv);
            ll = ll.wrapping_sub(s.du);
        }
    }
}

/// Expand `spans` (in order of `k`, each starting where the one before ended) into the
/// position buffers, which hold at least 8 entries past the last span (the SIMD kernels
/// write whole vectors; the next span overwrites what lies past a span). The row pass's
/// per-pixel positions, one kernel call per run.
///
/// # Panics
/// When a span (rounded up to 8 pixels) does not fit in the buffers.
#[inline]
pub(crate) fn expand(spans: &[SpanQ8], p: Positions<'_>) {
    expand_with(active(), spans, p);
}

/// [`expand`] with kernel `k`.
#[inline]
pub(super) fn expand_with(k: Selected, spans: &[SpanQ8], p: Positions<'_>) {
    #[cfg(target_arch = "x86_64")]
    let p = match x86::row::expand(k, spans, p) {
        None => return,
        Some(p) => p,
    };
    let _ = k;
    expand_scalar(spans, p);
}

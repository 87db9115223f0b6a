//! The row kernels' portable twins: one position at a time, the reference the SIMD
//! forms (`x86.rs`) equal (`kernel/tests/row_pass.rs`).

use super::{wrap_q8, Level, Positions, SpanQ8};
use crate::map::sample::lerp_px;
use crate::render::kernel::Texels;

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

/// The scalar kernel of `SelectedKernel::sample_lv`: `out[j]` = the sample at (`u[j]`, `v[j]`), or with `MIRROR` (the
/// left half) `out[n − 1 − j]` (n = `out.len()` ≤ the positions); on a pyramid level
/// with `LEVEL` (u wrapped into the level-0 map, then u and v shifted right by `lv.k`)
/// and blended into `out` by the weights `lv.w` with `BLEND` (`lerp_px(out, sample,
/// w[j])`).
#[inline(always)]
pub(super) fn sample_lv<
    const BILINEAR: bool,
    const MIRROR: bool,
    const LEVEL: bool,
    const BLEND: bool,
>(
    t: &Texels,
    u: &[i32],
    v: &[i32],
    out: &mut [u32],
    lv: &Level,
) {
    let n = out.len();
    for (j, (&uu, &vv)) in u[..n].iter().zip(&v[..n]).enumerate() {
        let at = if MIRROR { n - 1 - j } else { j };
        let (uu, vv) = if LEVEL {
            (wrap_q8(uu, lv.wq) >> lv.k, vv >> lv.k)
        } else {
            (uu, vv)
        };
        let s = sample_at::<BILINEAR>(t, uu, vv);
        out[at] = if BLEND {
            lerp_px(out[at], s, lv.w[j])
        } else {
            s
        };
    }
}

/// The scalar kernel of `SelectedKernel::expand`: exactly pixels `k..k + m` of each span.
#[inline(always)]
pub(super) fn expand<const MIRROR: bool>(spans: &[SpanQ8], p: Positions<'_>) {
    for s in spans {
        let r = s.k as usize..(s.k + s.m) as usize;
        let (mut lu, mut lv) = (s.lu, s.lv);
        for (a, b) in p.u[r.clone()].iter_mut().zip(&mut p.v[r.clone()]) {
            *a = s.hu.wrapping_add(lu >> 8);
            *b = s.hv.wrapping_add(lv >> 8);
            lu = lu.wrapping_add(s.du);
            lv = lv.wrapping_add(s.dv);
        }
        if MIRROR {
            let mut ll = s.ll;
            for c in &mut p.ul[r] {
                *c = s.hl.wrapping_add(ll >> 8);
                ll = ll.wrapping_sub(s.du);
            }
        }
    }
}

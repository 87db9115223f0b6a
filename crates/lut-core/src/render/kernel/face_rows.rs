//! Cube-face bilinear runs on the row kernels: the face's projective line evaluated
//! exactly at every pixel in a positions pass (`f64` SIMD lanes, [`positions_scalar`] the
//! twin), then the row kernels' gather and blend over the positions (`kernel/row.rs`,
//! AVX-512 / AVX2 / SSE4.1 / the scalar twin), as the LUT's rows are drawn. The cube
//! scanline renderer's bilinear runs (`render/cube.rs`); its nearest and trilinear runs
//! use the fused exact kernel (`face.rs`).
//!
//! # Why a separate positions pass
//! The fused kernel (`face.rs`: position, gather and blend per vector) is the slowest way
//! to draw a bilinear run here: its division sits between the position and the gather
//! in every iteration (1080p bilinear cube frame from the 8k map, one thread, 9.5 ms).
//! Stepping the line linearly between exact points every ~9 pixels (this module until
//! 2026-12-02) took 5.8 ms but ~21 instructions per pixel of planning and expanding, and
//! moved positions by up to 0.02 texels. A pass of positions alone is a stream of
//! independent divisions (8 `f64` lanes per AVX-512 division, ~0.14 ns a lane on this
//! machine), then the row kernels read the positions as they read the LUT's: 4.6 ms,
//! and every position exact.
//!
//! # Positions
//! On a run ([`FaceRun`]) the face coordinates are `u = h + h·a/m`, `v = h − h·b/m` with
//! `a`, `b`, `m` linear in the pixel. Pixel `i`'s are computed with the operations of
//! [`crate::cube::face_uv`] in their order (IEEE `f64` is deterministic: the SIMD lanes
//! equal the scalar twin), rounded to Q.16 and clamped to the face as
//! `CubeMap::bilinear` does, moved into the bordered face (+1 texel) and floored to
//! Q.8, the row kernels' positions. The row kernels' bilinear then reads exactly the
//! texels and 8-bit weights `CubeMap::bilinear` reads: the scanline renderer's bilinear
//! images are byte-identical to the per-pixel renderer's.
//!
//! # Texels
//! The positions are bordered-face coordinates (the face's `(n + 2)²` texels as a
//! [`Texels`] of side `n + 1`: face texel `j` is column `j + 1`), so the row kernels read
//! the border (the neighbouring faces) at the face's edges as `CubeMap::bilinear` does.
//! One difference remains: the row kernels clamp a bilinear read at the last row
//! (`row::sample_at`, the map's pole), which is the face's last texel row, not the
//! border below it; runs reaching the lower half of that row (the positions pass
//! returns the largest `v`) are redrawn there by [`bottom`] (reading the border row).

use super::face::{face_side, FaceRun};
use super::row::sample_q8_with;
#[cfg(test)]
use super::select::Kernel;
use super::select::{active, Selected};
use super::Texels;
use crate::geom::fixed::{FX_BITS, FX_ONE};
use crate::map::sample::lerp_px;

/// Room past a run the kernels may write in the position buffers (whole vectors).
const SLACK: usize = 16;

/// A band's scratch for face runs: the position buffers.
#[derive(Debug, Default)]
pub(crate) struct FaceBuf {
    u: Vec<i32>,
    v: Vec<i32>,
}

/// The exact face position of pixel `i` of the run (the arithmetic of `face_uv`) and its
/// `m`.
#[inline(always)]
fn exact(r: &FaceRun, i: usize) -> (f64, f64, f64) {
    // (Runs are shorter than 2³² pixels: u32 converts to f64 in one instruction.)
    let dx = r.dx + f64::from(i as u32);
    let a = r.p[0] + dx * r.d[0];
    let b = r.p[1] + dx * r.d[1];
    let m = r.p[2] + dx * r.d[2];
    let q = r.half / m;
    (r.half + a * q, r.half - b * q, m)
}

/// The bordered Q.8 positions of the run's pixels 0..m, exact (see the module docs), one
/// pixel at a time: the SIMD kernels' scalar twin. Returns the largest `v` (`i32::MIN`
/// for no pixel).
fn positions_scalar(n: usize, r: &FaceRun, u: &mut [i32], v: &mut [i32], m: usize) -> i32 {
    let (topf, one) = (((n as i64) << FX_BITS) as f64, FX_ONE as f64);
    // `CubeMap::bilinear`'s Q.16 (rounded half up, clamped into the face; NaN → 0: the
    // float clamped first gives the same integer), then + 1 texel (the border).
    let q16 = |x: f64| ((x * one + 0.5).max(0.0).min(topf) as i64) + FX_ONE;
    let mut top = i32::MIN;
    for (i, (pu, pv)) in u[..m].iter_mut().zip(&mut v[..m]).enumerate() {
        let (x, y, _) = exact(r, i);
        *pu = (q16(x) >> 8) as i32;
        *pv = (q16(y) >> 8) as i32;
        top = top.max(*pv);
    }
    top
}

/// [`positions_scalar`] with kernel `k` (the buffers hold `m` rounded up to 16).
#[inline]
fn positions_with(
    k: Selected,
    n: usize,
    r: &FaceRun,
    u: &mut [i32],
    v: &mut [i32],
    m: usize,
) -> i32 {
    #[cfg(target_arch = "x86_64")]
    if let Some(top) = super::x86::face::positions(k, n, r, u, v, m) {
        return top;
    }
    let _ = k;
    positions_scalar(n, r, u, v, m)
}

/// The bilinear sample at bordered Q.8 position (`u`, `v`) reading the rows `y` and
/// `y + 1` for any `y` ≤ n (the row kernels stop at row n − 1: see the module docs).
#[inline]
fn bottom(t: &Texels, u: i32, v: i32) -> u32 {
    let n = face_side(t) as i32;
    let (u, v) = (u - 128, v - 128);
    let (x, y) = ((u >> 8).clamp(0, n) as usize, (v >> 8).clamp(0, n) as usize);
    let (fx, fy) = ((u & 0xFF) as u32, (v & 0xFF) as u32);
    let stride = t.stride();
    let i = y * stride + x;
    let q = &t.px[i..i + stride + 2];
    lerp_px(
        lerp_px(q[0], q[1], fx),
        lerp_px(q[stride], q[stride + 1], fx),
        fy,
    )
}

/// A face run with kernel `k`.
#[inline]
fn run(k: Selected, t: &Texels, r: &FaceRun, out: &mut [u32], buf: &mut FaceBuf) {
    debug_assert!(t.width == t.height && t.width >= 2, "bordered face texels");
    let len = out.len();
    let n = face_side(t);
    for b in [&mut buf.u, &mut buf.v] {
        if b.len() < len + SLACK {
            b.resize(len + SLACK, 0);
        }
    }
    let top = positions_with(k, n, r, &mut buf.u, &mut buf.v, len);
    let (u, v) = (&buf.u[..len], &buf.v[..len]);
    sample_q8_with::<true, false>(k, t, u, v, out);
    if len > 0 && (top - 128) >> 8 >= n as i32 {
        let last = n as i32;
        for ((o, &u), &v) in out.iter_mut().zip(u).zip(v) {
            if (v - 128) >> 8 >= last {
                *o = bottom(t, u, v);
            }
        }
    }
}

/// Bilinear samples of one cube face along a run (see the module docs), with the
/// [`active_kernel`](super::active_kernel). `t` is the face's bordered texels. Every pixel
/// of `out` is written; positions are clamped into the face, so any run is safe.
#[inline]
pub(crate) fn face_rows(t: &Texels, r: &FaceRun, out: &mut [u32], buf: &mut FaceBuf) {
    run(active(), t, r, out, buf)
}

#[cfg(test)]
impl Kernel {
    /// [`face_rows`] with this kernel.
    ///
    /// # Panics
    /// When the CPU does not run this kernel, or `t` is not a face's bordered texels.
    pub(crate) fn face_rows(self, t: &Texels, r: &FaceRun, out: &mut [u32], buf: &mut FaceBuf) {
        assert!(t.width == t.height && t.width >= 2, "bordered face texels");
        run(self.selected(), t, r, out, buf)
    }
}

#[cfg(test)]
mod tests {
    use super::super::face::tests::{cubes, face_texels, view_run};
    use super::*;
    use crate::cube::Face;
    use crate::geom::camera::View;
    use crate::render::cube::scanline_runs;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Every kernel's positions equal the scalar twin's (and its largest `v`), and
        /// nothing is written past the whole vectors: view runs (past the face's edge
        /// too: clamped; behind the eye: NaN or negative `m`), lengths 0..=200.
        #[test]
        fn positions_equal_scalar(
            yaw in -180.0f64..180.0,
            pitch in prop_oneof![-90.0f64..=90.0, Just(90.0), Just(-90.0), Just(45.0)],
            hfov in 5.0f64..170.0,
            (w, x) in (1u32..400).prop_flat_map(|w| (Just(w), 0..w)),
            yf in 0.0f64..1.0,
            n in prop_oneof![Just(1u32), 2u32..64, 64u32..=8192],
            len in 0usize..=200,
        ) {
            let h = 300;
            let y = ((yf * h as f64) as u32).min(h - 1);
            let (_, r) = view_run((yaw, pitch, hfov), (w, h), (x, y), n);
            let n = n as usize;
            let whole = len.next_multiple_of(16);
            let (mut su, mut sv) = (vec![0; len], vec![0; len]);
            let top = positions_scalar(n, &r, &mut su, &mut sv, len);
            prop_assert_eq!(top, sv.iter().copied().max().unwrap_or(i32::MIN));
            for k in Kernel::available() {
                let (mut u, mut v) = (vec![7; whole + 5], vec![7; whole + 5]);
                let t = positions_with(k.selected(), n, &r, &mut u, &mut v, len);
                prop_assert_eq!(&u[..len], &su[..], "{} u", k.name());
                prop_assert_eq!(&v[..len], &sv[..], "{} v", k.name());
                prop_assert_eq!(t, top, "{} top", k.name());
                prop_assert!(u[whole..].iter().chain(&v[whole..]).all(|&x| x == 7));
            }
        }

        /// Every kernel draws the per-pixel renderer's bytes (`CubeMap::bilinear` at the
        /// exact position) and nothing outside the run: view runs of any length 1..=64
        /// (past the face's edge too: clamped), odd offsets.
        #[test]
        fn face_rows_equal_per_pixel(
            ci in 0usize..5,
            yaw in -180.0f64..180.0,
            pitch in prop_oneof![-90.0f64..=90.0, Just(90.0), Just(-90.0), Just(45.0)],
            hfov in 5.0f64..170.0,
            (w, x) in (1u32..400).prop_flat_map(|w| (Just(w), 0..w)),
            yf in 0.0f64..1.0,
            len in 1usize..=64,
            off in 0usize..9,
        ) {
            let h = 300;
            let y = ((yf * h as f64) as u32).min(h - 1);
            let n = cubes()[ci].face_size();
            let (f, r) = view_run((yaw, pitch, hfov), (w, h), (x, y), n);
            check(ci, f, &r, len, off);
        }
    }

    /// Every kernel against the per-pixel samples, with sentinels around `out`.
    fn check(ci: usize, f: Face, r: &FaceRun, len: usize, off: usize) {
        let c = &cubes()[ci];
        let t = face_texels(c, f);
        let mut buf = FaceBuf::default();
        let want: Vec<u32> = (0..len)
            .map(|i| {
                let (u, v, _) = exact(r, i);
                c.bilinear(f, u, v)
            })
            .collect();
        for k in Kernel::available() {
            let mut o = vec![0xDEAD_BEEFu32; off + len + 3];
            k.face_rows(&t, r, &mut o[off..off + len], &mut buf);
            let outside = o[..off].iter().chain(&o[off + len..]);
            assert!(
                outside.into_iter().all(|&x| x == 0xDEAD_BEEF),
                "{}",
                k.name()
            );
            assert_eq!(&o[off..off + len], &want[..], "{} {f:?} {r:?}", k.name());
        }
    }

    #[test]
    fn whole_rows_and_face_edges_equal_per_pixel() {
        // Whole rows of wide frames (long runs), runs ending on a face's bottom edge (the
        // border row) and corners.
        for (yaw, pitch, hfov, w, y) in [
            (0.0, 0.0, 60.0, 1920, 540),
            (30.0, 89.0, 90.0, 1001, 10),
            (-45.0, -90.0, 150.0, 777, 700),
            (45.0, 35.26, 120.0, 640, 100),
            (0.0, -44.9, 90.0, 800, 200),
            (10.0, 10.0, 1.0, 5, 540),
        ] {
            let v = View::new(yaw, pitch, hfov).unwrap();
            for (a, e, face, ok) in scanline_runs(v, w, 1080, 61, y) {
                let (f, r) = view_run((yaw, pitch, hfov), (w, 1080), (a, y), 61);
                if ok {
                    assert_eq!(f, face);
                }
                check(4, f, &r, (e - a) as usize, 1);
            }
        }
    }

    #[test]
    fn bottom_row_reads_the_border() {
        // A run along the face's last texel row's lower half: bilinear equals
        // `CubeMap::bilinear` there (rows n and n + 1, the border), as on the per-pixel
        // path, to the 8-bit weights.
        let c = &cubes()[4];
        let n = c.face_size();
        let half = n as f64 / 2.0;
        // a = x (u from 3.5 to 56.5 over 54 pixels), b = −(n − 0.25 − half)/half·m: v = n − 0.25.
        let m = 10.0;
        let vb = -(n as f64 - 0.25 - half) / half * m;
        let r = FaceRun {
            p: [-m * (1.0 - 3.5 / half), vb, m],
            d: [m / half, 0.0, 0.0],
            dx: 0.0,
            half,
        };
        check(4, Face::Front, &r, 54, 0);
    }
}

//! Cube-face runs on the row kernels: the face's projective line evaluated exactly at
//! every pixel in a positions pass (`f64` SIMD lanes, [`positions_scalar`] the twin),
//! then the row kernels' gather (and for bilinear, blend) over the positions
//! (`kernel/row.rs`, AVX-512 / AVX2 / SSE4.1 / the scalar twin), as the LUT's rows are
//! drawn. The cube scanline renderer's nearest and bilinear runs (`render/cube.rs`); its
//! trilinear runs use the fused exact kernel (`face.rs`).
//!
//! # Why a separate positions pass
//! The fused kernel (`face.rs`: position, gather and blend per vector) is the slowest way
//! to draw a run here: its division sits between the position and the gather in every
//! iteration (1080p cube frame from the 8k map's 2048² faces, one thread: bilinear 9.5
//! ms, nearest 7.3 ms). Stepping the line linearly between exact points every ~9 pixels
//! (bilinear, this module until 2026-12-02) took 5.8 ms but ~21 instructions per pixel of
//! planning and expanding, and moved positions by up to 0.02 texels. A pass of positions
//! alone is a stream of independent divisions (8 `f64` lanes per AVX-512 division, ~0.14
//! ns a lane on this machine), then the row kernels read the positions as they read the
//! LUT's: bilinear 4.6 ms, nearest 4.0 ms, every position exact.
//!
//! # Positions
//! On a run ([`FaceRun`]) the face coordinates are `u = h + h·a/m`, `v = h − h·b/m` with
//! `a`, `b`, `m` linear in the pixel. Pixel `i`'s are computed with the operations of
//! [`crate::cube::face_uv`] in their order (IEEE `f64` is deterministic: the SIMD lanes
//! equal the scalar twin) and rounded as the per-pixel samplers round them: bilinear to
//! Q.16, clamped to the face as `CubeMap::bilinear` does; nearest to the texel
//! `CubeMap::nearest` reads. Both are moved into the bordered face (+1 texel) and given
//! in Q.8, the row kernels' positions. The row kernels then read exactly the texels (and
//! 8-bit weights) the per-pixel samplers read: the scanline renderer's nearest and
//! bilinear images are byte-identical to the per-pixel renderer's.
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
fn positions_scalar<const BILINEAR: bool>(
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
        let (x, y, _) = exact(r, i);
        *pu = q8(x);
        *pv = q8(y);
        top = top.max(*pv);
    }
    top
}

/// [`positions_scalar`] with kernel `k` (the buffers hold `m` rounded up to 16).
#[inline]
fn positions_with<const BILINEAR: bool>(
    k: Selected,
    n: usize,
    r: &FaceRun,
    u: &mut [i32],
    v: &mut [i32],
    m: usize,
) -> i32 {
    #[cfg(target_arch = "x86_64")]
    if let Some(top) = super::x86::face::positions::<BILINEAR>(k, n, r, u, v, m) {
        return top;
    }
    let _ = k;
    positions_scalar::<BILINEAR>(n, r, u, v, m)
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

/// A face run with kernel `k`, bilinear (`BILINEAR`) or nearest.
#[inline]
fn run<const BILINEAR: bool>(
    k: Selected,
    t: &Texels,
    r: &FaceRun,
    out: &mut [u32],
    buf: &mut FaceBuf,
) {
    debug_assert!(t.width == t.height && t.width >= 2, "bordered face texels");
    let len = out.len();
    let n = face_side(t);
    for b in [&mut buf.u, &mut buf.v] {
        if b.len() < len + SLACK {
            b.resize(len + SLACK, 0);
        }
    }
    let top = positions_with::<BILINEAR>(k, n, r, &mut buf.u, &mut buf.v, len);
    let (u, v) = (&buf.u[..len], &buf.v[..len]);
    sample_q8_with::<BILINEAR, false>(k, t, u, v, out);
    if BILINEAR && len > 0 && (top - 128) >> 8 >= n as i32 {
        let last = n as i32;
        for ((o, &u), &v) in out.iter_mut().zip(u).zip(v) {
            if (v - 128) >> 8 >= last {
                *o = bottom(t, u, v);
            }
        }
    }
}

/// Bilinear (`BILINEAR`) or nearest samples of one cube face along a run (see the
/// module docs), with the [`active_kernel`](super::active_kernel). `t` is the face's
/// bordered texels. Every pixel of `out` is written; positions are clamped into the face,
/// so any run is safe.
#[inline]
pub(crate) fn face_rows<const BILINEAR: bool>(
    t: &Texels,
    r: &FaceRun,
    out: &mut [u32],
    buf: &mut FaceBuf,
) {
    run::<BILINEAR>(active(), t, r, out, buf)
}

#[cfg(test)]
impl Kernel {
    /// [`face_rows`] with this kernel.
    ///
    /// # Panics
    /// When the CPU does not run this kernel, or `t` is not a face's bordered texels.
    pub(crate) fn face_rows<const BILINEAR: bool>(
        self,
        t: &Texels,
        r: &FaceRun,
        out: &mut [u32],
        buf: &mut FaceBuf,
    ) {
        assert!(t.width == t.height && t.width >= 2, "bordered face texels");
        run::<BILINEAR>(self.selected(), t, r, out, buf)
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
            for bilinear in [false, true] {
                let (mut su, mut sv) = (vec![0; len], vec![0; len]);
                let top = if bilinear {
                    positions_scalar::<true>(n, &r, &mut su, &mut sv, len)
                } else {
                    positions_scalar::<false>(n, &r, &mut su, &mut sv, len)
                };
                prop_assert_eq!(top, sv.iter().copied().max().unwrap_or(i32::MIN));
                for k in Kernel::available() {
                    let (mut u, mut v) = (vec![7; whole + 5], vec![7; whole + 5]);
                    let (ks, (pu, pv)) = (k.selected(), (&mut u, &mut v));
                    let t = if bilinear {
                        positions_with::<true>(ks, n, &r, pu, pv, len)
                    } else {
                        positions_with::<false>(ks, n, &r, pu, pv, len)
                    };
                    prop_assert_eq!(&u[..len], &su[..], "{} u {}", k.name(), bilinear);
                    prop_assert_eq!(&v[..len], &sv[..], "{} v {}", k.name(), bilinear);
                    prop_assert_eq!(t, top, "{} top", k.name());
                    prop_assert!(u[whole..].iter().chain(&v[whole..]).all(|&x| x == 7));
                }
            }
        }

        /// Every kernel draws the per-pixel renderer's bytes (`CubeMap::bilinear` and
        /// `CubeMap::nearest` at the exact position) and nothing outside the run: view runs of any length 1..=64
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

    /// Every kernel against the per-pixel samples (`CubeMap::bilinear` and
    /// `CubeMap::nearest`), with sentinels around `out`.
    fn check(ci: usize, f: Face, r: &FaceRun, len: usize, off: usize) {
        check_with(ci, f, r, len, off, true);
        check_with(ci, f, r, len, off, false);
    }

    fn check_with(ci: usize, f: Face, r: &FaceRun, len: usize, off: usize, bilinear: bool) {
        let c = &cubes()[ci];
        let t = face_texels(c, f);
        let mut buf = FaceBuf::default();
        let want: Vec<u32> = (0..len)
            .map(|i| {
                let (u, v, _) = exact(r, i);
                if bilinear {
                    c.bilinear(f, u, v)
                } else {
                    c.nearest(f, u, v)
                }
            })
            .collect();
        for k in Kernel::available() {
            let mut o = vec![0xDEAD_BEEFu32; off + len + 3];
            let run = &mut o[off..off + len];
            if bilinear {
                k.face_rows::<true>(&t, r, run, &mut buf);
            } else {
                k.face_rows::<false>(&t, r, run, &mut buf);
            }
            let outside = o[..off].iter().chain(&o[off + len..]);
            assert!(
                outside.into_iter().all(|&x| x == 0xDEAD_BEEF),
                "{}",
                k.name()
            );
            let got = &o[off..off + len];
            assert_eq!(got, &want[..], "{} {bilinear} {f:?} {r:?}", k.name());
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

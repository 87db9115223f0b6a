//! Cube-face runs stepped like spans: the face's projective line evaluated exactly every
//! few pixels and interpolated linearly in fixed point between, then drawn by the row
//! kernels (`kernel/row.rs`: the positions expanded from [`SpanQ8`]s, one gather-and-blend
//! pass over them, AVX-512 / AVX2 / SSE4.1 / the scalar twin). The cube scanline renderer's
//! bilinear runs (`render/cube.rs`). Its nearest runs stay on the exact kernel
//! (`face.rs`): stepped, nearest took 36.8 instead of 20.4 instructions per pixel and
//! was no faster (one thread 9.53 against 8.90 ms, two 5.25 against 5.17 ms).
//!
//! # Positions
//! On a verified run ([`FaceRun`]) the face coordinates are `u(t) = h + h·a(t)/m(t)`,
//! `v(t) = h − h·b(t)/m(t)` with `a`, `b`, `m` linear in the pixel `t` and `m > 0`. The run
//! is cut into sub-spans; at each sub-span's ends the position is computed exactly (in
//! `f64`, the arithmetic of [`crate::cube::face_uv`]), clamped to the face and rounded to
//! Q.16 as `CubeMap::bilinear` rounds it; between, the position steps linearly by the
//! Q.16 difference of the ends divided by the length (truncated towards zero, so every
//! position lies between the ends and inside the face).
//!
//! # The bound, and the sub-span length
//! A projective function `f(t) = (p + q·t)/(r + s·t)` has `f''(t) = 2s(qr − ps)/(r + s·t)³`,
//! and the linear interpolation of `f` between two points `d` apart errs by at most
//! `d²/8 · max|f''|` between them. For `u` (`p, q, r, s` = `a₀, a₁, m₀, m₁`, times `h`) and
//! `v` (`b`), `|f''|` is largest where `m` is smallest, at an end of the interval since
//! `m` is linear and positive there, so the position error (the distance in face texels)
//! of the interpolation over `[t, t + d]` is at most
//!
//! `E(d) = d²/8 · 2h·|m₁|·√((a₁m₀ − a₀m₁)² + (b₁m₀ − b₀m₁)²) / min(m(t), m(t + d))³`.
//!
//! Each sub-span takes the largest length `d` ≤ [`FACE_STEP_MAX`] (or the rest of the
//! run) with `E(d)` ≤ [`FACE_STEP_ERROR`] (0.02 face texels, the LUT's own sampling
//! error; the project's budget is 0.05), taking for `min m` the smaller of `m` at the
//! sub-span's start and `FACE_STEP_MAX` pixels on (or at the run's last pixel), which
//! is no larger (m is linear) and costs no division: `d` the largest length with
//! `d² ≤ 0.02·min m³ / c`, found by stepping from the sub-span before's (a compare or
//! two: m changes little between sub-spans); `d` = 1 is exact. (Any length, not
//! only powers of two: the sub-spans are 1.4x longer on average at the cost of an
//! `i32` division for the step, 47.3 instead of 54.2 instructions per pixel.) The fixed
//! point adds less than `d` Q.16 units per axis (the ends' rounding, ≤ ½ unit, and the
//! truncated step, < 1 unit per pixel), so every position
//! is within [`FACE_STEP_BOUND`] = 0.02 + √2·32/65536 ≈ 0.0207 face texels of the exact
//! one (tested over random views' runs; the largest error measured, 0.0200 texels, is in
//! `docs/performance.md`). At hfov 90 on 2048² faces a sub-span is 9.4 pixels on average
//! (short near a face edge seen obliquely, where `m` is small), one division per
//! sub-span.
//!
//! # Texels
//! The positions are bordered-face coordinates (the face's `(n + 2)²` texels as a
//! [`Texels`] of side `n + 1`: face texel `j` is column `j + 1`), so the row kernels read
//! the border (the neighbouring faces) at the face's edges as `CubeMap::bilinear` does.
//! One difference remains: the row kernels clamp a bilinear read at the last row
//! (`row::sample_at`, the map's pole), which is the face's last texel row, not the
//! border below it; runs reaching the lower half of that row are redrawn there by
//! [`bottom`] (reading the border row), found from the sub-spans' ends (`v` is linear in a
//! sub-span).

use super::face::{face_side, FaceRun};
use super::row::{expand_with, sample_q8_with, Positions, SpanQ8};
#[cfg(test)]
use super::select::Kernel;
use super::select::{active, Selected};
use super::Texels;
use crate::geom::fixed::{FX_BITS, FX_HALF, FX_ONE};
use crate::map::sample::lerp_px;

/// Longest sub-span of a stepped face run, in pixels.
pub const FACE_STEP_MAX: usize = 32;

/// The interpolation error a sub-span may have, in face texels (see the module docs).
pub const FACE_STEP_ERROR: f64 = 0.02;

/// The largest distance between a stepped face position (Q.16, as the kernels read it)
/// and the exact one, in face texels: [`FACE_STEP_ERROR`] plus the fixed point's
/// `FACE_STEP_MAX` Q.16 units per axis.
pub const FACE_STEP_BOUND: f64 =
    FACE_STEP_ERROR + std::f64::consts::SQRT_2 * FACE_STEP_MAX as f64 / FX_ONE as f64;

/// `l²` for the sub-span lengths `l` in 0..=FACE_STEP_MAX.
const SQUARES: [f64; FACE_STEP_MAX + 1] = {
    let mut q = [0.0; FACE_STEP_MAX + 1];
    let mut l = 0;
    while l <= FACE_STEP_MAX {
        q[l] = (l * l) as f64;
        l += 1;
    }
    q
};

/// Room past a run the row kernels may write in the position buffers (whole vectors).
const SLACK: usize = 32;

/// A band's scratch for stepped face runs: the sub-spans and the position buffers.
#[derive(Debug, Default)]
pub(crate) struct StepBuf {
    spans: Vec<SpanQ8>,
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

/// Cut a run of `len` pixels on a face of side `n` into sub-spans (see the module docs):
/// their [`SpanQ8`]s into `spans` (positions in bordered-face Q.16, `k` from 0; the
/// mirror line unused). Returns whether the run reaches the lower half of the face's
/// last texel row (see [`bottom`]).
pub(super) fn plan(n: usize, r: &FaceRun, len: usize, spans: &mut Vec<SpanQ8>) -> bool {
    spans.clear();
    if len == 0 {
        return false;
    }
    // Clamped into the face as `CubeMap::bilinear` clamps, the same Q.16 values (it
    // clamps the truncated integer; clamping the float first gives the same integer,
    // NaN → 0 included, and leaves a conversion that cannot saturate).
    let top = (n as i64) << FX_BITS;
    let (topf, one) = (top as f64, FX_ONE as f64);
    let q16 = |x: f64| ((x * one + 0.5).max(0.0).min(topf) as i64) + FX_ONE;
    let ka = r.d[0] * r.p[2] - r.p[0] * r.d[2];
    let kb = r.d[1] * r.p[2] - r.p[1] * r.d[2];
    // E(d) = c·d² / min(m)³ ≤ FACE_STEP_ERROR ⟺ d² ≤ lim·min(m)³.
    let c = 0.25 * r.half * r.d[2].abs() * ka.hypot(kb);
    let lim = FACE_STEP_ERROR / c;
    let m_at = |i: usize| r.p[2] + (r.dx + f64::from(i as u32)) * r.d[2];
    let rising = r.d[2] >= 0.0;
    // The row (bordered, with bilinear's −½) at which the map kernels clamp.
    let last_row = (n as i64) << FX_BITS;
    let mut low = false;
    let (u, v, mut m0) = exact(r, 0);
    let (mut u0, mut v0) = (q16(u), q16(v));
    let mut i0 = 0;
    let mut l = 1;
    while i0 < len {
        let rest = len - 1 - i0;
        // m is linear: its minimum over any sub-span from i0 of up to FACE_STEP_MAX
        // pixels (all on the run) is at least the smaller of m there and at i0 (`m0`,
        // computed as `m_at(i0)` is). Rounded, m is still monotone in the pixel, so
        // that is `m0` where m rises (the other end not needed) and the far end where it
        // falls (NaN as before: both ends NaN).
        let mm = if rising {
            m0
        } else {
            m_at(i0 + FACE_STEP_MAX.min(rest))
        };
        // (NaN → 0, as m ≤ 0 off a verified run: one pixel per step, exact.)
        let most = (lim * mm * mm * mm).max(0.0);
        // The largest l in 1..=FACE_STEP_MAX with l² ≤ most (1 if none), searched from
        // the last sub-span's: m changes little from one sub-span to the next, so this
        // takes a compare or two where a square root and its conversion took ~35
        // instructions. (`most` is never NaN; ∞ gives the cap.)
        while l < FACE_STEP_MAX && SQUARES[l + 1] <= most {
            l += 1;
        }
        while l > 1 && SQUARES[l] > most {
            l -= 1;
        }
        let d = l.min(rest);
        let (u, v, m1) = exact(r, i0 + d);
        let (u1, v1) = (q16(u), q16(v));
        // The run's last sub-span draws its far end too.
        let count = if d == rest { d + 1 } else { d };
        let (du, dv) = if d == 0 {
            (0, 0)
        } else {
            (toward_zero(u1 - u0, d), toward_zero(v1 - v0, d))
        };
        spans.push(SpanQ8::from_q16((i0, count), (u0, v0, 0), (du, dv)));
        low |= v0.max(v1) - FX_HALF >= last_row;
        i0 += count;
        (u0, v0, m0) = (u1, v1, m1);
    }
    low
}

/// `x / d` rounded towards zero (`d` > 0): `x` is a difference of two positions in one
/// face (|x| ≤ 8192 · 2¹⁶ < 2³¹), so in `i32`.
#[inline(always)]
fn toward_zero(x: i64, d: usize) -> i64 {
    i64::from(x as i32 / d as i32)
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

/// A stepped face run with kernel `k`.
#[inline]
fn run(k: Selected, t: &Texels, r: &FaceRun, out: &mut [u32], buf: &mut StepBuf) {
    debug_assert!(t.width == t.height && t.width >= 2, "bordered face texels");
    let len = out.len();
    let n = face_side(t);
    let low = plan(n, r, len, &mut buf.spans);
    for b in [&mut buf.u, &mut buf.v] {
        if b.len() < len + SLACK {
            b.resize(len + SLACK, 0);
        }
    }
    let p = Positions {
        u: &mut buf.u,
        v: &mut buf.v,
        ul: &mut [],
    };
    expand_with::<false>(k, &buf.spans, p);
    let (u, v) = (&buf.u[..len], &buf.v[..len]);
    sample_q8_with::<true, false>(k, t, u, v, out);
    if low {
        let last = n as i32;
        for ((o, &u), &v) in out.iter_mut().zip(u).zip(v) {
            if (v - 128) >> 8 >= last {
                *o = bottom(t, u, v);
            }
        }
    }
}

/// Bilinear samples of one cube face along a verified run, stepped (see the module docs), with the [`active_kernel`](super::active_kernel). `t`
/// is the face's bordered texels. Every pixel of `out` is written; positions are clamped
/// into the face, so any run is safe (only verified runs meet the bound).
#[inline]
pub(crate) fn face_steps(t: &Texels, r: &FaceRun, out: &mut [u32], buf: &mut StepBuf) {
    run(active(), t, r, out, buf)
}

#[cfg(test)]
impl Kernel {
    /// [`face_steps`] with this kernel.
    ///
    /// # Panics
    /// When the CPU does not run this kernel, or `t` is not a face's bordered texels.
    pub(crate) fn face_steps(self, t: &Texels, r: &FaceRun, out: &mut [u32], buf: &mut StepBuf) {
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

    /// The Q.16 face positions (bordered, as the kernels read them) of a planned run.
    fn stepped(spans: &[SpanQ8], len: usize) -> Vec<(i64, i64)> {
        let mut p = vec![(i64::MIN, i64::MIN); len];
        for s in spans {
            for j in 0..s.m as i64 {
                let u = 256 * s.hu as i64 + s.lu as i64 + j * s.du as i64;
                let v = 256 * s.hv as i64 + s.lv as i64 + j * s.dv as i64;
                p[s.k as usize + j as usize] = (u, v);
            }
        }
        p
    }

    /// Largest distance (face texels) between the stepped and the exact positions of the
    /// verified runs of a few rows of a view; every pixel planned exactly once.
    fn view_error(view: (f64, f64, f64), (w, h): (u32, u32), n: u32, rows: &[u32]) -> f64 {
        let v = View::new(view.0, view.1, view.2).unwrap();
        let mut worst = 0.0f64;
        let mut spans = Vec::new();
        for &y in rows {
            for (a, e, face, ok) in scanline_runs(v, w, h, n, y) {
                if !ok {
                    continue;
                }
                let (f, r) = view_run(view, (w, h), (a, y), n);
                assert_eq!(f, face);
                let len = (e - a) as usize;
                plan(n as usize, &r, len, &mut spans);
                let p = stepped(&spans, len);
                for (i, &(su, sv)) in p.iter().enumerate() {
                    assert!(su != i64::MIN, "pixel {i} of {len} not planned");
                    let (u, v, m) = exact(&r, i);
                    assert!(m > 0.0);
                    let one = FX_ONE as f64;
                    let du = (su as f64 - one) / one - u;
                    let dv = (sv as f64 - one) / one - v;
                    worst = worst.max(du.hypot(dv));
                }
            }
        }
        worst
    }

    #[test]
    fn stepped_positions_within_the_bound_over_a_sweep() {
        let mut worst = 0.0f64;
        for yaw in (-180..180).step_by(15) {
            for pitch in [
                -90.0, -60.0, -35.26, -10.0, 0.0, 10.0, 35.26, 45.0, 80.0, 90.0,
            ] {
                for hfov in [20.0, 60.0, 90.0, 120.0, 170.0] {
                    let e = view_error(
                        (yaw as f64 + 0.3, pitch, hfov),
                        (1920, 1080),
                        2048,
                        &[0, 137, 540, 1000, 1079],
                    );
                    worst = worst.max(e);
                }
            }
        }
        eprintln!(
            "stepped face positions: max error {worst:.5} texels (bound {FACE_STEP_BOUND:.5})"
        );
        assert!(worst <= FACE_STEP_BOUND, "{worst} > {FACE_STEP_BOUND}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Random views, sizes and faces: the position bound.
        #[test]
        fn stepped_positions_within_the_bound(
            yaw in -180.0f64..180.0,
            pitch in -90.0f64..=90.0,
            hfov in 5.0f64..170.0,
            w in 1u32..3000,
            h in 1u32..2000,
            n in prop_oneof![Just(1u32), 2u32..64, 64u32..=8192],
            yf in 0.0f64..1.0,
        ) {
            let y = ((yf * h as f64) as u32).min(h - 1);
            let e = view_error((yaw, pitch, hfov), (w, h), n, &[y]);
            prop_assert!(e <= FACE_STEP_BOUND, "{e}");
        }

        /// Every kernel writes the scalar twin's bytes and nothing outside the run: view
        /// runs of any length 1..=64 (past the face's edge too: clamped), odd offsets.
        #[test]
        fn face_steps_equal_scalar(
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

    /// Every kernel against the scalar one, with sentinels around `out`.
    fn check(ci: usize, f: Face, r: &FaceRun, len: usize, off: usize) {
        let c = &cubes()[ci];
        let t = face_texels(c, f);
        let mut buf = StepBuf::default();
        let mut want = Vec::new();
        for k in Kernel::available() {
            let mut o = vec![0xDEAD_BEEFu32; off + len + 3];
            k.face_steps(&t, r, &mut o[off..off + len], &mut buf);
            let outside = o[..off].iter().chain(&o[off + len..]);
            assert!(
                outside.into_iter().all(|&x| x == 0xDEAD_BEEF),
                "{}",
                k.name()
            );
            let got = o[off..off + len].to_vec();
            if k == Kernel::Scalar {
                want = got;
            } else {
                assert_eq!(got, want, "{} {f:?} {r:?}", k.name());
            }
        }
    }

    #[test]
    fn whole_rows_and_face_edges_equal_scalar() {
        // Whole rows of wide frames (long runs, every sub-span length), runs ending on
        // a face's bottom edge (the border row) and corners.
        for (yaw, pitch, hfov, w, y) in [
            (0.0, 0.0, 60.0, 1920, 540),
            (30.0, 89.0, 90.0, 1001, 10),
            (-45.0, -90.0, 150.0, 777, 700),
            (45.0, 35.26, 120.0, 640, 100),
            (0.0, -44.9, 90.0, 800, 200),
            (10.0, 10.0, 1.0, 5, 540),
        ] {
            let v = View::new(yaw, pitch, hfov).unwrap();
            for (a, e, _, _) in scanline_runs(v, w, 1080, 61, y) {
                let (f, r) = view_run((yaw, pitch, hfov), (w, 1080), (a, y), 61);
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
        let t = face_texels(c, Face::Front);
        let mut buf = StepBuf::default();
        for k in Kernel::available() {
            let mut out = vec![0; 54];
            k.face_steps(&t, &r, &mut out, &mut buf);
            for (i, &o) in out.iter().enumerate() {
                let (u, v, _) = exact(&r, i);
                assert_eq!(o, c.bilinear(Face::Front, u, v), "{} pixel {i}", k.name());
            }
        }
    }
}

//! Cube-face runs evaluated exactly: the span kernels' gather and blend fed by a
//! projective line, one division per pixel, in one fused kernel. The cube scanline
//! renderer's trilinear runs (both pyramid levels of each chunk, bilinear on each); its
//! nearest and bilinear runs compute the same positions in a pass of their own and draw
//! them with the row kernels (`face_rows.rs`: faster, see there).
//!
//! Along a scanline the cube renderer's ray is `P + dx · B` (`render/cube.rs`), so on a
//! face with axes `(a, b, m)` the face coordinates are `u = h + h·a/m`, `v = h − h·b/m`
//! with `a`, `b`, `m` linear in `dx`: a projective line, not a linear one. Stepping it
//! linearly between exact points needs a bound on the curvature and changes bytes
//! (tried for bilinear, `docs/performance.md`); these kernels instead evaluate the
//! projective line *exactly* at every pixel, in `f64` SIMD lanes (8 per AVX-512 vector,
//! 4 per AVX2 vector, 2 per SSE vector: three multiply-adds, one division, two
//! multiply-adds per pixel), with the very operations, in the very order, of
//! [`crate::cube::face_uv`] and [`crate::cube::CubeMap::bilinear`] (IEEE `f64` arithmetic is deterministic and
//! correctly rounded, and rounding is symmetric in sign, so a negated axis is computed
//! as the negation of the same sum). The rounded positions then go to the same 2×2 gather
//! and 8-bit blend as the map's span kernels. So the images stay byte-identical to the
//! per-pixel renderer: the sampling-position error of the cube renderer stays zero.
//!
//! A run reads one face's bordered texels ([`Texels`] of side `n + 1`, the stored
//! `(n + 2)²` texels: the face and its one-texel border from the neighbours), so a
//! bilinear read across a face edge reads the neighbour exactly as the per-pixel path
//! does. Positions are clamped to the face as the per-pixel samplers clamp them
//! (NaN → 0), so any input is safe; only the renderer's proven runs (every pixel strictly
//! on the face) call it.

#[cfg(test)]
use super::select::Kernel;
use super::select::{active, Selected};
use super::Texels;
use crate::geom::fixed::{FX_BITS, FX_HALF, FX_ONE};
use crate::map::sample::lerp_px;

#[cfg(target_arch = "x86_64")]
use super::x86;

/// A run of pixels on one cube face: pixel `i` has the ray coordinates on the face's
/// axes `(a, b, m) = p + (dx + i) · d` (componentwise), and face coordinates
/// `u = half + a · (half / m)`, `v = half − b · (half / m)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FaceRun {
    /// `(a, b, m)` at `dx` = 0 (the row part `P` on the face's axes).
    pub p: [f64; 3],
    /// Their change per pixel (the image x axis `B` on the face's axes).
    pub d: [f64; 3],
    /// `dx` of the first pixel (`x + ½ − W/2`: a multiple of ½, so `dx + i` is exact).
    pub dx: f64,
    /// Half the face side.
    pub half: f64,
}

/// The face side `n` of a face's bordered texels (`Texels` of side `n + 1`).
#[inline(always)]
pub(super) fn face_side(t: &Texels) -> usize {
    t.width as usize - 1
}

/// The portable kernel, one pixel at a time: the reference the SIMD kernels equal, and
/// the per-pixel renderer's arithmetic (see the module docs): bilinear (`BLEND`: blended
/// into `out` by `frac`, `lerp_px(out, sample, frac)`).
pub(super) fn scalar<const BLEND: bool>(t: &Texels, r: &FaceRun, out: &mut [u32], frac: u32) {
    let n = face_side(t);
    let stride = t.stride();
    let nf = n as f64;
    for (i, o) in out.iter_mut().enumerate() {
        let dx = r.dx + i as f64;
        let a = r.p[0] + dx * r.d[0];
        let b = r.p[1] + dx * r.d[1];
        let m = r.p[2] + dx * r.d[2];
        let q = r.half / m;
        let (u, v) = (r.half + a * q, r.half - b * q);
        // `CubeMap::bilinear`: Q.16 rounded half up, + ½ − ½ (border, centres).
        let uu = (u.max(0.0).min(nf) * FX_ONE as f64 + 0.5) as i64 + FX_HALF;
        let vv = (v.max(0.0).min(nf) * FX_ONE as f64 + 0.5) as i64 + FX_HALF;
        let x0 = (uu >> FX_BITS) as usize;
        let y0 = (vv >> FX_BITS) as usize;
        let fx = ((uu >> (FX_BITS - 8)) & 0xFF) as u32;
        let fy = ((vv >> (FX_BITS - 8)) & 0xFF) as u32;
        let k = y0 * stride + x0;
        let q = &t.px[k..k + stride + 2];
        let sample = lerp_px(
            lerp_px(q[0], q[1], fx),
            lerp_px(q[stride], q[stride + 1], fx),
            fy,
        );
        *o = if BLEND {
            lerp_px(*o, sample, frac)
        } else {
            sample
        };
    }
}

/// [`Kernel::face_span`] / [`Kernel::face_blend`] with kernel `k`.
#[inline]
fn run<const BLEND: bool>(k: Selected, t: &Texels, r: &FaceRun, out: &mut [u32], frac: u32) {
    debug_assert!(t.width == t.height && t.width >= 2, "bordered face texels");
    #[cfg(target_arch = "x86_64")]
    if x86::face::face_span::<BLEND>(k, t, r, out, frac) {
        return;
    }
    let _ = k;
    scalar::<BLEND>(t, r, out, frac)
}

/// [`Kernel::face_span`] with the [`active_kernel`](super::active_kernel).
#[inline]
pub(crate) fn face_span(t: &Texels, r: &FaceRun, out: &mut [u32]) {
    run::<false>(active(), t, r, out, 0)
}

/// [`Kernel::face_blend`] with the [`active_kernel`](super::active_kernel).
#[inline]
pub(crate) fn face_blend(t: &Texels, r: &FaceRun, out: &mut [u32], frac: u32) {
    run::<true>(active(), t, r, out, frac)
}

#[cfg(test)]
impl Kernel {
    /// Bilinear samples of one cube face along a [`FaceRun`]:
    /// `t` is the face's bordered texels (`(n + 2)²`, as [`Texels`] of side `n + 1`).
    /// Writes every pixel of `out` (positions are clamped into the face).
    ///
    /// # Panics
    /// When the CPU does not run this kernel, or `t` is not a face's bordered texels
    /// (a square of side 2 or more).
    pub(crate) fn face_span(self, t: &Texels, r: &FaceRun, out: &mut [u32]) {
        assert!(t.width == t.height && t.width >= 2, "bordered face texels");
        run::<false>(self.selected(), t, r, out, 0)
    }

    /// `out[i]` = `lerp_px(out[i], bilinear sample i, frac)` along a [`FaceRun`] (the
    /// second level of a trilinear chunk; see [`Kernel::face_span`]).
    ///
    /// # Panics
    /// As [`Kernel::face_span`].
    pub(crate) fn face_blend(self, t: &Texels, r: &FaceRun, out: &mut [u32], frac: u32) {
        assert!(t.width == t.height && t.width >= 2, "bordered face texels");
        run::<true>(self.selected(), t, r, out, frac)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::cube::{face_axes, face_of, CubeMap, Face};
    use glam::DVec3;
    use proptest::prelude::*;

    /// A cube of random texels (random top bytes too) of side `n`.
    fn noise_cube(n: u32, mut seed: u64) -> CubeMap {
        let faces: Vec<Vec<u32>> = (0..6)
            .map(|_| {
                (0..n * n)
                    .map(|_| {
                        seed ^= seed << 13;
                        seed ^= seed >> 7;
                        seed ^= seed << 17;
                        (seed >> 16) as u32
                    })
                    .collect()
            })
            .collect();
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        CubeMap::from_faces(n, refs).unwrap()
    }

    pub(in crate::render::kernel) fn cubes() -> &'static [CubeMap] {
        static C: std::sync::OnceLock<Vec<CubeMap>> = std::sync::OnceLock::new();
        C.get_or_init(|| {
            [1, 2, 3, 16, 61]
                .iter()
                .enumerate()
                .map(|(k, &n)| noise_cube(n, 0x9E37_79B9 + k as u64))
                .collect()
        })
    }

    pub(in crate::render::kernel) fn face_texels(c: &CubeMap, f: Face) -> Texels<'_> {
        let s = c.face_size() + 1;
        Texels::new(c.bordered_face(f), s, s, false).unwrap()
    }

    /// The per-pixel bilinear sampler of [`CubeMap`] at [`crate::cube::face_uv`] of the
    /// ray.
    fn per_pixel(c: &CubeMap, f: Face, r: &FaceRun, len: usize) -> Vec<u32> {
        (0..len)
            .map(|i| {
                let dx = r.dx + i as f64;
                let (a, b, m) = (
                    r.p[0] + dx * r.d[0],
                    r.p[1] + dx * r.d[1],
                    r.p[2] + dx * r.d[2],
                );
                let q = r.half / m;
                let (u, v) = (r.half + a * q, r.half - b * q);
                c.bilinear(f, u, v)
            })
            .collect()
    }

    /// Every kernel against the scalar twin, and the twin against `CubeMap`'s samplers,
    /// with sentinels around the output; the blend with weight `frac` (into random
    /// pixels) against `lerp_px` of the per-pixel bilinear sample.
    fn check(ci: usize, f: Face, r: &FaceRun, len: usize, off: usize, frac: u32) {
        let c = &cubes()[ci];
        let t = face_texels(c, f);
        let want = per_pixel(c, f, r, len);
        for k in Kernel::available() {
            let mut buf = vec![0xDEAD_BEEFu32; off + len + 3];
            k.face_span(&t, r, &mut buf[off..off + len]);
            assert!(
                buf[..off]
                    .iter()
                    .chain(&buf[off + len..])
                    .all(|&x| x == 0xDEAD_BEEF),
                "{} wrote outside its run",
                k.name()
            );
            assert_eq!(
                &buf[off..off + len],
                &want[..],
                "{} {f:?} {r:?} len {len}",
                k.name()
            );
        }
        let under: Vec<u32> = (0..len as u32)
            .map(|i| i.wrapping_mul(0x9E37_79B9))
            .collect();
        for k in Kernel::available() {
            let mut buf = vec![0xDEAD_BEEFu32; off + len + 3];
            buf[off..off + len].copy_from_slice(&under);
            k.face_blend(&t, r, &mut buf[off..off + len], frac);
            assert!(
                buf[..off]
                    .iter()
                    .chain(&buf[off + len..])
                    .all(|&x| x == 0xDEAD_BEEF),
                "{} blend wrote outside its run",
                k.name()
            );
            for (i, (&got, (&u, &b))) in buf[off..off + len]
                .iter()
                .zip(under.iter().zip(&want))
                .enumerate()
            {
                assert_eq!(
                    got,
                    lerp_px(u, b, frac),
                    "{} blend {frac} pixel {i} {r:?}",
                    k.name()
                );
            }
        }
    }

    /// A face run of a view's scanline as the renderer builds it: `P`, `B` of
    /// `render/cube.rs` on the axes of the face of the run's first pixel.
    pub(in crate::render::kernel) fn view_run(
        (yaw, pitch, hfov): (f64, f64, f64),
        (w, h): (u32, u32),
        (x, y): (u32, u32),
        n: u32,
    ) -> (Face, FaceRun) {
        let focal = (w as f64 / 2.0) / (hfov.to_radians() / 2.0).tan();
        let (sp, cp) = pitch.to_radians().sin_cos();
        let (sy, cy) = yaw.to_radians().sin_cos();
        let b = DVec3::new(cy, 0.0, -sy);
        let r1 = DVec3::new(-sp * sy, cp, -sp * cy);
        let r2 = DVec3::new(cp * sy, sp, cp * cy);
        let dy = h as f64 / 2.0 - (y as f64 + 0.5);
        let p = dy * r1 + focal * r2;
        let dx = x as f64 + 0.5 - w as f64 / 2.0;
        let f = face_of(p + dx * b);
        let (pa, pb, pm) = face_axes(f, p);
        let (ba, bb, bm) = face_axes(f, b);
        (
            f,
            FaceRun {
                p: [pa, pb, pm],
                d: [ba, bb, bm],
                dx,
                half: n as f64 / 2.0,
            },
        )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]

        /// Runs of real views: any row (the poles' up and down faces included at pitch
        /// ±90), lengths 1..=64 running past the face edge (clamped, the border read),
        /// odd output offsets.
        #[test]
        fn view_runs_equal_scalar_and_per_pixel(
            ci in 0usize..5,
            yaw in -180.0f64..180.0,
            pitch in prop_oneof![-90.0f64..=90.0, Just(90.0), Just(-90.0), Just(45.0)],
            hfov in 5.0f64..170.0,
            (w, x) in (1u32..400).prop_flat_map(|w| (Just(w), 0..w)),
            yf in 0.0f64..1.0,
            len in 1usize..=64,
            off in 0usize..9,
            frac in 0u32..256,
        ) {
            let h = 300;
            let y = ((yf * h as f64) as u32).min(h - 1);
            let n = cubes()[ci].face_size();
            let (f, r) = view_run((yaw, pitch, hfov), (w, h), (x, y), n);
            check(ci, f, &r, len, off, frac);
        }

        /// Arbitrary lines: rays behind the face (m ≤ 0: infinite positions; 0/0: NaN),
        /// far off the face, tiny and huge steps; all clamped as the per-pixel samplers.
        #[test]
        fn any_line_equals_scalar(
            ci in 0usize..5,
            p in prop::array::uniform3(prop_oneof![4 => -3.0f64..3.0, 1 => Just(0.0), 1 => Just(-0.0)]),
            d in prop::array::uniform3(prop_oneof![-1.0f64..1.0, -1e-6f64..1e-6, Just(0.0)]),
            dx in -100i32..100,
            len in 1usize..=64,
            off in 0usize..9,
            fi in 0usize..6,
            frac in 0u32..256,
        ) {
            let n = cubes()[ci].face_size();
            let r = FaceRun { p, d, dx: dx as f64 * 0.5, half: n as f64 / 2.0 };
            check(ci, Face::from_index(fi), &r, len, off, frac);
        }
    }

    #[test]
    fn long_runs_equal_scalar() {
        // Whole rows of wide frames (many full vectors), and the one-pixel run.
        for (yaw, pitch, hfov, w) in [
            (0.0, 0.0, 60.0, 1920),
            (30.0, 89.0, 90.0, 1001),
            (-45.0, -90.0, 150.0, 777),
            (10.0, 10.0, 1.0, 5),
        ] {
            let (f, r) = view_run((yaw, pitch, hfov), (w, 1080), (0, 540), 61);
            check(4, f, &r, w as usize, 1, 77);
            check(4, f, &r, 1, 0, 255);
        }
    }
}

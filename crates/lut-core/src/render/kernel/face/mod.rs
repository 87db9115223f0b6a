//! Cube-face runs on the row kernels: the face's projective line evaluated exactly at
//! every pixel in a positions pass (`f64` SIMD lanes in `x86.rs`, `scalar.rs` the twin),
//! then the row kernels' gather (and for bilinear, blend) over the positions
//! (`kernel/row.rs`, AVX-512 / AVX2 / SSE4.1 / the scalar twin), as the LUT's rows are
//! drawn. The cube scanline renderer's runs (`render/cube.rs`): nearest, bilinear, and
//! trilinear's two levels ([`face_rows_blend`] blends the second in by a weight per
//! chunk of pixels).
//!
//! # Why a separate positions pass
//! A fused kernel (position, gather and blend per vector; this module's until
//! 2026-12-02) is the slowest way to draw a run here: its division sits between the
//! position and the gather in every iteration (1080p cube frame from the 8k map's 2048²
//! faces, one thread: bilinear 9.5 ms, nearest 7.3 ms, trilinear 14.1 ms). Stepping the
//! line linearly between exact points every ~9 pixels (bilinear, `face_step.rs` until
//! 2026-12-02) took 5.8 ms but ~21 instructions per pixel of planning and expanding, and
//! moved positions by up to 0.02 texels. A pass of positions alone is a stream of
//! independent divisions (8 `f64` lanes per AVX-512 division, ~0.14 ns a lane on this
//! machine), then the row kernels read the positions as they read the LUT's: bilinear
//! 4.6 ms, nearest 4.0 ms, trilinear 6.7 ms, every position exact.
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

use super::row::Level;
use super::select::SelectedKernel;
use super::Texels;
use crate::map::sample::lerp_px;

mod scalar;
#[cfg(target_arch = "x86_64")]
mod x86;

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

/// Room past a run the kernels may write in the position buffers (whole vectors).
const SLACK: usize = 16;

/// A band's scratch for face runs: the position buffers, and for trilinear's blended
/// level the weights and the pixels under redrawn ones.
#[derive(Debug, Default)]
pub(crate) struct FaceBuf {
    u: Vec<i32>,
    v: Vec<i32>,
    w: Vec<u32>,
    under: Vec<u32>,
    /// The caller's per-chunk scratch (trilinear: each chunk's two levels, and the
    /// weights of the second), kept here so a band allocates it once.
    pub(crate) levels: Vec<ChunkLevels>,
    pub(crate) fracs: Vec<u32>,
}

/// The two pyramid levels a trilinear chunk of a face run reads ([`FaceBuf::levels`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct ChunkLevels {
    /// The first level's index in the cube's pyramid (0: the cube itself).
    pub(crate) first: usize,
    /// The second level's index (the same as `first` at the pyramid's last level).
    pub(crate) second: usize,
}

/// The bordered Q.8 positions of the run's pixels 0..m with kernel `k` (the buffers
/// hold `m` rounded up to 16), and the largest `v` (`i32::MIN` for no pixel).
#[inline]
fn positions_with<const BILINEAR: bool>(
    k: SelectedKernel,
    n: usize,
    r: &FaceRun,
    u: &mut [i32],
    v: &mut [i32],
    m: usize,
) -> i32 {
    #[cfg(target_arch = "x86_64")]
    if let Some(top) = x86::positions::<BILINEAR>(k, n, r, u, v, m) {
        return top;
    }
    let _ = k;
    scalar::positions::<BILINEAR>(n, r, u, v, m)
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
    k: SelectedKernel,
    t: &Texels,
    r: &FaceRun,
    out: &mut [u32],
    buf: &mut FaceBuf,
) {
    debug_assert!(t.width == t.height && t.width >= 2, "bordered face texels");
    let (len, n) = (out.len(), face_side(t));
    let low = positions::<BILINEAR>(k, t, r, len, buf);
    let (u, v) = (&buf.u[..len], &buf.v[..len]);
    k.sample_q8::<BILINEAR, false>(t, u, v, out);
    if BILINEAR && low {
        let last = n as i32;
        for ((o, &u), &v) in out.iter_mut().zip(u).zip(v) {
            if (v - 128) >> 8 >= last {
                *o = bottom(t, u, v);
            }
        }
    }
}

/// The run's `len` positions into `buf` (grown as needed) with kernel `k`; whether a
/// bilinear read reaches the lower half of the face's last texel row (see [`bottom`]).
#[inline]
fn positions<const BILINEAR: bool>(
    k: SelectedKernel,
    t: &Texels,
    r: &FaceRun,
    len: usize,
    buf: &mut FaceBuf,
) -> bool {
    let n = face_side(t);
    for b in [&mut buf.u, &mut buf.v] {
        if b.len() < len + SLACK {
            b.resize(len + SLACK, 0);
        }
    }
    let top = positions_with::<BILINEAR>(k, n, r, &mut buf.u, &mut buf.v, len);
    len > 0 && (top - 128) >> 8 >= n as i32
}

/// Trilinear's second-level weights along a face run: pixel `j` is blended by
/// `fracs[j / chunk]` (0..=255), one weight per chunk of `chunk` pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ChunkWeights<'a> {
    pub(crate) chunk: usize,
    pub(crate) fracs: &'a [u32],
}

/// Bilinear samples along a run blended into `out` with kernel `k`: pixel `j` gets
/// `lerp_px(out[j], sample, fracs[j / chunk])` (trilinear's second level, one weight per
/// chunk of pixels).
#[inline]
fn run_blend(
    k: SelectedKernel,
    t: &Texels,
    r: &FaceRun,
    out: &mut [u32],
    weights: ChunkWeights<'_>,
    buf: &mut FaceBuf,
) {
    let ChunkWeights { chunk, fracs } = weights;
    debug_assert!(t.width == t.height && t.width >= 2, "bordered face texels");
    let (len, n) = (out.len(), face_side(t));
    assert!(
        chunk > 0 && fracs.len() * chunk >= len,
        "a weight per chunk"
    );
    let low = positions::<true>(k, t, r, len, buf);
    // Each chunk's weight repeated over its pixels (no division per pixel).
    buf.w.clear();
    for &f in fracs {
        let k = chunk.min(len - buf.w.len());
        buf.w.resize(buf.w.len() + k, f);
        if buf.w.len() == len {
            break;
        }
    }
    if low {
        buf.under.clear();
        buf.under.extend_from_slice(out);
    }
    let (u, v, w) = (&buf.u[..len], &buf.v[..len], &buf.w[..]);
    let lv = Level { k: 0, wq: 0, w };
    k.sample_lv::<true, false, false, true>(t, u, v, out, &lv);
    if low {
        let last = n as i32;
        for (j, o) in out.iter_mut().enumerate() {
            if (v[j] - 128) >> 8 >= last {
                *o = lerp_px(buf.under[j], bottom(t, u[j], v[j]), w[j]);
            }
        }
    }
}

impl SelectedKernel {
    /// Bilinear (`BILINEAR`) or nearest samples of one cube face along a run (see the
    /// module docs). `t` is the face's bordered texels. Every pixel of `out` is written;
    /// positions are clamped into the face, so any run is safe.
    #[inline]
    pub(crate) fn face_rows<const BILINEAR: bool>(
        self,
        t: &Texels,
        r: &FaceRun,
        out: &mut [u32],
        buf: &mut FaceBuf,
    ) {
        run::<BILINEAR>(self, t, r, out, buf)
    }

    /// Trilinear's second level: bilinear samples of one cube face along a run blended
    /// into `out` (pixel `j` by `weights.fracs[j / weights.chunk]`, 0..=255); otherwise as
    /// [`SelectedKernel::face_rows`].
    ///
    /// # Panics
    /// When `weights.fracs` holds fewer than a weight per chunk, or `weights.chunk` is 0.
    #[inline]
    pub(crate) fn face_rows_blend(
        self,
        t: &Texels,
        r: &FaceRun,
        out: &mut [u32],
        weights: ChunkWeights<'_>,
        buf: &mut FaceBuf,
    ) {
        run_blend(self, t, r, out, weights, buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cube::{face_axes, face_of, CubeMap, Face};
    use crate::geom::camera::View;
    use crate::render::cube::scanline_runs;
    use crate::render::kernel::Kernel;
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
                    scalar::positions::<true>(n, &r, &mut su, &mut sv, len)
                } else {
                    scalar::positions::<false>(n, &r, &mut su, &mut sv, len)
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

        /// Arbitrary lines: rays behind the face (m ≤ 0: infinite positions; 0/0: NaN),
        /// far off the face, tiny and huge steps; all clamped as the per-pixel samplers.
        #[test]
        fn any_line_equals_per_pixel(
            ci in 0usize..5,
            p in prop::array::uniform3(prop_oneof![4 => -3.0f64..3.0, 1 => Just(0.0), 1 => Just(-0.0)]),
            d in prop::array::uniform3(prop_oneof![-1.0f64..1.0, -1e-6f64..1e-6, Just(0.0)]),
            dx in -100i32..100,
            len in 1usize..=64,
            off in 0usize..9,
            fi in 0usize..6,
        ) {
            let n = cubes()[ci].face_size();
            let r = FaceRun { p, d, dx: dx as f64 * 0.5, half: n as f64 / 2.0 };
            check(ci, Face::from_index(fi), &r, len, off);
        }

        /// Trilinear's second level: every kernel blends the per-pixel bilinear sample
        /// into what was there by its chunk's weight (`lerp_px`), view runs and lines
        /// off the face, chunks of 1..=20 pixels, weights 0..=255.
        #[test]
        fn blend_equals_per_pixel(
            ci in 0usize..5,
            yaw in -180.0f64..180.0,
            pitch in prop_oneof![-90.0f64..=90.0, Just(90.0), Just(-90.0)],
            hfov in 5.0f64..170.0,
            (w, x) in (1u32..400).prop_flat_map(|w| (Just(w), 0..w)),
            yf in 0.0f64..1.0,
            len in 1usize..=80,
            chunk in 1usize..=20,
            seed in any::<u32>(),
        ) {
            let h = 300;
            let y = ((yf * h as f64) as u32).min(h - 1);
            let n = cubes()[ci].face_size();
            let (f, r) = view_run((yaw, pitch, hfov), (w, h), (x, y), n);
            check_blend(ci, f, &r, len, chunk, seed);
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
                let at = scalar::exact(r, i);
                if bilinear {
                    c.bilinear(f, at.u, at.v)
                } else {
                    c.nearest(f, at.u, at.v)
                }
            })
            .collect();
        for k in Kernel::available() {
            let mut o = vec![0xDEAD_BEEFu32; off + len + 3];
            let run = &mut o[off..off + len];
            if bilinear {
                k.selected().face_rows::<true>(&t, r, run, &mut buf);
            } else {
                k.selected().face_rows::<false>(&t, r, run, &mut buf);
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

    /// Every kernel's [`face_rows_blend`] against `lerp_px` of what was there and the
    /// per-pixel bilinear sample, with sentinels around `out`.
    fn check_blend(ci: usize, f: Face, r: &FaceRun, len: usize, chunk: usize, seed: u32) {
        let c = &cubes()[ci];
        let t = face_texels(c, f);
        let mut buf = FaceBuf::default();
        let fracs: Vec<u32> = (0..len.div_ceil(chunk) as u32)
            .map(|i| (seed.wrapping_add(i).wrapping_mul(0x9E37_79B9) >> 24) % 256)
            .collect();
        let under: Vec<u32> = (0..len as u32)
            .map(|i| (i ^ seed).wrapping_mul(0x85EB_CA6B))
            .collect();
        let want: Vec<u32> = (0..len)
            .map(|i| {
                let at = scalar::exact(r, i);
                lerp_px(under[i], c.bilinear(f, at.u, at.v), fracs[i / chunk])
            })
            .collect();
        for k in Kernel::available() {
            let mut o = vec![0xDEAD_BEEFu32; len + 4];
            o[1..=len].copy_from_slice(&under);
            k.selected().face_rows_blend(
                &t,
                r,
                &mut o[1..=len],
                ChunkWeights {
                    chunk,
                    fracs: &fracs,
                },
                &mut buf,
            );
            assert!(o[0] == 0xDEAD_BEEF && o[len + 1..].iter().all(|&x| x == 0xDEAD_BEEF));
            assert_eq!(
                &o[1..=len],
                &want[..],
                "{} {f:?} {r:?} chunk {chunk}",
                k.name()
            );
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
            for run in scanline_runs(v, w, 1080, 61, y) {
                let (f, r) = view_run((yaw, pitch, hfov), (w, 1080), (run.start, y), 61);
                if run.verified {
                    assert_eq!(f, run.face);
                }
                check(4, f, &r, (run.end - run.start) as usize, 1);
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
        check_blend(4, Face::Front, &r, 54, 16, 7);
        check_blend(4, Face::Front, &r, 54, 5, 0xFFFF_FFFF);
    }
}

//! Every kernel the CPU runs against the scalar twin (identical bytes, same answer to
//! "inside?"), and the scalar twin against the per-pixel samplers of [`EnvMap`].

use super::span::{
    nearest_span_direct, sample_span, sample_span_cropped, sample_spans, trilinear_span,
};
use super::*;
use crate::geom::coverage::Crop;
use crate::geom::fixed::{to_fx, FX_BITS, FX_ONE};
use crate::geom::projection::Projection;
use crate::map::sample::lerp_px;
use crate::map::synth::grid_map;
use crate::named::Named;
use proptest::prelude::*;
use std::sync::OnceLock;

mod row_pass;

/// Written around the output slice: a kernel must not touch it.
const SENTINEL: u32 = 0xDEAD_BEEF;

/// Padded test maps (width, height, pixels with random top bytes too), built once.
fn maps() -> &'static [(u32, u32, Vec<u32>)] {
    static MAPS: OnceLock<Vec<(u32, u32, Vec<u32>)>> = OnceLock::new();
    MAPS.get_or_init(|| {
        let sizes = [
            (1, 1),
            (2, 1),
            (1, 2),
            (2, 2),
            (3, 5),
            (17, 9),
            (64, 32),
            (257, 130),
            (65536, 3),
            (4096, 2048),
        ];
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        sizes
            .iter()
            .map(|&(w, h)| {
                let n = (w as usize + 1) * (h as usize + 1);
                let px = (0..n)
                    .map(|_| {
                        seed ^= seed << 13;
                        seed ^= seed >> 7;
                        seed ^= seed << 17;
                        (seed >> 16) as u32
                    })
                    .collect();
                (w, h, px)
            })
            .collect()
    })
}

/// A Q.16 coordinate on an axis `extent` pixels long: inside, at either edge (the seam,
/// the pole rows, the last column and row), or anywhere within a period outside.
fn coord(extent: u32) -> impl Strategy<Value = i64> {
    let e = (extent as i64) << 16;
    prop_oneof![
        8 => 0..e.max(1),
        1 => -2 * FX_ONE..2 * FX_ONE,
        1 => e - 2 * FX_ONE..e + 2 * FX_ONE,
        1 => -e..2 * e + 1,
    ]
}

/// A span: start, end (the step is their difference over the length, optionally
/// scaled up: zoomed far out), length 1..=64, and the output slice's offset.
#[derive(Debug, Clone, Copy)]
struct SpanCase {
    u: i64,
    v: i64,
    du: i64,
    dv: i64,
    len: usize,
    off: usize,
}

impl SpanCase {
    fn steps(&self) -> Steps {
        Steps {
            u: self.u,
            v: self.v,
            du: self.du,
            dv: self.dv,
        }
    }
}

fn span_case(w: u32, h: u32) -> impl Strategy<Value = SpanCase> {
    (
        coord(w),
        coord(h),
        coord(w),
        coord(h),
        1usize..=64,
        0usize..8,
        prop_oneof![6 => Just(1i64), 1 => 2i64..64],
    )
        .prop_map(|(u, v, u1, v1, len, off, zoom)| {
            let n = (len as i64 - 1).max(1);
            SpanCase {
                u,
                v,
                du: (u1 - u) / n * zoom,
                dv: (v1 - v) / n * zoom,
                len,
                off,
            }
        })
}

/// Runs `f` on a sentinel-filled buffer holding the output at `c.off`.
fn run(c: &SpanCase, f: impl FnOnce(&mut [u32]) -> bool) -> (bool, Vec<u32>) {
    let mut buf = vec![SENTINEL; c.len + 16];
    let r = f(&mut buf[c.off..c.off + c.len]);
    (r, buf)
}

fn others() -> Vec<Kernel> {
    Kernel::available()
        .into_iter()
        .filter(|&k| k != Kernel::Scalar)
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// Nearest and bilinear: every kernel equals the scalar one, byte for byte, and
    /// refuses exactly the spans it refuses (writing nothing then).
    #[test]
    fn spans_equal_scalar(
        (mi, wraps, cases) in (0..maps().len(), any::<bool>()).prop_flat_map(|(mi, wraps)| {
            let (w, h, _) = &maps()[mi];
            (Just(mi), Just(wraps), prop::collection::vec(span_case(*w, *h), 24))
        })
    ) {
        let (w, h, px) = &maps()[mi];
        let t = Texels::new(px, *w, *h, wraps).unwrap();
        let mut accepted = 0;
        for c in &cases {
            for bilinear in [false, true] {
                let f = |k: Kernel| move |o: &mut [u32]| if bilinear {
                    k.selected().bilinear_span(&t, o, c.steps())
                } else {
                    k.selected().nearest_span(&t, o, c.steps())
                };
                let want = run(c, f(Kernel::Scalar));
                if !want.0 {
                    prop_assert!(want.1.iter().all(|&p| p == SENTINEL));
                } else {
                    accepted += 1;
                }
                for k in others() {
                    let got = run(c, f(k));
                    prop_assert_eq!(&got, &want, "{} bilinear {} {}x{} {:?}", k, bilinear, w, h, c);
                }
            }
        }
        // The generator must exercise the kernels, not only the refusals.
        prop_assert!(accepted > 0 || *w < 2 || *h < 2 || cases.iter().all(|c| c.len > 40));
    }

    /// Batches of spans of one row: every kernel writes what the scalar single-span
    /// kernel writes for each span, and reports exactly the spans it refuses.
    #[test]
    fn batches_equal_single_spans(
        (mi, wraps, cases) in (0..maps().len(), any::<bool>()).prop_flat_map(|(mi, wraps)| {
            let (w, h, _) = &maps()[mi];
            (Just(mi), Just(wraps), prop::collection::vec(span_case(*w, *h), 1..=MAX_JOBS))
        }),
        bilinear in any::<bool>(),
    ) {
        let (w, h, px) = &maps()[mi];
        let t = Texels::new(px, *w, *h, wraps).unwrap();
        // Lay the spans side by side along a row, a gap of `off` pixels before each.
        let mut x = 0u32;
        let jobs: Vec<SpanJob> = cases
            .iter()
            .map(|c| {
                x += c.off as u32;
                let j = SpanJob { x, len: c.len as u32, u: c.u, v: c.v, du: c.du, dv: c.dv };
                x += c.len as u32;
                j
            })
            .collect();
        let mut want = vec![SENTINEL; x as usize + 3];
        let mut want_refused = 0u64;
        for (i, j) in jobs.iter().enumerate() {
            let o = &mut want[j.x as usize..(j.x + j.len) as usize];
            let ok = if bilinear {
                Kernel::Scalar.selected().bilinear_span(&t, o, j.steps())
            } else {
                Kernel::Scalar.selected().nearest_span(&t, o, j.steps())
            };
            if !ok {
                want_refused |= 1 << i;
            }
        }
        for k in Kernel::available() {
            let mut got = vec![SENTINEL; x as usize + 3];
            let refused = if bilinear {
                k.selected().bilinear_spans(&t, &mut got, &jobs)
            } else {
                k.selected().nearest_spans(&t, &mut got, &jobs)
            };
            prop_assert_eq!(refused, want_refused, "{}", k);
            prop_assert_eq!(&got, &want, "{} bilinear {}", k, bilinear);
        }
    }

    /// The scalar span equals the per-pixel samplers (u wrapped per pixel) wherever it
    /// accepts a span; what it refuses the per-pixel path handles.
    #[test]
    fn scalar_span_equals_per_pixel(
        (wh, wraps, cases) in (prop::sample::select(vec![(2u32, 2u32), (5, 3), (64, 32), (300, 150)]), any::<bool>())
            .prop_flat_map(|((w, h), wraps)| (Just((w, h)), Just(wraps), prop::collection::vec(span_case(w, h), 24)))
    ) {
        let (w, h) = wh;
        let px: Vec<u32> = (0..w * h).map(|i| i.wrapping_mul(2_654_435_761) & 0xFF_FFFF).collect();
        let p = if wraps { Projection::Equirect } else { Projection::Elliptical };
        let mut m = EnvMap::from_pixels(w, h, &px, p).unwrap();
        // The kernels clamp a non-wrapping map at its edges (partial maps); the elliptical
        // map's own samplers also keep each row on the sphere (`row_extent`), a path the
        // renderer takes per pixel: compare with the plain clamping sampler.
        m.row_extent.clear();
        let t = texels(&m);
        let wfx = (w as i64) << 16;
        for c in &cases {
            for bilinear in [false, true] {
                let mut out = vec![0u32; c.len];
                let ok = if bilinear {
                    Kernel::Scalar.selected().bilinear_span(&t, &mut out, c.steps())
                } else {
                    Kernel::Scalar.selected().nearest_span(&t, &mut out, c.steps())
                };
                if !ok {
                    continue;
                }
                for (i, o) in out.iter().enumerate() {
                    let u = c.u + c.du * i as i64;
                    let u = if wraps { u.rem_euclid(wfx) } else { u };
                    let v = c.v + c.dv * i as i64;
                    let want = if bilinear { m.bilinear(u, v) } else { m.nearest(u, v) };
                    prop_assert_eq!(*o, want, "pixel {} bilinear {} {:?}", i, bilinear, c);
                }
            }
        }
    }

    /// Trilinear: every kernel equals the scalar one; the scalar one equals the two
    /// levels sampled separately and blended (the second level's position restarting
    /// every 64 pixels), levels resolved as the pyramid resolves them (clamped to the
    /// last level, level 0 for lod ≤ 0, one level when the weight is 0).
    #[test]
    fn trilinear_equals_scalar_and_levels(
        lod in prop_oneof![1 => -300i32..=0, 6 => 1i32..(7 << 8), 1 => (0i32..7).prop_map(|k| k << 8)],
        cases in prop::collection::vec(span_case(128, 64), 16),
        long in 65usize..200,
    ) {
        let m = tri_map();
        let levels = all_levels(m);
        let levels = &levels[..];
        let last = levels.len() - 1;
        let mut cases = cases;
        cases[0].len = long; // beyond one 64-pixel piece
        cases[0].du = (cases[0].du / 4).clamp(-FX_ONE, FX_ONE);
        cases[0].dv = (cases[0].dv / 4).clamp(-FX_ONE / 8, FX_ONE / 8);
        for c in &cases {
            let f = |kk: Kernel| move |o: &mut [u32]| kk.selected().trilinear_span(levels, o, c.steps(), lod);
            let want = run(c, f(Kernel::Scalar));
            for kk in others() {
                let got = run(c, f(kk));
                if want.0 {
                    prop_assert_eq!(&got, &want, "{} lod {} {:?}", kk, lod, c);
                } else {
                    prop_assert!(!got.0, "{} accepted what scalar refused: {:?}", kk, c);
                }
            }
            if !want.0 {
                continue;
            }
            let (ka, kb, frac) = if lod <= 0 {
                (0, 0, 0)
            } else {
                let k = (lod >> 8) as usize;
                (k.min(last), (k + 1).min(last), (lod & 0xFF) as u32)
            };
            let level = |k: usize| if k == 0 { m } else { &m.pyramid()[k - 1] };
            let mut sep = vec![0u32; c.len];
            sample_span::<true>(level(ka), &mut sep, Steps { u: c.u >> ka, v: c.v >> ka, du: c.du >> ka, dv: c.dv >> ka });
            if frac != 0 && ka != kb {
                let (mut u, mut v) = (c.u, c.v);
                for chunk in sep.chunks_mut(TRILINEAR_CHUNK) {
                    let mut s = vec![0u32; chunk.len()];
                    sample_span::<true>(level(kb), &mut s, Steps { u: u >> kb, v: v >> kb, du: c.du >> kb, dv: c.dv >> kb });
                    for (o, q) in chunk.iter_mut().zip(&s) {
                        *o = lerp_px(*o, *q, frac);
                    }
                    u += c.du * chunk.len() as i64;
                    v += c.dv * chunk.len() as i64;
                }
            }
            prop_assert_eq!(&want.1[c.off..c.off + c.len], &sep[..], "lod {} {:?}", lod, c);
        }
    }

    /// Trilinear batches: every kernel writes what the scalar single-span kernel writes
    /// for each span (each with its own level of detail) and refuses the same spans.
    #[test]
    fn trilinear_batches_equal_single_spans(
        cases in prop::collection::vec((span_case(128, 64), -100i32..(7 << 8)), 1..=MAX_JOBS),
    ) {
        let levels = all_levels(tri_map());
        let mut x = 0u32;
        let (jobs, lods): (Vec<SpanJob>, Vec<i32>) = cases
            .iter()
            .map(|(c, lod)| {
                x += c.off as u32;
                let j = SpanJob { x, len: c.len as u32, u: c.u, v: c.v, du: c.du, dv: c.dv };
                x += c.len as u32;
                (j, *lod)
            })
            .unzip();
        for k in Kernel::available() {
            let mut want = vec![SENTINEL; x as usize + 3];
            let mut want_refused = 0u64;
            for (i, (j, &lod)) in jobs.iter().zip(&lods).enumerate() {
                let o = &mut want[j.x as usize..(j.x + j.len) as usize];
                if !k.selected().trilinear_span(&levels, o, j.steps(), lod) {
                    want_refused |= 1 << i;
                    o.fill(SENTINEL); // refused spans may hold partial results
                }
            }
            let mut got = vec![SENTINEL; x as usize + 3];
            let refused = k.selected().trilinear_spans(&levels, &mut got, &jobs, &lods);
            prop_assert_eq!(refused, want_refused, "{}", k);
            for (i, j) in jobs.iter().enumerate() {
                if refused & (1 << i) != 0 {
                    got[j.x as usize..(j.x + j.len) as usize].fill(SENTINEL);
                }
            }
            prop_assert_eq!(&got, &want, "{}", k);
        }
    }

    /// Partial maps: every kernel equals the scalar one, and whatever a kernel accepts
    /// equals the per-pixel cropped samplers (background outside, clamped edges).
    #[test]
    fn cropped_equals_scalar_and_per_pixel(
        (full, cw, ch, left, top) in (prop::sample::select(vec![(64u32, 32u32), (360, 180), (16, 8)]))
            .prop_flat_map(|(fw, fh)| (Just((fw, fh)), 2..=fw, 2..=fh))
            .prop_flat_map(|((fw, fh), cw, ch)| (Just((fw, fh)), Just(cw), Just(ch), 0..fw, 0..=fh - ch)),
        cases in prop::collection::vec(span_case(64, 32), 24),
        scale in 1i64..6,
    ) {
        let (fw, fh) = full;
        let px: Vec<u32> = (0..cw * ch).map(|i| i.wrapping_mul(2_654_435_761) & 0xFF_FFFF).collect();
        let crop = Crop::new(fw, fh, left, top, cw, ch).unwrap();
        let mut m = EnvMap::from_pixels(cw, ch, &px, Projection::Elliptical)
            .unwrap()
            .into_partial(crop)
            .unwrap();
        m.set_background(0x12_3456);
        let t = texels(&m);
        // A crop covering the whole panorama makes a plain map (stored as given).
        let (left, top) = m.crop().map_or((0, 0), |c| (c.left(), c.top()));
        let win = Window { full_width: fw, full_height: fh, left, top, background: 0x12_3456 };
        for c in &cases {
            // Spread the 64×32 positions over the panorama.
            let c = SpanCase { u: c.u * fw as i64 / 64 * scale / 2, v: c.v * fh as i64 / 32, du: c.du * scale / 2, ..*c };
            for bilinear in [false, true] {
                let f = |k: Kernel| move |o: &mut [u32]| if bilinear { k.selected().cropped_span::<true>(&t, &win, o, c.steps()) } else { k.selected().cropped_span::<false>(&t, &win, o, c.steps()) };
                let want = run(&c, f(Kernel::Scalar));
                for k in others() {
                    prop_assert_eq!(&run(&c, f(k)), &want, "{} {:?} {:?}", k, crop, c);
                }
                let mut full = vec![0u32; c.len];
                if bilinear {
                    sample_span_cropped::<true>(&m, &mut full, c.steps());
                } else {
                    sample_span_cropped::<false>(&m, &mut full, c.steps());
                }
                for (i, &got) in full.iter().enumerate() {
                    // u wrapped per pixel, as the renderer does (a crop covering the
                    // whole panorama is a plain map, whose samplers clamp).
                    let u = (c.u + c.du * i as i64).rem_euclid((fw as i64) << 16);
                    let v = c.v + c.dv * i as i64;
                    let px = if bilinear { m.bilinear_cropped(u, v) } else { m.nearest_cropped(u, v) };
                    prop_assert_eq!(got, px, "pixel {} bilinear {} {:?} {:?}", i, bilinear, crop, c);
                    if want.0 {
                        prop_assert_eq!(want.1[c.off + i], px, "kernel pixel {} {:?} {:?}", i, crop, c);
                    }
                }
            }
        }
    }
}

/// A 128×64 map with its pyramid (levels down to 4×2), built once.
fn tri_map() -> &'static EnvMap {
    static MAP: OnceLock<EnvMap> = OnceLock::new();
    MAP.get_or_init(|| {
        let px: Vec<u32> = (0..128 * 64)
            .map(|i: u32| i.wrapping_mul(2_246_822_519) & 0xFF_FFFF)
            .collect();
        EnvMap::from_pixels(128, 64, &px, Projection::Equirect).unwrap()
    })
}

/// The texels of a map and of its pyramid levels.
fn all_levels(m: &EnvMap) -> Vec<Texels<'_>> {
    std::iter::once(texels(m))
        .chain(m.pyramid().iter().map(texels))
        .collect()
}

/// The widest map: Q.16 positions past 2³¹ (32-bit lanes hold span-local offsets), and
/// steps too long for them (the scalar kernel then runs).
#[test]
fn widest_map_spans() {
    let (w, h, px) = maps().iter().find(|m| m.0 == 65536).unwrap();
    let t = Texels::new(px, *w, *h, true).unwrap();
    let wfx = (*w as i64) << 16;
    for &(u, du, len) in &[
        (wfx - 40 * FX_ONE, 3 * FX_ONE / 7, 64usize),
        (wfx - FX_ONE / 3, -FX_ONE, 64),
        (3 * FX_ONE, 1000 * FX_ONE + 17, 64),
        (FX_ONE, 60_000 * FX_ONE / 63, 64),
        (wfx - FX_ONE, -(wfx - 2 * FX_ONE) / 63, 64),
        (FX_ONE, 40_000 * FX_ONE, 2),
    ] {
        for k in Kernel::available() {
            for bilinear in [false, true] {
                let c = SpanCase {
                    u,
                    v: FX_ONE + 5,
                    du,
                    dv: 77,
                    len,
                    off: 3,
                };
                let f = |k: Kernel| {
                    move |o: &mut [u32]| {
                        if bilinear {
                            k.selected().bilinear_span(&t, o, c.steps())
                        } else {
                            k.selected().nearest_span(&t, o, c.steps())
                        }
                    }
                };
                let want = run(&c, f(Kernel::Scalar));
                assert!(want.0, "{c:?} should be inside");
                assert_eq!(run(&c, f(k)), want, "{k} bilinear {bilinear} {c:?}");
            }
        }
    }
}

#[test]
fn names_parse_and_selection() {
    for &k in Kernel::ALL {
        let p = parse_kernel(&k.name().to_uppercase());
        if k.is_supported() {
            assert_eq!(p, Ok(Some(k)));
        } else {
            assert!(matches!(p, Err(KernelError::Unsupported { kernel, .. }) if kernel == k));
        }
    }
    assert_eq!(parse_kernel(" auto "), Ok(None));
    let e = parse_kernel("avx3").unwrap_err();
    assert!(e.to_string().contains("avx3") && e.to_string().contains(KERNEL_ENV));
    assert!(Kernel::Scalar.is_supported());
    assert!(Kernel::best().is_supported());
    assert_eq!(Kernel::available().first(), Some(&Kernel::Scalar));
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        let avx512 = ["avx512f", "avx512bw", "avx512vl", "avx512dq"]
            .iter()
            .all(|f| cpu_features().contains(f));
        let best = if avx512 { Kernel::Avx512 } else { Kernel::Avx2 };
        assert_eq!(Kernel::best(), best);
        assert!(cpu_features().contains(&"avx2"));
    }
    let info = kernel_info();
    assert!(info.active.is_supported());
    assert!(info
        .to_string()
        .starts_with(&format!("kernel {}", info.active)));
}

/// Spans (u, v, du, dv) of a 64×32 map: inside, across the seam, off the edges; the last
/// one stands still on the last pixel.
const PER_PIXEL_SPANS: [(f64, f64, f64, f64); 6] = [
    (3.3, 4.2, 0.7, 0.1),
    (60.0, 10.0, 0.5, 0.0),
    (-2.0, 31.5, 0.25, 0.02),
    (10.0, 0.1, -0.3, -0.01),
    (0.2, 16.0, 1.9, 0.4),
    (63.99, 31.99, 0.0, 0.0),
];

/// The span kernels against the per-pixel samplers, inside the map, across the seam
/// and off its edges (the slow path), for a wrapping and a clamping projection.
#[test]
fn spans_equal_per_pixel_samples() {
    for proj in [Projection::Equirect, Projection::Elliptical] {
        let m = grid_map(64, 32, proj).unwrap();
        let wfx = 64i64 << FX_BITS;
        for &(u, v, du, dv) in &PER_PIXEL_SPANS[..5] {
            let (u, v, du, dv) = (to_fx(u), to_fx(v), to_fx(du), to_fx(dv));
            let mut nb = vec![0u32; 40];
            let mut nn = vec![0u32; 40];
            sample_span::<true>(&m, &mut nb, Steps { u, v, du, dv });
            sample_span::<false>(&m, &mut nn, Steps { u, v, du, dv });
            for i in 0..40 {
                let uu = u + du * i as i64;
                let uu = if proj.wraps() { uu.rem_euclid(wfx) } else { uu };
                let vv = v + dv * i as i64;
                assert_eq!(nb[i], m.bilinear(uu, vv), "{proj} bilinear pixel {i}");
                assert_eq!(nn[i], m.nearest(uu, vv), "{proj} nearest pixel {i}");
            }
        }
    }
}

#[test]
fn span_equals_per_pixel() {
    let m = crate::map::synth::grid_map(256, 128, Projection::Equirect).unwrap();
    for lod in [0, 100, 256, 300, 700, 5000] {
        let (u, v, du, dv) = (to_fx(250.3), to_fx(40.2), to_fx(1.7), to_fx(-0.4));
        let mut out = vec![0u32; 100];
        trilinear_span(&m, &mut out, Steps { u, v, du, dv }, lod);
        for (i, o) in out.iter().enumerate() {
            let uu = (u + du * i as i64).rem_euclid(256 << FX_BITS);
            let vv = v + dv * i as i64;
            // The span steps each level by du >> k (truncated): up to i/65536 px
            // off after i pixels, which can move an 8-bit weight by one step.
            let want = m.trilinear(uu, vv, lod);
            for s in [0, 8, 16] {
                let (a, b) = ((o >> s) & 0xFF, (want >> s) & 0xFF);
                assert!(
                    a.abs_diff(b) <= 2,
                    "lod {lod} pixel {i}: {o:06x} vs {want:06x}"
                );
            }
        }
    }
}

/// The renderer's short nearest spans, sampled without the batch
/// (`nearest_span_direct`), equal the per-pixel sampler and the batch path, inside the
/// map, across the seam, off its edges (the per-pixel fallback) and on maps whose rows
/// wrap within their length (no texels: per pixel).
#[test]
fn direct_nearest_spans_equal_per_pixel_samples() {
    for proj in [Projection::Equirect, Projection::Elliptical] {
        let m = grid_map(64, 32, proj).unwrap();
        let t = (!proj.scaled_rows()).then(|| texels(&m));
        let wfx = 64i64 << FX_BITS;
        for &(u, v, du, dv) in &PER_PIXEL_SPANS {
            let (u, v, du, dv) = (to_fx(u), to_fx(v), to_fx(du), to_fx(dv));
            for len in [1usize, 2, 7, 8, 9, 40] {
                let mut direct = vec![0u32; len];
                let mut batch = vec![0u32; len];
                nearest_span_direct(&m, t.as_ref(), &mut direct, Steps { u, v, du, dv });
                let job = SpanJob {
                    x: 0,
                    len: len as u32,
                    u,
                    v,
                    du,
                    dv,
                };
                sample_spans::<false>(&m, &mut batch, &[job]);
                assert_eq!(direct, batch, "{proj} len {len}");
                for (i, &d) in direct.iter().enumerate() {
                    let uu = u + du * i as i64;
                    let uu = if proj.wraps() { uu.rem_euclid(wfx) } else { uu };
                    assert_eq!(d, m.nearest(uu, v + dv * i as i64), "{proj} pixel {i}");
                }
            }
        }
    }
}

/// `LUTPANO_KERNEL` picks the active kernel (no test calls `set_kernel`): run the kernel
/// tests with `LUTPANO_KERNEL=avx2` (or `scalar`, `avx512`) and the renderer uses it.
#[test]
fn env_chooses_the_active_kernel() {
    let info = kernel_info();
    match kernel_from_env() {
        Ok(Some(k)) => {
            assert_eq!(info.active, k);
            assert_eq!(info.source, KernelSource::Env);
        }
        _ => assert_eq!(info.active, Kernel::best()),
    }
}

/// A table value: anywhere in `i32` (the extremes included), or small.
fn node_value() -> impl Strategy<Value = i32> {
    prop_oneof![
        4 => any::<i32>(),
        2 => -70_000..70_000i32,
        1 => Just(i32::MIN),
        1 => Just(i32::MAX),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// The node blend: every kernel writes what `Band::blend_nodes` (the scalar twin)
    /// writes, for runs of 0 to 40 nodes from any offset, weights 0 to 1 (Q.16) and any
    /// `i32` values, and nothing past the run.
    #[test]
    fn node_blend_equals_scalar(
        rows in prop::collection::vec(((node_value(), node_value()), (node_value(), node_value())), 2..48),
        wa in prop_oneof![3 => 0..=65536i64, 1 => Just(0i64), 1 => Just(65536i64), 1 => Just(32768i64)],
        (k0, n) in (0..4usize, 0..=40usize),
    ) {
        let top: Vec<[i32; 2]> = rows.iter().map(|r| [r.0 .0, r.0 .1]).collect();
        let bot: Vec<[i32; 2]> = rows.iter().map(|r| [r.1 .0, r.1 .1]).collect();
        let band = crate::lut::Band::from_rows(&top, &bot, wa);
        let k0 = k0.min(top.len());
        let n = n.min(top.len() - k0);
        let mut want = vec![[7i32, 7]; n + 3];
        band.blend_nodes(k0, &mut want[..n]);
        for k in Kernel::available() {
            let mut got = vec![[7i32, 7]; n + 3];
            k.selected().blend_nodes(&band, k0, &mut got[..n]);
            prop_assert_eq!(&got, &want, "{} k0 {} n {} wa {}", k, k0, n, wa);
        }
    }
}

/// A shading table of random bytes: the shading kernels only look entries up, so any
/// table tells whether they read the right entry.
fn shade_table() -> ShadeTable<'static> {
    static T: OnceLock<Vec<u8>> = OnceLock::new();
    let bytes = T.get_or_init(|| {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        (0..ShadeTable::LEN)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x >> 24) as u8
            })
            .collect()
    });
    ShadeTable::new(bytes).expect("a table's length")
}

/// Illuminances: any `f32` (negatives, NaN, infinities, subnormals), values over the
/// table's range, and smooth rows (a constant or a slow ramp: runs of 16 pixels on one
/// table row, the AVX-512 form's byte-permute path, and on two or more).
fn lux_row() -> impl Strategy<Value = Vec<f32>> {
    let value = prop_oneof![
        4 => (-20.0f32..20.0).prop_map(|e| 300.0 * 2f32.powf(e)),
        2 => any::<f32>(),
        1 => Just(0.0f32),
    ];
    prop_oneof![
        2 => prop::collection::vec(value, 0..100),
        1 => (0.0f32..5000.0, 0usize..100).prop_map(|(e, n)| vec![e; n]),
        1 => (1.0f32..5000.0, -1e-2f32..1e-2, 0usize..100)
            .prop_map(|(e, s, n)| (0..n).map(|i| e * (1.0 + s * i as f32)).collect()),
    ]
}

/// A light factor's `ambient` or `exposure`: any `f32` but NaN (which no caller passes:
/// with NaN on both sides of a product the NaN's sign, and so the row, would depend on
/// the operand order the compiler picks), typical values, and 0.
fn light_term() -> impl Strategy<Value = f32> {
    prop_oneof![
        2 => 0.0f32..2.0,
        1 => 1e-5f32..0.1,
        1 => Just(0.0f32),
        1 => any::<f32>().prop_filter("not NaN", |x| !x.is_nan()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    /// The shading rows: every kernel the CPU runs writes the scalar kernel's bytes
    /// (pixels with any top byte, which must not leak through; illuminances as
    /// [`lux_row`], rows of 0 to 99 pixels from an odd offset, so every form's tail runs;
    /// pixels past the illuminances left as they were).
    #[test]
    fn shade_rows_equal_scalar(
        pixels in prop::collection::vec(any::<u32>(), 0..104),
        lux in lux_row(),
        ambient in light_term(),
        exposure in light_term(),
        off in 0usize..4,
    ) {
        let t = shade_table();
        let l = Light { ambient, exposure };
        let off = off.min(pixels.len());
        let mut want = pixels.clone();
        Kernel::Scalar.selected().shade_row(t, &mut want[off..], &lux, l);
        for k in Kernel::available() {
            let mut got = pixels.clone();
            k.selected().shade_row(t, &mut got[off..], &lux, l);
            prop_assert_eq!(&got, &want, "{} {:?}", k, l);
        }
    }
}

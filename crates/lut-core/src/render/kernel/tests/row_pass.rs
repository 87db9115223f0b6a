//! The row pass's kernels (`row.rs`, `x86/row.rs`): positions expanded from spans,
//! nearest and bilinear rows, pyramid levels written and blended: every kernel the CPU
//! runs against the scalar twin, and the scalar twin against `EnvMap`'s samplers.

use super::*;
use crate::render::kernel::row::SpanQ8;

/// Q.8 positions as the row pass hands them to the row kernels (`row.rs`): u within W − 1
/// pixels of the map (mostly inside, at the seam, or a period off), v anywhere from a
/// map height above the top to one below the bottom (the pole rows), 1..=64 pixels
/// written at an offset 0..8 of a sentinel-filled buffer. Half the cases have every
/// position inside the map, so that whole vectors take the kernels' inside-the-map path
/// (`x86/row.rs`, `within`), and the others mostly mix lanes inside and outside.
#[derive(Debug, Clone)]
struct RowCase {
    u: Vec<i32>,
    v: Vec<i32>,
    off: usize,
}

fn row_case(w: u32, h: u32) -> impl Strategy<Value = RowCase> {
    let (wq, hq) = ((w as i32) << 8, (h as i32) << 8);
    let inside = (1usize..=64, 0usize..8).prop_flat_map(move |(n, off)| {
        (
            prop::collection::vec(0..wq, n),
            prop::collection::vec(0..hq, n),
            Just(off),
        )
            .prop_map(|(u, v, off)| RowCase { u, v, off })
    });
    prop_oneof![mixed_case(w, h), inside]
}

/// [`row_case`]'s positions inside and outside the map.
fn mixed_case(w: u32, h: u32) -> impl Strategy<Value = RowCase> {
    let (wq, hq) = ((w as i32) << 8, (h as i32) << 8);
    (1usize..=64, 0usize..8).prop_flat_map(move |(n, off)| {
        // Within W − 1 pixels of the map (a span travels less than that from [0, W)).
        let (lo, hi) = (256 - wq, 2 * wq - 256);
        let u = prop_oneof![
            6 => 0..wq,
            1 => (-256).max(lo)..256,
            1 => wq - 256..(wq + 256).min(hi),
            1 => lo..hi,
        ];
        let v = prop_oneof![
            6 => 0..hq,
            1 => -512..512,
            1 => hq - 512..hq + 512,
            1 => -hq..2 * hq,
        ];
        (
            prop::collection::vec(u, n),
            prop::collection::vec(v, n),
            Just(off),
        )
            .prop_map(|(u, v, off)| RowCase { u, v, off })
    })
}

/// The row kernel `k` on case `c`, written into a sentinel-filled buffer.
fn run_row<const B: bool, const M: bool>(k: Kernel, t: &Texels, c: &RowCase) -> Vec<u32> {
    let n = c.u.len();
    let mut buf = vec![SENTINEL; n + 16];
    let out = &mut buf[c.off..c.off + n];
    k.selected().sample_q8::<B, M>(t, &c.u, &c.v, out);
    buf
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The row kernels (nearest, bilinear; in order and reversed for the left half):
    /// every kernel writes the scalar one's pixels, and only its pixels (the sentinels
    /// around stay).
    #[test]
    fn row_kernels_equal_scalar(
        (mi, cases) in (0..maps().len()).prop_flat_map(|mi| {
            let (w, h, _) = &maps()[mi];
            (Just(mi), prop::collection::vec(row_case(*w, *h), 12))
        })
    ) {
        let (w, h, px) = &maps()[mi];
        let t = Texels::new(px, *w, *h, true).unwrap();
        for c in &cases {
            let want = [
                run_row::<false, false>(Kernel::Scalar, &t, c),
                run_row::<false, true>(Kernel::Scalar, &t, c),
                run_row::<true, false>(Kernel::Scalar, &t, c),
                run_row::<true, true>(Kernel::Scalar, &t, c),
            ];
            for w in &want {
                let n = c.u.len();
                prop_assert!(w[..c.off].iter().chain(&w[c.off + n..]).all(|&p| p == SENTINEL));
            }
            for k in others() {
                let got = [
                    run_row::<false, false>(k, &t, c),
                    run_row::<false, true>(k, &t, c),
                    run_row::<true, false>(k, &t, c),
                    run_row::<true, true>(k, &t, c),
                ];
                prop_assert_eq!(&got, &want, "{} {}x{} {:?}", k, w, h, c);
            }
        }
    }

    /// The scalar row kernel equals the per-pixel samplers at the Q.8 position, u
    /// wrapped into the map (reversed: pixel n − 1 − j at position j).
    #[test]
    fn row_scalar_equals_per_pixel(
        (wh, cases) in prop::sample::select(vec![(2u32, 2u32), (5, 3), (64, 32), (300, 150)])
            .prop_flat_map(|(w, h)| (Just((w, h)), prop::collection::vec(row_case(w, h), 12)))
    ) {
        let (w, h) = wh;
        let px: Vec<u32> = (0..w * h).map(|i| i.wrapping_mul(2_654_435_761) & 0xFF_FFFF).collect();
        let m = EnvMap::from_pixels(w, h, &px, Projection::Equirect).unwrap();
        let t = texels(&m);
        let wfx = (w as i64) << 16;
        for c in &cases {
            let n = c.u.len();
            for (b, rev) in [(false, false), (false, true), (true, false), (true, true)] {
                let out = match (b, rev) {
                    (false, false) => run_row::<false, false>(Kernel::Scalar, &t, c),
                    (false, true) => run_row::<false, true>(Kernel::Scalar, &t, c),
                    (true, false) => run_row::<true, false>(Kernel::Scalar, &t, c),
                    (true, true) => run_row::<true, true>(Kernel::Scalar, &t, c),
                };
                for j in 0..n {
                    let at = if rev { n - 1 - j } else { j };
                    let u = ((c.u[j] as i64) << 8).rem_euclid(wfx);
                    let v = (c.v[j] as i64) << 8;
                    let want = if b { m.bilinear(u, v) } else { m.nearest(u, v) };
                    prop_assert_eq!(out[c.off + at], want, "pixel {} bilinear {} reversed {} {:?}", j, b, rev, c);
                }
            }
        }
    }

    /// The positions kernel: every kernel writes what the scalar one writes over a run
    /// of consecutive spans of 1..=64 pixels (what a SIMD kernel writes past a span the
    /// next one overwrites; past the run it is not compared), and the scalar one the
    /// floored Q.8 positions of the spans' Q.16 lines.
    #[test]
    fn expand_equals_scalar(
        spans in prop::collection::vec(
            (1u32..=64, -(1i32 << 22)..(1 << 22), (0i32..256, 0i32..256, 0i32..256),
             -(1i32 << 22)..(1 << 22), -(1i32 << 22)..(1 << 22), -(1i32 << 22)..(1 << 22)),
            1..40,
        )
    ) {
        let mut k = 0u32;
        let spans: Vec<SpanQ8> = spans
            .into_iter()
            .map(|(m, hu, (lu, lv, ll), du, hv, dv)| {
                let s = SpanQ8 { k, m, hu, lu, du, hv, lv, dv, hl: hu ^ 0x5555, ll };
                k += m;
                s
            })
            .collect();
        let room = k as usize + 16;
        // With the mirror line (`ul`) or without it (an empty `ul`, left alone).
        let run = |kern: Kernel, mirror: bool| {
            let mut b = [vec![0i32; room], vec![0i32; room], vec![0i32; room]];
            let [u, v, ul] = &mut b;
            if mirror {
                kern.selected().expand::<true>(&spans, row::Positions { u, v, ul });
            } else {
                kern.selected().expand::<false>(&spans, row::Positions { u, v, ul: &mut [] });
            }
            b.map(|mut x| {
                x.truncate(k as usize);
                x
            })
        };
        let want = run(Kernel::Scalar, true);
        let plain = run(Kernel::Scalar, false);
        prop_assert_eq!(&plain[..2], &want[..2]);
        prop_assert!(plain[2].iter().all(|&x| x == 0));
        for s in &spans {
            for j in 0..s.m as i64 {
                let q = |h: i32, l: i32, d: i32| (((h as i64) << 8) + l as i64 + j * d as i64) >> 8;
                let i = s.k as usize + j as usize;
                prop_assert_eq!(want[0][i] as i64, q(s.hu, s.lu, s.du));
                prop_assert_eq!(want[1][i] as i64, q(s.hv, s.lv, s.dv));
                prop_assert_eq!(want[2][i] as i64, q(s.hl, s.ll, -s.du));
            }
        }
        for kern in others() {
            prop_assert_eq!(&run(kern, true), &want, "{}", kern);
            prop_assert_eq!(&run(kern, false), &plain, "{} without the mirror line", kern);
        }
    }
}

/// The trilinear row kernel `k` (`row::sample_lv_with` on a level, blended with `BLEND`)
/// on case `c` (level-0 positions, the level `lv`), written into `base` (the pixels it
/// blends into) inside a sentinel-filled buffer.
fn run_level<const M: bool, const BLEND: bool>(
    k: Kernel,
    t: &Texels,
    c: &RowCase,
    lv: &row::Level,
    base: &[u32],
) -> Vec<u32> {
    let n = c.u.len();
    let mut buf = vec![SENTINEL; n + 16];
    buf[c.off..c.off + n].copy_from_slice(&base[..n]);
    let out = &mut buf[c.off..c.off + n];
    k.selected()
        .sample_lv::<true, M, true, BLEND>(t, &c.u, &c.v, out, lv);
    buf
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The trilinear row kernels (a pyramid level's bilinear samples at level-0
    /// positions, written or blended in by per-position weights; in order and reversed):
    /// every kernel writes the scalar one's pixels, and only its pixels. The level is
    /// 0..=5 below the level-0 map (the test map's sides times 2^k: the level-0 positions
    /// wrap by that width first), the weights 0..=255.
    #[test]
    fn level_kernels_equal_scalar(
        (mi, lk, cases) in (0..maps().len() - 2, 0u32..=5).prop_flat_map(|(mi, lk)| {
            let (w, h, _) = &maps()[mi];
            let case = (row_case(*w << lk, *h << lk), prop::collection::vec(0u32..256, 64),
                prop::collection::vec(any::<u32>(), 64));
            (Just(mi), Just(lk), prop::collection::vec(case, 12))
        })
    ) {
        let (w, h, px) = &maps()[mi];
        let t = Texels::new(px, *w, *h, true).unwrap();
        let wq = ((*w as i32) << lk) << 8;
        for (c, wts, base) in &cases {
            let base: Vec<u32> = base.iter().map(|p| p & 0xFF_FFFF).collect();
            let a = &row::Level { k: lk, wq, w: wts };
            let want = [
                run_level::<false, false>(Kernel::Scalar, &t, c, a, &base),
                run_level::<true, false>(Kernel::Scalar, &t, c, a, &base),
                run_level::<false, true>(Kernel::Scalar, &t, c, a, &base),
                run_level::<true, true>(Kernel::Scalar, &t, c, a, &base),
            ];
            let n = c.u.len();
            for x in &want {
                prop_assert!(x[..c.off].iter().chain(&x[c.off + n..]).all(|&p| p == SENTINEL));
            }
            for k in others() {
                let got = [
                    run_level::<false, false>(k, &t, c, a, &base),
                    run_level::<true, false>(k, &t, c, a, &base),
                    run_level::<false, true>(k, &t, c, a, &base),
                    run_level::<true, true>(k, &t, c, a, &base),
                ];
                prop_assert_eq!(&got, &want, "{} {}x{} level {} {:?}", k, w, h, lk, c);
            }
        }
    }

    /// The scalar trilinear row kernel equals `EnvMap::trilinear` per pixel: level ka
    /// written, level ka + 1 blended in by the level of detail's weight (none on the
    /// last level), at the Q.8 position with u wrapped into the map; maps with odd
    /// sides on some levels (300×150: 75, 38, 19, …) included.
    #[test]
    fn level_scalar_equals_trilinear(
        (wh, lod, cases) in prop::sample::select(vec![(4u32, 2u32), (64, 32), (300, 150), (96, 40)])
            .prop_flat_map(|(w, h)| (Just((w, h)), 0i32..12 * 256,
                prop::collection::vec(row_case(w, h), 8)))
    ) {
        let (w, h) = wh;
        let px: Vec<u32> = (0..w * h).map(|i| i.wrapping_mul(2_654_435_761) & 0xFF_FFFF).collect();
        let m = EnvMap::from_pixels(w, h, &px, Projection::Equirect).unwrap();
        let levels = level_texels(&m);
        let last = levels.len() - 1;
        let (ka, frac) = (((lod >> 8) as usize).min(last), (lod & 0xFF) as u32);
        let wq = (w as i32) << 8;
        let wts = [frac; 64];
        let wfx = (w as i64) << 16;
        for c in &cases {
            let n = c.u.len();
            for rev in [false, true] {
                let mut out = vec![0u32; n];
                let a = row::Level { k: ka as u32, wq, w: &[] };
                let b = row::Level { k: ka as u32 + 1, wq, w: &wts };
                let s = Kernel::Scalar.selected();
                if rev {
                    s.sample_lv::<true, true, true, false>(&levels[ka], &c.u, &c.v, &mut out, &a);
                } else {
                    s.sample_lv::<true, false, true, false>(&levels[ka], &c.u, &c.v, &mut out, &a);
                }
                if ka < last {
                    let t = &levels[ka + 1];
                    if rev {
                        s.sample_lv::<true, true, true, true>(t, &c.u, &c.v, &mut out, &b);
                    } else {
                        s.sample_lv::<true, false, true, true>(t, &c.u, &c.v, &mut out, &b);
                    }
                }
                for j in 0..n {
                    let at = if rev { n - 1 - j } else { j };
                    let u = ((c.u[j] as i64) << 8).rem_euclid(wfx);
                    let v = (c.v[j] as i64) << 8;
                    prop_assert_eq!(out[at], m.trilinear(u, v, lod), "pixel {} lod {} reversed {} {:?}", j, lod, rev, c);
                }
            }
        }
    }
}

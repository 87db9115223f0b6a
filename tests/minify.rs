//! Minification anti-aliasing: zoomed out on a map with fine detail, the trilinear
//! sampler (pyramid, see `lut_core::pyramid`) must be measurably closer than bilinear to
//! the exact render supersampled 8×8 per pixel (the truth for a box-filtered pixel), for
//! the LUT renderer and the exact renderer alike, and must not hurt when magnifying.

use lut_core::Frame;
use lut_core::{
    render_exact, render_exact_supersampled, EnvMap, Projection, RenderOptions, Renderer,
    RendererKind, Sampler, View,
};
use test_support::pixels::psnr;
use test_support::render::render_frame;

/// A map that aliases when minified: 3-pixel black/white checks (not a power of two, so
/// the pyramid levels do not average them away exactly) over a colour ramp.
fn fine_map(w: u32, h: u32) -> EnvMap {
    let px: Vec<u32> = (0..h)
        .flat_map(|y| {
            (0..w).map(move |x| {
                if (x / 3 + y / 3) % 2 == 0 {
                    0xF0F0F0
                } else {
                    ((x * 255 / w) << 16) | ((y * 255 / h) << 8) | 0x20
                }
            })
        })
        .collect();
    EnvMap::from_pixels(w, h, &px, Projection::Equirect).unwrap()
}

fn lut(map: &EnvMap, view: View, sampler: Sampler, w: u32, h: u32) -> Vec<u32> {
    let opts = RenderOptions {
        sampler,
        ..RenderOptions::default()
    };
    render_frame(&mut Renderer::new(map), map, view, &opts, w, h).0
}

/// The exact render supersampled 8×8 per pixel (bilinear sub-samples, box filter).
fn truth(map: &EnvMap, view: View, w: u32, h: u32) -> Vec<u32> {
    let mut truth = vec![0u32; (w * h) as usize];
    render_exact_supersampled(
        map,
        view,
        Sampler::Bilinear,
        8,
        &mut Frame::new(&mut truth, w, h).unwrap(),
        true,
    );
    truth
}

#[test]
fn trilinear_is_closer_to_the_supersampled_truth_when_zoomed_out() {
    let map = fine_map(2048, 1024);
    let (w, h) = (200, 120);
    for (yaw, pitch, hfov) in [
        (0.0, 0.0, 120.0),
        (179.0, 30.0, 150.0),
        (-60.0, -70.0, 130.0),
        (90.0, 89.0, 100.0),
    ] {
        let view = View::new(yaw, pitch, hfov).unwrap();
        let truth = truth(&map, view, w, h);
        let bi = lut(&map, view, Sampler::Bilinear, w, h);
        let tri = lut(&map, view, Sampler::Trilinear, w, h);
        let mut tri_exact = vec![0u32; (w * h) as usize];
        render_exact(
            &map,
            view,
            Sampler::Trilinear,
            &mut Frame::new(&mut tri_exact, w, h).unwrap(),
            true,
        );
        let (pb, pt, pe) = (
            psnr(&bi, &truth),
            psnr(&tri, &truth),
            psnr(&tri_exact, &truth),
        );
        eprintln!(
            "view ({yaw}, {pitch}, {hfov}): PSNR vs 8x8 truth: bilinear {pb:.1} dB, \
             trilinear LUT {pt:.1} dB, trilinear exact {pe:.1} dB"
        );
        assert!(
            pt >= pb + 3.0,
            "view ({yaw}, {pitch}, {hfov}): trilinear {pt:.1} dB not 3 dB above bilinear {pb:.1} dB"
        );
        // The LUT's footprint (span step + scanline spacing) against the exact per-pixel
        // footprint: within 0.5 dB of each other.
        assert!(
            (pt - pe).abs() <= 0.5,
            "view ({yaw}, {pitch}, {hfov}): LUT trilinear {pt:.1} dB vs exact trilinear {pe:.1} dB"
        );
    }
}

#[test]
fn trilinear_is_bilinear_when_magnifying() {
    let map = fine_map(512, 256);
    let (w, h) = (160, 120);
    // hfov 20 on a 512-wide map: ~0.18 map pixels per screen pixel, level 0 everywhere.
    let view = View::new(33.0, 12.0, 20.0).unwrap();
    assert_eq!(
        lut(&map, view, Sampler::Trilinear, w, h),
        lut(&map, view, Sampler::Bilinear, w, h)
    );
}

/// `Renderer::set_bilinear_level`: a bilinear frame reads one pyramid level for the
/// whole frame, the level nearest to the footprint at the view's centre (2^k nearest to
/// it), drawn as a plain bilinear frame of that level; magnified views are plain bilinear.
#[test]
fn bilinear_level_reads_the_matching_level() {
    let map = fine_map(2048, 1024);
    let opts = RenderOptions {
        sampler: Sampler::Bilinear,
        ..RenderOptions::default()
    };
    let level_frame = |map: &EnvMap, view: View, w: u32, h: u32| {
        let mut r = Renderer::new(map);
        r.set_bilinear_level(true);
        assert!(r.bilinear_level());
        render_frame(&mut r, map, view, &opts, w, h).0
    };
    // Magnified: level 0, identical bytes.
    let view = View::new(33.0, 12.0, 20.0).unwrap();
    assert_eq!(
        level_frame(&map, view, 160, 120),
        lut(&map, view, Sampler::Bilinear, 160, 120)
    );
    // Zoomed out: hfov 90 over 64 columns of a 2048-wide map is 10.2 map pixels per
    // screen pixel at the centre (log2 3.35): level 3, the whole frame, byte for byte
    // the bilinear frame of level 3 (256x128) drawn as a map of its own.
    let (w, h) = (64, 48);
    let view = View::new(10.0, 0.0, 90.0).unwrap();
    let got = level_frame(&map, view, w, h);
    let level3 = &map.pyramid()[2];
    assert_eq!((level3.width(), level3.height()), (256, 128));
    assert_eq!(got, lut(level3, view, Sampler::Bilinear, w, h));
    // ... which is closer to the supersampled truth than bilinear on the map.
    let bi = lut(&map, view, Sampler::Bilinear, w, h);
    let truth = truth(&map, view, w, h);
    let (pl, pb) = (psnr(&got, &truth), psnr(&bi, &truth));
    assert!(pl >= pb + 3.0, "level {pl:.1} dB vs bilinear {pb:.1} dB");
    // Twice the columns: footprint 5.1 (log2 2.35), level 2.
    let got = level_frame(&map, view, 2 * w, 2 * h);
    assert_eq!(
        got,
        lut(&map.pyramid()[1], view, Sampler::Bilinear, 2 * w, 2 * h)
    );
    // The same renderer draws the still (plain) frame and the level frame in turn, each
    // as a renderer of its own would.
    let mut r = Renderer::new(&map);
    for on in [true, false, true] {
        r.set_bilinear_level(on);
        let f = render_frame(&mut r, &map, view, &opts, w, h).0;
        let want = if on {
            lut(level3, view, Sampler::Bilinear, w, h)
        } else {
            lut(&map, view, Sampler::Bilinear, w, h)
        };
        assert!(f == want, "bilinear_level {on}");
    }
    // With a band hook (`render_with`, the lit frames): the same pixels, every row
    // handed to the hook once.
    let rows = std::sync::atomic::AtomicUsize::new(0);
    let hook = |_y0: usize, band: &mut [u32]| {
        rows.fetch_add(
            band.len() / w as usize,
            std::sync::atomic::Ordering::Relaxed,
        );
    };
    let mut px = vec![0u32; (w * h) as usize];
    r.set_bilinear_level(true);
    r.render_with(
        &map,
        view,
        &opts,
        &mut Frame::new(&mut px, w, h).unwrap(),
        &hook,
    )
    .unwrap();
    assert!(px == lut(level3, view, Sampler::Bilinear, w, h));
    assert_eq!(rows.into_inner(), h as usize);
    // Trilinear and nearest ignore the switch.
    for s in [Sampler::Trilinear, Sampler::Nearest] {
        let o = RenderOptions {
            sampler: s,
            ..RenderOptions::default()
        };
        r.set_bilinear_level(true);
        let f = render_frame(&mut r, &map, view, &o, w, h).0;
        assert!(f == lut(&map, view, s, w, h), "{s:?}");
    }
}

/// `Renderer::set_still_level` (the window's still frames): a bilinear or trilinear
/// frame is drawn from the deepest pyramid level on which no pixel is magnified by more
/// than √2, the level 2^k nearest to the frame's smallest footprint, as a plain frame of
/// that level; views that are not zoomed out are drawn from the map, byte for byte. The
/// exact renderer draws the same level.
#[test]
fn still_level_reads_the_level_no_pixel_is_magnified_on() {
    let map = fine_map(2048, 1024);
    let opts = |renderer| RenderOptions {
        sampler: Sampler::Bilinear,
        renderer,
        ..RenderOptions::default()
    };
    let still = |view: View, w: u32, h: u32, renderer| {
        let mut r = Renderer::new(&map);
        assert!(!r.still_level(), "off by default");
        r.set_still_level(true);
        render_frame(&mut r, &map, view, &opts(renderer), w, h).0
    };
    // Magnified (hfov 20 over 160 columns: 0.2 map pixels per screen pixel): the map.
    let view = View::new(33.0, 12.0, 20.0).unwrap();
    assert_eq!(
        still(view, 160, 120, RendererKind::Lut),
        lut(&map, view, Sampler::Bilinear, 160, 120)
    );
    // hfov 90 over 48 columns: 13.6 map pixels per screen pixel at the centre, 7.5 at
    // the frame's corners (log2 2.91): level 3 (256x128), where the corners read 0.94
    // level texels per pixel. (The moving frame's rule, the centre, would take level 4.)
    let (w, h) = (48, 36);
    let view = View::new(10.0, 0.0, 90.0).unwrap();
    let level3 = &map.pyramid()[2];
    assert_eq!((level3.width(), level3.height()), (256, 128));
    let got = still(view, w, h, RendererKind::Lut);
    assert!(got == lut(level3, view, Sampler::Bilinear, w, h));
    assert!(got != lut(&map.pyramid()[3], view, Sampler::Bilinear, w, h));
    // Closer to the supersampled truth than bilinear on the map, and not further from
    // it than trilinear by more than 1 dB.
    let truth = truth(&map, view, w, h);
    let (pl, pb, pt) = (
        psnr(&got, &truth),
        psnr(&lut(&map, view, Sampler::Bilinear, w, h), &truth),
        psnr(&lut(&map, view, Sampler::Trilinear, w, h), &truth),
    );
    assert!(
        pl >= pb + 3.0 && pl >= pt - 1.0,
        "level {pl:.1} dB, bilinear {pb:.1}, trilinear {pt:.1}"
    );
    // The exact renderer draws the same level: exact bilinear of level 3.
    let mut ex = vec![0u32; (w * h) as usize];
    render_exact(
        level3,
        view,
        Sampler::Bilinear,
        &mut Frame::new(&mut ex, w, h).unwrap(),
        true,
    );
    assert!(still(view, w, h, RendererKind::Exact) == ex);
    // Looking up at 80°: again one level's frame, none finer than the horizon's (the
    // footprint only grows towards the pole; the frame's smallest is at its bottom).
    let up = View::new(10.0, 80.0, 90.0).unwrap();
    let got = still(up, w, h, RendererKind::Lut);
    let k = (1..map.pyramid().len())
        .find(|&i| got == lut(&map.pyramid()[i], up, Sampler::Bilinear, w, h))
        .expect("the frame of some level");
    assert!(k >= 2, "pyramid index {k}");
    // Trilinear: the trilinear frame of the same level (its levels of detail from the
    // level's own pyramid, which equals the map's below it), within 1.5 dB of trilinear
    // on the map against the truth (what it gives up: blending in levels finer than 3
    // where the footprint is smallest), and closer to it than bilinear on the map.
    let mut r = Renderer::new(&map);
    r.set_still_level(true);
    let tri = RenderOptions {
        sampler: Sampler::Trilinear,
        ..RenderOptions::default()
    };
    let got = render_frame(&mut r, &map, view, &tri, w, h).0;
    assert!(got == lut(level3, view, Sampler::Trilinear, w, h));
    let (l4, m4) = (&level3.pyramid()[0], &map.pyramid()[3]);
    assert_eq!((l4.width(), l4.height()), (m4.width(), m4.height()));
    assert!((0..l4.height()).all(|y| (0..l4.width()).all(|x| l4.pixel(x, y) == m4.pixel(x, y))));
    let p = psnr(&got, &truth);
    assert!(
        p >= pt - 1.5 && p >= pb + 3.0,
        "trilinear on the level {p:.1} dB, on the map {pt:.1}"
    );
    // Nearest ignores the switch.
    let o = RenderOptions {
        sampler: Sampler::Nearest,
        ..RenderOptions::default()
    };
    let f = render_frame(&mut r, &map, view, &o, w, h).0;
    assert!(f == lut(&map, view, Sampler::Nearest, w, h));
}

/// Maps with odd sides deeper down get every level too (1800×900: 225×113 at level 3,
/// where the pyramid used to stop at 450×225): zoomed out far enough to need level 3 and
/// beyond, trilinear is closer to the supersampled truth than bilinear, across the seam
/// too.
#[test]
fn odd_sided_maps_minify_too() {
    let map = fine_map(1800, 900);
    assert_eq!(map.pyramid().len(), 9, "levels down to 4x2");
    assert_eq!(
        (map.pyramid()[2].width(), map.pyramid()[2].height()),
        (225, 113)
    );
    let (w, h) = (48, 32);
    for (yaw, pitch) in [(0.0, 0.0), (179.0, 20.0)] {
        // hfov 100 over 48 columns: about 12 map pixels per screen pixel at the centre.
        let view = View::new(yaw, pitch, 100.0).unwrap();
        let truth = truth(&map, view, w, h);
        let pb = psnr(&lut(&map, view, Sampler::Bilinear, w, h), &truth);
        let pt = psnr(&lut(&map, view, Sampler::Trilinear, w, h), &truth);
        assert!(
            pt >= pb + 3.0,
            "({yaw}, {pitch}): trilinear {pt:.1} dB vs bilinear {pb:.1} dB"
        );
    }
}

/// Columns `x0..x1` of a `w`-wide image.
fn columns(px: &[u32], w: u32, x0: u32, x1: u32) -> Vec<u32> {
    px.chunks(w as usize)
        .flat_map(|row| row[x0 as usize..x1 as usize].iter().copied())
        .collect()
}

/// Regression (issue 12): above hfov 150 the pixels beyond the wide table are evaluated
/// exactly, and trilinear gave them the level of detail of the scanline's centre
/// (a far larger footprint than the stretched edge columns have): at hfov 170 on the
/// bundled courtyard photo the left 40 columns were 26 dB from the supersampled truth
/// against 44.7 dB for the exact renderer's trilinear (as reported; here, at 640x360,
/// 34.3 dB against 53.1 dB before the fix). Pixels evaluated exactly now take
/// their own exact footprint: they are the exact renderer's pixels, and as close to the
/// truth.
#[test]
fn trilinear_beyond_the_wide_table_takes_the_exact_level_of_detail() {
    let map = lut_core::load_map(
        &test_support::repo_root().join("assets/courtyard.jpg"),
        &lut_core::LoadOptions {
            projection: Some(Projection::Equirect),
            ..lut_core::LoadOptions::default()
        },
        &mut |_| {},
    )
    .expect("courtyard");
    let (w, h) = (640u32, 360u32);
    let view = View::new(0.0, 0.0, 170.0).unwrap();
    let (tri, report) = render_frame(
        &mut Renderer::new(&map),
        &map,
        view,
        &RenderOptions {
            sampler: Sampler::Trilinear,
            ..RenderOptions::default()
        },
        w,
        h,
    );
    assert!(report.exact_pixels >= 40 * h as u64, "{report:?}");
    let mut exact = vec![0u32; (w * h) as usize];
    render_exact(
        &map,
        view,
        Sampler::Trilinear,
        &mut Frame::new(&mut exact, w, h).unwrap(),
        true,
    );
    let mut truth = vec![0u32; (w * h) as usize];
    render_exact_supersampled(
        &map,
        view,
        Sampler::Bilinear,
        8,
        &mut Frame::new(&mut truth, w, h).unwrap(),
        true,
    );
    let (lut_left, exact_left, truth_left) = (
        columns(&tri, w, 0, 40),
        columns(&exact, w, 0, 40),
        columns(&truth, w, 0, 40),
    );
    let (pl, pe) = (psnr(&lut_left, &truth_left), psnr(&exact_left, &truth_left));
    eprintln!("hfov 170, left 40 columns against the 8x8 truth: LUT {pl:.1} dB, exact {pe:.1} dB");
    // Both evaluate these pixels exactly (by two f64 formulas: rounding may move an
    // 8-bit blend weight by one step) with the same level of detail.
    let d = test_support::pixels::diff(&lut_left, &exact_left);
    assert!(
        d.worst <= 2,
        "exact pixels differ from the exact renderer: {d:?}"
    );
    assert!(
        pl >= 40.0 && (pl - pe).abs() <= 0.5,
        "LUT trilinear {pl:.1} dB on the left 40 columns, exact {pe:.1} dB"
    );
}

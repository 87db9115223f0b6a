//! Minification anti-aliasing: zoomed out on a map with fine detail, the trilinear
//! sampler (pyramid, see `lut_core::pyramid`) must be measurably closer than bilinear to
//! the exact render supersampled 8×8 per pixel (the truth for a box-filtered pixel), for
//! the LUT renderer and the exact renderer alike, and must not hurt when magnifying.

use lut_core::{
    render_exact, render_exact_supersampled, EnvMap, Projection, RenderOptions, Renderer, Sampler,
    View,
};
use lut_core::{Frame, Scene};
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
    render_frame(&mut Renderer::new(map), Scene::Map(map), view, &opts, w, h).0
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
        render_frame(&mut r, Scene::Map(map), view, &opts, w, h).0
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
        let f = render_frame(&mut r, Scene::Map(&map), view, &opts, w, h).0;
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
        Scene::Map(&map),
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
        let f = render_frame(&mut r, Scene::Map(&map), view, &o, w, h).0;
        assert!(f == lut(&map, view, s, w, h), "{s:?}");
    }
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
        Scene::Map(&map),
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

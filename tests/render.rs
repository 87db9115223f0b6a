//! The LUT renderer against the exact map: sampling-position error over random and hard
//! views, single- vs multi-threaded bytes, sizes, options.
//!
//! The bound asserted is the product's stated one: **0.05 source pixels** (angular metric,
//! see `lut_core::accuracy`), everywhere, poles and seam included.

use lut_core::Frame;
use lut_core::Surface;
use lut_core::{compare_positions, ErrorStats};
use lut_core::{
    IndexStep, LutChoice, MapGeometry, Projection, RenderOptions, Renderer, Sampler, View,
};
use proptest::prelude::*;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};
use test_support::render::render_frame;

const BOUND: f64 = 0.05;

type Cache = Mutex<HashMap<(u32, u32, Projection), Renderer>>;

/// Renderers (and their tables) kept across cases, one per map geometry.
fn renderers() -> &'static Cache {
    static R: OnceLock<Cache> = OnceLock::new();
    R.get_or_init(|| Mutex::new(HashMap::new()))
}

fn measure(
    mw: u32,
    mh: u32,
    p: Projection,
    view: View,
    opts: RenderOptions,
    w: u32,
    h: u32,
) -> ErrorStats {
    let mut guard = renderers().lock().unwrap_or_else(|e| e.into_inner());
    let r = guard.entry((mw, mh, p)).or_default();
    let (pos, _) = r
        .positions(MapGeometry::new(mw, mh, p), view, &opts, w, h)
        .unwrap();
    compare_positions(&pos, view, w, h, p, mw, mh)
}

fn check(label: &str, st: &ErrorStats) {
    assert!(
        st.max <= BOUND && st.coverage_mismatch == 0,
        "{label}: max error {:.4} px at {:?} (bound {BOUND}), mean {:.5}, raw max {:.3}, coverage mismatches {}",
        st.max,
        st.worst_pixel,
        st.mean,
        st.max_raw,
        st.coverage_mismatch
    );
}

fn geometry(p: Projection, big: bool) -> (u32, u32) {
    let w = if big { 8192 } else { 2048 };
    match p {
        Projection::Cylinder => (w, w * 3 / 8),
        _ => (w, w / 2),
    }
}

fn opts(step: IndexStep, lut: LutChoice, surface: Surface) -> RenderOptions {
    RenderOptions {
        index_step: step,
        lut,
        surface,
        ..RenderOptions::default()
    }
}

/// The hard views of the issue: poles, near-poles, the seam, tiny and huge hfov.
#[test]
fn hard_views_within_bound_every_projection() {
    let views = [
        (0.0, 90.0, 90.0),
        (0.0, -90.0, 90.0),
        (37.0, 89.9, 90.0),
        (-120.0, -89.9, 120.0),
        (180.0, 0.0, 90.0),
        (-180.0, 30.0, 60.0),
        (179.9999, 60.0, 100.0),
        (10.0, 0.0, 1.0),
        (0.0, 45.0, 170.0),
        (170.0, 60.0, 100.0),
        (0.0, -45.0, 150.0),
        (90.0, 89.9999, 30.0),
    ];
    for p in Projection::ALL {
        let (mw, mh) = geometry(p, true);
        for &(y, pi, hf) in &views {
            let view = View::new(y, pi, hf).unwrap();
            for step in [
                IndexStep::Fixed(4),
                IndexStep::Fixed(16),
                IndexStep::Adaptive,
            ] {
                let st = measure(
                    mw,
                    mh,
                    p,
                    view,
                    opts(step, LutChoice::Auto, Surface::Cylinder),
                    160,
                    90,
                );
                check(&format!("{p} yaw {y} pitch {pi} hfov {hf} {step:?}"), &st);
            }
        }
    }
}

/// The diamond table (FIG. 8B) over the hard views, every projection, both tables: the
/// same bound as the cylinder's.
#[test]
fn diamond_table_hard_views_within_bound() {
    let views = [
        (0.0, 90.0, 90.0),
        (37.0, 89.9, 50.0),
        (-120.0, -89.9, 120.0),
        (180.0, 0.0, 90.0),
        (179.9999, 45.0, 100.0),
        (10.0, 0.0, 1.0),
        (0.0, -45.0, 150.0),
        (0.0, 30.0, 170.0),
    ];
    for p in Projection::ALL {
        let (mw, mh) = geometry(p, false);
        for &(y, pi, hf) in &views {
            let view = View::new(y, pi, hf).unwrap();
            for lut in [LutChoice::Auto, LutChoice::Wide, LutChoice::High] {
                let st = measure(
                    mw,
                    mh,
                    p,
                    view,
                    opts(IndexStep::Adaptive, lut, Surface::Diamond),
                    160,
                    90,
                );
                check(
                    &format!("diamond {p} {lut:?} yaw {y} pitch {pi} hfov {hf}"),
                    &st,
                );
            }
        }
    }
}

#[test]
fn both_tables_and_the_plane_within_bound() {
    let (mw, mh) = (8192, 4096);
    for (y, pi, hf) in [
        (0.0, 0.0, 45.0),
        (100.0, 70.0, 59.0),
        (-30.0, -20.0, 90.0),
        (0.0, 89.0, 50.0),
    ] {
        let view = View::new(y, pi, hf).unwrap();
        for lut in [LutChoice::Wide, LutChoice::High] {
            for surface in [Surface::Cylinder, Surface::Plane, Surface::Diamond] {
                let st = measure(
                    mw,
                    mh,
                    Projection::Equirect,
                    view,
                    opts(IndexStep::Fixed(8), lut, surface),
                    128,
                    96,
                );
                check(&format!("{lut:?} {surface:?} view {y},{pi},{hf}"), &st);
            }
        }
    }
}

/// Widest map supported (65536 wide): fixed-point ranges and the bound hold.
#[test]
fn widest_map_supported() {
    for (y, pi, hf) in [
        (179.99, 10.0, 20.0),
        (0.0, 89.95, 90.0),
        (-91.0, -30.0, 2.0),
    ] {
        let view = View::new(y, pi, hf).unwrap();
        let st = measure(
            65536,
            32768,
            Projection::Equirect,
            view,
            RenderOptions::default(),
            96,
            64,
        );
        check(&format!("65536-wide view {y},{pi},{hf}"), &st);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, .. ProptestConfig::default() })]

    /// Random views, sizes, steps, projections and table surfaces: error within the bound
    /// everywhere.
    #[test]
    fn random_views_within_bound(
        yaw in -720.0f64..720.0,
        pitch in prop_oneof![Just(90.0), Just(-90.0), Just(89.9), -90.0f64..90.0],
        hfov in prop_oneof![0.5f64..10.0, 10.0f64..179.0],
        w in 1u32..200,
        h in 1u32..120,
        step in prop_oneof![Just(1u32), Just(2), Just(4), Just(8), Just(16)],
        pi in 0usize..5,
        big in any::<bool>(),
        si in prop_oneof![4 => Just(0usize), 1 => Just(1), 2 => Just(2)],
    ) {
        let p = Projection::ALL[pi];
        let surface = [Surface::Cylinder, Surface::Plane, Surface::Diamond][si];
        let (mw, mh) = geometry(p, big);
        let view = View::new(yaw, pitch, hfov).unwrap();
        let st = measure(mw, mh, p, view, opts(IndexStep::Fixed(step), LutChoice::Auto, surface), w, h);
        prop_assert!(st.max <= BOUND && st.coverage_mismatch == 0,
            "{p} {mw}x{mh} {surface:?} view {yaw},{pitch},{hfov} {w}x{h} step {step}: max {:.4} at {:?}, mismatches {}",
            st.max, st.worst_pixel, st.coverage_mismatch);
    }
}

/// Single- and multi-threaded output are byte-identical, for every sampler and a seam/pole view.
#[test]
fn threads_are_byte_identical() {
    let map = lut_core::grid_map(1024, 512, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    for (y, pi, hf) in [(0.0, 0.0, 90.0), (180.0, 80.0, 120.0), (-45.0, -90.0, 40.0)] {
        let view = View::new(y, pi, hf).unwrap();
        for sampler in [Sampler::Nearest, Sampler::Bilinear, Sampler::Trilinear] {
            let (w, h) = (333, 211);
            let mut a = vec![0u32; (w * h) as usize];
            let mut b = vec![1u32; (w * h) as usize];
            let o1 = RenderOptions {
                sampler,
                threads: false,
                ..RenderOptions::default()
            };
            let o2 = RenderOptions {
                sampler,
                threads: true,
                ..RenderOptions::default()
            };
            r.render(&map, view, &o1, &mut Frame::new(&mut a, w, h).unwrap())
                .unwrap();
            r.render(&map, view, &o2, &mut Frame::new(&mut b, w, h).unwrap())
                .unwrap();
            assert!(
                a == b,
                "threads changed the output at view {y},{pi},{hf} {sampler:?}"
            );
        }
    }
}

/// Frames wide enough that each half row fills the row pass's position buffer
/// (`HALF_CHUNK`, 1024 pixels) more than once: the buffer is drawn and refilled mid-row,
/// and the positions stay within the bound across those joins (seam, pole and wide
/// views; fixed and adaptive steps).
#[test]
fn wide_frames_within_bound_across_position_buffers() {
    let views = [
        (0.0, 10.0, 90.0),
        (179.0, 0.0, 150.0),
        (33.0, 80.0, 120.0),
        (-90.0, -45.0, 60.0),
    ];
    for &(y, pi, hf) in &views {
        let view = View::new(y, pi, hf).unwrap();
        for step in [IndexStep::Fixed(4), IndexStep::Adaptive] {
            let o = opts(step, LutChoice::Auto, Surface::Cylinder);
            let st = measure(8192, 4096, Projection::Equirect, view, o, 4801, 9);
            check(
                &format!("4801x9 yaw {y} pitch {pi} hfov {hf} {step:?}"),
                &st,
            );
        }
    }
}

/// Every output size from 1x1, odd sizes and 1-pixel strips render without panic and
/// match the exact renderer's positions.
#[test]
fn odd_and_tiny_sizes() {
    let map = lut_core::grid_map(512, 256, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    for (w, h) in [(1, 1), (1, 7), (7, 1), (3, 3), (17, 5), (257, 1), (1, 300)] {
        let view = View::new(33.0, 12.0, 75.0).unwrap();
        render_frame(&mut r, &map, view, &RenderOptions::default(), w, h);
        let st = measure(
            512,
            256,
            Projection::Equirect,
            view,
            RenderOptions::default(),
            w,
            h,
        );
        check(&format!("size {w}x{h}"), &st);
    }
}

#[test]
fn bad_requests_are_errors_not_panics() {
    let map = lut_core::grid_map(64, 32, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    let view = View::default();
    let mut out = vec![0u32; 10];
    // Sizes and buffer lengths are checked when the frame is made.
    assert!(Frame::new(&mut out, 0, 10).is_err());
    assert!(Frame::new(&mut out, 3, 3).is_err());
    let bad = RenderOptions {
        index_step: IndexStep::Fixed(3),
        ..RenderOptions::default()
    };
    assert!(r
        .render(&map, view, &bad, &mut Frame::new(&mut out, 5, 2).unwrap())
        .is_err());
}

/// The report says which path rendered, and the table switches at 60 degrees.
#[test]
fn report_names_the_path() {
    let map = lut_core::grid_map(1024, 512, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    let mut out = vec![0u32; 64 * 48];
    let rep = |r: &mut Renderer, out: &mut Vec<u32>, hf: f64| {
        r.render(
            &map,
            View::new(0.0, 0.0, hf).unwrap(),
            &RenderOptions::default(),
            &mut Frame::new(out, 64, 48).unwrap(),
        )
        .unwrap()
    };
    assert_eq!(
        rep(&mut r, &mut out, 90.0).path,
        lut_core::RenderPath::LutWide
    );
    assert_eq!(
        rep(&mut r, &mut out, 60.0).path,
        lut_core::RenderPath::LutHigh
    );
    let wide = rep(&mut r, &mut out, 179.0);
    assert_eq!(wide.path, lut_core::RenderPath::LutWide);
    assert!(
        wide.exact_pixels > 0,
        "beyond 150 degrees the fallback must render the edges"
    );
    assert_eq!(rep(&mut r, &mut out, 90.0).exact_pixels, 0);
}

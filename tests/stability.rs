//! Hard-case numerical stability: poles, the seam, extreme yaw, tiny and huge hfov,
//! degenerate output sizes, the map's pole rows and seam columns, and the widest map.
//!
//! For every case: no NaN or infinite position, every sampled position inside the map
//! (u in [0, W), v in [0, H] for full-sphere maps), no panic when rendering pixels, and
//! the sampling-position error within the stated 0.05 px of the exact map.

use lut_core::compare_positions;
use lut_core::Frame;
use lut_core::{IndexStep, MapGeometry, Projection, RenderOptions, Renderer, View};
use test_support::render::render_frame;

const BOUND: f64 = 0.05;

#[allow(clippy::too_many_arguments)] // a test helper: one case per call
fn check(
    r: &mut Renderer,
    mw: u32,
    mh: u32,
    p: Projection,
    view: View,
    w: u32,
    h: u32,
    step: IndexStep,
) {
    let opts = RenderOptions {
        index_step: step,
        ..RenderOptions::default()
    };
    let (pos, _) = r
        .positions(MapGeometry::new(mw, mh, p), view, &opts, w, h)
        .unwrap();
    let label = format!(
        "{p} {mw}x{mh} yaw {} pitch {} hfov {} {w}x{h} {step:?}",
        view.yaw_deg(),
        view.pitch_deg(),
        view.hfov_deg()
    );
    for (i, q) in pos.iter().enumerate() {
        if let Some((u, v)) = q {
            assert!(u.is_finite() && v.is_finite(), "{label}: non-finite at {i}");
            assert!(
                *u >= 0.0 && *u <= mw as f64,
                "{label}: u {u} out of range at {i}"
            );
            if p.full_sphere() {
                assert!(
                    *v >= 0.0 && *v <= mh as f64,
                    "{label}: v {v} out of range at {i}"
                );
            }
        } else {
            assert!(
                !p.full_sphere(),
                "{label}: background on a full-sphere map at {i}"
            );
        }
    }
    let st = compare_positions(&pos, view, w, h, p, mw, mh);
    assert!(
        st.max <= BOUND && st.coverage_mismatch == 0,
        "{label}: max {} at {:?}",
        st.max,
        st.worst_pixel
    );
}

#[test]
fn extreme_angles() {
    let mut r = Renderer::default();
    let pitches = [90.0, -90.0, 89.9999, -89.9999, 0.0, 45.0];
    let yaws = [180.0, -180.0, 179.9999, -179.9999, 540.0, 1e9, -1e9, 0.0];
    let hfovs = [1e-3, 1.0, 90.0, 179.99];
    for p in [Projection::Equirect, Projection::Elliptical] {
        for &pitch in &pitches {
            for &yaw in &yaws {
                for &hfov in &hfovs {
                    let view = View::new(yaw, pitch, hfov).unwrap();
                    check(&mut r, 8192, 4096, p, view, 48, 27, IndexStep::Fixed(4));
                }
            }
        }
    }
}

#[test]
fn degenerate_output_sizes() {
    let mut r = Renderer::default();
    for (w, h) in [(1, 1), (1, 4096), (4096, 1), (4097, 3)] {
        for (yaw, pitch, hfov) in [
            (0.0, 0.0, 90.0),
            (180.0, 90.0, 120.0),
            (-45.0, -89.9999, 170.0),
        ] {
            let view = View::new(yaw, pitch, hfov).unwrap();
            for step in [IndexStep::Fixed(16), IndexStep::Adaptive] {
                check(&mut r, 4096, 2048, Projection::Equirect, view, w, h, step);
            }
        }
    }
}

/// Views aimed exactly at the map's pole rows and seam columns, so sampling positions
/// land on the first/last row and column.
#[test]
fn pole_rows_and_seam_columns_render() {
    let map = lut_core::grid_map(1024, 512, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    let _out = vec![0u32; 64 * 64];
    for (yaw, pitch, hfov) in [
        (180.0, 90.0, 0.01),
        (180.0, -90.0, 0.01),
        (-180.0, 0.0, 0.01),
        (179.99, 89.99, 0.5),
    ] {
        let view = View::new(yaw, pitch, hfov).unwrap();
        for sampler in [
            lut_core::Sampler::Nearest,
            lut_core::Sampler::Bilinear,
            lut_core::Sampler::Trilinear,
        ] {
            let opts = RenderOptions {
                sampler,
                ..RenderOptions::default()
            };
            render_frame(&mut r, &map, view, &opts, 64, 64);
        }
        check(
            &mut r,
            1024,
            512,
            Projection::Equirect,
            view,
            64,
            64,
            IndexStep::Fixed(4),
        );
    }
}

/// The widest map supported, 65536 pixels: fixed-point ranges hold at the seam and poles.
#[test]
fn widest_map_fixed_point_limits() {
    let mut r = Renderer::default();
    for (yaw, pitch, hfov) in [
        (180.0, 0.0, 0.001),
        (-179.9999, 45.0, 10.0),
        (90.0, 90.0, 60.0),
        (0.0, -89.9999, 150.0),
    ] {
        let view = View::new(yaw, pitch, hfov).unwrap();
        check(
            &mut r,
            65536,
            32768,
            Projection::Equirect,
            view,
            64,
            36,
            IndexStep::Fixed(16),
        );
    }
}

/// The trilinear sampler at degenerate sizes and hard views: no panic, on maps with even
/// and odd sides (which get as many pyramid levels: ⌈side / 2⌉ per level, down to a side
/// of 2); when magnifying it is exactly bilinear.
#[test]
fn trilinear_on_degenerate_sizes_and_odd_maps() {
    for (mw, mh) in [(1024u32, 512u32), (1023, 511)] {
        let map = lut_core::grid_map(mw, mh, Projection::Equirect).unwrap();
        assert_eq!(map.pyramid().len(), 8, "{mw}x{mh}: levels down to 4x2");
        let mut r = Renderer::new(&map);
        for (w, h) in [(1u32, 1u32), (1, 777), (777, 1), (97, 3)] {
            for (yaw, pitch, hfov) in [
                (0.0, 0.0, 170.0),
                (180.0, 90.0, 120.0),
                (-45.0, -89.9999, 0.01),
                (30.0, 10.0, 0.2),
            ] {
                let view = View::new(yaw, pitch, hfov).unwrap();
                let mut tri = vec![0u32; (w * h) as usize];
                let mut bi = vec![0u32; (w * h) as usize];
                for (sampler, out) in [
                    (lut_core::Sampler::Trilinear, &mut tri),
                    (lut_core::Sampler::Bilinear, &mut bi),
                ] {
                    let opts = RenderOptions {
                        sampler,
                        ..RenderOptions::default()
                    };
                    r.render(&map, view, &opts, &mut Frame::new(out, w, h).unwrap())
                        .unwrap();
                }
                // Magnified (hfov 0.2 on a 1024-wide map: a screen pixel covers at most
                // 0.57 map pixels, even a 1-pixel-wide frame): level 0 only.
                if hfov == 0.2 {
                    assert_eq!(tri, bi, "{mw}x{mh}, {w}x{h}, view {yaw},{pitch},{hfov}");
                }
            }
        }
    }
}

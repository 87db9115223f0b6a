//! Output projections (rectilinear, stereographic, fisheye, equisolid, Pannini) and the
//! grid renderer that draws them.
//!
//! * The projections against **independent evaluations of their formulas**
//!   (`docs/conventions.md`, "Output projections"), written out here from the angles: the
//!   centre is the view axis, the frame's left and right edges are at hfov/2, closed forms
//!   at known angles (fisheye θ = ρ/f, stereographic θ = 2 atan(ρ/2f), equisolid
//!   θ = 2 asin(ρ/2f), Pannini's forward map), Pannini with d = 0 is rectilinear and the
//!   stereographic view at a small hfov is too, to within a hundredth of a pixel.
//! * The grid renderer's **sampling-position error ≤ 0.05 px** (the product's bound,
//!   angular metric) over random views of every output projection on every map
//!   projection, and the hard views: poles, the ±180° seam, the edge of a fisheye's disc,
//!   the widest hfov of each projection.
//! * Images: the grid renderer against the exact renderer (the golden suite's
//!   tolerances), pixels with no direction show the background, cube maps and partial
//!   panoramas in every projection.

use lut_core::{compare_positions, grid_map, CubeMap, EnvMap, ErrorStats, Named, Projection};
use lut_core::{Camera, MapGeometry, Renderer, View, ViewProjection};
use lut_core::{RenderOptions, RenderPath, RendererKind, Sampler, ViewError};
use proptest::prelude::*;
use std::f64::consts::PI;
use test_support::pixels::{diff, psnr};
use test_support::render::{exact_frame, render_frame};

const BOUND: f64 = 0.05;

/// The projections with one Pannini per interesting d.
fn projections() -> Vec<ViewProjection> {
    vec![
        ViewProjection::Rectilinear,
        ViewProjection::Stereographic,
        ViewProjection::Fisheye,
        ViewProjection::Equisolid,
        ViewProjection::Pannini(0.0),
        ViewProjection::Pannini(0.5),
        ViewProjection::Pannini(1.0),
        ViewProjection::Pannini(2.5),
    ]
}

/// An hfov a fraction `t` ∈ (0, 1] of the way to the projection's widest (kept inside an
/// open range).
fn hfov_at(p: ViewProjection, t: f64) -> f64 {
    let (max, inclusive) = p.hfov_max();
    let h = max * t;
    if inclusive {
        h
    } else {
        h.min(max - 1e-3)
    }
}

/// Angle between two directions, radians.
fn angle(a: glam::DVec3, b: glam::DVec3) -> f64 {
    let (a, b) = (a.normalize(), b.normalize());
    a.cross(b).length().atan2(a.dot(b))
}

/// Azimuth atan2(x, z) and elevation atan2(y, √(x² + z²)) of a camera-space direction.
fn az_el(d: glam::DVec3) -> (f64, f64) {
    (d.x.atan2(d.z), d.y.atan2(d.x.hypot(d.z)))
}

/// The ray of image point (px, py) (pixel coordinates) of a yaw-0, pitch-0 view:
/// world = camera space.
fn ray(p: ViewProjection, hfov: f64, w: u32, h: u32, px: f64, py: f64) -> Option<glam::DVec3> {
    let cam = Camera::new(View::with_projection(0.0, 0.0, hfov, p).unwrap(), w, h);
    cam.ray(px, py)
}

#[test]
fn centre_is_the_axis_and_the_edges_are_at_half_the_hfov() {
    let (w, h) = (400u32, 300u32);
    for p in projections() {
        for t in [0.01, 0.3, 0.6, 0.9, 1.0] {
            let hfov = hfov_at(p, t);
            let what = format!("{p} hfov {hfov}");
            let c = ray(p, hfov, w, h, 200.0, 150.0).unwrap();
            assert!(angle(c, glam::DVec3::Z) < 1e-12, "{what}: centre {c}");
            for (x, sign) in [(0.0, -1.0), (400.0, 1.0)] {
                let Some(d) = ray(p, hfov, w, h, x, 150.0) else {
                    panic!("{what}: no direction at the edge x = {x}");
                };
                let (az, el) = az_el(d);
                let half = (hfov / 2.0).to_radians();
                // The edge is at θ = hfov/2 from the axis, on the centre row's plane; for
                // hfov/2 ≥ 180° (a 360° fisheye) both edges are the antipode.
                if half < PI - 1e-9 {
                    assert!(
                        (angle(d, glam::DVec3::Z) - half).abs() < 1e-9,
                        "{what}: θ at {x}"
                    );
                    assert!(
                        (az - sign * half).abs() < 1e-9,
                        "{what}: azimuth {az} at {x}"
                    );
                } else {
                    assert!(
                        angle(d, glam::DVec3::Z) > PI - 1e-7,
                        "{what}: antipode at {x}"
                    );
                }
                assert!(
                    el.abs() < 1e-9 || half >= PI - 1e-9,
                    "{what}: elevation {el}"
                );
            }
        }
    }
}

/// Radial projections: the angle from the axis of a pixel at radius ρ (pixels from the
/// centre, any direction in the image) against the closed form of each, with f from the
/// conventions' table written out here.
#[test]
fn radial_closed_forms() {
    let (w, h) = (640u32, 480u32);
    type Theta = fn(f64, f64) -> Option<f64>;
    type Focal = fn(f64) -> f64;
    let cases: [(ViewProjection, f64, Focal, Theta); 3] = [
        (
            ViewProjection::Stereographic,
            200.0,
            |hf| 320.0 / (2.0 * (hf / 4.0).tan()),
            |r, f| Some(2.0 * (r / (2.0 * f)).atan()),
        ),
        (
            ViewProjection::Fisheye,
            250.0,
            |hf| 320.0 / (hf / 2.0),
            |r, f| (r / f <= PI).then_some(r / f),
        ),
        (
            ViewProjection::Equisolid,
            360.0,
            |hf| 320.0 / (2.0 * (hf / 4.0).sin()),
            |r, f| (r / (2.0 * f) <= 1.0).then(|| 2.0 * (r / (2.0 * f)).asin()),
        ),
    ];
    for (p, hfov, focal, theta) in cases {
        let f = focal(hfov.to_radians());
        for (rho, alpha) in [
            (0.0, 0.0),
            (10.0, 0.3),
            (100.0, 2.0),
            (239.0, -1.1),
            (300.0, 0.7),
            (400.0, 3.0),
        ] {
            let (x, y) = (320.0 + rho * f64::cos(alpha), 240.0 - rho * f64::sin(alpha));
            let got = ray(p, hfov, w, h, x, y);
            match theta(rho, f) {
                None => assert!(got.is_none(), "{p} ρ {rho}: a direction beyond the disc"),
                Some(th) => {
                    let d = got.unwrap_or_else(|| panic!("{p} ρ {rho}: no direction"));
                    assert!((angle(d, glam::DVec3::Z) - th).abs() < 1e-9, "{p} ρ {rho}");
                    if rho > 0.0 {
                        // The direction lies in the pixel's radial plane, same side.
                        let phi = d.y.atan2(d.x);
                        let diff = (phi - alpha + PI).rem_euclid(2.0 * PI) - PI;
                        assert!(diff.abs() < 1e-9, "{p} ρ {rho}: direction angle {phi}");
                    }
                }
            }
        }
    }
    // Known values: stereographic hfov 180 puts θ = 45° at ρ = 2f tan 22.5° with
    // f = W/4; fisheye hfov 180 puts θ = 45° at a quarter width from the centre.
    let d = ray(
        ViewProjection::Stereographic,
        180.0,
        w,
        h,
        320.0 + 2.0 * 160.0 * (PI / 8.0).tan(),
        240.0,
    )
    .unwrap();
    assert!((angle(d, glam::DVec3::Z) - PI / 4.0).abs() < 1e-12);
    let d = ray(ViewProjection::Fisheye, 180.0, w, h, 320.0, 240.0 - 160.0).unwrap();
    assert!((angle(d, glam::DVec3::Z) - PI / 4.0).abs() < 1e-12);
    // Equisolid hfov 360 on a square image: the inscribed circle is the antipode.
    let d = ray(ViewProjection::Equisolid, 360.0, 200, 200, 100.0, 0.0).unwrap();
    assert!(angle(d, glam::DVec3::Z) > PI - 1e-7);
}

/// Pannini: pixels computed by the forward map written out here (S = (d+1)/(d + cos φ),
/// x = f S sin φ, y = f S tan ε) give back their azimuth and elevation.
#[test]
fn pannini_closed_forms() {
    let (w, h) = (800u32, 500u32);
    for d in [0.0, 0.3, 1.0, 2.0] {
        let p = ViewProjection::Pannini(d);
        let hfov: f64 = hfov_at(p, 0.8);
        let hr = hfov.to_radians();
        let f = 400.0 * (d + (hr / 2.0).cos()) / ((d + 1.0) * (hr / 2.0).sin());
        for (az_deg, el_deg) in [(0.0, 0.0), (20.0, 10.0), (-50.0, -30.0), (70.0, 45.0)] {
            let (az, el) = (f64::to_radians(az_deg), f64::to_radians(el_deg));
            if az.abs() > hr / 2.0 {
                continue;
            }
            let s = (d + 1.0) / (d + az.cos());
            let (x, y) = (400.0 + f * s * az.sin(), 250.0 - f * s * el.tan());
            let dir = ray(p, hfov, w, h, x, y).unwrap();
            let (ga, ge) = az_el(dir);
            assert!(
                (ga - az).abs() < 1e-9 && (ge - el).abs() < 1e-9,
                "d {d} at {az_deg},{el_deg}: {ga},{ge}"
            );
        }
    }
    // d = 1, hfov 180: x = 2f tan(φ/2) with f = W/4: azimuth 60° at x = (W/2) tan 30°.
    let dir = ray(
        ViewProjection::Pannini(1.0),
        180.0,
        w,
        h,
        400.0 + 400.0 * (PI / 6.0).tan(),
        250.0,
    )
    .unwrap();
    assert!((az_el(dir).0 - PI / 3.0).abs() < 1e-12);
    // d = 2.5 has directions only within |x| ≤ f (d + 1)/√(d² − 1) of the centre column.
    let p = ViewProjection::Pannini(2.5);
    let hr = 150f64.to_radians();
    let f = 2000.0 * (2.5 + (hr / 2.0).cos()) / (3.5 * (hr / 2.0).sin());
    let edge = f * 3.5 / (2.5f64 * 2.5 - 1.0).sqrt();
    assert!(ray(p, 150.0, 4000, 500, 2000.0 + edge * 0.999, 250.0).is_some());
    assert!(ray(p, 150.0, 4000, 500, 2000.0 + edge * 1.001, 250.0).is_none());
}

#[test]
fn pannini_zero_and_a_small_stereographic_view_are_rectilinear() {
    let (w, h) = (640u32, 360u32);
    // Pannini d = 0 is the rectilinear camera (same focal length, same rays), at any hfov.
    for hfov in [1.0, 60.0, 120.0, 179.0] {
        let a = Camera::new(View::new(30.0, 20.0, hfov).unwrap(), w, h);
        let b = Camera::new(
            View::with_projection(30.0, 20.0, hfov, ViewProjection::Pannini(0.0)).unwrap(),
            w,
            h,
        );
        for (x, y) in [(0.5, 0.5), (320.0, 180.0), (639.5, 10.5), (100.2, 359.5)] {
            assert!(
                angle(a.ray(x, y).unwrap(), b.ray(x, y).unwrap()) < 1e-12,
                "hfov {hfov} ({x},{y})"
            );
        }
    }
    // Stereographic at hfov 1: every pixel's ray lands within 0.01 px of the same pixel
    // of the rectilinear camera (the two differ by O(θ³)).
    let rect = Camera::new(View::new(-40.0, 10.0, 1.0).unwrap(), w, h);
    let st = Camera::new(
        View::with_projection(-40.0, 10.0, 1.0, ViewProjection::Stereographic).unwrap(),
        w,
        h,
    );
    let mut worst = 0.0f64;
    for y in (0..h).step_by(7) {
        for x in (0..w).step_by(5) {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let (qx, qy) = rect.project(st.ray(px, py).unwrap()).unwrap();
            worst = worst.max((qx - px).hypot(qy - py));
        }
    }
    assert!(
        worst < 0.01,
        "stereographic at hfov 1 is {worst} px from rectilinear"
    );
}

#[test]
fn project_inverts_the_ray_in_every_projection() {
    let (w, h) = (321u32, 201u32);
    for p in projections() {
        // (At the very widest hfov the forward map is ill-conditioned: a hemisphere
        // within a pixel of the centre.)
        for t in [0.2, 0.7, 0.99] {
            let hfov = hfov_at(p, t);
            let cam = Camera::new(View::with_projection(-70.0, 35.0, hfov, p).unwrap(), w, h);
            for (x, y) in [
                (0.5, 0.5),
                (160.5, 100.5),
                (320.5, 10.5),
                (40.2, 190.9),
                (250.0, 60.0),
            ] {
                let Some(d) = cam.ray(x, y) else { continue };
                // Antipodes (a 360° fisheye's rim) have no unique image point.
                if angle(d, cam.ray(160.5, 100.5).unwrap()) > PI - 1e-6 {
                    continue;
                }
                let (px, py) = cam
                    .project(d)
                    .unwrap_or_else(|| panic!("{p} hfov {hfov} ({x},{y})"));
                assert!(
                    (px - x).abs() < 1e-6 && (py - y).abs() < 1e-6,
                    "{p} hfov {hfov} ({x},{y}) -> ({px},{py})"
                );
            }
        }
    }
}

#[test]
fn hfov_ranges_and_the_pannini_parameter() {
    use ViewProjection::*;
    let ok = |p: ViewProjection, h: f64| View::with_projection(0.0, 0.0, h, p).is_ok();
    assert!(ok(Rectilinear, 179.9) && !ok(Rectilinear, 180.0));
    assert!(ok(Stereographic, 359.9) && !ok(Stereographic, 360.0));
    assert!(ok(Fisheye, 360.0) && !ok(Fisheye, 360.01));
    assert!(ok(Equisolid, 360.0) && !ok(Equisolid, 361.0));
    assert!(ok(Pannini(1.0), 359.9) && !ok(Pannini(1.0), 360.0));
    // d < 1: below 2·acos(−d); d > 1: below 2·acos(−1/d); d = 0: below 180.
    assert!(ok(Pannini(0.5), 239.9) && !ok(Pannini(0.5), 240.0));
    assert!(ok(Pannini(2.0), 239.9) && !ok(Pannini(2.0), 240.0));
    assert!(ok(Pannini(0.0), 179.9) && !ok(Pannini(0.0), 180.0));
    for p in ViewProjection::ALL {
        assert!(!ok(*p, 0.0) && !ok(*p, -5.0));
    }
    let e = View::with_projection(0.0, 0.0, 400.0, Fisheye).unwrap_err();
    assert_eq!(
        e.to_string(),
        "hfov must be in (0, 360] degrees for the fisheye view projection, got 400"
    );
    let e = View::with_projection(0.0, 0.0, 360.0, Stereographic).unwrap_err();
    assert!(
        e.to_string()
            .contains("(0, 360) degrees for the stereographic"),
        "{e}"
    );
    assert_eq!(
        View::with_projection(0.0, 0.0, 180.0, Rectilinear).unwrap_err(),
        ViewError::HfovOutOfRange(180.0)
    );
    for d in [-0.1, f64::NAN, f64::INFINITY, 1e6] {
        let e = View::with_projection(0.0, 0.0, 90.0, Pannini(d)).unwrap_err();
        assert!(matches!(e, ViewError::BadPanniniD { .. }), "{d}: {e}");
        assert!(e.to_string().contains(&format!("{d}")), "{e}");
    }
    assert_eq!(View::new(0.0, 0.0, 90.0).unwrap().projection(), Rectilinear);
    assert_eq!("little-planet".parse::<ViewProjection>(), Ok(Stereographic));
    assert_eq!("pannini".parse::<ViewProjection>(), Ok(Pannini(1.0)));
}

// ---------------------------------------------------------------------------------------
// The grid renderer's sampling positions.

fn map_geometry(p: Projection, big: bool) -> (u32, u32) {
    let w = if big { 8192 } else { 2048 };
    match p {
        Projection::Cylinder => (w, w * 3 / 8),
        _ => (w, w / 2),
    }
}

fn grid_opts(renderer: RendererKind) -> RenderOptions {
    RenderOptions {
        renderer,
        ..RenderOptions::default()
    }
}

/// The positions of `renderer` for `view` against the exact map.
fn measure(
    r: &mut Renderer,
    (mw, mh, p): (u32, u32, Projection),
    view: View,
    renderer: RendererKind,
    (w, h): (u32, u32),
) -> (ErrorStats, lut_core::RenderReport) {
    let (pos, rep) = r
        .positions(
            MapGeometry::new(mw, mh, p),
            view,
            &grid_opts(renderer),
            w,
            h,
        )
        .unwrap();
    (compare_positions(&pos, view, w, h, p, mw, mh), rep)
}

fn check(label: &str, st: &ErrorStats) {
    assert!(
        st.max <= BOUND && st.coverage_mismatch == 0,
        "{label}: max error {:.4} px at {:?} (bound {BOUND}), mean {:.5}, coverage mismatches {}",
        st.max,
        st.worst_pixel,
        st.mean,
        st.coverage_mismatch
    );
}

/// The hard views: poles (exactly and nearly), the seam, the widest hfov (the rim of a
/// 360° fisheye's disc is the antipode), a disc edge crossing the frame, small hfov.
#[test]
fn grid_hard_views_within_bound_every_projection() {
    let views = [
        (0.0, 90.0, 0.5),
        (0.0, -90.0, 1.0),
        (37.0, 89.9, 0.7),
        (180.0, 0.0, 0.5),
        (-180.0, 30.0, 0.95),
        (179.9999, -60.0, 1.0),
        (10.0, 0.0, 0.005),
        (-120.0, -89.9, 0.3),
    ];
    for mp in Projection::ALL {
        let (mw, mh) = map_geometry(mp, true);
        let mut r = Renderer::default();
        for vp in projections() {
            for &(yaw, pitch, t) in &views {
                let view = View::with_projection(yaw, pitch, hfov_at(vp, t), vp).unwrap();
                for size in [(160, 90), (97, 131)] {
                    let (st, rep) = measure(&mut r, (mw, mh, mp), view, RendererKind::Grid, size);
                    check(
                        &format!(
                            "{mp} {vp} yaw {yaw} pitch {pitch} hfov {} {size:?}",
                            view.hfov_deg()
                        ),
                        &st,
                    );
                    assert_eq!(rep.path, RenderPath::Grid);
                }
            }
        }
    }
}

/// Views the random search found beyond the bound while the grid was built (each a
/// reason for one of its rules): a little planet of a cylindrical map whose covered band
/// fits between a cell's points (background only in cells whose scale changes little),
/// a diamond map's seam (split where the seam may cross), a diamond map's equator in a
/// Pannini view (the row scale's kink: no cancellation assumed).
#[test]
fn grid_regressions() {
    let cases = [
        (
            (2048, 768, Projection::Cylinder),
            (
                -15.826827972915783,
                -86.69101565587074,
                346.4032279607309,
                ViewProjection::Stereographic,
            ),
            (24, 173),
        ),
        (
            (2048, 1024, Projection::Diamond),
            (
                98.00025419273453,
                -14.26915517922545,
                343.5676655972561,
                ViewProjection::Equisolid,
            ),
            (868, 565),
        ),
        (
            (2048, 1024, Projection::Diamond),
            (
                49.85259602454039,
                42.876285786288975,
                182.54267295179866,
                ViewProjection::Pannini(2.5),
            ),
            (923, 534),
        ),
        (
            (8192, 4096, Projection::Sine),
            (0.0, -90.0, 359.999, ViewProjection::Stereographic),
            (97, 131),
        ),
    ];
    let mut r = Renderer::default();
    for (geo, (yaw, pitch, hfov, vp), size) in cases {
        let view = View::with_projection(yaw, pitch, hfov, vp).unwrap();
        let (st, _) = measure(&mut r, geo, view, RendererKind::Grid, size);
        check(&format!("{geo:?} {view:?} {size:?}"), &st);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Random views, sizes and map projections: within the bound, every output projection.
    #[test]
    fn grid_random_views_within_bound(
        mp in 0usize..5,
        vp in 0usize..8,
        yaw in -540.0f64..540.0,
        pitch in -95.0f64..95.0,
        t in 0.001f64..1.0,
        w in 1u32..300,
        h in 1u32..200,
        big in any::<bool>(),
    ) {
        let mp = Projection::ALL[mp];
        let vp = projections()[vp];
        let (mw, mh) = map_geometry(mp, big);
        let view = View::with_projection(yaw, pitch, hfov_at(vp, t), vp).unwrap();
        let mut r = Renderer::default();
        let (st, _) = measure(&mut r, (mw, mh, mp), view, RendererKind::Grid, (w, h));
        check(&format!("{mp} {vp} {view:?} {w}x{h} map {mw}x{mh}"), &st);
    }
}

/// The LUT renderer draws non-rectilinear views with the grid; exact positions are exact.
#[test]
fn renderer_choice_for_each_projection() {
    let geo = (2048, 1024, Projection::Equirect);
    let mut r = Renderer::default();
    let rect = View::new(20.0, 10.0, 90.0).unwrap();
    let fish = View::with_projection(20.0, 10.0, 200.0, ViewProjection::Fisheye).unwrap();
    let (_, rep) = measure(&mut r, geo, rect, RendererKind::Lut, (64, 48));
    assert_eq!(rep.path, RenderPath::LutWide);
    let (_, rep) = measure(&mut r, geo, fish, RendererKind::Lut, (64, 48));
    assert_eq!(rep.path, RenderPath::Grid);
    let (st, rep) = measure(&mut r, geo, fish, RendererKind::Exact, (64, 48));
    assert_eq!((rep.path, st.max), (RenderPath::Exact, 0.0));
}

/// Building the grid alone (what the bench times) finds the same cells as a frame.
#[test]
fn building_the_grid_alone_finds_the_frames_cells() {
    let mut r = Renderer::default();
    for (vp, pitch) in [
        (ViewProjection::Rectilinear, 80.0),
        (ViewProjection::Fisheye, -90.0),
    ] {
        let view = View::with_projection(40.0, pitch, hfov_at(vp, 0.8), vp).unwrap();
        let (_, frame) = measure(
            &mut r,
            (2048, 1024, Projection::Equirect),
            view,
            RendererKind::Grid,
            (640, 400),
        );
        for threads in [false, true] {
            let built = r
                .build_grid(
                    MapGeometry::new(2048, 1024, Projection::Equirect),
                    view,
                    640,
                    400,
                    threads,
                )
                .unwrap();
            assert_eq!(built, frame, "{vp} threads {threads}");
        }
        assert!(
            frame.exact_pixels > 0 && frame.min_step >= 2 && frame.max_step <= 32,
            "{frame:?}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// Images.

/// The grid renderer's image against the exact renderer's with the golden suite's
/// tolerances (bilinear: at most 20 levels anywhere, 0.5 on average; nearest: at most 2 %
/// of pixels differ), every output projection, and the background where no direction.
#[test]
fn grid_images_match_the_exact_renderer() {
    let map = grid_map(1024, 512, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    let (w, h) = (160u32, 120u32);
    for vp in projections() {
        for (yaw, pitch, t) in [(30.0, -20.0, 0.6), (180.0, -90.0, 0.85)] {
            let view = View::with_projection(yaw, pitch, hfov_at(vp, t), vp).unwrap();
            for sampler in [Sampler::Bilinear, Sampler::Nearest] {
                let opts = RenderOptions {
                    sampler,
                    renderer: RendererKind::Grid,
                    ..RenderOptions::default()
                };
                let (img, _) = render_frame(&mut r, &map, view, &opts, w, h);
                let ex = exact_frame(&map, view, sampler, w, h);
                let d = diff(&img, &ex);
                let what = format!("{vp} {view:?} {}", sampler.name());
                match sampler {
                    Sampler::Nearest => assert!(
                        d.differ as f64 <= 0.02 * d.pixels as f64 + 1.0,
                        "{what}: {d:?}"
                    ),
                    _ => assert!(d.worst <= 20 && d.mean <= 0.5, "{what}: {d:?}"),
                }
            }
        }
    }
}

/// A 360° fisheye and equisolid on a wide output: the disc is the frame's height; pixels
/// outside it show the map's background in the grid and the exact renders alike, the
/// ones inside show the map.
#[test]
fn pixels_without_a_direction_show_the_background() {
    let mut map = grid_map(512, 256, Projection::Equirect).unwrap();
    map.set_background(0x123456);
    let mut r = Renderer::new(&map);
    let (w, h) = (120u32, 60u32);
    for vp in [ViewProjection::Fisheye, ViewProjection::Equisolid] {
        // hfov 720·(H/W)… : the disc's diameter is the height when hfov = 360 · H/W · 2.
        let view = View::with_projection(0.0, 0.0, 360.0, vp).unwrap();
        for renderer in [RendererKind::Grid, RendererKind::Exact, RendererKind::Lut] {
            let opts = RenderOptions {
                renderer,
                ..RenderOptions::default()
            };
            let (img, _) = render_frame(&mut r, &map, view, &opts, w, h);
            // Disc radius W/2 = 60: the corners (≈ 67 px from the centre) are outside.
            for (x, y) in [(0, 0), (119, 0), (0, 59), (119, 59)] {
                assert_eq!(
                    img[y * w as usize + x],
                    0x123456,
                    "{vp} {renderer:?} ({x},{y})"
                );
            }
            assert_ne!(
                img[30 * w as usize + 60],
                0x123456,
                "{vp} {renderer:?} centre"
            );
        }
    }
}

/// Cube maps in every output projection (per pixel from the view's rays) against the
/// exact render of the map the cube was made from (the cube golden's tolerance).
#[test]
fn cube_maps_in_every_projection() {
    let map = grid_map(1024, 512, Projection::Equirect).unwrap();
    let cube = CubeMap::from_envmap(&map, 512, Sampler::Bilinear).unwrap();
    let mut cube = lut_core::Panorama::cube(cube);
    for vp in projections() {
        let view = View::with_projection(45.0, 35.0, hfov_at(vp, 0.7), vp).unwrap();
        let opts = RenderOptions::default();
        let (img, rep) = test_support::render::pano_frame(&mut cube, view, &opts, 96, 64);
        let ex = exact_frame(&map, view, Sampler::Bilinear, 96, 64);
        let (p, d) = (psnr(&img, &ex), diff(&img, &ex));
        assert!(p >= 30.0 && d.mean <= 3.0, "{vp}: {p:.1} dB {d:?}");
        let want = if vp.is_rectilinear() {
            RenderPath::Cube(opts.cube)
        } else {
            RenderPath::CubeProjected
        };
        assert_eq!(rep.path, want, "{vp}");
    }
}

/// A partial panorama (a crop placed in its full panorama) in a fisheye and a little
/// planet: background outside the crop, the grid against the exact renderer.
#[test]
fn partial_panoramas_in_other_projections() {
    let full = grid_map(512, 256, Projection::Equirect).unwrap();
    let crop = lut_core::Coverage::new(200.0, 90.0, 150.0, 10.0)
        .unwrap()
        .crop_for_image(284, 128)
        .unwrap();
    let px: Vec<u32> = (0..crop.height())
        .flat_map(|y| (0..crop.width()).map(move |x| (x, y)))
        .map(|(x, y)| full.pixel((crop.left() + x) % 512, crop.top() + y))
        .collect();
    let mut map: EnvMap =
        EnvMap::from_pixels(crop.width(), crop.height(), &px, Projection::Equirect)
            .unwrap()
            .into_partial(crop)
            .unwrap();
    map.set_background(0x203040);
    let mut r = Renderer::new(&map);
    for (vp, hfov, pitch) in [
        (ViewProjection::Fisheye, 220.0, 0.0),
        (ViewProjection::Stereographic, 300.0, -90.0),
    ] {
        let view = View::with_projection(150.0, pitch, hfov, vp).unwrap();
        let opts = RenderOptions::default();
        let (img, _) = render_frame(&mut r, &map, view, &opts, 96, 64);
        let ex = exact_frame(&map, view, Sampler::Bilinear, 96, 64);
        assert!(
            img.contains(&0x203040) && img.iter().any(|&p| p != 0x203040),
            "{vp}"
        );
        let d = diff(&img, &ex);
        assert!(d.worst <= 20 && d.mean <= 0.5, "{vp}: {d:?}");
    }
}

/// Trilinear through the grid: the level of detail per cell from its nodes (exact
/// pixels: their exact footprint) against the exact renderer's per-pixel footprint.
#[test]
fn grid_trilinear_close_to_exact_trilinear() {
    let map = grid_map(2048, 1024, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    for vp in [
        ViewProjection::Stereographic,
        ViewProjection::Fisheye,
        ViewProjection::Pannini(1.0),
    ] {
        let view = View::with_projection(20.0, -30.0, hfov_at(vp, 0.6), vp).unwrap();
        let opts = RenderOptions {
            sampler: Sampler::Trilinear,
            ..RenderOptions::default()
        };
        let (img, _) = render_frame(&mut r, &map, view, &opts, 96, 64);
        let ex = exact_frame(&map, view, Sampler::Trilinear, 96, 64);
        let p = psnr(&img, &ex);
        assert!(p >= 35.0, "{vp}: {p:.1} dB");
    }
}

// ---------------------------------------------------------------------------------------
// The error heat map.

/// The heat map's summary is the measurement: its max is the max of `compare_positions`
/// (bit for bit), the largest of its per-pixel errors, and the worst pixel's colour is
/// the scale's colour of that max; the exact renderer's map is all zeros; a cube map's
/// too (both cube renderers compute every pixel's face coordinates exactly).
#[test]
fn heat_map_max_is_the_measured_max() {
    let map = grid_map(2048, 1024, Projection::Equirect).unwrap();
    let mut r = Renderer::new(&map);
    let (w, h) = (400u32, 240u32);
    for (view, renderer) in [
        (View::new(30.0, 80.0, 100.0).unwrap(), RendererKind::Lut),
        (View::new(180.0, -20.0, 60.0).unwrap(), RendererKind::Grid),
        (
            View::with_projection(0.0, -90.0, 300.0, ViewProjection::Stereographic).unwrap(),
            RendererKind::Lut,
        ),
        (
            View::with_projection(10.0, 20.0, 200.0, ViewProjection::Fisheye).unwrap(),
            RendererKind::Grid,
        ),
    ] {
        let opts = grid_opts(renderer);
        let em = lut_core::ErrorMap::measure(&mut r, &map, view, &opts, w, h).unwrap();
        let (pos, _) = r
            .positions(
                MapGeometry::new(2048, 1024, Projection::Equirect),
                view,
                &opts,
                w,
                h,
            )
            .unwrap();
        let st = compare_positions(&pos, view, w, h, Projection::Equirect, 2048, 1024);
        assert_eq!(em.stats, st, "{view:?}");
        let finite_max = em
            .errors
            .iter()
            .flatten()
            .copied()
            .filter(|e| e.is_finite())
            .fold(0.0f64, f64::max);
        assert_eq!(finite_max, em.stats.max);
        assert!(
            em.stats.max > 0.0 && em.stats.max <= BOUND,
            "{view:?}: {}",
            em.stats.max
        );
        let (x, y) = em.stats.worst_pixel;
        let i = (y * w + x) as usize;
        assert_eq!(em.errors[i], Some(em.stats.max));
        assert_eq!(em.colors()[i], lut_core::heat_color(em.stats.max));
        // The exact renderer measures nothing.
        let ex =
            lut_core::ErrorMap::measure(&mut r, &map, view, &grid_opts(RendererKind::Exact), w, h)
                .unwrap();
        assert_eq!((ex.stats.max, ex.stats.mean), (0.0, 0.0));
    }
    let cube = CubeMap::from_envmap(&map, 64, Sampler::Bilinear).unwrap();
    let view = View::with_projection(0.0, 0.0, 360.0, ViewProjection::Fisheye).unwrap();
    let em = lut_core::Panorama::cube(cube)
        .error_map(view, &RenderOptions::default(), 64, 32)
        .unwrap();
    assert_eq!(em.stats.max, 0.0);
    // Outside the 360° fisheye's disc there is no direction: background.
    assert_eq!(em.errors[0], None);
    assert_eq!(em.colors()[0], lut_core::HEAT_BACKGROUND);
    assert_eq!(em.errors[16 * 64 + 32], Some(0.0));
    // A frame the renderer draws from a pyramid level (a zoomed-out still frame,
    // `set_still_level`: hfov 90 over 48 columns of the 2048-wide map, level 3): the
    // level's positions against the exact level, as a renderer of the level measures them.
    let view = View::new(10.0, 0.0, 90.0).unwrap();
    let opts = RenderOptions::default();
    let level = &map.pyramid()[2];
    assert_eq!(level.width(), 256);
    let measure = |r: &mut Renderer, m: &lut_core::EnvMap| {
        lut_core::ErrorMap::measure(r, m, view, &opts, 48, 36).unwrap()
    };
    let mut r = Renderer::new(&map);
    let on_map = measure(&mut r, &map);
    r.set_still_level(true);
    let em = measure(&mut r, &map);
    assert_eq!(em, measure(&mut Renderer::new(level), level));
    assert_ne!(em, on_map);
}

#[test]
fn heat_scale_is_logarithmic_from_a_thousandth_to_one_pixel() {
    use lut_core::{heat_color, heat_scale};
    assert_eq!(heat_scale(0.0), 0.0);
    assert_eq!(heat_scale(0.001), 0.0);
    assert!((heat_scale(0.01) - 1.0 / 3.0).abs() < 1e-12);
    assert!((heat_scale(0.1) - 2.0 / 3.0).abs() < 1e-12);
    assert_eq!(heat_scale(1.0), 1.0);
    assert_eq!(heat_scale(7.0), 1.0);
    assert_eq!(heat_scale(f64::NAN), 0.0);
    assert_eq!(heat_color(0.0), heat_color(0.0005));
    assert_eq!(heat_color(1.0), heat_color(50.0));
    assert_ne!(heat_color(0.001), heat_color(1.0));
    // Distinct colours along the scale, none the background's or the mismatch's.
    let mut seen = std::collections::HashSet::new();
    for k in 0..=30 {
        let c = heat_color(10f64.powf(-3.0 + k as f64 * 0.1));
        assert!(c != lut_core::HEAT_BACKGROUND && c != lut_core::HEAT_MISMATCH);
        seen.insert(c);
    }
    assert!(seen.len() >= 25, "{}", seen.len());
}

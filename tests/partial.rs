//! Partial panoramas: a generated JPEG tagged with GPano XMP renders, through the LUT and
//! the exact renderer, its covered part at the right place (compared against the same
//! decoded pixels padded to a full equirect with the background colour) and background
//! elsewhere, including crops that straddle the ±180° seam or span 360°; the view limit
//! keeps every border pixel's ray inside a partial panorama at the seam.

use lut_core::exact_uv;
use lut_core::LoadOptions;
use lut_core::{dir_to_lat_long, Camera};
use lut_core::{insert_xmp, xmp_packet};
use lut_core::{
    limit_view, Coverage, CoverageSource, EnvMap, IndexStep, MapGeometry, Projection,
    RenderOptions, Renderer, RendererKind, Sampler, View,
};
use test_support::render::render_frame;

const FULL_W: u32 = 512;
const FULL_H: u32 = 256;
/// A colour the pattern (after JPEG) does not produce exactly.
const BG: u32 = 0xFE01FE;

/// A recognisable full panorama: red follows longitude, green latitude, blue a 32-px
/// checker.
fn pattern(x: u32, y: u32) -> [u8; 3] {
    let b = if (x / 32 + y / 32).is_multiple_of(2) {
        40
    } else {
        200
    };
    [(x / 2) as u8, y as u8, b]
}

/// The crop (left, top, w, h) of the pattern, JPEG-encoded and tagged with GPano XMP
/// describing a `FULL_W × FULL_H` panorama, plus an optional heading.
fn tagged_jpeg(left: u32, top: u32, w: u32, h: u32, heading: Option<&str>) -> Vec<u8> {
    let img = image::RgbImage::from_fn(w, h, |x, y| {
        image::Rgb(pattern((left + x) % FULL_W, top + y))
    });
    let mut jpeg = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut jpeg),
        image::ImageFormat::Jpeg,
    )
    .unwrap();
    let (fw, fh, l, t, cw, ch) = (
        FULL_W.to_string(),
        FULL_H.to_string(),
        left.to_string(),
        top.to_string(),
        w.to_string(),
        h.to_string(),
    );
    let mut fields = vec![
        ("ProjectionType", "equirectangular"),
        ("FullPanoWidthPixels", fw.as_str()),
        ("FullPanoHeightPixels", fh.as_str()),
        ("CroppedAreaLeftPixels", l.as_str()),
        ("CroppedAreaTopPixels", t.as_str()),
        ("CroppedAreaImageWidthPixels", cw.as_str()),
        ("CroppedAreaImageHeightPixels", ch.as_str()),
    ];
    if let Some(hd) = heading {
        fields.push(("PoseHeadingDegrees", hd));
    }
    insert_xmp(&jpeg, &xmp_packet(&fields)).unwrap()
}

/// The decoded JPEG pixels placed in a full equirect, background elsewhere: the
/// independent reference (an ordinary full map, no crop code involved).
fn padded_reference(jpeg: &[u8], left: u32, top: u32) -> EnvMap {
    let img = image::load_from_memory(jpeg).unwrap().to_rgb8();
    let mut px = vec![BG; (FULL_W * FULL_H) as usize];
    for (x, y, p) in img.enumerate_pixels() {
        let fx = (left + x) % FULL_W;
        px[((top + y) * FULL_W + fx) as usize] =
            (p[0] as u32) << 16 | (p[1] as u32) << 8 | p[2] as u32;
    }
    let mut m = EnvMap::from_pixels(FULL_W, FULL_H, &px, Projection::Equirect).unwrap();
    m.set_background(BG);
    m
}

fn load_partial(jpeg: &[u8]) -> EnvMap {
    let (mut m, src) = decode(jpeg, "test.jpg", None).unwrap();
    assert_eq!(src, CoverageSource::Xmp);
    m.set_background(BG);
    m
}

/// Decode `jpeg` as a possibly partial panorama with the default options.
fn decode(
    jpeg: &[u8],
    what: &str,
    coverage: Option<Coverage>,
) -> Result<(EnvMap, CoverageSource), lut_core::CoverageError> {
    lut_core::decode_partial(jpeg, what, &LoadOptions::default(), coverage, &mut |_| {})
}

fn render(map: &EnvMap, view: View, renderer: RendererKind, sampler: Sampler) -> Vec<u32> {
    render_at(map, view, renderer, sampler, (160, 90))
}

/// [`render`] on a `w × h` output.
fn render_at(
    map: &EnvMap,
    view: View,
    renderer: RendererKind,
    sampler: Sampler,
    (w, h): (u32, u32),
) -> Vec<u32> {
    let opts = RenderOptions {
        renderer,
        sampler,
        index_step: IndexStep::Fixed(4),
        ..RenderOptions::default()
    };
    render_frame(&mut Renderer::new(map), map, view, &opts, w, h).0
}

/// Where the exact position of each output pixel of a `w × h` frame lies relative to the
/// crop: its distance inside the crop's edge in full-panorama pixels (negative outside).
fn depth_inside_at(
    map: &EnvMap,
    view: View,
    (left, top, cw, ch): (u32, u32, u32, u32),
    (w, h): (u32, u32),
) -> Vec<f64> {
    let cam = Camera::new(view, w, h);
    let (mw, mh) = (map.width() as f64, map.height() as f64);
    let mut d = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = exact_uv(&cam, Projection::Equirect, mw, mh, x, y).unwrap();
            let su = (u - left as f64).rem_euclid(mw);
            // distance to the nearer horizontal edge, either way round the seam
            let dx = if cw == FULL_W {
                f64::INFINITY
            } else if su < cw as f64 {
                su.min(cw as f64 - su)
            } else {
                -((su - cw as f64).min(mw - su))
            };
            let sv = v - top as f64;
            let dy = if sv < 0.0 {
                sv
            } else if sv > ch as f64 {
                ch as f64 - sv
            } else {
                sv.min(ch as f64 - sv)
            };
            d.push(if dx < 0.0 || dy < 0.0 {
                dx.min(dy).min(0.0)
            } else {
                dx.min(dy)
            });
        }
    }
    d
}

/// Compare the partial map's renders with the padded reference's for several views.
///
/// * nearest: byte-identical everywhere (tolerance 0): both maps have the same geometry,
///   so both renderers sample the same positions, and the pixel containing each
///   position is the same crop pixel or background;
/// * bilinear: byte-identical where the exact position is at least 1 px inside the crop
///   (the four taps are crop pixels in both; the LUT's positions are within 0.05 px of
///   exact), background where it is at least 1 px outside; the 2 px band around the
///   edge differs by design (the crop clamps to its edge texels, the padded map blends
///   with background) and is not compared;
/// * trilinear (and the grid renderer's), on a smaller output (64 × 36: one pixel covers about two to eight map
///   pixels, so levels 1..3 are read): byte-identical where the exact position is at
///   least 1 px inside or outside the crop. The partial map's levels are the padded
///   map's levels (texels partly inside the crop included, `map/pyramid.rs`) and are read
///   as the padded map reads them, so outside the crop a minified edge blends into the
///   background there too; only level 0, weighing in at levels of detail below 1, keeps
///   the bilinear band above, which is not compared. Where the view shows the crop, the
///   partial map's trilinear frame also differs from its bilinear one (it minifies).
fn check_case(left: u32, top: u32, cw: u32, ch: u32, views: &[(f64, f64, f64)]) {
    check_case_at(left, top, cw, ch, views, (160, 90));
}

/// [`check_case`] on `size` frames (trilinear only at 160x90).
fn check_case_at(
    left: u32,
    top: u32,
    cw: u32,
    ch: u32,
    views: &[(f64, f64, f64)],
    size: (u32, u32),
) {
    let w = size.0 as usize;
    let jpeg = tagged_jpeg(left, top, cw, ch, None);
    let partial = load_partial(&jpeg);
    let crop = partial.crop().expect("a crop");
    assert_eq!(
        (crop.left(), crop.top(), crop.width(), crop.height()),
        (left, top, cw, ch)
    );
    assert_eq!((partial.width(), partial.height()), (FULL_W, FULL_H));
    // only the covered pixels are stored
    assert!(partial.bytes() <= ((cw + 1) * (ch + 1) * 4) as usize);
    let reference = padded_reference(&jpeg, left, top);
    for &(yaw, pitch, hfov) in views {
        let view = View::new(yaw, pitch, hfov).unwrap();
        let depth = depth_inside_at(&partial, view, (left, top, cw, ch), size);
        let (mut inside, mut outside) = (0, 0);
        for kind in [RendererKind::Lut, RendererKind::Exact] {
            let a = render_at(&partial, view, kind, Sampler::Nearest, size);
            let b = render_at(&reference, view, kind, Sampler::Nearest, size);
            if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
                panic!(
                    "{kind:?} nearest, crop {cw}x{ch}@({left},{top}), view {view:?}: pixel \
                     ({}, {}) is {:06x}, padded reference {:06x}",
                    i % w,
                    i / w,
                    a[i],
                    b[i]
                );
            }
            let a = render_at(&partial, view, kind, Sampler::Bilinear, size);
            let b = render_at(&reference, view, kind, Sampler::Bilinear, size);
            for i in 0..a.len() {
                let ctx = || {
                    format!(
                        "{kind:?} bilinear, crop {cw}x{ch}@({left},{top}), view {view:?}, \
                         pixel ({}, {}), depth {:.2}",
                        i % w,
                        i / w,
                        depth[i]
                    )
                };
                if depth[i] >= 1.0 {
                    assert_eq!(a[i], b[i], "{}", ctx());
                    assert_ne!(a[i], BG, "{}", ctx());
                    inside += 1;
                } else if depth[i] <= -1.0 {
                    assert_eq!(a[i], BG, "{}", ctx());
                    outside += 1;
                }
            }
        }
        assert!(inside > 0 || outside > 0, "view {view:?} compared nothing");
        if size == (160, 90) {
            check_trilinear(&partial, &reference, view, (left, top, cw, ch));
        }
    }
}

/// The trilinear part of [`check_case`].
fn check_trilinear(partial: &EnvMap, reference: &EnvMap, view: View, c: (u32, u32, u32, u32)) {
    const SIZE: (u32, u32) = (64, 36);
    let depth = depth_inside_at(partial, view, c, SIZE);
    let (mut compared, mut minified) = (0, false);
    for kind in [RendererKind::Lut, RendererKind::Grid, RendererKind::Exact] {
        let a = render_at(partial, view, kind, Sampler::Trilinear, SIZE);
        let b = render_at(reference, view, kind, Sampler::Trilinear, SIZE);
        for i in 0..a.len() {
            if depth[i].abs() >= 1.0 {
                let (x, y) = (i % SIZE.0 as usize, i / SIZE.0 as usize);
                assert_eq!(
                    a[i], b[i],
                    "{kind:?} trilinear, crop {c:?}, view {view:?}, pixel ({x}, {y}), depth {:.2}",
                    depth[i]
                );
                compared += 1;
            }
        }
        minified |= a != render_at(partial, view, kind, Sampler::Bilinear, SIZE);
    }
    assert!(compared > 0, "view {view:?} compared nothing");
    // (Where the view shows some of the crop.)
    let shows = depth.iter().any(|&d| d >= 1.0);
    assert!(minified || !shows, "view {view:?}: trilinear is bilinear");
}

#[test]
fn gpano_crop_renders_at_its_place() {
    // 160 x 100 px from column 200, row 60: longitudes -39.4..73.1, latitudes 47.8..-22.5
    check_case(
        200,
        60,
        160,
        100,
        &[
            (20.0, 10.0, 90.0),
            (0.0, 0.0, 150.0),
            (-60.0, 40.0, 60.0),
            (170.0, 0.0, 90.0),
        ],
    );
}

/// Frames wide enough (4801 pixels) that the row pass's position buffers are drawn and
/// refilled mid-row, on a crop and on one straddling the seam: the same checks.
#[test]
fn wide_frames_across_position_buffers_render_the_crop_at_its_place() {
    let views = [(20.0, 10.0, 90.0), (0.0, 0.0, 150.0), (170.0, 0.0, 120.0)];
    check_case_at(200, 60, 160, 100, &views, (4801, 9));
    check_case_at(420, 30, 200, 60, &views, (4801, 9));
}

#[test]
fn gpano_crop_straddling_the_seam_renders_at_its_place() {
    // 200 px from column 420: across the seam to column 108 (longitudes 115..-104)
    check_case(
        420,
        30,
        200,
        150,
        &[
            (180.0, 0.0, 90.0),
            (-170.0, 20.0, 60.0),
            (150.0, -30.0, 120.0),
            (0.0, 0.0, 100.0),
        ],
    );
}

#[test]
fn full_width_crop_wraps_and_stops_at_its_rows() {
    // all longitudes, latitudes 67.5..-22.5: wraps across the seam, background below
    check_case(
        0,
        32,
        FULL_W,
        128,
        &[
            (180.0, 0.0, 90.0),
            (-179.0, 60.0, 120.0),
            (90.0, -45.0, 90.0),
            (0.0, 89.0, 100.0),
        ],
    );
}

#[test]
fn explicit_coverage_overrides_the_metadata() {
    let jpeg = tagged_jpeg(200, 60, 160, 100, Some("123.5"));
    // the same placement in degrees: 112.5 x 70.3125, west edge -39.375, north 47.8125
    let cov = Coverage::new(112.5, 70.3125, -39.375 + 56.25, 47.8125 - 35.15625).unwrap();
    let (m, src) = decode(&jpeg, "t.jpg", Some(cov)).unwrap();
    assert_eq!(src, CoverageSource::Explicit);
    let c = m.crop().unwrap();
    assert_eq!(
        (c.full_width(), c.full_height(), c.left(), c.top()),
        (512, 256, 200, 60)
    );
    // a different coverage puts it elsewhere and ignores the XMP
    let cov = "360x90+0+0".parse::<Coverage>().unwrap();
    let (m, _) = decode(&jpeg, "t.jpg", Some(cov)).unwrap();
    let c = m.crop().unwrap();
    assert_eq!(
        (c.full_width(), c.full_height(), c.left(), c.top()),
        (160, 200, 0, 50)
    );
    // the heading comes with the metadata
    assert_eq!(load_partial(&jpeg).pose_heading_deg(), Some(123.5));
    // a coverage for a non-equirect projection is refused
    let e = lut_core::decode_partial(
        &jpeg,
        "t.jpg",
        &LoadOptions {
            projection: Some(Projection::Cylinder),
            ..LoadOptions::default()
        },
        Some(cov),
        &mut |_| {},
    );
    assert!(e.is_err());
}

#[test]
fn bad_metadata_is_a_clear_error_and_coverage_is_the_way_out() {
    // crop runs below the full panorama
    let img = image::RgbImage::from_fn(64, 32, |x, y| image::Rgb(pattern(x, y)));
    let mut jpeg = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut jpeg),
        image::ImageFormat::Jpeg,
    )
    .unwrap();
    let xmp = xmp_packet(&[
        ("FullPanoWidthPixels", "128"),
        ("FullPanoHeightPixels", "64"),
        ("CroppedAreaLeftPixels", "0"),
        ("CroppedAreaTopPixels", "40"),
        ("CroppedAreaImageWidthPixels", "64"),
        ("CroppedAreaImageHeightPixels", "32"),
    ]);
    let bad = insert_xmp(&jpeg, &xmp).unwrap();
    let e = decode(&bad, "bad.jpg", None).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("bad.jpg") && msg.contains("below"), "{msg}");
    let cov = "180x90+0+0".parse().unwrap();
    assert!(decode(&bad, "bad.jpg", Some(cov)).is_ok());
    // an untagged 2:1 JPEG is an ordinary map
    let (m, src) = decode(&jpeg, "plain.jpg", None).unwrap();
    assert_eq!(src, CoverageSource::Full);
    assert!(m.crop().is_none());
}

#[test]
fn view_limit_keeps_every_border_ray_inside_at_the_seam() {
    let jpeg = tagged_jpeg(420, 30, 200, 150, None);
    let mut map = load_partial(&jpeg);
    map.set_background(BG);
    let cov = map.coverage();
    assert!(map.crop().unwrap().straddles_seam());
    let (w, h) = (160u32, 90u32);
    for (yaw, pitch, hfov) in [
        (180.0, 0.0, 90.0),
        (-150.0, 50.0, 90.0),
        (120.0, -60.0, 120.0),
        (0.0, 0.0, 170.0),
        (-100.0, 10.0, 40.0),
        (179.9, 89.0, 10.0),
    ] {
        let v = limit_view(View::new(yaw, pitch, hfov).unwrap(), w, h, &cov);
        let cam = Camera::new(v, w, h);
        let border = (0..w)
            .flat_map(|x| [(x, 0), (x, h - 1)])
            .chain((0..h).flat_map(|y| [(0, y), (w - 1, y)]));
        for (x, y) in border {
            let (l, p) = dir_to_lat_long(cam.world_ray(x as f64 + 0.5, y as f64 + 0.5));
            assert!(
                cov.contains(l, p, 1e-9),
                "limited view {v:?}: border pixel ({x}, {y}) looks at ({:.3}, {:.3}), \
                 outside {cov}",
                l.to_degrees(),
                p.to_degrees()
            );
        }
        // and so the rendered view shows no background, with either renderer
        for kind in [RendererKind::Lut, RendererKind::Exact] {
            let img = render(&map, v, kind, Sampler::Nearest);
            let bg = img.iter().filter(|&&p| p == BG).count();
            assert_eq!(
                bg, 0,
                "{kind:?} limited view {v:?} shows {bg} background pixels"
            );
        }
    }
}

/// `--coverage` need not give square pixels (e.g. `360x90` on a 1000×500 image makes a
/// 1000×1000 full panorama). The LUT renderer's sampling positions on such geometries
/// stay within the project's 0.05 px bound of the exact ones.
#[test]
fn non_square_pixel_geometry_keeps_the_lut_bound() {
    use lut_core::compare_positions;
    for (mw, mh) in [(640u32, 160u32), (400, 400), (300, 600)] {
        let mut r = Renderer::default();
        for (yaw, pitch, hfov) in [
            (0.0, 0.0, 90.0),
            (179.0, 30.0, 120.0),
            (-90.0, 85.0, 60.0),
            (45.0, -89.0, 100.0),
            (180.0, 10.0, 20.0),
        ] {
            let view = View::new(yaw, pitch, hfov).unwrap();
            let opts = RenderOptions {
                index_step: IndexStep::Fixed(4),
                ..RenderOptions::default()
            };
            let (pos, _) = r
                .positions(
                    MapGeometry::new(mw, mh, Projection::Equirect),
                    view,
                    &opts,
                    160,
                    90,
                )
                .unwrap();
            let st = compare_positions(&pos, view, 160, 90, Projection::Equirect, mw, mh);
            assert!(
                st.max <= 0.05 && st.coverage_mismatch == 0,
                "{mw}x{mh} map, {view:?}: max error {} px at {:?}",
                st.max,
                st.worst_pixel
            );
        }
    }
}

/// The file's start view (GPano `InitialView*`) comes with the map, full or partial, and
/// is relative to the map (the heading minus the pose).
#[test]
fn the_start_view_comes_with_the_map() {
    let mut jpeg = Vec::new();
    image::RgbImage::from_pixel(64, 32, image::Rgb([1, 2, 3]))
        .write_to(
            &mut std::io::Cursor::new(&mut jpeg),
            image::ImageFormat::Jpeg,
        )
        .unwrap();
    let view = [
        ("PoseHeadingDegrees", "90"),
        ("InitialViewHeadingDegrees", "45"),
        ("InitialViewPitchDegrees", "10"),
        ("InitialHorizontalFOVDegrees", "60"),
    ];
    let full = lut_core::insert_xmp(&jpeg, &lut_core::xmp_packet(&view)).unwrap();
    let (m, src) = decode(&full, "full.jpg", None).unwrap();
    assert_eq!(src, CoverageSource::Full);
    let want = lut_core::StartView {
        yaw_deg: -45.0,
        pitch_deg: 10.0,
        hfov_deg: Some(60.0),
    };
    assert_eq!(m.start_view(), Some(want));
    let mut crop = view.to_vec();
    crop.extend([
        ("FullPanoWidthPixels", "128"),
        ("CroppedAreaLeftPixels", "10"),
        ("CroppedAreaTopPixels", "5"),
        ("CroppedAreaImageWidthPixels", "64"),
        ("CroppedAreaImageHeightPixels", "32"),
    ]);
    let part = lut_core::insert_xmp(&jpeg, &lut_core::xmp_packet(&crop)).unwrap();
    let (m, src) = decode(&part, "part.jpg", None).unwrap();
    assert_eq!(src, CoverageSource::Xmp);
    assert_eq!(m.start_view(), Some(want));
    // No metadata: no start view.
    assert_eq!(
        decode(&jpeg, "plain.jpg", None).unwrap().0.start_view(),
        None
    );
}

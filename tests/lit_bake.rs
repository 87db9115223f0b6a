//! The lit panorama (`IlluminanceMap::bake_map` / `bake_cube`): every texel lit once per
//! lighting change, then panned as an ordinary map.
//!
//! Two comparisons, both against the per-pixel computation:
//! * the texels themselves against each texel lit exactly (its own ray, E summed over the
//!   luminaires, the colour in f64 here, independently of lut-core's tables);
//! * frames of the lit copy (bilinear, nearest, trilinear; equirect, cube, partial maps;
//!   several views) against frames of the unlit map lit per pixel (`shade_frame`). Here
//!   the order of filtering and lighting differs: a frame of the lit copy filters lit
//!   texels, `shade_frame` lights the filtered sample with the light of the pixel's own
//!   ray. Where E is smooth that is the same picture; across a room edge or a light's
//!   cut-off, where E jumps, the lit copy blends the two sides over one texel (bilinear)
//!   or takes the texel centre's side (nearest) where the per-pixel frame switches at the
//!   pixel. The tolerances below are stated per comparison with what was measured.

use glam::DVec3;
use lut_core::{
    grid_map, lat_long_to_dir, lit_map_bytes, shade_frame, Camera, Coverage, CubeMap, EnvMap,
    Frame, IlluminanceMap, LightError, LightScene, MapOptions, Panorama, Projection, RenderOptions,
    Room, Sampler, ShadeOptions, View, ViewProjection, BAKE_MAX_BYTES,
};
use std::sync::atomic::AtomicBool;
use test_support::light_fixtures::{bench_table, lum, ring, views};
use test_support::pixels::{linear_to_srgb, max_channel_diff, srgb_to_linear};

/// Albedo `p` lit with light factor `k`, exactly (in f64, independently of lut-core's
/// tables).
fn lit(p: u32, k: f64) -> u32 {
    let ch = |s: u32| linear_to_srgb(srgb_to_linear((p >> s) & 0xff) * k) << s;
    ch(16) | ch(8) | ch(0)
}

/// A map of hashed colours (every byte value in every channel, no structure to hide
/// errors in).
fn noise_map(w: u32, h: u32) -> EnvMap {
    let px: Vec<u32> = (0..w * h)
        .map(|i| i.wrapping_mul(2_654_435_761) & 0xff_ffff)
        .collect();
    EnvMap::from_pixels(w, h, &px, Projection::Equirect).unwrap()
}

/// A room with lights close to its walls, aimed at them, in a turned and shifted box:
/// sharp light on the walls and across the room's edges.
fn walls() -> LightScene {
    let t = bench_table();
    let room = Room::new(4.2, 5.5, 2.6, 1.4)
        .unwrap()
        .with_yaw(-23.0)
        .unwrap()
        .with_center(0.4, -0.6)
        .unwrap();
    LightScene::new(
        room,
        vec![
            lum(&t, [2.3, 2.5, 0.0], 90.0, -30.0),
            lum(&t, [0.0, 2.55, -1.0], 15.0, -90.0),
            lum(&t, [-1.4, 2.2, -3.0], 30.0, -20.0),
        ],
    )
    .unwrap()
}

fn opts() -> ShadeOptions {
    ShadeOptions {
        ambient: 0.1,
        exposure: 1.0 / 400.0,
        ..ShadeOptions::default()
    }
}

/// Share of `diffs` within `levels`, and their mean.
/// The stored pixels of `m`, row by row.
fn pixels(m: &EnvMap) -> Vec<u32> {
    (0..m.height())
        .flat_map(|y| (0..m.width()).map(move |x| (x, y)))
        .map(|(x, y)| m.pixel(x, y))
        .collect()
}

fn stats(diffs: &[u32], levels: u32) -> (f64, f64) {
    let within = diffs.iter().filter(|&&d| d <= levels).count() as f64 / diffs.len() as f64;
    let mean = diffs.iter().map(|&d| d as f64).sum::<f64>() / diffs.len() as f64;
    (within, mean)
}

#[test]
fn texels_match_each_texel_lit_exactly() {
    // Every texel of the lit copy against its own ray lit exactly. The bake probes the
    // illuminance map at block corners and interpolates (E within the map's stated
    // error, docs/lights.md), and colours by the shading table (within a level): so
    // 99.8 % of the texels within 2 levels, the mean under half a level (measured:
    // 99.95 % and 99.995 %, means 0.34 and 0.36). The rest sit on a light's cut-off,
    // where E jumps within a texel.
    let (w, h) = (1024u32, 512u32);
    let pano = noise_map(w, h);
    let o = opts();
    for (label, scene) in [("ring", ring(&bench_table())), ("walls", walls())] {
        let map = IlluminanceMap::build(&scene, &MapOptions::default()).unwrap();
        let baked = map.bake_map(&pano, &o).unwrap();
        assert_eq!((baked.width(), baked.height()), (w, h));
        let mut diffs = Vec::with_capacity((w * h) as usize);
        for y in 0..h {
            let phi =
                std::f64::consts::FRAC_PI_2 - (y as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            for x in 0..w {
                let lambda =
                    (x as f64 + 0.5) / w as f64 * std::f64::consts::TAU - std::f64::consts::PI;
                let (p, n) = scene.scene_point(lat_long_to_dir(lambda, phi));
                let e = scene.illuminance(p, n);
                let want = lit(pano.pixel(x, y), o.ambient + o.exposure * e);
                diffs.push(max_channel_diff(want, baked.pixel(x, y)));
            }
        }
        let (within, mean) = stats(&diffs, 2);
        assert!(
            within >= 0.998 && mean < 0.5,
            "{label}: {:.4} % within 2 levels, mean {mean:.3}",
            within * 100.0
        );
    }
}

#[test]
fn texels_on_a_room_edge_take_their_own_face() {
    // Down one column, the rays cross from the front wall to the ceiling between two
    // texel rows: each of the two texels must carry its own face's light (the blocks
    // split along the edge, never interpolating across it). A grey map, a light close
    // to the edge so the two faces' E differ a lot.
    let (w, h) = (512u32, 256u32);
    let pano = EnvMap::from_pixels(
        w,
        h,
        &vec![0x80_8080; (w * h) as usize],
        Projection::Equirect,
    )
    .unwrap();
    let t = bench_table();
    let room = Room::new(4.0, 4.0, 2.6, 1.4).unwrap();
    let scene = LightScene::new(room, vec![lum(&t, [0.0, 2.4, 1.7], 0.0, 0.0)]).unwrap();
    let map = IlluminanceMap::build(&scene, &MapOptions::default()).unwrap();
    let o = ShadeOptions {
        ambient: 0.05,
        exposure: 1.0 / 2000.0,
        ..ShadeOptions::default()
    };
    let baked = map.bake_map(&pano, &o).unwrap();
    let mut checked = 0;
    for x in (0..w).step_by(7) {
        let lambda = (x as f64 + 0.5) / w as f64 * std::f64::consts::TAU - std::f64::consts::PI;
        let at = |y: u32| {
            let phi =
                std::f64::consts::FRAC_PI_2 - (y as f64 + 0.5) / h as f64 * std::f64::consts::PI;
            scene.scene_point(lat_long_to_dir(lambda, phi))
        };
        for y in 1..h / 2 {
            let ((p0, n0), (p1, n1)) = (at(y - 1), at(y));
            // The texel above on the ceiling, this one on a wall.
            if !(n0.y < -0.5 && n1.y.abs() < 0.5) {
                continue;
            }
            for (yy, p, n) in [(y - 1, p0, n0), (y, p1, n1)] {
                let e = scene.illuminance(p, n);
                let want = lit(0x80_8080, o.ambient + o.exposure * e);
                let got = baked.pixel(x, yy);
                assert!(
                    max_channel_diff(want, got) <= 2,
                    "column {x} row {yy} ({:?}): {got:06x} for {want:06x} (E {e:.0} lx)",
                    if n.y < -0.5 { "ceiling" } else { "wall" }
                );
            }
            // The two faces' light really differs here.
            let (e0, e1) = (scene.illuminance(p0, n0), scene.illuminance(p1, n1));
            if (e0 - e1).abs() > 0.3 * e0.max(e1) {
                checked += 1;
            }
        }
    }
    assert!(checked >= 10, "only {checked} edges with a real step in E");
}

#[test]
fn the_bake_does_not_depend_on_the_number_of_threads() {
    let pano = noise_map(700, 350);
    let cube = CubeMap::from_envmap(&pano, 96, Sampler::Bilinear).unwrap();
    let scene = walls();
    let map = IlluminanceMap::build(&scene, &MapOptions::default()).unwrap();
    let run = |n: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap();
        pool.install(|| {
            let m = map.bake_map(&pano, &opts()).unwrap();
            let c = map.bake_cube(&cube, &opts()).unwrap();
            let fc = map
                .bake_map(
                    &pano,
                    &ShadeOptions {
                        false_color: true,
                        ..opts()
                    },
                )
                .unwrap();
            (m, c, fc)
        })
    };
    let (a, b) = (run(1), run(2));
    assert!(pixels(&a.0) == pixels(&b.0), "map bytes differ");
    assert!(a.1 == b.1, "cube bytes differ");
    assert!(pixels(&a.2) == pixels(&b.2), "false-colour bytes differ");
}

/// Lit frames to compare: the scene, the shading, the panorama and its lit copy.
#[derive(Clone, Copy)]
struct Case<'a> {
    label: &'a str,
    scene: &'a LightScene,
    shade: &'a ShadeOptions,
    unlit: &'a Panorama,
    lit: &'a Panorama,
}

impl Case<'_> {
    /// [`frames_against_per_pixel`], then [`check`] with `(share, mean)`.
    fn check(&self, sampler: Sampler, views: &[View], tol: (f64, f64)) {
        let frames = frames_against_per_pixel(self, sampler, views);
        check(self.label, sampler, &frames, tol.0, tol.1);
    }
}

/// One frame of the lit copy against the per-pixel frame.
#[derive(Debug)]
struct Frames {
    view: View,
    /// Share of the pixels within 2 levels (largest channel difference).
    within: f64,
    /// Mean difference in levels.
    mean: f64,
    /// Pixels off by more than 2 levels, and how many of them lie within 3 pixels of a
    /// room edge or a step in E (over 10 % of E plus 1 % of the view's largest E).
    off: usize,
    on_feature: usize,
}

/// Frames of `lit` against frames of `unlit` lit per pixel (`shade_frame`) with `shade`,
/// for the views and sampler given (320 × 200 pixels).
fn frames_against_per_pixel(case: &Case<'_>, sampler: Sampler, views: &[View]) -> Vec<Frames> {
    let Case {
        scene,
        shade,
        unlit,
        lit,
        ..
    } = *case;
    // Handles on the same pixels and tables, drawn here.
    let (mut unlit, mut lit) = (unlit.share(), lit.share());
    let (w, h) = (320u32, 200u32);
    let ropts = RenderOptions {
        sampler,
        ..RenderOptions::default()
    };
    views
        .iter()
        .map(|&view| {
            let cam = Camera::new(view, w, h);
            let mut want = vec![0u32; (w * h) as usize];
            unlit
                .render(view, &ropts, &mut Frame::new(&mut want, w, h).unwrap())
                .unwrap();
            shade_frame(scene, &cam, &mut want, w, h, shade).unwrap();
            let mut got = vec![0u32; (w * h) as usize];
            lit.render(view, &ropts, &mut Frame::new(&mut got, w, h).unwrap())
                .unwrap();
            let diffs: Vec<u32> = want
                .iter()
                .zip(&got)
                .map(|(a, b)| max_channel_diff(*a, *b))
                .collect();
            let (within_2, mean) = stats(&diffs, 2);
            // Where E has a sharp feature: a room edge or a step in E within 3 pixels.
            let (wu, hu) = (w as usize, h as usize);
            let exact: Vec<(f64, DVec3)> = (0..wu * hu)
                .map(|i| {
                    // (No direction outside a fisheye's disc: both frames keep those
                    // pixels as rendered.)
                    match cam.ray((i % wu) as f64 + 0.5, (i / wu) as f64 + 0.5) {
                        Some(d) => {
                            let (p, n) = scene.scene_point(d);
                            (scene.illuminance(p, n), n)
                        }
                        None => (0.0, DVec3::ZERO),
                    }
                })
                .collect();
            let emax = exact.iter().map(|e| e.0).fold(0.0, f64::max);
            let sharp = |i: usize| {
                let (x, y) = ((i % wu) as i64, (i / wu) as i64);
                let (e, n) = exact[i];
                (-3..=3).any(|dy| {
                    (-3..=3).any(|dx| {
                        let (xx, yy) = (x + dx, y + dy);
                        if xx < 0 || yy < 0 || xx >= wu as i64 || yy >= hu as i64 {
                            return false;
                        }
                        let (e2, n2) = exact[yy as usize * wu + xx as usize];
                        n2 != n || (e2 - e).abs() > 0.1 * e.max(e2) + 0.01 * emax
                    })
                })
            };
            let on_feature = (0..diffs.len())
                .filter(|&i| diffs[i] > 2 && sharp(i))
                .count();
            Frames {
                view,
                within: within_2,
                mean,
                off: diffs.iter().filter(|&&d| d > 2).count(),
                on_feature,
            }
        })
        .collect()
}

/// The window's automatic exposure: 95 % of the room's surface below 1 / exposure lux.
fn auto(map: &IlluminanceMap) -> ShadeOptions {
    ShadeOptions {
        exposure: 1.0 / map.quantile(0.95),
        ..opts()
    }
}

/// The stated tolerance for frames of a lit copy against the per-pixel frames, per view:
/// at least `share` of the pixels within 2 levels and a mean difference under `mean`
/// levels; with nearest sampling (no filtering to reorder) at most 0.01 % of the pixels
/// off by more than 2 levels away from a room edge or a step in E.
///
/// Measured (grid map 2048 × 1024, cube faces of 512, 320 × 200 frames, automatic
/// exposure): bilinear and nearest 99.4 … 100 % within 2 levels, means 0.08 … 0.40;
/// trilinear 99.3 … 100 %, means up to 0.47 (a coarse level's texel averages lit texels
/// over a stretch where E changes: near the poles, where the level is coarse); the
/// partial map 98.9 … 99.7 %, means up to 0.54; curved view projections (fisheye,
/// stereographic, Pannini; stated 98.5 %, 0.6) 99.2 … 99.8 %, means up to 0.43; with
/// nearest at most 1 pixel in a frame off away from a sharp feature. Bilinear frames
/// blend the two sides of a room edge or a cut-off over one texel where the per-pixel
/// frame switches at the pixel (up to 56 levels there), and where a texel's lit colour
/// clips at white, the clipped value is filtered rather than the unclipped one (up to
/// about 35 levels next to bright texture edges under a light).
fn check(label: &str, sampler: Sampler, frames: &[Frames], share: f64, mean: f64) {
    for f in frames {
        eprintln!("{label} {sampler:?} {f:?}");
        assert!(
            f.within >= share && f.mean < mean,
            "{label} {sampler:?} {:?}: {:.3} % within 2 levels (at least {} % stated), mean \
             {:.3} (under {mean} stated)",
            f.view,
            f.within * 100.0,
            share * 100.0,
            f.mean
        );
        if sampler == Sampler::Nearest {
            assert!(
                (f.off - f.on_feature) * 10_000 <= 320 * 200,
                "{label} {f:?}: off pixels away from a sharp feature"
            );
        }
    }
}

#[test]
fn frames_of_the_lit_map_match_frames_lit_per_pixel() {
    let pano = Panorama::map(grid_map(2048, 1024, Projection::Equirect).unwrap());
    let no = AtomicBool::new(false);
    for (label, scene) in [("ring", ring(&bench_table())), ("walls", walls())] {
        let map = IlluminanceMap::build(&scene, &MapOptions::default()).unwrap();
        lut_core::build_frame_levels(pano.as_map().unwrap());
        let shade = auto(&map);
        let baked = map.bake_panorama(&pano, &shade, &no).unwrap();
        // Built with the copy, as the source's were: its pyramid and its levels' own.
        let b = baked.as_map().unwrap();
        assert!(b.pyramid_bytes() > 0 && b.pyramid()[0].pyramid_bytes() > 0);
        let case = Case {
            label,
            scene: &scene,
            shade: &shade,
            unlit: &pano,
            lit: &baked,
        };
        for sampler in [Sampler::Bilinear, Sampler::Nearest, Sampler::Trilinear] {
            let tol = match sampler {
                Sampler::Trilinear => (0.985, 0.6),
                _ => (0.99, 0.5),
            };
            case.check(sampler, &views(), tol);
        }
        // Curved view projections: a frame of the lit copy is an ordinary frame.
        let curved: Vec<View> = [
            (30.0, -60.0, 200.0, ViewProjection::Fisheye),
            (-70.0, 20.0, 250.0, ViewProjection::Stereographic),
            (120.0, -10.0, 150.0, ViewProjection::Pannini(1.0)),
        ]
        .iter()
        .map(|&(y, p, f, proj)| View::with_projection(y, p, f, proj).unwrap())
        .collect();
        case.check(Sampler::Bilinear, &curved, (0.985, 0.6));
    }
}

#[test]
fn cube_and_partial_maps() {
    let pano = grid_map(2048, 1024, Projection::Equirect).unwrap();
    let cube = CubeMap::from_envmap(&pano, 512, Sampler::Bilinear).unwrap();
    let t = bench_table();
    let room = Room::cube(3.0, 1.2).unwrap();
    let scene = LightScene::new(
        room,
        vec![
            lum(&t, [0.5, 2.7, 0.3], 0.0, -90.0),
            lum(&t, [-1.2, 2.0, -1.3], 45.0, -30.0),
        ],
    )
    .unwrap();
    let map = IlluminanceMap::build(&scene, &MapOptions::default()).unwrap();
    let shade = auto(&map);
    let lit_cube = Panorama::cube(map.bake_cube(&cube, &shade).unwrap());
    let cube = Panorama::cube(cube);
    for sampler in [Sampler::Bilinear, Sampler::Nearest] {
        Case {
            label: "cube",
            scene: &scene,
            shade: &shade,
            unlit: &cube,
            lit: &lit_cube,
        }
        .check(sampler, &views(), (0.99, 0.5));
    }
    // A partial map: 200° × 100° of the walls room, across the ±180° seam.
    let scene = walls();
    let map = IlluminanceMap::build(&scene, &MapOptions::default()).unwrap();
    let cov = Coverage::new(200.0, 100.0, 150.0, -20.0).unwrap();
    let crop = cov.crop_for_image(1200, 600).unwrap();
    let part = grid_map(crop.width(), crop.height(), Projection::Equirect)
        .unwrap()
        .into_partial(crop)
        .unwrap();
    let shade = auto(&map);
    let lit_part = map.bake_map(&part, &shade).unwrap();
    assert_eq!(lit_part.crop(), part.crop());
    let (part, lit_part) = (Panorama::map(part), Panorama::map(lit_part));
    let views: Vec<View> = [
        (150.0, -20.0, 90.0),
        (100.0, -50.0, 70.0),
        (210.0, 10.0, 60.0),
    ]
    .iter()
    .map(|&(y, p, f)| View::new(y, p, f).unwrap())
    .collect();
    Case {
        label: "partial",
        scene: &scene,
        shade: &shade,
        unlit: &part,
        lit: &lit_part,
    }
    .check(Sampler::Bilinear, &views, (0.98, 0.7));
}

#[test]
fn memory_budget_and_bad_options() {
    // The lit copy: the padded map plus a third for its pyramid and a ninth for its
    // levels' own pyramids (still frames drawn from a level).
    let m = grid_map(64, 32, Projection::Equirect).unwrap();
    assert_eq!(m.bytes(), 65 * 33 * 4);
    assert_eq!(lit_map_bytes(&m), m.bytes() + m.bytes() / 3 + m.bytes() / 9);
    // The budget holds an 8192 × 4096 map and its pyramids, not a 16384 × 8192 one.
    let bytes = |w: usize, h: usize| (w + 1) * (h + 1) * 4 * 13 / 9;
    assert!(bytes(8192, 4096) <= BAKE_MAX_BYTES);
    assert!(bytes(16384, 8192) > BAKE_MAX_BYTES);
    let e = LightError::BakeTooLarge {
        bytes: bytes(16384, 8192),
        max: BAKE_MAX_BYTES,
    };
    assert_eq!(
        e.to_string(),
        "the lit panorama would take 740 MiB, more than the 192 MiB a bake may use: frames \
         are lit one by one instead"
    );
    let scene = walls();
    let map = IlluminanceMap::build(&scene, &MapOptions::preview()).unwrap();
    for bad in [
        ShadeOptions {
            exposure: -1.0,
            ..opts()
        },
        ShadeOptions {
            ambient: f64::NAN,
            ..opts()
        },
    ] {
        assert!(matches!(
            map.bake_map(&m, &bad),
            Err(LightError::BadOption { .. })
        ));
    }
}

#[test]
fn a_cancelled_bake_makes_nothing() {
    // The window cancels a bake whose lighting has changed: with the flag set nothing is
    // made (each band checks it before it starts); with it clear the bake is the plain
    // one, byte for byte.
    use std::sync::atomic::AtomicBool;
    let pano = noise_map(300, 150);
    let cube = CubeMap::from_envmap(&pano, 48, Sampler::Bilinear).unwrap();
    let map = IlluminanceMap::build(&walls(), &MapOptions::preview()).unwrap();
    let (stop, go) = (AtomicBool::new(true), AtomicBool::new(false));
    assert!(matches!(
        map.bake_map_cancellable(&pano, &opts(), &stop),
        Err(LightError::Cancelled)
    ));
    assert!(matches!(
        map.bake_cube_cancellable(&cube, &opts(), &stop),
        Err(LightError::Cancelled)
    ));
    let a = map.bake_map_cancellable(&pano, &opts(), &go).unwrap();
    let b = map.bake_map(&pano, &opts()).unwrap();
    assert!(pixels(&a) == pixels(&b), "map bytes differ");
    let a = map.bake_cube_cancellable(&cube, &opts(), &go).unwrap();
    assert!(a == map.bake_cube(&cube, &opts()).unwrap());
    // Bad options are reported before the flag is looked at.
    let bad = ShadeOptions {
        exposure: -1.0,
        ..opts()
    };
    assert!(matches!(
        map.bake_map_cancellable(&pano, &bad, &stop),
        Err(LightError::BadOption { .. })
    ));
}

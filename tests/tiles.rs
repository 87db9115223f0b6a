//! Tiled pyramids (Pannellum multires): frames from tiles against the whole cube of the
//! same level (the cube renderer on `CubeMap::from_envmap` of the map, the independent
//! path), flat pyramids flat across every tile edge, missing and broken tiles drawn from
//! the ancestor with one notice each, bad configurations refused at open.

use lut_core::{
    render_tiles, write_pyramid, CubeMap, EnvMap, Face, Frame, LoadOptions, Panorama, Projection,
    RenderOptions, Sampler, TileId, TiledPanorama, View, ViewProjection,
};
use std::path::Path;
use test_support::pixels::psnr;

fn courtyard() -> EnvMap {
    lut_core::load_map(
        &test_support::repo_root().join("assets/courtyard.jpg"),
        &LoadOptions {
            projection: Some(Projection::Equirect),
            ..LoadOptions::default()
        },
        &mut |_| {},
    )
    .expect("courtyard")
}

/// The generator's face size for the 1024-wide courtyard: 8 · int(1024 / π / 8) = 320;
/// with 64-texel tiles: levels of 40, 80 (64 + a short 16), 160, 320 (five tiles, the
/// last 64).
const CUBE: u32 = 320;
const TILE: u32 = 64;

/// A pyramid cut from the cubes `CubeMap::from_envmap` makes of `map` at each level's
/// size (PNG: lossless), and those cubes.
fn pyramid_from_map(dir: &Path, map: &EnvMap) -> Vec<CubeMap> {
    let levels = lut_core::generator_levels(CUBE, TILE);
    let cubes: Vec<CubeMap> = (1..=levels)
        .map(|l| CubeMap::from_envmap(map, CUBE >> (levels - l), Sampler::Bilinear).unwrap())
        .collect();
    let faces: Vec<Vec<Vec<u32>>> = cubes
        .iter()
        .map(|c| Face::ALL.iter().map(|&f| c.face_pixels(f)).collect())
        .collect();
    let got = write_pyramid(dir, CUBE, TILE, "png", &|id: TileId, x0, y0, w, h| {
        let l = id.level as usize - 1;
        let n = cubes[l].face_size();
        let face = &faces[l][id.face.index()];
        (y0..y0 + h)
            .flat_map(|y| (x0..x0 + w).map(move |x| face[(y * n + x) as usize]))
            .collect()
    })
    .unwrap();
    assert_eq!(got, levels);
    cubes
}

fn cube_frame(cube: &CubeMap, view: View, w: u32, h: u32) -> Vec<u32> {
    let mut px = vec![0u32; (w * h) as usize];
    let mut frame = Frame::new(&mut px, w, h).unwrap();
    let opts = RenderOptions {
        sampler: Sampler::Bilinear,
        ..RenderOptions::default()
    };
    Panorama::cube(cube.clone())
        .render(view, &opts, &mut frame)
        .unwrap();
    px
}

/// Views across tile edges, face edges and corners, and both poles.
fn views() -> Vec<View> {
    [
        (0.0, 0.0, 60.0),
        (45.0, 0.0, 90.0),
        (-45.0, 35.0, 100.0),
        (130.0, -30.0, 75.0),
        (0.0, 90.0, 90.0),
        (20.0, -90.0, 120.0),
        (-90.0, 10.0, 30.0),
        (180.0, 44.0, 50.0),
    ]
    .iter()
    .map(|&(y, p, f)| View::new(y, p, f).unwrap())
    .collect()
}

#[test]
fn a_pyramid_cut_from_a_map_renders_its_levels_cubes() {
    let dir = tempfile::tempdir().unwrap();
    let map = courtyard();
    let cubes = pyramid_from_map(dir.path(), &map);
    let mut pano = TiledPanorama::open(dir.path(), 256 << 20, 2).unwrap();
    let (w, h) = (160, 120);
    let mut worst = f64::INFINITY;
    for view in views() {
        for (l, cube) in cubes.iter().enumerate() {
            let mut px = vec![0u32; (w * h) as usize];
            let f = pano.render_wait(view, Sampler::Bilinear, l as u32 + 1, &mut px, w, h);
            assert!(!f.coarser(), "{view:?} level {}: drawn coarser", l + 1);
            let want = cube_frame(cube, view, w, h);
            let p = psnr(&px, &want);
            worst = worst.min(p);
            // The same texels, positions shifted into the tile (1e-12 texel rounding may
            // move a Q.16 position by one step): required 45 dB.
            assert!(p >= 45.0, "{view:?} level {}: {p:.1} dB", l + 1);
        }
    }
    assert!(pano.take_notices().is_empty());
    eprintln!("worst tiles-vs-cube PSNR {worst:.1} dB");
}

#[test]
fn other_output_projections_render_from_tiles() {
    let dir = tempfile::tempdir().unwrap();
    let map = courtyard();
    let cubes = pyramid_from_map(dir.path(), &map);
    let pano = TiledPanorama::open(dir.path(), 256 << 20, 2).unwrap();
    let (w, h) = (120, 90);
    for proj in [ViewProjection::Stereographic, ViewProjection::Fisheye] {
        let view = View::with_projection(10.0, 60.0, 150.0, proj).unwrap();
        let mut px = vec![0u32; (w * h) as usize];
        // Level 1 is resident from the open: compare against the level-1 cube.
        render_tiles(pano.store(), view, Sampler::Bilinear, 1, &mut px, w, h);
        let want = cube_frame(&cubes[0], view, w, h);
        let p = psnr(&px, &want);
        assert!(p >= 45.0, "{proj:?}: {p:.1} dB");
    }
}

#[test]
fn a_flat_pyramid_is_flat_across_every_tile_and_face_edge() {
    let dir = tempfile::tempdir().unwrap();
    let c = 0x00_4a_91_c3;
    write_pyramid(dir.path(), 648, 128, "png", &|_, _, _, w, h| {
        vec![c; (w * h) as usize]
    })
    .unwrap();
    let mut pano = TiledPanorama::open(dir.path(), 64 << 20, 2).unwrap();
    let max = pano.config().max_level;
    for view in views() {
        for level in 1..=max {
            for sampler in [Sampler::Nearest, Sampler::Bilinear] {
                let mut px = vec![0u32; 97 * 61];
                pano.render_wait(view, sampler, level, &mut px, 97, 61);
                let bad: Vec<(usize, u32)> = px
                    .iter()
                    .copied()
                    .enumerate()
                    .filter(|&(_, p)| p != c)
                    .collect();
                assert!(
                    bad.is_empty(),
                    "{view:?} level {level} {sampler:?}: {bad:x?}"
                );
            }
        }
    }
}

#[test]
fn missing_and_broken_tiles_draw_the_ancestor_with_one_notice_each() {
    let dir = tempfile::tempdir().unwrap();
    let map = courtyard();
    pyramid_from_map(dir.path(), &map);
    let top = lut_core::generator_levels(CUBE, TILE);
    let view = View::new(0.0, 0.0, 60.0).unwrap();
    let (w, h) = (160, 120);
    let frame = |pano: &mut TiledPanorama, level| {
        let mut px = vec![0u32; (w * h) as usize];
        let f = pano.render_wait(view, Sampler::Bilinear, level, &mut px, w, h);
        (px, f)
    };
    let mut intact = TiledPanorama::open(dir.path(), 256 << 20, 2).unwrap();
    let (full, _) = frame(&mut intact, top);
    let (coarser, _) = frame(&mut intact, top - 1);
    drop(intact);
    // Break front-face tiles of the top level in every way.
    let tile = |x: u32, y: u32| dir.path().join(format!("{top}/f{y}_{x}.png"));
    std::fs::remove_file(tile(2, 2)).unwrap();
    std::fs::write(tile(1, 2), b"\x89PNG\r\n\x1a\n garbage").unwrap();
    let small = image::RgbImage::new(32, 32);
    small.save(tile(3, 2)).unwrap();
    std::fs::write(
        tile(2, 1),
        test_support::bombs::png_header_only(100_000, 100_000),
    )
    .unwrap();
    let mut trunc = std::fs::read(tile(2, 3)).unwrap();
    trunc.truncate(trunc.len() / 3);
    std::fs::write(tile(2, 3), trunc).unwrap();
    let mut pano = TiledPanorama::open(dir.path(), 256 << 20, 2).unwrap();
    let (px, f) = frame(&mut pano, top);
    assert!(f.coarser());
    let notices = pano.take_notices();
    assert_eq!(notices.len(), 5, "{notices:#?}");
    for n in &notices {
        assert!(
            !n.contains('\n') && n.contains("drawn from a coarser level"),
            "{n}"
        );
    }
    // Every pixel is the intact frame's or the coarser level's: never a hole.
    let (mut from_full, mut from_coarser) = (0, 0);
    for i in 0..px.len() {
        if px[i] == full[i] {
            from_full += 1;
        } else {
            assert_eq!(px[i], coarser[i], "pixel {i} is neither level's");
            from_coarser += 1;
        }
    }
    assert!(
        from_coarser > 2000 && from_full > 2000,
        "{from_full} {from_coarser}"
    );
    // A second frame gives no new notice.
    frame(&mut pano, top);
    assert!(pano.take_notices().is_empty());
}

#[test]
fn tiles_the_generator_left_out_are_background() {
    let dir = tempfile::tempdir().unwrap();
    write_pyramid(dir.path(), 648, 128, "png", &|_, _, _, w, h| {
        vec![0x808080; (w * h) as usize]
    })
    .unwrap();
    let cfg = dir.path().join("config.json");
    let text = std::fs::read_to_string(&cfg).unwrap();
    // The whole front face at level 1 (and so its children) left out; background red.
    let text = text.replace(
        "\"multiRes\": {",
        "\"backgroundColor\": [1, 0, 0], \"multiRes\": {\"missingTiles\": \"!f>1\",",
    );
    std::fs::write(&cfg, text).unwrap();
    let mut pano = TiledPanorama::open(dir.path(), 64 << 20, 1).unwrap();
    let mut px = vec![0u32; 64 * 48];
    pano.render_wait(
        View::new(0.0, 0.0, 40.0).unwrap(),
        Sampler::Bilinear,
        3,
        &mut px,
        64,
        48,
    );
    assert!(
        px.iter().all(|&p| p == 0xff0000),
        "front face not background"
    );
    pano.render_wait(
        View::new(180.0, 0.0, 40.0).unwrap(),
        Sampler::Bilinear,
        3,
        &mut px,
        64,
        48,
    );
    assert!(px.iter().all(|&p| p == 0x808080));
    assert!(pano.take_notices().is_empty());
}

#[test]
fn bad_pyramids_are_refused_at_open_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A folder with no configuration.
    let e = TiledPanorama::open(d, 1 << 20, 1).unwrap_err().to_string();
    assert!(
        e.contains("config.json") && e.contains("cannot read"),
        "{e}"
    );
    let good = "{\"type\": \"multires\", \"multiRes\": {\"path\": \"/%l/%s%y_%x\", \"extension\": \"jpg\", \"tileResolution\": 512, \"maxLevel\": 5, \"cubeResolution\": 5216}}";
    for (bad, want) in [
        (good.replace("5216", "1e12"), "cubeResolution"),
        (
            good.replace("\"maxLevel\": 5", "\"maxLevel\": 60"),
            "maxLevel",
        ),
        (good.replace("512,", "0,"), "tileResolution"),
        (good.replace("/%l/%s%y_%x", "/../../%l/%s%y_%x"), "leaves"),
        (good.replace("/%l/%s%y_%x", "/tmp/../%l%s%y_%x"), "leaves"),
    ] {
        std::fs::write(d.join("config.json"), &bad).unwrap();
        let e = TiledPanorama::open(d, 1 << 20, 1).unwrap_err().to_string();
        assert!(e.contains(want) && !e.contains('\n'), "{bad}: {e}");
    }
    // A FIFO as the configuration: refused at once, never waited on.
    #[cfg(unix)]
    {
        let fifo = d.join("fifo.json");
        let ok = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success();
        assert!(ok);
        let e = TiledPanorama::open(&fifo, 1 << 20, 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("not a regular file"), "{e}");
    }
}

/// The pyramid Pannellum's own `generate.py` made of `courtyard-512.jpg`
/// (tests/data/multires/README.md: 160-px faces, 64-px tiles, JPEG q75, nona's and
/// Pillow's Lanczos resampling) read by our reader and drawn from its top level, against
/// the source JPEG drawn directly by the map renderer (bilinear): the same views across
/// tile and face edges and both poles. Required ≥ 28 dB (the tiles are q75 JPEG of a
/// resampled, re-encoded image; both sides bilinear); a face turned or swapped, or tiles
/// placed at the wrong spot, score far lower, as the control view turned 90° shows.
#[test]
fn generate_py_pyramid_renders_like_its_source() {
    let data = test_support::repo_root().join("tests/data/multires");
    let src = lut_core::load_map(
        &data.join("courtyard-512.jpg"),
        &LoadOptions {
            projection: Some(Projection::Equirect),
            ..LoadOptions::default()
        },
        &mut |_| {},
    )
    .expect("courtyard-512");
    let mut map = Panorama::map(src);
    let mut pano = TiledPanorama::open(&data.join("generate-py"), 64 << 20, 2).unwrap();
    let top = pano.config().max_level;
    assert_eq!((pano.config().cube, top), (160, 3));
    let (w, h) = (160, 120);
    let opts = RenderOptions {
        sampler: Sampler::Bilinear,
        ..RenderOptions::default()
    };
    let direct = |map: &mut Panorama, view: View| {
        let mut px = vec![0u32; (w * h) as usize];
        let mut frame = Frame::new(&mut px, w, h).unwrap();
        map.render(view, &opts, &mut frame).unwrap();
        px
    };
    let (mut worst, mut best_wrong) = (f64::INFINITY, 0.0f64);
    for view in views() {
        let mut px = vec![0u32; (w * h) as usize];
        let f = pano.render_wait(view, Sampler::Bilinear, top, &mut px, w, h);
        assert!(!f.coarser(), "{view:?}: drawn coarser");
        let p = psnr(&px, &direct(&mut map, view));
        worst = worst.min(p);
        assert!(p >= 28.0, "{view:?}: {p:.1} dB against the source");
        // Control: the source turned by 90° is far from the tiles.
        let turned = View::new(view.yaw_deg() + 90.0, view.pitch_deg(), view.hfov_deg()).unwrap();
        best_wrong = best_wrong.max(psnr(&px, &direct(&mut map, turned)));
    }
    assert!(pano.take_notices().is_empty());
    assert!(
        best_wrong < worst - 6.0,
        "control {best_wrong:.1} dB, worst {worst:.1} dB"
    );
    eprintln!(
        "generate.py pyramid against its source: worst {worst:.1} dB, control {best_wrong:.1} dB"
    );
}

/// A pyramid whose folder changes while it is open (tiles replaced by other pictures,
/// removed, replaced by garbage, a tile of the wrong size, a FIFO; at last the whole
/// folder removed): tiles held in the cache stay as decoded; a tile decoded again (after
/// eviction) is the file as it is now, or, when it no longer decodes, drawn from its
/// ancestor with one notice. Never a panic, a hang or a hole: every pixel is the old
/// colour or the new one.
#[test]
fn a_folder_changing_while_open_gives_new_tiles_or_the_ancestor_with_a_notice() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("pyr");
    let (old, new) = (0x00_20_60_a0u32, 0x00_c0_40_10u32);
    write_pyramid(&dir, 648, 128, "png", &|_, _, _, w, h| {
        vec![old; (w * h) as usize]
    })
    .unwrap();
    let mut pano = TiledPanorama::open(&dir, 64 << 20, 2).unwrap();
    let top = pano.config().max_level;
    let view = View::new(0.0, 0.0, 60.0).unwrap();
    let (w, h) = (96, 64);
    let mut px = vec![0u32; (w * h) as usize];
    let f = pano.render_wait(view, Sampler::Nearest, top, &mut px, w, h);
    assert!(!f.coarser() && px.iter().all(|&p| p == old));
    let front: Vec<TileId> = f.touched.iter().map(|t| t.0).collect();
    assert!(front.len() >= 4, "{front:?}");
    let path = |id: TileId| dir.join(format!("{}/f{}_{}.png", id.level, id.y, id.x));
    // Every front tile of the top level and the level below replaced by the new colour…
    for level in [top - 1, top] {
        for entry in std::fs::read_dir(dir.join(level.to_string())).unwrap() {
            let p = entry.unwrap().path();
            let (tw, th) = image::image_dimensions(&p).unwrap();
            let c = image::Rgb([(new >> 16) as u8, (new >> 8) as u8, new as u8]);
            image::RgbImage::from_pixel(tw, th, c).save(&p).unwrap();
        }
    }
    // …then four of the frame's top-level tiles broken in different ways.
    std::fs::remove_file(path(front[0])).unwrap();
    std::fs::write(path(front[1]), b"\x89PNG\r\n\x1a\n garbage").unwrap();
    image::RgbImage::new(20, 20).save(path(front[2])).unwrap();
    std::fs::remove_file(path(front[3])).unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(path(front[3]))
        .status()
        .unwrap();
    assert!(made.success());
    // Still cached: the same frame, the old tiles.
    pano.render_wait(view, Sampler::Nearest, top, &mut px, w, h);
    assert!(px.iter().all(|&p| p == old));
    assert!(pano.take_notices().is_empty());
    // Evicted (level 1 is kept), then read again: the new colour where a tile decodes,
    // the ancestor (the new level below) where not, one notice a broken tile.
    pano.store_mut().set_budget(0);
    pano.store_mut().set_budget(64 << 20);
    let f = pano.render_wait(view, Sampler::Nearest, top, &mut px, w, h);
    assert!(f.coarser());
    assert!(
        px.iter().all(|&p| p == new),
        "not every pixel the new colour"
    );
    let notices = pano.take_notices();
    assert_eq!(notices.len(), 4, "{notices:#?}");
    assert!(notices
        .iter()
        .all(|n| !n.contains('\n') && n.contains("drawn from a coarser level")));
    // The whole folder gone: frames drawn from level 1 (kept since the open: the old
    // colour), the tiles not found noticed once each.
    std::fs::remove_dir_all(&dir).unwrap();
    pano.store_mut().set_budget(0);
    pano.store_mut().set_budget(64 << 20);
    for _ in 0..2 {
        let f = pano.render_wait(view, Sampler::Nearest, top, &mut px, w, h);
        assert!(f.coarser());
        assert!(px.iter().all(|&p| p == old));
    }
    let notices = pano.take_notices();
    assert!(!notices.is_empty());
    assert!(
        notices.iter().all(|n| n.contains("cannot read")),
        "{notices:#?}"
    );
}

/// Trilinear between two levels against the analytic footprint: each level a flat colour
/// of its own, so a trilinear frame is flat, the colours of level `l` and `l − 1` mixed by
/// `t = log2(m_l)`, where `m_l = size_l · tan(hfov / 2) / width` is the level's texels per
/// pixel at the centre of a view straight at a face (its face coordinate is `tan` of the
/// angle, scaled by the half face). Tolerance: one level per channel (the weight is
/// rounded to 1/256).
#[test]
fn trilinear_mixes_two_levels_by_the_analytic_footprint() {
    let dir = tempfile::tempdir().unwrap();
    let colours = [
        0x00_10_20_30u32,
        0x00_f0_d0_b0,
        0x00_30_a0_f0,
        0x00_80_ff_00,
    ];
    // Faces of 648: levels of 81, 162, 324 and 648 texels.
    write_pyramid(dir.path(), 648, 128, "png", &|id, _, _, w, h| {
        vec![colours[id.level as usize - 1]; (w * h) as usize]
    })
    .unwrap();
    let sizes = [81.0, 162.0, 324.0, 648.0];
    let mut pano = TiledPanorama::open(dir.path(), 64 << 20, 2).unwrap();
    let (w, h) = (64u32, 48u32);
    let ch = |c: u32, k: u32| f64::from((c >> k) & 0xff);
    // (level, its texels per pixel) → hfov, and the expected pair and weight.
    for (level, m) in [
        (2usize, 1.1892),
        (3, 1.5),
        (4, 1.9),
        (3, 1.0),
        (4, 0.5),
        (1, 1.6),
    ] {
        let hfov = 2.0 * (m * f64::from(w) / sizes[level - 1]).atan().to_degrees();
        for yaw in [0.0, 90.0, 180.0] {
            let view = View::new(yaw, 0.0, hfov).unwrap();
            let mut px = vec![0u32; (w * h) as usize];
            let (fine, tw) = lut_core::tile_trilinear_levels(pano.store(), view, w, h, false);
            pano.render_trilinear(view, fine, tw, &mut px, w, h, true);
            // Level 1 has no coarser level; a magnified top level no finer one.
            let t: f64 = if level == 1 || m < 1.0 { 0.0 } else { m.log2() };
            let (a, b) = (colours[level - 1], colours[level.saturating_sub(2)]);
            for &p in &px {
                for k in [0, 8, 16] {
                    let want = ch(a, k) * (1.0 - t) + ch(b, k) * t;
                    assert!(
                        (ch(p, k) - want).abs() <= 1.0,
                        "level {level}, m {m}, yaw {yaw}: {p:06x}, channel {k} wants {want:.1}"
                    );
                }
            }
        }
    }
}

/// A frame drawn (waiting) from one level holds only that level's texels, across the
/// level's tile edges too: each level a flat colour of its own, so any texel read from
/// an ancestor (a border filled before its neighbour was decoded and never refilled)
/// shows. Views straight at faces and oblique, nearest and bilinear, every level.
#[test]
fn a_waited_frame_reads_only_its_own_level_across_tile_edges() {
    let dir = tempfile::tempdir().unwrap();
    let colours = [
        0x00_10_20_30u32,
        0x00_f0_d0_b0,
        0x00_30_a0_f0,
        0x00_80_ff_00,
    ];
    // Faces of 648 in tiles of 128: the last tile of a row is short (8 texels at the top).
    write_pyramid(dir.path(), 648, 128, "png", &|id, _, _, w, h| {
        vec![colours[id.level as usize - 1]; (w * h) as usize]
    })
    .unwrap();
    let (w, h) = (64u32, 48u32);
    for level in 1..=4u32 {
        for (yaw, pitch, hfov) in [(0.0, 0.0, 21.26), (37.0, 20.0, 60.0), (180.0, -44.0, 90.0)] {
            for sampler in [Sampler::Nearest, Sampler::Bilinear] {
                // A fresh open each time: nothing decoded but level 1.
                let mut pano = TiledPanorama::open(dir.path(), 64 << 20, 2).unwrap();
                let view = View::new(yaw, pitch, hfov).unwrap();
                let mut px = vec![0u32; (w * h) as usize];
                pano.render_wait(view, sampler, level, &mut px, w, h);
                let want = colours[level as usize - 1];
                let bad = px.iter().filter(|&&p| p != want).count();
                assert_eq!(
                    bad, 0,
                    "level {level}, view {yaw},{pitch},{hfov}, {sampler:?}: {bad} pixels not {want:06x}, e.g. {:06x}",
                    px.iter().find(|&&p| p != want).unwrap()
                );
            }
        }
    }
}

/// Marzipano's cube geometry, ported from its `src/geometries/Cube.js` and
/// `src/views/Rectilinear.js` (google/marzipano 7936a4e): texel `(i, j)` of face
/// `letter` on a level of `size` texels is the vertex `(x, y, −½)`, `x = (i + ½)/size − ½`,
/// `y = ½ − (j + ½)/size`, rotated about X then Y by the face's `faceRotation`; its
/// coordinates are `yaw = atan2(x, −z)`, `pitch = acos(y / r) − π/2` (positive down,
/// `screenToCoordinates`). Returned in this project's world (yaw right, pitch up: our
/// direction `(cos p · sin y, sin p, cos p · cos y)` with `p = −pitch`). `mirror` mirrors
/// `x` (a control: a face written the wrong way round).
fn marzipano_dir(letter: char, size: u32, i: f64, j: f64, mirror: bool) -> glam::DVec3 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let (rx, ry) = match letter {
        'f' => (0.0, 0.0),
        'b' => (0.0, PI),
        'l' => (0.0, FRAC_PI_2),
        'r' => (0.0, -FRAC_PI_2),
        'u' => (FRAC_PI_2, 0.0),
        'd' => (-FRAC_PI_2, 0.0),
        _ => unreachable!(),
    };
    let mut x = (i + 0.5) / size as f64 - 0.5;
    if mirror {
        x = -x;
    }
    let (y, z) = (0.5 - (j + 0.5) / size as f64, -0.5);
    // gl-matrix vec3.rotateX, then vec3.rotateY, about the origin.
    let (y, z) = (y * rx.cos() - z * rx.sin(), y * rx.sin() + z * rx.cos());
    let (x, z) = (z * ry.sin() + x * ry.cos(), z * ry.cos() - x * ry.sin());
    let r = (x * x + y * y + z * z).sqrt();
    let (yaw, pitch) = (x.atan2(-z), (y / r).acos() - FRAC_PI_2);
    let p = -pitch;
    glam::DVec3::new(p.cos() * yaw.sin(), p.sin(), p.cos() * yaw.cos())
}

/// Uneven Marzipano levels as `(tileSize, size, fallbackOnly)`: a 32-px preview
/// (fallback only), then 96 (tiles of 48: three times the preview), 192 (tiles of 64),
/// 320 (tiles of 64: 5/3 of its parent, which Marzipano itself would refuse; drawn here).
const MARZIPANO_LEVELS: [(u32, u32, bool); 4] = [
    (32, 32, true),
    (48, 96, false),
    (64, 192, false),
    (64, 320, false),
];

/// A Marzipano scene written with Marzipano's own geometry ([`marzipano_dir`]) from the
/// cubes `CubeMap::from_envmap` makes of `map` at each level's size: each texel the
/// nearest texel of that cube in the texel's Marzipano direction (the very texel when our
/// reading of Marzipano's faces is right), lossless; level 0 as `preview.jpg`.
fn marzipano_from_map(dir: &Path, map: &EnvMap, mirror: bool) -> Vec<CubeMap> {
    let cubes: Vec<CubeMap> = MARZIPANO_LEVELS
        .iter()
        .map(|l| CubeMap::from_envmap(map, l.1, Sampler::Bilinear).unwrap())
        .collect();
    let levels: Vec<(u32, u32)> = MARZIPANO_LEVELS.iter().map(|l| (l.0, l.1)).collect();
    lut_core::write_marzipano(dir, &levels, true, None, &|z, f, x0, y0, w, h| {
        let (cube, size) = (&cubes[z as usize], MARZIPANO_LEVELS[z as usize].1);
        (y0..y0 + h)
            .flat_map(|j| (x0..x0 + w).map(move |i| (i, j)))
            .map(|(i, j)| {
                let d = marzipano_dir(f, size, i as f64, j as f64, mirror);
                cube.sample_dir(Sampler::Nearest, d)
            })
            .collect()
    })
    .unwrap();
    cubes
}

/// A Marzipano scene (uneven levels, a preview strip, tiles of two sizes) read through the
/// second reader renders, at every level, the views of the cube it was cut from (≥ 45 dB:
/// the same texels); the same scene written with each face mirrored scores far lower, so
/// the faces' letters and orientation are Marzipano's. The fallback-only preview is never
/// the level a frame is drawn at.
#[test]
fn a_marzipano_scene_renders_its_levels_cubes() {
    let map = courtyard();
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tiles/0-courtyard");
    let cubes = marzipano_from_map(&scene, &map, false);
    let mirrored = dir.path().join("tiles/mirrored");
    marzipano_from_map(&mirrored, &map, true);
    let open = |root: &Path| {
        let cfg = lut_core::MultiresConfig::marzipano(
            &dir.path().join("data.js"),
            root,
            &MARZIPANO_LEVELS,
        )
        .unwrap();
        TiledPanorama::with_config(cfg, 256 << 20, 2)
    };
    let (mut pano, mut wrong) = (open(&scene), open(&mirrored));
    assert_eq!(
        (
            pano.config().cube,
            pano.config().max_level,
            pano.config().first_level()
        ),
        (320, 4, 2)
    );
    let (w, h) = (160, 120);
    let (mut worst, mut best_wrong) = (f64::INFINITY, 0.0f64);
    for view in views() {
        for (l, cube) in cubes.iter().enumerate() {
            let level = l as u32 + 1;
            let mut px = vec![0u32; (w * h) as usize];
            let f = pano.render_wait(view, Sampler::Bilinear, level, &mut px, w, h);
            assert!(!f.coarser(), "{view:?} level {level}: drawn coarser");
            let want = cube_frame(cube, view, w, h);
            let p = psnr(&px, &want);
            worst = worst.min(p);
            assert!(p >= 45.0, "{view:?} level {level}: {p:.1} dB");
            let mut bad = vec![0u32; (w * h) as usize];
            wrong.render_wait(view, Sampler::Bilinear, level, &mut bad, w, h);
            best_wrong = best_wrong.max(psnr(&bad, &want));
        }
        // A frame never picks the fallback-only preview: a 4 × 3 frame has 8 preview
        // texels a pixel (level 1 without the rule), and is drawn from level 2, not
        // blended with the preview.
        for still in [true, false] {
            assert_eq!(
                lut_core::tile_frame_level(pano.store(), view, 4, 3, still),
                2
            );
            assert_eq!(
                lut_core::tile_trilinear_levels(pano.store(), view, 4, 3, still),
                (2, 0.0)
            );
        }
    }
    assert!(pano.take_notices().is_empty());
    assert!(best_wrong < 30.0, "mirrored faces score {best_wrong:.1} dB");
    eprintln!("Marzipano tiles against their cubes: worst {worst:.1} dB, mirrored faces {best_wrong:.1} dB");
}

/// A flat Marzipano scene with uneven levels and tiles of three sizes (the preview
/// strip, 48, 64) is exactly flat at every level, nearest and bilinear, across every tile
/// and face edge, both in frames that wait for their tiles and in frames drawn at once
/// from whatever is decoded (tiles of the wanted level missing: drawn from ancestors of
/// another tile size, borders filled from them): no hole, no background, no read out of
/// a tile's buffer (a panic). (Where texels land is the test above's: a flat scene
/// cannot show it.)
#[test]
fn a_flat_marzipano_scene_is_flat_across_levels_of_different_tile_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("tiles/flat");
    let c = 0x00_4a_91_c3;
    let levels: Vec<(u32, u32)> = MARZIPANO_LEVELS.iter().map(|l| (l.0, l.1)).collect();
    lut_core::write_marzipano(&scene, &levels, true, None, &|_, _, _, _, w, h| {
        vec![c; (w * h) as usize]
    })
    .unwrap();
    let cfg =
        lut_core::MultiresConfig::marzipano(&dir.path().join("data.js"), &scene, &MARZIPANO_LEVELS)
            .unwrap();
    let flat = |px: &[u32], what: &str| {
        let bad: Vec<(usize, u32)> = px
            .iter()
            .copied()
            .enumerate()
            .filter(|&(_, p)| p != c)
            .collect();
        assert!(bad.is_empty(), "{what}: {bad:x?}");
    };
    // At once: a fresh pyramid (only the preview decoded), each frame at the top level.
    let mut pano = TiledPanorama::with_config(cfg.clone(), 64 << 20, 2);
    for view in views() {
        for sampler in [Sampler::Nearest, Sampler::Bilinear] {
            let mut px = vec![0u32; 97 * 61];
            pano.render(view, sampler, 4, &mut px, 97, 61, true);
            flat(&px, &format!("{view:?} at once {sampler:?}"));
        }
    }
    let mut pano = TiledPanorama::with_config(cfg, 64 << 20, 2);
    for view in views() {
        for level in 1..=4 {
            for sampler in [Sampler::Nearest, Sampler::Bilinear] {
                let mut px = vec![0u32; 97 * 61];
                let f = pano.render_wait(view, sampler, level, &mut px, 97, 61);
                assert!(!f.coarser(), "{view:?} level {level}");
                flat(&px, &format!("{view:?} level {level} {sampler:?}"));
            }
        }
    }
    assert!(pano.take_notices().is_empty());
}

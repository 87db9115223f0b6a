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

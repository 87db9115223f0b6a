//! A tiled pyramid's `config.json` (`MultiresConfig::parse`: the JSON, the limits of
//! `lut_core::limits`, the path templates, `missingTiles`; `open` adds the containment,
//! left out here so that a panic is a finding). No tile is opened.
#![no_main]
use libfuzzer_sys::fuzz_target;
use lut_core::limits::{
    MAX_BASE_TILES, MAX_CUBE_RESOLUTION, MAX_TILE_LEVELS, MAX_TILE_RESOLUTION, MIN_TILE_RESOLUTION,
};
use lut_core::{Face, MultiresConfig, TileId};
use std::path::{Component, Path};

fuzz_target!(|data: &[u8]| {
    let dir = Path::new("pyramid");
    match MultiresConfig::parse(data, &dir.join("config.json"), dir) {
        Ok(cfg) => {
            // Within every limit.
            assert!((MIN_TILE_RESOLUTION..=MAX_TILE_RESOLUTION).contains(&cfg.tile));
            assert!((1..=MAX_CUBE_RESOLUTION).contains(&cfg.cube));
            assert!((1..=MAX_TILE_LEVELS).contains(&cfg.max_level));
            assert!(cfg.level_size(1) >= 1);
            assert!(cfg.tiles_across(1) <= MAX_BASE_TILES);
            assert!(cfg.missing_count() as u64 <= cfg.tile_count());
            // Every tile and fallback file lies inside the pyramid's folder.
            let inside = |p: &Path| {
                assert!(p.starts_with(dir), "{p:?} outside the folder");
                assert!(
                    !p.components().any(|c| matches!(c, Component::ParentDir)),
                    "{p:?} leaves the folder"
                );
            };
            for level in [1, cfg.max_level] {
                let n = cfg.tiles_across(level);
                assert!(n >= 1);
                for face in [Face::Front, Face::Down] {
                    for (x, y) in [(0, 0), (n - 1, n - 1)] {
                        let id = TileId {
                            level: level as u8,
                            face,
                            y,
                            x,
                        };
                        let (w, h) = cfg.tile_dims(id);
                        assert!(w >= 1 && h >= 1 && w <= cfg.tile && h <= cfg.tile);
                        inside(&cfg.tile_path(id));
                        let _ = cfg.is_missing(id);
                    }
                }
                if let Some(f) = cfg.fallback_path(Face::Up) {
                    inside(&f);
                }
            }
        }
        Err(e) => {
            // The message as the viewer prints it: one line, no control character.
            let line = lut_core::one_line(&e.to_string());
            lutpano_fuzz::assert_safe(&line);
            assert!(line.chars().count() <= lut_core::MESSAGE_MAX_CHARS + 40);
        }
    }
});

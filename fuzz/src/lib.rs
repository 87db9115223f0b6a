//! What the fuzz targets share: how the photometric parsers read bytes, the check that
//! their messages are safe for a terminal, and map decoding through lut-core's loader
//! with a small pixel limit.

use image::ImageFormat;
use lut_core::{EnvMap, LoadOptions, Projection};

/// The pixel limit of the map targets (2^18): small, so a header claiming a huge image is
/// refused at once and the fuzzer spends its time in the decoders.
pub const MAX_PIXELS: u64 = 1 << 18;

/// As the library reads photometric files: UTF-8 when valid, else ISO-8859-1.
pub fn text(data: &[u8]) -> String {
    match std::str::from_utf8(data) {
        Ok(s) => s.to_string(),
        Err(_) => data.iter().map(|&b| char::from(b)).collect(),
    }
}

/// A message quoting a file's bytes must carry no control character (escape sequences,
/// line breaks) to the terminal.
pub fn assert_safe(msg: &str) {
    assert!(
        !msg.chars().any(char::is_control),
        "raw control character in {msg:?}"
    );
}

/// The loader's options of the map targets: any aspect ratio (elliptical), the small
/// pixel limit.
pub fn map_options() -> LoadOptions {
    LoadOptions {
        projection: Some(Projection::Elliptical),
        max_pixels: MAX_PIXELS,
        ..LoadOptions::default()
    }
}

/// Decodes `data` as a map through lut-core's loader when `image` takes it for `format`
/// (the other inputs are skipped: each target stays in its own decoder). A map that loads
/// must have a size inside the limit. Returns whether the input was of `format`.
pub fn fuzz_map(data: &[u8], format: ImageFormat) -> bool {
    if image::guess_format(data).ok() != Some(format) {
        return false;
    }
    if let Ok(m) = lut_core::decode_map(data, "fuzz", &map_options(), &mut |_| {}) {
        check_map(&m);
    }
    true
}

fn check_map(m: &EnvMap) {
    assert!(m.width() >= 1 && m.height() >= 1);
    assert!(u64::from(m.width()) * u64::from(m.height()) <= MAX_PIXELS);
}

/// What the tour targets demand of a tour read from `path` (either format): within the
/// limits, every angle finite, every problem one safe line, and the Pannellum config it
/// is saved as reads back as a tour that saves to the same text. A Marzipano tour's
/// first save leaves its tile scenes out (Pannellum has no form for them), so for it
/// (`resave`) the test starts from the second save.
pub fn check_tour(r: anyhow::Result<viewer::tour::Loaded>, path: &std::path::Path, resave: bool) {
    use viewer::tour::{self, pannellum, HotspotKind, TargetAngle};
    let loaded = match r {
        Ok(l) => l,
        Err(e) => {
            let line = lut_core::one_line(&format!("{e:#}"));
            assert_safe(&line);
            assert!(line.chars().count() <= lut_core::MESSAGE_MAX_CHARS + 40);
            return;
        }
    };
    let t = &loaded.tour;
    assert!(t.scenes.len() <= lut_core::limits::MAX_TOUR_SCENES);
    for s in &t.scenes {
        assert!(s.hotspots.len() <= lut_core::limits::MAX_TOUR_HOTSPOTS);
        let a = s.start;
        assert!(
            a.yaw.is_finite() && a.pitch.is_finite() && a.hfov.is_finite(),
            "{a:?}"
        );
        assert!(s.north_offset.is_finite());
        assert!(s.horizon.pitch.is_finite() && s.horizon.roll.is_finite());
        for h in &s.hotspots {
            assert!(h.yaw.is_finite() && h.pitch.is_finite(), "{h:?}");
            if let HotspotKind::Scene { target, .. } = &h.kind {
                for v in [target.yaw, target.pitch, target.hfov] {
                    if let TargetAngle::Value(v) = v {
                        assert!(v.is_finite());
                    }
                }
            }
        }
    }
    // A Marzipano scene's levels as the pyramid reader takes them (what opening the scene
    // does with them): refused with one safe line, or a description within the limits.
    for s in &t.scenes {
        if let tour::Source::MarzipanoTiles { levels, .. } = &s.source {
            let root = std::path::Path::new("tour/tiles/scene");
            match lut_core::MultiresConfig::marzipano(path, root, levels) {
                Ok(cfg) => {
                    let limits = lut_core::limits::MIN_TILE_RESOLUTION
                        ..=lut_core::limits::MAX_TILE_RESOLUTION;
                    assert!((1..=lut_core::limits::MAX_CUBE_RESOLUTION).contains(&cfg.cube));
                    assert!((1..=lut_core::limits::MAX_TILE_LEVELS).contains(&cfg.max_level));
                    for level in 1..=cfg.max_level {
                        let n = cfg.tiles_across(level);
                        assert!(n >= 1 && cfg.level_size(level) >= 1);
                        let tile = cfg.tile_size(level);
                        assert!(
                            limits.contains(&tile) || tile == cfg.level_size(level),
                            "{tile}"
                        );
                        let id = lut_core::TileId {
                            level: level as u8,
                            face: lut_core::Face::Down,
                            y: n - 1,
                            x: n - 1,
                        };
                        let (w, h) = cfg.tile_dims(id);
                        assert!(w >= 1 && h >= 1 && w <= tile && h <= tile);
                        assert!(cfg.tile_path(id).starts_with(root));
                    }
                }
                Err(e) => {
                    let line = lut_core::one_line(&e.to_string());
                    assert_safe(&line);
                    assert!(line.chars().count() <= lut_core::MESSAGE_MAX_CHARS + 40);
                }
            }
        }
    }
    for p in &loaded.problems {
        let line = p.to_string();
        assert_safe(&line);
        assert!(line.chars().count() <= lut_core::MESSAGE_MAX_CHARS + 40);
    }
    // Saved as Pannellum, read back, saved again: the same text.
    let saved = std::path::Path::new("tour/saved.json");
    let (mut text, _) = pannellum::to_text(t);
    if resave {
        let back = tour::parse(text.as_bytes(), saved)
            .unwrap_or_else(|e| panic!("its own Pannellum config does not read: {e:#}\n{text}"));
        text = pannellum::to_text(&back.tour).0;
    }
    let back = tour::parse(text.as_bytes(), saved)
        .unwrap_or_else(|e| panic!("its own Pannellum config does not read: {e:#}\n{text}"));
    let (again, _) = pannellum::to_text(&back.tour);
    assert_eq!(again, text, "saving is not stable (read from {path:?})");
}

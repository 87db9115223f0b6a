//! The pyramid's geometry and names exactly as Pannellum's `utils/multires/generate.py`
//! computes them: the cube face size, the tile size, the number of levels (with its edge
//! case), the level sizes (`int(size / 2)` each), the tile names, the face letters, the
//! `missingTiles` string and the `config.json` text.

use lut_core::Face;

/// Pannellum's face letters in the generator's order (f, b, u, d, l, r) and our faces.
/// (Checked against the faces `nona` makes for generate.py: f looks at yaw 0, b at yaw
/// 180, u straight up with the front face's edge at its bottom, d straight down, l at yaw
/// −90, r at yaw +90: exactly the conventions' faces of the same names.)
pub const FACES: [(char, Face); 6] = [
    ('f', Face::Front),
    ('b', Face::Back),
    ('u', Face::Up),
    ('d', Face::Down),
    ('l', Face::Left),
    ('r', Face::Right),
];

/// Pannellum's default tile size (generate.py `--tilesize`).
pub const DEFAULT_TILE_SIZE: u32 = 512;
/// Pannellum's default fallback face size (generate.py `--fallbacksize`).
pub const DEFAULT_FALLBACK_SIZE: u32 = 1024;
/// generate.py's default JPEG quality (`--quality`).
pub const DEFAULT_QUALITY: u8 = 75;
/// generate.py's default starting hfov written to the config (`--hfov`).
pub const DEFAULT_HFOV: f64 = 100.0;
/// The largest cube face this generator writes (a 1.4-million-pixel-wide equirect).
pub const MAX_CUBE_SIZE: u32 = 1 << 19;

/// The geometry of one pyramid.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// The full-resolution face side (`cubeResolution`).
    pub cube_size: u32,
    /// The tile side (`tileResolution`): `min(--tile-size, cube_size)`.
    pub tile_size: u32,
    /// The number of levels (`maxLevel`); level `max_level` is the full face.
    pub max_level: u32,
}

/// generate.py's cube face side for an equirect `width` pixels wide covering `haov`
/// degrees: `8 * int((360 / haov) * width / pi / 8)`.
pub fn cube_size_for(width: u64, haov: f64) -> u64 {
    let s = (360.0 / haov) * width as f64 / std::f64::consts::PI / 8.0;
    8 * (s.floor().max(0.0) as u64)
}

impl Layout {
    /// The layout for faces of `cube_size` and tiles of `tile_size` (generate.py:
    /// `tileSize = min(tilesize, cubeSize)`, `levels = ceil(log(cube/tile, 2)) + 1`,
    /// minus one when `int(cubeSize / 2**(levels - 2)) == tileSize`).
    ///
    /// # Errors
    /// A message for a zero or too large size.
    pub fn new(cube_size: u64, tile_size: u32) -> Result<Layout, String> {
        if cube_size == 0 {
            return Err("the cube face would be 0 pixels (the input is too small: a face needs an equirect at least 26 pixels wide)".into());
        }
        if cube_size > u64::from(MAX_CUBE_SIZE) {
            return Err(format!(
                "the cube face would be {cube_size} pixels, above the {MAX_CUBE_SIZE} this generator writes"
            ));
        }
        if tile_size == 0 {
            return Err("the tile size must be at least 1 pixel".into());
        }
        let cube = cube_size as u32;
        let tile = tile_size.min(cube);
        // Python's math.log(x, 2) is log(x) / log(2), not log2: the same rounding here.
        let ratio = f64::from(cube) / f64::from(tile);
        let mut levels = (ratio.ln() / 2f64.ln()).ceil() as i64 + 1;
        // int(cubeSize / 2**(levels - 2)): for levels == 1 that is cube * 2.
        let at = if levels >= 2 {
            f64::from(cube) / 2f64.powi((levels - 2) as i32)
        } else {
            f64::from(cube) * 2f64.powi((2 - levels) as i32)
        };
        if at.floor() as u64 == u64::from(tile) {
            levels -= 1;
        }
        Ok(Layout {
            cube_size: cube,
            tile_size: tile,
            max_level: levels.max(1) as u32,
        })
    }

    /// The face side of level `level` (1..=max_level): `int(size / 2)` per level down.
    pub fn level_size(&self, level: u32) -> u32 {
        let mut s = self.cube_size;
        for _ in level..self.max_level {
            s /= 2;
        }
        s
    }

    /// Tiles per row (and column) at `level`: `ceil(size / tile)`.
    pub fn tiles_per_side(&self, level: u32) -> u32 {
        self.level_size(level).div_ceil(self.tile_size)
    }

    /// The number of tiles in the pyramid (all faces and levels).
    pub fn tile_count(&self) -> u64 {
        (1..=self.max_level)
            .map(|l| 6 * u64::from(self.tiles_per_side(l)).pow(2))
            .sum()
    }
}

/// The relative path of a tile: `LEVEL/{letter}{row}_{col}.EXT` (the config's
/// `"/%l/%s%y_%x"`).
pub fn tile_path(level: u32, letter: char, row: u32, col: u32, ext: &str) -> String {
    format!("{level}/{letter}{row}_{col}.{ext}")
}

const B83: &[u8] =
    b"0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz#$%*+,-.:;=?@[]^_{|}~";

fn b83(val: u64, length: u32, out: &mut String) {
    for i in 1..=length {
        let d = (val / 83u64.pow(length - i)) % 83;
        out.push(B83[d as usize] as char);
    }
}

/// A tile generate.py leaves out: `(face index in FACES order, level, x, y)`.
pub type MissingTile = (usize, u32, u32, u32);

/// generate.py's `missingTiles` string for tiles that were not written (uniform
/// background): children of missing tiles dropped, sorted, `!face` when the face changes,
/// `>level` when the level changes (base 83), each tile's x and y in base 83 with as many
/// digits as the level's largest tile number needs (none for a one-tile level). The
/// quirks are kept (the level is not repeated after a face change at the same level),
/// since Pannellum's reader parses exactly this.
pub fn missing_tiles_string(layout: &Layout, missing: &[MissingTile]) -> String {
    let mut list: Vec<MissingTile> = missing.to_vec();
    let mut children = Vec::new();
    for &(f, l, x, y) in &list {
        children.push((f, l + 1, x * 2, y * 2));
        children.push((f, l + 1, x * 2, y * 2 + 1));
        children.push((f, l + 1, x * 2 + 1, y * 2));
        children.push((f, l + 1, x * 2 + 1, y * 2 + 1));
    }
    for c in children {
        if let Some(i) = list.iter().position(|t| *t == c) {
            list.remove(i);
        }
    }
    list.sort();
    let mut s = String::new();
    let (mut prev_face, mut prev_level) = (None, None);
    let mut digits = 0;
    for &(f, l, x, y) in &list {
        if prev_face != Some(f) {
            s.push('!');
            s.push(FACES[f].0);
        }
        if prev_level != Some(l) {
            s.push('>');
            b83(u64::from(l), 1, &mut s);
            let tiles = (f64::from(layout.cube_size)
                / 2f64.powi((layout.max_level - l) as i32)
                / f64::from(layout.tile_size))
            .ceil()
                - 1.0;
            digits = ((tiles + 1.0).ln() / 83f64.ln()).ceil() as u32;
        }
        b83(u64::from(x), digits, &mut s);
        b83(u64::from(y), digits, &mut s);
        prev_face = Some(f);
        prev_level = Some(l);
    }
    s
}

/// What the config says besides the layout.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigExtras {
    /// The starting hfov (generate.py `--hfov`, default 100).
    pub hfov: f64,
    /// Tile file extension: `jpg` or `png`.
    pub extension: &'static str,
    /// Fallback faces written.
    pub fallback: bool,
    /// The `missingTiles` string (empty: none).
    pub missing_tiles: String,
}

/// Python's `str(float)` for the values a config holds (shortest repr, `.0` on integers).
fn py_float(v: f64) -> String {
    if v.is_finite() && v == v.trunc() && v.abs() < 1e16 {
        format!("{v:.1}")
    } else {
        format!("{v}")
    }
}

/// The `config.json` text generate.py writes for a full panorama, byte for byte (four
/// spaces, no final line break).
pub fn config_text(layout: &Layout, extras: &ConfigExtras) -> String {
    let mut t = vec![
        "{".to_string(),
        format!("    \"hfov\": {},", py_float(extras.hfov)),
        "    \"type\": \"multires\",".to_string(),
        "    \"multiRes\": {".to_string(),
    ];
    if !extras.missing_tiles.is_empty() {
        t.push(format!(
            "        \"missingTiles\": \"{}\",",
            extras.missing_tiles
        ));
    }
    t.push("        \"path\": \"/%l/%s%y_%x\",".to_string());
    if extras.fallback {
        t.push("        \"fallbackPath\": \"/fallback/%s\",".to_string());
    }
    t.push(format!("        \"extension\": \"{}\",", extras.extension));
    t.push(format!("        \"tileResolution\": {},", layout.tile_size));
    t.push(format!("        \"maxLevel\": {},", layout.max_level));
    t.push(format!("        \"cubeResolution\": {}", layout.cube_size));
    t.push("    }".to_string());
    t.push("}".to_string());
    t.join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_follow_generate_py() {
        assert_eq!(cube_size_for(512, 360.0), 160);
        assert_eq!(cube_size_for(32768, 360.0), 10424);
        assert_eq!(cube_size_for(1024, 360.0), 320);
        let l = Layout::new(160, 64).unwrap();
        assert_eq!((l.cube_size, l.tile_size, l.max_level), (160, 64, 3));
        assert_eq!(
            (1..=3).map(|k| l.level_size(k)).collect::<Vec<_>>(),
            [40, 80, 160]
        );
        assert_eq!(l.tile_count(), 6 * (1 + 4 + 9));
        // 648 px with 128-px tiles: six tiles, the last 8 px.
        let l = Layout::new(648, 128).unwrap();
        assert_eq!(l.tiles_per_side(l.max_level), 6);
        // The tile larger than the face: one level, the tile the face.
        let l = Layout::new(160, 512).unwrap();
        assert_eq!((l.tile_size, l.max_level), (160, 1));
        // Exact powers of two: levels = log2 + 1 (the edge case removes the extra level
        // a rounding up of the logarithm would add).
        let l = Layout::new(4096, 512).unwrap();
        assert_eq!(l.max_level, 4);
        assert_eq!(l.level_size(1), 512);
        // 10424 / 512 = 20.4: five levels, 10424, 5212, 2606, 1303, 651.
        let l = Layout::new(10424, 512).unwrap();
        assert_eq!(l.max_level, 6);
        assert_eq!(l.level_size(1), 325);
        assert!(Layout::new(0, 512).is_err());
        assert!(Layout::new(1 << 20, 512).is_err());
        assert!(Layout::new(64, 0).is_err());
    }

    #[test]
    fn levels_match_generate_py_for_many_sizes() {
        // generate.py's rule transcribed independently (Python semantics) for a sweep.
        for cube in (8..3000u32).step_by(8) {
            for tile in [1u32, 7, 64, 100, 128, 256, 500, 512, 1024] {
                let t = tile.min(cube);
                let mut levels =
                    ((f64::from(cube) / f64::from(t)).ln() / 2f64.ln()).ceil() as i32 + 1;
                if (f64::from(cube) / 2f64.powi(levels - 2)).floor() as u32 == t {
                    levels -= 1;
                }
                let l = Layout::new(u64::from(cube), tile).unwrap();
                assert_eq!(l.max_level as i32, levels, "cube {cube} tile {tile}");
                // the coarsest level fits in one tile (what makes the pyramid complete)
                assert_eq!(l.tiles_per_side(1), 1, "cube {cube} tile {tile}");
            }
        }
    }

    #[test]
    fn missing_tiles_encode_as_generate_py() {
        let l = Layout::new(160, 64).unwrap();
        // Face u level 1 (one tile: no digits), its children at level 2 dropped, a lone
        // tile of face d at level 3 (3 tiles per side: one digit each).
        let missing = [(2, 1, 0, 0), (2, 2, 0, 0), (2, 2, 1, 1), (3, 3, 2, 1)];
        assert_eq!(missing_tiles_string(&l, &missing), "!u>1!d>321");
        // The level is not repeated after a face change at the same level (as generate.py).
        let missing = [(0, 3, 1, 2), (1, 3, 0, 0)];
        assert_eq!(missing_tiles_string(&l, &missing), "!f>312!b00");
    }

    #[test]
    fn config_is_generate_py_text() {
        let l = Layout::new(160, 64).unwrap();
        let extras = ConfigExtras {
            hfov: DEFAULT_HFOV,
            extension: "jpg",
            fallback: true,
            missing_tiles: String::new(),
        };
        let want = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../tests/data/multires/generate-py/config.json"),
        )
        .unwrap();
        assert_eq!(config_text(&l, &extras), want);
    }
}

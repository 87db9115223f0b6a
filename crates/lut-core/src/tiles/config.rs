//! Pannellum's `multires` configuration: parsing, validation with stated limits, and the
//! pyramid's geometry (level sizes, tile grids, tile files).
//!
//! The format, as Pannellum's `utils/multires/generate.py` writes it and its
//! `src/js/libpannellum.js` reads it:
//! ```json
//! { "type": "multires",
//!   "multiRes": { "path": "/%l/%s%y_%x", "fallbackPath": "/fallback/%s", "extension": "jpg",
//!                 "tileResolution": 512, "maxLevel": 6, "cubeResolution": 8432,
//!                 "missingTiles": "!f>3000100..." } }
//! ```
//! Level `maxLevel` is the full face (`cubeResolution` texels); each level below has
//! `int(size / 2)` of the one above (so sides are not powers of two), down to level 1.
//! A level's face is cut into `ceil(size / tileResolution)²` tiles, row `%y`, column `%x`;
//! the last tile of a row (and the last row) is short: `size − (n − 1) · tileResolution`.
//! Face letters `f b u d l r` are our front, back, up, down, left and right faces in the
//! same orientation (each an unrotated hfov-90° view, `docs/cube.md`). `%l0` is the level
//! minus one. `basePath` (a prefix of the path) and `backgroundColor` (`[r, g, b]`, 0..1)
//! are top-level keys; `haov`/`vaov` (a partial panorama) only mark which tiles the
//! generator left out, which `missingTiles` lists (base 83: `!` face letter, `>` a level
//! digit, then `x y` pairs of ⌈log83(tiles)⌉ digits each; the level carries over to the
//! next face when unchanged, as the generator writes it).

use crate::cube::Face;
use std::collections::HashSet;
use std::path::{Component, Path, PathBuf};

/// The largest `cubeResolution` accepted: 2²¹ = 2,097,152 texels a face (an equirect
/// some 6.6 million pixels wide, 20 times the published 365-gigapixel record's).
pub const MAX_CUBE_RESOLUTION: u32 = 1 << 21;
/// `tileResolution` must lie in 16..=8192.
pub const MIN_TILE_RESOLUTION: u32 = 16;
/// See [`MIN_TILE_RESOLUTION`].
pub const MAX_TILE_RESOLUTION: u32 = 8192;
/// `maxLevel` at most 24 (the generator writes ⌈log2(cube / tile)⌉ + 1, 18 at most for
/// the limits above).
pub const MAX_LEVELS: u32 = 24;
/// The configuration file is read up to 64 MiB (a long `missingTiles` list or an inline
/// thumbnail fit many times over).
pub const MAX_CONFIG_BYTES: u64 = 64 << 20;
/// Level 1 is loaded whole at open: at most 8 × 8 tiles a face.
pub const MAX_BASE_TILES: u32 = 8;
/// Most tiles `missingTiles` may list (a set of them is held: 4 Mi ids are about
/// 100 MiB; a 64 MiB configuration could otherwise list 32 million, over 1 GB).
pub const MAX_MISSING_TILES: usize = 4 << 20;

/// A pyramid could not be opened: the file (or value) and the reason, on one line.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{path}: {reason}")]
pub struct TilesError {
    /// The configuration file (or the folder, or the tile).
    pub path: PathBuf,
    /// Why.
    pub reason: String,
}

impl From<crate::guard::DecoderPanic> for TilesError {
    fn from(p: crate::guard::DecoderPanic) -> TilesError {
        TilesError {
            path: p.path.clone(),
            reason: format!(
                "the file is damaged or of a kind the reader cannot handle (it failed on it: {})",
                p.message
            ),
        }
    }
}

impl TilesError {
    pub(crate) fn new(path: &Path, reason: impl Into<String>) -> TilesError {
        TilesError {
            path: path.to_path_buf(),
            reason: reason.into(),
        }
    }
}

/// One tile of the pyramid: level (1 = coarsest), face, row, column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TileId {
    /// 1..=maxLevel.
    pub level: u8,
    /// The cube face.
    pub face: Face,
    /// Row (`%y`).
    pub y: u32,
    /// Column (`%x`).
    pub x: u32,
}

/// A fast hash for [`TileId`] keys (the multiply-rotate of rustc's `FxHasher`): the tile
/// maps are looked up for every piece of every run and every border texel, where the
/// standard SipHash cost a fifth of a frame. The keys come from the configuration's
/// bounded grid, not from an adversary, so no flooding resistance is needed.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct TileHasher(u64);

impl TileHasher {
    #[inline]
    fn add(&mut self, w: u64) {
        self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl std::hash::Hasher for TileHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.add(u64::from(b));
        }
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.add(u64::from(i));
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.add(i);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }
    #[inline]
    fn write_isize(&mut self, i: isize) {
        self.add(i as u64);
    }
}

/// A map keyed by tile, with [`TileHasher`].
pub(crate) type TileMap<V> =
    std::collections::HashMap<TileId, V, std::hash::BuildHasherDefault<TileHasher>>;
/// A set of tiles, with [`TileHasher`].
pub(crate) type TileSet =
    std::collections::HashSet<TileId, std::hash::BuildHasherDefault<TileHasher>>;

/// One level of a pyramid: its face side, its tile side, and whether it is only a
/// fallback (Marzipano's `fallbackOnly`: drawn under missing tiles, never chosen).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LevelInfo {
    /// Face side (texels).
    pub size: u32,
    /// Tile side (texels; the last tile of a row may be short).
    pub tile: u32,
    /// Never chosen as a frame's level.
    pub fallback_only: bool,
}

/// How tile files are named.
#[derive(Debug, Clone, PartialEq)]
enum Naming {
    /// Pannellum's `path` template, `fallbackPath` and `extension`.
    Pannellum {
        path: String,
        fallback: Option<String>,
        extension: String,
    },
    /// The Marzipano tool's `{z}/{f}/{y}/{x}.jpg` under the scene's folder, level 1
    /// (`z` 0) from `preview.jpg` when the folder has one.
    Marzipano { preview: Option<PathBuf> },
}

/// A validated pyramid description: Pannellum's multires configuration
/// ([`MultiresConfig::open`]) or a Marzipano scene's levels ([`MultiresConfig::marzipano`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MultiresConfig {
    /// The configuration file (Marzipano: the `data.js` listing the levels).
    pub file: PathBuf,
    /// The folder the paths are relative to (the configuration's folder, plus `basePath`;
    /// Marzipano: the scene's `tiles/<id>`).
    pub root: PathBuf,
    naming: Naming,
    /// The levels, coarsest first (level `l` is `levels[l - 1]`).
    levels: Vec<LevelInfo>,
    /// Tile side of the full level (Pannellum: every level's).
    pub tile: u32,
    /// Number of levels (level `max_level` is the full face).
    pub max_level: u32,
    /// Face side of the full level.
    pub cube: u32,
    /// Tiles the generator left out (background), and their children.
    missing: HashSet<TileId>,
    /// Background colour, 0RGB (`backgroundColor`, black by default).
    pub background: u32,
    /// Horizontal angle of view of a partial panorama (degrees), when given.
    pub haov: Option<f64>,
    /// Vertical angle of view of a partial panorama (degrees), when given.
    pub vaov: Option<f64>,
}

/// Pannellum's face letters in its order (`generate.py`'s `faceLetters`).
pub const FACE_LETTERS: [(char, Face); 6] = [
    ('f', Face::Front),
    ('b', Face::Back),
    ('u', Face::Up),
    ('d', Face::Down),
    ('l', Face::Left),
    ('r', Face::Right),
];

/// The letter of `face`.
pub fn face_letter(face: Face) -> char {
    FACE_LETTERS
        .iter()
        .find(|(_, f)| *f == face)
        .map(|(c, _)| *c)
        .unwrap_or('f')
}

fn face_of_letter(c: char) -> Option<Face> {
    FACE_LETTERS.iter().find(|(l, _)| *l == c).map(|(_, f)| *f)
}

const B83: &str =
    "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz#$%*+,-.:;=?@[]^_{|}~";

fn b83(s: &[char]) -> Option<u64> {
    let mut v: u64 = 0;
    for c in s {
        let d = B83.find(*c)? as u64;
        v = v.checked_mul(83)?.checked_add(d)?;
    }
    Some(v)
}

/// A path template or `basePath` is a relative path inside the folder: no `..`, no root,
/// no drive or URL scheme, no NUL or backslash.
fn check_relative(what: &str, s: &str) -> Result<(), String> {
    if s.contains('\0') || s.contains('\\') {
        return Err(format!("{what} {s:?} has a NUL or backslash"));
    }
    if s.contains("://") || s.starts_with("//") || s.contains(':') {
        return Err(format!(
            "{what} {s:?} is a URL or drive path; only paths inside the pyramid's folder are read"
        ));
    }
    let trimmed = s.trim_start_matches('/');
    for c in Path::new(trimmed).components() {
        match c {
            Component::Normal(_) | Component::CurDir => {}
            _ => {
                return Err(format!(
                    "{what} {s:?} leaves the pyramid's folder (`..` or an absolute path)"
                ))
            }
        }
    }
    if s.split('/').any(|p| p == "..") {
        return Err(format!("{what} {s:?} leaves the pyramid's folder (`..`)"));
    }
    Ok(())
}

fn num(v: &serde_json::Value, key: &str) -> Result<Option<f64>, String> {
    match v.get(key) {
        None | Some(serde_json::Value::Null) => Ok(None),
        Some(x) => x
            .as_f64()
            .filter(|f| f.is_finite())
            .map(Some)
            .ok_or_else(|| format!("{key} is not a finite number")),
    }
}

fn whole(v: &serde_json::Value, key: &str, lo: u64, hi: u64) -> Result<u32, String> {
    let x = num(v, key)?.ok_or_else(|| format!("multiRes.{key} is missing"))?;
    if x.fract() != 0.0 || x < lo as f64 || x > hi as f64 {
        return Err(format!(
            "multiRes.{key} {x} is not a whole number in {lo}..={hi}"
        ));
    }
    Ok(x as u32)
}

fn text<'a>(v: &'a serde_json::Value, key: &str) -> Result<Option<&'a str>, String> {
    match v.get(key) {
        None | Some(serde_json::Value::Null) => Ok(None),
        Some(x) => x
            .as_str()
            .map(Some)
            .ok_or_else(|| format!("{key} is not a string")),
    }
}

impl MultiresConfig {
    /// Open a pyramid: `path` is its folder (holding `config.json`) or the configuration
    /// file itself. Only regular files are read (a FIFO is refused, never waited on).
    ///
    /// # Errors
    /// A [`TilesError`] naming the file and the reason: unreadable, not JSON, not
    /// `"type": "multires"`, or a value outside the limits ([`MAX_CUBE_RESOLUTION`],
    /// [`MIN_TILE_RESOLUTION`]..=[`MAX_TILE_RESOLUTION`], [`MAX_LEVELS`],
    /// [`MAX_BASE_TILES`]), or a path that leaves the folder.
    pub fn open(path: &Path) -> Result<MultiresConfig, TilesError> {
        let file = if path.is_dir() {
            path.join("config.json")
        } else {
            path.to_path_buf()
        };
        // The one reader of small input files: a FIFO or device is refused without
        // blocking, the size limited.
        let bytes = crate::file::read_regular(&file, MAX_CONFIG_BYTES)
            .map_err(|e| TilesError::new(&file, format!("cannot read: {e}")))?;
        let dir = file
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        let dir = if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir
        };
        // Parsed behind the decoders' one containment (docs/reliability.md, class 2; the
        // fuzz target calls `parse` itself, so that a panic is a finding there).
        crate::guard::contain(&file, || {
            crate::guard::fault_point("decoder");
            Self::parse(&bytes, &file, &dir)
        })
    }

    /// Parse a configuration's bytes; `file` names it in errors, `dir` is the folder the
    /// paths are relative to.
    ///
    /// # Errors
    /// As [`MultiresConfig::open`].
    pub fn parse(bytes: &[u8], file: &Path, dir: &Path) -> Result<MultiresConfig, TilesError> {
        Self::parse_inner(bytes, file, dir).map_err(|r| TilesError::new(file, r))
    }

    fn parse_inner(bytes: &[u8], file: &Path, dir: &Path) -> Result<MultiresConfig, String> {
        let v: serde_json::Value =
            serde_json::from_slice(bytes).map_err(|e| format!("not a JSON configuration: {e}"))?;
        if !v.is_object() {
            return Err("not a JSON object".into());
        }
        match text(&v, "type")? {
            Some("multires") => {}
            Some(t) => return Err(format!("type {t:?} is not \"multires\" (a tiled pyramid)")),
            None => return Err("no \"type\": \"multires\" (not a Pannellum tiled pyramid)".into()),
        }
        let m = v
            .get("multiRes")
            .filter(|m| m.is_object())
            .ok_or("no \"multiRes\" block")?;
        let tile = whole(
            m,
            "tileResolution",
            MIN_TILE_RESOLUTION as u64,
            MAX_TILE_RESOLUTION as u64,
        )?;
        let cube = whole(m, "cubeResolution", 1, MAX_CUBE_RESOLUTION as u64)?;
        let max_level = whole(m, "maxLevel", 1, MAX_LEVELS as u64)?;
        if (cube >> (max_level - 1)) == 0 {
            return Err(format!(
                "multiRes.maxLevel {max_level} halves cubeResolution {cube} to nothing at level 1"
            ));
        }
        let base = level_size(cube, max_level, 1);
        if base.div_ceil(tile) > MAX_BASE_TILES {
            return Err(format!(
                "level 1 is {base} px, more than {MAX_BASE_TILES} tiles of {tile} a side (maxLevel {max_level} too small for cubeResolution {cube})"
            ));
        }
        let path = text(m, "path")?
            .ok_or("multiRes.path is missing")?
            .to_string();
        check_template("multiRes.path", &path, &["%l0", "%l", "%s", "%x", "%y"])?;
        for need in ["%l", "%s", "%x", "%y"] {
            if !path.contains(need) {
                return Err(format!(
                    "multiRes.path {path:?} lacks {need}: tiles would share a file"
                ));
            }
        }
        let fallback = text(m, "fallbackPath")?.map(str::to_string);
        if let Some(f) = &fallback {
            check_template("multiRes.fallbackPath", f, &["%s"])?;
        }
        let extension = text(m, "extension")?.unwrap_or("").to_string();
        if extension.len() > 8 || !extension.chars().all(|c| c.is_ascii_alphanumeric()) {
            return Err(format!(
                "multiRes.extension {extension:?} is not a file extension"
            ));
        }
        let mut root = dir.to_path_buf();
        if let Some(b) = text(m, "basePath")?.or(text(&v, "basePath")?) {
            check_relative("basePath", b)?;
            root = root.join(b.trim_start_matches('/'));
        }
        let background = match v.get("backgroundColor") {
            None | Some(serde_json::Value::Null) => 0,
            Some(c) => {
                let a = c
                    .as_array()
                    .filter(|a| a.len() == 3)
                    .ok_or("backgroundColor is not [r, g, b]")?;
                let mut px = 0u32;
                for x in a {
                    let f = x
                        .as_f64()
                        .filter(|f| (0.0..=1.0).contains(f))
                        .ok_or("backgroundColor components must be numbers in 0..1")?;
                    px = (px << 8) | (f * 255.0).round() as u32;
                }
                px
            }
        };
        let angle = |k: &str, hi: f64| -> Result<Option<f64>, String> {
            match num(&v, k)? {
                Some(a) if !(a > 0.0 && a <= hi) => Err(format!("{k} {a} is not in (0, {hi}]")),
                a => Ok(a),
            }
        };
        let (haov, vaov) = (angle("haov", 360.0)?, angle("vaov", 180.0)?);
        let levels = (1..=max_level)
            .map(|l| LevelInfo {
                size: level_size(cube, max_level, l),
                tile,
                fallback_only: false,
            })
            .collect();
        let mut cfg = MultiresConfig {
            file: file.to_path_buf(),
            root,
            naming: Naming::Pannellum {
                path,
                fallback,
                extension,
            },
            levels,
            tile,
            max_level,
            cube,
            missing: HashSet::new(),
            background,
            haov,
            vaov,
        };
        if let Some(s) = text(m, "missingTiles")? {
            cfg.missing = cfg.parse_missing(s)?;
        }
        Ok(cfg)
    }

    /// `missingTiles` as `libpannellum.js` reads it.
    fn parse_missing(&self, s: &str) -> Result<HashSet<TileId>, String> {
        let bad = |why: &str| format!("multiRes.missingTiles: {why}");
        let mut out = HashSet::new();
        let mut level: Option<u32> = None;
        for side in s.split('!').skip(1) {
            let mut chars = side.chars();
            let face = chars
                .next()
                .and_then(face_of_letter)
                .ok_or_else(|| bad("a face letter other than f b u d l r"))?;
            let rest: String = chars.collect();
            let groups: Vec<(Option<char>, Vec<char>)> = if rest.contains('>') {
                rest.split('>')
                    .skip(1)
                    .map(|g| {
                        let mut c = g.chars();
                        (c.next(), c.collect())
                    })
                    .collect()
            } else {
                vec![(None, rest.chars().collect())]
            };
            for (lv, tiles) in groups {
                if let Some(c) = lv {
                    level =
                        Some(b83(&[c]).ok_or_else(|| bad("a level digit outside base 83"))? as u32);
                }
                let l = level.ok_or_else(|| bad("tiles before any level"))?;
                if l < 1 || l > self.max_level {
                    return Err(bad(&format!("level {l} outside 1..={}", self.max_level)));
                }
                let n = self.tiles_across(l);
                let digits = ((n as f64).ln() / 83f64.ln()).ceil().max(0.0) as usize;
                let pairs: Vec<u64> = if digits == 0 || tiles.is_empty() {
                    vec![0, 0]
                } else {
                    if tiles.len() % (2 * digits) != 0 {
                        return Err(bad("a tile number cut short"));
                    }
                    tiles
                        .chunks(digits)
                        .map(b83)
                        .collect::<Option<Vec<u64>>>()
                        .ok_or_else(|| bad("a character outside base 83"))?
                };
                for p in pairs.chunks(2) {
                    let (x, y) = (p[0], p[1]);
                    if x >= n as u64 || y >= n as u64 {
                        return Err(bad(&format!("tile {x},{y} outside level {l}'s {n}×{n}")));
                    }
                    if out.len() >= MAX_MISSING_TILES {
                        return Err(bad(&format!(
                            "more than the limit of {MAX_MISSING_TILES} tiles left out"
                        )));
                    }
                    out.insert(TileId {
                        level: l as u8,
                        face,
                        y: y as u32,
                        x: x as u32,
                    });
                }
            }
        }
        Ok(out)
    }

    /// The levels, coarsest first (level `l` is item `l − 1`).
    pub fn levels(&self) -> &[LevelInfo] {
        &self.levels
    }

    fn level_info(&self, level: u32) -> LevelInfo {
        self.levels[(level.clamp(1, self.max_level) - 1) as usize]
    }

    /// Face side of `level` (1..=max_level).
    pub fn level_size(&self, level: u32) -> u32 {
        self.level_info(level).size
    }

    /// Tile side of `level` (the last tile of a row may be short).
    pub fn tile_size(&self, level: u32) -> u32 {
        self.level_info(level).tile
    }

    /// Tiles across a face at `level`.
    pub fn tiles_across(&self, level: u32) -> u32 {
        let l = self.level_info(level);
        l.size.div_ceil(l.tile)
    }

    /// The coarsest level a frame may be drawn at (levels below it are fallbacks only).
    pub fn first_level(&self) -> u32 {
        self.levels
            .iter()
            .position(|l| !l.fallback_only)
            .map_or(1, |i| i as u32 + 1)
    }

    /// Width and height of a tile (the last of a row or column is short).
    pub fn tile_dims(&self, id: TileId) -> (u32, u32) {
        let l = self.level_info(id.level as u32);
        let side = |i: u32| l.size.saturating_sub(i * l.tile).min(l.tile);
        (side(id.x), side(id.y))
    }

    /// The tiles of level `id.level + 1` covering tile `id` (none on the top level).
    pub fn children(&self, id: TileId) -> Vec<TileId> {
        let l = id.level as u32;
        if l >= self.max_level {
            return Vec::new();
        }
        let (a, b) = (self.level_info(l), self.level_info(l + 1));
        let n = self.tiles_across(l + 1);
        // The tile's texel span on its level, scaled to the next level's texels.
        let span = |i: u32| {
            let lo = (i * a.tile) as u64 * b.size as u64 / a.size as u64;
            let hi =
                (((i + 1) * a.tile).min(a.size) as u64 * b.size as u64).div_ceil(a.size as u64);
            let first = (lo / b.tile as u64) as u32;
            let last = ((hi.max(lo + 1) - 1) / b.tile as u64) as u32;
            first.min(n - 1)..=last.min(n - 1)
        };
        let mut out = Vec::new();
        for y in span(id.y) {
            for x in span(id.x) {
                out.push(TileId {
                    level: id.level + 1,
                    face: id.face,
                    y,
                    x,
                });
            }
        }
        out
    }

    /// Whether the generator left `id` out (background), directly or as a child of a
    /// tile left out.
    pub fn is_missing(&self, id: TileId) -> bool {
        if self.missing.is_empty() {
            return false;
        }
        let mut t = id;
        loop {
            if self.missing.contains(&t) {
                return true;
            }
            if t.level <= 1 {
                return false;
            }
            // Pannellum drops the children (2x, 2y)..(2x + 1, 2y + 1) of a missing tile.
            t = TileId {
                level: t.level - 1,
                face: t.face,
                x: t.x / 2,
                y: t.y / 2,
            };
        }
    }

    /// How many tiles the generator listed as left out.
    pub fn missing_count(&self) -> usize {
        self.missing.len()
    }

    /// The file of tile `id` (a Marzipano level-1 tile: the `preview.jpg` holding it).
    pub fn tile_path(&self, id: TileId) -> PathBuf {
        match &self.naming {
            Naming::Pannellum { path, .. } => {
                let p = path
                    .replace("%s", &face_letter(id.face).to_string())
                    .replace("%l0", &(id.level as u32 - 1).to_string())
                    .replace("%l", &id.level.to_string())
                    .replace("%x", &id.x.to_string())
                    .replace("%y", &id.y.to_string());
                self.file_of(&p)
            }
            Naming::Marzipano { preview } => match (preview, id.level) {
                (Some(p), 1) => p.clone(),
                _ => self.root.join(format!(
                    "{}/{}/{}/{}.jpg",
                    id.level - 1,
                    face_letter(id.face),
                    id.y,
                    id.x
                )),
            },
        }
    }

    /// A Marzipano level-1 tile read from `preview.jpg`: the file and the face's place
    /// in its vertical strip (`bdflru`, [`MARZIPANO_PREVIEW_ORDER`]).
    pub fn preview_face(&self, id: TileId) -> Option<(PathBuf, usize)> {
        match &self.naming {
            Naming::Marzipano { preview: Some(p) } if id.level == 1 => {
                let k = MARZIPANO_PREVIEW_ORDER.find(face_letter(id.face))?;
                Some((p.clone(), k))
            }
            _ => None,
        }
    }

    /// The fallback face image of `face`, when the configuration names them.
    pub fn fallback_path(&self, face: Face) -> Option<PathBuf> {
        let Naming::Pannellum { fallback, .. } = &self.naming else {
            return None;
        };
        let f = fallback.as_ref()?;
        Some(self.file_of(&f.replace("%s", &face_letter(face).to_string())))
    }

    fn file_of(&self, p: &str) -> PathBuf {
        let mut name = p.trim_start_matches('/').to_string();
        if let Naming::Pannellum { extension, .. } = &self.naming {
            if !extension.is_empty() {
                name.push('.');
                name.push_str(extension);
            }
        }
        self.root.join(name)
    }

    /// Total tiles in the pyramid.
    pub fn tile_count(&self) -> u64 {
        (1..=self.max_level)
            .map(|l| 6 * (self.tiles_across(l) as u64).pow(2))
            .sum()
    }

    /// A Marzipano scene: the `levels` of its `data.js` (`file`, named in errors) as
    /// `(tileSize, size, fallbackOnly)`, its tiles under `root` (`tiles/<id>`) as the
    /// Marzipano tool writes them, `{z}/{f}/{y}/{x}.jpg` with `z` the level's index
    /// in size order (0 the smallest, as Marzipano's `CubeGeometry` sorts them); the
    /// smallest level from `root/preview.jpg` when it exists (the tool's
    /// `cubeMapPreviewUrl`: six faces stacked in `bdflru` order), else from its tiles.
    /// Face letters and orientation are Pannellum's (docs/huge.md, "Marzipano").
    ///
    /// # Errors
    /// No level, no level that is not `fallbackOnly`, more than [`MAX_LEVELS`], a size
    /// outside 1..=[`MAX_CUBE_RESOLUTION`], a tile side outside
    /// [`MIN_TILE_RESOLUTION`]..=[`MAX_TILE_RESOLUTION`] (smaller allowed when it is
    /// the whole face of a level smaller than that), a size that is not a multiple of its tile side (Marzipano refuses
    /// it too), two levels of one size, a smallest level of more than
    /// [`MAX_BASE_TILES`]² tiles a face, or a preview whose level is more than one tile.
    pub fn marzipano(
        file: &Path,
        root: &Path,
        levels: &[(u32, u32, bool)],
    ) -> Result<MultiresConfig, TilesError> {
        let bad = |r: String| TilesError::new(file, format!("{}: {r}", root.display()));
        if levels.is_empty() {
            return Err(bad("no levels".into()));
        }
        if levels.len() > MAX_LEVELS as usize {
            return Err(bad(format!(
                "{} levels, more than the limit of {MAX_LEVELS}",
                levels.len()
            )));
        }
        let mut ls: Vec<LevelInfo> = Vec::with_capacity(levels.len());
        for &(tile, size, fallback_only) in levels {
            if !(1..=MAX_CUBE_RESOLUTION).contains(&size) {
                return Err(bad(format!(
                    "level size {size} is not in 1..={MAX_CUBE_RESOLUTION}"
                )));
            }
            // A level smaller than the smallest tile is one tile; no tile is larger than
            // MAX_TILE_RESOLUTION (a tile is decoded whole).
            let small = tile == size && size < MIN_TILE_RESOLUTION;
            if !(small || (MIN_TILE_RESOLUTION..=MAX_TILE_RESOLUTION).contains(&tile)) {
                return Err(bad(format!(
                    "level of size {size}: tileSize {tile} is not in {MIN_TILE_RESOLUTION}..={MAX_TILE_RESOLUTION}"
                )));
            }
            if size % tile != 0 {
                return Err(bad(format!(
                    "level size {size} is not a multiple of its tileSize {tile} (Marzipano refuses such a level too)"
                )));
            }
            ls.push(LevelInfo {
                size,
                tile,
                fallback_only,
            });
        }
        // Marzipano's makeLevelList: sorted by size (stable), `z` is the sorted index.
        ls.sort_by_key(|l| l.size);
        if let Some(w) = ls.windows(2).find(|w| w[0].size == w[1].size) {
            return Err(bad(format!("two levels of size {}", w[0].size)));
        }
        if ls.iter().all(|l| l.fallback_only) {
            return Err(bad("every level is fallbackOnly: none to draw".into()));
        }
        let base = ls[0];
        if base.size.div_ceil(base.tile) > MAX_BASE_TILES {
            return Err(bad(format!(
                "the smallest level is {} px, more than {MAX_BASE_TILES} tiles of {} a side",
                base.size, base.tile
            )));
        }
        let preview = Some(root.join("preview.jpg")).filter(|p| p.is_file());
        if preview.is_some() && base.tile != base.size {
            return Err(bad(format!(
                "preview.jpg stands for the smallest level, whose tiles ({}) are not its whole face ({})",
                base.tile, base.size
            )));
        }
        let top = ls[ls.len() - 1];
        Ok(MultiresConfig {
            file: file.to_path_buf(),
            root: root.to_path_buf(),
            naming: Naming::Marzipano { preview },
            tile: top.tile,
            max_level: ls.len() as u32,
            cube: top.size,
            levels: ls,
            missing: HashSet::new(),
            background: 0,
            haov: None,
            vaov: None,
        })
    }
}

/// The order of the faces in a Marzipano `preview.jpg` (top to bottom; its
/// `cubeMapPreviewFaceOrder` default).
pub const MARZIPANO_PREVIEW_ORDER: &str = "bdflru";

/// Face side of `level` for a pyramid of `max_level` levels whose full face is `cube`:
/// halved with `int(size / 2)` once per level below the top, as the generator does.
pub fn level_size(cube: u32, max_level: u32, level: u32) -> u32 {
    let down = max_level.saturating_sub(level);
    if down >= 32 {
        0
    } else {
        cube >> down
    }
}

/// A template holds only the placeholders `allowed` and is a relative path.
fn check_template(what: &str, t: &str, allowed: &[&str]) -> Result<(), String> {
    if t.len() > 4096 {
        return Err(format!("{what} is longer than 4096 bytes"));
    }
    let mut rest = t;
    while let Some(i) = rest.find('%') {
        let after = &rest[i..];
        let Some(p) = allowed.iter().find(|p| after.starts_with(**p)) else {
            return Err(format!(
                "{what} {t:?} has a placeholder other than {}",
                allowed.join(" ")
            ));
        };
        rest = &after[p.len()..];
    }
    // Substituted values are digits and letters: checking the template checks every path.
    check_relative(what, t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(json: &str) -> Result<MultiresConfig, TilesError> {
        MultiresConfig::parse(json.as_bytes(), Path::new("t/config.json"), Path::new("t"))
    }

    fn multires(body: &str) -> String {
        format!("{{\"type\": \"multires\", \"multiRes\": {{{body}}}}}")
    }

    const GOOD: &str = "\"path\": \"/%l/%s%y_%x\", \"fallbackPath\": \"/fallback/%s\", \
        \"extension\": \"jpg\", \"tileResolution\": 512, \"maxLevel\": 5, \"cubeResolution\": 5216";

    #[test]
    fn the_generators_config_reads_with_its_sizes_and_paths() {
        let c = cfg(&multires(GOOD)).unwrap();
        assert_eq!((c.tile, c.max_level, c.cube), (512, 5, 5216));
        // int(size / 2) per level: 5216, 2608, 1304, 652, 326.
        let sizes: Vec<u32> = (1..=5).map(|l| c.level_size(l)).collect();
        assert_eq!(sizes, [326, 652, 1304, 2608, 5216]);
        assert_eq!(c.tiles_across(5), 11);
        // The last tile of a row is short: 5216 - 10 * 512 = 96.
        let id = TileId {
            level: 5,
            face: Face::Up,
            y: 10,
            x: 3,
        };
        assert_eq!(c.tile_dims(id), (512, 96));
        assert_eq!(c.tile_path(id), Path::new("t/5/u10_3.jpg"));
        assert_eq!(
            c.fallback_path(Face::Left).unwrap(),
            Path::new("t/fallback/l.jpg")
        );
        assert_eq!(
            c.tile_dims(TileId {
                level: 1,
                face: Face::Front,
                y: 0,
                x: 0
            }),
            (326, 326)
        );
        assert_eq!(c.tile_count(), 6 * (1 + 4 + 9 + 36 + 121));
        // %l0 and basePath.
        let c = cfg(&multires(
            "\"basePath\": \"tiles\", \"path\": \"/%l0/%s/%y/%x\", \"extension\": \"png\", \
             \"tileResolution\": 256, \"maxLevel\": 2, \"cubeResolution\": 512",
        ))
        .unwrap();
        let id = TileId {
            level: 2,
            face: Face::Right,
            y: 1,
            x: 0,
        };
        assert_eq!(c.tile_path(id), Path::new("t/tiles/1/r/1/0.png"));
        assert_eq!(c.fallback_path(Face::Front), None);
    }

    #[test]
    fn missing_tiles_decode_as_pannellum_reads_them() {
        // Written as generate.py writes it: face f level 3 tiles (1,0) and (0,2); face b
        // (same level, no '>') tile (0,0); face u level 2 (x=1,y=1). Level 3 of 1304 px
        // with 512 tiles: 3 across, one base-83 digit.
        let s = "!f>31002!b00!u>211";
        let json = multires(&format!("{GOOD}, \"missingTiles\": \"{s}\""));
        let c = cfg(&json).unwrap();
        assert_eq!(c.missing_count(), 3 + 1);
        let t = |level, face, x, y| TileId { level, face, x, y };
        assert!(c.is_missing(t(3, Face::Front, 1, 0)));
        assert!(c.is_missing(t(3, Face::Front, 0, 2)));
        assert!(!c.is_missing(t(3, Face::Front, 0, 0)));
        assert!(c.is_missing(t(3, Face::Back, 0, 0)));
        assert!(c.is_missing(t(2, Face::Up, 1, 1)));
        // Children of a missing tile are missing.
        assert!(c.is_missing(t(4, Face::Front, 3, 1)));
        assert!(c.is_missing(t(5, Face::Up, 9, 8)));
        assert!(!c.is_missing(t(5, Face::Up, 0, 0)));
        for bad in ["!x>300", "!f>9000", "!f>30z", "!f>3999"] {
            let json = multires(&format!("{GOOD}, \"missingTiles\": \"{bad}\""));
            assert!(cfg(&json).is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn bad_configs_are_refused_with_one_line_naming_the_value() {
        let cases: &[(String, &str)] = &[
            (
                multires(&GOOD.replace("5216", "1000000000000")),
                "cubeResolution",
            ),
            (
                multires(&GOOD.replace("\"maxLevel\": 5", "\"maxLevel\": 60")),
                "maxLevel",
            ),
            (
                multires(&GOOD.replace("\"tileResolution\": 512", "\"tileResolution\": 0")),
                "tileResolution",
            ),
            (
                multires(&GOOD.replace("\"maxLevel\": 5", "\"maxLevel\": 1")),
                "level 1",
            ),
            (
                multires(&GOOD.replace("\"maxLevel\": 5", "\"maxLevel\": 20")),
                "maxLevel",
            ),
            (
                multires(&GOOD.replace("/%l/%s%y_%x", "/../%l/%s%y_%x")),
                "leaves",
            ),
            (
                multires(&GOOD.replace("/%l/%s%y_%x", "%l/../../%s%y_%x")),
                "leaves",
            ),
            (multires(&GOOD.replace("/fallback/%s", "/../f%s")), "leaves"),
            (
                multires(&GOOD.replace("/%l/%s%y_%x", "/%l/%s%y")),
                "lacks %x",
            ),
            (
                multires(&GOOD.replace("/%l/%s%y_%x", "/%l/%s%y_%x%q")),
                "placeholder",
            ),
            (
                multires(&GOOD.replace("/%l/%s%y_%x", "C:/%l/%s%y_%x")),
                "URL or drive",
            ),
            (
                multires(&GOOD.replace("\"jpg\"", "\"j/../pg\"")),
                "extension",
            ),
            (
                multires(&format!("\"basePath\": \"/etc/..\", {GOOD}")),
                "leaves",
            ),
            (
                multires(&format!("\"basePath\": \"http://x/\", {GOOD}")),
                "URL",
            ),
            (multires(&GOOD.replace("512,", "512.5,")), "whole number"),
            ("{\"type\": \"equirectangular\"}".into(), "not \"multires\""),
            ("{\"type\": \"multires\"}".into(), "multiRes"),
            ("[1, 2]".into(), "JSON object"),
            ("{\"type\": \"multires\", ".into(), "JSON"),
        ];
        for (json, want) in cases {
            let e = cfg(json).expect_err(json).to_string();
            assert!(e.contains(want), "{json}: {e} lacks {want}");
            assert!(e.starts_with("t/config.json: "), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
    }

    #[test]
    fn marzipano_levels_sorted_named_and_checked() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("tiles/0-a");
        let file = dir.path().join("data.js");
        let m = |l: &[(u32, u32, bool)]| MultiresConfig::marzipano(&file, &root, l);
        // Listed out of order: sorted by size as Marzipano's makeLevelList does.
        let c = m(&[(512, 1536, false), (256, 256, true), (512, 512, false)]).unwrap();
        let sizes: Vec<(u32, u32)> = c.levels().iter().map(|l| (l.size, l.tile)).collect();
        assert_eq!(sizes, [(256, 256), (512, 512), (1536, 512)]);
        assert_eq!(
            (c.max_level, c.cube, c.tile, c.first_level()),
            (3, 1536, 512, 2)
        );
        let t = |level, face, y, x| TileId { level, face, y, x };
        // z is the level's index from 0; no preview.jpg: level 1 from its tiles.
        assert_eq!(
            c.tile_path(t(3, Face::Left, 2, 1)),
            root.join("2/l/2/1.jpg")
        );
        assert_eq!(c.tile_path(t(1, Face::Up, 0, 0)), root.join("0/u/0/0.jpg"));
        assert_eq!(c.preview_face(t(1, Face::Up, 0, 0)), None);
        assert_eq!(c.tiles_across(3), 3);
        // A level three times its parent: level 2's one tile (512 texels) is 1536 texels
        // of level 3, its 3 × 3 tiles.
        let kids = c.children(t(2, Face::Front, 0, 0));
        assert_eq!(kids.len(), 9);
        assert!(c.children(t(3, Face::Front, 0, 0)).is_empty());
        // Children of uneven levels: 96 (tiles 48) under 320 (tiles 64): tile 1 of 96 is
        // texels 48..96, i.e. 160..320 of 320, tiles 2..=4.
        let c = m(&[(48, 96, false), (64, 320, false)]).unwrap();
        let xs: Vec<u32> = c
            .children(t(1, Face::Down, 0, 1))
            .iter()
            .filter(|k| k.y == 0)
            .map(|k| k.x)
            .collect();
        assert_eq!(xs, [2, 3, 4]);
        // With preview.jpg, level 1 is read from it (face order bdflru).
        std::fs::create_dir_all(&root).unwrap();
        std::fs::write(root.join("preview.jpg"), b"x").unwrap();
        let c = m(&[(256, 256, true), (512, 512, false)]).unwrap();
        assert_eq!(
            c.preview_face(t(1, Face::Left, 0, 0)),
            Some((root.join("preview.jpg"), 3))
        );
        assert_eq!(
            c.tile_path(t(2, Face::Back, 0, 0)),
            root.join("1/b/0/0.jpg")
        );
        // Refused, one line each, naming the file and the scene's folder.
        type Levels<'a> = &'a [(u32, u32, bool)];
        let bad: &[(Levels, &str)] = &[
            (&[], "no levels"),
            (&[(512, 1000, false)], "not a multiple of its tileSize 512"),
            (&[(256, 256, true)], "fallbackOnly"),
            (
                &[(256, 512, false), (512, 512, false)],
                "two levels of size 512",
            ),
            (&[(8, 512, false)], "tileSize 8"),
            (&[(8, 8, false), (16384, 16384, false)], "tileSize 16384"),
            (&[(0, 512, false)], "tileSize 0"),
            (&[(512, 0, false)], "size 0"),
            (&[(512, 1 << 22, false)], "not in 1..="),
            (&[(16, 4096, false)], "more than 8 tiles"),
            (&[(256, 512, false), (512, 1024, false)], "preview.jpg"),
        ];
        for (levels, want) in bad {
            let e = m(levels).expect_err(want).to_string();
            assert!(e.contains(want), "{levels:?}: {e}");
            assert!(
                e.starts_with(&format!("{}: {}: ", file.display(), root.display())),
                "{e}"
            );
            assert!(!e.contains('\n'), "{e}");
        }
        // A level smaller than a tile is one tile.
        assert!(m(&[(8, 8, true), (16, 32, false)]).is_ok());
        let many: Vec<(u32, u32, bool)> = (1..=30).map(|k| (16, 16 * k, false)).collect();
        assert!(m(&many)
            .unwrap_err()
            .to_string()
            .contains("more than the limit"));
    }

    #[test]
    fn any_marzipano_levels_are_refused_or_give_a_sound_pyramid() {
        // Level lists as a data.js may hold them (the tour reader takes whole numbers in
        // 1..=65536): refused in one line, or every tile within its level and its
        // children within the next.
        let (file, root) = (Path::new("t/data.js"), Path::new("t/tiles/s"));
        let mut seed: u64 = 0x2545_f491_4f6c_dd1d;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        let mut ok = 0;
        for _ in 0..3000 {
            let k = 1 + next(5) as usize;
            let levels: Vec<(u32, u32, bool)> = (0..k)
                .map(|_| {
                    let tile = [1, 8, 16, 48, 64, 256, 512, 8192, 65536][next(9) as usize];
                    let size = tile * (1 + next(12) as u32).min(65536 / tile.max(1)).max(1);
                    let size = if next(4) == 0 {
                        size + next(7) as u32
                    } else {
                        size
                    };
                    (tile, size.min(65536), next(3) == 0)
                })
                .collect();
            match MultiresConfig::marzipano(file, root, &levels) {
                Err(e) => assert!(!e.to_string().contains('\n')),
                Ok(c) => {
                    ok += 1;
                    for l in 1..=c.max_level {
                        let n = c.tiles_across(l);
                        assert!(n >= 1 && (l > 1 || n <= MAX_BASE_TILES));
                        for (x, y) in [(0, 0), (n - 1, n - 1)] {
                            let id = TileId {
                                level: l as u8,
                                face: Face::Right,
                                y,
                                x,
                            };
                            assert_eq!(c.tile_dims(id), (c.tile_size(l), c.tile_size(l)));
                            assert!(c.tile_path(id).starts_with(root));
                            for k in c.children(id) {
                                let m = c.tiles_across(l + 1);
                                assert!(k.x < m && k.y < m && k.level as u32 == l + 1);
                            }
                        }
                    }
                }
            }
        }
        assert!(ok > 100, "only {ok} level lists accepted");
    }

    #[test]
    fn level_size_is_repeated_integer_halving() {
        for cube in [1u32, 7, 648, 5216, 8432, 81_488, MAX_CUBE_RESOLUTION] {
            let mut s = cube;
            for l in (1..=18u32).rev() {
                assert_eq!(level_size(cube, 18, l), s);
                s /= 2;
            }
        }
    }
}

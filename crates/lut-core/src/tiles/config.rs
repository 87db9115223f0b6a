//! The pyramid description every tiled panorama is read through ([`MultiresConfig`]: level
//! sizes, tile grids, tile files), and Pannellum's `multires` configuration parsed and
//! validated into it with stated limits. Marzipano's levels become the same description in
//! `marzipano.rs`; tile names and their hash are in `id.rs`.
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

use super::id::TileId;
use super::marzipano::MARZIPANO_PREVIEW_ORDER;
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
pub(super) enum Naming {
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
    pub(super) naming: Naming,
    /// The levels, coarsest first (level `l` is `levels[l - 1]`).
    pub(super) levels: Vec<LevelInfo>,
    /// Tile side of the full level (Pannellum: every level's).
    pub tile: u32,
    /// Number of levels (level `max_level` is the full face).
    pub max_level: u32,
    /// Face side of the full level.
    pub cube: u32,
    /// Tiles the generator left out (background), and their children.
    pub(super) missing: HashSet<TileId>,
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
}

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

//! Decoded tiles in memory: an LRU cache under a byte budget, each tile stored with a
//! one-texel border so the cube kernels' bilinear reads cross tile and face edges as they
//! cross face edges on a whole [`crate::CubeMap`].
//!
//! # Why a border, not runs split per texel
//! The renderer splits a face run at tile edges and draws each piece with the cube
//! kernels on the piece's tile. A bilinear read within half a texel of a tile edge needs
//! the neighbour's texel: kept in the tile's border, the kernels read it with no branch
//! (the same reason `CubeMap` keeps a border per face). It costs (T + 2)² − T² texels a
//! tile (0.8 % at 512) and a refill when a neighbour arrives (four strips).
//!
//! # Borders
//! A border texel is the texel the neighbouring tile has there, or across a face edge
//! the bilinear sample of the neighbouring face in the texel centre's direction (as
//! `CubeMap` fills its borders). When that neighbour is not decoded the border is
//! sampled from the nearest decoded ancestor, and refilled when the neighbour arrives
//! ([`TileStore::insert`]).
//!
//! # Misses
//! A tile not decoded is drawn from its nearest decoded ancestor (level 1 is loaded at
//! open and never evicted); a tile that cannot be decoded (missing file, wrong size or
//! format, corrupt, a decompression bomb) is remembered as failed, drawn from its
//! ancestor for good, with one notice.

use super::config::MultiresConfig;
use super::id::{TileId, TileMap, TileSet};
use crate::cube::{face_dir, face_of, face_uv, Face};
use crate::geom::fixed::{FX_BITS, FX_HALF, FX_ONE};
use crate::map::sample::lerp_px;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Sides of a tile's border ([`TileStore::fill_border`]'s mask).
const TOP: u8 = 1;
const BOTTOM: u8 = 2;
const LEFT: u8 = 4;
const RIGHT: u8 = 8;
const ALL_SIDES: u8 = TOP | BOTTOM | LEFT | RIGHT;

/// The default cache budget: 1 GiB of decoded tiles.
pub const DEFAULT_CACHE_BYTES: usize = 1 << 30;

/// A decoded tile with its border: `(T + 2)²` 0RGB texels, row-major; tile texel
/// `(x, y)` is at `(y + 1) · (T + 2) + x + 1` (short tiles use the top-left part).
#[derive(Debug)]
pub struct Tile {
    /// Width (texels, without border).
    pub w: u32,
    /// Height.
    pub h: u32,
    /// The bordered texels.
    pub px: Vec<u32>,
    /// The frame that last read it (LRU).
    used: AtomicU64,
    /// Level 1: never evicted.
    pinned: bool,
    /// The tiles of its own level some of its border was wanted from and which were not
    /// decoded when it was filled (the border holds their ancestors' texels there). A
    /// bilinear frame reading near this tile's edge asks for them
    /// ([`Tile::stale_border`]), so their arrival refills the border.
    stale: Vec<TileId>,
}

impl Tile {
    /// The tiles of its level whose texels its border holds only approximately (from an
    /// ancestor), until they are decoded.
    pub fn stale_border(&self) -> &[TileId] {
        &self.stale
    }
}

/// `w × h` row-major texels `px` (a tile of `dims`) placed in a bordered buffer of
/// `(tile + 2)²` texels, the border left to fill ([`TileStore::insert`]).
///
/// # Errors
/// When `px` is not `dims`' size, or `dims` is empty or larger than `tile`.
pub(crate) fn bordered(tile: u32, dims: (u32, u32), px: &[u32]) -> Result<Vec<u32>, String> {
    let (w, h) = dims;
    if px.len() != (w as usize) * (h as usize) || w == 0 || h == 0 || w > tile || h > tile {
        return Err(format!("{} texels, not {w}×{h}", px.len()));
    }
    let s = tile as usize + 2;
    let mut buf = vec![0u32; s * s];
    for (row, src) in buf[s..]
        .chunks_exact_mut(s)
        .zip(px.chunks_exact(w as usize))
    {
        row[1..=w as usize].copy_from_slice(src);
    }
    Ok(buf)
}

/// Counters the panel and the bench read.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct CacheStats {
    /// Decoded tiles held.
    pub tiles: usize,
    /// Their bytes.
    pub bytes: usize,
    /// The budget.
    pub budget: usize,
    /// Tile reads (pieces of runs) found at the wanted level, since the last reset.
    pub hits: u64,
    /// Tile reads drawn from an ancestor instead.
    pub misses: u64,
    /// Tiles decoded since open.
    pub decoded: u64,
    /// Tiles evicted since open.
    pub evicted: u64,
    /// Tiles that could not be decoded.
    pub failed: usize,
}

impl CacheStats {
    /// Hits over reads (1 with no reads).
    pub fn hit_rate(&self) -> f64 {
        let n = self.hits + self.misses;
        if n == 0 {
            1.0
        } else {
            self.hits as f64 / n as f64
        }
    }
}

/// The decoded tiles of one pyramid.
#[derive(Debug)]
pub struct TileStore {
    cfg: Arc<MultiresConfig>,
    tiles: TileMap<Tile>,
    failed: TileSet,
    bytes: usize,
    budget: usize,
    frame: u64,
    hits: AtomicU64,
    misses: AtomicU64,
    decoded: u64,
    evicted: u64,
    notices: Vec<String>,
}

impl TileStore {
    /// An empty store for `cfg` keeping at most `budget` bytes of tiles (level 1 is
    /// always kept, whatever the budget).
    pub fn new(cfg: Arc<MultiresConfig>, budget: usize) -> TileStore {
        TileStore {
            cfg,
            tiles: TileMap::default(),
            failed: TileSet::default(),
            bytes: 0,
            budget,
            frame: 1,
            hits: AtomicU64::new(0),
            misses: AtomicU64::new(0),
            decoded: 0,
            evicted: 0,
            notices: Vec::new(),
        }
    }

    /// The pyramid.
    pub fn config(&self) -> &Arc<MultiresConfig> {
        &self.cfg
    }

    /// Start a new frame (the LRU clock).
    pub fn next_frame(&mut self) {
        self.frame += 1;
    }

    /// Whether `id` is decoded.
    pub fn has(&self, id: TileId) -> bool {
        self.tiles.contains_key(&id)
    }

    /// Whether `id` need not be (or cannot be) loaded: decoded, failed, or left out by
    /// the generator.
    pub fn settled(&self, id: TileId) -> bool {
        self.tiles.contains_key(&id) || self.failed.contains(&id) || self.cfg.is_missing(id)
    }

    /// The counters.
    pub fn stats(&self) -> CacheStats {
        CacheStats {
            tiles: self.tiles.len(),
            bytes: self.bytes,
            budget: self.budget,
            hits: self.hits.load(Ordering::Relaxed),
            misses: self.misses.load(Ordering::Relaxed),
            decoded: self.decoded,
            evicted: self.evicted,
            failed: self.failed.len(),
        }
    }

    /// Reset the hit and miss counters.
    pub fn reset_hits(&self) {
        self.hits.store(0, Ordering::Relaxed);
        self.misses.store(0, Ordering::Relaxed);
    }

    /// Change the budget (evicting at once what no longer fits).
    pub fn set_budget(&mut self, budget: usize) {
        self.budget = budget;
        self.evict(None);
    }

    /// Notices since the last call (one per tile that could not be decoded).
    pub fn take_notices(&mut self) -> Vec<String> {
        std::mem::take(&mut self.notices)
    }

    /// Add a band's reads to the counters.
    pub(crate) fn count_many(&self, hits: u64, misses: u64) {
        self.hits.fetch_add(hits, Ordering::Relaxed);
        self.misses.fetch_add(misses, Ordering::Relaxed);
    }

    pub(crate) fn count(&self, hit: bool) {
        if hit {
            self.hits.fetch_add(1, Ordering::Relaxed);
        } else {
            self.misses.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// The decoded tile `id`, marked used this frame.
    #[inline]
    pub(crate) fn get(&self, id: TileId) -> Option<&Tile> {
        let t = self.tiles.get(&id)?;
        if t.used.load(Ordering::Relaxed) != self.frame {
            t.used.store(self.frame, Ordering::Relaxed);
        }
        Some(t)
    }

    /// The side of a bordered tile buffer of `level`.
    #[inline]
    pub(crate) fn stride(&self, level: u32) -> usize {
        self.cfg.tile_size(level) as usize + 2
    }

    /// Record that `id` could not be decoded: drawn from its ancestor from now on, and
    /// one notice.
    pub fn fail(&mut self, id: TileId, reason: &str) {
        if self.failed.insert(id) {
            let first = self.failed.len() == 1;
            self.notices.push(format!(
                "{}: {reason}; drawn from a coarser level{}",
                self.cfg.tile_path(id).display(),
                if first { "" } else { " (another tile)" }
            ));
        }
    }

    /// Insert the decoded texels of `id` (`w × h` row-major 0RGB, the tile's own
    /// dimensions), fill its border, refill its decoded neighbours' borders, and evict
    /// the least recently used tiles over the budget.
    ///
    /// # Errors
    /// When `px` is not the tile's size (then nothing changes).
    pub fn insert(&mut self, id: TileId, px: &[u32]) -> Result<(), String> {
        let buf = bordered(
            self.cfg.tile_size(id.level as u32),
            self.cfg.tile_dims(id),
            px,
        )?;
        self.insert_bordered(id, buf)
    }

    /// [`TileStore::insert`] of texels already laid out with room for the border
    /// ([`bordered`], done by the decoding thread: the frame's thread only fills the
    /// border).
    ///
    /// # Errors
    /// When `buf` is not a bordered buffer of this pyramid's tiles.
    pub(crate) fn insert_bordered(&mut self, id: TileId, buf: Vec<u32>) -> Result<(), String> {
        let (w, h) = self.cfg.tile_dims(id);
        let s = self.stride(id.level as u32);
        if buf.len() != s * s || w == 0 || h == 0 {
            return Err(format!("{} bordered texels, not {s}×{s}", buf.len()));
        }
        let tile = Tile {
            w,
            h,
            px: buf,
            used: AtomicU64::new(self.frame),
            pinned: id.level == 1,
            stale: Vec::new(),
        };
        if let Some(old) = self.tiles.insert(id, tile) {
            self.bytes -= old.px.len() * 4;
        }
        self.bytes += s * s * 4;
        self.decoded += 1;
        self.failed.remove(&id);
        // Refilled: the new tile's whole border, the side (and corners) of each decoded
        // neighbour on its face that faces it, and where it touches a face edge the whole
        // border of the decoded tiles across that edge near it. Those reaching across a
        // face edge twice: such a border is a bilinear sample of the neighbour face, which
        // near a corner reads that face's own border (refilled in the first pass).
        let mut refill: Vec<(TileId, u8)> = self
            .neighbours(id)
            .into_iter()
            .filter(|(n, _)| self.tiles.contains_key(n))
            .collect();
        refill.sort_unstable();
        refill.push((id, ALL_SIDES));
        for &(n, sides) in &refill {
            self.fill_border(n, sides);
        }
        // The second pass only where a border reaches across a face edge: a border inside
        // the face repeats texels of its own level (never a border) or samples an
        // ancestor's, and neither changed in the first pass.
        let across = self.cfg.tiles_across(id.level as u32) - 1;
        for &(n, sides) in &refill {
            if n.x == 0 || n.y == 0 || n.x == across || n.y == across {
                self.fill_border(n, sides);
            }
        }
        self.evict(Some(id));
        Ok(())
    }

    /// Tiles whose border may read `id`, each with the sides of its border to refill:
    /// the eight around it on its face (the side facing it; corners are always
    /// refilled), and where it touches a face edge the tiles of the same level across that
    /// edge whose texels its own border reads, with their neighbours along the edge (the
    /// tile grids of two faces need not line up; whole borders).
    fn neighbours(&self, id: TileId) -> Vec<(TileId, u8)> {
        let n = self.cfg.tiles_across(id.level as u32) as i64;
        let mut out = Vec::new();
        for dy in -1i64..=1 {
            for dx in -1i64..=1 {
                let (x, y) = (id.x as i64 + dx, id.y as i64 + dy);
                if (dx, dy) != (0, 0) && (0..n).contains(&x) && (0..n).contains(&y) {
                    // The neighbour's side toward `id` (none for a diagonal one: corners).
                    let side = match (dx, dy) {
                        (-1, 0) => RIGHT,
                        (1, 0) => LEFT,
                        (0, -1) => BOTTOM,
                        (0, 1) => TOP,
                        _ => 0,
                    };
                    out.push((
                        TileId {
                            x: x as u32,
                            y: y as u32,
                            ..id
                        },
                        side,
                    ));
                }
            }
        }
        let edge = |t: &TileId| t.x == 0 || t.y == 0 || t.x as i64 == n - 1 || t.y as i64 == n - 1;
        if edge(&id) {
            let mut across = Vec::new();
            self.border_reads(id, &mut across);
            across.sort_unstable();
            across.dedup();
            let mut near = TileSet::default();
            for a in across.into_iter().filter(|a| a.face != id.face) {
                for t in a.around(n as u32) {
                    if edge(&t) && near.insert(t) {
                        out.push((t, ALL_SIDES));
                    }
                }
            }
        }
        out
    }

    /// The tiles of `id`'s level holding the positions its border reads outside its face
    /// (the neighbouring faces' tiles at those directions), pushed on `out`.
    fn border_reads(&self, id: TileId, out: &mut Vec<TileId>) {
        let level = id.level as u32;
        let size = self.cfg.level_size(level) as i64;
        let (w, h) = self.cfg.tile_dims(id);
        let (w, h) = (w as i64, h as i64);
        let t = self.cfg.tile_size(level) as i64;
        let (x0, y0) = (id.x as i64 * t, id.y as i64 * t);
        let n = self.cfg.tiles_across(level);
        let half = size as f64 / 2.0;
        let tf = t as f64;
        let cell = |c: f64| ((c.max(0.0) / tf) as u32).min(n - 1);
        let mut at = |ix: i64, iy: i64| {
            if (0..size).contains(&ix) && (0..size).contains(&iy) {
                return;
            }
            let s = 2.0 * (ix as f64 + 0.5) / size as f64 - 1.0;
            let tt = 1.0 - 2.0 * (iy as f64 + 0.5) / size as f64;
            let d = face_dir(id.face, s, tt);
            let f2 = face_of(d);
            let (u, v) = face_uv(f2, d, half);
            out.push(TileId {
                level: id.level,
                face: f2,
                x: cell(u),
                y: cell(v),
            });
        };
        for bx in -1..=w {
            at(x0 + bx, y0 - 1);
            at(x0 + bx, y0 + h);
        }
        for by in 0..h {
            at(x0 - 1, y0 + by);
            at(x0 + w, y0 + by);
        }
    }

    fn evict(&mut self, keep: Option<TileId>) {
        if self.bytes <= self.budget {
            return;
        }
        let mut order: Vec<(u64, TileId)> = self
            .tiles
            .iter()
            .filter(|(id, t)| !t.pinned && Some(**id) != keep)
            .map(|(id, t)| (t.used.load(Ordering::Relaxed), *id))
            .collect();
        order.sort_unstable();
        for (_, id) in order {
            if self.bytes <= self.budget {
                break;
            }
            if let Some(t) = self.tiles.remove(&id) {
                self.bytes -= t.px.len() * 4;
                self.evicted += 1;
            }
        }
    }

    /// Fill the `sides` ([`TOP`], [`BOTTOM`], [`LEFT`], [`RIGHT`]) and the four corners
    /// of decoded tile `id`'s border from its neighbours (or their ancestors). A side
    /// inside the face whose neighbour is decoded is copied from that neighbour's edge
    /// row or column (one lookup a side); any other texel is [`TileStore::texel`]'s.
    fn fill_border(&mut self, id: TileId, sides: u8) {
        let Some(t) = self.tiles.get(&id) else { return };
        let (w, h) = (t.w as usize, t.h as usize);
        let level = id.level as u32;
        let tile = self.cfg.tile_size(level) as usize;
        let n = self.cfg.tiles_across(level);
        let (x0, y0) = (id.x as i64 * tile as i64, id.y as i64 * tile as i64);
        let s = self.stride(level);
        let mut ring: Vec<(usize, u32)> = Vec::with_capacity(2 * (w + h + 4));
        let mut stale = Vec::new();
        let mut slow = |bx: usize, by: usize, ring: &mut Vec<(usize, u32)>| {
            let v = self.texel(
                level,
                id.face,
                x0 + bx as i64 - 1,
                y0 + by as i64 - 1,
                &mut stale,
            );
            ring.push((by * s + bx, v));
        };
        for (bx, by) in [(0, 0), (w + 1, 0), (0, h + 1), (w + 1, h + 1)] {
            slow(bx, by, &mut ring);
        }
        // Each side: the neighbour on this face, if any, and its length.
        let plan = [
            (TOP, id.y.checked_sub(1).map(|y| (id.x, y)), w),
            (BOTTOM, (id.y + 1 < n).then_some((id.x, id.y + 1)), w),
            (LEFT, id.x.checked_sub(1).map(|x| (x, id.y)), h),
            (RIGHT, (id.x + 1 < n).then_some((id.x + 1, id.y)), h),
        ];
        for (side, nb, len) in plan {
            if sides & side == 0 {
                continue;
            }
            let from = nb.and_then(|(x, y)| self.tiles.get(&TileId { x, y, ..id }));
            for k in 1..=len {
                // Border position k of this side in this tile's buffer, and the texel of
                // the neighbour's buffer it repeats (a tile above or left of another is
                // never short: its last row or column is `tile`).
                let (bx, by, src) = match side {
                    TOP => (k, 0, tile * s + k),
                    BOTTOM => (k, h + 1, s + k),
                    LEFT => (0, k, k * s + tile),
                    _ => (w + 1, k, k * s + 1),
                };
                match from {
                    Some(f) => ring.push((by * s + bx, f.px[src])),
                    None => slow(bx, by, &mut ring),
                }
            }
        }
        stale.sort_unstable();
        stale.dedup();
        stale.retain(|&n| n != id);
        if sides != ALL_SIDES {
            // The sides not refilled keep what they stood in for, less what has arrived
            // since (whose arrival refilled them).
            let old = &self.tiles[&id].stale;
            let keep: Vec<TileId> = old
                .iter()
                .copied()
                .filter(|k| !self.tiles.contains_key(k))
                .collect();
            stale.extend(keep);
            stale.sort_unstable();
            stale.dedup();
        }
        let t = self.tiles.get_mut(&id).expect("present");
        for (i, v) in ring {
            t.px[i] = v;
        }
        t.stale = stale;
        // The texels right of and below a short tile's border repeat it (positions inside
        // the tile never read them; a position rounded a hair past the edge reads the
        // border's value).
        for row in t.px.chunks_exact_mut(s).take(h + 2) {
            let edge = row[w + 1];
            row[w + 2..].fill(edge);
        }
        let last = (h + 1) * s;
        let (top, rest) = t.px.split_at_mut(last + s);
        let edge = &top[last..];
        for row in rest.chunks_exact_mut(s) {
            row.copy_from_slice(edge);
        }
    }

    /// Texel `(ix, iy)` of `face` at `level`, where the indices may lie one texel outside
    /// the face (then: the neighbouring face's bilinear sample in that direction), from
    /// the tile holding it or its nearest decoded ancestor. A tile of `level` wanted and
    /// not decoded is pushed on `stale`.
    fn texel(&self, level: u32, face: Face, ix: i64, iy: i64, stale: &mut Vec<TileId>) -> u32 {
        let size = self.cfg.level_size(level) as i64;
        if (0..size).contains(&ix) && (0..size).contains(&iy) {
            let t = self.cfg.tile_size(level) as i64;
            let id = TileId {
                level: level as u8,
                face,
                x: (ix / t) as u32,
                y: (iy / t) as u32,
            };
            if let Some(tile) = self.tiles.get(&id) {
                let s = self.stride(level);
                return tile.px[((iy % t) + 1) as usize * s + (ix % t) as usize + 1];
            }
            stale.push(id);
            if level > 1 {
                let sc = self.cfg.level_size(level - 1) as f64 / size as f64;
                return self.bilinear(
                    level - 1,
                    face,
                    (ix as f64 + 0.5) * sc,
                    (iy as f64 + 0.5) * sc,
                    false,
                );
            }
            return self.cfg.background;
        }
        let half = size as f64 / 2.0;
        let s = 2.0 * (ix as f64 + 0.5) / size as f64 - 1.0;
        let tt = 1.0 - 2.0 * (iy as f64 + 0.5) / size as f64;
        let d = face_dir(face, s, tt);
        let f2 = face_of(d);
        let (u, v) = face_uv(f2, d, half);
        // The neighbour face's sample reads the tile holding (u, v) and, within half a
        // texel of its edge, that tile's border: the tile is the one wanted.
        let n = self.cfg.tiles_across(level);
        let t = self.cfg.tile_size(level) as f64;
        let cell = |c: f64| ((c.max(0.0) / t) as u32).min(n - 1);
        let want = TileId {
            level: level as u8,
            face: f2,
            x: cell(u),
            y: cell(v),
        };
        if !self.tiles.contains_key(&want) {
            stale.push(want);
        }
        self.bilinear(level, f2, u, v, false)
    }

    /// The decoded tile at `level` holding face position `(u, v)` (clamped into the
    /// face), or the nearest ancestor's: `(tile, its level, its tile id)`.
    #[inline]
    pub(crate) fn tile_at(
        &self,
        level: u32,
        face: Face,
        u: f64,
        v: f64,
    ) -> Option<(&Tile, u32, TileId)> {
        let mut l = level;
        let top = self.cfg.level_size(level) as f64;
        loop {
            let size = self.cfg.level_size(l);
            let sc = size as f64 / top;
            let n = self.cfg.tiles_across(l);
            let t = self.cfg.tile_size(l) as f64;
            let col = (((u * sc).max(0.0) / t) as u32).min(n - 1);
            let row = (((v * sc).max(0.0) / t) as u32).min(n - 1);
            let id = TileId {
                level: l as u8,
                face,
                x: col,
                y: row,
            };
            if let Some(tile) = self.get(id) {
                return Some((tile, l, id));
            }
            if l <= 1 {
                return None;
            }
            l -= 1;
        }
    }

    /// Per-pixel bilinear at face position `(u, v)` of `level` (face texels of that
    /// level), from the tile there or the nearest decoded ancestor; `count`: a frame's
    /// read (hit/miss counted). The arithmetic of `CubeMap::bilinear` on the tile's
    /// bordered texels.
    pub(crate) fn bilinear(&self, level: u32, face: Face, u: f64, v: f64, count: bool) -> u32 {
        let size = self.cfg.level_size(level) as f64;
        let (u, v) = (u.max(0.0).min(size), v.max(0.0).min(size));
        let Some((tile, l, id)) = self.tile_at(level, face, u, v) else {
            return self.cfg.background;
        };
        if count {
            self.count(l == level);
        }
        let sc = self.cfg.level_size(l) as f64 / size;
        let t = self.cfg.tile_size(l) as f64;
        let (lu, lv) = (u * sc - id.x as f64 * t, v * sc - id.y as f64 * t);
        let (lu, lv) = (
            lu.max(0.0).min(tile.w as f64),
            lv.max(0.0).min(tile.h as f64),
        );
        let uu = (lu * FX_ONE as f64 + 0.5) as i64 + FX_HALF;
        let vv = (lv * FX_ONE as f64 + 0.5) as i64 + FX_HALF;
        let (x0, y0) = ((uu >> FX_BITS) as usize, (vv >> FX_BITS) as usize);
        let fx = ((uu >> (FX_BITS - 8)) & 0xFF) as u32;
        let fy = ((vv >> (FX_BITS - 8)) & 0xFF) as u32;
        let s = self.stride(l);
        let i = y0 * s + x0;
        let (r0, r1) = (&tile.px[i..i + 2], &tile.px[i + s..i + s + 2]);
        lerp_px(lerp_px(r0[0], r0[1], fx), lerp_px(r1[0], r1[1], fx), fy)
    }

    /// Per-pixel nearest at face position `(u, v)` of `level`.
    pub(crate) fn nearest(&self, level: u32, face: Face, u: f64, v: f64, count: bool) -> u32 {
        let size = self.cfg.level_size(level) as f64;
        let Some((tile, l, id)) = self.tile_at(level, face, u, v) else {
            return self.cfg.background;
        };
        if count {
            self.count(l == level);
        }
        let sc = self.cfg.level_size(l) as f64 / size;
        let t = self.cfg.tile_size(l) as f64;
        let x = ((u * sc - id.x as f64 * t).max(0.0) as usize).min(tile.w as usize - 1);
        let y = ((v * sc - id.y as f64 * t).max(0.0) as usize).min(tile.h as usize - 1);
        tile.px[(y + 1) * self.stride(l) + x + 1]
    }
}

//! The name of one tile (level, face, row, column) and the fast hash the tile maps use.

use crate::cube::Face;

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

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

impl TileId {
    /// This tile and its eight neighbours on its face, those inside a grid of `n × n`
    /// tiles (the level's [`tiles_across`](super::MultiresConfig::tiles_across)), row by
    /// row.
    pub fn around(self, n: u32) -> impl Iterator<Item = TileId> {
        let n = i64::from(n);
        (-1i64..=1).flat_map(move |dy| {
            (-1i64..=1).filter_map(move |dx| {
                let (x, y) = (i64::from(self.x) + dx, i64::from(self.y) + dy);
                ((0..n).contains(&x) && (0..n).contains(&y)).then_some(TileId {
                    x: x as u32,
                    y: y as u32,
                    ..self
                })
            })
        })
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn around_keeps_the_neighbours_inside_the_face() {
        let t = |x, y| TileId {
            level: 3,
            face: Face::Front,
            y,
            x,
        };
        let xy = |v: Vec<TileId>| v.iter().map(|t| (t.x, t.y)).collect::<Vec<_>>();
        assert_eq!(
            xy(t(0, 0).around(4).collect()),
            [(0, 0), (1, 0), (0, 1), (1, 1)]
        );
        assert_eq!(t(1, 2).around(4).count(), 9);
        assert_eq!(
            xy(t(3, 3).around(4).collect()),
            [(2, 2), (3, 2), (2, 3), (3, 3)]
        );
        assert_eq!(xy(t(0, 0).around(1).collect()), [(0, 0)]);
        assert!(t(1, 2)
            .around(4)
            .all(|n| n.level == 3 && n.face == Face::Front));
    }
}

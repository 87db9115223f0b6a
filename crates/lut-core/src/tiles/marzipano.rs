//! Marzipano's tile layout (the Marzipano tool's export: `tiles/<id>/{z}/{f}/{y}/{x}.jpg`
//! and `preview.jpg`, its levels listed in `data.js`) as a [`MultiresConfig`], read by the
//! same store, loader and renderer as Pannellum's pyramids (docs/huge.md, "Marzipano").

use super::config::{
    LevelInfo, MultiresConfig, Naming, TilesError, MAX_BASE_TILES, MAX_CUBE_RESOLUTION, MAX_LEVELS,
    MAX_TILE_RESOLUTION, MIN_TILE_RESOLUTION,
};
use std::collections::HashSet;
use std::path::Path;

/// The order of the faces in a Marzipano `preview.jpg` (top to bottom; its
/// `cubeMapPreviewFaceOrder` default).
pub const MARZIPANO_PREVIEW_ORDER: &str = "bdflru";

impl MultiresConfig {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cube::Face;
    use crate::tiles::id::TileId;

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
}

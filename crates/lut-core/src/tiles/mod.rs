//! Tiled multiresolution pyramids (Pannellum's `multires` format, and a Marzipano scene's
//! tiles) read from disk: the configuration ([`MultiresConfig`]), decoded tiles in an LRU cache under a byte budget
//! ([`TileStore`]), a background decode pool ([`TileLoader`]) and frames drawn from the
//! tiles with the cube renderer's kernels ([`render_tiles`]). [`TiledPanorama`] holds the
//! three together. -> docs/huge.md, "Gigapixel panoramas from tiles".

pub(crate) mod config;
pub(crate) mod decode;
pub(crate) mod id;
pub(crate) mod loader;
pub(crate) mod marzipano;
pub(crate) mod render;
pub(crate) mod store;
pub(crate) mod write;

pub use config::{LevelInfo, MultiresConfig, TilesError};
pub use decode::decode_bytes;
pub use id::TileId;
pub use loader::{DecodeStats, TileLoader, PUMP_MAX_TILES, PUMP_MAX_TIME};
pub use marzipano::MARZIPANO_PREVIEW_ORDER;
pub use render::{frame_level, render_tiles, trilinear_levels, TileFrame};
pub use store::{CacheStats, TileStore};
pub use write::{generator_levels, write_marzipano, write_pyramid};

use crate::cube::Face;
use crate::geom::camera::View;
use crate::map::sample::Sampler;
use std::path::Path;
use std::sync::Arc;

/// A pyramid opened for viewing: its configuration, the decoded tiles and the pool.
#[derive(Debug)]
pub struct TiledPanorama {
    store: TileStore,
    loader: TileLoader,
}

impl TiledPanorama {
    /// Open the pyramid at `path` (its folder or its `config.json`) with a cache of
    /// `budget` bytes and `threads` decoding threads; level 1 (the coarsest, at most
    /// 8 × 8 tiles a face) is decoded before this returns, so every frame has something
    /// to draw.
    ///
    /// # Errors
    /// The configuration's [`TilesError`]. Tiles that cannot be decoded are not errors:
    /// they are drawn from their ancestor, or the background, with a notice.
    pub fn open(path: &Path, budget: usize, threads: usize) -> Result<TiledPanorama, TilesError> {
        TiledPanorama::open_with(path, budget, threads, Arc::new(decode::decode_tile))
    }

    /// Open the pyramid `cfg` describes (a Marzipano scene's,
    /// [`MultiresConfig::marzipano`]), as [`TiledPanorama::open`].
    pub fn with_config(cfg: MultiresConfig, budget: usize, threads: usize) -> TiledPanorama {
        TiledPanorama::with_config_and_decoder(cfg, budget, threads, Arc::new(decode::decode_tile))
    }

    /// [`TiledPanorama::open`] with the pool's threads calling `decoder`.
    pub(crate) fn open_with(
        path: &Path,
        budget: usize,
        threads: usize,
        decoder: Arc<loader::Decoder>,
    ) -> Result<TiledPanorama, TilesError> {
        Ok(TiledPanorama::with_config_and_decoder(
            MultiresConfig::open(path)?,
            budget,
            threads,
            decoder,
        ))
    }

    /// [`TiledPanorama::with_config`] with the pool's threads calling `decoder`.
    pub(crate) fn with_config_and_decoder(
        cfg: MultiresConfig,
        budget: usize,
        threads: usize,
        decoder: Arc<loader::Decoder>,
    ) -> TiledPanorama {
        let cfg = Arc::new(cfg);
        let mut store = TileStore::new(cfg.clone(), budget);
        let mut loader = TileLoader::with_decoder(cfg.clone(), threads, decoder);
        let n = cfg.tiles_across(1);
        let base: Vec<TileId> = Face::ALL
            .iter()
            .flat_map(|&face| {
                (0..n).flat_map(move |y| {
                    (0..n).map(move |x| TileId {
                        level: 1,
                        face,
                        x,
                        y,
                    })
                })
            })
            .collect();
        loader.load_now(&mut store, &base);
        TiledPanorama { store, loader }
    }

    /// The configuration.
    pub fn config(&self) -> &MultiresConfig {
        self.store.config()
    }

    /// The decoded tiles.
    pub fn store(&self) -> &TileStore {
        &self.store
    }

    /// The decoded tiles, to change the budget.
    pub fn store_mut(&mut self) -> &mut TileStore {
        &mut self.store
    }

    /// What the decoding threads did since the open ([`DecodeStats`]).
    pub fn decode_stats(&self) -> DecodeStats {
        self.loader.decode_stats()
    }

    /// Tiles requested and not yet decoded.
    pub fn pending(&self) -> usize {
        self.loader.pending()
    }

    /// Take tiles decoded since the last call into the cache, at most
    /// [`PUMP_MAX_TILES`] and for about [`PUMP_MAX_TIME`] (the rest on the next call:
    /// a frame is never held up by a burst of arrivals); returns how many.
    pub fn pump(&mut self) -> usize {
        self.loader
            .pump_some(&mut self.store, PUMP_MAX_TILES, Some(PUMP_MAX_TIME))
    }

    /// A frame that waits for nothing: drawn from what is decoded (missing tiles from
    /// their ancestors), then the tiles it lacked are requested, nearest the centre
    /// first, with the ring around them and the next level's tiles under the centre
    /// (`prefetch`); earlier requests not repeated are cancelled.
    #[allow(clippy::too_many_arguments)]
    pub fn render(
        &mut self,
        view: View,
        sampler: Sampler,
        level: u32,
        pixels: &mut [u32],
        width: u32,
        height: u32,
        prefetch: bool,
    ) -> TileFrame {
        self.pump();
        self.store.next_frame();
        let f = render_tiles(&self.store, view, sampler, level, pixels, width, height);
        let mut want = f.missed();
        if prefetch {
            want.extend(self.prefetch(&f));
        }
        want.retain(|id| !self.store.settled(*id));
        self.loader.request(&want);
        f
    }

    /// The ring of tiles around those the frame read, then the next level's under them.
    fn prefetch(&self, f: &TileFrame) -> Vec<TileId> {
        let cfg = self.store.config();
        let mut out = Vec::new();
        let read: std::collections::HashSet<TileId> = f.touched.iter().map(|t| t.0).collect();
        for (id, _, _) in &f.touched {
            let n = cfg.tiles_across(id.level as u32);
            out.extend(id.around(n).filter(|t| !read.contains(t)));
        }
        if f.level < cfg.max_level {
            // The next level's tiles under the nearest quarter of those read.
            for (id, _, _) in f.touched.iter().take(f.touched.len().div_ceil(4)) {
                out.extend(cfg.children(*id));
            }
        }
        out
    }

    /// A trilinear frame: bilinear on `fine` blended with bilinear on `fine − 1`, weight
    /// `t` ([`trilinear_levels`]); `wait` as [`TiledPanorama::render_wait`], else as
    /// [`TiledPanorama::render`]. The report is the finer level's (its misses and whether
    /// it was drawn coarser).
    #[allow(clippy::too_many_arguments)]
    pub fn render_trilinear(
        &mut self,
        view: View,
        fine: u32,
        t: f64,
        pixels: &mut [u32],
        width: u32,
        height: u32,
        wait: bool,
    ) -> TileFrame {
        let draw = |p: &mut Self, level: u32, px: &mut [u32]| {
            if wait {
                p.render_wait(view, Sampler::Bilinear, level, px, width, height)
            } else {
                p.render(view, Sampler::Bilinear, level, px, width, height, true)
            }
        };
        let w8 = (t.clamp(0.0, 1.0) * 256.0).round() as u32;
        if w8 == 0 || fine <= 1 {
            return draw(self, fine, pixels);
        }
        let mut coarse = vec![0u32; pixels.len()];
        // The coarser level first: the finer level's requests are the ones kept.
        draw(self, fine - 1, &mut coarse);
        let f = draw(self, fine, pixels);
        for (p, c) in pixels.iter_mut().zip(&coarse) {
            *p = crate::map::sample::lerp_px(*p, *c, w8);
        }
        f
    }

    /// A frame drawn only when every tile it reads at `level` is decoded (or cannot be):
    /// the same bytes whatever the timing (the CLI's `viewer render`).
    pub fn render_wait(
        &mut self,
        view: View,
        sampler: Sampler,
        level: u32,
        pixels: &mut [u32],
        width: u32,
        height: u32,
    ) -> TileFrame {
        let mut f = TileFrame::default();
        // A frame's tiles are known after drawing it; loading them can change which
        // border texels a frame reads, never which tiles, so two rounds settle it (four
        // allowed when the budget evicts).
        for _ in 0..4 {
            self.store.next_frame();
            f = render_tiles(&self.store, view, sampler, level, pixels, width, height);
            let missed: Vec<TileId> = f
                .missed()
                .into_iter()
                .filter(|id| !self.store.settled(*id))
                .collect();
            if missed.is_empty() {
                break;
            }
            self.loader.load_now(&mut self.store, &missed);
        }
        f
    }

    /// Level 1 (decoded at open) as a cube map: what lighting and small previews use.
    /// A tile of level 1 that could not be decoded is the background there.
    pub fn base_cube(&self) -> crate::cube::CubeMap {
        let n = self.config().level_size(1);
        let faces: Vec<Vec<u32>> = Face::ALL
            .iter()
            .map(|&f| {
                (0..n)
                    .flat_map(|y| (0..n).map(move |x| (x as f64 + 0.5, y as f64 + 0.5)))
                    .map(|(u, v)| self.store.nearest(1, f, u, v, false))
                    .collect()
            })
            .collect();
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        crate::cube::CubeMap::from_faces(n.max(1), refs).unwrap_or_else(|_| {
            let one = [self.config().background];
            crate::cube::CubeMap::from_faces(1, [&one[..]; 6]).expect("a 1-texel cube")
        })
    }

    /// The finest level as a cube map, texel for texel (each tile decoded, a row of
    /// tiles at a time so the cache budget holds): what `viewer tile` re-tiles. A tile
    /// that cannot be decoded is the background there.
    ///
    /// # Errors
    /// The finest face is larger than [`crate::cube::MAX_FACE_SIZE`].
    pub fn full_cube(&mut self) -> Result<crate::cube::CubeMap, TilesError> {
        let cfg = self.config().clone();
        let level = cfg.max_level;
        let n = cfg.level_size(level);
        let too_big = || {
            TilesError::new(
                &cfg.file,
                format!(
                    "its finest faces are {n} px, more than the {} px a cube map holds",
                    crate::cube::MAX_FACE_SIZE
                ),
            )
        };
        if n > crate::cube::MAX_FACE_SIZE {
            return Err(too_big());
        }
        let across = cfg.tiles_across(level);
        let tile = cfg.tile_size(level);
        let nu = n as usize;
        let mut faces = vec![vec![0u32; nu * nu]; 6];
        for (k, &face) in Face::ALL.iter().enumerate() {
            for ty in 0..across {
                let ids: Vec<TileId> = (0..across)
                    .map(|x| TileId {
                        level: level as u8,
                        face,
                        y: ty,
                        x,
                    })
                    .collect();
                self.store.next_frame();
                self.loader.load_now(&mut self.store, &ids);
                for y in ty * tile..((ty + 1) * tile).min(n) {
                    for x in 0..n {
                        faces[k][y as usize * nu + x as usize] =
                            self.store
                                .nearest(level, face, x as f64 + 0.5, y as f64 + 0.5, false);
                    }
                }
            }
        }
        let refs: [&[u32]; 6] = std::array::from_fn(|k| faces[k].as_slice());
        crate::cube::CubeMap::from_faces(n.max(1), refs).map_err(|_| too_big())
    }

    /// Notices since the last call (one per tile that could not be decoded).
    pub fn take_notices(&mut self) -> Vec<String> {
        self.store.take_notices()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;
    use std::sync::Mutex;
    use std::time::{Duration, Instant};

    /// A pyramid of faces of `cube` texels in `tile` tiles, each level one flat colour of
    /// its own (`0x10_00_00 · level`), as PNG (exact colours).
    fn flat_levels(dir: &Path, cube: u32, tile: u32) -> u32 {
        write_pyramid(dir, cube, tile, "png", &|id: TileId, _, _, w, h| {
            vec![0x10_00_00 * id.level as u32; (w * h) as usize]
        })
        .unwrap()
    }

    /// Run `f` on a thread; fail (instead of hanging) when it has not returned within
    /// 60 s.
    fn within_a_minute<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let _ = tx.send(f());
        });
        rx.recv_timeout(Duration::from_secs(60))
            .unwrap_or_else(|_| panic!("{what}: still waiting after 60 s"))
    }

    #[test]
    fn a_frame_never_waits_for_a_decode_that_does_not_finish() {
        let dir = tempfile::tempdir().unwrap();
        let levels = flat_levels(dir.path(), 256, 32);
        assert!(levels >= 3);
        // Level 1 decodes (the open waits for it); every other tile's decode blocks until
        // the test lets it go, which it does only after the frames.
        let (release, gate) = mpsc::channel::<()>();
        let gate = Arc::new(Mutex::new(gate));
        let decoder: Arc<loader::Decoder> = Arc::new(move |cfg: &MultiresConfig, id: TileId| {
            if id.level > 1 {
                let _ = gate.lock().unwrap().recv();
                return Err("released".into());
            }
            decode::decode_tile(cfg, id)
        });
        let mut pano = TiledPanorama::open_with(dir.path(), 64 << 20, 2, decoder).unwrap();
        let (w, h) = (96u32, 64u32);
        let frames = within_a_minute("frames with every decode blocked", move || {
            let mut out = Vec::new();
            for (k, yaw) in [0.0, 50.0, 130.0, -100.0].into_iter().enumerate() {
                let view = View::new(yaw, 20.0 * k as f64 - 30.0, 30.0).unwrap();
                let mut px = vec![0u32; (w * h) as usize];
                let f = pano.render(view, Sampler::Bilinear, levels, &mut px, w, h, true);
                out.push((f, px, pano.pending()));
            }
            (out, pano)
        });
        let (out, pano) = frames;
        for (f, px, pending) in &out {
            assert_eq!(f.level, levels);
            assert!(f.coarser(), "nothing of the top level is decoded");
            assert!(*pending > 0, "the frame's tiles are requested");
            // Every pixel from level 1, the one level decoded: no hole, no other colour.
            assert!(
                px.iter().all(|&p| p == 0x10_00_00),
                "drawn from level 1 alone"
            );
        }
        drop(release);
        drop(pano);
    }

    #[test]
    fn a_burst_of_arrivals_is_taken_in_over_several_frames() {
        let dir = tempfile::tempdir().unwrap();
        let levels = flat_levels(dir.path(), 512, 16);
        let mut pano = TiledPanorama::open(dir.path(), 256 << 20, 2).unwrap();
        let (w, h) = (160u32, 120u32);
        let view = View::new(10.0, 5.0, 120.0).unwrap();
        let mut px = vec![0u32; (w * h) as usize];
        let f = pano.render(view, Sampler::Bilinear, levels, &mut px, w, h, false);
        let wanted = f.missed().len();
        assert!(
            wanted > 2 * PUMP_MAX_TILES,
            "a burst larger than one frame takes in: {wanted}"
        );
        // Let every requested tile be decoded before the next frame.
        let base = pano.store().stats().decoded;
        let t = Instant::now();
        while (pano.decode_stats().tiles as usize) < base as usize + pano.pending() {
            assert!(t.elapsed() < Duration::from_secs(60), "decoding stalled");
            std::thread::sleep(Duration::from_millis(5));
        }
        let mut frames = 0;
        let mut last = base;
        while pano.pending() > 0 {
            pano.render(view, Sampler::Bilinear, levels, &mut px, w, h, false);
            let now = pano.store().stats().decoded;
            assert!(
                now - last <= PUMP_MAX_TILES as u64,
                "a frame took in {} tiles",
                now - last
            );
            last = now;
            frames += 1;
            assert!(frames < 10_000, "the arrivals never all arrive");
        }
        assert!(frames >= 2, "the burst was spread over frames");
        // And then the frame is the top level's colour everywhere.
        let f = pano.render(view, Sampler::Bilinear, levels, &mut px, w, h, false);
        assert!(!f.coarser());
        assert!(px.iter().all(|&p| p == 0x10_00_00 * levels));
    }
}

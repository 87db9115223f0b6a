//! The background decode pool: requests nearest the view's centre first, a request no
//! longer wanted cancelled (each call of [`TileLoader::request`] replaces the queue; tiles
//! already being decoded finish), results handed to the owner of the [`TileStore`] between
//! frames ([`TileLoader::pump`]), so a frame never waits for a tile.

use super::config::MultiresConfig;
use super::decode::decode_tile;
use super::id::TileId;
use super::store::{bordered, TileStore};
use std::collections::HashSet;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// A tile decoded (its texels laid out for the store's border, [`bordered`]) or why not.
type Done = (TileId, Result<Vec<u32>, String>);

/// What the pool's threads call to read and decode a tile: [`decode_tile`], or a test's
/// stand-in (one that blocks proves frames never wait for a decode).
pub(crate) type Decoder = dyn Fn(&MultiresConfig, TileId) -> Result<Vec<u32>, String> + Send + Sync;

/// The most tiles one [`TileLoader::pump_some`] call takes in by default, and the time
/// after which it stops early: each arrival fills its border and refills its
/// neighbours' (work on the frame's thread), so a burst of arrivals is spread over frames
/// instead of stalling one (the 0.5–1 s frames of the first bench, docs/huge.md).
pub const PUMP_MAX_TILES: usize = 32;
/// See [`PUMP_MAX_TILES`].
pub const PUMP_MAX_TIME: Duration = Duration::from_millis(4);

#[derive(Default)]
struct Queue {
    /// Wanted tiles, the next to decode last.
    wanted: Vec<TileId>,
    busy: HashSet<TileId>,
    /// Decoded and sent, not yet taken in by [`TileLoader::pump_some`]: not decoded
    /// again when requested meanwhile.
    sent: HashSet<TileId>,
    stop: bool,
}

struct Shared {
    q: Mutex<Queue>,
    cv: Condvar,
    /// Tiles decoded (successfully), their texels and the threads' time decoding them
    /// (reading the file included), for [`TileLoader::decode_stats`].
    tiles: AtomicU64,
    texels: AtomicU64,
    busy_ns: AtomicU64,
}

/// What the pool's threads decoded since it started (the bench's rates per thread).
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct DecodeStats {
    /// Tiles decoded (failures not counted).
    pub tiles: u64,
    /// Their texels.
    pub texels: u64,
    /// Seconds the threads spent reading and decoding tiles, summed over the threads.
    pub busy_s: f64,
}

/// A pool of threads decoding tiles of one pyramid.
pub struct TileLoader {
    shared: Arc<Shared>,
    rx: Receiver<Done>,
    threads: Vec<JoinHandle<()>>,
    /// Requested and not yet handed to the store.
    outstanding: HashSet<TileId>,
}

impl std::fmt::Debug for TileLoader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TileLoader")
            .field("threads", &self.threads.len())
            .field("outstanding", &self.outstanding.len())
            .finish()
    }
}

impl TileLoader {
    /// Start `threads` decoding threads (at least one) for `cfg`.
    pub fn new(cfg: Arc<MultiresConfig>, threads: usize) -> TileLoader {
        TileLoader::with_decoder(cfg, threads, Arc::new(decode_tile))
    }

    /// [`TileLoader::new`] with the threads calling `decoder` instead of [`decode_tile`].
    pub(crate) fn with_decoder(
        cfg: Arc<MultiresConfig>,
        threads: usize,
        decoder: Arc<Decoder>,
    ) -> TileLoader {
        let shared = Arc::new(Shared {
            q: Mutex::new(Queue::default()),
            cv: Condvar::new(),
            tiles: AtomicU64::new(0),
            texels: AtomicU64::new(0),
            busy_ns: AtomicU64::new(0),
        });
        let (tx, rx) = channel();
        let threads = (0..threads.max(1))
            .map(|i| {
                let (s, c, tx) = (shared.clone(), cfg.clone(), tx.clone());
                let d = decoder.clone();
                std::thread::Builder::new()
                    .name(format!("tiles-{i}"))
                    .spawn(move || worker(&s, &c, &*d, &tx))
                    .expect("spawn a tile decoding thread")
            })
            .collect();
        TileLoader {
            shared,
            rx,
            threads,
            outstanding: HashSet::new(),
        }
    }

    /// Want `ids` (the first the most), instead of whatever was wanted before: tiles
    /// not listed and not yet started are cancelled.
    pub fn request(&mut self, ids: &[TileId]) {
        let mut guard = self.shared.q.lock().unwrap_or_else(|e| e.into_inner());
        let q = &mut *guard;
        let mut seen = HashSet::new();
        q.wanted = ids
            .iter()
            .rev()
            .filter(|id| !q.busy.contains(id) && !q.sent.contains(id) && seen.insert(**id))
            .copied()
            .collect();
        self.outstanding = q
            .wanted
            .iter()
            .chain(q.busy.iter())
            .chain(q.sent.iter())
            .copied()
            .collect();
        drop(guard);
        self.shared.cv.notify_all();
    }

    /// Tiles decoded, their texels and the threads' busy time since the pool started.
    pub fn decode_stats(&self) -> DecodeStats {
        DecodeStats {
            tiles: self.shared.tiles.load(Ordering::Relaxed),
            texels: self.shared.texels.load(Ordering::Relaxed),
            busy_s: self.shared.busy_ns.load(Ordering::Relaxed) as f64 * 1e-9,
        }
    }

    /// Tiles requested and not yet in the store.
    pub fn pending(&self) -> usize {
        self.outstanding.len()
    }

    /// Hand the decoded tiles to `store` (a tile that failed: its one notice); returns
    /// how many arrived.
    pub fn pump(&mut self, store: &mut TileStore) -> usize {
        self.pump_some(store, usize::MAX, None)
    }

    /// [`TileLoader::pump`] of at most `max` tiles, stopping early once `time` has passed
    /// (after one tile at least); the rest wait in the channel for the next call. Never
    /// waits for a tile.
    pub fn pump_some(
        &mut self,
        store: &mut TileStore,
        max: usize,
        time: Option<Duration>,
    ) -> usize {
        let t = Instant::now();
        let mut n = 0;
        while n < max {
            let Ok((id, r)) = self.rx.try_recv() else {
                break;
            };
            self.arrive(store, id, r);
            n += 1;
            if time.is_some_and(|d| t.elapsed() >= d) {
                break;
            }
        }
        n
    }

    fn arrive(&mut self, store: &mut TileStore, id: TileId, r: Result<Vec<u32>, String>) {
        self.outstanding.remove(&id);
        self.shared
            .q
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .sent
            .remove(&id);
        match r.and_then(|buf| store.insert_bordered(id, buf)) {
            Ok(()) => {}
            Err(e) => store.fail(id, &e),
        }
    }

    /// Decode `ids` now and wait until every one is in `store` (or failed).
    pub fn load_now(&mut self, store: &mut TileStore, ids: &[TileId]) {
        let want: Vec<TileId> = ids
            .iter()
            .copied()
            .filter(|id| !store.settled(*id))
            .collect();
        self.request(&want);
        let mut left: HashSet<TileId> = want.into_iter().collect();
        while !left.is_empty() {
            match self.rx.recv_timeout(Duration::from_secs(60)) {
                Ok((id, r)) => {
                    left.remove(&id);
                    self.arrive(store, id, r);
                }
                Err(_) => {
                    for id in left.drain() {
                        store.fail(id, "not decoded within 60 s");
                    }
                }
            }
        }
    }
}

impl Drop for TileLoader {
    fn drop(&mut self) {
        {
            let mut q = self.shared.q.lock().unwrap_or_else(|e| e.into_inner());
            q.stop = true;
            q.wanted.clear();
        }
        self.shared.cv.notify_all();
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

fn worker(s: &Shared, cfg: &MultiresConfig, decoder: &Decoder, tx: &Sender<Done>) {
    loop {
        let id = {
            let mut q = s.q.lock().unwrap_or_else(|e| e.into_inner());
            loop {
                if q.stop {
                    return;
                }
                if let Some(id) = q.wanted.pop() {
                    q.busy.insert(id);
                    break id;
                }
                q = s.cv.wait(q).unwrap_or_else(|e| e.into_inner());
            }
        };
        let t = Instant::now();
        // Behind the decoders' one containment as a whole (the file's read, the path's
        // making): a panic is this tile's error, so the thread lives on and the tile is
        // settled, never waited for (docs/reliability.md, class 2).
        let r = crate::guard::catch_quiet(|| decoder(cfg, id))
            .unwrap_or_else(|m| Err(format!("the decoder failed on this file ({m})")));
        let texels = r.as_ref().map_or(0, |px| px.len() as u64);
        // Laid out for the store here, off the frame's thread.
        let r = r.and_then(|px| bordered(cfg.tile_size(id.level as u32), cfg.tile_dims(id), &px));
        let ns = u64::try_from(t.elapsed().as_nanos()).unwrap_or(u64::MAX);
        s.busy_ns.fetch_add(ns, Ordering::Relaxed);
        if r.is_ok() {
            s.tiles.fetch_add(1, Ordering::Relaxed);
            s.texels.fetch_add(texels, Ordering::Relaxed);
        }
        {
            let mut q = s.q.lock().unwrap_or_else(|e| e.into_inner());
            q.busy.remove(&id);
            q.sent.insert(id);
        }
        if tx.send((id, r)).is_err() {
            return;
        }
    }
}

//! The lit panorama in the window: once the lighting has settled, the panorama is lit once
//! ([`lut_core::IlluminanceMap::bake_panorama`]) on the baking thread
//! (`baker.rs`) and from then on panned like an unlit one, at an unlit frame's cost.
//!
//! While the lighting changes (a light or the room dragged, a slider moving, the coarse
//! preview map shown) frames are lit one by one from the illuminance map, so each change
//! shows at once. The lighting has settled when the full map is built, nothing is being
//! dragged, and the map and shading options are the same as on the frame before: then the
//! bake is requested, and frames stay lit one by one until it arrives (no frame waits for
//! it). Each request has a number; a bake is taken only when it answers the request in
//! flight, the one for the current lighting: when the lighting changes the request is
//! cancelled, and a bake that finishes anyway is dropped when it arrives. Memory: at most
//! the lit copy in use (or one finished, waiting to be taken or dropped) and one being
//! built. Exposure, ambient and false-colour changes bake again from the same map.
//! Panoramas whose lit copy would exceed [`lut_core::BAKE_MAX_BYTES`] keep the per-frame
//! lighting.

use super::baker::{Baker, Done, Job, Wake};
use lut_core::{lit_panorama_bytes, IlluminanceMap, Panorama, ShadeOptions, BAKE_MAX_BYTES};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// What a lit copy was baked from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BakeKey {
    /// The illuminance map's generation ([`super::LitCache::generation`]).
    pub map_generation: u64,
    /// The panorama's generation (a new file, or the same one reloaded).
    pub scene_generation: u64,
    /// How E turns into colour.
    pub shade: ShadeOptions,
}

/// Where the lit panorama stands (the lights panel shows it).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum BakeState {
    /// No luminaire: nothing to bake.
    #[default]
    Off,
    /// The lighting is changing: frames are lit one by one.
    Changing,
    /// Settled, the bake is running on the baking thread: frames are lit one by one
    /// until it arrives.
    Baking,
    /// Baked: frames pan the lit copy.
    Baked {
        /// Its memory (the copy and its pyramid).
        bytes: usize,
        /// How long the bake took.
        ms: f64,
    },
    /// Too large to bake: frames are lit one by one.
    TooLarge {
        /// The memory the copy would take.
        bytes: usize,
    },
    /// The bake failed (bad shading options): frames are lit one by one.
    Failed(String),
}

impl BakeState {
    /// One line for the lights panel.
    pub fn describe(&self) -> String {
        let mib = |b: usize| b as f64 / f64::from(1 << 20);
        match self {
            BakeState::Off => String::new(),
            BakeState::Changing => "lit panorama: lighting changing, each frame lit".into(),
            BakeState::Baking => "lit panorama: baking, each frame lit until it is done".into(),
            BakeState::Baked { bytes, ms } => {
                format!("lit panorama: {:.0} MiB, baked in {ms:.0} ms", mib(*bytes))
            }
            BakeState::TooLarge { bytes } => format!(
                "lit panorama: would take {:.0} MiB (over {} MiB), each frame lit",
                mib(*bytes),
                BAKE_MAX_BYTES >> 20
            ),
            BakeState::Failed(e) => format!("lit panorama: {e}"),
        }
    }
}

/// The bake in flight.
struct InFlight {
    /// Its request's number.
    id: u64,
    /// Set to stop it.
    cancel: Arc<AtomicBool>,
    /// The memory the copy will take.
    bytes: usize,
}

/// The lit copy of the current panorama, baked on the baking thread once the lighting has
/// settled.
pub struct LitPanorama {
    /// The key of the previous frame.
    seen: Option<BakeKey>,
    /// The key the copy (or the bake in flight, or the decision not to bake) is for.
    key: Option<BakeKey>,
    /// The lit copy: a panorama of the same kind and geometry, sharing the tables.
    copy: Option<Panorama>,
    state: BakeState,
    /// The lighting was settled on the last update (a bake is due on the next frame when
    /// it is [`BakeState::Changing`]).
    settled: bool,
    in_flight: Option<InFlight>,
    /// The number of the last request.
    requests: u64,
    /// Started on the first bake.
    baker: Option<Baker>,
    /// Threads for the bake's bands.
    threads: usize,
    wake: Wake,
}

impl LitPanorama {
    /// No copy yet; bakes will run on `threads` threads (the frames' pool has as many) and
    /// call `wake` when one is done (the window asks for a frame then).
    pub fn new(threads: usize, wake: Wake) -> LitPanorama {
        LitPanorama {
            seen: None,
            key: None,
            copy: None,
            state: BakeState::Off,
            settled: false,
            in_flight: None,
            requests: 0,
            baker: None,
            threads,
            wake,
        }
    }

    /// Update for this frame: `key` is the current lighting (`None` without luminaires),
    /// `settled` whether nothing is being dragged and the full map is built, `map` the
    /// illuminance map and `scene` the panorama. Requests a bake when the lighting has been
    /// the same since the frame before and is settled; takes the bake that answers the
    /// request for the current lighting when it has arrived; drops the copy, and cancels
    /// the bake in flight, as soon as the lighting differs from theirs. True when frames
    /// should pan the lit copy ([`LitPanorama::copy_mut`]).
    pub fn update(
        &mut self,
        key: Option<BakeKey>,
        settled: bool,
        map: Option<&Arc<IlluminanceMap>>,
        scene: &Panorama,
    ) -> bool {
        // First the bakes that have arrived (a stale one is freed before this frame
        // requests another).
        self.receive();
        let (Some(key), Some(map)) = (key, map) else {
            self.cancel();
            (self.seen, self.key, self.copy) = (None, None, None);
            (self.state, self.settled) = (BakeState::Off, false);
            return false;
        };
        self.settled = settled;
        if self.key != Some(key) {
            // Lit (or being lit) for other lighting: of no use any more.
            self.cancel();
            (self.copy, self.key) = (None, None);
            let stable = self.seen == Some(key);
            self.seen = Some(key);
            if stable && settled {
                self.key = Some(key);
                self.request(key, map, scene);
            } else {
                self.state = BakeState::Changing;
            }
        }
        self.copy.is_some()
    }

    /// Request the bake for `key` (the memory checked first).
    fn request(&mut self, key: BakeKey, map: &Arc<IlluminanceMap>, scene: &Panorama) {
        let bytes = lit_panorama_bytes(scene);
        if bytes > BAKE_MAX_BYTES {
            self.state = BakeState::TooLarge { bytes };
            return;
        }
        if self.baker.is_none() {
            match Baker::start(self.threads, self.wake.clone()) {
                Ok(b) => self.baker = Some(b),
                Err(e) => {
                    self.state = BakeState::Failed(e);
                    return;
                }
            }
        }
        self.requests += 1;
        let cancel = Arc::new(AtomicBool::new(false));
        let job = Job {
            id: self.requests,
            map: map.clone(),
            panorama: scene.share(),
            shade: key.shade,
            cancel: cancel.clone(),
        };
        if self.baker.as_ref().is_some_and(|b| b.submit(job)) {
            self.in_flight = Some(InFlight {
                id: self.requests,
                cancel,
                bytes,
            });
            self.state = BakeState::Baking;
        } else {
            self.baker = None;
            self.state = BakeState::Failed("the baking thread has stopped".into());
        }
    }

    /// Cancel the bake in flight (its result, if it comes, is dropped).
    fn cancel(&mut self) {
        if let Some(f) = self.in_flight.take() {
            f.cancel.store(true, Ordering::Relaxed);
        }
    }

    /// Take the finished bakes that have arrived: the one answering the request in flight
    /// becomes the copy, any other (for lighting that has since changed) is dropped.
    fn receive(&mut self) {
        while let Some(done) = self.baker.as_ref().and_then(Baker::try_recv) {
            self.take(done);
        }
    }

    /// The generation rule: `done` is taken only when it answers the request in flight.
    fn take(&mut self, done: Done) {
        let Some(f) = self.in_flight.take_if(|f| f.id == done.id) else {
            return;
        };
        match done.result {
            Ok(copy) => {
                self.copy = Some(copy);
                self.state = BakeState::Baked {
                    bytes: f.bytes,
                    ms: done.ms,
                };
            }
            Err(e) => self.state = BakeState::Failed(e),
        }
    }

    /// A bake is due to be requested on the next frame (the window asks for one; a bake
    /// in flight wakes the window itself when it is done).
    pub fn pending(&self) -> bool {
        self.settled && self.state == BakeState::Changing
    }

    /// Where the lit panorama stands.
    pub fn state(&self) -> &BakeState {
        &self.state
    }

    /// The lit copy to render (a panorama of the same kind and geometry as the one it
    /// was lit from, sharing its tables), or `None` when there is none.
    pub fn copy_mut(&mut self) -> Option<&mut Panorama> {
        self.copy.as_mut()
    }
}

impl Drop for LitPanorama {
    fn drop(&mut self) {
        // The baking thread stops at its next band (and ends: its sender goes with us).
        self.cancel();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lighting::{LightsState, LitCache};
    use crate::scene::render_scene;
    use lut_core::{grid_map, Camera, EnvMap, Projection, RenderOptions, Sampler, View};
    use std::path::Path;
    use std::sync::mpsc::{channel, Receiver};
    use std::time::Duration;

    fn lamp() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/ies/label_lines.ies")
    }

    fn key(cache: &LitCache, st: &LightsState) -> Option<BakeKey> {
        Some(BakeKey {
            map_generation: cache.generation(),
            scene_generation: 1,
            shade: st.shade_options(),
        })
    }

    /// A lit panorama on the real baking thread, and the wakes it sends.
    fn threaded() -> (LitPanorama, Receiver<()>) {
        let (tx, rx) = channel();
        let wake: Wake = Arc::new(move || {
            let _ = tx.send(());
        });
        (LitPanorama::new(2, wake), rx)
    }

    /// Wait for the baking thread's wake (a bake sent back).
    fn woken(rx: &Receiver<()>) {
        rx.recv_timeout(Duration::from_secs(60))
            .expect("the bake never arrived");
    }

    #[test]
    fn baked_off_the_ui_thread_when_settled_dropped_when_changing() {
        let mut st = LightsState::default();
        st.load_and_add(&lamp()).unwrap();
        let mut cache = LitCache::default();
        let mut scene = Panorama::map(grid_map(256, 128, Projection::Equirect).unwrap());
        let (mut lit, wakes) = threaded();
        // Coarse map, then the full one: frames lit one by one.
        let m = cache.update(&mut st, true).unwrap();
        assert!(!lit.update(key(&cache, &st), !cache.refining(), m.as_ref(), &scene));
        assert_eq!(lit.state(), &BakeState::Changing);
        let m = cache.update(&mut st, true).unwrap();
        assert!(!lit.update(key(&cache, &st), !cache.refining(), m.as_ref(), &scene));
        assert!(lit.pending(), "the full map is there: a bake is due");
        // Unchanged for a frame: the bake is requested; this frame is still lit from the
        // map (it does not wait), and the window is woken when the bake is done.
        assert!(!lit.update(key(&cache, &st), true, m.as_ref(), &scene));
        assert_eq!(lit.state(), &BakeState::Baking);
        assert!(!lit.pending(), "a bake in flight wakes the window itself");
        woken(&wakes);
        assert!(lit.update(key(&cache, &st), true, m.as_ref(), &scene));
        assert!(matches!(lit.state(), BakeState::Baked { bytes, .. } if *bytes > 0));
        assert!(lit.state().describe().starts_with("lit panorama: "));
        assert!(lit.copy_mut().is_some());
        // Its frames are the lit room: against the per-frame lighting, within the
        // filtering-order tolerance of tests/lit_bake.rs (here: a few levels on average).
        let view = View::new(20.0, -30.0, 90.0).unwrap();
        let (w, h) = (160u32, 100u32);
        let opts = RenderOptions {
            sampler: Sampler::Bilinear,
            ..RenderOptions::default()
        };
        let mut want = vec![0u32; (w * h) as usize];
        render_scene(&mut scene, view, &opts, &mut want, w, h).unwrap();
        m.as_ref()
            .unwrap()
            .shade_frame(
                &Camera::new(view, w, h),
                &mut want,
                w,
                h,
                &st.shade_options(),
            )
            .unwrap();
        let mut got = vec![0u32; (w * h) as usize];
        let r = lit.copy_mut().unwrap();
        render_scene(r, view, &opts, &mut got, w, h).unwrap();
        let close = want
            .iter()
            .zip(&got)
            .filter(|(a, b)| test_support::pixels::max_channel_diff(**a, **b) <= 2)
            .count();
        assert!(close * 100 >= want.len() * 98, "{close} of {}", want.len());
        // The exposure changes: the copy is dropped at once, baked again from the same
        // map once the lighting has stayed for a frame.
        st.exposure_lux *= 2.0;
        st.auto_exposure = false;
        let m = cache.update(&mut st, true).unwrap();
        assert!(!lit.update(key(&cache, &st), true, m.as_ref(), &scene));
        assert!(lit.copy_mut().is_none());
        assert!(!lit.update(key(&cache, &st), true, m.as_ref(), &scene));
        woken(&wakes);
        assert!(lit.update(key(&cache, &st), true, m.as_ref(), &scene));
        // Dragging (not settled): never baked.
        st.lights[0].position[0] += 0.1;
        let m = cache.update(&mut st, false).unwrap();
        for _ in 0..3 {
            assert!(!lit.update(key(&cache, &st), false, m.as_ref(), &scene));
            assert!(!lit.pending());
            assert_eq!(lit.state(), &BakeState::Changing);
        }
        // No luminaire: off.
        assert!(!lit.update(None, true, None, &scene));
        assert_eq!(lit.state(), &BakeState::Off);
    }

    #[test]
    fn a_stale_bake_is_dropped_the_current_one_taken() {
        // The baking thread played by the test: it sees each request and answers when
        // it likes, so a bake can arrive after its lighting changed.
        let mut st = LightsState::default();
        st.load_and_add(&lamp()).unwrap();
        st.auto_exposure = false;
        let mut cache = LitCache::default();
        let scene = Panorama::map(grid_map(128, 64, Projection::Equirect).unwrap());
        let pano = scene.as_map().unwrap();
        let (mut lit, _wakes) = threaded();
        let (baker, jobs, done) = Baker::fake();
        lit.baker = Some(baker);
        let m = cache.update(&mut st, false).unwrap();
        // Settled lighting A: bake 1 requested.
        let a = key(&cache, &st);
        lit.update(a, true, m.as_ref(), &scene);
        assert!(!lit.update(a, true, m.as_ref(), &scene));
        let job1 = jobs.try_recv().unwrap();
        assert_eq!(lit.state(), &BakeState::Baking);
        // The exposure changes and settles (lighting B) before bake 1 is back: bake 1 is
        // cancelled, bake 2 requested (at most one in flight).
        st.exposure_lux *= 4.0;
        let b = key(&cache, &st);
        assert!(!lit.update(b, true, m.as_ref(), &scene));
        assert!(
            job1.cancel.load(Ordering::Relaxed),
            "the older bake is cancelled"
        );
        assert!(!lit.update(b, true, m.as_ref(), &scene));
        let job2 = jobs.try_recv().unwrap();
        assert!(job2.id > job1.id && !job2.cancel.load(Ordering::Relaxed));
        assert!(jobs.try_recv().is_err(), "one request per settled lighting");
        let texels = |m: &EnvMap| -> Vec<u32> {
            (0..m.height())
                .flat_map(|y| (0..m.width()).map(move |x| m.pixel(x, y)))
                .collect()
        };
        let bake = |job: &Job| {
            let copy = job.map.bake_map(pano, &job.shade).unwrap();
            let px = texels(&copy);
            (copy, px)
        };
        let ((copy1, px1), (copy2, px2)) = (bake(&job1), bake(&job2));
        assert_ne!(
            px1, px2,
            "the two exposures must light the panorama differently"
        );
        // Bake 1 arrives late: dropped, frames stay lit one by one.
        let send = |id: u64, copy: EnvMap| {
            let result = Ok(Panorama::map(copy));
            done.send(Done {
                id,
                result,
                ms: 1.0,
            })
            .unwrap();
        };
        send(job1.id, copy1);
        assert!(!lit.update(b, true, m.as_ref(), &scene));
        assert_eq!(lit.state(), &BakeState::Baking);
        assert!(lit.copy.is_none());
        // Bake 2 arrives: taken, and it is B's.
        send(job2.id, copy2);
        assert!(lit.update(b, true, m.as_ref(), &scene));
        assert!(matches!(lit.state(), BakeState::Baked { .. }));
        let taken = lit.copy.as_ref().and_then(Panorama::as_map);
        assert!(taken.is_some_and(|c| texels(c) == px2));
        // A bake for the current lighting that arrives after the lighting changed again
        // (not yet settled) is dropped too.
        st.exposure_lux *= 2.0;
        let c = key(&cache, &st);
        lit.update(c, true, m.as_ref(), &scene);
        assert!(!lit.update(c, true, m.as_ref(), &scene));
        let job3 = jobs.try_recv().unwrap();
        let (copy3, _) = bake(&job3);
        st.exposure_lux *= 2.0;
        assert!(!lit.update(key(&cache, &st), false, m.as_ref(), &scene));
        send(job3.id, copy3);
        assert!(!lit.update(key(&cache, &st), false, m.as_ref(), &scene));
        assert!(lit.copy.is_none() && lit.state() == &BakeState::Changing);
        // A failed bake (for the current lighting) is reported.
        let d = key(&cache, &st);
        lit.update(d, true, m.as_ref(), &scene);
        lit.update(d, true, m.as_ref(), &scene);
        let job4 = jobs.try_recv().unwrap();
        let result = Err("bad shading".to_string());
        done.send(Done {
            id: job4.id,
            result,
            ms: 0.0,
        })
        .unwrap();
        assert!(!lit.update(d, true, m.as_ref(), &scene));
        assert_eq!(lit.state(), &BakeState::Failed("bad shading".into()));
    }
}

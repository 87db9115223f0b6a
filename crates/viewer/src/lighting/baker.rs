//! The thread that bakes the lit panorama for the window ([`super::LitPanorama`]), so the
//! UI thread never waits for a bake (about 40 ms for 4096 × 2048 on 2 threads, 145 ms for
//! 8192 × 4096).
//!
//! One thread takes the requests in order, so at most one bake is in flight: a newer
//! request cancels the older one (its flag, checked before each band of rows by
//! [`lut_core::IlluminanceMap::bake_map_cancellable`]) and starts once that one has
//! stopped; requests queued behind a newer one are skipped. The bake's bands run on a
//! rayon pool of its own: on the global pool, which draws the frames, a frame's bands
//! would queue behind the bake's (rayon's workers take their own queued work before work
//! handed in from outside) and the frame would mostly wait for the bake. The two pools
//! share the cores, so frames drawn during a bake take longer but are not held up.
//! A finished bake is sent back with its request's number and the event loop is woken
//! (no polling); a bake cancelled before it finished is dropped here.

use super::baked::LitCopy;
use lut_core::{CubeMap, EnvMap, IlluminanceMap, LightError, ShadeOptions};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;
use std::time::Instant;

/// Wakes the event loop when a bake is done.
pub type Wake = Arc<dyn Fn() + Send + Sync>;

/// The panorama to light (shared with the window, not copied).
#[derive(Clone)]
pub(super) enum Panorama {
    Map(Arc<EnvMap>),
    Cube(Arc<CubeMap>),
}

/// One bake to run.
pub(super) struct Job {
    /// The request's number (a later request has a larger one).
    pub id: u64,
    pub map: Arc<IlluminanceMap>,
    pub panorama: Panorama,
    pub shade: ShadeOptions,
    /// Set when the lighting changed: the bake stops and nothing is sent back.
    pub cancel: Arc<AtomicBool>,
}

/// A finished bake.
pub(super) struct Done {
    /// The request's number.
    pub id: u64,
    /// The lit copy, or why it could not be made (one line).
    pub result: Result<LitCopy, String>,
    /// How long the bake took.
    pub ms: f64,
}

/// The baking thread: requests in, finished bakes out.
pub(super) struct Baker {
    jobs: Sender<Job>,
    done: Receiver<Done>,
}

impl Baker {
    /// Start the thread, with a pool of `threads` for the bake's bands; `wake` is called
    /// after each bake sent back.
    ///
    /// # Errors
    /// The thread or the pool could not be started (one line).
    pub fn start(threads: usize, wake: Wake) -> Result<Baker, String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads.max(1))
            .thread_name(|i| format!("viewer-bake-{i}"))
            .build()
            .map_err(|e| format!("cannot start the baking threads: {e}"))?;
        let (jobs, job_rx) = channel::<Job>();
        let (done_tx, done) = channel::<Done>();
        std::thread::Builder::new()
            .name("viewer-bake".into())
            .spawn(move || run(&job_rx, &done_tx, &wake, &pool))
            .map_err(|e| format!("cannot start the baking thread: {e}"))?;
        Ok(Baker { jobs, done })
    }

    /// Queue `job`. False when the thread has gone.
    pub fn submit(&self, job: Job) -> bool {
        self.jobs.send(job).is_ok()
    }

    /// A finished bake, if one is waiting.
    pub fn try_recv(&self) -> Option<Done> {
        self.done.try_recv().ok()
    }

    /// A baker with no thread: the test takes the requests and sends back what it likes
    /// (the generation rule, tested without timing).
    #[cfg(test)]
    pub fn fake() -> (Baker, Receiver<Job>, Sender<Done>) {
        let (jobs, job_rx) = channel();
        let (done_tx, done) = channel();
        (Baker { jobs, done }, job_rx, done_tx)
    }
}

/// The thread's loop: until the window (the sender) is gone.
fn run(jobs: &Receiver<Job>, done: &Sender<Done>, wake: &Wake, pool: &rayon::ThreadPool) {
    while let Ok(mut job) = jobs.recv() {
        // Requests queued behind a newer one were cancelled by it.
        while let Ok(newer) = jobs.try_recv() {
            job = newer;
        }
        if job.cancel.load(Ordering::Relaxed) {
            continue;
        }
        let t0 = Instant::now();
        let result = pool.install(|| bake(&job));
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        if matches!(result, Err(LightError::Cancelled)) || job.cancel.load(Ordering::Relaxed) {
            continue;
        }
        let result = result.map_err(|e| e.to_string());
        if done
            .send(Done {
                id: job.id,
                result,
                ms,
            })
            .is_err()
        {
            return;
        }
        wake();
    }
}

/// Light `job`'s panorama (on the calling pool).
fn bake(job: &Job) -> Result<LitCopy, LightError> {
    let (map, shade, cancel) = (&job.map, &job.shade, &*job.cancel);
    match &job.panorama {
        Panorama::Map(pano) => map
            .bake_map_cancellable(pano, shade, cancel)
            .map(LitCopy::Map),
        Panorama::Cube(cube) => map
            .bake_cube_cancellable(cube, shade, cancel)
            .map(LitCopy::Cube),
    }
}

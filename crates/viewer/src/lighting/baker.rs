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
//! share the cores, so frames drawn during a bake take longer but are not held up; the
//! bake's threads run at the lowest priority ([`BAKE_NICE`]), so the frames come first.
//! A finished bake is sent back with its request's number and the event loop is woken
//! (no polling); a bake cancelled before it finished is dropped here.

use lut_core::{IlluminanceMap, LightError, Panorama, ShadeOptions};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;
use std::time::Instant;

/// Wakes the event loop when a bake is done.
pub type Wake = Arc<dyn Fn() + Send + Sync>;

/// One bake to run.
pub(super) struct Job {
    /// The request's number (a later request has a larger one).
    pub id: u64,
    pub map: Arc<IlluminanceMap>,
    /// The panorama to light: a handle on the window's (`Panorama::share`: the same
    /// pixels and tables, not copied).
    pub panorama: Panorama,
    pub shade: ShadeOptions,
    /// Set when the lighting changed: the bake stops and nothing is sent back.
    pub cancel: Arc<AtomicBool>,
}

/// A finished bake.
pub(super) struct Done {
    /// The request's number.
    pub id: u64,
    /// The lit copy (a panorama of the same kind, sharing the tables), or why it could
    /// not be made (one line).
    pub result: Result<Panorama, String>,
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
            .start_handler(|_| lower_priority())
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

/// The scheduling priority of the bake's threads: Linux nice 19, the lowest. The frames
/// the window draws while a bake runs then get the cores first (the bake takes what they
/// leave, and all of them when the view is still), so they are not held up by it. Measured
/// with `cargo run --release -p lut-core --example bake_contention nice=19`: 1080p frames
/// panning an 8192 × 4096 map during back-to-back bakes, median of 5 runs, 6.1 ms at nice
/// 19 against 8.8 ms at nice 0 (4.5 ms without a bake); the bake itself 1.3–2× slower.
const BAKE_NICE: i32 = 19;

/// Lower the calling thread's priority to [`BAKE_NICE`] (Linux: nice is per thread, set
/// by thread id). Elsewhere, or if the call fails, the thread keeps its priority: only
/// the frames' smoothness during a bake depends on it, never a result.
#[allow(unsafe_code)]
fn lower_priority() {
    #[cfg(target_os = "linux")]
    // SAFETY: two system calls on the calling thread's own id; no memory is passed.
    unsafe {
        let tid = libc::gettid();
        libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, BAKE_NICE);
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
fn bake(job: &Job) -> Result<Panorama, LightError> {
    job.map
        .bake_panorama(&job.panorama, &job.shade, &job.cancel)
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    /// The bake's threads really run at the lowest priority (and the caller's does not
    /// change): read back with getpriority on the thread's own id.
    #[test]
    #[allow(unsafe_code)]
    fn bake_threads_run_at_the_lowest_priority() {
        // SAFETY: getpriority on the calling thread's own id; no memory is passed.
        let nice =
            || unsafe { libc::getpriority(libc::PRIO_PROCESS, libc::gettid() as libc::id_t) };
        let before = nice();
        let lowered = std::thread::spawn(move || {
            lower_priority();
            nice()
        })
        .join()
        .unwrap();
        assert_eq!(lowered, BAKE_NICE);
        assert_eq!(nice(), before);
    }
}

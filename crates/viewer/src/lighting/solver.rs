//! The inter-reflections and the work plane's figures for the window, off the UI thread.
//!
//! The radiosity solve ([`lut_core::Radiosity`]) takes tens to hundreds of milliseconds;
//! the window must not wait for it. A change of the room, the luminaires or the
//! reflectances sends a request (the direct scene, the reflectances, the work plane's
//! height) to one thread, which solves and then reads the work plane's EN 12464-1 grid
//! exactly as `viewer report` does ([`work_plane`]: the same grid, the same direct + exact
//! indirect sum, the same [`AreaStats`]), and sends both back with the request's key,
//! waking the event loop. Requests queued behind a newer one are skipped; a result whose
//! key is no longer the panel's (the scene changed while it ran) is discarded when taken.
//! Until the fresh solve arrives the illuminance map is built with the last solve of the
//! same room and reflectances (only luminaires moved: close), else the direct light
//! ([`super::LitCache`]), so frames never wait.

use super::baker::Wake;
use super::state::{LightsKey, LightsState};
use lut_core::{AreaStats, CalcGrid, LightScene, Radiosity, Reflectances};
use rayon::prelude::*;
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;

/// The work plane's height the window reports, metres (`viewer report`'s default).
pub const WORK_PLANE_HEIGHT: f64 = 0.75;

/// The illuminance (direct + exact indirect) at each point of `grid`: what `viewer
/// report` reads on every area.
pub fn read_grid(scene: &LightScene, grid: &CalcGrid) -> Vec<f64> {
    grid.points
        .par_iter()
        .map(|&p| scene.direct(p, grid.normal) + scene.indirect(p, grid.normal))
        .collect()
}

/// The work plane's grid at `height`, its readings and figures (Em, Emin, Emax, U0, Ud)
/// in `scene` (with its inter-reflections, if it has them).
///
/// # Errors
/// A height outside the room, or a grid past the budget (the message).
pub fn work_plane(
    scene: &LightScene,
    height: f64,
) -> Result<(CalcGrid, Vec<f64>, AreaStats), String> {
    let grid = CalcGrid::work_plane(scene.room(), height).map_err(|e| e.to_string())?;
    let values = read_grid(scene, &grid);
    let stats = AreaStats::of(&values);
    Ok((grid, values, stats))
}

/// The panel's line for the work plane: "Em 512 lx  U0 0.64" from `solved` (for the
/// lights as they are), "computing…" while a request is out, or why there are none.
pub fn describe_work_plane(solved: Option<&Solved>, pending: bool) -> String {
    match solved.map(|s| &s.work_plane) {
        Some(Ok((stats, _))) => format!(
            "Em {}  U0 {:.2}",
            super::format_lux(Some(stats.em)),
            stats.u0
        ),
        Some(Err(e)) => format!("none: {e}"),
        None if pending => "computing…".into(),
        None => "—".into(),
    }
}

/// One request.
struct Request {
    id: u64,
    key: LightsKey,
    /// The direct scene (luminaires in the room).
    scene: LightScene,
    /// The reflectances, `None` with inter-reflections off.
    reflectances: Option<Reflectances>,
    height: f64,
}

/// What the thread sends back.
#[derive(Debug, Clone)]
pub struct Solved {
    /// The request's number.
    pub id: u64,
    /// What it was computed from.
    pub key: LightsKey,
    /// The inter-reflections (`None` with them off or every reflectance 0).
    pub radiosity: Option<Arc<Radiosity>>,
    /// The work plane's figures and its number of points, or why there are none.
    pub work_plane: Result<(AreaStats, usize), String>,
}

/// Solve `r` (on the calling thread).
fn solve(r: Request) -> Solved {
    let radiosity = match r.reflectances {
        Some(refl) if !refl.is_zero() => match Radiosity::solve_cached(&r.scene, refl) {
            Ok(s) => Some(s),
            Err(e) => {
                return Solved {
                    id: r.id,
                    key: r.key,
                    radiosity: None,
                    work_plane: Err(e.to_string()),
                }
            }
        },
        _ => None,
    };
    let scene = match &radiosity {
        Some(s) => r.scene.with_radiosity(s.clone()),
        None => r.scene,
    };
    let work_plane = work_plane(&scene, r.height).map(|(g, _, s)| (s, g.points.len()));
    Solved {
        id: r.id,
        key: r.key,
        radiosity,
        work_plane,
    }
}

/// The solving thread and what it last sent back.
pub struct Solver {
    jobs: Option<Sender<Request>>,
    done: Receiver<Solved>,
    /// The key of the last request sent.
    asked: Option<LightsKey>,
    next_id: u64,
    /// The newest result taken whose key was current when taken.
    latest: Option<Solved>,
    /// Results dropped because the lights had changed by the time they arrived.
    discarded: u64,
}

impl Solver {
    /// Start the thread; `wake` is called after each result sent back. If the thread
    /// cannot be started, requests are solved on the caller's thread instead (slower
    /// frames, the same figures).
    pub fn start(wake: Wake) -> Solver {
        let (jobs, job_rx) = channel::<Request>();
        let (done_tx, done) = channel::<Solved>();
        let started = std::thread::Builder::new()
            .name("viewer-radiosity".into())
            .spawn(move || {
                while let Ok(mut job) = job_rx.recv() {
                    // Requests queued behind a newer one are stale already.
                    while let Ok(newer) = job_rx.try_recv() {
                        job = newer;
                    }
                    if done_tx.send(solve(job)).is_err() {
                        return;
                    }
                    wake();
                }
            })
            .is_ok();
        let (jobs, done) = if started {
            (Some(jobs), done)
        } else {
            // No thread: `request` solves at once into this channel.
            let (tx, rx) = channel();
            std::mem::forget(tx);
            (None, rx)
        };
        Solver {
            jobs,
            done,
            asked: None,
            next_id: 0,
            latest: None,
            discarded: 0,
        }
    }

    /// Ask for the figures (and the inter-reflections) of `st` when its luminaires, room
    /// or reflectances changed since the last request; nothing with no luminaire or a
    /// scene that cannot be built (the panel shows that error). True when a request was
    /// sent.
    pub fn request(&mut self, st: &LightsState) -> bool {
        let key = st.geometry_key();
        if self.asked.as_ref() == Some(&key) {
            return false;
        }
        let scene = match st.direct_scene() {
            Ok(Some(s)) => s,
            Ok(None) => {
                self.asked = None;
                self.latest = None;
                return false;
            }
            Err(e) => {
                // Nothing to solve; the reason stands in for the figures.
                self.latest = Some(Solved {
                    id: 0,
                    key: key.clone(),
                    radiosity: None,
                    work_plane: Err(e),
                });
                self.asked = Some(key);
                return false;
            }
        };
        self.asked = Some(key.clone());
        self.next_id += 1;
        let req = Request {
            id: self.next_id,
            key,
            scene,
            reflectances: st.indirect.then_some(st.reflectances),
            height: WORK_PLANE_HEIGHT,
        };
        match &self.jobs {
            Some(tx) => {
                if let Err(e) = tx.send(req) {
                    // The thread has gone: solve here.
                    self.latest = Some(solve(e.0));
                }
            }
            None => self.latest = Some(solve(req)),
        }
        true
    }

    /// Take what the thread sent back: results for `current` (the panel's key now) are
    /// kept, stale ones dropped. True when a current result arrived.
    pub fn poll(&mut self, current: &LightsKey) -> bool {
        let mut fresh = false;
        while let Ok(s) = self.done.try_recv() {
            if &s.key == current {
                self.latest = Some(s);
                fresh = true;
            } else {
                self.discarded += 1;
            }
        }
        fresh
    }

    /// The newest current result, if any.
    pub fn latest(&self) -> Option<&Solved> {
        self.latest.as_ref()
    }

    /// A request is out whose result has not been taken.
    pub fn pending(&self) -> bool {
        self.asked.is_some() && self.latest.as_ref().map(|s| &s.key) != self.asked.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lighting::sample_path;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::{Duration, Instant};

    fn state() -> LightsState {
        let mut st = LightsState {
            room: (6.0, 5.0, 2.8),
            ..LightsState::default()
        };
        for _ in 0..3 {
            st.load_and_add(&sample_path()).unwrap();
        }
        st
    }

    /// Wait (bounded) for a current result.
    fn wait(s: &mut Solver, key: &LightsKey) -> bool {
        let t0 = Instant::now();
        while t0.elapsed() < Duration::from_secs(60) {
            if s.poll(key) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        false
    }

    #[test]
    fn figures_arrive_from_the_thread_and_match_the_report() {
        let wakes = Arc::new(AtomicUsize::new(0));
        let w = wakes.clone();
        let mut s = Solver::start(Arc::new(move || {
            w.fetch_add(1, Ordering::SeqCst);
        }));
        let st = state();
        assert!(s.request(&st));
        // The same state again: nothing new to ask.
        assert!(!s.request(&st));
        assert!(s.pending());
        let key = st.geometry_key();
        assert!(wait(&mut s, &key), "no result");
        assert!(!s.pending());
        assert!(wakes.load(Ordering::SeqCst) >= 1);
        let got = s.latest().unwrap();
        assert!(
            got.radiosity.is_some(),
            "inter-reflections are on by default"
        );
        let (stats, points) = got.work_plane.clone().unwrap();
        // `viewer report`'s own computation of the same scene.
        let scene = st.scene().unwrap().unwrap();
        let (grid, _, want) = work_plane(&scene, WORK_PLANE_HEIGHT).unwrap();
        assert_eq!(points, grid.points.len());
        assert!(
            (stats.em - want.em).abs() <= 1e-9 * want.em,
            "{stats:?} {want:?}"
        );
        assert!((stats.u0 - want.u0).abs() <= 1e-9, "{stats:?} {want:?}");
        // And more than the direct light alone.
        let direct = st.direct_scene().unwrap().unwrap();
        let (_, _, d) = work_plane(&direct, WORK_PLANE_HEIGHT).unwrap();
        assert!(stats.em > d.em * 1.05, "{} vs direct {}", stats.em, d.em);
    }

    #[test]
    fn a_result_for_a_scene_that_changed_is_discarded() {
        let mut s = Solver::start(Arc::new(|| {}));
        let mut st = state();
        assert!(s.request(&st));
        let old = st.geometry_key();
        st.lights[0].position[0] += 0.5;
        let new = st.geometry_key();
        // Taken while the panel shows the moved light: the old result is stale.
        let t0 = Instant::now();
        while t0.elapsed() < Duration::from_secs(60) && s.discarded == 0 {
            assert!(!s.poll(&new));
            std::thread::sleep(Duration::from_millis(5));
        }
        assert_eq!(s.discarded, 1);
        assert!(s.latest().is_none());
        // The moved light's own request brings a current result.
        assert!(s.request(&st));
        assert!(wait(&mut s, &new));
        assert_eq!(s.latest().unwrap().key, new);
        assert_ne!(old, new);
    }

    #[test]
    fn no_luminaire_no_request() {
        let mut s = Solver::start(Arc::new(|| {}));
        assert!(!s.request(&LightsState::default()));
        assert!(s.latest().is_none());
    }
}

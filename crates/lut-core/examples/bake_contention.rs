//! Frames drawn while a lit copy bakes, as in the window: the bake's bands on a rayon
//! pool of their own (`viewer`'s `lighting/baker.rs`), the frames on the global pool,
//! both sharing the cores. Prints the median frame time with no bake, then during
//! back-to-back bakes with the bake threads at nice 0 and at the given nice value, and
//! the bakes' median time in each case.
//!
//! ```sh
//! cargo build --release -p lut-core --example bake_contention
//! target/release/examples/bake_contention            # nice 19 (the window's) against 0
//! target/release/examples/bake_contention nice=10 frames=100 map=8192x4096
//! ```

use glam::DVec3;
use lut_core::{grid_map, Frame, Projection, RenderOptions, Renderer, View};
use lut_core::{IesFile, IlluminanceMap, LightScene, LightTable, Luminaire, MapOptions};
use lut_core::{Room, ShadeOptions, TableOptions};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

fn table() -> LightTable {
    let s = "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 50\n0 45 90\n0\n\
             1000 700 0\n";
    let f = IesFile::parse(s, "bake.ies").expect("parses");
    LightTable::from_ies(&f, &TableOptions::default()).expect("table")
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Lower the calling thread's scheduling priority (Linux: nice is per thread), as the
/// window's bake threads do (`viewer`'s `lighting/baker.rs`).
#[allow(unsafe_code)]
fn set_nice(nice: i32) {
    #[cfg(target_os = "linux")]
    // SAFETY: plain system calls on the calling thread's id; no memory is passed.
    unsafe {
        let tid = libc::gettid();
        libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, nice);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = nice;
}

fn main() {
    let mut nice = 19;
    let mut frames = 60;
    let (mut mw, mut mh) = (8192u32, 4096u32);
    for a in std::env::args().skip(1) {
        match a.split_once('=') {
            Some(("nice", v)) => nice = v.parse().expect("nice"),
            Some(("frames", v)) => frames = v.parse().expect("frames"),
            Some(("map", v)) => {
                let (w, h) = v.split_once('x').expect("map WxH");
                (mw, mh) = (w.parse().expect("W"), h.parse().expect("H"));
            }
            _ => panic!("unknown argument {a}"),
        }
    }
    let pano = grid_map(mw, mh, Projection::Equirect).expect("map");
    let t = Arc::new(table());
    let room = Room::new(6.0, 5.0, 2.8, 1.5).expect("room");
    let lights = (0..8)
        .map(|i| {
            let a = i as f64 / 8.0 * std::f64::consts::TAU;
            Luminaire::new(t.clone(), DVec3::new(2.0 * a.cos(), 2.7, 1.8 * a.sin()))
        })
        .collect();
    let scene = LightScene::new(room, lights).expect("scene");
    let illum = IlluminanceMap::build(&scene, &MapOptions::default()).expect("illuminance");
    let threads = rayon::current_num_threads();
    let opts = RenderOptions {
        threads: true,
        ..RenderOptions::default()
    };
    let mut r = Renderer::new(&pano);
    let mut px = vec![0u32; 1920 * 1080];
    let mut pan = |n: usize| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let view = View::new(30.0 + 7.3 * i as f64, 10.0, 90.0).expect("view");
                let mut f = Frame::new(&mut px, 1920, 1080).expect("frame");
                let t0 = Instant::now();
                r.render(&pano, view, &opts, &mut f).expect("render");
                t0.elapsed().as_secs_f64() * 1e3
            })
            .collect()
    };
    pan(5);
    println!(
        "{}x{} map, 1920x1080 frames, {threads} threads; no bake: frame {:.2} ms",
        mw,
        mh,
        median(pan(frames))
    );
    for n in [0, nice] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .start_handler(move |_| set_nice(n))
            .build()
            .expect("pool");
        let stop = AtomicBool::new(false);
        let bakes = Mutex::new(Vec::new());
        let frame_ms = std::thread::scope(|s| {
            s.spawn(|| {
                while !stop.load(Ordering::Relaxed) {
                    let t0 = Instant::now();
                    let never = AtomicBool::new(false);
                    pool.install(|| {
                        illum.bake_map_cancellable(&pano, &ShadeOptions::default(), &never)
                    })
                    .expect("bake");
                    bakes
                        .lock()
                        .expect("lock")
                        .push(t0.elapsed().as_secs_f64() * 1e3);
                }
            });
            std::thread::sleep(std::time::Duration::from_millis(50));
            let ms = median(pan(frames));
            stop.store(true, Ordering::Relaxed);
            ms
        });
        let b = bakes.into_inner().expect("lock");
        println!(
            "during bakes, bake threads at nice {n}: frame {frame_ms:.2} ms; bake {:.1} ms ({} bakes)",
            median(b.clone()),
            b.len()
        );
    }
}

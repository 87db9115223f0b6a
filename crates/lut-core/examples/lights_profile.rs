//! Instruction counts of lighting a 1920×1080 frame, for callgrind (counts do not depend
//! on the machine's load, unlike wall-clock times):
//!
//!     valgrind --tool=callgrind target/release/examples/lights_profile unlit
//!     valgrind --tool=callgrind target/release/examples/lights_profile map 8
//!     valgrind --tool=callgrind target/release/examples/lights_profile lit 8
//!     valgrind --tool=callgrind target/release/examples/lights_profile build 8
//!
//! `unlit` renders one frame of a 4096×2048 grid map (the benchmark's view and options,
//! one thread); `map N` lights it from an illuminance map of N lights (built before);
//! `lit N` renders and lights it in one pass (the shading run on each band of rows as
//! it is drawn, as the window does); `build N` builds the map; `pixel N` shades per pixel;
//! `time N` prints the minimum wall-clock times of 15 runs of each (one thread).

use glam::DVec3;
use lut_core::{grid_map, Frame, Projection, RenderOptions, Renderer};
use lut_core::{
    shade_frame, Camera, IesFile, IlluminanceMap, LightScene, LightTable, Luminaire, MapOptions,
    Room, ShadeOptions, TableOptions, View,
};
use std::sync::Arc;

fn table() -> LightTable {
    let v: Vec<f64> = (0..=36).map(|i| i as f64 * 5.0).collect();
    let h: Vec<f64> = (0..=12).map(|i| i as f64 * 15.0).collect();
    let join = |a: &[f64]| {
        a.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut s = format!(
        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 {} {} 1 2 0 0 0\n1 1 50\n{}\n{}\n",
        v.len(),
        h.len(),
        join(&v),
        join(&h)
    );
    for &hh in &h {
        let row: Vec<f64> = v
            .iter()
            .map(|&g| {
                let (sg, cg) = g.to_radians().sin_cos();
                if g >= 80.0 {
                    0.0
                } else {
                    2000.0 * cg * cg * (1.0 + 0.2 * hh.to_radians().cos() * sg)
                }
            })
            .collect();
        s += &join(&row);
        s += "\n";
    }
    let f = IesFile::parse(&s, "profile.ies").expect("parses");
    LightTable::from_ies(&f, &TableOptions::default()).expect("table")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).map_or("unlit", String::as_str);
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(8);
    let (w, h) = (1920u32, 1080u32);
    let threads: usize = std::env::var("THREADS").map_or(1, |s| s.parse().expect("THREADS"));
    let t = Arc::new(table());
    let room = Room::new(6.0, 5.0, 2.8, 1.5).expect("room");
    let lights = (0..n)
        .map(|i| {
            let a = i as f64 / n as f64 * std::f64::consts::TAU;
            Luminaire::new(t.clone(), DVec3::new(2.0 * a.cos(), 2.7, 1.8 * a.sin()))
        })
        .collect();
    let scene = LightScene::new(room, lights).expect("scene");
    let view = View::new(30.0, -15.0, 100.0).expect("view");
    let cam = Camera::new(view, w, h);
    let opts = RenderOptions {
        threads: threads > 1,
        ..RenderOptions::default()
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    pool.install(|| {
        let mut pixels = vec![0u32; (w * h) as usize];
        match mode {
            "unlit" => {
                let map = grid_map(4096, 2048, Projection::Equirect).expect("map");
                let mut r = Renderer::new(&map);
                let mut frame = Frame::new(&mut pixels, w, h).expect("frame");
                r.render(&map, view, &opts, &mut frame).expect("render");
            }
            "map" => {
                let m = IlluminanceMap::build(&scene, &MapOptions::default()).expect("map");
                m.shade_frame(&cam, &mut pixels, w, h, &ShadeOptions::default())
                    .expect("shade");
            }
            "lit" => {
                let map = grid_map(4096, 2048, Projection::Equirect).expect("map");
                let mut r = Renderer::new(&map);
                let m = IlluminanceMap::build(&scene, &MapOptions::default()).expect("map");
                let shader = m
                    .frame_shader(&cam, &ShadeOptions::default())
                    .expect("shader");
                let hook = |y0: usize, rows: &mut [u32]| shader.shade_band(y0, rows);
                for _ in 0..std::env::var("REPS").map_or(1, |s| s.parse().unwrap()) {
                    let mut frame = Frame::new(&mut pixels, w, h).expect("frame");
                    r.render_with(&map, view, &opts, &mut frame, &hook)
                        .expect("render");
                }
            }
            "time" => {
                // Minimum over interleaved repeats (robust to other load on the machine).
                let map = grid_map(4096, 2048, Projection::Equirect).expect("map");
                let mut r = Renderer::new(&map);
                let m = IlluminanceMap::build(&scene, &MapOptions::default()).expect("map");
                let shader = m
                    .frame_shader(&cam, &ShadeOptions::default())
                    .expect("shader");
                let hook = |y0: usize, rows: &mut [u32]| shader.shade_band(y0, rows);
                let ms = |t: std::time::Instant| t.elapsed().as_secs_f64() * 1e3;
                let mut best = [f64::INFINITY; 4];
                for _ in 0..15 {
                    let t = std::time::Instant::now();
                    let mut frame = Frame::new(&mut pixels, w, h).expect("frame");
                    r.render(&map, view, &opts, &mut frame).expect("render");
                    best[0] = best[0].min(ms(t));
                    let t = std::time::Instant::now();
                    m.shade_frame(&cam, &mut pixels, w, h, &ShadeOptions::default())
                        .expect("shade");
                    best[1] = best[1].min(ms(t));
                    let t = std::time::Instant::now();
                    let mut frame = Frame::new(&mut pixels, w, h).expect("frame");
                    r.render_with(&map, view, &opts, &mut frame, &hook)
                        .expect("render");
                    best[2] = best[2].min(ms(t));
                    let t = std::time::Instant::now();
                    IlluminanceMap::build(&scene, &MapOptions::default()).expect("map");
                    best[3] = best[3].min(ms(t));
                }
                let [unlit, shade, lit, build] = best;
                println!(
                    "{threads} thread(s): unlit {unlit:.2} ms, map shading {shade:.2} ms \
                     ({:.2}x), lit in one pass {lit:.2} ms ({:.2}x), build {build:.2} ms",
                    shade / unlit,
                    lit / unlit
                );
            }
            "build" => {
                let m = IlluminanceMap::build(&scene, &MapOptions::default()).expect("map");
                println!("{} nodes", m.nodes());
            }
            _ => shade_frame(&scene, &cam, &mut pixels, w, h, &ShadeOptions::default())
                .expect("shade"),
        }
        println!("{}", pixels.iter().map(|&p| p as u64).sum::<u64>());
    });
}

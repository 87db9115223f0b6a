//! The grid renderer's per-view cost: the grid built alone (`Renderer::build_grid`)
//! against whole frames (grid and LUT), one thread, for `callgrind`'s instruction counts
//! (the machine's load does not change them):
//!
//! ```text
//! cargo build --release -p lut-core --example grid_cost
//! valgrind --tool=callgrind --toggle-collect='*build_grid*' target/release/examples/grid_cost build fisheye 180
//! valgrind --tool=callgrind --toggle-collect='*Renderer::render*' target/release/examples/grid_cost grid fisheye 180
//! valgrind --tool=callgrind --toggle-collect='*Renderer::render*' target/release/examples/grid_cost lut rectilinear 90
//! ```
//!
//! Arguments: `build|grid|lut|exact PROJECTION HFOV [WIDTHxHEIGHT [MAP_WIDTH]]` (default
//! 1920x1080 from an 8192x4096 equirectangular map); it renders the five fixed views of
//! `viewer bench` (pitches 0 to 80) once each and prints wall-clock milliseconds too, and
//! a checksum of the frames' pixels (0 for `build`, which draws none).

use lut_core::{
    EnvMap, Frame, MapGeometry, Projection, RenderOptions, Renderer, RendererKind, View,
    ViewProjection,
};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: grid_cost build|grid|lut|exact PROJECTION HFOV [WxH [MAP_WIDTH]]";
    if args.len() < 4 {
        eprintln!("{usage}");
        std::process::exit(2);
    }
    let mode = args[1].as_str();
    let proj: ViewProjection = args[2].parse().unwrap_or_else(|e| {
        eprintln!("{e}");
        std::process::exit(2)
    });
    let hfov: f64 = args[3].parse().expect("hfov");
    let (w, h) = args
        .get(4)
        .and_then(|s| s.split_once('x'))
        .map(|(a, b)| (a.parse().expect("width"), b.parse().expect("height")))
        .unwrap_or((1920u32, 1080u32));
    let mw: u32 = args.get(5).map_or(8192, |s| s.parse().expect("map width"));
    let mh = mw / 2;
    // Pixel content does not change positions; a cheap pattern keeps the setup short.
    let px: Vec<u32> = (0..mw * mh)
        .map(|i| i.wrapping_mul(2654435761) >> 8)
        .collect();
    let map = EnvMap::from_pixels(mw, mh, &px, Projection::Equirect).expect("map");
    let mut r = Renderer::new(&map);
    let opts = RenderOptions {
        renderer: match mode {
            "lut" => RendererKind::Lut,
            "exact" => RendererKind::Exact,
            _ => RendererKind::Grid,
        },
        threads: false,
        ..RenderOptions::default()
    };
    if mode == "lut" {
        // Tables are per map, not per view: built before the measured part.
        r.table(
            opts.surface,
            Renderer::table_kind(View::new(0.0, 0.0, hfov.min(179.0)).unwrap(), &opts),
        );
    }
    let mut out = vec![0u32; (w * h) as usize];
    let t = Instant::now();
    let (mut exact, mut cells) = (0u64, (u32::MAX, 0u32));
    // Of every frame's pixels (as frame_cost's): the same before and after a refactor.
    let mut checksum = 0u64;
    for (yaw, pitch) in [
        (0.0, 0.0),
        (180.0, 0.0),
        (37.5, 25.0),
        (-100.0, -45.0),
        (60.0, 80.0),
    ] {
        let view = View::with_projection(yaw, pitch, hfov, proj).expect("view");
        let rep = if mode == "build" {
            r.build_grid(
                MapGeometry::new(mw, mh, Projection::Equirect),
                view,
                w,
                h,
                false,
            )
            .expect("build")
        } else {
            let mut f = Frame::new(&mut out, w, h).expect("frame");
            let rep = r.render(&map, view, &opts, &mut f).expect("render");
            checksum = out
                .iter()
                .fold(checksum, |a, &p| a.wrapping_mul(31).wrapping_add(p as u64));
            rep
        };
        exact += rep.exact_pixels;
        cells = (cells.0.min(rep.min_step), cells.1.max(rep.max_step));
    }
    println!(
        "{mode} {} hfov {hfov} {w}x{h} from {mw}x{mh}: {:.1} ms per view (one thread), {:.2} % exact, cells/steps {}..{} (checksum {checksum:016x})",
        proj.name(),
        t.elapsed().as_secs_f64() * 1e3 / 5.0,
        exact as f64 * 100.0 / (5.0 * w as f64 * h as f64),
        cells.0,
        cells.1
    );
}
